"""Constraint networks and their propagation; FALL/CLIMB on trees; beta-tuning."""

from .beta import BetaResult, beta_tuning
from .propagate import Propagation, propagate
from .tree import Arc, TreeSCSP

__all__ = ["Arc", "BetaResult", "Propagation", "TreeSCSP", "beta_tuning", "propagate"]
