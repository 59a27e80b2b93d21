"""``boundest run jaulin2001``: Jaulin et al. 2001 section 5 (equation 21), with the Fig. 7
picture."""

from __future__ import annotations

import argparse
import math

from . import pyplot, save_figure, write_json
from .figures import FigureWorker
from .options import announce, check_input, check_outputs, positive_float

DEFAULT_EPS = 0.01
#: ``PavingSets.max_boxes``: the boxes one set operation may process; beyond them its set is
#: kept coarser than eps (sound)
BOX_BUDGET = 2_000_000
#: An --eps that costs more than this many times the default's work is announced: the work grew
#: 12-fold from eps 0.01 to 0.0025 (1.8 s to 23 s, the development machine), about as 1/eps^2
LARGE_WORK = 10

#: The choice of domains and what the other one costs (embedded data, in-process solve of RCSE
#: and NCSE: subpavings at eps 0.01 0.56 s, boxes 0.18 s; non-causal hull of x(10)).
SUBPAVINGS_LINE = ("mode: subpavings at eps = {eps:g} (the default domains; --boxes: hull "
                   "consistency on one box per k, about 3x faster, but a box cannot hold the "
                   "arcs of x(k): x(10) 5.1 x 6.0 against 0.20 x 0.29 at eps 0.01; a larger "
                   "--eps is faster and coarser)")
BOXES_LINE = ("mode: boxes, hull consistency on one box per k (the default subpavings keep the "
              "arcs of x(k): x(10) 0.20 x 0.29 against 5.1 x 6.0 at eps 0.01, about 3x the "
              "time)")


def check(args: argparse.Namespace) -> None:
    """The checks before any work: paths, --eps with --boxes, and the work --eps sets."""
    check_input("--data", args.data)
    check_outputs(args.out, args.json)
    if args.boxes and args.eps is not None:
        raise ValueError(f"--eps {args.eps:g} is the precision of the subpavings; --boxes "
                         "computes one box per k and has none: give one or the other")
    if args.eps is None:
        args.eps = DEFAULT_EPS
    ratio = DEFAULT_EPS / args.eps
    work = ratio * ratio  # inf, not OverflowError, for a tiny eps
    if not args.boxes and work > LARGE_WORK:
        announce(f"a large run: --eps {args.eps:g}: about {work:,.0f} times the work of the "
                 f"default --eps {DEFAULT_EPS:g} (it grows as 1/eps^2; 2 s at the default on a "
                 f"2-core machine); a set operation that needs more than {BOX_BUDGET:,} boxes "
                 "keeps its set coarser than eps ...")


def run(args: argparse.Namespace) -> int:
    with FigureWorker(preload=("boundest.plot", "boundest.scenarios.jaulin2001")) as figures:
        return _run(args, figures)


def _run(args: argparse.Namespace, figures: FigureWorker) -> int:
    from ..scenarios import jaulin2001 as jw

    y = jw.load(args.data)
    K = y.shape[0]
    domains = "boxes" if args.boxes else "subpavings"
    print(f"jaulin2001 (Jaulin et al. 2001, eq. 21): K = {K}, domains {domains}"
          + (f", eps = {args.eps:g}, x(0) paved in [-4, 4]^2" if not args.boxes else ""))
    res = jw.solve(y, domains=domains, eps=args.eps, progress=True)
    data = jw.to_json(res)
    print(f"RCSE {res.rcse.time_s:.2f} s, NCSE {res.ncse.time_s - res.rcse.time_s:.2f} s more "
          "(one CLIMB from the RCSE's sets)")
    print(f"{'k':>3} {'RCSE hull':>40} {'boxes':>6}   {'NCSE hull':>40} {'boxes':>6}")
    for r, n in zip(data["rcse"]["sets"], data["ncse"]["sets"], strict=True):
        def fmt(row: dict) -> str:
            return " x ".join(f"[{_f(a)}, {_f(b)}]"
                              for a, b in zip(row["hull_lo"], row["hull_hi"], strict=True))
        print(f"{r['k']:>3} {fmt(r):>40} {r['boxes']:>6}   {fmt(n):>40} {n['boxes']:>6}")
    print("  " + (BOXES_LINE if args.boxes else SUBPAVINGS_LINE.format(eps=args.eps)))
    hit = res.ncse.stats.get("budget_hit", 0)
    if hit:
        print(f"  {hit} set operation(s) reached the budget of {BOX_BUDGET:,} boxes: their sets "
              f"are coarser than eps = {args.eps:g} (still sound); a larger --eps avoids it")
    empty = any(math.isnan(s["hull_lo"][0]) for e in ("rcse", "ncse") for s in data[e]["sets"])
    if empty:
        print("proven INCONSISTENT: an empty set (the data contradict the model)")
    figures.submit(draw_figure, res, args.out)
    write_json(data, args.json)
    figures.finish()
    return 1 if empty else 0


def draw_figure(res, out: str) -> None:
    """``out/jaulin2001_{domains}.png``: every x(k), causal and non-causal (Fig. 7)."""
    from ..plot import plot_set_sequence
    from ..scenarios import jaulin2001 as jw

    pyplot()  # the file-only backend, before plot_set_sequence makes its figure
    K = len(res.rcse.x) - 1
    fig = plot_set_sequence([res.rcse.x, res.ncse.x], ["causal (RCSE)", "non-causal (NCSE)"],
                            jw.FRAME)
    fig.suptitle(f"x(k), k = 0..{K}: causal and non-causal sets (Jaulin et al. 2001, Fig. 7);\n"
                 "each panel framed on the non-causal set (ticks differ)", fontsize=10)
    save_figure(fig, out, f"jaulin2001_{res.domains}", dpi=110)


def _f(v: float) -> str:
    return "empty" if math.isnan(v) else f"{v:.3f}"


def register(runs: argparse._SubParsersAction) -> None:
    """Add ``boundest run jaulin2001`` and its options."""
    p = runs.add_parser("jaulin2001",
                        help="Jaulin et al. 2001: causal and non-causal set estimation")
    p.add_argument("--data", help="measurement CSV, columns k,y_lo,y_hi (default: the embedded "
                   "one; docs/data-format.md)")
    p.add_argument("--eps", type=positive_float, default=None,
                   help="subpaving precision, > 0 (default 0.01; the work grows as 1/eps^2: "
                        "below 0.003 the run is announced as large); not with --boxes")
    p.add_argument("--boxes", action="store_true",
                   help="box domains (hull consistency) instead of subpavings")
    p.add_argument("--out", default="out", help="folder for figures, created if missing "
                   "(default: out)")
    p.add_argument("--json", help="write the sets' hulls, box counts and areas to this file, in "
                   "an existing folder (strict JSON: docs/json.md)")
    p.set_defaults(func=run, check=check)
