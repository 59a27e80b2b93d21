"""Interval derivatives of function tapes: Jacobians over boxes, centered (mean-value) forms.

The kernel runs a :class:`~boundest.expr.function_tape.FunctionTape` forward over a box (the
natural interval extension, with the same per-node images as the propagation engine) and then,
for each output, backward through the output's own nodes (reverse-mode automatic
differentiation), accumulating interval adjoints with outward rounding. Each node contributes
its *local slope enclosures*: for ``z = f(x, y)`` intervals ``S_x, S_y`` with
``f(x', y') - f(x, y) in S_x (x' - x) + S_y (y' - y)`` for every two points of the argument box
where ``f`` is defined. For a differentiable primitive that is the range of its partial
derivatives over the box (mean value theorem; the domains of the primitives are intervals, so
two points of the domain have every point between them in it); for the non-smooth ones it is
the range of their generalized derivatives: ``abs`` gives ``[-1, 1]`` across 0, ``min``/``max``
give ``[0, 1]`` where the arguments can tie; a jump inside the box (``sign`` across 0,
``floor``/``ceil`` across an integer, ``tan`` across a pole, ``atan2`` across its branch cut or
around the origin, ``x / y`` or a negative integer power across a pole) makes the slope the
entire line. The chain rule over slopes then gives, for every ``x, c`` in the box,
``f(x) - f(c) in J (x - c)`` with ``J`` the computed Jacobian: the centered form
``f(X) in f(c) + J (X - c)`` (Moore; Neumaier 1990, section 2.3) holds without any smoothness
assumption beyond the primitives'.

Reverse mode costs one backward sweep per output over that output's nodes only, so the cost of a
Jacobian is that of evaluating the tape a few times, whatever the number of variables, and a
chain of local constraints costs the same per constraint however long it is.
"""

from __future__ import annotations

import math
from typing import Any

import numba as nb
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..expr.function_tape import FunctionTape, as_function_tape
from ..interval import Interval, as_interval
from ..interval import algebraic as al
from ..interval import arith as ar
from ..interval import explog as el
from ..interval import trig as tr
from .revise import (
    ABS,
    ACOS,
    ADD,
    ASIN,
    ATAN,
    ATAN2,
    CEIL,
    COS,
    COSH,
    DIV,
    EXP,
    FLOOR,
    LOG,
    MAX,
    MIN,
    MUL,
    NEG,
    POW,
    POWN,
    SIGN,
    SIN,
    SINH,
    SQR,
    SQRT,
    SUB,
    TAN,
    TANH,
    family_flags,
    image,
)

__all__ = ["centered", "evaluate", "forward_jacobian", "jacobian", "jacobian_sparse"]

INF = math.inf
_add_lo, _add_hi, _sub_lo, _sub_hi = (ar._add_lo.scalar, ar._add_hi.scalar, ar._sub_lo.scalar,
                                      ar._sub_hi.scalar)
_mul_lo, _mul_hi, _div_lo, _div_hi = (ar._mul_lo.scalar, ar._mul_hi.scalar, ar._div_lo.scalar,
                                      ar._div_hi.scalar)
_sqr_lo, _sqr_hi, _sqrt_lo, _sqrt_hi = (ar._sqr_lo.scalar, ar._sqr_hi.scalar,
                                        ar._sqrt_lo.scalar, ar._sqrt_hi.scalar)
_f_cosh, _f_sinh, _f_log = el._cosh.bounds, el._sinh.bounds, el._log.bounds
_f_pow, _f_sin, _f_cos, _f_pown = el._pow.scalar, tr._sin.scalar, tr._cos.scalar, al._pown.scalar
_njit = nb.njit(cache=True, error_model="numpy")


@nb.njit(cache=True, inline="always", error_model="numpy")
def _mul(al_, ah, bl, bh):
    return _mul_lo(al_, ah, bl, bh), _mul_hi(al_, ah, bl, bh)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _div(al_, ah, bl, bh):
    return _div_lo(al_, ah, bl, bh), _div_hi(al_, ah, bl, bh)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _one_minus_sqr(xl, xh):
    """``1 - x**2``, rounded outward."""
    sl, sh = _sqr_lo(xl, xh), _sqr_hi(xl, xh)
    return _sub_lo(1.0, 1.0, sl, sh), _sub_hi(1.0, 1.0, sl, sh)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _one_plus_sqr(xl, xh):
    sl, sh = _sqr_lo(xl, xh), _sqr_hi(xl, xh)
    return _add_lo(1.0, 1.0, sl, sh), _add_hi(1.0, 1.0, sl, sh)


