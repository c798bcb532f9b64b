"""The spatial model: coordinates, ``M(q)``, ``Q(t, q, qd)``, ``Phi``, ``A = Phi_q``, ``b = gamma``.

Equations of motion (the planar reference's sign convention)::

    M(q) qdd + A^T lam = Q(t, q, qd),      A qdd = b,
    b = gamma = -(A qd)_q qd - 2 Phi_qt qd - Phi_tt.

Row order of ``Phi``: joints and drivers in the order they were added, then one
normalization row ``p^T p - 1`` per rigid body (``A`` row ``2 p^T``, ``gamma = -2 pd.pd``).

``M`` is the true (singular) mass matrix. ``regularized(q, qd)`` returns the block-diagonal
``M + sum_i 4 k_i p_i p_i^T`` and the matching right-hand side ``Q - sum_i 4 k_i (pd_i.pd_i) p_i``,
which is the normalization rows' ``k A_n^T (A_n qdd - b_n) = 0`` added to the equations: the
accelerations it gives are those of ``M`` itself (see :mod:`.uk`).
"""
from __future__ import annotations

import numpy as np

from .bodies import RigidBody, PointMass
from .forces import PointForce, Torque, SpringDamper, RotationalSpringDamper
from .joints import Marker, Joint, Driver, frame_from_z, InvalidJoint
from .rotations import rot_A

__all__ = ["SpatialModel"]


