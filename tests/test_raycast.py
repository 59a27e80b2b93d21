"""ObstacleMap and CtcRayCast: the range sensor of Jaulin's robust set-membership observer
(pool robot).

The oracle is independent of boundest: the first-hit distance of the data formulas evaluated
with mpmath at 60 digits, from a float ray (x, y, beta) whose numbers are exact. Boxes are built
around the true tuple with random widths and outward-stepped bounds, so the exact value is
inside; every contraction must keep it. Expected tight results are derived by hand in the
comments.
"""

from __future__ import annotations

import json
import math

import mpmath
import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, note, settings
from hypothesis import strategies as st

from boundest import Interval
from boundest.ctc import CtcRayCast, Fixpoint, ObstacleMap

mpmath.mp.dps = 60
POOL = ObstacleMap.pool()
CTC = CtcRayCast(POOL)


# -------------------------------------------------------------------------------------------
# the oracle
# -------------------------------------------------------------------------------------------

def exact_distance(m: ObstacleMap, x: float, y: float, beta: float):
    """``(d, margin)``: the first-hit distance (mpf, ``inf`` for no hit) and how far the ray
    is from changing which obstacles it hits (distance of tau to 0 and 1, of the discriminant
    to 0, of s to 0, as mpf)."""
    mp = mpmath.mpf
    x, y, beta = mp(x), mp(y), mp(beta)
    c, s = mpmath.cos(beta), mpmath.sin(beta)
    best, margin = mpmath.inf, mpmath.inf
    for (ax, ay), (bx, by) in m.segments:
        ex, ey = mp(bx) - mp(ax), mp(by) - mp(ay)
        wx, wy = mp(ax) - x, mp(ay) - y
        den = c * ey - s * ex
        if den == 0:
            continue
        dist = (wx * ey - wy * ex) / den
        tau = (wx * s - wy * c) / den
        margin = min(margin, abs(tau), abs(tau - 1), abs(dist))
        if dist > 0 and 0 <= tau <= 1:
            best = min(best, dist)
    for (cx, cy), r in zip(m.centers, m.radii, strict=True):
        wx, wy = x - mp(cx), y - mp(cy)
        b = c * wx + s * wy
        q = wx * wx + wy * wy - mp(r) ** 2
        margin = min(margin, abs(b * b - q))
        if b * b >= q:
            dist = -b - mpmath.sqrt(b * b - q)
            margin = min(margin, abs(dist))
            if dist > 0:
                best = min(best, dist)
    return best, margin


def down(v: float) -> float:
    return float(np.nextafter(v, -np.inf))


def up(v: float) -> float:
    return float(np.nextafter(v, np.inf))


def keeps(box: Interval, x: float, y: float, beta: float, d) -> bool:
    """Whether the contracted box (4,) holds the true tuple (d an mpf)."""
    lo, hi = box.lo, box.hi
    return bool(lo[0] <= x <= hi[0] and lo[1] <= y <= hi[1] and lo[2] <= beta <= hi[2]
                and mpmath.mpf(lo[3]) <= d <= mpmath.mpf(hi[3]))


# -------------------------------------------------------------------------------------------
# strategies
# -------------------------------------------------------------------------------------------

@st.composite
def free_points(draw):
    """A ray origin in the pool's free space (inside the rectangle, outside the discs) and a
    direction."""
    x = draw(st.floats(0.001, 19.999))
    y = draw(st.floats(0.001, 9.999))
    for (cx, cy), r in zip(POOL.centers, POOL.radii, strict=True):
        assume(math.hypot(x - cx, y - cy) > r + 1e-3)
    # grazing rays: aimed at a wall's end (a corner) or tangent to a pillar, up to rounding
    grazing = [math.atan2(ay - y, ax - x) for ax, ay in POOL.segments[:, 0]]
    for (cx, cy), r in zip(POOL.centers, POOL.radii, strict=True):
        side = math.asin(r / math.hypot(cx - x, cy - y))
        grazing += [math.atan2(cy - y, cx - x) + side, math.atan2(cy - y, cx - x) - side]
    beta = draw(st.one_of(st.floats(-math.pi, math.pi), st.floats(-20.0, 20.0),
                          st.sampled_from([0.0, math.pi / 2, math.pi, -math.pi / 2,
                                           math.pi / 4]),
                          st.sampled_from(grazing)))
    return x, y, beta


widths = st.one_of(st.just(0.0), st.sampled_from([1e-12, 1e-6, 1e-3]),
                   st.floats(0.0, 0.2), st.floats(0.0, 5.0), st.just(math.inf))


