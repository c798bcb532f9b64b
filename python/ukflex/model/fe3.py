"""Spatial flexible bodies from finite-element data: the inertia invariants of a ``flexible3``
body (:meth:`ukflex.SpatialScene.flexible_body`) from a 3D linear-elastic FE model reduced to a
few modes (docs/spatial-flexible.md).

* :func:`solid_matrices` -- a scikit-fem tetrahedral or hexahedral mesh (or a meshio mesh or
  file) assembled as an isotropic linear-elastic solid: node coordinates, stiffness ``K``
  (3N x 3N, dofs ``x_1, y_1, z_1, x_2, ...``) and the scalar mass matrix ``M_s``
  (``M = M_s (x) I_3``);
* :func:`from_mesh` -- the reduced body: modes, invariants, interfaces;
* :func:`bar_mesh` -- a box-shaped bar meshed with tetrahedra or hexahedra (studies and tests).

Invariants (Shabana's, in the compact form of the extended shapes ``S_0 = u0``, ``S_j`` the
modes): ``first_moment[a] = int rho S_a dV = 1^T M_s X_a`` and
``second_moment[a, b] = int rho S_a S_b^T dV = X_a^T M_s X_b`` (``X_a``: the nodal values,
(N, 3)). They are exact for the interpolated fields: the element space holds ``u0`` (the
geometry is interpolated by the same functions).

Interfaces (where markers sit) are node sets: the point is their centroid, the displacement of a
mode their mean displacement, the rotation their least-squares rotation about the centroid
(``theta = H^-1 sum d_i x u_i``, ``H = sum |d_i|^2 I - d_i d_i^T``), the average of RBE3-like
interpolation elements. Solid elements have no rotational dofs: a single node gives a point
whose frame is attached rigidly to the floating frame (no elastic rotation), right for a
spherical joint, wrong for a joint that transmits a moment (use a face's node set there).

The floating frame (``frame``) takes the words of every FFRF body (``ukflex.fe.FRAMES``); a 3D
body's frame is one of two:

* ``"mean-axis"`` (default) -- free-free eigenmodes without the six rigid-body modes (the modes
  are mass-orthogonal to the rigid motions, so ``S_bar q = 0`` and ``int rho u0 x S q dV = 0``);
* ``"clamped"`` -- an interface's node set held (``("clamped", "A")``; the word alone: the first
  interface), the frame attached to it.

Reduction (``reduction``, ``ukflex.fe.REDUCTIONS``): ``"modes"`` (default) keeps the eigenmodes
of the model in its frame; ``"craig-bampton"`` (a clamped frame) moves every other interface's
node set rigidly in six static constraint modes (unit translations and rotations about its
centroid, the rest statically condensed), followed by the fixed-interface normal modes.

Stress stiffening (``stress_stiffening=True``, a clamped frame): the modal geometric stiffness
of twelve unit inertia load cases (:mod:`ukflex.model.fe3_stiffening`), which the body scales by
its frame's motion (docs/spatial-flexible.md, "Stress stiffening").

Quadratic strain (``quadratic_strain=True``): the Green-Lagrange strain's second-order part kept
for the modal field, a St-Venant-Kirchhoff solid's cubic and quartic strain energy
(docs/spatial-flexible.md, "Quadratic strain"): the stress the modes carry (a Craig-Bampton
basis: the axial force from the joints) stiffens the body.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..arguments import count, non_negative, positive, real
from ..errors import InvalidArgumentError, require
from ..reference._blas import single_blas_thread
from .fe import REDUCTIONS, frame_interfaces
from .fe3_stiffening import geometric_stiffness, held_mask, quadratic_strain as _quadratic_strain, stress_modes

__all__ = ["FlexibleData3", "Interface3", "solid_matrices", "from_mesh", "bar_mesh"]

InterfaceSpec = Union[int, Sequence[int], Mapping[str, Any], Callable[[np.ndarray], np.ndarray]]


@dataclass
class Interface3:
    """An interface node (set) of a ``flexible3`` body: undeformed ``point`` (frame axes),
    ``phi`` (n, 3) the nodal displacement of each mode and ``psi`` (n, 3) its rotation."""

    point: Tuple[float, float, float]
    phi: np.ndarray
    psi: Optional[np.ndarray] = None
    nodes: Optional[np.ndarray] = None

    def to_dict(self) -> Dict[str, Any]:
        d: Dict[str, Any] = {"point": [float(x) for x in self.point], "phi": np.asarray(self.phi, float).reshape(-1, 3).tolist()}
        if self.psi is not None:
            d["psi"] = np.asarray(self.psi, float).reshape(-1, 3).tolist()
        return d


@dataclass
class FlexibleData3:
    """The data of a ``flexible3`` body: ``mass``, ``first_moment`` (n + 1, 3),
    ``second_moment`` (n + 1, n + 1, 3, 3), ``k_ff`` and optional ``d_ff`` (n, n), the
    ``interfaces`` by name; ``info`` holds what the reduction found (``frequencies`` of the
    kept normal modes in Hz, the basis ``modes`` (3N, n), ``nodes``, the VTK ``cells``, the
    nodal ``stress_modes`` (N, 6, n): ``xx, yy, zz, yz, zx, xy`` per unit modal coordinate; with
    stress stiffening the static ``load_displacements`` (12, N, 3) of the unit load cases);
    ``geometric_stiffness`` (12, n, n), with ``stress_stiffening=True``, the modal geometric
    stiffness of the unit load cases (:data:`ukflex.model.fe3_stiffening.LOAD_CASES`);
    ``quadratic_strain`` (n, n, n) and ``quadratic_strain_quartic`` (n^2, n^2), with
    ``quadratic_strain=True``, the cubic and quartic energy terms of the Green-Lagrange strain
    (:func:`ukflex.model.fe3_stiffening.quadratic_strain`)."""

    mass: float
    first_moment: np.ndarray
    second_moment: np.ndarray
    k_ff: np.ndarray
    d_ff: Optional[np.ndarray] = None
    interfaces: Dict[str, Interface3] = field(default_factory=dict)
    info: Dict[str, Any] = field(default_factory=dict)
    geometric_stiffness: Optional[np.ndarray] = None
    quadratic_strain: Optional[np.ndarray] = None
    quadratic_strain_quartic: Optional[np.ndarray] = None

    @property
    def n_modes(self) -> int:
        return int(self.k_ff.shape[0])

    @property
    def m_ff(self) -> np.ndarray:
        """``M_ff = tr P_jk`` (n, n)."""
        s = np.asarray(self.second_moment)[1:, 1:]
        return np.einsum("jkaa->jk", s)

    @property
    def com(self) -> np.ndarray:
        """Centre of mass of the undeformed body (frame axes)."""
        return np.asarray(self.first_moment[0]) / self.mass

    @property
    def inertia(self) -> np.ndarray:
        """Inertia tensor of the undeformed body about its centre of mass (frame axes)."""
        p00 = np.asarray(self.second_moment[0, 0])
        c = self.com
        w = p00 - self.mass * np.outer(c, c)
        return np.trace(w) * np.eye(3) - w

    def to_dict(self) -> Dict[str, Any]:
        """The description entries of the body (without name and state)."""
        d: Dict[str, Any] = {"mass": float(self.mass), "first_moment": np.asarray(self.first_moment, float).tolist(),
                             "second_moment": np.asarray(self.second_moment, float).reshape(-1, 3, 3).tolist(),
                             "k_ff": np.asarray(self.k_ff, float).tolist(),
                             "interfaces": [f.to_dict() for f in self.interfaces.values()]}
        if self.d_ff is not None:
            d["d_ff"] = np.asarray(self.d_ff, float).tolist()
        if self.geometric_stiffness is not None:
            d["geometric_stiffness"] = np.asarray(self.geometric_stiffness, float).tolist()
        if self.quadratic_strain is not None:
            d["quadratic_strain"] = np.asarray(self.quadratic_strain, float).tolist()
            d["quadratic_strain_quartic"] = np.asarray(self.quadratic_strain_quartic, float).tolist()
        return d


def bar_mesh(length: float, width: float, height: float, cells: Sequence[int] = (20, 2, 2), kind: str = "tet") -> Any:
    """A bar ``[0, length] x [-width/2, width/2] x [-height/2, height/2]`` meshed with
    ``cells = (nx, ny, nz)`` boxes, split into tetrahedra (``kind="tet"``) or kept as hexahedra."""
    skfem = require("skfem", "ukflex.fe3.bar_mesh", extra="fe")
    length, width, height = positive("length", length), positive("width", width), positive("height", height)
    nx, ny, nz = (count("cells", c) for c in cells)
    axes = (np.linspace(0.0, length, nx + 1), np.linspace(-width / 2, width / 2, ny + 1), np.linspace(-height / 2, height / 2, nz + 1))
    if kind == "tet":
        return skfem.MeshTet.init_tensor(*axes)
    if kind == "hex":
        return skfem.MeshHex.init_tensor(*axes)
    raise InvalidArgumentError("kind", f"expected 'tet' or 'hex', got {kind!r}")


def _mesh(mesh: Any) -> Any:
    """A scikit-fem 3D mesh from a scikit-fem mesh, a meshio mesh or a meshio-readable file."""
    skfem = require("skfem", "ukflex.fe3.solid_matrices", extra="fe")
    if isinstance(mesh, (skfem.MeshTet, skfem.MeshHex)):
        return mesh
    if isinstance(mesh, (str, os.PathLike)):
        meshio = require("meshio", "ukflex.fe3 (mesh files)", extra="fe")
        try:
            mesh = meshio.read(mesh)
        except Exception as exc:  # noqa: BLE001 - meshio raises many kinds
            raise InvalidArgumentError("mesh", f"cannot read the mesh file {str(mesh)!r}: {type(exc).__name__}: {exc}") from exc
    if hasattr(mesh, "points") and hasattr(mesh, "cells_dict"):
        pts = np.asarray(mesh.points, dtype=float)
        for key, cls in (("tetra", skfem.MeshTet), ("hexahedron", skfem.MeshHex)):
            if key in mesh.cells_dict:
                cells = np.asarray(mesh.cells_dict[key])
                used = np.unique(cells)
                remap = np.full(pts.shape[0], -1)
                remap[used] = np.arange(used.size)
                return cls(np.ascontiguousarray(pts[used].T), np.ascontiguousarray(remap[cells].T))
        raise InvalidArgumentError("mesh", f"the mesh has no tetra or hexahedron cells (found: {sorted(mesh.cells_dict)})")
    raise InvalidArgumentError("mesh", "expected a scikit-fem MeshTet or MeshHex, a meshio.Mesh or a mesh file")


def _check_cells(mesh: Any) -> None:
    """No degenerate or inverted cell (a zero or negative Jacobian at a cell's centre)."""
    p, t = mesh.p, mesh.t
    x = p[:, t]  # (3, nodes per cell, E)
    if t.shape[0] == 4:
        d = np.einsum("ij...->...ij", x[:, 1:4] - x[:, [0]])
    else:  # hex: the edges from vertex 0 along the three local axes (scikit-fem order)
        d = np.einsum("ij...->...ij", x[:, [1, 3, 4]] - x[:, [0]])
    vol = np.abs(np.linalg.det(d))
    scale = np.max(np.ptp(p, axis=1)) ** 3
    bad = np.nonzero(~(vol > 1e-12 * scale))[0]
    if bad.size:
        raise InvalidArgumentError("mesh", f"cell {int(bad[0])} {t[:, bad[0]].tolist()} is degenerate (zero volume)")


def solid_matrices(mesh: Any, *, density: float, youngs_modulus: float, poisson_ratio: float,
                   order: int = 2) -> Tuple[np.ndarray, sp.csr_matrix, sp.csr_matrix]:
    """Node coordinates (N, 3), stiffness ``K`` (3N x 3N, node-major dofs) and scalar mass
    ``M_s`` (N x N) of an isotropic linear-elastic solid on ``mesh`` (tetrahedra P1/P2,
    hexahedra Q1/Q2 by ``order``); the nodes are the element's dof locations (vertices, then
    edge, face and cell nodes)."""
    s = _solid(mesh, density=density, youngs_modulus=youngs_modulus, poisson_ratio=poisson_ratio, order=order)
    return s.nodes, s.k, s.ms


@dataclass
class _Solid:
    """The assembled solid: nodes, ``K``, ``M_s``, the scalar scikit-fem basis, the mesh and the
    Lame parameters (what the geometric stiffness and the VTK cells need besides the matrices)."""

    nodes: np.ndarray
    k: sp.csr_matrix
    ms: sp.csr_matrix
    basis: Any
    mesh: Any
    lam: float
    mu: float


def _solid(mesh: Any, *, density: float, youngs_modulus: float, poisson_ratio: float, order: int = 2) -> _Solid:
    skfem = require("skfem", "ukflex.fe3.solid_matrices", extra="fe")
    elasticity = require("skfem.models.elasticity", "ukflex.fe3.solid_matrices", extra="fe")
    lame_parameters = elasticity.lame_parameters

    rho = positive("density", density)
    e = positive("youngs_modulus", youngs_modulus)
    nu = real("poisson_ratio", poisson_ratio)
    if not -1.0 < nu < 0.5:
        raise InvalidArgumentError("poisson_ratio", f"must lie in (-1, 0.5) for an isotropic solid, got {poisson_ratio!r}")
    if order not in (1, 2) or isinstance(order, bool):
        raise InvalidArgumentError("order", f"order must be 1 or 2, got {order!r}")
    m = _mesh(mesh)
    _check_cells(m)
    if isinstance(m, skfem.MeshTet):
        scalar = skfem.ElementTetP1() if order == 1 else skfem.ElementTetP2()
    else:
        scalar = skfem.ElementHex1() if order == 1 else skfem.ElementHex2()
    basis = skfem.Basis(m, scalar)
    nodes = np.ascontiguousarray(basis.doflocs.T)
    lam, mu = lame_parameters(e, nu)
    # K[(i, a), (j, b)] = lam D_ab + mu D_ba + mu delta_ab sum_c D_cc with the scalar
    # D_ab[i, j] = int d_a phi_i d_b phi_j (the isotropic law on scalar blocks: much faster than
    # scikit-fem's vector form, the same matrix)
    d = {}
    for a_ in range(3):
        for b_ in range(a_, 3):
            form = skfem.BilinearForm(lambda u, v, w, a_=a_, b_=b_: v.grad[a_] * u.grad[b_])
            d[a_, b_] = skfem.asm(form, basis).tocsr()
            d[b_, a_] = d[a_, b_].T.tocsr()
    lap = d[0, 0] + d[1, 1] + d[2, 2]
    k = sp.csr_matrix((3 * nodes.shape[0],) * 2)
    for a_ in range(3):
        for b_ in range(3):
            block = lam * d[a_, b_] + mu * d[b_, a_] + (mu * lap if a_ == b_ else 0)
            e_ab = sp.csr_matrix(([1.0], ([a_], [b_])), shape=(3, 3))
            k = k + sp.kron(block, e_ab, format="csr")
    ms = skfem.asm(skfem.BilinearForm(lambda u, v, w: rho * u * v), basis).tocsr()
    return _Solid(nodes, k, ms, basis, m, float(lam), float(mu))


def _select(name: str, spec: InterfaceSpec, nodes: np.ndarray) -> np.ndarray:
    """The node indices of an interface: a node index, indices, a boolean mask, a callable
    ``select(nodes (N, 3)) -> mask``, or ``{"point": (x, y, z)}`` (the node there)."""
    n = nodes.shape[0]
    size = float(np.max(np.ptp(nodes, axis=0)))
    if callable(spec):
        spec = np.asarray(spec(nodes))
    if isinstance(spec, Mapping):
        if set(spec) != {"point"}:
            raise InvalidArgumentError("interfaces", f"interface {name!r}: a dict must be {{'point': (x, y, z)}}, got keys {sorted(spec)}")
        pt = np.asarray(spec["point"], dtype=float).reshape(-1)
        if pt.size != 3 or not np.all(np.isfinite(pt)):
            raise InvalidArgumentError("interfaces", f"interface {name!r}: point must be 3 finite numbers, got {spec['point']!r}")
        dist = np.linalg.norm(nodes - pt, axis=1)
        i = int(np.argmin(dist))
        if dist[i] > 1e-9 * size:
            raise InvalidArgumentError("interfaces", f"interface {name!r}: the mesh has no node at {pt.tolist()} "
                                       f"(nearest node {i} at {nodes[i].tolist()}, {dist[i]:.3g} away): markers sit on nodes")
        return np.array([i])
    a = np.asarray(spec)
    if a.dtype == bool:
        if a.shape != (n,):
            raise InvalidArgumentError("interfaces", f"interface {name!r}: a mask needs one entry per node ({n}), got shape {a.shape}")
        idx = np.nonzero(a)[0]
    else:
        if a.dtype.kind not in "iu" or a.size == 0:
            raise InvalidArgumentError("interfaces", f"interface {name!r}: expected node indices, a mask, a selector or {{'point': ...}}, got {spec!r}")
        idx = np.unique(a.reshape(-1))
    if idx.size == 0:
        raise InvalidArgumentError("interfaces", f"interface {name!r} selects no node")
    if idx.min() < 0 or idx.max() >= n:
        raise InvalidArgumentError("interfaces", f"interface {name!r}: node indices must lie in 0..{n - 1}")
    return idx


def _interface_rows(nodes: np.ndarray, idx: np.ndarray) -> Tuple[np.ndarray, sp.csr_matrix, Optional[sp.csr_matrix]]:
    """Centroid, and the rows (3 x 3N) of the mean displacement and (sets) the least-squares
    rotation of the node set ``idx``."""
    n3 = 3 * nodes.shape[0]
    c = nodes[idx].mean(axis=0)
    k = idx.size
    rows = np.repeat(np.arange(3), k)
    cols = (3 * idx[None, :] + np.arange(3)[:, None]).ravel()
    disp = sp.csr_matrix((np.full(3 * k, 1.0 / k), (rows, cols)), shape=(3, n3))
    if k == 1:
        return c, disp, None
    d = nodes[idx] - c
    h = np.sum(d * d) * np.eye(3) - d.T @ d
    if np.linalg.matrix_rank(h, tol=1e-10 * np.trace(h)) < 3:
        raise InvalidArgumentError("interfaces", "a node set on a line has no least-squares rotation about its axis; select a face")
    hinv = np.linalg.inv(h)
    # sum_i d_i x u_i = sum_i ~d_i u_i
    blocks = np.zeros((3, n3))
    for i, di in zip(idx, d):
        blocks[:, 3 * i:3 * i + 3] = np.array([[0, -di[2], di[1]], [di[2], 0, -di[0]], [-di[1], di[0], 0]])
    return c, disp, sp.csr_matrix(hinv @ blocks)


def _eigs(k: sp.spmatrix, m: sp.spmatrix, count_: int) -> Tuple[np.ndarray, np.ndarray]:
    """The ``count_`` lowest eigenpairs of ``K x = lam M x`` (shift-invert about a small negative
    shift, so that rigid-body modes are found as well)."""
    shift = -1e-6 * float(k.diagonal().mean() / m.diagonal().mean())
    with np.errstate(all="ignore"):
        lam, x = spla.eigsh(k.tocsc(), k=count_, M=m.tocsc(), sigma=shift, which="LM")
    order = np.argsort(lam)
    lam, x = lam[order], x[:, order]
    if not (np.all(np.isfinite(lam)) and np.all(np.isfinite(x))):
        raise InvalidArgumentError("youngs_modulus", "the eigenproblem has no finite solution: masses or stiffnesses out of double-precision range?")
    return lam, x


def _mode_numbers(modes: Any) -> Tuple[int, np.ndarray]:
    """``from_mesh``'s ``modes``: how many of the lowest normal modes to compute, and the numbers
    of those kept (a count: all of them; a sequence: its numbers, 0-based and ascending)."""
    if not isinstance(modes, (Sequence, np.ndarray)) or isinstance(modes, (str, bytes)):
        n = count("modes", modes)
        return n, np.arange(n)
    items = list(np.asarray(modes, dtype=object).ravel())
    whole = all(isinstance(m, (int, np.integer)) and not isinstance(m, (bool, np.bool_)) and m >= 0 for m in items)
    numbers = [int(m) for m in items] if whole else []
    if not numbers or any(b <= a for a, b in zip(numbers, numbers[1:])):
        raise InvalidArgumentError("modes", f"expected a count or mode numbers (integers >= 0, ascending), got {modes!r}")
    return numbers[-1] + 1, np.asarray(numbers)


def _held(frame: Any, names: List[str]) -> Optional[str]:
    """The interface a frame holds (``None``: the mean axes), its words those of every FFRF body."""
    words = frame_interfaces(frame, names, accepted=("mean-axis", "clamped"))
    if words is None:
        raise InvalidArgumentError("frame", f"unknown frame {frame!r}; a 3D body's frame is 'mean-axis' or 'clamped' "
                                   "(('clamped', NAME): that interface held)")
    return words[1][0] if words[0] == "clamped" else None


# one BLAS thread: the build's many small dense blocks (SuperLU's supernodes, ARPACK's steps) ran
# 2-15x slower with two threads on a loaded 2-core machine (docs/spatial-flexible.md, the default rod)
@single_blas_thread()
def from_mesh(mesh: Any, *, density: float, youngs_modulus: float, poisson_ratio: float,
              interfaces: Mapping[str, InterfaceSpec], modes: Union[int, Sequence[int]] = 8, frame: Any = "mean-axis",
              reduction: str = "modes", order: int = 2, damping_ratio: float = 0.0,
              stress_stiffening: bool = False, quadratic_strain: bool = False) -> FlexibleData3:
    """The ``flexible3`` body of an FE solid reduced to ``modes`` normal modes (module docs):
    the lowest ``modes``, or, a sequence, the normal modes of those numbers (0-based, ascending,
    in the spectrum of the free-free modes after the six rigid ones, or of the fixed-interface
    modes; ``info["mode_numbers"]``), e.g. the lowest few and an axial mode. ``interfaces``: name -> node index, indices, mask, ``select(nodes) -> mask`` or
    ``{"point": (x, y, z)}`` (a node must sit there). ``frame``: ``"mean-axis"`` or
    ``"clamped"`` (``("clamped", NAME)``: that interface held); ``reduction``: ``"modes"`` or
    ``"craig-bampton"`` (module docs). ``damping_ratio``: modal damping of the kept modes.
    ``stress_stiffening``: also the modal geometric stiffness of the unit inertia load cases
    (:mod:`ukflex.model.fe3_stiffening`; a clamped frame: the solid carries the loads held at
    its frame's interface), stored as ``geometric_stiffness`` (12, n, n). ``quadratic_strain``:
    the Green-Lagrange strain's cubic and quartic energy, stored as ``quadratic_strain``
    (n, n, n) and ``quadratic_strain_quartic`` (n^2, n^2) (module docs); not with ``stress_stiffening`` (both would count the stress the modes carry)."""
    zeta = non_negative("damping_ratio", damping_ratio)
    nmodes, keep = _mode_numbers(modes)
    for name, flag in (("stress_stiffening", stress_stiffening), ("quadratic_strain", quadratic_strain)):
        if not isinstance(flag, bool):
            raise InvalidArgumentError(name, f"expected True or False, got {flag!r}")
    if stress_stiffening and quadratic_strain:
        raise InvalidArgumentError("quadratic_strain", "quadratic_strain and stress_stiffening together would count the inertia "
                                   "loads' stress twice (the modes carry it); choose one (docs/spatial-flexible.md, 'Quadratic strain')")
    solid = _solid(mesh, density=density, youngs_modulus=youngs_modulus, poisson_ratio=poisson_ratio, order=order)
    nodes, k, ms = solid.nodes, solid.k, solid.ms
    n3 = 3 * nodes.shape[0]
    if not isinstance(interfaces, Mapping):
        raise InvalidArgumentError("interfaces", f"expected a dict name -> nodes, got {type(interfaces).__name__}")
    sets = {name: _select(name, spec, nodes) for name, spec in interfaces.items()}
    rows = {name: _interface_rows(nodes, idx) for name, idx in sets.items()}
    mfull = sp.kron(ms, sp.eye(3), format="csr")
    reference = _held(frame, list(sets))
    if reduction not in REDUCTIONS:
        raise InvalidArgumentError("reduction", f"unknown reduction {reduction!r}; expected one of {list(REDUCTIONS)}")
    if reduction == "craig-bampton" and reference is None:
        raise InvalidArgumentError("reduction", "the craig-bampton reduction needs a clamped frame (an interface held)")
    if quadratic_strain and reference is None:
        raise InvalidArgumentError("quadratic_strain", "the quadratic strain needs a clamped frame (('clamped', NAME)): the "
                                   "displacement outside the basis is condensed on the solid held at its frame's interface")
    if stress_stiffening and reference is None:
        raise InvalidArgumentError("stress_stiffening", "stress stiffening needs a clamped frame (('clamped', NAME)): the "
                                   "inertia loads are carried by the solid held at its frame's interface")
    if reference is None:
        if nmodes + 6 >= n3:
            raise InvalidArgumentError("modes", f"{nmodes} modes do not fit a model with {n3} dofs")
        lam, x = _eigs(k, mfull, nmodes + 6)
        if lam[5] > 1e-6 * lam[6]:
            raise InvalidArgumentError("mesh", f"the free part does not have six rigid-body modes (eigenvalues {lam[:7].tolist()}): is the mesh connected?")
        basis, normal = x[:, 6:][:, keep], lam[6:][keep]
    else:
        held = held_mask(sets, reference, n3)
        boundary = []
        if reduction == "craig-bampton":
            for name, idx in sets.items():
                if name == reference:
                    continue
                mask = np.zeros(n3, dtype=bool)
                for i in idx:
                    mask[3 * i:3 * i + 3] = True
                boundary.append((name, idx, mask))
        fixed = held.copy()
        for _, _, mask in boundary:
            fixed |= mask
        free = np.nonzero(~fixed)[0]
        if nmodes >= free.size:
            raise InvalidArgumentError("modes", f"{nmodes} modes do not fit: only {free.size} free dofs")
        kff, mff = k[free][:, free], mfull[free][:, free]
        lam, xf = _eigs(kff, mff, nmodes)
        lam, xf = lam[keep], xf[:, keep]
        normal_x = np.zeros((n3, keep.size))
        normal_x[free] = xf
        static = []
        if boundary:
            lu = spla.splu(kff.tocsc())
            for name, idx, mask in boundary:
                c = nodes[idx].mean(axis=0)
                for r in range(6):
                    u = np.zeros(n3)
                    for i in idx:
                        if r < 3:
                            u[3 * i + r] = 1.0
                        else:
                            e = np.zeros(3)
                            e[r - 3] = 1.0
                            u[3 * i:3 * i + 3] = np.cross(e, nodes[i] - c)
                    u[free] = -lu.solve(k[free][:, np.nonzero(mask)[0]] @ u[mask])
                    static.append(u)
        basis = np.column_stack(static + [normal_x]) if static else normal_x
        normal = lam
    data = _reduced(nodes, k, ms, basis, rows, sets, normal, zeta)
    data.info["mode_numbers"] = keep.tolist()
    data.info["cells"] = _vtk_cells(solid.mesh)
    data.info["stress_modes"] = stress_modes(solid, basis)
    if stress_stiffening:
        data.geometric_stiffness, data.info["load_displacements"] = geometric_stiffness(solid, held_mask(sets, reference, n3), basis)
    if quadratic_strain:
        data.quadratic_strain, data.quadratic_strain_quartic = _quadratic_strain(solid, basis, held_mask(sets, reference, n3))
    return data


def _vtk_cells(mesh: Any) -> Tuple[str, np.ndarray]:
    """The mesh's cells on the vertex nodes in VTK's order (meshio's cell type and indices): the
    vertices are the first nodes of every element space, numbered as the mesh's points."""
    to_meshio = require("skfem.io.meshio", "ukflex.fe3 (VTK cells)", extra="fe").to_meshio
    block = to_meshio(mesh).cells[0]
    return block.type, np.asarray(block.data, dtype=np.int64)


def _reduced(nodes: np.ndarray, k: sp.spmatrix, ms: sp.spmatrix, basis: np.ndarray, rows: Dict[str, Any],
             sets: Dict[str, np.ndarray], normal: np.ndarray, zeta: float) -> FlexibleData3:
    """Invariants, stiffness, damping and interfaces of the basis (3N, n)."""
    n_nodes = nodes.shape[0]
    n = basis.shape[1]
    # extended shapes X_a (N, 3): u0 then the modes; flat (N, 3 (n + 1))
    xs = np.concatenate([nodes[:, None, :], basis.T.reshape(n, n_nodes, 3).transpose(1, 0, 2)], axis=1)
    flat = xs.reshape(n_nodes, 3 * (n + 1))
    z = ms @ flat
    second = (flat.T @ z).reshape(n + 1, 3, n + 1, 3).transpose(0, 2, 1, 3)
    second = 0.5 * (second + second.transpose(1, 0, 3, 2))
    ones = np.ones(n_nodes)
    mass = float(ones @ (ms @ ones))
    first = (ones @ z).reshape(n + 1, 3)
    k_ff = basis.T @ (k @ basis)
    k_ff = 0.5 * (k_ff + k_ff.T)
    m_ff = np.einsum("jkaa->jk", second[1:, 1:])
    d_ff = None
    if zeta > 0.0:
        import scipy.linalg as sla

        lam_r, v = sla.eigh(k_ff, m_ff)
        mv = m_ff @ v
        d_ff = mv @ np.diag(2.0 * zeta * np.sqrt(np.maximum(lam_r, 0.0))) @ mv.T
        d_ff = 0.5 * (d_ff + d_ff.T)
    ifaces = {}
    for name, (c, disp, rot) in rows.items():
        ifaces[name] = Interface3(tuple(float(x) for x in c), np.asarray((disp @ basis).T), None if rot is None else np.asarray((rot @ basis).T), sets[name])
    info = {"frequencies": np.sqrt(np.maximum(normal, 0.0)) / (2 * np.pi), "modes": basis, "nodes": nodes}
    return FlexibleData3(mass=mass, first_moment=first, second_moment=second, k_ff=k_ff, d_ff=d_ff, interfaces=ifaces, info=info)
