"""Tubes drawn as filled bands (slices), gate segments, a truth line and measurement boxes."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..interval import Interval
from .boxes import _axes, plot_boxes

if TYPE_CHECKING:
    from ..tube import Tube

__all__ = ["plot_tube"]

_BIG = 1e300


def plot_tube(tube: Tube, ax: Any = None, *, component: int | None = None,
              truth: Any = None, boxes: tuple[Interval, Interval] | None = None,
              color: str = "tab:blue", alpha: float = 0.35, gates: bool | None = None,
              label: str | None = None, truth_color: str = "black",
              box_color: str = "tab:red", truth_label: str | None = None,
              box_label: str | None = None) -> list[Any]:
    """Draw a scalar tube (or one ``component`` of a tube vector) against time.

    Parameters
    ----------
    truth : (t, y) arrays or callable ``y(t)``, optional
        A trajectory drawn as a line over the tube.
    boxes : (Interval, Interval), optional
        Measurement boxes ``[t_i] x [z_i]`` (1-D interval arrays).
    gates : bool, optional
        Draw the gates as vertical segments (default: when there are at most 500 slices).
    label, truth_label, box_label : str, optional
        Legend entries of the tube, the truth and the boxes.

    Returns
    -------
    list
        The artists drawn. Unbounded parts of the tube are not drawn.
    """
    if tube.is_vector:
        if component is None:
            raise ValueError("plot_tube: give component= for a tube vector")
        tube = tube[component]
    ax = _axes(ax)
    t = tube.t
    lo = np.where(np.isfinite(tube.slices.lo) & (np.abs(tube.slices.lo) < _BIG),
                  tube.slices.lo, np.nan)
    hi = np.where(np.isfinite(tube.slices.hi) & (np.abs(tube.slices.hi) < _BIG),
                  tube.slices.hi, np.nan)
    x = np.repeat(t, 2)[1:-1]
    artists = [ax.fill_between(x, np.repeat(lo, 2), np.repeat(hi, 2), color=color, alpha=alpha,
                               linewidth=0, label=label)]
    if gates if gates is not None else tube.n_slices <= 500:
        from matplotlib.collections import LineCollection

        ok = np.isfinite(tube.gates.lo) & np.isfinite(tube.gates.hi)
        segs = np.stack([np.stack([t[ok], tube.gates.lo[ok]], 1),
                         np.stack([t[ok], tube.gates.hi[ok]], 1)], axis=1)
        artists.append(ax.add_collection(LineCollection(segs, colors=color, linewidths=0.8)))
    if truth is not None:
        if callable(truth):
            ts = np.linspace(t[0], t[-1], max(2, 4 * tube.n_slices))
            ys = np.asarray(truth(ts), dtype=np.float64)
        else:
            ts, ys = (np.asarray(a, dtype=np.float64) for a in truth)
        artists += ax.plot(ts, ys, color=truth_color, linewidth=1.0, label=truth_label)
    if boxes is not None:
        artists.append(plot_boxes(boxes[0], boxes[1], ax=ax, facecolor=box_color,
                                  edgecolor=box_color, alpha=0.5, label=box_label))
    ax.set_xlim(t[0], t[-1])
    ax.autoscale_view(scalex=False)
    return artists