@_njit
def _slopes_other(code, zl, zh, xl, xh, yl, yh, p, buf):
    """Slope enclosures of the elementary functions (see :func:`slopes`)."""
    o0, o1 = buf[0:1], buf[1:2]
    if code == EXP:
        return zl, zh, 0.0, 0.0
    if code == LOG:  # 1/x over the part x > 0 of the domain
        dl, dh = _div(1.0, 1.0, max(xl, 0.0), xh)
        return dl, dh, 0.0, 0.0
    if code == SIN:
        _f_cos(xl, xh, o0, o1)
        return buf[0], buf[1], 0.0, 0.0
    if code == COS:
        _f_sin(xl, xh, o0, o1)
        return -buf[1], -buf[0], 0.0, 0.0
    if code == TAN:  # 1 + tan^2, unless the box meets a pole (then tan's image is unbounded)
        if zl == -INF or zh == INF:
            return -INF, INF, 0.0, 0.0
        dl, dh = _one_plus_sqr(zl, zh)
        return dl, dh, 0.0, 0.0
    if code in (ASIN, ACOS):  # +-1/sqrt(1 - x^2) over x in [-1, 1]
        dl, dh = _one_minus_sqr(max(xl, -1.0), min(xh, 1.0))
        dl, dh = _div(1.0, 1.0, _sqrt_lo(dl, dh), _sqrt_hi(dl, dh))
        return (dl, dh, 0.0, 0.0) if code == ASIN else (-dh, -dl, 0.0, 0.0)
    if code == ATAN:
        dl, dh = _one_plus_sqr(xl, xh)
        dl, dh = _div(1.0, 1.0, dl, dh)
        return dl, dh, 0.0, 0.0
    if code == SINH:
        dl, dh = _f_cosh(xl, xh, math.cosh(xl), math.cosh(xh))
        return dl, dh, 0.0, 0.0
    if code == COSH:
        dl, dh = _f_sinh(xl, xh, math.sinh(xl), math.sinh(xh))
        return dl, dh, 0.0, 0.0
    if code == TANH:
        dl, dh = _one_minus_sqr(zl, zh)
        return dl, dh, 0.0, 0.0
    if code == POWN:  # p x**(p - 1): p exact (a float64), x**(p - 1) by the int64 exponent
        n = al._tape_exponent(p)
        if n == 0:
            return 0.0, 0.0, 0.0, 0.0
        if n == 1:
            return 1.0, 1.0, 0.0, 0.0
        if n < 0 and xl < 0.0 < xh:  # the pole at 0 inside the box
            return -INF, INF, 0.0, 0.0
        _f_pown(xl, xh, n - 1, o0, o1)
        dl, dh = _mul(p, p, buf[0], buf[1])
        return dl, dh, 0.0, 0.0
    if code == POW:  # x**y: y x**(y-1) and log(x) x**y, over x > 0 only
        if xl <= 0.0:
            return -INF, INF, -INF, INF
        _f_pow(xl, xh, _sub_lo(yl, yh, 1.0, 1.0), _sub_hi(yl, yh, 1.0, 1.0), o0, o1)
        sal, sah = _mul(yl, yh, buf[0], buf[1])
        ll, lh = _f_log(xl, xh, math.log(xl), math.log(xh))
        sbl, sbh = _mul(ll, lh, zl, zh)
        return sal, sah, sbl, sbh
    if code == ATAN2:  # atan2(y, x): y = a is (xl, xh) here, x = b is (yl, yh)
        # d/dy = x / (x^2 + y^2), d/dx = -y / (x^2 + y^2); entire around the origin (no
        # angle) or across the branch cut (x < 0, y = 0 from below)
        if (xl <= 0.0 <= xh and yl <= 0.0 <= yh) or (yl < 0.0 and xl < 0.0 <= xh):
            return -INF, INF, -INF, INF
        rl = _add_lo(_sqr_lo(yl, yh), _sqr_hi(yl, yh), _sqr_lo(xl, xh), _sqr_hi(xl, xh))
        rh = _add_hi(_sqr_lo(yl, yh), _sqr_hi(yl, yh), _sqr_lo(xl, xh), _sqr_hi(xl, xh))
        sal, sah = _div(yl, yh, rl, rh)
        sbl, sbh = _div(-xh, -xl, rl, rh)
        return sal, sah, sbl, sbh
    return -INF, INF, -INF, INF


