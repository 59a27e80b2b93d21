"""Soundness of the interval derivatives of function tapes (boundest.ctc.derivatives).

Every check compares the compiled enclosures with values computed independently in mpmath at
256 bits (77 digits), by analytic formulas (forward-mode derivatives of the expression trees):

- the Jacobian enclosure of every primitive (and of random composite expressions) contains the
  derivative at every sampled point of the box where it exists, both one-sided derivatives at
  a kink inside the box, and is unbounded where the box holds a jump;
- the mean-value property the centered form relies on: ``f(x) - f(c) in J (x - c)`` for
  points ``x, c`` of the box (``c`` also the midpoint), ``J (x - c)`` summed exactly in mpmath
  from the float bounds of ``J``;
- the centered form contains ``f`` at the sampled points, is never wider than the natural form
  and is quadratically narrow around a point where the natural form suffers from dependency;
- ``with_defined`` never claims a primitive defined and continuous on a box where it is not;
- empty and unbounded boxes.

The boxes mix random bounds with each primitive's special points (domain ends, kinks, jumps,
poles, the atan2 branch cut and origin, overflow thresholds) and infinite or degenerate bounds.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import boundest as bd
from boundest import Interval
from boundest.ctc.derivatives import centered, evaluate, jacobian, jacobian_sparse, midpoint
from boundest.expr import Var
from boundest.expr.function_tape import function_tape
from boundest.expr.nodes import Op, as_expr

from .strategies import bound, intervals

INF = math.inf
MAXF = 1.7976931348623157e308
mpf = mpmath.mpf

# -------------------------------------------------------------------------------------------
# exact arithmetic helpers
# -------------------------------------------------------------------------------------------

#: mpmath values at 256 bits are within 2**-250 (relative) of the exact ones: comparisons of
#: such a value ``v`` with float bounds allow that much (the float bounds are exact)
REL = mpmath.ldexp(1, -240)


def leq(a, b) -> bool:
    """``a <= b`` for an mpmath value ``a`` and a float ``b`` (-inf/inf allowed)."""
    return b == INF or a <= mpf(b)


def mp_in(v, lo: float, hi: float, slack=0) -> bool:
    """Whether the mpmath value ``v`` (known to ``slack``) lies in ``[lo, hi]``; never for an
    empty (NaN) interval."""
    if math.isnan(lo) or math.isnan(hi):
        return False
    return (lo == -INF or mpf(lo) <= v + slack) and (hi == INF or v - slack <= mpf(hi))


def exact_linear_form(jlo, jhi, d) -> tuple:
    """``sum_j [jlo_j, jhi_j] d_j`` for exact reals ``d_j``, computed exactly (``[J] * 0 = 0``:
    the enclosure holds real numbers only)."""
    lo = hi = mpf(0)
    for a, b, dj in zip(jlo, jhi, d, strict=True):
        if dj == 0:
            continue
        pa = mpmath.fmul(mpf(a), dj, exact=True)
        pb = mpmath.fmul(mpf(b), dj, exact=True)
        pl, ph = (pa, pb) if dj > 0 else (pb, pa)
        lo = mpmath.fadd(lo, pl, exact=True)
        hi = mpmath.fadd(hi, ph, exact=True)
    return lo, hi


def assert_valid(z: Interval) -> None:
    """Interval invariants, and no NaN (empty) bound."""
    lo, hi = np.asarray(z.lo), np.asarray(z.hi)
    assert not np.isnan(lo).any() and not np.isnan(hi).any(), (lo, hi)
    assert np.all(lo <= hi) and np.all(lo < INF) and np.all(hi > -INF), (lo, hi)


# -------------------------------------------------------------------------------------------
# the primitives in mpmath: value and derivative (None: not differentiable at that point)
# -------------------------------------------------------------------------------------------


class UndefinedError(Exception):
    """The point is outside the function's domain."""


class TooBigError(Exception):
    """A value beyond 1e150 (left out of composite checks: mpmath would crawl on exp(exp(.)))."""


def _is_int(v) -> bool:
    return mpmath.floor(v) == v


def _tan_d(v):
    t = mpmath.tan(v)
    return t, 1 + t * t


def _asin(v):
    if abs(v) > 1:
        raise UndefinedError
    return mpmath.asin(v), (1 / mpmath.sqrt(1 - v * v) if abs(v) < 1 else None)


def _acos(v):
    if abs(v) > 1:
        raise UndefinedError
    return mpmath.acos(v), (-1 / mpmath.sqrt(1 - v * v) if abs(v) < 1 else None)


def _sqrt(v):
    if v < 0:
        raise UndefinedError
    return mpmath.sqrt(v), (1 / (2 * mpmath.sqrt(v)) if v > 0 else None)


def _log(v):
    if v <= 0:
        raise UndefinedError
    return mpmath.log(v), 1 / v


def _tanh(v):
    t = mpmath.tanh(v)
    return t, 1 - t * t


def _step(f):
    """A piecewise-constant function: derivative 0 away from its jumps (at the integers or 0)."""
    def g(v):
        at_jump = v == 0 if f is mpmath.sign else _is_int(v)
        return f(v), (None if at_jump else mpf(0))
    return g


#: name -> v -> (f(v), f'(v) or None)
MP_UNARY: dict[str, Callable] = {
    "neg": lambda v: (-v, mpf(-1)),
    "sqr": lambda v: (v * v, 2 * v),
    "sqrt": _sqrt,
    "exp": lambda v: (mpmath.exp(v), mpmath.exp(v)),
    "log": _log,
    "sin": lambda v: (mpmath.sin(v), mpmath.cos(v)),
    "cos": lambda v: (mpmath.cos(v), -mpmath.sin(v)),
    "tan": _tan_d,
    "asin": _asin,
    "acos": _acos,
    "atan": lambda v: (mpmath.atan(v), 1 / (1 + v * v)),
    "sinh": lambda v: (mpmath.sinh(v), mpmath.cosh(v)),
    "cosh": lambda v: (mpmath.cosh(v), mpmath.sinh(v)),
    "tanh": _tanh,
    "abs": lambda v: (abs(v), (mpmath.sign(v) if v != 0 else None)),
    "sign": _step(mpmath.sign),
    "floor": _step(mpmath.floor),
    "ceil": _step(mpmath.ceil),
}


