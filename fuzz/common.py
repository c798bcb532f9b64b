"""Helpers every fuzz category shares: the category record, what counts as a named error,
finiteness and hostile-input tests, and the compiled systems the per-call categories reuse."""

from __future__ import annotations

import contextlib
import warnings
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Sequence, Tuple

import numpy as np
from hypothesis import strategies as st

Finding = Tuple[str, str]


@dataclass(frozen=True)
class Category:
    name: str
    strategy: Callable[[], st.SearchStrategy]
    check: Callable[[Any], List[Finding]]
    doc: str


# ----------------------------------------------------------------------------------- helpers
def _ukflex():
    import ukflex

    return ukflex


def _named(exc: BaseException, names: Sequence[str]) -> bool:
    """A ukflex error, or a TypeError/ValueError whose message names one of ``names`` (an
    ``OverflowError`` such as "int too big to convert" is not named, whatever its note says)."""
    uk = _ukflex()
    if isinstance(exc, uk.UkflexError):
        return True
    if isinstance(exc, (TypeError, ValueError)):
        # pyo3 names the argument in an exception note ("while processing 'q'")
        msg = " ".join([str(exc)] + [str(n) for n in getattr(exc, "__notes__", [])])
        return any(n and n in msg for n in names)
    return False


def _exc(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {str(exc)[:300]}"


def _panic(exc: BaseException) -> bool:
    """A PyO3 panic that crossed into Python (``pyo3_runtime.PanicException``, a BaseException)."""
    return type(exc).__name__ == "PanicException"


def _classify(exc: BaseException, names: Sequence[str], where: str = "") -> List[Finding]:
    """No finding for a named error; a ``panic`` for a PanicException; else ``unnamed-exception``."""
    if _panic(exc):
        return [("panic", f"{where}{_exc(exc)}")]
    return [] if _named(exc, names) else [("unnamed-exception", f"{where}{_exc(exc)}")]


def _finite(*arrays: Any) -> bool:
    for a in arrays:
        a = np.asarray(a)
        if a.dtype.kind in "fc" and not np.all(np.isfinite(a)):
            return False
    return True


def _is_bad_input(v: Any) -> bool:
    """Input that a careful API must refuse (non-finite, masked, complex, wrong type)."""
    if isinstance(v, np.ma.MaskedArray):
        return True
    if isinstance(v, (str, bytes, dict)) or v is None or isinstance(v, bool):
        return True
    if isinstance(v, int):  # a Python int is a number; only one beyond the double range is bad
        return abs(v) > 1.7e308
    try:
        a = np.asarray(v)
    except Exception:  # noqa: BLE001 - ragged etc.
        return True
    if a.dtype.kind == "c" or a.dtype.kind in "OUSV":
        return True
    if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
        return True
    return False


@contextlib.contextmanager
def _quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with np.errstate(all="ignore"):
            yield


def _max_abs(a: Any) -> float:
    a = np.asarray(a, dtype=float)
    return float(np.max(np.abs(a))) if a.size else 0.0


# ----------------------------------------------------------------------------------- systems
_SYSTEMS: Dict[str, Any] = {}


def _ancf_cantilever():
    uk = _ukflex()
    s = uk.Scene(gravity=(0.0, -9.81))
    b = s.cable("beam", length=1.0, section=uk.Rectangular(0.02, 0.01), density=7850.0, youngs_modulus=2.1e11,
               elements=2)
    s.weld(s.ground.frame(), b.at(0.0), name="clamp")
    return s


def _system(name: str):
    if name not in _SYSTEMS:
        uk = _ukflex()
        scene = {"slider_crank": lambda: uk.scenes.slider_crank(elements=2),
                 "pendulum": lambda: uk.scenes.pendulum(),
                 "cantilever_ancf": _ancf_cantilever,
                 "every_joint": lambda: uk.scenes.every_joint()}[name]()
        _SYSTEMS[name] = uk.System(scene)
    return _SYSTEMS[name]


def _short(v: Any) -> str:
    import reprlib

    try:
        r = repr(v)
    except RecursionError:  # a list nested thousands deep
        r = reprlib.repr(v)
    return r if len(r) < 120 else r[:117] + "..."
