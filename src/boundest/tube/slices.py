"""Algebraic constraints between tubes: a box contractor applied to every slice and gate.

A constraint such as ``v = f(x, u)`` holds at every time, so for every slice (and every gate)
the tuple of the tubes' values at that time lies in the box of their slices (gates). The box
contractor (typically ``CtcFwdBwd``, batched: one NumPy call per tape node) runs once on the
``(2n+1, n_vars)`` batch of the slices and the gates.
"""

from __future__ import annotations

from collections.abc import Sequence as Seq

import numpy as np

from ..ctc import Contractor, CtcFwdBwd
from ..expr.model import Model
from ..expr.nodes import Constraint
from ..interval import Interval
from .tube import Tube

__all__ = ["CtcSlices"]

Domain = Tube | Interval


class CtcSlices:
    """Apply a box contractor at every time: ``contract(*domains)`` contracts in place.

    Parameters
    ----------
    ctc : Contractor, Model or list of Constraint
        The box contractor over ``n_vars`` variables (constraints are compiled to a
        ``CtcFwdBwd`` over ``variables``).
    variables : list of str, optional
        Variable order when ``ctc`` is given as constraints.

    Notes
    -----
    The domains passed to ``contract`` supply the variables in order: a scalar tube one, a tube
    vector of dimension ``d`` d of them, and an ``Interval`` (scalar or box) a time-invariant
    value, contracted to the intersection of its contractions over all times. If the constraint
    cannot hold at one time, every domain becomes empty.

    Examples
    --------
    >>> from boundest import Var, Interval
    >>> x, v = Var("x"), Var("v")
    >>> ctc = CtcSlices([v == 2 * x], ["x", "v"])
    >>> X = Tube.constant(0, 1, 10, Interval(0, 1))
    >>> V = Tube.constant(0, 1, 10, Interval(-5, 5))
    >>> ctc.contract(X, V)
    >>> V(0.5)
    Interval([0.0, 2.0])
    """

    def __init__(self, ctc: Contractor | Model | Seq[Constraint],
                 variables: Seq[str] | None = None) -> None:
        self.ctc = ctc if isinstance(ctc, Contractor) else CtcFwdBwd(ctc, variables)

    def contract(self, *domains: Domain) -> None:
        tubes = [d for d in domains if isinstance(d, Tube)]
        if not tubes:
            raise ValueError("CtcSlices needs at least one tube among its domains")
        t = tubes[0].t
        for y in tubes[1:]:
            if not np.array_equal(y.t, t):
                raise ValueError("CtcSlices: all tubes must share their gate times")
        for d in domains:
            if not isinstance(d, (Tube, Interval)) or (isinstance(d, Interval) and d.ndim > 1):
                raise ValueError(f"CtcSlices domains are tubes, intervals or boxes, got {d!r}")
        n_vars = sum(_width(d) for d in domains)
        if self.ctc.n is not None and n_vars != self.ctc.n:
            raise ValueError(f"CtcSlices: the domains hold {n_vars} variables, the contractor "
                             f"expects {self.ctc.n}")
        if any(d.is_empty() if isinstance(d, Tube) else np.any(d.is_empty()) for d in domains):
            _empty_all(domains)
            return
        n = t.size - 1
        # one batch: the n slices, then the n + 1 gates
        lo = np.concatenate([_rows(d, n, "lo") for d in domains], axis=1)
        hi = np.concatenate([_rows(d, n, "hi") for d in domains], axis=1)
        out = self.ctc.contract(Interval.trusted(lo, hi))
        if np.isnan(out.lo).any():
            _empty_all(domains)
            return
        k = 0
        for d in domains:
            w = _width(d)
            olo, ohi = out.lo[:, k:k + w], out.hi[:, k:k + w]
            k += w
            if isinstance(d, Tube):
                for part, rows in ((d.slices, slice(0, n)), (d.gates, slice(n, 2 * n + 1))):
                    part.lo[...] = olo[rows].reshape(part.lo.shape)
                    part.hi[...] = ohi[rows].reshape(part.hi.shape)
            else:
                d.lo[...] = olo.max(axis=0).reshape(d.shape)
                d.hi[...] = ohi.min(axis=0).reshape(d.shape)
                if np.any(d.lo > d.hi):
                    _empty_all(domains)
                    return

    __call__ = contract


def _width(d: Domain) -> int:
    if isinstance(d, Tube):
        return d.dim
    return 1 if d.ndim == 0 else d.shape[0]


def _rows(d: Domain, n: int, bound: str) -> np.ndarray:
    """The ``(2n + 1, width)`` bounds of a domain: slices then gates (an interval repeated)."""
    if isinstance(d, Tube):
        return np.concatenate([getattr(d.slices, bound).reshape(n, -1),
                               getattr(d.gates, bound).reshape(n + 1, -1)])
    a = getattr(d, bound).reshape(1, -1)
    return np.broadcast_to(a, (2 * n + 1, a.shape[1]))


def _empty_all(domains: Seq[Domain]) -> None:
    for d in domains:
        if isinstance(d, Tube):
            d.set_empty()
        else:
            d.lo[...] = np.nan
            d.hi[...] = np.nan
