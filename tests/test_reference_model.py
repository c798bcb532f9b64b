"""Self-tests of the NumPy reference model (no Rust needed).

Every check compares the reference against something computed another way: the paper's
Appendix A closed forms, finite differences, a brute-force kinetic energy, energy balance.
"""
import copy
import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))

import _ref_scenes as scenes  # noqa: E402
from ukflex.reference import (ReferenceModel, augmented_qdd, correct_initial_state,  # noqa: E402
                              element_matrices, element_shape, simulate_uk_numpy, uk_multipliers,
                              uk_qdd)
from ukflex.reference.model import element_shape_derivatives  # noqa: E402


def all_scenes():
    return {
        "paper-timo-1": scenes.slider_crank("timoshenko", 1),
        "paper-eb-2": scenes.slider_crank("euler-bernoulli", 2),
        "paper-timo-8-clamped": scenes.slider_crank("timoshenko", 8, frame="clamped"),
        "rigid": scenes.rigid_slider_crank(),
        "every-joint": scenes.every_joint_scene(),
        "line-and-beam": scenes.line_and_beam_scene(),
        "pendulum": scenes.pendulum(),
        "free-beam": scenes.free_beam(),
    }


def random_state(model, rng, scale_f=1e-3):
    """Random (not necessarily consistent) state near the initial guess."""
    q, qd = model.initial_guess()
    q = q + rng.normal(scale=0.2, size=q.size)
    qd = rng.normal(scale=2.0, size=q.size)
    for b in model.bodies:
        if b.kind == "beam":
            sl = slice(b.offset + 3, b.offset + b.n)
            q[sl] = rng.normal(scale=scale_f, size=b.n_f)
            qd[sl] = rng.normal(scale=100 * scale_f, size=b.n_f)
    return q, qd


def random_consistent_state(model, rng, t=0.0):
    q, qd = model.initial_guess()
    q = q + rng.normal(scale=0.02, size=q.size)
    qd = qd + rng.normal(scale=1.0, size=q.size)
    for b in model.bodies:
        if b.kind == "beam":
            sl = slice(b.offset + 3, b.offset + b.n)
            q[sl] = rng.normal(scale=1e-4, size=b.n_f)
            qd[sl] = rng.normal(scale=1e-2, size=b.n_f)
    return correct_initial_state(model, q, qd, t0=t)


PARAMS = dict(l=0.3048, rho=7834.56, a=math.pi * 0.00635**2 / 4, I=math.pi * 0.00635**4 / 64,
              E=2.06843e11, G=2.06843e11 / (2 * 1.285), k=0.8)


# ------------------------------------------------------------------ shape functions
@pytest.mark.parametrize("phi", [0.0, 1e-3, 0.7])
def test_shape_functions_nodal_values(phi):
    l = 0.2
    Nv, Np = element_shape(np.array([0.0, 1.0]), l, phi)
    e = np.eye(6)
    # at s=0: u=u_j, v=v_j, psi=psi_j ; at s=1 the j+1 values
    np.testing.assert_allclose(Nv[0] @ e, e[[0, 1]], atol=1e-15)
    np.testing.assert_allclose(Np[0], e[2], atol=1e-15)
    np.testing.assert_allclose(Nv[1] @ e, e[[3, 4]], atol=1e-15)
    np.testing.assert_allclose(Np[1], e[5], atol=1e-15)


