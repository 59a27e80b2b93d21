"""``boundest run auv``: localization and SLAM of an AUV mine survey (Jaulin, Bertholom, Dabe
2007, the Redermor AUV) on the embedded 60,000-sample survey."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from . import save_figure, subplots, write_json
from .figures import FigureWorker
from .options import check_input, check_outputs, fraction, whole


def check(args: argparse.Namespace) -> None:
    """The checks before any work: paths, and the SLAM options only with the SLAM."""
    check_input("--data", args.data, "folder")
    check_outputs(args.out, args.json,
                  () if args.json is None else (("--json", str(_npz(args.json))),))
    if args.mode == "localization":
        given = [f"{o} {v:g}" for o, v in (("--rel-eps", args.rel_eps),
                                           ("--max-iter", args.max_iter)) if v is not None]
        if given:
            raise ValueError(f"{' and '.join(given)}: the SLAM's iterations (--mode slam); "
                             "--mode localization is one forward and one backward pass, with no "
                             "iterations to stop")
    args.rel_eps = 1e-4 if args.rel_eps is None else args.rel_eps
    args.max_iter = 100 if args.max_iter is None else args.max_iter


def _npz(json: str) -> Path:
    """The file of every sample's position box that goes with ``--json FILE``."""
    return Path(json).with_suffix(".npz")


def _summary(res, data) -> None:
    import numpy as np

    w = res.widths()
    print(f"{res.mode}: {'consistent' if res.consistent else 'INCONSISTENT (no solution)'}, "
          f"{res.report.iterations} iteration(s) in {res.time_s:.3f} s "
          f"(R v over all samples: {res.rv_s:.3f} s)")
    if not res.consistent:
        return
    for i, name in enumerate(("north", "east", "depth")):
        print(f"  {name:>5} width: mean {w[:, i].mean():8.2f} m, max {w[:, i].max():8.2f} m")
    if res.mode == "slam":
        print("  mine boxes (north x east x depth, m):")
        m = res.mines
        for j in range(m.shape[0]):
            seen = int(np.count_nonzero(data.det_mine == j))
            print(f"    mine {j}: [{m.lo[j, 0]:.1f}, {m.hi[j, 0]:.1f}] x "
                  f"[{m.lo[j, 1]:.1f}, {m.hi[j, 1]:.1f}] x [{m.lo[j, 2]:.2f}, {m.hi[j, 2]:.2f}]"
                  f"  ({m.hi[j, 0] - m.lo[j, 0]:.1f} x {m.hi[j, 1] - m.lo[j, 1]:.1f} m, seen "
                  f"{seen} time{'s' if seen > 1 else ''})")


def to_json(res, data, npz: Path | None) -> dict:
    """The JSON of a result; the position box of every sample goes to ``npz`` (if given)."""
    w = res.widths()
    out = {"scenario": "auv", "mode": res.mode, "samples": data.n, "t0": data.t0,
           "dt": data.dt, "consistent": res.consistent, "iterations": res.report.iterations,
           "converged": res.report.converged, "time_s": res.time_s, "rv_time_s": res.rv_s,
           "width_mean": w.mean(axis=0) if res.consistent else None,
           "width_max": w.max(axis=0) if res.consistent else None,
           "mines": res.mines if res.mode == "slam" else None,
           "fixes": {"k": data.fix_k, "box": data.fix},
           "detections": {"k": data.det_k, "mine": data.det_mine, "range": data.det_range},
           "positions_npz": str(npz) if npz is not None else None}
    if npz is not None:
        import numpy as np

        np.savez_compressed(npz, t=data.t, lo=res.positions.lo, hi=res.positions.hi)
        print(f"wrote {npz}")
    return out


def run(args: argparse.Namespace) -> int:
    with FigureWorker(preload=("boundest.plot.auv", "boundest.scenarios.auv")) as figures:
        return _run(args, figures)


