"""The LP contractor of the linear / log-linear sub-networks (``boundest.ctc.linear``).

Soundness is checked against exact rational optima (``tests/exact_lp.py``, vertex enumeration
in ``fractions.Fraction``): the rigorous bound never exceeds the exact optimum, on random small
LPs including degenerate, ill-conditioned, unbounded-variable and infeasible ones; an
infeasibility is declared only where the exact solver finds no feasible point. On the tape,
points of the feasible set (built so that every intermediate value is exact in float64)
survive the contraction.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytest.importorskip("scipy")

from boundest.ctc.linear import (
    CtcLinear,
    LinearSystem,
    contract_slots,
    extract,
    infeasible,
    lp_bound,
    safe_lower_bound,
)
from boundest.expr import Model, Var
from boundest.expr.tape import compile_model
from boundest.interval import Interval

from .checks import examples
from .exact_lp import exact_min

SETTINGS = settings(max_examples=150, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])


@st.composite
def small_lp(draw, kind: str = "plain"):
    """A random LP with 2-3 variables and 1-3 rows of small integer (or, ``ill``, nearly
    dependent) coefficients; ``unbounded`` lets some variable bounds be infinite."""
    n = draw(st.integers(2, 3))
    m = draw(st.integers(1, 3))
    ints = st.integers(-4, 4)
    A = np.array([[draw(ints) for _ in range(n)] for _ in range(m)], dtype=float)
    if kind == "ill" and m >= 2:
        A[1] = A[0] * (1 + 2.0 ** -draw(st.integers(20, 40)))  # nearly dependent rows
    if kind == "degenerate":
        A = np.vstack([A, A[:1]])  # a repeated row: a degenerate vertex
    rows = A.shape[0]
    b_lo, b_hi = np.empty(rows), np.empty(rows)
    for i in range(rows):
        t = draw(st.sampled_from(["eq", "le", "range"]))
        v = float(draw(st.integers(-6, 6)))
        b_lo[i], b_hi[i] = (v, v) if t == "eq" else (-np.inf, v) if t == "le" else (
            v, v + draw(st.integers(0, 3)))
    lo = np.array([float(draw(st.integers(-5, 0))) for _ in range(n)])
    hi = np.array([lo[j] + draw(st.integers(0, 6)) for j in range(n)])
    if kind == "unbounded":
        for j in range(n):
            if draw(st.booleans()):
                lo[j] = -np.inf
            if draw(st.booleans()):
                hi[j] = np.inf
    c = np.array([float(draw(ints)) for _ in range(n)])
    return c, A, b_lo, b_hi, lo, hi


def _check(c, A, b_lo, b_hi, lo, hi, tight: bool) -> None:
    exact = exact_min(c, A, b_lo, b_hi, lo, hi)
    bound = lp_bound(LinearSystem.dense(A, b_lo, b_hi), c, lo, hi)
    if exact is None:  # infeasible: any bound is sound
        return
    assert bound != np.inf, "infeasibility claimed for a feasible LP"
    if exact == -math.inf:
        assert bound == -np.inf
        return
    assert Fraction(bound) <= exact if bound != -np.inf else True
    if tight:  # a correct dual gives a bound close to the optimum when no bound is infinite
        assert bound > -np.inf
        assert float(exact) - bound <= 1e-7 * (1 + abs(float(exact)))


@SETTINGS
@given(small_lp())
def test_bound_below_exact_optimum(p):
    _check(*p, tight=True)


@SETTINGS
@given(small_lp("degenerate"))
def test_bound_degenerate(p):
    _check(*p, tight=True)


@SETTINGS
@given(small_lp("ill"))
def test_bound_ill_conditioned(p):
    _check(*p, tight=False)


@SETTINGS
@given(small_lp("unbounded"))
def test_bound_unbounded_variables(p):
    _check(*p, tight=False)


def test_bound_tight_on_a_known_lp():
    # min x + y s.t. x - y = 0.3, x, y in [0, 1]: optimum 0.3 at (0.3, 0)
    S = LinearSystem.dense([[1.0, -1.0]], [0.3], [0.3])
    b = lp_bound(S, np.array([1.0, 1.0]), np.zeros(2), np.ones(2))
    assert Fraction(b) <= Fraction(0.3) and 0.3 - b < 1e-15


def test_free_variable_with_zero_reduced_cost_keeps_a_finite_bound():
    # min x s.t. x - y = 0, x in [1, 2], y free: the dual (1) zeroes y's reduced cost exactly
    S = LinearSystem.dense([[1.0, -1.0]], [0.0], [0.0])
    b = lp_bound(S, np.array([1.0, 0.0]), np.array([1.0, -np.inf]), np.array([2.0, np.inf]))
    assert 1.0 - 1e-12 < b <= 1.0


def test_bound_is_sound_for_any_multipliers():
    rng = np.random.default_rng(1)
    for _ in range(200):
        n, m = 3, 2
        A = rng.integers(-3, 4, size=(m, n)).astype(float)
        x0 = rng.integers(-2, 3, size=n).astype(float)
        b = A @ x0
        lo, hi = x0 - rng.integers(0, 3, size=n), x0 + rng.integers(0, 3, size=n)
        c = rng.integers(-3, 4, size=n).astype(float)
        exact = exact_min(c, A, b, b, lo, hi)
        y = rng.normal(size=m) * 10.0 ** rng.integers(-3, 4)
        v = safe_lower_bound(LinearSystem.dense(A, b, b), c, y, lo, hi)
        assert Fraction(v) <= exact if v != -np.inf else True


def test_interval_coefficients():
    # x = [a] y with a in [1, 2], y in [1, 3]: x in [1, 6]; min x is 1 for every a
    S = LinearSystem.dense([[1.0, -1.0]], [0.0], [0.0], A_hi=[[1.0, -2.0]])
    lo, hi = np.array([-10.0, 1.0]), np.array([10.0, 3.0])
    assert lp_bound(S, np.array([1.0, 0.0]), lo, hi) <= 1.0
    assert -lp_bound(S, np.array([-1.0, 0.0]), lo, hi) >= 6.0


@SETTINGS
@given(small_lp())
def test_infeasibility_only_with_a_certificate(p):
    c, A, b_lo, b_hi, lo, hi = p
    proven = infeasible(LinearSystem.dense(A, b_lo, b_hi), lo, hi)
    if proven:
        assert exact_min(c, A, b_lo, b_hi, lo, hi) is None


def test_infeasibility_proven():
    # x + y = 3 with x, y in [0, 1]; 2x - y = 5 with x in [0, 2], y in [0, 1] (needs x = 2.5+)
    for A, b, lo, hi in (([[1.0, 1.0]], 3.0, [0, 0], [1, 1]),
                         ([[2.0, -1.0]], 5.0, [0, 0], [2, 1])):
        S = LinearSystem.dense(A, [b], [b])
        assert infeasible(S, np.array(lo, float), np.array(hi, float))
        assert lp_bound(S, np.array([1.0, 0.0]), np.array(lo, float),
                        np.array(hi, float)) == np.inf


def test_barely_feasible_is_not_declared_empty():
    # x + y = 2 with x, y in [0, 1]: a single point; float noise must not make it empty
    S = LinearSystem.dense([[1.0, 1.0]], [2.0], [2.0])
    assert not infeasible(S, np.zeros(2), np.ones(2))
    S = LinearSystem.dense([[0.1, 0.2]], [0.30000000000000004], [0.30000000000000004])
    assert not infeasible(S, np.ones(2), np.ones(2))


# --- tapes -----------------------------------------------------------------------------------

def test_linear_tape_contracts_to_the_solution():
    x, y = Var("x"), Var("y")
    m = Model()
    m.declare(x, (0, 10))
    m.declare(y, (0, 10))
    m.add(x + y == 4, x - y == 2)
    t = compile_model(m)
    lo, hi, ok = contract_slots(t, t.lo, t.hi)
    sx, sy = t.slot_of["x"], t.slot_of["y"]
    assert ok
    assert lo[sx] <= 3 <= hi[sx] and hi[sx] - lo[sx] < 1e-12
    assert lo[sy] <= 1 <= hi[sy] and hi[sy] - lo[sy] < 1e-12


def test_log_linear_tape_contracts():
    # x y = 8 and x / y = 2 over positive x, y: x = 4, y = 2 (hull consistency alone cannot)
    x, y = Var("x"), Var("y")
    m = Model()
    m.declare(x, (1, 10))
    m.declare(y, (1, 10))
    m.add(x * y == 8, x / y == 2)
    t = compile_model(m)
    lo, hi, ok = contract_slots(t, t.lo, t.hi)
    sx, sy = t.slot_of["x"], t.slot_of["y"]
    assert ok
    assert lo[sx] <= 4 <= hi[sx] and hi[sx] - lo[sx] < 1e-9
    assert lo[sy] <= 2 <= hi[sy] and hi[sy] - lo[sy] < 1e-9
    lo2, hi2, _ = contract_slots(t, t.lo, t.hi, log_linear=False)
    assert hi2[sx] - lo2[sx] > 1  # the linear part alone has nothing to say here


def test_negative_sign_definite_variables_use_log_abs():
    # x y = -8, x / y = -2 with x in [1, 10], y in [-10, -1]: x = 4, y = -2
    x, y = Var("x"), Var("y")
    m = Model()
    m.declare(x, (1, 10))
    m.declare(y, (-10, -1))
    m.add(x * y == -8, x / y == -2)
    t = compile_model(m)
    lo, hi, ok = contract_slots(t, t.lo, t.hi)
    sy = t.slot_of["y"]
    assert ok and lo[sy] <= -2 <= hi[sy] and hi[sy] - lo[sy] < 1e-9


def test_infeasible_tape_is_empty_and_ctc_returns_empty():
    x, y = Var("x"), Var("y")
    m = Model()
    m.declare(x, (0, 1))
    m.declare(y, (0, 1))
    m.add(x + y == 3)
    t = compile_model(m)
    out = CtcLinear(t)(Interval.trusted(t.lo, t.hi))
    assert bool(out.is_empty().all())


def test_decimal_constants_are_interval_coefficients():
    # 0.1 is not a float: x = 0.1 y must keep the real solution x = 0.1 for y = 1
    from boundest.expr import parse_model

    m = parse_model("Variables x in [-1, 1], y in [1, 1];\nConstraints x = 0.1*y;\n")
    t = compile_model(m)
    lo, hi, ok = contract_slots(t, t.lo, t.hi)
    sx = t.slot_of["x"]
    assert ok and Fraction(lo[sx]) <= Fraction(1, 10) <= Fraction(hi[sx])
    assert hi[sx] - lo[sx] < 1e-15


def test_extract_rows():
    x, y, z = Var("x"), Var("y"), Var("z")
    m = Model()
    m.declare(x, (1, 2))
    m.declare(y, (-1, 2))
    m.add(z == 2 * x + y, z * x == y**2 + 1)
    t = compile_model(m)
    ext = extract(t, t.lo, t.hi)
    # z * x is log-linear only when z is sign-definite: not at this box (z unbounded)
    assert ext.system.n_rows >= 3
    assert ext.log_slots.size == 0


dyadic = st.integers(-24, 24).map(lambda k: k / 8.0)
positive = st.integers(1, 24).map(lambda k: k / 4.0)


@SETTINGS
@given(dyadic, dyadic, positive, positive, st.integers(0, 3), st.integers(0, 3),
       st.booleans())
def test_feasible_points_survive(a, b, p, q, ra, rb, log_linear):
    """A point whose every intermediate value is exact in float64 (dyadic values, products of
    dyadics, a power-of-two divisor) survives, with its constraints' domains around it."""
    x, y, u, v = Var("x"), Var("y"), Var("u"), Var("v")
    r = 0.25 * (ra + 1)
    m = Model()
    m.declare(x, (a - r, a + r))
    m.declare(y, (b - rb, b + rb))
    m.declare(u, (p / 2, p * 2))
    m.declare(v, (q / 2, q * 2))
    s1, s2 = a + 3 * b - 2 * p, 2 * a - b
    m.add((x + 3 * y - 2 * u).in_((s1 - rb, s1 + r)), (2 * x - y).in_((s2 - r, s2)),
          (u * v).in_((p * q - r, p * q + r)), (u / 4 + v * v).in_((p / 4 + q * q,) * 2),
          (u**3).in_((p**3 / 2, p**3 * 2)))
    t = compile_model(m)
    lo, hi, ok = contract_slots(t, t.lo, t.hi, log_linear=log_linear)
    assert ok
    for name, val in (("x", a), ("y", b), ("u", p), ("v", q)):
        s = t.slot_of[name]
        assert lo[s] <= val <= hi[s], (name, val, lo[s], hi[s])


