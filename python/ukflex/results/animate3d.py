"""A GIF of a spatial (3D) run with matplotlib's 3D axes (``ukflex.results.animate.animate``
dispatches here for a ``"dim": 3`` System; ``ukflex run FILE.toml --animate``).

Each body is drawn as the polyline through its centre of mass and the points of its markers
(the joints', drivers' and forces' markers on it, in the order they appear in the scene) with a
short triad of its body axes (x red, y green, z blue) at the centre of mass; joints are dots at
their first marker's point. Positions and orientations come from the spatial sensors
(``SpatialSensors.body``: centre of mass and rotation matrix, computed in Rust); the markers'
body-frame points from the description, shifted by the body's centre-of-mass offset
(``r_marker = r_com + R (s - c)``, docs/spatial-design.md, section 1).
"""

from __future__ import annotations

from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

__all__ = ["animate3d", "SpatialDrawer"]

_SECTIONS = ("joints", "drivers", "forces")


class SpatialDrawer:
    """World geometry of a spatial system at its stored states: ``body_points(k, name)`` (the
    polyline of a body at sample ``k``), ``joint_points(k)``, ``triad(k, name)``."""

    def __init__(self, res: Any):
        self.res = res
        d = res.system.description
        self.kind = {b["name"]: b["kind"] for b in d.get("bodies", [])}
        self.com = {b["name"]: np.asarray(b.get("com", [0.0, 0.0, 0.0]), dtype=float) for b in d.get("bodies", [])}
        self.points: Dict[str, List[np.ndarray]] = {name: [] for name in self.kind}
        self.joints: List[Tuple[str, np.ndarray]] = []
        for section in _SECTIONS:
            for item in d.get(section) or []:
                markers = [item[k] for k in ("a", "b", "point") if isinstance(item.get(k), dict)]
                for m in markers:
                    body, s = m.get("body", "ground"), np.asarray(m.get("point", [0.0, 0.0, 0.0]), dtype=float)
                    if body in self.points and not any(np.array_equal(s, p) for p in self.points[body]):
                        self.points[body].append(s)
                if section != "forces" and markers:
                    m = markers[0]
                    self.joints.append((m.get("body", "ground"), np.asarray(m.get("point", [0.0, 0.0, 0.0]), dtype=float)))
        sens = res.sensors
        self.kin = {name: sens.body(name) for name in self.kind}
        self.size = self._size()

    def _world(self, k: int, body: str, s: np.ndarray) -> np.ndarray:
        if body == "ground":
            return s
        kin = self.kin[body]
        if self.kind[body] != "rigid3":
            return kin["position"][k]
        return kin["position"][k] + kin["rotation"][k] @ (s - self.com[body])

    def body_points(self, k: int, body: str) -> np.ndarray:
        """(p, 3): the centre of mass, then the body's marker points (world)."""
        pts = [self.kin[body]["position"][k]] + [self._world(k, body, s) for s in self.points[body]]
        return np.array(pts)

    def joint_points(self, k: int) -> np.ndarray:
        return np.array([self._world(k, b, s) for b, s in self.joints]).reshape(-1, 3)

    def triad(self, k: int, body: str) -> np.ndarray:
        """(3, 2, 3): each body axis as a segment from the centre of mass (length ``size / 8``)."""
        r = self.kin[body]["position"][k]
        R = self.kin[body]["rotation"][k]
        return np.array([[r, r + self.size / 8.0 * R[:, i]] for i in range(3)])

    def _size(self) -> float:
        pts = np.concatenate([self.body_points(k, b) for b in self.kind for k in (0, self.res.t.size - 1)])
        span = float(np.max(np.ptp(pts, axis=0))) if len(pts) > 1 else 0.0
        return span if span > 0 else 1.0

    def bounds(self, idx: Sequence[int]) -> Tuple[np.ndarray, float]:
        """Centre and half-width of a cube holding every drawn point at the samples ``idx``."""
        pts = [self.body_points(k, b) for k in idx for b in self.kind] + [self.joint_points(k) for k in idx]
        allp = np.concatenate([p for p in pts if p.size])
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        half = 0.55 * max(float(np.max(hi - lo)), 1e-9) + self.size / 8.0
        return 0.5 * (lo + hi), half


def animate3d(res: Any, path: str, fps: int = 25, frames: int = 150, title: Optional[str] = None,
              size: Tuple[float, float] = (6.4, 5.0), dpi: int = 90) -> int:
    """Write a GIF of a spatial run (module docstring); returns the number of frames."""
    from ..errors import require

    require("matplotlib", "the animation (a GIF)")
    Image = require("PIL.Image", "the animation (a GIF)")
    if res.t.size == 0:
        raise ValueError("the result has no output times to animate")
    from .plotting import figure

    idx = np.unique(np.linspace(0, res.t.size - 1, min(int(frames), res.t.size)).round().astype(int))
    drawer = SpatialDrawer(res)
    fig = figure(size, "the animation (a GIF)", dpi=dpi)  # an Agg canvas
    canvas = fig.canvas
    ax = fig.add_subplot(1, 1, 1, projection="3d")
    centre, half = drawer.bounds(idx)
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.set_title(title or "ukflex (3D)", fontsize=9)
    colours = ("tab:red", "tab:green", "tab:blue")
    lines = {b: ax.plot([], [], [], "-o", lw=2.0, ms=3)[0] for b in drawer.kind}
    triads = {b: [ax.plot([], [], [], "-", color=c, lw=1.0)[0] for c in colours] for b in drawer.kind if drawer.kind[b] == "rigid3"}
    joints = ax.plot([], [], [], "o", color="k", ms=5, label="joints")[0]
    text = ax.text2D(0.02, 0.95, "", transform=ax.transAxes, fontsize=8)
    images = []
    for k in idx:
        for b, ln in lines.items():
            p = drawer.body_points(k, b)
            ln.set_data_3d(p[:, 0], p[:, 1], p[:, 2])
        for b, segs in triads.items():
            for ln, seg in zip(segs, drawer.triad(k, b)):
                ln.set_data_3d(seg[:, 0], seg[:, 1], seg[:, 2])
        jp = drawer.joint_points(k)
        joints.set_data_3d(jp[:, 0], jp[:, 1], jp[:, 2])
        text.set_text(f"t = {res.t[k]:.4f} s")
        canvas.draw()
        rgba = np.asarray(canvas.buffer_rgba())
        images.append(Image.fromarray(rgba[:, :, :3].copy()).quantize(colors=64, method=Image.Quantize.FASTOCTREE))
    duration = max(int(round(1000.0 / max(int(fps), 1))), 20)
    images[0].save(path, save_all=True, append_images=images[1:], duration=duration, loop=0, optimize=True)
    return len(images)
