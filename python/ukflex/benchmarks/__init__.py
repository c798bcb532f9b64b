"""The paper's reproduction and the work-precision bench, on the public API: what ``ukflex paper``
and ``ukflex bench`` run.

* :mod:`.paper` -- reproduction of Pennestri, Valentini, de Falco (2010): Fig. 4 and the
  Table 1 analogue (``ukflex paper``, ``ukflex bench table1``);
* :mod:`.workprecision` -- error against run time for every integrator and formulation, and
  over element counts (``ukflex bench work-precision``, ``ukflex bench elements``);
* :mod:`.machine` -- the machine description in the reports' headers.

The other studies live in the repository's ``studies/`` package (``python -m studies NAME``).
"""

__all__ = ["paper", "workprecision", "machine"]
