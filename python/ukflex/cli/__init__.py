"""Command line interface: ``ukflex <command>`` (also ``python -m ukflex``).

Commands
--------
``ukflex run SCENE``
    Simulate a built-in scene or a TOML scene file; write CSV, NPZ, a plot of chosen outputs
    and (``--animate``) a GIF.
``ukflex list``
    List the built-in scenes.
``ukflex export NAME``
    Write a built-in scene as a TOML scene file (a starting point for your own).
``ukflex paper --out DIR``
    Reproduce the paper: Fig. 4 (``fig4.csv``, ``fig4.png``) for the Timoshenko and the
    Euler-Bernoulli coupler, and the Table 1 analogue (``table1.md``, ``table1.csv``).
``ukflex bench work-precision|elements|table1 --out DIR``
    Error against run time for every integrator and formulation; the same over element
    counts; the Table 1 analogue alone.

``run``, ``list`` and ``export`` use the library; ``paper`` and ``bench`` run
:mod:`ukflex.benchmarks` (imported when the command runs). The other studies (the stability
report, the cross-checks, geometric nonlinearity, ...) live in the repository's ``studies/``
package, outside the wheel: ``python -m studies NAME``.
Each command is a ``_cmd_<name>(args)`` function; ``_build_parser`` registers them.
"""

from __future__ import annotations

import argparse
import ast
import csv
import os
import sys
import time
from typing import Any, Callable, Dict, List, Optional, Sequence, TextIO

import numpy as np

__all__ = ["main", "Progress"]

RUN_DEFAULTS = {"t_end": 1.0, "method": "auto", "rtol": 1e-6, "atol": None, "formulation": "uk", "samples": 201}


