"""Tube contractors: CtcDeriv, CtcEval, CtcSlices and the contractor network.

Soundness: random smooth trajectories (tests/test_tube.py ``Traj``) lie in random tubes whose
derivative tubes enclose their exact derivatives; no contractor may remove them (checked exactly
with mpmath at the gates and at random times). Tightness and emptiness cases are derived by
hand in the comments.
"""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import boundest as bd
from boundest import Interval, Var
from boundest.tube import ContractorNetwork, CtcDeriv, CtcEval, CtcSlices, Tube
from boundest.tube.eval import invert_kernel

from .checks import examples
from .test_tube import grids, inside, sample_times, seeds, trajectories, tube_around, tube_keeps

INF = math.inf


# -- CtcDeriv --
@settings(max_examples=60)
@given(trajectories(), grids(), seeds, st.sampled_from([0.0, 0.05, 0.5]))
def test_deriv_keeps_truth(tr, t, seed, p_entire):
    rng = np.random.default_rng(seed)
    x = tube_around(tr, t, rng, p_entire)
    v = tube_around(tr, t, rng, p_entire / 5, deriv=True)
    CtcDeriv().contract(x, v)
    assert not x.is_empty()
    assert tube_keeps(x, tr, sample_times(t, rng))


@settings(max_examples=30)
@given(trajectories(), trajectories(), grids(), seeds)
def test_deriv_vector_keeps_truth(tr1, tr2, t, seed):
    rng = np.random.default_rng(seed)
    v = Tube.stack([tube_around(tr1, t, rng, deriv=True), tube_around(tr2, t, rng, deriv=True)])
    # only the initial gates are known (widened): x is entire elsewhere
    x = Tube(t, Interval.entire((t.size - 1, 2)))
    t0 = Interval(t[0], t[0])
    x.gates[0] = Interval([float(tr1.enclose(t0).lo), float(tr2.enclose(t0).lo)],
                          [float(tr1.enclose(t0).hi), float(tr2.enclose(t0).hi)]).inflate(0.1)
    CtcDeriv().contract(x, v)
    times = sample_times(t, rng, 20)
    assert tube_keeps(x[0], tr1, times) and tube_keeps(x[1], tr2, times)
    assert np.all(np.isfinite(x.gates.lo))  # the initial gates bound everything


def test_deriv_tight_on_unit_slope():
    # x' = 1, x(0) = 0 on 1000 slices of [0, 10]: x(t_i) = t_i up to rounding, slices exact
    x = Tube.constant(0, 10, 1000, Interval.entire())
    x.gates[0] = Interval(0.0, 0.0)
    CtcDeriv().contract(x, Tube.constant(0, 10, 1000, Interval(1.0, 1.0)))
    err = np.maximum(np.abs(x.gates.lo - x.t), np.abs(x.gates.hi - x.t))
    assert np.all(x.gates.lo <= x.t) and np.all(x.t <= x.gates.hi)
    assert err.max() < 1e-12
    assert np.all(np.abs(x.slices.lo - x.t[:-1]) < 1e-12)
    assert np.all(np.abs(x.slices.hi - x.t[1:]) < 1e-12)


def test_deriv_polygon_slice():
    # gates 0 at both ends of [0, 1], |x'| <= 1: x(s) <= min(s, 1 - s) <= 1/2 (box: 1)
    x = Tube([0.0, 1.0], Interval([-5.0], [5.0]), Interval([0.0, 0.0], [0.0, 0.0]))
    CtcDeriv().contract(x, Tube([0.0, 1.0], Interval([-1.0], [1.0])))
    assert 0.5 <= float(x.slices.hi[0]) < 0.5 + 1e-15
    assert -0.5 - 1e-15 < float(x.slices.lo[0]) <= -0.5
    # asymmetric: x' in [0, 2], x(0) in [0, 1], x(1) in [1.5, 2]: upper = min(1 + 2s, 2) = 2,
    # lower = max(0, 1.5 - 2(1 - s)) = 0 at s = 0
    x = Tube([0.0, 1.0], Interval([-5.0], [5.0]), Interval([0.0, 1.5], [1.0, 2.0]))
    CtcDeriv().contract(x, Tube([0.0, 1.0], Interval([0.0], [2.0])))
    assert float(x.slices.lo[0]) == 0.0 and float(x.slices.hi[0]) == 2.0


