"""Work-precision study: error against run time on the paper's slider-crank.

For every integrator x formulation x tolerance the scene is simulated over ``0..t_end`` and
compared with a tight reference solution:

* ``err_max``: ``max_k |v_k/Lb - v_ref,k/Lb|`` over ``samples`` equally spaced output times
  (``v`` = transverse elastic displacement of the coupler midpoint in the beam frame, the
  paper's Fig. 4 quantity; dense output of the integrator at those times);
* ``peak_err``: ``| max_k |v_k| - max_k |v_ref,k| | / Lb`` (the peak on the same output grid);
* ``drift_end``: ``||Phi(q(t_end), t_end)||`` (no stabilization: UK drifts, CP recovers the
  dependent coordinates by Newton and stays on the constraints);
* ``wall_time``: the integration alone (``SimulationResult.wall_time``; for the native
  integrators the Python call of ``System.integrate``), one run per point;
* ``nfev`` (right-hand-side calls as the integrator reports them -- see the CSV notes),
  ``njev``, ``nlu``.

Formulations: ``uk`` (Rust UK accelerations, scipy ``solve_ivp``), ``uk-numpy`` (NumPy UK),
``cp`` (NumPy coordinate partitioning, partition once with repartitioning), and ``native``
(the Rust UK with the Rust integrators ``DOPRI5``/``RADAU5``, ``System.integrate``).

**Time budget.**  Each run gets ``budget`` seconds of wall time.  scipy runs are interrupted
with ``SIGALRM`` (POSIX, main thread) and recorded with ``status = "over_budget"`` and no
error; native runs cannot be interrupted (they hold no Python frame) -- a native run that
finishes over the budget keeps its error and is marked ``over_budget`` as well.  Once a
(formulation, method) line is over budget, its tighter tolerances are not run and appear as
``status = "skipped"`` (they would cost more).  Nothing is dropped from the CSV or the plot.

**Reference.**  Native DOPRI5 at ``ref_rtol`` (default 1e-13, ``atol = 1e-3 ref_rtol``),
checked against native RADAU5 at the same tolerance; the maximum difference of ``v/Lb``
between the two is reported as the reference's estimated accuracy.
"""

from __future__ import annotations

import csv
import math
import os
import signal
import sys
import threading
import time
from contextlib import contextmanager
from typing import Any, Dict, Iterator, List, Optional, Sequence, TextIO, Tuple

import numpy as np

from .. import System, scenes, simulate
from ..run.simulate import FORMULATIONS, NATIVE_METHODS, RUN_OPTIONS

ATOL_PER_RTOL = RUN_OPTIONS["defaults"]["atol_per_rtol"]  # the default atol, as simulate
from .machine import machine_info, machine_line

__all__ = [
    "run_work_precision",
    "run_elements",
    "paper_system",
    "reference_solution",
    "run_one",
    "best_per_level",
    "plot_work_precision",
    "SCIPY_METHODS",
    "NATIVE_METHODS",
    "FORMULATIONS",
    "DEFAULT_RTOLS",
]

SCIPY_METHODS = ("RK45", "DOP853", "Radau", "BDF", "LSODA")
DEFAULT_RTOLS = tuple(10.0 ** -k for k in range(3, 11))
DEFAULT_LEVELS = tuple(10.0 ** -k for k in range(4, 12))
FORMULATION_LABEL = {"uk": "UK Rust", "uk-numpy": "UK NumPy", "cp": "CP NumPy", "native": "UK Rust, native"}

CSV_FIELDS = [
    "study", "beam", "elements", "formulation", "method", "rtol", "atol", "status", "wall_time", "nfev",
    "njev", "nlu", "err_max", "err_rel", "peak", "peak_err", "t_peak", "drift_end", "err_vs_finest",
    "budget", "message",
]


class BudgetExceeded(Exception):
    """Raised by the SIGALRM handler when a run exceeds its time budget."""


