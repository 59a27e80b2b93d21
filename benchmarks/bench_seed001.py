"""Rohou et al. 2018 benchmark: the range-only robot and the drifting clock against Codac 1.5.7.

For each case it reports boundest's time to the fixed point (``solve(...).time_s``: the
contraction only, building the tubes excluded and reported as ``build_s``), the median of
``--repeat`` runs after a warm-up run (the first run in the process also loads or compiles the
Numba kernels: ``first_run_s``), the iterations and the widths that matter, and the same with
the scenario's other ``CtcEval`` mode (``other_mode``: ``time_deriv`` flipped; the clock
contracts its ``[t_i]`` with the derivative by default, the robot uses the plain inverse); then
the same for
Codac 1.5.7 (``benchmarks/seed001_codac.py``, run as a subprocess with
``.bench-venv-codac1/bin/python``, because importing codac switches the FPU to rounding upward),
with speed-ups (Codac time / boundest time) and width ratios (Codac / boundest: > 1 means
boundest is tighter).

Cases: the robot at each ``--dts`` (default 0.01 and 0.001) and each ``--rates`` (the forms of
the distance rate: ``both``, the default of ``range_only.solve``, and ``bearing``, the network
of Rohou et al. 2018; Codac runs the same network in each case) on Table 1, and the clock at each
``--clock-dts`` (default 0.01 and 0.002) on Table 2 over ``[0, t_final]`` (12.44 s for Table 2
at dt = 0.01). The paper's
truths (robot: x(0) = (0, 0, pi/2, 0) with the centre of eq. 14; clock: eq. 16) are checked
against every enclosure (``contains_truth``, at the gate times).

Usage::

    .venv/bin/python benchmarks/bench_seed001.py [--out seed001.json] [--dts 0.01,0.001]
        [--repeat 5] [--codac-repeat 3] [--no-codac] [--quick]

JSON goes to stdout (and to ``--out``); progress and a summary table go to stderr.
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
from decimal import Decimal
from pathlib import Path
from typing import Any

import numpy as np
from _machine import cpu_model
from _subprocess import run_json_script

ROOT = Path(__file__).resolve().parent.parent
CODAC_PY = ROOT / ".bench-venv-codac1" / "bin" / "python"
CODAC_SCRIPT = Path(__file__).resolve().parent / "seed001_codac.py"
#: Figures quoted by the issue (measured earlier by the team; not measured by this script).
TEAM = {"seed_paper": "robot: 52 iterations in 2 minutes; clock: 5 steps in under 2 s",
        "codac_1.5.7": {"robot_dt_0.01_s": 22.0, "robot_iterations": 14,
                        "robot_mean_diagonal_m": 10.3, "clock_s": 0.99}}


def _r(v: Any, nd: int = 4) -> Any:
    return round(v, nd) if isinstance(v, float) else v


def _h(a: Any) -> list:
    return [float(v).hex() for v in np.asarray(a, dtype=float).ravel()]


def _unhex(a: list) -> np.ndarray:
    return np.array([float.fromhex(v) for v in a])


def _diag(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Position-box diagonal per gate from (n+1, >=2) bounds."""
    return np.hypot(hi[:, 0] - lo[:, 0], hi[:, 1] - lo[:, 1])


def _timed(fn: Any, repeat: int) -> tuple[list, Any]:
    runs = [fn() for _ in range(repeat)]
    return [r.time_s for r in runs], runs[-1]


# -- boundest --------------------------------------------------------------------------------
def _other_mode(solve: Any, width: Any, repeat: int) -> dict:
    """The scenario with its other ``CtcEval`` mode (``time_deriv`` flipped): time and widths."""
    times, res = _timed(solve, repeat)
    return {"time_deriv": res.time_deriv, "time_s": statistics.median(times),
            "iterations": res.iterations, **width(res)}


