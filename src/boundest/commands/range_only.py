"""``boundest run range-only``: Rohou et al. 2018 section 4 end to end, with Figs. 8 and 9."""

from __future__ import annotations

import argparse

from . import save_figure, subplots, write_json
from .figures import FigureWorker


def run(args: argparse.Namespace) -> int:
    with FigureWorker(preload=("boundest.plot.scenarios_tube",
                               "boundest.scenarios.range_only")) as figures:
        return _run(args, figures)


def _run(args: argparse.Namespace, figures: FigureWorker) -> int:
    import numpy as np

    from ..scenarios import range_only as ro

    meas = ro.load(args.data, args.beacons)
    n = int(np.ceil((ro.TF - ro.T0) / args.dt))
    print(f"range-only robot (Rohou et al. 2018): {len(meas)} measurements, "
          f"{meas.beacons.shape[0]} beacons, data {meas.source}")
    print(f"tubes over [{ro.T0:g}, {ro.TF:g}] with dt = {args.dt:g} ({n} slices) ...",
          flush=True)
    res = ro.solve(meas, dt=args.dt, rel_eps=args.rel_eps, max_iter=args.max_iter,
                   time_deriv=args.time_deriv_eval,
                   rate="bearing" if args.bearing_rate else "both")
    if res.empty:
        print(f"proven INCONSISTENT after {res.iterations} iterations: no trajectory of the "
              "model meets every measurement")
    else:
        d = res.position_diagonal()
        state = "fixed point reached" if res.converged else "stopped at --max-iter"
        print(f"{state}: {res.iterations} iterations in {res.time_s:.3f} s "
              f"(building {res.build_s:.3f} s)")
        print("  distance rate constrained in "
              + ("the bearing form only (--bearing-rate: cheaper, wider)" if args.bearing_rate
                 else "both forms, bearing and product (about 20 % more time than "
                      "--bearing-rate, mean diagonal 3 % smaller on Table 1)"))
        print("  mean position-box diagonal d per iteration: "
              + ", ".join(f"{float(np.mean(r)):.2f}" for r in res.diag))
        print(f"  final d: mean {float(np.mean(d)):.2f} m, max {float(np.max(d)):.2f} m")
        for i in range(len(meas)):
            print(f"  [t_{i + 1}] = [{res.t.lo[i]:.3f}, {res.t.hi[i]:.3f}] "
                  f"(data [{meas.t.lo[i]:.2f}, {meas.t.hi[i]:.2f}]), "
                  f"[z_{i + 1}] = [{res.z.lo[i]:.3f}, {res.z.hi[i]:.3f}]")
        truth = ro.RobotTruth() if args.data is None else None
        figures.submit(draw_diagonal, res, args)
        figures.submit(draw_map, res, truth, args)
    write_json(res.to_json(), args.json)
    figures.finish()
    return 1 if res.empty else 0


def draw_diagonal(res, args: argparse.Namespace) -> None:
    """``range_only_diagonal.png``: the position-box diagonal per iteration (Fig. 8)."""
    from ..plot.scenarios_tube import plot_range_only_diagonal

    fig, ax = subplots(figsize=(9, 4))
    plot_range_only_diagonal(res, ax=ax)
    ax.set_title(f"position-box diagonal per iteration (Rohou et al. 2018, Fig. 8), "
                 f"dt = {args.dt:g}")
    save_figure(fig, args.out, "range_only_diagonal")


def draw_map(res, truth, args: argparse.Namespace) -> None:
    """``range_only_map.png``: the position tube among the beacons (Fig. 9)."""
    from ..plot.scenarios_tube import plot_range_only_map

    fig, ax = subplots(figsize=(9, 7))
    plot_range_only_map(res, truth=truth, ax=ax)
    ax.set_title("[x1](.) x [x2](.) among the beacons (Rohou et al. 2018, Fig. 9)")
    save_figure(fig, args.out, "range_only_map")


def register(runs: argparse._SubParsersAction) -> None:
    """Add ``boundest run range-only`` and its options."""
    p = runs.add_parser("range-only",
                        help="Rohou et al. 2018: range-only robot with uncertain times")
    p.add_argument("--dt", type=float, default=0.01, help="slice duration (default 0.01)")
    p.add_argument("--data", help="measurement CSV, columns i,beacon,t_lo,t_hi,z_lo,z_hi "
                   "(default: the embedded Table 1; docs/data-format.md)")
    p.add_argument("--beacons", help="beacon CSV, columns beacon,bx,by (default: the embedded one)")
    p.add_argument("--rel-eps", type=float, default=1e-4,
                   help="stop when an iteration shrinks the domains by less than this fraction "
                        "(default 1e-4)")
    p.add_argument("--max-iter", type=int, default=200, help="iteration limit (default 200)")
    p.add_argument("--time-deriv-eval", action="store_true",
                   help="contract the measurement times with the derivative inside the slices "
                        "(default: the plain tube inverse; the same result on Table 1)")
    p.add_argument("--bearing-rate", action="store_true",
                   help="constrain the distance rate in its bearing form only, as Rohou et al. "
                        "2018 and Codac (cheaper, wider; default: also the product form)")
    p.add_argument("--out", default="out", help="folder for figures (default: out)")
    p.add_argument("--json", help="write the tubes and measurement boxes as JSON to this file "
                   "(strict JSON: docs/json.md)")
    p.set_defaults(func=run)