@examples(150, 30)
def test_radius_is_a_sound_relaxation(n_examples):
    @settings(SETTINGS, max_examples=n_examples)
    @given(st.lists(dyadic, min_size=4, max_size=4), st.integers(1, 3))
    def check(vals, radius):
        # a chain x_{k+1} = x_k + 0.5 d_k: local LPs (few rows) keep the point, like the full one
        xs = [Var(f"x{k}") for k in range(5)]
        ds = [Var(f"d{k}") for k in range(4)]
        m = Model()
        pt = [0.0]
        for k in range(4):
            pt.append(pt[-1] + 0.5 * vals[k])
        for k in range(4):
            m.declare(ds[k], (vals[k] - 0.5, vals[k] + 0.25))
            m.add(xs[k + 1] == xs[k] + 0.5 * ds[k])
        m.declare(xs[0], (-0.125, 0.125))
        m.declare(xs[4], (pt[4] - 0.25, pt[4] + 0.5))
        t = compile_model(m)
        for rad in (radius, None):
            lo, hi, ok = contract_slots(t, t.lo, t.hi, radius=rad)
            assert ok
            for k in range(5):
                s = t.slot_of[f"x{k}"]
                assert lo[s] <= pt[k] <= hi[s]

    check()


finite = st.floats(-1e300, 1e300, allow_nan=False, allow_subnormal=True)


