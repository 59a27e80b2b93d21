"""The recursive q-relaxed observer on the pool robot: the set keeps the simulated truth while
every window holds at most q outliers; emptiness is reported and the observer restarts."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from boundest.estimation.robust import RobustObserver, window_probability
from boundest.interval import Interval
from boundest.scenarios.pool import restart_box, solve_pool
from boundest.scenarios.pool_data import binomial_bound, load_pool
from boundest.scenarios.pool_sim import simulate_pool


@cache
def missions(seed: int, m: int):
    return simulate_pool(seed=seed, n_missions=m)


def _windows_ok(outlier: np.ndarray, m: int, q: int) -> np.ndarray:
    """``ok[i, k]``: every window of ``m`` pings ending at or before ``k`` held <= q outliers."""
    c = np.cumsum(outlier, axis=-1)
    prev = np.concatenate([np.zeros_like(c[..., :m]), c[..., :-m]], axis=-1)
    bad = (c - prev) > q
    return ~np.maximum.accumulate(bad, axis=-1)


@pytest.mark.parametrize("q", [4, 8])
def test_truth_kept_while_windows_hold_at_most_q_outliers(q):
    data, truth = missions(11, 24)
    res = solve_pool(data, q=q, m=80)
    inside = ((res.boxes.lo <= truth.states) & (truth.states <= res.boxes.hi)).all(-1)
    ok = _windows_ok(truth.outlier, 80, q)
    assert ok.any()
    assert inside[ok].all(), np.argwhere(ok & ~inside)[:5]
    # never an empty set kept: an empty step is reported and the box is the restart box
    assert not np.isnan(res.boxes.lo).any()
    rb = restart_box(data)
    for i, k in np.argwhere(res.empty):
        assert np.array_equal(res.boxes.lo[i, k], rb.lo) and np.array_equal(res.boxes.hi[i, k],
                                                                             rb.hi)


def test_embedded_mission():
    data = load_pool()
    res = solve_pool(data, q=8, m=80)
    assert not res.empty.any() and res.rejected.max() <= 8
    w = res.widths()
    assert np.all(np.isfinite(w)) and w[40:, :2].mean() < 2.0
    # fewer outliers allowed than the data hold: the set empties, is reported, and restarts
    strict = solve_pool(data, q=2, m=80)
    assert strict.empty.any()


def test_window_probability_is_the_binomial_bound():
    for q, p in ((6, 0.894715), (8, 0.981597), (10, 0.997901), (12, 0.999836)):
        assert abs(window_probability(80, q, 0.05) - p) < 5e-7
        assert abs(window_probability(80, q, 0.05) - binomial_bound(80, q, 0.05)) < 1e-12
    assert window_probability(5, 9, 0.3) == pytest.approx(1.0)
    with pytest.raises(ValueError):
        window_probability(80, -1, 0.05)


def test_observer_with_q_zero_is_the_intersection():
    obs = RobustObserver(lambda x, u: x, lambda x, y: x & y, Interval([0.0], [10.0]), m=4, q=0)
    a = obs.update(None, Interval([1.0], [5.0])).box
    b = obs.update(None, Interval([4.0], [9.0])).box
    assert a.lo.tolist() == [1.0] and a.hi.tolist() == [5.0]
    assert b.lo.tolist() == [4.0] and b.hi.tolist() == [5.0]
    step = obs.update(None, Interval([6.0], [7.0]))  # inconsistent: reported, restarted
    assert step.empty.item() and step.box.lo.tolist() == [0.0] and step.box.hi.tolist() == [10.0]
