"""The stability report: the catalogue :mod:`studies.extreme` run with every integrator.

:func:`report` writes ``stability.md`` and ``stability.json`` (``python -m studies stability --out DIR
[--quick] [--case NAME]``).  The safeguards and diagnostics it uses are library functions of
:mod:`ukflex.stability` (``run``, ``check``, ``rank_history``, ``buckling_ratio``,
``ffrf_validity``, ``scaling_accuracy``).
"""

from __future__ import annotations

import json
import math
import os
import time
import traceback
import warnings
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ukflex import System, SimulationResult, UkflexError, simulate
from ukflex.analysis.stability import (IntegrationFailure, beam_properties, buckling_ratio, check, drift, ffrf_validity,
                         rank_history, scaling_accuracy)
from . import extreme

__all__ = ["report"]


def _has_beam(system: System, body: str) -> bool:
    return body in system.body_names and system.body_kind(body) == "beam"


def _v_mid(result: SimulationResult, body: str = "coupler") -> np.ndarray:
    _, v = result.beam_displacement(body, 0.5)
    return v / beam_properties(result.system, body)["length"]


def _observable(result: SimulationResult) -> Tuple[str, np.ndarray]:
    """What the report compares: coupler midpoint ``v/Lb`` if there is a coupler beam, else every
    coordinate (rigid mechanisms)."""
    if _has_beam(result.system, "coupler"):
        return "v(Lb/2)/Lb", _v_mid(result)
    return "q", result.q


def _closed_form_error(c: extreme.Case, quick: bool, result: SimulationResult) -> Optional[Tuple[str, float]]:
    s = result.system
    q = result.q.T  # (nt, n): columns per coordinate
    name = c.name
    if name == "singular_slider_crank":  # slider branch: coupler angle = -omega t
        w = c.parameters(quick)["omega"]
        return "closed form (coupler angle = -omega t)", float(np.abs(q[:, s.coordinate_index("coupler.theta")] + w * result.t).max())
    if name in ("flat_parallelogram", "redundant_parallelogram"):
        th = q[:, s.coordinate_index("crank.theta")]
        e = np.abs(q[:, s.coordinate_index("rocker.theta")] - th).max()
        e = max(e, np.abs(q[:, s.coordinate_index("coupler.theta")]).max())
        if "extra.theta" in s.coordinate_names:
            e = max(e, np.abs(q[:, s.coordinate_index("extra.theta")] - th).max())
        return "closed form (parallelogram branch: rocker angle = crank angle, coupler angle 0)", float(e)
    return None


def _energy_drift(result: SimulationResult) -> float:
    """``(max E - min E) / max T`` over the run (``T + V`` may start at 0: normalize by the
    largest kinetic energy reached)."""
    s = result.system
    E = result.energy()
    T = np.array([s.kinetic_energy(q, qd) for q, qd in zip(result.q.T, result.qd.T)])
    return float(np.ptp(E) / max(T.max(), 1e-300))


def _fmt(x: Any, spec: str = ".2e") -> str:
    if x is None:
        return "-"
    if isinstance(x, float) and not math.isfinite(x):
        return str(x)
    return format(x, spec)


