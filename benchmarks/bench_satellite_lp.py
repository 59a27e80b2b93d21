"""Satellite (Jaulin 2002), k_max = 200, embedded data: hull consistency alone against hull
consistency alternated with LP contraction of the linear and log-linear sub-networks
(``boundest.csp.linear.propagate_lp``, Jaulin 2002 section 5.1).

Modes (each a row: mean and max width of x1 over k = 0..k_max+1, mean widths of x1..x4, time
split between propagation and LPs, rounds):

* ``hc4``                 ``propagate`` (today's default);
* ``lp-lin-r12``          + LPs over the linear rows only, each target's LP on the rows within
                          12 row-steps of it;
* ``lp-r12``              + the log-linear rows (eq. 17-19), same locality;
* ``lp-full``             + the whole connected sub-network in every LP (one HiGHS instance,
                          warm-started from objective to objective).

Targets: the 808 state variables x1..x4 at k = 0..201. Usage::

    .venv/bin/python benchmarks/bench_satellite_lp.py [--out results/satellite_lp.json]
        [--rounds 3] [--modes hc4,lp-r12]

Needs SciPy (``pip install -e '.[lp]'``). One run per mode (the LP modes take tens of seconds).
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time

import numpy as np
from _machine import cpu_model, emit

from boundest.csp import propagate
from boundest.csp.linear import propagate_lp
from boundest.expr.tape import compile_model
from boundest.scenarios import satellite

MODES = {
    "hc4": None,
    "lp-lin-r12": {"radius": 12, "log_linear": False},
    "lp-r12": {"radius": 12, "log_linear": True},
    "lp-full": {"radius": None, "log_linear": True},
}


def _widths(tape, slots_lo, slots_hi, K):
    idx = np.array([[tape.slot_of[f"x{i}_{k}"] for i in (1, 2, 3, 4)] for k in range(K + 2)])
    w = slots_hi[idx] - slots_lo[idx]
    return w


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--modes", default=",".join(MODES))
    args = ap.parse_args()
    meas = satellite.load(k_max=200)
    K = meas.k_max
    tape = compile_model(satellite.build_model(meas))
    states = [f"x{i}_{k}" for k in range(K + 2) for i in (1, 2, 3, 4)]
    propagate(tape, mode="hc4")  # load the kernels outside the timings
    rows = []
    for mode in args.modes.split(","):
        kw = MODES[mode]
        t0 = time.perf_counter()
        if kw is None:
            p = propagate(tape, mode="hc4")
            row = {"mode": mode, "time_s": time.perf_counter() - t0, "hc_time_s": p.time_s,
                   "lp_time_s": 0.0, "rounds": 0, "consistent": p.consistent}
            lo, hi = p.slots.lo, p.slots.hi
        else:
            r = propagate_lp(tape, targets=states, rounds=args.rounds, **kw)
            row = {"mode": mode, "time_s": time.perf_counter() - t0,
                   "hc_time_s": r.hc_time_s, "lp_time_s": r.lp_time_s, "rounds": r.rounds,
                   "consistent": r.consistent, "target_width_per_round": r.widths, **kw}
            lo, hi = r.slots.lo, r.slots.hi
        w = _widths(tape, lo, hi, K)
        row.update({"x1_mean_width": float(w[:, 0].mean()), "x1_max_width": float(w[:, 0].max()),
                    "x1_steps_wider_than_1": int((w[:, 0] > 1).sum()),
                    "mean_widths": w.mean(axis=0).tolist(), "x1_width": w[:, 0].tolist()})
        rows.append(row)
        print(f"{mode:12s} x1 mean {row['x1_mean_width']:.4f} max {row['x1_max_width']:.3f} "
              f"time {row['time_s']:.2f} s (lp {row['lp_time_s']:.2f}) rounds {row['rounds']}",
              file=sys.stderr)
    import scipy

    emit({"benchmark": "satellite_lp", "k_max": K, "data": "satellite_k200.csv",
          "targets": "x1..x4 at k = 0..k_max+1", "max_rounds": args.rounds,
          "exact_hull_x1_mean_width_at_least": 0.137, "rows": rows,
          "machine": {"cpu": cpu_model(), "python": platform.python_version(),
                      "scipy": scipy.__version__, "loadavg": os.getloadavg()}}, args.out)


if __name__ == "__main__":
    main()
