"""Decimal literals enclosed exactly: the tightest float interval around a number written in
decimal, such as ``"0.1"`` (which no float equals), for data and model constants.

The value is compared with floats in exact rational arithmetic (``fractions``) on at most
about 40 significant digits; longer literals are compared digit by digit as text, so a literal
of any length or exponent takes microseconds. ``Interval.from_decimal`` is the public entry.
"""

from __future__ import annotations

import math
import re
import sys
from fractions import Fraction

__all__ = ["decimal_bounds"]

#: A decimal literal: sign, integer digits, fraction digits, exponent sign, exponent digits.
_DECIMAL = re.compile(r"([+-]?)([0-9]*)(?:\.([0-9]*))?(?:[eE]([+-]?)([0-9]+))?")
#: Significant digits kept for the exact rational comparison; further digits only matter
#: when a float falls between the truncated bounds, and then they are compared as text.
_KEEP = 40
#: Decimal orders of magnitude beyond which a literal certainly over- or underflows float64.
_OVER, _UNDER = 400, -400
#: Exponents of more digits than this are past both limits whatever the mantissa's length.
_EXP_DIGITS = 18
_MAX = sys.float_info.max
_TINY = math.ulp(0.0)  # the smallest subnormal, 2**-1074


def _scaled(m: int, e: int) -> Fraction:
    """``m * 10**e`` exactly (``|e|`` stays below about 450 here)."""
    return Fraction(m * 10**e) if e >= 0 else Fraction(m, 10**-e)


def _down(q: Fraction) -> float:
    """The largest float ``<= q`` (``q >= 0``), at most ``MAX``."""
    try:
        f = q.numerator / q.denominator  # correctly rounded
    except OverflowError:
        return _MAX
    return math.nextafter(f, -math.inf) if Fraction(f) > q else f


def _up(q: Fraction) -> float:
    """The smallest float ``>= q`` (``q >= 0``), ``+oo`` beyond ``MAX``."""
    try:
        f = q.numerator / q.denominator
    except OverflowError:
        return math.inf
    return math.nextafter(f, math.inf) if Fraction(f) < q else f


def _compare(digits: str, order: int, g: float) -> int:
    """Sign of ``0.digits * 10**order - g`` for a finite float ``g > 0`` (exact; ``digits``
    starts and ends with a nonzero digit)."""
    num, den = g.as_integer_ratio()
    k = den.bit_length() - 1  # g = num / 2**k = num * 5**k / 10**k
    gd = str(num * 5**k)
    g_order = len(gd) - k
    if order != g_order:
        return -1 if order < g_order else 1
    gd = gd.rstrip("0")
    return (digits > gd) - (digits < gd)  # same order: digit strings compare as numbers


def _enclose_positive(digits: str, order: int) -> tuple[float, float]:
    """The tightest float interval containing ``0.digits * 10**order`` (> 0)."""
    if order > _OVER:
        return _MAX, math.inf
    if order < _UNDER:
        return 0.0, _TINY
    n = len(digits)
    if n <= _KEEP:
        q = _scaled(int(digits), order - n)
        return _down(q), _up(q)
    # truncated: the value lies strictly inside ]A, B[ = ]m, m + 1[ * 10**(order - KEEP), a
    # range so narrow (relative width 1e-39) that at most one float g lies inside it
    m = int(digits[:_KEEP])
    a = _scaled(m, order - _KEEP)
    lo = _down(a)
    g = math.nextafter(lo, math.inf)
    if g == math.inf or Fraction(g) >= _scaled(m + 1, order - _KEEP):
        return lo, g
    c = _compare(digits, order, g)
    if c == 0:
        return g, g
    return (lo, g) if c < 0 else (g, math.nextafter(g, math.inf))


def decimal_bounds(text: str) -> tuple[float, float, tuple[int, str, int]]:
    """The bounds of the tightest float interval containing the decimal written in ``text``,
    and the exact decimal as ``(sign, digits, exponent)``: ``sign * int(digits) *
    10**exponent`` (``(0, "", 0)`` for zero).

    Beyond the float range the enclosure is ``[MAX, +oo]`` (or its negative); below the
    smallest subnormal it is ``[0, 2**-1074]``. The magnitude is read from the text before any
    exact arithmetic, which involves at most about 40 digits, so any literal (a million digits,
    an exponent of 10**9) takes microseconds.

    Raises
    ------
    ValueError
        When ``text`` is not a decimal literal.
    """
    match = _DECIMAL.fullmatch(text)
    if match is None or not (match.group(2) or match.group(3)):
        raise ValueError(f"not a decimal number: {text[:40]!r}")
    sign_t, int_part, frac, exp_sign, exp_t = match.groups()
    frac = frac or ""
    mantissa = int_part + frac
    sig = mantissa.lstrip("0")
    if not sig:
        return 0.0, 0.0, (0, "", 0)
    exp_t = (exp_t or "").lstrip("0") or "0"
    exp = int(exp_t) if len(exp_t) <= _EXP_DIGITS else 10**_EXP_DIGITS
    if exp_sign == "-":
        exp = -exp
    order = exp - len(frac) + len(sig)  # the value is 0.sig * 10**order
    digits = sig.rstrip("0")
    lo, hi = _enclose_positive(digits, order)
    if sign_t == "-":
        return -hi, -lo, (-1, digits, order - len(digits))
    return lo, hi, (1, digits, order - len(digits))
