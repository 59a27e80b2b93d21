"""AUV survey benchmark (Jaulin, Bertholom, Dabe 2007): localization and SLAM on the embedded
60,000-sample survey, against Codac 1.5.7 on the same data.

boundest, in-process and warm (after one run that loads the Numba kernels), medians of
``--repeat`` runs: reading the data, localization (``auv.localize``), SLAM (``auv.slam``), the
discrete CSP through ``propagate`` (``auv_discrete.solve_discrete``, both modes). Then the whole
``boundest run auv`` process (warm: the kernel cache filled; cold: a fresh ``NUMBA_CACHE_DIR``,
so every kernel it uses compiles) with its peak resident memory, and the peak memory of a
process that only loads the data and runs SLAM.

Codac 1.5.7 (``benchmarks/auv_codac.py`` in ``.bench-venv-codac1/``, a subprocess: importing
codac switches the FPU to rounding upward) runs the same localization and SLAM; the ratios
are Codac time / boundest time (> 1: boundest faster) and Codac width / boundest width (> 1:
boundest tighter), side by side in the same run.

Usage::

    .venv/bin/python benchmarks/bench_auv.py [--out benchmarks/results/auv.json]
        [--repeat 5] [--process-repeat 3] [--no-codac] [--no-cold]

JSON goes to stdout (and to ``--out``); progress goes to stderr.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
from _machine import cpu_model, emit
from _subprocess import run_json_script

ROOT = Path(__file__).resolve().parent.parent
CODAC_PY = ROOT / ".bench-venv-codac1" / "bin" / "python"
CODAC_SCRIPT = Path(__file__).resolve().parent / "auv_codac.py"
CODAC2_PY = ROOT / ".bench-venv-codac2" / "bin" / "python"
CODAC2_SCRIPT = Path(__file__).resolve().parent / "auv_codac2.py"
BOUNDEST = Path(sys.executable).with_name("boundest")
#: Figures quoted by the issue (measured earlier by the team with Codac 1.5.7; not by this run).
TEAM = {"codac_1.5.7": {
    "localization_wall_s": 9.8, "localization_cpu_s": 4.7, "localization_build_s": 7.5,
    "localization_width_mean": [104.0, 107.1, 0.14], "localization_width_max": [195.3, 208.1],
    "slam_wall_s": 19.6, "slam_cpu_s": 9.7, "slam_iterations": 5,
    "slam_width_mean": [68.6, 71.8], "slam_width_max": [137.4, 145.4], "slam_peak_mb": 241,
    "discrete_cn_s": 58, "discrete_cn_mb": 627},
    "codac_2.1.2": "centred form for R v: localization widths 0.4 % narrower than Codac 1"}


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def _timed(fn: Any, repeat: int) -> tuple[list[float], Any]:
    out, times = None, []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return times, out


def _summary(times: list[float]) -> dict:
    return {"median_s": statistics.median(times), "min_s": min(times), "runs": len(times)}


def _widths(positions: Any) -> dict:
    w = positions.width()
    return {"mean": w.mean(axis=0).tolist(), "max": w.max(axis=0).tolist()}


def _process(argv: list[str], env: dict | None = None) -> tuple[float, float]:
    """Wall time and peak RSS (MB) of one child process."""
    code = ("import resource, subprocess, sys, time, json; t = time.perf_counter(); "
            "subprocess.run(sys.argv[1:], check=True, stdout=subprocess.DEVNULL, "
            "stderr=subprocess.DEVNULL); w = time.perf_counter() - t; "
            "print(json.dumps([w, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss]))")
    out = subprocess.run([sys.executable, "-c", code, *argv], env=env, check=True,
                         capture_output=True, text=True)
    wall, rss_kb = json.loads(out.stdout)
    return wall, rss_kb / 1024


def _codac_spec(data: Any, repeat: int) -> dict:
    def h(a: Any) -> list[str]:
        return [float(v).hex() for v in np.asarray(a, dtype=float).ravel()]
    dt = np.nextafter(data.dt, -np.inf), np.nextafter(data.dt, np.inf)
    return {"n": data.n, "dt_lo": float(dt[0]).hex(), "dt_hi": float(dt[1]).hex(),
            "att_lo": h(data.attitude.lo), "att_hi": h(data.attitude.hi),
            "vel_lo": h(data.velocity.lo), "vel_hi": h(data.velocity.hi),
            "alt_lo": h(data.altitude.lo), "alt_hi": h(data.altitude.hi),
            "depth_lo": h(data.depth.lo), "depth_hi": h(data.depth.hi),
            "fix_k": data.fix_k.tolist(), "fix_lo": h(data.fix.lo), "fix_hi": h(data.fix.hi),
            "det_k": data.det_k.tolist(), "det_mine": data.det_mine.tolist(),
            "r_lo": h(data.det_range.lo), "r_hi": h(data.det_range.hi),
            "n_mines": data.n_mines, "seabed_tol": data.seabed_tol,
            "modes": ["localization", "slam"], "rel_eps": 1e-4, "repeat": repeat}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", help="also write the JSON here")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--process-repeat", type=int, default=3)
    ap.add_argument("--codac-repeat", type=int, default=1)
    ap.add_argument("--no-codac", action="store_true")
    ap.add_argument("--no-cold", action="store_true")
    args = ap.parse_args()

    from boundest.scenarios import auv
    from boundest.scenarios.auv_data import load_auv
    from boundest.scenarios.auv_discrete import solve_discrete

    rec: dict[str, Any] = {
        "benchmark": "auv", "started": time.strftime("%Y-%m-%dT%H:%M:%S"),
        "machine": {"cpu": cpu_model(), "cores": os.cpu_count(),
                    "python": platform.python_version()},
        "loadavg_start": os.getloadavg(), "args": vars(args), "team_reference": TEAM}
    log("first run (loads or compiles the kernels) ...")
    t0 = time.perf_counter()
    data = load_auv()
    auv.slam(data, progress=False)
    solve_discrete(data, slam=True)
    rec["first_run_in_process_s"] = time.perf_counter() - t0

    times, data = _timed(load_auv, args.repeat)
    rec["load"] = _summary(times)
    b: dict[str, Any] = {}
    for mode, fn in (("localization", lambda: auv.localize(data)),
                     ("localization_natural", lambda: auv.localize(data, "natural")),
                     ("slam", lambda: auv.slam(data, progress=False)),
                     ("slam_natural", lambda: auv.slam(data, "natural", progress=False))):
        log(f"boundest {mode} ...")
        times, res = _timed(fn, args.repeat)
        b[mode] = {**_summary(times), "widths": _widths(res.positions),
                   "iterations": res.report.iterations, "rv_s": res.rv_s,
                   "consistent": res.consistent}
        if res.mode == "slam":
            b[mode]["mine_widths"] = res.mines.width().tolist()
    for slam in (False, True):
        name = "discrete_slam" if slam else "discrete_localization"
        log(f"boundest {name} ...")
        times, res = _timed(lambda s=slam: solve_discrete(data, slam=s), max(1, args.repeat // 2))
        ref = auv.slam(data, "natural", rel_eps=0.0, max_iter=200, progress=False) if slam \
            else auv.localize(data, "natural")
        diff = max(float(np.max(np.abs(res.positions.lo - ref.positions.lo))),
                   float(np.max(np.abs(res.positions.hi - ref.positions.hi))))
        b[name] = {**_summary(times), "build_s": res.build_s,
                   "propagate_s": res.propagation.time_s, "variables": len(res.propagation.domains),
                   "n_nodes": res.propagation.n_nodes, "widths": _widths(res.positions),
                   "max_diff_to_tube_natural_m": diff}
    rec["boundest"] = b

    log("whole process ...")
    proc: dict[str, Any] = {}
    with tempfile.TemporaryDirectory() as tmp:
        argv = [str(BOUNDEST), "run", "auv", "--out", tmp]
        _process(argv)  # fill the kernel cache
        runs = [_process(argv) for _ in range(args.process_repeat)]
        proc["warm_wall_s"] = statistics.median(r[0] for r in runs)
        proc["warm_peak_mb"] = max(r[1] for r in runs)
        code = ("from boundest.scenarios import auv; from boundest.scenarios.auv_data import "
                "load_auv; auv.slam(load_auv(), progress=False)")
        proc["slam_only_peak_mb"] = _process([sys.executable, "-c", code])[1]
        proc["help_wall_s"] = statistics.median(
            _process([str(BOUNDEST), "--help"])[0] for _ in range(args.process_repeat))
        if not args.no_cold:
            cache = Path(tmp) / "numba-cache"
            env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
            log("cold process (empty kernel cache) ...")
            proc["cold_wall_s"], proc["cold_peak_mb"] = _process(argv, env)
    rec["process"] = proc

    if not args.no_codac and CODAC_PY.exists() and CODAC_SCRIPT.exists():
        c: dict[str, Any] = {"results": {}}
        for mode in ("localization", "slam"):  # one process each: its own peak memory
            log(f"codac 1.5.7 {mode} ...")
            spec = _codac_spec(data, args.codac_repeat)
            spec["modes"] = [mode]
            out = run_json_script(CODAC_PY, CODAC_SCRIPT, spec)
            c["results"][mode] = out["results"][mode]
            c.update({k: v for k, v in out.items() if k != "results"})
        rec["codac"] = c
        ratios = {}
        for mode in ("localization", "slam"):
            cm = c.get("results", {}).get(mode)
            if not cm:
                continue
            ratios[f"{mode}_time_codac_over_boundest"] = cm["total_s"] / b[mode]["median_s"]
            ratios[f"{mode}_cpu_codac_over_boundest_wall"] = cm["cpu_s"] / b[mode]["median_s"]
            wm = [cm[f"{a}_mean"] for a in ("north", "east", "depth")]
            ratios[f"{mode}_width_codac_over_boundest"] = [
                x / y for x, y in zip(wm, b[mode]["widths"]["mean"], strict=True)]
            for key in [k for k in cm if k.endswith(("_at_fix", "_at_det", "_lo", "_hi"))]:
                cm.pop(key)
        rec["ratios"] = ratios
    else:
        rec["codac"] = "not run (no .bench-venv-codac1 or --no-codac)"
    if not args.no_codac and CODAC2_PY.exists():
        log("codac 2 (localization, per-sample comparison) ...")
        spec = _codac_spec(data, args.codac_repeat)
        spec.update(modes=["natural", "centered", "default"], check_recurrence=False,
                    positions_modes=["default"])
        c2 = run_json_script(CODAC2_PY, CODAC2_SCRIPT, spec)
        mine = auv.localize(data)
        b_loc = mine.widths().mean(axis=0).tolist()
        comp = {}
        for mode in ("centered", "default"):
            rec2 = c2["modes"][mode]
            if mode == "centered":
                lo, hi = c2["positions_lo"], c2["positions_hi"]
            else:
                lo, hi = rec2["positions_lo"], rec2["positions_hi"]
            lo = np.array([float.fromhex(x) for x in lo]).reshape(-1, 3)
            hi = np.array([float.fromhex(x) for x in hi]).reshape(-1, 3)
            excess = mine.widths() - (hi - lo)
            comp[mode] = {"samples_wider_per_axis": (excess > 0).sum(axis=0).tolist(),
                          "max_excess_m": excess.max(axis=0).tolist(),
                          "mean_width_codac": rec2["mean_width"],
                          "width_codac_over_boundest": [
                              a / b for a, b in zip(rec2["mean_width"], b_loc, strict=True)],
                          "mean_width_boundest": b_loc}
        for mode in ("natural", "centered", "default"):
            r2 = c2["modes"][mode]
            for key in ("positions_lo", "positions_hi", "w_lo", "w_hi"):
                r2.pop(key, None)
        c2.pop("positions_lo", None)
        c2.pop("positions_hi", None)
        rec["codac2"] = {"run": c2, "localization_vs_boundest": comp}
    else:
        rec["codac2"] = "not run (no .bench-venv-codac2 or --no-codac)"
    rec["loadavg_end"] = os.getloadavg()
    rec["children_maxrss_mb"] = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    emit(rec, args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
