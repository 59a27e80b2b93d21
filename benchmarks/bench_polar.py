"""The minimal polar contractor ``CtcPolar`` against hull consistency on the decomposition
(``Fixpoint(CtcFwdBwd)`` of ``x = rho cos theta, y = rho sin theta, rho >= 0``) and, when
``.bench-venv-codac1/`` exists, Codac 1.5.7's ``CtcPolar`` (a subprocess, Python loop).

Random boxes (seeded) around a true tuple (``rho`` in ``[0, 30]``, ``theta`` in ``[-4, 4]``):
widths up to 10 for ``x, y``, 5 for ``rho``, 0.5 (half the boxes) or 8 for ``theta``.
Per batch size: the median time of ``--repeat`` warm calls, per box, the mean widths of each
component (an empty box counts 0), the number of empty boxes and of boxes where one result is
narrower than the other by more than 1e-9 in some component. Codac runs on the first
``--codac-boxes`` boxes; its widths are reported side by side with ours on the same boxes,
with the number of boxes where one is tighter than the other by more than 1e-9 in a component.
The compile time is that of the first call in a fresh process with an empty
``NUMBA_CACHE_DIR``, then with that cache filled. ``numpy_floor``: what a vectorised NumPy
version would cost at least per quarter turn (why the kernel is compiled).

Usage::

    .venv/bin/python benchmarks/bench_polar.py --out benchmarks/results/polar.json
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _machine import cpu_model, emit
from _subprocess import run_json_script

import boundest.interval as iv
from boundest import Interval
from boundest.ctc import CtcFwdBwd, CtcPolar, Fixpoint
from boundest.expr import Var
from boundest.expr.functions import cos, sin

ROOT = Path(__file__).resolve().parent.parent
CODAC1_PY = ROOT / ".bench-venv-codac1" / "bin" / "python"
CODAC1_SCRIPT = Path(__file__).resolve().parent / "polar_codac.py"
NAMES = ["x", "y", "rho", "theta"]


def boxes(m: int, seed: int = 1) -> Interval:
    """Boxes around a true ``(rho, theta)`` (rho in [0, 30], theta in [-4, 4]) and its point,
    so that each holds a solution; the truth sits anywhere in each interval."""
    rng = np.random.default_rng(seed)
    rho, theta = rng.uniform(0, 30, m), rng.uniform(-4, 4, m)
    truth = np.column_stack([rho * np.cos(theta), rho * np.sin(theta), rho, theta])
    w = np.column_stack([rng.uniform(0, 10, (m, 2)), rng.uniform(0, 5, m),
                         np.where(rng.random(m) < 0.5, rng.uniform(0, 0.5, m),
                                  rng.uniform(0, 8, m))])
    lo = truth - rng.uniform(0, 1, (m, 4)) * w
    lo[:, 2] = np.maximum(lo[:, 2], 0.0)
    return Interval(lo, lo + w)


def hc4() -> Fixpoint:
    x, y, rho, theta = (Var(n) for n in NAMES)
    return Fixpoint(CtcFwdBwd([x == rho * cos(theta), y == rho * sin(theta), rho >= 0], NAMES))


def widths(b: Interval) -> np.ndarray:
    return np.where(np.isnan(b.lo), 0.0, b.hi - b.lo)


def timed(ctc, box: Interval, repeat: int) -> tuple[float, Interval]:
    ctc(box[:10])  # compile / load
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = ctc(box)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def summary(box: Interval, out: Interval, t: float) -> dict:
    m = box.shape[0]
    return {"time_s": t, "us_per_box": 1e6 * t / m,
            "mean_width": dict(zip(NAMES, widths(out).mean(axis=0).tolist(), strict=True)),
            "empty": int(np.isnan(out.lo).any(axis=-1).sum())}


def numpy_floor(m: int, repeat: int) -> float:
    """Seconds per box of the public NumPy interval calls that one quarter turn of a
    vectorised CtcPolar would need at least (6 inverse trig, 4 trig, 24 products and
    quotients; no masking, no case analysis): the floor of a NumPy implementation."""
    rng = np.random.default_rng(2)
    z = Interval(rng.uniform(0, 1, m))
    a, b = Interval(rng.uniform(0.1, 3, m)), Interval(rng.uniform(0.1, 3, m))

    def quarter() -> None:
        for f in (iv.acos, iv.asin, iv.asin, iv.acos, iv.cos, iv.sin, iv.cos, iv.sin):
            f(z)
        iv.atan2(a, b)
        iv.atan2(b, a)
        for _ in range(12):
            iv.div(a, b)
            iv.mul(a, b)

    quarter()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        quarter()
        times.append(time.perf_counter() - t0)
    return statistics.median(times) / m


COMPILE = """
import time
t0 = time.perf_counter()
from boundest import Interval
from boundest.ctc import CtcPolar
t1 = time.perf_counter()
CtcPolar()(Interval([1.0, 1.0, 0.0, -1.0], [2.0, 2.0, 3.0, 1.0]))
t2 = time.perf_counter()
print(t1 - t0, t2 - t1)
"""


def compile_times() -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, NUMBA_CACHE_DIR=tmp)
        res = {}
        for key in ("cold_cache", "warm_cache"):
            out = subprocess.run([sys.executable, "-c", COMPILE], env=env, capture_output=True,
                                 text=True, check=True).stdout.split()
            res[key] = {"import_s": float(out[0]), "first_call_s": float(out[1])}
    return res


def codac_side(box: Interval, ours: Interval, repeat: int) -> dict | str:
    if not CODAC1_PY.exists():
        return "not run (no .bench-venv-codac1)"
    spec = {"lo": [[float(v).hex() for v in r] for r in box.lo],
            "hi": [[float(v).hex() for v in r] for r in box.hi], "repeat": repeat}
    res = run_json_script(CODAC1_PY, CODAC1_SCRIPT, spec)
    m = box.shape[0]
    lo = np.array([[np.nan] * 4 if b is None else [c[0] for c in b] for b in res["bounds"]])
    hi = np.array([[np.nan] * 4 if b is None else [c[1] for c in b] for b in res["bounds"]])
    theirs = Interval.trusted(lo, hi)
    wo, wt = widths(ours), widths(theirs)
    return {"time_s": res["time_s"], "us_per_box": 1e6 * res["time_s"] / m, "boxes": m,
            "mean_width": dict(zip(NAMES, wt.mean(axis=0).tolist(), strict=True)),
            "ours_mean_width_same_boxes": dict(zip(NAMES, wo.mean(axis=0).tolist(),
                                                   strict=True)),
            "empty": int(np.isnan(lo).any(axis=-1).sum()),
            "boxes_codac_tighter": int((wt < wo - 1e-9).any(axis=-1).sum()),
            "boxes_ours_tighter": int((wo < wt - 1e-9).any(axis=-1).sum())}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out")
    ap.add_argument("--sizes", default="10000,100000")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--codac-boxes", type=int, default=10000)
    ap.add_argument("--no-codac", action="store_true")
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args()
    sizes = [1000] if a.quick else [int(s) for s in a.sizes.split(",")]
    polar, hc = CtcPolar(), hc4()
    rows = {}
    for m in sizes:
        box = boxes(m)
        t_p, out_p = timed(polar, box, a.repeat)
        t_h, out_h = timed(hc, box, a.repeat)
        rows[m] = {"input_mean_width": dict(zip(NAMES, widths(box).mean(axis=0).tolist(),
                                                 strict=True)),
                   "ctc_polar": summary(box, out_p, t_p), "hc4_fixpoint": summary(box, out_h, t_h),
                   "hc4_over_polar_time": t_h / t_p,
                   "boxes_polar_tighter": int((widths(out_p) < widths(out_h) - 1e-9)
                                              .any(axis=-1).sum()),
                   "boxes_hc4_tighter": int((widths(out_h) < widths(out_p) - 1e-9)
                                            .any(axis=-1).sum())}
    n = min(a.codac_boxes, 1000 if a.quick else a.codac_boxes)
    box = boxes(n)
    codac = "not run (--no-codac)" if a.no_codac else codac_side(box, polar(box), 3)
    first = rows[sizes[0]]
    emit({"cpu": cpu_model(), "numpy": np.__version__, "sizes": sizes, "repeat": a.repeat,
          "batches": rows, "codac_1_5_7": codac, "compile": compile_times(),
          "numpy_floor_us_per_box_per_quarter_turn": 1e6 * numpy_floor(sizes[-1], a.repeat),
          "summary": {"polar_us_per_box": {m: r["ctc_polar"]["us_per_box"]
                                           for m, r in rows.items()},
                      "hc4_us_per_box": {m: r["hc4_fixpoint"]["us_per_box"]
                                         for m, r in rows.items()},
                      "polar_mean_width": first["ctc_polar"]["mean_width"],
                      "hc4_mean_width": first["hc4_fixpoint"]["mean_width"],
                      "codac_us_per_box": None if isinstance(codac, str)
                      else codac["us_per_box"]}}, a.out)


if __name__ == "__main__":
    main()
