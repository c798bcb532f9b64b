"""Hypothesis strategies for hostile values: what a careless or hostile user passes."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

#: floats at the edges of the double range and of physical sense
EXTREME_FLOATS = [0.0, -0.0, -1.0, 5e-324, 1e-300, -1e-300, 1e-30, 1e30, 1e100, 1e200, 1e300, -1e300, 1e308,
                  -1e308, float("inf"), float("-inf"), float("nan")]

#: values of the wrong type or absurd size
WRONG_TYPES = ["1", "abc", "", True, False, None, [], [1.0, 2.0, 3.0], {}, {"a": 1}, complex(1.0, 2.0),
               10 ** 400, -(10 ** 400), 10 ** 30, 1.5, -7, np.float32(1.0), np.int64(3), b"1",
               np.ma.masked_array([1.0], mask=[True])]


def scaled(lo: float, hi: float) -> st.SearchStrategy[float]:
    """A plausible value, log-uniform in ``[lo, hi]``."""
    return st.floats(np.log10(lo), np.log10(hi)).map(lambda e: float(10.0 ** e))


def hostile() -> st.SearchStrategy:
    """Any hostile scalar: an extreme float, a wrong type, or an arbitrary double."""
    return st.one_of(st.sampled_from(EXTREME_FLOATS), st.sampled_from(WRONG_TYPES),
                     st.floats(allow_nan=True, allow_infinity=True))


def maybe_hostile(plausible: st.SearchStrategy, p_plausible: int = 3) -> st.SearchStrategy:
    """Mostly the plausible value, sometimes a hostile one."""
    return st.one_of(*([plausible] * p_plausible), hostile())


def hostile_array(n: int) -> st.SearchStrategy:
    """Arrays meant to have shape ``(n,)``: wrong shapes, dtypes, layouts, non-finite entries,
    masked, complex, strings, None, nested lists."""
    base = st.lists(st.floats(-1.0, 1.0), min_size=n, max_size=n).map(lambda v: np.array(v, dtype=float))

    def poison(a: np.ndarray, where: int, value: float) -> np.ndarray:
        a = a.copy()
        if a.size:
            a[where % a.size] = value
        return a

    return st.one_of(
        base,
        st.tuples(base, st.integers(0, 10 ** 6), st.sampled_from([float("nan"), float("inf"), -float("inf"), 1e300,
                                                                  -1e308, 1e200, 5e-324])).map(lambda t: poison(*t)),
        base.map(lambda a: a[:-1] if a.size else a),                      # too short
        base.map(lambda a: np.append(a, 0.0)),                           # too long
        base.map(lambda a: a.reshape(1, -1)),                            # 2-D
        base.map(lambda a: np.repeat(a, 2)[::2]),                        # non-contiguous, same values
        base.map(lambda a: a.astype(">f8")),                             # big-endian
        base.map(lambda a: a.astype(np.float32)),
        base.map(lambda a: np.round(a).astype(np.int64)),
        base.map(lambda a: a.astype(complex) + 1j),                      # complex
        base.map(lambda a: np.ma.masked_array(a, mask=np.ones(a.shape, bool))),
        base.map(lambda a: a.tolist()),
        base.map(lambda a: [str(x) for x in a]),
        st.sampled_from([None, 0.0, "q", np.array(1.0), np.empty(0), np.zeros((0, 0)), [[]]]),
    )
