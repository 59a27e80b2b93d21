"""Beta-tuning (Jaulin 2002 section 5.2): the smallest relaxation that keeps a CSP non-empty."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from .propagate import Propagation

__all__ = ["BetaResult", "beta_tuning"]


@dataclass
class BetaResult:
    """``beta``: smallest factor found (within ``tol``) with a non-empty contraction;
    ``propagation``: the contracted CSP at that ``beta``; ``trials``: (beta, consistent) pairs."""

    beta: float
    propagation: Propagation
    trials: list[tuple[float, bool]]
    time_s: float = 0.0


def beta_tuning(contract: Callable[[float], Propagation], beta_max: float = 16.0,
                tol: float = 1e-3, beta_min: float = 0.0) -> BetaResult:
    """Search the smallest ``beta`` for which ``contract(beta)`` is consistent.

    ``contract(beta)`` propagates the CSP whose uncertain domains (perturbations, outputs) are
    scaled by ``beta``. Contraction is monotone in the domains, so consistency is monotone in
    ``beta`` and bisection applies: the answer lies within ``tol`` (relative) above the true
    threshold. Raises ``ValueError`` when even ``beta_max`` gives the empty set.
    """
    if not 0.0 <= beta_min < beta_max:
        raise ValueError(f"need 0 <= beta_min < beta_max, got {beta_min}, {beta_max}")
    trials: list[tuple[float, bool]] = []
    best = contract(beta_max)
    trials.append((beta_max, best.consistent))
    if not best.consistent:
        raise ValueError(f"the CSP is empty even with beta = {beta_max}: raise beta_max")
    lo, hi = beta_min, beta_max
    while hi - lo > tol * hi:
        mid = 0.5 * (lo + hi)
        r = contract(mid)
        trials.append((mid, r.consistent))
        if r.consistent:
            hi, best = mid, r
        else:
            lo = mid
    return BetaResult(hi, best, trials)
