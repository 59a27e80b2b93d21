"""Subpavings drawn in the colours of the field: inside red, boundary yellow, outside cyan."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..paving import Subpaving
from .boxes import _axes

__all__ = ["plot_paving"]

_BIG = 1e300


def _rects(lo: np.ndarray, hi: np.ndarray, dims: tuple[int, int]) -> np.ndarray:
    """Vertices ``(m, 4, 2)`` of the projections of boxes on two dimensions (vectorised)."""
    i, j = dims
    x0, x1 = np.clip(lo[:, i], -_BIG, _BIG), np.clip(hi[:, i], -_BIG, _BIG)
    y0, y1 = np.clip(lo[:, j], -_BIG, _BIG), np.clip(hi[:, j], -_BIG, _BIG)
    return np.stack([np.stack([x0, y0], 1), np.stack([x1, y0], 1), np.stack([x1, y1], 1),
                     np.stack([x0, y1], 1)], axis=1)


def plot_paving(sp: Subpaving, ax: Any = None, dims: tuple[int, int] = (0, 1), *,
                inside: str = "tab:red", boundary: str = "yellow", outside: str = "cyan",
                edgecolor: str = "black", linewidth: float = 0.2, alpha: float = 1.0,
                labels: tuple[str | None, str | None, str | None] | None = None,
                **kwargs: Any) -> list[Any]:
    """Draw a subpaving projected on the dimensions ``dims``.

    Inside boxes in ``inside``, boundary boxes in ``boundary`` and kept outside boxes in
    ``outside`` colours, one ``PolyCollection`` each (built from vertex arrays, no patch object
    per box).

    Parameters
    ----------
    sp : Subpaving
        The subpaving.
    ax : matplotlib Axes, optional
        Where to draw (default: the current axes).
    dims : (int, int)
        The two dimensions drawn (x axis, y axis).
    inside, boundary, outside : str
        Colours of the inside (proven in the set), boundary (undecided) and kept outside boxes.
    labels : (str, str, str), optional
        Legend entries of the inside, boundary and outside boxes (default: ``"inside"``,
        ``"boundary"``, ``"outside"``); ``None`` for one of them leaves it out of the legend.

    Returns
    -------
    list of PolyCollection
        The collections drawn (outside, boundary, inside; the empty ones are skipped).
    """
    from matplotlib.collections import PolyCollection

    if not isinstance(sp, Subpaving):
        raise ValueError(f"plot_paving needs a Subpaving, got {type(sp).__name__}")
    if len(dims) != 2 or not all(0 <= d < sp.dim for d in dims) or dims[0] == dims[1]:
        raise ValueError(f"dims must be two distinct dimensions below {sp.dim}, got {dims}")
    ax = _axes(ax)
    l_in, l_bd, l_out = labels if labels is not None else ("inside", "boundary", "outside")
    out = []
    for boxes, colour, label in ((sp.outside, outside, l_out), (sp.boundary(), boundary, l_bd),
                                 (sp.inner(), inside, l_in)):
        if boxes.shape[0] == 0:
            continue
        coll = PolyCollection(_rects(boxes.lo, boxes.hi, dims), facecolor=colour,
                              edgecolor=edgecolor, linewidth=linewidth, alpha=alpha,
                              label=label, **kwargs)
        ax.add_collection(coll)
        out.append(coll)
    ax.autoscale_view()
    return out
