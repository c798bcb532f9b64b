"""The paper's slider-crank with its coupler as a general flexible body reduced to ``k`` modes,
against the built-in beam (docs/flexible-bodies.md).

The coupler's FE model is ``elements`` Timoshenko beam elements on the pinned-pinned (chord)
frame, its invariants integrated in NumPy (:mod:`ukflex.reference.fe_invariants`), reduced to its
``k`` lowest modes (:func:`ukflex.fe.reduce`) and built with :meth:`ukflex.Scene.flexible_body`.
The measure is the paper's: peak ``|v(0.5)| / Lb`` over ``0 <= t <= 0.07`` s (``v`` the midpoint
deflection in the chord frame), compared with the built-in beam of the same elements.
With nonlinear strain the basis takes the modes' modal derivatives (``modal_derivatives``).

The same coupler as a plane-stress rectangle meshed with quadratic quads
(:func:`mesh_coupler_data`, :func:`mesh_study`) converges to the beam under mesh refinement.

Commands (docs/flexible-bodies.md has the figures and times)::

    python -m studies flexible-coupler                                    # beam FE, linear
    python -m studies flexible-coupler --nonlinear --modal-derivatives=2  # beam FE, nonlinear
    python -m studies flexible-coupler --mesh                             # Q2 meshes, linear
    python -m studies flexible-coupler --mesh --nonlinear --modal-derivatives=2
    python -m studies flexible-coupler --figure coupler_nonlinear.png
"""

from __future__ import annotations

import math
import time
from typing import Any, Dict, List, Optional

import numpy as np

from ukflex import ConstantSpeed, FlexibleData, InterfacePoint, Scene, fe, scenes, simulate
from ukflex.reference import fe_invariants as fi

from . import progress

__all__ = ["coupler_data", "mesh_coupler_data", "scene", "peak", "study", "mesh_study", "beam_frequencies", "figure"]

P = scenes.PAPER
WINDOW = 0.07


def coupler_data(elements: int = 8, modes: Optional[int] = None, strain: str = "linear") -> FlexibleData:
    """The paper's coupler (round 6.35 mm steel rod, Timoshenko, rotary inertia) as a flexible
    body: nodal (``modes=None``) or reduced to ``modes`` modes; markers ``"A"`` (xi = 0), ``"M"``
    (xi = 0.5), ``"B"`` (xi = 1)."""
    d = P["diameter"]
    area, i2 = math.pi * d * d / 4, math.pi * d**4 / 64
    g = P["youngs_modulus"] / (2 * (1 + P["poisson_ratio"]))
    inv = fi.beam_invariants(P["coupler_length"], elements, P["density"], P["youngs_modulus"], area, i2,
                             shear_stiffness=P["shear_factor"] * g, rotary_inertia=True, markers=(0.0, 0.5, 1.0),
                             nonlinear=strain == "nonlinear")
    names = dict(zip(["xi=0", "xi=0.5", "xi=1"], "AMB"))
    markers = {names[k]: InterfacePoint(v["point"], v["displacement"], v["rotation"]) for k, v in inv.pop("markers").items()}
    data = FlexibleData(markers=markers, **inv)
    return data if modes is None else fe.reduce(data, modes)


def _section():
    """Rectangle of the coupler's area and second moment (plane-stress height ``h``, thickness
    ``t``): ``h = sqrt(12 I / A) = d sqrt(3) / 2``, ``t = A / h``."""
    d = P["diameter"]
    area, i2 = math.pi * d * d / 4, math.pi * d**4 / 64
    h = math.sqrt(12 * i2 / area)
    return h, area / h


