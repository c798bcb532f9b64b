"""Cross-checks against the NumPy reference, behind docs/errata.md and the cross-validation report.

    python -m studies crosscheck errata   [--t-end 0.07] [--rtol 1e-8]   the paper's printed terms vs corrected
    python -m studies crosscheck sweep    [--t-end 0.07]                 Rust UK vs NumPy CP over rtol
    python -m studies crosscheck timing   [--t-end 0.02]                 NumPy UK vs CP acceleration time
    python -m studies crosscheck bdf      [--t-end 0.07]                 paper-like BDF runs, E-B vs Timoshenko

(:func:`run` is the same as a function.)  ``errata`` and ``timing`` use only the NumPy
reference; ``sweep`` and ``bdf`` compare it with the Rust core through :class:`ukflex.System`.
"""
from __future__ import annotations

import sys
import time
import warnings
from typing import Optional, TextIO

import numpy as np
from scipy.integrate import solve_ivp

from ukflex import System
from ukflex.reference import ReferenceModel, correct_initial_state, simulate_cp, simulate_uk_numpy
from ukflex.reference.paper_closed_form import ALL_FIXES, PaperSliderCrank
from ukflex.reference.uk import fd_jacobian

from . import progress

__all__ = ["STUDIES", "paper_description", "errata_effects", "rtol_sweep", "timing", "bdf_study", "run"]

#: The studies of :func:`run` (``python -m studies crosscheck STUDY``).
STUDIES = ("errata", "sweep", "timing", "bdf")


def paper_description(theory="timoshenko", elements=1, gravity=True):
    """The paper's scene as a description dict (crank frame at the ground pivot)."""
    L, Lb, d, rho = 0.1524, 0.3048, 0.00635, 7834.56
    a = np.pi * d * d / 4
    mc = rho * a * L
    desc = {
        "bodies": [
            {"name": "crank", "kind": "rigid", "mass": mc, "inertia": mc * L * L / 12,
             "com": [L / 2, 0.0], "position": [0.0, 0.0], "angle": 0.0,
             "angular_velocity": 124.8},
            {"name": "coupler", "kind": "beam", "length": Lb, "elements": elements,
             "theory": theory, "density": rho, "youngs_modulus": 2.06843e11,
             "poisson_ratio": 0.285, "shear_factor": 0.8,
             "section": {"shape": "circular", "diameter": d}, "frame": "pinned-pinned",
             "position": [L, 0.0], "angle": 0.0},
        ],
        "joints": [
            {"kind": "revolute", "a": {"body": "crank", "point": [0.0, 0.0]},
             "b": {"body": "ground", "point": [0.0, 0.0]}},
            {"kind": "revolute", "a": {"body": "crank", "point": [L, 0.0]},
             "b": {"body": "coupler", "xi": 0.0}},
            {"kind": "point_on_line", "point": {"body": "coupler", "xi": 1.0},
             "line": {"body": "ground", "point": [0.0, 0.0], "angle": 0.0}},
        ],
        "drivers": [{"kind": "angle", "a": {"body": "crank", "point": [0.0, 0.0]},
                     "motion": {"kind": "constant_speed", "initial": 0.0, "speed": 124.8}}],
    }
    if gravity:
        desc["gravity"] = [0.0, -9.81]
    return desc


def _closed_form_deflection(model, t_end, t_eval, rtol, atol):
    q0, qd0 = model.initial_guess()
    res = simulate_uk_numpy(model, t_end, method="DOP853", rtol=rtol, atol=atol, t_eval=t_eval,
                            q0=q0, qd0=qd0)
    if not res.success:
        raise RuntimeError(res.message)
    return PaperSliderCrank.midpoint_deflection(res.q)


def errata_effects(theory="timoshenko", t_end=0.07, rtol=1e-8, atol=1e-11, npts=701):
    """Coupler midpoint deflection v(Lb/2)/Lb of the closed-form model for every variant.

    Returns dict variant -> (t, v). Reference variant: ``"corrected"`` (all fixes, ukflex's
    ``(theta_dot + psi_dot)^2`` rotary inertia), which equals the general model.
    """
    t = np.linspace(0.0, t_end, npts)
    variants = {
        "corrected": dict(fixes="all", rotary="full"),
        "as printed": dict(fixes=(), rotary="printed"),
        "all fixes, rotary as printed": dict(fixes="all", rotary="printed"),
        "all fixes, rotary psi_dot^2 only (eq. 19)": dict(fixes="all", rotary="psi_dot"),
    }
    for fx in ALL_FIXES:
        variants[f"all fixes except {fx}"] = dict(fixes=tuple(set(ALL_FIXES) - {fx}),
                                                  rotary="full")
    out = {}
    for name, kw in variants.items():
        progress("crosscheck", f"errata {theory}: {name}")
        out[name] = (t, _closed_form_deflection(PaperSliderCrank(theory, **kw), t_end, t, rtol, atol))
    # the general element-by-element model through coordinate partitioning, for the record
    m = ReferenceModel(paper_description(theory))
    cp = simulate_cp(m, t_end, method="DOP853", rtol=rtol, atol=atol, t_eval=t)
    S, _ = m.beam_shape("coupler", 0.5)
    out["general model (CP)"] = (t, (S @ cp.q[6:9])[1] / 0.3048)
    return out


