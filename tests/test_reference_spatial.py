"""The spatial NumPy reference (python/ukflex/reference/spatial/): its equations against finite
differences and closed forms, its accelerations against each other and against coordinate
partitioning, its scenes against conservation laws, a closed-form nutation period and Exudyn.

The package is loaded by path so that these tests run without the compiled core.
docs/spatial-design.md quotes the figures these tests hold.
"""
from __future__ import annotations

import importlib
import importlib.util
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "python" / "ukflex" / "reference" / "spatial"


def _load():
    try:
        return importlib.import_module("ukflex.reference.spatial")
    except ImportError:
        pass
    name = "ukflex_reference_spatial"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, PKG / "__init__.py",
                                                  submodule_search_locations=[str(PKG)])
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod


sp = _load()
scenes = sp.scenes
RNG = np.random.default_rng(20240530)


def random_rotation(rng):
    p = rng.normal(size=4)
    return sp.rot_A(p / np.linalg.norm(p))


def random_inertia(rng):
    w = rng.uniform(1.0, 2.0, 3)
    R = random_rotation(rng)
    return R @ np.diag(w) @ R.T


# ----------------------------------------------------------------------------------------
# rotations
# ----------------------------------------------------------------------------------------

def test_euler_parameter_identities():
    for _ in range(20):
        p = RNG.normal(size=4)
        p /= np.linalg.norm(p)
        A, G, E = sp.rot_A(p), sp.rot_G(p), sp.rot_E(p)
        assert np.allclose(A.T @ A, np.eye(3), atol=1e-14) and np.isclose(np.linalg.det(A), 1.0)
        assert np.allclose(A, E @ G.T, atol=1e-14)
        assert np.allclose(G @ p, 0, atol=1e-15) and np.allclose(G @ G.T, np.eye(3), atol=1e-14)
        assert np.allclose(sp.p_from_matrix(A) * np.sign(p[0]), p, atol=1e-13)
        # w' = 2 G pd: A^T Ad = skew(w') for a pd tangent to the unit sphere
        pd = RNG.normal(size=4)
        pd -= (pd @ p) * p
        h = 1e-6
        Ad = (sp.rot_A(p + h * pd) - sp.rot_A(p - h * pd)) / (2 * h)
        assert np.allclose(A.T @ Ad, sp.skew(sp.omega_body(p, pd)), atol=1e-8)
        assert np.allclose(sp.omega_world(p, pd), A @ sp.omega_body(p, pd), atol=1e-13)


def test_B_is_the_derivative_of_A_a_for_any_p():
    for _ in range(10):
        p, a = RNG.normal(size=4), RNG.normal(size=3)     # not normalized on purpose
        h = 1e-6
        fd = np.column_stack([(sp.rot_A(p + h * e) @ a - sp.rot_A(p - h * e) @ a) / (2 * h) for e in np.eye(4)])
        assert np.allclose(sp.rot_B(p, a), fd, atol=1e-9)
        assert np.allclose(sp.rot_B(p, a) @ p, 2 * sp.rot_A(p) @ a, atol=1e-13)


# ----------------------------------------------------------------------------------------
# joints: Jacobians and gamma against finite differences
# ----------------------------------------------------------------------------------------

JOINTS = ["spherical", "revolute", "universal", "fixed", "cylindrical", "prismatic", "planar",
          "distance", "point_on_line", "point_on_plane"]
DRIVERS = ["rotation", "translation"]
POINT_OK = {"spherical", "distance", "point_on_line", "point_on_plane"}