def _bench_robot(ro: Any, dt: float, repeat: int, rate: str,
                 rel_eps: float) -> tuple[dict, Any]:
    t0 = time.perf_counter()
    first = ro.solve(dt=dt, progress=False, rate=rate, rel_eps=rel_eps)
    first_wall = time.perf_counter() - t0
    times, res = _timed(lambda: ro.solve(dt=dt, progress=False, rate=rate, rel_eps=rel_eps),
                        repeat)
    d = res.position_diagonal()
    s = res.x.t
    truth = ro.RobotTruth().states(s)
    rec = {"time_s": statistics.median(times), "time_min_s": min(times), "times_s": times,
           "first_run_s": first.time_s, "first_run_wall_s": first_wall,
           "build_s": res.build_s, "iterations": res.iterations, "converged": res.converged,
           "consistent": res.consistent, "n_slices": res.x.n_slices,
           "mean_diagonal_m": float(np.mean(d)), "max_diagonal_m": float(np.max(d)),
           "mean_diagonal_per_iteration": [_r(float(np.mean(r)), 4) for r in res.diag],
           "t_width_sum": float(np.sum(res.t.width())),
           "t_width_data_sum": float(np.sum(res.meas.t.width())),
           "t_contracted": int(np.sum(res.t.width() < res.meas.t.width() - 1e-9)),
           "z_width_sum": float(np.sum(res.z.width())),
           "t_i": [[_r(float(a), 4), _r(float(b), 4)] for a, b in zip(res.t.lo, res.t.hi,
                                                                      strict=True)],
           "contains_truth": bool(np.all(res.x.gates.contains(truth))),
           "time_deriv": res.time_deriv, "rate": rate,
           "other_mode": _other_mode(
               lambda: ro.solve(dt=dt, progress=False, time_deriv=not res.time_deriv,
                                rate=rate, rel_eps=rel_eps),
               lambda r: {"mean_diagonal_m": float(np.mean(r.position_diagonal())),
                          "t_width_sum": float(np.sum(r.t.width()))}, min(repeat, 3))}
    return rec, res


def _bench_clock(dc: Any, dt: float, repeat: int, rel_eps: float) -> tuple[dict, Any]:
    t0 = time.perf_counter()
    first = dc.solve(dt=dt, rel_eps=rel_eps)
    first_wall = time.perf_counter() - t0
    times, res = _timed(lambda: dc.solve(dt=dt, rel_eps=rel_eps), repeat)
    truth = dc.ClockTruth()
    t_exact = truth.inverse_drift((res.meas.tau.lo + res.meas.tau.hi) / 2)
    rec = {"time_s": statistics.median(times), "time_min_s": min(times), "times_s": times,
           "first_run_s": first.time_s, "first_run_wall_s": first_wall,
           "build_s": res.build_s, "iterations": res.iterations, "converged": res.converged,
           "n_slices": res.h.n_slices, "tf": float(res.h.t[-1]),
           "h_max_width": float(np.max(res.h.gates.width())),
           "h_mean_width": float(np.mean(res.h.gates.width())),
           "t_width_sum": float(np.sum(res.t.width())),
           "t_initial_width_sum": float(np.sum(res.t_initial.width())),
           "t_i": [[_r(float(a), 4), _r(float(b), 4)] for a, b in zip(res.t.lo, res.t.hi,
                                                                      strict=True)],
           "contains_truth": bool(res.h.gates.contains(truth.drift(res.h.t)).all()
                                  and res.t.contains(t_exact).all()),
           "time_deriv": res.time_deriv,
           "other_mode": _other_mode(
               lambda: dc.solve(dt=dt, time_deriv=not res.time_deriv, rel_eps=rel_eps),
               lambda r: {"t_width_sum": float(np.sum(r.t.width())),
                          "t_i": [[_r(float(a), 4), _r(float(b), 4)]
                                  for a, b in zip(r.t.lo, r.t.hi, strict=True)]}, repeat)}
    return rec, res


def _robot_label(dt: float, rate: str) -> str:
    return f"robot dt={dt:g} rate={rate}"


