"""The exponential family, forward and backward: exp, log, sinh, cosh, tanh, their inverses,
atan, atan2, pow (and exp2, exp10, expm1, log2, log10, log1p).

Forward functions are monotone (or piecewise monotone): each bound is a libm value at an end
point, widened by the assumed ``LIBM_ULPS`` error (``libm_dn``/``libm_up``) and
then clamped with facts that hold exactly whatever the rounding. For the unary functions the
libm values come from NumPy's ufunc on the whole bound arrays (SIMD code, SVML on AVX-512; SVML
is documented at 4 ulps), and a compiled branch-free loop does the widening and clamping; atan2
and pow are element kernels that call libm through Numba. The facts:

* known ranges: ``exp >= 0``, ``cosh >= 1``, ``|tanh| <= 1``, ``|atan| <= pi/2`` (with the
  float enclosure ``[HALF_PI_LO, HALF_PI_HI]`` of pi/2), atan2 in the quadrant of its arguments;
* exact values: ``exp(0) = 1``, ``log(1) = 0``, ``atan(+inf) = pi/2``, ``exp2(k) = 2**k``...;
* elementary inequalities: ``exp(x) >= 1 + x``, ``log(x) <= x - 1``, ``sinh(x) >= x`` for
  ``x >= 0``, ``|tanh(x)| <= |x|``, ``|atan(x)| <= |x|``, ``tanh(x) > 1 - 2**-53`` for ``x >= 20``.

Functions are applied to the part of the argument inside their domain (IEEE 1788-2015 set-based
semantics): ``log([-1, 4]) = [-inf, log 4]``, ``log([-2, -1])`` is empty. ``pow(x, y)`` is the
IEEE 1788 ``pow``: defined for ``x > 0`` and for ``x = 0, y > 0`` (``0**y = 0``); a plain integer
exponent (``x ** 2``) goes to ``algebraic.pown`` instead, which also accepts negative ``x``.

Reverse operators ``f_rev(z, x)`` return ``hull{x in X : f(x) in Z}`` from the inverse function
evaluated at the bounds of ``Z`` with outward widening (so that no solution is lost); the binary
ones return a pair: ``atan2_rev(z, y, x) -> (y', x')`` and ``pow_rev(z, x, y) -> (x', y')``.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic
from numpy.typing import ArrayLike

from .core import Interval, as_interval
from .rounding import (
    ETA,
    INF,
    LIBM_ULPS,
    MAX,
    NAN,
    PHI,
    add_dn,
    add_up,
    check_rounding_mode,
    div_dn,
    div_up,
    gufunc,
    libm_dn,
    libm_up,
    mul_dn,
    mul_up,
    sqrt_dn,
    sqrt_up,
    sub_dn,
    sub_up,
)

__all__ = [
    "acosh",
    "acosh_rev",
    "asinh",
    "asinh_rev",
    "atan",
    "atan2",
    "atan2_rev",
    "atan_rev",
    "atanh",
    "atanh_rev",
    "cosh",
    "cosh_rev",
    "exp",
    "exp2",
    "exp10",
    "exp_rev",
    "expm1",
    "log",
    "log1p",
    "log2",
    "log10",
    "log_rev",
    "pow_rev",
    "sinh",
    "sinh_rev",
    "tanh",
    "tanh_rev",
]

IntervalLike = ArrayLike | Interval

#: pi lies strictly between these two adjacent floats (0x1.921fb54442d18p+1 and its successor).
PI_LO = float.fromhex("0x1.921fb54442d18p+1")
PI_HI = float.fromhex("0x1.921fb54442d19p+1")
#: pi/2 lies strictly between these two adjacent floats.
HALF_PI_LO = float.fromhex("0x1.921fb54442d18p+0")
HALF_PI_HI = float.fromhex("0x1.921fb54442d19p+0")
#: The float just below 1 (1 - 2**-53).
_ONE_MINUS = float.fromhex("0x1.fffffffffffffp-1")
#: Exactly representable powers of ten 10**0 .. 10**22.
_POW10 = np.array([float(10**k) for k in range(23)])

#: The libm widening of ``rounding.libm_dn``/``libm_up``: relative and absolute parts.
_LIBM_REL = (LIBM_ULPS + 1) * 2.0**-52
_LIBM_ABS = LIBM_ULPS * ETA

_jit = nb.njit(inline="always", cache=True, error_model="numpy")
#: Larger helpers called from several kernels: compiled once (LLVM still inlines them).
_fn = nb.njit(cache=True, error_model="numpy")


# =============================================================================================
# scalar bounds of the elementary functions at one point (arguments are not NaN)
# =============================================================================================

@_jit
def _exp_dn(x):
    """Lower bound of exp(x)."""
    if x == 0.0:
        return 1.0
    r = max(libm_dn(math.exp(x)), add_dn(1.0, x))  # exp(x) >= 1 + x
    return max(r, 0.0)


@_jit
def _exp_up(x):
    """Upper bound of exp(x)."""
    if x == 0.0:
        return 1.0
    if x == -INF:
        return 0.0
    r = libm_up(math.exp(x))
    if x < 0.0:
        r = min(r, 1.0)
    return r


@_jit
def _log_dn(x):
    """Lower bound of log(x), x > 0."""
    if x == 1.0:
        return 0.0
    r = libm_dn(math.log(x))
    if x > 1.0:
        r = max(r, 0.0)
    return r


@_jit
def _log_up(x):
    """Upper bound of log(x), x >= 0."""
    if x == 1.0:
        return 0.0
    if x == 0.0:
        return -INF
    r = min(libm_up(math.log(x)), sub_up(x, 1.0))  # log(x) <= x - 1
    if x < 1.0:
        r = min(r, 0.0)
    return r


@_jit
def _sinh_dn(x):
    r = libm_dn(math.sinh(x))
    return max(r, x) if x >= 0.0 else r  # sinh(x) >= x for x >= 0


@_jit
def _sinh_up(x):
    r = libm_up(math.sinh(x))
    return min(r, x) if x <= 0.0 else r


@_jit
def _cosh_dn(a):
    """Lower bound of cosh(a), a >= 0."""
    return max(libm_dn(math.cosh(a)), 1.0)


@_jit
def _cosh_up(a):
    if a == 0.0:
        return 1.0
    return libm_up(math.cosh(a))


@_jit
def _tanh_dn(x):
    if x >= 20.0:  # 1 - tanh(20) = 2 / (e**40 + 1) < 2**-53
        return _ONE_MINUS
    r = libm_dn(math.tanh(x))
    if x >= 0.0:
        return max(r, 0.0)
    return max(max(r, x), -1.0)  # x <= tanh(x) for x <= 0


@_jit
def _tanh_up(x):
    if x <= -20.0:
        return -_ONE_MINUS
    r = libm_up(math.tanh(x))
    if x <= 0.0:
        return min(r, 0.0)
    return min(min(r, x), 1.0)


@_jit
def _tan_dn(t):
    """Lower bound of tan(t) for a float |t| < pi/2 (so |t| <= HALF_PI_LO)."""
    if t == 0.0:
        return 0.0
    r = libm_dn(math.tan(t))
    return max(r, t) if t > 0.0 else r  # tan(t) >= t for t >= 0


@_jit
def _tan_up(t):
    if t == 0.0:
        return 0.0
    r = libm_up(math.tan(t))
    return min(r, t) if t < 0.0 else r


@_jit
def _asinh_dn(z):
    if z == 0.0:
        return 0.0
    r = libm_dn(math.asinh(z))
    return max(r, 0.0) if z > 0.0 else max(r, z)  # asinh(z) >= z for z < 0


@_jit
def _asinh_up(z):
    if z == 0.0:
        return 0.0
    r = libm_up(math.asinh(z))
    return min(r, z) if z > 0.0 else min(r, 0.0)


@_jit
def _acosh_dn(z):
    """Lower bound of acosh(z), z >= 1."""
    if z == 1.0:
        return 0.0
    return max(libm_dn(math.acosh(z)), 0.0)


@_jit
def _acosh_up(z):
    if z == 1.0:
        return 0.0
    return libm_up(math.acosh(z))


@_jit
def _atanh_dn(z):
    """Lower bound of atanh(z), -1 < z < 1."""
    if z == 0.0:
        return 0.0
    r = libm_dn(math.atanh(z))
    return max(r, z) if z > 0.0 else r  # atanh(z) >= z for z > 0


@_jit
def _atanh_up(z):
    if z == 0.0:
        return 0.0
    r = libm_up(math.atanh(z))
    return min(r, z) if z < 0.0 else r


@_jit
def _atan2_dn(y, x):
    """Lower bound of atan2(y, x) in [-pi, pi]; (y, x) != (0, 0); y = 0, x < 0 gives pi."""
    if y == 0.0:
        return 0.0 if x > 0.0 else PI_LO
    if x == 0.0:
        return HALF_PI_LO if y > 0.0 else -HALF_PI_HI
    if abs(y) == INF and abs(x) != INF:
        return HALF_PI_LO if y > 0.0 else -HALF_PI_HI
    if abs(x) == INF and abs(y) != INF:
        if x > 0.0:
            return 0.0
        return PI_LO if y > 0.0 else -PI_HI
    r = libm_dn(math.atan2(y, x))
    if y > 0.0:
        r = max(r, HALF_PI_LO) if x < 0.0 else max(r, 0.0)
    else:
        r = max(r, -HALF_PI_HI) if x > 0.0 else max(r, -PI_HI)
    return r


@_jit
def _atan2_up(y, x):
    """Upper bound of atan2(y, x) in [-pi, pi]; (y, x) != (0, 0)."""
    if y == 0.0:
        return 0.0 if x > 0.0 else PI_HI
    if x == 0.0:
        return HALF_PI_HI if y > 0.0 else -HALF_PI_LO
    if abs(y) == INF and abs(x) != INF:
        return HALF_PI_HI if y > 0.0 else -HALF_PI_LO
    if abs(x) == INF and abs(y) != INF:
        if x > 0.0:
            return 0.0
        return PI_HI if y > 0.0 else -PI_LO
    r = libm_up(math.atan2(y, x))
    if y > 0.0:
        r = min(r, HALF_PI_HI) if x > 0.0 else min(r, PI_HI)
    else:
        r = min(r, -HALF_PI_LO) if x < 0.0 else min(r, 0.0)
    return r


@_fn
def _pow_dn(x, y):
    """Lower bound of x**y (or its limit) for x >= 0 (never -0.0), y not NaN."""
    if y == 0.0 or x == 1.0:
        return 1.0
    if x == 0.0:
        return 0.0 if y > 0.0 else MAX  # the limit +inf: MAX as a lower bound
    if x == INF:
        return MAX if y > 0.0 else 0.0
    if y == INF:
        return MAX if x > 1.0 else 0.0
    if y == -INF:
        return 0.0 if x > 1.0 else MAX
    if y == 1.0:
        return x
    if y == 2.0:
        return max(mul_dn(x, x), 0.0)  # x*x underflowing to 0 steps below 0
    if y == 0.5:
        return sqrt_dn(x)
    if y == -1.0:
        return div_dn(1.0, x)
    r = max(libm_dn(math.pow(x, y)), 0.0)
    if (x > 1.0) == (y > 0.0):  # then x**y > 1
        r = max(r, 1.0)
    return r


@_fn
def _pow_up(x, y):
    """Upper bound of x**y (or its limit) for x >= 0 (never -0.0), y not NaN."""
    if y == 0.0 or x == 1.0:
        return 1.0
    if x == 0.0:
        return 0.0 if y > 0.0 else INF
    if x == INF:
        return INF if y > 0.0 else 0.0
    if y == INF:
        return INF if x > 1.0 else 0.0
    if y == -INF:
        return 0.0 if x > 1.0 else INF
    if y == 1.0:
        return x
    if y == 2.0:
        return mul_up(x, x)
    if y == 0.5:
        return sqrt_up(x)
    if y == -1.0:
        return div_up(1.0, x)
    r = libm_up(math.pow(x, y))
    if (x > 1.0) != (y > 0.0):  # then x**y < 1
        r = min(r, 1.0)
    return r


# =============================================================================================
# small interval helpers
# =============================================================================================

@_jit
def _meet(l, h, xl, xh):
    """``[l, h] & [xl, xh]`` as a pair, ``(nan, nan)`` when empty."""
    a = max(l, xl)
    b = min(h, xh)
    if a <= b:
        return a, b
    return NAN, NAN


@_jit
def _join(al, ah, bl, bh):
    """Hull of two intervals, either possibly empty (NaN bounds)."""
    if al != al:
        return bl, bh
    if bl != bl:
        return al, ah
    return min(al, bl), max(ah, bh)


# =============================================================================================
# forward functions: NumPy evaluates f at the bounds, compiled loops widen and clamp
# =============================================================================================
# The public function computes ``fl = f(xl)``, ``fh = f(xh)`` with NumPy's ufunc on the whole
# bound arrays (SIMD code, SVML on AVX-512: within LIBM_ULPS like any libm), on
# the raw bounds: values outside the domain (NaN, +-inf) are never used, the bounds functions
# select the exact result there. ``_<f>_b(xl, xh, fl, fh) -> (lo, hi)`` then widens the two values
# and applies the exact facts of the module docstring; the compiled propagation engine calls them
# directly, with glibc's values (``math.exp(xl)``, ...). The loops ``_<f>_loop`` write ``lo`` into
# ``fl`` and ``hi`` into ``fh`` in place and run as SIMD code, because the bounds functions are
# branch-free: plain selects ``a if c else b``, no and/or chains, no builtin min/max. Each
# comparison costs a mask instruction (one per cycle on x86), so special values are obtained from
# the clamps where that gives the same result, e.g. ``exp(0) = 1`` from ``exp(x) >= 1 + x`` and
# ``exp(x) <= 1`` for ``x <= 0``: a libm value within LIBM_ULPS of 1 widens to an interval that
# straddles 1, and the clamps cut it to exactly 1.

@_jit
def _min(a, b):
    return a if a < b else b  # vminpd: b when either is NaN


@_jit
def _max(a, b):
    return a if a > b else b


@_jit
def _wdn(r):
    """``libm_dn(r)`` without a comparison: ``r = +inf`` (overflow) gives ``MAX`` through the
    NaN of ``inf - inf``. ``r = NaN`` gives ``MAX`` too: libm returns NaN only for arguments
    outside the domain (or empty ones), for which the callers select the result."""
    return _min(r - (abs(r) * _LIBM_REL + _LIBM_ABS), MAX)


@_jit
def _wup(r):
    """``libm_up(r)`` without a comparison: ``-inf`` gives ``-MAX``, NaN gives ``-MAX``."""
    return _max(r + (abs(r) * _LIBM_REL + _LIBM_ABS), -MAX)


@_jit
def _add1_dn(x):
    """A float <= 1 + x, the largest one (rarely the one below): ``add_dn(1, x)`` for
    ``x < +inf``, with one comparison less."""
    s = 1.0 + x
    bb = s - 1.0
    e = (1.0 - (s - bb)) + (x - bb)  # TwoSum: 1 + x - s exactly (NaN when x = -inf)
    return s if e >= 0.0 else s - (abs(s) * PHI + ETA)


@_jit
def _sub1_up(x):
    """A float >= x - 1, the smallest one (rarely the one above): ``sub_up(x, 1)`` for
    ``x > -inf``."""
    s = x - 1.0
    bb = s - x
    e = (x - (s - bb)) + (-1.0 - bb)
    return s if e <= 0.0 else s + (abs(s) * PHI + ETA)


@_jit
def _nan_if_empty(xl, xh, lo, hi):
    """``(lo, hi)``, or ``(nan, nan)`` when either bound of the argument is NaN (empty)."""
    lo = NAN if xh != xh else lo
    hi = NAN if xl != xl else hi
    lo = NAN if xl != xl else lo
    return lo, (NAN if xh != xh else hi)


@intrinsic
def _f2i(typingctx, x):  # noqa: ARG001 - numba intrinsic signature
    """The bits of a float64 as an int64."""
    def codegen(context, builder, signature, args):  # noqa: ARG001
        return builder.bitcast(args[0], ir.IntType(64))
    return types.int64(types.float64), codegen


@intrinsic
def _i2f(typingctx, i):  # noqa: ARG001
    """The float64 with the given bits."""
    def codegen(context, builder, signature, args):  # noqa: ARG001
        return builder.bitcast(args[0], ir.DoubleType())
    return types.float64(types.int64), codegen


@_jit
def _pow2_int(k):
    """``2.0**k`` exactly for an integer ``k`` in [-1074, 1023] (subnormals included): the
    product of two normal powers of two ``2**(k >> 1)`` and ``2**(k - (k >> 1))``."""
    h = k >> 1
    return _i2f((h + 1023) << 52) * _i2f((k - h + 1023) << 52)


@_jit
def _pow10_int(k):
    """``10.0**k`` (exact) for an integer ``k`` in [0, 22]."""
    return _POW10[k]


@_jit
def _exp2_exact(x, r):
    """``2**x`` when ``x`` is an integer in [-1074, 1023] (the power is a float), else ``r``."""
    k = np.floor(_min(_max(x, -1074.0), 1023.0))  # NaN -> -1074: int() is safe
    return _pow2_int(int(k)) if x == k else r


@_jit
def _exp10_exact(x, r):
    """``10**x`` when ``x`` is an integer in [0, 22] (the power is a float), else ``r``."""
    k = np.floor(_min(_max(x, 0.0), 22.0))
    return _pow10_int(int(k)) if x == k else r


@_jit
def _log2_exact(x, f, r):
    """``log2(x)`` when ``x > 0`` is a power of two (subnormals too), else ``r``; ``f`` is a
    libm value of ``log2(x)`` (within a few ulps: it rounds to the exponent)."""
    k = _min(_max(np.floor(f + 0.5), -1074.0), 1023.0)  # NaN -> -1074
    return k if _pow2_int(int(k)) == x else r


@_jit
def _log10_exact(x, f, r):
    """``log10(x)`` when ``x = 10**k``, ``k`` in [0, 22], else ``r``; ``f`` is a libm value of
    ``log10(x)``."""
    k = _min(_max(np.floor(f + 0.5), 0.0), 22.0)
    return k if _pow10_int(int(k)) == x else r


@_jit
def _exp_b(xl, xh, fl, fh):
    lo = _max(_max(_wdn(fl), _add1_dn(xl)), 0.0)  # exp(x) >= 1 + x (exp(0) = 1)
    hi = _wup(fh)
    hi = _min(hi, 1.0) if xh <= 0.0 else hi
    return _nan_if_empty(xl, xh, lo, hi)


@_jit
def _exp2_b(xl, xh, fl, fh):
    lo = _exp2_exact(xl, _max(_wdn(fl), 1.0 if xl > 0.0 else 0.0))
    hi = _wup(fh)
    hi = _exp2_exact(xh, _min(hi, 1.0) if xh < 0.0 else hi)
    return _nan_if_empty(xl, xh, lo, hi)


@_jit
def _exp10_b(xl, xh, fl, fh):
    lo = _exp10_exact(xl, _max(_wdn(fl), 1.0 if xl > 0.0 else 0.0))
    hi = _wup(fh)
    hi = _exp10_exact(xh, _min(hi, 1.0) if xh <= 0.0 else hi)
    return _nan_if_empty(xl, xh, lo, hi)


@_jit
def _expm1_b(xl, xh, fl, fh):
    lo = _max(_max(_wdn(fl), xl), -1.0)  # expm1(x) >= x (expm1(0) = 0)
    hi = _wup(fh)
    hi = _min(hi, 0.0) if xh <= 0.0 else hi
    return _nan_if_empty(xl, xh, lo, hi)


@_jit
def _log_b(xl, xh, fl, fh):
    lo = _wdn(fl)
    lo = _max(lo, 0.0) if xl >= 1.0 else lo  # (log(1) = 0)
    lo = -INF if xl <= 0.0 else lo
    hi = _min(_wup(fh), _sub1_up(xh))  # log(x) <= x - 1 (also gives log(1) = 0, log < 0 below)
    lo = lo if xh > 0.0 else NAN  # no positive part (or empty)
    return _nan_if_empty(xl, xh, lo, hi if xh > 0.0 else NAN)


@_jit
def _log2_b(xl, xh, fl, fh):
    lo = _wdn(fl)
    lo = _log2_exact(xl, fl, _max(lo, 0.0) if xl > 1.0 else lo)
    lo = -INF if xl <= 0.0 else lo
    hi = _wup(fh)
    hi = _log2_exact(xh, fh, _min(hi, 0.0) if xh < 1.0 else hi)
    lo = lo if xh > 0.0 else NAN
    return _nan_if_empty(xl, xh, lo, hi if xh > 0.0 else NAN)


@_jit
def _log10_b(xl, xh, fl, fh):
    lo = _wdn(fl)
    lo = _log10_exact(xl, fl, _max(lo, 0.0) if xl > 1.0 else lo)
    lo = -INF if xl <= 0.0 else lo
    hi = _wup(fh)
    hi = _log10_exact(xh, fh, _min(hi, 0.0) if xh < 1.0 else hi)
    lo = lo if xh > 0.0 else NAN
    return _nan_if_empty(xl, xh, lo, hi if xh > 0.0 else NAN)


@_jit
def _log1p_b(xl, xh, fl, fh):
    lo = _wdn(fl)
    lo = _max(lo, 0.0) if xl >= 0.0 else lo  # (log1p(0) = 0)
    lo = -INF if xl <= -1.0 else lo
    hi = _min(_wup(fh), xh)  # log1p(x) <= x
    lo = lo if xh > -1.0 else NAN  # nothing above -1 (or empty)
    return _nan_if_empty(xl, xh, lo, hi if xh > -1.0 else NAN)


@_jit
def _sinh_b(xl, xh, fl, fh):
    lo = _wdn(fl)
    lo = _max(lo, xl) if xl >= 0.0 else lo  # sinh(x) >= x for x >= 0
    hi = _wup(fh)
    hi = _min(hi, xh) if xh <= 0.0 else hi
    return _nan_if_empty(xl, xh, lo, hi)


@_jit
def _cosh_b(xl, xh, fl, fh):
    # minimum at the end nearest 0 (1 when 0 is inside), maximum at the farthest end; cosh is
    # even, so the value at xh stands for the one at -xh
    lo = _max(_wdn(fl if xl >= 0.0 else fh), 1.0)
    lo = (1.0 if xh > 0.0 else lo) if xl < 0.0 else lo
    left = -xl >= xh
    hi = _wup(fl if left else fh)
    hi = 1.0 if (xl if left else xh) == 0.0 else hi
    return _nan_if_empty(xl, xh, lo, hi)


@_jit
def _tanh_b(xl, xh, fl, fh):
    # tanh(x) >= min(x, 0), tanh(x) <= max(x, 0) and |tanh(x)| <= 1 (as min/max: no select)
    lo = _max(_max(_wdn(fl), _min(xl, 0.0)), -1.0)
    lo = _ONE_MINUS if xl >= 20.0 else lo  # 1 - tanh(20) = 2 / (e**40 + 1) < 2**-53
    hi = _min(_min(_wup(fh), _max(xh, 0.0)), 1.0)
    hi = -_ONE_MINUS if xh <= -20.0 else hi
    return _nan_if_empty(xl, xh, lo, hi)


@_jit
def _atan_b(xl, xh, fl, fh):
    # atan(x) >= min(x, 0), atan(x) <= max(x, 0) (atan(0) = 0); the clamps to +-HALF_PI_HI
    # give atan(-inf) and atan(+inf) from libm values within a few ulps of -+pi/2
    lo = _max(_max(_wdn(fl), _min(xl, 0.0)), -HALF_PI_HI)
    hi = _min(_min(_wup(fh), _max(xh, 0.0)), HALF_PI_HI)
    return _nan_if_empty(xl, xh, lo, hi)


@_jit
def _asinh_b(xl, xh, fl, fh):
    lo = _max(_wdn(fl), _min(xl, 0.0))  # asinh(x) >= min(x, 0) (asinh(0) = 0)
    hi = _min(_wup(fh), _max(xh, 0.0))
    return _nan_if_empty(xl, xh, lo, hi)


@_jit
def _acosh_b(xl, xh, fl, fh):
    lo = _max(_wdn(fl), 0.0)
    lo = 0.0 if xl <= 1.0 else lo
    hi = _wup(fh)
    hi = 0.0 if xh == 1.0 else hi
    lo = lo if xh >= 1.0 else NAN  # nothing in the domain [1, inf] (or empty)
    return _nan_if_empty(xl, xh, lo, hi if xh >= 1.0 else NAN)


@_jit
def _atanh_b(xl, xh, fl, fh):
    lo = _wdn(fl)
    lo = _max(lo, xl) if xl >= 0.0 else lo  # atanh(x) >= x for x >= 0
    lo = -INF if xl <= -1.0 else lo
    hi = _wup(fh)
    hi = _min(hi, xh) if xh <= 0.0 else hi
    hi = INF if xh >= 1.0 else hi
    # nothing in the domain ]-1, 1[
    lo = (lo if xl < 1.0 else NAN) if xh > -1.0 else NAN
    hi = (hi if xl < 1.0 else NAN) if xh > -1.0 else NAN
    return _nan_if_empty(xl, xh, lo, hi)


# One loop per function (a loop taking the bounds function as an argument would not be cached).
@_fn
def _exp_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _exp_b(xl[i], xh[i], fl[i], fh[i])


@_fn
def _exp2_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _exp2_b(xl[i], xh[i], fl[i], fh[i])


@_fn
def _exp10_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _exp10_b(xl[i], xh[i], fl[i], fh[i])


@_fn
def _expm1_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _expm1_b(xl[i], xh[i], fl[i], fh[i])


@_fn
def _log_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _log_b(xl[i], xh[i], fl[i], fh[i])


@_fn
def _log2_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _log2_b(xl[i], xh[i], fl[i], fh[i])


@_fn
def _log10_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _log10_b(xl[i], xh[i], fl[i], fh[i])


@_fn
def _log1p_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _log1p_b(xl[i], xh[i], fl[i], fh[i])


@_fn
def _sinh_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _sinh_b(xl[i], xh[i], fl[i], fh[i])


@_fn
def _cosh_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _cosh_b(xl[i], xh[i], fl[i], fh[i])


@_fn
def _tanh_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _tanh_b(xl[i], xh[i], fl[i], fh[i])


@_fn
def _atan_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _atan_b(xl[i], xh[i], fl[i], fh[i])


@_fn
def _asinh_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _asinh_b(xl[i], xh[i], fl[i], fh[i])


@_fn
def _acosh_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _acosh_b(xl[i], xh[i], fl[i], fh[i])


@_fn
def _atanh_loop(xl, xh, fl, fh):
    for i in range(xl.size):
        fl[i], fh[i] = _atanh_b(xl[i], xh[i], fl[i], fh[i])


def _np_exp10(a: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """``10**a`` by ``np.power`` with an array base: its SIMD loop (a scalar base is not)."""
    base = np.empty_like(a) if out is None else out
    base.fill(10.0)
    return np.power(base, a, out=base)


#: Below this size ``out=`` results are copied (cheaper than the overlap checks of the direct path).
_DIRECT_MIN = 4096


def _writable_apart(out: Interval, shape: tuple, xl: np.ndarray, xh: np.ndarray) -> bool:
    """Whether the bounds of ``out`` are C-contiguous arrays of ``shape`` that overlap neither
    each other nor the argument bounds (so NumPy may write into them before the loop runs)."""
    ol, oh = out.lo, out.hi
    return (ol.shape == shape and oh.shape == shape and ol.flags.c_contiguous
            and oh.flags.c_contiguous and not np.may_share_memory(ol, oh)
            and not any(np.may_share_memory(o, a) for o in (ol, oh) for a in (xl, xh)))


class _Forward:
    """A forward interval function: NumPy ufunc(s) at the bounds, then a compiled loop.

    ``bounds`` is the scalar bounds function (for compiled callers), ``loop`` its in-place
    loop over the flat bound arrays, ``npfs`` the NumPy functions whose values at the two bounds
    the loop receives (in that order: ``f(xl), f(xh), g(xl), g(xh)``).
    """

    __slots__ = ("bounds", "loop", "npfs")

    def __init__(self, bounds, loop, *npfs) -> None:
        self.bounds = bounds
        self.loop = loop
        self.npfs = npfs

    def __call__(self, x: IntervalLike, out: Interval | None = None) -> Interval:
        x = as_interval(x)
        xl, xh = x.lo, x.hi
        shape = xl.shape
        if xh.shape != shape:
            xl, xh = np.broadcast_arrays(xl, xh)
            shape = xl.shape
        a, b = xl.ravel(), xh.ravel()  # contiguous: views, or copies
        f = self.npfs[0]
        direct = out is not None and a.size >= _DIRECT_MIN and _writable_apart(out, shape, xl, xh)
        check_rounding_mode()
        with np.errstate(all="ignore"):
            if direct:
                lo, hi = f(a, out=out.lo.reshape(-1)), f(b, out=out.hi.reshape(-1))
            else:
                lo, hi = f(a), f(b)
            if len(self.npfs) == 1:
                self.loop(a, b, lo, hi)
            else:
                g = self.npfs[1]
                self.loop(a, b, lo, hi, g(a), g(b))
        if out is None:
            return Interval._new(lo.reshape(shape), hi.reshape(shape))
        if not direct:
            out.lo[...] = lo.reshape(shape)
            out.hi[...] = hi.reshape(shape)
        return out


_exp = _Forward(_exp_b, _exp_loop, np.exp)
_exp2 = _Forward(_exp2_b, _exp2_loop, np.exp2)
_exp10 = _Forward(_exp10_b, _exp10_loop, _np_exp10)
_expm1 = _Forward(_expm1_b, _expm1_loop, np.expm1)
_log = _Forward(_log_b, _log_loop, np.log)
_log2 = _Forward(_log2_b, _log2_loop, np.log2)
_log10 = _Forward(_log10_b, _log10_loop, np.log10)
_log1p = _Forward(_log1p_b, _log1p_loop, np.log1p)
_sinh = _Forward(_sinh_b, _sinh_loop, np.sinh)
_cosh = _Forward(_cosh_b, _cosh_loop, np.cosh)
_tanh = _Forward(_tanh_b, _tanh_loop, np.tanh)
_atan = _Forward(_atan_b, _atan_loop, np.arctan)
_asinh = _Forward(_asinh_b, _asinh_loop, np.arcsinh)
_acosh = _Forward(_acosh_b, _acosh_loop, np.arccosh)
_atanh = _Forward(_atanh_b, _atanh_loop, np.arctanh)


# =============================================================================================
# forward kernels: atan2, pow
# =============================================================================================

@_jit
def _atan2_upper_half(yl, yh, xl, xh):
    """Bounds of atan2 over the box when yl > 0 (angle in ]0, pi[, continuous there).

    In the upper half plane the angle decreases with x, increases with y where x > 0 and
    decreases with y where x < 0: the minimum is at (yl, xh) or (yh, xh), the maximum at
    (yh, xl) or (yl, xl).
    """
    lo = _atan2_dn(yl, xh) if xh >= 0.0 else _atan2_dn(yh, xh)
    hi = _atan2_up(yh, xl) if xl >= 0.0 else _atan2_up(yl, xl)
    return lo, hi


@gufunc(4)
def _atan2(yl, yh, xl, xh, lo, hi):
    if (yl != yl or yh != yh or xl != xl or xh != xh
            or (yl == 0.0 and yh == 0.0 and xl == 0.0 and xh == 0.0)):
        lo[0] = NAN
        hi[0] = NAN
        return
    if yl > 0.0 or yh < 0.0:  # a half plane; the lower one is the mirror image of the upper
        up = yl > 0.0
        a, b = _atan2_upper_half(yl if up else -yh, yh if up else -yl, xl, xh)
        lo[0] = a if up else -b
        hi[0] = b if up else -a
    elif xl < 0.0:  # 0 in Y, the box meets the negative x axis (where atan2 = pi)
        hi[0] = PI_HI
        if yl < 0.0:  # ... and the points just below it (angles near -pi)
            lo[0] = -PI_HI
        elif xh > 0.0:  # Y = [0, yh]: the positive x axis too
            lo[0] = 0.0
        elif yh > 0.0:  # Y = [0, yh], X = [xl, xh] with xh <= 0
            lo[0] = _atan2_dn(yh, xh)
        else:  # Y = [0, 0], X in ]-inf, 0]
            lo[0] = PI_LO
    elif xh == 0.0:  # X = [0, 0], 0 in Y, Y != [0, 0]: the y axis
        lo[0] = -HALF_PI_HI if yl < 0.0 else HALF_PI_LO
        hi[0] = HALF_PI_HI if yh > 0.0 else -HALF_PI_LO
    else:  # X = [xl, xh] with xl >= 0 and xh > 0, 0 in Y: the right half plane
        lo[0] = _atan2_dn(yl, xl) if yl < 0.0 else 0.0
        hi[0] = _atan2_up(yh, xl) if yh > 0.0 else 0.0


@gufunc(4)
def _pow(xl, xh, yl, yh, lo, hi):
    if xl != xl or xh != xh or yl != yl or yh != yh or xh < 0.0:
        lo[0] = NAN
        hi[0] = NAN
        return
    if xh == 0.0:  # X & [0, inf[ = {0}: 0**y = 0 for y > 0, undefined otherwise
        if yh > 0.0:
            lo[0] = 0.0
            hi[0] = 0.0
        else:
            lo[0] = NAN
            hi[0] = NAN
        return
    if xl <= 0.0:
        xl = 0.0  # the part x >= 0 (never -0.0: pow(-0.0, -1) would be -inf)
    # x**y is monotone in x for each fixed y and monotone in y for each fixed x (the
    # directions depend on the signs of y and of log x), so the range over the box is reached
    # at corners, with the limits 0**y (y < 0) = inf, x**(+-inf), inf**y where bounds are
    # infinite. Which corners depends on the signs of y and of log x; where y spans 0, each
    # bound has one candidate on each side of y = 0 (the corner (1, 1) stands for x**0 = 1).
    if yl >= 0.0:
        ax = xl
        ay = yl if xl >= 1.0 else yh
        bx, by = ax, ay
        cx = xh
        cy = yh if xh >= 1.0 else yl
        dx, dy = cx, cy
    elif yh <= 0.0:
        ax = xh
        ay = yl if xh >= 1.0 else yh
        bx, by = ax, ay
        cx = xl
        cy = yh if xl >= 1.0 else yl
        dx, dy = cx, cy
    else:
        ax, ay = (1.0, 1.0) if xl >= 1.0 else (xl, yh)
        bx, by = (xh, yl) if xh >= 1.0 else (1.0, 1.0)
        cx, cy = (xh, yh) if xh >= 1.0 else (1.0, 1.0)
        dx, dy = (1.0, 1.0) if xl >= 1.0 else (xl, yl)
    # lower bound from the corners a, b; upper bound from c, d
    r = _pow_dn(ax, ay)
    if bx != ax or by != ay:
        r = min(r, _pow_dn(bx, by))
    lo[0] = r
    r = _pow_up(cx, cy)
    if dx != cx or dy != cy:
        r = max(r, _pow_up(dx, dy))
    hi[0] = r


# =============================================================================================
# reverse kernels
# =============================================================================================

@gufunc(4)
def _exp_rev(zl, zh, xl, xh, lo, hi):
    # exp(x) in Z  <=>  x in log(Z & ]0, inf])
    if zl != zl or xl != xl or not zh > 0.0:
        lo[0] = NAN
        hi[0] = NAN
        return
    lo[0], hi[0] = _meet(-INF if zl <= 0.0 else _log_dn(zl), _log_up(zh), xl, xh)


@gufunc(4)
def _log_rev(zl, zh, xl, xh, lo, hi):
    # log(x) in Z  <=>  x in exp(Z), x > 0
    if zl != zl or xl != xl or not xh > 0.0:
        lo[0] = NAN
        hi[0] = NAN
        return
    lo[0], hi[0] = _meet(_exp_dn(zl), _exp_up(zh), max(xl, 0.0), xh)


@gufunc(4)
def _sinh_rev(zl, zh, xl, xh, lo, hi):
    if zl != zl or xl != xl:
        lo[0] = NAN
        hi[0] = NAN
        return
    lo[0], hi[0] = _meet(_asinh_dn(zl), _asinh_up(zh), xl, xh)


@gufunc(4)
def _cosh_rev(zl, zh, xl, xh, lo, hi):
    # cosh(x) in Z  <=>  |x| in acosh(Z & [1, inf]): two branches, each met with X
    if zl != zl or xl != xl or not zh >= 1.0:
        lo[0] = NAN
        hi[0] = NAN
        return
    al = 0.0 if zl <= 1.0 else _acosh_dn(zl)
    ah = _acosh_up(zh)
    pl, ph = _meet(al, ah, xl, xh)
    nl, nh = _meet(-ah, -al, xl, xh)
    lo[0], hi[0] = _join(pl, ph, nl, nh)


@gufunc(4)
def _tanh_rev(zl, zh, xl, xh, lo, hi):
    # tanh maps R onto ]-1, 1[
    if zl != zl or xl != xl or zh <= -1.0 or zl >= 1.0:
        lo[0] = NAN
        hi[0] = NAN
        return
    al = -INF if zl <= -1.0 else _atanh_dn(zl)
    ah = INF if zh >= 1.0 else _atanh_up(zh)
    lo[0], hi[0] = _meet(al, ah, xl, xh)


@gufunc(4)
def _atan_rev(zl, zh, xl, xh, lo, hi):
    # atan maps R onto ]-pi/2, pi/2[; a float >= HALF_PI_HI is > pi/2
    if zl != zl or xl != xl or zl >= HALF_PI_HI or zh <= -HALF_PI_HI:
        lo[0] = NAN
        hi[0] = NAN
        return
    al = -INF if zl <= -HALF_PI_HI else _tan_dn(zl)
    ah = INF if zh >= HALF_PI_HI else _tan_up(zh)
    lo[0], hi[0] = _meet(al, ah, xl, xh)


@gufunc(4)
def _asinh_rev(zl, zh, xl, xh, lo, hi):
    if zl != zl or xl != xl:
        lo[0] = NAN
        hi[0] = NAN
        return
    lo[0], hi[0] = _meet(_sinh_dn(zl), _sinh_up(zh), xl, xh)


@gufunc(4)
def _acosh_rev(zl, zh, xl, xh, lo, hi):
    # acosh maps [1, inf[ onto [0, inf[
    if zl != zl or xl != xl or zh < 0.0 or xh < 1.0:
        lo[0] = NAN
        hi[0] = NAN
        return
    lo[0], hi[0] = _meet(_cosh_dn(max(zl, 0.0)), _cosh_up(zh), max(xl, 1.0), xh)


@gufunc(4)
def _atanh_rev(zl, zh, xl, xh, lo, hi):
    # atanh maps ]-1, 1[ onto R: x = tanh(z), and x = +-1 is not in the domain
    if zl != zl or xl != xl:
        lo[0] = NAN
        hi[0] = NAN
        return
    a, b = _meet(_tanh_dn(zl), _tanh_up(zh), max(xl, -1.0), min(xh, 1.0))
    if a >= 1.0 or b <= -1.0:
        a = NAN
        b = NAN
    lo[0] = a
    hi[0] = b


@_jit
def _atan2_rev_q1(t_lo, t_hi, al, ah, bl, bh):
    """Contract ``(x, y)`` in ``[al, ah] x [bl, bh]`` (both >= 0) to atan2(y, x) in [t_lo, t_hi].

    ``[t_lo, t_hi]`` is an enclosure of angles in [0, pi/2], so y = x tan(t) with
    tan(t) in [c1, c2], 0 <= c1 <= c2 <= inf (c2 = inf: the y axis, x = 0 and any y > 0).
    Returns ``(xl, xh, yl, yh)``, NaN when no point but possibly the origin remains.
    """
    t_lo = max(t_lo, 0.0)
    if not t_lo <= t_hi or al != al or bl != bl:
        return NAN, NAN, NAN, NAN
    c1 = _tan_dn(min(t_lo, HALF_PI_LO))
    c2 = INF if t_hi >= HALF_PI_LO else _tan_up(t_hi)
    # y' = Y & X*[c1, c2]
    y_lo = mul_dn(al, c1)
    y_hi = INF if c2 == INF else mul_up(ah, c2)
    if y_lo == INF:
        return NAN, NAN, NAN, NAN
    yl, yh = _meet(y_lo, y_hi, bl, bh)
    if yl != yl:
        return NAN, NAN, NAN, NAN
    # x' = X & y'/[c1, c2]
    x_lo = 0.0 if yl == 0.0 else div_dn(yl, c2)
    x_hi = INF if c1 == 0.0 else div_up(yh, c1)
    if x_lo == INF:
        return NAN, NAN, NAN, NAN
    xl, xh = _meet(x_lo, x_hi, al, ah)
    if xl != xl or (xh == 0.0 and yh == 0.0):  # nothing, or only the origin
        return NAN, NAN, NAN, NAN
    return xl, xh, yl, yh


@gufunc(6, 4)
def _atan2_rev(zl, zh, yl, yh, xl, xh, ylo, yhi, xlo, xhi):
    ylo[0] = NAN
    yhi[0] = NAN
    xlo[0] = NAN
    xhi[0] = NAN
    if zl != zl or yl != yl or xl != xl or zl > PI_HI or zh < -PI_HI:
        return
    rxl = NAN
    rxh = NAN
    ryl = NAN
    ryh = NAN
    # One quadrant at a time, reflected onto quadrant I: q = 0: angles in [0, pi/2], (x, y) as
    # is; q = 1: [pi/2, pi], (-x, y) at angle pi - t; q = 2: [-pi/2, 0], (x, -y) at angle -t;
    # q = 3: [-pi, -pi/2], (-x, -y) at angle t + pi. The angle ranges are widened with the
    # float enclosures of pi and pi/2 (a superset of the exact split).
    for q in range(4):
        if q == 0:
            if not (zh >= 0.0 and zl <= HALF_PI_HI):
                continue
            t_lo = max(zl, 0.0)
            t_hi = min(zh, HALF_PI_HI)
        elif q == 1:
            if not zh >= HALF_PI_LO:
                continue
            t_lo = sub_dn(PI_LO, min(zh, PI_HI))
            t_hi = sub_up(PI_HI, max(zl, HALF_PI_LO))
        elif q == 2:
            if not (zl <= 0.0 and zh >= -HALF_PI_HI):
                continue
            t_lo = -min(zh, 0.0)
            t_hi = -max(zl, -HALF_PI_HI)
        else:
            if not zl <= -HALF_PI_LO:
                continue
            t_lo = add_dn(max(zl, -PI_HI), PI_LO)
            t_hi = add_up(min(zh, -HALF_PI_LO), PI_HI)
        fx = q == 1 or q == 3  # x reflected
        fy = q >= 2  # y reflected
        al, ah = _meet(0.0, INF, -xh if fx else xl, -xl if fx else xh)
        bl, bh = _meet(0.0, INF, -yh if fy else yl, -yl if fy else yh)
        a, b, c, d = _atan2_rev_q1(t_lo, t_hi, al, ah, bl, bh)
        if a == a:
            rxl, rxh = _join(rxl, rxh, -b if fx else a, -a if fx else b)
            ryl, ryh = _join(ryl, ryh, -d if fy else c, -c if fy else d)
    if rxl == rxl and ryl == ryl:
        ylo[0], yhi[0] = _meet(ryl, ryh, yl, yh)
        xlo[0], xhi[0] = _meet(rxl, rxh, xl, xh)
        if ylo[0] != ylo[0] or xlo[0] != xlo[0]:
            ylo[0] = NAN
            yhi[0] = NAN
            xlo[0] = NAN
            xhi[0] = NAN


@_fn
def _quotient_hull(wl, wh, bl, bh):
    """Hull of ``{w / b : w in [wl, wh], b in [bl, bh]}`` for 0 not in [bl, bh] (limits at inf)."""
    lo = INF
    hi = -INF
    for w in (wl, wh):
        for b in (bl, bh):
            if abs(w) == INF and abs(b) == INF:
                continue  # no limit; dominated by the other corners
            lo = min(lo, div_dn(w, b))
            hi = max(hi, div_up(w, b))
    return lo, hi


@_jit
def _meet_nonzero(l, h, al, ah):
    """``[l, h] & [al, ah]``, empty when that is just {0} (a point that is not a solution)."""
    a, b = _meet(l, h, al, ah)
    if a == 0.0 and b == 0.0:
        return NAN, NAN
    return a, b


@_fn
def _mul_rev_proj(wl, wh, bl, bh, al, ah):
    """``hull{a in [al, ah] : a * b in [wl, wh] for some b in [bl, bh]}`` (real a, b).

    Infinite bounds stand for unbounded sides. NaN pair when empty. When 0 is not in W, a = 0
    is never a solution (a * b = 0): a quotient bound 0 is then only the limit of w / b for
    b -> +-inf, and a meet with A that leaves just {0} is empty.
    """
    if wl <= 0.0 <= wh:
        if bl <= 0.0 <= bh:  # b = 0 gives 0 in W for every a
            return al, ah
        l, h = _quotient_hull(wl, wh, bl, bh)
        return _meet(l, h, al, ah)
    if bl > 0.0 or bh < 0.0:
        l, h = _quotient_hull(wl, wh, bl, bh)
        return _meet_nonzero(l, h, al, ah)
    # 0 in B, 0 not in W: a = w / b over b in [bl, 0[ and b in ]0, bh]
    rl = NAN
    rh = NAN
    if wl > 0.0:
        if bh > 0.0:  # a >= wl / bh
            l, h = _meet_nonzero(div_dn(wl, bh), INF, al, ah)
            rl, rh = _join(rl, rh, l, h)
        if bl < 0.0:  # a <= wl / bl
            l, h = _meet_nonzero(-INF, div_up(wl, bl), al, ah)
            rl, rh = _join(rl, rh, l, h)
    else:  # wh < 0
        if bh > 0.0:  # a <= wh / bh
            l, h = _meet_nonzero(-INF, div_up(wh, bh), al, ah)
            rl, rh = _join(rl, rh, l, h)
        if bl < 0.0:  # a >= wh / bl
            l, h = _meet_nonzero(div_dn(wh, bl), INF, al, ah)
            rl, rh = _join(rl, rh, l, h)
    return rl, rh


@gufunc(6, 4)
def _pow_rev(zl, zh, xl, xh, yl, yh, xlo, xhi, ylo, yhi):
    xlo[0] = NAN
    xhi[0] = NAN
    ylo[0] = NAN
    yhi[0] = NAN
    if zl != zl or xl != xl or yl != yl:
        return
    rxl = NAN
    rxh = NAN
    ryl = NAN
    ryh = NAN
    # x = 0: 0**y = 0 for y > 0
    if xl <= 0.0 <= xh and zl <= 0.0 <= zh and yh > 0.0:
        rxl = 0.0
        rxh = 0.0
        ryl = max(yl, 0.0)
        ryh = yh
    # x > 0: z = exp(y * u) with u = log x, i.e. y * u = w = log z (z > 0): the reverse of
    # a product in log space, with outward-rounded logarithms.
    if xh > 0.0 and zh > 0.0:
        ul = -INF if xl <= 0.0 else _log_dn(xl)
        uh = _log_up(xh)
        wl = -INF if zl <= 0.0 else _log_dn(zl)
        wh = _log_up(zh)
        # first u' = {u in U : u * y in W, y in Y}, then y' = {y in Y : u * y in W, u in u'}
        al, ah, bl, bh = ul, uh, yl, yh
        for k in range(2):
            al, ah = _mul_rev_proj(wl, wh, bl, bh, al, ah)
            if al != al:
                break
            if k == 0:
                ul, uh = al, ah
                al, ah, bl, bh = yl, yh, ul, uh
        if al == al:  # (al, ah) = y'
            pl, ph = _meet(_exp_dn(ul), _exp_up(uh), max(xl, 0.0), xh)
            if pl == pl:
                rxl, rxh = _join(rxl, rxh, pl, ph)
                ryl, ryh = _join(ryl, ryh, al, ah)
    xlo[0] = rxl
    xhi[0] = rxh
    ylo[0] = ryl
    yhi[0] = ryh


# =============================================================================================
# public functions
# =============================================================================================

def _binary(kernel, x: IntervalLike, y: IntervalLike, out: Interval | None) -> Interval:
    x, y = as_interval(x), as_interval(y)
    if out is None:
        return Interval._new(*kernel(x.lo, x.hi, y.lo, y.hi))
    kernel(x.lo, x.hi, y.lo, y.hi, out.lo, out.hi)
    return out


def exp(x: IntervalLike, out: Interval | None = None) -> Interval:
    """``exp(x)``; ``exp(-inf) = 0``, overflow gives ``[MAX, inf]``."""
    return _exp(x, out)


def exp2(x: IntervalLike, out: Interval | None = None) -> Interval:
    """``2**x`` (exact for integer ``x`` in [-1074, 1023])."""
    return _exp2(x, out)


def exp10(x: IntervalLike, out: Interval | None = None) -> Interval:
    """``10**x`` (exact for integer ``x`` in [0, 22])."""
    return _exp10(x, out)


def expm1(x: IntervalLike, out: Interval | None = None) -> Interval:
    """``exp(x) - 1``, accurate near 0."""
    return _expm1(x, out)


def log(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Natural logarithm of the part of ``x`` above 0 (``log([0, 1]) = [-inf, 0]``; empty when
    ``x <= 0``)."""
    return _log(x, out)


