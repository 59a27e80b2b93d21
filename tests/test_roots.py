"""solve_square (interval Newton branch and prune): every solution in a proved or an undecided
box, proofs on systems with known solutions; and the LU preconditioner of its Newton step."""

import math

import numpy as np
import pytest

from boundest.ctc.linear_forms import preconditioner, square_preconditioner
from boundest.expr import Model, Var
from boundest.interval import Interval
from boundest.paving.roots import solve_square


def test_square_preconditioner_inverts_and_falls_back_when_singular():
    rng = np.random.default_rng(4)
    n = 200
    A = np.zeros((n, n))
    for i in range(n):  # banded, as the Jacobian of Broyden banded
        A[i, max(0, i - 5):min(n, i + 2)] = rng.normal(size=min(n, i + 2) - max(0, i - 5))
        A[i, i] += 8.0
    W, pivot, used = np.empty((n, 2 * n)), np.empty(n, np.int64), np.empty(n, np.bool_)
    square_preconditioner(A, W, pivot, used)
    P = W[:, n:]
    assert np.abs(P @ A - np.eye(n)).max() < 1e-12 and np.array_equal(pivot, np.arange(n))
    S = rng.normal(size=(6, 6))
    S[5] = S[0] + S[1]  # rank 5 (to rounding): handed to the Gauss-Jordan preconditioner
    W, pivot, used = np.empty((6, 12)), np.empty(6, np.int64), np.empty(6, np.bool_)
    square_preconditioner(S, W, pivot, used)
    W0, pivot0, used0 = np.empty((6, 12)), np.empty(6, np.int64), np.empty(6, np.bool_)
    preconditioner(S, W0, pivot0, used0)
    assert np.array_equal(W, W0) and np.array_equal(pivot, pivot0)


@pytest.mark.parametrize("shaving", [True, False])
def test_every_solution_in_exactly_one_proved_box(shaving):
    x, y = Var("x"), Var("y")
    r = solve_square(Model().add(x**2 + y**2 == 4, x * y == 1), Interval([-3, -3], [3, 3]),
                     shaving=shaving)
    assert len(r.undecided) == 0 and len(r.solutions) == 4
    for s in (1, -1):
        for v in (math.sqrt(2 + math.sqrt(3)), math.sqrt(2 - math.sqrt(3))):
            pt = np.array([s * v, s / v])
            inside = np.all((r.solutions.lo <= pt + 1e-12) & (pt - 1e-12 <= r.solutions.hi),
                            axis=1)
            assert inside.sum() == 1
    assert r.solutions.width().max() < 1e-8


def test_broyden_banded_in_a_large_box():
    n = 30
    x = [Var(f"x{i}") for i in range(n)]
    m = Model()
    for v in x:
        m.declare(v, (-100.0, 100.0))
    for i in range(n):
        s = sum((x[j] * (1 + x[j]) for j in range(max(0, i - 5), min(n, i + 2)) if j != i),
                start=0)
        m.add(x[i] * (2 + 5 * x[i] ** 2) + 1 - s == 0)
    r = solve_square(m)
    assert len(r.solutions) == 1 and len(r.undecided) == 0
    assert r.stats["processed"] < 50  # shaving: no bisection, where hull consistency needs 100s
    c = r.solutions[0].mid()
    f = [c[i] * (2 + 5 * c[i] ** 2) + 1 - sum(c[j] * (1 + c[j]) for j in range(
        max(0, i - 5), min(n, i + 2)) if j != i) for i in range(n)]
    assert max(abs(v) for v in f) < 1e-12


def test_a_double_root_is_undecided_and_no_root_leaves_nothing():
    x, y = Var("x"), Var("y")
    r = solve_square(Model().add(x**2 == 0, y - x == 0), Interval([-1, -1], [1, 1]))
    assert len(r.solutions) == 0 and len(r.undecided) >= 1
    assert np.any(np.all((r.undecided.lo <= 0) & (r.undecided.hi >= 0), axis=1))
    r = solve_square(Model().add(x**2 + y**2 == 0.5 * (x - y) ** 2 - 1, x + y == 0.25),
                     Interval([-2, -2], [2, 2]))
    assert len(r) == 0