@st.composite
def true_boxes(draw):
    """``(box bounds (2, 4), x, y, beta, d)``: a box around a true tuple of the pool."""
    x, y, beta = draw(free_points())
    d, _ = exact_distance(POOL, x, y, beta)
    assert d < mpmath.inf  # the pool is closed
    note(f"x={x!r}, y={y!r}, beta={beta!r}, d={mpmath.nstr(d, 20)}")
    lo, hi = [], []
    for v in (x, y, beta):
        w1, w2 = draw(widths), draw(widths)
        lo.append(down(v - w1) if w1 else v)
        hi.append(up(v + w2) if w2 else v)
    df = float(d)
    w1, w2 = draw(widths), draw(widths)
    lo.append(down(down(df) - w1))
    hi.append(up(up(df) + w2))
    assert mpmath.mpf(lo[3]) < d < mpmath.mpf(hi[3])
    return np.array([lo, hi]), x, y, beta, d


SETTINGS = settings(max_examples=150, deadline=None,
                    suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])


# -------------------------------------------------------------------------------------------
# ObstacleMap
# -------------------------------------------------------------------------------------------

def test_pool_map_embedded():
    # the pool of the data definition: the rectangle [0, 20] x [0, 10] counter-clockwise from
    # the origin, pillars (7, 6.5) r 0.6 and (13.5, 3) r 0.45
    m = ObstacleMap.pool()
    assert m.segments.tolist() == [[[0, 0], [20, 0]], [[20, 0], [20, 10]], [[20, 10], [0, 10]],
                                   [[0, 10], [0, 0]]]
    assert m.radii.tolist() == [0.6, 0.45]
    assert m.centers.tolist() == [[7.0, 6.5], [13.5, 3.0]]
    assert m.segment_ids == ["wall0", "wall1", "wall2", "wall3"]
    assert m.circle_ids == ["cyl0", "cyl1"]


def test_distance_by_hand():
    # from (5, 5): +x meets nothing before wall1 (x = 20) -> 15; +y meets wall2 -> 5;
    # from (5, 6.5) along +x the pillar (7, 6.5), r 0.6 is at 2 - 0.6 = 1.4;
    # from (10, 3) along +x the pillar (13.5, 3), r 0.45 at 3.5 - 0.45 = 3.05;
    # from (1, 1) at 225 degrees: the corner (0, 0) at sqrt(2)
    d = POOL.distance([5, 5, 5, 10, 1], [5, 5, 6.5, 3, 1],
                      [0, np.pi / 2, 0, 0, 5 * np.pi / 4])
    np.testing.assert_allclose(d, [15, 5, 1.4, 3.05, math.sqrt(2)], rtol=1e-14)
    # broadcasting, and inf where nothing is hit (an open map), NaN in -> NaN out
    m = ObstacleMap([[(0, 0), (0, 10)]], [((5, 0), 1.0)])
    assert m.distance(3.0, 0.0, np.array([[0.0], [np.pi]])).shape == (2, 1)
    assert m.distance(3.0, 0.0, np.pi / 2) == np.inf
    assert m.distance(-1.0, 5.0, 0.0) == 1.0  # from behind the segment: it is hit too
    assert m.distance(2.0, 5.0, 0.0) == np.inf  # the segment is behind (s < 0)
    assert np.isnan(m.distance(np.nan, 0.0, 0.0))
    # from inside a disc, the near root is behind: no hit (the data formulas)
    assert m.distance(5.0, 0.0, 0.0) == np.inf


@SETTINGS
@given(free_points())
def test_distance_matches_the_exact_formulas(p):
    x, y, beta = p
    d, margin = exact_distance(POOL, x, y, beta)
    assume(margin > 1e-9)  # far from a corner, a tangent or a change of obstacle
    assert POOL.distance(x, y, beta) == pytest.approx(float(d), rel=1e-10, abs=1e-10)


def _write(tmp_path, data, name="map.json"):
    p = tmp_path / name
    p.write_text(data if isinstance(data, str) else json.dumps(data))
    return p


@pytest.mark.parametrize(("data", "message"), [
    ('{"walls": [', "not JSON"),
    ("[1, 2]", "must be a JSON object"),
    ({"description": "nothing"}, "no obstacle"),
    ({"walls": {"p1": [0, 0]}}, "'walls' must be a list"),
    ({"walls": [{"p1": [0, 0]}]}, "walls[0] lacks the key(s) p2"),
    ({"walls": [[0, 0, 1, 1]]}, "walls[0] must be an object"),
    ({"walls": [{"p1": [0, 0], "p2": [1, "a"]}]}, "walls[0].p2 must be two finite numbers"),
    ({"walls": [{"p1": [0, 0, 0], "p2": [1, 1]}]}, "walls[0].p1 must be two finite numbers"),
    ({"walls": [{"p1": [0, 0], "p2": [1, 1]}, {"p1": [2, 2], "p2": [2, 2]}]},
     "walls[1] has p1 == p2"),
    ('{"walls": [{"p1": [0, NaN], "p2": [1, 1]}]}', "walls[0].p1 must be two finite numbers"),
    ({"cylinders": [{"center": [0, 0], "radius": -1}]}, "cylinders[0].radius must be"),
    ({"cylinders": [{"center": [0, 0], "radius": "1"}]}, "cylinders[0].radius must be"),
    ({"cylinders": [{"center": [0, 0]}]}, "cylinders[0] lacks the key(s) radius"),
    ({"cylinders": [{"center": [0, 0], "radius": 1, "id": 3}]}, "cylinders[0].id must be"),
])
def test_bad_map_files(tmp_path, data, message):
    p = _write(tmp_path, data)
    with pytest.raises(ValueError) as exc:
        ObstacleMap.from_json(p)
    assert message in str(exc.value) and str(p) in str(exc.value)


