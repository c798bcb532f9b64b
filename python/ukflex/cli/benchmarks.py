"""``ukflex paper`` and ``ukflex bench``: what :mod:`ukflex.benchmarks` runs."""

from __future__ import annotations

import argparse
from typing import Any, Dict, Optional


from .common import (_FMT, _add_integrator_options, _add_progress_option, _add_theory_option, _float_list,
                     _int_list, _positive_float, _positive_int, _progress_from, _str_list)


# ----------------------------------------------------------------------------------- paper
def _cmd_paper(args: argparse.Namespace) -> int:
    from ..benchmarks.paper import run_paper

    prog = _progress_from(args)
    try:
        run_paper(args.out, table=args.table, table_t_end=args.table_t_end, repeats=args.repeats,
                  elements=args.elements, t_end=args.t_end, method=args.method, rtol=args.rtol, atol=args.atol,
                  samples=args.samples, formulation=args.formulation, gravity=not args.no_gravity,
                  plot=not args.no_plot, progress=lambda label: prog.callback(label, args.t_end))
    finally:
        prog.done()
    return 0


# ----------------------------------------------------------------------------------- bench
def _cmd_bench_wp(args: argparse.Namespace) -> int:
    from ..benchmarks.workprecision import run_work_precision

    rtols = args.rtols or ([1e-3, 1e-5, 1e-7] if args.quick else None)
    if args.quick and args.formulations is None:
        args.formulations = ["uk"]  # the NumPy references take ~15 min even with 3 tolerances
    if args.budget is None:
        args.budget = 15.0 if args.quick else 60.0
    kw: Dict[str, Any] = {}
    if rtols:
        kw["rtols"] = rtols
    if args.methods is not None:
        kw["methods"] = args.methods
    if args.formulations is not None:
        kw["formulations"] = args.formulations
    if args.native is not None:
        kw["native"] = args.native
    run_work_precision(args.out, theory=args.theory, elements=args.elements, t_end=args.t_end, samples=args.samples,
                       budget=args.budget, ref_rtol=args.ref_rtol, skip_after_timeout=not args.no_skip,
                       plot=not args.no_plot, **kw)
    return 0


def _cmd_bench_elements(args: argparse.Namespace) -> int:
    from ..benchmarks.workprecision import run_elements

    cases = []
    for c in args.cases.split(","):
        if ":" not in c:
            raise ValueError(f"--cases expects FORMULATION:METHOD items, got {c!r}")
        f, m = c.split(":", 1)
        cases.append((f.strip(), m.strip()))
    kw: Dict[str, Any] = {}
    if args.rtols:
        kw["rtols"] = args.rtols
    run_elements(args.out, elements=args.elements, cases=cases, theory=args.theory, t_end=args.t_end,
                 samples=args.samples, budget=args.budget, ref_rtol=args.ref_rtol,
                 skip_after_timeout=not args.no_skip, plot=not args.no_plot,
                 reference_elements=args.reference_elements, **kw)
    return 0


def _cmd_bench_table1(args: argparse.Namespace) -> int:
    from ..benchmarks.paper import table1

    table1(args.out, mode=args.mode, elements=args.elements, t_end=args.t_end, method=args.method, rtol=args.rtol,
           repeats=args.repeats, max_states=args.max_states, whole=args.whole or None,
           whole_repeats=args.whole_repeats)
    return 0


