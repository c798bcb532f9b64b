"""Issue 6: every case of the extreme catalogue at reduced size, asserting its physics."""

import math
import warnings

import numpy as np
import pytest

from conftest import core_available

pytestmark = pytest.mark.skipif(not core_available(), reason="ukflex._core not built")

import ukflex  # noqa: E402
from studies import extreme as X  # noqa: E402
from ukflex import stability as S  # noqa: E402


def v_mid(r):
    return r.beam_displacement("coupler", 0.5)[1] / S.beam_properties(r.system, "coupler")["length"]


# ---------------------------------------------------------------- 1. stiff
def test_stiff_highest_frequencies():
    import scipy.linalg as sla

    for elements, factor, lo in [(32, 1.0, 2e6), (64, 1.0, 3e6), (1, 1e4, 2.5e6)]:
        s = X.stiff(factor, elements=elements).build()
        Mff, Kff = s.beam_matrices("coupler")
        w = np.sqrt(sla.eigh(Kff, Mff, eigvals_only=True))
        assert w.max() > lo


def test_stiff_deflection_scales_as_one_over_E():
    """Quasi-static limit: E x 100 -> x 10^4 divides the coupler deflection by 100."""
    T, te = 0.01, np.linspace(0, 0.01, 201)
    peaks = {}
    for f in (100.0, 1e4):
        r = ukflex.simulate(X.stiff(f), T, "DOPRI5", rtol=1e-7, t_eval=te, stabilization="none", raise_on_failure=True)
        assert r.max_residual("position") < 1e-9
        peaks[f] = np.abs(v_mid(r)).max()
    assert 95.0 < peaks[100.0] / peaks[1e4] < 105.0


def test_stiff_fine_mesh_native_integrators_agree():
    system = X.stiff(1.0, elements=32).build()
    te = np.linspace(0, 5e-4, 51)
    a = ukflex.simulate(system, 5e-4, "DOPRI5", rtol=1e-8, t_eval=te, stabilization="none", raise_on_failure=True)
    b = ukflex.simulate(system, 5e-4, "RADAU5", rtol=1e-8, t_eval=te, stabilization="none", raise_on_failure=True)
    assert np.abs(v_mid(a) - v_mid(b)).max() < 1e-3 * np.abs(v_mid(a)).max()
    assert max(a.max_residual(), b.max_residual()) < 1e-9


# ---------------------------------------------------------------- 2, 3. flexible, high speed
def test_thin_coupler_leaves_ffrf_range_and_paper_does_not():
    r = ukflex.simulate(X.flexible(0.25), 0.03, "DOPRI5", rtol=1e-6, t_eval=np.linspace(0, 0.03, 151), stabilization="none", raise_on_failure=True)
    with pytest.warns(S.ModelValidityWarning):
        kinds = {d.kind for d in S.check(r)}
    assert "ffrf-validity" in kinds
    assert S.ffrf_validity(r, "coupler")["max_v_over_L"] > 0.05
    p = ukflex.simulate(ukflex.scenes.slider_crank(), 0.07, "DOPRI5", rtol=1e-6, t_eval=np.linspace(0, 0.07, 141), stabilization="none", raise_on_failure=True)
    with warnings.catch_warnings():
        warnings.simplefilter("error", S.StabilityWarning)
        assert S.check(p) == []
    assert 0.007 < S.ffrf_validity(p, "coupler")["max_v_over_L"] < 0.01


def test_axial_force_strain_vs_multipliers_and_buckling_load():
    """The strain-based axial force at the crank end equals the joint reaction along the coupler
    (from the multipliers) in a near-rigid coupler; P_cr = pi^2 E I / Lb^2."""
    r = ukflex.simulate(X.stiff(100.0, elements=4), 0.006, "DOPRI5", rtol=1e-7, t_eval=np.linspace(0.002, 0.006, 41), stabilization="none", raise_on_failure=True)
    strain = -S.axial_force(r, "coupler")[0]  # compression positive, element 1
    joint = S.joint_end_force(r, "crank_coupler", "coupler")
    scale = np.abs(joint).max()
    # element 1 (mean over its length) carries the end force minus part of the inertia of 1/4 of the coupler
    assert np.abs(strain - joint).max() < 0.15 * scale
    P = S.beam_properties(r.system, "coupler")
    assert S.buckling_load(r.system, "coupler") == pytest.approx(math.pi**2 * P["E"] * P["I"] / P["length"] ** 2)
    assert S.buckling_load(ukflex.System(ukflex.scenes.slider_crank()), "coupler") == pytest.approx(1753.6, rel=1e-3)


def test_high_speed_buckling_ratio_grows_and_warns():
    ratios = {}
    for f in (1.0, 5.0):
        T = 0.014
        r = ukflex.simulate(X.high_speed(f), T, "DOPRI5", rtol=1e-6, t_eval=np.linspace(0, T, 141), stabilization="none", raise_on_failure=True)
        ratios[f] = S.buckling_ratio(r, "coupler")["ratio"]
        if f == 5.0:
            with pytest.warns(S.BucklingWarning):
                S.check(r, rank=False)
    assert ratios[1.0] < 0.2
    assert ratios[5.0] > 1.0  # beyond the Euler load: the model is out of range (and says so)