def _pair_model(kind, case, seed):
    """Two bodies with random markers (no need to satisfy the joint: Jacobians hold anywhere)."""
    rng = np.random.default_rng(seed)
    m = sp.SpatialModel(gravity=(0.3, -9.81, 0.5))
    b1 = m.add_rigid_body(1.3, random_inertia(rng), com=rng.normal(size=3) * 0.2, position=rng.normal(size=3),
                          orientation=random_rotation(rng))
    if case == "point":
        b2 = m.add_point_mass(0.7, position=rng.normal(size=3))
        mj = m.add_marker(b2, orientation=random_rotation(rng))
    else:
        b2 = m.add_rigid_body(0.8, random_inertia(rng), com=rng.normal(size=3) * 0.2, position=rng.normal(size=3),
                              orientation=random_rotation(rng))
        mj = m.add_marker(b2, rng.normal(size=3), random_rotation(rng))
    mi = m.add_marker(None if case == "ground" else b1, rng.normal(size=3), random_rotation(rng))
    if case == "ground":
        mj, mi = m.add_marker(b1, rng.normal(size=3), random_rotation(rng)), mi
        if kind in DRIVERS or kind in ("revolute",):
            mi, mj = mj, mi      # the body on the first marker for some, the ground for the others
    if kind in DRIVERS:
        motion = sp.Harmonic(0.7, 3.0, 0.2, 0.4) if kind == "rotation" else sp.Polynomial((0.1, -0.3, 0.8, 0.2))
        m.add_driver(kind, mi, mj, motion)
    else:
        m.add_joint(kind, mi, mj, length=0.9 if kind == "distance" else None)
    return m, rng


def _random_state(m, rng):
    q = rng.normal(size=m.n)
    for b in m.rigid_bodies():                          # |p| near, but not at, 1
        p = rng.normal(size=4)
        q[b.offset + 3:b.offset + 7] = p / np.linalg.norm(p) * rng.uniform(0.9, 1.1)
    return q, rng.normal(size=m.n)


CASES = [(k, c) for k in JOINTS + DRIVERS for c in ("pair", "ground", "point")
         if c != "point" or k in POINT_OK]


@pytest.mark.parametrize("kind,case", CASES, ids=[f"{k}-{c}" for k, c in CASES])
def test_jacobian_and_gamma_against_finite_differences(kind, case):
    m, rng = _pair_model(kind, case, seed=zlib.crc32(f"{kind}-{case}".encode()))
    for _ in range(3):
        q, qd = _random_state(m, rng)
        t = rng.uniform(0, 2)
        Phi, A, phi_t, gamma = m.constraint_terms(t, q, qd)
        assert A.shape == (m.m, m.n)
        h = 1e-6
        fd = np.column_stack([(m.phi(t, q + h * e) - m.phi(t, q - h * e)) / (2 * h) for e in np.eye(m.n)])
        assert np.abs(A - fd).max() <= 1e-8 * max(1.0, np.abs(A).max()), (kind, case)
        fdt = (m.phi(t + h, q) - m.phi(t - h, q)) / (2 * h)
        assert np.abs(phi_t - fdt).max() <= 1e-8 * max(1.0, np.abs(phi_t).max())

        # gamma = -d/de [A(q + e qd, t + e) qd + Phi_t(q + e qd, t + e)] at e = 0
        def vel(e):
            qq = q + e * qd
            return m.A(t + e, qq) @ qd + m.phi_t(t + e, qq)
        fdg = -(vel(h) - vel(-h)) / (2 * h)
        assert np.abs(gamma - fdg).max() <= 1e-7 * max(1.0, np.abs(gamma).max()), (kind, case)


def test_every_kind_has_its_row_count_and_holds_when_the_frames_coincide():
    rng = np.random.default_rng(7)
    for kind in JOINTS:
        m = sp.SpatialModel()
        R1, R2 = random_rotation(rng), random_rotation(rng)
        b1 = m.add_rigid_body(1.0, np.eye(3), position=rng.normal(size=3), orientation=R1)
        b2 = m.add_rigid_body(1.0, np.eye(3), position=rng.normal(size=3), orientation=R2)
        P, F = rng.normal(size=3), random_rotation(rng)          # a common world frame
        mi = m.add_marker(b1, R1.T @ (P - b1.position), R1.T @ F)
        mj = m.add_marker(b2, R2.T @ (P - b2.position), R2.T @ F)
        j = m.add_joint(kind, mi, mj, length=None)
        q, _ = m.initial_guess()
        assert j.nrows == sp.JOINT_ROWS[kind] and m.m == j.nrows + 2
        if kind != "distance":      # a distance joint of zero length is degenerate: skip its value
            assert np.abs(m.phi(0.0, q)).max() < 1e-14, kind


# ----------------------------------------------------------------------------------------
# mass matrix, quadratic velocity term, forces
# ----------------------------------------------------------------------------------------

