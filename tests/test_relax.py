"""The linear relaxation of nonlinear nodes (``boundest.ctc.relax``) and the polytope hull.

Per primitive: points of the node's graph over random boxes (degenerate, tiny, huge, touching
0, negative, half-unbounded) satisfy every generated row, checked in mpmath at 120 digits
(the graph's values to far more digits than any row's rounding margin, each row's sum in
exact rationals). On random CSPs with known solutions, the solutions survive
``CtcPolytopeHull`` and ``propagate(mode="lp")`` with the relaxation; small relaxed systems are
checked against exact rational optima (``tests/exact_lp.py``).
"""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytest.importorskip("scipy")

from boundest.csp import LinearRelaxation, propagate
from boundest.csp.linear import propagate_lp
from boundest.ctc import CtcLinear, CtcPolytopeHull
from boundest.ctc.linear import extract, lp_bound
from boundest.ctc.relax import relaxation
from boundest.expr import Model, Op, Var
from boundest.expr import functions as fn
from boundest.expr.tape import OPS, compile_model
from boundest.interval import Interval

from .checks import examples
from .exact_lp import exact_min
from .strategies import solvable_csps

x, y, z = Var("x"), Var("y"), Var("z")
SETTINGS = settings(max_examples=150, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])

mpmath.mp.dps = 120
M = mpmath.mpf

#: unary primitives: (expression, exact value in mpmath, natural domain)
UNARY = {
    "sqr": (lambda e: fn.sqr(e), lambda v: v * v, (-math.inf, math.inf)),
    "exp": (fn.exp, mpmath.exp, (-math.inf, math.inf)),
    "log": (fn.log, mpmath.log, (0.0, math.inf)),
    "sqrt": (fn.sqrt, mpmath.sqrt, (0.0, math.inf)),
    "sin": (fn.sin, mpmath.sin, (-math.inf, math.inf)),
    "cos": (fn.cos, mpmath.cos, (-math.inf, math.inf)),
    "tan": (fn.tan, mpmath.tan, (-math.inf, math.inf)),
    "atan": (fn.atan, mpmath.atan, (-math.inf, math.inf)),
    "asin": (fn.asin, mpmath.asin, (-1.0, 1.0)),
    "acos": (fn.acos, mpmath.acos, (-1.0, 1.0)),
    "sinh": (fn.sinh, mpmath.sinh, (-math.inf, math.inf)),
    "cosh": (fn.cosh, mpmath.cosh, (-math.inf, math.inf)),
    "tanh": (fn.tanh, mpmath.tanh, (-math.inf, math.inf)),
    "abs": (abs, abs, (-math.inf, math.inf)),
    **{f"pown{n}": (lambda e, n=n: fn.pown(e, n), lambda v, n=n: v**n, (-math.inf, math.inf))
       for n in (-3, -2, -1, 2, 3, 4, 5)},
}


@st.composite
def boxes(draw, natural=(-math.inf, math.inf)):
    """An interval: degenerate, tiny, ordinary, huge, touching 0, negative or half-unbounded,
    meeting ``natural``."""
    kind = draw(st.sampled_from(["point", "tiny", "plain", "huge", "zero", "neg", "unbounded"]))
    c = draw(st.floats(-4, 4))
    if kind == "point":
        lo = hi = c
    elif kind == "tiny":
        lo, hi = c, c + abs(c) * 2.0**-40 + 1e-300
    elif kind == "plain":
        lo, hi = sorted((c, draw(st.floats(-4, 4))))
    elif kind == "huge":
        lo, hi = sorted((c * 1e5, draw(st.floats(-1e6, 1e6))))
    elif kind == "zero":
        lo, hi = (0.0, abs(c)) if draw(st.booleans()) else (-abs(c), 0.0)
    elif kind == "neg":
        lo, hi = sorted((-abs(c), -abs(draw(st.floats(-4, 4)))))
    else:
        lo, hi = (c, math.inf) if draw(st.booleans()) else (-math.inf, c)
    lo, hi = max(lo, natural[0]), min(hi, natural[1])
    if lo > hi:
        lo = hi = natural[0] if math.isfinite(natural[0]) else natural[1]
    return lo, hi


