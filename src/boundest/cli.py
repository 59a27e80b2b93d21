"""The ``boundest`` command.

Parsing the arguments imports neither NumPy nor Numba: the scenario modules are imported only
for the scenario named on the command line (``commands.SCENARIOS`` lists them), and each
command imports the numerical layers when it runs. ``boundest --help`` and an argument error
therefore return in a few tens of milliseconds.
"""

from __future__ import annotations

import argparse
import atexit
import contextlib
import importlib
import os
import sys

from . import __version__
from .commands import SCENARIOS, save_figure, subplots, write_json
from .commands.options import Parser, check_outputs

#: Measured empty-cache first run of each command without the shipped kernel archive
#: (``BOUNDEST_KERNEL_ARCHIVE=0``, ``benchmarks/bench_startup.py``, a quiet 2-core machine,
#: 2026-12-04; under load from other jobs it took up to 3x as long), printed when a run starts
#: compiling; with the archive nothing compiles. pool: 38 s times the 1.18x that the heading
#: slices' kernels cost, measured side by side (44.9 -> 52.8 s, median of two, same machine).
#: satellite and solve: 62 and 48 s measured 2026-12-07 (AMD EPYC, load 1.2, about twice the
#: Xeon's times), since their default mode compiles the centered-form kernels.
COMPILE_ESTIMATE_S = {"satellite": 62, "jaulin2001": 8, "range-only": 14,
                      "drifting-clock": 10, "auv": 14, "pool": 45, "solve": 48, "demo": 4}


def _demo(args: argparse.Namespace) -> int:
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
    fig, axes = subplots(1, 2, figsize=(11, 4.2), sharey=True)
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


def _scenario_named(argv: list[str] | None) -> str | None:
    """The scenario of ``boundest run NAME`` in ``argv`` (None: not a run, or no name yet)."""
    if argv is None:
        return None
    words = [a for a in argv if not a.startswith("-")]
    if len(words) >= 2 and words[0] == "run":
        return words[1]
    return None


def build_parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    """The argument parser of ``boundest``.

    Parameters
    ----------
    argv : list of str, optional
        The arguments about to be parsed. When they name a scenario (``run NAME ...``), only
        that scenario's module is imported and registered with its options; the others are
        listed by name and help only. Without ``argv`` every scenario module is imported.
    """
    chosen = _scenario_named(argv)
    parser = Parser(
        prog="boundest",
        description="Guaranteed nonlinear state estimation by interval constraint propagation.")
    parser.add_argument("--version", action="version", version=f"boundest {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="enclose the graph of a function with interval boxes "
                                       "and draw it")
    demo.add_argument("--out", default="out", help="folder for figures, created if missing "
                                                   "(default: out)")
    demo.add_argument("--json", help="also write the summary as JSON to this file, in an "
                                     "existing folder (strict JSON: docs/json.md)")
    demo.set_defaults(func=_demo, check=lambda a: check_outputs(a.out, a.json))

    run = sub.add_parser("run", help="run a seed scenario end to end on its embedded data")
    scen = run.add_subparsers(dest="scenario", required=True)
    for name, (module, text) in SCENARIOS.items():
        if argv is None or name == chosen:
            importlib.import_module(f".commands.{module}", __package__).register(scen)
        else:  # named for `boundest run --help`; never parsed (the chosen one is registered)
            scen.add_parser(name, help=text)

    from .commands import solve

    solve.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``boundest`` console script."""
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser(argv).parse_args(argv)
    try:
        # the command's own checks, before any work: options that cannot go together, output
        # paths, inputs, optional extras, the size of the run (commands/options.py)
        check = getattr(args, "check", None)
        if check is not None:
            check(args)
    except (ValueError, OSError) as exc:
        print(f"boundest: error: {exc}", file=sys.stderr)
        return 2
    from ._kernels import announce_compilation
    from ._malloc import keep_freed_memory

    keep_freed_memory()  # the process is boundest's own: keep freed heap (see _malloc)

    what = args.scenario if args.command == "run" else args.command
    label = f"boundest run {what}" if args.command == "run" else f"boundest {what}"
    announce_compilation(f"'{label}'", COMPILE_ESTIMATE_S.get(what))
    try:
        return args.func(args)
    except (ValueError, OSError) as exc:
        print(f"boundest: error: {exc}", file=sys.stderr)
        return 2


def console() -> None:
    """The ``boundest`` console script: :func:`main`, then an exit that skips tearing down the
    interpreter's modules.

    Finalizing the modules of Numba, llvmlite and NumPy took 0.12 s of every warm run (7 % of
    ``boundest run pool``) and does nothing a command needs: the exit handlers still run
    (``atexit``: multiprocessing, Dask, ``weakref.finalize``), the standard streams are
    flushed, and every file a command writes is closed before it returns. Where the
    interpreter offers no way to run the exit handlers alone, it exits as usual.
    """
    rc = main()
    run_exit_handlers = getattr(atexit, "_run_exitfuncs", None)
    if run_exit_handlers is None:
        sys.exit(rc)
    run_exit_handlers()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError):  # a closed pipe: nothing more to write
            stream.flush()
    os._exit(0 if rc is None else int(rc))


if __name__ == "__main__":
    console()