def mesh_coupler_data(nx: int, ny: int, order: int = 2, modes: int = 4, cells: str = "quad", strain: str = "linear",
                      modal_derivatives: Any = False) -> FlexibleData:
    """The paper's coupler as a plane-stress rectangle (same length, area, second moment, mass
    per length and rotary inertia as the rod: height ``d sqrt(3)/2``, thickness ``A / height``)
    meshed with ``nx`` x ``ny`` quads (``cells="quad"``, Q1/Q2 by ``order``) or twice as many
    triangles (``"tri"``, P1/P2), assembled by :func:`ukflex.fe.from_mesh`, pinned-pinned frame
    through the centres of the end edges, ``modes`` normal modes.  Markers ``"A"``, ``"M"``,
    ``"B"``: rigid averages of the nodes of the left, middle (``nx`` even) and right sections.
    ``strain``, ``modal_derivatives``: see :func:`ukflex.fe.from_mesh` (Green-Lagrange strain)."""
    if nx % 2:
        raise ValueError("nx must be even (a section of nodes at the midpoint)")
    lb = P["coupler_length"]
    h, t = _section()
    xs, ys = np.linspace(0.0, lb, nx + 1), np.linspace(-h / 2, h / 2, ny + 1)
    pts = np.array([(x, y) for x in xs for y in ys])
    at = lambda i, j: i * (ny + 1) + j  # noqa: E731
    quads = np.array([[at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)] for i in range(nx) for j in range(ny)])
    cellarr = quads if cells == "quad" else np.vstack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    tol = 1e-9 * lb
    ifs = {name: (lambda p, x0=x0: np.abs(p[:, 0] - x0) < tol) for name, x0 in (("A", 0.0), ("M", lb / 2), ("B", lb))}
    return fe.from_mesh(pts, cells=cellarr, thickness=t, density=P["density"], youngs_modulus=P["youngs_modulus"],
                        poisson_ratio=P["poisson_ratio"], interfaces=ifs, modes=modes,
                        frame=[("A", "x"), ("A", "y"), ("B", "y")], order=order, strain=strain,
                        modal_derivatives=modal_derivatives)


def beam_frequencies(elements: int = 32, shear_factor: Optional[float] = None, count: int = 8) -> np.ndarray:
    """The lowest ``count`` frequencies (Hz) of the pinned-pinned Timoshenko coupler of
    ``elements`` elements (shear factor: the paper's 0.8 unless given)."""
    d = P["diameter"]
    area, i2 = math.pi * d * d / 4, math.pi * d**4 / 64
    g = P["youngs_modulus"] / (2 * (1 + P["poisson_ratio"]))
    k = P["shear_factor"] if shear_factor is None else shear_factor
    inv = fi.beam_invariants(P["coupler_length"], elements, P["density"], P["youngs_modulus"], area, i2,
                             shear_stiffness=k * g, rotary_inertia=True)
    import scipy.linalg as sla

    lam = sla.eigh(inv["k_ff"], inv["m_ff"], eigvals_only=True, subset_by_index=[0, count - 1])
    return np.sqrt(lam) / (2 * math.pi)


def scene(data: FlexibleData, strain: str = "linear") -> Scene:
    """The paper's slider-crank (scenes.slider_crank) with ``data`` as the coupler."""
    L, Lb, d, om = P["crank_length"], P["coupler_length"], P["diameter"], P["omega"]
    m_crank = P["density"] * math.pi * d * d / 4 * L
    s = Scene(gravity=(0.0, -P["g"]))
    crank = s.rigid_body("crank", mass=m_crank, inertia=m_crank * L * L / 12, com=(L / 2, 0.0), angular_velocity=om)
    cp = s.flexible_body("coupler", data, strain=strain if strain == "nonlinear" else None, position=(L, 0.0),
                         velocity=(0.0, L * om), angular_velocity=-L * om / Lb)
    s.revolute(s.ground.point(0.0, 0.0), crank.point(0.0, 0.0), name="crank_pivot")
    s.revolute(crank.point(L, 0.0), cp.marker("A"), name="crank_coupler")
    s.point_on_line(cp.marker("B"), s.ground.line((0.0, 0.0), angle=0.0), name="slider")
    s.angle_driver(crank.frame(), ConstantSpeed(om, initial=0.0), name="crank_speed")
    return s


def peak(t: np.ndarray, w: np.ndarray) -> float:
    window = t <= WINDOW + 1e-12
    return float(np.max(np.abs(w[window])))


def run_flexible(data: FlexibleData, strain: str = "linear", rtol: float = 1e-8) -> Dict[str, Any]:
    system = scene(data, strain).build()
    t0 = time.perf_counter()
    res = simulate(system, WINDOW, method="DOPRI5", rtol=rtol, atol=1e-3 * rtol)
    wall = time.perf_counter() - t0
    qf = np.array([res.coordinate(f"coupler.qf{i}") for i in range(data.n_f)])
    v = np.asarray(data.markers["M"].displacement)[1] @ qf
    return dict(peak=peak(res.t, v / P["coupler_length"]), wall=wall, nfev=int(getattr(res, "nfev", -1)),
                t=np.asarray(res.t), v=v / P["coupler_length"])


