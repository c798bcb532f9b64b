"""The paper's closed-form single-element slider-crank terms (eqs. 44-69, Appendix A).

Pennestri, Valentini, de Falco (2010), section 5, in the paper's own coordinates
``q1..q9`` (stored 0-based here as ``q[0]..q[8]``):

* ``q1, q2`` centre of the crank, ``q3`` crank angle (the crank reference is at its centre);
* ``q4, q5`` origin of the coupler's floating frame (node 1), ``q6`` its angle;
* ``q7 = psi_1``, ``q8 = u_2``, ``q9 = psi_2`` (pinned-pinned reference conditions).

The text we have is an OCR of the paper with the formulas damaged; this module implements
our reading of what is printed, term by term, with named switches for every place where the
printed term and the equations of sections 2-4 disagree (see ``docs/errata.md``):

``fixes`` (set of names, or ``"all"``):

* ``"eq62_a12_sign"`` -- eq. (62), first row of the centrifugal part prints
  ``... - a11 q7 sin q6 + a12 q9 (sin q6)``; the second row (``+ a11 q7 cos q6 + a12 q9 (cos
  q6)``) and eq. (40) give ``-(a11 q7 + a12 q9) sin q6``.
* ``"eq62_coriolis_sign"`` -- eq. (62) prints ``- mb q6' {2 q7' a11 cos q6 + q8' sin q6 + ...}``;
  eq. (40) gives ``+ mb q6' {...}`` (``Q_vR = -2 theta' A_theta S_bar qf'``).
* ``"eq63_64_denominator"`` -- eqs. (63)-(64) print ``840 (1 + phi^2)`` and ``30 (1 + phi^2)``
  where Appendix A and eq. (54) have ``(1 + phi)^2``.
* ``"eq63_b12_rotary_sign"`` -- eq. (63), ``b12`` prints ``rho I Lb (5 phi^2 - 5 phi + 1)``,
  Appendix A ``m(3,6)`` and eq. (54) have ``(5 phi^2 - 5 phi - 1)``.
* ``"eq69_row1_sign"`` -- eq. (69) prints the same sign for the ``psi_1`` and ``psi_2``
  gravity forces; ``Q_f = S_bar^T A^T m g`` gives opposite signs (``-`` for ``psi_1``).

``rotary`` (how the cross-section rotary inertia ``rho I`` enters):

* ``"printed"`` -- as printed: ``M_ff`` of Appendix A (with ``rho I N_psi^T N_psi``), the
  ``(m_thth)_ff`` of eq. (54) = ``q_f^T M_ff q_f`` (with ``rho I`` terms), ``b11, b12`` of eq. (63)
  with ``rho I`` terms, ``c11, c31`` of eq. (64) without: this mixes the kinetic energy of
  eq. (19) (``psi_dot^2`` only) with a ``1/2 theta_dot^2 int rho I psi^2`` term.
* ``"psi_dot"`` -- eq. (19) applied consistently: ``1/2 int rho I psi_dot^2`` only.
* ``"full"`` -- the ukflex model (scene-format.md): ``1/2 int rho I (theta_dot + psi_dot)^2``:
  adds ``rho I Lb`` to ``m_thth`` and ``rho I int N_psi`` to ``m_thf``; no velocity terms.

The driver ``q3 = omega t`` is not part of the printed eq. (44) (five joint rows); it is added
here as the sixth row (and ``gamma_6 = 0``) as in the general model.

Eq. (55) (the ``m_thf`` block) did not survive the OCR; only its auxiliary definitions
``s = 6 alpha / Lb^2``, ``z1 = -Lb (2 + s)``, ``z2 = Lb (1 + s)``, ``z2' = Lb (s - 1)``,
``z3..z5 = 3..5 (1 + 2 s)`` did. It is reconstructed from eq. (31) with these definitions:
``int_0^1 xi N3 dxi = Lb/z5 + z1/z4 + z2/z3`` and ``int xi N6 = Lb/z5 + z2'/z4 - s Lb/z3``.
Likewise the numerical coefficient of eqs. (68)-(69) and the ``c31`` velocity part of
eq. (64) are unreadable and are taken as the integrals of the printed shape functions.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["PaperSliderCrank", "ALL_FIXES"]

ALL_FIXES = ("eq62_a12_sign", "eq62_coriolis_sign", "eq63_64_denominator",
             "eq63_b12_rotary_sign", "eq69_row1_sign")


class PaperSliderCrank:
    """Closed-form terms of the paper's flexible slider-crank in the paper's coordinates.

    Parameters
    ----------
    beam : "timoshenko" | "euler-bernoulli"
    gravity : include the gravity forces (66)-(69)
    fixes : iterable of names from :data:`ALL_FIXES`, or "all"
    rotary : "printed" | "psi_dot" | "full" (see module docstring)
    rotary_inertia : include ``rho I`` at all (default: True for Timoshenko, False for E-B,
        as in scene-format.md)
    """

    n = 9
    m = 6

    def __init__(self, beam="timoshenko", gravity=True, fixes=(), rotary="printed",
                 rotary_inertia=None, L=0.1524, Lb=0.3048, d=0.00635, rho=7834.56,
                 E=2.06843e11, nu=0.285, k=0.8, omega=124.8, g=9.81):
        if fixes == "all":
            fixes = ALL_FIXES
        unknown = set(fixes) - set(ALL_FIXES)
        if unknown:
            raise ValueError(f"unknown fixes {unknown}")
        if rotary not in ("printed", "psi_dot", "full"):
            raise ValueError(rotary)
        self.fixes = frozenset(fixes)
        self.rotary = rotary
        self.beam = beam
        self.L, self.Lb, self.rho, self.E, self.omega = L, Lb, rho, E, omega
        self.g = g if gravity else 0.0
        self.a = math.pi * d * d / 4
        self.I = math.pi * d**4 / 64
        G = E / (2 * (1 + nu))
        if beam == "timoshenko":
            self.alpha = E * self.I / (k * G * self.a)       # nomenclature: alpha = EI/(kGa)
        elif beam == "euler-bernoulli":
            self.alpha = 0.0
        else:
            raise ValueError(beam)
        if rotary_inertia is None:
            rotary_inertia = beam == "timoshenko"
        self.Ir = self.I if rotary_inertia else 0.0          # I in the rho*I terms
        self.fphi = 12 * self.alpha / Lb**2                   # eq. (5) with l = Lb
        self.s = 6 * self.alpha / Lb**2
        self.mc = rho * self.a * L
        self.Ic = self.mc * L**2 / 12
        self.mb = rho * self.a * Lb

    # ------------------------------------------------------------------ helpers
    def _has(self, name):
        return name in self.fixes

    def app_a(self):
        """Appendix A entries m(3,3), m(3,6), m(4,4), m(6,6) for l = Lb (with rho I)."""
        r, a, I, l, f = self.rho, self.a, self.Ir, self.Lb, self.fphi
        d = (1 + f) ** 2
        m33 = r * a * l**3 * (7 * f**2 + 14 * f + 8) / (840 * d) + r * I * (10 * f**2 + 5 * f + 4) * l / (30 * d)
        m36 = -r * a * l**3 * (7 * f**2 + 14 * f + 6) / (840 * d) + r * I * (5 * f**2 - 5 * f - 1) * l / (30 * d)
        m44 = r * a * l / 3
        return m33, m36, m44, m33

    def _zint(self):
        """int_0^1 xi N3 dxi, int_0^1 xi N6 dxi from the z definitions of eq. (55)."""
        Lb, s = self.Lb, self.s
        z1, z2, z2p = -Lb * (2 + s), Lb * (1 + s), Lb * (s - 1)
        z3, z4, z5 = 3 * (1 + 2 * s), 4 * (1 + 2 * s), 5 * (1 + 2 * s)
        return Lb / z5 + z1 / z4 + z2 / z3, Lb / z5 + z2p / z4 - s * Lb / z3

    def _a11_a12(self):
        """eq. (62): a11 = Lb/(1+phi) (1/4 - (2+s)/3 + (1+s)/2), a12 = Lb/(1+phi) (1/4 - (1-s)/3 - s/2)."""
        Lb, s, f = self.Lb, self.s, self.fphi
        a11 = Lb / (1 + f) * (0.25 - (2 + s) / 3 + (1 + s) / 2)
        a12 = Lb / (1 + f) * (0.25 - (1 - s) / 3 - s / 2)
        return a11, a12

    def _rot_psi_integrals(self):
        """rho I int_0^Lb N_psi dx for (psi1, u2, psi2), from eq. (7)."""
        f = self.fphi
        # int_0^1 (3 xi^2 - (4+f) xi + (1+f))/(1+f) = (1 - (4+f)/2 + 1 + f)/(1+f) = (f/2)/(1+f)
        # int_0^1 (3 xi^2 - (2-f) xi)/(1+f)       = (1 - (2-f)/2)/(1+f)     = (f/2)/(1+f)
        c = self.rho * self.Ir * self.Lb * (f / 2) / (1 + f)
        return np.array([c, 0.0, c])

    # ------------------------------------------------------------------ eq. (44), (45)
    def phi_(self, t, q):
        L, Lb = self.L, self.Lb
        q1, q2, q3, q4, q5, q6, q7, q8, q9 = q
        return np.array([
            q1 - L / 2 * math.cos(q3),
            q2 - L / 2 * math.sin(q3),
            q1 + L / 2 * math.cos(q3) - q4,
            q2 + L / 2 * math.sin(q3) - q5,
            q5 + (Lb + q8) * math.sin(q6),
            q3 - self.omega * t,                      # driver (not printed in eq. 44)
        ])

    def phi(self, t, q):
        return self.phi_(t, np.asarray(q, float))

    def A(self, q):
        """Jacobian of eq. (44) (not printed in the paper; differentiated here)."""
        L, Lb = self.L, self.Lb
        q3, q6, q8 = q[2], q[5], q[7]
        A = np.zeros((6, 9))
        A[0, 0], A[0, 2] = 1, L / 2 * math.sin(q3)
        A[1, 1], A[1, 2] = 1, -L / 2 * math.cos(q3)
        A[2, 0], A[2, 2], A[2, 3] = 1, -L / 2 * math.sin(q3), -1
        A[3, 1], A[3, 2], A[3, 4] = 1, L / 2 * math.cos(q3), -1
        A[4, 4], A[4, 5], A[4, 7] = 1, (Lb + q8) * math.cos(q6), math.sin(q6)
        A[5, 2] = 1
        return A

    def phi_t(self, t):
        return np.array([0, 0, 0, 0, 0, -self.omega], dtype=float)

    def gamma(self, t, q, qd):
        """eq. (45), read as gamma = -{...} (the leading minus of the printed vector)."""
        L, Lb = self.L, self.Lb
        q3, q6, q8 = q[2], q[5], q[7]
        d3, d6, d8 = qd[2], qd[5], qd[7]
        return -np.array([
            L / 2 * d3**2 * math.cos(q3),
            L / 2 * d3**2 * math.sin(q3),
            -L / 2 * d3**2 * math.cos(q3),
            -L / 2 * d3**2 * math.sin(q3),
            -(Lb + q8) * d6**2 * math.sin(q6) + 2 * d6 * d8 * math.cos(q6),
            0.0,                                      # driver: constant speed
        ])

    # ------------------------------------------------------------------ eqs. (46)-(56)
    def M(self, q):
        q = np.asarray(q, float)
        mb, Lb = self.mb, self.Lb
        q6, q7, q8, q9 = q[5], q[6], q[7], q[8]
        c, s = math.cos(q6), math.sin(q6)
        M = np.zeros((9, 9))
        M[0, 0] = M[1, 1] = self.mc                   # (47)
        M[2, 2] = self.Ic
        M[3, 3] = M[4, 4] = mb                         # (49)
        mRth = mb * np.array([Lb * (q9 - q7) / 12 * c - (Lb + q8) / 2 * s,      # (50)
                              (Lb + q8) / 2 * c + Lb * (q9 - q7) / 12 * s])
        M[3:5, 5] = M[5, 3:5] = mRth
        mRf = mb * np.array([[-Lb * s / 12, c / 2, Lb * s / 12],                 # (51)
                             [Lb * c / 12, s / 2, -Lb * c / 12]])
        M[3:5, 6:9] = mRf
        M[6:9, 3:5] = mRf.T
        # (52)-(54)
        f = self.fphi
        rr = mb * Lb**2 / 3
        rf = 2 * mb * Lb / 3 * q8
        Ib = self.Ir if self.rotary == "printed" else 0.0
        ff = Lb * self.rho / (840 * (1 + f) ** 2) * (
            self.a * Lb**2 * (q7**2 + q9**2) * (8 + 14 * f + 7 * f**2)
            - self.a * Lb**2 * (12 + 28 * f + 14 * f**2) * q7 * q9
            + 280 * self.a * (1 + f) ** 2 * q8**2
            + Ib * (q7**2 + q9**2) * (112 + 140 * f + 280 * f**2)
            - Ib * (56 + 280 * f - 280 * f**2) * q7 * q9)
        M[5, 5] = rr + rf + ff
        # (55), reconstructed (see module docstring)
        k3, k6 = self._zint()
        mthf = mb * np.array([(Lb + q8) * k3, -(k3 * q7 + k6 * q9), (Lb + q8) * k6])
        if self.rotary == "full":
            M[5, 5] += self.rho * self.Ir * Lb
            mthf = mthf + self._rot_psi_integrals()
        M[5, 6:9] = M[6:9, 5] = mthf
        # (56) from Appendix A
        m33, m36, m44, m66 = self.app_a()
        M[6:9, 6:9] = [[m33, 0, m36], [0, m44, 0], [m36, 0, m66]]
        return M

    # ------------------------------------------------------------------ eqs. (57)-(69)
    def K_b(self):
        """eq. (59)."""
        E, I, a, Lb, f = self.E, self.I, self.a, self.Lb, self.fphi
        return E / (1 + f) * np.array([[(4 + f) * I / Lb, 0, (2 - f) * I / Lb],
                                       [0, a * (1 + f) / Lb, 0],
                                       [(2 - f) * I / Lb, 0, (4 + f) * I / Lb]])

    def Q(self, t, q, qd):
        q = np.asarray(q, float)
        qd = np.asarray(qd, float)
        mb, Lb, f, g = self.mb, self.Lb, self.fphi, self.g
        q6, q7, q8, q9 = q[5], q[6], q[7], q[8]
        d6, d7, d8, d9 = qd[5], qd[6], qd[7], qd[8]
        c, s = math.cos(q6), math.sin(q6)
        a11, a12 = self._a11_a12()
        Q = np.zeros(9)
        # (66), (67)
        Q[1] -= self.mc * g
        Q[4] -= mb * g
        # (62)
        sgn12 = -1.0 if self._has("eq62_a12_sign") else 1.0
        QvR = mb * d6**2 * np.array([(q8 + Lb) / 2 * c - a11 * q7 * s + sgn12 * a12 * q9 * s,
                                     (q8 + Lb) / 2 * s + a11 * q7 * c + a12 * q9 * c])
        sgnc = 1.0 if self._has("eq62_coriolis_sign") else -1.0
        QvR += sgnc * mb * d6 * np.array([2 * d7 * a11 * c + d8 * s + 2 * d9 * a12 * c,
                                          2 * d7 * a11 * s - d8 * c + 2 * d9 * a12 * s])
        Q[3:5] += QvR
        # (63)
        den = (1 + f) ** 2 if self._has("eq63_64_denominator") else (1 + f**2)
        Ib = self.Ir if self.rotary == "printed" else 0.0
        c12r = -1.0 if self._has("eq63_b12_rotary_sign") else 1.0
        b11 = mb * Lb**2 * (7 * f**2 + 14 * f + 8) / (840 * den) + Ib * Lb * self.rho * (10 * f**2 + 5 * f + 4) / (30 * den)
        b12 = -mb * Lb**2 * (7 * f**2 + 14 * f + 6) / (840 * den) + Ib * Lb * self.rho * (5 * f**2 - 5 * f + c12r) / (30 * den)
        Q[5] += -2 * d6 * ((b11 * q7 + b12 * q9) * d7 + (b12 * q7 + b11 * q9) * d9
                           + mb / 3 * (q8 + Lb) * d8)
        # (64)
        c11 = mb * d6**2 * Lb**2 / (840 * den) * ((8 + 14 * f + 7 * f**2) * q7 - (6 + 14 * f + 7 * f**2) * q9)
        c31 = mb * d6**2 * Lb**2 / (840 * den) * ((8 + 14 * f + 7 * f**2) * q9 - (6 + 14 * f + 7 * f**2) * q7)
        c21 = mb * d6**2 / 3 * (q8 + Lb)
        sh = self.s / 2                                      # 3 alpha / Lb^2
        k12 = 2 * mb * d6 / (1 + f) * (Lb / 2 * (1 + sh) - Lb / 5 - Lb / 3 * (1 + self.s))
        k32 = 2 * mb * d6 / (1 + f) * (Lb / 4 * (1 - self.s) - Lb / 5 + 2 * self.alpha / Lb)
        c12, c32 = k12 * d8, k32 * d8
        c22 = -(k12 * d7 + k32 * d9)                        # = -(c12 q7' + c32 q9')/q8'
        Q[6:9] += [c11 + c12, c21 + c22, c31 + c32]
        # (68), (69): coefficient mb g Lb (...)/(1 + 12 alpha/Lb^2) read as mb g int N3 = mb g a11
        X = mb * g * a11
        Q[5] += -0.5 * mb * g * (Lb + q8) * c + X * s * (q7 - q9)
        sg1 = -1.0 if self._has("eq69_row1_sign") else 1.0
        Q[6:9] += [sg1 * X * c, -0.5 * mb * g * s, X * c]
        # (58)
        Q[6:9] -= self.K_b() @ q[6:9]
        return Q

    def terms(self, t, q, qd):
        return self.M(q), self.Q(t, q, qd), self.A(q), self.gamma(t, q, qd)

    # ------------------------------------------------------------------ coordinates
    def from_general(self, qg, qdg=None):
        """Map the general model's coordinates (crank frame at the ground pivot, com at
        (L/2, 0)) to the paper's q (crank centre). Returns (q, qd, J, Jdot_qd)."""
        qg = np.asarray(qg, float)
        L = self.L
        th = qg[2]
        q = qg.copy()
        q[0] = qg[0] + L / 2 * math.cos(th)
        q[1] = qg[1] + L / 2 * math.sin(th)
        J = np.eye(9)
        J[0, 2] = -L / 2 * math.sin(th)
        J[1, 2] = L / 2 * math.cos(th)
        if qdg is None:
            return q, None, J, None
        qdg = np.asarray(qdg, float)
        qd = J @ qdg
        jd = np.zeros(9)
        jd[0] = -L / 2 * math.cos(th) * qdg[2] ** 2
        jd[1] = -L / 2 * math.sin(th) * qdg[2] ** 2
        return q, qd, J, jd

    def general_terms(self, t, qg, qdg):
        """The closed-form terms transformed to the general coordinates:
        ``M_g = J^T M J``, ``Q_g = J^T (Q - M Jdot qd_g)``, ``A_g = A J``,
        ``b_g = b - A Jdot qd_g``, ``Phi_g = Phi``."""
        q, qd, J, jd = self.from_general(qg, qdg)
        M, Q, A, b = self.terms(t, q, qd)
        return J.T @ M @ J, J.T @ (Q - M @ jd), A @ J, b - A @ jd

    @staticmethod
    def midpoint_deflection(q):
        """v(Lb/2)/Lb = (q7 - q9)/8 (N3(1/2) = Lb/8, N6(1/2) = -Lb/8 for every phi)."""
        q = np.asarray(q)
        return (q[6] - q[8]) / 8

    def initial_guess(self):
        """Aligned, undeformed, crank at omega (consistent)."""
        L, Lb, w = self.L, self.Lb, self.omega
        q = np.array([L / 2, 0, 0, L, 0, 0, 0, 0, 0], float)
        qd = np.array([0, L / 2 * w, w, 0, L * w, -L * w / Lb, 0, 0, 0], float)
        return q, qd
