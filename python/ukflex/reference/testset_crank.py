"""Simeon's flexible slider crank as the Test Set for IVP Solvers states it (problem ``crank``).

An independent NumPy transcription of the Test Set's equations of motion (its Fortran
subroutine ``RESMBS``, minimal coordinates ``p = (phi1, phi2, x3)``, ``q = (q1..q4)``), its
initial values and its published reference solution at ``t = 0.1``.  It shares no code with
ukflex: the study ``studies.simeon_crank`` builds the same mechanism through the public
API (a rigid crank, a general flexible body for the rod, a slider) and compares the two.

Model (Simeon, Math. Modelling of Systems 2, 1996; Test Set release 2.4, ``crank.f``): crank of
length ``L1`` driven at ``phi1 = OMEGA t``; elastic connecting rod of length ``L2`` on a frame at
the crank pin, two lateral modes ``sin(pi x / L2)``, ``sin(2 pi x / L2)`` and a quadratic axial
ansatz with nodes at ``L2 / 2`` and ``L2``; slider mass ``M3`` at the rod's end on the x axis.
The Test Set's constants are used as written (``PI = 3.1415927``; its axial mass entries
``FACM * (8, 1, 2)``).  ``ipar_nonlinear = True`` adds its nonlinear stiffness term,
``ipar_damping = True`` its damping matrix.
"""

from __future__ import annotations

from typing import Tuple

import numpy as np

__all__ = ["CONSTANTS", "Y0", "REFERENCE", "fe_matrices", "rhs", "integrate", "mixed_scd"]

M1, M2, M3 = 0.36, 0.151104, 0.075552
L1, L2 = 0.15, 0.30
J1, J2 = 0.002727, 0.0045339259
PI = 3.1415927
EE, NUE, BB, HH, RHO = 0.20e12, 0.30, 0.0080, 0.0080, 7870.0
GRAV, OMEGA = 0.0, 150.0

CONSTANTS = dict(M1=M1, M2=M2, M3=M3, L1=L1, L2=L2, J1=J1, J2=J2, PI=PI, EE=EE, NUE=NUE, BB=BB, HH=HH, RHO=RHO,
                 GRAV=GRAV, OMEGA=OMEGA)

#: The Test Set's consistent initial values (``crank.f``, subroutine init): positions
#: ``(phi1, phi2, x3, q1..q4)``, velocities, accelerations, Lagrange multipliers.
Y0 = np.array([
    0.0, 0.0, 4.500169330000000e-01, 0.0, 0.0, 1.033398630000000e-05, 1.693279690000000e-05,
    1.500000000000000e+02, -7.499576703969453e+01, -2.689386719979040e-06, 4.448961125815990e-01,
    4.634339319238670e-03, -1.785910760000550e-06, -2.689386719979040e-06,
    0.0, -1.344541576709835e-03, -5.062194924490193e+03, -6.829725665986310e-05, 1.813207639590617e-20,
    -4.268463266810281e+00, 2.098339029337557e-01,
    -6.552727150584648e-08, 3.824589509350831e+02, -4.635908708561371e-09,
])

#: The Test Set's reference solution at ``t = 0.1`` (``crank.f``, subroutine solut), same order.
REFERENCE = np.array([
    0.1500000000000104e+02, -0.3311734988256260e+00, 0.1697373328427860e+00, 0.1893192899613509e-03,
    0.2375751249879174e-04, -0.5323896770569702e-05, -0.8363313279112129e-05, 0.1500000000000000e+03,
    0.6025346755138369e+02, -0.8753116326670527e+01, -0.3005541400289738e-01, -0.5500431812571696e-02,
    0.4974111734266989e-03, 0.1105560003626645e-02, 0.0, 0.6488737541276957e+04,
    0.2167938629509884e+04, 0.3391137060286523e+02, 0.1715134772216488e+00, -0.1422449408912512e+01,
    0.1003946428124810e+01, -0.6232935833287916e+02, -0.1637920993367306e+03, 0.2529857947066878e+02,
])

#: Names of the 14 position and velocity components.
NAMES = ["phi1", "phi2", "x3", "q1", "q2", "q3", "q4", "phi1_t", "phi2_t", "x3_t", "q1_t", "q2_t", "q3_t", "q4_t"]


