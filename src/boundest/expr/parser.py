"""The model text format (close to RealPaver's), parsed with a Lark LALR grammar.

Grammar (EBNF; the authoritative copy is ``GRAMMAR`` below)::

    model       := option* ["Variables"] declaration ("," declaration)* ";"
                   "Constraints" constraint ("," constraint)* ";"
    option      := NAME (NAME | NUMBER) ";"              e.g.  Bisection none;
    declaration := NAME "in" domain                      e.g.  x1_0 in [0, +oo[
    domain      := ("[" | "]") bound "," bound ("]" | "[")
    bound       := ["+" | "-"] (NUMBER | "oo")
    constraint  := expr ("=" | "<=" | ">=") expr  |  expr "in" domain
    expr        := term (("+" | "-") term)*
    term        := factor (("*" | "/") factor)*
    factor      := "-" factor | power
    power       := atom ["^" factor]         (an integer constant exponent gives pown)
    atom        := NUMBER | NAME | NAME "(" expr ("," expr)* ")" | "(" expr ")"

Comments run from ``//`` or ``#`` to the end of the line. A bracket written open (``]0, 1]``)
is read as closed: float intervals are closed, so this is a sound relaxation. A decimal literal
such as ``0.1`` denotes the exact decimal and becomes the tightest float interval enclosing it
(``[MAX, +oo]`` beyond the float range, ``[0, 2**-1074]`` below it); two occurrences of one
decimal are one number, two different decimals are never merged.
Functions: sqrt exp log sin cos tan asin acos atan sinh cosh tanh abs sign floor ceil (one
argument), atan2 min max pow (two). ``x^n`` and ``pow(x, n)`` mean the same: with an integer
constant ``n`` (``2``, ``2.0``, ``-3``, ``(-3)``, ``1e20``) the integer power (``sqr`` for 2,
else ``pown``; any sign of x), with any other exponent the real power ``pow`` (defined for
x >= 0). An integer literal beyond ``2**53`` must be a float64 value (``1e20``, not ``1e23``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from lark import Lark, Token, Transformer_NonRecursive, v_args
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, VisitError

from .._textfile import read_text
from ..interval import Interval
from ..interval.decimal import decimal_bounds
from .model import Model
from .nodes import Const, Constraint, Op, Var, power

__all__ = ["GRAMMAR", "ModelSyntaxError", "decimal_value", "load_model", "parse_model"]

GRAMMAR = r"""
start: option* _VARIABLES? decl ("," decl)* ";" _CONSTRAINTS constraint ("," constraint)* ";"
option: NAME (NAME | NUMBER) ";"
decl: NAME _IN domain
domain: LB bound "," bound RB
!bound: ("+" | "-")? (NUMBER | INF)
?constraint: expr "=" expr   -> eq
           | expr "<=" expr  -> le
           | expr ">=" expr  -> ge
           | expr _IN domain -> within
?expr: term
     | term (_addop term)+ -> sum
?term: factor
     | factor (_mulop factor)+ -> product
!_addop: "+" | "-"
!_mulop: "*" | "/"
?factor: power
       | "-" factor -> neg
?power: atom
      | atom "^" factor -> power
?atom: NUMBER -> number
     | NAME -> name
     | NAME "(" expr ("," expr)* ")" -> call
     | "(" expr ")"
