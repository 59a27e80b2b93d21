"""The ``boundest`` command."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from . import __version__
from .commands import RUNS, pyplot, save_figure, write_json


def _demo(args: argparse.Namespace) -> int:
    plt = pyplot()

    from .plot import plot_boxes
    from .scenarios import function_enclosure as fe

    result = fe.run()
    lo, hi = result["sampled_range"]
    print(f"f(x) = {result['function']} over x in {result['domain']}")
    print(f"sampled range (inner estimate): [{lo:.6f}, {hi:.6f}]")
    print(f"{'boxes':>6} {'guaranteed range of f':>32} {'width':>9} {'mean box height':>16}")
    for r in result["enclosures"]:
        print(f"{r['pieces']:>6} [{r['range_lo']:>14.6f}, {r['range_hi']:>14.6f}] "
              f"{r['range_width']:>9.4f} {r['mean_box_height']:>16.5f}")
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    xs = np.linspace(*fe.DOMAIN, 2000)
    for ax, n in zip(axes, (16, 64), strict=True):
        enc = fe.enclose(n)
        plot_boxes(enc.x, enc.y, ax=ax, label="box [x] x f([x]) (interval evaluation)")
        ax.plot(xs, fe.f_float(xs), color="crimson", lw=1.2, label="f(x)")
        ax.set_title(f"{n} boxes: [x] x f([x]) contains the graph")
        ax.set_xlabel("x (no unit)")
        ax.legend(loc="lower right", fontsize=8)
    axes[0].set_ylabel("f(x)")
    save_figure(fig, args.out, "function_enclosure")
    write_json(result, args.json)
    return 0


def _solve(args: argparse.Namespace) -> int:
    from .csp import propagate
    from .expr import load_model

    model = load_model(args.file)
    for key, value in model.options.items():
        print(f"note: option '{key} {value}' is not used by boundest")
    res = propagate(model, rel_eps=args.rel_eps)
    status = "consistent" if res.consistent else "INCONSISTENT (no solution)"
    print(f"{args.file}: {len(model.domains)} variables, {len(model.constraints)} constraints: "
          f"{status}; {res.evaluations} node revisions in {res.time_s:.3f} s")
    width = max((len(n) for n in res.domains), default=0)
    for name, dom in res.domains.items():
        text = "[empty]" if bool(dom.is_empty()) else f"[{float(dom.lo)!r}, {float(dom.hi)!r}]"
        print(f"  {name:<{width}} in {text}")
    if args.json:
        write_json({"file": str(args.file), "consistent": res.consistent,
                    "evaluations": res.evaluations, "time_s": res.time_s,
                    "domains": res.domains}, args.json)
    return 0 if res.consistent else 1


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="boundest",
        description="Guaranteed nonlinear state estimation by interval constraint propagation.")
    parser.add_argument("--version", action="version", version=f"boundest {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="enclose the graph of a function with interval boxes "
                                       "and draw it")
    demo.add_argument("--out", default="out", help="folder for figures (default: out)")
    demo.add_argument("--json", help="also write the summary as JSON to this file "
                                     "(strict JSON: docs/json.md)")
    demo.set_defaults(func=_demo)

    run = sub.add_parser("run", help="run a seed scenario end to end on its embedded data")
    scen = run.add_subparsers(dest="scenario", required=True)
    for module in RUNS:
        module.register(scen)

    solve = sub.add_parser("solve", help="propagate a model file and print every domain")
    solve.add_argument("file", help="model in the text format (docs: boundest.expr.parser)")
    solve.add_argument("--rel-eps", type=float, default=1e-3)
    solve.add_argument("--json", help="write the domains as JSON to this file "
                                      "(strict JSON: docs/json.md)")
    solve.set_defaults(func=_solve)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``boundest`` console script."""
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, OSError) as exc:
        print(f"boundest: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
