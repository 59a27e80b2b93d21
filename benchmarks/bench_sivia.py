"""SIVIA benchmark: boxes per second on a 2-D ring and a 3-D shell, against Codac 2.1.2 and 1.5.7.

Problems (``shell`` of dimension 2 and 3): ``{x in [-3, 3]^dim : 1 <= |x|^2 <= 4}``. For each
``eps`` (2-D: 1e-1, 1e-2, 1e-3; 3-D: 1e-1, 3e-2, 1e-2 by default: 1e-3 in 3-D would need about
2e8 boxes), it reports for boundest:

``contractors``  ``sivia(X, f=|x|^2, y=[1, 4], eps)``: the forward-backward contractor of the set
                 and of its complement, the whole frontier as one batch per iteration;
``test``         ``sivia(X, test=..., eps)`` with the natural interval extension of ``|x|^2``
                 (inside when the image lies in ``[1, 4]``, outside when disjoint),

the median wall time of ``--repeat`` runs after a warm-up run, the boxes processed (classified)
and the boxes of the result (inside, boundary), the rates ``processed / time`` and
``result boxes / time``, and the inner and outer areas/volumes (the exact one is ``3 pi`` in 2-D,
``28 pi / 3`` in 3-D). Then the same problems with Codac, each in a subprocess of its own venv
(``benchmarks/sivia_codac.py``; importing codac switches the FPU to rounding upward):

* codac 2.1.2 ``pave(X, SepInverse(f, [1, 4]), eps)`` (pairs with ``contractors``) and
  ``sivia(X, f, [1, 4], eps)`` (pairs with ``test``): nodes of the paving tree (boxes processed),
  inside and boundary boxes;
* codac 1.5.7 ``SIVIA(X, SepFwdBwd(f, [1, 4]), eps)`` (pairs with ``contractors``): the lengths of
  the IN / UNKNOWN / OUT lists.

Each boundest row gets ``vs_codac``: Codac time / boundest time (speed-up), and the ratio of
boundary boxes (boundest / Codac) that says whether the pavings are alike (same within 10 %).

Usage::

    .venv/bin/python benchmarks/bench_sivia.py [--out sivia.json] [--repeat 5] [--no-codac]
        [--eps2 1e-1,1e-2,1e-3] [--eps3 1e-1,3e-2,1e-2] [--quick]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
from _machine import cpu_model
from _subprocess import run_json_script

ROOT = Path(__file__).resolve().parent.parent
CODAC_SCRIPT = Path(__file__).resolve().parent / "sivia_codac.py"
CODAC = {"codac2": (ROOT / ".bench-venv" / "bin" / "python", ["pave", "sivia"]),
         "codac1": (ROOT / ".bench-venv-codac1" / "bin" / "python", ["SIVIA"])}
#: which Codac variant computes the same paving as which boundest variant
PAIRS = {"contractors": [("codac2", "pave"), ("codac1", "SIVIA")],
         "test": [("codac2", "sivia")]}
LO, HI, A, B = -3.0, 3.0, 1.0, 4.0


def _cases(eps2: list[float], eps3: list[float]) -> list[dict]:
    return [{"label": f"shell{d}d eps={e:g}", "dim": d, "eps": e}
            for d, es in ((2, eps2), (3, eps3)) for e in es]


def _natural_test(xb: Any) -> np.ndarray:
    from boundest import interval as iv

    z = iv.sqr(xb[:, 0])
    for i in range(1, xb.shape[1]):
        z = z + iv.sqr(xb[:, i])
    inside = (z.lo >= A) & (z.hi <= B)
    out = (z.hi < A) | (z.lo > B)
    return np.where(inside, 1, np.where(out, -1, 0)).astype(np.int8)


def _bench_boundest(case: dict, variant: str, repeat: int, long_s: float) -> dict:
    from boundest.expr import Var
    from boundest.interval import Interval
    from boundest.paving import sivia

    d, eps = case["dim"], case["eps"]
    xs = [Var(n) for n in "xyz"[:d]]
    f = sum((v**2 for v in xs[1:]), xs[0] ** 2)
    box = Interval([LO] * d, [HI] * d)

    def run() -> Any:
        if variant == "contractors":
            return sivia(box, f=f, y=Interval([A], [B]), eps=eps)
        return sivia(box, test=_natural_test, eps=eps)

    t = time.perf_counter()
    sp = run()
    first = time.perf_counter() - t
    n = repeat if first < long_s else max(1, min(repeat, 2))
    times = []
    for _ in range(n):
        t = time.perf_counter()
        run()
        times.append(time.perf_counter() - t)
    med = statistics.median(times)
    k = int(sp.inside.sum())
    exact = 3 * math.pi if d == 2 else 28 * math.pi / 3
    return {"label": case["label"], "dim": d, "eps": eps, "variant": variant,
            "first_run_s": first, "times_s": times, "time_s": med,
            "processed": sp.stats["processed"], "iterations": sp.stats["iterations"],
            "inside": k, "boundary": len(sp) - k, "result_boxes": len(sp),
            "processed_per_s": sp.stats["processed"] / med, "result_boxes_per_s": len(sp) / med,
            "volume_inner": sp.volume_inner(), "volume_outer": sp.volume_outer(),
            "volume_exact": exact,
            "encloses_exact": sp.volume_inner() <= exact <= sp.volume_outer()}


def _run_codac(which: str, cases: list[dict], repeat: int, long_s: float, timeout: float
               ) -> dict:
    python, variants = CODAC[which]
    if not python.exists():
        return {"skipped": f"{python} not found"}
    spec = {"cases": [{"label": c["label"], "dim": c["dim"], "lo": LO.hex(), "hi": HI.hex(),
                       "a": A.hex(), "b": B.hex(), "eps": float(c["eps"]).hex()}
                      for c in cases],
            "repeat": repeat, "long_s": long_s, "variants": variants}
    try:
        out = run_json_script(python, CODAC_SCRIPT, spec, timeout)
    except RuntimeError as exc:
        return {"skipped": str(exc)[-1500:]}
    for r in out["results"]:
        r["eps"] = float.fromhex(r["eps"])
        if "processed" in r:
            r["processed_per_s"] = r["processed"] / r["time_s"]
        r["result_boxes"] = r["inside"] + r["boundary"]
        r["result_boxes_per_s"] = r["result_boxes"] / r["time_s"]
    return out


def _compare(rows: list[dict], codac: dict) -> None:
    for row in rows:
        cmp = {}
        for which, variant in PAIRS[row["variant"]]:
            for r in codac.get(which, {}).get("results", []):
                if r["label"] == row["label"] and r["variant"] == variant:
                    cmp[f"{which}_{variant}"] = {
                        "speedup": r["time_s"] / row["time_s"],
                        "boundary_ratio": row["boundary"] / max(1, r["boundary"]),
                        "same_paving_10pct": abs(row["boundary"] / max(1, r["boundary"]) - 1)
                        <= 0.10,
                        "processed_ratio": (row["processed"] / r["processed"]
                                            if "processed" in r else None)}
        row["vs_codac"] = cmp


def _summary(rows: list[dict]) -> list[dict]:
    """One line per case and boundest variant: time, rate, and Codac's paired figures."""
    out = []
    for r in rows:
        line = {"case": r["label"], "variant": r["variant"], "time_s": round(r["time_s"], 5),
                "processed": r["processed"], "boundary": r["boundary"],
                "boxes_per_s": round(r["processed_per_s"])}
        for key, c in r["vs_codac"].items():
            line[f"{key}_speedup"] = round(c["speedup"], 2)
            line[f"{key}_boundary_ratio"] = round(c["boundary_ratio"], 3)
        out.append(line)
    return out


