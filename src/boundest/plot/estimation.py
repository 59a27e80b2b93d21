"""Set estimates of a state over time: one panel per time step (Jaulin et al. 2001 Fig. 7)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from ..interval import Interval
from ..paving import Subpaving
from .boxes import plot_boxes
from .paving import plot_paving

__all__ = ["plot_set_sequence"]


def _draw(d: Interval | Subpaving, ax: Any, frame: Interval) -> None:
    if isinstance(d, Subpaving):
        plot_paving(d, ax=ax)
    elif not bool(d.is_empty().any()):  # a box domain (possibly unbounded): clip to the frame
        c = d & frame
        plot_boxes(c[0:1], c[1:2], ax=ax, facecolor="yellow", edgecolor="black", alpha=1.0,
                   linewidth=0.2)


def plot_set_sequence(rows: Sequence[Sequence[Interval | Subpaving]],
                      labels: Sequence[str], frame: Interval, *, truth: Any = None,
                      panel: float = 1.6) -> Any:
    """A grid of panels: one row per estimator (``rows[r][k]``: domain of ``x_k``, a 2-D box or
    subpaving), one column per time step, every panel framed to ``frame`` (shape ``(2,)``).

    ``truth`` (optional, ``(K + 1, 2)``) marks the true state in each panel. Returns the figure.
    """
    import matplotlib.pyplot as plt

    ncol = max(len(r) for r in rows)
    fig, axes = plt.subplots(len(rows), ncol, figsize=(panel * ncol, panel * len(rows) + 0.4),
                             squeeze=False)
    for r, (row, label) in enumerate(zip(rows, labels, strict=True)):
        for k in range(ncol):
            ax = axes[r][k]
            if k < len(row):
                _draw(row[k], ax, frame)
            if truth is not None and k < len(truth):
                ax.plot(truth[k][0], truth[k][1], "+", color="tab:blue", ms=6)
            ax.set_xlim(float(frame.lo[0]), float(frame.hi[0]))
            ax.set_ylim(float(frame.lo[1]), float(frame.hi[1]))
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            if r == 0:
                ax.set_title(f"k = {k}", fontsize=9)
            if k == 0:
                ax.set_ylabel(label, fontsize=9)
    fig.tight_layout()
    return fig
