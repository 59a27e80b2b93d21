"""A small dense simplex method: the oracle that chooses the multipliers of a centered form.

The centered-form contractors aggregate the linearised constraints ``J d = s``, ``s in Z``,
``d in D`` with a real row of multipliers ``y``: every solution satisfies
``(J^T y) . d = y . s``, whatever ``y`` (:mod:`boundest.ctc.windows` evaluates that row in
interval arithmetic, rounded outward). The bound a row gives on ``d_i`` is best for the ``y``
that solves the linear programme ``min +-d_i`` over ``A d = s, d in D, s in Z`` with the real
matrix ``A = mid(J)``: its optimal dual (LP duality: the tableau row of the optimal basis is the
aggregated row whose interval evaluation reaches the LP's optimum). So the LP is an *untrusted
oracle*: a wrong, suboptimal or unconverged ``y`` only makes the contraction weaker, never
unsound, and float rounding inside it needs no care.

The programmes are small (tens to a few hundred rows), many, and share their constraints
(``+-d_i`` for each target ``i`` of a window), so a dense tableau with warm starts suits them:
the bounded dual simplex method from the slack basis for the first objective, then the bounded
primal simplex method from the previous optimal basis for each next one (Chvatal 1983, chapter
8; Koberstein 2005 for the bounded dual simplex). Standard form: variables ``v = (d, s)``,
constraints ``[A, -I] v = 0``, every variable between finite bounds (the caller clamps
infinite ones: the oracle only has to be good, not exact); the tableau is
``T = B^-1 [A, -I]``, so ``B^-1 = -T[:, n:]`` and the multipliers are ``y = c_B^T B^-1``.
"""

from __future__ import annotations

import numba as nb
import numpy as np

__all__ = ["LP_INFEASIBLE", "LP_LIMIT", "LP_OPTIMAL", "lp_setup", "lp_solve", "multipliers"]

LP_OPTIMAL, LP_INFEASIBLE, LP_LIMIT = 0, 1, 2
_njit = nb.njit(cache=True, error_model="numpy")
_TOL = 1e-9
_DTOL = 1e-9  # dual feasibility tolerance of Harris's ratio test


@_njit
def lp_setup(A, lb_d, ub_d, lb_s, ub_s, T, x, lb, ub, basis, nonbasic):
    """Fill the tableau of the slack basis: ``T = [-A, I]``, every ``d_j`` at its lower bound,
    ``s = A d``. Arrays are preallocated by the caller: ``T (m, n + m)``, ``x, lb, ub
    (n + m)``, ``basis (m)`` (the variable of each row), ``nonbasic (n + m)`` (-1 for a basic
    variable, 0 at its lower bound, 1 at its upper bound)."""
    m, n = A.shape
    T[:, :] = 0.0
    for i in range(m):
        for j in range(n):
            T[i, j] = -A[i, j]
        T[i, n + i] = 1.0
        basis[i] = n + i
        nonbasic[n + i] = -1
        lb[n + i] = lb_s[i]
        ub[n + i] = ub_s[i]
    for j in range(n):
        lb[j] = lb_d[j]
        ub[j] = ub_d[j]
        x[j] = lb_d[j]
        nonbasic[j] = 0
    _basic_values(T, x, basis, nonbasic)


@_njit
def _basic_values(T, x, basis, nonbasic):
    """Recompute the basic values from the nonbasic ones: ``x_B = -sum_N T_j x_j``."""
    m, nt = T.shape
    for i in range(m):
        acc = 0.0
        for j in range(nt):
            if nonbasic[j] >= 0 and x[j] != 0.0:
                acc -= T[i, j] * x[j]
        x[basis[i]] = acc


