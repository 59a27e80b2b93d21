"""boundest: guaranteed nonlinear state estimation by interval constraint propagation.

The top level gathers what a user touches most: the interval type and its operators, elementary
functions that accept intervals and expressions alike (``sin(Interval)`` is an enclosure,
``sin(Var)`` an expression node), variables and models, contractors and propagation. ``abs``,
``min``, ``max`` and ``pow`` are reachable as ``boundest.abs`` etc. but are not exported by
``from boundest import *``.
"""

from .csp import Arc, BetaResult, Propagation, TreeSCSP, beta_tuning, propagate  # noqa: F401
from .ctc import (  # noqa: F401
    Contractor,
    CtcFwdBwd,
    CtcQInter,
    Fixpoint,
    FunctionContractor,
    Inflate,
    Sequence,
    Union,
)
from .estimation import ChainEstimate, DiscreteSystem, cse, ncse, rcse  # noqa: F401
from .expr import (  # noqa: F401
    Constraint,
    Model,
    ModelSyntaxError,
    Var,
    VarFamily,
    load_model,
    parse_model,
)
from .expr import functions as _functions
from .interval import *  # noqa: F403
from .interval import IntervalVector
from .interval import __all__ as _interval_all
from .paving import Subpaving, image, separators, sivia  # noqa: F401
from .tube import (  # noqa: F401
    ContractorNetwork,
    CtcDeriv,
    CtcEval,
    CtcSlices,
    NetworkReport,
    Tube,
    TubeVector,
)

# the dispatching functions replace the interval-only ones of the same name
globals().update({name: getattr(_functions, name) for name in _functions.__all__})
abs, min, max, pow = _functions.abs, _functions.min, _functions.max, _functions.pow

__version__ = "0.1.0"
Box = IntervalVector

__all__ = list(dict.fromkeys([
    *_interval_all, *_functions.__all__, "Box", "__version__", "BetaResult", "Propagation",
    "beta_tuning", "propagate", "Contractor", "CtcFwdBwd", "CtcQInter", "Fixpoint",
    "FunctionContractor", "Inflate", "Sequence", "Union", "Constraint", "Model",
    "ModelSyntaxError", "Var",
    "VarFamily", "load_model", "parse_model", "Arc", "TreeSCSP", "ChainEstimate",
    "DiscreteSystem", "cse", "ncse", "rcse", "Subpaving", "image", "separators", "sivia",
    "ContractorNetwork", "CtcDeriv", "CtcEval", "CtcSlices", "NetworkReport", "Tube",
    "TubeVector"]))
