"""Independent NumPy model of a planar flexible multibody system (FFRF beams + rigid bodies).

This module reads the scene description dict (``docs/scene-format.md``) on its own and
evaluates the terms of ``M(q) qdd + A(q)^T lambda = Q(t, q, qd)``, ``Phi(t, q) = 0``,
``A = Phi_q``, ``b = gamma = -(A qd)_q qd - 2 Phi_qt qd - Phi_tt``.

It is written from the equations, deliberately along a different code path than the Rust
core (which precomputes body-level inertia shape integrals):

* beams are integrated **element by element, at every call**, by Gauss quadrature of the
  kinetic energy density: with ``r(x) = R + A(theta) (u0(x) + S(x) q_f)`` and
  ``r_dot = L(x) qd_body``, ``L = [I, A_theta u, A S]``, the mass matrix is
  ``M = sum_g w_g rho a L_g^T L_g`` (+ the rotary inertia ``rho I J_psi^T J_psi`` with
  ``J_psi = [0, 0, 1, N_psi]``, i.e. ``1/2 rho I (theta_dot + psi_dot)^2``);
* the quadratic velocity vector is obtained point-wise from d'Alembert:
  ``Q_v = -sum_g w_g rho a L_g^T a_v(x_g)`` with the velocity-dependent part of the
  acceleration ``a_v = -A u theta_dot^2 + 2 theta_dot A_theta S q_f_dot`` (no block formulas);
* ``K_ff`` is assembled element by element from the strain energy (paper eq. 8) by quadrature
  of the derivatives of the shape functions (6)-(7).

ANCF cables (bodies of kind ``"cable"``) come from :mod:`.ancf` (element by element at
every call; constant mass matrix, no velocity terms); their marker angles follow the tangent, so
the angle rows of the constraints carry its velocity term ``h_phi``.

Pure NumPy; it never imports ``ukflex._core``.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np

from . import ancf as _ancf

__all__ = [
    "ReferenceModel",
    "element_shape",
    "element_shape_derivatives",
    "element_matrices",
    "section_properties",
    "ModelError",
]

#: Gauss points per element. The kinetic-energy integrand is a polynomial of degree <= 6 in
#: the element abscissa (cubic shape functions squared), the strain energy of degree <= 4, so
#: 4 points (exact to degree 7) are enough; 5 gives margin.
GAUSS_POINTS_PER_ELEMENT = 5


class ModelError(ValueError):
    """Invalid or unsupported scene description."""


# ----------------------------------------------------------------------------------------
# Element shape functions (paper eqs. (4)-(7), Davis-Heshell-Warburton Timoshenko element)
# ----------------------------------------------------------------------------------------

def element_shape(s, l, phi):
    """Shape functions of one element at local abscissa ``s = (x - x_k)/l`` in [0, 1].

    Parameters
    ----------
    s : float or array (ns,)
    l : element length
    phi : ``12 E I / (k G a l^2)`` (0 for Euler-Bernoulli)

    Returns
    -------
    Nv : (ns, 2, 6) -- rows (u, v) of eq. (6) acting on ``[u_j, v_j, psi_j, u_j+1, v_j+1, psi_j+1]``
    Npsi : (ns, 6) -- eq. (7)
    """
    s = np.atleast_1d(np.asarray(s, dtype=float))
    d = 1.0 + phi
    ns = s.size
    Nv = np.zeros((ns, 2, 6))
    Nv[:, 0, 0] = 1.0 - s
    Nv[:, 0, 3] = s
    Nv[:, 1, 1] = (2 * s**3 - 3 * s**2 - phi * s + d) / d
    Nv[:, 1, 2] = l / d * (s**3 - (2 + phi / 2) * s**2 + (1 + phi / 2) * s)
    Nv[:, 1, 4] = (-2 * s**3 + 3 * s**2 + phi * s) / d
    Nv[:, 1, 5] = l / d * (s**3 - (1 - phi / 2) * s**2 - phi / 2 * s)
    Np = np.zeros((ns, 6))
    Np[:, 1] = 6.0 / (d * l) * (s**2 - s)
    Np[:, 2] = (3 * s**2 - (4 + phi) * s + d) / d
    Np[:, 4] = -6.0 / (d * l) * (s**2 - s)
    Np[:, 5] = (3 * s**2 - (2 - phi) * s) / d
    return Nv, Np


def element_shape_derivatives(s, l, phi):
    """x-derivatives of the shape functions: ``(du/dx, dv/dx, dpsi/dx)`` rows, each (ns, 6)."""
    s = np.atleast_1d(np.asarray(s, dtype=float))
    d = 1.0 + phi
    ns = s.size
    du = np.zeros((ns, 6))
    du[:, 0] = -1.0 / l
    du[:, 3] = 1.0 / l
    dv = np.zeros((ns, 6))
    dv[:, 1] = (6 * s**2 - 6 * s - phi) / (d * l)
    dv[:, 2] = (3 * s**2 - (4 + phi) * s + 1 + phi / 2) / d
    dv[:, 4] = (-6 * s**2 + 6 * s + phi) / (d * l)
    dv[:, 5] = (3 * s**2 - (2 - phi) * s - phi / 2) / d
    dp = np.zeros((ns, 6))
    dp[:, 1] = 6.0 * (2 * s - 1) / (d * l * l)
    dp[:, 2] = (6 * s - 4 - phi) / (d * l)
    dp[:, 4] = -6.0 * (2 * s - 1) / (d * l * l)
    dp[:, 5] = (6 * s - 2 + phi) / (d * l)
    return du, dv, dp


def _gauss01(n):
    z, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (z + 1.0), 0.5 * w


def element_matrices(l, rho, a, I, E, G, k, phi, rotary=True, ngauss=GAUSS_POINTS_PER_ELEMENT):
    """Element mass and stiffness matrices (6x6) by Gauss quadrature of eqs. (8)-(9).

    The mass matrix is ``int rho a N_v^T N_v + rho I N_psi^T N_psi dx`` (the paper's eq. (9));
    the stiffness matrix is eq. (8). For Euler-Bernoulli (``phi = 0``) pass ``k G a`` anything:
    the shear strain ``psi - v'`` vanishes identically and the term is skipped.
    """
    s, w = _gauss01(ngauss)
    Nv, Np = element_shape(s, l, phi)
    du, dv, dp = element_shape_derivatives(s, l, phi)
    wl = w * l
    m = rho * a * np.einsum("g,gia,gib->ab", wl, Nv, Nv)
    if rotary:
        m += rho * I * np.einsum("g,ga,gb->ab", wl, Np, Np)
    K = E * I * np.einsum("g,ga,gb->ab", wl, dp, dp) + E * a * np.einsum("g,ga,gb->ab", wl, du, du)
    if phi != 0.0:
        g = Np - dv
        K += k * G * a * np.einsum("g,ga,gb->ab", wl, g, g)
    return m, K


def section_properties(section):
    """Return (area, second moment of area) of a section dict."""
    shape = section.get("shape")
    if shape == "circular":
        d = float(section["diameter"])
        return math.pi * d * d / 4.0, math.pi * d**4 / 64.0
    if shape == "rectangular":
        b, h = float(section["width"]), float(section["height"])
        return b * h, b * h**3 / 12.0
    if shape == "custom":
        return float(section["area"]), float(section["second_moment"])
    raise ModelError(f"unknown section shape {shape!r}")


def _rot(theta):
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s], [s, c]]), np.array([[-s, -c], [c, -s]])


# ----------------------------------------------------------------------------------------
# Bodies
# ----------------------------------------------------------------------------------------

@dataclass
class _Rigid:
    name: str
    offset: int
    mass: float
    inertia: float
    com: np.ndarray
    q0: np.ndarray
    qd0: np.ndarray
    kind: str = "rigid"
    n: int = 3
    n_f: int = 0


@dataclass
class _Beam:
    name: str
    offset: int
    length: float
    elements: int
    theory: str
    rho: float
    E: float
    G: float
    kshear: float
    area: float
    I: float
    frame: str
    rotary: bool
    damping: float
    q0: np.ndarray
    qd0: np.ndarray
    strain: str = "nonlinear"
    kind: str = "beam"
    # derived
    l: float = 0.0
    phi: float = 0.0
    n_f: int = 0
    n: int = 0
    keep: np.ndarray = field(default=None)        # indices of e kept in q_f
    B: np.ndarray = field(default=None)           # (3(N+1), n_f) e = B q_f
    K_ff: np.ndarray = field(default=None)
    M_ff: np.ndarray = field(default=None)        # eq. (9) element assembly (diagnostic)
    # quadrature data, (G,) (G,2,n_f) (G,n_f)
    xg: np.ndarray = field(default=None)
    mw: np.ndarray = field(default=None)          # rho a * weight * l
    rw: np.ndarray = field(default=None)          # rho I * weight * l
    Sg: np.ndarray = field(default=None)
    Pg: np.ndarray = field(default=None)
    # second-order axial strain: per element, u' (N, n_f) and v' at the Gauss points (N, G, n_f)
    dug: np.ndarray = field(default=None)
    dvg: np.ndarray = field(default=None)
    wg: np.ndarray = field(default=None)

    def setup(self):
        N = self.elements
        self.l = self.length / N
        if self.theory == "timoshenko":
            self.phi = 12.0 * self.E * self.I / (self.kshear * self.G * self.area * self.l**2)
        elif self.theory == "euler-bernoulli":
            self.phi = 0.0
        else:
            raise ModelError(f"beam {self.name!r}: unknown theory {self.theory!r}")
        ne = 3 * (N + 1)
        if self.frame == "pinned-pinned":
            removed = {0, 1, 3 * N + 1}
        elif self.frame == "clamped":
            removed = {0, 1, 2}
        else:
            raise ModelError(f"beam {self.name!r}: unknown frame {self.frame!r}")
        self.keep = np.array([i for i in range(ne) if i not in removed], dtype=int)
        self.n_f = len(self.keep)
        self.n = 3 + self.n_f
        self.B = np.zeros((ne, self.n_f))
        self.B[self.keep, np.arange(self.n_f)] = 1.0
        # element-by-element assembly of K_ff and M_ff (nodal), then reduction
        Ke = np.zeros((ne, ne))
        Me = np.zeros((ne, ne))
        me, ke = element_matrices(self.l, self.rho, self.area, self.I, self.E, self.G,
                                  self.kshear, self.phi, rotary=self.rotary)
        for k in range(N):
            sl = slice(3 * k, 3 * k + 6)
            Ke[sl, sl] += ke
            Me[sl, sl] += me
        self.K_ff = self.B.T @ Ke @ self.B
        self.M_ff = self.B.T @ Me @ self.B
        # quadrature points of the whole body, element by element
        s, w = _gauss01(GAUSS_POINTS_PER_ELEMENT)
        Nv, Np = element_shape(s, self.l, self.phi)
        xs, mws, rws, Ss, Ps = [], [], [], [], []
        for k in range(N):
            P = self.B[3 * k:3 * k + 6, :]            # element dofs from q_f
            xs.append(self.l * (k + s))
            mws.append(self.rho * self.area * self.l * w)
            rws.append(self.rho * self.I * self.l * w)
            Ss.append(Nv @ P)
            Ps.append(Np @ P)
        self.xg = np.concatenate(xs)
        self.mw = np.concatenate(mws)
        self.rw = np.concatenate(rws) if self.rotary else np.zeros_like(self.mw)
        self.Sg = np.concatenate(Ss)
        self.Pg = np.concatenate(Ps)
        if self.strain not in ("linear", "nonlinear"):
            raise ModelError(f"beam {self.name!r}: unknown strain {self.strain!r}")
        du, dv, _ = element_shape_derivatives(s, self.l, self.phi)
        self.wg = w
        self.dug = np.array([du[0] @ self.B[3 * k:3 * k + 6, :] for k in range(N)])
        self.dvg = np.array([dv @ self.B[3 * k:3 * k + 6, :] for k in range(N)])

    def axial(self, qf):
        """Element axial strains averaged over each element, ``eps = u' + 1/2 mean(v'^2)``
        (``u'`` alone for linear strain), and their gradients on ``q_f``: (eps (N,), eps_lin (N,),
        grad (N, n_f))."""
        eps_lin = self.dug @ qf
        if self.strain == "linear":
            return eps_lin, eps_lin, self.dug
        vp = self.dvg @ qf                                   # (N, G)
        eps = eps_lin + 0.5 * (vp * vp) @ self.wg
        grad = self.dug + np.einsum("g,kg,kgf->kf", self.wg, vp, self.dvg)
        return eps, eps_lin, grad

    def axial_force(self, qf):
        """Axial force of each element ``E a eps`` (N,)."""
        return self.E * self.area * self.axial(qf)[0]

    def nonlinear_elastic(self, qf):
        """What the second-order axial strain adds to the linear elastic model: (strain energy,
        generalized force on ``q_f``), from ``U = E a l eps^2 / 2`` per element less the linear
        ``E a l eps_lin^2 / 2`` already in ``K_ff``."""
        eps, eps_lin, grad = self.axial(qf)
        eal = self.E * self.area * self.l
        energy = 0.5 * eal * float(np.sum(eps * eps - eps_lin * eps_lin))
        force = -eal * (eps @ grad - eps_lin @ self.dug)
        return energy, force

    def nonlinear_damping(self, qf, qfd):
        """What strain-rate damping adds with the second-order strain: ``-beta E a l`` times
        ``(grad . qfd) grad - (u' . qfd) u'`` per element (the linear part is ``-beta K_ff qfd``)."""
        if self.strain == "linear" or not self.damping:
            return np.zeros_like(qf)
        _, _, grad = self.axial(qf)
        eal = self.E * self.area * self.l
        return -self.damping * eal * ((grad @ qfd) @ grad - (self.dug @ qfd) @ self.dug)

    def shape(self, xi):
        """S (2, n_f) and N_psi (n_f,) at ``x = xi * length``."""
        if not (-1e-12 <= xi <= 1 + 1e-12):
            raise ModelError(f"beam {self.name!r}: xi={xi} outside [0, 1]")
        x = min(max(xi, 0.0), 1.0) * self.length
        k = min(int(x / self.l), self.elements - 1)
        s = x / self.l - k
        Nv, Np = element_shape(s, self.l, self.phi)
        P = self.B[3 * k:3 * k + 6, :]
        return Nv[0] @ P, Np[0] @ P


@dataclass
class _Cable:
    """Planar ANCF cable: node ``j`` carries ``[x_j, y_j, x'_j, y'_j]`` (see :mod:`.ancf`)."""
    name: str
    offset: int
    length: float
    elements: int
    rho_a: float
    EA: float
    EI: float
    damping: float
    angle0: float
    q0: np.ndarray
    qd0: np.ndarray
    kind: str = "ancf"
    n_f: int = 0
    n: int = 0
    l: float = 0.0
    M_body: np.ndarray = field(default=None)

    def setup(self):
        N = self.elements
        self.l = self.length / N
        self.n = 4 * (N + 1)
        me = _ancf.element_mass(self.rho_a, self.l)
        self.M_body = np.zeros((self.n, self.n))
        for k in range(N):
            self.M_body[4 * k:4 * k + 8, 4 * k:4 * k + 8] += me

    def element(self, xi):
        """(element k, local s) of the axis point ``x = xi * length``."""
        if not (0.0 <= xi <= 1.0):
            raise ModelError(f"beam {self.name!r}: xi={xi} outside [0, 1]")
        k = min(int(xi * self.elements), self.elements - 1)
        return k, xi * self.elements - k

    def gravity_force(self, g):
        """Constant generalized gravity force (n,)."""
        Q = np.zeros(self.n)
        fe = _ancf.element_gravity(self.rho_a, self.l, g)
        for k in range(self.elements):
            Q[4 * k:4 * k + 8] += fe
        return Q


# ----------------------------------------------------------------------------------------
def _wrap(x: float) -> float:
    """An angle row's residual at the nearest turn, ``[-pi, pi)``: a relative angle is the same
    modulo 2 pi (a body may turn any number of times; a direction's angle passes +-pi)."""
    return x - 2.0 * math.pi * math.floor((x + math.pi) / (2.0 * math.pi))


# Markers, motions
# ----------------------------------------------------------------------------------------

@dataclass
class _Marker:
    body: object            # None for ground, else _Rigid or _Beam
    point: np.ndarray       # rigid/ground: point in body frame; beam: (x, 0) undeformed
    angle: float
    S: np.ndarray = None    # beam: (2, n_f)
    Npsi: np.ndarray = None  # beam: (n_f,)

    def kin(self, q, qd, n):
        """World position r, Jacobian J (2, n), angle phi, J_phi (n,), r_dot, phi_dot and the
        velocity-dependent part of the acceleration a_v (so that r_ddot = J qdd + a_v)."""
        J = np.zeros((2, n))
        Jp = np.zeros(n)
        b = self.body
        if b is None:
            return (self.point.copy(), J, self.angle, Jp, np.zeros(2), 0.0, np.zeros(2))
        o = b.offset
        R = q[o:o + 2]
        th = q[o + 2]
        thd = qd[o + 2]
        Arot, Ath = _rot(th)
        u = self.point.copy()
        phi = th + self.angle
        J[0, o] = 1.0
        J[1, o + 1] = 1.0
        Jp[o + 2] = 1.0
        av = -(Arot @ u) * thd * thd
        if b.kind == "beam":
            qf = q[o + 3:o + b.n]
            qfd = qd[o + 3:o + b.n]
            u = u + self.S @ qf
            AS = Arot @ self.S
            J[:, o + 3:o + b.n] = AS
            Jp[o + 3:o + b.n] = self.Npsi
            phi = phi + self.Npsi @ qf
            av = -(Arot @ u) * thd * thd + 2.0 * thd * (Ath @ (self.S @ qfd))
        J[:, o + 2] = Ath @ u
        r = R + Arot @ u
        return r, J, phi, Jp, J @ qd, Jp @ qd, av


class _CableMarker:
    """A marker on an ANCF cable: ``r = S e`` (``a_v = 0``), angle ``angle + angle0 +
    atan2(t0 x r', t0 . r')`` measured from the cable's initial direction ``t0``."""

    def __init__(self, body, xi, angle):
        self.body, self.angle = body, float(angle)
        k, s = body.element(float(xi))
        self.cols = slice(body.offset + 4 * k, body.offset + 4 * k + 8)
        self.S, self.Sx = _ancf.hermite(s, body.l), _ancf.hermite(s, body.l, 1)
        self.t0 = np.array([math.cos(body.angle0), math.sin(body.angle0)])

    def _slope(self, q, qd):
        t, td = self.Sx @ q[self.cols], self.Sx @ qd[self.cols]
        return t, td, t @ t

    def kin(self, q, qd, n):
        """Same tuple as :meth:`_Marker.kin`."""
        J = np.zeros((2, n))
        J[:, self.cols] = self.S
        t, td, g = self._slope(q, qd)
        phi = self.angle + self.body.angle0 + math.atan2(self.t0[0] * t[1] - self.t0[1] * t[0], self.t0 @ t)
        Jp = np.zeros(n)
        Jp[self.cols] = (t[0] * self.Sx[1] - t[1] * self.Sx[0]) / g
        return J[:, self.cols] @ q[self.cols], J, phi, Jp, J @ qd, Jp @ qd, np.zeros(2)

    def phi_velocity_term(self, q, qd):
        """``h_phi`` with ``phi_dd = J_phi qdd + h_phi``: ``d/dt (t x t_dot / |t|^2)`` without ``t_dd``."""
        t, td, g = self._slope(q, qd)
        return -2.0 * (t @ td) * (t[0] * td[1] - t[1] * td[0]) / g**2


def _phi_velocity_term(marker, q, qd):
    """Velocity term of a marker's angular acceleration (non-zero only on cables)."""
    return marker.phi_velocity_term(q, qd) if isinstance(marker, _CableMarker) else 0.0


class _Motion:
    def __init__(self, d):
        kind = d.get("kind")
        self.kind = kind
        if kind == "constant_speed":
            self.c = [float(d.get("initial", 0.0)), float(d["speed"])]
            self.kind = "polynomial"
        elif kind == "polynomial":
            self.c = [float(c) for c in d["coefficients"]] or [0.0]
        elif kind == "harmonic":
            self.off = float(d.get("offset", 0.0))
            self.amp = float(d["amplitude"])
            self.w = float(d["frequency"])
            self.ph = float(d.get("phase", 0.0))
        else:
            raise ModelError(f"unknown motion kind {kind!r}")

        if self.kind == "polynomial":      # coefficients of f, f', f'' (ascending powers)
            c0 = list(self.c)
            c1 = [k * c0[k] for k in range(1, len(c0))] or [0.0]
            c2 = [k * c1[k] for k in range(1, len(c1))] or [0.0]
            self.cs = (c0, c1, c2)

    def __call__(self, t, der=0):
        if self.kind == "polynomial":
            v = 0.0
            for ck in reversed(self.cs[der]):       # Horner
                v = v * t + ck
            return v
        arg = self.w * t + self.ph
        if der == 0:
            return self.off + self.amp * math.sin(arg)
        if der == 1:
            return self.amp * self.w * math.cos(arg)
        return -self.amp * self.w**2 * math.sin(arg)


def _vec2(v, default=(0.0, 0.0)):
    if v is None:
        v = default
    v = np.asarray(v, dtype=float).reshape(-1)
    if v.shape != (2,):
        raise ModelError(f"expected a 2-vector, got {v!r}")
    return v


# ----------------------------------------------------------------------------------------
# The model
# ----------------------------------------------------------------------------------------

class ReferenceModel:
    """NumPy evaluation of the model terms of a scene description.

    Attributes
    ----------
    n : number of generalized coordinates
    m : number of constraint rows (joints in order, then drivers)
    coordinate_slices : dict body name -> slice of q
    """

    def __init__(self, description):
        if isinstance(description, str):
            description = json.loads(description)
        self.description = description
        g = description.get("gravity")
        self.gravity = None if g is None else _vec2(g)
        self.bodies = []
        self._by_name = {}
        off = 0
        for bd in description.get("bodies", []):
            name = bd["name"]
            if name == "ground" or name in self._by_name:
                raise ModelError(f"body name {name!r} reserved or duplicated")
            kind = bd.get("kind")
            if kind == "rigid":
                b = _Rigid(name=name, offset=off, mass=float(bd["mass"]),
                           inertia=float(bd["inertia"]), com=_vec2(bd.get("com")),
                           q0=np.r_[_vec2(bd.get("position")), float(bd.get("angle", 0.0))],
                           qd0=np.r_[_vec2(bd.get("velocity")),
                                     float(bd.get("angular_velocity", 0.0))])
            elif kind == "cable":
                a, I = section_properties(bd["section"])
                E, rho = float(bd["youngs_modulus"]), float(bd["density"])
                b = _Cable(name=name, offset=off, length=float(bd["length"]), elements=int(bd.get("elements", 1)),
                           rho_a=rho * a, EA=E * a, EI=E * I, damping=float(bd.get("damping", 0.0) or 0.0),
                           angle0=float(bd.get("angle", 0.0)), q0=None, qd0=None)
                b.setup()
                b.q0, b.qd0 = _ancf.cable_state(_vec2(bd.get("position")), b.angle0, _vec2(bd.get("velocity")),
                                                float(bd.get("angular_velocity", 0.0)), b.length, b.elements)
            elif kind == "beam":
                theory = bd.get("theory", "timoshenko")
                a, I = section_properties(bd["section"])
                E = float(bd["youngs_modulus"])
                if bd.get("shear_modulus") is not None:
                    G = float(bd["shear_modulus"])
                elif bd.get("poisson_ratio") is not None:
                    G = E / (2.0 * (1.0 + float(bd["poisson_ratio"])))
                elif theory == "euler-bernoulli":
                    G = float("nan")                     # not used: no shear strain
                else:
                    raise ModelError(f"beam {name!r}: poisson_ratio or shear_modulus required")
                ks = bd.get("shear_factor")
                if theory == "timoshenko" and ks is None:
                    raise ModelError(f"beam {name!r}: shear_factor required for Timoshenko")
                rot = bd.get("rotary_inertia")
                if rot is None:
                    rot = theory == "timoshenko"
                b = _Beam(name=name, offset=off, length=float(bd["length"]),
                          elements=int(bd.get("elements", 1)), theory=theory,
                          rho=float(bd["density"]), E=E, G=G,
                          kshear=float(ks) if ks is not None else 1.0,
                          area=a, I=I, frame=bd.get("frame", "pinned-pinned"), rotary=bool(rot),
                          damping=float(bd.get("damping", 0.0) or 0.0),
                          strain=bd.get("strain", "nonlinear"),
                          q0=np.r_[_vec2(bd.get("position")), float(bd.get("angle", 0.0))],
                          qd0=np.r_[_vec2(bd.get("velocity")),
                                    float(bd.get("angular_velocity", 0.0))])
                b.setup()
                el = bd.get("elastic")
                er = bd.get("elastic_rates")
                b.q0 = np.r_[b.q0, np.zeros(b.n_f) if el is None else np.asarray(el, float)]
                b.qd0 = np.r_[b.qd0, np.zeros(b.n_f) if er is None else np.asarray(er, float)]
                if b.q0.size != b.n or b.qd0.size != b.n:
                    raise ModelError(f"beam {name!r}: elastic state must have length {b.n_f}")
            else:
                raise ModelError(f"body {name!r}: unknown kind {kind!r}")
            self.bodies.append(b)
            self._by_name[name] = b
            off += b.n
        if not self.bodies:
            raise ModelError("a scene needs at least one body")
        self.n = off
        self.coordinate_slices = {b.name: slice(b.offset, b.offset + b.n) for b in self.bodies}
        self._q0 = np.concatenate([b.q0 for b in self.bodies])
        self._qd0 = np.concatenate([b.qd0 for b in self.bodies])
        self._build_constraints(description)
        self._build_forces(description)

    # ---------------------------------------------------------------- description parsing
    def _marker(self, d):
        if d is None:
            return _Marker(None, np.zeros(2), 0.0)
        bname = d.get("body", "ground")
        angle = float(d.get("angle", 0.0))
        if bname == "ground":
            return _Marker(None, _vec2(d.get("point")), angle)
        if bname not in self._by_name:
            raise ModelError(f"marker on unknown body {bname!r}")
        b = self._by_name[bname]
        if b.kind == "rigid":
            return _Marker(b, _vec2(d.get("point")), angle)
        if b.kind == "ancf":
            if "xi" not in d:
                raise ModelError(f"marker on beam {bname!r} needs 'xi'")
            return _CableMarker(b, d["xi"], angle)
        if "xi" not in d:
            raise ModelError(f"marker on beam {bname!r} needs 'xi'")
        xi = float(d["xi"])
        S, Np = b.shape(xi)
        return _Marker(b, np.array([xi * b.length, 0.0]), angle, S, Np)

    def _build_constraints(self, desc):
        self.joints = []
        q0, qd0 = self._q0, self._qd0
        for j in desc.get("joints", []) or []:
            kind = j.get("kind")
            if kind in ("revolute", "prismatic", "weld"):
                ma, mb = self._marker(j["a"]), self._marker(j["b"])
                phi0 = 0.0
                if kind in ("prismatic", "weld"):
                    phi0 = ma.kin(q0, qd0, self.n)[2] - mb.kin(q0, qd0, self.n)[2]
                self.joints.append((kind, ma, mb, phi0))
            elif kind == "point_on_line":
                self.joints.append((kind, self._marker(j["point"]), self._marker(j["line"]), 0.0))
            else:
                raise ModelError(f"unknown joint kind {kind!r}")
        self.drivers = []
        for d in desc.get("drivers", []) or []:
            kind = d.get("kind")
            mot = _Motion(d["motion"])
            if kind == "angle":
                self.drivers.append((kind, self._marker(d["a"]), self._marker(d.get("b")), mot))
            elif kind == "coordinate":
                axis = {"x": 0, "y": 1}[d["axis"]]
                self.drivers.append((kind, self._marker(d["point"]), axis, mot))
            else:
                raise ModelError(f"unknown driver kind {kind!r}")
        rows = {"revolute": 2, "point_on_line": 1, "prismatic": 2, "weld": 3}
        self.m = sum(rows[j[0]] for j in self.joints) + len(self.drivers)

    def _build_forces(self, desc):
        self.forces = []
        for f in desc.get("forces", []) or []:
            kind = f.get("kind")
            if kind == "point_force":
                self.forces.append((kind, self._marker(f["point"]), _vec2(f["force"])))
            elif kind == "torque":
                self.forces.append((kind, self._marker(f["frame"]), float(f["torque"])))
            elif kind == "spring_damper":
                self.forces.append((kind, self._marker(f["a"]), self._marker(f["b"]),
                                    float(f.get("stiffness", 0.0)), float(f.get("damping", 0.0)),
                                    float(f.get("rest_length", 0.0))))
            else:
                raise ModelError(f"unknown force kind {kind!r}")

    # ---------------------------------------------------------------- public helpers
    def initial_guess(self):
        """(q0, qd0) read from the description's state fields (no correction)."""
        return self._q0.copy(), self._qd0.copy()

    def body(self, name):
        return self._by_name[name]

    def beam_shape(self, body_name, xi):
        """(S (2, n_f), N_psi (n_f,)) of beam ``body_name`` at ``x = xi * length``."""
        b = self._by_name[body_name]
        if b.kind != "beam":
            raise ModelError(f"{body_name!r} is not a beam")
        return b.shape(float(xi))

    def marker_state(self, marker_dict, q, qd=None):
        """World position, angle, velocity of a marker dict at (q, qd) (diagnostics)."""
        qd = np.zeros(self.n) if qd is None else np.asarray(qd, float)
        r, J, phi, Jp, rd, phid, av = self._marker(marker_dict).kin(np.asarray(q, float), qd,
                                                                     self.n)
        return r, phi, rd, phid

    def _body_L(self, b, q):
        """Beam: u (G,2), L (G,2,nb) velocity map at the quadrature points, A, A_theta."""
        o = b.offset
        th = q[o + 2]
        qf = q[o + 3:o + b.n]
        Arot, Ath = _rot(th)
        u = np.stack([b.xg, np.zeros_like(b.xg)], axis=1) + b.Sg @ qf
        G = b.xg.size
        L = np.zeros((G, 2, b.n))
        L[:, 0, 0] = 1.0
        L[:, 1, 1] = 1.0
        L[:, :, 2] = u @ Ath.T
        L[:, :, 3:] = np.einsum("ij,gjk->gik", Arot, b.Sg)
        return u, L, Arot, Ath

    # ---------------------------------------------------------------- mass matrix
    def M(self, q):
        """Mass matrix M(q), (n, n)."""
        q = np.asarray(q, dtype=float)
        M = np.zeros((self.n, self.n))
        for b in self.bodies:
            o = b.offset
            sl = slice(o, o + b.n)
            if b.kind == "rigid":
                Arot, Ath = _rot(q[o + 2])
                ac = Ath @ b.com
                Mb = np.zeros((3, 3))
                Mb[0, 0] = Mb[1, 1] = b.mass
                Mb[0:2, 2] = Mb[2, 0:2] = b.mass * ac
                Mb[2, 2] = b.inertia + b.mass * (b.com @ b.com)
                M[sl, sl] = Mb
            elif b.kind == "ancf":
                M[sl, sl] = b.M_body
            else:
                u, L, Arot, Ath = self._body_L(b, q)
                Mb = np.einsum("g,gia,gib->ab", b.mw, L, L)
                if b.rotary:
                    Jpsi = np.zeros((b.xg.size, b.n))
                    Jpsi[:, 2] = 1.0
                    Jpsi[:, 3:] = b.Pg
                    Mb += np.einsum("g,ga,gb->ab", b.rw, Jpsi, Jpsi)
                M[sl, sl] = Mb
        return M

    # ---------------------------------------------------------------- forces
    def Q(self, t, q, qd):
        """Generalized forces: quadratic velocity + gravity + elastic + damping + applied."""
        q = np.asarray(q, dtype=float)
        qd = np.asarray(qd, dtype=float)
        Q = np.zeros(self.n)
        g = self.gravity
        for b in self.bodies:
            o = b.offset
            sl = slice(o, o + b.n)
            thd = qd[o + 2]
            if b.kind == "rigid":
                Arot, Ath = _rot(q[o + 2])
                Lc = np.zeros((2, 3))
                Lc[:, :2] = np.eye(2)
                Lc[:, 2] = Ath @ b.com
                av = -(Arot @ b.com) * thd * thd          # velocity part of com acceleration
                Qb = -b.mass * (Lc.T @ av)
                if g is not None:
                    Qb += b.mass * (Lc.T @ g)
                Q[sl] += Qb
            elif b.kind == "ancf":
                if g is not None:
                    Q[sl] += b.gravity_force(g)
                for k in range(b.elements):
                    c = slice(o + 4 * k, o + 4 * k + 8)
                    Q[c] += _ancf.element_elastic_force(q[c], qd[c], b.l, b.EA, b.EI, b.damping)
            else:
                u, L, Arot, Ath = self._body_L(b, q)
                qfd = qd[o + 3:o + b.n]
                qf = q[o + 3:o + b.n]
                # a_v(x_g) = -A u thd^2 + 2 thd A_theta S qf_dot
                av = -(u @ Arot.T) * thd * thd + 2.0 * thd * (b.Sg @ qfd) @ Ath.T
                Qb = -np.einsum("g,gia,gi->a", b.mw, L, av)
                if g is not None:
                    Qb += np.einsum("g,gia,i->a", b.mw, L, g)
                Qb[3:] -= b.K_ff @ qf
                Qb[3:] += b.nonlinear_elastic(qf)[1]
                if b.damping:
                    Qb[3:] -= b.damping * (b.K_ff @ qfd)
                    Qb[3:] += b.nonlinear_damping(qf, qfd)
                Q[sl] += Qb
        for f in self.forces:
            kind = f[0]
            if kind == "point_force":
                r, J, *_ = f[1].kin(q, qd, self.n)
                Q += J.T @ f[2]
            elif kind == "torque":
                _, _, _, Jp, *_ = f[1].kin(q, qd, self.n)
                Q += Jp * f[2]
            else:
                _, ma, mb, k, c, l0 = f
                ra, Ja, _, _, rda, _, _ = ma.kin(q, qd, self.n)
                rb, Jb, _, _, rdb, _, _ = mb.kin(q, qd, self.n)
                d = ra - rb
                ln = math.hypot(d[0], d[1])
                if ln == 0.0:
                    raise ModelError("spring_damper of zero length: direction undefined")
                e = d / ln
                ldot = e @ (rda - rdb)
                Q -= (k * (ln - l0) + c * ldot) * ((Ja - Jb).T @ e)
        return Q

    # ---------------------------------------------------------------- constraints
    def _constraints(self, t, q, qd):
        """Phi (m,), A (m, n), gamma (m,), Phi_t (m,)."""
        q = np.asarray(q, dtype=float)
        qd = np.zeros(self.n) if qd is None else np.asarray(qd, dtype=float)
        n, m = self.n, self.m
        Phi = np.zeros(m)
        A = np.zeros((m, n))
        gam = np.zeros(m)
        Pt = np.zeros(m)
        i = 0
        for kind, ma, mb, phi0 in self.joints:
            ra, Ja, pa, Jpa, rda, pda, ava = ma.kin(q, qd, n)
            rb, Jb, pb, Jpb, rdb, pdb, avb = mb.kin(q, qd, n)
            hpa, hpb = _phi_velocity_term(ma, q, qd), _phi_velocity_term(mb, q, qd)
            if kind in ("revolute", "weld"):
                Phi[i:i + 2] = ra - rb
                A[i:i + 2] = Ja - Jb
                gam[i:i + 2] = -(ava - avb)
                i += 2
                if kind == "weld":
                    Phi[i] = _wrap(pa - pb - phi0)
                    A[i] = Jpa - Jpb
                    gam[i] = -(hpa - hpb)
                    i += 1
            else:  # point_on_line (point=a, line=b) and prismatic (a on b's line + angle)
                tl = np.array([math.cos(pb), math.sin(pb)])
                nl = np.array([-tl[1], tl[0]])
                d = ra - rb
                dd = rda - rdb
                Phi[i] = nl @ d
                A[i] = nl @ (Ja - Jb) - (tl @ d) * Jpb
                # Phi_ddot = n.d_ddot + 2 n_dot.d_dot + n_ddot.d,
                # n_dot = -t phid, n_ddot = -t phi_ddot - n phid^2, phi_ddot = J_phi qdd + h_phi
                gam[i] = -(nl @ (ava - avb) - 2.0 * pdb * (tl @ dd) - pdb * pdb * (nl @ d) - (tl @ d) * hpb)
                i += 1
                if kind == "prismatic":
                    Phi[i] = _wrap(pa - pb - phi0)
                    A[i] = Jpa - Jpb
                    gam[i] = -(hpa - hpb)
                    i += 1
        for drv in self.drivers:
            if drv[0] == "angle":
                _, ma, mb, mot = drv
                _, _, pa, Jpa, *_ = ma.kin(q, qd, n)
                _, _, pb, Jpb, *_ = mb.kin(q, qd, n)
                Phi[i] = _wrap(pa - pb - mot(t))
                A[i] = Jpa - Jpb
                gam[i] = mot(t, 2) - (_phi_velocity_term(ma, q, qd) - _phi_velocity_term(mb, q, qd))
            else:
                _, mp, axis, mot = drv
                r, J, _, _, _, _, av = mp.kin(q, qd, n)
                Phi[i] = r[axis] - mot(t)
                A[i] = J[axis]
                gam[i] = -av[axis] + mot(t, 2)
            Pt[i] = -mot(t, 1)
            i += 1
        assert i == m
        return Phi, A, gam, Pt

    def phi(self, t, q):
        """Constraint residual Phi(t, q), (m,)."""
        return self._constraints(t, q, None)[0]

    def phi_A(self, t, q):
        """(Phi, A) in one pass."""
        Phi, A, _, _ = self._constraints(t, q, None)
        return Phi, A

    def A(self, q):
        """Constraint Jacobian Phi_q, (m, n) (independent of t)."""
        return self._constraints(0.0, q, None)[1]

    def phi_t(self, t):
        """Partial time derivative of Phi, (m,)."""
        Pt = np.zeros(self.m)
        i = self.m - len(self.drivers)
        for k, drv in enumerate(self.drivers):
            Pt[i + k] = -drv[3](t, 1)
        return Pt

    def gamma(self, t, q, qd):
        """Right-hand side b = gamma of the acceleration constraints (eq. 43), (m,)."""
        return self._constraints(t, q, qd)[2]

    b = gamma

    def terms(self, t, q, qd):
        """(M, Q, A, b) in one call."""
        _, A, gam, _ = self._constraints(t, q, qd)
        return self.M(q), self.Q(t, q, qd), A, gam

    # ---------------------------------------------------------------- energies (diagnostics)
    def kinetic_energy(self, q, qd):
        qd = np.asarray(qd, float)
        return 0.5 * qd @ self.M(q) @ qd

    def potential_energy(self, q):
        """Strain + gravity + spring potential (forces/torques/dampers excluded)."""
        q = np.asarray(q, float)
        V = 0.0
        g = self.gravity
        for b in self.bodies:
            o = b.offset
            if b.kind == "rigid":
                Arot, _ = _rot(q[o + 2])
                if g is not None:
                    V -= b.mass * g @ (q[o:o + 2] + Arot @ b.com)
            elif b.kind == "ancf":
                for k in range(b.elements):
                    V += _ancf.element_strain_energy(q[o + 4 * k:o + 4 * k + 8], b.l, b.EA, b.EI)
                if g is not None:
                    V -= b.gravity_force(g) @ q[o:o + b.n]
            else:
                qf = q[o + 3:o + b.n]
                V += 0.5 * qf @ b.K_ff @ qf + b.nonlinear_elastic(qf)[0]
                if g is not None:
                    u, L, Arot, _ = self._body_L(b, q)
                    r = q[o:o + 2] + u @ Arot.T
                    V -= np.einsum("g,gi,i->", b.mw, r, g)
        for f in self.forces:
            if f[0] == "spring_damper":
                _, ma, mb, k, c, l0 = f
                ra = ma.kin(q, np.zeros(self.n), self.n)[0]
                rb = mb.kin(q, np.zeros(self.n), self.n)[0]
                V += 0.5 * k * (np.linalg.norm(ra - rb) - l0) ** 2
        return V
