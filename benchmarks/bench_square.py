"""Square systems: every solution with a proof, by interval Newton branch and prune.

Standard benchmarks of interval solvers, solved by ``boundest.paving.roots.solve_square`` (hull
consistency and the preconditioned Hansen-Sengupta step on each box of the frontier, the Krawczyk
test for existence and uniqueness, bisection of what is left): per problem the number of proved
solutions, undecided boxes (with why), boxes contracted and the median time over ``--repeat``
warm runs in-process. A first call (at most 64 boxes) compiles or loads the kernels before them:
its time is recorded as ``first_call_s``, so that a run with an empty Numba cache
(``NUMBA_CACHE_DIR`` a new folder, ``BOUNDEST_KERNEL_ARCHIVE=0``) gives the compile cost on its
first problem. Problems (the ``ibex`` ones are those of IBEX's ``benchs/solver`` folder, same
equations and domains):

- ``broyden-N`` (N = 10, 100, 1000): Broyden banded (More, Garbow, Hillstrom 1981, problem 31,
  ``ml = 5``, ``mu = 1``), ``f_i = x_i (2 + 5 x_i^2) + 1 - sum_{j in J_i} x_j (1 + x_j)``,
  ``J_i = {max(1, i - 5) .. min(n, i + 1)} - {i}``, in ``[-100, 100]^n`` as IBEX's
  ``BroydenBanded-N.bch`` (one solution, all ``x_i`` in ``[-0.63, -0.42]``); ``broyden1-N``:
  the same in ``[-1, 1]^n``;
- ``brown-5``: Brown's almost linear system (``Brown-05.bch``), ``x_i + sum_j x_j = n + 1``
  (``i < n``), ``prod_j x_j = 1``, in ``[-1e8, 1e8]^5`` (three solutions);
- ``trigexp1-30``: trigonometric-exponential system 1 (``Trigexp1-030.bch``), tridiagonal with
  ``sin``, ``exp`` and cubes, in ``[-100, 100]^30`` (one solution);
- ``kin1``: inverse kinematics of a 6-revolute-joint arm (``Kin1.bch``), products of ``sin``
  and ``cos``, angles in ``[0, 2 pi]`` (16 solutions);
- ``circles``: two circles ``x^2 + y^2 = 4``, ``(x - 1)^2 + y^2 = 2`` (two solutions);
- ``arm``: planar two-link arm, ``2 cos(a) + 1.5 cos(a + b) = 2.2``,
  ``2 sin(a) + 1.5 sin(a + b) = 1.3``, ``a, b in [-pi, pi]`` (elbow up and down: two);
- ``double-root``: ``x^2 = 0``, ``y = x`` (a double root: undecided, never proved);
- ``no-root``: ``x^2 + y^2 = 0.5 (x - y)^2 - 1``, ``x + y = 0.25`` (no real solution: nothing
  proved, nothing left).

Every proved box is checked independently of boundest: mpmath's ``findroot`` at 50 digits from
the box's midpoint (``n <= 100``; for ``n > 100`` a simplified Newton iteration whose residuals
are mpmath's at 50 digits and whose steps solve with a float64 finite-difference Jacobian taken
once) must converge to a point inside the box with ``|f| < 1e-40``, and the proved boxes must
give distinct roots.

``--bch DIR`` writes each problem as an IBEX ``.bch`` file (the same equations, printed by
boundest) and ``--ibex PATH`` runs that ``ibexsolve`` binary on them (``-e EPS -t
IBEX_TIMEOUT``, same ``--repeat``, one run for ``n >= 1000``; killed after ``1.5 IBEX_TIMEOUT +
30`` s wall, since ibexsolve checks its limit only between cells), recording its version,
solution / unknown / pending box counts (its ``--`` is 0), cells, its CPU time and the wall time
of the process.

Usage::

    flock /tmp/bench.lock .venv/bin/python benchmarks/bench_square.py \\
        [--out benchmarks/results/square.json] [--repeat 3] [--problems broyden-10,kin1]
        [--quick] [--ibex /path/to/ibexsolve [--ibex-timeout 600]] [--bch DIR]
"""

