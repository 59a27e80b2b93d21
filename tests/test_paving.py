"""SIVIA, subpavings and images: soundness checked with exact rational (or mpmath) arithmetic."""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from boundest import interval as iv
from boundest.ctc import CtcFwdBwd
from boundest.expr import Var
from boundest.interval import Interval
from boundest.paving import Subpaving, box_difference, image, separators, sivia
from boundest.paving.subpaving import pairs

X, Y, Z = Var("x"), Var("y"), Var("z")
SQUARE = Interval([-3, -3], [3, 3])


# -- exact helpers ---------------------------------------------------------------------------
def _sq_range(lo: float, hi: float) -> tuple[Fraction, Fraction]:
    """Exact min and max of t^2 over [lo, hi]."""
    a, b = Fraction(lo), Fraction(hi)
    top = max(a * a, b * b)
    low = Fraction(0) if a <= 0 <= b else min(a * a, b * b)
    return low, top


def _norm2_range(lo: np.ndarray, hi: np.ndarray) -> tuple[Fraction, Fraction]:
    """Exact min and max of |x|^2 over the box."""
    r = [_sq_range(a, b) for a, b in zip(lo, hi, strict=True)]
    return sum(p[0] for p in r), sum(p[1] for p in r)


def _norm2(p: np.ndarray) -> Fraction:
    return sum(Fraction(float(v)) ** 2 for v in p)


def _in_shell(p: np.ndarray, a: float, b: float) -> bool:
    q = _norm2(p)
    return Fraction(a) <= q <= Fraction(b)


def _check_shell(sp: Subpaving, a: float, b: float, points: np.ndarray) -> None:
    """Inside boxes are in {a <= |x|^2 <= b} (exactly); outside boxes have no point of the set
    in their interior; sampled points of the set are in inside or boundary boxes."""
    ins = sp.inner()
    for lo, hi in zip(ins.lo, ins.hi, strict=True):
        low, top = _norm2_range(lo, hi)
        assert Fraction(a) <= low and top <= Fraction(b), (lo, hi)
    for lo, hi in zip(sp.outside.lo, sp.outside.hi, strict=True):
        low, top = _norm2_range(lo, hi)
        assert top <= Fraction(a) or low >= Fraction(b), (lo, hi)
    got = sp.contains(points)
    truth = np.array([_in_shell(p, a, b) for p in points])
    assert np.all(got[truth] >= 0), points[truth & (got < 0)][:5]
    assert not np.any(got[~truth] == 1), points[~truth & (got == 1)][:5]


def _ring_points(rng: np.random.Generator, n: int, dim: int, a: float, b: float,
                 half: float = 3.0) -> np.ndarray:
    """Uniform points of the box, points near both spheres and points exactly on them."""
    u = rng.uniform(-half, half, size=(n, dim))
    d = rng.normal(size=(n, dim))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    r = np.where(rng.random(n) < 0.5, math.sqrt(a), math.sqrt(b)) * (1 + rng.normal(0, 1e-3, n))
    near = d * r[:, None]
    exact = np.zeros((4, dim))
    exact[0, 0], exact[1, 0], exact[2, -1], exact[3, -1] = 1.0, -1.0, 2.0, -2.0
    return np.concatenate([u, near, exact])


# -- SIVIA -----------------------------------------------------------------------------------
def test_ring_f_y_sound_and_volumes_bracket_three_pi():
    rng = np.random.default_rng(1)
    pts = _ring_points(rng, 3000, 2, 1.0, 4.0)
    gaps = []
    for eps in (0.2, 0.05, 0.01):
        sp = sivia(SQUARE, f=X**2 + Y**2, y=Interval([1], [4]), eps=eps, keep_outside=True)
        if eps > 0.01:
            _check_shell(sp, 1.0, 4.0, pts)
        lo_v, hi_v = sp.volume_inner(), sp.volume_outer()
        assert lo_v <= 3 * math.pi <= hi_v
        gaps.append(hi_v - lo_v)
        assert np.all(sp.boundary().max_diam() < eps)
        assert sp.stats["stopped"] == "eps" and sp.stats["processed"] >= len(sp) // 4
    assert gaps[0] > gaps[1] > gaps[2]
    assert gaps[2] < 0.1  # 0.01-wide boundary boxes along two circles of total length 6 pi


