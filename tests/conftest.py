"""Shared pytest setup for the Python API tests (headless matplotlib, common helpers)."""

import os

os.environ.setdefault("MPLBACKEND", "Agg")

import matplotlib  # noqa: E402

matplotlib.use("Agg")

import pytest  # noqa: E402


def core_available() -> bool:
    """True when the compiled extension ukflex._core can be imported."""
    try:
        import ukflex._core  # noqa: F401
    except ImportError:
        return False
    return True


@pytest.fixture(scope="session")
def paper_data():
    from ukflex.model.scenes import PAPER

    return dict(PAPER)


@pytest.fixture(autouse=True)
def no_success_on_garbage(monkeypatch):
    """Everywhere in the suite: a run that returns status 0 kept every output within its drift
    bound (res.extra["drift_limit"]), unless it was told to go on (on_drift="warn", which
    reports the drift in res.extra["drift"])."""
    import sys

    try:
        import ukflex  # noqa: F401
    except ImportError:  # the extension is not built: nothing to check
        yield
        return
    sim = sys.modules["ukflex.run.simulate"]  # the module (ukflex.simulate is the function)
    seen = []
    original = sim._report

    def report(system, res, guard, method, options):
        original(system, res, guard, method, options)
        seen.append(res)

    monkeypatch.setattr(sim, "_report", report)
    yield
    for res in seen:
        check_no_success_on_garbage(res)


def check_no_success_on_garbage(res) -> None:
    """Status 0 only within the drift bound (or with the drift reported, on_drift="warn")."""
    if res.status != 0 or "drift" in res.extra or not res.t.size:
        return
    worst = float(max(res.residuals.get("position", [0.0]), default=0.0))
    assert worst <= res.extra["drift_limit"], (
        f"status 0 beyond the drift bound: ||Phi|| = {worst:.3g} > {res.extra['drift_limit']:.3g} ({res.method})")
