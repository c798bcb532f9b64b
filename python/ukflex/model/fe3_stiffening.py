"""Stresses of the FE solid of a ``flexible3`` body: stress stiffening (docs/spatial-flexible.md,
"Stress stiffening"), the modal geometric-stiffness matrices of the unit inertia load cases
(:func:`ukflex.fe3.from_mesh` with ``stress_stiffening=True``), the Green-Lagrange strain's
energy terms of the modal field (:func:`quadratic_strain`, ``quadratic_strain=True``), and the
modes' nodal stress shapes (:func:`stress_modes`, for the fields and the VTK export).

A load case is a body force per unit mass ``b(x) = B x + c`` in the frame's axes. The solid,
held at the frame's interface, carries it statically (``K u = f``, ``f_i = int rho phi_i b``);
its stress ``sigma = lam tr(eps) I + 2 mu eps`` gives the geometric stiffness
``G_ij = int sigma_kl d_k phi_i d_l phi_j dV`` of every displacement component, projected onto
the modes: ``K_c = sum_a Phi_a^T G Phi_a`` (``Phi_a`` the a-components of the modes, N x n).
The cases, in :data:`LOAD_CASES` order (the order of the description's ``geometric_stiffness``):

* six centrifugal cases ``ww_kl`` (``b = (tr E I - E) x``, ``E = e_k e_l^T + e_l e_k^T`` for
  ``k != l``, ``e_k e_k^T`` else): ``-w x (w x x) = sum_kl w_k w_l (...)`` over ``k <= l``;
* three angular-acceleration cases ``alpha_k`` (``b = -e_k x x``);
* three specific-force cases ``f_k`` (``b = e_k``: gravity ``g`` enters with the coefficients
  ``R^T g``, a frame acceleration ``a`` with ``-R^T a``).
"""

from __future__ import annotations

from typing import Any, Dict, Tuple

import numpy as np
import scipy.sparse.linalg as spla

from ..errors import require

#: The unit load cases, in the order of the description's ``geometric_stiffness`` (the Rust
#: body reads them by this position: ``rust/body/flexible3.rs``, ``LOAD_CASES``).
LOAD_CASES = ("ww_xx", "ww_yy", "ww_zz", "ww_xy", "ww_yz", "ww_zx",
              "alpha_x", "alpha_y", "alpha_z", "f_x", "f_y", "f_z")


def _case(c: int) -> Tuple[np.ndarray, np.ndarray]:
    """``(B, c)`` of load case ``c``: the body force per unit mass ``b(x) = B x + c``."""
    e = np.eye(3)
    if c < 6:
        k, l = ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0))[c]
        m = np.outer(e[k], e[l])
        if k != l:
            m = m + m.T
        return np.trace(m) * np.eye(3) - m, np.zeros(3)
    if c < 9:
        k = c - 6
        ek = e[k]
        return -np.array([[0, -ek[2], ek[1]], [ek[2], 0, -ek[0]], [-ek[1], ek[0], 0]]), np.zeros(3)
    return np.zeros((3, 3)), e[c - 9].copy()


def stress(solid: Any, u: np.ndarray) -> Dict[str, np.ndarray]:
    """The stress ``s{ij}`` (i, j = 0..2) at the quadrature points of the displacement ``u``
    (N, 3) of the solid: ``sigma = lam tr(eps) I + 2 mu eps``."""
    grad = [solid.basis.interpolate(u[:, a]).grad for a in range(3)]  # grad[a][k] = d u_a / d x_k
    eps = [[0.5 * (grad[i][j] + grad[j][i]) for j in range(3)] for i in range(3)]
    tr = eps[0][0] + eps[1][1] + eps[2][2]
    return {f"s{i}{j}": solid.lam * tr * (i == j) + 2.0 * solid.mu * eps[i][j] for i in range(3) for j in range(3)}


#: The stress components of :func:`stress_modes`, in their order (Voigt's).
STRESS_COMPONENTS = ("xx", "yy", "zz", "yz", "zx", "xy")


