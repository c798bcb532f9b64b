"""What the commands share: argument types, output folders, the progress display, the
integrator and theory options."""

from __future__ import annotations

import argparse
import os
import sys
import time
from typing import Any, Callable, Dict, List, Optional, Sequence, TextIO

import numpy as np

from .. import _core

#: The CLI's run defaults; rtol is the core's (rust/integrate/options.rs).
RUN_DEFAULTS = {"t_end": 1.0, "method": "auto", "rtol": _core.run_options()["defaults"]["rtol"], "atol": None,
                "formulation": "uk", "samples": 201}


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
    """Simulated time / end time on stderr, only when it is a terminal (or ``--progress``): a
    tqdm bar when tqdm is installed (the [sweep] extra), else one plain line
    ``LABEL: t = T / T_END s (P %), E s elapsed``.

    ``callback(label, t_end)`` returns a ``progress(t)`` function for :func:`ukflex.simulate`
    (native runs call it from Rust every 100 steps or 0.5 s); the display appears after
    ``delay`` seconds (short runs stay quiet) and is refreshed at most every ``interval``
    seconds; it is cleared when ``t`` reaches ``t_end`` or by :meth:`done`. ``use_tqdm=False``
    keeps the plain line.
    """

    def __init__(self, enabled: Optional[bool] = None, stream: Optional[TextIO] = None, delay: float = 0.5,
                 interval: float = 0.2, use_tqdm: Optional[bool] = None):
        self.stream = stream or sys.stderr
        if enabled is None:
            enabled = bool(getattr(self.stream, "isatty", lambda: False)())
        self.enabled = enabled
        self.delay, self.interval = delay, interval
        if use_tqdm is None:
            import importlib.util

            use_tqdm = importlib.util.find_spec("tqdm") is not None
        self.use_tqdm = use_tqdm
        self._shown = False
        self._bar: Any = None

    def callback(self, label: str, t_end: float) -> Optional[Callable[[float], None]]:
        if not self.enabled:
            return None
        if self.use_tqdm:
            try:
                from tqdm import tqdm
            except ImportError:  # told to use tqdm, but it is not there: the plain line
                self.use_tqdm = False
            else:
                return self._tqdm_callback(tqdm, label, t_end)
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

    def _tqdm_callback(self, tqdm: Any, label: str, t_end: float) -> Callable[[float], None]:
        bar = tqdm(total=t_end, desc=label, file=self.stream, delay=self.delay, mininterval=self.interval,
                   leave=False, dynamic_ncols=True,
                   bar_format="{desc}: t = {n:.6g} / {total:g} s |{bar}| {percentage:3.0f}% [{elapsed}<{remaining}]")
        self._bar = bar

        def progress(t: float) -> None:
            if t >= t_end:
                self.done()
                return
            bar.update(min(t, t_end) - bar.n)

        return progress

    def done(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None
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


def _method(text: str) -> str:
    """A ``--method`` value: any case, as :func:`ukflex.simulate` takes it (its one rule), returned
    in the spelling the docs use (``dop853`` -> ``DOP853``)."""
    from ..errors import InvalidArgumentError
    from ..run.simulate import _method_name

    try:
        return str(_method_name(text))
    except InvalidArgumentError as exc:
        raise argparse.ArgumentTypeError(str(exc.args[0] if exc.args else exc)) from None


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
    p.add_argument("--method", default=d.get("method"), type=_method, metavar="METHOD",
                   help=f"integrator, any case: auto (chosen from the natural frequencies, docs/integrators.md), a "
                        f"scipy solve_ivp method ({', '.join(METHODS)}) or a native Rust integrator "
                        f"({', '.join(native)})" + hint("method"))
    p.add_argument("--rtol", type=_positive_float, default=d.get("rtol"), help="relative tolerance" + hint("rtol"))
    p.add_argument("--atol", type=_positive_float, default=d.get("atol"), help="absolute tolerance" + hint("atol"))
    p.add_argument("--formulation", default=d.get("formulation"), choices=FORMULATIONS,
                   help="accelerations: uk (Rust Udwadia-Kalaba), uk-numpy (NumPy reference), cp (NumPy "
                        "coordinate partitioning)" + hint("formulation"))


_FMT = argparse.RawDescriptionHelpFormatter
_THEORIES = ("timoshenko", "euler-bernoulli")


def _add_theory_option(p: argparse.ArgumentParser, default: Optional[str] = "timoshenko") -> None:
    """--theory."""
    shown = f"default {default}" if default else "default both"
    p.add_argument("--theory", choices=_THEORIES, default=default, help=f"coupler beam theory ({shown})")