def test_deriv_backward_and_empty():
    # x(10) = 0, x' in [1, 2]: backward, x(0) in [-20, -10]
    x = Tube.constant(0, 10, 100, Interval.entire())
    x.gates[100] = Interval(0.0, 0.0)
    CtcDeriv().contract(x, Tube.constant(0, 10, 100, Interval(1.0, 2.0)))
    g = x.gates[0]
    assert -20 - 1e-12 < float(g.lo) <= -20 and -10 <= float(g.hi) < -10 + 1e-12
    # x(0) = 0, x(10) = 0 and x' >= 1: impossible
    x.gates[0] = Interval(0.0, 0.0)
    CtcDeriv().contract(x, Tube.constant(0, 10, 100, Interval(1.0, 2.0)))
    assert x.is_empty()
    # an empty derivative tube empties x; entire tubes stay entire
    y = Tube.constant(0, 1, 4)
    CtcDeriv().contract(y, Tube.constant(0, 1, 4))
    assert np.all(y.slices.is_entire()) and np.all(y.gates.is_entire())
    v = Tube.constant(0, 1, 4, Interval(0, 1))
    v.set_empty()
    CtcDeriv().contract(y, v)
    assert y.is_empty()
    with pytest.raises(ValueError, match="gate times"):
        CtcDeriv().contract(y, Tube.constant(0, 1, 5))


# -- CtcEval --
@settings(max_examples=60)
@given(trajectories(), grids(), seeds, st.floats(0, 1), st.floats(0, 0.3), st.floats(0, 1),
       st.booleans())
def test_eval_keeps_truth(tr, t, seed, where, trad, zrad, time_deriv):
    rng = np.random.default_rng(seed)
    y = tube_around(tr, t, rng, p_entire=0.2)
    w = tube_around(tr, t, rng, p_entire=0.02, deriv=True)
    ts = float(t[0] + where * (t[-1] - t[0]))
    if rng.random() < 0.2:
        ts = float(t[rng.integers(t.size)])  # a measurement at a gate time
    span = trad * (t[-1] - t[0])
    tm = Interval(max(t[0], ts - span * rng.random()), min(t[-1], ts + span * rng.random()))
    zt = tr.value(ts)
    z = Interval(float(zt) - zrad * rng.random() - 1e-9, float(zt) + zrad * rng.random() + 1e-9)
    if rng.random() < 0.3:
        tm = Interval(ts, ts)
    tm, z = CtcEval(time_deriv).contract(tm, z, y, w)
    assert inside(tm, mpmath.mpf(ts)) and inside(z, zt)
    assert tube_keeps(y, tr, sample_times(t, rng))


@settings(max_examples=80)
@given(trajectories(), grids(), seeds, st.floats(0, 1), st.floats(0, 1),
       st.sampled_from([0.0, 1e-9, 1e-3, 0.05, 0.3]), st.booleans(),
       st.sampled_from([0.0, 0.1, 1.0]))
def test_invert_keeps_every_feasible_time(tr, t, seed, where, span, zrad, consistent, p_inf):
    # every time s in [t] at which the true trajectory lies in [z] (decided exactly with
    # mpmath) survives the inversion with the derivative, and so does its value; the tube may
    # be raw (gates and slices widened at random, some unbounded) or CtcDeriv-consistent
    rng = np.random.default_rng(seed)
    y = tube_around(tr, t, rng, p_entire=0.1 * p_inf)
    w = tube_around(tr, t, rng, p_entire=0.02 * p_inf, deriv=True)
    if consistent:
        CtcDeriv().contract(y, w)
    a = float(t[0] + where * (t[-1] - t[0]))
    b = min(float(t[-1]), a + span * (t[-1] - t[0]))
    s0 = float(rng.uniform(a, b)) if b > a else a
    v0 = tr.value(s0)
    z = (float(v0) - zrad - 1e-12, float(v0) + zrad + 1e-12)
    lo, hi, zl, zh = invert_kernel(y.t, y.slices.lo, y.slices.hi, y.gates.lo, y.gates.hi,
                                   w.slices.lo, w.slices.hi, a, b, *z)
    times = np.concatenate([[a, b, s0], rng.uniform(a, b, 80), t[(t >= a) & (t <= b)]])
    for s in times:
        v = tr.value(float(s))
        if mpmath.mpf(z[0]) <= v <= mpmath.mpf(z[1]):
            assert lo <= s <= hi, (s, lo, hi)
            assert mpmath.mpf(zl) <= v <= mpmath.mpf(zh)