# ----------------------------------------------------------------------------------- helpers
def _positive_float(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not np.isfinite(x) or x <= 0:
        raise argparse.ArgumentTypeError(f"must be positive and finite: {text!r}")
    return x


def _positive_int(text: str) -> int:
    from ..model.scenefile import MAX_COUNT

    try:
        x = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if x < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1: {text!r}")
    if x > MAX_COUNT:
        raise argparse.ArgumentTypeError(f"{text!r} is too large (at most {MAX_COUNT:,})")
    return x


class UserError(Exception):
    """A problem with what the user asked for (paths, sizes, options): one line, exit status 2."""


class _Parser(argparse.ArgumentParser):
    """Argument errors on one line (``ukflex run: error: ...``), exit status 2."""

    def error(self, message: str):  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def _safe_name(name: str) -> str:
    """``name`` as a file/folder name that stays inside its folder: letters, digits, ``_ . + -``
    (anything else becomes ``_``), no leading dot (so neither ``.`` nor ``..``)."""
    import re

    safe = re.sub(r"[^A-Za-z0-9_.+-]", "_", name).lstrip(".")
    return safe or "scene"


def _writable_dir(path: str, what: str) -> str:
    """Create directory ``path`` if needed and check that a file can be written there, before any
    work is done; raise :class:`UserError` otherwise."""
    import tempfile

    if os.path.exists(path) and not os.path.isdir(path):
        raise UserError(f"{what} {path!r} exists and is not a directory")
    try:
        os.makedirs(path, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path, prefix=".ukflex-write-check-"):
            pass
    except OSError as exc:
        raise UserError(f"{what} {path!r} is not writable ({exc.strerror or exc})") from None
    return path


def _writable_file(path: str, what: str) -> None:
    """Check that file ``path`` can be written (not a directory or a special file) before writing it."""
    import stat

    if os.path.isdir(path):
        raise UserError(f"{what} {path!r} is a directory; give a file name")
    if os.path.exists(path) and not stat.S_ISREG(os.stat(path).st_mode):
        raise UserError(f"{what} {path!r} is not a regular file")
    parent = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(parent):
        raise UserError(f"{what} {path!r}: directory {parent!r} does not exist")
    if not os.access(parent, os.W_OK) or (os.path.exists(path) and not os.access(path, os.W_OK)):
        raise UserError(f"{what} {path!r} is not writable")


def _float_list(text: str) -> List[float]:
    return [_positive_float(t) for t in text.replace(" ", "").split(",") if t]


def _int_list(text: str) -> List[int]:
    return [_positive_int(t) for t in text.replace(" ", "").split(",") if t]


def _str_list(choices: Sequence[str]) -> Callable[[str], List[str]]:
    def parse(text: str) -> List[str]:
        items = [t.strip() for t in text.split(",") if t.strip()]  # names may hold spaces ("omega x1")
        for it in items:
            if it not in choices:
                raise argparse.ArgumentTypeError(f"{it!r} is not one of {', '.join(choices)}")
        return items

    return parse


class Progress:
    """Simulated time / end time on one terminal line (stderr), only when it is a terminal.

    ``callback(label, t_end)`` returns a ``progress(t)`` function for :func:`ukflex.simulate`;
    the line appears after ``delay`` seconds (short runs stay quiet) and is refreshed at most
    every ``interval`` seconds; it is cleared when ``t`` reaches ``t_end`` or by :meth:`done`.
    """

    def __init__(self, enabled: Optional[bool] = None, stream: Optional[TextIO] = None, delay: float = 0.5,
                 interval: float = 0.2):
        self.stream = stream or sys.stderr
        if enabled is None:
            enabled = bool(getattr(self.stream, "isatty", lambda: False)())
        self.enabled = enabled
        self.delay, self.interval = delay, interval
        self._shown = False

    def callback(self, label: str, t_end: float) -> Optional[Callable[[float], None]]:
        if not self.enabled:
            return None
        start = time.perf_counter()
        last = [start]

        def progress(t: float) -> None:
            if t >= t_end:  # the run is over: leave the terminal line clean for what follows
                self.done()
                return
            now = time.perf_counter()
            if now - start < self.delay or now - last[0] < self.interval:
                return
            last[0] = now
            frac = min(max(t / t_end, 0.0), 1.0) if t_end > 0 else 1.0
            self.stream.write(f"\r{label}: t = {t:.6g} / {t_end:g} s ({100 * frac:5.1f} %), "
                              f"{now - start:.1f} s elapsed ")
            self.stream.flush()
            self._shown = True

        return progress

    def done(self) -> None:
        if self._shown:
            self.stream.write("\r" + " " * 79 + "\r")
            self.stream.flush()
            self._shown = False


def _progress_from(args: argparse.Namespace) -> Progress:
    return Progress(enabled=getattr(args, "progress", None))


def _add_progress_option(p: argparse.ArgumentParser) -> None:
    g = p.add_mutually_exclusive_group()
    g.add_argument("--progress", dest="progress", action="store_true", default=None,
                   help="always show progress on stderr (default: only when stderr is a terminal)")
    g.add_argument("--no-progress", dest="progress", action="store_false", help="never show progress")


def _add_integrator_options(p: argparse.ArgumentParser, defaults: Optional[Dict[str, Any]]) -> None:
    """--t-end, --method, --rtol, --atol, --formulation.

    With ``defaults=None`` the options default to None, so that a scene file's ``[solver]``
    values fill in what the command line does not give (then :data:`RUN_DEFAULTS`).
    """
    from ..run.simulate import FORMULATIONS, METHODS, NATIVE_METHODS

    native = list(NATIVE_METHODS)

    def hint(key: str) -> str:
        if defaults is not None:
            v = defaults.get(key)
        else:
            v = RUN_DEFAULTS[key]
        shown = "1e-3 rtol" if v is None else f"{v:g}" if isinstance(v, float) else str(v)
        if defaults is None:
            return f" (default: the scene file's [solver] {key}, else {shown})"
        return f" (default {shown})"

    d = defaults or {}
    p.add_argument("--t-end", type=_positive_float, default=d.get("t_end"), help="end time [s]" + hint("t_end"))
    p.add_argument("--method", default=d.get("method"), choices=["auto"] + list(METHODS) + native,
                   help=f"integrator: auto (chosen from the natural frequencies, docs/integrators.md), a scipy "
                        f"solve_ivp method or a native Rust integrator ({', '.join(native)})"
                        + hint("method"))
    p.add_argument("--rtol", type=_positive_float, default=d.get("rtol"), help="relative tolerance" + hint("rtol"))
    p.add_argument("--atol", type=_positive_float, default=d.get("atol"), help="absolute tolerance" + hint("atol"))
    p.add_argument("--formulation", default=d.get("formulation"), choices=FORMULATIONS,
                   help="accelerations: uk (Rust Udwadia-Kalaba), uk-numpy (NumPy reference), cp (NumPy "
                        "coordinate partitioning)" + hint("formulation"))


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


# ----------------------------------------------------------------------------------- run
def _parse_params(items: Sequence[str]) -> Dict[str, Any]:
    params: Dict[str, Any] = {}
    for it in items:
        if "=" not in it:
            raise ValueError(f"--param expects KEY=VALUE, got {it!r}")
        k, v = it.split("=", 1)
        try:
            params[k] = ast.literal_eval(v)
        except (ValueError, SyntaxError):
            try:  # nan, inf, -inf: numbers literal_eval does not know (the scene then says what it takes)
                params[k] = float(v)
            except ValueError:
                params[k] = v
    return params


def _load_scene(scene: str, params: Sequence[str]):
    """(name, System, solver settings, output settings, source) for a built-in name or a scene file.

    ``source`` identifies what was run (``builtin:NAME [params]`` or the file's absolute path);
    :func:`_default_out` keeps different sources in different folders.
    """
    from ..model.scenefile import SceneFileError, load
    from ..model.scenes import SCENES

    looks_like_file = scene.endswith(".toml") or os.sep in scene or os.path.exists(scene)
    if scene in SCENES and not os.path.exists(scene):
        system = SCENES[scene](**_parse_params(params)).build()
        return scene, system, {}, {}, "builtin:" + " ".join([scene] + list(params))
    if not looks_like_file:
        raise SceneFileError(f"{scene!r} is neither a built-in scene ({', '.join(SCENES)}) nor a scene file")
    if params:
        raise ValueError("--param applies to built-in scenes only; edit the scene file instead")
    sf = load(scene)
    return sf.name, sf.build(), sf.solver, sf.output, "file:" + os.path.abspath(scene)


_SOURCE_MARK = ".ukflex-source"


def _default_out(scene: str, name: str, params: Sequence[str], source: str) -> str:
    """``results/NAME`` for a built-in scene (``results/NAME_key-value...`` with ``--param``),
    ``results/STEM-toml`` for a scene file; if that folder holds the outputs of another source
    (``.ukflex-source``), ``-2``, ``-3``, ... is appended, so runs never overwrite each other."""
    if source.startswith("builtin:"):
        base = _safe_name(name + "".join("_" + p.replace("=", "-") for p in params))
    else:
        base = _safe_name(os.path.splitext(os.path.basename(scene))[0]) + "-toml"
    for k in range(1, 1000):
        out = os.path.join("results", base if k == 1 else f"{base}-{k}")
        mark = os.path.join(out, _SOURCE_MARK)
        if not os.path.exists(out):
            return out
        if not os.path.exists(mark):  # written before output folders were marked: as before, reuse it
            return out
        try:
            with open(mark, encoding="utf-8") as fh:
                if fh.read().strip() == source:
                    return out
        except OSError:
            continue
    raise UserError(f"no free output folder for {base!r} under results/; give --out")


def _write_outputs_csv(path: str, t: np.ndarray, names: Sequence[str], values: Sequence[np.ndarray]) -> None:
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["t"] + list(names))
        for k in range(t.size):
            w.writerow([repr(float(t[k]))] + [repr(float(v[k])) for v in values])


