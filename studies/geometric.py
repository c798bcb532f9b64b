"""Geometric nonlinearity of the paper's coupler at speed (issue 11, item 4; ``python -m studies
geometric``, ``docs/geometric-nonlinearity.md``).

The paper's slider-crank with four coupler models (:data:`MODELS`): the paper's linear FFRF
beam, the nonlinear FFRF beam (second-order axial strain averaged per element, Euler-Bernoulli
and Timoshenko) and the geometrically exact ANCF cable, each with ``N = 1, 2, 4, 8, 16``
elements, over the crank speeds ``omega/10 .. 5 omega`` and the thinner sections ``d/2, d/4``
(:data:`CASES`), side by side with Exudyn's geometrically exact models (the committed
``benches/data/exudyn_*.csv``; E-B models against its ANCF cable, Timoshenko models against its
geometrically exact beam with shear and rotary inertia).

Every case uses the same crank-angle window: the peak is ``max |v(0.5)|/Lb`` over
``0 <= omega t <= 8.736 rad`` (the paper's 0..0.07 s), on a 1e-5 s output grid (the elastic
periods do not scale with omega) refined by the parabola through the three samples around the
discrete maximum (:func:`refined_peak`; at a window end the sample value is kept); the runs go
on to 12.48 rad (0.1 s at the paper speed) for the history metrics and the post-buckling
behaviour.

Parts (:func:`run_geometric` writes them all into one directory):

* (a) peaks against speed and section with element convergence (``runs.csv``, ``speeds.png``,
  ``convergence.png``), time-discretization check (the same runs at a tighter tolerance or half
  the step);
* (b) the coupler's axial force (largest element compression) against the Euler load
  ``pi^2 E I / Lb^2`` (``axial.csv``, ``axial.png``);
* (c) the extreme-catalogue cases speed x3/x5 and ``d/2``, ``d/4`` with the nonlinear models:
  peak, ``max |v|/Lb`` over 0..12.48 rad, whether the run finished, model and mesh spread
  (``extreme.csv``, ``extreme.png``);
* (d) cost at the paper speed (wall time against the error to the converged answer;
  ``cost.csv``, ``cost.png``) and the model-choice table;
* the targets of issue 11 (``targets.csv``) and ``summary.md`` with every table.

Only the public API is used (:func:`ukflex.scenes.slider_crank`, :func:`ukflex.simulate`,
``System.axial_forces``, ``System.beam_shape``, ``System.body_info``).
"""

from __future__ import annotations

import csv
import math
import os
import statistics
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Dict, Iterable, List, Optional, Sequence, Tuple

import numpy as np

from ukflex import UkflexError, scenes, simulate
from ukflex.benchmarks.machine import machine_info, machine_line

PAPER = scenes.PAPER

__all__ = [
    "Model",
    "Case",
    "Integrator",
    "Run",
    "MODELS",
    "CASES",
    "PAPER_CASE",
    "EXTREME_CASES",
    "FULL",
    "QUICK",
    "WINDOW_ANGLE",
    "HISTORY_ANGLE",
    "refined_peak",
    "history_error",
    "load_exudyn",
    "default_exudyn_dir",
    "run_one",
    "axial_forces",
    "euler_load",
    "membrane_locking_index",
    "run_geometric",
]

OMEGA = PAPER["omega"]
LB = PAPER["coupler_length"]
#: Peak window in crank angle: the paper's 0..0.07 s at 124.8 rad/s.
WINDOW_ANGLE = 0.07 * OMEGA
#: History window in crank angle: 0..0.1 s at the paper's speed (Exudyn's references span it).
HISTORY_ANGLE = 0.1 * OMEGA
#: Output grid [s], the same for every speed (the elastic periods do not scale with omega).
OUTPUT_STEP = 1e-5
#: Two runs peak on the same lobe when their crank angles at the peak differ by less than this
#: (2 ms at the paper speed; the lobes are ~0.4 rad or more apart).
SAME_LOBE_ANGLE = 2e-3 * OMEGA
#: Accuracy level of issue 11's targets and of the model-choice table.
LEVEL = 5e-3


@dataclass(frozen=True)
class Model:
    """A coupler model: ``scene`` is passed to :func:`ukflex.scenes.slider_crank`; ``reference``
    names the Exudyn model it is compared with (like with like)."""

    key: str
    label: str
    scene: Dict[str, Any]
    reference: str
    style: str = "-"


MODELS: Dict[str, Model] = {m.key: m for m in (
    Model("linear-ffrf", "linear FFRF (E-B)", {"strain": "linear", "theory": "euler-bernoulli"}, "ancf", ":"),
    Model("nonlinear-ffrf", "nonlinear FFRF (E-B)", {"strain": "nonlinear", "theory": "euler-bernoulli"}, "ancf", "-"),
    Model("nonlinear-ffrf-timoshenko", "nonlinear FFRF (Timoshenko)", {"strain": "nonlinear", "theory": "timoshenko"},
          "ge", "-."),
    Model("ancf", "ANCF cable (E-B)", {"formulation": "ancf"}, "ancf", "--"),
)}
NONLINEAR = ("nonlinear-ffrf", "nonlinear-ffrf-timoshenko", "ancf")
EXUDYN_LABEL = {"ancf": "Exudyn ANCF cable", "ge": "Exudyn GE beam (shear, rotary inertia)"}


@dataclass(frozen=True)
class Case:
    """Crank speed ``speed x 124.8 rad/s`` and coupler diameter ``diameter x 6.35 mm``; ``name``
    as in ``exudyn_speeds.csv``."""

    name: str
    speed: float = 1.0
    diameter: float = 1.0

    @property
    def omega(self) -> float:
        return OMEGA * self.speed

    @property
    def t_window(self) -> float:
        return WINDOW_ANGLE / self.omega

    @property
    def t_history(self) -> float:
        return HISTORY_ANGLE / self.omega


SPEEDS = (0.1, 0.5, 1.0, 2.0, 3.0, 5.0)
CASES: List[Case] = [Case(f"omega x{s:g}", s, 1.0) for s in SPEEDS] + [Case("d/2", 1.0, 0.5), Case("d/4", 1.0, 0.25)]
PAPER_CASE = CASES[2]
EXTREME_CASES = ("omega x3", "omega x5", "d/2", "d/4")
AXIAL_CASES = ("omega x1", "omega x2", "omega x3")
#: Bow amplitudes of the locking illustration: about the peaks at omega, 2 omega, 3 omega.
LOCKING_AMPLITUDES = (0.0098, 0.055, 0.16)


@dataclass(frozen=True)
class Integrator:
    """``method`` with ``rtol`` (DOPRI5) or a fixed ``step`` (GENALPHA, ``rho_inf``)."""

    method: str
    rtol: float = 1e-8
    step: Optional[float] = None
    rho_inf: float = 0.9

    def options(self) -> Dict[str, Any]:
        kw: Dict[str, Any] = {"method": self.method, "rtol": self.rtol, "max_steps": 100_000_000}
        if self.method == "GENALPHA":
            kw.update(step=self.step, rho_inf=self.rho_inf)
        return kw

    @property
    def label(self) -> str:
        if self.method == "GENALPHA":
            return f"GENALPHA h={self.step:g} rho_inf={self.rho_inf:g}"
        return f"{self.method} rtol={self.rtol:g}"


#: The study's integrator: DOPRI5 resolves the undamped axial ripple like Exudyn's references do
#: (generalized-alpha at h = 7.8e-7 s); it is stability-limited here, so its tolerance costs little.
FULL = Integrator("DOPRI5", rtol=1e-8)
FULL_CHECK = Integrator("DOPRI5", rtol=1e-10)
#: ``--quick``: generalized-alpha with a fixed step (a preview, ~0.1 % on the peak).
QUICK = Integrator("GENALPHA", rtol=1e-8, step=2.5e-5)
QUICK_CHECK = Integrator("GENALPHA", rtol=1e-8, step=1.25e-5)


@dataclass
class Run:
    """One simulation: the midpoint history ``v`` (= v(0.5)/Lb) and its metrics."""

    model: str
    case: Case
    elements: int
    integrator: str
    purpose: str = "sweep"
    t: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    v: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    compression: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)  # max element compression / P_cr
    axial_mean: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)  # mean axial force / P_cr
    compression_smooth: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)  # over one axial period
    axial_mean_smooth: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    success: bool = False
    message: str = ""
    t_end: float = 0.0
    peak: float = float("nan")
    t_peak: float = float("nan")
    at_window_end: bool = False
    max_abs: float = float("nan")
    wall: float = float("nan")
    nfev: int = 0
    max_residual: float = float("nan")
    euler_load: float = float("nan")
    max_compression: float = float("nan")
    angle_max_compression: float = float("nan")
    axial_at_peak: float = float("nan")
    max_compression_smooth: float = float("nan")
    axial_min: float = float("nan")  # smoothed mean axial force / P_cr over the peak window
    axial_max: float = float("nan")
    axial_period: float = float("nan")  # first axial period of the fixed-free coupler, 4 Lb / sqrt(E / rho)
    max_psi: float = float("nan")  # largest |rotation| of the end cross-sections against the beam/chord frame [rad]

    @property
    def angle_peak(self) -> float:
        return self.t_peak * self.case.omega

    @property
    def finished(self) -> bool:
        return self.success and self.t.size > 0 and self.t[-1] >= self.t_end * (1 - 1e-9) and bool(np.all(np.isfinite(self.v)))


