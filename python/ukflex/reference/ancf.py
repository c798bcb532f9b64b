"""Independent NumPy reference of the planar ANCF cable element (Euler-Bernoulli, gradient deficient).

Written from the equations, element by element, with its own matrix formulation (no code shared
with the Rust kind ``rust/body/ancf_cable.rs``, which works component-wise in the four numbers
``(r', r'')``; here the strain measures are quadratic forms of the element vector):

* element coordinates ``e = [r_1, r'_1, r_2, r'_2]`` (8 numbers: position and slope of both
  nodes, ``' = d/dx`` in the arc length ``x`` of the undeformed straight beam), cubic Hermite
  interpolation ``r(x) = S(x) e``, ``S = [S_1 I, S_2 I, S_3 I, S_4 I]`` (Berzeri and Shabana's
  interpolation, Exudyn's ``ObjectANCFCable2D``);
* axial strain ``eps = |r'| - 1`` and material curvature ``K = (r' x r'') / |r'|^2`` (Gerstmayr and
  Irschik's elastic line approach, Exudyn's definitions), strain energy
  ``U = int EA/2 eps^2 + EI/2 K^2 dx``; with ``G = S'^T S'`` and ``F = S'^T J S''``
  (``a x b = a^T J b``): ``|r'|^2 = e^T G e`` and ``r' x r'' = e^T F e``;
* strain-rate damping ``N = EA (eps + beta eps_dot)``, ``M = EI (K + beta K_dot)``;
* the axial term is integrated at the three Lobatto points of each element (0, l/2, l), the bending
  term at two Gauss points (``AXIAL_RULE``, ``BENDING_RULE``): the locking-free reduced rule of
  Exudyn's ``useReducedOrderIntegration = 2`` (see docs/scene-format.md); ``FULL_AXIAL_RULE``,
  ``FULL_BENDING_RULE`` are Exudyn's default (5 and 3 Gauss points), kept for the locking study;
* constant mass matrix ``rho A int S^T S dx`` and gravity ``rho A int S^T g dx`` (5-point Gauss).

Pure NumPy; it never imports ``ukflex._core``.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = [
    "AXIAL_RULE", "BENDING_RULE", "FULL_AXIAL_RULE", "FULL_BENDING_RULE",
    "hermite", "element_mass", "element_gravity", "element_strains", "element_elastic_force",
    "element_tangent_stiffness", "element_strain_energy", "cable_state",
]


def _gauss(n):
    z, w = np.polynomial.legendre.leggauss(n)
    return tuple(zip(0.5 * (z + 1.0), 0.5 * w))


#: (abscissa in [0, 1], weight) pairs of the axial-strain quadrature: Lobatto 3 (Simpson).
AXIAL_RULE = ((0.0, 1.0 / 6.0), (0.5, 2.0 / 3.0), (1.0, 1.0 / 6.0))
#: The bending quadrature: Gauss 2.
BENDING_RULE = _gauss(2)
#: Exudyn's default (``useReducedOrderIntegration = 0``): Gauss 5 axial, Gauss 3 bending.
FULL_AXIAL_RULE = _gauss(5)
FULL_BENDING_RULE = _gauss(3)

_J = np.array([[0.0, 1.0], [-1.0, 0.0]])  # a x b = a^T J b


def hermite(s, l, derivative=0):
    """Shape matrix (2, 8) of an element of length ``l`` at local abscissa ``s`` in [0, 1]:
    ``S`` (``derivative=0``), ``S' = dS/dx`` (1) or ``S''`` (2)."""
    if derivative == 0:
        n = [1 - 3 * s**2 + 2 * s**3, l * (s - 2 * s**2 + s**3), 3 * s**2 - 2 * s**3, l * (s**3 - s**2)]
    elif derivative == 1:
        n = [(6 * s**2 - 6 * s) / l, 1 - 4 * s + 3 * s**2, (6 * s - 6 * s**2) / l, 3 * s**2 - 2 * s]
    elif derivative == 2:
        n = [(12 * s - 6) / l**2, (6 * s - 4) / l, (6 - 12 * s) / l**2, (6 * s - 2) / l]
    else:
        raise ValueError("derivative must be 0, 1 or 2")
    return np.kron(np.asarray(n, dtype=float)[None, :], np.eye(2))


def element_mass(rho_a, l, ngauss=5):
    """Consistent mass matrix (8, 8) ``rho A int S^T S dx``."""
    return sum(w * l * rho_a * hermite(s, l).T @ hermite(s, l) for s, w in _gauss(ngauss))


