"""The Interval type: construction, validation, set operations, measures, bisection."""

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import boundest as bd
from boundest import Interval, IntervalVector


def test_construction_forms():
    assert Interval(1, 2).shape == ()
    x = Interval([0, 1], [2, 3])
    assert x.shape == (2,) and np.array_equal(x.lo, [0, 1]) and np.array_equal(x.hi, [2, 3])
    assert Interval(3).is_degenerate()
    b = IntervalVector([[0, 1], [2, 3]])
    assert b.shape == (2,) and np.array_equal(b.hi, [1, 3])
    assert IntervalVector(3).is_entire().all() and IntervalVector(2, Interval(0, 1)).shape == (2,)
    assert bd.Box is IntervalVector
    assert Interval.empty().is_empty() and Interval.empty((2, 3)).shape == (2, 3)
    assert Interval.entire().is_entire()
    assert np.all(Interval(x) == x) and Interval(x) is not x


@pytest.mark.parametrize(("lo", "hi", "match"), [
    (2, 1, r"\[2.0, 1.0\].*lower bound above upper"),
    (np.nan, 1, "NaN"),
    ([0, 5, 1], [1, 4, 2], r"index \(1,\).*\[5.0, 4.0\]"),
    (np.inf, np.inf, "infinite bound"),
    (-np.inf, -np.inf, "infinite bound"),
    ([1, 2, 3], [1, 2], "do not broadcast"),
    ("a", 1, "real numbers"),
])
def test_construction_rejects_bad_input(lo, hi, match):
    with pytest.raises(ValueError, match=match):
        Interval(lo, hi)


def test_from_bounds_rejects_wrong_shape():
    with pytest.raises(ValueError, match="last axis of length 2"):
        IntervalVector([[0, 1, 2]])


def test_indexing_slicing_iteration_and_setitem():
    x = Interval(np.arange(6.0).reshape(3, 2), np.arange(6.0).reshape(3, 2) + 1)
    assert x[1, 0] == Interval(2, 3)
    assert x[:, 1].shape == (3,)
    rows = list(x)
    assert len(rows) == 3 and np.all(rows[2] == Interval([4, 5], [5, 6]))
    x[0] = Interval(-1, 1)
    assert np.all(x[0] == Interval(-1, 1))
    with pytest.raises(TypeError):
        len(Interval(1, 2))


def test_set_operations():
    a, b = Interval(0, 2), Interval(1, 3)
    assert (a & b) == Interval(1, 2)
    assert (a | b) == Interval(0, 3)
    assert (a & Interval(5, 6)).is_empty()
    assert (a | Interval.empty()) == a
    assert (a & Interval.empty()).is_empty()
    assert Interval(1, 2).is_subset(a) and not b.is_subset(a)
    assert Interval.empty().is_subset(a)
    assert Interval(0.5, 1).is_interior_subset(a) and not Interval(0, 1).is_interior_subset(a)
    assert a.contains(2.0) and not a.contains(2.5) and 1.0 in a
    assert not Interval.empty().contains(0.0)
    assert not Interval.entire().contains(np.inf) and not Interval.entire().contains(-np.inf)
    assert a.intersects(b) and not a.intersects(Interval(3, 4))
    assert bd.hull(Interval([0, 5], [1, 6]), axis=0) == Interval(0, 6)


def test_measures():
    x = Interval(1, 2)
    assert x.width() == 1.0 and x.diam() == 1.0 and x.mid() == 1.5 and x.rad() == 0.5
    w = Interval(0.1, 0.3).width()
    # RN(0.3 - 0.1) lies below the real difference of the two floats: width must round up
    assert Fraction(float(w)) >= Fraction(0.3) - Fraction(0.1)
    assert np.isnan(Interval.empty().width())
    assert Interval(0, np.inf).width() == np.inf
    assert Interval.entire().mid() == 0.0
    assert Interval(0, np.inf).mid() == np.finfo(float).max
    assert Interval(-np.inf, 0).mid() == -np.finfo(float).max
    huge = Interval(-np.finfo(float).max, np.finfo(float).max)
    assert huge.mid() == 0.0 and np.isfinite(Interval(1e308, 1.7e308).mid())
    box = IntervalVector([[0, 1], [0, 3], [1, 3]])
    assert box.volume() == 6.0 and box.max_diam() == 3.0
    assert Interval(-3, 2).mag() == 3 and Interval(-3, 2).mig() == 0 and Interval(2, 3).mig() == 2


