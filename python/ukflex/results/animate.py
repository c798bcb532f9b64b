"""Headless drawings and GIF animations of a simulated mechanism.

Every body kind draws itself in the core (``System.core.outline``, ``rust/body/outline.rs``):
beams as their deformed axis, ``r(x) = R + A(theta) (x e_1 + s S(x) q_f)`` sampled along the
beam from the element shape functions, with an optional magnification ``s`` of the elastic
displacement (``deform_scale``); an ANCF beam as its axis points, their displacement from the
chord of the ends magnified by ``s``; a flexible body through its interface points.  Rigid
bodies are drawn as lines from their centre of mass to every point where a joint, driver or
force attaches to them (a crank becomes a bar from its pivot to its tip); joints are circles,
ground attachments triangles, and ground lines of point-on-line and prismatic joints dashed
lines.

Rendering uses matplotlib's Agg canvas directly (no pyplot, no display needed) and Pillow (a
matplotlib dependency) to write the GIF.
"""

from __future__ import annotations

import math
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np


__all__ = ["MechanismDrawer", "animate", "snapshots"]

GROUND = "ground"


def _markers_of(description: Dict[str, Any]) -> List[Tuple[str, Dict[str, Any], str]]:
    """Every marker of the description as ``(item kind, marker dict, role)``."""
    out = []
    for j in description.get("joints") or []:
        for role in ("a", "b", "point", "line"):
            if role in j:
                out.append((j["kind"], j[role], role))
    for d in description.get("drivers") or []:
        for role in ("a", "b", "point"):
            if role in d:
                out.append(("driver", d[role], role))
    for f in description.get("forces") or []:
        for role in ("a", "b", "point", "frame"):
            if role in f:
                out.append((f["kind"], f[role], role))
    return out


class MechanismDrawer:
    """World-frame geometry of every body for a given ``q``.

    Each body kind draws itself in the core (``System.core.outline``: a beam's or cable's axis,
    a flexible body's interface points, a rigid body's star from its centre of mass to its
    attachment points, a point mass; ``rust/body/outline.rs``), so this class knows no kinds.

    Parameters
    ----------
    system : ukflex.System
    deform_scale : float
        Magnification of the elastic displacements in the drawing (1 = true scale).
    points_per_element : int
        Samples of each beam element's axis.
    """

    def __init__(self, system, deform_scale: float = 1.0, points_per_element: int = 8):
        self.system = system
        self.scale = float(deform_scale)
        self.points_per_element = int(points_per_element)
        #: name -> kind ("rigid", "beam", ...), in declaration order
        self.bodies = {name: system.body_kind(name) for name in system.body_names}
        self.markers = _markers_of(system.description)
        #: the joints in the order of the core's constraints (joints first, then drivers)
        self._joints = list(system.description.get("joints") or [])

    def body_polyline(self, q: np.ndarray, name: str) -> np.ndarray:
        """World points (k, 2) drawing body ``name`` at ``q``."""
        return np.asarray(self.system.core.outline(name, np.asarray(q, dtype=float), self.scale,
                                                   self.points_per_element))

    def joint_positions(self, q: np.ndarray) -> np.ndarray:
        """World positions (k, 2) of the joints' first markers (revolute, weld) and of points on lines."""
        points = list(self.system.core.marker_points(np.asarray(q, dtype=float), self.scale).values())
        out = [p[0] for j, p in zip(self._joints, points) if j["kind"] in ("revolute", "weld", "point_on_line")]
        return np.array(out, dtype=float).reshape(-1, 2)

    def ground_points(self) -> np.ndarray:
        pts = [m["point"] for kind, m, role in self.markers
               if m["body"] == GROUND and kind in ("revolute", "weld", "spring_damper")]
        return np.array(pts, dtype=float).reshape(-1, 2)

    def ground_lines(self) -> List[Tuple[np.ndarray, float]]:
        """(point, angle) of every line on the ground (point-on-line and prismatic joints)."""
        return [(np.asarray(m["point"], dtype=float), float(m.get("angle", 0.0)))
                for kind, m, role in self.markers
                if m["body"] == GROUND and ((kind == "point_on_line" and role == "line") or (kind == "prismatic" and role == "b"))]

    def bounds(self, qs: Sequence[np.ndarray]) -> Tuple[float, float, float, float]:
        pts = [self.body_polyline(q, n) for q in qs for n in self.bodies]
        pts.append(self.ground_points())
        allp = np.vstack([p for p in pts if p.size])
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        span = max(hi[0] - lo[0], hi[1] - lo[1], 1e-3)
        pad = 0.08 * span
        return lo[0] - pad, hi[0] + pad, lo[1] - pad, hi[1] + pad


def _new_figure(size: Tuple[float, float], dpi: int):
    from .plotting import figure

    return figure(size, "the animation", dpi=dpi)


