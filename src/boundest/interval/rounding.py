"""Directed rounding for the interval kernels.

Every kernel evaluates in IEEE 754 round-to-nearest and then moves each bound outward only
when the rounded result is not exact. For ``+ - * / sqrt`` an error-free transformation
(TwoSum, or the FMA remainder) tells the sign of the rounding error, so these operations
return the tightest float64 enclosure. For library functions (``exp``, ``sin``, ...) the
error is bounded by ``LIBM_ULPS`` units in the last place and the bound is widened by that
much (shared/RIGOR.md: glibc needs 1-3 ulp, SVML is documented at 4).

``next_down``/``next_up`` are the predecessor/successor trick of Rump, Zimmermann, Boldo
and Melquiond (BIT 2009): ``x - (|x| phi + eta)`` with ``phi = 2^-53 + 2^-105`` evaluated in
round-to-nearest is the predecessor of ``x`` (or one further, which is still sound), at a
fraction of the cost of ``np.nextafter``.
"""

from __future__ import annotations

from collections.abc import Callable

import numba as nb
import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

__all__ = [
    "INF",
    "LIBM_ULPS",
    "MAX",
    "NAN",
    "add_dn",
    "add_up",
    "div_dn",
    "div_up",
    "fma",
    "gufunc",
    "libm_dn",
    "libm_up",
    "mul_dn",
    "mul_up",
    "next_down",
    "next_up",
    "sqrt_dn",
    "sqrt_up",
    "sub_dn",
    "sub_up",
]

PHI = 2.0**-53 + 2.0**-105
ETA = 2.0**-1074
MAX = float(np.finfo(np.float64).max)
INF = float("inf")
NAN = float("nan")
#: Below this magnitude an FMA remainder may underflow; the kernels then widen blindly.
TINY = 2.0**-960
#: Assumed maximal error of the platform's libm functions, in ulps (shared/RIGOR.md).
LIBM_ULPS = 4
_LIBM_REL = (LIBM_ULPS + 1) * 2.0**-52
_LIBM_ABS = LIBM_ULPS * ETA

_jit = nb.njit(inline="always", cache=True)


