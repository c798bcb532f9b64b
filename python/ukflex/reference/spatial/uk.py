"""Udwadia-Kalaba accelerations with a singular mass matrix, multipliers, joint reactions,
initial-state correction and a solve_ivp driver.

Four routes to the same ``qdd`` (the tests hold them to each other and to coordinate
partitioning, :mod:`.cp`):

``qdd_block(model, ...)`` -- the recommended one (docs/spatial-design.md). Each rigid body's
    Euler-parameter block is regularized with its own normalization row,
    ``M_reg = M + sum_i k_i A_ni^T A_ni = M + sum_i 4 k_i p_i p_i^T``, and the right-hand side
    with ``k_i A_ni^T b_ni = -4 k_i (pd_i.pd_i) p_i``. Both additions are ``k A_n^T (A_n qdd - b_n)``,
    which is zero on every acceleration that satisfies the constraints, so nothing is
    approximated. ``M_reg`` stays block diagonal and positive definite; UK with any factor
    ``M_reg = F F^T``: ``qdd = a + F^-T (A F^-T)^+ (b - A a)``, ``a = M_reg^-1 Q_reg``.
    ``factor="cholesky"`` factors numerically, ``factor="explicit"`` uses each body's closed-form
    ``F^-T`` (:meth:`RigidBody.factor_inv_T`), ``factor="eliminated"`` additionally removes the
    normalization rows, which in the coordinates ``z = F^T qdd`` are unit rows.
``qdd_augmented(M, Q, A, b, alpha)`` -- the whole constraint set augments the mass:
    ``(M + alpha A^T A) qdd = Q + alpha A^T b`` plus the UK correction (Udwadia and Schutte 2010).
``qdd_singular(M, Q, A, b)`` -- Udwadia and Phohomsiri (2006), no regularization at all:
    ``qdd = [(I - A^+ A) M; A]^+ [(I - A^+ A) Q; b]``, unique when ``[M; A]`` has full column rank.

Sign convention: ``M qdd + A^T lam = Q``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
from scipy.integrate import solve_ivp

__all__ = ["pinv", "qdd_block", "qdd_augmented", "qdd_singular", "accelerations", "multipliers",
           "joint_reactions", "reaction_uniqueness", "correct_initial_state", "consistent_velocities",
           "simulate", "SpatialResult", "uk_rank"]


def pinv(D, rtol=None):
    """Pseudoinverse at ``scipy.linalg.pinv``'s default tolerance ``max(m, n) eps sigma_max``."""
    if D.shape[0] == 0:
        return np.zeros((D.shape[1], 0))
    return sla.pinv(D) if rtol is None else sla.pinv(D, rtol=rtol)


def _block_factor_inv_T(model, q):
    FiT = np.zeros((model.n, model.n))
    for b in model.bodies:
        s = slice(b.offset, b.offset + b.ncoord)
        FiT[s, s] = b.factor_inv_T(q)
    return FiT


def qdd_block(model, t, q, qd, factor="explicit", terms=None, rtol=None):
    """Recommended UK route (block regularization by the normalization rows)."""
    T = model.terms(t, q, qd) if terms is None else terms
    Mreg, Qs = model.regularized(q, qd)
    Qr = T["Q"] + Qs
    A, b = T["A"], T["b"]
    if factor == "cholesky":
        L = np.linalg.cholesky(Mreg)                       # M_reg = L L^T
        FiT = sla.solve_triangular(L, np.eye(model.n), lower=True).T
    else:
        FiT = _block_factor_inv_T(model, q)
    a = FiT @ (FiT.T @ Qr)
    D = A @ FiT
    if factor != "eliminated":
        return a + FiT @ (pinv(D, rtol) @ (b - A @ a))
    # z = F^T qdd. Each normalization row of D = A F^-T is the unit row e_z4 / sqrt(k) of its
    # body: it fixes z4 = sqrt(k) b_n; the joint rows then act on the remaining coordinates
    # only (6 per rigid body, 3 per point mass, as in a velocity-space formulation).
    za = _za(model, q, Qr)                                # F^-1 Q_reg, so a = F^-T za
    rig = model.rigid_bodies()
    z4 = np.array([bd.offset + 6 for bd in rig], dtype=int)
    keep = np.setdiff1d(np.arange(model.n), z4)
    jr = np.arange(model.norm_rows.start)
    z = za.copy()
    z[z4] = np.sqrt([bd.k_reg for bd in rig]) * b[model.norm_rows]
    rhs = b[jr] - D[np.ix_(jr, z4)] @ z[z4]
    Dk = D[np.ix_(jr, keep)]
    z[keep] = za[keep] + pinv(Dk, rtol) @ (rhs - Dk @ za[keep])
    return FiT @ z