def element_gravity(rho_a, l, g, ngauss=5):
    """Generalized gravity force (8,) ``rho A int S^T g dx``."""
    g = np.asarray(g, dtype=float)
    return sum(w * l * rho_a * hermite(s, l).T @ g for s, w in _gauss(ngauss))


def _axial(e, s, l):
    """eps, d eps / d e (8,), d^2 eps / d e^2 (8, 8) at ``s``."""
    Sx = hermite(s, l, 1)
    G = Sx.T @ Sx
    g = e @ G @ e
    nr = math.sqrt(g)
    de = G @ e / nr
    d2e = G / nr - np.outer(G @ e, G @ e) / nr**3
    return nr - 1.0, de, d2e


def _bending(e, s, l):
    """K, dK / d e (8,), d^2 K / d e^2 (8, 8) at ``s``."""
    Sx, Sxx = hermite(s, l, 1), hermite(s, l, 2)
    F = Sx.T @ _J @ Sxx
    Fs = F + F.T
    G2 = 2.0 * Sx.T @ Sx
    f, g = e @ F @ e, 0.5 * e @ G2 @ e
    df, dg = Fs @ e, G2 @ e
    K = f / g
    dK = df / g - f * dg / g**2
    d2K = (Fs / g - (np.outer(df, dg) + np.outer(dg, df)) / g**2 - f * G2 / g**2
           + 2.0 * f * np.outer(dg, dg) / g**3)
    return K, dK, d2K


def element_strains(e, l, axial=AXIAL_RULE, bending=BENDING_RULE):
    """(eps at the axial points, K at the bending points) of element vector ``e``."""
    e = np.asarray(e, dtype=float)
    return (np.array([_axial(e, s, l)[0] for s, _ in axial]), np.array([_bending(e, s, l)[0] for s, _ in bending]))


def element_strain_energy(e, l, EA, EI, axial=AXIAL_RULE, bending=BENDING_RULE):
    """``U_e = sum w l (EA/2 eps^2) + sum w l (EI/2 K^2)``."""
    e = np.asarray(e, dtype=float)
    u = sum(w * l * 0.5 * EA * _axial(e, s, l)[0] ** 2 for s, w in axial)
    return u + sum(w * l * 0.5 * EI * _bending(e, s, l)[0] ** 2 for s, w in bending)


def element_elastic_force(e, ed, l, EA, EI, beta=0.0, axial=AXIAL_RULE, bending=BENDING_RULE):
    """Generalized elastic and damping force (8,) ``-dU/de`` with ``N = EA (eps + beta eps_dot)``,
    ``M = EI (K + beta K_dot)``."""
    e, ed = np.asarray(e, dtype=float), np.asarray(ed, dtype=float)
    Q = np.zeros(8)
    for s, w in axial:
        eps, de, _ = _axial(e, s, l)
        Q -= w * l * EA * (eps + beta * (de @ ed)) * de
    for s, w in bending:
        K, dK, _ = _bending(e, s, l)
        Q -= w * l * EI * (K + beta * (dK @ ed)) * dK
    return Q


def element_tangent_stiffness(e, l, EA, EI, axial=AXIAL_RULE, bending=BENDING_RULE):
    """``K_t = d^2 U_e / d e^2`` (8, 8) (``-dQ/de`` of the undamped elastic force)."""
    e = np.asarray(e, dtype=float)
    H = np.zeros((8, 8))
    for s, w in axial:
        eps, de, d2e = _axial(e, s, l)
        H += w * l * EA * (np.outer(de, de) + eps * d2e)
    for s, w in bending:
        K, dK, d2K = _bending(e, s, l)
        H += w * l * EI * (np.outer(dK, dK) + K * d2K)
    return H


def cable_state(position, angle, velocity, angular_velocity, length, elements):
    """Coordinates and rates (4 (N + 1),) of the straight undeformed cable in rigid motion:
    node ``j`` at ``position + x_j t`` with slope ``t = (cos angle, sin angle)``, velocity
    ``velocity + omega x_j n`` and slope rate ``omega n``, ``n = (-sin angle, cos angle)``."""
    t = np.array([math.cos(angle), math.sin(angle)])
    n = np.array([-t[1], t[0]])
    p, v, w = np.asarray(position, float), np.asarray(velocity, float), float(angular_velocity)
    q, qd = [], []
    for j in range(elements + 1):
        x = length * j / elements
        q += [*(p + x * t), *t]
        qd += [*(v + w * x * n), *(w * n)]
    return np.array(q), np.array(qd)
