"""Codac 1.5.7 side of the interval Newton comparison in ``bench_centered.py``: ``CtcNewton``
(IBEX's, as Codac 1 wraps it) on batches of boxes, one ``contract`` call per box in a Python
loop.

Run it with the interpreter of ``.bench-venv-codac1/`` (``pip install codac==1.5.7``), never in
the process that runs boundest (importing codac switches the FPU to rounding upward; recorded
with ``fegetround``). Input: a JSON file, floats as ``float.hex`` strings, decoded before codac
is imported. Output: one JSON document on stdout (bounds as ``float.hex``, an empty box as
``"nan"`` bounds); progress on stderr.

Spec fields: ``repeat``; ``problems``: a list of ``name``, ``n``, ``ibex`` (the function in
IBEX's syntax, argument ``x[n]``: ``"(f_1; ...; f_n)"``, solved for ``f = 0``), ``modes`` (a
list of ``name``, ``prec``, ``ratio``: ``CtcNewton(f, ceil, prec, ratio)`` with ``ceil`` huge so
that every box is contracted; IBEX's ``newton`` repeats its step while a bound moves by
``prec`` or more, so ``prec`` huge is one step, and Gauss-Seidel repeats its sweeps while they
gain more than ``ratio``), ``batches`` (``key``, ``lo``, ``hi``: flat row-major ``N x n``).

Usage::

    .bench-venv-codac1/bin/python benchmarks/newton_codac1.py SPEC.json > OUT.json
"""

from __future__ import annotations

import json
import math
import statistics
import sys
import time

from _subprocess import decode_hex, fegetround


def _h(v: float) -> str:
    return "nan" if math.isnan(v) else float(v).hex()


def main() -> None:
    with open(sys.argv[1]) as fh:
        spec = decode_hex(json.load(fh))
    mode_before = fegetround()
    t0 = time.perf_counter()
    from codac import CtcNewton, Function, IntervalVector
    import_s = time.perf_counter() - t0
    mode_after = fegetround()
    repeat = max(1, int(spec.get("repeat", 3)))

    out = []
    for prob in spec["problems"]:
        n = int(prob["n"])
        f = Function(f"x[{n}]", prob["ibex"])
        rec = {"name": prob["name"], "batches": {}}
        for batch in prob["batches"]:
            lo, hi = batch["lo"], batch["hi"]
            rows = [[[lo[i * n + j], hi[i * n + j]] for j in range(n)]
                    for i in range(len(lo) // n)]
            brec = {}
            for mode in prob["modes"]:
                ctc = CtcNewton(f, 1e300, float(mode["prec"]), float(mode["ratio"]))
                times, boxes = [], []
                for _ in range(repeat):
                    boxes = [IntervalVector(r) for r in rows]
                    t1 = time.perf_counter()
                    for b in boxes:
                        ctc.contract(b)
                    times.append(time.perf_counter() - t1)
                olo, ohi = [], []
                for b in boxes:
                    if b.is_empty():
                        olo += ["nan"] * n
                        ohi += ["nan"] * n
                    else:
                        olo += [_h(b[j].lb()) for j in range(n)]
                        ohi += [_h(b[j].ub()) for j in range(n)]
                med = statistics.median(times)
                print(f"codac1 {prob['name']} {batch['key']} {mode['name']}: {len(rows)} boxes,"
                      f" {med:.3f} s", file=sys.stderr, flush=True)
                brec[mode["name"]] = {"contract_s": med, "contract_times_s": times,
                                      "lo": olo, "hi": ohi}
            rec["batches"][batch["key"]] = brec
        out.append(rec)

    from importlib.metadata import version
    print(json.dumps({"codac_version": version("codac"), "python": sys.version.split()[0],
                      "import_s": import_s, "fegetround_before_import": mode_before,
                      "fegetround_after_import": mode_after, "fegetround_end": fegetround(),
                      "repeat": repeat, "problems": out}))


if __name__ == "__main__":
    main()
