"""All solutions of a square system of equations: branch and prune with interval Newton.

``solve_square`` bisects the box, contracts every box of the frontier (batched) with hull
consistency and the interval Newton contractor (:class:`boundest.ctc.CtcNewton`), and keeps the
boxes where the Krawczyk test proves that exactly one solution lies inside. What is left at the
precision ``eps`` without a proof is *undecided*: it may hold a solution (a multiple root, a
root on a box face, a singular Jacobian), or none that the contractors could refute. Every
solution of the system in the initial box lies in a proved or an undecided box.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numba as nb
import numpy as np
from numpy.typing import NDArray

from ..ctc.centered import CtcNewton
from ..ctc.derivatives import jacobian_sparse
from ..ctc.revise import family_flags, hc4_pass
from ..expr.function_tape import constraint_functions
from ..expr.model import Model
from ..expr.tape import compile_model
from ..interval import Interval

__all__ = ["Roots", "solve_square"]


@dataclass
class Roots:
    """The result of ``solve_square``.

    Attributes
    ----------
    boxes : Interval, shape (k, n)
        Proved boxes first, then undecided ones.
    proved : bool array, shape (k,)
        ``True``: the box holds exactly one solution (Krawczyk test).
    variables : list of str
        The variable of each box component.
    stats : dict
        ``processed`` (boxes contracted), ``bisections``, ``stopped`` (``"eps"`` or
        ``"max_boxes"``), ``time_s``, ``undecided_why`` (reason -> count: ``"eps"`` a box
        narrower than eps without proof, ``"discontinuous"`` some primitive is not defined or
        not continuous on it, ``"max_boxes"`` left when the box budget ran out), ``merged``
        (proved boxes found to hold the same solution and merged).
    """

    boxes: Interval
    proved: NDArray[np.bool_]
    variables: list[str]
    stats: dict[str, Any] = field(default_factory=dict)

    @property
    def solutions(self) -> Interval:
        """The proved boxes, one per solution."""
        return self.boxes[self.proved]

    @property
    def undecided(self) -> Interval:
        return self.boxes[~self.proved]

    def __len__(self) -> int:
        return len(self.proved)

    def __repr__(self) -> str:
        return (f"Roots({int(self.proved.sum())} proved solutions, "
                f"{int((~self.proved).sum())} undecided boxes)")


@nb.njit(cache=True, error_model="numpy")
def _hc4_batch(op, out, a, b, param, slot_lo, slot_hi, var_slots, xl, xh, passes,
               piecewise, pown, explog, trig):
    """Forward-backward passes (:func:`boundest.ctc.revise.hc4_pass`, compiled) on each box
    ``(xl[i], xh[i])`` of the model's constraint tape, in place (NaN bounds: no solution).

    An empty box (NaN bounds, e.g. refuted by Newton) stays empty: ``max(lo, nan)`` would keep
    the slot's initial domain and bring the whole domain back."""
    buf = np.empty(4)
    for i in range(xl.shape[0]):
        if not np.all(xl[i] <= xh[i]):
            xl[i, :] = np.nan
            xh[i, :] = np.nan
            continue
        lo = slot_lo.copy()
        hi = slot_hi.copy()
        for j in range(var_slots.size):
            s = var_slots[j]
            lo[s] = max(lo[s], xl[i, j])
            hi[s] = min(hi[s], xh[i, j])
        ok = True
        for _ in range(passes):
            if not hc4_pass(op, out, a, b, param, lo, hi, buf, piecewise, pown, explog, trig):
                ok = False
                break
        for j in range(var_slots.size):
            s = var_slots[j]
            xl[i, j] = lo[s] if ok else np.nan
            xh[i, j] = hi[s] if ok else np.nan


