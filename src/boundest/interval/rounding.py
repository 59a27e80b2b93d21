"""Directed rounding for the interval kernels.

Every kernel evaluates in IEEE 754 round-to-nearest and then moves each bound outward only
when the rounded result is not exact. For ``+ - * / sqrt`` an error-free transformation
(TwoSum, or the FMA remainder) tells the sign of the rounding error, so these operations
return the tightest float64 enclosure. For library functions (``exp``, ``sin``, ...) the
error is bounded by ``LIBM_ULPS`` units in the last place and the bound is widened by that
much (glibc measured at 1-3 ulp on the project's machine, SVML documented at 4).

``next_down``/``next_up`` are the predecessor/successor trick of Rump, Zimmermann, Boldo
and Melquiond (BIT 2009): ``x - (|x| phi + eta)`` with ``phi = 2^-53 + 2^-105`` evaluated in
round-to-nearest is the predecessor of ``x`` (or one further, which is still sound), at a
fraction of the cost of ``np.nextafter``.
"""

from __future__ import annotations

from collections.abc import Callable
from types import FunctionType

import numba as nb
import numpy as np
from llvmlite import ir
from numba import carray, types
from numba.core import cgutils
from numba.extending import intrinsic
from numba.np.ufunc import _internal  # the ufunc constructor nb.vectorize uses

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
#: Assumed maximal error of the platform's libm functions, in ulps (glibc measured at 1-3).
LIBM_ULPS = 4
_LIBM_REL = (LIBM_ULPS + 1) * 2.0**-52
_LIBM_ABS = LIBM_ULPS * ETA

_jit = nb.njit(cache=True, error_model="numpy")  # small helpers: LLVM inlines them


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
    r = x - (abs(x) * PHI + ETA)
    return MAX if x == INF else r


@_jit
def next_up(x: float) -> float:
    """A float strictly above ``x`` (its successor, rarely one further); ``-inf -> -MAX``."""
    r = x + (abs(x) * PHI + ETA)
    return -MAX if x == -INF else r


# The helpers below are written as selects, not branches: whether a rounded result is exact
# is random on real data, and a mispredicted branch costs more than the arithmetic.
@_jit
def _lower(s: float, err: float) -> float:
    """Lower bound of the exact value, given ``s = RN(exact)`` and ``err`` with the sign of
    ``exact - s`` (NaN: unknown, step anyway). An overflow ``s = +inf`` gives ``MAX``."""
    r = s if err >= 0.0 else s - (abs(s) * PHI + ETA)
    return MAX if s == INF else r


@_jit
def _upper(s: float, err: float) -> float:
    """Upper bound of the exact value (see ``_lower``); ``s = -inf`` gives ``-MAX``."""
    r = s if err <= 0.0 else s + (abs(s) * PHI + ETA)
    return -MAX if s == -INF else r


@_jit
def _two_sum_err(a: float, b: float, s: float) -> float:
    """``a + b - s`` exactly (Knuth's TwoSum), for ``s = RN(a + b)``; NaN with infinities."""
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
    """``a*b - p`` exactly (FMA) for ``p = RN(a*b)``; NaN (unknown) in the underflow range,
    where the remainder itself may round."""
    e = fma(a, b, -p)
    return NAN if abs(p) < TINY else e


@_jit
def mul_dn(a: float, b: float) -> float:
    """Lower bound of a*b (tightest outside the underflow range), with 0*inf = 0."""
    p = a * b
    r = _lower(p, _mul_err(a, b, p))
    return 0.0 if (a == 0.0 or b == 0.0) else r


@_jit
def mul_up(a: float, b: float) -> float:
    """Upper bound of a*b (tightest outside the underflow range), with 0*inf = 0."""
    p = a * b
    r = _upper(p, _mul_err(a, b, p))
    return 0.0 if (a == 0.0 or b == 0.0) else r