def test_invert_by_hand_and_degenerate():
    # y' = 1 exactly, y(0) = 0: y(s) = s; y in [3, 3.5] only for s in [3, 3.5] (the plain
    # inverse gives the whole slices that meet [3, 3.5]: [2, 3] (at its end) and [3, 4])
    t = np.arange(6.0)
    y = Tube(t, Interval.entire(5))
    y.gates[0] = Interval(0.0)
    w = Tube.constant(0, 5, 5, Interval(1.0))
    CtcDeriv().contract(y, w)
    assert invert_kernel(y.t, y.slices.lo, y.slices.hi, y.gates.lo, y.gates.hi, w.slices.lo,
                         w.slices.hi, 0.0, 5.0, 3.0, 3.5) == (3.0, 3.5, 3.0, 3.5)
    tm, _ = CtcEval(time_deriv=False).contract(Interval(0, 5), Interval(3, 3.5), y.copy(), w)
    assert (float(tm.lo), float(tm.hi)) == (2.0, 4.0)
    # no time at all, and an unbounded derivative (the cones say nothing: the plain inverse)
    lo, hi, _, _ = invert_kernel(y.t, y.slices.lo, y.slices.hi, y.gates.lo, y.gates.hi,
                                 w.slices.lo, w.slices.hi, 0.0, 2.0, 3.0, 3.5)
    assert lo > hi
    we = Tube.constant(0, 5, 5)
    assert invert_kernel(y.t, y.slices.lo, y.slices.hi, y.gates.lo, y.gates.hi, we.slices.lo,
                         we.slices.hi, 0.0, 5.0, 3.0, 3.5)[:2] == (2.0, 4.0)
    # a degenerate [t] inside a slice, and at a gate
    assert invert_kernel(y.t, y.slices.lo, y.slices.hi, y.gates.lo, y.gates.hi, w.slices.lo,
                         w.slices.hi, 3.25, 3.25, 3.0, 3.5)[:2] == (3.25, 3.25)
    assert invert_kernel(y.t, y.slices.lo, y.slices.hi, y.gates.lo, y.gates.hi, w.slices.lo,
                         w.slices.hi, 3.0, 3.0, 3.0, 3.5)[:2] == (3.0, 3.0)


def _codac_special_tube() -> tuple[Tube, Tube]:
    """Codac's "CtcEval, special cases" (tests_ctc_eval.cpp): 10 unit slices on [0, 10],
    x' in [-0.5, 1], x entire but slices 4 and 5 in [-1.5, 1] and [-1, 1.5], then CtcDeriv."""
    t = np.arange(11.0)
    xd = Tube.constant(0, 10, 10, Interval(-0.5, 1))
    s = Interval.entire(10)
    s[4], s[5] = Interval(-1.5, 1), Interval(-1, 1.5)
    x = Tube(t, s)
    CtcDeriv().contract(x, xd)
    return x, xd


# Codac's expected [t] and [z] (by hand: the cones of x' in [-0.5, 1] from the gates)
CODAC_CASES = [((0.5, 3.5), (-4, -4), (0.5, 1.5), (-4, -4)),          # test C
               ((6.5, 8.5), (-4.5, -1.75), (7.5, 8.5), (-2.25, -1.75)),  # test E
               ((6.5, 7.5), (3, 4), (7.5, 7.5), (3, 3)),               # test G
               ((8.5, 9.5), (-0.5, 2.5), (8.5, 9.5), (-0.5, 2.5)),     # test F
               ((0.5, 2.5), (-2, -2), (0.5, 2.5), (-2, -2))]           # test B


