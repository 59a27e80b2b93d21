"""Set estimates of a state over time, one zoomed panel per time step (Jaulin et al. 2001
Fig. 7)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..interval import Interval
from ..paving import Subpaving
from .boxes import plot_boxes
from .paving import plot_paving

__all__ = ["SET_STYLES", "plot_set_sequence"]

#: (inside, boundary, edge) colours: the first estimator pale (underneath), the last strong
#: (on top), a middle one blue
SET_STYLES = (("#f4a9a8", "#fdf0b0", "#b0b0b0", "\\\\\\"),
              ("#c0392b", "#f1c40f", "black", "///"), ("#1f77b4", "#aec7e8", "black", "|||"))


def _is_empty(d: Interval | Subpaving) -> bool:
    return d.is_empty() if isinstance(d, Subpaving) else bool(d.is_empty().any())


def _hull(d: Interval | Subpaving, frame: Interval) -> Interval | None:
    """The hull of a 2-D domain clipped to ``frame`` (None when empty)."""
    if isinstance(d, Subpaving):
        if d.is_empty():
            return None
        h = d.hull()
    else:
        if bool(d.is_empty().any()):
            return None
        h = d
    c = h & frame
    return None if bool(c.is_empty().any()) else c


def _draw(d: Interval | Subpaving, ax: Any, frame: Interval,
          style: tuple[str, str, str, str], name: str, points: float = np.inf) -> None:
    """Draw ``d`` in ``style``; ``points``: the size of one unit of the view, in points."""
    inside, boundary, edge, hatch = style
    if isinstance(d, Subpaving):
        if not d.is_empty():
            # boxes narrower than 2 points would show their edges only: black lines the legend
            # does not explain; edges in the boxes' own colours keep them in the legend's
            side = float(np.median(np.max(d.boxes.width()[:, :2], axis=1)))
            if side * points < 2.0:
                edge = "face"
        plot_paving(d, ax=ax, inside=inside, boundary=boundary, edgecolor=edge, linewidth=0.3,
                    labels=(f"{name}: inside (proven in the set)",
                            f"{name}: boundary (undecided at eps)", None))
    elif not bool(d.is_empty().any()):  # a box domain (possibly unbounded): clip to the frame
        c = d & frame
        plot_boxes(c[0:1], c[1:2], ax=ax, facecolor="none", edgecolor=inside, alpha=1.0,
                   linewidth=1.5, hatch=hatch, label=f"{name}: box domain (encloses the set)")


def _outside_view(d: Interval | Subpaving, view: Interval) -> int:
    """How many boxes of ``d`` do not meet ``view``."""
    if not isinstance(d, Subpaving) or d.is_empty():
        return 0
    b = d.boxes
    meet = np.all((b.lo <= view.hi) & (b.hi >= view.lo), axis=1)
    return int(np.count_nonzero(~meet))


def plot_set_sequence(rows: Sequence[Sequence[Interval | Subpaving]],
                      labels: Sequence[str], frame: Interval, *, truth: Any = None,
                      ncols: int = 4, panel: float = 2.7,
                      axis_names: tuple[str, str] = ("x1", "x2"),
                      unit: str = "dimensionless") -> Any:
    """The sets of several estimators over time: one overview and one zoom per time step.

    Parameters
    ----------
    rows : sequence of sequences of Interval or Subpaving
        ``rows[r][k]``: the domain of ``x_k`` found by estimator ``r`` (a 2-D box or
        subpaving). Estimators are drawn on top of each other in the order given, the first in
        pale colours, the last in strong ones: give the widest (e.g. causal) first.
    labels : sequence of str
        The name of each estimator, for the legend.
    frame : Interval, shape (2,)
        The region of interest: unbounded boxes are clipped to it, and it is the view of the
        overview and of any step whose set fills it.
    truth : array (K + 1, 2), optional
        The true state at each step, marked with a cross.
    ncols : int
        Panels per row of the figure.
    panel : float
        The side of one panel, in inches.
    axis_names : (str, str)
        The names of the two state components.
    unit : str
        Their unit, written in the axis labels.

    Returns
    -------
    matplotlib.figure.Figure
        The first panel shows every step ``k >= 1`` of the last estimator in the frame, in a
        colour scale of ``k``. Each following panel is framed on the last estimator's set at
        step ``k`` (a square view around its hull, with ticks; the frame, said in the panel's
        title, where that hull spans it), where both estimators are drawn with their inside
        boxes (proven in the set) and boundary boxes (undecided at the precision eps) in the
        colours of the legend (boxes too small for their edges drawn in their own colour);
        boxes of an earlier estimator lying outside that view are counted in the panel.
    """
    import matplotlib as mpl
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    if len(rows) != len(labels) or not rows:
        raise ValueError("plot_set_sequence: give one label per estimator")
    n_k = max(len(r) for r in rows)
    nrows = -(-(n_k + 1) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(panel * ncols, panel * nrows + 0.9),
                             squeeze=False, layout="constrained")
    axes = axes.ravel()
    for ax in axes[n_k + 1:]:
        ax.set_visible(False)
    last = rows[-1]
    fl, fh = frame.lo.astype(float), frame.hi.astype(float)

    # overview: every k >= 1 of the last estimator, coloured by k, thick edges so specks show
    ax = axes[0]
    cmap = mpl.colormaps["viridis"]
    norm = mpl.colors.Normalize(vmin=1, vmax=max(n_k - 1, 2))
    for k in range(1, len(last)):
        d = last[k]
        colour = cmap(norm(k))
        if isinstance(d, Subpaving):
            if not d.is_empty():
                plot_boxes(d.boxes[:, 0], d.boxes[:, 1], ax=ax, facecolor=colour,
                           edgecolor=colour, alpha=1.0, linewidth=2.5)
        elif not bool(d.is_empty().any()):
            c = d & frame
            plot_boxes(c[0:1], c[1:2], ax=ax, facecolor="none", edgecolor=colour, alpha=1.0,
                       linewidth=1.5)
    ax.set_xlim(fl[0], fh[0])
    ax.set_ylim(fl[1], fh[1])
    ax.set_aspect("equal")
    ax.set_title(f"{labels[-1]}, all k >= 1", fontsize=9)
    cb = fig.colorbar(mpl.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, shrink=0.8)
    cb.set_label("k (time step)", fontsize=8)
    cb.ax.tick_params(labelsize=7)
    ax.tick_params(labelsize=7)

    span = float(np.max(fh - fl))
    for k in range(n_k):
        ax = axes[k + 1]
        h = _hull(last[k], frame) if k < len(last) else None
        if h is None:
            view = frame
        else:
            mid = (h.lo + h.hi) / 2
            half = max(float(np.max(h.hi - h.lo)) / 2 * 1.3, 0.02 * span)
            view = Interval.trusted(np.maximum(mid - half, fl), np.minimum(mid + half, fh))
        points = panel * 72 / float(np.max(view.hi - view.lo))
        for r, row in enumerate(rows):
            style = SET_STYLES[1 if r == len(rows) - 1 else (0 if r == 0 else 2)]
            if k < len(row):
                _draw(row[k], ax, frame, style, labels[r], points)
        if truth is not None and k < len(truth):
            ax.plot(truth[k][0], truth[k][1], "x", color="tab:blue", ms=8, mew=2,
                    label="true state")
        short = [lb.split(" ")[-1].strip("()") for lb in labels]
        hidden = [(short[r], _outside_view(row[k], view))
                  for r, row in enumerate(rows[:-1]) if k < len(row)]
        notes = [f"+{c} {n} box{'es' if c > 1 else ''} out of view" for n, c in hidden if c]
        empty = [short[r] for r, row in enumerate(rows) if k < len(row) and _is_empty(row[k])]
        if empty:
            notes.insert(0, f"{', '.join(empty)}: empty")
        elif h is not None and bool(np.all(h.hi - h.lo >= 0.9 * (fh - fl))):
            notes.insert(0, f"{short[-1]} spans the frame: not zoomed")
        ax.set_xlim(float(view.lo[0]), float(view.hi[0]))
        ax.set_ylim(float(view.lo[1]), float(view.hi[1]))
        ax.set_aspect("equal", adjustable="box")
        for axis in (ax.xaxis, ax.yaxis):
            axis.set_major_locator(MaxNLocator(4))
        ax.ticklabel_format(useOffset=False)
        ax.tick_params(labelsize=7)
        ax.set_title("\n".join([f"k = {k}", *notes]), fontsize=9 if not notes else 8)
    for i, ax in enumerate(axes[: n_k + 1]):
        if i + ncols > n_k:  # nothing below it
            ax.set_xlabel(f"{axis_names[0]} ({unit})", fontsize=8)
        if i % ncols == 0:
            ax.set_ylabel(f"{axis_names[1]} ({unit})", fontsize=8)

    handles: dict[str, Any] = {}
    for ax in axes[1: n_k + 1]:
        for hd, lb in zip(*ax.get_legend_handles_labels(), strict=True):
            handles.setdefault(lb, hd)
    from matplotlib.patches import Patch

    for r, row in enumerate(rows):  # explain the inside colour even where no box is inside
        label = f"{labels[r]}: inside (proven in the set)"
        if label not in handles and any(isinstance(d, Subpaving) for d in row):
            style = SET_STYLES[1 if r == len(rows) - 1 else (0 if r == 0 else 2)]
            handles[f"{label}; none here"] = Patch(facecolor=style[0], edgecolor=style[2])
    fig.legend(list(handles.values()), list(handles.keys()), loc="outside lower center",
               ncol=min(len(handles), 2), fontsize=8, frameon=False)
    return fig
