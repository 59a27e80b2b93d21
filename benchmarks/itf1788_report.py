"""IEEE 1788 conformance report: the ITF1788 test vectors run against boundest.

Parses every vendored ``.itl`` file (``tests/itf1788/``), runs each operation's bare vectors as
one batched boundest call (``tests/itf1788_runner.py`` holds the parser, the operation table
and the classification) and prints, per operation and in total:

* ``vectors``        lines of that operation in the files;
* ``skipped``        decorated vectors (boundest has bare intervals only);
* ``unimplemented``  bare vectors not run because boundest has no such function (``reason``);
* ``run``            bare vectors run;
* ``sound_failures`` vectors whose tightest expected result is not inside boundest's, invalid
  results, exceptions, wrong booleans or numbers (broken down in ``unsound``, ``invalid``,
  ``mismatch``, ``error``);
* ``tight``, ``within_1ulp``, ``within_4ulp``, ``looser``: the sound results, by the largest
  distance of a bound from the tightest one in float64 steps (0, 1, 2-4, more or infinite);
* ``looser_unbounded`` the looser ones at an infinite distance (a half-line or the entire line
  where the tightest result is bounded, or non-empty for empty): missed cases, not rounding;
* ``max_ulps``       the largest finite distance among the sound results;
* ``errata``         vectors checked against a corrected expected result (runner's ``ERRATA``);
* ``seconds``        time of the batched calls (Numba compilation included on a cold cache).

The run happens in a worker process, so a kernel that crashes the interpreter costs its own
operation only (``note`` tells how it was recovered). JSON goes to stdout (and to ``--out``);
progress to stderr.

Usage::

    .venv/bin/python benchmarks/itf1788_report.py [--out itf1788.json] [--ops add,mul,pow]
        [--decimal-mode nearest|outward] [--max-failures 10] [--fresh-numba-cache]
        [--in-process] [--op-timeout 300]
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import platform
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
RUNNER = ROOT / "tests" / "itf1788_runner.py"


def _load_runner():
    spec = importlib.util.spec_from_file_location("itf1788_runner", RUNNER)
    if spec is None or spec.loader is None:
        raise SystemExit(f"cannot load {RUNNER}")
    mod = importlib.util.module_from_spec(spec)
    sys.modules["itf1788_runner"] = mod  # dataclasses look their module up by name
    spec.loader.exec_module(mod)
    return mod


def _machine() -> dict[str, Any]:
    info: dict[str, Any] = {"python": platform.python_version(), "platform": platform.platform(),
                            "cpu_count": os.cpu_count()}
    for name in ("numpy", "numba", "boundest"):
        try:
            mod = __import__(name)
            info[name] = getattr(mod, "__version__", "?")
        except ImportError as exc:  # boundest itself missing is reported, not hidden
            info[name] = f"not importable: {exc}"
    return info


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=Path, help="also write the JSON report to this file")
    p.add_argument("--ops", help="comma-separated ITF operation names (default: all)")
    p.add_argument("--decimal-mode", choices=("nearest", "outward"), default="nearest",
                   help="reading of decimal literals that are not float64 numbers: the nearest "
                        "double (what the files mean, default) or their tightest enclosure")
    p.add_argument("--max-failures", type=int, default=10,
                   help="failing vectors listed per operation (default 10)")
    p.add_argument("--fresh-numba-cache", action="store_true",
                   help="compile every kernel into an empty NUMBA_CACHE_DIR (cold timings)")
    p.add_argument("--in-process", action="store_true",
                   help="run in this process (no protection against crashing kernels)")
    p.add_argument("--op-timeout", type=float, default=300.0,
                   help="seconds one operation may take in the worker (default 300)")
    p.add_argument("--list", action="store_true", help="list the operations and exit")
    args = p.parse_args(argv)

    runner = _load_runner()
    vectors = runner.parse_all(decimal_mode=args.decimal_mode)
    all_ops = sorted({v.op for v in vectors})
    if args.list:
        print("\n".join(all_ops))
        return 0
    ops = all_ops if not args.ops else [o.strip() for o in args.ops.split(",") if o.strip()]
    unknown = sorted(set(ops) - set(all_ops))
    if unknown:
        p.error(f"no vectors for operation(s) {', '.join(unknown)}; see --list")

    print(f"ITF1788: {len(vectors)} vectors, {len(ops)} operations "
          f"({'in process' if args.in_process else 'in a worker process'})...", file=sys.stderr)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as cache:
        if args.fresh_numba_cache:
            os.environ["NUMBA_CACHE_DIR"] = cache  # before any Numba import or worker start
        if args.in_process:
            chosen = [v for v in vectors if v.op in set(ops)]
            results = runner.run_all(chosen)
        else:
            results = runner.run_isolated(decimal_mode=args.decimal_mode, ops=ops,
                                          op_timeout=args.op_timeout)
    wall = time.perf_counter() - t0

    report = runner.summarize(results, max_failures=args.max_failures)
    doc: dict[str, Any] = {
        "benchmark": "itf1788",
        "machine": _machine(),
        "itf1788": {
            "directory": str(runner.ITF_DIR.relative_to(ROOT)),
            "files": sorted(f.name for f in runner.ITF_DIR.glob("*.itl")),
            "decimal_mode": args.decimal_mode,
            "vectors": len([v for v in vectors if v.op in set(ops)]),
        },
        "classes": {
            "tight": "both bounds equal to the tightest result",
            "within_1ulp": "sound, each bound at most 1 float64 step outside",
            "within_4ulp": "sound, at most 4 steps (more than 1)",
            "looser": "sound, more than 4 steps, an infinite bound, or non-empty for empty",
            "looser_unbounded": "looser at an infinite distance (a missed case, not rounding)",
            "sound_failures": "unsound + invalid + mismatch (booleans, numbers) + error",
        },
        "wall_s": round(wall, 3),
        **report,
        "errata": [{"where": v.where, "vector": v.text, "erratum": v.erratum}
                   for v in vectors if v.erratum and v.op in set(ops)],
    }
    text = json.dumps(doc, indent=2, allow_nan=False, default=str)
    print(text)
    if args.out:
        args.out.write_text(text + "\n")
        print(f"written to {args.out}", file=sys.stderr)
    t = report["total"]
    print(f"ITF1788: {t.get('run', 0)} run, {t.get('sound_failures', 0)} sound failures, "
          f"{t.get('tight', 0)} tight, {t.get('unimplemented', 0)} unimplemented, "
          f"{t.get('skipped', 0)} decorated skipped ({wall:.1f} s)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