def mp_pown(v, n: int):
    if n < 0 and v == 0:
        raise UndefinedError
    return v ** n, (n * v ** (n - 1) if n != 0 else mpf(0))


def mp_pow(a, b):
    """``a ** b`` for real ``b``: ``a > 0``, or ``a = 0`` with ``b > 0``."""
    if a < 0 or (a == 0 and b <= 0):
        raise UndefinedError
    if a == 0:
        return mpf(0), None  # one-sided in a
    v = mpmath.power(a, b)
    return v, (b * mpmath.power(a, b - 1), mpmath.log(a) * v)


def mp_atan2(y, x):
    """IEEE 1788 ``atan2(y, x)`` in ``]-pi, pi]``; the y-derivative jumps on the cut."""
    if x == 0 and y == 0:
        raise UndefinedError
    r = x * x + y * y
    grad = None if (y == 0 and x < 0) else (x / r, -y / r)
    return mpmath.atan2(y, x), grad


def _div(a, b):
    if b == 0:
        raise UndefinedError
    return a / b, (1 / b, -a / (b * b))


def _min(a, b):
    return min(a, b), ((mpf(1), mpf(0)) if a < b else (mpf(0), mpf(1)) if a > b else None)


def _max(a, b):
    return max(a, b), ((mpf(1), mpf(0)) if a > b else (mpf(0), mpf(1)) if a < b else None)


#: name -> (a, b) -> (f(a, b), (df/da, df/db) or None)
MP_BINARY: dict[str, Callable] = {
    "add": lambda a, b: (a + b, (mpf(1), mpf(1))),
    "sub": lambda a, b: (a - b, (mpf(1), mpf(-1))),
    "mul": lambda a, b: (a * b, (b, a)),
    "div": _div,
    "pow": mp_pow,
    "atan2": mp_atan2,
    "min": _min,
    "max": _max,
}

#: expression builders of the primitives (boundest.expr)
EX_UNARY: dict[str, Callable] = {
    "neg": lambda a: -a, "sqr": lambda a: a ** 2, **{
        k: getattr(bd, k) for k in ("sqrt", "exp", "log", "sin", "cos", "tan", "asin", "acos",
                                    "atan", "sinh", "cosh", "tanh", "abs", "sign", "floor",
                                    "ceil")}}
EX_BINARY: dict[str, Callable] = {
    "add": lambda a, b: a + b, "sub": lambda a, b: a - b, "mul": lambda a, b: a * b,
    "div": lambda a, b: a / b, "pow": lambda a, b: a ** b, "atan2": bd.atan2, "min": bd.min,
    "max": bd.max}


# -------------------------------------------------------------------------------------------
# the primitives under test
# -------------------------------------------------------------------------------------------


def _near(values) -> list[float]:
    """The values and their float neighbours."""
    out = set()
    for v in values:
        out |= {v, math.nextafter(v, INF), math.nextafter(v, -INF)}
    return sorted(x for x in out if math.isfinite(x))


def _pole_in(lo: float, hi: float) -> bool:
    """Whether ``[lo, hi]`` holds a pole ``pi/2 + k pi`` of tan (mpmath)."""
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return True
    k = mpmath.ceil((mpf(lo) - mpmath.pi / 2) / mpmath.pi)
    return mpmath.pi / 2 + k * mpmath.pi <= hi


def _floor_jump(lo: float, hi: float) -> bool:
    """Some integer ``k`` with ``lo < k <= hi`` (floor jumps up at ``k``)."""
    if lo == hi:
        return False
    if hi == INF or lo == -INF:
        return True
    return mpmath.floor(mpf(hi)) > lo


def _ceil_jump(lo: float, hi: float) -> bool:
    """Some integer ``k`` with ``lo <= k < hi`` (ceil jumps up just after ``k``)."""
    if lo == hi:
        return False
    if hi == INF or lo == -INF:
        return True
    return mpmath.ceil(mpf(lo)) < hi


@dataclass(frozen=True)
class Prim:
    """A primitive under test: its expression, mpmath value and derivative, special points."""

    name: str
    arity: int
    build: Callable  # (Var, Var) -> Expr
    mp: Callable  # mp args -> (value, gradient tuple or None); raises UndefinedError
    specials: tuple = (0.0, 1.0, -1.0)
    #: (lo, hi) per component -> whether the primitive is undefined or discontinuous somewhere
    #: in the box (independent of derivatives.defined)
    bad: Callable = lambda lo, hi: False
    #: (lo, hi) -> per column, the side(s) on which a jump inside the box makes the slopes
    #: unbounded: "hi" (a jump up), "both", or None
    jumps: Callable = lambda lo, hi: (None, None)

    def value(self, *p):
        """``f(p)``, or None outside the domain."""
        try:
            return self.mp(*[mpf(v) for v in p])[0]
        except UndefinedError:
            return None

    def grad(self, *p):
        """The gradient at ``p`` as a tuple, or None (undefined or not differentiable)."""
        try:
            _, g = self.mp(*[mpf(v) for v in p])
        except UndefinedError:
            return None
        if g is None:
            return None
        return (g,) if self.arity == 1 else tuple(g)


def _unary(name, bad=None, jumps=None, specials=(0.0, 1.0, -1.0)) -> Prim:
    f = MP_UNARY[name]
    return Prim(name, 1, lambda a, b: EX_UNARY[name](a), f, tuple(specials),
                bad or (lambda lo, hi: False), jumps or (lambda lo, hi: (None,)))


def _binary(name, bad=None, jumps=None, specials=(0.0, 1.0, -1.0)) -> Prim:
    f = MP_BINARY[name]
    return Prim(name, 2, EX_BINARY[name], lambda a, b: f(a, b), tuple(specials),
                bad or (lambda lo, hi: False), jumps or (lambda lo, hi: (None, None)))


def _pown(n: int) -> Prim:
    return Prim(f"pown{n}", 1, lambda a, b: a ** n, lambda v: mp_pown(v, n),
                (0.0, 5e-324, -5e-324, 1.0, -1.0, 1e-300, 1e160),
                (lambda lo, hi: lo[0] <= 0 <= hi[0]) if n < 0 else (lambda lo, hi: False),
                lambda lo, hi: (None,))