from __future__ import annotations

import argparse
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace

import numpy as np
from _machine import cpu_model, emit

import boundest as bd
from boundest.expr import Model, Var
from boundest.interval import Interval
from boundest.paving.roots import solve_square


@dataclass
class Problem:
    name: str
    lo: list[float]
    hi: list[float]
    eqs: Callable  # eqs(x, lib) -> residuals, lib: sin, cos, exp
    ibex: str | None = None  # the file of IBEX's benchs/solver folder with this system
    expected: int | None = None  # solutions in the box (literature / IBEX)

    @property
    def n(self) -> int:
        return len(self.lo)


def _broyden_eqs(x, _lib):
    n = len(x)
    out = []
    for i in range(n):
        s = None
        for j in range(max(0, i - 5), min(n - 1, i + 1) + 1):
            if j != i:
                t = x[j] * (1 + x[j])
                s = t if s is None else s + t
        out.append(x[i] * (2 + 5 * x[i] ** 2) + 1 - s)
    return out


def broyden(n: int, r: float = 100.0) -> Problem:
    name = f"broyden-{n}" if r == 100.0 else f"broyden1-{n}"
    return Problem(name, [-r] * n, [r] * n, _broyden_eqs,
                   f"polynom/BroydenBanded-{n:03d}.bch" if r == 100.0 else None, 1)


def _brown_eqs(x, _lib):
    n = len(x)
    out = []
    for i in range(n - 1):  # as Brown-05.bch writes it: 2 x_i + sum_{j != i} x_j - (n + 1)
        s = 2 * x[i]
        for j in range(n):
            if j != i:
                s = s + x[j]
        out.append(s - (n + 1))
    prod = x[0]
    for v in x[1:]:
        prod = prod * v
    return [*out, prod - 1]


def brown(n: int = 5) -> Problem:
    return Problem(f"brown-{n}", [-1e8] * n, [1e8] * n, _brown_eqs,
                   f"polynom/Brown-{n:02d}.bch", 3 if n == 5 else None)


def _trigexp1_eqs(x, lib):
    n = len(x)
    sin, exp = lib.sin, lib.exp
    out = [-5 + sin(x[0] - x[1]) * sin(x[0] + x[1]) + 3 * x[0] ** 3 + 2 * x[1]]
    for i in range(1, n - 1):
        out.append(-8 + sin(x[i] - x[i + 1]) * sin(x[i] + x[i + 1])
                   - exp(x[i - 1] - x[i]) * x[i - 1] - 4 * x[i] + 3 * x[i] ** 3
                   + 2 * x[i + 1])
    out.append(-3 - exp(x[n - 2] - x[n - 1]) * x[n - 2] + 4 * x[n - 1])
    return out


def trigexp1(n: int = 30) -> Problem:
    return Problem(f"trigexp1-{n}", [-100.0] * n, [100.0] * n, _trigexp1_eqs,
                   f"non-polynom/Trigexp1-{n:03d}.bch", 1)


def _kin1_eqs(t, lib):
    s, c = [lib.sin(v) for v in t], [lib.cos(v) for v in t]
    s1, s2, s3, s4, s5, s6 = s
    c1, c2, c3, c4, c5, c6 = c
    return [-0.4077 + c2 * c6 + c3 * c6 + c4 * c6 + c5 * s2 * s6 - c5 * s3 * s6 - c5 * s4 * s6,
            -1.9115 + c5 * s1 + c1 * c2 * s5 + c1 * c3 * s5 + c1 * c4 * s5,
            -1.9791 + s2 * s5 + s3 * s5 + s4 * s5,
            -4.0616 + 3 * c1 * c2 + 2 * c1 * c3 + c1 * c4,
            -1.7172 + 3 * c2 * s1 + 2 * c3 * s1 + c4 * s1,
            -3.9701 + 3 * s2 + 2 * s3 + s4]