@_njit
def _pivot(T, basis, nonbasic, r, j):
    m, nt = T.shape
    p = T[r, j]
    for k in range(nt):
        T[r, k] /= p
    T[r, j] = 1.0
    for i in range(m):
        if i != r:
            f = T[i, j]
            if f != 0.0:
                for k in range(nt):
                    T[i, k] -= f * T[r, k]
                T[i, j] = 0.0
    nonbasic[basis[r]] = 0  # the caller sets 0/1 (lower/upper) for the leaving variable
    nonbasic[j] = -1
    basis[r] = j


@_njit
def _reduced_costs(T, c, basis, nonbasic, r):
    """``r_j = c_j - sum_i c_basis[i] T_ij`` for the nonbasic ``j`` (0 for basic)."""
    m, nt = T.shape
    for j in range(nt):
        r[j] = c[j] if nonbasic[j] >= 0 else 0.0
    for i in range(m):
        cb = c[basis[i]]
        if cb != 0.0:
            for j in range(nt):
                if nonbasic[j] >= 0:
                    r[j] -= cb * T[i, j]


@_njit
def _update_costs(T, r, row, col):
    """The reduced costs after a pivot on ``(row, col)``: ``r -= r_col T[row]`` (the new row)."""
    rc = r[col]
    if rc != 0.0:
        for j in range(T.shape[1]):
            r[j] -= rc * T[row, j]
    r[col] = 0.0


@_njit
def _dual_simplex(T, x, lb, ub, basis, nonbasic, c, max_iter):
    """Bounded dual simplex from a dual feasible basis (nonbasic variables at the bound their
    reduced cost's sign asks for). Returns LP_OPTIMAL, LP_INFEASIBLE or LP_LIMIT."""
    m, nt = T.shape
    r = np.empty(nt)
    _reduced_costs(T, c, basis, nonbasic, r)
    for _ in range(max_iter):
        # leaving: the most infeasible basic variable
        row, worst, up = np.int64(-1), 0.0, False
        for i in range(m):
            v = basis[i]
            if x[v] < lb[v] - _TOL * (1.0 + abs(lb[v])) and lb[v] - x[v] > worst:
                row, worst, up = i, lb[v] - x[v], True
            elif x[v] > ub[v] + _TOL * (1.0 + abs(ub[v])) and x[v] - ub[v] > worst:
                row, worst, up = i, x[v] - ub[v], False
        if row < 0:
            return LP_OPTIMAL
        # entering: keep the reduced costs' signs; Harris's two passes: the largest step that
        # keeps them within a tolerance, then the largest pivot within that step (stability)
        amax = 0.0
        for j in range(nt):
            if nonbasic[j] >= 0:
                amax = max(amax, abs(T[row, j]))
        ptol = max(_TOL, 1e-7 * amax)
        bound = np.inf
        for j in range(nt):
            if nonbasic[j] < 0 or ub[j] - lb[j] <= 0.0:
                continue
            a = -T[row, j]  # d x_B[row] / d x_j
            if abs(a) < ptol:
                continue
            inc = nonbasic[j] == 0  # at its lower bound: x_j may only increase
            if (a > 0.0) == (inc == up):
                bound = min(bound, (abs(r[j]) + _DTOL) / abs(a))
        col, step = np.int64(-1), 0.0
        for j in range(nt):
            if nonbasic[j] < 0 or ub[j] - lb[j] <= 0.0:
                continue
            a = -T[row, j]
            if abs(a) < ptol:
                continue
            inc = nonbasic[j] == 0
            if (a > 0.0) == (inc == up) and abs(r[j]) / abs(a) <= bound and abs(a) > abs(step):
                col, step = j, a
        if col < 0:
            return LP_INFEASIBLE
        v = basis[row]
        target = lb[v] if up else ub[v]
        t = (target - x[v]) / step  # change of x_col
        for i in range(m):
            x[basis[i]] -= T[i, col] * t
        x[col] += t
        x[v] = target
        _pivot(T, basis, nonbasic, row, col)
        _update_costs(T, r, row, col)
        nonbasic[v] = 0 if up else 1
    return LP_LIMIT


