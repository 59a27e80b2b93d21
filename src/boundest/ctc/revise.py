"""Compiled HC4-revise of one primitive node, and a forward-backward pass over a tape.

The scalar kernels that the propagation engine (:mod:`boundest.csp.engine`) and compiled
contractors (:class:`boundest.ctc.CtcRayCast`) share: ``revise`` contracts the three domains of
one node ``z = f(x, y)`` (``z ∩= f(x, y)``, then ``(x, y) = f_rev(z, x, y)``), ``hc4_pass``
revises every node of a tape once forward and once backward on one box's slots. The ops are in
families (:data:`FAMILIES`); a caller passes ``True`` for the families its tape uses and
``None`` for the others, whose kernels Numba then neither compiles nor loads.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ..expr.tape import OPS
from ..interval import algebraic as al
from ..interval import arith as ar
from ..interval import explog as el
from ..interval import trig as tr

__all__ = ["FAMILIES", "OP_CODES", "back", "family_flags", "hc4_pass", "image", "revise",
           "revise_nodes"]

INF = math.inf
OP_CODES = _C = {name: i for i, name in enumerate(OPS)}
NEG, SQR, SQRT, EXP, LOG, SIN, COS, TAN = (_C[k] for k in
                                           ("neg", "sqr", "sqrt", "exp", "log", "sin", "cos",
                                            "tan"))
ASIN, ACOS, ATAN, SINH, COSH, TANH, ABS, SIGN = (_C[k] for k in
                                                 ("asin", "acos", "atan", "sinh", "cosh",
                                                  "tanh", "abs", "sign"))
FLOOR, CEIL, POWN, ADD, SUB, MUL, DIV, POW = (_C[k] for k in
                                              ("floor", "ceil", "pown", "add", "sub", "mul",
                                               "div", "pow"))
ATAN2, MIN, MAX = _C["atan2"], _C["min"], _C["max"]

_add_lo, _add_hi, _sub_lo, _sub_hi = (ar._add_lo.scalar, ar._add_hi.scalar, ar._sub_lo.scalar,
                                      ar._sub_hi.scalar)
_mul_lo, _mul_hi, _div_lo, _div_hi = (ar._mul_lo.scalar, ar._mul_hi.scalar, ar._div_lo.scalar,
                                      ar._div_hi.scalar)
_sqr_lo, _sqr_hi, _sqrt_lo, _sqrt_hi = (ar._sqr_lo.scalar, ar._sqr_hi.scalar,
                                        ar._sqrt_lo.scalar, ar._sqrt_hi.scalar)
# bounds functions f(xl, xh, f(xl), f(xh)) -> (lo, hi), given libm values at the bounds
_f_exp, _f_log, _f_sinh, _f_cosh = el._exp.bounds, el._log.bounds, el._sinh.bounds, el._cosh.bounds
_f_tanh, _f_atan, _f_asin, _f_acos = (el._tanh.bounds, el._atan.bounds, tr._asin.bounds,
                                      tr._acos.bounds)
_f_atan2, _f_pow = el._atan2.scalar, el._pow.scalar
_f_sin, _f_cos, _f_tan = tr._sin.scalar, tr._cos.scalar, tr._tan.bounds
# a tape's pown exponent (a float64 of any magnitude) as the kernels' int64: not np.int64(p),
# undefined beyond 2**63 (1e20 became -2**63, an odd negative power)
_f_pown, _b_pown, _pown_n = al._pown.scalar, al._pown_rev.scalar, al._tape_exponent
_b_exp, _b_log, _b_sinh, _b_cosh = (el._exp_rev.scalar, el._log_rev.scalar, el._sinh_rev.scalar,
                                    el._cosh_rev.scalar)
_b_tanh, _b_atan, _b_atan2, _b_pow = (el._tanh_rev.scalar, el._atan_rev.scalar,
                                      el._atan2_rev.scalar, el._pow_rev.scalar)
_b_sin, _b_cos, _b_tan, _b_asin, _b_acos = (tr._sin_rev.scalar, tr._cos_rev.scalar,
                                            tr._tan_rev.scalar, tr._asin_rev.scalar,
                                            tr._acos_rev.scalar)


#: The op families: ``propagate_kernel`` is compiled (and cached) once per combination of
#: families a tape uses, each family's kernels only where it is used; the basic arithmetic
#: (+, -, *, /, sqr, sqrt, neg) is always there.
FAMILIES: dict[str, tuple[int, ...]] = {
    "piecewise": (ABS, SIGN, FLOOR, CEIL, MIN, MAX),
    "pown": (POWN,),
    "explog": (EXP, LOG, SINH, COSH, TANH, ATAN, ATAN2, POW),
    "trig": (SIN, COS, TAN, ASIN, ACOS),
}


def family_flags(op: np.ndarray) -> tuple[bool | None, ...]:
    """The family arguments of ``propagate_kernel`` for a tape with op codes ``op``: ``True``
    for a family some node uses, ``None`` for the others (Numba prunes their branches before
    compiling, so their kernels are neither compiled nor loaded)."""
    used = set(np.unique(op).tolist())
    return tuple(True if used & set(codes) else None for codes in FAMILIES.values())


@nb.njit(cache=True, inline="always", error_model="numpy")
def _cap(zl, zh, nl, nh):
    """``[zl, zh] ∩ [nl, nh]`` where a NaN (empty) image stays NaN."""
    return (max(nl, zl) if nl == nl else nl), (min(nh, zh) if nh == nh else nh)


@nb.njit(cache=True, error_model="numpy")
def _image_explog(code, xl, xh, yl, yh, buf):
    """Forward image of an exponential-family node (exp, log, sinh, cosh, tanh, atan, atan2,
    and the real power ``pow(x, y) = exp(y log x)``)."""
    if code == POW:
        _f_pow(xl, xh, yl, yh, buf[0:1], buf[1:2])
        return buf[0], buf[1]
    if code == ATAN2:
        _f_atan2(xl, xh, yl, yh, buf[0:1], buf[1:2])
        return buf[0], buf[1]
    if code == EXP:
        return _f_exp(xl, xh, math.exp(xl), math.exp(xh))
    if code == LOG:
        return _f_log(xl, xh, math.log(xl), math.log(xh))
    if code == SINH:
        return _f_sinh(xl, xh, math.sinh(xl), math.sinh(xh))
    if code == COSH:
        return _f_cosh(xl, xh, math.cosh(xl), math.cosh(xh))
    if code == TANH:
        return _f_tanh(xl, xh, math.tanh(xl), math.tanh(xh))
    if code == ATAN:
        return _f_atan(xl, xh, math.atan(xl), math.atan(xh))
    return -INF, INF


@nb.njit(cache=True, error_model="numpy")
def _image_trig(code, xl, xh, buf):
    """Forward image of a trigonometric node (sin, cos, tan, asin, acos)."""
    if code == SIN:
        _f_sin(xl, xh, buf[0:1], buf[1:2])
        return buf[0], buf[1]
    if code == COS:
        _f_cos(xl, xh, buf[0:1], buf[1:2])
        return buf[0], buf[1]
    if code == TAN:
        return _f_tan(xl, xh, math.tan(xl), math.tan(xh))
    if code == ASIN:
        return _f_asin(xl, xh, math.asin(xl), math.asin(xh))
    if code == ACOS:  # asin is only used where |x| <= 1/2
        return _f_acos(xl, xh, math.acos(xl), math.acos(xh),
                       math.asin(xl) if abs(xl) <= 0.5 else 0.0,
                       math.asin(xh) if abs(xh) <= 0.5 else 0.0)
    return -INF, INF


@nb.njit(cache=True, error_model="numpy")
def image(code, xl, xh, yl, yh, p, buf, piecewise, pown, explog, trig):
    """Forward image ``f(x, y)`` of node ``z = f(x, y)`` rounded outward, as ``(lo, hi)``
    (NaN bounds: empty; the entire line for a node of a family left out, see :func:`revise`)."""
    if code == ADD:
        return _add_lo(xl, xh, yl, yh), _add_hi(xl, xh, yl, yh)
    if code == MUL:
        return _mul_lo(xl, xh, yl, yh), _mul_hi(xl, xh, yl, yh)
    if code == SUB:
        return _sub_lo(xl, xh, yl, yh), _sub_hi(xl, xh, yl, yh)
    if code == DIV:
        return _div_lo(xl, xh, yl, yh), _div_hi(xl, xh, yl, yh)
    if code == SQR:
        return _sqr_lo(xl, xh), _sqr_hi(xl, xh)
    if code == SQRT:
        return _sqrt_lo(xl, xh), _sqrt_hi(xl, xh)
    if code == NEG:
        return -xh, -xl
    if pown is not None and code == POWN:
        _f_pown(xl, xh, _pown_n(p), buf[0:1], buf[1:2])
        return buf[0], buf[1]
    if piecewise is not None and code in (ABS, SIGN, FLOOR, CEIL, MIN, MAX):
        if code == MIN:
            return al._min_all(xl, xh, yl, yh)
        if code == MAX:
            return al._max_all(xl, xh, yl, yh)
        if code == ABS:
            return al._abs_all(xl, xh)
        if code == SIGN:
            return al._sign_all(xl, xh)
        if code == FLOOR:
            return al._floor_all(xl, xh)
        return al._ceil_all(xl, xh)
    if explog is not None and code in (EXP, LOG, SINH, COSH, TANH, ATAN, ATAN2, POW):
        return _image_explog(code, xl, xh, yl, yh, buf)
    if trig is not None and code in (SIN, COS, TAN, ASIN, ACOS):
        return _image_trig(code, xl, xh, buf)
    return -INF, INF


@nb.njit(cache=True, error_model="numpy")
def _back_explog(code, zl, zh, xl, xh, yl, yh, buf):
    """The reverse step of an exponential-family node (the forward image already in ``z``)."""
    o0, o1, o2, o3 = buf[0:1], buf[1:2], buf[2:3], buf[3:4]
    if code == POW:
        _b_pow(zl, zh, xl, xh, yl, yh, o0, o1, o2, o3)
        return buf[0], buf[1], buf[2], buf[3]
    if code == ATAN2:
        _b_atan2(zl, zh, xl, xh, yl, yh, o0, o1, o2, o3)
        return buf[0], buf[1], buf[2], buf[3]
    if code == EXP:
        _b_exp(zl, zh, xl, xh, o0, o1)
    elif code == LOG:
        _b_log(zl, zh, xl, xh, o0, o1)
    elif code == SINH:
        _b_sinh(zl, zh, xl, xh, o0, o1)
    elif code == COSH:
        _b_cosh(zl, zh, xl, xh, o0, o1)
    elif code == TANH:
        _b_tanh(zl, zh, xl, xh, o0, o1)
    else:  # ATAN
        _b_atan(zl, zh, xl, xh, o0, o1)
    return buf[0], buf[1], yl, yh


@nb.njit(cache=True, error_model="numpy")
def _back_trig(code, zl, zh, xl, xh, buf):
    """The reverse step of a trigonometric node."""
    o0, o1 = buf[0:1], buf[1:2]
    if code == SIN:
        _b_sin(zl, zh, xl, xh, o0, o1)
    elif code == COS:
        _b_cos(zl, zh, xl, xh, o0, o1)
    elif code == TAN:
        _b_tan(zl, zh, xl, xh, o0, o1)
    elif code == ASIN:
        _b_asin(zl, zh, xl, xh, o0, o1)
    else:  # ACOS
        _b_acos(zl, zh, xl, xh, o0, o1)
    return buf[0], buf[1]


@nb.njit(cache=True, error_model="numpy")
def _back_piecewise(code, zl, zh, xl, xh, yl, yh):
    """The reverse step of a piecewise node (abs, sign, floor, ceil, min, max)."""
    if code == MIN:
        return al._min_rev_all(zl, zh, xl, xh, yl, yh)
    if code == MAX:
        return al._max_rev_all(zl, zh, xl, xh, yl, yh)
    if code == ABS:
        xl, xh = al._abs_rev_all(zl, zh, xl, xh)
    elif code == SIGN:
        xl, xh = al._sign_rev_all(zl, zh, xl, xh)
    elif code == FLOOR:
        xl, xh = al._floor_rev_all(zl, zh, xl, xh)
    else:  # CEIL
        xl, xh = al._ceil_rev_all(zl, zh, xl, xh)
    return xl, xh, yl, yh


@nb.njit(cache=True, error_model="numpy")
def back(code, zl, zh, xl, xh, yl, yh, p, buf, piecewise, pown, explog, trig):
    """The reverse step of node ``z = f(x, y)``: ``(x, y) ∩= f_rev(z, x, y)``, for a ``z``
    already within the forward image. Returns ``(xl, xh, yl, yh)`` (NaN bounds: empty); a node
    of a family left out (see :func:`revise`) contracts nothing."""
    if code == ADD:
        return al._add_rev_all(zl, zh, xl, xh, yl, yh)
    if code == MUL:
        return al._mul_rev_all(zl, zh, xl, xh, yl, yh)
    if code == SUB:
        return al._sub_rev_all(zl, zh, xl, xh, yl, yh)
    if code == DIV:
        return al._div_rev_all(zl, zh, xl, xh, yl, yh)
    if code == SQR:
        xl, xh = al._sqr_rev_all(zl, zh, xl, xh)
    elif code == SQRT:
        xl, xh = al._sqrt_rev_all(zl, zh, xl, xh)
    elif code == NEG:
        xl, xh = al._neg_rev_all(zl, zh, xl, xh)
    elif pown is not None and code == POWN:
        _b_pown(zl, zh, xl, xh, _pown_n(p), buf[0:1], buf[1:2])
        xl, xh = buf[0], buf[1]
    elif piecewise is not None and code in (ABS, SIGN, FLOOR, CEIL, MIN, MAX):
        return _back_piecewise(code, zl, zh, xl, xh, yl, yh)
    elif explog is not None and code in (EXP, LOG, SINH, COSH, TANH, ATAN, ATAN2, POW):
        return _back_explog(code, zl, zh, xl, xh, yl, yh, buf)
    elif trig is not None and code in (SIN, COS, TAN, ASIN, ACOS):
        xl, xh = _back_trig(code, zl, zh, xl, xh, buf)
    return xl, xh, yl, yh


@nb.njit(cache=True, error_model="numpy")
def revise(code, zl, zh, xl, xh, yl, yh, p, buf, piecewise, pown, explog, trig):
    """HC4-revise of node ``z = f(x, y)``: ``z ∩= f(x, y)`` (:func:`image`), then
    ``(x, y) = f_rev(z, x, y)`` (:func:`back`).

    Returns the new ``(zl, zh, xl, xh, yl, yh)``. The basic arithmetic is inline; each other
    family is one kernel, compiled in only when its argument (``piecewise``, ``pown``,
    ``explog``, ``trig``) is not ``None`` (Numba prunes ``x is not None`` on a ``None``
    argument before typing). A node of a family left out is not contracted, which is sound.
    """
    nl, nh = image(code, xl, xh, yl, yh, p, buf, piecewise, pown, explog, trig)
    zl, zh = _cap(zl, zh, nl, nh)
    xl, xh, yl, yh = back(code, zl, zh, xl, xh, yl, yh, p, buf, piecewise, pown, explog, trig)
    return zl, zh, xl, xh, yl, yh


@nb.njit(cache=True, error_model="numpy")
def hc4_pass(op, out, a, b, param, lo, hi, buf, piecewise, pown, explog, trig):
    """Revise nodes ``0..n-1`` then ``n-1..0`` of a tape on the slots ``lo``/``hi`` (in place;
    the family flags as in :func:`revise`).

    Each revision intersects the node's three slots with their contracted domains, so every
    slot only shrinks and holds every solution it held. Returns False as soon as a slot becomes
    empty (the slots are then partly updated: the box has no solution), True otherwise.
    """
    # the direction as an int64 value, not a bool literal: Numba would compile revise_nodes
    # once per literal (test_compile_once)
    return (revise_nodes(op, out, a, b, param, lo, hi, buf, np.int64(0), piecewise, pown,
                         explog, trig)
            and revise_nodes(op, out, a, b, param, lo, hi, buf, np.int64(1), piecewise, pown,
                             explog, trig))


@nb.njit(cache=True, error_model="numpy")
def revise_nodes(op, out, a, b, param, lo, hi, buf, backward, piecewise, pown, explog, trig):
    """Revise every node of a tape once, in tape order (last to first when the int64
    ``backward`` is nonzero: the backward half of :func:`hc4_pass`, which is all a pass needs
    when the slots already hold the forward images); returns False as soon as a slot becomes
    empty."""
    n = op.size
    for step in range(n):
        i = n - 1 - step if backward else step
        o, ia, ib = out[i], a[i], b[i]
        yl, yh = (lo[ib], hi[ib]) if ib >= 0 else (0.0, 0.0)
        zl, zh, xl, xh, yl, yh = revise(op[i], lo[o], hi[o], lo[ia], hi[ia], yl, yh, param[i],
                                        buf, piecewise, pown, explog, trig)
        if not (_meet(lo, hi, o, zl, zh) and _meet(lo, hi, ia, xl, xh)):
            return False
        if ib >= 0 and not _meet(lo, hi, ib, yl, yh):
            return False
    return True


@nb.njit(cache=True, inline="always", error_model="numpy")
def _meet(lo, hi, s, nl, nh):
    """``slot s ∩= [nl, nh]``; False when the result is empty (NaN bounds are empty)."""
    nl = max(nl, lo[s]) if nl == nl else nl
    nh = min(nh, hi[s]) if nh == nh else nh
    lo[s], hi[s] = nl, nh
    return nl <= nh
