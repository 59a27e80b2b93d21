"""Set state estimators of Jaulin et al. 2001 (RCSE, NCSE, CSE) on equation 21: the exact truth
(mpmath)
stays inside every set over many simulated runs, and the last causal and non-causal sets
coincide (Jaulin et al. 2001 section 5)."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from boundest import Interval
from boundest.estimation import DiscreteSystem, cse, ncse, rcse, rcse_ncse
from boundest.paving import Subpaving
from boundest.scenarios import jaulin2001 as jw


def exact_inside(point, d) -> bool:
    """Whether the exact point (mpf pair) lies in the box or in a box of the subpaving."""
    boxes = d.boxes if isinstance(d, Subpaving) else d.reshape(1, -1)
    near = np.all((boxes.lo <= np.array([float(p) for p in point]) + 1e-9)
                  & (np.array([float(p) for p in point]) - 1e-9 <= boxes.hi), axis=1)
    for i in np.flatnonzero(near):
        if all(mpmath.mpf(float(boxes.lo[i, j])) <= point[j] <= mpmath.mpf(float(boxes.hi[i, j]))
               for j in range(len(point))):
            return True
    return False


def random_runs(n: int, seed: int) -> list[jw.Simulation]:
    rng = np.random.default_rng(seed)
    return [jw.simulate(tuple(rng.uniform(-4, 4, 2)), seed=int(rng.integers(2**31)))
            for _ in range(n)]


def test_box_estimators_keep_the_truth_over_many_runs_in_one_batch():
    runs = random_runs(200, seed=1)
    y = Interval(np.stack([r.y.lo for r in runs]), np.stack([r.y.hi for r in runs]))
    sys_ = jw.system()
    for est in (rcse(sys_, y), ncse(sys_, y)):
        hull = est.hull()
        assert hull.shape == (200, 11, 2)
        for i, r in enumerate(runs):
            for k in range(11):
                assert exact_inside(r.x[k], hull[i, k]), (i, k)
        for i, r in enumerate(runs):  # outputs too
            for k in range(1, 11):
                yk = est.y[k - 1][i]
                assert mpmath.mpf(float(yk.lo[0])) <= abs(r.x[k][0]) <= mpmath.mpf(
                    float(yk.hi[0]))
    # the non-causal sets are inside the causal ones; the last ones are equal
    c, nc = rcse(sys_, y).hull(), ncse(sys_, y).hull()
    assert bool(np.all(nc.is_subset(c)))
    assert np.array_equal(c.lo[:, -1], nc.lo[:, -1]) and np.array_equal(c.hi[:, -1],
                                                                         nc.hi[:, -1])


@pytest.mark.parametrize("seed", range(6))
def test_subpaving_estimators_keep_the_truth(seed):
    (run,) = random_runs(1, seed=100 + seed)
    res = jw.solve(run.y, eps=0.05)
    for est in (res.rcse, res.ncse):
        for k in range(11):
            d = est.x[k]
            if k == 0 and isinstance(d, Interval):
                assert exact_inside(run.x[0], d)
                continue
            assert exact_inside(run.x[k], d), (est, k)
    # Jaulin et al. 2001 section 5: both estimators end with the same information
    a, b = res.rcse.x[-1], res.ncse.x[-1]
    assert np.array_equal(a.hull().lo, b.hull().lo) and np.array_equal(a.hull().hi,
                                                                         b.hull().hi)
    assert len(a) == len(b)
    # the non-causal sets are (up to the paving) inside the causal ones: hulls nested
    for k in range(1, 11):
        assert bool(np.all(res.ncse.x[k].hull().is_subset(res.rcse.x[k].hull()))), k


def test_the_seed_data_set_is_consistent_and_contains_the_seed_truth():
    y = jw.load()
    truth = jw.simulate((0.0, 0.0), seed=0).x  # x*(0) = (0, 0) as in Jaulin et al. 2001
    res = jw.solve(y, eps=0.02)
    for est in (res.rcse, res.ncse):
        for k in range(1, 11):
            assert not est.x[k].is_empty()
            assert exact_inside(truth[k], est.x[k]), k
    assert exact_inside(truth[0], res.ncse.x[0])
    a, b = res.rcse.x[-1], res.ncse.x[-1]
    assert np.array_equal(a.boxes.lo, b.boxes.lo) and np.array_equal(a.boxes.hi, b.boxes.hi)
    # RCSE knows nothing about x(0): its set is the prior frame
    assert isinstance(res.rcse.x[0], Interval) and bool(np.all(res.rcse.x[0] == jw.FRAME))


def _same_domain(a, b) -> bool:
    if isinstance(a, Subpaving):
        return (isinstance(b, Subpaving) and np.array_equal(a.inside, b.inside)
                and np.array_equal(a.boxes.lo, b.boxes.lo)
                and np.array_equal(a.boxes.hi, b.boxes.hi))
    return (isinstance(b, Interval) and np.array_equal(a.lo, b.lo, equal_nan=True)
            and np.array_equal(a.hi, b.hi, equal_nan=True))


@pytest.mark.parametrize("seed", range(2))
def test_ncse_from_the_rcse_domains_is_the_ncse(seed):
    """RCSE's domains are what FALL from x_K computes, so one CLIMB gives NCSE: on subpavings
    (prior x0 only) the very same boxes, and on box batches a subset of NCSE's hulls."""
    (run,) = random_runs(1, seed=200 + seed)
    kw = dict(x0=jw.FRAME, domains="subpavings", eps=0.05)
    causal, smoothed = rcse_ncse(jw.system(), run.y, **kw)
    ref = ncse(jw.system(), run.y, **kw)  # FALL-CLIMB on its own (rcse is rcse_ncse itself)
    assert all(_same_domain(a, b) for a, b in zip(smoothed.x, ref.x, strict=True))
    assert all(_same_domain(a, b) for a, b in zip(smoothed.y, ref.y, strict=True))
    assert smoothed.time_s >= causal.time_s
    assert rcse_ncse(jw.system(), run.y, smooth=False, **kw)[1] is None
    runs = random_runs(30, seed=300 + seed)
    y = Interval(np.stack([r.y.lo for r in runs]), np.stack([r.y.hi for r in runs]))
    _, smoothed = rcse_ncse(jw.system(), y)
    hull, ref = smoothed.hull(), ncse(jw.system(), y).hull()
    assert bool(np.all(hull.is_subset(ref) | ref.is_empty()))
    for i, r in enumerate(runs):
        for k in range(11):
            assert exact_inside(r.x[k], hull[i, k]), (i, k)


