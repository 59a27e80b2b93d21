"""Codac 1.5.7 side of the polar benchmark; run by bench_polar.py.

Run with ``.bench-venv-codac1/bin/python`` in its own process (importing codac switches the FPU
to rounding upward). Input: a JSON file with the boxes ``(x, y, rho, theta)`` as ``float.hex``
strings (``lo``, ``hi``: lists of rows), decoded before codac is imported, and ``repeat``.
Each box is an ``IntervalVector`` contracted by ``codac.CtcPolar`` (a Python loop: pybind11
has no batch call). Output: the median time of the whole batch and the contracted bounds.

Usage: ``.bench-venv-codac1/bin/python benchmarks/polar_codac.py INPUT.json``
"""

from __future__ import annotations

import json
import statistics
import sys
import time


def main() -> None:
    with open(sys.argv[1]) as fh:
        spec = json.load(fh)
    lo = [[float.fromhex(v) for v in row] for row in spec["lo"]]
    hi = [[float.fromhex(v) for v in row] for row in spec["hi"]]
    repeat = int(spec["repeat"])
    import codac
    from codac import CtcPolar, IntervalVector

    ctc = CtcPolar()
    boxes = [[[a, b] for a, b in zip(r0, r1, strict=True)] for r0, r1 in zip(lo, hi, strict=True)]
    times, out = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = []
        for rows in boxes:
            box = IntervalVector(rows)
            ctc.contract(box)
            res.append(box)
        times.append(time.perf_counter() - t0)
        out = res
    # empty boxes as None (JSON has no NaN)
    bounds = [None if b.is_empty() else [[b[i].lb(), b[i].ub()] for i in range(4)] for b in out]
    json.dump({"codac": codac.__version__ if hasattr(codac, "__version__") else "1.5.7",
               "time_s": statistics.median(times), "bounds": bounds}, sys.stdout)


if __name__ == "__main__":
    main()
