"""sin cos tan asin acos and their reverse operators: soundness against mpmath (256 bits),
tightness against exact ranges / preimage hulls, hand-derived edge cases (tests/test_itf1788.py
checks the ITF1788 vectors)."""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from boundest import Interval
from boundest.interval.trig import (
    PI_HI,
    PI_LO,
    PIO2_HI,
    PIO2_LO,
    acos,
    acos_rev,
    asin,
    asin_rev,
    cos,
    cos_rev,
    sin,
    sin_rev,
    tan,
    tan_rev,
)

from .checks import engine_forward, is_empty, valid
from .strategies import point_in, ulps_apart

mpmath.mp.prec = 256
mpf = mpmath.mpf
MPI = mpmath.pi
INF = math.inf
MAX = 1.7976931348623157e308
EMPTY = Interval.empty()
ENTIRE = Interval.entire()


# ---------------------------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------------------------

def bounds(x: Interval) -> tuple[float, float]:
    return float(x.lo), float(x.hi)


def contains(x: Interval, v) -> bool:
    """Whether the exact real ``v`` (mpf) lies in ``x``."""
    lo, hi = bounds(x)
    if math.isnan(lo):
        return False
    return mpf(lo) <= v <= mpf(hi)


def _err(v):
    """A bound on the error of an mpmath value at 256 bits (a few ulps, relative)."""
    return abs(v) * mpf(2) ** -240 + mpf(2) ** -1200


def rd(v) -> float:
    """A float <= the exact value that the mpf ``v`` approximates (v minus its error)."""
    v = v - _err(v)
    f = float(v)
    if mpf(f) > v:
        f = math.nextafter(f, -INF)
    return f


def ru(v) -> float:
    v = v + _err(v)
    f = float(v)
    if mpf(f) < v:
        f = math.nextafter(f, INF)
    return f


def step(v: float, k: int) -> float:
    for _ in range(abs(k)):
        v = math.nextafter(v, INF if k > 0 else -INF)
    return v


def halfpi(k: int) -> float:
    """The float nearest to ``k pi / 2``."""
    return float(mpf(k) * MPI / 2)


# ---------------------------------------------------------------------------------------------
# strategies
# ---------------------------------------------------------------------------------------------

SPECIAL = [0.0, -0.0, 5e-324, -5e-324, 1e-300, -1e-300, 2.0**-30, -(2.0**-27), 1.0, -1.0,
           PIO2_LO, PIO2_HI, -PIO2_LO, PI_LO, PI_HI, -PI_HI, 2 * PI_LO, 2.0**30, -(2.0**30),
           step(2.0**30, 1), 1e15, -1e300, MAX, -MAX]
moderate = st.floats(-20.0, 20.0)
near_critical = st.builds(
    lambda k, s, d: step(halfpi(k), s) + d,
    st.integers(-2000, 2000), st.integers(-4, 4),
    st.sampled_from([0.0, 0.0, 0.0, 1e-13, -1e-13, 1e-9, -1e-9, 1e-5, -1e-5]))
near_threshold = st.floats(-(2.0**31), 2.0**31)
huge = st.one_of(st.floats(1e15, 1e300), st.floats(-1e300, -1e15))
trig_bound = st.one_of(moderate, moderate, near_critical, near_critical, near_threshold, huge,
                       st.sampled_from(SPECIAL))
widths = st.one_of(st.floats(0.0, 7.0), st.floats(0.0, 1e-6),
                   st.sampled_from([0.0, PIO2_LO, PI_LO, PI_HI, 2 * PI_LO, 2 * PI_HI, 6.0, 6.5]))


@st.composite
def trig_intervals(draw, bound=trig_bound):
    """Intervals of widths from 0 to beyond 2 pi, near critical points, huge or unbounded."""
    a = draw(bound)
    kind = draw(st.integers(0, 9))
    if kind == 0:
        b = a
    elif kind <= 5:
        b = a + draw(widths)
    else:
        a, b = sorted([a, draw(bound)])
    if kind == 8:
        a = -INF if draw(st.booleans()) else a
        b = INF if draw(st.booleans()) or a != -INF else b
    elif kind == 9 and draw(st.booleans()):
        a, b = -INF, INF
    if a == INF:
        a = MAX
    if b == -INF:
        b = -MAX
    return Interval(a, b)


