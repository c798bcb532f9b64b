"""Packaging: single-source version, metadata, optional matplotlib, BLAS threads."""

import re
import sys
from importlib import metadata
from pathlib import Path

import numpy as np
import pytest

import ukflex

ROOT = Path(__file__).resolve().parents[1]


def test_version_single_source():
    cargo = re.search(r'^version\s*=\s*"([^"]+)"', (ROOT / "Cargo.toml").read_text(), re.M).group(1)
    assert ukflex.__version__ == metadata.version("ukflex") == cargo
    text = (ROOT / "pyproject.toml").read_text()
    assert 'dynamic = ["version"]' in text and not re.search(r'^version\s*=', text, re.M)


def test_metadata_and_extras():
    md = metadata.metadata("ukflex")
    assert md["License-Expression"] == "MIT" or md["License"] == "MIT"
    assert (ROOT / "LICENSE").read_text().startswith("MIT License")
    extras = set(md.get_all("Provides-Extra") or [])
    assert {"plot", "sweep", "fe", "test", "peers"} <= extras
    requires = " ".join(md.get_all("Requires-Dist") or [])
    assert "matplotlib" not in [r.split(">")[0].split(";")[0].strip() for r in md.get_all("Requires-Dist")
                                if "extra ==" not in r]
    assert "pandas" in requires and "scikit-fem" in requires and "exudyn" in requires
    assert md["Keywords"] and any(c.startswith("License") or c.startswith("Topic") for c in md.get_all("Classifier"))
    assert "ukflex" in (md.get_payload() or md["Description"] or "")  # the README is the long description


@pytest.fixture
def no_matplotlib(monkeypatch):
    """Make every ``import matplotlib...`` (and PIL) fail as if they were not installed."""
    for name in list(sys.modules):
        if name == "matplotlib" or name.startswith("matplotlib.") or name == "PIL" or name.startswith("PIL."):
            monkeypatch.delitem(sys.modules, name)
    for name in ("matplotlib", "matplotlib.figure", "matplotlib.backends.backend_agg", "matplotlib.colors",
                 "matplotlib.transforms", "PIL", "PIL.Image"):
        monkeypatch.setitem(sys.modules, name, None)


def _check(exc_info, what):
    msg = str(exc_info.value)
    assert isinstance(exc_info.value, ImportError) and isinstance(exc_info.value, ukflex.UkflexError)
    assert "ukflex's extra [plot]" in msg and "pip install " in msg and what in msg


def test_library_imports_without_matplotlib(no_matplotlib):
    res = ukflex.simulate(ukflex.scenes.pendulum(), 0.05, method="DOPRI5")
    assert res.success


def test_every_plot_entry_point_names_the_missing_matplotlib(no_matplotlib, tmp_path):
    from ukflex.results.animate import animate
    from studies import geometric, sweeps
    from ukflex.benchmarks import paper, workprecision

    res = ukflex.simulate(ukflex.scenes.pendulum(), 0.05, method="DOPRI5")
    with pytest.raises(ukflex.MissingDependencyError) as e:
        animate(res, str(tmp_path / "a.gif"))
    _check(e, "animation")
    with pytest.raises(ukflex.MissingDependencyError) as e:
        workprecision.plot_work_precision([], str(tmp_path / "wp.png"))
    _check(e, "work-precision")
    with pytest.raises(ukflex.MissingDependencyError) as e:
        paper._plot_fig4(str(tmp_path / "f.png"), np.zeros(2), {}, 1, True)
    _check(e, "Fig. 4")
    with pytest.raises(ukflex.MissingDependencyError) as e:
        geometric._figure()
    _check(e, "geometric")
    with pytest.raises(ukflex.MissingDependencyError) as e:
        sweeps._contours(None, str(tmp_path / "c.png"))
    _check(e, "contour")


def test_cli_run_without_matplotlib_fails_before_running_only_when_asked_to_animate(no_matplotlib, tmp_path, capsys):
    from ukflex.cli import main

    assert main(["run", "pendulum", "--t-end", "0.05", "--animate", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "ukflex's extra [plot]" in err[0] and "--animate" in err[0]
    assert not (tmp_path / "o" / "pendulum.csv").exists()  # nothing ran
    # the default plot is skipped with a note (tests/test_cli_truth.py); --no-plot needs no note
    assert main(["run", "pendulum", "--t-end", "0.05", "--no-plot", "--out", str(tmp_path / "p")]) == 0
    assert (tmp_path / "p" / "pendulum.csv").exists() and "note:" not in capsys.readouterr().out


def test_blas_threads_context():
    threadpoolctl = pytest.importorskip("threadpoolctl")
    from ukflex.reference._blas import blas_threads
    from ukflex.reference import single_blas_thread

    def counts():
        return [i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"]

    before = counts()
    with single_blas_thread():
        assert all(n == 1 for n in counts())
    assert counts() == before
    with blas_threads(None):
        assert counts() == before


def test_blas_threads_without_threadpoolctl(monkeypatch):
    monkeypatch.setitem(sys.modules, "threadpoolctl", None)
    from ukflex.reference._blas import blas_threads, have_threadpoolctl

    assert not have_threadpoolctl()
    with blas_threads(1):  # graceful: does nothing
        pass
