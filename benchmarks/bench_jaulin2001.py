"""Jaulin et al. 2001 test case (equation 21) with subpavings: boundest's RCSE and NCSE against
Codac 1.5.7.

boundest: ``boundest.scenarios.jaulin2001.solve`` (subpavings, x(0) paved in [-4, 4]^2) at each
``--eps``; time of RCSE and NCSE (median of ``--repeat`` runs after a warm-up run), hull widths
of the non-causal (and causal) sets for k = 0..10, box counts. Codac 1.5.7
(``benchmarks/jaulin2001_codac1.py``, a subprocess of ``.bench-venv-codac1/bin/python``): the box
CSP of the whole chain contracted on each box of a bisection of x(0) to width ``--codac-eps``.

Usage::

    .venv/bin/python benchmarks/bench_jaulin2001.py [--out benchmarks/results/jaulin2001.json]
        [--eps 0.05,0.02,0.01] [--repeat 3] [--codac-eps 0.01] [--no-codac]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from _machine import cpu_model
from _subprocess import run_json_script

ROOT = Path(__file__).resolve().parent.parent
CODAC1_PY = ROOT / ".bench-venv-codac1" / "bin" / "python"
CODAC1_SCRIPT = Path(__file__).resolve().parent / "jaulin2001_codac1.py"


def _widths(lo: np.ndarray, hi: np.ndarray) -> list:
    return [[round(float(b - a), 4) for a, b in zip(la, ha, strict=True)]
            for la, ha in zip(lo, hi, strict=True)]


def bench_boundest(eps: float, repeat: int) -> dict:
    from boundest.scenarios import jaulin2001 as jw

    y = jw.load()
    t = time.perf_counter()
    jw.solve(y, eps=eps)
    first = time.perf_counter() - t
    runs = [jw.solve(y, eps=eps) for _ in range(repeat)]
    last = runs[-1]
    out = {"eps": eps, "first_run_s": first,
           "rcse_time_s": statistics.median(r.rcse.time_s for r in runs),
           "ncse_time_s": statistics.median(r.ncse.time_s for r in runs),
           "total_time_s": statistics.median(r.rcse.time_s + r.ncse.time_s for r in runs)}
    for name in ("rcse", "ncse"):
        est = getattr(last, name)
        h = est.hull()
        out[f"{name}_hull_widths"] = _widths(h.lo, h.hi)
        out[f"{name}_boxes"] = [len(d) if hasattr(d, "boxes") else 1 for d in est.x]
        out[f"{name}_processed"] = est.stats.get("processed")
    return out


def bench_codac1(eps: float, repeat: int) -> dict:
    if not CODAC1_PY.exists():
        return {"skipped": f"{CODAC1_PY} not found"}
    from boundest.scenarios import jaulin2001 as jw

    y = jw.load()
    spec = {"y_lo": [float(v).hex() for v in y.lo[:, 0]],
            "y_hi": [float(v).hex() for v in y.hi[:, 0]], "eps": eps, "repeat": repeat}
    res = run_json_script(CODAC1_PY, CODAC1_SCRIPT, spec, timeout=600)
    hull = res.pop("hull")
    lo = np.array([[float.fromhex(v) for v in h["lo"]] for h in hull])
    hi = np.array([[float.fromhex(v) for v in h["hi"]] for h in hull])
    res["ncse_hull_widths"] = _widths(lo, hi)
    return res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--eps", default="0.05,0.02,0.01")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--codac-eps", type=float, default=0.01)
    ap.add_argument("--no-codac", action="store_true")
    ap.add_argument("--out")
    args = ap.parse_args()
    rows = []
    for e in (float(v) for v in args.eps.split(",")):
        print(f"boundest eps={e} ...", file=sys.stderr)
        rows.append(bench_boundest(e, args.repeat))
    codac1 = None if args.no_codac else bench_codac1(args.codac_eps, args.repeat)
    doc = {"benchmark": "jaulin2001 (Jaulin et al. 2001 eq. 21), subpavings",
           "machine": {"cpu": cpu_model(), "cpus": os.cpu_count(),
                       "python": platform.python_version(), "numpy": np.__version__,
                       "loadavg": os.getloadavg()},
           "boundest": rows, "codac_1_5_7": codac1,
           "codac_2_1_2": {"skipped": "not written in this session (see README)"},
           "summary": {"boundest_total_s": {str(r["eps"]): round(r["total_time_s"], 3)
                                            for r in rows},
                       "boundest_ncse_width_k10": {str(r["eps"]): r["ncse_hull_widths"][-1]
                                                   for r in rows},
                       "codac1_time_s": None if not codac1 else codac1.get("time_s"),
                       "codac1_ncse_width_k10": None if not codac1 else
                       codac1.get("ncse_hull_widths", [None])[-1]}}
    text = json.dumps(doc, indent=1)
    print(text)
    if args.out:
        Path(args.out).write_text(text)


if __name__ == "__main__":
    main()
