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
import scipy.sparse as sp
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
    values, ds, dx = _operators(solid)
    sig = _modal_stress(solid, _modal_gradients(ds, basis))  # (n, 3, 3, P)
    pairs = ((0, 0), (1, 1), (2, 2), (1, 2), (2, 0), (0, 1))
    # int sigma phi of every component and mode, one solve for the 6 n right-hand sides
    rhs = values.T @ np.concatenate([(sig[:, i, j] * dx).T for i, j in pairs], axis=1)
    return spla.splu(m1).solve(rhs).reshape(nn, 6, n)


def _operators(solid: Any) -> Tuple[sp.csr_matrix, Tuple[sp.csr_matrix, ...], np.ndarray]:
    """The scalar element functions at the quadrature points (``P = E Q``, point ``e Q + q``):
    their values ``V`` and gradient components ``D_k`` (P x N: ``(D_k u)[p] = d u / d x_k``)
    and the weights ``dx`` (P,). A linear form ``int s . grad v`` is ``sum_k D_k^T (s_k dx)``, a
    bilinear one ``sum_kl D_k^T diag(s_kl dx) D_l``: the modal forms below as array products
    (scikit-fem's assembly per load, mode pair and component cost the default rod's build ~1 s)."""
    b = solid.basis
    e, q = np.asarray(b.dx).shape
    shape = (len(b.basis), e, q)
    rows = np.broadcast_to(np.arange(e * q).reshape(1, e, q), shape).ravel()
    cols = np.broadcast_to(np.asarray(b.element_dofs)[:, :, None], shape).ravel()

    def op(vals: np.ndarray) -> sp.csr_matrix:
        return sp.csr_matrix((vals.ravel(), (rows, cols)), shape=(e * q, solid.nodes.shape[0]))

    values = op(np.stack([np.asarray(f[0].value) for f in b.basis]))
    ds = tuple(op(np.stack([np.asarray(f[0].grad[k]) for f in b.basis])) for k in range(3))
    return values, ds, np.asarray(b.dx).reshape(-1)


def _modal_gradients(ds: Any, basis: np.ndarray) -> np.ndarray:
    """``grads[i, a, k]`` (n, 3, 3, P) = ``d phi_i,a / d x_k`` at the quadrature points."""
    return np.stack([np.stack([(d @ basis[a::3, :]).T for d in ds]) for a in range(3)]).transpose(2, 0, 1, 3).copy()


