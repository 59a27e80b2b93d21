"""Trigonometric functions ``sin cos tan asin acos`` and their reverse (backward) operators.

Every kernel is a Numba gufunc over the bound arrays, except asin and acos, whose libm values
at the bounds come from NumPy's ufuncs on the whole arrays (SIMD code) before a compiled
branch-free loop (see explog's forward functions); libm values are widened by ``LIBM_ULPS``
(``libm_dn``/``libm_up``) and clamped to the function's range. Soundness rests on these facts:

* ``PI_LO < pi < PI_HI`` (consecutive floats), so ``n * PIO2_LO`` and ``n * PIO2_HI`` rounded
  outward enclose ``n * pi / 2`` for any integer ``n``; for ``n != 0`` that point is
  irrational, hence *strictly* inside its enclosure and never equal to a float.
* The critical points of ``sin`` / ``cos`` and the poles of ``tan`` are the points ``n pi/2``.
  A cheap bracket of ``x * 2/pi`` (``_quadrants``) proves most intervals to lie inside one
  quadrant (monotone: evaluate at the ends); otherwise each candidate ``n`` is decided on its
  enclosure ``[l, h]``: ``n pi/2`` may lie in ``[a, b]`` iff ``l < b`` and ``a < h``
  (ambiguous cases count as inside, which only widens the result).
* Beyond ``|x| > 2**30`` no libm accuracy is assumed (none is measured): ``sin``/``cos`` give
  ``[-1, 1]``, ``tan`` the entire line, and the reverse operators keep such bounds of ``X``.

The reverse operators ``f_rev(z, x)`` return the hull of ``{x in X : f(x) in Z}`` over all
periods: the preimage of ``Z`` is a union of ordered *branches* (``j pi + (-1)^j asin(Z)`` for
``sin``, ``2k pi -+ acos(Z)`` for ``cos``, ``j pi + atan(Z)`` for ``tan``); the new lower bound
comes from the first branch whose enclosure reaches ``X.lo``, the new upper bound from the last
branch whose enclosure starts below ``X.hi``. Branch ends that are exact multiples of ``pi/2``
(``Z`` bounds ``0``, ``+-1``, ``+-inf``) are bounded with one rounding and compared strictly, so
``sin_rev(0, [-math.pi, math.pi])`` is ``[0, 0]`` (``math.pi < pi``).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from numpy.typing import ArrayLike

from .core import Interval, as_interval
from .explog import _Forward, _max, _min, _wdn, _wup
from .rounding import (
    INF,
    NAN,
    add_dn,
    add_up,
    div_dn,
    div_up,
    gufunc,
    libm_dn,
    libm_up,
    mul_dn,
    mul_up,
    next_down,
    next_up,
    sub_dn,
    sub_up,
)

__all__ = [
    "acos",
    "acos_rev",
    "asin",
    "asin_rev",
    "cos",
    "cos_rev",
    "sin",
    "sin_rev",
    "tan",
    "tan_rev",
]

IntervalLike = ArrayLike | Interval

#: Consecutive floats around pi (``PI_LO`` is ``math.pi``, below pi).
PI_LO = 3.141592653589793
PI_HI = math.nextafter(PI_LO, math.inf)
#: Their halves (exact): consecutive floats around pi / 2.
PIO2_LO = 0.5 * PI_LO
PIO2_HI = 0.5 * PI_HI
_TWO_PI_LO = 2.0 * PI_LO
#: Above this magnitude no libm accuracy is trusted for sin, cos and tan.
BIG = 2.0**30
#: Below this magnitude the odd functions are within one ulp of their argument.
_SMALL = 2.0**-26
#: atan(w) >= w (1 - w^2 / 3) >= w * _ATAN_TAIL for 0 <= w <= 2^-30
_ATAN_TAIL = 1.0 - 2.0**-58
# only used for estimates (an index off by one is caught by the rigorous checks)
_TWO_OVER_PI = 2.0 / math.pi
_INV_PI = 1.0 / math.pi
_EST_REL = 2.0**-50
_EST_ABS = 2.0**-1000

# floats, not ints: Numba would compile one specialisation per integer literal
_SIN, _COS, _TAN = 0.0, 1.0, 2.0

_jit = nb.njit(inline="always", cache=True, error_model="numpy")
#: Larger helpers: LLVM still inlines them into the kernels, while Numba-IR inlining
#: (inline='always') at every call site multiplies the compile time (minutes).
_njit = nb.njit(cache=True, error_model="numpy")


# ---------------------------------------------------------------------------------------------
# directed enclosures of the point functions
# ---------------------------------------------------------------------------------------------
# Each returns an enclosure (dn, up) of f(x) for one float x, from one libm call widened by
# LIBM_ULPS and clamped to the range, plus two exact refinements:
# * sin(x) <= x, atan(x) <= x, asin(x) >= x, tan(x) >= x for x >= 0 (mirrored for x <= 0);
# * for 0 < x < 2^-26 the cubic term of the Taylor series (x^3/6 for sin and asin, x^3/3 for
#   tan and atan, with a relative tail below x^2) is below a third of ulp(x), so the exact value
#   lies between x and its float neighbour: no libm call at all.

@_jit
def _sin_enc(x):
    """Enclosure of sin(x) for finite x (meaningful for |x| <= BIG)."""
    if x == 0.0:
        return 0.0, 0.0
    if abs(x) < _SMALL:
        if x > 0.0:
            return next_down(x), x
        return x, next_up(x)
    r = math.sin(x)
    dn = max(libm_dn(r), -1.0)
    up = min(libm_up(r), 1.0)
    if x > 0.0:
        up = min(up, x)
    else:
        dn = max(dn, x)
    return dn, up


@_jit
def _cos_enc(x):
    """Enclosure of cos(x) for finite x (meaningful for |x| <= BIG)."""
    if x == 0.0:
        return 1.0, 1.0
    r = math.cos(x)
    return max(libm_dn(r), -1.0), min(libm_up(r), 1.0)


@_jit
def _tan_enc(x, r):
    """Enclosure of tan(x) for finite x (a float is never a pole), from a libm value ``r``."""
    if x == 0.0:
        return 0.0, 0.0
    if abs(x) < _SMALL:
        if x > 0.0:
            return x, next_up(x)
        return next_down(x), x
    dn = libm_dn(r)
    up = libm_up(r)
    if 0.0 < x <= PIO2_LO:
        dn = max(dn, x)
    elif -PIO2_LO <= x < 0.0:
        up = min(up, x)
    return dn, up


@_jit
def _asin_enc(z):
    """Enclosure of asin(z) for z in [-1, 1]."""
    if z == 0.0:
        return 0.0, 0.0
    if z == 1.0:
        return PIO2_LO, PIO2_HI
    if z == -1.0:
        return -PIO2_HI, -PIO2_LO
    if abs(z) < _SMALL:
        if z > 0.0:
            return z, next_up(z)
        return next_down(z), z
    r = math.asin(z)
    dn = max(libm_dn(r), -PIO2_HI)
    up = min(libm_up(r), PIO2_HI)
    if z > 0.0:
        dn = max(dn, z)
    else:
        up = min(up, z)
    return dn, up


@_njit
def _acos_enc(z):
    """Enclosure of acos(z) for z in [-1, 1]; ``acos = pi/2 - asin`` is tighter near 0."""
    if z == 1.0:
        return 0.0, 0.0
    if z == -1.0:
        return PI_LO, PI_HI
    if abs(z) <= 0.5:
        dn, up = _asin_enc(z)
        return sub_dn(PIO2_LO, up), sub_up(PIO2_HI, dn)
    r = math.acos(z)
    return max(libm_dn(r), 0.0), min(libm_up(r), PI_HI)


@_njit
def _atan_enc(z):
    """Enclosure of atan(z) for any z, infinities included (atan(+-inf) = +-pi/2)."""
    if z == 0.0:
        return 0.0, 0.0
    # |z| >= 2^30: atan(z) = +-pi/2 -+ atan(w) with w = 1/|z| <= 2^-30, and
    # w (1 - 2^-58) <= w - w^3/3 <= atan(w) <= w
    if z >= BIG:
        return (sub_dn(PIO2_LO, div_up(1.0, z)),
                sub_up(PIO2_HI, mul_dn(div_dn(1.0, z), _ATAN_TAIL)))
    if z <= -BIG:
        return (add_dn(-PIO2_HI, mul_dn(div_dn(1.0, -z), _ATAN_TAIL)),
                sub_up(-PIO2_LO, div_dn(1.0, z)))
    if abs(z) < _SMALL:
        if z > 0.0:
            return next_down(z), z
        return z, next_up(z)
    r = math.atan(z)
    dn = max(libm_dn(r), -PIO2_HI)
    up = min(libm_up(r), PIO2_HI)
    if z > 0.0:
        up = min(up, z)
    else:
        dn = max(dn, z)
    return dn, up


# ---------------------------------------------------------------------------------------------
# forward kernels
# ---------------------------------------------------------------------------------------------

@_njit
def _halfpi_dn(n):
    """Lower bound of ``n * pi / 2`` for an integer ``n`` (strictly below unless n = 0)."""
    if n == 0:
        return 0.0
    return mul_dn(float(n), PIO2_LO if n > 0 else PIO2_HI)


@_njit
def _halfpi_up(n):
    """Upper bound of ``n * pi / 2`` for an integer ``n`` (strictly above unless n = 0)."""
    if n == 0:
        return 0.0
    return mul_up(float(n), PIO2_HI if n > 0 else PIO2_LO)


@_njit
def _halfpi_may_be_in(n, a, b):
    """Whether ``n * pi / 2`` (``n`` an integer) may lie in ``[a, b]`` (ambiguous: True)."""
    if n == 0:
        return a <= 0.0 and b >= 0.0
    # lo < n pi/2 < hi strictly (n pi/2 is irrational), hence n pi/2 in [a, b] => lo < b, a < hi
    return _halfpi_dn(n) < b and a < _halfpi_up(n)


@_jit
def _quadrants(a, b):
    """Integers ``n0 <= n1`` such that every ``n`` with ``n pi/2 in [a, b]`` lies in [n0, n1].

    ``t = RN(x * RN(2/pi))`` is within ``|t| 2^-51`` (+ an underflow term) of ``x 2/pi``; moving
    it by ``|t| 2^-50 + 2^-1000`` outward leaves room for the rounding of that subtraction too.
    ``n0 > n1`` means ``[a, b]`` lies strictly inside the quadrant ``]n1 pi/2, (n1 + 1) pi/2[``.
    Needs finite ``|a|, |b| <= 2^30``.
    """
    ta = a * _TWO_OVER_PI
    tb = b * _TWO_OVER_PI
    n0 = math.ceil(ta - (abs(ta) * _EST_REL + _EST_ABS))
    n1 = math.floor(tb + (abs(tb) * _EST_REL + _EST_ABS))
    return n0, n1


@_njit
def _sincos_enc(x, shift):
    if shift == 0:
        return _sin_enc(x)
    return _cos_enc(x)


@_njit
def _sincos(a, b, shift):
    """Enclosure of sin([a, b]) (shift 0) or cos([a, b]) = sin([a, b] + pi/2) (shift 1)."""
    if a != a or b != b:
        return NAN, NAN
    if a < -BIG or b > BIG or b - a >= _TWO_PI_LO:
        return -1.0, 1.0
    if a == b:  # a float is never a critical point (except 0 for cos: cos(0) = 1 exactly)
        return _sincos_enc(a, shift)
    n, end = _quadrants(a, b)
    if n > end:
        # monotone: sin increases on the quadrants q = 0, 3 (mod 4), cos on q = 2, 3
        if (end + shift + 1) & 2 == 0:
            return _sincos_enc(a, shift)[0], _sincos_enc(b, shift)[1]
        return _sincos_enc(b, shift)[0], _sincos_enc(a, shift)[1]
    # critical points: n pi/2 with (n + shift) = 1 mod 4 (max 1) or 3 mod 4 (min -1)
    if (n + shift) & 1 == 0:
        n += 1
    has_max = False
    has_min = False
    while n <= end:
        if _halfpi_may_be_in(n, a, b):
            if (n + shift) & 3 == 1:
                has_max = True
            else:
                has_min = True
        n += 2
    if has_max and has_min:
        return -1.0, 1.0
    adn, aup = _sincos_enc(a, shift)
    bdn, bup = _sincos_enc(b, shift)
    lo = -1.0 if has_min else min(adn, bdn)
    hi = 1.0 if has_max else max(aup, bup)
    return lo, hi


@gufunc(2)
def _sin(a, b, lo, hi):
    lo[0], hi[0] = _sincos(a, b, np.int64(0))  # np.int64: _sincos compiled once, not per literal


@gufunc(2)
def _cos(a, b, lo, hi):
    lo[0], hi[0] = _sincos(a, b, np.int64(1))


@_jit
def _tan_b(a, b, ta, tb):
    """Bounds of tan([a, b]) from ``ta, tb`` = libm tan at a, b (NumPy's, or glibc's in the
    engine): the entire line when a pole may lie inside, else monotone."""
    if a != a or b != b:
        return NAN, NAN
    if a < -BIG or b > BIG or b - a >= 4.0:  # a width > pi surely holds a pole
        return -INF, INF
    if a != b:  # poles: n pi/2 with n odd
        n, end = _quadrants(a, b)
        if n & 1 == 0:
            n += 1
        while n <= end:
            if _halfpi_may_be_in(n, a, b):
                return -INF, INF
            n += 2
    return _tan_enc(a, ta)[0], _tan_enc(b, tb)[1]


@_njit
def _tan_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _tan_b(xl[i], xh[i], fl[i], fh[i])


_tan = _Forward(_tan_b, _tan_loop, np.tan)


# asin and acos: NumPy evaluates them at the bounds (explog._Forward), the branch-free bounds
# functions below widen, clamp and apply the refinements of _asin_enc / _acos_enc (asin(0) = 0
# comes from the clamps: see explog).

@_jit
def _asin_dn_at(z, g):
    """Lower bound of asin(z) for z <= 1 (below -1: -pi/2), ``g`` a libm value of asin(z)."""
    r = _max(_wdn(g), -PIO2_HI)
    r = _max(r, z) if z >= 0.0 else r  # asin(z) >= z for z >= 0
    r = _max(r, next_down(z)) if z > -_SMALL else r  # asin(z) > pred(z) for -2**-26 < z < 0
    r = PIO2_LO if z == 1.0 else r
    return -PIO2_HI if z <= -1.0 else r


@_jit
def _asin_up_at(z, g):
    """Upper bound of asin(z) for z >= -1 (above 1: pi/2), ``g`` a libm value of asin(z)."""
    r = _min(_wup(g), PIO2_HI)
    r = _min(r, z) if z <= 0.0 else r
    r = _min(r, next_up(z)) if z < _SMALL else r
    r = -PIO2_LO if z == -1.0 else r
    return PIO2_HI if z >= 1.0 else r


@_jit
def _asin_b(a, b, fa, fb):
    """Bounds of asin([a, b]) from ``fa, fb`` = libm asin at a, b (NaN outside [-1, 1])."""
    lo = _asin_dn_at(a, fa)
    hi = _asin_up_at(b, fb)
    lo = (lo if a <= 1.0 else NAN) if b >= -1.0 else NAN  # empty, or disjoint from the domain
    hi = (hi if a <= 1.0 else NAN) if b >= -1.0 else NAN
    return lo, hi


@_jit
def _acos_b(a, b, fa, fb, ga, gb):
    """Bounds of acos([a, b]) from ``fa, fb`` = libm acos and ``ga, gb`` = libm asin at a, b
    (only used where |z| <= 1/2, where ``acos = pi/2 - asin`` is tighter); acos decreases."""
    lo = _max(_wdn(fb), 0.0)
    lo = sub_dn(PIO2_LO, _asin_up_at(b, gb)) if abs(b) <= 0.5 else lo
    lo = PI_LO if b == -1.0 else lo
    lo = 0.0 if b >= 1.0 else lo
    hi = _min(_wup(fa), PI_HI)
    hi = sub_up(PIO2_HI, _asin_dn_at(a, ga)) if abs(a) <= 0.5 else hi
    hi = 0.0 if a == 1.0 else hi
    hi = PI_HI if a <= -1.0 else hi
    lo = (lo if a <= 1.0 else NAN) if b >= -1.0 else NAN
    hi = (hi if a <= 1.0 else NAN) if b >= -1.0 else NAN
    return lo, hi


@_njit
def _asin_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _asin_b(xl[i], xh[i], fl[i], fh[i])


@_njit
def _acos_loop(xl, xh, fl, fh, gl, gh):
    for i in range(xl.size):
        fl[i], fh[i] = _acos_b(xl[i], xh[i], fl[i], fh[i], gl[i], gh[i])


_asin = _Forward(_asin_b, _asin_loop, np.arcsin)
_acos = _Forward(_acos_b, _acos_loop, np.arccos, np.arcsin)


# ---------------------------------------------------------------------------------------------
# reverse kernels
# ---------------------------------------------------------------------------------------------

# The preimage of Z under sin, cos or tan is a union of ordered branches (the exact lower and
# the exact upper ends both increase with the branch index j):
#   sin: p <= asin(zl), q >= asin(zh); branch j is j pi + (-1)^j asin(Z), inside the window
#        [j pi - pi/2, j pi + pi/2];
#   cos: p <= acos(zh), q >= acos(zl); branch 2k is 2k pi - acos(Z), branch 2k + 1 is
#        2k pi + acos(Z), inside the window [(j - 1) pi, j pi];
#   tan: p <= atan(zl), q >= atan(zh); branch j is j pi + atan(Z), inside the window
#        [j pi - pi/2, j pi + pi/2].
# A branch is m pi + [p, q] or m pi - [p, q]. When the exact base value (asin(0), acos(-1),
# atan(inf), ...) is a multiple kp pi/2 (kq pi/2) of pi/2, the branch end is the multiple
# (2m +- kp) pi/2, bounded with a single rounding (strictly, unless it is 0); NOEX marks a
# base that is not such a multiple.
NOEX = 1 << 40


@_jit
def _branch_shape(kind, j):
    """``(m, neg)``: branch ``j`` is ``m pi - [p, q]`` when ``neg``, else ``m pi + [p, q]``."""
    odd = j & 1 == 1
    if kind == _COS:
        return (j - 1, False) if odd else (j, True)
    return j, kind == _SIN and odd


@_njit
def _branch_lo(kind, j, p, q, kp, kq):
    """Lower bound of the lower end of branch ``j``."""
    m, neg = _branch_shape(kind, j)
    if neg:
        if kq != NOEX:
            return _halfpi_dn(2 * m - kq)
        return sub_dn(_halfpi_dn(2 * m), q)
    if kp != NOEX:
        return _halfpi_dn(2 * m + kp)
    return add_dn(_halfpi_dn(2 * m), p)


@_njit
def _branch_hi(kind, j, p, q, kp, kq):
    """Upper bound of the upper end of branch ``j``."""
    m, neg = _branch_shape(kind, j)
    if neg:
        if kp != NOEX:
            return _halfpi_up(2 * m - kp)
        return sub_up(_halfpi_up(2 * m), p)
    if kq != NOEX:
        return _halfpi_up(2 * m + kq)
    return add_up(_halfpi_up(2 * m), q)


@_jit
def _windows(kind, x):
    """Integers ``w0 <= w1`` around the index of the branch window that holds ``x``.

    The quadrant index ``floor(x 2/pi)`` is bracketed as in ``_quadrants``; a sin/tan window
    ``j`` covers the quadrants ``2j - 1, 2j``, a cos window the quadrants ``2j - 2, 2j - 1``.
    Needs finite ``|x| <= 2^30``.
    """
    t = x * _TWO_OVER_PI
    d = abs(t) * _EST_REL + _EST_ABS
    q0 = math.floor(t - d)
    q1 = math.floor(t + d)
    if kind == _COS:
        return (q0 >> 1) + 1, (q1 >> 1) + 1
    return (q0 + 1) >> 1, (q1 + 1) >> 1


@_jit
def _strict(kind, j, lower_end, kp, kq, bound):
    """Whether the branch end that ``bound`` encloses is known to differ from ``bound``: it is
    a non-zero multiple of pi/2 (irrational), then ``bound`` lies strictly outside it."""
    if bound == 0.0:
        return False
    neg = _branch_shape(kind, j)[1]
    if lower_end != neg:  # lower end of m pi + [p, q] or upper end of m pi - [p, q]: from p
        return kp != NOEX
    return kq != NOEX


@_jit
def _search(kind, p, q, kp, kq, xl, xh):
    """hull{x in [xl, xh] : f(x) in Z} for the periodic f (sin, cos, tan) given the enclosing
    base values ``p``, ``q`` of the branches (and ``kp``, ``kq``, see ``NOEX``); the preimage
    of ``Z`` must be non-empty.

    A tie between a bound of X and a branch bound that is strictly outside the exact branch
    end (``_strict``) means that the branch end is beyond the bound of X.
    """
    # The preimage is unbounded both ways: infinite or huge bounds of X are kept.
    # Lower bound: x lies in window w, w0 <= w <= w1. Every branch of a window <= w - 2 ends
    # below x - pi (below xl even after rounding), and the branch of window w + 1 starts above
    # x; so the first branch from w0 - 1 on whose upper bound reaches xl is found by w1 + 1,
    # and no earlier branch meets X.
    lo = xl
    if -BIG <= xl <= BIG:
        j, last = _windows(kind, xl)
        j -= 1
        while j <= last + 1:
            bu = _branch_hi(kind, j, p, q, kp, kq)
            if bu > xl or (bu == xl and not _strict(kind, j, False, kp, kq, bu)):
                bl = _branch_lo(kind, j, p, q, kp, kq)
                if bl > xh or (bl == xh and _strict(kind, j, True, kp, kq, bl)):
                    return NAN, NAN  # later branches start even higher: nothing in X
                lo = max(xl, bl)
                break
            j += 1
    hi = xh
    if -BIG <= xh <= BIG:
        last, j = _windows(kind, xh)
        j += 1
        while j >= last - 1:
            bl = _branch_lo(kind, j, p, q, kp, kq)
            if bl < xh or (bl == xh and not _strict(kind, j, True, kp, kq, bl)):
                bu = _branch_hi(kind, j, p, q, kp, kq)
                if bu < xl or (bu == xl and _strict(kind, j, False, kp, kq, bu)):
                    return NAN, NAN
                hi = min(xh, bu)
                break
            j -= 1
    if lo > hi:  # each bound is sound on its own, so no point can remain
        return NAN, NAN
    return lo, hi


@_jit
def _asin_k(z):
    """asin(z) = k pi/2: k for z in {-1, 0, 1}, else NOEX."""
    if z == 0.0:
        return 0
    if z == 1.0:
        return 1
    if z == -1.0:
        return -1
    return NOEX


@_jit
def _acos_k(z):
    """acos(z) = k pi/2: k for z in {-1, 0, 1}, else NOEX."""
    if z == 1.0:
        return 0
    if z == 0.0:
        return 1
    if z == -1.0:
        return 2
    return NOEX


@_jit
def _atan_k(z):
    """atan(z) = k pi/2: k for z in {-inf, 0, inf}, else NOEX."""
    if z == 0.0:
        return 0
    if z == INF:
        return 1
    if z == -INF:
        return -1
    return NOEX


@gufunc(4)
def _sin_rev(zl, zh, xl, xh, lo, hi):
    if zl != zl or xl != xl or zl > 1.0 or zh < -1.0:
        lo[0] = NAN
        hi[0] = NAN
    elif zl <= -1.0 and zh >= 1.0:
        lo[0] = xl
        hi[0] = xh
    else:
        zl = max(zl, -1.0)
        zh = min(zh, 1.0)
        lo[0], hi[0] = _search(_SIN, _asin_enc(zl)[0], _asin_enc(zh)[1],
                               _asin_k(zl), _asin_k(zh), xl, xh)


@gufunc(4)
def _cos_rev(zl, zh, xl, xh, lo, hi):
    if zl != zl or xl != xl or zl > 1.0 or zh < -1.0:
        lo[0] = NAN
        hi[0] = NAN
    elif zl <= -1.0 and zh >= 1.0:
        lo[0] = xl
        hi[0] = xh
    else:
        zl = max(zl, -1.0)
        zh = min(zh, 1.0)
        lo[0], hi[0] = _search(_COS, _acos_enc(zh)[0], _acos_enc(zl)[1],
                               _acos_k(zh), _acos_k(zl), xl, xh)


@gufunc(4)
def _tan_rev(zl, zh, xl, xh, lo, hi):
    if zl != zl or xl != xl:
        lo[0] = NAN
        hi[0] = NAN
    elif zl == -INF and zh == INF:  # tan is onto on every branch; a float is never a pole
        lo[0] = xl
        hi[0] = xh
    else:
        lo[0], hi[0] = _search(_TAN, _atan_enc(zl)[0], _atan_enc(zh)[1],
                               _atan_k(zl), _atan_k(zh), xl, xh)


@_jit
def _clip(l0, h0, xl, xh):
    """``[l0, h0] & [xl, xh] & [-1, 1]``, empty as NaN."""
    lo = max(max(l0, xl), -1.0)
    hi = min(min(h0, xh), 1.0)
    if not lo <= hi:
        return NAN, NAN
    return lo, hi


@gufunc(4)
def _asin_rev(zl, zh, xl, xh, lo, hi):
    # asin is increasing from [-1, 1] onto [-pi/2, pi/2]: x = sin(Z & [-pi/2, pi/2]).
    # zl > PIO2_LO means zl >= PIO2_HI > pi/2; zl < -PIO2_LO means zl < -pi/2.
    if zl != zl or xl != xl or zl > PIO2_LO or zh < -PIO2_LO:
        lo[0] = NAN
        hi[0] = NAN
        return
    l0 = -1.0 if zl < -PIO2_LO else _sin_enc(zl)[0]
    h0 = 1.0 if zh > PIO2_LO else _sin_enc(zh)[1]
    lo[0], hi[0] = _clip(l0, h0, xl, xh)


@gufunc(4)
def _acos_rev(zl, zh, xl, xh, lo, hi):
    # acos is decreasing from [-1, 1] onto [0, pi]: x = cos(Z & [0, pi]).
    if zl != zl or xl != xl or zl > PI_LO or zh < 0.0:
        lo[0] = NAN
        hi[0] = NAN
        return
    l0 = -1.0 if zh > PI_LO else _cos_enc(zh)[0]
    h0 = 1.0 if zl <= 0.0 else _cos_enc(zl)[1]
    lo[0], hi[0] = _clip(l0, h0, xl, xh)


# ---------------------------------------------------------------------------------------------
# public functions
# ---------------------------------------------------------------------------------------------

def _unary(kernel, x: IntervalLike, out: Interval | None) -> Interval:
    x = as_interval(x)
    if out is None:
        return Interval._new(*kernel(x.lo, x.hi))
    kernel(x.lo, x.hi, out.lo, out.hi)
    return out


def _reverse(kernel, z: IntervalLike, x: IntervalLike | None, out: Interval | None) -> Interval:
    z = as_interval(z)
    x = Interval.entire() if x is None else as_interval(x)
    if out is None:
        return Interval._new(*kernel(z.lo, z.hi, x.lo, x.hi))
    kernel(z.lo, z.hi, x.lo, x.hi, out.lo, out.hi)
    return out


def sin(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Sine (``sin([0, 10]) = [-1, 1]``; ``[-1, 1]`` for bounds beyond ``2**30`` in magnitude)."""
    return _unary(_sin, x, out)


def cos(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Cosine (``cos([0, 0]) = [1, 1]``; ``[-1, 1]`` for bounds beyond ``2**30``)."""
    return _unary(_cos, x, out)


def tan(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Tangent: the entire line when ``x`` may contain a pole ``pi/2 + k pi`` (or for bounds
    beyond ``2**30``), else ``[tan(lo), tan(hi)]`` rounded outward."""
    return _tan(x, out)


def asin(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Arcsine over the part of ``x`` in ``[-1, 1]`` (empty if disjoint)."""
    return _asin(x, out)


def acos(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Arccosine over the part of ``x`` in ``[-1, 1]`` (empty if disjoint)."""
    return _acos(x, out)


def sin_rev(z: IntervalLike, x: IntervalLike | None = None,
            out: Interval | None = None) -> Interval:
    """Hull of ``{x in X : sin(x) in Z}`` over all periods (``X`` defaults to the entire line).

    Bounds of ``X`` beyond ``2**30`` in magnitude are kept as they are (sound, not tight).
    """
    return _reverse(_sin_rev, z, x, out)


def cos_rev(z: IntervalLike, x: IntervalLike | None = None,
            out: Interval | None = None) -> Interval:
    """Hull of ``{x in X : cos(x) in Z}`` over all periods (``X`` defaults to the entire line)."""
    return _reverse(_cos_rev, z, x, out)


def tan_rev(z: IntervalLike, x: IntervalLike | None = None,
            out: Interval | None = None) -> Interval:
    """Hull of ``{x in X : tan(x) in Z}`` over all periods (``X`` defaults to the entire line)."""
    return _reverse(_tan_rev, z, x, out)


def asin_rev(z: IntervalLike, x: IntervalLike | None = None,
             out: Interval | None = None) -> Interval:
    """Hull of ``{x in X & [-1, 1] : asin(x) in Z}`` (``X`` defaults to the entire line)."""
    return _reverse(_asin_rev, z, x, out)


def acos_rev(z: IntervalLike, x: IntervalLike | None = None,
             out: Interval | None = None) -> Interval:
    """Hull of ``{x in X & [-1, 1] : acos(x) in Z}`` (``X`` defaults to the entire line)."""
    return _reverse(_acos_rev, z, x, out)
