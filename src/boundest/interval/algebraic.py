"""Algebraic functions (``abs``, ``pown``, ``min``, ``max``, ``sign``, ``floor``, ``ceil``,
``trunc``) and the backward (reverse) operators of the algebraic primitives.

Forward functions return the tightest float64 enclosure of the image (IEEE 1788-2015 set-based
semantics). Backward operators contract their arguments: the unary ``f_rev(z, x)`` returns
``hull{x in X : f(x) in Z}`` and the binary ``f_rev(z, x, y)`` returns ``(x', y')`` with
``x' = hull{x in X : exists y in Y, f(x, y) in Z}`` and likewise ``y'``. Every result is a subset
of the corresponding input and contains every point of the exact set; the empty set is
``[nan, nan]`` and any empty argument makes every result empty.

Kernels are written with selects rather than branches (rounding directions and signs are random
on real data): forward functions and unary backward operators are one Numba ufunc per bound
(vectorised loops), binary backward operators one gufunc per element. ``pown`` evaluates integer
powers in double-word arithmetic (a product of two double-words has a relative error below
``7 u^2``, Joldes, Muller and Popescu, ACM TOMS 2017) with a running rigorous error bound, and
exact results are detected, so its bounds are the tightest float64 ones except in rare
hard-to-round cases, where they are one ulp wider. Roots (``pown_rev``) are found by a
floating-point guess that is then verified (and tightened) with those rigorous power bounds.
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
    ufunc,
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
_bany = any

_jit = nb.njit(cache=True, error_model="numpy")
#: Larger helpers (loops) are compiled once and called, not inlined everywhere.
_jit_call = nb.njit(cache=True, error_model="numpy")

ETA = 2.0**-1074
#: Bound on the relative error of one double-word product (< 8 u^2) or reciprocal (< 11 u^2).
_DW_DELTA = 16.0 * 2.0**-106
#: Covers the round-to-nearest errors made while propagating the error bounds themselves.
_SAFE = 1.0 + 2.0**-40
#: Beyond this (in binary orders of magnitude) a power certainly over- or underflows.
_LOG2_LIMIT = 1100.0
#: The kernels take the exponent of pown as an int64 ``n`` with ``|n| < 2**63``; an integer
#: exponent ``N`` beyond that range stands for ``sign(N) * (_N_HUGE + N % 2)``, an int64 of the
#: same sign and parity. The two have the same power at every float base: for ``|n| >= 7e18``
#: (``_N_HUGE`` and ``_N_HUGE - 1``, the exponent of a derivative, among them) and a float
#: ``a > 0`` other than 1, ``|n log2 a| >= 7e18 * 2**-53 / ln 2 > 1100`` (``1 - 2**-53`` is the
#: float ``!= 1`` nearest to 1 in log; at ``_N_HUGE`` the product exceeds 1400), so ``a**n`` and
#: ``a**N`` both lie beyond ``2**1100`` or both below ``2**-1100`` (on the same side), and
#: ``_pow_pos`` decides both alike (``_LOG2_LIMIT``): ``[MAX, inf]`` or ``[0, ETA]``. The
#: bases 0, 1 and inf depend only on the sign, and a negative base only on the parity too; the
#: roots of ``pown_rev`` are found by comparing such powers of float candidates. Every float
#: beyond ``2**53`` is even, so a float exponent that large maps to ``+-_N_HUGE``.
_N_HUGE = 2**63 - 2
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
# The helpers and kernels below are written with selects (``a if c else b``), not branches or
# and/or chains: the ufunc loops then run them with SIMD, and no misprediction is paid on the
# random outcomes (rounding directions, signs). Numba's min()/max() check for NaN and block
# vectorisation; _smin/_smax are plain selects (a NaN argument is handled by the callers).
@_jit
def _smin(a, b):
    return a if a < b else b


@_jit
def _smax(a, b):
    return a if a > b else b


@_jit
def _hull2(xl, xh, l1, h1, l2, h2):
    """``hull(X ∩ P1, X ∩ P2)`` as ``(lo, hi)``, ``(nan, nan)`` when empty; a piece with
    ``l > h`` is empty. X must be non-empty (checked by the callers)."""
    a = _smax(xl, l1)
    b = _smin(xh, h1)
    c = _smax(xl, l2)
    d = _smin(xh, h2)
    ok1 = a <= b
    ok2 = c <= d
    lo = (_smin(a, c) if ok2 else a) if ok1 else (c if ok2 else NAN)
    hi = (_smax(b, d) if ok2 else b) if ok1 else (d if ok2 else NAN)
    return lo, hi


@_jit
def _q_dn(n, d):
    """Lower bound of ``n / d`` (``d != 0``, not both infinite); ``n / ±inf`` is the limit 0
    exactly (``div_dn`` alone steps out to ``-ETA`` there)."""
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
    absent whenever the set is one interval (IEEE 1788 mulRevToPair; C and B non-empty).
    Every case needs one downward and one upward division, whose operands are selected first.
    """
    pos = bl > 0.0
    nz = pos | (bh < 0.0)  # 0 not in B: C / B = [n1 / d1, n2 / d2], sign case analysis
    cpos = cl >= 0.0
    cneg = ch <= 0.0
    n1 = cl if pos else ch
    n2 = ch if pos else cl
    d1 = (bh if cpos else bl) if pos else (bh if cpos else (bl if cneg else bh))
    d2 = (bl if cpos else (bh if cneg else bl)) if pos else (bl if cpos else bh)
    # 0 in B, 0 not in C. For C > 0: b < 0 gives x <= cl/bl, b > 0 gives x >= cl/bh;
    # for C < 0: b > 0 gives x <= ch/bh, b < 0 gives x >= ch/bl.
    cp = cl > 0.0
    c = cl if cp else ch
    e1 = bl if cp else bh
    e2 = bh if cp else bl
    has1 = (bl < 0.0) if cp else (bh > 0.0)
    has2 = (bh > 0.0) if cp else (bl < 0.0)
    qd = _q_dn(n1 if nz else c, d1 if nz else e2)
    qu = _q_up(n2 if nz else c, d2 if nz else e1)
    zc = (cl <= 0.0) & (ch >= 0.0)  # 0 in B and 0 in C: x * 0 = 0 for every x
    both = has1 & has2
    l1 = qd if nz else (-INF if zc else (-INF if has1 else (qd if has2 else INF)))
    h1 = qu if nz else (INF if zc else (qu if has1 else (INF if has2 else -INF)))
    l2 = INF if nz else (INF if zc else (qd if both else INF))
    h2 = -INF if nz else (-INF if zc else (INF if both else -INF))
    return l1, h1, l2, h2


