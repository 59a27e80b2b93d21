"""Soundness and tightness of the exponential family (boundest.interval.explog).

Forward functions: every point of the argument, evaluated exactly with mpmath (256 bits), must
lie in the computed enclosure. Reverse operators: a point x of X with z = f(x) computed exactly
and Z a float interval around z must survive the contraction. Edge cases use values derived by
hand (tests/test_itf1788.py checks the ITF1788 vectors).
"""

from __future__ import annotations

import math
import sys

import mpmath
import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from boundest import Interval
from boundest.interval import explog as ex

from .checks import engine_forward, examples, is_empty, same, subset, valid
from .strategies import intervals, point_in, ulps_apart

mpmath.mp.prec = 256
INF = math.inf
MAX = sys.float_info.max
MP_PI = mpmath.pi
EMPTY = Interval.empty()
ENTIRE = Interval.entire()


# -------------------------------------------------------------------------------------------
# helpers
# -------------------------------------------------------------------------------------------

def mp(v: float) -> mpmath.mpf:
    return mpmath.mpf(v)


def mp_in(v, z: Interval) -> bool:
    """Whether the exact (mpmath) value ``v`` lies in the scalar float interval ``z``."""
    lo, hi = float(z.lo), float(z.hi)
    if math.isnan(lo) or math.isnan(hi):
        return False
    return mp(lo) <= v <= mp(hi)










#: mpmath values are within a few units of 2**-256 (relative) of the exact ones: float bounds
#: are kept this far from them, so that a rounded mpmath value that happens to be a float (e.g.
#: exp(-1e-108) = 1 at 256 bits) still gives an enclosure of the exact value.
_MARGIN = mpmath.ldexp(1, -230)


def float_dn(v) -> float:
    """A float below the exact value ``v`` (the largest one, unless ``v`` is within 2**-230
    relative of a float); ``MAX`` when ``v`` overflows."""
    if v == 0:
        return 0.0
    f = float(v)
    if f == INF:
        f = MAX
    while f != -INF and mp(f) > v - abs(v) * _MARGIN:
        f = math.nextafter(f, -INF)
    return f


def float_up(v) -> float:
    if v == 0:
        return 0.0
    f = float(v)
    if f == -INF:
        f = -MAX
    while f != INF and mp(f) < v + abs(v) * _MARGIN:
        f = math.nextafter(f, INF)
    return f


def enclose(v) -> Interval:
    """The tightest float interval around the exact value ``v``."""
    return Interval(float_dn(v), float_up(v))


@st.composite
def around(draw, v):
    """A float interval containing the exact value ``v``: tight, or widened at random."""
    lo, hi = float_dn(v), float_up(v)
    kind = draw(st.integers(0, 3))
    if kind == 1 and math.isfinite(lo):
        lo -= draw(st.floats(0, 10)) * (abs(lo) + 1e-300)
    elif kind == 2 and math.isfinite(hi):
        hi += draw(st.floats(0, 10)) * (abs(hi) + 1e-300)
    elif kind == 3:
        lo, hi = -INF, INF
    return Interval(lo, hi)


def meet_positive(x: Interval, lower: float = 0.0) -> Interval | None:
    """``x & [lower, inf]`` or None when empty."""
    lo, hi = max(float(x.lo), lower), float(x.hi)
    return Interval(lo, hi) if lo <= hi else None


# -------------------------------------------------------------------------------------------
# forward, unary: soundness at sampled points
# -------------------------------------------------------------------------------------------

UNARY = {
    # name: (function, exact, domain lower end, domain upper end, domain closed)
    "exp": (ex.exp, mpmath.exp, -INF, INF, False),
    "exp2": (ex.exp2, lambda v: mpmath.power(2, v), -INF, INF, False),
    "exp10": (ex.exp10, lambda v: mpmath.power(10, v), -INF, INF, False),
    "expm1": (ex.expm1, mpmath.expm1, -INF, INF, False),
    "log": (ex.log, mpmath.log, 0.0, INF, False),
    "log2": (ex.log2, lambda v: mpmath.log(v, 2), 0.0, INF, False),
    "log10": (ex.log10, mpmath.log10, 0.0, INF, False),
    "log1p": (ex.log1p, mpmath.log1p, -1.0, INF, False),
    "sinh": (ex.sinh, mpmath.sinh, -INF, INF, False),
    "cosh": (ex.cosh, mpmath.cosh, -INF, INF, False),
    "tanh": (ex.tanh, mpmath.tanh, -INF, INF, False),
    "asinh": (ex.asinh, mpmath.asinh, -INF, INF, False),
    "acosh": (ex.acosh, mpmath.acosh, 1.0, INF, True),
    "atanh": (ex.atanh, mpmath.atanh, -1.0, 1.0, False),
    "atan": (ex.atan, mpmath.atan, -INF, INF, False),
}

#: exact range of each function (closure), for clamping checks
RANGE = {"exp": (0, INF), "exp2": (0, INF), "exp10": (0, INF), "expm1": (-1, INF),
         "cosh": (1, INF), "tanh": (-1, 1), "acosh": (0, INF),
         "atan": (-ex.HALF_PI_HI, ex.HALF_PI_HI)}


def in_domain(name: str, a: float) -> bool:
    _f, _e, lo, hi, closed = UNARY[name]
    return lo <= a <= hi if closed else lo < a < hi


def misses_domain(name: str, x: Interval) -> bool:
    _f, _e, lo, hi, closed = UNARY[name]
    xl, xh = float(x.lo), float(x.hi)
    return (xh < lo or xl > hi) if closed else (xh <= lo or xl >= hi)


@pytest.mark.parametrize("name", sorted(UNARY))
@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_unary_contains_exact_image(name, data):
    f, exact, *_ = UNARY[name]
    x = data.draw(intervals())
    z = f(x)
    assert valid(z), (x, z)
    if name in RANGE:
        assert is_empty(z) or (RANGE[name][0] <= float(z.lo) and float(z.hi) <= RANGE[name][1])
    if misses_domain(name, x):
        assert is_empty(z), (x, z)
        return
    a = data.draw(point_in(x))
    assume(in_domain(name, a))
    assert mp_in(exact(mp(a)), z), (name, x, a, z)


@pytest.mark.parametrize("name", sorted(UNARY))
@settings(max_examples=200, deadline=None)
@given(data=st.data())
def test_unary_degenerate_is_tight(name, data):
    """On a point the enclosure is a few ulps wide (4-ulp widening each side plus libm error)."""
    f, exact, lo, hi, closed = UNARY[name]
    # points of the function's domain within [-700, 700] (exp overflows beyond)
    a = data.draw(st.floats(max(lo, -700.0), min(hi, 700.0),
                            exclude_min=not closed and lo >= -700.0,
                            exclude_max=not closed and hi <= 700.0))
    assume(in_domain(name, a))
    z = f(Interval(a))
    v = exact(mp(a))
    assert mp_in(v, z)
    lo, hi = float(z.lo), float(z.hi)
    if abs(v) > 1e-300 and math.isfinite(hi) and math.isfinite(lo):
        assert ulps_apart(lo, hi) <= 24, (name, a, z)


