"""Symbolic variables, expressions and constraints; the model text format."""

from .model import Model
from .nodes import Const, Constraint, Expr, Op, Var, VarFamily, as_expr, variables
from .parser import ModelSyntaxError, load_model, parse_model

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