@_jit
def _mul_lohi(al, ah, bl, bh):
    """Tightest enclosure of ``A * B`` (non-empty), with ``0 * inf = 0``.

    Sign case analysis (selects): only the corners that can be extreme are multiplied, so a
    zero bound is never paired with a tiny one whose product would underflow and step out.
    """
    apos = al >= 0.0
    aneg = ah <= 0.0
    bpos = bl >= 0.0
    bneg = bh <= 0.0
    mixed = (not apos) & (not aneg) & (not bpos) & (not bneg)  # 0 inside both
    p1 = (al if bpos else ah) if apos else (al if bpos else (ah if bneg else al))
    q1 = bl if apos else (bh if aneg else (bh if bpos else (bl if bneg else bh)))
    p3 = (ah if bpos else (al if bneg else ah)) if apos else (ah if bpos else al)
    q3 = bh if apos else (bl if aneg else (bh if bpos else bl))
    lo = mul_dn(p1, q1)
    hi = mul_up(p3, q3)
    lo2 = mul_dn(ah, bl)  # the other candidates when 0 is inside both factors
    hi2 = mul_up(ah, bh)
    lo = _smin(lo, lo2) if mixed else lo
    hi = _smax(hi, hi2) if mixed else hi
    return lo, hi


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
    """``(lo, hi)`` enclosing ``a**n`` for finite ``a > 0`` and an integer ``0 < |n| < 2**63``."""
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
    # np.bool_, not the literals: one compilation of _scale, not one per Literal[bool]
    return _scale(lo, re, np.bool_(False)), _scale(hi, re, np.bool_(True))


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
        t = _step(r, k, np.bool_(True))
        if not _below_root(t, c, n):
            break
        r = t
        k *= 2.0
    k *= 0.5
    while k >= 1.0:
        t = _step(r, k, np.bool_(True))
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
        t = _step(r, k, np.bool_(False))
        if not _above_root(t, c, n):
            break
        r = t
        k *= 2.0
    k *= 0.5
    while k >= 1.0:
        t = _step(r, k, np.bool_(False))
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
# forward kernels: one branch-free ufunc per bound (pown: a gufunc with an integer exponent)
# ----------------------------------------------------------------------------------------
@_jit
def _abs_all(xl, xh):
    lo = (xl + 0.0) if xl >= 0.0 else ((0.0 - xh) if xh <= 0.0 else 0.0)  # + 0.0: no -0.0
    return (lo if xl == xl else NAN), _smax(-xl, xh)  # NaN stays NaN in the upper bound


@_jit
def _min_all(al, ah, bl, bh):
    ok = (al == al) & (bl == bl)
    return (_smin(al, bl) if ok else NAN), (_smin(ah, bh) if ok else NAN)


