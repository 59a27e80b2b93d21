"""The centered form with optimal multipliers (``ctc.windows``, ``ctc.simplex``): the simplex is
a good oracle (it reaches SciPy's optimum), the aggregated row is sound whatever the
multipliers, and the contractors and modes built on it never lose a solution."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import boundest as bd
from boundest.csp import Centered, propagate
from boundest.ctc.simplex import LP_INFEASIBLE, LP_OPTIMAL, lp_setup, lp_solve, multipliers
from boundest.ctc.windows import _aggregate, _narrow, assign_targets
from boundest.expr import Model, Var, VarFamily
from boundest.expr.function_tape import constraint_functions
from boundest.interval import Interval

from .checks import examples


def _tableau(A, ld, ud, ls, us):
    m, n = A.shape
    T = np.empty((m, n + m))
    x, lb, ub = np.empty(n + m), np.empty(n + m), np.empty(n + m)
    basis, nonbasic = np.empty(m, dtype=np.int64), np.empty(n + m, dtype=np.int64)
    lp_setup(A, ld, ud, ls, us, T, x, lb, ub, basis, nonbasic)
    return T, x, lb, ub, basis, nonbasic


@settings(deadline=None, max_examples=60)
@given(st.integers(0, 10_000))
def test_the_simplex_reaches_the_optimum_of_scipy(seed):
    """Dual simplex from the slack basis, then primal simplex from each optimum: every
    objective +-d_i reaches HiGHS's optimal value, the point satisfies the rows and bounds,
    and the multipliers reproduce the optimum by LP duality."""
    linprog = pytest.importorskip("scipy.optimize").linprog
    rng = np.random.default_rng(seed)
    m, n = int(rng.integers(1, 9)), int(rng.integers(1, 12))
    A = rng.normal(size=(m, n)) * (rng.random((m, n)) < 0.6)
    x0 = rng.uniform(-1, 1, n)
    ld, ud = x0 - rng.uniform(0, 1, n), x0 + rng.uniform(0, 1, n)
    ls, us = A @ x0 - rng.uniform(0, 0.3, m), A @ x0 + rng.uniform(0, 0.3, m)
    T, x, lb, ub, basis, nonbasic = _tableau(A, ld, ud, ls, us)
    first = True
    for i in range(n):
        for sign in (1.0, -1.0):
            c = np.zeros(n + m)
            c[i] = sign
            assert lp_solve(T, x, lb, ub, basis, nonbasic, c, first, 1000) == LP_OPTIMAL
            first = False
            ref = linprog(c, A_eq=np.hstack([A, -np.eye(m)]), b_eq=np.zeros(m),
                          bounds=list(zip(np.r_[ld, ls], np.r_[ud, us], strict=True)),
                          method="highs")
            assert abs(c @ x - ref.fun) <= 1e-7 * (1 + abs(ref.fun))
            assert np.allclose(A @ x[:n], x[n:], atol=1e-9)
            assert np.all(x >= lb - 1e-9) and np.all(x <= ub + 1e-9)
            y = multipliers(T, basis, c, n)
            r = c[:n] - A.T @ y  # reduced costs of d; of s: y
            dual = np.where(r > 0, r * ld, r * ud).sum() + np.where(y > 0, y * ls, y * us).sum()
            assert abs(dual - ref.fun) <= 1e-7 * (1 + abs(ref.fun))


def test_an_empty_programme_is_reported_infeasible():
    A = np.array([[1.0, 1.0]])
    T, x, lb, ub, basis, nonbasic = _tableau(A, np.zeros(2), np.ones(2), np.array([3.0]),
                                             np.array([4.0]))
    c = np.zeros(3)
    c[0] = 1.0
    assert lp_solve(T, x, lb, ub, basis, nonbasic, c, True, 100) == LP_INFEASIBLE


@settings(deadline=None, max_examples=200)
@given(st.integers(0, 10_000))
def test_the_aggregated_row_is_sound_for_any_multipliers(seed):
    """``_narrow`` with random multipliers, an interval matrix around the true one and a
    known solution of ``J d = s`` never cuts the solution off."""
    rng = np.random.default_rng(seed)
    m, n = int(rng.integers(1, 6)), int(rng.integers(1, 7))
    Jt = rng.normal(size=(m, n)) * (rng.random((m, n)) < 0.7)
    rad = rng.uniform(0, 0.1, (m, n)) * (Jt != 0)
    Jl, Jh = Jt - rad, Jt + rad
    d = rng.uniform(-1, 1, n)
    s = Jt @ d
    zl, zh = s - rng.uniform(0, 0.2, m), s + rng.uniform(0, 0.2, m)
    dl, dh = d - rng.uniform(0, 1, n), d + rng.uniform(0, 1, n)
    y = rng.normal(size=m) * (rng.random(m) < 0.8)
    gl, gh = np.empty(n), np.empty(n)
    _aggregate(y, Jl, Jh, gl, gh)
    for i in range(n):
        assert _narrow(i, y, zl, zh, gl, gh, dl, dh) >= 0
        assert dl[i] <= d[i] <= dh[i]


def test_targets_go_to_the_window_where_they_are_most_central():
    x = VarFamily("x")
    m = Model().add(*(x[k + 1] == x[k] + 1 for k in range(20)))
    tape, _ = constraint_functions(m)
    lo, hi, ptr, tv = assign_targets(tape, np.arange(tape.n_vars), 6, 3)
    assert lo[0] == 0 and np.all(np.diff(lo) == 3) and np.all(hi - lo <= 6) and hi[-1] == 20
    covered = np.zeros(20, dtype=bool)
    for a, b in zip(lo, hi, strict=True):
        covered[a:b] = True
    assert covered.all()
    assert sorted(tv.tolist()) == list(range(tape.n_vars))
    for w in range(len(lo)):  # each target lies in its window's rows
        for j in tv[ptr[w]:ptr[w + 1]]:
            rows = [r for r in range(20) if j in tape.cols[tape.row_ptr[r]:tape.row_ptr[r + 1]]]
            assert any(lo[w] <= r < hi[w] for r in rows)


def _chain(seed: int, steps: int = 40):
    """A damped pendulum discretised by Euler, its angle measured to +-0.05 with bounded
    process noise: the model and the simulated truth."""
    rng = np.random.default_rng(seed)
    dt, wb = 0.1, 0.01
    th, om = np.empty(steps + 1), np.empty(steps + 1)
    th[0], om[0] = 1.0, 0.0
    w = rng.uniform(-0.99 * wb, 0.99 * wb, (steps, 2))
    for k in range(steps):
        th[k + 1] = th[k] + dt * om[k] + w[k, 0]
        om[k + 1] = om[k] - dt * (np.sin(th[k]) + 0.2 * om[k]) + w[k, 1]
    meas = th + rng.uniform(-0.049, 0.049, steps + 1)
    t, o = VarFamily("th"), VarFamily("om")
    m = Model()
    for k in range(steps):
        m.add(t[k + 1] - t[k] - dt * o[k] <= wb, t[k + 1] - t[k] - dt * o[k] >= -wb)
        m.add(o[k + 1] - o[k] + dt * (bd.sin(t[k]) + 0.2 * o[k]) <= wb,
              o[k + 1] - o[k] + dt * (bd.sin(t[k]) + 0.2 * o[k]) >= -wb)
    for k in range(steps + 1):
        m.declare(t[k], (meas[k] - 0.05, meas[k] + 0.05))
        m.declare(o[k], (-10.0, 10.0))
    return m, th, om


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("mode", ["centered", "3b+centered"])
def test_centered_modes_keep_the_truth_of_a_pendulum_and_narrow_its_rate(seed, mode):
    m, th, om = _chain(seed)
    hc = propagate(m, mode="hc4")
    ce = propagate(m, mode=mode, centered=Centered(window=40, rounds=3))
    assert ce.consistent and ce.mode == mode and ce.centered["lp_optimal"] > 0
    for k in range(len(th)):
        assert ce[f"th_{k}"].contains(th[k]) and ce[f"om_{k}"].contains(om[k]), k
    w_hc = np.mean([float(hc[f"om_{k}"].width()) for k in range(len(om))])
    w_ce = np.mean([float(ce[f"om_{k}"].width()) for k in range(len(om))])
    assert w_ce < 0.5 * w_hc


def test_the_centered_mode_proves_an_inconsistent_window_empty():
    """x = y with x + y + 0.1 x y = 1.1 (x = 0.53565...) and x + y + 0.12 x y = 1.11
    (x = 0.5401...) have no common solution; hull consistency on [0, 1]^2 cannot see it, the
    linearisation of the three constraints can."""
    x, y = Var("x"), Var("y")
    m = Model().add(x + y + 0.1 * x * y == 1.1, x - y == 0, x + y + 0.12 * x * y == 1.11)
    m.declare(x, (0, 1))
    m.declare(y, (0, 1))
    assert propagate(m, mode="hc4").consistent
    res = propagate(m, mode="centered")
    assert not res.consistent and bool(res["x"].is_empty())


def test_a_tape_without_its_model_is_refused_by_the_centered_modes():
    from dataclasses import replace

    from boundest.expr.tape import compile_model

    x = Var("x")
    tape = replace(compile_model(Model().add(x * x == 2)), model=None)
    with pytest.raises(ValueError, match="differentiates the model"):
        propagate(tape, mode="centered")
    res = propagate(tape)  # the default falls back to shaving, which needs no derivative
    assert res.mode == "3b" and float(res["x"].lo) <= 2**0.5 <= float(res["x"].hi)
    assert propagate(compile_model(Model().add(x * x == 2))).mode == "3b+centered"
    with pytest.raises(ValueError, match="stride"):
        Centered(window=4, stride=5)


@examples(40, 4)
def test_ctc_centered_lp_keeps_a_known_solution(n_examples):
    """Random polynomial and trigonometric constraints through a random point: every box
    around the point keeps it after CtcCentered(precondition="lp")."""
    @settings(deadline=None, max_examples=n_examples)
    @given(st.integers(0, 10_000))
    def check(seed):
        rng = np.random.default_rng(seed)
        x, y, z = Var("x"), Var("y"), Var("z")
        p = rng.uniform(-2, 2, 3)
        exprs = [x * y + bd.sin(z), x**2 - y * z + 0.5 * x, bd.cos(x) * z + y]
        vals = [p[0] * p[1] + np.sin(p[2]), p[0] ** 2 - p[1] * p[2] + 0.5 * p[0],
                np.cos(p[0]) * p[2] + p[1]]
        m = Model()
        for e, v in zip(exprs[: int(rng.integers(1, 4))], vals, strict=False):
            m.add(e - v >= -1e-9, e - v <= 1e-9)
        names = m.variable_names()
        point = np.array([dict(zip("xyz", p, strict=True))[n] for n in names])
        r = rng.uniform(0.001, 0.5, (20, len(names)))
        off = rng.uniform(0, 1, (20, len(names)))
        box = Interval(point - r * off, point + r * (1 - off))
        out = bd.CtcCentered(m, precondition="lp")(box)
        assert np.all(out.lo <= point) and np.all(point <= out.hi)

    check()
