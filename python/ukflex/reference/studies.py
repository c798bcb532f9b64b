"""Reproducible numerical studies behind docs/errata.md and the cross-validation report.

    python -m ukflex.reference.studies errata   [--t-end 0.07] [--rtol 1e-8]
    python -m ukflex.reference.studies sweep    [--t-end 0.07]     (needs ukflex._core)
    python -m ukflex.reference.studies timing   [--t-end 0.02]
    python -m ukflex.reference.studies bdf                         (needs ukflex._core)

Pure NumPy/SciPy except ``sweep``, which imports the compiled core lazily (inside the
function) to compare Rust UK against NumPy CP.
"""
from __future__ import annotations

import argparse
import json
import time

import numpy as np

from .cp import simulate_cp
from .model import ReferenceModel
from .paper_closed_form import ALL_FIXES, PaperSliderCrank
from .uk import correct_initial_state, simulate_uk_numpy


def paper_description(beam="timoshenko", elements=1, gravity=True):
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
             "theory": beam, "density": rho, "youngs_modulus": 2.06843e11,
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


def errata_effects(beam="timoshenko", t_end=0.07, rtol=1e-8, atol=1e-11, npts=701):
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
        out[name] = (t, _closed_form_deflection(PaperSliderCrank(beam, **kw), t_end, t, rtol, atol))
    # the general element-by-element model through coordinate partitioning, for the record
    m = ReferenceModel(paper_description(beam))
    cp = simulate_cp(m, t_end, method="DOP853", rtol=rtol, atol=atol, t_eval=t)
    S, _ = m.beam_shape("coupler", 0.5)
    out["general model (CP)"] = (t, (S @ cp.q[6:9])[1] / 0.3048)
    return out


def _print_errata(beam, out):
    t, ref = out["corrected"]
    peak = np.abs(ref).max()
    print(f"\n### {beam}: coupler midpoint deflection v(Lb/2)/Lb, t in [0, {t[-1]:g}] s")
    print(f"corrected model: max|v|/Lb = {peak:.5e} at t = {t[np.argmax(np.abs(ref))]:.4f} s\n")
    print("| variant | max abs(v - v_corrected)/Lb | relative to peak | its own peak |v|/Lb |")
    print("|---|---|---|---|")
    for name, (_, v) in out.items():
        if name == "corrected":
            continue
        d = np.abs(v - ref).max()
        print(f"| {name} | {d:.3e} | {d / peak:.2e} | {np.abs(v).max():.5e} |")


def rtol_sweep(beam="timoshenko", gravity=True, t_end=0.07, rtols=(1e-6, 1e-8, 1e-10),
               npts=71, method="DOP853"):
    """Rust UK (solve_ivp on System.rhs) vs NumPy CP: max |v_rust - v_cp| / max |v|."""
    from scipy.integrate import solve_ivp
    from ukflex import _core                     # lazy: only this study needs the core

    d = paper_description(beam, gravity=gravity)
    m = ReferenceModel(d)
    r = _core.System(json.dumps(d))
    q0, qd0 = correct_initial_state(m)
    t = np.linspace(0.0, t_end, npts)
    S, _ = m.beam_shape("coupler", 0.5)
    rows = []
    for rtol in rtols:
        atol = 1e-3 * rtol
        tic = time.perf_counter()
        sr = solve_ivp(r.rhs, (0, t_end), np.r_[q0, qd0], method=method, rtol=rtol, atol=atol,
                       t_eval=t)
        wr = time.perf_counter() - tic
        cp = simulate_cp(m, t_end, method=method, rtol=rtol, atol=atol, t_eval=t, q0=q0, qd0=qd0)
        vr = (S @ sr.y[6:9])[1] / 0.3048
        vc = (S @ cp.q[6:9])[1] / 0.3048
        rows.append(dict(rtol=rtol, diff=np.abs(vr - vc).max(), peak=np.abs(vr).max(),
                         rust_nfev=sr.nfev, rust_wall=wr, cp_nfev=cp.nfev, cp_wall=cp.wall_time,
                         repartitions=cp.repartitions,
                         rust_phi=np.abs([r.phi(tk, sr.y[:9, k]) for k, tk in enumerate(t)]).max()))
    return rows


def timing(beam="timoshenko", t_end=0.02, rtol=1e-6, method="DOP853"):
    """Acceleration-evaluation time: UK (NumPy), CP partitioned once, CP every call."""
    m = ReferenceModel(paper_description(beam))
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
        best = None
        for _ in range(3):
            res = f()
            if best is None or res.accel_time < best.accel_time:
                best = res
        out[name] = best
    return out