def test_map_from_dict_and_constructor_errors(tmp_path):
    m = ObstacleMap.from_dict({"walls": [{"p1": [0, 0], "p2": [1, 0]}]})
    assert m.segment_ids == ["walls[0]"] and m.n_obstacles == 1
    with pytest.raises(ValueError, match=r"my\.json: 'cylinders' must be a list"):
        ObstacleMap.from_dict({"cylinders": 3}, source="my.json")
    with pytest.raises(ValueError, match="cannot read"):
        ObstacleMap.from_json(tmp_path / "missing.json")
    with pytest.raises(ValueError, match="shape"):
        ObstacleMap([(0, 0), (1, 1)])
    with pytest.raises(ValueError, match="radius > 0"):
        ObstacleMap((), [((0, 0), 0.0)])
    with pytest.raises(ValueError, match="equal ends"):
        ObstacleMap([[(1, 1), (1, 1)]])
    with pytest.raises(TypeError, match="ObstacleMap"):
        CtcRayCast("pool")  # type: ignore[arg-type]


# -------------------------------------------------------------------------------------------
# CtcRayCast: soundness
# -------------------------------------------------------------------------------------------

@SETTINGS
@given(true_boxes())
def test_true_tuple_survives(case):
    bounds, x, y, beta, d = case
    box = Interval(bounds[0], bounds[1])
    out = CTC(box)
    assert out.is_subset(box).all()
    assert keeps(out, x, y, beta, d), out
    assert keeps(Fixpoint(CTC, ratio=1e-3, max_iter=20)(box), x, y, beta, d)


@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])
@given(st.lists(true_boxes(), min_size=1, max_size=12))
def test_batches_are_the_rows(cases):
    lo = np.array([c[0][0] for c in cases])
    hi = np.array([c[0][1] for c in cases])
    out = CTC(Interval(lo, hi))
    assert out.shape == (len(cases), 4)
    for i, (_, x, y, beta, d) in enumerate(cases):
        assert keeps(out[i], x, y, beta, d)
        one = CTC(Interval(lo[i], hi[i]))
        np.testing.assert_array_equal(one.lo, out.lo[i])
        np.testing.assert_array_equal(one.hi, out.hi[i])
    # a batch of shape (k, 1, 4) gives the same rows
    deep = CTC(Interval(lo[:, None, :], hi[:, None, :]))
    np.testing.assert_array_equal(deep.lo[:, 0], out.lo)


def test_not_certain_pillar_keeps_the_far_wall():
    # y in [6.5, 8]: a ray along +x at y = 7.5 passes above the pillar (7, 6.5), r = 0.6, and
    # meets wall1 at 15 m, so d = 15 is possible and must stay
    out = CTC(Interval([5.0, 6.5, 0.0, 14.0], [5.0, 8.0, 0.0, 16.0]))
    assert out.lo[3] <= 15.0 <= out.hi[3] and out.lo[1] <= 7.5 <= out.hi[1]
    # (the y hidden by the pillar, [6.5, 7.1], are not removed: the box is not split, and the
    # hull of "on wall1" keeps all of y; d itself is pinned to 15 by wall1)
    assert out.lo[1] == 6.5 and 15.0 - 1e-9 <= out.lo[3] <= out.hi[3] <= 15.0 + 1e-9


def test_unbounded_and_entire_boxes():
    # nothing is certain about an unbounded box: still sound, no warning, no error
    out = CTC(Interval.entire(4))
    assert (out.lo[3] >= 0) and out.hi[3] == np.inf
    # x, y degenerate, beta entire: every direction is possible. d in [0, oo] becomes the
    # hull over the obstacles: at most the farthest corner, |(20, 0) - (5, 5)| = sqrt(250)
    # (from d^2 = |a + tau e - p|^2), at least the pillar's near side (|(7, 6.5) - (5, 5)| - 0.6)
    out = CTC(Interval([5.0, 5.0, -np.inf, 0.0], [5.0, 5.0, np.inf, np.inf]))
    assert 0 < out.lo[3] <= 2.5 - 0.6 + 1e-9
    assert math.sqrt(250) - 1e-9 <= out.hi[3] <= math.sqrt(250) + 1e-9


