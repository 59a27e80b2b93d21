"""The compiled propagation kernel: AC3-style revisions of the primitive nodes of a tape.

Each node ``z = f(x, y)`` is revised by ``z ∩= f(x, y)`` then ``(x, y) = f_rev(z, x, y)``. When a
slot's domain shrinks by more than ``rel_eps`` of its width (or loses an infinite bound), every
other node using that slot becomes dirty again. Dirty nodes are revised window by window along
the tape order (the order of the constraints, i.e. of the time steps for a time series), in
alternating forward and backward passes, so that the work per time step does not grow with the
horizon.
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

__all__ = ["DONE", "EMPTY", "RUNNING", "propagate_kernel"]

DONE, RUNNING, EMPTY = 0, 1, 2
#: A window that has not settled after this many local sweeps hands its remaining dirty nodes
#: to the next pass (a safeguard against slowly converging cycles; it never loses soundness).
_LOCAL_SWEEPS = 64
_C = {name: i for i, name in enumerate(OPS)}
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
def _revise(code, zl, zh, xl, xh, yl, yh, p, buf, piecewise, pown, explog, trig):
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


@nb.njit(cache=True, inline="always", error_model="numpy")
def _significant(ol, oh, nl, nh, rel_eps):
    """Whether ``[ol, oh] -> [nl, nh]`` is a shrink worth propagating."""
    if nl == ol and nh == oh:
        return False
    w0 = oh - ol
    if w0 == np.inf:
        return True  # a bound became finite or moved: cheap to propagate, often decisive
    return (w0 - (nh - nl)) > rel_eps * w0


@nb.njit(cache=True, error_model="numpy")
def _update(s, nl, nh, lo, hi, rel_eps):
    """Intersect slot ``s`` with ``[nl, nh]``: -1 empty, 1 significant shrink, 0 otherwise."""
    ol, oh = lo[s], hi[s]
    nl = max(nl, ol) if nl == nl else nl  # NaN (empty) must survive the max
    nh = min(nh, oh) if nh == nh else nh
    if nl != nl or nh != nh or nl > nh:
        lo[s] = np.nan
        hi[s] = np.nan
        return -1
    sig = _significant(ol, oh, nl, nh, rel_eps)
    lo[s] = nl
    hi[s] = nh
    return 1 if sig else 0


@nb.njit(cache=True, inline="always", error_model="numpy")
def _revise_node(i, op, out, a, b, param, lo, hi, ptr, adj, dirty, pending, window, rel_eps,
                 buf, changed, piecewise, pown, explog, trig):
    """Revise node ``i`` and mark the nodes whose slots it shrank significantly. Returns the
    number of nodes newly marked dirty, or -1 when a domain became empty."""
    o, ia, ib = out[i], a[i], b[i]
    # the node itself is revised again only when it reads what it writes
    again = (o == ia) | (o == ib) | (ia == ib)
    xl, xh = lo[ia], hi[ia]
    yl, yh = (lo[ib], hi[ib]) if ib >= 0 else (0.0, 0.0)
    zl, zh, xl, xh, yl, yh = _revise(op[i], lo[o], hi[o], xl, xh, yl, yh, param[i], buf,
                                       piecewise, pown, explog, trig)
    # when o aliases an argument, each update is still a sound intersection
    nch = 0
    r = _update(o, zl, zh, lo, hi, rel_eps)
    if r < 0:
        return -1
    if r > 0:
        changed[nch] = o
        nch += 1
    r = _update(ia, xl, xh, lo, hi, rel_eps)
    if r < 0:
        return -1
    if r > 0:
        changed[nch] = ia
        nch += 1
    if ib >= 0:
        r = _update(ib, yl, yh, lo, hi, rel_eps)
        if r < 0:
            return -1
        if r > 0:
            changed[nch] = ib
            nch += 1
    added = 0
    for c in range(nch):
        s = changed[c]
        for k in range(ptr[s], ptr[s + 1]):
            j = adj[k]
            if (j != i or again) and not dirty[j]:
                dirty[j] = True
                pending[j // window] += 1
                added += 1
    return added


@nb.njit(cache=True, error_model="numpy")
def propagate_kernel(op, out, a, b, param, lo, hi, ptr, adj, dirty, state, rel_eps, max_evals,
                     window, piecewise=None, pown=None, explog=None, trig=None):
    """Revise dirty nodes window by window, for at most about ``max_evals`` node revisions.

    The tape is cut into windows of ``window`` consecutive nodes. A pass visits the windows in
    tape order (or in reverse order: passes alternate) and brings each window to its local fixed
    point by alternating sweeps over its nodes before moving on (block Gauss-Seidel). Along a
    time series one pass carries information through the whole horizon, where a FIFO queue
    moves it by one step per wave, and a window settles before it passes its change on, so its
    neighbours are revised once for a burst of small changes rather than once per change.
    ``state = [window index in the pass, dirty count, status, evals_total, direction]`` is read
    and written so that a long run can be continued in chunks (progress reports); a call that
    reaches ``max_evals`` inside a window leaves the rest of that window to the next pass.
    ``ptr``/``adj`` list, for each slot, the nodes using it (CSR). Returns the status (DONE,
    RUNNING or EMPTY).
    """
    n = op.size
    nw = (n + window - 1) // window
    pending = np.zeros(nw, dtype=np.int64)
    for i in range(n):
        if dirty[i]:
            pending[i // window] += 1
    wpos, count, evals, direction = state[0], state[1], 0, state[4]
    buf = np.empty(4)
    changed = np.empty(3, dtype=np.int64)
    status = RUNNING
    while count > 0 and evals < max_evals and status == RUNNING:
        if wpos >= nw:  # end of a pass: turn round
            wpos = 0
            direction = -direction
        w = wpos if direction > 0 else nw - 1 - wpos
        wpos += 1
        first, last = w * window, min((w + 1) * window, n)
        d = direction
        sweeps = 0
        while pending[w] > 0 and sweeps < _LOCAL_SWEEPS and evals < max_evals:
            sweeps += 1
            i = first if d > 0 else last - 1
            while first <= i < last and evals < max_evals:
                if dirty[i]:
                    dirty[i] = False
                    pending[w] -= 1
                    count -= 1
                    evals += 1
                    r = _revise_node(i, op, out, a, b, param, lo, hi, ptr, adj, dirty, pending,
                                     window, rel_eps, buf, changed, piecewise, pown,
                                     explog, trig)
                    if r < 0:
                        status = EMPTY
                        break
                    count += r
                i += d
            if status == EMPTY:
                break
            d = -d
    if status != EMPTY and count == 0:
        status = DONE
    state[0], state[1], state[2], state[3], state[4] = wpos, count, status, state[3] + evals, \
        direction
    return status
