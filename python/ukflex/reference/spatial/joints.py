"""Markers, joints and drivers: each joint kind states its rows from marker points and axes.

A marker is a frame on a body: a point ``s`` (body frame) and axes ``C`` (3 x 3, columns
``x, y, z`` in body axes). Every joint below is stated for two markers ``i`` (first) and ``j``
(second) so that it is satisfied when the two marker frames coincide; with
``d = P_j - P_i`` and world axes ``x_i = A_i C_i e_x`` etc.:

=============== ==== ============================================================
kind            rows equations
=============== ==== ============================================================
spherical       3    ``d = 0``
revolute        5    ``d = 0``, ``x_i.z_j = 0``, ``y_i.z_j = 0`` (about ``z``)
universal       4    ``d = 0``, ``x_i.y_j = 0`` (cross arms ``x_i`` and ``y_j``)
fixed (weld)    6    ``d = 0``, ``x_i.z_j = 0``, ``y_i.z_j = 0``, ``x_i.y_j = 0``
cylindrical     4    ``x_i.z_j = 0``, ``y_i.z_j = 0``, ``x_i.d = 0``, ``y_i.d = 0`` (along ``z``)
prismatic       5    cylindrical and ``x_i.y_j = 0``
planar          3    ``x_i.z_j = 0``, ``y_i.z_j = 0``, ``z_i.d = 0`` (in the ``x_i y_i`` plane)
distance        1    ``d.d - L^2 = 0``
point_on_line   2    ``x_i.d = 0``, ``y_i.d = 0`` (``P_j`` on the ``z_i`` line)
point_on_plane  1    ``z_i.d = 0`` (``P_j`` on the ``x_i y_i`` plane)
=============== ==== ============================================================

Drivers (one row each), for markers whose ``z`` axes the joint keeps parallel:

* ``rotation``: the angle ``theta`` of ``x_j`` about ``z_i`` measured from ``x_i``;
  ``Phi = s cos f(t) - c sin f(t)`` with ``s = y_i.x_j``, ``c = x_i.x_j``, i.e.
  ``Phi = rho sin(theta - f)`` (``rho = 1`` on the joint). No angle is ever computed, so the
  row is smooth and continuous through ``theta = +-pi`` and any number of turns; its gradient
  on the solution has size ``rho``. The angle the driver holds is reported as
  ``f + atan2(Phi, s sin f + c cos f)``, continuous as long as ``|theta - f| < pi``.
* ``translation``: ``Phi = z_i.d - f(t)``.

Motions give ``(f, f', f'')``: :class:`ConstantSpeed`, :class:`Polynomial`, :class:`Harmonic`,
:class:`MotionFunctions` (any three callables).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .kinematics import Kin, dot, body_point, body_vector, particle_point

__all__ = ["Marker", "Joint", "Driver", "JOINT_ROWS", "ConstantSpeed", "Polynomial", "Harmonic",
           "MotionFunctions", "InvalidJoint"]


class InvalidJoint(ValueError):
    pass


JOINT_ROWS = {"spherical": 3, "revolute": 5, "universal": 4, "fixed": 6, "cylindrical": 4,
              "prismatic": 5, "planar": 3, "distance": 1, "point_on_line": 2, "point_on_plane": 1}


def _unit_frame(C, name):
    C = np.asarray(C, dtype=float)
    if C.shape != (3, 3) or not np.all(np.isfinite(C)):
        raise InvalidJoint(f"{name}: marker orientation must be a finite 3x3 matrix")
    if np.abs(C.T @ C - np.eye(3)).max() > 1e-9 or np.linalg.det(C) < 0:
        raise InvalidJoint(f"{name}: marker orientation must be a rotation matrix")
    return C


def frame_from_z(z, x_hint=None):
    """A right-handed frame (columns x, y, z) whose z is ``z`` (normalized; zero is an error)."""
    z = np.asarray(z, dtype=float)
    nz = np.linalg.norm(z)
    if not np.isfinite(nz) or nz == 0.0:
        raise InvalidJoint("joint axis must be finite and nonzero")
    z = z / nz
    if x_hint is None:
        x_hint = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.asarray(x_hint, dtype=float) - (np.asarray(x_hint, dtype=float) @ z) * z
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


@dataclass
class Marker:
    body: object                 # RigidBody, PointMass or None (ground)
    position: np.ndarray         # in the body frame (world for the ground)
    orientation: np.ndarray      # columns x, y, z in body axes
    name: str = ""

    def __post_init__(self):
        self.position = np.asarray(self.position, dtype=float)
        self.orientation = _unit_frame(self.orientation, self.name or "marker")
        if self.body is not None:
            self.s = self.body.local(self.position)   # relative to the centre of mass
        else:
            self.s = self.position.copy()

    def point(self, n, q, qd):
        b = self.body
        if b is None:
            return Kin.constant(self.s, n)
        if b.kind == "point":
            return particle_point(n, b.offset, q, qd)
        return body_point(n, b.offset, q, qd, self.s)

    def axis(self, k, n, q, qd):
        a = self.orientation[:, k]
        b = self.body
        if b is None or b.kind == "point":
            return Kin.constant(a, n)
        return body_vector(n, b.offset, q, qd, a)


# ----------------------------------------------------------------------------------------
# motions
# ----------------------------------------------------------------------------------------

@dataclass
class ConstantSpeed:
    x0: float
    v: float

    def __call__(self, t):
        return self.x0 + self.v * t, self.v, 0.0


@dataclass
class Polynomial:
    coeffs: tuple    # c0 + c1 t + c2 t^2 + ...

    def __call__(self, t):
        c = np.asarray(self.coeffs, dtype=float)
        P = np.polynomial.Polynomial(c)
        return float(P(t)), float(P.deriv(1)(t)), float(P.deriv(2)(t))


@dataclass
class Harmonic:
    amplitude: float
    omega: float
    phase: float = 0.0
    offset: float = 0.0

    def __call__(self, t):
        a, w, ph = self.amplitude, self.omega, self.phase
        s, c = np.sin(w * t + ph), np.cos(w * t + ph)
        return self.offset + a * s, a * w * c, -a * w * w * s


@dataclass
class MotionFunctions:
    f: object
    fd: object
    fdd: object

    def __call__(self, t):
        return float(self.f(t)), float(self.fd(t)), float(self.fdd(t))


# ----------------------------------------------------------------------------------------
# joints
# ----------------------------------------------------------------------------------------

@dataclass
class Joint:
    kind: str
    mi: Marker
    mj: Marker
    name: str = ""
    length: float | None = None       # distance joint only
    rows: slice = field(default=None)  # set by the model

    def __post_init__(self):
        if self.kind not in JOINT_ROWS:
            raise InvalidJoint(f"unknown joint kind {self.kind!r}; known: {sorted(JOINT_ROWS)}")
        if self.mi.body is None and self.mj.body is None:
            raise InvalidJoint(f"{self.name}: a joint needs at least one body")
        if self.kind == "distance" and self.length is not None and not self.length > 0:
            raise InvalidJoint(f"{self.name}: distance must be positive")

    @property
    def nrows(self):
        return JOINT_ROWS[self.kind]

    def kin(self, n, q, qd):
        """Rows ``Phi`` (a Kin) of this joint."""
        mi, mj, k = self.mi, self.mj, self.kind
        ax = lambda m, c: m.axis(c, n, q, qd)  # noqa: E731
        d = mj.point(n, q, qd) - mi.point(n, q, qd)
        rows = []
        if k in ("spherical", "revolute", "universal", "fixed"):
            rows.append(d)
        if k in ("revolute", "fixed", "cylindrical", "prismatic", "planar"):
            zj = ax(mj, 2)
            rows += [dot(ax(mi, 0), zj), dot(ax(mi, 1), zj)]
        if k in ("cylindrical", "prismatic"):
            rows += [dot(ax(mi, 0), d), dot(ax(mi, 1), d)]
        if k in ("universal", "fixed", "prismatic"):
            rows.append(dot(ax(mi, 0), ax(mj, 1)))
        if k == "planar":
            rows.append(dot(ax(mi, 2), d))
        if k == "distance":
            dd = dot(d, d)
            rows.append(Kin(dd.v - self.length ** 2, dd.J, dd.vd, dd.h))
        if k == "point_on_line":
            rows += [dot(ax(mi, 0), d), dot(ax(mi, 1), d)]
        if k == "point_on_plane":
            rows.append(dot(ax(mi, 2), d))
        return Kin(np.concatenate([r.v for r in rows]), np.vstack([r.J for r in rows]),
                   np.concatenate([r.vd for r in rows]), np.concatenate([r.h for r in rows]))


@dataclass
class Driver:
    kind: str            # "rotation" | "translation"
    mi: Marker
    mj: Marker
    motion: object
    name: str = ""
    rows: slice = field(default=None)

    nrows = 1

    def __post_init__(self):
        if self.kind not in ("rotation", "translation"):
            raise InvalidJoint(f"unknown driver kind {self.kind!r}")

    def terms(self, t, n, q, qd):
        """``(Phi, Phi_q, Phi_t, gamma)`` of the driver row (arrays of one row)."""
        f, fd, fdd = self.motion(t)
        mi, mj = self.mi, self.mj
        if self.kind == "translation":
            d = mj.point(n, q, qd) - mi.point(n, q, qd)
            g = dot(mi.axis(2, n, q, qd), d)
            return g.v - f, g.J, np.array([-fd]), -g.h + fdd
        xi, yi, xj = mi.axis(0, n, q, qd), mi.axis(1, n, q, qd), mj.axis(0, n, q, qd)
        s, c = dot(yi, xj), dot(xi, xj)
        cf, sf = np.cos(f), np.sin(f)
        phi = cf * s.v - sf * c.v
        w = sf * s.v + cf * c.v                      # rho cos(theta - f)
        wd = sf * s.vd + cf * c.vd                   # w_q qd
        J = cf * s.J - sf * c.J
        phi_t = -fd * w
        quad = cf * s.h - sf * c.h                   # (Phi_q qd)_q qd
        phi_qt_qd = -fd * wd
        phi_tt = -fdd * w - fd * fd * phi
        gamma = -quad - 2.0 * phi_qt_qd - phi_tt
        return phi, J, phi_t, gamma

    def value(self, t, n, q):
        """The coordinate the driver holds: the angle (continuous near ``f``) or the distance."""
        zero = np.zeros(n)
        f = self.motion(t)[0]
        mi, mj = self.mi, self.mj
        if self.kind == "translation":
            d = mj.point(n, q, zero) - mi.point(n, q, zero)
            return float(dot(mi.axis(2, n, q, zero), d).v[0])
        xi, yi, xj = mi.axis(0, n, q, zero), mi.axis(1, n, q, zero), mj.axis(0, n, q, zero)
        s, c = dot(yi, xj).v[0], dot(xi, xj).v[0]
        return float(f + np.arctan2(s * np.cos(f) - c * np.sin(f), s * np.sin(f) + c * np.cos(f)))
