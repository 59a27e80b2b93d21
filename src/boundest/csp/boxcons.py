"""Box consistency (BC3), batched over boxes.

For a constraint ``f(x) ∈ [y]`` and a variable ``x_i`` that occurs several times in ``f``,
hull consistency (``CtcFwdBwd``) treats each occurrence as a separate variable and can leave
much of the domain of ``x_i`` in place (the dependency problem). Box consistency (Benhamou,
McAllester, Van Hentenryck 1999) instead looks at the univariate interval extension

    ``F_i(X_i) = f(X_1, .., X_i, .., X_n)``  (the other components fixed at their domains)

and moves the lower bound of ``x_i`` to the leftmost *canonical* slice ``[a, b]`` (width at
most ``eps``, or ``max_depth`` bisections deep) whose image ``F_i([a, b])`` meets ``[y]``,
and the upper bound to the rightmost one. Every slice dropped has an image, computed with the
outward-rounded operators of ``boundest.interval``, that misses ``[y]``: it holds no solution.

The search is the depth-first leftmost search of BC3 over the dyadic bisection tree of the
domain, compiled (``boundest.csp.engine``, the one implementation, which
``propagate(mode="bc")`` runs too): the constraints are decomposed into a tape of primitive
nodes, and ``F_i`` is the forward evaluation of the nodes that ``x_i`` reaches, up to the named
variables (so every constraint ``x_i`` occurs in is checked at once, and an intermediate image
that misses its domain refutes the slice too). A search that runs out of ``max_steps`` keeps the
left end of its current slice, which is still sound: in depth-first order every slice to its
left was refuted. The boxes of a batch are contracted one after the other in compiled code.

Only the natural interval extension is used (the expression layer has no symbolic
differentiation, so there is no centred / mean-value form here).
"""

from __future__ import annotations

from collections.abc import Sequence as Seq

import numpy as np

from ..ctc.base import Contractor, _empty_rows
from ..ctc.revise import family_flags
from ..expr.model import Model
from ..expr.nodes import Constraint, Expr, Op, Var
from ..expr.tape import compile_model
from ..interval import Interval
from .engine import bc_boxes
from .propagate import bc_candidates

__all__ = ["CtcBox", "occurrences"]


def occurrences(e: Expr) -> dict[str, int]:
    """How many times each variable occurs in the tree ``e`` (a sub-expression reused by
    identity counts at each use, as in its natural interval evaluation)."""
    count: dict[str, int] = {}
    stack = [e]
    while stack:
        t = stack.pop()
        if isinstance(t, Var):
            count[t.name] = count.get(t.name, 0) + 1
        elif isinstance(t, Op):
            stack.extend(t.args)
    return count


class CtcBox(Contractor):
    """Box consistency (BC3) of the variables occurring several times in a constraint.

    Parameters
    ----------
    constraints : Model or list of Constraint
        The constraints. Domains declared in a ``Model`` are intersected with every box.
    variables : list of str, optional
        Order of the box components (default: the model's variables in order of appearance).
    eps : float
        Width below which a slice that cannot be refuted is not bisected further (absolute).
    max_depth : int
        Bisections of a domain at most (1..52): the slices are at least
        ``2**-max_depth`` of the domain wide.
    max_steps : int
        Evaluations per bound and per variable at most; a search cut short keeps what it has
        refuted so far.

    Notes
    -----
    One call is one pass over every variable occurring several times in its constraints
    (``candidates``; all the constraints it occurs in are evaluated together), each narrowing
    applied before the next. Variables that occur once are left to hull
    consistency: compose, e.g. ``Fixpoint(CtcFwdBwd(cs) & CtcBox(cs))``. A bound that is
    infinite is left alone (the domain is still refuted as a whole when its image misses
    ``[y]``).

    Examples
    --------
    >>> from boundest.ctc import CtcFwdBwd
    >>> from boundest.expr import Var
    >>> x = Var("x")
    >>> box = Interval([-10.0], [10.0])
    >>> CtcFwdBwd([x * x - x == 0])(box)   # x * x - x holds 0 on the box: nothing to cut
    Interval([[-10.0, 10.0]])
    >>> out = CtcBox([x * x - x == 0], eps=1e-9)(box)   # the solutions are 0 and 1
    >>> bool(out.lo[0] <= 0.0 and out.hi[0] >= 1.0 and out.width()[0] < 1.0 + 1e-8)
    True
    """

    def __init__(self, constraints: Model | Seq[Constraint], variables: Seq[str] | None = None,
                 eps: float = 1e-8, max_depth: int = 40, max_steps: int = 400) -> None:
        model = constraints if isinstance(constraints, Model) else Model(
            constraints=list(constraints))
        if not 1 <= max_depth <= 52:
            raise ValueError(f"max_depth must lie in 1..52, got {max_depth}")
        if not eps >= 0.0:
            raise ValueError(f"eps must be non-negative, got {eps}")
        if max_steps < 1:
            raise ValueError(f"max_steps must be at least 1, got {max_steps}")
        known = model.variable_names()
        names = known if variables is None else list(variables)
        unknown = [v for v in names if v not in known]
        if unknown:
            raise ValueError(f"variables not in the constraints: {', '.join(unknown)}")
        missing = [v for v in known if v not in names]
        if missing:
            raise ValueError(f"variables of the constraints not in variables=: "
                             f"{', '.join(missing)}")
        self.variables, self.n = names, len(names)
        self.eps, self.max_depth, self.max_steps = float(eps), int(max_depth), int(max_steps)
        self._tape = compile_model(model)
        self._slot = np.array([self._tape.slot_of[v] for v in names], dtype=np.int64)
        # every node a variable reaches (no truncation: these are small constraint sets)
        cand, self._cptr, self._cnodes = bc_candidates(self._tape, np.unique(self._slot),
                                                       max(self._tape.n_nodes, 1))
        self._cand = cand
        keep = set(cand.tolist())
        #: the variables narrowed (those occurring several times in their constraints)
        self.candidates = [v for v, s in zip(names, self._slot, strict=True) if int(s) in keep]
        self._families = family_flags(self._tape.op)

    def contract(self, x: Interval) -> Interval:
        if x.ndim == 0:
            raise ValueError("CtcBox contracts boxes (shape (..., n)), not a scalar interval")
        shape = x.shape
        lo = np.ascontiguousarray(x.lo.reshape(-1, self.n), dtype=np.float64).copy()
        hi = np.ascontiguousarray(x.hi.reshape(-1, self.n), dtype=np.float64).copy()
        t = self._tape
        if np.isnan(t.lo).any():  # the constraints alone are inconsistent
            lo[:] = hi[:] = np.nan
        else:
            bc_boxes(t.op, t.out, t.a, t.b, t.param, t.lo, t.hi, self._slot, lo, hi, self._cand,
                     self._cptr, self._cnodes, self.eps, self.max_depth, self.max_steps,
                     *self._families)
        return _empty_rows(Interval.trusted(lo.reshape(shape), hi.reshape(shape)))