def _add_paper_parser(sub) -> None:
    p = sub.add_parser(
        "paper", formatter_class=_FMT,
        help="reproduce the paper: Fig. 4 and the Table 1 analogue",
        description="Reproduce Pennestri, Valentini, de Falco (2010) on the flexible slider-crank.\n\n"
                    "Fig. 4: coupler midpoint deflection v(Lb/2)/Lb vs time, Timoshenko and Euler-Bernoulli\n"
                    "coupler (DIR/fig4.csv, DIR/fig4.png; peak in 0..0.07 s and constraint drift printed).\n\n"
                    "Table 1 analogue (DIR/table1.md, DIR/table1.csv): time spent computing accelerations over a\n"
                    "whole simulation (scipy BDF, rtol 1e-6, over 0..min(t-end, 0.07) s), UK (Rust kernel,\n"
                    "Rust via Python, NumPy) and CP (NumPy, partition once / every call), all evaluated on the\n"
                    "same recorded states, best of --repeats, with the ratios next to the paper's 3.1x and the\n"
                    "machine's name. --table quick (default, about a minute) times at most 1000 of the states\n"
                    "and projects the total; --table full times all of them and adds whole-simulation runs of\n"
                    "every formulation (tens of minutes).",
    )
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--elements", type=_positive_int, default=1, help="coupler elements (default 1, as in the paper)")
    _add_integrator_options(p, {"t_end": 0.1, "method": "Radau", "rtol": 1e-6, "atol": None, "formulation": "uk"})
    p.add_argument("--samples", type=_positive_int, default=5001, help="output points in [0, t_end] (default 5001)")
    p.add_argument("--no-gravity", action="store_true", help="switch gravity off")
    p.add_argument("--no-plot", action="store_true", help="skip fig4.png")
    p.add_argument("--table", choices=("quick", "full", "none"), default="quick",
                   help="Table 1 analogue: quick (default), full, or none")
    p.add_argument("--table-t-end", type=_positive_float, default=None,
                   help="simulated span of the Table 1 run [s] (default min(t-end, 0.07))")
    p.add_argument("--repeats", type=_positive_int, default=5, help="timing repeats, best kept (default 5)")
    _add_progress_option(p)
    p.set_defaults(func=_cmd_paper)


