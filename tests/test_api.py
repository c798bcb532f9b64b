"""Public API of the compiled system: shapes, names, the UK equations, initial-state correction."""

import math
import os
import subprocess
import sys

import numpy as np
import pytest

import ukflex
from ukflex import Scene, scenes


@pytest.fixture(scope="module")
def crank():
    return scenes.slider_crank().build()


def test_package_exports():
    for name in ukflex.__all__:
        assert hasattr(ukflex, name), name
    import ukflex._core as core

    assert ukflex.UkflexError is core.UkflexError
    assert ukflex.InvalidSceneError is core.InvalidSceneError
    assert ukflex.SingularMassError is core.SingularMassError
    assert ukflex.SolverError is core.SolverError
    assert ukflex.NonFiniteError is core.NonFiniteError
    assert issubclass(ukflex.InconsistentInitialStateError, core.UkflexError)


def test_layout_and_names(crank):
    n, m = crank.n_coords, crank.n_constraints
    assert (n, m) == (9, 6)
    assert crank.body_names == ["crank", "coupler"]
    assert crank.body_slices == {"crank": (0, 3), "coupler": (3, 9)}
    assert crank.coordinate_names[:6] == ["crank.x", "crank.y", "crank.theta", "coupler.x", "coupler.y", "coupler.theta"]
    assert len(crank.coordinate_names) == n and len(set(crank.coordinate_names)) == n
    assert len(crank.constraint_names) == m and len(set(crank.constraint_names)) == m
    # the user's joint names appear in the row names
    for name in ("crank_pivot", "crank_coupler", "slider", "crank_speed"):
        assert any(name in row for row in crank.constraint_names), (name, crank.constraint_names)
    assert crank.elastic_slice("coupler") == slice(6, 9)
    assert crank.coordinate_index("coupler.theta") == 5
    assert crank.n_dof == 3
    with pytest.raises(KeyError, match="nope"):
        crank.coordinate_index("nope")
    with pytest.raises(KeyError, match="rigid"):
        crank.elastic_slice("crank")


def test_shapes(crank):
    n, m = crank.n_coords, crank.n_constraints
    q, qd, t = crank.q0, crank.qd0, 0.0
    assert crank.M(q).shape == (n, n)
    assert crank.Q(t, q, qd).shape == (n,)
    assert crank.phi(t, q).shape == (m,)
    assert crank.A(q).shape == (m, n)
    assert crank.phi_t(t).shape == (m,)
    assert crank.b(t, q, qd).shape == (m,)
    assert crank.qdd(t, q, qd).shape == (n,)
    assert crank.rhs(t, crank.y0).shape == (2 * n,)
    assert crank.multipliers(t, q, qd).shape == (m,)
    rp, rv, ra = crank.residuals(t, q, qd)
    assert rp.shape == rv.shape == ra.shape == (m,)
    rank, smin = crank.rank()
    assert rank == m and smin > 0
    S, Npsi = crank.beam_shape("coupler", 0.5)
    assert np.shape(S) == (2, 3) and np.shape(Npsi) == (3,)
    assert np.isscalar(crank.kinetic_energy(q, qd)) or np.ndim(crank.kinetic_energy(q, qd)) == 0
    for a in (crank.M(q), crank.Q(t, q, qd), crank.A(q), crank.rhs(t, crank.y0)):
        assert a.dtype == np.float64


def test_rhs_is_the_compiled_method(crank):
    # no Python layer on the hot path
    assert crank.rhs.__self__ is crank.core
    assert crank.qdd.__self__ is crank.core


def test_uk_equations_hold(crank):
    """qdd satisfies A qdd = b and M qdd + A^T lam = Q with the reported multipliers, at a
    generic (consistent) state."""
    rng = np.random.default_rng(1)
    n = crank.n_coords
    q = crank.q0.copy()
    qd = crank.qd0.copy()
    q[crank.elastic_slice("coupler")] = 1e-4 * rng.standard_normal(3)  # deformed, still consistent
    t = 0.0
    qdd = crank.qdd(t, q, qd)
    M, Q, A, b = crank.M(q), crank.Q(t, q, qd), crank.A(q), crank.b(t, q, qd)
    lam = crank.multipliers(t, q, qd)
    scale = np.abs(Q).max() + np.abs(M @ qdd).max()
    assert np.allclose(A @ qdd, b, atol=1e-9 * (1 + np.abs(b).max()))
    assert np.allclose(M @ qdd + A.T @ lam, Q, atol=1e-9 * scale)
    assert np.allclose(M, M.T, atol=1e-14 * np.abs(M).max())
    assert np.all(np.linalg.eigvalsh(M) > 0)
    y = np.concatenate([q, qd])
    assert np.allclose(crank.rhs(t, y), np.concatenate([qd, qdd]), rtol=1e-13, atol=1e-13 * np.abs(qdd).max())
    _, _, ra = crank.residuals(t, q, qd)
    assert np.allclose(ra, A @ qdd - b, atol=1e-9 * (1 + np.abs(b).max()))


