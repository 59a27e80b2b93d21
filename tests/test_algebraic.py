"""Soundness and tightness of the algebraic family (boundest.interval.algebraic).

Forward functions: every point of the argument, evaluated exactly (``Fraction``; mpmath interval
arithmetic at 300 bits for huge exponents), must lie in the computed enclosure. Backward
operators: points x in X (and y in Y) with z = f(x, y) computed exactly and Z a float interval
around z (sometimes widened) must survive the contraction, and the results must be subsets of
the inputs. Edge cases use values derived by hand; tightness is checked against independent
exact references (Fractions, mpmath); tests/test_itf1788.py checks the ITF1788 vectors.
"""

from __future__ import annotations

import math
import sys
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from boundest import Interval
from boundest.interval import algebraic as alg

from .checks import exact_in, is_empty, same, subset, valid
from .strategies import intervals, point_in, ulps_apart

mpmath.mp.prec = 256
INF = math.inf
MAX = sys.float_info.max
ETA = 2.0**-1074
EMPTY = Interval.empty()
ENTIRE = Interval.entire()


# -------------------------------------------------------------------------------------------
# helpers
# -------------------------------------------------------------------------------------------

def mp_in(v: mpmath.mpf, x: Interval) -> bool:
    lo, hi = float(x.lo), float(x.hi)
    if math.isnan(lo):
        return False
    return mpmath.mpf(lo) <= v <= mpmath.mpf(hi)


def point_in_result(a: float, x: Interval) -> bool:
    lo, hi = float(x.lo), float(x.hi)
    return lo <= a <= hi  # False for an empty result










def f_dn(q: Fraction) -> float:
    """Largest float <= q (``MAX`` when q > MAX, ``-inf`` below -MAX)."""
    if q > Fraction(MAX):
        return MAX
    if q < -Fraction(MAX):
        return -INF
    f = float(q)
    if Fraction(f) > q:
        f = math.nextafter(f, -INF)
    return f


def f_up(q: Fraction) -> float:
    return -f_dn(-q)


def mp_dn(v: mpmath.mpf) -> float:
    """Largest float <= the mpmath value v (v finite, within the float range)."""
    f = float(v)
    if mpmath.mpf(f) > v:
        f = math.nextafter(f, -INF)
    return f


def mp_up(v: mpmath.mpf) -> float:
    return -mp_dn(-v)


def enclose(q: Fraction) -> Interval:
    return Interval(f_dn(q), f_up(q))


@st.composite
def z_around(draw, q: Fraction) -> Interval:
    """A float interval containing the exact value ``q``: tight, or widened at random."""
    z = enclose(q)
    if draw(st.booleans()):
        w = draw(intervals())
        z = Interval(min(float(z.lo), float(w.lo)), max(float(z.hi), float(w.hi)))
    return z


def check_rev1(x: Interval, xr: Interval, a: float) -> None:
    assert valid(xr)
    assert subset(xr, x), (x, xr)
    assert point_in_result(a, xr), (x, xr, a)


# -------------------------------------------------------------------------------------------
# forward: soundness
# -------------------------------------------------------------------------------------------

def _sign(a: float) -> float:
    return 1.0 if a > 0 else (-1.0 if a < 0 else 0.0)


UNARY = {
    "abs": (alg.abs, lambda a: Fraction(a) if a >= 0 else -Fraction(a)),
    "sign": (alg.sign, lambda a: Fraction(_sign(a))),
    "floor": (alg.floor, lambda a: Fraction(math.floor(a))),
    "ceil": (alg.ceil, lambda a: Fraction(math.ceil(a))),
    "trunc": (alg.trunc, lambda a: Fraction(math.trunc(a))),
}


@pytest.mark.parametrize("name", sorted(UNARY))
@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_unary_contains_exact_and_is_exact_hull(name, data):
    f, exact = UNARY[name]
    x = data.draw(intervals())
    a = data.draw(point_in(x))
    r = f(x)
    assert valid(r)
    assert exact_in(exact(a), r), (x, a, r)
    # these functions are exact: the bounds are attained (or are the infinite limits)
    lo, hi = float(x.lo), float(x.hi)
    if name in ("floor", "ceil", "trunc"):
        g = {"floor": math.floor, "ceil": math.ceil, "trunc": math.trunc}[name]
        want = (lo if lo == -INF else float(g(lo)), hi if hi == INF else float(g(hi)))
    elif name == "abs":
        mag = max(-lo, hi)
        mig = 0.0 if lo <= 0 <= hi else min(abs(lo), abs(hi))
        want = (mig, mag)
    else:
        want = (_sign(lo), _sign(hi))
    assert same(r, *want), (x, r, want)


@pytest.mark.parametrize("name", ["min", "max"])
@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_min_max_contain_exact(name, data):
    f = alg.min if name == "min" else alg.max
    g = min if name == "min" else max
    x, y = data.draw(intervals()), data.draw(intervals())
    a, b = data.draw(point_in(x)), data.draw(point_in(y))
    r = f(x, y)
    assert valid(r)
    assert point_in_result(g(a, b), r)
    assert same(r, g(float(x.lo), float(y.lo)), g(float(x.hi), float(y.hi)))


@settings(max_examples=400, deadline=None)
@given(data=st.data())
def test_pown_contains_exact(data):
    x = data.draw(intervals())
    n = data.draw(st.one_of(st.integers(-12, 12), st.integers(-60, 60)))
    a = data.draw(point_in(x))
    assume(not (n < 0 and a == 0.0))
    r = alg.pown(x, n)
    assert valid(r)
    assert exact_in(Fraction(a) ** n, r), (x, n, a, r)