def _case_runs(c, quick: bool, log) -> Dict[str, Any]:
    T = c.duration(quick)
    nt = 201
    t_eval = np.linspace(0.0, T, nt)
    rec: Dict[str, Any] = {"name": c.name, "group": c.group, "title": c.title, "t_end": T, "runs": [], "diagnoses": []}
    try:
        system = System(c.build_scene(quick))
    except UkflexError as exc:
        rec["build_error"] = f"{type(exc).__name__}: {exc}"
        return rec
    rec["n"], rec["m"] = system.n_coords, system.n_constraints
    rec["has_beam"] = any(system.body_kind(b) == "beam" for b in system.body_names)
    rec["cond_M"] = float(np.linalg.cond(system.M(system.q0)))
    rank_tol = (1e-10, 0.0) if c.group == 5 else None
    # reference we trust: UK DOPRI5 at rtol 1e-10 (self-convergence), closed forms where known
    tic = time.perf_counter()
    ref = None
    try:
        ref = simulate(system, T, "DOPRI5", rtol=1e-10, t_eval=t_eval, rank_tolerance=rank_tol, stabilization="none", raise_on_failure=True)
        rec["reference"] = "UK (Rust) DOPRI5, rtol 1e-10"
    except IntegrationFailure as exc:
        rec["reference_error"] = str(exc)
    log(f"  {c.name}: reference {time.perf_counter() - tic:.1f}s")
    label, ref_obs = _observable(ref) if ref is not None else ("", None)
    rec["observable"] = label
    if ref is not None:
        cf = _closed_form_error(c, quick, ref)
        if cf:
            rec["reference_closed_form"] = {"what": cf[0], "error": cf[1]}
        rec["diagnoses"] = [str(d) for d in check(ref, warn=False)]
        if _has_beam(system, "coupler"):
            rec["buckling"] = buckling_ratio(ref, "coupler")
            rec["ffrf"] = ffrf_validity(ref, "coupler")
        if system.description.get("drivers") in (None, []):
            rec["energy_drift_rel"] = _energy_drift(ref)
        rh = rank_history(ref, *(rank_tol or (None, 0.0)))
        rec["rank"] = {"full": rh["full"], "min": rh["min_rank"], "changes": rh["changes"][:4],
                       "min_ratio": float(rh["ratio"].min())}
    skip_scipy = c.name in ("stiff_E1e4", "stiff_N32", "stiff_N64", "long_run")
    has_beam = any(system.body_kind(b) == "beam" for b in system.body_names)
    configs = [("UK", "DOPRI5"), ("UK", "RADAU5")] + ([] if skip_scipy else [("UK", "DOP853")])
    if not has_beam:  # scipy's Radau costs ~10 ms per step in Python on the flexible scenes
        configs.append(("UK", "Radau"))
    if c.group == 5:
        configs += [("UK default rcond", "DOP853")]
    for form, meth in configs:
        tic = time.perf_counter()
        entry: Dict[str, Any] = {"formulation": form, "method": meth, "rtol": 1e-6}
        try:
            rt = None if form == "UK default rcond" else rank_tol
            r = simulate(system, T, meth, rtol=1e-6, t_eval=t_eval, rank_tolerance=rt, max_nfev=2_000_000, stabilization="none", raise_on_failure=True)
            entry.update(ok=True, wall=time.perf_counter() - tic, nfev=r.nfev, drift=drift(r)["max_position"])
            if ref is not None:
                entry["error"] = float(np.abs(_observable(r)[1] - ref_obs).max())
            if system.description.get("drivers") in (None, []):
                entry["energy_drift_rel"] = _energy_drift(r)
        except IntegrationFailure as exc:
            entry.update(ok=False, wall=time.perf_counter() - tic, error_message=exc.reason,
                         t_fail=exc.t_fail, partial_outputs=int(exc.result.t.size) if exc.result is not None else 0)
        except UkflexError as exc:
            entry.update(ok=False, wall=time.perf_counter() - tic, error_message=f"{type(exc).__name__}: {exc}")
        log(f"  {c.name}: {form} {meth} {'ok' if entry['ok'] else 'FAILED'} {entry['wall']:.1f}s")
        rec["runs"].append(entry)
    if c.cp_t_end is not None:
        Tc = min(c.cp_t_end, T, 0.001 if (quick and has_beam) else np.inf)
        te = t_eval[t_eval <= Tc + 1e-15]
        entry = {"formulation": "CP (NumPy)", "method": "DOP853", "rtol": 1e-8, "t_end": Tc}
        tic = time.perf_counter()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = simulate(system, Tc, method="DOP853", rtol=1e-8, atol=1e-11, t_eval=te, formulation="cp")
            entry["wall"] = time.perf_counter() - tic
            entry["ok"] = bool(r.status >= 0 and r.t.size == te.size)
            entry["drift"] = drift(r)["max_position"]
            entry["repartitions"] = int(r.extra.get("repartitions", 0) or 0)
            if not entry["ok"]:
                entry["error_message"] = r.message
            elif ref is not None:
                entry["error"] = float(np.abs(_observable(r)[1] - ref_obs[..., : te.size]).max())
        except Exception as exc:  # the reference CP raises plain NumPy / Python errors
            entry.update(ok=False, wall=time.perf_counter() - tic, error_message=f"{type(exc).__name__}: {exc}")
        log(f"  {c.name}: CP {'ok' if entry['ok'] else 'FAILED'} {entry['wall']:.1f}s")
        rec["runs"].append(entry)
    return rec