def kin1() -> Problem:
    return Problem("kin1", [0.0] * 6, [math.nextafter(2 * math.pi, math.inf)] * 6, _kin1_eqs,
                   "non-polynom/Kin1.bch", 16)


def _circles_eqs(v, _lib):
    x, y = v
    return [x**2 + y**2 - 4, (x - 1) ** 2 + y**2 - 2]


def _arm_eqs(v, lib):
    a, b = v
    return [2 * lib.cos(a) + 1.5 * lib.cos(a + b) - 2.2,
            2 * lib.sin(a) + 1.5 * lib.sin(a + b) - 1.3]


def _double_root_eqs(v, _lib):
    x, y = v
    return [x**2, y - x]


def _no_root_eqs(v, _lib):
    x, y = v
    return [x**2 + y**2 - (0.5 * (x - y) ** 2 - 1), y + x - 0.25]


PI_UP = math.nextafter(math.pi, math.inf)
SMALL = {
    "circles": lambda: Problem("circles", [-3.0, -3.0], [3.0, 3.0], _circles_eqs, None, 2),
    "arm": lambda: Problem("arm", [-PI_UP, -PI_UP], [PI_UP, PI_UP], _arm_eqs, None, 2),
    "double-root": lambda: Problem("double-root", [-1.0, -1.0], [1.0, 1.0], _double_root_eqs,
                                   None, 1),
    "no-root": lambda: Problem("no-root", [-2.0, -2.0], [2.0, 2.0], _no_root_eqs, None, 0),
}


def problems(quick: bool) -> list[Problem]:
    out = [broyden(10), broyden(100)] + ([] if quick else [broyden(1000)])
    out += [broyden(10, 1.0), broyden(100, 1.0)] + ([] if quick else [broyden(1000, 1.0)])
    out += [brown(5), trigexp1(30), kin1()]
    return out + [make() for make in SMALL.values()]


BD = SimpleNamespace(sin=bd.sin, cos=bd.cos, exp=bd.exp)


def model_of(p: Problem) -> tuple[Model, Interval, list[str]]:
    names = [f"x{i}" for i in range(p.n)]
    x = [Var(v) for v in names]
    m = Model()
    for v, lo, hi in zip(x, p.lo, p.hi, strict=True):
        m.declare(v, (lo, hi))
    m.add(*(r == 0 for r in p.eqs(x, BD)))
    return m, Interval(p.lo, p.hi), names


def write_bch(p: Problem, path: Path) -> None:
    """The problem in IBEX's Minibex syntax: boundest prints the same expressions."""
    _, _, names = model_of(p)
    x = [Var(v) for v in names]
    lines = ["Variables"]
    lines += [f"  {v} in [{lo!r}, {hi!r}];" for v, lo, hi in zip(names, p.lo, p.hi,
                                                                  strict=True)]
    lines.append("Constraints")
    lines += [f"  {r} = 0;" for r in p.eqs(x, BD)]
    lines.append("end")
    path.write_text("\n".join(lines) + "\n")


def check_roots(p: Problem, boxes: Interval) -> dict:
    """Each proved box holds a root that mpmath finds at 50 digits from its midpoint."""
    import mpmath

    def f(*x):
        return p.eqs(list(x), mpmath)

    inside, residual, roots = [], [], []
    with mpmath.workdps(50):
        for k in range(len(boxes)):
            mid = [mpmath.mpf(float(v)) for v in boxes[k].mid()]
            try:
                if p.n <= 100:
                    r = list(mpmath.findroot(f, mid, tol=mpmath.mpf(10) ** -80, maxsteps=100))
                else:
                    r = _simplified_newton(p, mid)
            except (ValueError, ZeroDivisionError):
                inside.append(False)
                residual.append(None)
                continue
            roots.append(r)
            res = max(abs(v) for v in f(*r))
            residual.append(float(res))
            lo, hi = boxes.lo[k], boxes.hi[k]
            inside.append(bool(res < mpmath.mpf(10) ** -40 and all(
                mpmath.mpf(float(lo[j])) <= r[j] <= mpmath.mpf(float(hi[j]))
                for j in range(p.n))))
        distinct = sum(1 for i, r in enumerate(roots) if all(
            max(abs(a - b) for a, b in zip(r, s, strict=True)) > mpmath.mpf(10) ** -30
            for s in roots[:i]))
    return {"method": "findroot" if p.n <= 100 else "simplified Newton, mpmath residuals",
            "all_inside": all(inside), "distinct_roots": distinct,
            "max_residual": max((r for r in residual if r is not None), default=None)}


