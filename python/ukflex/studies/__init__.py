"""Studies built on the public ukflex API (they use nothing private of the library).

* :mod:`.paper` -- reproduction of Pennestri, Valentini, de Falco (2010): Fig. 4 and the
  Table 1 analogue (``ukflex paper``, ``ukflex bench table1``);
* :mod:`.workprecision` -- error against run time for every integrator and formulation, and
  over element counts (``ukflex bench work-precision``, ``ukflex bench elements``);
* :mod:`.extreme` -- the catalogue of stiff and extreme scenes;
* :mod:`.stability` -- the stability report over that catalogue (``ukflex stability``);
* :mod:`.crosscheck` -- cross-checks against the NumPy reference: the paper's errata, Rust UK
  vs CP, timings (``ukflex crosscheck``);
* :mod:`.geometric` -- geometric nonlinearity of the coupler at speed: linear FFRF, nonlinear
  FFRF and ANCF against Exudyn's geometrically exact references (``ukflex study-geometric``);
* :mod:`.machine` -- the machine description in the reports' headers.

The library's stability diagnostics that users call on their own runs stay in
:mod:`ukflex.stability`.
"""

__all__ = ["paper", "workprecision", "extreme", "stability", "crosscheck", "geometric", "machine"]