@contextmanager
def _deadline(seconds: Optional[float]) -> Iterator[bool]:
    """Raise :class:`BudgetExceeded` in this thread after ``seconds`` of wall time.

    Yields True if the deadline is enforced (POSIX main thread), False otherwise.
    """
    usable = (seconds is not None and math.isfinite(seconds) and hasattr(signal, "setitimer")
              and threading.current_thread() is threading.main_thread())
    if not usable:
        yield False
        return

    def _raise(signum, frame):
        raise BudgetExceeded()

    old = signal.signal(signal.SIGALRM, _raise)
    signal.setitimer(signal.ITIMER_REAL, float(seconds))
    try:
        yield True
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)


# ----------------------------------------------------------------------------------- helpers
def paper_system(theory: str, elements: int) -> System:
    """The paper's slider-crank with ``elements`` coupler elements of beam theory ``theory``."""
    return System(scenes.slider_crank(theory=theory, elements=elements))


def _deflection(system, Y: np.ndarray) -> np.ndarray:
    """v(0.5)/Lb for states Y of shape (2n, nt) or (nt, n) (q in the rows/columns given)."""
    S, _ = system.beam_shape("coupler", 0.5)
    S = np.asarray(S)
    sl = system.elastic_slice("coupler")
    Lb = system.body_info("coupler")["length"]
    return (S[1] @ Y[sl.start:sl.stop]) / Lb


def _native(system, method: str, rtol: float, atol: float, t_end: float, t_eval: np.ndarray,
            max_steps: int = 10_000_000) -> Dict[str, Any]:
    return system.integrate(system.t0, system.y0, float(t_end), method, float(rtol),
                            np.array([float(atol)]), t_eval, max_steps=int(max_steps))


def reference_solution(system, t_end: float, t_eval: np.ndarray, rtol: float = 1e-13,
                       stream: Optional[TextIO] = None) -> Dict[str, Any]:
    """Tight solution of ``v(0.5)/Lb`` at ``t_eval``: native DOPRI5, checked by native RADAU5.

    Returns
    -------
    dict
        ``v`` (nt,), ``peak``, ``t_peak``, ``method``, ``check_method``, ``rtol``,
        ``accuracy`` (max |v - v_check|), ``wall_time`` of both runs.
    """
    atol = ATOL_PER_RTOL * rtol
    tic = time.perf_counter()
    a = _native(system, "DOPRI5", rtol, atol, t_end, t_eval)
    w1 = time.perf_counter() - tic
    b = _native(system, "RADAU5", rtol, atol, t_end, t_eval)
    names = (f"native DOPRI5, rtol {rtol:g}, atol {atol:g}", f"native RADAU5, rtol {rtol:g}, atol {atol:g}")
    for r, nm in ((a, names[0]), (b, names[1])):
        if r["status"] != 0:
            raise RuntimeError(f"reference run failed ({nm}): {r['message']}")
    ya, yb = a["y"], b["y"]
    w2 = time.perf_counter() - tic - w1
    va, vb = _deflection(system, ya), _deflection(system, yb)
    i = int(np.argmax(np.abs(va)))
    ref = {"v": va, "peak": float(abs(va[i])), "t_peak": float(t_eval[i]), "method": names[0],
           "check_method": names[1], "rtol": rtol, "accuracy": float(np.max(np.abs(va - vb))),
           "wall_time": (w1, w2)}
    if stream is not None:
        print(f"reference: {names[0]} ({w1:.1f} s); check: {names[1]} ({w2:.1f} s); max |dv/Lb| between them "
              f"{ref['accuracy']:.1e}; peak |v|/Lb {ref['peak']:.6e} at t = {ref['t_peak']:.4f} s", file=stream,
              flush=True)
    return ref