def _plot_outputs(path: str, name: str, t: np.ndarray, labels: Sequence[str], values: Sequence[np.ndarray],
                  subtitle: str) -> None:
    from ..results.plotting import figure

    k = len(values)
    fig = figure((7.0, 1.2 + 2.0 * k), "the output plot (ukflex run; --no-plot skips it)")
    axes = fig.subplots(k, 1, sharex=True, squeeze=False)[:, 0]
    for ax, lab, v in zip(axes, labels, values):
        ax.plot(t, v, lw=1.1)
        ax.set_ylabel(lab, fontsize=8)
        ax.grid(True, lw=0.3)
    axes[-1].set_xlabel("t [s]")
    axes[0].set_title(f"{name}: {subtitle}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=130)


def _cmd_run(args: argparse.Namespace) -> int:
    from ..results import outputs
    from ..run.simulate import simulate

    if args.out is not None:  # fail before loading or running anything
        _writable_dir(args.out, "--out")
    name, system, file_solver, file_output, source = _load_scene(args.scene, args.param)
    solver = dict(RUN_DEFAULTS)
    solver.update(file_solver)
    for key in ("t_end", "method", "rtol", "atol", "formulation", "samples"):
        v = getattr(args, key)
        if v is not None:
            solver[key] = v
    extra = {k: file_solver[k] for k in ("max_step", "first_step") if k in file_solver}
    exprs = args.plot or file_output.get("plot") or outputs.default_outputs(system)
    for e in exprs:  # fail before a long run
        outputs.validate(system, e)
    animate = args.animate or file_output.get("animate", False)
    deform_scale = args.deform_scale if args.deform_scale is not None else file_output.get("deform_scale", 1.0)
    fps = args.fps if args.fps is not None else file_output.get("fps", 25)
    frames = args.frames if args.frames is not None else file_output.get("frames", 150)
    if not args.no_plot or animate:  # matplotlib is optional: say so before the run, not after it
        from ..errors import require

        require("matplotlib", "the output plot and the animation (--no-plot, without --animate, skips both)")
    out = args.out or _default_out(args.scene, name, args.param, source)
    _writable_dir(out, "output folder")
    with open(os.path.join(out, _SOURCE_MARK), "w", encoding="utf-8") as fh:
        fh.write(source + "\n")
    name = _safe_name(name)  # file names inside the folder never leave it

    print(f"scene {name}: n = {system.n_coords} coordinates, m = {system.n_constraints} constraints, "
          f"{system.n_dof} degree(s) of freedom")
    print(system.initial_correction)
    t_eval = np.linspace(system.t0, solver["t_end"], solver["samples"])
    prog = _progress_from(args)
    try:
        res = simulate(system, solver["t_end"], method=solver["method"], rtol=solver["rtol"], atol=solver["atol"],
                       t_eval=t_eval, formulation=solver["formulation"],
                       progress=prog.callback(name, solver["t_end"]), **extra)
    finally:
        prog.done()
    print(f"{res.method} rtol={res.rtol:g} ({res.formulation}): status {res.status} ({res.message}); nfev {res.nfev}, "
          f"njev {res.njev}, nlu {res.nlu}; integration {res.wall_time:.3f} s")
    if "auto" in res.extra:
        print(f"method auto -> {res.method}: {res.extra['auto']['reason']}")
    print(f"max ||Phi|| = {res.max_residual('position'):.3e}, max ||A qd + Phi_t|| = "
          f"{res.max_residual('velocity'):.3e}, max ||A qdd - b|| = {res.max_residual('acceleration'):.3e}")
    print(res.sensors.energy_line())

    base = os.path.join(out, name)
    res.to_csv(base + ".csv")
    res.save_npz(base + ".npz")
    written = [base + ".csv", base + ".npz"]
    evaluated = [outputs.evaluate(res, x) for x in exprs]
    for x, (_, v) in zip(exprs, evaluated):
        print(f"{x}: min {np.min(v):.6g}, max {np.max(v):.6g}, final {v[-1]:.6g}")
    _write_outputs_csv(base + "_outputs.csv", res.t, exprs, [v for _, v in evaluated])
    written.append(base + "_outputs.csv")
    if not args.no_plot:
        _plot_outputs(base + ".png", name, res.t, [lab for lab, _ in evaluated], [v for _, v in evaluated],
                      f"{res.method}, rtol {res.rtol:g}, {res.formulation}")
        written.append(base + ".png")
    if animate:
        from ..results.animate import animate as write_gif

        nfr = write_gif(res, base + ".gif", fps=fps, frames=frames, deform_scale=deform_scale, title=name)
        written.append(f"{base}.gif ({nfr} frames)")
    print("wrote " + ", ".join(written))
    return 0 if res.success else 1


def _scene_summary(fn: Callable[..., Any]) -> str:
    """The first sentence of a scene function's docstring (may span lines)."""
    import re

    doc = (fn.__doc__ or "").strip().split("\n\n")[0]
    doc = re.sub(r":\w+:`~?([^`]+)`", r"\1", doc).replace("``", "")  # reST roles and literals -> text
    return " ".join(doc.split())


def _cmd_list(args: argparse.Namespace) -> int:
    from ..model.scenes import SCENES, scene_parameters

    for name, fn in SCENES.items():
        print(f"{name}: {_scene_summary(fn)}")
        for p, default in scene_parameters(fn):
            print(f"    --param {p}={default!r}")
    print("Run 'ukflex run NAME --param KEY=VALUE ...'; 'ukflex export NAME' writes a scene as a TOML file.")
    return 0


def _cmd_export(args: argparse.Namespace) -> int:
    from ..model.scenefile import dumps
    from ..model.scenes import SCENES

    if args.output not in (None, "-"):
        _writable_file(args.output, "-o")
    scene = SCENES[args.scene](**_parse_params(args.param))
    doc = _scene_summary(SCENES[args.scene])
    params = " ".join(f"--param {p}" for p in args.param)
    text = dumps(scene, name=args.scene, description=doc,
                 solver={"t_end": args.t_end, "method": args.method, "rtol": args.rtol},
                 header=f"ukflex scene file: built-in scene '{args.scene}' (ukflex export {args.scene}"
                        f"{' ' + params if params else ''}).\nFormat: docs/scene-format.md; run with: ukflex run FILE")
    if args.output in (None, "-"):
        sys.stdout.write(text)
    else:
        with open(args.output, "w", encoding="utf-8") as fh:
            fh.write(text)
        print(f"wrote {args.output}")
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


_FMT = argparse.RawDescriptionHelpFormatter
_THEORIES = ("timoshenko", "euler-bernoulli")


def _add_theory_option(p: argparse.ArgumentParser, default: Optional[str] = "timoshenko") -> None:
    """--theory."""
    shown = f"default {default}" if default else "default both"
    p.add_argument("--theory", choices=_THEORIES, default=default, help=f"coupler beam theory ({shown})")


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


def _add_run_parser(sub) -> None:
    from ..results.outputs import OUTPUT_HELP
    from ..model.scenes import SCENES

    p = sub.add_parser(
        "run", formatter_class=_FMT,
        help="simulate a built-in scene or a TOML scene file",
        description="Simulate SCENE and write, into --out (default results/NAME):\n"
                    "  NAME.csv          t, every coordinate and rate\n"
                    "  NAME.npz          t, q, qd, residual histories, statistics, names\n"
                    "  NAME_outputs.csv  t and the chosen outputs (--plot)\n"
                    "  NAME.png          plot of the chosen outputs (unless --no-plot)\n"
                    "  NAME.gif          animation of the mechanism (--animate)\n\n"
                    "SCENE is a built-in scene (ukflex list) or a TOML scene file (docs/scene-format.md,\n"
                    "examples/*.toml). Options given here override the file's [solver] and [output] tables.\n\n"
                    f"Output expressions (--plot): {OUTPUT_HELP}.\n"
                    "Default: v(BEAM, 0.5)/L of every beam, else the bodies' angles.",
    )
    p.add_argument("scene", metavar="SCENE", help=f"built-in scene ({', '.join(SCENES)}) or path to a .toml file")
    _add_integrator_options(p, None)
    p.add_argument("--samples", type=_positive_int, default=None,
                   help="output points in [t0, t_end] (default: the file's [solver] samples, else 201)")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                   help="built-in scene argument, e.g. --param elements=4 (repeatable)")
    p.add_argument("--out", default=None, help="output directory (default results/NAME)")
    p.add_argument("--plot", action="append", default=None, metavar="EXPR",
                   help="output to plot and write, e.g. 'v(coupler, 0.5)/L' or crank.theta (repeatable)")
    p.add_argument("--no-plot", action="store_true", help="do not write NAME.png")
    p.add_argument("--animate", action="store_true", help="write NAME.gif (headless)")
    p.add_argument("--deform-scale", type=_positive_float, default=None,
                   help="magnification of the elastic displacements in the animation (default 1)")
    p.add_argument("--fps", type=_positive_int, default=None, help="GIF frames per second (default 25)")
    p.add_argument("--frames", type=_positive_int, default=None, help="maximum number of GIF frames (default 150)")
    _add_progress_option(p)
    p.set_defaults(func=_cmd_run)


