"""Boxes drawn as rectangles."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..interval import Interval


def _axes(ax: Any) -> Any:
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.gca()


def plot_boxes(x: Interval, y: Interval, ax: Any = None, *, facecolor: str = "tab:blue",
               edgecolor: str = "navy", alpha: float = 0.35, **kwargs: Any) -> Any:
    """Draw the boxes ``[x_i] x [y_i]`` (1-D interval arrays of equal length) as rectangles.

    Empty boxes are skipped; unbounded sides are clipped to the current view.
    """
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Rectangle

    ax = _axes(ax)
    keep = ~(x.is_empty() | y.is_empty())
    big = 1e300
    x0, x1 = np.clip(x.lo[keep], -big, big), np.clip(x.hi[keep], -big, big)
    y0, y1 = np.clip(y.lo[keep], -big, big), np.clip(y.hi[keep], -big, big)
    rects = [Rectangle((a, c), b - a, d - c) for a, b, c, d in zip(x0, x1, y0, y1, strict=True)]
    coll = PatchCollection(rects, facecolor=facecolor, edgecolor=edgecolor, alpha=alpha,
                           **kwargs)
    ax.add_collection(coll)
    ax.autoscale_view()
    return coll
