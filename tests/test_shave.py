"""3B shaving: ``propagate(mode="3b")`` (the compiled engine) and ``CtcShave`` (any contractor,
batched). Solutions must survive every shave: points of the solution set, checked with mpmath,
on random small CSPs; the simulated truth of the satellite (``tests/test_satellite.py``)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from boundest import Interval
from boundest.csp import Shaving, propagate
from boundest.ctc import CtcFwdBwd, CtcShave, Fixpoint
from boundest.expr import Model, Var
from boundest.expr.functions import sqr

from .strategies import solvable_csps


def csps():
    """Random CSPs whose sampled solutions are known (``strategies.solvable_csps``)."""
    return solvable_csps((2, 4), 4, [0.0, 1e-6, 0.01, 0.3], 6)


@pytest.mark.slow  # about 30 s on 2 cores
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(csps(), st.sampled_from([Shaving(), Shaving(frac=0.05, probe_evals=40, rounds=4,
                                                   reach=1, min_gain=0.0)]))
def test_solutions_survive_shaving_in_the_engine(csp, opts):
    model, n, pts = csp
    hc = propagate(model, mode="hc4")
    res = propagate(model, mode="3b", shaving=opts)
    assert res.consistent and res.mode == "3b"
    for p in pts:
        for i in range(n):
            assert res[f"x{i}"].contains(p[i]), (p, i, res[f"x{i}"])
    for name, dom in res.domains.items():  # tighter than (or as tight as) hull consistency
        assert hc[name].lo <= dom.lo and dom.hi <= hc[name].hi, name


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(csps())
def test_solutions_survive_the_shaving_contractor(csp):
    model, n, pts = csp
    ctc = CtcShave(Fixpoint(CtcFwdBwd(model, [f"x{i}" for i in range(n)])), frac=0.05)
    # a batch: the full box, and boxes around each solution point (with an empty one)
    lo = np.array([[-2.0] * n] + [[max(-2.0, v - 0.3) for v in p] for p in pts] + [[np.nan] * n])
    hi = np.array([[2.0] * n] + [[min(2.0, v + 0.3) for v in p] for p in pts] + [[np.nan] * n])
    out = ctc(Interval.trusted(lo, hi))
    for p in pts:
        for row in range(len(pts) + 1):
            if np.all((lo[row] <= p) & (p <= hi[row])):
                assert np.all((out.lo[row] <= p) & (p <= out.hi[row])), (row, p)
    assert np.isnan(out.lo[-1]).all()


def _cross() -> Model:
    """``x + y = 0``, ``x - y = 0`` on ``[-1, 1]^2``: the only solution is (0, 0), and hull
    consistency cannot contract at all (each constraint alone is satisfied on the whole box)."""
    x, y = Var("x"), Var("y")
    m = Model()
    m.declare(x, (-1.0, 1.0))
    m.declare(y, (-1.0, 1.0))
    return m.add(x + y == 0, x - y == 0)


def test_shaving_finds_what_hull_consistency_cannot():
    hc = propagate(_cross(), mode="hc4")
    assert hc["x"].lo == -1.0 and hc["x"].hi == 1.0
    res = propagate(_cross(), mode="3b", shaving=Shaving(rounds=20, min_gain=0.0))
    for v in ("x", "y"):
        assert res[v].contains(0.0) and float(res[v].width()) < 0.05, res[v]
    assert res.shaving["refuted"] > 0 and res.shaving["probes"] >= res.shaving["refuted"]
    box = CtcShave(CtcFwdBwd(_cross(), ["x", "y"]), max_slices=30)(Interval([-1, -1], [1, 1]))
    assert np.all(box.contains(np.zeros(2))) and np.all(box.width() < 0.05)


def test_probes_that_refute_nothing_leave_no_trace():
    """A probe of one revision refutes no slice of the cross: every probe is undone, and the
    result is hull consistency's, bit for bit."""
    hc = propagate(_cross(), mode="hc4")
    res = propagate(_cross(), mode="3b", shaving=Shaving(probe_evals=1, rounds=5, min_gain=0))
    assert res.shaving["probes"] > 0 and res.shaving["refuted"] == 0
    assert np.array_equal(res.slots.lo, hc.slots.lo) and np.array_equal(res.slots.hi,
                                                                           hc.slots.hi)


def test_shave_selects_variables_and_rejects_bad_settings():
    res = propagate(_cross(), mode="3b", shave=["y"], shaving=Shaving(rounds=20, min_gain=0))
    assert float(res["y"].width()) < 0.05 and float(res["x"].width()) < 0.05  # x = y follows
    with pytest.raises(ValueError, match="unknown variable"):
        propagate(_cross(), mode="3b", shave=["z"])
    with pytest.raises(ValueError, match="mode"):
        propagate(_cross(), mode="bc3")
    for bad in (dict(frac=0.0), dict(frac=0.6), dict(probe_evals=0), dict(rounds=0),
                dict(reach=-1), dict(probe_eps=1.0)):
        with pytest.raises(ValueError):
            Shaving(**bad)
    with pytest.raises(ValueError):
        CtcShave(CtcFwdBwd(_cross(), ["x", "y"]), frac=0.7)
    with pytest.raises(ValueError):
        CtcShave(CtcFwdBwd(_cross(), ["x", "y"]), variables=[2])


def test_empty_unbounded_and_degenerate_domains():
    x, y = Var("x"), Var("y")
    # inconsistent only for shaving: x + y = 0, x - y = 0, x in [0.5, 1] (hc4 sees y in
    # [-1, -0.5] and [0.5, 1]: empty already); take one hull consistency cannot refute
    m = Model()
    m.declare(x, (-1.0, 1.0))
    m.declare(y, (-1.0, 1.0))
    m.add(x + y == 0, x - y == 0, sqr(x) + sqr(y) >= 0.01)
    assert propagate(m, mode="hc4").consistent
    res = propagate(m, mode="3b", shaving=Shaving(rounds=50, min_gain=0.0))
    assert not res.consistent
    assert all(bool(d.is_empty()) for d in res.domains.values())
    # unbounded domains are not sliced; they stay sound
    u = Model()
    u.declare(x, (-math.inf, math.inf))
    u.declare(y, (0.0, math.inf))
    u.add(y == sqr(x))
    r = propagate(u, mode="3b")
    assert r.consistent and r["x"].contains(-1e6) and r["y"].contains(0.0)
    # a degenerate solution stays
    d = Model()
    d.declare(x, (2.0, 2.0))
    d.declare(y, (-5.0, 5.0))
    d.add(y == x * x - x)
    r = propagate(d, mode="3b")
    assert r["y"].contains(2.0) and r["x"].lo == 2.0 == r["x"].hi
