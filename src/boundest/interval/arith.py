"""Forward arithmetic ``+ - * /``, ``sqr``, ``sqrt``: tightest float64 enclosures.

Each bound is one Numba ufunc over the bound arrays (broadcasting, ``out=``, SIMD loops).
"""

from __future__ import annotations

import numba as nb
from numpy.typing import ArrayLike

from .core import Interval, as_interval
from .rounding import (
    INF,
    NAN,
    add_dn,
    add_up,
    div_dn,
    div_up,
    mul_dn,
    mul_up,
    sqrt_dn,
    sqrt_up,
    sub_dn,
    sub_up,
    ufunc,
)

__all__ = ["add", "div", "mul", "neg", "recip", "sqr", "sqrt", "sub"]

IntervalLike = ArrayLike | Interval
_njit = nb.njit(cache=True, error_model="numpy")


# One branch-free scalar kernel per bound (selects, no jumps), so that Numba's ufunc loops
# vectorise them; the rare cases (empty, zero in a divisor) are selected at the end.
@ufunc(4)
def _add_lo(al, ah, bl, bh):  # noqa: ARG001 - all kernels of a binary op share a signature
    return add_dn(al, bl)


@ufunc(4)
def _add_hi(al, ah, bl, bh):  # noqa: ARG001
    return add_up(ah, bh)


@ufunc(4)
def _sub_lo(al, ah, bl, bh):  # noqa: ARG001
    return sub_dn(al, bh)


@ufunc(4)
def _sub_hi(al, ah, bl, bh):  # noqa: ARG001
    return sub_up(ah, bl)


@_njit
def _min(a, b):
    return a if a < b else b  # a plain select (Numba's min() also checks for NaN)


@_njit
def _max(a, b):
    return a if a > b else b


@ufunc(4)
def _mul_lo(al, ah, bl, bh):
    r = _min(_min(mul_dn(al, bl), mul_dn(al, bh)), _min(mul_dn(ah, bl), mul_dn(ah, bh)))
    r = NAN if al != al else r
    return NAN if bl != bl else r


@ufunc(4)
def _mul_hi(al, ah, bl, bh):
    r = _max(_max(mul_up(al, bl), mul_up(al, bh)), _max(mul_up(ah, bl), mul_up(ah, bh)))
    r = NAN if al != al else r
    return NAN if bl != bl else r


# Division: the signs of the bounds select which corner is extreme, so each bound costs one
# division (selects only, no branches). ``pos``: divisor >= 0 (lower bound at 0 allowed);
# ``neg``: divisor <= 0 with a negative lower bound; otherwise 0 is strictly inside (or the
# divisor is [0, 0]). A selected zero denominator means an infinite bound; the corner choices
# never divide inf by inf.
@ufunc(4)
def _div_lo(al, ah, bl, bh):
    pos = bl >= 0.0
    n = al if pos else ah
    d = (bh if al >= 0.0 else bl) if pos else (bh if ah > 0.0 else bl)
    r = div_dn(n, d)
    r = -INF if d == 0.0 else r
    r = r if (pos or bh <= 0.0) else -INF  # 0 strictly inside the divisor
    r = (0.0 if ah == 0.0 else r) if al == 0.0 else r  # [0, 0] / y = [0, 0]
    r = (NAN if bh == 0.0 else r) if bl == 0.0 else r  # divisor [0, 0]: empty
    r = NAN if al != al else r
    return NAN if bl != bl else r


@ufunc(4)
def _div_hi(al, ah, bl, bh):
    pos = bl >= 0.0
    n = ah if pos else al
    d = (bl if ah > 0.0 else bh) if pos else (bl if al >= 0.0 else bh)
    r = div_up(n, d)
    r = INF if d == 0.0 else r
    r = r if (pos or bh <= 0.0) else INF
    r = (0.0 if ah == 0.0 else r) if al == 0.0 else r
    r = (NAN if bh == 0.0 else r) if bl == 0.0 else r
    r = NAN if al != al else r
    return NAN if bl != bl else r


@ufunc(2)
def _sqr_lo(al, ah):
    r = mul_dn(al, al) if al >= 0.0 else (mul_dn(ah, ah) if ah <= 0.0 else 0.0)
    r = r if r > 0.0 else 0.0  # an underflowing square steps below 0: squares are >= 0
    return NAN if al != al else r


@ufunc(2)
def _sqr_hi(al, ah):
    return max(mul_up(al, al), mul_up(ah, ah))  # NaN stays NaN: both are NaN


@ufunc(2)
def _sqrt_lo(al, ah):
    r = sqrt_dn(max(al, 0.0))
    return r if ah >= 0.0 else NAN  # empty, or entirely negative


@ufunc(2)
def _sqrt_hi(al, ah):  # noqa: ARG001
    r = sqrt_up(ah)
    return r if ah >= 0.0 else NAN


def _binary(klo, khi, x: IntervalLike, y: IntervalLike, out: Interval | None) -> Interval:
    x, y = as_interval(x), as_interval(y)
    args = (x.lo, x.hi, y.lo, y.hi)
    if out is None:
        return Interval._new(klo(*args), khi(*args))
    lo = klo(*args)  # not into out.lo yet: out may be one of the arguments
    khi(*args, out=out.hi)
    out.lo[...] = lo
    return out


def _unary(klo, khi, x: IntervalLike, out: Interval | None) -> Interval:
    x = as_interval(x)
    if out is None:
        return Interval._new(klo(x.lo, x.hi), khi(x.lo, x.hi))
    lo = klo(x.lo, x.hi)
    khi(x.lo, x.hi, out=out.hi)
    out.lo[...] = lo
    return out


def add(x: IntervalLike, y: IntervalLike, out: Interval | None = None) -> Interval:
    """``x + y`` (tightest). ``out`` receives the result in place when given."""
    return _binary(_add_lo, _add_hi, x, y, out)


def sub(x: IntervalLike, y: IntervalLike, out: Interval | None = None) -> Interval:
    """``x - y`` (tightest)."""
    return _binary(_sub_lo, _sub_hi, x, y, out)


def mul(x: IntervalLike, y: IntervalLike, out: Interval | None = None) -> Interval:
    """``x * y`` (tightest; ``0 * inf`` counts as 0, so ``[0, 0] * entire = [0, 0]``)."""
    return _binary(_mul_lo, _mul_hi, x, y, out)


def div(x: IntervalLike, y: IntervalLike, out: Interval | None = None) -> Interval:
    """``x / y`` (tightest hull; a divisor containing 0 gives a half-line or the entire line,
    ``y = [0, 0]`` gives the empty set)."""
    return _binary(_div_lo, _div_hi, x, y, out)


def recip(x: IntervalLike, out: Interval | None = None) -> Interval:
    """``1 / x``."""
    return div(1.0, x, out)


def neg(x: IntervalLike) -> Interval:
    """``-x`` (exact)."""
    x = as_interval(x)
    return Interval._new(-x.hi, -x.lo)


def sqr(x: IntervalLike, out: Interval | None = None) -> Interval:
    """``x**2`` as one operation (tighter than ``x * x``: ``sqr([-1, 2]) = [0, 4]``)."""
    return _unary(_sqr_lo, _sqr_hi, x, out)


def sqrt(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Square root over the part of ``x`` where it is defined (``sqrt([-4, 4]) = [0, 2]``)."""
    return _unary(_sqrt_lo, _sqrt_hi, x, out)


