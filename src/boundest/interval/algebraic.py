"""Algebraic functions (``abs``, ``pown``, ``min``, ``max``, ``sign``, ``floor``, ``ceil``,
``trunc``) and the backward (reverse) operators of the algebraic primitives.

Forward functions return the tightest float64 enclosure of the image (IEEE 1788-2015 set-based
semantics). Backward operators contract their arguments: the unary ``f_rev(z, x)`` returns
``hull{x in X : f(x) in Z}`` and the binary ``f_rev(z, x, y)`` returns ``(x', y')`` with
``x' = hull{x in X : exists y in Y, f(x, y) in Z}`` and likewise ``y'``. Every result is a subset
of the corresponding input and contains every point of the exact set; the empty set is
``[nan, nan]`` and any empty argument makes every result empty.

``pown`` evaluates integer powers in double-word arithmetic (a product of two double-words has
a relative error below ``7 u^2``, Joldes, Muller and Popescu, ACM TOMS 2017) with a running
rigorous error bound, and exact results are detected, so its bounds are the tightest float64
ones except in rare hard-to-round cases, where they are one ulp wider. Roots (``pown_rev``) are
found by a floating-point guess that is then verified (and tightened) with those rigorous
power bounds.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numba as nb
import numpy as np
from numpy.typing import ArrayLike

from .core import Interval, as_interval
from .rounding import (
    INF,
    MAX,
    NAN,
    _LazyGufunc,
    add_dn,
    add_up,
    div_dn,
    div_up,
    fma,
    gufunc,
    mul_dn,
    mul_up,
    sqrt_dn,
    sqrt_up,
    sub_dn,
    sub_up,
)

__all__ = [
    "abs_rev",
    "add_rev",
    "ceil",
    "ceil_rev",
    "div_rev",
    "floor",
    "floor_rev",
    "max_rev",
    "min_rev",
    "mul_rev",
    "mul_rev_to_pair",
    "neg_rev",
    "pown",
    "pown_rev",
    "sign",
    "sign_rev",
    "sqr_rev",
    "sqrt_rev",
    "sub_rev",
    "trunc",
]

IntervalLike = ArrayLike | Interval

# the public abs/min/max below shadow the builtins inside this module
_babs = abs
_bmin = min
_bmax = max

_jit = nb.njit(inline="always", cache=True)
#: Larger helpers (loops) are compiled once and called, not inlined everywhere.
_jit_call = nb.njit(cache=True)

ETA = 2.0**-1074
#: Bound on the relative error of one double-word product (< 8 u^2) or reciprocal (< 11 u^2).
_DW_DELTA = 16.0 * 2.0**-106
#: Covers the round-to-nearest errors made while propagating the error bounds themselves.
_SAFE = 1.0 + 2.0**-40
#: Beyond this (in binary orders of magnitude) a power certainly over- or underflows.
_LOG2_LIMIT = 1100.0
#: Largest accepted |n| for pown (the exponent is handled as an int64).
_N_LIMIT = 2**62
_TINY_SQR = 2.0**-480


# ----------------------------------------------------------------------------------------
# gufuncs with an integer exponent argument
# ----------------------------------------------------------------------------------------
class _LazyIntGufunc(_LazyGufunc):
    """Like ``rounding.gufunc`` but the last input is an int64 (the exponent of pown)."""

    def _build(self):
        args = ",".join(["f8"] * self._nin + ["i8"] + ["f8[:]"] * self._nout)
        layout = ",".join(["()"] * (self._nin + 1)) + "->" + ",".join(["()"] * self._nout)
        self._ufunc = nb.guvectorize([f"void({args})"], layout, cache=True)(self._func)
        return self._ufunc


def _int_gufunc(nin_float: int, nout: int = 2) -> Callable[[Callable], _LazyIntGufunc]:
    def wrap(func: Callable) -> _LazyIntGufunc:
        return _LazyIntGufunc(func, nin_float, nout)
    return wrap


# ----------------------------------------------------------------------------------------
# scalar helpers
# ----------------------------------------------------------------------------------------
@_jit
def _meet(xl, xh, l, h):
    """``[xl, xh] ∩ [l, h]``; empty when the returned lo > hi (no NaN inputs)."""
    lo = xl if xl > l else l
    hi = xh if xh < h else h
    return lo, hi


@_jit
def _hull_meet2(xl, xh, l1, h1, l2, h2):
    """``hull(X ∩ P1, X ∩ P2)``; pieces with ``l > h`` are empty; empty result has lo > hi."""
    a, b = _meet(xl, xh, l1, h1)
    c, d = _meet(xl, xh, l2, h2)
    if a > b:
        return c, d
    if c > d:
        return a, b
    return (a if a < c else c), (b if b > d else d)


@_jit
def _div_nz_operands(cl, ch, bl, bh):
    """Corners ``(n1, d1, n2, d2)`` with ``C / B = [n1 / d1, n2 / d2]`` for ``0 not in B``.

    Sign case analysis; no inf/inf corner is ever selected (``C``, ``B`` non-empty).
    """
    if bl > 0.0:
        if cl >= 0.0:
            return cl, bh, ch, bl
        if ch <= 0.0:
            return cl, bl, ch, bh
        return cl, bl, ch, bl
    if cl >= 0.0:
        return ch, bh, cl, bl
    if ch <= 0.0:
        return ch, bl, cl, bh
    return ch, bh, cl, bh


@_jit
def _q_dn(n, d):
    """Lower bound of ``n / d`` for finite ``n`` or finite ``d`` (``d != 0``); ``n / ±inf``
    is the limit 0 exactly (``div_dn`` alone would step out to ``-ETA``)."""
    r = div_dn(n, d)
    return 0.0 if _babs(d) == INF else r


@_jit
def _q_up(n, d):
    r = div_up(n, d)
    return 0.0 if _babs(d) == INF else r


@_jit
def _div_pair(cl, ch, bl, bh):
    """``{x : exists b in B, c in C, x*b = c}`` as two pieces ``(l1, h1, l2, h2)``.

    The first piece is the lower one; an absent piece is ``(INF, -INF)`` and the second is
    absent whenever the set is one interval (IEEE 1788 mulRevToPair, C and B non-empty).
    Every case needs at most one downward and one upward division.
    """
    if bl > 0.0 or bh < 0.0:
        n1, d1, n2, d2 = _div_nz_operands(cl, ch, bl, bh)
        return _q_dn(n1, d1), _q_up(n2, d2), INF, -INF
    if cl <= 0.0 <= ch:  # 0 in B and 0 in C: x * 0 = 0 for every x
        return -INF, INF, INF, -INF
    # 0 in B, 0 not in C. With c > 0: b < 0 gives x <= cl/bl, b > 0 gives x >= cl/bh.
    # With c < 0: b > 0 gives x <= ch/bh, b < 0 gives x >= ch/bl.
    if cl > 0.0:
        c = cl
        has1 = bl < 0.0
        has2 = bh > 0.0
        d1 = bl
        d2 = bh
    else:
        c = ch
        has1 = bh > 0.0
        has2 = bl < 0.0
        d1 = bh
        d2 = bl
    if has1 and has2:
        return -INF, _q_up(c, d1), _q_dn(c, d2), INF
    if has1:
        return -INF, _q_up(c, d1), INF, -INF
    if has2:
        return _q_dn(c, d2), INF, INF, -INF
    return INF, -INF, INF, -INF  # B = [0, 0]


@_jit
def _mul_operands(al, ah, bl, bh):
    """Corners for ``A * B`` (sign case analysis): lo = min of the first two products,
    hi = max of the last two."""
    if al >= 0.0:
        if bl >= 0.0:
            return al, bl, al, bl, ah, bh, ah, bh
        if bh <= 0.0:
            return ah, bl, ah, bl, al, bh, al, bh
        return ah, bl, ah, bl, ah, bh, ah, bh
    if ah <= 0.0:
        if bl >= 0.0:
            return al, bh, al, bh, ah, bl, ah, bl
        if bh <= 0.0:
            return ah, bh, ah, bh, al, bl, al, bl
        return al, bh, al, bh, al, bl, al, bl
    if bl >= 0.0:
        return al, bh, al, bh, ah, bh, ah, bh
    if bh <= 0.0:
        return ah, bl, ah, bl, al, bl, al, bl
    return al, bh, ah, bl, al, bl, ah, bh


@_jit
def _mul_lohi(al, ah, bl, bh):
    """Tightest enclosure of ``A * B`` (non-empty), with ``0 * inf = 0``."""
    p1, q1, p2, q2, p3, q3, p4, q4 = _mul_operands(al, ah, bl, bh)
    return _bmin(mul_dn(p1, q1), mul_dn(p2, q2)), _bmax(mul_up(p3, q3), mul_up(p4, q4))


#: 2**k for -1022 <= k <= 1023, index k + 1022 (a table: cheaper than ldexp in kernels)
_POW2 = np.ldexp(1.0, np.arange(-1022, 1024))


@_jit
def _p2(k):
    """``2.0**k`` for -1022 <= k <= 1023 (exact)."""
    return _POW2[k + 1022]


@_jit_call
def _scale(v, s, up):
    """Directed rounding of ``v * 2**s`` for ``0.1 < v < 4`` and ``|s| < 2000``."""
    if -1000 <= s <= 1000:  # the product is a normal number: exact
        return v * _p2(s)
    if s >= 0:
        s1 = _bmin(s, 1000)
        r = (v * _p2(s1)) * _p2(s - s1)  # both products exact unless the last overflows
        if r == INF and not up:
            return MAX
        return r
    s1 = _bmax(s, -1000)
    r = v * _p2(s1)  # exact: still a normal number
    f = _p2(s - s1)
    r2 = r * f  # correctly rounded, possibly subnormal
    back = r2 / f  # exact
    if up:
        if back < r:
            r2 = r2 + ETA
    elif back > r:
        r2 = r2 - ETA
        if r2 < 0.0:
            r2 = 0.0
    return r2


@_jit
def _dw_mul(ah, al, bh, bl):
    """Double-word product (DWTimesDW1 of Joldes-Muller-Popescu, relative error < 7 u^2).

    Returns ``(hi, lo, exact)``; ``exact`` is true when both inputs are plain floats and their
    product is a float (then ``lo == 0``). The callers keep the magnitudes within
    [2**-900, 2**900], so nothing (not even the exact error of the leading product)
    underflows.
    """
    p = ah * bh
    e = fma(ah, bh, -p)
    t = e + (ah * bl + al * bh)
    s = p + t
    return s, t - (s - p), al == 0.0 and bl == 0.0 and e == 0.0


@_jit_call
def _pow_pos(a, n):
    """``(lo, hi)`` enclosing ``a**n`` for finite ``a > 0`` and an integer ``0 < |n| < 2**62``."""
    if n == 1:
        return a, a
    if n == 2 and a >= _TINY_SQR:
        return mul_dn(a, a), mul_up(a, a)
    if n == -1 and 2.0**-900 <= a <= 2.0**900:
        return div_dn(1.0, a), div_up(1.0, a)
    k = n if n > 0 else -n
    m, e = math.frexp(a)  # a = m * 2**e, m in [0.5, 1)
    span = float(k) * (_babs(e) + 1)  # >= |log2(a**j)| for every j <= k
    if span > 1000.0:  # a**k may over- or underflow: check the range
        lg = math.log2(a) * k  # only used for a decision with a wide margin
        if lg > _LOG2_LIMIT:  # a**k > 2**1099
            if n > 0:
                return MAX, INF
            return 0.0, ETA
        if lg < -_LOG2_LIMIT:  # a**k < 2**-1099
            if n > 0:
                return 0.0, ETA
            return MAX, INF
    # Unscaled, every a**j (j <= k) lies in [2**-900, 2**900]: no intermediate quantity of
    # the double-word products (exact errors included) under- or overflows. Otherwise work on
    # the mantissa m and keep the binary exponents aside (the double-words stay in [0.5, 1)).
    scaled = span > 900.0
    bh = m if scaled else a
    bl = 0.0
    be = e if scaled else 0
    eb = 0.0  # base (bh + bl) * 2**be = a**(2**j) * (1 + theta), |theta| <= eb
    rh = 1.0
    rl = 0.0
    re = 0
    er = 0.0  # result so far; er == 0 means exact
    while True:
        if k & 1:
            rh, rl, ex = _dw_mul(rh, rl, bh, bl)
            re += be
            d = 0.0 if ex else _DW_DELTA
            er = (er + eb + er * eb + d * (1.0 + er) * (1.0 + eb)) * _SAFE
            if scaled and rh < 0.5:
                rh *= 2.0
                rl *= 2.0
                re -= 1
        k >>= 1
        if k == 0:
            break
        bh, bl, ex = _dw_mul(bh, bl, bh, bl)
        be *= 2
        d = 0.0 if ex else _DW_DELTA
        eb = (2.0 * eb + eb * eb + d * (1.0 + eb) * (1.0 + eb)) * _SAFE
        if scaled and bh < 0.5:
            bh *= 2.0
            bl *= 2.0
            be -= 1
    if n < 0:
        q = 1.0 / rh
        rr = fma(-q, rh, 1.0)  # exact remainder 1 - q*rh
        ql = (rr - q * rl) / rh
        if er != 0.0 or rr != 0.0 or rl != 0.0:
            er = (er + _DW_DELTA) / (1.0 - er) * _SAFE
        rh = q
        rl = ql
        re = -re
    if er == 0.0:  # exact: rl == 0
        lo = rh
        hi = rh
    else:
        ea = mul_up(rh, er * 1.25)  # >= |rh + rl| * er / (1 - er)
        lo = add_dn(rh, sub_dn(rl, ea))
        hi = add_up(rh, add_up(rl, ea))
    if not scaled:
        return lo, hi
    return _scale(lo, re, False), _scale(hi, re, True)


@_jit
def _pow_lo(a, n):
    """Lower bound of ``a**n`` for ``a >= 0`` (0 and +inf as limits), ``n != 0``."""
    if a == 0.0:
        return 0.0 if n > 0 else INF
    if a == INF:
        return INF if n > 0 else 0.0
    return _pow_pos(a, n)[0]


@_jit
def _pow_hi(a, n):
    """Upper bound of ``a**n`` for ``a >= 0``, ``n != 0``."""
    if a == 0.0:
        return 0.0 if n > 0 else INF
    if a == INF:
        return INF if n > 0 else 0.0
    return _pow_pos(a, n)[1]


@_jit
def _pow_lo_odd(a, n):
    """Lower bound of ``a**n`` for odd ``n`` and any sign of ``a`` (non-NaN)."""
    if a >= 0.0:
        return _pow_lo(a, n)
    return -_pow_hi(-a, n)


@_jit
def _pow_hi_odd(a, n):
    if a >= 0.0:
        return _pow_hi(a, n)
    return -_pow_lo(-a, n)


@_jit
def _root_guess(c, n):
    """Floating-point approximation of ``c**(1/n)`` (c > 0 finite): exp/log, then one Newton
    step when ``c`` and the power are normal numbers (a few ulps off; verified later)."""
    r = math.exp(math.log(c) / n)
    if 0.0 < r < INF and c >= 2.0**-1022:
        p = math.pow(r, float(n))
        if 2.0**-1022 <= p < INF:
            r2 = r * (1.0 + (c / p - 1.0) / n)
            if 0.0 < r2 < INF:
                r = r2
    return r


@_jit
def _below_root(r, c, n):
    """Proven ``r <= c**(1/n)`` (c > 0 finite, r >= 0 finite)."""
    if r <= 0.0:
        return True
    if r > MAX:
        return False
    if n > 0:
        return _pow_pos(r, n)[1] <= c
    return _pow_pos(r, n)[0] >= c  # x -> x**n is decreasing for n < 0


@_jit
def _above_root(r, c, n):
    """Proven ``r >= c**(1/n)`` (c > 0 finite, r > 0)."""
    if r > MAX:
        return True
    if r <= 0.0:
        return False
    if n > 0:
        return _pow_pos(r, n)[0] >= c
    return _pow_pos(r, n)[1] <= c


@_jit
def _step(r, k, up):
    """``r`` moved by about ``k`` ulps (exactly one when ``k == 1``) up or down."""
    if up:
        t = np.nextafter(r, INF)
        return t if k == 1.0 else r + k * (t - r)
    t = np.nextafter(r, -INF)
    return t if k == 1.0 else r - k * (r - t)


@_jit_call
def _root_dn_pos(c, n):
    """The largest float ``r >= 0`` with ``r <= c**(1/n)`` (c > 0 finite, n != 0).

    Each candidate is proven with the rigorous power bounds; hard-to-round cases may end one
    ulp low. A guess above the root is first lowered (steps doubling), then the bound is
    raised by galloping and bisection in ulps.
    """
    r = _root_guess(c, n)
    if r != r or r < 0.0:
        r = 0.0
    if r > MAX:
        r = MAX
    d = 2.0**-52
    while not _below_root(r, c, n):
        r = _bmin(np.nextafter(r, -INF), r - r * d)
        d *= 2.0
        if d > 1.0 or r < 0.0:
            r = 0.0
    k = 1.0
    while True:
        t = _step(r, k, True)
        if not _below_root(t, c, n):
            break
        r = t
        k *= 2.0
    k *= 0.5
    while k >= 1.0:
        t = _step(r, k, True)
        if _below_root(t, c, n):
            r = t
        k *= 0.5
    return r


@_jit_call
def _root_up_pos(c, n):
    """The smallest float ``r >= c**(1/n)`` (c > 0 finite, n != 0), +inf beyond ``MAX``."""
    r = _root_guess(c, n)
    if r != r or r <= 0.0:
        r = ETA
    if r > MAX:
        r = MAX
    d = 2.0**-52
    while not _above_root(r, c, n):
        r = _bmax(np.nextafter(r, INF), r + r * d)
        d *= 2.0
    if r > MAX:
        return INF
    k = 1.0
    while True:
        t = _step(r, k, False)
        if not _above_root(t, c, n):
            break
        r = t
        k *= 2.0
    k *= 0.5
    while k >= 1.0:
        t = _step(r, k, False)
        if _above_root(t, c, n):
            r = t
        k *= 0.5
    return r


@_jit_call
def _root_dn(c, n):
    """Lower bound of ``c**(1/n)`` for ``c in [0, inf]``, ``n != 0``, limits at 0 and inf."""
    if c == 0.0:
        return 0.0 if n > 0 else MAX
    if c == INF:
        return MAX if n > 0 else 0.0
    if n == 1:
        return c
    if n == 2:
        return sqrt_dn(c)
    return _root_dn_pos(c, n)


@_jit_call
def _root_up(c, n):
    """Upper bound of ``c**(1/n)`` for ``c in [0, inf]``, ``n != 0``."""
    if c == 0.0:
        return 0.0 if n > 0 else INF
    if c == INF:
        return INF if n > 0 else 0.0
    if n == 1:
        return c
    if n == 2:
        return sqrt_up(c)
    return _root_up_pos(c, n)


# ----------------------------------------------------------------------------------------
# forward kernels
# ----------------------------------------------------------------------------------------
@gufunc(2)
def _abs(xl, xh, lo, hi):
    if xl >= 0.0:
        lo[0] = _babs(xl)
        hi[0] = xh
    elif xh <= 0.0:
        lo[0] = _babs(xh)
        hi[0] = -xl
    elif xl == xl:
        lo[0] = 0.0
        hi[0] = _bmax(-xl, xh)
    else:
        lo[0] = NAN
        hi[0] = NAN


@_int_gufunc(2)
def _pown(xl, xh, n, lo, hi):
    if xl != xl or (n < 0 and xl == 0.0 and xh == 0.0):
        lo[0] = NAN
        hi[0] = NAN
        return
    if n == 0:
        lo[0] = 1.0
        hi[0] = 1.0
        return
    if n & 1:  # odd: increasing for n > 0; decreasing on each side of the pole for n < 0
        if n > 0:
            lo[0] = _pow_lo_odd(xl, n)
            hi[0] = _pow_hi_odd(xh, n)
        elif xl >= 0.0:
            lo[0] = _pow_lo(xh, n)
            hi[0] = _pow_hi(_babs(xl), n)
        elif xh <= 0.0:
            lo[0] = -_pow_hi(_babs(xh), n)
            hi[0] = -_pow_lo(-xl, n)
        else:
            lo[0] = -INF
            hi[0] = INF
        return
    # even: a function of |x|, increasing for n > 0, decreasing for n < 0
    if xl >= 0.0:
        ml = _babs(xl)
        mh = xh
    elif xh <= 0.0:
        ml = _babs(xh)
        mh = -xl
    else:
        ml = 0.0
        mh = _bmax(-xl, xh)
    if n > 0:
        lo[0] = _pow_lo(ml, n)
        hi[0] = _pow_hi(mh, n)
    else:
        lo[0] = _pow_lo(mh, n)
        hi[0] = _pow_hi(ml, n)


@gufunc(4)
def _min(al, ah, bl, bh, lo, hi):
    if al != al or bl != bl:
        lo[0] = NAN
        hi[0] = NAN
        return
    lo[0] = _bmin(al, bl)
    hi[0] = _bmin(ah, bh)


@gufunc(4)
def _max(al, ah, bl, bh, lo, hi):
    if al != al or bl != bl:
        lo[0] = NAN
        hi[0] = NAN
        return
    lo[0] = _bmax(al, bl)
    hi[0] = _bmax(ah, bh)


@gufunc(2)
def _sign(xl, xh, lo, hi):
    if xl != xl:
        lo[0] = NAN
        hi[0] = NAN
        return
    lo[0] = -1.0 if xl < 0.0 else (1.0 if xl > 0.0 else 0.0)
    hi[0] = 1.0 if xh > 0.0 else (-1.0 if xh < 0.0 else 0.0)


@gufunc(2)
def _floor(xl, xh, lo, hi):
    lo[0] = np.floor(xl)  # exact; NaN stays NaN, infinities stay
    hi[0] = np.floor(xh)


@gufunc(2)
def _ceil(xl, xh, lo, hi):
    lo[0] = np.ceil(xl)
    hi[0] = np.ceil(xh)


@gufunc(2)
def _trunc(xl, xh, lo, hi):
    lo[0] = np.trunc(xl)
    hi[0] = np.trunc(xh)


# ----------------------------------------------------------------------------------------
# backward kernels
# ----------------------------------------------------------------------------------------
@gufunc(6, 4)
def _add_rev(zl, zh, xl, xh, yl, yh, xlo, xhi, ylo, yhi):
    # x in Z - Y, then y in Z - X'
    if zl == zl and xl == xl and yl == yl:
        a, b = _meet(xl, xh, sub_dn(zl, yh), sub_up(zh, yl))
        if a <= b:
            c, d = _meet(yl, yh, sub_dn(zl, b), sub_up(zh, a))
            if c <= d:
                xlo[0] = a
                xhi[0] = b
                ylo[0] = c
                yhi[0] = d
                return
    xlo[0] = NAN
    xhi[0] = NAN
    ylo[0] = NAN
    yhi[0] = NAN


@gufunc(6, 4)
def _sub_rev(zl, zh, xl, xh, yl, yh, xlo, xhi, ylo, yhi):
    # z = x - y: x in Z + Y, then y in X' - Z
    if zl == zl and xl == xl and yl == yl:
        a, b = _meet(xl, xh, add_dn(zl, yl), add_up(zh, yh))
        if a <= b:
            c, d = _meet(yl, yh, sub_dn(a, zh), sub_up(b, zl))
            if c <= d:
                xlo[0] = a
                xhi[0] = b
                ylo[0] = c
                yhi[0] = d
                return
    xlo[0] = NAN
    xhi[0] = NAN
    ylo[0] = NAN
    yhi[0] = NAN


@gufunc(6, 4)
def _mul_rev(zl, zh, xl, xh, yl, yh, xlo, xhi, ylo, yhi):
    # z = x*y: x in X ∩ mulRevToPair(Y, Z) (two pieces), then y in Y ∩ mulRevToPair(X', Z).
    # One loop over the two passes (roles swapped) keeps a single inlined copy of _div_pair.
    if zl == zl and xl == xl and yl == yl:
        al = xl
        ah = xh
        bl = yl
        bh = yh
        for _ in range(2):
            l1, h1, l2, h2 = _div_pair(zl, zh, bl, bh)
            a, b = _hull_meet2(al, ah, l1, h1, l2, h2)
            if not a <= b:
                al = NAN
                break
            al = bl
            ah = bh
            bl = a
            bh = b
        if al == al:  # after the two passes: (al, ah) = x', (bl, bh) = y'
            xlo[0] = al
            xhi[0] = ah
            ylo[0] = bl
            yhi[0] = bh
            return
    xlo[0] = NAN
    xhi[0] = NAN
    ylo[0] = NAN
    yhi[0] = NAN


@gufunc(6, 4)
def _div_rev(zl, zh, xl, xh, yl, yh, xlo, xhi, ylo, yhi):
    # z = x/y (y != 0): x in X ∩ Z*Y, then y in Y ∩ {y : exists z in Z, y*z in X'}, y != 0
    if zl == zl and xl == xl and yl == yl and not (yl == 0.0 and yh == 0.0):
        pl, ph = _mul_lohi(zl, zh, yl, yh)
        a, b = _meet(xl, xh, pl, ph)
        if a <= b:
            l1, h1, l2, h2 = _div_pair(a, b, zl, zh)
            c, d = _hull_meet2(yl, yh, l1, h1, l2, h2)
            if c <= d and not (c == 0.0 and d == 0.0):
                xlo[0] = a
                xhi[0] = b
                ylo[0] = c
                yhi[0] = d
                return
    xlo[0] = NAN
    xhi[0] = NAN
    ylo[0] = NAN
    yhi[0] = NAN


@gufunc(4)
def _neg_rev(zl, zh, xl, xh, lo, hi):
    a, b = _meet(xl, xh, -zh, -zl)
    if a <= b and zl == zl and xl == xl:
        lo[0] = a
        hi[0] = b
    else:
        lo[0] = NAN
        hi[0] = NAN


@gufunc(4)
def _sqr_rev(zl, zh, xl, xh, lo, hi):
    if zh >= 0.0 and xl == xl:  # false when Z is empty or negative
        sl = sqrt_dn(_bmax(zl, 0.0))
        sh = sqrt_up(zh)
        a, b = _hull_meet2(xl, xh, -sh, -sl, sl, sh)
        if a <= b:
            lo[0] = a
            hi[0] = b
            return
    lo[0] = NAN
    hi[0] = NAN


@gufunc(4)
def _sqrt_rev(zl, zh, xl, xh, lo, hi):
    if zh >= 0.0 and xl == xl:
        zl0 = _bmax(zl, 0.0)
        a, b = _meet(xl, xh, _bmax(mul_dn(zl0, zl0), 0.0), mul_up(zh, zh))
        if a <= b:
            lo[0] = a
            hi[0] = b
            return
    lo[0] = NAN
    hi[0] = NAN


@gufunc(4)
def _abs_rev(zl, zh, xl, xh, lo, hi):
    if zh >= 0.0 and xl == xl:
        zl0 = _bmax(zl, 0.0)
        a, b = _hull_meet2(xl, xh, -zh, -zl0, zl0, zh)
        if a <= b:
            lo[0] = a
            hi[0] = b
            return
    lo[0] = NAN
    hi[0] = NAN


@_int_gufunc(4)
def _pown_rev(zl, zh, xl, xh, n, lo, hi):
    lo[0] = NAN
    hi[0] = NAN
    if zl != zl or xl != xl:
        return
    if n == 0:  # x**0 = 1 for every x
        if zl <= 1.0 <= zh:
            lo[0] = xl
            hi[0] = xh
        return
    l1 = INF
    h1 = -INF
    l2 = INF
    h2 = -INF
    if n & 1:
        if n > 0:  # increasing bijection
            l1 = -_root_up(-zl, n) if zl < 0.0 else _root_dn(zl, n)
            h1 = -_root_dn(-zh, n) if zh < 0.0 else _root_up(zh, n)
        else:  # x**n > 0 for x > 0, < 0 for x < 0, decreasing on each side
            if zh > 0.0:
                l1 = _root_dn(zh, n)
                h1 = _root_up(_bmax(zl, 0.0), n)
            if zl < 0.0:
                l2 = -_root_up(-_bmin(zh, 0.0), n)
                h2 = -_root_dn(-zl, n)
    elif n > 0:  # x**n = |x|**n >= 0, increasing in |x|
        if zh >= 0.0:
            sl = _root_dn(_bmax(zl, 0.0), n)
            sh = _root_up(zh, n)
            l1 = -sh
            h1 = -sl
            l2 = sl
            h2 = sh
    elif zh > 0.0:  # n < 0 even: x**n > 0, decreasing in |x|
        sl = _root_dn(zh, n)
        sh = _root_up(_bmax(zl, 0.0), n)
        l1 = -sh
        h1 = -sl
        l2 = sl
        h2 = sh
    a, b = _hull_meet2(xl, xh, l1, h1, l2, h2)
    if a <= b:
        lo[0] = a
        hi[0] = b


@gufunc(6, 4)
def _min_rev(zl, zh, xl, xh, yl, yh, xlo, xhi, ylo, yhi):
    # _bmin(x, y) in Z: (x in Z and some y >= x) or (some y in Y ∩ Z with y <= x)
    if zl == zl and xl == xl and yl == yl:
        yz = _bmax(yl, zl) <= _bmin(yh, zh)
        a, b = _hull_meet2(xl, xh, zl, _bmin(zh, yh),
                           _bmax(yl, zl) if yz else INF, INF if yz else -INF)
        if a <= b:
            xz = _bmax(a, zl) <= _bmin(b, zh)
            c, d = _hull_meet2(yl, yh, zl, _bmin(zh, b),
                               _bmax(a, zl) if xz else INF, INF if xz else -INF)
            if c <= d:
                xlo[0] = a
                xhi[0] = b
                ylo[0] = c
                yhi[0] = d
                return
    xlo[0] = NAN
    xhi[0] = NAN
    ylo[0] = NAN
    yhi[0] = NAN


@gufunc(6, 4)
def _max_rev(zl, zh, xl, xh, yl, yh, xlo, xhi, ylo, yhi):
    # _bmax(x, y) in Z: (x in Z and some y <= x) or (some y in Y ∩ Z with y >= x)
    if zl == zl and xl == xl and yl == yl:
        yz = _bmax(yl, zl) <= _bmin(yh, zh)
        a, b = _hull_meet2(xl, xh, _bmax(zl, yl), zh,
                           -INF if yz else INF, _bmin(yh, zh) if yz else -INF)
        if a <= b:
            xz = _bmax(a, zl) <= _bmin(b, zh)
            c, d = _hull_meet2(yl, yh, _bmax(zl, a), zh,
                               -INF if xz else INF, _bmin(b, zh) if xz else -INF)
            if c <= d:
                xlo[0] = a
                xhi[0] = b
                ylo[0] = c
                yhi[0] = d
                return
    xlo[0] = NAN
    xhi[0] = NAN
    ylo[0] = NAN
    yhi[0] = NAN


@gufunc(4)
def _sign_rev(zl, zh, xl, xh, lo, hi):
    a = INF
    b = -INF
    if zl == zl and xl == xl:
        if zl <= -1.0 <= zh and xl < 0.0:  # x < 0
            a = xl
            b = _bmin(xh, 0.0)
        if zl <= 0.0 <= zh and xl <= 0.0 <= xh:  # x = 0
            a = _bmin(a, 0.0)
            b = _bmax(b, 0.0)
        if zl <= 1.0 <= zh and xh > 0.0:  # x > 0
            a = _bmin(a, _bmax(xl, 0.0))
            b = xh
    if a <= b:
        lo[0] = a
        hi[0] = b
    else:
        lo[0] = NAN
        hi[0] = NAN


@gufunc(4)
def _floor_rev(zl, zh, xl, xh, lo, hi):
    # floor(x) = k  <=>  k <= x < k + 1, for the integers k in Z
    lo[0] = NAN
    hi[0] = NAN
    if zl != zl or xl != xl:
        return
    kl = np.ceil(zl)
    kh = np.floor(zh)
    a = _bmax(xl, kl)
    if kl > kh or a > xh or np.floor(a) > kh:  # the last test: a >= kh + 1 (exact)
        return
    lo[0] = a
    hi[0] = xh if np.floor(xh) <= kh else add_up(kh, 1.0)


@gufunc(4)
def _ceil_rev(zl, zh, xl, xh, lo, hi):
    # ceil(x) = k  <=>  k - 1 < x <= k, for the integers k in Z
    lo[0] = NAN
    hi[0] = NAN
    if zl != zl or xl != xl:
        return
    kl = np.ceil(zl)
    kh = np.floor(zh)
    b = _bmin(xh, kh)
    if kl > kh or b < xl or np.ceil(b) < kl:  # the last test: b <= kl - 1 (exact)
        return
    lo[0] = xl if np.ceil(xl) >= kl else sub_dn(kl, 1.0)
    hi[0] = b


# ----------------------------------------------------------------------------------------
# public API
# ----------------------------------------------------------------------------------------
def _unary(kernel, x: IntervalLike, out: Interval | None) -> Interval:
    x = as_interval(x)
    if out is None:
        return Interval._new(*kernel(x.lo, x.hi))
    kernel(x.lo, x.hi, out.lo, out.hi)
    return out


def _binary(kernel, x: IntervalLike, y: IntervalLike, out: Interval | None) -> Interval:
    x, y = as_interval(x), as_interval(y)
    if out is None:
        return Interval._new(*kernel(x.lo, x.hi, y.lo, y.hi))
    kernel(x.lo, x.hi, y.lo, y.hi, out.lo, out.hi)
    return out


def _rev1(kernel, z: IntervalLike, x: IntervalLike, out: Interval | None) -> Interval:
    z, x = as_interval(z), as_interval(x)
    if out is None:
        return Interval._new(*kernel(z.lo, z.hi, x.lo, x.hi))
    kernel(z.lo, z.hi, x.lo, x.hi, out.lo, out.hi)
    return out


def _rev2(kernel, z: IntervalLike, x: IntervalLike, y: IntervalLike,
          out: tuple[Interval, Interval] | None) -> tuple[Interval, Interval]:
    z, x, y = as_interval(z), as_interval(x), as_interval(y)
    if out is None:
        xl, xh, yl, yh = kernel(z.lo, z.hi, x.lo, x.hi, y.lo, y.hi)
        return Interval._new(xl, xh), Interval._new(yl, yh)
    kernel(z.lo, z.hi, x.lo, x.hi, y.lo, y.hi, out[0].lo, out[0].hi, out[1].lo, out[1].hi)
    return out


def _exponent(n: ArrayLike) -> np.ndarray:
    """The integer exponent(s) ``n`` as int64, refusing non-integers and |n| >= 2**62."""
    arr = np.asarray(n)
    if arr.dtype == np.bool_ or arr.dtype.kind not in "iuf":
        raise ValueError(f"pown exponent must be an integer, got {n!r}")
    if arr.dtype.kind == "f":
        if not np.all(np.isfinite(arr) & (arr == np.round(arr))):
            raise ValueError(f"pown exponent must be an integer, got {n!r}")
        if np.any(np.abs(arr) >= float(_N_LIMIT)):
            raise ValueError(f"pown exponent must satisfy |n| < 2**62, got {n!r}")
        return arr.astype(np.int64)
    if arr.dtype.kind == "u":
        if np.any(arr >= _N_LIMIT):
            raise ValueError(f"pown exponent must satisfy |n| < 2**62, got {n!r}")
        return arr.astype(np.int64)
    arr = arr.astype(np.int64)
    if np.any((arr >= _N_LIMIT) | (arr <= -_N_LIMIT)):
        raise ValueError(f"pown exponent must satisfy |n| < 2**62, got {n!r}")
    return arr


def _exponent_checked(n: ArrayLike) -> np.ndarray:
    if isinstance(n, int) and not isinstance(n, bool) and _babs(n) >= _N_LIMIT:
        raise ValueError(f"pown exponent must satisfy |n| < 2**62, got {n!r}")
    return _exponent(n)


def abs(x: IntervalLike, out: Interval | None = None) -> Interval:
    """``|x|`` (exact): ``abs([-3, 2]) = [0, 3]``."""
    return _unary(_abs, x, out)


def pown(x: IntervalLike, n: ArrayLike, out: Interval | None = None) -> Interval:
    """``x**n`` for an integer ``n`` (a Python int or an integer array broadcasting with ``x``).

    IEEE 1788 ``pown``: ``pown(x, 0) = [1, 1]`` for non-empty ``x`` (also at 0); a negative ``n``
    means ``1 / x**|n|`` over ``x != 0`` (``pown([-1, 1], -2) = [1, inf]``,
    ``pown([0, 0], -1)`` is empty). Even powers use the case analysis of ``sqr``, never
    ``x * x``. Bounds are the tightest floats but in rare hard-to-round cases (one ulp wider).
    """
    x = as_interval(x)
    k = _exponent_checked(n)
    if out is None:
        return Interval._new(*_pown(x.lo, x.hi, k))
    _pown(x.lo, x.hi, k, out.lo, out.hi)
    return out


def min(x: IntervalLike, y: IntervalLike, out: Interval | None = None) -> Interval:
    """Elementwise ``{min(a, b) : a in x, b in y}`` (exact)."""
    return _binary(_min, x, y, out)


def max(x: IntervalLike, y: IntervalLike, out: Interval | None = None) -> Interval:
    """Elementwise ``{max(a, b) : a in x, b in y}`` (exact)."""
    return _binary(_max, x, y, out)


def sign(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Hull of the signs (-1, 0 or 1) taken over ``x``: ``sign([0, 2]) = [0, 1]``."""
    return _unary(_sign, x, out)