def test_unary_empty_and_out_param():
    for name, (f, *_rest) in UNARY.items():
        assert is_empty(f(EMPTY)), name
        x = Interval([0.5, -1.0, 2.0], [1.0, 1.0, 3.0])
        out = Interval.empty(3)
        r = f(x, out=out)
        assert r is out
        ref = f(x)
        assert np.array_equal(out.lo, ref.lo, equal_nan=True)
        assert np.array_equal(out.hi, ref.hi, equal_nan=True)
        # batched results equal the scalar ones
        for i in range(3):
            s = f(x[i])
            assert np.array_equal(s.lo, ref.lo[i], equal_nan=True), name


# -------------------------------------------------------------------------------------------
# forward, unary: edge cases derived by hand
# -------------------------------------------------------------------------------------------

def test_exp_edges():
    assert same(ex.exp(Interval(-INF, 0)), 0.0, 1.0)
    assert same(ex.exp(Interval(0, INF)), 1.0, INF)
    assert same(ex.exp(ENTIRE), 0.0, INF)
    assert same(ex.exp(Interval(0.0)), 1.0, 1.0)
    assert same(ex.exp(Interval(-0.0)), 1.0, 1.0)
    assert same(ex.exp(Interval(1000.0)), MAX, INF)  # e**1000 overflows: [MAX, inf]
    z = ex.exp(Interval(-1000.0))  # e**-1000 ~ 5e-435 underflows to 0
    assert float(z.lo) == 0.0 and 0.0 < float(z.hi) < 1e-320
    z = ex.exp(Interval(-1.0, 1.0))
    assert mp_in(mpmath.e, z) and mp_in(1 / mpmath.e, z)
    # exp(x) >= 1 + x makes tiny arguments tight
    assert same(ex.exp(Interval(-1e-20)), 1.0 - 2.0**-53, 1.0)


def test_log_edges():
    assert same(ex.log(Interval(0, 1)), -INF, 0.0)
    assert same(ex.log(Interval(-0.0, 1)), -INF, 0.0)
    assert is_empty(ex.log(Interval(-2, -1)))
    assert is_empty(ex.log(Interval(-INF, 0)))
    assert is_empty(ex.log(Interval(0.0)))
    z = ex.log(Interval(-1, 4))
    assert float(z.lo) == -INF and mp_in(mpmath.log(4), z)
    assert same(ex.log(Interval(1, INF)), 0.0, INF)
    assert same(ex.log(ENTIRE), -INF, INF)
    assert same(ex.log(Interval(1.0)), 0.0, 0.0)
    z = ex.log(Interval(5e-324, MAX))  # log of the smallest subnormal, of the largest float
    assert mp_in(mpmath.log(mp(5e-324)), z) and mp_in(mpmath.log(mp(MAX)), z)
    assert same(ex.log1p(Interval(-1, 0)), -INF, 0.0)
    assert is_empty(ex.log1p(Interval(-3, -1)))


def test_exact_powers():
    assert same(ex.exp2(Interval(1, 5)), 2.0, 32.0)
    assert same(ex.exp2(Interval(-1074, 1023)), 5e-324, 2.0**1023)
    assert same(ex.exp2(Interval(1024.0)), MAX, INF)
    assert same(ex.exp10(Interval(1, 5)), 10.0, 1e5)
    assert same(ex.exp10(Interval(0, 22)), 1.0, 1e22)
    assert same(ex.log2(Interval(0.5, 8)), -1.0, 3.0)
    assert same(ex.log2(Interval(5e-324, 1)), -1074.0, 0.0)
    assert same(ex.log10(Interval(10, 1e5)), 1.0, 5.0)
    assert same(ex.expm1(Interval(0.0)), 0.0, 0.0)
    z = ex.exp10(Interval(-1.0))  # 0.1 is not a float
    assert mp_in(mpmath.mpf(1) / 10, z) and ulps_apart(float(z.lo), float(z.hi)) <= 24


def test_hyperbolic_edges():
    z = ex.cosh(Interval(-1, 2))  # not monotone: the minimum 1 is at 0
    assert float(z.lo) == 1.0 and mp_in(mpmath.cosh(2), z)
    assert ulps_apart(float(z.hi), float(mpmath.cosh(2))) <= 12
    z = ex.cosh(Interval(-3, -2))
    assert mp_in(mpmath.cosh(2), z) and mp_in(mpmath.cosh(3), z)
    assert float(z.lo) > 3.7  # cosh 2 = 3.76...: the minimum is at -2, not 1
    assert same(ex.cosh(Interval(0.0)), 1.0, 1.0)
    assert same(ex.cosh(ENTIRE), 1.0, INF)
    assert same(ex.cosh(Interval(-1000, 1)), 1.0, INF)
    assert same(ex.cosh(Interval(1000.0)), MAX, INF)
    assert same(ex.sinh(Interval(0.0)), 0.0, 0.0)
    assert same(ex.sinh(ENTIRE), -INF, INF)
    assert same(ex.sinh(Interval(-1000.0, 1000.0)), -INF, INF)
    assert same(ex.sinh(Interval(1e-300)), 1e-300, float(ex.sinh(Interval(1e-300)).hi))
    assert same(ex.tanh(ENTIRE), -1.0, 1.0)
    assert same(ex.tanh(Interval(0, INF)), 0.0, 1.0)
    assert same(ex.tanh(Interval(0.0)), 0.0, 0.0)
    # tanh(x) in ]1 - 2**-53, 1[ for x >= 20: the tightest enclosure
    assert same(ex.tanh(Interval(20, 1e300)), 1.0 - 2.0**-53, 1.0)
    assert same(ex.tanh(Interval(-1e300, -20)), -1.0, -(1.0 - 2.0**-53))