def _add_list_export_parsers(sub) -> None:
    from ..model.scenes import SCENES

    p = sub.add_parser("list", help="list the built-in scenes", description="List the built-in scenes.")
    p.set_defaults(func=_cmd_list)

    p = sub.add_parser("export", help="write a built-in scene as a TOML scene file",
                       description="Write built-in scene NAME (with --param arguments) as a TOML scene file, "
                                   "to stdout or -o FILE.")
    p.add_argument("scene", metavar="NAME", choices=sorted(SCENES), help=f"built-in scene ({', '.join(SCENES)})")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                   help="scene function argument, e.g. --param elements=4 (repeatable)")
    p.add_argument("-o", "--output", default=None, help="output file (default stdout)")
    p.add_argument("--t-end", type=_positive_float, default=0.1, help="[solver] t_end to write (default 0.1)")
    p.add_argument("--method", default="auto", help="[solver] method to write (default auto)")
    p.add_argument("--rtol", type=_positive_float, default=1e-6, help="[solver] rtol to write (default 1e-6)")
    p.set_defaults(func=_cmd_export)


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


def _build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="ukflex",
        formatter_class=_FMT,
        description="Planar flexible multibody dynamics with the Udwadia-Kalaba formulation (Rust core), "
                    "cross-checked against coordinate partitioning (NumPy).",
        epilog="examples:\n"
               "  ukflex run examples/slider_crank.toml --animate\n"
               "  ukflex run pendulum --t-end 2 --method DOP853 --plot rod.theta --plot energy\n"
               "  ukflex export four_bar > my_scene.toml    # start a scene file from a built-in scene\n"
               "  ukflex paper --out results/paper          # Fig. 4 and the Table 1 analogue\n"
               "  ukflex bench work-precision --out results/wp --quick\n"
               "\nRun 'ukflex COMMAND --help' for the options of a command.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for add in (_add_run_parser, _add_list_export_parsers, _add_paper_parser, _add_bench_parsers):
        add(sub)
    return parser