def _powc(e: float) -> Prim:
    """``a ** e`` with a constant non-integer exponent (the real power, ``b`` a constant)."""
    def f(v):
        value, grad = mp_pow(v, mpf(e))
        return value, (None if grad is None else grad[0])

    return Prim(f"pow{e}", 1, lambda a, b: a ** e, f, (0.0, 5e-324, -5e-324, 1.0, 1e-300, 1e300),
        lambda lo, hi: lo[0] < 0 or (lo[0] <= 0 and e <= 0), lambda lo, hi: (None,))


def _atan2_bad(lo, hi) -> bool:
    (yl, xl), (yh, xh) = lo, hi
    origin = yl <= 0 <= yh and xl <= 0 <= xh
    cut = xl < 0 and yl < 0 <= yh  # points with x < 0 on both sides of the cut (y < 0, y >= 0)
    return origin or cut


def _atan2_jumps(lo, hi):
    (yl, xl), (yh, _) = lo, hi
    return ("hi" if xl < 0 and yl < 0 <= yh else None, None)


def _div_same(v):
    if v == 0:
        raise UndefinedError
    return mpf(1), mpf(0)


EDGE = (0.0, -0.0, 5e-324, -5e-324, 1e-300, 1.0, 2.0)
PRIMS: dict[str, Prim] = {p.name: p for p in [
    _binary("add"), _binary("sub"), _unary("neg"), _binary("mul"),
    Prim("mulsame", 1, lambda a, b: a * a, lambda v: (v * v, 2 * v)),
    Prim("subsame", 1, lambda a, b: a - a, lambda v: (mpf(0), mpf(0))),
    Prim("divsame", 1, lambda a, b: a / a, _div_same,
         (0.0, 5e-324, -5e-324, 1.0, -1.0), lambda lo, hi: lo[0] <= 0 <= hi[0]),
    _binary("div", bad=lambda lo, hi: lo[1] <= 0 <= hi[1],
            specials=(0.0, 5e-324, -5e-324, 1.0, -1.0, 1e-300, 1e300)),
    _unary("sqr", specials=(0.0, 1.0, -1.0, 1.4e154, 1e300)),
    _unary("sqrt", bad=lambda lo, hi: lo[0] < 0, specials=(*EDGE, -1.0)),
    _unary("exp", specials=(0.0, 709.78, 709.79, -745.2, -745.1, 1e300, -1e300)),
    _unary("log", bad=lambda lo, hi: lo[0] <= 0, specials=(*EDGE, -1.0, 1e300)),
    _unary("sin", specials=(0.0, math.pi / 2, math.pi, -math.pi / 2, 1e17)),
    _unary("cos", specials=(0.0, math.pi / 2, math.pi, -math.pi, 1e17)),
    _unary("tan", bad=lambda lo, hi: _pole_in(lo[0], hi[0]),
           jumps=lambda lo, hi: ("both" if _pole_in(lo[0], hi[0]) else None,),
           specials=(0.0, math.pi / 2, -math.pi / 2, 3 * math.pi / 2, 1.5, 1.6, 1e17)),
    _unary("asin", bad=lambda lo, hi: lo[0] < -1 or hi[0] > 1,
           specials=(-1.0, 1.0, 0.0, 0.5, -0.5, 2.0)),
    _unary("acos", bad=lambda lo, hi: lo[0] < -1 or hi[0] > 1,
           specials=(-1.0, 1.0, 0.0, 0.5, -0.5, 2.0)),
    _unary("atan", specials=(0.0, 1.0, 1e160, -1e160)),
    _unary("sinh", specials=(0.0, 710.47, 710.48, -710.48, 1e300)),
    _unary("cosh", specials=(0.0, 710.47, 710.48, -710.48, 1e300)),
    _unary("tanh", specials=(0.0, 1.0, 19.0, -19.0, 1e300)),
    _unary("abs", specials=(0.0, -0.0, 5e-324, -5e-324, 1.0, -1.0)),
    _unary("sign", bad=lambda lo, hi: lo[0] <= 0 <= hi[0] and lo[0] < hi[0],
           jumps=lambda lo, hi: ("hi" if lo[0] <= 0 <= hi[0] and lo[0] < hi[0] else None,),
           specials=(0.0, -0.0, 5e-324, -5e-324, 1.0, -1.0)),
    _unary("floor", bad=lambda lo, hi: _floor_jump(lo[0], hi[0]),
           jumps=lambda lo, hi: ("hi" if _floor_jump(lo[0], hi[0]) else None,),
           specials=(0.0, 1.0, -1.0, 2.0, 0.5, -0.5, 2.0 ** 52, 2.0 ** 53)),
    _unary("ceil", bad=lambda lo, hi: _ceil_jump(lo[0], hi[0]),
           jumps=lambda lo, hi: ("hi" if _ceil_jump(lo[0], hi[0]) else None,),
           specials=(0.0, 1.0, -1.0, 2.0, 0.5, -0.5, 2.0 ** 52, 2.0 ** 53)),
    *[_pown(n) for n in (-3, -2, -1, 0, 1, 3, 4)],
    _binary("pow", bad=lambda lo, hi: lo[0] < 0 or (lo[0] <= 0 and lo[1] <= 0),
            specials=(0.0, 5e-324, 1.0, -1.0, 0.5, 2.0, 1e-300, 100.0)),
    _powc(0.5), _powc(-1.5),
    _binary("atan2", bad=_atan2_bad, jumps=_atan2_jumps,
            specials=(0.0, -0.0, 5e-324, -5e-324, 1.0, -1.0, -2.0)),
    _binary("min", specials=(0.0, 1.0, -1.0, 5e-324)),
    _binary("max", specials=(0.0, 1.0, -1.0, 5e-324)),
]}
NAMES = list(PRIMS)
BINARY_NAMES = [k for k, p in PRIMS.items() if p.arity == 2]


def test_every_primitive_is_covered():
    """Every op code of the derivative layer appears in some tape under test."""
    from boundest.ctc import revise as rv

    codes = set()
    for name in NAMES:
        codes |= set(np.unique(prim_tape(name).op).tolist())
    expected = {getattr(rv, k) for k in (
        "ADD", "SUB", "NEG", "MUL", "DIV", "SQR", "SQRT", "EXP", "LOG", "SIN", "COS", "TAN",
        "ASIN", "ACOS", "ATAN", "SINH", "COSH", "TANH", "POWN", "POW", "ATAN2", "ABS", "SIGN",
        "FLOOR", "CEIL", "MIN", "MAX")}
    assert expected <= codes, expected - codes