# -- Codac (subprocess) ----------------------------------------------------------------------
def _clock_consts(dc: Any) -> dict:
    """boundest's enclosures of the clock's decimal constants, as exact decimal strings.

    Codac 1.5.7 parses constants in the upward rounding mode it sets at import (its lower
    bound of 0.97 is the double above 0.97: it excludes the decimal). The exact decimal
    expansion of a double parses to that double in any rounding mode, so both libraries see
    the same floats.
    """
    def dec(x: Any) -> list[str]:
        return [format(Decimal(float(x.lo)), "f"), format(Decimal(float(x.hi)), "f")]
    return {"rate": dec(dc.RATE), "offset": dec(dc.OFFSET), "x_offset": [dec(v) for v in
            dc.X_OFFSET], "v_error": dec(dc.V_ERROR)}


def _codac_spec(ro: Any, dc: Any, robot: list[dict], clock: list[dict],
                args: argparse.Namespace) -> dict:
    meas = ro.load()
    x3_0, x4_0 = ro.initial_heading_speed()
    b = (meas.beacons.lo + meas.beacons.hi) / 2
    cases = [{"kind": "robot", "label": _robot_label(row["dt"], row["rate"]),
              "rate": row["rate"], "dt": float(row["dt"]).hex(),
              "t0": float(ro.T0).hex(), "tf": float(ro.TF).hex(),
              "u_bound": float(ro.U_BOUND).hex(),
              "x3_0": _h([x3_0.lo, x3_0.hi]), "x4_0": _h([x4_0.lo, x4_0.hi]),
              "beacons": [_h(row) for row in b], "beacon": [int(k) for k in meas.beacon],
              "t_lo": _h(meas.t.lo), "t_hi": _h(meas.t.hi), "z_lo": _h(meas.z.lo),
              "z_hi": _h(meas.z.hi), "rel_eps": float(args.rel_eps).hex(), "max_iter": 200,
              "every": max(1, round(0.1 / row["dt"]))}
             for row in robot]
    cm = dc.load()
    cases += [{"kind": "clock", "label": f"clock dt={row['dt']:g}",
               "dt": float(row["dt"]).hex(), "tf": float(row["boundest"]["tf"]).hex(),
               "tau_lo": _h(cm.tau.lo), "tau_hi": _h(cm.tau.hi), "z_lo": _h(cm.z.lo),
               "consts": _clock_consts(dc),
               "z_hi": _h(cm.z.hi), "rel_eps": float(args.rel_eps).hex(), "max_iter": 200,
               "every": max(1, round(0.01 / row["dt"]))}
              for row in clock]
    return {"cases": cases, "variants": args.codac_variants, "repeat": args.codac_repeat,
            "limit_s": float(args.codac_limit).hex()}


def _codac_robot_row(rec: dict, b_rec: dict, b_res: Any, ro: Any) -> dict:
    row = {k: rec[k] for k in ("variant", "first_run_s", "rounds", "finished", "n_slices")
           if k in rec}
    if "skipped" in rec:
        row["skipped"] = rec["skipped"]
        return row
    lo = np.stack([_unhex(rec["x_gates"][j][0]) for j in range(4)], axis=1)
    hi = np.stack([_unhex(rec["x_gates"][j][1]) for j in range(4)], axis=1)
    d = _diag(lo, hi)
    t_lo, t_hi = _unhex(rec["t_lo"]), _unhex(rec["t_hi"])
    idx = np.array(rec["gate_index"])             # Codac's gates are sampled (see its script)
    truth = ro.RobotTruth().states(b_res.x.t[idx])
    blo, bhi = b_res.x.gates.lo[idx], b_res.x.gates.hi[idx]
    b_mean = float(np.mean(_diag(blo, bhi)))
    row.update(time_s=rec["time_s"], time_min_s=min(rec["times_s"]), times_s=rec["times_s"],
               build_s=rec["build_s"], empty=rec["empty"],
               mean_diagonal_m=float(np.mean(d)), max_diagonal_m=float(np.max(d)),
               mean_diagonal_per_round=[_r(v, 4) for v in rec["diag_history"]],
               t_width_sum=float(np.sum(t_hi - t_lo)),
               contains_truth=bool(np.all((lo <= truth) & (truth <= hi))),
               speedup=rec["time_s"] / b_rec["time_s"],
               sampled_gates=len(idx), boundest_mean_diagonal_sampled_m=b_mean,
               diagonal_ratio=float(np.mean(d)) / b_mean,
               check={"disjoint_components": int(np.sum(np.maximum(lo, blo)
                                                        > np.minimum(hi, bhi))),
                      "boundest_inside_codac": float(np.mean((lo <= blo) & (bhi <= hi))),
                      "codac_inside_boundest": float(np.mean((blo <= lo) & (hi <= bhi)))})
    return row