def run_beam(elements: int, strain: str = "linear", rtol: float = 1e-8) -> Dict[str, Any]:
    system = scenes.slider_crank(elements=elements, strain=strain).build()
    t0 = time.perf_counter()
    res = simulate(system, WINDOW, method="DOPRI5", rtol=rtol, atol=1e-3 * rtol)
    wall = time.perf_counter() - t0
    _, v = res.beam_displacement("coupler", 0.5)
    return dict(peak=peak(res.t, v / P["coupler_length"]), wall=wall, t=np.asarray(res.t), v=v / P["coupler_length"])


def study(elements: int = 8, ks=(2, 4, 8), strain: str = "linear", rtol: float = 1e-8,
          modal_derivatives: Any = False, nodal: bool = True) -> List[Dict[str, Any]]:
    """Peak error of the k-mode coupler vs the built-in beam (same elements, same strain).
    ``modal_derivatives`` is passed to :func:`ukflex.fe.reduce` (nonlinear strain: ``True`` or
    the number of modes differentiated); ``nodal`` adds the unreduced model's row."""
    ref = run_beam(elements, strain, rtol)
    rows = [dict(model=f"built-in beam N={elements}", k=None, n_f=None, peak=ref["peak"], error=0.0, wall=ref["wall"],
                 f_max=None)]
    full = coupler_data(elements, None, strain)
    for k in ks:
        progress("flexible-coupler", f"{k} modes of the {elements}-element coupler")
        data = fe.reduce(full, k, modal_derivatives=modal_derivatives)
        r = run_flexible(data, strain, rtol)
        rows.append(dict(model=f"flexible k={k}", k=k, n_f=data.n_f, peak=r["peak"],
                         error=abs(r["peak"] - ref["peak"]) / ref["peak"], wall=r["wall"],
                         f_max=float(data.info["frequencies"][-1] / (2 * math.pi))))
    if nodal:
        r = run_flexible(full, strain, rtol)
        rows.append(dict(model=f"flexible nodal n_f={full.n_f}", k=full.n_f, n_f=full.n_f, peak=r["peak"],
                         error=abs(r["peak"] - ref["peak"]) / ref["peak"], wall=r["wall"], f_max=None))
    return rows


#: Meshes of the coupler study (quads: nx along, ny through the height).
MESHES = ((8, 1), (16, 1), (32, 2), (64, 4))


def mesh_study(meshes=MESHES, ks=(2, 4, 8), order: int = 2, cells: str = "quad", beam_elements: int = 16,
               rtol: float = 1e-8, strain: str = "linear", modal_derivatives: Any = False) -> Dict[str, Any]:
    """The coupler from a plane-stress mesh (:func:`mesh_coupler_data`), reduced to ``k`` modes,
    against the built-in beam of ``beam_elements`` elements (linear strain): for every mesh the
    four lowest frequencies and, for every ``k``, the peak ``|v(0.5)|/Lb``, its error and the
    wall time of the run; ``error_k`` is the error against the same ``k`` modes of the 32-element
    Timoshenko beam (the modelling difference alone, without the modal truncation; linear only).

    ``strain="nonlinear"``: Green-Lagrange strain for the mesh (:func:`ukflex.fe.from_mesh`, with
    ``modal_derivatives``), the built-in beam's nonlinear strain for the reference; each ``k``
    builds its own basis (the derivatives depend on the modes kept)."""
    ref = run_beam(beam_elements, strain, rtol)
    beam_k: Dict[int, float] = {}
    if strain == "linear":
        beam32 = coupler_data(32)
        beam_k = {k: run_flexible(fe.reduce(beam32, k), "linear", rtol)["peak"] for k in ks}
    rows = []
    for nx, ny in meshes:
        progress("flexible-coupler", f"mesh {nx}x{ny}: build and reduce")
        t0 = time.perf_counter()
        data = mesh_coupler_data(nx, ny, order, max(ks), cells)
        build = time.perf_counter() - t0
        row: Dict[str, Any] = dict(mesh=(nx, ny), dofs=int(data.info["modes"].shape[0]), build=build,
                                   frequencies=data.info["frequencies"][:4] / (2 * math.pi), runs=[])
        for k in ks:
            if strain == "linear":
                dk = fe.reduce(data, k)
            else:
                dk = mesh_coupler_data(nx, ny, order, k, cells, "nonlinear", modal_derivatives)
            progress("flexible-coupler", f"mesh {nx}x{ny}: {k} modes")
            r = run_flexible(dk, strain, rtol)
            row["runs"].append(dict(k=k, n_f=dk.n_f, peak=r["peak"], error=abs(r["peak"] - ref["peak"]) / ref["peak"],
                                    error_k=abs(r["peak"] - beam_k[k]) / beam_k[k] if beam_k else None, wall=r["wall"]))
        rows.append(row)
    return dict(beam=ref, beam_elements=beam_elements, beam_k=beam_k, rows=rows)


