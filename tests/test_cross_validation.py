"""Cross-validation: the Rust core (ukflex._core) against the independent NumPy reference.

Nothing here is skipped: without the compiled extension the import below fails the module.
The Rust side is used through ``ukflex._core.System(json)`` directly (not the Python API
layer), and its trajectories are integrated here with scipy's solve_ivp on ``System.rhs``.
"""
import json
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))

import _ref_scenes as scenes  # noqa: E402
from ukflex import _core  # noqa: E402  (must exist: no skip)
from ukflex.reference import (ReferenceModel, augmented_qdd, correct_initial_state,  # noqa: E402
                              simulate_cp, uk_multipliers, uk_qdd)
from test_reference_model import random_consistent_state, random_state  # noqa: E402


def rust(desc):
    return _core.System(json.dumps(desc))


SCENES = {
    "rigid": scenes.rigid_slider_crank(),
    "pendulum": scenes.pendulum(),
    "paper-timo-1": scenes.slider_crank("timoshenko", 1),
    "paper-timo-2": scenes.slider_crank("timoshenko", 2),
    "paper-timo-8": scenes.slider_crank("timoshenko", 8),
    "paper-eb-1": scenes.slider_crank("euler-bernoulli", 1),
    "paper-eb-2": scenes.slider_crank("euler-bernoulli", 2),
    "paper-eb-8": scenes.slider_crank("euler-bernoulli", 8),
    "paper-timo-4-clamped-nograv": scenes.slider_crank("timoshenko", 4, frame="clamped",
                                                       gravity=False, damping=1e-5),
    "every-joint": scenes.every_joint_scene(),
    "every-joint-swapped": scenes.every_joint_scene("euler-bernoulli", "timoshenko"),
    "line-and-beam": scenes.line_and_beam_scene(),
    "free-beam": scenes.free_beam(),
    "misc": scenes.misc_scene(),
}


def rel(a, b):
    a, b = np.asarray(a), np.asarray(b)
    s = np.abs(b).max() if b.size else 0.0
    return np.abs(a - b).max() / s if s > 0 else (np.abs(a - b).max() if a.size else 0.0)


# ------------------------------------------------------------------ model terms
@pytest.mark.parametrize("name", list(SCENES))
def test_model_terms_agree_at_random_states(name):
    d = SCENES[name]
    r, m = rust(d), ReferenceModel(d)
    assert (r.n_coords, r.n_constraints) == (m.n, m.m)
    q0r, qd0r = r.initial_guess()
    q0, qd0 = m.initial_guess()
    np.testing.assert_array_equal(q0r, q0)
    np.testing.assert_array_equal(qd0r, qd0)
    rng = np.random.default_rng(100)
    for t in (0.0, 0.0731):
        q, qd = random_state(m, rng, scale_f=1e-3)
        assert rel(r.M(q), m.M(q)) < 1e-12
        assert rel(r.Q(t, q, qd), m.Q(t, q, qd)) < 1e-12
        if m.m:
            assert rel(r.phi(t, q), m.phi(t, q)) < 1e-12 or np.abs(r.phi(t, q) - m.phi(t, q)).max() < 1e-15
            assert rel(r.A(q), m.A(q)) < 1e-12
            assert rel(r.phi_t(t), m.phi_t(t)) < 1e-12 or np.abs(m.phi_t(t)).max() == 0
            assert rel(r.b(t, q, qd), m.gamma(t, q, qd)) < 1e-12


@pytest.mark.parametrize("name", ["paper-timo-8", "paper-eb-2", "every-joint", "line-and-beam"])
def test_beam_shapes_agree(name):
    d = SCENES[name]
    r, m = rust(d), ReferenceModel(d)
    for body in d["bodies"]:
        if body["kind"] != "beam":
            continue
        for xi in (0.0, 0.13, 0.5, 0.77, 1.0):
            Sr, Pr = r.beam_shape(body["name"], xi)
            Sm, Pm = m.beam_shape(body["name"], xi)
            np.testing.assert_allclose(Sr, Sm, rtol=0, atol=1e-14 * max(1, np.abs(Sm).max()))
            np.testing.assert_allclose(Pr, Pm, rtol=0, atol=1e-13 * max(1, np.abs(Pm).max()))


