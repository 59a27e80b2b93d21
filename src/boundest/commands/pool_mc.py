"""``boundest run pool --monte-carlo N [--scheduler ADDRESS | --workers K]``: the Monte Carlo
check of the pool observer's claimed probability (:mod:`boundest.scenarios.pool_mc`), its
table, strict JSON and figure."""

from __future__ import annotations

import argparse
import contextlib
import os
from collections.abc import Iterator
from concurrent.futures import Executor, ProcessPoolExecutor
from pathlib import Path

from . import save_figure, subplots, write_json
from .options import announce, check_outputs, check_size, require_extra, whole

DEFAULT_CHUNK = 250
#: Memory of a task per mission of its chunk: the peak resident memory of a chunk of 200
#: missions exceeded that of 20 by 84 KiB a mission (simulated pings, truths and the observer's
#: boxes, 406 pings each; 2026-12, the development machine); rounded up
BYTES_PER_MISSION = 96 * 1024
#: The memory of a worker process besides its chunk: the interpreter, NumPy, the kernels
WORKER_BYTES = 250 << 20


def check(args: argparse.Namespace) -> None:
    """The Monte Carlo's checks before any work (``pool.check`` calls it): options that go
    together, the output paths, the Dask extra for --scheduler, and the memory of the workers
    and their chunks."""
    from .pool import announce_duration, heading_slices, observer_bytes

    if args.scheduler and args.workers is not None:
        raise ValueError(f"give either --scheduler {args.scheduler} or --workers "
                         f"{args.workers}, not both")
    if args.data:
        raise ValueError(f"--data {args.data}: --monte-carlo simulates missions of the embedded "
                         "setup; it does not read --data")
    if args.online:
        raise ValueError("--monte-carlo runs each chunk of missions offline, in one call; it "
                         "does not take --online")
    check_outputs(args.out, args.json)
    if args.scheduler:
        require_extra(f"--scheduler {args.scheduler}", "distributed", "distributed",
                      "Dask distributed")
    args.mc_chunk = DEFAULT_CHUNK if args.mc_chunk is None else args.mc_chunk
    args.mc_seed = 0 if args.mc_seed is None else args.mc_seed
    if args.scheduler:  # the memory and the time are the cluster's workers', not this machine's
        return
    chunk = min(args.mc_chunk, args.monte_carlo)
    per_task = WORKER_BYTES + observer_bytes(args.m, heading_slices(args)) \
        + chunk * BYTES_PER_MISSION
    workers = processes(args) or 1
    option = (f"--mc-chunk {args.mc_chunk}" if workers == 1 else
              f"--workers {args.workers} --mc-chunk {args.mc_chunk}")
    check_size(workers * per_task, f"{workers} process(es) at a time, each on a chunk of "
               f"{chunk:,} missions", option)
    # after the memory: a run refused for its memory is not announced first
    announce_duration(0 if args.sweeps is None else args.sweeps, args.monte_carlo, workers)
    cores = os.cpu_count() or 1
    if workers > cores:
        announce(f"--workers {args.workers}: {workers} worker processes for the {cores} cores "
                 "of this machine: they take turns")


