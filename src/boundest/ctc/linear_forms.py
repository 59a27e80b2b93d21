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

from ..interval.rounding import add_dn, add_up, mul_dn, mul_up
from .revise import _div_hi, _div_lo, _sub_hi, _sub_lo

__all__ = ["contract_rows", "csr_times", "point_times", "preconditioner", "square_preconditioner"]

_njit = nb.njit(cache=True, error_model="numpy")
INF = math.inf


@_njit
def preconditioner(A):
    """A real ``P`` (m, m) with ``P A`` reduced by Gauss-Jordan with full pivoting.

    Pivots smaller than ``1e-300`` times the largest entry end the elimination (the rank
    deficient rows of ``P`` are then what elimination left, which is still a valid, if weaker,
    preconditioner). Returns ``(P, pivot)``: ``pivot[i]`` is row ``i``'s pivot column, -1 if
    none.
    """
    m, n = A.shape
    W = np.empty((m, n + m))
    W[:, :n] = A
    W[:, n:] = 0.0
    for i in range(m):
        W[i, n + i] = 1.0
    pivot = np.full(m, -1, dtype=np.int64)
    used = np.zeros(n, dtype=np.bool_)
    scale = 0.0
    for i in range(m):
        for j in range(n):
            scale = max(scale, abs(A[i, j]))
    if not scale > 0.0 or not math.isfinite(scale):
        return W[:, n:].copy(), pivot
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
    return W[:, n:].copy(), pivot


@nb.njit(cache=True, inline="always", error_model="numpy")
def _scale(p, lo, hi):
    """``p * [lo, hi]`` rounded outward (``p`` real; ``0 * inf = 0``)."""
    if p == 0.0:
        return 0.0, 0.0
    if p > 0.0:
        return mul_dn(p, lo), mul_up(p, hi)
    return mul_dn(p, hi), mul_up(p, lo)


@_njit
def point_times(P, lo, hi):
    """``P [lo, hi]`` for a real ``P`` (m, k) and an interval matrix ``(k, n)`` rounded
    outward; returns ``(lo, hi)`` of shape (m, n). An inf - inf sum is the entire line. Only
    the nonzero entries of each row of the interval matrix are visited (Jacobians of local
    constraints are sparse)."""
    m, k = P.shape
    n = lo.shape[1]
    rl = np.zeros((m, n))
    rh = np.zeros((m, n))
    nz = np.empty(n, dtype=np.int64)
    for q in range(k):
        cnt = 0
        for j in range(n):
            if lo[q, j] != 0.0 or hi[q, j] != 0.0:
                nz[cnt] = j
                cnt += 1
        if cnt == 0:
            continue
        for i in range(m):
            p = P[i, q]
            if p == 0.0:
                continue
            for t in range(cnt):
                j = nz[t]
                sl, sh = _scale(p, lo[q, j], hi[q, j])
                rl[i, j] = add_dn(rl[i, j], sl)
                rh[i, j] = add_up(rh[i, j], sh)
    for i in range(m):
        for j in range(n):
            if rl[i, j] != rl[i, j]:
                rl[i, j] = -INF
            if rh[i, j] != rh[i, j]:
                rh[i, j] = INF
    return rl, rh


@_njit
def contract_rows(al, ah, rl, rh, dl, dh):
    """Contract ``d`` (in place) with the rows ``sum_j [a_ij] d_j in [r_i]``.

    ``al, ah`` (m, n), ``rl, rh`` (m,), ``dl, dh`` (n,). Returns False when some row has no
    solution in the box (then ``d`` is partly updated and must be discarded), True otherwise.
    """
    m, n = al.shape
    pl = np.empty(n + 1)
    ph = np.empty(n + 1)
    ql = np.empty(n + 1)
    qh = np.empty(n + 1)
    tl = np.empty(n)
    th = np.empty(n)
    for i in range(m):
        for j in range(n):
            tl[j], th[j] = _term(al[i, j], ah[i, j], dl[j], dh[j])
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
            if al[i, j] <= 0.0 <= ah[i, j]:
                continue  # a divisor containing 0: no contraction from this row
            # others = prefix(j) + suffix(j + 1), with the already contracted d_0..d_{j-1}
            ol = _nan_lo(add_dn(pl[j], ql[j + 1]))
            oh = _nan_hi(add_up(ph[j], qh[j + 1]))
            nl = _sub_lo(rl[i], rh[i], ol, oh)
            nh = _sub_hi(rl[i], rh[i], ol, oh)
            xl = _div_lo(nl, nh, al[i, j], ah[i, j])
            xh = _div_hi(nl, nh, al[i, j], ah[i, j])
            if xl > dl[j]:
                dl[j] = xl
            if xh < dh[j]:
                dh[j] = xh
            if not dl[j] <= dh[j]:
                return False
            # the prefix sums after j use the contracted d_j
            tl[j], th[j] = _term(al[i, j], ah[i, j], dl[j], dh[j])
            pl[j + 1] = _nan_lo(add_dn(pl[j], tl[j]))
            ph[j + 1] = _nan_hi(add_up(ph[j], th[j]))
    return True


