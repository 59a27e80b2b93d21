"""Contractors from the centered form: ``CtcCentered`` (a mean-value linearisation, optionally
preconditioned by Gauss-Jordan elimination) and ``CtcNewton`` (interval Newton for square
systems, with proofs of existence and uniqueness).

For constraints ``f(x) in Y`` on a box ``X`` with centre ``c``, every solution ``x`` satisfies
``f(c) + S (x - c) in Y`` for a real matrix ``S`` in the Jacobian enclosure ``J`` over ``X``
(:mod:`boundest.ctc.derivatives`), so ``d = x - c`` lies in the solution set of the interval
linear system ``J d in (Y & f(X)) - f(c)``, which
:func:`~boundest.ctc.linear_forms.contract_rows` projects outward. Without preconditioning each
constraint is taken on its own, with the first-order correlation of its variables kept. With
Gauss-Jordan preconditioning (``P = mid(J)`` reduced, rows ``P J d in P (Y - f(c))``, swept
forward, backward and forward, then the plain rows: the centered step of Codac 2's
``CtcInverse`` also preconditions) the rows are nearly decoupled and the contraction is
asymptotically minimal for narrow boxes (Jaulin 2023, arXiv 2307.10502): the result tends to
the hull of the solution set, where hull consistency stays at the hull of each constraint's
projection.

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
from .derivatives import evaluate, jacobian_sparse, midpoint
from .linear_forms import _term, contract_rows, point_times, preconditioner
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
def _dense(entries_lo, entries_hi, row_ptr, cols, n):
    """The dense ``(m, n)`` Jacobian of one box from its sparse entries."""
    m = row_ptr.size - 1
    jl = np.zeros((m, n))
    jh = np.zeros((m, n))
    for k in range(m):
        for q in range(row_ptr[k], row_ptr[k + 1]):
            jl[k, cols[q]] = entries_lo[q]
            jh[k, cols[q]] = entries_hi[q]
    return jl, jh


@_njit
def _midpoints(jl, jh):
    """Finite midpoints of an interval matrix (0 where a bound is infinite)."""
    a = np.empty(jl.shape)
    for i in range(jl.shape[0]):
        for j in range(jl.shape[1]):
            lo, hi = jl[i, j], jh[i, j]
            a[i, j] = 0.5 * lo + 0.5 * hi if (math.isfinite(lo) and math.isfinite(hi)) else 0.0
    return a


@_njit
def _rhs(tl, th, fl, fh):
    """``Y - f(c)`` rounded outward (entire where it is undefined)."""
    m = tl.size
    zl = np.empty(m)
    zh = np.empty(m)
    for k in range(m):
        lo, hi = sub_dn(tl[k], fh[k]), sub_up(th[k], fl[k])
        zl[k] = lo if lo == lo else -INF
        zh[k] = hi if hi == hi else INF
    return zl, zh


@_njit
def _centered_kernel(el, eh, row_ptr, cols, fcl, fch, vl, vh, tl, th, xl, xh, c, precondition):
    """Contract each box ``(xl[b], xh[b])`` in place; an empty box gets NaN bounds. The
    targets ``tl, th`` are per box, shape (n_boxes, m)."""
    n = xl.shape[1]
    for bx in range(xl.shape[0]):
        if not (np.all(xl[bx] <= xh[bx])):
            continue
        empty = False
        for k in range(tl.shape[1]):  # the natural form already refutes the box
            if vl[bx, k] > th[bx, k] or vh[bx, k] < tl[bx, k]:
                empty = True
        if not empty:
            if np.any(np.isnan(fcl[bx])):
                continue  # the centre is outside some primitive's domain: no linearisation
            jl, jh = _dense(el[bx], eh[bx], row_ptr, cols, n)
            # f(x) lies in Y and in the natural form f(X): Y & f(X) - f(c) (as Codac 2 does)
            m = tl.shape[1]
            yl = np.empty(m)
            yh = np.empty(m)
            for k in range(m):
                yl[k] = max(tl[bx, k], vl[bx, k]) if vl[bx, k] == vl[bx, k] else tl[bx, k]
                yh[k] = min(th[bx, k], vh[bx, k]) if vh[bx, k] == vh[bx, k] else th[bx, k]
            zl, zh = _rhs(yl, yh, fcl[bx], fch[bx])
            dl = np.empty(n)
            dh = np.empty(n)
            for j in range(n):
                dl[j] = sub_dn(xl[bx, j], c[bx, j])
                dh[j] = sub_up(xh[bx, j], c[bx, j])
            empty = not contract_rows(jl, jh, zl, zh, dl, dh)
            if not empty and precondition:
                A = _midpoints(jl, jh)
                for j in range(n):
                    w = dh[j] - dl[j]
                    A[:, j] *= w if math.isfinite(w) else 1e300
                P, _ = preconditioner(A)
                ml, mh = point_times(P, jl, jh)
                rl, rh = point_times(P, zl.reshape(-1, 1), zh.reshape(-1, 1))
                # the preconditioned rows forward, backward and forward again (each sweep
                # starts from what the previous one narrowed), then the plain rows
                bl, bh = ml[::-1].copy(), mh[::-1].copy()
                brl, brh = rl[::-1, 0].copy(), rh[::-1, 0].copy()
                empty = not (contract_rows(ml, mh, rl[:, 0], rh[:, 0], dl, dh)
                             and contract_rows(bl, bh, brl, brh, dl, dh)
                             and contract_rows(ml, mh, rl[:, 0], rh[:, 0], dl, dh)
                             and contract_rows(jl, jh, zl, zh, dl, dh))
        if empty:
            xl[bx, :] = np.nan
            xh[bx, :] = np.nan
            continue
        for j in range(n):
            xl[bx, j] = max(xl[bx, j], add_dn(c[bx, j], dl[j]))
            xh[bx, j] = min(xh[bx, j], add_up(c[bx, j], dh[j]))


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
        After each constraint's linearisation on its own (all of it when False), also contract
        with the rows of ``P J``: with True or
        ``"gauss-jordan"``, ``P`` from Gauss-Jordan elimination on ``mid(J)`` with columns
        scaled by the domains' widths (asymptotically minimal for narrow boxes, Jaulin 2023;
        ``O(m^2 (m + n))`` per box); with ``"lp"``, for each variable and each of its bounds
        the aggregation of the rows that a linear programme over the linearisation finds best
        (:mod:`boundest.ctc.windows`: the hull of the linearised set up to the Jacobian's
        width, two small dense simplexes per variable and box).

    Examples
    --------
    >>> from boundest.expr import Var, Model
    >>> x, y = Var("x"), Var("y")
    >>> ctc = CtcCentered(Model().add(x + y == 1, x - y == 0))
    >>> ctc(Interval([0, 0], [1, 1]))
    Interval([[0.5, 0.5], [0.5, 0.5]])
    """

    def __init__(self, system: FunctionTape | Model, precondition: bool | str = True) -> None:
        super().__init__(system)
        if precondition not in (True, False, "gauss-jordan", "lp"):
            raise ValueError(f"precondition must be True, False, 'gauss-jordan' or 'lp', got "
                             f"{precondition!r}")
        self.precondition = precondition

    def contract(self, x: Interval, targets: Interval | None = None) -> Interval:
        """Contract boxes ``(..., n)``; ``targets`` (broadcast to ``(..., m)``) replaces the
        tape's target sets, one per box (the same constraints with other data)."""
        box, c, values, entries, _, fc = self._linearise(x)
        lo, hi = box.lo.copy(), box.hi.copy()
        t = self.tape
        if targets is None:
            tl = np.broadcast_to(t.target_lo, (len(lo), t.n_outputs))
            th = np.broadcast_to(t.target_hi, (len(lo), t.n_outputs))
        else:
            shape = (*x.shape[:-1], t.n_outputs)
            tl = np.broadcast_to(targets.lo, shape).reshape(len(lo), -1)
            th = np.broadcast_to(targets.hi, shape).reshape(len(lo), -1)
        tl, th = np.ascontiguousarray(tl), np.ascontiguousarray(th)
        _centered_kernel(entries.lo, entries.hi, t.row_ptr, t.cols, fc.lo, fc.hi, values.lo,
                         values.hi, tl, th, lo, hi, c, self.precondition in (True, "gauss-jordan"))
        if self.precondition == "lp":
            stats = np.zeros(len(WINDOW_STATS), dtype=np.int64)
            batch_kernel(entries.lo, entries.hi, t.row_ptr, t.cols, fc.lo, fc.hi, tl, th, lo,
                         hi, c, 20 * (t.n_outputs + self.n) + 200, stats)
        return _empty_rows(Interval.trusted(lo.reshape(x.shape), hi.reshape(x.shape)))


