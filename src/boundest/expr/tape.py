"""Compilation of constraints to a tape of primitive operations.

Every distinct sub-expression becomes one *slot* (hash-consing, so shared sub-expressions are
computed once, also across constraints) and one *node* ``out = op(a, b)``. An equality
``lhs == rhs`` merges the two sides' slots (union-find), and merging may make two nodes
identical, which are then merged too (congruence closure). Inequalities and ``in`` constraints
become initial domains of slots. The result is the classic decomposition of a CSP into
primitive constraints (Jaulin 2002 section 5, Jaulin, Bertholom, Dabe 2007 section 6.4).

A slot is one real value, so only constants known to be one number share a slot: degenerate
constants by their float, decimal literals by their exact value (``Const.exact``). Every
occurrence of any other (non-degenerate) interval constant is a fresh slot, and a
sub-expression containing one is never shared by identity: each occurrence is an independent
value of the interval, as in forward evaluation. Congruence closure then stays sound, since two
nodes merge only when their argument slots are equal.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..interval import Interval
from .model import Model
from .nodes import BINARY, UNARY, Const, Constraint, Expr, Op, Var

__all__ = ["OPS", "Tape", "compile_model", "instantiate"]

#: Op codes: the index of a primitive's name in this tuple.
OPS: tuple[str, ...] = UNARY + BINARY
_CODE = {name: i for i, name in enumerate(OPS)}


@dataclass
class Tape:
    """A CSP decomposed into primitive constraints over slots.

    Attributes
    ----------
    lo, hi : (n_slots,) float64
        Initial domains of the slots (variables first, then constants and intermediates).
    slot_of : dict
        Variable name -> slot (two variables merged by an equality share a slot).
    op, out, a, b : (n_nodes,) int32
        Node ``i`` is the primitive constraint ``slot out[i] = OPS[op[i]](slot a[i], slot b[i])``
        (``b[i] = -1`` for unary ops). Nodes are in an order where, before merging, every
        input was produced earlier (forward order).
    param : (n_nodes,) float64
        Integer exponent of ``pown`` nodes (0 elsewhere).
    model : Model, optional
        The model the tape was compiled from (``compile_model`` keeps it: the centered-form
        modes of ``propagate`` differentiate its constraints).
    """

    lo: NDArray[np.float64]
    hi: NDArray[np.float64]
    slot_of: dict[str, int]
    op: NDArray[np.int32]
    out: NDArray[np.int32]
    a: NDArray[np.int32]
    b: NDArray[np.int32]
    param: NDArray[np.float64]
    model: Model | None = field(default=None, repr=False, compare=False)

    @property
    def n_slots(self) -> int:
        return len(self.lo)

    @property
    def n_nodes(self) -> int:
        return len(self.op)

    def domains(self) -> Interval:
        """The initial domains of all slots."""
        return Interval.trusted(self.lo.copy(), self.hi.copy())

    def describe(self) -> str:
        names = {s: n for n, s in self.slot_of.items()}
        lines = []
        for i in range(self.n_nodes):
            args = [names.get(int(s), f"t{int(s)}") for s in (self.a[i], self.b[i]) if s >= 0]
            p = f", {int(self.param[i])}" if OPS[self.op[i]] == "pown" else ""
            out = names.get(int(self.out[i]), f"t{int(self.out[i])}")
            lines.append(f"{out} = {OPS[self.op[i]]}({', '.join(args)}{p})")
        return "\n".join(lines)


class _Builder:
    def __init__(self) -> None:
        self.lo: list[float] = []
        self.hi: list[float] = []
        self.slot_of: dict[str, int] = {}
        self.const_slot: dict[tuple, int] = {}  # constants that are one number
        self.node_of: dict[tuple, int] = {}
        self.nodes: list[tuple[int, int, int, int, float]] = []  # (op, out, a, b, param)
        # id(expr) -> slot, for trees reused by identity (only those that are one value)
        self.memo: dict[int, int] = {}
        self.keep: list[Expr] = []  # keep memoised expressions alive (ids stay unique)

    def new_slot(self, lo: float = -np.inf, hi: float = np.inf) -> int:
        self.lo.append(lo)
        self.hi.append(hi)
        return len(self.lo) - 1

    def var(self, name: str) -> int:
        s = self.slot_of.get(name)
        if s is None:
            s = self.slot_of[name] = self.new_slot()
        return s

    def expr(self, e: Expr) -> int:
        """The slot of ``e`` (a fresh one where ``e`` holds a non-degenerate constant)."""
        return self._expr(e)[0]

    def _expr(self, root: Expr) -> tuple[int, bool]:
        """``(slot, shared)``; ``shared`` is False when ``root`` contains an occurrence of a
        non-degenerate constant, whose slot must not serve another occurrence of ``root``.

        A post-order walk with an explicit stack (a tree of any depth): the arguments of an
        operation in order, then the operation, as a recursion would visit them.
        """
        done: list[tuple[int, bool]] = []  # the results of the walk, arguments before ops
        stack: list[tuple[Expr, bool]] = [(root, False)]
        while stack:
            e, expanded = stack.pop()
            if not expanded:
                s = self.memo.get(id(e))
                if s is not None:
                    done.append((s, True))
                    continue
                if isinstance(e, Op):
                    stack.append((e, True))
                    stack.extend((x, False) for x in reversed(e.args))
                    continue
            shared = True
            if isinstance(e, Var):
                s = self.var(e.name)
            elif isinstance(e, Const):
                lo, hi = float(e.value.lo), float(e.value.hi)
                key: tuple | None = ("point", lo) if lo == hi else (
                    None if e.exact is None else ("exact", e.exact))
                if key is None:
                    s, shared = self.new_slot(lo, hi), False
                else:
                    s = self.const_slot.get(key)
                    if s is None:
                        s = self.const_slot[key] = self.new_slot(lo, hi)
                    else:  # the same number: both enclosures contain it
                        self.restrict(s, lo, hi)
            elif isinstance(e, Op):
                k = len(e.args)
                args = done[-k:]
                del done[-k:]
                shared = all(sh for _, sh in args)
                a, b = args[0][0], (args[1][0] if k == 2 else -1)
                param = float(e.param) if e.param is not None else 0.0
                key = (_CODE[e.name], a, b, param)
                node = self.node_of.get(key)  # a fresh argument slot makes the key unique
                if node is None:
                    s = self.new_slot()
                    self.node_of[key] = len(self.nodes)
                    self.nodes.append((key[0], s, a, b, param))
                else:
                    s = self.nodes[node][1]
            else:
                raise TypeError(f"not an expression: {e!r}")
            if shared:
                self.memo[id(e)] = s
                self.keep.append(e)
            done.append((s, shared))
        return done[0]

    def restrict(self, s: int, lo: float, hi: float) -> None:
        if lo != lo or hi != hi:  # an empty domain (NaN bounds): Python's max would drop it
            self.lo[s] = self.hi[s] = np.nan
            return
        self.lo[s] = max(self.lo[s], lo)
        self.hi[s] = min(self.hi[s], hi)


def _find(parent: list[int], s: int) -> int:
    while parent[s] != s:
        parent[s] = parent[parent[s]]
        s = parent[s]
    return s


def compile_model(model: Model | list[Constraint], domains: dict[str, Interval] | None = None
                  ) -> Tape:
    """Decompose a model (or a list of constraints) into a ``Tape``."""
    if not isinstance(model, Model):
        model = Model(domains=dict(domains or {}), constraints=list(model))
    bld = _Builder()
    for name in model.variable_names():
        bld.var(name)
    for name, dom in model.domains.items():
        bld.restrict(bld.slot_of[name], float(dom.lo), float(dom.hi))
    merges: list[tuple[int, int]] = []
    for c in model.constraints:
        if c.rel == "in":
            assert isinstance(c.rhs, Const)
            bld.restrict(bld.expr(c.lhs), float(c.rhs.value.lo), float(c.rhs.value.hi))
        elif c.rel == "==":
            merges.append((bld.expr(c.lhs), bld.expr(c.rhs)))
        else:
            lhs, rhs = (c.lhs, c.rhs) if c.rel == "<=" else (c.rhs, c.lhs)  # lhs <= rhs
            if isinstance(rhs, Const):
                bld.restrict(bld.expr(lhs), -np.inf, float(rhs.value.hi))
            elif isinstance(lhs, Const):
                bld.restrict(bld.expr(rhs), float(lhs.value.lo), np.inf)
            else:
                bld.restrict(bld.expr(lhs - rhs), -np.inf, 0.0)
    tape = _close(bld, merges)
    tape.model = model
    return tape


def _close(bld: _Builder, merges: list[tuple[int, int]]) -> Tape:
    """Apply the equalities (union-find) and merge nodes that became identical."""
    n = len(bld.lo)
    parent = list(range(n))
    # prefer variables, then lower slot numbers, as representatives
    for s1, s2 in merges:
        r1, r2 = _find(parent, s1), _find(parent, s2)
        if r1 != r2:
            parent[max(r1, r2)] = min(r1, r2)
    nodes = bld.nodes
    while True:
        seen: dict[tuple, int] = {}
        changed = False
        for op, out, a, b, p in nodes:
            key = (op, _find(parent, a), _find(parent, b) if b >= 0 else -1, p)
            o = _find(parent, out)
            prev = seen.setdefault(key, o)
            if prev != o:
                parent[max(prev, o)] = min(prev, o)
                seen[key] = min(prev, o)
                changed = True
        if not changed:
            break
    roots = sorted({_find(parent, s) for s in range(n)})
    new_id = {r: i for i, r in enumerate(roots)}
    lo = np.full(len(roots), -np.inf)
    hi = np.full(len(roots), np.inf)
    for s in range(n):
        r = new_id[_find(parent, s)]
        lo[r] = np.fmax(lo[r], bld.lo[s]) if lo[r] == lo[r] else lo[r]
        hi[r] = np.fmin(hi[r], bld.hi[s]) if hi[r] == hi[r] else hi[r]
        if bld.lo[s] != bld.lo[s]:  # an empty slot empties its merged class
            lo[r] = hi[r] = np.nan
    empty = lo > hi
    lo[empty] = hi[empty] = np.nan
    uniq: dict[tuple, None] = {}
    for op, out, a, b, p in nodes:
        key = (op, new_id[_find(parent, out)], new_id[_find(parent, a)],
               new_id[_find(parent, b)] if b >= 0 else -1, p)
        uniq.setdefault(key, None)
    arr = np.array(list(uniq), dtype=np.float64).reshape(-1, 5)
    slot_of = {name: new_id[_find(parent, s)] for name, s in bld.slot_of.items()}
    return Tape(lo=lo, hi=hi, slot_of=slot_of, op=arr[:, 0].astype(np.int32),
                out=arr[:, 1].astype(np.int32), a=arr[:, 2].astype(np.int32),
                b=arr[:, 3].astype(np.int32), param=arr[:, 4].copy())


def instantiate(names: list[str], lo: NDArray[np.float64], hi: NDArray[np.float64],
                pieces: list[tuple[Tape, dict[str, NDArray[np.intp]]]]) -> Tape:
    """One tape from templates repeated over many index tuples, without compiling each copy.

    A CSP that repeats the same constraints (a time step of a dynamical model, one
    measurement) is compiled once as a small template tape; this function lays out ``m``
    copies of each template with NumPy, the template's variables placed on global variables
    and every other slot of the template (constants, intermediates) fresh in each copy, so each
    copy is exactly what ``compile_model`` makes of that copy alone (an interval constant stays
    one independent value per occurrence).

    Parameters
    ----------
    names : list of str
        The global variables (slots ``0 .. len(names) - 1`` of the result).
    lo, hi : array, shape (len(names),)
        Their initial domains (intersected with the domains the templates give them).
    pieces : list of (Tape, dict)
        Each template with its placement: template variable name -> int array ``(m,)`` of the
        global variable that copy ``i`` puts there (one ``m`` per template). The nodes of copy
        ``i`` follow those of copy ``i - 1``.

    Examples
    --------
    >>> from boundest.expr import Var
    >>> step = compile_model([Var("y") == 0.5 * Var("x")])
    >>> t = instantiate(["x0", "x1", "x2"], np.array([4.0, -np.inf, -np.inf]),
    ...                 np.array([4.0, np.inf, np.inf]),
    ...                 [(step, {"x": np.array([0, 1]), "y": np.array([1, 2])})])
    >>> t.n_nodes, t.slot_of["x2"]
    (2, 2)
    """
    n = len(names)
    lo, hi = np.array(lo, dtype=np.float64), np.array(hi, dtype=np.float64)
    if lo.shape != (n,) or hi.shape != (n,):
        raise ValueError(f"lo and hi must have shape ({n},), got {lo.shape} and {hi.shape}")
    slot_lo, slot_hi = [lo], [hi]
    ops, outs, as_, bs, params = [], [], [], [], []
    nxt = n
    for tape, place in pieces:
        var_slots = {tape.slot_of[v] for v in tape.slot_of}
        if set(place) != set(tape.slot_of):
            raise ValueError(f"placement names {sorted(place)} differ from the template's "
                             f"variables {sorted(tape.slot_of)}")
        if len(var_slots) != len(tape.slot_of):
            raise ValueError("a template must not merge two of its variables into one slot")
        sizes = {np.asarray(p).shape for p in place.values()}
        if len(sizes) != 1 or len(next(iter(sizes))) != 1:
            raise ValueError(f"placements must be 1-D arrays of one length, got shapes {sizes}")
        m = next(iter(sizes))[0]
        private = np.array([s for s in range(tape.n_slots) if s not in var_slots], dtype=np.intp)
        where = np.empty((m, tape.n_slots), dtype=np.int64)
        for v, s in tape.slot_of.items():
            g = np.asarray(place[v], dtype=np.int64)
            if g.size and (g.min() < 0 or g.max() >= n):
                raise ValueError(f"placement of {v!r} outside the {n} global variables")
            where[:, s] = g
            np.maximum.at(lo, g, tape.lo[s])  # the template's domain of the variable
            np.minimum.at(hi, g, tape.hi[s])
        q = private.size
        where[:, private] = nxt + np.arange(m * q, dtype=np.int64).reshape(m, q)
        nxt += m * q
        slot_lo.append(np.tile(tape.lo[private], m))
        slot_hi.append(np.tile(tape.hi[private], m))
        ops.append(np.tile(tape.op, m))
        outs.append(where[:, tape.out].ravel())
        as_.append(where[:, tape.a].ravel())
        bs.append(np.where(tape.b >= 0, where[:, np.maximum(tape.b, 0)], -1).ravel())
        params.append(np.tile(tape.param, m))
    all_lo, all_hi = np.concatenate(slot_lo), np.concatenate(slot_hi)
    if nxt >= 2**31:
        raise ValueError(f"{nxt} slots exceed the tape's int32 slot numbers")
    empty = np.isnan(all_lo) | np.isnan(all_hi) | (all_lo > all_hi)
    all_lo[empty] = all_hi[empty] = np.nan
    return Tape(lo=all_lo, hi=all_hi, slot_of={v: i for i, v in enumerate(names)},
                op=np.concatenate(ops).astype(np.int32), out=np.concatenate(outs).astype(np.int32),
                a=np.concatenate(as_).astype(np.int32), b=np.concatenate(bs).astype(np.int32),
                param=np.concatenate(params))
