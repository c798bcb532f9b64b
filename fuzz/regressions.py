"""Seeded regressions: each puts one fixed bug back (a monkeypatch inside the fuzz worker), so a
run with it must report findings -- the proof that the suite bites (tests/test_fuzz.py).

Each entry: name -> (category that must catch it, patch)."""

from __future__ import annotations

from typing import Callable, Dict, Tuple

import numpy as np

_PER_CALL = ("qdd", "rhs", "M", "Q", "phi", "A", "b", "multipliers", "residuals", "kinetic_energy",
             "potential_energy", "jac")


def _wrap_system_methods(wrap: Callable[[Callable], Callable]) -> None:
    from ukflex.model import system as system_module

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
    """No check of the corrected state (resolution, conditioning): a mechanism 1e17 m from the
    origin builds."""
    from ukflex.model import system as system_module

    system_module.System._check_state = lambda self: None


def _shared_settings() -> None:
    """simulate(..., stabilization=...) configuring the caller's System (settings shared across threads)."""
    from ukflex.model import system as system_module

    system_module.System.copy = lambda self: self


# ----------------------------------------------------------------------------------- issue 28
def _old_expressions(**defects: bool) -> Callable[[], None]:
    """Expressions evaluated by the old evaluator (:mod:`fuzz.old_expressions`) with one defect."""
    def patch() -> None:
        import json

        from ukflex import _core

        from .old_expressions import motion_values as old

        new = _core.motion_values

        def motion_values(motion_json, t):
            d = json.loads(motion_json)
            text = d.get("expression") if isinstance(d, dict) and d.get("kind") == "expression" else None
            # the defects of size (recursion, trees) need the long texts; the others are about
            # values: long texts go to the core as they are now, so the run stays quick
            if isinstance(text, str) and (len(text) <= 5000 or defects.get("recursion") or defects.get("trees")):
                return old(text, t, **defects)
            return new(motion_json, t)

        _core.motion_values = motion_values

    return patch


def _dense_unchecked() -> None:
    """Dense records evaluated without checking them against the method's layout: index errors
    escape (the core's were panics) and NaN passes through."""
    from ukflex import _core
    from ukflex import simulate as sim_module

    def dense_eval(method, meta, data, part_len, t):
        # as the core did: the parts cut from each segment by part_len, the first part's length
        # taken as the state's, DOPRI5's continuous extension, no question asked
        meta, data = np.asarray(meta, dtype=float), np.asarray(data, dtype=float)
        t = np.atleast_1d(np.asarray(t, dtype=float))
        dim = int(part_len[0])
        out = np.zeros((dim, t.size))
        for j, tj in enumerate(t):
            k = min(int(np.searchsorted(meta[:, 1], tj)), len(meta) - 1)
            seg, parts, at = data[k], [], 0
            for n in part_len:
                parts.append(seg[at:at + int(n)])
                at += int(n)
            h = meta[k, 1] - meta[k, 0]
            th = (tj - meta[k, 0]) / h if h else 1.0
            for i in range(dim):
                r = [parts[p][i] for p in range(5)]
                out[i, j] = r[0] + th * (r[1] + (1 - th) * (r[2] + th * (r[3] + (1 - th) * r[4])))
        return out

    _core.dense_eval = dense_eval
    sim_module = __import__("sys").modules["ukflex.run.simulate"]
    sim_module._core.dense_eval = dense_eval
    init = sim_module.DenseSolution.__init__

    def unchecked(self, method, meta, data, part_len):
        self.method, self.meta, self.data, self.part_len = method, np.asarray(meta), np.asarray(data), list(part_len)
        self.ts = np.zeros(0)
        self.t_min = self.t_max = float("nan")

    sim_module.DenseSolution.__init__ = unchecked
    del init


_NON_FINITE_CALLS = ("project", "phi_t", "tangent_stiffness", "axial_forces", "beam_point")


def _percall_nonfinite() -> None:
    """The per-call methods that returned inf and NaN before: NonFiniteError turned back into NaN."""
    import ukflex
    from ukflex.model import system as system_module

    bind = system_module.System._bind

    def nan_instead(f):
        def g(*a):
            try:
                return f(*a)
            except ukflex.NonFiniteError:
                return np.full(3, np.nan)
        return g

    def patched(self, core):
        bind(self, core)
        for name in _NON_FINITE_CALLS:
            setattr(self, name, nan_instead(getattr(self, name)))

    system_module.System._bind = patched


def _bare_keyerror() -> None:
    """Unknown names raise a bare KeyError (no UnknownNameError, no list of valid names)."""
    from ukflex.errors import UnknownNameError

    UnknownNameError.of = classmethod(lambda cls, what, name, valid: KeyError(name))


def _pickle_unchecked() -> None:
    """System pickle states restored without checks (KeyError, AttributeError, wrong shapes accepted)."""
    import json

    from ukflex.model import system as system_module

    def setstate(self, state):
        self.description = state["description"]
        self._build_options = dict(state["build_options"])
        self._settings = {}
        self._core_options = dict(state.get("core_options", {}))
        self._bind(system_module._core.System(json.dumps(self.description), **self._core_options))
        for name, args in state["settings"].items():
            getattr(self, name)(*args)
        for key in ("t0", "q_guess", "qd_guess", "q0", "qd0", "initial_correction"):
            setattr(self, key, state[key])

    system_module.System.__setstate__ = setstate


