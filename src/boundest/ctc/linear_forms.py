"""Compiled kernels for interval linear forms: preconditioning and row contraction.

The centered-form contractor and interval Newton reduce a nonlinear constraint ``f(x) in Y`` on
a box ``X`` to the interval linear system ``J d in Z`` with ``d = x - c``, ``J`` the Jacobian
enclosure and ``Z = Y - f(c)``. These kernels solve that system's projections outward:

- ``preconditioner``: Gauss-Jordan elimination with full pivoting on the midpoint matrix, which
  gives a real ``P`` with ``P mid(J)`` the identity on one pivot column per row (any real ``P``
  is sound: ``J d in Z`` implies ``(P J) d in P Z``; a good ``P`` makes the rows nearly
  decoupled, which is what makes the contraction asymptotically minimal, Jaulin 2023,
  arXiv 2307.10502);
- ``point_times``: ``P [A]`` and ``P [z]`` rounded outward;
- ``contract_rows``: for each row ``sum_j a_j d_j in r``, every ``d_j`` is intersected with
  ``(r - sum_{l != j} a_l d_l) / a_j`` (Gauss-Seidel, prefix and suffix sums so that no term
  is subtracted back out).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ..interval.algebraic import _mul_rev_all
from ..interval.rounding import add_dn, add_up, mul_dn, mul_up
from .revise import _div_hi, _div_lo, _sub_hi, _sub_lo

__all__ = ["band_preconditioner", "contract_rows", "interval_elimination", "point_times",
           "preconditioner", "square_preconditioner"]

_njit = nb.njit(cache=True, error_model="numpy")
INF = math.inf


@_njit
def preconditioner(A, W, pivot, used):
    """Gauss-Jordan elimination with full pivoting on ``A`` (m, n), in the workspace ``W``
    (m, n + m): afterwards ``P = W[:, n:]`` is a real (m, m) matrix with ``P A`` reduced.

    Pivots smaller than ``1e-300`` times the largest entry end the elimination (the rank
    deficient rows of ``P`` are then what elimination left, which is still a valid, if weaker,
    preconditioner). ``pivot[i]`` (m,) receives row ``i``'s pivot column, -1 if none; ``used``
    (n,) is scratch.
    """
    m, n = A.shape
    for i in range(m):
        pivot[i] = -1
        for j in range(n):
            W[i, j] = A[i, j]
        for j in range(m):
            W[i, n + j] = 1.0 if i == j else 0.0
    for j in range(n):
        used[j] = False
    scale = 0.0
    for i in range(m):
        for j in range(n):
            scale = max(scale, abs(A[i, j]))
    if not scale > 0.0 or not math.isfinite(scale):
        return
    for r in range(m):
        best, bi, bj = 0.0, -1, -1
        for i in range(r, m):
            for j in range(n):
                if not used[j] and abs(W[i, j]) > best:
                    best, bi, bj = abs(W[i, j]), i, j
        if bi < 0 or best <= 1e-300 * scale:
            break
        if bi != r:
            for j in range(n + m):
                W[r, j], W[bi, j] = W[bi, j], W[r, j]
        inv = 1.0 / W[r, bj]
        for j in range(n + m):
            W[r, j] *= inv
        for i in range(m):
            if i != r and W[i, bj] != 0.0:
                f = W[i, bj]
                for j in range(n + m):
                    W[i, j] -= f * W[r, j]
        used[bj] = True
        pivot[r] = bj


@_njit
def band_preconditioner(A, R, B, perm):
    """The banded Gauss-Jordan preconditioner of Jaulin's centered-form paper (the one Codac
    2's ``CtcInverse`` applies when ``m <= n``) for a real ``A`` (m, n), ``m <= n``.

    ``B`` (m, m) and ``perm`` (m,) are scratch. An LU factorisation with partial (row)
    pivoting of the first ``m`` columns gives ``R = L^-1 Perm`` with ``R A`` upper triangular
    in those columns; then, for ``i = m - 1 .. 1``, row ``i`` eliminates column ``i + n - m``
    from the rows above it. Row ``i`` of ``R A`` is then zero outside columns
    ``i .. i + n - m``: every variable is in few rows, and the rows are nearly decoupled (for
    a square ``A``, ``R A`` is diagonal: Gauss-Jordan). Any real ``R`` is sound. Writes ``R``
    (m, m) and returns the reciprocal condition number (1-norm) of the first ``m`` columns,
    0 when they are singular (then ``R`` is the identity).
    """
    m, n = A.shape
    p = n - m
    norm = 0.0
    for j in range(m):
        s = 0.0
        for i in range(m):
            B[i, j] = A[i, j]
            s += abs(A[i, j])
        norm = max(norm, s)
    for i in range(m):
        perm[i] = i
    singular = not (norm > 0.0 and math.isfinite(norm))
    for k in range(m):
        if singular:
            break
        bi, best = k, abs(B[k, k])
        for i in range(k + 1, m):
            if abs(B[i, k]) > best:
                bi, best = i, abs(B[i, k])
        if not best > 0.0:
            singular = True
            break
        if bi != k:
            for j in range(m):
                B[k, j], B[bi, j] = B[bi, j], B[k, j]
            perm[k], perm[bi] = perm[bi], perm[k]
        for i in range(k + 1, m):
            f = B[i, k] / B[k, k]
            B[i, k] = f
            for j in range(k + 1, m):
                B[i, j] -= f * B[k, j]
    for i in range(m):
        for j in range(m):
            R[i, j] = 0.0
        R[i, i] = 1.0
    if singular:
        return 0.0
    # the 1-norm of the inverse, column by column: B^-1 e_j = U^-1 L^-1 Perm e_j
    inv_norm = 0.0
    for j in range(m):
        s = 0.0
        for i in range(m):  # R is scratch for one column here: solve L y = Perm e_j, U x = y
            v = 1.0 if perm[i] == j else 0.0
            for k in range(i):
                v -= B[i, k] * R[k, 0]
            R[i, 0] = v
        for i in range(m - 1, -1, -1):
            v = R[i, 0]
            for k in range(i + 1, m):
                v -= B[i, k] * R[k, 0]
            R[i, 0] = v / B[i, i]
            s += abs(R[i, 0])
        inv_norm = max(inv_norm, s)
    # R = L^-1 Perm
    for i in range(m):
        for j in range(m):
            R[i, j] = 1.0 if perm[i] == j else 0.0
        for k in range(i):
            f = B[i, k]
            if f != 0.0:
                for j in range(m):
                    R[i, j] -= f * R[k, j]
    # rising: row i clears column i + p in the rows above it
    for i in range(m - 1, 0, -1):
        col = i + p
        piv = 0.0
        for k in range(m):
            piv += R[i, k] * A[k, col]
        if piv == 0.0 or not math.isfinite(piv):
            continue
        for r in range(i):
            u = 0.0
            for k in range(m):
                u += R[r, k] * A[k, col]
            f = u / piv
            if f != 0.0:
                for k in range(m):
                    R[r, k] -= f * R[i, k]
    rc = 1.0 / (norm * inv_norm)
    return rc if rc == rc else 0.0


@_njit
def interval_elimination(gl, gh, zl, zh, M, rp, cp):
    """Interval Gaussian elimination of ``G d in z`` (``gl, gh`` (m, n), ``zl, zh`` (m,), in
    place) with the pivots of full pivoting on ``M`` (m, n: a real matrix, ``mid(G)``,
    overwritten).

    Step ``k`` takes pivot row ``rp[k]`` and column ``cp[k]`` and, for every row ``i`` below,
    the interval multiplier ``l = G[i, c] / G[r, c]`` (it holds ``S[i, c] / S[r, c]`` for
    every real ``S`` in ``G``), so that ``row_i - l row_r`` has a zero in column ``c`` for that
    ``S``: column ``c`` is set to 0 and the other entries and ``z_i`` get ``- l G[r, j]``,
    ``- l z_r`` (rounded outward). Every row stays sound: for the ``S`` and ``s in z`` of a
    solution, ``(S_i - l S_r) d = s_i - l s_r`` holds with the multiplier's true value. The
    first ``min(m, n)`` rows in ``rp`` order are then upper triangular in the columns ``cp``;
    the rows after them (when ``m > n``) have only zeros left: ``0 in z_i`` is their
    consistency test. Elimination stops at a pivot interval containing 0. ``rp`` (m,) and
    ``cp`` (n,) receive the pivot order; returns the number of steps done.
    """
    m, n = gl.shape
    for i in range(m):
        rp[i] = i
    for j in range(n):
        cp[j] = j
    steps = 0
    for k in range(min(m, n)):
        best, bi, bj = 0.0, -1, -1
        for i in range(k, m):
            for j in range(k, n):
                v = abs(M[rp[i], cp[j]])
                if v > best:
                    best, bi, bj = v, i, j
        if bi < 0 or not math.isfinite(best):
            break
        rp[k], rp[bi] = rp[bi], rp[k]
        cp[k], cp[bj] = cp[bj], cp[k]
        r, c = rp[k], cp[k]
        for i in range(k + 1, m):
            f = M[rp[i], c] / M[r, c]
            for j in range(k, n):
                M[rp[i], cp[j]] -= f * M[r, cp[j]]
        pl, ph = gl[r, c], gh[r, c]
        if pl <= 0.0 <= ph or not (pl <= ph):
            break
        for i in range(k + 1, m):
            q = rp[i]
            if gl[q, c] == 0.0 and gh[q, c] == 0.0:
                continue
            ll = _nan_lo(_div_lo(gl[q, c], gh[q, c], pl, ph))
            lh = _nan_hi(_div_hi(gl[q, c], gh[q, c], pl, ph))
            gl[q, c] = gh[q, c] = 0.0
            for t in range(k + 1, n):
                j = cp[t]
                if gl[r, j] == 0.0 and gh[r, j] == 0.0:
                    continue
                sl, sh = _term(ll, lh, gl[r, j], gh[r, j])
                gl[q, j] = _nan_lo(_sub_lo(gl[q, j], gh[q, j], sl, sh))
                gh[q, j] = _nan_hi(_sub_hi(gl[q, j], gh[q, j], sl, sh))
            sl, sh = _term(ll, lh, zl[r], zh[r])
            a, b = _sub_lo(zl[q], zh[q], sl, sh), _sub_hi(zl[q], zh[q], sl, sh)
            zl[q], zh[q] = _nan_lo(a), _nan_hi(b)
        steps = k + 1
    return steps


@nb.njit(cache=True, inline="always", error_model="numpy")
def _scale(p, lo, hi):
    """``p * [lo, hi]`` rounded outward (``p`` real; ``0 * inf = 0``)."""
    if p == 0.0:
        return 0.0, 0.0
    if p > 0.0:
        return mul_dn(p, lo), mul_up(p, hi)
    return mul_dn(p, hi), mul_up(p, lo)


@_njit
def point_times(P, lo, hi, rl, rh):
    """``[rl, rh] = P [lo, hi]`` for a real ``P`` (m, k) and an interval matrix ``(k, n)``
    rounded outward (``rl, rh`` (m, n) are written). An inf - inf sum is the entire line. Only
    the nonzero entries of the interval matrix are visited (Jacobians of local constraints are
    sparse)."""
    m, k = P.shape
    n = lo.shape[1]
    for i in range(m):
        for j in range(n):
            rl[i, j] = 0.0
            rh[i, j] = 0.0
    for q in range(k):
        for j in range(n):
            ql, qh = lo[q, j], hi[q, j]
            if ql == 0.0 and qh == 0.0:
                continue
            for i in range(m):
                p = P[i, q]
                if p == 0.0:
                    continue
                sl, sh = _scale(p, ql, qh)
                rl[i, j] = add_dn(rl[i, j], sl)
                rh[i, j] = add_up(rh[i, j], sh)
    for i in range(m):
        for j in range(n):
            if rl[i, j] != rl[i, j]:
                rl[i, j] = -INF
            if rh[i, j] != rh[i, j]:
                rh[i, j] = INF


@_njit
def contract_rows(al, ah, rl, rh, dl, dh, reverse, work):
    """Contract ``d`` (in place) with the rows ``sum_j [a_ij] d_j in [r_i]``, first to last
    (last to first with ``reverse``).

    ``al, ah`` (m, n), ``rl, rh`` (m,), ``dl, dh`` (n,), ``work`` (6, n + 1) scratch. In each
    row, for ``j = 0 .. n - 1``, ``N = r - sum_{l != j} a_l d_l`` (prefix sums over the
    already contracted ``d_0 .. d_{j-1}``, suffix sums over the others) and the product
    ``a_j d_j in N`` is inverted both ways (relational division, as HC4 does on a product
    node): ``a_j`` first, then ``d_j`` by the contracted ``a_j``, with the two-piece quotient
    when ``a_j`` contains 0. The coefficient stays contracted in ``al, ah``: each row is one
    relation ``s . d in r`` with its own real ``s`` in the row's intervals, so a later sweep of
    the same rows may use it. Returns False when some row has no solution in the box (then
    ``d`` is partly updated and must be discarded), True otherwise.
    """
    m, n = al.shape
    pl, ph, ql, qh = work[0], work[1], work[2], work[3]
    tl, th = work[4], work[5]
    for step in range(m):
        i = m - 1 - step if reverse else step
        for j in range(n):
            tl[j], th[j] = _term(al[i, j], ah[i, j], dl[j], dh[j])
        if _inactive(tl, th, rl[i], rh[i], n):
            continue
        pl[0] = ph[0] = 0.0
        for j in range(n):
            pl[j + 1] = _nan_lo(add_dn(pl[j], tl[j]))
            ph[j + 1] = _nan_hi(add_up(ph[j], th[j]))
        ql[n] = qh[n] = 0.0
        for j in range(n - 1, -1, -1):
            ql[j] = _nan_lo(add_dn(ql[j + 1], tl[j]))
            qh[j] = _nan_hi(add_up(qh[j + 1], th[j]))
        # the row's range must meet r
        if pl[n] > rh[i] or ph[n] < rl[i]:
            return False
        for j in range(n):
            if al[i, j] == 0.0 and ah[i, j] == 0.0:
                pl[j + 1], ph[j + 1] = pl[j], ph[j]
                continue
            # others = prefix(j) + suffix(j + 1), with the already contracted d_0..d_{j-1}
            ol = _nan_lo(add_dn(pl[j], ql[j + 1]))
            oh = _nan_hi(add_up(ph[j], qh[j + 1]))
            nl = _nan_lo(_sub_lo(rl[i], rh[i], ol, oh))
            nh = _nan_hi(_sub_hi(rl[i], rh[i], ol, oh))
            if nl <= tl[j] and th[j] <= nh:
                # a_j d_j already lies in N: every (a, d) of the domains satisfies the row, so
                # relational division contracts nothing (exactly; it would round outward)
                pl[j + 1] = _nan_lo(add_dn(pl[j], tl[j]))
                ph[j + 1] = _nan_hi(add_up(ph[j], th[j]))
                continue
            a0, a1, x0, x1 = _mul_rev_all(nl, nh, al[i, j], ah[i, j], dl[j], dh[j])
            if not (a0 <= a1 and x0 <= x1):
                return False
            al[i, j], ah[i, j], dl[j], dh[j] = a0, a1, x0, x1
            # the prefix sums after j use the contracted a_j and d_j
            tl[j], th[j] = _term(a0, a1, x0, x1)
            pl[j + 1] = _nan_lo(add_dn(pl[j], tl[j]))
            ph[j + 1] = _nan_hi(add_up(ph[j], th[j]))
    return True


@nb.njit(cache=True, inline="always", error_model="numpy")
def _inactive(tl, th, rl, rh, n):
    """Whether a row whose terms are ``[tl_j, th_j]`` contracts nothing: every term lies in
    ``r`` minus the sum of the others, i.e. ``rl <= S_hi - w`` and ``S_lo + w <= rh`` for the
    sums ``S`` of the terms and their largest width ``w`` (so the row's range meets ``r`` as
    well). Decided in round-to-nearest, true only with a margin above the rounding errors of
    the sums (Higham's ``gamma_n`` bound, doubled, and an underflow floor): then the outward
    rounded row sweep of :func:`contract_rows` would skip every term too, so skipping the row
    changes no bit. False (do the sweep) when unsure, and for infinite terms or targets."""
    sl = sh = mag = w = 0.0
    for j in range(n):
        sl += tl[j]
        sh += th[j]
        mag += abs(tl[j]) + abs(th[j])
        w = max(w, th[j] - tl[j])
    e = (n + 4) * (2.0**-52 * (mag + abs(rl) + abs(rh)) + 2.0**-1074)
    return (sh - w) - rl >= e and rh - (sl + w) >= e


@nb.njit(cache=True, inline="always", error_model="numpy")
def _nan_lo(x):
    return x if x == x else -INF


@nb.njit(cache=True, inline="always", error_model="numpy")
def _nan_hi(x):
    return x if x == x else INF


@nb.njit(cache=True, inline="always", error_model="numpy")
def _term(al_, ah, xl, xh):
    """``[a] [x]`` rounded outward, ``0 * inf = 0``, an empty result as the entire line. The
    signs of the bounds select the extreme corners (two products, not eight)."""
    if (al_ == 0.0 and ah == 0.0) or (xl == 0.0 and xh == 0.0):
        return 0.0, 0.0
    if xl >= 0.0:
        if al_ >= 0.0:
            lo, hi = _mdn(al_, xl), _mup(ah, xh)
        elif ah <= 0.0:
            lo, hi = _mdn(al_, xh), _mup(ah, xl)
        else:
            lo, hi = _mdn(al_, xh), _mup(ah, xh)
    elif xh <= 0.0:
        if al_ >= 0.0:
            lo, hi = _mdn(ah, xl), _mup(al_, xh)
        elif ah <= 0.0:
            lo, hi = _mdn(ah, xh), _mup(al_, xl)
        else:
            lo, hi = _mdn(ah, xl), _mup(al_, xl)
    elif al_ >= 0.0:
        lo, hi = _mdn(ah, xl), _mup(ah, xh)
    elif ah <= 0.0:
        lo, hi = _mdn(al_, xh), _mup(al_, xl)
    else:
        lo = min(_mdn(al_, xh), _mdn(ah, xl))
        hi = max(_mup(al_, xl), _mup(ah, xh))
    return _nan_lo(lo), _nan_hi(hi)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _mdn(a, b):
    return 0.0 if (a == 0.0 or b == 0.0) else mul_dn(a, b)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _mup(a, b):
    return 0.0 if (a == 0.0 or b == 0.0) else mul_up(a, b)


@_njit
def square_preconditioner(A, W, pivot, used):
    """:func:`preconditioner`'s output (``P = W[:, n:]``, ``pivot``) for a square ``A``, by LU
    with partial pivoting that skips zero entries: ``P ~ A^-1`` (``pivot[i] = i``), each row of
    ``P`` without its entries below ``1e-20`` times its largest (the inverse of a banded matrix
    decays away from the band), in about ``O(n nnz(L + U))`` where the full-pivoting
    Gauss-Jordan elimination is ``O(n^3)`` (a banded Jacobian of 1000 unknowns: a few ms
    against 0.7-2 s). A pivot below ``1e-13`` times the largest entry of ``A`` (singular or
    nearly so) hands the matrix to :func:`preconditioner`, which copes with rank deficiency.
    Any real ``P`` is sound; this one only decides how much the rows contract.
    """
    n = A.shape[0]
    scale = 0.0
    for i in range(n):
        for j in range(n):
            scale = max(scale, abs(A[i, j]))
    if not scale > 0.0 or not math.isfinite(scale):
        preconditioner(A, W, pivot, used)
        return
    LU = A.copy()
    row = np.arange(n)  # row k of LU is row row[k] of A
    last = np.zeros(n, dtype=np.int64)  # the last nonzero column of each row of LU
    for i in range(n):
        for j in range(n - 1, -1, -1):
            if LU[i, j] != 0.0:
                last[i] = j
                break
    for k in range(n):
        p, best = k, abs(LU[k, k])
        for i in range(k + 1, n):
            if abs(LU[i, k]) > best:
                p, best = i, abs(LU[i, k])
        if not best > 1e-13 * scale:
            preconditioner(A, W, pivot, used)
            return
        if p != k:
            for j in range(n):
                LU[k, j], LU[p, j] = LU[p, j], LU[k, j]
            row[k], row[p] = row[p], row[k]
            last[k], last[p] = last[p], last[k]
        inv = 1.0 / LU[k, k]
        for i in range(k + 1, n):
            if LU[i, k] != 0.0:
                f = LU[i, k] * inv
                LU[i, k] = f
                for j in range(k + 1, last[k] + 1):
                    LU[i, j] -= f * LU[k, j]
                last[i] = max(last[i], last[k])
    # P = U^-1 L^-1 (rows permuted): forward then back substitution, one row of P at a time,
    # each row kept within the span of its nonzero columns; an entry below 1e-20 times the
    # largest of its row is dropped (the inverse of a banded matrix decays away from the band:
    # what is dropped would only add subnormal arithmetic, and any real P is sound)
    P = np.zeros((n, n))
    c0 = np.empty(n, dtype=np.int64)
    c1 = np.empty(n, dtype=np.int64)
    for i in range(n):
        P[i, row[i]] = 1.0
        a, b = row[i], row[i]
        for j in range(i):
            f = LU[i, j]
            if f != 0.0 and c0[j] <= c1[j]:
                for c in range(c0[j], c1[j] + 1):
                    P[i, c] -= f * P[j, c]
                a, b = min(a, c0[j]), max(b, c1[j])
        c0[i], c1[i] = _trim(P, i, a, b)
    for i in range(n - 1, -1, -1):
        a, b = c0[i], c1[i]
        for j in range(i + 1, last[i] + 1):
            f = LU[i, j]
            if f != 0.0 and c0[j] <= c1[j]:
                for c in range(c0[j], c1[j] + 1):
                    P[i, c] -= f * P[j, c]
                a, b = min(a, c0[j]), max(b, c1[j])
        inv = 1.0 / LU[i, i]
        for c in range(a, b + 1):
            P[i, c] *= inv
        c0[i], c1[i] = _trim(P, i, a, b)
    for i in range(n):
        for c in range(c0[i], c1[i] + 1):
            if not math.isfinite(P[i, c]):
                preconditioner(A, W, pivot, used)
                return
    for i in range(n):
        pivot[i] = i
        for j in range(n):
            W[i, j] = 0.0  # (the reduced matrix is not needed: rows are in variable order)
            W[i, n + j] = P[i, j]


@_njit
def _trim(P, i, a, b):
    """Zero the entries of row ``i`` of ``P`` in columns ``a..b`` below ``1e-20`` times the
    largest; returns the span of what is left (``a > b`` if nothing)."""
    big = 0.0
    for c in range(a, b + 1):
        big = max(big, abs(P[i, c]))
    cut = 1e-20 * big
    lo, hi = b + 1, a - 1
    for c in range(a, b + 1):
        if abs(P[i, c]) < cut or P[i, c] == 0.0:
            P[i, c] = 0.0
        else:
            lo, hi = min(lo, c), max(hi, c)
    return lo, hi