class _HC4:
    """Hull consistency of a model on a batch of boxes (a few compiled passes per box)."""

    def __init__(self, model: Model, names: list[str], passes: int = 3) -> None:
        self.tape = compile_model(model)
        self.slots = np.array([self.tape.slot_of[v] for v in names], dtype=np.int64)
        self.flags = family_flags(self.tape.op)
        self.passes = passes

    def __call__(self, x: Interval) -> Interval:
        t = self.tape
        lo, hi = x.lo.copy(), x.hi.copy()
        _hc4_batch(t.op, t.out, t.a, t.b, t.param, t.lo, t.hi, self.slots, lo, hi,
                   self.passes, *self.flags)
        return Interval._new(lo, hi)


def _nonempty(x: Interval) -> NDArray[np.bool_]:
    return ~np.isnan(x.lo).any(axis=-1)


def _newton_rounds(newton: CtcNewton, hc4: _HC4 | None, x: Interval, rounds: int
                   ) -> tuple[Interval, NDArray[np.bool_]]:
    """Alternate Newton and hull consistency while some box still shrinks by 10 %.

    Newton runs first on each box: hull consistency may leave a component degenerate (one
    exact value), where the Krawczyk test has no room to prove anything; a proof found on a
    box stays valid for every contraction of it."""
    proved = np.zeros(len(x), dtype=np.bool_)
    for _ in range(rounds):
        before = x.width().max(axis=-1)
        x, p = newton.prove(x)
        proved |= p & _nonempty(x)
        if hc4 is not None:
            x = hc4(x)
        after = x.width().max(axis=-1)
        with np.errstate(invalid="ignore"):
            if not np.any(after < 0.9 * before):
                break
    return x, proved & _nonempty(x)


def _merge(newton: CtcNewton, boxes: Interval) -> tuple[Interval, int]:
    """Proved boxes that overlap and whose hull is proved to hold one solution are one."""
    k = len(boxes)
    if k < 2:
        return boxes, 0
    lo, hi = boxes.lo, boxes.hi
    keep = np.ones(k, dtype=np.bool_)
    merged = 0
    meets = np.all((lo[:, None, :] <= hi[None, :, :]) & (lo[None, :, :] <= hi[:, None, :]),
                   axis=-1)
    for i in range(k):  # proved boxes are few: one per solution
        if not keep[i]:
            continue
        for j in np.nonzero(meets[i, i + 1:])[0] + i + 1:
            if not keep[j]:
                continue
            h = Interval(np.minimum(lo[i], lo[j]), np.maximum(hi[i], hi[j]))
            hb, p = newton.prove(h[None, :])
            if p[0]:
                lo[i], hi[i] = hb.lo[0], hb.hi[0]
                keep[j] = False
                merged += 1
    return Interval(lo[keep], hi[keep]), merged