def run_one(system, formulation: str, method: str, rtol: float, t_end: float, t_eval: np.ndarray,
            ref: Dict[str, Any], budget: Optional[float] = 60.0) -> Dict[str, Any]:
    """One point of the diagram (see the module docstring for the fields)."""
    atol = ATOL_PER_RTOL * rtol
    row: Dict[str, Any] = {"formulation": formulation, "method": method, "rtol": rtol, "atol": atol,
                           "status": "ok", "wall_time": float("nan"), "nfev": -1, "njev": -1, "nlu": -1,
                           "err_max": float("nan"), "err_rel": float("nan"), "peak": float("nan"),
                           "peak_err": float("nan"), "t_peak": float("nan"), "drift_end": float("nan"),
                           "budget": budget if budget is not None else float("inf"), "message": ""}
    Y = None
    tic = time.perf_counter()
    try:
        if formulation == "native":
            r = _native(system, method, rtol, atol, t_end, t_eval)
            row["wall_time"] = time.perf_counter() - tic
            row.update(nfev=int(r["nfev"]) + int(r.get("jac_evals", 0)), njev=int(r["njev"]), nlu=int(r["nlu"]))
            if r["status"] != 0:
                row.update(status="failed", message=str(r["message"]))
            else:
                Y = np.asarray(r["y"])
                n = system.n_coords
                row["drift_end"] = float(np.linalg.norm(system.phi(float(r["t"][-1]), Y[:n, -1])))
        else:
            with _deadline(budget):
                res = simulate(system, t_end, method=method, rtol=rtol, atol=atol, t_eval=t_eval,
                               formulation=formulation)
            row["wall_time"] = res.wall_time
            row.update(nfev=res.nfev, njev=res.njev, nlu=res.nlu)
            if not res.success or res.t.size != t_eval.size:
                row.update(status="failed", message=res.message)
            else:
                Y = res.q
                row["drift_end"] = float(res.residuals["position"][-1])
    except BudgetExceeded:
        row.update(status="over_budget", wall_time=time.perf_counter() - tic,
                   message=f"interrupted after the {budget:g} s budget")
    except Exception as exc:  # noqa: BLE001 - record what happened, keep the study going
        row.update(status="failed", wall_time=time.perf_counter() - tic, message=f"{type(exc).__name__}: {exc}")
    if Y is not None:
        v = _deflection(system, Y)
        e = np.abs(v - ref["v"])
        i = int(np.argmax(np.abs(v)))
        row.update(err_max=float(e.max()), err_rel=float(e.max() / ref["peak"]), peak=float(abs(v[i])),
                   peak_err=float(abs(abs(v[i]) - ref["peak"])), t_peak=float(t_eval[i]))
        row["_v"] = v
        if budget is not None and row["wall_time"] > budget:
            row.update(status="over_budget", message=f"finished in {row['wall_time']:.1f} s, over the {budget:g} s "
                                                      f"budget (native runs cannot be interrupted)")
    return row


def _fmt(x: Any) -> str:
    if isinstance(x, float):
        return repr(x)
    return str(x)


class _CsvWriter:
    """Appends rows as they come (a long study leaves a usable file even if stopped)."""

    def __init__(self, path: str):
        self.path = path
        self.fh = open(path, "w", newline="")
        self.w = csv.writer(self.fh)
        self.w.writerow(CSV_FIELDS)
        self.fh.flush()

    def write(self, row: Dict[str, Any]) -> None:
        self.w.writerow([_fmt(row.get(k, "")) for k in CSV_FIELDS])
        self.fh.flush()

    def close(self) -> None:
        self.fh.close()


def _print_row(row: Dict[str, Any], stream: TextIO) -> None:
    tag = f"{row.get('study', '')} N={row.get('elements', '')} " if row.get("study") == "elements" else ""
    err = f"{row['err_max']:.2e}" if np.isfinite(row["err_max"]) else "-"
    wall = f"{row['wall_time']:.3f}" if np.isfinite(row["wall_time"]) else "-"
    print(f"{tag}{row['formulation']:9s} {row['method']:7s} rtol {row['rtol']:.0e}: {row['status']:11s} "
          f"wall {wall:>8s} s  nfev {row['nfev']:>9}  err {err:>8s}  drift {row['drift_end']:.1e}"
          + (f"  ({row['message']})" if row["status"] != "ok" and row["message"] else ""), file=stream, flush=True)