@_njit
def _slopes_piecewise(code, xl, xh, yl, yh):
    """Generalized-derivative enclosures of abs, sign, floor, ceil, min, max."""
    if code == ABS:
        if xl >= 0.0:
            return 1.0, 1.0, 0.0, 0.0
        if xh <= 0.0:
            return -1.0, -1.0, 0.0, 0.0
        return -1.0, 1.0, 0.0, 0.0
    if code == SIGN:
        constant = xl > 0.0 or xh < 0.0 or xl == xh
    elif code == FLOOR:
        constant = np.floor(xl) == np.floor(xh)
    elif code == CEIL:
        constant = np.ceil(xl) == np.ceil(xh)
    elif code == MIN:
        if xh <= yl:
            return 1.0, 1.0, 0.0, 0.0
        if yh <= xl:
            return 0.0, 0.0, 1.0, 1.0
        return 0.0, 1.0, 0.0, 1.0
    else:  # MAX
        if xh <= yl:
            return 0.0, 0.0, 1.0, 1.0
        if yh <= xl:
            return 1.0, 1.0, 0.0, 0.0
        return 0.0, 1.0, 0.0, 1.0
    return (0.0, 0.0, 0.0, 0.0) if constant else (-INF, INF, 0.0, 0.0)


@_njit
def slopes(code, zl, zh, xl, xh, yl, yh, p, buf):
    """Slope enclosures ``(S_x, S_y)`` of node ``z = f(x, y)`` over the argument box.

    ``z`` is the node's forward image. Returns ``(sxl, sxh, syl, syh)`` (``S_y = [0, 0]`` for a
    unary node); an enclosure that comes out empty (the node is nowhere defined on the box) is
    returned as the entire line, which is always sound.
    """
    if code == ADD:
        r = (1.0, 1.0, 1.0, 1.0)
    elif code == SUB:
        r = (1.0, 1.0, -1.0, -1.0)
    elif code == NEG:
        r = (-1.0, -1.0, 0.0, 0.0)
    elif code == MUL:
        r = (yl, yh, xl, xh)
    elif code == DIV:  # 1/y and -x/y^2 = -(x/y)/y
        sal, sah = _div(1.0, 1.0, yl, yh)
        sbl, sbh = _div(zl, zh, yl, yh)
        r = (sal, sah, -sbh, -sbl)
    elif code == SQR:
        r = (2.0 * xl, 2.0 * xh, 0.0, 0.0)
    elif code == SQRT:  # 1 / (2 sqrt(x))
        dl, dh = _div(0.5, 0.5, zl, zh)
        r = (dl, dh, 0.0, 0.0)
    elif code in (ABS, SIGN, FLOOR, CEIL, MIN, MAX):
        r = _slopes_piecewise(code, xl, xh, yl, yh)
    else:
        r = _slopes_other(code, zl, zh, xl, xh, yl, yh, p, buf)
    sxl, sxh, syl, syh = r
    if not sxl <= sxh:
        sxl, sxh = -INF, INF
    if not syl <= syh:
        syl, syh = -INF, INF
    return sxl, sxh, syl, syh


@_njit
def defined(code, zl, zh, xl, xh, yl, yh, p):
    """Whether node ``z = f(x, y)`` is defined and continuous on the whole argument box
    (``x`` within the domain of ``sqrt``, ``log``, ``asin``..., no pole, jump or branch cut
    inside): what a proof of existence (Brouwer's theorem) needs of every node."""
    if not zl <= zh:
        return False
    if code == SQRT:
        return xl >= 0.0
    if code == LOG:
        return xl > 0.0
    if code in (ASIN, ACOS):
        return xl >= -1.0 and xh <= 1.0
    if code == DIV:
        return not yl <= 0.0 <= yh
    if code == POWN:
        return p >= 0.0 or not xl <= 0.0 <= xh
    if code == POW:
        return xl > 0.0 or (xl >= 0.0 and yl > 0.0)
    if code == ATAN2:  # atan2(y, x) with y = a (xl, xh), x = b (yl, yh)
        return not ((xl <= 0.0 <= xh and yl <= 0.0 <= yh) or (yl < 0.0 and xl < 0.0 <= xh))
    if code == TAN:
        return zl > -INF and zh < INF
    if code == SIGN:
        return xl > 0.0 or xh < 0.0 or xl == xh
    if code == FLOOR:
        return np.floor(xl) == np.floor(xh)
    if code == CEIL:
        return np.ceil(xl) == np.ceil(xh)
    return True