@pytest.mark.parametrize("phi", [0.0, 1e-3, 0.7])
def test_shape_function_derivatives_and_shear_strain(phi):
    l = 0.2
    s = np.linspace(0.05, 0.95, 7)
    h = 1e-6
    Nvp, Npp = element_shape(s + h, l, phi)
    Nvm, Npm = element_shape(s - h, l, phi)
    du, dv, dp = element_shape_derivatives(s, l, phi)
    np.testing.assert_allclose(du, (Nvp[:, 0] - Nvm[:, 0]) / (2 * h * l), atol=1e-7)
    np.testing.assert_allclose(dv, (Nvp[:, 1] - Nvm[:, 1]) / (2 * h * l), atol=1e-7)
    np.testing.assert_allclose(dp, (Npp - Npm) / (2 * h * l), atol=1e-6)
    _, Np = element_shape(s, l, phi)
    gamma = Np - dv                      # shear strain: constant along the Davis element
    np.testing.assert_allclose(gamma, np.broadcast_to(gamma[0], gamma.shape), atol=1e-13)
    if phi == 0.0:                       # Euler-Bernoulli: psi = dv/dx exactly
        np.testing.assert_allclose(Np, dv, atol=1e-14)
    else:
        assert abs(gamma[0, 2] - phi / 2 / (1 + phi)) < 1e-14


def appendix_a_mass(l, rho, a, I, phi):
    """Paper's Appendix A mass matrix, as printed (entries listed there)."""
    f, d = phi, (1 + phi) ** 2
    m = np.zeros((6, 6))
    m[0, 0] = m[3, 3] = rho * a * l / 3
    m[0, 3] = rho * a * l / 6
    m[1, 1] = m[4, 4] = rho * a * l * (70 * f**2 + 147 * f + 78) / (210 * d) + 36 * rho * I / (30 * d * l)
    m[1, 2] = rho * a * l**2 * (35 * f**2 + 77 * f + 44) / (840 * d) - rho * I * (15 * f - 3) / (30 * d)
    m[1, 4] = rho * a * l * (35 * f**2 + 63 * f + 27) / (210 * d) - 36 * rho * I / (30 * d * l)
    m[1, 5] = -rho * a * l**2 * (35 * f**2 + 63 * f + 26) / (840 * d) - rho * I * (15 * f - 3) / (30 * d)
    m[2, 2] = m[5, 5] = (rho * a * l**3 * (7 * f**2 + 14 * f + 8) / (840 * d)
                         + rho * I * (10 * f**2 + 5 * f + 4) * l / (30 * d))
    m[2, 4] = rho * a * l**2 * (35 * f**2 + 63 * f + 26) / (840 * d) + rho * I * (15 * f - 3) / (30 * d)
    m[2, 5] = (-rho * a * l**3 * (7 * f**2 + 14 * f + 6) / (840 * d)
               + rho * I * (5 * f**2 - 5 * f - 1) * l / (30 * d))
    m[4, 5] = -rho * a * l**2 * (35 * f**2 + 77 * f + 44) / (840 * d) + rho * I * (15 * f - 3) / (30 * d)
    return np.triu(m) + np.triu(m, 1).T


def appendix_a_stiffness(l, a, I, E, phi):
    """Paper's eq. (75)."""
    f = phi
    k = np.array([
        [a * (1 + f) / l, 0, 0, -a * (1 + f) / l, 0, 0],
        [0, 12 * I / l**3, 6 * I / l**2, 0, -12 * I / l**3, 6 * I / l**2],
        [0, 6 * I / l**2, (4 + f) * I / l, 0, -6 * I / l**2, (2 - f) * I / l],
        [-a * (1 + f) / l, 0, 0, a * (1 + f) / l, 0, 0],
        [0, -12 * I / l**3, -6 * I / l**2, 0, 12 * I / l**3, -6 * I / l**2],
        [0, 6 * I / l**2, (2 - f) * I / l, 0, -6 * I / l**2, (4 + f) * I / l]])
    return E / (1 + f) * k