# ---------------------------------------------------------------- 4. singular configurations
def test_equal_slider_crank_passes_the_singularity_on_the_slider_branch():
    w = 20.0
    system = X.equal_slider_crank(omega=w).build()
    T = math.pi / w
    te = np.linspace(0, T, 101)  # t = pi / (2 w) (singular) is output 50
    r = ukflex.simulate(system, T, "DOPRI5", rtol=1e-9, t_eval=te, stabilization="none", raise_on_failure=True)
    th = r.coordinate("coupler.theta")
    assert np.abs(th + w * r.t).max() < 1e-6  # closed form of the slider branch
    L = X.PAPER["crank_length"]
    xs = r.coordinate("coupler.x") + L * np.cos(th)
    assert np.abs(xs - 2 * L * np.cos(w * r.t)).max() < 1e-6
    rh = S.rank_history(r)
    # A F^-T is singular there: the tiny singular value is dropped (rank 5) or kept at < 1e-10
    assert rh["rank"][50] == 5 or rh["ratio"][50] < 1e-10
    assert rh["rank"][49] == rh["rank"][51] == 6
    assert np.median(rh["ratio"]) > 1e-2
    with pytest.warns(S.RankDeficiencyWarning):
        S.check(r)
    cp = ukflex.simulate(system, T, method="DOP853", rtol=1e-9, atol=1e-12, t_eval=te, formulation="cp")
    assert cp.status == 0 and np.abs(cp.q - r.q).max() < 1e-6


def test_flat_parallelogram_stays_on_a_consistent_branch_and_warns():
    system = X.parallelogram(omega=10.0).build()
    r = ukflex.simulate(system, 0.3, "DOPRI5", rtol=1e-8, t_eval=np.linspace(0, 0.3, 301), stabilization="none", raise_on_failure=True)
    assert r.max_residual("position") < 1e-6
    # the crank passes theta = pi at t = pi/20: near-singular there
    rh = S.rank_history(r)
    k = int(np.argmin(rh["ratio"]))
    assert abs(r.t[k] - math.pi / 20) < 2e-3 and rh["ratio"][k] < 1e-3
    kinds = {d.kind for d in S.check(r, warn=False)}
    assert kinds & {"near-singular", "rank"}
    # before the change point the mechanism is the parallelogram (rocker angle = crank angle)
    before = r.t < math.pi / 20 - 0.01
    assert np.abs(r.coordinate("rocker.theta")[before] - r.coordinate("crank.theta")[before]).max() < 1e-6


# ---------------------------------------------------------------- 5. redundant constraints
def test_redundant_parallelogram_energy_branch_and_cp():
    system = X.parallelogram(omega=None, extra_link=True, angle=-math.pi / 2 + 0.6).build()
    assert system.n_constraints == 12 and system.n_dof == 1
    te = np.linspace(0, 1.0, 101)
    r = ukflex.simulate(system, 1.0, "DOPRI5", rtol=1e-9, t_eval=te, rank_tolerance=(1e-10, 0.0), stabilization="none", raise_on_failure=True)
    E = r.energy()
    T = np.array([system.kinetic_energy(q, qd) for q, qd in zip(r.q.T, r.qd.T)])
    assert np.ptp(E) < 1e-7 * T.max()
    th = r.coordinate("crank.theta")
    for other in ("rocker.theta", "extra.theta"):
        assert np.abs(r.coordinate(other) - th).max() < 1e-7
    assert S.rank_history(r, 1e-10)["min_rank"] == 11
    cp = ukflex.simulate(system, 1.0, method="DOP853", rtol=1e-9, atol=1e-12, t_eval=te, formulation="cp")
    assert cp.status == 0 and np.abs(cp.q - r.q).max() < 1e-6


def test_redundant_default_tolerance_collapses_step_and_keeps_partial_result():
    """With the default rcond = max(m, n) eps the dropped singular value (~1e-14 sigma_max, from
    rounding) hovers at the tolerance; the rank decision flips between calls and scipy's step
    size collapses near t = 0.915 s.  The failure is raised with everything computed so far."""
    system = X.parallelogram(omega=None, extra_link=True, angle=-math.pi / 2 + 0.6).build()
    with pytest.raises(S.IntegrationFailure) as ei:
        ukflex.simulate(system, 1.0, "DOP853", rtol=1e-8, max_nfev=100_000, rank_tolerance=(None, 0.0), stabilization="none", raise_on_failure=True)
    part = ei.value.result
    assert part is not None and part.status == -1 and part.t[-1] > 0.5
    assert part.max_residual("position") < 1e-6
    assert "right-hand-side calls" in ei.value.reason
    kinds = {d.kind for d in S.check(part, warn=False)}
    assert "fragile-rank" in kinds and kinds & {"redundant", "rank"}


