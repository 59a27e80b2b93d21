"""Box consistency (``CtcBox``, BC3) against hull consistency (``Fixpoint(CtcFwdBwd)``) and 3B
shaving (``CtcShave`` around it) on a few constraints where a variable occurs several times.

Per constraint: a batch of ``--boxes`` random boxes (seeded), the mean width of each variable
after each contractor and the median time of ``--repeat`` calls. Then whether the Jaulin et al.
2001 system has any constraint with a multiply occurring variable (only those are for BC).

Usage::

    .venv/bin/python benchmarks/bench_boxcons.py --out benchmarks/results/boxcons.json
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _machine import cpu_model, emit

from boundest import Interval
from boundest.csp import CtcBox
from boundest.csp.boxcons import occurrences
from boundest.ctc import CtcFwdBwd, CtcShave, Fixpoint
from boundest.expr import Var
from boundest.expr.functions import cos, sin, sqr


def cases():
    x, y = Var("x"), Var("y")
    return {
        "x*x - x == 0": ([x * x - x == 0], ["x"], ([-10.0], [10.0])),
        "x*(x-1) == y": ([x * (x - 1) == y], ["x", "y"], ([-5.0, -0.1], [5.0, 0.1])),
        "x/(1+x^2) == y": ([x / (1.0 + sqr(x)) == y], ["x", "y"], ([-10.0, 0.3], [10.0, 0.4])),
        "sin(x) + x*y == cos(x)": ([sin(x) + x * y == cos(x)], ["x", "y"],
                                   ([-3.0, -2.0], [3.0, 2.0])),
    }


def run(m: int, repeat: int) -> dict:
    rng = np.random.default_rng(1)
    out = {}
    for name, (cs, names, (lo0, hi0)) in cases().items():
        lo0, hi0 = np.array(lo0), np.array(hi0)
        a = rng.uniform(lo0, hi0, (m, len(names)))
        b = rng.uniform(lo0, hi0, (m, len(names)))
        box = Interval(np.minimum(a, b), np.maximum(a, b))
        hc = Fixpoint(CtcFwdBwd(cs, names))
        ctcs = {"hc": hc, "bc": CtcBox(cs, names), "bc+hc": Fixpoint(CtcBox(cs, names) & hc),
                "3b": CtcShave(hc, frac=0.05, max_slices=20)}
        res = {}
        for key, c in ctcs.items():
            times = []
            for _ in range(repeat):
                t0 = time.perf_counter()
                r = c(box)
                times.append(time.perf_counter() - t0)
            w = np.where(np.isnan(r.lo), 0.0, r.hi - r.lo)
            res[key] = {"time_s": statistics.median(times),
                        "mean_width": dict(zip(names, w.mean(axis=0).tolist(), strict=True)),
                        "empty": int(np.isnan(r.lo).any(axis=-1).sum())}
        res["input_mean_width"] = dict(zip(names, (box.hi - box.lo).mean(axis=0).tolist(),
                                           strict=True))
        out[name] = res
    return out


def jaulin2001_multi() -> list[str]:
    # the maps of boundest.scenarios.jaulin2001.system() (Jaulin et al. 2001 equation 21)
    x1, x2 = Var("x1"), Var("x2")
    exprs = [3 * sin(x1 + x2), 3 * cos(x1 + x2), abs(x1)]
    return [str(e) for e in exprs if any(k > 1 for k in occurrences(e).values())]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out")
    ap.add_argument("--boxes", type=int, default=1000)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    emit({"cpu": cpu_model(), "boxes": a.boxes, "cases": run(a.boxes, a.repeat),
          "jaulin2001_multi_occurrence_expressions": jaulin2001_multi()}, a.out)


if __name__ == "__main__":
    main()