@pytest.mark.parametrize("l", [0.3048, 0.0381, 0.01])
def test_element_matrices_match_appendix_a(l):
    p = dict(PARAMS, l=l)
    phi = 12 * p["E"] * p["I"] / (p["k"] * p["G"] * p["a"] * l**2)
    m, K = element_matrices(l, p["rho"], p["a"], p["I"], p["E"], p["G"], p["k"], phi)
    mA = appendix_a_mass(l, p["rho"], p["a"], p["I"], phi)
    KA = appendix_a_stiffness(l, p["a"], p["I"], p["E"], phi)
    scale_m = np.abs(mA).max()
    np.testing.assert_allclose(m, mA, rtol=1e-10, atol=1e-12 * scale_m)
    np.testing.assert_allclose(K, KA, rtol=1e-10, atol=1e-12 * np.abs(KA).max())
    # Euler-Bernoulli limit: no shear term, classic 4, 2 stiffness
    m0, K0 = element_matrices(l, p["rho"], p["a"], p["I"], p["E"], p["G"], p["k"], 0.0, rotary=False)
    KA0 = appendix_a_stiffness(l, p["a"], p["I"], p["E"], 0.0)
    np.testing.assert_allclose(K0, KA0, rtol=1e-12, atol=1e-12 * np.abs(KA0).max())
    np.testing.assert_allclose(m0[2, 2], p["rho"] * p["a"] * l**3 / 105, rtol=1e-12)


def test_beam_shape_interpolates_nodes_across_elements():
    m = ReferenceModel(scenes.slider_crank("timoshenko", 4))
    b = m.body("coupler")
    rng = np.random.default_rng(1)
    qf = rng.normal(size=b.n_f)
    e = b.B @ qf
    for j in range(5):
        S, Np = m.beam_shape("coupler", j / 4)
        np.testing.assert_allclose(S @ qf, e[3 * j:3 * j + 2], atol=1e-14)
        np.testing.assert_allclose(Np @ qf, e[3 * j + 2], atol=1e-14)
    # pinned-pinned: u1 = v1 = v_{N+1} = 0 whatever q_f
    S0, _ = m.beam_shape("coupler", 0.0)
    S1, _ = m.beam_shape("coupler", 1.0)
    assert np.abs(S0 @ qf).max() == 0 and abs((S1 @ qf)[1]) < 1e-15


# ------------------------------------------------------------------ mass matrix
@pytest.mark.parametrize("name", list(all_scenes()))
def test_mass_matrix_symmetric_positive_definite(name):
    m = ReferenceModel(all_scenes()[name])
    rng = np.random.default_rng(2)
    for _ in range(3):
        q, _ = random_state(m, rng)
        M = m.M(q)
        np.testing.assert_allclose(M, M.T, rtol=0, atol=1e-15 * np.abs(M).max())
        assert np.linalg.eigvalsh(M).min() > 0


def brute_force_kinetic_energy(model, q, qd, npts=400):
    """1/2 int rho a |r_dot|^2 + 1/2 int rho I (theta_dot + psi_dot)^2 by a fine midpoint sum,
    r_dot from central differences of world positions along qd (no use of M or L)."""
    T = 0.0
    h = 1e-7
    for b in model.bodies:
        o = b.offset
        if b.kind == "rigid":
            def com(qq):
                c, s = math.cos(qq[o + 2]), math.sin(qq[o + 2])
                return qq[o:o + 2] + np.array([[c, -s], [s, c]]) @ b.com
            v = (com(q + h * qd) - com(q - h * qd)) / (2 * h)
            T += 0.5 * b.mass * v @ v + 0.5 * b.inertia * qd[o + 2] ** 2
            continue
        xi = (np.arange(npts) + 0.5) / npts
        dx = b.length / npts
        for x in xi:
            S, Np = model.beam_shape(b.name, x)

            def pos(qq):
                c, s = math.cos(qq[o + 2]), math.sin(qq[o + 2])
                u = np.array([x * b.length, 0.0]) + S @ qq[o + 3:o + b.n]
                return qq[o:o + 2] + np.array([[c, -s], [s, c]]) @ u
            v = (pos(q + h * qd) - pos(q - h * qd)) / (2 * h)
            T += 0.5 * b.rho * b.area * dx * v @ v
            if b.rotary:
                T += 0.5 * b.rho * b.I * dx * (qd[o + 2] + Np @ qd[o + 3:o + b.n]) ** 2
    return T


