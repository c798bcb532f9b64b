"""``python -m fuzz``: run the fuzz suite (docs/robustness.md)."""

from __future__ import annotations

import argparse
import sys

from .cases import CATEGORIES, WEIGHTS
from .regressions import REGRESSIONS
from .runner import run


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m fuzz", description=__doc__)
    p.add_argument("--cases", type=int, default=2000, help="total cases, split over the categories by weight")
    p.add_argument("--categories", default=",".join(CATEGORIES), help="comma-separated subset")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--timeout", type=float, default=10.0, help="seconds before a case counts as a hang")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--batch", type=int, default=25)
    p.add_argument("--regression", choices=sorted(REGRESSIONS), help="put back an old bug (proves the suite bites)")
    p.add_argument("--json", help="write the report as JSON here")
    a = p.parse_args(argv)
    cats = [c.strip() for c in a.categories.split(",") if c.strip()]
    unknown = [c for c in cats if c not in CATEGORIES]
    if unknown:
        p.error(f"unknown categories {unknown}; known: {sorted(CATEGORIES)}")
    w = sum(WEIGHTS[c] for c in cats)
    cases = {c: max(1, a.cases * WEIGHTS[c] // w) for c in cats}
    report = run(cases, workers=a.workers, timeout=a.timeout, seed=a.seed, batch=a.batch, regression=a.regression,
                 progress=True)
    print(report.text())
    if a.json:
        with open(a.json, "w") as f:
            f.write(report.to_json())
    return 1 if report.total_findings else 0


if __name__ == "__main__":
    sys.exit(main())
