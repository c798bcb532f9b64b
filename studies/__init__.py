"""Studies built on the public ukflex API (they use nothing private of the library); not part of
the wheel. Entry point: ``python -m studies NAME ...`` (:mod:`studies.__main__`), from the
repository's root.

* :mod:`.extreme` -- the catalogue of stiff and extreme scenes;
* :mod:`.stability` -- the stability report over that catalogue (``python -m studies stability``);
* :mod:`.crosscheck` -- cross-checks against the NumPy reference: the paper's errata, Rust UK
  vs CP, timings (``python -m studies crosscheck``);
* :mod:`.geometric` -- geometric nonlinearity of the coupler at speed: linear FFRF, nonlinear
  FFRF and ANCF against Exudyn's geometrically exact references (``python -m studies geometric``);
* :mod:`.flexible_coupler` -- the paper's coupler as an FE-reduced flexible body
  (``python -m studies flexible-coupler``);
* :mod:`.simeon_crank` -- Simeon's flexible slider-crank test set (``python -m studies simeon-crank``);
* :mod:`.sweeps` -- the sweep study (``python -m studies sweeps``);
* :mod:`.clearance` -- revolute joints with clearance at the piston pin: Flores's slider-crank,
  the flexible coupler's peak strain against the clearance (``python -m studies clearance``).

The paper's reproduction and the work-precision bench (``ukflex paper``, ``ukflex bench``) ship
with the library: :mod:`ukflex.benchmarks`. The stability diagnostics users call on their own runs
are the library's :mod:`ukflex.stability`.
"""

import sys
import time

__all__ = ["progress", "extreme", "stability", "crosscheck", "geometric", "flexible_coupler", "simeon_crank", "sweeps", "clearance"]


_START = time.perf_counter()


def progress(study: str, what: str) -> None:
    """One line on stderr as a long study starts a case (``python -m studies NAME``): the study,
    the case and the seconds since the studies were imported (stdout keeps the study's tables)."""
    print(f"[{study} {time.perf_counter() - _START:7.1f} s] {what}", file=sys.stderr, flush=True)