class SpatialModel:
    def __init__(self, gravity=(0.0, 0.0, 0.0), name=""):
        self.gravity = np.asarray(gravity, dtype=float)
        self.name = name
        self.bodies = []
        self.markers = []
        self.joints = []       # joints and drivers, in row order
        self.forces = []
        self.n = 0
        self._m = None

    # -- building -----------------------------------------------------------------------
    def add_rigid_body(self, mass, inertia, **kw):
        b = RigidBody(mass, inertia, **kw)
        return self._add_body(b)

    def add_point_mass(self, mass, **kw):
        return self._add_body(PointMass(mass, **kw))

    def _add_body(self, b):
        b.offset = self.n
        self.n += b.ncoord
        self.bodies.append(b)
        self._m = None
        return b

    def add_marker(self, body, position=(0.0, 0.0, 0.0), orientation=None, z=None, x=None, name=""):
        """A frame on ``body`` (None: the ground). ``orientation`` (columns x, y, z in body axes),
        or its ``z`` axis (and optionally a hint for ``x``)."""
        if orientation is None:
            orientation = np.eye(3) if z is None else frame_from_z(z, x)
        m = Marker(body, position, orientation, name)
        self.markers.append(m)
        return m

    def add_joint(self, kind, mi, mj, name="", length=None):
        j = Joint(kind, mi, mj, name=name or f"{kind}{len(self.joints)}", length=length)
        if kind == "distance" and length is None:
            q0, _ = self.initial_guess()
            n = self.n
            d = mj.point(n, q0, np.zeros(n)).v - mi.point(n, q0, np.zeros(n)).v
            j.length = float(np.linalg.norm(d))
        self.joints.append(j)
        self._m = None
        return j

    def add_driver(self, kind, mi, mj, motion, name=""):
        d = Driver(kind, mi, mj, motion, name=name or f"{kind}_driver{len(self.joints)}")
        self.joints.append(d)
        self._m = None
        return d

    def add_force(self, marker, vector, frame="world", name=""):
        f = PointForce(marker, vector, frame, name)
        self.forces.append(f)
        return f

    def add_torque(self, body, vector, frame="world", name=""):
        if body is None or body.kind != "rigid":
            raise InvalidJoint("a torque acts on a rigid body")
        f = Torque(body, vector, frame, name)
        self.forces.append(f)
        return f

    def add_spring_damper(self, mi, mj, stiffness, damping=0.0, length0=None, name=""):
        if length0 is None:
            q0, _ = self.initial_guess()
            n = self.n
            length0 = float(np.linalg.norm(mj.point(n, q0, np.zeros(n)).v - mi.point(n, q0, np.zeros(n)).v))
        f = SpringDamper(mi, mj, stiffness, damping, length0, name)
        self.forces.append(f)
        return f

    def add_rotational_spring_damper(self, mi, mj, stiffness, damping=0.0, angle0=0.0, name=""):
        f = RotationalSpringDamper(mi, mj, stiffness, damping, angle0, name)
        self.forces.append(f)
        return f

    # -- layout -------------------------------------------------------------------------
    def _layout(self):
        if self._m is not None:
            return
        r = 0
        for j in self.joints:
            j.rows = slice(r, r + j.nrows)
            r += j.nrows
        self.rigid = [b for b in self.bodies if b.kind == "rigid"]
        self.norm_rows = slice(r, r + len(self.rigid))
        self._m = r + len(self.rigid)

    @property
    def m(self):
        self._layout()
        return self._m

    def initial_guess(self):
        q = np.zeros(self.n)
        qd = np.zeros(self.n)
        for b in self.bodies:
            qi, qdi = b.initial_guess()
            q[b.offset:b.offset + b.ncoord] = qi
            qd[b.offset:b.offset + b.ncoord] = qdi
        return q, qd

    def euler_parameter_indices(self):
        return np.array([b.offset + 3 + k for b in self.bodies if b.kind == "rigid" for k in range(4)],
                        dtype=int)

    # -- terms --------------------------------------------------------------------------
    def M(self, q):
        M = np.zeros((self.n, self.n))
        for b in self.bodies:
            s = slice(b.offset, b.offset + b.ncoord)
            M[s, s] = b.mass_block(q)
        return M

    def Q(self, t, q, qd):
        n = self.n
        Q = np.zeros(n)
        for b in self.bodies:
            s = slice(b.offset, b.offset + b.ncoord)
            Q[s] += b.quadratic_velocity(q, qd)
            if np.any(self.gravity):
                Q[s] += b.gravity(self.gravity)
        for f in self.forces:
            Q += f.Q(t, n, q, qd)
        return Q

    def regularized(self, q, qd):
        """``(M_reg, Q_reg_shift)``: ``M + sum 4 k p p^T`` and ``-sum 4 k (pd.pd) p``."""
        Mr = self.M(q)
        Qs = np.zeros(self.n)
        for b in self.rigid_bodies():
            s = slice(b.offset, b.offset + 7)
            dM, dQ = b.regularization(q, qd)
            Mr[s, s] += dM
            Qs[s] += dQ
        return Mr, Qs

    def rigid_bodies(self):
        self._layout()
        return self.rigid

    def constraint_terms(self, t, q, qd):
        """``(Phi, A, phi_t, gamma)`` of every row."""
        self._layout()
        n, m = self.n, self._m
        Phi = np.zeros(m)
        A = np.zeros((m, n))
        phi_t = np.zeros(m)
        gamma = np.zeros(m)
        for j in self.joints:
            if isinstance(j, Driver):
                ph, J, pt, g = j.terms(t, n, q, qd)
                Phi[j.rows], A[j.rows], phi_t[j.rows], gamma[j.rows] = ph, J, pt, g
            else:
                k = j.kin(n, q, qd)
                Phi[j.rows], A[j.rows], gamma[j.rows] = k.v, k.J, -k.h
        for i, b in enumerate(self.rigid):
            r = self.norm_rows.start + i
            p, pd = b.p(q), b.p(qd)
            Phi[r] = p @ p - 1.0
            A[r, b.offset + 3:b.offset + 7] = 2.0 * p
            gamma[r] = -2.0 * pd @ pd
        return Phi, A, phi_t, gamma

    def phi(self, t, q):
        return self.constraint_terms(t, q, np.zeros(self.n))[0]

    def A(self, t, q):
        return self.constraint_terms(t, q, np.zeros(self.n))[1]

    def phi_t(self, t, q):
        return self.constraint_terms(t, q, np.zeros(self.n))[2]

    def gamma(self, t, q, qd):
        return self.constraint_terms(t, q, qd)[3]

    def terms(self, t, q, qd):
        """All terms at once: dict with M, Q, Phi, A, phi_t, b."""
        Phi, A, phi_t, b = self.constraint_terms(t, q, qd)
        return {"M": self.M(q), "Q": self.Q(t, q, qd), "Phi": Phi, "A": A, "phi_t": phi_t, "b": b}

    # -- sensors ------------------------------------------------------------------------
    def kinetic_energy(self, q, qd):
        return float(sum(b.kinetic_energy(q, qd) for b in self.bodies))

    def potential_energy(self, t, q):
        V = 0.0
        for b in self.bodies:
            V -= b.mass * self.gravity @ b.r(q)
        for f in self.forces:
            V += f.potential(t, q)
        return float(V)

    def energy(self, t, q, qd):
        return self.kinetic_energy(q, qd) + self.potential_energy(t, q)

    def angular_momentum(self, q, qd, about=(0.0, 0.0, 0.0)):
        about = np.asarray(about, dtype=float)
        return sum(b.angular_momentum(q, qd, about) for b in self.bodies)

    def marker_position(self, marker, q):
        return marker.point(self.n, q, np.zeros(self.n)).v

    def marker_axes(self, marker, q):
        b = marker.body
        if b is None or b.kind == "point":
            return marker.orientation.copy()
        return rot_A(b.p(q)) @ marker.orientation

    def rank_report(self, t, q, rtol=None):
        """Singular values of ``A``, its numerical rank (pinv tolerance) and the degrees of
        freedom ``n - rank``; ``redundant = m - rank``."""
        A = self.A(t, q)
        s = np.linalg.svd(A, compute_uv=False)
        tol = (max(A.shape) * np.finfo(float).eps if rtol is None else rtol) * s[0]
        r = int(np.sum(s > tol))
        return {"rank": r, "rows": A.shape[0], "n": self.n, "dof": self.n - r,
                "redundant": A.shape[0] - r, "singular_values": s, "tol": tol}
