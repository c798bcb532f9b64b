"""Seeded regressions: each puts one fixed bug back (a monkeypatch inside the fuzz worker), so a
run with it must report findings -- the proof that the suite bites (tests/test_fuzz.py)."""

from __future__ import annotations

from typing import Callable, Dict


def _cli_tracebacks() -> None:
    """The CLI before it caught user errors: every exception escapes as a traceback."""
    from ukflex import cli

    def main(argv=None):
        parser = cli._build_parser()
        args = parser.parse_args(argv)
        return int(args.func(args) or 0)

    cli.main = main


REGRESSIONS: Dict[str, Callable[[], None]] = {
    "cli-tracebacks": _cli_tracebacks,
}


def apply(name: str) -> None:
    REGRESSIONS[name]()