@cache
def prim_tape(name: str):
    p = PRIMS[name]
    a, b = Var("a"), Var("b")
    return function_tape([p.build(a, b)], [a] if p.arity == 1 else [a, b])


# -------------------------------------------------------------------------------------------
# strategies: boxes and points
# -------------------------------------------------------------------------------------------


@st.composite
def prim_boxes(draw, prim: Prim) -> Interval:
    """A box for the primitive: bounds at its special points and their neighbours, random,
    huge, infinite; degenerate components; for binary ones sometimes both components equal."""
    elements = st.one_of(st.sampled_from(_near(prim.specials)), st.floats(-4, 4),
                         st.floats(-1e3, 1e3), bound)
    comps = [draw(intervals(elements=elements)) for _ in range(prim.arity)]
    if prim.arity == 2 and draw(st.integers(0, 4)) == 0:
        comps[1] = comps[0]
    return Interval([float(c.lo) for c in comps], [float(c.hi) for c in comps])


def _candidates(lo: float, hi: float, specials) -> list[float]:
    """Finite points of ``[lo, hi]``: its finite bounds and the special points inside."""
    c = [v for v in (lo, hi) if math.isfinite(v)]
    c += [v for v in _near(specials) if lo <= v <= hi]
    return c or [0.0 if lo <= 0.0 <= hi else (MAXF if lo > 0 else -MAXF)]


@st.composite
def points_in(draw, box: Interval, specials=(), k: int = 5) -> list[tuple]:
    """``k`` finite points of the box: bounds, special points inside, random floats; for a
    box of two components also a point on the diagonal where the components meet."""
    lo, hi = [float(v) for v in box.lo], [float(v) for v in box.hi]
    cols = []
    for a, b in zip(lo, hi, strict=True):
        fa, fb = max(a, -MAXF), min(b, MAXF)
        cols.append(st.one_of(st.sampled_from(_candidates(a, b, specials)),
                              st.floats(fa, fb) if fa < fb else st.just(fa)))
    pts = [tuple(draw(c) for c in cols) for _ in range(k)]
    if len(lo) == 2 and max(lo) <= min(hi):
        fa, fb = max(max(lo), -MAXF), min(min(hi), MAXF)
        t = draw(st.one_of(st.sampled_from(_candidates(max(lo), min(hi), specials)),
                           st.floats(fa, fb) if fa < fb else st.just(fa)))
        pts.append((t, t))
    return pts


def _rows(z: Interval, k: int = 0) -> tuple[list[float], list[float]]:
    """Row ``k`` of a single box's Jacobian ``(m, n)`` as lists of bounds."""
    return [float(v) for v in z.lo[k]], [float(v) for v in z.hi[k]]


# -------------------------------------------------------------------------------------------
# the checks, shared by the default and the slow tests
# -------------------------------------------------------------------------------------------


def check_derivative(prim: Prim, box: Interval, pts) -> None:
    """The Jacobian enclosure is a valid interval and holds the exact gradient at every point
    of the box where the primitive is differentiable."""
    _, jac = jacobian(prim_tape(prim.name), box)
    assert_valid(jac)
    jlo, jhi = _rows(jac)
    for p in pts:
        g = prim.grad(*p)
        if g is None:
            continue
        for j, d in enumerate(g):
            assert mp_in(d, jlo[j], jhi[j], abs(d) * REL), (prim.name, box, p, j, d, jlo, jhi)


def check_mean_value(prim: Prim, box: Interval, pts) -> None:
    """``f(x) - f(c) in J (x - c)`` for every two sampled points where ``f`` is defined, the
    midpoint of the box (as ``centered`` picks it) among the centres."""
    _, jac = jacobian(prim_tape(prim.name), box)
    jlo, jhi = _rows(jac)
    centres = [*pts, tuple(float(v) for v in midpoint(box))]
    for x in pts:
        fx = prim.value(*x)
        if fx is None:
            continue
        for c in centres:
            fc = prim.value(*c)
            if fc is None:
                continue
            d = [mpmath.fsub(mpf(u), mpf(v), exact=True) for u, v in zip(x, c, strict=True)]
            lo, hi = exact_linear_form(jlo, jhi, d)
            diff = fx - fc
            slack = (abs(fx) + abs(fc)) * REL
            assert lo <= diff + slack and diff - slack <= hi, (
                prim.name, box, x, c, mpmath.nstr(diff, 20), jlo, jhi)


def check_centered(prim: Prim, box: Interval, pts, centre) -> None:
    """The centered form (at the midpoint and at a given centre) holds ``f`` at the sampled
    points and lies inside the natural form."""
    tape = prim_tape(prim.name)
    natural = evaluate(tape, box)
    forms = [centered(tape, box), centered(tape, box, center=np.array(centre))]
    for cf in forms:
        assert cf.shape == (1,)
        if natural.is_empty()[0]:
            assert cf.is_empty()[0]
        else:
            assert bool(cf.is_subset(natural)[0]), (prim.name, box, cf, natural)
    for p in pts:
        v = prim.value(*p)
        if v is None:
            continue
        slack = abs(v) * REL
        for z in (natural, *forms):
            assert mp_in(v, float(z.lo[0]), float(z.hi[0]), slack), (prim.name, box, p, z)


def check_defined(prim: Prim, box: Interval, pts) -> None:
    """``with_defined`` is False on a box where the primitive is undefined or discontinuous
    somewhere (the independent predicate, or a sampled point outside the domain)."""
    _, _, ok = jacobian_sparse(prim_tape(prim.name), box, with_defined=True)
    lo, hi = [float(v) for v in box.lo], [float(v) for v in box.hi]
    if prim.bad(lo, hi) or any(prim.value(*p) is None for p in pts):
        assert not bool(ok), (prim.name, box)


def check_jumps(prim: Prim, box: Interval) -> None:
    """A jump inside the box makes the slopes of its column unbounded on the side(s) it
    forces: ``(f(k) - f(k - d)) / d`` grows without bound as ``d -> 0``."""
    _, jac = jacobian(prim_tape(prim.name), box)
    jlo, jhi = _rows(jac)
    lo, hi = [float(v) for v in box.lo], [float(v) for v in box.hi]
    for j, side in enumerate(prim.jumps(lo, hi)):
        if side in ("hi", "both"):
            assert jhi[j] == INF, (prim.name, box, j, jlo, jhi)
        if side == "both":
            assert jlo[j] == -INF, (prim.name, box, j, jlo, jhi)


