"""Sliced tubes and their contractors: derivative, evaluation with uncertain times, algebraic
constraints on every slice, and a contractor network (Rohou et al. 2018)."""

from .deriv import CtcDeriv
from .eval import CtcEval
from .functions import *  # noqa: F403
from .functions import __all__ as _functions_all
from .network import ContractorNetwork, NetworkReport
from .slices import CtcSlices
from .tube import Tube, TubeVector, time_grid

__all__ = ["ContractorNetwork", "CtcDeriv", "CtcEval", "CtcSlices", "NetworkReport", "Tube",
           "TubeVector", "time_grid", *_functions_all]
