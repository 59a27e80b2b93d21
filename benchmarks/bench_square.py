"""Square systems: every solution with a proof, by interval Newton branch and prune.

Standard benchmarks of interval solvers, solved by ``boundest.paving.roots.solve_square`` (hull
consistency and the preconditioned Hansen-Sengupta step on each box of the frontier, the Krawczyk
test for existence and uniqueness, bisection of what is left): per problem the number of proved
solutions, undecided boxes (with why), boxes contracted and the median time over ``--repeat``
runs after a warm-up (compilation excluded). Problems:

- ``broyden-N``: Broyden banded, ``x_i (2 + 5 x_i^2) + 1 - sum_{j in J_i} x_j (1 + x_j) = 0``,
  ``J_i = {max(0, i - 5) .. min(n - 1, i + 1)} - {i}``, in ``[-1, 1]^n`` (one solution);
- ``circles``: two circles ``x^2 + y^2 = 4``, ``(x - 1)^2 + y^2 = 2`` (two solutions);
- ``arm``: inverse kinematics of a planar two-link arm, ``l1 cos(a) + l2 cos(a + b) = px``,
  ``l1 sin(a) + l2 sin(a + b) = py`` with ``a, b in [-pi, pi]`` (elbow up and down: two);
- ``double-root``: ``x^2 = 0``, ``y = x`` (a double root: undecided, never proved);
- ``no-root``: ``x^2 + y^2 = -1 + 2 z^2``, ``z = 0.5 x``, ``y = x`` style system with no real
  solution (nothing proved, nothing left).

Every proved box is checked: a float Newton iteration from its midpoint stays in it and the
residual there is below ``1e-9`` (an independent plausibility check; the proof is the Krawczyk
test itself).

Usage::

    .venv/bin/python benchmarks/bench_square.py [--out benchmarks/results/square.json]
        [--repeat 3] [--sizes 10,100,1000]
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np
from _machine import cpu_model, emit

import boundest as bd
from boundest.expr import Model, Var
from boundest.interval import Interval
from boundest.paving.roots import solve_square


def broyden(n: int) -> tuple[Model, Interval]:
    x = [Var(f"x{i}") for i in range(n)]
    m = Model()
    for v in x:
        m.declare(v, (-1.0, 1.0))
    for i in range(n):
        s = None
        for j in range(max(0, i - 5), min(n - 1, i + 1) + 1):
            if j != i:
                t = x[j] * (1 + x[j])
                s = t if s is None else s + t
        m.add(x[i] * (2 + 5 * x[i] ** 2) + 1 - s == 0)
    return m, Interval(-np.ones(n), np.ones(n))


def circles() -> tuple[Model, Interval]:
    x, y = Var("x"), Var("y")
    m = Model().add(x**2 + y**2 == 4, (x - 1) ** 2 + y**2 == 2)
    return m, Interval([-3.0, -3.0], [3.0, 3.0])


def arm() -> tuple[Model, Interval]:
    a, b = Var("a"), Var("b")
    m = Model().add(2 * bd.cos(a) + 1.5 * bd.cos(a + b) == 2.2,
                    2 * bd.sin(a) + 1.5 * bd.sin(a + b) == 1.3)
    return m, Interval([-math.pi, -math.pi], [math.pi, math.pi])


def double_root() -> tuple[Model, Interval]:
    x, y = Var("x"), Var("y")
    return Model().add(x**2 == 0, y - x == 0), Interval([-1.0, -1.0], [1.0, 1.0])


def no_root() -> tuple[Model, Interval]:
    x, y = Var("x"), Var("y")
    return (Model().add(x**2 + y**2 == 0.5 * (x - y) ** 2 - 1, y + x == 0.25),
            Interval([-2.0, -2.0], [2.0, 2.0]))


def _residual_check(model: Model, names: list[str], sol: Interval) -> bool:
    """A float Newton iteration from each proved box's midpoint stays in the box."""
    from boundest.ctc.derivatives import evaluate, jacobian
    from boundest.expr.function_tape import constraint_functions

    tape, _ = constraint_functions(model)
    ok = True
    for b in sol:
        x = b.mid().copy()
        for _ in range(20):
            f = evaluate(tape, Interval(x, x)).mid()
            _, J = jacobian(tape, Interval(x, x))
            try:
                x = x - np.linalg.solve(J.mid(), f)
            except np.linalg.LinAlgError:
                break
        res = np.abs(evaluate(tape, Interval(x, x)).mid()).max()
        ok &= bool(np.all(b.lo - 1e-12 <= x) and np.all(x <= b.hi + 1e-12) and res < 1e-9)
    return ok


def run(name: str, make, repeat: int, eps: float) -> dict:
    model, box = make()
    solve_square(model, box, eps=eps)  # warm-up (compilation)
    times, res = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        res = solve_square(model, box, eps=eps)
        times.append(time.perf_counter() - t)
    assert res is not None
    sol = res.solutions
    row = {"problem": name, "variables": len(res.variables), "eps": eps,
           "proved": int(res.proved.sum()), "undecided": int((~res.proved).sum()),
           "undecided_why": res.stats["undecided_why"], "processed": res.stats["processed"],
           "merged": res.stats["merged"], "time_s": statistics.median(times),
           "times_s": times, "float_newton_agrees": _residual_check(model, res.variables, sol),
           "widest_proved_box": float(sol.width().max()) if len(sol) else None}
    print(f"{name:>14}: {row['proved']} proved, {row['undecided']} undecided "
          f"{row['undecided_why']}, {row['processed']} boxes, {row['time_s']:.3f} s",
          flush=True)
    return row


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", help="write the JSON here")
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--sizes", default="10,100,1000", help="Broyden banded sizes")
    p.add_argument("--eps", type=float, default=1e-8)
    args = p.parse_args()
    rows = []
    for n in [int(s) for s in args.sizes.split(",") if s]:
        rows.append(run(f"broyden-{n}", lambda n=n: broyden(n),
                        args.repeat if n < 1000 else 1, args.eps))
    for name, make in (("circles", circles), ("arm", arm), ("double-root", double_root),
                       ("no-root", no_root)):
        rows.append(run(name, make, args.repeat, args.eps))
    emit({"benchmark": "square systems, interval Newton branch and prune (solve_square)",
          "cpu": cpu_model(), "rows": rows}, args.out)


if __name__ == "__main__":
    main()
