"""Constraint networks and their propagation; beta-tuning."""

from .beta import BetaResult, beta_tuning
from .propagate import Propagation, propagate

__all__ = ["BetaResult", "Propagation", "beta_tuning", "propagate"]