def _simplified_newton(p: Problem, x: list) -> list:
    """Newton's iteration with 50-digit residuals and a float64 Jacobian taken once (central
    differences at the start): it converges linearly to the root to full precision."""
    import mpmath

    x0 = np.array([float(v) for v in x])
    n = p.n
    jac = np.empty((n, n))
    for j in range(n):
        h = 1e-6 * max(1.0, abs(x0[j]))
        xp, xm = x0.copy(), x0.copy()
        xp[j] += h
        xm[j] -= h
        jac[:, j] = (np.array(p.eqs(list(xp), math)) - np.array(p.eqs(list(xm), math))) / (2 * h)
    for _ in range(100):
        fx = p.eqs(x, mpmath)
        if max(abs(v) for v in fx) < mpmath.mpf(10) ** -45:
            return x
        d = np.linalg.solve(jac, np.array([float(v) for v in fx]))
        x = [a - mpmath.mpf(float(b)) for a, b in zip(x, d, strict=True)]
    raise ValueError("no convergence")


def run(p: Problem, repeat: int, eps: float) -> dict:
    model, box, _ = model_of(p)
    t = time.perf_counter()
    solve_square(model, box, eps=eps, max_boxes=64)  # warm-up: compiles (or loads) the kernels
    first = time.perf_counter() - t
    times, res = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        res = solve_square(model, box, eps=eps)
        times.append(time.perf_counter() - t)
    assert res is not None
    sol = res.solutions
    row = {"problem": p.name, "variables": p.n, "eps": eps, "expected_solutions": p.expected,
           "ibex_file": p.ibex, "proved": int(res.proved.sum()),
           "undecided": int((~res.proved).sum()), "undecided_why": res.stats["undecided_why"],
           "processed": res.stats["processed"], "bisections": res.stats["bisections"],
           "merged": res.stats["merged"], "stopped": res.stats["stopped"],
           "time_s": statistics.median(times), "times_s": times, "first_call_s": first,
           "widest_proved_box": float(sol.width().max()) if len(sol) else None}
    row["check"] = check_roots(p, sol)
    print(f"{p.name:>14}: {row['proved']} proved, {row['undecided']} undecided "
          f"{ {k: v for k, v in row['undecided_why'].items() if v} }, {row['processed']} boxes, "
          f"{row['time_s']:.3f} s, check {row['check']['all_inside']} "
          f"({row['check']['distinct_roots']} distinct)", file=sys.stderr, flush=True)
    return row


