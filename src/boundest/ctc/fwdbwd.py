"""The forward-backward contractor (HC4-revise) on a tape, batched over boxes.

One pass evaluates every node forward (``z = z ∩ f(x, y)``, in tape order) then projects
backward (``(x, y) = f_rev(z, x, y)``, in reverse order). Each node is one vectorised call over
the whole batch of boxes: there is no Python loop per box.
"""

from __future__ import annotations

from collections.abc import Sequence as Seq

import numpy as np

from .. import interval as iv
from ..expr.model import Model
from ..expr.nodes import Constraint
from ..expr.tape import OPS, Tape, compile_model
from ..interval import Interval
from .base import Contractor, _empty_rows

__all__ = ["BACKWARD", "FORWARD", "CtcFwdBwd"]

#: Forward image of each primitive: ``f(x)``, ``f(x, y)`` or ``pown(x, n)``.
FORWARD = {
    "neg": iv.neg, "sqr": iv.sqr, "sqrt": iv.sqrt, "exp": iv.exp, "log": iv.log,
    "sin": iv.sin, "cos": iv.cos, "tan": iv.tan, "asin": iv.asin, "acos": iv.acos,
    "atan": iv.atan, "sinh": iv.sinh, "cosh": iv.cosh, "tanh": iv.tanh,
    "abs": iv.algebraic.abs, "sign": iv.sign, "floor": iv.floor, "ceil": iv.ceil,
    "pown": lambda x, n: iv.pown(x, int(n)),
    "add": iv.add, "sub": iv.sub, "mul": iv.mul, "div": iv.div, "pow": iv.explog.pow,
    "atan2": iv.atan2, "min": iv.algebraic.min, "max": iv.algebraic.max,
}
#: Backward projection of each primitive: ``f_rev(z, x) -> x'`` or ``f_rev(z, x, y) -> (x', y')``.
BACKWARD = {
    "neg": iv.neg_rev, "sqr": iv.sqr_rev, "sqrt": iv.sqrt_rev, "exp": iv.exp_rev,
    "log": iv.log_rev, "sin": iv.sin_rev, "cos": iv.cos_rev, "tan": iv.tan_rev,
    "asin": iv.asin_rev, "acos": iv.acos_rev, "atan": iv.atan_rev, "sinh": iv.sinh_rev,
    "cosh": iv.cosh_rev, "tanh": iv.tanh_rev, "abs": iv.abs_rev, "sign": iv.sign_rev,
    "floor": iv.floor_rev, "ceil": iv.ceil_rev,
    "pown": lambda z, x, n: iv.pown_rev(z, x, int(n)),
    "add": iv.add_rev, "sub": iv.sub_rev, "mul": iv.mul_rev, "div": iv.div_rev,
    "pow": iv.pow_rev, "atan2": iv.atan2_rev, "min": iv.min_rev, "max": iv.max_rev,
}
assert set(FORWARD) == set(OPS) == set(BACKWARD)


class CtcFwdBwd(Contractor):
    """HC4-revise contractor for a set of constraints over named variables.

    Parameters
    ----------
    constraints : Model, list of Constraint, or Tape
        What to contract. Domains declared in a ``Model`` are intersected with every box.
    variables : list of str, optional
        Order of the box components (default: the model's variables in order of appearance).

    Examples
    --------
    >>> from boundest.expr import Var
    >>> x, y = Var("x"), Var("y")
    >>> ctc = CtcFwdBwd([x + y == 3, x - y == 1], ["x", "y"])
    >>> ctc(Interval([0, 0], [10, 10]))
    Interval([[1.0, 3.0], [0.0, 2.0]])
    """

    def __init__(self, constraints: Model | Seq[Constraint] | Tape,
                 variables: Seq[str] | None = None) -> None:
        self.tape = constraints if isinstance(constraints, Tape) else compile_model(
            constraints if isinstance(constraints, Model) else list(constraints))
        names = list(self.tape.slot_of) if variables is None else list(variables)
        unknown = [v for v in names if v not in self.tape.slot_of]
        if unknown:
            raise ValueError(f"variables not in the constraints: {', '.join(unknown)}")
        self.variables = names
        self.n = len(names)
        self._slots = np.array([self.tape.slot_of[v] for v in names], dtype=np.intp)
        self._codes = [OPS[c] for c in self.tape.op]

    def contract(self, x: Interval) -> Interval:
        t = self.tape
        batch = x.shape[:-1]
        # slots first: each node then reads and writes contiguous rows of the batch
        shape = (t.n_slots, *batch)
        col = (-1, *([1] * len(batch)))
        lo = np.broadcast_to(t.lo.reshape(col), shape).copy()
        hi = np.broadcast_to(t.hi.reshape(col), shape).copy()
        xlo, xhi = np.moveaxis(x.lo, -1, 0), np.moveaxis(x.hi, -1, 0)
        for j, s in enumerate(self._slots):  # several variables may share a slot
            lo[s] = np.maximum(lo[s], xlo[j])
            hi[s] = np.minimum(hi[s], xhi[j])
        bad = ~(lo <= hi)
        bad |= bad.any(axis=0)
        lo[bad] = hi[bad] = np.nan

        def dom(s: int) -> Interval:
            return Interval.trusted(lo[s], hi[s])

        def put(s: int, v: Interval) -> None:
            lo[s], hi[s] = v.lo, v.hi

        for i, name in enumerate(self._codes):  # forward: images
            o, a, b = t.out[i], t.a[i], t.b[i]
            if name == "pown":
                img = FORWARD[name](dom(a), t.param[i])
            elif b < 0:
                img = FORWARD[name](dom(a))
            else:
                img = FORWARD[name](dom(a), dom(b))
            put(o, iv.intersect(dom(o), img))
        for i in range(t.n_nodes - 1, -1, -1):  # backward: projections
            name, o, a, b = self._codes[i], t.out[i], t.a[i], t.b[i]
            if name == "pown":
                put(a, BACKWARD[name](dom(o), dom(a), t.param[i]))
            elif b < 0:
                put(a, BACKWARD[name](dom(o), dom(a)))
            else:
                xa, xb = BACKWARD[name](dom(o), dom(a), dom(b))
                if a == b:
                    put(a, iv.intersect(xa, xb))
                else:
                    put(a, xa)
                    put(b, xb)
        out = Interval.trusted(np.moveaxis(lo[self._slots], 0, -1),
                            np.moveaxis(hi[self._slots], 0, -1))
        empty = np.isnan(lo).any(axis=0)  # a box with one empty slot is empty
        res = _empty_rows(iv.intersect(x, out))
        if empty.any():
            res.lo[empty] = np.nan
            res.hi[empty] = np.nan
        return res
