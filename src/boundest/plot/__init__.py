"""Figures with matplotlib (imported lazily). Functions take ``ax=None`` and return artists."""

from .boxes import plot_boxes

__all__ = ["plot_boxes"]