@SETTINGS
@given(st.lists(st.tuples(finite, st.integers(0, 3)), min_size=1, max_size=40))
def test_segment_sums_enclose_the_exact_sums(terms):
    from boundest.ctc.linear import _segment_sum

    v = np.array([t[0] for t in terms])
    seg = np.array([t[1] for t in terms], dtype=np.int64)
    lo, hi = _segment_sum(v, v, seg, 4)
    for g in range(4):
        exact = sum((Fraction(x) for x, s in zip(v, seg, strict=True) if s == g), Fraction(0))
        assert Fraction(lo[g]) <= exact <= Fraction(hi[g])


def test_propagate_lp_proves_an_inconsistent_cycle():
    from boundest.csp.linear import propagate_lp

    x, y, z = Var("x"), Var("y"), Var("z")
    m = Model()
    for v in (x, y, z):
        m.declare(v, (-10, 10))
    m.add(x + y == 1, y + z == 1, x - z == 0.5, (x * y).in_((0.1, 10)))
    # x = z + 0.5 and y = 1 - x give y + z = 0.5, not 1: no solution, which the LP proves
    # (a Farkas certificate) where hull consistency only creeps towards it
    lp = propagate_lp(m, targets=["x", "y", "z"], max_evaluations=200)
    assert not lp.consistent