def test_mass_matrix_and_quadratic_velocity_term_follow_from_lagrange():
    """T = 1/2 qd^T M(q) qd; Lagrange: M qdd = Q_ext - Md qd + dT/dq, so the velocity term is
    Q_v = -Md qd + dT/dq = 8 Gd^T J Gd p (the sign the docs derive)."""
    rng = np.random.default_rng(3)
    m = sp.SpatialModel()
    b = m.add_rigid_body(2.0, random_inertia(rng), com=[0.1, 0.2, -0.3], orientation=random_rotation(rng))
    for _ in range(5):
        q, qd = _random_state(m, rng)
        M = m.M(q)
        w = 2 * sp.rot_G(b.p(q)) @ b.p(qd)          # |p| != 1 here: the Lagrangian's w', not the sensor's
        assert np.isclose(0.5 * qd @ M @ qd, 0.5 * b.mass * b.r(qd) @ b.r(qd) + 0.5 * w @ b.inertia @ w)
        assert np.linalg.matrix_rank(M) == 6
        h = 1e-6
        Md_qd = (m.M(q + h * qd) - m.M(q - h * qd)) @ qd / (2 * h)
        dT = np.array([(qd @ m.M(q + h * e) @ qd - qd @ m.M(q - h * e) @ qd) / (4 * h) for e in np.eye(m.n)])
        assert np.allclose(m.Q(0.0, q, qd), -Md_qd + dT, atol=1e-7 * np.abs(dT).max())


def test_generalized_forces_are_virtual_work():
    rng = np.random.default_rng(11)
    m = sp.SpatialModel()
    b1 = m.add_rigid_body(1.0, random_inertia(rng), com=[0.05, 0, 0.1], position=[0, 0, 0],
                          orientation=random_rotation(rng))
    b2 = m.add_rigid_body(1.5, random_inertia(rng), position=[1.0, 0.3, 0.2], orientation=random_rotation(rng))
    mi, mj = m.add_marker(b1, [0.3, 0.1, 0]), m.add_marker(b2, [-0.2, 0, 0.1], z=[0.2, 1.0, 0.3])
    spring = m.add_spring_damper(mi, mj, 120.0, 0.0, length0=0.4)
    rot = m.add_rotational_spring_damper(m.add_marker(b1, [0, 0, 0], z=[0.2, 1.0, 0.3]), mj, 7.0, 0.0, angle0=0.2)
    q, _ = m.initial_guess()
    h = 1e-6
    for f in (spring, rot):
        Q = f.Q(0.0, m.n, q, np.zeros(m.n))
        dV = np.array([(f.potential(0, q + h * e) - f.potential(0, q - h * e)) / (2 * h) for e in np.eye(m.n)])
        assert np.allclose(Q, -dV, atol=1e-7 * np.abs(dV).max())
    # dampers dissipate c Ld^2; a world force does F.dP; a torque does n.w
    q, qd = _random_state(m, rng)
    for b in m.rigid_bodies():                  # unit p and p.pd = 0 for the power identities
        s = slice(b.offset + 3, b.offset + 7)
        q[s] /= np.linalg.norm(q[s])
        qd[s] -= (qd[s] @ q[s]) * q[s]
    damper = sp.forces.SpringDamper(mi, mj, 0.0, 3.0, 0.4)
    assert np.isclose(damper.Q(0, m.n, q, qd) @ qd, -damper.dissipation(q, qd))
    F = np.array([0.3, -1.0, 2.0])
    P = mi.point(m.n, q, qd)
    assert np.isclose(sp.forces.PointForce(mi, F).Q(0, m.n, q, qd) @ qd, F @ P.vd[:3])
    n = np.array([1.0, 0.5, -0.2])
    w = sp.omega_world(b1.p(q), b1.p(qd))
    assert np.isclose(sp.forces.Torque(b1, n).Q(0, m.n, q, qd) @ qd, n @ w)
    nb = np.array([0.1, -0.4, 0.3])
    assert np.isclose(sp.forces.Torque(b1, nb, "body").Q(0, m.n, q, qd) @ qd, nb @ b1.omega_body(q, qd))


