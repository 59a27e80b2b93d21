"""Distributed benchmark (boundest.parallel on a Dask LocalCluster on loopback): a paving of at
least 10^6 boxes and a batch of simulated satellite trajectories, in-process and on 1 and 2
worker processes (1 thread each), with the overhead per task and the data sizes from which
docs/distributed.md projects the time on 10 and 100 workers.

- Paving: ``sivia`` of the shell ``1 <= x^2 + y^2 + z^2 + 0.5 x y <= 4`` in ``[-3, 3]^3`` at
  ``--eps``, cut into ``--tasks`` parts once the frontier holds ``--split`` boxes. Checked: the
  boxes on the cluster are the in-process ones (``Subpaving.sorted``), and 1 and 2 workers give
  the same arrays in the same order.
- Batch: ``--trajectories`` trajectories of the satellite of Jaulin 2002
  (``scenarios.satellite.simulate(--kmax, seed=i)``), each estimated by ``solve`` (the CSP's
  fixed point), through ``parallel.run_batch``. Checked: same table in-process and on 1 and 2
  workers, and every true state inside its enclosure.
- Dask's nannies start workers with ``MALLOC_TRIM_THRESHOLD_=65536``, which makes glibc map
  and unmap every large NumPy temporary (the kernels' working arrays): the same paving task ran
  30-40 % slower in such a worker than in-process. The benchmark removes it from the
  workers' environment unless ``--dask-malloc-trim`` is given (docs/distributed.md).
- Overhead: ``o_task`` = (workers x wall of the tasks - seconds the tasks computed) / tasks,
  i.e. scheduling, serialisation, transfers and idle time charged to each task; also the
  round trip of empty tasks and pickle sizes and times of one task's input and output.

Each worker runs one small paving and one trajectory first (loading the Numba kernels from the
disk cache); that warm-up is reported, not timed with the runs. Times are medians of
``--repeat`` runs; the clusters of 1 and 2 workers are alive together and the runs alternate
(in-process, 1, 2, in-process, ...), so that a drift of the shared machine's load hits every
configuration alike (``speedup_2_vs_1.per_repeat`` has the ratio of each repeat). Key ``0`` of
``workers`` is the in-process run.

Usage::

    flock /tmp/boundest-bench.lock .venv/bin/python benchmarks/bench_distributed.py \\
        [--out benchmarks/results/distributed.json] [--eps 0.018] [--trajectories 200]

JSON goes to stdout (and to ``--out``); progress goes to stderr.
"""

from __future__ import annotations

import argparse
import os
import pickle
import platform
import sys
import time
from typing import Any

import numpy as np
from _machine import cpu_model, emit


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def satellite_row(seed: int, k_max: int = 200) -> dict:
    """One simulated satellite trajectory and its enclosures."""
    from boundest.scenarios import satellite as sat

    truth, meas = sat.simulate(k_max, seed=seed)
    res = sat.solve(meas, progress=False, mode="hc4")  # the batch measured: hull consistency
    return {"seed": seed, "x_lo": res.x_lo, "x_hi": res.x_hi, "consistent": res.consistent,
            "truth_inside": bool(((res.x_lo <= truth) & (truth <= res.x_hi)).all())}


def _problem():
    from boundest.expr import Var
    from boundest.interval import Interval

    x, y, z = Var("x"), Var("y"), Var("z")
    return (Interval([-3, -3, -3], [3, 3, 3]),
            {"f": x**2 + y**2 + z**2 + 0.5 * x * y, "y": Interval([1], [4])})


def warm(k_max: int) -> float:
    """Load the kernels a worker needs (run there by ``client.run``); seconds taken."""
    from boundest.paving import sivia

    t0 = time.perf_counter()
    box, kw = _problem()
    sivia(box, eps=0.3, **kw)
    satellite_row(0, k_max)
    return time.perf_counter() - t0


def _noop(v: int) -> int:
    return v


def _pickled(obj: Any) -> dict:
    t0 = time.perf_counter()
    data = pickle.dumps(obj, protocol=5)
    t1 = time.perf_counter()
    pickle.loads(data)
    return {"bytes": len(data), "dumps_s": t1 - t0, "loads_s": time.perf_counter() - t1}


def _same_paving(a, b) -> bool:
    return (np.array_equal(a.boxes.lo, b.boxes.lo) and np.array_equal(a.boxes.hi, b.boxes.hi)
            and np.array_equal(a.inside, b.inside))


#: what the projection assumes of a real cluster's network (10 GbE, to the client)
NETWORK_BYTES_PER_S = 1.0e9