def _long_run_study(quick: bool, log) -> Dict[str, Any]:
    revs = 10 if quick else 100
    T = revs * extreme.REVOLUTION
    system = System(extreme.long_run())
    t_eval = np.linspace(0.0, T, 20 * revs + 1)
    out: Dict[str, Any] = {"revolutions": revs, "t_end": T, "method": "DOPRI5", "rtol": 1e-6, "rows": []}
    for label, stab in [("none", None), ("Baumgarte alpha = beta = 10/s", ("baumgarte", 10.0, 10.0)),
                        ("Baumgarte alpha = beta = 100/s", ("baumgarte", 100.0, 100.0)), ("projection every step", "projection")]:
        tic = time.perf_counter()
        r = simulate(system, T, "DOPRI5", rtol=1e-6, t_eval=t_eval, stabilization=stab or "none", raise_on_failure=True)
        wall = time.perf_counter() - tic
        d = drift(r)
        out["rows"].append({"stabilization": label, "max_position": d["max_position"], "final_position": d["final_position"],
                            "max_velocity": d["max_velocity"], "wall": wall, "nfev": r.nfev,
                            "peak_v": float(np.abs(_v_mid(r)).max())})
        log(f"  long run {label}: {wall:.1f}s drift {d['max_position']:.2e}")
    system.set_stabilization("none")
    # scipy path: projection by restarts
    tic = time.perf_counter()
    Ts = min(T, 10 * extreme.REVOLUTION)
    r = simulate(system, Ts, "DOP853", rtol=1e-6, t_eval=np.linspace(0, Ts, 201), stabilization="none", raise_on_failure=True)
    r2 = simulate(system, Ts, "DOP853", rtol=1e-6, t_eval=np.linspace(0, Ts, 201),
             stabilization={"kind": "projection", "interval": extreme.REVOLUTION / 10}, raise_on_failure=True)
    out["scipy"] = {"revolutions": round(Ts / extreme.REVOLUTION), "none": drift(r)["max_position"],
                    "projection_every_0.1_rev": drift(r2)["max_position"], "projections": r2.extra.get("projections")}
    log(f"  long run scipy: {time.perf_counter() - tic:.1f}s")
    return out


def _scaling_study(quick: bool) -> List[Dict[str, Any]]:
    rows = []
    cases = [("paper, N = 1", extreme.stiff(1.0)), ("paper, N = 64", extreme.stiff(1.0, elements=64)),
             ("double pendulum 1 : 1e-6", extreme.mass_ratio(1e-6)), ("double pendulum 1 : 1e-9", extreme.mass_ratio(1e-9)),
             ("slider block 1e-9 kg", extreme.near_massless()), ("paper N = 2, SI", extreme.slider_crank_units("m")),
             ("paper N = 2, mm", extreme.slider_crank_units("mm"))]
    for label, sc in cases:
        system = System(sc)
        r = simulate(system, 0.01, "DOPRI5", rtol=1e-8, t_eval=[0.0, 0.01], stabilization="none", raise_on_failure=True)
        a = scaling_accuracy(system, r.t[-1], r.q[:, -1], r.qd[:, -1])
        a["case"] = label
        rows.append(a)
    return rows


def _units_study(quick: bool) -> Dict[str, Any]:
    T = 0.02 if quick else 0.07
    te = np.linspace(0, T, 201)
    out = {}
    res = {}
    for u in ("m", "mm"):
        system = System(extreme.slider_crank_units(u))
        res[u] = simulate(system, T, "DOPRI5", rtol=1e-10, t_eval=te, stabilization="none", raise_on_failure=True)
    out["max_abs_diff_v_over_Lb"] = float(np.abs(_v_mid(res["m"]) - _v_mid(res["mm"])).max())
    out["peak_v_over_Lb"] = float(np.abs(_v_mid(res["m"])).max())
    out["t_end"] = T
    return out


