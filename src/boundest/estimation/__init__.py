"""Set state estimators: causal (CSE, RCSE) and non-causal (NCSE) on boxes or subpavings."""

from .discrete import ChainEstimate, DiscreteSystem, cse, ncse, rcse, rcse_ncse
from .maps import Map
from .setops import BoxSets, PavingSets

__all__ = ["BoxSets", "ChainEstimate", "DiscreteSystem", "Map", "PavingSets", "cse", "ncse",
           "rcse", "rcse_ncse"]
