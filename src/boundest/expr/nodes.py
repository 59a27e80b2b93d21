"""Symbolic expressions and constraints built by operator overloading.

>>> x1, x3, w1 = Var.family("x1"), Var.family("x3"), Var.family("w1")
>>> c = x1[1] == x1[0] + 0.5 * x3[0] + w1[0]
>>> str(c)
'x1_1 == x1_0 + 0.5 * x3_0 + w1_0'

Expressions are immutable trees; the compiler (``tape.py``) shares equal sub-expressions.

Constants: a degenerate constant (``lo == hi``) is that float. A non-degenerate one (an
``Interval`` used in an expression) stands for *some* value of the interval, chosen
independently at each occurrence, as interval evaluation does; the compiler never merges two
occurrences, unless ``Const.exact`` says they denote the same real number (a decimal literal
of the model text format).

Powers: an integer constant exponent (``2``, ``2.0``, ``-3``, ``1e20``, ``Const(3)``) is the
integer power ``pown`` (``sqr`` for 2), defined for every sign of the base; any other exponent is
the real power ``pow``, defined for a base ``>= 0``. ``x ** n``, ``boundest.pow(x, n)`` and the
text format's ``x^n`` and ``pow(x, n)`` all follow this rule (``power``), as intervals do
(``boundest.interval.explog.power``): the one difference between the operator and the named
function is an ``Interval`` exponent, which ``boundest.pow`` always takes as the IEEE 1788 real
power (``pow(x, Interval(2))`` is defined for ``x >= 0`` only) and ``**`` as the integer power
when it is a degenerate integer.
"""

from __future__ import annotations

import math
import numbers
import re
from collections.abc import Iterable

from ..interval import Interval, as_interval

__all__ = [
    "BINARY",
    "MAX_POWN_EXPONENT",
    "UNARY",
    "Const",
    "Constraint",
    "Expr",
    "Op",
    "Var",
    "VarFamily",
    "as_expr",
    "integer_exponent",
    "power",
    "variables",
]

#: Unary primitives (name -> infix/func display) understood by the compiler.
UNARY = ("neg", "sqr", "sqrt", "exp", "log", "sin", "cos", "tan", "asin", "acos", "atan",
         "sinh", "cosh", "tanh", "abs", "sign", "floor", "ceil", "pown")
#: Binary primitives.
BINARY = ("add", "sub", "mul", "div", "pow", "atan2", "min", "max")
_INFIX = {"add": ("+", 1), "sub": ("-", 1), "mul": ("*", 2), "div": ("/", 2)}
#: Beyond this ``|n|`` an integer exponent must be a float64 value (every integer-valued float
#: is, ``1e300`` too): the tape keeps exponents as float64, and an integer such as
#: ``2**53 + 1`` would be rounded to another one (an odd power to an even one).
MAX_POWN_EXPONENT = 2**53


