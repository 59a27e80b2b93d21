"""Box consistency (``CtcBox``, BC3): solutions survive (mpmath and exact fractions as the
truth), it is strictly tighter than hull consistency where a variable occurs several times,
and empty, unbounded, degenerate inputs."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from boundest import Interval
from boundest.csp import CtcBox
from boundest.csp.boxcons import occurrences
from boundest.ctc import CtcFwdBwd, Fixpoint
from boundest.expr import Model, Var
from boundest.expr.functions import sqr

from .checks import examples
from .strategies import solvable_csps

x, z = Var("x"), Var("z")


def csps():
    """Random CSPs whose sampled solutions are known (``strategies.solvable_csps``)."""
    return solvable_csps((1, 3), 3, [0.0, 1e-9, 0.01, 0.3], 7)


@examples(120, 6)
def test_solutions_survive_box_consistency(n_examples):
    @settings(max_examples=n_examples, deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(csps(), st.sampled_from([(1e-8, 40), (1e-3, 12), (0.0, 52)]))
    def check(csp, opts):
        model, n, pts = csp
        names = model.variable_names()
        eps, depth = opts
        ctc = CtcBox(model, names, eps=eps, max_depth=depth, max_steps=300)
        hc = Fixpoint(CtcFwdBwd(model, names))
        m = len(names)
        # a batch: the full box, boxes around each solution point, an empty one
        rows_lo = [[-np.inf] * m] + [[v - 0.3 for v in p] + [-np.inf] * (m - n) for p in pts]
        rows_hi = [[np.inf] * m] + [[v + 0.3 for v in p] + [np.inf] * (m - n) for p in pts]
        box = Interval.trusted(np.array([*rows_lo, [np.nan] * m]),
                               np.array([*rows_hi, [np.nan] * m]))
        for out in (ctc(box), ctc(hc(box)), Fixpoint(CtcBox(model, names) & hc)(box)):
            for p in pts:
                for r in range(len(pts) + 1):
                    if all(rows_lo[r][i] <= p[i] <= rows_hi[r][i] for i in range(n)):
                        assert all(out.lo[r, i] <= p[i] <= out.hi[r, i] for i in range(n)), (r, p)
            assert np.isnan(out.lo[-1]).all()

    check()


@settings(max_examples=200, deadline=None)
@given(st.integers(-256, 256), st.integers(0, 64), st.integers(0, 64),
       st.sampled_from([0, 1, 2]))
def test_exact_solutions_of_polynomials_survive(k, below, above, which):
    """``f(x) == z`` with ``x = k / 64`` and ``z = f(x)`` exact in float64 (checked with
    fractions), in a box around ``(x, z)``: ``x`` must survive."""
    xv = k / 64
    f = [lambda v: v * v - v, lambda v: v * (v - 3) * (v + 2), lambda v: (v - 1) * (v - 1) - v]
    zq = f[which](Fraction(k, 64))
    zv = float(zq)
    assert Fraction(zv) == zq  # the constraint holds exactly at (xv, zv)
    ctc = CtcBox([f[which](x) == z], ["x", "z"])
    box = Interval([xv - below / 16, zv], [xv + above / 16, zv])
    out = ctc(box)
    assert out.lo[0] <= xv <= out.hi[0]
    assert out.lo[1] == zv == out.hi[1]


def test_tighter_than_hull_consistency():
    # x (x - 1) = 0 on [-0.5, 3]: both factors contain 0, hull consistency is stuck
    box = Interval([-0.5], [3.0])
    hc = Fixpoint(CtcFwdBwd([x * (x - 1) == 0]))(box)
    bc = CtcBox([x * (x - 1) == 0], eps=1e-9)(box)
    assert hc.lo[0] == -0.5 and hc.hi[0] == 3.0
    assert bc.lo[0] <= 0.0 and bc.hi[0] >= 1.0 and bc.width()[0] < 1.0 + 1e-8
    # x x - x = 0 on [-10, 10]: solutions 0 and 1, hull consistency cannot cut
    box = Interval([-10.0], [10.0])
    hc = Fixpoint(CtcFwdBwd([x * x - x == 0]))(box)
    bc = CtcBox([x * x - x == 0], eps=1e-9)(box)
    assert hc.width()[0] == 20.0
    assert bc.lo[0] <= 0.0 and bc.hi[0] >= 1.0 and bc.width()[0] < 1.0 + 1e-8
    # sqr(x) - x = 0: the fixpoint of hull consistency creeps towards [0, 1] (x = sqrt(x)) and
    # stops at its ratio; box consistency is there in one pass
    hc = Fixpoint(CtcFwdBwd([sqr(x) - x == 0]))(box)
    bc = CtcBox([sqr(x) - x == 0], eps=1e-9)(box)
    assert bc.lo[0] <= 0.0 and bc.hi[0] >= 1.0 and bc.width()[0] < 1.0 + 1e-8 < hc.width()[0]
    # x^2 - x in [-1, 0]: the exact projection is [0, 1]
    bc = CtcBox([(sqr(x) - x).in_((-1.0, 0.0))], eps=1e-9)(box)
    assert bc.lo[0] <= 0.0 and bc.hi[0] >= 1.0 and bc.width()[0] < 1.0 + 1e-8


def test_no_solution_is_refuted():
    # x^2 - x + 1 = 0 has no real root (x^2 - x >= -1/4)
    c = [sqr(x) - x + 1 == 0]
    assert np.isnan(CtcBox(c)(Interval([-10.0], [10.0])).lo).all()
    # x (x - 1) = 0 on [2, inf]: the whole half-line is refuted at once
    assert np.isnan(CtcBox([x * (x - 1) == 0])(Interval([2.0], [np.inf])).lo).all()


def test_inputs_empty_unbounded_degenerate():
    ctc = CtcBox([x * (x - 1) == z], ["x", "z"])
    lo = np.array([[np.nan, np.nan], [-np.inf, 0.0], [1.0, 0.0], [2.0, 0.0], [0.5, -np.inf],
                   [-1e308, 0.0]])
    hi = np.array([[np.nan, np.nan], [np.inf, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, np.inf],
                   [1e308, 0.0]])
    box = Interval.trusted(lo.copy(), hi.copy())
    out = ctc(box)
    assert np.array_equal(box.lo, lo, equal_nan=True)  # the input is not modified
    assert np.isnan(out.lo[0]).all()
    assert out.lo[1, 0] == -np.inf and out.hi[1, 0] == np.inf  # unbounded: left alone
    assert out.lo[2, 0] == 1.0 == out.hi[2, 0]  # a degenerate solution stays
    assert np.isnan(out.lo[3]).all()  # 2 (2 - 1) != 0
    assert out.lo[4, 0] == 0.5 and out.hi[4, 0] == 3.0  # z unbounded: nothing to cut
    # a huge domain: max_depth = 40 bisections leave slices of 2e308 / 2**40 around 0 and 1
    assert out.lo[5, 0] <= 0.0 and out.hi[5, 0] >= 1.0
    assert out.lo[5, 0] >= -2e308 * 2.0**-40 and out.hi[5, 0] <= 2e308 * 2.0**-39
    # batch shape kept
    many = CtcBox([x * (x - 1) == 0])(Interval(np.full((2, 3, 1), 0.5), np.full((2, 3, 1), 3.0)))
    assert many.shape == (2, 3, 1) and np.all(many.lo <= 1.0) and np.all(many.hi >= 1.0)


def test_model_domains_and_arguments():
    m = Model()
    m.declare(x, (0.5, 3.0))
    m.add(x * (x - 1) == 0)
    out = CtcBox(m)(Interval([-5.0], [5.0]))
    assert 0.5 <= out.lo[0] <= 1.0 <= out.hi[0] < 1.01
    assert occurrences(x * (x - 1) + z) == {"x": 2, "z": 1}
    assert CtcBox([x + z == 1], ["x", "z"]).candidates == []  # nothing occurs twice
    assert CtcBox([x * (x - 1) == z], ["x", "z"]).candidates == ["x"]
    with pytest.raises(ValueError):
        CtcBox([x * x == 1], ["y"])
    with pytest.raises(ValueError):
        CtcBox([x * x == z], ["x"])
    with pytest.raises(ValueError):
        CtcBox([x * x == 1], max_depth=60)
    with pytest.raises(ValueError):
        CtcBox([x * x == 1])(Interval(0.0, 1.0))
