"""Compilation of expressions to a *function* tape: a DAG from variables to outputs.

A constraint tape (:mod:`boundest.expr.tape`) merges the two sides of every equality, so it is
a network of primitive constraints, not a function one can differentiate. A function tape keeps
each output ``f_k(x)`` as its own block of nodes in forward order (shared sub-expressions once
inside a block, never across blocks, so that the derivative of one output touches only its own
nodes: a long chain of local constraints costs the same per constraint however long it is).
Slots ``0 .. n_vars - 1`` are the variables; constants are leaf slots with their value.

A model's constraints become the functions ``g = lhs - rhs`` with a target set: ``[0, 0]`` for
``==``, ``]-inf, 0]`` for ``<=`` (``>=`` is turned around), and ``lhs`` itself with the target
``[lo, hi]`` for ``lhs in [lo, hi]``. A solution of the model is a point of the variables'
domains whose every ``g_k`` lies in its target.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..interval import Interval
from .model import Model
from .nodes import Const, Constraint, Expr, Var, as_expr, variables
from .tape import _Builder

__all__ = ["FunctionTape", "as_function_tape", "constraint_functions", "function_tape"]


@dataclass
class FunctionTape:
    """Outputs ``f_k(x)``, ``k = 0 .. m - 1``, of variables ``x_0 .. x_{n-1}`` as primitive nodes.

    Attributes
    ----------
    names : list of str
        The variables, in slot order (slot ``j`` is ``names[j]``).
    lo, hi : (n_slots,) float64
        Values of the constant slots (the variable and intermediate slots are entire).
    op, out, a, b, param : (n_nodes,) arrays
        Node ``i`` computes ``slot out[i] = OPS[op[i]](slot a[i], slot b[i])`` (as in ``Tape``).
    node_ptr : (m + 1,) int64
        Output ``k`` is computed by nodes ``node_ptr[k] .. node_ptr[k + 1] - 1``.
    out_slot : (m,) int32
        The slot holding output ``k`` (a variable or constant slot when the output is one).
    row_ptr, cols : int64 arrays
        The variables output ``k`` depends on are ``cols[row_ptr[k]:row_ptr[k + 1]]`` (sorted):
        the sparsity pattern of the Jacobian.
    target_lo, target_hi : (m,) float64
        The set each output must lie in (entire for plain functions).
    """

    names: list[str]
    lo: NDArray[np.float64]
    hi: NDArray[np.float64]
    op: NDArray[np.int32]
    out: NDArray[np.int32]
    a: NDArray[np.int32]
    b: NDArray[np.int32]
    param: NDArray[np.float64]
    node_ptr: NDArray[np.int64]
    out_slot: NDArray[np.int32]
    row_ptr: NDArray[np.int64]
    cols: NDArray[np.int64]
    target_lo: NDArray[np.float64]
    target_hi: NDArray[np.float64]

    @property
    def n_vars(self) -> int:
        return len(self.names)

    @property
    def n_outputs(self) -> int:
        return len(self.out_slot)

    @property
    def n_slots(self) -> int:
        return len(self.lo)

    def targets(self) -> Interval:
        """The target set of every output, shape ``(m,)``."""
        return Interval.trusted(self.target_lo.copy(), self.target_hi.copy())


def function_tape(outputs: Sequence[Expr | float], names: Sequence[str | Var] | None = None,
                  targets: Sequence[tuple[float, float]] | None = None) -> FunctionTape:
    """Compile expressions ``f_0 .. f_{m-1}`` of the variables ``names`` to a ``FunctionTape``.

    Parameters
    ----------
    outputs : sequence of Expr
        The functions (a number is a constant function).
    names : sequence of str or Var, optional
        The variables in the order of the Jacobian's columns; by default those of ``outputs``
        in order of first appearance. Every variable of ``outputs`` must be among them.
    targets : sequence of (lo, hi), optional
        The set each output must lie in (entire by default).

    Examples
    --------
    >>> x, y = Var("x"), Var("y")
    >>> t = function_tape([x * y + 1, x - y])
    >>> t.names, t.n_outputs, t.cols.tolist()
    (['x', 'y'], 2, [0, 1, 0, 1])
    """
    exprs = [as_expr(e) for e in outputs]
    if names is None:
        var_names = [v.name for v in variables(exprs)]
    else:
        var_names = [v.name if isinstance(v, Var) else str(v) for v in names]
        if len(set(var_names)) != len(var_names):
            raise ValueError(f"a variable is listed twice in {var_names}")
        known = set(var_names)
        missing = [v.name for v in variables(exprs) if v.name not in known]
        if missing:
            raise ValueError(f"the outputs use variables not among the given names: {missing}")
    if targets is None:
        tl = np.full(len(exprs), -np.inf)
        th = np.full(len(exprs), np.inf)
    else:
        tg = np.asarray(targets, dtype=np.float64).reshape(-1, 2)
        if len(tg) != len(exprs):
            raise ValueError(f"{len(tg)} targets for {len(exprs)} outputs")
        tl, th = tg[:, 0].copy(), tg[:, 1].copy()
    bld = _Builder()
    for name in var_names:
        bld.var(name)
    n = len(var_names)
    node_ptr, out_slot, row_ptr, cols = [0], [], [0], []
    for e in exprs:
        bld.node_of.clear()  # no node shared across outputs: each output's block is its own
        bld.memo.clear()
        start = len(bld.nodes)
        out_slot.append(bld.expr(e))
        node_ptr.append(len(bld.nodes))
        deps = {s for _, _, sa, sb, _ in bld.nodes[start:] for s in (sa, sb) if 0 <= s < n}
        if out_slot[-1] < n:
            deps.add(out_slot[-1])
        cols += sorted(deps)
        row_ptr.append(len(cols))
    nodes = np.array(bld.nodes, dtype=np.float64).reshape(-1, 5)
    return FunctionTape(
        names=var_names, lo=np.array(bld.lo, dtype=np.float64),
        hi=np.array(bld.hi, dtype=np.float64), op=nodes[:, 0].astype(np.int32),
        out=nodes[:, 1].astype(np.int32), a=nodes[:, 2].astype(np.int32),
        b=nodes[:, 3].astype(np.int32), param=nodes[:, 4].copy(),
        node_ptr=np.array(node_ptr, dtype=np.int64), out_slot=np.array(out_slot, dtype=np.int32),
        row_ptr=np.array(row_ptr, dtype=np.int64), cols=np.array(cols, dtype=np.int64),
        target_lo=tl, target_hi=th)


def _as_function(c: Constraint) -> tuple[Expr, float, float]:
    """``(g, lo, hi)`` with ``c`` equivalent to ``g in [lo, hi]``."""
    if c.rel == "in":
        assert isinstance(c.rhs, Const)
        return c.lhs, float(c.rhs.value.lo), float(c.rhs.value.hi)
    lhs, rhs = (c.rhs, c.lhs) if c.rel == ">=" else (c.lhs, c.rhs)
    if isinstance(rhs, Const) and rhs.value.lo == rhs.value.hi and rhs.value.lo == 0:
        g = lhs
    else:
        g = lhs - rhs
    return g, (0.0 if c.rel == "==" else -np.inf), 0.0


def constraint_functions(model: Model | Sequence[Constraint]) -> tuple[FunctionTape, Interval]:
    """The constraints of a model as a ``FunctionTape`` with targets, and the variables' domains.

    Returns the tape (outputs ``g_k``, targets as in the module docstring, columns the model's
    variables in ``Model.variable_names`` order) and the box of the declared domains (entire
    for undeclared variables), shape ``(n,)``.
    """
    if not isinstance(model, Model):
        model = Model(constraints=list(model))
    names = model.variable_names()
    parts = [_as_function(c) for c in model.constraints]
    tape = function_tape([g for g, _, _ in parts], names, [(lo, hi) for _, lo, hi in parts])
    lo = np.array([float(model.domains[v].lo) if v in model.domains else -np.inf for v in names])
    hi = np.array([float(model.domains[v].hi) if v in model.domains else np.inf for v in names])
    return tape, Interval(lo, hi)


def as_function_tape(system: FunctionTape | Model | Expr | Sequence,
                     names: Sequence[str | Var] | None = None) -> FunctionTape:
    """A ``FunctionTape`` from what a user has at hand: a tape (returned as it is), a model or
    a list of constraints (``constraint_functions``: ``g = lhs - rhs`` with their targets, the
    model's variables), or an expression or a list of expressions (``function_tape``, columns
    ``names`` or the variables in order of first appearance)."""
    if isinstance(system, FunctionTape):
        return system
    if isinstance(system, Model):
        return constraint_functions(system)[0]
    if isinstance(system, Constraint):
        return constraint_functions([system])[0]
    if isinstance(system, (Expr, int, float)):
        return function_tape([system], names)
    items = list(system)
    if items and all(isinstance(c, Constraint) for c in items):
        return constraint_functions(items)[0]
    if any(isinstance(c, Constraint) for c in items):
        raise TypeError("mix of constraints and expressions: pass either constraints (a model) "
                        "or expressions (functions)")
    return function_tape(items, names)