def _points(draw, lo: float, hi: float, k: int = 6) -> list[float]:
    """Floats in ``[lo, hi]``: its finite ends, its midpoint and random ones."""
    a = lo if math.isfinite(lo) else (min(hi, 0.0) - 1e3 if math.isfinite(hi) else -1e3)
    b = hi if math.isfinite(hi) else max(a, 0.0) + 1e3
    a, b = a + 0.0, b + 0.0  # no -0.0
    pts = [a, b, 0.5 * a + 0.5 * b]
    pts += [draw(st.floats(a, b)) for _ in range(k)]
    return pts


def _exact(v: mpmath.mpf) -> Fraction:
    """The mpmath number as an exact rational (sums of terms of very different magnitudes
    would be rounded at 120 digits)."""
    v = v if isinstance(v, mpmath.mpf) else mpmath.mpf(v)  # mpf(v) would round v to 120 digits
    sign, man, exp, _ = v._mpf_
    return (-1) ** sign * Fraction(int(man)) * Fraction(2) ** int(exp)


def _value(exact, p: float) -> mpmath.mpf:
    """``exact(p)`` to well below the rows' margin: next to 0 that margin is ``p**2`` or
    ``p**3`` relative to the value (``exp(p) >= 1 + p``, ``sin(p) <= p``), so a tiny ``p``
    needs more than 120 digits (``exp(1e-300)`` at 120 digits is 1, which breaks the exact row
    ``z >= 1 + x``)."""
    prec = mpmath.mp.prec + (4 * max(0, -int(mpmath.mag(M(p)))) if p != 0 else 0)
    with mpmath.workprec(prec):
        return exact(M(p))


def _check_rows(tape, lo, hi, values: dict[int, mpmath.mpf]) -> int:
    """Every relaxed row at ``[lo, hi]`` holds at the point ``values`` (slot -> value)."""
    n = 0
    for blk in relaxation(tape, lo, hi):
        for i in range(blk.n_rows):
            lhs = sum(Fraction(float(c[i])) * _exact(values[int(s[i])])
                      for s, c in zip(blk.cols, blk.coefs, strict=True))
            assert lhs <= Fraction(float(blk.rhs[i])), (i, float(lhs), blk.rhs[i], values)
            n += 1
    return n


def _tape_box(cons, doms: dict[str, tuple[float, float]]):
    m = Model()
    for v in (x, y, z):
        if v.name in doms:
            m.declare(v, doms[v.name])
    m.add(cons)
    tape = compile_model(m)
    lo, hi = tape.lo.copy(), tape.hi.copy()
    for name, (a, b) in doms.items():
        lo[tape.slot_of[name]], hi[tape.slot_of[name]] = a, b
    return tape, lo, hi


@SETTINGS
@given(st.sampled_from(sorted(UNARY)), st.data())
def test_unary_rows_hold_on_the_graph(name, data):
    expr, exact, natural = UNARY[name]
    xl, xh = data.draw(boxes(natural))
    if name.startswith("pown-") and xl <= 0 <= xh:
        xl, xh = (1e-3, max(xh, 1e-3)) if xh > 0 or xl == 0 else (min(xl, -1e-3), -1e-3)
    tape, lo, hi = _tape_box(z == expr(x), {"x": (xl, xh)})
    sx, sz = tape.slot_of["x"], tape.slot_of["z"]
    for p in _points(data.draw, xl, xh):
        if name == "tan" and abs(mpmath.cos(M(p))) < M(10) ** -100:
            continue
        v = _value(exact, p)
        if not mpmath.isfinite(v):  # log(0): not a point of the graph
            continue
        _check_rows(tape, lo, hi, {sx: M(p), sz: v})


@pytest.mark.parametrize("name", ["exp", "sin", "cos", "tan", "sinh", "cosh", "tanh", "atan",
                                  "asin", "acos", "sqr", "pown3"])
@pytest.mark.parametrize("box", [(0.0, 1e-300), (-1e-300, 0.0), (0.0, 5e-324)])
def test_unary_rows_hold_next_to_zero(name, box):
    """Boxes of subnormal or tiny width with an end at 0, where the tangent rows at 0 are
    exact (``z >= 1 + x`` for exp) and the graph leaves them by ``x**2``: there are rows, and
    every row holds at the ends and the midpoint (hypothesis found ``exp`` on ``[0, 1e-300]``
    once, when the reference was computed at 120 digits)."""
    expr, exact, _ = UNARY[name]
    xl, xh = box
    tape, lo, hi = _tape_box(z == expr(x), {"x": (xl, xh)})
    sx, sz = tape.slot_of["x"], tape.slot_of["z"]
    n = 0
    for p in (xl, xh, 0.5 * xl + 0.5 * xh):
        n += _check_rows(tape, lo, hi, {sx: M(p), sz: _value(exact, p)})
    assert n > 0