@_njit
def _primal_simplex(T, x, lb, ub, basis, nonbasic, c, max_iter):
    """Bounded primal simplex from a primal feasible basis (Dantzig's rule, bound flips)."""
    m, nt = T.shape
    r = np.empty(nt)
    _reduced_costs(T, c, basis, nonbasic, r)
    for _ in range(max_iter):
        col, best, d = np.int64(-1), _TOL, 1.0
        for j in range(nt):
            if nonbasic[j] < 0 or ub[j] - lb[j] <= 0.0:
                continue
            if nonbasic[j] == 0 and -r[j] > best:
                col, best, d = j, -r[j], 1.0
            elif nonbasic[j] == 1 and r[j] > best:
                col, best, d = j, r[j], -1.0
        if col < 0:
            return LP_OPTIMAL
        tmax, row = ub[col] - lb[col], np.int64(-1)
        amax = 0.0
        for i in range(m):
            amax = max(amax, abs(T[i, col]))
        ptol = max(_TOL, 1e-7 * amax)
        bound = np.inf  # Harris: the largest step within the tolerance, then the largest pivot
        for i in range(m):
            a = -T[i, col] * d  # d x_B[i] / dt
            v = basis[i]
            if a > ptol:
                tol = _TOL * (1.0 + abs(ub[v]))
                bound = min(bound, (max(ub[v] - x[v], 0.0) + tol) / a)
            elif a < -ptol:
                tol = _TOL * (1.0 + abs(lb[v]))
                bound = min(bound, (max(x[v] - lb[v], 0.0) + tol) / -a)
        if bound < tmax:
            best = 0.0
            for i in range(m):
                a = -T[i, col] * d
                v = basis[i]
                if a > ptol:
                    ti = max(ub[v] - x[v], 0.0) / a
                elif a < -ptol:
                    ti = max(x[v] - lb[v], 0.0) / -a
                else:
                    continue
                if ti <= bound and abs(a) > best:
                    best, row, tmax = abs(a), i, ti
        for i in range(m):
            x[basis[i]] -= T[i, col] * d * tmax
        x[col] += d * tmax
        if row < 0:  # a bound flip
            nonbasic[col] = 1 if d > 0 else 0
            x[col] = ub[col] if d > 0 else lb[col]
            continue
        v = basis[row]
        hit_upper = -T[row, col] * d > 0.0
        x[v] = ub[v] if hit_upper else lb[v]
        _pivot(T, basis, nonbasic, row, col)
        _update_costs(T, r, row, col)
        nonbasic[v] = 1 if hit_upper else 0
    return LP_LIMIT


@_njit
def lp_solve(T, x, lb, ub, basis, nonbasic, c, dual, max_iter):
    """Minimise ``c . v`` from the current basis: the dual simplex method when ``dual`` (the
    basis must then be dual feasible for ``c``: after ``lp_setup``, put each nonbasic ``d_j``
    with ``c_j < 0`` at its upper bound first), the primal one otherwise (the basis must be
    primal feasible: an optimal basis for another objective)."""
    if dual:
        nt = T.shape[1]
        for j in range(nt):
            if nonbasic[j] >= 0:
                up = c[j] < 0.0
                nonbasic[j] = 1 if up else 0
                x[j] = ub[j] if up else lb[j]
        _basic_values(T, x, basis, nonbasic)
        return _dual_simplex(T, x, lb, ub, basis, nonbasic, c, max_iter)
    _basic_values(T, x, basis, nonbasic)
    return _primal_simplex(T, x, lb, ub, basis, nonbasic, c, max_iter)


@_njit
def multipliers(T, basis, c, n):
    """The multipliers ``y = c_B^T B^-1`` (one per row) of the current basis."""
    m = T.shape[0]
    y = np.zeros(m)
    for i in range(m):
        cb = c[basis[i]]
        if cb != 0.0:
            for q in range(m):
                y[q] -= cb * T[i, n + q]
    return y
