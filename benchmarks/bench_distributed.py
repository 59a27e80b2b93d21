"""Distributed benchmark (boundest.parallel on a Dask LocalCluster on loopback): pavings of
at least 10^6 boxes and a batch of simulated satellite trajectories, in-process and on 1 and 2
worker processes (1 thread each), with the overhead per task and the data sizes from which
docs/distributed.md projects the time on 10 and 100 workers.

- Pavings (``sivia``, cut into ``--tasks`` parts once the frontier holds ``--split`` boxes):
  ``shell``, ``1 <= x^2 + y^2 + z^2 + 0.5 x y <= 4`` in ``[-3, 3]^3`` at eps 0.018 (one
  constraint: about 2 us of work per box, so the 48 bytes a box sent back weigh most), and
  ``beacons``, a 3-D position from six squared ranges to beacons, each known to +-0.5 m, in
  ``[-2, 12]^3`` at eps 0.004 (six constraints: about 6 us per box for the same bytes).
  Checked: the boxes on the cluster are the in-process ones (``Subpaving.sorted``), and 1 and 2
  workers give the same arrays in the same order.
- Batch: ``--trajectories`` trajectories of the satellite of Jaulin 2002
  (``scenarios.satellite.simulate(--kmax, seed=i)``), each estimated by ``solve`` (the CSP's
  fixed point), through ``parallel.run_batch``. Checked: same table in-process and on 1 and 2
  workers, and every true state inside its enclosure.
- Dask settings (docs/distributed.md), each measured here and kept at Dask's default by
  ``--dask-defaults``: the nannies start workers with ``MALLOC_TRIM_THRESHOLD_=65536``, which
  makes glibc map and unmap every large NumPy temporary (a paving task ran 30-40 % slower);
  every process checks its event loop every 20 ms, monitors memory every 100 ms and the system
  every 500 ms, the scheduler balances work every 100 ms, and the workers sample their threads'
  stacks every 10 ms for the dashboard's profile (under the GIL): an idle LocalCluster of 2
  workers burnt 11 % of a core with Dask's defaults and 1.3 % with ``DASK_SETTINGS``, CPU
  taken from the workers on a 2-core machine.
- The cost of cutting: the parts of the frontier are paved with smaller batches, so more
  tasks mean more work. Each paving is also run part after part in this process for several
  task counts (``split_cost``), which the projection uses.
- Overhead: ``o_task`` = (workers x wall of the tasks - seconds the tasks computed) / tasks,
  i.e. scheduling, serialisation, transfers and idle time charged to each task; also the
  round trip of empty tasks and pickle sizes and times of one task's input and output.

Each worker runs small pavings and one trajectory first (loading the Numba kernels from the
disk cache); that warm-up is reported, not timed with the runs. Times are medians of
``--repeat`` runs (``--batch-repeat`` for the batch, which takes minutes); the clusters of 1 and
2 workers are alive together and the runs alternate (in-process, 1, 2, in-process, ...), so
that a drift of the shared machine's load hits every configuration alike
(``speedup_2_vs_1.per_repeat`` has the ratio of each repeat). Key ``0`` of ``workers`` is the
in-process run.

Usage::

    flock /tmp/boundest-bench.lock .venv/bin/python benchmarks/bench_distributed.py \\
        [--out benchmarks/results/distributed.json] [--trajectories 200]

JSON goes to stdout (and to ``--out``); progress goes to stderr.
"""

from __future__ import annotations

import argparse
import os
import pickle
import platform
import sys
import time
from concurrent.futures import Executor, Future
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


def _shell():
    from boundest.expr import Var
    from boundest.interval import Interval

    x, y, z = Var("x"), Var("y"), Var("z")
    return (Interval([-3, -3, -3], [3, 3, 3]),
            {"f": x**2 + y**2 + z**2 + 0.5 * x * y, "y": Interval([1], [4])})


#: the beacons of the ``beacons`` paving, and the position their ranges were measured from
BEACONS = ((0, 0, 0), (10, 0, 0), (0, 10, 0), (10, 10, 0), (5, 5, 8), (0, 5, 6))
BEACON_POSITION = (4.0, 3.0, 2.0)