def test_propagate_lp_keeps_the_solution_and_narrows():
    from boundest.csp import propagate
    from boundest.csp.linear import propagate_lp

    x, y, z = Var("x"), Var("y"), Var("z")
    m = Model()
    for v in (x, y, z):
        m.declare(v, (0.25, 10))
    # solution x = 2, y = 1, z = 0.5 (x = 2 y, y = 2 z, x y z = 1): linear in log x, log y,
    # log z (written as equalities, x is the slot of 2 y; ``x - 2 y == 0`` would be a linear
    # row, which the log-linear system does not see)
    m.add(x == 2 * y, y == 2 * z, (x * y * z).in_((1, 1)))
    hc = propagate(m)
    lp = propagate_lp(m, targets=["x", "y", "z"])
    assert lp.consistent and lp.rounds >= 1
    for name, val in (("x", 2.0), ("y", 1.0), ("z", 0.5)):
        d = lp[name]
        assert float(d.lo) <= val <= float(d.hi)
        assert float(d.hi - d.lo) <= float(hc[name].hi - hc[name].lo)
    assert float(lp["x"].hi - lp["x"].lo) < 1e-6


@SETTINGS
@given(small_lp("unbounded"))
def test_linprog_fallback_is_sound_and_tight(p):
    """The public ``linprog(method="highs")`` path (used where SciPy's bundled HiGHS bindings
    are missing) gives the same guarantees."""
    from boundest.ctc.linear import _Solver

    c, A, b_lo, b_hi, lo, hi = p
    solver = _Solver(LinearSystem.dense(A, b_lo, b_hi))
    solver.highs = None
    bound = solver.bound(c, lo, hi)
    exact = exact_min(c, A, b_lo, b_hi, lo, hi)
    if exact is None:
        return
    assert bound != np.inf
    if exact == -math.inf:
        assert bound == -np.inf
    elif bound != -np.inf:
        assert Fraction(bound) <= exact
        if np.isfinite(lo).all() and np.isfinite(hi).all():
            assert float(exact) - bound <= 1e-7 * (1 + abs(float(exact)))


def test_missing_scipy_names_the_extra(monkeypatch):
    import sys

    t = compile_model([Var("x") + Var("y") == 1])
    monkeypatch.setitem(sys.modules, "scipy.optimize", None)  # import fails as if absent
    with pytest.raises(ImportError, match=r"pip install 'boundest\[lp\]'"):
        CtcLinear(t)
