"""The expression evaluator before issue 28, ported to Python for the seeded regressions
(:mod:`fuzz.regressions`): a recursive-descent parser, derivatives by the textbook rules with
constant folding, evaluation by recursion.  Each old defect can be put back alone:

* ``recursion``: parse and evaluate by recursion with no depth limit (the core segfaulted; here
  Python's ``RecursionError`` escapes);
* ``sign_nan``: ``sign(NaN) = 0`` (``sign(log(t - 1))`` ran as a motion ``x = 0``);
* ``quotient``: ``(a/b)' = (a'b - ab')/b^2`` (underflows for operands of 1e-170);
* ``trees``: derivatives as trees without sharing (exponential for towers); past 5 million
  nodes the process aborts, as the core did on its 6 GB allocation.

Without a defect it computes what the core computes now, so one regression shows one defect.
"""

from __future__ import annotations

import math
import os
import sys
from typing import Any, Dict, Tuple

import numpy as np

Node = Tuple[Any, ...]

_FUNCS = {"sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "log": np.log, "sqrt": np.sqrt, "abs": np.abs,
          "tanh": np.tanh, "sinh": np.sinh, "cosh": np.cosh, "atan": np.arctan, "sign": None}


class ParseError(Exception):
    def __init__(self, message: str, position: int):
        super().__init__(message)
        self.position = position


def _apply(f: str, x: float, sign_nan: bool) -> float:
    """IEEE semantics (NumPy doubles), as the core's ``f64`` methods."""
    if f == "sign":
        if x > 0:
            return 1.0
        if x < 0:
            return -1.0
        return 0.0 if (x == 0 or sign_nan) else math.nan
    return float(_FUNCS[f](np.float64(x)))


def _pow(x: float, y: float) -> float:
    """``x^y`` as the core: ``powi`` for integer exponents up to 64, else ``powf`` (IEEE)."""
    return float(np.float64(x) ** np.float64(y))