def moderate_intervals(limit: float = 1e4):
    """Finite intervals with |bounds| <= limit, widths up to ~2.5 pi."""
    bound = st.one_of(st.floats(-limit, limit), near_critical.filter(lambda v: abs(v) <= limit))
    return st.builds(lambda a, w: Interval(a, min(a + w, limit)),
                     bound.filter(lambda v: v < limit),
                     st.one_of(st.floats(0.0, 8.0), st.floats(0.0, 1e-3), st.just(0.0)))


# ---------------------------------------------------------------------------------------------
# exact references (mpmath)
# ---------------------------------------------------------------------------------------------

def exact_sincos_range(name: str, a: float, b: float):
    """Exact [min, max] of sin or cos over the finite [a, b]."""
    f = mpmath.sin if name == "sin" else mpmath.cos
    lo, hi = mpf(a), mpf(b)
    vals = [f(lo), f(hi)]
    n0 = int(mpmath.ceil(lo * 2 / MPI))
    n1 = int(mpmath.floor(hi * 2 / MPI))
    for n in range(n0, n1 + 1):
        r = (n + (1 if name == "cos" else 0)) % 4
        if r == 1:
            vals.append(mpf(1))
        elif r == 3:
            vals.append(mpf(-1))
    return min(vals), max(vals)


def branches(name: str, zl: float, zh: float, j0: int, j1: int):
    """Exact branches (l, u) of the preimage of [zl, zh] (inside the range) for j0 <= j <= j1."""
    out = []
    if name == "tan":
        p = -MPI / 2 if zl == -INF else mpmath.atan(mpf(zl))
        q = MPI / 2 if zh == INF else mpmath.atan(mpf(zh))
        return [(j * MPI + p, j * MPI + q) for j in range(j0, j1 + 1)]
    zl, zh = max(zl, -1.0), min(zh, 1.0)
    if name == "sin":
        p, q = mpmath.asin(mpf(zl)), mpmath.asin(mpf(zh))
        for j in range(j0, j1 + 1):
            out.append((j * MPI + p, j * MPI + q) if j % 2 == 0 else (j * MPI - q, j * MPI - p))
    else:
        p, q = mpmath.acos(mpf(zh)), mpmath.acos(mpf(zl))
        for j in range(j0, j1 + 1):
            if j % 2 == 0:
                out.append((j * MPI - q, j * MPI - p))
            else:
                out.append(((j - 1) * MPI + p, (j - 1) * MPI + q))
    return out


def exact_rev(name: str, z: Interval, x: Interval, slack=0):
    """Exact hull (lo, hi) of {x in X : f(x) in Z} for finite X, or None when empty. With
    ``slack`` > 0 the branches that come within ``slack`` of X count too (a superset that an
    algorithm working on rounded branch ends may return), the hull still clipped to X."""
    zl, zh = bounds(z)
    xl, xh = mpf(float(x.lo)), mpf(float(x.hi))
    j0 = int(mpmath.floor(xl / MPI)) - 2
    j1 = int(mpmath.ceil(xh / MPI)) + 2
    pieces = []
    for l, u in branches(name, zl, zh, j0, j1):
        if max(l, xl - slack) <= min(u, xh + slack):
            pieces.append((max(l, xl), min(u, xh)))
    if not pieces:
        return None
    return min(p[0] for p in pieces), max(p[1] for p in pieces)


# ---------------------------------------------------------------------------------------------
# forward: soundness
# ---------------------------------------------------------------------------------------------

MP_FUN = {"sin": mpmath.sin, "cos": mpmath.cos, "tan": mpmath.tan,
          "asin": mpmath.asin, "acos": mpmath.acos}
FUN = {"sin": sin, "cos": cos, "tan": tan, "asin": asin, "acos": acos}


@pytest.mark.parametrize("name", ["sin", "cos", "tan"])
@settings(max_examples=400, deadline=None)
@given(data=st.data())
def test_periodic_contains_exact_value(name, data):
    x = data.draw(trig_intervals())
    t = data.draw(point_in(x))
    y = FUN[name](x)
    assert valid(y), (x, y)
    assert contains(y, MP_FUN[name](mpf(t))), (name, x, t, y)
    if name != "tan":
        assert float(y.lo) >= -1.0 and float(y.hi) <= 1.0