@settings(max_examples=200, deadline=None)
@given(a=st.floats(min_value=0.5, max_value=2.0), n=st.integers(2**20, 2**61),
       neg=st.booleans(), sgn=st.booleans())
def test_pown_huge_exponent_contains_exact(a, n, neg, sgn):
    n = -n if neg else n
    a = -a if sgn else a
    r = alg.pown(Interval(a), n)
    assert valid(r)
    with mpmath.workprec(300):
        v = mpmath.iv.mpf(abs(a)) ** n  # rigorous enclosure of |a|**n at 300 bits
        lo, hi = v.a, v.b
        if a < 0 and n % 2:
            lo, hi = -hi, -lo
        assert mpmath.mpf(float(r.lo)) <= lo and hi <= mpmath.mpf(float(r.hi)), (a, n, r, v)


# Exponents beyond int64 (issue 27 item 7): Python integers of any size and integer-valued
# floats (every float beyond 2**53 is an even integer), around 2**62 .. 2**63 (the kernels'
# int64 range ends there) and far beyond; bases near 1 are the only floats whose powers stay
# in range there.
HUGE_N = st.one_of(
    st.integers(2**62 - 4, 2**63 + 4), st.integers(2**63, 2**1100),
    st.floats(2.0**52, 1e300), st.sampled_from(
        [2**62, 2**62 + 1, 3 * 2**61 + 1, 2**63 - 2, 2**63 - 1, 2**63, 2**63 + 1, 2**64 + 1,
         10**20, 10**20 + 1, 10**300 + 1, 1e20, 2.0**64, 1e300, 2.0**62, 2.0**63]))
NEAR_ONE = st.sampled_from([1.0, 1 - 2**-53, 1 - 2**-52, 1 - 2**-50, 1 + 2**-52, 1 + 2**-51,
                            0.5, 2.0, 5e-324, 1e308])


def mp_pown(a: float, n: int) -> tuple[mpmath.mpf, mpmath.mpf]:
    """A rigorous enclosure (mpmath interval arithmetic, 300 bits) of the real ``a**n``."""
    with mpmath.workprec(300):
        v = mpmath.iv.mpf(abs(a)) ** n
        lo, hi = v.a, v.b
    if a < 0 and n % 2:
        lo, hi = -hi, -lo
    return lo, hi


@st.composite
def huge_pown_case(draw) -> tuple[Interval, float, int | float]:
    """An interval, a point of it and an integer exponent of magnitude >= 2**52."""
    if draw(st.booleans()):
        a = draw(NEAR_ONE) * draw(st.sampled_from([1.0, -1.0]))
        x = Interval(a)
    else:
        x = draw(intervals())
        a = draw(point_in(x))
    n = draw(HUGE_N) * draw(st.sampled_from([1, -1]))
    assume(not (n < 0 and a == 0.0))
    return x, a, n


@settings(max_examples=300, deadline=None)
@given(case=huge_pown_case())
def test_pown_beyond_int64_contains_exact(case):
    """Every integer exponent, however large, is an integer power: the exact real value (its
    sign from the parity, its magnitude over MAX or under the smallest subnormal) is enclosed,
    and outside the float range by the tightest enclosure."""
    x, a, n = case
    r = alg.pown(x, n)
    assert valid(r)
    lo, hi = mp_pown(a, int(n))
    assert mpmath.mpf(float(r.lo)) <= lo and hi <= mpmath.mpf(float(r.hi)), (x, a, n, r)
    if float(x.lo) == float(x.hi):  # a degenerate base: the tightest enclosure out of range
        want = ((MAX, INF) if lo > MAX else (-INF, -MAX) if hi < -MAX
                else (0.0, ETA) if lo > 0 and hi < ETA else (-ETA, 0.0) if lo > -ETA and hi < 0
                else None)
        if want is not None:
            assert (float(r.lo), float(r.hi)) == want, (a, n, r)


@settings(max_examples=200, deadline=None)
@given(case=huge_pown_case())
def test_pown_rev_beyond_int64_keeps_solutions(case):
    x, a, n = case
    lo, hi = mp_pown(a, int(n))
    z = Interval(mp_dn(lo), mp_up(hi))
    check_rev1(x, alg.pown_rev(z, x, n), a)


def test_pown_beyond_int64_examples():
    x = Interval(-3, -2)
    assert same(alg.pown(x, 1e20), MAX, INF)
    assert same(alg.pown(x, 2.0**64), MAX, INF)
    assert same(alg.pown(x, 2**64 + 1), -INF, -MAX)
    assert same(alg.pown(x, -1e300), 0.0, ETA)
    assert same(alg.pown(x, -(2**64 + 1)), -ETA, 0.0)
    assert same(alg.pown(Interval(-1, -1), 2**100 + 1), -1.0, -1.0)
    assert same(alg.pown(Interval(-1, 1), 1e300), 0.0, 1.0)
    assert same(alg.pown(Interval(-2, 0.5), -(2**64 + 1)), -INF, INF)
    assert same(alg.pown(Interval(0, 0.5), 1e300), 0.0, ETA)
    assert is_empty(alg.pown(Interval(0, 0), -1e300))
    # the int64 range ends at 2**63: one beyond it, one inside, the same power here
    assert same(alg.pown(Interval(1 - 2**-53), 2**63 + 1), 0.0, ETA)
    assert same(alg.pown(Interval(1 - 2**-53), 2**63 - 1), 0.0, ETA)
    # arrays of exponents: NumPy integers and floats, and Python integers beyond int64
    r = alg.pown(Interval([-3.0] * 4), np.array([2**70, 2**70 + 1, 2**63 + 1, -(2**63)],
                                                dtype=object))
    assert np.array_equal(r.lo, [MAX, -INF, -INF, 0.0]) and np.array_equal(r.hi,
                                                                            [INF, -MAX, -MAX, ETA])
    r = alg.pown(Interval([-3.0] * 3), np.array([2.0**64, -1e300, 2.0**62]))
    assert np.array_equal(r.lo, [MAX, 0.0, MAX]) and np.array_equal(r.hi, [INF, ETA, INF])
    assert same(alg.pown(x, np.uint64(2**63 + 1)), -INF, -MAX)
    assert same(alg.pown(x, np.int64(-(2**63))), 0.0, ETA)
    assert same(alg.pown_rev(Interval(-3, -2), Interval(-5, 5), 2**64 + 1),
                -1 - 2**-52, -1.0)
    assert is_empty(alg.pown_rev(Interval(-3, -2), Interval(-5, 5), 2.0**64))