def check_one_sided(prim: Prim, box: Interval, pts) -> None:
    """Piecewise-linear primitives (abs, min, max): at every sampled point, each one-sided
    partial derivative in a direction that stays in the box (exact difference quotients with
    a step below the float spacing, so no kink is crossed) lies in the enclosure. At a kink
    inside the box both one-sided derivatives are there; at a kink on the box's face only the
    one from inside the box (the mean-value property needs no more)."""
    _, jac = jacobian(prim_tape(prim.name), box)
    jlo, jhi = _rows(jac)
    lo, hi = [float(v) for v in box.lo], [float(v) for v in box.hi]
    with mpmath.workprec(2600):  # exact: floats and the step span less than 2**2500
        h = mpmath.ldexp(1, -1200)
        for p in pts:
            base = [mpf(v) for v in p]
            f0 = prim.mp(*base)[0]
            for j in range(prim.arity):
                for s in (1, -1):
                    if (s > 0 and not p[j] < hi[j]) or (s < 0 and not p[j] > lo[j]):
                        continue
                    q = list(base)
                    q[j] = q[j] + s * h
                    d = (prim.mp(*q)[0] - f0) / (s * h)
                    assert mp_in(d, jlo[j], jhi[j]), (prim.name, box, p, j, s, d, jlo, jhi)


# -------------------------------------------------------------------------------------------
# per-primitive properties
# -------------------------------------------------------------------------------------------

#: the default run samples each primitive lightly (36 of them, times six properties); the slow
#: run checks every property on many more boxes
FAST = settings(max_examples=15, deadline=None)
FASTER = settings(max_examples=10, deadline=None)
SLOW = settings(max_examples=400, deadline=None)


def _draw(data, name):
    prim = PRIMS[name]
    box = data.draw(prim_boxes(prim), label="box")
    pts = data.draw(points_in(box, prim.specials), label="points")
    return prim, box, pts


@pytest.mark.parametrize("name", NAMES)
@FAST
@given(data=st.data())
def test_derivative_in_jacobian(name, data):
    """Every primitive: the exact derivative at sampled points lies in the Jacobian."""
    check_derivative(*_draw(data, name))


@pytest.mark.parametrize("name", NAMES)
@FAST
@given(data=st.data())
def test_mean_value_property(name, data):
    """Every primitive: ``f(x) - f(c) in J (x - c)``, exactly."""
    check_mean_value(*_draw(data, name))


@pytest.mark.parametrize("name", NAMES)
@FASTER
@given(data=st.data())
def test_centered_form_contains_values(name, data):
    """Every primitive: natural and centered forms hold ``f`` at the sampled points, the
    centered form inside the natural one."""
    prim, box, pts = _draw(data, name)
    check_centered(prim, box, pts, pts[0])


@pytest.mark.parametrize("name", NAMES)
@FASTER
@given(data=st.data())
def test_defined_is_never_claimed_falsely(name, data):
    """Every primitive: ``with_defined`` is False where the primitive is undefined or
    discontinuous somewhere in the box."""
    check_defined(*_draw(data, name))


@pytest.mark.parametrize("name", ["tan", "sign", "floor", "ceil", "atan2"])
@FASTER
@given(data=st.data())
def test_jumps_give_unbounded_slopes(name, data):
    """Jumps (tan's poles, sign at 0, floor/ceil at the integers, atan2's branch cut): the
    column's enclosure is unbounded on the side the jump forces."""
    prim, box, _ = _draw(data, name)
    check_jumps(prim, box)


@pytest.mark.parametrize("name", ["abs", "min", "max", "add", "sub", "neg"])
@FASTER
@given(data=st.data())
def test_kinks_one_sided_derivatives(name, data):
    """Piecewise-linear primitives: one-sided derivatives at sampled points (kinks among
    them) lie in the enclosure."""
    check_one_sided(*_draw(data, name))


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
@SLOW
@given(data=st.data())
def test_primitive_properties_long(name, data):
    """Every primitive, many more boxes: all the per-primitive properties above."""
    prim, box, pts = _draw(data, name)
    check_derivative(prim, box, pts)
    check_mean_value(prim, box, pts)
    check_centered(prim, box, pts, pts[-1])
    check_defined(prim, box, pts)
    check_jumps(prim, box)
    if name in ("abs", "min", "max"):
        check_one_sided(prim, box, pts)


# -------------------------------------------------------------------------------------------
# hand-picked cases
# -------------------------------------------------------------------------------------------


def _box(*comps) -> Interval:
    return Interval([c[0] for c in comps], [c[1] for c in comps])


def test_atan2_derivative_regression():
    """atan2(y, x) at (y, x) = (1, 2): d/dy = x / (x^2 + y^2) = 0.4 and d/dx = -y / (x^2 +
    y^2) = -0.2 (the two partial derivatives were swapped: J was [0.2, -0.4])."""
    prim = PRIMS["atan2"]
    box = _box((1.0, 1.0), (2.0, 2.0))
    check_derivative(prim, box, [(1.0, 2.0)])
    check_mean_value(prim, _box((1.0, 1.5), (2.0, 2.5)), [(1.0, 2.0), (1.5, 2.5), (1.0, 2.5)])


def test_atan2_branch_cut_regression():
    """atan2 over y in [-1, 1], x in [-2, -1] jumps from -pi to pi across y = 0: the
    y-column must be unbounded and the box not claimed continuous (it was claimed defined,
    with finite slopes, the cut test looking at the wrong argument)."""
    prim = PRIMS["atan2"]
    box = _box((-1.0, 1.0), (-2.0, -1.0))
    check_jumps(prim, box)
    check_defined(prim, box, [])
    check_mean_value(prim, box, [(-1e-300, -1.5), (0.0, -1.5), (1.0, -2.0), (-1.0, -1.0)])
    # the other side: y < 0 across x = 0 is continuous (angle about -pi/2)
    _, _, ok = jacobian_sparse(prim_tape("atan2"), _box((-2.0, -1.0), (-1.0, 1.0)),
                               with_defined=True)
    assert bool(ok)