@pytest.mark.parametrize("n", [2.0**53 + 2, 2.0**62, 1e20, 2.0**64, -(2.0**64), 1e300])
@pytest.mark.parametrize("box", [(1 - 2**-44, 1 + 2**-44), (-1 - 2**-44, -1 + 2**-44),
                                 (0.5, 1.0), (-1.0, 1.0), (-3.0, 1.0), (1.0, 2.0)])
def test_huge_pown_rows_hold_on_the_graph(n, box):
    """Issue 27 item 7: rows of ``z = x**n`` for an integer-valued float n beyond 2**53 (even)
    hold at the points of the graph within the float range (the kernels take n beyond 2**63
    as an int64 of its parity; the tangents' slope factor is the exact n)."""
    xl, xh = box
    if n < 0 and xl <= 0 <= xh:
        return
    tape, lo, hi = _tape_box(z == x**n, {"x": (xl, xh)})
    assert tape.param[[OPS[c] for c in tape.op].index("pown")] == n
    sx, sz = tape.slot_of["x"], tape.slot_of["z"]
    pts = [xl, xh, 0.5 * xl + 0.5 * xh, 1.0, -1.0, 1 - 2**-53, 1 - 2**-52, 1 + 2**-52]
    for p in pts:
        if not xl <= p <= xh:
            continue
        v = M(p) ** int(n)
        if v != 0 and not M(2) ** -1000 < abs(v) < M(2) ** 1000:  # not a float-range point
            continue
        _check_rows(tape, lo, hi, {sx: M(p), sz: v})


@examples(150, 30)
def test_binary_rows_hold_on_the_graph(n_examples):
    @settings(SETTINGS, max_examples=n_examples)
    @given(st.sampled_from(["mul", "div", "min", "max", "square"]), st.data())
    def check(name, data):
        (xl, xh), (yl, yh), (zl, zh) = (data.draw(boxes()) for _ in range(3))
        if name == "div":  # the rows hold for every y != 0 and z in its domain: x = z y
            tape, lo, hi = _tape_box(z == x / y, {"x": (-math.inf, math.inf), "y": (yl, yh),
                                                  "z": (zl, zh)})
            for q in _points(data.draw, yl, yh, 3):
                for r in _points(data.draw, zl, zh, 3):
                    vals = {tape.slot_of["y"]: M(q), tape.slot_of["z"]: M(r),
                            tape.slot_of["x"]: M(q) * M(r)}
                    _check_rows(tape, lo, hi, vals)
            return
        cons = {"mul": z == x * y, "square": z == x * x, "min": z == Op("min", (x, y)),
                "max": z == Op("max", (x, y))}[name]
        doms = {"x": (xl, xh)} if name == "square" else {"x": (xl, xh), "y": (yl, yh)}
        tape, lo, hi = _tape_box(cons, doms)
        op = {"mul": lambda a, b: a * b, "square": lambda a, b: a * a, "min": min, "max": max}[name]
        for p in _points(data.draw, xl, xh, 3):
            for q in _points(data.draw, yl, yh, 3):
                vals = {tape.slot_of["x"]: M(p), tape.slot_of["z"]: op(M(p), M(q))}
                if name != "square":
                    vals[tape.slot_of["y"]] = M(q)
                _check_rows(tape, lo, hi, vals)

    check()


def test_rows_exist_where_convexity_is_proven():
    """Each primitive gives rows on a box inside its convexity region, none on sin over a
    box where it changes curvature."""
    for name, (expr, _, _) in UNARY.items():
        box = (0.2, 0.7)
        tape, lo, hi = _tape_box(z == expr(x), {"x": box})
        assert sum(b.n_rows for b in relaxation(tape, lo, hi)) >= 3, name
    tape, lo, hi = _tape_box(z == fn.sin(x), {"x": (-0.5, 0.5)})
    assert relaxation(tape, lo, hi) == []
    tape, lo, hi = _tape_box(z == x * y, {"x": (1.0, 2.0), "y": (-1.0, 3.0)})
    assert sum(b.n_rows for b in relaxation(tape, lo, hi)) == 4


