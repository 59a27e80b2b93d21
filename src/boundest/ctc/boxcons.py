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
domain, run for all boxes of a batch at once: each step evaluates ``F_i`` once on the whole
batch of boxes still searching (one vectorised call per node of the expression), and each box
keeps its own position ``(depth, index)`` in its tree. There is no Python loop per box. A box
whose search runs out of ``max_steps`` keeps the left end of its current slice, which is still
sound: in depth-first order every slice to its left was refuted.

Only the natural interval extension is used (the expression layer has no symbolic
differentiation, so there is no centred / mean-value form here).
"""

from __future__ import annotations

from collections.abc import Sequence as Seq

import numpy as np
from numpy.typing import NDArray

from ..expr.model import Model
from ..expr.nodes import Const, Constraint, Expr, Op, Var
from ..interval import Interval
from .base import Contractor, _empty_rows
from .fwdbwd import FORWARD

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


def _evaluate(e: Expr, cols: dict[str, Interval]) -> Interval:
    """Natural interval extension of ``e``, the variables given as batched columns."""
    memo: dict[int, Interval] = {}

    def ev(t: Expr) -> Interval:
        r = memo.get(id(t))
        if r is not None:
            return r
        if isinstance(t, Var):
            r = cols[t.name]
        elif isinstance(t, Const):
            r = t.value
        elif isinstance(t, Op):
            args = [ev(a) for a in t.args]
            r = (FORWARD[t.name](args[0], t.param) if t.name == "pown"
                 else FORWARD[t.name](*args))
        else:
            raise TypeError(f"not an expression: {t!r}")
        memo[id(t)] = r
        return r

    return ev(e)


def _as_range(c: Constraint) -> tuple[Expr, float, float]:
    """``c`` as ``g(x) ∈ [ylo, yhi]``."""
    lhs, rel, rhs = c.lhs, c.rel, c.rhs
    if rel == ">=":
        lhs, rhs, rel = rhs, lhs, "<="
    if rel == "in" or (rel == "==" and isinstance(rhs, Const)):
        assert isinstance(rhs, Const)
        return lhs, float(rhs.value.lo), float(rhs.value.hi)
    if rel == "==" and isinstance(lhs, Const):
        return rhs, float(lhs.value.lo), float(lhs.value.hi)
    if rel == "==":
        return lhs - rhs, 0.0, 0.0
    if isinstance(rhs, Const):  # lhs <= rhs
        return lhs, -np.inf, float(rhs.value.hi)
    if isinstance(lhs, Const):
        return rhs, float(lhs.value.lo), np.inf
    return lhs - rhs, -np.inf, 0.0


def _point(lo: NDArray, hi: NDArray, t: NDArray) -> NDArray:
    """``lo + t (hi - lo)`` for dyadic ``t ∈ [0, 1]``, exactly ``lo`` at 0 and ``hi`` at 1 and
    non-decreasing in ``t`` (rounding is monotone), so adjacent slices of the bisection tree
    share their endpoints exactly and cover the domain; no overflow when ``hi - lo`` does."""
    with np.errstate(over="ignore", invalid="ignore"):
        w = hi - lo
        p = np.where(np.isfinite(w), lo + t * w, 2.0 * (0.5 * lo + t * (0.5 * hi - 0.5 * lo)))
    p = np.clip(p, lo, hi)
    p = np.where(t == 0.0, lo, p)
    return np.where(t == 1.0, hi, p)


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
        Evaluations per bound and per (constraint, variable) at most; a search cut short keeps
        what it has refuted so far.

    Notes
    -----
    One call is one pass over every (constraint, multiply occurring variable) pair, each
    narrowing applied before the next. Variables that occur once are left to hull
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
        index = {v: j for j, v in enumerate(names)}
        self._domain = (np.array([float(model.domains[v].lo) if v in model.domains else -np.inf
                                  for v in names]),
                        np.array([float(model.domains[v].hi) if v in model.domains else np.inf
                                  for v in names]))
        #: (g, ylo, yhi, [indices of the variables occurring several times in g])
        self.pairs: list[tuple[Expr, float, float, list[int]]] = []
        for c in model.constraints:
            g, ylo, yhi = _as_range(c)
            multi = [index[v] for v, k in occurrences(g).items() if k > 1]
            if multi:
                self.pairs.append((g, ylo, yhi, sorted(multi)))

    def contract(self, x: Interval) -> Interval:
        if x.ndim == 0:
            raise ValueError("CtcBox contracts boxes (shape (..., n)), not a scalar interval")
        shape = x.shape
        lo = np.maximum(x.lo.reshape(-1, self.n), self._domain[0])
        hi = np.minimum(x.hi.reshape(-1, self.n), self._domain[1])
        bad = ~(lo <= hi).all(axis=-1)
        lo[bad] = hi[bad] = np.nan
        for g, ylo, yhi, multi in self.pairs:
            for i in multi:
                for side in (0, 1):
                    live = np.flatnonzero(~np.isnan(lo[:, 0]))
                    if live.size == 0:
                        break
                    bound, empty = self._search(g, ylo, yhi, lo[live], hi[live], i, side)
                    (lo if side == 0 else hi)[live, i] = bound
                    lo[live[empty]] = hi[live[empty]] = np.nan
        return _empty_rows(Interval._new(lo.reshape(shape), hi.reshape(shape)))

    def _search(self, g: Expr, ylo: float, yhi: float, lo: NDArray, hi: NDArray, i: int,
                side: int) -> tuple[NDArray, NDArray]:
        """Depth-first search of the leftmost (``side`` 0) or rightmost (1) slice of
        component ``i`` whose image meets ``[ylo, yhi]``, for every box ``(lo, hi)`` (shape
        ``(m, n)``). Returns the new bound of each box and which boxes are empty."""
        m = lo.shape[0]
        L, U = lo[:, i], hi[:, i]
        bound = (L if side == 0 else U).copy()
        empty = np.zeros(m, dtype=bool)
        d = np.zeros(m, dtype=np.int64)
        k = np.zeros(m, dtype=np.int64)
        act = np.arange(m)
        finite = np.isfinite(L) & np.isfinite(U)
        for _ in range(self.max_steps):
            if act.size == 0:
                break
            scale = np.ldexp(1.0, -d[act])  # exact: d <= 52
            t0, t1 = k[act] * scale, (k[act] + 1) * scale
            if side == 1:
                t0, t1 = 1.0 - t1, 1.0 - t0
            la, ua = L[act], U[act]
            a, b = _point(la, ua, t0), _point(la, ua, t1)
            cols = {v: Interval._new(lo[act, j], hi[act, j])
                    for j, v in enumerate(self.variables)}
            cols[self.variables[i]] = Interval._new(a, b)
            img = _evaluate(g, cols)
            with np.errstate(invalid="ignore"):
                ok = (img.lo <= yhi) & (img.hi >= ylo)  # NaN (empty image): refuted
            ok = np.broadcast_to(ok, act.shape)
            # a slice that meets [y]: the bound when thin enough (or not bisectable)
            with np.errstate(over="ignore"):
                thin = b - a <= self.eps
            stop = ok & (thin | (d[act] >= self.max_depth) | ~finite[act])
            bound[act[stop]] = (a if side == 0 else b)[stop]
            down = ok & ~stop
            d[act[down]] += 1
            k[act[down]] *= 2
            # a refuted slice: the next one in depth-first order (up while a right child)
            ref = act[~ok]
            while True:
                up = (k[ref] & 1).astype(bool) & (d[ref] > 0)
                if not up.any():
                    break
                k[ref[up]] >>= 1
                d[ref[up]] -= 1
            gone = d[ref] == 0  # the whole domain refuted
            empty[ref[gone]] = True
            k[ref[~gone]] += 1
            act = act[down | (~ok & (d[act] > 0))]
        else:  # cut short: everything before the current slice was refuted
            if act.size:
                scale = np.ldexp(1.0, -d[act])
                t = k[act] * scale if side == 0 else 1.0 - k[act] * scale
                bound[act] = _point(L[act], U[act], t)
        return bound, empty