def test_inverse_hyperbolic_edges():
    assert same(ex.asinh(Interval(0.0)), 0.0, 0.0)
    assert same(ex.asinh(ENTIRE), -INF, INF)
    assert same(ex.acosh(Interval(-INF, 1)), 0.0, 0.0)  # only x = 1 is in the domain
    assert is_empty(ex.acosh(Interval(-INF, math.nextafter(1.0, 0.0))))
    assert same(ex.acosh(ENTIRE), 0.0, INF)
    assert same(ex.atanh(Interval(-1, 1)), -INF, INF)
    assert is_empty(ex.atanh(Interval(1.0))) and is_empty(ex.atanh(Interval(1, INF)))
    assert is_empty(ex.atanh(Interval(-INF, -1)))
    assert same(ex.atanh(Interval(0, INF)), 0.0, INF)
    z = ex.atanh(Interval(0.5))
    assert mp_in(mpmath.atanh(0.5), z) and ulps_apart(float(z.lo), float(z.hi)) <= 24
    # reverse
    assert same(ex.asinh_rev(ENTIRE, Interval(-3, 4)), -3.0, 4.0)
    assert same(ex.acosh_rev(Interval(0.0), ENTIRE), 1.0, 1.0)
    assert is_empty(ex.acosh_rev(Interval(-2, -1), ENTIRE))  # acosh >= 0
    assert is_empty(ex.acosh_rev(ENTIRE, Interval(-3, 0.5)))  # acosh needs x >= 1
    assert same(ex.acosh_rev(ENTIRE, Interval(-3, 5)), 1.0, 5.0)
    assert same(ex.atanh_rev(ENTIRE, Interval(-3, 3)), -1.0, 1.0)
    assert is_empty(ex.atanh_rev(ENTIRE, Interval(1, 2)))  # x = 1 is not in the domain
    r = ex.atanh_rev(Interval(0, 0.5), ENTIRE)  # x = tanh(z)
    assert float(r.lo) == 0.0 and mp_in(mpmath.tanh(0.5), r) and float(r.hi) < 0.4622


def test_atan_edges():
    assert same(ex.atan(Interval(0, INF)), 0.0, ex.HALF_PI_HI)
    assert same(ex.atan(ENTIRE), -ex.HALF_PI_HI, ex.HALF_PI_HI)
    assert same(ex.atan(Interval(-INF, 0)), -ex.HALF_PI_HI, 0.0)
    assert same(ex.atan(Interval(0.0)), 0.0, 0.0)
    z = ex.atan(Interval(1.0))
    assert mp_in(MP_PI / 4, z) and ulps_apart(float(z.lo), float(z.hi)) <= 24
    assert float(ex.atan(Interval(1e-300)).hi) == 1e-300  # |atan x| <= |x|


def test_pi_constants():
    assert mp(ex.PI_LO) < MP_PI < mp(ex.PI_HI)
    assert math.nextafter(ex.PI_LO, INF) == ex.PI_HI
    assert mp(ex.HALF_PI_LO) < MP_PI / 2 < mp(ex.HALF_PI_HI)
    assert math.nextafter(ex.HALF_PI_LO, INF) == ex.HALF_PI_HI


# -------------------------------------------------------------------------------------------
# atan2 forward
# -------------------------------------------------------------------------------------------

@settings(max_examples=500, deadline=None)
@given(data=st.data())
def test_atan2_contains_exact_angle(data):
    y, x = data.draw(intervals()), data.draw(intervals())
    z = ex.atan2(y, x)
    assert valid(z)
    assert is_empty(z) or -ex.PI_HI <= float(z.lo) <= float(z.hi) <= ex.PI_HI
    b, a = data.draw(point_in(y)), data.draw(point_in(x))
    assume(not (a == 0 and b == 0))
    assert mp_in(mpmath.atan2(mp(b), mp(a)), z), (y, x, b, a, z)


@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_atan2_is_tight_away_from_the_cut(data):
    """Boxes inside one open quadrant: bounds within a few ulps of the exact extreme angles."""
    sy, sx = data.draw(st.sampled_from([1, -1])), data.draw(st.sampled_from([1, -1]))
    m = st.floats(1e-3, 1e3)
    y = sorted([data.draw(m), data.draw(m)])
    x = sorted([data.draw(m), data.draw(m)])
    ys = Interval(*sorted([sy * y[0], sy * y[1]]))
    xs = Interval(*sorted([sx * x[0], sx * x[1]]))
    z = ex.atan2(ys, xs)
    angles = [mpmath.atan2(mp(float(b)), mp(float(a)))
              for b in (ys.lo, ys.hi) for a in (xs.lo, xs.hi)]
    lo, hi = min(angles), max(angles)  # one open quadrant: extremes at corners
    assert mp(float(z.lo)) <= lo and hi <= mp(float(z.hi))
    assert ulps_apart(float(z.lo), float_dn(lo)) <= 11
    assert ulps_apart(float(z.hi), float_up(hi)) <= 11


def test_atan2_edges():
    pi_ = (ex.PI_LO, ex.PI_HI)
    assert is_empty(ex.atan2(Interval(0.0), Interval(0.0)))
    assert is_empty(ex.atan2(EMPTY, ENTIRE)) and is_empty(ex.atan2(ENTIRE, EMPTY))
    assert same(ex.atan2(ENTIRE, ENTIRE), -ex.PI_HI, ex.PI_HI)
    assert same(ex.atan2(Interval(0.0), Interval(-INF, 0)), *pi_)  # the negative x axis: pi
    assert same(ex.atan2(Interval(0.0), Interval(-2, -1)), *pi_)
    assert same(ex.atan2(Interval(0.0), Interval(0, INF)), 0.0, 0.0)
    assert same(ex.atan2(Interval(0, INF), Interval(0.0)), ex.HALF_PI_LO, ex.HALF_PI_HI)
    assert same(ex.atan2(Interval(-INF, 0), Interval(0.0)), -ex.HALF_PI_HI, -ex.HALF_PI_LO)
    assert same(ex.atan2(Interval(-1, 1), Interval(0.0)), -ex.HALF_PI_HI, ex.HALF_PI_HI)
    # crossing the negative x axis: the hull [-pi, pi]
    assert same(ex.atan2(Interval(-1, 1), Interval(-2, -1)), -ex.PI_HI, ex.PI_HI)
    # touching it from below: the axis itself has angle pi, the points below ~ -pi
    assert same(ex.atan2(Interval(-2, 0), Interval(-3, -1)), -ex.PI_HI, ex.PI_HI)
    # touching it from above: no wrap
    z = ex.atan2(Interval(0, 1), Interval(-2, -1))
    assert float(z.hi) == ex.PI_HI and mp_in(mpmath.atan2(1, -1), z)
    assert float(z.lo) > 2.3  # atan2(1, -1) = 3 pi / 4 = 2.356...
    assert same(ex.atan2(Interval(0, 5), Interval(0, 5)), 0.0, ex.HALF_PI_HI)
    assert same(ex.atan2(Interval(-5, 0), Interval(0, 5)), -ex.HALF_PI_HI, 0.0)
    assert same(ex.atan2(Interval(0, 5), Interval(-5, 0)), ex.HALF_PI_LO, ex.PI_HI)
    assert same(ex.atan2(Interval(0.0), Interval(-1, 1)), 0.0, ex.PI_HI)
    z = ex.atan2(Interval(1.0), Interval(1.0))
    assert mp_in(MP_PI / 4, z) and ulps_apart(float(z.lo), float(z.hi)) <= 24
    z = ex.atan2(Interval(-2, 2), Interval(1, 3))  # symmetric about the x axis
    assert float(z.lo) == -float(z.hi) and mp_in(mpmath.atan(2), z)


