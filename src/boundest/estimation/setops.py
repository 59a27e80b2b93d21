"""The local contraction operators of Jaulin et al. 2001 (equations 9-11) for a constraint ``v =
h(u)``:

    toward_out(V_out, V_in) = V_out ∩ h(V_in)         (image, eq. 11)
    toward_in(V_in, V_out)  = V_in ∩ h^-1(V_out)      (reciprocal image, eq. 10)

on two kinds of domains:

``BoxSets``     domains are boxes (or batches of boxes ``(..., n)``, one independent problem per
                batch entry): both operators are the forward-backward contractor of ``v = h(u)``
                on the joint box (hull consistency; fast, not optimal).
``PavingSets``  domains are subpavings (``boundest.paving.Subpaving``), or boxes while they are
                unbounded (a prior ``R^n``): both operators branch and prune over the boxes of
                ``V_in``, a batch of boxes at a time. Each batch images the boxes (``h([u])``),
                drops those whose image meets no box of ``V_out``, contracts the others by one
                forward-backward pass with the hull of the boxes of ``V_out`` their image meets
                (the bisection loop iterates it), and bisects what is left. The reciprocal image
                goes level by level and keeps the surviving boxes of ``V_in`` once narrower than
                ``eps`` (a box whose image lies in one inside box of ``V_out`` is decided at
                once). The image bisects until every image box is narrower than ``eps`` and
                paves the images on the grid of ``boundest.paving.image`` (IMAGESP, Jaulin et al.
                2001
                Remark 3), then intersects with ``V_out``; it goes depth first over batches and
                keeps a ``CellGrid`` of the cells already in the image (cells of final images,
                and cells whose interior holds the image of a box's midpoint inside ``V_out``):
                a box whose image cells are all known, or miss ``V_out``, is dropped, since its
                descendants would add no cell (the Jaulin et al. 2001 case: 8x fewer boxes).

Soundness: a box is dropped only when its interval image (an enclosure of ``h`` on it) meets no
box of ``V_out``, when the contractor (which never removes a solution of ``v = h(u)`` with
``v`` in the hull of the met boxes, a superset of ``V_out`` near the image) empties it, or (image)
when every grid cell covering its image is already in the image paving or meets no box of
``V_out``. Every point of ``V_in ∩ h^-1(V_out)`` thus stays in a kept box, and every point of
``V_out ∩ h(V_in)`` in the image of a kept box or in a known cell. Inside labels mean "inside
the domain as represented". The grid drops nothing the plain algorithm would not cover: a known
cell holds a point of ``V_out ∩ h(V_in)`` or is a cell of a final image, so the image is the
same or smaller than without it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..ctc.base import _empty_rows
from ..interval import Interval
from ..paving import Subpaving, image
from ..paving.image import grid_step
from ..paving.subpaving import pairs
from .cells import CellGrid
from .maps import Map

__all__ = ["BoxSets", "Domain", "PavingSets"]

Domain = Interval | Subpaving

#: boxes per batch of the image branch and prune (depth first over batches)
CHUNK = 8192
#: largest grid of image cells kept by one image operator
_MAX_CELLS = 1 << 20


class BoxSets:
    """Box domains: the local operators are forward-backward contractions (hull consistency)."""

    name = "boxes"

    @staticmethod
    def entire(n: int) -> Interval:
        return Interval.entire(n)

    @staticmethod
    def intersect(a: Interval, b: Interval) -> Interval:
        return _empty_rows(a & b)

    @staticmethod
    def toward_out(m: Map, v_out: Interval, v_in: Interval) -> Interval:
        return m.contract(v_in, v_out)[1]

    @staticmethod
    def toward_in(m: Map, v_in: Interval, v_out: Interval) -> Interval:
        return m.contract(v_in, v_out)[0]


def _boxes(x: Interval) -> Interval:
    return x.reshape(1, -1)


def _bounded(x: Interval) -> bool:
    return bool(np.all(np.isfinite(x.lo) & np.isfinite(x.hi)))


def _hull(d: Domain) -> Interval:
    return d.hull() if isinstance(d, Subpaving) else d


def _is_empty(d: Domain) -> bool:
    return d.is_empty() if isinstance(d, Subpaving) else bool(np.any(d.is_empty()))


def _against(target: Domain, y: Interval) -> tuple[NDArray[np.int8], Interval]:
    """For image boxes ``y (b, m)``: 1 if in one inside box of ``target``, -1 if it meets none,
    0 otherwise; and per box the hull of the target boxes it meets (empty when none)."""
    b, m = y.shape
    empty = np.isnan(y.lo).any(axis=1)
    if isinstance(target, Interval):
        meet = np.all((y.lo <= target.hi) & (target.lo <= y.hi), axis=1) & ~empty
        inside = np.all((target.lo <= y.lo) & (y.hi <= target.hi), axis=1) & meet
        cls = np.where(inside, 1, np.where(meet, 0, -1)).astype(np.int8)
        return cls, Interval.trusted(np.broadcast_to(target.lo, (b, m)),
                                  np.broadcast_to(target.hi, (b, m)))
    tb = target.boxes
    ylo, yhi = np.where(empty[:, None], np.inf, y.lo), np.where(empty[:, None], -np.inf, y.hi)
    i, j = pairs(ylo, yhi, tb.lo, tb.hi)
    lo, hi = np.full((b, m), np.inf), np.full((b, m), -np.inf)
    np.minimum.at(lo, i, tb.lo[j])
    np.maximum.at(hi, i, tb.hi[j])
    meets = np.zeros(b, dtype=bool)
    meets[i] = True
    sub = target.inside[j] & np.all((tb.lo[j] <= y.lo[i]) & (y.hi[i] <= tb.hi[j]), axis=1)
    cls = np.where(meets, 0, -1).astype(np.int8)
    cls[i[sub]] = 1
    lo[~meets] = hi[~meets] = np.nan
    return cls, Interval.trusted(lo, hi)


def _bisect(x: Interval) -> Interval:
    """Both halves of every box (``Interval.bisect``), lefts then rights."""
    if not x.shape[0]:
        return x
    left, right = x.bisect()
    return _cat([left, right], x.shape[1])


def _pop(stack: list[Interval], size: int) -> Interval:
    """Up to ``size`` boxes from the top of a stack of batches (the last batch taken may be
    split: its tail is taken, its head stays)."""
    parts: list[Interval] = []
    count = 0
    while stack and count < size:
        x = stack.pop()
        if count + x.shape[0] > size:
            k = size - count
            stack.append(x[:-k])
            x = x[-k:]
        parts.append(x)
        count += x.shape[0]
    return _cat(parts, parts[0].shape[1])


def _cat(parts: list[Interval], n: int) -> Interval:
    if not parts:
        return Interval.trusted(np.empty((0, n)), np.empty((0, n)))
    return Interval.trusted(np.concatenate([p.lo for p in parts]).reshape(-1, n),
                         np.concatenate([p.hi for p in parts]).reshape(-1, n))


@dataclass
class PavingSets:
    """Subpaving domains (Jaulin et al. 2001): the local operators by branch and prune (module doc).

    Parameters
    ----------
    eps : float
        Boxes of a reciprocal image, and image boxes, are bisected until narrower than ``eps``.
    max_boxes : int
        Budget of boxes processed by one operator call; beyond it the frontier is kept as it is
        (still sound, only coarser) and ``stats["budget_hit"]`` counts it.
    """

    eps: float = 0.01
    max_boxes: int = 2_000_000
    name: str = "subpavings"
    #: whether priors other than x_0's carry information (set by the estimators)
    informative_priors: bool = True
    stats: dict = field(default_factory=lambda: {"processed": 0, "calls": 0, "budget_hit": 0})

    def __post_init__(self) -> None:
        if not (np.isfinite(self.eps) and self.eps > 0):
            raise ValueError(f"eps must be a positive finite number, got {self.eps}")
        if self.max_boxes < 1:
            raise ValueError(f"max_boxes must be at least 1, got {self.max_boxes}")

    @staticmethod
    def entire(n: int) -> Interval:
        return Interval.entire(n)

    @staticmethod
    def intersect(a: Domain, b: Domain) -> Domain:
        if isinstance(a, Interval) and isinstance(b, Interval):
            return _empty_rows(a & b)
        if isinstance(a, Interval):
            a, b = b, a
        return a.intersect(b)

    def toward_out(self, m: Map, v_out: Domain, v_in: Domain) -> Domain:
        """``V_out ∩ h(V_in)``."""
        if _is_empty(v_in) or _is_empty(v_out):
            return Subpaving.empty(m.n_out) if isinstance(v_out, Subpaving) else \
                Interval.empty(m.n_out)
        if isinstance(v_in, Interval):
            u, v = m.contract(v_in, _hull(v_out))
            if not _bounded(u) or np.any(u.is_empty()):  # cannot be paved: stay a box
                return self.intersect(v_out, v)
            v_in = Subpaving(_boxes(u), np.ones(1, dtype=bool))
        images, left = self._images(m, v_in, v_out)
        img = image(Subpaving(left, np.zeros(len(left), dtype=bool)), m, eps=self.eps,
                    extra=images)
        return self.intersect(v_out, img)

    def toward_in(self, m: Map, v_in: Domain, v_out: Domain) -> Domain:
        """``V_in ∩ h^-1(V_out)``."""
        if isinstance(v_out, Interval) and bool(np.all(v_out.is_entire())):
            return v_in
        if _is_empty(v_in) or _is_empty(v_out):
            return Subpaving.empty(m.n_in) if isinstance(v_in, Subpaving) else \
                Interval.empty(m.n_in)
        if isinstance(v_in, Interval):
            u, _ = m.contract(v_in, _hull(v_out))
            if not _bounded(u) or np.any(u.is_empty()):
                return u
            v_in = Subpaving(_boxes(u), np.ones(1, dtype=bool))
        return self._prune(m, v_in, v_out)

    def _step(self, m: Map, frontier: Interval, v_out: Domain, y: Interval | None = None
              ) -> tuple[Interval, NDArray[np.int8], NDArray[np.bool_]]:
        """One branch-and-prune level: image the boxes (unless their images ``y`` are given),
        classify them against ``v_out``, contract them with the hull of the boxes of ``v_out``
        their image meets. Returns the surviving contracted boxes, their classes and which
        input boxes survive."""
        self.stats["processed"] += frontier.shape[0]
        cls, cand = _against(v_out, m(frontier) if y is None else y)
        u, _ = m.contract(frontier, cand, once=True)  # the levels iterate: no fixpoint here
        alive = (cls >= 0) & ~np.isnan(u.lo).any(axis=1)
        return u[alive], cls[alive], alive

    def _prune(self, m: Map, v_in: Subpaving, v_out: Domain) -> Subpaving:
        """Reciprocal image: branch and prune over the boxes of ``v_in``, one level per batch
        (module doc)."""
        n = m.n_in
        self.stats["calls"] += 1
        frontier, labels = v_in.boxes, v_in.inside
        out_boxes: list[Interval] = []
        out_labels: list[NDArray[np.bool_]] = []
        processed = 0
        while frontier.shape[0]:
            processed += frontier.shape[0]
            frontier, cls, alive = self._step(m, frontier, v_out)
            labels = labels[alive]
            done = (cls == 1) | (frontier.max_diam() < self.eps)
            out_boxes.append(frontier[done])
            out_labels.append(labels[done] & (cls[done] == 1))
            frontier, labels = frontier[~done], labels[~done]
            if processed + 2 * frontier.shape[0] > self.max_boxes:
                self.stats["budget_hit"] += int(frontier.shape[0] > 0)
                out_boxes.append(frontier)
                out_labels.append(np.zeros(frontier.shape[0], dtype=bool))
                break
            frontier = _bisect(frontier)
            labels = np.concatenate([labels, labels])
        return Subpaving(_cat(out_boxes, n), np.concatenate(out_labels) if out_labels
                         else np.zeros(0, dtype=bool))

    def _images(self, m: Map, v_in: Subpaving, v_out: Domain) -> tuple[Interval, Interval]:
        """Image: branch and prune over the boxes of ``v_in`` until their images are narrower
        than ``eps``, depth first over chunks of ``CHUNK`` boxes so that the cells of the
        image found early (``CellGrid``) let the later boxes stop as soon as all the cells
        they could add are known. Returns image boxes (final images and known cells, to pave)
        and the boxes of ``v_in`` left to ``image`` (budget exhausted, or narrower than
        ``eps * 2^-20`` with a wider image)."""
        n, eps = m.n_in, self.eps
        self.stats["calls"] += 1
        grid = CellGrid.build(grid_step(eps), v_out, m(v_in.boxes), _MAX_CELLS)
        floor = eps * 2.0**-20  # no bisection below: h may not shrink (degenerate boxes)
        stack, pending = [v_in.boxes], len(v_in)
        images: list[Interval] = []
        left: list[Interval] = []
        processed = 0
        while stack:
            frontier = _pop(stack, CHUNK)
            pending -= frontier.shape[0]
            processed += frontier.shape[0]
            y = m(frontier)
            if grid is not None:  # before contracting
                keep = ~grid.covered(y)
                frontier, y = frontier[keep], y[keep]
            u, _, _ = self._step(m, frontier, v_out, y)
            y = m(u)
            if grid is not None:
                p = u.mid()  # points of V_in
                grid.certify(m(Interval.trusted(p, p)))
                keep = ~grid.covered(y)
                u, y = u[keep], y[keep]
            done = y.max_diam() <= eps
            small = ~done & (u.max_diam() <= floor)
            fin = y[done]
            images.append(fin if grid is None else fin[~grid.mark(fin)])
            left.append(u[small])
            rest = u[~done & ~small]
            if processed + pending + 2 * rest.shape[0] > self.max_boxes:
                self.stats["budget_hit"] += int(rest.shape[0] + pending > 0)
                left.extend([rest, *stack])
                break
            if rest.shape[0]:
                stack.append(_bisect(rest))
                pending += 2 * rest.shape[0]
        if grid is not None:
            images.append(grid.cells())
        return _cat(images, m.n_out), _cat(left, n)