@_jit
def _max_all(al, ah, bl, bh):
    ok = (al == al) & (bl == bl)
    return (_smax(al, bl) if ok else NAN), (_smax(ah, bh) if ok else NAN)


@_jit
def _sign_all(xl, xh):
    lo = -1.0 if xl < 0.0 else (1.0 if xl > 0.0 else 0.0)
    hi = 1.0 if xh > 0.0 else (-1.0 if xh < 0.0 else 0.0)
    return (lo if xl == xl else NAN), (hi if xl == xl else NAN)


@_jit
def _floor_all(xl, xh):  # floor, ceil and trunc are exact; NaN stays NaN
    return np.floor(xl), np.floor(xh)


@_jit
def _ceil_all(xl, xh):
    return np.ceil(xl), np.ceil(xh)


@_jit
def _trunc_all(xl, xh):
    return np.trunc(xl), np.trunc(xh)


@ufunc(2)
def _abs_lo(xl, xh):
    return _abs_all(xl, xh)[0]


@ufunc(2)
def _abs_hi(xl, xh):
    return _abs_all(xl, xh)[1]


@ufunc(2)
def _sign_lo(xl, xh):
    return _sign_all(xl, xh)[0]


@ufunc(2)
def _sign_hi(xl, xh):
    return _sign_all(xl, xh)[1]


@ufunc(2)
def _floor_lo(xl, xh):
    return _floor_all(xl, xh)[0]


@ufunc(2)
def _floor_hi(xl, xh):
    return _floor_all(xl, xh)[1]


@ufunc(2)
def _ceil_lo(xl, xh):
    return _ceil_all(xl, xh)[0]


@ufunc(2)
def _ceil_hi(xl, xh):
    return _ceil_all(xl, xh)[1]


@ufunc(2)
def _trunc_lo(xl, xh):
    return _trunc_all(xl, xh)[0]


@ufunc(2)
def _trunc_hi(xl, xh):
    return _trunc_all(xl, xh)[1]


@ufunc(4)
def _min_lo(al, ah, bl, bh):
    return _min_all(al, ah, bl, bh)[0]


@ufunc(4)
def _min_hi(al, ah, bl, bh):
    return _min_all(al, ah, bl, bh)[1]


@ufunc(4)
def _max_lo(al, ah, bl, bh):
    return _max_all(al, ah, bl, bh)[0]


@ufunc(4)
def _max_hi(al, ah, bl, bh):
    return _max_all(al, ah, bl, bh)[1]


# Element kernels with the gufunc calling convention (outputs are 1-element arrays), whose
# ``.scalar`` compiled callers (the propagation engine) use; the public functions run the
# ufuncs above.
@gufunc(2)
def _abs(xl, xh, lo, hi):
    lo[0], hi[0] = _abs_all(xl, xh)


@gufunc(2)
def _sign(xl, xh, lo, hi):
    lo[0], hi[0] = _sign_all(xl, xh)


@gufunc(2)
def _floor(xl, xh, lo, hi):
    lo[0], hi[0] = _floor_all(xl, xh)


@gufunc(2)
def _ceil(xl, xh, lo, hi):
    lo[0], hi[0] = _ceil_all(xl, xh)


@gufunc(2)
def _trunc(xl, xh, lo, hi):
    lo[0], hi[0] = _trunc_all(xl, xh)


@gufunc(4)
def _min(al, ah, bl, bh, lo, hi):
    lo[0], hi[0] = _min_all(al, ah, bl, bh)


@gufunc(4)
def _max(al, ah, bl, bh, lo, hi):
    lo[0], hi[0] = _max_all(al, ah, bl, bh)


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


# ----------------------------------------------------------------------------------------
# backward kernels: a select-based scalar function computes every result (NaN when empty).
# Unary operators run one ufunc per bound (SIMD); binary ones run one gufunc per element,
# since four ufuncs would each redo the whole work. x' and y' are empty together.
# ----------------------------------------------------------------------------------------
@_jit
def _nonempty3(zl, xl, yl):
    return (zl == zl) & (xl == xl) & (yl == yl)


@_jit
def _finish2(a, b, c, d, ok):
    """``(x', y')`` bounds, all NaN unless ``ok`` and both are non-empty."""
    ok = ok & (a <= b) & (c <= d)
    return (a if ok else NAN), (b if ok else NAN), (c if ok else NAN), (d if ok else NAN)


@_jit
def _add_rev_all(zl, zh, xl, xh, yl, yh):
    # x in Z - Y, then y in Z - X'
    a = _smax(xl, sub_dn(zl, yh))
    b = _smin(xh, sub_up(zh, yl))
    c = _smax(yl, sub_dn(zl, b))
    d = _smin(yh, sub_up(zh, a))
    return _finish2(a, b, c, d, _nonempty3(zl, xl, yl))