def _za(model, q, Qr):
    """``F^-1 Q_reg`` body by body (``a = F^-T F^-1 Q_reg``)."""
    z = np.zeros(model.n)
    for bd in model.bodies:
        s = slice(bd.offset, bd.offset + bd.ncoord)
        z[s] = bd.factor_inv_T(q).T @ Qr[s]
    return z


def qdd_augmented(M, Q, A, b, alpha=1.0, rtol=None):
    """``M_A = M + alpha A^T A`` (positive definite iff ``[M; A]`` has full column rank)."""
    MA = M + alpha * A.T @ A
    QA = Q + alpha * A.T @ b
    w, V = np.linalg.eigh(0.5 * (MA + MA.T))
    if w[0] <= 0:
        raise np.linalg.LinAlgError(f"M + alpha A^T A not positive definite (min eig {w[0]:.3e})")
    Mih = (V / np.sqrt(w)) @ V.T
    a = Mih @ (Mih @ QA)
    return a + Mih @ (pinv(A @ Mih, rtol) @ (b - A @ a))


def qdd_singular(M, Q, A, b, rtol=None):
    """Udwadia-Phohomsiri 2006 for singular ``M``."""
    P = np.eye(M.shape[0]) - pinv(A, rtol) @ A
    K = np.vstack([P @ M, A])
    return pinv(K) @ np.concatenate([P @ Q, b])


def accelerations(model, t, q, qd, route="block", **kw):
    T = model.terms(t, q, qd)
    if route == "block":
        return qdd_block(model, t, q, qd, terms=T, **kw)
    if route == "augmented":
        return qdd_augmented(T["M"], T["Q"], T["A"], T["b"], **kw)
    if route == "singular":
        return qdd_singular(T["M"], T["Q"], T["A"], T["b"], **kw)
    raise ValueError(route)


def uk_rank(model, t, q, rtol=None):
    """Rank of ``D = A F^-T`` at the pinv tolerance (equals rank A)."""
    D = model.A(t, q) @ _block_factor_inv_T(model, q)
    s = np.linalg.svd(D, compute_uv=False)
    tol = (max(D.shape) * np.finfo(float).eps if rtol is None else rtol) * s[0]
    return int(np.sum(s > tol)), s


def multipliers(M, Q, A, qdd, rtol=None):
    """Minimum-norm ``lam`` with ``A^T lam = Q - M qdd`` (what UK's eq. (74) gives: its
    pseudoinverse lands in ``range(A)``, the orthogonal complement of ``null(A^T)``)."""
    return pinv(A.T, rtol) @ (Q - M @ qdd)


# ----------------------------------------------------------------------------------------
# joint reactions
# ----------------------------------------------------------------------------------------

def _body_wrench(model, body, Qc, q):
    """A generalized force block on ``body`` as (force, torque about its centre of mass),
    world components. ``f_p = 2 G^T n' + (multiple of p)`` -> ``n' = G f_p / (2 |p|^2)``."""
    from .rotations import rot_A, rot_G
    s = Qc[body.offset:body.offset + body.ncoord]
    F = s[:3].copy()
    if body.kind != "rigid":
        return F, np.zeros(3)
    p = body.p(q)
    nb = rot_G(p) @ s[3:] / (2.0 * (p @ p))
    return F, rot_A(p) @ nb / (p @ p)


def reaction_map(model, t, q, joint, frame="world"):
    """Linear map ``R`` (6, m): ``[force; torque] = R lam`` -- the force and the torque (about
    the first marker's point) that the joint exerts on the body of its **first** marker, the
    convention of the Rust core's ``Reaction`` (the second marker's body receives the opposite
    wrench); for a first marker on the ground, the wrench the ground receives. Components in
    world axes (``frame="world"``) or in the first marker's axes (``frame="joint"``)."""
    A = model.A(t, q)
    m = A.shape[0]
    R = np.zeros((6, m))
    on_i = joint.mi.body is not None
    body = joint.mi.body if on_i else joint.mj.body
    X = model.marker_position(joint.mi, q)
    sign = 1.0 if on_i else -1.0
    rc = body.r(q)
    for r in range(joint.rows.start, joint.rows.stop):
        Qc = -A[r]                        # generalized constraint force of lam_r = 1
        F, n_c = _body_wrench(model, body, Qc, q)
        R[:3, r] = sign * F
        R[3:, r] = sign * (n_c - np.cross(X - rc, F))
    if frame == "joint":
        C = model.marker_axes(joint.mi, q)
        R = np.vstack([C.T @ R[:3], C.T @ R[3:]])
    return R