def test_explicit_factor_is_a_factor_of_the_regularized_block():
    rng = np.random.default_rng(5)
    m = sp.SpatialModel()
    b = m.add_rigid_body(2.0, random_inertia(rng), orientation=random_rotation(rng))
    q, qd = _random_state(m, rng)                   # |p| != 1 too
    Mr, _ = m.regularized(q, qd)
    FiT = b.factor_inv_T(q)
    assert np.allclose(FiT @ FiT.T, np.linalg.inv(Mr), rtol=1e-12, atol=1e-12 * np.abs(np.linalg.inv(Mr)).max())
    # the normalization row becomes the unit row e_z4 / sqrt(k) in z = F^T qdd
    An = np.zeros(7)
    An[3:] = 2 * b.p(q)
    assert np.allclose(An @ FiT, np.eye(7)[6] / np.sqrt(b.k_reg), atol=1e-14)


# ----------------------------------------------------------------------------------------
# accelerations: four UK routes and coordinate partitioning on every scene
# ----------------------------------------------------------------------------------------

SCENES = {
    "heavy_top": lambda: scenes.heavy_top(),
    "heavy_top_offset": lambda: scenes.heavy_top(com_offset=True),
    "double_pendulum": lambda: scenes.double_pendulum(),
    "bricard": lambda: scenes.bricard(),
    "flyball": lambda: scenes.flyball_governor(),
    "flyball_composite": lambda: scenes.flyball_governor(point_masses="composite"),
    "flyball_driven": lambda: scenes.flyball_governor(driven=True),
    "slider_crank": lambda: scenes.slider_crank(),
    "slider_crank_driven": lambda: scenes.slider_crank(driven=True, theta0=0.7),
}


def _start(m):
    if m.name == "slider_crank" and not m.driven:
        return scenes.slider_crank_state(m)
    return m.initial_guess()


def _moving_state(m, rng):
    """A consistent state with random velocities: positions corrected from a small random
    perturbation, velocities projected onto A qd + Phi_t = 0."""
    q, qd = _start(m)
    q = q + 1e-3 * rng.normal(size=m.n)
    q, qd, _ = sp.correct_initial_state(m, q, qd + rng.normal(size=m.n))
    return q, qd


@pytest.mark.parametrize("name", list(SCENES))
def test_uk_routes_and_coordinate_partitioning_agree(name):
    m = SCENES[name]()
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    for q, qd in (_start(m), _moving_state(m, rng)):
        q, qd, _ = sp.correct_initial_state(m, q, qd)
        t = 0.3
        T = m.terms(t, q, qd)
        ref = sp.qdd_block(m, t, q, qd, factor="cholesky", terms=T)
        scale = max(np.abs(ref).max(), 1.0)
        others = {
            "explicit": sp.qdd_block(m, t, q, qd, factor="explicit", terms=T),
            "eliminated": sp.qdd_block(m, t, q, qd, factor="eliminated", terms=T),
            "augmented": sp.qdd_augmented(T["M"], T["Q"], T["A"], T["b"], alpha=1.0),
            "singular": sp.qdd_singular(T["M"], T["Q"], T["A"], T["b"]),
            "cp": sp.cp_accelerations(T["M"], T["Q"], T["A"], T["b"], sp.partition(T["A"])),
        }
        for k, v in others.items():
            assert np.abs(v - ref).max() <= 1e-10 * scale, (name, k, np.abs(v - ref).max() / scale)
        # the whole-set augmentation is exact in exact arithmetic only: a large alpha costs digits
        v = sp.qdd_augmented(T["M"], T["Q"], T["A"], T["b"], alpha=1e3)
        assert np.abs(v - ref).max() <= 1e-7 * scale, (name, "augmented alpha 1e3")
        assert np.abs(T["A"] @ ref - T["b"]).max() <= 1e-9 * max(1.0, np.abs(T["b"]).max())


