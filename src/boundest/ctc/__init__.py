"""Contractors: forward-backward on a tape, composition, fixpoint, inflation."""

from .base import Contractor, Fixpoint, FunctionContractor, Inflate, Sequence, Union, shrink_ratio
from .fwdbwd import CtcFwdBwd

__all__ = ["Contractor", "CtcFwdBwd", "Fixpoint", "FunctionContractor", "Inflate", "Sequence",
           "Union", "shrink_ratio"]
