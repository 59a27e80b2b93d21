"""Figures with matplotlib (imported lazily). Functions take ``ax=None`` and return artists."""

from .boxes import plot_boxes
from .estimation import plot_set_sequence
from .paving import plot_paving
from .tube import plot_tube

__all__ = ["plot_boxes", "plot_paving", "plot_set_sequence", "plot_tube"]