# -------------------------------------------------------------------------------------------
# pow forward
# -------------------------------------------------------------------------------------------

def exact_pow(a: float, b: float):
    """IEEE 1788 pow at a point: None outside the domain."""
    if a < 0 or (a == 0 and b <= 0):
        return None
    if a == 0:
        return mp(0)
    return mpmath.power(mp(a), mp(b))


@settings(max_examples=500, deadline=None)
@given(data=st.data())
def test_pow_contains_exact_value(data):
    x, y = data.draw(intervals()), data.draw(intervals())
    z = ex.pow(x, y)
    assert valid(z)
    assert is_empty(z) or float(z.lo) >= 0.0
    xp = meet_positive(x)
    if xp is None:
        assert is_empty(z)
        return
    a, b = data.draw(point_in(xp)), data.draw(point_in(y))
    v = exact_pow(a, b)
    assume(v is not None)
    assert mp_in(v, z), (x, y, a, b, z)


@settings(max_examples=300, deadline=None)
@given(a=st.floats(1e-5, 1e5), b=st.floats(-60, 60))
def test_pow_degenerate_is_tight(a, b):
    z = ex.pow(Interval(a), Interval(b))
    v = mpmath.power(mp(a), mp(b))
    assert mp_in(v, z)
    if 1e-300 < v < 1e300:
        assert ulps_apart(float(z.lo), float(z.hi)) <= 24


def test_pow_edges():
    assert is_empty(ex.pow(Interval(0.0), Interval(-1, 0)))  # 0**y undefined for y <= 0
    assert is_empty(ex.pow(Interval(0.0), Interval(0.0)))
    assert same(ex.pow(Interval(0.0), Interval(-1, 0.5)), 0.0, 0.0)  # only y > 0 counts
    assert same(ex.pow(Interval(0.0), ENTIRE), 0.0, 0.0)
    assert same(ex.pow(Interval(-1, 0), Interval(0.1, 1)), 0.0, 0.0)
    assert is_empty(ex.pow(Interval(-2, -1), Interval(1, 2)))  # negative bases: no domain
    assert same(ex.pow(Interval(0.1, 0.5), Interval(0.0)), 1.0, 1.0)
    assert same(ex.pow(Interval(0, 0.5), Interval(-1, 0)), 1.0, INF)
    assert same(ex.pow(Interval(0, 0.5), Interval(0, 0)), 1.0, 1.0)
    assert same(ex.pow(Interval(1.0), ENTIRE), 1.0, 1.0)
    assert same(ex.pow(Interval(0.5, 2), ENTIRE), 0.0, INF)
    assert same(ex.pow(Interval(4.0), Interval(0.5)), 2.0, 2.0)  # sqrt path, exact
    assert same(ex.pow(Interval(3.0), Interval(2.0)), 9.0, 9.0)
    assert same(ex.pow(Interval(2, 3), Interval(1, 2)), 2.0, 9.0)
    assert same(ex.pow(Interval(0.5, 2), Interval(-1, 1)), 0.5, 2.0)
    assert same(ex.pow(Interval(2, INF), Interval(-1, -1)), 0.0, 0.5)
    assert same(ex.pow(Interval(1e300), Interval(2.0)), MAX, INF)  # overflow
    z = ex.pow(Interval(2.0), Interval(0.5, 3))
    assert mp_in(mpmath.sqrt(2), z) and mp_in(mp(8), z)
    # 0.1**[-0.1, 0.1]: the corners (0.1, 0.1) and (0.1, -0.1)
    z = ex.pow(Interval(0.1, 0.5), Interval(-0.1, 0.1))
    assert mp_in(mpmath.power(mp(0.1), mp(0.1)), z) and mp_in(mpmath.power(mp(0.1), -mp(0.1)), z)


def test_pow_integer_exponent_goes_to_pown():
    alg = pytest.importorskip("boundest.interval.algebraic")
    if not hasattr(alg, "pown"):
        pytest.skip("algebraic.pown not available yet")
    x = Interval(-2, 1)
    for n in (2, np.int64(2), 2.0, np.float64(2.0)):
        z = ex.pow(x, n)
        assert same(z, 0.0, 4.0), (n, z)  # pown: (-2)**2 = 4 counts
    assert same(x ** 2, 0.0, 4.0)
    assert same(ex.pow(Interval(-2, -1), 3), -8.0, -1.0)
    # an Interval exponent keeps IEEE 1788 pow: only x >= 0
    assert same(ex.pow(x, Interval(2.0)), 0.0, 1.0)
    # a non-integer plain number is an interval exponent
    z = ex.pow(Interval(4.0), 0.5)
    assert same(z, 2.0, 2.0)


ETA = 2.0**-1074


def test_pow_integer_float_exponent_beyond_2_63_keeps_negative_bases():
    """Issue 27 item 7: an integer-valued float exponent beyond 2**63 is still an integer, so
    the integer power: (-3..-2)**1e20 is a real number beyond MAX, not the empty set."""
    import boundest as bd

    x = Interval(-3, -2)
    assert same(bd.pow(x, 1e20), MAX, INF)
    assert same(bd.pow(x, 2.0**64), MAX, INF)
    assert same(x**1e300, MAX, INF)
    assert same(x**-1e300, 0.0, ETA)  # positive, below the smallest subnormal
    assert same(ex.pow(x, np.float64(2.0**63)), MAX, INF)
    assert same(x ** (2**64 + 1), -INF, -MAX)  # a Python int of any size, odd: negative
    assert same(Interval(-1, -1) ** 1e300, 1.0, 1.0)


#: Integer-valued floats from 2**52 (spacing 1) to 1e300, and their negatives.
_INT_FLOATS = st.one_of(st.floats(2.0**52, 1e300), st.sampled_from([2.0**62, 2.0**63, 2.0**64]))


@settings(max_examples=200, deadline=None)
@given(data=st.data())
def test_pow_and_operator_with_huge_integer_floats_enclose_the_exact_power(data):
    """Negative, positive and zero-containing bases: ``pow``, ``**`` and the operator with a
    degenerate ``Interval`` exponent are ``pown``, and contain the exact power (its sign from
    the parity, its magnitude possibly beyond the float range)."""
    import boundest as bd
    from boundest.interval import algebraic as alg

    x = data.draw(intervals())
    a = data.draw(point_in(x))
    n = data.draw(_INT_FLOATS) * data.draw(st.sampled_from([1.0, -1.0]))
    assume(not (n < 0 and a == 0.0))
    want = alg.pown(x, n)
    with mpmath.workprec(300):
        v = mpmath.iv.mpf(abs(a)) ** int(n)  # a rigorous enclosure of |a|**n
    lo, hi = (-v.b, -v.a) if a < 0 and int(n) % 2 else (v.a, v.b)  # odd below 2**53 only
    for r in (ex.pow(x, n), bd.pow(x, n), x**n, x ** Interval(n)):
        assert valid(r) and same(r, float(want.lo), float(want.hi)), (x, n, r, want)
        assert mp(float(r.lo)) <= lo and hi <= mp(float(r.hi)), (x, a, n, r)