@_jit
def _div_err(a: float, b: float, q: float) -> float:
    """Sign of ``a/b - q`` for ``q = RN(a/b)``, ``b != 0``: the exact remainder ``a - q*b``
    (FMA) times the sign of ``b``; exact for ``a = 0`` and ``a / inf``; NaN (unknown: step
    outward) in the underflow range and for an infinite ``a``, where ``_lower``/``_upper``
    still give sound bounds."""
    r = fma(-q, b, a)
    e = r if b > 0.0 else -r
    e = NAN if (abs(q) < TINY or abs(a) < TINY) else e
    e = 0.0 if abs(b) == INF else e  # a / inf = 0 exactly (inf / inf is NaN anyway)
    return 0.0 if a == 0.0 else e


@_jit
def div_dn(a: float, b: float) -> float:
    """Lower bound of a/b for b != 0 (limits at infinities: a/inf = 0, inf/b = inf)."""
    q = a / b
    return _lower(q, _div_err(a, b, q))


@_jit
def div_up(a: float, b: float) -> float:
    """Upper bound of a/b for b != 0."""
    q = a / b
    return _upper(q, _div_err(a, b, q))


@_jit
def _sqrt_err(a: float, s: float) -> float:
    """``a - s*s`` exactly for ``s = RN(sqrt(a))`` (0 at 0 and inf, NaN when tiny)."""
    e = fma(-s, s, a)
    e = NAN if a < TINY else e
    return 0.0 if (a == INF or a == 0.0) else e


@_jit
def sqrt_dn(a: float) -> float:
    """Lower bound of sqrt(a), a >= 0."""
    s = np.sqrt(a)
    r = _lower(s, _sqrt_err(a, s))
    return r if r > 0.0 else 0.0  # (plain selects: Numba's max() blocks vectorisation)


@_jit
def sqrt_up(a: float) -> float:
    """Upper bound of sqrt(a), a >= 0."""
    s = np.sqrt(a)
    return _upper(s, _sqrt_err(a, s))


@_jit
def libm_dn(r: float) -> float:
    """Lower bound for a libm result ``r`` within ``LIBM_ULPS`` ulps of the exact value."""
    d = r - (abs(r) * _LIBM_REL + _LIBM_ABS)
    return MAX if r == INF else d


@_jit
def libm_up(r: float) -> float:
    """Upper bound for a libm result ``r`` within ``LIBM_ULPS`` ulps of the exact value."""
    u = r + (abs(r) * _LIBM_REL + _LIBM_ABS)
    return -MAX if r == -INF else u


_ONE = 1.0
_QUARTER_ULP = 2.0**-54


def check_rounding_mode() -> None:
    """Raise ``FloatingPointError`` unless the FPU rounds to nearest.

    Every kernel assumes round-to-nearest; some libraries switch the process to upward
    rounding (importing ``codac`` does), after which results would not be enclosures.
    """
    if _ONE + _QUARTER_ULP != _ONE or -_ONE - _QUARTER_ULP != -_ONE:
        raise FloatingPointError(
            "the floating-point rounding mode is not round-to-nearest (another library, e.g. "
            "codac, changed it); boundest's enclosures need round-to-nearest: restore it "
            "(fesetround(FE_TONEAREST)) before calling boundest")


class _LazyGufunc:
    """A NumPy gufunc over float64 scalars, compiled by Numba on first call (then cached)."""

    def __init__(self, func: Callable, nin: int, nout: int) -> None:
        self._func = func
        self._nin = nin
        self._nout = nout
        self._ufunc = None
        #: The element kernel as a Numba function ``f(a0, ..., out0, ...)`` for compiled
        #: callers (outputs are 1-element array views); compiled on first use.
        self.scalar = nb.njit(cache=True, error_model="numpy")(func)
        self.__name__ = func.__name__
        self.__doc__ = func.__doc__

    def _build(self):
        args = ",".join(["f8"] * self._nin + ["f8[:]"] * self._nout)
        layout = ",".join(["()"] * self._nin) + "->" + ",".join(["()"] * self._nout)
        self._ufunc = nb.guvectorize([f"void({args})"], layout, cache=True)(self._func)
        return self._ufunc

    def __call__(self, *args, **kwargs):
        ufunc = self._ufunc or self._build()
        check_rounding_mode()
        with np.errstate(all="ignore"):  # overflow and inf - inf are expected inside kernels
            return ufunc(*args, **kwargs)


