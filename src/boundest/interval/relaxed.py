"""The q-relaxed intersection of intervals and of boxes (Jaulin's robust set membership).

Given ``N`` sets ``X_1 ... X_N`` and an integer ``q >= 0``, the *q-relaxed intersection* is the
set of the points that belong to all of them but at most ``q``, i.e. to at least ``N - q``::

    X^{q} = { x : #{i : x in X_i} >= N - q }

``q`` counts the sets allowed to **fail** (the outliers): ``q = 0`` is the plain intersection,
``q = N - 1`` the union. Conventions, the same in every function of this module:

- **Empty members.** An empty set contains no point, so an empty member can never be one of the
  ``N - q`` sets that hold: it always counts as one of the ``q`` failures. A box with one empty
  component is the empty set as a whole.
- **q >= N.** Then ``N - q <= 0`` sets must hold, which every point of the space does: the result
  is the entire space (``]-oo, +oo[`` in every component), even when all members are empty. In a
  contractor this means "no contraction".
- **q < 0** is an error.

The results are exact hulls or sound outer approximations of ``X^{q}``; every bound is one of the
members' bounds, so no rounding is involved.
"""

from __future__ import annotations

from math import comb
from typing import Literal

import numba as nb
import numpy as np
from numpy.typing import NDArray

from .core import Interval

__all__ = ["EXACT_MAX_SUBSETS", "qinter", "qinter_boxes"]

#: ``method="auto"`` of ``qinter_boxes`` is exact when ``C(N, q)`` is at most this
EXACT_MAX_SUBSETS = 256

#: the exact method gathers at most about this many bounds at once (chunks of subsets)
_CHUNK_ELEMENTS = 1 << 21

Method = Literal["auto", "exact", "projection"]


def _check_q(q: int) -> int:
    if isinstance(q, bool) or not isinstance(q, (int, np.integer)):
        raise TypeError(f"q must be an integer, got {q!r}")
    if q < 0:
        raise ValueError(f"q (the number of sets allowed to fail) must be >= 0, got {q}")
    return int(q)


@nb.njit(cache=True, error_model="numpy")
def covered_hull(lo, hi, n, k, lows, highs):
    """``(a, b)``: the smallest and the largest real covered by at least ``k >= 1`` of the
    intervals ``[lo[i], hi[i]]``, ``i < n`` (NaN bounds: empty, covering nothing); NaNs when
    no real is. ``lows``/``highs``: scratch of ``n`` floats.

    Sweep: the bounds sorted, lower bounds before upper bounds at equal coordinates (the
    intervals are closed), a running count +1 at a lower bound and -1 at an upper bound. The
    count only grows at lower bounds, so the first position where it reaches ``k`` is a lower
    bound ``a``, covered by at least ``k`` intervals, and every real below ``a`` by fewer. The
    same sweep from the top, over the same sorted bounds, gives ``b``.
    """
    m = 0
    for i in range(n):
        if lo[i] <= hi[i]:
            lows[m] = lo[i]
            highs[m] = hi[i]
            m += 1
    if m < k:
        return np.nan, np.nan
    lows[:m].sort()
    highs[:m].sort()
    a = np.nan
    count, j = 0, 0
    for i in range(m):
        while j < m and highs[j] < lows[i]:  # upper bounds strictly before this lower bound
            count -= 1
            j += 1
        count += 1
        if count >= k:
            a = lows[i]
            break
    b = np.nan
    count, j = 0, m - 1
    for i in range(m - 1, -1, -1):
        while j >= 0 and lows[j] > highs[i]:  # lower bounds strictly after this upper bound
            count -= 1
            j -= 1
        count += 1
        if count >= k:
            b = highs[i]
            break
    return a, b


@nb.njit(cache=True, error_model="numpy")
def _covered_rows(lo, hi, k, out_lo, out_hi):
    n = lo.shape[1]
    lows, highs = np.empty(n), np.empty(n)
    for r in range(lo.shape[0]):
        out_lo[r], out_hi[r] = covered_hull(lo[r], hi[r], n, k, lows, highs)


