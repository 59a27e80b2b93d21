"""Raw tube contractor throughput: boundest's CtcDeriv and CtcEval against Codac 1.5.7.

For n = 10^4, 10^5, 10^6 slices over [0, 10] (dt = 10 / n), with the derivative tube
``v(t) = sin(t) + [-0.01, 0.01]`` (boundest.interval enclosures on the slices and gates, copied
bound for bound into Codac's tube):

``deriv``  ``CtcDeriv`` on ``x`` entire but ``x(0) in [0, 0.1]``: forward and backward over
           every slice; reported: median time, slices per second, the volume of ``x``
           (sum of slice widths x dt), its largest slice width and its last gate;
``eval``   ``CtcEval`` with ``t in [4, 5]``, ``z in [0, 0.5]``, ``y`` = [-100, 100], ``w = v``:
           the measurement is propagated forward and backward over the whole tube; reported:
           median time, slices per second, volume and largest slice width of ``y``, ``t``, ``z``;
``unit``   Codac's own CtcEval unit cases (``UNIT_CASES``), the contracted ``t`` and ``z`` of
           ``CtcEval()`` (time contraction with the derivative), of ``CtcEval(time_deriv=False)``
           (the plain inverse) and of Codac's ``CtcEval`` (``codac_unit_cases`` in the JSON).

Each time is the median of ``--repeat`` runs on fresh copies (copying excluded), after a
warm-up run (Numba compilation is excluded; the kernels are cached on disk). Codac runs in a
subprocess of ``.bench-venv-codac1/bin/python`` (``benchmarks/tube_codac.py``) on the same
tubes; ``speedup`` = Codac time / boundest time and ``width_ratio`` = Codac volume / boundest
volume (> 1: boundest is tighter).

Usage::

    .venv/bin/python benchmarks/bench_tube.py [--out benchmarks/results/tube.json]
        [--repeat 5] [--sizes 10000 100000 1000000] [--no-codac] [--codac-python PY]
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


#: Codac's own CtcEval unit cases (tests_ctc_eval.cpp): name, [t], [z]; ``special`` on the
#: tube of its "special cases", ``case2`` the second evaluation of its "CtcEval, 2".
UNIT_CASES = [{"kind": "special", "name": "C", "t": (0.5, 3.5), "z": (-4.0, -4.0)},
              {"kind": "special", "name": "E", "t": (6.5, 8.5), "z": (-4.5, -1.75)},
              {"kind": "special", "name": "G", "t": (6.5, 7.5), "z": (3.0, 4.0)},
              {"kind": "special", "name": "F", "t": (8.5, 9.5), "z": (-0.5, 2.5)},
              {"kind": "special", "name": "B", "t": (0.5, 2.5), "z": (-2.0, -2.0)},
              {"kind": "special", "name": "D", "t": (3.5, 3.5), "z": (-3.5, -0.5)},
              {"kind": "case2", "name": "2", "t": (1.75, 5.5), "z": (1.6, 1.6)}]


def bench_unit_cases(time_deriv: bool) -> list[dict[str, Any]]:
    """boundest's ``CtcEval(time_deriv)`` on Codac's unit cases (same tubes, same order)."""
    out = []
    for c in UNIT_CASES:
        if c["kind"] == "special":
            xd = Tube.constant(0, 10, 10, Interval(-0.5, 1))
            s = Interval.entire(10)
            s[4], s[5] = Interval(-1.5, 1), Interval(-1, 1.5)
            x = Tube(np.arange(11.0), s)
            CtcDeriv().contract(x, xd)
            evals = [(c["t"], c["z"])]
        else:
            gt = np.array([-1.0, 1, 2, 3, 5, 7])
            x = Tube(gt, Interval.entire(5))
            x.gates[2] = Interval(0, 1)
            xd = Tube.piecewise_constant(gt, Interval([-1, -1, -1, -1, 1], [-1, 1, 1, -1, 1]))
            evals = [((0.0, 6.0), (-1.0, 1.0)), (c["t"], c["z"])]
        for tt, zz in evals:
            t, z = CtcEval(time_deriv).contract(Interval(*tt), Interval(*zz), x, xd)
        out.append({"name": c["name"], "t": [float(t.lo), float(t.hi)],
                    "z": [float(z.lo), float(z.hi)]})
    return out


def bench_codac(sizes: list[int], repeat: int, python: Path = CODAC_PY
                ) -> dict[str, Any] | None:
    if not python.exists():
        print(f"codac 1.5.7 venv not found at {python}: skipped", file=sys.stderr)
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
            out = run_json_script(python, CODAC_SCRIPT, {"cases": cases, "repeat": repeat,
                                                           "unit_cases": UNIT_CASES})
        except RuntimeError as exc:
            print(f"codac run failed: {exc}", file=sys.stderr)
            return None
    for row in out["cases"] + out["unit_cases"]:
        for k, val in list(row.items()):
            if k == "name":
                continue
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
    ap.add_argument("--codac-python", type=Path, default=CODAC_PY)
    args = ap.parse_args()
    rows = []
    for n in args.sizes:
        print(f"boundest n = {n}", file=sys.stderr)
        rows.append(bench_boundest(n, args.repeat))
    codac = None if args.no_codac else bench_codac(args.sizes, args.repeat, args.codac_python)
    if codac is not None:
        for row, c in zip(rows, codac["cases"], strict=True):
            row["codac"] = c
            row["deriv_speedup"] = c["deriv_s"] / row["deriv_s"]
            row["eval_speedup"] = c["eval_s"] / row["eval_s"]
            row["deriv_width_ratio"] = c["deriv_volume"] / row["deriv_volume"]
            row["eval_width_ratio"] = c["eval_volume"] / row["eval_volume"]
    unit = []
    for deriv, plain, *c in zip(bench_unit_cases(True), bench_unit_cases(False),
                                *([codac["unit_cases"]] if codac is not None else []),
                                strict=True):
        row = {"case": deriv["name"], "t": deriv["t"], "z": deriv["z"], "t_plain": plain["t"],
               "t_width": deriv["t"][1] - deriv["t"][0],
               "t_plain_width": plain["t"][1] - plain["t"][0]}
        if c:
            row.update(codac_t=c[0]["t"], codac_z=c[0]["z"],
                       codac_t_width=c[0]["t"][1] - c[0]["t"][0])
            row["t_excess_over_codac"] = row["t_width"] - row["codac_t_width"]
            row["t_plain_excess_over_codac"] = row["t_plain_width"] - row["codac_t_width"]
        unit.append(row)
    doc = {"benchmark": "tube", "machine": {"cpu": cpu_model(), "cores": os.cpu_count(),
                                            "python": platform.python_version()},
           "repeat": args.repeat, "codac": None if codac is None else "1.5.7", "rows": rows,
           "codac_unit_cases": unit}
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
    for u in unit:
        print(f"unit case {u['case']}: t {u['t']} (plain {u['t_plain']})"
              + (f", codac {u['codac_t']}" if "codac_t" in u else ""), file=sys.stderr)


if __name__ == "__main__":
    main()
