"""The work-precision runner on a reduced grid (a short span of the paper's scene)."""

import csv
import os
import subprocess
import sys

import numpy as np
import pytest

import ukflex
from ukflex.benchmarks import workprecision as wp

T_END = 0.004
SAMPLES = 41


def _rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("wp")
    res = wp.run_work_precision(str(out), t_end=T_END, samples=SAMPLES, methods=("RK45",), formulations=("uk", "cp"),
                                native=("DOPRI5",), rtols=(1e-3, 1e-6), budget=120.0, ref_rtol=1e-11)
    return out, res


def test_outputs_written(study):
    out, res = study
    rows = _rows(out / "work_precision.csv")
    assert len(rows) == 3 * 2 == len(res["rows"])
    assert set(rows[0]) == set(wp.CSV_FIELDS)
    assert {(r["formulation"], r["method"]) for r in rows} == {("uk", "RK45"), ("cp", "RK45"), ("native", "DOPRI5")}
    assert all(r["status"] == "ok" for r in rows)
    assert (out / "work_precision.png").stat().st_size > 20_000
    md = (out / "work_precision.md").read_text()
    assert "Reference (N = 1): native DOPRI5, rtol 1e-11" in md and "Machine:" in md and "| 1e-04 |" in md


def test_reference_is_tight(study):
    _, res = study
    ref = res["reference"]
    assert ref["accuracy"] < 1e-11 * 10 and ref["peak"] > 1e-4


def test_error_falls_with_rtol_and_formulations_agree(study):
    _, res = study
    by = {(r["formulation"], r["method"], r["rtol"]): r for r in res["rows"]}
    for line in (("uk", "RK45"), ("cp", "RK45"), ("native", "DOPRI5")):
        loose, tight = by[line + (1e-3,)], by[line + (1e-6,)]
        assert tight["err_max"] < loose["err_max"] / 10, line
        assert tight["err_max"] < 1e-3 * res["reference"]["peak"], line  # CP (NumPy) meets the Rust UK reference
        assert tight["peak_err"] <= tight["err_max"] + 1e-15
        assert tight["nfev"] > loose["nfev"] > 0
        assert tight["wall_time"] > 0
    # coordinate partitioning stays on the constraints (Newton recovery); UK drifts slightly
    assert by[("cp", "RK45", 1e-6)]["drift_end"] < 1e-10
    assert np.isfinite(by[("uk", "RK45", 1e-3)]["drift_end"])


def test_error_measure_matches_a_direct_computation(study):
    _, res = study
    row = next(r for r in res["rows"] if r["formulation"] == "uk" and r["rtol"] == 1e-3)
    system = wp.paper_system("timoshenko", 1)
    t = np.linspace(0.0, T_END, SAMPLES)
    sim = ukflex.simulate(system, T_END, method="RK45", rtol=1e-3, atol=1e-6, t_eval=t)
    _, v = sim.beam_displacement("coupler", 0.5)
    ref = res["reference"]["v"] * 0.3048
    assert row["err_max"] == pytest.approx(np.max(np.abs(v - ref)) / 0.3048, rel=1e-9)


def test_best_per_level_is_the_fastest_accurate_run(study):
    _, res = study
    rows = res["rows"]
    for b in res["best"]:
        good = [r for r in rows if r["status"] == "ok" and r["err_max"] <= b["level"]]
        if not good:
            assert b["overall"] is None
            continue
        assert b["overall"]["wall_time"] == min(r["wall_time"] for r in good)
        for g, r in b["by_group"].items():
            gg = [x for x in good if wp.FORMULATION_LABEL[x["formulation"]] == g]
            assert (r is None) == (not gg)


def test_budget_marks_and_skips(tmp_path):
    res = wp.run_work_precision(str(tmp_path), t_end=T_END, samples=SAMPLES, methods=("RK45",), formulations=("cp",),
                                native=(), rtols=(1e-3, 1e-6), budget=0.05, ref_rtol=1e-10, plot=True)
    st = [(r["rtol"], r["status"]) for r in res["rows"]]
    assert st == [(1e-3, "over_budget"), (1e-6, "skipped")]
    over = res["rows"][0]
    assert 0.05 <= over["wall_time"] < 5.0 and not np.isfinite(over["err_max"])
    rows = _rows(tmp_path / "work_precision.csv")
    assert [r["status"] for r in rows] == ["over_budget", "skipped"]
    md = (tmp_path / "work_precision.md").read_text()
    assert "over_budget" in md and "interrupted after the 0.05 s budget" in md
    assert (tmp_path / "work_precision.png").exists()


def test_elements_study(tmp_path):
    res = wp.run_elements(str(tmp_path), elements=(1, 2), cases=(("native", "DOPRI5"), ("uk", "RK45")), t_end=0.002,
                          samples=21, rtols=(1e-4,), budget=60.0, ref_rtol=1e-10)
    rows = res["rows"]
    assert [(r["elements"], r["formulation"]) for r in rows] == [(1, "native"), (1, "uk"), (2, "native"), (2, "uk")]
    for r in rows:
        assert r["status"] == "ok"
        if r["elements"] == 2:  # the finest model: both errors are against the same reference
            assert r["err_vs_finest"] == r["err_max"]
        else:  # N = 1 carries its discretization error
            assert r["err_vs_finest"] >= res["settings"]["model_error"][1] - r["err_max"]
    assert res["settings"]["model_error"][1] > 10 * max(r["err_max"] for r in rows)
    for f in ("elements.csv", "elements.png", "elements.md"):
        assert (tmp_path / f).exists()


def test_elements_study_with_a_finer_reference_only_model(tmp_path):
    # N = 2 is only the reference: the studied N = 1 rows carry their discretization error
    res = wp.run_elements(str(tmp_path), elements=(1,), cases=(("native", "DOPRI5"),), t_end=0.002,
                          samples=21, rtols=(1e-4,), budget=60.0, ref_rtol=1e-10, reference_elements=2)
    (row,) = res["rows"]
    assert row["elements"] == 1 and row["status"] == "ok"
    model_error = res["settings"]["model_error"]
    assert set(model_error) == {1, 2} and model_error[2] == 0.0 and res["settings"]["finest"] == 2
    assert model_error[1] > 10 * row["err_max"]
    assert abs(row["err_vs_finest"] - model_error[1]) <= row["err_max"]
    assert "Reference (N = 2)" in (tmp_path / "elements.md").read_text()
    with pytest.raises(ValueError, match="reference_elements"):
        wp.run_elements(str(tmp_path), elements=(1, 2), cases=(("native", "DOPRI5"),), t_end=0.002,
                        samples=21, rtols=(1e-4,), reference_elements=2)


def test_cli_bench_work_precision(tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg")
    r = subprocess.run([sys.executable, "-m", "ukflex", "bench", "work-precision", "--out", str(tmp_path), "--t-end",
                        "0.002", "--samples", "21", "--rtols", "1e-3,1e-5", "--methods", "DOP853", "--formulations",
                        "uk", "--native", "", "--ref-rtol", "1e-10"], capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    rows = _rows(tmp_path / "work_precision.csv")
    assert [(x["method"], float(x["rtol"]), x["status"]) for x in rows] == [("DOP853", 1e-3, "ok"),
                                                                            ("DOP853", 1e-5, "ok")]
    bad = subprocess.run([sys.executable, "-m", "ukflex", "bench", "work-precision", "--out", str(tmp_path),
                          "--methods", "RK4"], capture_output=True, text=True, env=env)
    assert bad.returncode == 2 and "RK4" in bad.stderr
