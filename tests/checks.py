"""Helpers shared by the tests: assertions (plain functions returning bools) and
:func:`examples`, the example budget of a property test in the default and slow parts."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from boundest import Interval

INF = math.inf


def exact_in(q: Fraction | float, x: Interval) -> bool:
    """Whether the exact real ``q`` (a Fraction or float) lies in the scalar interval ``x``."""
    lo, hi = float(x.lo), float(x.hi)
    if math.isnan(lo):
        return False
    return (lo == -INF or Fraction(lo) <= q) and (hi == INF or q <= Fraction(hi))


def valid(z: Interval) -> bool:
    """The representation invariants: both bounds NaN, or lo <= hi, lo != +inf, hi != -inf."""
    lo, hi = np.asarray(z.lo), np.asarray(z.hi)
    empty = np.isnan(lo) & np.isnan(hi)
    ok = (lo <= hi) & (lo < INF) & (hi > -INF)
    return bool(np.all(empty | ok))


def is_empty(z: Interval) -> bool:
    return bool(np.all(z.is_empty()))


def subset(a: Interval, b: Interval) -> bool:
    return bool(np.all(a.is_subset(b)))


def same(z: Interval, lo: float, hi: float) -> bool:
    """``z`` is exactly ``[lo, hi]``."""
    return float(z.lo) == lo and float(z.hi) == hi


def engine_forward(name: str, x: Interval) -> Interval:
    """Images of the scalar intervals of ``x`` through the compiled engine's forward step
    (``revise.image``, the explog and trig families compiled in)."""
    from boundest.ctc import revise as engine

    code = getattr(engine, name.upper())
    buf = np.empty(4)
    lo, hi = np.empty(x.lo.size), np.empty(x.lo.size)
    for i in range(x.lo.size):
        lo[i], hi[i] = engine.image(code, float(x.lo.flat[i]), float(x.hi.flat[i]), 0.0, 0.0,
                                    0.0, buf, None, None, True, True)
    return Interval.trusted(lo, hi)


def examples(full: int, default: int) -> pytest.MarkDecorator:
    """Parametrize a property test by its number of hypothesis examples, ``n_examples``:
    ``default`` in the suite's default part (quick, on every run), ``full`` in its slow part
    (``pytest -m slow``, run by CI). The test builds its ``@given`` check inside."""
    return pytest.mark.parametrize("n_examples", [
        pytest.param(default, id=f"{default}-examples"),
        pytest.param(full, id=f"{full}-examples", marks=pytest.mark.slow)])
