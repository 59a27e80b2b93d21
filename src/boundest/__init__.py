"""boundest: guaranteed nonlinear state estimation by interval constraint propagation."""

from .interval import *  # noqa: F403
from .interval import __all__ as _interval_all

__version__ = "0.1.0"
Box = IntervalVector  # noqa: F405

__all__ = [*_interval_all, "Box", "__version__"]
