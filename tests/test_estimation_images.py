"""The image operator of subpaving estimators (``PavingSets.toward_out``) with its cell grid:
exact images (mpmath) of sampled points stay inside, the grid never makes the result looser,
and the grid, cell and dedup helpers are checked with exact (Fraction) arithmetic."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import boundest as bd
from boundest import Interval
from boundest.estimation import Map, PavingSets, setops
from boundest.estimation.cells import CellGrid
from boundest.paving import Subpaving, image
from boundest.paving.image import _unique_rows, cell_range, grid_step, pave

from .checks import examples


@contextmanager
def _no_grid() -> Iterator[None]:
    """``PavingSets`` builds no cell grid inside (the plain branch and prune)."""
    old = setops._MAX_CELLS
    setops._MAX_CELLS = 0
    try:
        yield
    finally:
        setops._MAX_CELLS = old


F = Map(lambda x: [3 * bd.sin(x[0] + x[1]), 3 * bd.cos(x[0] + x[1])], 2, 2, "f")


def _exact_f(p: np.ndarray) -> tuple[mpmath.mpf, mpmath.mpf]:
    s = mpmath.mpf(float(p[0])) + mpmath.mpf(float(p[1]))
    return 3 * mpmath.sin(s), 3 * mpmath.cos(s)


def _exact_in(q, boxes: Interval) -> bool:
    """The exact point ``q`` lies in one of the closed boxes (compared in mpmath)."""
    return any(all(mpmath.mpf(float(boxes.lo[i, d])) <= q[d] <= mpmath.mpf(float(boxes.hi[i, d]))
                   for d in range(len(q))) for i in range(boxes.shape[0]))


def _problem(seed: int, as_box: bool) -> tuple[Subpaving, Subpaving | Interval, np.ndarray]:
    """V_in: random small boxes; V_out: boxes around the exact images of some of their points
    (so that many sampled images fall inside); sample points of V_in."""
    rng = np.random.default_rng(seed)
    c = rng.uniform(-2, 2, (6, 2))
    w = rng.uniform(0.01, 0.3, (6, 2))
    v_in = Subpaving(Interval(c, c + w), np.zeros(6, dtype=bool))
    k = rng.integers(0, 6, 300)
    pts = c[k] + rng.random((300, 2)) * w[k]
    with mpmath.workdps(30):
        imgs = np.array([[float(v) for v in _exact_f(p)] for p in pts[:8]])
    r = rng.uniform(0.02, 0.4, (8, 2))
    if as_box:
        v_out: Subpaving | Interval = Interval(imgs.min(axis=0) - 0.1, imgs.max(axis=0) + 0.1)
    else:
        v_out = Subpaving(Interval(imgs - r, imgs + r), np.zeros(8, dtype=bool))
    return v_in, v_out, pts


@examples(12, 4)
def test_image_operator_keeps_the_exact_images(n_examples):
    @settings(max_examples=n_examples, deadline=None)
    @given(st.integers(0, 2**31), st.sampled_from([0.02, 0.05, 0.1]), st.booleans())
    def check(seed, eps, as_box):
        v_in, v_out, pts = _problem(seed, as_box)
        out = PavingSets(eps=eps).toward_out(F, v_out, v_in)
        vb = v_out.boxes if isinstance(v_out, Subpaving) else v_out.reshape(1, -1)
        ob = out.boxes if isinstance(out, Subpaving) else out.reshape(1, -1)
        kept = 0
        with mpmath.workdps(40):
            for p in pts:
                q = _exact_f(p)
                if _exact_in(q, vb):  # a point of V_out ∩ f(V_in)
                    kept += 1
                    assert _exact_in(q, ob), (p, q)
        assert kept > 0

    check()


@settings(max_examples=8, deadline=None)
@given(st.integers(0, 2**31), st.sampled_from([0.02, 0.05]), st.booleans())
def test_the_cell_grid_never_loosens_the_image(seed, eps, as_box):
    v_in, v_out, _ = _problem(seed, as_box)
    with_grid = PavingSets(eps=eps)
    a = with_grid.toward_out(F, v_out, v_in)
    with _no_grid():
        without = PavingSets(eps=eps)
        b = without.toward_out(F, v_out, v_in)
    rows_b = {tuple(r) for r in np.hstack([b.boxes.lo, b.boxes.hi]).tolist()}
    assert all(tuple(r) in rows_b for r in np.hstack([a.boxes.lo, a.boxes.hi]).tolist())
    assert with_grid.stats["processed"] <= without.stats["processed"]


def test_the_grid_drops_most_boxes_of_the_seed_case():
    """Jaulin et al. 2001's first step: the image of the frame [-4, 4]^2 within the hull of x(1)'s
    reciprocal image. With the grid, the boxes whose cells are all known stop early."""
    v_in = Subpaving(Interval([[-4.0, -4.0]], [[4.0, 4.0]]), np.zeros(1, dtype=bool))
    v_out = Subpaving(Interval([[-0.25, -3.0]], [[-0.08, 3.0]]), np.zeros(1, dtype=bool))
    a, b = PavingSets(eps=0.05), PavingSets(eps=0.05)
    ra = a.toward_out(F, v_out, v_in)
    with _no_grid():
        rb = b.toward_out(F, v_out, v_in)
    assert 0 < len(ra) <= len(rb)
    assert bool(np.all(ra.hull().is_subset(rb.hull())))
    assert 4 * a.stats["processed"] < b.stats["processed"]


# -- the grid ----------------------------------------------------------------------------------
def test_cell_grid_certify_mark_and_cover():
    h = 0.25
    target = Interval([0.0, 0.0], [1.0, 1.0])
    y0 = Interval([[-0.5, -0.5]], [[2.0, 2.0]])
    g = CellGrid.build(h, target, y0, max_cells=10_000)
    assert g is not None
    # cells meeting the closed target: indices -1..4 (touching ones included)
    assert g.relevant.sum() == 6 * 6
    pts = Interval([[0.1, 0.1], [0.25, 0.6], [1.1, 0.1], [0.6, 0.6]],
                   [[0.1, 0.1], [0.25, 0.6], [1.1, 0.1], [0.6, 0.6]])
    g.certify(pts)  # on a cell face: no; outside the target: no
    cells = g.cells()
    assert cells.shape == (2, 2)
    assert {tuple(r) for r in cells.lo.tolist()} == {(0.0, 0.0), (0.5, 0.5)}
    assert bool(np.all(cells.hi - cells.lo == h))
    inside_known = Interval([[0.05, 0.05]], [[0.2, 0.2]])
    astride = Interval([[0.05, 0.05]], [[0.3, 0.2]])  # one unknown relevant cell
    far = Interval([[5.0, 5.0]], [[6.0, 6.0]])  # misses the target's hull
    empty = Interval.trusted(np.full((1, 2), np.nan), np.full((1, 2), np.nan))
    cov = g.covered(Interval.trusted(np.concatenate([b.lo for b in (inside_known, astride, far,
                                                                  empty)]),
                                  np.concatenate([b.hi for b in (inside_known, astride, far,
                                                                  empty)])))
    assert cov.tolist() == [True, False, True, False]
    assert g.mark(astride).tolist() == [True]
    assert g.covered(astride).tolist() == [True]
    # too large, unbounded or empty regions give no grid
    assert CellGrid.build(h, target, y0, max_cells=10) is None
    assert CellGrid.build(h, Interval.entire(2), Interval([[-np.inf, 0]], [[0, 1]]), 100) is None
    assert CellGrid.build(h, Interval([5.0, 5.0], [6.0, 6.0]), y0, 10_000) is None


@settings(max_examples=200)
@given(st.floats(-1e3, 1e3) | st.sampled_from([-5e-324, 0.0, 5e-324, -1e-310, 0.25, -0.25]),
       st.floats(0, 10) | st.sampled_from([0.0, 5e-324, 1e-310]),
       st.sampled_from([0.01, 0.3, 1.0, 4.0, 16.0]))
def test_cell_range_covers_each_box_with_its_own_cells(lo, w, eps):
    hi = lo + w
    h = grid_step(eps)
    assert Fraction(h) <= Fraction(eps) < 2 * Fraction(h)
    i, j = cell_range(np.array([lo]), np.array([hi]), h)
    i, j = int(i[0]), int(j[0])
    assert i * Fraction(h) <= Fraction(lo) < (i + 1) * Fraction(h)  # the cell of lo
    assert Fraction(hi) <= (j + 1) * Fraction(h)
    assert j == i or j * Fraction(h) < Fraction(hi)  # no useless last cell


@settings(max_examples=50)
@given(st.integers(0, 2**31), st.sampled_from([3, 1000, 2**40, 2**62]), st.integers(1, 3))
def test_unique_rows_is_numpy_unique(seed, spread, m):
    rng = np.random.default_rng(seed)
    idx = rng.integers(-spread // 2, spread // 2, (500, m), dtype=np.int64)
    idx = np.concatenate([idx, idx[:100]])
    assert np.array_equal(_unique_rows(idx), np.unique(idx, axis=0))


def test_pave_and_image_with_extra_boxes():
    y = Interval.trusted(np.array([[0.1, 0.1], [0.12, 0.1], [np.nan, np.nan]]),
                      np.array([[0.2, 0.15], [0.2, 0.15], [np.nan, np.nan]]))  # one empty
    sp = pave(y, 0.125)
    assert sp.stats == {"images": 2, "cells": 4} and not sp.inside.any()  # 2 x 2 cells, twice
    assert bool(np.all(sp.boxes.hi - sp.boxes.lo == 0.125))
    v = Subpaving(Interval([[0.0, 0.0]], [[0.1, 0.1]]), np.zeros(1, dtype=bool))
    w = image(v, lambda x: x + 1.0, eps=0.125, extra=Interval([[5.0, 5.0]], [[5.05, 5.05]]))
    assert w.contains(np.array([[1.05, 1.05], [5.02, 5.02], [3.0, 3.0]])).tolist() == [0, 0, -1]
    with pytest.raises(ValueError, match="extra"):
        image(v, lambda x: x, eps=0.1, extra=Interval([1.0, 1.0]))
