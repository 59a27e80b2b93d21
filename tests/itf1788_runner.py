"""IEEE 1788 conformance harness: the ITF1788 test vectors run against boundest.

The vectors (``tests/itf1788/*.itl``, Apache-2.0, see ``tests/itf1788/ORIGIN.md``) are lines

    op arg1 arg2 ... = res1 [res2];

inside ``testcase NAME { ... }`` blocks. This module parses them, maps each IEEE 1788 operation
to the boundest function that implements it (looked up by name at run time, so an operation
whose function does not exist yet is reported as *unimplemented*, not failed), runs all vectors
of one operation as one batched array call, and classifies every result:

* ``tight``        bounds equal to the expected (tightest float64) result;
* ``within_1ulp``  sound, each bound at most 1 float64 step outside the expected one;
* ``within_4ulp``  sound, at most 4 steps (and more than 1);
* ``looser``       sound, more than 4 steps, or infinitely many (an infinite bound where the
                   tightest one is finite, or non-empty where the tightest result is empty);
* a *failure* otherwise: the expected result is not contained in boundest's (unsound), the
  result is not a valid interval (``lo > hi``, a single NaN bound, ``lo = +inf``...), the call
  raised (or the worker process died on it), or a boolean / number differs from the expected
  one. Numbers are compared exactly, except ``wid`` and ``rad``, upper bounds by definition, for
  which a larger result is sound and classified by its distance like an enclosure bound.

Numbers in the files. Hexadecimal floats are exact float64 values. Decimal literals that are not
float64 numbers (``0.1``, ``-2.1``, ``12.4``) denote their *nearest* float64 number, on both sides
of ``=``: most vectors were converted from the C++ unit tests of libieeep1788, where such
literals were evidently C++ ``double`` constants, and the expected results were computed from
those doubles. The
files show it: ``mulRev [0.01, 1.1] [-2.1, -0.4] = [-0X1.A400000000001P+7, ...]`` is the tightest
lower bound of ``double(-2.1) / double(0.01)``; from the tightest enclosures of the decimals it
would be one ulp lower, and from the exact decimals it would be ``-210``. The test
``test_decimal_literals_denote_the_nearest_double`` checks this on every such mulRev vector.
``decimal_mode="outward"`` gives the other reading (tightest enclosure of each decimal bound,
inputs and expected results alike) for comparison only.

A few expected results in the files are wrong (not the tightest, so a correct tighter result
would look unsound): ``ERRATA`` lists them with the corrected result and the reason; the files
stay unchanged and the report counts the vectors concerned (``errata``).

Decorated vectors (``_com``/``_dac``/``_def``/``_trv`` suffixes, ``[nai]``, and every line of a
``*_dec*`` testcase, where bare-looking literals are decorated intervals repeating the bare
vectors) are counted as *skipped*: boundest has bare intervals only.
"""

from __future__ import annotations

import importlib
import json
import math
import os
import queue
import re
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections import defaultdict
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "ERRATA",
    "ITF_DIR",
    "OPS",
    "Ival",
    "Outcome",
    "Vector",
    "parse_all",
    "parse_file",
    "resolve",
    "run_all",
    "run_isolated",
    "run_op",
    "summarize",
]

ITF_DIR = Path(__file__).resolve().parent / "itf1788"

_MAX = float(np.finfo(np.float64).max)
_INF = math.inf
_NAN = math.nan

# classes of a sound enclosure, best first
CLASSES = ("tight", "within_1ulp", "within_4ulp", "looser")
# kinds of failures
FAILURES = ("unsound", "invalid", "mismatch", "error")


# =============================================================================================
# values
# =============================================================================================

@dataclass(frozen=True)
class Ival:
    """A bare interval literal: ``lo = hi = nan`` for the empty set."""

    lo: float
    hi: float

    @property
    def is_empty(self) -> bool:
        return math.isnan(self.lo)

    def __str__(self) -> str:
        if self.is_empty:
            return "[empty]"
        return f"[{_fmt(self.lo)}, {_fmt(self.hi)}]"


def _fmt(v: float) -> str:
    if math.isnan(v):
        return "nan"
    if math.isinf(v):
        return "infinity" if v > 0 else "-infinity"
    return v.hex() if v != int(v) or abs(v) > 2**53 else repr(v)


Value = Ival | float | int | bool | str

_HEX = re.compile(r"([+-]?)0x([0-9a-f]*)(?:\.([0-9a-f]*))?p([+-]?\d+)", re.IGNORECASE)
_DEC = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:e[+-]?\d+)?", re.IGNORECASE)
_INT = re.compile(r"[+-]?\d+")
_INFS = {"infinity": _INF, "+infinity": _INF, "-infinity": -_INF,
         "inf": _INF, "+inf": _INF, "-inf": -_INF}


def _exact(tok: str) -> Fraction | float:
    """The exact value of a number literal: a ``Fraction``, or ``+-inf``."""
    low = tok.lower()
    if low in _INFS:
        return _INFS[low]
    m = _HEX.fullmatch(tok)
    if m:
        sign, whole, frac, exp = m.groups()
        frac = frac or ""
        mant = int((whole or "0") + frac, 16)
        q = Fraction(mant) * Fraction(2) ** (int(exp) - 4 * len(frac))
        return -q if sign == "-" else q
    if _DEC.fullmatch(tok):
        return Fraction(tok)
    raise ValueError(f"not a number literal: {tok!r}")


def _float_nearest(q: Fraction) -> float:
    """Correctly rounded (ties to even) float64 of ``q``; overflow goes to ``+-inf``."""
    try:
        return float(q)  # int / int true division: correctly rounded in CPython
    except OverflowError:
        return _INF if q > 0 else -_INF