def _beacons():
    from boundest.expr import Var
    from boundest.interval import Interval

    x, y, z = Var("x"), Var("y"), Var("z")
    fs, lo, hi = [], [], []
    for a in BEACONS:
        d = float(np.linalg.norm(np.subtract(BEACON_POSITION, a)))
        fs.append((x - a[0]) ** 2 + (y - a[1]) ** 2 + (z - a[2]) ** 2)
        lo.append((d - 0.5) ** 2)
        hi.append((d + 0.5) ** 2)
    return Interval([-2, -2, -2], [12, 12, 12]), {"f": fs, "y": Interval(lo, hi)}


#: name -> (box and sivia's f and y, eps)
PROBLEMS = {"shell": (_shell, 0.018), "beacons": (_beacons, 0.004)}

#: Dask settings for a small machine (the module's docstring and docs/distributed.md)
DASK_SETTINGS = {"distributed.worker.profile.enabled": False,
                 "distributed.admin.tick.interval": "1s",
                 "distributed.admin.system-monitor.interval": "5s",
                 "distributed.worker.memory.monitor-interval": "1s",
                 "distributed.scheduler.work-stealing-interval": "1s"}


def warm(k_max: int) -> float:
    """Load the kernels a worker needs (run there by ``client.run``); seconds taken."""
    from boundest.paving import sivia

    t0 = time.perf_counter()
    for make, _ in PROBLEMS.values():
        box, kw = make()
        sivia(box, eps=0.5, **kw)
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


class _InProcess(Executor):
    """Runs each task at once in this process (the parts one after the other)."""

    def submit(self, fn, /, *args, **kwargs):
        fut: Future = Future()
        fut.set_result(fn(*args, **kwargs))
        return fut


def split_cost(box, kw: dict, eps: float, split: int, counts=(1, 16, 64, 256),
               repeat: int = 1) -> dict:
    """Seconds (wall and CPU; median of ``repeat``) of the paving cut into ``counts`` parts
    paved one after the other in this process: what cutting finer costs in work, without any
    transfer."""
    from boundest.paving import sivia

    out = {}
    for tasks in counts:
        wall, cpu = [], []
        for _ in range(repeat):
            t0, c0 = time.perf_counter(), time.process_time()
            sivia(box, eps=eps, executor=_InProcess() if tasks > 1 else None, split=split,
                  tasks=tasks, **kw)
            wall.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
        out[str(tasks)] = {"wall_s": float(np.median(wall)), "cpu_s": float(np.median(cpu))}
    return out


def _same_paving(a, b) -> bool:
    return (np.array_equal(a.boxes.lo, b.boxes.lo) and np.array_equal(a.boxes.hi, b.boxes.hi)
            and np.array_equal(a.inside, b.inside))


#: what the projection assumes of a real cluster's network (10 GbE, to the client)
NETWORK_BYTES_PER_S = 1.0e9