def test_forces_along_p_and_the_regularization_constant_do_not_change_accelerations():
    """A generalized force along p_i (per body) is taken by the normalization row's multiplier:
    the accelerations ignore it. So the right-hand side shift -4 k (pd.pd) p, the value of k and
    the choice between 8 Gd^T J Gd p and -2 G^T (w' x J w') (equal up to a multiple of p on
    consistent states) leave qdd alone; a force off p does not."""
    m = scenes.double_pendulum()
    rng = np.random.default_rng(17)
    q, qd = _moving_state(m, rng)
    T = m.terms(0.0, q, qd)
    ref = sp.qdd_block(m, 0.0, q, qd, terms=T)
    scale = np.abs(ref).max()
    rig = m.rigid_bodies()
    Qp = T["Q"].copy()
    Qe = T["Q"].copy()
    for b in rig:
        s_ = slice(b.offset + 3, b.offset + 7)
        p, pd = b.p(q), b.p(qd)
        Qp[s_] += rng.normal() * 10 * p
        w = b.omega_body(q, qd)
        Qe[s_] += -2 * sp.rot_G(p).T @ np.cross(w, b.inertia @ w) - b.quadratic_velocity(q, qd)[3:]
    for Q in (Qp, Qe):
        v = sp.qdd_block(m, 0.0, q, qd, terms={**T, "Q": Q})
        assert np.abs(v - ref).max() < 1e-11 * scale
    k0 = [b.k_reg for b in rig]
    try:
        for f in (1e-3, 1e3):
            for b, k in zip(rig, k0):
                b.k_reg = f * k
            v = sp.qdd_block(m, 0.0, q, qd, terms=T)
            assert np.abs(v - ref).max() < 1e-10 * scale, f
    finally:
        for b, k in zip(rig, k0):
            b.k_reg = k
    Qx = T["Q"].copy()
    Qx[rig[0].offset + 3:rig[0].offset + 7] += rng.normal(size=4)
    assert np.abs(sp.qdd_block(m, 0.0, q, qd, terms={**T, "Q": Qx}) - ref).max() > 1e-3 * scale


def test_flyball_point_masses_and_composite_bodies_move_alike():
    """A 5 kg point mass on a spherical joint at the rod's end is the composite rigid body with
    its centre of mass offset: the shared coordinates accelerate alike."""
    a, b = scenes.flyball_governor(), scenes.flyball_governor(point_masses="composite")
    qa, qda = a.initial_guess()
    qb, qdb = b.initial_guess()
    qdda, qddb = sp.accelerations(a, 0.0, qa, qda), sp.accelerations(b, 0.0, qb, qdb)
    for ba, bb in zip(a.rigid_bodies(), b.rigid_bodies()):
        assert ba.name == bb.name
        pa, pb = slice(ba.offset + 3, ba.offset + 7), slice(bb.offset + 3, bb.offset + 7)
        assert np.allclose(qdda[pa], qddb[pb], atol=1e-10 * np.abs(qdda).max())
        if ba.name in ("shaft", "slider"):
            assert np.allclose(qdda[ba.offset:ba.offset + 3], qddb[bb.offset:bb.offset + 3], atol=1e-10)
    sl = a.bodies[1]
    assert abs(qdda[sl.offset + 2]) > 1.0          # the slider is not at rest: the check bites


# ----------------------------------------------------------------------------------------
# heavy symmetric top
# ----------------------------------------------------------------------------------------

def _u_max_event(t, y):
    p, pd = y[3:7], y[10:14]
    return np.cross(sp.omega_world(p, pd), sp.rot_A(p)[:, 2])[2]


_u_max_event.direction = -1


def test_heavy_top_conserves_energy_and_momenta_and_nutates_with_its_closed_form_period():
    m = scenes.heavy_top(spin=30.0)
    q0, qd0 = m.initial_guess()
    ts = np.linspace(0.0, 2.0, 81)
    res = sp.simulate(m, 2.0, q0, qd0, rtol=1e-12, atol=1e-14, t_eval=ts, events=_u_max_event)
    E = np.array([m.energy(0, res.q[:, i], res.qd[:, i]) for i in range(ts.size)])
    L = np.array([m.angular_momentum(res.q[:, i], res.qd[:, i]) for i in range(ts.size)])
    e3 = np.array([sp.rot_A(res.q[3:7, i])[:, 2] for i in range(ts.size)])
    Lz, L3 = L[:, 2], np.einsum("ij,ij->i", L, e3)
    rel = lambda x: np.abs(x - x[0]).max() / abs(x[0])  # noqa: E731
    assert rel(E) < 1e-9 and rel(Lz) < 1e-9 and rel(L3) < 1e-9, (rel(E), rel(Lz), rel(L3))
    assert np.isclose(L3[0], 0.005 * 30.0)            # C w3
    theta = np.arccos(e3[:, 2])
    assert theta.max() - theta.min() > 1.0            # a large nutation: the check bites
    d = m.top_data
    T, (u1, u2, _) = scenes.nutation_period(d["mass"], d["A"], d["C"], d["l"], d["theta0"], d["spin"])
    ev = res.extra["events"][0]
    periods = np.diff(ev)
    assert periods.size >= 2
    assert np.abs(periods - T).max() < 1e-8 * T, (periods, T)
    assert np.isclose(np.cos(theta).max(), u2, atol=1e-9) and np.isclose(np.cos(theta).min(), u1, atol=2e-3)