def _round(q: Fraction | float, mode: str) -> float:
    """``q`` as a float64: ``nearest``, ``down`` (largest float <= q) or ``up``."""
    if isinstance(q, float):
        return q
    f = _float_nearest(q)
    if mode == "nearest":
        return f
    if mode not in ("down", "up"):
        raise ValueError(f"unknown rounding mode {mode!r}")
    if math.isinf(f):  # |q| rounded to an infinity: q lies beyond MAX
        if mode == "down":
            return _MAX if f > 0 else f
        return f if f > 0 else -_MAX
    if mode == "down" and Fraction(f) > q:
        return float(np.nextafter(f, -_INF))
    if mode == "up" and Fraction(f) < q:
        return float(np.nextafter(f, _INF))
    return f


def _is_float(tok: str) -> bool:
    """Whether a number literal is exactly a float64 value (so its reading is unambiguous)."""
    q = _exact(tok)
    if isinstance(q, float):
        return True
    f = _float_nearest(q)
    return math.isfinite(f) and Fraction(f) == q


def _number(tok: str, mode: str) -> float:
    return _round(_exact(tok), mode)


def _interval(body: str, decimal_mode: str) -> Ival | None:
    """Parse the text between the brackets; ``None`` for ``[nai]``."""
    body = body.strip().lower()
    if body == "empty":
        return Ival(_NAN, _NAN)
    if body == "entire":
        return Ival(-_INF, _INF)
    if body == "nai":
        return None
    parts = [p.strip() for p in body.split(",")]
    if len(parts) == 1:  # a point interval [x]
        parts = parts * 2
    if len(parts) != 2:
        raise ValueError(f"bad interval literal [{body}]")
    lo_mode, hi_mode = ("down", "up") if decimal_mode == "outward" else ("nearest", "nearest")
    lo = _number(parts[0], lo_mode)
    hi = _number(parts[1], hi_mode)
    # IEEE 1788 intervals have no signed zeros; store +0 (bound comparisons ignore the sign)
    return Ival(lo + 0.0, hi + 0.0)


_TOKEN = re.compile(r"\[[^\]]*\](?:_[a-z]+)?|[^\s\[\]]+", re.IGNORECASE)


def _value(tok: str, decimal_mode: str) -> tuple[Value | None, bool, bool]:
    """``(value, decorated, exact)`` of one token."""
    if tok.startswith("["):
        body, _, deco = tok[1:].partition("]")
        decorated = bool(deco)
        iv = _interval(body, decimal_mode)
        exact = all(_is_float(p.strip()) for p in body.split(",")
                    if p.strip().lower() not in ("empty", "entire", "nai"))
        return iv, decorated or iv is None, exact
    low = tok.lower()
    if low in ("true", "false"):
        return low == "true", False, True
    if _INT.fullmatch(tok):
        return int(tok), False, True
    if low in _INFS or _HEX.fullmatch(tok) or _DEC.fullmatch(tok):
        return _number(tok, "nearest"), False, _is_float(tok)
    return tok, False, True  # a word such as an overlap state ("before")


# =============================================================================================
# parsing
# =============================================================================================

@dataclass(frozen=True)
class Vector:
    """One test vector: ``op args = expected`` at ``file:line``."""

    file: str
    line: int
    testcase: str
    op: str
    args: tuple[Value, ...]
    expected: tuple[Value, ...]
    decorated: bool
    exact: bool  # every literal is exactly a float64 number (no decimal rounding involved)
    text: str
    erratum: str = ""  # why ``expected`` differs from the file (see ERRATA)

    @property
    def where(self) -> str:
        return f"{self.file}:{self.line}"


_POW_REV_WHY = (
    "the file's result is not the tightest: for a in [0.25, 1[, a**y >= 2 iff "
    "y <= ln 2 / ln a, and ln 2 / ln a <= ln 2 / ln 0.25 = -0.5 (a = 1 gives 1**y = 1 < 2), "
    "so the hull is [-inf, -0.5], as the file's own vector with C = [2, 4] says")

#: Vectors whose expected result in the files is wrong (here: sound but not the tightest, so
#: a correct tighter result would be judged unsound). Keyed by (file, statement text); the
#: value is the corrected result and the reason. The files themselves stay unchanged.
ERRATA: dict[tuple[str, str], tuple[str, str]] = {
    ("pow_rev.itl", "powRev2 [0.25, 0.5] [2.0, infinity] [entire] = [entire]"):
        ("[-infinity, -0.5]", _POW_REV_WHY),
    ("pow_rev.itl", "powRev2 [0.25, 1.0] [2.0, infinity] [entire] = [-infinity, 0.0]"):
        ("[-infinity, -0.5]", _POW_REV_WHY),
    ("libieeep1788_tests_rev.itl",
     "cosRevBin [-1.0,-1.0] [3.14,3.15] = [0x1.921fb54442d18p+1,0x1.921fb54442d1ap+1]"):
        ("[0x1.921fb54442d18p+1, 0x1.921fb54442d19p+1]",
         "the file's upper bound is one ulp above the tightest: cos(x) = -1 on [3.14, 3.15] "
         "only at x = pi, and 0x1.921fb54442d18p+1 < pi < 0x1.921fb54442d19p+1"),
}


def _strip_comments(text: str) -> str:
    """Remove ``/* */`` and ``//`` comments, keeping the newlines (line numbers stay right)."""
    text = re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.DOTALL)
    return re.sub(r"//[^\n]*", "", text)


_TESTCASE = re.compile(r"testcase\s+([\w.]+)\s*\{(.*?)\}", re.DOTALL)