def _cases(formulations: Sequence[str], methods: Sequence[str], native: Sequence[str]) -> List[Tuple[str, str]]:
    for f in formulations:
        if f not in FORMULATIONS:
            raise ValueError(f"unknown formulation {f!r}; expected one of {FORMULATIONS}")
    for m in methods:
        if m not in SCIPY_METHODS + ("RK23",):
            raise ValueError(f"unknown scipy method {m!r}; expected one of {SCIPY_METHODS}")
    for m in native:
        if m not in NATIVE_METHODS:
            raise ValueError(f"unknown native method {m!r}; expected one of {NATIVE_METHODS}")
    return [(f, m) for f in formulations for m in methods] + [("native", m) for m in native]


def _warm_up(system, formulation: str, method: str, t_end: float) -> None:
    """One short untimed run of a (formulation, method) line before its timed points: the first
    call of a method in a process pays lazy imports and first-touch costs (seen as a 3-4x slower
    first DOP853 point), which belong to no tolerance."""
    t_short = 1e-3 * t_end
    try:
        if formulation == "native":
            _native(system, method, 1e-3, 1e-6, t_short, np.array([system.t0, t_short]))
        else:
            simulate(system, t_short, method=method, rtol=1e-3, atol=1e-6, formulation=formulation)
    except Exception:  # noqa: BLE001 - the timed runs record any failure
        pass


def _run_cases(system, cases, rtols, t_end, t_eval, ref, budget, skip_after_timeout, base, writer, stream,
               rows):
    for formulation, method in cases:
        _warm_up(system, formulation, method, t_end)
        over = False
        for rtol in sorted(rtols, reverse=True):
            if over and skip_after_timeout:
                row = {"formulation": formulation, "method": method, "rtol": rtol, "atol": ATOL_PER_RTOL * rtol,
                       "status": "skipped", "wall_time": float("nan"), "nfev": -1, "njev": -1, "nlu": -1,
                       "err_max": float("nan"), "err_rel": float("nan"), "peak": float("nan"),
                       "peak_err": float("nan"), "t_peak": float("nan"), "drift_end": float("nan"),
                       "budget": budget, "message": "not run: a looser rtol of this line was already over budget"}
            else:
                row = run_one(system, formulation, method, rtol, t_end, t_eval, ref, budget)
                over = row["status"] == "over_budget"
            row.update(base)
            rows.append(row)
            writer.write(row)
            _print_row(row, stream)


# ----------------------------------------------------------------------------------- studies
def run_work_precision(
    out: str,
    theory: str = "timoshenko",
    elements: int = 1,
    t_end: float = 0.1,
    samples: int = 1001,
    methods: Sequence[str] = SCIPY_METHODS,
    formulations: Sequence[str] = FORMULATIONS,
    native: Sequence[str] = NATIVE_METHODS,
    rtols: Sequence[float] = DEFAULT_RTOLS,
    budget: Optional[float] = 60.0,
    ref_rtol: float = 1e-13,
    skip_after_timeout: bool = True,
    levels: Sequence[float] = DEFAULT_LEVELS,
    plot: bool = True,
    stream: Optional[TextIO] = None,
) -> Dict[str, Any]:
    """Run the grid and write ``work_precision.csv``, ``work_precision.png`` and
    ``work_precision.md`` (settings, reference, machine, best method per accuracy level) to ``out``.

    Returns
    -------
    dict
        ``rows`` (list of dicts, CSV fields), ``reference``, ``best`` (see :func:`best_per_level`).
    """
    stream = stream or sys.stdout
    os.makedirs(out, exist_ok=True)
    system = paper_system(theory, elements)
    cases = _cases(formulations, methods, native)
    t_eval = np.linspace(system.t0, t_end, samples)
    info = machine_info()
    print(f"work-precision: paper slider-crank, {theory}, N = {elements}, 0..{t_end:g} s, {samples} output times, "
          f"{len(cases)} lines x {len(rtols)} tolerances, budget {budget} s per run", file=stream, flush=True)
    ref = reference_solution(system, t_end, t_eval, rtol=ref_rtol, stream=stream)
    rows: List[Dict[str, Any]] = []
    writer = _CsvWriter(os.path.join(out, "work_precision.csv"))
    t0 = time.perf_counter()
    try:
        _run_cases(system, cases, rtols, t_end, t_eval, ref, budget, skip_after_timeout,
                   {"study": "work-precision", "beam": theory, "elements": elements}, writer, stream, rows)
    finally:
        writer.close()
    total = time.perf_counter() - t0
    info["load_average_end"] = machine_info()["load_average"]
    best = best_per_level(rows, levels)
    settings = {"beam": theory, "elements": elements, "t_end": t_end, "samples": samples, "budget": budget,
                "rtols": list(rtols), "total_time": total}
    if plot:
        plot_work_precision(rows, os.path.join(out, "work_precision.png"), budget,
                            title=f"Paper slider-crank, {theory}, N = {elements}: error of v(0.5)/Lb vs wall time")
    _write_md(os.path.join(out, "work_precision.md"), "Work-precision: the paper's slider-crank", rows, ref, best,
              settings, info)
    print(f"wrote {out}/work_precision.csv, .png, .md ({total:.0f} s)", file=stream)
    return {"rows": rows, "reference": ref, "best": best, "machine": info, "settings": settings}