@_njit
def forward_pass(op, out, a, b, param, lo, hi, buf, piecewise, pown, explog, trig):
    """Forward images of the nodes of a function tape on one box's slots (in place)."""
    for i in range(op.size):
        ib = b[i]
        yl, yh = (lo[ib], hi[ib]) if ib >= 0 else (0.0, 0.0)
        lo[out[i]], hi[out[i]] = image(op[i], lo[a[i]], hi[a[i]], yl, yh, param[i], buf,
                                       piecewise, pown, explog, trig)


@_njit
def _accumulate(adl, adh, s, gl, gh, sl, sh):
    """``adj[s] += g * S`` rounded outward; a NaN (inf - inf) becomes the entire line."""
    if sl == 0.0 and sh == 0.0:
        return
    pl, ph = _mul(gl, gh, sl, sh)
    nl, nh = _add_lo(adl[s], adh[s], pl, ph), _add_hi(adl[s], adh[s], pl, ph)
    adl[s] = nl if nl == nl else -INF
    adh[s] = nh if nh == nh else INF


@_njit
def box_jacobian(op, out, a, b, param, node_ptr, out_slot, row_ptr, cols, sl, sh, adl, adh,
                 buf, jl, jh):
    """Sparse Jacobian ``jl, jh`` (nnz,) of one box whose slots ``sl, sh`` hold the forward
    images (:func:`forward_pass`): one reverse sweep per output over that output's nodes.
    ``adl, adh`` (n_slots,) are zero on entry and on return."""
    for k in range(out_slot.size):
        adl[out_slot[k]] = 1.0
        adh[out_slot[k]] = 1.0
        for i in range(node_ptr[k + 1] - 1, node_ptr[k] - 1, -1):
            o = out[i]
            gl, gh = adl[o], adh[o]
            if gl == 0.0 and gh == 0.0:
                continue
            ia, ib = a[i], b[i]
            yl, yh = (sl[ib], sh[ib]) if ib >= 0 else (0.0, 0.0)
            sxl, sxh, syl, syh = slopes(op[i], sl[o], sh[o], sl[ia], sh[ia], yl, yh, param[i],
                                        buf)
            _accumulate(adl, adh, ia, gl, gh, sxl, sxh)
            if ib >= 0:
                _accumulate(adl, adh, ib, gl, gh, syl, syh)
        for j in range(row_ptr[k], row_ptr[k + 1]):
            jl[j] = adl[cols[j]]
            jh[j] = adh[cols[j]]
        adl[out_slot[k]] = adh[out_slot[k]] = 0.0
        for i in range(node_ptr[k], node_ptr[k + 1]):
            adl[a[i]] = adh[a[i]] = 0.0
            if b[i] >= 0:
                adl[b[i]] = adh[b[i]] = 0.0