class _Scene2D:
    """Artists of one axes, updated in place for every frame."""

    COLORS = ("C0", "C3", "C2", "C1", "C4", "C5", "C6", "C8", "C9")

    def __init__(self, ax, drawer: MechanismDrawer, limits, title: str):
        self.ax, self.d = ax, drawer
        x0, x1, y0, y1 = limits
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_title(title, fontsize=10)
        ax.grid(True, lw=0.3, color="0.85")
        for p, ang in drawer.ground_lines():
            L = 2.0 * max(x1 - x0, y1 - y0)
            e = np.array([math.cos(ang), math.sin(ang)])
            ax.plot([p[0] - L * e[0], p[0] + L * e[0]], [p[1] - L * e[1], p[1] + L * e[1]], "--", color="0.6", lw=0.8)
        gp = drawer.ground_points()
        if gp.size:
            ax.plot(gp[:, 0], gp[:, 1], "^", color="0.3", ms=9, zorder=1)
        self.lines = {}
        for k, name in enumerate(drawer.bodies):
            can = drawer.system.capabilities(name)
            (ln,) = ax.plot([], [], "-", lw=2.5 if can["beam"] else 4.0, color=self.COLORS[k % len(self.COLORS)],
                            label=name, solid_capstyle="round", zorder=2, marker=None if can["elastic"] else "o",
                            ms=3 if can["oriented"] else 8)
            self.lines[name] = ln
        (self.joints,) = ax.plot([], [], "o", ms=6, mfc="white", mec="k", mew=1.2, zorder=3)
        self.text = ax.text(0.02, 0.96, "", transform=ax.transAxes, va="top", fontsize=9)
        ax.legend(loc="upper right", fontsize=8)

    def animated(self) -> List[Any]:
        return list(self.lines.values()) + [self.joints, self.text]

    def update(self, q: np.ndarray, t: float) -> None:
        for name, ln in self.lines.items():
            p = self.d.body_polyline(q, name)
            ln.set_data(p[:, 0], p[:, 1])
        jp = self.d.joint_positions(q)
        self.joints.set_data(jp[:, 0], jp[:, 1])
        self.text.set_text(f"t = {t:.4f} s")


def _title(res, deform_scale: float, title: Optional[str]) -> str:
    base = title or "ukflex"
    if any(res.system.capabilities(name)["beam"] for name in res.system.body_names):
        base += f" (elastic displacements x{deform_scale:g})" if deform_scale != 1.0 else " (true scale)"
    return base


def animate(
    res,
    path: str,
    fps: int = 25,
    frames: int = 150,
    deform_scale: float = 1.0,
    title: Optional[str] = None,
    size: Tuple[float, float] = (6.4, 4.0),
    dpi: int = 90,
) -> int:
    """Write a GIF of the mechanism over the result's output times.

    Parameters
    ----------
    res : SimulationResult
    path : str
        Output ``.gif`` file.
    fps : int
        Frames per second of the GIF.
    frames : int
        Maximum number of frames (output times are subsampled evenly).
    deform_scale : float
        Magnification of the elastic displacements (drawing only).

    Returns
    -------
    int
        Number of frames written.
    """
    from ..errors import require
    from .spatial import is_spatial

    if is_spatial(res.system):  # a spatial run: matplotlib 3D (animate3d.py)
        from .animate3d import animate3d

        return animate3d(res, path, fps=fps, frames=frames, title=title, size=size, dpi=dpi)
    require("matplotlib", "the animation (a GIF)")
    Image = require("PIL.Image", "the animation (a GIF)")
    if res.t.size == 0:
        raise ValueError("the result has no output times to animate")
    idx = np.unique(np.linspace(0, res.t.size - 1, min(int(frames), res.t.size)).round().astype(int))
    drawer = MechanismDrawer(res.system, deform_scale=deform_scale)
    fig = _new_figure(size, dpi)
    ax = fig.add_subplot(1, 1, 1)
    sc = _Scene2D(ax, drawer, drawer.bounds([res.q[:, i] for i in idx]), _title(res, deform_scale, title))
    fig.tight_layout()
    # blitting: the static background (axes, ground, legend) is drawn once
    for a in sc.animated():
        a.set_animated(True)
    canvas = fig.canvas
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    images = []
    for i in idx:
        sc.update(res.q[:, i], float(res.t[i]))
        canvas.restore_region(background)
        for a in sc.animated():
            ax.draw_artist(a)
        rgba = np.asarray(canvas.buffer_rgba())
        images.append(Image.fromarray(rgba[:, :, :3].copy()).quantize(colors=64, method=Image.Quantize.FASTOCTREE))
    duration = max(int(round(1000.0 / max(int(fps), 1))), 20)
    images[0].save(path, save_all=True, append_images=images[1:], duration=duration, loop=0, optimize=True)
    return len(images)


def snapshots(
    res,
    path: str,
    times: Optional[Sequence[float]] = None,
    deform_scale: float = 1.0,
    title: Optional[str] = None,
    size: Tuple[float, float] = (6.4, 4.0),
    dpi: int = 120,
) -> None:
    """Write a PNG with the mechanism drawn at several times (default: 6 evenly spaced),
    later instants darker."""
    drawer = MechanismDrawer(res.system, deform_scale=deform_scale)
    if times is None:
        idx = np.unique(np.linspace(0, res.t.size - 1, min(6, res.t.size)).round().astype(int))
    else:
        idx = np.unique([int(np.argmin(np.abs(res.t - tt))) for tt in times])
    fig = _new_figure(size, dpi)
    ax = fig.add_subplot(1, 1, 1)
    sc = _Scene2D(ax, drawer, drawer.bounds([res.q[:, i] for i in idx]), _title(res, deform_scale, title))
    for ln in sc.lines.values():
        ln.remove()
    sc.joints.remove()
    for k, i in enumerate(idx):
        alpha = 0.25 + 0.75 * (k + 1) / len(idx)
        for c, name in enumerate(drawer.bodies):
            p = drawer.body_polyline(res.q[:, i], name)
            ax.plot(p[:, 0], p[:, 1], "-", color=_Scene2D.COLORS[c % len(_Scene2D.COLORS)], alpha=alpha,
                    lw=2.0, label=name if k == len(idx) - 1 else None,
                    marker=None if drawer.system.capabilities(name)["oriented"] else "o", ms=7)
    sc.text.set_text("t = " + ", ".join(f"{res.t[i]:.3g}" for i in idx) + " s")
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
