"""simulate(): the paper's slider-crank over its parameter grid, result helpers, other scenes.

Timings of the slow cases are printed with ``pytest -s`` / ``-rA`` via the recorded properties.
"""

import math
import time

import numpy as np
import pytest

import ukflex
from ukflex import scenes, simulate

T_END = 0.1
LB = scenes.PAPER["coupler_length"]
OMEGA = scenes.PAPER["omega"]

# Every (beam kind, gravity, N) combination of the paper scene runs once over 0..0.1 s at the
# paper's tolerance rtol = 1e-6.  The grid uses DOP853: the coupler's axial (and, for fine meshes,
# shear) modes are excited by the sudden start and have to be resolved at this tolerance, so the
# implicit methods take as many steps as an explicit one and cost 10-20x more per step in scipy
# (Radau ~10 s for N = 1, ~4 min for N = 16 on a loaded 2-core machine; DOP853 1 s and 15 s).
# The default method (Radau) runs the paper's case in test_paper_scene_radau_matches_dop853.
GRID = [
    (beam, gravity, n)
    for beam in ("timoshenko", "euler-bernoulli")
    for gravity in (True, False)
    for n in (1, 2, 4, 8, 16)
]
GRID_METHOD = "DOP853"
RTOL = 1e-6


_PEAKS = {}


@pytest.mark.parametrize("beam,gravity,n", GRID, ids=[f"{b}-{'g' if g else 'nog'}-N{n}" for b, g, n in GRID])
def test_paper_scene_grid(beam, gravity, n, record_property):
    system = scenes.slider_crank(theory=beam, elements=n, gravity=gravity).build()
    t_eval = np.linspace(0.0, T_END, 1001)
    start = time.perf_counter()
    res = simulate(system, T_END, method=GRID_METHOD, rtol=RTOL, t_eval=t_eval)
    record_property("seconds", round(time.perf_counter() - start, 3))
    record_property("nfev", res.nfev)
    assert res.success, res.message
    assert res.t[-1] == pytest.approx(T_END)
    assert res.q.shape == (system.n_coords, 1001)
    # the driver is obeyed: crank angle = omega t (UK enforces it at acceleration level only)
    assert np.abs(res.coordinate("crank.theta") - OMEGA * res.t).max() < 1e-5
    # constraint drift without stabilization stays small over 0.1 s
    assert res.max_residual("position") < 1e-5
    assert res.max_residual("acceleration") < 1e-4 * np.abs(res.qdd()).max()
    # the slider end stays on the X axis and the coupler midpoint deflects by a small fraction of Lb
    _, v = res.beam_displacement("coupler", 0.5)
    w = v / LB
    assert np.all(np.isfinite(w))
    assert w[0] == 0.0
    peak = np.abs(w[res.t <= 0.07]).max()
    assert 1e-4 < peak < 2e-2
    _PEAKS[(beam, gravity, n)] = peak


def test_paper_peaks_converge_with_mesh():
    """Peak midpoint deflection in 0..0.07 s: N = 8 and N = 16 agree closely, the one-element
    model is in the same range, and gravity changes the response (runs from the grid above; if
    they were deselected they are recomputed here)."""
    for key in [(b, g, n) for b in ("timoshenko", "euler-bernoulli") for g in (True, False) for n in (1, 8, 16)]:
        if key not in _PEAKS:
            beam, gravity, n = key
            res = simulate(scenes.slider_crank(theory=beam, elements=n, gravity=gravity), T_END, method=GRID_METHOD,
                           rtol=RTOL, t_eval=np.linspace(0, T_END, 1001))
            _PEAKS[key] = np.abs(res.beam_displacement("coupler", 0.5)[1][res.t <= 0.07]).max() / LB
    for beam in ("timoshenko", "euler-bernoulli"):
        for g in (True, False):
            p1, p8, p16 = (_PEAKS[(beam, g, n)] for n in (1, 8, 16))
            assert abs(p8 - p16) / p16 < 0.02, (beam, g, p8, p16)
            assert 0.5 < p1 / p16 < 2.0, (beam, g, p1, p16)
        assert abs(_PEAKS[(beam, True, 16)] - _PEAKS[(beam, False, 16)]) > 1e-3 * _PEAKS[(beam, True, 16)]


