"""``python -m studies NAME [options]``: the studies of the repository, on the public ukflex API.

They are not part of the wheel (the library is ``python/ukflex``); run them from the
repository's root with the development build (``bash scripts/dev-build.sh``). The long ones
report each case on stderr as they start it (``[crosscheck   12.3 s] sweep timoshenko, ...``;
stability and geometric their own log lines, sweeps a progress bar); their tables go to stdout
or their output folder:

  python -m studies stability --out results/stability --quick
  python -m studies crosscheck errata
  python -m studies geometric --out results/geometric --quick
  python -m studies flexible-coupler [--nonlinear] [--mesh] [--modal-derivatives[=K]] [--figure PNG]
  python -m studies simeon-crank [--nonlinear]
  python -m studies spatial-fe-bar
  python -m studies spatial-flexible-exudyn
  python -m studies spatial-beam-pendulum
  python -m studies spatial-beam-pendulum-exudyn [--quick] [--repeat 3]
  python -m studies spatial-beam-spin-up
  python -m studies spatial-beam-spin-up-exudyn [--meshes 8,12,16,20,24] [--rtols 1e-3,1e-5] [--exudyn-meshes 8,12,16,24] [--steps 1000,2000,4000] [--repeat 3] [--exudyn-repeat 1] [--no-fe]
  python -m studies right-angle-cantilever [--quick] [--meshes 5,10,20,40] [--exudyn-meshes 10,20,40,80] [--steps 500,1000,3000] [--repeat 3] [--exudyn-repeat 1] [--published [20]]
  python -m studies spatial-flexible-crank [--quick]
  python -m studies sweeps --out results/sweeps [--small]
  python -m studies clearance [flores]
  python -m studies engine [--figure PNG]
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import Callable, List, Optional, Sequence

_FMT = argparse.RawDescriptionHelpFormatter
THEORIES = ("timoshenko", "euler-bernoulli")


class _Parser(argparse.ArgumentParser):
    """Argument errors on one line, exit status 2."""

    def error(self, message: str):  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def _positive_float(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (x > 0 and x < float("inf")):
        raise argparse.ArgumentTypeError(f"must be positive and finite: {text!r}")
    return x


def _int_list(text: str) -> List[int]:
    out = []
    for t in text.replace(" ", "").split(","):
        if t:
            if not t.isdigit() or int(t) < 1:
                raise argparse.ArgumentTypeError(f"not a positive integer: {t!r}")
            out.append(int(t))
    return out


def _str_list(choices: Sequence[str]) -> Callable[[str], List[str]]:
    def parse(text: str) -> List[str]:
        items = [t.strip() for t in text.split(",") if t.strip()]  # names may hold spaces ("omega x1")
        for it in items:
            if it not in choices:
                raise argparse.ArgumentTypeError(f"{it!r} is not one of {', '.join(choices)}")
        return items

    return parse


def _cmd_stability(args: argparse.Namespace) -> int:
    from .stability import report

    report(args.out, quick=args.quick, cases=args.case)
    print(f"wrote {os.path.join(args.out, 'stability.md')}")
    return 0


def _cmd_crosscheck(args: argparse.Namespace) -> int:
    from .crosscheck import run

    run(args.study, t_end=args.t_end, rtol=args.rtol, theory=args.theory)
    return 0


def _cmd_geometric(args: argparse.Namespace) -> int:
    import importlib.util

    from .geometric import run_geometric

    if not args.no_plot and importlib.util.find_spec("matplotlib") is None:  # say so before the whole study
        print("python -m studies geometric: error: the study's plots need matplotlib, which is not installed: "
              "pip install matplotlib, or --no-plot", file=sys.stderr)
        return 2
    run_geometric(args.out, quick=args.quick, models=args.models, elements=args.elements, cases=args.cases,
                  exudyn_data=args.exudyn_data, checks=not args.no_checks, cost=not args.no_cost,
                  plot=not args.no_plot, log=(lambda msg: None) if args.silent else
                  (lambda msg: print(msg, file=sys.stderr, flush=True)))
    print(f"wrote {os.path.join(args.out, 'summary.md')}")
    return 0


#: The studies with their own argument handling (``module.main(argv)``), by command name:
#: ``main`` hands them their arguments before parsing (an ``argparse.REMAINDER`` does not take
#: arguments that start with ``-``, so ``flexible-coupler --nonlinear`` was refused).
_PASSTHROUGH = {"flexible-coupler": "flexible_coupler", "simeon-crank": "simeon_crank", "sweeps": "sweeps",
                "clearance": "clearance", "engine": "engine", "spatial-flexible-crank": "spatial_flexible_crank",
                "right-angle-cantilever": "right_angle_cantilever", "spatial-beam-spin-up-exudyn": "spatial_beam_spin_up_exudyn",
                "spatial-beam-pendulum-exudyn": "spatial_beam_pendulum_exudyn"}


def _passthrough(sub, name: str, module: str, help: str) -> None:
    """A study with its own argument handling (``module.main(argv)``), listed in the help."""
    p = sub.add_parser(name, help=help, add_help=False)
    p.add_argument("rest", nargs=argparse.REMAINDER)
    p.set_defaults(func=lambda args: __import__(f"studies.{module}", fromlist=["main"]).main(args.rest))


def _add_stability_parser(sub) -> None:
    p = sub.add_parser(
        "stability", formatter_class=_FMT,
        help="the stability report over the catalogue of extreme scenes",
        description="Run every case of the catalogue of stiff and extreme scenes (studies.extreme) with the\n"
                    "native and scipy integrators and the NumPy coordinate partitioning, then the long-run drift,\n"
                    "scaling and units studies; write DIR/stability.md and DIR/stability.json.",
    )
    p.add_argument("--out", required=True, help="output directory (stability.md, stability.json)")
    p.add_argument("--quick", action="store_true", help="reduced sizes (minutes instead of hours)")
    p.add_argument("--case", action="append", default=None, metavar="NAME",
                   help="run only this case (repeatable; skips the long-run, scaling and units studies)")
    p.set_defaults(func=_cmd_stability)


def _add_crosscheck_parser(sub) -> None:
    from .crosscheck import STUDIES

    p = sub.add_parser(
        "crosscheck", formatter_class=_FMT,
        help="cross-checks against the NumPy reference (errata, Rust UK vs CP, timings)",
        description="Studies on the paper's slider-crank against the independent NumPy reference; each prints\n"
                    "markdown tables (docs/errata.md):\n"
                    "  errata  the paper's printed single-element terms, each erratum on and off (NumPy only)\n"
                    "  sweep   Rust UK vs NumPy coordinate partitioning over rtol, with and without gravity\n"
                    "  timing  acceleration time of NumPy UK vs CP (partition once / every call)\n"
                    "  bdf     paper-like BDF runs (Rust UK, NumPy CP) against a tight reference; E-B vs Timoshenko",
    )
    p.add_argument("study", choices=STUDIES, metavar="STUDY", help=f"one of {', '.join(STUDIES)}")
    p.add_argument("--t-end", type=_positive_float, default=None,
                   help="simulated span [s] (default 0.07; timing 0.02)")
    p.add_argument("--rtol", type=_positive_float, default=1e-8, help="rtol of the errata runs (default 1e-8)")
    p.add_argument("--theory", choices=THEORIES, default=None, help="coupler beam theory (default both)")
    p.set_defaults(func=_cmd_crosscheck)


def _add_geometric_parser(sub) -> None:
    from .geometric import CASES, MODELS

    p = sub.add_parser(
        "geometric", formatter_class=_FMT,
        help="geometric nonlinearity of the coupler at speed: linear/nonlinear FFRF and ANCF vs Exudyn",
        description="The paper's slider-crank with the linear FFRF, the nonlinear FFRF (Euler-Bernoulli and Timoshenko)\n"
                    "and the ANCF cable coupler, N = 1, 2, 4, 8, 16, at omega/10 .. 5 omega and d/2, d/4, side by side with\n"
                    "Exudyn's geometrically exact references (benches/data). Writes into DIR: runs.csv, axial.csv,\n"
                    "extreme.csv, cost.csv, targets.csv, speeds.png, convergence.png, paper_history.png, axial.png,\n"
                    "extreme.png, cost.png and summary.md (docs/geometric-nonlinearity.md).\n"
                    "Full: DOPRI5 rtol 1e-8 (about 45 min on 2 cores); --quick: N = 1, 2, 4 with generalized-alpha\n"
                    "(h = 2.5e-5 s), a reduced cost table (about a minute).",
    )
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--quick", action="store_true", help="N = 1, 2, 4, generalized-alpha, reduced checks (~1 min)")
    p.add_argument("--models", type=_str_list(tuple(MODELS)), default=None,
                   help=f"comma-separated models (default all: {','.join(MODELS)})")
    p.add_argument("--elements", type=_int_list, default=None, help="comma-separated N (default 1,2,4,8,16; quick 1,2,4)")
    p.add_argument("--cases", type=_str_list(tuple(c.name for c in CASES)), default=None,
                   help=f"comma-separated cases (default all: {','.join(c.name for c in CASES)})")
    p.add_argument("--exudyn-data", default=None,
                   help="directory with Exudyn's exudyn_*.csv (default benches/data of the source tree)")
    p.add_argument("--no-checks", action="store_true", help="skip the N = 32 and time-discretization checks")
    p.add_argument("--no-cost", action="store_true", help="skip the cost table")
    p.add_argument("--no-plot", action="store_true", help="skip the PNGs")
    p.add_argument("--silent", action="store_true", help="no per-run lines on stderr")
    p.set_defaults(func=_cmd_geometric)


def _build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="python -m studies", formatter_class=_FMT, description=__doc__.split("\n\n")[0],
                     epilog="Run 'python -m studies NAME --help' for the options of a study.")
    sub = parser.add_subparsers(dest="command", metavar="NAME", parser_class=_Parser)
    sub.required = True
    _add_stability_parser(sub)
    _add_crosscheck_parser(sub)
    _add_geometric_parser(sub)
    _passthrough(sub, "flexible-coupler", "flexible_coupler", "the FE-reduced coupler against the beam (docs/flexible-bodies.md)")
    _passthrough(sub, "simeon-crank", "simeon_crank", "Simeon's flexible slider-crank test set (docs/flexible-bodies.md)")
    _passthrough(sub, "spatial-fe-bar", "spatial_fe_bar", "the modes of a 3D FE bar against closed forms (docs/spatial-flexible.md)")
    _passthrough(sub, "spatial-flexible-exudyn", "spatial_flexible_exudyn", "the 3D flexible pendulum against Exudyn's ObjectFFRFreducedOrder (docs/spatial-flexible.md)")
    _passthrough(sub, "spatial-beam-pendulum", "spatial_beam_pendulum", "the 3D flexible pendulum: geometrically exact beam against the modal body (docs/spatial-flexible.md)")
    _passthrough(sub, "spatial-beam-pendulum-exudyn", "spatial_beam_pendulum_exudyn", "the 3D flexible pendulum's beam against Exudyn's ObjectBeamGeometricallyExact (docs/spatial-flexible.md)")
    _passthrough(sub, "spatial-beam-spin-up", "spatial_beam_spin_up", "Kane's spin-up beam: the 3D beam against the planar ANCF cable (docs/spatial-flexible.md)")
    _passthrough(sub, "spatial-beam-spin-up-exudyn", "spatial_beam_spin_up_exudyn",
                 "Kane's spin-up beam in 3D: the modal body against the beam, and against Exudyn (docs/spatial-flexible.md)")
    _passthrough(sub, "right-angle-cantilever", "right_angle_cantilever", "Simo and Vu-Quoc's right-angle cantilever: beam3 against Exudyn (docs/spatial-flexible.md)")
    _passthrough(sub, "spatial-flexible-crank", "spatial_flexible_crank",
                 "the spatial slider-crank with a flexible rod: beam3 against flexible3 and against Exudyn (docs/spatial-flexible.md)")
    _passthrough(sub, "sweeps", "sweeps", "the sweep study: serial, processes, Dask (docs/sweeps.md)")
    _passthrough(sub, "clearance", "clearance", "revolute joints with clearance: Flores's slider-crank, the flexible coupler (docs/loads.md)")
    _passthrough(sub, "engine", "engine", "a four-stroke engine with a flexible rod and joint friction started by a DC motor (docs/loads.md)")
    return parser


def main(argv: Optional[List[str]] = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] in _PASSTHROUGH:
        return int(__import__(f"studies.{_PASSTHROUGH[argv[0]]}", fromlist=["main"]).main(argv[1:]) or 0)
    args = _build_parser().parse_args(argv)
    return int(args.func(args) or 0)


if __name__ == "__main__":
    sys.exit(main())