def parse_file(path: str | Path, decimal_mode: str = "nearest") -> list[Vector]:
    """All vectors of one ``.itl`` file (``decimal_mode``: ``nearest`` or ``outward``)."""
    if decimal_mode not in ("nearest", "outward"):
        raise ValueError(f"decimal_mode must be 'nearest' or 'outward', got {decimal_mode!r}")
    path = Path(path)
    text = _strip_comments(path.read_text())
    out: list[Vector] = []
    for tc in _TESTCASE.finditer(text):
        name, body = tc.group(1), tc.group(2)
        dec_case = "_dec" in name
        offset = tc.start(2)
        pos = 0
        for stmt in body.split(";"):
            start = pos + len(stmt) - len(stmt.lstrip())
            pos += len(stmt) + 1
            s = stmt.strip()
            if not s:
                continue
            line = text.count("\n", 0, offset + start) + 1
            toks = _TOKEN.findall(s)
            if "=" not in toks:
                raise ValueError(f"{path.name}:{line}: no '=' in {s!r}")
            k = toks.index("=")
            op, arg_toks, res_toks = toks[0], toks[1:k], toks[k + 1:]
            if not res_toks:
                raise ValueError(f"{path.name}:{line}: no result in {s!r}")
            decorated = dec_case
            exact = True
            vals: list[list[Value | None]] = [[], []]
            for side, group in enumerate((arg_toks, res_toks)):
                for t in group:
                    v, d, e = _value(t, decimal_mode)
                    decorated |= d
                    exact &= e
                    vals[side].append(v)
            stmt_text = " ".join(s.split())
            erratum = ""
            fix = ERRATA.get((path.name, stmt_text))
            if fix is not None:
                vals[1] = [_value(t, decimal_mode)[0] for t in _TOKEN.findall(fix[0])]
                erratum = f"expected {fix[0]} instead of {' '.join(res_toks)}: {fix[1]}"
            out.append(Vector(path.name, line, name, op, tuple(vals[0]), tuple(vals[1]),
                              decorated, exact, stmt_text, erratum))
    return out


def parse_all(directory: str | Path = ITF_DIR, decimal_mode: str = "nearest") -> list[Vector]:
    """All vectors of all ``.itl`` files in ``directory`` (sorted by file name)."""
    files = sorted(Path(directory).glob("*.itl"))
    if not files:
        raise FileNotFoundError(f"no .itl files in {directory}")
    return [v for f in files for v in parse_file(f, decimal_mode)]


# =============================================================================================
# boundest look-up
# =============================================================================================

# where a name is looked for: the package first, then the submodules (names that shadow
# builtins -- abs, min, max, pow -- are module attributes outside __all__)
_MODULES = ("boundest", "boundest.interval", "boundest.interval.algebraic",
            "boundest.interval.explog", "boundest.interval.trig", "boundest.interval.arith",
            "boundest.interval.core")


def resolve(name: str) -> Callable[..., Any] | None:
    """The boundest function called ``name``, or ``None`` when none exists (yet)."""
    for modname in _MODULES:
        try:
            mod = importlib.import_module(modname)
        except ImportError:
            continue
        fn = getattr(mod, name, None)
        # only boundest's own public functions: not a NumPy or builtin name a module imported,
        # nor a scalar Numba helper of rounding.py (e.g. its ``fma`` intrinsic)
        origin = getattr(fn, "__module__", None) or ""
        if callable(fn) and origin.startswith("boundest") and not origin.endswith(".rounding"):
            return fn
    return None


def _interval_cls():
    return importlib.import_module("boundest").Interval


# =============================================================================================
# the operation table
# =============================================================================================

@dataclass(frozen=True)
class Impl:
    """One way to run an ITF operation: the boundest names it needs and a call.

    ``call(f, *args)`` gets ``f`` (name -> resolved function) and the batched arguments:
    ``Interval`` arrays for interval arguments, float arrays for numbers, and a Python ``int``
    for integer arguments (vectors are grouped by them).
    """

    needs: tuple[str, ...]
    call: Callable[..., Any]
    note: str


@dataclass(frozen=True)
class OpSpec:
    kind: str  # "interval" | "pair" | "number" | "bool" | "word"
    impls: tuple[Impl, ...]  # tried in order; the first whose names all resolve is used
    number_mode: str = "exact"  # for kind "number": "exact" | "upper" (result >= expected)
    why_absent: str = ""  # reason printed when no implementation resolves

    def pick(self) -> tuple[Impl | None, dict[str, Callable[..., Any]], str]:
        missing: list[str] = []
        for impl in self.impls:
            fns = {n: resolve(n) for n in impl.needs}
            gone = [n for n, fn in fns.items() if fn is None]
            if not gone:
                return impl, fns, ""
            missing.extend(g for g in gone if g not in missing)
        why = self.why_absent or (
            "boundest has no " + " / ".join(missing) if missing else "no implementation")
        return None, {}, why


def _entire(n: int):
    return _interval_cls().entire(n)


def _u(name: str, note: str = "") -> OpSpec:
    """Unary forward operation ``f(x)``."""
    return OpSpec("interval", (Impl((name,), lambda f, x: f[name](x), note or f"{name}(x)"),))


def _b(name: str, note: str = "") -> OpSpec:
    """Binary forward operation ``f(x, y)``."""
    return OpSpec("interval",
                  (Impl((name,), lambda f, x, y: f[name](x, y), note or f"{name}(x, y)"),))


def _rev1(name: str) -> OpSpec:
    """``fRev c`` = ``f_rev(c, entire)`` (the unary reverse without a constraint on x)."""
    return OpSpec("interval", (Impl((name,), lambda f, c: f[name](c, _entire(c.size)),
                                    f"{name}(c, entire)"),))


def _rev2(name: str) -> OpSpec:
    """``fRevBin c x`` = ``f_rev(c, x)``."""
    return OpSpec("interval", (Impl((name,), lambda f, c, x: f[name](c, x), f"{name}(c, x)"),))


def _absent(kind: str, why: str, *names: str) -> OpSpec:
    """An operation boundest does not offer by design; still run if such a name appears."""
    return OpSpec(kind, tuple(Impl((n,), _call_named(n), f"{n}(...)") for n in names),
                  why_absent=why)


