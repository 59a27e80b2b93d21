"""Hypothesis strategies shared by the tests: intervals and points inside them."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import strategies as st

from boundest import Interval

#: Bounds that exercise zeros, tiny, huge and infinite magnitudes.
SPECIAL = [0.0, -0.0, 1.0, -1.0, 0.5, 2.0**-1074, -(2.0**-1074), 2.0**-1022, 1e-300, -1e-300,
           1e300, -1e300, 1.7976931348623157e308, -1.7976931348623157e308]

finite = st.floats(allow_nan=False, allow_infinity=False)
moderate = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False)
bound = st.one_of(finite, moderate, st.sampled_from(SPECIAL))


@st.composite
def intervals(draw, elements=bound, allow_inf: bool = True, allow_degenerate: bool = True):
    """A non-empty interval, possibly with infinite bounds or degenerate."""
    a, b = sorted([draw(elements), draw(elements)])
    if allow_degenerate and draw(st.integers(0, 9)) == 0:
        b = a
    if allow_inf:
        kind = draw(st.integers(0, 9))
        if kind == 0:
            a = -math.inf
        elif kind == 1:
            b = math.inf
        elif kind == 2:
            a, b = -math.inf, math.inf
    return Interval(a, b)


@st.composite
def point_in(draw, x: Interval) -> float:
    """A float inside the (non-empty, scalar) interval ``x``."""
    lo, hi = float(x.lo), float(x.hi)
    lo = max(lo, -1.7976931348623157e308)
    hi = min(hi, 1.7976931348623157e308)
    if lo == hi or draw(st.booleans()):
        return draw(st.sampled_from([lo, hi]))
    return draw(st.floats(min_value=lo, max_value=hi, allow_nan=False))


def ulps_apart(a: float, b: float) -> int:
    """Number of float64 steps between ``a`` and ``b`` (finite)."""
    ia = np.array(a, dtype=np.float64).view(np.int64).item()
    ib = np.array(b, dtype=np.float64).view(np.int64).item()
    ia = ia if ia >= 0 else -(ia & 0x7FFFFFFFFFFFFFFF)
    ib = ib if ib >= 0 else -(ib & 0x7FFFFFFFFFFFFFFF)
    return abs(ia - ib)
