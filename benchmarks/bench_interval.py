"""Interval-layer benchmark: boundest's forward and backward operators, element by element.

For each operator and array size it reports the median cost in nanoseconds per element of

* ``boundest``      the boundest function (fresh output arrays), and ``boundest_out`` with ``out=``
                    buffers where the function accepts them;
* ``numpy_floor``   the plain float64 NumPy operation on points (``np.add``, ``np.sin``, ...; for a
                    backward operator its plain inverse, e.g. ``np.divide`` for ``mul_rev``): no
                    interval library can be cheaper than this;
* ``naive_numpy``   (add and mul only) a pure-NumPy interval implementation widened with
                    ``np.nextafter``: what boundest would cost without Numba;
* ``crival``        crival's vectorized ``ival`` module, when importable (tight, C via ctypes);
* ``codac``         Codac 2.x ``Interval`` objects in a Python loop, when importable (at most
                    ``--codac-n`` elements per loop, never at the largest sizes; per element).

Importing codac switches the FPU to rounding upward (Gaol); the benchmark puts round-to-nearest
back after the import and after every codac loop (see benchmarks/README.md).

The first call of each boundest function (Numba compilation, or loading its on-disk cache) is
timed separately (``first_call_s``) in a fresh child process, which also shields the benchmark
from a kernel that crashes the interpreter (reported as ``crashed``); the measured calls come
after a warm-up call. Inputs are random intervals of moderate width; divisors are bounded away
from 0 except in ``div_zero``.
As a sanity check, where crival has the same operation, the number of elements on which the
boundest result does not contain crival's (tight) one is reported (``check``).

Boundest functions are resolved by name on ``boundest``, ``boundest.interval`` and its
submodules, so operators that are not written yet are skipped with a note.

Usage::

    .bench-venv/bin/python benchmarks/bench_interval.py [--quick] [--sizes 1e3,1e5,1e6]
        [--ops add,mul,sin_rev] [--repeat 7] [--out results.json] [--cold]

JSON goes to stdout (and to ``--out``); progress goes to stderr.
"""

from __future__ import annotations

import argparse
import ctypes
import ctypes.util
import gc
import importlib
import inspect
import json
import os
import platform
import shutil
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from _machine import cpu_model

# ----------------------------------------------------------------------------------------------
# input domains: each maps (rng, n) to the bounds (lo, hi) of n random intervals


