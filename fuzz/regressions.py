"""Seeded regressions: each puts one fixed bug back (a monkeypatch inside the fuzz worker), so a
run with it must report findings -- the proof that the suite bites (tests/test_fuzz.py).

Each entry: name -> (category that must catch it, patch)."""

from __future__ import annotations

from typing import Callable, Dict, Tuple

import numpy as np

_PER_CALL = ("qdd", "rhs", "M", "Q", "phi", "A", "b", "multipliers", "residuals", "kinetic_energy",
             "potential_energy", "jac")


def _wrap_system_methods(wrap: Callable[[Callable], Callable]) -> None:
    from ukflex import system as system_module

    init = system_module.System.__init__

    def patched(self, *args, **kwargs):
        init(self, *args, **kwargs)
        for name in _PER_CALL:
            setattr(self, name, wrap(getattr(self, name)))

    system_module.System.__init__ = patched


def _cli_tracebacks() -> None:
    """The CLI before it caught user errors: every exception escapes as a traceback."""
    from ukflex import cli

    def main(argv=None):
        parser = cli._build_parser()
        args = parser.parse_args(argv)
        return int(args.func(args) or 0)

    cli.main = main


def _lenient_arrays() -> None:
    """Array inputs converted with ``numpy.asarray(x, float)`` whatever they are (masks ignored,
    imaginary parts dropped, strings parsed), as before the bindings refused them."""

    def coerce(x):
        if isinstance(x, (np.ndarray, list, tuple)):
            try:
                return np.asarray(np.ma.getdata(x).real if np.iscomplexobj(x) else np.ma.getdata(x), dtype=float)
            except (TypeError, ValueError):
                return x
        return x

    def wrap(f):
        return lambda *a: f(*[coerce(x) for x in a])

    _wrap_system_methods(wrap)


def _nan_results() -> None:
    """Results that overflow come back as NaN instead of a NonFiniteError (the old behaviour)."""
    import ukflex

    def wrap(f):
        def g(*a):
            try:
                return f(*a)
            except ukflex.NonFiniteError as exc:
                if "result" not in str(exc):
                    raise
                return np.full(3, np.nan)
        return g

    _wrap_system_methods(wrap)


def _unresolved_positions() -> None:
    """No resolution check of the corrected state: a mechanism 1e17 m from the origin builds."""
    from ukflex import system as system_module

    system_module.System._check_resolution = lambda self, q: None


def _shared_settings() -> None:
    """stability.run configuring the caller's System (settings shared across threads)."""
    from ukflex import system as system_module

    system_module.System.copy = lambda self: self


REGRESSIONS: Dict[str, Tuple[str, Callable[[], None]]] = {
    "shared-settings": ("threads", _shared_settings),
    "cli-tracebacks": ("cli", _cli_tracebacks),
    "lenient-arrays": ("arrays", _lenient_arrays),
    "nan-results": ("arrays", _nan_results),
    "unresolved-positions": ("scene", _unresolved_positions),
}


def apply(name: str) -> None:
    REGRESSIONS[name][1]()