def _add_bench_parsers(sub) -> None:
    from ..run.simulate import FORMULATIONS, NATIVE_METHODS
    from ..benchmarks.paper import PAPER_WINDOW
    from ..benchmarks.workprecision import DEFAULT_RTOLS, SCIPY_METHODS

    p = sub.add_parser("bench", help="work-precision studies and the Table 1 analogue",
                       description="Benchmarks on the paper's slider-crank: 'work-precision', 'elements', 'table1'.")
    bsub = p.add_subparsers(dest="bench", metavar="BENCH")
    bsub.required = True
    rt = ",".join(f"{r:.0e}" for r in DEFAULT_RTOLS)

    def common(q: argparse.ArgumentParser, ref_rtol: float, budget: Optional[float] = 60.0,
               budget_help: str = "") -> None:
        q.add_argument("--out", required=True, help="output directory")
        _add_theory_option(q)
        q.add_argument("--t-end", type=_positive_float, default=0.1, help="end time [s] (default 0.1)")
        q.add_argument("--samples", type=_positive_int, default=1001,
                       help="output times where the error is measured (default 1001)")
        q.add_argument("--rtols", type=_float_list, default=None, help=f"comma-separated rtols (default {rt})")
        q.add_argument("--budget", type=_positive_float, default=budget,
                       help="wall-time budget per run [s] (default " + (budget_help or f"{budget:g}") + ")")
        q.add_argument("--ref-rtol", type=_positive_float, default=ref_rtol,
                       help=f"rtol of the reference solutions (default {ref_rtol:g})")
        q.add_argument("--no-skip", action="store_true",
                       help="run tighter tolerances even after a looser one of the same line exceeded the budget")
        q.add_argument("--no-plot", action="store_true", help="skip the PNG")

    q = bsub.add_parser(
        "work-precision", formatter_class=_FMT,
        help="error vs wall time for every method x formulation x rtol",
        description="Simulate the paper's scene with every solve_ivp method x formulation (UK Rust, UK NumPy,\n"
                    "CP NumPy) and the native Rust integrators, at every rtol (atol = 1e-3 rtol); measure the\n"
                    "error of v(0.5)/Lb over the trajectory and of its peak against a tight reference (native\n"
                    "DOPRI5 checked by native RADAU5), the constraint drift at the end, the wall time and the\n"
                    "rhs evaluations. Writes work_precision.csv, work_precision.png (log-log error vs time,\n"
                    "over-budget runs marked) and work_precision.md (best method per accuracy level).\n"
                    "The full grid takes an hour or more; --quick runs 3 tolerances of the Rust formulation and\n"
                    "the native integrators with a 15 s budget per run (under 3 minutes).",
    )
    common(q, 1e-13, None, "60; 15 with --quick")
    q.add_argument("--elements", type=_positive_int, default=1, help="coupler elements (default 1)")
    q.add_argument("--methods", type=_str_list(SCIPY_METHODS + ("RK23",)), default=None,
                   help=f"comma-separated scipy methods (default {','.join(SCIPY_METHODS)})")
    q.add_argument("--formulations", type=_str_list(FORMULATIONS), default=None,
                   help=f"comma-separated formulations (default {','.join(FORMULATIONS)})")
    q.add_argument("--native", type=_str_list(NATIVE_METHODS), default=None,
                   help=f"comma-separated native integrators (default {','.join(NATIVE_METHODS)}; '' for none)")
    q.add_argument("--quick", action="store_true",
                   help="rtols 1e-3, 1e-5, 1e-7, formulation uk (unless --formulations), budget 15 s (unless --budget)")
    q.set_defaults(func=_cmd_bench_wp)

    q = bsub.add_parser(
        "elements", formatter_class=_FMT,
        help="the work-precision study over coupler element counts",
        description="Work-precision for N = 1, 2, 4, 8 coupler elements with the best methods. Two errors:\n"
                    "against the tight reference of the same N (integration error) and against the tight\n"
                    "reference of the largest N or of --reference-elements (discretization + integration: what a\n"
                    "budget buys for the "
                    "physical problem). Writes elements.csv, elements.png, elements.md.",
    )
    common(q, 1e-12)
    q.add_argument("--elements", type=_int_list, default=[1, 2, 4, 8], help="comma-separated N (default 1,2,4,8)")
    q.add_argument("--reference-elements", type=_positive_int, default=None,
                   help="finer N used only as the physical reference (e.g. 16), so the largest studied N "
                        "shows its discretization error too (default: the largest studied N)")
    q.add_argument("--cases", default="native:DOPRI5,native:RADAU5,uk:DOP853",
                   help="comma-separated FORMULATION:METHOD (default native:DOPRI5,native:RADAU5,uk:DOP853)")
    q.set_defaults(func=_cmd_bench_elements)

    q = bsub.add_parser("table1", formatter_class=_FMT, help="the Table 1 analogue alone",
                        description="Time spent computing accelerations, UK vs CP, both beam models (see "
                                    "'ukflex paper --help'). Writes table1.md and table1.csv.")
    q.add_argument("--out", required=True, help="output directory")
    q.add_argument("--mode", choices=("quick", "full"), default="full", help="quick or full (default full)")
    q.add_argument("--elements", type=_positive_int, default=1, help="coupler elements (default 1)")
    q.add_argument("--t-end", type=_positive_float, default=PAPER_WINDOW,
                   help=f"simulated span [s] (default {PAPER_WINDOW:g})")
    q.add_argument("--method", default="BDF", help="scipy method of the recording run (default BDF, like ode15s)")
    q.add_argument("--rtol", type=_positive_float, default=1e-6, help="rtol of the runs (default 1e-6)")
    q.add_argument("--repeats", type=_positive_int, default=5, help="timing sweeps, best kept (default 5)")
    q.add_argument("--max-states", type=_positive_int, default=1000, help="states timed in quick mode (default 1000)")
    q.add_argument("--whole", action="store_true", help="also whole-simulation runs in quick mode")
    q.add_argument("--whole-repeats", type=_positive_int, default=None,
                   help="repeats of each whole-simulation run (default --repeats)")
    q.set_defaults(func=_cmd_bench_table1)
