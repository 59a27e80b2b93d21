"""Tubes with jumps: piecewise-continuous signals (derivatives, held samples, bang-bang inputs).

A derivative may jump at a gate: its neighbouring slices need not overlap, and the gate carries
no constraint on them. The truth here is ``v(s) = c_k + g'(s)`` on piece ``k`` (break times at
random gates and inside slices, right-continuous), with ``x(s) = x0 + g(s) - g(t0) +
Σ_k c_k |[t0, s] ∩ piece_k|`` evaluated exactly with mpmath: ``x`` is continuous with kinks, its
derivative jumps. Every contractor and integral must keep it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from itertools import pairwise

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from boundest import Interval, Var
from boundest.tube import ContractorNetwork, CtcDeriv, CtcEval, CtcSlices, Tube

from .checks import examples
from .test_tube import Traj, grids, inside, sample_times, seeds, trajectories, widen

INF = math.inf


@dataclass
class Jumpy:
    """``v = c_k + g'`` on ``[tau_k, tau_{k+1})``; ``x = x0 + ∫_{t0} v`` (exact, mpmath)."""

    g: Traj
    tau: np.ndarray  # break times, tau[0] = t0, tau[-1] = tf
    c: np.ndarray  # one constant per piece
    x0: float

    def piece(self, s: float) -> int:
        k = int(np.searchsorted(self.tau, s, side="right")) - 1
        return min(max(k, 0), self.c.size - 1)

    def v(self, s: float) -> mpmath.mpf:
        return mpmath.mpf(float(self.c[self.piece(s)])) + self.g.deriv(s)

    def x(self, s: float) -> mpmath.mpf:
        """``x0 + (x(s) - x(t0))``, the increment free of cancellation (:meth:`increment`)."""
        return mpmath.mpf(self.x0) + self.increment(float(self.tau[0]), s)

    def increment(self, r: float, s: float) -> mpmath.mpf:
        """``x(s) - x(r)`` free of cancellation: ``g(s) - g(r)`` by the sine difference formula
        with the exact ``s - r`` (times differ by as little as 1e-131, where the increment is of
        order 1e-99 next to values of order 1: subtracting values of ``x`` would need more
        digits than any fixed precision), plus the constant pieces between ``r`` and ``s``."""
        r_mp, s_mp = mpmath.mpf(r), mpmath.mpf(s)
        h = mpmath.fsub(s_mp, r_mp, exact=True)
        mid = mpmath.fadd(s_mp, r_mp, exact=True) / 2
        out = mpmath.mpf(0)
        for a, w, p in zip(self.g.a, self.g.w, self.g.p, strict=True):
            out += 2 * a * mpmath.cos(w * mid + p) * mpmath.sin(w * h / 2)
        sign, lo_t, hi_t = (1, r_mp, s_mp) if s_mp >= r_mp else (-1, s_mp, r_mp)
        for k in range(self.c.size):
            a = max(lo_t, mpmath.mpf(float(self.tau[k])))
            b = min(hi_t, mpmath.mpf(float(self.tau[k + 1])))
            if b > a:
                out += sign * mpmath.mpf(float(self.c[k])) * mpmath.fsub(b, a, exact=True)
        return out

    def v_slices(self, t: np.ndarray) -> Interval:
        """Sound enclosure of ``v`` on each open slice ``]t_i, t_{i+1}[``."""
        lo, hi = t[:-1], t[1:]
        meets = (self.tau[:-1][None, :] < hi[:, None]) & (self.tau[1:][None, :] > lo[:, None])
        c_lo = np.min(np.where(meets, self.c[None, :], INF), axis=1)
        c_hi = np.max(np.where(meets, self.c[None, :], -INF), axis=1)
        return Interval(c_lo, c_hi) + self.g.enclose_deriv(Interval.trusted(lo, hi))


