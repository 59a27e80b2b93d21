"""The ``boundest`` command."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from . import __version__


def _write_json(data: dict, path: str | None) -> None:
    if path:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        Path(path).write_text(json.dumps(data, indent=2))
        print(f"wrote {path}")


def _demo(args: argparse.Namespace) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

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
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    xs = np.linspace(*fe.DOMAIN, 2000)
    for ax, n in zip(axes, (16, 64), strict=True):
        enc = fe.enclose(n)
        plot_boxes(enc.x, enc.y, ax=ax)
        ax.plot(xs, fe.f_float(xs), color="crimson", lw=1.2, label="f(x)")
        ax.set_title(f"{n} boxes: [x] x f([x]) contains the graph")
        ax.set_xlabel("x")
        ax.legend(loc="upper left")
    axes[0].set_ylabel("f(x)")
    fig.tight_layout()
    png = out / "function_enclosure.png"
    fig.savefig(png, dpi=120)
    print(f"wrote {png}")
    _write_json(result, args.json)
    return 0


def _run_satellite(args: argparse.Namespace) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .interval import Interval
    from .plot import plot_boxes
    from .scenarios import satellite as sat

    meas = sat.load(args.data, k_max=args.kmax)
    print(f"satellite (seed 000): k_max = {meas.k_max}, data {meas.source}")
    print(f"CSP: {7 * (meas.k_max + 1)} constraints over {11 * meas.k_max + 15} variables; "
          "first run compiles the propagation kernel (cached afterwards)")
    res = sat.solve(meas, rel_eps=args.rel_eps)
    if not res.consistent and args.beta_tuning:
        print("the CSP is empty: the data contradict the model; beta-tuning ...")
        bres, res = sat.tune(meas, rel_eps=args.rel_eps)
        print(f"smallest beta with a non-empty contraction: {bres.beta:.4f} "
              f"({len(bres.trials)} propagations, {bres.time_s:.2f} s)")
    if not res.consistent:
        print("proven INCONSISTENT: no state trajectory satisfies the model and the data "
              "(rerun with --beta-tuning to relax the perturbation and output bounds)")
    else:
        print(f"fixed point reached in {res.time_s:.3f} s ({res.evaluations} node revisions, "
              f"{res.iterations:.1f} passes equivalent)")
        for k in (0, meas.k_max):
            b = res.box(k)
            print(f"  x({k}) in " + " x ".join(f"[{lo:.4f}, {hi:.4f}]"
                                               for lo, hi in zip(b.lo, b.hi, strict=True)))
        w = res.x_hi - res.x_lo
        print("  mean width over k: " + ", ".join(f"x{i + 1} {np.mean(w[:, i]):.3f}"
                                                  for i in range(4)))
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        fig, ax = plt.subplots(figsize=(6.5, 6))
        plot_boxes(Interval._new(res.x_lo[:, 0], res.x_hi[:, 0]),
                   Interval._new(res.x_lo[:, 1], res.x_hi[:, 1]), ax=ax)
        ax.plot(0, 0, "o", color="tab:green", ms=10, label="earth")
        ax.set_xlabel("x1")
        ax.set_ylabel("x2")
        ax.set_aspect("equal")
        ax.set_title(f"[x1](k) x [x2](k), k = 0..{meas.k_max + 1} (seed 000, Fig. 4)")
        ax.legend()
        fig.tight_layout()
        png = out / f"satellite_k{meas.k_max}.png"
        fig.savefig(png, dpi=120)
        print(f"wrote {png}")
    _write_json(res.to_json(), args.json)
    return 0 if res.consistent else 1


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
        _write_json({"file": str(args.file), "consistent": res.consistent,
                     "evaluations": res.evaluations, "time_s": res.time_s,
                     "domains": {n: None if bool(d.is_empty()) else [float(d.lo), float(d.hi)]
                                 for n, d in res.domains.items()}}, args.json)
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
    demo.add_argument("--json", help="also write the summary as JSON to this file")
    demo.set_defaults(func=_demo)

    run = sub.add_parser("run", help="run a seed scenario end to end on its embedded data")
    scen = run.add_subparsers(dest="scenario", required=True)
    sat = scen.add_parser("satellite", help="seed 000: satellite localisation as a CSP")
    sat.add_argument("--kmax", type=int, choices=(200, 800), default=200,
                     help="horizon (default 200)")
    sat.add_argument("--data", help="measurement CSV (default: the embedded one for --kmax)")
    sat.add_argument("--rel-eps", type=float, default=1e-3,
                     help="propagation stops when no domain shrinks by more than this "
                          "fraction of its width (default 1e-3)")
    sat.add_argument("--beta-tuning", action="store_true",
                     help="if the CSP is empty, search the smallest relaxation beta")
    sat.add_argument("--out", default="out", help="folder for figures (default: out)")
    sat.add_argument("--json", help="write the enclosures as JSON to this file")
    sat.set_defaults(func=_run_satellite)

    solve = sub.add_parser("solve", help="propagate a model file and print every domain")
    solve.add_argument("file", help="model in the text format (docs: boundest.expr.parser)")
    solve.add_argument("--rel-eps", type=float, default=1e-3)
    solve.add_argument("--json", help="write the domains as JSON to this file")
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
