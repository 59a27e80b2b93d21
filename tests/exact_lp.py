"""A tiny exact LP solver for the tests: vertex enumeration in rational arithmetic.

``min c^T x`` subject to ``b_lo <= A x <= b_hi`` and ``l <= x <= u`` (infinite bounds allowed),
for a handful of variables: every vertex is the solution of ``n`` linearly independent active
constraints, solved exactly with ``fractions.Fraction``. Infinite bounds are replaced by
``+-M`` for two values of ``M`` far beyond every vertex of the data; an optimum that moves with
``M`` means the LP is unbounded below.
"""

from __future__ import annotations

import itertools
import math
from fractions import Fraction

import numpy as np


def _solve(G: list[list[Fraction]], h: list[Fraction]) -> list[Fraction] | None:
    """``G x = h`` for square ``G`` by Gaussian elimination; None when singular."""
    n = len(G)
    M = [[*row, hv] for row, hv in zip(G, h, strict=True)]
    for col in range(n):
        piv = next((r for r in range(col, n) if M[r][col] != 0), None)
        if piv is None:
            return None
        M[col], M[piv] = M[piv], M[col]
        for r in range(n):
            if r != col and M[r][col] != 0:
                f = M[r][col] / M[col][col]
                M[r] = [a - f * b for a, b in zip(M[r], M[col], strict=True)]
    return [M[i][n] / M[i][i] for i in range(n)]


def _min_over_box(c, A, b_lo, b_hi, lo, hi, big: Fraction) -> Fraction | None:
    n = len(c)
    F = Fraction
    rows: list[tuple[list[Fraction], Fraction]] = []  # g x <= h
    for a, bl, bh in zip(A, b_lo, b_hi, strict=True):
        if math.isfinite(bh):
            rows.append(([F(v) for v in a], F(bh)))
        if math.isfinite(bl):
            rows.append(([-F(v) for v in a], -F(bl)))
    for j in range(n):
        e = [F(0)] * n
        e[j] = F(1)
        rows.append((e, F(hi[j]) if math.isfinite(hi[j]) else big))
        rows.append(([-v for v in e], -F(lo[j]) if math.isfinite(lo[j]) else big))
    cf = [F(v) for v in c]
    best = None
    for combo in itertools.combinations(range(len(rows)), n):
        x = _solve([rows[i][0] for i in combo], [rows[i][1] for i in combo])
        if x is None:
            continue
        if all(sum(g * xi for g, xi in zip(gr, x, strict=True)) <= hv for gr, hv in rows):
            v = sum(ci * xi for ci, xi in zip(cf, x, strict=True))
            best = v if best is None or v < best else best
    return best


def exact_min(c, A, b_lo, b_hi, lo, hi) -> Fraction | float | None:
    """The exact optimum (a Fraction), ``-inf`` when unbounded below, None when infeasible.

    The data must be small (entries of magnitude <= 100, at most 4 variables) so that every
    vertex lies well inside ``|x| <= 10**8``.
    """
    A = np.atleast_2d(np.asarray(A, dtype=float))
    v1 = _min_over_box(c, A, b_lo, b_hi, lo, hi, Fraction(10**12))
    if v1 is None:
        return None
    v2 = _min_over_box(c, A, b_lo, b_hi, lo, hi, Fraction(2 * 10**12))
    return v1 if v1 == v2 else -math.inf
