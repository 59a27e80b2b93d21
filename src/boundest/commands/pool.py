"""``boundest run pool``: the pool robot of Jaulin's robust set-membership observer (a
q-relaxed observer over sonar pings with outliers, smoothed inside its window) on the embedded
mission.

What the sets guarantee (:mod:`boundest.scenarios.pool_observer`): the recursive set holds
``x_k`` whenever every window of ``m`` pings since the start or the last restart held at most
``q`` outliers; the pure window set (``--window-only``) whenever the window at ``k`` did. The
printed ``P(at most q outliers in m pings)`` is the binomial probability of ONE window: the
pure window observer's guarantee at each step; the recursive set's event has a probability at
most that (its measured containment is higher: ``benchmarks/bench_pool.py``).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from . import save_figure, subplots, write_json
from .figures import FigureWorker
from .options import announce, check_input, check_outputs, check_size, positive_float, whole

#: ``boundest.scenarios.pool.DEFAULT_SLICES`` and ``pool_observer.MAX_SIDE``, spelt out here so
#: that the checks import nothing numerical (``tests/test_bad_input.py`` checks that they agree)
DEFAULT_SLICES = 32
MAX_SIDE = 64

GUARANTEE = {
    True: ("the probability that one window of {m} pings holds at most {q} outliers; the "
           "recursive set X_k holds the true state whenever every window since the last "
           "restart held at most {q} outliers, an event whose probability is at most this "
           "(so it is not a proven lower bound on P(x_k in X_k))"),
    False: ("the probability that one window of {m} pings holds at most {q} outliers: the pure "
            "window set X_k holds the true state whenever its own window does, so "
            "P(x_k in X_k) >= this at every step"),
}


def table_rows(data, res, rows: int = 10) -> list[dict]:
    """The paper's table: ``rows`` steps at regular times, with the window probability and the
    pings rejected in the window."""
    import numpy as np

    from ..plot.pool import window_of

    ks = np.unique(np.rint(np.linspace(0, data.n - 1, rows)).astype(int))
    return [{"k": int(k), "t": float(data.t[k]), "window": int(window_of(res, int(k)).size),
             "window_probability": float(res.window_probability[k]),
             "rejected": int(res.rejected[k]), "empty": bool(res.empty[k])} for k in ks]


def format_table(rows: list[dict], q: int) -> str:
    head = (f"{'k':>4} {'t (s)':>7} {'window':>6} {f'P(<= {q} outliers)':>18} "
            f"{'rejected':>8} {'empty':>5}")
    lines = [head] + [f"{r['k']:>4} {r['t']:>7.2f} {r['window']:>6} "
                      f"{r['window_probability']:>18.6f} {r['rejected']:>8} "
                      f"{'yes' if r['empty'] else 'no':>5}" for r in rows]
    return "\n".join(lines)


def _mean_widths(res) -> tuple:
    """Mean widths over the steps whose box is bounded (a restart box has an unbounded theta)."""
    import numpy as np

    w = res.widths()
    ok = np.isfinite(w).all(axis=1)
    return (w[ok].mean(axis=0) if ok.any() else np.full(4, np.nan)), int(ok.sum())


def observer_bytes(m: int, slices: int) -> int:
    """The memory of one mission's observer (``pool_observer.make_work``, ``make_bank``): two
    ``(m, m, 4)`` arrays of the window's smoothing, and four ``(2 slices, m, 4)`` arrays of the
    heading slices' windows, in float64."""
    return 64 * m * m + 256 * slices * m


#: The rest of a run on one mission (the interpreter, the libraries, the figure process: 0.35
#: GiB on the embedded mission)
BASE_BYTES = 400 << 20


