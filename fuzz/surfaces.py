"""Fuzz categories of the surfaces added since the first campaign (issue 28): expressions against
SymPy, splines against scipy's ``CubicSpline``, dense output records, tampered pickle states,
finite-element input, sweeps, per-call methods at extreme states, unknown names and the
built-in scene functions.  Each states what counts as wrong for it, as in :mod:`fuzz.cases`.

SymPy is optional (the ``expr`` category's reference): without it that category only checks
named errors, limits, closed forms and the scaling identities.
"""

from __future__ import annotations

import contextlib
import json
import math
import pickle
import time
import warnings
from typing import Any, Dict, List, Optional, Tuple

import numpy as np
from hypothesis import strategies as st

from .common import (Category, Finding, _classify, _exc, _finite, _max_abs, _named, _panic, _quiet, _short, _system,
                     _ukflex)
from .values import EXTREME_FLOATS, WRONG_TYPES, hostile


def _motion_values(motion: Dict[str, Any], t: np.ndarray) -> np.ndarray:
    uk = _ukflex()
    return np.asarray(uk._core.motion_values(json.dumps(motion), np.asarray(t, dtype=float)))


# ============================================================================== expressions
_FUNCS = ["sin", "cos", "tan", "exp", "log", "sqrt", "abs", "tanh", "sinh", "cosh", "atan", "sign"]
_CONSTS = ["0", "1", "2", "3", "0.5", "3.25", "0.001", "1.5e1", "pi", "e", "10", ".25"]
_PREC = {"num": 5, "t": 5, "call": 5, "pow": 4, "neg": 3, "pos": 3, "*": 2, "/": 2, "+": 1, "-": 1}


@st.composite
def _tree(draw, depth: int = 4):
    """A random expression tree (nested tuples)."""
    if depth <= 0 or draw(st.integers(0, 9)) < 3:
        return ("t",) if draw(st.booleans()) else ("num", draw(st.sampled_from(_CONSTS)))
    kind = draw(st.sampled_from(["bin", "bin", "bin", "call", "call", "neg", "pow"]))
    if kind == "bin":
        return (draw(st.sampled_from(["+", "-", "*", "/"])), draw(_tree(depth - 1)), draw(_tree(depth - 1)))
    if kind == "call":
        return ("call", draw(st.sampled_from(_FUNCS)), draw(_tree(depth - 1)))
    if kind == "neg":
        return ("neg", draw(_tree(depth - 1)))
    exponent = draw(st.one_of(st.sampled_from([("num", "2"), ("num", "3"), ("num", "0.5"), ("neg", ("num", "1")),
                                               ("num", "4")]), _tree(depth - 2)))
    return ("pow", draw(_tree(depth - 1)), exponent)


def _has_t(n) -> bool:
    return n[0] == "t" or any(_has_t(c) for c in n[1:] if isinstance(c, tuple))


def _render(node, sympy: bool, style: Tuple[bool, bool], fold: bool = True) -> str:
    """Text of a tree with the fewest parentheses the grammar allows (``style``: ``**`` for ``^``,
    spaces around operators); ``sympy``: SymPy's spelling (``**``, ``Abs``, ``E``)."""
    stars, spaces = style
    sp = " " if spaces else ""

    def prec(n) -> int:
        return _PREC[n[0]]

    def wrap(child, need: bool) -> str:
        text = go(child)
        return f"({text})" if need else text

    def go(n) -> str:
        k = n[0]
        if k == "t":
            return "t"
        if sympy and fold and k not in ("num",) and not _has_t(n):
            # a part without t is computed once, in doubles, as the core folds it: SymPy gets that
            # double (sin(sinh(15)^3) is the sine of the double 4.3e18, not of the real number)
            text = _render(n, True, style, fold=False)
            v = _naive(text, 0.0, "ieee")
            if math.isfinite(v):
                import decimal

                return f"Float('{decimal.Decimal(v)}', 60)"
            return text
        if k == "num":
            if sympy:
                # the doubles the core uses (sin(pi) is 1.2e-16, not 0), as SymPy floats of 60
                # digits: folded at parse time with 17 digits, sin(pi) came out 2.3e-16; floats, not
                # integers: an exact power such as 10**(10**10) would never finish
                import decimal

                x = {"e": math.e, "pi": math.pi}.get(n[1], None)
                exact = decimal.Decimal(float(n[1]) if x is None else x)  # the double's exact binary value
                return f"Float('{exact}', 60)"
            return n[1]
        if k == "call":
            name = "Abs" if sympy and n[1] == "abs" else n[1]
            return f"{name}({go(n[2])})"
        if k == "neg":
            return "-" + wrap(n[1], prec(n[1]) < 3)
        if k == "pow":
            op = "**" if sympy or stars else "^"
            return wrap(n[1], prec(n[1]) < 5) + op + wrap(n[2], prec(n[2]) < 3)
        left = wrap(n[1], prec(n[1]) < _PREC[k])
        right = wrap(n[2], prec(n[2]) <= _PREC[k])
        return f"{left}{sp}{k}{sp}{right}"

    return go(node)


_SYMPY: Dict[str, Any] = {}


class _SlowReference(Exception):
    """SymPy took longer than the case's budget for the reference (not a finding: skipped)."""