def fe_matrices(damping: bool = False):
    """``MQ, KQ, BQ, DQ, c1, c2, c12, c21`` of ``RESMBS`` (first call block)."""
    facm, fack, facb = RHO * BB * HH * L2, EE * BB * HH / L2, BB * HH * L2
    mq, kq, bq, dq = (np.zeros((4, 4)) for _ in range(4))
    mq[0, 0] = mq[1, 1] = facm * 0.5
    mq[2, 2], mq[2, 3], mq[3, 2], mq[3, 3] = facm * 8.0, facm, facm, facm * 2.0
    kq[0, 0] = fack * PI**4 / 24.0 * (HH / L2) ** 2
    kq[1, 1] = fack * PI**4 * 2.0 / 3.0 * (HH / L2) ** 2
    kq[2, 2], kq[2, 3], kq[3, 2], kq[3, 3] = fack * 16.0 / 3.0, -fack * 8.0 / 3.0, -fack * 8.0 / 3.0, fack * 7.0 / 3.0
    bq[0, 2] = -facb * 16.0 / PI**3
    bq[0, 3] = facb * (8.0 / PI**3 - 1.0 / PI)
    bq[1, 3] = facb * 0.5 / PI
    bq[2, 0] = facb * 16.0 / PI**3
    bq[3, 0] = -facb * (8.0 / PI**3 - 1.0 / PI)
    bq[3, 1] = -facb * 0.5 / PI
    c1 = np.array([0.0, 0.0, facb * 2.0 / 3.0, facb / 6.0])
    c2 = np.array([facb * 2.0 / PI, 0.0, 0.0, 0.0])
    c12 = np.array([0.0, 0.0, L2 * facb / 3.0, L2 * facb / 6.0])
    c21 = np.array([L2 * facb / PI, -L2 * facb * 0.5 / PI, 0.0, 0.0])
    if damping:
        dq[0, 0], dq[1, 1] = 5.0, 25.0
        dq[2, 2] = 0.5 * 2.308375455264791e02
        dq[2, 3] = -0.5 * 2.62688487992052e02
        dq[3, 2] = -0.5 * 2.626884879920526e02
        dq[3, 3] = 0.5 * 4.217421837156818e02
    return mq, kq, bq, dq, c1, c2, c12, c21


def nonlinear_force(q: np.ndarray) -> np.ndarray:
    """The term ``RESMBS`` subtracts from ``F(4..7)`` with ``IPAR(1) = 1``."""
    fack = 0.5 * EE * BB * HH / L2**2 * PI**2
    facb = 80.0 / (PI**2 * 9.0)
    return fack * np.array([
        q[0] * q[3] - facb * q[1] * (-4 * q[2] + 2 * q[3]),
        4 * q[1] * q[3] - facb * q[0] * (-4 * q[2] + 2 * q[3]),
        4.0 * facb * q[0] * q[1],
        0.5 * q[0] ** 2 + 2 * q[1] ** 2 - 2 * facb * q[0] * q[1],
    ])


