"""Long and deep expressions: parse, build, compile and propagate in time linear in their size.

Two families of one-constraint models, each at several sizes (issue 27, item 1: a sum of a few
hundred terms used to die with a RecursionError at every stage):

* ``sum-N``: ``x_k in [0, 1]`` (``k < N``), ``x_0 + ... + x_{N-1} = N - 0.5``
  (N = 10**3, 10**4, 10**5); the hull of the solutions is ``x_k in [0.5, 1]``;
* ``nest-D``: ``x in [0, 1]``, ``y = sqrt(1 + sqrt(1 + ... sqrt(1 + x)))``, ``D`` levels
  (D = 10**3, 10**4); ``y`` is the golden ratio to the last bit.

Stages, each the median of ``--repeat`` runs in this process:

* ``parse``: ``parse_model`` of the model text (lark's LALR parser and the transformer to
  expressions; for ``sum-N`` it reads the ``N`` declarations too);
* ``build``: the same model through the Python front end (``e = e + x[k]``,
  ``e = sqrt(1 + e)``, then ``Model.add``);
* ``print``: ``str`` of the constraint;
* ``compile``: ``compile_model``, the constraint tape that propagation runs on;
* ``function_tape``: ``constraint_functions``, the tape the centered modes differentiate;
* ``propagate``: ``propagate(tape, mode="hc4")`` (hull consistency, one pass to the fixed
  point; the default mode adds shaving and the centered form, whose cost is the solver's, not
  the expression's). Every run's domains are checked against the answers above.

Per stage and family, ``per_unit_us`` is the time per term or level at each size and
``exponent`` the least-squares slope of log(time) against log(size) over the sizes: 1 for
linear time, 2 for quadratic. ``linear`` is true when the exponent is below 1.3 (small
sizes carry fixed costs, which only lower it).

Usage::

    flock /tmp/bench.lock .venv/bin/python benchmarks/bench_long_expr.py \\
        [--out benchmarks/results/long_expr.json] [--repeat 3] [--quick]

``--quick`` leaves out the 10**5-term sum. JSON goes to stdout (and to ``--out``), a table to
stderr.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable

import numpy as np
from _machine import cpu_model, emit

import boundest as bd
from boundest.csp import propagate
from boundest.expr import Model, Var, parse_model
from boundest.expr.function_tape import constraint_functions
from boundest.expr.tape import compile_model

PHI = (1 + math.sqrt(5)) / 2
STAGES = ("parse", "build", "print", "compile", "function_tape", "propagate")
LINEAR_EXPONENT = 1.3


def sum_text(n: int) -> str:
    names = [f"x{k}" for k in range(n)]
    return ("Variables\n" + ",\n".join(f"  {v} in [0, 1]" for v in names) + ";\n"
            "Constraints\n  " + " + ".join(names) + f" = {n - 0.5};\n")


def sum_build(n: int) -> Model:
    xs = [Var(f"x{k}") for k in range(n)]
    m = Model()
    for v in xs:
        m.declare(v, (0, 1))
    e = xs[0]
    for v in xs[1:]:
        e = e + v
    return m.add(e == n - 0.5)


def sum_check(res, n: int) -> bool:
    lo = np.array([float(res[f"x{k}"].lo) for k in range(n)])
    hi = np.array([float(res[f"x{k}"].hi) for k in range(n)])
    return bool(res.consistent and np.all(lo <= 0.5) and np.all(lo >= 0.5 - 1e-9)
                and np.all(hi == 1.0))


def nest_text(d: int) -> str:
    return ("Variables x in [0, 1], y in [0, 10];\nConstraints\n  y = "
            + "sqrt(1 + " * d + "x" + ")" * d + ";\n")


def nest_build(d: int) -> Model:
    x, y = Var("x"), Var("y")
    m = Model()
    m.declare(x, (0, 1))
    m.declare(y, (0, 10))
    e = x
    for _ in range(d):
        e = bd.sqrt(1 + e)
    return m.add(y == e)


def nest_check(res, _d: int) -> bool:
    lo, hi = float(res["y"].lo), float(res["y"].hi)
    return bool(res.consistent and lo <= PHI + 1e-15 and hi >= PHI - 1e-15 and hi - lo < 1e-12)


FAMILIES: dict[str, tuple[Callable, Callable, Callable, str]] = {
    "sum": (sum_text, sum_build, sum_check, "terms"),
    "nest": (nest_text, nest_build, nest_check, "levels"),
}


def timed(f: Callable, repeat: int) -> tuple[float, list[float], object]:
    """Median wall time of ``repeat`` calls of ``f``, every time, and the last result."""
    times = []
    out = None
    for _ in range(repeat):
        out = None  # free the previous result before the next run
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), times, out


def run(family: str, size: int, repeat: int) -> dict:
    text_of, build, check, _unit = FAMILIES[family]
    text = text_of(size)
    row: dict = {"family": family, "size": size, "text_bytes": len(text),
                 "load_before": os.getloadavg()[0]}
    times: dict = {}
    times["parse"], row["parse_runs_s"], parsed = timed(lambda: parse_model(text), repeat)
    times["build"], _, model = timed(lambda: build(size), repeat)
    times["print"], _, printed = timed(lambda: str(model.constraints[0]), repeat)
    times["compile"], _, tape = timed(lambda: compile_model(model), repeat)
    times["function_tape"], _, _ft = timed(lambda: constraint_functions(model), repeat)
    times["propagate"], _, res = timed(lambda: propagate(tape, mode="hc4", progress=False),
                                       repeat)
    row["times_s"] = times
    row["n_nodes"] = int(tape.n_nodes)
    row["evaluations"] = int(res.evaluations)
    row["answer_ok"] = check(res, size)
    # the text front end gives the same tape as the Python one
    t2 = compile_model(parsed)
    row["same_tape_as_text"] = bool(t2.n_nodes == tape.n_nodes and np.array_equal(t2.op, tape.op))
    row["print_chars"] = len(printed)
    row["load_after"] = os.getloadavg()[0]
    return row


def linearity(rows: list[dict]) -> dict:
    out: dict = {}
    for family, (*_, unit) in FAMILIES.items():
        fr = sorted((r for r in rows if r["family"] == family), key=lambda r: r["size"])
        if len(fr) < 2:
            continue
        fam: dict = {"unit": unit, "sizes": [r["size"] for r in fr]}
        for stage in STAGES:
            t = [r["times_s"][stage] for r in fr]
            n = [r["size"] for r in fr]
            k = (float(np.polyfit(np.log(n), np.log(t), 1)[0]) if min(t) > 0 else None)
            fam[stage] = {"per_unit_us": [1e6 * ti / ni for ti, ni in zip(t, n, strict=True)],
                          "exponent": k,
                          "linear": k is not None and k < LINEAR_EXPONENT}
        out[family] = fam
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", help="write the JSON here")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="leave out the 10**5-term sum")
    args = ap.parse_args()
    sys.setrecursionlimit(1000)  # Python's default: nothing may lean on a raised limit
    cases = [("sum", 10**3), ("sum", 10**4), *([] if args.quick else [("sum", 10**5)]),
             ("nest", 10**3), ("nest", 10**4)]
    load_before = os.getloadavg()
    t0 = time.perf_counter()
    warm = propagate(sum_build(10), mode="hc4", progress=False)  # load the kernels first
    first_call_s = time.perf_counter() - t0
    assert warm.consistent
    rows = []
    print(f"{'case':<12}" + "".join(f"{s:>15}" for s in STAGES) + "  ok   load", file=sys.stderr)
    for family, size in cases:
        row = run(family, size, args.repeat)
        rows.append(row)
        print(f"{family}-{size:<8}" + "".join(f"{row['times_s'][s]:>14.4f}s" for s in STAGES)
              + f"  {row['answer_ok']!s:<5}{row['load_before']:>5.1f}", file=sys.stderr,
              flush=True)
    import lark
    import numba

    lin = linearity(rows)
    emit({"benchmark": "long and deep expressions: parse, build, print, compile, propagate",
          "machine": {"cpu": cpu_model(), "cpus": os.cpu_count(),
                      "python": platform.python_version(), "numpy": np.__version__,
                      "numba": numba.__version__, "lark": lark.__version__,
                      "load_before": load_before, "load_after": os.getloadavg()},
          "repeat": args.repeat, "recursion_limit": sys.getrecursionlimit(),
          "first_call_s": first_call_s, "rows": rows, "linearity": lin,
          "summary": {"all_answers_ok": all(r["answer_ok"] for r in rows),
                      "all_linear": all(v["linear"] for fam in lin.values()
                                        for k, v in fam.items() if k in STAGES),
                      **{f"{f}.{s}.exponent": lin[f][s]["exponent"]
                         for f in lin for s in STAGES}}}, args.out)


if __name__ == "__main__":
    main()