# -------------------------------------------------------------------------------------------
# CtcRayCast: tightness (derived by hand)
# -------------------------------------------------------------------------------------------

def test_pillar_in_the_way_removes_the_wall_distance():
    # a square room [0, 10]^2 with a pillar of centre (8, 5) and radius 1; the robot at (5, 5)
    # looking along +x sees the pillar at 3 - 1 = 2, not the wall at 5. For the box
    # x, y in [4.9, 5.1], beta in [-0.01, 0.01], every ray meets the pillar: the centre's
    # offset from the ray's line is at most 0.1 + 3.1 * 0.01 < 1, and s <= 3.1 - sqrt(1 - 0.14^2)
    # < 2.2. So d in [4, 6] (only the wall) is impossible.
    room = ObstacleMap([[(0, 0), (10, 0)], [(10, 0), (10, 10)], [(10, 10), (0, 10)],
                        [(0, 10), (0, 0)]], [((8.0, 5.0), 1.0)])
    ctc = CtcRayCast(room)
    box = Interval([4.9, 4.9, -0.01, 4.0], [5.1, 5.1, 0.01, 6.0])
    assert ctc(box).is_empty().all()
    # part (a) alone keeps it (the end point can be on the wall x = 10): (b) does the work
    assert not ctc.contract_on_obstacle(box).is_empty().any()
    assert ctc.contract_nearest(box).is_empty().all()
    assert ctc.nearest_bound(box[:3]) < 2.2
    # d in [0, 100]: (b) cuts d to below 2.2, then (a) keeps only the pillar: d near 2
    out = Fixpoint(ctc)(Interval([4.9, 4.9, -0.01, 0.0], [5.1, 5.1, 0.01, 100.0]))
    assert 1.8 < out.lo[3] <= 2.0 <= out.hi[3] < 2.2


def test_pool_pillar_and_walls_by_hand():
    # (5, 6.5) along +x: the pillar cyl0 is at exactly 1.4; the wall at 15 is hidden
    assert CTC(Interval([4.9, 6.5, 0.0, 14.0], [5.1, 6.5, 0.0, 16.0])).is_empty().all()
    # a reading of 1.4 +- 0.01 puts x within 0.01 of 5 (it was [4, 6])
    out = CTC(Interval([4.0, 6.5, 0.0, 1.39], [6.0, 6.5, 0.0, 1.41]))
    assert out.lo[0] >= 4.99 - 1e-9 and out.hi[0] <= 5.01 + 1e-9
    # (10, 5) looking up (+y): wall2 (y = 10) at 5; a degenerate ray pins d to a few ulps
    out = CTC(Interval([10.0, 5.0, np.pi / 2, 0.0], [10.0, 5.0, np.pi / 2, 100.0]))
    assert out.lo[3] <= 5.0 <= out.hi[3] and out.hi[3] - out.lo[3] < 1e-12
    # (10, 5) along +x: cyl1 (13.5, 3) is 2 off the line; wall1 at 10. d in [0.5, 0.6] is on
    # no obstacle: part (a) empties it
    assert CTC.contract_on_obstacle(
        Interval([10.0, 5.0, 0.0, 0.5], [10.0, 5.0, 0.0, 0.6])).is_empty().all()


def test_empty_and_degenerate_boxes():
    assert CTC(Interval.empty(4)).is_empty().all()
    assert CTC(Interval.empty((3, 4))).is_empty().all()
    # one empty component empties the box; the other rows of the batch are untouched by it
    lo = np.array([[5.0, 6.5, 0.0, 1.3], [np.nan, 6.5, 0.0, 1.3]])
    hi = np.array([[5.0, 6.5, 0.0, 1.5], [np.nan, 6.5, 0.0, 1.5]])
    out = CTC(Interval.trusted(lo, hi))
    assert out[1].is_empty().all() and not out[0].is_empty().any()
    assert out.lo[0, 3] <= 1.4 <= out.hi[0, 3]
    # a fully degenerate box: the float 1.4 is not the exact distance 2 - 0.6 of the floats
    # (0.6 is not 3/5), so the box may or may not survive; a box one ulp around it does
    d = exact_distance(POOL, 5.0, 6.5, 0.0)[0]
    out = CTC(Interval([5.0, 6.5, 0.0, down(1.4)], [5.0, 6.5, 0.0, up(1.4)]))
    assert keeps(out, 5.0, 6.5, 0.0, d)
    with pytest.raises(ValueError, match="dimension 4"):
        CTC(Interval([0, 0, 0], [1, 1, 1]))
