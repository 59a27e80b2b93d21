"""Hull consistency alternated with LP contraction of the linear / log-linear sub-networks.

Jaulin 2002 (section 5.1): contract the linear sub-networks of the CSP (and, through
logarithms, its positive multiplicative constraints) by a linear solver and propagate the
result back to the CSP. ``propagate_lp`` runs ``propagate`` (hull consistency to its fixed
point), then ``boundest.ctc.linear.contract_slots`` on the box it reached, and repeats while the
LP narrows the targets by more than ``min_gain``. Needs SciPy (``pip install 'boundest[lp]'``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from ..ctc.linear import CtcLinear, contract_slots
from ..expr.model import Model
from ..expr.nodes import Constraint, Var, VarFamily
from ..expr.tape import Tape, compile_model
from ..interval import Interval
from .propagate import Propagation, propagate

__all__ = ["LPPropagation", "propagate_lp"]


@dataclass
class LPPropagation:
    """Result of ``propagate_lp``: the last hull-consistency ``propagation`` (its domains are
    the final ones) and the cost of each part.

    Attributes
    ----------
    propagation : Propagation
    consistent : bool
        False when hull consistency or an LP (Farkas certificate) proved the CSP empty.
    rounds : int
        LP contractions run (each followed by a hull-consistency propagation).
    lp_time_s, hc_time_s : float
        Wall time in the LPs (extraction, solves, rigorous bounds) and in propagation.
    widths : list of float
        Total width of the targets after each propagation (the first: hull consistency
        alone).
    """

    propagation: Propagation
    consistent: bool
    rounds: int
    lp_time_s: float
    hc_time_s: float
    widths: list[float]

    @property
    def domains(self) -> dict[str, Interval]:
        return self.propagation.domains

    @property
    def slots(self) -> Interval:
        return self.propagation.slots

    @property
    def time_s(self) -> float:
        return self.lp_time_s + self.hc_time_s

    def __getitem__(self, key: str | Var | VarFamily) -> Interval:
        """The final domain of a variable or family (``Propagation.__getitem__``)."""
        return self.propagation[key]

    def bounds(self, key: str | Var | VarFamily) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bounds as arrays (``Propagation.bounds``)."""
        return self.propagation.bounds(key)


def propagate_lp(model: Model | list[Constraint] | Tape, *, targets: list[str] | None = None,
                 rounds: int = 3, min_gain: float = 0.01, radius: int | None = None,
                 log_linear: bool = True, relax: bool = False, **kwargs) -> LPPropagation:
    """Hull consistency, then LP contraction and hull consistency again, up to ``rounds``
    times.

    Parameters
    ----------
    model : Model, list of Constraint or Tape
    targets : list of str, optional
        Variables whose domains the LPs contract (default: every named variable). Each costs
        two LPs (four where it is sign-definite and in a log-linear row).
    rounds : int
        Most LP contractions.
    min_gain : float
        Stop when a round narrows the targets' total width by less than this fraction.
    radius : int, optional
        Each target's LPs use the rows within this many row-steps of it (see
        ``CtcLinear``); default: the whole connected sub-network.
    log_linear : bool
        Use the log-linear rows of multiplicative constraints (Jaulin 2002 eq. 19).
    relax : bool
        Also use a linear relaxation of the nonlinear nodes around the box of each round
        (``ctc.relax.relaxation``).
    **kwargs
        Passed to ``propagate`` (``rel_eps``, ``max_evaluations``, ``window``, ...); its
        ``mode`` is ``"hc4"`` unless given.
    """
    kwargs.setdefault("mode", "hc4")
    tape = model if isinstance(model, Tape) else compile_model(model)
    CtcLinear(tape)  # checks that SciPy is there before any work
    names = list(tape.slot_of) if targets is None else targets
    unknown = [n for n in names if n not in tape.slot_of]
    if unknown:
        raise ValueError(f"unknown variable {unknown[0]!r}")
    slots = np.unique(np.array([tape.slot_of[n] for n in names], dtype=np.int64))
    t0 = time.perf_counter()
    prop = propagate(tape, **kwargs)
    hc, lp = time.perf_counter() - t0, 0.0
    widths = [_width(prop, slots)]
    done = 0
    while prop.consistent and done < rounds:
        t0 = time.perf_counter()
        lo, hi, ok = contract_slots(tape, prop.slots.lo, prop.slots.hi, slots, log_linear,
                                    radius, relax)
        lp += time.perf_counter() - t0
        done += 1
        if not ok:
            lo = np.full(tape.n_slots, np.nan)
            hi = lo.copy()
        t0 = time.perf_counter()
        prop = propagate(replace(tape, lo=lo, hi=hi), **kwargs)
        hc += time.perf_counter() - t0
        widths.append(_width(prop, slots))
        if not prop.consistent or widths[-1] > (1.0 - min_gain) * widths[-2]:
            break
    return LPPropagation(prop, prop.consistent, done, lp, hc, widths)


def _width(prop: Propagation, slots: np.ndarray) -> float:
    if not prop.consistent:
        return 0.0
    return float(np.sum(prop.slots.hi[slots] - prop.slots.lo[slots]))
