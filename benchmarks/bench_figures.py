"""Figure benchmark: whole-process wall time of every ``boundest run`` scenario, and how much of
it goes to matplotlib (importing it, laying figures out, writing them).

Each run is a fresh process, ``python -c DRIVER``, where the driver calls
``boundest.cli.main(["run", NAME, "--out", TMP])`` as the console script does, after putting
timers around:

* ``Figure.savefig`` (``savefig_s``: drawing, the layout engine when it runs there, PNG
  encoding), ``Figure.tight_layout`` (``tight_layout_s``) and the layout engines' ``execute``
  (``layout_engine_s``, wherever it runs, also inside the other two);
* ``output_s``: the time spent in any of these, counted once where they nest: what laying out
  and writing the figures costs;
* the outermost imports of ``matplotlib``, ``mpl_toolkits`` and ``PIL`` modules
  (``matplotlib_import_s``).

The parent times the whole process (``wall_s``). The timers are patched in lazily (when the
module is first imported), so a run that imports no matplotlib pays nothing for them.

With ``--tree DIR`` (repeatable) the same scenarios run with ``PYTHONPATH=DIR/src``, so two
checkouts can be compared side by side with one environment (their Numba caches live beside
their sources: warm each tree first); runs of the trees are interleaved, a warm-up run each
first. On a shared machine hold the benchmark lock and keep each call short::

    flock /tmp/boundest-bench.lock .venv/bin/python benchmarks/bench_figures.py \\
        --only pool,jaulin2001 [--tree ../baseline --tree .] [--repeat 3] [--out FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _machine import cpu_model, emit

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ("satellite", "jaulin2001", "range-only", "drifting-clock", "auv", "pool")

DRIVER = r"""
import importlib.abc, json, sys, time
acc = {"output_s": 0.0, "savefig_s": 0.0, "tight_layout_s": 0.0, "layout_engine_s": 0.0,
       "matplotlib_import_s": 0.0, "figures": 0}
depth = [0]
out_depth = [0]

def timed(fn, key, count=False):
    def wrapper(*a, **k):
        t = time.perf_counter()
        out_depth[0] += 1
        try:
            return fn(*a, **k)
        finally:
            out_depth[0] -= 1
            dt = time.perf_counter() - t
            acc[key] += dt
            if out_depth[0] == 0:
                acc["output_s"] += dt
            acc["figures"] += count
    return wrapper

class Hook(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name.split(".")[0] not in ("matplotlib", "mpl_toolkits", "PIL"):
            return None
        sys.meta_path.remove(self)
        try:
            spec = importlib.util.find_spec(name)
        finally:
            sys.meta_path.insert(0, self)
        if spec is None or spec.loader is None:
            return spec
        run = spec.loader.exec_module
        def exec_module(module):
            depth[0] += 1
            t = time.perf_counter()
            try:
                run(module)
            finally:
                depth[0] -= 1
                if depth[0] == 0:
                    acc["matplotlib_import_s"] += time.perf_counter() - t
            if name == "matplotlib.figure":
                module.Figure.savefig = timed(module.Figure.savefig, "savefig_s", True)
                module.Figure.tight_layout = timed(module.Figure.tight_layout,
                                                   "tight_layout_s")
            if name == "matplotlib.layout_engine":
                for cls in (module.ConstrainedLayoutEngine, module.TightLayoutEngine):
                    cls.execute = timed(cls.execute, "layout_engine_s")
        spec.loader.exec_module = exec_module
        return spec

import importlib.util
sys.meta_path.insert(0, Hook())
from boundest.cli import main
try:
    rc = main(sys.argv[1:])
except SystemExit as e:
    rc = e.code
sys.stdout.flush()
print("BENCH_FIGURES " + json.dumps(acc), file=sys.stderr)
"""


def one_run(name: str, tree: Path | None, tmp: Path, timeout: float) -> dict:
    """One fresh process running ``boundest run NAME``; its wall time and the driver's timers."""
    env = dict(os.environ)
    if tree is not None:
        env["PYTHONPATH"] = str(tree / "src") + os.pathsep + env.get("PYTHONPATH", "")
    argv = [sys.executable, "-c", DRIVER, "run", name, "--out", str(tmp / "out")]
    load = os.getloadavg()[0]
    t0 = time.perf_counter()
    p = subprocess.run(argv, env=env, cwd=tmp, capture_output=True, text=True, timeout=timeout,
                       check=False)
    wall = time.perf_counter() - t0
    line = [ln for ln in p.stderr.splitlines() if ln.startswith("BENCH_FIGURES ")]
    out = {"wall_s": round(wall, 3), "rc": p.returncode, "loadavg_before": load}
    if line:
        out.update({k: round(v, 4) if isinstance(v, float) else v
                    for k, v in json.loads(line[-1].split(" ", 1)[1]).items()})
    else:
        out["stderr_tail"] = p.stderr[-1500:]
    if "compiling" in p.stderr:
        out["compiled"] = True
    return out


def summarise(runs: list[dict]) -> dict:
    keys = ("wall_s", "output_s", "savefig_s", "layout_engine_s", "matplotlib_import_s")
    return {f"{k}_median": round(statistics.median(r[k] for r in runs), 3)
            for k in keys if all(k in r for r in runs)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", help="comma-separated scenarios (default: all six)")
    ap.add_argument("--tree", action="append", type=Path,
                    help="a checkout to run (PYTHONPATH=TREE/src); repeat to compare "
                    "(default: the installed boundest)")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per tree (default 3)")
    ap.add_argument("--quick", action="store_true", help="one timed run, no warm-up")
    ap.add_argument("--timeout", type=float, default=600.0)
    ap.add_argument("--out", help="also write the JSON here")
    args = ap.parse_args()
    names = args.only.split(",") if args.only else list(SCENARIOS)
    trees: list[Path | None] = [t.resolve() for t in args.tree] if args.tree else [None]
    repeat = 1 if args.quick else args.repeat
    results = {}
    with tempfile.TemporaryDirectory(prefix="bench-figures-") as tmp:
        for name in names:
            runs: dict[str, list[dict]] = {str(t): [] for t in trees}
            if not args.quick:
                for t in trees:
                    one_run(name, t, Path(tmp), args.timeout)  # warm-up: caches, page cache
            for _ in range(repeat):
                for t in trees:
                    runs[str(t)].append(one_run(name, t, Path(tmp), args.timeout))
            results[name] = {t: {"runs": r, **summarise(r)} for t, r in runs.items()}
            for t, r in results[name].items():
                print(f"{name:>15} {Path(t).name if t != 'None' else 'installed':>12}: "
                      + ", ".join(f"{k} {v:.3f}" for k, v in r.items() if k != "runs"),
                      file=sys.stderr)
    import matplotlib
    import numba
    import numpy

    doc = {"benchmark": "figures", "machine": {
        "cpu": cpu_model(), "cpus": os.cpu_count(), "python": platform.python_version(),
        "numpy": numpy.__version__, "numba": numba.__version__,
        "matplotlib": matplotlib.__version__}, "repeat": repeat,
        "trees": [str(t) for t in trees], "results": results,
        "summary": {name: {t: {k: v for k, v in r.items() if k != "runs"}
                           for t, r in res.items()} for name, res in results.items()}}
    emit(doc, args.out)


if __name__ == "__main__":
    main()