def test_ring_outside_inside_boundary_tile_the_box():
    sp = sivia(SQUARE, f=X**2 + Y**2, y=Interval([1], [4]), eps=0.1, keep_outside=True)
    every = Subpaving(Interval.trusted(np.concatenate([sp.boxes.lo, sp.outside.lo]),
                                    np.concatenate([sp.boxes.hi, sp.outside.hi])),
                      np.zeros(len(sp) + sp.outside.shape[0], dtype=bool))
    pts = np.random.default_rng(2).uniform(-3, 3, size=(5000, 2))
    assert np.all(every.contains(pts) == 0)
    i, j = pairs(every.boxes.lo, every.boxes.hi, every.boxes.lo, every.boxes.hi, strict=True)
    assert np.all(i == j)  # interiors pairwise disjoint
    assert every.volume_outer() >= 36.0 > every.volume_inner() - 1e-9


@settings(max_examples=25)
@given(a=st.floats(0.0, 6.0), w=st.floats(0.0, 4.0), eps=st.floats(0.05, 0.6),
       c=st.tuples(st.floats(-1, 1), st.floats(-1, 1)), seed=st.integers(0, 2**31))
def test_shell_property(a, w, eps, c, seed):
    b = a + w
    box = Interval([-2.5 + c[0], -2.5 + c[1]], [2.5 + c[0], 2.5 + c[1]])
    sp = sivia(box, f=X**2 + Y**2, y=Interval([a], [b]), eps=eps, keep_outside=True)
    rng = np.random.default_rng(seed)
    pts = _ring_points(rng, 300, 2, max(a, 1e-6), b, half=2.5) + np.asarray(c)
    pts = pts[np.all((pts >= box.lo) & (pts <= box.hi), axis=1)]
    _check_shell(sp, a, b, pts)


def test_shell_3d():
    box = Interval([-3, -3, -3], [3, 3, 3])
    sp = sivia(box, f=X**2 + Y**2 + Z**2, y=Interval([1], [4]), eps=0.3)
    pts = _ring_points(np.random.default_rng(3), 1500, 3, 1.0, 4.0)
    _check_shell(sp, 1.0, 4.0, pts)
    exact = 4 / 3 * math.pi * 7
    assert sp.volume_inner() <= exact <= sp.volume_outer()


def test_inclusion_test_mode():
    def ring(xb: Interval) -> np.ndarray:
        z = iv.sqr(xb[:, 0]) + iv.sqr(xb[:, 1])
        inside = (z.lo >= 1) & (z.hi <= 4)
        out = (z.hi < 1) | (z.lo > 4)
        return np.where(inside, 1, np.where(out, -1, 0)).astype(np.int8)

    sp = sivia(SQUARE, test=ring, eps=0.1, keep_outside=True)
    _check_shell(sp, 1.0, 4.0, _ring_points(np.random.default_rng(4), 2000, 2, 1.0, 4.0))
    assert sp.volume_inner() <= 3 * math.pi <= sp.volume_outer()
    with pytest.raises(ValueError, match="test must return"):
        sivia(SQUARE, test=lambda b: np.zeros(3), eps=0.1)


def test_contractor_pair_mode_matches_f_y():
    ctc_in, ctc_out = separators(X**2 + Y**2, Interval([1], [4]))
    a = sivia(SQUARE, ctc_in=ctc_in, ctc_out=ctc_out, eps=0.05)
    b = sivia(SQUARE, f=X**2 + Y**2, y=Interval([1], [4]), eps=0.05)
    assert len(a) == len(b) and a.volume_inner() == b.volume_inner()
    # only an outer contractor: no inside box, the outer approximation is still sound
    c = sivia(SQUARE, ctc_out=CtcFwdBwd([(X**2 + Y**2).in_(Interval(1, 4))], ["x", "y"]),
              eps=0.1)
    assert not c.inside.any()
    _check_shell(c, 1.0, 4.0, _ring_points(np.random.default_rng(5), 2000, 2, 1.0, 4.0))