@pytest.mark.parametrize("n", [2.0**62, 1e20, 2.0**64, -1e20, 1e300])
@pytest.mark.parametrize("a", [1.0, -1.0, 0.5, -0.5, 1 - 2**-53, -(1 + 2**-52), -3.0, 3.0])
def test_huge_integer_exponent_derivative(n, a):
    """d/dx x**n = n x**(n - 1) for an integer-valued float n beyond 2**62 (issue 27 item 7):
    the factor n is exact (not the int64 the kernels take beyond 2**63), the power has the
    parity of n - 1 (odd): at x = 1 the slope is exactly n, at x = -1 exactly -n."""
    _, J = jacobian(Var("x") ** n, Interval([a], [a]))
    lo, hi = float(J.lo[0, 0]), float(J.hi[0, 0])
    with mpmath.workprec(300):
        p = mpmath.iv.mpf(abs(a)) ** (int(n) - 1)  # rigorous enclosure of |a|**(n-1)
        d = p * int(n)
        dl, dh = (-d.b, -d.a) if a < 0 else (d.a, d.b)  # n - 1 is odd
    assert (lo == -INF or mpf(lo) <= dl) and (hi == INF or dh <= mpf(hi)), (n, a, lo, hi)
    if abs(a) == 1.0:
        assert lo == hi == n * a


@pytest.mark.parametrize(("name", "box", "ok"), [
    ("sqrt", [(0.0, 1.0)], True), ("sqrt", [(-1e-300, 1.0)], False),
    ("log", [(1e-300, 1.0)], True), ("log", [(0.0, 1.0)], False),
    ("asin", [(-1.0, 1.0)], True), ("acos", [(-1.0, 1.0000000000000002)], False),
    ("div", [(1.0, 2.0), (1e-300, 1.0)], True), ("div", [(1.0, 2.0), (0.0, 1.0)], False),
    ("pown-1", [(-2.0, -1e-300)], True), ("pown-2", [(-2.0, 0.0)], False),
    ("pow", [(0.0, 1.0), (0.5, 2.0)], True), ("pow", [(0.0, 1.0), (0.0, 2.0)], False),
    ("tan", [(1.5, 1.5707963267948966)], True), ("tan", [(1.5, 1.5707963267948968)], False),
    ("sign", [(0.0, 0.0)], True), ("sign", [(0.0, 1.0)], False),
    ("floor", [(1.0, 1.5)], True), ("floor", [(0.5, 1.0)], False),
    ("ceil", [(0.5, 1.0)], True), ("ceil", [(1.0, 1.5)], False),
    ("atan2", [(0.0, 1.0), (-2.0, -1.0)], True), ("atan2", [(-1.0, 0.0), (-2.0, -1.0)], False),
    ("atan2", [(-1.0, 1.0), (0.0, 1.0)], False), ("atan2", [(-1.0, 1.0), (1e-300, 1.0)], True),
    ("abs", [(-1.0, 1.0)], True), ("min", [(-1.0, 1.0), (0.0, 2.0)], True),
])
def test_defined_at_the_domain_edges(name, box, ok):
    """``with_defined`` on boxes touching or straddling a domain edge, pole, jump or the
    branch cut: False exactly when the primitive is undefined or discontinuous there (the
    True cases keep the flag useful: interval Newton's proofs need it)."""
    b = _box(*box)
    _, _, got = jacobian_sparse(prim_tape(name), b, with_defined=True)
    assert bool(got) == ok
    assert PRIMS[name].bad([c[0] for c in box], [c[1] for c in box]) == (not ok)


@pytest.mark.parametrize("name", NAMES)
def test_empty_boxes(name):
    """An empty component gives empty values (natural and centered), an undefined flag, and
    no crash, for a single box and inside a batch."""
    tape = prim_tape(name)
    n = tape.n_vars
    for k in range(n):
        lo = np.zeros(n)
        hi = np.ones(n)
        lo[k] = hi[k] = np.nan
        box = Interval.trusted(lo, hi)
        values, jac = jacobian(tape, box)
        assert values.is_empty().all() and jac.shape == (1, n)
        assert evaluate(tape, box).is_empty().all()
        assert centered(tape, box).is_empty().all()
        _, _, ok = jacobian_sparse(tape, box, with_defined=True)
        assert not bool(ok)
        batch = Interval.trusted(np.stack([lo, np.full(n, 0.25)]), np.stack([hi, np.full(n, 0.5)]))
        cf = centered(tape, batch)
        assert cf.is_empty()[0].all() and cf.shape == (2, 1)
        assert cf[1].is_subset(evaluate(tape, batch)[1]).all()


@pytest.mark.parametrize("name", NAMES)
def test_unbounded_boxes(name):
    """Entire and half-line boxes: valid (possibly entire) enclosures that satisfy the
    mean-value property and contain the values at finite points."""
    prim = PRIMS[name]
    comps = [(-INF, INF), (0.0, INF), (-INF, 0.0), (1.0, INF), (-INF, -1.0)]
    pts_of = {(-INF, INF): [0.0, -3.0, 1e300], (0.0, INF): [0.0, 2.0, 1e300],
              (-INF, 0.0): [0.0, -2.5, -1e300], (1.0, INF): [1.0, 7.0],
              (-INF, -1.0): [-1.0, -7.5]}
    for c0 in comps:
        for c1 in (comps[:3] if prim.arity == 2 else [None]):
            cs = [c0] if c1 is None else [c0, c1]
            box = _box(*cs)
            pts = [tuple(p) for p in np.array(np.meshgrid(*[pts_of[c] for c in cs]))
                   .reshape(len(cs), -1).T]
            check_derivative(prim, box, pts)
            check_mean_value(prim, box, pts)
            check_centered(prim, box, pts, pts[0])


# -------------------------------------------------------------------------------------------
# random composite expressions
# -------------------------------------------------------------------------------------------

N_VARS = 3
VARS = [Var(f"x{i}") for i in range(N_VARS)]
UNARY_OPS = list(MP_UNARY)
BINARY_OPS = list(MP_BINARY)
CONSTS = [0.5, 1.0, -2.0, 3.0, 0.0]