def solve_square(system: Model | Sequence, box: Interval | None = None, *, eps: float = 1e-8,
                 max_boxes: int = 100_000) -> Roots:
    """Every solution of ``n`` equations in ``n`` unknowns in a box, with proofs.

    Parameters
    ----------
    system : Model or list of Constraint
        Equations ``lhs == rhs`` (other constraints may restrict the domains but are not used
        by Newton: they must come with as many equations as unknowns).
    box : Interval, shape (n,), optional
        The search box (default: the model's declared domains; they must be bounded).
    eps : float
        Boxes narrower than this without a proof are reported undecided.
    max_boxes : int
        Stop bisecting when proved, undecided and frontier boxes would exceed this many.

    Examples
    --------
    >>> from boundest.expr import Var
    >>> x, y = Var("x"), Var("y")
    >>> m = Model().add(x**2 + y**2 == 4, x * y == 1)
    >>> r = solve_square(m, Interval([-3, -3], [3, 3]))
    >>> int(r.proved.sum()), int((~r.proved).sum())
    (4, 0)
    """
    t0 = time.perf_counter()
    model = system if isinstance(system, Model) else Model(constraints=list(system))
    eqs = [c for c in model.constraints if c.rel == "=="]
    names = model.variable_names()
    tape, domains = constraint_functions(Model(domains=model.domains, constraints=eqs))
    if len(eqs) != len(names):
        raise ValueError(f"solve_square needs as many equations as unknowns: {len(eqs)} "
                         f"equations in {len(names)} unknowns ({', '.join(names)})")
    if box is None:
        box = domains
    if box.shape != (len(names),):
        raise ValueError(f"the box must have shape ({len(names)},), got {box.shape}")
    if not np.all(np.isfinite(box.lo) & np.isfinite(box.hi)):
        raise ValueError("solve_square needs a bounded box")
    if not eps > 0:
        raise ValueError(f"eps must be positive, got {eps}")
    newton = CtcNewton(tape)
    hc4 = _HC4(model, list(tape.names))
    frontier = box[None, :]
    proved_boxes: list[Interval] = []
    undecided: list[Interval] = []
    reasons: list[NDArray] = []
    processed = bisections = 0
    stopped = "eps"
    while len(frontier):
        processed += len(frontier)
        x, proved = _newton_rounds(newton, hc4, frontier, 8)
        alive = _nonempty(x)
        proved_boxes.append(x[proved])
        x = x[alive & ~proved]
        small = x.width().max(axis=-1) < eps
        if small.any():
            undecided.append(x[small])
            reasons.append(np.full(int(small.sum()), "eps"))
        x = x[~small]
        count = (sum(len(b) for b in proved_boxes) + sum(len(b) for b in undecided)
                 + 2 * len(x))
        if count > max_boxes:
            undecided.append(x)
            reasons.append(np.full(len(x), "max_boxes"))
            stopped = "max_boxes"
            break
        if len(x):
            left, right = x.bisect()
            bisections += len(x)
            frontier = Interval(np.concatenate([left.lo, right.lo]),
                                np.concatenate([left.hi, right.hi]))
        else:
            frontier = x
    n = len(names)
    sol = _cat(proved_boxes, n)
    und = _cat(undecided, n)
    # a root on a bisection face: try the proof on a slightly inflated undecided box; a proof
    # on a contraction of the inflated box proves that the inflated box holds exactly one
    # solution (the contraction lost none), so the undecided boxes inside it hold no other
    covers = sol
    if len(und):
        rad = np.maximum(und.width(), eps) * 0.25
        infl = Interval(np.maximum(und.lo - rad, box.lo), np.minimum(und.hi + rad, box.hi))
        ib, ip = _newton_rounds(newton, None, infl, 4)
        if ip.any():
            sol = _cat([sol, ib[ip]], n)
            covers = _cat([covers, infl[ip]], n)
    sol, merged = _merge(newton, sol)
    why = np.concatenate(reasons) if reasons else np.empty(0, dtype="<U13")
    if len(und):  # an undecided box inside a proved one holds no other solution
        inside = np.zeros(len(und), dtype=np.bool_)
        for i in range(len(covers)):
            inside |= np.all((und.lo >= covers.lo[i]) & (und.hi <= covers.hi[i]), axis=-1)
        und, why = und[~inside], why[~inside]
    if len(und):
        _, _, cont = jacobian_sparse(newton.tape, und, with_defined=True)
        why = np.where(cont | (why != "eps"), why, "discontinuous")
    boxes = _cat([sol, und], n)
    proved = np.concatenate([np.ones(len(sol), dtype=np.bool_), np.zeros(len(und), np.bool_)])
    return Roots(boxes, proved, list(tape.names), {
        "processed": processed, "bisections": bisections, "stopped": stopped,
        "time_s": time.perf_counter() - t0, "merged": merged,
        "undecided_why": {r: int((why == r).sum()) for r in ("eps", "discontinuous",
                                                             "max_boxes")}})


def _cat(parts: list[Interval], n: int) -> Interval:
    parts = [p for p in parts if len(p)]
    if not parts:
        return Interval(np.empty((0, n)), np.empty((0, n)))
    return Interval(np.concatenate([p.lo for p in parts]), np.concatenate([p.hi for p in parts]))