def test_empty_set_full_box_degenerate_box():
    unit = Interval([-1, -1], [1, 1])
    for yy in (Interval([5], [6]), Interval([-2], [-1])):
        sp = sivia(unit, f=X**2 + Y**2, y=yy, eps=0.01, keep_outside=True)
        assert sp.is_empty() and sp.volume_outer() == 0.0 and np.all(sp.hull().is_empty())
        assert sp.outside.shape[0] >= 1
    sp = sivia(unit, f=X**2 + Y**2, y=Interval([-1], [100]), eps=0.01)
    assert len(sp) == 1 and sp.inside.all() and sp.volume_inner() == pytest.approx(4, rel=1e-12)
    sp = sivia(unit, f=[X**2 + Y**2], y=Interval.empty(1), eps=0.01, keep_outside=True)
    assert sp.is_empty() and sp.outside.shape == (1, 2)
    # a degenerate box: the segment x = 0.5, y in [-3, 3]
    seg = Interval([0.5, -3], [0.5, 3])
    sp = sivia(seg, f=X**2 + Y**2, y=Interval([1], [4]), eps=0.01)
    pts = np.stack([np.full(2001, 0.5), np.linspace(-3, 3, 2001)], axis=1)
    _check_shell(sp, 1.0, 4.0, pts)
    assert sp.volume_outer() == 0.0


def test_bad_input():
    with pytest.raises(ValueError, match="bounded"):
        sivia(Interval([-np.inf, 0], [1, 1]), f=X**2 + Y**2, y=Interval([1], [4]))
    with pytest.raises(ValueError, match="exactly one"):
        sivia(SQUARE, eps=0.1)
    with pytest.raises(ValueError, match="eps"):
        sivia(SQUARE, f=X + Y, y=Interval([1], [4]), eps=0.0)
    with pytest.raises(ValueError, match="components"):
        sivia(SQUARE, f=[X, Y], y=Interval([1], [4]))
    with pytest.raises(ValueError, match="dimension"):
        sivia(Interval([0, 0, 0], [1, 1, 1]), f=X + Y, y=Interval([1], [4]))
    with pytest.raises(ValueError, match="non-empty"):
        sivia(Interval.empty(2), f=X + Y, y=Interval([1], [4]))


def test_chunked_frontier_gives_the_same_paving():
    a = sivia(SQUARE, f=X**2 + Y**2, y=Interval([1], [4]), eps=0.05, keep_outside=True)
    b = sivia(SQUARE, f=X**2 + Y**2, y=Interval([1], [4]), eps=0.05, keep_outside=True, batch=7)
    key = np.lexsort(np.concatenate([a.boxes.lo, a.boxes.hi], axis=1).T)
    kb = np.lexsort(np.concatenate([b.boxes.lo, b.boxes.hi], axis=1).T)
    assert np.array_equal(a.boxes.lo[key], b.boxes.lo[kb])
    assert np.array_equal(a.inside[key], b.inside[kb])
    assert a.outside.shape == b.outside.shape and a.stats == b.stats
    with pytest.raises(ValueError, match="batch"):
        sivia(SQUARE, f=X**2 + Y**2, y=Interval([1], [4]), batch=0)


def test_max_boxes_budget_keeps_frontier_as_boundary():
    sp = sivia(SQUARE, f=X**2 + Y**2, y=Interval([1], [4]), eps=1e-4, max_boxes=500)
    assert sp.stats["stopped"] == "max_boxes" and len(sp) <= 500
    _check_shell(sp, 1.0, 4.0, _ring_points(np.random.default_rng(6), 2000, 2, 1.0, 4.0))


# -- box difference and subpaving operations ---------------------------------------------------
@settings(max_examples=40)
@given(st.integers(1, 4), st.integers(0, 2**31))
def test_box_difference(n, seed):
    rng = np.random.default_rng(seed)
    b = 20
    xl = rng.uniform(-1, 0, (b, n))
    xh = xl + rng.uniform(0, 2, (b, n)) * (rng.random((b, n)) > 0.1)
    t = np.sort(rng.uniform(0, 1, (b, n, 2)), axis=2)
    cl, ch = xl + t[..., 0] * (xh - xl), xl + t[..., 1] * (xh - xl)
    cl[rng.random(b) < 0.2] = np.nan  # some c empty
    pieces, parent = box_difference(Interval.trusted(xl, xh), Interval.trusted(cl, ch))
    assert np.all(np.bincount(parent, minlength=b) <= 2 * n)
    assert np.all(pieces.lo >= xl[parent]) and np.all(pieces.hi <= xh[parent])
    pts = xl[:, None, :] + rng.random((b, 50, n)) * (xh - xl)[:, None, :]
    for k in range(b):
        p = pts[k]
        in_c = np.all((p >= cl[k]) & (p <= ch[k]), axis=1)
        mine = parent == k
        sub = Subpaving(pieces[mine], np.zeros(int(mine.sum()), dtype=bool))
        assert np.all(in_c | (sub.contains(p) == 0))
        if not np.isnan(cl[k, 0]):  # pieces' interiors avoid c's interior
            i, _ = pairs(pieces.lo[mine], pieces.hi[mine], cl[k:k + 1], ch[k:k + 1], strict=True)
            assert i.size == 0


