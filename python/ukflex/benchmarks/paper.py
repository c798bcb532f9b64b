"""Reproduction of Pennestri, Valentini, de Falco (2010): Fig. 4 and the Table 1 analogue.

* :func:`run_fig4` -- the paper's slider-crank with a Timoshenko and an Euler-Bernoulli coupler:
  the coupler midpoint deflection ``v(Lb/2)/Lb`` vs time (``fig4.csv``, ``fig4.png``).
* :func:`table1` -- the time spent computing accelerations over a whole simulation, UK vs CP,
  for both beam models (``table1.md``, ``table1.csv``).
* :func:`run_paper` -- both (``ukflex paper --out DIR``).

How Table 1 is measured here
----------------------------
The paper timed its MATLAB acceleration routines with the profiler over one simulation
(ode15s, ``RelTol = 1e-6``), best of five runs: CP 2.320 s / UK 0.754 s (Euler-Bernoulli),
CP 3.770 s / UK 1.207 s (Timoshenko), i.e. UK about 3.1x faster; its CP re-partitioned at every
call.  Here:

1. **The states.** One simulation of ``0..t_end`` (default 0.07 s, the span of Fig. 4) with
   scipy's ``BDF`` (variable-order NDF, the family of MATLAB's ode15s), ``rtol = 1e-6``,
   ``atol = 1e-9``, driven by the Rust UK accelerations (``System.rhs``, Jacobian
   ``System.jac``).  Every state ``(t, q, qd)`` at which the integrator called the
   right-hand side is recorded (the Jacobian's internal evaluations are not).
2. **Same states, every formulation.** Each acceleration routine is evaluated on the recorded
   states, in order; the time of one sweep is summed with ``time.perf_counter`` and the best of
   ``repeats`` (default 5) sweeps is kept:

   * UK, Rust kernel (:func:`ukflex.run.simulate.time_acceleration`: the kernel timed inside Rust,
     one call per state);
   * UK, Rust through the Python binding (``System.qdd(t, q, qd)``, what scipy pays);
   * UK, NumPy (``ukflex.reference``: ``ReferenceModel.terms`` + ``uk_qdd``, the paper's
     eq. (70) with the symmetric root of M);
   * CP, NumPy, partition once (Wehage-Haug: the partition of the initial state; per call the
     dependent positions by Newton-Raphson warm-started from the previous call, dependent
     velocities, then the reduced equations -- what ``simulate(formulation="cp")`` does per
     call);
   * CP, NumPy, partition every call (the paper's implementation: pivoted QR of ``A`` at every
     call, then the reduced equations; no recovery, the full state is integrated);
   * for reference, the NumPy model terms ``M, Q, A, gamma`` alone (``ReferenceModel.terms``),
     which both NumPy formulations evaluate first: the rest is the formulation's own work.

   All NumPy code runs with one BLAS thread (as in the reference integrators).  The ratios
   UK/CP are taken within this one run.  In ``mode="quick"`` (the default) only an evenly
   spaced subset of at most ``max_states`` states is timed and the whole-simulation time is
   projected as ``mean time per call x number of recorded states`` (labelled as projected);
   ``mode="full"`` times every state.
3. **Whole simulations** (``mode="full"``, or ``whole=True``): each formulation drives its own
   BDF run; wall time, right-hand-side calls and the time spent inside the right-hand side
   (best of ``whole_repeats``, the repeats interleaved across formulations so that a change
   of the machine's load hits all of them alike).  The trajectories and call counts differ between formulations
   (CP integrates only the independent coordinates), which is why the same-states figures are
   the fair ratio.
"""

from __future__ import annotations

import csv
import os
import sys
import time
from typing import Any, Callable, Dict, List, Optional, Sequence, TextIO

import numpy as np

from .. import System, scenes, simulate
from ..reference import CPSystem, ReferenceModel, choose_partition, reduced_accelerations, single_blas_thread, uk_qdd
from ..run.simulate import RUN_OPTIONS, time_acceleration
from .machine import machine_info, machine_line

__all__ = ["run_fig4", "table1", "run_paper", "machine_info", "PAPER_TABLE1", "PAPER_WINDOW"]

PAPER_WINDOW = 0.07  # s, the time span of the paper's Fig. 4
BEAMS = ("euler-bernoulli", "timoshenko")
BEAM_LABEL = {"euler-bernoulli": "Euler-Bernoulli", "timoshenko": "Timoshenko"}

