"""Contractors: forward-backward on a tape, composition, fixpoint, inflation, q-relaxed
intersection."""

from .base import Contractor, Fixpoint, FunctionContractor, Inflate, Sequence, Union, shrink_ratio
from .fwdbwd import CtcFwdBwd
from .qinter import CtcQInter

__all__ = ["Contractor", "CtcFwdBwd", "CtcQInter", "Fixpoint", "FunctionContractor", "Inflate",
           "Sequence", "Union", "shrink_ratio"]