@pytest.mark.parametrize("beam", ["timoshenko", "euler-bernoulli"])
def test_paper_scene_radau_matches_dop853(beam):
    """The paper's case (N = 1, gravity, rtol = 1e-6) with scipy's implicit Radau (and the core's
    Jacobian) agrees with the explicit DOP853; both obey the constraints."""
    t_eval = np.linspace(0.0, T_END, 1001)
    scene = scenes.slider_crank(theory=beam)
    radau = simulate(scene, T_END, method="Radau", rtol=RTOL, t_eval=t_eval)
    dop = simulate(scene, T_END, method="DOP853", rtol=RTOL, t_eval=t_eval)
    assert radau.method == "Radau" and radau.njev > 0
    _, v_r = radau.beam_displacement("coupler", 0.5)
    _, v_d = dop.beam_displacement("coupler", 0.5)
    peak = np.abs(v_d).max()
    assert np.abs(v_r - v_d).max() < 1e-3 * peak
    assert radau.max_residual("position") < 1e-8


def test_default_jacobian_and_bdf():
    """The default Jacobian of the implicit methods (``System.jac``, finite differences in Rust)
    matches central differences of rhs, keeps exactly-zero columns zero, and lets BDF run the
    N = 4 paper scene (scipy's own num_jac overflows on those zero columns and feeds inf into
    rhs)."""
    system = scenes.slider_crank(elements=4).build()
    rng = np.random.default_rng(0)
    y = system.y0.copy()
    y[system.elastic_slice("coupler")] = 1e-5 * rng.standard_normal(12)
    J = system.jac(0.01, y)
    n2 = 2 * system.n_coords
    h = 1e-6 * np.maximum(np.abs(y), 1e-2)
    Jc = np.column_stack(
        [(system.rhs(0.01, y + h[j] * e) - system.rhs(0.01, y - h[j] * e)) / (2 * h[j]) for j, e in enumerate(np.eye(n2))]
    )
    assert np.all(np.isfinite(J))
    assert np.allclose(J, Jc, rtol=1e-4, atol=1e-6 * np.abs(Jc).max())
    assert np.all(J[:, system.coordinate_index("crank.x")] == 0.0)
    res = simulate(system, T_END, method="BDF", rtol=1e-6, atol=1e-6, t_eval=np.linspace(0, T_END, 101))
    assert res.success and res.njev > 0
    assert res.max_residual("position") < 1e-6


def test_result_helpers(tmp_path):
    system = scenes.slider_crank(elements=2).build()
    res = simulate(system, 0.01, t_eval=np.linspace(0, 0.01, 11))
    assert res.t.shape == (11,) and res.qd.shape == (system.n_coords, 11)
    assert res.y.shape == (2 * system.n_coords, 11)
    np.testing.assert_array_equal(res.y, np.vstack([res.q, res.qd]))
    assert set(res.residuals) == {"position", "velocity", "acceleration"}
    assert all(r.shape == (11,) for r in res.residuals.values())
    assert res.nfev > 0 and res.njev > 0 and res.nlu > 0 and res.wall_time > 0
    assert res.status == 0 and res.method == "RADAU5M" and res.extra["auto"]["method"] == "RADAU5M" and res.formulation == "uk"
    u0, v0 = res.beam_displacement("coupler", 0.0)
    assert np.allclose(u0, 0.0) and np.allclose(v0, 0.0)  # pinned frame origin
    _, v1 = res.beam_displacement("coupler", 1.0)
    assert np.allclose(v1, 0.0)
    u1, _ = res.beam_displacement("coupler", 1.0)
    assert np.allclose(u1, system.beam_shape("coupler", 1.0)[0][0] @ res.q[system.elastic_slice("coupler")])
    assert np.array_equal(res.coordinate("coupler.theta"), res.q[5])
    assert np.array_equal(res.velocity("crank.theta"), res.qd[2])
    assert res.multipliers().shape == (6, 11) and res.qdd().shape == (system.n_coords, 11)
    assert res.energy().shape == (11,)
    with pytest.raises(KeyError):
        res.coordinate("coupler.phi")
    path = tmp_path / "r.csv"
    res.to_csv(str(path), columns=["t", "crank.theta", "d:crank.theta", "residual.position"])
    data = np.genfromtxt(path, delimiter=",", names=True)
    assert data.dtype.names == ("t", "cranktheta", "dcranktheta", "residualposition")
    assert np.allclose(data["cranktheta"], res.coordinate("crank.theta"), rtol=1e-15)
    res.to_csv(str(tmp_path / "all.csv"))
    with open(tmp_path / "all.csv") as fh:
        assert fh.readline().strip().split(",")[:3] == ["t", "crank.x", "crank.y"]
    res.save_npz(str(tmp_path / "r.npz"))
    z = np.load(tmp_path / "r.npz")
    assert np.array_equal(z["q"], res.q) and np.array_equal(z["t"], res.t)
    assert list(z["coordinate_names"]) == system.coordinate_names