#: The paper's Table 1 (MATLAB profiler, best of five), seconds.
PAPER_TABLE1 = {
    "euler-bernoulli": {"cp": 2.320, "uk": 0.754},
    "timoshenko": {"cp": 3.770, "uk": 1.207},
}

#: Formulations timed by :func:`table1`, in table order: key -> label.
TABLE_ROWS = {
    "uk-rust-kernel": "UK, Rust kernel (timed inside Rust)",
    "uk-rust": "UK, Rust via Python binding (System.qdd)",
    "uk-numpy": "UK, NumPy reference (eq. 70)",
    "cp-once": "CP, NumPy, partition once (Newton recovery + reduced equations)",
    "cp-every": "CP, NumPy, partition every call (the paper's implementation)",
    "terms-numpy": "(part of both NumPy rows: model terms M, Q, A, gamma alone)",
}


# ----------------------------------------------------------------------------------- Fig. 4
def run_fig4(
    out: str,
    elements: int = 1,
    t_end: float = 0.1,
    method: str = "Radau",
    rtol: float = 1e-6,
    atol: Optional[float] = None,
    samples: int = 5001,
    formulation: str = "uk",
    gravity: bool = True,
    plot: bool = True,
    stream: Optional[TextIO] = None,
    progress: Optional[Callable[[str], Callable[[float], None]]] = None,
) -> Dict[str, Dict[str, float]]:
    """Run the paper's slider-crank for both beam models and write ``fig4.csv`` / ``fig4.png``.

    Parameters
    ----------
    progress : callable, optional
        ``progress(label)`` returns a ``callback(t)`` for :func:`ukflex.simulate` (CLI display).

    Returns
    -------
    dict
        Per beam model: ``peak`` (max |v(0.5)|/Lb in 0..0.07 s), ``peak_signed``, ``t_peak``,
        ``drift`` (||Phi|| at ``t_end``), ``max_drift``, ``wall_time``, ``nfev``.
    """
    stream = stream or sys.stdout
    os.makedirs(out, exist_ok=True)
    t_eval = np.linspace(0.0, t_end, samples)
    Lb = scenes.PAPER["coupler_length"]
    curves: Dict[str, np.ndarray] = {}
    summary: Dict[str, Dict[str, float]] = {}
    for beam in ("timoshenko", "euler-bernoulli"):
        scene = scenes.slider_crank(theory=beam, elements=elements, gravity=gravity)
        cb = progress(f"fig. 4, {beam}") if progress else None
        res = simulate(scene, t_end, method=method, rtol=rtol, atol=atol, t_eval=t_eval, formulation=formulation,
                       progress=cb)
        if not res.success:
            raise RuntimeError(f"{beam}: integration failed: {res.message}")
        _, v = res.beam_displacement("coupler", 0.5)
        w = v / Lb
        curves[beam] = w
        window = res.t <= PAPER_WINDOW + 1e-12
        i = int(np.argmax(np.abs(w[window])))
        summary[beam] = {
            "peak": float(abs(w[window][i])),
            "peak_signed": float(w[window][i]),
            "t_peak": float(res.t[window][i]),
            "drift": float(res.residuals["position"][-1]),
            "max_drift": float(res.max_residual("position")),
            "wall_time": res.wall_time,
            "nfev": res.nfev,
        }
        s = summary[beam]
        print(
            f"{beam:16s} N={elements}: peak |v(0.5)|/Lb in 0..{min(PAPER_WINDOW, t_end):g} s = {s['peak']:.6e} "
            f"(v/Lb = {s['peak_signed']:+.6e}) at t = {s['t_peak']:.5f} s; "
            f"||Phi(t_end = {t_end:g} s)|| = {s['drift']:.3e} (max {s['max_drift']:.3e}); "
            f"nfev {s['nfev']}, integration {s['wall_time']:.2f} s",
            file=stream,
        )
    csv_path = os.path.join(out, "fig4.csv")
    with open(csv_path, "w", newline="") as fh:
        wr = csv.writer(fh)
        wr.writerow(["t", "v_mid_over_Lb_timoshenko", "v_mid_over_Lb_euler_bernoulli"])
        for row in zip(t_eval, curves["timoshenko"], curves["euler-bernoulli"]):
            wr.writerow([repr(float(x)) for x in row])
    print(f"wrote {csv_path}", file=stream)
    if plot:
        png_path = os.path.join(out, "fig4.png")
        _plot_fig4(png_path, t_eval, curves, elements, gravity, method, rtol)
        print(f"wrote {png_path}", file=stream)
    return summary


