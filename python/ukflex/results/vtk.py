"""Export of a run to VTK files that ParaView opens as a time series (docs/outputs.md, "Export to
ParaView (VTK)").

:func:`export_vtk` writes, through meshio, one ``.vtu`` file per body and output time into a
folder next to a ``.pvd`` collection that lists them with their times (ParaView: File > Open the
``.pvd``; each body is a block of the collection):

* beams (FFRF and ANCF): their axis as a polyline of ``points_per_element`` points per element,
  with ``deflection`` (the axis displacement ``u, v`` in the beam frame, ``System.beam_point``)
  and ``rotation`` (``psi``);
* modal (FE) bodies whose :func:`ukflex.fe.from_mesh` data is given (``flexible=``): their mesh
  at its deformed place (the vertices' cells; the mid-edge nodes of P2/Q2 are points without
  cells), with ``displacement`` (rigid + elastic, from the undeformed place at ``system.q0``),
  ``elastic_displacement`` (world), ``stress`` (``sigma_xx, sigma_yy, sigma_xy``, body frame)
  and ``von_mises`` (:mod:`ukflex.results.fields`); without data, the polyline through their
  interface points;
* rigid bodies and point masses: the polyline of the animation (centre of mass to every point
  where a joint, driver or force attaches) or a point;
* spatial scenes (:class:`ukflex.SpatialScene`): each body as the polyline from its centre of
  mass to its marker points, with its axes ``x_axis``, ``y_axis``, ``z_axis`` (world) at every
  point (:func:`ukflex.spatial_outputs`); a ``flexible3`` body whose :func:`ukflex.fe3.from_mesh`
  data is given (``flexible=``): its mesh (tetrahedra or hexahedra on the vertex nodes) at its
  deformed place with ``displacement``, ``elastic_displacement`` (world), ``stress``
  (``xx, yy, zz, yz, zx, xy``, frame axes) and ``von_mises``.

Planar points get ``z = 0``; vectors have three components (ParaView's Warp By Vector).
"""

from __future__ import annotations

import os
import re
from typing import Any, Dict, List, Mapping, Optional, Tuple
from xml.sax.saxutils import quoteattr

import numpy as np

from ..errors import InvalidArgumentError, require

__all__ = ["export_vtk"]

Part = Tuple[np.ndarray, List[Tuple[str, np.ndarray]], Dict[str, np.ndarray]]  # points (k, 3), cells, point data


def _xyz(p: np.ndarray) -> np.ndarray:
    """(..., 2|3) -> (..., 3)."""
    p = np.asarray(p, dtype=float)
    if p.shape[-1] == 3:
        return p
    return np.concatenate([p, np.zeros(p.shape[:-1] + (1,))], axis=-1)


def _modal_parts(f: Dict[str, Any]) -> List[Part]:
    """The mesh of a modal body at each time of its :func:`ukflex.results.fields.modal_fields`
    (planar: triangles or quads, with stress; spatial: its (cell type, cells) pair)."""
    cells = f["cells"]
    if isinstance(cells, tuple):
        block = [cells]
    else:
        block = [("triangle" if cells.shape[1] == 3 else "quad", cells)]
    parts = []
    for j in range(f["position"].shape[0]):
        data = {"displacement": _xyz(f["displacement"][j]), "elastic_displacement": _xyz(f["elastic"][j])}
        if "stress" in f:
            data.update(stress=f["stress"][j], von_mises=f["von_mises"][j])
        parts.append((_xyz(f["position"][j]), block, data))
    return parts


def _line_cells(k: int) -> List[Tuple[str, np.ndarray]]:
    if k < 2:
        return [("vertex", np.zeros((1, 1), dtype=np.int64))]
    i = np.arange(k - 1, dtype=np.int64)
    return [("line", np.column_stack([i, i + 1]))]


def _planar_parts(system: Any, q: np.ndarray, idx: np.ndarray, flexible: Mapping[str, Any],
                  points_per_element: int) -> Dict[str, List[Part]]:
    """Per body, its part at each output index ``idx``."""
    from .animate import MechanismDrawer
    from .fields import modal_fields

    drawer = MechanismDrawer(system)
    out: Dict[str, List[Part]] = {}
    qs = q[:, idx]
    for name in system.body_names:
        kind = system.body_kind(name)
        if system.capabilities(name)["beam"]:
            info = system.body_info(name)
            xi = np.linspace(0.0, 1.0, max(2, points_per_element * int(info["elements"])) + 1)
            bp = np.array([np.asarray(system.beam_point(name, float(x), qs)) for x in xi])  # (k, 5, nt)
            cells = _line_cells(xi.size)
            out[name] = [(_xyz(bp[:, 0:2, j]), cells, {"deflection": _xyz(bp[:, 2:4, j]), "rotation": bp[:, 4, j],
                                                         "xi": xi})
                         for j in range(qs.shape[1])]
        elif kind == "flexible" and name in flexible:
            out[name] = _modal_parts(modal_fields(system, qs, name, flexible[name]))
        else:
            parts = []
            for j in range(qs.shape[1]):
                p = drawer.body_polyline(qs[:, j], name)
                parts.append((_xyz(p), _line_cells(p.shape[0]), {}))
            out[name] = parts
    return out


