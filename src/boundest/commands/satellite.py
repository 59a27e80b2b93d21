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
    """``out/satellite_k{k_max}.png``: the boxes of the position (Jaulin 2002, Fig. 4).

    The canvas takes the shape of the orbit (a long strip for ``k_max = 800``, not a square
    around it), and the ``k = 0`` and ``k = k_max`` labels go where they cover no box, no tick
    label and not the earth (:func:`_place_labels`).
    """
    from ..interval import Interval
    from ..plot import plot_boxes

    lo, hi = res.x_lo[:, :2], res.x_hi[:, :2]
    x0, y0 = min(float(lo[:, 0].min()), 0.0), min(float(lo[:, 1].min()), 0.0)
    x1, y1 = max(float(hi[:, 0].max()), 0.0), max(float(hi[:, 1].max()), 0.0)
    pad = 0.04 * max(x1 - x0, y1 - y0)
    x0, x1, y0, y1 = x0 - pad, x1 + pad, y0 - pad, y1 + pad
    # the canvas takes the data's aspect ratio (equal scales): at most 6 inches either way
    ratio = (y1 - y0) / (x1 - x0)
    width = min(6.0, 6.0 / ratio)
    height = max(width * ratio, 1.2)
    fig, ax = subplots(figsize=(width + 1.0, height + 1.2))
    plot_boxes(Interval.trusted(lo[:, 0], hi[:, 0]), Interval.trusted(lo[:, 1], hi[:, 1]), ax=ax,
               label="box [x1](k) x [x2](k), one per k")
    ax.plot(0, 0, "o", color="tab:green", ms=8, label="earth", zorder=1)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_xlabel("x1 (length unit of the model, G M = 1)")
    ax.set_ylabel("x2 (length unit of the model)")
    ax.set_aspect("equal")
    ax.set_title(f"[x1](k) x [x2](k), k = 0..{k_max} (Jaulin 2002, Fig. 4)")
    ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    _place_labels(ax, [(k, res.box(k)) for k in (0, k_max)], (lo + hi) / 2)
    save_figure(fig, out, f"satellite_k{k_max}")


def _place_labels(ax, boxes: list, centres) -> list:
    """Label each ``(k, box)`` with ``"k = {k}"`` and a leader line, at the one of eight
    positions around the box whose text stays inside the axes and covers the fewest box
    centres, the earth, the legend and the labels already placed. Returns the annotations."""
    import numpy as np

    fig = ax.figure
    renderer = fig.canvas.get_renderer()
    ax.apply_aspect()
    pts = ax.transData.transform(np.vstack([centres, [[0.0, 0.0]]]))
    frame = ax.get_window_extent(renderer)
    legend = ax.get_legend()
    taken = [legend.get_window_extent(renderer)] if legend is not None else []
    from matplotlib.text import Text
    from matplotlib.transforms import Bbox

    ex, ey = ax.transData.transform((0.0, 0.0))
    r = 6 * fig.dpi / 72  # the earth marker's radius (4 points) and a margin
    earth = Bbox.from_extents(ex - r, ey - r, ex + r, ey + r)
    done = []
    for k, b in boxes:
        xy = ((b.lo[0] + b.hi[0]) / 2, (b.lo[1] + b.hi[1]) / 2)
        best = None
        for angle in np.arange(8) * np.pi / 4 + np.pi / 8:
            dx, dy = 22 * np.cos(angle), 22 * np.sin(angle)
            ann = ax.annotate(f"k = {k}", xy, xytext=(dx, dy), textcoords="offset points",
                              ha="left" if dx > 0 else "right",
                              va="bottom" if dy > 0 else "top", fontsize=9,
                              arrowprops=dict(arrowstyle="-", color="0.3", lw=0.8))
            ann.update_positions(renderer)
            ext = Text.get_window_extent(ann, renderer).expanded(1.1, 1.2)  # not the line
            inside = frame.x0 <= ext.x0 and ext.x1 <= frame.x1 and frame.y0 <= ext.y0 \
                and ext.y1 <= frame.y1
            covered = int(np.count_nonzero((pts[:, 0] >= ext.x0) & (pts[:, 0] <= ext.x1)
                                           & (pts[:, 1] >= ext.y0) & (pts[:, 1] <= ext.y1)))
            hit = sum(ext.overlaps(t) for t in [*taken, earth])
            score = (0 if inside else 10_000) + covered + 1_000 * hit
            if best is None or score < best[0]:
                if best is not None:
                    best[1].remove()
                best = (score, ann, ext)
            else:
                ann.remove()
        taken.append(best[2])
        done.append(best[1])
    return done


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
