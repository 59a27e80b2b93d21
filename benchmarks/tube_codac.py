"""Codac 1.5.7 side of the raw tube benchmark; run by bench_tube.py.

Run it with the interpreter of ``.bench-venv-codac1/`` (``codac==1.5.7``), never in the process
that runs boundest (importing codac switches the FPU to rounding upward). Input: a JSON spec and
raw float64 files written by ``bench_tube.py`` (read before codac is imported; raw binary floats
are exact whatever the rounding mode). For each size it builds the same tubes as boundest
(same gate times; the derivative tube's slice bounds are copied, its gates are Codac's default:
the contractors of both libraries read only the derivative's slices; building is not timed),
then times, as the median of ``repeat`` runs on fresh copies:

``deriv``  ``CtcDeriv().contract(x, v)``: ``x`` entire but ``x(0) in [0, 0.1]``;
``eval``   ``CtcEval().contract(t, z, y, w)`` with ``y`` = [-100, 100], ``w = v``,
           ``t = [4, 5]``, ``z = [0, 0.5]``, ``preserve_slicing(True)`` (same slices as
           boundest; Codac would otherwise add gates at the bounds of ``t``);
``unit``   Codac's own CtcEval unit cases (``unit_cases`` below): the contracted ``t``, ``z``.

Output: one JSON document on stdout (floats as ``float.hex`` strings).

Usage::

    .bench-venv-codac1/bin/python benchmarks/tube_codac.py SPEC.json
"""

from __future__ import annotations

import json
import statistics
import sys
import time
from pathlib import Path


def main() -> None:
    spec = json.loads(Path(sys.argv[1]).read_text())
    import numpy as np

    cases = []
    for c in spec["cases"]:
        arr = {k: np.fromfile(c[k], dtype=np.float64) for k in ("t", "v_slo", "v_shi")}
        cases.append((c, arr))
    repeat = int(spec["repeat"])
    import codac
    from codac import CtcDeriv, CtcEval, Interval, Tube

    out = {"codac_version": codac.__version__ if hasattr(codac, "__version__") else "1.5.7",
           "cases": []}
    for c, arr in cases:
        n = int(c["n"])
        t = arr["t"]
        start = time.perf_counter()
        tdom = [Interval(t[i], t[i + 1]) for i in range(n)]
        slo, shi = arr["v_slo"], arr["v_shi"]
        v = Tube(tdom, [Interval(slo[i], shi[i]) for i in range(n)])
        x = Tube(tdom, [Interval() for _ in range(n)])
        x.set(Interval(0.0, 0.1), float(t[0]))
        y0 = Tube(tdom, [Interval(-100.0, 100.0) for _ in range(n)])
        tf = float(t[-1])
        build_s = time.perf_counter() - start
        row = {"n": n, "build_s": build_s}
        times, xc = [], None
        for _ in range(repeat):
            xc = Tube(x)
            ctc = CtcDeriv()
            a = time.perf_counter()
            ctc.contract(xc, v)
            times.append(time.perf_counter() - a)
        row["deriv_s"] = statistics.median(times)
        row["deriv_volume"] = float(xc.volume()).hex()
        row["deriv_max_diam"] = float(xc.max_diam()).hex()
        g = xc(tf)
        row["deriv_last_gate"] = [float(g.lb()).hex(), float(g.ub()).hex()]
        times = []
        for _ in range(repeat):
            yc = Tube(y0)
            tt, zz = Interval(4.0, 5.0), Interval(0.0, 0.5)
            ctc = CtcEval()
            ctc.preserve_slicing(True)
            a = time.perf_counter()
            ctc.contract(tt, zz, yc, v)
            times.append(time.perf_counter() - a)
        row["eval_s"] = statistics.median(times)
        row["eval_volume"] = float(yc.volume()).hex()
        row["eval_max_diam"] = float(yc.max_diam()).hex()
        row["eval_t"] = [float(tt.lb()).hex(), float(tt.ub()).hex()]
        row["eval_z"] = [float(zz.lb()).hex(), float(zz.ub()).hex()]
        out["cases"].append(row)
    out["unit_cases"] = unit_cases(spec.get("unit_cases", []))
    json.dump(out, sys.stdout)


def unit_cases(cases: list) -> list:
    """Codac's own CtcEval unit cases (tests_ctc_eval.cpp): ``special`` on the tube of its
    "special cases" (10 unit slices, x' in [-0.5, 1], slices 4, 5 in [-1.5, 1], [-1, 1.5],
    then CtcDeriv), ``case2`` its "CtcEval, 2" (two evaluations on a tube with x(2) in [0, 1]).
    Slicing preserved, temporal propagation on (Codac's defaults apart from the slicing)."""
    from codac import CtcDeriv, CtcEval, Interval, Tube

    out = []
    for c in cases:
        if c["kind"] == "special":
            xdot = Tube(Interval(0.0, 10.0), 1.0)
            xdot.set(Interval(-0.5, 1.0))
            x = Tube(xdot)
            x.set(Interval())
            x.set(Interval(-1.5, 1.0), 4)
            x.set(Interval(-1.0, 1.5), 5)
            CtcDeriv().contract(x, xdot)
            evals = [(c["t"], c["z"])]
        else:
            x = Tube(Interval(-1.0, 7.0), 2.0)
            xdot = Tube(x)
            for k, val in enumerate([(-1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, 1.0)]):
                xdot.set(Interval(*val), k)
            x.set(Interval(0.0, 1.0), 2.0)
            xdot.sample(2.0)
            evals = [((0.0, 6.0), (-1.0, 1.0)), (c["t"], c["z"])]
        for tt, zz in evals:
            ctc = CtcEval()
            ctc.preserve_slicing(True)
            T, Z = Interval(*tt), Interval(*zz)
            ctc.contract(T, Z, x, xdot)
        out.append({"name": c["name"], "t": [float(T.lb()).hex(), float(T.ub()).hex()],
                    "z": [float(Z.lb()).hex(), float(Z.ub()).hex()]})
    return out


if __name__ == "__main__":
    main()
