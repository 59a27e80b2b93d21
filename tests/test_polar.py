"""CtcPolar (``x = rho cos theta``, ``y = rho sin theta``): solutions survive (mpmath at 700
digits as the truth), the result is the hull of the solutions (an independent oracle: the
extreme points of the solution set are vertices of its boundary), it is never wider than hull
consistency and strictly tighter where that one is weak; empty, unbounded, degenerate boxes."""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from hypothesis import HealthCheck, given, note, settings
from hypothesis import strategies as st

from boundest import Interval
from boundest.ctc import CtcFwdBwd, CtcPolar, Fixpoint
from boundest.expr import Var
from boundest.expr.functions import cos, sin

#: digits for the exact values: cos(5e-324) and sin(5e-324) / 5e-324 differ from 1 by 1e-647
DPS = 700
CTC = CtcPolar()
INF = math.inf
SETTINGS = settings(max_examples=120, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])


def hc4() -> Fixpoint:
    x, y, rho, theta = Var("x"), Var("y"), Var("rho"), Var("theta")
    return Fixpoint(CtcFwdBwd([x == rho * cos(theta), y == rho * sin(theta), rho >= 0],
                              ["x", "y", "rho", "theta"]), ratio=0.0, max_iter=200)


HC4 = hc4()


def down(v) -> float:
    """The largest float <= v (an mpf)."""
    f = float(v)
    return float(np.nextafter(f, -INF)) if mpmath.mpf(f) > v else f


def up(v) -> float:
    f = float(v)
    return float(np.nextafter(f, INF)) if mpmath.mpf(f) < v else f


def exact_xy(rho: float, theta: float):
    with mpmath.workdps(DPS):
        r, t = mpmath.mpf(rho), mpmath.mpf(theta)
        return r * mpmath.cos(t), r * mpmath.sin(t)


def holds(box: Interval, x, y, rho: float, theta: float) -> bool:
    """Whether the box (4,) holds the point (x, y mpf; rho, theta floats)."""
    lo, hi = box.lo, box.hi
    return bool(mpmath.mpf(lo[0]) <= x <= mpmath.mpf(hi[0])
                and mpmath.mpf(lo[1]) <= y <= mpmath.mpf(hi[1])
                and lo[2] <= rho <= hi[2] and lo[3] <= theta <= hi[3])


# -------------------------------------------------------------------------------------------
# strategies
# -------------------------------------------------------------------------------------------

rhos = st.one_of(st.just(0.0), st.floats(0.0, 10.0), st.floats(0.0, 1e300),
                 st.sampled_from([1e-300, 5e-324, 1.0, 1e300]))
quarter_turns = st.integers(-12, 12).map(lambda k: k * math.pi / 2)
thetas = st.one_of(st.floats(-20.0, 20.0), quarter_turns,
                   quarter_turns.map(lambda t: float(np.nextafter(t, INF))),
                   quarter_turns.map(lambda t: float(np.nextafter(t, -INF))),
                   st.floats(-1e9, 1e9), st.floats(-1e20, 1e20))
widths = st.one_of(st.sampled_from([0.0, 0.0, 1e-300, 1e-12, 1e-6, 1e6, 1e300, INF]),
                   st.floats(0.0, 0.5), st.floats(0.0, 10.0))


@st.composite
def boxes_with_solutions(draw):
    """``(box, points)``: a box around a solution, and solutions in it (``(x, y, rho, theta)``
    with exact ``x, y``), the first one the box was built around."""
    rho, theta = draw(rhos), draw(thetas)
    x, y = exact_xy(rho, theta)
    lo, hi = [], []
    for v in (x, y, mpmath.mpf(rho), mpmath.mpf(theta)):
        w1, w2 = draw(widths), draw(widths)
        with mpmath.workdps(DPS):
            lo.append(down(v - w1) if w1 < INF else -INF)
            hi.append(up(v + w2) if w2 < INF else INF)
    lo[2] = max(lo[2], draw(st.sampled_from([-INF, -1.0, 0.0])))
    box = Interval(lo, hi)
    points = [(x, y, rho, theta)]
    # more solutions: (rho, theta) drawn in the box, kept when the exact (x, y) is in it
    for _ in range(draw(st.integers(0, 8))):
        r = draw(st.floats(max(lo[2], 0.0), min(hi[2], 1e300)))
        t = draw(st.floats(max(lo[3], -1e20), min(hi[3], 1e20)))
        px, py = exact_xy(r, t)
        if holds(box, px, py, r, t):
            points.append((px, py, r, t))
    return box, points