def test_simulate_accepts_scene_dict_and_methods():
    s = scenes.pendulum()
    a = simulate(s, 0.2, rtol=1e-8, t_eval=[0.0, 0.1, 0.2])
    b = simulate(s.to_dict(), 0.2, rtol=1e-8, t_eval=[0.0, 0.1, 0.2])
    c = simulate(s.build(), 0.2, method="DOP853", rtol=1e-8, t_eval=[0.0, 0.1, 0.2])
    assert np.allclose(a.q, b.q, atol=1e-12)
    assert np.allclose(a.q, c.q, atol=1e-6)
    assert c.method == "DOP853"


def test_simulate_initial_state_override():
    sys_ = scenes.pendulum().build()
    res = simulate(sys_, 0.05, q0=sys_.q0, qd0=np.zeros(3), t_eval=[0, 0.05])
    assert np.array_equal(res.q[:, 0], sys_.q0)


def test_reference_formulations_are_wired():
    """formulation="uk-numpy" / "cp" run the NumPy reference on the same description and come
    back as a SimulationResult that agrees with the Rust run (the thorough cross-validation lives
    in test_cross_validation.py)."""
    t_eval = np.linspace(0.0, 0.003, 4)
    scene = scenes.slider_crank()
    ref = simulate(scene, 0.003, method="DOP853", rtol=1e-9, t_eval=t_eval)
    for form in ("uk-numpy", "cp"):
        res = simulate(scene, 0.003, method="DOP853", formulation=form, rtol=1e-9, t_eval=t_eval)
        assert res.formulation == form and res.success and res.nfev > 0
        assert res.q.shape == ref.q.shape and res.residuals["position"].shape == (4,)
        _, v = res.beam_displacement("coupler", 0.5)
        _, v_ref = ref.beam_displacement("coupler", 0.5)
        assert np.abs(v_ref).max() > 1e-4
        assert np.abs(v - v_ref).max() < 1e-6 * np.abs(v_ref).max()
        assert np.allclose(res.q[:6], ref.q[:6], atol=1e-9)


def test_cantilever_static_deflection():
    """A damped cantilever under its weight and a tip load settles at the Euler-Bernoulli static
    tip deflection  P L^3 / (3 EI) + w L^4 / (8 EI)  (cubic elements are nodally exact)."""
    L, P = 1.0, -2.0
    b, h = 0.02, 0.01
    E, rho = 2.1e11, 7850.0
    EI = E * b * h**3 / 12
    w = -rho * b * h * 9.81
    # first mode ~ 52 rad/s; beta = 2 / 52 gives it critical damping, and every higher
    # (overdamped) mode decays at about 1 / beta = 26 1/s: settled to ~1e-7 by t = 0.6 s
    scene = scenes.cantilever(length=L, elements=4, tip_force=(0.0, P), damping=2.0 / 52.0, strain="linear")
    res = simulate(scene, 0.8, rtol=1e-6, atol=1e-10, t_eval=[0.6, 0.8])
    _, v = res.beam_displacement("beam", 1.0)
    expected = P * L**3 / (3 * EI) + w * L**4 / (8 * EI)
    assert v[-1] == pytest.approx(expected, rel=1e-3)
    assert abs(v[-1] - v[0]) < 1e-4 * abs(expected)  # settled
    # The clamp is linear, so the integrator keeps it up to rounding: UK meets A qdd = b only to
    # ~eps |qdd| (median 4e-9 m/s^2 at perturbed states, |qdd| ~ 1e7), accumulated over ~1500
    # evaluations.  Two builds that differ only in the summation order of the beam's mass
    # products measured 0.7e-12 and 1.5e-12 here; 1e-11 is still ~1e4 eps on a metre.
    assert res.max_residual("position") < 1e-11