@contextlib.contextmanager
def _budget(seconds: float):
    """Raise :class:`_SlowReference` in the block after ``seconds`` (SIGALRM: the fuzz workers
    run their cases in the main thread); elsewhere, no limit."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "setitimer"):
        yield
        return

    def stop(signum, frame):
        raise _SlowReference()

    old = signal.signal(signal.SIGALRM, stop)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)


def _sympy():
    """(sympy, t) or None when SymPy is not installed."""
    if "mod" not in _SYMPY:
        try:
            import sympy
        except ImportError:
            _SYMPY["mod"] = None
        else:
            _SYMPY["mod"] = (sympy, sympy.Symbol("t", real=True))
    return _SYMPY["mod"]


def _exact(expr, t_sym, tv: Any) -> Tuple[str, float]:
    """(kind, value) of a SymPy expression at ``tv`` with 40 digits: kind "real" (a double if
    representable), "overflow" (beyond the double range), "undefined" (complex, NaN, zoo,
    infinite) or "skip" (a distribution such as DiracDelta, or SymPy could not evaluate)."""
    sympy = _SYMPY["mod"][0]
    try:
        x = tv if isinstance(tv, sympy.Float) else sympy.Float(tv, 53)
        v = expr.subs(t_sym, x).evalf(40)
    except Exception:  # noqa: BLE001 - SymPy's own failures are not ours to judge
        return "skip", 0.0
    if v.free_symbols or v.has(sympy.DiracDelta) or v.has(sympy.Heaviside):
        return "skip", 0.0
    if v in (sympy.nan, sympy.zoo, sympy.oo, -sympy.oo) or v.is_real is False or v.is_finite is False:
        return "undefined", float("nan")
    if v.is_real is not True:
        return "skip", 0.0
    try:
        x = float(v)
    except (TypeError, ValueError):
        return "skip", 0.0
    if not math.isfinite(x):
        return "overflow", x
    return "real", x


@st.composite
def _expr_case(draw):
    mode = draw(st.sampled_from(["sympy"] * 5 + ["undefined", "stress", "stress", "scaled", "syntax"]))
    ts = draw(st.lists(st.sampled_from([0.0, 0.3, -0.7, 1.0, 1.7, -2.0, 0.5]), min_size=1, max_size=3, unique=True))
    if mode == "sympy":
        tree = draw(_tree(draw(st.integers(1, 5))))
        style = (draw(st.booleans()), draw(st.booleans()))
        return dict(mode=mode, text=_render(tree, False, style), sympy=_render(tree, True, style), t=ts, tree=tree)
    if mode == "undefined":  # NaN at t = 0 inside a function that could hide it (sign): must be refused
        inner = draw(st.sampled_from(["log(t - 1)", "sqrt(t - 2)", "(t - 1)^0.5", "log(-1 - t^2)", "0/0", "t/t",
                                      "atan(sqrt(-1 - t))"]))
        outer = draw(st.sampled_from(["sign({})", "sign({}) * t", "abs(sign({}))", "t + sign({})^2", "2*sign(sign({}))"]))
        return dict(mode="undefined", text=outer.format(inner), t=ts)
    if mode == "scaled":  # identities under a common factor c of extreme size: the same f, f', f''
        g, h = draw(_tree(2)), draw(_tree(2))
        c = draw(st.sampled_from(["1e-170", "1e170", "1e-300", "1e300", "1e-200", "3e150", "1e-160"]))
        sg, sh = _render(g, False, (False, True)), _render(h, False, (False, True))
        text, plain = draw(st.sampled_from([(f"{c}*({sg})/({c}*({sh}))", f"({sg})/({sh})"),
                                            (f"{c}/({c}*({sh}))", f"1/({sh})"),
                                            (f"({c}*({sg}))/{c}", f"{sg}"),
                                            (f"log({c}*({sg}))", f"log({sg}) + log({c})")]))
        return dict(mode=mode, text=text, plain=plain, t=ts)
    if mode == "syntax":
        junk = draw(st.one_of(st.text(max_size=30), st.sampled_from(
            ["", "(", ")", "t t", "sin t", "foo(t)", "1e+", "2..3", "t^", "**t", "((t)", "(t))", "t+*t", "e.t",
             "crank.theta", "d:t", "t^-", "--", "sin()", "t\x00", "1e999", "pi(t)"])))
        return dict(mode=mode, text=junk, t=ts)
    form = draw(st.sampled_from(["nest", "signs", "open", "flat", "tower", "sin", "product", "quotient", "sum"]))
    k = draw(st.sampled_from([10, 300, 1000, 9999, 10000, 10001, 30000]))
    return dict(mode=mode, form=form, k=k, t=ts)


def _stress_text(form: str, k: int) -> Tuple[str, Optional[Any]]:
    """The text of a stress form and its closed form ``f(t)`` (None: none checked)."""
    if form == "nest":
        return "(" * k + "t" + ")" * k, lambda t: t
    if form == "signs":
        return "-" * k + "t", lambda t: (-1) ** k * t
    if form == "open":
        return "(" * k, None
    if form == "flat":
        return "t+" * (4 * k) + "t", lambda t: (4 * k + 1) * t
    if form == "tower":
        return "t^" * k + "t", None
    if form == "sin":
        return "sin(" * k + "t" + ")" * k, None
    if form == "product":
        return "*".join(["(t+1)"] * (k // 4 + 1)), None
    if form == "quotient":
        return "/".join(["(t+2)"] * (k // 4 + 1)), None
    return "+".join(f"{j % 7 + 1}*t^{j % 5}" for j in range(k // 4 + 1)), None


def _check_expr(case: Dict[str, Any]) -> List[Finding]:
    uk = _ukflex()
    mode = case["mode"]
    if mode == "stress":
        text, closed = _stress_text(case["form"], case["k"])
    else:
        text, closed = case["text"], None
    ts = np.array(case["t"], dtype=float)
    tic = time.perf_counter()
    with _quiet():
        try:
            v = _motion_values({"kind": "expression", "expression": text}, ts)
        except BaseException as exc:  # noqa: BLE001
            wall = time.perf_counter() - tic
            if _panic(exc):
                return [("panic", _exc(exc))]
            if isinstance(exc, uk.ExpressionError):
                found = []
                if mode in ("sympy", "scaled"):  # generated, well formed and small: must parse
                    found.append(("wrong", f"a well-formed expression refused: {_exc(exc)}"))
                if mode == "stress" and len(text) <= 100_000 and "nested deeper" not in str(exc) and case["form"] != "open":
                    found.append(("wrong", f"refused within the limits: {_exc(exc)}"))
                return found + ([("wrong", f"{wall:.1f} s to refuse {len(text)} characters")] if wall > 3.0 else [])
            if isinstance(exc, uk.InvalidSceneError) and "not finite at t = 0" in str(exc):
                if mode == "scaled":  # refused where the unscaled form is fine: the factor broke it
                    try:
                        _motion_values({"kind": "expression", "expression": case["plain"]}, ts)
                    except Exception:  # noqa: BLE001 - the form itself is undefined at 0
                        return []
                    return [("wrong", f"refused at t = 0 ({str(exc)[-90:]}) while {case['plain']!r} is not")]
                try:
                    with _budget(3.0):
                        refused = _refused_at_zero(case, exc)
                except _SlowReference:
                    refused = []
                return refused + (
                    [("wrong", f"{wall:.1f} s to build {len(text)} characters (cost not linear)")] if wall > 3.0 else [])
            return [("unnamed-exception", _exc(exc))]
    wall = time.perf_counter() - tic
    if mode == "stress" and wall > 3.0:
        return [("wrong", f"{wall:.1f} s to build and evaluate {len(text)} characters (cost not linear)")]
    if mode == "syntax":
        return []  # parsed: whatever it is, it evaluated (and was finite at t = 0)
    if mode == "undefined":
        return [("wrong", f"a motion undefined at t = 0 (NaN inside) accepted: f, f', f'' = {v[:, 0].tolist()}: {text!r}")]
    if closed is not None:
        ref = np.array([closed(t) for t in ts])
        # a flat sum of 4k terms accumulates 4k roundings
        if not np.allclose(v[0], ref, rtol=1e-14 * len(text), atol=0.0):
            return [("wrong", f"{case['form']} k={case['k']}: f = {v[0]} instead of {ref}")]
        return []
    if mode == "scaled":
        keep = [j for j, tv in enumerate(ts) if math.isfinite(_naive(text, float(tv), "exact"))]
        if not keep:  # the scaled factors themselves leave the double range: nothing to compare
            return []
        ts, v = ts[keep], v[:, keep]
        try:
            w = _motion_values({"kind": "expression", "expression": case["plain"]}, ts)
        except Exception as exc:  # noqa: BLE001 - the unscaled form may be refused at t = 0 alone
            return [] if _named(exc, []) else [("unnamed-exception", "unscaled: " + _exc(exc))]
        for k, name in enumerate(("f", "f'", "f''")):
            a, b = v[k], w[k]
            if np.isfinite(b).all() and (not np.isfinite(a).all() or np.any(np.abs(a - b) > 1e-9 * np.maximum(np.abs(b), 1e-300) + 1e-12 * np.maximum(1.0, np.abs(b)))):
                return [("wrong", f"{name} of c g / (c h) = {a} differs from that of g / h = {b}")]
        return []
    if mode == "sympy":
        try:
            with _budget(3.0):
                return _against_sympy(case, ts, v)
        except _SlowReference:
            return []
    return []


#: what stops a naive evaluation (``_naive``): "strict" any division by zero, invalid operation
#: or overflow; "ieee" only an invalid operation (log(0) = -inf goes on, as IEEE arithmetic
#: does); "exact" also underflow (an expression whose own factors leave the double range)
_NAIVE = {"strict": dict(divide="raise", invalid="raise", over="raise", under="ignore"),
          "ieee": dict(divide="ignore", invalid="raise", over="ignore", under="ignore"),
          "exact": dict(divide="raise", invalid="raise", over="raise", under="raise")}


def _naive(text: str, tv: float, mode: str = "strict") -> float:
    """The expression (SymPy's spelling, or ours with ``^``) evaluated operation by operation in
    NumPy doubles, as written: no simplification (``t/(t/2)`` is NaN at 0, as it is for the
    core); NaN where ``mode`` stops it."""
    import ast

    class Floats(ast.NodeTransformer):
        def visit_Constant(self, node):  # every number a NumPy double: IEEE results, no exceptions
            return ast.Call(ast.Name("F", ast.Load()), [node], []) if isinstance(node.value, (int, float)) else node

    text = text.replace("^", "**")
    env = {"F": np.float64, "Float": lambda text, digits=None: np.float64(float(text)), "t": np.float64(tv),
           "E": np.float64(math.e), "e": np.float64(math.e),
           "pi": np.float64(math.pi), "Abs": np.abs, "abs": np.abs,
           "sign": np.sign, "sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "log": np.log,
           "sqrt": np.sqrt, "tanh": np.tanh, "sinh": np.sinh, "cosh": np.cosh, "atan": np.arctan}
    try:
        tree = ast.fix_missing_locations(Floats().visit(ast.parse(text, mode="eval")))
        # a division by zero, an invalid operation or an overflow on the way makes it undefined,
        # even when IEEE arithmetic would carry an infinity through to a finite end (x / inf = 0)
        with warnings.catch_warnings(), np.errstate(**_NAIVE[mode]):
            warnings.simplefilter("ignore")
            return float(eval(compile(tree, "<expr>", "eval"), {"__builtins__": {}}, env))  # noqa: S307 - our own text
    except Exception:  # noqa: BLE001
        return float("nan")


def _parts_refused(tree: Any) -> bool:
    """Whether a proper part of the expression is itself refused at t = 0 (not differentiable
    there, ``sqrt(t^2)``): the chain rule then meets 0 x inf, and a refusal of the whole is
    explained even where SymPy's simplified formula (``|t|^81``) is finite."""
    def parts(n):
        for c in n[1:]:
            if isinstance(c, tuple) and c[0] not in ("t", "num"):
                yield c
                yield from parts(c)

    for p in parts(tree):
        try:
            _motion_values({"kind": "expression", "expression": _render(p, False, (False, True))}, np.zeros(1))
        except Exception:  # noqa: BLE001 - refused (or not an expression on its own)
            return True
    return False


def _singular_at(tree: Any, tv: float) -> bool:
    """Whether a node of the expression is at a point where its function is not differentiable
    (a fractional or negative power of 0, sqrt or log of 0 or less, a division by 0, abs or sign
    of 0): there the chain rule meets 0 x inf even where the whole is smooth (``((t - t) t)^0.5``)."""
    def value(n) -> float:
        return _naive(_render(n, True, (True, False)), tv, "ieee")

    def walk(n) -> bool:
        k = n[0]
        if k == "pow":
            base, expo = value(n[1]), n[2]
            integral = expo[0] == "num" and float(expo[1]).is_integer() and float(expo[1]) >= 0
            if not integral and not base > 0.0:
                return True
        elif k == "/" and value(n[2]) == 0.0:
            return True
        elif k == "call" and n[1] in ("sqrt", "log") and not value(n[2]) > 0.0:
            return True
        elif k == "call" and n[1] in ("abs", "sign") and value(n[2]) == 0.0:
            return True
        return any(walk(c) for c in n[1:] if isinstance(c, tuple))

    return walk(tree)


def _refused_at_zero(case: Dict[str, Any], exc: BaseException) -> List[Finding]:
    """A motion refused as not finite at t = 0 must be undefined there: its value as written
    (NaN for 0/0, as the core's) or SymPy's derivatives not finite, or a part of it refused."""
    if case["mode"] != "sympy" or _sympy() is None or not math.isfinite(_naive(case["sympy"], 0.0)):
        return []
    if "tree" in case and (_parts_refused(case["tree"]) or _singular_at(case["tree"], 0.0)):
        return []
    sympy, t = _sympy()
    try:
        f = sympy.parse_expr(case["sympy"], local_dict=_LOCALS(), evaluate=True)
        derivs = [f, sympy.diff(f, t), sympy.diff(f, t, 2)]
    except Exception:  # noqa: BLE001 - SymPy could not take it: nothing to compare
        return []
    kinds = [_exact(d, t, 0.0)[0] for d in derivs]
    if all(k == "real" for k in kinds):
        vals = [_exact(d, t, 0.0)[1] for d in derivs]
        return [("wrong", f"refused at t = 0 ({str(exc)[-80:]}) where f, f', f'' = {vals}: {case['text']!r}")]
    return []


def _LOCALS() -> Dict[str, Any]:
    """SymPy's names for the expression, with ``sign`` and ``Abs`` as functions of the motion's
    semantics: ``sign`` has derivative 0 (not a DiracDelta, whose handling sends SymPy's
    assumptions into endless recursion), is undefined for an undefined argument, and ``Abs'`` is
    ``sign``."""
    sympy, t = _sympy()
    if "funcs" not in _SYMPY:
        def real_function(name, value, derivative):
            """A SymPy function that is ``value`` at real numbers, undefined (NaN) at others."""
            def evaluate(cls, x):
                if x.is_number:
                    if x in (sympy.nan, sympy.zoo) or x.is_real is False:
                        return sympy.nan
                    if x.is_real:
                        return value(x)
                return None

            return type(name, (sympy.Function,), {"eval": classmethod(evaluate),
                                                  "fdiff": lambda self, argindex=1: derivative(self.args[0])})

        Sgn = real_function("Sgn", sympy.sign, lambda x: sympy.S.Zero)
        Absv = real_function("Absv", abs, lambda x: Sgn(x))
        _SYMPY["funcs"] = (Sgn, Absv)
    sgn, absv = _SYMPY["funcs"]
    return {"t": t, "E": sympy.E, "pi": sympy.pi, "e": sympy.E, "Abs": absv, "sign": sgn}


def _difference(f, t_sym, tv: float, k: int) -> Optional[float]:
    """The k-th derivative of ``f`` at ``tv`` from central differences of its exact values (60
    digits, step 1e-15): the reference where SymPy's symbolic derivative is undefined at a point
    where ``f`` is smooth (``d/dt sign(0^t) = 0``, SymPy: ``0 * log(0)``); None if ``f`` is not
    real there."""
    sympy = _SYMPY["mod"][0]
    h = sympy.Float("1e-15", 60) * max(1.0, abs(tv))
    x0 = sympy.Float(tv, 53)
    vals = []
    for x in (x0 - h, x0, x0 + h):
        try:
            v = f.subs(t_sym, x).evalf(60)
        except Exception:  # noqa: BLE001
            return None
        if v.free_symbols or v.is_real is not True or v.is_finite is not True:
            return None
        vals.append(v)
    d = (vals[2] - vals[0]) / (2 * h) if k == 1 else (vals[2] - 2 * vals[1] + vals[0]) / (h * h)
    return float(d)


def _jumps(f, t_sym, tv: float) -> bool:
    """Whether ``f`` is not continuous at ``tv``: undefined on a side, or its values a hair to
    either side differ (a step of ``sign``)."""
    sympy = _SYMPY["mod"][0]
    h = sympy.Float("1e-25", 60) * max(1.0, abs(tv))
    sides = [_exact(f, t_sym, sympy.Float(tv, 53) + s * h) for s in (-1, 1)]
    if any(kind != "real" for kind, _ in sides):
        return True
    return abs(sides[0][1] - sides[1][1]) > 1e-9 * max(1.0, abs(sides[0][1]))


def _removable(expr, t_sym, tv: float, ours: float) -> bool:
    """Whether SymPy's "undefined" at ``tv`` is only its formula's (``pi t^pi / t`` at 0, a
    removable singularity): the exact value a hair away, on either side, is real and is ours."""
    sympy = _SYMPY["mod"][0]
    h = sympy.Float("1e-25", 60) * max(1.0, abs(tv))  # close: t^0.72 vanishes slowly
    for probe in (sympy.Float(tv, 53) + h, sympy.Float(tv, 53) - h):
        kind, near = _exact(expr, t_sym, probe)
        if kind == "real" and abs(near - ours) <= 1e-5 * max(1.0, abs(ours)):
            return True
    return False


def _against_sympy(case: Dict[str, Any], ts: np.ndarray, v: np.ndarray) -> List[Finding]:
    """Values and both derivatives against SymPy's exact ones (40 digits). Wrong: a finite value
    where the exact one is undefined or beyond the double range, or one that differs from it by
    more than 1e-7 of max(1, |exact|) and more than 100 x the error of SymPy's own derivative
    evaluated in doubles (the expression's conditioning)."""
    if _sympy() is None:
        return []
    sympy, t = _sympy()
    try:
        f = sympy.parse_expr(case["sympy"], local_dict=_LOCALS(), evaluate=True)
        derivs = [f, sympy.diff(f, t), sympy.diff(f, t, 2)]
    except Exception:  # noqa: BLE001
        return []

    def double(k: int, tv: float) -> float:
        """SymPy's k-th derivative evaluated in doubles (NaN when it cannot be)."""
        try:
            with _quiet():
                return float(sympy.lambdify(t, derivs[k], modules="math")(tv))
        except Exception:  # noqa: BLE001 - math domain errors, overflow, DiracDelta
            return float("nan")

    for j, tv in enumerate(ts):
        if math.isinf(_naive(case["sympy"], float(tv), "ieee")):
            continue  # beyond doubles as written (cosh(cosh(t^30))): 40 digits of it would take SymPy ages
        for k, name in enumerate(("f", "f'", "f''")):
            ours = float(v[k][j])
            kind, exact = _exact(derivs[k], t, float(tv))
            if kind == "skip":
                continue
            if k > 0 and _exact(derivs[0], t, float(tv))[0] != "real":
                continue  # SymPy's derivatives of an undefined value (t + nan = nan: d/dt 0) say nothing
            if kind in ("undefined", "overflow"):
                # defined in IEEE arithmetic through an infinity (sign(log(0)) = sign(-inf) = -1) is
                # what doubles do; defined where an invalid operation (NaN) was hidden is not
                ieee = k == 0 and _naive(case["sympy"], float(tv), "ieee") == ours
                fd = _difference(derivs[0], t, float(tv), k) if k > 0 and math.isfinite(ours) else None
                if fd is not None and abs(ours - fd) <= 1e-6 * max(1.0, abs(fd)):
                    continue  # SymPy's formula is undefined where f is smooth; ours is its derivative
                if k > 0 and math.isfinite(ours) and _jumps(derivs[0], t, float(tv)):
                    continue  # f jumps (or ends) here: its derivative is a convention (sign' = 0), not a value
                if math.isfinite(ours) and not ieee and not (kind == "undefined" and _removable(derivs[k], t, float(tv), ours)):
                    return [("wrong", f"{name}({tv}) = {ours!r} finite where it is {kind}: {case['text']!r}")]
                continue
            if not math.isfinite(ours):
                continue  # refused (NaN/inf) where the exact value exists: conservative, not silent
            dbl = double(k, float(tv))
            slack = 100.0 * abs(dbl - exact) if math.isfinite(dbl) else float("inf")
            err = abs(ours - exact)
            if err > 1e-7 * max(1.0, abs(exact)) and err > slack:
                return [("wrong", f"{name}({tv}) = {ours!r}, exact {exact!r} (SymPy in doubles {dbl!r}): {case['text']!r}")]
    return []


# ============================================================================== splines
@st.composite
def _spline_case(draw):
    n = draw(st.integers(2, 25))
    scale = draw(st.sampled_from([1e-6, 1e-3, 1.0, 10.0, 1e4, 1e6]))
    offset = draw(st.sampled_from([0.0, -3.0, 1e3, 1e9]))
    gaps = draw(st.lists(st.floats(0.05, 3.0), min_size=n - 1, max_size=n - 1))
    times = list(offset + scale * np.concatenate([[0.0], np.cumsum(gaps)]))
    yscale = draw(st.sampled_from([1e-300, 1e-6, 1.0, 1e3, 1e100, 1e300]))
    values = [yscale * x for x in draw(st.lists(st.floats(-1.0, 1.0), min_size=n, max_size=n))]
    slopes = draw(st.one_of(st.none(), st.lists(st.floats(-5.0, 5.0), min_size=2, max_size=2)))
    if slopes is not None:
        slopes = [yscale / scale * s for s in slopes]
    hostile_field = draw(st.sampled_from([None] * 6 + ["times", "values", "slopes", "length", "order"]))
    if hostile_field == "length" and n == 2:
        hostile_field = "values"
    if hostile_field in ("times", "values", "slopes"):
        target = {"times": times, "values": values, "slopes": slopes if slopes is not None else [0.0, 0.0]}[hostile_field]
        target[draw(st.integers(0, len(target) - 1))] = draw(st.sampled_from(
            [float("nan"), float("inf"), -float("inf"), 1e308, "x", None, [1.0]]))
        if hostile_field == "slopes":
            slopes = target
    elif hostile_field == "length":  # lengths that differ, or a single point
        times, values = (times, values[:-1]) if draw(st.booleans()) else (times[:1], values[:1])
    elif hostile_field == "order":
        i = draw(st.integers(0, max(0, n - 2)))
        times[i + 1] = times[i] - draw(st.sampled_from([0.0, 1.0]))
    lo, hi = (times[0], times[-1]) if all(isinstance(x, float) and math.isfinite(x) for x in (times[0], times[-1])) \
        else (0.0, 1.0)
    where = draw(st.lists(st.floats(-0.2, 1.2), min_size=1, max_size=5))
    t_eval = [lo + w * (hi - lo) for w in where] + [times[0] if isinstance(times[0], float) else 0.0]
    return dict(times=times, values=values, slopes=slopes, hostile=hostile_field, t=t_eval)


def _spline_valid(times: Any, values: Any, slopes: Any) -> bool:
    """Finite numbers, times strictly increasing, as many values, two slopes if any."""
    def numbers(v):
        return isinstance(v, list) and all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
                                           for x in v)
    return (numbers(times) and numbers(values) and len(times) == len(values) >= 2
            and all(b > a for a, b in zip(times, times[1:])) and (slopes is None or (numbers(slopes) and len(slopes) == 2)))