@pytest.mark.parametrize("n", [2, 3, 5, -1, -2, 0, 2**40 + 1, 2.0**64])
def test_operator_takes_a_degenerate_integer_interval_exponent_as_pown(n):
    """One rule with expressions: ``x ** Interval(n)`` is the integer power for an integer
    ``n`` (negative bases kept), while the named ``pow`` with an ``Interval`` exponent stays
    IEEE 1788 ``pow`` (its conformance vectors: ``pow([-0.1, 0.5], [1, 1]) = [0, 0.5]``)."""
    import boundest as bd
    from boundest.interval import algebraic as alg

    for x in (Interval(-3, -2), Interval(-2, 1.5), Interval(0.5, 3)):
        want = alg.pown(x, n)
        assert same(x ** Interval(n), float(want.lo), float(want.hi)), (x, n)
        assert same(ex.power(x, Interval(n)), float(want.lo), float(want.hi))
        real = ex.pow(x, Interval(n))
        got = bd.pow(x, Interval(n))
        assert np.array_equal([got.lo, got.hi], [real.lo, real.hi], equal_nan=True)
        if float(x.hi) < 0:  # 1788 pow is defined for x >= 0 only
            assert is_empty(real)
    assert is_empty(bd.pow(Interval(-3, -2), Interval(2)))
    assert same(bd.pow(Interval(-0.1, 0.5), Interval(1)), 0.0, 0.5)
    assert same(Interval(-0.1, 0.5) ** Interval(1), -0.1, 0.5)
    # a non-integer or non-degenerate interval exponent is the real power with either spelling
    assert is_empty(Interval(-3, -2) ** Interval(2.5))
    assert is_empty(Interval(-3, -2) ** Interval(2, 3))


# -------------------------------------------------------------------------------------------
# reverse, unary
# -------------------------------------------------------------------------------------------

REV = {
    # name: (reverse, exact forward, domain predicate)
    "exp": (ex.exp_rev, mpmath.exp, lambda a: True),
    "log": (ex.log_rev, mpmath.log, lambda a: a > 0),
    "sinh": (ex.sinh_rev, mpmath.sinh, lambda a: True),
    "cosh": (ex.cosh_rev, mpmath.cosh, lambda a: True),
    "tanh": (ex.tanh_rev, mpmath.tanh, lambda a: True),
    "atan": (ex.atan_rev, mpmath.atan, lambda a: True),
    "asinh": (ex.asinh_rev, mpmath.asinh, lambda a: True),
    "acosh": (ex.acosh_rev, mpmath.acosh, lambda a: a >= 1),
    "atanh": (ex.atanh_rev, mpmath.atanh, lambda a: -1 < a < 1),
}


@pytest.mark.parametrize("name", sorted(REV))
@examples(300, 60)
def test_unary_rev_keeps_every_solution(name, n_examples):
    @settings(max_examples=n_examples, deadline=None)
    @given(data=st.data())
    def check(data):
        rev, exact, dom = REV[name]
        x = data.draw(intervals())
        a = data.draw(point_in(x))
        assume(dom(a))
        # enough bits that f(a) is not rounded onto a float (cosh(1e-296) = 1 + 5e-593)
        with mpmath.workprec(2400):
            v = exact(mp(a))
        z = data.draw(around(v))
        r = rev(z, x)
        assert valid(r)
        assert subset(r, x), (x, z, r)
        assert r.contains(a), (name, x, a, z, r)

    check()


@pytest.mark.parametrize("name", sorted(REV))
@settings(max_examples=200, deadline=None)
@given(data=st.data())
def test_unary_rev_is_tight_on_points(name, data):
    """Z = the tightest enclosure of f(a): the contraction of the entire line is narrow."""
    rev, exact, dom = REV[name]
    # tanh(15) = 1 - 2e-13: not yet saturated
    lo, hi = {"atanh": (-0.999, 0.999), "acosh": (1.001, 15.0)}.get(name, (-15.0, 15.0))
    a = data.draw(st.floats(lo, hi))
    assume(dom(a) and abs(a) > 1e-3)
    z = enclose(exact(mp(a)))
    r = rev(z, Interval(0, INF) if a > 0 else Interval(-INF, 0))
    assert r.contains(a)
    # the width of Z maps to about |dx| = |dz| / f'(a): allow that and a few widening ulps
    w = float(r.width())
    slack = 64 * math.ulp(a) * (1 + abs(a))
    dz = float(z.width())
    deriv = float(mpmath.diff(exact, mp(a)))
    assert w <= dz / abs(deriv) * 2 + slack, (name, a, z, r)