@_jit
def _sub_rev_all(zl, zh, xl, xh, yl, yh):
    # z = x - y: x in Z + Y, then y in X' - Z
    a = _smax(xl, add_dn(zl, yl))
    b = _smin(xh, add_up(zh, yh))
    c = _smax(yl, sub_dn(a, zh))
    d = _smin(yh, sub_up(b, zl))
    return _finish2(a, b, c, d, _nonempty3(zl, xl, yl))


@_jit
def _mul_rev_all(zl, zh, xl, xh, yl, yh):
    # z = x*y: x in X ∩ mulRevToPair(Y, Z) (two pieces), then y in Y ∩ mulRevToPair(X', Z)
    l1, h1, l2, h2 = _div_pair(zl, zh, yl, yh)
    a, b = _hull2(xl, xh, l1, h1, l2, h2)
    l1, h1, l2, h2 = _div_pair(zl, zh, a, b)
    c, d = _hull2(yl, yh, l1, h1, l2, h2)
    return _finish2(a, b, c, d, _nonempty3(zl, xl, yl))


@_jit
def _div_rev_all(zl, zh, xl, xh, yl, yh):
    # z = x/y (y != 0): x in X ∩ Z*Y, then y in Y ∩ {y : exists z in Z, y*z in X'}, y != 0
    pl, ph = _mul_lohi(zl, zh, yl, yh)
    a = _smax(xl, pl)
    b = _smin(xh, ph)
    l1, h1, l2, h2 = _div_pair(a, b, zl, zh)
    c, d = _hull2(yl, yh, l1, h1, l2, h2)
    ok = _nonempty3(zl, xl, yl) & ((c != 0.0) | (d != 0.0))  # y = 0 is no divisor
    return _finish2(a, b, c, d, ok)


@_jit
def _min_rev_all(zl, zh, xl, xh, yl, yh):
    # min(x, y) in Z: (x in Z and some y >= x) or (some y in Y ∩ Z with y <= x)
    yz = _smax(yl, zl) <= _smin(yh, zh)
    a, b = _hull2(xl, xh, zl, _smin(zh, yh), _smax(yl, zl) if yz else INF, INF if yz else -INF)
    xz = _smax(a, zl) <= _smin(b, zh)
    c, d = _hull2(yl, yh, zl, _smin(zh, b), _smax(a, zl) if xz else INF, INF if xz else -INF)
    return _finish2(a, b, c, d, _nonempty3(zl, xl, yl))


@_jit
def _max_rev_all(zl, zh, xl, xh, yl, yh):
    # max(x, y) in Z: (x in Z and some y <= x) or (some y in Y ∩ Z with y >= x)
    yz = _smax(yl, zl) <= _smin(yh, zh)
    a, b = _hull2(xl, xh, _smax(zl, yl), zh, -INF if yz else INF, _smin(yh, zh) if yz else -INF)
    xz = _smax(a, zl) <= _smin(b, zh)
    c, d = _hull2(yl, yh, _smax(zl, a), zh, -INF if xz else INF, _smin(b, zh) if xz else -INF)
    return _finish2(a, b, c, d, _nonempty3(zl, xl, yl))


@_jit
def _finish1(a, b, ok):
    ok = ok & (a <= b)
    return (a if ok else NAN), (b if ok else NAN)


@_jit
def _neg_rev_all(zl, zh, xl, xh):
    return _finish1(_smax(xl, -zh), _smin(xh, -zl), (zl == zl) & (xl == xl))


@_jit
def _sqr_rev_all(zl, zh, xl, xh):
    # x in [-sqrt(zh), -sqrt(zl)] u [sqrt(zl), sqrt(zh)] (Z ∩ [0, inf])
    sl = sqrt_dn(_smax(zl, 0.0))
    sh = sqrt_up(zh)
    a, b = _hull2(xl, xh, -sh, -sl, sl, sh)
    return _finish1(a, b, (zh >= 0.0) & (xl == xl))


@_jit
def _sqrt_rev_all(zl, zh, xl, xh):
    zl0 = _smax(zl, 0.0)
    a = _smax(xl, _smax(mul_dn(zl0, zl0), 0.0))
    b = _smin(xh, mul_up(zh, zh))
    return _finish1(a, b, (zh >= 0.0) & (xl == xl))


@_jit
def _abs_rev_all(zl, zh, xl, xh):
    zl0 = _smax(zl, 0.0)
    a, b = _hull2(xl, xh, -zh, -zl0, zl0, zh)
    return _finish1(a, b, (zh >= 0.0) & (xl == xl))


