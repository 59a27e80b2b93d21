"""SIVIA: set inversion via interval analysis, the whole frontier of boxes as one batch.

``sivia`` characterises ``S = {x in box : f(x) in y}`` (or a set given by an inclusion test or a
pair of contractors) by a ``Subpaving``. Each iteration classifies every undecided box at once
(one batched contractor or test call), then bisects all the boxes still undecided and wider than
``eps`` at once (``Interval.bisect`` splits each box of a batch along its own widest side).

With contractors, ``ctc_out`` contracts ``S`` and ``ctc_in`` its complement. What ``ctc_out``
removes from a box ``x`` holds no point of ``S``: its closure ``x - ctc_out(x)`` (at most ``2n``
boxes, ``box_difference``) is outside. What ``ctc_in`` removes holds no point of the complement,
so its closure lies in the closure of ``S``: inside, for a closed ``S`` (which ``f^-1(y)`` is for a
continuous ``f`` and a closed ``y``). The contracted box stays undecided. No point of ``S`` in
``box`` ever leaves the inside and boundary boxes.

Examples
--------
>>> from boundest.expr import Var
>>> from boundest.interval import Interval
>>> x, y = Var("x"), Var("y")
>>> ring = sivia(Interval([-3, -3], [3, 3]), f=x**2 + y**2, y=Interval([1], [4]), eps=0.1)
>>> ring.volume_inner() <= 3 * np.pi <= ring.volume_outer()
True
>>> int(ring.contains(np.array([[1.5, 0.0], [0.0, 0.0]]))[1])
-1
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass
from itertools import pairwise

import numpy as np
from numpy.typing import NDArray

from ..ctc import Contractor, CtcFwdBwd, Union
from ..expr import Expr, variables
from ..interval import Interval, as_interval
from ..parallel import map_chunked
from .subpaving import Subpaving, box_difference

__all__ = ["separators", "sivia"]

Test = Callable[[Interval], NDArray]


class _Nothing(Contractor):
    """The contractor of the empty set (used for the complement of ``y = R^m``)."""

    def contract(self, x: Interval) -> Interval:
        return Interval.trusted(np.full(x.shape, np.nan), np.full(x.shape, np.nan))


def separators(f: Expr | Sequence[Expr], y: Interval, variables_: Sequence[str] | None = None
               ) -> tuple[Contractor, Contractor]:
    """The contractor pair ``(ctc_in, ctc_out)`` of ``{x : f(x) in y}``: ``ctc_out`` is the
    forward-backward contractor of ``f_i(x) in y_i``, ``ctc_in`` the union of those of
    ``f_i(x) <= lo(y_i)`` and ``f_i(x) >= hi(y_i)`` over the finite bounds (the closure of the
    complement).
    """
    exprs = [f] if isinstance(f, Expr) else list(f)
    if not exprs or not all(isinstance(e, Expr) for e in exprs):
        raise ValueError(f"f must be an expression or a list of expressions, got {f!r}")
    yv = as_interval(y).reshape(-1)
    if yv.shape[0] != len(exprs):
        raise ValueError(f"y has {yv.shape[0]} components for {len(exprs)} expressions of f")
    names = ([v.name for v in variables(exprs)] if variables_ is None else list(variables_))
    ctc_out = CtcFwdBwd([e.in_(yv[i]) for i, e in enumerate(exprs)], names)
    pieces: list[Contractor] = []
    for i, e in enumerate(exprs):
        lo, hi = float(yv.lo[i]), float(yv.hi[i])
        if lo > -np.inf:
            pieces.append(CtcFwdBwd([e <= lo], names))
        if hi < np.inf:
            pieces.append(CtcFwdBwd([e >= hi], names))
    ctc_in: Contractor = Union(*pieces) if pieces else _Nothing()
    return ctc_in, ctc_out


def _contract(ctc: Contractor | Callable[[Interval], Interval], x: Interval) -> Interval:
    """``ctc(x) & x`` with a box made wholly empty when one component is."""
    c = ctc(x)
    if not isinstance(c, Interval) or c.shape != x.shape:
        raise ValueError(f"a contractor returned {type(c).__name__} "
                         f"{getattr(c, 'shape', '')} for boxes of shape {x.shape}")
    lo, hi = np.maximum(c.lo, x.lo), np.minimum(c.hi, x.hi)
    bad = np.any(np.isnan(lo) | np.isnan(hi) | (lo > hi), axis=1)
    lo[bad] = np.nan
    hi[bad] = np.nan
    return Interval.trusted(lo, hi)


def _classify(x: Interval, test: Test | None, ctc_in: Contractor | None,
              ctc_out: Contractor | None, keep_outside: bool
              ) -> tuple[Interval, Interval, Interval]:
    """One batch: the boxes proven inside, those proven outside (when kept) and the
    undecided ones."""
    none = x[:0]
    if test is not None:
        r = np.asarray(test(x))
        if r.shape != (x.shape[0],) or not np.isin(r, (-1, 0, 1)).all():
            raise ValueError(f"test must return -1, 0 or 1 per box, shape ({x.shape[0]},); "
                             f"got {r.dtype} {r.shape}")
        return x[r == 1], x[r == -1] if keep_outside else none, x[r == 0]
    new_in, new_out = none, none
    if ctc_out is not None:
        c = _contract(ctc_out, x)
        if keep_outside:
            new_out = box_difference(x, c)[0]
        x = c[~np.isnan(c.lo[:, 0])]
    if ctc_in is not None and x.shape[0]:
        c = _contract(ctc_in, x)
        new_in = box_difference(x, c)[0]
        x = c[~np.isnan(c.lo[:, 0])]
    return new_in, new_out, x


def _cat(parts: list[Interval], n: int) -> Interval:
    if not parts:
        return Interval.trusted(np.empty((0, n)), np.empty((0, n)))
    return Interval.trusted(np.concatenate([p.lo for p in parts]),
                         np.concatenate([p.hi for p in parts]))


def sivia(box: Interval, *, test: Test | None = None, ctc_in: Contractor | None = None,
          ctc_out: Contractor | None = None, f: Expr | Sequence[Expr] | None = None,
          y: Interval | None = None, eps: float = 1e-2, max_boxes: int | None = None,
          keep_outside: bool = False, variables: Sequence[str] | None = None,
          batch: int = 16384, executor: Executor | None = None, split: int = 16384,
          tasks: int = 16, progress: bool | None = False) -> Subpaving:
    """Set inversion of ``{x in box : f(x) in y}`` by a subpaving.

    Parameters
    ----------
    box : Interval, shape (n,)
        The bounded initial box.
    test : callable, optional
        Inclusion test ``test(boxes (b, n)) -> int8 (b,)``: 1 inside, -1 outside, 0 undecided.
    ctc_in, ctc_out : Contractor, optional
        Contractors of the complement of the set (``ctc_in``) and of the set (``ctc_out``),
        called on a batch ``(b, n)``; either may be omitted.
    f, y : expression(s) and Interval, optional
        The set ``f(x) in y`` (``y`` of shape ``(m,)`` for ``m`` expressions), inverted with the
        forward-backward contractor pair of ``separators``.
    eps : float
        Undecided boxes whose widest side is below ``eps`` are kept as boundary boxes.
    max_boxes : int, optional
        Stop before the result would exceed this many boxes; the frontier is then boundary.
    keep_outside : bool
        Keep the boxes proven outside in ``Subpaving.outside``.
    variables : list of str, optional
        With ``f``: the variable of each box component (default: order of appearance in ``f``).
    batch : int
        The frontier is classified in chunks of this many boxes (whole batches for the
        contractor or test, small enough to stay in cache).
    executor : concurrent.futures.Executor, optional
        Pave on these workers (``boundest.parallel``): once the frontier holds ``split`` boxes,
        it is cut into ``tasks`` contiguous parts and each worker paves its parts to the end
        with the same batched loop. The parts are disjoint pieces of the frontier, so the
        merged subpaving has neither duplicates nor holes; it holds exactly the boxes of the
        in-process paving (the contractors and tests act box by box), in an order set by
        ``split`` and ``tasks`` only: bit-identical with any number of workers
        (``Subpaving.sorted`` compares it with the in-process one). Not with ``max_boxes``
        (a bound on the whole paving).
    split, tasks : int
        With an executor: the frontier size at which the work is cut, and into how many tasks
        (a few per worker: the parts differ in size; but each part pays the batched loop's
        fixed costs again, so cutting finer costs work: docs/distributed.md).
    progress : bool or None
        With an executor: a progress bar over the tasks (None: only on a terminal).

    Returns
    -------
    Subpaving
        Inside boxes proven in the set; every point of the set in ``box`` lies in an inside or
        boundary box. ``stats`` holds ``iterations``, ``processed`` (boxes classified) and
        ``stopped`` (``"eps"`` or ``"max_boxes"``); with an executor (once the work was cut),
        also ``parallel``: ``tasks``, ``split_at`` (frontier size), ``head_s`` (paving before the
        cut), ``map_s`` (the tasks, wall-clock), ``merge_s`` and ``task_s`` (seconds each task
        spent paving on its worker, ``task_cpu_s`` the CPU seconds).
    """
    if not isinstance(box, Interval) or box.ndim != 1 or box.shape[0] == 0:
        raise ValueError(f"sivia needs a box of shape (n,), got {box!r}")
    if np.any(box.is_empty()):
        raise ValueError(f"sivia needs a non-empty initial box, got {box}")
    if not np.all(np.isfinite(box.lo) & np.isfinite(box.hi)):
        raise ValueError(f"sivia needs a bounded initial box, got {box}")
    if not (np.isfinite(eps) and eps > 0):
        raise ValueError(f"eps must be a positive finite number, got {eps}")
    if batch < 1:
        raise ValueError(f"batch must be at least 1, got {batch}")
    if max_boxes is not None and max_boxes < 1:
        raise ValueError(f"max_boxes must be at least 1, got {max_boxes}")
    modes = [test is not None, ctc_in is not None or ctc_out is not None,
             f is not None or y is not None]
    if sum(modes) != 1:
        raise ValueError("sivia needs exactly one of: test, a contractor pair (ctc_in/ctc_out), "
                         "or f and y")
    n = box.shape[0]
    if modes[2]:
        if f is None or y is None:
            raise ValueError("sivia needs both f and y")
        if np.any(as_interval(y).is_empty()):  # f(x) in an empty set: nothing is in S
            out = Subpaving.empty(n)
            if keep_outside:
                out.outside = box.reshape(1, n).copy()
            out.stats = {"iterations": 0, "processed": 0, "stopped": "eps"}
            return out
        ctc_in, ctc_out = separators(f, y, variables)
        if getattr(ctc_out, "n", n) != n:
            raise ValueError(f"f has {ctc_out.n} variables, the box has dimension {n}")

    frontier = box.reshape(1, n).copy()
    kw = {"test": test, "ctc_in": ctc_in, "ctc_out": ctc_out, "eps": eps,
          "keep_outside": keep_outside, "batch": batch}
    if executor is None:
        run = _pave(frontier, max_boxes=max_boxes, **kw)
        return _subpaving([run], n)
    if max_boxes is not None:
        raise ValueError("max_boxes bounds the whole paving, which workers paving their own "
                         "parts cannot enforce; with an executor, bound the work with eps")
    if split < 1 or tasks < 1:
        raise ValueError(f"split and tasks must be at least 1, got {split} and {tasks}")
    t0 = time.perf_counter()
    head = _pave(frontier, split=max(split, tasks), **kw)
    if head.frontier.shape[0] == 0:  # decided before the frontier grew large: in-process
        return _subpaving([head], n)
    bounds = np.linspace(0, head.frontier.shape[0], tasks + 1).astype(np.intp)
    parts = [head.frontier[a:b] for a, b in pairwise(bounds) if b > a]
    t1 = time.perf_counter()
    work: dict = {}
    runs = map_chunked(_PavePart(kw), parts, executor, chunk=1, progress=progress,
                       desc="sivia", stats=work)
    t2 = time.perf_counter()
    out = _subpaving([head, *runs], n, head.iterations)
    out.stats["parallel"] = {"tasks": len(parts), "split_at": head.frontier.shape[0],
                             "head_s": t1 - t0, "map_s": t2 - t1,
                             "merge_s": time.perf_counter() - t2, "task_s": work["compute_s"],
                             "task_cpu_s": work["cpu_s"]}
    return out


@dataclass
class _Run:
    """What one paving loop produced (its frontier is non-empty when it stopped to split)."""

    inside: list[Interval]
    boundary: list[Interval]
    outside: list[Interval]
    frontier: Interval
    iterations: int
    processed: int
    stopped: str


@dataclass
class _PavePart:
    """The paving of one part of the frontier, run on a worker (picklable: a dataclass)."""

    kw: dict

    def __call__(self, frontier: Interval) -> _Run:
        run = _pave(frontier, **self.kw)
        # one array per kind, in the merge's order, concatenated here on the worker: fewer
        # and larger frames to send, and less to copy in the client
        n = frontier.shape[1]
        run.inside, run.boundary, run.outside = ([_cat(b, n)] for b in
                                                 (run.inside, run.boundary, run.outside))
        return run


def _pave(frontier: Interval, *, test, ctc_in, ctc_out, eps: float, keep_outside: bool,
          batch: int, max_boxes: int | None = None, split: int | None = None) -> _Run:
    """SIVIA's loop from ``frontier``: classify the whole frontier (in chunks of ``batch``),
    keep the decided and the small boxes, bisect the others; stop when nothing is left, before
    exceeding ``max_boxes``, or (``split``) once the frontier holds at least ``split`` boxes."""
    n = frontier.shape[1]
    inside: list[Interval] = []
    boundary: list[Interval] = []
    outside: list[Interval] = []
    done = processed = iterations = 0
    stopped = "eps"
    while frontier.shape[0]:
        if split is not None and frontier.shape[0] >= split:
            return _Run(inside, boundary, outside, frontier, iterations, processed, stopped)
        iterations += 1
        processed += frontier.shape[0]
        bigs = []
        for k in range(0, frontier.shape[0], batch):  # cache-sized chunks of the frontier
            new_in, new_out, und = _classify(frontier[k:k + batch], test, ctc_in, ctc_out,
                                             keep_outside)
            inside.append(new_in)
            outside.append(new_out)
            small = und.max_diam() < eps
            boundary.append(und[small])
            bigs.append(und[~small])
            done += new_in.shape[0] + int(small.sum())
        big = _cat(bigs, n)
        if max_boxes is not None and done + 2 * big.shape[0] > max_boxes:
            boundary.append(big)
            stopped = "max_boxes" if big.shape[0] else stopped
            break
        left, right = big.bisect()
        frontier = Interval.trusted(np.concatenate([left.lo, right.lo]),
                                 np.concatenate([left.hi, right.hi]))
    return _Run(inside, boundary, outside, frontier[:0], iterations, processed, stopped)


def _subpaving(runs: list[_Run], n: int, head_iterations: int = 0) -> Subpaving:
    """The subpaving of the runs, their boxes in the order of the runs (inside, then
    boundary)."""
    ins = _cat([b for r in runs for b in r.inside], n)
    bnd = _cat([b for r in runs for b in r.boundary], n)
    labels = np.zeros(ins.shape[0] + bnd.shape[0], dtype=bool)
    labels[:ins.shape[0]] = True
    out = Subpaving(_cat([ins, bnd], n), labels, _cat([b for r in runs for b in r.outside], n))
    tail = max((r.iterations for r in runs[1:]), default=0)
    stopped = "max_boxes" if any(r.stopped == "max_boxes" for r in runs) else "eps"
    out.stats = {"iterations": (head_iterations + tail) if len(runs) > 1 else runs[0].iterations,
                 "processed": sum(r.processed for r in runs), "stopped": stopped}
    return out