def run_elements(
    out: str,
    elements: Sequence[int] = (1, 2, 4, 8),
    cases: Sequence[Tuple[str, str]] = (("native", "DOPRI5"), ("native", "RADAU5"), ("uk", "DOP853")),
    theory: str = "timoshenko",
    t_end: float = 0.1,
    samples: int = 1001,
    rtols: Sequence[float] = DEFAULT_RTOLS,
    budget: Optional[float] = 60.0,
    ref_rtol: float = 1e-12,
    skip_after_timeout: bool = True,
    levels: Sequence[float] = DEFAULT_LEVELS,
    plot: bool = True,
    stream: Optional[TextIO] = None,
    reference_elements: Optional[int] = None,
) -> Dict[str, Any]:
    """The same study over coupler element counts (``elements.csv``, ``elements.png``,
    ``elements.md``).

    Besides ``err_max`` (against the tight reference of the same N: the integration error),
    each row has ``err_vs_finest``: the error against the tight reference of the finest model,
    N = ``reference_elements`` if given (a finer mesh that is only used as the reference, so
    the largest studied N also shows its discretization error), else the largest studied N
    (discretization + integration error: what a user gets for the physical problem).
    """
    stream = stream or sys.stdout
    os.makedirs(out, exist_ok=True)
    elements = sorted(set(int(e) for e in elements))
    for f, m in cases:
        _cases([], [], [m]) if f == "native" else _cases([f], [m], [])
    info = machine_info()
    print(f"elements study: paper slider-crank, {theory}, N = {elements}, 0..{t_end:g} s, cases {list(cases)}, "
          f"budget {budget} s per run", file=stream, flush=True)
    if reference_elements is not None and int(reference_elements) <= elements[-1]:
        raise ValueError(f"reference_elements ({reference_elements}) must exceed the largest studied N "
                         f"({elements[-1]})")
    ref_ns = elements + ([int(reference_elements)] if reference_elements is not None else [])
    systems = {N: paper_system(theory, N) for N in ref_ns}
    t_eval = np.linspace(0.0, t_end, samples)
    refs = {}
    for N in ref_ns:
        print(f"N = {N}:", file=stream, end=" ")
        refs[N] = reference_solution(systems[N], t_end, t_eval, rtol=ref_rtol, stream=stream)
    finest = refs[ref_ns[-1]]
    rows: List[Dict[str, Any]] = []
    writer = _CsvWriter(os.path.join(out, "elements.csv"))
    t0 = time.perf_counter()
    try:
        for N in elements:
            sub: List[Dict[str, Any]] = []

            class _W:  # add err_vs_finest before writing
                def write(self, row):
                    if "_v" in row:
                        row["err_vs_finest"] = float(np.max(np.abs(row["_v"] - finest["v"])))
                    else:
                        row["err_vs_finest"] = float("nan")
                    writer.write(row)

            _run_cases(systems[N], list(cases), rtols, t_end, t_eval, refs[N], budget, skip_after_timeout,
                       {"study": "elements", "beam": theory, "elements": N}, _W(), stream, sub)
            rows += sub
    finally:
        writer.close()
    total = time.perf_counter() - t0
    info["load_average_end"] = machine_info()["load_average"]
    model_err = {N: float(np.max(np.abs(refs[N]["v"] - finest["v"]))) for N in ref_ns}
    settings = {"beam": theory, "elements": elements, "t_end": t_end, "samples": samples, "budget": budget,
                "rtols": list(rtols), "total_time": total, "model_error": model_err,
                "peaks": {N: refs[N]["peak"] for N in ref_ns}, "finest": ref_ns[-1]}
    best = best_per_level(rows, levels, key="err_vs_finest", group=lambda r: f"N={r['elements']}")
    if plot:
        plot_elements(rows, os.path.join(out, "elements.png"), budget, theory, finest=ref_ns[-1])
    _write_md(os.path.join(out, "elements.md"), "Work-precision over coupler element counts", rows,
              {N: refs[N] for N in ref_ns}, best, settings, info, key="err_vs_finest")
    print(f"wrote {out}/elements.csv, .png, .md ({total:.0f} s)", file=stream)
    return {"rows": rows, "references": refs, "best": best, "machine": info, "settings": settings}