def test_A_is_the_jacobian_of_phi(crank):
    rng = np.random.default_rng(2)
    q = crank.q0 + 1e-2 * rng.standard_normal(crank.n_coords)
    A = crank.A(q)
    h = 1e-7
    fd = np.column_stack(
        [(crank.phi(0.0, q + h * e) - crank.phi(0.0, q - h * e)) / (2 * h) for e in np.eye(crank.n_coords)]
    )
    assert np.allclose(A, fd, atol=1e-7)
    # phi_t: the crank driver moves at omega
    assert np.allclose(crank.phi_t(0.0), [0, 0, 0, 0, 0, -124.8])


def test_paper_initial_state_is_exactly_consistent(crank, paper_data):
    rep = crank.initial_correction
    assert rep.position_residual_before < 1e-14
    assert rep.velocity_residual_before < 1e-12
    assert rep.max_position_change < 1e-14 and rep.max_velocity_change < 1e-12
    L, Lb, w = paper_data["crank_length"], paper_data["coupler_length"], paper_data["omega"]
    q0, qd0 = crank.q0, crank.qd0
    assert q0 == pytest.approx([0, 0, 0, L, 0, 0, 0, 0, 0], abs=1e-15)
    assert qd0 == pytest.approx([0, 0, w, 0, L * w, -L * w / Lb, 0, 0, 0], abs=1e-12)
    assert rep.held == ["coupler.qf0", "coupler.qf1", "coupler.qf2"]


def test_beam_shape_reference_conditions(crank):
    # pinned-pinned frame: u(0) = v(0) = 0 and v(L) = 0 for any q_f
    S0, _ = crank.beam_shape("coupler", 0.0)
    S1, N1 = crank.beam_shape("coupler", 1.0)
    assert np.allclose(S0, 0.0)
    assert np.allclose(S1[1], 0.0)
    # q_f = [psi_1, u_2, psi_2]: u(L) = u_2, psi(L) = psi_2
    assert np.allclose(S1[0], [0, 1, 0])
    assert np.allclose(N1, [0, 0, 1])
    with pytest.raises(ValueError, match="crank"):
        crank.beam_shape("crank", 0.5)
    with pytest.raises(KeyError, match="ghost"):
        crank.beam_shape("ghost", 0.5)
    with pytest.raises(ValueError, match="xi"):
        crank.beam_shape("coupler", 1.5)


def test_position_and_velocity_correction():
    """A perturbed guess is moved onto Phi = 0 (Newton, mass metric) and its velocities projected
    onto A qd = -Phi_t; elastic coordinates stay held."""
    s = scenes.slider_crank()
    d = s.to_dict()
    d["bodies"][1]["angle"] = 0.05  # coupler tilted: the slider end leaves the X axis
    d["bodies"][1]["position"] = [0.15, 0.004]
    d["bodies"][1]["angular_velocity"] = -50.0
    d["bodies"][1]["elastic"] = [1e-4, 0.0, -1e-4]
    sys_ = ukflex.System(d)
    rep = sys_.initial_correction
    assert rep.iterations >= 1
    assert rep.position_residual_before > 1e-3
    assert rep.position_residual_after <= 1e-12
    assert np.abs(sys_.phi(0.0, sys_.q0)).max() <= 1e-12
    assert np.abs(sys_.A(sys_.q0) @ sys_.qd0 + sys_.phi_t(0.0)).max() <= 1e-9
    el = sys_.elastic_slice("coupler")
    assert np.array_equal(sys_.q0[el], [1e-4, 0.0, -1e-4])  # held exactly
    assert np.array_equal(sys_.qd0[el], np.zeros(3))
    # the crank is pinned and driven: it is already consistent and must not move
    assert np.allclose(sys_.q0[:3], 0.0, atol=1e-14)
    assert rep.velocity_residual_before > 1.0
    assert "Newton" in str(rep)
    assert set(rep.per_coordinate()) == set(sys_.coordinate_names)


def test_velocity_projection_is_the_mass_weighted_minimum():
    """Among all consistent velocities, the projection is the closest to the guess in the M norm."""
    d = scenes.double_pendulum().to_dict()
    d["bodies"][0]["angular_velocity"] = 1.0  # inconsistent guess: only rotation, no translation
    d["bodies"][1]["velocity"] = [0.3, -0.2]
    sys_ = ukflex.System(d)
    q, qd_g, qd = sys_.q0, sys_.qd_guess, sys_.qd0
    A, M = sys_.A(q), sys_.M(q)
    assert np.abs(A @ qd + sys_.phi_t(0.0)).max() < 1e-12
    # optimality: M (qd - qd_g) lies in the row space of A  <=>  orthogonal to null(A)
    _, sv, vt = np.linalg.svd(A)
    null = vt[np.sum(sv > 1e-12):].T
    assert null.shape[1] == 2
    assert np.abs(null.T @ (M @ (qd - qd_g))).max() < 1e-12