class Expr:
    """Base class of expression nodes; arithmetic operators build new nodes."""

    __slots__ = ()
    __array_ufunc__ = None
    __hash__ = object.__hash__  # == builds a constraint, so hashing is by identity

    # arithmetic
    def __add__(self, o: object) -> Expr:
        return Op("add", (self, as_expr(o)))

    def __radd__(self, o: object) -> Expr:
        return Op("add", (as_expr(o), self))

    def __sub__(self, o: object) -> Expr:
        return Op("sub", (self, as_expr(o)))

    def __rsub__(self, o: object) -> Expr:
        return Op("sub", (as_expr(o), self))

    def __mul__(self, o: object) -> Expr:
        return Op("mul", (self, as_expr(o)))

    def __rmul__(self, o: object) -> Expr:
        return Op("mul", (as_expr(o), self))

    def __truediv__(self, o: object) -> Expr:
        return Op("div", (self, as_expr(o)))

    def __rtruediv__(self, o: object) -> Expr:
        return Op("div", (as_expr(o), self))

    def __neg__(self) -> Expr:
        return Op("neg", (self,))

    def __pos__(self) -> Expr:
        return self

    def __pow__(self, o: object) -> Expr:
        """``self ** o``: the integer power for an integer constant ``o`` (see ``power``)."""
        return power(self, o)

    def __rpow__(self, o: object) -> Expr:
        return Op("pow", (as_expr(o), self))

    def __abs__(self) -> Expr:
        return Op("abs", (self,))

    # constraints
    def __eq__(self, o: object) -> Constraint:  # type: ignore[override]
        return Constraint(self, "==", as_expr(o))

    def __le__(self, o: object) -> Constraint:
        return Constraint(self, "<=", as_expr(o))

    def __ge__(self, o: object) -> Constraint:
        return Constraint(self, ">=", as_expr(o))

    def in_(self, domain: Interval | tuple[float, float] | list[float]) -> Constraint:
        """The constraint ``self in domain`` (Python's ``in`` cannot return a constraint)."""
        if not isinstance(domain, Interval):
            domain = Interval(*domain)
        if domain.shape != ():
            raise ValueError(f"in_() needs a scalar interval, got shape {domain.shape}")
        return Constraint(self, "in", Const(domain))

    def __bool__(self) -> bool:
        raise TypeError("an expression has no truth value (did you compare two expressions "
                        "outside a constraint?)")

    def __repr__(self) -> str:
        return f"Expr({self})"


class Const(Expr):
    """A constant, held as a scalar interval (a decimal literal is its outward enclosure).

    Parameters
    ----------
    value : Interval or float
        The constant; a non-degenerate interval stands for an unknown value inside it, chosen
        independently at each occurrence.
    exact : (sign, digits, exponent), optional
        The real number ``sign * int(digits) * 10**exponent`` that ``value`` encloses, when it
        is known (decimal literals); ``digits`` has no leading or trailing zero (zero is
        ``(0, "", 0)``). Occurrences with equal ``exact`` denote the same number, so the
        compiler may share them.
    """

    __slots__ = ("exact", "value")

    def __init__(self, value: Interval | float, exact: tuple[int, str, int] | None = None
                 ) -> None:
        v = as_interval(value)
        if v.shape != ():
            raise ValueError(f"a constant must be a scalar, got shape {v.shape}")
        self.value = v
        self.exact = exact

    def __str__(self) -> str:
        lo, hi = float(self.value.lo), float(self.value.hi)
        return f"{lo:g}" if lo == hi else f"[{lo!r}, {hi!r}]"


class Var(Expr):
    """A named real variable. ``Var.family("x")[k]`` is the variable ``x_k``."""

    __slots__ = ("name",)

    def __init__(self, name: str) -> None:
        if not isinstance(name, str) or not name.isidentifier():
            raise ValueError(f"invalid variable name: {name!r}")
        self.name = name

    def __str__(self) -> str:
        return self.name

    @staticmethod
    def family(name: str) -> VarFamily:
        return VarFamily(name)