def _private_matplotlib_cache() -> None:
    """Unless the user chose one (``MPLCONFIGDIR``), give matplotlib a temporary configuration
    and cache folder for this process, removed at exit: a run that plots writes nothing under
    ``$HOME`` (matplotlib's font cache goes to ``~/.cache/matplotlib`` by default; building it
    again takes ~0.2 s)."""
    if "MPLCONFIGDIR" in os.environ or "matplotlib" in sys.modules:
        return
    import atexit
    import shutil
    import tempfile

    folder = tempfile.mkdtemp(prefix="ukflex-matplotlib-")
    os.environ["MPLCONFIGDIR"] = folder
    atexit.register(shutil.rmtree, folder, ignore_errors=True)


def main(argv: Optional[List[str]] = None) -> int:
    """Entry point of the ``ukflex`` console script."""
    from ..errors import UkflexError

    parser = _build_parser()
    args = parser.parse_args(argv)  # argument errors: one line, SystemExit(2) (--help: SystemExit(0))
    # ./x/../y is y: os.makedirs would otherwise create a stray x/ on the way
    for key in ("out", "output"):
        if getattr(args, key, None) not in (None, "-"):
            setattr(args, key, os.path.normpath(getattr(args, key)))
    _private_matplotlib_cache()
    try:
        if getattr(args, "out", None):  # an unwritable output folder fails now, not after the work
            _writable_dir(args.out, "--out")
        return int(args.func(args) or 0)
    except (UkflexError, UserError, ValueError, TypeError, NotImplementedError, KeyError, OverflowError,
            RecursionError, MemoryError, OSError) as exc:
        # user-facing problems (bad scene files, paths or parameters, inconsistent scenes, sizes
        # beyond this machine): one line, exit 2
        msg = exc.args[0] if isinstance(exc, KeyError) and exc.args else exc
        text = " ".join(f"{msg}".split()) or type(exc).__name__
        label = "" if isinstance(exc, UserError) else f"{type(exc).__name__}: "
        print(f"ukflex {args.command}: error: {label}{text}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"ukflex {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