def _modal_stress(solid: Any, grads: np.ndarray) -> np.ndarray:
    """The linear stress (n, 3, 3, P) of each mode of the gradients ``grads`` (n, 3, 3, P)."""
    eps = 0.5 * (grads + grads.transpose(0, 2, 1, 3))
    tr = eps[:, 0, 0] + eps[:, 1, 1] + eps[:, 2, 2]
    return 2.0 * solid.mu * eps + solid.lam * tr[:, None, None] * np.eye(3)[None, :, :, None]


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
    n = basis.shape[1]
    _, ds, dx = _operators(solid)
    grads = _modal_gradients(ds, basis)  # grads[i, a, k] = d phi_i,a / d x_k (n, 3, 3, P)
    sig = _modal_stress(solid, grads)
    # G_k = sum_a Phi_a^T G(sigma_k) Phi_a: [m, n] = int sigma_k,ij d_i phi_n,a d_j phi_m,a
    flat_g = grads.reshape(n, -1)
    g = np.stack([np.einsum("ijp,majp->maip", sig[k] * dx, grads).reshape(n, -1) @ flat_g.T for k in range(n)])
    g = 0.5 * (g + g.transpose(0, 2, 1))
    # B_ij = B_ji: every term below is computed once per pair i <= j (index u) and spread to
    # (i, j) and (j, i) by ``pair`` (n^2,): n (n + 1) / 2 of the n^2 rows and right-hand sides
    iu, ju = np.triu_indices(n)
    pair = np.empty((n, n), dtype=np.int64)
    pair[iu, ju] = pair[ju, iu] = np.arange(iu.size)
    pair = pair.reshape(-1)
    # per quadrature point p (3n x 3n, rows (i, k)): A[(i, k), (j, l)] = sum_a d_k phi_i,a d_l phi_j,a
    # and Z[(i, k), (j, a)] = sum_l sigma_i,kl d_l phi_j,a, two small products per point, by blocks
    # of points (the blocks' arrays stay in cache: the whole rod's were 137 MB each)
    gp = np.ascontiguousarray(grads.transpose(3, 0, 2, 1)).reshape(-1, 3 * n, 3)  # [p, (i, k), a]
    gl = np.ascontiguousarray(grads.transpose(3, 0, 1, 2)).reshape(-1, 3 * n, 3)  # [p, (j, a), l]
    sp_ = np.ascontiguousarray(sig.transpose(3, 0, 1, 2)).reshape(-1, 3 * n, 3)  # [p, (i, k), l]
    k3, l3 = np.arange(3)[:, None], np.arange(3)[None, :]

    def at(i: np.ndarray, k: Any, j: np.ndarray, l: Any) -> np.ndarray:
        """The flat indices of ``m[(i, k), (j, l)]`` (U, 3, 3) of the pairs in a 3n x 3n block."""
        return ((3 * i[:, None, None] + k) * 3 * n + 3 * j[:, None, None] + l).reshape(-1)

    bkl, blk = at(iu, k3, ju, l3), at(iu, l3, ju, k3)
    zij, zji = at(iu, l3, ju, k3), at(ju, l3, iu, k3)  # Z[(i, k), (j, a)] at (a, k)
    h = np.zeros((iu.size, iu.size))
    w = np.empty((dx.size, iu.size, 3, 3))
    eye = np.eye(3)
    for p0 in range(0, dx.size, 256):
        sl = slice(p0, min(p0 + 256, dx.size))
        m = sl.stop - sl.start
        a_ = np.matmul(gp[sl], gp[sl].transpose(0, 2, 1)).reshape(m, -1)
        z = np.matmul(sp_[sl], gl[sl].transpose(0, 2, 1)).reshape(m, -1)
        # B_ij = sym(grad phi_i^T grad phi_j) (the A_ij + A_ji of A_ij,kl)
        b = (0.5 * (a_[:, bkl] + a_[:, blk])).reshape(m, iu.size, 3, 3)
        # H = sum_p B_ij(p) : C : B_kl(p) dx(p) (the rule's weights may be negative: no square root)
        tr = b[:, :, 0, 0] + b[:, :, 1, 1] + b[:, :, 2, 2]
        flat = b.reshape(m, iu.size, 9)
        h += solid.lam * ((tr.T * dx[sl]) @ tr) + 2.0 * solid.mu * np.einsum("pu,puc,pvc->uv", dx[sl, None], flat, flat, optimize=True)
        # r_ij: the nodal load of the gradient of V3 over the full field at u = Phi q, f2 = sum_ij
        # r_ij q_i q_j: 1/2 int (C : B_ij) : grad du + 1/2 (G_i phi_j + G_j phi_i), the a-components
        # sum_k D_k^T (w_ak dx), w_ak = 1/2 (C : B_ij)_ak + 1/2 sum_l (sigma_i,kl d_l phi_j,a + sigma_j,kl d_l phi_i,a)
        wb = 2.0 * solid.mu * b + solid.lam * tr[:, :, None, None] * eye
        wb += (z[:, zij] + z[:, zji]).reshape(m, iu.size, 3, 3)
        w[sl] = wb * (0.5 * dx[sl, None, None, None])
    r = np.zeros((3 * solid.nodes.shape[0], iu.size))
    for a in range(3):
        r[a::3] = sum(ds[k].T @ np.ascontiguousarray(w[:, :, a, k]) for k in range(3))
    # the complement's compliance: R^T K^-1 R - (Phi^T R)^T K_r^-1 (Phi^T R)
    free = np.nonzero(~held)[0]
    c = _compliance(solid.k[free][:, free], r[free])
    pr = basis.T @ r
    kr = basis.T @ (solid.k @ basis)
    c -= pr.T @ np.linalg.solve(0.5 * (kr + kr.T), pr)
    h = (h - 4.0 * c)[np.ix_(pair, pair)]
    return g, 0.5 * (h + h.T)


def _compliance(k: sp.spmatrix, r: np.ndarray) -> np.ndarray:
    """``R^T K^-1 R`` (K symmetric positive definite, R with many columns): ``Y^T Y``, ``Y = U^-T
    R`` with ``K = U^T U`` the banded Cholesky factor in the reverse Cuthill-McKee order (a bar's
    narrow band: the default rod's 4800 dofs, band 175, 120 right-hand sides in 0.1 s where
    SuperLU's solves took 0.3-1.7 s CPU on the loaded machine); SuperLU with a symmetric ordering
    for a wide band or an indefinite ``K``."""
    from scipy.sparse.csgraph import reverse_cuthill_mckee
    import scipy.linalg as sla

    k = sp.csr_matrix(k)
    perm = reverse_cuthill_mckee(k, symmetric_mode=True)
    upper = sp.triu(k[perm][:, perm]).tocoo()
    band = int(np.max(upper.col - upper.row, initial=0))
    if band < k.shape[0] // 8:
        ab = np.zeros((band + 1, k.shape[0]))
        ab[band + upper.row - upper.col, upper.col] = upper.data
        try:
            u = sla.cholesky_banded(ab, lower=False)
        except sla.LinAlgError:
            u = None
        if u is not None:
            y, info = sla.lapack.dtbtrs(u, r[perm], uplo="U", trans="T")
            if info == 0:
                return y.T @ y
    # with scipy's default ordering (COLAMD) the solves took ten times longer
    lu = spla.splu(k.tocsc(), permc_spec="MMD_AT_PLUS_A")
    return r.T @ lu.solve(r)


def held_mask(sets: Any, reference: str, n3: int) -> np.ndarray:
    """The dofs (mask of 3N) of the held interface's node set."""
    held = np.zeros(n3, dtype=bool)
    for i in sets[reference]:
        held[3 * i:3 * i + 3] = True
    return held


__all__ = ["LOAD_CASES", "STRESS_COMPONENTS", "geometric_stiffness", "held_mask", "quadratic_strain", "stress", "stress_modes"]