# -------------------------------------------------------------------------------------------
# soundness
# -------------------------------------------------------------------------------------------

@SETTINGS
@given(boxes_with_solutions())
def test_solutions_survive(case):
    box, points = case
    note(f"box={box!r}")
    out = CTC(box)
    note(f"out={out!r}")
    for p in points:
        assert holds(out, *p), p
    assert out.is_subset(box).all()


@SETTINGS
@given(boxes_with_solutions(), st.floats(-100, 100), st.floats(-100, 100))
def test_solutions_survive_about_a_center(case, cx, cy):
    """``x - cx = rho cos theta``: the same solutions, shifted by ``(cx, cy)`` outward."""
    box, points = case
    shift = Interval([cx, cy, 0.0, 0.0], [cx, cy, 0.0, 0.0])
    moved = box + shift
    out = CtcPolar(center=(cx, cy))(moved)
    for x, y, rho, theta in points:
        lo, hi = out.lo, out.hi
        assert mpmath.mpf(lo[0]) <= x + cx <= mpmath.mpf(hi[0])
        assert mpmath.mpf(lo[1]) <= y + cy <= mpmath.mpf(hi[1])
        assert lo[2] <= rho <= hi[2] and lo[3] <= theta <= hi[3]


def test_batch_shape_and_no_mutation():
    lo = np.array([[[1.0, 1.0, 0.0, -10.0]] * 3] * 2)
    hi = np.array([[[2.0, 2.0, 9.0, 10.0]] * 3] * 2)
    box = Interval(lo, hi)
    out = CTC(box)
    assert out.shape == (2, 3, 4)
    assert (box.lo == lo).all() and (box.hi == hi).all()
    assert (out.lo == out.lo[0, 0]).all()


# -------------------------------------------------------------------------------------------
# the hull of the solutions: an oracle from the boundary's vertices
# -------------------------------------------------------------------------------------------