@settings(max_examples=400, deadline=None)
@given(a=st.floats(allow_nan=False, allow_infinity=False), n=st.integers(-40, 40))
def test_pown_degenerate_is_tightest(a, n):
    assume(a != 0.0 or n > 0)
    r = alg.pown(Interval(a), n)
    q = Fraction(a) ** n
    lo, hi = float(r.lo), float(r.hi)
    assert exact_in(q, r)
    if abs(q) > Fraction(MAX):
        assert (lo, hi) in ((MAX, INF), (-INF, -MAX))
    elif Fraction(lo) == q:
        assert lo == hi
    else:  # the tightest enclosure of a non-float: adjacent floats (also subnormals)
        assert ulps_apart(lo, hi) == 1, (a, n, lo, hi)


def test_pown_array_exponent_broadcasts():
    r = alg.pown(Interval([2.0, -3.0, 2.0, 0.5]), np.array([1, 3, -2, 0]))
    assert np.array_equal(r.lo, [2.0, -27.0, 0.25, 1.0])
    assert np.array_equal(r.hi, [2.0, -27.0, 0.25, 1.0])
    r = alg.pown(Interval([[1.0, 2.0]], [[3.0, 4.0]]), np.array([[2], [3]]))  # (1,2)x(2,1)
    assert r.shape == (2, 2)
    assert np.array_equal(r.hi, [[9.0, 16.0], [27.0, 64.0]])
    assert same(alg.pown(Interval(-2, 3), 2.0), 0.0, 9.0)  # integral float exponent accepted
    r = alg.pown(Interval([2.0, 2.0]), np.array([3, -1], dtype=np.int32))
    assert np.array_equal(r.lo, [8.0, 0.5]) and np.array_equal(r.hi, [8.0, 0.5])
    assert same(alg.pown(Interval(2.0), np.uint8(3)), 8.0, 8.0)
    for bad in (2.5, "2", True, np.inf, 1e300 + 0.5j, np.array([2, 2.5], dtype=object)):
        with pytest.raises(ValueError):
            alg.pown(Interval(1, 2), bad)


# -------------------------------------------------------------------------------------------
# forward: edge cases derived by hand
# -------------------------------------------------------------------------------------------

@pytest.mark.parametrize("x, n, want", [
    ((-1.0, 1.0), -2, (1.0, INF)),
    ((-2.0, 3.0), 2, (0.0, 9.0)),
    ((-3.0, 2.0), 4, (0.0, 81.0)),
    ((-2.0, 3.0), 3, (-8.0, 27.0)),
    ((-2.0, 3.0), -1, (-INF, INF)),
    ((2.0, 4.0), -1, (0.25, 0.5)),
    ((-4.0, -2.0), -2, (0.0625, 0.25)),
    ((-4.0, -2.0), -3, (-0.125, -0.015625)),
    ((0.0, 4.0), -2, (0.0625, INF)),
    ((-4.0, 0.0), -1, (-INF, -0.25)),
    ((0.0, INF), -2, (0.0, INF)),
    ((-INF, -2.0), -3, (-0.125, 0.0)),
    ((-INF, INF), 0, (1.0, 1.0)),
    ((0.0, 0.0), 0, (1.0, 1.0)),
    ((-INF, INF), 5, (-INF, INF)),
    ((-INF, INF), -4, (0.0, INF)),
    ((MAX, MAX), 2, (MAX, INF)),
    ((-MAX, -MAX), 3, (-INF, -MAX)),
    ((1e-200, 1e-200), 2, (0.0, ETA)),       # 1e-400: below the smallest subnormal
    ((-1e-200, -1e-200), 3, (-ETA, 0.0)),
    ((2.0, 2.0), 1023, (2.0**1023, 2.0**1023)),
    ((2.0, 2.0), 1024, (MAX, INF)),
    ((2.0, 2.0), -1074, (ETA, ETA)),          # exact subnormal
    ((2.0, 2.0), -1075, (0.0, ETA)),
    ((0.5, 0.5), 1074, (ETA, ETA)),
    ((3.0, 3.0), 33, (5559060566555523.0, 5559060566555523.0)),  # 3**33 < 2**53: exact
    ((-1.0, -1.0), 2**61 + 1, (-1.0, -1.0)),
    ((MAX, MAX), -1, (2.0**-1024, 2.0**-1024 + ETA)),
])
def test_pown_edge_cases(x, n, want):
    assert same(alg.pown(Interval(*x), n), *want)