def _covered(lo: NDArray, hi: NDArray, k: int) -> tuple[NDArray, NDArray]:
    """:func:`covered_hull` along the last axis of ``lo``/``hi`` (a batch on the others)."""
    n = lo.shape[-1]
    rows = int(np.prod(lo.shape[:-1], dtype=np.int64))
    out_lo, out_hi = np.empty(rows), np.empty(rows)
    _covered_rows(np.ascontiguousarray(lo, dtype=np.float64).reshape(-1, n),
                  np.ascontiguousarray(hi, dtype=np.float64).reshape(-1, n), k, out_lo, out_hi)
    return out_lo.reshape(lo.shape[:-1]), out_hi.reshape(lo.shape[:-1])


def qinter(intervals: Interval, q: int, axis: int = 0) -> Interval:
    """The q-relaxed intersection of the intervals along ``axis``: the hull of the reals that lie
    in at least ``N - q`` of the ``N`` intervals.

    Parameters
    ----------
    intervals : Interval
        ``N`` intervals along ``axis``; the other axes are a batch (one q-intersection each).
    q : int
        Number of intervals allowed to fail (not to contain the point), ``q >= 0``.
    axis : int
        The axis of the ``N`` members.

    Returns
    -------
    Interval
        The shape of ``intervals`` without ``axis``. Exact: the smallest interval that contains
        every real covered by at least ``N - q`` members (empty when there is none). An empty
        member covers nothing, so it is one of the ``q`` failures; ``q >= N`` gives the entire
        line (every real is in at least ``N - q <= 0`` members), ``q = 0`` the intersection and
        ``q = N - 1`` the hull of the union.

    Notes
    -----
    The set itself need not be an interval (``[0, 1]`` and ``[2, 3]`` with ``q = 1``: their
    union), only its hull is returned. The shortcut "lower bound = the (q+1)-th largest lower
    bound, upper bound = the (q+1)-th smallest upper bound" is a sound outer approximation but
    not the hull when members are disjoint: for ``[0, 1], [2, 3], [2.5, 4]`` with ``q = 1`` it
    gives ``[2, 3]``, the hull is ``[2.5, 3]``. Here each bound comes from a sweep over the
    sorted ``2 N`` bounds (``O(N log N)``, compiled, one call for the whole batch).

    Examples
    --------
    >>> qinter(Interval([0, 1, 2, 10], [3, 4, 5, 11]), q=1)
    Interval([2.0, 3.0])
    >>> qinter(Interval([0, 2, 2.5], [1, 3, 4]), q=1)
    Interval([2.5, 3.0])
    """
    q = _check_q(q)
    if not isinstance(intervals, Interval):
        raise TypeError(f"qinter needs an Interval, got {type(intervals).__name__}")
    if intervals.ndim == 0:
        raise ValueError("qinter needs an axis of member intervals, got a scalar interval")
    lo = np.moveaxis(intervals.lo, axis, -1)
    hi = np.moveaxis(intervals.hi, axis, -1)
    n = lo.shape[-1]
    k = n - q
    if k <= 0:
        return Interval.entire(lo.shape[:-1])
    lower, upper = _covered(lo, hi, k)
    return Interval._new(lower, upper)


def _empty_boxes(lo: NDArray, hi: NDArray) -> tuple[NDArray, NDArray]:
    """Boxes (last axis) with one empty component made wholly empty."""
    bad = np.isnan(lo).any(axis=-1, keepdims=True)
    return np.where(bad, np.nan, lo), np.where(bad, np.nan, hi)


