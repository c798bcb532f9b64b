"""Flexible bodies from finite-element data: the invariants of :class:`ukflex.FlexibleData`
computed from a planar FE model reduced to a few modes (docs/flexible-bodies.md).

* :func:`from_nodal` -- node coordinates and assembled nodal mass and stiffness matrices (two
  translations per node, dof order ``x_1, y_1, x_2, ...``; consistent or lumped mass of the form
  ``m (x) I_2``, as every isotropic continuum element gives);
* :func:`from_mesh` -- a planar mesh (points + triangles or quads, or any meshio-readable file)
  assembled by scikit-fem as a plane-stress part of given thickness, density, Young's modulus
  and Poisson's ratio (optional extra ``fe``: ``pip install scikit-fem meshio``).

Interfaces (where joints attach) are nodes or rigid averages of several nodes (RBE3-like: the
point is their centroid, its displacement their mean displacement, its rotation their mean
rotation about it).  The floating frame (``frame``) uses the vocabulary of every FFRF body
(:data:`FRAMES`, the core's; the beams of :meth:`ukflex.Scene.beam` take the first two):

* ``"pinned-pinned"`` -- the chord frame of two interfaces ``A``, ``B``
  (``("pinned-pinned", "A", "B")``; the word alone: the first two, in the order given): ``A``
  fixed in x and y, ``B``'s displacement across the line ``AB`` zero (a beam's
  ``u_1 = v_1 = v_N+1 = 0``);
* ``"clamped"`` -- an interface (``("clamped", "A")``; the word alone: the first) fixed in x, y
  and rotation (a beam's ``u_1 = v_1 = psi_1 = 0``; the interface needs several nodes to have a
  rotation);
* ``"mean-axis"`` (default) -- free-free eigenmodes without the three rigid-body modes (the
  floating frame then satisfies the mean-axis conditions ``S_bar q = 0``, ``s_ju0 . q = 0``);
* three explicit reference conditions ``[(interface, "x"|"y"|"rotation"), ...]``.

Reduction (``reduction``): ``"modes"`` (default) keeps the eigenmodes of the model with the
frame's reference conditions; ``"craig-bampton"`` (a frame with reference conditions) takes the
remaining dofs of the interfaces as boundary: static constraint modes for each of them and
fixed-interface normal modes.

``modes`` is the number of normal modes kept; ``damping_ratio`` gives modal damping.
"""

from __future__ import annotations

import os
import reprlib
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import scipy.linalg as sla

from ..arguments import count, non_negative, positive, real, real_array
from ..errors import InvalidArgumentError, core, require
from .flexible import FlexibleData, InterfacePoint

__all__ = ["from_nodal", "from_mesh", "plane_stress_mesh_matrices", "reduce", "FRAMES", "REDUCTIONS"]

#: The floating-frame options (the core's vocabulary, shared with :meth:`ukflex.Scene.beam`).
FRAMES: Tuple[str, ...] = tuple(core.frame_options())
#: The reductions of :func:`from_nodal` / :func:`from_mesh`.
REDUCTIONS: Tuple[str, ...] = ("modes", "craig-bampton")
_AXES = ("x", "y", "rotation")

Interface = Union[int, Sequence[int]]
Frame = Union[str, Sequence[Tuple[str, str]]]


def _indices(name: str, value: Any, n: int, what: str) -> np.ndarray:
    """``value`` as an array of whole numbers in ``0..n-1`` (integral floats accepted; 2.5, -1,
    strings and out-of-range indices refused, naming ``name``)."""
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(name, f"expected {what} (whole numbers), got {reprlib.repr(value)} ({exc})") from None
    if raw.dtype.kind not in "iuf" or raw.size == 0:
        raise InvalidArgumentError(name, f"expected {what} (whole numbers), got {raw.dtype} values {reprlib.repr(value)}")
    if raw.dtype.kind == "f" and not np.all(np.isfinite(raw) & (raw == np.round(raw))):
        bad = raw[~(np.isfinite(raw) & (raw == np.round(raw)))]
        raise InvalidArgumentError(name, f"{what} must be whole numbers, got {bad[:8].tolist()}")
    outside = raw[(raw < 0) | (raw >= n)]
    if outside.size:
        raise InvalidArgumentError(name, f"{what} {outside[:8].tolist()} are not nodes of the mesh (0..{n - 1})")
    return raw.astype(np.int64)


def _eigh(k: np.ndarray, m: np.ndarray, **options: Any) -> Any:
    """``scipy.linalg.eigh(k, m, **options)`` whose results must be finite and complete: masses or
    stiffnesses beyond what double precision can resolve (a density of 1e-300 kg/m^3) are an
    :class:`InvalidArgumentError`, not an empty or NaN basis further on."""
    expected = None
    if "subset_by_index" in options:
        lo, hi = options["subset_by_index"]
        expected = hi - lo + 1
    scales = f"max |K| = {np.max(np.abs(k)) if k.size else 0.0:.3g}, max |M| = {np.max(np.abs(m)) if m.size else 0.0:.3g}"
    try:
        with np.errstate(all="ignore"):
            out = sla.eigh(k, m, **options)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise InvalidArgumentError("stiffness_matrix", f"the eigenproblem of the part cannot be solved ({exc}; {scales}): "
                                   "masses or stiffnesses out of double-precision range? check the units") from None
    lam = out if options.get("eigvals_only") else out[0]
    arrays = (out,) if options.get("eigvals_only") else out
    if (expected is not None and lam.size != expected) or lam.size == 0 or not all(np.all(np.isfinite(a)) for a in arrays):
        raise InvalidArgumentError("stiffness_matrix", f"the eigenproblem of the part has no finite solution ({scales}): "
                                   "masses or stiffnesses out of double-precision range? check the units")
    return out


def _interface_rows(nodes: np.ndarray, spec: Interface) -> Tuple[Tuple[float, float], np.ndarray, Optional[np.ndarray]]:
    """Point, displacement rows (2, 2N) and rotation row (2N,) of an interface (one node or the
    rigid average of several)."""
    ndof = 2 * nodes.shape[0]
    idx = np.atleast_1d(_indices("interfaces", spec, nodes.shape[0], "interface nodes")).ravel()
    c = nodes[idx].mean(axis=0)
    d = np.zeros((2, ndof))
    for i in idx:
        d[0, 2 * i] += 1.0 / idx.size
        d[1, 2 * i + 1] += 1.0 / idx.size
    if idx.size == 1:
        return (float(c[0]), float(c[1])), d, None
    r = nodes[idx] - c
    r2 = float(np.sum(r * r))
    rot = np.zeros(ndof)
    for i, (rx, ry) in zip(idx, r):
        rot[2 * i] += -ry / r2
        rot[2 * i + 1] += rx / r2
    return (float(c[0]), float(c[1])), d, rot