@pytest.mark.parametrize("name", ["paper-timo-1", "paper-eb-2", "every-joint", "free-beam"])
def test_mass_matrix_against_brute_force_kinetic_energy(name):
    m = ReferenceModel(all_scenes()[name])
    rng = np.random.default_rng(3)
    q, qd = random_state(m, rng, scale_f=1e-2)
    T = 0.5 * qd @ m.M(q) @ qd
    Tb = brute_force_kinetic_energy(m, q, qd)
    # midpoint rule error ~ (1/npts)^2
    assert abs(T - Tb) < 1e-5 * T


def test_rigid_limits_of_beam_mass_matrix():
    d = scenes.slider_crank("timoshenko", 3)
    m = ReferenceModel(d)
    b = m.body("coupler")
    q, _ = m.initial_guess()
    M = m.M(q)[b.offset:b.offset + 3, b.offset:b.offset + 3]
    mass = b.rho * b.area * b.length
    J = mass * b.length**2 / 3 + b.rho * b.I * b.length       # bar about its end + rotary
    np.testing.assert_allclose(M, [[mass, 0, 0], [0, mass, mass * b.length / 2],
                                   [0, mass * b.length / 2, J]], rtol=1e-13, atol=1e-15)


# ------------------------------------------------------------------ forces
def no_velocity_forces(d):
    d = copy.deepcopy(d)
    for body in d["bodies"]:
        body.pop("damping", None)
    for f in d.get("forces", []):
        if f["kind"] == "spring_damper":
            f["damping"] = 0.0
    return d


@pytest.mark.parametrize("name", ["paper-timo-1", "paper-eb-2", "paper-timo-8-clamped",
                                  "every-joint", "line-and-beam", "free-beam", "rigid"])
def test_quadratic_velocity_vector_against_finite_differences(name):
    """Q_v = -Mdot qd + 1/2 d/dq (qd^T M qd)  (eq. 40), M differentiated numerically."""
    m = ReferenceModel(no_velocity_forces(all_scenes()[name]))
    rng = np.random.default_rng(4)
    for _ in range(2):
        q, qd = random_state(m, rng, scale_f=1e-2)
        Qv = m.Q(0.3, q, qd) - m.Q(0.3, q, np.zeros_like(qd))
        h = 1e-6
        Mdot = (m.M(q + h * qd) - m.M(q - h * qd)) / (2 * h)
        grad = np.array([(qd @ m.M(q + h * e) @ qd - qd @ m.M(q - h * e) @ qd) / (2 * h)
                         for e in np.eye(m.n)])
        Qv_fd = -Mdot @ qd + 0.5 * grad
        scale = np.abs(Qv_fd).max()
        assert scale > 0
        np.testing.assert_allclose(Qv, Qv_fd, rtol=0, atol=1e-7 * scale)


@pytest.mark.parametrize("name", ["paper-timo-1", "paper-timo-8-clamped", "line-and-beam",
                                  "pendulum", "free-beam", "rigid"])
def test_conservative_forces_are_minus_gradient_of_potential(name):
    """Gravity + strain + springs: Q(t, q, 0) = -dV/dq (applied forces/torques removed)."""
    d = no_velocity_forces(all_scenes()[name])
    d["forces"] = [f for f in d.get("forces", []) if f["kind"] == "spring_damper"]
    m = ReferenceModel(d)
    rng = np.random.default_rng(5)
    q, _ = random_state(m, rng, scale_f=1e-2)
    Q0 = m.Q(0.0, q, np.zeros(m.n))
    h = 1e-6
    grad = np.array([(m.potential_energy(q + h * e) - m.potential_energy(q - h * e)) / (2 * h)
                     for e in np.eye(m.n)])
    np.testing.assert_allclose(Q0, -grad, rtol=0, atol=1e-6 * np.abs(grad).max())