def test_inflate():
    x = Interval(1, 2).inflate(0.5)
    assert x.lo <= 0.5 and x.hi >= 2.5 and x.width() < 2.0 + 1e-12
    assert Interval.empty().inflate(1).is_empty()
    assert Interval(0, np.inf).inflate(1).hi == np.inf
    with pytest.raises(ValueError):
        Interval(1, 2).inflate(-1)


def test_bisect_scalar_and_boxes():
    left, right = Interval(0, 4).bisect()
    assert left == Interval(0, 2) and right == Interval(2, 4)
    box = IntervalVector([[0, 1], [0, 10], [0, 2]])
    l, r = box.bisect()
    assert l[1] == Interval(0, 5) and r[1] == Interval(5, 10) and l[0] == box[0]
    batch = Interval(np.array([[0.0, 0.0], [0.0, 0.0]]), np.array([[1.0, 4.0], [8.0, 2.0]]))
    l, r = batch.bisect()
    assert l[0, 1] == Interval(0, 2) and l[1, 0] == Interval(0, 4) and l[1, 1] == batch[1, 1]
    # unbounded intervals split at a finite point strictly inside
    for x in (Interval.entire(), Interval(0, np.inf), Interval(-np.inf, -5)):
        l, r = x.bisect()
        assert np.isfinite(l.hi) and l.hi == r.lo and x.lo < l.hi < x.hi
    # adjacent floats: split point is one of the bounds, both halves still cover x
    a = 1.0
    l, r = Interval(a, np.nextafter(a, 2)).bisect()
    assert (l | r) == Interval(a, np.nextafter(a, 2))
    with pytest.raises(ValueError):
        Interval(1, 1).bisect()
    with pytest.raises(ValueError):
        Interval.empty().bisect()


def test_repr_is_readable():
    assert repr(Interval(1, 2)) == "Interval([1.0, 2.0])"
    assert repr(Interval.empty()) == "Interval([empty])"
    assert repr(Interval([0, 1], [1, np.inf])) == "Interval([[0.0, 1.0], [1.0, inf]])"


def test_truth_value_is_an_error():
    with pytest.raises(TypeError):
        bool(Interval(1, 2))


def test_equality_is_set_equality():
    assert Interval(-0.0, 1) == Interval(0.0, 1)
    assert Interval.empty() == Interval.empty()
    assert Interval(1, 2) != Interval(1, 3)
    assert np.array_equal(Interval([1, 2], [3, 4]) == Interval([1, 0], [3, 4]), [True, False])


def test_volume_is_an_upper_bound_of_the_exact_volume():
    rng = np.random.default_rng(7)
    lo = rng.uniform(-1, 1, (400, 3)) * 10.0 ** rng.integers(-3, 4, (400, 3))
    hi = lo + rng.uniform(0, 1, (400, 3)) * 10.0 ** rng.integers(-5, 2, (400, 3))
    vol = Interval(lo, hi).volume()
    for b in range(400):
        exact = Fraction(1)
        for i in range(3):
            exact *= Fraction(hi[b, i]) - Fraction(lo[b, i])
        assert exact <= Fraction(vol[b]) <= exact * (1 + Fraction(1, 2**48))
    assert Interval([0, 0], [0, 1e300]).volume() == 0.0  # a degenerate box has volume 0


@settings(max_examples=60)
@given(st.lists(st.tuples(st.floats(-1e6, 1e6), st.floats(0, 1e3), st.booleans()), min_size=1,
                max_size=4), st.integers(1, 3))
def test_stack_keeps_every_component(parts, n):
    ivs = [Interval.empty(n) if empty else Interval(np.full(n, a), np.full(n, a + w))
           for a, w, empty in parts]
    for axis in (-1, 0):
        box = Interval.stack(ivs, axis=axis)
        assert box.shape == ((n, len(ivs)) if axis == -1 else (len(ivs), n))
        for i, v in enumerate(ivs):
            got = box[..., i] if axis == -1 else box[i]
            assert np.array_equal(got.lo, v.lo, equal_nan=True)
            assert np.array_equal(got.hi, v.hi, equal_nan=True)


def test_stack_broadcasts_numbers_and_rejects_mismatched_shapes():
    box = Interval.stack([Interval([0.0, 1.0], [1.0, 2.0]), 5.0])
    assert np.array_equal(box.lo, [[0.0, 5.0], [1.0, 5.0]])
    assert np.array_equal(box.hi, [[1.0, 5.0], [2.0, 5.0]])
    with pytest.raises(ValueError, match="do not broadcast"):
        Interval.stack([Interval.empty(2), Interval.empty(3)])
    with pytest.raises(ValueError, match="at least one"):
        Interval.stack([])