@intrinsic
def fma(typingctx, a, b, c):  # noqa: ARG001 - numba intrinsic signature
    """Fused multiply-add ``a*b + c`` with a single rounding (LLVM ``llvm.fma.f64``)."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):  # noqa: ARG001
        d = ir.DoubleType()
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(d, [d, d, d]),
                                            "llvm.fma.f64")
        return builder.call(fn, args)

    return sig, codegen


@_jit
def next_down(x: float) -> float:
    """A float strictly below ``x`` (its predecessor, rarely one further); ``inf -> MAX``."""
    if x == INF:
        return MAX
    return x - (abs(x) * PHI + ETA)


@_jit
def next_up(x: float) -> float:
    """A float strictly above ``x`` (its successor, rarely one further); ``-inf -> -MAX``."""
    if x == -INF:
        return -MAX
    return x + (abs(x) * PHI + ETA)


@_jit
def _lower(s: float, err: float) -> float:
    """Lower bound of ``s + err`` where ``s = RN(exact)`` and ``err`` has the sign of the error."""
    if s == INF:
        return MAX
    if err < 0.0:
        return next_down(s)
    return s


@_jit
def _upper(s: float, err: float) -> float:
    if s == -INF:
        return -MAX
    if err > 0.0:
        return next_up(s)
    return s


@_jit
def _two_sum_err(a: float, b: float, s: float) -> float:
    bb = s - a
    return (a - (s - bb)) + (b - bb)


@_jit
def add_dn(a: float, b: float) -> float:
    """Largest float <= a + b (tightest); NaN propagates."""
    s = a + b
    return _lower(s, _two_sum_err(a, b, s))


@_jit
def add_up(a: float, b: float) -> float:
    """Smallest float >= a + b (tightest); NaN propagates."""
    s = a + b
    return _upper(s, _two_sum_err(a, b, s))


@_jit
def sub_dn(a: float, b: float) -> float:
    return add_dn(a, -b)


@_jit
def sub_up(a: float, b: float) -> float:
    return add_up(a, -b)


@_jit
def _mul_err(a: float, b: float, p: float) -> float:
    """Sign-correct error of ``p = RN(a*b)``; +-inf when it cannot be trusted (underflow)."""
    if abs(p) < TINY:
        if a == 0.0 or b == 0.0:
            return 0.0
        return NAN
    if abs(p) == INF:
        return 0.0
    return fma(a, b, -p)


@_jit
def mul_dn(a: float, b: float) -> float:
    """Lower bound of a*b with 0*inf = 0 (the interval convention)."""
    if a == 0.0 or b == 0.0:
        return 0.0
    p = a * b
    e = _mul_err(a, b, p)
    if e != e:  # underflow: step blindly, but the sign of a*b is known
        r = next_down(p)
        return max(r, 0.0) if (a > 0.0) == (b > 0.0) else r
    return _lower(p, e)


@_jit
def mul_up(a: float, b: float) -> float:
    """Upper bound of a*b with 0*inf = 0."""
    if a == 0.0 or b == 0.0:
        return 0.0
    p = a * b
    e = _mul_err(a, b, p)
    if e != e:
        r = next_up(p)
        return min(r, 0.0) if (a > 0.0) != (b > 0.0) else r
    return _upper(p, e)


@_jit
def _div_err(a: float, b: float, q: float) -> float:
    """Sign of ``a/b - q`` (exact), NaN when it cannot be decided cheaply."""
    if abs(a) == INF or abs(b) == INF or (q == 0.0 and a == 0.0):
        return 0.0
    if abs(q) == INF:
        return 0.0
    if abs(q) < TINY or abs(a) < TINY:
        return NAN
    r = fma(-q, b, a)  # exact remainder a - q*b
    return r if b > 0.0 else -r


@_jit
def div_dn(a: float, b: float) -> float:
    """Lower bound of a/b for b != 0 (limits at infinities: a/inf = 0, inf/b = inf)."""
    q = a / b
    e = _div_err(a, b, q)
    if e != e:
        r = next_down(q)
        return max(r, 0.0) if (a > 0.0) == (b > 0.0) else r
    return _lower(q, e)


@_jit
def div_up(a: float, b: float) -> float:
    """Upper bound of a/b for b != 0."""
    q = a / b
    e = _div_err(a, b, q)
    if e != e:
        r = next_up(q)
        return min(r, 0.0) if (a > 0.0) != (b > 0.0) else r
    return _upper(q, e)


@_jit
def sqrt_dn(a: float) -> float:
    """Lower bound of sqrt(a), a >= 0."""
    s = np.sqrt(a)
    if a == INF or a == 0.0:
        return s
    if a < TINY:
        return next_down(s)
    return _lower(s, fma(-s, s, a))


@_jit
def sqrt_up(a: float) -> float:
    """Upper bound of sqrt(a), a >= 0."""
    s = np.sqrt(a)
    if a == INF or a == 0.0:
        return s
    if a < TINY:
        return next_up(s)
    return _upper(s, fma(-s, s, a))


@_jit
def libm_dn(r: float) -> float:
    """Lower bound for a libm result ``r`` within ``LIBM_ULPS`` ulps of the exact value."""
    if r == INF:
        return MAX
    return r - (abs(r) * _LIBM_REL + _LIBM_ABS)


@_jit
def libm_up(r: float) -> float:
    """Upper bound for a libm result ``r`` within ``LIBM_ULPS`` ulps of the exact value."""
    if r == -INF:
        return -MAX
    return r + (abs(r) * _LIBM_REL + _LIBM_ABS)


class _LazyGufunc:
    """A NumPy gufunc over float64 scalars, compiled by Numba on first call (then cached)."""

    def __init__(self, func: Callable, nin: int, nout: int) -> None:
        self._func = func
        self._nin = nin
        self._nout = nout
        self._ufunc = None
        self.__name__ = func.__name__
        self.__doc__ = func.__doc__

    def _build(self):
        args = ",".join(["f8"] * self._nin + ["f8[:]"] * self._nout)
        layout = ",".join(["()"] * self._nin) + "->" + ",".join(["()"] * self._nout)
        self._ufunc = nb.guvectorize([f"void({args})"], layout, cache=True)(self._func)
        return self._ufunc

    def __call__(self, *args, **kwargs):
        ufunc = self._ufunc or self._build()
        with np.errstate(all="ignore"):  # overflow and inf - inf are expected inside kernels
            return ufunc(*args, **kwargs)


def gufunc(nin: int, nout: int = 2) -> Callable[[Callable], _LazyGufunc]:
    """Declare an element kernel ``f(a0, ..., a_{nin-1}, out0, ..., out_{nout-1})``.

    The kernel body reads float64 scalars and writes ``out_k[0]``. The result is a
    broadcasting NumPy gufunc that accepts ``out=`` arrays; Numba compiles it lazily and
    caches the machine code on disk.
    """
    def wrap(func: Callable) -> _LazyGufunc:
        return _LazyGufunc(func, nin, nout)
    return wrap
