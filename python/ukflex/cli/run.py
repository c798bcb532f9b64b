"""``ukflex run``, ``ukflex list``, ``ukflex export``: simulate a built-in scene or a scene file,
list the built-in scenes, write one as a TOML file."""

from __future__ import annotations

import argparse
import ast
import csv
import os
import sys
from typing import Any, Callable, Dict, Sequence

import numpy as np

from . import spatial as cli_spatial
from .common import (RUN_DEFAULTS, UserError, _FMT, _add_integrator_options, _add_progress_option,
                     _positive_float, _positive_int, _progress_from, _safe_name, _writable_dir, _writable_file)


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


def _build_scene(name: str, params: Sequence[str]):
    """Built-in scene ``name`` with its ``--param KEY=VALUE`` arguments; an unknown KEY is refused
    with the scene's parameter names (``UnknownNameError``)."""
    from ..errors import UnknownNameError
    from ..model.scenes import SCENES, scene_parameters

    fn = SCENES[name]
    kwargs = _parse_params(params)
    valid = [p for p, _ in scene_parameters(fn)]
    for key in kwargs:
        if key not in valid:
            raise UnknownNameError.of(f"parameter of scene '{name}'", key, valid)
    return fn(**kwargs)


def _load_scene(scene: str, params: Sequence[str]):
    """(name, System, solver settings, output settings, source) for a built-in name or a scene file.

    ``source`` identifies what was run (``builtin:NAME [params]`` or the file's absolute path);
    :func:`_default_out` keeps different sources in different folders.
    """
    from ..model.scenefile import SceneFileError, load
    from ..model.scenes import SCENES

    looks_like_file = scene.endswith(".toml") or os.sep in scene or os.path.exists(scene)
    if scene in SCENES and not os.path.exists(scene):
        system = _build_scene(scene, params).build()
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


def _settings_line(solver: Dict[str, Any]) -> str:
    """The run's settings as the user gave them (command line, then the scene file, then the
    defaults), e.g. ``settings: method auto, rtol 1e-08, atol 1e-3 rtol, formulation uk, 201 samples``."""
    from ..run.simulate import RUN_OPTIONS

    atol = solver["atol"]
    shown = (f"{RUN_OPTIONS['defaults']['atol_per_rtol']:g} rtol" if atol is None
             else f"{atol:g}" if isinstance(atol, (int, float)) else str(atol))
    return (f"settings: method {solver['method']}, rtol {solver['rtol']:g}, atol {shown}, formulation "
            f"{solver['formulation']}, t_end {solver['t_end']:g} s, {solver['samples']} samples")


def _auto_line(auto: Dict[str, Any]) -> str:
    """What ``method="auto"`` derived from the settings (``res.extra["auto"]``), named as such:
    ``auto: RADAU5M, fixed step 8.2e-05 s, Newton tol 1e-05 (reason ...)``, ``auto: DOPRI5, rtol
    3e-07 (reason ...)``."""
    derived = [str(auto["method"])]
    if auto.get("step") is not None:
        derived.append(f"fixed step {auto['step']:.3g} s")
    if auto.get("rtol") is not None:
        derived.append(f"{'Newton tol' if auto.get('step') is not None else 'rtol'} {auto['rtol']:g}")
    return f"auto: {', '.join(derived)} ({auto['reason']})"


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
    from ..errors import MissingDependencyError, require

    plot = not args.no_plot
    if animate:  # asked for by name: without matplotlib it fails now, before the run
        require("matplotlib", "the animation (--animate)")
    elif plot:  # the default plot is skipped without matplotlib (a base install), with a note
        try:
            require("matplotlib", "the output plot")
        except MissingDependencyError as exc:
            print(f"note: no plot: {exc} (--no-plot skips it quietly)")
            plot = False
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
    print(_settings_line(solver))
    if "auto" in res.extra:
        print(_auto_line(res.extra["auto"]))
    print(f"{res.method} ({res.formulation}): status {res.status} ({res.message}); nfev {res.nfev}, "
          f"njev {res.njev}, nlu {res.nlu}; integration {res.wall_time:.3f} s")
    print(f"max ||Phi|| = {res.max_residual('position'):.3e}, max ||A qd + Phi_t|| = "
          f"{res.max_residual('velocity'):.3e}, max ||A qdd - b|| = {res.max_residual('acceleration'):.3e}")
    print(res.sensors.energy_line())

    base = os.path.join(out, name)
    res.to_csv(base + ".csv")
    res.save_npz(base + ".npz")
    written = [base + ".csv", base + ".npz"] + cli_spatial.write_outputs(res, base)
    evaluated = [outputs.evaluate(res, x) for x in exprs]
    for x, (_, v) in zip(exprs, evaluated):
        print(f"{x}: min {np.min(v):.6g}, max {np.max(v):.6g}, final {v[-1]:.6g}")
    _write_outputs_csv(base + "_outputs.csv", res.t, exprs, [v for _, v in evaluated])
    written.append(base + "_outputs.csv")
    if plot:
        auto = " (auto)" if "auto" in res.extra else ""
        _plot_outputs(base + ".png", name, res.t, [lab for lab, _ in evaluated], [v for _, v in evaluated],
                      f"{res.method}{auto}, rtol {solver['rtol']:g}, {res.formulation}")
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
    if args.scene not in SCENES and args.vtk is not None:  # a scene file run for ParaView
        from ..model.scenefile import load

        return _export_vtk_run(load(args.scene).scene, args)
    if args.scene not in SCENES:  # a scene file (planar or spatial): written back validated
        text = cli_spatial.export_text(args.scene)
    else:
        scene = _build_scene(args.scene, args.param)
        if args.vtk is not None:
            return _export_vtk_run(scene, args)
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


def _export_vtk_run(scene: Any, args: argparse.Namespace) -> int:
    """``ukflex export NAME --vtk FILE.pvd``: run the scene (--t-end, --method, --rtol, --samples)
    and write the run for ParaView (docs/outputs.md)."""
    from ..results.vtk import export_vtk
    from ..run.simulate import simulate

    system = scene.build()
    res = simulate(system, args.t_end, method=args.method, rtol=args.rtol,
                   t_eval=np.linspace(system.t0, system.t0 + args.t_end, args.samples))
    print(f"wrote {export_vtk(system, res, args.vtk)} ({res.t.size} output times)")
    return 0


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
    p.add_argument("scene", metavar="NAME", type=cli_spatial.export_source, help=f"built-in scene ({', '.join(SCENES)}) or a .toml scene file")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                   help="scene function argument, e.g. --param elements=4 (repeatable)")
    p.add_argument("-o", "--output", default=None, help="output file (default stdout)")
    p.add_argument("--t-end", type=_positive_float, default=0.1, help="[solver] t_end to write (default 0.1)")
    p.add_argument("--method", default="auto", help="[solver] method to write (default auto)")
    p.add_argument("--rtol", type=_positive_float, default=1e-6, help="[solver] rtol to write (default 1e-6)")
    p.add_argument("--vtk", default=None, metavar="FILE.pvd",
                   help="instead, run the scene (--t-end, --method, --rtol) and write it for ParaView: FILE.pvd "
                        "and FILE/*.vtu (docs/outputs.md)")
    p.add_argument("--samples", type=_positive_int, default=101, help="output times of the --vtk run (default 101)")
    p.set_defaults(func=_cmd_export)