# ----------------------------------------------------------------------------------- metrics
def refined_peak(t: np.ndarray, y: np.ndarray, t_max: Optional[float] = None) -> Tuple[float, float]:
    """``max |y|`` over ``t <= t_max`` with parabolic refinement around the discrete maximum.

    Returns ``(peak, time of peak)``.  The parabola goes through the three samples around the
    discrete maximum of ``|y|`` (uniform or not); at the window's ends the sample value is kept.
    (The Exudyn scripts in ``benches/peers`` use this function too.)
    """
    t = np.asarray(t, float)
    a = np.abs(np.asarray(y, float))
    if t_max is not None:
        keep = t <= t_max * (1.0 + 1e-12)
        t, a = t[keep], a[keep]
    if a.size == 0 or not np.any(np.isfinite(a)):
        return float("nan"), float("nan")
    k = int(np.nanargmax(a))
    if k == 0 or k == len(a) - 1:
        return float(a[k]), float(t[k])
    t0, t1, t2 = t[k - 1], t[k], t[k + 1]
    y0, y1, y2 = a[k - 1], a[k], a[k + 1]
    d0 = (t0 - t1) * (t0 - t2)
    d1 = (t1 - t0) * (t1 - t2)
    d2 = (t2 - t0) * (t2 - t1)
    c2 = y0 / d0 + y1 / d1 + y2 / d2
    c1 = -(y0 * (t1 + t2) / d0 + y1 * (t0 + t2) / d1 + y2 * (t0 + t1) / d2)
    c0 = y0 * t1 * t2 / d0 + y1 * t0 * t2 / d1 + y2 * t0 * t1 / d2
    if c2 >= 0.0:
        return float(y1), float(t1)
    tv = -c1 / (2.0 * c2)
    if not (t0 <= tv <= t2):
        return float(y1), float(t1)
    return float(c0 + c1 * tv + c2 * tv * tv), float(tv)


def _interpolate(t_ref: np.ndarray, v_ref: np.ndarray, t: np.ndarray) -> np.ndarray:
    from scipy.interpolate import CubicSpline

    return CubicSpline(t_ref, v_ref)(t)


def history_error(t: np.ndarray, v: np.ndarray, t_ref: np.ndarray, v_ref: np.ndarray, ref_peak: float,
                  t_max: Optional[float] = None) -> float:
    """``max |v - v_ref|`` over ``t <= t_max`` (and the reference's span) divided by
    ``ref_peak``; the reference is interpolated by a cubic spline at the times ``t``."""
    t = np.asarray(t, float)
    v = np.asarray(v, float)
    end = min(t_max if t_max is not None else t_ref[-1], t_ref[-1]) * (1 + 1e-12)
    keep = t <= end
    if not np.any(keep):
        return float("nan")
    return float(np.max(np.abs(v[keep] - _interpolate(t_ref, v_ref, t[keep]))) / ref_peak)


# ----------------------------------------------------------------------------------- Exudyn data
def default_exudyn_dir() -> Path:
    """``benches/data`` of the source tree this package was loaded from."""
    return Path(__file__).resolve().parents[1] / "benches" / "data"


def _read_reference(path: Path) -> Dict[str, Any]:
    meta: Dict[str, str] = {}
    t, v = [], []
    with open(path) as fh:
        for line in fh:
            if line.startswith("#"):
                if ":" in line:
                    k, val = line[1:].split(":", 1)
                    meta[k.strip()] = val.strip()
                continue
            if line.startswith("t,"):
                continue
            a, b = line.split(",")
            t.append(float(a))
            v.append(float(b))
    tt, vv = np.array(t), np.array(v)
    peak, t_peak = refined_peak(tt, vv, 0.07)
    if "peak_0_0.07s" in meta:  # the reference's own peak, from its 7.8e-7 s step grid
        word = meta["peak_0_0.07s"].split()
        peak, t_peak = float(word[0]), float(word[word.index("t") + 2])
    return {"t": tt, "v": vv, "peak": peak, "t_peak": t_peak, "meta": meta}


def _read_csv(path: Path) -> List[Dict[str, str]]:
    with open(path) as fh:
        return list(csv.DictReader(line for line in fh if not line.startswith("#")))


def load_exudyn(data_dir: Optional[os.PathLike] = None) -> Optional[Dict[str, Any]]:
    """Exudyn's committed results, or None when the directory or a file is missing.

    Returns ``{"ancf": ref, "ge": ref, "speeds": {(case, model): row}, "timing": [rows], "dir": path}``;
    a ``ref`` holds ``t``, ``v`` (v(0.5)/Lb on a 1e-5 s grid, 0..0.1 s), ``peak``, ``t_peak``, ``meta``.
    """
    d = Path(data_dir) if data_dir is not None else default_exudyn_dir()
    files = {"ancf": "exudyn_ref_ancf.csv", "ge": "exudyn_ref_ge.csv", "speeds": "exudyn_speeds.csv",
             "timing": "exudyn_timing.csv"}
    if not all((d / f).is_file() for f in files.values()):
        return None
    out: Dict[str, Any] = {"dir": d}
    out["ancf"] = _read_reference(d / files["ancf"])
    out["ge"] = _read_reference(d / files["ge"])
    out["speeds"] = {(r["case"], r["model"]): r for r in _read_csv(d / files["speeds"])}
    out["timing"] = _read_csv(d / files["timing"])
    return out


def _exudyn_peak(exudyn: Optional[Dict[str, Any]], case: Case, ref: str) -> float:
    if exudyn is None:
        return float("nan")
    row = exudyn["speeds"].get((case.name, ref))
    if case is PAPER_CASE or case.name == PAPER_CASE.name:
        return float(exudyn[ref]["peak"])  # the converged N = 32, h = 7.8e-7 reference
    return float(row["peak"]) if row else float("nan")


# ----------------------------------------------------------------------------------- runs
def euler_load(system: Any, body: str = "coupler") -> float:
    """``pi^2 E I / L^2`` of ``body`` from ``System.body_info``."""
    info = system.body_info(body)
    return math.pi**2 * float(info["youngs_modulus"]) * float(info["second_moment"]) / float(info["length"]) ** 2


def axial_forces(system: Any, q: np.ndarray, body: str = "coupler") -> np.ndarray:
    """Axial force (tension positive) per element at every state of ``q`` (nt, n) -> (nt, N).

    FFRF beams: ``System.axial_forces`` (constant per element).  ANCF cables: ``E A (|r'| - 1)``
    at each element's midpoint, ``r'`` from ``System.beam_shape`` (the slope rows map the body's
    coordinates to ``r'``).
    """
    info = system.body_info(body)
    q = np.atleast_2d(np.asarray(q, float))
    if info["formulation"] == "ffrf":
        return np.array([np.asarray(system.axial_forces(body, qi), float) for qi in q])
    start, stop = system.body_slices[body]
    e = q[:, start:stop]
    n_el = int(info["elements"])
    ea = float(info["youngs_modulus"]) * float(info["area"])
    cols = []
    for k in range(n_el):
        _, slope = system.beam_shape(body, (k + 0.5) / n_el)
        r = e @ np.asarray(slope, float).T
        cols.append(ea * (np.hypot(r[:, 0], r[:, 1]) - 1.0))
    return np.column_stack(cols)


def axial_period(system: Any, body: str = "coupler") -> float:
    """First axial period of ``body`` as a fixed-free bar, ``4 L / sqrt(E / rho)`` [s] (the ripple the
    undeformed start sets ringing: the crank end is held, the slider end is free axially)."""
    info = system.body_info(body)
    return 4.0 * float(info["length"]) / math.sqrt(float(info["youngs_modulus"]) / float(info["density"]))


def _smooth(x: np.ndarray, n: int) -> np.ndarray:
    """Centred moving average over ``n`` samples (shorter at the ends)."""
    if n <= 1 or x.size == 0:
        return x.copy()
    k = np.ones(n)
    num = np.convolve(np.nan_to_num(x), k, mode="same")
    den = np.convolve(np.isfinite(x).astype(float), k, mode="same")
    with np.errstate(invalid="ignore", divide="ignore"):
        out = num / den
    out[~np.isfinite(x)] = np.nan
    return out


def _scene(model: str, elements: int, case: Case):
    m = MODELS[model]
    return scenes.slider_crank(elements=elements, omega=case.omega, diameter=PAPER["diameter"] * case.diameter,
                               gravity=True, **m.scene)