def _check_spline(case: Dict[str, Any]) -> List[Finding]:
    uk = _ukflex()
    motion: Dict[str, Any] = {"kind": "spline", "times": case["times"], "values": case["values"]}
    if case["slopes"] is not None:
        motion["slopes"] = case["slopes"]
    try:
        text = json.dumps(motion)
    except (TypeError, ValueError):
        return []
    with _quiet():
        try:
            v = np.asarray(uk._core.motion_values(text, np.asarray(case["t"], dtype=float)))
        except BaseException as exc:  # noqa: BLE001
            return _classify(exc, ["spline", "times", "values", "slopes"], "spline: ")
    if not _spline_valid(case["times"], case["values"], case["slopes"]):
        return [("wrong", f"spline accepted a table that is not one ({case['hostile']})")]
    from scipy.interpolate import CubicSpline

    tt, yy = np.asarray(case["times"]), np.asarray(case["values"])
    bc = "natural" if case["slopes"] is None else ((1, case["slopes"][0]), (1, case["slopes"][1]))
    with _quiet():
        try:
            ref = CubicSpline(tt, yy, bc_type=bc, extrapolate=True)
        except ValueError:  # scipy's own limits (differences beyond the double range): nothing to compare
            return []
        te = np.asarray(case["t"], dtype=float)
        refs = [ref(te), ref(te, 1), ref(te, 2)]
    h = float(np.min(np.diff(tt)))
    span = float(tt[-1] - tt[0])
    ymax = float(np.max(np.abs(yy))) + (0.0 if case["slopes"] is None else float(np.max(np.abs(case["slopes"]))) * span)
    for k, name in enumerate(("f", "f'", "f''")):
        ours, r = v[k], refs[k]
        if not _finite(r):
            continue
        if not _finite(ours):
            return [("silent-nonfinite", f"spline {name} = {ours} where scipy's is finite {r}")]
        # scale of the k-th derivative of a spline of these knots (plus extrapolation's growth)
        with np.errstate(all="ignore"):
            reach = np.float64(max(1.0, float(np.max(np.abs(te - np.clip(te, tt[0], tt[-1])))) / h)) ** 3
            scale = float(np.float64(ymax) / np.float64(h) ** k * (np.float64(span) / h) ** 2 * reach)
        if not math.isfinite(scale):
            return []  # a table spanning the double range: no scale to judge by
        err = float(np.max(np.abs(ours - r)))
        if err > 1e-9 * scale + 1e-290:  # below ~1e-290 both work in subnormal numbers
            return [("wrong", f"spline {name} differs from scipy's CubicSpline by {err:.3g} (scale {scale:.3g})")]
    return []


