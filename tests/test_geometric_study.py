"""The geometric nonlinearity study (studies.geometric, `python -m studies geometric`): its quick
path on a tiny grid and its outputs, the peak metric, the membrane-locking illustration, and the
physics it documents (docs/geometric-nonlinearity.md): at the paper speed the nonlinear FFRF
coupler is within 0.5 % of Exudyn's geometrically exact peak and the paper's linear FFRF is more
than 5 % above it."""

import csv
import math
from pathlib import Path

import numpy as np
import pytest

from studies.__main__ import main as studies_main
from studies import geometric as G

EXUDYN = G.load_exudyn()
needs_exudyn_data = pytest.mark.skipif(EXUDYN is None, reason="benches/data/exudyn_*.csv not in this tree")


def _rows(path):
    with open(path) as fh:
        return list(csv.DictReader(line for line in fh if not line.startswith("#")))


def test_refined_peak_finds_the_vertex_between_samples_and_keeps_window_ends():
    t = np.linspace(0.0, 1.0, 11)
    y = -3.0 * (t - 0.437) ** 2 + 2.0
    peak, tp = G.refined_peak(t, y)
    assert peak == pytest.approx(2.0, abs=1e-12) and tp == pytest.approx(0.437, abs=1e-12)
    peak, tp = G.refined_peak(t, -t, t_max=0.5)  # |y| grows to the window end: the sample there
    assert (peak, tp) == (0.5, 0.5)


def test_membrane_locking_index_falls_like_one_over_n_squared_and_grows_with_the_bow():
    small = G.membrane_locking_index((4, 8, 16), amplitude=0.01)
    big = G.membrane_locking_index((4,), amplitude=0.1)
    r = [x["U_m/U_b"] for x in small]
    assert all(x > 0 for x in r)
    assert 3.0 < r[0] / r[1] < 5.0 and 3.0 < r[1] / r[2] < 5.0  # O(h^2)
    assert big[0]["U_m/U_b"] / r[0] == pytest.approx(100.0, rel=1e-9)  # quadratic in the amplitude


@needs_exudyn_data
def test_quick_study_on_a_tiny_grid_writes_its_outputs(tmp_path):
    s = G.run_geometric(tmp_path, quick=True, models=("linear-ffrf", "nonlinear-ffrf", "ancf"), elements=(4,),
                        cases=("omega x1",), log=lambda msg: None)
    for name in ("runs.csv", "axial.csv", "extreme.csv", "cost.csv", "targets.csv", "summary.md", "paper_history.png",
                 "axial.png", "cost.png"):
        assert (tmp_path / name).is_file(), name
    runs = _rows(tmp_path / "runs.csv")
    sweep = {r["model"]: r for r in runs if r["purpose"] == "sweep"}
    assert set(sweep) == {"linear-ffrf", "nonlinear-ffrf", "ancf"}
    assert {r["model"] for r in runs if r["purpose"] == "check-time"} == {"nonlinear-ffrf", "ancf"}
    for r in sweep.values():
        assert r["finished"] == "1" and r["case"] == "omega x1" and r["elements"] == "4"
        assert float(r["exudyn_peak"]) == pytest.approx(EXUDYN["ancf"]["peak"])
        assert 0.05 < float(r["max_compression_ratio"]) < 0.5  # the paper speed: ~0.1-0.2 P_cr
    # the quick integrator is a preview: still within 0.3 % of Exudyn for the nonlinear models
    assert abs(float(sweep["nonlinear-ffrf"]["peak_vs_exudyn"])) < 3e-3
    assert abs(float(sweep["ancf"]["peak_vs_exudyn"])) < 3e-3
    assert float(sweep["linear-ffrf"]["peak_vs_exudyn"]) > 0.05
    targets = _rows(tmp_path / "targets.csv")
    assert any("vs ANCF" in t["target"] and t["met"] == "yes" for t in targets)
    cost = _rows(tmp_path / "cost.csv")
    assert {(c["model"], c["elements"]) for c in cost} == {(m, n) for m in ("nonlinear-ffrf", "ancf") for n in ("2", "4")}
    md = (tmp_path / "summary.md").read_text()
    for section in ("## (a)", "## (b)", "## (d)", "## Targets of issue 11", "## Membrane locking index"):
        assert section in md, section
    assert s["finest"][("ancf", "omega x1")].finished


def test_cli_study_geometric_runs_a_restricted_grid(tmp_path, capsys):
    out = tmp_path / "g"
    assert studies_main(["geometric", "--out", str(out), "--quick", "--models", "nonlinear-ffrf", "--elements", "2",
                     "--cases", "omega x1, omega x3", "--no-cost", "--no-plot", "--silent"]) == 0
    assert "summary.md" in capsys.readouterr().out
    runs = _rows(out / "runs.csv")
    assert [(r["case"], r["elements"]) for r in runs] == [("omega x1", "2"), ("omega x3", "2")]
    with pytest.raises(SystemExit):
        studies_main(["geometric", "--out", str(out), "--cases", "omega x7"])


@needs_exudyn_data
def test_paper_speed_nonlinear_ffrf_matches_the_geometrically_exact_peak_and_linear_ffrf_does_not():
    """The physics of docs/geometric-nonlinearity.md with the study's own integrator (DOPRI5,
    rtol 1e-8): N = 4 elements at 124.8 rad/s, peak over 0..8.736 rad of crank angle."""
    ref = EXUDYN["ancf"]["peak"]
    nl = G.run_one("nonlinear-ffrf", 4, G.PAPER_CASE, G.FULL, angle=G.WINDOW_ANGLE, axial=False)
    lin = G.run_one("linear-ffrf", 4, G.PAPER_CASE, G.FULL, angle=G.WINDOW_ANGLE, axial=False)
    assert nl.finished and lin.finished
    assert abs(nl.peak / ref - 1.0) < 5e-3, nl.peak
    assert abs(nl.t_peak - EXUDYN["ancf"]["t_peak"]) < 2e-3  # the same lobe
    assert lin.peak / ref - 1.0 > 0.05, lin.peak
