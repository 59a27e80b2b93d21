"""Codac 2.x side of the centered-form benchmark (``bench_centered.py``): ``CtcInverse`` on
batches of boxes, one ``contract`` call per box in a Python loop.

Run it with the interpreter of ``.bench-venv-codac2/`` (``pip install "codac==2.1.2" numpy``),
never in the process that runs boundest: importing codac switches the FPU to rounding upward
(``fegetround`` is recorded before and after the import). Input: a JSON file in which every
float is a ``float.hex`` string, decoded *before* codac is imported. Output: one JSON document
on stdout (bounds as ``float.hex`` strings, an empty box as ``"nan"`` bounds); progress on
stderr.

Spec fields: ``repeat``; ``problems``: a list of ``name``, ``n``, ``exprs`` (Python expression
strings in ``x[i]``, ``sin``, ``cos``, ``sqrt``, ``sqr``, ``cube``, ``+ - * /`` and float
literals: the same strings build boundest's model), ``t_lo``, ``t_hi`` (the target interval of
each expression), ``modes`` (``default``: ``CtcInverse(f, y)``, Codac's default, a forward
evaluation, the centered step, then the backward evaluation; ``hc4``:
``CtcInverse(f, y, False)``, forward-backward only), ``batches``: a list of ``key``, ``lo``,
``hi`` (boxes, flat row-major, ``N x n``); optional ``jacobian_boxes`` (``k``: also write
``f.diff`` -- Codac's Jacobian enclosure, forward mode -- on the first ``k`` boxes of each
batch, flat ``k x m x n``).

Each mode and batch: the boxes are built as ``IntervalVector`` before the clock starts (a fresh
copy per run), then ``ctc.contract(box)`` is called on each in a Python loop (``contract_s``:
median of ``repeat`` runs). ``build_contract_s`` times building the boxes from Python lists and
contracting them, once: what a user with the boxes in lists pays.

Usage::

    .bench-venv-codac2/bin/python benchmarks/centered_codac2.py SPEC.json > OUT.json
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


def _log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def main() -> None:
    with open(sys.argv[1]) as fh:
        spec = decode_hex(json.load(fh))      # decoded under round-to-nearest, before codac
    mode_before = fegetround()
    t0 = time.perf_counter()
    import codac
    from codac import (
        AnalyticFunction,
        CtcInverse,
        IntervalVector,
        VectorVar,
        cos,
        sin,
        sqr,
        sqrt,
        vec,
    )
    import_s = time.perf_counter() - t0
    mode_after = fegetround()
    repeat = max(1, int(spec.get("repeat", 3)))

    out_problems = []
    for prob in spec["problems"]:
        n = int(prob["n"])
        x = VectorVar(n)
        ns = {"x": x, "sin": sin, "cos": cos, "sqrt": sqrt, "sqr": sqr,
              "cube": lambda e: e ** 3, "__builtins__": {}}
        exprs = [eval(e, ns) for e in prob["exprs"]]
        f = AnalyticFunction([x], vec(*exprs))
        y = IntervalVector([[a, b] for a, b in zip(prob["t_lo"], prob["t_hi"], strict=True)])
        ctcs = {"default": CtcInverse(f, y), "hc4": CtcInverse(f, y, False)}
        rec = {"name": prob["name"], "batches": {}}
        for batch in prob["batches"]:
            lo, hi = batch["lo"], batch["hi"]
            rows = [[[lo[i * n + j], hi[i * n + j]] for j in range(n)]
                    for i in range(len(lo) // n)]
            brec = {}
            for mode in prob.get("modes", ["default", "hc4"]):
                ctc = ctcs[mode]
                times, boxes = [], []
                for _ in range(repeat):
                    boxes = [IntervalVector(r) for r in rows]
                    t1 = time.perf_counter()
                    for b in boxes:
                        ctc.contract(b)
                    times.append(time.perf_counter() - t1)
                t1 = time.perf_counter()
                for r in rows:
                    ctc.contract(IntervalVector(r))
                build_s = time.perf_counter() - t1
                olo, ohi = [], []
                for b in boxes:
                    if b.is_empty():
                        olo += ["nan"] * n
                        ohi += ["nan"] * n
                    else:
                        olo += [_h(b[j].lb()) for j in range(n)]
                        ohi += [_h(b[j].ub()) for j in range(n)]
                med = statistics.median(times)
                _log(f"codac2 {prob['name']} {batch['key']} {mode}: {len(rows)} boxes, "
                     f"{med:.3f} s ({1e6 * med / max(1, len(rows)):.1f} us/box)")
                brec[mode] = {"contract_s": med, "contract_times_s": times,
                              "build_contract_s": build_s, "lo": olo, "hi": ohi}
            k = min(int(prob.get("jacobian_boxes", 0)), len(rows))
            if k:  # Codac's Jacobian enclosure (forward mode) on the first k input boxes
                jlo, jhi = [], []
                for r in rows[:k]:
                    jac = f.diff(IntervalVector(r))
                    for i in range(jac.rows()):
                        for j in range(jac.cols()):
                            jlo.append(_h(jac(i, j).lb()))
                            jhi.append(_h(jac(i, j).ub()))
                brec["jacobian"] = {"lo": jlo, "hi": jhi}
            rec["batches"][batch["key"]] = brec
        out_problems.append(rec)

    version = getattr(codac, "__version__", None)
    if version is None:
        from importlib.metadata import version as _v
        version = _v("codac")
    doc = {"codac_version": version, "python": sys.version.split()[0], "import_s": import_s,
           "fegetround_before_import": mode_before, "fegetround_after_import": mode_after,
           "fegetround_end": fegetround(), "repeat": repeat, "problems": out_problems}
    print(json.dumps(doc))


if __name__ == "__main__":
    main()