# ============================================================================== dense output
_DENSE: Dict[str, Any] = {}


def _dense_record(method: str):
    """(meta, data, part_len, t range) of a short native run with dense output (cached)."""
    if method not in _DENSE:
        s = _system("pendulum")
        out = s.integrate(0.0, s.y0, 0.05, method, 1e-6, None, None, dense=True)
        d = out["dense"]
        _DENSE[method] = (np.asarray(d["meta"]), np.asarray(d["data"]), list(d["part_len"]))
    return _DENSE[method]


_DENSE_MUTATIONS = ["none", "none_copy", "lower", "drop_col", "add_col", "drop_row_meta", "part_plus", "part_minus",
                    "part_huge", "part_neg", "part_count", "part_empty", "meta_cols", "nan_data", "inf_meta",
                    "reverse", "swap_methods", "empty", "object", "complex", "noncontig", "t_nan", "t_far", "t_2d",
                    "t_str", "unknown_method", "one_dim"]


@st.composite
def _dense_case(draw):
    return dict(method=draw(st.sampled_from(["DOPRI5", "RADAU5", "GENALPHA", "RADAU5M"])),
                mutation=draw(st.sampled_from(_DENSE_MUTATIONS)), api=draw(st.sampled_from(["core", "solution"])),
                other=draw(st.sampled_from(["DOPRI5", "RADAU5", "GENALPHA", "RADAU5M"])),
                t=draw(st.lists(st.floats(0.0, 0.05), min_size=1, max_size=4)))


