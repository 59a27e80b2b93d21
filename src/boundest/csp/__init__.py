"""Constraint networks and their propagation; FALL/CLIMB on trees; beta-tuning."""

from .beta import BetaResult, beta_tuning
from .propagate import MODES, BoxConsistency, LinearRelaxation, Propagation, Shaving, propagate
from .tree import Arc, TreeSCSP

__all__ = ["MODES", "Arc", "BetaResult", "BoxConsistency", "LinearRelaxation", "Propagation",
           "Shaving", "TreeSCSP", "beta_tuning", "propagate"]