def test_pown_empty_and_pole():
    for n in (-3, -2, -1, 0, 1, 2, 3):
        assert is_empty(alg.pown(EMPTY, n))
    for n in (-3, -2, -1):
        assert is_empty(alg.pown(Interval(0.0, 0.0), n))
        assert is_empty(alg.pown(Interval(-0.0, -0.0), n))


def test_pown_three_pow_34_is_one_ulp():
    r = alg.pown(Interval(3.0), 34)  # 3**34 = 16677181699666569 needs 54 bits
    assert float(r.lo) == 16677181699666568.0 and float(r.hi) == 16677181699666570.0


def test_other_forward_edge_cases():
    assert same(alg.abs(Interval(-3, 2)), 0.0, 3.0)
    assert same(alg.abs(Interval(-INF, -2.2)), 2.2, INF)
    assert same(alg.sign(Interval(0.0, 2.0)), 0.0, 1.0)
    assert same(alg.sign(Interval(-0.0, 0.0)), 0.0, 0.0)
    assert same(alg.sign(ENTIRE), -1.0, 1.0)
    assert same(alg.floor(Interval(-1.1, 2.0)), -2.0, 2.0)
    assert same(alg.ceil(Interval(-1.1, 2.0)), -1.0, 2.0)
    assert same(alg.trunc(Interval(-1.9, 2.2)), -1.0, 2.0)
    assert same(alg.floor(ENTIRE), -INF, INF)
    assert same(alg.min(Interval(1, 5), Interval(2, 4)), 1.0, 4.0)
    assert same(alg.max(Interval(1, 5), ENTIRE), 1.0, INF)
    for f in (alg.abs, alg.sign, alg.floor, alg.ceil, alg.trunc):
        assert is_empty(f(EMPTY))
    for f in (alg.min, alg.max):
        assert is_empty(f(EMPTY, ENTIRE)) and is_empty(f(Interval(1, 2), EMPTY))
    out = Interval.empty(3)
    res = alg.abs(Interval([-1.0, 2.0, -5.0], [0.5, 3.0, -4.0]), out=out)
    assert res is out and np.array_equal(out.lo, [0, 2, 4]) and np.array_equal(out.hi, [1, 3, 5])
    assert abs(Interval(-2, 1)).hi == 2.0  # Interval.__abs__


# -------------------------------------------------------------------------------------------
# backward: soundness
# -------------------------------------------------------------------------------------------

BINARY_REV = {
    "add": (alg.add_rev, lambda a, b: Fraction(a) + Fraction(b)),
    "sub": (alg.sub_rev, lambda a, b: Fraction(a) - Fraction(b)),
    "mul": (alg.mul_rev, lambda a, b: Fraction(a) * Fraction(b)),
    "div": (alg.div_rev, lambda a, b: Fraction(a) / Fraction(b)),
    "min": (alg.min_rev, lambda a, b: Fraction(min(a, b))),
    "max": (alg.max_rev, lambda a, b: Fraction(max(a, b))),
}


@pytest.mark.parametrize("name", sorted(BINARY_REV))
@settings(max_examples=400, deadline=None)
@given(data=st.data())
def test_binary_rev_keeps_solutions(name, data):
    f, exact = BINARY_REV[name]
    x, y = data.draw(intervals()), data.draw(intervals())
    a, b = data.draw(point_in(x)), data.draw(point_in(y))
    assume(not (name == "div" and b == 0.0))
    z = data.draw(z_around(exact(a, b)))
    xr, yr = f(z, x, y)
    check_rev1(x, xr, a)
    check_rev1(y, yr, b)


@pytest.mark.parametrize("name", sorted(BINARY_REV))
@settings(max_examples=200, deadline=None)
@given(data=st.data())
def test_binary_rev_random_domains(name, data):
    """Any Z: results are subsets, valid, empty together, and keep every sampled solution."""
    f, exact = BINARY_REV[name]
    x, y, z = data.draw(intervals()), data.draw(intervals()), data.draw(intervals())
    xr, yr = f(z, x, y)
    assert valid(xr) and valid(yr)
    assert subset(xr, x) and subset(yr, y)
    assert is_empty(xr) == is_empty(yr)
    for _ in range(5):
        a, b = data.draw(point_in(x)), data.draw(point_in(y))
        if name == "div" and b == 0.0:
            continue
        if exact_in(exact(a, b), z):
            assert point_in_result(a, xr) and point_in_result(b, yr), (z, x, y, a, b, xr, yr)


@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_mul_rev_to_pair_keeps_solutions(data):
    """x*y in Z for x, y sampled: x lies in one of the two pieces; pieces are ordered."""
    x, y = data.draw(intervals()), data.draw(intervals())
    a, b = data.draw(point_in(x)), data.draw(point_in(y))
    z = data.draw(z_around(Fraction(a) * Fraction(b)))
    p1, p2 = alg.mul_rev_to_pair(z, y)
    assert valid(p1) and valid(p2)
    assert point_in_result(a, p1) or point_in_result(a, p2), (z, y, a, p1, p2)
    if not is_empty(p2):
        assert not is_empty(p1) and float(p1.lo) <= float(p2.lo)
    # mul_rev's x' is the hull of x intersected with the two pieces
    xr, _ = alg.mul_rev(z, x, y)
    assert subset(xr, x)
    for p in (p1, p2):
        if is_empty(p):
            continue
        lo, hi = max(float(x.lo), float(p.lo)), min(float(x.hi), float(p.hi))
        if lo <= hi:
            assert float(xr.lo) <= lo and hi <= float(xr.hi), (z, x, y, p, xr)


