"""Property tests of the row kernels of the centered contractors (``boundest.ctc.linear_forms``):
whatever real matrix ``S`` in the interval matrix ``J`` and point ``d`` in the box ``D`` a
system was built from, with ``S d`` enclosed in the right-hand side, ``d`` survives every
contraction (row sweeps with relational division, the banded preconditioner, interval Gaussian
elimination), for ``m < n``, ``m = n`` and ``m > n``, entries containing 0 or unbounded, and
degenerate boxes."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from boundest.ctc.linear_forms import (
    band_preconditioner,
    contract_rows,
    interval_elimination,
    point_times,
)
from boundest.interval.rounding import add_dn, add_up, mul_dn, mul_up

from .checks import examples


def _enclose_product(S, d):
    """An enclosure of ``S d`` (rows), rounded outward."""
    lo = np.zeros(S.shape[0])
    hi = np.zeros(S.shape[0])
    for i in range(S.shape[0]):
        for j in range(S.shape[1]):
            lo[i] = add_dn(lo[i], mul_dn(S[i, j], d[j]))
            hi[i] = add_up(hi[i], mul_up(S[i, j], d[j]))
    return lo, hi


@st.composite
def linear_systems(draw):
    """``(J, D, S, d, z)``: an interval matrix around a real ``S`` (some entries containing 0,
    some unbounded, some exact zeros), a box around ``d`` (some components degenerate or
    unbounded), and ``z`` around ``S d``."""
    m = draw(st.integers(1, 5))
    n = draw(st.integers(1, 5))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    S = rng.normal(size=(m, n))
    S[rng.random((m, n)) < 0.2] = 0.0
    w = rng.choice([0.0, 1e-9, 1e-3, 0.1, 1.0], size=(m, n))
    jl, jh = S - w * rng.random((m, n)), S + w * rng.random((m, n))
    jl[rng.random((m, n)) < 0.05] = -np.inf
    jh[rng.random((m, n)) < 0.05] = np.inf
    d = rng.normal(size=n)
    r = rng.choice([0.0, 1e-6, 0.01, 1.0], size=n)
    dl, dh = d - r * rng.random(n), d + r * rng.random(n)
    dl[rng.random(n) < 0.1] = -np.inf
    dh[rng.random(n) < 0.1] = np.inf
    zl, zh = _enclose_product(S, d)
    e = rng.choice([0.0, 1e-9, 0.1], size=m)
    return jl, jh, dl, dh, S, d, zl - e, zh + e


def _inside(d, dl, dh) -> bool:
    return bool(np.all((dl <= d) & (d <= dh)))


@examples(300, 20)
def test_contract_rows_keeps_the_point(n_examples):
    @settings(max_examples=n_examples, deadline=None)
    @given(linear_systems(), st.booleans())
    def check(system, reverse):
        jl, jh, dl, dh, S, d, zl, zh = system
        work = np.empty((6, len(d) + 1))
        ok = contract_rows(jl, jh, zl, zh, dl, dh, reverse, work)
        assert ok and _inside(d, dl, dh), (dl, d, dh)
        # the contracted coefficients still hold S: a second sweep keeps d too
        assert np.all((jl <= S) & (jh >= S))
        assert contract_rows(jl, jh, zl, zh, dl, dh, not reverse, work) and _inside(d, dl, dh)

    check()


@settings(max_examples=300, deadline=None)
@given(linear_systems())
def test_preconditioned_rows_keep_the_point(system):
    jl, jh, dl, dh, _, d, zl, zh = system
    m, n = jl.shape
    work = np.empty((6, n + 1))
    with np.errstate(invalid="ignore"):
        mid = np.where(np.isfinite(jl) & np.isfinite(jh), 0.5 * jl + 0.5 * jh, 0.0)
    if m <= n:
        R, B, perm = np.empty((m, m)), np.empty((m, m)), np.empty(m, dtype=np.int64)
        rc = band_preconditioner(mid, R, B, perm)
        assert 0.0 <= rc <= 1.0 + 1e-12
        gl, gh = np.empty((m, n)), np.empty((m, n))
        rl, rh = np.empty((m, 1)), np.empty((m, 1))
        point_times(R, jl, jh, gl, gh)
        point_times(R, zl.reshape(-1, 1), zh.reshape(-1, 1), rl, rh)
        assert contract_rows(gl, gh, rl[:, 0].copy(), rh[:, 0].copy(), dl, dh, True, work)
    else:
        gl, gh, ezl, ezh = jl.copy(), jh.copy(), zl.copy(), zh.copy()
        rp, cp = np.empty(m, dtype=np.int64), np.empty(n, dtype=np.int64)
        interval_elimination(gl, gh, ezl, ezh, mid.copy(), rp, cp)
        assert sorted(rp) == list(range(m)) and sorted(cp) == list(range(n))
        assert contract_rows(gl[rp], gh[rp], ezl[rp], ezh[rp], dl, dh, True, work)
    assert _inside(d, dl, dh), (dl, d, dh)


def test_band_preconditioner_structure():
    """Row ``i`` of ``R A`` vanishes outside columns ``i .. i + n - m`` (a square ``A``: Gauss-
    Jordan, ``R A`` diagonal); singular leading columns give the identity and 0."""
    rng = np.random.default_rng(3)
    for m, n in ((1, 1), (2, 3), (3, 3), (4, 6), (7, 8)):
        A = rng.normal(size=(m, n))
        R, B, perm = np.empty((m, m)), np.empty((m, m)), np.empty(m, dtype=np.int64)
        assert band_preconditioner(A, R, B, perm) > 0.0
        RA = R @ A
        scale = np.abs(RA).max()
        for i in range(m):
            for j in range(n):
                if j < i or j > i + n - m:
                    assert abs(RA[i, j]) < 1e-12 * scale, (m, n, i, j, RA)
    A = np.array([[1.0, 2.0, 3.0], [2.0, 4.0, 1.0]])
    R, B, perm = np.empty((2, 2)), np.empty((2, 2)), np.empty(2, dtype=np.int64)
    assert band_preconditioner(A, R, B, perm) == 0.0
    assert np.array_equal(R, np.eye(2))


def test_interval_elimination_consistency_rows_refute():
    """``x = 1, y = 1, x + y in [3, 4]`` has no solution: the consistency row left by the
    elimination excludes 0, and the sweep says so."""
    jl = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    zl, zh = np.array([1.0, 1.0, 3.0]), np.array([1.0, 1.0, 4.0])
    gl, gh = jl.copy(), jl.copy()
    rp, cp = np.empty(3, dtype=np.int64), np.empty(2, dtype=np.int64)
    assert interval_elimination(gl, gh, zl, zh, jl.copy(), rp, cp) == 2
    work = np.empty((6, 3))
    dl, dh = np.full(2, -10.0), np.full(2, 10.0)
    assert not contract_rows(gl[rp], gh[rp], zl[rp], zh[rp], dl, dh, True, work)
