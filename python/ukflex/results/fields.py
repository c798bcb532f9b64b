"""Displacement and stress fields of modal (FE) bodies at their nodes, per output time
(docs/outputs.md, "Fields of modal bodies").

A node of a flexible body built by :func:`ukflex.fe.from_mesh` with body-frame position ``u0``
is at ``r = R + A(theta) (u0 + Phi q_f)`` (``Phi`` its rows of the nodal modes); its plane-stress
stress is ``sigma = sum_k q_k sigma_k`` with the stress shapes ``sigma_k`` of the modes,
computed once when the body is built (``info["stress_modes"]``).

A node of a spatial modal body (``flexible3``, built by :func:`ukflex.fe3.from_mesh`) is at
``r + R(p) (u0 + Phi q_f)`` (docs/spatial-flexible.md); its stress ``sum_k q_k sigma_k`` from the
modes' nodal stress shapes (``xx, yy, zz, yz, zx, xy``, frame axes; ``info["stress_modes"]``).
"""

from __future__ import annotations

from typing import Any, Dict

import numpy as np

from ..errors import InvalidArgumentError

__all__ = ["modal_fields", "von_mises", "von_mises3"]


def von_mises(stress: np.ndarray) -> np.ndarray:
    """Plane-stress von Mises stress of ``stress[..., 3]`` = ``(sigma_xx, sigma_yy, sigma_xy)``:
    ``sqrt(sxx^2 - sxx syy + syy^2 + 3 sxy^2)``."""
    sxx, syy, sxy = stress[..., 0], stress[..., 1], stress[..., 2]
    return np.sqrt(np.maximum(sxx * sxx - sxx * syy + syy * syy + 3.0 * sxy * sxy, 0.0))


def von_mises3(stress: np.ndarray) -> np.ndarray:
    """Von Mises stress of ``stress[..., 6]`` = ``(xx, yy, zz, yz, zx, xy)``."""
    s = stress
    d = (s[..., 0] - s[..., 1]) ** 2 + (s[..., 1] - s[..., 2]) ** 2 + (s[..., 2] - s[..., 0]) ** 2
    return np.sqrt(0.5 * d + 3.0 * (s[..., 3] ** 2 + s[..., 4] ** 2 + s[..., 5] ** 2))


def check_mesh_data(system: Any, body: str, data: Any) -> np.ndarray:
    """The nodal modes (dN, n_f) of ``data`` after checking that it is the mesh data of ``body``
    (built by :func:`ukflex.fe.from_mesh` or, for a ``flexible3`` body, :func:`ukflex.fe3.from_mesh`;
    same ``k_ff`` as the body in the system)."""
    kind = system.body_kind(body)
    if kind not in ("flexible", "flexible3"):
        raise InvalidArgumentError("body", f"body {body!r} is a {kind}, not a flexible (modal) body")
    spatial = kind == "flexible3"
    keys = ("cells", "nodes", "modes", "stress_modes")
    info = getattr(data, "info", None)
    if not isinstance(info, dict) or any(k not in info for k in keys):
        raise InvalidArgumentError("data", f"the data of body {body!r} must be the FlexibleData{'3' if spatial else ''} that "
                                   f"ukflex.{'fe3' if spatial else 'fe'}.from_mesh (or fe.reduce of it) returned: its info "
                                   "holds the mesh, the nodal modes and their stress shapes")
    entry = next(b for b in system.description["bodies"] if b["name"] == body)
    k_ff = np.asarray(entry["k_ff"], dtype=float)
    if np.shape(data.k_ff) != k_ff.shape or not np.allclose(np.asarray(data.k_ff, dtype=float), k_ff, rtol=1e-12, atol=0.0):
        raise InvalidArgumentError("data", f"the data given for body {body!r} is not the one the body was built from "
                                   "(its stiffness k_ff differs)")
    modes = np.asarray(info.get("nodal_modes", info["modes"]), dtype=float)  # fe.reduce: nodal_modes
    if modes.shape != ((3 if spatial else 2) * np.asarray(info["nodes"]).shape[0], k_ff.shape[0]):
        raise InvalidArgumentError("data", f"the modes of body {body!r} are not nodal ({modes.shape})")
    return modes