UNARY_REV = {
    "neg": (alg.neg_rev, lambda a: -Fraction(a)),
    "sqr": (alg.sqr_rev, lambda a: Fraction(a) ** 2),
    "abs": (alg.abs_rev, lambda a: abs(Fraction(a))),
    "sign": (alg.sign_rev, lambda a: Fraction(_sign(a))),
    "floor": (alg.floor_rev, lambda a: Fraction(math.floor(a))),
    "ceil": (alg.ceil_rev, lambda a: Fraction(math.ceil(a))),
}


@pytest.mark.parametrize("name", sorted(UNARY_REV))
@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_unary_rev_keeps_solutions(name, data):
    f, exact = UNARY_REV[name]
    x = data.draw(intervals())
    a = data.draw(point_in(x))
    z = data.draw(z_around(exact(a)))
    check_rev1(x, f(z, x), a)


@pytest.mark.parametrize("name", sorted(UNARY_REV))
@settings(max_examples=200, deadline=None)
@given(data=st.data())
def test_unary_rev_random_domains(name, data):
    f, exact = UNARY_REV[name]
    x, z = data.draw(intervals()), data.draw(intervals())
    xr = f(z, x)
    assert valid(xr) and subset(xr, x)
    for _ in range(5):
        a = data.draw(point_in(x))
        if exact_in(exact(a), z):
            assert point_in_result(a, xr), (z, x, a, xr)


@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_sqrt_rev_keeps_solutions(data):
    x = data.draw(intervals())
    assume(float(x.hi) >= 0.0)
    a = data.draw(point_in(Interval(max(float(x.lo), 0.0), float(x.hi))))
    v = mpmath.sqrt(mpmath.mpf(a))
    z = Interval(mp_dn(v), mp_up(v))
    if data.draw(st.booleans()):
        w = data.draw(intervals())
        z = Interval(min(float(z.lo), float(w.lo)), max(float(z.hi), float(w.hi)))
    check_rev1(x, alg.sqrt_rev(z, x), a)


@settings(max_examples=400, deadline=None)
@given(data=st.data())
def test_pown_rev_keeps_solutions(data):
    x = data.draw(intervals())
    n = data.draw(st.one_of(st.integers(-9, 9), st.integers(-40, 40)))
    a = data.draw(point_in(x))
    assume(not (n < 0 and a == 0.0))
    z = data.draw(z_around(Fraction(a) ** n))
    check_rev1(x, alg.pown_rev(z, x, n), a)


@settings(max_examples=200, deadline=None)
@given(data=st.data())
def test_pown_rev_random_domains(data):
    x, z = data.draw(intervals()), data.draw(intervals())
    n = data.draw(st.integers(-9, 9))
    xr = alg.pown_rev(z, x, n)
    assert valid(xr) and subset(xr, x)
    for _ in range(5):
        a = data.draw(point_in(x))
        if (n >= 0 or a != 0.0) and exact_in(Fraction(a) ** n, z):
            assert point_in_result(a, xr), (z, x, n, a, xr)


# -------------------------------------------------------------------------------------------
# backward: tightness against independent exact references
# -------------------------------------------------------------------------------------------

# away from the subnormal range, where the shared division helper steps out blindly
_moderate = st.one_of(st.just(0.0), st.floats(1e-100, 1e6), st.floats(-1e6, -1e-100))
finite_iv = intervals(elements=_moderate, allow_inf=False)


def _ref_hull(x: Interval, pieces: list[tuple[float, float]]) -> tuple[float, float]:
    """hull of X ∩ each (closed float) piece; (nan, nan) when empty."""
    xl, xh = float(x.lo), float(x.hi)
    got = [(max(xl, p), min(xh, q)) for p, q in pieces if max(xl, p) <= min(xh, q)]
    if not got:
        return (math.nan, math.nan)
    return (min(g[0] for g in got), max(g[1] for g in got))


def _same_or_both_empty(r: Interval, want: tuple[float, float]) -> bool:
    if math.isnan(want[0]):
        return is_empty(r)
    return same(r, *want)


@st.composite
def nonzero_iv(draw) -> Interval:
    """A finite interval not containing 0."""
    a, b = sorted([draw(st.floats(1e-100, 1e6)), draw(st.floats(1e-100, 1e6))])
    return Interval(-b, -a) if draw(st.booleans()) else Interval(a, b)


@settings(max_examples=300, deadline=None)
@given(x=finite_iv, y=nonzero_iv(), z=finite_iv)
def test_mul_rev_is_tightest_when_y_excludes_zero(x, y, z):
    yl, yh = float(y.lo), float(y.hi)
    # reference: Z / Y from the four exact corner quotients, rounded outward
    q = [Fraction(c) / Fraction(b) for c in (float(z.lo), float(z.hi)) for b in (yl, yh)]
    want_x = _ref_hull(x, [(f_dn(min(q)), f_up(max(q)))])
    xr, _ = alg.mul_rev(z, x, y)
    assert _same_or_both_empty(xr, want_x), (z, x, y, xr, want_x)


@settings(max_examples=300, deadline=None)
@given(x=intervals(), z=intervals())
def test_sqr_rev_is_tightest(x, z):
    zl, zh = float(z.lo), float(z.hi)
    # the shared sqrt helpers step out blindly on (sub)normal arguments below 2**-960
    assume(not (0 < zl < 2.0**-960 or 0 < zh < 2.0**-960))
    if zh < 0:
        assert is_empty(alg.sqr_rev(z, x))
        return
    sl = mp_dn(mpmath.sqrt(mpmath.mpf(max(zl, 0.0))))
    sh = INF if zh == INF else mp_up(mpmath.sqrt(mpmath.mpf(zh)))
    want = _ref_hull(x, [(-sh, -sl), (sl, sh)])
    assert _same_or_both_empty(alg.sqr_rev(z, x), want), (z, x)