@st.composite
def jumpy(draw, t: np.ndarray) -> Jumpy:
    """Breaks at a random subset of the inner gates and at random times inside slices."""
    g = draw(trajectories())
    inner_gates = t[1:-1]
    at_gates = [s for s in inner_gates if draw(st.integers(0, 3)) == 0] if inner_gates.size <= 60 \
        else list(inner_gates[:: draw(st.integers(1, 7))])
    inside_slices = draw(st.lists(st.floats(0.01, 0.99), max_size=4))
    tau = np.unique(np.concatenate([[t[0], t[-1]], at_gates,
                                    [t[0] + (t[-1] - t[0]) * u for u in inside_slices]]))
    c = np.array(draw(st.lists(st.sampled_from([-2.0, -1.0, 0.0, 0.5, 1.0, 3.0]),
                               min_size=tau.size - 1, max_size=tau.size - 1)))
    return Jumpy(g=g, tau=tau, c=c, x0=draw(st.floats(-5, 5)))


@st.composite
def cases(draw):
    t = draw(grids())
    return t, draw(jumpy(t))


def keeps(y: Tube, f, times: np.ndarray) -> bool:
    """Exact values ``f(s)`` at ``times`` lie in the tube (by ``y(s)``: the gate at a gate time)."""
    return all(inside(y(float(s)), f(float(s))) for s in times)


def derivative_tube(jp: Jumpy, t: np.ndarray, rng: np.random.Generator) -> Tube:
    return Tube.piecewise_constant(t, widen(jp.v_slices(t), rng))


def state_tube(jp: Jumpy, t: np.ndarray, rng: np.random.Generator) -> Tube:
    """Entire except the first gate, which encloses ``x0``."""
    x = Tube(t, Interval.entire(t.size - 1))
    x.gates[0] = Interval(jp.x0).inflate(float(rng.uniform(0, 0.3)))
    return x


# -- the example, derived by hand --
def test_bang_bang_example():
    # x' = 1 on [0, 1], x' = -1 on [1, 2], x(0) = 0: x(t) = min(t, 2 - t)
    v = Tube.piecewise_constant([0.0, 1.0, 2.0], Interval([1.0, -1.0], [1.0, -1.0]))
    assert not v.is_empty() and not v.continuous
    x = Tube.constant(0, 2, 2, Interval.entire())
    x.gates[0] = Interval(0.0, 0.0)
    CtcDeriv().contract(x, v)
    assert x.gates.lo.tolist() == [0.0, 1.0, 0.0] and x.gates.hi.tolist() == [0.0, 1.0, 0.0]
    assert x.slices.lo.tolist() == [0.0, 0.0] and x.slices.hi.tolist() == [1.0, 1.0]
    assert x.contains([0.0, 0.5, 1.0, 1.5, 2.0], [0.0, 0.5, 1.0, 0.5, 0.0])
    # and with an observation x(t) = 1 for t in [0, 2]: only t = 1 fits
    t, z = Interval(0.0, 2.0), Interval(1.0, 1.0)
    CtcEval().contract(t, z, x, v)
    assert float(t.lo) <= 1.0 <= float(t.hi) and float(z.lo) == 1.0
    assert float(v.integral(0.0, 2.0).lo) == 0.0 == float(v.integral(0.0, 2.0).hi)


def test_continuous_constructor_rejects_disjoint_slices():
    with pytest.raises(ValueError, match=r"slices 0 \[1.0, 1.0\] and 1 \[-1.0, -1.0\] do not "
                                         r"overlap.*t = 1.0.*piecewise_constant"):
        Tube([0.0, 1.0, 2.0], Interval([1.0, -1.0], [1.0, -1.0]))
    with pytest.raises(ValueError, match=r"component 1"):
        Tube([0.0, 1.0, 2.0], Interval([[0, 0], [0, 2]], [[1, 1], [1, 3]]))