def _codac_clock_row(rec: dict, b_rec: dict, b_res: Any, dc: Any) -> dict:
    row = {k: rec[k] for k in ("variant", "first_run_s", "rounds", "finished", "n_slices")
           if k in rec}
    if "skipped" in rec:
        row["skipped"] = rec["skipped"]
        return row
    lo, hi = _unhex(rec["h_gates"][0]), _unhex(rec["h_gates"][1])
    t_lo, t_hi = _unhex(rec["t_lo"]), _unhex(rec["t_hi"])
    truth = dc.ClockTruth()
    t_exact = truth.inverse_drift((b_res.meas.tau.lo + b_res.meas.tau.hi) / 2)
    idx = np.array(rec["gate_index"])
    hs = truth.drift(b_res.h.t[idx])
    b_mean = float(np.mean(b_res.h.gates.width()[idx]))
    row.update(time_s=rec["time_s"], time_min_s=min(rec["times_s"]), times_s=rec["times_s"],
               build_s=rec["build_s"], empty=rec["empty"],
               h_max_width=float(np.max(hi - lo)), h_mean_width=float(np.mean(hi - lo)),
               t_width_sum=float(np.sum(t_hi - t_lo)),
               t_i=[[_r(float(a), 4), _r(float(b), 4)] for a, b in zip(t_lo, t_hi, strict=True)],
               contains_truth=bool(np.all((lo <= hs) & (hs <= hi))
                                   and np.all((t_lo <= t_exact) & (t_exact <= t_hi))),
               speedup=rec["time_s"] / b_rec["time_s"],
               sampled_gates=len(idx), boundest_h_mean_width_sampled=b_mean,
               h_width_ratio=float(np.mean(hi - lo)) / b_mean,
               t_width_ratio=float(np.sum(t_hi - t_lo)) / b_rec["t_width_sum"])
    # each [t_i] of boundest against Codac's (the target: none wider)
    bw, cw = b_res.t.hi - b_res.t.lo, t_hi - t_lo
    row["t_i_wider_than_codac"] = int(np.sum(bw > cw))
    row["t_i_max_excess_over_codac"] = float(np.max((bw - cw) / cw))
    row["t_i_max_excess_over_codac_abs"] = float(np.max(bw - cw))
    # bound by bound, in ulps: > 0 where boundest's bound lies outside Codac's
    lo_ulps = _ulps_between(b_res.t.lo, t_lo)
    hi_ulps = _ulps_between(t_hi, b_res.t.hi)
    row["t_lo_ulps_outside_codac"] = [int(v) for v in lo_ulps]
    row["t_hi_ulps_outside_codac"] = [int(v) for v in hi_ulps]
    row["t_i_bounds_outside_codac"] = int(np.sum(lo_ulps > 0) + np.sum(hi_ulps > 0))
    return row


def _ulps_between(a: Any, b: Any) -> np.ndarray:
    """The number of doubles from ``a`` up to ``b`` (negative where ``b < a``)."""
    def key(x: Any) -> np.ndarray:
        i = np.asarray(x, dtype=np.float64).view(np.int64)
        return np.where(i < 0, np.int64(-(2**63)) - i, i)   # monotone in the float's value
    return key(b) - key(a)