def oracle(lo: np.ndarray, hi: np.ndarray, e: float) -> np.ndarray | None:
    """The hull ``(2, 4)`` of the solutions in a bounded box (``rho >= 0``), None if empty.

    The solution set in the plane is the box cut by the annulus and the angular sector; x, y,
    rho and theta restricted to each of its boundary pieces (a box edge, an arc, a ray) are
    monotone or have their extremes at the axis points of an arc or (rho on an edge) at the
    foot of the perpendicular from the origin, so the hull is that of the pairwise
    intersections of the boundary curves, those points and the origin.
    Points within ``e`` of the box are kept (float arithmetic)."""
    xl, yl, rl, tl = lo
    xh, yh, rh, th = hi
    circles = [r for r in (rl, rh) if r >= 0]
    pts = []  # (x, y, theta or None)
    pts += [(a, b, None) for a in (xl, xh) for b in (yl, yh)]
    pts += [(a, 0.0, None) for a in (xl, xh)] + [(0.0, b, None) for b in (yl, yh)]
    for r in circles:
        for v in (xl, xh, yl, yh):
            if r * r >= v * v:
                s = math.sqrt(r * r - v * v)
                pts += [(v, s, None), (v, -s, None), (s, v, None), (-s, v, None)]
        pts += [(r, 0.0, None), (0.0, r, None), (-r, 0.0, None), (0.0, -r, None)]
        pts += [(r * math.cos(t), r * math.sin(t), t) for t in (tl, th)]
    for t in (tl, th):
        c, s = math.cos(t), math.sin(t)
        for v in (xl, xh):
            if abs(c) > 1e-12 and v / c >= 0:
                pts.append((v, v / c * s, t))
        for v in (yl, yh):
            if abs(s) > 1e-12 and v / s >= 0:
                pts.append((v / s * c, v, t))
    best = None
    for x, y, t in pts:
        r = math.hypot(x, y)
        if not (xl - e <= x <= xh + e and yl - e <= y <= yh + e and rl - e <= r <= rh + e):
            continue
        if t is None:
            phi = math.atan2(y, x)
            k0 = math.ceil((tl - e - phi) / (2 * math.pi))
            k1 = math.floor((th + e - phi) / (2 * math.pi))
            if k0 > k1:
                continue
            t0, t1 = phi + 2 * math.pi * k0, phi + 2 * math.pi * k1
        else:
            t0 = t1 = t
        row = np.array([[x, y, r, t0], [x, y, r, t1]])
        best = row if best is None else np.array([np.minimum(best[0], row[0]),
                                                  np.maximum(best[1], row[1])])
    if rl <= e and xl <= e and xh >= -e and yl <= e and yh >= -e:  # the origin, every theta
        row = np.array([[0.0, 0.0, 0.0, tl], [0.0, 0.0, 0.0, th]])
        best = row if best is None else np.array([np.minimum(best[0], row[0]),
                                                  np.maximum(best[1], row[1])])
    return best


small = st.one_of(st.floats(-3.0, 3.0), st.sampled_from([0.0, 1.0, -1.0, 0.5]))


@st.composite
def bounded_boxes(draw):
    lo, hi = [], []
    for k in range(4):
        a = draw(small if k < 3 else st.one_of(st.floats(-15.0, 15.0), quarter_turns))
        w = draw(st.one_of(st.just(0.0), st.floats(0.0, 3.0), st.floats(0.0, 20.0)))
        lo.append(a)
        hi.append(a + w)
    lo[2], hi[2] = abs(lo[2]), abs(lo[2]) + (hi[2] - lo[2])
    return np.array(lo), np.array(hi)


@settings(max_examples=300, deadline=None)
@given(bounded_boxes())
def test_result_is_the_hull_of_the_solutions(bounds):
    lo, hi = bounds
    out = CTC(Interval(lo, hi))
    note(f"out={out!r}")
    loose = oracle(lo, hi, 1e-9)
    tight = oracle(lo, hi, -1e-9)
    if loose is None:
        assert out.is_empty().all()
        return
    if out.is_empty().all():  # only when the solutions vanish within a rounding error
        assert tight is None
        return
    note(f"oracle={loose!r}")
    assert (out.lo >= loose[0] - 1e-8).all() and (out.hi <= loose[1] + 1e-8).all()
    if tight is not None:
        assert (out.lo <= tight[0] + 1e-8).all() and (out.hi >= tight[1] - 1e-8).all()


# -------------------------------------------------------------------------------------------
# against hull consistency (Fixpoint of CtcFwdBwd on the same equations)
# -------------------------------------------------------------------------------------------

def _inflated(b: Interval, rel: float = 1e-12) -> Interval:
    return Interval.trusted(b.lo - rel * (np.abs(b.lo) + 1.0), b.hi + rel * (np.abs(b.hi) + 1.0))


@settings(max_examples=150, deadline=None)
@given(bounded_boxes())
def test_never_wider_than_hull_consistency(bounds):
    box = Interval(*bounds)
    ours, theirs = CTC(box), HC4(box)
    note(f"ours={ours!r} hc4={theirs!r}")
    if theirs.is_empty().any():
        # HC4 is sound: no solution; ours is minimal up to rounding
        assert ours.is_empty().all() or oracle(*bounds, -1e-9) is None
        return
    assert (ours.is_empty().all() or ours.is_subset(_inflated(theirs)).all())