def test_unary_rev_edges():
    e1 = float(mpmath.e)
    assert is_empty(ex.exp_rev(Interval(-1, 0), ENTIRE))  # exp > 0
    assert same(ex.exp_rev(Interval(0, 1), ENTIRE), -INF, 0.0)
    assert same(ex.exp_rev(Interval(1.0), Interval(-5, 5)), 0.0, 0.0)
    r = ex.exp_rev(Interval(1, e1), ENTIRE)
    assert float(r.lo) == 0.0 and r.contains(1.0) and float(r.hi) < 1 + 1e-14
    assert same(ex.exp_rev(Interval(0, INF), Interval(-3, 4)), -3.0, 4.0)
    assert is_empty(ex.exp_rev(EMPTY, ENTIRE)) and is_empty(ex.exp_rev(ENTIRE, EMPTY))
    assert same(ex.log_rev(Interval(-INF, 0), ENTIRE), 0.0, 1.0)
    assert is_empty(ex.log_rev(Interval(-1, 1), Interval(-2, 0)))  # log needs x > 0
    assert same(ex.log_rev(Interval(0.0), Interval(-2, 2)), 1.0, 1.0)
    assert same(ex.log_rev(ENTIRE, Interval(-2, 2)), 0.0, 2.0)
    # cosh: two branches
    c2 = float(mpmath.cosh(2))
    r = ex.cosh_rev(Interval(1, c2), Interval(-3, -1))
    assert float(r.hi) == -1.0 and mp(float(r.lo)) <= -2 and float(r.lo) > -2.0001
    r = ex.cosh_rev(Interval(1, c2), ENTIRE)
    assert mp(float(r.lo)) <= -2 and mp(float(r.hi)) >= 2 and float(r.hi) < 2.0001
    c1 = float(mpmath.cosh(1))
    assert is_empty(ex.cosh_rev(Interval(c1, c2), Interval(-0.5, 0.5)))  # the gap ]-1, 1[
    r = ex.cosh_rev(Interval(c1, c2), Interval(-1.5, 3))  # hull of [-1.5, -1] and [1, 2]
    assert float(r.lo) == -1.5 and 2 <= mp(float(r.hi)) < 2.0001
    assert is_empty(ex.cosh_rev(Interval(0, 0.5), ENTIRE))
    assert same(ex.cosh_rev(Interval(1.0), ENTIRE), 0.0, 0.0)
    assert same(ex.cosh_rev(Interval(0, INF), Interval(-3, 4)), -3.0, 4.0)
    # tanh and atan: open ranges
    assert is_empty(ex.tanh_rev(Interval(1.0), ENTIRE))
    assert is_empty(ex.tanh_rev(Interval(-5, -1), ENTIRE))
    assert same(ex.tanh_rev(Interval(-1, 1), Interval(-7, 9)), -7.0, 9.0)
    assert same(ex.tanh_rev(Interval(0, 1), ENTIRE), 0.0, INF)
    assert is_empty(ex.atan_rev(Interval(ex.HALF_PI_HI, 2), ENTIRE))
    assert same(ex.atan_rev(Interval(-2, 2), Interval(-7, 9)), -7.0, 9.0)
    r = ex.atan_rev(Interval(0, ex.HALF_PI_LO), ENTIRE)  # HALF_PI_LO < pi/2: tan is finite
    assert float(r.lo) == 0.0 and 1e16 < float(r.hi) < INF
    r = ex.atan_rev(enclose(MP_PI / 4), ENTIRE)
    assert r.contains(1.0) and float(r.width()) < 1e-14
    assert same(ex.sinh_rev(ENTIRE, Interval(-1, 2)), -1.0, 2.0)
    assert same(ex.sinh_rev(Interval(0.0), ENTIRE), 0.0, 0.0)
    for rev, _f, _d in REV.values():
        assert is_empty(rev(EMPTY, ENTIRE)) and is_empty(rev(ENTIRE, EMPTY))


# -------------------------------------------------------------------------------------------
# reverse, atan2
# -------------------------------------------------------------------------------------------

@settings(max_examples=500, deadline=None)
@given(data=st.data())
def test_atan2_rev_keeps_every_solution(data):
    y, x = data.draw(intervals()), data.draw(intervals())
    b, a = data.draw(point_in(y)), data.draw(point_in(x))
    assume(not (a == 0 and b == 0))
    z = data.draw(around(mpmath.atan2(mp(b), mp(a))))
    y2, x2 = ex.atan2_rev(z, y, x)
    assert valid(y2) and valid(x2)
    assert subset(y2, y) and subset(x2, x)
    assert y2.contains(b) and x2.contains(a), (z, y, x, b, a, y2, x2)


@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_atan2_rev_narrow_angle_contracts(data):
    """A narrow angle interval inside a quadrant contracts the box to the cone's hull."""
    t = data.draw(st.floats(-3.1, 3.1))
    assume(min(abs(t - k * math.pi / 2) for k in range(-2, 3)) > 1e-3)
    z = Interval(t, math.nextafter(t, INF) + 1e-9)
    box = Interval(-10, 10)
    y2, x2 = ex.atan2_rev(z, box, box)
    c, s = math.cos(t), math.sin(t)
    # points r (cos t', sin t') with r up to where the ray leaves the box
    r = 10 / max(abs(c), abs(s))
    px, py = r * c, r * s
    assert x2.contains(0.0) and y2.contains(0.0)  # the cone's apex is a limit point
    assert x2.contains(px * (1 - 1e-6)) and y2.contains(py * (1 - 1e-6))
    # the other side of the origin is cut away
    assert not x2.contains(-px * 0.5) and not y2.contains(-py * 0.5)
    # and the widths are those of the segment, up to the angle width
    assert float(x2.width()) <= abs(px) * (1 + 1e-6) + 1e-6
    assert float(y2.width()) <= abs(py) * (1 + 1e-6) + 1e-6


def test_atan2_rev_edges():
    box = Interval(-10, 10)
    # the whole circle: identity (box minus nothing)
    y2, x2 = ex.atan2_rev(Interval(-ex.PI_HI, ex.PI_HI), box, box)
    assert same(y2, -10.0, 10.0) and same(x2, -10.0, 10.0)
    # pi/4: the diagonal of the box part in quadrant I
    y2, x2 = ex.atan2_rev(enclose(MP_PI / 4), Interval(0, 5), Interval(0, 10))
    assert float(y2.lo) == 0.0 and float(x2.lo) == 0.0
    assert 5 <= float(x2.hi) < 5 + 1e-12 and float(y2.hi) == 5.0
    # a box in quadrant II cannot have angles in [0.1, 0.2]
    y2, x2 = ex.atan2_rev(Interval(0.1, 0.2), Interval(1, 2), Interval(-5, -1))
    assert is_empty(y2) and is_empty(x2)
    # angle pi/2 (enclosure): the positive y axis
    y2, x2 = ex.atan2_rev(Interval(ex.HALF_PI_LO, ex.HALF_PI_HI), Interval(-1, 1), box)
    assert float(y2.lo) == 0.0 and float(y2.hi) == 1.0 and float(x2.width()) < 1e-15
    assert x2.contains(0.0)
    # angles near pi: only y >= 0 (the angle pi is on the axis, -pi is not reached)
    y2, x2 = ex.atan2_rev(Interval(3.0, ex.PI_HI), Interval(-1, 1), box)
    assert float(y2.lo) == 0.0 and float(x2.hi) <= 0.0 and float(x2.lo) == -10.0
    assert 0.14 < float(y2.hi) <= 1.0  # tan(pi - 3) * 10 = 1.43 > 1: y up to 1
    # angle 0: the positive x axis
    y2, x2 = ex.atan2_rev(Interval(0.0), box, box)
    assert same(y2, 0.0, 0.0) and same(x2, 0.0, 10.0)
    # only the origin is left: empty
    y2, x2 = ex.atan2_rev(Interval(0.1, 0.2), Interval(-1, 0), Interval(-1, 0))
    assert is_empty(y2) and is_empty(x2)
    y2, x2 = ex.atan2_rev(Interval(-5, 5), Interval(0.0), Interval(0.0))
    assert is_empty(y2) and is_empty(x2)
    # angles outside [-pi, pi]
    y2, x2 = ex.atan2_rev(Interval(4, 5), box, box)
    assert is_empty(y2) and is_empty(x2)
    y2, x2 = ex.atan2_rev(EMPTY, box, box)
    assert is_empty(y2) and is_empty(x2)


# -------------------------------------------------------------------------------------------
# reverse, pow
# -------------------------------------------------------------------------------------------