def run_one(model: str, elements: int, case: Case = PAPER_CASE, integrator: Integrator = FULL,
            angle: float = HISTORY_ANGLE, output_step: float = OUTPUT_STEP, axial: bool = True,
            purpose: str = "sweep") -> Run:
    """Simulate ``model`` with ``elements`` coupler elements for ``case`` over ``0..angle`` of
    crank angle and extract the metrics (peak over :data:`WINDOW_ANGLE`, ``max |v|``, axial
    force).  A run that stops early (integrator failure, non-finite state) keeps what it
    computed, ``finished`` is False and ``message`` says why."""
    system = _scene(model, elements, case).build()
    t_end = angle / case.omega
    n = int(math.floor(t_end / output_step + 1e-9))
    te = np.arange(n + 1) * output_step
    if te[-1] < t_end * (1 - 1e-12):
        te = np.append(te, t_end)
    r = Run(model=model, case=case, elements=elements, integrator=integrator.label, purpose=purpose, t_end=t_end)
    r.euler_load = euler_load(system)
    r.axial_period = axial_period(system)
    try:
        res = simulate(system, t_end, t_eval=te, **integrator.options())
    except (UkflexError, ArithmeticError, ValueError) as exc:  # a failed step names the problem
        r.message = f"{type(exc).__name__}: {exc}"
        return r
    r.success, r.message, r.wall, r.nfev = bool(res.success), str(res.message), float(res.wall_time), int(res.nfev)
    r.t = np.asarray(res.t, float)
    if r.t.size == 0:
        return r
    _, v = res.beam_displacement("coupler", 0.5)
    r.v = np.asarray(v, float) / LB
    finite = np.all(np.isfinite(res.q), axis=0)
    if not np.all(finite):
        r.success = False
        r.message = (r.message + "; " if r.message else "") + f"non-finite state at t = {r.t[np.argmin(finite)]:.6g} s"
    r.peak, r.t_peak = refined_peak(r.t, r.v, case.t_window)
    r.at_window_end = bool(abs(r.t_peak - min(case.t_window, r.t[-1])) < 0.5 * output_step)
    r.max_abs = float(np.nanmax(np.abs(r.v)))
    w_all = r.t <= case.t_window * (1 + 1e-12)
    r.max_psi = float(max(np.nanmax(np.abs(res.beam_rotation("coupler", xi)[w_all])) for xi in (0.0, 1.0)))
    res_pos = np.asarray(res.residuals["position"], float)
    r.max_residual = float(np.nanmax(res_pos)) if res_pos.size else float("nan")
    if axial:
        P = axial_forces(system, np.asarray(res.q).T[finite]) / r.euler_load
        comp = np.full(r.t.size, np.nan)
        mean = np.full(r.t.size, np.nan)
        comp[finite] = np.maximum(-P.min(axis=1), 0.0)
        mean[finite] = P.mean(axis=1)
        r.compression, r.axial_mean = comp, mean
        n_avg = max(1, int(round(r.axial_period / output_step)))
        r.compression_smooth, r.axial_mean_smooth = _smooth(comp, n_avg), _smooth(mean, n_avg)
        w = r.t <= case.t_window * (1 + 1e-12)
        k = int(np.nanargmax(comp[w]))
        r.max_compression, r.angle_max_compression = float(comp[k]), float(r.t[k] * case.omega)
        r.max_compression_smooth = float(np.nanmax(r.compression_smooth[w]))
        r.axial_min, r.axial_max = float(np.nanmin(r.axial_mean_smooth[w])), float(np.nanmax(r.axial_mean_smooth[w]))
        if np.isfinite(r.t_peak):
            r.axial_at_peak = float(r.axial_mean_smooth[int(np.argmin(np.abs(r.t - r.t_peak)))])
    return r


# ----------------------------------------------------------------------------------- locking
def membrane_locking_index(elements: Sequence[int], amplitude: float, slenderness: float = LB / PAPER["diameter"]
                           ) -> List[Dict[str, float]]:
    """Spurious membrane energy of a point-by-point second-order strain, relative to the bending
    energy, for a half-sine bow ``v = amplitude Lb sin(pi x / Lb)`` of a circular rod
    (``Lb / d = slenderness``) on ``N`` elements with linear ``u`` and cubic Hermite ``v``.

    With ``eps(x) = u' + v'^2 / 2`` and ``u`` linear per element, the best ``u`` (inextensional
    bending) leaves ``eps = v'^2/2 - mean_e(v'^2/2)``, which cannot vanish point by point: the
    element stores ``U_m = E A / 2 int eps^2`` that a bending element should not (membrane
    locking).  The element-averaged strain (constant axial force per element) is exactly zero
    for this bow.  Returns rows ``{"elements", "U_m/U_b"}`` (``U_b = E I / 2 int v''^2``);
    pure NumPy, independent of the core.
    """
    g, w = np.polynomial.legendre.leggauss(6)
    d = 1.0 / slenderness  # lengths in units of Lb
    area_over_inertia = (math.pi * d * d / 4.0) / (math.pi * d**4 / 64.0)
    out = []
    for n_el in elements:
        le = 1.0 / n_el
        xs = np.linspace(0.0, 1.0, n_el + 1)
        vn = amplitude * np.sin(math.pi * xs)
        tn = amplitude * math.pi * np.cos(math.pi * xs)
        um = ub = 0.0
        for k in range(n_el):
            s = 0.5 * (g + 1.0)  # 0..1 on the element
            # Hermite cubic derivatives (d/dx, element length le)
            dN = np.array([(-6 * s + 6 * s * s) / le, 1 - 4 * s + 3 * s * s, (6 * s - 6 * s * s) / le, -2 * s + 3 * s * s])
            ddN = np.array([(-6 + 12 * s) / le**2, (-4 + 6 * s) / le, (6 - 12 * s) / le**2, (-2 + 6 * s) / le])
            nodal = np.array([vn[k], tn[k], vn[k + 1], tn[k + 1]])
            vp, vpp = nodal @ dN, nodal @ ddN
            wq = 0.5 * le * w
            half = 0.5 * vp * vp
            eps = half - np.sum(wq * half) / le
            um += area_over_inertia * np.sum(wq * eps * eps)
            ub += np.sum(wq * vpp * vpp)
        out.append({"elements": n_el, "U_m/U_b": float(um / ub)})
    return out


