"""Hypothesis strategies shared by the tests: intervals and points inside them, and random
solvable CSPs with known solutions."""

from __future__ import annotations

import math

import mpmath
import numpy as np
from hypothesis import strategies as st

from boundest import Interval
from boundest.expr import Model, Var
from boundest.expr.functions import cos, sin, sqr

#: Bounds that exercise zeros, tiny, huge and infinite magnitudes.
SPECIAL = [0.0, -0.0, 1.0, -1.0, 0.5, 2.0**-1074, -(2.0**-1074), 2.0**-1022, 1e-300, -1e-300,
           1e300, -1e300, 1.7976931348623157e308, -1.7976931348623157e308]

finite = st.floats(allow_nan=False, allow_infinity=False)
moderate = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False)
bound = st.one_of(finite, moderate, st.sampled_from(SPECIAL))


@st.composite
def intervals(draw, elements=bound, allow_inf: bool = True, allow_degenerate: bool = True):
    """A non-empty interval, possibly with infinite bounds or degenerate."""
    a, b = sorted([draw(elements), draw(elements)])
    if allow_degenerate and draw(st.integers(0, 9)) == 0:
        b = a
    if allow_inf:
        kind = draw(st.integers(0, 9))
        if kind == 0:
            a = -math.inf
        elif kind == 1:
            b = math.inf
        elif kind == 2:
            a, b = -math.inf, math.inf
    return Interval(a, b)


@st.composite
def point_in(draw, x: Interval) -> float:
    """A float inside the (non-empty, scalar) interval ``x``."""
    lo, hi = float(x.lo), float(x.hi)
    lo = max(lo, -1.7976931348623157e308)
    hi = min(hi, 1.7976931348623157e308)
    if lo == hi or draw(st.booleans()):
        return draw(st.sampled_from([lo, hi]))
    return draw(st.floats(min_value=lo, max_value=hi, allow_nan=False))


def ulps_apart(a: float, b: float) -> int:
    """Number of float64 steps between ``a`` and ``b`` (finite)."""
    ia = np.array(a, dtype=np.float64).view(np.int64).item()
    ib = np.array(b, dtype=np.float64).view(np.int64).item()
    ia = ia if ia >= 0 else -(ia & 0x7FFFFFFFFFFFFFFF)
    ib = ib if ib >= 0 else -(ib & 0x7FFFFFFFFFFFFFFF)
    return abs(ia - ib)


#: the variables of :func:`solvable_csps`
CSP_VARS = [Var(f"x{i}") for i in range(4)]


def expression_trees(n: int, max_leaves: int):
    """Random expression trees over ``x0..x{n-1}`` (nested tuples); with a few variables and
    several leaves, a variable occurring several times (the dependency problem) is common."""
    leaf = st.one_of(st.integers(0, n - 1).map(lambda i: ("x", i)),
                     st.sampled_from([0.5, 1.0, -2.0, 3.0]).map(lambda c: ("c", c)))

    def grow(sub):
        return st.one_of(
            st.tuples(st.sampled_from(["add", "sub", "mul"]), sub, sub),
            st.tuples(st.sampled_from(["sqr", "sin", "cos", "rat"]), sub))

    return st.recursive(leaf, grow, max_leaves=max_leaves)


def tree_expr(t):
    """The boundest expression of a tree (``rat``: ``a / (1 + a^2)``)."""
    k = t[0]
    if k == "x":
        return CSP_VARS[t[1]]
    if k == "c":
        return t[1]
    a = [tree_expr(s) for s in t[1:]]
    return {"add": lambda: a[0] + a[1], "sub": lambda: a[0] - a[1], "mul": lambda: a[0] * a[1],
            "sqr": lambda: sqr(a[0]), "sin": lambda: sin(a[0]), "cos": lambda: cos(a[0]),
            "rat": lambda: a[0] / (1.0 + sqr(a[0]))}[k]()


def tree_value(t, p):
    """The value of a tree at the point ``p`` in mpmath (the independent truth)."""
    k = t[0]
    if k == "x":
        return mpmath.mpf(p[t[1]])
    if k == "c":
        return mpmath.mpf(t[1])
    v = [tree_value(s, p) for s in t[1:]]
    return {"add": lambda: v[0] + v[1], "sub": lambda: v[0] - v[1], "mul": lambda: v[0] * v[1],
            "sqr": lambda: v[0] ** 2, "sin": lambda: mpmath.sin(v[0]),
            "cos": lambda: mpmath.cos(v[0]), "rat": lambda: v[0] / (1 + v[0] ** 2)}[k]()


def _outward(v, up: bool) -> float:
    """A float beyond the mpmath value ``v`` (below it, or above when ``up``)."""
    d = math.inf if up else -math.inf
    return float(np.nextafter(np.nextafter(float(v), d), d))


@st.composite
def solvable_csps(draw, n_vars: tuple[int, int], max_constraints: int, margins: list[float],
                  max_leaves: int):
    """``y_j = f_j(x)``, ``x in [-2, 2]^n``, the domain of ``y_j`` the hull of ``f_j`` at a few
    random points (computed in mpmath at 60 digits, rounded outward) plus a margin: those
    points are solutions. Returns the model, ``n`` and the points."""
    n = draw(st.integers(*n_vars))
    pts = draw(st.lists(st.tuples(*[st.floats(-2, 2) for _ in range(n)]), min_size=1,
                        max_size=3))
    trees = draw(st.lists(expression_trees(n, max_leaves), min_size=1,
                          max_size=max_constraints))
    margin = draw(st.sampled_from(margins))
    mpmath.mp.dps = 60
    model = Model()
    for i in range(n):
        model.declare(CSP_VARS[i], (-2.0, 2.0))
    for j, t in enumerate(trees):
        vals = [tree_value(t, p) for p in pts]
        model.declare(Var(f"y{j}"), (_outward(min(vals) - margin, False),
                                     _outward(max(vals) + margin, True)))
        model.add(Var(f"y{j}") == tree_expr(t))
    return model, n, pts