def report(out_dir: str, quick: bool = False, cases: Optional[Sequence[str]] = None, verbose: bool = True) -> Dict[str, Any]:
    """Run the catalogue :data:`studies.extreme.CASES` and write ``stability.md`` and
    ``stability.json`` into ``out_dir``.

    Per case: the UK core with the native ``DOPRI5`` / ``RADAU5`` and scipy's ``DOP853`` /
    ``Radau`` at ``rtol = 1e-6``, and the NumPy coordinate partitioning (``DOP853``, ``rtol =
    1e-8``) on a short interval; error against the reference (UK ``DOPRI5`` at ``rtol = 1e-10``
    and closed forms where they exist), drift, run time, diagnoses and failure messages.  Then
    the long-run drift study, the scaling/accuracy study and the units check.
    ``quick=True`` runs the reduced sizes (about a minute).

    Returns the data written to ``stability.json``.
    """
    os.makedirs(out_dir, exist_ok=True)

    def log(msg):
        if verbose:
            print(msg, flush=True)

    tic = time.perf_counter()
    data: Dict[str, Any] = {"quick": quick, "cases": []}
    for c in extreme.CASES:
        if cases is not None and c.name not in cases:
            continue
        try:
            data["cases"].append(_case_runs(c, quick, log))
        except Exception as exc:  # a report must not die on one case
            data["cases"].append({"name": c.name, "group": c.group, "title": c.title,
                                  "report_error": "".join(traceback.format_exception_only(type(exc), exc)).strip()})
    if cases is None:
        data["long_run"] = _long_run_study(quick, log)
        data["scaling"] = _scaling_study(quick)
        data["units"] = _units_study(quick)
    data["wall_time"] = time.perf_counter() - tic
    with open(os.path.join(out_dir, "stability.json"), "w") as fh:
        json.dump(data, fh, indent=1, default=lambda o: o.tolist() if isinstance(o, np.ndarray) else str(o))
    with open(os.path.join(out_dir, "stability.md"), "w") as fh:
        fh.write(_markdown(data))
    return data


