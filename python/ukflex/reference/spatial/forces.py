"""Applied forces as generalized forces ``Q`` (virtual work ``Q . dq``).

* gravity ``m g`` at the centre of mass: ``Q_r = m g`` (rigid bodies and point masses);
* a point force ``F`` at a marker (world components, or components ``F'`` in the marker's axes,
  which turn with the body: ``F = A C F'``):
  ``Q = J_P^T F`` with ``J_P = dP/dq = [I, B(p, s')]``;
* a torque (world ``n`` or body ``n'``): ``Q_p = 2 G^T n'`` (virtual rotation
  ``d pi' = 2 G dp``);
* a translational spring-damper between two marker points: ``L = |d|``,
  ``f = k (L - L0) + c Ld`` (tension positive), ``Q = -f J_L^T``, ``J_L = u^T (J_Pj - J_Pi)``;
* a rotational spring-damper about a joint axis ``z_i``: ``theta = atan2(y_i.x_j, x_i.x_j)``,
  ``tau = -k (theta - theta0) - c thetad``, ``Q = tau J_theta^T`` with
  ``J_theta = (c J_s - s J_c) / (s^2 + c^2)``. ``atan2`` limits ``theta`` to ``(-pi, pi]``:
  the reference is for motions that stay within one turn (a turn counter in the workspace is
  the kernel's way past it; see the design note).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kinematics import dot
from .rotations import rot_A, rot_G

__all__ = ["PointForce", "Torque", "SpringDamper", "RotationalSpringDamper"]


@dataclass
class PointForce:
    marker: object
    vector: np.ndarray
    frame: str = "world"
    name: str = ""

    def Q(self, t, n, q, qd):
        m = self.marker
        P = m.point(n, q, qd)
        F = np.asarray(self.vector, dtype=float)
        if self.frame == "body" and m.body is not None and m.body.kind == "rigid":
            F = rot_A(m.body.p(q)) @ (m.orientation @ F)
        return P.J[0:3].T @ F

    def potential(self, t, q):
        return 0.0   # not conservative in general (body frame); no energy term


@dataclass
class Torque:
    body: object
    vector: np.ndarray
    frame: str = "world"
    name: str = ""

    def Q(self, t, n, q, qd):
        b = self.body
        Q = np.zeros(n)
        p = b.p(q)
        nn = np.asarray(self.vector, dtype=float)
        nb = nn if self.frame == "body" else rot_A(p).T @ nn
        Q[b.offset + 3:b.offset + 7] = 2.0 * rot_G(p).T @ nb
        return Q

    def potential(self, t, q):
        return 0.0


@dataclass
class SpringDamper:
    mi: object
    mj: object
    stiffness: float
    damping: float = 0.0
    length0: float = 0.0
    name: str = ""

    def length(self, n, q, qd):
        d = self.mj.point(n, q, qd) - self.mi.point(n, q, qd)
        L = float(np.linalg.norm(d.v))
        u = d.v / L
        JL = u @ d.J
        return L, JL, float(JL @ qd)

    def tension(self, n, q, qd):
        L, JL, Ld = self.length(n, q, qd)
        return self.stiffness * (L - self.length0) + self.damping * Ld

    def Q(self, t, n, q, qd):
        L, JL, Ld = self.length(n, q, qd)
        f = self.stiffness * (L - self.length0) + self.damping * Ld
        return -f * JL

    def potential(self, t, q):
        n = q.size
        L = self.length(n, q, np.zeros(n))[0]
        return 0.5 * self.stiffness * (L - self.length0) ** 2

    def dissipation(self, q, qd):
        return self.damping * self.length(q.size, q, qd)[2] ** 2


@dataclass
class RotationalSpringDamper:
    mi: object
    mj: object
    stiffness: float
    damping: float = 0.0
    angle0: float = 0.0
    name: str = ""

    def angle(self, n, q, qd):
        xi, yi, xj = self.mi.axis(0, n, q, qd), self.mi.axis(1, n, q, qd), self.mj.axis(0, n, q, qd)
        s, c = dot(yi, xj), dot(xi, xj)
        r2 = s.v[0] ** 2 + c.v[0] ** 2
        Jt = (c.v[0] * s.J[0] - s.v[0] * c.J[0]) / r2
        return float(np.arctan2(s.v[0], c.v[0])), Jt, float(Jt @ qd)

    def Q(self, t, n, q, qd):
        th, Jt, thd = self.angle(n, q, qd)
        tau = -self.stiffness * (th - self.angle0) - self.damping * thd
        return tau * Jt

    def potential(self, t, q):
        n = q.size
        th = self.angle(n, q, np.zeros(n))[0]
        return 0.5 * self.stiffness * (th - self.angle0) ** 2

    def dissipation(self, q, qd):
        return self.damping * self.angle(q.size, q, qd)[2] ** 2