def modal_fields(system: Any, result: Any, body: str, data: Any) -> Dict[str, np.ndarray]:
    """Nodal fields of the modal body ``body`` over the result's output times.

    Parameters
    ----------
    system : ukflex.System
    result : SimulationResult, or positions ``q`` (n,) or (n, nt)
    body : str
        A flexible body of the system.
    data : FlexibleData
        What :func:`ukflex.fe.from_mesh` (or :func:`ukflex.fe.reduce` of it) returned for it
        (checked: same ``k_ff``).

    Returns
    -------
    dict
        ``nodes`` (N, 2) body frame, ``cells`` (E, 3|4) (the mesh's vertex indices);
        ``position`` (nt, N, 2) world; ``displacement`` (nt, N, 2) world, rigid + elastic, from
        the node's undeformed place at the system's initial state (``R0 + A0 u0``, frame of
        ``system.q0``); ``elastic`` (nt, N, 2)
        the elastic displacement ``A Phi q_f`` in the world frame; ``stress`` (nt, N, 3)
        ``sigma_xx, sigma_yy, sigma_xy`` in the body frame (plane stress, Pa); ``von_mises``
        (nt, N). A ``flexible3`` body: the same with three components, ``cells`` a pair
        (meshio cell type, vertex indices), ``stress`` (nt, N, 6) ``xx, yy, zz, yz, zx, xy`` in
        the frame's axes.
    """
    modes = check_mesh_data(system, body, data)
    q = np.asarray(result.q if hasattr(result, "q") else result, dtype=float)
    if q.ndim == 1:
        q = q[:, None]
    if system.body_kind(body) == "flexible3":
        return _fields3(system, q, body, data, modes)
    frame = q[system.body_slice(body)][:3]  # (3, nt): x, y, theta
    qf = q[system.elastic_slice(body)]  # (n_f, nt)
    nodes = np.asarray(data.info["nodes"], dtype=float)
    local_el = np.einsum("nf,ft->tn", modes, qf).reshape(qf.shape[1], -1, 2)  # (nt, N, 2) body frame
    c, s = np.cos(frame[2]), np.sin(frame[2])
    rot = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)  # (nt, 2, 2)
    elastic = np.einsum("tij,tnj->tni", rot, local_el)
    rigid = np.einsum("tij,nj->tni", rot, nodes)
    position = frame[:2].T[:, None, :] + rigid + elastic
    q0 = np.asarray(system.q0, dtype=float)
    f0 = q0[system.body_slice(body)][:3]
    c0, s0 = np.cos(f0[2]), np.sin(f0[2])
    reference = f0[:2] + nodes @ np.array([[c0, -s0], [s0, c0]]).T  # undeformed, at the system's q0
    stress = np.einsum("nkf,ft->tnk", np.asarray(data.info["stress_modes"], dtype=float), qf)
    return {"nodes": nodes, "cells": np.asarray(data.info["cells"]), "position": position,
            "displacement": position - reference[None], "elastic": elastic, "stress": stress,
            "von_mises": von_mises(stress)}


def _frame3(system: Any, q: np.ndarray, body: str) -> tuple:
    """Origin (nt, 3) and rotation (nt, 3, 3) of a spatial body's frame at the states ``q``
    (n, nt), from the compiled model's outputs."""
    from .spatial import outputs

    o = outputs(system, np.zeros(q.shape[1]), q.T, np.zeros_like(q.T), reactions=False)["bodies"][body]
    return o["position"], o["rotation"]


def _fields3(system: Any, q: np.ndarray, body: str, data: Any, modes: np.ndarray) -> Dict[str, Any]:
    """:func:`modal_fields` of a ``flexible3`` body: ``r + R (u0 + Phi q_f)``."""
    qf = q[system.elastic_slice(body)]
    nodes = np.asarray(data.info["nodes"], dtype=float)
    local_el = np.einsum("nf,ft->tn", modes, qf).reshape(qf.shape[1], -1, 3)
    origin, rot = _frame3(system, q, body)
    elastic = np.einsum("tij,tnj->tni", rot, local_el)
    position = origin[:, None, :] + np.einsum("tij,nj->tni", rot, nodes) + elastic
    o0, r0 = _frame3(system, np.asarray(system.q0, dtype=float)[:, None], body)
    reference = o0[0] + nodes @ r0[0].T
    stress = np.einsum("nkf,ft->tnk", np.asarray(data.info["stress_modes"], dtype=float), qf)
    return {"nodes": nodes, "cells": data.info["cells"], "position": position, "displacement": position - reference[None],
            "elastic": elastic, "stress": stress, "von_mises": von_mises3(stress)}