@settings(max_examples=200, deadline=None)
@given(a=st.floats(1e-20, 1e20), n=st.sampled_from([-7, -4, -3, -1, 3, 4, 5, 8, 11]))
def test_pown_rev_is_tight(a, n):
    """The root bounds are the tightest floats around the exact real root (mpmath)."""
    z = enclose(Fraction(a) ** n)
    r = alg.pown_rev(z, Interval(0.0, INF), n)
    zl, zh = mpmath.mpf(float(z.lo)), mpmath.mpf(float(z.hi))
    lo_root = mpmath.root(zh if n < 0 else zl, abs(n))
    hi_root = mpmath.root(zl if n < 0 else zh, abs(n))
    if n < 0:
        lo_root, hi_root = 1 / lo_root, 1 / hi_root
    assert same(r, mp_dn(lo_root), mp_up(hi_root)), (a, n, r)
    assert point_in_result(a, r)


# -------------------------------------------------------------------------------------------
# backward: edge cases derived by hand
# -------------------------------------------------------------------------------------------

def test_add_sub_rev_cases():
    xr, yr = alg.add_rev(Interval(1, 2), Interval(0, 10), Interval(0, 10))
    assert same(xr, 0.0, 2.0) and same(yr, 0.0, 2.0)
    xr, yr = alg.sub_rev(Interval(1, 2), Interval(0, 10), Interval(0, 10))
    assert same(xr, 1.0, 10.0) and same(yr, 0.0, 9.0)
    xr, yr = alg.add_rev(Interval(100, 200), Interval(0, 10), Interval(0, 10))
    assert is_empty(xr) and is_empty(yr)
    xr, yr = alg.add_rev(ENTIRE, Interval(0, 1), Interval(2, 3))
    assert same(xr, 0.0, 1.0) and same(yr, 2.0, 3.0)
    xr, yr = alg.add_rev(Interval(0.1, 0.1), ENTIRE, Interval(0.2, 0.2))
    assert xr.contains(Interval(-0.1)) and float(xr.hi) - float(xr.lo) < 1e-16


def test_mul_rev_cases():
    # the brief's example: |x*y| <= 0.5 < 1
    xr, yr = alg.mul_rev(Interval(1, 2), Interval(-0.5, 0.5), Interval(-1, 1))
    assert is_empty(xr) and is_empty(yr)
    # y straddles 0: x in (-inf, -1] u [1, inf); then y in [1, 2] / [1, 5]
    xr, yr = alg.mul_rev(Interval(1, 2), Interval(0.5, 5), Interval(-1, 1))
    assert same(xr, 1.0, 5.0) and same(yr, f_dn(Fraction(1, 5)), 1.0)
    # 0 in z and 0 in y: x is unconstrained
    xr, yr = alg.mul_rev(Interval(-1, 1), ENTIRE, Interval(-3, 3))
    assert same(xr, -INF, INF) and same(yr, -3.0, 3.0)
    xr, yr = alg.mul_rev(Interval(0, 0), Interval(1, 2), Interval(-3, 3))
    assert same(xr, 1.0, 2.0) and same(yr, 0.0, 0.0)
    xr, yr = alg.mul_rev(Interval(4, 4), ENTIRE, Interval(2, 2))
    assert same(xr, 2.0, 2.0) and same(yr, 2.0, 2.0)
    xr, yr = alg.mul_rev(Interval(1, 1), ENTIRE, Interval(0, 0))  # x*0 = 1: no solution
    assert is_empty(xr) and is_empty(yr)
    xr, yr = alg.mul_rev(Interval(1, 2), Interval(-5, 5), Interval(0, INF))  # x = z/y > 0
    assert same(xr, 0.0, 5.0) and same(yr, f_dn(Fraction(1, 5)), INF)
    for args in ((EMPTY, ENTIRE, ENTIRE), (ENTIRE, EMPTY, ENTIRE), (ENTIRE, ENTIRE, EMPTY)):
        assert all(is_empty(r) for r in alg.mul_rev(*args))


def test_div_rev_cases():
    xr, yr = alg.div_rev(Interval(2, 3), Interval(0, 10), Interval(1, 2))
    assert same(xr, 2.0, 6.0) and same(yr, 1.0, 2.0)
    xr, yr = alg.div_rev(Interval(1, 2), ENTIRE, Interval(0, 0))  # division by 0: no solution
    assert is_empty(xr) and is_empty(yr)
    xr, yr = alg.div_rev(Interval(1, 1), Interval(0, 0), Interval(0, 1))  # 0/y = 1 impossible
    assert is_empty(xr) and is_empty(yr)
    xr, yr = alg.div_rev(Interval(0, 0), Interval(-1, 1), Interval(2, 3))  # x = 0
    assert same(xr, 0.0, 0.0) and same(yr, 2.0, 3.0)
    xr, yr = alg.div_rev(Interval(1, 2), Interval(4, 4), Interval(-10, 10))  # y = 4/z
    assert same(xr, 4.0, 4.0) and same(yr, 2.0, 4.0)