def _call_named(name: str) -> Callable[..., Any]:
    return lambda f, *args: f[name](*args)


def _fma_call(f, x, y, z):
    return f["fma"](x, y, z)


def _fma_emulated(f, x, y, z):
    return f["add"](f["mul"](x, y), z)


def _inf(f, x):
    # IEEE 1788 inf(empty) = +inf; boundest encodes the empty set as [nan, nan] (DESIGN.md),
    # so the harness maps its NaN lower bound of the empty set to +inf. Non-empty: x.lb().
    return np.where(x.is_empty(), _INF, x.lb())


def _sup(f, x):
    return np.where(x.is_empty(), -_INF, x.ub())


# Argument orders, from the files (and IEEE 1788-2015, section 10.5.4, for the reverse ones):
# * ``atan2 y x`` (atan2.itl: ``atan2 [0,0] [-inf,0] = [pi]``, y first);
# * ``pown x p`` / ``pow x y`` (elem.itl: ``pown [-2,-2] 3``, ``pow [0.1,0.5] [0,1]``);
# * ``fma x y z`` = x*y + z (elem.itl minimal_fma_test);
# * ``fRev c`` / ``fRevBin c x``: c the constraint on f(x), x the domain (rev.itl:
#   ``sqrRevBin [0,25] [-4.1,6] = [-4.1,5]``) -> boundest ``f_rev(c, x)``;
# * ``pownRev c p`` / ``pownRevBin c x p``: the integer exponent last (rev.itl
#   ``pownRevBin [1,1] [1,1] 0 = [1,1]``) -> ``pown_rev(c, x, p)``;
# * ``mulRev b c`` / ``mulRevTen b c x``: x' = hull{x in X : b*x in C for some b in B}
#   (rev.itl: ``mulRev [-2,-0.1] [-2.1,-0.4] = [0.2, 21]``, i.e. c/b) -> boundest
#   ``mul_rev(c, x, b)[0]`` with boundest's ``f_rev(z, x, y) -> (x', y')`` convention;
# * ``mulRevToPair b c``: the two parts of c/b (mul_rev.itl, same operand order as mulRev)
#   -> ``mul_rev_to_pair(c, b)`` (z first, as every boundest reverse operator);
# * ``powRev1 b c x``: x' = hull{x in X : x**b in C for some b in B} -> ``pow_rev(c, x, b)[0]``;
#   ``powRev2 a c y``: y' = hull{y in Y : a**y in C for some a in A} -> ``pow_rev(c, a, y)[1]``
#   (pow_rev.itl: ``powRev1 [entire] [entire] [entire] = [0, inf]``, the base is >= 0;
#   ``powRev2 [0,0] [-inf,-0.1] [entire] = [empty]``: 0**y is never negative).
OPS: dict[str, OpSpec] = {
    # --- forward, basic
    "pos": OpSpec("interval", (Impl((), lambda f, x: +x, "+x (Interval.__pos__)"),)),
    "neg": _u("neg"),
    "add": _b("add"),
    "sub": _b("sub"),
    "mul": _b("mul"),
    "div": _b("div"),
    "recip": _u("recip"),
    "sqr": _u("sqr"),
    "sqrt": _u("sqrt"),
    "fma": OpSpec("interval", (
        Impl(("fma",), _fma_call, "fma(x, y, z)"),
        Impl(("add", "mul"), _fma_emulated, "add(mul(x, y), z): emulated, sound, not tight"),
    )),
    # --- forward, elementary
    "pown": OpSpec("interval", (Impl(("pown",), lambda f, x, p: f["pown"](x, p), "pown(x, p)"),)),
    "pow": _b("pow"),
    **{n: _u(n) for n in ("exp", "exp2", "exp10", "log", "log2", "log10", "sin", "cos", "tan",
                          "asin", "acos", "atan", "sinh", "cosh", "tanh", "asinh", "acosh",
                          "atanh", "sign", "ceil", "floor", "trunc", "abs")},
    "atan2": _b("atan2", "atan2(y, x)"),
    "min": _b("min"),
    "max": _b("max"),
    "roundTiesToEven": _absent("interval", "not offered by boundest", "round_ties_to_even"),
    "roundTiesToAway": _absent("interval", "not offered by boundest", "round_ties_to_away"),
    # --- set operations
    "intersection": OpSpec("interval", (Impl((), lambda f, x, y: x & y, "x & y"),)),
    "convexHull": OpSpec("interval", (Impl((), lambda f, x, y: x | y, "x | y"),)),
    "cancelMinus": _absent("interval", "not offered by boundest", "cancel_minus"),
    "cancelPlus": _absent("interval", "not offered by boundest", "cancel_plus"),
    # --- numeric functions of intervals
    "inf": OpSpec("number", (Impl((), _inf, "x.lb() (empty -> +inf)"),)),
    "sup": OpSpec("number", (Impl((), _sup, "x.ub() (empty -> -inf)"),)),
    "mid": OpSpec("number", (Impl((), lambda f, x: x.mid(), "x.mid()"),)),
    "rad": OpSpec("number", (Impl((), lambda f, x: x.rad(), "x.rad()"),), number_mode="upper"),
    "wid": OpSpec("number", (Impl((), lambda f, x: x.width(), "x.width()"),),
                  number_mode="upper"),
    "mag": OpSpec("number", (Impl((), lambda f, x: x.mag(), "x.mag()"),)),
    "mig": OpSpec("number", (Impl((), lambda f, x: x.mig(), "x.mig()"),)),
    # --- boolean functions of intervals
    "isEmpty": OpSpec("bool", (Impl((), lambda f, x: x.is_empty(), "x.is_empty()"),)),
    "isEntire": OpSpec("bool", (Impl((), lambda f, x: x.is_entire(), "x.is_entire()"),)),
    "subset": OpSpec("bool", (Impl((), lambda f, a, b: a.is_subset(b), "a.is_subset(b)"),)),
    "equal": OpSpec("bool", (Impl((), lambda f, a, b: a == b, "a == b"),)),
    "interior": OpSpec("bool", (Impl((), lambda f, a, b: a.is_interior_subset(b),
                                     "a.is_interior_subset(b)"),)),
    "disjoint": OpSpec("bool", (Impl((), lambda f, a, b: ~a.intersects(b),
                                     "~a.intersects(b)"),)),
    "isMember": OpSpec("bool", (Impl((), lambda f, m, x: x.contains(m), "x.contains(m)"),)),
    "isSingleton": OpSpec("bool", (Impl((), lambda f, x: x.is_degenerate() & ~x.is_empty(),
                                        "x.is_degenerate() & ~x.is_empty()"),)),
    "isCommonInterval": OpSpec("bool", (Impl((), lambda f, x: x.is_bounded() & ~x.is_empty(),
                                             "x.is_bounded() & ~x.is_empty()"),)),
    "less": _absent("bool", "not offered by boundest (interval order relations)", "less"),
    "strictLess": _absent("bool", "not offered by boundest (interval order relations)",
                          "strict_less"),
    "precedes": _absent("bool", "not offered by boundest (interval order relations)",
                        "precedes"),
    "strictPrecedes": _absent("bool", "not offered by boundest (interval order relations)",
                              "strict_precedes"),
    "overlap": _absent("word", "not offered by boundest (interval overlapping states)",
                       "overlap"),
    "isNaI": _absent("bool", "decorated intervals only (boundest has bare intervals)"),
    # --- reverse operations
    **{f"{n}Rev": _rev1(f"{n}_rev") for n in ("sqr", "abs", "sin", "cos", "tan", "cosh")},
    **{f"{n}RevBin": _rev2(f"{n}_rev") for n in ("sqr", "abs", "sin", "cos", "tan", "cosh")},
    "pownRev": OpSpec("interval", (Impl(("pown_rev",), lambda f, c, p: f["pown_rev"](
        c, _entire(c.size), p), "pown_rev(c, entire, p)"),)),
    "pownRevBin": OpSpec("interval", (Impl(("pown_rev",), lambda f, c, x, p: f["pown_rev"](
        c, x, p), "pown_rev(c, x, p)"),)),
    "mulRev": OpSpec("interval", (Impl(("mul_rev",), lambda f, b, c: f["mul_rev"](
        c, _entire(c.size), b)[0], "mul_rev(c, entire, b)[0]"),)),
    "mulRevTen": OpSpec("interval", (Impl(("mul_rev",), lambda f, b, c, x: f["mul_rev"](
        c, x, b)[0], "mul_rev(c, x, b)[0]"),)),
    "mulRevToPair": OpSpec("pair", (Impl(("mul_rev_to_pair",), lambda f, b, c: f[
        "mul_rev_to_pair"](c, b), "mul_rev_to_pair(c, b)"),)),
    "powRev1": OpSpec("interval", (Impl(("pow_rev",), lambda f, b, c, x: f["pow_rev"](
        c, x, b)[0], "pow_rev(c, x, b)[0]"),)),
    "powRev2": OpSpec("interval", (Impl(("pow_rev",), lambda f, a, c, y: f["pow_rev"](
        c, a, y)[1], "pow_rev(c, a, y)[1]"),)),
}