@_jit
def _sign_rev_all(zl, zh, xl, xh):
    neg = (zl <= -1.0) & (zh >= -1.0) & (xl < 0.0)  # some x < 0
    zer = (zl <= 0.0) & (zh >= 0.0) & (xl <= 0.0) & (xh >= 0.0)  # x = 0
    pos = (zl <= 1.0) & (zh >= 1.0) & (xh > 0.0)  # some x > 0
    lo = xl if neg else (0.0 if zer else (_smax(xl, 0.0) if pos else NAN))
    hi = xh if pos else (0.0 if zer else (_smin(xh, 0.0) if neg else NAN))
    return lo, hi


@_jit
def _floor_rev_all(zl, zh, xl, xh):
    # floor(x) = k  <=>  k <= x < k + 1, for the integers k in Z
    kl = np.ceil(zl)
    kh = np.floor(zh)
    a = _smax(xl, kl)
    b = xh if np.floor(xh) <= kh else add_up(kh, 1.0)
    ok = (zl == zl) & (xl == xl) & (kl <= kh) & (np.floor(a) <= kh)  # a < kh + 1, exactly
    return _finish1(a, b, ok)


@_jit
def _ceil_rev_all(zl, zh, xl, xh):
    # ceil(x) = k  <=>  k - 1 < x <= k, for the integers k in Z
    kl = np.ceil(zl)
    kh = np.floor(zh)
    b = _smin(xh, kh)
    a = xl if np.ceil(xl) >= kl else sub_dn(kl, 1.0)
    ok = (zl == zl) & (xl == xl) & (kl <= kh) & (np.ceil(b) >= kl)  # b > kl - 1, exactly
    return _finish1(a, b, ok)


@ufunc(4)
def _neg_rev_lo(zl, zh, xl, xh):
    return _neg_rev_all(zl, zh, xl, xh)[0]


@ufunc(4)
def _neg_rev_hi(zl, zh, xl, xh):
    return _neg_rev_all(zl, zh, xl, xh)[1]


_NEG_REV = (_neg_rev_lo, _neg_rev_hi)


@ufunc(4)
def _sqr_rev_lo(zl, zh, xl, xh):
    return _sqr_rev_all(zl, zh, xl, xh)[0]


@ufunc(4)
def _sqr_rev_hi(zl, zh, xl, xh):
    return _sqr_rev_all(zl, zh, xl, xh)[1]


_SQR_REV = (_sqr_rev_lo, _sqr_rev_hi)


@ufunc(4)
def _sqrt_rev_lo(zl, zh, xl, xh):
    return _sqrt_rev_all(zl, zh, xl, xh)[0]


@ufunc(4)
def _sqrt_rev_hi(zl, zh, xl, xh):
    return _sqrt_rev_all(zl, zh, xl, xh)[1]


_SQRT_REV = (_sqrt_rev_lo, _sqrt_rev_hi)


@ufunc(4)
def _abs_rev_lo(zl, zh, xl, xh):
    return _abs_rev_all(zl, zh, xl, xh)[0]


@ufunc(4)
def _abs_rev_hi(zl, zh, xl, xh):
    return _abs_rev_all(zl, zh, xl, xh)[1]


_ABS_REV = (_abs_rev_lo, _abs_rev_hi)


@ufunc(4)
def _sign_rev_lo(zl, zh, xl, xh):
    return _sign_rev_all(zl, zh, xl, xh)[0]


@ufunc(4)
def _sign_rev_hi(zl, zh, xl, xh):
    return _sign_rev_all(zl, zh, xl, xh)[1]


_SIGN_REV = (_sign_rev_lo, _sign_rev_hi)


@ufunc(4)
def _floor_rev_lo(zl, zh, xl, xh):
    return _floor_rev_all(zl, zh, xl, xh)[0]


@ufunc(4)
def _floor_rev_hi(zl, zh, xl, xh):
    return _floor_rev_all(zl, zh, xl, xh)[1]


_FLOOR_REV = (_floor_rev_lo, _floor_rev_hi)


@ufunc(4)
def _ceil_rev_lo(zl, zh, xl, xh):
    return _ceil_rev_all(zl, zh, xl, xh)[0]


@ufunc(4)
def _ceil_rev_hi(zl, zh, xl, xh):
    return _ceil_rev_all(zl, zh, xl, xh)[1]


_CEIL_REV = (_ceil_rev_lo, _ceil_rev_hi)


# Element kernels with the gufunc calling convention (outputs are 1-element arrays): the
# binary ones run the public functions; all serve compiled callers through ``.scalar``.
@gufunc(6, 4)
def _add_rev(zl, zh, xl, xh, yl, yh, xlo, xhi, ylo, yhi):
    xlo[0], xhi[0], ylo[0], yhi[0] = _add_rev_all(zl, zh, xl, xh, yl, yh)