@pytest.mark.parametrize(("tm", "zm", "t_exp", "z_exp"), CODAC_CASES)
def test_eval_codac_unit_cases(tm, zm, t_exp, z_exp):
    x, xd = _codac_special_tube()
    assert (float(x.gates.lo[0]), float(x.gates.hi[0])) == (-5.5, 3.0)  # Codac's x_raw(0)
    T, Z = CtcEval().contract(Interval(*tm), Interval(*zm), x.copy(), xd)
    assert (float(T.lo), float(T.hi)) == t_exp and (float(Z.lo), float(Z.hi)) == z_exp
    # the plain inverse is never tighter
    T0, _ = CtcEval(time_deriv=False).contract(Interval(*tm), Interval(*zm), x.copy(), xd)
    assert float(T0.lo) <= t_exp[0] and t_exp[1] <= float(T0.hi)


def test_eval_codac_unit_case_2():
    # Codac's "CtcEval, 2": slices [-1, 1, 2, 3, 5, 7], x' = -1, [-1, 1], [-1, 1], -1, 1 and
    # x(2) in [0, 1]; after y(t) in [-1, 1] for t in [0, 6], the value 1.6 is reached only for
    # t in [2.6, 3.4] (x(3) in [-1, 2], then x' = -1 down to x(3.4) <= 1.6)
    t = np.array([-1.0, 1, 2, 3, 5, 7])
    x = Tube(t, Interval.entire(5))
    x.gates[2] = Interval(0, 1)
    v = Tube.piecewise_constant(t, Interval([-1, -1, -1, -1, 1], [-1, 1, 1, -1, 1]))
    CtcEval().contract(Interval(0, 6), Interval(-1, 1), x, v)
    T, Z = CtcEval().contract(Interval(1.75, 5.5), Interval(1.6), x, v)
    assert abs(float(T.lo) - 2.6) < 1e-12 and abs(float(T.hi) - 3.4) < 1e-12
    z = Fraction(1.6)  # the float: the exact bounds are 2 + (z - 1) and 3 + (2 - z)
    assert Fraction(float(T.lo)) <= 1 + z and 5 - z <= Fraction(float(T.hi))
    assert float(Z.lo) == 1.6 == float(Z.hi)


def _sin_pair_tubes() -> tuple[Tube, Tube]:
    """Codac's "CtcEval, dependency on t" (tests_ctc_eval.cpp): x = (sin t, -sin t) on
    [0, 10], slices of 0.1 (outward enclosures), and here its derivative (cos t, -cos t)."""
    def pair(f):
        def g(T: Interval) -> Interval:
            v = f(T)
            return Interval.trusted(np.stack([v.lo, -v.hi], -1), np.stack([v.hi, -v.lo], -1))
        return g
    return (Tube.from_function(0, 10, 0.1, pair(bd.sin)),
            Tube.from_function(0, 10, 0.1, pair(bd.cos)))


def test_eval_codac_dependency_on_t():
    """x(t) in [0, 2]^2 for some t in [0, 10]: sin t >= 0 and -sin t >= 0 at the same t, so
    sin t = 0, t in {0, pi, 2 pi, 3 pi}, z = (0, 0): these must stay. Per component the
    times are [0, pi] u [2 pi, 3 pi] and {0} u [pi, 2 pi] u [3 pi, 10], whose hulls share
    [0, 3 pi], where each component reaches 1: the hull per component gives [0, 1]^2.
    With the derivative the common times are near k pi only: on the slice [a, a + h] holding
    k pi (h = 0.1; k = 0 is the gate t = 0, where both are 0), both components leave the gate
    at a as +-u (u = sin a, |u| <= k pi - a) with slopes of opposite signs and magnitudes in
    [m, M], m >= cos h, M <= 1. Both are >= 0 at a + s only if s is in [|u| / M, |u| / m];
    there each is at most |u| (M / m - 1) <= h (1 / cos h - 1) = 5.0e-4, and
    a + |u| / m <= k pi + (k pi - a)(1 / m - 1) <= k pi + 5.0e-4. (Codac gives
    t = [0, 9.5] and z within 0.02 of 0, without the derivative.)"""
    x, w = _sin_pair_tubes()
    bound = 0.1 * (1 / math.cos(0.1) - 1) * (1 + 1e-6)
    T, Z = CtcEval().contract(Interval(0, 10), Interval([0, 0], [2, 2]), x.copy(), w)
    assert float(T.lo) == 0.0 and 3 * math.pi <= float(T.hi) <= 3 * math.pi + bound
    assert (Z.lo == 0).all() and (Z.hi <= bound).all()