# =============================================================================================
# running and classifying
# =============================================================================================

@dataclass
class Outcome:
    """The verdict on one vector: a class in ``CLASSES`` or a failure in ``FAILURES``."""

    vector: Vector
    status: str
    got: str = ""
    ulps: float = 0.0

    @property
    def failed(self) -> bool:
        return self.status in FAILURES

    def describe(self) -> str:
        v = self.vector
        fix = f" [erratum: {v.erratum.split(':')[0]}]" if v.erratum else ""
        return f"{v.where}: {v.text}{fix}  -> got {self.got} ({self.status})"


@dataclass
class OpResult:
    """All outcomes of one operation."""

    op: str
    vectors: int = 0  # all lines of this operation in the files
    skipped: int = 0  # decorated
    unimplemented: int = 0  # bare vectors not run: no boundest function
    reason: str = ""  # why unimplemented
    implementation: str = ""
    seconds: float = 0.0  # wall time of the run (Numba compilation included)
    note: str = ""  # e.g. how a crashed worker was recovered
    outcomes: list[Outcome] = field(default_factory=list)

    @property
    def failures(self) -> list[Outcome]:
        return [o for o in self.outcomes if o.failed]

    def counts(self) -> dict[str, Any]:
        c: dict[str, Any] = {
            "vectors": self.vectors, "skipped": self.skipped,
            "unimplemented": self.unimplemented, "run": len(self.outcomes),
            "sound_failures": len(self.failures),
            "errata": sum(bool(o.vector.erratum) for o in self.outcomes),
        }
        for k in (*CLASSES, *FAILURES):
            c[k] = sum(o.status == k for o in self.outcomes)
        # looser by an infinite distance (a half-line or the entire line where the tightest
        # result is bounded, non-empty for empty): a missed case rather than rounding slack
        c["looser_unbounded"] = sum(o.status == "looser" and math.isinf(o.ulps)
                                    for o in self.outcomes)
        finite = [o.ulps for o in self.outcomes if o.status in CLASSES and math.isfinite(o.ulps)]
        c["max_ulps"] = int(max(finite, default=0))  # largest finite distance, sound results
        return c


