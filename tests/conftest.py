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
    from ukflex.scenes import PAPER

    return dict(PAPER)