def _machine() -> dict:
    import numba

    import boundest
    return {"python": sys.version.split()[0], "platform": platform.platform(),
            "cpu_model": cpu_model(), "cpu_count": os.cpu_count(), "numpy": np.__version__,
            "numba": numba.__version__, "boundest": getattr(boundest, "__version__", None),
            "loadavg_end": list(os.getloadavg()) if hasattr(os, "getloadavg") else None}


def _floats(s: str) -> list[float]:
    return [float(v) for v in s.split(",") if v]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--long", type=float, default=5.0,
                    help="runs longer than this (s) are repeated twice only")
    ap.add_argument("--eps2", type=_floats, default=[1e-1, 1e-2, 1e-3])
    ap.add_argument("--eps3", type=_floats, default=[1e-1, 3e-2, 1e-2])
    ap.add_argument("--no-codac", action="store_true")
    ap.add_argument("--quick", action="store_true",
                    help="eps 1e-1 and 1e-2 in 2-D, 1e-1 in 3-D, 3 repeats")
    ap.add_argument("--codac-timeout", type=float, default=1800.0)
    args = ap.parse_args()

    if args.quick:
        args.eps2, args.eps3, args.repeat = [1e-1, 1e-2], [1e-1], 3
    loadavg_start = list(os.getloadavg()) if hasattr(os, "getloadavg") else None
    cases = _cases(args.eps2, args.eps3)
    rows = []
    for case in cases:
        for variant in ("contractors", "test"):
            row = _bench_boundest(case, variant, args.repeat, args.long)
            rows.append(row)
            print(f"boundest {variant} {case['label']}: {row['time_s']:.4f} s, "
                  f"{row['processed']} processed, {row['inside']} in, {row['boundary']} bd, "
                  f"{row['processed_per_s']:.0f} boxes/s", file=sys.stderr)
    codac: dict[str, Any] = {}
    if not args.no_codac:
        for which in CODAC:
            try:
                codac[which] = _run_codac(which, cases, args.repeat, args.long,
                                          args.codac_timeout)
            except subprocess.TimeoutExpired:
                codac[which] = {"skipped": f"over {args.codac_timeout:g} s"}
    _compare(rows, codac)
    doc = {"benchmark": "sivia", "problem": {"set": "a <= |x|^2 <= b", "a": A, "b": B,
                                             "box": [LO, HI]},
           "repeat": args.repeat, "summary": _summary(rows), "boundest": rows, "codac": codac,
           "machine": {**_machine(), "loadavg_start": loadavg_start}}
    text = json.dumps(doc, indent=1)
    print(text)
    if args.out:
        args.out.write_text(text + "\n")


if __name__ == "__main__":
    main()
