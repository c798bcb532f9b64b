"""Kinematic quantities carried with their first and second time derivatives.

A :class:`Kin` is a vector ``v(q)`` (shape (k,)) together with

* ``J = dv/dq`` (k, n) -- the rows it contributes to ``A = Phi_q``,
* ``vd = J qd`` -- its velocity,
* ``h`` -- the part of its second derivative that does not contain ``qdd``:
  ``vdd = J qdd + h``. For a constraint ``Phi = g(q) - f(t)``, ``h`` is ``(A qd)_q qd`` and
  ``gamma = -h + f''(t)``.

Markers give points ``P = r + A(p) s'`` and vectors ``a = A(p) a'``; constraints and forces are
scalar products, differences and norms of them, built with the product rule below. Nothing here
is specific to one joint: every joint's Jacobian and gamma come out of these few rules, which
the tests check against finite differences of ``Phi`` and of ``A qd``.
"""
from __future__ import annotations

import numpy as np

from .rotations import rot_A, rot_B

__all__ = ["Kin", "dot", "scalar_stack"]


class Kin:
    __slots__ = ("v", "J", "vd", "h")

    def __init__(self, v, J, vd, h):
        self.v = np.atleast_1d(np.asarray(v, dtype=float))
        self.J = np.atleast_2d(np.asarray(J, dtype=float))
        self.vd = np.atleast_1d(np.asarray(vd, dtype=float))
        self.h = np.atleast_1d(np.asarray(h, dtype=float))

    @staticmethod
    def constant(v, n):
        v = np.atleast_1d(np.asarray(v, dtype=float))
        z = np.zeros(v.shape[0])
        return Kin(v, np.zeros((v.shape[0], n)), z, z.copy())

    def __sub__(self, other):
        return Kin(self.v - other.v, self.J - other.J, self.vd - other.vd, self.h - other.h)

    def __add__(self, other):
        return Kin(self.v + other.v, self.J + other.J, self.vd + other.vd, self.h + other.h)

    def scale(self, c):
        return Kin(c * self.v, c * self.J, c * self.vd, c * self.h)

    def __repr__(self):
        return f"Kin(v={self.v})"


def dot(u, w):
    """Scalar product of two 3-vectors: ``s = u.w``; ``sdd = J_s qdd + u.h_w + w.h_u + 2 ud.wd``."""
    return Kin([u.v @ w.v], (w.v @ u.J + u.v @ w.J)[None, :], [u.v @ w.vd + w.v @ u.vd],
               [u.v @ w.h + w.v @ u.h + 2.0 * (u.vd @ w.vd)])


def scalar_stack(kins):
    """Stack scalar (or vector) Kins into one Kin of their rows."""
    if not kins:
        return None
    return Kin(np.concatenate([k.v for k in kins]), np.vstack([k.J for k in kins]),
               np.concatenate([k.vd for k in kins]), np.concatenate([k.h for k in kins]))


def body_point(n, off, q, qd, s):
    """Point ``P = r + A(p) s'`` of a rigid body whose coordinates start at ``off``."""
    r, p = q[off:off + 3], q[off + 3:off + 7]
    rd, pd = qd[off:off + 3], qd[off + 3:off + 7]
    B = rot_B(p, s)
    J = np.zeros((3, n))
    J[:, off:off + 3] = np.eye(3)
    J[:, off + 3:off + 7] = B
    return Kin(r + rot_A(p) @ s, J, rd + B @ pd, rot_B(pd, s) @ pd)


def body_vector(n, off, q, qd, a):
    """Body-fixed vector ``a = A(p) a'``."""
    p, pd = q[off + 3:off + 7], qd[off + 3:off + 7]
    B = rot_B(p, a)
    J = np.zeros((3, n))
    J[:, off + 3:off + 7] = B
    return Kin(rot_A(p) @ a, J, B @ pd, rot_B(pd, a) @ pd)


def particle_point(n, off, q, qd):
    """Position of a point mass (coordinates ``r`` at ``off``)."""
    J = np.zeros((3, n))
    J[:, off:off + 3] = np.eye(3)
    return Kin(q[off:off + 3].copy(), J, qd[off:off + 3].copy(), np.zeros(3))
