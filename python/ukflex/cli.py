"""Command line interface: ``ukflex <command>`` (also ``python -m ukflex``).

Commands
--------
``ukflex paper --out DIR``
    The paper's slider-crank with Timoshenko and Euler-Bernoulli couplers (gravity on):
    ``DIR/fig4.csv`` and ``DIR/fig4.png`` (midpoint deflection / Lb vs time, the paper's Fig. 4),
    peak deflection in 0..0.07 s and the position-constraint drift at ``t_end``.
``ukflex run SCENE``
    Simulate a built-in scene (``ukflex list`` shows them) and print a summary.
``ukflex list``
    List the built-in scenes.

Each command is a ``_cmd_<name>(args)`` function registered in ``_build_parser``; new commands
(scene files, benchmarks) plug in the same way.
"""

from __future__ import annotations

import argparse
import ast
import csv
import os
import sys
import time
from typing import Any, Dict, List, Optional, Sequence

import numpy as np

__all__ = ["main"]

PAPER_WINDOW = 0.07  # s, the time span of the paper's Fig. 4


def _positive_float(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not np.isfinite(x) or x <= 0:
        raise argparse.ArgumentTypeError(f"must be positive and finite: {text!r}")
    return x


def _positive_int(text: str) -> int:
    try:
        x = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if x < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1: {text!r}")
    return x


def _add_integrator_options(p: argparse.ArgumentParser, t_end: float) -> None:
    from .simulate import METHODS

    p.add_argument("--t-end", type=_positive_float, default=t_end, help=f"end time [s] (default {t_end})")
    p.add_argument("--method", default="Radau", choices=METHODS, help="solve_ivp method (default Radau)")
    p.add_argument("--rtol", type=_positive_float, default=1e-6, help="relative tolerance (default 1e-6)")
    p.add_argument("--atol", type=_positive_float, default=None, help="absolute tolerance (default 1e-3 rtol)")
    p.add_argument(
        "--formulation", default="uk", choices=("uk", "uk-numpy", "cp"), help="acceleration formulation (default uk)"
    )


# ----------------------------------------------------------------------------------- paper
def run_paper(
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
    stream=None,
) -> Dict[str, Dict[str, float]]:
    """Run the paper's slider-crank for both beam models and write ``fig4.csv`` / ``fig4.png``.

    Returns
    -------
    dict
        Per beam model: ``peak`` (max |v(0.5)|/Lb in 0..0.07 s), ``t_peak``, ``drift`` (||Phi||
        at ``t_end``), ``wall_time``, ``nfev``.
    """
    from . import scenes
    from .simulate import simulate

    stream = stream or sys.stdout
    os.makedirs(out, exist_ok=True)
    t_eval = np.linspace(0.0, t_end, samples)
    Lb = scenes.PAPER["coupler_length"]
    curves: Dict[str, np.ndarray] = {}
    summary: Dict[str, Dict[str, float]] = {}
    for beam in ("timoshenko", "euler-bernoulli"):
        scene = scenes.slider_crank(beam=beam, elements=elements, gravity=gravity)
        res = simulate(scene, t_end, method=method, rtol=rtol, atol=atol, t_eval=t_eval, formulation=formulation)
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
        _plot_fig4(png_path, t_eval, curves, elements, gravity)
        print(f"wrote {png_path}", file=stream)
    return summary


def _plot_fig4(path: str, t: np.ndarray, curves: Dict[str, np.ndarray], elements: int, gravity: bool) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 4.2))
    ax.plot(t, curves["euler-bernoulli"], "-", lw=1.2, label="Euler-Bernoulli")
    ax.plot(t, curves["timoshenko"], "--", lw=1.2, label="Timoshenko")
    if t[-1] > PAPER_WINDOW:
        ax.axvline(PAPER_WINDOW, color="0.6", lw=0.8, ls=":")
    ax.axhline(0.0, color="0.8", lw=0.6)
    ax.set_xlabel("Time (s)")
    ax.set_ylabel("Midpoint deflection / $L_b$")
    ax.set_title(f"Flexible slider-crank, coupler {elements} element(s){', gravity' if gravity else ''}")
    ax.set_xlim(t[0], t[-1])
    ax.legend()
    ax.grid(True, lw=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)


def _cmd_paper(args: argparse.Namespace) -> int:
    run_paper(
        args.out,
        elements=args.elements,
        t_end=args.t_end,
        method=args.method,
        rtol=args.rtol,
        atol=args.atol,
        samples=args.samples,
        formulation=args.formulation,
        gravity=not args.no_gravity,
        plot=not args.no_plot,
    )
    return 0


