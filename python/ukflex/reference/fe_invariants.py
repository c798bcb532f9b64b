"""Inertia invariants of planar flexible bodies computed independently in NumPy, by quadrature
over the elements (the check of ``rust/body/ffrf_beam.rs`` and ``rust/body/flexible.rs``).

``beam_invariants`` integrates the Davis et al. Timoshenko (or Euler-Bernoulli) beam element's
shape functions with Gauss-Legendre quadrature of its own order and returns the invariants in the
field names of a flexible body's description (docs/flexible-bodies.md); a flexible body built
from them must reproduce the built-in beam's mass matrix and forces.  ``triangle_invariants``
integrates a plane-stress mesh of linear triangles (the check of :mod:`ukflex.fe`, which
computes them from the assembled mass matrix).  Imports nothing else of ukflex.
"""

from __future__ import annotations

from typing import Any, Dict, Optional, Sequence

import numpy as np

__all__ = ["beam_shape", "beam_invariants", "triangle_invariants"]


def beam_shape(s: float, l: float, phi: float):
    """``(N_u, N_v, N_psi, N_u', N_v', N_psi')`` of the element at ``s`` in [0, 1] (6 each;
    local dofs ``u1 v1 psi1 u2 v2 psi2``)."""
    c = 1.0 / (1.0 + phi)
    nu = np.array([1 - s, 0, 0, s, 0, 0], dtype=float)
    nv = c * np.array([0, 2 * s**3 - 3 * s**2 - phi * s + 1 + phi, l * (s**3 - (2 + phi / 2) * s**2 + (1 + phi / 2) * s),
                       0, -2 * s**3 + 3 * s**2 + phi * s, l * (s**3 - (1 - phi / 2) * s**2 - phi / 2 * s)])
    npsi = c * np.array([0, 6 / l * (s**2 - s), 3 * s**2 - (4 + phi) * s + 1 + phi, 0, -6 / l * (s**2 - s),
                         3 * s**2 - (2 - phi) * s])
    dnu = np.array([-1, 0, 0, 1, 0, 0]) / l
    dnv = c * np.array([0, (6 * s**2 - 6 * s - phi) / l, 3 * s**2 - (4 + phi) * s + 1 + phi / 2, 0,
                        (-6 * s**2 + 6 * s + phi) / l, 3 * s**2 - (2 - phi) * s - phi / 2])
    dnpsi = c * np.array([0, 6 / l**2 * (2 * s - 1), (6 * s - 4 - phi) / l, 0, -6 / l**2 * (2 * s - 1), (6 * s - 2 + phi) / l])
    return nu, nv, npsi, dnu, dnv, dnpsi