class VarFamily:
    """An indexed family of variables: ``x[k]`` is the variable named ``x_k``.

    The same index gives the same ``Var`` object; multi-indices join with ``_``.
    """

    def __init__(self, name: str) -> None:
        if not isinstance(name, str) or not name.isidentifier():
            raise ValueError(f"invalid variable family name: {name!r}")
        self.name = name
        self._members: dict[tuple[int, ...], Var] = {}

    def __getitem__(self, k: int | tuple[int, ...]) -> Var:
        key = k if isinstance(k, tuple) else (k,)
        for i in key:
            if not isinstance(i, numbers.Integral) or i < 0:
                raise IndexError(f"{self.name}[{k}]: indices must be non-negative integers")
        var = self._members.get(key)
        if var is None:
            var = Var(self.name + "".join(f"_{int(i)}" for i in key))
            self._members[key] = var
        return var

    def members(self, names: Iterable[str]) -> dict[tuple[int, ...], str]:
        """The members of this family among ``names``, by index: ``{(k,): "x_k"}`` or
        ``{(k, i): "x_k_i"}``, whether or not they were built by indexing this object (a model
        parsed from text names its variables ``x_k`` too).

        Raises ``ValueError`` when the members found have different numbers of indices (``x_1``
        and ``x_1_0``, which may be another family ``x_1``): ask for that family by its own name.
        """
        pattern = re.compile(re.escape(self.name) + r"((?:_(?:0|[1-9][0-9]*))+)")
        found: dict[tuple[int, ...], str] = {}
        for n in names:
            m = pattern.fullmatch(n)
            if m:
                found[tuple(int(i) for i in m.group(1)[1:].split("_"))] = n
        arity = {len(k) for k in found}
        if len(arity) > 1:
            raise ValueError(f"family {self.name!r}: members with {sorted(arity)} indices "
                             f"({', '.join(sorted(found.values())[:4])} ...); name the family "
                             "of the longer names (e.g. VarFamily('x_1') for x_1_0) instead")
        return found

    def __repr__(self) -> str:
        return f"VarFamily({self.name!r})"


class Op(Expr):
    """An operation node: ``name`` is one of ``UNARY + BINARY``; ``param`` is pown's exponent."""

    __slots__ = ("args", "name", "param")

    def __init__(self, name: str, args: tuple[Expr, ...], param: int | None = None) -> None:
        arity = 1 if name in UNARY else 2 if name in BINARY else None
        if arity is None:
            raise ValueError(f"unknown operation {name!r}")
        if len(args) != arity:
            raise ValueError(f"{name} takes {arity} argument(s), got {len(args)}")
        if name == "pown" and not (isinstance(param, numbers.Integral)
                                   and not isinstance(param, bool)):
            raise ValueError(f"pown needs an integer exponent, got {param!r}")
        if name == "pown" and not _tape_exact(int(param)):  # type: ignore[arg-type]
            raise ValueError(f"integer exponent {param} is not a float64 value: beyond "
                             f"2**53 an expression's integer exponent must be one")
        self.name, self.args, self.param = name, args, param

    def __str__(self) -> str:
        return _render(self)

    def __reduce__(self) -> tuple:
        # pickle and copy would recurse once per level of the tree: a flat table instead
        return _decode_one, (_encode([self]),)


def _prec(e: Expr) -> int | None:
    """The precedence ``e`` is printed at, or None for an atom that never needs parentheses
    (a non-negative constant, a variable)."""
    if isinstance(e, Op):
        return _INFIX[e.name][1] if e.name in _INFIX else 3 if e.name == "neg" else 5
    if isinstance(e, Const) and float(e.value.lo) < 0:
        return -1  # printed with a sign: parenthesised wherever an operand
    return None


def _operand(e: Expr, prec: int, right: bool = False) -> list:
    """``e`` as the operand of an operator of precedence ``prec``, parenthesised if needed."""
    p = _prec(e)
    if p is not None and (p < prec or (right and p == prec)):
        return ["(", e, ")"]
    return [e]


def _render(root: Expr) -> str:
    """The text of ``root``: an explicit stack of pieces (text or a sub-expression still to
    print), so that an expression of any depth prints in time linear in its text."""
    out: list[str] = []
    stack: list[str | Expr] = [root]
    while stack:
        item = stack.pop()
        if isinstance(item, str):
            out.append(item)
            continue
        if not isinstance(item, Op):
            out.append(str(item))
            continue
        name, args = item.name, item.args
        if name in _INFIX:
            sym, prec = _INFIX[name]
            parts = [*_operand(args[0], prec), f" {sym} ", *_operand(args[1], prec, right=True)]
        elif name == "neg":
            parts = ["-", *_operand(args[0], 3)]
        elif name in ("sqr", "pown"):
            parts = [*_operand(args[0], 4), "^2" if name == "sqr" else f"^{item.param}"]
        else:
            parts = [f"{name}("]
            for i, a in enumerate(args):
                parts += [", ", a] if i else [a]
            parts.append(")")
        stack.extend(reversed(parts))
    return "".join(out)