def test_mul_rev_to_pair_cases():
    a, b = alg.mul_rev_to_pair(Interval(1, 2), Interval(-1, 1))
    assert same(a, -INF, -1.0) and same(b, 1.0, INF)
    a, b = alg.mul_rev_to_pair(Interval(1, 2), Interval(2, 4))
    assert same(a, 0.25, 1.0) and is_empty(b)
    a, b = alg.mul_rev_to_pair(Interval(1, 2), Interval(0, 0))
    assert is_empty(a) and is_empty(b)
    a, b = alg.mul_rev_to_pair(Interval(-1, 2), Interval(0, 1))
    assert same(a, -INF, INF) and is_empty(b)
    a, b = alg.mul_rev_to_pair(Interval(-2, -1), Interval(0, 4))
    assert same(a, -INF, -0.25) and is_empty(b)


def test_unary_rev_cases():
    assert same(alg.sqr_rev(Interval(1, 4), Interval(0, 5)), 1.0, 2.0)
    assert same(alg.sqr_rev(Interval(1, 4), Interval(-5, 5)), -2.0, 2.0)
    assert same(alg.sqr_rev(Interval(1, 4), Interval(-5, 1.5)), -2.0, 1.5)
    assert same(alg.sqr_rev(Interval(4, 4), Interval(-INF, 0)), -2.0, -2.0)
    assert same(alg.sqr_rev(Interval(0, 0), Interval(-1, 1)), 0.0, 0.0)
    assert is_empty(alg.sqr_rev(Interval(-4, -1), ENTIRE))
    assert is_empty(alg.sqr_rev(Interval(1, 4), Interval(-0.5, 0.5)))
    s2 = mp_up(mpmath.sqrt(2))  # RN(sqrt 2) happens to lie above sqrt 2
    assert same(alg.sqr_rev(Interval(2, 2), ENTIRE), -s2, s2)
    assert same(alg.sqrt_rev(Interval(1, 2), Interval(-10, 10)), 1.0, 4.0)
    assert same(alg.sqrt_rev(Interval(-1, 2), Interval(-10, 10)), 0.0, 4.0)
    assert is_empty(alg.sqrt_rev(Interval(-2, -1), ENTIRE))
    assert same(alg.abs_rev(Interval(1, 2), Interval(-5, 1.5)), -2.0, 1.5)
    assert same(alg.abs_rev(Interval(-1, 0), Interval(-3, 3)), 0.0, 0.0)
    assert is_empty(alg.abs_rev(Interval(1, 2), Interval(-0.5, 0.5)))
    assert same(alg.neg_rev(Interval(1, 2), Interval(-1.5, 10)), -1.5, -1.0)
    assert same(alg.pown_rev(Interval(-8, 27), Interval(-5, 5), 3), -2.0, 3.0)
    assert same(alg.pown_rev(Interval(1, 4), Interval(-5, 5), 2), -2.0, 2.0)
    assert same(alg.pown_rev(Interval(16, 16), ENTIRE, 4), -2.0, 2.0)
    assert is_empty(alg.pown_rev(Interval(-16, -16), ENTIRE, 4))
    assert same(alg.pown_rev(Interval(0.5, 1), ENTIRE, -1), 1.0, 2.0)
    assert same(alg.pown_rev(Interval(-1, 1), ENTIRE, -1), -INF, INF)
    assert same(alg.pown_rev(Interval(1, 4), Interval(0, 5), -2), 0.5, 1.0)
    assert same(alg.pown_rev(Interval(-1, -0.125), Interval(-5, 5), -3), -2.0, -1.0)
    assert same(alg.pown_rev(Interval(1, 1), Interval(-3, 7), 0), -3.0, 7.0)
    assert is_empty(alg.pown_rev(Interval(2, 3), Interval(-3, 7), 0))
    assert same(alg.pown_rev(Interval(2, 3), Interval(-3, 7), 1), 2.0, 3.0)
    assert same(alg.pown_rev(Interval(0, 0), ENTIRE, 5), 0.0, 0.0)
    assert is_empty(alg.pown_rev(Interval(0, 0), ENTIRE, -5))
    # sqrt(MAX) = 2**512 * sqrt(1 - 2**-53) lies just below 2**512
    assert same(alg.pown_rev(Interval(MAX, INF), Interval(0, INF), 2),
                math.nextafter(2.0**512, 0), INF)
    # x**-3 <= 2**-1074 <=> |x| >= 2**358 (x > 0); the guess of the root is poor down there
    assert same(alg.pown_rev(Interval(0.0, ETA), ENTIRE, -3), 2.0**358, INF)
    assert same(alg.pown_rev(Interval(-ETA, 0.0), ENTIRE, -3), -INF, -(2.0**358))
    assert same(alg.pown_rev(Interval(ETA, ETA), ENTIRE, 1074), -0.5, 0.5)  # (1/2)**1074
    assert same(alg.pown_rev(Interval(ETA, ETA), ENTIRE, -1), MAX, INF)  # 2**1074 > MAX
    r = alg.pown_rev(Interval([8.0, 16.0]), ENTIRE, np.array([3, 4]))
    assert np.array_equal(r.lo, [2.0, -2.0]) and np.array_equal(r.hi, [2.0, 2.0])