def _scalar_mass(mm: np.ndarray) -> np.ndarray:
    m = mm[0::2, 0::2]
    scale = np.max(np.abs(mm))
    if (np.max(np.abs(mm[1::2, 1::2] - m)) > 1e-10 * scale or np.max(np.abs(mm[0::2, 1::2])) > 1e-10 * scale):
        raise InvalidArgumentError("mass_matrix", "the mass matrix must act alike on x and y (m (x) I_2, dof order x_1, y_1, x_2, ...): "
                         "give a consistent or lumped mass of a planar continuum")
    return m


def frame_interfaces(frame: Any, names: List[str], accepted: Sequence[str] = FRAMES) -> Optional[Tuple[str, List[str]]]:
    """``(word, interfaces)`` of a frame given by a word of :data:`FRAMES` among ``accepted``, or
    by ``(word, NAME, ...)``: on those interfaces (the word alone: the first ones it needs; the
    mean axes need none); ``None`` when ``frame`` is not a word (explicit reference conditions)."""
    word, on = frame, None
    if not isinstance(frame, str) and isinstance(frame, (tuple, list)) and frame and isinstance(frame[0], str):
        word, on = frame[0], list(frame[1:])  # ("pinned-pinned", "A", "B"), ("clamped", "A")
    if not isinstance(word, str):
        return None
    if word not in FRAMES:
        more = " or three (interface, 'x'|'y'|'rotation') reference conditions" if set(accepted) == set(FRAMES) else ""
        raise InvalidArgumentError("frame", f"unknown frame {word!r}; expected one of {list(accepted)}{more}")
    if word not in accepted:
        raise InvalidArgumentError("frame", f"frame {word!r} is a planar body's; here the frame is one of {list(accepted)}")
    need = {"mean-axis": 0, "clamped": 1, "pinned-pinned": 2}[word]
    if on is None:
        if len(names) < need:
            raise InvalidArgumentError("frame", f"frame {word!r} is defined on the first {need} interface(s); the body "
                                       f"has {len(names)}")
        return word, names[:need]
    if len(on) != need or any(nm not in names for nm in on):
        raise InvalidArgumentError("frame", f"frame {word!r} is defined on {need} interface(s) of {names}, got {on}")
    return word, on


def _reference_rows(frame: Any, iface: Dict[str, Any]) -> Optional[np.ndarray]:
    """The rows ``c`` (3, 2N) of the frame's reference conditions ``c u = 0`` (``None``: the mean
    axes), checked independent."""
    words = frame_interfaces(frame, list(iface))
    if words is not None:
        frame, names = words
        if frame == "mean-axis":
            return None
        (pa, da, ra) = iface[names[0]]
        if frame == "clamped":
            if ra is None:
                raise InvalidArgumentError("frame", f"frame 'clamped' fixes the rotation of interface {names[0]!r}, which is a "
                                           "single node (no rotation): give it several nodes")
            return np.vstack([da, ra])
        pb, db, _ = iface[names[1]]
        chord = np.subtract(pb, pa)
        length = float(np.hypot(*chord))
        if length <= 0.0:
            raise InvalidArgumentError("frame", f"frame 'pinned-pinned': interfaces {names[0]!r} and {names[1]!r} are at the "
                                       "same point (no chord)")
        cx, cy = chord / length
        return np.vstack([da, -cy * db[0] + cx * db[1]])
    try:
        entries = [tuple(e) for e in frame]
    except TypeError:
        entries = []
    if len(entries) != 3 or any(len(e) != 2 for e in entries):
        raise InvalidArgumentError("frame", f"expected one of {list(FRAMES)} or three (interface, 'x'|'y'|'rotation') "
                                   f"reference conditions, got {reprlib.repr(frame)}")
    rows = []
    for name, ax in entries:
        if name not in iface or ax not in _AXES:
            raise InvalidArgumentError("frame", f"reference condition ({name!r}, {ax!r}): expected an interface name "
                                       f"{list(iface)} and one of {list(_AXES)}")
        _, d, rot = iface[name]
        if ax == "rotation" and rot is None:
            raise InvalidArgumentError("frame", f"reference condition ({name!r}, 'rotation'): the interface is a single node "
                                       "(no rotation)")
        rows.append(rot if ax == "rotation" else d[_AXES.index(ax)])
    c = np.array(rows)
    if np.linalg.matrix_rank(c) < 3:
        raise InvalidArgumentError("frame", f"the reference conditions {entries} are not independent (they do "
                                   "not fix the three rigid-body motions of the frame)")
    return c