def accelerations(t: float, p: np.ndarray, v: np.ndarray, nonlinear: bool = False, damping: bool = False,
                  _fe=None) -> Tuple[np.ndarray, np.ndarray]:
    """``(w, lambda)`` from ``AM w + GP^T lambda = F``, ``GP w = -(d GP/dt) v`` (the index-1
    form of ``RESMBS``, ``ITYP = 3``)."""
    mq, kq, bq, dq, c1, c2, c12, c21 = _fe if _fe is not None else fe_matrices(damping)
    q, qd = p[3:], v[3:]
    c1q, c2q, c12q = c1 @ q, c2 @ q, c12 @ q
    c1qd, c2qd, c12qd = c1 @ qd, c2 @ qd, c12 @ qd
    mqq, kqq, dqqd = mq @ q, kq @ q, dq @ qd
    qtbq = q @ bq
    bqqd = bq @ qd
    cp1, sp1, cp2, sp2 = np.cos(p[0]), np.sin(p[0]), np.cos(p[1]), np.sin(p[1])
    cp12, sp12 = np.cos(p[0] - p[1]), np.sin(p[0] - p[1])
    v1, v2 = v[0], v[1]
    am = np.zeros((7, 7))
    am[0, 0] = J1 + M2 * L1 * L1
    am[0, 1] = 0.5 * L1 * L2 * M2 * cp12 + RHO * L1 * (sp12 * c2q + cp12 * c1q)
    am[1, 1] = J2 + q @ mqq + 2.0 * RHO * c12q
    am[2, 2] = M3
    am[0, 3:] = RHO * L1 * (-sp12 * c1 + cp12 * c2)
    am[1, 3:] = RHO * c21 + RHO * qtbq
    am[3:, 3:] = mq
    am = np.triu(am) + np.triu(am, 1).T
    qku = q[3]
    gp = np.zeros((3, 7))
    gp[0, 0], gp[0, 1] = L1 * cp1, (L2 + qku) * cp2
    gp[1, 0], gp[1, 1], gp[1, 2] = L1 * sp1, (L2 + qku) * sp2, 1.0
    gp[2, 0] = 1.0
    gp[0, 6], gp[1, 6] = sp2, -cp2
    f = np.zeros(7)
    f[0] = -0.5 * L1 * GRAV * (M1 + 2 * M2) * cp1 - 0.5 * L1 * L2 * M2 * v2 * v2 * sp12
    f[1] = -0.5 * L2 * GRAV * M2 * cp2 + 0.5 * L1 * L2 * M2 * v1 * v1 * sp12
    f[0] += RHO * L1 * v2 * v2 * (-sp12 * c1q + cp12 * c2q) - 2.0 * RHO * L1 * v2 * (cp12 * c1qd + sp12 * c2qd)
    f[1] += (RHO * L1 * v1 * v1 * (sp12 * c1q - cp12 * c2q) - 2.0 * RHO * v2 * c12qd - 2.0 * v2 * (qd @ mqq)
             - RHO * (qd @ bqqd) - RHO * GRAV * (cp2 * c1q - sp2 * c2q))
    f[3:] = (v2 * v2 * mqq + RHO * (v2 * v2 * c12 + L1 * v1 * v1 * (cp12 * c1 + sp12 * c2) + 2.0 * v2 * bqqd)
             - RHO * GRAV * (sp2 * c1 + cp2 * c2) - kqq - dqqd)
    if nonlinear:
        f[3:] -= nonlinear_force(q)
    # acceleration-level constraints: GP w + alc0 = 0 (ALC of RESMBS without the GP w part)
    qdku = qd[3]
    alc0 = np.array([
        -L1 * sp1 * v1 * v1 - (L2 + qku) * sp2 * v2 * v2 + 2.0 * v2 * cp2 * qdku,
        L1 * cp1 * v1 * v1 + (L2 + qku) * cp2 * v2 * v2 + 2.0 * v2 * sp2 * qdku,
        0.0,
    ])
    kkt = np.zeros((10, 10))
    kkt[:7, :7] = am
    kkt[:7, 7:] = gp.T
    kkt[7:, :7] = gp
    sol = np.linalg.solve(kkt, np.concatenate([f, -alc0]))
    return sol[:7], sol[7:]


def rhs(t: float, y: np.ndarray, nonlinear: bool = False, damping: bool = False, _fe=None) -> np.ndarray:
    """First-order right-hand side on ``y = (p, v)`` (14 components)."""
    w, _ = accelerations(t, y[:7], y[7:], nonlinear, damping, _fe)
    return np.concatenate([y[7:], w])


def integrate(t_end: float = 0.1, nonlinear: bool = False, damping: bool = False, rtol: float = 1e-13,
              atol: float = 1e-15) -> np.ndarray:
    """The 14 positions and velocities at ``t_end`` from the Test Set's initial values, by
    DOP853 on the index-1 form (an independent check of the published reference)."""
    from scipy.integrate import solve_ivp

    fe = fe_matrices(damping)
    sol = solve_ivp(lambda t, y: rhs(t, y, nonlinear, damping, fe), (0.0, t_end), Y0[:14].copy(), method="DOP853",
                    rtol=rtol, atol=atol)
    if not sol.success:
        raise RuntimeError(sol.message)
    return sol.y[:, -1]


def mixed_scd(y: np.ndarray, ref: np.ndarray, atol_over_rtol: float = 1.0) -> np.ndarray:
    """The Test Set's mixed-error significant correct digits per component,
    ``-log10(|y - ref| / (atol/rtol + |ref|))`` (its drivers run with ``atol = rtol``); ``inf``
    where the error is exactly zero."""
    err = np.abs(np.asarray(y, dtype=float) - np.asarray(ref, dtype=float)) / (atol_over_rtol + np.abs(ref))
    with np.errstate(divide="ignore"):
        return -np.log10(err)
