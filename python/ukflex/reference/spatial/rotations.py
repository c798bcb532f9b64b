"""Euler parameters (unit quaternions) and the matrices built on them.

Conventions (Haug, *Computer Aided Kinematics and Dynamics of Mechanical Systems*, ch. 9;
Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, ch. 6):

* ``p = [e0, e1, e2, e3]``, scalar first, ``e = [e1, e2, e3]``;
* ``A(p) = (e0^2 - e.e) I + 2 e e^T + 2 e0 ~e`` maps body components to world components
  (``~a`` is the cross-product matrix, ``~a b = a x b``);
* ``G(p) = [-e, -~e + e0 I]``, ``E(p) = [-e, ~e + e0 I]`` (3 x 4), ``A = E G^T``;
* angular velocity in body components ``w' = 2 G pd``, in world components ``w = 2 E pd``;
  for ``p^T p = 1``: ``G G^T = I``, ``G p = 0``, so ``pd = 1/2 G^T w'`` when ``p^T pd = 0``;
* ``B(p, a') = d(A(p) a')/dp = 2 [(e0 I + ~e) a', e a'^T - (e0 I + ~e) ~a']`` (3 x 4);
  ``A(p) a'`` is a quadratic form in ``p``, so ``B(p, a') p = 2 A(p) a'`` and
  ``d^2/dt^2 (A a') = B(p, a') pdd + B(pd, a') pd``.

Nothing here normalizes silently: every function takes ``p`` as it is (the equations of
motion carry ``p^T p = 1`` as a constraint row), except the constructors from rotation
matrices and axis-angle pairs, which return unit quaternions.
"""
from __future__ import annotations

import numpy as np

__all__ = ["skew", "rot_A", "rot_G", "rot_E", "rot_B", "p_from_matrix", "p_from_axis_angle",
           "matrix_from_axis_angle", "pd_from_omega_world", "pd_from_omega_body",
           "omega_world", "omega_body", "rotation_angle_about"]


def skew(a):
    """Cross-product matrix: ``skew(a) @ b == np.cross(a, b)``."""
    a = np.asarray(a, dtype=float)
    return np.array([[0.0, -a[2], a[1]],
                     [a[2], 0.0, -a[0]],
                     [-a[1], a[0], 0.0]])


def rot_A(p):
    """Rotation matrix ``A(p)`` (3, 3); ``|p|^2`` times a rotation if ``p`` is not unit."""
    e0, e = p[0], np.asarray(p[1:4], dtype=float)
    return (e0 * e0 - e @ e) * np.eye(3) + 2.0 * np.outer(e, e) + 2.0 * e0 * skew(e)


def rot_G(p):
    """``G(p) = [-e, -~e + e0 I]`` (3, 4): ``w' = 2 G(p) pd``."""
    e0, e = p[0], np.asarray(p[1:4], dtype=float)
    return np.column_stack([-e, -skew(e) + e0 * np.eye(3)])


def rot_E(p):
    """``E(p) = [-e, ~e + e0 I]`` (3, 4): ``w = 2 E(p) pd``."""
    e0, e = p[0], np.asarray(p[1:4], dtype=float)
    return np.column_stack([-e, skew(e) + e0 * np.eye(3)])


def rot_B(p, a):
    """``B(p, a) = d(A(p) a)/dp`` (3, 4) for a body-fixed vector ``a`` (3,)."""
    e0, e = p[0], np.asarray(p[1:4], dtype=float)
    a = np.asarray(a, dtype=float)
    S = e0 * np.eye(3) + skew(e)
    return 2.0 * np.column_stack([S @ a, np.outer(e, a) - S @ skew(a)])


def p_from_matrix(R):
    """Unit Euler parameters of a rotation matrix (Shepperd's method; ``e0 >= 0``)."""
    R = np.asarray(R, dtype=float)
    tr = np.trace(R)
    cand = np.array([tr, R[0, 0], R[1, 1], R[2, 2]])
    k = int(np.argmax(cand))
    p = np.empty(4)
    if k == 0:
        p[0] = 0.5 * np.sqrt(1.0 + tr)
        f = 0.25 / p[0]
        p[1] = (R[2, 1] - R[1, 2]) * f
        p[2] = (R[0, 2] - R[2, 0]) * f
        p[3] = (R[1, 0] - R[0, 1]) * f
    else:
        i = k - 1
        j, m = (i + 1) % 3, (i + 2) % 3
        ei = 0.5 * np.sqrt(1.0 + 2.0 * R[i, i] - tr)
        f = 0.25 / ei
        p[1 + i] = ei
        p[0] = (R[m, j] - R[j, m]) * f
        p[1 + j] = (R[j, i] + R[i, j]) * f
        p[1 + m] = (R[m, i] + R[i, m]) * f
    if p[0] < 0.0:
        p = -p
    return p / np.linalg.norm(p)


def p_from_axis_angle(axis, angle):
    """Unit Euler parameters of a rotation by ``angle`` about ``axis`` (normalized here)."""
    u = np.asarray(axis, dtype=float)
    u = u / np.linalg.norm(u)
    return np.concatenate([[np.cos(0.5 * angle)], np.sin(0.5 * angle) * u])


def matrix_from_axis_angle(axis, angle):
    return rot_A(p_from_axis_angle(axis, angle))


def omega_world(p, pd):
    return 2.0 * rot_E(p) @ pd


def omega_body(p, pd):
    return 2.0 * rot_G(p) @ pd


def pd_from_omega_body(p, w_body):
    """``pd = 1/2 G^T w'`` (exact inverse of ``w' = 2 G pd`` on ``p^T pd = 0`` for unit p)."""
    return 0.5 * rot_G(p).T @ np.asarray(w_body, dtype=float)


def pd_from_omega_world(p, w_world):
    return 0.5 * rot_E(p).T @ np.asarray(w_world, dtype=float)


def rotation_angle_about(R_rel, axis):
    """Angle of a relative rotation ``R_rel`` about ``axis`` (in (-pi, pi]), for reporting."""
    u = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    # any vector perpendicular to the axis
    t = np.array([1.0, 0.0, 0.0]) if abs(u[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = t - (t @ u) * u
    x /= np.linalg.norm(x)
    y = np.cross(u, x)
    xr = R_rel @ x
    return float(np.arctan2(xr @ y, xr @ x))