def test_hold_none_and_explicit_names():
    d = scenes.pendulum().to_dict()
    d["bodies"][0]["position"] = [0.4, -0.3]  # the rod centre should be at 0.5 (cos, sin) of angle
    a = ukflex.System(d)
    assert np.abs(a.phi(0.0, a.q0)).max() < 1e-12
    # holding the angle: only x, y move; with the angle free the mass metric also turns the rod
    b = ukflex.System(d, hold=["rod.theta"])
    assert b.q0[2] == d["bodies"][0]["angle"]
    assert np.abs(b.phi(0.0, b.q0)).max() < 1e-12
    assert a.q0[2] != b.q0[2]
    c = ukflex.System(d, correct=False)
    assert np.array_equal(c.q0, c.q_guess)
    assert c.initial_correction.position_residual_after > 0.01


def test_system_accepts_scene_and_dict_and_keeps_description():
    s = scenes.pendulum()
    a, b = s.build(), ukflex.System(s.to_dict())
    assert a.description == b.description == s.to_dict()
    assert np.array_equal(a.q0, b.q0)
    with pytest.raises(TypeError):
        ukflex.System("pendulum")


def test_energy_helpers(crank):
    q, qd = crank.q0, crank.qd0
    T = crank.kinetic_energy(q, qd)
    assert T == pytest.approx(0.5 * qd @ crank.M(q) @ qd, rel=1e-12)
    # potential energy at q0: gravity of the crank (com at y = 0) and coupler (y = 0) is 0
    assert crank.potential_energy(q) == pytest.approx(0.0, abs=1e-12)
    q2 = q.copy()
    q2[4] += 0.01  # lift the coupler by 1 cm
    m_coupler = crank.M(q)[3, 3]
    assert crank.potential_energy(q2) == pytest.approx(m_coupler * 9.81 * 0.01, rel=1e-9)


def test_every_joint_scene_builds_consistently():
    sys_ = scenes.every_joint().build()
    assert (sys_.n_coords, sys_.n_constraints) == (24, 14)
    assert sys_.n_dof == 10
    assert np.abs(sys_.phi(0.0, sys_.q0)).max() < 1e-12
    assert np.abs(sys_.A(sys_.q0) @ sys_.qd0 + sys_.phi_t(0.0)).max() < 1e-9
    sys_.qdd(0.0, sys_.q0, sys_.qd0)
    rank, _ = sys_.rank()
    assert rank == 14


def test_cli_list_and_paper(tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg")
    out = subprocess.run([sys.executable, "-m", "ukflex", "list"], capture_output=True, text=True, env=env)
    assert out.returncode == 0 and "slider_crank" in out.stdout
    outdir = tmp_path / "paper"
    out = subprocess.run(
        [sys.executable, "-m", "ukflex", "paper", "--out", str(outdir), "--t-end", "0.01", "--samples", "101"],
        capture_output=True,
        text=True,
        env=env,
    )
    assert out.returncode == 0, out.stderr
    assert "timoshenko" in out.stdout and "euler-bernoulli" in out.stdout and "peak" in out.stdout
    data = np.genfromtxt(outdir / "fig4.csv", delimiter=",", names=True)
    assert data.dtype.names == ("t", "v_mid_over_Lb_timoshenko", "v_mid_over_Lb_euler_bernoulli")
    assert data["t"].size == 101 and data["t"][-1] == pytest.approx(0.01)
    assert np.all(np.isfinite(data["v_mid_over_Lb_timoshenko"]))
    assert data["v_mid_over_Lb_timoshenko"][0] == 0.0  # undeformed start
    assert np.abs(data["v_mid_over_Lb_euler_bernoulli"]).max() > 0.0
    assert (outdir / "fig4.png").stat().st_size > 10_000
    bad = subprocess.run([sys.executable, "-m", "ukflex", "paper", "--out", str(outdir), "--t-end", "-1"],
                         capture_output=True, text=True, env=env)
    assert bad.returncode != 0 and "t-end" in bad.stderr


def test_cli_run(tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg")
    out = subprocess.run(
        [sys.executable, "-m", "ukflex", "run", "pendulum", "--t-end", "0.5", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        env=env,
    )
    assert out.returncode == 0, out.stderr
    assert "energy" in out.stdout and "max ||Phi||" in out.stdout
    assert (tmp_path / "pendulum.csv").exists() and (tmp_path / "pendulum.npz").exists()
    bad = subprocess.run(
        [sys.executable, "-m", "ukflex", "run", "slider_crank", "--param", "theory=eb"],
        capture_output=True,
        text=True,
        env=env,
    )
    assert bad.returncode == 2
    assert "InvalidSceneError" in bad.stderr and "'eb'" in bad.stderr and "Traceback" not in bad.stderr
