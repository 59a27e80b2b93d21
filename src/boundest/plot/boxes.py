"""Boxes drawn as rectangles."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..interval import Interval

_BIG = 1e300


def _axes(ax: Any) -> Any:
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.gca()


def plot_boxes(x: Interval, y: Interval, ax: Any = None, *, facecolor: str = "tab:blue",
               edgecolor: str = "navy", alpha: float = 0.35, label: str | None = None,
               **kwargs: Any) -> Any:
    """Draw the boxes ``[x_i] x [y_i]`` as rectangles, one ``PolyCollection``.

    Parameters
    ----------
    x, y : Interval
        1-D interval arrays of equal length: the sides of the boxes.
    ax : matplotlib Axes, optional
        Where to draw (default: the current axes).
    facecolor, edgecolor, alpha : optional
        The look of the rectangles.
    label : str, optional
        The legend entry of the boxes (``ax.legend()`` shows it).
    **kwargs
        Passed to ``PolyCollection`` (``linewidth``, ``zorder``, ...).

    Returns
    -------
    matplotlib.collections.PolyCollection
        The rectangles. Empty boxes are skipped; unbounded sides are clipped to +-1e300.
    """
    from matplotlib.collections import PolyCollection

    ax = _axes(ax)
    keep = ~(x.is_empty() | y.is_empty())
    x0, x1 = np.clip(x.lo[keep], -_BIG, _BIG), np.clip(x.hi[keep], -_BIG, _BIG)
    y0, y1 = np.clip(y.lo[keep], -_BIG, _BIG), np.clip(y.hi[keep], -_BIG, _BIG)
    verts = np.stack([np.stack([x0, y0], 1), np.stack([x1, y0], 1), np.stack([x1, y1], 1),
                      np.stack([x0, y1], 1)], axis=1)
    coll = PolyCollection(verts, facecolor=facecolor, edgecolor=edgecolor, alpha=alpha,
                          label=label, **kwargs)
    ax.add_collection(coll)
    ax.autoscale_view()
    return coll