def from_nodal(
    nodes: np.ndarray,
    mass_matrix: np.ndarray,
    stiffness_matrix: np.ndarray,
    *,
    interfaces: Mapping[str, Interface],
    modes: int = 4,
    frame: Frame = "mean-axis",
    reduction: str = "modes",
    damping_ratio: float = 0.0,
) -> FlexibleData:
    """A :class:`FlexibleData` from nodal coordinates (N, 2) and the assembled mass and stiffness
    matrices (2N, 2N) of a planar FE model (see the module docs for ``frame`` and ``reduction``).

    The returned data carries ``info["frequencies"]`` (rad/s, the kept normal modes; for
    Craig-Bampton those of the reduced model) and ``info["modes"]`` (2N, n_f), the nodal shapes.
    """
    x = real_array("nodes", nodes)
    mm = real_array("mass_matrix", mass_matrix)
    kk = real_array("stiffness_matrix", stiffness_matrix)
    modes = count("modes", modes)
    damping_ratio = non_negative("damping_ratio", damping_ratio)
    if not isinstance(interfaces, Mapping):
        raise InvalidArgumentError("interfaces", f"expected a dict name -> node index or indices, got {type(interfaces).__name__}")
    n = 2 * x.shape[0] if x.ndim == 2 else 0
    if x.ndim != 2 or x.shape[1] != 2 or mm.shape != (n, n) or kk.shape != (n, n):
        raise InvalidArgumentError("nodes",
                                   f"nodes must be (N, 2) and the matrices (2N, 2N); got {x.shape}, {mm.shape}, {kk.shape}")
    for name, a in (("mass_matrix", mm), ("stiffness_matrix", kk)):
        if not np.all(np.isfinite(a)):
            raise InvalidArgumentError(name, "has entries that are not finite")
        if np.max(np.abs(a - a.T)) > 1e-10 * max(np.max(np.abs(a)), 1e-300):
            raise InvalidArgumentError(name, "must be symmetric")
    try:
        sla.cholesky(mm, lower=True)
    except np.linalg.LinAlgError:
        raise InvalidArgumentError("mass_matrix", "is not positive definite (a negative or zero nodal mass, or a node "
                                   "without mass)") from None
    m_scalar = _scalar_mass(mm)
    iface = {name: _interface_rows(x, spec) for name, spec in interfaces.items()}
    if reduction not in REDUCTIONS:
        raise InvalidArgumentError("reduction", f"unknown reduction {reduction!r}; expected one of {list(REDUCTIONS)}")
    c = _reference_rows(frame, iface)
    if c is None:
        if reduction != "modes":
            raise InvalidArgumentError("reduction", f"the {reduction} reduction needs a frame with reference conditions "
                                       f"({[f for f in FRAMES if f != 'mean-axis']} or three (interface, axis)), not 'mean-axis'")
        lam, vec = _eigh(kk, mm)
        if modes + 3 > n:
            raise InvalidArgumentError("modes", f"{modes} modes do not fit a model with {n} dofs")
        lam_rigid = lam[:3]
        if np.max(np.abs(lam_rigid)) > 1e-6 * abs(lam[3]):
            raise InvalidArgumentError("stiffness_matrix", "the stiffness matrix does not have the three rigid-body modes of a free planar part "
                             f"(lowest eigenvalues {lam[:4]}): is the part supported or disconnected?")
        phi = vec[:, 3:3 + modes]
        freq = np.sqrt(np.maximum(lam[3:3 + modes], 0.0))
    else:
        if reduction == "craig-bampton":
            rows = [iface[nm][1][k] for nm in iface for k in range(2)]
            rows = [r for r in rows if np.linalg.matrix_rank(np.vstack([c, r])) > np.linalg.matrix_rank(c)]
            b = np.array(rows) if rows else np.zeros((0, n))
        else:
            b = np.zeros((0, n))
        phi = _constrained_basis(kk, mm, c, b, modes)
        kr, mr = phi.T @ kk @ phi, phi.T @ mm @ phi
        lam = _eigh(kr, mr, eigvals_only=True)
        if lam[0] <= 1e-9 * abs(lam[-1]):
            raise InvalidArgumentError("stiffness_matrix", f"the stiffness with the reference conditions of frame {frame!r} is "
                                       f"not positive definite (lowest eigenvalue {lam[0]:.3e}): rigid-body motions left "
                                       "free, a mechanism or a disconnected part, or an indefinite stiffness")
        freq = np.sqrt(np.maximum(lam, 0.0))
    data = _data_from_basis(x, mm, kk, m_scalar, iface, phi, damping_ratio)
    data.info["frequencies"] = freq
    return data


def _data_from_basis(x: np.ndarray, mm: np.ndarray, kk: np.ndarray, m_scalar: np.ndarray, iface: Dict[str, Any],
                     phi: np.ndarray, damping_ratio: float) -> FlexibleData:
    """The flexible body of the nodal model on the basis ``phi`` (2N, n_f)."""
    inv = _invariants(x, mm, m_scalar, phi)
    k_ff = phi.T @ kk @ phi
    k_ff = 0.5 * (k_ff + k_ff.T)
    d_ff = None
    if damping_ratio > 0.0:
        m_ff = inv["m_ff"]
        lam_r, v = _eigh(k_ff, m_ff)
        w = np.sqrt(np.maximum(lam_r, 0.0))
        mv = m_ff @ v
        d_ff = mv @ np.diag(2.0 * damping_ratio * w) @ mv.T
    markers = {name: InterfacePoint(p, d @ phi, None if r is None else r @ phi) for name, (p, d, r) in iface.items()}
    return FlexibleData(k_ff=k_ff, d_ff=d_ff, markers=markers, info={"modes": phi}, **inv)


def _constrained_basis(kk: np.ndarray, mm: np.ndarray, c: np.ndarray, b: np.ndarray, modes: int) -> np.ndarray:
    """Basis (n, n_f) satisfying ``c u = 0``: ``b.shape[0]`` static constraint modes (unit value
    of each boundary row ``b`` with the others zero, the rest statically condensed) followed by
    ``modes`` normal modes with ``c u = 0`` and ``b u = 0``."""
    n = kk.shape[0]
    nb = b.shape[0]
    # null space of all constraints (c and b): interior motions
    cb = np.vstack([c, b]) if nb else c
    z = sla.null_space(cb)
    kz, mz = z.T @ kk @ z, z.T @ mm @ z
    if modes > kz.shape[0]:
        raise InvalidArgumentError("modes", f"{modes} modes do not fit: only {kz.shape[0]} interior dofs")
    lam, v = _eigh(kz, mz, subset_by_index=[0, modes - 1])
    normal = z @ v
    if not nb:
        return normal
    # constraint modes: minimize u K u subject to c u = 0, b u = e_i
    kkt = np.block([[kk, cb.T], [cb, np.zeros((cb.shape[0], cb.shape[0]))]])
    rhs = np.zeros((n + cb.shape[0], nb))
    rhs[n + c.shape[0]:, :] = np.eye(nb)
    static = np.linalg.solve(kkt, rhs)[:n]
    return np.hstack([static, normal])


def _invariants(x: np.ndarray, mm: np.ndarray, m_scalar: np.ndarray, phi: np.ndarray) -> Dict[str, Any]:
    """The inertia invariants from the assembled mass matrix (exact where the element fields
    interpolate rigid motions and ``u0``: ``int rho N^T N dV = M``)."""
    ex = np.zeros(mm.shape[0])
    ex[0::2] = 1.0
    ey = np.zeros(mm.shape[0])
    ey[1::2] = 1.0
    u0 = x.ravel()
    ju0 = np.column_stack([-x[:, 1], x[:, 0]]).ravel()
    mass = float(ex @ mm @ ex)
    com = np.array([ex @ mm @ u0, ey @ mm @ u0]) / mass
    j0 = float(u0 @ mm @ u0)
    tilde = np.kron(m_scalar, np.array([[0.0, 1.0], [-1.0, 0.0]]))
    m_ff = phi.T @ mm @ phi
    return dict(mass=mass, inertia=j0 - mass * float(com @ com), com=(float(com[0]), float(com[1])),
                s_bar=np.vstack([ex @ mm @ phi, ey @ mm @ phi]), s_u0=phi.T @ mm @ u0, s_ju0=phi.T @ mm @ ju0,
                s_tilde=_antisym(phi.T @ tilde @ phi), m_ff=0.5 * (m_ff + m_ff.T))