# ----------------------------------------------------------------------------------- summaries
def _label(r: Dict[str, Any]) -> str:
    if r["formulation"] == "native":
        return f"native {r['method']} (Rust UK)"
    return f"{r['method']} + {FORMULATION_LABEL[r['formulation']]}"


def best_per_level(rows: Sequence[Dict[str, Any]], levels: Sequence[float] = DEFAULT_LEVELS, key: str = "err_max",
                   group=None) -> List[Dict[str, Any]]:
    """For every accuracy level: the fastest finished run (status ok) with ``row[key] <= level``,
    overall and per formulation group.

    Returns
    -------
    list of dict
        ``level``, ``overall`` (row or None), ``by_group`` {group: row or None}.
    """
    group = group or (lambda r: FORMULATION_LABEL[r["formulation"]])
    ok = [r for r in rows if r["status"] == "ok" and np.isfinite(r.get(key, float("nan")))]
    groups = sorted({group(r) for r in rows}, key=lambda g: [group(r) for r in rows].index(g))
    out = []
    for lev in levels:
        good = [r for r in ok if r[key] <= lev]
        best = min(good, key=lambda r: r["wall_time"]) if good else None
        by = {}
        for g in groups:
            gg = [r for r in good if group(r) == g]
            by[g] = min(gg, key=lambda r: r["wall_time"]) if gg else None
        out.append({"level": lev, "overall": best, "by_group": by})
    return out


def _cell(r: Optional[Dict[str, Any]], with_n: bool = False) -> str:
    if r is None:
        return "-"
    n = f"N={r['elements']} " if with_n else ""
    return f"{n}{_label(r)}, rtol {r['rtol']:.0e}: {r['wall_time']:.3g} s"