def beam_invariants(length: float, elements: int, density: float, youngs_modulus: float, area: float,
                    second_moment: float, shear_stiffness: Optional[float] = None, rotary_inertia: bool = True,
                    frame: str = "pinned-pinned", markers: Sequence[float] = (0.0, 1.0), order: int = 6,
                    nonlinear: bool = False) -> Dict[str, Any]:
    """Invariants of a uniform beam of ``elements`` elements on its floating frame.

    ``shear_stiffness`` is ``k G`` (Timoshenko); ``None`` gives Euler-Bernoulli.  ``frame``:
    ``"pinned-pinned"`` removes ``u_1, v_1, v_N+1``, ``"clamped"`` ``u_1, v_1, psi_1``.
    ``markers``: abscissas ``xi`` of interface points (named ``"xi=<value>"``).  Returns a dict
    with the fields of a flexible body (``mass, inertia, com, s_bar, s_u0, s_ju0, s_tilde, m_ff,
    m_ff_tr, k_ff, markers``; with ``nonlinear`` also ``k3``, ``k4``: the cubic and quartic
    strain energy of the element-averaged second-order axial strain
    ``eps = (u_2 - u_1) / l + int v'^2 dx / (2 l)``, ``U = E a l eps^2 / 2`` per element).
    """
    n = int(elements)
    l = length / n
    rho_a, rho_i = density * area, density * second_moment
    ea, ei = youngs_modulus * area, youngs_modulus * second_moment
    phi = 0.0 if shear_stiffness is None else 12 * ei / (shear_stiffness * area * l * l)
    nd = 3 * (n + 1)
    removed = [0, 1, 3 * n + 1] if frame == "pinned-pinned" else [0, 1, 2]
    keep = [k for k in range(nd) if k not in removed]
    xg, wg = np.polynomial.legendre.leggauss(order)
    sg, wg = (xg + 1) / 2, wg / 2
    mass = j0 = sx = 0.0
    s_bar = np.zeros((2, nd))
    s_u0, s_ju0 = np.zeros(nd), np.zeros(nd)
    s_tilde, m_tr, m_full, k_full = (np.zeros((nd, nd)) for _ in range(4))
    for e in range(n):
        dofs = np.arange(3 * e, 3 * e + 6)
        for s, w in zip(sg, wg):
            nu, nv, npsi, dnu, dnv, dnpsi = beam_shape(s, l, phi)
            x = (e + s) * l
            wl = w * l
            ix = np.ix_(dofs, dofs)
            mass += wl * rho_a
            sx += wl * rho_a * x
            j0 += wl * (rho_a * x * x + (rho_i if rotary_inertia else 0.0))
            s_bar[0, dofs] += wl * rho_a * nu
            s_bar[1, dofs] += wl * rho_a * nv
            s_u0[dofs] += wl * rho_a * x * nu
            s_ju0[dofs] += wl * (rho_a * x * nv + (rho_i * npsi if rotary_inertia else 0.0))
            s_tilde[ix] += wl * rho_a * (np.outer(nu, nv) - np.outer(nv, nu))
            mt = wl * rho_a * (np.outer(nu, nu) + np.outer(nv, nv))
            m_tr[ix] += mt
            m_full[ix] += mt + (wl * rho_i * np.outer(npsi, npsi) if rotary_inertia else 0.0)
            kk = ea * np.outer(dnu, dnu) + ei * np.outer(dnpsi, dnpsi)
            if shear_stiffness is not None:
                g = npsi - dnv
                kk = kk + shear_stiffness * area * np.outer(g, g)
            k_full[ix] += wl * kk
    sel = np.ix_(keep, keep)
    com = (sx / mass, 0.0)
    extra: Dict[str, Any] = {}
    if nonlinear:
        k3 = np.zeros((nd, nd, nd))
        k4 = np.zeros((nd, nd, nd, nd))
        for e in range(n):
            dofs = np.arange(3 * e, 3 * e + 6)
            bvec = np.zeros(6)
            bvec[0], bvec[3] = -1.0 / l, 1.0 / l
            gmat = np.zeros((6, 6))
            for s, w in zip(sg, wg):
                dnv = beam_shape(s, l, phi)[4]
                gmat += w * l * np.outer(dnv, dnv)
            t3 = ea * (np.einsum("i,jk->ijk", bvec, gmat) + np.einsum("j,ik->ijk", bvec, gmat) + np.einsum("k,ij->ijk", bvec, gmat))
            t4 = ea / l * (np.einsum("ij,kl->ijkl", gmat, gmat) + np.einsum("ik,jl->ijkl", gmat, gmat)
                           + np.einsum("il,jk->ijkl", gmat, gmat))
            k3[np.ix_(dofs, dofs, dofs)] += t3
            k4[np.ix_(dofs, dofs, dofs, dofs)] += t4
        extra = dict(k3=k3[np.ix_(keep, keep, keep)], k4=k4[np.ix_(keep, keep, keep, keep)])
    out_markers = {}
    for xi in markers:
        t = xi * n
        e = min(int(np.floor(t)), n - 1)
        nu, nv, npsi, *_ = beam_shape(t - e, l, phi)
        d = np.zeros((2, nd))
        r = np.zeros(nd)
        d[0, 3 * e:3 * e + 6], d[1, 3 * e:3 * e + 6], r[3 * e:3 * e + 6] = nu, nv, npsi
        out_markers[f"xi={xi:g}"] = dict(point=(xi * length, 0.0), displacement=d[:, keep], rotation=r[keep])
    return dict(mass=mass, inertia=j0 - mass * com[0] ** 2, com=com, s_bar=s_bar[:, keep], s_u0=s_u0[keep],
                s_ju0=s_ju0[keep], s_tilde=s_tilde[sel], m_ff=m_full[sel], m_ff_tr=m_tr[sel], k_ff=k_full[sel],
                markers=out_markers, **extra)


def triangle_invariants(nodes: np.ndarray, triangles: np.ndarray, thickness: float, density: float,
                        modes: np.ndarray) -> Dict[str, Any]:
    """Invariants of a mesh of linear triangles (plane stress, thickness ``thickness``) for the
    elastic displacement ``u = modes @ q_f`` (``modes``: (2 N, n_f), dofs ``x_1, y_1, ...``), by
    a three-point quadrature (exact for the quadratic integrands) over each triangle."""
    x = np.asarray(nodes, dtype=float)
    phi = np.asarray(modes, dtype=float).reshape(x.shape[0], 2, -1)
    nf = phi.shape[2]
    bary = np.array([[2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]])
    mass = j0 = 0.0
    first = np.zeros(2)
    s_bar = np.zeros((2, nf))
    s_u0, s_ju0 = np.zeros(nf), np.zeros(nf)
    s_tilde, m_ff = np.zeros((nf, nf)), np.zeros((nf, nf))
    for tri in np.asarray(triangles):
        p = x[tri]
        area = 0.5 * abs((p[1, 0] - p[0, 0]) * (p[2, 1] - p[0, 1]) - (p[2, 0] - p[0, 0]) * (p[1, 1] - p[0, 1]))
        for lam in bary:
            w = density * thickness * area / 3.0
            u0 = lam @ p
            s = np.einsum("a,adf->df", lam, phi[tri])  # (2, nf)
            mass += w
            first += w * u0
            j0 += w * u0 @ u0
            s_bar += w * s
            s_u0 += w * s.T @ u0
            s_ju0 += w * s.T @ np.array([-u0[1], u0[0]])
            s_tilde += w * (np.outer(s[0], s[1]) - np.outer(s[1], s[0]))
            m_ff += w * s.T @ s
    com = first / mass
    return dict(mass=mass, inertia=j0 - mass * float(com @ com), com=tuple(com), s_bar=s_bar, s_u0=s_u0, s_ju0=s_ju0,
                s_tilde=s_tilde, m_ff=m_ff)