# -- semantics of a tube with jumps --
def test_jump_tube_gates_evaluation_and_contains():
    v = Tube.piecewise_constant([0.0, 1.0, 2.0, 3.0], Interval([0.0, 5.0, -1.0],
                                                              [1.0, 6.0, -1.0]))
    # gates: the hull of the neighbouring slices (left or right value at a jump)
    assert v.gates.lo.tolist() == [0.0, 0.0, -1.0, -1.0]
    assert v.gates.hi.tolist() == [1.0, 6.0, 6.0, -1.0]
    assert float(v(Interval(0.5, 1.5)).lo) == 0.0 and float(v(Interval(0.5, 1.5)).hi) == 6.0
    # a held sample: right-continuous values, checked at the gates against the gate only
    assert v.contains([0.0, 1.0, 1.5, 2.0, 2.5, 3.0], [0.5, 5.5, 5.5, -1.0, -1.0, -1.0])
    assert not v.contains([1.5], [0.5])
    # given gates are kept as they are (not intersected with the slices)
    w = Tube.piecewise_constant([0.0, 1.0, 2.0], Interval([0.0, 5.0], [1.0, 6.0]),
                                gates=Interval([-9.0, -9.0, -9.0], [9.0, 9.0, 9.0]))
    assert w.gates.lo.tolist() == [-9.0] * 3
    assert "continuous=False" in repr(w)


def test_jump_tube_flags_through_operations():
    t = [0.0, 1.0, 2.0]
    v = Tube.piecewise_constant(t, Interval([1.0, -1.0], [1.0, -1.0]))
    c = Tube.constant(0, 2, 2, Interval(-2, 2))
    assert not (v + c).continuous and not (2 * v).continuous and (c * c).continuous
    assert not v.copy().continuous and not (v | v).continuous and not v.subtube(0.5, 2).continuous
    assert v.primitive(0.0).continuous  # an integral is continuous
    # an intersection with a continuous tube is continuous: gates inside both slices
    both = v & c
    assert both.continuous and both.is_empty()  # 1 and -1 cannot meet at t = 1
    vec = Tube.stack([v, c])
    assert not vec.continuous and not vec[0].continuous
    # make_continuous proves what a derivative constraint proves
    u = Tube.piecewise_constant(t, Interval([0.0, 0.5], [1.0, 2.0]))
    u.make_continuous()
    assert u.continuous and u.gates.lo.tolist() == [0.0, 0.5, 0.5]
    assert u.gates.hi.tolist() == [1.0, 1.0, 2.0]