def _print_errata(theory, out, stream):
    t, ref = out["corrected"]
    peak = np.abs(ref).max()
    print(f"\n### {theory}: coupler midpoint deflection v(Lb/2)/Lb, t in [0, {t[-1]:g}] s", file=stream)
    print(f"corrected model: max|v|/Lb = {peak:.5e} at t = {t[np.argmax(np.abs(ref))]:.4f} s\n", file=stream)
    print("| variant | max abs(v - v_corrected)/Lb | relative to peak | its own peak |v|/Lb |", file=stream)
    print("|---|---|---|---|", file=stream)
    for name, (_, v) in out.items():
        if name == "corrected":
            continue
        d = np.abs(v - ref).max()
        print(f"| {name} | {d:.3e} | {d / peak:.2e} | {np.abs(v).max():.5e} |", file=stream)


def _rust(description):
    """The Rust core on the description, without the initial correction (the studies start
    from the reference's corrected state)."""
    return System(description, correct=False)


def _v_mid(system, S, Y):
    """v(Lb/2)/Lb of the coupler for states Y (rows: the coordinates, or [q; qd])."""
    return (S @ Y[system.elastic_slice("coupler")])[1] / system.body_info("coupler")["length"]


def rtol_sweep(theory="timoshenko", gravity=True, t_end=0.07, rtols=(1e-6, 1e-8, 1e-10),
               npts=71, method="DOP853"):
    """Rust UK (solve_ivp on System.rhs) vs NumPy CP: max |v_rust - v_cp| / max |v|."""
    d = paper_description(theory, gravity=gravity)
    m = ReferenceModel(d)
    r = _rust(d)
    q0, qd0 = correct_initial_state(m)
    t = np.linspace(0.0, t_end, npts)
    S, _ = m.beam_shape("coupler", 0.5)
    rows = []
    for rtol in rtols:
        progress("crosscheck", f"sweep {theory}, gravity={gravity}: rtol {rtol:g}")
        atol = 1e-3 * rtol
        tic = time.perf_counter()
        sr = solve_ivp(r.rhs, (0, t_end), np.r_[q0, qd0], method=method, rtol=rtol, atol=atol,
                       t_eval=t)
        wr = time.perf_counter() - tic
        cp = simulate_cp(m, t_end, method=method, rtol=rtol, atol=atol, t_eval=t, q0=q0, qd0=qd0)
        vr = _v_mid(r, S, sr.y)
        vc = _v_mid(r, S, cp.q)
        rows.append(dict(rtol=rtol, diff=np.abs(vr - vc).max(), peak=np.abs(vr).max(),
                         rust_nfev=sr.nfev, rust_wall=wr, cp_nfev=cp.nfev, cp_wall=cp.wall_time,
                         repartitions=cp.repartitions,
                         rust_phi=np.abs([r.phi(tk, sr.y[:r.n_coords, k]) for k, tk in enumerate(t)]).max()))
    return rows


def timing(theory="timoshenko", t_end=0.02, rtol=1e-6, method="DOP853"):
    """Acceleration-evaluation time: UK (NumPy), CP partitioned once, CP every call."""
    m = ReferenceModel(paper_description(theory))
    q0, qd0 = correct_initial_state(m)
    out = {}
    for name, f in [
        ("UK (NumPy, eigh + pinv)", lambda: simulate_uk_numpy(m, t_end, method=method, rtol=rtol,
                                                               atol=1e-3 * rtol, q0=q0, qd0=qd0)),
        ("CP, partition once", lambda: simulate_cp(m, t_end, method=method, rtol=rtol,
                                                   atol=1e-3 * rtol, q0=q0, qd0=qd0)),
        ("CP, partition every call", lambda: simulate_cp(m, t_end, method=method, rtol=rtol,
                                                         atol=1e-3 * rtol, q0=q0, qd0=qd0,
                                                         partition="every_call")),
    ]:
        progress("crosscheck", f"timing {theory}: {name}")
        best = None
        for _ in range(3):
            res = f()
            if best is None or res.accel_time < best.accel_time:
                best = res
        out[name] = best
    return out