def _mesh_basis(points: np.ndarray, cells: np.ndarray, order: int) -> Tuple[Any, np.ndarray, np.ndarray]:
    """scikit-fem vector basis of the mesh, the permutation ``perm`` (node dof ``j`` = scikit-fem
    dof ``perm[j]``; node dofs ``x_1, y_1, x_2, ...``) and the node coordinates (N, 2)."""
    skfem = require("skfem", "ukflex.fe.from_mesh", extra="fe")
    if order not in (1, 2) or isinstance(order, bool):
        raise InvalidArgumentError("order", f"order must be 1 (P1/Q1) or 2 (P2/Q2), got {order!r}")
    p, t = _mesh_arrays(points, cells)
    if t.shape[0] == 3:
        mesh = skfem.MeshTri(p, t)
        scalar = skfem.ElementTriP1() if order == 1 else skfem.ElementTriP2()
    elif t.shape[0] == 4:
        mesh = skfem.MeshQuad(p, t)
        scalar = skfem.ElementQuad1() if order == 1 else skfem.ElementQuad2()
    else:
        raise InvalidArgumentError("cells", "cells must be triangles (E, 3) or quadrilaterals (E, 4)")
    basis = skfem.Basis(mesh, skfem.ElementVector(scalar))
    per_node = _node_dofs(basis, order)  # (2, N)
    nodes = np.ascontiguousarray(basis.doflocs[:, per_node[0]].T)
    return basis, per_node.T.ravel(), nodes


def _node_dofs(basis: Any, order: int) -> np.ndarray:
    """The dofs of a (vector or scalar) scikit-fem basis by node, (components, N): vertices,
    then (order 2) edge midpoints, then cell interiors (the node order of :func:`_mesh_basis`)."""
    groups = [basis.nodal_dofs]
    if order == 2:
        groups.append(basis.facet_dofs)
        if getattr(basis, "interior_dofs", None) is not None and basis.interior_dofs.size:
            groups.append(basis.interior_dofs)
    return np.hstack(groups)


def _stress_modes(basis: Any, perm: np.ndarray, phi: np.ndarray, order: int, lam: float, mu: float) -> np.ndarray:
    """Plane-stress stress shapes of the columns of ``phi`` at the nodes, (N, 3, n_f):
    ``sigma_xx, sigma_yy, sigma_xy`` (body frame) of each mode, recovered at the nodes from the
    stresses at the element's superconvergent points (order 2: the 2 x 2 Gauss points of a Q2
    quad, the 3-point rule of a P2 triangle), fitted by the element of one order less (bilinear,
    linear) and evaluated at the element's nodes; order 1: the element's mean stress. Each node
    takes the mean over the elements around it."""
    skfem = require("skfem", "ukflex.fe.from_mesh (stress shapes)", extra="fe")
    elem = basis.elem.elem  # the scalar element
    reduced = skfem.Basis(basis.mesh, basis.elem, intorder=2)  # same dofs, the reduced points
    g, _ = _mode_gradients(reduced, perm, phi)
    sig = _stress(0.5 * (g + np.swapaxes(g, 1, 2)), lam, mu)  # (r, 2, 2, E, Q)
    comps = np.stack([sig[:, 0, 0], sig[:, 1, 1], sig[:, 0, 1]], axis=1)  # (r, 3, E, Q)
    x = np.asarray(reduced.X).T  # (Q, 2) reference coordinates of the points
    local = np.asarray(elem.doflocs, dtype=float)  # (n_loc, 2) reference coordinates of the nodes
    if order == 1:
        fit = np.full((local.shape[0], x.shape[0]), 1.0 / x.shape[0])
    else:
        quad = basis.mesh.t.shape[0] == 4

        def monomials(p: np.ndarray) -> np.ndarray:
            cols = [np.ones(len(p)), p[:, 0], p[:, 1]] + ([p[:, 0] * p[:, 1]] if quad else [])
            return np.column_stack(cols)

        fit = monomials(local) @ np.linalg.inv(monomials(x))  # (n_loc, Q)
    at_nodes = np.einsum("lq,rceq->elcr", fit, comps)  # (E, n_loc, 3, r)
    scalar = basis.with_element(elem)
    node_dofs = _node_dofs(scalar, order)[0]
    node_of = np.empty(scalar.N, dtype=np.int64)
    node_of[node_dofs] = np.arange(node_dofs.size)
    idx = node_of[np.asarray(scalar.element_dofs).T]  # (E, n_loc)
    out = np.zeros((node_dofs.size, 3, phi.shape[1]))
    np.add.at(out, idx.ravel(), at_nodes.reshape(-1, 3, phi.shape[1]))
    return out / np.bincount(idx.ravel(), minlength=node_dofs.size)[:, None, None]