def test_eval_codac_dependency_on_t_plain():
    """The same case on whole slices (no derivative): slice [a, a + h] is kept when both
    envelopes meet [0, 2], i.e. when it holds k pi: [0, 0.1], [3.1, 3.2], [6.2, 6.3],
    [9.4, 9.5]. So t = [0, 9.5], z_1 = [0, max sin over them] = [0, sin 0.1] (sin is largest
    at the end of [0, 0.1]), z_2 = [0, max -sin over them] = [0, -sin 6.2] (the slices give
    0, -sin 3.2, -sin 6.2, -sin 9.5). Codac intersects z with each piece's image instead of
    taking their hull, which loses trajectories of the tube (x = (0.09, 0) at t = 0.05)."""
    x, w = _sin_pair_tubes()
    T, Z = CtcEval(time_deriv=False).contract(Interval(0, 10), Interval([0, 0], [2, 2]),
                                              x.copy(), w)
    assert (float(T.lo), float(T.hi)) == (0.0, 9.5)
    assert (Z.lo == 0).all()
    assert Z.hi[0] == pytest.approx(math.sin(0.1), rel=1e-14) and Z.hi[0] >= math.sin(0.1)
    assert Z.hi[1] == pytest.approx(-math.sin(6.2), rel=1e-14) and Z.hi[1] >= -math.sin(6.2)


@examples(40, 5)
def test_eval_vector_keeps_truth(n_examples):
    @settings(max_examples=n_examples)
    @given(trajectories(), trajectories(), grids(), seeds, st.floats(0, 1), st.floats(0, 1),
           st.floats(0, 1), st.sampled_from([0.0, 1e-3, 0.1, 1.0]), st.booleans())
    def check(tr1, tr2, t, seed, where, left, right, zrad, time_deriv):
        # two components measured at the same uncertain time: the time pieces common to both
        # components, slice by slice, keep the true time, values and trajectories
        rng = np.random.default_rng(seed)
        y = Tube.stack([tube_around(tr1, t, rng), tube_around(tr2, t, rng)])
        w = Tube.stack([tube_around(tr1, t, rng, deriv=True), tube_around(tr2, t, rng, deriv=True)])
        ts = float(t[0] + where * (t[-1] - t[0]))
        tm = Interval(ts - left * (ts - t[0]), ts + right * (t[-1] - ts))
        v1, v2 = tr1.value(ts), tr2.value(ts)
        z = Interval([float(v1) - zrad - 1e-9, float(v2) - zrad - 1e-9],
                     [float(v1) + zrad + 1e-9, float(v2) + zrad + 1e-9])
        tm, z = CtcEval(time_deriv).contract(tm, z, y, w)
        assert inside(tm, mpmath.mpf(ts)) and inside(z[0], v1) and inside(z[1], v2)
        times = sample_times(t, rng)
        assert tube_keeps(y[0], tr1, times) and tube_keeps(y[1], tr2, times)

    check()


@settings(max_examples=60)
@given(trajectories(), grids(), seeds, st.floats(0, 1), st.floats(0, 1), st.floats(0, 1),
       st.sampled_from([0.0, 1e-6, 1e-3, 1e-2, 0.1, 0.5]))