def _spatial_markers(description: Dict[str, Any]) -> Dict[str, List[List[float]]]:
    """Marker points (body frame) of every body of a spatial description, first use first."""
    pts: Dict[str, List[List[float]]] = {}
    for section in ("joints", "drivers", "forces"):
        for item in description.get(section) or []:
            for v in item.values():
                if isinstance(v, dict) and "body" in v and "point" in v and v["body"] != "ground":
                    lst = pts.setdefault(v["body"], [])
                    p = [float(x) for x in v["point"]]
                    if all(np.linalg.norm(np.subtract(p, u)) > 1e-12 for u in lst):
                        lst.append(p)
    return pts


def _spatial_parts(system: Any, t: np.ndarray, q: np.ndarray, qd: np.ndarray,
                   flexible: Mapping[str, Any]) -> Dict[str, List[Part]]:
    from .fields import modal_fields
    from .spatial import outputs

    out = outputs(system, t, q.T, qd.T, reactions=False)
    markers = _spatial_markers(system.description)
    parts: Dict[str, List[Part]] = {}
    for b in system.description["bodies"]:
        name = b["name"]
        if b["kind"] == "flexible3" and name in flexible:
            parts[name] = _modal_parts(modal_fields(system, q, name, flexible[name]))
            continue
        o = out["bodies"][name]
        com = np.asarray(b.get("com", (0.0, 0.0, 0.0)), dtype=float)
        local = np.asarray(markers.get(name, []), dtype=float).reshape(-1, 3) - com
        rows = []
        for j in range(t.size):
            c, R = o["position"][j], o["rotation"][j]
            if b["kind"] == "point3" or local.shape[0] == 0:
                pts = c[None, :]
            else:
                world = c + local @ R.T
                pts = np.vstack([np.vstack([c, p]) for p in world] + [c[None, :]]) if local.shape[0] > 1 \
                    else np.vstack([c, world[0]])
            data = {} if b["kind"] == "point3" else {f"{a}_axis": np.repeat(R[:, k][None, :], pts.shape[0], axis=0)
                                                      for k, a in enumerate("xyz")}
            rows.append((pts, _line_cells(pts.shape[0]), data))
        parts[name] = rows
    return parts


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name)


def export_vtk(system: Any, result: Any, path: str, *, flexible: Optional[Mapping[str, Any]] = None,
               frames: Optional[int] = None, points_per_element: int = 8) -> str:
    """Write the run ``result`` of ``system`` as VTK files that ParaView opens as a time series.

    Parameters
    ----------
    system : ukflex.System
        The system that ran (planar or spatial).
    result : SimulationResult
        Its run; every output time (or ``frames`` of them, evenly spaced) is written.
    path : str
        The ``.pvd`` collection to write; the ``.vtu`` files go into the folder of the same name
        without the suffix (``run.pvd`` -> ``run/BODY_00000.vtu``).
    flexible : dict, optional
        Body name -> the :class:`ukflex.FlexibleData` returned by :func:`ukflex.fe.from_mesh`
        for that modal body (the :class:`ukflex.fe3.FlexibleData3` of :func:`ukflex.fe3.from_mesh`
        for a ``flexible3`` body): its mesh is written with the displacement and stress fields.
    frames : int, optional
        At most this many output times.
    points_per_element : int
        Points of each beam element's polyline.

    Returns
    -------
    str
        The path of the ``.pvd`` file.
    """
    from ..arguments import count

    meshio = require("meshio", "ukflex.export_vtk (VTK files)", extra="fe")
    flexible = dict(flexible or {})
    for name in flexible:
        if name not in system.body_names:
            from ..errors import UnknownNameError

            raise UnknownNameError.of("body", name, system.body_names)
    points_per_element = count("points_per_element", points_per_element)
    path = os.fspath(path)
    if not path.endswith(".pvd"):
        raise InvalidArgumentError("path", f"expected a .pvd file name, got {path!r}")
    t = np.asarray(result.t, dtype=float)
    if t.size == 0:
        raise InvalidArgumentError("result", "the result has no output times to export")
    nt = t.size if frames is None else min(count("frames", frames), t.size)
    idx = np.unique(np.linspace(0, t.size - 1, nt).round().astype(int))
    q, qd = np.asarray(result.q, dtype=float), np.asarray(result.qd, dtype=float)
    if system.description.get("dim") == 3:
        parts = _spatial_parts(system, t[idx], q[:, idx], qd[:, idx], flexible)
    else:
        parts = _planar_parts(system, q, idx, flexible, points_per_element)
    folder = path[:-4]
    os.makedirs(folder, exist_ok=True)
    rel = os.path.basename(folder)
    entries = []
    for k, (name, rows) in enumerate(parts.items()):
        for j, (pts, cells, data) in enumerate(rows):
            fname = f"{_safe(name)}_{j:05d}.vtu"
            meshio.write(os.path.join(folder, fname), meshio.Mesh(pts, cells, point_data=data), file_format="vtu")
            entries.append(f'    <DataSet timestep="{float(t[idx[j]])!r}" group="" part="{k}" name={quoteattr(name)} '
                           f'file={quoteattr(rel + "/" + fname)}/>')
    with open(path, "w", encoding="utf-8") as fh:
        fh.write('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
                 "  <Collection>\n" + "\n".join(entries) + "\n  </Collection>\n</VTKFile>\n")
    return path
