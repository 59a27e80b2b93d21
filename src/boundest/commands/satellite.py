"""``boundest run satellite``: Jaulin 2002 end to end, with the Fig. 4 picture."""

from __future__ import annotations

import argparse

from . import save_figure, subplots, write_json
from .figures import FigureWorker
from .options import check_input, check_outputs, fraction


def check(args: argparse.Namespace) -> None:
    """The checks before any work: the input and output paths."""
    check_input("--data", args.data)
    check_outputs(args.out, args.json)


def run(args: argparse.Namespace) -> int:
    with FigureWorker(preload=("boundest.plot", "boundest.scenarios.satellite")) as figures:
        return _run(args, figures)


def _run(args: argparse.Namespace, figures: FigureWorker) -> int:
    import numpy as np

    from ..scenarios import satellite as sat

    meas = sat.load(args.data, k_max=args.kmax)
    print(f"satellite (Jaulin 2002): k_max = {meas.k_max}, data {meas.source}")
    print(f"CSP: {7 * (meas.k_max + 1)} constraints over {11 * meas.k_max + 15} variables; "
          "propagating ...", flush=True)
    res = sat.solve(meas, rel_eps=args.rel_eps, mode=args.mode)
    if not res.consistent and args.beta_tuning:
        print("the CSP is empty: the data contradict the model; beta-tuning ...")
        bres, res = sat.tune(meas, rel_eps=args.rel_eps, mode=args.mode)
        how = ("bisection by hull consistency" if args.mode == "hc4" else
               f"bisection by hull consistency, then mode {args.mode} from its beta on")
        print(f"smallest beta with a non-empty contraction in mode {args.mode}: "
              f"{bres.beta:.4f} ({len(bres.trials)} propagations, {how}, {bres.time_s:.2f} s)")
    if not res.consistent:
        print("proven INCONSISTENT: no state trajectory satisfies the model and the data "
              "(rerun with --beta-tuning to relax the perturbation and output bounds)")
    else:
        print(f"fixed point reached in {res.time_s:.3f} s ({res.evaluations} node revisions, "
              f"{res.iterations:.1f} passes equivalent)")
        if res.centered:
            sh, ce = res.shaving or {}, res.centered
            print(f"  mode 3b+centered: hull consistency, shaving of the states "
                  f"({sh.get('probes', 0)} probes, {sh.get('time_s', 0.0):.3f} s), then the "
                  f"centered form of windows of {ce['settings']['window'] // 7} steps "
                  f"({ce['rounds']} rounds, {ce['lp_optimal']} linear programmes, "
                  f"{ce['time_s']:.3f} s; --mode 3b or hc4: faster, wider)")
        elif res.shaving:
            sh = res.shaving
            print(f"  mode 3b: hull consistency, then shaving of the states "
                  f"({sh['probes']} probes, {sh['refuted']} slices refuted, "
                  f"{sh['time_s']:.3f} s; --mode hc4: hull consistency alone, faster, wider)")
        else:
            print(f"  mode {res.mode}: hull consistency alone (--mode 3b shaves: tighter)")
        for k in (0, meas.k_max):
            b = res.box(k)
            print(f"  x({k}) in " + " x ".join(f"[{lo:.4f}, {hi:.4f}]"
                                               for lo, hi in zip(b.lo, b.hi, strict=True)))
        w = res.x_hi - res.x_lo
        print("  mean width over k: " + ", ".join(f"x{i + 1} {np.mean(w[:, i]):.3f}"
                                                  for i in range(4)))
        figures.submit(draw_figure, res, meas.k_max, args.out)
    write_json(res.to_json(), args.json)
    figures.finish()
    return 0 if res.consistent else 1


def draw_figure(res, k_max: int, out: str) -> None:
    """``out/satellite_k{k_max}.png``: the boxes of the position (Jaulin 2002, Fig. 4)."""
    from ..interval import Interval
    from ..plot import plot_boxes

    fig, ax = subplots(figsize=(6.5, 6))
    plot_boxes(Interval.trusted(res.x_lo[:, 0], res.x_hi[:, 0]),
               Interval.trusted(res.x_lo[:, 1], res.x_hi[:, 1]), ax=ax,
               label="box [x1](k) x [x2](k), one per k")
    ax.plot(0, 0, "o", color="tab:green", ms=10, label="earth")
    ax.set_xlabel("x1 (length unit of the model, G M = 1)")
    ax.set_ylabel("x2 (length unit of the model)")
    ax.set_aspect("equal")
    ax.set_title(f"[x1](k) x [x2](k), k = 0..{k_max} (Jaulin 2002, Fig. 4)")
    for k, dx in ((0, -12), (k_max, -12)):
        b = res.box(k)
        ax.annotate(f"k = {k}", ((b.lo[0] + b.hi[0]) / 2, (b.lo[1] + b.hi[1]) / 2),
                    xytext=(dx, 0), textcoords="offset points", ha="right", va="center",
                    fontsize=9, arrowprops=dict(arrowstyle="-", color="0.3", lw=0.8))
    ax.legend(loc="center", bbox_to_anchor=(0.55, 0.45), fontsize=8)
    save_figure(fig, out, f"satellite_k{k_max}")


def register(runs: argparse._SubParsersAction) -> None:
    """Add ``boundest run satellite`` and its options."""
    sat = runs.add_parser("satellite", help="Jaulin 2002: satellite localisation as a CSP")
    sat.add_argument("--kmax", type=int, choices=(200, 800), default=None,
                     help="horizon (default: 200, or every row of --data)")
    sat.add_argument("--data", help="measurement CSV, columns k,y1_lo,y1_hi,y2_lo,y2_hi,"
                                    "y3_lo,y3_hi (default: the embedded one for --kmax; "
                                    "docs/data-format.md)")
    sat.add_argument("--rel-eps", type=fraction, default=1e-3,
                     help="propagation stops when no domain shrinks by more than this "
                          "fraction of its width, in [0, 1[ (default 1e-3)")
    sat.add_argument("--mode", choices=("3b+centered", "3b", "hc4"), default="3b+centered",
                     help="3b+centered (default): hull consistency, 3B shaving of the states, "
                          "then the centered form of windows of steps (tightest); 3b: shaving "
                          "alone; hc4: hull consistency alone (fastest); "
                          "benchmarks/README.md compares them")
    sat.add_argument("--beta-tuning", action="store_true",
                     help="if the CSP is empty, search the smallest relaxation beta for which "
                          "--mode does not prove it empty (a bisection by hull consistency, "
                          "then in --mode from its result)")
    sat.add_argument("--out", default="out", help="folder for figures, created if missing "
                                                  "(default: out)")
    sat.add_argument("--json", help="write the enclosures as JSON to this file, in an existing "
                                    "folder (strict JSON: docs/json.md)")
    sat.set_defaults(func=run, check=check)