def test_point_force_and_torque_virtual_work():
    d = scenes.every_joint_scene()
    d.pop("gravity")
    d_loads = copy.deepcopy(d)
    d_loads["forces"] = [f for f in d["forces"] if f["kind"] in ("point_force", "torque")]
    d_none = copy.deepcopy(d)
    d_none["forces"] = []
    m, m0 = ReferenceModel(d_loads), ReferenceModel(d_none)
    rng = np.random.default_rng(6)
    q, qd = random_state(m, rng, scale_f=1e-2)
    Q = m.Q(0.0, q, qd) - m0.Q(0.0, q, qd)
    dq = rng.normal(size=m.n)
    h = 1e-6
    work = 0.0
    for f in d_loads["forces"]:
        mk = f.get("point", f.get("frame"))
        rp, pp, _, _ = m.marker_state(mk, q + h * dq)
        rm, pm, _, _ = m.marker_state(mk, q - h * dq)
        if f["kind"] == "point_force":
            work += np.dot(f["force"], (rp - rm) / (2 * h))
        else:
            work += f["torque"] * (pp - pm) / (2 * h)
    assert abs(Q @ dq - work) < 1e-7 * abs(work)


def test_damping_and_dashpot_forces():
    d = scenes.every_joint_scene()
    for b in d["bodies"]:  # the linear damping law -beta K_ff qd (nonlinear strain: tests/test_geometric_stiffening.py)
        if b["kind"] == "beam":
            b["strain"] = "linear"
    m = ReferenceModel(d)
    d0 = no_velocity_forces(d)
    m0 = ReferenceModel(d0)
    rng = np.random.default_rng(7)
    q, qd = random_state(m, rng)
    dQ = m.Q(0, q, qd) - m0.Q(0, q, qd)
    expect = np.zeros(m.n)
    cp = m.body("coupler")
    sl = slice(cp.offset + 3, cp.offset + cp.n)
    expect[sl] = -1e-5 * cp.K_ff @ qd[sl]
    f = d["forces"][0]
    ra, _, va, _ = m.marker_state(f["a"], q, qd)
    rb, _, vb, _ = m.marker_state(f["b"], q, qd)
    e = (ra - rb) / np.linalg.norm(ra - rb)
    h = 1e-6
    dq = np.eye(m.n)
    Jrel = np.array([((m.marker_state(f["a"], q + h * x)[0] - m.marker_state(f["b"], q + h * x)[0])
                      - (m.marker_state(f["a"], q - h * x)[0] - m.marker_state(f["b"], q - h * x)[0]))
                     / (2 * h) for x in dq]).T
    expect -= f["damping"] * (e @ (va - vb)) * (Jrel.T @ e)
    np.testing.assert_allclose(dQ, expect, rtol=0, atol=1e-7 * np.abs(expect).max())


# ------------------------------------------------------------------ constraints
@pytest.mark.parametrize("name", [k for k in all_scenes() if k != "free-beam"])
def test_jacobian_phi_t_and_gamma_against_finite_differences(name):
    m = ReferenceModel(all_scenes()[name])
    rng = np.random.default_rng(8)
    t = 0.137
    for _ in range(2):
        q, qd = random_state(m, rng, scale_f=1e-2)
        h = 1e-6
        A_fd = np.array([(m.phi(t, q + h * e) - m.phi(t, q - h * e)) / (2 * h)
                         for e in np.eye(m.n)]).T
        A = m.A(q)
        np.testing.assert_allclose(A, A_fd, rtol=0, atol=1e-8 * max(1.0, np.abs(A).max()))
        Pt_fd = (m.phi(t + h, q) - m.phi(t - h, q)) / (2 * h)
        np.testing.assert_allclose(m.phi_t(t), Pt_fd, rtol=0, atol=1e-7)
        # gamma = -d^2/dtau^2 Phi(t + tau, q + tau qd) at tau = 0
        h = 1e-4
        d2 = (m.phi(t + h, q + h * qd) - 2 * m.phi(t, q) + m.phi(t - h, q - h * qd)) / h**2
        g = m.gamma(t, q, qd)
        np.testing.assert_allclose(g, -d2, rtol=0, atol=1e-5 * max(1.0, np.abs(g).max()))


