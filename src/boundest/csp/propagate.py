"""Propagation of a CSP to a fixed point (hull consistency on its primitive decomposition)."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..expr.model import Model
from ..expr.nodes import Constraint
from ..expr.tape import Tape, compile_model
from ..interval import Interval
from .engine import EMPTY, RUNNING, family_flags, propagate_kernel

__all__ = ["Propagation", "propagate", "slot_users"]


@dataclass
class Propagation:
    """Result of ``propagate``.

    Attributes
    ----------
    domains : dict of str -> Interval
        Final domain of every variable (empty intervals when inconsistent).
    consistent : bool
        False when the CSP was *proven* to have no solution.
    evaluations : int
        Number of node revisions (forward image + backward projection of one primitive).
    iterations : float
        ``evaluations / n_nodes``: the work in units of full passes over the tape.
    time_s : float
        Wall time of the propagation (compilation of the model excluded).
    """

    domains: dict[str, Interval]
    consistent: bool
    evaluations: int
    iterations: float
    time_s: float
    n_nodes: int
    n_slots: int
    slots: Interval = field(repr=False)

    def __getitem__(self, name: str) -> Interval:
        return self.domains[name]

    def __repr__(self) -> str:
        """Counts and summary numbers, never every domain (``domains`` holds them)."""
        doms = list(self.domains.values())
        empty = sum(int(np.count_nonzero(d.is_empty())) for d in doms)
        unbounded = sum(int(np.count_nonzero(~d.is_bounded())) for d in doms)
        return (f"Propagation(consistent={self.consistent}, variables={len(doms)}, "
                f"empty={empty}, unbounded={unbounded}, evaluations={self.evaluations}, "
                f"iterations={self.iterations:.3g}, time_s={self.time_s:.3g}, "
                f"n_nodes={self.n_nodes}, n_slots={self.n_slots})")


def slot_users(tape: Tape) -> tuple[np.ndarray, np.ndarray]:
    """CSR lists of the nodes that use each slot (as output or argument)."""
    slots = np.concatenate([tape.out, tape.a, tape.b])
    nodes = np.tile(np.arange(tape.n_nodes, dtype=np.int64), 3)
    keep = slots >= 0
    slots, nodes = slots[keep], nodes[keep]
    order = np.lexsort((nodes, slots))
    slots, nodes = slots[order], nodes[order]
    pair = np.stack([slots, nodes])
    dedup = np.ones(slots.size, dtype=bool)
    dedup[1:] = np.any(pair[:, 1:] != pair[:, :-1], axis=0)
    slots, nodes = slots[dedup], nodes[dedup]
    ptr = np.zeros(tape.n_slots + 1, dtype=np.int64)
    np.add.at(ptr, slots + 1, 1)
    return np.cumsum(ptr), nodes


def propagate(model: Model | list[Constraint] | Tape, *, rel_eps: float = 1e-3,
              max_evaluations: int | None = None, domains: dict[str, Interval] | None = None,
              progress: bool | None = None, chunk: int = 2_000_000, window: int = 64
              ) -> Propagation:
    """Contract all domains of a CSP to a fixed point.

    Stopping rule: a node is revised again only when one of its slots shrank by more than
    ``rel_eps`` times its width (or lost an infinite bound); propagation stops when no such
    node is left (the fixed point at that tolerance), when a domain becomes empty (the CSP is
    proven inconsistent), or after ``max_evaluations`` node revisions.

    Parameters
    ----------
    model : Model, list of Constraint or Tape
    rel_eps : float
        Relative shrink below which a change is not propagated further.
    max_evaluations : int, optional
        Budget of node revisions (default: 10,000 per node).
    domains : dict, optional
        Domains overriding the model's initial ones (by variable name).
    progress : bool, optional
        Show a progress counter of node revisions and dirty nodes (default: only when the run
        lasts more than 2 s).
    chunk : int
        Node revisions per call of the compiled kernel (between progress updates).
    window : int
        Consecutive tape nodes brought to their local fixed point together before a pass moves
        on (see ``engine.propagate_kernel``); 64 nodes is about three time steps of the
        satellite.
    """
    if not 0.0 <= rel_eps < 1.0:
        raise ValueError(f"rel_eps must lie in [0, 1[, got {rel_eps}")
    if window < 1:
        raise ValueError(f"window must be a positive number of nodes, got {window}")
    tape = model if isinstance(model, Tape) else compile_model(model)
    lo, hi = tape.lo.copy(), tape.hi.copy()
    for name, dom in (domains or {}).items():
        if name not in tape.slot_of:
            raise ValueError(f"unknown variable {name!r}")
        s = tape.slot_of[name]
        if bool(dom.is_empty()):
            lo[s] = hi[s] = np.nan
        else:
            lo[s] = max(lo[s], float(dom.lo))
            hi[s] = min(hi[s], float(dom.hi))
    budget = 10_000 * max(tape.n_nodes, 1) if max_evaluations is None else max_evaluations
    ptr, adj = slot_users(tape)
    families = family_flags(tape.op)
    n = tape.n_nodes
    dirty = np.ones(n, dtype=np.bool_)
    state = np.array([0, n, RUNNING, 0, 1], dtype=np.int64)
    # a zero-budget call compiles (first use) or loads the kernel outside the timed part
    propagate_kernel(tape.op, tape.out, tape.a, tape.b, tape.param, lo, hi, ptr, adj, dirty,
                     state.copy(), rel_eps, 0, window, *families)
    t0 = time.perf_counter()
    status = EMPTY if np.isnan(lo).any() or (lo > hi).any() else RUNNING
    bar = None
    while status == RUNNING and state[3] < budget and n > 0:
        status = propagate_kernel(tape.op, tape.out, tape.a, tape.b, tape.param, lo, hi, ptr,
                                  adj, dirty, state, rel_eps, min(chunk, budget - state[3]),
                                  window, *families)
        if bar is None and status == RUNNING and (progress or (
                progress is None and time.perf_counter() - t0 > 2.0)):
            from tqdm import tqdm

            # no total: the budget is a cap, not a forecast of the revisions to the fixed
            # point; the bar counts revisions and shows how many nodes are still dirty
            bar = tqdm(unit="rev", unit_scale=True, desc="propagating", leave=False)
        if bar is not None:
            bar.update(int(state[3]) - bar.n)
            bar.set_postfix(dirty=int(state[1]))
    if bar is not None:
        bar.close()
    elapsed = time.perf_counter() - t0
    consistent = status != EMPTY
    if not consistent:
        lo[:] = np.nan
        hi[:] = np.nan
    doms = {name: Interval._new(lo[s], hi[s]) for name, s in tape.slot_of.items()}
    return Propagation(domains=doms, consistent=consistent, evaluations=int(state[3]),
                       iterations=float(state[3]) / max(n, 1), time_s=elapsed, n_nodes=n,
                       n_slots=tape.n_slots, slots=Interval._new(lo, hi))
