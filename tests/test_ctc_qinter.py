"""CtcQInter: the q-relaxed intersection of contractors (boundest.ctc.qinter).

The truth is built by choosing the point first: a point ``p``, beacons, the exact distances,
then ring constraints ``|x - b_i|^2 in [(d_i - e)^2, (d_i + e)^2]`` that ``p`` satisfies, and
outliers whose ring is moved away from ``p`` (``p`` fails them). Every contractor below must keep
``p`` as long as it fails at most ``q`` of the constraints.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import boundest as bd
from boundest import Interval
from boundest.ctc import CtcFwdBwd, CtcQInter, Fixpoint, FunctionContractor, Union
from boundest.expr import Var
from boundest.interval import qinter_boxes
from boundest.paving import separators, sivia

X, Y = Var("x"), Var("y")


def ring_expr(b: np.ndarray):
    return (X - float(b[0])) ** 2 + (Y - float(b[1])) ** 2


def ring_bounds(d: float, e: float, shift: float) -> tuple[float, float]:
    lo = max(d + shift - e, 0.0)
    return lo * lo, (d + shift + e) ** 2


def rings(p: np.ndarray, beacons: np.ndarray, e: float, outliers: set[int], shift: float = 3.0
          ) -> tuple[list[CtcFwdBwd], list[tuple[float, float]]]:
    """Ring contractors around ``beacons``; ``p`` satisfies all but those in ``outliers``."""
    ctcs, bounds = [], []
    for i, b in enumerate(beacons):
        d = float(np.hypot(*(p - b)))
        lo, hi = ring_bounds(d, e, shift if i in outliers else 0.0)
        ctcs.append(CtcFwdBwd([ring_expr(b).in_(Interval(lo, hi))], ["x", "y"]))
        bounds.append((lo, hi))
    return ctcs, bounds


def boxes_around(p: np.ndarray, rng: np.random.Generator, count: int) -> Interval:
    """``count`` random boxes containing ``p`` (some wide, some thin)."""
    scale = 10.0 ** rng.uniform(-2, 1, (count, 1))
    lo = p - scale * rng.random((count, 2))
    hi = p + scale * rng.random((count, 2))
    return Interval(lo, hi)


@settings(max_examples=40)
@given(st.integers(3, 7).flatmap(lambda n: st.tuples(
    st.just(n), st.integers(0, n - 1), st.integers(0, n), st.integers(0, 2**32 - 1))),
    st.sampled_from(["auto", "exact", "projection"]))
def test_point_with_at_most_q_failures_survives(args, method):
    n, n_out, q, seed = args
    rng = np.random.default_rng(seed)
    p = rng.uniform(-5, 5, 2)
    beacons = rng.uniform(-10, 10, (n, 2))
    outliers = set(rng.choice(n, size=n_out, replace=False).tolist())
    ctcs, _ = rings(p, beacons, e=0.05, outliers=outliers)
    boxes = boxes_around(p, rng, 64)
    ctc = CtcQInter(ctcs, q, method)
    out = ctc(boxes)
    assert out.shape == boxes.shape
    assert np.all(out.is_subset(boxes))
    if n_out <= q:  # p fails at most q constraints: every box keeps it
        assert np.all(out.contains(p))
    # the exact combination is never wider than the projection
    tight = CtcQInter(ctcs, q, "exact")(boxes)
    loose = CtcQInter(ctcs, q, "projection")(boxes)
    assert np.all(tight.is_subset(loose))


def test_contracts_away_the_outlier():
    rng = np.random.default_rng(1)
    p = np.array([1.0, 2.0])
    beacons = rng.uniform(-10, 10, (6, 2))
    ctcs, _ = rings(p, beacons, e=0.05, outliers={2})
    box = Interval([-10, -10], [10, 10])
    assert np.all(bd.Sequence(*ctcs)(box).is_empty())  # inconsistent without relaxation
    got = Fixpoint(CtcQInter(ctcs, 1))(box)
    assert np.all(got.contains(p))
    assert np.all(got.width() < 0.5)  # the five good rings pin p down


def test_q_zero_and_q_n_minus_one_and_q_at_least_n():
    rng = np.random.default_rng(2)
    p = np.array([0.5, -1.0])
    ctcs, _ = rings(p, rng.uniform(-10, 10, (4, 2)), e=0.3, outliers={0})
    boxes = boxes_around(p, rng, 32)
    parts = [c(boxes) for c in ctcs]
    inter = parts[0]
    for c in parts[1:]:
        inter = inter & c
    inter = Interval.trusted(np.where(np.isnan(inter.lo).any(-1, keepdims=True), np.nan, inter.lo),
                          np.where(np.isnan(inter.lo).any(-1, keepdims=True), np.nan, inter.hi))
    assert np.all(CtcQInter(ctcs, 0)(boxes) == inter)  # the parallel intersection
    assert np.all(CtcQInter(ctcs, 3, "exact")(boxes) == Union(*ctcs)(boxes))
    for q in (4, 5):  # every point satisfies at least N - q <= 0 constraints
        assert np.all(CtcQInter(ctcs, q)(boxes) == boxes)


def test_empty_contraction_counts_as_failure():
    def nothing(x: Interval) -> Interval:
        return Interval.empty(x.shape)

    def keep(x: Interval) -> Interval:
        return x

    ctcs = [FunctionContractor(nothing, 2), FunctionContractor(keep, 2)]
    box = Interval([0, 0], [1, 1])
    assert np.all(CtcQInter(ctcs, 0)(box).is_empty())
    assert np.all(CtcQInter(ctcs, 1)(box) == box)
    assert np.all(CtcQInter([ctcs[0], ctcs[0]], 1)(box).is_empty())
    # an already empty box stays empty
    assert np.all(CtcQInter(ctcs, 1)(Interval.empty(2)).is_empty())


def test_batches_any_leading_shape_and_matches_one_by_one():
    rng = np.random.default_rng(3)
    p = np.array([2.0, 2.0])
    ctcs, _ = rings(p, rng.uniform(-10, 10, (5, 2)), e=0.2, outliers={1, 3})
    boxes = boxes_around(p, rng, 24)
    ctc = CtcQInter(ctcs, 2)
    flat = ctc(boxes)
    assert np.all(ctc(boxes.reshape(4, 6, 2)).reshape(24, 2) == flat)
    for i in range(0, 24, 5):
        assert np.all(ctc(boxes[i]) == flat[i])


def test_composes_with_and_or_fixpoint():
    rng = np.random.default_rng(4)
    p = np.array([-1.0, 3.0])
    ctcs, _ = rings(p, rng.uniform(-10, 10, (5, 2)), e=0.1, outliers={4})
    boxes = boxes_around(p, rng, 32)
    qc = CtcQInter(ctcs, 1)
    seq = qc & ctcs[0]
    uni = qc | ctcs[4]
    fix = Fixpoint(qc, ratio=1e-6)
    one = qc(boxes)
    for c in (seq, uni, fix, Fixpoint(seq)):
        got = c(boxes)
        assert np.all(got.contains(p))
    assert np.all(fix(boxes).is_subset(one))
    assert np.all(seq(boxes).is_subset(one))
    assert qc.n == 2 and seq.n == 2 and fix.n == 2


def test_bad_arguments():
    c = CtcFwdBwd([X + Y == 1], ["x", "y"])
    with pytest.raises(ValueError, match=">= 0"):
        CtcQInter([c], -1)
    with pytest.raises(TypeError):
        CtcQInter([c], 0.5)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="at least one"):
        CtcQInter([], 0)
    with pytest.raises(ValueError, match="dimensions"):
        CtcQInter([c, CtcFwdBwd([X == 1], ["x"])], 0)
    with pytest.raises(ValueError, match="method"):
        CtcQInter([c], 0, "fast")  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        CtcQInter([lambda b: b], 0)  # type: ignore[list-item]
    with pytest.raises(ValueError, match="dimension 2"):
        CtcQInter([c], 0)(Interval([0, 0, 0], [1, 1, 1]))


def test_sivia_with_one_outlier_among_six_rings():
    rng = np.random.default_rng(5)
    p = np.array([1.0, 2.0])
    beacons = rng.uniform(-10, 10, (6, 2))
    n, q = 6, 1
    pairs, bounds = [], []
    for i, b in enumerate(beacons):
        d = float(np.hypot(*(p - b)))
        lo, hi = ring_bounds(d, 0.5, 3.0 if i == 3 else 0.0)
        pairs.append(separators(ring_expr(b), Interval([lo], [hi]), ["x", "y"]))
        bounds.append((lo, hi))
    ctc_out = CtcQInter([o for _, o in pairs], q)  # at most q rings fail
    ctc_in = CtcQInter([i for i, _ in pairs], n - q - 1)  # at least q + 1 rings fail
    box = Interval([-10, -10], [10, 10])
    sp = sivia(box, ctc_in=ctc_in, ctc_out=ctc_out, eps=0.05)
    assert len(sp) > 0 and np.any(sp.inside)
    assert sp.contains(p)[0] >= 0
    # sample points, near the truth and everywhere; skip the few within 1e-9 of a ring
    pts = np.concatenate([rng.uniform(-10, 10, (20000, 2)), p + rng.normal(0, 1, (20000, 2))])
    pts = pts[np.all(np.abs(pts) <= 10, axis=1)]
    sq = ((pts[:, None, :] - beacons[None]) ** 2).sum(axis=-1)  # (m, 6)
    lo = np.array([b[0] for b in bounds])
    hi = np.array([b[1] for b in bounds])
    near = (np.abs(sq - lo) < 1e-9 * (1 + lo)) | (np.abs(sq - hi) < 1e-9 * (1 + hi))
    pts, sq = pts[~near.any(axis=1)], sq[~near.any(axis=1)]
    satisfied = ((lo <= sq) & (sq <= hi)).sum(axis=1)
    where = sp.contains(pts)
    assert np.any(satisfied >= n - q)
    assert np.all(where[satisfied >= n - q] >= 0)  # never lost: inside or boundary
    assert np.all(where[satisfied <= n - q - 1] != 1)  # never proven inside


def test_qinter_boxes_is_what_ctcqinter_combines():
    rng = np.random.default_rng(6)
    p = np.array([0.0, 0.0])
    ctcs, _ = rings(p, rng.uniform(-10, 10, (4, 2)), e=0.3, outliers={2})
    boxes = boxes_around(p, rng, 8)
    stacked = [c(boxes) for c in ctcs]
    s = Interval.trusted(np.stack([b.lo for b in stacked], -2),
                         np.stack([b.hi for b in stacked], -2))
    expect = qinter_boxes(s, 1, "exact") & boxes
    got = CtcQInter(ctcs, 1, "exact")(boxes)
    bad = np.isnan(expect.lo).any(-1)
    assert np.all(got[~bad] == expect[~bad])
    assert np.all(got[bad].is_empty())