def test_strictly_tighter_than_hull_consistency():
    """x, y in [1, 2]: the angles of the square are [atan(1/2), atan(2)] and the ranges
    [sqrt(2), sqrt(8)]; HC4 cannot see the corners (rho occurs twice)."""
    box = Interval([1.0, 1.0, 0.0, -math.pi], [2.0, 2.0, 10.0, math.pi])
    ours, theirs = CTC(box), HC4(box)
    assert ours.lo[2] == pytest.approx(math.sqrt(2), rel=1e-14)
    assert ours.hi[2] == pytest.approx(math.sqrt(8), rel=1e-14)
    assert ours.lo[3] == pytest.approx(math.atan(0.5), rel=1e-14)
    assert ours.hi[3] == pytest.approx(math.atan(2.0), rel=1e-14)
    assert ours.is_subset(theirs).all()
    assert theirs.hi[2] > 3.0 and theirs.hi[3] - theirs.lo[3] > 1.0


# -------------------------------------------------------------------------------------------
# special boxes
# -------------------------------------------------------------------------------------------

def test_empty_in_empty_out():
    e = Interval.trusted(np.array([np.nan, 0.0, 0.0, 0.0]), np.array([np.nan, 1.0, 1.0, 1.0]))
    assert CTC(e).is_empty().all()
    assert CTC(Interval.empty(4)).is_empty().all()


@pytest.mark.parametrize(("lo", "hi"), [
    ([0, 0, 1, 0], [0, 0, 2, 0]),  # the origin at range 1 or more
    ([3, 3, 0, -10], [4, 4, 1, 10]),  # out of range
    ([1, 1, 0, 2], [2, 2, 9, 3]),  # the square seen at angles in [2, 3]
    ([-1, -1, -5, 0], [1, 1, -1, 1]),  # rho < 0
    ([1, -1, 0, math.pi / 2], [2, 1, 9, math.pi / 2]),  # x > 0 on the y axis
])
def test_boxes_without_solution_become_empty(lo, hi):
    assert CTC(Interval(lo, hi)).is_empty().all()


def test_box_of_solutions_is_kept():
    """A box that is the hull of its solutions stays (up to rounding)."""
    t0, t1 = 0.3, 0.6
    r0, r1 = 1.0, 2.0
    box = Interval([r0 * math.cos(t1), r0 * math.sin(t0), r0, t0],
                   [r1 * math.cos(t0), r1 * math.sin(t1), r1, t1])
    out = CTC(box)
    assert np.allclose(out.lo, box.lo, rtol=1e-14) and np.allclose(out.hi, box.hi, rtol=1e-14)


@pytest.mark.parametrize(("lo", "hi", "expect_lo", "expect_hi"), [
    # the whole space: nothing to contract but rho >= 0
    ([-INF, -INF, -INF, -INF], [INF, INF, INF, INF], [-INF, -INF, 0, -INF], [INF, INF, INF, INF]),
    # the origin: every angle
    ([0, 0, 0, -7], [0, 0, 5, 7], [0, 0, 0, -7], [0, 0, 0, 7]),
    # an unbounded quadrant seen from several turns: the first and last angles in it
    ([0, 0, 1, -10], [INF, INF, INF, 10], [0, 0, 1, -2 * math.pi], [INF, INF, INF,
                                                                      2 * math.pi + math.pi / 2]),
    # rho degenerate, theta a point: x, y are points
    ([-INF, -INF, 2, math.pi / 3], [INF, INF, 2, math.pi / 3],
     [1.0, math.sqrt(3), 2, math.pi / 3], [1.0, math.sqrt(3), 2, math.pi / 3]),
    # an unbounded theta below, a bounded one above
    ([1, 1, 0, -INF], [2, 2, 9, 0.3], [1, 1, math.sqrt(2), -INF],
     [2, 2, math.sqrt(8), math.atan(2.0) - 2 * math.pi]),
    # huge theta (beyond 2**30): kept; the rest as for a full turn
    ([1, 1, 0, 1e12], [2, 2, 9, 1e13], [1, 1, math.sqrt(2), 1e12],
     [2, 2, math.sqrt(8), 1e13]),
])
def test_special_boxes(lo, hi, expect_lo, expect_hi):
    out = CTC(Interval(lo, hi))
    assert np.allclose(out.lo, expect_lo, rtol=1e-14, atol=1e-15)
    assert np.allclose(out.hi, expect_hi, rtol=1e-14, atol=1e-15)