def test_cse_smooths_and_ends_like_ncse_on_boxes():
    runs = random_runs(20, seed=7)
    y = Interval(np.stack([r.y.lo for r in runs]), np.stack([r.y.hi for r in runs]))
    hist = cse(jw.system(), y)
    assert len(hist) == 11
    final, nc = hist[-1].hull(), ncse(jw.system(), y).hull()
    for i, r in enumerate(runs):
        for k in range(11):
            for h in hist:
                hull = h.hull()
                box = Interval.trusted(np.broadcast_to(hull.lo, (20, 11, 2))[i, k],
                                    np.broadcast_to(hull.hi, (20, 11, 2))[i, k])
                assert exact_inside(r.x[k], box)
    # after the last measurement CSE holds the non-causal information (Theorem 7)
    assert np.allclose(np.nan_to_num(final.lo), np.nan_to_num(nc.lo), atol=1e-9)
    assert np.allclose(np.nan_to_num(final.hi), np.nan_to_num(nc.hi), atol=1e-9)


def test_inconsistent_data_give_empty_sets():
    y = Interval([[3.5], [0.0]], [[3.9], [0.1]])  # |x1| <= 3 on the circle
    est = rcse(jw.system(), y, domains="subpavings", x0=jw.FRAME, eps=0.1)
    d = est.x[1]
    assert d.is_empty() if isinstance(d, Subpaving) else bool(np.all(d.is_empty()))
    assert ncse(jw.system(), y, domains="subpavings", x0=jw.FRAME, eps=0.1).x[2].is_empty()


def test_bad_input_is_refused():
    sys_ = jw.system()
    with pytest.raises(ValueError, match="shape"):
        ncse(sys_, Interval([0.0], [1.0]))
    with pytest.raises(ValueError, match="domains"):
        ncse(sys_, Interval([[0.0]], [[1.0]]), domains="ellipsoids")
    with pytest.raises(ValueError, match="returned 1 components"):
        DiscreteSystem(lambda x: [x[0]], lambda x: [x[0]], nx=2, ny=1)
    with pytest.raises(ValueError, match="eps"):
        ncse(sys_, Interval([[0.0]], [[1.0]]), domains="subpavings", eps=0.0)


def test_load_names_the_bad_row(tmp_path):
    p = tmp_path / "y.csv"
    p.write_text("k,y_lo,y_hi\n1,0,1\n3,0,1\n")
    with pytest.raises(ValueError, match=r"y.csv:3: k = 3.0"):
        jw.load(p)