@gufunc(6, 4)
def _sub_rev(zl, zh, xl, xh, yl, yh, xlo, xhi, ylo, yhi):
    xlo[0], xhi[0], ylo[0], yhi[0] = _sub_rev_all(zl, zh, xl, xh, yl, yh)


@gufunc(6, 4)
def _mul_rev(zl, zh, xl, xh, yl, yh, xlo, xhi, ylo, yhi):
    xlo[0], xhi[0], ylo[0], yhi[0] = _mul_rev_all(zl, zh, xl, xh, yl, yh)


@gufunc(6, 4)
def _div_rev(zl, zh, xl, xh, yl, yh, xlo, xhi, ylo, yhi):
    xlo[0], xhi[0], ylo[0], yhi[0] = _div_rev_all(zl, zh, xl, xh, yl, yh)


@gufunc(6, 4)
def _min_rev(zl, zh, xl, xh, yl, yh, xlo, xhi, ylo, yhi):
    xlo[0], xhi[0], ylo[0], yhi[0] = _min_rev_all(zl, zh, xl, xh, yl, yh)


@gufunc(6, 4)
def _max_rev(zl, zh, xl, xh, yl, yh, xlo, xhi, ylo, yhi):
    xlo[0], xhi[0], ylo[0], yhi[0] = _max_rev_all(zl, zh, xl, xh, yl, yh)


@gufunc(4)
def _neg_rev(zl, zh, xl, xh, lo, hi):
    lo[0], hi[0] = _neg_rev_all(zl, zh, xl, xh)


@gufunc(4)
def _sqr_rev(zl, zh, xl, xh, lo, hi):
    lo[0], hi[0] = _sqr_rev_all(zl, zh, xl, xh)


@gufunc(4)
def _sqrt_rev(zl, zh, xl, xh, lo, hi):
    lo[0], hi[0] = _sqrt_rev_all(zl, zh, xl, xh)


@gufunc(4)
def _abs_rev(zl, zh, xl, xh, lo, hi):
    lo[0], hi[0] = _abs_rev_all(zl, zh, xl, xh)


@gufunc(4)
def _sign_rev(zl, zh, xl, xh, lo, hi):
    lo[0], hi[0] = _sign_rev_all(zl, zh, xl, xh)


@gufunc(4)
def _floor_rev(zl, zh, xl, xh, lo, hi):
    lo[0], hi[0] = _floor_rev_all(zl, zh, xl, xh)


@gufunc(4)
def _ceil_rev(zl, zh, xl, xh, lo, hi):
    lo[0], hi[0] = _ceil_rev_all(zl, zh, xl, xh)


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
    a, b = _hull2(xl, xh, l1, h1, l2, h2)
    if a <= b:  # false when empty (NaN)
        lo[0] = a
        hi[0] = b


# ----------------------------------------------------------------------------------------
# public API
# ----------------------------------------------------------------------------------------
_Bounds = tuple[np.ndarray, ...]


def _apply(kernels: tuple, ins: _Bounds, outs: _Bounds | None) -> _Bounds:
    """Run one ufunc per output bound. With ``outs`` the bounds are written there; when an
    output overlaps an input (an in-place contraction) every bound is computed first."""
    if outs is None:
        return tuple(k(*ins) for k in kernels)
    if _bany(np.may_share_memory(o, i) for o in outs for i in ins):
        res = [k(*ins) for k in kernels]
        for o, r in zip(outs, res, strict=True):
            np.copyto(o, r)
    else:
        for k, o in zip(kernels, outs, strict=True):
            k(*ins, out=o)
    return outs


def _unary(kernels: tuple, x: IntervalLike, out: Interval | None) -> Interval:
    x = as_interval(x)
    lo, hi = _apply(kernels, (x.lo, x.hi), None if out is None else (out.lo, out.hi))
    return out if out is not None else Interval._new(lo, hi)


def _binary(kernels: tuple, x: IntervalLike, y: IntervalLike, out: Interval | None) -> Interval:
    x, y = as_interval(x), as_interval(y)
    lo, hi = _apply(kernels, (x.lo, x.hi, y.lo, y.hi),
                    None if out is None else (out.lo, out.hi))
    return out if out is not None else Interval._new(lo, hi)


def _rev1(kernels: tuple, z: IntervalLike, x: IntervalLike, out: Interval | None) -> Interval:
    z, x = as_interval(z), as_interval(x)
    lo, hi = _apply(kernels, (z.lo, z.hi, x.lo, x.hi),
                    None if out is None else (out.lo, out.hi))
    return out if out is not None else Interval._new(lo, hi)