# ----------------------------------------------------------------------------------- study
def _log_default(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def _fmt(x: float, spec: str = ".4e") -> str:
    return "-" if x is None or not np.isfinite(x) else format(x, spec)


def _pct(x: float, spec: str = "+.3f") -> str:
    return "-" if x is None or not np.isfinite(x) else format(100.0 * x, spec) + " %"


def _rel(a: float, b: float) -> float:
    return a / b - 1.0 if (np.isfinite(a) and np.isfinite(b) and b != 0) else float("nan")


def _downsample(n: int, target: int = 2000) -> np.ndarray:
    step = max(1, int(math.ceil(n / target)))
    idx = np.arange(0, n, step)
    return idx if idx[-1] == n - 1 else np.append(idx, n - 1)


def _md_table(header: Sequence[str], rows: Iterable[Sequence[Any]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def _write_csv(path: Path, fields: Sequence[str], rows: Iterable[Dict[str, Any]], comments: Sequence[str] = ()) -> None:
    with open(path, "w", newline="") as fh:
        for c in comments:
            fh.write(f"# {c}\n")
        w = csv.DictWriter(fh, fieldnames=list(fields), extrasaction="ignore")
        w.writeheader()
        for row in rows:
            w.writerow({k: (f"{v:.9g}" if isinstance(v, float) else v) for k, v in row.items()})


RUN_FIELDS = ["purpose", "model", "case", "omega", "diameter", "elements", "integrator", "finished", "message", "peak",
              "t_peak", "angle_peak", "at_window_end", "max_abs_v", "max_psi", "max_compression_ratio", "angle_max_compression",
              "axial_at_peak_ratio", "euler_load", "max_position_residual", "wall_s", "nfev", "exudyn_reference",
              "exudyn_peak", "peak_vs_exudyn", "hist_vs_exudyn", "peak_vs_finest", "hist_vs_finest"]


def _run_row(r: Run, exudyn: Optional[Dict[str, Any]], finest: Optional[Run]) -> Dict[str, Any]:
    m = MODELS[r.model]
    ex = _exudyn_peak(exudyn, r.case, m.reference)
    row = {"purpose": r.purpose, "model": r.model, "case": r.case.name, "omega": r.case.omega,
           "diameter": PAPER["diameter"] * r.case.diameter, "elements": r.elements, "integrator": r.integrator,
           "finished": int(r.finished), "message": r.message.replace("\n", " ")[:200], "peak": r.peak, "t_peak": r.t_peak,
           "angle_peak": r.angle_peak, "at_window_end": int(r.at_window_end), "max_abs_v": r.max_abs,
           "max_psi": r.max_psi, "max_compression_ratio": r.max_compression, "angle_max_compression": r.angle_max_compression,
           "axial_at_peak_ratio": r.axial_at_peak, "euler_load": r.euler_load, "max_position_residual": r.max_residual,
           "wall_s": r.wall, "nfev": r.nfev, "exudyn_reference": m.reference, "exudyn_peak": ex,
           "peak_vs_exudyn": _rel(r.peak, ex), "hist_vs_exudyn": float("nan"),
           "peak_vs_finest": _rel(r.peak, finest.peak) if finest is not None else float("nan"),
           "hist_vs_finest": float("nan")}
    if exudyn is not None and r.case.name == PAPER_CASE.name and r.t.size:
        ref = exudyn[m.reference]
        row["hist_vs_exudyn"] = history_error(r.t, r.v, ref["t"], ref["v"], ref["peak"], 0.1)
    if finest is not None and finest is not r and r.t.size and finest.t.size:
        n = min(r.t.size, finest.t.size)
        if np.allclose(r.t[:n], finest.t[:n]):
            row["hist_vs_finest"] = float(np.nanmax(np.abs(r.v[:n] - finest.v[:n])) / finest.peak)
    return row


@dataclass
class _Config:
    elements: Tuple[int, ...]
    check_elements: Tuple[int, ...]
    integrator: Integrator
    check_integrator: Integrator
    time_check: Tuple[Tuple[str, int, str], ...]  # (model, N, case name | "*")
    cost_elements: Tuple[int, ...]
    cost_integrators: Tuple[Integrator, ...]
    cost_models: Tuple[str, ...]
    repeats: int


def _config(quick: bool) -> _Config:
    if quick:
        return _Config(elements=(1, 2, 4), check_elements=(), integrator=QUICK, check_integrator=QUICK_CHECK,
                       time_check=(("nonlinear-ffrf", 4, PAPER_CASE.name), ("ancf", 4, PAPER_CASE.name)),
                       cost_elements=(2, 4),
                       cost_integrators=(Integrator("GENALPHA", step=1e-4), Integrator("GENALPHA", step=5e-5)),
                       cost_models=("nonlinear-ffrf", "ancf"), repeats=1)
    return _Config(elements=(1, 2, 4, 8, 16), check_elements=(32,), integrator=FULL, check_integrator=FULL_CHECK,
                   time_check=(("nonlinear-ffrf", 4, "*"), ("ancf", 4, "*"), ("nonlinear-ffrf-timoshenko", 4, PAPER_CASE.name),
                               ("nonlinear-ffrf", 16, PAPER_CASE.name), ("ancf", 16, PAPER_CASE.name)),
                   cost_elements=(1, 2, 4, 8),
                   cost_integrators=(Integrator("DOPRI5", rtol=1e-6), Integrator("GENALPHA", step=2e-4),
                                     Integrator("GENALPHA", step=1e-4), Integrator("GENALPHA", step=5e-5),
                                     Integrator("GENALPHA", step=2.5e-5)),
                   cost_models=("linear-ffrf", "nonlinear-ffrf", "nonlinear-ffrf-timoshenko", "ancf"), repeats=3)


def run_geometric(out: os.PathLike, quick: bool = False, *, models: Optional[Sequence[str]] = None,
                  elements: Optional[Sequence[int]] = None, cases: Optional[Sequence[str]] = None,
                  exudyn_data: Optional[os.PathLike] = None, checks: bool = True, cost: bool = True,
                  plot: bool = True, log: Callable[[str], None] = _log_default) -> Dict[str, Any]:
    """Run the study and write its CSVs, PNGs and ``summary.md`` into ``out``.

    ``quick``: ``N = 1, 2, 4`` with generalized-alpha (h = 2.5e-5 s), a reduced cost table, no
    ``N = 32`` check (about a minute).  Full: ``N = 1..16`` with DOPRI5 at rtol 1e-8, ``N = 32``
    at the paper speed, the tolerance check at rtol 1e-10, the full cost table.
    ``models``, ``elements``, ``cases`` (names of :data:`CASES`) restrict the sweep (tests);
    ``checks`` / ``cost`` switch off the time-discretization/N = 32 checks and the cost table.
    Returns the summary data (runs, targets, tables).
    """
    t_start = time.perf_counter()
    info = machine_info()
    outdir = Path(out)
    outdir.mkdir(parents=True, exist_ok=True)
    cfg = _config(quick)
    model_keys = list(models) if models is not None else list(MODELS)
    for m in model_keys:
        if m not in MODELS:
            raise ValueError(f"unknown model {m!r}; models are {list(MODELS)}")
    el = tuple(sorted(set(int(n) for n in elements))) if elements is not None else cfg.elements
    case_list = [c for c in CASES if cases is None or c.name in cases]
    if cases is not None and len(case_list) != len(set(cases)):
        raise ValueError(f"unknown case in {list(cases)}; cases are {[c.name for c in CASES]}")
    exudyn = load_exudyn(exudyn_data)
    if exudyn is None:
        log(f"Exudyn data not found in {exudyn_data or default_exudyn_dir()}: no side-by-side columns")

    # (a) the sweep ---------------------------------------------------------------------------
    runs: Dict[Tuple[str, str, int], Run] = {}
    for case in case_list:
        for m in model_keys:
            for n in el:
                r = run_one(m, n, case, cfg.integrator)
                runs[(m, case.name, n)] = r
                log(f"{case.name:>10} {m:<26} N={n:<3} peak {_fmt(r.peak)} at {_fmt(r.angle_peak, '.3f')} rad, "
                    f"max|v| {_fmt(r.max_abs, '.3e')}, P/Pcr {_fmt(r.max_compression, '.3f')}, "
                    f"{'ok' if r.finished else 'STOPPED: ' + r.message[:60]}, {r.wall:.2f} s")
    finest_n = max(el)
    finest = {(m, c.name): runs[(m, c.name, finest_n)] for m in model_keys for c in case_list}

    extra: List[Run] = []
    if checks and PAPER_CASE in case_list:
        for n in cfg.check_elements:
            for m in model_keys:
                if m in NONLINEAR:
                    r = run_one(m, n, PAPER_CASE, cfg.integrator, purpose="check-elements")
                    extra.append(r)
                    log(f"N check {m} N={n}: peak {_fmt(r.peak)} ({r.wall:.1f} s)")
        for m, n, cname in cfg.time_check:
            if m not in model_keys or n not in el:
                continue
            for case in case_list:
                if cname != "*" and case.name != cname:
                    continue
                r = run_one(m, n, case, cfg.check_integrator, purpose="check-time")
                extra.append(r)
                base = runs[(m, case.name, n)]
                log(f"time check {m} N={n} {case.name}: peak change {_pct(_rel(base.peak, r.peak), '+.5f')} ({r.wall:.1f} s)")

    rows = [_run_row(r, exudyn, finest.get((r.model, r.case.name))) for r in list(runs.values()) + extra]
    _write_csv(outdir / "runs.csv", RUN_FIELDS, rows, comments=[
        "python -m studies geometric: paper slider-crank, gravity on, peak = max |v(0.5)|/Lb over crank angle 0..8.736 rad "
        "(parabolic refinement on a 1e-5 s grid), runs to 12.48 rad",
        "peak_vs_exudyn: against Exudyn's ANCF cable (E-B models) or GE beam (Timoshenko), converged; hist_vs_exudyn "
        "(paper speed only): max |v - v_ref| over 0..0.1 s / reference peak; *_vs_finest: against the same model at "
        f"N = {finest_n}; compression ratios: largest element compression / (pi^2 E I / Lb^2) over the peak window",
        f"integrator: {cfg.integrator.label}; check runs: {cfg.check_integrator.label}; machine: {machine_line(info)}"])

    # time-discretization check summary
    time_checks = []
    for r in extra:
        if r.purpose != "check-time":
            continue
        base = runs[(r.model, r.case.name, r.elements)]
        n = min(base.t.size, r.t.size)
        hist = float(np.nanmax(np.abs(base.v[:n] - r.v[:n])) / r.peak) if n else float("nan")
        time_checks.append({"model": r.model, "case": r.case.name, "elements": r.elements, "integrator": base.integrator,
                            "check": r.integrator, "peak": base.peak, "peak_check": r.peak,
                            "peak_change": _rel(base.peak, r.peak), "history_change": hist})
    n_checks = [r for r in extra if r.purpose == "check-elements"]

    # (b) axial forces --------------------------------------------------------------------------
    axial_rows = []
    for (m, cname), r in finest.items():
        if r.compression.size == 0 or cname not in AXIAL_CASES or m == "nonlinear-ffrf-timoshenko":
            continue
        for i in _downsample(r.t.size, 600):
            axial_rows.append({"case": cname, "model": m, "elements": r.elements, "t": float(f"{r.t[i]:.6g}"),
                               "angle": float(f"{r.t[i] * r.case.omega:.5g}"), "v": float(f"{r.v[i]:.6g}"),
                               "max_compression_ratio": float(f"{r.compression[i]:.5g}"),
                               "max_compression_ratio_smooth": float(f"{r.compression_smooth[i]:.5g}"),
                               "mean_axial_ratio_smooth": float(f"{r.axial_mean_smooth[i]:.5g}")})
    _write_csv(outdir / "axial.csv", ["case", "model", "elements", "t", "angle", "v", "max_compression_ratio",
                                       "max_compression_ratio_smooth", "mean_axial_ratio_smooth"], axial_rows,
               comments=["coupler histories of the finest mesh at 1, 2, 3 omega (every k-th output, <= 600 per run): "
                         "v = v(0.5)/Lb; largest element compression / (pi^2 E I / Lb^2), raw and averaged over one "
                         "axial period 4 Lb / sqrt(E / rho) (the ripple of the undeformed start removed); mean axial force "
                         "over the elements, averaged likewise (tension +); ANCF: E A (|r'| - 1) at the element midpoints"])

    # (c) extreme cases -------------------------------------------------------------------------
    extreme_rows = []
    for cname in EXTREME_CASES:
        case = next((c for c in case_list if c.name == cname), None)
        if case is None:
            continue
        for m in model_keys:
            for n in el:
                r = runs[(m, cname, n)]
                ex = exudyn["speeds"].get((cname, MODELS[m].reference)) if exudyn else None
                extreme_rows.append({
                    "case": cname, "model": m, "elements": n, "finished": int(r.finished), "message": r.message[:120],
                    "peak": r.peak, "angle_peak": r.angle_peak, "at_window_end": int(r.at_window_end),
                    "max_abs_v": r.max_abs, "max_compression_ratio": r.max_compression,
                    "exudyn_peak": float(ex["peak"]) if ex else float("nan"),
                    "exudyn_max_abs_v": float(ex["max_abs_v_history"]) if ex else float("nan"),
                    "peak_vs_exudyn": _rel(r.peak, float(ex["peak"])) if ex else float("nan"),
                    "max_abs_vs_exudyn": _rel(r.max_abs, float(ex["max_abs_v_history"])) if ex else float("nan"),
                    "sign_changes": _sign_changes(r.v, 0.05), "wall_s": r.wall})
    _write_csv(outdir / "extreme.csv", ["case", "model", "elements", "finished", "message", "peak", "angle_peak",
                                         "at_window_end", "max_abs_v", "max_compression_ratio", "exudyn_peak",
                                         "exudyn_max_abs_v", "peak_vs_exudyn", "max_abs_vs_exudyn", "sign_changes",
                                         "wall_s"], extreme_rows,
               comments=["extreme-catalogue cases with every model: peak over 0..8.736 rad, max |v|/Lb over 0..12.48 rad; "
                         "sign_changes: times v(0.5) changes sign between excursions beyond 0.05 Lb (flips of the bow)"])

    # (d) cost at the paper speed ---------------------------------------------------------------
    cost_rows: List[Dict[str, Any]] = []
    if cost and PAPER_CASE in case_list:
        cost_rows = _cost_table(cfg, [m for m in cfg.cost_models if m in model_keys],
                                {m: finest[(m, PAPER_CASE.name)] for m in model_keys}, exudyn, log)
        _write_csv(outdir / "cost.csv", ["model", "elements", "integrator", "wall_median_s", "wall_min_s", "repeats",
                                         "peak", "t_peak", "peak_err", "hist_err", "same_lobe", "peak_err_exudyn",
                                         "hist_err_exudyn"], cost_rows,
                   comments=["paper speed, 0..0.1 s, integration wall time (System.integrate, build excluded), median of "
                             "repeats; errors against the same model's finest run of the sweep (peak over 0..0.07 s, "
                             "history over 0..0.1 s relative to the peak) and against Exudyn's reference",
                             f"machine: {machine_line(info)}"])

    targets = _targets(runs, finest, n_checks, exudyn, el, model_keys, case_list)
    _write_csv(outdir / "targets.csv", ["target", "measured", "limit", "met", "note"], targets)
    locking = {a: membrane_locking_index((1, 2, 4, 8, 16), amplitude=a) for a in LOCKING_AMPLITUDES}

    summary = {"runs": runs, "extra": extra, "rows": rows, "finest": finest, "time_checks": time_checks,
               "extreme": extreme_rows, "cost": cost_rows, "targets": targets, "locking": locking, "config": cfg,
               "models": model_keys, "cases": case_list, "elements": el, "exudyn": exudyn, "quick": quick}
    if plot:
        _plots(outdir, summary)
    summary["wall_total"] = time.perf_counter() - t_start
    summary["machine_start"], summary["machine_end"] = info, machine_info()
    (outdir / "summary.md").write_text(_summary_md(summary))
    log(f"wrote {outdir / 'summary.md'} ({summary['wall_total']:.0f} s)")
    return summary


def _sign_changes(v: np.ndarray, level: float) -> int:
    """How often v changes sign between excursions beyond +-level."""
    s = 0
    count = 0
    for x in v:
        if not np.isfinite(x):
            break
        if x > level:
            count += s == -1
            s = 1
        elif x < -level:
            count += s == 1
            s = -1
    return int(count)


def _cost_table(cfg: _Config, models: Sequence[str], converged: Dict[str, Run], exudyn: Optional[Dict[str, Any]],
                log: Callable[[str], None]) -> List[Dict[str, Any]]:
    """Wall time against the error to the converged answer at the paper speed over 0..0.1 s."""
    configs = [(m, n, integ) for m in models for n in cfg.cost_elements for integ in cfg.cost_integrators]
    walls: Dict[int, List[float]] = {i: [] for i in range(len(configs))}
    first: Dict[int, Run] = {}
    for rep in range(cfg.repeats):
        order = range(len(configs)) if rep % 2 == 0 else reversed(range(len(configs)))
        for i in order:
            m, n, integ = configs[i]
            r = run_one(m, n, PAPER_CASE, integ, axial=False, purpose="cost")
            walls[i].append(r.wall)
            first.setdefault(i, r)
    rows = []
    for i, (m, n, integ) in enumerate(configs):
        r, conv = first[i], converged[m]
        row = {"model": m, "elements": n, "integrator": integ.label, "wall_median_s": statistics.median(walls[i]),
               "wall_min_s": min(walls[i]), "repeats": len(walls[i]), "peak": r.peak, "t_peak": r.t_peak,
               "peak_err": _rel(r.peak, conv.peak),
               "hist_err": float(np.nanmax(np.abs(r.v - conv.v[:r.v.size])) / conv.peak) if r.finished else float("nan"),
               "same_lobe": int(abs(r.angle_peak - conv.angle_peak) < SAME_LOBE_ANGLE),
               "peak_err_exudyn": float("nan"), "hist_err_exudyn": float("nan")}
        if exudyn is not None and r.finished:
            ref = exudyn[MODELS[m].reference]
            row["peak_err_exudyn"] = _rel(r.peak, ref["peak"])
            row["hist_err_exudyn"] = history_error(r.t, r.v, ref["t"], ref["v"], ref["peak"], 0.1)
        rows.append(row)
        log(f"cost {m} N={n} {integ.label}: {row['wall_median_s']:.3f} s, peak {_pct(row['peak_err'])}, "
            f"history {_pct(row['hist_err'], '.3f')}")
    return rows


def _cheapest(rows: Sequence[Dict[str, Any]], model: str, key: str, level: float = LEVEL) -> Optional[Dict[str, Any]]:
    """The fastest configuration within ``level``, not by chance (same lobe, history within 10 x level)."""
    ok = [r for r in rows if r["model"] == model and np.isfinite(r[key]) and abs(r[key]) <= level and r["same_lobe"]
          and np.isfinite(r["hist_err"]) and r["hist_err"] <= 10 * level]
    return min(ok, key=lambda r: r["wall_median_s"]) if ok else None


# ----------------------------------------------------------------------------------- targets
def _targets(runs, finest, n_checks, exudyn, el, model_keys, case_list) -> List[Dict[str, Any]]:
    out: List[Dict[str, Any]] = []
    nmax = max(el)
    names = [c.name for c in case_list]

    def add(target, measured, limit, note="", signed=True):
        met = "yes" if (np.isfinite(measured) and abs(measured) <= limit) else ("no" if np.isfinite(measured) else "n/a")
        out.append({"target": target, "measured": _pct(measured, "+.3f" if signed else ".3f"), "limit": f"{100 * limit:g} %",
                    "met": met, "note": note})

    if PAPER_CASE.name in names and exudyn is not None:
        for m in ("nonlinear-ffrf", "ancf", "nonlinear-ffrf-timoshenko"):
            if m not in model_keys:
                continue
            r = finest[(m, PAPER_CASE.name)]
            ref = exudyn[MODELS[m].reference]
            add(f"{MODELS[m].label} N={nmax} vs {EXUDYN_LABEL[MODELS[m].reference]}: peak", _rel(r.peak, ref["peak"]), LEVEL)
            add(f"{MODELS[m].label} N={nmax} vs {EXUDYN_LABEL[MODELS[m].reference]}: history 0..0.1 s (of the peak)",
                history_error(r.t, r.v, ref["t"], ref["v"], ref["peak"], 0.1), LEVEL, signed=False)
    if PAPER_CASE.name in names and {"nonlinear-ffrf", "ancf"} <= set(model_keys):
        a, b = finest[("nonlinear-ffrf", PAPER_CASE.name)], finest[("ancf", PAPER_CASE.name)]
        add(f"nonlinear FFRF (E-B) vs ANCF, both N={nmax}, paper-scene peak", _rel(a.peak, b.peak), 3e-3)
    if "omega x0.1" in names and "linear-ffrf" in model_keys:
        lin = finest[("linear-ffrf", "omega x0.1")]
        for m in ("nonlinear-ffrf", "ancf"):
            if m in model_keys:
                add(f"{MODELS[m].label} vs linear FFRF (E-B) at omega/10, N={nmax}: peak",
                    _rel(finest[(m, "omega x0.1")].peak, lin.peak), 1.5e-2)
    if PAPER_CASE.name in names and "nonlinear-ffrf" in model_keys:
        conv = finest[("nonlinear-ffrf", PAPER_CASE.name)]
        for n in el:
            if n <= 4 and n < nmax:
                r = runs[("nonlinear-ffrf", PAPER_CASE.name, n)]
                same = abs(r.angle_peak - conv.angle_peak) < SAME_LOBE_ANGLE
                note = "" if same else "peak on another lobe (crank angle %.2f vs %.2f rad)" % (r.angle_peak, conv.angle_peak)
                if n == max(k for k in el if k <= 4 and k < nmax):
                    add(f"nonlinear FFRF (E-B) N={n} vs its N={nmax} value, paper-scene peak", _rel(r.peak, conv.peak),
                        LEVEL, note)
                else:
                    out.append({"target": f"(info) nonlinear FFRF (E-B) N={n} vs its N={nmax} value, paper-scene peak",
                                "measured": _pct(_rel(r.peak, conv.peak)), "limit": "-", "met": "-", "note": note})
    for r in n_checks:
        base = finest[(r.model, r.case.name)]
        out.append({"target": f"(check) {MODELS[r.model].label} N={nmax} vs N={r.elements}, paper-scene peak",
                    "measured": _pct(_rel(base.peak, r.peak)), "limit": "-", "met": "-", "note": "element convergence"})
    return out


# ----------------------------------------------------------------------------------- plots
COLORS = {"linear-ffrf": "tab:gray", "nonlinear-ffrf": "tab:blue", "nonlinear-ffrf-timoshenko": "tab:green",
          "ancf": "tab:red"}


def _figure(w: float = 7.0, h: float = 4.2, rows: int = 1, cols: int = 1, **kw):
    from ukflex.results.plotting import figure

    fig = figure((w, h), "the geometric study's plots (--no-plot skips them)", dpi=90)
    axes = fig.subplots(rows, cols, squeeze=False, **kw)
    return fig, axes


def _save(fig, path: Path) -> None:
    fig.tight_layout()
    fig.savefig(str(path), dpi=90)


def _plots(outdir: Path, s: Dict[str, Any]) -> None:
    finest, runs, exudyn, models, el = s["finest"], s["runs"], s["exudyn"], s["models"], s["elements"]
    names = [c.name for c in s["cases"]]
    speed_cases = [c for c in s["cases"] if c.diameter == 1.0]
    # (a) peak vs speed
    if len(speed_cases) > 1:
        fig, ax = _figure(7.0, 6.0, 2, 1, sharex=True)
        x = [c.speed for c in speed_cases]
        for m in models:
            ax[0, 0].loglog(x, [finest[(m, c.name)].peak for c in speed_cases], MODELS[m].style, marker="o", ms=3,
                            color=COLORS[m], label=f"{MODELS[m].label}, N={max(el)}")
            ax[1, 0].semilogx(x, [100 * _rel(finest[(m, c.name)].peak, _exudyn_peak(exudyn, c, MODELS[m].reference))
                                  for c in speed_cases], MODELS[m].style, marker="o", ms=3, color=COLORS[m])
        if exudyn is not None:
            for ref, mk in (("ancf", "x"), ("ge", "+")):
                ax[0, 0].loglog(x, [_exudyn_peak(exudyn, c, ref) for c in speed_cases], mk, color="k", ms=7,
                                label=EXUDYN_LABEL[ref])
        ax[0, 0].set_ylabel("peak |v(0.5)|/Lb, crank angle 0..8.74 rad")
        ax[0, 0].legend(fontsize=7)
        ax[0, 0].grid(True, which="both", alpha=0.3)
        ax[1, 0].axhline(0.0, color="k", lw=0.5)
        ax[1, 0].set_yscale("symlog", linthresh=1.0)
        ax[1, 0].set_ylabel("vs Exudyn (E-B: ANCF, Tim.: GE) [%]")
        ax[1, 0].set_xlabel("crank speed / 124.8 rad/s")
        ax[1, 0].grid(True, which="both", alpha=0.3)
        _save(fig, outdir / "speeds.png")
    # (a) element convergence at the paper speed
    if PAPER_CASE.name in names and len(el) > 1:
        fig, ax = _figure(7.0, 4.0)
        for m in models:
            ref = exudyn[MODELS[m].reference]["peak"] if exudyn is not None else finest[(m, PAPER_CASE.name)].peak
            ns = list(el) + [r.elements for r in s["extra"] if r.purpose == "check-elements" and r.model == m]
            pk = [runs[(m, PAPER_CASE.name, n)].peak for n in el] + [r.peak for r in s["extra"]
                                                                    if r.purpose == "check-elements" and r.model == m]
            ax[0, 0].semilogx(ns, [100 * _rel(p, ref) for p in pk], MODELS[m].style, marker="o", ms=3, color=COLORS[m],
                              label=MODELS[m].label, base=2)
        ax[0, 0].axhspan(-100 * LEVEL, 100 * LEVEL, color="0.9", zorder=0)
        ax[0, 0].set_ylim(-25, 10)
        ax[0, 0].set_xlabel("coupler elements N")
        ax[0, 0].set_ylabel("peak vs Exudyn reference [%]" if exudyn is not None else "peak vs finest N [%]")
        ax[0, 0].set_title("paper speed: element convergence (band: +-0.5 %)", fontsize=9)
        ax[0, 0].legend(fontsize=7)
        ax[0, 0].grid(True, which="both", alpha=0.3)
        _save(fig, outdir / "convergence.png")
    if PAPER_CASE.name in names:  # the paper-speed history against Exudyn
        fig, ax = _figure(7.0, 5.5, 2, 1, sharex=True)
        for m in models:
            r = finest[(m, PAPER_CASE.name)]
            ax[0, 0].plot(r.t, r.v, MODELS[m].style, color=COLORS[m], lw=1, label=f"{MODELS[m].label}, N={max(el)}")
            if exudyn is not None:
                ref = exudyn[MODELS[m].reference]
                w = r.t <= ref["t"][-1] * (1 + 1e-12)
                ax[1, 0].plot(r.t[w], 100 * (r.v[w] - _interpolate(ref["t"], ref["v"], r.t[w])) / ref["peak"],
                              MODELS[m].style, color=COLORS[m], lw=0.8)
        if exudyn is not None:
            ax[0, 0].plot(exudyn["ancf"]["t"], exudyn["ancf"]["v"], color="k", lw=0.6, alpha=0.6, label=EXUDYN_LABEL["ancf"])
        ax[0, 0].set_ylabel("v(0.5)/Lb")
        ax[0, 0].legend(fontsize=7)
        ax[0, 0].grid(True, alpha=0.3)
        ax[1, 0].set_ylabel("minus Exudyn, % of its peak")
        ax[1, 0].set_ylim(-3, 3)
        ax[1, 0].set_xlabel("t [s] (paper speed; 0.1 s = 12.48 rad)")
        ax[1, 0].grid(True, alpha=0.3)
        _save(fig, outdir / "paper_history.png")
    # (b) axial force
    ax_cases = [c for c in AXIAL_CASES if c in names]
    axial_models = [m for m in ("nonlinear-ffrf", "ancf", "linear-ffrf") if m in models]
    if ax_cases and axial_models:
        fig, ax = _figure(7.0, 2.2 * len(ax_cases) + 0.6, len(ax_cases), 1, sharex=True)
        for i, cname in enumerate(ax_cases):
            for m in axial_models:
                r = finest[(m, cname)]
                if r.axial_mean.size:
                    if m == "nonlinear-ffrf":  # the raw force, with the ripple of the undeformed start
                        ax[i, 0].plot(r.t * r.case.omega, r.axial_mean, color=COLORS[m], lw=0.3, alpha=0.25)
                    ax[i, 0].plot(r.t * r.case.omega, r.axial_mean_smooth, MODELS[m].style, color=COLORS[m], lw=1.0,
                                  label=f"{MODELS[m].label}")
            ax[i, 0].axhline(-1.0, color="k", lw=0.5)
            ax[i, 0].set_ylabel(f"{cname}\nN / P_cr")
            ax[i, 0].grid(True, alpha=0.3)
        ax[0, 0].legend(fontsize=7)
        ax[0, 0].set_title("mean axial force / Euler load (tension +), averaged over one axial period; light: raw",
                           fontsize=8)
        ax[-1, 0].set_xlabel("crank angle [rad]")
        _save(fig, outdir / "axial.png")
    # (c) extreme cases
    ex_cases = [c for c in EXTREME_CASES if c in names]
    if ex_cases:
        fig, ax = _figure(8.0, 5.5, 2, 2)
        for i, cname in enumerate(ex_cases):
            a = ax[i // 2, i % 2]
            for m in models:
                r = finest[(m, cname)]
                a.plot(r.t * r.case.omega, r.v, MODELS[m].style, color=COLORS[m], lw=0.8, label=MODELS[m].label)
            a.axvline(WINDOW_ANGLE, color="k", lw=0.5, ls=":")
            a.set_title(f"{cname}, N = {max(el)}", fontsize=9)
            a.grid(True, alpha=0.3)
            a.set_xlabel("crank angle [rad]", fontsize=8)
            a.set_ylabel("v(0.5)/Lb", fontsize=8)
        ax[0, 0].legend(fontsize=6)
        _save(fig, outdir / "extreme.png")
    # (d) cost
    if s["cost"]:
        fig, ax = _figure(7.0, 4.2)
        for m in sorted(set(r["model"] for r in s["cost"])):
            rows = [r for r in s["cost"] if r["model"] == m and np.isfinite(r["peak_err"])]
            ax[0, 0].loglog([r["wall_median_s"] for r in rows], [max(abs(r["peak_err"]), 1e-6) for r in rows], "o",
                            color=COLORS[m], ms=4, label=MODELS[m].label, alpha=0.8)
        ax[0, 0].axhline(LEVEL, color="k", lw=0.5, ls="--")
        ax[0, 0].set_xlabel("wall time of the run [s] (0..0.1 s simulated)")
        ax[0, 0].set_ylabel("|peak error| vs the converged model")
        ax[0, 0].legend(fontsize=7)
        ax[0, 0].grid(True, which="both", alpha=0.3)
        _save(fig, outdir / "cost.png")


# ----------------------------------------------------------------------------------- summary
def _summary_md(s: Dict[str, Any]) -> str:
    finest, runs, exudyn, models, el = s["finest"], s["runs"], s["exudyn"], s["models"], s["elements"]
    cases = s["cases"]
    names = [c.name for c in cases]
    nmax = max(el)
    cfg: _Config = s["config"]
    L: List[str] = []
    L.append("# Geometric nonlinearity study: summary")
    L.append("")
    cmd = "python -m studies geometric --out DIR" + (" --quick" if s["quick"] else "")
    L.append(f"Written by `{cmd}` in {s['wall_total']:.0f} s. Integrator: {cfg.integrator.label} "
             f"(checks: {cfg.check_integrator.label}). Machine: {machine_line(s['machine_start'])}; load average at the "
             f"end {s['machine_end']['load_average'][0]:.2f}.")
    L.append("")
    L.append("Peak = max |v(0.5)|/Lb over crank angle 0..8.736 rad, parabolic refinement on a 1e-5 s grid; "
             "max |v| over 0..12.48 rad. Exudyn: `benches/data/exudyn_speeds.csv` (N = 32, h = 6.25e-6) and, at the "
             "paper speed, the converged references `exudyn_ref_*.csv` (N = 32, h = 7.8e-7). E-B models are compared "
             "with Exudyn's ANCF cable, the Timoshenko model with its GE beam." if exudyn is not None else
             "Exudyn data not found: no side-by-side columns.")
    L.append("")

    # (a)
    L.append("## (a) Peak against speed and section")
    L.append("")
    hdr = ["case"] + [f"{MODELS[m].label}, N={nmax}" for m in models]
    if exudyn is not None:
        hdr += ["Exudyn ANCF", "Exudyn GE"]
    body = []
    for c in cases:
        row = [c.name]
        for m in models:
            r = finest[(m, c.name)]
            ex = _exudyn_peak(exudyn, c, MODELS[m].reference)
            mark = " (window end)" if r.at_window_end else ""
            row.append(f"{_fmt(r.peak)}{mark} ({_pct(_rel(r.peak, ex), '+.2f')})" if exudyn is not None
                       else f"{_fmt(r.peak)}{mark}")
        if exudyn is not None:
            row += [_fmt(_exudyn_peak(exudyn, c, "ancf")), _fmt(_exudyn_peak(exudyn, c, "ge"))]
        body.append(row)
    L.append(_md_table(hdr, body))
    L.append("")
    L.append("In brackets: against Exudyn's like model. \"window end\": the largest |v| of the window is at its end.")
    L.append("")
    L.append("### Element convergence")
    L.append("")
    L.append("Peak per N (crank angle of the peak in brackets), and the change of the finest N from the next coarser one. "
             "A mesh counts as converged when the next refinement changes the peak by less than 0.1 %.")
    L.append("")
    for c in cases:
        hdr = ["model"] + [f"N={n}" for n in el] + [f"N={nmax} vs N={el[-2]}" if len(el) > 1 else "-",
                                                    "smallest N within 0.5 % / 0.1 % of the finest"]
        body = []
        for m in models:
            rs = [runs[(m, c.name, n)] for n in el]
            fin = rs[-1]
            cells = [f"{_fmt(r.peak)} ({_fmt(r.angle_peak, '.2f')})" + ("" if r.finished else " stopped") for r in rs]
            ch = _pct(_rel(fin.peak, rs[-2].peak), "+.3f") if len(rs) > 1 else "-"

            def smallest(level):
                for r in rs:
                    if abs(_rel(r.peak, fin.peak)) <= level and abs(r.angle_peak - fin.angle_peak) < SAME_LOBE_ANGLE:
                        return str(r.elements)
                return "-"

            body.append([MODELS[m].label] + cells + [ch, f"{smallest(LEVEL)} / {smallest(1e-3)}"])
        L.append(f"**{c.name}**")
        L.append("")
        L.append(_md_table(hdr, body))
        L.append("")
    if s["extra"]:
        nc = [r for r in s["extra"] if r.purpose == "check-elements"]
        if nc:
            L.append("Finer mesh at the paper speed: " + "; ".join(
                f"{MODELS[r.model].label} N={r.elements}: {_fmt(r.peak)}, N={nmax} differs by "
                f"{_pct(_rel(finest[(r.model, PAPER_CASE.name)].peak, r.peak))}" for r in nc) + ".")
            L.append("")
    if s["time_checks"]:
        L.append("### Time discretization")
        L.append("")
        L.append(_md_table(["model", "case", "N", "study run", "check run", "peak change", "history change (of the peak)"],
                           [[MODELS[t['model']].label, t["case"], t["elements"], t["integrator"], t["check"],
                             _pct(t["peak_change"], "+.5f"), _pct(t["history_change"], ".5f")] for t in s["time_checks"]]))
        L.append("")
    if PAPER_CASE.name in names and exudyn is not None:
        L.append("### Paper speed against Exudyn's converged references (every N)")
        L.append("")
        body = []
        for m in models:
            ref = exudyn[MODELS[m].reference]
            for n in el:
                r = runs[(m, PAPER_CASE.name, n)]
                body.append([MODELS[m].label, n, _fmt(r.peak), _fmt(r.t_peak, ".5f"), _pct(_rel(r.peak, ref["peak"])),
                             _pct(history_error(r.t, r.v, ref["t"], ref["v"], ref["peak"], 0.1), ".3f"),
                             f"{r.wall:.2f}"])
        L.append(_md_table(["model", "N", "peak", "t_peak [s]", "peak vs Exudyn", "history 0..0.1 s vs Exudyn",
                            "wall [s]"], body))
        L.append("")
        L.append(f"Exudyn references: ANCF cable {_fmt(exudyn['ancf']['peak'])} at {exudyn['ancf']['t_peak']:.5f} s, "
                 f"GE beam {_fmt(exudyn['ge']['peak'])} at {exudyn['ge']['t_peak']:.5f} s.")
        L.append("")

    # (b)
    L.append("## (b) Axial force of the coupler")
    L.append("")
    any_run = next((r for (m, c), r in finest.items() if c == PAPER_CASE.name), next(iter(finest.values())))
    L.append("Axial force over the Euler load P_cr = pi^2 E I / Lb^2 (%.4g N for the paper's section), peak window. "
             "The undeformed start sets the first axial mode ringing (period 4 Lb / sqrt(E/rho) = %.3g ms, undamped): "
             "\"raw\" is the largest element compression with that ripple, \"smooth\" the same averaged over one axial "
             "period; the range is that of the smoothed mean axial force (tension +), and the last column the smoothed "
             "mean axial force at the time of the peak." % (any_run.euler_load, 1e3 * any_run.axial_period))
    L.append("")
    body = []
    for c in cases:
        for m in models:
            rs = [runs[(m, c.name, n)] for n in el]
            f = rs[-1]
            body.append([c.name, MODELS[m].label, _fmt(f.euler_load, ".4g")]
                        + [f"{_fmt(r.max_compression, '.3f')} / {_fmt(r.max_compression_smooth, '.3f')}" for r in rs]
                        + [f"{_fmt(f.axial_min, '+.3f')} .. {_fmt(f.axial_max, '+.3f')}", _fmt(f.axial_at_peak, "+.3f")])
    L.append(_md_table(["case", "model", "P_cr [N]"] + [f"N={n}: raw / smooth" for n in el]
                       + [f"N/P_cr range, N={nmax}", "N/P_cr at the peak"], body))
    L.append("")
    w1 = _bending_frequency()
    L.append("First bending frequency of the pinned-pinned coupler (paper section, no axial force): omega_1 = pi^2 "
             f"sqrt(E I / (rho A Lb^4)) = {w1:.4g} rad/s = {w1 / OMEGA:.3g} x the paper's crank speed; an axial force P "
             "moves it to omega_1 sqrt(1 + P/P_cr) and the quasi-static bow to 1 / (1 + P/P_cr) of the linear one. "
             "Over the paper-speed window: " + "; ".join(
                 f"{MODELS[m].label}: sqrt(1 + P/P_cr) from {math.sqrt(max(0.0, 1 + finest[(m, PAPER_CASE.name)].axial_min)):.3f}"
                 f" to {math.sqrt(max(0.0, 1 + finest[(m, PAPER_CASE.name)].axial_max)):.3f}"
                 for m in models if PAPER_CASE.name in names and np.isfinite(finest[(m, PAPER_CASE.name)].axial_min)) + ".")
    L.append("")

    # (c)
    if s["extreme"]:
        L.append("## (c) Extreme-catalogue cases with the nonlinear models")
        L.append("")
        body = []
        for e in s["extreme"]:
            if e["elements"] not in (el[-1], el[len(el) // 2]):
                continue
            body.append([e["case"], MODELS[e["model"]].label, e["elements"], "yes" if e["finished"] else "NO: " + e["message"],
                         _fmt(e["peak"]) + (" (window end)" if e["at_window_end"] else ""),
                         _fmt(e["angle_peak"], ".2f"), _fmt(e["max_abs_v"]), _fmt(e["max_compression_ratio"], ".2f"),
                         e["sign_changes"], _pct(e["peak_vs_exudyn"], "+.2f"), _pct(e["max_abs_vs_exudyn"], "+.2f")])
        L.append(_md_table(["case", "model", "N", "finished", "peak 0..8.74 rad", "angle [rad]", "max |v| 0..12.48 rad",
                            "max P/P_cr", "bow flips", "peak vs Exudyn", "max |v| vs Exudyn"], body))
        L.append("")
        spread = []
        for cname in EXTREME_CASES:
            if cname not in names:
                continue
            nl = [finest[(m, cname)] for m in models if m in NONLINEAR]
            pk = [r.peak for r in nl if np.isfinite(r.peak)]
            if len(pk) > 1:
                spread.append(f"{cname}: nonlinear models' peaks span {_pct(max(pk) / min(pk) - 1, '.2f')} "
                              f"({', '.join(MODELS[r.model].label + ' ' + _fmt(r.peak, '.4f') for r in nl)})")
        if spread:
            L.append("Spread at N = %d: " % nmax + "; ".join(spread) + ".")
            L.append("")
        if exudyn is not None:
            L.append("Exudyn (exudyn_speeds.csv): " + "; ".join(
                f"{cn}: ANCF {_fmt(float(exudyn['speeds'][(cn, 'ancf')]['peak']), '.4f')} / GE "
                f"{_fmt(float(exudyn['speeds'][(cn, 'ge')]['peak']), '.4f')}, max |v| "
                f"{_fmt(float(exudyn['speeds'][(cn, 'ancf')]['max_abs_v_history']), '.3f')} / "
                f"{_fmt(float(exudyn['speeds'][(cn, 'ge')]['max_abs_v_history']), '.3f')}"
                for cn in EXTREME_CASES if (cn, "ancf") in exudyn["speeds"]) + ".")
            L.append("")

    # (d)
    L.append("## (d) Which model when")
    L.append("")
    pick = _pick_rows(s)
    if pick:
        L.append(f"Per case, sorted by the axial load (largest element compression, smoothed over one axial period, "
                 f"nonlinear FFRF): the peak error of each model (N = {nmax}) against the geometrically exact answer "
                 "(Exudyn's ANCF cable; our ANCF cable where Exudyn has no case), the crank angle of each peak, the "
                 f"largest end-section rotation of our ANCF cable over the window, and which models are within "
                 f"{100 * LEVEL:g} % on the same lobe.")
        L.append("")
        L.append(_md_table(["case", "max compression / P_cr (smoothed)", "exact peak |v|/Lb", "at crank angle",
                            "max end rotation psi [rad]"]
                           + [f"{MODELS[m].label}: peak error (angle)" for m in models if m != "nonlinear-ffrf-timoshenko"]
                           + ["within 0.5 %, same lobe"], pick))
        L.append("")
    if s["cost"]:
        L.append("### Cost at the paper speed (0..0.1 s)")
        L.append("")
        L.append(_md_table(["model", "N", "integrator", "wall median [s]", "peak err", "history err", "same lobe",
                            "peak vs Exudyn", "history vs Exudyn"],
                           [[MODELS[r['model']].label, r["elements"], r["integrator"], f"{r['wall_median_s']:.3f}",
                             _pct(r["peak_err"]), _pct(r["hist_err"], ".3f"), "yes" if r["same_lobe"] else "NO",
                             _pct(r["peak_err_exudyn"]), _pct(r["hist_err_exudyn"], ".3f")] for r in s["cost"]]))
        L.append("")
        L.append("Errors against the same model's finest run of the sweep. Cheapest configuration within 0.5 % "
                 "(not by chance: same lobe as the converged peak and history error below 5 %):")
        L.append("")
        body = []
        for m in sorted(set(r["model"] for r in s["cost"]), key=list(MODELS).index):
            conv = finest[(m, PAPER_CASE.name)]
            pk = _cheapest(s["cost"], m, "peak_err")
            hs = _cheapest(s["cost"], m, "hist_err")
            body.append([MODELS[m].label, f"{_fmt(conv.peak)} (N={nmax}, {conv.integrator}, {conv.wall:.1f} s)",
                         f"N={pk['elements']}, {pk['integrator']}: {pk['wall_median_s']:.3f} s ({_pct(pk['peak_err'])})"
                         if pk else "-",
                         f"N={hs['elements']}, {hs['integrator']}: {hs['wall_median_s']:.3f} s ({_pct(hs['hist_err'], '.3f')})"
                         if hs else "-"])
        L.append(_md_table(["model", "converged peak", "peak within 0.5 %", "history within 0.5 %"], body))
        L.append("")
        if exudyn is not None:
            L.append("Exudyn (benches/data/exudyn_timing.csv, measured in another session, solve-only, median of 9, "
                     "same rule, errors against its own converged reference): " + "; ".join(
                _exudyn_cheapest(exudyn, v) for v in ("ancf", "ge")) + ".")
            L.append("")

    # targets
    L.append("## Targets of issue 11")
    L.append("")
    L.append(_md_table(["target", "measured", "limit", "met", "note"],
                       [[t["target"], t["measured"], t["limit"], t["met"], t["note"]] for t in s["targets"]]))
    L.append("")
    L.append("## Membrane locking index")
    L.append("")
    L.append("Spurious membrane energy / bending energy of a point-by-point second-order strain (linear u, cubic v) for a "
             "half-sine bow of amplitude a (about the peaks at omega, 2 omega, 3 omega), Lb/d = 48 "
             "(`membrane_locking_index`); the element-averaged strain has none.")
    L.append("")
    amps = list(s["locking"])
    L.append(_md_table(["N"] + [f"a = {a:g} Lb" for a in amps],
                       [[row["elements"]] + [f"{s['locking'][a][i]['U_m/U_b']:.3g}" for a in amps]
                        for i, row in enumerate(s["locking"][amps[0]])]))
    L.append("")
    return "\n".join(L)


def _bending_frequency(diameter: float = PAPER["diameter"]) -> float:
    """``pi^2 sqrt(E I / (rho A Lb^4))`` of the paper's coupler [rad/s]."""
    area, inertia = math.pi * diameter**2 / 4.0, math.pi * diameter**4 / 64.0
    return math.pi**2 * math.sqrt(PAPER["youngs_modulus"] * inertia / (PAPER["density"] * area * LB**4))


def _exudyn_cheapest(exudyn: Dict[str, Any], variant: str) -> str:
    t_ref = exudyn[variant]["t_peak"]
    rows = [r for r in exudyn["timing"] if r["variant"] == variant and r["module"] == "exudynCPP" and r["ok"] == "1"
            and abs(float(r["t_peak"]) - t_ref) < SAME_LOBE_ANGLE / OMEGA and float(r["hist_err_own"]) <= 10 * LEVEL]
    ok = [r for r in rows if abs(float(r["peak_err_own"])) <= LEVEL]
    hs = [r for r in rows if abs(float(r["hist_err_own"])) <= LEVEL]
    parts = []
    if ok:
        b = min(ok, key=lambda r: float(r["median_ms"]))
        parts.append(f"{variant}: peak within 0.5 %: N={b['N']}, h={b['h']}, {float(b['median_ms']) / 1e3:.3f} s "
                     f"({_pct(float(b['peak_err_own']), '.2f')})")
    if hs:
        b = min(hs, key=lambda r: float(r["median_ms"]))
        parts.append(f"history within 0.5 %: N={b['N']}, h={b['h']}, {float(b['median_ms']) / 1e3:.3f} s "
                     f"({_pct(float(b['hist_err_own']), '.2f')})")
    return ", ".join(parts) if parts else f"{variant}: -"


def _pick_rows(s: Dict[str, Any]) -> List[List[str]]:
    """One row per case, sorted by the axial load: each E-B model's peak error against the geometrically
    exact answer (Exudyn's ANCF cable, else our finest ANCF run) and the models within :data:`LEVEL` on
    the same lobe (crank angle of the peak within :data:`SAME_LOBE_ANGLE` of the reference's)."""
    finest, exudyn, models = s["finest"], s["exudyn"], s["models"]
    data = []
    for c in s["cases"]:
        ref, ref_angle = _exudyn_peak(exudyn, c, "ancf"), float("nan")
        if np.isfinite(ref):
            ref_angle = (exudyn["ancf"]["t_peak"] * c.omega if c.name == PAPER_CASE.name
                         else float(exudyn["speeds"][(c.name, "ancf")]["crank_angle_at_peak"]))
        elif "ancf" in models:
            ref, ref_angle = finest[("ancf", c.name)].peak, finest[("ancf", c.name)].angle_peak
        if not np.isfinite(ref):
            continue
        load_model = "nonlinear-ffrf" if "nonlinear-ffrf" in models else ("ancf" if "ancf" in models else models[0])
        ratio = finest[(load_model, c.name)].max_compression_smooth
        psi = finest[("ancf", c.name)].max_psi if "ancf" in models else finest[(models[0], c.name)].max_psi
        cells, ok = [], []
        for m in models:
            if m == "nonlinear-ffrf-timoshenko":
                continue
            r = finest[(m, c.name)]
            e = _rel(r.peak, ref)
            same = abs(r.angle_peak - ref_angle) < SAME_LOBE_ANGLE
            cell = f"{_pct(e, '+.2f')} ({_fmt(r.angle_peak, '.2f')} rad)"
            if np.isfinite(e) and abs(e) <= LEVEL:
                if same:
                    ok.append(MODELS[m].label)
                else:
                    cell += " by chance: another lobe"
            cells.append(cell)
        data.append((ratio, [c.name, _fmt(ratio, ".3f"), _fmt(ref, ".4g"), f"{_fmt(ref_angle, '.2f')}", _fmt(psi, ".3f")]
                     + cells + [", ".join(ok) if ok else "none"]))
    return [row for _, row in sorted(data, key=lambda x: x[0] if np.isfinite(x[0]) else 1e9)]
