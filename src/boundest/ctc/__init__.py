"""Contractors: forward-backward on a tape, composition, fixpoint, inflation, q-relaxed
intersection, 3B shaving; interval Jacobians, centered forms, the centered-form contractor and
interval Newton; LP contraction of linear / log-linear sub-networks and of a linear
relaxation of the nonlinear ones (polytope hull); the minimal polar contractor (range and
bearing); the range sensor (first-hit distance along a ray of an obstacle map)."""

from .base import Contractor, Fixpoint, FunctionContractor, Inflate, Sequence, Union, shrink_ratio
from .centered import CtcCentered, CtcNewton
from .derivatives import centered, jacobian
from .fwdbwd import CtcFwdBwd
from .linear import CtcLinear
from .obstacles import ObstacleMap
from .polar import CtcPolar
from .qinter import CtcQInter
from .raycast import CtcRayCast
from .relax import CtcPolytopeHull
from .shave import CtcShave

__all__ = ["Contractor", "CtcCentered", "CtcFwdBwd", "CtcLinear", "CtcNewton", "CtcPolar",
           "CtcPolytopeHull", "CtcQInter", "CtcRayCast", "CtcShave", "Fixpoint",
           "FunctionContractor", "Inflate", "ObstacleMap", "Sequence", "Union", "centered",
           "jacobian", "shrink_ratio"]