def _machine() -> dict:
    import numba

    import boundest
    return {"python": sys.version.split()[0], "platform": platform.platform(),
            "cpu_model": cpu_model(), "cpu_count": os.cpu_count(),
            "numpy": np.__version__, "numba": numba.__version__,
            "boundest": getattr(boundest, "__version__", None),
            "numba_cache_dir": os.environ.get("NUMBA_CACHE_DIR"),
            "loadavg_end": list(os.getloadavg()) if hasattr(os, "getloadavg") else None}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--dts", default="0.01,0.001", help="robot slice durations")
    p.add_argument("--rates", default="both,bearing",
                   help="forms of the robot's distance rate (range_only.RATE_FORMS), each run "
                        "by both libraries")
    p.add_argument("--clock-dts", default="0.01,0.002", help="clock slice durations")
    p.add_argument("--repeat", type=int, default=5, help="boundest runs per case (median)")
    p.add_argument("--repeat-slow", type=int, default=3,
                   help="boundest runs for cases whose warm-up took over 10 s")
    p.add_argument("--rel-eps", type=float, default=1e-4)
    p.add_argument("--no-codac", action="store_true")
    p.add_argument("--codac-python", default=str(CODAC_PY))
    p.add_argument("--codac-variants", default="loop",
                   help="loop (explicit rounds, as boundest) and/or cn (one Codac "
                        "ContractorNetwork; very slow on the robot: ~22 s at dt = 0.1)")
    p.add_argument("--codac-repeat", type=int, default=3)
    p.add_argument("--codac-limit", type=float, default=300.0,
                   help="seconds of contraction after which a Codac case is skipped")
    p.add_argument("--codac-timeout", type=float, default=3600.0)
    p.add_argument("--quick", action="store_true", help="robot at dt = 0.01 only, 3 repeats")
    p.add_argument("--out", help="write the JSON document to this file")
    args = p.parse_args()
    import boundest

    boundest.keep_freed_memory()  # as the boundest command does for itself (boundest._malloc)
    args.codac_variants = [v for v in args.codac_variants.split(",") if v]
    dts = [0.01] if args.quick else [float(v) for v in args.dts.split(",")]
    if args.quick:
        args.repeat = args.codac_repeat = 3

    from boundest.scenarios import drifting_clock as dc
    from boundest.scenarios import range_only as ro

    started = time.strftime("%Y-%m-%dT%H:%M:%S")
    load_start = list(os.getloadavg()) if hasattr(os, "getloadavg") else None
    robot, results = [], {}
    for dt in dts:
        for rate in [v for v in args.rates.split(",") if v]:
            t0 = time.perf_counter()
            # warm-up (the first also loads kernels)
            ro.solve(dt=dt, progress=False, rate=rate, rel_eps=args.rel_eps)
            slow = time.perf_counter() - t0 > 10
            rec, res = _bench_robot(ro, dt, args.repeat_slow if slow else args.repeat, rate,
                                    args.rel_eps)
            print(f"boundest robot dt={dt:g} rate={rate}: {rec['time_s']:.3f} s, "
                  f"{rec['iterations']} iterations, mean d {rec['mean_diagonal_m']:.3f} m",
                  file=sys.stderr)
            robot.append({"dt": dt, "rate": rate, "boundest": rec})
            results[_robot_label(dt, rate)] = res
    clock_dts = [0.01] if args.quick else [float(v) for v in args.clock_dts.split(",")]
    clock = []
    for dt in clock_dts:
        crec, cres = _bench_clock(dc, dt, args.repeat, args.rel_eps)
        print(f"boundest clock dt={dt:g}: {crec['time_s']:.4f} s, {crec['iterations']} "
              f"iterations, sum of [t_i] widths {crec['t_width_sum']:.4f}", file=sys.stderr)
        clock.append({"dt": dt, "boundest": crec})
        results[f"clock dt={dt:g}"] = cres

    codac_info: dict[str, Any] = {}
    python = Path(args.codac_python)
    if args.no_codac:
        codac_info["skipped"] = "--no-codac"
    elif not python.exists():
        codac_info["skipped"] = f"{python} not found (see benchmarks/README.md)"
    else:
        try:
            out = run_json_script(python, CODAC_SCRIPT, _codac_spec(ro, dc, robot, clock, args),
                                  args.codac_timeout)
            codac_info = {k: out[k] for k in ("codac_version", "python", "import_s",
                                              "fegetround_before_import",
                                              "fegetround_after_import", "subprocess_wall_s")}
            for rec in out["results"]:
                if rec["label"].startswith("robot"):
                    row = next(r for r in robot
                               if _robot_label(r["dt"], r["rate"]) == rec["label"])
                    row.setdefault("codac", []).append(_codac_robot_row(
                        rec, row["boundest"], results[rec["label"]], ro))
                else:
                    row = next(r for r in clock if f"clock dt={r['dt']:g}" == rec["label"])
                    row.setdefault("codac", []).append(_codac_clock_row(
                        rec, row["boundest"], results[rec["label"]], dc))
        except (RuntimeError, subprocess.TimeoutExpired, json.JSONDecodeError) as exc:
            codac_info["error"] = str(exc)[-2000:]

    table = []
    for row in robot:
        b = row["boundest"]
        line = {"case": _robot_label(row["dt"], row["rate"]), "boundest_s": _r(b["time_s"]),
                "iterations": b["iterations"], "mean_d_m": _r(b["mean_diagonal_m"]),
                "t_contracted": b["t_contracted"], "time_deriv": b["time_deriv"],
                "other_mode_s": _r(b["other_mode"]["time_s"]),
                "other_mode_mean_d_m": _r(b["other_mode"]["mean_diagonal_m"])}
        for c in row.get("codac", []):
            if "skipped" not in c:
                line[f"codac_{c['variant']}_s"] = _r(c["time_s"])
                line[f"codac_{c['variant']}_mean_d_m"] = _r(c["mean_diagonal_m"])
                line[f"speedup_{c['variant']}"] = _r(c["speedup"], 2)
        table.append(line)
    for row in clock:
        b = row["boundest"]
        line = {"case": f"clock dt={row['dt']:g}", "boundest_s": _r(b["time_s"]),
                "iterations": b["iterations"], "t_width_sum": _r(b["t_width_sum"]),
                "h_mean_width": _r(b["h_mean_width"]), "time_deriv": b["time_deriv"],
                "other_mode_s": _r(b["other_mode"]["time_s"]),
                "other_mode_t_width_sum": _r(b["other_mode"]["t_width_sum"])}
        for c in row.get("codac", []):
            if "skipped" not in c:
                line[f"codac_{c['variant']}_s"] = _r(c["time_s"])
                line[f"codac_{c['variant']}_t_width_sum"] = _r(c["t_width_sum"])
                line[f"codac_{c['variant']}_h_mean_width"] = _r(c["h_mean_width"])
                line[f"t_i_wider_than_codac_{c['variant']}"] = c["t_i_wider_than_codac"]
                line[f"t_i_bounds_outside_codac_{c['variant']}"] = c["t_i_bounds_outside_codac"]
                line[f"speedup_{c['variant']}"] = _r(c["speedup"], 2)
        table.append(line)
    doc = {"benchmark": "seed001", "started": started, "machine": _machine(),
           "loadavg_start": load_start, "args": {k: v for k, v in vars(args).items()},
           "team_reference": TEAM, "robot": robot, "clock": clock, "codac": codac_info,
           "summary": {"table": table}}
    text = json.dumps(doc, indent=1, default=lambda o: None if isinstance(o, float)
                      and math.isnan(o) else str(o))
    print(text)
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(text)
    for line in table:
        print("  ".join(f"{k}={v}" for k, v in line.items()), file=sys.stderr)


if __name__ == "__main__":
    main()