def figure(path: str, k: int = 4, modal_derivatives: Any = 2, rtol: float = 1e-8) -> None:
    """Midpoint deflection over 0-0.07 s: the built-in beam N = 8 (linear and nonlinear strain)
    and the k-mode coupler with nonlinear strain, without and with modal derivatives."""
    from ukflex.results.plotting import figure as new_figure

    nodal = coupler_data(8, None, "nonlinear")
    curves = [("built-in beam N=8, linear strain", run_beam(8, "linear", rtol), dict(color="0.6", lw=2.5)),
              ("built-in beam N=8, nonlinear strain", run_beam(8, "nonlinear", rtol), dict(color="k", lw=2.5)),
              (f"{k} modes, nonlinear strain", run_flexible(fe.reduce(nodal, k), "nonlinear", rtol), dict(color="C3")),
              (f"{k} modes + modal derivatives, nonlinear strain",
               run_flexible(fe.reduce(nodal, k, modal_derivatives=modal_derivatives), "nonlinear", rtol),
               dict(color="C0", ls="--"))]
    fig = new_figure((7.0, 3.8), "the flexible coupler figure")
    ax = fig.add_subplot(1, 1, 1)
    for label, r, style in curves:
        ax.plot(1e3 * r["t"], r["v"], label=label, **style)
    ax.set_xlabel("t [ms]")
    ax.set_ylabel("v(0.5) / Lb")
    ax.set_xlim(0.0, 1e3 * WINDOW)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower left")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def _print_mesh_study(out: Dict[str, Any]) -> None:
    fb = beam_frequencies(32)
    print(f"built-in beam N={out['beam_elements']}: peak |v(0.5)|/Lb {out['beam']['peak']:.6e}  {out['beam']['wall']:.1f} s")
    if out["beam_k"]:
        print("Timoshenko beam N=32 reduced to k modes: " + "  ".join(f"k={k}: {v:.6e}" for k, v in out["beam_k"].items()))
    print("Timoshenko beam N=32 frequencies (Hz): k=0.8 " + " ".join(f"{f:.2f}" for f in fb[:4])
          + ";  Cowper rectangle k=" + f"{10 * (1 + P['poisson_ratio']) / (12 + 11 * P['poisson_ratio']):.3f} "
          + " ".join(f"{f:.2f}" for f in beam_frequencies(32, 10 * (1 + P["poisson_ratio"]) / (12 + 11 * P["poisson_ratio"]))[:4]))
    for row in out["rows"]:
        fr = " ".join(f"{f:.2f}" for f in row["frequencies"])  # of the linear model
        print(f"mesh {row['mesh'][0]}x{row['mesh'][1]} ({row['dofs']} dofs, built in {row['build']:.1f} s): f {fr} Hz")
        for r in row["runs"]:
            ek = "" if r["error_k"] is None else f" (vs beam N=32, k modes: {r['error_k']:.2e})"
            print(f"    k={r['k']} (n_f {r['n_f']}): peak {r['peak']:.6e}  rel. error {r['error']:.2e}{ek}  {r['wall']:.2f} s")


def main(argv: Optional[List[str]] = None) -> int:
    """``python -m studies flexible-coupler [--nonlinear] [--mesh] [--modal-derivatives[=K]] [--figure PNG]``."""
    import sys

    argv = sys.argv[1:] if argv is None else list(argv)
    if "--figure" in argv:
        figure(argv[argv.index("--figure") + 1])
        return 0
    strain = "nonlinear" if "--nonlinear" in argv else "linear"
    md: Any = False
    for a in argv:
        if a.startswith("--modal-derivatives"):
            md = True if a == "--modal-derivatives" else int(a.split("=")[1])
    if "--mesh" in argv:
        if strain == "linear":
            _print_mesh_study(mesh_study())
        else:
            _print_mesh_study(mesh_study(meshes=((32, 2),), strain="nonlinear", modal_derivatives=md))
        return 0
    for row in study(strain=strain, modal_derivatives=md, nodal=strain == "linear"):
        fmax = "" if row["f_max"] is None else f"  f_max {row['f_max']:.0f} Hz"
        nf = "" if row["n_f"] is None else f"  n_f {row['n_f']}"
        print(f"{row['model']:26s}{nf} peak |v(0.5)|/Lb {row['peak']:.6e}  rel. error {row['error']:.2e}  {row['wall']:.2f} s{fmax}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