@pytest.mark.parametrize("name", ["asin", "acos"])
@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_inverse_contains_exact_value(name, data):
    bound = st.one_of(st.floats(-1.5, 1.5), st.sampled_from([-1.0, 1.0, 0.0, -0.0, 1e-300,
                                                             step(1.0, -1), step(-1.0, 1)]),
                      st.floats(-1e300, 1e300))
    x = data.draw(trig_intervals(bound))
    y = FUN[name](x)
    assert valid(y), (x, y)
    part = Interval(max(float(x.lo), -1.0), min(float(x.hi), 1.0)) if (
        float(x.lo) <= 1.0 and float(x.hi) >= -1.0) else None
    if part is None:
        assert is_empty(y), (x, y)
        return
    t = data.draw(point_in(part))
    assert contains(y, MP_FUN[name](mpf(t))), (name, x, t, y)
    top = PIO2_HI if name == "asin" else PI_HI
    assert float(y.hi) <= top and float(y.lo) >= (-PIO2_HI if name == "asin" else 0.0)


# ---------------------------------------------------------------------------------------------
# forward: tightness
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["sin", "cos"])
@settings(max_examples=400, deadline=None)
@given(x=moderate_intervals())
def test_sincos_encloses_exact_range_tightly(name, x):
    lo, hi = exact_sincos_range(name, *bounds(x))
    y = FUN[name](x)
    assert contains(y, lo) and contains(y, hi), (x, y, lo, hi)
    tol = mpf(4e-15)
    assert mpf(float(y.lo)) >= lo - tol and mpf(float(y.hi)) <= hi + tol, (x, y, lo, hi)


@settings(max_examples=400, deadline=None)
@given(x=moderate_intervals())
def test_tan_encloses_exact_range_tightly(x):
    a, b = bounds(x)
    n0 = int(mpmath.ceil(mpf(a) * 2 / MPI))
    n1 = int(mpmath.floor(mpf(b) * 2 / MPI))
    pole = any(n % 2 for n in range(n0, n1 + 1))
    y = tan(x)
    if pole:
        assert y.is_entire(), (x, y)
        return
    if y.is_entire():  # only allowed when a pole is within rounding of a bound
        k = round(float((mpf(a) + mpf(b)) / (2 * MPI) - mpf(0.5)))
        gaps = [min(abs((j + mpf(0.5)) * MPI - mpf(a)), abs((j + mpf(0.5)) * MPI - mpf(b)))
                for j in (k - 1, k, k + 1)]
        assert min(gaps) < 1e-12, (x, y)
        return
    ta, tb = mpmath.tan(mpf(a)), mpmath.tan(mpf(b))
    assert contains(y, ta) and contains(y, tb)
    assert mpf(float(y.lo)) >= ta - mpf(4e-15) * max(1, abs(ta))
    assert mpf(float(y.hi)) <= tb + mpf(4e-15) * max(1, abs(tb))


@pytest.mark.parametrize("name", ["sin", "cos", "tan", "asin", "acos"])
@settings(max_examples=200, deadline=None)
@given(t=st.floats(-1e6, 1e6))
def test_degenerate_is_within_a_few_ulps(name, t):
    if name in ("asin", "acos"):
        t = math.fmod(t, 1.0)
    y = FUN[name](Interval(t))
    exact = MP_FUN[name](mpf(t))
    assert contains(y, exact)
    assert ulps_apart(float(y.lo), float(y.hi)) <= 24, (t, y)


# ---------------------------------------------------------------------------------------------
# forward: hand-derived edge cases
# ---------------------------------------------------------------------------------------------

