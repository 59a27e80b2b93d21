"""Figures with matplotlib (imported lazily). Functions take ``ax=None`` and return artists."""

from .boxes import plot_boxes
from .estimation import plot_set_sequence
from .paving import plot_paving
from .scenarios_tube import (
    plot_clock_distance,
    plot_clock_drift,
    plot_range_only_diagonal,
    plot_range_only_map,
)
from .tube import plot_tube

__all__ = ["plot_boxes", "plot_clock_distance", "plot_clock_drift", "plot_paving",
           "plot_range_only_diagonal", "plot_range_only_map", "plot_set_sequence", "plot_tube"]