def joint_reactions(model, t, q, qd, lam=None, rtol=None, frame="world"):
    """Dict name -> (force (3,), torque (3,)) for every joint and driver, from the
    minimum-norm multipliers (``rtol``: the pseudoinverse's rank tolerance, see
    :func:`simulate`; an over-constrained mechanism off its constraint manifold needs one
    above the drift, else the redundant direction is inverted and the multipliers explode)."""
    if lam is None:
        T = model.terms(t, q, qd)
        qdd = qdd_block(model, t, q, qd, terms=T, rtol=rtol)
        lam = multipliers(T["M"], T["Q"], T["A"], qdd, rtol=rtol)
    out = {}
    for j in model.joints:
        w = reaction_map(model, t, q, j, frame) @ lam
        out[j.name] = (w[:3], w[3:])
    return out


def reaction_uniqueness(model, t, q, rtol=1e-8, rank_rtol=1e-8):
    """Which reaction components (joint frame: force, then torque, along the first marker's
    x, y, z) are the same for every admissible ``lam``: component ``c`` of joint ``j`` is
    unique iff its row of ``R_j`` is orthogonal to ``null(A^T)``.
    Returns ``(null_dim, {name: bool (6,)})``."""
    A = model.A(t, q)
    U, s, Vt = np.linalg.svd(A.T, full_matrices=True)
    tol = rank_rtol * s[0]
    r = int(np.sum(s > tol))
    Z = Vt[r:].T                                   # null(A^T), (m, m - r)
    out = {}
    for j in model.joints:
        R = reaction_map(model, t, q, j, frame="joint")
        scale = np.abs(R).max() + 1e-300
        out[j.name] = np.abs(R @ Z).max(axis=1) <= rtol * scale if Z.size else np.ones(6, bool)
    return Z.shape[1], out


# ----------------------------------------------------------------------------------------
# initial state
# ----------------------------------------------------------------------------------------

def _metric(model, q, qd, hold):
    W, _ = model.regularized(q, qd)
    free = np.ones(model.n, bool)
    if hold is not None:
        free[np.asarray(hold)] = False
    return W, free


def correct_initial_state(model, q0=None, qd0=None, t0=0.0, hold=None, tol=1e-13, maxit=50):
    """Positions by Gauss-Newton in the mass metric (the smallest ``dq^T W dq`` that brings
    ``Phi`` to zero, ``W`` the regularized mass matrix), then velocities by the
    ``W``-orthogonal projection onto ``A qd + Phi_t = 0``. ``hold``: coordinates kept.
    Returns ``(q, qd, report)``."""
    qi, qdi = model.initial_guess()
    q = np.array(qi if q0 is None else q0, dtype=float)
    qd = np.array(qdi if qd0 is None else qd0, dtype=float)
    qs, qds = q.copy(), qd.copy()
    W, free = _metric(model, q, qd, hold)
    Wf = W[np.ix_(free, free)]
    it = 0
    for it in range(maxit):
        Phi = model.phi(t0, q)
        if np.linalg.norm(Phi) <= tol * max(1.0, np.abs(q).max()):
            break
        A = model.A(t0, q)[:, free]
        X = np.linalg.solve(Wf, A.T)
        q[free] -= X @ (pinv(A @ X) @ Phi)
    else:
        raise RuntimeError(f"position correction did not converge (|Phi| = {np.linalg.norm(Phi):.3e})")
    qd = consistent_velocities(model, q, qd, t0, hold=hold)
    rep = {"iterations": it, "dq": float(np.linalg.norm(q - qs)), "dqd": float(np.linalg.norm(qd - qds)),
           "phi": float(np.linalg.norm(model.phi(t0, q))),
           "velocity_residual": float(np.linalg.norm(model.A(t0, q) @ qd + model.phi_t(t0, q)))}
    return q, qd, rep


