"""The fuzz suite (fuzz/, docs/robustness.md) inside pytest: a bounded run of every category must
find nothing, and each seeded regression (an old bug put back) must be found -- the proof that
the suite bites.  The long run is ``python -m fuzz --cases 50000`` (not in CI)."""
import os
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

pytest.importorskip("hypothesis")

from fuzz.cases import CATEGORIES  # noqa: E402
from fuzz.regressions import REGRESSIONS  # noqa: E402
from fuzz.runner import run  # noqa: E402

#: cases per category in CI (about two minutes on two shared cores)
BOUNDED = {"scene": 150, "toml": 100, "core": 150, "arrays": 250, "options": 100, "cli": 40, "threads": 25,
           "expr": 150, "spline": 100, "dense": 100, "pickle": 100, "fe": 40, "sweep": 40, "extremes": 150, "names": 100,
           "builders": 100}


@pytest.fixture(autouse=True)
def _from_root(monkeypatch):
    monkeypatch.chdir(ROOT)  # the workers import the fuzz package from the repository root


def test_bounded_fuzz_run_finds_nothing():
    assert set(BOUNDED) == set(CATEGORIES)
    report = run(BOUNDED, workers=2, timeout=30.0, seed=20261122)
    assert sum(report.cases.values()) >= 0.95 * sum(BOUNDED.values()), report.text()
    assert report.total_findings == 0, report.text()


@pytest.mark.parametrize("name", sorted(REGRESSIONS))
def test_seeded_regression_is_caught(name):
    category, _ = REGRESSIONS[name]
    report = run({category: 120}, workers=2, timeout=30.0, seed=7, regression=name)
    assert report.total_findings > 0, f"the suite did not catch the seeded regression {name!r}:\n{report.text()}"