def project(rec: dict, workers: tuple[int, ...] = (1, 2, 10, 100)) -> dict:
    """Projected wall-clock time on ``workers`` single-threaded workers, from the measured
    per-task costs and data sizes (docs/distributed.md explains the model)."""
    one, two = rec["workers"]["1"], rec["workers"]["2"]
    sched = two["noop_task_s"]
    out: dict = {"network_bytes_per_s": NETWORK_BYTES_PER_S, "paving": {}, "batch": {}}
    # paving: serial head and merge, the result sent to the client, the tasks' CPU work
    # spread over the workers, plus the largest task (parts differ in size), plus the
    # per-task overhead, and never faster than the scheduler's task rate. The work grows with
    # the number of parts (smaller batches): the CPU seconds measured on 1 worker with the
    # benchmark's cut, scaled by the in-process cost of each other cut (``split_cost``).
    for name, prob in rec["paving"].items():
        pv = two["paving"][name]
        cost, measured = prob["split_cost"], str(pv["tasks"])
        ratio = pv["task_compute_s_max"] / (pv["task_compute_s_total"] / pv["tasks"])
        base = one["paving"][name]["task_cpu_s_total"] / cost[measured]["cpu_s"]
        out["paving"][name] = {}
        for w in workers:
            best = None
            for key in cost:
                tasks = int(key)
                if tasks < 2:  # "1" is the paving without a cut
                    continue
                busy = min(w, tasks)  # with fewer tasks than workers, some idle
                work = base * cost[key]["cpu_s"]
                t = (pv["head_s"] + pv["merge_s"] + prob["result_bytes"] / NETWORK_BYTES_PER_S
                     + max(work / busy + ratio * work / tasks
                           + -(-tasks // busy) * max(pv["overhead_per_task_s"], 0.0),
                           tasks * sched))
                if best is None or t < best["time_s"]:
                    best = {"tasks": tasks, "time_s": t}
            out["paving"][name][str(w)] = best
    bt = two["batch"]
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


def _median_index(times: list[float]) -> int:
    return int(np.argsort(times)[len(times) // 2])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out")
    ap.add_argument("--pavings", default=",".join(PROBLEMS),
                    help=f"which pavings (of {', '.join(PROBLEMS)})")
    ap.add_argument("--split", type=int, default=16384)
    ap.add_argument("--tasks", type=int, default=16)
    ap.add_argument("--trajectories", type=int, default=200)
    ap.add_argument("--kmax", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=11, help="runs of each paving")
    ap.add_argument("--batch-repeat", type=int, default=3, help="runs of the batch")
    ap.add_argument("--workers", default="1,2")
    ap.add_argument("--reproject", metavar="JSON",
                    help="only recompute the projection of an earlier run's JSON file")
    ap.add_argument("--dask-defaults", action="store_true",
                    help="keep Dask's defaults (MALLOC_TRIM_THRESHOLD_=65536 in the workers, "
                         "the profiler and the frequent monitors) instead of DASK_SETTINGS")
    args = ap.parse_args()
    if args.reproject:
        import json
        from pathlib import Path

        rec = json.loads(Path(args.reproject).read_text())
        rec["projection"] = project(rec)
        emit(rec, args.reproject)
        return 0
    names = [v for v in args.pavings.split(",") if v]
    unknown = [v for v in names if v not in PROBLEMS]
    if unknown:
        ap.error(f"unknown paving {unknown[0]!r} (known: {', '.join(PROBLEMS)})")

    import dask
    import distributed  # noqa: F401  (registers the distributed.* settings)
    from distributed import Client, LocalCluster

    if not args.dask_defaults:
        env = dict(dask.config.get("distributed.nanny.pre-spawn-environ"))
        env.pop("MALLOC_TRIM_THRESHOLD_", None)
        dask.config.set({"distributed.nanny.pre-spawn-environ": env, **DASK_SETTINGS})

    from boundest.parallel import map_chunked, run_batch
    from boundest.paving import sivia
    from boundest.paving.sivia import _pave, _PavePart, separators

    rec: dict[str, Any] = {
        "benchmark": "distributed", "started": time.strftime("%Y-%m-%dT%H:%M:%S"),
        "machine": {"cpu": cpu_model(), "cores": os.cpu_count(),
                    "python": platform.python_version(), "dask": dask.__version__},
        "loadavg_start": os.getloadavg(), "args": vars(args),
        "dask_settings": {"worker_environ": dict(dask.config.get(
            "distributed.nanny.pre-spawn-environ"))}
        | {k: dask.config.get(k) for k in DASK_SETTINGS}}
    row = lambda s: satellite_row(s, args.kmax)  # noqa: E731  (pickled by value by Dask)
    seeds = list(range(args.trajectories))

    log("in-process references ...")
    warm(args.kmax)
    problems, refs, pavings = {}, {}, {}
    for name in names:
        make, eps = PROBLEMS[name]
        box, kw = make()
        problems[name] = (box, kw, eps)
        ref = sivia(box, eps=eps, **kw)
        refs[name] = ref.sorted()
        # serialisation of one paving task's input and output, measured here
        ci, co = separators(kw["f"], kw["y"])
        part_kw = {"test": None, "ctc_in": ci, "ctc_out": co, "eps": eps,
                   "keep_outside": False, "batch": 16384}
        head = _pave(box.reshape(1, 3).copy(), split=args.split, **part_kw)
        first = head.frontier[: max(1, head.frontier.shape[0] // args.tasks)]
        run = _PavePart(part_kw)(first)
        log(f"the cost of cutting the {name} paving: its parts one after the other here ...")
        pavings[name] = {
            "eps": eps, "boxes": len(ref), "inside": int(ref.inside.sum()), "stats": ref.stats,
            "result_bytes": ref.boxes.lo.nbytes * 2 + ref.inside.nbytes,
            "task_input": _pickled((_PavePart(part_kw), first)),
            "task_output": _pickled(run) | {
                "boxes": sum(b.shape[0] for b in run.inside + run.boundary)},
            "split_cost": split_cost(box, kw, eps, args.split)}
    ref_table = run_batch(row, seeds, progress=False)
    batch = {"trajectories": len(seeds), "k_max": args.kmax,
             "all_consistent": bool(ref_table["consistent"].all()),
             "all_truth_inside": bool(ref_table["truth_inside"].all()),
             "row_bytes": len(pickle.dumps(ref_table.columns["x_lo"][0])) * 2}

    # every configuration is alive at once and the runs alternate (in-process, 1 worker,
    # 2 workers, ...): the machine is shared, and its load drifts over minutes
    counts = [int(v) for v in args.workers.split(",")]
    configs = [0, *counts]
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
    runs: dict = {name: {w: [] for w in configs} for name in names}
    runs["batch"] = {w: [] for w in configs}
    last: dict = {name: {} for name in names}
    for r in range(max(args.repeat, args.batch_repeat)):
        for name in names if r < args.repeat else ():
            box, kw, eps = problems[name]
            for w in configs:
                t0 = time.perf_counter()
                got = sivia(box, eps=eps, executor=execs.get(w), split=args.split,
                            tasks=args.tasks, **kw)
                runs[name][w].append((time.perf_counter() - t0, got.stats.get("parallel")))
                last[name][w] = got
                log(f"  repeat {r}: {name} paving, {w} workers: {runs[name][w][-1][0]:.2f} s")
        for w in configs if r < args.batch_repeat else ():
            st = {}
            t0 = time.perf_counter()
            table = run_batch(row, seeds, execs.get(w), progress=False, stats=st)
            runs["batch"][w].append((time.perf_counter() - t0, st))
            log(f"  repeat {r}: batch, {w} workers: {runs['batch'][w][-1][0]:.2f} s")
            if w and not all(np.array_equal(table[k], ref_table[k]) for k in ref_table):
                raise AssertionError(f"the batch on {w} workers differs from in-process")
    for w in configs:
        entry = results.setdefault(w, {})
        entry["paving"] = {}
        for name in names:
            times = [t for t, _ in runs[name][w]]
            i = _median_index(times)
            pv = entry["paving"][name] = {"median_s": times[i], "runs_s": times}
            if not w:
                continue
            par = runs[name][w][i][1]
            compute = float(sum(par["task_s"]))
            pv |= {"tasks": par["tasks"], "split_at": par["split_at"], "head_s": par["head_s"],
                   "map_s": par["map_s"], "merge_s": par["merge_s"],
                   "task_compute_s_total": compute,
                   "task_cpu_s_total": float(sum(par["task_cpu_s"])),
                   "task_compute_s_max": float(max(par["task_s"])),
                   "overhead_per_task_s": (w * par["map_s"] - compute) / par["tasks"],
                   "same_boxes_as_in_process": _same_paving(last[name][w].sorted(),
                                                            refs[name])}
        times = [t for t, _ in runs["batch"][w]]
        k = _median_index(times)
        entry["batch"] = {"median_s": times[k], "runs_s": times}
        if not w:
            continue
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
        kinds = [*names, "batch"]
        one, two = results["1"], results["2"]
        rec["speedup_2_vs_1"] = (
            {name: one["paving"][name]["median_s"] / two["paving"][name]["median_s"]
             for name in names}
            | {"batch": one["batch"]["median_s"] / two["batch"]["median_s"],
               "per_repeat": {kind: [a[0] / b[0] for a, b in
                                     zip(runs[kind][1], runs[kind][2], strict=True)]
                              for kind in kinds}})
        rec["same_order_1_and_2_workers"] = {name: _same_paving(last[name][1], last[name][2])
                                             for name in names}
        log(f"speed-up 2 vs 1 workers: {rec['speedup_2_vs_1']}")
    rec["paving"] = pavings
    rec["batch"] = batch
    rec["workers"] = results
    if "1" in results and "2" in results:
        rec["projection"] = project(rec)
    rec["loadavg_end"] = os.getloadavg()
    emit(rec, args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
