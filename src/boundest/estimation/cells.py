"""Occupancy grid of the image cells built by ``PavingSets.toward_out`` (``V_out ∩ h(V_in)``).

The image is paved on the grid of ``boundest.paving.image`` (cells ``[i h, (i + 1) h]``,
``h = grid_step(eps)``). ``CellGrid`` covers the cells that can meet ``V_out`` near the first
image enclosure and records, per cell:

``relevant``  the cell meets a box of ``V_out`` (closed boxes). An irrelevant cell adds nothing
              to ``V_out ∩ image``;
``known``     the cell is already part of the image paving: either a final image box covers it
              (``mark``), or it is *proven*: the interval image of a point of ``V_in`` lies in
              its interior and in a box of ``V_out`` (``certify``), so that the cell holds a
              point of ``V_out ∩ h(V_in)`` and every sound paving on this grid has it.

A box of ``V_in`` whose image cells are all known or irrelevant (``covered``) can be dropped:
the cells its descendants would add are already there. The known cells are returned as boxes
(``cells``) and paved with the other image boxes.
"""

from __future__ import annotations

import itertools

import numpy as np
from numpy.typing import NDArray

from ..interval import Interval
from ..paving import Subpaving
from ..paving.image import cell_range
from ..paving.subpaving import pairs

__all__ = ["CellGrid"]

#: grid indices stay far below 2^52 (exact in float64)
_MAX_INDEX = 2.0**50


def _hull(d: Interval | Subpaving) -> Interval:
    return d.hull() if isinstance(d, Subpaving) else d