def test_energies_agree():
    for name in ("paper-timo-2", "line-and-beam", "free-beam"):
        d = SCENES[name]
        r, m = rust(d), ReferenceModel(d)
        q, qd = random_state(m, np.random.default_rng(101), scale_f=1e-3)
        assert rel(r.kinetic_energy(q, qd), m.kinetic_energy(q, qd)) < 1e-12
        assert rel(r.potential_energy(q) - r.potential_energy(m.initial_guess()[0]),
                   m.potential_energy(q) - m.potential_energy(m.initial_guess()[0])) < 1e-10


def test_builtin_api_scene_is_the_reference_scene():
    """ukflex.scenes.slider_crank().to_dict() describes the same system as tests/_ref_scenes
    (the pivot joint is declared ground-first there, so its two rows change sign)."""
    from ukflex import scenes as api_scenes
    for beam in ("timoshenko", "euler-bernoulli"):
        da = api_scenes.slider_crank(theory=beam, elements=2).to_dict()
        ma, mr = ReferenceModel(da), ReferenceModel(scenes.slider_crank(beam, 2))
        ra = rust(da)
        q, qd = random_state(mr, np.random.default_rng(102))
        np.testing.assert_array_equal(ma.M(q), mr.M(q))
        np.testing.assert_array_equal(ma.Q(0.1, q, qd), mr.Q(0.1, q, qd))
        sign = np.array([-1, -1, 1, 1, 1, 1.0])
        np.testing.assert_allclose(ma.A(q), sign[:, None] * mr.A(q), atol=1e-15)
        assert rel(ra.qdd(0.1, *correct_initial_state(ma, q, qd, t0=0.1)),
                   uk_qdd(*ma.terms(0.1, *correct_initial_state(ma, q, qd, t0=0.1)))) < 1e-9


# ------------------------------------------------------------------ accelerations
@pytest.mark.parametrize("name", [k for k in SCENES if k != "free-beam"])
def test_accelerations_and_multipliers_agree(name):
    d = SCENES[name]
    r, m = rust(d), ReferenceModel(d)
    rng = np.random.default_rng(103)
    for t in (0.0, 0.05):
        q, qd = random_consistent_state(m, rng, t)
        M, Q, A, b = m.terms(t, q, qd)
        qdd_aug, lam_aug = augmented_qdd(M, Q, A, b)
        qdd_np = uk_qdd(M, Q, A, b)
        lam_np = uk_multipliers(M, Q, A, b)
        qdd_r = r.qdd(t, q, qd)
        lam_r = r.multipliers(t, q, qd)
        # the symmetric root of M (eigh) costs accuracy ~ cond(M) eps; the saddle point and
        # Rust's Cholesky-based UK are ~100x closer to each other
        assert rel(qdd_r, qdd_aug) < 1e-10
        assert rel(qdd_np, qdd_aug) < 1e-9
        assert rel(qdd_r, qdd_np) < 1e-9
        assert rel(lam_r, lam_aug) < 1e-10
        assert rel(lam_r, lam_np) < 1e-10
        np.testing.assert_allclose(r.rhs(t, np.r_[q, qd]), np.r_[qd, qdd_r], rtol=0, atol=0)
        # residuals reported by Rust are the ones we compute
        pr, vr, ar = r.residuals(t, q, qd)
        np.testing.assert_allclose(pr, m.phi(t, q), rtol=0, atol=1e-15)
        np.testing.assert_allclose(vr, A @ qd + m.phi_t(t), rtol=0, atol=1e-12)
        np.testing.assert_allclose(ar, A @ qdd_r - b, rtol=0,
                                   atol=1e-12 * (np.abs(A) @ np.abs(qdd_r) + np.abs(b)).max())


def test_redundant_constraints_agree():
    d = scenes.rigid_slider_crank()
    d["joints"].append(json.loads(json.dumps(d["joints"][1])))
    r, m = rust(d), ReferenceModel(d)
    q, qd = random_consistent_state(m, np.random.default_rng(104))
    M, Q, A, b = m.terms(0.0, q, qd)
    qdd_aug, _ = augmented_qdd(M, Q, A, b)
    assert rel(r.qdd(0.0, q, qd), qdd_aug) < 1e-10
    lam_r = r.multipliers(0.0, q, qd)
    np.testing.assert_allclose(M @ qdd_aug + A.T @ lam_r, Q, atol=1e-9 * np.abs(Q).max())
    assert rel(lam_r, uk_multipliers(M, Q, A, b)) < 1e-9     # both minimum-norm
    assert r.rank()[0] == m.m - 2