def test_forward_edge_cases():
    for f in (sin, cos, tan, asin, acos):
        assert is_empty(f(EMPTY))
    assert bounds(sin(ENTIRE)) == (-1.0, 1.0) and bounds(cos(ENTIRE)) == (-1.0, 1.0)
    assert tan(ENTIRE).is_entire()
    assert bounds(sin(Interval(0.0, INF))) == (-1.0, 1.0)
    assert bounds(cos(Interval(-INF, 0.0))) == (-1.0, 1.0)
    # exact zeros and ones stay exact
    assert bounds(sin(Interval(0.0))) == (0.0, 0.0) and bounds(sin(Interval(-0.0))) == (0, 0)
    assert bounds(cos(Interval(0.0))) == (1.0, 1.0) and bounds(tan(Interval(0.0))) == (0, 0)
    assert bounds(asin(Interval(0.0))) == (0.0, 0.0)
    assert bounds(acos(Interval(1.0))) == (0.0, 0.0)
    # sin([0, pi_hi]): max 1 at pi/2 inside, min 0 at 0 and just below 0 at pi_hi > pi
    y = sin(Interval(0.0, PI_HI))
    assert float(y.hi) == 1.0 and -1e-15 < float(y.lo) <= -1.2e-16
    assert bounds(sin(Interval(0.0, 10.0))) == (-1.0, 1.0)  # [0, 10] holds pi/2 and 3pi/2
    assert bounds(cos(Interval(0.0, 2 * PI_LO))) == (-1.0, 1.0)
    # width >= 2 pi always gives [-1, 1]; huge arguments too (conservative rule)
    assert bounds(sin(Interval(1000.0, 1000.0 + 2 * PI_HI))) == (-1.0, 1.0)
    assert bounds(sin(Interval(1e20))) == (-1.0, 1.0)
    assert bounds(cos(Interval(-1e300, -1e299))) == (-1.0, 1.0)
    assert tan(Interval(1e20)).is_entire()
    # [1, 2] holds pi/2: sin reaches 1, the lower end is sin(1) = 0.84147...; cos is monotone
    y = sin(Interval(1.0, 2.0))
    assert float(y.hi) == 1.0 and abs(float(y.lo) - 0.8414709848078965) < 1e-15
    y = cos(Interval(1.0, 2.0))
    assert abs(float(y.lo) + 0.4161468365471424) < 1e-15
    assert abs(float(y.hi) - 0.5403023058681398) < 1e-15
    # sin over [3pi/2 - 0.1, 3pi/2 + 0.1] reaches -1 exactly, max cos(0.1) - ish
    y = sin(Interval(halfpi(3) - 0.1, halfpi(3) + 0.1))
    assert float(y.lo) == -1.0 and abs(float(y.hi) + math.cos(0.1)) < 1e-14
    # tan: pole pi/2 in [1, 2]; none in [-1, 1]; PIO2_LO < pi/2 < PIO2_HI
    assert tan(Interval(1.0, 2.0)).is_entire()
    y = tan(Interval(-1.0, 1.0))
    assert abs(float(y.hi) - 1.5574077246549023) < 3e-15 and float(y.lo) == -float(y.hi)
    y = tan(Interval(0.0, PIO2_LO))
    assert float(y.lo) == 0.0 and 1.633123935319536e16 < float(y.hi) < 1.6331239353196e16
    assert tan(Interval(0.0, PIO2_HI)).is_entire()
    assert tan(Interval(PIO2_LO, PIO2_HI)).is_entire()
    assert tan(Interval(-1.0, 2.0 + PI_LO)).is_entire()
    # asin / acos: domain [-1, 1], ranges [-pi/2, pi/2] and [0, pi]
    assert is_empty(asin(Interval(2.0, 3.0))) and is_empty(acos(Interval(-INF, -1.5)))
    assert bounds(asin(Interval(-2.0, 2.0))) == (-PIO2_HI, PIO2_HI)
    assert bounds(asin(Interval(1.0, INF))) == (PIO2_LO, PIO2_HI)
    assert bounds(acos(Interval(-INF, -1.0))) == (PI_LO, PI_HI)
    assert bounds(acos(Interval(-1.0, 1.0))) == (0.0, PI_HI)
    assert bounds(acos(Interval(0.0))) == (PIO2_LO, PIO2_HI)
    y = asin(Interval(0.5))  # pi/6
    assert contains(y, MPI / 6) and ulps_apart(*bounds(y)) <= 24


def test_forward_arrays_broadcast_and_out():
    x = Interval([0.0, 1.0, -INF, 5.0], [0.0, 2.0, INF, 5.0])
    y = sin(x)
    assert y.shape == (4,)
    assert bounds(y[0]) == (0.0, 0.0) and float(y[1].hi) == 1.0 and bounds(y[2]) == (-1.0, 1.0)
    out = Interval(np.zeros(4), np.zeros(4))
    r = cos(x, out=out)
    assert r is out and float(out[0].lo) == 1.0 and bounds(out[2]) == (-1.0, 1.0)
    e = sin(Interval.empty((2, 3)))
    assert e.shape == (2, 3) and e.is_empty().all()
    assert bounds(sin(0.0)) == (0.0, 0.0)  # plain numbers are degenerate intervals


# ---------------------------------------------------------------------------------------------
# reverse: soundness
# ---------------------------------------------------------------------------------------------