def _ordered(x: np.ndarray) -> np.ndarray:
    """Map float64 to int64 monotonically: consecutive floats map to consecutive integers,
    and -0.0 and +0.0 both map to 0 (so a difference counts ``np.nextafter`` steps)."""
    i = np.ascontiguousarray(x, dtype=np.float64).view(np.int64)
    return np.where(i < 0, -(i & np.int64(0x7FFFFFFFFFFFFFFF)), i)


def _steps(a: float, b: float) -> float:
    """Number of float64 steps from ``a`` to ``b`` (``>= 0`` when ``a <= b``; an infinite
    bound where a finite one is expected counts as infinitely many)."""
    if math.isinf(a) or math.isinf(b):
        return 0.0 if a == b else _INF
    return float(int(_ordered(np.array([b]))[0]) - int(_ordered(np.array([a]))[0]))


def _class(ulps: float) -> str:
    if ulps == 0:
        return "tight"
    if ulps <= 1:
        return "within_1ulp"
    if ulps <= 4:
        return "within_4ulp"
    return "looser"


def _valid(lo: float, hi: float) -> bool:
    if math.isnan(lo) or math.isnan(hi):
        return math.isnan(lo) and math.isnan(hi)
    return lo <= hi and lo != _INF and hi != -_INF


def _show(lo: float, hi: float) -> str:
    if math.isnan(lo) and math.isnan(hi):
        return "[empty]"
    return f"[{_fmt(lo)}, {_fmt(hi)}]"


def _judge_interval(exp: Ival, lo: float, hi: float) -> tuple[str, float]:
    """``(status, ulps)`` of the result ``[lo, hi]`` against the tightest ``exp``."""
    if not _valid(lo, hi):
        return "invalid", _INF
    r_empty = math.isnan(lo)
    if exp.is_empty:
        return ("tight", 0.0) if r_empty else ("looser", _INF)
    if r_empty or lo > exp.lo or hi < exp.hi:
        return "unsound", _INF
    ulps = max(_steps(lo, exp.lo), _steps(exp.hi, hi))
    return _class(ulps), ulps


def _contained_in_union(e: Ival, r1: tuple[float, float], r2: tuple[float, float]) -> bool:
    if e.is_empty:
        return True
    parts = [r for r in (r1, r2) if not math.isnan(r[0])]
    for lo, hi in parts:
        if lo <= e.lo and e.hi <= hi:
            return True
    if len(parts) == 2:
        (a, b), (c, d) = sorted(parts)
        if c <= b:  # overlapping or touching: the union is one interval
            return a <= e.lo and e.hi <= max(b, d)
    return False


def _judge_pair(exp: Sequence[Ival], got: Sequence[tuple[float, float]]) -> tuple[str, float]:
    if not all(_valid(*g) for g in got):
        return "invalid", _INF
    if not all(_contained_in_union(e, got[0], got[1]) for e in exp):
        return "unsound", _INF
    best = _INF
    for order in (got, got[::-1]):  # either order of the two parts
        worst = 0.0
        for e, (lo, hi) in zip(exp, order, strict=True):
            st, u = _judge_interval(e, lo, hi)
            worst = max(worst, u if st in CLASSES else _INF)
        best = min(best, worst)
    return _class(best), best


def _judge_number(exp: float, r: float, mode: str) -> tuple[str, float]:
    if math.isnan(exp) or math.isnan(r):
        return ("tight", 0.0) if math.isnan(exp) and math.isnan(r) else ("mismatch", _INF)
    if r == exp:
        return "tight", 0.0
    if mode == "upper" and r > exp:
        u = _steps(exp, r)
        return _class(u), u
    return "mismatch", _INF


def _as_bounds(res: Any, n: int) -> tuple[np.ndarray, np.ndarray]:
    lo = np.broadcast_to(np.asarray(res.lo, dtype=np.float64), (n,))
    hi = np.broadcast_to(np.asarray(res.hi, dtype=np.float64), (n,))
    return lo, hi


def _batch_args(vecs: Sequence[Vector]) -> list[Any]:
    """Per argument position: an ``Interval`` array, a float array, or the common int."""
    interval = _interval_cls()
    out: list[Any] = []
    for k, first in enumerate(vecs[0].args):
        col = [v.args[k] for v in vecs]
        if isinstance(first, Ival):
            lo = np.array([a.lo for a in col], dtype=np.float64)
            hi = np.array([a.hi for a in col], dtype=np.float64)
            out.append(interval.trusted(lo, hi))
        elif isinstance(first, (bool, str)):
            raise TypeError(f"unsupported argument {first!r}")
        elif isinstance(first, int):
            out.append(first)  # grouped: identical in the batch
        else:
            out.append(np.array(col, dtype=np.float64))
    return out


def _signature(v: Vector) -> tuple[Any, ...]:
    """Batching key: argument kinds, and the value of integer arguments (pown's p)."""
    key: list[Any] = []
    for a in v.args:
        if isinstance(a, Ival):
            key.append("I")
        elif isinstance(a, bool):
            key.append(("b", a))
        elif isinstance(a, int):
            key.append(("i", a))
        elif isinstance(a, float):
            key.append("f")
        else:
            key.append(("w", a))
    return tuple(key)