def _check_dense(case: Dict[str, Any]) -> List[Finding]:
    uk = _ukflex()
    from ukflex.run.simulate import DenseSolution

    meta, data, parts = _dense_record(case["method"])
    meta, data, parts = meta.copy(), data.copy(), list(parts)
    method, t = case["method"], np.asarray(case["t"], dtype=float)
    m = case["mutation"]
    valid = m in ("none", "none_copy", "lower", "noncontig", "t_far")
    if m == "lower":
        method = method.lower()
    elif m == "drop_col":
        data = data[:, :-1]
    elif m == "add_col":
        data = np.hstack([data, data[:, :1]])
    elif m == "drop_row_meta":
        meta = meta[:-1] if len(meta) > 1 else meta[:0]
    elif m == "part_plus":
        parts[0] += 1
    elif m == "part_minus":
        parts[-1] -= 1
    elif m == "part_huge":
        parts = [2 ** 63] * len(parts)
    elif m == "part_neg":
        parts[0] = -1
    elif m == "part_count":
        parts = parts[:-1]
    elif m == "part_empty":
        parts = []
    elif m == "meta_cols":
        meta = meta[:, :2]
    elif m == "nan_data":
        data[len(data) // 2, 0] = np.nan
    elif m == "inf_meta":
        meta[0, 1] = np.inf
    elif m == "reverse":
        meta, data = meta[::-1].copy(), data[::-1].copy()
        valid = len(meta) == 1
    elif m == "swap_methods":
        method = case["other"]
        valid = _dense_record(case["other"])[2] == parts
    elif m == "empty":
        meta, data = meta[:0], data[:0]
    elif m == "object":
        data = data.astype(object)
    elif m == "complex":
        data = data + 0j
    elif m == "noncontig":
        data = np.repeat(data, 2, axis=1)[:, ::2]
    elif m == "t_nan":
        t = np.append(t, np.nan)
    elif m == "t_far":
        t = np.append(t, 1e300)
    elif m == "t_2d":
        t = t.reshape(1, -1)
    elif m == "t_str":
        t = np.array(["0.01"])
    elif m == "unknown_method":
        method = "RK45"
    elif m == "one_dim":
        data = data.ravel()
    with _quiet():
        try:
            if case["api"] == "core":
                out = np.asarray(uk._core.dense_eval(method, meta, data, parts, t))
            else:
                out = np.asarray(DenseSolution(method, meta, data, parts)(t))
        except BaseException as exc:  # noqa: BLE001
            found = _classify(exc, ["dense", "meta", "data", "part_len", "t", "method", "native method", "'"],
                              f"dense_eval ({m}): ")
            if not found and valid and m != "t_far":
                found = [("wrong", f"a consistent record refused ({m}): {_exc(exc)}")]
            return found
    if not _finite(out):
        return [("silent-nonfinite", f"dense output ({m}) returned non-finite values")]
    if not valid:
        return [("wrong", f"dense output accepted an inconsistent record ({m}): shape {out.shape}")]
    if m in ("none_copy", "lower", "noncontig"):
        ref = np.asarray(uk._core.dense_eval(case["method"], *_dense_record(case["method"])[:2],
                                              _dense_record(case["method"])[2], t))
        if not np.array_equal(out, ref):
            return [("wrong", f"dense output ({m}) differs from the original record's by {_max_abs(out - ref):.3g}")]
    return []


# ============================================================================== pickles
_PICKLE_ENTRIES = ["description", "build_options", "settings", "t0", "q_guess", "qd_guess", "q0", "qd0",
                   "initial_correction", "core_options", "__new__"]


def _deep(k: int) -> Any:
    x: Any = []
    for _ in range(k):
        x = [x]
    return x


def _made(value: Any) -> Any:
    """A drawn value, with ``("deep", k)`` made into lists nested ``k`` deep here (hypothesis and
    the runner print every case: a drawn 2000-deep list would not print)."""
    if isinstance(value, tuple) and len(value) == 2 and value[0] == "deep":
        return _deep(value[1])
    if isinstance(value, dict):
        return {k: _made(v) for k, v in value.items()}
    return value


@st.composite
def _pickle_case(draw):
    target = draw(st.sampled_from(["system", "system", "scene"]))
    base = draw(st.sampled_from(["pendulum", "slider_crank"]))
    if target == "scene":
        section = draw(st.sampled_from(["bodies", "bodies", "joints", "gravity", "__top__"]))
        value = draw(st.one_of(hostile(), st.just(("deep", 2000)),
                               st.sampled_from([("deep", 70), {"kind": "nope"}, [None], "x"])))
        return dict(target=target, base=base, entry=section, action="replace", value=value)
    entry = draw(st.sampled_from(_PICKLE_ENTRIES))
    action = draw(st.sampled_from(["delete", "replace", "replace", "shape", "keep"]))
    value = draw(st.one_of(hostile(), st.sampled_from([
        {}, {"nope": ()}, {"set_stabilization": ("x",)}, {"set_stabilization": "baumgarte"},
        {"set_rank_tolerance": (None, -1.0)}, {"uk_solver": "nope"}, {"memory_limit": -5.0}, np.zeros(7),
        np.full(3, np.nan), [1.0, 2.0], ("deep", 2000), {"bodies": []}, {"bodies": "x"}, {"bodies": ("deep", 3000)}])))
    return dict(target=target, base=base, entry=entry, action=action, value=value)


def _check_pickle(case: Dict[str, Any]) -> List[Finding]:
    uk = _ukflex()
    src = {"pendulum": lambda: uk.scenes.pendulum(), "slider_crank": lambda: uk.scenes.slider_crank()}[case["base"]]()
    entry, action, value = case["entry"], case["action"], _made(case["value"])
    with _quiet():
        if case["target"] == "scene":
            state = src.__getstate__()
            if entry == "__top__":
                state["extra_key"] = value
            elif entry == "gravity":
                state["gravity"] = value
            elif state.get(entry):  # a property of the first item
                state[entry][0][sorted(state[entry][0])[0] if entry == "joints" else "mass"] = value
            else:
                state[entry] = value
            try:
                new = uk.Scene.__new__(uk.Scene)
                new.__setstate__(state)
            except BaseException as exc:  # noqa: BLE001
                return _classify(exc, ["scene", "state", entry], "Scene state: ")
            return []
        system = _system(case["base"])
        state = dict(system.__getstate__())
        if action == "delete":
            state.pop(entry, None)
        elif action == "shape" and entry in ("q_guess", "qd_guess", "q0", "qd0"):
            state[entry] = np.append(np.asarray(state[entry]), 0.0)
        elif action in ("replace", "shape") and entry == "description" and isinstance(value, list):
            state[entry] = dict(state[entry], bodies=[dict(state[entry]["bodies"][0], mass=value)])
        elif action in ("replace", "shape"):
            state[entry] = value
        tampered = action != "keep"
        try:
            restored = pickle.loads(pickle.dumps(state))
        except RecursionError:  # pickle itself cannot nest that deep: hand the state over as it is
            restored = state
        try:
            new = uk.System.__new__(uk.System)
            new.__setstate__(restored)
        except BaseException as exc:  # noqa: BLE001
            found = _classify(exc, ["state", entry, "pickle"], "System state: ")
            if not tampered and not found:
                found = [("wrong", f"an untouched state refused: {_exc(exc)}")]
            return found
    if entry in ("q_guess", "qd_guess", "q0", "qd0") and tampered:
        arr = np.asarray(getattr(new, entry))
        if arr.shape != (new.n_coords,) or not _finite(arr):
            return [("wrong", f"a pickle state with {entry} = {_short(value)} ({action}) was accepted")]
    if entry == "settings" and tampered and isinstance(value, dict) and any(k not in new.SETTINGS for k in value):
        return [("wrong", f"a pickle state with settings {_short(value)} was accepted")]
    try:
        out = new.qdd(new.t0, new.q0, new.qd0)
    except BaseException as exc:  # noqa: BLE001
        return _classify(exc, [], "restored System: ")
    if not _finite(out):
        return [("silent-nonfinite", "the restored System's qdd at its initial state is not finite")]
    return []


# ============================================================================== finite-element input
_FE_FIELDS = {"thickness": 0.01, "density": 7800.0, "youngs_modulus": 2e11, "poisson_ratio": 0.3, "modes": 2,
              "damping_ratio": 0.0, "order": 1}
_FE_SPECIAL = {
    "poisson_ratio": [0.5, 0.4999999, -0.999, -1.0, 0.6, 1.0, -2.0],
    "modes": [0, -1, 1.5, 10 ** 30, "2", 100, True],
    "order": [0, 3, 1.0, "1", None],
    "cells": ["out_of_range", "negative", "float", "repeat", "shape", "empty", "strings", "nan"],
    "points": ["nan", "shape", "collinear", "strings", "huge"],
    "interfaces": ["float", "out_of_range", "empty", "callable_bad", "not_dict", "bool_mask"],
    "frame": ["short", "junk", "names", "word"],
    "reduce": ["none", "int", "modes", "damping", "tol"],
}


@st.composite
def _fe_case(draw):
    field = draw(st.sampled_from(sorted(_FE_FIELDS) + ["cells", "points", "interfaces", "frame", "reduce", "none"]))
    if field in ("cells", "points", "interfaces", "frame", "reduce"):
        value = draw(st.sampled_from(_FE_SPECIAL[field]))
    elif field == "none":
        value = None
    else:
        value = draw(st.one_of(st.sampled_from(_FE_SPECIAL.get(field, [])) if field in _FE_SPECIAL else hostile(),
                               hostile()))
    return dict(field=field, value=value, quads=draw(st.booleans()), frame=draw(st.sampled_from(["mean-axis", "pinned-pinned"])))


def _fe_mesh(quads: bool) -> Tuple[np.ndarray, np.ndarray]:
    """A 3 x 2 cell strip (a slender part): points (N, 2) and cells."""
    xs, ys = np.linspace(0.0, 0.3, 4), np.linspace(0.0, 0.05, 3)
    pts = np.array([(x, y) for y in ys for x in xs])
    quad = [[j * 4 + i, j * 4 + i + 1, (j + 1) * 4 + i + 1, (j + 1) * 4 + i] for j in range(2) for i in range(3)]
    if quads:
        return pts, np.array(quad)
    return pts, np.array([c for q in quad for c in ([q[0], q[1], q[2]], [q[0], q[2], q[3]])])


def _fe_acceptable(field: str, value: Any) -> bool:
    """Whether a material or reduction argument is one the API must take."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        return False
    try:
        x = float(value)
    except OverflowError:
        return False
    if not math.isfinite(x):
        return False
    if field == "poisson_ratio":
        return -1.0 < x <= 0.5
    if field == "damping_ratio":
        return x >= 0.0
    if field == "modes":
        return x.is_integer() and 1 <= x <= 3  # the strip of 12 nodes leaves a few elastic modes
    if field == "order":
        return x in (1.0, 2.0)
    return x > 0.0


def _check_fe(case: Dict[str, Any]) -> List[Finding]:
    try:
        from ukflex import fe
        import skfem  # noqa: F401
    except ImportError:
        return []
    uk = _ukflex()
    pts, cells = _fe_mesh(case["quads"])
    kw: Dict[str, Any] = dict(_FE_FIELDS, cells=cells, interfaces={"A": [0, 4, 8], "B": [3, 7, 11]}, frame=case["frame"])
    field, value = case["field"], case["value"]
    hostile_in = field != "none"
    if field in _FE_FIELDS:
        kw[field] = value
        hostile_in = not _fe_acceptable(field, value)
    elif field == "cells":
        c = cells.copy()
        kw["cells"] = {"out_of_range": np.vstack([c, [[0, 1, 99] + ([0] if case["quads"] else [])]]),
                       "negative": np.where(c == c.max(), -1, c), "float": c + 0.5, "repeat": np.where(c == c[0, 1], c[0, 0], c),
                       "shape": c[:, :2], "empty": np.zeros((0, c.shape[1]), int), "strings": c.astype(str),
                       "nan": np.where(c == 0, np.nan, c)}[value]
    elif field == "points":
        kw_pts = {"nan": np.where(pts == pts.max(), np.nan, pts), "shape": pts[:, :1], "collinear": np.column_stack([pts[:, 0], 0 * pts[:, 1]]),
                  "strings": pts.astype(str), "huge": pts * 1e300}[value]
        pts = kw_pts
    elif field == "interfaces":
        kw["interfaces"] = {"float": {"A": [0.5, 4]}, "out_of_range": {"A": [0, 400]}, "empty": {"A": []},
                            "callable_bad": {"A": lambda p: "x"}, "not_dict": [0, 1],
                            "bool_mask": {"A": lambda p: np.array([True, False])}}[value]
    elif field == "frame":
        kw["frame"] = {"short": [("A", "x")], "junk": 5, "names": [("Z", "x"), ("A", "q"), ("B", "y")], "word": "fixed"}[value]
    with _quiet():
        try:
            data = fe.from_mesh(pts, **kw)
            if field == "reduce":
                target = {"none": None, "int": 3, "modes": data, "damping": data, "tol": data}[value]
                rkw = {"modes": {"modes": 0, "damping": 1, "tol": 1}.get(value, 1),
                       "damping_ratio": "x" if value == "damping" else 0.0}
                if value == "tol":
                    rkw["tol"] = -1.0
                data = fe.reduce(target, **rkw)
        except BaseException as exc:  # noqa: BLE001
            names = ["mesh", "cells", "points", "interfaces", "frame", "reduction", "data", "modes", "damping_ratio", "tol",
                     "order", "thickness", "density", "youngs_modulus", "poisson_ratio", "stiffness_matrix", "mass_matrix"]
            return _classify(exc, names, f"fe ({field}): ")
    if hostile_in:
        return [("wrong", f"fe accepted {field} = {_short(value)}")]
    freq = np.asarray(data.info.get("frequencies", []))
    if not (_finite(freq, data.k_ff, data.m_ff, data.s_bar) and np.all(freq >= 0) and data.mass > 0):
        return [("silent-nonfinite", f"fe ({field}): invariants not finite or frequencies negative")]
    return []


# ============================================================================== sweeps
class _Unprintable(Exception):
    def __str__(self) -> str:  # a user's exception whose message cannot be shown
        raise RuntimeError("no message")


def _sweep_build(kind: str):
    uk = _ukflex()

    def build(**case):
        if kind == "ok":
            return uk.scenes.pendulum(), {"method": "DOPRI5"}
        if kind == "raise_value":
            raise ValueError("a bad case")
        if kind == "raise_zero":
            return 1 / 0
        if kind == "raise_key":
            return {}["missing"]
        if kind == "raise_recursion":
            def f(n):
                return f(n + 1)
            return f(0)
        if kind == "raise_memory":
            raise MemoryError()
        if kind == "raise_unprintable":
            raise _Unprintable()
        if kind == "none":
            return None
        if kind == "int":
            return 3
        if kind == "tuple1":
            return (uk.scenes.pendulum(),)
        if kind == "bad_options":
            return uk.scenes.pendulum(), "x"
        if kind == "bad_t_end":
            return uk.scenes.pendulum(), {"t_end": "x"}
        if kind == "slow":
            time.sleep(0.05)
            return uk.scenes.pendulum(), {"method": "DOPRI5"}
        if kind == "long_run":  # a run far longer than the case's budget: bounded by max_wall_time
            return uk.scenes.pendulum(), {"t_end": 1e7, "method": "RK45", "max_wall_time": 0.3}
        raise AssertionError(kind)

    return build


def _sweep_outputs(kind: str):
    def outputs(res):
        if kind == "ok":
            return {"theta": float(res.coordinate("rod.theta")[-1])}
        if kind == "raise":
            raise ZeroDivisionError("in outputs")
        if kind == "array":
            return {"x": np.ones(3)}
        if kind == "nan":
            return {"x": float("nan")}
        if kind == "not_dict":
            return [1, 2]
        return {"status": 1}  # clashes with a result column

    return outputs


@st.composite
def _sweep_case(draw):
    grid_kind = draw(st.sampled_from(["small", "small", "small", "list", "huge", "huge_range", "junk"]))
    if grid_kind == "small":
        grid = {"a": list(range(draw(st.integers(1, 3)))), "b": draw(st.sampled_from([[0.5], [1, 2], "fixed"]))}
    elif grid_kind == "list":
        grid = [{"a": k} for k in range(draw(st.integers(1, 3)))]
    elif grid_kind == "huge":
        grid = {k: list(range(draw(st.sampled_from([101, 1000])))) for k in "abc"}  # > 10**6 cases
    elif grid_kind == "huge_range":
        grid = {"a": range(10 ** draw(st.integers(7, 15)))}
    else:
        grid = draw(st.sampled_from([{}, [], "ab", None, {"not a name": [1]}, {"status": [1]}, {"a": []}, [1], {1: [2]},
                                     {"a": [1]}.items(), [{"a": 1}, 5]]))
    huge = grid_kind in ("huge", "huge_range")
    return dict(grid_kind=grid_kind, grid=grid,
                build=draw(st.sampled_from(["ok", "ok", "raise_value", "raise_zero", "raise_key", "raise_recursion",
                                            "raise_memory", "raise_unprintable", "none", "int", "tuple1", "bad_options",
                                            "bad_t_end", "slow", "long_run"])),
                outputs=draw(st.sampled_from(["ok", "ok", "raise", "array", "nan", "not_dict", "clash"])),
                max_cases=draw(st.sampled_from([None, None, 10, 0, -1, 1.5, "x"] + ([] if huge else [10 ** 30]))),
                executor=draw(st.sampled_from(["serial"] * 9 + ["processes"])))


def _check_sweep(case: Dict[str, Any]) -> List[Finding]:
    uk = _ukflex()
    try:
        import pandas  # noqa: F401
    except ImportError:
        return []
    kw: Dict[str, Any] = dict(t_end=0.005)
    if case["max_cases"] is not None:
        kw["max_cases"] = case["max_cases"]
    if case["executor"] == "processes":
        kw["workers"] = 2
    tic = time.perf_counter()
    with _quiet():
        try:
            df = uk.sweep(_sweep_build(case["build"]), case["grid"], _sweep_outputs(case["outputs"]), case["executor"],
                          progress=False, **kw)
        except BaseException as exc:  # noqa: BLE001
            wall = time.perf_counter() - tic
            found = _classify(exc, ["grid", "max_cases", "sweep", "executor", "workers"], "sweep: ")
            if wall > 3.0 and case["grid_kind"] in ("huge", "huge_range"):
                found.append(("wrong", f"{wall:.1f} s to refuse a grid beyond max_cases (generated before refused?)"))
            return found
    wall = time.perf_counter() - tic
    if case["grid_kind"] in ("huge", "huge_range") and (case["max_cases"] in (None, 10) or isinstance(case["max_cases"], int)):
        limit = 10 ** 6 if case["max_cases"] is None else case["max_cases"]
        if isinstance(limit, int) and limit >= 1 and len(df) > limit:
            return [("wrong", f"a grid of {len(df)} cases ran, beyond max_cases = {limit}")]
    if case["max_cases"] in (0, -1, 1.5, "x"):
        return [("wrong", f"sweep accepted max_cases = {case['max_cases']!r}")]
    if case["grid_kind"] == "junk":
        return [("wrong", f"sweep accepted the grid {_short(case['grid'])}")]
    findings: List[Finding] = []
    if not set(df["status"]) <= {"ok", "unfinished", "failed"}:
        findings.append(("wrong", f"sweep statuses {sorted(set(df['status']))}"))
    failed = df[df["status"] == "failed"]
    if any(not isinstance(e, str) or not e.strip() for e in failed["error"]):
        findings.append(("wrong", "a failed case without an error message"))
    if case["build"] == "long_run" and wall > 20.0:
        findings.append(("wrong", f"the case's max_wall_time 0.3 s did not bound it ({wall:.1f} s)"))
    return findings


# ============================================================================== per-call methods at extreme states
_EXTREME_SYSTEMS = ["pendulum", "slider_crank_nl", "cantilever_ancf", "driven_point", "every_joint"]
_EXTREME_METHODS = ["qdd", "rhs", "Q", "phi", "phi_t", "b", "multipliers", "residuals", "residual_norms", "project",
                    "project_step", "kinetic_energy", "potential_energy", "jac", "tangent_stiffness", "axial_forces",
                    "beam_point", "beam_internal_forces", "sensors", "rank_info", "linearization", "tangent_project",
                    "material_energies", "M", "A", "dense_eval"]


def _extreme_system(name: str):
    uk = _ukflex()
    key = "x:" + name
    from .common import _SYSTEMS

    if key not in _SYSTEMS:
        if name == "slider_crank_nl":
            s = uk.System(uk.scenes.slider_crank(elements=2, strain="nonlinear"))
        elif name == "driven_point":
            sc = uk.Scene()
            p = sc.point_mass("p", mass=1.0)
            sc.coordinate_driver(p.point(), "x", "2*t + t^2/(1 + t^2)", name="drive")
            s = uk.System(sc)
        else:
            s = _system(name)
        _SYSTEMS[key] = s
    return _SYSTEMS[key]


@st.composite
def _extreme_case(draw):
    t = draw(st.one_of(st.sampled_from([0.0, 1e308, -1e308, 1e300, -1e150, 1e150, 1e20, float("nan"), float("inf"),
                                        10 ** 400]), st.floats(0.0, 1.0)))
    scale = draw(st.sampled_from([0.0, 1.0, 1e150, -1e150, 1e300, 1e308, -1e308, 1e-300]))
    mode = draw(st.sampled_from(["q_all", "q_one", "qd_all", "qd_one", "zero_q", "t_only"]))
    return dict(system=draw(st.sampled_from(_EXTREME_SYSTEMS)), method=draw(st.sampled_from(_EXTREME_METHODS)),
                t=t, scale=scale, mode=mode, index=draw(st.integers(0, 10 ** 6)))


def _check_extreme(case: Dict[str, Any]) -> List[Finding]:
    uk = _ukflex()
    s = _extreme_system(case["system"])
    n = s.n_coords
    q, qd = np.array(s.q0, dtype=float), np.array(s.qd0, dtype=float)
    mode, scale, i = case["mode"], case["scale"], case["index"] % n
    if mode == "q_all":
        q = q * scale if scale else q
    elif mode == "q_one":
        q[i] = scale
    elif mode == "qd_all":
        qd = np.full(n, scale)
    elif mode == "qd_one":
        qd[i] = scale
    elif mode == "zero_q":
        q = np.zeros(n)
    t = case["t"]
    beams = [b for b in s.body_names if s.capabilities(b)["beam"]]
    beam = beams[0] if beams else s.body_names[0]
    m = case["method"]
    calls = {
        "qdd": lambda: s.qdd(t, q, qd), "rhs": lambda: s.rhs(t, np.concatenate([q, qd])), "Q": lambda: s.Q(t, q, qd),
        "phi": lambda: s.phi(t, q), "phi_t": lambda: s.phi_t(t), "b": lambda: s.b(t, q, qd),
        "multipliers": lambda: s.multipliers(t, q, qd), "residuals": lambda: s.residuals(t, q, qd),
        "residual_norms": lambda: s.core.residual_norms([t, 0.0], np.column_stack([q, s.q0]), np.column_stack([qd, s.qd0])),
        "project": lambda: s.project(t, q, qd), "project_step": lambda: s.core.project_step(t, q, qd, 1e-10),
        "kinetic_energy": lambda: s.kinetic_energy(q, qd), "potential_energy": lambda: s.potential_energy(q),
        "jac": lambda: s.jac(t, np.concatenate([q, qd])), "tangent_stiffness": lambda: s.tangent_stiffness(beam, q),
        "axial_forces": lambda: s.axial_forces(beam, q), "beam_point": lambda: s.beam_point(beam, 0.5, q),
        "beam_internal_forces": lambda: s.core.beam_internal_forces(beam, np.array([0.0, 0.5, 1.0]), q[None, :]),
        "sensors": lambda: _sensor_arrays(s.core.sensors([t], q[None, :], qd[None, :])),
        "rank_info": lambda: _dict_arrays(s.rank_info(t, q, qd)),
        "linearization": lambda: _dict_arrays(s.core.linearization(t, q, qd)),
        "tangent_project": lambda: s.core.tangent_project(t, q, np.eye(n)[:, :2].copy()),
        "material_energies": lambda: s.core.material_energies(q, np.eye(n)[:, :2].copy()),
        "M": lambda: s.M(q), "A": lambda: s.A(q),
        "dense_eval": lambda: uk._core.dense_eval("DOPRI5", *_dense_record("DOPRI5")[:2], _dense_record("DOPRI5")[2], [t]),
    }
    with _quiet():
        try:
            out = calls[m]()
        except BaseException as exc:  # noqa: BLE001
            found = _classify(exc, ["t", "q", "qd", "y", "body", "'", "not a beam", "a beam"], f"{m}: ")
            return found
    outs = out if isinstance(out, tuple) else (out,)
    arrays = [a for o in outs if not isinstance(o, (bool, np.bool_))
              for a in (_dict_arrays(o) if isinstance(o, dict) else (np.asarray(o, dtype=float),))]
    if not _finite(*arrays):
        return [("silent-nonfinite", f"{m} returned non-finite values at t = {_short(t)}, {mode} x {scale:g}")]
    if not (isinstance(t, float) and math.isfinite(t)) and m not in ("M", "A", "kinetic_energy", "potential_energy",
                                                                     "tangent_stiffness", "axial_forces", "beam_point",
                                                                     "beam_internal_forces", "material_energies"):
        return [("wrong", f"{m} accepted t = {_short(t)}")]
    return []


def _dict_arrays(d: Dict[str, Any]) -> Tuple[np.ndarray, ...]:
    return tuple(np.asarray(v, dtype=float) for v in d.values()
                 if isinstance(v, (float, np.ndarray)) and not isinstance(v, bool))


def _sensor_arrays(d: Dict[str, Any]) -> Tuple[np.ndarray, ...]:
    return tuple(np.asarray(d[k], dtype=float) for k in ("reactions", "body_energies", "force_potentials",
                                                         "dissipation_power"))


# ============================================================================== unknown names
_RESULTS: Dict[str, Any] = {}


def _result(name: str):
    if name not in _RESULTS:
        uk = _ukflex()
        s = _extreme_system(name)
        with _quiet():
            _RESULTS[name] = uk.simulate(s, 0.002, method="DOPRI5", t_eval=np.linspace(0.0, 0.002, 3))
    return _RESULTS[name]


_NAME_CALLS = ["body_info", "body_kind", "elastic_range", "body_slice", "elastic_slice", "coordinate_index",
               "beam_point", "tangent_stiffness", "axial_forces", "beam_matrices", "beam_shape", "coordinate", "velocity",
               "max_residual", "residuals", "reaction", "body_energies", "driver_work", "internal_forces",
               "beam_displacement", "beam_properties"]


@st.composite
def _names_case(draw):
    return dict(system=draw(st.sampled_from(["pendulum", "slider_crank_nl", "cantilever_ancf", "driven_point"])),
                call=draw(st.sampled_from(_NAME_CALLS)),
                name=draw(st.one_of(st.sampled_from(["valid", "valid", "upper", "nope", "", "ground", "rod.theta",
                                                     "position", "pivot", "drive", "coupler", "beam"]),
                                    st.text(max_size=12), st.sampled_from([3, None, 1.5, b"rod", ["rod"]]))))


def _check_names(case: Dict[str, Any]) -> List[Finding]:
    uk = _ukflex()
    from ukflex import stability

    s = _extreme_system(case["system"])
    res = _result(case["system"])
    valid = {
        "body_info": s.body_names, "body_kind": s.body_names, "elastic_range": s.body_names, "body_slice": s.body_names,
        "elastic_slice": [b for b in s.body_names if s.core.elastic_range(b)[0] != s.core.elastic_range(b)[1]],
        "coordinate_index": s.coordinate_names, "coordinate": s.coordinate_names, "velocity": s.coordinate_names,
        "beam_point": s.body_names, "tangent_stiffness": s.body_names, "axial_forces": s.body_names,
        "beam_matrices": s.body_names, "beam_shape": s.body_names,
        "max_residual": ["position", "velocity", "acceleration"], "residuals": ["position", "velocity", "acceleration"],
        "reaction": list(s.core.constraint_items), "body_energies": s.body_names, "driver_work": list(s.core.driver_names),
        "internal_forces": s.body_names, "beam_displacement": s.body_names,
        "beam_properties": [b for b in s.body_names if s.body_kind(b) == "beam"],
    }[case["call"]]
    name = case["name"]
    if name == "valid":
        if not valid:
            return []
        name = valid[0]
    elif name == "upper" and valid:
        name = valid[0].upper()
    q = s.q0
    calls = {
        "body_info": lambda: s.body_info(name), "body_kind": lambda: s.body_kind(name),
        "elastic_range": lambda: s.core.elastic_range(name), "body_slice": lambda: s.body_slice(name),
        "elastic_slice": lambda: s.elastic_slice(name), "coordinate_index": lambda: s.coordinate_index(name),
        "beam_point": lambda: s.beam_point(name, 0.5, q), "tangent_stiffness": lambda: s.tangent_stiffness(name, q),
        "axial_forces": lambda: s.axial_forces(name, q), "beam_matrices": lambda: s.beam_matrices(name),
        "beam_shape": lambda: s.beam_shape(name, 0.5), "coordinate": lambda: res.coordinate(name),
        "velocity": lambda: res.velocity(name), "max_residual": lambda: res.max_residual(name),
        "residuals": lambda: res.residuals[name], "reaction": lambda: res.sensors.reaction(name),
        "body_energies": lambda: res.sensors.body_energies(name), "driver_work": lambda: res.sensors.driver_work(name),
        "internal_forces": lambda: res.sensors.internal_forces(name, [0.5]),
        "beam_displacement": lambda: res.beam_displacement(name, 0.5),
        "beam_properties": lambda: stability.beam_properties(s, name),
    }
    with _quiet():
        try:
            calls[case["call"]]()
        except BaseException as exc:  # noqa: BLE001
            if _panic(exc):
                return [("panic", _exc(exc))]
            if isinstance(name, str) and name not in valid:
                if not isinstance(exc, uk.UnknownNameError):
                    if isinstance(exc, (uk.UkflexError, ValueError)) and "beam" in str(exc):
                        return []  # a body that exists but is not a beam: said so
                    return [("unnamed-exception", f"{case['call']}({name!r}): {_exc(exc)} (not an UnknownNameError)")]
                if valid and not any(v in str(exc) for v in valid[:20]):
                    return [("wrong", f"{case['call']}({name!r}): the message lists no valid name: {str(exc)[:200]}")]
                return []
            if not isinstance(name, str):
                return _classify(exc, ["body", "name", "'", "str", "kind", "joint", "driver", "coordinate"],
                                 f"{case['call']}({name!r}): ")
            # a valid name of the wrong kind (not a beam, no elastic coordinates): named and said
            return _classify(exc, ["beam", "elastic", "not a", "kind"], f"{case['call']}({name!r}): ")
    if isinstance(name, str) and name not in valid:
        return [("wrong", f"{case['call']}({name!r}) accepted an unknown name")]
    return []


# ============================================================================== built-in scene functions
_BUILDERS = {"chain": ["links", "length", "mass", "angle"], "rope": ["links", "length", "mass", "span"],
             "lattice": ["columns", "rows", "cell", "mass", "shear"], "n_four_bar": ["loops", "angle", "velocity", "link"],
             "pendulum": ["mass", "length", "angle", "angular_velocity"], "four_bar": ["crank_length", "rocker_length"],
             "spline": ["times", "values", "slopes"], "event": ["terminal", "direction"],
             "simulate": ["max_steps", "max_nfev", "max_steps", "max_nfev", "max_wall_time", "min_step", "first_step",
                          "max_step"]}


@st.composite
def _builder_case(draw):
    fn = draw(st.sampled_from(sorted(_BUILDERS) + ["simulate"]))  # simulate twice as often: it has budgets
    arg = draw(st.sampled_from(_BUILDERS[fn]))
    value = draw(st.one_of(hostile(), st.sampled_from([1e300, -1e300, 1e-300, 0, -3, 2 ** 70, 10 ** 23, 5, "x",
                                                       [1.0, 2.0]])))
    if fn == "simulate" and draw(st.booleans()):  # budgets beyond any machine word
        value = draw(st.sampled_from([10 ** 23, 2 ** 64, 2 ** 70, 10 ** 30, 1.5e19, 1e300]))
    return dict(fn=fn, arg=arg, value=value, method=draw(st.sampled_from(["DOPRI5", "RADAU5M", "RK45"])))


def _check_builder(case: Dict[str, Any]) -> List[Finding]:
    uk = _ukflex()
    fn, arg, value = case["fn"], case["arg"], case["value"]
    with _quiet():
        try:
            if fn == "spline":
                kw: Dict[str, Any] = dict(times=[0.0, 0.5, 1.0], values=[0.0, 0.2, 0.1], slopes=None)
                kw[arg] = value
                sc = uk.Scene()
                p = sc.point_mass("p", mass=1.0)
                sc.coordinate_driver(p.point(), "x", uk.Spline(**kw))
                uk.System(sc)
            elif fn == "simulate":  # budgets and steps beyond any run, or not numbers at all
                uk.simulate(_system("pendulum"), 0.002, method=case.get("method", "DOPRI5"), **{arg: value})
            elif fn == "event":
                def ev(t, y):
                    return y[0] - 10.0
                setattr(ev, arg, value)
                uk.simulate(_system("pendulum"), 0.01, method="DOPRI5", events=[ev])
            else:
                system = uk.System(getattr(uk.scenes, fn)(**{arg: value}))
                if not _finite(system.q0, system.qd0):
                    return [("silent-nonfinite", f"{fn}({arg}={_short(value)}): q0 not finite")]
        except BaseException as exc:  # noqa: BLE001
            return _classify(exc, [arg, fn], f"{fn}({arg}={_short(value)}): ")
    return []


SURFACES: List[Category] = [
    Category("expr", _expr_case, _check_expr,
             "expressions: values and both derivatives against SymPy, deep/long/huge texts, scaling identities"),
    Category("spline", _spline_case, _check_spline, "spline motions against scipy's CubicSpline, hostile tables"),
    Category("dense", _dense_case, _check_dense, "DenseSolution / dense_eval with inconsistent records and times"),
    Category("pickle", _pickle_case, _check_pickle, "Scene and System pickle states, tampered"),
    Category("fe", _fe_case, _check_fe, "fe.from_mesh and fe.reduce inputs"),
    Category("sweep", _sweep_case, _check_sweep, "sweep grids, max_cases, build/outputs functions that raise or run long"),
    Category("extremes", _extreme_case, _check_extreme, "per-call methods at extreme t, q, qd"),
    Category("names", _names_case, _check_names, "methods that take names, given unknown ones"),
    Category("builders", _builder_case, _check_builder, "built-in scene functions, Spline and events with hostile arguments"),
]

#: weights of the new categories in a mixed run (fe and sweep cases cost the most)
SURFACE_WEIGHTS = {"expr": 4, "spline": 2, "dense": 2, "pickle": 2, "fe": 1, "sweep": 1, "extremes": 3, "names": 2,
                   "builders": 2}

__all__ = ["SURFACES", "SURFACE_WEIGHTS", "EXTREME_FLOATS", "WRONG_TYPES"]