def floor(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Hull of ``floor`` over ``x`` (exact): ``floor([-1.1, 2]) = [-2, 2]``."""
    return _unary(_floor, x, out)


def ceil(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Hull of ``ceil`` over ``x`` (exact): ``ceil([-1.1, 2]) = [-1, 2]``."""
    return _unary(_ceil, x, out)


def trunc(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Hull of rounding towards zero over ``x`` (exact): ``trunc([-1.9, 2.2]) = [-1, 2]``."""
    return _unary(_trunc, x, out)


def add_rev(z: IntervalLike, x: IntervalLike, y: IntervalLike,
            out: tuple[Interval, Interval] | None = None) -> tuple[Interval, Interval]:
    """Contract ``x`` and ``y`` with ``z = x + y``; returns ``(x', y')``."""
    return _rev2(_add_rev, z, x, y, out)


def sub_rev(z: IntervalLike, x: IntervalLike, y: IntervalLike,
            out: tuple[Interval, Interval] | None = None) -> tuple[Interval, Interval]:
    """Contract ``x`` and ``y`` with ``z = x - y``; returns ``(x', y')``."""
    return _rev2(_sub_rev, z, x, y, out)


def mul_rev(z: IntervalLike, x: IntervalLike, y: IntervalLike,
            out: tuple[Interval, Interval] | None = None) -> tuple[Interval, Interval]:
    """Contract ``x`` and ``y`` with ``z = x * y``; returns ``(x', y')``.

    Division by a factor containing 0 is extended: ``x'`` is the hull of ``x`` intersected with
    each of the (up to two) pieces of ``{x : x*y in z}``, so ``mul_rev([1, 2], [-0.5, 0.5],
    [-1, 1])`` is empty. When ``0`` is in both ``z`` and ``y``, ``x`` is not constrained.
    """
    return _rev2(_mul_rev, z, x, y, out)


def div_rev(z: IntervalLike, x: IntervalLike, y: IntervalLike,
            out: tuple[Interval, Interval] | None = None) -> tuple[Interval, Interval]:
    """Contract ``x`` and ``y`` with ``z = x / y`` (``y != 0``); returns ``(x', y')``."""
    return _rev2(_div_rev, z, x, y, out)


def min_rev(z: IntervalLike, x: IntervalLike, y: IntervalLike,
            out: tuple[Interval, Interval] | None = None) -> tuple[Interval, Interval]:
    """Contract ``x`` and ``y`` with ``z = _bmin(x, y)``; returns ``(x', y')`` (exact)."""
    return _rev2(_min_rev, z, x, y, out)


def max_rev(z: IntervalLike, x: IntervalLike, y: IntervalLike,
            out: tuple[Interval, Interval] | None = None) -> tuple[Interval, Interval]:
    """Contract ``x`` and ``y`` with ``z = _bmax(x, y)``; returns ``(x', y')`` (exact)."""
    return _rev2(_max_rev, z, x, y, out)


def neg_rev(z: IntervalLike, x: IntervalLike, out: Interval | None = None) -> Interval:
    """``x ∩ (-z)``: contract ``x`` with ``z = -x``."""
    return _rev1(_neg_rev, z, x, out)


def sqr_rev(z: IntervalLike, x: IntervalLike, out: Interval | None = None) -> Interval:
    """Contract ``x`` with ``z = x**2``: ``hull(x ∩ [-√z], x ∩ [√z])``.

    ``sqr_rev([1, 4], [0, 5]) = [1, 2]``, ``sqr_rev([1, 4], [-5, 5]) = [-2, 2]``.
    """
    return _rev1(_sqr_rev, z, x, out)


def sqrt_rev(z: IntervalLike, x: IntervalLike, out: Interval | None = None) -> Interval:
    """Contract ``x`` with ``z = sqrt(x)``: ``x ∩ [_bmax(z, 0)**2]``."""
    return _rev1(_sqrt_rev, z, x, out)


def abs_rev(z: IntervalLike, x: IntervalLike, out: Interval | None = None) -> Interval:
    """Contract ``x`` with ``z = |x|``: ``abs_rev([1, 2], [-5, 1.5]) = [-2, 1.5]``."""
    return _rev1(_abs_rev, z, x, out)


def pown_rev(z: IntervalLike, x: IntervalLike, n: ArrayLike,
             out: Interval | None = None) -> Interval:
    """Contract ``x`` with ``z = pown(x, n)`` (IEEE 1788 pownRev, integer ``n``).

    ``pown_rev([1, 4], [-5, 5], 2) = [-2, 2]``; ``pown_rev([-8, 27], [-5, 5], 3) = [-2, 3]``;
    ``n = 0`` keeps ``x`` when ``1 in z`` and empties it otherwise.
    """
    z, x = as_interval(z), as_interval(x)
    k = _exponent_checked(n)
    if out is None:
        return Interval._new(*_pown_rev(z.lo, z.hi, x.lo, x.hi, k))
    _pown_rev(z.lo, z.hi, x.lo, x.hi, k, out.lo, out.hi)
    return out


def sign_rev(z: IntervalLike, x: IntervalLike, out: Interval | None = None) -> Interval:
    """Contract ``x`` with ``z = sign(x)``: ``sign_rev([1, 1], [-2, 3]) = [0, 3]``."""
    return _rev1(_sign_rev, z, x, out)


def floor_rev(z: IntervalLike, x: IntervalLike, out: Interval | None = None) -> Interval:
    """Contract ``x`` with ``z = floor(x)``: ``floor_rev([1, 2], [0, 10]) = [1, 3]``."""
    return _rev1(_floor_rev, z, x, out)


def ceil_rev(z: IntervalLike, x: IntervalLike, out: Interval | None = None) -> Interval:
    """Contract ``x`` with ``z = ceil(x)``: ``ceil_rev([1, 2], [0, 10]) = [0, 2]``."""
    return _rev1(_ceil_rev, z, x, out)


@gufunc(4, 4)
def _mul_rev_to_pair(zl, zh, yl, yh, l1, h1, l2, h2):
    if zl != zl or yl != yl:
        a = INF
        b = -INF
        c = INF
        d = -INF
    else:
        a, b, c, d = _div_pair(zl, zh, yl, yh)
    if a <= b:
        l1[0] = a
        h1[0] = b
    else:
        l1[0] = NAN
        h1[0] = NAN
    if c <= d:
        l2[0] = c
        h2[0] = d
    else:
        l2[0] = NAN
        h2[0] = NAN


def mul_rev_to_pair(z: IntervalLike, y: IntervalLike) -> tuple[Interval, Interval]:
    """IEEE 1788 ``mulRevToPair``: ``{x : exists y in Y, x*y in Z}`` as two intervals.

    The first is the lower piece; the second is empty when the set is one interval (or
    empty): ``mul_rev_to_pair([1, 2], [-1, 1]) = ([-inf, -1], [1, inf])``.
    """
    z, y = as_interval(z), as_interval(y)
    a, b, c, d = _mul_rev_to_pair(z.lo, z.hi, y.lo, y.hi)
    return Interval._new(a, b), Interval._new(c, d)
