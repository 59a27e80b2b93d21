"""Symbolic variables, expressions and constraints; the model text format.

The text-format parser (``parse_model``, ``load_model``, ``ModelSyntaxError``) is imported on
first access: building it loads Lark and its grammar, which a run that reads no model file
does not need.
"""

from typing import Any

from .model import Model
from .nodes import Const, Constraint, Expr, Op, Var, VarFamily, as_expr, variables

__all__ = [
           "Const",
           "Constraint",
           "Expr",
           "Model",
           "ModelSyntaxError",
           "Op",
           "Var",
           "VarFamily",
           "as_expr",
           "load_model",
           "parse_model",
           "variables",
]


def __getattr__(name: str) -> Any:
    if name in ("ModelSyntaxError", "load_model", "parse_model"):
        from . import parser

        return getattr(parser, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