def _run(args: argparse.Namespace, figures: FigureWorker) -> int:
    from ..scenarios import auv
    from ..scenarios.auv_data import load_auv

    start = time.perf_counter()
    data = load_auv(args.data)
    print(f"AUV survey: {data.n} samples over {data.n * data.dt:.0f} s, {data.fix_k.size} GPS "
          f"fixes, {data.det_k.size} detections of {data.n_mines} mines (data: {data.source}; "
          f"read in {time.perf_counter() - start:.2f} s)")
    print("  hull consistency (box consistency of the attitudes narrows nothing here, at 10x "
          "the time: benchmarks/README.md, AUV modes)")
    print("localization ...", flush=True)
    loc = auv.localize(data)
    _summary(loc, data)
    results = [loc]
    if args.mode == "slam":
        print("SLAM: detections and dead reckoning in one contractor network ...", flush=True)
        res = auv.slam(data, rel_eps=args.rel_eps, max_iter=args.max_iter)
        _summary(res, data)
        results.append(res)
    final = results[-1]

    for draw in (draw_map, draw_depth, draw_widths):  # the slowest first
        figures.submit(draw, data, results, args.out)
    if args.json:
        npz = _npz(args.json)
        write_json(to_json(final, data, npz), args.json)
    figures.finish()
    return 0 if final.consistent else 1


def draw_map(data, results, out: str) -> None:
    """``auv_{mode}_map.png``: position boxes, GPS fixes (and mines, detections)."""
    from ..plot.auv import plot_auv_map

    final = results[-1]
    fig, ax = subplots(figsize=(10, 7.5))
    plot_auv_map(data, results, ax=ax)
    ax.set_title(f"AUV survey ({final.mode}): position boxes, GPS fixes"
                 + (", mines and detections" if final.mode == "slam" else ""))
    save_figure(fig, out, f"auv_{final.mode}_map")


def draw_widths(data, results, out: str) -> None:
    """``auv_{mode}_widths.png``: the width of the position box against time."""
    from ..plot.auv import plot_auv_widths

    final = results[-1]
    fig, ax = subplots(figsize=(10, 4))
    plot_auv_widths(data, results, ax=ax)
    ax.set_title("width of the position box against time"
                 + (": localization and SLAM" if final.mode == "slam" else ""))
    save_figure(fig, out, f"auv_{final.mode}_widths")


def draw_depth(data, results, out: str) -> None:
    """``auv_{mode}_depth.png``: the depth profile."""
    from ..plot.auv import plot_auv_depth

    final = results[-1]
    fig, ax = subplots(figsize=(10, 3.5))
    plot_auv_depth(data, final, ax=ax)
    ax.set_title("depth profile")
    save_figure(fig, out, f"auv_{final.mode}_depth")


def register(runs: argparse._SubParsersAction) -> None:
    """Add ``boundest run auv`` and its options."""
    p = runs.add_parser("auv", help="AUV mine survey (Jaulin et al. 2007): localization and "
                                    "SLAM over 60,000 samples")
    p.add_argument("--mode", choices=("localization", "slam"), default="slam",
                   help="localization (dead reckoning, GPS, depth) or slam (also the mines; "
                        "default)")
    p.add_argument("--data", help="folder holding auv_setup.json and the files it names "
                   "(default: the embedded survey; docs/data-format.md)")
    p.add_argument("--rel-eps", type=fraction, default=None,
                   help="SLAM stops when no domain shrinks by more than this fraction in an "
                        "iteration, in [0, 1[ (default 1e-4; --mode slam only)")
    p.add_argument("--max-iter", type=whole(1), default=None,
                   help="SLAM iteration limit, >= 1 (default 100; --mode slam only)")
    p.add_argument("--out", default="out", help="folder for figures, created if missing "
                   "(default: out)")
    p.add_argument("--json", help="write the summary, mines and detections as JSON to this file "
                   "and the position box of every sample to FILE.npz, in an existing folder "
                   "(docs/json.md)")
    p.set_defaults(func=run, check=check)