def _plot_fig4(path: str, t: np.ndarray, curves: Dict[str, np.ndarray], elements: int, gravity: bool,
               method: str = "", rtol: float = float("nan")) -> None:
    from ..results.plotting import figure

    fig = figure((7.0, 4.2), "Fig. 4 (--no-plot skips it)")
    ax = fig.add_subplot(1, 1, 1)
    ax.plot(t, curves["euler-bernoulli"], "-", lw=1.2, label="Euler-Bernoulli")
    ax.plot(t, curves["timoshenko"], "--", lw=1.2, label="Timoshenko")
    if t[-1] > PAPER_WINDOW:
        ax.axvline(PAPER_WINDOW, color="0.6", lw=0.8, ls=":")
    ax.axhline(0.0, color="0.8", lw=0.6)
    ax.set_xlabel("Time (s)")
    ax.set_ylabel("Midpoint deflection / $L_b$")
    extra = f"; {method}, rtol {rtol:g}" if method else ""
    ax.set_title(f"Flexible slider-crank, coupler {elements} element(s){', gravity' if gravity else ''}{extra}",
                 fontsize=10)
    ax.set_xlim(t[0], t[-1])
    ax.legend()
    ax.grid(True, lw=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=150)


# ----------------------------------------------------------------------------------- Table 1
def _timed_uk_run(system, t_end: float, method: str, rtol: float, atol: float, record: bool = False):
    """A UK (Rust) run as ``simulate`` does it (scipy, ``System.rhs``, ``System.jac``), timing the
    rhs and Jacobian calls; with ``record`` every right-hand-side state is kept.

    Returns ``(T, Y, info)``: the recorded times (k,) and states (k, 2n) (empty unless
    ``record``) and ``wall_time``, ``accel_time``, ``nfev``, ``njev``, ``status``, ``steps``.
    """
    from scipy.integrate import solve_ivp

    ts: List[float] = []
    ys: List[np.ndarray] = []
    acc = [0.0]
    rhs0, jac0 = system.rhs, system.jac
    clock = time.perf_counter

    def rhs(t, y):
        if record:
            ts.append(t)
            ys.append(y.copy())
        tic = clock()
        f = rhs0(t, y)
        acc[0] += clock() - tic
        return f

    def jac(t, y):
        tic = clock()
        J = jac0(t, y)
        acc[0] += clock() - tic
        return J

    kw = {"jac": jac} if method in ("BDF", "Radau") else {}
    tic = clock()
    sol = solve_ivp(rhs, (system.t0, t_end), system.y0, method=method, rtol=rtol, atol=atol, **kw)
    wall = clock() - tic
    info = {"wall_time": wall, "accel_time": acc[0], "nfev": int(sol.nfev), "njev": int(sol.njev),
            "status": int(sol.status), "steps": int(sol.t.size - 1), "message": sol.message}
    return np.array(ts), np.array(ys), info


def _accel_functions(system) -> Dict[str, Callable]:
    """key -> f(T, Y) that evaluates the accelerations on every state and returns seconds spent."""
    n = system.n_coords
    ref = ReferenceModel(system.description)
    part0 = choose_partition(ref.A(system.q0))
    clock = time.perf_counter
    qdd = system.qdd

    def uk_rust_kernel(T, Y):
        total = 0.0
        for t, y in zip(T, Y):
            total += time_acceleration(system, float(t), y[:n], y[n:], reps=1, batches=1)
        return total

    def uk_rust(T, Y):
        Q, QD = [y[:n] for y in Y], [y[n:] for y in Y]
        tic = clock()
        for t, q, qd in zip(T, Q, QD):
            qdd(t, q, qd)
        return clock() - tic

    def uk_numpy(T, Y):
        terms = ref.terms
        tic = clock()
        for t, y in zip(T, Y):
            uk_qdd(*terms(t, y[:n], y[n:]))
        return clock() - tic

    def cp_every(T, Y):
        tic = clock()
        for t, y in zip(T, Y):
            q, qd = y[:n], y[n:]
            part = choose_partition(ref.A(q))
            reduced_accelerations(ref, part, t, q, qd)
        return clock() - tic

    def cp_once(T, Y):
        ind = part0.ind
        sysm = CPSystem(ref, part0, Y[0][:n])  # the per-call work of simulate_cp
        QI, QDI = [y[:n][ind] for y in Y], [y[n:][ind] for y in Y]
        tic = clock()
        for t, qi, qdi in zip(T, QI, QDI):
            q, qd, _ = sysm.recover(t, qi, qdi)
            sysm.accelerations(t, q, qd)
        return clock() - tic

    def terms_numpy(T, Y):
        terms = ref.terms
        tic = clock()
        for t, y in zip(T, Y):
            terms(t, y[:n], y[n:])
        return clock() - tic

    return {"uk-rust-kernel": uk_rust_kernel, "uk-rust": uk_rust, "uk-numpy": uk_numpy, "cp-once": cp_once,
            "cp-every": cp_every, "terms-numpy": terms_numpy}


