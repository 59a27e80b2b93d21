"""Satellite benchmark (Jaulin 2002): boundest's propagation against Codac 1.5.7, k_max = 100..1600.

For each data set it reports boundest's time to the fixed point of the satellite CSP
(``boundest.scenarios.satellite.solve``, ``time_s``: propagation only, the model's compilation
excluded), the median of ``--repeat`` runs after a warm-up run (the very first run in the process
also loads or compiles the Numba kernels; it is reported as ``first_run_s``), evaluations, the
mean width of each state component over k = 0..k_max and the enclosures of x(0) and x(k_max);
in boundest's hull-consistency mode (``mode="hc4"``, what Codac computes too; the shaving mode,
``boundest run satellite``'s default, is compared in ``bench_satellite_modes.py``);
then the same for Codac 1.5.7 (``benchmarks/satellite_codac.py``, run as a subprocess with
``.bench-venv-codac1/bin/python``, because importing codac switches the FPU to rounding upward),
with speed-ups (Codac time / boundest time) and width ratios (Codac / boundest).

Data sets (``data`` in each row says which):

* ``k800[:K+1]``  the first K+1 rows of ``src/boundest/data/satellite_k800.csv``
                  (``load(k800, k_max=K)``), K = 100, 200, 400, 800;
* ``k200``        ``src/boundest/data/satellite_k200.csv``, K = 200;
* ``sim1600``     ``simulate(1600, seed=--seed)`` from the paper's x(0) = (4, 0.5, -0.2, 0.5)
                  (the files stop at k = 800); its true states are known, so the rows also
                  check that every enclosure contains them; ``sim1600[:K+1]`` prefixes of the
                  same simulation give a same-data scaling series (``--no-same-data`` drops
                  them).

Usage::

    .venv/bin/python benchmarks/bench_satellite.py [--out satellite.json] [--repeat 7]
        [--codac-repeat 5] [--seed 0] [--no-codac] [--cold]

JSON goes to stdout (and to ``--out``); progress and a summary table go to stderr. Non-finite
numbers are written as the strings "inf" / "-inf" (and NaN as null).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
from _machine import cpu_model
from _subprocess import run_json_script

ROOT = Path(__file__).resolve().parent.parent
CODAC_PY = ROOT / ".bench-venv-codac1" / "bin" / "python"
CODAC_SCRIPT = Path(__file__).resolve().parent / "satellite_codac.py"
#: Figures the team measured earlier for Codac 1.5.7 (quoted, not measured by this script).
TEAM_CODAC = {"k_max=200": {"time_s": 0.50, "mean_width_x1": 0.77},
              "k_max=800": {"time_s": 4.8}}


def _num(v: float) -> float | str | None:
    v = float(v)
    if math.isnan(v):
        return None
    if math.isinf(v):
        return "inf" if v > 0 else "-inf"
    return v


def _box(lo: np.ndarray, hi: np.ndarray) -> list:
    return [[_num(a), _num(b)] for a, b in zip(lo, hi, strict=True)]


def _mean_widths(lo: np.ndarray, hi: np.ndarray, k_max: int) -> dict:
    """Mean over k = 0..k_max of hi - lo, per component (inf if any width is infinite)."""
    w = hi[: k_max + 1] - lo[: k_max + 1]
    return {f"x{i + 1}": _num(np.mean(w[:, i])) for i in range(4)}


def _r(v: Any, nd: int = 4) -> Any:
    return round(v, nd) if isinstance(v, float) else v


# ----------------------------------------------------------------------------------------------
# data sets


def _datasets(sat: Any, seed: int, ks: list[int], same_data: bool) -> list[dict]:
    from boundest.scenarios._data import embedded

    k800, k200 = embedded("satellite_k800.csv"), embedded("satellite_k200.csv")
    out = []
    for K in ks:
        if K <= 800:
            out.append({"label": f"k800[:{K + 1}]", "k_max": K,
                        "data": f"src/boundest/data/satellite_k800.csv, rows k = 0..{K} "
                                f"(load(k800, k_max={K}))",
                        "meas": sat.load(k800, k_max=K), "truth": None})
        if K == 200:
            out.append({"label": "k200", "k_max": 200,
                        "data": "src/boundest/data/satellite_k200.csv (all rows, k = 0..200)",
                        "meas": sat.load(k200), "truth": None})
    big = [K for K in ks if K > 800]
    if big:
        kmax = max(big)
        truth, sim = sat.simulate(kmax, seed=seed)
        prefixes = sorted({k for k in ks if k < kmax} | {200}) if same_data else []
        for k in [*prefixes, kmax]:
            meas = sat.Measurements(sim.y_lo[: k + 1], sim.y_hi[: k + 1], sim.source)
            label = f"sim{kmax}" if k == kmax else f"sim{kmax}[:{k + 1}]"
            out.append({"label": label, "k_max": k,
                        "data": f"simulate({kmax}, seed={seed}) from x(0) = "
                                f"{sat.X0_TRUE}, rows k = 0..{k} (simulated, not a file)",
                        "meas": meas, "truth": truth[: k + 2], "same_data_series": k != kmax})
    return out


# ----------------------------------------------------------------------------------------------
# boundest


def _bench_boundest(sat: Any, ds: dict, repeat: int, rel_eps: float) -> tuple[dict, Any]:
    meas, K = ds["meas"], ds["k_max"]
    t0 = time.perf_counter()
    first = sat.solve(meas, rel_eps=rel_eps, progress=False, mode="hc4")
    first_wall = time.perf_counter() - t0
    runs, walls = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        runs.append(sat.solve(meas, rel_eps=rel_eps, progress=False, mode="hc4"))
        walls.append(time.perf_counter() - t0)
    res = runs[-1]
    times = [r.time_s for r in runs]
    t = statistics.median(times)
    same = all(np.array_equal(r.x_lo, res.x_lo, equal_nan=True)
               and np.array_equal(r.x_hi, res.x_hi, equal_nan=True) for r in runs)
    rec = {
        "first_run_s": first.time_s,
        "first_run_wall_s": first_wall,
        "time_s": t,
        "time_min_s": min(times),
        "times_s": times,
        "time_per_step_us": 1e6 * t / K,
        "build_s": statistics.median(w - r.time_s for w, r in zip(walls, runs, strict=True)),
        "iterations": float(res.iterations),
        "evaluations": int(res.evaluations),
        "consistent": bool(res.consistent),
        "deterministic": same,
        "mean_width": _mean_widths(res.x_lo, res.x_hi, K),
        "x0": _box(res.x_lo[0], res.x_hi[0]),
        "x_kmax": _box(res.x_lo[K], res.x_hi[K]),
    }
    if ds["truth"] is not None:
        tr = ds["truth"]
        rec["contains_truth"] = bool(np.all((res.x_lo <= tr) & (tr <= res.x_hi)))
    return rec, res


# ----------------------------------------------------------------------------------------------
# Codac (subprocess)


def _flatness(sat: Any, seeds: list[int], k_long: int, repeat: int, rel_eps: float) -> dict:
    """t(k_long)/t(200) on the prefixes of ``simulate(k_long, seed)`` for several seeds.

    A single trajectory mixes the engine's scaling with the data: the Euler-discretised
    satellite gains energy every step and escapes, and how hard its late steps are depends on
    the direction it leaves in. The median over seeds measures the engine.
    """
    per_seed = []
    for seed in seeds:
        truth, sim = sat.simulate(k_long, seed=seed)
        rec: dict[str, Any] = {"seed": seed}
        for k in (200, k_long):
            meas = sat.Measurements(sim.y_lo[: k + 1], sim.y_hi[: k + 1], sim.source)
            sat.solve(meas, rel_eps=rel_eps, progress=False, mode="hc4")  # warm-up, compilation
            runs = [sat.solve(meas, rel_eps=rel_eps, progress=False, mode="hc4")
                    for _ in range(repeat)]
            res = runs[-1]
            rec[f"t{k}_s"] = statistics.median(r.time_s for r in runs)
            rec[f"revisions_per_node_{k}"] = _r(res.iterations, 3)
            rec[f"truth_inside_{k}"] = bool(np.all((res.x_lo <= truth[: k + 2])
                                                   & (truth[: k + 2] <= res.x_hi)))
        rec["ratio"] = _r(rec[f"t{k_long}_s"] / rec["t200_s"], 3)
        print(f"flatness seed {seed}: t({k_long})/t(200) = {rec['ratio']}", file=sys.stderr)
        per_seed.append(rec)
    ratios = [r["ratio"] for r in per_seed]
    return {"what": f"t({k_long})/t(200) on prefixes of simulate({k_long}, seed), one row per "
                    "seed; median over seeds", "per_seed": per_seed,
            "median_ratio": _r(statistics.median(ratios), 3),
            "min_ratio": _r(min(ratios), 3), "max_ratio": _r(max(ratios), 3)}


def _run_codac(python: Path, datasets: list[dict], args: argparse.Namespace,
               w_bound: float) -> dict:
    spec = {
        "cases": [{"label": d["label"],
                   "y_lo": [[float(v).hex() for v in row] for row in d["meas"].y_lo],
                   "y_hi": [[float(v).hex() for v in row] for row in d["meas"].y_hi]}
                  for d in datasets],
        "w_bound": w_bound.hex(),
        "variants": args.codac_variants,
        "repeat": args.codac_repeat,
        "limit_s": args.codac_limit,
        "ratio": args.codac_ratio,
        "fixpoint_ratio": args.codac_fixpoint_ratio,
    }
    return run_json_script(python, CODAC_SCRIPT, spec, args.codac_timeout)


def _codac_row(rec: dict, ds: dict, b_res: Any, b_rec: dict, b_tight: dict | None) -> dict:
    K = ds["k_max"]
    row = {k: rec[k] for k in ("variant", "first_run_s", "n_contractors", "n_domains",
                               "finished") if k in rec}
    if "skipped" in rec:
        row["skipped"] = rec["skipped"]
        return row
    lo = np.array([[float.fromhex(v) for v in r] for r in rec["x_lo"]])
    hi = np.array([[float.fromhex(v) for v in r] for r in rec["x_hi"]])
    mw = _mean_widths(lo, hi, K)
    row.update(time_s=rec["time_s"], time_min_s=min(rec["times_s"]), times_s=rec["times_s"],
               cpu_s=rec["cpu_s"],
               build_s=rec["build_s"], time_per_step_us=1e6 * rec["time_s"] / K,
               empty=rec["empty"], deterministic=rec["deterministic"], mean_width=mw,
               x0=_box(lo[0], hi[0]), x_kmax=_box(lo[K], hi[K]))
    row["speedup"] = rec["time_s"] / b_rec["time_s"]
    row["speedup_total"] = (rec["time_s"] + rec["build_s"]) / (b_rec["time_s"] + b_rec["build_s"])
    row["width_ratio"] = _ratios(mw, b_rec["mean_width"])
    if b_tight is not None:
        row["speedup_vs_tight"] = rec["time_s"] / b_tight["time_s"]
        row["width_ratio_vs_tight"] = _ratios(mw, b_tight["mean_width"])
    # cross-check: both are outer enclosures of one solution set, so they must intersect
    blo, bhi = b_res.x_lo[: K + 2], b_res.x_hi[: K + 2]
    disjoint = (np.maximum(lo, blo) > np.minimum(hi, bhi))
    row["check"] = {
        "disjoint_components": int(np.sum(disjoint)),
        "boundest_inside_codac": float(np.mean((lo <= blo) & (bhi <= hi))),
        "codac_inside_boundest": float(np.mean((blo <= lo) & (hi <= bhi))),
    }
    if ds["truth"] is not None:
        tr = ds["truth"]
        row["contains_truth"] = bool(np.all((lo <= tr) & (tr <= hi)))
    return row


def _ratios(a: dict, b: dict) -> dict:
    return {c: (a[c] / b[c] if isinstance(a[c], float) and isinstance(b[c], float) and b[c] > 0
                else None) for c in a}


# ----------------------------------------------------------------------------------------------
# machine info, summary


def _machine() -> dict:
    import numba

    import boundest
    info: dict[str, Any] = {
        "python": sys.version.split()[0],
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "cpus_usable": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
        "numpy": np.__version__,
        "numba": numba.__version__,
        "boundest": getattr(boundest, "__version__", None),
        "numba_cache_dir": os.environ.get("NUMBA_CACHE_DIR"),
        "loadavg_end": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
    }
    info["cpu_model"] = cpu_model()
    return info


def _summary(rows: list[dict], variants: list[str]) -> dict:
    table = []
    for r in rows:
        b = r["boundest"]
        t = {"data": r["label"], "k_max": r["k_max"], "boundest_s": _r(b["time_s"], 5),
             "boundest_width_x1": _r(b["mean_width"]["x1"])}
        if "boundest_tight" in r:
            t["boundest_tight_s"] = _r(r["boundest_tight"]["time_s"], 5)
            t["boundest_tight_width_x1"] = _r(r["boundest_tight"]["mean_width"]["x1"])
        for c in r.get("codac", []):
            v = c["variant"]
            if "skipped" in c:
                t[f"codac_{v}_s"] = "skipped"
                continue
            t[f"codac_{v}_s"] = _r(c["time_s"], 5)
            t[f"speedup_{v}"] = _r(c["speedup"], 2)
            if "speedup_vs_tight" in c:
                t[f"speedup_tight_{v}"] = _r(c["speedup_vs_tight"], 2)
            t[f"codac_{v}_width_x1"] = _r(c["mean_width"]["x1"])
        table.append(t)

    def tb(label: str) -> dict | None:
        return next((r for r in rows if r["label"] == label), None)

    out: dict[str, Any] = {"table": table}
    r200 = tb("k800[:201]")
    big = [r for r in rows if r["k_max"] > 800 and not r.get("same_data_series")]
    if r200 and big:
        r1600 = big[-1]
        key = f"t({r1600['k_max']})/t(200)"
        out[key] = {"boundest": _r(r1600["boundest"]["time_s"] / r200["boundest"]["time_s"], 2),
                    "note": f"{r1600['label']} (simulated) over k800[:201] (file): different data"}
        for v in variants:
            a = next((c for c in r1600.get("codac", []) if c["variant"] == v), None)
            b = next((c for c in r200.get("codac", []) if c["variant"] == v), None)
            if a and b and "time_s" in a and "time_s" in b:
                out[key][f"codac_{v}"] = _r(a["time_s"] / b["time_s"], 2)
        s200 = next((r for r in rows if r.get("same_data_series") and r["k_max"] == 200), None)
        if s200:
            out[key + "_same_data"] = {
                "boundest": _r(r1600["boundest"]["time_s"] / s200["boundest"]["time_s"], 2),
                "note": f"{r1600['label']} over {s200['label']}: one simulated trajectory"}
            for v in variants:
                a = next((c for c in r1600.get("codac", []) if c["variant"] == v), None)
                b = next((c for c in s200.get("codac", []) if c["variant"] == v), None)
                if a and b and "time_s" in a and "time_s" in b:
                    out[key + "_same_data"][f"codac_{v}"] = _r(a["time_s"] / b["time_s"], 2)
    return out


def _print_table(summary: dict, variants: list[str]) -> None:
    cols = ["data", "k_max", "boundest_s", "boundest_width_x1", "boundest_tight_s",
            "boundest_tight_width_x1"]
    for v in variants:
        cols += [f"codac_{v}_s", f"speedup_{v}", f"speedup_tight_{v}", f"codac_{v}_width_x1"]
    print("  ".join(cols), file=sys.stderr)
    for t in summary["table"]:
        print("  ".join(str(t.get(c, "-")) for c in cols), file=sys.stderr)
    for k, v in summary.items():
        if k.startswith("t("):
            print(f"{k}: {v}", file=sys.stderr)


# ----------------------------------------------------------------------------------------------


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", help="also write the JSON to this file")
    p.add_argument("--ks", default="100,200,400,800,1600",
                   help="k_max values (<= 800: the k800 file; above: simulated)")
    p.add_argument("--repeat", type=int, default=7, help="boundest runs after the warm-up")
    p.add_argument("--rel-eps", type=float, default=1e-3, help="boundest's fixed-point tolerance")
    p.add_argument("--rel-eps-tight", type=float, default=1e-4,
                   help="a second boundest run per row at this tolerance (Codac's default "
                        "network ratio), reported as boundest_tight; 0: skip it")
    p.add_argument("--seed", type=int, default=0, help="seed of the simulated extension")
    p.add_argument("--flat-seeds", default="0,1,2,3,4,5,6,7",
                   help="seeds of the flatness series t(max k)/t(200) (boundest only); "
                        "empty: skip it")
    p.add_argument("--no-same-data", dest="same_data", action="store_false",
                   help="drop the prefixes of the simulated run (same-data scaling series)")
    p.add_argument("--no-codac", action="store_true", help="boundest only")
    p.add_argument("--codac-python", default=str(CODAC_PY),
                   help="interpreter with codac==1.5.7 (default .bench-venv-codac1/bin/python)")
    p.add_argument("--codac-variants", default="cn,cn_fixpoint",
                   help="cn (CtcFunction per step), cn_fixpoint (CtcFixPoint(CtcFunction))")
    p.add_argument("--codac-repeat", type=int, default=5, help="Codac runs after the first one")
    p.add_argument("--codac-limit", type=float, default=60.0,
                   help="skip a Codac case whose first run is not done after this many seconds")
    p.add_argument("--codac-ratio", type=float, default=None,
                   help="ContractorNetwork.set_fixedpoint_ratio (default: Codac's, 1e-4)")
    p.add_argument("--codac-fixpoint-ratio", type=float, default=1e-3,
                   help="ratio of CtcFixPoint in the cn_fixpoint variant")
    p.add_argument("--codac-timeout", type=float, default=600.0,
                   help="wall-clock limit of the Codac subprocess")
    p.add_argument("--cold", action="store_true",
                   help="compile the Numba kernels into an empty NUMBA_CACHE_DIR, so that the "
                        "first run's time is the JIT compile time (adds ~1 min or more)")
    args = p.parse_args()
    args.codac_variants = [v for v in args.codac_variants.split(",") if v]
    ks = sorted({int(k) for k in args.ks.split(",")})
    if args.repeat < 1 or args.codac_repeat < 1:
        p.error("--repeat and --codac-repeat must be >= 1")

    cold_dir = None
    if args.cold:
        if "numba" in sys.modules:
            print("warning: numba already imported; --cold has no effect", file=sys.stderr)
        cold_dir = tempfile.mkdtemp(prefix="bench-satellite-numba-")
        os.environ["NUMBA_CACHE_DIR"] = cold_dir

    t_start = time.perf_counter()
    loadavg_start = list(os.getloadavg()) if hasattr(os, "getloadavg") else None
    t0 = time.perf_counter()
    from boundest.scenarios import satellite as sat
    import_s = time.perf_counter() - t0

    datasets = _datasets(sat, args.seed, ks, args.same_data)
    by_label = {d["label"]: d for d in datasets}
    from boundest.scenarios._data import embedded
    a, b = sat.load(embedded("satellite_k200.csv")), sat.load(embedded("satellite_k800.csv"))
    n = min(len(a.y_lo), len(b.y_lo))
    k200_is_prefix = bool(np.array_equal(a.y_lo, b.y_lo[:n]) and np.array_equal(a.y_hi, b.y_hi[:n]))

    rows, results = [], {}
    for i, ds in enumerate(datasets):
        rec, res = _bench_boundest(sat, ds, args.repeat, args.rel_eps)
        if i == 0:
            rec["note"] = ("first_run_wall_s of this row includes loading (or, with --cold, "
                           "compiling) the Numba kernels")
        results[ds["label"]] = res
        row = {"label": ds["label"], "k_max": ds["k_max"], "data": ds["data"],
               "n_variables": 11 * ds["k_max"] + 15, "n_constraints": 7 * (ds["k_max"] + 1),
               "boundest": rec}
        if ds.get("same_data_series"):
            row["same_data_series"] = True
        print(f"boundest {ds['label']}: {rec['time_s']:.4f} s (first {rec['first_run_s']:.3f} s"
              f", {rec['evaluations']} evaluations)", file=sys.stderr)
        if args.rel_eps_tight > 0:
            row["boundest_tight"], _ = _bench_boundest(sat, ds, args.repeat, args.rel_eps_tight)
            print(f"boundest rel_eps={args.rel_eps_tight:g} {ds['label']}: "
                  f"{row['boundest_tight']['time_s']:.4f} s", file=sys.stderr)
        rows.append(row)

    flat_seeds = [int(v) for v in args.flat_seeds.split(",") if v]
    flatness = (_flatness(sat, flat_seeds, max(ks), args.repeat, args.rel_eps)
                if flat_seeds and max(ks) > 800 else None)

    codac_info: dict[str, Any] = {}
    codac_py = Path(args.codac_python)
    if args.no_codac:
        codac_info["skipped"] = "--no-codac"
    elif not codac_py.exists():
        codac_info["skipped"] = (f"{codac_py} not found; create it with: python3 -m venv "
                                 ".bench-venv-codac1 && .bench-venv-codac1/bin/pip install "
                                 "codac==1.5.7 numpy")
    else:
        try:
            out = _run_codac(codac_py, datasets, args, float(sat.W_BOUND))
        except (RuntimeError, subprocess.TimeoutExpired, json.JSONDecodeError) as exc:
            codac_info["error"] = str(exc)
        else:
            codac_info = {k: v for k, v in out.items() if k != "results"}
            for rec in out["results"]:
                row = next(r for r in rows if r["label"] == rec["label"])
                ds = by_label[rec["label"]]
                row.setdefault("codac", []).append(
                    _codac_row(rec, ds, results[rec["label"]], row["boundest"],
                               row.get("boundest_tight")))
    if "skipped" in codac_info or "error" in codac_info:
        print(f"codac: {codac_info.get('skipped') or codac_info.get('error')}", file=sys.stderr)

    summary = _summary(rows, args.codac_variants if "formulation" in codac_info else [])
    doc = {
        "benchmark": "satellite (Jaulin 2002, equation 14)",
        "what": {
            "time_s": "median over the repeats of the propagation time (wall clock); boundest: "
                      "SatelliteResult.time_s (model compilation excluded, reported as "
                      "build_s); Codac: ContractorNetwork.contract() (network building "
                      "excluded, reported as build_s)",
            "time_min_s": "the fastest of the repeats (steadier on a loaded machine)",
            "time_per_step_us": "time_s / k_max in microseconds (as t_c / k_max in the paper's "
                                "Fig. 5)",
            "mean_width": "mean over k = 0..k_max of the enclosure width of each component",
            "speedup": "Codac time_s / boundest time_s (> 1: boundest faster)",
            "speedup_total": "the same with build_s added on both sides (boundest: building and "
                             "compiling the model; Codac: building the network)",
            "width_ratio": "Codac mean width / boundest mean width (> 1: boundest tighter)",
            "boundest_tight": "boundest again with rel_eps = --rel-eps-tight (default 1e-4, "
                              "Codac's default network ratio); speedup_vs_tight and "
                              "width_ratio_vs_tight compare Codac with it",
            "check": "both enclosures are outer enclosures of the same solution set: "
                     "disjoint_components must be 0",
            "first_run_s": "propagation time of the first (warm-up) run; first_run_wall_s: "
                           "the whole first solve() call (model compilation too); in the "
                           "first row it includes loading (default) or compiling (--cold) the "
                           "Numba kernels; see boundest_first_call",
        },
        "config": {"ks": ks, "repeat": args.repeat, "rel_eps": args.rel_eps,
                   "rel_eps_tight": args.rel_eps_tight, "seed": args.seed,
                   "codac_repeat": args.codac_repeat, "codac_limit_s": args.codac_limit,
                   "codac_variants": args.codac_variants, "cold_numba_cache": args.cold,
                   "w_bound": 0.01, "x0_domains": "x1, x2, x4 >= 0, x3 <= 0 (Remark 2)"},
        "data_notes": {
            "k200_file_equals_k800_prefix": k200_is_prefix,
            "k200_vs_k800": "rows k = 0..200 of satellite_k800.csv compared with "
                            "satellite_k200.csv (y bounds, exact comparison)",
            "sim": "simulate() draws w in [-0.99, 0.99] * 0.01 and noise in +-0.099, so the "
                   "true states are known and must lie in every enclosure",
        },
        "boundest_import_s": import_s,
        "codac": codac_info,
        "team_codac_reference": {"values": TEAM_CODAC,
                                 "note": "quoted from the task brief, not measured here"},
        "rows": rows,
        "summary": summary,
        "flatness_over_seeds": flatness,
        "boundest_first_call": {
            "first_run_wall_s": rows[0]["boundest"]["first_run_wall_s"] if rows else None,
            "warm_run_wall_s": (rows[0]["boundest"]["time_s"] + rows[0]["boundest"]["build_s"]
                                if rows else None),
            "numba": "compiled into an empty cache (--cold)" if args.cold
                     else "loaded from the on-disk cache when warm (use --cold to compile)"},
        "machine": {**_machine(), "loadavg_start": loadavg_start},
        "total_wall_s": time.perf_counter() - t_start,
    }
    text = json.dumps(doc, indent=1)
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")
    _print_table(summary, args.codac_variants if "formulation" in codac_info else [])
    if flatness:
        print(f"flatness over seeds {flat_seeds}: median {flatness['median_ratio']} "
              f"(min {flatness['min_ratio']}, max {flatness['max_ratio']})", file=sys.stderr)
    if cold_dir is not None:
        shutil.rmtree(cold_dir, ignore_errors=True)


if __name__ == "__main__":
    main()
