"""Tubes (boundest.tube.Tube): construction, evaluation, inversion, integrals, arithmetic.

Soundness is checked against random smooth trajectories ``x(t) = c + Σ a_k sin(ω_k t + φ_k)``
whose values, derivatives and antiderivatives are evaluated exactly (mpmath, 60 digits) at
sample times: every sample must lie inside the tubes built from sound interval enclosures of the
trajectory (boundest.interval over the slices' time intervals, widened at random).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import boundest.interval as iv
import boundest.tube as bt
from boundest import Interval
from boundest.tube import Tube, time_grid

mpmath.mp.dps = 60
INF = math.inf


@dataclass
class Traj:
    """``c + Σ a_k sin(ω_k t + φ_k)``: exact value, derivative and antiderivative."""

    c: float
    a: list[float]
    w: list[float]
    p: list[float]

    def value(self, s: float) -> mpmath.mpf:
        s = mpmath.mpf(s)
        return self.c + sum(a * mpmath.sin(w * s + p) for a, w, p in
                            zip(self.a, self.w, self.p, strict=True))

    def deriv(self, s: float) -> mpmath.mpf:
        s = mpmath.mpf(s)
        return sum(a * w * mpmath.cos(w * s + p) for a, w, p in
                   zip(self.a, self.w, self.p, strict=True))

    def anti(self, s: float) -> mpmath.mpf:
        s = mpmath.mpf(s)
        return self.c * s - sum(a / mpmath.mpf(w) * mpmath.cos(w * s + p) for a, w, p in
                                zip(self.a, self.w, self.p, strict=True))

    def enclose(self, T: Interval) -> Interval:
        """Sound enclosure over the time intervals ``T`` (boundest.interval)."""
        out = Interval(self.c) + 0 * T
        for a, w, p in zip(self.a, self.w, self.p, strict=True):
            out = out + a * iv.sin(w * T + p)
        return out

    def enclose_deriv(self, T: Interval) -> Interval:
        out = 0 * T
        for a, w, p in zip(self.a, self.w, self.p, strict=True):
            out = out + Interval(a) * w * iv.cos(w * T + p)
        return out


@st.composite
def trajectories(draw) -> Traj:
    k = draw(st.integers(1, 3))
    fl = st.floats
    return Traj(c=draw(fl(-5, 5)), a=[draw(fl(0.1, 3)) for _ in range(k)],
                w=[draw(fl(0.1, 3)) for _ in range(k)], p=[draw(fl(-3, 3)) for _ in range(k)])


@st.composite
def grids(draw) -> np.ndarray:
    """Gate times: uniform or random, 1 to 200 slices over a domain of length 0.5 to 20."""
    t0 = draw(st.floats(-10, 10))
    length = draw(st.floats(0.5, 20))
    n = draw(st.integers(1, 200))
    if draw(st.booleans()):
        return time_grid(t0, t0 + length, n)
    inner = np.sort(np.array(draw(st.lists(st.floats(0.001, 0.999), min_size=n - 1,
                                           max_size=n - 1))))
    t = np.unique(np.concatenate([[t0], t0 + length * inner, [t0 + length]]))
    return t


def widen(x: Interval, rng: np.random.Generator, p_entire: float = 0.0) -> Interval:
    """``x`` widened by random non-negative radii; some entries made entire."""
    r = rng.uniform(0, 0.5, x.shape) * rng.integers(0, 2, x.shape)
    out = x.inflate(r)
    mask = rng.random(x.shape) < p_entire
    return Interval.trusted(np.where(mask, -INF, out.lo), np.where(mask, INF, out.hi))


def tube_around(tr: Traj, t: np.ndarray, rng: np.random.Generator, p_entire: float = 0.0,
                deriv: bool = False) -> Tube:
    f = tr.enclose_deriv if deriv else tr.enclose
    slices = widen(f(Interval.trusted(t[:-1], t[1:])), rng, p_entire)
    gates = widen(f(Interval.trusted(t, t)), rng, p_entire)
    return Tube(t, slices, gates)


def sample_times(t: np.ndarray, rng: np.random.Generator, k: int = 60) -> np.ndarray:
    """All gate times (up to 200) plus random times inside slices."""
    inner = rng.uniform(t[0], t[-1], k)
    gates = t if t.size <= 200 else t[rng.choice(t.size, 200, replace=False)]
    return np.concatenate([gates, inner])


def inside(x: Interval, v: mpmath.mpf) -> bool:
    """Whether the exact ``v`` lies in the scalar interval ``x``."""
    lo, hi = float(x.lo), float(x.hi)
    return not math.isnan(lo) and mpmath.mpf(lo) <= v <= mpmath.mpf(hi)


def tube_keeps(y: Tube, tr: Traj, times: np.ndarray, fn: str = "value") -> bool:
    """Exact trajectory values at ``times`` lie in the tube (gates and the slices around)."""
    f = getattr(tr, fn)
    for s in times:
        v = f(float(s))
        i = int(np.clip(np.searchsorted(y.t, s, side="right") - 1, 0, y.n_slices - 1))
        j = int(np.clip(np.searchsorted(y.t, s, side="left") - 1, 0, y.n_slices - 1))
        if not (inside(y(float(s)), v) and inside(y.slices[i], v) and inside(y.slices[j], v)):
            return False
    return True


seeds = st.integers(0, 2**32 - 1)


# -- construction and errors --
def test_time_grid_and_constant():
    t = time_grid(0, 1, 0.3)
    assert t.tolist() == [0.0, 0.3, 0.6, 0.8999999999999999, 1.0]
    assert time_grid(0, 1, 4).tolist() == [0, 0.25, 0.5, 0.75, 1]
    x = Tube.constant(0, 1, 4, Interval([0, 1], [2, 3]))
    assert x.dim == 2 and x.is_vector and x.n_slices == 4 and len(x) == 4
    assert x.domain == (0.0, 1.0)
    assert np.all(x.slices.lo == [0, 1]) and x.gates.shape == (5, 2)
    assert x.volume() == pytest.approx(4.0)  # widths 2 + 2 over a unit domain
    assert x.max_thickness() == 2.0
    assert Tube.constant(0, 2, 4).volume() == INF


@pytest.mark.parametrize("args, match", [
    (([0, 1, 1], Interval([0, 0], [1, 1])), "strictly increasing"),
    (([0, np.nan], Interval([0], [1])), "non-finite"),
    (([0, 1, 2], Interval([0], [1])), "shape"),
])
def test_bad_tubes(args, match):
    with pytest.raises(ValueError, match=match):
        Tube(*args)


def test_bad_inputs():
    with pytest.raises(ValueError, match="t0 < tf"):
        time_grid(1, 0, 0.1)
    with pytest.raises(ValueError, match="positive"):
        time_grid(0, 1, -0.1)
    with pytest.raises(ValueError, match="not finite"):
        Tube.from_samples([0, 1, 2], [0, np.nan, 1], 0.1)
    with pytest.raises(ValueError, match="non-negative"):
        Tube.from_samples([0, 1, 2], [0, 1, 1], -0.1)
    x = Tube.constant(0, 1, 4, Interval(0, 1))
    with pytest.raises(ValueError, match="outside the tube domain"):
        x(1.5)
    with pytest.raises(ValueError, match="outside the tube domain"):
        x(Interval(-1, 0.5))
    with pytest.raises(ValueError, match="t1 <= t2"):
        x.integral(0.8, 0.2)
    with pytest.raises(ValueError, match="gate times"):
        _ = x + Tube.constant(0, 1, 5, Interval(0, 1))


def test_from_samples_and_contains():
    y = Tube.from_samples([0.0, 1.0, 2.0], [0.0, 2.0, 1.0], 0.5)
    assert y(1.0).lo < 1.5 + 1e-12 and y(1.0).hi > 2.5 - 1e-12
    assert float(y(0.5).lo) <= -0.5 and float(y(0.5).hi) >= 2.5  # hull of samples, widened
    assert y.contains([0, 0.5, 1, 2], [0.1, 1.0, 2.4, 0.6])
    assert not y.contains([1.0], [2.6])


def test_gates_inside_slices_and_subtube():
    s = Interval([0.0, 1.0], [2.0, 3.0])
    y = Tube([0, 1, 2], s)
    assert y.gates.lo.tolist() == [0.0, 1.0, 1.0] and y.gates.hi.tolist() == [2.0, 2.0, 3.0]
    y = Tube([0, 1, 2], s, Interval([-5, -5, -5], [5, 5, 5]))
    assert y.gates.lo.tolist() == [0.0, 1.0, 1.0]
    sub = Tube.constant(0, 10, 10, Interval(0, 1)).subtube(2.5, 7)
    assert sub.t.tolist() == [2.5, 3, 4, 5, 6, 7] and sub.n_slices == 5


def test_empty_tube_propagates():
    y = Tube([0, 1, 2], Interval([0.0, 0.0], [1.0, 1.0]), Interval([5, 0, 0], [6, 1, 1]))
    assert y.is_empty() and np.all(np.isnan(y.slices.lo))
    assert (y + 1).is_empty() and y.primitive().is_empty()
    assert y.integral(0, 2).is_empty()
    assert y.inverse(Interval(0, 1)) == []
    assert not y.contains([0.5], [0.5])


def test_vector_component_is_a_view():
    x = Tube.constant(0, 1, 4, Interval([0, 1], [2, 3]))
    x[1].slices[2] = Interval(1.5, 2)
    assert x.slices[2, 1].lo == 1.5
    v = Tube.stack([x[0], x[1]])
    assert v.slices.shape == (4, 2) and v.slices[2, 1].lo == 1.5


# -- evaluation and inversion --
def test_eval_and_inverse_by_hand():
    # slices [0,1], [1,2], [2,3], [3,4] on gates 0..4; gates degenerate at 0, 1, 2, 3, 4
    t = np.arange(5.0)
    y = Tube(t, Interval([0, 1, 2, 3], [1, 2, 3, 4]), Interval(t, t))
    assert float(y(2.0).lo) == 2.0 and float(y(2.0).hi) == 2.0  # a gate
    assert float(y(2.5).lo) == 2.0 and float(y(2.5).hi) == 3.0  # a slice
    e = y(Interval(0.5, 2.0))
    assert float(e.lo) == 0.0 and float(e.hi) == 2.0  # slices 0, 1 and gates 1, 2
    pieces = y.inverse(Interval(1.2, 2.5))
    assert len(pieces) == 1 and float(pieces[0].lo) == 1 and float(pieces[0].hi) == 3
    # only slice 2 meets [2.5, 2.6] (the gates at 2 and 3 miss it)
    p = y.inverse(Interval(2.5, 2.6))
    assert len(p) == 1 and float(p[0].lo) == 2 and float(p[0].hi) == 3
    # a tube that leaves [0, 0.2] over ]1, 3[: two pieces
    y2 = Tube(t, Interval([0, 0.3, 0.3, 0], [0.5, 2, 2, 0.5]),
              Interval([0, 0.3, 1.5, 0.3, 0], [0.5, 0.5, 1.5, 0.5, 0.5]))
    p = y2.inverse(Interval(0, 0.2))
    assert [(float(q.lo), float(q.hi)) for q in p] == [(0, 1), (3, 4)]
    h = y2.inverse(Interval(0, 0.2), hull=True)
    assert float(h.lo) == 0 and float(h.hi) == 4
    assert y2.inverse(Interval(10, 11)) == []
    assert y2.inverse(Interval(10, 11), hull=True).is_empty()


@settings(max_examples=40)
@given(trajectories(), grids(), seeds, st.floats(-6, 6), st.floats(0, 3))
def test_inverse_keeps_every_time(tr, t, seed, zc, zr):
    rng = np.random.default_rng(seed)
    y = tube_around(tr, t, rng, p_entire=0.05)
    z = Interval(zc - zr, zc + zr)
    pieces = y.inverse(z)
    h = y.inverse(z, hull=True)
    for s in sample_times(t, rng):
        v = tr.value(float(s))
        if mpmath.mpf(float(z.lo)) <= v <= mpmath.mpf(float(z.hi)):
            assert any(inside(p, mpmath.mpf(float(s))) for p in pieces), s
            assert inside(h, mpmath.mpf(float(s)))


@settings(max_examples=40)
@given(trajectories(), grids(), seeds)
def test_evaluation_keeps_truth(tr, t, seed):
    rng = np.random.default_rng(seed)
    y = tube_around(tr, t, rng, p_entire=0.05)
    assert tube_keeps(y, tr, sample_times(t, rng))
    a, b = np.sort(rng.uniform(t[0], t[-1], 2))
    e = y(Interval(a, b))
    for s in np.linspace(a, b, 20):
        assert inside(e, tr.value(float(s)))


# -- integrals --
@settings(max_examples=40)
@given(trajectories(), grids(), seeds)
def test_integral_and_primitive_keep_truth(tr, t, seed):
    rng = np.random.default_rng(seed)
    y = tube_around(tr, t, rng, p_entire=0.02)
    a, b, c, d = np.sort(rng.uniform(t[0], t[-1], 4))
    assert inside(y.integral(a, d), tr.anti(d) - tr.anti(a))
    both = y.integral(Interval(a, b), Interval(c, d))
    for s, u in rng.uniform([a, c], [b, d], (10, 2)):
        assert inside(both, tr.anti(u) - tr.anti(s))
    x0 = Interval(-1, 2)
    p = y.primitive(x0)
    for s in sample_times(t, rng, 30):
        assert inside(p(float(s)), tr.anti(float(s)) - tr.anti(float(t[0])) + mpmath.mpf(0.5))
        assert inside(y.integral(float(s)), tr.anti(float(s)) - tr.anti(float(t[0])))


def test_integral_tight_and_infinite():
    y = Tube.constant(0, 1, 10, Interval(1, 2))
    i = y.integral(0, 1)
    assert 1 - 1e-14 < float(i.lo) <= 1 and 2 <= float(i.hi) < 2 + 1e-14
    p = y.primitive()
    assert float(p.gates.lo[-1]) <= 1 <= float(p.gates.lo[-1]) + 1e-14
    # an unbounded slice makes the integral unbounded on its side only
    y.slices[3] = Interval(1, INF)
    assert float(y.integral(0, 1).hi) == INF and float(y.integral(0, 1).lo) > 0.99
    assert float(y.integral(0.5, 1).hi) < 1.01  # the unbounded slice lies before 0.5


# -- arithmetic --
@settings(max_examples=30)
@given(trajectories(), trajectories(), grids(), seeds)
def test_arithmetic_keeps_truth(tr1, tr2, t, seed):
    rng = np.random.default_rng(seed)
    x, y = tube_around(tr1, t, rng), tube_around(tr2, t, rng)
    times = sample_times(t, rng, 20)
    for s in times:
        a, b = tr1.value(float(s)), tr2.value(float(s))
        s = float(s)
        assert inside((x + y)(s), a + b) and inside((x - y)(s), a - b)
        assert inside((x * y)(s), a * b) and inside((2 * x - 1)(s), 2 * a - 1)
        assert inside(bt.sin(x)(s), mpmath.sin(a)) and inside(bt.exp(y)(s), mpmath.exp(b))
        assert inside(bt.sqr(x)(s), a * a) and inside(bt.atan2(y, x)(s), mpmath.atan2(b, a))
        if not (y(s).contains(0.0)):
            assert inside((x / y)(s), a / b)


def test_intersection_and_hull():
    a = Tube.constant(0, 1, 4, Interval(0, 2))
    b = Tube.constant(0, 1, 4, Interval(1, 3))
    assert float((a & b)(0.5).lo) == 1 and float((a | b)(0.5).hi) == 3
    assert (a & Tube.constant(0, 1, 4, Interval(5, 6))).is_empty()
    assert (a & b).is_subset(a) and not a.is_subset(a & b)


def test_plot_tube():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from boundest.plot import plot_tube

    y = Tube.from_function(0, 10, 0.5, iv.sin).map(lambda s: s.inflate(0.1))
    fig, ax = plt.subplots()
    arts = plot_tube(y, ax=ax, truth=(np.linspace(0, 10, 50), np.sin(np.linspace(0, 10, 50))),
                     boxes=(Interval([1, 4], [2, 5]), Interval([0, 0], [0.5, 0.5])))
    assert len(arts) == 4  # band, gates, truth, boxes
    x0, x1 = ax.get_xlim()
    assert x0 <= 0 and x1 >= 10
    plt.close(fig)
