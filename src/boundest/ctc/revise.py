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

__all__ = ["FAMILIES", "OP_CODES", "family_flags", "hc4_pass", "revise", "revise_nodes"]

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
_f_pown, _b_pown = al._pown.scalar, al._pown_rev.scalar
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
def _revise_piecewise(code, zl, zh, xl, xh, yl, yh):
    """HC4-revise of the piecewise nodes (abs, sign, floor, ceil, min, max)."""
    if code == MIN:
        nl, nh = al._min_all(xl, xh, yl, yh)
        zl, zh = _cap(zl, zh, nl, nh)
        xl, xh, yl, yh = al._min_rev_all(zl, zh, xl, xh, yl, yh)
    elif code == MAX:
        nl, nh = al._max_all(xl, xh, yl, yh)
        zl, zh = _cap(zl, zh, nl, nh)
        xl, xh, yl, yh = al._max_rev_all(zl, zh, xl, xh, yl, yh)
    elif code == ABS:
        nl, nh = al._abs_all(xl, xh)
        zl, zh = _cap(zl, zh, nl, nh)
        xl, xh = al._abs_rev_all(zl, zh, xl, xh)
    elif code == SIGN:
        nl, nh = al._sign_all(xl, xh)
        zl, zh = _cap(zl, zh, nl, nh)
        xl, xh = al._sign_rev_all(zl, zh, xl, xh)
    elif code == FLOOR:
        nl, nh = al._floor_all(xl, xh)
        zl, zh = _cap(zl, zh, nl, nh)
        xl, xh = al._floor_rev_all(zl, zh, xl, xh)
    elif code == CEIL:
        nl, nh = al._ceil_all(xl, xh)
        zl, zh = _cap(zl, zh, nl, nh)
        xl, xh = al._ceil_rev_all(zl, zh, xl, xh)
    return zl, zh, xl, xh, yl, yh


@nb.njit(cache=True, error_model="numpy")
def _revise_pown(zl, zh, xl, xh, p, buf):
    """HC4-revise of a ``pown`` node (integer exponent ``p``)."""
    o0, o1 = buf[0:1], buf[1:2]
    _f_pown(xl, xh, np.int64(p), o0, o1)
    zl, zh = _cap(zl, zh, buf[0], buf[1])
    _b_pown(zl, zh, xl, xh, np.int64(p), o0, o1)
    return zl, zh, buf[0], buf[1]


@nb.njit(cache=True, error_model="numpy")
def _revise_explog(code, zl, zh, xl, xh, yl, yh, buf):
    """HC4-revise of the exponential family (exp, log, sinh, cosh, tanh, atan, atan2, and the
    real power ``pow(x, y) = exp(y log x)``)."""
    o0, o1, o2, o3 = buf[0:1], buf[1:2], buf[2:3], buf[3:4]
    if code == POW:
        _f_pow(xl, xh, yl, yh, o0, o1)
        zl, zh = _cap(zl, zh, buf[0], buf[1])
        _b_pow(zl, zh, xl, xh, yl, yh, o0, o1, o2, o3)
        return zl, zh, buf[0], buf[1], buf[2], buf[3]
    if code == ATAN2:
        _f_atan2(xl, xh, yl, yh, o0, o1)
        zl, zh = _cap(zl, zh, buf[0], buf[1])
        _b_atan2(zl, zh, xl, xh, yl, yh, o0, o1, o2, o3)
        return zl, zh, buf[0], buf[1], buf[2], buf[3]
    if code == EXP:
        nl, nh = _f_exp(xl, xh, math.exp(xl), math.exp(xh))
    elif code == LOG:
        nl, nh = _f_log(xl, xh, math.log(xl), math.log(xh))
    elif code == SINH:
        nl, nh = _f_sinh(xl, xh, math.sinh(xl), math.sinh(xh))
    elif code == COSH:
        nl, nh = _f_cosh(xl, xh, math.cosh(xl), math.cosh(xh))
    elif code == TANH:
        nl, nh = _f_tanh(xl, xh, math.tanh(xl), math.tanh(xh))
    elif code == ATAN:
        nl, nh = _f_atan(xl, xh, math.atan(xl), math.atan(xh))
    else:
        return zl, zh, xl, xh, yl, yh
    zl, zh = _cap(zl, zh, nl, nh)
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
    return zl, zh, buf[0], buf[1], yl, yh


