"""The command line on spatial (3D) scenes (``dim = 3`` scene files, docs/spatial.md).

``ukflex run FILE.toml`` runs a spatial scene file as any other (the same summary: sizes,
initial correction, solver statistics, residuals, the energy balance of
:class:`ukflex.results.spatial.SpatialSensors`) and, for a spatial scene, also writes
``NAME_spatial.csv`` and ``NAME_spatial.npz``: per body the centre of mass, velocity,
quaternion, rotation matrix and angular velocity, per joint the 3D reaction and its power, the
energies, work and balance (``SpatialSensors.columns``). ``ukflex export FILE.toml`` writes a
scene file back as validated TOML (``dim`` first). ``run.py`` calls these with a line each.
"""

from __future__ import annotations

import argparse
import csv
import os
from typing import Any, List

import numpy as np

from ..results.spatial import is_spatial

__all__ = ["is_spatial", "write_outputs", "export_source", "export_text"]


def write_outputs(res: Any, base: str) -> List[str]:
    """Write ``BASE_spatial.csv`` (``t`` and every spatial sensor column) and
    ``BASE_spatial.npz`` for a spatial result; nothing for a planar one. Returns the paths."""
    if not is_spatial(res.system):
        return []
    cols = res.sensors.columns()
    with open(base + "_spatial.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["t"] + list(cols))
        data = np.column_stack([res.t] + list(cols.values()))
        for row in data:
            w.writerow([repr(float(x)) for x in row])
    res.sensors.save_npz(base + "_spatial.npz")
    return [base + "_spatial.csv", base + "_spatial.npz"]


def export_source(text: str) -> str:
    """``ukflex export``'s argument: a built-in scene's name or a scene file (``.toml`` or a path)."""
    from ..model.scenes import SCENES

    if text in SCENES or text.endswith(".toml") or os.sep in text:
        return text
    raise argparse.ArgumentTypeError(f"invalid choice: {text!r} (choose from {', '.join(sorted(SCENES))}, or a .toml file)")


def export_text(path: str) -> str:
    """``ukflex export FILE.toml``: the file loaded and validated (a spatial file by the core,
    whole), as TOML with its ``[scene]``, ``[initial]``, ``[solver]`` and ``[output]`` tables
    (the export options ``--t-end``, ``--method``, ``--rtol`` are for built-in scenes; a file
    keeps its own ``[solver]``)."""
    from ..model.scenefile import dumps, load

    sf = load(path)
    return dumps(sf.scene, name=sf.name, description=sf.description or None, initial=sf.initial, solver=sf.solver,
                 output=sf.output, header=f"ukflex scene file (ukflex export {path}).\n"
                                          "Format: docs/scene-format.md, docs/spatial.md; run with: ukflex run FILE")
