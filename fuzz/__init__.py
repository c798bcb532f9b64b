"""The project's fuzz suite: hostile inputs for every public entry point, run in a pool of
worker processes with a watchdog (docs/robustness.md).

* :mod:`fuzz.values`     -- hypothesis strategies for hostile values (extreme floats, wrong types,
  masked/complex arrays, huge integers, ...).
* :mod:`fuzz.cases`      -- the categories: how a case is drawn and what counts as *wrong* for it
  (checkable invariants: named exceptions, finite outputs, constraint residuals relative to the
  scene's length scale, energy of conservative scenes, agreement with the NumPy reference).
* :mod:`fuzz.runner`     -- the worker pool, the per-case watchdog (hangs), crash detection
  (a worker that dies) and the report.
* :mod:`fuzz.regressions` -- seeded regressions (an old bug put back by a monkeypatch) that prove
  the suite bites.

Run ``python -m fuzz --cases 50000`` from the repository root (``--help`` for options).
"""