def test_heavy_top_with_a_centre_of_mass_offset_moves_alike():
    a, b = scenes.heavy_top(), scenes.heavy_top(com_offset=True)
    ra = sp.simulate(a, 0.3, *a.initial_guess(), rtol=1e-11, atol=1e-13, t_eval=[0.3])
    rb = sp.simulate(b, 0.3, *b.initial_guess(), rtol=1e-11, atol=1e-13, t_eval=[0.3])
    assert np.abs(ra.q[:, -1] - rb.q[:, -1]).max() < 1e-9
    assert np.abs(ra.q[:3, -1] - ra.q[:3, 0] if ra.q.shape[1] > 1 else ra.q[:3, -1] - a.initial_guess()[0][:3]).max() > 1e-3


# ----------------------------------------------------------------------------------------
# constraints along a run, projection, initial correction, drivers, CP runs
# ----------------------------------------------------------------------------------------

def test_constraints_stay_satisfied_along_a_run_and_projection_removes_the_drift():
    m = scenes.slider_crank()
    q0, qd0 = scenes.slider_crank_state(m)
    ts = np.linspace(0.0, 0.5, 11)
    res = sp.simulate(m, 0.5, q0, qd0, rtol=1e-10, atol=1e-12, t_eval=ts)
    drift = max(np.abs(m.phi(t, res.q[:, i])).max() for i, t in enumerate(ts))
    vdrift = max(np.abs(m.A(t, res.q[:, i]) @ res.qd[:, i]).max() for i, t in enumerate(ts))
    norm = max(np.abs(res.q[m.euler_parameter_indices(), i].reshape(-1, 4) ** 2).sum(axis=1).__sub__(1).__abs__().max()
               for i in range(ts.size))
    assert drift < 1e-8 and vdrift < 1e-7 and norm < 1e-9, (drift, vdrift, norm)
    rp = sp.simulate(m, 0.5, q0, qd0, rtol=1e-8, atol=1e-10, t_eval=ts, project_every=0.1)
    assert rp.projections == 5
    ends = [i for i, t in enumerate(rp.t) if np.isclose(t % 0.1, 0) or np.isclose(t % 0.1, 0.1)]
    assert max(np.abs(m.phi(rp.t[i], rp.q[:, i])).max() for i in ends[1:]) < 1e-7
    qp, qdp = sp.project(m, 0.5, rp.q[:, -1], rp.qd[:, -1])
    assert np.abs(m.phi(0.5, qp)).max() < 1e-13 and np.abs(m.A(0.5, qp) @ qdp).max() < 1e-12


def test_initial_state_correction():
    m = scenes.slider_crank()
    q, qd = scenes.slider_crank_state(m)
    q1, qd1, rep = sp.correct_initial_state(m, q, qd)
    assert rep["dq"] < 1e-14 and rep["dqd"] < 1e-10            # a consistent state stays put
    rng = np.random.default_rng(1)
    dq = 1e-3 * rng.normal(size=m.n)
    q2, qd2, rep = sp.correct_initial_state(m, q + dq, qd + 0.1 * rng.normal(size=m.n))
    assert rep["phi"] < 1e-13 and rep["velocity_residual"] < 1e-11
    assert rep["dq"] < 3 * np.linalg.norm(dq)                   # the correction is no larger than needed
    # held coordinates keep their values
    hold = [m.slider_body.offset]
    q3, _, rep = sp.correct_initial_state(m, q + dq, qd, hold=hold)
    assert q3[hold[0]] == (q + dq)[hold[0]] and rep["phi"] < 1e-13


def test_rotation_driver_is_continuous_through_pi():
    m = scenes.slider_crank(driven=True, omega0=6.0)
    q0, qd0, _ = sp.correct_initial_state(m)
    ts = np.linspace(0.0, 0.9, 19)                 # 5.4 rad: through +-pi
    res = sp.simulate(m, 0.9, q0, qd0, rtol=1e-10, atol=1e-12, t_eval=ts)
    drv = m.joints[1]
    held = np.array([drv.value(t, m.n, res.q[:, i]) for i, t in enumerate(ts)])
    assert np.abs(held - 6.0 * ts).max() < 1e-8
    wrapped = np.array([scenes.crank_angle(m, res.q[:, i]) for i in range(ts.size)])
    assert np.abs(np.diff(wrapped)).max() > np.pi                # the wrapped angle jumps; the driver does not
    assert np.abs(np.unwrap(wrapped) - 6.0 * ts).max() < 1e-8