def trees(depth: int):
    """Expression trees of depth <= ``depth`` over ``x0..x2`` and a few constants (nested
    tuples): every primitive, integer powers, real powers with a constant exponent."""
    leaf = st.one_of(st.integers(0, N_VARS - 1).map(lambda i: ("x", i)),
                     st.sampled_from(CONSTS).map(lambda c: ("c", c)))
    if depth == 0:
        return leaf
    sub = trees(depth - 1)
    return st.one_of(
        leaf,
        st.tuples(st.sampled_from(UNARY_OPS), sub),
        st.tuples(st.sampled_from(BINARY_OPS), sub, sub),
        st.tuples(st.just("pown"), st.sampled_from([-2, -1, 3]), sub),
        st.tuples(st.just("powc"), st.sampled_from([0.5, 1.5, -0.5]), sub))


def tree_expr(t):
    """The boundest expression of a tree."""
    k = t[0]
    if k == "x":
        return VARS[t[1]]
    if k == "c":
        return as_expr(t[1])
    if k == "pown":
        return bd.pown(tree_expr(t[2]), t[1])
    if k == "powc":
        return bd.pow(tree_expr(t[2]), t[1])
    if k in MP_UNARY:
        return EX_UNARY[k](tree_expr(t[1]))
    if k == "pow":  # the real power even for an integer constant exponent (x**2. is sqr)
        return Op("pow", (tree_expr(t[1]), tree_expr(t[2])))
    return EX_BINARY[k](tree_expr(t[1]), tree_expr(t[2]))


def _big(v):
    if abs(v) > 1e150:
        raise TooBigError
    return v


def tree_eval(t, p):
    """``(value, gradient)`` of a tree at the point ``p`` (mpmath, forward mode); the gradient
    is None where some primitive is not differentiable. Raises UndefinedError outside the domain,
    TooBigError past 1e150."""
    n = N_VARS
    k = t[0]
    if k == "x":
        return mpf(p[t[1]]), tuple(mpf(1 if i == t[1] else 0) for i in range(n))
    if k == "c":
        return mpf(t[1]), tuple(mpf(0) for _ in range(n))
    if k in ("pown", "powc"):
        v, g = tree_eval(t[2], p)
        if k == "pown":
            f, d = mp_pown(v, t[1])
        else:
            if v > 0 and abs(t[1] * mpmath.log(v)) > 300:
                raise TooBigError
            f, dd = mp_pow(v, mpf(t[1]))
            d = None if dd is None else dd[0]
        return _big(f), (None if g is None or d is None else tuple(d * gi for gi in g))
    if k in MP_UNARY:
        v, g = tree_eval(t[1], p)
        if k in ("exp", "sinh", "cosh") and abs(v) > 300:
            raise TooBigError
        f, d = MP_UNARY[k](v)
        return _big(f), (None if g is None or d is None else tuple(d * gi for gi in g))
    (va, ga), (vb, gb) = tree_eval(t[1], p), tree_eval(t[2], p)
    if k == "pow" and va > 0 and abs(vb * mpmath.log(va)) > 300:
        raise TooBigError
    f, d = MP_BINARY[k](va, vb)
    if ga is None or gb is None or d is None:
        return _big(f), None
    return _big(f), tuple(d[0] * x + d[1] * y for x, y in zip(ga, gb, strict=True))


def _try_eval(t, p):
    """``(value, gradient)``, or ``("undefined", None)`` / ``(None, None)`` (too big)."""
    try:
        return tree_eval(t, p)
    except UndefinedError:
        return "undefined", None
    except TooBigError:
        return None, None


#: an extra output using every op family: all composite tapes then share one compiled
#: specialisation of the kernels (each family combination compiles on its own)
_X = VARS[0]
ALL_FAMILIES = bd.sin(_X) + bd.exp(_X) + bd.abs(_X) + _X ** 3


@st.composite
def composite_boxes(draw) -> Interval:
    """Boxes over ``x0..x2``: random centres (special points among them), widths from 0 to
    6, now and then a half-line or the whole line."""
    lo, hi = [], []
    for _ in range(N_VARS):
        c = draw(st.one_of(st.floats(-3, 3), st.sampled_from(
            [0.0, 0.5, 1.0, -1.0, 2.0, math.pi / 2, 5e-324])))
        w = draw(st.sampled_from([0.0, 1e-9, 1e-4, 0.01, 0.3, 1.0, 3.0, 6.0]))
        a = c - w * draw(st.floats(0, 1))
        b = max(a + w, a)
        kind = draw(st.integers(0, 19))
        a = -INF if kind == 0 else a
        b = INF if kind == 1 else b
        if kind == 2:
            a, b = -INF, INF
        lo.append(a)
        hi.append(b)
    return Interval(lo, hi)


@st.composite
def composites(draw):
    """A random tree of depth <= 4, a box, points in it, and the compiled tape (the tree is
    the first output)."""
    t = draw(trees(4))
    box = draw(composite_boxes())
    pts = draw(points_in(box, (0.0, 1.0, -1.0, 0.5), k=5))
    tape = function_tape([tree_expr(t), ALL_FAMILIES], VARS)
    return t, box, pts, tape