def test_every_joint_scene_simulates():
    # undamped beams: DOP853 is ~10x faster than Radau here (see the note on GRID)
    sys_ = scenes.every_joint().build()
    res = simulate(sys_, 0.3, method="DOP853", rtol=1e-6, t_eval=np.linspace(0, 0.3, 31))
    assert res.success, res.message
    assert res.max_residual("position") < 1e-6
    assert res.max_residual("velocity") < 1e-5
    # drivers: crank angle 0.3 sin(5 t); lifter pivot height 0.1 + 0.5 t^2
    assert np.allclose(res.coordinate("crank.theta"), 0.3 * np.sin(5.0 * res.t), atol=1e-6)
    assert np.allclose(res.coordinate("lifter.y"), 0.1 + 0.5 * res.t**2, atol=1e-6)
    assert np.allclose(res.coordinate("lifter.x"), -0.3, atol=1e-6)
    # the prismatic joint keeps the slider on the X axis without rotation
    assert np.allclose(res.coordinate("slider.y"), 0.0, atol=1e-6)
    assert np.allclose(res.coordinate("slider.theta"), 0.0, atol=1e-6)
    # the arm tip load bends the arm
    u, v = res.beam_displacement("arm", 1.0)
    assert np.abs(v).max() > 1e-7


@pytest.mark.parametrize("name", ["double_pendulum", "four_bar"])
def test_rigid_scenes_keep_constraints(name):
    res = simulate(scenes.SCENES[name](), 1.0, rtol=1e-8, t_eval=np.linspace(0, 1, 51))
    assert res.success
    assert res.max_residual("position") < 1e-6


def test_four_bar_with_flexible_coupler():
    res = simulate(scenes.four_bar(theory="timoshenko"), 0.3, method="DOP853", rtol=1e-6,
                   t_eval=np.linspace(0, 0.3, 31))
    assert res.success
    assert res.max_residual("position") < 1e-6
    assert np.allclose(res.coordinate("crank.theta"), math.pi / 2 + 10.0 * res.t, atol=1e-6)


def test_result_from_trajectory_equals_the_simulate_result():
    """SimulationResult.from_trajectory on a raw native run gives what simulate gives (it is
    what simulate uses), and refuses states of the wrong shape (e.g. transposed)."""
    system = scenes.slider_crank(elements=2).build()
    te = np.linspace(0.0, 0.005, 11)
    ref = simulate(system, 0.005, method="DOPRI5", rtol=1e-6, t_eval=te)
    out = system.integrate(system.t0, system.y0, 0.005, "DOPRI5", 1e-6, np.array([1e-9]), te)
    res = ukflex.SimulationResult.from_trajectory(system, out["t"], out["y"], method="DOPRI5", rtol=1e-6,
                                                  nfev=out["nfev"], status=out["status"])
    np.testing.assert_array_equal(res.t, ref.t)
    np.testing.assert_array_equal(res.q, ref.q)
    np.testing.assert_array_equal(res.qd, ref.qd)
    for kind in ("position", "velocity", "acceleration"):
        np.testing.assert_array_equal(res.residuals[kind], ref.residuals[kind])
    assert res.nfev == ref.nfev and res.success and res.system is system
    with pytest.raises(ValueError, match="shape"):
        ukflex.SimulationResult.from_trajectory(system, out["t"], out["y"].T)
