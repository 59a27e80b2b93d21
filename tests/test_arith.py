"""Soundness and tightness of + - * / sqr sqrt against exact rational / mpmath results."""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import boundest as bd
from boundest import Interval

from .checks import exact_in
from .strategies import intervals, point_in, ulps_apart

mpmath.mp.prec = 256
EMPTY = Interval.empty()
ENTIRE = Interval.entire()


OPS = {
    "add": (bd.add, lambda a, b: a + b),
    "sub": (bd.sub, lambda a, b: a - b),
    "mul": (bd.mul, lambda a, b: a * b),
    "div": (bd.div, lambda a, b: a / b),
}


@pytest.mark.parametrize("name", sorted(OPS))
@settings(max_examples=400, deadline=None)
@given(data=st.data())
def test_binary_contains_exact_result(name, data):
    op, exact = OPS[name]
    x, y = data.draw(intervals()), data.draw(intervals())
    a, b = data.draw(point_in(x)), data.draw(point_in(y))
    assume(not (name == "div" and b == 0.0))
    z = op(x, y)
    assert exact_in(exact(Fraction(a), Fraction(b)), z), (x, y, a, b, z)


@pytest.mark.parametrize("name", sorted(OPS))
@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_binary_on_degenerate_is_tightest(name, data):
    a = data.draw(st.floats(-1e200, 1e200))
    b = data.draw(st.floats(-1e200, 1e200))
    assume(not (name == "div" and b == 0.0))
    op, exact = OPS[name]
    z = op(Interval(a), Interval(b))
    e = exact(Fraction(a), Fraction(b))
    lo, hi = float(z.lo), float(z.hi)
    assert exact_in(e, z)
    if not (math.isfinite(lo) and math.isfinite(hi)):  # overflow: [MAX, inf] or [-inf, -MAX]
        assert abs(e) > Fraction(1.7976931348623157e308)
        return
    # tightest: either the exact value is a float (degenerate result) or lo, hi are adjacent
    if Fraction(lo) == e:
        assert lo == hi
    elif min(abs(a), abs(b), abs(e)) > 2.0**-900:
        assert ulps_apart(lo, hi) == 1, (a, b, lo, hi)
    else:  # near the subnormal range the kernels step out blindly: a few ulps
        assert ulps_apart(lo, hi) <= 4


@settings(max_examples=400, deadline=None)
@given(data=st.data())
def test_sqr_sqrt_contain_exact_result(data):
    x = data.draw(intervals())
    a = data.draw(point_in(x))
    assert exact_in(Fraction(a) ** 2, bd.sqr(x))
    if a >= 0:
        r = bd.sqrt(x)
        s = mpmath.sqrt(mpmath.mpf(a))
        assert mpmath.mpf(float(r.lo)) <= s <= mpmath.mpf(float(r.hi))


def test_division_by_intervals_containing_zero():
    one_two = Interval(1, 2)
    assert bd.div(one_two, Interval(0, 0)).is_empty()
    assert bd.div(one_two, Interval(-1, 1)) == ENTIRE
    assert bd.div(one_two, Interval(0, 4)) == Interval(0.25, np.inf)
    assert bd.div(one_two, Interval(-4, 0)) == Interval(-np.inf, -0.25)
    assert bd.div(Interval(-2, -1), Interval(0, 4)) == Interval(-np.inf, -0.25)
    assert bd.div(Interval(-1, 2), Interval(0, 4)) == ENTIRE
    assert bd.div(Interval(0, 0), Interval(-1, 1)) == Interval(0, 0)
    # a dividend bound at 0 over a divisor bound at 0 gives a half-line, not the entire line
    assert bd.div(Interval(-30, 0), Interval(-3, 0)) == Interval(0, np.inf)
    assert bd.div(Interval(0, 30), Interval(-3, 0)) == Interval(-np.inf, 0)
    assert bd.div(Interval(-30, 0), Interval(0, 3)) == Interval(-np.inf, 0)
    assert bd.div(Interval(0, 30), Interval(0, 3)) == Interval(0, np.inf)
    assert bd.div(Interval(1, np.inf), Interval(1, np.inf)) == Interval(0, np.inf)


def test_seed_004_examples():
    # Jaulin, Bertholom, Dabe 2007 section 6.1
    assert bd.add(Interval(-1, 3), Interval(2, 5)) == Interval(1, 8)
    assert bd.mul(Interval(-1, 3), Interval(2, 5)) == Interval(-5, 15)
    assert bd.div(Interval(-1, 3), Interval(2, 5)) == Interval(-0.5, 1.5)
    assert bd.sqr(Interval(-1, 3)) == Interval(0, 9)
    assert bd.sqrt(Interval(-10, 4)) == Interval(0, 2)


def test_empty_and_entire_propagate():
    for op in (bd.add, bd.sub, bd.mul, bd.div):
        assert op(EMPTY, Interval(1, 2)).is_empty()
        assert op(Interval(1, 2), EMPTY).is_empty()
    assert bd.sqr(EMPTY).is_empty() and bd.sqrt(EMPTY).is_empty()
    assert bd.sqrt(Interval(-3, -1)).is_empty()
    assert bd.mul(Interval(0, 0), ENTIRE) == Interval(0, 0)
    assert bd.mul(ENTIRE, Interval(1, 2)) == ENTIRE
    assert bd.add(ENTIRE, Interval(1, 2)) == ENTIRE
    assert bd.sqr(ENTIRE) == Interval(0, np.inf)


