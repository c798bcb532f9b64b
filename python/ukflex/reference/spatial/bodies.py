"""Spatial bodies: a rigid body in Euler parameters and a point mass.

Rigid body coordinates ``q_i = [r (3), p (4)]``: ``r`` is the **centre of mass** in world
components, ``p`` the Euler parameters of the body frame. A centre-of-mass offset ``c'`` from
the user's body frame is absorbed when the body is built: a marker given at ``s`` in the body
frame sits at ``s' = s - c'`` from the centre of mass, and the body frame origin is
``r - A c'``. The mass matrix is then block diagonal without a coupling block:

    M_i = diag(m I_3, 4 G^T J G),        J = inertia about the centre of mass, body axes,

and the velocity-dependent generalized force (Lagrange's equations with
``T = 1/2 m rd.rd + 2 pd^T G^T J G pd``; docs/spatial-design.md derives it) is

    Q_v = [0; 8 Gd^T J Gd p],            Gd = G(pd).

``M_pp = 4 G^T J G`` has rank 3 (``G p = 0``). The regularized block that the recommended UK
route factors is ``4 G^T J G + 4 k p p^T`` with ``k = trace(J)/3``; with ``N = [G; p^T]``
(``N N^T = |p|^2 I``) it is ``4 N^T diag(J, k) N`` and has the explicit factor
``F = 2 N^T diag(L_J, sqrt(k))`` (``J = L_J L_J^T``), so
``F^-T = N^T diag(L_J^-T, 1/sqrt(k)) / (2 |p|^2)``.

A point mass has coordinates ``r`` (3) and ``M = m I_3``; its markers carry no orientation
(their axes are the world axes).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .rotations import rot_A, rot_G, p_from_matrix, pd_from_omega_world

__all__ = ["RigidBody", "PointMass", "check_inertia", "box_inertia", "InvalidBody"]


class InvalidBody(ValueError):
    pass


def check_inertia(J, name="body"):
    """Symmetric, positive definite, principal moments obey the triangle inequality."""
    J = np.asarray(J, dtype=float)
    if J.shape != (3, 3) or not np.all(np.isfinite(J)):
        raise InvalidBody(f"{name}: inertia must be a finite 3x3 matrix")
    if np.abs(J - J.T).max() > 1e-12 * max(1.0, np.abs(J).max()):
        raise InvalidBody(f"{name}: inertia tensor is not symmetric")
    w = np.linalg.eigvalsh(J)
    if w[0] <= 0.0:
        raise InvalidBody(f"{name}: inertia tensor is not positive definite (eigenvalues {w})")
    if w[0] + w[1] < w[2] * (1.0 - 1e-12):
        raise InvalidBody(f"{name}: principal moments {w} violate the triangle inequality")
    return 0.5 * (J + J.T)


def box_inertia(m, a, b, c):
    """Inertia about the centre of a homogeneous box with edges a, b, c along x, y, z."""
    return m / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


@dataclass
class RigidBody:
    mass: float
    inertia: np.ndarray                       # about the centre of mass, body axes (3, 3)
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))   # c' in the body frame
    position: np.ndarray = field(default_factory=lambda: np.zeros(3))  # body frame origin, world
    orientation: np.ndarray = field(default_factory=lambda: np.eye(3))  # body -> world
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))   # of the body frame origin
    angular_velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))  # world components
    name: str = ""
    offset: int = -1                           # first coordinate in q (set by the model)

    ncoord = 7
    kind = "rigid"

    def __post_init__(self):
        if not (np.isfinite(self.mass) and self.mass > 0):
            raise InvalidBody(f"{self.name}: mass must be positive and finite")
        self.inertia = check_inertia(self.inertia, self.name)
        self.com = np.asarray(self.com, dtype=float)
        self.position = np.asarray(self.position, dtype=float)
        self.orientation = np.asarray(self.orientation, dtype=float)
        self.velocity = np.asarray(self.velocity, dtype=float)
        self.angular_velocity = np.asarray(self.angular_velocity, dtype=float)
        self.k_reg = float(np.trace(self.inertia)) / 3.0
        self.L_J = np.linalg.cholesky(self.inertia)

    # -- layout -------------------------------------------------------------------------
    def r(self, q):
        return q[self.offset:self.offset + 3]

    def p(self, q):
        return q[self.offset + 3:self.offset + 7]

    def local(self, s):
        """Body-frame point -> coordinates relative to the centre of mass."""
        return np.asarray(s, dtype=float) - self.com

    def initial_guess(self):
        p = p_from_matrix(self.orientation)
        R = rot_A(p)
        r = self.position + R @ self.com
        w = self.angular_velocity
        rd = self.velocity + np.cross(w, R @ self.com)
        return np.concatenate([r, p]), np.concatenate([rd, pd_from_omega_world(p, w)])

    # -- mass ---------------------------------------------------------------------------
    def mass_block(self, q):
        G = rot_G(self.p(q))
        M = np.zeros((7, 7))
        M[:3, :3] = self.mass * np.eye(3)
        M[3:, 3:] = 4.0 * G.T @ self.inertia @ G
        return M

    def regularization(self, q, qd):
        """``(4 k p p^T, -4 k (pd.pd) p)``: ``alpha A_n^T A_n`` and ``alpha A_n^T b_n`` of the
        normalization row ``A_n = 2 p^T``, ``b_n = -2 pd.pd`` with ``alpha = k``."""
        p, pd = self.p(q), self.p(qd)
        Mr = np.zeros((7, 7))
        Mr[3:, 3:] = 4.0 * self.k_reg * np.outer(p, p)
        Qr = np.zeros(7)
        Qr[3:] = -4.0 * self.k_reg * (pd @ pd) * p
        return Mr, Qr

    def factor_inv_T(self, q):
        """Explicit ``F^-T`` (7, 7) of the regularized block ``F F^T``."""
        p = self.p(q)
        N = np.vstack([rot_G(p), p])
        D = np.zeros((4, 4))
        D[:3, :3] = np.linalg.inv(self.L_J).T
        D[3, 3] = 1.0 / np.sqrt(self.k_reg)
        FiT = np.zeros((7, 7))
        FiT[:3, :3] = np.eye(3) / np.sqrt(self.mass)
        FiT[3:, 3:] = N.T @ D / (2.0 * (p @ p))
        return FiT

    def quadratic_velocity(self, q, qd):
        Gd = rot_G(self.p(qd))
        Qv = np.zeros(7)
        Qv[3:] = 8.0 * Gd.T @ self.inertia @ Gd @ self.p(q)
        return Qv

    def gravity(self, g):
        Q = np.zeros(7)
        Q[:3] = self.mass * np.asarray(g)
        return Q

    # -- sensors ------------------------------------------------------------------------
    # Sensors read the rotation that p represents, p / |p|: with p = c u (|u| = 1),
    # G(p) pd = c^2 G(u) ud, so w' = 2 G(p) pd / |p|^2 and R = A(p) / |p|^2. On |p| = 1 these
    # are the usual formulas; off it (drift) they stay the physical ones.
    def kinetic_energy(self, q, qd):
        w = self.omega_body(q, qd)
        rd = self.r(qd)
        return 0.5 * self.mass * rd @ rd + 0.5 * w @ self.inertia @ w

    def omega_body(self, q, qd):
        p = self.p(q)
        return 2.0 * rot_G(p) @ self.p(qd) / (p @ p)

    def rotation(self, q):
        p = self.p(q)
        return rot_A(p) / (p @ p)

    def angular_momentum(self, q, qd, about):
        """World components, about the world point ``about``."""
        w = self.omega_body(q, qd)
        return self.mass * np.cross(self.r(q) - about, self.r(qd)) + self.rotation(q) @ (self.inertia @ w)

    def frame_origin(self, q):
        return self.r(q) - rot_A(self.p(q)) @ self.com


@dataclass
class PointMass:
    mass: float
    position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    name: str = ""
    offset: int = -1

    ncoord = 3
    kind = "point"

    def __post_init__(self):
        if not (np.isfinite(self.mass) and self.mass > 0):
            raise InvalidBody(f"{self.name}: mass must be positive and finite")
        self.position = np.asarray(self.position, dtype=float)
        self.velocity = np.asarray(self.velocity, dtype=float)
        self.com = np.zeros(3)

    def r(self, q):
        return q[self.offset:self.offset + 3]

    def local(self, s):
        s = np.asarray(s, dtype=float)
        if np.any(s != 0.0):
            raise InvalidBody(f"{self.name}: a marker on a point mass sits at the point itself")
        return s

    def initial_guess(self):
        return self.position.copy(), self.velocity.copy()

    def mass_block(self, q):
        return self.mass * np.eye(3)

    def regularization(self, q, qd):
        return np.zeros((3, 3)), np.zeros(3)

    def factor_inv_T(self, q):
        return np.eye(3) / np.sqrt(self.mass)

    def quadratic_velocity(self, q, qd):
        return np.zeros(3)

    def gravity(self, g):
        return self.mass * np.asarray(g, dtype=float)

    def kinetic_energy(self, q, qd):
        rd = self.r(qd)
        return 0.5 * self.mass * rd @ rd

    def angular_momentum(self, q, qd, about):
        return self.mass * np.cross(self.r(q) - about, self.r(qd))

    def frame_origin(self, q):
        return self.r(q).copy()


