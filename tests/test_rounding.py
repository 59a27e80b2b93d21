"""The outward-stepping helpers: sound (never inside) and one ulp in all but rare cases."""

import numba as nb
import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from boundest.interval.rounding import MAX, libm_dn, libm_up, next_down, next_up


@nb.njit
def _steps(x):
    return next_down(x), next_up(x), libm_dn(x), libm_up(x)


@given(st.floats(allow_nan=False))
@np.errstate(over="ignore")  # nextafter(MAX, inf) overflows to inf, as it should
def test_next_down_up_are_strict_and_tight(x):
    dn, up, ldn, lup = _steps(x)
    if x != np.inf:
        assert dn < x or (x == -np.inf and dn == x)
        assert dn >= np.nextafter(np.nextafter(x, -np.inf), -np.inf)
    if x != -np.inf:
        assert up > x or (x == np.inf and up == x)
        assert up <= np.nextafter(np.nextafter(x, np.inf), np.inf)
    assert ldn <= dn if x != np.inf else ldn == MAX
    assert lup >= up if x != -np.inf else lup == -MAX


def test_next_down_is_exactly_one_step_on_random_floats():
    rng = np.random.default_rng(1)
    bits = rng.integers(0, 2**63 - 2**52, size=200_000, dtype=np.int64)  # finite positives
    x = bits.view(np.float64) * rng.choice([-1.0, 1.0], size=bits.size)
    got = np.array([_steps(v)[0] for v in x[:2000]])
    assert np.all(got <= np.nextafter(x[:2000], -np.inf))
    # Rump et al.: the trick is the exact predecessor except near the subnormal boundary
    exact = got == np.nextafter(x[:2000], -np.inf)
    assert exact.mean() > 0.99


def test_infinities_and_nan():
    dn, up, _, _ = _steps(np.inf)
    assert dn == MAX and up == np.inf
    dn, up, _, _ = _steps(-np.inf)
    assert dn == -np.inf and up == -MAX
    assert all(np.isnan(v) for v in _steps(np.nan))
    assert _steps(0.0)[0] == -(2.0**-1074) and _steps(0.0)[1] == 2.0**-1074


def test_kernels_refuse_to_run_with_upward_rounding():
    import ctypes
    import ctypes.util

    import pytest

    import boundest as bd

    libm = ctypes.CDLL(ctypes.util.find_library("m"))
    fe_upward, fe_tonearest = 0x800, 0x000  # x86-64 glibc values
    assert libm.fegetround() == fe_tonearest
    libm.fesetround(fe_upward)
    try:
        with pytest.raises(FloatingPointError, match="round-to-nearest"):
            bd.Interval(1, 2) + bd.Interval(3, 4)
    finally:
        libm.fesetround(fe_tonearest)
    assert bd.Interval(1, 2) + 1 == bd.Interval(2, 3)