@nb.njit(cache=True, error_model="numpy")
def _revise_trig(code, zl, zh, xl, xh, yl, yh, buf):
    """HC4-revise of the trigonometric family (sin, cos, tan, asin, acos)."""
    o0, o1 = buf[0:1], buf[1:2]
    if code == SIN:
        _f_sin(xl, xh, o0, o1)
    elif code == COS:
        _f_cos(xl, xh, o0, o1)
    elif code == TAN:
        buf[0], buf[1] = _f_tan(xl, xh, math.tan(xl), math.tan(xh))
    elif code == ASIN:
        buf[0], buf[1] = _f_asin(xl, xh, math.asin(xl), math.asin(xh))
    elif code == ACOS:  # asin is only used where |x| <= 1/2
        buf[0], buf[1] = _f_acos(xl, xh, math.acos(xl), math.acos(xh),
                                 math.asin(xl) if abs(xl) <= 0.5 else 0.0,
                                 math.asin(xh) if abs(xh) <= 0.5 else 0.0)
    else:
        return zl, zh, xl, xh, yl, yh
    zl, zh = _cap(zl, zh, buf[0], buf[1])
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
    return zl, zh, buf[0], buf[1], yl, yh


@nb.njit(cache=True, error_model="numpy")
def revise(code, zl, zh, xl, xh, yl, yh, p, buf, piecewise, pown, explog, trig):
    """HC4-revise of node ``z = f(x, y)``: ``z ∩= f(x, y)``, then ``(x, y) = f_rev(z, x, y)``.

    Returns the new ``(zl, zh, xl, xh, yl, yh)``. The basic arithmetic is inline; each other
    family is one kernel, compiled in only when its argument (``piecewise``, ``pown``,
    ``explog``, ``trig``) is not ``None`` (Numba prunes ``x is not None`` on a ``None``
    argument before typing). A node of a family left out is not contracted, which is sound.
    """
    if code == ADD:
        zl, zh = _cap(zl, zh, _add_lo(xl, xh, yl, yh), _add_hi(xl, xh, yl, yh))
        xl, xh, yl, yh = al._add_rev_all(zl, zh, xl, xh, yl, yh)
    elif code == MUL:
        zl, zh = _cap(zl, zh, _mul_lo(xl, xh, yl, yh), _mul_hi(xl, xh, yl, yh))
        xl, xh, yl, yh = al._mul_rev_all(zl, zh, xl, xh, yl, yh)
    elif code == SUB:
        zl, zh = _cap(zl, zh, _sub_lo(xl, xh, yl, yh), _sub_hi(xl, xh, yl, yh))
        xl, xh, yl, yh = al._sub_rev_all(zl, zh, xl, xh, yl, yh)
    elif code == DIV:
        zl, zh = _cap(zl, zh, _div_lo(xl, xh, yl, yh), _div_hi(xl, xh, yl, yh))
        xl, xh, yl, yh = al._div_rev_all(zl, zh, xl, xh, yl, yh)
    elif code == SQR:
        zl, zh = _cap(zl, zh, _sqr_lo(xl, xh), _sqr_hi(xl, xh))
        xl, xh = al._sqr_rev_all(zl, zh, xl, xh)
    elif code == SQRT:
        zl, zh = _cap(zl, zh, _sqrt_lo(xl, xh), _sqrt_hi(xl, xh))
        xl, xh = al._sqrt_rev_all(zl, zh, xl, xh)
    elif code == NEG:
        zl, zh = _cap(zl, zh, -xh, -xl)
        xl, xh = al._neg_rev_all(zl, zh, xl, xh)
    else:
        if pown is not None and code == POWN:
            zl, zh, xl, xh = _revise_pown(zl, zh, xl, xh, p, buf)
            return zl, zh, xl, xh, yl, yh
        if piecewise is not None and code in (ABS, SIGN, FLOOR, CEIL, MIN, MAX):
            return _revise_piecewise(code, zl, zh, xl, xh, yl, yh)
        if explog is not None and code in (EXP, LOG, SINH, COSH, TANH, ATAN, ATAN2, POW):
            return _revise_explog(code, zl, zh, xl, xh, yl, yh, buf)
        if trig is not None:
            return _revise_trig(code, zl, zh, xl, xh, yl, yh, buf)
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