def test_range_and_bearing_from_a_landmark():
    """A landmark at (3, 4) seen at range 5 and bearing pi + atan2(4, 3) puts the robot at
    the origin."""
    bearing = math.pi + math.atan2(4.0, 3.0)
    ctc = CtcPolar(center=(3.0, 4.0))
    out = ctc(Interval([-10, -10, 4.999, bearing - 1e-9], [10, 10, 5.001, bearing + 1e-9]))
    assert np.allclose(out.lo[:2], 0.0, atol=2e-3) and np.allclose(out.hi[:2], 0.0, atol=2e-3)


# -------------------------------------------------------------------------------------------
# theta at the float nearest a multiple of pi/2 (issue 27, item 10)
# -------------------------------------------------------------------------------------------

def _ulps_beyond(ours: Interval, theirs: Interval) -> np.ndarray:
    """Per box, how many ulps (of ``theirs``' bound) ``ours`` sticks out of ``theirs``."""
    def ulps(a, b):
        return np.abs(a - b) / np.maximum(np.spacing(np.abs(b)), 5e-324)
    lo = np.where(ours.lo < theirs.lo, ulps(ours.lo, theirs.lo), 0.0)
    hi = np.where(ours.hi > theirs.hi, ulps(ours.hi, theirs.hi), 0.0)
    return np.maximum(lo, hi).max(axis=-1)


def test_theta_next_to_a_quarter_turn_bounds_rho():
    """theta is the float t nearest -5 pi/2: cos t = 3.06e-16 (exactly, up to mpmath), not
    0, so x = rho cos t with x in [1e-17, 2e-17] puts rho in [1e-17, 2e-17] / cos t
    = [0.0327, 0.0653] and y = rho sin t in -rho (1 - 5e-32). The angle of t past -5 pi/2
    (3e-16) is below one ulp of t (9e-16): the bounds from cos and sin of t itself must win
    over the float bound of that angle."""
    t = -5 * math.pi / 2
    box = Interval([1e-17, -1, 0, t], [2e-17, 1, 1, t])
    out = CTC(box)
    with mpmath.workdps(60):
        c, s = mpmath.cos(mpmath.mpf(t)), mpmath.sin(mpmath.mpf(t))
        r_lo, r_hi = mpmath.mpf(1e-17) / c, mpmath.mpf(2e-17) / c
        expect = [(1e-17, 2e-17), (r_hi * s, r_lo * s), (r_lo, r_hi), (t, t)]
    for k, (a, b) in enumerate(expect):
        assert out.lo[k] <= a and b <= out.hi[k], k  # sound
        # and tight, up to the roundings (the enclosure of libm's cos t, of rho's bound,
        # then of the product: 12 ulps for y's upper bound, the same as forward-backward)
        assert float(a) - out.lo[k] <= 16 * np.spacing(abs(float(a)))
        assert out.hi[k] - float(b) <= 16 * np.spacing(abs(float(b)))
    assert out.is_subset(_inflated(HC4(box), 1e-15)).all()