def _mesh_arrays(points: Any, cells: Any) -> Tuple[np.ndarray, np.ndarray]:
    """The mesh as scikit-fem takes it: points (2, N) and cells (3|4, E), checked: finite points
    (N, 2) or (N, 3), cells of whole-number indices of the points, each cell's vertices distinct."""
    p = real_array("points", points)
    if p.ndim != 2 or p.shape[1] not in (2, 3) or p.shape[0] < 3:
        raise InvalidArgumentError("points", f"expected an array (N, 2) or (N, 3) of N >= 3 points, got shape {p.shape}")
    t = _indices("cells", cells, p.shape[0], "cell vertices")
    if t.ndim != 2 or t.shape[1] not in (3, 4):
        raise InvalidArgumentError("cells", f"cells must be triangles (E, 3) or quadrilaterals (E, 4), got shape {t.shape}")
    s = np.sort(t, axis=1)
    repeated = np.flatnonzero(np.any(s[:, 1:] == s[:, :-1], axis=1))
    if repeated.size:
        raise InvalidArgumentError("cells", f"cell {int(repeated[0])} {t[repeated[0]].tolist()} repeats a vertex")
    # every corner of a cell must turn the same way (area > 0 at each, counterclockwise or not):
    # a collinear or folded cell has no valid element map (scikit-fem: "Zero Jacobian determinant")
    xy = p[:, :2][t]  # (E, k, 2)
    e1 = np.roll(xy, -1, axis=1) - xy
    e0 = xy - np.roll(xy, 1, axis=1)
    turn = e0[..., 0] * e1[..., 1] - e0[..., 1] * e1[..., 0]  # (E, k)
    size = np.max(np.abs(xy - xy.mean(axis=1, keepdims=True)), axis=(1, 2)) ** 2
    flat = ~((np.all(turn > 1e-12 * size[:, None], axis=1)) | np.all(turn < -1e-12 * size[:, None], axis=1))
    if np.any(flat):
        k = int(np.flatnonzero(flat)[0])
        raise InvalidArgumentError("cells", f"cell {k} {t[k].tolist()} at {xy[k].tolist()} is degenerate or folded "
                                   "(collinear vertices, zero area or a non-convex corner)")
    return np.ascontiguousarray(p[:, :2].T), np.ascontiguousarray(t.T)


def _material(thickness: Any, density: Any, youngs_modulus: Any, poisson_ratio: Any) -> Tuple[float, float, float, float]:
    """A plane-stress material, checked: positive thickness, density and modulus, Poisson's ratio
    in (-1, 0.5] (0.5: incompressible, which plane stress allows)."""
    nu = real("poisson_ratio", poisson_ratio)
    if not -1.0 < nu <= 0.5:
        raise InvalidArgumentError("poisson_ratio", f"must lie in (-1, 0.5] for an isotropic material, got {poisson_ratio!r}")
    return positive("thickness", thickness), positive("density", density), positive("youngs_modulus", youngs_modulus), nu


def _plane_stress_lame(youngs_modulus: float, poisson_ratio: float) -> Tuple[float, float]:
    """Plane-stress Lame parameters ``(lambda*, mu)``: ``lambda* = E nu / (1 - nu^2)`` (the 3-D
    ``2 lambda mu / (lambda + 2 mu)`` without the 3-D ``lambda``, which is singular at 0.5) and
    ``mu = E / (2 (1 + nu))``."""
    mu = youngs_modulus / (2.0 * (1.0 + poisson_ratio))
    return youngs_modulus * poisson_ratio / (1.0 - poisson_ratio * poisson_ratio), mu