def _markdown(data: Dict[str, Any]) -> str:
    L: List[str] = []
    L.append(f"# Stability report ({'quick, reduced sizes' if data['quick'] else 'full size'})\n")
    L.append("Generated by `python -m studies stability --out DIR" + (" --quick" if data["quick"] else "") +
             f"` ({data['wall_time']:.0f} s). Error = max abs difference of the observable against the reference "
             "(UK DOPRI5 at rtol 1e-10 on the same output grid of 201 points); drift = max ||Phi||; runs at rtol 1e-6 "
             "unless stated.\n")
    L.append("| case | group | n / m | cond(M) | UK DOPRI5 | UK RADAU5 | UK scipy DOP853 | UK scipy Radau | CP (NumPy) | physics / diagnosis |")
    L.append("|---|---|---|---|---|---|---|---|---|---|")
    for c in data["cases"]:
        if "report_error" in c or "build_error" in c:
            L.append(f"| {c['name']} | {extreme.GROUPS[c['group']]} | - | - | refused | refused | refused | refused | - | "
                     f"{c.get('build_error') or c.get('report_error')} |")
            continue
        cells = {}
        for r in c["runs"]:
            key = (r["formulation"], r["method"])
            if r.get("ok"):
                txt = f"ok: err {_fmt(r.get('error'))}, drift {_fmt(r.get('drift'))}, {r['wall']:.2f} s"
                if "energy_drift_rel" in r:
                    txt += f", dE/E {_fmt(r['energy_drift_rel'])}"
                if r["formulation"].startswith("CP"):
                    txt += f" (0..{r['t_end']:.3g} s, {r.get('repartitions', 0)} repart.)"
            else:
                txt = f"**failed**: {r.get('error_message', '')[:160]}"
                if "t_fail" in r:
                    txt += f" (t = {r['t_fail']:.4g} s, {r.get('partial_outputs', 0)} outputs kept)"
            cells[key] = txt
        cp = cells.get(("CP (NumPy)", "DOP853"), "not run (too slow in NumPy at this size)")
        phys = []
        if "buckling" in c:
            b = c["buckling"]
            phys.append(f"max compression {b['max_compression']:.4g} = {b['ratio']:.3f} P_cr")
        if "ffrf" in c:
            phys.append(f"max v/Lb {c['ffrf']['max_v_over_L']:.3g}, max psi {c['ffrf']['max_psi']:.3g} rad")
        if "reference_closed_form" in c:
            phys.append(f"ref. vs {c['reference_closed_form']['what']}: {c['reference_closed_form']['error']:.1e}")
        if "energy_drift_rel" in c:
            phys.append(f"ref. dE/E {c['energy_drift_rel']:.1e}")
        if "rank" in c:
            rk = c["rank"]
            phys.append(f"rank {rk['min']}..{rk['full']} of {rk['full']}, min sigma ratio {rk['min_ratio']:.1e}")
        phys += c.get("diagnoses", [])
        extra_uk = cells.get(("UK default rcond", "DOP853"))
        if extra_uk:
            phys.append(f"scipy DOP853 with the default rcond = max(m, n) eps: {extra_uk}")
        L.append(f"| {c['name']} ({c['title']}, {c['t_end']:.4g} s) | {extreme.GROUPS[c['group']]} | {c['n']} / {c['m']} | "
                 f"{c['cond_M']:.1e} | {cells.get(('UK', 'DOPRI5'), '-')} | {cells.get(('UK', 'RADAU5'), '-')} | "
                 f"{cells.get(('UK', 'DOP853'), 'not run')} | {cells.get(('UK', 'Radau'), 'not run (flexible: slow in Python)' if c.get('has_beam') else 'not run')} | {cp} | "
                 + "; ".join(phys).replace("|", "/") + " |")
    if "long_run" in data:
        lr = data["long_run"]
        L.append(f"\n## Long run: {lr['revolutions']} revolutions ({lr['t_end']:.3f} s), native DOPRI5, rtol 1e-6\n")
        L.append("| stabilization | max ||Phi|| | final ||Phi|| | max ||A qd + Phi_t|| | peak v/Lb | nfev | wall [s] |")
        L.append("|---|---|---|---|---|---|---|")
        for r in lr["rows"]:
            L.append(f"| {r['stabilization']} | {r['max_position']:.2e} | {r['final_position']:.2e} | {r['max_velocity']:.2e} | "
                     f"{r['peak_v']:.4e} | {r['nfev']} | {r['wall']:.2f} |")
        s = lr["scipy"]
        L.append(f"\nscipy DOP853 over {s['revolutions']} revolutions: max ||Phi|| {s['none']:.2e} without, "
                 f"{s['projection_every_0.1_rev']:.2e} with projection every 0.1 revolution ({s['projections']} restarts).")
    if "scaling" in data:
        L.append("\n## Accuracy of the acceleration solve and diagonal scaling\n")
        L.append("Relative error `||qdd - qdd_ref||_M / ||qdd_ref||_M` at the state of t = 0.01 s; reference: the augmented "
                 "system in 80-bit extended precision (same double-precision M, Q, A, b). Scaled: `D = diag(M)^-1/2`.\n")
        L.append("| case | n | cond(M) | cond(DMD) | cond(A F^-T) | Rust UK | UK symmetric root | scaled | UK dense Cholesky | scaled | augmented LU | scaled |")
        L.append("|---|---|---|---|---|---|---|---|---|---|---|---|")
        for a in data["scaling"]:
            L.append(f"| {a['case']} | {a['n']} | {a['cond_M']:.1e} | {a['cond_M_scaled']:.1e} | {a['cond_B']:.1e} | {a['rust_uk']:.1e} | "
                     f"{a['uk_symmetric']:.1e} | {a['uk_symmetric_scaled']:.1e} | {a['uk_cholesky']:.1e} | {a['uk_cholesky_scaled']:.1e} | "
                     f"{a['augmented']:.1e} | {a['augmented_scaled']:.1e} |")
    if "units" in data:
        u = data["units"]
        L.append(f"\n## Units\n\nPaper scene (N = 2) in m and in mm (kg, s), DOPRI5 rtol 1e-10, 0..{u['t_end']} s: "
                 f"max |v/Lb (m) - v/Lb (mm)| = {u['max_abs_diff_v_over_Lb']:.2e} (peak {u['peak_v_over_Lb']:.3e}).")
    return "\n".join(L) + "\n"
