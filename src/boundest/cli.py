"""The ``boundest`` command."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

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