REV = {"sin": sin_rev, "cos": cos_rev, "tan": tan_rev, "asin": asin_rev, "acos": acos_rev}
z_pad = st.sampled_from([0.0, 0.0, 0.0, 1e-15, 1e-9, 1e-3, 0.1, 1.0, 10.0, INF])


@pytest.mark.parametrize("name", ["sin", "cos", "tan"])
@settings(max_examples=400, deadline=None)
@given(data=st.data())
def test_periodic_rev_keeps_every_solution(name, data):
    x = data.draw(trig_intervals())
    t = data.draw(point_in(x))
    v = MP_FUN[name](mpf(t))
    z = Interval(rd(v) - data.draw(z_pad), ru(v) + data.draw(z_pad))
    r = REV[name](z, x)
    assert valid(r), (z, x, r)
    assert contains(r, mpf(t)), (name, z, x, t, r)
    assert bool(r.is_subset(x))


@pytest.mark.parametrize("name", ["asin", "acos"])
@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_inverse_rev_keeps_every_solution(name, data):
    bound = st.one_of(st.floats(-1.5, 1.5), st.sampled_from([-1.0, 1.0, 0.0, 1e-300]))
    x = data.draw(trig_intervals(bound))
    assume(float(x.lo) <= 1.0 and float(x.hi) >= -1.0)
    t = data.draw(point_in(Interval(max(float(x.lo), -1.0), min(float(x.hi), 1.0))))
    v = MP_FUN[name](mpf(t))
    z = Interval(rd(v) - data.draw(z_pad), ru(v) + data.draw(z_pad))
    r = REV[name](z, x)
    assert valid(r) and contains(r, mpf(t)), (name, z, x, t, r)
    assert bool(r.is_subset(x)) and float(r.lo) >= -1.0 and float(r.hi) <= 1.0


# ---------------------------------------------------------------------------------------------
# reverse: tightness against the exact preimage hull
# ---------------------------------------------------------------------------------------------

@st.composite
def z_intervals(draw, name):
    if name == "tan":
        b = st.one_of(st.floats(-50.0, 50.0), st.floats(-1e20, 1e20),
                      st.sampled_from([-INF, INF, 0.0, 1.0, -1.0, 1e300]))
    else:
        b = st.one_of(st.floats(-1.2, 1.2), st.sampled_from([-1.0, 1.0, 0.0, -INF, INF]))
    zl, zh = sorted([draw(b), draw(b)])
    if draw(st.integers(0, 4)) == 0:
        zh = zl
    assume(zl != INF and zh != -INF)
    return Interval(zl, zh)


@pytest.mark.parametrize("name", ["sin", "cos", "tan"])
@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_periodic_rev_is_tight(name, data):
    z = data.draw(z_intervals(name))
    x = data.draw(moderate_intervals(1e3).filter(lambda v: float(v.hi - v.lo) < 20))
    r = REV[name](z, x)
    assert valid(r)
    if name != "tan" and (float(z.lo) > 1.0 or float(z.hi) < -1.0):
        assert is_empty(r)
        return
    tol = mpf(1e-14) * (1 + max(abs(float(x.lo)), abs(float(x.hi))))
    inner = exact_rev(name, z, x)
    outer = exact_rev(name, z, x, tol)
    if inner is not None:
        assert contains(r, inner[0]) and contains(r, inner[1]), (name, z, x, r, inner)
    if is_empty(r):
        assert inner is None, (name, z, x, r, inner)
        return
    assert outer is not None, (name, z, x, r)  # only a sliver within rounding of a branch
    assert mpf(float(r.lo)) >= outer[0] - tol and mpf(float(r.hi)) <= outer[1] + tol, (
        name, z, x, r, inner, outer)


@pytest.mark.parametrize("name", ["asin", "acos"])
@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_inverse_rev_is_tight(name, data):
    b = st.one_of(st.floats(-2.0, 4.0), st.sampled_from([-INF, INF, 0.0, PIO2_LO, PI_LO]))
    zl, zh = sorted([data.draw(b), data.draw(b)])
    assume(zl != INF and zh != -INF)
    x = data.draw(trig_intervals(st.floats(-1.5, 1.5)))
    r = REV[name](Interval(zl, zh), x)
    assert valid(r)
    # exact: X & [-1, 1] & f^-1(Z & range)
    top = MPI / 2 if name == "asin" else MPI
    bot = -MPI / 2 if name == "asin" else mpf(0)
    zlo, zhi = max(mpf(zl), bot), min(mpf(zh), top)
    xlo, xhi = max(mpf(float(x.lo)), -1), min(mpf(float(x.hi)), 1)
    if zlo > zhi or xlo > xhi:
        assert is_empty(r)
        return
    if name == "asin":
        plo, phi = mpmath.sin(zlo), mpmath.sin(zhi)
    else:
        plo, phi = mpmath.cos(zhi), mpmath.cos(zlo)
    lo, hi = max(plo, xlo), min(phi, xhi)
    if lo > hi:
        assert is_empty(r) or hi > lo - mpf(1e-15)
        return
    assert contains(r, lo) and contains(r, hi), (name, zl, zh, x, r)
    assert mpf(float(r.lo)) >= lo - mpf(4e-15) and mpf(float(r.hi)) <= hi + mpf(4e-15)


