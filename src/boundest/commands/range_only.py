"""``boundest run range-only``: Rohou et al. 2018 section 4 end to end, with Figs. 8 and 9."""

from __future__ import annotations

import argparse
import math

from . import save_figure, subplots, write_json
from .figures import FigureWorker
from .options import (
    check_input,
    check_outputs,
    check_size,
    count,
    fraction,
    positive_float,
    whole,
)

#: ``boundest.scenarios.range_only.TF - T0``, the time domain that ``--dt`` slices, spelt out here
#: so that the checks import nothing numerical (``tests/test_bad_input.py`` checks that they
#: agree)
HORIZON_S = 64.0
DEFAULT_DT = 0.01
#: Memory of a run per slice: the peak resident memory of the command (``--max-iter 1``) grew by
#: 3.6 KiB per slice from ``--dt 0.01`` to ``--dt 0.001``, its figure process by 1.1 KiB, the
#: ``--json`` text by 1.0 KiB (2026-12, the development machine); rounded up
BYTES_PER_SLICE = 6 * 1024
#: The rest: the interpreter, the libraries and the figure process (0.3 GiB at ``--dt 0.01``)
BASE_BYTES = 350 << 20
#: More slices than this (16 times the default's 6400) are announced before the run starts
LARGE_SLICES = 100_000


def slices(dt: float) -> float:
    """Slices of the tubes over the time domain at step ``dt`` (as ``tube.time_grid``): a whole
    number, or ``inf`` when ``dt`` is so small that their number overflows a float."""
    n = HORIZON_S / dt * (1 - 1e-12)
    return max(1, math.ceil(n)) if math.isfinite(n) else math.inf


def check(args: argparse.Namespace) -> None:
    """The checks before any work: inputs, outputs, and the size ``--dt`` sets."""
    check_input("--data", args.data)
    check_input("--beacons", args.beacons)
    check_outputs(args.out, args.json)
    n = slices(args.dt)
    check_size(BASE_BYTES + n * BYTES_PER_SLICE,
               f"{count(n)} slices over [0, {HORIZON_S:g}] s, {count(n / slices(DEFAULT_DT))} "
               f"times the default --dt {DEFAULT_DT:g}'s, in every tube", f"--dt {args.dt:g}",
               large=n > LARGE_SLICES)


def run(args: argparse.Namespace) -> int:
    with FigureWorker(preload=("boundest.plot.scenarios_tube",
                               "boundest.scenarios.range_only")) as figures:
        return _run(args, figures)


def _run(args: argparse.Namespace, figures: FigureWorker) -> int:
    import numpy as np

    from ..scenarios import range_only as ro

    meas = ro.load(args.data, args.beacons)
    n = slices(args.dt)
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
    p.add_argument("--dt", type=positive_float, default=DEFAULT_DT,
                   help="slice duration in seconds, > 0 (default 0.01: 6400 slices); a run that "
                        "needs more memory than the machine has is refused, one of more than "
                        f"{LARGE_SLICES:,} slices announced")
    p.add_argument("--data", help="measurement CSV, columns i,beacon,t_lo,t_hi,z_lo,z_hi "
                   "(default: the embedded Table 1; docs/data-format.md)")
    p.add_argument("--beacons", help="beacon CSV, columns beacon,bx,by (default: the embedded one)")
    p.add_argument("--rel-eps", type=fraction, default=1e-4,
                   help="stop when an iteration shrinks the domains by less than this fraction, "
                        "in [0, 1[ (default 1e-4)")
    p.add_argument("--max-iter", type=whole(1), default=200,
                   help="iteration limit, >= 1 (default 200)")
    p.add_argument("--time-deriv-eval", action="store_true",
                   help="contract the measurement times with the derivative inside the slices "
                        "(default: the plain tube inverse; the same result on Table 1)")
    p.add_argument("--bearing-rate", action="store_true",
                   help="constrain the distance rate in its bearing form only, as Rohou et al. "
                        "2018 and Codac (cheaper, wider; default: also the product form)")
    p.add_argument("--out", default="out", help="folder for figures, created if missing "
                   "(default: out)")
    p.add_argument("--json", help="write the tubes and measurement boxes as JSON to this file, "
                   "in an existing folder (strict JSON: docs/json.md)")
    p.set_defaults(func=run, check=check)
