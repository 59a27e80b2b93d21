"""The figure of a Monte Carlo check of a set estimator: per step, the empirical frequency with
which the set contains the truth, its confidence band, and the probability the estimator
claims."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .boxes import _axes

if TYPE_CHECKING:
    from ..scenarios.pool_mc import MonteCarloResult


def plot_containment(mc: MonteCarloResult, ax: Any = None) -> Any:
    """Frequency of ``x_k in X_k`` against time with its 95 % Wilson band, and the claimed
    ``P(at most q outliers in the window)``; every curve is in the legend. Returns the axes."""
    ax = _axes(ax)
    lo, hi = mc.ci()
    ax.fill_between(mc.t, lo, hi, step="mid", color="#9ecae1", alpha=0.8,
                    label=f"95 % Wilson interval ({mc.missions} missions)")
    ax.step(mc.t, mc.frequency(), where="mid", color="#08519c", lw=1.2,
            label="empirical frequency of x_k in X_k")
    ax.plot(mc.t, mc.window_probability, color="#d62728", lw=1.4, ls="--",
            label=f"claimed P(at most {mc.q} outliers in the window of {mc.m})")
    ax.plot(mc.t, mc.windows_ok / mc.missions, color="0.45", lw=1.0, ls=":",
            label="frequency of: every window so far held at most q outliers")
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("probability / frequency")
    ax.legend(loc="lower left", fontsize=8)
    return ax
