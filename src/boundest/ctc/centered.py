"""Contractors from the centered form: ``CtcCentered`` (a mean-value linearisation, optionally
preconditioned by Gauss-Jordan elimination) and ``CtcNewton`` (interval Newton for square
systems, with proofs of existence and uniqueness).

For constraints ``f(x) in Y`` on a box ``X`` with centre ``c``, every solution ``x`` satisfies
``f(c) + S (x - c) in Y`` for a real matrix ``S`` in the Jacobian enclosure ``J`` over ``X``
(:mod:`boundest.ctc.derivatives`), so ``d = x - c`` lies in the solution set of the interval
linear system ``J d in (Y & f(X)) - f(c)``, which
:func:`~boundest.ctc.linear_forms.contract_rows` projects outward. Without preconditioning each
constraint is taken on its own, with the first-order correlation of its variables kept. With
preconditioning (the banded Gauss-Jordan ``R`` of ``mid(J)``, rows ``R J d in R z`` swept last
to first and first to last, or an interval Gaussian elimination when there are more constraints
than unknowns, then the plain rows: the sweeps of Codac 2's ``CtcInverse``, see
:func:`_centered_step`) the rows are nearly decoupled and the contraction is asymptotically
minimal for narrow boxes (Jaulin 2023, arXiv 2307.10502): the result tends to the hull of the
solution set, where hull consistency stays at the hull of each constraint's projection. With
``hc4=True`` one backward sweep of HC4 over the forward images follows, as in ``CtcInverse``.

For a square system ``f(x) = t`` the preconditioned rows are the Hansen-Sengupta (Gauss-Seidel)
step of interval Newton, and the Krawczyk operator
``K(X) = c - P (f(c) - t) + (I - P J) (X - c)`` gives the proof: if every primitive is defined
and continuous on ``X``, ``K(X)`` lies in ``X`` and ``|I - P J| r < r`` for the radius vector
``r`` of ``X`` (so every ``P S`` is regular, Perron-Frobenius), then ``X`` holds exactly one
solution (Brouwer's fixed-point theorem for ``x - P (f(x) - t)``; Krawczyk 1969, Moore 1977,
Neumaier 1990 section 5.1).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from numpy.typing import NDArray

from ..expr.function_tape import FunctionTape, constraint_functions
from ..expr.model import Model
from ..interval import Interval
from ..interval.rounding import add_dn, add_up, mul_up, sub_dn, sub_up
from .base import Contractor, _empty_rows
from .derivatives import evaluate, forward_jacobian, forward_pass, jacobian_sparse, midpoint
from .linear_forms import (
    _term,
    band_preconditioner,
    contract_rows,
    interval_elimination,
    point_times,
    square_preconditioner,
)
from .revise import _meet, back, family_flags
from .windows import WINDOW_STATS, batch_kernel

__all__ = ["CtcCentered", "CtcNewton"]

INF = math.inf
_njit = nb.njit(cache=True, error_model="numpy")


def _as_tape(system: FunctionTape | Model) -> FunctionTape:
    if isinstance(system, FunctionTape):
        return system
    if isinstance(system, (Model, list, tuple)):
        return constraint_functions(system)[0]
    raise TypeError(f"expected a Model, a list of constraints or a FunctionTape, got "
                    f"{type(system).__name__}")


@_njit
def _dense(entries_lo, entries_hi, row_ptr, cols, jl, jh):
    """The dense ``(m, n)`` Jacobian ``jl, jh`` of one box from its sparse entries."""
    jl[:, :] = 0.0
    jh[:, :] = 0.0
    for k in range(row_ptr.size - 1):
        for q in range(row_ptr[k], row_ptr[k + 1]):
            jl[k, cols[q]] = entries_lo[q]
            jh[k, cols[q]] = entries_hi[q]


@_njit
def _midpoints(jl, jh, a):
    """Finite midpoints ``a`` of an interval matrix (0 where a bound is infinite)."""
    for i in range(jl.shape[0]):
        for j in range(jl.shape[1]):
            lo, hi = jl[i, j], jh[i, j]
            a[i, j] = 0.5 * lo + 0.5 * hi if (math.isfinite(lo) and math.isfinite(hi)) else 0.0


@_njit
def _rhs(tl, th, fl, fh, zl, zh):
    """``zl, zh = Y - f(c)`` rounded outward (entire where it is undefined)."""
    for k in range(tl.size):
        lo, hi = sub_dn(tl[k], fh[k]), sub_up(th[k], fl[k])
        zl[k] = lo if lo == lo else -INF
        zh[k] = hi if hi == hi else INF


@_njit
def _centre(lo, hi):
    """The point of ``[lo, hi]`` that :func:`~boundest.ctc.derivatives.midpoint` takes."""
    if math.isfinite(lo) and math.isfinite(hi):
        c = 0.5 * lo + 0.5 * hi
    elif math.isfinite(lo):
        c = lo
    elif math.isfinite(hi):
        c = hi
    else:
        c = 0.0
    return min(max(c, lo), hi)


@_njit
def _centered_step(jl, jh, zl, zh, dl, dh, precondition, ws_m, ws_mn, ws_mm, piv, cp, work):
    """The linear part of one centered step: contract ``d`` (in place) with ``J d in z``
    (``jl, jh`` (m, n) and ``zl, zh`` (m,) are overwritten). Returns False when there is no
    solution.

    Without ``precondition`` the rows of ``J`` once. With it, in this order (each sweep starts
    from what the previous one narrowed, and every one is sound on its own):

    1. when ``m <= n``, the rows of ``R J d in R z`` with the banded preconditioner ``R`` of
       ``mid(J)`` (:func:`~boundest.ctc.linear_forms.band_preconditioner`), last to first,
       then first to last -- and, when the first ``m`` columns of ``mid(J)`` are near singular
       (reciprocal condition number below ``1e-5``), the rows of ``J`` last to first and
       first to last; when ``m > n``, the rows of the interval Gaussian elimination of
       ``J d in z`` (:func:`~boundest.ctc.linear_forms.interval_elimination`, full pivoting on
       ``mid(J)``), the consistency rows (``0 in z_i``) first, then the pivot rows last to
       first;
    2. the rows of ``J``, first to last.

    That is, sweep for sweep, what Codac 2's ``CtcInverse`` does after its forward evaluation
    (its ``MulOp::bwd``: the rows of ``R J`` last to first and first to last, or an interval
    LU solve when ``m > n``, then the rows of ``J``), with each row contraction at least as
    tight (relational division in every product, the variables contracted earlier in the row
    reused), so the result lies inside Codac's up to rounding.
    """
    m, n = jl.shape
    if not precondition or m == 0:
        return contract_rows(jl, jh, zl, zh, dl, dh, False, work)
    mid = ws_mn[0]
    _midpoints(jl, jh, mid)
    gl, gh = ws_mn[1], ws_mn[2]
    rl, rh = ws_m[0], ws_m[1]
    if m <= n:
        R, B = ws_mm[0], ws_mm[1]
        rc = band_preconditioner(mid, R, B, piv)
        if rc > 0.0:
            point_times(R, jl, jh, gl, gh)
            point_times(R, zl.reshape(-1, 1), zh.reshape(-1, 1), rl.reshape(-1, 1),
                        rh.reshape(-1, 1))
            if not (contract_rows(gl, gh, rl, rh, dl, dh, True, work)
                    and contract_rows(gl, gh, rl, rh, dl, dh, False, work)):
                return False
        if rc < 1e-5 and not (contract_rows(jl, jh, zl, zh, dl, dh, True, work)
                              and contract_rows(jl, jh, zl, zh, dl, dh, False, work)):
            return False
    else:
        el, eh = ws_mn[3], ws_mn[4]
        el[:, :] = jl
        eh[:, :] = jh
        ezl, ezh = ws_m[2], ws_m[3]
        ezl[:] = zl
        ezh[:] = zh
        steps = interval_elimination(el, eh, ezl, ezh, mid, piv, cp)
        # the rows in pivot order (the consistency rows last), swept last to first
        for k in range(m):
            q = piv[k]
            gl[k, :] = el[q, :]
            gh[k, :] = eh[q, :]
            rl[k], rh[k] = ezl[q], ezh[q]
        if steps > 0 and not contract_rows(gl, gh, rl, rh, dl, dh, True, work):
            return False
    return contract_rows(jl, jh, zl, zh, dl, dh, False, work)


@_njit
def _backward(op, out, a, b, param, lo, hi, buf, piecewise, pown, explog, trig):
    """The backward sweep of HC4 on slots that hold the forward images (the nodes last to
    first, each node's arguments contracted by :func:`~boundest.ctc.revise.back` from its
    slot, which is not re-evaluated: Codac 2's ``bwd``); False as soon as a slot is empty."""
    for i in range(op.size - 1, -1, -1):
        o, ia, ib = out[i], a[i], b[i]
        yl, yh = (lo[ib], hi[ib]) if ib >= 0 else (0.0, 0.0)
        xl, xh, yl, yh = back(op[i], lo[o], hi[o], lo[ia], hi[ia], yl, yh, param[i], buf,
                              piecewise, pown, explog, trig)
        if not _meet(lo, hi, ia, xl, xh):
            return False
        if ib >= 0 and not _meet(lo, hi, ib, yl, yh):
            return False
    return True


@_njit
def _centered_kernel(op, out, a, b, param, node_ptr, out_slot, row_ptr, cols, slot_lo, slot_hi,
                     tl, th, xl, xh, precondition, hc4, piecewise, pown, explog, trig):
    """Contract each box ``(xl[b], xh[b])`` in place (an empty box gets NaN bounds): the
    forward images over the box, its Jacobian (forward mode), the outputs at its centre, the
    centered step (:func:`_centered_step`) on ``(Y & f(X)) - f(c)`` and, with ``hc4``, the
    backward sweep of HC4 (:func:`_backward`) from the forward images over the box as given and
    the variables as the centered step left them. The targets ``tl, th`` are per box, shape
    (n_boxes, m). One call per batch; the workspaces are allocated once."""
    n = xl.shape[1]
    m = out_slot.size
    ns = slot_lo.size
    nnz = cols.size
    sl, sh = np.empty(ns), np.empty(ns)
    cl, ch = np.empty(ns), np.empty(ns)
    width = 1
    for k in range(m):
        width = max(width, row_ptr[k + 1] - row_ptr[k])
    gdl, gdh = np.zeros((ns, width)), np.zeros((ns, width))
    buf = np.empty(4)
    el, eh = np.empty(nnz), np.empty(nnz)
    jl, jh = np.empty((m, n)), np.empty((m, n))
    yl, yh = np.empty(m), np.empty(m)
    zl, zh = np.empty(m), np.empty(m)
    dl, dh = np.empty(n), np.empty(n)
    c = np.empty(n)
    ws_m = np.empty((4, m))
    ws_mn = np.empty((5, m, n))  # mid(J), the preconditioned rows, the eliminated system
    ws_mm = np.empty((2, m, m))
    piv = np.empty(max(m, 1), dtype=np.int64)
    cp = np.empty(n, dtype=np.int64)
    work = np.empty((6, n + 1))
    for bx in range(xl.shape[0]):
        if not np.all(xl[bx] <= xh[bx]):
            continue
        sl[:] = slot_lo
        sh[:] = slot_hi
        sl[:n] = xl[bx]
        sh[:n] = xh[bx]
        forward_pass(op, out, a, b, param, sl, sh, buf, piecewise, pown, explog, trig)
        empty = False
        for k in range(m):  # the natural form already refutes the box
            vl, vh = sl[out_slot[k]], sh[out_slot[k]]
            if vl > th[bx, k] or vh < tl[bx, k]:
                empty = True
            # f(x) lies in Y and in the natural form f(X): Y & f(X) - f(c) (as Codac 2 does)
            yl[k] = max(tl[bx, k], vl) if vl == vl else tl[bx, k]
            yh[k] = min(th[bx, k], vh) if vh == vh else th[bx, k]
        if not empty:
            cl[:] = slot_lo
            ch[:] = slot_hi
            for j in range(n):
                c[j] = _centre(xl[bx, j], xh[bx, j])
                cl[j] = ch[j] = c[j]
            forward_pass(op, out, a, b, param, cl, ch, buf, piecewise, pown, explog, trig)
            centre_ok = True
            for k in range(m):
                if cl[out_slot[k]] != cl[out_slot[k]]:
                    centre_ok = False  # c outside some primitive's domain: no linearisation
            if centre_ok:
                forward_jacobian(op, out, a, b, param, node_ptr, out_slot, row_ptr, cols, sl,
                                 sh, gdl, gdh, buf, el, eh)
                _dense(el, eh, row_ptr, cols, jl, jh)
                for k in range(m):
                    fl, fh = cl[out_slot[k]], ch[out_slot[k]]
                    lo, hi = sub_dn(yl[k], fh), sub_up(yh[k], fl)
                    zl[k] = lo if lo == lo else -INF
                    zh[k] = hi if hi == hi else INF
                for j in range(n):
                    dl[j] = sub_dn(xl[bx, j], c[j])
                    dh[j] = sub_up(xh[bx, j], c[j])
                if _centered_step(jl, jh, zl, zh, dl, dh, precondition, ws_m, ws_mn, ws_mm, piv,
                                  cp, work):
                    for j in range(n):
                        xl[bx, j] = max(xl[bx, j], add_dn(c[j], dl[j]))
                        xh[bx, j] = min(xh[bx, j], add_up(c[j], dh[j]))
                        if not xl[bx, j] <= xh[bx, j]:
                            empty = True
                else:
                    empty = True
        if not empty and hc4:
            # Codac's backward sweep, from the forward images over the box as given (still in
            # the slots) and the variables as the centered step left them
            for j in range(n):
                sl[j], sh[j] = xl[bx, j], xh[bx, j]
            for k in range(m):
                o = out_slot[k]
                sl[o], sh[o] = max(sl[o], tl[bx, k]), min(sh[o], th[bx, k])
                if not sl[o] <= sh[o]:
                    empty = True
            if not empty and _backward(op, out, a, b, param, sl, sh, buf, piecewise, pown,
                                       explog, trig):
                for j in range(n):
                    xl[bx, j] = max(xl[bx, j], sl[j])
                    xh[bx, j] = min(xh[bx, j], sh[j])
                    if not xl[bx, j] <= xh[bx, j]:
                        empty = True
            else:
                empty = True
        if empty:
            xl[bx, :] = np.nan
            xh[bx, :] = np.nan


class _Linearised(Contractor):
    """What both contractors share: the tape, the Jacobian and the centre of each box."""

    def __init__(self, system: FunctionTape | Model) -> None:
        self.tape = _as_tape(system)
        self.n = self.tape.n_vars

    def _linearise(self, x: Interval, with_defined: bool = False):
        box = x.reshape(-1, self.n)
        c = midpoint(box)
        c = np.where(np.isnan(c), 0.0, c)
        if with_defined:  # only a proof needs it (Newton)
            values, entries, ok = jacobian_sparse(self.tape, box, with_defined=True)
        else:
            (values, entries), ok = jacobian_sparse(self.tape, box), None
        fc = evaluate(self.tape, Interval(c, c))
        return box, c, values, entries, ok, fc


class CtcCentered(_Linearised):
    """Centered-form contractor of ``f(x) in Y`` (a model's constraints or a ``FunctionTape``
    with targets), batched over boxes ``(..., n)``.

    Parameters
    ----------
    system : Model, list of Constraint or FunctionTape
        The constraints (see :func:`boundest.expr.function_tape.constraint_functions`).
    precondition : bool or {"gauss-jordan", "lp"}
        False: each constraint's linearisation on its own. True or ``"gauss-jordan"``: first
        the preconditioned rows of :func:`_centered_step` (the banded Gauss-Jordan ``R`` of
        ``mid(J)``, or interval elimination when ``m > n``; asymptotically minimal for narrow
        boxes, Jaulin 2023; ``O(m^2 (m + n))`` per box), then the plain rows. ``"lp"``: the
        plain rows, then for each variable and each of its bounds the aggregation of the rows
        that a linear programme over the linearisation finds best
        (:mod:`boundest.ctc.windows`: the hull of the linearised set up to the Jacobian's
        width, two small dense simplexes per variable and box).
    hc4 : bool
        Then one backward sweep of forward-backward propagation (the reverse step of each
        node, last to first) from the forward images over the box as given, on the variables
        as the centered step left them: Codac 2's ``CtcInverse(f, y)``, in the same kernel
        (not with ``"lp"``).

    Examples
    --------
    >>> from boundest.expr import Var, Model
    >>> x, y = Var("x"), Var("y")
    >>> ctc = CtcCentered(Model().add(x + y == 1, x - y == 0))
    >>> ctc(Interval([0, 0], [1, 1]))
    Interval([[0.5, 0.5], [0.5, 0.5]])
    """

    def __init__(self, system: FunctionTape | Model, precondition: bool | str = True,
                 hc4: bool = False) -> None:
        super().__init__(system)
        if precondition not in (True, False, "gauss-jordan", "lp"):
            raise ValueError(f"precondition must be True, False, 'gauss-jordan' or 'lp', got "
                             f"{precondition!r}")
        self.precondition = precondition
        self.hc4 = bool(hc4)
        self._flags = family_flags(self.tape.op)

    def contract(self, x: Interval, targets: Interval | None = None) -> Interval:
        """Contract boxes ``(..., n)``; ``targets`` (broadcast to ``(..., m)``) replaces the
        tape's target sets, one per box (the same constraints with other data)."""
        t = self.tape
        box = x.reshape(-1, self.n)
        lo = np.array(box.lo, dtype=np.float64, order="C")
        hi = np.array(box.hi, dtype=np.float64, order="C")
        if targets is None:
            tl = np.broadcast_to(t.target_lo, (len(lo), t.n_outputs))
            th = np.broadcast_to(t.target_hi, (len(lo), t.n_outputs))
        else:
            shape = (*x.shape[:-1], t.n_outputs)
            tl = np.broadcast_to(targets.lo, shape).reshape(len(lo), -1)
            th = np.broadcast_to(targets.hi, shape).reshape(len(lo), -1)
        # copies, always writable: for one box, ascontiguousarray would return the read-only
        # broadcast view itself, a distinct Numba type (a second compilation of the kernel)
        tl = np.array(tl, dtype=np.float64, order="C")
        th = np.array(th, dtype=np.float64, order="C")
        lp = self.precondition == "lp"
        if lp:  # the linear programmes linearise on the box as given
            _, c, _, entries, _, fc = self._linearise(x)
        _centered_kernel(t.op, t.out, t.a, t.b, t.param, t.node_ptr, t.out_slot, t.row_ptr,
                         t.cols, t.lo, t.hi, tl, th, lo, hi,
                         self.precondition in (True, "gauss-jordan"), self.hc4 and not lp,
                         *self._flags)
        if lp:
            stats = np.zeros(len(WINDOW_STATS), dtype=np.int64)
            # f(c) in C order (evaluate's batch is Fortran-ordered, one box's is both): one
            # compiled batch_kernel for one box and for a batch
            batch_kernel(entries.lo, entries.hi, t.row_ptr, t.cols, np.ascontiguousarray(fc.lo),
                         np.ascontiguousarray(fc.hi), tl, th, lo, hi, c,
                         20 * (t.n_outputs + self.n) + 200, stats)
        return _empty_rows(Interval.trusted(lo.reshape(x.shape), hi.reshape(x.shape)))


@_njit
def _newton_kernel(el, eh, row_ptr, cols, fcl, fch, ok, tl, th, xl, xh, c, proved):
    """Hansen-Sengupta contraction and the Krawczyk test of each box, in place."""
    n = xl.shape[1]
    jl, jh = np.empty((n, n)), np.empty((n, n))
    ml, mh = np.empty((n, n)), np.empty((n, n))
    mid = np.empty((n, n))
    W = np.empty((n, 2 * n))
    pivot = np.empty(n, dtype=np.int64)
    used = np.empty(n, dtype=np.bool_)
    P = np.empty((n, n))
    zl, zh = np.empty(n), np.empty(n)
    rl, rh = np.empty((n, 1)), np.empty((n, 1))
    dl, dh, rad = np.empty(n), np.empty(n), np.empty(n)
    work = np.empty((6, n + 1))
    for bx in range(xl.shape[0]):
        proved[bx] = False
        if not np.all(xl[bx] <= xh[bx]) or np.any(np.isnan(fcl[bx])):
            continue
        _dense(el[bx], eh[bx], row_ptr, cols, jl, jh)
        _midpoints(jl, jh, mid)
        square_preconditioner(mid, W, pivot, used)  # sparse LU; Gauss-Jordan if singular
        full = True
        for r in range(n):
            if pivot[r] < 0:
                full = False
        P[:, :] = 0.0
        for r in range(n):
            if full:
                P[pivot[r]] = W[r, n:]  # P mid(J) ~ I, rows in the order of the variables
            else:
                P[r] = W[r, n:]
        _rhs(tl, th, fcl[bx], fch[bx], zl, zh)
        point_times(P, jl, jh, ml, mh)
        point_times(P, zl.reshape(-1, 1), zh.reshape(-1, 1), rl, rh)
        for j in range(n):
            dl[j] = sub_dn(xl[bx, j], c[bx, j])
            dh[j] = sub_up(xh[bx, j], c[bx, j])
            rad[j] = max(-dl[j], dh[j])
        # Krawczyk: K = c + P (t - f(c)) + (I - P J) (X - c), on the box before contraction
        if full and ok[bx] and np.all(tl == th):
            inside = True
            for i in range(n):
                kl, kh = rl[i, 0], rh[i, 0]
                mag_sum = 0.0
                for j in range(n):
                    nl = sub_dn(1.0 if i == j else 0.0, mh[i, j])
                    nh = sub_up(1.0 if i == j else 0.0, ml[i, j])
                    sl, sh = _term(nl, nh, dl[j], dh[j])
                    kl, kh = add_dn(kl, sl), add_up(kh, sh)
                    mag_sum = add_up(mag_sum, mul_up(max(-nl, nh), rad[j]))
                if not (add_dn(c[bx, i], kl) >= xl[bx, i] and add_up(c[bx, i], kh) <= xh[bx, i]
                        and mag_sum < rad[i]):
                    inside = False
                    break
            proved[bx] = inside
        if not contract_rows(ml, mh, rl[:, 0], rh[:, 0], dl, dh, False, work):
            proved[bx] = False
            xl[bx, :] = np.nan
            xh[bx, :] = np.nan
            continue
        for j in range(n):
            xl[bx, j] = max(xl[bx, j], add_dn(c[bx, j], dl[j]))
            xh[bx, j] = min(xh[bx, j], add_up(c[bx, j], dh[j]))


class CtcNewton(_Linearised):
    """Interval Newton for a square system ``f(x) = t`` (``n`` equations in ``n`` unknowns):
    the preconditioned Hansen-Sengupta step as a contractor, and a proof of existence and
    uniqueness of a solution by the Krawczyk test (module docstring).

    ``contract`` returns the contracted boxes; ``prove`` also returns, per box, whether it is
    proved to hold exactly one solution (then the contracted box holds it). Constraints with
    a non-degenerate target (``<=``, ``in``) are contracted but never proved.

    Examples
    --------
    >>> from boundest.expr import Var, Model
    >>> x, y = Var("x"), Var("y")
    >>> newton = CtcNewton(Model().add(x**2 + y**2 == 1, x - y == 0))
    >>> box = Interval([0.6, 0.6], [0.8, 0.8])
    >>> for _ in range(3):  # quadratic convergence: widths 0.2, 1.5e-2, 1e-5, 2e-11
    ...     box, proved = newton.prove(box)
    >>> bool(proved), bool(box.contains(np.sqrt(0.5)).all()), float(box.width().max()) < 1e-10
    (True, True, True)
    """

    def __init__(self, system: FunctionTape | Model) -> None:
        super().__init__(system)
        if self.tape.n_outputs != self.n:
            raise ValueError(f"interval Newton needs a square system: {self.tape.n_outputs} "
                             f"equations in {self.n} unknowns")

    def prove(self, x: Interval) -> tuple[Interval, NDArray[np.bool_]]:
        """Contracted boxes and, per box, whether it provably holds exactly one solution."""
        box, c, _, entries, ok, fc = self._linearise(x, with_defined=True)
        lo, hi = box.lo.copy(), box.hi.copy()
        proved = np.zeros(len(lo), dtype=np.bool_)
        t = self.tape
        _newton_kernel(entries.lo, entries.hi, t.row_ptr, t.cols, np.ascontiguousarray(fc.lo),
                       np.ascontiguousarray(fc.hi), ok,
                       t.target_lo, t.target_hi, lo, hi, c, proved)
        out = _empty_rows(Interval.trusted(lo.reshape(x.shape), hi.reshape(x.shape)))
        return out, proved.reshape(x.shape[:-1])

    def contract(self, x: Interval) -> Interval:
        return self.prove(x)[0]
