"""The propagation modes beyond hull consistency: box consistency (``mode="bc"``, BC3 compiled
in the engine), box consistency then shaving (``"bc+3b"``) and LP contraction at the fixed
point (``"lp"``). Solutions of random solvable CSPs (checked with mpmath) survive every mode,
no mode is wider than hull consistency, and what each mode proves empty or narrows where hull
consistency cannot."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from boundest import Interval
from boundest.csp import MODES, BoxConsistency, CtcBox, LinearRelaxation, Shaving, propagate
from boundest.csp.linear import propagate_lp
from boundest.expr import Model, Var
from boundest.expr.functions import sqr

from .strategies import solvable_csps

x, y, z = Var("x"), Var("y"), Var("z")
HAS_SCIPY = True
try:
    import scipy.optimize  # noqa: F401
except ImportError:  # pragma: no cover - the lp extra is not installed
    HAS_SCIPY = False

#: the modes and settings the property tests run: the defaults, and cheap / thorough ones
SETTINGS = [("bc", {}),
            ("bc", {"boxcons": BoxConsistency(depth=3, max_steps=4, max_nodes=2, rounds=1)}),
            ("bc", {"boxcons": BoxConsistency(depth=30, max_steps=200, rounds=6, reach=0,
                                              min_gain=0.0)}),
            ("bc+3b", {"shaving": Shaving(frac=0.05, probe_evals=40, rounds=3)})]


def csps():
    """Random CSPs whose sampled solutions are known (``strategies.solvable_csps``)."""
    return solvable_csps((1, 4), 4, [0.0, 1e-9, 0.01, 0.3], 7)


def _check(model, n, pts, res, hc):
    assert res.consistent and res.mode in MODES
    for p in pts:
        for i in range(n):
            assert res[f"x{i}"].contains(p[i]), (p, i, res[f"x{i}"])
    for name, dom in res.domains.items():  # never wider than hull consistency
        assert hc[name].lo <= dom.lo and dom.hi <= hc[name].hi, (name, hc[name], dom)


@pytest.mark.slow  # about 100 s with an empty kernel cache (a compile per op family), 5 s warm
@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(csps(), st.sampled_from(SETTINGS))
def test_solutions_survive_box_consistency_in_the_engine(csp, mode_kw):
    model, n, pts = csp
    mode, kw = mode_kw
    hc = propagate(model, mode="hc4")
    res = propagate(model, mode=mode, **kw)
    _check(model, n, pts, res, hc)
    if res.boxcons:  # (a CSP whose equalities merge every node away has no phase to run)
        assert res.boxcons["searches"] <= res.boxcons["candidates"] * res.boxcons["rounds"]


@pytest.mark.skipif(not HAS_SCIPY, reason="the lp extra (SciPy) is not installed")
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(csps(), st.sampled_from([LinearRelaxation(), LinearRelaxation(rounds=1, radius=1,
                                                                     log_linear=False)]))
def test_solutions_survive_lp_in_the_engine(csp, opts):
    model, n, pts = csp
    hc = propagate(model, mode="hc4")
    res = propagate(model, mode="lp", linear=opts)
    _check(model, n, pts, res, hc)
    if res.linear:
        assert 1 <= res.linear["rounds"] <= opts.rounds


def test_box_consistency_narrows_what_hull_consistency_cannot():
    m = Model()
    m.declare(x, (-10.0, 10.0))
    m.add(x * x - x == 0)  # solutions 0 and 1; hull consistency keeps [-10, 10]
    hc = propagate(m, mode="hc4")
    assert hc["x"].lo == -10.0 and hc["x"].hi == 10.0
    res = propagate(m, mode="bc", boxcons=BoxConsistency(depth=40, max_steps=400))
    assert res["x"].contains(0.0) and res["x"].contains(1.0)
    assert float(res["x"].width()) < 1.0 + 1e-6
    assert res.boxcons["candidates"] == 1 and res.boxcons["narrowed"] >= 1
    # the same narrowing as the contractor, which runs the same compiled search
    box = CtcBox([x * x - x == 0], eps=0.0, max_depth=40, max_steps=400)
    out = box(Interval([-10.0], [10.0]))
    assert out.lo[0] <= res["x"].lo + 1e-6 and res["x"].hi - 1e-6 <= out.hi[0]


def test_empty_csps_are_detected():
    # x (x - 1) >= -1/4 everywhere: hull consistency cannot see it, box consistency can
    m = Model()
    m.declare(x, (-10.0, 10.0))
    m.add(x * (x - 1) == -0.5)
    assert propagate(m, mode="hc4").consistent
    for mode in ("bc", "bc+3b"):
        res = propagate(m, mode=mode)
        assert not res.consistent and all(bool(d.is_empty()) for d in res.domains.values())
    # x = y = z and x - z in [1e-6, 2e-6]: hull consistency creeps by 1e-6 per pass and
    # stops at its tolerance; the LP proves it empty (a Farkas certificate)
    m = Model()
    for v in (x, y, z):
        m.declare(v, (-10.0, 10.0))
    m.add(x - y == 0, y - z == 0, (x - z).in_((1e-6, 2e-6)))
    assert propagate(m, mode="hc4").consistent
    if HAS_SCIPY:
        res = propagate(m, mode="lp")
        assert not res.consistent and all(bool(d.is_empty()) for d in res.domains.values())
    # an empty initial domain: every mode says so without running
    e = Model()
    e.declare(x, (0.0, 1.0))
    e.add(x * x == x, x >= 2.0)
    for mode in ("bc", "bc+3b") + (("lp",) if HAS_SCIPY else ()):
        assert not propagate(e, mode=mode).consistent


@pytest.mark.skipif(not HAS_SCIPY, reason="the lp extra (SciPy) is not installed")
def test_lp_mode_narrows_what_hull_consistency_cannot_and_matches_propagate_lp():
    m = Model()
    m.declare(x, (-1.0, 1.0))
    m.declare(y, (-1.0, 1.0))
    m.add(x + y == 0, x - y == 0)  # each alone holds on the whole box; together x = y = 0
    assert propagate(m, mode="hc4")["x"].lo == -1.0
    res = propagate(m, mode="lp")
    ref = propagate_lp(m)
    for v in ("x", "y"):
        assert res[v].contains(0.0) and float(res[v].width()) < 1e-12
        assert float(res[v].width()) <= float(ref[v].width()) + 1e-15
    assert res.linear["widths"][0] == 4.0 and res.linear["widths"][-1] < 1e-12
    assert res.linear["evaluations"] < 10 * res.n_nodes  # only the users of what moved


def test_box_consistency_cost_is_flat_in_the_number_of_copies():
    """Independent copies of one constraint: the searches and the revisions that propagate
    what they narrowed grow in proportion to the copies (no rescan of the whole CSP)."""
    def run(m):
        model = Model()
        xs = [Var(f"x{i}") for i in range(m)]
        for v in xs:
            model.declare(v, (-10.0, 10.0))
        model.add(*[v * v - v == 0 for v in xs])
        return propagate(model, mode="bc", boxcons=BoxConsistency(rounds=2)).boxcons

    small, big = run(5), run(20)
    assert small["narrowed"] > 0
    for key in ("searches", "narrowed", "bc_evaluations", "evaluations"):
        assert big[key] == 4 * small[key], key


def test_unbounded_and_degenerate_domains():
    u = Model()
    u.declare(x, (-np.inf, np.inf))
    u.declare(y, (0.0, np.inf))
    u.add(y == x * x - x)
    r = propagate(u, mode="bc")
    assert r.consistent and r["x"].contains(-1e6) and r["x"].contains(1e6)
    d = Model()
    d.declare(x, (2.0, 2.0))
    d.declare(y, (-5.0, 5.0))
    d.add(y == x * x - x)
    r = propagate(d, mode="bc")
    assert r["y"].contains(2.0) and r["x"].lo == 2.0 == r["x"].hi
    # sqr(x) - x in [-1, 0]: the exact projection is [0, 1]
    s = Model()
    s.declare(x, (-10.0, 10.0))
    s.add((sqr(x) - x).in_((-1.0, 0.0)))
    r = propagate(s, mode="bc", boxcons=BoxConsistency(depth=40, max_steps=400))
    assert r["x"].lo <= 0.0 and r["x"].hi >= 1.0 and float(r["x"].width()) < 1.0 + 1e-6


def test_bad_modes_and_settings_are_rejected(monkeypatch):
    m = Model()
    m.declare(x, (-1.0, 1.0))
    m.add(x * x == x)
    with pytest.raises(ValueError, match="mode must be one of hc4, bc, 3b, bc\\+3b, lp"):
        propagate(m, mode="bc3")
    with pytest.raises(ValueError, match="unknown variable 'q' in targets"):
        propagate(m, mode="bc", targets=["q"])
    for bad in (dict(depth=0), dict(depth=53), dict(max_steps=0), dict(max_nodes=0),
                dict(rounds=0), dict(reach=-1), dict(min_gain=-0.1)):
        with pytest.raises(ValueError):
            BoxConsistency(**bad)
    for bad in (dict(rounds=0), dict(min_gain=-1.0), dict(radius=0)):
        with pytest.raises(ValueError):
            LinearRelaxation(**bad)
    monkeypatch.setitem(sys.modules, "scipy.optimize", None)  # import fails as if absent
    with pytest.raises(ImportError, match=r"pip install 'boundest\[lp\]'"):
        propagate(m, mode="lp")
