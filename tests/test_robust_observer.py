"""The recursive q-relaxed observer on the pool robot: the set keeps the simulated truth while
every window holds at most q outliers; emptiness is reported and the observer restarts."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from boundest.estimation.robust import RobustObserver, window_probability
from boundest.interval import Interval
from boundest.scenarios.pool import PoolObserver, solve_pool
from boundest.scenarios.pool_data import PoolData, binomial_bound, load_pool
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


def _guaranteed(outlier: np.ndarray, empty: np.ndarray, m: int, q: int) -> np.ndarray:
    """``ok[i, k]``: every window since the observer's last restart (its last empty step at or
    before ``k``, else the start) held at most ``q`` outliers: where the recursive set must
    hold the truth."""
    c = np.cumsum(outlier, axis=-1)
    prev = np.concatenate([np.zeros_like(c[..., :m]), c[..., :-m]], axis=-1)
    bad = (c - prev) > q
    ok = np.zeros_like(bad)
    for i in range(bad.shape[0]):
        since_bad = False
        for k in range(bad.shape[1]):
            since_bad = bad[i, k] if empty[i, k] else (since_bad or bad[i, k])
            ok[i, k] = not since_bad
    return ok


def _inside(res, truth) -> np.ndarray:
    return ((res.boxes.lo <= truth.states) & (truth.states <= res.boxes.hi)).all(-1)


@pytest.mark.slow  # about 35 s for the six cases
@pytest.mark.parametrize(("q", "sweeps", "n", "heading"),
                         [(4, 0, 48, None), (8, 0, 48, None), (4, 1, 6, None), (8, 1, 6, None),
                          (4, 0, 12, 0.05), (8, 0, 12, 0.02)])
def test_truth_kept_while_windows_hold_at_most_q_outliers(q, sweeps, n, heading):
    data, truth = missions(11, n)
    # heading slices: cut, dropped when empty and merged beyond 8 (merges at most steps)
    res = solve_pool(data, q=q, m=80, sweeps=sweeps, paving_heading=heading, heading_slices=8)
    if heading is not None:
        assert res.cells.max() == 8 and res.cells.min() >= 1
    inside = _inside(res, truth)
    ok = _guaranteed(truth.outlier, res.empty, 80, q)
    assert ok.sum() > 80 * n  # of n x 406 steps
    assert inside[ok].all(), np.argwhere(ok & ~inside)[:5]
    # never an empty set kept: an empty step is reported and the box is a bounded set
    assert not np.isnan(res.boxes.lo).any()
    assert np.isfinite(res.boxes.lo[..., :2]).all() and np.isfinite(res.boxes.hi[..., :2]).all()


def test_pure_window_observer_holds_the_truth_when_its_window_does():
    data, truth = missions(5, 4)
    q = 4
    res = solve_pool(data, q=q, m=40, carry=False)
    c = np.cumsum(truth.outlier, axis=-1)
    prev = np.concatenate([np.zeros_like(c[..., :40]), c[..., :-40]], axis=-1)
    ok = (c - prev) <= q  # only this step's window matters
    inside = _inside(res, truth)
    assert (~ok).any() and inside[ok].all(), np.argwhere(ok & ~inside)[:5]
    # the recursive observer carries more: never wider on average
    rec = solve_pool(data, q=q, m=40)
    assert np.nanmean(rec.widths()[..., :2]) <= np.nanmean(res.widths()[..., :2])


def test_restart_recovers_from_a_window_with_too_many_outliers():
    # q = 1 is too small for p = 0.05 and m = 80: the set empties, is reported, and the
    # observer restarts from the window alone; the heading stays bounded (the open-loop prior)
    data, truth = missions(3, 3)
    for heading in (None, 0.05):  # heading slices: restarts when every slice is empty
        res = solve_pool(data, q=1, m=80, sweeps=0, paving_heading=heading, heading_slices=4)
        assert res.empty.any()
        assert np.isfinite(res.boxes.lo).all() and np.isfinite(res.boxes.hi).all()
        inside = _inside(res, truth)
        ok = _guaranteed(truth.outlier, res.empty, 80, 1)
        assert inside[ok].all()


@pytest.mark.parametrize("kw", [{}, {"sweeps": 0, "paving_heading": 0.05, "heading_slices": 8}])
def test_online_updates_are_the_offline_run(kw):
    data = load_pool()
    off = solve_pool(data, q=8, m=80, **kw)
    obs = PoolObserver(data, q=8, m=80, **kw)
    for k in range(60):
        u = data.inputs[k - 1] if k else None
        box, rejected, empty = obs.update(u, float(data.alpha[k]), data.ranges[k])
        assert np.array_equal(box.lo, off.boxes.lo[k]) and np.array_equal(box.hi,
                                                                           off.boxes.hi[k])
        assert rejected == off.rejected[k] and empty == off.empty[k]
        assert obs.cells_kept == off.cells[k]
    with pytest.raises(ValueError, match="input box"):
        obs.update(None, 0.0, data.ranges[60])


@pytest.mark.slow  # about 11 s on 2 cores
def test_paving_keeps_the_truth_and_tightens():
    data, truth = missions(21, 2)
    data = PoolData(data.t0, data.dt, data.inputs[:, :160], data.alpha[:160],
                    data.ranges[:, :160], data.x0, data.map, data.p_outlier)
    states, outlier = truth.states[:, :160], truth.outlier[:, :160]
    box = solve_pool(data, q=8, m=80, sweeps=0)
    paved = solve_pool(data, q=8, m=80, sweeps=0, paving=0.5, paving_heading=0.1)
    assert paved.cells.min() >= 1 and paved.paving is not None
    ok = _guaranteed(outlier, paved.empty, 80, 8)
    inside = ((paved.boxes.lo <= states) & (states <= paved.boxes.hi)).all(-1)
    assert ok.sum() > 200 and inside[ok].all()
    # every kept cell lies in its step's box, and the cells' hull is the box in (x, y)
    cells = paved.paving
    n = np.arange(cells.shape[-2]) < paved.cells[..., None]
    assert (cells.lo[n][:, :2] >= paved.boxes.lo[..., None, :2].repeat(cells.shape[-2], -2)[n]
            ).all()
    assert paved.widths()[..., :2].mean() < box.widths()[..., :2].mean()
    for bad in ({"paving": 0.0}, {"paving_heading": -1.0}, {"paving": float("nan")}):
        with pytest.raises(ValueError, match="paving"):
            solve_pool(data, **bad)
    for bad in (0, 2.5, True):
        with pytest.raises(ValueError, match="heading_slices"):
            solve_pool(data, paving_heading=0.1, heading_slices=bad)
    with pytest.raises(ValueError, match="recursive observer"):
        solve_pool(data, paving_heading=0.1, carry=False)


def test_embedded_mission():
    data = load_pool()
    res = solve_pool(data, q=8, m=80)
    assert not res.empty.any() and res.rejected.max() <= 8
    w = res.widths()
    assert np.all(np.isfinite(w)) and w[40:, :2].mean() < 1.0
    fast = solve_pool(data, q=8, m=80, sweeps=0)
    assert w[:, :2].mean() < fast.widths()[:, :2].mean()  # smoothing inside the window pays
    # heading slices that carry their own past pay more, and lie in the hull they make
    sliced = solve_pool(data, q=8, m=80, sweeps=0, paving_heading=0.05, heading_slices=8)
    assert sliced.widths()[:, :2].mean() < w[:, :2].mean()
    cells, kept = sliced.paving, np.arange(sliced.paving.shape[-2]) < sliced.cells[:, None]
    assert (cells.lo[kept] >= sliced.boxes.lo[:, None].repeat(cells.shape[-2], 1)[kept]).all()
    assert (cells.hi[kept] <= sliced.boxes.hi[:, None].repeat(cells.shape[-2], 1)[kept]).all()
    # fewer outliers allowed than the data hold: the set empties, is reported, and restarts
    strict = solve_pool(data, q=2, m=80)
    assert strict.empty.any() and np.isfinite(strict.boxes.lo).all()
    with pytest.raises(ValueError, match="sweeps"):
        solve_pool(data, q=8, m=80, sweeps=-1)


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