def check(args: argparse.Namespace) -> None:
    """The checks before any work: options that go together, paths, and the memory --m and
    --heading-slices set (the Monte Carlo's own: ``pool_mc.check``)."""
    if args.q > args.m:
        raise ValueError(f"--q {args.q} outliers cannot be more than the --m {args.m} pings of "
                         "a window")
    if args.heading_slices is not None and args.paving_heading is None:
        raise ValueError(f"--heading-slices {args.heading_slices} goes with --paving-heading "
                         "RAD (it bounds the heading slices, and there are none)")
    if args.paving_heading is not None and args.window_only:
        raise ValueError("--paving-heading keeps heading slices that carry their own past: it "
                         "needs the recursive observer, not --window-only")
    monte_carlo = [o for o, v in (("--scheduler", args.scheduler), ("--workers", args.workers),
                                  ("--mc-chunk", args.mc_chunk), ("--mc-seed", args.mc_seed))
                   if v is not None]
    if args.monte_carlo is None and monte_carlo:
        raise ValueError(f"{' and '.join(monte_carlo)} "
                         f"{'go' if len(monte_carlo) > 1 else 'goes'} with --monte-carlo N: "
                         "without it there are no missions to simulate")
    if args.monte_carlo is not None:
        from .pool_mc import check as check_monte_carlo

        check_monte_carlo(args)
        return
    check_input("--data", args.data, "folder")
    check_outputs(args.out, args.json)
    slices = heading_slices(args)
    check_size(BASE_BYTES + observer_bytes(args.m, slices),
               f"the observer's windows of {args.m} pings"
               + (f" in {slices} heading slices" if args.paving_heading is not None else ""),
               f"--m {args.m}" + (f" --heading-slices {slices}"
                                  if args.paving_heading is not None else ""))
    announce_duration(1 if args.sweeps is None else args.sweeps)


#: Seconds of work a run costs, measured on the development machine (2-core AMD EPYC): one
#: mission of the embedded setup per smoothing round (--sweeps 1: 0.8 s in-process), and one
#: Monte Carlo mission without rounds per worker (21 ms, docs/distributed.md)
SWEEP_S = 0.8
MISSION_S = 0.021
#: A run estimated longer than this is announced before it starts
LARGE_S = 60.0


def announce_duration(sweeps: int, missions: int = 1, workers: int = 1) -> bool:
    """Announce, in one line, a run whose estimated time exceeds :data:`LARGE_S`: ``missions``
    of ``sweeps`` smoothing rounds shared by ``workers``. Returns whether it did."""
    per_mission = SWEEP_S * sweeps if sweeps else MISSION_S
    seconds = missions * per_mission / max(workers, 1)
    if seconds <= LARGE_S:
        return False
    what = (f"{missions:,} mission(s)" + (f" on {workers} workers" if workers > 1 else "")
            + f", {sweeps} smoothing round(s) per ping")
    announce(f"a long run: {what}: about {seconds / 60:,.0f} min on a 2-core machine "
             f"({per_mission:g} s per mission{' per round' if sweeps else ''}; --sweeps and "
             "--monte-carlo set it) ...")
    return True


def heading_slices(args: argparse.Namespace) -> int:
    """The heading slices the observer keeps room for (1 without --paving-heading)."""
    if args.paving_heading is None:
        return 1
    return DEFAULT_SLICES if args.heading_slices is None else args.heading_slices


def run(args: argparse.Namespace) -> int:
    if args.monte_carlo is not None:
        from .pool_mc import run_monte_carlo

        return run_monte_carlo(args)
    with FigureWorker(preload=("boundest.plot.pool", "boundest.scenarios.pool")) as figures:
        return _run(args, figures)