def _centred(c: tuple[float, float], r: tuple[float, float]) -> Callable:
    def gen(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
        mid = rng.uniform(*c, n)
        rad = rng.uniform(*r, n)
        return mid - rad, mid + rad
    return gen


def _from_lo(lo: tuple[float, float], w: tuple[float, float]) -> Callable:
    def gen(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
        a = rng.uniform(*lo, n)
        return a, a + rng.uniform(*w, n)
    return gen


def _divisor(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    """|centre| in [1, 10], radius <= 0.5: never contains 0."""
    mid = rng.choice([-1.0, 1.0], n) * rng.uniform(1.0, 10.0, n)
    rad = rng.uniform(0.0, 0.5, n)
    return mid - rad, mid + rad


def _zero_divisor(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Every divisor contains 0: 80 % strictly inside, 10 % [0, b], 10 % [a, 0]."""
    lo = -rng.uniform(0.1, 2.0, n)
    hi = rng.uniform(0.1, 2.0, n)
    u = rng.uniform(size=n)
    lo[u < 0.1] = 0.0
    hi[u > 0.9] = 0.0
    return lo, hi


GEN = _centred((-10.0, 10.0), (0.0, 1.0))      # generic operand
POS = _from_lo((0.01, 100.0), (0.0, 1.0))      # sqrt, log
EXPD = _centred((-20.0, 20.0), (0.0, 1.0))     # exp
TRIG = _centred((-10.0, 10.0), (0.05, 0.5))    # sin/cos/tan: widths 0.1-1
WTRIG = _centred((-10.0, 10.0), (0.5, 3.0))    # domains of sin_rev/cos_rev: widths 1-6
UNIT = _centred((-0.9, 0.9), (0.0, 0.1))       # asin/acos
HYP = _centred((-5.0, 5.0), (0.0, 0.5))        # sinh/cosh/tanh
PBASE = _from_lo((0.1, 10.0), (0.0, 0.5))      # pow base
PEXP = _centred((-3.0, 3.0), (0.0, 0.5))       # pow exponent


# ----------------------------------------------------------------------------------------------
# the operator table


@dataclass
class Case:
    """One benchmark case.

    ``doms`` generate the interval operands (forward: the arguments; backward: the domains X, Y
    of ``f_rev(Z, X, Y)``); ``point`` is the plain function on points, used for backward cases to
    build a consistent Z around ``f(x, y)`` for points x in X, y in Y; ``floor(*points)`` is the
    float64 NumPy floor, evaluated on points (forward: the operand points; backward: z first).
    """

    name: str
    kind: str                     # "forward" or "backward"
    func: str                     # boundest function name
    doms: tuple
    floor: Callable
    floor_label: str
    point: Callable | None = None
    extra: tuple = ()             # extra scalar arguments (pown's exponent)
    crival: Callable | None = None
    codac: Callable | None = None
    note: str = ""
    clip: tuple[float, float] | None = None   # range of f, to keep Z realistic
    results: dict = field(default_factory=dict)


def _fwd(name: str, doms: tuple, floor: Callable, label: str, func: str | None = None,
         **kw: Any) -> Case:
    return Case(name, "forward", func or name, doms, floor, label, **kw)


def _bwd(name: str, doms: tuple, point: Callable, floor: Callable, label: str,
         **kw: Any) -> Case:
    return Case(name, "backward", name, doms, floor, label, point=point, **kw)


def _cases(iv: Any, cd: Any) -> list[Case]:
    """The table; ``iv`` is crival's ``ival`` module (or None), ``cd`` codac (or None)."""
    c = iv is not None
    d = cd is not None

    def cr(fn: Callable) -> Callable | None:
        return fn if c else None

    def co(fn: Callable) -> Callable | None:
        return fn if d else None

    def cop(op: str) -> Callable | None:   # codac XxxOp.fwd, cheaper than the operators
        return getattr(cd, op).fwd if d else None

    def cob(op: str) -> Callable | None:   # codac XxxOp.bwd(z, x[, y]): contracts x, y in place
        return getattr(cd, op).bwd if d else None

    inf = np.inf
    return [
        # -- forward ------------------------------------------------------------------------
        _fwd("add", (GEN, GEN), np.add, "np.add", crival=cr(lambda x, y: x + y),
             codac=cop("AddOp")),
        _fwd("sub", (GEN, GEN), np.subtract, "np.subtract", crival=cr(lambda x, y: x - y),
             codac=cop("SubOp")),
        _fwd("mul", (GEN, GEN), np.multiply, "np.multiply", crival=cr(lambda x, y: x * y),
             codac=cop("MulOp")),
        _fwd("div", (GEN, _divisor), np.divide, "np.divide", crival=cr(lambda x, y: x / y),
             codac=cop("DivOp")),
        _fwd("div_zero", (GEN, _zero_divisor), np.divide, "np.divide", func="div",
             crival=cr(lambda x, y: x / y), codac=cop("DivOp"),
             note="every divisor contains 0 (10 % [0, b], 10 % [a, 0])"),
        _fwd("sqr", (GEN,), np.square, "np.square", crival=cr(lambda x: iv.sqr(x)),
             codac=cop("SqrOp")),
        _fwd("sqrt", (POS,), np.sqrt, "np.sqrt", crival=cr(lambda x: iv.sqrt(x)),
             codac=cop("SqrtOp")),
        _fwd("exp", (EXPD,), np.exp, "np.exp", crival=cr(lambda x: iv.exp(x)),
             codac=cop("ExpOp")),
        _fwd("log", (POS,), np.log, "np.log", crival=cr(lambda x: iv.log(x)),
             codac=cop("LogOp")),
        _fwd("sin", (TRIG,), np.sin, "np.sin", crival=cr(lambda x: iv.sin(x)),
             codac=cop("SinOp")),
        _fwd("cos", (TRIG,), np.cos, "np.cos", crival=cr(lambda x: iv.cos(x)),
             codac=cop("CosOp")),
        _fwd("tan", (TRIG,), np.tan, "np.tan", crival=cr(lambda x: iv.tan(x)),
             codac=cop("TanOp"), note="about 18 % of the inputs contain a pole"),
        _fwd("asin", (UNIT,), np.arcsin, "np.arcsin", crival=cr(lambda x: iv.asin(x)),
             codac=cop("AsinOp")),
        _fwd("acos", (UNIT,), np.arccos, "np.arccos", crival=cr(lambda x: iv.acos(x)),
             codac=cop("AcosOp")),
        _fwd("atan", (GEN,), np.arctan, "np.arctan", crival=cr(lambda x: iv.atan(x)),
             codac=cop("AtanOp")),
        _fwd("atan2", (GEN, GEN), np.arctan2, "np.arctan2",
             crival=cr(lambda y, x: iv.atan2(y, x)), codac=cop("Atan2Op"),
             note="atan2(y, x), IEEE 1788 argument order"),
        _fwd("sinh", (HYP,), np.sinh, "np.sinh", crival=cr(lambda x: iv.sinh(x)),
             codac=cop("SinhOp")),
        _fwd("cosh", (HYP,), np.cosh, "np.cosh", crival=cr(lambda x: iv.cosh(x)),
             codac=cop("CoshOp")),
        _fwd("tanh", (HYP,), np.tanh, "np.tanh", crival=cr(lambda x: iv.tanh(x)),
             codac=cop("TanhOp")),
        _fwd("pow", (PBASE, PEXP), np.power, "np.power", crival=cr(lambda x, y: iv.pow(x, y)),
             codac=cop("PowOp"), note="real exponent: an interval; the base is positive"),
        _fwd("pown", (GEN,), lambda x: x * x * x, "x * x * x", extra=(3,),
             crival=cr(lambda x: iv.pown(x, 3)), codac=co(lambda x: cd.pow(x, 3)),
             note="integer exponent 3; floor x*x*x (np.power(x, 3) takes ~45 ns with "
                  "negative bases)"),
        _fwd("abs", (GEN,), np.abs, "np.abs", crival=cr(lambda x: abs(x)),
             codac=cop("AbsOp")),
        _fwd("min", (GEN, GEN), np.minimum, "np.minimum",
             crival=cr(lambda x, y: iv.min(x, y)), codac=cop("MinOp")),
        _fwd("max", (GEN, GEN), np.maximum, "np.maximum",
             crival=cr(lambda x, y: iv.max(x, y)), codac=cop("MaxOp")),
        _fwd("sign", (GEN,), np.sign, "np.sign", crival=cr(lambda x: iv.sign(x)),
             codac=cop("SignOp")),
        _fwd("floor", (GEN,), np.floor, "np.floor", crival=cr(lambda x: iv.floor(x)),
             codac=cop("FloorOp")),
        _fwd("ceil", (GEN,), np.ceil, "np.ceil", crival=cr(lambda x: iv.ceil(x)),
             codac=cop("CeilOp")),
        # -- backward: f_rev(z, x[, y]); crival entries return the same projections -----------
        _bwd("add_rev", (GEN, GEN), np.add, lambda z, _x, y: np.subtract(z, y), "np.subtract",
             crival=cr(lambda z, x, y: ((z - y) & x, (z - x) & y)), codac=cob("AddOp"),
             note="crival: (Z - Y) & X, (Z - X) & Y"),
        _bwd("sub_rev", (GEN, GEN), np.subtract, lambda z, _x, y: np.add(z, y), "np.add",
             crival=cr(lambda z, x, y: ((z + y) & x, (x - z) & y)), codac=cob("SubOp"),
             note="crival: (Z + Y) & X, (X - Z) & Y"),
        _bwd("mul_rev", (GEN, GEN), np.multiply, lambda z, _x, y: np.divide(z, y), "np.divide",
             crival=cr(lambda z, x, y: (iv.mulrev(y, z, x), iv.mulrev(x, z, y))),
             codac=cob("MulOp"), note="Y (and X) contain 0 in about 5 % of the cases; "
                                      "crival: mulrev twice"),
        _bwd("div_rev", (GEN, _divisor), np.divide, lambda z, _x, y: np.multiply(z, y),
             "np.multiply", crival=cr(lambda z, x, y: ((z * y) & x, iv.mulrev(z, x, y))),
             codac=cob("DivOp"), note="crival: (Z * Y) & X, mulrev(Z, X, Y)"),
        _bwd("sqr_rev", (GEN,), np.square, lambda z, _x: np.sqrt(z), "np.sqrt",
             crival=cr(lambda z, x: iv.sqrrev(z, x)), codac=cob("SqrOp"), clip=(0.0, inf)),
        _bwd("sqrt_rev", (POS,), np.sqrt, lambda z, _x: np.square(z), "np.square",
             crival=cr(lambda z, x: iv.sqr(z & iv.Interval(0.0, inf)) & x),
             codac=cob("SqrtOp"), clip=(0.0, inf), note="crival: sqr(Z & [0, inf]) & X"),
        _bwd("abs_rev", (GEN,), np.abs, lambda z, _x: np.negative(z), "np.negative",
             crival=cr(lambda z, x: iv.absrev(z, x)), codac=cob("AbsOp"), clip=(0.0, inf)),
        _bwd("exp_rev", (EXPD,), np.exp, lambda z, _x: np.log(z), "np.log",
             crival=cr(lambda z, x: iv.log(z) & x), codac=cob("ExpOp"), clip=(0.0, inf),
             note="crival: log(Z) & X"),
        _bwd("log_rev", (POS,), np.log, lambda z, _x: np.exp(z), "np.exp",
             crival=cr(lambda z, x: iv.exp(z) & x), codac=cob("LogOp"),
             note="crival: exp(Z) & X"),
        _bwd("sin_rev", (WTRIG,), np.sin, lambda z, _x: np.arcsin(z), "np.arcsin",
             crival=cr(lambda z, x: iv.sinrev(z, x)), codac=cob("SinOp"), clip=(-1.0, 1.0),
             note="domains of width 1-6"),
        _bwd("cos_rev", (WTRIG,), np.cos, lambda z, _x: np.arccos(z), "np.arccos",
             crival=cr(lambda z, x: iv.cosrev(z, x)), codac=cob("CosOp"), clip=(-1.0, 1.0),
             note="domains of width 1-6"),
        _bwd("tan_rev", (TRIG,), np.tan, lambda z, _x: np.arctan(z), "np.arctan",
             crival=cr(lambda z, x: iv.tanrev(z, x)), codac=cob("TanOp")),
        _bwd("asin_rev", (UNIT,), np.arcsin, lambda z, _x: np.sin(z), "np.sin",
             codac=cob("AsinOp")),
        _bwd("acos_rev", (UNIT,), np.arccos, lambda z, _x: np.cos(z), "np.cos",
             codac=cob("AcosOp")),
        _bwd("atan_rev", (GEN,), np.arctan, lambda z, _x: np.tan(z), "np.tan",
             codac=cob("AtanOp")),
        _bwd("atan2_rev", (GEN, GEN), np.arctan2, lambda _z, y, x: np.arctan2(y, x),
             "np.arctan2 (forward)", codac=cob("Atan2Op"),
             note="atan2_rev(z, y, x) -> (y', x')"),
        _bwd("sinh_rev", (HYP,), np.sinh, lambda z, _x: np.arcsinh(z), "np.arcsinh",
             crival=cr(lambda z, x: iv.asinh(z) & x), codac=cob("SinhOp"),
             note="crival: asinh(Z) & X"),
        _bwd("cosh_rev", (HYP,), np.cosh, lambda z, _x: np.arccosh(z), "np.arccosh",
             crival=cr(lambda z, x: iv.coshrev(z, x)), codac=cob("CoshOp"), clip=(1.0, inf)),
        _bwd("tanh_rev", (HYP,), np.tanh, lambda z, _x: np.arctanh(z), "np.arctanh",
             crival=cr(lambda z, x: iv.atanh(z) & x), codac=cob("TanhOp"), clip=(-1.0, 1.0),
             note="crival: atanh(Z) & X"),
        _bwd("pow_rev", (PBASE, PEXP), np.power, lambda z, _x, y: np.power(z, y), "np.power",
             crival=cr(lambda z, x, y: (iv.powrev1(y, z, x), iv.powrev2(x, z, y))),
             codac=cob("PowOp"), clip=(0.0, inf), note="crival: powrev1 and powrev2"),
        _bwd("pown_rev", (GEN,), lambda x: np.power(x, 3), lambda z, _x: np.cbrt(z), "np.cbrt",
             extra=(3,), crival=cr(lambda z, x: iv.pownrev(z, 3, x)),
             codac=co(lambda z, x: cd.PowOp.bwd(z, x, cd.Interval(3))),
             note="pown_rev(z, x, 3); codac: PowOp.bwd with exponent [3, 3]"),
        _bwd("min_rev", (GEN, GEN), np.minimum, lambda z, _x, y: np.minimum(z, y), "np.minimum",
             codac=cob("MinOp")),
        _bwd("max_rev", (GEN, GEN), np.maximum, lambda z, _x, y: np.maximum(z, y), "np.maximum",
             codac=cob("MaxOp")),
        _bwd("sign_rev", (GEN,), np.sign, lambda z, _x: np.sign(z), "np.sign",
             codac=cob("SignOp")),
        _bwd("floor_rev", (GEN,), np.floor, lambda z, _x: np.floor(z), "np.floor",
             codac=cob("FloorOp")),
        _bwd("ceil_rev", (GEN,), np.ceil, lambda z, _x: np.ceil(z), "np.ceil",
             codac=cob("CeilOp")),
    ]


# ----------------------------------------------------------------------------------------------
# naive pure-NumPy interval baseline (NOT boundest code; NaN/0*inf cases are not handled)


def naive_add(al: np.ndarray, ah: np.ndarray, bl: np.ndarray, bh: np.ndarray):
    return np.nextafter(al + bl, -np.inf), np.nextafter(ah + bh, np.inf)


def naive_mul(al: np.ndarray, ah: np.ndarray, bl: np.ndarray, bh: np.ndarray):
    p1, p2, p3, p4 = al * bl, al * bh, ah * bl, ah * bh
    lo = np.minimum(np.minimum(p1, p2), np.minimum(p3, p4))
    hi = np.maximum(np.maximum(p1, p2), np.maximum(p3, p4))
    return np.nextafter(lo, -np.inf), np.nextafter(hi, np.inf)


NAIVE = {"add": naive_add, "mul": naive_mul}


# ----------------------------------------------------------------------------------------------
# floating-point rounding mode: importing codac (Gaol) switches the process to rounding upward,
# which breaks every round-to-nearest kernel (boundest's, NumPy's); codac runs in its own mode


class RoundingMode:
    """fegetround/fesetround through ctypes (no-ops where libm cannot be loaded)."""

    def __init__(self) -> None:
        try:
            libm = ctypes.CDLL(ctypes.util.find_library("m") or "libm.so.6")
            self._get, self._set = libm.fegetround, libm.fesetround
        except (OSError, AttributeError):
            self._get = self._set = None
        self.nearest = self.get()   # the mode at start-up (round to nearest unless tampered)
        self.codac = self.nearest

    def get(self) -> int | None:
        return None if self._get is None else int(self._get())

    def set(self, mode: int | None) -> None:
        if self._set is not None and mode is not None:
            self._set(mode)


FENV = RoundingMode()


def _short(exc: Exception) -> str:
    text = " ".join(str(exc).replace("=", " ").split())
    return f"{type(exc).__name__}: {text}"[:240]


# ----------------------------------------------------------------------------------------------
# timing


STAT: Callable[[list[float]], float] = statistics.median


#: crival is skipped at the larger sizes once it costs more than this per element.
CRIVAL_SLOW_NS = 2000.0
#: A measurement whose single call is slow gets fewer samples (at least 3) to stay in budget.
SLOW_BUDGET_S = 1.5


def _timeit(fn: Callable[[], Any], n: int, repeat: int, min_sample: float) -> float:
    """Median (or, with --stat min, minimum) ns per element over ``repeat`` samples, each at
    least ``min_sample`` seconds long (fewer samples, >= 3, when one call is very slow)."""
    t0 = time.perf_counter()
    fn()  # warm-up
    one = time.perf_counter() - t0
    if one < min_sample:   # the warm-up may include one-off costs: time a second call
        t0 = time.perf_counter()
        fn()
        one = time.perf_counter() - t0
    one = max(one, 1e-9)
    loops = max(1, int(min_sample / one))
    repeat = max(3, min(repeat, int(SLOW_BUDGET_S / (one * loops))))
    samples = []
    gc_was = gc.isenabled()
    gc.disable()
    try:
        for _ in range(repeat):
            t0 = time.perf_counter_ns()
            for _ in range(loops):
                fn()
            samples.append((time.perf_counter_ns() - t0) / loops / n)
    finally:
        if gc_was:
            gc.enable()
    return STAT(samples)


def _timeit_setup(setup: Callable[[], Any], fn: Callable[[Any], Any], n: int,
                  repeat: int) -> float:
    """Like _timeit for one long call per sample, with a fresh untimed ``setup()`` each time."""
    state = setup()
    t0 = time.perf_counter()
    fn(state)  # warm-up
    repeat = max(3, min(repeat, int(SLOW_BUDGET_S / max(time.perf_counter() - t0, 1e-9))))
    samples = []
    gc.disable()
    try:
        for _ in range(repeat):
            state = setup()
            t0 = time.perf_counter_ns()
            fn(state)
            samples.append((time.perf_counter_ns() - t0) / n)
    finally:
        gc.enable()
    return STAT(samples)


# ----------------------------------------------------------------------------------------------
# data


def _make_data(case: Case, n: int, seed: int) -> dict:
    """Interval operands (lo, hi) and points inside them; for backward cases Z around f(points)."""
    rng = np.random.default_rng(seed)
    ivs = [dom(rng, n) for dom in case.doms]
    pts = [lo + rng.uniform(size=n) * (hi - lo) for lo, hi in ivs]
    data = {"ivs": ivs, "pts": pts}
    if case.kind == "backward":
        with np.errstate(all="ignore"):
            zp = case.point(*pts)
            rad = rng.uniform(0.01, 0.1, n) * (1.0 + np.abs(zp))
            zl, zh = zp - rad, zp + rad
            if case.clip is not None:
                zl = np.clip(zl, *case.clip)
                zh = np.clip(zh, *case.clip)
        data["z"] = (zl, zh)
        data["zp"] = zp
    return data


def _floor_args(case: Case, data: dict) -> list[np.ndarray]:
    if case.kind == "forward":
        return list(data["pts"])
    return [data["zp"], *data["pts"]]


# ----------------------------------------------------------------------------------------------
# resolving boundest functions

_SUBMODULES = ("algebraic", "explog", "trig", "arith")


def _boundest_namespaces() -> list[tuple[str, Any]]:
    import pkgutil

    import boundest
    spaces = [("boundest", boundest)]
    try:
        import boundest.interval as bi
        spaces.append(("boundest.interval", bi))
        names = list(_SUBMODULES) + sorted(m.name for m in pkgutil.iter_modules(bi.__path__)
                                           if m.name not in _SUBMODULES)
        for name in names:
            try:
                spaces.append((f"boundest.interval.{name}",
                               importlib.import_module(f"boundest.interval.{name}")))
            except Exception:  # a module being written may not import
                continue
    except ImportError:
        pass
    return spaces


def _resolve(name: str, spaces: list[tuple[str, Any]]) -> tuple[Callable | None, str | None]:
    for where, mod in spaces:
        f = getattr(mod, name, None)
        if callable(f) and not isinstance(f, type):
            return f, f"{where}.{name}"
    return None, None


def _accepts_out(f: Callable) -> bool:
    try:
        return "out" in inspect.signature(f).parameters
    except (TypeError, ValueError):
        return False


# ----------------------------------------------------------------------------------------------
# enclosure check against crival


def _as_pairs(res: Any) -> list[tuple[np.ndarray, np.ndarray]]:
    items = res if isinstance(res, tuple) else (res,)
    return [(np.asarray(r.lo, dtype=np.float64), np.asarray(r.hi, dtype=np.float64))
            for r in items]


def _check(b_res: Any, c_res: Any) -> dict:
    """Elements where boundest's result fails to contain crival's (tight) one; strictly wider."""
    bad = wider = total = 0
    b_pairs, c_pairs = _as_pairs(b_res), _as_pairs(c_res)
    if len(b_pairs) != len(c_pairs):
        return {"error": f"boundest returned {len(b_pairs)} intervals, crival {len(c_pairs)}"}
    for (bl, bh), (cl, ch) in zip(b_pairs, c_pairs, strict=True):
        c_empty = np.isnan(cl)
        b_empty = np.isnan(bl)
        ok = c_empty | ((bl <= cl) & (ch <= bh))
        bad += int(np.count_nonzero(~ok))
        wider += int(np.count_nonzero(ok & ~c_empty & ((bl < cl) | (ch < bh))
                                      | (c_empty & ~b_empty)))
        total += cl.size
    return {"n": total, "not_enclosing_crival": bad, "wider_than_crival": wider}


# ----------------------------------------------------------------------------------------------
# probing boundest in a child process: operators being written may crash the interpreter
# (a segfault in a kernel), and a fresh process is where the first call (JIT compile or cache
# load) is measured honestly


def _boundest_args(case: Case, data: dict, interval: Any) -> tuple:
    ops = [interval(lo, hi) for lo, hi in data["ivs"]]
    if case.kind == "backward":
        ops = [interval(*data["z"]), *ops]
    return (*ops, *case.extra)


def _probe_child(names: list[str], sizes: list[int], seed: int) -> int:
    """Child process: call each case's boundest function once per size; one JSON line each."""
    t0 = time.perf_counter()
    import boundest
    print("PROBE " + json.dumps({"import_s": time.perf_counter() - t0}), flush=True)
    spaces = _boundest_namespaces()
    cases = {c.name: c for c in _cases(None, None)}
    seen: dict[str, str] = {}   # function -> first case that called it
    for name in names:
        case = cases[name]
        f, _ = _resolve(case.func, spaces)
        if f is None:
            continue
        print("PROBE " + json.dumps({"case": name, "start": True}), flush=True)
        out: dict[str, Any] = {"case": name}
        if case.func in seen:
            out["first_call_see"] = seen[case.func]   # its first call was timed there
        seen.setdefault(case.func, name)
        try:
            for i, n in enumerate(sizes):
                call_args = _boundest_args(case, _make_data(case, n, seed + n), boundest.Interval)
                with np.errstate(all="ignore"):
                    t0 = time.perf_counter()
                    f(*call_args)
                    dt = time.perf_counter() - t0
                if i == 0 and "first_call_see" not in out:
                    out["first_call_s"] = round(dt, 4)
                    out["first_call_n"] = n
                    t0 = time.perf_counter()
                    f(*call_args)
                    out["second_call_s"] = round(time.perf_counter() - t0, 6)
        except Exception as exc:  # reported; the parent skips the function
            out["error"] = _short(exc)
        print("PROBE " + json.dumps(out), flush=True)
    return 0


def _probe(cases: list[Case], sizes: list[int], seed: int) -> tuple[dict, float | None]:
    """Run _probe_child, restarting it after a crash; returns ({case: info}, import time)."""
    import subprocess
    todo = [c.name for c in cases]
    info: dict[str, dict] = {}
    import_s = None
    while todo:
        cmd = [sys.executable, os.path.abspath(__file__), "--_probe", ",".join(todo),
               "--sizes", ",".join(map(str, sizes)), "--seed", str(seed)]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=900)
            stdout, rc = proc.stdout, proc.returncode
            stderr = proc.stderr
        except subprocess.TimeoutExpired as exc:
            stdout = exc.stdout.decode() if isinstance(exc.stdout, bytes) else (exc.stdout or "")
            rc, stderr = "timeout", ""
        started = None
        for line in stdout.splitlines():
            if not line.startswith("PROBE "):
                continue
            rec = json.loads(line[6:])
            if "import_s" in rec:
                import_s = import_s if import_s is not None else round(rec["import_s"], 4)
            elif rec.get("start"):
                started = rec["case"]
            else:
                info[rec["case"]] = rec
                started = None
        if rc == 0:
            break
        if started is None:   # died outside any case (import error...): give up probing
            for name in todo:
                info.setdefault(name, {"case": name, "error": f"probe process failed (rc={rc}):"
                                       f" {stderr.strip()[-200:]}"})
            break
        why = f"signal {-rc}" if isinstance(rc, int) and rc < 0 else str(rc)
        info[started] = {"case": started, "crashed": f"the call killed the process ({why})"}
        todo = todo[todo.index(started) + 1:]
    return info, import_s


# ----------------------------------------------------------------------------------------------
# running one case


def _run_case(case: Case, sizes: list[int], args: argparse.Namespace, env: dict) -> dict:
    res: dict[str, Any] = {"floor": case.floor_label, "note": case.note or None}
    if FENV.get() != FENV.nearest:   # something switched the rounding mode: put it back
        res["rounding_mode_reset_from"] = FENV.get()
        FENV.set(FENV.nearest)
    f, where = _resolve(case.func, env["spaces"])
    res["boundest_function"] = where
    if f is None:
        res["boundest_missing"] = True
    probe = env["probe"].get(case.name, {})
    res.update({k: v for k, v in probe.items() if k != "case"})
    if probe.get("crashed") or probe.get("error"):
        f = None   # it killed (or failed in) the probe process: time only the references
    interval = env["Interval"]
    by_size: dict[str, dict] = {}
    crival_slow = False
    for n in sizes:
        row: dict[str, Any] = {}
        data = _make_data(case, n, args.seed + n)
        ivs = data["ivs"]
        fargs = _floor_args(case, data)
        with np.errstate(all="ignore"):
            row["numpy_floor_ns"] = _r(_timeit(lambda fa=fargs: case.floor(*fa), n,
                                               args.repeat, args.min_sample))
        # naive NumPy baseline
        if case.kind == "forward" and case.name in NAIVE:
            flat = [a for pair in ivs for a in pair]
            row["naive_numpy_ns"] = _r(_timeit(lambda fl=flat: NAIVE[case.name](*fl), n,
                                               args.repeat, args.min_sample))
        # boundest
        b_res = None
        if f is not None:
            try:
                call_args = _boundest_args(case, data, interval)
                with np.errstate(all="ignore"):
                    row["boundest_ns"] = _r(_timeit(lambda fn=f, a=call_args: fn(*a), n,
                                                    args.repeat, args.min_sample))
                    if case.kind == "forward" and _accepts_out(f):
                        out = interval.trusted(np.empty(n), np.empty(n))
                        row["boundest_out_ns"] = _r(_timeit(
                            lambda fn=f, a=call_args, o=out: fn(*a, out=o), n, args.repeat,
                            args.min_sample))
                    b_res = f(*call_args)
            except Exception as exc:  # report it and go on with the other cases
                row["boundest_error"] = _short(exc)
        # crival, vectorized (skipped at larger sizes once it costs > 1 us per element)
        if case.crival is not None and crival_slow:
            row["crival_skipped"] = f"over {CRIVAL_SLOW_NS:.0f} ns/element at a smaller size"
        elif case.crival is not None:
            iv = env["ival"]
            try:
                c_ops = [iv.Interval(lo, hi) for lo, hi in ivs]
                if case.kind == "backward":
                    c_ops = [iv.Interval(*data["z"]), *c_ops]
                with np.errstate(all="ignore"):
                    row["crival_ns"] = _r(_timeit(lambda a=c_ops: case.crival(*a), n,
                                                  args.repeat, args.min_sample))
                crival_slow = row["crival_ns"] > CRIVAL_SLOW_NS
                if b_res is not None and n == sizes[0]:
                    res["check"] = _check(b_res, case.crival(*c_ops))
            except Exception as exc:
                row["crival_error"] = _short(exc)
        # codac, scalar objects in a Python loop
        if case.codac is not None and n <= args.codac_max_size:
            m = min(n, args.codac_n)
            row["codac_n"] = m
            FENV.set(FENV.codac)
            try:
                row["codac_ns"] = _r(_codac_time(case, data, m, env["codac"], args.repeat))
            except Exception as exc:
                row["codac_error"] = _short(exc)
            finally:
                FENV.set(FENV.nearest)
        if "boundest_ns" in row:
            row["ratio_vs_floor"] = _r(row["boundest_ns"] / row["numpy_floor_ns"], 3)
        by_size[str(n)] = row
    res["sizes"] = by_size
    return res


def _codac_time(case: Case, data: dict, m: int, cd: Any, repeat: int) -> float:
    ivs = [(lo[:m].tolist(), hi[:m].tolist()) for lo, hi in data["ivs"]]
    new = cd.Interval
    if case.kind == "forward":
        cols = [[new(a, b) for a, b in zip(lo, hi, strict=True)] for lo, hi in ivs]
        fn = case.codac
        if len(cols) == 1:
            (xs,) = cols
            return _timeit_setup(lambda: xs, lambda s: [fn(x) for x in s], m, repeat)
        xs, ys = cols
        return _timeit_setup(lambda: (xs, ys),
                             lambda s: [fn(x, y) for x, y in zip(*s, strict=True)], m, repeat)
    # backward: XxxOp.bwd(z, x[, y]) contracts x and y in place: fresh copies for each sample
    zl, zh = data["z"][0][:m].tolist(), data["z"][1][:m].tolist()
    zs = [new(a, b) for a, b in zip(zl, zh, strict=True)]
    fn = case.codac

    def setup() -> list:
        return [[new(a, b) for a, b in zip(lo, hi, strict=True)] for lo, hi in ivs]

    if len(ivs) == 1:
        def run1(s: list) -> None:
            for z, x in zip(zs, s[0], strict=True):
                fn(z, x)
        return _timeit_setup(setup, run1, m, repeat)

    def run2(s: list) -> None:
        for z, x, y in zip(zs, s[0], s[1], strict=True):
            fn(z, x, y)
    return _timeit_setup(setup, run2, m, repeat)


def _r(x: float, nd: int = 2) -> float:
    return float(round(x, nd))


# ----------------------------------------------------------------------------------------------
# machine info and summary


def _machine(env: dict) -> dict:
    import numba
    info: dict[str, Any] = {
        "python": sys.version.split()[0],
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "cpus_usable": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
        "numpy": np.__version__,
        "numba": numba.__version__,
        "rounding_mode_at_start": FENV.nearest,
        "loadavg_start": env.get("loadavg_start"),
        "loadavg_end": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
    }
    info["cpu_model"] = cpu_model()
    try:
        from numpy._core._multiarray_umath import __cpu_features__ as feats
        info["cpu_simd"] = {k: bool(feats.get(k)) for k in ("AVX2", "FMA3", "AVX512F")}
    except ImportError:
        pass
    try:
        import llvmlite
        info["llvmlite"] = llvmlite.__version__
    except ImportError:
        pass
    import boundest
    info["boundest"] = getattr(boundest, "__version__", None)
    info["crival"] = env.get("crival_version")
    info["codac"] = env.get("codac_version")
    return info


ARITH = ("add", "sub", "mul", "div", "sqr", "sqrt")
ELEMENTARY = ("exp", "log", "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh",
              "cosh", "tanh", "pow")


def _summary(results: dict, sizes: list[int]) -> dict:
    allc = {**results["forward"], **results["backward"]}
    ref = 100_000 if 100_000 in sizes else sizes[len(sizes) // 2]
    s: dict[str, Any] = {"reference_size": ref}

    def get(name: str, n: int, key: str) -> float | None:
        return allc.get(name, {}).get("sizes", {}).get(str(n), {}).get(key)

    s["ratio_vs_numpy_floor"] = {k: get(k, ref, "ratio_vs_floor") for k in allc
                                 if get(k, ref, "ratio_vs_floor") is not None}
    s["boundest_ns"] = {k: get(k, ref, "boundest_ns") for k in allc
                        if get(k, ref, "boundest_ns") is not None}
    for key in ("crival_ns", "codac_ns"):
        s[f"speedup_vs_{key[:-3]}"] = {
            k: _r(get(k, ref, key) / get(k, ref, "boundest_ns"), 1) for k in allc
            if get(k, ref, key) and get(k, ref, "boundest_ns")}
    s["speedup_vs_naive_numpy"] = {
        k: _r(get(k, n, "naive_numpy_ns") / get(k, n, "boundest_ns"), 2)
        for k in NAIVE for n in [ref] if get(k, n, "naive_numpy_ns") and get(k, n, "boundest_ns")}

    target_sizes = [n for n in (100_000, 1_000_000) if n in sizes]
    arith: dict[str, Any] = {}
    for key, label in (("boundest_ns", "le_10ns"), ("boundest_out_ns", "le_10ns_with_out")):
        per_op = {}
        for op in ARITH:
            vals = {str(n): get(op, n, key) for n in target_sizes}
            if any(v is None for v in vals.values()) or not vals:
                per_op[op] = None
            else:
                per_op[op] = {**vals, "ok": all(v <= 10.0 for v in vals.values())}
        oks = [v["ok"] for v in per_op.values() if v is not None]
        arith[label] = {"sizes": target_sizes, "ops": per_op,
                        "all": (all(oks) if len(oks) == len(ARITH) else None),
                        "missing": [op for op, v in per_op.items() if v is None]}
    s["arith_targets"] = arith
    elem = {}
    for op in ELEMENTARY:
        r = get(op, ref, "ratio_vs_floor")
        elem[op] = None if r is None else {"ratio": r, "ok": r <= 3.0}
    oks = [v["ok"] for v in elem.values() if v is not None]
    s["elementary_within_3x_numpy"] = {
        "size": ref, "ops": elem, "all": (all(oks) if len(oks) == len(ELEMENTARY) else None),
        "all_present": all(oks) if oks else None,
        "missing": [op for op, v in elem.items() if v is None]}
    s["missing_in_boundest"] = sorted(k for k, v in allc.items() if v.get("boundest_missing"))
    s["errors"] = {k: {n: {e: r[e] for e in r if e.endswith("_error")}
                       for n, r in v["sizes"].items() if any(e.endswith("_error") for e in r)}
                   for k, v in allc.items()
                   if any(e.endswith("_error") for r in v["sizes"].values() for e in r)}
    s["boundest_failed"] = {k: v.get("crashed") or v.get("error") for k, v in allc.items()
                            if v.get("crashed") or v.get("error")}
    s["check_failures"] = {k: v["check"] for k, v in allc.items()
                           if v.get("check", {}).get("not_enclosing_crival")}
    return s


# ----------------------------------------------------------------------------------------------


def _parse_sizes(text: str) -> list[int]:
    try:
        return [int(float(t)) for t in text.split(",") if t.strip()]
    except ValueError as exc:
        raise SystemExit(f"--sizes: expected comma-separated numbers like 1e3,1e5, got {text!r}"
                         ) from exc


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--sizes", default=None, help="comma-separated element counts "
                   "(default 1e3,1e5,1e6; --quick: 1e3,1e5)")
    p.add_argument("--ops", default=None, help="comma-separated case names (e.g. add,mul,sin_rev)"
                   "; 'forward' or 'backward' select a whole group")
    p.add_argument("--repeat", type=int, default=None, help="samples per timing (default 7; "
                   "--quick: 3); the median is reported")
    p.add_argument("--stat", choices=("median", "min"), default="median",
                   help="statistic over the samples (default median; min is steadier on a "
                   "shared machine)")
    p.add_argument("--quick", action="store_true", help="fewer sizes, repeats and codac elements")
    p.add_argument("--out", default=None, help="also write the JSON to this file")
    p.add_argument("--seed", type=int, default=1788)
    p.add_argument("--codac-n", type=int, default=None,
                   help="elements per Codac loop (default 1e4; --quick 2e3)")
    p.add_argument("--codac-max-size", type=int, default=100_000,
                   help="skip Codac at sizes above this (default 1e5)")
    p.add_argument("--no-external", action="store_true", help="skip crival and codac")
    p.add_argument("--cold", action="store_true", help="compile Numba kernels from scratch "
                   "(empty NUMBA_CACHE_DIR), so that first_call_s is the JIT compile time")
    p.add_argument("--list", action="store_true", help="list the case names and exit")
    p.add_argument("--_probe", default=None, help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    sizes = _parse_sizes(args.sizes) if args.sizes else (
        [1000, 100_000] if args.quick else [1000, 100_000, 1_000_000])
    if args._probe is not None:
        return _probe_child(args._probe.split(","), sizes, args.seed)
    args.repeat = args.repeat or (3 if args.quick else 7)
    args.min_sample = 0.005 if args.quick else 0.01
    args.codac_n = args.codac_n or (2000 if args.quick else 10_000)
    global STAT
    STAT = min if args.stat == "min" else statistics.median

    cache_dir = None
    if args.cold:
        if "numba" in sys.modules:
            print("warning: numba already imported; --cold has no effect", file=sys.stderr)
        cache_dir = tempfile.mkdtemp(prefix="bench-numba-cache-")
        os.environ["NUMBA_CACHE_DIR"] = cache_dir

    env: dict[str, Any] = {"ival": None, "codac": None,
                           "loadavg_start": list(os.getloadavg())
                           if hasattr(os, "getloadavg") else None}
    notes: list[str] = []
    if not args.no_external:
        try:
            import ival
            env["ival"] = ival
            env["crival_version"] = ival.version()
        except (ImportError, OSError) as exc:
            notes.append(f"crival not importable ({exc}); crival columns skipped")
        try:
            import codac
            FENV.codac = FENV.get()
            FENV.set(FENV.nearest)
            if FENV.codac != FENV.nearest:
                notes.append(f"importing codac switched the FPU rounding mode from "
                             f"{FENV.nearest:#x} to {FENV.codac:#x} (upward): the benchmark "
                             "restores round-to-nearest after every codac loop and gives codac "
                             "its own mode while it runs")
            env["codac"] = codac
            env["codac_version"] = getattr(codac, "__version__", None)
            if not hasattr(codac, "AddOp"):
                notes.append("codac has no AddOp (codac 1.x?): codac columns skipped")
                env["codac"] = None
        except ImportError as exc:
            notes.append(f"codac not importable ({exc}); codac columns skipped")

    cases = _cases(env["ival"], env["codac"])
    if args.list:
        for c in cases:
            print(f"{c.kind:9s} {c.name}")
        return 0
    if args.ops:
        want = {w.strip() for w in args.ops.split(",") if w.strip()}
        known = {c.name for c in cases} | {"forward", "backward"}
        if want - known:
            raise SystemExit(f"--ops: unknown case(s) {sorted(want - known)}; see --list")
        cases = [c for c in cases if c.name in want or c.kind in want]

    t_start = time.perf_counter()
    t0 = time.perf_counter()
    import boundest
    t_import = time.perf_counter() - t0
    env["Interval"] = boundest.Interval
    env["spaces"] = _boundest_namespaces()
    print("[bench_interval] probing boundest in a child process ...", file=sys.stderr, flush=True)
    present = [c for c in cases if _resolve(c.func, env["spaces"])[0] is not None]
    t0 = time.perf_counter()
    env["probe"], probe_import_s = _probe(present, sizes, args.seed)
    t_probe = time.perf_counter() - t0
    crashed = sorted(k for k, v in env["probe"].items() if v.get("crashed"))
    if crashed:
        notes.append("boundest functions that crashed the interpreter in the probe process "
                     "(skipped): " + ", ".join(crashed))
    failed = sorted(k for k, v in env["probe"].items() if v.get("error"))
    if failed:
        notes.append("boundest functions that raised in the probe process (skipped; see each "
                     "case's 'error'): " + ", ".join(failed))

    results: dict[str, Any] = {"forward": {}, "backward": {}}
    for case in cases:
        print(f"[bench_interval] {time.perf_counter() - t_start:6.1f}s {case.kind} {case.name}",
              file=sys.stderr, flush=True)
        results[case.kind][case.name] = _run_case(case, sizes, args, env)

    missing = sorted(c.name for c in cases if results[c.kind][c.name].get("boundest_missing"))
    if missing:
        notes.append("not (yet) in boundest, only the references were timed: "
                     + ", ".join(missing))
    if env["codac"] is not None:
        notes.append("codac: scalar codac.Interval objects in a Python list comprehension/loop, "
                     "XxxOp.fwd / XxxOp.bwd (cheaper than the operators), at most "
                     f"{args.codac_n} elements per loop, skipped above {args.codac_max_size}")
    notes.append("boundest calls allocate their results; boundest_out_ns passes out= buffers")
    notes.append("numpy_floor: the plain float64 operation on points (backward: its inverse), "
                 "allocating its result")

    report = {
        "benchmark": "interval",
        "machine": _machine(env),
        "config": {"sizes": sizes, "repeat": args.repeat, "stat": args.stat,
                   "min_sample_s": args.min_sample,
                   "seed": args.seed, "quick": args.quick, "cold_numba_cache": args.cold,
                   "codac_n": args.codac_n},
        "import_boundest_s": round(t_import, 4),
        "import_boundest_fresh_process_s": probe_import_s,
        "probe_process_s": round(t_probe, 2),
        "notes": notes,
        **results,
        "summary": _summary(results, sizes),
        "total_run_s": round(time.perf_counter() - t_start, 1),
    }
    text = json.dumps(report, indent=1)
    print(text)
    if args.out:
        with open(args.out, "w") as fh:
            fh.write(text + "\n")
    if cache_dir:
        shutil.rmtree(cache_dir, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