def test_coordinate_partitioning_run_matches_uk_run():
    m = scenes.slider_crank()
    q0, qd0 = scenes.slider_crank_state(m)
    ts = np.linspace(0.0, 0.3, 4)
    uk = sp.simulate(m, 0.3, q0, qd0, rtol=1e-11, atol=1e-13, t_eval=ts)
    cp = sp.simulate_cp(m, 0.3, q0, qd0, rtol=1e-10, atol=1e-12, t_eval=ts)
    assert cp.q.shape == uk.q.shape
    assert np.abs(cp.q - uk.q).max() < 1e-8, np.abs(cp.q - uk.q).max()
    assert np.abs(cp.q[m.slider_body.offset] - q0[m.slider_body.offset]).max() > 1e-2


# ----------------------------------------------------------------------------------------
# Bricard's mechanism (MBS benchmark A04)
# ----------------------------------------------------------------------------------------

def test_bricard_redundancy_energy_and_unique_reactions():
    m = scenes.bricard()
    q0, qd0 = m.initial_guess()
    rr = m.rank_report(0.0, q0)
    assert (m.n, m.m, rr["rank"], rr["redundant"], rr["dof"]) == (35, 35, 34, 1, 1)
    assert rr["singular_values"][-1] < 1e-15 * rr["singular_values"][0] < rr["singular_values"][-2]
    r, s = sp.uk_rank(m, 0.0, q0)
    assert r == 34
    part = sp.partition(m.A(0.0, q0))
    assert part.dep.size == 34 and part.rows.size == 34          # CP drops one redundant row
    # energy over 0.6 s (the docs quote 10 s); the rank tolerance sits above the drift
    ts = np.linspace(0.0, 0.6, 7)
    res = sp.simulate(m, 0.6, q0, qd0, rtol=1e-10, atol=1e-12, t_eval=ts, pinv_rtol=1e-8)
    E = np.array([m.energy(0, res.q[:, i], res.qd[:, i]) for i in range(ts.size)])
    KE = max(m.kinetic_energy(res.q[:, i], res.qd[:, i]) for i in range(ts.size))
    assert KE > 0.05                                               # it moves
    assert np.abs(E - E[0]).max() < 1e-9, np.abs(E - E[0]).max()
    # reactions: the minimum-norm multipliers are orthogonal to the self-stress null(A^T);
    # only the torque about each revolute's own axis is unique (and zero)
    t, q, qd = ts[-1], res.q[:, -1], res.qd[:, -1]
    T = m.terms(t, q, qd)
    qdd = sp.qdd_block(m, t, q, qd, terms=T, rtol=1e-8)
    lam = sp.multipliers(T["M"], T["Q"], T["A"], qdd, rtol=1e-8)
    nd, uniq = sp.reaction_uniqueness(m, t, q)
    assert nd == 1
    R = sp.joint_reactions(m, t, q, qd, lam=lam, frame="joint")
    expect = np.array([False] * 5 + [True])                       # joint frame: torque about z
    for j in m.joints:
        assert np.array_equal(uniq[j.name], expect), (j.name, uniq[j.name])
        F, Tq = R[j.name]
        assert abs(Tq[2]) < 1e-9 * max(1.0, np.abs(Tq).max())
        assert np.abs(F).max() > 1.0                               # the others carry load
    U, sv, Vt = np.linalg.svd(T["A"].T)
    z = Vt[-1]
    assert abs(z @ lam) < 1e-8 * np.linalg.norm(lam)
    R2 = sp.joint_reactions(m, t, q, qd, lam=lam + 5.0 * z)        # another admissible lam
    assert max(np.abs(R2[j.name][0] - R[j.name][0]).max() for j in m.joints) > 0.1
    assert np.allclose(T["A"].T @ (lam + 5.0 * z), T["A"].T @ lam, atol=1e-6)