def test_held_samples_vector_zero_order_hold():
    # boxes held over each sample, as sensor data: 3 components, sample period 0.1
    rng = np.random.default_rng(1)
    n = 1000
    t = 0.1 * np.arange(n + 1)
    mid = rng.normal(size=(n, 3)).cumsum(axis=0)
    v = Tube.piecewise_constant(t, Interval(mid - 0.01, mid + 0.01))
    assert v.dim == 3 and not v.is_empty()
    x = Tube(t, Interval.entire((n, 3)))
    x.gates[0] = Interval([0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    CtcDeriv().contract(x, v)
    assert not x.is_empty()
    # the exact position of the mid trajectory at every gate, in rationals
    h = [Fraction(float(b)) - Fraction(float(a)) for a, b in pairwise(t)]
    for j in range(3):
        acc = Fraction(0)
        for k in range(n + 1):
            assert Fraction(float(x.gates.lo[k, j])) <= acc <= Fraction(float(x.gates.hi[k, j]))
            if k < n:
                acc += h[k] * Fraction(float(mid[k, j]))
    # the width grows by 0.02 h per sample: 2.0 at the end, up to rounding
    assert float(np.max(x.gates.hi - x.gates.lo)) < 2.0 + 1e-6


# -- property tests: the truth survives --
@examples(60, 6)
def test_deriv_with_jumps_keeps_truth(n_examples):
    @settings(max_examples=n_examples, deadline=None)
    @given(cases(), seeds)
    def check(case, seed):
        t, jp = case
        rng = np.random.default_rng(seed)
        v = derivative_tube(jp, t, rng)
        assert keeps(v, jp.v, sample_times(t, rng, 30))  # the derivative tube itself
        x = state_tube(jp, t, rng)
        CtcDeriv().contract(x, v)
        assert not x.is_empty() and x.continuous
        times = sample_times(t, rng)
        assert keeps(x, jp.x, times)
        # and backward: from a last gate only
        xb = Tube(t, Interval.entire(t.size - 1))
        xb.gates[-1] = Interval(float(jp.x(float(t[-1])))).inflate(1e-9)
        CtcDeriv().contract(xb, v)
        assert keeps(xb, jp.x, times)

    check()


@examples(40, 10)
def test_eval_with_jumps_keeps_truth(n_examples):
    @settings(max_examples=n_examples, deadline=None)
    @given(cases(), seeds, st.floats(0, 1), st.floats(0, 0.3), st.floats(0, 0.5))
    def check(case, seed, u, dt, dz):
        t, jp = case
        rng = np.random.default_rng(seed)
        v = derivative_tube(jp, t, rng)
        y = state_tube(jp, t, rng) if rng.random() < 0.5 else Tube(t, Interval.entire(t.size - 1))
        t_true = float(t[0] + u * (t[-1] - t[0]))
        if rng.random() < 0.3:
            t_true = float(t[rng.integers(t.size)])  # at a gate, where v jumps
        z_true = jp.x(t_true)
        T = Interval(max(t_true - dt, t[0]), min(t_true + dt, t[-1]))
        z = Interval(float(z_true)).inflate(1e-9 + dz)
        assert inside(z, z_true)
        CtcEval().contract(T, z, y, v)
        assert not y.is_empty()
        assert float(T.lo) <= t_true <= float(T.hi)
        assert inside(z, z_true)
        assert keeps(y, jp.x, sample_times(t, rng))

    check()


@pytest.mark.slow  # about 20 s on 2 cores
@settings(max_examples=60, deadline=None)
@given(cases(), seeds, st.floats(0, 1), st.floats(0, 1), st.floats(0, 0.2))
def test_integrals_with_jumps_keep_truth(case, seed, a, b, r):
    t, jp = case
    rng = np.random.default_rng(seed)
    v = derivative_tube(jp, t, rng)
    a, b = sorted((float(t[0] + a * (t[-1] - t[0])), float(t[0] + b * (t[-1] - t[0]))))
    exact = jp.increment(a, b)
    assert inside(v.integral(a, b), exact)
    # uncertain bounds: every t1 in [t1], t2 in [t2] (sampled at the ends and inside)
    A = Interval(max(a - r, float(t[0])), a)
    B = Interval(b, min(b + r, float(t[-1])))
    enc = v.integral(A, B)
    for s1 in (float(A.lo), a):
        for s2 in (b, float(B.hi)):
            assert inside(enc, jp.increment(s1, s2))
    prim = v.primitive(Interval(jp.x0))
    assert prim.continuous
    assert keeps(prim, jp.x, sample_times(t, rng))


@examples(25, 6)
def test_network_with_held_input_keeps_truth(n_examples):
    """``x' = v``, ``v = 2 u - 1`` with ``u`` a held input: CtcSlices acts on jump tubes."""
    @settings(max_examples=n_examples, deadline=None)
    @given(cases(), seeds)
    def check(case, seed):
        t, jp = case
        rng = np.random.default_rng(seed)
        # u = (v + 1) / 2 is the held input; v is unknown (entire, with jumps)
        vs = widen(jp.v_slices(t), rng)
        u = Tube.piecewise_constant(t, (vs + 1) / 2)
        v = Tube.piecewise_constant(t, Interval.entire(t.size - 1))
        x = state_tube(jp, t, rng)
        U, V = Var("u"), Var("v")
        cn = ContractorNetwork()
        cn.add(CtcSlices([V == 2 * U - 1], ["u", "v"]), [u, v])
        cn.add(CtcDeriv(), [x, v])
        report = cn.contract()
        assert not report.empty
        times = sample_times(t, rng)
        assert keeps(x, jp.x, times)
        # away from the gates v is enclosed (at a gate, v(t_i) is either neighbour's value)
        inner = times[~np.isin(times, t)]
        assert keeps(v, jp.v, inner)

    check()