def project(rec: dict, workers: tuple[int, ...] = (1, 2, 10, 100)) -> dict:
    """Projected wall-clock time on ``workers`` single-threaded workers, from the measured
    per-task costs and data sizes (docs/distributed.md explains the model)."""
    two = rec["workers"]["2"]
    pv, bt = two["paving"], two["batch"]
    one = rec["workers"]["1"]
    out: dict = {"network_bytes_per_s": NETWORK_BYTES_PER_S, "paving": {}, "batch": {}}
    # paving: serial head and merge, the result sent to the client, the tasks' CPU work
    # spread over the workers, plus the largest task (parts differ in size), plus the
    # per-task overhead, and never faster than the scheduler's task rate
    work = one["paving"]["task_cpu_s_total"]
    ratio = pv["task_compute_s_max"] / (pv["task_compute_s_total"] / pv["tasks"])
    sched = two["noop_task_s"]
    for w in workers:
        best = None
        for tasks in (64, 128, 256, 512, 1024, 2048):  # the best cut for w workers
            biggest = ratio * work / tasks
            t = (pv["head_s"] + pv["merge_s"]
                 + rec["paving"]["result_bytes"] / NETWORK_BYTES_PER_S
                 + max(work / w + biggest + -(-tasks // w) * max(pv["overhead_per_task_s"], 0.0),
                       tasks * sched))
            if best is None or t < best["time_s"]:
                best = {"tasks": tasks, "time_s": t}
        out["paving"][str(w)] = best
    n = rec["batch"]["trajectories"]
    per_row = one["batch"]["task_cpu_s_total"] / n
    for w in workers:
        chunk = max(1, -(-n // (4 * w)))
        tasks = -(-n // chunk)
        t = (-(-tasks // w) * (chunk * per_row + max(bt["overhead_per_task_s"], 0.0))
             + n * rec["batch"]["row_bytes"] / NETWORK_BYTES_PER_S)
        out["batch"][str(w)] = {"tasks": tasks, "chunk": chunk,
                                "time_s": max(t, tasks * sched)}
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out")
    ap.add_argument("--eps", type=float, default=0.018)
    ap.add_argument("--split", type=int, default=16384)
    ap.add_argument("--tasks", type=int, default=64)
    ap.add_argument("--trajectories", type=int, default=200)
    ap.add_argument("--kmax", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--workers", default="1,2")
    ap.add_argument("--reproject", metavar="JSON",
                    help="only recompute the projection of an earlier run's JSON file")
    ap.add_argument("--dask-malloc-trim", action="store_true",
                    help="keep Dask's default MALLOC_TRIM_THRESHOLD_=65536 in the workers")
    args = ap.parse_args()
    if args.reproject:
        import json
        from pathlib import Path

        rec = json.loads(Path(args.reproject).read_text())
        rec["projection"] = project(rec)
        emit(rec, args.reproject)
        return 0

    import dask
    from distributed import Client, LocalCluster

    if not args.dask_malloc_trim:  # docs/distributed.md: it slowed a paving task by 30-40 %
        env = dict(dask.config.get("distributed.nanny.pre-spawn-environ"))
        env.pop("MALLOC_TRIM_THRESHOLD_", None)
        dask.config.set({"distributed.nanny.pre-spawn-environ": env})

    from boundest.parallel import map_chunked, run_batch
    from boundest.paving import sivia
    from boundest.paving.sivia import _pave, _PavePart, separators

    rec: dict[str, Any] = {
        "benchmark": "distributed", "started": time.strftime("%Y-%m-%dT%H:%M:%S"),
        "machine": {"cpu": cpu_model(), "cores": os.cpu_count(),
                    "python": platform.python_version()},
        "loadavg_start": os.getloadavg(), "args": vars(args),
        "worker_environ": dict(dask.config.get("distributed.nanny.pre-spawn-environ"))}
    box, kw = _problem()
    row = lambda s: satellite_row(s, args.kmax)  # noqa: E731  (pickled by value by Dask)
    seeds = list(range(args.trajectories))

    log("in-process reference ...")
    warm(args.kmax)
    ref = sivia(box, eps=args.eps, **kw)
    ref_sorted = ref.sorted()
    paving = {"boxes": len(ref), "inside": int(ref.inside.sum()), "stats": ref.stats,
              "result_bytes": ref.boxes.lo.nbytes * 2 + ref.inside.nbytes}
    ref_table = run_batch(row, seeds, progress=False)
    batch = {"trajectories": len(seeds), "k_max": args.kmax,
             "all_consistent": bool(ref_table["consistent"].all()),
             "all_truth_inside": bool(ref_table["truth_inside"].all()),
             "row_bytes": len(pickle.dumps(ref_table.columns["x_lo"][0])) * 2}

    # serialisation of one paving task's input and output, measured here
    ci, co = separators(kw["f"], kw["y"])
    part_kw = {"test": None, "ctc_in": ci, "ctc_out": co, "eps": args.eps,
               "keep_outside": False, "batch": 16384}
    head = _pave(box.reshape(1, 3).copy(), split=args.split, **part_kw)
    first = head.frontier[: max(1, head.frontier.shape[0] // args.tasks)]
    run = _PavePart(part_kw)(first)
    paving["task_input"] = _pickled((_PavePart(part_kw), first))
    paving["task_output"] = _pickled(run)
    paving["task_output"]["boxes"] = sum(b.shape[0] for b in run.inside + run.boundary)

    # every configuration is alive at once and the runs alternate (in-process, 1 worker,
    # 2 workers, ...): the machine is shared, and its load drifts over minutes
    counts = [int(v) for v in args.workers.split(",")]
    clusters, execs, results = {}, {}, {}
    for w in counts:
        clusters[w] = LocalCluster(n_workers=w, threads_per_worker=1, processes=True,
                                   host="127.0.0.1", dashboard_address=None)
        client = Client(clusters[w])
        execs[w] = client.get_executor()
        st: dict = {}
        results[w] = {"warmup_s": client.run(warm, args.kmax)}
        map_chunked(_noop, range(400), execs[w], chunk=1, stats=st)  # scheduling alone
        results[w]["noop_task_s"] = st["wall_s"] / 400
    runs: dict = {"paving": {w: [] for w in [0, *counts]}, "batch": {w: [] for w in [0, *counts]}}
    last = {}
    for r in range(args.repeat):
        for w in [0, *counts]:
            t0 = time.perf_counter()
            got = sivia(box, eps=args.eps, executor=execs.get(w), split=args.split,
                        tasks=args.tasks, **kw)
            runs["paving"][w].append((time.perf_counter() - t0, got.stats.get("parallel")))
            last[w] = got
            log(f"  repeat {r}: paving, {w} workers: {runs['paving'][w][-1][0]:.2f} s")
        for w in [0, *counts]:
            st = {}
            t0 = time.perf_counter()
            table = run_batch(row, seeds, execs.get(w), progress=False, stats=st)
            runs["batch"][w].append((time.perf_counter() - t0, st))
            log(f"  repeat {r}: batch, {w} workers: {runs['batch'][w][-1][0]:.2f} s")
            if w and not all(np.array_equal(table[k], ref_table[k]) for k in ref_table):
                raise AssertionError(f"the batch on {w} workers differs from in-process")
    for w in [0, *counts]:
        pv_times = [t for t, _ in runs["paving"][w]]
        bt_times = [t for t, _ in runs["batch"][w]]
        i = int(np.argsort(pv_times)[len(pv_times) // 2])
        k = int(np.argsort(bt_times)[len(bt_times) // 2])
        entry = results.setdefault(w, {})
        entry["paving"] = {"median_s": pv_times[i], "runs_s": pv_times}
        entry["batch"] = {"median_s": bt_times[k], "runs_s": bt_times}
        if not w:
            continue
        par = runs["paving"][w][i][1]
        compute = float(sum(par["task_s"]))
        entry["paving"] |= {
            "tasks": par["tasks"], "split_at": par["split_at"], "head_s": par["head_s"],
            "map_s": par["map_s"], "merge_s": par["merge_s"], "task_compute_s_total": compute,
            "task_cpu_s_total": float(sum(par["task_cpu_s"])),
            "task_compute_s_max": float(max(par["task_s"])),
            "overhead_per_task_s": (w * par["map_s"] - compute) / par["tasks"],
            "same_boxes_as_in_process": _same_paving(last[w].sorted(), ref_sorted)}
        st = runs["batch"][w][k][1]
        compute = float(sum(st["compute_s"]))
        entry["batch"] |= {"tasks": st["tasks"], "chunk": st["chunk"],
                           "task_compute_s_total": compute,
                           "task_cpu_s_total": float(sum(st["cpu_s"])),
                           "overhead_per_task_s": (w * st["wall_s"] - compute) / st["tasks"]}
    for w in counts:
        execs[w]._client.close()
        clusters[w].close()
    results = {str(w): v for w, v in results.items()}
    if "1" in results and "2" in results:
        ratio = {kind: [a[0] / b[0] for a, b in zip(runs[kind][1], runs[kind][2], strict=True)]
                 for kind in ("paving", "batch")}
        rec["speedup_2_vs_1"] = {
            kind: results["1"][kind]["median_s"] / results["2"][kind]["median_s"]
            for kind in ("paving", "batch")} | {"per_repeat": ratio}
        rec["same_order_1_and_2_workers"] = _same_paving(last[1], last[2])
        log(f"speed-up 2 vs 1 workers: {rec['speedup_2_vs_1']}")
    rec["paving"] = paving
    rec["batch"] = batch
    rec["workers"] = results
    if "1" in results and "2" in results:
        rec["projection"] = project(rec)
    rec["loadavg_end"] = os.getloadavg()
    emit(rec, args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