# ---------------------------------------------------------------------------------------------
# reverse: hand-derived edge cases
# ---------------------------------------------------------------------------------------------

def near(v: float, exact, tol: float = 1e-14) -> bool:
    return abs(mpf(v) - exact) <= tol


def test_reverse_edge_cases():
    x = Interval(-3.0, 7.0)
    for f in (sin_rev, cos_rev, tan_rev, asin_rev, acos_rev):
        assert is_empty(f(EMPTY, x)) and is_empty(f(Interval(0.0, 0.5), EMPTY))
    # Z outside the range of sin / cos: empty; Z covering it: X unchanged
    assert is_empty(sin_rev(Interval(1.1, 2.0))) and is_empty(cos_rev(Interval(-2.0, -1.1)))
    assert bounds(sin_rev(Interval(-1.0, 1.0), x)) == (-3.0, 7.0)
    assert bounds(cos_rev(Interval(-5.0, 5.0), x)) == (-3.0, 7.0)
    assert bounds(tan_rev(ENTIRE, x)) == (-3.0, 7.0)
    assert sin_rev(Interval(0.0, 0.5)).is_entire() and tan_rev(Interval(3.0, 4.0)).is_entire()
    # sin x = 0 on [3, 4]: x = pi; on [-10, 10]: x in {-3pi, ..., 3pi}
    assert bounds(sin_rev(Interval(0.0), Interval(3.0, 4.0))) == (PI_LO, PI_HI)
    r = sin_rev(Interval(0.0), Interval(-10.0, 10.0))
    assert contains(r, -3 * MPI) and contains(r, 3 * MPI)
    assert near(float(r.lo), -3 * MPI) and near(float(r.hi), 3 * MPI)
    assert bounds(sin_rev(Interval(0.0), Interval(-1.0, 1.0))) == (0.0, 0.0)
    assert is_empty(sin_rev(Interval(0.0), Interval(0.5, 3.0)))
    # sin x = 1 on [0, 100]: x = pi/2 + 2k pi, k = 0 .. 15 (30.5 pi = 95.8 < 100 < 32.5 pi)
    r = sin_rev(Interval(1.0), Interval(0.0, 100.0))
    assert near(float(r.lo), MPI / 2) and near(float(r.hi), mpf(61) * MPI / 2, 1e-13)
    assert contains(r, MPI / 2) and contains(r, mpf(61) * MPI / 2)
    # sin x = 0.5 with x <= 0: the largest solution is 5pi/6 - 2pi = -7pi/6
    r = sin_rev(Interval(0.5), Interval(-INF, 0.0))
    assert float(r.lo) == -INF and contains(r, -7 * MPI / 6) and near(float(r.hi), -7 * MPI / 6)
    # sin x in [0.5, 1] within [1, 10]: [1, 5pi/6] and [2pi + pi/6, 2pi + 5pi/6]
    r = sin_rev(Interval(0.5, 1.0), Interval(1.0, 10.0))
    assert float(r.lo) == 1.0 and near(float(r.hi), 17 * MPI / 6) and contains(r, 17 * MPI / 6)
    r = sin_rev(Interval(0.5, 1.0), Interval(1.0, 6.0))
    assert float(r.lo) == 1.0 and near(float(r.hi), 5 * MPI / 6) and contains(r, 5 * MPI / 6)
    # cos x = -1: odd multiples of pi; cos x = 1 has no solution in [1, 6] (2 pi > 6)
    r = cos_rev(Interval(-1.0), Interval(-10.0, 10.0))
    assert near(float(r.lo), -3 * MPI) and near(float(r.hi), 3 * MPI)
    assert is_empty(cos_rev(Interval(1.0), Interval(1.0, 6.0)))
    assert bounds(cos_rev(Interval(1.0), Interval(-0.1, 0.1))) == (0.0, 0.0)
    r = cos_rev(Interval(0.0, 0.5), Interval(0.0, 7.0))  # [pi/3, pi/2] u [3pi/2, 5pi/3]
    assert near(float(r.lo), MPI / 3) and near(float(r.hi), 5 * MPI / 3)
    # tan x = 0 on [1, 4] is pi; tan x >= 1 on [-1, 1] is [pi/4, 1]
    assert bounds(tan_rev(Interval(0.0), Interval(1.0, 4.0))) == (PI_LO, PI_HI)
    r = tan_rev(Interval(1.0, INF), Interval(-1.0, 1.0))
    assert near(float(r.lo), MPI / 4) and float(r.hi) == 1.0 and contains(r, MPI / 4)
    assert is_empty(tan_rev(Interval(1.0, 2.0), Interval(-0.5, 0.5)))
    # unbounded and huge X: infinite / huge bounds are kept, the others contracted
    r = sin_rev(Interval(0.5), Interval(-1e20, 1.0))
    assert float(r.lo) == -1e20 and near(float(r.hi), MPI / 6)
    assert bounds(sin_rev(Interval(0.0, 0.5), Interval(1e300, INF))) == (1e300, INF)
    r = tan_rev(Interval(0.0), Interval(-INF, 1.0))
    assert float(r.lo) == -INF and float(r.hi) == 0.0
    # asin / acos reverse: x = sin(Z) / cos(Z) on the monotone part
    assert bounds(asin_rev(Interval(0.0, 10.0), Interval(-5.0, 5.0))) == (0.0, 1.0)
    assert bounds(acos_rev(Interval(0.0, 10.0), Interval(-5.0, 5.0))) == (-1.0, 1.0)
    assert is_empty(asin_rev(Interval(2.0, 3.0))) and is_empty(acos_rev(Interval(-1.0, -0.5)))
    assert is_empty(acos_rev(Interval(PI_HI, 5.0)))  # PI_HI > pi: above the range
    r = acos_rev(Interval(PI_LO, 5.0))  # cos([PI_LO, pi]) = [-1, -1 + 7.5e-33]
    assert float(r.lo) == -1.0 and -1.0 < float(r.hi) < -1.0 + 3e-15
    r = asin_rev(Interval(0.5235987755982988), Interval(-1.0, 1.0))  # the float nearest pi/6
    v = mpmath.sin(mpf(0.5235987755982988))
    assert contains(r, v) and near(float(r.lo), v, 1e-15) and near(float(r.hi), v, 1e-15)
    assert bounds(acos_rev(Interval(-1.0, 0.0), Interval(-2.0, 2.0))) == (1.0, 1.0)