def consistent_velocities(model, q, qd, t0=0.0, hold=None, extra_rows=None, extra_values=None):
    """The ``W``-closest ``qd`` to the given one with ``A qd + Phi_t = 0`` (and optional extra
    rows ``C qd = v``, e.g. an initial crank speed)."""
    W, free = _metric(model, q, qd, hold)
    A = model.A(t0, q)
    r = -model.phi_t(t0, q) - A @ qd
    if extra_rows is not None:
        C = np.atleast_2d(extra_rows)
        A = np.vstack([A, C])
        r = np.concatenate([r, np.atleast_1d(extra_values) - C @ qd])
    Af = A[:, free]
    X = np.linalg.solve(W[np.ix_(free, free)], Af.T)
    qd = qd.copy()
    qd[free] += X @ (pinv(Af @ X) @ r)
    return qd


# ----------------------------------------------------------------------------------------
# solve_ivp driver
# ----------------------------------------------------------------------------------------

@dataclass
class SpatialResult:
    t: np.ndarray
    q: np.ndarray            # (n, nt)
    qd: np.ndarray
    nfev: int = 0
    status: int = 0
    message: str = ""
    wall_time: float = 0.0
    projections: int = 0
    extra: dict = field(default_factory=dict)


def project(model, t, q, qd, tol=1e-14, maxit=10):
    """Coordinate projection (mass metric) of a state onto ``Phi = 0`` and ``A qd + Phi_t = 0``."""
    W, _ = model.regularized(q, qd)
    q = q.copy()
    for _ in range(maxit):
        Phi = model.phi(t, q)
        if np.linalg.norm(Phi) <= tol:
            break
        A = model.A(t, q)
        X = np.linalg.solve(W, A.T)
        q -= X @ (pinv(A @ X) @ Phi)
    A = model.A(t, q)
    X = np.linalg.solve(W, A.T)
    qd = qd - X @ (pinv(A @ X) @ (A @ qd + model.phi_t(t, q)))
    return q, qd


def simulate(model, t_end, q0=None, qd0=None, t0=0.0, method="DOP853", rtol=1e-10, atol=1e-12,
             t_eval=None, route="block", project_every=None, events=None, pinv_rtol=None, **kw):
    """Integrate ``y = [q, qd]`` with ``solve_ivp``; accelerations from UK (``route``).

    ``project_every``: if set, the run is split into segments of this length and the state is
    projected onto the constraints (:func:`project`) between segments; otherwise the drift is
    left as it comes (measure it with ``model.phi``). ``pinv_rtol``: the rank tolerance of the
    pseudoinverse relative to the largest singular value (default ``max(m, n) eps``); see the
    design note on redundant constraints.
    """
    if q0 is None or qd0 is None:
        qc, qdc, _ = correct_initial_state(model, q0, qd0, t0)
        q0 = qc if q0 is None else q0
        qd0 = qdc if qd0 is None else qd0
    n = model.n

    def rhs(t, y):
        q, qd = y[:n], y[n:]
        return np.concatenate([qd, accelerations(model, t, q, qd, route=route, rtol=pinv_rtol)])

    tic = time.perf_counter()
    if project_every is None:
        sol = solve_ivp(rhs, (t0, t_end), np.concatenate([q0, qd0]), method=method, rtol=rtol,
                        atol=atol, t_eval=t_eval, dense_output=False, events=events, **kw)
        res = SpatialResult(sol.t, sol.y[:n], sol.y[n:], sol.nfev, sol.status, sol.message)
        res.extra["events"] = sol.t_events
        res.wall_time = time.perf_counter() - tic
        return res
    ts, qs, qds = [t0], [np.asarray(q0, float)], [np.asarray(qd0, float)]
    y = np.concatenate([q0, qd0])
    t = t0
    nfev = 0
    nproj = 0
    while t < t_end - 1e-14:
        t1 = min(t + project_every, t_end)
        te = None if t_eval is None else t_eval[(t_eval > t) & (t_eval <= t1)]
        sol = solve_ivp(rhs, (t, t1), y, method=method, rtol=rtol, atol=atol, t_eval=te, **kw)
        nfev += sol.nfev
        if sol.status != 0:
            break
        if sol.t.size and (te is None or te.size):
            keep = slice(1, None) if te is None else slice(None)
            ts += list(sol.t[keep])
            qs += list(sol.y[:n, keep].T)
            qds += list(sol.y[n:, keep].T)
        qp, qdp = project(model, t1, sol.y[:n, -1], sol.y[n:, -1])
        nproj += 1
        y = np.concatenate([qp, qdp])
        t = t1
    res = SpatialResult(np.array(ts), np.array(qs).T, np.array(qds).T, nfev, 0, "")
    res.projections = nproj
    res.wall_time = time.perf_counter() - tic
    return res