def _encode(roots: Iterable[Expr]) -> tuple[list, list[int]]:
    """Expressions as a flat table in post-order, and the index of each root in it.

    An entry is a leaf (a ``Var`` or ``Const``, pickled as itself) or ``(name, param, i, ...)``
    for an ``Op`` over the entries ``i, ...``. A sub-expression reused by identity is one entry,
    so the table is as large as the DAG, and decoding restores the sharing.
    """
    index: dict[int, int] = {}
    table: list = []
    positions: list[int] = []
    for root in roots:
        stack: list[tuple[Expr, bool]] = [(root, False)]
        while stack:
            e, expanded = stack.pop()
            if id(e) in index:
                continue
            if isinstance(e, Op) and not expanded:
                stack.append((e, True))
                stack.extend((a, False) for a in reversed(e.args) if id(a) not in index)
                continue
            index[id(e)] = len(table)
            table.append((e.name, e.param, *(index[id(a)] for a in e.args))
                         if isinstance(e, Op) else e)
        positions.append(index[id(root)])
    return table, positions


def _decode(table: list, positions: list[int]) -> list[Expr]:
    """The roots of an ``_encode`` table, rebuilt."""
    built: list[Expr] = []
    for entry in table:
        if isinstance(entry, tuple):
            name, param, *idx = entry
            built.append(Op(name, tuple(built[i] for i in idx), param))
        else:
            built.append(entry)
    return [built[i] for i in positions]


def _decode_one(enc: tuple[list, list[int]]) -> Expr:
    return _decode(*enc)[0]


def _decode_constraint(rel: str, enc: tuple[list, list[int]]) -> Constraint:
    lhs, rhs = _decode(*enc)
    return Constraint(lhs, rel, rhs)


class Constraint:
    """``lhs rel rhs`` with ``rel`` one of ``==``, ``<=``, ``>=``, ``in`` (rhs a constant)."""

    __slots__ = ("lhs", "rel", "rhs")

    def __init__(self, lhs: Expr, rel: str, rhs: Expr) -> None:
        if rel not in ("==", "<=", ">=", "in"):
            raise ValueError(f"unknown relation {rel!r}")
        self.lhs, self.rel, self.rhs = lhs, rel, rhs

    def __str__(self) -> str:
        return f"{self.lhs} {self.rel} {self.rhs}"

    def __repr__(self) -> str:
        return f"Constraint({self})"

    def __reduce__(self) -> tuple:
        return _decode_constraint, (self.rel, _encode([self.lhs, self.rhs]))

    def __bool__(self) -> bool:
        raise TypeError("a constraint has no truth value; add it to a model instead")


def as_expr(x: object) -> Expr:
    """``x`` itself for an expression, else a constant (numbers and scalar intervals)."""
    if isinstance(x, Expr):
        return x
    if isinstance(x, (Interval, numbers.Real)):
        return Const(x)  # type: ignore[arg-type]
    raise TypeError(f"cannot use {type(x).__name__} {x!r} in an expression")


def _tape_exact(n: int) -> bool:
    """Whether the integer ``n`` is a float64 value (a tape holds its exponent as one)."""
    if -MAX_POWN_EXPONENT <= n <= MAX_POWN_EXPONENT:
        return True
    try:
        return int(float(n)) == n
    except OverflowError:
        return False