@examples(500, 100)
def test_pow_rev_keeps_every_solution(n_examples):
    @settings(max_examples=n_examples, deadline=None)
    @given(data=st.data())
    def check(data):
        x, y = data.draw(intervals()), data.draw(intervals())
        xp = meet_positive(x)
        assume(xp is not None)
        a, b = data.draw(point_in(xp)), data.draw(point_in(y))
        v = exact_pow(a, b)
        assume(v is not None)
        z = data.draw(around(v))
        x2, y2 = ex.pow_rev(z, x, y)
        assert valid(x2) and valid(y2)
        assert subset(x2, x) and subset(y2, y)
        assert x2.contains(a) and y2.contains(b), (z, x, y, a, b, x2, y2)

    check()


@settings(max_examples=200, deadline=None)
@given(a=st.floats(0.01, 100), b=st.floats(-5, 5))
def test_pow_rev_recovers_points(a, b):
    """With the other argument known, the contraction is narrow (log-space rounding only)."""
    assume(abs(b) > 1e-3 and abs(a - 1) > 1e-3)
    z = enclose(mpmath.power(mp(a), mp(b)))
    x2, _ = ex.pow_rev(z, Interval(0, INF), Interval(b))
    _, y2 = ex.pow_rev(z, Interval(a), ENTIRE)
    assert x2.contains(a) and y2.contains(b)
    assert float(x2.width()) <= 1e-12 * a * (1 + 1 / abs(b))
    assert float(y2.width()) <= 1e-12 * (1 + abs(b)) / abs(math.log(a))


def test_pow_rev_edges():
    x2, y2 = ex.pow_rev(Interval(4.0), Interval(0, 10), Interval(2.0))
    assert x2.contains(2.0) and float(x2.width()) < 1e-14 and same(y2, 2.0, 2.0)
    # z = 0: x = 0 with y > 0
    x2, y2 = ex.pow_rev(Interval(0.0), Interval(0, 1), Interval(1, 2))
    assert same(x2, 0.0, 0.0) and same(y2, 1.0, 2.0)
    x2, y2 = ex.pow_rev(Interval(0.0), Interval(0, 1), Interval(-2, 0))
    assert is_empty(x2) and is_empty(y2)
    x2, y2 = ex.pow_rev(Interval(0.0), Interval(-1, 1), Interval(-2, 3))
    assert same(x2, 0.0, 0.0) and same(y2, 0.0, 3.0)
    # z = 1: y = 0 (any x > 0) or x = 1 (any y)
    x2, y2 = ex.pow_rev(Interval(1.0), Interval(2, 3), ENTIRE)
    assert same(x2, 2.0, 3.0) and same(y2, 0.0, 0.0)
    x2, y2 = ex.pow_rev(Interval(1.0), Interval(1.0), Interval(-4, 7))
    assert same(x2, 1.0, 1.0) and same(y2, -4.0, 7.0)
    # x <= 1 and y >= 0 give z <= 1: z in [2, 4] impossible
    x2, y2 = ex.pow_rev(Interval(2, 4), Interval(0, 1), Interval(0, INF))
    assert is_empty(x2) and is_empty(y2)
    # negative z, negative x: outside the domain
    x2, y2 = ex.pow_rev(Interval(-2, -1), ENTIRE, ENTIRE)
    assert is_empty(x2) and is_empty(y2)
    x2, y2 = ex.pow_rev(ENTIRE, Interval(-3, -1), ENTIRE)
    assert is_empty(x2) and is_empty(y2)
    x2, y2 = ex.pow_rev(ENTIRE, ENTIRE, ENTIRE)
    assert same(x2, 0.0, INF) and same(y2, -INF, INF)
    # y in [-4, -2], z in [1/4, 1/2]: x = z**(1/y) in [2**(1/4), 2]
    x2, y2 = ex.pow_rev(Interval(0.25, 0.5), ENTIRE, Interval(-4, -2))
    assert mp(float(x2.lo)) <= mpmath.root(2, 4) and 2 <= float(x2.hi) < 2 + 1e-14
    assert float(x2.lo) > 1.189
    for args in ((EMPTY, ENTIRE, ENTIRE), (ENTIRE, EMPTY, ENTIRE), (ENTIRE, ENTIRE, EMPTY)):
        x2, y2 = ex.pow_rev(*args)
        assert is_empty(x2) and is_empty(y2)


# -------------------------------------------------------------------------------------------
# forward, unary: whole arrays (the SIMD loops), out= and layouts, glibc values (the engine)
# -------------------------------------------------------------------------------------------
# The forward functions evaluate NumPy's ufunc at the bounds of the whole array and then run a
# compiled loop: the hypothesis tests above exercise one element at a time (the scalar tail of
# that loop), these ones long arrays (its SIMD body) with every kind of element mixed.

_EDGE = [0.0, -0.0, 1.0, -1.0, 0.5, -0.5, 2.0, -2.0, 20.0, -20.0, 1e-300, -1e-300, 5e-324,
         -5e-324, 2.0**-1022, 1e-20, -1e-20, 2.0**-27, 709.78, 710.5, -745.2, 1023.0, 1024.0,
         -1074.0, 22.0, 1e22, 1e300, -1e300, MAX, -MAX, math.nextafter(1.0, 0.0),
         math.nextafter(1.0, 2.0), math.nextafter(-1.0, 0.0)]


def batch(n: int = 400, seed: int = 0) -> Interval:
    """``n`` random intervals of mixed magnitudes, widths and signs, edge values, infinite bounds
    and degenerate ones, followed by one empty interval."""
    rng = np.random.default_rng(seed)
    lo, hi = [], []
    for _ in range(n):
        kind = int(rng.integers(0, 10))
        a = float(rng.choice([-1.0, 1.0]) * 10.0 ** rng.uniform(-12, 3))
        if kind == 0:
            a = float(rng.choice(_EDGE))
        elif kind == 1:
            a = float(rng.choice([-1.0, 1.0]) * 10.0 ** rng.uniform(-300, 300))
        w = (0.0 if kind < 3 else abs(a) * 10.0 ** rng.uniform(-16, -1) if kind < 6
             else float(rng.uniform(0, 5)))
        b = a + w
        if kind == 9:
            a, b = [(-INF, b), (a, INF), (-INF, INF)][int(rng.integers(0, 3))]
        lo.append(min(a, b) if min(a, b) < INF else MAX)
        hi.append(max(a, b))
    return Interval.trusted(np.array([*lo, math.nan]), np.array([*hi, math.nan]))


def sample_points(xl: float, xh: float, rng: np.random.Generator) -> list[float]:
    """The (finite) ends of [xl, xh] and a point between them."""
    a, b = max(xl, -MAX), min(xh, MAX)
    return [a, b, float(rng.uniform(a, b)) if math.isfinite(b - a) else 0.5 * a + 0.5 * b]