def _rev2(kernel, z: IntervalLike, x: IntervalLike, y: IntervalLike,
          out: tuple[Interval, Interval] | None) -> tuple[Interval, Interval]:
    """A binary backward operator: one gufunc computing the four bounds per element (its
    select-based body is cheaper than four ufuncs that would each redo the whole work)."""
    z, x, y = as_interval(z), as_interval(x), as_interval(y)
    if out is None:
        xl, xh, yl, yh = kernel(z.lo, z.hi, x.lo, x.hi, y.lo, y.hi)
        return Interval._new(xl, xh), Interval._new(yl, yh)
    kernel(z.lo, z.hi, x.lo, x.hi, y.lo, y.hi, out[0].lo, out[0].hi, out[1].lo, out[1].hi)
    return out


def _int_exponent(n: int) -> int:
    """The kernels' exponent for a Python integer ``n`` (see ``_N_HUGE``): ``n`` itself when
    ``|n| < 2**63``, else ``+-(_N_HUGE + n % 2)`` (the same sign and parity)."""
    if -(2**63) < n < 2**63:
        return n
    k = _N_HUGE + (n & 1)
    return k if n > 0 else -k


def _scalar_exponent(v: object, n: object) -> int:
    """One element of an object array of exponents (Python integers beyond int64 among them)."""
    if isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_)):
        return _int_exponent(int(v))
    if isinstance(v, (float, np.floating)) and math.isfinite(v) and float(v).is_integer():
        return _int_exponent(int(v))
    raise ValueError(f"pown exponent must be an integer, got {n!r}")


@_jit
def _tape_exponent(p):
    """The kernels' int64 exponent for an integer-valued float64 ``p`` (a tape's exponent):
    ``p`` itself when ``|p| < 2**63``, else ``+-_N_HUGE`` (a float that large is even)."""
    if p >= 9223372036854775808.0:
        return np.int64(_N_HUGE)
    if p <= -9223372036854775808.0:
        return np.int64(-_N_HUGE)
    return np.int64(p)


def _exponent(n: ArrayLike) -> np.ndarray:
    """The integer exponent(s) ``n`` as int64 for the kernels, refusing non-integers.

    Every integer is accepted, of any magnitude (a Python int, a NumPy integer, an
    integer-valued float); one beyond int64 becomes an int64 of the same sign and parity whose
    power is enclosed alike at every float base (``_N_HUGE``).
    """
    if isinstance(n, int) and not isinstance(n, bool):
        return np.asarray(_int_exponent(n), dtype=np.int64)
    arr = np.asarray(n)
    if arr.dtype == np.object_:
        out = np.empty(arr.shape, dtype=np.int64)
        for i, v in np.ndenumerate(arr):
            out[i] = _scalar_exponent(v, n)
        return out
    if arr.dtype == np.bool_ or arr.dtype.kind not in "iuf":
        raise ValueError(f"pown exponent must be an integer, got {n!r}")
    if arr.dtype.kind == "f":
        if not np.all(np.isfinite(arr) & (arr == np.round(arr))):
            raise ValueError(f"pown exponent must be an integer, got {n!r}")
        big = np.abs(arr) >= 2.0**63  # even (every float beyond 2**53 is)
        k = np.where(big, 0.0, arr).astype(np.int64)
        return np.where(big, np.where(arr > 0, _N_HUGE, -_N_HUGE), k).astype(np.int64)
    if arr.dtype.kind == "u":
        big = arr >= np.uint64(2**63)
        return np.where(big, _N_HUGE + (arr & 1).astype(np.int64),
                        np.where(big, 0, arr).astype(np.int64)).astype(np.int64)
    arr = arr.astype(np.int64)
    return np.where(arr == np.iinfo(np.int64).min, -_N_HUGE, arr).astype(np.int64)


def abs(x: IntervalLike, out: Interval | None = None) -> Interval:
    """``|x|`` (exact): ``abs([-3, 2]) = [0, 3]``."""
    return _unary((_abs_lo, _abs_hi), x, out)


def pown(x: IntervalLike, n: ArrayLike, out: Interval | None = None) -> Interval:
    """``x**n`` for an integer ``n`` (a Python int or an integer array broadcasting with ``x``).

    IEEE 1788 ``pown``: ``pown(x, 0) = [1, 1]`` for non-empty ``x`` (also at 0); a negative ``n``
    means ``1 / x**|n|`` over ``x != 0`` (``pown([-1, 1], -2) = [1, inf]``,
    ``pown([0, 0], -1)`` is empty). Even powers use the case analysis of ``sqr``, never
    ``x * x``. Bounds are the tightest floats but in rare hard-to-round cases (one ulp wider).

    ``n`` may have any magnitude (an integer-valued float such as ``1e300`` is an even integer):
    ``pown([-3, -2], 1e20) = [MAX, inf]``, ``pown([-3, -2], -(2**64 + 1)) = [-ETA, 0]`` (the
    exact value, negative and below the smallest subnormal in magnitude, lies in it).

    Raises
    ------
    ValueError
        When ``n`` is not an integer (a non-integer or non-finite float, a boolean, a string).
    """
    x = as_interval(x)
    k = _exponent(n)
    if out is None:
        return Interval._new(*_pown(x.lo, x.hi, k))
    _pown(x.lo, x.hi, k, out.lo, out.hi)
    return out