def test_sign_floor_ceil_rev_cases():
    assert same(alg.sign_rev(Interval(1, 1), Interval(-2, 3)), 0.0, 3.0)
    assert same(alg.sign_rev(Interval(0, 0), Interval(-2, 3)), 0.0, 0.0)
    assert same(alg.sign_rev(Interval(-1, 0), Interval(-2, 3)), -2.0, 0.0)
    assert is_empty(alg.sign_rev(Interval(-1, -1), Interval(0, 3)))
    assert is_empty(alg.sign_rev(Interval(0.5, 0.7), ENTIRE))
    assert same(alg.floor_rev(Interval(1, 2), Interval(0, 10)), 1.0, 3.0)
    assert is_empty(alg.floor_rev(Interval(0.5, 0.7), ENTIRE))
    assert same(alg.floor_rev(Interval(1, 1), Interval(1.5, 10)), 1.5, 2.0)
    assert is_empty(alg.floor_rev(Interval(1, 1), Interval(2, 3)))
    assert same(alg.floor_rev(Interval(1, 1), Interval(0, 1.5)), 1.0, 1.5)
    assert same(alg.floor_rev(Interval(-INF, 0), ENTIRE), -INF, 1.0)
    assert same(alg.ceil_rev(Interval(1, 2), Interval(0, 10)), 0.0, 2.0)
    assert same(alg.ceil_rev(Interval(1, 1), Interval(0, 1)), 0.0, 1.0)
    assert is_empty(alg.ceil_rev(Interval(1, 1), Interval(-1, 0)))
    assert same(alg.ceil_rev(Interval(1, 1), Interval(0.5, 0.7)), 0.5, 0.7)
    assert same(alg.ceil_rev(Interval(0, INF), ENTIRE), -1.0, INF)


def test_min_max_rev_cases():
    xr, yr = alg.min_rev(Interval(5, 6), Interval(0, 10), Interval(2, 8))
    assert same(xr, 5.0, 10.0) and same(yr, 5.0, 8.0)
    xr, yr = alg.min_rev(Interval(5, 6), Interval(0, 10), Interval(2, 3))
    assert is_empty(xr) and is_empty(yr)
    xr, yr = alg.min_rev(Interval(5, 6), Interval(0, 10), Interval(7, 8))  # y > 6: x = z
    assert same(xr, 5.0, 6.0) and same(yr, 7.0, 8.0)
    xr, yr = alg.max_rev(Interval(5, 6), Interval(0, 10), Interval(2, 8))
    assert same(xr, 0.0, 6.0) and same(yr, 2.0, 6.0)
    xr, yr = alg.max_rev(Interval(5, 6), Interval(0, 10), Interval(0, 3))  # y < 5: x = z
    assert same(xr, 5.0, 6.0) and same(yr, 0.0, 3.0)


def test_rev_empty_and_broadcast_and_out():
    ops2 = (alg.add_rev, alg.sub_rev, alg.mul_rev, alg.div_rev, alg.min_rev, alg.max_rev)
    for f in ops2:
        for args in ((EMPTY, ENTIRE, ENTIRE), (ENTIRE, EMPTY, ENTIRE), (ENTIRE, ENTIRE, EMPTY)):
            assert all(is_empty(r) for r in f(*args)), f
    ops1 = (alg.neg_rev, alg.sqr_rev, alg.sqrt_rev, alg.abs_rev, alg.sign_rev, alg.floor_rev,
            alg.ceil_rev)
    for f in ops1:
        assert is_empty(f(EMPTY, ENTIRE)) and is_empty(f(ENTIRE, EMPTY)), f
    for n in (-2, -1, 0, 1, 2, 3):
        assert is_empty(alg.pown_rev(EMPTY, ENTIRE, n))
        assert is_empty(alg.pown_rev(ENTIRE, EMPTY, n))
    z = Interval([[1.0], [2.0]], [[2.0], [8.0]])  # (2, 1) against (3,)
    x = Interval([0.0, 1.0, 3.0], [5.0, 1.5, 9.0])
    xr, yr = alg.mul_rev(z, x, Interval(1.0, 2.0))
    assert xr.shape == (2, 3) and yr.shape == (2, 3)
    assert same(xr[1, 2], 3.0, 8.0)
    outs = (Interval.empty((2, 3)), Interval.empty((2, 3)))
    res = alg.mul_rev(z, x, Interval(1.0, 2.0), out=outs)
    assert res is outs and np.array_equal(outs[0].lo, xr.lo, equal_nan=True)
    o = Interval.empty(3)
    assert alg.sqr_rev(Interval(4.0, 9.0), x, out=o) is o
    assert np.array_equal(o.lo, [2.0, np.nan, 3.0], equal_nan=True)


def test_in_place_contraction():
    """``out`` may be the contracted argument itself (the usual contractor pattern)."""
    rng = np.random.default_rng(1)
    lo = rng.uniform(-3, 3, 500)
    x0 = Interval(lo, lo + rng.uniform(0, 3, 500))
    y0 = Interval(lo[::-1], lo[::-1] + 1.0)
    z = Interval(np.full(500, 1.0), np.full(500, 4.0))
    want = alg.sqr_rev(z, x0)
    x = x0.copy()
    assert alg.sqr_rev(z, x, out=x) is x
    assert np.array_equal(x.lo, want.lo, equal_nan=True)
    assert np.array_equal(x.hi, want.hi, equal_nan=True)
    wx, wy = alg.mul_rev(z, x0, y0)
    x, y = x0.copy(), y0.copy()
    alg.mul_rev(z, x, y, out=(x, y))
    assert np.array_equal(x.lo, wx.lo, equal_nan=True) and np.array_equal(x.hi, wx.hi,
                                                                          equal_nan=True)
    assert np.array_equal(y.lo, wy.lo, equal_nan=True) and np.array_equal(y.hi, wy.hi,
                                                                          equal_nan=True)
    w = alg.abs(x0)
    x = x0.copy()
    alg.abs(x, out=x)
    assert np.array_equal(x.lo, w.lo) and np.array_equal(x.hi, w.hi)