def _run(args: argparse.Namespace, figures: FigureWorker) -> int:
    import numpy as np

    from ..scenarios.pool import solve_pool
    from ..scenarios.pool_data import binomial_bound, load_pool

    start = time.perf_counter()
    data = load_pool(args.data)
    read_s = time.perf_counter() - start
    print(f"pool robot: {data.n} pings over {data.n * data.dt:.1f} s (dt = {data.dt:g} s), "
          f"outlier probability {data.p_outlier:g} per ping (data: {data.source}; read in "
          f"{read_s:.2f} s)")
    if args.sweeps is None:
        args.sweeps = 1
    kw = {"q": args.q, "m": args.m, "sweeps": args.sweeps, "carry": not args.window_only,
          "paving": args.paving, "paving_heading": args.paving_heading,
          **({} if args.heading_slices is None else {"heading_slices": args.heading_slices})}
    paved = args.paving is not None or args.paving_heading is not None
    what = ("pure window observer" if args.window_only else "recursive observer") + (
        f", {args.sweeps} smoothing round(s) per ping" if args.sweeps else ", no smoothing") + (
        f", paving with {_sides((args.paving, args.paving_heading))}" if paved else "")
    print(f"{what} ({'online, one update per ping' if args.online else 'offline'})",
          flush=True)
    res, per_update = (_online(data, kw) if args.online else (solve_pool(data, **kw), None))
    p_full = binomial_bound(args.m, args.q, data.p_outlier)
    print(f"q = {args.q} outliers allowed in a window of m = {args.m} pings: "
          f"P(at most {args.q} outliers in {args.m} pings) = {p_full:.6f},")
    print("  " + GUARANTEE[not args.window_only].format(m=args.m, q=args.q))
    w, nw = _mean_widths(res)
    note = "" if nw == data.n else f" (over the {nw} steps with a bounded box)"
    print(f"mean widths{note}: x {w[0]:.3f} m, y {w[1]:.3f} m, theta {w[2]:.3f} rad, "
          f"v {w[3]:.3f} m/s")
    empty = np.flatnonzero(res.empty)
    where = "" if not empty.size else ": at " + ", ".join(
        f"k = {k} (t = {data.t[k]:.2f} s)" for k in empty[:10]) + (
        f" and {empty.size - 10} more" if empty.size > 10 else "")
    print(f"empty steps (restarts): {empty.size}{where}")
    kmax = int(np.argmax(res.rejected))
    print(f"most pings rejected in a window: {int(res.rejected[kmax])} (first at k = {kmax}, "
          f"t = {data.t[kmax]:.2f} s)")
    print(f"time: {res.time_s:.2f} s for the observer"
          + ("" if per_update is None else
             f" ({len(per_update)} online updates: median {np.median(per_update) * 1e3:.2f} ms,"
             f" max {np.max(per_update) * 1e3:.2f} ms)"))
    if res.eps:
        what = "heading slices" if res.eps[1] is not None else "cells"
        print(f"paving ({_sides(res.eps)}): {res.cells.mean():.1f} {what} kept per step on "
              "average")
    print("  " + _mode_line(args.sweeps, args.paving, args.paving_heading))
    rows = table_rows(data, res)
    table = format_table(rows, args.q)
    print("table (P: one window, see above):")
    print(table)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "pool_table.txt").write_text(
        f"# boundest run pool, q = {args.q}, m = {args.m}, data: {data.source}\n"
        f"# P: {GUARANTEE[not args.window_only].format(m=args.m, q=args.q)}\n"
        f"# rejected: pings of the window inconsistent with X_k\n{table}\n")
    print(f"wrote {out / 'pool_table.txt'}")

    from ..plot.pool import ping_consistency

    consistent = ping_consistency(data, res)
    for draw in (draw_snapshots, draw_emission, draw_trajectory):  # the slowest first
        figures.submit(draw, data, res, consistent, args)
    if args.json:
        write_json(to_json(data, res, args, p_full, rows, per_update), args.json)
    figures.finish()
    return 1 if res.empty.all() else 0


def _observer(args: argparse.Namespace) -> str:
    """The observer a figure shows, for its title."""
    return "pure window observer" if args.window_only else "recursive observer"


def draw_snapshots(data, res, consistent, args: argparse.Namespace) -> None:
    """``pool_snapshots.png``: the (x, y) box at six times, the window's pings on the last."""
    import numpy as np

    from ..plot.pool import plot_pool_snapshot, window_of

    snaps = np.unique(np.rint(np.linspace(0, data.n - 1, 6)).astype(int))
    # fixed margins: constrained layout took 0.25 s here (half of the figure's time), for
    # a frame that never changes (the panels hold the pool's map at one scale)
    fig, axes = subplots(2, 3, figsize=(15, 7.4))
    fig.subplots_adjust(left=0.04, right=0.995, bottom=0.12, top=0.89, wspace=0.13, hspace=0.36)
    for i, (ax, k) in enumerate(zip(axes.flat, snaps, strict=False)):
        last = i == len(snaps) - 1
        plot_pool_snapshot(data, res, int(k), consistent, ax=ax, pings=last)
        ax.set_title(f"t = {data.t[k]:.2f} s (k = {k})"
                     + (f", the window's {window_of(res, int(k)).size} pings" if last else ""),
                     fontsize=9)
    for ax in list(axes.flat)[len(snaps):]:
        ax.set_visible(False)
    handles, labels = axes.flat[len(snaps) - 1].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", bbox_to_anchor=(0.5, 0.005), ncol=4,
               fontsize=8, frameon=False)
    fig.suptitle(f"pool robot, {_observer(args)}, q = {args.q}, m = {args.m}: the (x, y) box "
                 "at six times.\n"
                 "Last panel: each ping of the window drawn from the box centre at its time "
                 "along theta_centre + alpha, length d_mid; grey: the ray-cast contractor "
                 "empties (X_j, ping j)", fontsize=10)
    save_figure(fig, args.out, "pool_snapshots", tight=False)


