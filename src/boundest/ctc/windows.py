"""Centered-form contraction of a large system, window by window, with optimal multipliers.

For constraints ``f(x) in Y`` (a :class:`~boundest.expr.function_tape.FunctionTape` with
targets) on a box ``X`` with centre ``c``, every solution satisfies ``J' d = s`` with
``d = x - c``, ``s in Z = Y - f(c)`` and some real ``J'`` in the Jacobian enclosure ``J`` over
``X`` (:mod:`boundest.ctc.derivatives`). For any real multipliers ``y`` the aggregated row
``(J'^T y) . d = y . s`` holds, so

    g_i d_i in y . Z - sum_{j != i} g_j D_j,   g = J^T y  (intervals, rounded outward),

contracts ``d_i`` whenever ``0`` is not in ``g_i``. That is sound whatever ``y``. The ``y``
that gives the tightest bound on one side of ``d_i`` is the optimal dual of the linear programme
``min +-d_i`` over the linearisation with ``mid(J)``: its value is the hull of the linearised
set, where rows taken one at a time (hull consistency, :class:`~boundest.ctc.CtcCentered`
without preconditioning) or a single Gauss-Jordan preconditioner stay well above it on long
chains. A compiled dense simplex (:mod:`boundest.ctc.simplex`) finds those multipliers; it is
an oracle, trusted for nothing (Neumaier and Shcherbina 2004 use LP duals the same way to get
rigorous bounds from an unverified LP solver).

A long chain of local constraints (a state estimation CSP over many time steps) is cut into
overlapping *windows* of consecutive constraints; each target variable is contracted in the
window where it lies most central, so the cost per target is that of one window's simplex
(bounded, whatever the length of the chain): the per-step cost stays flat.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from numpy.typing import NDArray

from ..expr.function_tape import FunctionTape
from ..interval.rounding import add_dn, add_up, sub_dn, sub_up
from .linear_forms import _nan_hi, _nan_lo, _scale, _term
from .revise import _div_hi, _div_lo
from .simplex import LP_OPTIMAL, lp_setup, lp_solve, multipliers

__all__ = ["WINDOW_STATS", "assign_targets", "batch_kernel", "contract_windows", "windows_kernel"]

INF = math.inf
_njit = nb.njit(cache=True, error_model="numpy")
#: counters of :func:`windows_kernel`: windows visited, linear programmes solved to optimality,
#: not (infeasible linearisation or iteration limit), bounds narrowed
WINDOW_STATS = ("windows", "lp_optimal", "lp_other", "narrowed")
_CLAMP = 1e8


@_njit
def _window_columns(row_ptr, cols, r0, r1, loc, colbuf):
    """The variables of rows ``r0 .. r1 - 1`` in order of first appearance, with ``loc``
    (global -> local index, -1 elsewhere) set for them; returns their count."""
    n = np.int64(0)
    for p in range(row_ptr[r0], row_ptr[r1]):
        j = cols[p]
        if loc[j] < 0:
            loc[j] = n
            colbuf[n] = j
            n += 1
    return n


@_njit
def _aggregate(y, Jl, Jh, gl, gh):
    """``g = J^T y`` for a real ``y`` and an interval matrix, rounded outward."""
    m, n = Jl.shape
    for j in range(n):
        gl[j] = 0.0
        gh[j] = 0.0
    for q in range(m):
        if y[q] == 0.0:
            continue
        for j in range(n):
            if Jl[q, j] == 0.0 and Jh[q, j] == 0.0:
                continue
            sl, sh = _scale(y[q], Jl[q, j], Jh[q, j])
            gl[j] = _nan_lo(add_dn(gl[j], sl))
            gh[j] = _nan_hi(add_up(gh[j], sh))


@_njit
def _clean(y, zl, zh):
    """Zero the multipliers whose sign would make the lower end of ``y . s`` infinite (a row
    bounded on one side only, with a multiplier of the wrong sign left by rounding in the
    simplex): the bound the programme finds is on that end, and any ``y`` is sound."""
    for q in range(y.size):
        if (y[q] > 0.0 and zl[q] == -INF) or (y[q] < 0.0 and zh[q] == INF):
            y[q] = 0.0


@_njit
def _narrow(i, y, zl, zh, gl, gh, dl, dh):
    """Contract ``d_i`` with the aggregated row (module docstring), in place. Returns -1 when
    the row proves that no solution is left, 1 when ``d_i`` narrowed, 0 otherwise."""
    if gl[i] <= 0.0 <= gh[i]:
        return 0
    rl, rh = 0.0, 0.0  # y . Z - sum_{j != i} g_j D_j
    for q in range(y.size):
        if y[q] != 0.0:
            sl, sh = _scale(y[q], zl[q], zh[q])
            rl, rh = _nan_lo(add_dn(rl, sl)), _nan_hi(add_up(rh, sh))
    for j in range(gl.size):
        if j != i:
            tl, th = _term(gl[j], gh[j], dl[j], dh[j])
            rl, rh = _nan_lo(add_dn(rl, -th)), _nan_hi(add_up(rh, -tl))
    if rl == -INF and rh == INF:
        return 0
    nl = _div_lo(rl, rh, gl[i], gh[i])
    nh = _div_hi(rl, rh, gl[i], gh[i])
    moved = np.int64(0)
    if nl > dl[i]:
        dl[i] = nl
        moved = 1
    if nh < dh[i]:
        dh[i] = nh
        moved = 1
    if not dl[i] <= dh[i]:
        return -1
    return moved


@_njit
def _oracle_bound(lo, hi, width):
    """A finite stand-in for an infinite bound (the oracle only has to be good)."""
    big = _CLAMP * (1.0 + width)
    return max(lo, -big), min(hi, big)


@_njit
def windows_kernel(el, eh, row_ptr, cols, fcl, fch, tl, th, xl, xh, c, win_lo, win_hi,
                   tptr, tvars, max_iter, stats):
    """Contract the box ``(xl, xh)`` (the tape's variables, in place) window by window.

    ``el, eh`` are the Jacobian entries over the box in the tape's sparsity pattern
    (``row_ptr``, ``cols``), ``fcl, fch`` the outputs at the centre ``c`` (an enclosure),
    ``tl, th`` the targets. Window ``w`` is rows ``win_lo[w] .. win_hi[w] - 1``; its targets are
    ``tvars[tptr[w]:tptr[w + 1]]``. Returns False when a window proves that the box holds no
    solution.
    """
    n_vars = xl.size
    loc = np.full(n_vars, -1, dtype=np.int64)
    colbuf = np.empty(n_vars, dtype=np.int64)
    for w in range(win_lo.size):
        if tptr[w + 1] == tptr[w]:
            continue
        r0, r1 = win_lo[w], win_hi[w]
        m = r1 - r0
        n = _window_columns(row_ptr, cols, r0, r1, loc, colbuf)
        stats[0] += 1
        Jl = np.zeros((m, n))
        Jh = np.zeros((m, n))
        A = np.zeros((m, n))
        for q in range(m):
            for p in range(row_ptr[r0 + q], row_ptr[r0 + q + 1]):
                j = loc[cols[p]]
                Jl[q, j], Jh[q, j] = el[p], eh[p]
                if math.isfinite(el[p]) and math.isfinite(eh[p]):
                    A[q, j] = 0.5 * el[p] + 0.5 * eh[p]
        zl = np.empty(m)
        zh = np.empty(m)
        lb_s = np.empty(m)
        ub_s = np.empty(m)
        for q in range(m):
            zl[q] = _nan_lo(sub_dn(tl[r0 + q], fch[r0 + q]))
            zh[q] = _nan_hi(sub_up(th[r0 + q], fcl[r0 + q]))
        dl = np.empty(n)
        dh = np.empty(n)
        lb_d = np.empty(n)
        ub_d = np.empty(n)
        wmax = 0.0
        for k in range(n):
            g = colbuf[k]
            dl[k] = _nan_lo(sub_dn(xl[g], c[g]))
            dh[k] = _nan_hi(sub_up(xh[g], c[g]))
            if math.isfinite(dh[k] - dl[k]):
                wmax = max(wmax, dh[k] - dl[k])
        for k in range(n):
            lb_d[k], ub_d[k] = _oracle_bound(dl[k], dh[k], wmax)
        for q in range(m):
            # the oracle's rows hold mid(J) d: widen them by what the rest of J adds, so that
            # its programme is feasible whenever the box holds a solution
            e = 0.0
            for k in range(n):
                if Jl[q, k] != 0.0 or Jh[q, k] != 0.0:
                    e += 0.5 * (Jh[q, k] - Jl[q, k]) * max(abs(dl[k]), abs(dh[k]))
            # a row's value never leaves the range of mid(J) d over the (clamped) box: an
            # infinite side becomes that range, not a huge number
            reach = 1.0
            for k in range(n):
                if A[q, k] != 0.0:
                    reach += abs(A[q, k]) * max(abs(lb_d[k]), abs(ub_d[k]))
            lb_s[q] = max(zl[q] - e, -reach)
            ub_s[q] = min(zh[q] + e, reach)
        # the oracle's programme: a column that occurs in one row only and is no target is
        # folded into that row's bounds (exact for the programme, and its multipliers are
        # the same): on a chain that leaves the states, not the noises and measurements
        cnt = np.zeros(n, dtype=np.int64)
        for q in range(m):
            for k in range(n):
                if Jl[q, k] != 0.0 or Jh[q, k] != 0.0:
                    cnt[k] += 1
        lpcol = np.full(n, -1, dtype=np.int64)
        for t in range(tptr[w], tptr[w + 1]):
            lpcol[loc[tvars[t]]] = 0
        nl = np.int64(0)
        for k in range(n):
            if cnt[k] >= 2 or lpcol[k] == 0:
                lpcol[k] = nl
                nl += 1
            else:
                for q in range(m):
                    a = A[q, k]
                    if a != 0.0:
                        lb_s[q] -= max(a * lb_d[k], a * ub_d[k])
                        ub_s[q] -= min(a * lb_d[k], a * ub_d[k])
        A_lp = np.empty((m, nl))
        lb_lp = np.empty(nl)
        ub_lp = np.empty(nl)
        for k in range(n):
            p = lpcol[k]
            if p >= 0:
                A_lp[:, p] = A[:, k]
                lb_lp[p], ub_lp[p] = lb_d[k], ub_d[k]
        T = np.empty((m, nl + m))
        x = np.empty(nl + m)
        lb = np.empty(nl + m)
        ub = np.empty(nl + m)
        basis = np.empty(m, dtype=np.int64)
        nonbasic = np.empty(nl + m, dtype=np.int64)
        obj = np.zeros(nl + m)
        gl = np.empty(n)
        gh = np.empty(n)
        lp_setup(A_lp, lb_lp, ub_lp, lb_s, ub_s, T, x, lb, ub, basis, nonbasic)
        first = np.int64(1)
        feasible = True
        for t in range(tptr[w], tptr[w + 1]):
            i = loc[tvars[t]]
            if i < 0 or not feasible:
                continue
            o = lpcol[i]
            for sign in (1.0, -1.0):
                obj[o] = sign
                status = lp_solve(T, x, lb, ub, basis, nonbasic, obj, first, max_iter)
                if status != LP_OPTIMAL:
                    obj[o] = 0.0
                    stats[2] += 1
                    if first:  # the linearisation with mid(J) has no solution: no oracle
                        feasible = False
                        break
                    lp_setup(A_lp, lb_lp, ub_lp, lb_s, ub_s, T, x, lb, ub, basis, nonbasic)
                    first = np.int64(1)
                    continue
                first = np.int64(0)
                stats[1] += 1
                y = multipliers(T, basis, obj, nl)
                obj[o] = 0.0
                _clean(y, zl, zh)
                _aggregate(y, Jl, Jh, gl, gh)
                res = _narrow(i, y, zl, zh, gl, gh, dl, dh)
                if res < 0:
                    return False
                stats[3] += res
        for k in range(n):
            g = colbuf[k]
            xl[g] = max(xl[g], add_dn(c[g], dl[k]))
            xh[g] = min(xh[g], add_up(c[g], dh[k]))
            loc[g] = -1
            if not xl[g] <= xh[g]:
                return False
    return True


@_njit
def batch_kernel(el, eh, row_ptr, cols, fcl, fch, tl, th, xl, xh, c, max_iter, stats):
    """:func:`windows_kernel` on each box of a batch (``(n_boxes, ...)`` arrays), with one
    window holding every constraint and every variable a target; an empty box gets NaN
    bounds."""
    m = row_ptr.size - 1
    n = xl.shape[1]
    win_lo = np.zeros(1, dtype=np.int64)
    win_hi = np.full(1, m, dtype=np.int64)
    tptr = np.array([0, n], dtype=np.int64)
    tvars = np.arange(n, dtype=np.int64)
    for bx in range(xl.shape[0]):
        if not np.all(xl[bx] <= xh[bx]) or m == 0:
            continue
        if not windows_kernel(el[bx], eh[bx], row_ptr, cols, fcl[bx], fch[bx], tl[bx], th[bx],
                              xl[bx], xh[bx], c[bx], win_lo, win_hi, tptr, tvars, max_iter,
                              stats):
            xl[bx, :] = np.nan
            xh[bx, :] = np.nan


def assign_targets(tape: FunctionTape, targets: NDArray[np.int64], size: int, stride: int
                   ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64],
                              NDArray[np.int64]]:
    """Windows of ``size`` consecutive outputs every ``stride`` and, for each, the targets
    (variable indices) that lie most central in it: each target goes to the window whose
    middle is nearest the middle of the rows it occurs in. Returns ``(win_lo, win_hi, tptr,
    tvars)``."""
    m = tape.n_outputs
    if size < 1 or stride < 1:
        raise ValueError(f"window size and stride must be positive, got {size}, {stride}")
    starts = np.arange(0, max(m - size, 0) + stride, stride, dtype=np.int64)
    starts = starts[starts < max(m, 1)]
    win_lo = starts
    win_hi = np.minimum(starts + size, m)
    rows = np.repeat(np.arange(m), np.diff(tape.row_ptr))
    first = np.full(tape.n_vars, m, dtype=np.int64)
    last = np.full(tape.n_vars, -1, dtype=np.int64)
    np.minimum.at(first, tape.cols, rows)
    np.maximum.at(last, tape.cols, rows)
    targets = np.asarray(targets, dtype=np.int64)
    targets = targets[last[targets] >= 0]  # variables that occur in no constraint
    middle = 0.5 * (first[targets] + last[targets])
    centre = 0.5 * (win_lo + win_hi - 1)
    owner = np.abs(middle[:, None] - centre[None, :]).argmin(axis=1)
    order = np.argsort(owner, kind="stable")
    tvars = targets[order]
    tptr = np.zeros(len(win_lo) + 1, dtype=np.int64)
    np.add.at(tptr, owner + 1, 1)
    return win_lo, win_hi, np.cumsum(tptr), tvars


def contract_windows(tape: FunctionTape, xl: NDArray[np.float64], xh: NDArray[np.float64],
                     windows: tuple, max_iter: int = 0) -> tuple[bool, NDArray[np.int64]]:
    """One pass of the window contraction over the box ``(xl, xh)`` (in place): the Jacobian
    and the centre are computed over the box as it is at the start. Returns whether the box
    may hold a solution and the counters (:data:`WINDOW_STATS`)."""
    from ..interval import Interval
    from .derivatives import evaluate, jacobian_sparse, midpoint

    box = Interval.trusted(xl.copy(), xh.copy())
    c = midpoint(box)
    _, entries = jacobian_sparse(tape, box)
    fc = evaluate(tape, Interval.trusted(c, c))
    win_lo, win_hi, tptr, tvars = windows
    stats = np.zeros(len(WINDOW_STATS), dtype=np.int64)
    if max_iter <= 0:
        size = int(np.max(win_hi - win_lo)) if len(win_lo) else 1
        max_iter = 20 * size + 200
    ok = windows_kernel(entries.lo, entries.hi, tape.row_ptr, tape.cols, fc.lo, fc.hi,
                        tape.target_lo, tape.target_hi, xl, xh, c, win_lo, win_hi, tptr, tvars,
                        max_iter, stats)
    return bool(ok), stats