def _quarter_turn_boxes(rng: np.random.Generator, n: int):
    """``(lo, hi, points)``: ``n`` boxes, half of them around a solution whose theta is a
    float nearest (or next to) a multiple of pi/2, with one of x, y a few 1e-16 rho; the
    others random boxes whose theta ends are such floats. ``points`` lists, per box, exact
    solutions ``(x, y, rho, theta)`` in it (x, y as mpf)."""
    lo, hi, points = np.empty((n, 4)), np.empty((n, 4)), []
    for i in range(n):
        t = rng.integers(-12, 13) * (math.pi / 2)
        t = float(np.nextafter(t, rng.choice([-INF, INF]))) if rng.random() < 0.3 else t
        if i % 2 == 0:  # around a solution (rho, t); widths zero, tiny or wide
            rho = float(rng.uniform(0.01, 3.0))
            x, y = exact_xy(rho, t)
            p = []
            for k, v in enumerate((x, y, mpmath.mpf(rho), mpmath.mpf(t))):
                w = [0.0, 0.0] if k == 3 and rng.random() < 0.6 else [
                    rng.choice([0.0, 1e-17 * rng.random(), 1e-15 * rng.random(), rng.random()])
                    for _ in range(2)]
                with mpmath.workdps(DPS):  # x = rho cos(5e-324) is below rho by 1e-647 rho
                    p.append((down(v - w[0]), up(v + w[1])))
            lo[i], hi[i] = [a for a, _ in p], [b for _, b in p]
            pts = [(x, y, rho, t)]
        else:  # a random box with a tiny x or y range
            for k in range(3):
                a = rng.uniform(-3.0, 3.0)
                lo[i, k], hi[i, k] = a, a + rng.uniform(0.0, 3.0)
            k = rng.integers(0, 2)
            lo[i, k] = rng.choice([1e-17, -1e-17, 3e-16, -3e-16, 1e-300])
            hi[i, k] = lo[i, k] + abs(lo[i, k]) * rng.uniform(0.0, 2.0)
            lo[i, 2] = abs(lo[i, 2])
            hi[i, 2] = max(hi[i, 2], lo[i, 2])
            w = 0.0 if rng.random() < 0.6 else rng.uniform(0.0, 2.0)
            lo[i, 3], hi[i, 3] = (t, t + w) if rng.random() < 0.5 else (t - w, t)
            pts = []
        # more solutions: (rho, theta) drawn in the box, kept when (x, y) is in it
        for _ in range(20):
            r = float(rng.uniform(max(lo[i, 2], 0.0), hi[i, 2]))
            s = float(rng.uniform(lo[i, 3], hi[i, 3]))
            for r_, s_ in ((r, s), (r, lo[i, 3]), (r, hi[i, 3])):
                px, py = exact_xy(r_, s_)
                if holds(Interval(lo[i], hi[i]), px, py, r_, s_):
                    pts.append((px, py, r_, s_))
        points.append(pts)
    return lo, hi, points


@pytest.mark.parametrize(("seed", "n"), [(0, 60), pytest.param(0, 400, marks=pytest.mark.slow),
                                         pytest.param(1, 400, marks=pytest.mark.slow)])
def test_quarter_turns_as_tight_as_hull_consistency_and_sound(seed, n):
    """Boxes whose theta is (or ends at) a float nearest k pi/2: the result is inside the
    fixpoint of forward-backward propagation up to 16 ulps (libm's and the rounding's
    errors), empty where that one is, and keeps every sampled solution (exact x, y). The
    exact solutions cost mpmath at 700 digits: 60 boxes here, 2 x 400 in the slow part."""
    lo, hi, points = _quarter_turn_boxes(np.random.default_rng(seed), n)
    box = Interval(lo, hi)
    ours, theirs = CTC(box), HC4(box)
    ours_empty, theirs_empty = ours.is_empty().any(-1), theirs.is_empty().any(-1)
    assert not (theirs_empty & ~ours_empty).any()
    both = ~ours_empty & ~theirs_empty
    beyond = _ulps_beyond(ours, theirs)
    assert (beyond[both] <= 16).all(), np.flatnonzero(both & (beyond > 16))
    for i, pts in enumerate(points):
        for p in pts:
            assert holds(ours[i], *p), (i, p)