def tasks_for(missions: int, chunk: int, workers: int, local: bool = True) -> tuple[int, str]:
    """The missions per task, and why they differ from ``chunk`` (empty: they do not):
    chunks of ``chunk`` missions, cut smaller when there would be fewer tasks than ``workers``,
    so that every worker gets a part; with fewer missions than workers, one mission per task
    (``local``: the local pool then starts one process per mission, see :func:`processes`)."""
    tasks = -(-missions // chunk)
    if workers <= 1 or tasks >= workers:
        return min(chunk, missions), ""
    if missions < workers:
        idle = (f"so {missions} worker process(es), not {workers}" if local else
                f"{workers - missions} of the cluster's {workers} worker threads idle")
        return 1, f"one mission per task: {missions} mission(s) for {workers} workers, {idle}"
    size = missions // workers  # at least `workers` tasks: 9 on 4 workers as 2+2+2+2+1, not 3+3+3
    return size, (f"--mc-chunk {chunk} cut to {size} so that each of the {workers} workers "
                  "gets a part")


def processes(args: argparse.Namespace) -> int | None:
    """The local worker processes to start: ``--workers``, but no more than the missions (a
    process without a task would only cost its start); None without ``--workers``."""
    return None if args.workers is None else min(args.workers, args.monte_carlo)


@contextlib.contextmanager
def executor_of(args: argparse.Namespace) -> Iterator[Executor | None]:
    """The executor ``--scheduler``/``--workers`` ask for (None: in this process)."""
    if args.scheduler:
        from ..parallel import client_executor

        try:
            ex = client_executor(args.scheduler)
        except RuntimeError as exc:  # Dask distributed is not installed: one sentence
            raise ValueError(str(exc)) from None
        try:
            yield ex
        finally:
            ex._client.close()
    elif args.workers:
        with ProcessPoolExecutor(processes(args)) as ex:
            yield ex
    else:
        yield None


def table_rows(mc, rows: int = 12) -> list[dict]:
    """``rows`` steps at regular times: frequency, its 95 % interval, the claimed bound."""
    import numpy as np

    lo, hi = mc.ci()
    freq = mc.frequency()
    ks = np.unique(np.rint(np.linspace(0, mc.t.size - 1, rows)).astype(int))
    return [{"k": int(k), "t": float(mc.t[k]), "frequency": float(freq[k]),
             "ci95_lo": float(lo[k]), "ci95_hi": float(hi[k]),
             "window_probability": float(mc.window_probability[k]),
             "above_bound": bool(freq[k] >= mc.window_probability[k])} for k in ks]


def format_table(rows: list[dict]) -> str:
    head = (f"{'k':>4} {'t (s)':>7} {'frequency':>9} {'95% interval':>19} {'claimed P':>9} "
            f"{'above':>5}")
    return "\n".join([head] + [
        f"{r['k']:>4} {r['t']:>7.2f} {r['frequency']:>9.4f} "
        f"[{r['ci95_lo']:.4f}, {r['ci95_hi']:.4f}] {r['window_probability']:>9.4f} "
        f"{'yes' if r['above_bound'] else 'NO':>5}" for r in rows])


def run_monte_carlo(args: argparse.Namespace) -> int:
    """Run the Monte Carlo of ``args.monte_carlo`` missions; print, write JSON and the figure.
    Returns 0 when the frequency is at or above the claimed bound at every step, else 1."""
    import numpy as np

    from ..parallel import executor_workers
    from ..scenarios.pool_mc import pool_monte_carlo

    with executor_of(args) as ex:
        where = (f"on the cluster at {args.scheduler}" if args.scheduler else
                 f"on {processes(args)} local worker processes" if args.workers else
                 "in-process")
        chunk, why = tasks_for(args.monte_carlo, args.mc_chunk,
                               args.workers or (0 if ex is None else executor_workers(ex)),
                               local=not args.scheduler)
        print(f"pool Monte Carlo: {args.monte_carlo} simulated missions (outlier probability "
              f"0.05 per ping), q = {args.q}, m = {args.m}, chunks of {chunk} "
              f"missions{f' ({why})' if why else ''}, {where}")
        mc = pool_monte_carlo(args.monte_carlo, args.q, args.m, seed=args.mc_seed,
                              chunk=chunk, executor=ex, progress=None,
                              sweeps=0 if args.sweeps is None else args.sweeps,
                              carry=not args.window_only, paving=args.paving,
                              paving_heading=args.paving_heading,
                              **({} if args.heading_slices is None else
                                 {"heading_slices": args.heading_slices}))
    freq = mc.frequency()
    below = int(np.count_nonzero(freq < mc.window_probability))
    hi = mc.ci()[1]
    print("observer: " + ", ".join(f"{k} = {v}" for k, v in mc.observer.items()
                                   if v is not None))
    print(f"time: {mc.time_s:.1f} s ({mc.solve_s:.1f} s in the observer, summed over tasks; "
          f"{mc.empty_steps} empty steps in all)")
    print(f"containment: min {freq.min():.4f} at k = {int(freq.argmin())}; frequency below the "
          f"claimed bound at {below} of {freq.size} steps; 95 % interval entirely below it at "
          f"{int(np.count_nonzero(hi < mc.window_probability))}")
    viol = int((mc.windows_ok - mc.inside_when_ok).sum())
    print(f"guarantee (every window so far held at most q outliers => x_k in X_k): "
          f"{viol} violations")
    rows = table_rows(mc)
    table = format_table(rows)
    print(table)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "pool_monte_carlo.txt").write_text(
        f"# boundest run pool --monte-carlo {args.monte_carlo}, q = {args.q}, m = {args.m}\n"
        f"# frequency of x_k in X_k, its 95 % Wilson interval, the claimed one-window P\n"
        f"{table}\n")
    print(f"wrote {out / 'pool_monte_carlo.txt'}")
    from ..plot.monte_carlo import plot_containment

    fig, ax = subplots(figsize=(9, 5))
    plot_containment(mc, ax=ax)
    ax.set_title(f"pool robot: does X_k contain the truth? {mc.missions} simulated missions, "
                 f"q = {mc.q}, m = {mc.m}", fontsize=10)
    save_figure(fig, args.out, "pool_monte_carlo")
    if args.json:
        write_json(mc.to_json() | {"table": rows}, args.json)
    return 0 if below == 0 else 1


def add_options(p: argparse.ArgumentParser) -> None:
    """The Monte Carlo options of ``boundest run pool``."""
    p.add_argument("--monte-carlo", type=whole(1), metavar="N",
                   help="instead of the embedded mission: simulate N >= 1 missions with random "
                   "outliers and compare, per step, how often X_k contains the truth with the "
                   "claimed probability (figure, table, --json)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="with --monte-carlo: run on the Dask "
                   "cluster at this scheduler address (pip install 'boundest[distributed]'); "
                   "not with --workers")
    p.add_argument("--workers", type=whole(1), metavar="K",
                   help="with --monte-carlo: run on K >= 1 local worker processes (workers "
                   "whose chunks would not fit in memory are refused)")
    p.add_argument("--mc-chunk", type=whole(1), metavar="C",
                   help=f"with --monte-carlo: missions per task, >= 1 (default {DEFAULT_CHUNK}); "
                   "cut smaller when that leaves a worker without a task, and said so")
    p.add_argument("--mc-seed", type=whole(0), help="with --monte-carlo: seed of the first "
                   "mission, >= 0 (default 0)")