def _deep_lists() -> None:
    """Descriptions converted by recursion without a depth limit (RecursionError on deep lists)."""
    from ukflex.model import description

    plain = description.plain

    def unlimited(item, path, value, _depth=0):
        if isinstance(value, (list, tuple)):
            return [unlimited(item, f"{path}[{i}]", v) for i, v in enumerate(value)]
        if isinstance(value, dict):
            return {str(k): unlimited(item, f"{path}.{k}", v) for k, v in value.items()}
        return plain(item, path, value)

    description.plain = unlimited


def _fe_unchecked() -> None:
    """fe without its input checks: the 3-D Lame parameter (ZeroDivisionError at nu = 0.5), cells
    cast with ``astype(int)`` (floats truncated, out-of-range indices reaching scikit-fem)."""
    from ukflex import fe

    def lame(youngs_modulus, poisson_ratio):
        mu = youngs_modulus / (2.0 * (1.0 + poisson_ratio))
        lam = youngs_modulus * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio))
        return 2.0 * lam * mu / (lam + 2.0 * mu), mu

    fe._plane_stress_lame = lame
    fe._material = lambda thickness, density, youngs_modulus, poisson_ratio: (thickness, density, youngs_modulus,
                                                                              poisson_ratio)
    fe._mesh_arrays = lambda points, cells: (np.asarray(points, dtype=float)[:, :2].T, np.asarray(cells, dtype=int).T)


def _sweep_eager() -> None:
    """The whole grid built before the first case, with no max_cases: a 10^9-case grid filled the
    memory (here: a MemoryError with an empty message after 2 million cases, as the machine's)."""
    import itertools
    import sys

    import ukflex  # noqa: F401 - loads ukflex.sweep (the package's `sweep` is the function)

    sweep_module = sys.modules["ukflex.run.sweep"]

    def init(self, grid, max_cases=None):
        if isinstance(grid, dict):
            keys = list(grid)
            if any(isinstance(v, range) and len(v) > 200_000 for v in grid.values()):
                raise MemoryError()  # list(range(10**12)): the old code's end, without the wait
            axes = [list(v) if isinstance(v, (list, tuple, range)) else [v] for v in grid.values()]
            cases = []
            for combo in itertools.product(*axes):
                if len(cases) >= 200_000:  # the machine would run out much later, and slowly
                    raise MemoryError()
                cases.append(dict(zip(keys, combo)))
        else:
            cases = [dict(c) for c in grid]
        self._list, self._keys, self._axes, self.size = cases, [], [], len(cases)

    sweep_module.Cases.__init__ = init


def _count_overflow() -> None:
    """Work budgets passed on as they are: simulate(max_steps=10**30) ends in OverflowError."""
    import sys

    from ukflex import arguments

    def count(name, value):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or value < 1 or value != int(value):
            raise arguments.InvalidArgumentError(name, f"must be a positive integer, got {value!r}")
        return int(value)

    sys.modules["ukflex.run.simulate"].count = count


def _unchecked_builtins() -> None:
    """chain and rope without their argument checks (chain(length=1e300): OverflowError)."""
    from ukflex import scenes

    scenes.chain = scenes.chain.__wrapped__
    scenes.rope = scenes.rope.__wrapped__


def _late_plot_check() -> None:
    """Output expressions that name a joint or driver accepted before the run (they fail after it)."""
    from ukflex.results import sensors

    parse = sensors.Sensors.parse.__func__

    @classmethod
    def lenient(cls, system, expr):
        e = expr.strip()
        m = cls._REACTION.match(e)
        if m and m.group(2) in sensors.REACTION_COLUMNS:
            return ("reaction", m.group(1), m.group(2))
        m = cls._WORK.match(e)
        if m:
            return ("work", m.group(1))
        return parse(cls, system, expr)

    sensors.Sensors.parse = lenient


def _home_cache() -> None:
    """The CLI leaves matplotlib's cache where matplotlib puts it ($HOME/.cache/matplotlib)."""
    from ukflex import cli

    cli._private_matplotlib_cache = lambda: None


def _stray_dirs() -> None:
    """--out used as given: ./x/../y creates a stray x/."""
    from ukflex import cli

    main = cli.main

    def keep_out(argv=None):
        import os

        normpath = os.path.normpath
        os.path.normpath = lambda p: p
        try:
            return main(argv)
        finally:
            os.path.normpath = normpath

    cli.main = keep_out


REGRESSIONS: Dict[str, Tuple[str, Callable[[], None]]] = {
    "shared-settings": ("threads", _shared_settings),
    "cli-tracebacks": ("cli", _cli_tracebacks),
    "lenient-arrays": ("arrays", _lenient_arrays),
    "nan-results": ("arrays", _nan_results),
    "unresolved-positions": ("scene", _unresolved_positions),
    # issue 28
    "expr-recursion": ("expr", _old_expressions(recursion=True)),
    "expr-sign-nan": ("expr", _old_expressions(sign_nan=True)),
    "expr-quotient-underflow": ("expr", _old_expressions(quotient=True)),
    "expr-tree-blowup": ("expr", _old_expressions(trees=True)),
    "dense-unchecked": ("dense", _dense_unchecked),
    "percall-nonfinite": ("extremes", _percall_nonfinite),
    "bare-keyerror": ("names", _bare_keyerror),
    "pickle-unchecked": ("pickle", _pickle_unchecked),
    "deep-lists": ("pickle", _deep_lists),
    "fe-unchecked": ("fe", _fe_unchecked),
    "sweep-eager": ("sweep", _sweep_eager),
    "count-overflow": ("builders", _count_overflow),
    "unchecked-builtins": ("builders", _unchecked_builtins),
    "late-plot-check": ("cli", _late_plot_check),
    "home-cache": ("cli", _home_cache),
    "stray-dirs": ("cli", _stray_dirs),
}


def apply(name: str) -> None:
    REGRESSIONS[name][1]()