def plane_stress_mesh_matrices(points: np.ndarray, cells: np.ndarray, *, thickness: float, density: float,
                               youngs_modulus: float, poisson_ratio: float,
                               order: int = 1) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Consistent mass and stiffness matrices (2N, 2N; dof order ``x_1, y_1, ...``) of a planar
    mesh of triangles (``cells`` (E, 3)) or quadrilaterals ((E, 4)), plane stress, assembled by
    scikit-fem, and the coordinates (N, 2) of the N nodes.

    ``order=1``: linear triangles / bilinear quads (P1/Q1; the nodes are the mesh points; stiff in
    bending: shear locking).  ``order=2``: quadratic triangles (P2, 6 nodes) / biquadratic quads
    (Q2, 9 nodes), which represent pure bending exactly; the nodes are the mesh points followed by
    the edge midpoints (and, for Q2, the cell centres)."""
    skfem = require("skfem", "ukflex.fe.plane_stress_mesh_matrices", extra="fe")
    dot = require("skfem.helpers", "ukflex.fe.plane_stress_mesh_matrices", extra="fe").dot
    linear_elasticity = require("skfem.models.elasticity", "ukflex.fe.plane_stress_mesh_matrices", extra="fe").linear_elasticity

    thickness, density, youngs_modulus, poisson_ratio = _material(thickness, density, youngs_modulus, poisson_ratio)
    basis, perm, nodes = _mesh_basis(points, cells, order)
    lam_ps, mu = _plane_stress_lame(youngs_modulus, poisson_ratio)
    kk = (thickness * skfem.asm(linear_elasticity(lam_ps, mu), basis)).toarray()

    @skfem.BilinearForm
    def mass(u, v, w):
        return density * thickness * dot(u, v)

    mm = skfem.asm(mass, basis).toarray()
    return mm[np.ix_(perm, perm)], kk[np.ix_(perm, perm)], nodes


#: Fractions of :func:`from_mesh`'s work done after each stage (its ``progress``), measured on a
#: Q2 mesh of 2322 dofs (docs/flexible-bodies.md: 9 % assembly, 91 % the dense eigen solve).
FE_STAGES = {"assembled": 0.1, "reduced": 0.95, "nonlinear": 0.98}


def _is_skfem_mesh(mesh: Any) -> bool:
    return type(mesh).__module__.split(".")[0] == "skfem" and hasattr(mesh, "p") and hasattr(mesh, "t")


def _mesh_input(mesh: Any, cells: Any) -> Tuple[Any, Any]:
    """Points (N, 2|3) and cells (E, 3|4) of what :func:`from_mesh` takes: points with
    ``cells``, a mesh file (read by meshio), a ``meshio.Mesh`` (every triangle block, or every
    quad block, joined) or a planar scikit-fem mesh (its vertices ``p`` and cells ``t``)."""
    if cells is not None:
        return mesh, cells
    if isinstance(mesh, (str, os.PathLike)):
        meshio = require("meshio", "ukflex.fe.from_mesh (reading a mesh file)", extra="fe")
        try:
            mesh = meshio.read(mesh)
        except Exception as exc:  # meshio's ReadError, a missing file, ...
            raise InvalidArgumentError("mesh", f"cannot read the mesh file {str(mesh)!r}: {type(exc).__name__}: {exc}") from exc
    if _is_skfem_mesh(mesh):
        p, t = np.asarray(mesh.p), np.asarray(mesh.t)
        if p.ndim != 2 or p.shape[0] != 2 or t.ndim != 2 or t.shape[0] not in (3, 4):
            raise InvalidArgumentError("mesh", f"expected a planar scikit-fem mesh of triangles or quads (MeshTri, "
                                       f"MeshQuad), got {type(mesh).__name__} with p {p.shape}, t {t.shape}")
        # a quadratic-geometry mesh (MeshTri2, MeshQuad2) lists its vertices first, then the
        # edge (and cell) points its cells do not index: the part is meshed with straight edges
        nv = int(t.max()) + 1
        return p[:, :nv].T, t.T
    if not hasattr(mesh, "cells") or not hasattr(mesh, "points"):
        raise InvalidArgumentError("mesh", "expected a mesh file, a meshio.Mesh, a scikit-fem mesh (MeshTri, MeshQuad) "
                                   f"or points with cells=, got {type(mesh).__name__}")
    kinds = sorted({c.type for c in mesh.cells if c.type in ("triangle", "quad")})
    if not kinds:
        raise InvalidArgumentError("mesh", "the mesh has no triangle or quad cells (found: "
                                   f"{sorted({c.type for c in mesh.cells})})")
    if len(kinds) > 1:
        raise InvalidArgumentError("mesh", "the mesh mixes triangles and quads; give one kind of cell")
    return mesh.points, np.vstack([np.asarray(c.data) for c in mesh.cells if c.type == kinds[0]])


def from_mesh(mesh: Any, *, thickness: float, density: float, youngs_modulus: float, poisson_ratio: float,
              interfaces: Mapping[str, Interface], modes: int = 4, frame: Frame = "mean-axis",
              reduction: str = "modes", damping_ratio: float = 0.0,
              cells: Optional[np.ndarray] = None, order: int = 1, strain: str = "linear",
              modal_derivatives: Union[bool, int] = False,
              progress: Optional[Callable[[float], None]] = None) -> FlexibleData:
    """A :class:`FlexibleData` of a planar part meshed with triangles or quads.

    ``mesh``: a path of any meshio-readable file, a ``meshio.Mesh`` (its triangle or quad
    blocks), a planar scikit-fem mesh (``skfem.MeshTri``, ``MeshQuad``; of a quadratic-geometry
    ``MeshTri2``/``MeshQuad2`` the vertices, i.e. straight edges), or a points array (N, 2|3)
    with ``cells``.  A missing scikit-fem or meshio raises :class:`ukflex.MissingDependencyError`.  The part is plane stress of ``thickness``; ``order`` 1 (P1/Q1) or 2 (P2/Q2,
    free of the bending locking of linear elements; see :func:`plane_stress_mesh_matrices`).
    An interface is a node index, a list of them, or a callable taking the (N, 2) node
    coordinates (with ``order=2`` the mid-edge nodes too) and returning a boolean mask or indices
    (e.g. ``lambda p: np.isclose(p[:, 0], 0.0)``: every node of the left edge).  See
    :func:`from_nodal` for the rest.  ``info["points"]``, ``info["cells"]`` keep the mesh,
    ``info["nodes"]`` all nodes (for drawing) and ``info["stress_modes"]`` (N, 3, n_f) the
    plane-stress stress shape of each mode at the nodes (``sigma_xx, sigma_yy, sigma_xy``, body
    frame, recovered from the element's superconvergent points; for
    :func:`ukflex.results.fields.modal_fields` and the VTK export).

    ``strain="nonlinear"``: the body also gets ``k3``, ``k4``, the plane-stress Green-Lagrange
    strain energy ``int t E:C:E / 2 dA`` (``E = (grad u + grad u^T + grad u^T grad u) / 2``)
    restricted to the basis, integrated over the elements (use it with
    ``Scene.flexible_body(..., strain="nonlinear")``).  ``modal_derivatives`` (``True`` or the
    number ``m`` of lowest modes differentiated; needs a frame fixed by reference conditions)
    adds the static modal derivatives of the Green-Lagrange energy, ``K^-1 k3(phi_i, phi_j)``,
    to the basis: without them the bending modes of a slender part cannot shorten and the
    reduced part locks (docs/flexible-bodies.md).

    ``progress``: a callable, as :func:`ukflex.simulate`'s, called with the fraction of the
    build done (in [0, 1]) after each stage: assembly (``FE_STAGES["assembled"]``), the eigen
    solve of the reduction (``"reduced"``), the nonlinear tensors (``"nonlinear"``, with
    ``strain="nonlinear"``) and the stress shapes (1.0).
    """
    if strain not in ("linear", "nonlinear"):
        raise InvalidArgumentError("strain", f"expected 'linear' or 'nonlinear', got {strain!r}")
    if modal_derivatives is not False and strain != "nonlinear":
        raise InvalidArgumentError("modal_derivatives", "modal derivatives need strain='nonlinear'")
    if modal_derivatives is not False and isinstance(frame, str) and frame == "mean-axis":
        raise InvalidArgumentError("modal_derivatives", "modal derivatives need a frame fixed by reference conditions "
                                   "(not frame='mean-axis'): the free-free static problem is singular")
    points, cells = _mesh_input(mesh, cells)
    if not isinstance(interfaces, Mapping):
        raise InvalidArgumentError("interfaces", f"expected a dict name -> node index, indices or selector, got {type(interfaces).__name__}")
    if progress is not None and not callable(progress):
        raise InvalidArgumentError("progress", f"expected a callable progress(fraction) or None, got {type(progress).__name__}")
    done = progress or (lambda fraction: None)
    mm, kk, nodes = plane_stress_mesh_matrices(points, cells, thickness=thickness, density=density,
                                               youngs_modulus=youngs_modulus, poisson_ratio=poisson_ratio, order=order)
    done(FE_STAGES["assembled"])
    resolved = {}
    for name, spec in interfaces.items():
        if callable(spec):
            sel = np.asarray(spec(nodes))
            if sel.dtype == bool and sel.shape != (nodes.shape[0],):
                raise InvalidArgumentError("interfaces", f"interface {name!r}: a boolean selection needs one entry per node "
                                           f"({nodes.shape[0]}), got shape {sel.shape}")
            idx = np.flatnonzero(sel) if sel.dtype == bool else (
                _indices("interfaces", sel, nodes.shape[0], f"interface {name!r} nodes").ravel() if sel.size else sel.ravel())
            if idx.size == 0:
                raise InvalidArgumentError("interfaces",
                                           f"interface {name!r}: the selection matches no node of the mesh")
            resolved[name] = idx
        else:
            resolved[name] = spec
    data = from_nodal(nodes, mm, kk, interfaces=resolved, modes=modes, frame=frame, reduction=reduction,
                      damping_ratio=damping_ratio)
    done(FE_STAGES["reduced"])
    if strain == "nonlinear":
        basis, perm, _ = _mesh_basis(points, cells, order)
        lam_ps, mu = _plane_stress_lame(youngs_modulus, poisson_ratio)
        phi = data.info["modes"]
        if modal_derivatives is not False:
            nd = modes if modal_derivatives is True else count("modal_derivatives", modal_derivatives)
            if not 1 <= nd <= phi.shape[1]:
                raise InvalidArgumentError("modal_derivatives", f"the number of modes differentiated must be in "
                                           f"1..{phi.shape[1]}, got {nd}")
            # the lowest nd normal modes (Craig-Bampton: its reduced model's modes)
            lam_r, v = _eigh(phi.T @ kk @ phi, phi.T @ mm @ phi)
            low = phi @ v[:, :nd]
            loads = _green_lagrange_md_loads(basis, perm, low, thickness, lam_ps, mu)
            iface = {name: _interface_rows(nodes, spec) for name, spec in resolved.items()}
            c = _reference_rows(frame, iface)
            kkt = np.block([[kk, c.T], [c, np.zeros((3, 3))]])
            theta = np.linalg.solve(kkt, np.vstack([loads, np.zeros((3, loads.shape[1]))]))[:kk.shape[0]]
            p = _enrich(np.zeros((kk.shape[0], 0)), np.hstack([phi, theta]), mm, 1e-9)
            lam_e, v = _eigh(p.T @ kk @ p, p.T @ mm @ p)
            phi = p @ v
            freq = np.sqrt(np.maximum(lam_e, 0.0))
            data = _data_from_basis(nodes, mm, kk, _scalar_mass(mm), iface, phi, damping_ratio)
            data.info["frequencies"] = freq
        data.k3, data.k4 = _green_lagrange_tensors(basis, perm, phi, thickness, lam_ps, mu)
        done(FE_STAGES["nonlinear"])
    basis, perm, _ = _mesh_basis(points, cells, order)
    lam_ps, mu = _plane_stress_lame(*_material(thickness, density, youngs_modulus, poisson_ratio)[2:])
    data.info.update(points=points, cells=np.asarray(cells), nodes=nodes,
                     stress_modes=_stress_modes(basis, perm, data.info["modes"], order, lam_ps, mu))
    done(1.0)
    return data


def _mode_gradients(basis: Any, perm: np.ndarray, phi: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Displacement gradients ``G[a, i, j, e, g] = d u_i / d x_j`` of the columns of ``phi``
    (node dofs) at the quadrature points, and the quadrature weights ``dx[e, g]``."""
    out = []
    for a in range(phi.shape[1]):
        u = np.zeros(basis.N)
        u[perm] = phi[:, a]
        out.append(np.asarray(basis.interpolate(u).grad))
    return np.array(out), np.asarray(basis.dx)