def _grid(rng: np.random.Generator, k: int, lo: float, step: float, keep: float) -> Subpaving:
    """Random cells of a k x k grid (dyadic bounds), random labels."""
    i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
    idx = np.stack([i.ravel(), j.ravel()], axis=1)
    idx = idx[rng.random(len(idx)) < keep]
    blo = lo + idx * step
    return Subpaving(Interval.trusted(blo, blo + step), rng.random(len(idx)) < 0.5)


@settings(max_examples=40)
@given(st.integers(0, 2**31))
def test_subpaving_ops_against_membership(seed):
    rng = np.random.default_rng(seed)
    a = _grid(rng, 8, 0.0, 0.125, 0.6)
    b = _grid(rng, 6, 0.0625, 0.1875, 0.6)
    pts = np.concatenate([rng.uniform(-0.1, 1.3, (800, 2)),
                          np.round(rng.uniform(0, 1.2, (200, 2)) * 16) / 16])  # on grid lines
    ca, cb = a.contains(pts), b.contains(pts)
    u = a.union(b)
    assert np.array_equal(u.contains(pts), np.maximum(ca, cb))
    i, j = pairs(u.boxes.lo, u.boxes.hi, u.boxes.lo, u.boxes.hi, strict=True)
    assert np.all(i == j)
    inter = a.intersect(b)
    assert np.array_equal(inter.contains(pts), np.minimum(ca, cb))
    box = Interval([0.2, 0.3], [0.7, 1.0])
    ab = a.intersect(box)
    inbox = np.all((pts >= box.lo) & (pts <= box.hi), axis=1)
    assert np.array_equal(ab.contains(pts), np.where(inbox, ca, -1))
    # exact volumes of dyadic cells
    cell = 0.125**2
    assert a.volume_inner() <= a.inside.sum() * cell <= a.volume_outer() + 0 * len(a)
    assert a.volume_outer() >= len(a) * cell
    assert u.volume_inner() >= max(a.volume_inner(), b.volume_inner()) * (1 - 1e-12)
    if len(a):
        h = a.hull()
        assert np.all(h.lo <= a.boxes.lo) and np.all(a.boxes.hi <= h.hi)
    # classify: boxes inside an inside box, meeting nothing, or in between
    cls = a.classify(Interval.trusted(pts, pts))
    assert np.array_equal(cls, np.where(ca == 1, 1, np.where(ca == -1, -1, 0)))


def test_subpaving_errors():
    a = Subpaving.from_box(Interval([0, 0], [1, 1]))
    assert len(a) == 1 and not a.inside.any() and a.volume_outer() >= 1.0
    with pytest.raises(ValueError, match="dimension"):
        a.intersect(Interval([0, 0, 0], [1, 1, 1]))
    with pytest.raises(ValueError, match="dimension"):
        a.union(Subpaving.from_box(Interval([0], [1])))
    with pytest.raises(ValueError, match="dimension"):
        a.contains(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="NaN"):
        a.contains(np.array([[np.nan, 0.0]]))
    with pytest.raises(ValueError, match="inside"):
        Subpaving(Interval([[0, 0]], [[1, 1]]), [True, False])
    with pytest.raises(ValueError, match="empty or invalid"):
        Subpaving(Interval.trusted(np.array([[0.0, np.nan]]), np.array([[1.0, np.nan]])), [True])
    e = Subpaving.empty(2)
    assert e.is_empty() and e.volume_inner() == 0.0 == e.volume_outer()
    assert np.all(e.hull().is_empty()) and len(e.intersect(a)) == 0 and len(e.union(a)) == 1