def test_reverse_arrays_and_out():
    z = Interval([0.0, 2.0, -1.0], [0.0, 3.0, 1.0])
    x = Interval(3.0, 4.0)  # broadcast
    r = sin_rev(z, x)
    assert r.shape == (3,)
    assert bounds(r[0]) == (PI_LO, PI_HI) and is_empty(r[1]) and bounds(r[2]) == (3.0, 4.0)
    out = Interval(np.zeros(3), np.zeros(3))
    assert cos_rev(z, x, out=out) is out and is_empty(out[1])


# ---------------------------------------------------------------------------------------------
# asin / acos on whole arrays (the SIMD loops), out= and layouts, glibc values (the engine)
# ---------------------------------------------------------------------------------------------
# asin and acos evaluate NumPy's ufuncs at the bounds of the whole array and then run a compiled
# loop: long arrays exercise its SIMD body with every kind of element mixed.

_UNIT_EDGE = [0.0, -0.0, 1.0, -1.0, 0.5, -0.5, step(0.5, 1), step(-0.5, -1), 2.0**-26,
              -(2.0**-26), step(2.0**-26, -1), step(-(2.0**-26), 1), 1e-300, -1e-300, 5e-324,
              -5e-324, step(1.0, -1), step(-1.0, 1), 1.5, -1.5, 1e300, -1e300, MAX, -MAX]