def _judge_batch(spec: OpSpec, vecs: Sequence[Vector], res: Any) -> list[Outcome]:
    n = len(vecs)
    outs: list[Outcome] = []
    if spec.kind == "interval":
        lo, hi = _as_bounds(res, n)
        for v, a, b in zip(vecs, lo, hi, strict=True):
            st, u = _judge_interval(v.expected[0], float(a), float(b))
            outs.append(Outcome(v, st, _show(float(a), float(b)), u))
    elif spec.kind == "pair":
        (lo1, hi1), (lo2, hi2) = _as_bounds(res[0], n), _as_bounds(res[1], n)
        for i, v in enumerate(vecs):
            got = ((float(lo1[i]), float(hi1[i])), (float(lo2[i]), float(hi2[i])))
            st, u = _judge_pair(v.expected, got)
            outs.append(Outcome(v, st, " ".join(_show(*g) for g in got), u))
    elif spec.kind == "number":
        r = np.broadcast_to(np.asarray(res, dtype=np.float64), (n,))
        for v, x in zip(vecs, r, strict=True):
            exp = float(v.expected[0])
            st, u = _judge_number(exp, float(x), spec.number_mode)
            outs.append(Outcome(v, st, _fmt(float(x)), u))
    elif spec.kind == "bool":
        r = np.broadcast_to(np.asarray(res, dtype=bool), (n,))
        for v, x in zip(vecs, r, strict=True):
            ok = bool(x) == v.expected[0]
            outs.append(Outcome(v, "tight" if ok else "mismatch", str(bool(x)).lower()))
    else:  # "word"
        r = np.broadcast_to(np.asarray(res, dtype=object), (n,))
        for v, x in zip(vecs, r, strict=True):
            ok = str(x) == v.expected[0]
            outs.append(Outcome(v, "tight" if ok else "mismatch", str(x)))
    return outs


class _UnimplementedError(Exception):
    pass


def _call(impl: Impl, fns: dict[str, Callable[..., Any]], args: list[Any]) -> Any:
    try:
        with np.errstate(all="ignore"):
            return impl.call(fns, *args)
    except NotImplementedError as exc:
        raise _UnimplementedError(str(exc) or "NotImplementedError") from exc


def _run_group(spec: OpSpec, impl: Impl, fns: dict[str, Callable[..., Any]],
               vecs: Sequence[Vector]) -> list[Outcome]:
    """One batched call; when it raises, one call per vector pins the error down."""
    try:
        return _judge_batch(spec, vecs, _call(impl, fns, _batch_args(vecs)))
    except _UnimplementedError:
        raise
    except Exception:  # retried vector by vector below
        pass
    outs: list[Outcome] = []
    for v in vecs:
        try:
            outs.extend(_judge_batch(spec, [v], _call(impl, fns, _batch_args([v]))))
        except _UnimplementedError:
            raise
        except Exception as exc:  # recorded against the vector
            outs.append(Outcome(v, "error", f"{type(exc).__name__}: {exc}", _INF))
    return outs


def run_op(op: str, vecs: Sequence[Vector]) -> OpResult:
    """Run all vectors of operation ``op`` (decorated ones are counted and skipped)."""
    result = OpResult(op, vectors=len(vecs))
    bare = [v for v in vecs if not v.decorated]
    result.skipped = len(vecs) - len(bare)
    spec = OPS.get(op)
    if spec is None:
        result.unimplemented, result.reason = len(bare), "operation unknown to the harness"
        return result
    impl, fns, why = spec.pick()
    if impl is None:
        result.unimplemented, result.reason = len(bare), why
        return result
    result.implementation = impl.note
    groups: dict[tuple[Any, ...], list[Vector]] = defaultdict(list)
    for v in bare:
        groups[_signature(v)].append(v)
    t0 = time.perf_counter()
    try:
        for key in sorted(groups, key=repr):
            result.outcomes.extend(_run_group(spec, impl, fns, groups[key]))
    except _UnimplementedError as exc:
        result.outcomes.clear()
        result.unimplemented, result.reason = len(bare), f"raises NotImplementedError: {exc}"
    result.seconds = time.perf_counter() - t0
    result.outcomes.sort(key=lambda o: (o.vector.file, o.vector.line))
    return result


def run_all(vectors: Iterable[Vector] | None = None) -> dict[str, OpResult]:
    """Run every operation found in ``vectors`` (default: all vendored files)."""
    by_op: dict[str, list[Vector]] = defaultdict(list)
    for v in parse_all() if vectors is None else vectors:
        by_op[v.op].append(v)
    return {op: run_op(op, by_op[op]) for op in sorted(by_op)}


def summarize(results: dict[str, OpResult], max_failures: int = 10) -> dict[str, Any]:
    """A JSON-ready report: per operation and in total."""
    ops: dict[str, Any] = {}
    total: dict[str, float] = defaultdict(int)
    for op, r in results.items():
        c = r.counts()
        for k, val in c.items():
            total[k] = max(total[k], val) if k == "max_ulps" else total[k] + val
        total["seconds"] += r.seconds
        entry: dict[str, Any] = dict(c)
        if r.implementation:
            entry["implementation"] = r.implementation
        if r.reason:
            entry["reason"] = r.reason
        if r.note:
            entry["note"] = r.note
        entry["seconds"] = round(r.seconds, 3)
        if r.failures:
            entry["failing"] = [o.describe() for o in r.failures[:max_failures]]
        ops[op] = entry
    status = {
        "implemented": sorted(op for op, r in results.items() if r.outcomes),
        "unimplemented": sorted(op for op, r in results.items()
                                if r.unimplemented and not r.outcomes),
        "decorated_only": sorted(op for op, r in results.items()
                                 if r.vectors == r.skipped),
    }
    tot = dict(total)
    tot["seconds"] = round(tot.get("seconds", 0.0), 3)
    return {"total": tot, "operations": ops, **status}


# =============================================================================================
# running in a worker process (a crash or a hang of one kernel costs one operation, not all)
# =============================================================================================

_MARK = "@@ITF1788 "


def _child_main(argv: Sequence[str]) -> int:
    """Worker: ``itf1788_runner.py --child DIR MODE OP...``; one JSON line per event."""
    directory, mode, *ops = argv
    by_op: dict[str, list[Vector]] = defaultdict(list)
    for v in parse_all(directory, decimal_mode=mode):
        by_op[v.op].append(v)
    out = sys.stdout
    for op in ops:
        out.write(_MARK + json.dumps({"start": op}) + "\n")
        out.flush()
        r = run_op(op, by_op.get(op, []))
        msg = {"op": op, "seconds": r.seconds, "vectors": r.vectors, "skipped": r.skipped,
               "unimplemented": r.unimplemented, "reason": r.reason,
               "implementation": r.implementation,
               "outcomes": [[o.vector.file, o.vector.line, o.vector.text, o.status, o.got, o.ulps]
                            for o in r.outcomes]}
        out.write(_MARK + json.dumps(msg) + "\n")
        out.flush()
    return 0


