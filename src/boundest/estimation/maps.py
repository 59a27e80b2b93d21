"""A function of a discrete-time model in its two uses: batched interval image and contractor.

``Map(h, n_in, n_out)`` wraps a Python function written once with boundest's elementary
functions (``boundest.sin``...), taking a list of ``n_in`` components and returning ``n_out``:
called on ``Interval`` columns it is the natural inclusion function (one NumPy call per operation
over the whole batch of boxes), called on ``Var`` objects it builds the constraints
``v_j = h_j(u)`` of the forward-backward contractor over the joint box ``(u, v)``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ..ctc import CtcFwdBwd, Fixpoint
from ..expr import Var, variables
from ..interval import Interval, as_interval

__all__ = ["Map"]


class Map:
    """``v = h(u)`` with ``u`` in ``R^n_in`` and ``v`` in ``R^n_out``.

    Parameters
    ----------
    h : callable
        ``h(components) -> components``: a sequence of ``n_in`` values in, ``n_out`` out (or
        one value when ``n_out == 1``), built from arithmetic and boundest's elementary functions
        so that it accepts both intervals and expressions.
    n_in, n_out : int
        Dimensions.
    name : str
        Used in error messages.
    """

    def __init__(self, h: Callable[[Sequence[Any]], Any], n_in: int, n_out: int,
                 name: str = "h") -> None:
        if n_in < 1 or n_out < 1:
            raise ValueError(f"{name}: dimensions must be positive, got {n_in} -> {n_out}")
        self.h, self.n_in, self.n_out, self.name = h, n_in, n_out, name
        u = [Var(f"u{i}") for i in range(n_in)]
        v = [Var(f"v{j}") for j in range(n_out)]
        out = self._components(h(u))
        cons = [vj == oj for vj, oj in zip(v, out, strict=True)]
        used = {w.name for w in variables(cons)}
        #: columns of the joint box that the constraints involve (``h`` may ignore some inputs)
        self._cols = np.array([i for i, w in enumerate((*u, *v)) if w.name in used])
        #: one forward-backward pass of ``v = h(u)`` on joint boxes ``(..., n_in + n_out)`` (what
        #: a branch and prune applies once per level: its bisection loop iterates)
        self.fwdbwd = CtcFwdBwd(cons, [w.name for w in (*u, *v) if w.name in used])
        #: the same pass iterated while a component shrinks by more than 1 % (HC4 on a tree is
        #: not idempotent when a sub-expression is shared, as ``x1 + x2`` in Jaulin et al.
        #: 2001, eq. 21)
        self.ctc = Fixpoint(self.fwdbwd, ratio=0.01, max_iter=20)

    def _components(self, out: Any) -> list[Any]:
        out = [out] if self.n_out == 1 and not isinstance(out, (list, tuple)) else list(out)
        if len(out) != self.n_out:
            raise ValueError(f"{self.name} returned {len(out)} components, expected "
                             f"{self.n_out}")
        return out

    def __call__(self, x: Interval) -> Interval:
        """Interval image of boxes ``(..., n_in)`` as boxes ``(..., n_out)``."""
        if x.shape[-1] != self.n_in:
            raise ValueError(f"{self.name} takes boxes of dimension {self.n_in}, got shape "
                             f"{x.shape}")
        out = [as_interval(o) for o in self._components(self.h([x[..., i]
                                                                for i in range(self.n_in)]))]
        batch = x.shape[:-1]
        lo = np.stack([np.broadcast_to(o.lo, batch) for o in out], axis=-1)
        hi = np.stack([np.broadcast_to(o.hi, batch) for o in out], axis=-1)
        bad = np.isnan(lo).any(axis=-1) | np.isnan(x.lo).any(axis=-1)
        if bad.any():  # an empty box, or h undefined on the whole box: empty image
            lo, hi = lo.copy(), hi.copy()
            lo[bad] = hi[bad] = np.nan
        return Interval.trusted(lo, hi)

    def contract(self, u: Interval, v: Interval, *, once: bool = False
                 ) -> tuple[Interval, Interval]:
        """Hull-consistent contraction of ``(u, v)`` (broadcast batches) by ``v = h(u)``; with
        ``once``, a single forward-backward pass instead of the fixpoint."""
        shape = np.broadcast_shapes(u.shape[:-1], v.shape[:-1])
        joint = Interval.trusted(
            np.concatenate([np.broadcast_to(u.lo, (*shape, self.n_in)),
                            np.broadcast_to(v.lo, (*shape, self.n_out))], axis=-1),
            np.concatenate([np.broadcast_to(u.hi, (*shape, self.n_in)),
                            np.broadcast_to(v.hi, (*shape, self.n_out))], axis=-1))
        sub = (self.fwdbwd if once else self.ctc)(joint[..., self._cols])
        lo, hi = joint.lo.copy(), joint.hi.copy()
        lo[..., self._cols], hi[..., self._cols] = sub.lo, sub.hi
        empty = np.isnan(lo).any(axis=-1)
        lo[empty] = hi[empty] = np.nan
        c = Interval.trusted(lo, hi)
        return c[..., :self.n_in], c[..., self.n_in:]