def qinter_boxes(boxes: Interval, q: int, method: Method = "auto") -> Interval:
    """The hull of the q-relaxed intersection of boxes: the smallest box containing every point
    that lies in at least ``N - q`` of the ``N`` boxes.

    Parameters
    ----------
    boxes : Interval, shape (..., N, n)
        ``N`` boxes of dimension ``n`` (axis ``-2``); leading axes are a batch.
    q : int
        Number of boxes allowed to fail, ``q >= 0``.
    method : {"auto", "exact", "projection"}
        ``"exact"``: the hull of the non-empty intersections of every ``N - q`` of the boxes
        (``C(N, q)`` of them, vectorised); it is the exact hull. ``"projection"``: the q-relaxed
        intersection of the intervals of each component separately (``qinter`` along the member
        axis); a sound outer approximation (a point in ``N - q`` boxes has each coordinate in
        ``N - q`` intervals) that can be strictly larger, or non-empty where the set is empty.
        ``"auto"``: exact when ``C(N, q) <= EXACT_MAX_SUBSETS``, projection otherwise.

    Returns
    -------
    Interval, shape (..., n)
        Empty (NaN in every component) where no point lies in ``N - q`` boxes; the entire space
        when ``q >= N``. A box with an empty component is empty and counts as a failure.

    Examples
    --------
    Three unit squares, no two of which meet: no point is in two of them, but each coordinate
    alone is in two intervals.

    >>> b = Interval([[0, 0], [2, 2], [0, 2]], [[1, 1], [3, 3], [1, 3]])
    >>> qinter_boxes(b, 1, method="exact")
    Interval([[empty], [empty]])
    >>> qinter_boxes(b, 1, method="projection")
    Interval([[0.0, 1.0], [2.0, 3.0]])
    """
    q = _check_q(q)
    if not isinstance(boxes, Interval):
        raise TypeError(f"qinter_boxes needs an Interval, got {type(boxes).__name__}")
    if boxes.ndim < 2:
        raise ValueError(f"qinter_boxes needs boxes of shape (..., N, n), got {boxes.shape}")
    if method not in ("auto", "exact", "projection"):
        raise ValueError(f"method must be 'auto', 'exact' or 'projection', got {method!r}")
    n_members = boxes.shape[-2]
    k = n_members - q
    out_shape = boxes.shape[:-2] + boxes.shape[-1:]
    if k <= 0:
        return Interval.entire(out_shape)
    lo, hi = _empty_boxes(boxes.lo, boxes.hi)
    if method == "auto":
        method = "exact" if comb(n_members, q) <= EXACT_MAX_SUBSETS else "projection"
    if method == "projection":
        res = qinter(Interval._new(lo, hi), q, axis=-2)
        rlo, rhi = _empty_boxes(res.lo, res.hi)
        return Interval._new(rlo, rhi)
    return _exact(lo, hi, k)


def _subsets(n: int, k: int) -> NDArray[np.intp]:
    """Every k-subset of ``range(n)`` as rows of a ``(C(n, k), k)`` array (lexicographic)."""
    from itertools import combinations  # a loop over subsets, not over boxes

    return np.array(list(combinations(range(n), k)), dtype=np.intp).reshape(-1, k)


def _exact(lo: NDArray, hi: NDArray, k: int) -> Interval:
    """The hull of the union of the intersections of every ``k`` of the boxes (axis -2).

    A point lies in at least ``k`` boxes exactly when it lies in the intersection of some
    ``k`` of them, so the set is that union and its hull is the hull of the non-empty
    intersections. Subsets are batched: one gather and one reduction per chunk of subsets, the
    chunks sized so that the gathered bounds stay under ``_CHUNK_ELEMENTS`` floats.
    """
    n_members = lo.shape[-2]
    idx = _subsets(n_members, k)  # (C, k): the kept boxes; C(N, k) = C(N, q)
    per_subset = max(1, lo.size // n_members * k)
    step = max(1, _CHUNK_ELEMENTS // per_subset)
    rlo = np.full(lo.shape[:-2] + lo.shape[-1:], np.nan)
    rhi = rlo.copy()
    for start in range(0, idx.shape[0], step):  # a loop over chunks of subsets, not boxes
        sub = idx[start:start + step]
        ilo = lo[..., sub, :].max(axis=-2)  # (..., c, n); NaN (an empty member) propagates
        ihi = hi[..., sub, :].min(axis=-2)
        bad = (np.isnan(ilo) | (ilo > ihi)).any(axis=-1, keepdims=True)
        # the hull skips the empty intersections (fmin/fmax ignore NaN)
        rlo = np.fmin(rlo, np.fmin.reduce(np.where(bad, np.nan, ilo), axis=-2))
        rhi = np.fmax(rhi, np.fmax.reduce(np.where(bad, np.nan, ihi), axis=-2))
    return Interval._new(rlo, rhi)