def _dense(ext):
    s = ext.system
    A = np.zeros((s.n_rows, s.n_cols))
    A[s.rows, s.cols] = s.a_lo
    assert np.array_equal(s.a_lo, s.a_hi)  # relaxed rows: exact coefficients
    return A, s.b_lo, s.b_hi


@examples(60, 12)
def test_relaxed_lp_bound_below_exact_optimum(n_examples):
    """The rigorous bound of the relaxed LP is at most its exact rational optimum."""
    @settings(max_examples=n_examples, deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(st.sampled_from([("mul", lambda: z == x * y), ("sqr", lambda: z == fn.sqr(x) + y),
                            ("exp", lambda: z == fn.exp(x) - y),
                            ("sqrt", lambda: z == fn.sqrt(x))]),
           st.integers(-3, 2), st.integers(1, 3), st.integers(-3, 2), st.integers(1, 3),
           st.sampled_from([-1.0, 1.0]), st.integers(0, 3))
    def check(case, a, w, b, v, sense, col):
        _, cons = case
        tape, lo, hi = _tape_box(cons(), {"x": (a / 2, (a + w) / 2), "y": (b / 2, (b + v) / 2),
                                          "z": (-20.0, 20.0)})
        if tape.n_slots > 4:
            return
        lo[~np.isfinite(lo)], hi[~np.isfinite(hi)] = -50.0, 50.0
        ext = extract(tape, lo, hi, log_linear=False, relax=True)
        if ext.system.n_rows == 0:
            return
        A, b_lo, b_hi = _dense(ext)
        c = np.zeros(tape.n_slots)
        c[col % tape.n_slots] = sense
        exact = exact_min(c, A, b_lo, b_hi, lo, hi)
        bound = lp_bound(ext.system, c, lo, hi)
        if exact is None:
            return
        assert bound != np.inf
        assert bound <= exact, (bound, exact)
        assert bound >= float(exact) - 1e-6 * (1 + abs(float(exact)))  # and nearly tight

    check()


def _model_x_y(cons, box=(-3.0, 3.0)):
    m = Model()
    m.declare(x, box)
    m.declare(y, box)
    m.add(*cons)
    return m


def test_relaxation_beats_hull_consistency_on_the_dependency_problem():
    """``x^2 - 2x + y = 0, y = x/2``: solutions x = 0 and x = 1.5; hull consistency cannot
    move x from [-3, 3] (x occurs twice), the polytope hull reaches [0, 1.5]."""
    m = _model_x_y([x * x - 2 * x + y == 0, y == 0.5 * x])
    hc = propagate(m, mode="hc4")
    assert (float(hc["x"].lo), float(hc["x"].hi)) == (-3.0, 3.0)
    lp = propagate(m, mode="lp")  # the linear rows alone do not help either
    assert float(lp["x"].hi - lp["x"].lo) > 5.9
    r = propagate(m, mode="lp", linear=LinearRelaxation(relax=True, rounds=10))
    assert r.consistent and r["x"].contains(0.0) and r["x"].contains(1.5)
    assert -1e-4 < float(r["x"].lo) <= 0.0 and 1.5 <= float(r["x"].hi) < 1.5 + 1e-4
    tape = compile_model(m)
    box = CtcPolytopeHull(tape, rounds=10)(hc.slots)[tape.slot_of["x"]]
    assert box.contains(0.0) and box.contains(1.5) and float(box.hi - box.lo) < 1.5 + 1e-3


def test_relax_option_of_ctc_linear_and_propagate_lp():
    m = _model_x_y([x * x - 2 * x + y == 0, y == 0.5 * x])
    tape = compile_model(m)
    hc = propagate(tape, mode="hc4")
    sx = tape.slot_of["x"]
    one = CtcLinear(tape, relax=True)(hc.slots)[sx]
    assert one.contains(0.0) and one.contains(1.5) and float(one.hi - one.lo) < 6.0
    assert float(CtcLinear(tape)(hc.slots)[sx].hi - CtcLinear(tape)(hc.slots)[sx].lo) == 6.0
    r = propagate_lp(tape, relax=True, rounds=10)
    assert r.consistent and r["x"].contains(0.0) and r["x"].contains(1.5)
    assert float(r["x"].hi - r["x"].lo) < 1.6
    ext = extract(tape, hc.slots.lo, hc.slots.hi, relax=True)
    ineq = ext.system.b_lo == -np.inf
    assert ineq.any() and np.all(np.isfinite(ext.system.b_hi))


def test_polytope_hull_on_a_batch_and_on_an_empty_csp():
    m = _model_x_y([x * x - 2 * x + y == 0, y == 0.5 * x])
    tape = compile_model(m)
    box = propagate(tape, mode="hc4").slots
    ctc = CtcPolytopeHull(tape, rounds=2)
    batch = ctc(Interval.trusted(np.stack([box.lo, box.lo]), np.stack([box.hi, box.hi])))
    one = ctc(box)
    assert batch.shape == (2, tape.n_slots)
    assert np.array_equal(batch.lo[1], one.lo) and np.array_equal(batch.hi[0], one.hi)
    m = _model_x_y([x + y == 1.5, x * x + y * y <= 0.9], (-2.0, 2.0))
    tape = compile_model(m)
    box = propagate(tape, mode="hc4").slots
    assert bool(CtcPolytopeHull(tape, rounds=10)(box).is_empty().all())
    with pytest.raises(ValueError, match="rounds"):
        CtcPolytopeHull(tape, rounds=0)


def test_relaxation_narrows_products_more_than_hull_consistency():
    m = _model_x_y([x * y == 1, x + y == 2.05], (0.0, 4.0))
    hc = propagate(m, mode="hc4")
    r = propagate(m, mode="lp", linear=LinearRelaxation(relax=True, rounds=10))
    assert float(r["x"].hi - r["x"].lo) < float(hc["x"].hi - hc["x"].lo) - 1e-4
    assert r["x"].contains(0.8) and r["x"].contains(1.25)


def test_relax_is_off_by_default_and_proves_emptiness():
    m = _model_x_y([x * x - 2 * x + y == 0, y == 0.5 * x])
    tape = compile_model(m)
    base = extract(tape, tape.lo, tape.hi)
    assert base.system.n_rows == extract(tape, tape.lo, tape.hi, relax=False).system.n_rows
    assert extract(tape, tape.lo, tape.hi, relax=True).system.n_rows > base.system.n_rows
    assert CtcLinear(tape).relax is False and LinearRelaxation().relax is False
    # x^2 + y^2 = 1 and x + y = 1.5 meet; x + y = 1.5 with x^2 + y^2 <= 0.9 does not
    # (min of x^2 + y^2 on the line is 1.125), which hull consistency cannot see
    m = _model_x_y([x + y == 1.5, x * x + y * y <= 0.9], (-2.0, 2.0))
    assert propagate(m, mode="hc4").consistent
    assert not propagate(m, mode="lp", linear=LinearRelaxation(relax=True, rounds=10)).consistent


def _csps():
    return solvable_csps((1, 3), 3, [0.0, 1e-9, 0.01, 0.3], 5)


def _survive(n, pts, doms):
    for p in pts:
        for i in range(n):
            assert doms[f"x{i}"].contains(p[i]), (p, i, doms[f"x{i}"])


@pytest.mark.slow  # about 10 s warm
@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_csps())
def test_solutions_survive_the_polytope_hull(csp):
    model, n, pts = csp
    tape = compile_model(model)
    hc = propagate(tape, mode="hc4")
    if not hc.consistent:
        raise AssertionError("hull consistency lost a known solution")
    box = CtcPolytopeHull(tape, rounds=3)(hc.slots)
    assert not bool(box.is_empty().any())
    _survive(n, pts, {f"x{i}": box[tape.slot_of[f"x{i}"]] for i in range(n)})
    r = propagate(tape, mode="lp", linear=LinearRelaxation(relax=True))
    assert r.consistent
    _survive(n, pts, r.domains)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_csps())
def test_solutions_survive_the_polytope_hull_quick(csp):
    model, n, pts = csp
    r = propagate(model, mode="lp", linear=LinearRelaxation(relax=True, rounds=2))
    assert r.consistent
    _survive(n, pts, r.domains)