def test_volume_rounding_is_directed():
    third = 1 / 3  # widths that are not exact products
    boxes = Interval.trusted(np.zeros((1000, 3)), np.full((1000, 3), third))
    sp = Subpaving(boxes, np.ones(1000, dtype=bool))
    exact = 1000 * Fraction(third) ** 3
    assert Fraction(sp.volume_inner()) <= exact <= Fraction(sp.volume_outer())
    assert sp.volume_outer() - sp.volume_inner() < 1e-10


# -- image ------------------------------------------------------------------------------------
def _f_seed(x: Interval) -> Interval:
    s = x[:, 0] + x[:, 1]
    a, b = 3 * iv.sin(s), 3 * iv.cos(s)
    return Interval.trusted(np.stack([a.lo, b.lo], axis=1), np.stack([a.hi, b.hi], axis=1))


def _covered(sp: Subpaving, exact: list[tuple[mpmath.mpf, ...]]) -> bool:
    """Every exact point lies in a box of ``sp`` (compared in mpmath)."""
    for q in exact:
        near = np.array([float(v) for v in q])
        cand = np.flatnonzero(np.all((sp.boxes.lo <= near + 1e-9) & (near - 1e-9 <= sp.boxes.hi),
                                     axis=1))
        if not any(all(mpmath.mpf(sp.boxes.lo[c, d]) <= q[d] <= mpmath.mpf(sp.boxes.hi[c, d])
                       for d in range(len(q))) for c in cand):
            return False
    return True


@settings(max_examples=15)
@given(st.integers(0, 2**31), st.floats(0.02, 0.3))
def test_image_contains_exact_images(seed, eps):
    rng = np.random.default_rng(seed)
    v = sivia(Interval([-1, -1], [1, 1]), f=X**2 + Y**2, y=Interval([0.25], [1]), eps=0.1)
    w = image(v, _f_seed, eps=eps)
    assert not w.inside.any() and np.all(w.boxes.max_diam() <= eps)
    k = rng.integers(0, len(v), 200)
    pts = v.boxes.lo[k] + rng.random((200, 2)) * (v.boxes.hi[k] - v.boxes.lo[k])
    mpmath.mp.prec = 120
    exact = []
    for p in pts:
        s = mpmath.mpf(float(p[0])) + mpmath.mpf(float(p[1]))
        exact.append((3 * mpmath.sin(s), 3 * mpmath.cos(s)))
    assert _covered(w, exact)


def test_image_linear_map_and_edge_cases():
    def shift(x: Interval) -> Interval:
        return x + 1.0

    v = Subpaving(Interval([[0, 0], [0.5, 0]], [[0.5, 0.5], [1, 0.5]]), [True, False])
    w = image(v, shift, eps=0.25)
    pts = np.random.default_rng(7).uniform(0, 1, (500, 2)) * [1, 0.5]
    assert np.all(w.contains(pts + 1.0) == 0)
    assert w.volume_outer() >= 0.5
    assert w.volume_outer() <= 0.5 + 4 * 1.5 * 0.25  # one ring of cells at most
    assert image(Subpaving.empty(2), shift, eps=0.1).is_empty()
    # an image that cannot shrink (a constant-width term): the budget stops the bisection
    wide = image(v, lambda x: x + Interval(0, 1), eps=0.25, max_boxes=200)
    assert np.all(wide.contains(pts) == 0) and np.all(wide.contains(pts + 0.9) == 0)
    with pytest.raises(ValueError, match="eps"):
        image(v, shift, eps=-1.0)
    with pytest.raises(ValueError, match="f must map"):
        image(v, lambda x: x[:, 0], eps=0.1)


def test_plot_paving():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from boundest.plot import plot_paving

    sp = sivia(SQUARE, f=X**2 + Y**2, y=Interval([1], [4]), eps=0.2, keep_outside=True)
    fig, ax = plt.subplots()
    colls = plot_paving(sp, ax=ax)
    assert [len(c.get_paths()) for c in colls] == [sp.outside.shape[0], len(sp.boundary()),
                                                   len(sp.inner())]
    with pytest.raises(ValueError, match="dims"):
        plot_paving(sp, ax=ax, dims=(0, 2))
    plt.close(fig)
