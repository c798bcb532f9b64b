"""The optional Exudyn peer reference (benches/peers): post-processing and stored references without
Exudyn; one short Exudyn run only when Exudyn is installed (it is not a CI requirement)."""

import importlib
import math
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
PEERS = ROOT / "benches" / "peers"
DATA = ROOT / "benches" / "data"


@pytest.fixture(scope="module")
def es():
    sys.path.insert(0, str(PEERS))
    try:
        yield importlib.import_module("exudyn_slider_crank")
    finally:
        sys.path.remove(str(PEERS))


def test_module_imports_and_cli_names_the_missing_package(es, monkeypatch, capsys):
    monkeypatch.setattr(es, "HAVE_EXUDYN", False)
    assert es.main(["--model", "ancf"]) == 2
    assert "exudyn is not installed" in capsys.readouterr().err
    with pytest.raises(es.ExudynMissing):
        es.build("ancf", 2)


def test_chord_deflection_is_the_signed_normal_distance(es):
    r0 = np.array([[0.0, 0.0], [1.0, 1.0]])
    r1 = np.array([[2.0, 0.0], [1.0, 3.0]])  # second chord points along +y: e_n = (-1, 0)
    rm = np.array([[1.0, 0.25], [0.5, 2.0]])
    np.testing.assert_allclose(es.chord_deflection(r0, r1, rm), [0.25, 0.5])


def test_refined_peak_recovers_a_parabola_vertex_between_samples(es):
    t = np.linspace(0.0, 1.0, 101)
    y = -3.0 * (t - 0.4237) ** 2 + 0.9
    peak, tp = es.refined_peak(t, -y)  # |.|: sign does not matter
    assert peak == pytest.approx(0.9, rel=1e-12)
    assert tp == pytest.approx(0.4237, abs=1e-12)
    peak_w, _ = es.refined_peak(t, y, t_max=0.3)  # window end: sample value, no extrapolation
    assert peak_w == pytest.approx(y[30])


def test_history_error_against_an_identical_reference_is_zero(es):
    t = np.linspace(0.0, 0.1, 1001)
    v = 0.01 * np.sin(2 * math.pi * 20 * t)
    assert es.history_error(t[::10], v[::10], t, v, 0.01) < 1e-9


@pytest.mark.parametrize("name", ["exudyn_ref_ancf.csv", "exudyn_ref_ge.csv"])
def test_stored_references_are_readable_and_match_their_header(es, name):
    path = DATA / name
    if not path.exists():
        pytest.skip(f"{name} not generated")
    t, v, meta = es.load_reference(str(path))
    assert t[0] == 0.0 and t[-1] == pytest.approx(0.1) and np.all(np.diff(t) <= 1.0001e-5)
    peak, _ = es.refined_peak(t, v, 0.07)
    stated = float(meta["peak_0_0.07s"].split()[0])
    assert peak == pytest.approx(stated, rel=1e-5)
    assert 0.0095 < peak < 0.0101  # geometrically exact models: ~7 % below the linear FFRF peak


def test_exudyn_short_run_starts_consistent():
    pytest.importorskip("exudyn")
    sys.path.insert(0, str(PEERS))
    try:
        es = importlib.import_module("exudyn_slider_crank")
        for model in ("ancf", "ge"):
            r = es.build_and_solve(model, 2, 2e-4, t_end=0.008)
            assert r["ok"], r["error"]
            assert abs(r["v"][0]) < 1e-12 and abs(r["v"][1]) < 1e-4  # undeformed start, smooth
            assert r["crank_angle_error"] < 1e-10  # prescribed crank angle omega*t
            assert 0.009 < r["peak"] < 0.0105  # first lobe (t ~ 5.6 ms) of the converged ~0.0098
    finally:
        sys.path.remove(str(PEERS))