def _composite_checks(t, box, pts, tape, which) -> None:
    """The checks on one composite (``which``: a set of "gradient", "mean_value",
    "centered", "defined")."""
    values, jac = jacobian(tape, box)
    assert_valid(jac)
    jlo, jhi = _rows(jac, 0)
    evals = [_try_eval(t, p) for p in pts]
    c_mid = tuple(float(v) for v in midpoint(box))
    if "gradient" in which:
        for p, (v, g) in zip(pts, evals, strict=True):
            if g is None or v == "undefined":
                continue
            for j, d in enumerate(g):
                assert mp_in(d, jlo[j], jhi[j], abs(d) * REL), (t, box, p, j, d, jlo, jhi)
    if "mean_value" in which:
        centres = [*zip(pts, evals, strict=True), (c_mid, _try_eval(t, c_mid))]
        for x, (fx, _) in zip(pts, evals, strict=True):
            if fx is None or fx == "undefined":
                continue
            for c, (fc, _) in centres:
                if fc is None or fc == "undefined":
                    continue
                d = [mpmath.fsub(mpf(u), mpf(v), exact=True) for u, v in zip(x, c, strict=True)]
                lo, hi = exact_linear_form(jlo, jhi, d)
                slack = (abs(fx) + abs(fc)) * REL
                assert lo <= fx - fc + slack and fx - fc - slack <= hi, (
                    t, box, x, c, mpmath.nstr(fx - fc, 20), jlo, jhi)
    if "centered" in which:
        natural = evaluate(tape, box)
        forms = [centered(tape, box), centered(tape, box, center=np.array(pts[0]))]
        for cf in forms:
            if natural.is_empty()[0]:
                assert cf.is_empty()[0]
            else:
                assert bool(cf[0].is_subset(natural[0])), (t, box, cf, natural)
        for p, (v, _) in zip(pts, evals, strict=True):
            if v is None or v == "undefined":
                continue
            for z in (natural, values, *forms):
                assert mp_in(v, float(z.lo[0]), float(z.hi[0]), abs(v) * REL), (t, box, p, z)
    if "defined" in which and any(v == "undefined" for v, _ in evals):
        _, _, ok = jacobian_sparse(tape, box, with_defined=True)
        assert not bool(ok), (t, box)
    if "batch" in which:  # a batch (2, 2, n) gives each box what it gets alone
        other = Interval(np.minimum(box.lo, -1.0), np.maximum(box.hi, 2.0))
        batch = Interval(np.stack([np.stack([box.lo, other.lo]), np.stack([other.lo, box.lo])]),
                         np.stack([np.stack([box.hi, other.hi]), np.stack([other.hi, box.hi])]))
        bv, bj = jacobian(tape, batch)
        ov, oj = jacobian(tape, other)
        assert bj.shape == (2, 2, 2, N_VARS) and bv.shape == (2, 2, 2)
        for (i, j), (v1, j1) in {(0, 0): (values, jac), (1, 1): (values, jac), (0, 1): (ov, oj),
                                 (1, 0): (ov, oj)}.items():
            np.testing.assert_array_equal(bj.lo[i, j], j1.lo)
            np.testing.assert_array_equal(bj.hi[i, j], j1.hi)
            np.testing.assert_array_equal(bv.lo[i, j], v1.lo)
        cb = centered(tape, batch)
        np.testing.assert_array_equal(cb.lo[0, 0], centered(tape, box).lo)
        np.testing.assert_array_equal(cb.hi[1, 0], centered(tape, other).hi)


COMPOSITE = settings(max_examples=100, deadline=None)


@COMPOSITE
@given(composites())
def test_composite_gradient_in_jacobian(case):
    """Random composite expressions: the exact gradient (forward mode in mpmath) lies in the
    Jacobian at every sampled point where every primitive is differentiable."""
    _composite_checks(*case, {"gradient"})


@COMPOSITE
@given(composites())
def test_composite_mean_value_property(case):
    """Random composite expressions: ``f(x) - f(c) in J (x - c)`` exactly for sampled pairs
    where ``f`` is defined (the midpoint among the centres)."""
    _composite_checks(*case, {"mean_value"})


@COMPOSITE
@given(composites())
def test_composite_centered_and_defined(case):
    """Random composite expressions: natural and centered forms hold the values, centered
    inside natural; a point outside the domain means the box is not claimed defined; a batch
    of boxes gets what each box gets alone."""
    _composite_checks(*case, {"centered", "defined", "batch"})


@pytest.mark.slow
@settings(max_examples=3000, deadline=None)
@given(composites())
def test_composite_properties_long(case):
    """Random composite expressions, many more: every composite property above."""
    _composite_checks(*case, {"gradient", "mean_value", "centered", "defined", "batch"})


# -------------------------------------------------------------------------------------------
# tightness of the centered form where the natural form suffers from dependency
# -------------------------------------------------------------------------------------------

_x = Var("x")
DEPENDENT = {
    "x*(1-x)": (_x * (1 - _x), lambda v: v * (1 - v)),
    "x-x**2": (_x - _x ** 2, lambda v: v - v * v),
}


@pytest.mark.parametrize("name", list(DEPENDENT))
@settings(max_examples=60, deadline=None)
@given(c=st.floats(0.5 - 1e-3, 0.5 + 1e-3), r=st.floats(1e-7, 1e-2))
def test_centered_form_beats_dependency(name, c, r):
    """``f = x (1 - x)`` (or ``x - x^2``) on ``[c - r, c + r]`` near the maximum 1/2: the
    natural form is about ``2 r`` wide whatever ``c``, the exact range about ``2 r |1 - 2c| +
    r^2``; the centered form's excess over the exact range is of order ``r^2`` (the mean-value
    form: ``|J - f'(c)| r`` with ``J = 1 - 2X``, at most ``4 r^2``) and the measured width
    ratio centered / natural is below ``|1 - 2 c| + 3 r``."""
    expr, f = DEPENDENT[name]
    tape = function_tape([expr], [_x])
    box = Interval([c - r], [c + r])
    lo, hi = float(box.lo[0]), float(box.hi[0])
    nat = evaluate(tape, box)[0]
    cen = centered(tape, box)[0]
    w_nat = float(nat.hi - nat.lo)
    w_cen = float(cen.hi - cen.lo)
    # the exact range of the concave parabola on [lo, hi]
    ends = [f(mpf(lo)), f(mpf(hi))]
    top = f(mpf(0.5)) if lo <= 0.5 <= hi else max(ends)
    w_range = float(top - min(ends))
    ulp = 4 * 2.0 ** -52  # rounding of the bounds (values about 1/4)
    assert w_cen <= w_range + 4 * (hi - lo) ** 2 / 4 * 1.000001 + ulp, (w_cen, w_range)
    assert w_cen / w_nat <= abs(1 - 2 * c) + 3 * r + ulp / w_nat, (w_cen, w_nat)
    assert bool(cen.is_subset(nat))


def test_centered_form_converges_quadratically():
    """Around the maximum of ``x (1 - x)`` the centered form's width falls with the square
    of the box width (halving the box quarters it) while the natural form's only halves:
    the measured ratios, over widths ``2^-4 .. 2^-16``."""
    tape = function_tape([DEPENDENT["x*(1-x)"][0]], [_x])
    widths = [2.0 ** -k for k in range(4, 17)]
    cen = [float(centered(tape, Interval([0.5 - r], [0.5 + r]))[0].width()) for r in widths]
    nat = [float(evaluate(tape, Interval([0.5 - r], [0.5 + r]))[0].width()) for r in widths]
    for i in range(len(widths) - 1):
        assert cen[i] / cen[i + 1] >= 3.5, cen  # quadratic: 4
        assert 1.8 <= nat[i] / nat[i + 1] <= 2.2, nat  # linear: 2
    assert cen[-1] / nat[-1] <= 3 * widths[-1]  # 4 r^2 / 2 r = 2 r