class CellGrid:
    """Known and relevant cells over a rectangle of cell indices (module doc).

    Build it with ``CellGrid.build``; indices are integers ``glo <= i <= ghi`` per dimension.
    """

    def __init__(self, h: float, target: Interval | Subpaving, glo: NDArray[np.int64],
                 ghi: NDArray[np.int64], outer: tuple[NDArray, NDArray]) -> None:
        self.h, self.target, self.glo, self.ghi = h, target, glo, ghi
        #: cell indices (floats, may be infinite) that can meet the hull of the target
        self.olo, self.ohi = outer
        shape = tuple((ghi - glo + 1).tolist())
        self.known = np.zeros(shape, dtype=bool)
        self.relevant = self._raster(shape)

    @classmethod
    def build(cls, h: float, target: Interval | Subpaving, y0: Interval, max_cells: int
              ) -> CellGrid | None:
        """The grid over the cells that meet both the hull of ``target`` and that of the image
        boxes ``y0 (b, m)`` (one cell of margin), or None when that region is unbounded, empty,
        too far from the origin or larger than ``max_cells`` cells."""
        th = _hull(target)
        ok = ~np.isnan(y0.lo).any(axis=1)
        if not ok.any() or np.any(th.is_empty()):
            return None
        lo = np.maximum(th.lo, y0.lo[ok].min(axis=0))
        hi = np.minimum(th.hi, y0.hi[ok].max(axis=0))
        if not (np.all(np.isfinite(lo) & np.isfinite(hi)) and np.all(lo <= hi)):
            return None
        glo, ghi = np.floor(lo / h) - 1, np.floor(hi / h) + 1
        if max(np.abs(glo).max(), np.abs(ghi).max()) >= _MAX_INDEX:
            return None
        if np.prod(ghi - glo + 1) > max_cells:
            return None
        with np.errstate(invalid="ignore"):
            outer = np.ceil(th.lo / h) - 1, np.floor(th.hi / h)
        return cls(h, target, glo.astype(np.int64), ghi.astype(np.int64), outer)

    def _raster(self, shape: tuple[int, ...]) -> NDArray[np.bool_]:
        """Cells that meet a target box: a difference array over the corners, summed."""
        tb = self.target.boxes if isinstance(self.target, Subpaving) else \
            self.target.reshape(1, -1)
        a = np.maximum(np.ceil(tb.lo / self.h) - 1, self.glo)
        b = np.minimum(np.floor(tb.hi / self.h), self.ghi)
        keep = np.all(a <= b, axis=1)
        a = a[keep].astype(np.int64) - self.glo
        b = b[keep].astype(np.int64) - self.glo + 1
        m = len(shape)
        diff = np.zeros(tuple(s + 1 for s in shape), dtype=np.int64)
        for bits in itertools.product((0, 1), repeat=m):  # 2^m corners
            sel = np.array(bits, dtype=bool)
            np.add.at(diff, tuple(np.where(sel, b, a).T), (-1) ** int(sel.sum()))
        for d in range(m):
            diff = np.cumsum(diff, axis=d)
        return diff[tuple(slice(0, s) for s in shape)] > 0

    def _rects(self, ilo: NDArray, ihi: NDArray) -> tuple[NDArray[np.bool_], NDArray[np.int64],
                                                         NDArray[np.int64]]:
        """For cell index ranges ``ilo..ihi`` (floats): whether a range lies in the grid with at
        most 3 cells per dimension, its first index relative to the grid and its counts."""
        with np.errstate(invalid="ignore"):
            ok = np.all((ilo >= self.glo) & (ihi <= self.ghi) & (ihi - ilo < 3), axis=1)
        return ok, (ilo[ok] - self.glo).astype(np.int64), (ihi[ok] - ilo[ok] + 1).astype(
            np.int64)

    def covered(self, y: Interval) -> NDArray[np.bool_]:
        """For image boxes ``y (b, m)``: every cell covering the box (``cell_range``) is known
        or irrelevant. Cells out of the hull of the target are irrelevant; the others must lie
        in the grid, at most 3 per dimension (else the box is not covered)."""
        ilo, ihi = cell_range(y.lo, y.hi, self.h)
        with np.errstate(invalid="ignore"):
            ilo, ihi = np.maximum(ilo, self.olo), np.minimum(ihi, self.ohi)
            out = np.any(ilo > ihi, axis=1)
        ok, base, k = self._rects(ilo, ihi)
        pending = self.relevant & ~self.known
        free = np.ones(base.shape[0], dtype=bool)
        for off in itertools.product(range(3), repeat=self.known.ndim):  # 3^m, not per box
            o = np.asarray(off, dtype=np.int64)
            use = np.all(o < k, axis=1)
            idx = np.where(use[:, None], base + o, 0)
            free &= ~(use & pending[tuple(idx.T)])
        out[np.flatnonzero(ok)[free]] = True
        return out

    def mark(self, y: Interval) -> NDArray[np.bool_]:
        """Mark as known the cells covering each image box of ``y`` that lies in the grid with
        at most 3 cells per dimension (the cells ``pave`` gives it); returns which boxes were
        marked (the others must be paved)."""
        ok, base, k = self._rects(*cell_range(y.lo, y.hi, self.h))
        for off in itertools.product(range(3), repeat=self.known.ndim):
            o = np.asarray(off, dtype=np.int64)
            use = np.all(o < k, axis=1)
            self.known[tuple((base[use] + o).T)] = True
        return ok

    def certify(self, yp: Interval) -> None:
        """Mark as known the cells whose interior holds an enclosure ``yp`` ``(q, m)`` of the
        image of a point of ``V_in`` that also lies in one box of the target."""
        h = self.h
        c = np.floor(yp.lo / h)
        with np.errstate(invalid="ignore"):
            ok = np.all((yp.lo > c * h) & (yp.hi < (c + 1) * h) & (c >= self.glo)
                        & (c <= self.ghi), axis=1)
        c, lo, hi = c[ok].astype(np.int64) - self.glo, yp.lo[ok], yp.hi[ok]
        new = self.relevant[tuple(c.T)] & ~self.known[tuple(c.T)]
        c, lo, hi = c[new], lo[new], hi[new]
        if isinstance(self.target, Subpaving):
            tb = self.target.boxes
            i, j = pairs(lo, hi, tb.lo, tb.hi)
            inside = np.all((tb.lo[j] <= lo[i]) & (hi[i] <= tb.hi[j]), axis=1)
            c = c[i[inside]]
        else:
            c = c[np.all((self.target.lo <= lo) & (hi <= self.target.hi), axis=1)]
        self.known[tuple(c.T)] = True

    def cells(self) -> Interval:
        """The known cells as boxes ``(c, m)`` (exact: integers times a power of two)."""
        idx = np.argwhere(self.known) + self.glo
        return Interval.trusted(idx * self.h, (idx + 1) * self.h)