def draw_emission(data, res, consistent, args: argparse.Namespace) -> None:  # noqa: ARG001
    """``pool_emission.png``: the last revolution of pings in the robot frame."""
    from ..plot.pool import plot_pool_emission

    fig, ax = subplots(figsize=(7, 7))
    plot_pool_emission(data, consistent, ax=ax)
    ax.set_title(f"emission diagram: the last {min(80, data.n)} pings (one revolution) "
                 f"up to t = {data.t[-1]:.2f} s, robot frame", fontsize=10)
    save_figure(fig, args.out, "pool_emission")


def draw_trajectory(data, res, consistent, args: argparse.Namespace) -> None:  # noqa: ARG001
    """``pool_trajectory.png``: the envelope of the trajectory and the widths against time."""
    from ..plot.pool import plot_pool_trajectory, plot_pool_widths

    fig, (ax1, ax2) = subplots(2, 1, figsize=(10, 8.5), gridspec_kw={"height_ratios": [1.6, 1]})
    plot_pool_trajectory(data, res, ax=ax1)
    ax1.set_title(f"trajectory envelope, {_observer(args)} (q = {args.q}, m = {args.m})")
    plot_pool_widths(data, res, ax=ax2)
    ax2.set_title("widths of the state box against time")
    save_figure(fig, args.out, "pool_trajectory")


def to_json(data, res, args, p_full: float, rows: list[dict], per_update=None) -> dict:
    import numpy as np

    w, nw = _mean_widths(res)
    c = res.centre()
    steps = [{"k": k, "t": float(data.t[k]), "box": res.boxes[k], "centre": c[k],
              "window_probability": float(res.window_probability[k]),
              "rejected": int(res.rejected[k]), "empty": bool(res.empty[k]),
              **({"cells": int(res.cells[k])} if res.eps else {})}
             for k in range(data.n)]
    online = None if per_update is None else {
        "updates": len(per_update), "median_s": float(np.median(per_update)),
        "max_s": float(np.max(per_update))}
    return {"scenario": "pool", "data": data.source, "samples": data.n, "t0": data.t0,
            "dt": data.dt, "p_outlier": data.p_outlier, "q": args.q, "m": args.m,
            "observer": "window" if args.window_only else "recursive",
            "sweeps": args.sweeps, "paving": args.paving,
            "paving_heading": args.paving_heading,
            "heading_slices": (None if args.paving_heading is None else
                               _heading_slices(args)),
            "online": online,
            "window_probability": p_full,
            "guarantee": GUARANTEE[not args.window_only].format(m=args.m, q=args.q),
            "width_mean": w, "width_mean_steps": nw,
            "empty_steps": np.flatnonzero(res.empty), "max_rejected": int(res.rejected.max()),
            "time_s": res.time_s, "table": rows, "steps": steps}


def _mode_line(sweeps: int, paving: float | None, heading: float | None) -> str:
    """Which contraction this run used, and what the other choices cost (the measured table of
    the README: embedded mission, q = 8, in-process warm times, 2026-12-04)."""
    table = ("in-process: --sweeps 0: 0.02 s, 0.96 x 0.87 m; default --sweeps 1: 0.8 s, 0.74 x "
             "0.66 m; --sweeps 0 --paving-heading 0.01: 1.2 s, 0.57 x 0.42 m")
    if heading is not None:
        return f"mode: heading slices, the tightest (on the embedded mission {table})"
    if paving is not None:
        return ("mode: (x, y) paving, slower and wider than heading slices (on the embedded "
                f"mission {table}; --sweeps 0 --paving 0.25: 7.3 s, 0.68 x 0.55 m)")
    if sweeps == 0:
        return f"mode: the recursive box observer, no smoothing, the fastest ({table})"
    return f"mode: smoothing inside the window ({table})"