def test_eval_on_entire_tube_keeps_truth(tr, t, seed, where, left, right, zrad):
    # only the measurement and the derivative bound y: the contracted tube is the envelope of
    # the trajectories through [t] x [z], the sharpest test of the propagation
    rng = np.random.default_rng(seed)
    y = Tube(t, Interval.entire(t.size - 1))
    w = tube_around(tr, t, rng, deriv=True)
    ts = float(t[0] + where * (t[-1] - t[0]))
    tm = Interval(ts - left * (ts - t[0]), ts + right * (t[-1] - ts))
    zt = tr.value(ts)
    z = Interval(float(zt) - zrad - 1e-9, float(zt) + zrad + 1e-9)
    tm, z = CtcEval().contract(tm, z, y, w)
    assert inside(tm, mpmath.mpf(ts)) and inside(z, zt)
    assert np.all(np.isfinite(y.gates.lo)) and np.all(np.isfinite(y.slices.hi))
    assert tube_keeps(y, tr, sample_times(t, rng))


@settings(max_examples=30)
@given(trajectories(), grids(), seeds, st.floats(0, 1))
def test_eval_then_deriv_keep_truth(tr, t, seed, where):
    # entire tube, one exact-time measurement, then CtcDeriv: the truth survives both
    rng = np.random.default_rng(seed)
    y = Tube.constant(t[0], t[-1], 1, Interval.entire())
    y = Tube(t, Interval.entire(t.size - 1))
    w = tube_around(tr, t, rng, deriv=True)
    ts = float(t[0] + where * (t[-1] - t[0]))
    zt = tr.value(ts)
    z = Interval(float(zt) - 0.1, float(zt) + 0.1)
    tm = Interval(max(t[0], ts - 0.5), min(t[-1], ts + 0.5))
    CtcEval().contract(tm, z, y, w)
    assert np.all(np.isfinite(y.gates.lo))  # the measurement bounds the whole tube
    CtcDeriv().contract(y, w)
    assert tube_keeps(y, tr, sample_times(t, rng))


def test_eval_by_hand():
    # y' = 1, y in [-10, 10], y(t) = 0 for some t in [2, 8]: y(s) = s - t1, t1 in [2, 8]
    y = Tube.constant(0, 10, 100, Interval(-10, 10))
    w = Tube.constant(0, 10, 100, Interval(1, 1))
    t, z = CtcEval().contract(Interval(2, 8), Interval(0, 0), y, w)
    assert float(t.lo) == 2 and float(t.hi) == 8 and float(z.lo) == 0 == float(z.hi)
    e9, e1, e5 = y(9.0), y(1.0), y(5.0)
    assert 1 - 1e-9 < float(e9.lo) <= 1 and 7 <= float(e9.hi) < 7 + 1e-9
    assert -7 - 1e-9 < float(e1.lo) <= -7 and -1 <= float(e1.hi) < -1 + 1e-9
    assert -3 - 1e-9 < float(e5.lo) <= -3 and 3 <= float(e5.hi) < 3 + 1e-9
    # a second measurement: y(t) in [3, 3.5] for t in [4, 9]; trajectories s - t1 reach 3 at
    # t1 + 3 in [5, 11]: t contracts to [5 - dt, 9]
    t2, _ = CtcEval().contract(Interval(4, 9), Interval(3, 3.5), y, w)
    assert 4.8 <= float(t2.lo) <= 5.0 and float(t2.hi) == 9