def test_prismatic_and_weld_reference_angle_from_initial_guess():
    m = ReferenceModel(scenes.every_joint_scene())
    q, qd = m.initial_guess()
    np.testing.assert_allclose(m.phi(0.0, q), 0.0, atol=1e-15)
    m2 = ReferenceModel(scenes.line_and_beam_scene())
    q2, _ = m2.initial_guess()
    np.testing.assert_allclose(m2.phi(0.0, q2), 0.0, atol=1e-15)


def test_correct_initial_state_is_consistent_and_holds_elastic():
    m = ReferenceModel(scenes.every_joint_scene())
    rng = np.random.default_rng(9)
    q, qd = m.initial_guess()
    q += rng.normal(scale=0.01, size=m.n)
    qd += rng.normal(scale=0.1, size=m.n)
    qc, qdc = correct_initial_state(m, q, qd, t0=0.2)
    assert np.abs(m.phi(0.2, qc)).max() < 1e-12
    assert np.abs(m.A(qc) @ qdc + m.phi_t(0.2)).max() < 1e-10
    for b in m.bodies:
        if b.kind == "beam":
            sl = slice(b.offset + 3, b.offset + b.n)
            np.testing.assert_array_equal(qc[sl], q[sl])
            np.testing.assert_array_equal(qdc[sl], qd[sl])


# ------------------------------------------------------------------ UK / augmented
@pytest.mark.parametrize("name", [k for k in all_scenes() if k != "free-beam"])
def test_uk_equals_augmented_and_nullspace(name):
    m = ReferenceModel(all_scenes()[name])
    rng = np.random.default_rng(10)
    q, qd = random_consistent_state(m, rng, t=0.05)
    M, Q, A, b = m.terms(0.05, q, qd)
    qdd = uk_qdd(M, Q, A, b)
    qdd2, lam2 = augmented_qdd(M, Q, A, b)
    lam = uk_multipliers(M, Q, A, b)
    s = np.abs(qdd2).max()
    np.testing.assert_allclose(qdd, qdd2, rtol=0, atol=1e-10 * s)
    np.testing.assert_allclose(lam, lam2, rtol=0, atol=1e-9 * np.abs(lam2).max())
    # sign convention M qdd + A^T lam = Q and the acceleration constraint
    np.testing.assert_allclose(M @ qdd + A.T @ lam, Q, rtol=0, atol=1e-9 * np.abs(Q).max())
    bound = np.abs(A) @ np.abs(qdd) + np.abs(b)        # scale of the terms that cancel
    assert np.all(np.abs(A @ qdd - b) <= 1e-12 * bound.max())
    # third opinion: null-space method, qdd = qp + Z z with Z^T M Z z = Z^T (Q - M qp)
    import scipy.linalg as sla
    Z = sla.null_space(A)
    qp = np.linalg.lstsq(A, b, rcond=None)[0]
    z = np.linalg.solve(Z.T @ M @ Z, Z.T @ (Q - M @ qp))
    np.testing.assert_allclose(qdd, qp + Z @ z, rtol=0, atol=1e-9 * s)