# The ufunc loops. ``nb.vectorize(cache=True)`` caches a ufunc's element function on disk but
# builds its loop again (LLVM) in every process, 50-75 ms a ufunc; a gufunc's loop is cached
# but runs the branch-free kernels without SIMD. Instead, each kernel's loop is a ``cfunc``
# with NumPy's inner-loop signature, cached on disk like any Numba function (a few ms to
# load), registered as a NumPy ufunc the way ``nb.vectorize`` registers its own loops
# (``numba.np.ufunc._internal.fromfunc``): broadcasting, ``out=``, casts and 0-d results are
# NumPy's own. The loop has a contiguous branch, which LLVM vectorises with the kernel inlined,
# and a strided one (broadcast scalars, views).
_F8 = types.float64
_LOOP_SIG = types.void(types.CPointer(types.voidptr), types.CPointer(types.intp),
                       types.CPointer(types.intp), types.voidptr)
_F8_NUM = np.dtype(np.float64).num


@intrinsic
def _load_f8(typingctx, ptr, offset):  # noqa: ARG001 - numba intrinsic signature
    """The float64 at ``offset`` bytes past ``ptr``."""
    def codegen(context, builder, signature, args):  # noqa: ARG001
        p = builder.bitcast(builder.gep(args[0], [args[1]]), ir.DoubleType().as_pointer())
        return builder.load(p)

    return _F8(types.voidptr, types.intp), codegen


@intrinsic
def _store_f8(typingctx, ptr, offset, value):  # noqa: ARG001 - numba intrinsic signature
    """Store the float64 ``value`` at ``offset`` bytes past ``ptr``."""
    def codegen(context, builder, signature, args):  # noqa: ARG001
        p = builder.bitcast(builder.gep(args[0], [args[1]]), ir.DoubleType().as_pointer())
        builder.store(args[2], p)
        return context.get_dummy_value()

    return types.void(types.voidptr, types.intp, _F8), codegen


# Loop templates, one per arity; ``_KERNEL`` is bound per kernel by ``_kernel_loop``.
def _loop2(args, dims, steps, data):  # noqa: ARG001 - NumPy's inner-loop signature
    n = dims[0]
    p0, p1, po = args[0], args[1], args[2]
    s0, s1, so = steps[0], steps[1], steps[2]
    if s0 == 8 and s1 == 8 and so == 8:
        a0, a1 = carray(p0, n, np.float64), carray(p1, n, np.float64)
        o = carray(po, n, np.float64)
        for i in range(n):
            o[i] = _KERNEL(a0[i], a1[i])  # noqa: F821
    else:
        for i in range(n):
            _store_f8(po, i * so, _KERNEL(_load_f8(p0, i * s0), _load_f8(p1, i * s1)))  # noqa: F821


def _loop4(args, dims, steps, data):  # noqa: ARG001 - NumPy's inner-loop signature
    n = dims[0]
    p0, p1, p2, p3, po = args[0], args[1], args[2], args[3], args[4]
    s0, s1, s2, s3, so = steps[0], steps[1], steps[2], steps[3], steps[4]
    if s0 == 8 and s1 == 8 and s2 == 8 and s3 == 8 and so == 8:
        a0, a1 = carray(p0, n, np.float64), carray(p1, n, np.float64)
        a2, a3 = carray(p2, n, np.float64), carray(p3, n, np.float64)
        o = carray(po, n, np.float64)
        for i in range(n):
            o[i] = _KERNEL(a0[i], a1[i], a2[i], a3[i])  # noqa: F821
    else:
        for i in range(n):
            _store_f8(po, i * so, _KERNEL(_load_f8(p0, i * s0), _load_f8(p1, i * s1),  # noqa: F821
                                          _load_f8(p2, i * s2), _load_f8(p3, i * s3)))


