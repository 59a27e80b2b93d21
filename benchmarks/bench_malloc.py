"""What glibc's heap thresholds cost the solvers: ``boundest._malloc`` against the default.

Each run is a fresh process that imports boundest, solves once (loading the kernels), then
times ``--repeat`` warm solves, reading user and system CPU time (``os.times``) and the peak
resident memory (``ru_maxrss``). ``default`` sets ``BOUNDEST_MALLOC=default`` (glibc's dynamic
thresholds); ``tuned`` is what the ``boundest`` command does for its process and what
``boundest.keep_freed_memory()`` does for a library user (trim threshold 256 MiB, mmap
threshold 32 MiB). The two alternate, ``--rounds`` times each, so that both see the same
load of this shared machine; the table gives the medians over all warm solves.

Usage::

    flock /tmp/boundest-bench.lock .venv/bin/python benchmarks/bench_malloc.py \\
        --out benchmarks/results/malloc.json
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _machine import cpu_model, emit

CHILD = r"""
import json, os, resource, sys, time
import boundest
boundest.keep_freed_memory()  # does nothing under BOUNDEST_MALLOC=default
case, repeat = sys.argv[1], int(sys.argv[2])
if case == "range_only":
    from boundest.scenarios import range_only as m
    run = lambda: m.solve(dt=0.01, progress=False)
elif case == "satellite":
    from boundest.scenarios import satellite as m
    meas = m.load()
    run = lambda: m.solve(meas, progress=False)
elif case == "pool":
    from boundest.scenarios import pool, pool_data
    data = pool_data.load_pool()
    run = lambda: pool.solve_pool(data, 8, 80)
run()
rows = []
for _ in range(repeat):
    a, t = os.times(), time.perf_counter()
    run()
    b = os.times()
    rows.append({"wall_s": time.perf_counter() - t, "user_s": b.user - a.user,
                 "sys_s": b.system - a.system})
print(json.dumps({"runs": rows,
                  "maxrss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def _child(case: str, mode: str, repeat: int) -> dict:
    env = dict(os.environ)
    env.pop("BOUNDEST_MALLOC", None)
    if mode == "default":
        env["BOUNDEST_MALLOC"] = "default"
    out = subprocess.run([sys.executable, "-c", CHILD, case, str(repeat)], env=env, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--cases", default="range_only,satellite,pool")
    p.add_argument("--rounds", type=int, default=3, help="processes per mode and case")
    p.add_argument("--repeat", type=int, default=5, help="warm solves per process")
    p.add_argument("--out", help="write the JSON document to this file")
    args = p.parse_args()
    doc: dict = {"machine": {"cpu_model": cpu_model(), "cpu_count": os.cpu_count(),
                             "loadavg_start": list(os.getloadavg())},
                 "rounds": args.rounds, "repeat": args.repeat, "cases": {}}
    for case in [c for c in args.cases.split(",") if c]:
        runs: dict[str, list] = {"default": [], "tuned": []}
        rss: dict[str, list] = {"default": [], "tuned": []}
        for _ in range(args.rounds):
            for mode in ("default", "tuned"):
                res = _child(case, mode, args.repeat)
                runs[mode] += res["runs"]
                rss[mode].append(res["maxrss_mib"])
        row = {}
        for mode in runs:
            row[mode] = {k: statistics.median(r[k] for r in runs[mode])
                         for k in ("wall_s", "user_s", "sys_s")}
            row[mode]["maxrss_mib"] = max(rss[mode])
            row[mode]["walls_s"] = [r["wall_s"] for r in runs[mode]]
        row["speedup"] = row["default"]["wall_s"] / row["tuned"]["wall_s"]
        doc["cases"][case] = row
        print(f"{case}: default {row['default']['wall_s']:.3f} s (sys "
              f"{row['default']['sys_s']:.2f}, {row['default']['maxrss_mib']:.0f} MiB), tuned "
              f"{row['tuned']['wall_s']:.3f} s (sys {row['tuned']['sys_s']:.2f}, "
              f"{row['tuned']['maxrss_mib']:.0f} MiB): x{row['speedup']:.2f}", file=sys.stderr)
    doc["machine"]["loadavg_end"] = list(os.getloadavg())
    emit(doc, args.out)


if __name__ == "__main__":
    main()