@nb.njit(cache=True, inline="always", error_model="numpy")
def _nan_lo(x):
    return x if x == x else -INF


@nb.njit(cache=True, inline="always", error_model="numpy")
def _nan_hi(x):
    return x if x == x else INF


@nb.njit(cache=True, inline="always", error_model="numpy")
def _term(al_, ah, xl, xh):
    """``[a] [x]`` rounded outward, ``0 * inf = 0``, an empty result as the entire line."""
    if al_ == 0.0 and ah == 0.0:
        return 0.0, 0.0
    if xl == 0.0 and xh == 0.0:
        return 0.0, 0.0
    lo = min(_mdn(al_, xl), _mdn(al_, xh), _mdn(ah, xl), _mdn(ah, xh))
    hi = max(_mup(al_, xl), _mup(al_, xh), _mup(ah, xl), _mup(ah, xh))
    return _nan_lo(lo), _nan_hi(hi)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _mdn(a, b):
    return 0.0 if (a == 0.0 or b == 0.0) else mul_dn(a, b)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _mup(a, b):
    return 0.0 if (a == 0.0 or b == 0.0) else mul_up(a, b)


@_njit
def square_preconditioner(A):
    """``(P, pivot)`` as :func:`preconditioner` for a square ``A``, by LU with partial pivoting
    that skips zero entries: ``P ~ A^-1`` (``pivot[i] = i``), each row of ``P`` without its
    entries below ``1e-20`` times its largest (the inverse of a banded matrix decays away from
    the band), in about ``O(n nnz(L + U))`` where the full-pivoting Gauss-Jordan elimination is
    ``O(n^3)`` (a banded Jacobian of 1000 unknowns: a few ms against 0.7-2 s). A pivot below
    ``1e-13`` times the largest entry of ``A`` (singular or nearly so) hands the matrix to
    :func:`preconditioner`, which copes with rank deficiency. Any real ``P`` is sound; this one
    only decides how much the rows contract.
    """
    n = A.shape[0]
    scale = 0.0
    for i in range(n):
        for j in range(n):
            scale = max(scale, abs(A[i, j]))
    if not scale > 0.0 or not math.isfinite(scale):
        return preconditioner(A)
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
            return preconditioner(A)
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
                return preconditioner(A)
    return P, np.arange(n)


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


@_njit
def csr_times(P, el, eh, row_ptr, cols, n):
    """``P [J]`` rounded outward for a real ``P`` (m, k) and an interval matrix ``[J]`` (k, n)
    given by its nonzero entries in CSR form (row ``q``: columns ``cols[row_ptr[q]:row_ptr[q +
    1]]``, bounds ``el``, ``eh``): what :func:`point_times` gives on the dense matrix, in
    ``O(m nnz)``. An inf - inf sum is the entire line."""
    m, k = P.shape
    rl = np.zeros((m, n))
    rh = np.zeros((m, n))
    for i in range(m):
        for q in range(k):
            p = P[i, q]
            if p == 0.0:
                continue
            for t in range(row_ptr[q], row_ptr[q + 1]):
                j = cols[t]
                sl, sh = _scale(p, el[t], eh[t])
                rl[i, j] = add_dn(rl[i, j], sl)
                rh[i, j] = add_up(rh[i, j], sh)
    for i in range(m):
        for j in range(n):
            if rl[i, j] != rl[i, j]:
                rl[i, j] = -INF
            if rh[i, j] != rh[i, j]:
                rh[i, j] = INF
    return rl, rh