def _stress(e: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """Plane-stress ``C : E`` of symmetric tensors ``e[..., 2, 2, e, g]`` (first two of the last
    four axes the tensor's)."""
    tr = e[..., 0, 0, :, :] + e[..., 1, 1, :, :]
    s = 2.0 * mu * e
    s[..., 0, 0, :, :] += lam * tr
    s[..., 1, 1, :, :] += lam * tr
    return s


def _green_lagrange_tensors(basis: Any, perm: np.ndarray, phi: np.ndarray, thickness: float, lam: float,
                            mu: float) -> Tuple[np.ndarray, np.ndarray]:
    """``k3``, ``k4`` of the plane-stress Green-Lagrange strain energy on the basis ``phi``:
    ``U = int t (E_l + E_n) : C : (E_l + E_n) / 2``, ``E_l = sym G q``, ``E_n = (G q)^T (G q) / 2``;
    the cubic part ``int t E_l : C : E_n`` and the quartic ``int t E_n : C : E_n / 2``."""
    g, dx = _mode_gradients(basis, perm, phi)
    w = thickness * dx
    sig = _stress(0.5 * (g + np.swapaxes(g, 1, 2)), lam, mu)  # (r, 2, 2, E, Q)
    h = np.einsum("bkieq,ckjeq->bcijeq", g, g)  # G_b^T G_c
    hs = 0.5 * (h + np.swapaxes(h, 2, 3))
    t3 = 0.5 * np.einsum("aijeq,bcijeq,eq->abc", sig, hs, w)  # symmetric in (b, c)
    k3 = 2.0 * (t3 + np.transpose(t3, (1, 2, 0)) + np.transpose(t3, (2, 0, 1)))
    chs = _stress(hs, lam, mu)
    t4 = 0.125 * np.einsum("abijeq,cdijeq,eq->abcd", hs, chs, w)
    k4 = 8.0 * (t4 + np.transpose(t4, (0, 2, 1, 3)) + np.transpose(t4, (0, 2, 3, 1)))
    return k3, k4


def _green_lagrange_md_loads(basis: Any, perm: np.ndarray, phi: np.ndarray, thickness: float, lam: float,
                             mu: float) -> np.ndarray:
    """Node loads ``k3(., phi_a, phi_b)`` (2N, m (m + 1) / 2), ``a <= b``, of the Green-Lagrange
    energy: ``int t grad N_i : (C:sym(G_a^T G_b) + G_b sigma_a + G_a sigma_b)``."""
    skfem = require("skfem", "ukflex.fe.from_mesh (modal derivatives)", extra="fe")
    helpers = require("skfem.helpers", "ukflex.fe.from_mesh (modal derivatives)", extra="fe")
    ddot, grad = helpers.ddot, helpers.grad

    g, _ = _mode_gradients(basis, perm, phi)
    sig = _stress(0.5 * (g + np.swapaxes(g, 1, 2)), lam, mu)

    @skfem.LinearForm
    def load(v, w):
        return thickness * ddot(grad(v), w["s"])

    cols = []
    m = phi.shape[1]
    for a in range(m):
        for b in range(a, m):
            hab = np.einsum("kieq,kjeq->ijeq", g[a], g[b])
            s = _stress(0.5 * (hab + np.swapaxes(hab, 0, 1)), lam, mu)
            s = s + np.einsum("ikeq,kjeq->ijeq", g[b], sig[a]) + np.einsum("ikeq,kjeq->ijeq", g[a], sig[b])
            cols.append(skfem.asm(load, basis, s=s)[perm])
    return np.array(cols).T


def reduce(data: FlexibleData, modes: int, damping_ratio: float = 0.0, *, modal_derivatives: Union[bool, int] = False,
           tol: float = 1e-9) -> FlexibleData:
    """Reduce a flexible body (e.g. nodal, with its frame fixed by reference conditions) to its
    ``modes`` lowest eigenmodes of ``(K_ff, M_ff)``: every invariant is projected on the basis
    (``k3``/``k4`` too).  ``info["frequencies"]`` holds the frequencies (rad/s) of the reduced
    model, ``info["modes"]`` the basis (n_f of ``data``, n_f of the result); of mesh data
    (:func:`from_mesh`) also the mesh, ``info["nodal_modes"]`` (2N, n_f of the result) and the
    ``stress_modes`` on the new basis (for :mod:`ukflex.results.fields`).

    ``modal_derivatives`` (needs ``k3``, i.e. nonlinear strain data) adds the static modal
    derivatives ``K^-1 k3(phi_i, phi_j)``, ``i <= j``, of the kept modes (``True``) or of the
    ``m`` lowest ones (an int ``m``: ``m (m + 1) / 2`` vectors instead of ``k (k + 1) / 2``); the
    basis is then mass-orthonormalized (vectors it already spans, to ``tol``, dropped) and
    diagonalized.  For beams and slender parts the derivatives carry the axial shortening a
    bending mode needs: without them a basis of bending modes cannot shorten and the quartic
    membrane energy locks it (docs/flexible-bodies.md: 21 % too stiff on the paper's coupler).
    """
    if not isinstance(data, FlexibleData):
        raise InvalidArgumentError("data", f"expected a FlexibleData (from fe.from_nodal, fe.from_mesh or FlexibleData(...)), "
                                   f"got {type(data).__name__}")
    modes = count("modes", modes)
    damping_ratio = non_negative("damping_ratio", damping_ratio)
    tol = positive("tol", tol)
    k, m = np.asarray(data.k_ff, dtype=float), np.asarray(data.m_ff, dtype=float)
    if not 1 <= modes <= k.shape[0]:
        raise InvalidArgumentError("modes", f"modes must be in 1..{k.shape[0]}, got {modes}")
    lam, p = _eigh(k, m, subset_by_index=[0, modes - 1])
    if modal_derivatives is not False:
        if data.k3 is None:
            raise InvalidArgumentError("modal_derivatives", "modal derivatives need the third-order stiffness k3 "
                                       "(nonlinear strain data)")
        nd = modes if modal_derivatives is True else count("modal_derivatives", modal_derivatives)
        if not 1 <= nd <= modes:
            raise InvalidArgumentError("modal_derivatives",
                                       f"the number of modes differentiated must be in 1..{modes}, got {nd}")
        k3p = np.einsum("ijk,jb,kc->ibc", np.asarray(data.k3, dtype=float), p[:, :nd], p[:, :nd])
        extra = [k3p[:, a, b] for a in range(nd) for b in range(a, nd)]
        loads = np.array(extra).T  # (n, n_extra)
        p = _enrich(p, sla.cho_solve(sla.cho_factor(k), loads), m, tol)
        lam, v = _eigh(p.T @ k @ p, p.T @ m @ p)
        p = p @ v
    n_r = p.shape[1]
    proj = lambda a: None if a is None else p.T @ np.asarray(a, dtype=float) @ p  # noqa: E731
    k3 = None if data.k3 is None else _project_tensor(np.asarray(data.k3, dtype=float), p)
    k4 = None if data.k4 is None else _project_tensor(np.asarray(data.k4, dtype=float), p)
    w = np.sqrt(np.maximum(lam, 0.0))
    d_ff = proj(data.d_ff)
    if damping_ratio > 0.0:
        d_ff = (d_ff if d_ff is not None else 0.0) + np.diag(2.0 * damping_ratio * w)
    markers = {name: InterfacePoint(pt.point, np.asarray(pt.displacement) @ p, None if pt.rotation is None else np.asarray(pt.rotation) @ p)
               for name, pt in data.markers.items()}
    info: Dict[str, Any] = {"frequencies": w, "modes": p}
    if "stress_modes" in data.info:  # mesh data (fe.from_mesh): its nodal fields on the new basis
        nodal = np.asarray(data.info.get("nodal_modes", data.info["modes"]), dtype=float)
        info.update({k: data.info[k] for k in ("points", "cells", "nodes")},
                    nodal_modes=nodal @ p, stress_modes=np.asarray(data.info["stress_modes"], dtype=float) @ p)
    return FlexibleData(mass=data.mass, inertia=data.inertia, com=data.com, s_bar=np.asarray(data.s_bar) @ p,
                        s_u0=p.T @ np.asarray(data.s_u0), s_ju0=p.T @ np.asarray(data.s_ju0), s_tilde=_antisym(proj(data.s_tilde)),
                        m_ff=np.eye(n_r), k_ff=np.diag(lam), d_ff=d_ff, m_ff_tr=proj(data.m_ff_tr), k3=k3, k4=k4,
                        markers=markers, info=info)


def _antisym(a: np.ndarray) -> np.ndarray:
    """The antisymmetric part (a projected ``s_tilde`` is antisymmetric up to rounding)."""
    return 0.5 * (a - a.T)


def _project_tensor(t: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``t`` (n, ..., n) with every index projected on the columns of ``p`` (n, r), one index at
    a time (n^d r work instead of n^d r^d)."""
    for _ in range(t.ndim):
        # contract the first index and move the new one last: after ndim steps the order is back
        t = np.moveaxis(np.tensordot(p, t, axes=([0], [0])), 0, -1)
    return np.ascontiguousarray(t)


def _enrich(p: np.ndarray, extra: np.ndarray, m: np.ndarray, tol: float) -> np.ndarray:
    """``p`` (mass-orthonormal columns) extended by the columns of ``extra`` that it does not
    span: Gram-Schmidt in the mass inner product, twice, dropping a vector whose remainder is
    below ``tol`` times its mass norm."""
    cols = [c for c in p.T]
    for v in extra.T:
        n0 = float(np.sqrt(v @ m @ v))
        if n0 == 0.0:
            continue
        r = v.copy()
        for _ in range(2):
            for c in cols:
                r -= (c @ m @ r) * c
        nr = float(np.sqrt(max(r @ m @ r, 0.0)))
        if nr > tol * n0:
            cols.append(r / nr)
    return np.array(cols).T
