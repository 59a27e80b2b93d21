"""Figures with matplotlib (imported lazily). Functions take ``ax=None`` and return artists.

Each name is imported from its module on first access, so that a command drawing boxes does
not load the modules (and the layers below them) of the figures it does not draw.
"""

import importlib
from typing import Any

_WHERE = {"plot_boxes": "boxes", "plot_set_sequence": "estimation", "plot_paving": "paving",
          "plot_clock_distance": "scenarios_tube", "plot_clock_drift": "scenarios_tube",
          "plot_range_only_diagonal": "scenarios_tube", "plot_range_only_map": "scenarios_tube",
          "plot_tube": "tube"}

__all__ = ["plot_boxes", "plot_clock_distance", "plot_clock_drift", "plot_paving",
           "plot_range_only_diagonal", "plot_range_only_map", "plot_set_sequence", "plot_tube"]


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        return getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
