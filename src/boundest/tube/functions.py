"""Elementary functions of tubes: the interval function on all slices and gates at once
(``boundest.tube.functions.sin(x)`` is the tube of ``sin(x(.))``, Rohou et al. 2018 section 2.2)."""

from __future__ import annotations

from collections.abc import Callable

from .. import interval as iv
from .tube import Tube

__all__ = ["tube_function"]

_UNARY = ["sqr", "sqrt", "exp", "log", "sin", "cos", "tan", "asin", "acos", "atan", "sinh",
          "cosh", "tanh"]


def tube_function(f: Callable) -> Callable[..., Tube]:
    """Lift an interval function ``f(x, *args)`` to tubes: ``F(tube, *args)``."""
    def lifted(x: Tube, *args: object) -> Tube:
        return x.map(f, *args)
    lifted.__name__ = getattr(f, "__name__", "tube_function")
    lifted.__doc__ = f"The tube of ``{lifted.__name__}`` applied to every slice and gate."
    return lifted


for _name in _UNARY:
    globals()[_name] = tube_function(getattr(iv, _name))
abs = tube_function(iv.algebraic.abs)
atan2 = tube_function(iv.atan2)
pown = tube_function(lambda x, n: iv.pown(x, int(n)))
pown.__name__ = "pown"
__all__ += [*_UNARY, "atan2", "pown"]