def test_eval_degenerate_and_unbounded():
    # y' = 1 and y(5) = 0 exactly (a gate time): y(t_i) = t_i - 5 at every gate, to rounding
    y = Tube.constant(0, 10, 100, Interval.entire())
    w = Tube.constant(0, 10, 100, Interval(1, 1))
    t, z = CtcEval().contract(Interval(5, 5), Interval(0, 0), y, w)
    assert float(t.lo) == 5 == float(t.hi) and float(z.lo) == 0 == float(z.hi)
    exact = y.t - 5
    assert np.all(y.gates.lo <= exact) and np.all(exact <= y.gates.hi)
    assert np.max(y.gates.hi - y.gates.lo) < 1e-13
    # the same at a time inside slice 50 = [t_50, t_51] ~ [5, 5.1]: y(s) = s - 5.05 there, so
    # the slice becomes [t_50 - 5.05, t_51 - 5.05] (the polygon; the box alone gives +-0.1)
    y = Tube.constant(0, 10, 100, Interval.entire())
    CtcEval().contract(Interval(5.05, 5.05), Interval(0, 0), y, w)
    s = y.slices[50]
    lo, hi = Fraction(y.t[50]) - Fraction(5.05), Fraction(y.t[51]) - Fraction(5.05)
    assert lo - Fraction(1e-13) < Fraction(float(s.lo)) <= lo
    assert hi <= Fraction(float(s.hi)) < hi + Fraction(1e-13)
    # an unbounded derivative: y may leave [z] at once, nothing is learnt outside (t1 itself
    # is unknown in [2, 3], so even the gates inside [t] stay entire)
    y = Tube.constant(0, 10, 100, Interval.entire())
    t, z = CtcEval().contract(Interval(2, 3), Interval(0, 1), y, Tube.constant(0, 10, 100))
    assert float(t.lo) == 2 and float(t.hi) == 3 and float(z.lo) == 0 and float(z.hi) == 1
    assert np.all(y.gates.is_entire()) and np.all(y.slices.is_entire())
    # ... but a degenerate time pins the gate there
    CtcEval().contract(Interval(2, 2), Interval(0, 1), y, Tube.constant(0, 10, 100))
    assert float(y.gates.lo[20]) == 0 and float(y.gates.hi[20]) == 1
    assert np.all(y.gates[21:].is_entire())


def test_eval_contracts_time_and_value():
    # y(s) in [s, s + 1] (thin, increasing): y(t) in [5, 5.5] => t in [4, 5.5]
    t = np.linspace(0, 10, 1001)
    y = Tube(t, Interval(t[:-1], t[1:] + 1), Interval(t, t + 1))
    w = Tube.constant(0, 10, 1000, Interval(1, 1))
    tm, z = CtcEval().contract(Interval(0, 10), Interval(5, 5.5), y, w)
    assert 3.98 <= float(tm.lo) <= 4.0 and 5.5 <= float(tm.hi) <= 5.52
    # z contracted by y([t]) when [t] is narrow: y([1, 2]) = [1, 3]
    tm, z = CtcEval().contract(Interval(1, 2), Interval(-10, 10), y.copy(), w)
    assert float(z.lo) == 1 and float(z.hi) == 3


def test_eval_inconsistent_is_empty():
    y = Tube.constant(0, 10, 100, Interval(-1, 1))
    w = Tube.constant(0, 10, 100, Interval(-1, 1))
    t, z = CtcEval().contract(Interval(2, 3), Interval(5, 6), y, w)
    assert t.is_empty() and z.is_empty() and y.is_empty()
    # consistent in value but not with the derivative: y(0) = 0 (gate), y' in [0, 0.1],
    # y(t) = 5 for t in [1, 2] is out of reach
    y = Tube.constant(0, 10, 100, Interval(-10, 10))
    y.gates[0] = Interval(0, 0)
    w = Tube.constant(0, 10, 100, Interval(0, 0.1))
    CtcDeriv().contract(y, w)
    t, z = CtcEval().contract(Interval(1, 2), Interval(5, 5), y, w)
    assert t.is_empty() and y.is_empty()
    # a time outside the domain
    y = Tube.constant(0, 10, 100, Interval(-10, 10))
    t, z = CtcEval().contract(Interval(20, 30), Interval(0, 1), y, w)
    assert t.is_empty() and y.is_empty()


def test_eval_vector():
    # y = (s, -s) thin; measurement (5, -5) +- 0.1 at t in [0, 10] => t near 5
    t = np.linspace(0, 10, 101)
    y = Tube.stack([Tube(t, Interval(t[:-1], t[1:])), Tube(t, Interval(-t[1:], -t[:-1]))])
    w = Tube.stack([Tube.constant(0, 10, 100, Interval(1, 1)),
                    Tube.constant(0, 10, 100, Interval(-1, -1))])
    tm, _ = CtcEval().contract(Interval(0, 10), Interval([4.9, -5.1], [5.1, -4.9]), y, w)
    assert 4.7 <= float(tm.lo) <= 4.9 and 5.1 <= float(tm.hi) <= 5.3


