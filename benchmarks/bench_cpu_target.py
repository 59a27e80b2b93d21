"""What the kernel archive's generic CPU target costs at run time against the host target.

The shipped kernels (``boundest._kernels``) are compiled for LLVM's ``x86-64-v3`` (AVX2, FMA,
BMI; no AVX-512), so that one archive serves every x86-64 machine; a kernel compiled on the
machine itself targets its own CPU (``llvmlite.binding.get_host_cpu_name()`` and all its
features). This times the same computations with both, warm and in process: each target runs
in its own process (Numba fixes the target per process) with its own cache folder, calls each
workload once (loading or compiling its kernels), then ``--repeat`` times, timed; the rounds
alternate host, generic, host, generic... (``--rounds``) so that a change of load hits both.

Workloads: the satellite's propagation (``scenarios.satellite.solve``, k_max = 200), the
range-only robot's tube network (``scenarios.range_only.solve``), the pool robot's observer
(``scenarios.pool.solve_pool``, one smoothing sweep as ``boundest run pool``).

    flock /tmp/boundest-bench.lock .venv/bin/python benchmarks/bench_cpu_target.py \\
        --out benchmarks/results/cpu_target.json [--repeat 5] [--rounds 2] [--cache-dir D]

The host target's first round compiles every kernel (minutes on 2 cores; not timed). JSON on
stdout (and ``--out``): per workload the median of every timed call of each target, and the
ratio generic / host (above 1: the generic target is slower).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _machine import cpu_model, emit

WORKLOADS = ("satellite", "range-only", "pool")


def _workload(name: str):
    if name == "satellite":
        from boundest.scenarios import satellite as sat

        meas = sat.load()
        return lambda: sat.solve(meas, progress=False)
    if name == "range-only":
        from boundest.scenarios import range_only as ro

        meas = ro.load()
        return lambda: ro.solve(meas, progress=False)
    if name == "pool":
        from boundest.scenarios.pool import solve_pool
        from boundest.scenarios.pool_data import load_pool

        data = load_pool()
        return lambda: solve_pool(data, sweeps=1)
    raise ValueError(name)


def worker(repeat: int) -> None:
    """In the child: time each workload, print one JSON line."""
    import boundest.interval  # noqa: F401 - sets up the kernel archive and Numba's target
    from boundest import _kernels

    out: dict = {"archive": _kernels.STATUS}
    for name in WORKLOADS:
        run = _workload(name)
        t0 = time.perf_counter()
        run()
        first = time.perf_counter() - t0
        times = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            run()
            times.append(time.perf_counter() - t0)
        out[name] = {"first_s": round(first, 3), "times_s": [round(t, 4) for t in times]}
    from numba.core import registry

    magic = registry.cpu_target.target_context.codegen().magic_tuple()
    out["cpu_name"] = magic[1]
    out["cpu_features"] = magic[2][:60] + ("..." if len(magic[2]) > 60 else "")
    print(json.dumps(out))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", help="also write the JSON to this file")
    ap.add_argument("--repeat", type=int, default=5, help="timed calls per round (default 5)")
    ap.add_argument("--rounds", type=int, default=2, help="host/generic rounds (default 2)")
    ap.add_argument("--cache-dir", help="keep the two targets' Numba caches in this folder "
                    "(default: a temporary one; the host's first round then compiles)")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        worker(args.repeat)
        return 0
    import numba

    from boundest import _kernels

    doc: dict = {"benchmark": "cpu_target", "machine": {
        "cpu": cpu_model(), "cores": os.cpu_count(), "numba": numba.__version__},
        "generic_target": _kernels.TARGET_CPU, "repeat": args.repeat, "rounds": args.rounds,
        "runs": []}
    samples: dict = {t: {w: [] for w in WORKLOADS} for t in ("host", "generic")}
    with tempfile.TemporaryDirectory(prefix="bench-cpu-target-") as tmp:
        tmp = args.cache_dir or tmp
        envs = {
            "host": dict(os.environ, NUMBA_CACHE_DIR=str(Path(tmp) / "host"),
                         BOUNDEST_KERNEL_ARCHIVE="0"),
            "generic": dict(os.environ, NUMBA_CACHE_DIR=str(Path(tmp) / "generic"),
                            NUMBA_CPU_NAME=_kernels.TARGET_CPU,
                            NUMBA_CPU_FEATURES=_kernels.TARGET_FEATURES)}
        for var in ("NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES"):  # the host's own CPU
            envs["host"].pop(var, None)
        for r in range(args.rounds):
            for target in ("host", "generic"):
                before = os.getloadavg()[0]
                p = subprocess.run([sys.executable, __file__, "--worker", "--repeat",
                                    str(args.repeat)], env=envs[target], capture_output=True,
                                   text=True, check=False, timeout=3600)
                if p.returncode:
                    print(p.stderr[-3000:], file=sys.stderr)
                    return 1
                res = json.loads(p.stdout.strip().splitlines()[-1])
                res.update(target=target, round=r, loadavg_before=before,
                           loadavg_after=os.getloadavg()[0])
                doc["runs"].append(res)
                for w in WORKLOADS:
                    samples[target][w] += res[w]["times_s"]
                print(f"round {r} {target:<8} ({res['cpu_name']}, archive {res['archive']}, "
                      f"load {before:.2f}): " + ", ".join(
                          f"{w} {statistics.median(res[w]['times_s']):.3f} s"
                          for w in WORKLOADS), file=sys.stderr, flush=True)
    doc["median_s"] = {w: {t: round(statistics.median(samples[t][w]), 4)
                           for t in ("host", "generic")} for w in WORKLOADS}
    doc["ratio_generic_over_host"] = {
        w: round(doc["median_s"][w]["generic"] / doc["median_s"][w]["host"], 3)
        for w in WORKLOADS}
    # the ratio within each round (host and generic back to back): how much the load moved it
    per_round = {w: [] for w in WORKLOADS}
    for r in range(args.rounds):
        pair = {x["target"]: x for x in doc["runs"] if x["round"] == r}
        for w in WORKLOADS:
            per_round[w].append(round(statistics.median(pair["generic"][w]["times_s"])
                                      / statistics.median(pair["host"][w]["times_s"]), 3))
    doc["ratio_per_round"] = per_round
    for w in WORKLOADS:
        m = doc["median_s"][w]
        print(f"{w:<12} host {m['host']:.3f} s  {doc['generic_target']} {m['generic']:.3f} s  "
              f"ratio {doc['ratio_generic_over_host'][w]:.3f}", file=sys.stderr)
    emit(doc, args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