def table1(
    out: Optional[str] = None,
    mode: str = "quick",
    theories: Sequence[str] = BEAMS,
    elements: int = 1,
    t_end: float = PAPER_WINDOW,
    method: str = "BDF",
    rtol: float = 1e-6,
    atol: Optional[float] = None,
    repeats: int = 5,
    max_states: int = 1000,
    whole: Optional[bool] = None,
    whole_repeats: Optional[int] = None,
    stream: Optional[TextIO] = None,
) -> Dict[str, Any]:
    """The Table 1 analogue (see the module docstring for the method).

    Parameters
    ----------
    out : str, optional
        Directory for ``table1.md`` and ``table1.csv``.
    theories : sequence of str
        Coupler beam theories, one table column each (default both).
    mode : {"quick", "full"}
        ``"quick"``: time at most ``max_states`` evenly spaced recorded states and project;
        no whole-simulation runs except the recording run.  ``"full"``: every recorded state,
        and whole-simulation runs of every formulation.
    repeats : int
        Sweeps over the states; the best is kept (the paper: best of 5).
    whole : bool, optional
        Run whole simulations with every formulation (default: ``mode == "full"``).
    whole_repeats : int, optional
        Repeats of each whole simulation (default ``repeats``).

    Returns
    -------
    dict
        ``machine``, ``settings``, and per beam: ``states`` (recorded), ``timed`` (states
        timed), ``record`` (the recording run), ``per_call`` and ``total`` (seconds, per
        formulation key), ``projected`` (bool), ``whole`` (per formulation, if run).
    """
    if mode not in ("quick", "full"):
        raise ValueError(f"mode must be 'quick' or 'full', got {mode!r}")
    stream = stream or sys.stdout
    atol = RUN_OPTIONS["defaults"]["atol_per_rtol"] * rtol if atol is None else atol
    whole = (mode == "full") if whole is None else whole
    whole_repeats = repeats if whole_repeats is None else whole_repeats
    info = machine_info()
    result: Dict[str, Any] = {
        "machine": info,
        "settings": {"mode": mode, "elements": elements, "t_end": t_end, "method": method, "rtol": rtol,
                     "atol": atol, "repeats": repeats, "max_states": max_states, "whole": whole,
                     "whole_repeats": whole_repeats},
    }
    print(f"Table 1 analogue ({mode}): {method} rtol {rtol:g} atol {atol:g}, 0..{t_end:g} s, N = {elements}; "
          f"machine: {machine_line(info)}", file=stream, flush=True)
    for beam in theories:
        system = System(scenes.slider_crank(theory=beam, elements=elements))
        T, Y, rec = _timed_uk_run(system, t_end, method, rtol, atol, record=True)
        if rec["status"] != 0:
            raise RuntimeError(f"recording run failed: {rec['message']}")
        k = T.size
        if mode == "quick" and k > max_states:
            sel = np.unique(np.linspace(0, k - 1, max_states).round().astype(int))
        else:
            sel = np.arange(k)
        Ts, Ys = T[sel], Y[sel]
        fns = _accel_functions(system)
        best = {key: np.inf for key in fns}
        with single_blas_thread():
            for fn in fns.values():  # warm-up (imports, caches)
                fn(Ts[:20], Ys[:20])
            for _ in range(max(1, repeats)):
                for key, fn in fns.items():  # interleaved: load changes hit every formulation alike
                    best[key] = min(best[key], fn(Ts, Ys))
        per_call = {key: best[key] / sel.size for key in fns}
        total = {key: per_call[key] * k for key in fns} if sel.size < k else dict(best)
        entry: Dict[str, Any] = {"states": k, "timed": int(sel.size), "record": rec, "per_call": per_call,
                                 "total": total, "projected": bool(sel.size < k)}
        print(f"  {beam}: {k} recorded states ({rec['steps']} steps, njev {rec['njev']}), timed {sel.size}, "
              f"best of {repeats}:", file=stream)
        for key in fns:
            print(f"    {TABLE_ROWS[key]:66s} {per_call[key] * 1e6:10.2f} us/call  {total[key]:9.4f} s"
                  f"{' (projected)' if entry['projected'] else ''}", file=stream, flush=True)
        if whole:
            runs: Dict[str, Dict[str, float]] = {}
            jobs = {
                "uk-rust": lambda: _timed_uk_run(system, t_end, method, rtol, atol)[2],
                "uk-numpy": lambda: simulate(system, t_end, method=method, rtol=rtol, atol=atol, formulation="uk-numpy"),
                "cp-once": lambda: simulate(system, t_end, method=method, rtol=rtol, atol=atol, formulation="cp"),
                "cp-every": lambda: simulate(system, t_end, method=method, rtol=rtol, atol=atol, formulation="cp",
                                             partition="every_call"),
            }
            for rep in range(max(1, whole_repeats)):  # interleaved, like the sweeps
                for key, job in jobs.items():
                    r = job()
                    if not isinstance(r, dict):
                        r = {"wall_time": r.wall_time, "accel_time": float(r.extra.get("accel_time", float("nan"))),
                             "nfev": r.nfev, "njev": r.njev, "status": r.status}
                    if key not in runs or r["accel_time"] < runs[key]["accel_time"]:
                        runs[key] = r
                    print(f"    whole run {rep + 1}, {key:9s}: wall {r['wall_time']:8.3f} s, in rhs "
                          f"{r['accel_time']:8.3f} s, nfev {r['nfev']}", file=stream, flush=True)
            entry["whole"] = runs
        result[beam] = entry
    result["machine"]["load_average_end"] = machine_info()["load_average"]
    if out:
        os.makedirs(out, exist_ok=True)
        _write_table1(out, result, theories)
        print(f"wrote {os.path.join(out, 'table1.md')} and table1.csv", file=stream)
    return result


