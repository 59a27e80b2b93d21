"""``boundest run drifting-clock``: Rohou et al. 2018 section 5 end to end, with Figs. 11 and 12."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable

from . import save_figure, subplots, write_json
from .figures import FigureWorker
from .options import check_input, check_outputs, check_size, count, fraction, positive_float

DEFAULT_DT = 0.01
#: Memory of a run per slice: the peak resident memory of the command grew by 1.8 KiB per slice
#: from ``--dt 0.01`` to ``--dt 0.0001``, its figure process by 0.55 KiB, the ``--json`` text by
#: 0.4 KiB (2026-12, the development machine); rounded up
BYTES_PER_SLICE = 3 * 1024
#: The rest: the interpreter, the libraries and the figure process (0.28 GiB at ``--dt 0.01``)
BASE_BYTES = 300 << 20
#: More slices than this (80 times the default's 1244 on Table 2) are announced before the run
LARGE_SLICES = 100_000


def check(args: argparse.Namespace) -> None:
    """The checks before any work (the size ``--dt`` sets depends on the data: see
    :func:`check_slices`)."""
    check_input("--data", args.data)
    check_outputs(args.out, args.json)


def check_slices(t_final: Callable[[float], float], dt: float) -> None:
    """Refuse or announce the run whose tubes cover ``[0, t_final(dt)]`` at step ``dt``
    (``t_final(step)``: the end of the time domain the data need, a multiple of ``step``:
    ``boundest.scenarios.drifting_clock.t_final``)."""
    def slices(step: float) -> float:
        try:
            return max(1, round(t_final(step) / step))
        except OverflowError:  # a step so small that the count overflows a float
            return math.inf

    n = slices(dt)
    span = f" over [0, {n * dt:.6g}] s" if math.isfinite(n) else ""
    check_size(BASE_BYTES + n * BYTES_PER_SLICE,
               f"{count(n)} slices{span}, {count(n / slices(DEFAULT_DT))} times the default "
               f"--dt {DEFAULT_DT:g}'s, in every tube", f"--dt {dt:g}",
               large=n > LARGE_SLICES)


def run(args: argparse.Namespace) -> int:
    with FigureWorker(preload=("boundest.plot.scenarios_tube",
                               "boundest.scenarios.drifting_clock")) as figures:
        return _run(args, figures)


def _run(args: argparse.Namespace, figures: FigureWorker) -> int:
    import numpy as np

    from ..scenarios import drifting_clock as dc

    meas = dc.load(args.data)
    check_slices(lambda step: dc.t_final(meas, step=step), args.dt)
    print(f"drifting clock (Rohou et al. 2018): {len(meas)} measurements, data {meas.source}")
    res = dc.solve(meas, dt=args.dt, rel_eps=args.rel_eps, time_deriv=not args.plain_eval)
    if res.empty:
        print(f"proven INCONSISTENT after {res.iterations} iterations: no drift and boat path "
              "of the model meet every measurement")
    else:
        state = "fixed point reached" if res.converged else "stopped at the iteration limit"
        print(f"{state}: {res.iterations} iterations in {res.time_s:.3f} s over [0, "
              f"{res.h.t[-1]:g}] with dt = {args.dt:g}")
        if args.plain_eval:
            print("  [t_i] contracted with the plain tube inverse (whole slices); the default, "
                  "the derivative inside the slices, is tighter at about the same cost")
        else:
            print("  [t_i] contracted with the derivative inside the slices (y' = w; "
                  "--plain-eval: the plain inverse, which stops at slice bounds: up to 3 % "
                  "wider, no faster)")
        print(f"  [h]: max width {float(np.max(res.h.gates.width())):.3f}")
        for i in range(len(meas)):
            print(f"  tau_{i + 1} = {float(meas.tau.lo[i] + meas.tau.hi[i]) / 2:g}: "
                  f"[t_{i + 1}] = [{res.t.lo[i]:.3f}, {res.t.hi[i]:.3f}] (from [h] alone "
                  f"[{res.t_initial.lo[i]:.3f}, {res.t_initial.hi[i]:.3f}])")
        truth = dc.ClockTruth() if args.data is None else None
        for name in FIGURES:
            figures.submit(draw_figure, name, res, truth, args.out)
    write_json(res.to_json(), args.json)
    figures.finish()
    return 1 if res.empty else 0


#: figure name -> (plotting function in ``boundest.plot.scenarios_tube``, title)
FIGURES = {
    "clock_distance": ("plot_clock_distance",
                       "ephemeris [y](.) and the measurements (Rohou et al. 2018, Fig. 11)"),
    "clock_drift": ("plot_clock_drift",
                    "clock drift [h](.) and the times [t_i] (Rohou et al. 2018, Fig. 12)"),
}


def draw_figure(name: str, res, truth, out: str) -> None:
    """``out/name.png``, one of :data:`FIGURES`."""
    from ..plot import scenarios_tube

    fn, title = FIGURES[name]
    fig, ax = subplots(figsize=(9, 5.5))
    getattr(scenarios_tube, fn)(res, truth=truth, ax=ax)
    ax.set_title(title)
    save_figure(fig, out, name)


def register(runs: argparse._SubParsersAction) -> None:
    """Add ``boundest run drifting-clock`` and its options."""
    p = runs.add_parser("drifting-clock", help="Rohou et al. 2018: correcting a drifting clock")
    p.add_argument("--dt", type=positive_float, default=DEFAULT_DT,
                   help="slice duration in seconds, > 0 (default 0.01: 1244 slices on Table 2); "
                        "a run that needs more memory than the machine has is refused, one of "
                        f"more than {LARGE_SLICES:,} slices announced")
    p.add_argument("--data", help="measurement CSV, columns i,tau,z_lo,z_hi (default: the "
                   "embedded Table 2; docs/data-format.md)")
    p.add_argument("--rel-eps", type=fraction, default=1e-4,
                   help="stop when an iteration shrinks the domains by less than this fraction, "
                        "in [0, 1[ (default 1e-4)")
    p.add_argument("--plain-eval", action="store_true",
                   help="contract the [t_i] with the plain tube inverse (whole slices) instead "
                        "of the derivative inside the slices (the default)")
    p.add_argument("--out", default="out", help="folder for figures, created if missing "
                   "(default: out)")
    p.add_argument("--json", help="write [h], [y] and the [t_i] as JSON to this file, in an "
                   "existing folder (strict JSON: docs/json.md)")
    p.set_defaults(func=run, check=check)