def test_overflow_gives_infinite_upper_bound_not_infinite_lower():
    big = Interval(1e308, 1.7976931348623157e308)
    s = big + big
    assert s.lo == 1.7976931348623157e308 and s.hi == np.inf
    p = -big * big
    assert p.lo == -np.inf and p.hi == -1.7976931348623157e308


def test_signed_zero_and_tiny_products():
    z = bd.mul(Interval(-0.0, 0.0), Interval(-np.inf, np.inf))
    assert z == Interval(0, 0)
    t = bd.mul(Interval(2.0**-600), Interval(2.0**-600))  # underflows to 0
    # sound, and at most one subnormal step on each side (the kernels stay branch-free)
    assert t.lo == -(2.0**-1074) and t.hi == 2.0**-1074
    assert bd.sqr(Interval(1e-200)) == Interval(0, 2.0**-1074)  # a square stays >= 0


def test_broadcasting_and_out_buffers():
    x = Interval(np.zeros((3, 4)), np.ones((3, 4)))
    y = Interval(np.arange(4.0), np.arange(4.0) + 1)
    z = x + y
    assert z.shape == (3, 4)
    assert np.array_equal(z.lo, np.broadcast_to(np.arange(4.0), (3, 4)))
    out = Interval.empty((3, 4))
    r = bd.mul(x, y, out=out)
    assert r is out and np.array_equal(out.hi, np.broadcast_to(np.arange(4.0) + 1, (3, 4)))
    assert (2 * x).shape == (3, 4) and (x - 1.0).shape == (3, 4) and (1.0 / y).shape == (4,)


def test_reflected_operators_with_numpy_scalars():
    x = Interval(1, 2)
    assert np.float64(2) * x == Interval(2, 4)
    assert 1 - x == Interval(-1, 0)
    assert 2 / x == Interval(1, 2)


def _ufunc_kernels():
    from boundest.interval import algebraic, arith
    from boundest.interval.rounding import _LazyUfunc

    return [(f"{mod.__name__.rsplit('.', 1)[1]}.{name}", k) for mod in (arith, algebraic)
            for name, k in sorted(vars(mod).items()) if isinstance(k, _LazyUfunc)]


@pytest.mark.parametrize(("name", "kernel"), _ufunc_kernels(), ids=lambda v: v
                         if isinstance(v, str) else "")
def test_ufunc_loops_agree_on_contiguous_strided_and_broadcast_arguments(name, kernel):
    # the compiled loop has a contiguous (SIMD) branch and a strided one: both must run the
    # same kernel, element by element, and NumPy's conventions (scalars, out=) must hold
    rng = np.random.default_rng(7)
    special = np.array([0.0, -0.0, np.inf, -np.inf, np.nan, 2.0**-1074, 1e300, -1e-300])
    cols = []
    for j in range(kernel._nin):
        a = rng.standard_normal(64) * 10.0 ** rng.integers(-300, 300, 64)
        a[rng.integers(0, 64, 16)] = rng.choice(special, 16)
        cols.append(np.sort(a) if j % 2 else a)  # a few ordered pairs, most not
    ref = kernel(*cols)
    assert ref.dtype == np.float64 and ref.shape == (64,)
    wide = [np.repeat(c, 2) for c in cols]
    assert np.array_equal(kernel(*[w[::2] for w in wide]), ref, equal_nan=True), name
    out = np.full(128, -1.0)
    assert kernel(*cols, out=out[1::2]) is not None
    assert np.array_equal(out[1::2], ref, equal_nan=True) and np.all(out[::2] == -1.0)
    k = 5
    one = kernel(*[float(c[k]) for c in cols])
    assert isinstance(one, np.float64)
    assert np.array_equal(one, ref[k], equal_nan=True)
    bcast = kernel(*[c if j == 1 else c[k] for j, c in enumerate(cols)])  # stride-0 arguments
    single = [kernel(*[c[i] if j == 1 else c[k] for j, c in enumerate(cols)]) for i in range(64)]
    assert np.array_equal(bcast, np.array(single), equal_nan=True), name
    assert np.array_equal(kernel(*[c.reshape(8, 8) for c in cols]), ref.reshape(8, 8),
                          equal_nan=True)


_CACHE_SCRIPT = """
import boundest as bd
from boundest.interval import arith
x = bd.Interval(1, 2) * bd.Interval(3, 4) + bd.Interval(0.5, 1.0)
print(float(x.lo), float(x.hi), arith._add_lo._loop.cache_hits, arith._mul_hi._loop.cache_hits)
"""


@pytest.mark.slow  # subprocesses with an empty cache, 6-8 s
def test_ufunc_loops_load_from_the_disk_cache_in_a_new_process(tmp_path):
    # nb.vectorize rebuilt every ufunc's loop with LLVM in every process (50-75 ms each)
    import os
    import subprocess
    import sys

    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), BOUNDEST_KERNEL_ARCHIVE="0")
    runs = []
    for _ in range(2):  # compiling, then loading what the first run cached
        out = subprocess.run([sys.executable, "-c", _CACHE_SCRIPT], env=env,
                             capture_output=True, text=True, timeout=900)
        assert out.returncode == 0, out.stderr[-2000:]
        runs.append(out.stdout.split())
    assert runs[0] == ["3.5", "9.0", "0", "0"]
    assert runs[1] == ["3.5", "9.0", "1", "1"]
