"""q-relaxed intersection of intervals and boxes (boundest.interval.relaxed).

The oracle is brute force on the grid of the members' bounds: the q-relaxed intersection of
boxes is the union of the intersections of ``N - q`` of them, boxes whose corners have their
coordinates among the members' bounds, so its hull is the hull of the grid points covered by at
least ``N - q`` members (an infinite coordinate stands for the limit: it is "covered" by the
members unbounded on that side). Bounds are drawn from a few small integers so that ties,
touching and degenerate members are frequent.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import boundest as bd
from boundest import Interval
from boundest.interval import qinter, qinter_boxes, relaxed
from boundest.interval.relaxed import EXACT_MAX_SUBSETS

SMALL = st.sampled_from([-3.0, -2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 2.0, 3.0])


@st.composite
def member_bounds(draw, shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Bounds of intervals of ``shape``: small values, some infinite, degenerate or empty."""
    size = math.prod(shape)
    a = np.array(draw(st.lists(SMALL, min_size=size, max_size=size)))
    b = np.array(draw(st.lists(SMALL, min_size=size, max_size=size)))
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    kind = np.array(draw(st.lists(st.integers(0, 11), min_size=size, max_size=size)))
    lo = np.where(kind == 0, -np.inf, lo)
    hi = np.where(kind == 1, np.inf, hi)
    hi = np.where(kind == 2, lo, hi)
    empty = kind == 3
    lo, hi = np.where(empty, np.nan, lo), np.where(empty, np.nan, hi)
    return lo.reshape(shape), hi.reshape(shape)


@st.composite
def box_sets(draw, max_n_members: int = 5, max_dim: int = 3):
    n_members = draw(st.integers(1, max_n_members))
    dim = draw(st.integers(1, max_dim))
    lo, hi = draw(member_bounds((n_members, dim)))
    q = draw(st.integers(0, n_members + 1))
    return Interval.trusted(lo, hi), q