def _write_md(path, title, rows, ref, best, settings, info, key="err_max"):
    L = [f"# {title}", ""]
    L.append(f"Machine: {machine_line(info)}; load average at the end {info['load_average_end'][0]:.2f}.")
    L.append("")
    el = settings["elements"]
    L.append(f"Scene: the paper's slider-crank, {settings['beam']} coupler, N = {el}; 0..{settings['t_end']:g} s; "
             f"errors of v(0.5)/Lb at {settings['samples']} equally spaced times; atol = 1e-3 rtol; "
             f"budget {settings['budget']} s per run; total {settings['total_time']:.0f} s.")
    L.append("")
    refs = ref if isinstance(ref, dict) and "v" not in ref else {el: ref}
    for N, r in refs.items():
        L.append(f"Reference (N = {N}): {r['method']}; checked by {r['check_method']}: max |dv/Lb| = "
                 f"{r['accuracy']:.1e} (estimated accuracy); peak |v|/Lb = {r['peak']:.6e} at t = {r['t_peak']:.4f} s.")
    L.append("")
    if "model_error" in settings:
        fin = max(settings["model_error"])
        L.append(f"Discretization error of each N (tight references, max |v_N - v_N={fin}|/Lb over the trajectory): "
                 + ", ".join(f"N = {N}: {e:.2e} (peak {settings['peaks'][N]:.5e})"
                             for N, e in settings["model_error"].items()) + ".")
        L.append("")
    what = "error against the finest model" if key == "err_vs_finest" else "max error of v(0.5)/Lb"
    L.append(f"Fastest run reaching each accuracy level ({what} <= level; finished runs only):")
    L.append("")
    groups = list(best[0]["by_group"]) if best else []
    L.append("| level | fastest overall | " + " | ".join(groups) + " |")
    L.append("|---" * (2 + len(groups)) + "|")
    with_n = key == "err_vs_finest"
    for b in best:
        L.append(f"| {b['level']:.0e} | {_cell(b['overall'], with_n)} | "
                 + " | ".join(_cell(b["by_group"][g]) for g in groups) + " |")
    L.append("")
    counts: Dict[str, int] = {}
    for r in rows:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    L.append("Runs: " + ", ".join(f"{k} {v}" for k, v in counts.items()) + ".")
    over = [r for r in rows if r["status"] in ("over_budget", "failed")]
    if over:
        L.append("")
        L.append("Over budget or failed (tighter tolerances of an over-budget line are skipped):")
        L.append("")
        for r in over:
            n = f"N = {r['elements']}, " if with_n else ""
            L.append(f"* {n}{_label(r)}, rtol {r['rtol']:.0e}: {r['status']} ({r['message']})")
    L.append("")
    with open(path, "w") as fh:
        fh.write("\n".join(L))


# ----------------------------------------------------------------------------------- plots
_METHOD_COLOR = {"RK45": "C0", "RK23": "C7", "DOP853": "C1", "Radau": "C2", "BDF": "C3", "LSODA": "C4",
                 "DOPRI5": "k", "RADAU5": "C5"}
_FORM_STYLE = {"uk": ("-", "o"), "uk-numpy": ("--", "s"), "cp": (":", "^"), "native": ("-", "D")}


def _figure(size):
    from ..results.plotting import figure

    fig = figure(size, "the work-precision plot (--no-plot skips it)")
    return fig


def _draw_lines(ax, rows, key, color_of, style_of, label_of, budget):
    from ..errors import require

    blended_transform_factory = require("matplotlib.transforms", "the work-precision plot (--no-plot skips it)").blended_transform_factory

    lines: Dict[Tuple, List[Dict[str, Any]]] = {}
    for r in rows:
        lines.setdefault(label_of(r), []).append(r)
    top = blended_transform_factory(ax.transData, ax.transAxes)
    any_over = False
    for k_line, (label, rs) in enumerate(lines.items()):
        rs = sorted(rs, key=lambda r: -r["rtol"])
        ok = [r for r in rs if np.isfinite(r.get(key, float("nan"))) and r[key] > 0]
        ls, mk = style_of(rs[0])
        c = color_of(rs[0])
        n_bad = sum(r["status"] != "ok" for r in rs)
        lab = label + (f" ({n_bad} over budget/failed/skipped)" if n_bad else "")
        if ok:
            x = [r["wall_time"] for r in ok]
            y = [r[key] for r in ok]
            ax.plot(x, y, ls=ls, marker=mk, color=c, ms=4, lw=1.2, label=lab,
                    mfc=c, alpha=0.9)
            for r in ok:  # finished but over budget (native): hollow marker
                if r["status"] == "over_budget":
                    ax.plot([r["wall_time"]], [r[key]], marker="o", ms=11, mfc="none", mec="r", mew=1.0)
                    any_over = True
        elif n_bad:
            ax.plot([], [], ls=ls, marker=mk, color=c, label=lab)
        for r in rs:  # interrupted / failed: a cross on the top strip at its wall time
            if r["status"] in ("over_budget", "failed") and not np.isfinite(r.get(key, float("nan"))):
                ax.plot([r["wall_time"]], [0.975 - 0.012 * (k_line % 6)], transform=top, marker="x", color=c, ms=7,
                        mew=1.5, clip_on=False)
                any_over = True
    if budget is not None and np.isfinite(budget):
        ax.axvline(budget, color="r", lw=0.8, ls="--")
        ax.text(budget, 0.90, " budget", transform=top, color="r", fontsize=8, va="top")
    return any_over