@_njit
def forward_jacobian(op, out, a, b, param, node_ptr, out_slot, row_ptr, cols, sl, sh, dl, dh,
                     buf, jl, jh):
    """Sparse Jacobian ``jl, jh`` (nnz,) of one box in forward mode (the slots ``sl, sh`` hold
    the forward images, :func:`forward_pass`): for each output, the gradient of every node of
    its block over the output's own variables, ``D_z = S_x D_x + S_y D_y`` with the local
    slopes ``S`` of :func:`slopes` (sound by sub-distributivity: ``S (D d)`` lies in
    ``(S D) d``), except a quotient, which takes ``(D_x y - x D_y) / y^2`` (the quotient
    rule, as Codac 2 differentiates; entire when ``y`` contains 0). ``dl, dh``
    (n_slots, max row length) are scratch whose constant rows must be zero (they stay so)."""
    for k in range(out_slot.size):
        c0 = row_ptr[k]
        nk = row_ptr[k + 1] - c0
        for q in range(nk):
            j = cols[c0 + q]
            for t in range(nk):
                dl[j, t] = dh[j, t] = 0.0
            dl[j, q] = dh[j, q] = 1.0
        for i in range(node_ptr[k], node_ptr[k + 1]):
            o, ia, ib = out[i], a[i], b[i]
            xl, xh = sl[ia], sh[ia]
            yl, yh = (sl[ib], sh[ib]) if ib >= 0 else (0.0, 0.0)
            if op[i] == DIV:
                if yl <= 0.0 <= yh or not yl <= yh:
                    for t in range(nk):
                        dl[o, t], dh[o, t] = -INF, INF
                    continue
                ql, qh = _sqr_lo(yl, yh), _sqr_hi(yl, yh)
                for t in range(nk):
                    ul, uh = _mul(dl[ia, t], dh[ia, t], yl, yh)
                    vl, vh = _mul(xl, xh, dl[ib, t], dh[ib, t])
                    wl, wh = _sub_lo(ul, uh, vl, vh), _sub_hi(ul, uh, vl, vh)
                    rl, rh = _div(wl, wh, ql, qh)
                    dl[o, t] = rl if rl == rl else -INF
                    dh[o, t] = rh if rh == rh else INF
                continue
            sxl, sxh, syl, syh = slopes(op[i], sl[o], sh[o], xl, xh, yl, yh, param[i], buf)
            for t in range(nk):
                ul, uh = _term0(sxl, sxh, dl[ia, t], dh[ia, t])
                if ib >= 0:
                    vl, vh = _term0(syl, syh, dl[ib, t], dh[ib, t])
                    ul, uh = _add_lo(ul, uh, vl, vh), _add_hi(ul, uh, vl, vh)
                dl[o, t] = ul if ul == ul else -INF
                dh[o, t] = uh if uh == uh else INF
        s = out_slot[k]
        for q in range(nk):
            jl[c0 + q] = dl[s, q]
            jh[c0 + q] = dh[s, q]


@nb.njit(cache=True, inline="always", error_model="numpy")
def _term0(sl, sh, gl, gh):
    """``S D`` for a chain-rule term: exactly 0 when either factor is [0, 0] (a constant's
    zero gradient times an unbounded slope contributes nothing)."""
    if (sl == 0.0 and sh == 0.0) or (gl == 0.0 and gh == 0.0):
        return 0.0, 0.0
    return _mul(sl, sh, gl, gh)


@_njit
def jacobian_kernel(op, out, a, b, param, node_ptr, out_slot, row_ptr, cols, lo, hi, jl, jh,
                    ok, piecewise, pown, explog, trig):
    """Forward images and sparse Jacobians of a function tape over a batch of boxes.

    ``lo, hi`` (n_boxes, n_slots) hold each box's variables and the constants; the node slots
    are overwritten with their forward images. ``jl, jh`` (n_boxes, nnz) receive the Jacobian
    entries in the tape's ``row_ptr``/``cols`` pattern, ``ok`` (n_boxes,) whether every node is
    defined and continuous on the box (:func:`defined`).
    """
    n_slots = lo.shape[1]
    adl = np.zeros(n_slots)
    adh = np.zeros(n_slots)
    buf = np.empty(4)
    for bx in range(lo.shape[0]):
        sl, sh = lo[bx], hi[bx]
        forward_pass(op, out, a, b, param, sl, sh, buf, piecewise, pown, explog, trig)
        good = True
        for i in range(op.size):
            ib = b[i]
            yl, yh = (sl[ib], sh[ib]) if ib >= 0 else (0.0, 0.0)
            if not defined(op[i], sl[out[i]], sh[out[i]], sl[a[i]], sh[a[i]], yl, yh, param[i]):
                good = False
                break
        ok[bx] = good
        box_jacobian(op, out, a, b, param, node_ptr, out_slot, row_ptr, cols, sl, sh, adl, adh,
                     buf, jl[bx], jh[bx])


@_njit
def forward_kernel(op, out, a, b, param, lo, hi, piecewise, pown, explog, trig):
    """Forward images of a function tape over a batch of boxes (``lo, hi`` as above)."""
    buf = np.empty(4)
    for bx in range(lo.shape[0]):
        forward_pass(op, out, a, b, param, lo[bx], hi[bx], buf, piecewise, pown, explog, trig)


