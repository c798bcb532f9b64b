"""Reference of the geometrically exact 3D beam element (docs/spatial-flexible.md), written
apart from the Rust one (``rust/body/beam3/element.rs``) along another route: rotation
matrices instead of quaternion algebra, the logarithm from the trace and the skew part of
``R_A^T R_B``, the midpoint rotation by Rodrigues' formula, and the gradient by the complex
step (every operation below is complex-analytic: no ``abs``, no conjugate), so that it is
exact to rounding.

Element coordinates ``x = [r_A (3), p_A (4), r_B (3), p_B (4)]``, ``R(p) = A(p) / (p . p)``:

* ``kappa = log(R_A^T R_B) / L`` (``theta = arccos((tr - 1) / 2)``,
  ``log = theta / sin(theta) * vee(R - R^T) / 2``);
* ``R_m = R_A exp(~kappa L / 2)``, ``Gamma = R_m^T (r_B - r_A) / L - e_1``;
* ``U = L / 2 (Gamma . C_N Gamma + kappa . C_M kappa)``;
* the nodes' points are ``r - R c'`` (``offsets``: a node body's centre of mass from its node,
  body axes; nonzero at the beam's two end nodes).

Valid away from ``theta = 0`` and ``theta = pi`` (the test states are bent).
"""
from __future__ import annotations

import numpy as np

__all__ = ["rotation", "strains", "energy", "gradient"]


def _skew(a):
    z = 0 * a[0]
    return np.array([[z, -a[2], a[1]], [a[2], z, -a[0]], [-a[1], a[0], z]])


def rotation(p):
    """``A(p) / (p . p)`` (complex-safe)."""
    e0, e = p[0], p[1:]
    A = (e0 * e0 - e @ e) * np.eye(3) + 2 * np.outer(e, e) + 2 * e0 * _skew(e)
    return A / (p @ p)


def _expm_so3(a):
    """Rodrigues: ``exp(~a)``."""
    t2 = a @ a
    t = np.sqrt(t2)
    K = _skew(a)
    return np.eye(3) + np.sin(t) / t * K + (1 - np.cos(t)) / t2 * (K @ K)


def strains(x, length, offsets=((0, 0, 0), (0, 0, 0))):
    """``(Gamma, kappa)`` of the element at ``x``."""
    x = np.asarray(x)
    RA, RB = rotation(x[3:7]), rotation(x[10:14])
    ra = x[0:3] - RA @ np.asarray(offsets[0], dtype=float)
    rb = x[7:10] - RB @ np.asarray(offsets[1], dtype=float)
    Rr = RA.T @ RB
    c = (np.trace(Rr) - 1) / 2
    th = np.arccos(c)
    w = np.array([Rr[2, 1] - Rr[1, 2], Rr[0, 2] - Rr[2, 0], Rr[1, 0] - Rr[0, 1]]) / 2
    phi = th / np.sin(th) * w
    Rm = RA @ _expm_so3(phi / 2)
    gamma = Rm.T @ (rb - ra) / length - np.array([1.0, 0.0, 0.0])
    return gamma, phi / length


def energy(x, length, c_n, c_m, offsets=((0, 0, 0), (0, 0, 0))):
    g, k = strains(x, length, offsets)
    return 0.5 * length * (g @ (np.asarray(c_n) * g) + k @ (np.asarray(c_m) * k))


def gradient(x, length, c_n, c_m, offsets=((0, 0, 0), (0, 0, 0)), h=1e-30):
    """``dU/dx`` by the complex step (exact to rounding)."""
    x = np.asarray(x, dtype=float)
    out = np.zeros(x.size)
    for j in range(x.size):
        xc = x.astype(complex)
        xc[j] += 1j * h
        out[j] = energy(xc, length, c_n, c_m, offsets).imag / h
    return out
