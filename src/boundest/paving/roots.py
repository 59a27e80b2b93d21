"""All solutions of a square system of equations: branch and prune with interval Newton.

``solve_square`` contracts every box of the frontier with hull consistency and 3B shaving
(:class:`_Shaving`, the compiled kernel of :func:`boundest.csp.engine.shave_kernel`) and the
interval Newton contractor (:class:`boundest.ctc.CtcNewton`), keeps the boxes where the
Krawczyk test proves that exactly one solution lies inside, and bisects the others (the whole
frontier at once) along the variable of largest relative smear sum. What is left at the
precision ``eps`` without a proof is *undecided*: it may hold a solution (a multiple root, a
root on a box face, a singular Jacobian), or none that the contractors could refute. Every
solution of the system in the initial box lies in a proved or an undecided box.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..csp.engine import EMPTY, SHAVE_STATS, shave_kernel
from ..csp.propagate import slot_users
from ..ctc.centered import CtcNewton
from ..ctc.derivatives import evaluate, jacobian_sparse
from ..ctc.revise import family_flags
from ..expr.function_tape import (
    FunctionTape,
    _as_function,
    constraint_functions,
    function_tape,
)
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
        (proved boxes found to hold the same solution and merged), ``newton`` (Newton calls,
        one per box), ``shave_probes`` (slices propagated by shaving).
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


class _Shaving:
    """Hull consistency to a fixed point, then 3B shaving of every variable, box by box: the
    compiled kernel of :func:`boundest.csp.engine.shave_kernel` (ACID-like: a slice at each
    bound is propagated and removed when the propagation proves it empty, slices double while
    they are refuted; a variable is shaved again only while shaving pays). A probe revises only
    what its change reaches, so its cost does not grow with the system. ``shave=False``:
    hull consistency alone."""

    def __init__(self, model: Model, names: list[str], shave: bool = True) -> None:
        self.tape = t = compile_model(model)
        self.slots = np.array([t.slot_of[v] for v in names], dtype=np.int64)
        self.ptr, self.adj = slot_users(t)
        self.flags = family_flags(t.op)
        self.cand = self.slots if shave else self.slots[:0]
        self.stats = np.zeros(len(SHAVE_STATS), dtype=np.int64)
        self.probes = 0

    def __call__(self, x: Interval, shave: NDArray[np.bool_] | None = None) -> Interval:
        """Contract boxes ``(k, n)``; ``shave[i]`` False: hull consistency alone on box i."""
        t = self.tape
        out_lo, out_hi = x.lo.copy(), x.hi.copy()
        for i in range(len(x)):
            cand = self.cand if shave is None or shave[i] else self.cand[:0]
            lo, hi = t.lo.copy(), t.hi.copy()
            if np.all(x.lo[i] <= x.hi[i]):  # NaN bounds: an empty box
                np.maximum.at(lo, self.slots, x.lo[i])  # several variables may share a slot
                np.minimum.at(hi, self.slots, x.hi[i])
            else:
                lo[0], hi[0] = 1.0, 0.0
            if not np.all(lo <= hi) or shave_kernel(
                    t.op, t.out, t.a, t.b, t.param, lo, hi, self.ptr, self.adj, cand,
                    *_SHAVE, self.stats, *self.flags) == EMPTY or np.isnan(lo).any():
                out_lo[i] = out_hi[i] = np.nan  # NaN bounds in x (empty) also end here
                continue
            self.probes += int(self.stats[1])
            out_lo[i] = np.maximum(x.lo[i], lo[self.slots])
            out_hi[i] = np.minimum(x.hi[i], hi[self.slots])
        return Interval.trusted(out_lo, out_hi)


#: shave_kernel's settings: rel_eps, probe_eps, probe_evals, frac, max_rounds, reach, min_gain,
#: window (those of boundest.csp.propagate.Shaving and propagate's rel_eps)
_SHAVE = (1e-3, 1e-2, 500, 0.1, 2, 12, 0.05, 64)
#: bisection point, as a fraction of the chosen component's width (IBEX's Bsc default is 0.45:
#: off the middle, so that a symmetric system's root does not fall on the cut)
_RATIO = 0.45


def _nonempty(x: Interval) -> NDArray[np.bool_]:
    return ~np.isnan(x.lo).any(axis=-1)


def _contract(newton: CtcNewton, prop: _Shaving, x: Interval, rounds: int,
              in_model: Callable[[Interval], NDArray[np.bool_]]
              ) -> tuple[Interval, NDArray[np.bool_], int]:
    """Alternate propagation (hull consistency and shaving) and Newton on each box while it
    shrinks by 10 % (its widest component). Returns the boxes, which are proved to hold exactly
    one solution, and the number of Newton calls.

    Newton runs on the propagated box except where propagation left a component degenerate
    (one exact value): there it gets the component from before, since the Krawczyk test has no
    room to prove anything in a zero radius (any box between the two holds every solution).
    A box that Newton halved in a round is not shaved in the next one (Newton converges on it:
    shaving would cost much and add little). A proof counts where the whole box Newton returns
    lies in the declared domains and satisfies the other constraints (``in_model``): its one
    solution of the equations is then a solution of the model (propagation, which uses the
    domains and the other constraints, may have cut the root away and left Newton a thin
    component widened back). Proved boxes leave the rounds: they are polished by Newton alone
    (:func:`_polish`)."""
    lo, hi = x.lo.copy(), x.hi.copy()
    proved = np.zeros(len(x), dtype=np.bool_)
    active = _nonempty(x)
    shave = np.ones(len(x), dtype=np.bool_)
    calls = 0
    for _ in range(rounds):
        idx = np.flatnonzero(active)
        if not len(idx):
            break
        xa = Interval.trusted(lo[idx], hi[idx])
        before = xa.width().max(axis=-1)
        y = prop(xa, shave[idx])
        alive = _nonempty(y)
        thin = y.width() <= 0
        zl = np.where(thin, xa.lo, y.lo)
        zh = np.where(thin, xa.hi, y.hi)
        zl[~alive] = zh[~alive] = np.nan
        sel = np.flatnonzero(alive)
        if len(sel):
            z0 = Interval.trusted(zl[sel], zh[sel])
            z, p = newton.prove(z0)
            calls += len(sel)
            zl[sel], zh[sel] = z.lo, z.hi
            proved[idx[sel]] = p & _nonempty(z) & in_model(z)
            with np.errstate(invalid="ignore"):
                shave[idx[sel]] = ~(z.width().max(axis=-1) < 0.5 * z0.width().max(axis=-1))
        lo[idx], hi[idx] = zl, zh
        after = np.where(alive, np.nan_to_num(zh - zl, nan=0.0).max(axis=-1), 0.0)
        with np.errstate(invalid="ignore"):
            active[idx] = alive & (after < 0.9 * before) & ~proved[idx]
    out = Interval.trusted(lo, hi)
    return out, proved & _nonempty(out), calls


def _polish(newton: CtcNewton, x: Interval, rounds: int = 4) -> tuple[Interval, int]:
    """Newton steps on proved boxes while they halve (a contraction of a proved box holds its
    solution, and lies in the domains and the other constraints if the box did: nothing to
    prove again)."""
    calls = 0
    for _ in range(rounds):
        if not len(x):
            break
        y, _ = newton.prove(x)
        calls += len(x)
        ok = _nonempty(y)  # a proved box is never emptied; keep x where rounding says so
        y = Interval.trusted(np.where(ok[:, None], y.lo, x.lo), np.where(ok[:, None], y.hi, x.hi))
        shrunk = y.width().max(axis=-1) < 0.5 * x.width().max(axis=-1)
        x = y
        if not shrunk.any():
            break
    return x, calls


def _prove(newton: CtcNewton, x: Interval, rounds: int,
           in_model: Callable[[Interval], NDArray[np.bool_]]
           ) -> tuple[Interval, NDArray[np.bool_], int]:
    """Newton alone while a box shrinks by 10 %: the boxes and which are proved (a proof
    counts where the box lies in the model, as in :func:`_contract`)."""
    proved = np.zeros(len(x), dtype=np.bool_)
    calls = 0
    for _ in range(rounds):
        before = x.width().max(axis=-1)
        x, p = newton.prove(x)
        calls += len(x)
        proved |= p & _nonempty(x) & in_model(x)
        with np.errstate(invalid="ignore"):
            if not np.any(x.width().max(axis=-1) < 0.9 * before):
                break
    return x, proved & _nonempty(x), calls


def _bisect(tape: FunctionTape, x: Interval, eps: float
            ) -> tuple[Interval, NDArray[np.bool_]]:
    """Split each box in two along the component of largest relative smear sum (IBEX's
    SmearSumRelative: ``sum_i |J_ij| w_j / sum_k |J_ik| w_k``, the share of the variable in the
    width of each equation's linearisation), among the components at least ``eps`` wide that
    ``_RATIO`` cuts strictly inside; the widest such component where no smear is positive.
    Returns the halves (left ones first) and, per box, whether it could be split."""
    w = x.width()
    p = x.lo + _RATIO * w
    can = (w >= eps) & (x.lo < p) & (p < x.hi)
    _, e, _ = jacobian_sparse(tape, x, with_defined=True)
    with np.errstate(invalid="ignore", over="ignore"):
        mag = np.maximum(np.abs(e.lo), np.abs(e.hi))
        s = mag * w[:, tape.cols]
    s = np.where(np.isfinite(s), s, 1e300)  # an infinite or undefined slope: a large smear
    rows = np.repeat(np.arange(tape.n_outputs), np.diff(tape.row_ptr))
    tot = np.zeros((len(x), tape.n_outputs))
    np.add.at(tot, (slice(None), rows), s)
    tot = tot[:, rows]
    s = np.divide(s, tot, out=np.zeros_like(s), where=tot > 0)
    score = np.zeros(w.shape)
    np.add.at(score, (slice(None), tape.cols), s)
    score[~can] = -1.0
    k = np.arange(len(x))
    axis = np.argmax(score, axis=-1)
    flat = score[k, axis] <= 0.0
    axis[flat] = np.argmax(np.where(can, w, -1.0), axis=-1)[flat]
    ok = can[k, axis]
    k, axis = k[ok], axis[ok]
    llo, lhi, rlo, rhi = x.lo[ok], x.hi[ok].copy(), x.lo[ok].copy(), x.hi[ok]
    lhi[np.arange(len(k)), axis] = p[k, axis]
    rlo[np.arange(len(k)), axis] = p[k, axis]
    return Interval.trusted(np.concatenate([llo, rlo]), np.concatenate([lhi, rhi])), ok


def _inside(model: Model, names: list[str], domains: Interval
            ) -> Callable[[Interval], NDArray[np.bool_]]:
    """Per box, whether every point of it lies in the declared domains and satisfies the
    model's constraints other than its equations (natural interval form)."""
    others = [_as_function(c) for c in model.constraints if c.rel != "=="]
    tape = function_tape([g for g, _, _ in others], names, [(a, b) for _, a, b in others])

    def inside(x: Interval) -> NDArray[np.bool_]:
        ok = np.all((x.lo >= domains.lo) & (x.hi <= domains.hi), axis=-1)
        if others:
            v = evaluate(tape, x)
            ok &= np.all((v.lo >= tape.target_lo) & (v.hi <= tape.target_hi), axis=-1)
        return ok

    return inside


def _merge(newton: CtcNewton, boxes: Interval, eps: float) -> tuple[Interval, int]:
    """Proved boxes that overlap and whose hull (or the hull inflated by a quarter of its
    width, at least ``eps / 4``) is proved to hold one solution are one."""
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
            if np.all((lo[i] <= lo[j]) & (hi[j] <= hi[i])) or np.all(
                    (lo[j] <= lo[i]) & (hi[i] <= hi[j])):
                # nested (e.g. the same point twice, from a root on a bisection face): the
                # inner box's solution is the outer one's only solution
                lo[i], hi[i] = np.maximum(lo[i], lo[j]), np.minimum(hi[i], hi[j])
                keep[j] = False
                merged += 1
                continue
            h = Interval(np.minimum(lo[i], lo[j]), np.maximum(hi[i], hi[j]))
            hb, p = newton.prove(h[None, :])
            if not p[0]:  # a hull a few ulps wide leaves Krawczyk no room beyond rounding
                rad = np.maximum(h.width(), eps) * 0.25
                hb, p = newton.prove(Interval(h.lo - rad, h.hi + rad)[None, :])
            if p[0]:  # one solution in the hull: the same in both boxes, so in both
                nl = np.maximum(np.maximum(lo[i], lo[j]), hb.lo[0])
                nh = np.minimum(np.minimum(hi[i], hi[j]), hb.hi[0])
                lo[i], hi[i] = (nl, nh) if np.all(nl <= nh) else (hb.lo[0], hb.hi[0])
                keep[j] = False
                merged += 1
    return Interval(lo[keep], hi[keep]), merged


def solve_square(system: Model | Sequence, box: Interval | None = None, *, eps: float = 1e-8,
                 max_boxes: int = 100_000, shaving: bool = True) -> Roots:
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
    shaving : bool
        Contract each box by 3B shaving after hull consistency (:class:`_Shaving`; the default)
        or by hull consistency alone. Shaving costs more per box and usually saves most
        bisections (Broyden banded in ``[-100, 100]^n``: one box instead of hundreds).

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
    prop = _Shaving(model, list(tape.names), shave=shaving)
    in_model = _inside(model, list(tape.names), domains)
    frontier = box[None, :]
    proved_boxes: list[Interval] = []
    undecided: list[Interval] = []
    reasons: list[NDArray] = []
    processed = bisections = calls = 0
    stopped = "eps"
    while len(frontier):
        processed += len(frontier)
        x, proved, c = _contract(newton, prop, frontier, 8, in_model)
        calls += c
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
            frontier, split = _bisect(tape, x, eps)
            bisections += int(split.sum())
            if not split.all():  # no component can be cut strictly inside (float spacing)
                undecided.append(x[~split])
                reasons.append(np.full(int((~split).sum()), "eps"))
        else:
            frontier = x
    n = len(names)
    sol, c = _polish(newton, _cat(proved_boxes, n))
    calls += c
    und = _cat(undecided, n)
    # a root on a bisection face, or a box whose components propagation made too thin for the
    # Krawczyk test: try the proof on a slightly inflated undecided box; a proof on a
    # contraction of the inflated box proves that the inflated box holds exactly one solution
    # (the contraction lost none), so the undecided boxes inside it hold no other
    covers = sol
    if len(und):
        rad = np.maximum(und.width(), eps) * 0.25
        infl = Interval(np.maximum(und.lo - rad, box.lo), np.minimum(und.hi + rad, box.hi))
        ib, ip, c = _prove(newton, infl, 4, in_model)
        calls += c
        if ip.any():
            sol = _cat([sol, ib[ip]], n)
            covers = _cat([covers, infl[ip]], n)
    sol, merged = _merge(newton, sol, eps)
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
        "time_s": time.perf_counter() - t0, "merged": merged, "newton": calls,
        "shave_probes": prop.probes,
        "undecided_why": {r: int((why == r).sum()) for r in ("eps", "discontinuous",
                                                             "max_boxes")}})


def _cat(parts: list[Interval], n: int) -> Interval:
    parts = [p for p in parts if len(p)]
    if not parts:
        return Interval(np.empty((0, n)), np.empty((0, n)))
    return Interval(np.concatenate([p.lo for p in parts]), np.concatenate([p.hi for p in parts]))