def min(x: IntervalLike, y: IntervalLike, out: Interval | None = None) -> Interval:
    """Elementwise ``{min(a, b) : a in x, b in y}`` (exact)."""
    return _binary((_min_lo, _min_hi), x, y, out)


def max(x: IntervalLike, y: IntervalLike, out: Interval | None = None) -> Interval:
    """Elementwise ``{max(a, b) : a in x, b in y}`` (exact)."""
    return _binary((_max_lo, _max_hi), x, y, out)


def sign(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Hull of the signs (-1, 0 or 1) taken over ``x``: ``sign([0, 2]) = [0, 1]``."""
    return _unary((_sign_lo, _sign_hi), x, out)


def floor(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Hull of ``floor`` over ``x`` (exact): ``floor([-1.1, 2]) = [-2, 2]``."""
    return _unary((_floor_lo, _floor_hi), x, out)


def ceil(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Hull of ``ceil`` over ``x`` (exact): ``ceil([-1.1, 2]) = [-1, 2]``."""
    return _unary((_ceil_lo, _ceil_hi), x, out)


def trunc(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Hull of rounding towards zero over ``x`` (exact): ``trunc([-1.9, 2.2]) = [-1, 2]``."""
    return _unary((_trunc_lo, _trunc_hi), x, out)


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
    return _rev1(_NEG_REV, z, x, out)


def sqr_rev(z: IntervalLike, x: IntervalLike, out: Interval | None = None) -> Interval:
    """Contract ``x`` with ``z = x**2``: ``hull(x ∩ [-√z], x ∩ [√z])``.

    ``sqr_rev([1, 4], [0, 5]) = [1, 2]``, ``sqr_rev([1, 4], [-5, 5]) = [-2, 2]``.
    """
    return _rev1(_SQR_REV, z, x, out)


def sqrt_rev(z: IntervalLike, x: IntervalLike, out: Interval | None = None) -> Interval:
    """Contract ``x`` with ``z = sqrt(x)``: ``x ∩ [_bmax(z, 0)**2]``."""
    return _rev1(_SQRT_REV, z, x, out)


def abs_rev(z: IntervalLike, x: IntervalLike, out: Interval | None = None) -> Interval:
    """Contract ``x`` with ``z = |x|``: ``abs_rev([1, 2], [-5, 1.5]) = [-2, 1.5]``."""
    return _rev1(_ABS_REV, z, x, out)


def pown_rev(z: IntervalLike, x: IntervalLike, n: ArrayLike,
             out: Interval | None = None) -> Interval:
    """Contract ``x`` with ``z = pown(x, n)`` (IEEE 1788 pownRev, integer ``n``).

    ``pown_rev([1, 4], [-5, 5], 2) = [-2, 2]``; ``pown_rev([-8, 27], [-5, 5], 3) = [-2, 3]``;
    ``n = 0`` keeps ``x`` when ``1 in z`` and empties it otherwise. ``n`` may have any
    magnitude, as in ``pown``.
    """
    z, x = as_interval(z), as_interval(x)
    k = _exponent(n)
    if out is None:
        return Interval._new(*_pown_rev(z.lo, z.hi, x.lo, x.hi, k))
    _pown_rev(z.lo, z.hi, x.lo, x.hi, k, out.lo, out.hi)
    return out


def sign_rev(z: IntervalLike, x: IntervalLike, out: Interval | None = None) -> Interval:
    """Contract ``x`` with ``z = sign(x)``: ``sign_rev([1, 1], [-2, 3]) = [0, 3]``."""
    return _rev1(_SIGN_REV, z, x, out)


def floor_rev(z: IntervalLike, x: IntervalLike, out: Interval | None = None) -> Interval:
    """Contract ``x`` with ``z = floor(x)``: ``floor_rev([1, 2], [0, 10]) = [1, 3]``."""
    return _rev1(_FLOOR_REV, z, x, out)


def ceil_rev(z: IntervalLike, x: IntervalLike, out: Interval | None = None) -> Interval:
    """Contract ``x`` with ``z = ceil(x)``: ``ceil_rev([1, 2], [0, 10]) = [0, 2]``."""
    return _rev1(_CEIL_REV, z, x, out)


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