def test_uk_with_redundant_constraints():
    d = scenes.rigid_slider_crank()
    d["joints"].append(copy.deepcopy(d["joints"][0]))          # duplicate the ground pivot
    m = ReferenceModel(d)
    rng = np.random.default_rng(11)
    q, qd = random_consistent_state(m, rng)
    M, Q, A, b = m.terms(0.0, q, qd)
    assert np.linalg.matrix_rank(A) == m.m - 2
    qdd = uk_qdd(M, Q, A, b)
    qdd2, lam2 = augmented_qdd(M, Q, A, b)
    np.testing.assert_allclose(qdd, qdd2, atol=1e-10 * np.abs(qdd2).max())
    lam = uk_multipliers(M, Q, A, b)
    np.testing.assert_allclose(M @ qdd + A.T @ lam, Q, atol=1e-9 * np.abs(Q).max())
    # the reaction at the duplicated pivot is shared: pseudo-inverse splits it evenly
    np.testing.assert_allclose(lam[:2], lam[-2:], atol=1e-9 * np.abs(lam).max())


# ------------------------------------------------------------------ energy
def test_free_spinning_beam_conserves_energy_and_momentum():
    m = ReferenceModel(scenes.free_beam("timoshenko", 2, "pinned-pinned", youngs_modulus=7e7))
    q0, qd0 = m.initial_guess()
    b = m.body("b")
    q0[b.offset + 3:] = 1e-3 * np.linspace(-1, 1, b.n_f)
    res = simulate_uk_numpy(m, 0.02, method="DOP853", rtol=1e-10, atol=1e-12, q0=q0, qd0=qd0,
                            t_eval=np.linspace(0, 0.02, 5))
    assert res.success
    E = [m.kinetic_energy(res.q[:, i], res.qd[:, i]) + m.potential_energy(res.q[:, i])
         for i in range(res.t.size)]
    assert np.ptp(E) < 1e-8 * E[0]
    p = [(m.M(res.q[:, i]) @ res.qd[:, i])[:2] for i in range(res.t.size)]
    np.testing.assert_allclose(p, np.broadcast_to(p[0], (len(p), 2)), atol=1e-9 * np.abs(p[0]).max())
    # the elastic coordinates actually vibrated (the test is not vacuous)
    assert np.ptp(res.q[b.offset + 3 + 1]) > 1e-5


def flexible_double_pendulum():
    # a soft material keeps the elastic frequencies low so that the check runs fast
    beam = dict(density=1200.0, youngs_modulus=5e6, poisson_ratio=0.45, shear_factor=0.85,
                section={"shape": "rectangular", "width": 0.01, "height": 0.008})
    return {
        "gravity": [0.0, -9.81],
        "bodies": [
            {"name": "b1", "kind": "beam", "length": 0.4, "elements": 2, "theory": "timoshenko",
             "frame": "pinned-pinned", "position": [0, 0], "angle": 0.0, **beam},
            {"name": "b2", "kind": "beam", "length": 0.3, "elements": 2,
             "theory": "euler-bernoulli", "frame": "clamped", "rotary_inertia": True,
             "position": [0.4, 0], "angle": 0.0, **beam},
        ],
        "joints": [
            {"kind": "revolute", "a": {"body": "ground", "point": [0, 0]}, "b": {"body": "b1", "xi": 0}},
            {"kind": "revolute", "a": {"body": "b1", "xi": 1.0}, "b": {"body": "b2", "xi": 0}},
        ],
    }


def test_constrained_flexible_double_pendulum_conserves_energy():
    m = ReferenceModel(flexible_double_pendulum())
    q0, qd0 = correct_initial_state(m)
    res = simulate_uk_numpy(m, 0.3, method="DOP853", rtol=1e-10, atol=1e-12, q0=q0, qd0=qd0,
                            t_eval=np.linspace(0, 0.3, 7))
    assert res.success
    E = np.array([m.kinetic_energy(res.q[:, i], res.qd[:, i]) + m.potential_energy(res.q[:, i])
                  for i in range(res.t.size)])
    T_end = m.kinetic_energy(res.q[:, -1], res.qd[:, -1])
    assert T_end > 0.01                       # it fell and moves
    assert np.abs(E - E[0]).max() < 1e-7 * T_end
    b2 = m.body("b2")
    assert np.ptp(res.q[b2.offset + 3 + 1]) > 1e-4     # and bent: not a rigid-body check