def _heading_slices(args: argparse.Namespace) -> int:
    """The most heading slices this run keeps (``--heading-slices``, else the default)."""
    return DEFAULT_SLICES if args.heading_slices is None else args.heading_slices


def _sides(eps) -> str:
    xy, th = eps
    return ", ".join(([f"(x, y) cells of {xy:g} m"] if xy else [])
                     + ([f"heading slices of at most {th:g} rad"] if th else []))


def _online(data, kw: dict):
    """The mission through :class:`PoolObserver`, one update per ping, each timed."""
    import numpy as np

    from ..interval import Interval
    from ..scenarios.pool import PoolObserver, PoolResult, window_probabilities

    obs = PoolObserver(data, **kw)
    boxes, rejected, empty, cells, times = [], [], [], [], []
    for k in range(data.n):
        t0 = time.perf_counter()
        box, rej, emp = obs.update(data.inputs[k - 1] if k else None, float(data.alpha[k]),
                                   data.ranges[k])
        times.append(time.perf_counter() - t0)
        boxes.append(box)
        rejected.append(rej)
        empty.append(emp)
        cells.append(obs.cells_kept)
    probs = window_probabilities(data.n, kw["m"], kw["q"], data.p_outlier)
    res = PoolResult(Interval.trusted(np.stack([b.lo for b in boxes]),
                                   np.stack([b.hi for b in boxes])),
                     np.array(rejected), np.array(empty), probs, kw["q"], kw["m"],
                     float(sum(times)), np.array(cells), eps=obs.paving)
    return res, np.array(times[1:])  # the first update also loads the kernels


def register(runs: argparse._SubParsersAction) -> None:
    """Add ``boundest run pool`` and its options."""
    p = runs.add_parser("pool", help="pool robot (Jaulin's robust set-membership observer): "
                                     "a recursive q-relaxed observer over sonar pings")
    p.add_argument("--q", type=whole(0), default=8,
                   help="outliers allowed in a window, 0 <= q <= m (default 8)")
    p.add_argument("--m", type=whole(1), default=80,
                   help="window length in pings, >= 1 (default 80: one sonar revolution; the "
                   "observer holds two m x m arrays: a window too long for the memory is "
                   "refused)")
    p.add_argument("--sweeps", type=whole(0),
                   help="smoothing rounds inside the window per ping, >= 0 (default 1, with "
                   "--monte-carlo 0; 0: the plain recursive box observer, about 50x faster "
                   "and wider)")
    p.add_argument("--paving", type=positive_float, metavar="EPS",
                   help="pave (x, y) of each set into cells of side EPS > 0 metres, at most "
                   f"{MAX_SIDE} cells a side (a smaller EPS gives {MAX_SIDE} cells), and keep "
                   "the hull of the cells whose window is consistent (tighter, slower)")
    p.add_argument("--paving-heading", type=positive_float, metavar="RAD",
                   help="keep the set as heading slices, each with its own window, cut in two "
                   "when wider than RAD > 0 radians (what pays most: e.g. 0.01; recursive "
                   "observer only, not with --window-only)")
    p.add_argument("--heading-slices", type=whole(1), metavar="N",
                   help="most heading slices kept with --paving-heading, >= 1 (default 32; "
                   "beyond it neighbours merge)")
    p.add_argument("--window-only", action="store_true",
                   help="the pure window observer: each set from the open-loop prior and the "
                   "window's pings alone (its per-step guarantee is the binomial bound)")
    p.add_argument("--online", action="store_true",
                   help="run the online interface (one update per ping) and time each update")
    p.add_argument("--data", help="folder holding pool_setup.json, pool_map.json and the files "
                   "the setup names (default: the embedded mission; docs/data-format.md)")
    p.add_argument("--out", default="out", help="folder for figures and pool_table.txt, "
                   "created if missing (default: out)")
    p.add_argument("--json", help="write the summary and every step's box as JSON to this file, "
                   "in an existing folder (strict JSON: docs/json.md)")
    from .pool_mc import add_options

    add_options(p)
    p.set_defaults(func=run, check=check)
