"""Forward arithmetic ``+ - * /``, ``sqr``, ``sqrt``: tightest float64 enclosures.

Each operation is one fused Numba gufunc over the bound arrays (broadcasting, ``out=``).
"""

from __future__ import annotations

from numpy.typing import ArrayLike

from .core import Interval, as_interval
from .rounding import (
    INF,
    NAN,
    add_dn,
    add_up,
    div_dn,
    div_up,
    gufunc,
    mul_dn,
    mul_up,
    sqrt_dn,
    sqrt_up,
    sub_dn,
    sub_up,
)

__all__ = ["add", "div", "mul", "neg", "recip", "sqr", "sqrt", "sub"]

IntervalLike = ArrayLike | Interval


@gufunc(4)
def _add(al, ah, bl, bh, lo, hi):
    lo[0] = add_dn(al, bl)
    hi[0] = add_up(ah, bh)


@gufunc(4)
def _sub(al, ah, bl, bh, lo, hi):
    lo[0] = sub_dn(al, bh)
    hi[0] = sub_up(ah, bl)


@gufunc(4)
def _mul(al, ah, bl, bh, lo, hi):
    if al != al or bl != bl:
        lo[0] = NAN
        hi[0] = NAN
        return
    lo[0] = min(min(mul_dn(al, bl), mul_dn(al, bh)), min(mul_dn(ah, bl), mul_dn(ah, bh)))
    hi[0] = max(max(mul_up(al, bl), mul_up(al, bh)), max(mul_up(ah, bl), mul_up(ah, bh)))


@gufunc(4)
def _div(al, ah, bl, bh, lo, hi):
    if al != al or bl != bl or (bl == 0.0 and bh == 0.0):
        lo[0] = NAN
        hi[0] = NAN
        return
    if al == 0.0 and ah == 0.0:
        lo[0] = 0.0
        hi[0] = 0.0
        return
    if bl > 0.0 or bh < 0.0:
        # 0 not in the divisor: the extreme quotients are at corners; an inf/inf corner has no
        # limit and is dominated by the others, so it is skipped.
        l0 = INF
        h0 = -INF
        for a in (al, ah):
            for b in (bl, bh):
                if abs(a) == INF and abs(b) == INF:
                    continue
                l0 = min(l0, div_dn(a, b))
                h0 = max(h0, div_up(a, b))
        lo[0] = l0
        hi[0] = h0
        return
    if bl == 0.0:  # divisor [0, bh], bh > 0
        if ah < 0.0:
            lo[0] = -INF
            hi[0] = div_up(ah, bh)
        elif al > 0.0:
            lo[0] = div_dn(al, bh)
            hi[0] = INF
        else:
            lo[0] = -INF
            hi[0] = INF
        return
    if bh == 0.0:  # divisor [bl, 0], bl < 0
        if ah < 0.0:
            lo[0] = div_dn(ah, bl)
            hi[0] = INF
        elif al > 0.0:
            lo[0] = -INF
            hi[0] = div_up(al, bl)
        else:
            lo[0] = -INF
            hi[0] = INF
        return
    lo[0] = -INF  # 0 strictly inside the divisor
    hi[0] = INF


@gufunc(2)
def _sqr(al, ah, lo, hi):
    if al >= 0.0:
        lo[0] = mul_dn(al, al)
        hi[0] = mul_up(ah, ah)
    elif ah <= 0.0:
        lo[0] = mul_dn(ah, ah)
        hi[0] = mul_up(al, al)
    elif al == al:
        lo[0] = 0.0
        hi[0] = max(mul_up(al, al), mul_up(ah, ah))
    else:
        lo[0] = NAN
        hi[0] = NAN


@gufunc(2)
def _sqrt(al, ah, lo, hi):
    if not ah >= 0.0:  # empty, or entirely negative
        lo[0] = NAN
        hi[0] = NAN
        return
    lo[0] = sqrt_dn(max(al, 0.0))
    hi[0] = sqrt_up(ah)


def _binary(kernel, x: IntervalLike, y: IntervalLike, out: Interval | None) -> Interval:
    x, y = as_interval(x), as_interval(y)
    if out is None:
        return Interval._new(*kernel(x.lo, x.hi, y.lo, y.hi))
    kernel(x.lo, x.hi, y.lo, y.hi, out.lo, out.hi)
    return out


def _unary(kernel, x: IntervalLike, out: Interval | None) -> Interval:
    x = as_interval(x)
    if out is None:
        return Interval._new(*kernel(x.lo, x.hi))
    kernel(x.lo, x.hi, out.lo, out.hi)
    return out


def add(x: IntervalLike, y: IntervalLike, out: Interval | None = None) -> Interval:
    """``x + y`` (tightest). ``out`` receives the result in place when given."""
    return _binary(_add, x, y, out)


def sub(x: IntervalLike, y: IntervalLike, out: Interval | None = None) -> Interval:
    """``x - y`` (tightest)."""
    return _binary(_sub, x, y, out)


def mul(x: IntervalLike, y: IntervalLike, out: Interval | None = None) -> Interval:
    """``x * y`` (tightest; ``0 * inf`` counts as 0, so ``[0, 0] * entire = [0, 0]``)."""
    return _binary(_mul, x, y, out)


def div(x: IntervalLike, y: IntervalLike, out: Interval | None = None) -> Interval:
    """``x / y`` (tightest hull; a divisor containing 0 gives a half-line or the entire line,
    ``y = [0, 0]`` gives the empty set)."""
    return _binary(_div, x, y, out)


def recip(x: IntervalLike, out: Interval | None = None) -> Interval:
    """``1 / x``."""
    return div(1.0, x, out)


def neg(x: IntervalLike) -> Interval:
    """``-x`` (exact)."""
    x = as_interval(x)
    return Interval._new(-x.hi, -x.lo)


def sqr(x: IntervalLike, out: Interval | None = None) -> Interval:
    """``x**2`` as one operation (tighter than ``x * x``: ``sqr([-1, 2]) = [0, 4]``)."""
    return _unary(_sqr, x, out)


def sqrt(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Square root over the part of ``x`` where it is defined (``sqrt([-4, 4]) = [0, 2]``)."""
    return _unary(_sqrt, x, out)