def bdf_study(t_end=0.07, stream=None):
    """Paper-like integrator (BDF, rtol 1e-6): Rust UK vs NumPy CP vs a DOP853 1e-10 reference;
    E-B vs Timoshenko; and scipy's num_jac overflow on raw System.rhs at rtol 1e-8."""
    stream = stream or sys.stdout
    t = np.linspace(0.0, t_end, 701)
    ref = {}
    for beam in ("euler-bernoulli", "timoshenko"):
        progress("crosscheck", f"bdf {beam}")
        d = paper_description(beam)
        r, m = _rust(d), ReferenceModel(d)
        q0, qd0 = correct_initial_state(m)
        S, _ = m.beam_shape("coupler", 0.5)
        y0 = np.r_[q0, qd0]
        sr = solve_ivp(r.rhs, (0, t_end), y0, method="DOP853", rtol=1e-10, atol=1e-13, t_eval=t)
        ref[beam] = _v_mid(r, S, sr.y)
        pk = np.abs(ref[beam]).max()
        sb = solve_ivp(r.rhs, (0, t_end), y0, method="BDF", rtol=1e-6, atol=1e-9, t_eval=t)
        vb = _v_mid(r, S, sb.y)
        cp = simulate_cp(m, t_end, method="BDF", rtol=1e-6, atol=1e-9, t_eval=t[::10], q0=q0,
                         qd0=qd0)
        vc = _v_mid(r, S, cp.q)
        print(f"{beam}: BDF rtol 1e-6, atol 1e-9 (max abs dv / peak): Rust UK vs reference "
              f"{np.abs(vb - ref[beam]).max() / pk:.2e}, NumPy CP vs reference "
              f"{np.abs(vc - ref[beam][::10]).max() / pk:.2e}, Rust UK vs CP "
              f"{np.abs(vb[::10] - vc).max() / pk:.2e}; nfev Rust {sb.nfev}, CP {cp.nfev}", file=stream)
        for jac in ("scipy num_jac", "fd_jacobian"):
            kw = {} if jac.startswith("scipy") else {"jac": fd_jacobian(r.rhs, 1e-11)}
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                try:
                    s2 = solve_ivp(r.rhs, (0, t_end), y0, method="BDF", rtol=1e-8, atol=1e-11,
                                   **kw)
                    print(f"  raw System.rhs, BDF rtol 1e-8, {jac}: status {s2.status}, "
                          f"njev {s2.njev}", file=stream)
                except Exception as exc:            # noqa: BLE001 (report what happened)
                    print(f"  raw System.rhs, BDF rtol 1e-8, {jac}: {type(exc).__name__}: {exc}", file=stream)
    dv = np.abs(ref["euler-bernoulli"] - ref["timoshenko"])
    pk = np.abs(ref["timoshenko"]).max()
    print(f"E-B vs Timoshenko: max abs dv/Lb = {dv.max():.3e} ({dv.max() / pk:.2e} of the peak); "
          f"peaks {np.abs(ref['euler-bernoulli']).max():.6e}, {pk:.6e}", file=stream)


def run(study: str, t_end: Optional[float] = None, rtol: float = 1e-8, theory: Optional[str] = None,
        stream: Optional[TextIO] = None) -> None:
    """Run one of :data:`STUDIES` for ``theory`` (default both) and print its markdown tables.

    ``t_end`` defaults to 0.07 s (0.02 s for ``timing``); ``rtol`` applies to ``errata``.
    """
    if study not in STUDIES:
        raise ValueError(f"unknown study {study!r}; expected one of {STUDIES}")
    stream = stream or sys.stdout
    theories = [theory] if theory else ["euler-bernoulli", "timoshenko"]
    if study == "errata":
        for th in theories:
            _print_errata(th, errata_effects(th, t_end=t_end or 0.07, rtol=rtol, atol=1e-3 * rtol), stream)
    elif study == "bdf":
        bdf_study(t_end=t_end or 0.07, stream=stream)
    elif study == "sweep":
        for th in theories:
            for gravity in (True, False):
                print(f"\n### {th}, gravity={gravity}: Rust UK vs NumPy CP, "
                      f"t in [0, {t_end or 0.07:g}] s (DOP853, atol = 1e-3 rtol)", file=stream)
                print("| rtol | max abs(v_rust - v_cp)/Lb | / peak | Rust nfev | Rust wall s "
                      "| CP nfev | CP wall s | CP repartitions | Rust max abs(Phi) |", file=stream)
                print("|---|---|---|---|---|---|---|---|---|", file=stream)
                for row in rtol_sweep(th, gravity, t_end=t_end or 0.07):
                    print(f"| {row['rtol']:.0e} | {row['diff']:.2e} | {row['diff'] / row['peak']:.2e}"
                          f" | {row['rust_nfev']} | {row['rust_wall']:.2f} | {row['cp_nfev']}"
                          f" | {row['cp_wall']:.1f} | {row['repartitions']} | {row['rust_phi']:.1e} |", file=stream)
    else:
        for th in theories:
            print(f"\n### {th}: t in [0, {t_end or 0.02:g}] s, DOP853 rtol 1e-6, best of 3", file=stream)
            print("| formulation | calls | accel time s | per call ms | wall s |", file=stream)
            print("|---|---|---|---|---|", file=stream)
            for name, res in timing(th, t_end=t_end or 0.02).items():
                print(f"| {name} | {res.nfev} | {res.accel_time:.2f} | "
                      f"{1e3 * res.accel_time / res.nfev:.3f} | {res.wall_time:.2f} |", file=stream)