# ----------------------------------------------------------------------------------- run / list
def _parse_params(items: Sequence[str]) -> Dict[str, Any]:
    params: Dict[str, Any] = {}
    for it in items:
        if "=" not in it:
            raise SystemExit(f"ukflex: error: --param expects KEY=VALUE, got {it!r}")
        k, v = it.split("=", 1)
        try:
            params[k] = ast.literal_eval(v)
        except (ValueError, SyntaxError):
            params[k] = v
    return params


def _cmd_run(args: argparse.Namespace) -> int:
    from .scenes import SCENES
    from .simulate import simulate

    scene = SCENES[args.scene](**_parse_params(args.param))
    t0 = time.perf_counter()
    system = scene.build()
    build_time = time.perf_counter() - t0
    print(f"scene {args.scene}: n = {system.n_coords} coordinates, m = {system.n_constraints} constraints, "
          f"{system.n_dof} degree(s) of freedom; built in {build_time * 1e3:.1f} ms")
    print(system.initial_correction)
    t_eval = np.linspace(0.0, args.t_end, args.samples)
    res = simulate(system, args.t_end, method=args.method, rtol=args.rtol, atol=args.atol, t_eval=t_eval,
                   formulation=args.formulation)
    e = res.energy()
    print(f"{res.method} rtol={res.rtol:g}: status {res.status} ({res.message}); nfev {res.nfev}, njev {res.njev}, "
          f"nlu {res.nlu}; integration {res.wall_time:.3f} s")
    print(f"max ||Phi|| = {res.max_residual('position'):.3e}, max ||A qd + Phi_t|| = "
          f"{res.max_residual('velocity'):.3e}, max ||A qdd - b|| = {res.max_residual('acceleration'):.3e}")
    print(f"energy T + V: {e[0]:.9g} -> {e[-1]:.9g} (change {e[-1] - e[0]:+.3e})")
    if args.out:
        os.makedirs(args.out, exist_ok=True)
        res.to_csv(os.path.join(args.out, f"{args.scene}.csv"))
        res.save_npz(os.path.join(args.out, f"{args.scene}.npz"))
        print(f"wrote {args.out}/{args.scene}.csv and .npz")
    return 0 if res.success else 1


def _cmd_list(args: argparse.Namespace) -> int:
    from .scenes import SCENES

    for name, fn in SCENES.items():
        doc = (fn.__doc__ or "").strip().splitlines()[0]
        print(f"{name:16s} {doc}")
    return 0


# ----------------------------------------------------------------------------------- parser
def _build_parser() -> argparse.ArgumentParser:
    from .scenes import SCENES

    parser = argparse.ArgumentParser(prog="ukflex", description="Planar flexible multibody dynamics (Udwadia-Kalaba).")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    p = sub.add_parser("paper", help="reproduce the paper's Fig. 4 (flexible slider-crank)")
    p.add_argument("--out", required=True, help="output directory for fig4.csv and fig4.png")
    p.add_argument("--elements", type=_positive_int, default=1, help="coupler elements (default 1, as in the paper)")
    _add_integrator_options(p, 0.1)
    p.add_argument("--samples", type=_positive_int, default=5001, help="output points in [0, t_end] (default 5001)")
    p.add_argument("--no-gravity", action="store_true", help="switch gravity off")
    p.add_argument("--no-plot", action="store_true", help="skip fig4.png")
    p.set_defaults(func=_cmd_paper)

    p = sub.add_parser("run", help="simulate a built-in scene and print a summary")
    p.add_argument("scene", choices=sorted(SCENES), help="built-in scene")
    _add_integrator_options(p, 1.0)
    p.add_argument("--samples", type=_positive_int, default=201, help="output points (default 201)")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                   help="scene function argument, e.g. --param elements=4 (repeatable)")
    p.add_argument("--out", default=None, help="write SCENE.csv and SCENE.npz to this directory")
    p.set_defaults(func=_cmd_run)

    p = sub.add_parser("list", help="list the built-in scenes")
    p.set_defaults(func=_cmd_list)
    return parser


def main(argv: Optional[List[str]] = None) -> int:
    """Entry point of the ``ukflex`` console script."""
    from .errors import UkflexError

    parser = _build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except (UkflexError, ValueError, TypeError, NotImplementedError) as exc:
        # user-facing problems (bad scene parameters, inconsistent scenes): one line, exit 2
        print(f"ukflex {args.command}: error: {type(exc).__name__}: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