@_njit
def _newton_kernel(el, eh, row_ptr, cols, fcl, fch, ok, tl, th, xl, xh, c, proved):
    """Hansen-Sengupta contraction and the Krawczyk test of each box, in place."""
    n = xl.shape[1]
    for bx in range(xl.shape[0]):
        proved[bx] = False
        if not np.all(xl[bx] <= xh[bx]) or np.any(np.isnan(fcl[bx])):
            continue
        jl, jh = _dense(el[bx], eh[bx], row_ptr, cols, n)
        P0, pivot = preconditioner(_midpoints(jl, jh))
        P = np.zeros((n, n))
        full = True
        for r in range(n):
            if pivot[r] < 0:
                full = False
            else:
                P[pivot[r]] = P0[r]  # P mid(J) ~ I, rows in the order of the variables
        if not full:
            P = P0
        zl, zh = _rhs(tl, th, fcl[bx], fch[bx])
        ml, mh = point_times(P, jl, jh)
        rl, rh = point_times(P, zl.reshape(-1, 1), zh.reshape(-1, 1))
        dl = np.empty(n)
        dh = np.empty(n)
        rad = np.empty(n)
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
        if not contract_rows(ml, mh, rl[:, 0], rh[:, 0], dl, dh):
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
        _newton_kernel(entries.lo, entries.hi, t.row_ptr, t.cols, fc.lo, fc.hi, ok,
                       t.target_lo, t.target_hi, lo, hi, c, proved)
        out = _empty_rows(Interval.trusted(lo.reshape(x.shape), hi.reshape(x.shape)))
        return out, proved.reshape(x.shape[:-1])

    def contract(self, x: Interval) -> Interval:
        return self.prove(x)[0]