_LOOPS = {2: _loop2, 4: _loop4}


def _kernel_loop(func: Callable, nin: int) -> nb.core.ccallback.CFunc:
    """The cached ``cfunc`` NumPy loop of one kernel.

    A copy of the arity's template whose global ``_KERNEL`` is the kernel, inlined at Numba IR
    level (one compilation per loop; an empty-cache run compiled a separate scalar kernel 10 %
    slower), and whose name, file and first line are the kernel's: Numba keys its disk cache on
    those (a closure would not do: its key hashes the pickled kernel, which differs in every
    process).
    """
    template = _LOOPS[nin]
    name = f"{func.__name__}_loop"
    code = template.__code__.replace(co_name=name, co_qualname=f"{func.__qualname__}_loop",
                                     co_filename=func.__code__.co_filename,
                                     co_firstlineno=func.__code__.co_firstlineno)
    kernel = nb.njit(inline="always", error_model="numpy")(func)  # not compiled on its own
    loop = FunctionType(code, {**template.__globals__, "_KERNEL": kernel}, name)
    loop.__qualname__ = f"{func.__qualname__}_loop"
    loop.__module__ = func.__module__
    return nb.cfunc(_LOOP_SIG, cache=True, error_model="numpy")(loop)


class _LazyUfunc:
    """A NumPy ufunc ``f(a0, ..., a_{nin-1}) -> float64`` compiled by Numba on first call.

    Used for the branch-free kernels of ``+ - * / sqr sqrt``, one ufunc per bound: the loop
    runs them with SIMD on contiguous arrays, several times faster than a gufunc per element,
    and is cached on disk (see ``_kernel_loop``).
    """

    def __init__(self, func: Callable, nin: int) -> None:
        if nin not in _LOOPS:
            raise ValueError(f"no ufunc loop for {nin} inputs (have {sorted(_LOOPS)})")
        self._func = func
        self._nin = nin
        self._ufunc = None
        self._loop = None  # the compiled NumPy inner loop (a Numba ``cfunc``), once built
        #: The scalar kernel as a Numba function, for compiled callers (and the loop).
        self.scalar = nb.njit(cache=True, error_model="numpy")(func)
        self.__name__ = func.__name__
        self.__doc__ = func.__doc__

    def _build(self):
        self._loop = loop = _kernel_loop(self._func, self._nin)
        self._ufunc = _internal.fromfunc(
            self._func.__name__, self._func.__doc__, [loop.address],
            [[_F8_NUM] * (self._nin + 1)], self._nin, 1, [None], [loop], _internal.PyUFunc_None)
        return self._ufunc

    def __call__(self, *args, **kwargs):
        ufunc = self._ufunc or self._build()
        check_rounding_mode()
        with np.errstate(all="ignore"):
            return ufunc(*args, **kwargs)


def ufunc(nin: int) -> Callable[[Callable], _LazyUfunc]:
    """Declare a scalar kernel ``f(a0, ..., a_{nin-1}) -> float`` as a lazy NumPy ufunc."""
    def wrap(func: Callable) -> _LazyUfunc:
        return _LazyUfunc(func, nin)
    return wrap


def gufunc(nin: int, nout: int = 2) -> Callable[[Callable], _LazyGufunc]:
    """Declare an element kernel ``f(a0, ..., a_{nin-1}, out0, ..., out_{nout-1})``.

    The kernel body reads float64 scalars and writes ``out_k[0]``. The result is a
    broadcasting NumPy gufunc that accepts ``out=`` arrays; Numba compiles it lazily and
    caches the machine code on disk.
    """
    def wrap(func: Callable) -> _LazyGufunc:
        return _LazyGufunc(func, nin, nout)
    return wrap
