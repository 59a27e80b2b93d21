"""Contractors: callables mapping a box (or a batch of boxes) to a sub-box.

A contractor ``C`` takes an ``Interval`` of shape ``(..., n)`` and returns one of the same shape
with ``C(X) ⊆ X`` and no solution of its constraints lost (every solution in ``X`` stays in
``C(X)``). Contractors never modify their argument. They compose:

- ``C1 & C2`` (or ``Sequence(C1, C2)``): apply one after the other (intersection of contractions);
- ``C1 | C2`` (or ``Union(C1, C2)``): hull of the two results (the union of their solution sets);
- ``Fixpoint(C)``: repeat until no box shrinks by more than a relative ratio;
- ``Inflate(C, rad)``: inflate the result (for robustness to rounding in outer loops).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..interval import Interval, hull, intersect

__all__ = [
    "Contractor",
    "Fixpoint",
    "FunctionContractor",
    "Inflate",
    "Sequence",
    "Union",
    "shrink_ratio",
]


class Contractor:
    """Base class: subclasses implement ``contract(x) -> Interval``."""

    #: number of variables (last-axis length of the boxes), when known
    n: int | None = None

    def contract(self, x: Interval) -> Interval:
        raise NotImplementedError

    def __call__(self, x: Interval) -> Interval:
        if not isinstance(x, Interval):
            x = Interval.from_bounds(x)
        if self.n is not None and (x.ndim == 0 or x.shape[-1] != self.n):
            raise ValueError(f"{type(self).__name__} expects boxes of dimension {self.n}, "
                             f"got an interval array of shape {x.shape}")
        return self.contract(x)

    def __and__(self, other: Contractor) -> Sequence:
        return Sequence(self, other)

    def __or__(self, other: Contractor) -> Union:
        return Union(self, other)


class FunctionContractor(Contractor):
    """Wrap a plain function ``f(box) -> box`` as a contractor (the result is intersected
    with the input, so ``f`` may return any superset of the solutions)."""

    def __init__(self, f: Callable[[Interval], Interval], n: int | None = None) -> None:
        self.f = f
        self.n = n

    def contract(self, x: Interval) -> Interval:
        return _empty_rows(intersect(x, self.f(x)))


def _empty_rows(x: Interval) -> Interval:
    """A box with one empty component is empty as a whole."""
    if x.ndim == 0:
        return x
    bad = np.isnan(x.lo).any(axis=-1)
    if bad.any():
        lo, hi = x.lo.copy(), x.hi.copy()
        lo[bad] = np.nan
        hi[bad] = np.nan
        return Interval.trusted(lo, hi)
    return x


def _dimension(ctcs: tuple[Contractor, ...]) -> int | None:
    dims = {c.n for c in ctcs if c.n is not None}
    if len(dims) > 1:
        raise ValueError(f"cannot compose contractors of dimensions {sorted(dims)}")
    return dims.pop() if dims else None


class Sequence(Contractor):
    """Apply contractors one after the other."""

    def __init__(self, *ctcs: Contractor) -> None:
        if not ctcs:
            raise ValueError("Sequence needs at least one contractor")
        self.ctcs = ctcs
        self.n = _dimension(ctcs)

    def contract(self, x: Interval) -> Interval:
        for c in self.ctcs:
            x = c.contract(x)
        return x


class Union(Contractor):
    """Hull of the results of several contractors applied to the same box."""

    def __init__(self, *ctcs: Contractor) -> None:
        if not ctcs:
            raise ValueError("Union needs at least one contractor")
        self.ctcs = ctcs
        self.n = _dimension(ctcs)

    def contract(self, x: Interval) -> Interval:
        out = _empty_rows(self.ctcs[0].contract(x))
        for c in self.ctcs[1:]:
            out = hull(out, _empty_rows(c.contract(x)))
        return out


def shrink_ratio(before: Interval, after: Interval) -> np.ndarray:
    """Per box, the largest relative shrink of a component: ``(w_before - w_after) / w_before``;
    1 when a component lost an infinite bound or the box became empty, 0 when nothing moved."""
    wb, wa = before.width(), after.width()
    with np.errstate(invalid="ignore", divide="ignore"):
        r = np.where(np.isinf(wb), np.where((before.lo != after.lo) | (before.hi != after.hi),
                                            1.0, 0.0),
                     np.where(wb > 0, (wb - wa) / wb, 0.0))
    r = np.where(after.is_empty() & ~before.is_empty(), 1.0, np.nan_to_num(r, nan=0.0))
    return r if r.ndim == 0 else r.max(axis=-1)


class Fixpoint(Contractor):
    """Repeat a contractor until no component of any box shrinks by more than ``ratio`` of its
    width (``shrink_ratio``) or ``max_iter`` passes have run. ``iterations`` holds the count of
    the last call."""

    def __init__(self, ctc: Contractor, ratio: float = 1e-3, max_iter: int = 1000) -> None:
        if not 0.0 <= ratio < 1.0:
            raise ValueError(f"ratio must lie in [0, 1[, got {ratio}")
        self.ctc, self.ratio, self.max_iter = ctc, ratio, max_iter
        self.n = ctc.n
        self.iterations = 0

    def contract(self, x: Interval) -> Interval:
        self.iterations = 0
        while self.iterations < self.max_iter:
            y = _empty_rows(self.ctc.contract(x))
            self.iterations += 1
            done = np.all(shrink_ratio(x, y) <= self.ratio) or np.all(
                y.is_empty() if y.ndim == 0 else y.is_empty().any(axis=-1))
            x = y
            if done:
                break
        return x


class Inflate(Contractor):
    """Apply a contractor then inflate its result by ``rad`` (empty boxes stay empty), clipped
    to the input box."""

    def __init__(self, ctc: Contractor, rad: float) -> None:
        if rad < 0:
            raise ValueError(f"inflation radius must be non-negative, got {rad}")
        self.ctc, self.rad, self.n = ctc, rad, ctc.n

    def contract(self, x: Interval) -> Interval:
        y = _empty_rows(self.ctc.contract(x))
        return _empty_rows(intersect(x, y.inflate(self.rad)))