def _rebuild(msg: dict[str, Any], index: dict[tuple[str, int, str], Vector]) -> OpResult:
    r = OpResult(msg["op"], msg["vectors"], msg["skipped"], msg["unimplemented"], msg["reason"],
                 msg["implementation"], seconds=msg["seconds"])
    r.outcomes = [Outcome(index[(f, line, text)], st, got, ulps)
                  for f, line, text, st, got, ulps in msg["outcomes"]]
    return r


def _died(op: str, vecs: Sequence[Vector], why: str) -> OpResult:
    """Every bare vector of ``op`` counts as an error: the worker died running it."""
    bare = [v for v in vecs if not v.decorated]
    spec = OPS.get(op)
    impl = spec.pick()[0] if spec is not None else None
    r = OpResult(op, len(vecs), len(vecs) - len(bare),
                 implementation=impl.note if impl is not None else "")
    r.outcomes = [Outcome(v, "error", why, _INF) for v in bare]
    return r


def _describe_exit(rc: int | None) -> str:
    if rc is not None and rc < 0:
        try:
            return f"worker process killed by {signal.Signals(-rc).name}"
        except ValueError:
            return f"worker process killed by signal {-rc}"
    return f"worker process exited with status {rc}"


def _worker(directory: str | Path, decimal_mode: str, todo: Sequence[str], env: dict[str, str],
            op_timeout: float, index: dict[tuple[str, int, str], Vector]
            ) -> tuple[dict[str, OpResult], tuple[str, str, bool] | None]:
    """Run ``todo`` in one worker: the results it delivered, and ``(op, why, timed_out)`` for
    the operation it died on (``None`` when it finished)."""
    results: dict[str, OpResult] = {}
    with tempfile.TemporaryFile("w+") as err:
        proc = subprocess.Popen(
            [sys.executable, str(Path(__file__).resolve()), "--child", str(directory),
             decimal_mode, *todo],
            stdout=subprocess.PIPE, stderr=err, text=True, env=env)
        lines: queue.Queue[str | None] = queue.Queue()

        def pump(stream=proc.stdout, sink=lines) -> None:
            for line in stream:
                sink.put(line)
            sink.put(None)

        threading.Thread(target=pump, daemon=True).start()
        current: str | None = None
        death: tuple[str, bool] | None = None
        while True:
            try:
                line = lines.get(timeout=op_timeout)
            except queue.Empty:
                proc.kill()
                proc.wait()
                death = (f"timed out after {op_timeout:g} s", True)
                break
            if line is None:
                rc = proc.wait()
                if rc != 0 or current is not None:
                    death = (_describe_exit(rc), False)
                break
            if line.startswith(_MARK):
                msg = json.loads(line[len(_MARK):])
                if "start" in msg:
                    current = msg["start"]
                else:
                    results[msg["op"]] = _rebuild(msg, index)
                    current = None
        if death is None:
            return results, None
        if current is None:
            if all(op in results for op in todo):  # died on the way out: results complete
                return results, None
            err.seek(0)  # died outside any operation: nothing to blame, give up
            raise RuntimeError(f"ITF1788 worker failed ({death[0]}):\n{err.read()[-3000:]}")
        return results, (current, death[0], death[1])


def run_isolated(directory: str | Path = ITF_DIR, decimal_mode: str = "nearest",
                 ops: Sequence[str] | None = None, op_timeout: float = 300.0,
                 retry_crashes: bool = True) -> dict[str, OpResult]:
    """Like :func:`run_all`, but in a worker process.

    When the worker dies on an operation (a segmentation fault in a kernel), that operation is
    tried once more alone with an empty private Numba cache (``NUMBA_CACHE_DIR``): stale cached
    kernels compiled against an older ``rounding.py`` are a known cause of such crashes, as the
    cache is keyed on the kernel's own file only. If it dies again, or takes longer than
    ``op_timeout`` seconds, all its bare vectors count as errors. A new worker goes on with the
    remaining operations.
    """
    vecs = parse_all(directory, decimal_mode)
    by_op: dict[str, list[Vector]] = defaultdict(list)
    for v in vecs:
        by_op[v.op].append(v)
    index = {(v.file, v.line, v.text): v for v in vecs}
    todo = sorted(by_op) if ops is None else list(ops)
    results: dict[str, OpResult] = {}
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p and Path(p).is_dir())
    while todo:
        done, death = _worker(directory, decimal_mode, todo, env, op_timeout, index)
        results.update(done)
        if death is not None:
            op, why, timed_out = death
            if retry_crashes and not timed_out:
                with tempfile.TemporaryDirectory() as cache:
                    again, death2 = _worker(directory, decimal_mode, [op],
                                            {**env, "NUMBA_CACHE_DIR": cache}, op_timeout, index)
                if op in again:
                    results[op] = again[op]
                    results[op].note = (f"first run: {why}; passed when rerun with a fresh "
                                        "Numba cache (so most likely stale cached kernels)")
                else:
                    assert death2 is not None
                    results[op] = _died(op, by_op[op], f"{why}; again with a fresh Numba "
                                                        f"cache: {death2[1]}")
            else:
                results[op] = _died(op, by_op[op], why)
        todo = [op for op in todo if op not in results]
    return {op: results[op] for op in sorted(results)}


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        sys.exit(_child_main(sys.argv[2:]))
    sys.exit("usage: run benchmarks/itf1788_report.py (this module is a library)")
