"""3B consistency around any contractor: shaving the bounds of a box, batched over boxes.

``CtcShave(ctc)`` contracts a box with ``ctc``, then for each variable and each of its bounds
cuts a slice off the box at that bound and contracts the slice with ``ctc``: when the slice comes
back empty, it holds no solution and is removed (the next slice, twice as wide, is then tried).
Every slice of every box of a batch is one call of ``ctc`` on the whole batch: there is no
Python loop per box. It is the contractor form of ``propagate(mode="3b")``, which shaves a
large CSP in the compiled engine (``boundest.csp``).

Why two implementations of shaving. Neither calls the other, and neither can replace the
other: this one shaves many boxes through an opaque contractor (any ``Contractor``: a
``Fixpoint``, a polar or ray-cast contractor, a union, a Python function), each slice of every
box one batched call, which a compiled kernel cannot take as an argument; the engine's
``csp.engine.shave_kernel`` shaves one box of a CSP of thousands of variables through its tape,
and its probes are local (they revise only what a slice reaches and undo themselves from a
trail), so a probe costs what its change travels, not the size of the CSP, which no
contractor-level loop can do. A contractor over a tape can have both: ``CtcShave(CtcFwdBwd(..))``
here, or ``propagate(..., mode="3b")`` for one large box.
"""

from __future__ import annotations

from collections.abc import Sequence as Seq

import numpy as np

from ..interval import Interval
from .base import Contractor, _empty_rows

__all__ = ["CtcShave"]


class CtcShave(Contractor):
    """3B consistency (shaving) of the boxes around a contractor.

    Parameters
    ----------
    ctc : Contractor
        The contractor that refutes slices (e.g. a ``Fixpoint(CtcFwdBwd(...))``).
    variables : sequence of int, optional
        Indices of the components to shave (default: all, when ``ctc.n`` is known).
    frac : float
        First slice of a bound, as a fraction of the component's width; it doubles (up to 1/2)
        after each slice refuted.
    max_slices : int
        Slices per bound at most.

    Examples
    --------
    >>> from boundest.ctc import CtcFwdBwd
    >>> from boundest.expr import Var
    >>> x, y = Var("x"), Var("y")
    >>> hc = CtcFwdBwd([x + y == 0, x - y == 0], ["x", "y"])
    >>> hc(Interval([-1, -1], [1, 1]))   # hull consistency cannot see that only (0, 0) is left
    Interval([[-1.0, 1.0], [-1.0, 1.0]])
    >>> box = CtcShave(hc, frac=0.1, max_slices=20)(Interval([-1, -1], [1, 1]))
    >>> bool(np.all(box.width() < 1e-3))
    True
    """

    def __init__(self, ctc: Contractor, variables: Seq[int] | None = None, frac: float = 0.1,
                 max_slices: int = 8) -> None:
        if not 0.0 < frac <= 0.5:
            raise ValueError(f"frac must lie in ]0, 1/2], got {frac}")
        if max_slices < 1:
            raise ValueError(f"max_slices must be at least 1, got {max_slices}")
        if variables is None and ctc.n is None:
            raise ValueError("CtcShave needs variables= when the contractor's dimension is "
                             "unknown")
        self.ctc, self.frac, self.max_slices, self.n = ctc, float(frac), max_slices, ctc.n
        self.variables = list(range(ctc.n)) if variables is None else [int(v) for v in
                                                                        variables]
        if self.n is not None and any(not 0 <= v < self.n for v in self.variables):
            raise ValueError(f"variables must lie in 0..{self.n - 1}, got {self.variables}")

    def contract(self, x: Interval) -> Interval:
        box = _empty_rows(self.ctc.contract(x))
        if box.ndim == 0:
            raise ValueError("CtcShave contracts boxes (shape (..., n)), not a scalar interval")
        lo, hi = box.lo.copy(), box.hi.copy()
        for i in self.variables:
            for side in (0, 1):
                f = np.full(lo.shape[:-1], self.frac)
                todo = ~np.isnan(lo).any(axis=-1)
                for _ in range(self.max_slices):
                    l, h = lo[..., i], hi[..., i]
                    with np.errstate(invalid="ignore"):
                        cut = l + f * (h - l) if side == 0 else h - f * (h - l)
                        todo &= (l < cut) & (cut < h)  # unbounded, too thin: left alone
                    if not todo.any():
                        break
                    slo, shi = lo.copy(), hi.copy()
                    if side == 0:
                        shi[..., i] = np.where(todo, cut, h)
                    else:
                        slo[..., i] = np.where(todo, cut, l)
                    sl = self.ctc.contract(Interval.trusted(slo, shi))
                    refuted = todo & np.isnan(sl.lo).any(axis=-1)
                    if not refuted.any():
                        break
                    # the slices refuted hold no solution: the bound moves to the cut
                    if side == 0:
                        lo[..., i] = np.where(refuted, cut, l)
                    else:
                        hi[..., i] = np.where(refuted, cut, h)
                    out = _empty_rows(self.ctc.contract(Interval.trusted(lo, hi)))
                    lo, hi = out.lo.copy(), out.hi.copy()
                    todo = refuted & ~np.isnan(lo).any(axis=-1)
                    f = np.minimum(2.0 * f, 0.5)
        return Interval.trusted(lo, hi)
