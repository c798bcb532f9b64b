"""The one number checker of the Python API: each function coerces one value of a public
function (NumPy scalars and arrays included) or raises :class:`ukflex.InvalidArgumentError`
naming the argument (and, with ``where``, the function).  The rules of a scene are the core's;
these are the types of builder arguments (``real(..., finite=False)``: the core judges the
value) and the rules of function arguments (budgets, tolerances, ratios, counts, arrays) that
only Python sees.  Used by every room: the builders and built-in scenes (``model/``), the runs
(``run/``), the analyses (``analysis/``)."""

from __future__ import annotations

import math
import numbers
from typing import Any, Optional

import numpy as np

from .errors import InvalidArgumentError, NonFiniteError

__all__ = ["real", "reals", "positive", "non_negative", "count", "integer", "real_array", "COUNT_LIMIT"]


def _shown(value: Any) -> str:
    """A short repr for a message (a 400-digit integer or a list nested thousands deep prints short)."""
    import reprlib

    r = reprlib.Repr()
    r.maxlevel, r.maxstring, r.maxother, r.maxlong = 3, 40, 40, 40
    return r.repr(value)


def real(name: str, value: Any, *, finite: bool = True, where: str = "") -> float:
    """A real scalar: int or float (NumPy's too); bool, str, complex, None and arrays refused;
    beyond the double range refused; with ``finite`` (default) NaN and infinity refused."""
    if isinstance(value, np.ndarray) and value.ndim == 0 and not isinstance(value, np.ma.MaskedArray):
        value = value[()]
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise InvalidArgumentError(name, f"must be a real number, got {type(value).__name__} {_shown(value)}", where)
    try:
        x = float(value)
    except OverflowError:
        raise InvalidArgumentError(name, f"{_shown(value)} is beyond the double-precision range", where) from None
    if finite and not math.isfinite(x):
        raise InvalidArgumentError(name, f"must be finite, got {_shown(value)}", where)
    return x


def reals(name: str, values: Any, *, finite: bool = True, where: str = "") -> list:
    """A sequence of real numbers (a list, tuple or 1-D array), each as :func:`real`."""
    if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__") or getattr(values, "ndim", 1) != 1:
        raise InvalidArgumentError(name, f"must be a sequence of real numbers, got {_shown(values)}", where)
    return [real(f"{name}[{i}]", x, finite=finite, where=where) for i, x in enumerate(values)]


def integer(name: str, value: Any, *, at_most: Optional[int] = None, where: str = "") -> int:
    """An integer (NumPy's too; bools and floats such as 2.0 refused), ``|value| <= at_most``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise InvalidArgumentError(name, f"must be an integer, got {_shown(value)}", where)
    if at_most is not None and abs(value) > at_most:
        raise InvalidArgumentError(name, f"= {_shown(value)} is beyond the limit of {at_most:,}", where)
    return int(value)


def positive(name: str, value: Any) -> float:
    x = real(name, value)
    if x <= 0.0:
        raise InvalidArgumentError(name, f"must be positive, got {_shown(value)}")
    return x


#: A work budget (``max_steps``, ``max_nfev``) above this is unlimited in practice: it is
#: passed on as this (no run takes 2**62 steps), never overflowing the core's counters.
COUNT_LIMIT = 2 ** 62


def count(name: str, value: Any) -> int:
    """A positive integer (an integral float such as 1e6 too); 1.5, bools and strings refused;
    beyond :data:`COUNT_LIMIT` it is that limit."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise InvalidArgumentError(name, f"must be a positive integer, got {type(value).__name__} {_shown(value)}")
    if isinstance(value, numbers.Integral):
        if value < 1:
            raise InvalidArgumentError(name, f"must be a positive integer, got {_shown(value)}")
        return min(int(value), COUNT_LIMIT)
    x = float(value)
    if not x.is_integer() or x < 1:
        raise InvalidArgumentError(name, f"must be a positive integer, got {_shown(value)}")
    return min(int(x), COUNT_LIMIT)


def real_array(name: str, value: Any, shape: Optional[tuple] = None) -> np.ndarray:
    """A finite float array; None, strings, masked, complex, boolean and object arrays refused."""
    if value is None:
        raise InvalidArgumentError(name, "must be an array of real numbers, got None")
    if isinstance(value, np.ma.MaskedArray):
        raise InvalidArgumentError(name, "masked arrays are not accepted (fill or compress the mask first)")
    if isinstance(value, (str, bytes)):
        raise InvalidArgumentError(name, f"must be an array of real numbers, got a string {_shown(value)}")
    raw = np.asarray(value)
    if raw.dtype.kind not in "iuf":
        raise InvalidArgumentError(name, f"must hold real numbers, got dtype {raw.dtype}")
    arr = raw.astype(float)
    if shape is not None and arr.shape != shape:
        raise InvalidArgumentError(name, f"expected shape {shape}, got {arr.shape}")
    bad = np.flatnonzero(~np.isfinite(arr.ravel()))
    if bad.size:
        raise NonFiniteError(f"{name}: contains NaN or infinity at index {int(bad[0])}")
    return arr


def non_negative(name: str, value: Any) -> float:
    x = real(name, value)
    if x < 0.0:
        raise InvalidArgumentError(name, f"must be >= 0, got {_shown(value)}")
    return x