def _slots(tape: FunctionTape, box: Interval) -> tuple[NDArray, NDArray, tuple[int, ...]]:
    """Slot arrays ``(n_boxes, n_slots)`` with each box's variables, and the batch shape."""
    if box.shape[-1:] != (tape.n_vars,):
        raise ValueError(f"the box must have {tape.n_vars} components (the tape's variables "
                         f"{tape.names}), got shape {box.shape}")
    batch = box.shape[:-1]
    nb_ = int(np.prod(batch, dtype=np.int64))
    lo = np.tile(tape.lo, (nb_, 1))
    hi = np.tile(tape.hi, (nb_, 1))
    lo[:, : tape.n_vars] = box.lo.reshape(nb_, tape.n_vars)
    hi[:, : tape.n_vars] = box.hi.reshape(nb_, tape.n_vars)
    return lo, hi, batch


def _args(tape: FunctionTape) -> tuple:
    return (tape.op, tape.out, tape.a, tape.b, tape.param)


def evaluate(tape: FunctionTape | Any, box: ArrayLike | Interval) -> Interval:
    """Natural interval extension of the tape's outputs over a box or a batch ``(..., n)``;
    returns shape ``(..., m)``. ``tape`` may also be an expression, a list of them, a model
    or a list of constraints (``expr.function_tape.as_function_tape``)."""
    tape = as_function_tape(tape)
    box = as_interval(box)
    lo, hi, batch = _slots(tape, box)
    forward_kernel(*_args(tape), lo, hi, *family_flags(tape.op))
    return Interval.trusted(lo[:, tape.out_slot].reshape(*batch, -1),
                         hi[:, tape.out_slot].reshape(*batch, -1))


def jacobian_sparse(tape: FunctionTape, box: ArrayLike | Interval, with_defined: bool = False
                    ) -> tuple:
    """Natural values ``(..., m)`` and Jacobian entries ``(..., nnz)`` in the tape's sparsity
    pattern (row ``k`` holds columns ``tape.cols[tape.row_ptr[k]:tape.row_ptr[k + 1]]``); with
    ``with_defined`` also a boolean array ``(...)``: whether every primitive is defined and
    continuous on the box."""
    tape = as_function_tape(tape)
    box = as_interval(box)
    lo, hi, batch = _slots(tape, box)
    nnz = len(tape.cols)
    jl = np.empty((lo.shape[0], nnz))
    jh = np.empty((lo.shape[0], nnz))
    ok = np.empty(lo.shape[0], dtype=np.bool_)
    jacobian_kernel(*_args(tape), tape.node_ptr, tape.out_slot, tape.row_ptr, tape.cols, lo, hi,
                    jl, jh, ok, *family_flags(tape.op))
    values = Interval.trusted(lo[:, tape.out_slot].reshape(*batch, -1),
                           hi[:, tape.out_slot].reshape(*batch, -1))
    entries = Interval.trusted(jl.reshape(*batch, nnz), jh.reshape(*batch, nnz))
    if with_defined:
        return values, entries, ok.reshape(batch)
    return values, entries


def _row_index(tape: FunctionTape) -> NDArray[np.int64]:
    return np.repeat(np.arange(tape.n_outputs), np.diff(tape.row_ptr))


def jacobian(tape: FunctionTape | Any, box: ArrayLike | Interval) -> tuple[Interval, Interval]:
    """Natural values ``(..., m)`` and an enclosure of the Jacobian ``(..., m, n)`` over a box
    or a batch of boxes ``(..., n)``.

    ``tape`` is a ``FunctionTape``, an expression or a list of them (columns: the variables in
    order of first appearance; ``function_tape(..., names)`` fixes another order), or a model
    or a list of constraints (the functions ``lhs - rhs``, columns ``Model.variable_names``).

    Every entry ``J[k, j]`` contains ``d f_k / d x_j`` at every point of the box where it
    exists (and, for non-smooth primitives, their generalized derivatives), so that
    ``f(x) - f(c) in J (x - c)`` for every two points ``x, c`` of the box.

    Examples
    --------
    >>> from boundest.expr import Var
    >>> from boundest.expr.function_tape import function_tape
    >>> x, y = Var("x"), Var("y")
    >>> _, J = jacobian([x * y, x ** 2], Interval([1, 2], [2, 3]))
    >>> J.lo.tolist(), J.hi.tolist()
    ([[2.0, 1.0], [2.0, 0.0]], [[3.0, 2.0], [4.0, 0.0]])
    """
    tape = as_function_tape(tape)
    values, entries = jacobian_sparse(tape, box)
    batch = values.shape[:-1]
    jl = np.zeros((*batch, tape.n_outputs, tape.n_vars))
    jh = np.zeros((*batch, tape.n_outputs, tape.n_vars))
    rows = _row_index(tape)
    jl[..., rows, tape.cols] = entries.lo
    jh[..., rows, tape.cols] = entries.hi
    return values, Interval.trusted(jl, jh)


