"""Image of a subpaving by a function: IMAGESP (Jaulin et al. 2001, Remark 3).

``image(sp, f, eps)`` bisects the boxes of ``sp`` (all at once, level by level) until each image
box ``f([x])`` has its widest side at most ``eps``, then paves the union of the image boxes on a
regular grid: the cells of step ``h = 2^floor(log2 eps)`` that each image box meets. A cell is
``[i h, (i + 1) h]`` with ``i`` an integer, exact in float64, and the cells an image box meets
cover it, so the result contains ``f(V)`` for ``V`` the inside and boundary boxes of ``sp``.

``f`` is a vectorised interval function: it takes an ``Interval`` of shape ``(b, n)`` and
returns an ``Interval`` of shape ``(b, m)`` built with boundest's interval operators, so that
the image of every box is one batched call.

Examples
--------
>>> from boundest import interval as iv
>>> from boundest.interval import Interval
>>> def f(x):  # x -> 3 (sin(x1 + x2), cos(x1 + x2)), Jaulin et al. 2001 equation 21
...     s = x[:, 0] + x[:, 1]
...     return Interval.trusted(np.stack([(3 * iv.sin(s)).lo, (3 * iv.cos(s)).lo], axis=1),
...                          np.stack([(3 * iv.sin(s)).hi, (3 * iv.cos(s)).hi], axis=1))
>>> v = Subpaving.from_box(Interval([-0.1, -0.1], [0.1, 0.1]))
>>> w = image(v, f, eps=0.05)
>>> int(w.contains(np.array([[0.0, 3.0]]))[0]), bool(w.inside.any())
(0, False)
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..interval import Interval
from .subpaving import Subpaving, _subtract

__all__ = ["cell_range", "grid_step", "image", "pave"]

#: grid indices must stay exact integers in float64
_MAX_INDEX = 2.0**52


def _images(f: Callable[[Interval], Interval], x: Interval, m: int | None) -> Interval:
    y = f(x)
    if not isinstance(y, Interval) or y.ndim != 2 or y.shape[0] != x.shape[0] or (
            m is not None and y.shape[1] != m):
        raise ValueError(f"f must map boxes of shape {x.shape} to an Interval of shape "
                         f"({x.shape[0]}, m), got {type(y).__name__} {getattr(y, 'shape', '')}")
    return y


def grid_step(eps: float) -> float:
    """The step ``h`` of the grid of ``image`` for a precision ``eps``: the largest power of two
    not above ``eps``."""
    h = float(2.0 ** np.floor(np.log2(eps)))
    return h / 2.0 if h > eps else h


def cell_range(lo: NDArray, hi: NDArray, h: float) -> tuple[NDArray, NDArray]:
    """First and last indices (floats) of the grid cells ``[i h, (i + 1) h]`` that cover the
    boxes ``[lo, hi]``: ``floor(lo / h)`` to ``max(ceil(hi / h) - 1, floor(lo / h))`` (NaN for
    empty boxes). ``h`` is a power of two: the quotients are exact unless they underflow, and
    the products ``i h`` checked below are exact while the indices stay below ``2^52``."""
    with np.errstate(invalid="ignore"):
        ilo = np.floor(lo / h)
        ilo = np.where(ilo * h > lo, ilo - 1, ilo)  # a negative quotient rounded to -0
        ihi = np.ceil(hi / h) - 1
        ihi = np.where((ihi + 1) * h < hi, ihi + 1, ihi)  # a positive one rounded to +0
    return ilo, np.maximum(ihi, ilo)


def _unique_rows(idx: NDArray[np.int64]) -> NDArray[np.int64]:
    """The distinct rows of ``idx`` in lexicographic order: one flat key per row over the rows'
    bounding grid, deduplicated by an occupancy array when that grid is small (else sorted)."""
    base = idx.min(axis=0)
    ext = idx.max(axis=0) - base + 1
    size = 1
    for e in ext.tolist():
        size *= e
    if size >= 2**62:
        return np.unique(idx, axis=0)
    key = np.ravel_multi_index(tuple((idx - base).T), tuple(ext.tolist()))
    if size <= max(8 * idx.shape[0], 1 << 16):
        occ = np.zeros(size, dtype=bool)
        occ[key] = True
        key = np.flatnonzero(occ)
    else:
        key = np.unique(key)
    return np.stack(np.unravel_index(key, tuple(ext.tolist())), axis=1) + base


def pave(y: Interval, eps: float) -> Subpaving:
    """An outer subpaving of the union of the boxes ``y`` ``(b, m)``, on the grid of ``image``.

    Boxes that meet at most 3 cells per dimension are replaced by those cells; the others (and
    unbounded ones) by their hull, cut out of the cells. Empty boxes are ignored.
    """
    y = y[~np.isnan(y.lo).any(axis=1)]
    m = y.shape[1]
    lo, hi = y.lo, y.hi
    h = grid_step(eps)
    # the image may be far from the origin: coarsen the grid until every index is exact
    big = max(float(np.abs(lo[np.isfinite(lo)]).max(initial=0.0)),
              float(np.abs(hi[np.isfinite(hi)]).max(initial=0.0)))
    while big / h >= _MAX_INDEX:
        h *= 2.0
    ilo, ihi = cell_range(lo, hi, h)
    with np.errstate(invalid="ignore"):
        k = ihi - ilo + 1  # cells per dimension
        snap = np.all(np.isfinite(k) & (k <= 3), axis=1)
    ilo, k = ilo[snap].astype(np.int64), k[snap].astype(np.int64)
    cells = []
    for off in itertools.product(range(3), repeat=m):  # 3^m offsets, not a loop over boxes
        o = np.asarray(off, dtype=np.int64)
        cells.append(ilo[np.all(o < k, axis=1)] + o)
    idx = np.concatenate(cells).reshape(-1, m)
    if idx.shape[0]:
        idx = _unique_rows(idx)
    clo, chi = idx * h, (idx + 1) * h
    if not snap.all():  # wide or unbounded images: their hull, cut out of the cells
        rlo = lo[~snap].min(axis=0, keepdims=True)
        rhi = hi[~snap].max(axis=0, keepdims=True)
        clo, chi, _ = _subtract(clo, chi, rlo, rhi)
        clo, chi = np.concatenate([clo, rlo]), np.concatenate([chi, rhi])
    out = Subpaving(Interval.trusted(clo, chi), np.zeros(clo.shape[0], dtype=bool))
    out.stats = {"images": int(lo.shape[0]), "cells": int(idx.shape[0])}
    return out


def image(sp: Subpaving, f: Callable[[Interval], Interval], *, eps: float,
          max_boxes: int = 1_000_000, extra: Interval | None = None,
          executor: Executor | None = None, split: int = 16384, tasks: int = 16,
          progress: bool | None = None) -> Subpaving:
    """A subpaving guaranteed to contain ``f(V)``, ``V`` the inside and boundary boxes of ``sp``.

    Parameters
    ----------
    sp : Subpaving
        The set ``V``.
    f : callable
        Vectorised interval function, ``Interval (b, n) -> Interval (b, m)`` (picklable, with
        an executor).
    eps : float
        Target width of the image boxes and step (rounded down to a power of two) of the grid.
    max_boxes : int
        Budget of boxes of ``V`` bisected; beyond it the remaining images are paved as they
        are (still enclosures, only wider). With an executor each part gets its share of the
        budget (in proportion to its boxes), so the result depends on ``tasks``, never on the
        number of workers, and is the in-process one whenever the budget is not reached.
    extra : Interval, optional
        Boxes ``(e, m)`` already known to enclose part of the image (computed by the caller),
        paved together with the images.
    executor : concurrent.futures.Executor, optional
        Where to bisect once the frontier holds ``split`` boxes: it is cut into ``tasks``
        parts of consecutive boxes, each bisected to the end on a worker
        (:mod:`boundest.parallel`); None: in this process.
    split, tasks : int
        With an executor: the frontier size at which the work is cut, and into how many parts.
    progress : bool or None
        With an executor: a progress bar over the parts (None: only on a terminal).

    Returns
    -------
    Subpaving
        Boundary boxes only (an outer approximation), made by ``pave``. Image boxes wider than
        3 grid cells (budget exhausted) or unbounded are replaced by their hull, cut out of the
        grid cells. ``stats`` holds ``bisected`` (boxes of ``V`` after bisection), ``images`` and
        ``cells``.
    """
    if not isinstance(sp, Subpaving):
        raise ValueError(f"image needs a Subpaving, got {type(sp).__name__}")
    if not (np.isfinite(eps) and eps > 0):
        raise ValueError(f"eps must be a positive finite number, got {eps}")
    if split < 1 or tasks < 1:
        raise ValueError(f"split and tasks must be at least 1, got {split} and {tasks}")
    m: int | None = None
    done: list[Interval] = []
    if extra is not None:
        if not isinstance(extra, Interval) or extra.ndim != 2:
            raise ValueError(f"extra must be an Interval of shape (e, m), got "
                             f"{getattr(extra, 'shape', type(extra).__name__)}")
        m = extra.shape[1]
        done.append(extra)
    head = _bisect(_ImagePart(f, eps, m, max_boxes), sp.boxes,
                   split=None if executor is None else max(split, tasks))
    done += head.done
    count, m = head.count, head.m
    frontier = head.frontier
    if frontier.shape[0]:  # cut the rest into parts, each with its share of the budget
        from ..parallel import map_chunked

        bounds = np.linspace(0, frontier.shape[0], tasks + 1).astype(np.intp)
        left = max(max_boxes - count, 0)
        parts = [(frontier[a:b], (left * (b - a)) // frontier.shape[0])
                 for a, b in itertools.pairwise(bounds) if b > a]
        runs = map_chunked(_ImagePart(f, eps, m, max_boxes), parts, executor, chunk=1,
                           progress=progress, desc="image")
        for r in runs:
            done += r.done
            count += r.count
            m = r.m if m is None else m
    if m is None:  # sp is empty: so is its image (of unknown dimension: keep sp's)
        out = Subpaving.empty(sp.dim)
        out.stats = {"bisected": 0, "images": 0, "cells": 0}
        return out
    out = pave(Interval.trusted(np.concatenate([d.lo for d in done]).reshape(-1, m),
                             np.concatenate([d.hi for d in done]).reshape(-1, m)), eps)
    out.stats = {"bisected": count, **out.stats}
    return out


@dataclass
class _Bisected:
    """What one bisection loop produced: image boxes, boxes of ``V`` counted, the image's
    dimension, and the frontier left when it stopped to split."""

    done: list[Interval]
    count: int
    m: int | None
    frontier: Interval


@dataclass
class _ImagePart:
    """The bisection of one part of ``V`` (run on a worker: a picklable dataclass)."""

    f: Callable[[Interval], Interval]
    eps: float
    m: int | None
    max_boxes: int

    def __call__(self, part: tuple[Interval, int]) -> _Bisected:
        frontier, budget = part
        return _bisect(self, frontier, budget=budget)


def _bisect(job: _ImagePart, frontier: Interval, *, budget: int | None = None,
            split: int | None = None) -> _Bisected:
    """IMAGESP's loop from ``frontier``: image every box, keep the narrow images, bisect the
    boxes of the wide ones; stop when none is left, before exceeding the ``budget`` (default
    ``job.max_boxes``; the wide images are then kept as they are), or (``split``) once the
    frontier holds at least ``split`` boxes."""
    budget = job.max_boxes if budget is None else budget
    m, done, count = job.m, [], 0
    while frontier.shape[0]:
        if split is not None and frontier.shape[0] >= split:
            break
        y = _images(job.f, frontier, m)
        m = y.shape[1]
        empty = np.isnan(y.lo).any(axis=1)  # f is undefined on the whole box
        wide = (y.max_diam() > job.eps) & ~empty & (frontier.max_diam() > 0)
        ok = ~wide & ~empty
        done.append(y[ok])
        count += int(ok.sum())
        if count + 2 * int(wide.sum()) > budget:
            done.append(y[wide])
            count += int(wide.sum())
            frontier = frontier[:0]
            break
        left, right = frontier[wide].bisect()
        frontier = Interval.trusted(np.concatenate([left.lo, right.lo]),
                                 np.concatenate([left.hi, right.hi]))
    return _Bisected(done, count, m, frontier)
