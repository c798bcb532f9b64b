"""Exception classes of ukflex.

The classes raised by the compiled core (``ukflex._core``) are re-exported here unchanged, so
``except ukflex.InvalidSceneError`` catches errors from the Python-side validation and from the
Rust-side validation alike.  :class:`InconsistentInitialStateError` is defined in Python (it is
raised by the initial-state correction in :mod:`ukflex.system`) as a subclass of the Rust base
class :class:`UkflexError`.

If the extension module has not been built yet (pure-Python use of :class:`ukflex.Scene`), stand-in
classes with the same names and hierarchy are defined so that scene validation still works;
``CORE_AVAILABLE`` tells which case applies and ``MISSING_FROM_CORE`` lists names the built core
does not provide (it should be empty).
"""

from __future__ import annotations

from typing import List, Sequence

__all__ = [
    "UkflexError",
    "InvalidSceneError",
    "SingularMassError",
    "SolverError",
    "NonFiniteError",
    "InconsistentInitialStateError",
    "CORE_AVAILABLE",
    "MISSING_FROM_CORE",
]

try:  # pragma: no cover - depends on whether the extension is built
    from . import _core  # type: ignore[attr-defined]

    CORE_AVAILABLE = True
except ImportError:  # pragma: no cover
    _core = None  # type: ignore[assignment]
    CORE_AVAILABLE = False

MISSING_FROM_CORE: List[str] = []


def _from_core(name: str, base: type) -> type:
    cls = getattr(_core, name, None) if _core is not None else None
    if cls is None:
        if _core is not None:
            MISSING_FROM_CORE.append(name)
        cls = type(name, (base,), {"__module__": __name__})
    return cls


UkflexError = _from_core("UkflexError", Exception)
InvalidSceneError = _from_core("InvalidSceneError", UkflexError)
SingularMassError = _from_core("SingularMassError", UkflexError)
SolverError = _from_core("SolverError", UkflexError)
NonFiniteError = _from_core("NonFiniteError", UkflexError)


class InconsistentInitialStateError(UkflexError):  # type: ignore[misc, valid-type]
    """The initial guess cannot be corrected onto the constraint manifold.

    Attributes
    ----------
    rows : list of str
        Names of the constraint rows with the largest residual, largest first.
    residuals : numpy.ndarray, shape (m,)
        The constraint residual (position ``Phi`` or velocity ``A qd + Phi_t``) at the point
        where the correction gave up.
    """

    def __init__(self, message: str, rows: Sequence[str] = (), residuals=None):
        super().__init__(message)
        self.rows = list(rows)
        self.residuals = residuals