def run_ibex(binary: str, p: Problem, repeat: int, eps: float, folder: Path, limit: float
             ) -> dict:
    path = folder / f"{p.name}.bch"
    write_bch(p, path)
    cmd = [binary, "-e", repr(eps), "-t", repr(limit), "-o", str(folder / f"{p.name}.cov"),
           str(path)]
    out: dict = {"command": " ".join([Path(binary).name, *cmd[1:5], path.name])}
    cpu, wall = [], []
    for _ in range(repeat):
        t = time.perf_counter()
        try:
            text = subprocess.run(cmd, capture_output=True, text=True,
                                  timeout=1.5 * limit + 30).stdout
        except subprocess.TimeoutExpired:  # -t is checked between cells: one cell can outlast it
            wall.append(time.perf_counter() - t)
            out.update({"solutions": None, "unknown": None, "boundary": None, "pending": None,
                        "cells": None, "status": f"killed after {wall[-1]:.0f} s wall"})
            cpu.append(None)
            continue
        wall.append(time.perf_counter() - t)
        got = {k: re.search(rf"{k}[^:]*:\s*(\S+)", text) for k in
               ("solution boxes", "unknown boxes", "boundary boxes", "pending boxes",
                "cpu time used", "number of cells")}
        vals = {k: (None if m is None else "0" if m.group(1) == "--" else m.group(1))
                for k, m in got.items()}
        cpu.append(float(vals["cpu time used"].rstrip("s")) if vals["cpu time used"] else None)
        out.update({"solutions": vals["solution boxes"], "unknown": vals["unknown boxes"],
                    "boundary": vals["boundary boxes"], "pending": vals["pending boxes"],
                    "cells": vals["number of cells"], "status": _ibex_status(text)})
    out["cpu_s"] = statistics.median([c for c in cpu if c is not None]) if any(cpu) else None
    out["wall_s"] = statistics.median(wall)
    print(f"{'ibex ' + p.name:>20}: {out['solutions']} solutions, {out['unknown']} unknown, "
          f"{out['cells']} cells, {out['cpu_s']} s cpu, {out['status']}", file=sys.stderr,
          flush=True)
    return out


def _ibex_status(text: str) -> str:
    """ibexsolve's verdict, from its report."""
    for key, status in (("successful", "success"), ("infeasible", "infeasible"),
                        ("'unknown' status", "unknown boxes"), ("time limit", "time limit")):
        if key in text:
            return status
    return "other: " + text.strip()[-200:]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", help="write the JSON here")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--eps", type=float, default=1e-8)
    ap.add_argument("--quick", action="store_true", help="leave out the n = 1000 problems")
    ap.add_argument("--problems", help="comma-separated names (default: all)")
    ap.add_argument("--ibex", help="an ibexsolve binary to run on the same problems")
    ap.add_argument("--ibex-timeout", type=float, default=600.0,
                    help="ibexsolve's -t (CPU seconds) per run")
    ap.add_argument("--bch", help="write the problems as IBEX .bch files in this folder")
    args = ap.parse_args()
    todo = problems(args.quick and not args.problems)
    if args.problems:
        want = args.problems.split(",")
        todo = [p for p in problems(False) if p.name in want]
        missing = set(want) - {p.name for p in todo}
        if missing:
            ap.error(f"unknown problems: {', '.join(sorted(missing))}")
    if args.bch:
        Path(args.bch).mkdir(parents=True, exist_ok=True)
        for p in todo:
            write_bch(p, Path(args.bch) / f"{p.name}.bch")
    load_before = os.getloadavg()
    rows = []
    ibex_version = None
    if args.ibex:
        ibex_version = subprocess.run([args.ibex, "--version"], capture_output=True,
                                      text=True).stdout.strip()
    with tempfile.TemporaryDirectory() as tmp:
        for p in todo:
            row = run(p, args.repeat, args.eps)
            if args.ibex:
                row["ibex"] = run_ibex(args.ibex, p, args.repeat if p.n < 1000 else 1,
                                       args.eps, Path(tmp), args.ibex_timeout)
            rows.append(row)
    import numba

    emit({"benchmark": "square systems, interval Newton branch and prune (solve_square)",
          "machine": {"cpu": cpu_model(), "cpus": os.cpu_count(), "numpy": np.__version__,
                      "numba": numba.__version__, "load_before": load_before,
                      "load_after": os.getloadavg()},
          "kernel_cache": {v: os.environ.get(v) for v in ("NUMBA_CACHE_DIR",
                                                           "BOUNDEST_KERNEL_ARCHIVE")},
          "ibex": ibex_version, "eps": args.eps, "repeat": args.repeat, "rows": rows,
          "summary": {r["problem"]: {"proved": r["proved"], "undecided": r["undecided"],
                                     "boxes": r["processed"], "time_s": r["time_s"],
                                     "check": r["check"]["all_inside"],
                                     "ibex_cpu_s": r.get("ibex", {}).get("cpu_s")}
                      for r in rows}}, args.out)


if __name__ == "__main__":
    main()
