"""Subpavings: finite unions of boxes labelled inside / boundary (and optionally outside).

A ``Subpaving`` holds ``m`` closed boxes of ``R^n`` with pairwise disjoint interiors: the inside
boxes are proven subsets of the set they describe, the boundary boxes may hold points of the
set and of its complement. The union of all of them (``inside + boundary``) is an outer
approximation of the set, the union of the inside boxes an inner one. Boxes proven outside can
be kept apart (``outside``). Every operation is vectorised over the boxes; pairwise operations
(intersection of two subpavings, membership of points) run in chunks of bounded memory.

Examples
--------
>>> from boundest.interval import Interval
>>> a = Subpaving(Interval([[0, 0], [1, 0]], [[1, 1], [2, 1]]), [True, False])
>>> a.volume_inner() <= 1.0 and 2.0 <= a.volume_outer() < 2.0 + 1e-12
True
>>> a.contains(np.array([[0.5, 0.5], [1.5, 0.5], [3.0, 0.0]]))
array([ 1,  0, -1], dtype=int8)
>>> len(a.intersect(Interval([0.5, 0.5], [1.5, 2])))
2
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..interval import Interval

__all__ = ["Subpaving", "box_difference", "pairs"]

_U = 2.0**-53          # unit roundoff of float64
_TINY = 2.0**-1074     # smallest subnormal
#: largest number of (box, box, dimension) comparisons held in memory at once
_CHUNK = 1 << 22


# -- vectorised helpers --------------------------------------------------------------------------
def _width(lo: NDArray, hi: NDArray, upward: bool) -> NDArray:
    """``hi - lo`` rounded up or down (TwoSum gives the sign of the rounding error)."""
    with np.errstate(invalid="ignore", over="ignore"):
        w = hi - lo
        bb = w - hi
        err = (hi - (w - bb)) + (-lo - bb)
        if upward:
            return np.where(err > 0, np.nextafter(w, np.inf), w)
        return np.where(err < 0, np.nextafter(w, -np.inf), w)


def _volumes(lo: NDArray, hi: NDArray, upward: bool) -> NDArray:
    """Per-box volumes (product over the last axis), rounded up or down.

    A product of ``n`` non-negative floats computed in round-to-nearest is within a factor
    ``(1 +- u)^(n-1)`` of the exact product of the (already rounded) widths, plus underflow of at
    most ``n`` subnormal units; the bound below covers both with room to spare.
    """
    n = lo.shape[-1]
    if upward:
        w = _width(lo, hi, upward=True)
        with np.errstate(over="ignore", invalid="ignore"):
            p = np.prod(w, axis=-1)
            p = np.nextafter(p * (1 + 2 * n * _U) + n * _TINY, np.inf)
        p = np.where(np.any(w == 0, axis=-1), 0.0, p)  # a zero width is exact
        return np.where(np.any(np.isinf(w), axis=-1), np.inf, p)
    w = np.maximum(_width(lo, hi, upward=False), 0.0)
    with np.errstate(over="ignore", invalid="ignore"):
        p = np.prod(w, axis=-1)
        p = np.nextafter(p * (1 - 2 * n * _U) - n * _TINY, -np.inf)
    return np.maximum(p, 0.0)


def _sum(v: NDArray, upward: bool) -> float:
    """Sum of non-negative floats rounded up or down (any summation order loses at most
    ``(len - 1) u`` relative to the exact sum, covered here by ``2 len u``)."""
    if v.size == 0:
        return 0.0
    s = float(np.sum(v))
    if s == 0.0:  # non-negative terms: all zero
        return 0.0
    if np.isinf(s):
        return s if upward else float(np.finfo(np.float64).max)
    k = 2 * v.size * _U
    if upward:
        return float(np.nextafter(s * (1 + k), np.inf))
    return max(0.0, float(np.nextafter(s * (1 - k), -np.inf)))


def pairs(alo: NDArray, ahi: NDArray, blo: NDArray, bhi: NDArray, *, strict: bool = False
          ) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Index pairs ``(i, j)`` of boxes ``a_i``, ``b_j`` that meet (closed boxes) or, with
    ``strict``, whose interiors meet (in every dimension ``a.lo < b.hi`` and ``b.lo < a.hi``).

    ``a`` is sorted along its first coordinate and cut into chunks; each chunk is compared with
    the ``b`` boxes whose first coordinate can meet the chunk's range, so memory stays below
    ``_CHUNK`` comparisons whatever the sizes.
    """
    na, nb = alo.shape[0], blo.shape[0]
    if na == 0 or nb == 0:
        e = np.empty(0, dtype=np.intp)
        return e, e
    n = alo.shape[1]
    order = np.argsort(alo[:, 0], kind="stable")
    size = max(1, _CHUNK // max(1, nb * n))
    out_i, out_j = [], []
    for start in range(0, na, size):  # a loop over chunks of boxes, not over boxes
        idx = order[start:start + size]
        clo, chi = alo[idx], ahi[idx]
        lo0, hi0 = clo[:, 0].min(), chi[:, 0].max()
        cand = np.flatnonzero((blo[:, 0] <= hi0) & (bhi[:, 0] >= lo0))
        if cand.size == 0:
            continue
        dlo, dhi = blo[cand], bhi[cand]
        if strict:
            meet = ((clo[:, None, :] < dhi[None]) & (dlo[None] < chi[:, None, :])).all(axis=2)
        else:
            meet = ((clo[:, None, :] <= dhi[None]) & (dlo[None] <= chi[:, None, :])).all(axis=2)
        i, j = np.nonzero(meet)
        out_i.append(idx[i])
        out_j.append(cand[j])
    if not out_i:
        e = np.empty(0, dtype=np.intp)
        return e, e
    return np.concatenate(out_i), np.concatenate(out_j)


def box_difference(x: Interval, c: Interval) -> tuple[Interval, NDArray[np.intp]]:
    """The closure of ``x_i minus c_i`` for each box of a batch, as at most ``2n`` boxes per box.

    ``x`` and ``c`` have shape ``(b, n)``; ``c_i`` is first intersected with ``x_i`` (an empty
    component makes ``c_i`` empty, and then ``x_i`` itself is the one piece). Piece ``2d`` (and
    ``2d + 1``) is the slab of ``x`` below (above) ``c`` along dimension ``d``, restricted to
    ``c`` in the dimensions before ``d``; slabs of zero width are dropped. The pieces and ``c``
    have disjoint interiors and their union is ``x``. Returns the pieces ``(k, n)`` and, for
    each, the index of its box in the batch.
    """
    n = x.shape[1]
    lo = np.maximum(c.lo, x.lo)
    hi = np.minimum(c.hi, x.hi)
    empty = np.any(np.isnan(lo) | np.isnan(hi) | (lo > hi), axis=1)
    full = np.flatnonzero(empty)
    part = np.flatnonzero(~empty)
    xl, xh, cl, ch = x.lo[part], x.hi[part], lo[part], hi[part]
    before = np.tri(n, n, -1, dtype=bool)  # before[d, j]: j < d
    plo = np.where(before[None], cl[:, None, :], xl[:, None, :])  # (k, n pieces, n dims)
    phi = np.where(before[None], ch[:, None, :], xh[:, None, :])
    diag = np.arange(n)
    low_lo, low_hi = plo.copy(), phi.copy()
    low_hi[:, diag, diag] = cl
    up_lo, up_hi = plo, phi
    up_lo[:, diag, diag] = ch
    keep_low = xl < cl  # (k, n): a slab of positive width below c along d
    keep_up = ch < xh
    pieces_lo = np.concatenate([low_lo[keep_low], up_lo[keep_up]])
    pieces_hi = np.concatenate([low_hi[keep_low], up_hi[keep_up]])
    rows = np.broadcast_to(part[:, None], (part.size, n))
    parent = np.concatenate([rows[keep_low], rows[keep_up], full])
    pieces_lo = np.concatenate([pieces_lo, x.lo[full]])
    pieces_hi = np.concatenate([pieces_hi, x.hi[full]])
    return Interval.trusted(pieces_lo.reshape(-1, n), pieces_hi.reshape(-1, n)), parent


def _subtract(lo: NDArray, hi: NDArray, qlo: NDArray, qhi: NDArray) -> tuple[NDArray, NDArray,
                                                                               NDArray]:
    """Cut from the boxes ``[lo, hi]`` the interiors of the boxes ``q``: returns pieces with no
    interior point in common with any ``q`` and the index of each piece's original box.

    Each round cuts every piece by the first ``q`` box its interior meets (one batched
    ``box_difference``); a piece never meets that ``q`` again, so the rounds are at most the
    largest number of ``q`` boxes one box meets.
    """
    n = lo.shape[1]
    parent = np.arange(lo.shape[0])
    done_lo, done_hi, done_p = [lo[:0]], [hi[:0]], [parent[:0]]
    while lo.shape[0]:
        i, j = pairs(lo, hi, qlo, qhi, strict=True)
        hit = np.zeros(lo.shape[0], dtype=bool)
        hit[i] = True
        done_lo.append(lo[~hit])
        done_hi.append(hi[~hit])
        done_p.append(parent[~hit])
        if not hit.any():
            break
        first_i, first = np.unique(i, return_index=True)
        pieces, src = box_difference(Interval.trusted(lo[first_i], hi[first_i]),
                                     Interval.trusted(qlo[j[first]], qhi[j[first]]))
        # a degenerate piece of a degenerate box inside q is covered by q
        lo, hi, parent = pieces.lo, pieces.hi, parent[first_i][src]
        covered = pieces.is_empty().any(axis=1)
        lo, hi, parent = lo[~covered], hi[~covered], parent[~covered]
    return (np.concatenate(done_lo).reshape(-1, n), np.concatenate(done_hi).reshape(-1, n),
            np.concatenate(done_p))


def _as_boxes(x: Interval | ArrayLike, what: str) -> Interval:
    if not isinstance(x, Interval):
        raise ValueError(f"{what} must be an Interval of shape (m, n), got {type(x).__name__}")
    if x.ndim != 2:
        raise ValueError(f"{what} must have shape (m, n), got {x.shape}")
    return x


# -- the type ------------------------------------------------------------------------------------
class Subpaving:
    """Boxes of ``R^n`` labelled inside / boundary (outside boxes optionally kept).

    Parameters
    ----------
    boxes : Interval, shape (m, n)
        Inside and boundary boxes, non-empty, with pairwise disjoint interiors.
    inside : array_like of bool, shape (m,)
        True where the box is proven inside the set, False for a boundary box.
    outside : Interval, shape (p, n), optional
        Boxes proven outside the set.

    Attributes
    ----------
    stats : dict
        What the algorithm that built it counted (e.g. ``sivia``'s boxes processed).
    """

    __slots__ = ("boxes", "dim", "inside", "outside", "stats")

    def __init__(self, boxes: Interval, inside: ArrayLike, outside: Interval | None = None
                 ) -> None:
        boxes = _as_boxes(boxes, "boxes")
        m, n = boxes.shape
        ins = np.asarray(inside)
        if ins.shape != (m,) or (ins.size and ins.dtype != np.bool_):
            raise ValueError(f"inside must be a bool array of shape ({m},), got "
                             f"{ins.dtype} {ins.shape}")
        bad = np.isnan(boxes.lo).any(axis=1) | (boxes.lo > boxes.hi).any(axis=1)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise ValueError(f"subpaving box {k} is empty or invalid: {boxes[k]}")
        if outside is None:
            outside = Interval.trusted(np.empty((0, n)), np.empty((0, n)))
        outside = _as_boxes(outside, "outside")
        if outside.shape[1] != n:
            raise ValueError(f"outside boxes have dimension {outside.shape[1]}, the subpaving "
                             f"{n}")
        self.boxes, self.inside, self.outside = boxes, ins.astype(bool), outside
        self.dim = n
        self.stats: dict[str, Any] = {}

    @classmethod
    def from_box(cls, box: Interval) -> Subpaving:
        """One boundary box (shape ``(n,)``)."""
        if not isinstance(box, Interval) or box.ndim != 1:
            raise ValueError(f"from_box needs a box of shape (n,), got {box!r}")
        if np.any(box.is_empty()):
            return cls.empty(box.shape[0])
        return cls(box.reshape(1, -1), np.zeros(1, dtype=bool))

    @classmethod
    def empty(cls, dim: int) -> Subpaving:
        """The empty subpaving of ``R^dim``."""
        return cls(Interval.trusted(np.empty((0, dim)), np.empty((0, dim))),
                   np.zeros(0, dtype=bool))

    def sorted(self) -> Subpaving:
        """The same subpaving with its boxes in a canonical order (inside boxes first, then by
        lower then upper bounds, dimension 0 first; the outside boxes likewise): two subpavings
        hold the same labelled boxes exactly when their ``sorted()`` arrays are equal."""
        def order(b: Interval, first: NDArray | None = None) -> NDArray[np.intp]:
            keys = [b.hi[:, d] for d in range(b.shape[1] - 1, -1, -1)]
            keys += [b.lo[:, d] for d in range(b.shape[1] - 1, -1, -1)]
            return np.lexsort(keys + ([first] if first is not None else []))

        i = order(self.boxes, ~self.inside)
        j = order(self.outside)
        out = Subpaving(self.boxes[i], self.inside[i], self.outside[j])
        out.stats = dict(self.stats)
        return out

    # -- views ----------------------------------------------------------------------------------
    def __len__(self) -> int:
        return self.boxes.shape[0]

    def __iter__(self) -> Iterator[Interval]:
        return iter(self.boxes)

    def __repr__(self) -> str:
        k = int(self.inside.sum())
        return (f"Subpaving(dim={self.dim}, inside={k}, boundary={len(self) - k}, "
                f"outside={self.outside.shape[0]})")

    def inner(self) -> Interval:
        """The inside boxes, shape ``(k, n)``."""
        return self.boxes[self.inside]

    def boundary(self) -> Interval:
        """The boundary boxes."""
        return self.boxes[~self.inside]

    def is_empty(self) -> bool:
        return len(self) == 0

    def hull(self) -> Interval:
        """Interval hull of the inside and boundary boxes, shape ``(n,)`` (empty when none)."""
        if len(self) == 0:
            return Interval.empty(self.dim)
        return Interval.trusted(self.boxes.lo.min(axis=0), self.boxes.hi.max(axis=0))

    def volume_inner(self) -> float:
        """Total volume of the inside boxes, rounded downward (a lower bound of the set's)."""
        b = self.inner()
        return _sum(_volumes(b.lo, b.hi, upward=False), upward=False)

    def volume_outer(self) -> float:
        """Total volume of the inside and boundary boxes, rounded upward."""
        return _sum(_volumes(self.boxes.lo, self.boxes.hi, upward=True), upward=True)

    def _check_dim(self, n: int, what: str) -> None:
        if n != self.dim:
            raise ValueError(f"{what} has dimension {n}, the subpaving has dimension {self.dim}")

    # -- membership -----------------------------------------------------------------------------
    def contains(self, points: ArrayLike) -> NDArray[np.int8]:
        """For points ``(q, n)``: 1 in an inside box, 0 in a boundary box only, -1 in none."""
        p = np.asarray(points, dtype=np.float64)
        if p.ndim == 1 and p.shape[0] == self.dim:
            p = p[None]
        if p.ndim != 2:
            raise ValueError(f"points must have shape (q, {self.dim}), got {p.shape}")
        self._check_dim(p.shape[1], "points")
        if np.isnan(p).any():
            raise ValueError(f"point {np.argwhere(np.isnan(p))[0][0]} has a NaN coordinate")
        out = np.full(p.shape[0], -1, dtype=np.int8)
        i, j = pairs(p, p, self.boxes.lo, self.boxes.hi)
        out[i] = 0
        out[i[self.inside[j]]] = 1
        return out

    def classify(self, boxes: Interval) -> NDArray[np.int8]:
        """An inclusion test against this subpaving for boxes ``(b, n)`` (e.g. images ``f(X)`` in
        a reciprocal image by ``sivia``): 1 when the box lies in one inside box, -1 when it meets
        no inside or boundary box, 0 otherwise. Empty boxes give -1."""
        boxes = _as_boxes(boxes, "boxes")
        self._check_dim(boxes.shape[1], "boxes")
        out = np.zeros(boxes.shape[0], dtype=np.int8)
        empty = np.isnan(boxes.lo).any(axis=1)
        i, j = pairs(boxes.lo, boxes.hi, self.boxes.lo, self.boxes.hi)
        meets = np.zeros(boxes.shape[0], dtype=bool)
        meets[i] = True
        sub = self.inside[j] & np.all((self.boxes.lo[j] <= boxes.lo[i])
                                      & (boxes.hi[i] <= self.boxes.hi[j]), axis=1)
        out[~meets | empty] = -1
        out[i[sub]] = 1
        return out

    # -- set operations -------------------------------------------------------------------------
    def intersect(self, other: Interval | Subpaving) -> Subpaving:
        """Outer approximation of the intersection with a box ``(n,)`` or another subpaving.

        With a subpaving, every pair of boxes that meet gives its intersection (inside when both
        are inside). Pairs that only touch give degenerate boxes; those lying in a
        non-degenerate result box with the same or a better label are dropped, the others are
        kept (they may hold points of both sets).
        """
        if isinstance(other, Interval):
            if other.ndim != 1:
                raise ValueError(f"intersect needs a box of shape (n,) or a Subpaving, got an "
                                 f"interval of shape {other.shape}")
            self._check_dim(other.shape[0], "the box")
            if np.any(other.is_empty()):
                return Subpaving.empty(self.dim)
            lo = np.maximum(self.boxes.lo, other.lo)
            hi = np.minimum(self.boxes.hi, other.hi)
            keep = np.all(lo <= hi, axis=1)
            olo = np.maximum(self.outside.lo, other.lo)
            ohi = np.minimum(self.outside.hi, other.hi)
            okeep = np.all(olo <= ohi, axis=1)
            return Subpaving(Interval.trusted(lo[keep], hi[keep]), self.inside[keep],
                             Interval.trusted(olo[okeep], ohi[okeep]))
        if not isinstance(other, Subpaving):
            raise ValueError(f"intersect needs a box or a Subpaving, got {type(other).__name__}")
        self._check_dim(other.dim, "the other subpaving")
        a, b = self.boxes, other.boxes
        i, j = pairs(a.lo, a.hi, b.lo, b.hi)
        lo = np.maximum(a.lo[i], b.lo[j])
        hi = np.minimum(a.hi[i], b.hi[j])
        ins = self.inside[i] & other.inside[j]
        flat = np.any(lo == hi, axis=1)
        if flat.any() and (~flat).any():
            fi, gi = pairs(lo[flat], hi[flat], lo[~flat], hi[~flat])
            inner = np.all((lo[~flat][gi] <= lo[flat][fi]) & (hi[flat][fi] <= hi[~flat][gi]),
                           axis=1) & (ins[~flat][gi] | ~ins[flat][fi])  # same or better label
            drop = np.zeros(lo.shape[0], dtype=bool)
            drop[np.flatnonzero(flat)[fi[inner]]] = True
            lo, hi, ins = lo[~drop], hi[~drop], ins[~drop]
        outside = Interval.trusted(np.concatenate([self.outside.lo, other.outside.lo]),
                                np.concatenate([self.outside.hi, other.outside.hi]))
        return Subpaving(Interval.trusted(lo, hi), ins, outside)

    def union(self, other: Subpaving) -> Subpaving:
        """The union (boxes of ``other`` are cut so that interiors stay disjoint).

        Inside boxes of either operand stay inside; a boundary region covered by an inside box
        of the other operand is cut away. Outside boxes are those of ``self`` cut to the ones
        of ``other`` (pairwise intersections of positive volume).
        """
        if not isinstance(other, Subpaving):
            raise ValueError(f"union needs a Subpaving, got {type(other).__name__}")
        self._check_dim(other.dim, "the other subpaving")
        ai, bi = self.inner(), other.inner()
        ilo, ihi, _ = _subtract(bi.lo, bi.hi, ai.lo, ai.hi)
        ilo, ihi = np.concatenate([ai.lo, ilo]), np.concatenate([ai.hi, ihi])
        ab, bb = self.boundary(), other.boundary()
        alo, ahi, _ = _subtract(ab.lo, ab.hi, ilo, ihi)
        blo, bhi, _ = _subtract(bb.lo, bb.hi, ilo, ihi)
        blo, bhi, _ = _subtract(blo, bhi, alo, ahi)
        lo = np.concatenate([ilo, alo, blo])
        hi = np.concatenate([ihi, ahi, bhi])
        ins = np.zeros(lo.shape[0], dtype=bool)
        ins[:ilo.shape[0]] = True
        so, oo = self.outside, other.outside
        i, j = pairs(so.lo, so.hi, oo.lo, oo.hi, strict=True)
        outside = Interval.trusted(np.maximum(so.lo[i], oo.lo[j]), np.minimum(so.hi[i], oo.hi[j]))
        return Subpaving(Interval.trusted(lo, hi), ins, outside)
