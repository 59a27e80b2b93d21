"""``boundest run jaulin2001``: Jaulin et al. 2001 section 5 (equation 21), with the Fig. 7
picture."""

from __future__ import annotations

import argparse
import math

from . import pyplot, save_figure, write_json
from .figures import FigureWorker

#: The choice of domains and what the other one costs (embedded data, in-process solve of RCSE
#: and NCSE: subpavings at eps 0.01 0.56 s, boxes 0.18 s; non-causal hull of x(10)).
SUBPAVINGS_LINE = ("mode: subpavings at eps = {eps:g} (the default domains; --boxes: hull "
                   "consistency on one box per k, about 3x faster, but a box cannot hold the "
                   "arcs of x(k): x(10) 5.1 x 6.0 against 0.20 x 0.29 at eps 0.01; a larger "
                   "--eps is faster and coarser)")
BOXES_LINE = ("mode: boxes, hull consistency on one box per k (the default subpavings keep the "
              "arcs of x(k): x(10) 0.20 x 0.29 against 5.1 x 6.0 at eps 0.01, about 3x the "
              "time)")


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
                 "each panel zoomed on the non-causal set (ticks differ)", fontsize=10)
    save_figure(fig, out, f"jaulin2001_{res.domains}", dpi=110)


def _f(v: float) -> str:
    return "empty" if math.isnan(v) else f"{v:.3f}"


def register(runs: argparse._SubParsersAction) -> None:
    """Add ``boundest run jaulin2001`` and its options."""
    p = runs.add_parser("jaulin2001",
                        help="Jaulin et al. 2001: causal and non-causal set estimation")
    p.add_argument("--data", help="measurement CSV, columns k,y_lo,y_hi (default: the embedded "
                   "one; docs/data-format.md)")
    p.add_argument("--eps", type=float, default=0.01,
                   help="subpaving precision (default 0.01)")
    p.add_argument("--boxes", action="store_true",
                   help="box domains (hull consistency) instead of subpavings")
    p.add_argument("--out", default="out", help="folder for figures (default: out)")
    p.add_argument("--json", help="write the sets' hulls, box counts and areas to this file "
                   "(strict JSON: docs/json.md)")
    p.set_defaults(func=run)