def check_batch(name: str, x: Interval, z: Interval) -> None:
    """Soundness of every element of ``z = f(x)`` at sampled points, range and emptiness."""
    _f, exact, *_ = UNARY[name]
    rng = np.random.default_rng(1)
    assert valid(z)
    for i in range(x.lo.size):
        xl, xh = float(x.lo[i]), float(x.hi[i])
        zi = z[i]
        if math.isnan(xl) or misses_domain(name, Interval(xl, xh)):
            assert is_empty(zi), (name, xl, xh, zi)
            continue
        if name in RANGE:
            assert RANGE[name][0] <= float(zi.lo) and float(zi.hi) <= RANGE[name][1]
        for a in sample_points(xl, xh, rng):
            if in_domain(name, a):
                v = exact(mp(a))
                assert mp_in(v, zi), (name, xl, xh, a, zi)
                if xl == xh and abs(v) > 1e-300 and math.isfinite(float(zi.hi)) and \
                        math.isfinite(float(zi.lo)):
                    assert ulps_apart(float(zi.lo), float(zi.hi)) <= 24, (name, a, zi)


@pytest.mark.parametrize("name", sorted(UNARY))
def test_unary_whole_array_contains_exact_image(name):
    x = batch()
    check_batch(name, x, UNARY[name][0](x))


@pytest.mark.parametrize("name", sorted(UNARY))
def test_unary_out_and_layouts(name):
    """``out=`` (written directly, or through a copy when it overlaps the argument or is small),
    non-contiguous, 2-D, Fortran-ordered and broadcast bounds give the same bounds."""
    f = UNARY[name][0]
    n = 5000  # above explog._DIRECT_MIN: NumPy writes into out, the loop updates it in place
    x = batch(n - 1, seed=2)
    ref = f(x)

    def same_as_ref(r: Interval, shape=(n,)) -> None:
        assert r.lo.shape == shape
        assert np.array_equal(r.lo.ravel(), ref.lo, equal_nan=True)
        assert np.array_equal(r.hi.ravel(), ref.hi, equal_nan=True)

    out = Interval.trusted(np.empty(n), np.empty(n))
    assert f(x, out=out) is out
    same_as_ref(out)
    y = Interval.trusted(x.lo.copy(), x.hi.copy())
    f(y, out=y)  # in place
    same_as_ref(y)
    y = Interval.trusted(x.lo.copy(), x.hi.copy())
    f(y, out=Interval.trusted(y.hi, np.empty(n)))  # out.lo is the argument's upper bound
    same_as_ref(Interval.trusted(y.hi, f(x).hi))
    big = np.empty((4, n))
    big[0], big[2] = x.lo, x.hi
    xs = Interval.trusted(big[0::2].T[:, 0], big[0::2].T[:, 1])  # strided views
    same_as_ref(f(xs))
    outs = Interval.trusted(np.empty(2 * n)[::2], np.empty(2 * n)[1::2])
    f(xs, out=outs)
    same_as_ref(outs)
    small = Interval.trusted(np.empty(10), np.empty(10))  # below _DIRECT_MIN: copied
    f(x[:10], out=small)
    assert np.array_equal(small.lo, ref.lo[:10], equal_nan=True)
    same_as_ref(f(Interval.trusted(x.lo.reshape(50, 100), x.hi.reshape(50, 100))), (50, 100))
    xf = Interval.trusted(np.asfortranarray(x.lo.reshape(50, 100)),
                       np.asfortranarray(x.hi.reshape(50, 100)))
    r = f(xf)
    assert np.array_equal(r.lo, ref.lo.reshape(50, 100), equal_nan=True)
    assert np.array_equal(r.hi, ref.hi.reshape(50, 100), equal_nan=True)
    # bounds of different shapes broadcast together: [0.5, 1], [0.5, 2]
    r = f(Interval.trusted(np.array([0.5]), np.array([[1.0], [2.0]])))
    assert r.lo.shape == (2, 1)
    for j, h in enumerate((1.0, 2.0)):
        s = f(Interval(0.5, h))
        assert float(r.lo[j, 0]) == float(s.lo) and float(r.hi[j, 0]) == float(s.hi)


def test_exact_values_on_whole_arrays():
    k = np.arange(-1074.0, 1024.0)
    p = np.array([math.ldexp(1.0, int(v)) for v in k])  # every power of two, subnormals too
    assert same_arrays(ex.exp2(Interval(k)), p, p)
    assert same_arrays(ex.log2(Interval(p)), k, k)
    t = np.arange(23.0)
    e = np.array([float(10**j) for j in range(23)])
    assert same_arrays(ex.exp10(Interval(t)), e, e)
    assert same_arrays(ex.log10(Interval(e)), t, t)
    # non-integers, neighbours of the powers and integers without a float power are not exact
    # (the neighbours of subnormal powers of two can be powers of two themselves)
    pn = p[k >= -1021]
    for z in (ex.exp2(Interval(k[:-1] + 0.5)), ex.log2(Interval(np.nextafter(pn, INF))),
              ex.log2(Interval(np.nextafter(pn, 0.0))), ex.log10(Interval(e[1:] * 3.0)),
              ex.log10(Interval(np.nextafter(e, INF))), ex.exp10(Interval(np.arange(23.0, 300))),
              ex.exp10(Interval(-np.arange(1.0, 300.0))), ex.exp10(Interval(t + 0.5))):
        assert np.all(z.lo < z.hi)
    v = np.nextafter(e, INF)
    z = ex.log10(Interval(v))
    assert np.all(z.hi > t) and all(mp_in(mpmath.log10(mp(v[j])), z[j]) for j in range(23))
    # the other exact values at 0 and 1, in arrays
    one = Interval(np.ones(64))
    zero = Interval(np.zeros(64))
    for f, x, v in ((ex.exp, zero, 1.0), (ex.expm1, zero, 0.0), (ex.log, one, 0.0),
                    (ex.log1p, zero, 0.0), (ex.sinh, zero, 0.0), (ex.cosh, zero, 1.0),
                    (ex.tanh, zero, 0.0), (ex.atan, zero, 0.0), (ex.asinh, zero, 0.0),
                    (ex.acosh, one, 0.0), (ex.atanh, zero, 0.0), (ex.log2, one, 0.0),
                    (ex.log10, one, 0.0), (ex.exp2, zero, 1.0), (ex.exp10, zero, 1.0)):
        assert same_arrays(f(x), v, v), f


def same_arrays(z: Interval, lo, hi) -> bool:
    return bool(np.array_equal(z.lo, np.broadcast_to(lo, z.lo.shape))
                and np.array_equal(z.hi, np.broadcast_to(hi, z.hi.shape)))


@pytest.mark.parametrize("name", ["exp", "log", "sinh", "cosh", "tanh", "atan"])
def test_engine_bounds_with_glibc_values(name):
    """The compiled propagation engine feeds the same bounds functions with glibc's values."""
    x = batch(300, seed=3)
    check_batch(name, x, engine_forward(name, x))