def _ratio(a: float, b: float) -> str:
    return f"{a / b:.2f}x" if b > 0 and np.isfinite(a) and np.isfinite(b) else "-"


def _write_table1(out: str, r: Dict[str, Any], beams: Sequence[str]) -> None:
    s = r["settings"]
    keys = [k for k in TABLE_ROWS if k in r[beams[0]]["total"]]
    with open(os.path.join(out, "table1.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["beam", "formulation", "states", "timed_states", "projected", "per_call_s", "total_s",
                    "whole_wall_s", "whole_accel_s", "whole_nfev"])
        for beam in beams:
            e = r[beam]
            for k in keys:
                wr = (e.get("whole") or {}).get(k, {})
                w.writerow([beam, k, e["states"], e["timed"], e["projected"], repr(e["per_call"][k]),
                            repr(e["total"][k]), repr(wr.get("wall_time", "")), repr(wr.get("accel_time", "")),
                            wr.get("nfev", "")])
    m = r["machine"]
    L: List[str] = []
    proj = any(r[b]["projected"] for b in beams)
    L.append("# Table 1 analogue: time spent computing accelerations, UK vs CP")
    L.append("")
    L.append(f"Machine: {machine_line(m)}; load average at the end {m['load_average_end'][0]:.2f}.")
    L.append("")
    L.append(f"States: every right-hand-side call of one scipy `{s['method']}` run (rtol {s['rtol']:g}, atol "
             f"{s['atol']:g}, 0..{s['t_end']:g} s, coupler N = {s['elements']}) driven by the Rust UK; every "
             f"formulation is evaluated on the same states; best of {s['repeats']} sweeps. "
             + ("Mode `quick`: an evenly spaced subset of the states is timed and the total is **projected** "
                "(mean per call x number of states)." if proj else "Mode `full`: every state is timed."))
    L.append("")
    head = "| formulation | " + " | ".join(f"{BEAM_LABEL[b]} (s)" for b in beams) + " | " + \
        " | ".join(f"{BEAM_LABEL[b]} per call (us)" for b in beams) + " |"
    L.append(head)
    L.append("|---" * (1 + 2 * len(beams)) + "|")
    for k in keys:
        L.append(f"| {TABLE_ROWS[k]} | " + " | ".join(f"{r[b]['total'][k]:.4f}" for b in beams) + " | "
                 + " | ".join(f"{r[b]['per_call'][k] * 1e6:.2f}" for b in beams) + " |")
    for k, label in (("cp", "paper: CP (MATLAB, partition every call)"), ("uk", "paper: UK (MATLAB)")):
        L.append(f"| {label} | " + " | ".join(f"{PAPER_TABLE1[b][k]:.3f}" for b in beams) + " | "
                 + " | ".join("-" for _ in beams) + " |")
    L.append("")
    L.append("States per beam model: " + ", ".join(
        f"{BEAM_LABEL[b]} {r[b]['states']} (timed {r[b]['timed']})" for b in beams) + ".")
    L.append("")
    L.append("Ratios (same states, same run; > 1 means UK is faster):")
    L.append("")
    L.append("| ratio | " + " | ".join(BEAM_LABEL[b] for b in beams) + " | paper |")
    L.append("|---" * (2 + len(beams)) + "|")
    paper = " / ".join(f"{PAPER_TABLE1[b]['cp'] / PAPER_TABLE1[b]['uk']:.2f}x" for b in beams)
    pairs = [("cp-every", "uk-numpy", paper), ("cp-once", "uk-numpy", "'comparable' (not measured)"),
             ("cp-every", "uk-rust", "-"), ("cp-once", "uk-rust", "-"), ("cp-every", "uk-rust-kernel", "-"),
             ("uk-numpy", "uk-rust", "-")]
    for a, b_, pap in pairs:
        if a in keys and b_ in keys:
            L.append(f"| {TABLE_ROWS[a].split(' (')[0]} / {TABLE_ROWS[b_].split(' (')[0]} | "
                     + " | ".join(_ratio(r[b]['total'][a], r[b]['total'][b_]) for b in beams) + f" | {pap} |")
    if "terms-numpy" in keys:
        def solve_ratio(b):
            t = r[b]["total"]
            return _ratio(t["cp-every"] - t["terms-numpy"], t["uk-numpy"] - t["terms-numpy"])
        L.append("| CP every call / UK, NumPy, without the shared model terms (solution stage only) | "
                 + " | ".join(solve_ratio(b) for b in beams) + " | - |")
    L.append("")
    rec_line = ", ".join(f"{BEAM_LABEL[b]}: wall {r[b]['record']['wall_time']:.2f} s, {r[b]['record']['nfev']} rhs "
                         f"calls, {r[b]['record']['njev']} Jacobians, {r[b]['record']['accel_time']:.3f} s inside "
                         f"System.rhs/jac" for b in beams)
    L.append(f"Recording run (UK, Rust, scipy {s['method']}): {rec_line}.")
    if all("whole" in r[b] for b in beams):
        L.append("")
        L.append(f"Whole simulations, each formulation driving its own `{s['method']}` run (best of "
                 f"{s['whole_repeats']} by time in the right-hand side; reference formulations count the "
                 f"forward-difference Jacobian's calls in nfev, the Rust UK computes its Jacobian in Rust):")
        L.append("")
        L.append("| formulation | " + " | ".join(f"{BEAM_LABEL[b]}: in rhs (s) / wall (s) / nfev" for b in beams) + " |")
        L.append("|---" * (1 + len(beams)) + "|")
        for k in ("uk-rust", "uk-numpy", "cp-once", "cp-every"):
            L.append(f"| {TABLE_ROWS[k]} | " + " | ".join(
                f"{r[b]['whole'][k]['accel_time']:.3f} / {r[b]['whole'][k]['wall_time']:.3f} / {r[b]['whole'][k]['nfev']}"
                for b in beams) + " |")
    L.append("")
    with open(os.path.join(out, "table1.md"), "w") as fh:
        fh.write("\n".join(L))


# ----------------------------------------------------------------------------------- both
def run_paper(out: str, table: str = "quick", table_t_end: Optional[float] = None, repeats: int = 5,
              stream: Optional[TextIO] = None, **fig4_kwargs: Any) -> Dict[str, Any]:
    """Fig. 4 (:func:`run_fig4`) and, unless ``table == "none"``, the Table 1 analogue
    (:func:`table1` with ``mode=table``) over ``0..min(t_end, 0.07)`` s."""
    summary = run_fig4(out, stream=stream, **fig4_kwargs)
    res: Dict[str, Any] = {"fig4": summary}
    if table != "none":
        t_end = fig4_kwargs.get("t_end", 0.1)
        span = table_t_end if table_t_end is not None else min(t_end, PAPER_WINDOW)
        res["table1"] = table1(out, mode=table, elements=fig4_kwargs.get("elements", 1), t_end=span,
                               repeats=repeats, stream=stream)
    return res