def test_duplicate_joint_equals_the_plain_scene():
    te = np.linspace(0, 0.01, 101)
    a = ukflex.simulate(X.duplicate_joint(), 0.01, "DOPRI5", rtol=1e-10, t_eval=te, rank_tolerance=(1e-10, 0.0), stabilization="none", raise_on_failure=True)
    b = ukflex.simulate(ukflex.scenes.slider_crank(), 0.01, "DOPRI5", rtol=1e-10, t_eval=te, stabilization="none", raise_on_failure=True)
    assert np.abs(v_mid(a) - v_mid(b)).max() < 1e-9
    cp = ukflex.simulate(X.duplicate_joint().build(), 0.001, method="DOP853", rtol=1e-9, atol=1e-12,
                         t_eval=te[te <= 0.001], formulation="cp")
    assert cp.status == 0 and np.abs(v_mid(cp) - v_mid(b)[: cp.t.size]).max() < 1e-9


# ---------------------------------------------------------------- 6. long runs
def test_long_run_drift_before_and_after_stabilization():
    revs = 3
    T = revs * X.REVOLUTION
    te = np.linspace(0, T, 61 * revs)
    system = X.long_run().build()
    runs = {k: ukflex.simulate(system, T, "DOPRI5", rtol=1e-6, t_eval=te, stabilization=st or "none", raise_on_failure=True)
            for k, st in [("none", None), ("baumgarte", ("baumgarte", 100.0, 100.0)), ("projection", "projection")]}
    d = {k: r.max_residual("position") for k, r in runs.items()}
    assert d["projection"] < 1e-11 < d["none"]
    assert d["baumgarte"] < d["none"]
    ref = v_mid(runs["none"])
    for k in ("baumgarte", "projection"):
        assert np.abs(v_mid(runs[k]) - ref).max() < 1e-3 * np.abs(ref).max()
    # scipy path: projection by restarts
    a = ukflex.simulate(system, X.REVOLUTION, "DOP853", rtol=1e-6, stabilization={"kind": "projection", "interval": X.REVOLUTION / 10}, raise_on_failure=True)
    assert a.extra["projections"] == 9 and a.max_residual("position") < 1e-11


# ---------------------------------------------------------------- 7. ill-conditioning
@pytest.mark.parametrize("ratio", [1e-6, 1e6])
def test_mass_ratio_energy_and_cp(ratio):
    system = X.mass_ratio(ratio).build()
    assert np.linalg.cond(system.M(system.q0)) > 1e7
    te = np.linspace(0, 1.0, 101)
    r = ukflex.simulate(system, 1.0, "DOPRI5", rtol=1e-10, t_eval=te, stabilization="none", raise_on_failure=True)
    T = np.array([system.kinetic_energy(q, qd) for q, qd in zip(r.q.T, r.qd.T)])
    assert np.ptp(r.energy()) < 1e-6 * T.max()
    cp = ukflex.simulate(system, 1.0, method="DOP853", rtol=1e-10, atol=1e-13, t_eval=te, formulation="cp")
    assert cp.status == 0 and np.abs(cp.q - r.q).max() < 1e-5


def test_near_massless_slider_equals_paper_and_massless_is_refused():
    te = np.linspace(0, 0.01, 101)
    a = ukflex.simulate(X.near_massless(1e-9), 0.01, "DOPRI5", rtol=1e-10, t_eval=te, stabilization="none", raise_on_failure=True)
    b = ukflex.simulate(ukflex.scenes.slider_crank(), 0.01, "DOPRI5", rtol=1e-10, t_eval=te, stabilization="none", raise_on_failure=True)
    assert np.linalg.cond(a.system.M(a.system.q0)) > 1e11
    assert np.abs(v_mid(a) - v_mid(b)).max() < 1e-6 * np.abs(v_mid(b)).max()
    with pytest.raises(ukflex.InvalidSceneError, match="slider.*mass must be positive"):
        X.near_massless(0.0, slider_inertia=0.0).build()


def test_same_scene_in_mm_gives_the_same_physics():
    te = np.linspace(0, 0.01, 101)
    m = ukflex.simulate(X.slider_crank_units("m"), 0.01, "DOPRI5", rtol=1e-10, t_eval=te, stabilization="none", raise_on_failure=True)
    mm = ukflex.simulate(X.slider_crank_units("mm"), 0.01, "DOPRI5", rtol=1e-10, t_eval=te, stabilization="none", raise_on_failure=True)
    assert np.abs(v_mid(m) - v_mid(mm)).max() < 1e-9 * np.abs(v_mid(m)).max() + 1e-13
    assert np.abs(mm.coordinate("crank.theta") - m.coordinate("crank.theta")).max() < 1e-10


def test_catalogue_scenes_build():
    for c in X.CASES:
        sc = c.build_scene(quick=True)
        assert isinstance(sc, ukflex.Scene)
        assert c.duration(True) <= c.duration(False)