def bdf_study(t_end=0.07):
    """Paper-like integrator (BDF, rtol 1e-6): Rust UK vs NumPy CP vs a DOP853 1e-10 reference;
    E-B vs Timoshenko; and scipy's num_jac overflow on raw System.rhs at rtol 1e-8."""
    import warnings
    from scipy.integrate import solve_ivp
    from ukflex import _core                     # lazy: only this study needs the core
    from .uk import fd_jacobian

    t = np.linspace(0.0, t_end, 701)
    ref = {}
    for beam in ("euler-bernoulli", "timoshenko"):
        d = paper_description(beam)
        r, m = _core.System(json.dumps(d)), ReferenceModel(d)
        q0, qd0 = correct_initial_state(m)
        S, _ = m.beam_shape("coupler", 0.5)
        y0 = np.r_[q0, qd0]
        sr = solve_ivp(r.rhs, (0, t_end), y0, method="DOP853", rtol=1e-10, atol=1e-13, t_eval=t)
        ref[beam] = (S @ sr.y[6:9])[1] / 0.3048
        pk = np.abs(ref[beam]).max()
        sb = solve_ivp(r.rhs, (0, t_end), y0, method="BDF", rtol=1e-6, atol=1e-9, t_eval=t)
        vb = (S @ sb.y[6:9])[1] / 0.3048
        cp = simulate_cp(m, t_end, method="BDF", rtol=1e-6, atol=1e-9, t_eval=t[::10], q0=q0,
                         qd0=qd0)
        vc = (S @ cp.q[6:9])[1] / 0.3048
        print(f"{beam}: BDF rtol 1e-6, atol 1e-9 (max abs dv / peak): Rust UK vs reference "
              f"{np.abs(vb - ref[beam]).max() / pk:.2e}, NumPy CP vs reference "
              f"{np.abs(vc - ref[beam][::10]).max() / pk:.2e}, Rust UK vs CP "
              f"{np.abs(vb[::10] - vc).max() / pk:.2e}; nfev Rust {sb.nfev}, CP {cp.nfev}")
        for jac in ("scipy num_jac", "fd_jacobian"):
            kw = {} if jac.startswith("scipy") else {"jac": fd_jacobian(r.rhs, 1e-11)}
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                try:
                    s2 = solve_ivp(r.rhs, (0, t_end), y0, method="BDF", rtol=1e-8, atol=1e-11,
                                   **kw)
                    print(f"  raw System.rhs, BDF rtol 1e-8, {jac}: status {s2.status}, "
                          f"njev {s2.njev}")
                except Exception as exc:            # noqa: BLE001 (report what happened)
                    print(f"  raw System.rhs, BDF rtol 1e-8, {jac}: {type(exc).__name__}: {exc}")
    dv = np.abs(ref["euler-bernoulli"] - ref["timoshenko"])
    pk = np.abs(ref["timoshenko"]).max()
    print(f"E-B vs Timoshenko: max abs dv/Lb = {dv.max():.3e} ({dv.max() / pk:.2e} of the peak); "
          f"peaks {np.abs(ref['euler-bernoulli']).max():.6e}, {pk:.6e}")


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m ukflex.reference.studies")
    ap.add_argument("study", choices=["errata", "sweep", "timing", "bdf"])
    ap.add_argument("--t-end", type=float, default=None)
    ap.add_argument("--rtol", type=float, default=1e-8)
    ap.add_argument("--beam", default=None)
    args = ap.parse_args(argv)
    beams = [args.beam] if args.beam else ["euler-bernoulli", "timoshenko"]
    if args.study == "errata":
        for beam in beams:
            _print_errata(beam, errata_effects(beam, t_end=args.t_end or 0.07, rtol=args.rtol,
                                               atol=1e-3 * args.rtol))
    elif args.study == "bdf":
        bdf_study(t_end=args.t_end or 0.07)
    elif args.study == "sweep":
        for beam in beams:
            for gravity in (True, False):
                print(f"\n### {beam}, gravity={gravity}: Rust UK vs NumPy CP, "
                      f"t in [0, {args.t_end or 0.07:g}] s (DOP853, atol = 1e-3 rtol)")
                print("| rtol | max abs(v_rust - v_cp)/Lb | / peak | Rust nfev | Rust wall s "
                      "| CP nfev | CP wall s | CP repartitions | Rust max abs(Phi) |")
                print("|---|---|---|---|---|---|---|---|---|")
                for row in rtol_sweep(beam, gravity, t_end=args.t_end or 0.07):
                    print(f"| {row['rtol']:.0e} | {row['diff']:.2e} | {row['diff'] / row['peak']:.2e}"
                          f" | {row['rust_nfev']} | {row['rust_wall']:.2f} | {row['cp_nfev']}"
                          f" | {row['cp_wall']:.1f} | {row['repartitions']} | {row['rust_phi']:.1e} |")
    else:
        for beam in beams:
            print(f"\n### {beam}: t in [0, {args.t_end or 0.02:g}] s, DOP853 rtol 1e-6, best of 3")
            print("| formulation | calls | accel time s | per call ms | wall s |")
            print("|---|---|---|---|---|")
            for name, res in timing(beam, t_end=args.t_end or 0.02).items():
                print(f"| {name} | {res.nfev} | {res.accel_time:.2f} | "
                      f"{1e3 * res.accel_time / res.nfev:.3f} | {res.wall_time:.2f} |")


if __name__ == "__main__":
    main()