def _log_axes(ax, rows, key):
    """Log-log axes; fixed limits where there is nothing finite to scale to (every run over budget)."""
    ax.set_xscale("log")
    ax.set_yscale("log")
    ys = [r[key] for r in rows if np.isfinite(r.get(key, float("nan"))) and r[key] > 0]
    xs = [r["wall_time"] for r in rows if np.isfinite(r["wall_time"]) and r["wall_time"] > 0]
    if not ys:
        ax.set_ylim(1e-12, 1e-2)
    if not xs:
        ax.set_xlim(1e-3, 1e2)


def plot_work_precision(rows: Sequence[Dict[str, Any]], path: str, budget: Optional[float] = None,
                        title: str = "", key: str = "err_max") -> None:
    """Log-log error vs wall time, one line per method x formulation; runs over the budget
    or failed are crosses on the top edge at their wall time (hollow red circle: finished over
    budget)."""
    fig = _figure((10.5, 6.2))
    ax = fig.add_subplot(1, 1, 1)
    any_over = _draw_lines(
        ax, rows, key,
        color_of=lambda r: _METHOD_COLOR.get(r["method"], "0.5"),
        style_of=lambda r: _FORM_STYLE[r["formulation"]],
        label_of=_label, budget=budget)
    _log_axes(ax, rows, key)
    ax.set_xlabel("wall time of the integration [s]")
    ax.set_ylabel("max |v(0.5)/Lb - reference| over the trajectory")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="major", lw=0.4)
    ax.grid(True, which="minor", lw=0.2, color="0.9")
    note = "x on the top edge: interrupted at the budget or failed" if any_over else ""
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5), title=note or None, title_fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=130)


def plot_elements(rows: Sequence[Dict[str, Any]], path: str, budget: Optional[float], theory: str,
                  finest: Optional[int] = None) -> None:
    """Two panels: integration error (vs the same-N reference) and error against the finest
    model (N = ``finest``, default the largest N of the rows), both vs wall time; colour = N,
    line style = method."""
    fig = _figure((13.0, 5.6))
    Ns = sorted({r["elements"] for r in rows})
    finest = finest if finest is not None else Ns[-1]
    colors = {N: f"C{i}" for i, N in enumerate(Ns)}
    styles = {}
    for r in rows:
        styles.setdefault((r["formulation"], r["method"]), (["-", "--", ":", "-."][len(styles) % 4],
                                                              ["o", "s", "^", "D"][len(styles) % 4]))
    for k, (key, ylab) in enumerate((("err_max", "integration error: max |v - v_ref(same N)| / Lb"),
                                     ("err_vs_finest", f"error vs the N = {finest} model: max |v - v_ref(N={finest})| / Lb"))):
        ax = fig.add_subplot(1, 2, k + 1)
        _draw_lines(ax, rows, key,
                    color_of=lambda r: colors[r["elements"]],
                    style_of=lambda r: styles[(r["formulation"], r["method"])],
                    label_of=lambda r: f"N={r['elements']}: {_label(r)}", budget=budget)
        _log_axes(ax, rows, key)
        ax.set_xlabel("wall time of the integration [s]")
        ax.set_ylabel(ylab, fontsize=9)
        ax.grid(True, which="major", lw=0.4)
        if k == 1:
            ax.legend(fontsize=6.5, loc="center left", bbox_to_anchor=(1.01, 0.5))
    fig.suptitle(f"Paper slider-crank, {theory}: work-precision over coupler element counts", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