def log2(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Base-2 logarithm of the part of ``x`` above 0 (exact at powers of two)."""
    return _log2(x, out)


def log10(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Base-10 logarithm of the part of ``x`` above 0 (exact at 10**k, k = 0..22)."""
    return _log10(x, out)


def log1p(x: IntervalLike, out: Interval | None = None) -> Interval:
    """``log(1 + x)`` over the part of ``x`` above -1, accurate near 0."""
    return _log1p(x, out)


def sinh(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Hyperbolic sine."""
    return _sinh(x, out)


def cosh(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Hyperbolic cosine (``cosh([-1, 2]) = [1, cosh 2]``)."""
    return _cosh(x, out)


def tanh(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Hyperbolic tangent, within [-1, 1]."""
    return _tanh(x, out)


def atan(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Arc tangent, within ``[-HALF_PI_HI, HALF_PI_HI]``."""
    return _atan(x, out)


def asinh(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Inverse hyperbolic sine."""
    return _asinh(x, out)


def acosh(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Inverse hyperbolic cosine of the part of ``x`` in [1, inf] (empty when ``x < 1``)."""
    return _acosh(x, out)


def atanh(x: IntervalLike, out: Interval | None = None) -> Interval:
    """Inverse hyperbolic tangent of the part of ``x`` in ]-1, 1[ (``atanh([-1, 1])`` is the
    entire line, ``atanh([1, 2])`` is empty)."""
    return _atanh(x, out)


def atan2(y: IntervalLike, x: IntervalLike, out: Interval | None = None) -> Interval:
    """Angle of the points ``(x, y)`` of the box, IEEE 1788 ``atan2(y, x)`` in ``]-pi, pi]``.

    The origin is left out (``atan2([0, 0], [0, 0])`` is empty). The negative x axis has angle
    pi, so a box that meets it and reaches below it gives ``[-pi, pi]`` (the hull).
    """
    return _binary(_atan2, y, x, out)


def _integer_exponent(y: object) -> int | None:
    """``int(y)`` for a plain integer (or integer-valued float) scalar, of any magnitude, else
    None (``1e300`` is an integer: an even one, as every float beyond ``2**53``)."""
    if isinstance(y, (int, np.integer)):
        return int(y)
    if isinstance(y, (float, np.floating)) and math.isfinite(y) and float(y).is_integer():
        return int(y)
    return None


def _degenerate_integer(y: Interval) -> int | None:
    """``n`` when ``y`` is a scalar degenerate interval ``[n, n]`` with ``n`` an integer."""
    if y.shape != ():
        return None
    lo, hi = float(y.lo), float(y.hi)
    return int(lo) if lo == hi and math.isfinite(lo) and lo.is_integer() else None


def pow(x: IntervalLike, y: IntervalLike, out: Interval | None = None) -> Interval:
    """``x**y`` with IEEE 1788 ``pow`` semantics: ``exp(y log x)`` over ``x > 0``, and
    ``0**y = 0`` for ``y > 0`` (``0**y`` is undefined for ``y <= 0``; negative ``x`` is outside
    the domain).

    A plain integer exponent (a Python or NumPy integer, or an integer-valued float scalar such
    as ``2.0`` or ``1e20``, of any magnitude; not an ``Interval``) is handed to
    ``algebraic.pown``, which also accepts negative bases: ``pow([-2, 1], 2) = [0, 4]`` but
    ``pow([-2, 1], Interval(2)) = [0, 1]`` (an ``Interval`` exponent is always the 1788
    ``pow``). The operator ``x ** y`` (``power``) differs only there: it takes a degenerate
    integer ``Interval`` exponent as the integer power too. Expressions follow the same rule
    (``boundest.expr.nodes.power``).
    """
    n = None if isinstance(y, Interval) else _integer_exponent(y)
    if n is not None:
        from .algebraic import pown
        r = pown(x, n)
        if out is None:
            return r
        out.lo[...] = r.lo
        out.hi[...] = r.hi
        return out
    return _binary(_pow, x, y, out)


def power(x: IntervalLike, y: IntervalLike) -> Interval:
    """``x ** y``, the operator: the integer power ``pown`` (any sign of ``x``) for an
    integer-valued exponent of any magnitude -- a Python or NumPy integer, an integer-valued
    float scalar, or a scalar degenerate ``Interval`` ``[n, n]`` -- else IEEE 1788 ``pow``.

    ``Interval(-3, -2) ** Interval(5, 5) = [-243, -32]`` while ``pow(Interval(-3, -2),
    Interval(5, 5))`` is empty (1788 ``pow``, defined for ``x >= 0``). An expression's ``**``
    follows the same rule, so a model function gives the same powers evaluated on intervals as
    compiled from expressions.
    """
    if isinstance(y, Interval):
        n = _degenerate_integer(y)
        if n is not None:
            from .algebraic import pown
            return pown(x, n)
    return pow(x, y)


# -- reverse -----------------------------------------------------------------------------------

def _rev1(kernel, z: IntervalLike, x: IntervalLike) -> Interval:
    z, x = as_interval(z), as_interval(x)
    return Interval._new(*kernel(z.lo, z.hi, x.lo, x.hi))


def exp_rev(z: IntervalLike, x: IntervalLike) -> Interval:
    """``hull{x in X : exp(x) in Z}`` = ``X & log(Z)``."""
    return _rev1(_exp_rev, z, x)


def log_rev(z: IntervalLike, x: IntervalLike) -> Interval:
    """``hull{x in X, x > 0 : log(x) in Z}`` = ``X & exp(Z)``."""
    return _rev1(_log_rev, z, x)


def sinh_rev(z: IntervalLike, x: IntervalLike) -> Interval:
    """``hull{x in X : sinh(x) in Z}`` = ``X & asinh(Z)``."""
    return _rev1(_sinh_rev, z, x)


def cosh_rev(z: IntervalLike, x: IntervalLike) -> Interval:
    """``hull{x in X : cosh(x) in Z}``: both branches ``+-acosh(Z)`` met with ``X``
    (``cosh_rev([1, cosh 2], [-3, -1]) = [-2, -1]``)."""
    return _rev1(_cosh_rev, z, x)


def tanh_rev(z: IntervalLike, x: IntervalLike) -> Interval:
    """``hull{x in X : tanh(x) in Z}`` = ``X & atanh(Z & ]-1, 1[)``."""
    return _rev1(_tanh_rev, z, x)


def atan_rev(z: IntervalLike, x: IntervalLike) -> Interval:
    """``hull{x in X : atan(x) in Z}`` = ``X & tan(Z & ]-pi/2, pi/2[)``."""
    return _rev1(_atan_rev, z, x)


def asinh_rev(z: IntervalLike, x: IntervalLike) -> Interval:
    """``hull{x in X : asinh(x) in Z}`` = ``X & sinh(Z)``."""
    return _rev1(_asinh_rev, z, x)


def acosh_rev(z: IntervalLike, x: IntervalLike) -> Interval:
    """``hull{x in X, x >= 1 : acosh(x) in Z}`` = ``X & cosh(Z & [0, inf])``."""
    return _rev1(_acosh_rev, z, x)


def atanh_rev(z: IntervalLike, x: IntervalLike) -> Interval:
    """``hull{x in X, -1 < x < 1 : atanh(x) in Z}`` = ``X & tanh(Z)``."""
    return _rev1(_atanh_rev, z, x)


def atan2_rev(z: IntervalLike, y: IntervalLike, x: IntervalLike) -> tuple[Interval, Interval]:
    """Contract the box ``(y, x)`` to the points whose angle ``atan2(y, x)`` lies in ``z``.

    Returns ``(y', x')``. The angles ``z & [-pi, pi]`` are split by quadrant; in each quadrant
    the points at angle ``t`` satisfy ``|y| = |x| tan(t')`` with ``t'`` in ``[0, pi/2]``
    (``t' = t``, ``pi - t``, ``-t`` or ``t + pi``), whose projections are exact hulls of products
    and quotients of non-negative intervals. The union over the quadrants is hulled, so the
    result is the hull of the box part inside the cone of angles ``z`` (up to rounding).
    Both parts are empty when no point of the box (other than the origin) has its angle in ``z``.
    """
    z, y, x = as_interval(z), as_interval(y), as_interval(x)
    yl, yh, xl, xh = _atan2_rev(z.lo, z.hi, y.lo, y.hi, x.lo, x.hi)
    return Interval._new(yl, yh), Interval._new(xl, xh)


def pow_rev(z: IntervalLike, x: IntervalLike, y: IntervalLike) -> tuple[Interval, Interval]:
    """Contract ``x`` and ``y`` to the points with ``pow(x, y)`` in ``z``; returns ``(x', y')``.

    ``x'`` is IEEE 1788 ``powRev1(y, z, x)`` and ``y'`` is ``powRev2(x, z, y)`` (computed from
    the contracted ``x'``, which loses nothing). For ``x > 0`` the constraint is
    ``y * log(x) = log(z)``: the reverse of a product in log space, with outward-rounded
    logarithms and exponentials. ``x = 0`` is kept when ``0`` is in ``z`` and some ``y > 0``
    is in ``y`` (``0**y = 0``).
    """
    z, x, y = as_interval(z), as_interval(x), as_interval(y)
    xl, xh, yl, yh = _pow_rev(z.lo, z.hi, x.lo, x.hi, y.lo, y.hi)
    return Interval._new(xl, xh), Interval._new(yl, yh)
