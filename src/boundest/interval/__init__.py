"""Rigorous interval arithmetic over NumPy arrays (forward and backward operators).

Names that would shadow Python builtins (``abs``, ``min``, ``max``, ``pow``) are reachable as
``boundest.abs`` etc. but are left out of ``__all__`` so that ``from boundest import *`` is safe.
"""

from .._kernels import activate as _activate_kernel_archive
from .._numba_cache import drop_stale_numba_cache

drop_stale_numba_cache()
_activate_kernel_archive()  # the shipped machine code, before Numba's codegen is set up

from . import algebraic, explog, trig  # noqa: E402
from .algebraic import *  # noqa: E402, F403
from .arith import add, div, mul, neg, recip, sqr, sqrt, sub  # noqa: E402
from .core import Interval, IntervalVector, as_interval, hull, intersect  # noqa: E402
from .explog import *  # noqa: E402, F403
from .relaxed import qinter, qinter_boxes  # noqa: E402
from .trig import *  # noqa: E402, F403

__all__ = ["Interval", "IntervalVector", "as_interval", "hull", "intersect",
           "add", "sub", "mul", "div", "neg", "recip", "sqr", "sqrt", "qinter", "qinter_boxes",
           *algebraic.__all__, *explog.__all__, *trig.__all__]
