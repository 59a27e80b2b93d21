"""Elementary functions that work on both intervals and expressions.

``sin(x)`` is the interval enclosure when ``x`` is an ``Interval`` or a number, and the
expression node ``sin(x)`` when ``x`` is an expression (a ``Var`` or anything built from one),
so the same formula serves for evaluation and for constraints.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from .. import interval as iv
from .nodes import Expr, Op, as_expr, integer_exponent, power

_UNARY: dict[str, Callable[..., Any]] = {
    "sqr": iv.sqr, "sqrt": iv.sqrt, "exp": iv.exp, "log": iv.log, "sin": iv.sin, "cos": iv.cos,
    "tan": iv.tan, "asin": iv.asin, "acos": iv.acos, "atan": iv.atan, "sinh": iv.sinh,
    "cosh": iv.cosh, "tanh": iv.tanh, "abs": iv.algebraic.abs, "sign": iv.sign,
    "floor": iv.floor, "ceil": iv.ceil,
}
_BINARY: dict[str, Callable[..., Any]] = {
    "pow": iv.explog.pow, "atan2": iv.atan2, "min": iv.algebraic.min, "max": iv.algebraic.max,
}

__all__ = [n for n in (*_UNARY, *_BINARY, "pown") if n not in ("abs", "min", "max", "pow")]


def _unary(name: str) -> Callable[[Any], Any]:
    f = _UNARY[name]

    def func(x: Any) -> Any:
        if isinstance(x, Expr):
            return Op(name, (x,))
        return f(x)

    func.__name__ = func.__qualname__ = name
    func.__doc__ = f"``{name}(x)``: interval enclosure, or an expression node for expressions."
    return func


def _binary(name: str) -> Callable[[Any, Any], Any]:
    f = _BINARY[name]

    def func(x: Any, y: Any) -> Any:
        if isinstance(x, Expr) or isinstance(y, Expr):
            if name == "pow":
                return power(x, y, named=True)  # an integer constant: the integer power
            return Op(name, (as_expr(x), as_expr(y)))
        return f(x, y)

    func.__name__ = func.__qualname__ = name
    func.__doc__ = f"``{name}(x, y)``: interval enclosure, or an expression node."
    if name == "pow":
        func.__doc__ = ("``pow(x, y)``: interval enclosure, or an expression node. An integer "
                        "number ``y`` (``2``, ``2.0``, ``-3``, ``1e20``: any magnitude) is the "
                        "integer power (any sign of ``x``), any other ``y`` the real power "
                        "(``x >= 0``), an ``Interval`` ``y`` too (IEEE 1788 ``pow``, also when "
                        "degenerate: ``x ** Interval(2)`` is the integer power); the same on "
                        "intervals and on expressions, see ``boundest.expr.nodes.power``.")
    return func


def pown(x: Any, n: int) -> Any:
    """``x**n`` for an integer ``n``: interval enclosure, or an expression node."""
    if isinstance(x, Expr):
        k = integer_exponent(n)
        if k is None:
            raise ValueError(f"pown needs an integer exponent (a float64 value beyond 2**53), "
                             f"got {n!r}")
        return power(x, k)
    return iv.pown(x, n)


sqr, sqrt, exp, log = (_unary(n) for n in ("sqr", "sqrt", "exp", "log"))
sin, cos, tan, asin, acos, atan = (_unary(n) for n in ("sin", "cos", "tan", "asin", "acos",
                                                        "atan"))
sinh, cosh, tanh, sign, floor, ceil = (_unary(n) for n in ("sinh", "cosh", "tanh", "sign",
                                                            "floor", "ceil"))
abs = _unary("abs")
pow, atan2, min, max = (_binary(n) for n in ("pow", "atan2", "min", "max"))