def centered(tape: FunctionTape | Any, box: ArrayLike | Interval,
             center: ArrayLike | None = None) -> Interval:
    """Mean-value (centered) form of the outputs, intersected with the natural form.

    ``f(X) in f(c) + J(X) (X - c)`` with ``c`` the midpoint of the box (clamped into the box
    and finite where a bound is infinite) unless ``center`` is given; ``f(c)`` is evaluated
    rigorously as an interval. The centered form is quadratically close to the range as the
    box shrinks, the natural form only linearly; their intersection is never wider than either.
    Returns shape ``(..., m)``; ``tape`` as in :func:`jacobian`.

    Examples
    --------
    >>> from boundest.expr import Var
    >>> x = Var("x")
    >>> box = Interval(0.4, 0.6)[None]
    >>> natural, mean_value = evaluate(x * (1 - x), box), centered(x * (1 - x), box)
    >>> round(float(natural.width()[0]), 3), round(float(mean_value.width()[0]), 3)
    (0.2, 0.04)
    """
    tape = as_function_tape(tape)
    box = as_interval(box)
    c = midpoint(box) if center is None else np.asarray(center, dtype=np.float64)
    if center is not None and not np.all(box.contains(c) | box.is_empty()):
        raise ValueError("the center must lie in the box")
    natural, entries = jacobian_sparse(tape, box)
    c = np.where(box.is_empty(), 0.0, c)  # an empty component: any centre, the result is empty
    fc = evaluate(tape, Interval(c, c))
    dx = box - Interval(c, c)
    rows = _row_index(tape)
    terms = entries * dx[..., tape.cols]
    total_lo = np.zeros(natural.shape)
    total_hi = np.zeros(natural.shape)
    _sum_rows(terms.lo, terms.hi, rows, total_lo, total_hi)
    cf = fc + Interval.trusted(total_lo, total_hi)
    # an empty f(c) (c outside some primitive's domain) gives no centered information
    cf = Interval.trusted(np.where(np.isnan(fc.lo), -np.inf, cf.lo),
                       np.where(np.isnan(fc.lo), np.inf, cf.hi))
    return natural & cf


def midpoint(box: Interval) -> NDArray[np.float64]:
    """A finite point of each box: the midpoint, 0 or a finite bound where one is infinite."""
    lo, hi = box.lo, box.hi
    with np.errstate(invalid="ignore"):  # inf - inf where both bounds are infinite: replaced
        c = 0.5 * lo + 0.5 * hi
    c = np.where(np.isfinite(lo) & np.isfinite(hi), c,
                 np.where(np.isfinite(lo), lo, np.where(np.isfinite(hi), hi, 0.0)))
    return np.clip(c, lo, hi)


@_njit
def _sum_rows(tl, th, rows, out_lo, out_hi):
    """``out[..., rows[j]] += t[..., j]`` rounded outward (``tl, th`` are (..., nnz))."""
    tl2 = tl.reshape(-1, tl.shape[-1])
    th2 = th.reshape(-1, th.shape[-1])
    ol = out_lo.reshape(-1, out_lo.shape[-1])
    oh = out_hi.reshape(-1, out_hi.shape[-1])
    for bx in range(tl2.shape[0]):
        for j in range(rows.size):
            k = rows[j]
            nl = _add_lo(ol[bx, k], oh[bx, k], tl2[bx, j], th2[bx, j])
            nh = _add_hi(ol[bx, k], oh[bx, k], tl2[bx, j], th2[bx, j])
            ol[bx, k], oh[bx, k] = nl, nh
