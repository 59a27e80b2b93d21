"""Pool robot benchmark (Jaulin's robust set-membership observer): the recursive q-relaxed box
observer on the embedded mission, its online update time, and a Monte Carlo check of what its
set guarantees.

- Embedded mission, in-process and warm: ``scenarios.pool.solve_pool`` at each ``--qs`` (median
  of ``--repeat`` runs), mean widths, empty steps (restarts), the most pings rejected in a
  window; the online ``update`` timed step by step (median and max).
- Monte Carlo: ``--missions`` simulated missions (``scenarios.pool_sim.simulate_pool``, outliers
  with p = 0.05), run as batches of ``--chunk`` missions through the same observer. Per step:
  the empirical frequency with which the set contains the truth, with its 95 % Wilson score
  interval, next to the per-window binomial bound
  ``P(at most q outliers among the window's pings)`` and to the empirical frequency of the event
  the recursive set is conditioned on (every window so far held at most q outliers).

Usage::

    .venv/bin/python benchmarks/bench_pool.py [--out benchmarks/results/pool.json]
        [--missions 10000] [--chunk 1000] [--q 8] [--m 80]

JSON goes to stdout (and to ``--out``); progress goes to stderr.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import statistics
import sys
import time
from typing import Any

import numpy as np
from _machine import cpu_model, emit


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def wilson(x: int, n: int, z: float = 1.959963984540054) -> tuple[float, float]:
    """The 95 % Wilson score interval of a binomial frequency ``x / n``."""
    p = x / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def _windows_ok(outlier: np.ndarray, m: int, q: int) -> np.ndarray:
    """Every window of ``m`` pings ending at or before ``k`` held at most ``q`` outliers."""
    c = np.cumsum(outlier, axis=-1)
    prev = np.concatenate([np.zeros_like(c[..., :m]), c[..., :-m]], axis=-1)
    return ~np.maximum.accumulate((c - prev) > q, axis=-1)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out")
    ap.add_argument("--qs", default="6,8,10")
    ap.add_argument("--q", type=int, default=8, help="q of the Monte Carlo")
    ap.add_argument("--m", type=int, default=80)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--missions", type=int, default=10_000)
    ap.add_argument("--chunk", type=int, default=1000)
    args = ap.parse_args()

    from boundest.scenarios.pool import pool_observer, solve_pool
    from boundest.scenarios.pool_data import load_pool
    from boundest.scenarios.pool_sim import simulate_pool

    rec: dict[str, Any] = {
        "benchmark": "pool", "started": time.strftime("%Y-%m-%dT%H:%M:%S"),
        "machine": {"cpu": cpu_model(), "cores": os.cpu_count(),
                    "python": platform.python_version()},
        "loadavg_start": os.getloadavg(), "args": vars(args),
        "team_reference": {"codac_1.5.7_boxes_q8": {"time_s": 18.5, "time_numpy_qinter_s": 2.3,
                                                    "mean_width_x": 1.00, "mean_width_y": 0.89},
                           "codac_paving_eps_0.25": {"time_s": 52, "widths": [0.77, 0.67]},
                           "codac_paving_eps_0.1": {"time_s": 291, "widths": [0.70, 0.61]},
                           "q6": "empty at the 4 steps whose window holds 7 outliers"}}
    data = load_pool()
    solve_pool(data, q=args.q, m=args.m)  # load the kernels
    emb = {}
    for q in (int(s) for s in args.qs.split(",")):
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            res = solve_pool(data, q=q, m=args.m)
            times.append(time.perf_counter() - t0)
        w = res.widths()
        emb[str(q)] = {"median_s": statistics.median(times), "mean_width": w.mean(0).tolist(),
                       "empty_steps": np.flatnonzero(res.empty).tolist(),
                       "max_rejected": int(res.rejected.max()),
                       "window_probability": res.window_probability[-1]}
        log(f"embedded q={q}: {emb[str(q)]['median_s']:.2f} s, widths {w.mean(0)[:2]}")
    obs = pool_observer(data, q=args.q, m=args.m)
    steps = []
    for k in range(data.n):
        t0 = time.perf_counter()
        obs.update(data.inputs[k - 1] if k else None, (float(data.alpha[k]), data.ranges[k]))
        steps.append(time.perf_counter() - t0)
    rec["embedded"] = emb
    rec["online_update_s"] = {"median": statistics.median(steps), "max": max(steps)}

    log(f"Monte Carlo: {args.missions} missions in chunks of {args.chunk} ...")
    n = data.n
    inside = np.zeros(n, dtype=np.int64)
    ok_count = np.zeros(n, dtype=np.int64)
    inside_given_ok = np.zeros(n, dtype=np.int64)
    empties = 0
    t_mc = time.perf_counter()
    done = 0
    while done < args.missions:
        size = min(args.chunk, args.missions - done)
        sim, truth = simulate_pool(seed=done, n_missions=size)
        res = solve_pool(sim, q=args.q, m=args.m)
        hit = ((res.boxes.lo <= truth.states) & (truth.states <= res.boxes.hi)).all(-1)
        ok = _windows_ok(truth.outlier, args.m, args.q)
        inside += hit.sum(0)
        ok_count += ok.sum(0)
        inside_given_ok += (hit & ok).sum(0)
        empties += int(res.empty.sum())
        done += size
        log(f"  {done} missions, {time.perf_counter() - t_mc:.0f} s")
    bound = res.window_probability
    freq = inside / args.missions
    ci = [wilson(int(x), args.missions) for x in inside]
    rec["monte_carlo"] = {
        "missions": args.missions, "q": args.q, "m": args.m, "time_s": time.perf_counter() - t_mc,
        "empty_steps_total": empties,
        "containment_frequency": freq.tolist(),
        "containment_ci95_lo": [c[0] for c in ci], "containment_ci95_hi": [c[1] for c in ci],
        "window_probability_bound": bound.tolist(),
        "all_windows_ok_frequency": (ok_count / args.missions).tolist(),
        "inside_when_all_windows_ok": int(inside_given_ok.sum()),
        "all_windows_ok_pairs": int(ok_count.sum()),
        "min_containment": float(freq.min()), "step_of_min": int(freq.argmin()),
        "steps_below_bound": int(np.count_nonzero(freq < bound)),
        "steps_ci_upper_below_bound": int(np.count_nonzero(
            np.array([c[1] for c in ci]) < bound)),
    }
    rec["loadavg_end"] = os.getloadavg()
    emit(rec, args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