LB: "[" | "]"
RB: "]" | "["
INF: "oo"
_IN: "in"
_VARIABLES.2: /variables\b/i
_CONSTRAINTS.2: /constraints\b/i
NUMBER: /([0-9]+\.[0-9]*|\.[0-9]+|[0-9]+)([eE][+-]?[0-9]+)?/
NAME: /(?!oo\b|in\b)[A-Za-z_][A-Za-z0-9_]*/
COMMENT: /(\/\/|#)[^\n]*/
%import common.WS
%ignore WS
%ignore COMMENT
"""

_UNARY_FUNCS = {"sqrt", "exp", "log", "sin", "cos", "tan", "asin", "acos", "atan", "sinh",
                "cosh", "tanh", "abs", "sign", "floor", "ceil"}
_BINARY_FUNCS = {"atan2", "min", "max", "pow"}

_parser = Lark(GRAMMAR, parser="lalr", propagate_positions=True, maybe_placeholders=False)


class ModelSyntaxError(ValueError):
    """A malformed model file; the message names the file, line and column."""


def decimal_value(text: str) -> tuple[Interval, tuple[int, str, int]]:
    """The tightest float interval containing the decimal written in ``text``, and the exact
    decimal as ``(sign, digits, exponent)`` (see ``Const.exact``;
    :func:`boundest.interval.decimal.decimal_bounds`)."""
    lo, hi, exact = decimal_bounds(text)
    return Interval(lo, hi), exact


_BINOP = {"+": "add", "-": "sub", "*": "mul", "/": "div"}


def _fold(items: list) -> Op:
    """``a op b op c ...`` (operands and operator tokens alternating) as the left-deep binary
    tree of the Python front end, ``((a op b) op c) ...``, built by a loop."""
    e = items[0]
    for i in range(1, len(items), 2):
        e = Op(_BINOP[str(items[i])], (e, items[i + 1]))
    return e


class _Build(Transformer_NonRecursive):
    """The model of a parse tree, built bottom-up without recursion (a tree of any depth)."""

    def __init__(self, source: str) -> None:
        super().__init__()
        self.source = source
        self.model = Model()
        self.vars: dict[str, Var] = {}

    def _err(self, tok: Token, msg: str) -> ModelSyntaxError:
        return ModelSyntaxError(f"{self.source}:{tok.line}:{tok.column}: {msg}")

    # header and declarations
    def option(self, items):
        key, value = items
        self.model.options[str(key)] = str(value)
        self.model.option_lines[str(key)] = key.line

    def bound(self, items):
        sign = -1.0 if str(items[0]) == "-" else 1.0
        tok = items[-1]
        if tok.type == "INF":
            return (tok, sign * np.inf, None)
        iv = self._decimal(tok).value
        return (tok, float(iv.lo) if sign > 0 else -float(iv.hi),
                float(iv.hi) if sign > 0 else -float(iv.lo))

    def domain(self, items):
        lb, (tok_a, a_lo, _), (tok_b, b_lo, b_hi), _rb = items
        lo = a_lo
        hi = b_lo if b_hi is None else b_hi
        if lo == np.inf or hi == -np.inf or lo > hi:
            raise self._err(lb, f"invalid domain [{tok_a}, {tok_b}]: lower bound above upper "
                                "bound or infinite on the wrong side")
        return Interval(lo, hi)

    def decl(self, items):
        name, dom = items
        if str(name) in self.vars:
            raise self._err(name, f"variable {name} declared twice")
        self.vars[str(name)] = self.model.declare(str(name), dom)

    # expressions
    def _decimal(self, tok: Token) -> Const:
        try:
            value, exact = decimal_value(str(tok))
        except ValueError as exc:
            raise self._err(tok, str(exc)) from None
        return Const(value, exact)

    def number(self, items):
        return self._decimal(items[0])

    def name(self, items):
        tok = items[0]
        var = self.vars.get(str(tok))
        if var is None:
            raise self._err(tok, f"unknown variable {tok} (declare it with '{tok} in [a, b]')")
        return var

    def call(self, items):
        fname, args = items[0], items[1:]
        f = str(fname)
        if f in _UNARY_FUNCS:
            if len(args) != 1:
                raise self._err(fname, f"{f} takes one argument, got {len(args)}")
            return Op(f, (args[0],))
        if f in _BINARY_FUNCS:
            if len(args) != 2:
                raise self._err(fname, f"{f} takes two arguments, got {len(args)}")
            if f == "pow":
                return self._power(fname, args[0], args[1])
            return Op(f, (args[0], args[1]))
        raise self._err(fname, f"unknown function {f}")

    def _power(self, tok: Token, base, e):
        try:
            return power(base, e)  # the rule of the Python front end, too
        except ValueError as exc:
            raise self._err(tok, str(exc)) from None

    def sum(self, items):
        return _fold(items)

    def product(self, items):
        return _fold(items)

    @v_args(inline=True)
    def neg(self, a):
        if isinstance(a, Const) and a.exact is not None:  # -2 is the literal -2
            sign, digits, exp = a.exact
            return Const(-a.value, (-sign, digits, exp))
        return -a

    @v_args(meta=True)
    def power(self, meta, items):
        base, e = items
        try:
            return power(base, e)
        except ValueError as exc:
            raise ModelSyntaxError(f"{self.source}:{meta.line}:{meta.column}: {exc}") from None

    # constraints
    @v_args(inline=True)
    def eq(self, a, b):
        return Constraint(a, "==", b)

    @v_args(inline=True)
    def le(self, a, b):
        return Constraint(a, "<=", b)

    @v_args(inline=True)
    def ge(self, a, b):
        return Constraint(a, ">=", b)

    @v_args(inline=True)
    def within(self, a, dom):
        return Constraint(a, "in", Const(dom))

    def start(self, items):
        self.model.add(c for c in items if isinstance(c, Constraint))
        return self.model


_READABLE = {"NAME": "a name", "NUMBER": "a number", "LB": "'[' or ']'", "RB": "']' or '['",
             "INF": "'oo'", "_IN": "'in'", "_VARIABLES": "'Variables'",
             "_CONSTRAINTS": "'Constraints'", "$END": "end of file"}


def _expected(names: set[str]) -> str:
    """The terminals a parser state accepts, as a reader would write them."""
    out = []
    for n in sorted(names):
        if n in _READABLE:
            out.append(_READABLE[n])
            continue
        try:
            pattern = _parser.get_terminal(n).pattern
        except KeyError:
            out.append(n)
            continue
        out.append(repr(pattern.value) if pattern.type == "str" else n.lower())
    return ", ".join(sorted(set(out)))


def _end_position(text: str) -> tuple[int, int]:
    """Line and column just after the last non-blank character."""
    lines = text.rstrip().splitlines() or [""]
    return len(lines), len(lines[-1]) + 1


def parse_model(text: str, source: str = "<string>") -> Model:
    """Parse model text into a ``Model``; errors name ``source``, line and column."""
    try:
        tree = _parser.parse(text)
    except UnexpectedCharacters as exc:
        raise ModelSyntaxError(f"{source}:{exc.line}:{exc.column}: unexpected character "
                               f"{text[exc.pos_in_stream]!r}") from None
    except UnexpectedInput as exc:
        expected = getattr(exc, "expected", None) or getattr(exc, "accepts", None) or set()
        hint = f" (expected {_expected(set(expected))})" if expected else ""
        tok = getattr(exc, "token", None)
        if isinstance(exc, UnexpectedEOF) or (tok is not None and tok.type == "$END"):
            line, col = _end_position(text)
            raise ModelSyntaxError(f"{source}:{line}:{col}: unexpected end of file{hint}"
                                   ) from None
        raise ModelSyntaxError(f"{source}:{exc.line}:{exc.column}: unexpected {tok!s}{hint}"
                               ) from None
    try:
        return _Build(source).transform(tree)
    except VisitError as exc:
        if isinstance(exc.orig_exc, ValueError):
            raise (exc.orig_exc if isinstance(exc.orig_exc, ModelSyntaxError)
                   else ModelSyntaxError(f"{source}: {exc.orig_exc}")) from None
        raise


def load_model(path: str | Path) -> Model:
    """Read and parse a model file (UTF-8, a byte-order mark accepted).

    Raises
    ------
    ModelSyntaxError
        For an unreadable, UTF-16, non-UTF-8 or binary file, or malformed text; the message
        names the file and line.
    """
    return parse_model(read_text(path, ModelSyntaxError), source=str(path))


