"""Constraint networks and their propagation (hull consistency, box consistency, shaving, LP);
FALL/CLIMB on trees; beta-tuning."""

from .beta import BetaResult, beta_tuning
from .boxcons import CtcBox
from .propagate import (
    DEFAULT_MODE,
    MODES,
    BoxConsistency,
    Centered,
    LinearRelaxation,
    Propagation,
    Shaving,
    propagate,
)
from .tree import Arc, TreeSCSP

__all__ = ["DEFAULT_MODE", "MODES", "Arc", "BetaResult", "BoxConsistency", "Centered", "CtcBox",
           "LinearRelaxation", "Propagation", "Shaving", "TreeSCSP", "beta_tuning", "propagate"]