class OldExpr:
    def __init__(self, text: str, *, recursion: bool = False, sign_nan: bool = False, quotient: bool = False,
                 trees: bool = False):
        self.chars, self.pos = text, 0
        self.sign_nan, self.quotient, self.trees = sign_nan, quotient, trees
        self.nodes = 0
        self.consts: Dict[int, Tuple[bool, Node]] = {}  # id -> (constant?, the node, kept alive)
        limit = sys.getrecursionlimit()
        if not recursion:  # Python 3.11 recursion costs no C stack: only the core's old crash is left out
            sys.setrecursionlimit(max(limit, 400_000))
        try:
            self.root = self._parse_all()
            self.memo: Dict[int, Node] = {}
            self.d1 = self._derive(self.root)
            self.memo = {}
            self.d2 = self._derive(self.d1)
        finally:
            sys.setrecursionlimit(limit)

    # --------------------------------------------------------------------------------- build
    def _node(self, *n: Any) -> Node:
        self.nodes += 1
        if self.trees and self.nodes > 5_000_000:
            os.abort()  # the core: "memory allocation of 6442450944 bytes failed", then abort
        return n

    @staticmethod
    def _num(n: Node):
        return n[1] if n[0] == "num" else None

    def num(self, v: float) -> Node:
        return self._node("num", float(v))

    def add(self, a: Node, b: Node) -> Node:
        x, y = self._num(a), self._num(b)
        if x is not None and y is not None:
            return self.num(np.float64(x) + y)
        if x == 0.0:
            return b
        if y == 0.0:
            return a
        return self._node("+", a, b)

    def sub(self, a: Node, b: Node) -> Node:
        x, y = self._num(a), self._num(b)
        if x is not None and y is not None:
            return self.num(np.float64(x) - y)
        if x == 0.0:
            return self.neg(b)
        if y == 0.0:
            return a
        return self._node("-", a, b)

    def mul(self, a: Node, b: Node) -> Node:
        x, y = self._num(a), self._num(b)
        if x is not None and y is not None:
            return self.num(np.float64(x) * y)
        if x == 0.0 or y == 0.0:
            return self.num(0.0)
        if x == 1.0:
            return b
        if y == 1.0:
            return a
        return self._node("*", a, b)

    def exact_mul(self, a: Node, b: Node) -> Node:
        """``a * b`` as written (the parser's, as the core's now: no 0 * x = 0)."""
        x, y = self._num(a), self._num(b)
        if x is not None and y is not None:
            return self.num(np.float64(x) * y)
        return b if x == 1.0 else a if y == 1.0 else self._node("*", a, b)

    def exact_div(self, a: Node, b: Node) -> Node:
        """``a / b`` as written (no 0 / x = 0)."""
        x, y = self._num(a), self._num(b)
        if x is not None and y is not None and y != 0.0:
            return self.num(np.float64(x) / y)
        return a if y == 1.0 else self._node("/", a, b)

    def div(self, a: Node, b: Node) -> Node:
        x, y = self._num(a), self._num(b)
        if x is not None and y is not None and y != 0.0:
            return self.num(np.float64(x) / y)
        if x == 0.0 and y is None:
            return self.num(0.0)
        if y == 1.0:
            return a
        return self._node("/", a, b)

    def neg(self, a: Node) -> Node:
        if a[0] == "num":
            return self.num(-a[1])
        if a[0] == "neg":
            return a[1]
        return self._node("neg", a)

    def pw(self, a: Node, b: Node) -> Node:
        x, y = self._num(a), self._num(b)
        if x is not None and y is not None:
            return self.num(_pow(x, y))
        if y == 0.0:
            return self.num(1.0)
        if y == 1.0:
            return a
        return self._node("^", a, b)

    def call(self, f: str, a: Node) -> Node:
        x = self._num(a)
        return self.num(_apply(f, x, self.sign_nan)) if x is not None else self._node("call", f, a)

    def _const(self, n: Node) -> bool:
        """No t in it (the core forms 0 for such a part's derivative); memoized by node."""
        key = id(n)
        if key not in self.consts:
            if n[0] in ("num", "t"):
                self.consts[key] = (n[0] == "num", n)
            else:
                self.consts[key] = (all(self._const(c) for c in n[1:] if isinstance(c, tuple)), n)
        return self.consts[key][0]

    def _derive(self, n: Node) -> Node:
        key = id(n)
        if not self.trees and key in self.memo:
            return self.memo[key]
        d = self._rule(n)
        if not self.trees:
            self.memo[key] = d
        return d

    def _rule(self, n: Node) -> Node:
        k = n[0]
        if k == "num" or (not self.trees and self._const(n)):
            return self.num(0.0)
        if k == "t":
            return self.num(1.0)
        if k == "neg":
            return self.neg(self._derive(n[1]))
        if k in ("+", "-"):
            da, db = self._derive(n[1]), self._derive(n[2])
            return self.add(da, db) if k == "+" else self.sub(da, db)
        if k == "*":
            a, b = n[1], n[2]
            return self.add(self.mul(self._derive(a), b), self.mul(a, self._derive(b)))
        if k == "/":
            a, b = n[1], n[2]
            da, db = self._derive(a), self._derive(b)
            if self.quotient:
                return self.div(self.sub(self.mul(da, b), self.mul(a, db)), self.pw(b, self.num(2.0)))
            return self.sub(self.div(da, b), self.mul(n, self.div(db, b)))
        if k == "^":
            a, b = n[1], n[2]
            da = self._derive(a)
            c = self._num(b)
            if c is not None:
                return self.mul(self.mul(self.num(c), self.pw(a, self.num(c - 1.0))), da)
            db = self._derive(b)
            return self.mul(n, self.add(self.mul(db, self.call("log", a)), self.mul(b, self.div(da, a))))
        f, a = n[1], n[2]
        da = self._derive(a)
        if f == "log":
            return self.div(da, a)
        if f == "sqrt":
            return self.div(da, self.mul(self.num(2.0), n))
        if f == "atan":
            return self.div(da, self.add(self.num(1.0), self.pw(a, self.num(2.0))))
        outer = {"sin": lambda: self.call("cos", a), "cos": lambda: self.neg(self.call("sin", a)),
                 "tan": lambda: self.add(self.num(1.0), self.pw(n, self.num(2.0))),
                 "tanh": lambda: self.sub(self.num(1.0), self.pw(n, self.num(2.0))), "exp": lambda: n,
                 "abs": lambda: self.call("sign", a), "sinh": lambda: self.call("cosh", a),
                 "cosh": lambda: self.call("sinh", a), "sign": lambda: self.num(0.0)}[f]()
        return self.mul(outer, da)

    # --------------------------------------------------------------------------------- evaluate
    def eval(self, t: float) -> Tuple[float, float, float]:
        cache: Dict[int, float] = {}
        limit = sys.getrecursionlimit()
        sys.setrecursionlimit(max(limit, 400_000))
        try:
            with np.errstate(all="ignore"):
                return self._value(self.root, t, cache), self._value(self.d1, t, cache), self._value(self.d2, t, cache)
        finally:
            sys.setrecursionlimit(limit)

    def _value(self, n: Node, t: float, cache: Dict[int, float]) -> float:
        key = id(n)
        if key in cache:
            return cache[key]
        k = n[0]
        if k == "num":
            v = n[1]
        elif k == "t":
            v = t
        elif k == "neg":
            v = -self._value(n[1], t, cache)
        elif k == "call":
            v = _apply(n[1], self._value(n[2], t, cache), self.sign_nan)
        else:
            a, b = self._value(n[1], t, cache), self._value(n[2], t, cache)
            a, b = np.float64(a), np.float64(b)
            if k == "+":
                v = float(a + b)
            elif k == "-":
                v = float(a - b)
            elif k == "*":
                v = float(a * b)
            elif k == "/":
                v = float(a / b)
            else:
                v = _pow(a, b)
        cache[key] = v
        return v

    # --------------------------------------------------------------------------------- parse
    def _err(self, msg: str, pos: int):
        raise ParseError(msg, pos)

    def _peek(self):
        while self.pos < len(self.chars) and self.chars[self.pos].isspace():
            self.pos += 1
        return self.chars[self.pos] if self.pos < len(self.chars) else None

    def _parse_all(self) -> Node:
        if self._peek() is None:
            self._err("empty expression", self.pos)
        e = self._expr()
        c = self._peek()
        if c is not None:
            self._err("unmatched ')'" if c == ")" else f"unexpected '{c}' (expected an operator)", self.pos)
        return e

    def _expr(self) -> Node:
        a = self._term()
        while self._peek() in ("+", "-"):
            c = self.chars[self.pos]
            self.pos += 1
            b = self._term()
            a = self.add(a, b) if c == "+" else self.sub(a, b)
        return a

    def _term(self) -> Node:
        a = self._unary()
        while True:
            c = self._peek()
            if c == "*" and self.chars[self.pos + 1:self.pos + 2] != "*":
                self.pos += 1
                a = self.exact_mul(a, self._unary())
            elif c == "/":
                self.pos += 1
                a = self.exact_div(a, self._unary())
            else:
                return a

    def _unary(self) -> Node:
        c = self._peek()
        if c == "-":
            self.pos += 1
            return self.neg(self._unary())
        if c == "+":
            self.pos += 1
            return self._unary()
        a = self._atom()
        c = self._peek()
        if c == "^":
            self.pos += 1
        elif c == "*" and self.chars[self.pos + 1:self.pos + 2] == "*":
            self.pos += 2
        else:
            return a
        return self.pw(a, self._unary())

    def _atom(self) -> Node:
        c = self._peek()
        if c is None:
            self._err("unexpected end of expression", self.pos)
        start = self.pos
        if c == "(":
            self.pos += 1
            e = self._expr()
            if self._peek() != ")":
                self._err(f"expected ')' to close the '(' at position {start}", self.pos)
            self.pos += 1
            return e
        if c.isdigit() or c == ".":
            return self._number()
        if c.isalpha() or c == "_":
            while self.pos < len(self.chars) and (self.chars[self.pos].isalnum() or self.chars[self.pos] in "_.:"):
                self.pos += 1
            name = self.chars[start:self.pos]
            if name == "t":
                return self._node("t")
            if name in ("pi", "e"):
                return self.num(math.pi if name == "pi" else math.e)
            if name not in _FUNCS:
                self._err(f"unknown name '{name}'", start)
            if self._peek() != "(":
                self._err(f"expected '(' after the function '{name}'", self.pos)
            self.pos += 1
            a = self._expr()
            if self._peek() != ")":
                self._err("expected ')'", self.pos)
            self.pos += 1
            return self.call(name, a)
        self._err(f"unexpected '{c}'", start)

    def _number(self) -> Node:
        import re

        m = re.match(r"(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?", self.chars[self.pos:])
        if not m:
            self._err("malformed number", self.pos)
        self.pos += m.end()
        return self.num(float(m.group(0)))


def motion_values(text: str, ts, **defects: bool):
    """``(3, nt)`` values like ``ukflex._core.motion_values`` for an expression, raising ukflex's
    errors as the core does (a parse error, a motion not finite at t = 0)."""
    import numpy as np

    import ukflex

    try:
        e = OldExpr(text, **defects)
    except ParseError as exc:
        raise ukflex.ExpressionError(f"motion: cannot parse the motion expression at position {exc.position}: {exc}") from None
    f0 = e.eval(0.0)
    if not all(math.isfinite(v) for v in f0):
        raise ukflex.InvalidSceneError(f"motion: motion is not finite at t = 0: f = {f0[0]}, f' = {f0[1]}, f'' = {f0[2]}")
    return np.array([e.eval(float(t)) for t in np.asarray(ts, dtype=float)]).T.reshape(3, -1)