# -- CtcSlices and the network --
def test_ctc_slices_with_parameter():
    x, v, p = Var("x"), Var("v"), Var("p")
    ctc = CtcSlices([v == p * x], ["x", "v", "p"])
    X = Tube.constant(0, 1, 10, Interval(1, 2))
    V = Tube.constant(0, 1, 10, Interval(-10, 10))
    P = Interval(-1, 3)
    ctc.contract(X, V, P)
    assert float(V(0.5).lo) == -2 and float(V(0.5).hi) == 6
    V2 = Tube.constant(0, 1, 10, Interval(2, 3))
    ctc.contract(X, V2, P)  # p = v / x in [1, 3]
    assert float(P.lo) == 1 and float(P.hi) == 3
    ctc.contract(X, Tube.constant(0, 1, 10, Interval(10, 11)), P)  # p would be >= 5
    assert P.is_empty() and X.is_empty()


@settings(max_examples=15)
@given(trajectories(), grids(), seeds)
def test_network_keeps_truth(tr, t, seed):
    # x' = v, v = u (u the exact derivative enclosure), two measurements, x otherwise unknown
    rng = np.random.default_rng(seed)
    u = tube_around(tr, t, rng, deriv=True)
    x = Tube(t, Interval.entire(t.size - 1))
    v = Tube(t, Interval.entire(t.size - 1))
    cn = ContractorNetwork()
    cn.add(CtcSlices([Var("v") == Var("u")], ["v", "u"]), [v, u])
    cn.add(CtcDeriv(), [x, v])
    meas = []
    for s in rng.uniform(t[0], t[-1], 2):
        zt = float(tr.value(float(s)))
        tm = Interval(max(t[0], s - 0.3), min(t[-1], s + 0.3))
        z = Interval(zt - 0.2, zt + 0.2)
        meas.append((float(s), tm, z))
        cn.add(CtcEval(), [tm, z, x, v])
    report = cn.contract(rel_eps=1e-6, max_iter=50, progress=False)
    assert not report.empty and report.iterations == len(report.contraction) >= 2
    assert report.converged or report.iterations == 50
    assert np.all(np.isfinite(x.gates.lo))
    assert tube_keeps(x, tr, sample_times(t, rng, 20))
    for s, tm, _ in meas:
        assert inside(tm, mpmath.mpf(s))


def test_network_report_and_errors():
    x = Tube.constant(0, 1, 10, Interval.entire())
    x.gates[0] = Interval(0, 0)
    v = Tube.constant(0, 1, 10, Interval(-1, 1))
    cn = ContractorNetwork()
    cn.add(CtcDeriv(), [x, v])
    r = cn.contract()
    # iteration 1 bounds the 10 slices and the 10 unknown gates; iteration 2 changes nothing
    assert r.iterations == 2 and r.newly_bounded[0] == 10 + 10 and r.contraction[1] == 0
    assert r.converged and not r.empty
    x.gates[10] = Interval(5, 6)  # out of reach with |x'| <= 1
    r = cn.contract()
    assert r.empty and r.iterations == 1
    with pytest.raises(ValueError, match="rel_eps"):
        cn.contract(rel_eps=2)
    with pytest.raises(ValueError, match="domains"):
        cn.add(CtcDeriv(), [x, 3.0])


def test_network_progress_has_no_false_total(monkeypatch):
    # the iteration cap is not a forecast: the bar counts iterations and shows the contraction
    import io
    import sys

    class Terminal(io.StringIO):  # bars are drawn on a terminal only
        def isatty(self) -> bool:
            return True

    x = Tube.constant(0, 1, 10, Interval.entire())
    x.gates[0] = Interval(0, 0)
    cn = ContractorNetwork()
    cn.add(CtcDeriv(), [x, Tube.constant(0, 1, 10, Interval(-1, 1))])
    term = Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    report = cn.contract(max_iter=100, progress=True)
    err = term.getvalue()
    assert f"{report.iterations}it" in err and "/100" not in err and "contraction=" in err