def test_reactions_balance_the_bodies():
    """Heavy top and double pendulum: the wrench the first joint exerts on the ground (its first
    marker) is minus what the bodies need: -sum m_i (rdd_i - g) and, about the pivot, minus the
    rate of the angular momentum less the moment of gravity. A joint between two bodies exerts
    opposite wrenches on them (computed once from each side)."""
    for m in (scenes.heavy_top(), scenes.double_pendulum()):
        q, qd = m.initial_guess()
        qdd = sp.accelerations(m, 0.0, q, qd)
        R = sp.joint_reactions(m, 0.0, q, qd)
        F, Tq = R[m.joints[0].name]
        expect = sum(b.mass * (qdd[b.offset:b.offset + 3] - m.gravity) for b in m.bodies)
        assert np.allclose(F, -expect, atol=1e-10 * np.abs(expect).max())
        h = 1e-6
        Ld = (m.angular_momentum(q + h * qd, qd + h * qdd) - m.angular_momentum(q - h * qd, qd - h * qdd)) / (2 * h)
        Mg = sum(np.cross(b.r(q), b.mass * m.gravity) for b in m.bodies)
        assert np.allclose(Tq, -(Ld - Mg), atol=1e-6 * np.abs(Ld).max()), (Tq, Ld - Mg)
    m = scenes.double_pendulum()
    q, qd = m.initial_guess()
    j = m.joints[1]
    lam = sp.multipliers(*[m.terms(0.0, q, qd)[k] for k in ("M", "Q", "A")], sp.accelerations(m, 0.0, q, qd))
    flipped = sp.joints.Joint("spherical", j.mj, j.mi)
    flipped.rows = j.rows
    Wi, Wj = sp.uk.reaction_map(m, 0.0, q, j) @ lam, sp.uk.reaction_map(m, 0.0, q, flipped) @ lam
    assert np.allclose(Wi, -Wj, atol=1e-12) and np.abs(Wi[:3]).max() > 1.0


# ----------------------------------------------------------------------------------------
# bad input
# ----------------------------------------------------------------------------------------

def test_bad_input_is_refused():
    m = sp.SpatialModel()
    with pytest.raises(sp.InvalidBody):
        m.add_rigid_body(1.0, np.diag([1.0, 1.0, 0.0]))            # singular
    with pytest.raises(sp.InvalidBody):
        m.add_rigid_body(1.0, np.diag([1.0, 1.0, 3.0]))            # triangle inequality
    with pytest.raises(sp.InvalidBody):
        m.add_rigid_body(float("nan"), np.eye(3))
    b = m.add_rigid_body(1.0, np.eye(3))
    with pytest.raises(sp.InvalidJoint):
        m.add_marker(b, z=[0.0, 0.0, 0.0])
    with pytest.raises(sp.InvalidJoint):
        m.add_marker(b, z=[np.nan, 0.0, 1.0])
    mk = m.add_marker(b, z=[0.0, 0.0, 5.0])                          # normalized
    assert np.allclose(mk.orientation[:, 2], [0, 0, 1])
    with pytest.raises(sp.InvalidJoint):
        m.add_joint("hinge", mk, m.add_marker(None))


# ----------------------------------------------------------------------------------------
# Exudyn (the peer, spatial rigid bodies in Euler parameters)
# ----------------------------------------------------------------------------------------

@pytest.mark.filterwarnings("ignore::DeprecationWarning")
@pytest.mark.parametrize("name", ["double_pendulum", "heavy_top"])
def test_against_exudyn(name):
    """Exudyn's generalized-alpha (spectral radius 1, second order) at h and h/2 against the
    reference at rtol 1e-12: the error falls fourfold with h/2 (the reference is Exudyn's limit),
    the finer run is within 1e-6 m, Richardson's extrapolation within 2e-8 m."""
    pytest.importorskip("exudyn")
    from importlib import import_module
    peer = import_module(sp.__name__ + ".exudyn_peer")
    m = scenes.double_pendulum() if name == "double_pendulum" else scenes.heavy_top(spin=30.0)
    r = peer.compare(m, t_end=0.5, steps=(2.5e-4, 1.25e-4))
    errs = r["position_error"]
    assert errs[1] < 1e-6, r
    assert 3.0 < errs[0] / errs[1] < 5.0, r                        # second order towards the reference
    assert r["richardson"] < 2e-8, r