def stress_modes(solid: Any, basis: np.ndarray) -> np.ndarray:
    """The nodal stress shapes (N, 6, n) of the modes ``basis`` (3N, n): each component's L2
    projection onto the element space (``M_1 s = int sigma phi``, ``M_1`` the mass matrix of
    unit density), components in :data:`STRESS_COMPONENTS` order (Pa per unit modal coordinate)."""
    skfem = require("skfem", "ukflex.fe3 (stress shapes)", extra="fe")
    nn, n = solid.nodes.shape[0], basis.shape[1]
    m1 = skfem.asm(skfem.BilinearForm(lambda u, v, w: u * v), solid.basis).tocsc()
    lu = spla.splu(m1)
    form = skfem.LinearForm(lambda v, w: w["s"] * v)
    pairs = ((0, 0), (1, 1), (2, 2), (1, 2), (2, 0), (0, 1))
    out = np.zeros((nn, 6, n))
    for k in range(n):
        sig = stress(solid, basis[:, k].reshape(nn, 3))
        for c, (i, j) in enumerate(pairs):
            out[:, c, k] = lu.solve(skfem.asm(form, solid.basis, s=sig[f"s{i}{j}"]))
    return out


def geometric_stiffness(solid: Any, held: np.ndarray, basis: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """The modal geometric stiffness ``K_c`` (12, n, n) of the :data:`LOAD_CASES` and the
    static displacements of the cases (12, N, 3), the solid held on the dofs ``held`` (mask of
    3N). ``solid``: the assembled model of :mod:`ukflex.model.fe3` (nodes, ``k``, ``ms``, the
    scalar ``basis``, ``lam``, ``mu``)."""
    nodes, k, ms = solid.nodes, solid.k, solid.ms
    nn, n = nodes.shape[0], basis.shape[1]
    free = np.nonzero(~held)[0]
    lu = spla.splu(k[free][:, free].tocsc())
    mx, m1 = ms @ nodes, ms @ np.ones(nn)
    modes = [basis[a::3, :] for a in range(3)]  # (N, n) each
    form = _geometric_form()
    out = np.zeros((len(LOAD_CASES), n, n))
    disp = np.zeros((len(LOAD_CASES), nn, 3))
    for c in range(len(LOAD_CASES)):
        bm, cv = _case(c)
        f = (mx @ bm.T + np.outer(m1, cv)).reshape(-1)
        u = np.zeros(3 * nn)
        u[free] = lu.solve(f[free])
        u = u.reshape(nn, 3)
        disp[c] = u
        out[c] = _modal_geometric(solid, form, modes, u)
    return out, disp


def _modal_geometric(solid: Any, form: Any, modes: Any, u: np.ndarray) -> np.ndarray:
    """``sum_a Phi_a^T G(sigma(u)) Phi_a`` (n, n), symmetrized: the modal geometric stiffness
    of the linear stress of the displacement ``u`` (N, 3)."""
    skfem = require("skfem", "ukflex.fe3 (geometric stiffness)", extra="fe")
    g = skfem.asm(form, solid.basis, **stress(solid, u)).tocsr()
    kc = sum(modes[a].T @ (g @ modes[a]) for a in range(3))
    return 0.5 * (kc + kc.T)


def _geometric_form() -> Any:
    skfem = require("skfem", "ukflex.fe3 (geometric stiffness)", extra="fe")
    return skfem.BilinearForm(lambda u, v, w: sum(w[f"s{i}{j}"] * u.grad[i] * v.grad[j] for i in range(3) for j in range(3)))


def quadratic_strain(solid: Any, basis: np.ndarray, held: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """The Green-Lagrange strain's energy terms of the modal field ``u = Phi q`` of the solid
    held on the dofs ``held`` (docs/spatial-flexible.md, "Quadratic strain";
    ``rust/body/flexible3_strain.rs``): the modal geometric stiffness ``G_k`` (n, n, n) of each
    mode's linear stress (the cubic energy ``1/2 sum_k q_k q^T G_k q``) and ``H`` (n^2, n^2),
    the quartic energy ``1/8 H_ijkl q_i q_j q_k q_l``: ``int B_ij : C : B_kl`` (``B_ij =
    sym(grad phi_i^T grad phi_j)``) less the static condensation of the displacement outside
    the basis that the second-order load ``f2 = r_ij q_i q_j`` drives, ``4 r_ij^T K_c^+ r_kl``
    (without it a basis that cannot shorten pointwise as it bends locks: docs)."""
    skfem = require("skfem", "ukflex.fe3 (quadratic strain)", extra="fe")
    nn, n = solid.nodes.shape[0], basis.shape[1]
    modes = [basis[a::3, :] for a in range(3)]
    form = _geometric_form()
    gs = [skfem.asm(form, solid.basis, **stress(solid, basis[:, k].reshape(nn, 3))).tocsr() for k in range(n)]
    g = np.stack([sum(modes[a].T @ (gk @ modes[a]) for a in range(3)) for gk in gs])
    g = 0.5 * (g + g.transpose(0, 2, 1))
    # grads[i, a, k] = d phi_i,a / d x_k at the quadrature points (E, Q)
    shape = np.asarray(solid.basis.dx).shape
    grads = np.stack([np.stack([np.stack(solid.basis.interpolate(basis[a::3, i]).grad) for a in range(3)]) for i in range(n)])
    grads = grads.reshape(n, 3, 3, -1)
    # B_ij = B_ji: every term below is computed once per pair i <= j (index u) and spread to
    # (i, j) and (j, i) by ``pair`` (n^2,): n (n + 1) / 2 of the n^2 rows and right-hand sides
    iu, ju = np.triu_indices(n)
    pair = np.empty((n, n), dtype=np.int64)
    pair[iu, ju] = pair[ju, iu] = np.arange(iu.size)
    pair = pair.reshape(-1)
    # B_ij = sym(grad phi_i^T grad phi_j) (the A_ij + A_ji of A_ij,kl = sum_a d_k phi_i,a d_l phi_j,a)
    a_ = np.einsum("uakp,ualp->uklp", grads[iu], grads[ju])
    b = 0.5 * (a_ + a_.transpose(0, 2, 1, 3)).reshape(iu.size, 9, -1)
    del a_
    # H = sum_p B_ij(p) : C : B_kl(p) dx(p) (the rule's weights may be negative: no square root)
    dx = np.asarray(solid.basis.dx).reshape(-1)
    tr = b[:, 0] + b[:, 4] + b[:, 8]
    flat = b.reshape(iu.size, -1)
    h = solid.lam * ((tr * dx) @ tr.T) + 2.0 * solid.mu * ((flat * np.tile(dx, 9)) @ flat.T)
    # r_ij: the nodal load of the gradient of V3 over the full field at u = Phi q, f2 = sum_ij
    # r_ij q_i q_j: 1/2 int (C : B_ij) : grad du + 1/2 (G_i phi_j + G_j phi_i)
    lin = skfem.LinearForm(lambda v, w: w["s0"] * v.grad[0] + w["s1"] * v.grad[1] + w["s2"] * v.grad[2])
    r = np.zeros((3 * nn, iu.size))
    for u, (i, j) in enumerate(zip(iu, ju)):
        bij = b[u].reshape(3, 3, *shape)
        sij = 2.0 * solid.mu * bij + solid.lam * (bij[0, 0] + bij[1, 1] + bij[2, 2]) * np.eye(3).reshape(3, 3, 1, 1)
        for a in range(3):
            col = 0.5 * skfem.asm(lin, solid.basis, s0=sij[a, 0], s1=sij[a, 1], s2=sij[a, 2])
            r[a::3, u] = col + 0.5 * (gs[i] @ modes[a][:, j] + gs[j] @ modes[a][:, i])
    # the complement's compliance: R^T K^-1 R - (Phi^T R)^T K_r^-1 (Phi^T R)
    free = np.nonzero(~held)[0]
    # a symmetric ordering: with scipy's default (COLAMD) the solves with the n (n + 1) / 2
    # right-hand sides took ten times longer (the slider-crank's rod: 3.2 s against 0.37 s, CPU)
    lu = spla.splu(solid.k[free][:, free].tocsc(), permc_spec="MMD_AT_PLUS_A")
    c = r[free].T @ lu.solve(r[free])
    pr = basis.T @ r
    kr = basis.T @ (solid.k @ basis)
    c -= pr.T @ np.linalg.solve(0.5 * (kr + kr.T), pr)
    h = (h - 4.0 * c)[np.ix_(pair, pair)]
    return g, 0.5 * (h + h.T)


def held_mask(sets: Any, reference: str, n3: int) -> np.ndarray:
    """The dofs (mask of 3N) of the held interface's node set."""
    held = np.zeros(n3, dtype=bool)
    for i in sets[reference]:
        held[3 * i:3 * i + 3] = True
    return held


__all__ = ["LOAD_CASES", "STRESS_COMPONENTS", "geometric_stiffness", "held_mask", "quadratic_strain", "stress", "stress_modes"]