def _as_set(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Boxes (last axis) with an empty component made wholly empty."""
    bad = np.isnan(lo).any(axis=-1, keepdims=True)
    return np.where(bad, np.nan, lo), np.where(bad, np.nan, hi)


def _count(lo: np.ndarray, hi: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """How many of the boxes ``(N, n)`` contain each point of ``pts (m, n)``."""
    inside = (lo[None] <= pts[:, None]) & (pts[:, None] <= hi[None])  # NaN compares False
    return inside.all(axis=-1).sum(axis=-1)


def brute_hull(boxes: Interval, q: int) -> tuple[np.ndarray, np.ndarray]:
    """The hull of the grid points covered by at least N - q boxes (NaN when none)."""
    lo, hi = _as_set(boxes.lo, boxes.hi)
    n_members, dim = lo.shape
    k = n_members - q
    if k <= 0:
        return np.full(dim, -np.inf), np.full(dim, np.inf)
    axes = []
    for d in range(dim):
        v = np.concatenate([lo[:, d], hi[:, d]])
        axes.append(np.unique(v[~np.isnan(v)]))
    if any(a.size == 0 for a in axes):
        return np.full(dim, np.nan), np.full(dim, np.nan)
    grid = np.array(list(itertools.product(*axes)), dtype=np.float64).reshape(-1, dim)
    ok = grid[_count(lo, hi, grid) >= k]
    if ok.shape[0] == 0:
        return np.full(dim, np.nan), np.full(dim, np.nan)
    return ok.min(axis=0), ok.max(axis=0)


def same(x: Interval, lo: np.ndarray, hi: np.ndarray) -> bool:
    return bool(np.all(x == Interval.trusted(np.asarray(lo, float), np.asarray(hi, float))))


def sample_points(boxes: Interval, rng: np.random.Generator, per_box: int = 20) -> np.ndarray:
    """Random points inside the non-empty boxes (infinite sides clipped to [-5, 5]), plus their
    corners."""
    lo, hi = _as_set(boxes.lo, boxes.hi)
    keep = ~np.isnan(lo).any(axis=1)
    lo, hi = np.clip(lo[keep], -5, 5), np.clip(hi[keep], -5, 5)
    if lo.shape[0] == 0:
        return np.zeros((0, boxes.shape[1]))
    u = rng.random((lo.shape[0], per_box, lo.shape[1]))
    pts = lo[:, None] + u * (hi - lo)[:, None]
    return np.concatenate([pts.reshape(-1, lo.shape[1]), lo, hi])


# -- intervals ----------------------------------------------------------------------------------
def test_qinter_examples():
    x = Interval([0, 1, 2, 10], [3, 4, 5, 11])
    assert qinter(x, 0) == Interval.empty()
    assert qinter(x, 1) == Interval(2, 3)
    assert qinter(x, 2) == Interval(1, 4)
    assert qinter(x, 3) == Interval(0, 11)  # the hull of the union
    assert np.all(qinter(x, 4).is_entire())  # q >= N: every real qualifies
    assert np.all(qinter(x, 9).is_entire())
    # disjoint members: the sweep is exact where "(q+1)-th largest lower bound" is not
    assert qinter(Interval([0, 2, 2.5], [1, 3, 4]), 1) == Interval(2.5, 3)
    # touching closed intervals share their common point
    assert qinter(Interval([0, 1], [1, 2]), 0) == Interval(1, 1)


def test_qinter_empty_members_are_failures():
    e = np.nan
    x = Interval.trusted(np.array([0.0, e, 1.0]), np.array([2.0, e, 3.0]))
    assert qinter(x, 0) == Interval.empty()  # the empty member cannot hold
    assert qinter(x, 1) == Interval(1, 2)  # it is the one failure allowed
    assert qinter(x, 2) == Interval(0, 3)
    assert np.all(qinter(Interval.empty(4), 3).is_empty())
    assert np.all(qinter(Interval.empty(4), 4).is_entire())


def test_qinter_infinite_and_axis_and_errors():
    x = Interval([-np.inf, 0, 1], [1, np.inf, 2])
    assert qinter(x, 0) == Interval(1, 1)
    assert qinter(x, 2) == Interval.entire()
    y = Interval([-np.inf, -np.inf], [np.inf, 5])
    assert qinter(y, 0) == Interval(-np.inf, 5)
    # axis: members along axis 1 of a (2, 3) array
    z = Interval([[0, 1, 2], [0, 5, 6]], [[3, 4, 5], [1, 7, 8]])
    assert np.all(qinter(z, 1, axis=1) == Interval([1, 6], [4, 7]))
    assert np.all(qinter(z, 1, axis=-1) == qinter(Interval.trusted(z.lo.T, z.hi.T), 1))
    with pytest.raises(ValueError, match=">= 0"):
        qinter(x, -1)
    with pytest.raises(TypeError):
        qinter(x, 1.5)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="scalar"):
        qinter(Interval(0, 1), 0)


@settings(max_examples=300)
@given(st.integers(1, 7).flatmap(lambda n: st.tuples(member_bounds((n,)), st.integers(0, n + 1))))
def test_qinter_matches_brute_force(args):
    (lo, hi), q = args
    x = Interval.trusted(lo, hi)
    blo, bhi = brute_hull(Interval.trusted(lo[:, None], hi[:, None]), q)
    assert same(qinter(x, q), blo[0], bhi[0])


@settings(max_examples=100)
@given(member_bounds((4, 3, 5)), st.integers(0, 5), st.sampled_from([0, 1, 2, -1]))
def test_qinter_batched_equals_one_by_one(bounds, q, axis):
    x = Interval.trusted(*bounds)
    got = qinter(x, q, axis=axis)
    lo, hi = np.moveaxis(x.lo, axis, -1), np.moveaxis(x.hi, axis, -1)
    for idx in np.ndindex(lo.shape[:-1]):
        assert bool(got[idx] == qinter(Interval.trusted(lo[idx], hi[idx]), q))


# -- boxes --------------------------------------------------------------------------------------
def test_qinter_boxes_examples():
    b = Interval([[0, 0], [2, 2], [0, 2]], [[1, 1], [3, 3], [1, 3]])
    assert np.all(qinter_boxes(b, 1, "exact").is_empty())
    assert np.all(qinter_boxes(b, 1, "projection") == Interval([0, 2], [1, 3]))
    assert np.all(qinter_boxes(b, 2, "exact") == Interval([0, 0], [3, 3]))
    assert np.all(qinter_boxes(b, 3).is_entire())
    c = Interval([[0, 0], [1, 1], [0.5, -5]], [[2, 2], [3, 3], [2.5, 5]])
    assert np.all(qinter_boxes(c, 0) == Interval([1, 1], [2, 2]))  # plain intersection
    with pytest.raises(ValueError, match="method"):
        qinter_boxes(b, 1, "fast")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=">= 0"):
        qinter_boxes(b, -1)
    with pytest.raises(ValueError, match="shape"):
        qinter_boxes(Interval([0, 1], [1, 2]), 0)


def test_qinter_boxes_box_with_an_empty_component_is_empty():
    # box 1 is empty as a whole: its non-empty x component must not count in the projection
    b = Interval.trusted(np.array([[0.0, 0.0], [0.0, np.nan], [5.0, 5.0]]),
                      np.array([[1.0, 1.0], [1.0, np.nan], [6.0, 6.0]]))
    for method in ("exact", "projection"):
        assert np.all(qinter_boxes(b, 1, method).is_empty())
        assert np.all(qinter_boxes(b, 2, method) == Interval([0, 0], [6, 6]))


def test_qinter_boxes_auto_switches_to_projection():
    rng = np.random.default_rng(0)
    n_members = 20
    lo = rng.uniform(-1, 0, (n_members, 2))
    b = Interval.trusted(lo, lo + 1.5)
    q = 5
    assert math.comb(n_members, q) > EXACT_MAX_SUBSETS
    assert np.all(qinter_boxes(b, q) == qinter_boxes(b, q, "projection"))
    assert np.all(qinter_boxes(b, 1) == qinter_boxes(b, 1, "exact"))


@settings(max_examples=300)
@given(box_sets())
def test_qinter_boxes_exact_matches_brute_force(args):
    boxes, q = args
    blo, bhi = brute_hull(boxes, q)
    assert same(qinter_boxes(boxes, q, "exact"), blo, bhi)


@settings(max_examples=200)
@given(box_sets(), st.integers(0, 2**32 - 1))
def test_qinter_boxes_sound_and_ordered(args, seed):
    boxes, q = args
    exact = qinter_boxes(boxes, q, "exact")
    proj = qinter_boxes(boxes, q, "projection")
    auto = qinter_boxes(boxes, q)
    assert np.all(exact.is_subset(proj))
    assert np.all(auto == exact)  # C(N, q) is small here
    pts = sample_points(boxes, np.random.default_rng(seed))
    lo, hi = _as_set(boxes.lo, boxes.hi)
    good = pts[_count(lo, hi, pts) >= boxes.shape[0] - q]
    for res in (exact, proj):
        assert np.all((res.lo <= good) & (good <= res.hi))


@settings(max_examples=60)
@given(member_bounds((3, 4, 2)), st.integers(0, 4), st.sampled_from(["exact", "projection"]))
def test_qinter_boxes_batched_equals_one_by_one(bounds, q, method):
    x = Interval.trusted(*bounds)  # a batch of 3 sets of 4 boxes of dimension 2
    got = qinter_boxes(x, q, method)
    assert got.shape == (3, 2)
    for i in range(3):
        assert np.all(got[i] == qinter_boxes(x[i], q, method))


def test_exported_at_top_level():
    assert bd.qinter is qinter and bd.qinter_boxes is qinter_boxes
    assert "qinter" in bd.__all__ and "qinter_boxes" in bd.__all__


@settings(max_examples=60)
@given(box_sets(max_n_members=6), st.integers(1, 7))
def test_qinter_boxes_exact_in_chunks_of_subsets(args, chunk):
    mod = relaxed
    boxes, q = args
    whole = qinter_boxes(boxes, q, "exact")
    saved = mod._CHUNK_ELEMENTS
    mod._CHUNK_ELEMENTS = chunk  # a few subsets (or one) per chunk
    try:
        assert np.all(qinter_boxes(boxes, q, "exact") == whole)
    finally:
        mod._CHUNK_ELEMENTS = saved
