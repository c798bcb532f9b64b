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
Each command is a ``_cmd_<name>(args)`` function with its ``_add_<name>_parser(sub)``, in the
module of its group (:mod:`.run`: run, list, export; :mod:`.benchmarks`: paper, bench; what they
share: :mod:`.common`); ``_build_parser`` registers them.
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import List, Optional

from .benchmarks import _add_bench_parsers, _add_paper_parser
from .common import _FMT, Progress, UserError, _Parser, _writable_dir
from .run import _add_list_export_parsers, _add_run_parser

__all__ = ["main", "Progress"]


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
    from .. import __version__

    parser.add_argument("--version", action="version", version=f"ukflex {__version__}")
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