# ------------------------------------------------------------------ trajectories
T_SHORT = 5e-3
T_EVAL = np.linspace(0.0, T_SHORT, 11)


def rust_trajectory(d, q0, qd0, t_end, t_eval, rtol, atol, method="DOP853"):
    r = rust(d)
    sol = solve_ivp(r.rhs, (0.0, t_end), np.r_[q0, qd0], method=method, rtol=rtol, atol=atol,
                    t_eval=t_eval)
    assert sol.success
    return sol


def midpoint_deflection(m, q):
    S, _ = m.beam_shape("coupler", 0.5)
    b = m.body("coupler")
    return (S @ q[b.offset + 3:b.offset + b.n])[1] / b.length


@pytest.mark.parametrize("beam", ["timoshenko", "euler-bernoulli"])
@pytest.mark.parametrize("gravity", [True, False])
def test_paper_trajectory_rust_uk_vs_numpy_cp(beam, gravity):
    d = scenes.slider_crank(beam, 1, gravity=gravity)
    m = ReferenceModel(d)
    q0, qd0 = correct_initial_state(m)
    rtol, atol = 1e-8, 1e-11
    sr = rust_trajectory(d, q0, qd0, T_SHORT, T_EVAL, rtol, atol)
    cp = simulate_cp(m, T_SHORT, method="DOP853", rtol=rtol, atol=atol, t_eval=T_EVAL, q0=q0,
                     qd0=qd0)
    assert cp.success and cp.repartitions == 0
    vr, vc = midpoint_deflection(m, sr.y[:m.n]), midpoint_deflection(m, cp.q)
    assert np.abs(vr).max() > 5e-3                       # a real deflection (~0.8 % of Lb)
    assert np.abs(vr - vc).max() < 100 * rtol * np.abs(vr).max()
    # the whole state, too (CP keeps Phi = 0 exactly, UK drifts a little)
    np.testing.assert_allclose(sr.y[:m.n], cp.q, rtol=0, atol=1e-8)


def test_paper_trajectory_agreement_tightens_with_rtol():
    d = scenes.slider_crank("timoshenko", 1, gravity=True)
    m = ReferenceModel(d)
    q0, qd0 = correct_initial_state(m)
    diffs = []
    for rtol in (1e-6, 1e-8, 1e-10):
        atol = 1e-3 * rtol
        sr = rust_trajectory(d, q0, qd0, T_SHORT, T_EVAL, rtol, atol)
        cp = simulate_cp(m, T_SHORT, method="DOP853", rtol=rtol, atol=atol, t_eval=T_EVAL,
                         q0=q0, qd0=qd0)
        vr, vc = midpoint_deflection(m, sr.y[:m.n]), midpoint_deflection(m, cp.q)
        diffs.append(np.abs(vr - vc).max() / np.abs(vr).max())
        assert diffs[-1] < 100 * rtol
    # measured (2-core box): 9.8e-10, 6.2e-11, 1.4e-12
    assert diffs[0] > 5 * diffs[1] > 25 * diffs[2]


def test_pendulum_cp_repartitions_and_matches_rust_uk():
    d = scenes.pendulum()
    m = ReferenceModel(d)
    q0, qd0 = correct_initial_state(m)
    te = np.linspace(0.0, 3.0, 31)
    sr = rust_trajectory(d, q0, qd0, 3.0, te, 1e-10, 1e-12)
    cp = simulate_cp(m, 3.0, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=te, q0=q0, qd0=qd0)
    assert cp.success and cp.repartitions >= 2
    np.testing.assert_allclose(cp.q, sr.y[:3], atol=1e-7)
    np.testing.assert_allclose(cp.qd, sr.y[3:], atol=1e-6)


def test_every_joint_scene_trajectory_rust_vs_cp():
    d = scenes.every_joint_scene()
    m = ReferenceModel(d)
    q0, qd0 = correct_initial_state(m)
    te = np.linspace(0.0, 1e-3, 5)
    sr = rust_trajectory(d, q0, qd0, 1e-3, te, 1e-8, 1e-11, method="BDF")
    cp = simulate_cp(m, 1e-3, method="BDF", rtol=1e-8, atol=1e-11, t_eval=te, q0=q0, qd0=qd0)
    assert cp.success
    assert np.abs(cp.q - q0[:, None]).max() > 1e-3          # it moved
    np.testing.assert_allclose(cp.q, sr.y[:m.n], atol=1e-7)