def integer_exponent(e: object) -> int | None:
    """The integer ``n`` when ``e`` is an integer constant exponent, else None.

    Integer constants are Python/NumPy integers, integer-valued floats (``2.0``, ``1e20``: every
    float beyond ``2**53`` is an integer), and degenerate constants (``Const``, ``Interval``)
    with an integer value; beyond ``MAX_POWN_EXPONENT`` an integer must be a float64 value
    (``2**64`` is, ``2**53 + 1`` is not). Booleans are not numbers here.
    """
    if isinstance(e, bool):
        return None
    if isinstance(e, numbers.Integral):
        n = int(e)
    elif isinstance(e, numbers.Real):
        f = float(e)
        if not (math.isfinite(f) and f.is_integer()):
            return None
        n = int(f)
    elif isinstance(e, (Const, Interval)):
        v = e.value if isinstance(e, Const) else e
        if v.shape != ():
            return None
        lo, hi = float(v.lo), float(v.hi)
        if not (lo == hi and math.isfinite(lo) and lo.is_integer()):
            return None
        n = int(lo)
    else:
        return None
    return n if _tape_exact(n) else None


def power(base: object, exponent: object, named: bool = False) -> Expr:
    """``base ** exponent`` (or ``pow(base, exponent)`` when ``named``) as an expression, the
    one power rule of both front ends.

    An integer constant exponent (see ``integer_exponent``), of any magnitude, gives the integer
    power: ``sqr`` for 2, else ``pown`` (any sign of the base; ``pown(x, -1) = 1/x``,
    ``pown(x, 0) = 1``, ``x ** 1e20`` is even, ``[MAX, inf]`` for ``x in [-3, -2]``). Any other
    exponent (a non-integer, an interval, an expression) gives the real power ``pow``, defined
    for ``base >= 0``. The named function (``boundest.pow``) takes an ``Interval`` exponent as
    IEEE 1788 ``pow`` even when it is a degenerate integer, as it does on intervals (the 1788
    ``pow([-0.1, 0.5], [1, 1]) = [0, 0.5]``); ``x ** Interval(3)`` is ``pown(x, 3)`` on both
    front ends.

    Parameters
    ----------
    base, exponent : expression, number or Interval
    named : bool
        Whether this is the named function ``pow`` rather than the operator ``**``.

    Raises
    ------
    ValueError
        For an integer exponent beyond ``MAX_POWN_EXPONENT`` that is not a float64 value (the
        tape could not hold it exactly, and the real power would drop the negative bases): a
        Python integer such as ``2**53 + 1``, a decimal literal such as ``1e23``.
    TypeError
        For a boolean exponent.
    """
    if isinstance(exponent, bool):
        raise TypeError("a boolean is not an exponent")
    if named and isinstance(exponent, Interval):
        return Op("pow", (as_expr(base), as_expr(exponent)))
    n = integer_exponent(exponent)
    if n is not None:
        b = as_expr(base)
        return Op("sqr", (b,)) if n == 2 else Op("pown", (b,), n)
    if isinstance(exponent, numbers.Integral):
        raise ValueError(f"integer exponent {int(exponent)} is not a float64 value: beyond "
                         f"2**53 an expression's integer exponent must be one")
    e = as_expr(exponent)
    if isinstance(e, Const) and e.exact is not None and e.exact[0] != 0 and e.exact[2] >= 0:
        # a decimal integer that no float equals (1e23): its enclosure is not degenerate
        shown = f"{'-' if e.exact[0] < 0 else ''}{e.exact[1][:20]}e{e.exact[2]}"
        raise ValueError(f"integer exponent {shown} is not a float64 value: beyond 2**53 an "
                         f"expression's integer exponent must be one")
    return Op("pow", (as_expr(base), e))


def variables(items: Iterable[Expr | Constraint]) -> list[Var]:
    """The distinct variables of expressions/constraints, in order of first appearance."""
    seen: dict[str, Var] = {}
    stack: list[Expr] = []
    for it in items:
        stack.extend([it.rhs, it.lhs] if isinstance(it, Constraint) else [it])
        while stack:
            e = stack.pop()
            if isinstance(e, Var):
                seen.setdefault(e.name, e)
            elif isinstance(e, Op):
                stack.extend(reversed(e.args))
    return list(seen.values())