def unit_batch(n: int = 400, seed: int = 0) -> Interval:
    """``n`` random intervals around [-1, 1] (uniform, tiny, edge values, infinite bounds,
    degenerate ones), followed by one empty interval."""
    rng = np.random.default_rng(seed)
    lo, hi = [], []
    for _ in range(n):
        kind = int(rng.integers(0, 10))
        a = float(rng.uniform(-1.2, 1.2))
        if kind == 0:
            a = float(rng.choice(_UNIT_EDGE))
        elif kind == 1:
            a = float(rng.choice([-1.0, 1.0]) * 10.0 ** rng.uniform(-300, 0))
        b = a if kind < 4 else a + float(rng.uniform(0, 1)) * 10.0 ** rng.uniform(-15, 0)
        if kind == 9:
            a, b = [(-INF, b), (a, INF), (-INF, INF)][int(rng.integers(0, 3))]
        lo.append(min(a, b))
        hi.append(max(a, b))
    return Interval.trusted(np.array([*lo, math.nan]), np.array([*hi, math.nan]))


def check_inverse_batch(name: str, x: Interval, y: Interval) -> None:
    """Soundness of every element of ``y = f(x)`` (f = asin or acos) at sampled points."""
    rng = np.random.default_rng(1)
    top, bottom = (PIO2_HI, -PIO2_HI) if name == "asin" else (PI_HI, 0.0)
    for i in range(x.lo.size):
        a, b = float(x.lo[i]), float(x.hi[i])
        yi = y[i]
        assert valid(yi), (name, a, b, yi)
        if math.isnan(a) or a > 1.0 or b < -1.0:
            assert is_empty(yi), (name, a, b, yi)
            continue
        lo, hi = bounds(yi)
        assert bottom <= lo and hi <= top
        a, b = max(a, -1.0), min(b, 1.0)
        for t in (a, b, float(rng.uniform(a, b))):
            v = MP_FUN[name](mpf(t))
            assert contains(yi, v), (name, a, b, t, yi)
            if a == b and abs(v) > 1e-300:
                assert ulps_apart(lo, hi) <= 24, (name, t, yi)


@pytest.mark.parametrize("name", ["asin", "acos"])
def test_inverse_whole_array_contains_exact_value(name):
    x = unit_batch()
    check_inverse_batch(name, x, FUN[name](x))


def test_acos_is_tight_near_zero():
    """For |z| <= 1/2 acos is pi/2 - asin (tighter than acos's own libm value): a few ulps."""
    z = np.concatenate([np.linspace(-0.5, 0.5, 2001), [1e-10, -1e-300, 2.0**-27]])
    y = acos(Interval(z))
    assert max(ulps_apart(lo, hi) for lo, hi in zip(y.lo, y.hi, strict=True)) <= 8
    assert ulps_apart(*bounds(acos(Interval(1e-10)))) <= 3
    assert bounds(acos(Interval(np.zeros(40)))[17]) == (PIO2_LO, PIO2_HI)


@pytest.mark.parametrize("name", ["asin", "acos"])
def test_inverse_out_and_layouts(name):
    """``out=`` (direct, in place, small), strided and 2-D bounds give the same bounds."""
    f = FUN[name]
    n = 5000
    x = unit_batch(n - 1, seed=2)
    ref = f(x)

    def same_as_ref(r: Interval) -> None:
        assert np.array_equal(r.lo.ravel(), ref.lo, equal_nan=True)
        assert np.array_equal(r.hi.ravel(), ref.hi, equal_nan=True)

    out = Interval.trusted(np.empty(n), np.empty(n))
    assert f(x, out=out) is out
    same_as_ref(out)
    y = Interval.trusted(x.lo.copy(), x.hi.copy())
    f(y, out=y)
    same_as_ref(y)
    big = np.empty((4, n))
    big[0], big[2] = x.lo, x.hi
    xs = Interval.trusted(big[0::2].T[:, 0], big[0::2].T[:, 1])
    outs = Interval.trusted(np.empty(2 * n)[::2], np.empty(2 * n)[1::2])
    f(xs, out=outs)
    same_as_ref(outs)
    same_as_ref(f(Interval.trusted(x.lo.reshape(100, 50), x.hi.reshape(100, 50))))
    small = Interval.trusted(np.empty(7), np.empty(7))
    f(x[:7], out=small)
    assert np.array_equal(small.hi, ref.hi[:7], equal_nan=True)


@pytest.mark.parametrize("name", ["asin", "acos"])
def test_engine_inverse_bounds_with_glibc_values(name):
    """The compiled propagation engine feeds the same bounds functions with glibc's values."""
    x = unit_batch(300, seed=3)
    check_inverse_batch(name, x, engine_forward(name, x))
