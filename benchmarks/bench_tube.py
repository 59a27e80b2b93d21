"""Raw tube contractor throughput: boundest's CtcDeriv and CtcEval against Codac 1.5.7.

For n = 10^4, 10^5, 10^6 slices over [0, 10] (dt = 10 / n), with the derivative tube
``v(t) = sin(t) + [-0.01, 0.01]`` (boundest.interval enclosures on the slices and gates, copied
bound for bound into Codac's tube):

``deriv``  ``CtcDeriv`` on ``x`` entire but ``x(0) in [0, 0.1]``: forward and backward over
           every slice; reported: median time, slices per second, the volume of ``x``
           (sum of slice widths x dt), its largest slice width and its last gate;
``eval``   ``CtcEval`` with ``t in [4, 5]``, ``z in [0, 0.5]``, ``y`` = [-100, 100], ``w = v``:
           the measurement is propagated forward and backward over the whole tube; reported:
           median time, slices per second, volume and largest slice width of ``y``, ``t``, ``z``.

Each time is the median of ``--repeat`` runs on fresh copies (copying excluded), after a
warm-up run (Numba compilation is excluded; the kernels are cached on disk). Codac runs in a
subprocess of ``.bench-venv-codac1/bin/python`` (``benchmarks/tube_codac.py``) on the same
tubes; ``speedup`` = Codac time / boundest time and ``width_ratio`` = Codac volume / boundest
volume (> 1: boundest is tighter).

Usage::

    .venv/bin/python benchmarks/bench_tube.py [--out benchmarks/results/tube.json]
        [--repeat 5] [--sizes 10000 100000 1000000] [--no-codac]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
from _machine import cpu_model
from _subprocess import run_json_script

import boundest.interval as iv
from boundest import Interval
from boundest.tube import CtcDeriv, CtcEval, Tube

ROOT = Path(__file__).resolve().parent.parent
CODAC_PY = ROOT / ".bench-venv-codac1" / "bin" / "python"
CODAC_SCRIPT = Path(__file__).resolve().parent / "tube_codac.py"
T0, TF = 0.0, 10.0


def _v_tube(n: int) -> Tube:
    return Tube.from_function(T0, TF, TF / n, lambda T: iv.sin(T) + Interval(-0.01, 0.01))


def _median_time(make: Any, run: Any, repeat: int) -> tuple[float, Any]:
    run(make())  # warm-up
    times, last = [], None
    for _ in range(repeat):
        arg = make()
        a = time.perf_counter()
        last = run(arg)
        times.append(time.perf_counter() - a)
    return statistics.median(times), last


def bench_boundest(n: int, repeat: int) -> dict[str, Any]:
    v = _v_tube(n)
    x0 = Tube.constant(T0, TF, TF / n, Interval.entire())
    x0.gates[0] = Interval(0.0, 0.1)

    def run_deriv(x: Tube) -> Tube:
        return CtcDeriv().contract(x, v)

    t_d, x = _median_time(x0.copy, run_deriv, repeat)
    y0 = Tube.constant(T0, TF, TF / n, Interval(-100.0, 100.0))

    def run_eval(y: Tube) -> tuple[Tube, Interval, Interval]:
        t, z = CtcEval().contract(Interval(4.0, 5.0), Interval(0.0, 0.5), y, v)
        return y, t, z

    t_e, (y, t, z) = _median_time(y0.copy, run_eval, repeat)
    g = x.gates[-1]
    return {"n": n, "deriv_s": t_d, "deriv_slices_per_s": n / t_d,
            "deriv_volume": x.volume(), "deriv_max_diam": x.max_thickness(),
            "deriv_last_gate": [float(g.lo), float(g.hi)],
            "eval_s": t_e, "eval_slices_per_s": n / t_e, "eval_volume": y.volume(),
            "eval_max_diam": y.max_thickness(), "eval_t": [float(t.lo), float(t.hi)],
            "eval_z": [float(z.lo), float(z.hi)]}


def bench_codac(sizes: list[int], repeat: int) -> dict[str, Any] | None:
    if not CODAC_PY.exists():
        print(f"codac 1.5.7 venv not found at {CODAC_PY}: skipped", file=sys.stderr)
        return None
    with tempfile.TemporaryDirectory() as tmp:
        cases = []
        for n in sizes:
            v = _v_tube(n)
            files = {}
            for key, arr in (("t", v.t), ("v_slo", v.slices.lo), ("v_shi", v.slices.hi)):
                path = os.path.join(tmp, f"{key}_{n}.bin")
                np.ascontiguousarray(arr, dtype=np.float64).tofile(path)
                files[key] = path
            cases.append({"n": n, **files})
        try:
            out = run_json_script(CODAC_PY, CODAC_SCRIPT, {"cases": cases, "repeat": repeat})
        except RuntimeError as exc:
            print(f"codac run failed: {exc}", file=sys.stderr)
            return None
    for row in out["cases"]:
        for k, val in list(row.items()):
            if isinstance(val, str):
                row[k] = float.fromhex(val)
            elif isinstance(val, list):
                row[k] = [float.fromhex(u) for u in val]
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--sizes", type=int, nargs="+", default=[10**4, 10**5, 10**6])
    ap.add_argument("--no-codac", action="store_true")
    args = ap.parse_args()
    rows = []
    for n in args.sizes:
        print(f"boundest n = {n}", file=sys.stderr)
        rows.append(bench_boundest(n, args.repeat))
    codac = None if args.no_codac else bench_codac(args.sizes, args.repeat)
    if codac is not None:
        for row, c in zip(rows, codac["cases"], strict=True):
            row["codac"] = c
            row["deriv_speedup"] = c["deriv_s"] / row["deriv_s"]
            row["eval_speedup"] = c["eval_s"] / row["eval_s"]
            row["deriv_width_ratio"] = c["deriv_volume"] / row["deriv_volume"]
            row["eval_width_ratio"] = c["eval_volume"] / row["eval_volume"]
    doc = {"benchmark": "tube", "machine": {"cpu": cpu_model(), "cores": os.cpu_count(),
                                            "python": platform.python_version()},
           "repeat": args.repeat, "codac": None if codac is None else "1.5.7", "rows": rows}
    text = json.dumps(doc, indent=1)
    print(text)
    if args.out:
        args.out.write_text(text + "\n")
    for r in rows:
        line = (f"n={r['n']:>8}  deriv {r['deriv_s'] * 1e3:8.2f} ms  eval "
                f"{r['eval_s'] * 1e3:8.2f} ms")
        if "codac" in r:
            line += (f"  | codac deriv {r['codac']['deriv_s'] * 1e3:8.2f} ms "
                     f"(x{r['deriv_speedup']:.1f}, widths x{r['deriv_width_ratio']:.3f})  "
                     f"eval {r['codac']['eval_s'] * 1e3:8.2f} ms (x{r['eval_speedup']:.1f}, "
                     f"widths x{r['eval_width_ratio']:.3f})")
        print(line, file=sys.stderr)


if __name__ == "__main__":
    main()
