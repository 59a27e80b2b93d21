"""Satellite (Jaulin 2002): width against time for each propagation mode of boundest.

Modes: ``hc4`` (hull consistency, the fixed point of ``benchmarks/bench_satellite.py``),
``3b`` (hull consistency, then 3B shaving of the states, ``boundest.csp.propagate(mode="3b")``)
with the default settings (``satellite.SHAVING``, what ``boundest run satellite`` uses) and a few
others (cheaper, tighter), ``bc`` (box consistency of the states, ``mode="bc"``), ``bc+3b``, and
``lp`` (LP contraction of the linear rows at the fixed point, ``mode="lp"``, side by side with
``csp.linear.propagate_lp``, which restarts hull consistency after each LP), ``lp + relax`` (the
LPs also over the linear relaxation of the nonlinear nodes around the box,
``LinearRelaxation(relax=True)``) and ``3b`` then ``lp + relax`` from its box, ``centered``
and ``3b+centered`` (the centered form of windows of steps with optimal multipliers,
``mode="3b+centered"`` with the settings of ``boundest run satellite``, and variants), on the
embedded data
at k_max = 200 (``satellite_k200.csv``) and 800
(``satellite_k800.csv``). Per mode and data set: the median propagation time over ``--repeat``
runs after a warm-up, the mean width of each state component over k = 0..k_max, the widest x1
box and the steps where x1 is wider than 1; the time per step. Then soundness on simulated
data: the truth of ``simulate(200, seed)`` for ``--seeds`` seeds must lie in every box of every
mode. Codac 1.5.7's widths and times are quoted from ``benchmarks/results/satellite.json``
(measured there on the same data, hull consistency); the EKF/RTS widths and the lower bound of
the exact hull are quoted from the project's issue tracker (issue 13), not measured here.

Usage (the whole run is about 6 min without the relax rows, which add about 2 min at k_max = 200
and 2 min per seed of ``--lp-seeds``; ``--update`` merges a part into the JSON, so it can be
run in parts: by horizon with ``--k-max``, by mode with ``--only``, a regular expression on the
labels)::

    .venv/bin/python benchmarks/bench_satellite_modes.py \
        --out benchmarks/results/satellite_modes.json [--repeat 5] [--seeds 20] \
        [--k-max 200,800] [--only REGEX] [--update]
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
import sys
import time
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np
from _machine import cpu_model, emit

ROOT = Path(__file__).resolve().parent.parent
#: quoted from issue 13 (not measured by this script)
QUOTED = {"exact_hull_lower_bound_mean_x1_k200": 0.137, "ekf_6sigma_mean_x1_k200": 0.205,
          "rts_smoother_6sigma_mean_x1_k200": 0.110,
          "note": "issue 13: a nonlinear optimizer's feasible trajectories (a proven lower bound "
                  "of the exact hull's width), an EKF's and an RTS smoother's 6-sigma boxes "
                  "(no guarantee)"}


#: the LP settings of the lp rows: each target's LPs on the rows within 12 row-steps of it, the
#: linear rows only (``benchmarks/bench_satellite_lp.py``'s ``lp-lin-r12``, its fastest)
LP = {"radius": 12, "log_linear": False}


def _modes():
    """``(label, mode, keyword arguments of propagate)``; mode ``propagate_lp`` is
    ``csp.linear.propagate_lp``."""
    from boundest.csp import BoxConsistency, Centered, LinearRelaxation, Shaving
    from boundest.scenarios import satellite as sat

    return [("hc4", "hc4", {}),
            ("3b, probe_evals=100", "3b", {"shaving": Shaving(probe_evals=100)}),
            ("3b, probe_evals=200", "3b", {"shaving": Shaving(probe_evals=200)}),
            ("3b, probe_evals=500, 1 round", "3b",
             {"shaving": Shaving(probe_evals=500, rounds=1)}),
            ("3b default (satellite.SHAVING)", "3b", {"shaving": sat.SHAVING}),
            ("3b, probe_evals=1000, 3 rounds", "3b",
             {"shaving": Shaving(probe_evals=1000, rounds=3)}),
            ("3b, probe_evals=3000, frac=0.05, 5 rounds", "3b",
             {"shaving": Shaving(probe_evals=3000, frac=0.05, rounds=5)}),
            ("bc default (BoxConsistency())", "bc", {"boxcons": BoxConsistency()}),
            ("bc, depth=20, max_steps=200, 6 rounds", "bc",
             {"boxcons": BoxConsistency(depth=20, max_steps=200, rounds=6)}),
            ("bc+3b (BoxConsistency(), satellite.SHAVING)", "bc+3b",
             {"boxcons": BoxConsistency(), "shaving": sat.SHAVING}),
            ("lp (radius=12, linear rows, 3 rounds)", "lp",
             {"linear": LinearRelaxation(**LP)}),
            ("propagate_lp (radius=12, linear rows, 3 rounds)", "propagate_lp", {}),
            ("lp + relax (radius=6, linear + relaxed rows, 1 round)", "lp",
             {"linear": LinearRelaxation(radius=6, log_linear=False, rounds=1, relax=True)}),
            ("lp + relax (radius=12, linear + relaxed rows, 1 round)", "lp",
             {"linear": LinearRelaxation(**LP, rounds=1, relax=True)}),
            ("lp + relax (radius=12, linear + relaxed rows, 3 rounds)", "lp",
             {"linear": LinearRelaxation(**LP, relax=True)}),
            ("3b default, then lp + relax (radius=12, 1 round)", "3b+lp",
             {"shaving": sat.SHAVING, "linear": LinearRelaxation(**LP, rounds=1, relax=True)}),
            ("centered (satellite.CENTERED, after hc4)", "centered",
             {"centered": sat.CENTERED}),
            ("3b+centered default (satellite.SHAVING_CENTERED, CENTERED)", "3b+centered",
             {"shaving": sat.SHAVING_CENTERED, "centered": sat.CENTERED}),
            ("3b+centered, window=42", "3b+centered",
             {"shaving": sat.SHAVING_CENTERED, "centered": Centered(window=42, rounds=2)}),
            ("3b+centered, window=70, 3 rounds", "3b+centered",
             {"shaving": sat.SHAVING_CENTERED, "centered": Centered(window=70, rounds=3)}),
            ("3b default, then centered (satellite.CENTERED)", "3b+centered",
             {"shaving": sat.SHAVING, "centered": sat.CENTERED})]


def _lp_like(mode: str) -> bool:
    return mode in ("lp", "propagate_lp", "3b+lp")


def _once(tape, names, mode, kw):
    """One propagation: ``(result with slots, time_s, counters)``."""
    from boundest.csp import propagate
    from boundest.csp.linear import propagate_lp

    if mode == "propagate_lp":
        r = propagate_lp(tape, targets=names, rounds=3, min_gain=0.01, progress=False, **LP)
        return r, r.time_s, {"rounds": r.rounds, "lp_time_s": r.lp_time_s,
                             "hc_time_s": r.hc_time_s, "widths": r.widths,
                             "evaluations": None}
    if mode == "3b+lp":  # shaving's box, then LP contraction (and propagation) from it
        t0 = time.perf_counter()
        s = propagate(tape, mode="3b", shave=names, progress=False, shaving=kw["shaving"])
        r = propagate(replace(tape, lo=s.slots.lo, hi=s.slots.hi), mode="lp", targets=names,
                      progress=False, linear=kw["linear"])
        info = {"evaluations": s.evaluations + r.evaluations, "shaving": s.shaving,
                "linear": r.linear, "shave_time_s": s.time_s}
        return r, time.perf_counter() - t0, info
    r = propagate(tape, mode=mode, shave=names, targets=names, progress=False, **kw)
    info = {"evaluations": r.evaluations, "shaving": r.shaving, "boxcons": r.boxcons,
            "linear": r.linear, "centered": r.centered}
    return r, r.time_s, info


def _run(tape, names, mode, kw, repeat):
    if not _lp_like(mode):
        _once(tape, names, mode, kw)  # warm-up (and first use of the kernels)
    else:  # an LP run takes seconds: one run, after a warm-up on a short prefix elsewhere
        repeat = 1
    runs = [_once(tape, names, mode, kw) for _ in range(repeat)]
    return runs[-1][0], statistics.median(r[1] for r in runs), [r[1] for r in runs], runs[-1][2]


def _state_idx(tape, K):
    return np.array([[tape.slot_of[f"x{i}_{k}"] for i in (1, 2, 3, 4)] for k in range(K + 2)])


def _soundness_record(truth, tape, names, idx, modes):
    """Per mode: whether the truth lies in every box, and the mean x1 width."""
    rec = {}
    for label, mode, kw in modes:
        res = _once(tape, names, mode, kw)[0]
        lo, hi = res.slots.lo[idx], res.slots.hi[idx]
        rec[label] = {"truth_inside": bool(np.all((lo <= truth) & (truth <= hi))),
                      "mean_width_x1": float((hi - lo)[:201, 0].mean())}
    return rec


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", help="also write the JSON to this file")
    p.add_argument("--repeat", type=int, default=5)
    p.add_argument("--seeds", type=int, default=20, help="simulated trajectories (soundness)")
    p.add_argument("--seed-start", type=int, default=0,
                   help="the seeds are seed-start .. seed-start + seeds - 1")
    p.add_argument("--lp-seeds", type=int, default=5,
                   help="of those, how many the LP rows also run (seconds each)")
    p.add_argument("--k-max", default="200,800", help="horizons to measure (200, 800)")
    p.add_argument("--only", help="measure only the modes whose label matches this regex")
    p.add_argument("--update", action="store_true",
                   help="merge into the JSON of --out: its other rows and seeds are kept")
    args = p.parse_args()
    t_start = time.perf_counter()
    from boundest.csp import propagate
    from boundest.expr.tape import compile_model
    from boundest.scenarios import satellite as sat
    from boundest.scenarios._data import embedded

    modes = [m for m in _modes() if args.only is None or re.search(args.only, m[0])]
    if any(_lp_like(m[1]) for m in modes):  # SciPy's import and HiGHS' first use, untimed
        truth, meas = sat.simulate(5, seed=0)
        propagate(compile_model(sat.build_model(meas)), mode="lp", progress=False)
    rows = []
    files = {200: "satellite_k200.csv", 800: "satellite_k800.csv"}
    for K in (int(k) for k in args.k_max.split(",") if k):
        file = files[K]
        meas = sat.load(embedded(file), k_max=K)
        tape = compile_model(sat.build_model(meas))
        idx = _state_idx(tape, K)
        names = [f"x{i}_{k}" for k in range(K + 2) for i in (1, 2, 3, 4)]
        for label, mode, kw in modes:
            res, t, times, info = _run(tape, names, mode, kw, args.repeat)
            w = (res.slots.hi[idx] - res.slots.lo[idx])[: K + 1]
            wide = np.flatnonzero(w[:, 0] > 1)
            row = {"data": file, "k_max": K, "mode": label, "propagate_mode": mode,
                   "settings": ({k: asdict(v) for k, v in kw.items()} if kw
                                else (LP if mode == "propagate_lp" else None)),
                   "time_s": t, "times_s": times, "time_per_step_us": 1e6 * t / K,
                   "consistent": res.consistent,
                   "mean_width": {f"x{i + 1}": float(w[:, i].mean()) for i in range(4)},
                   "max_width_x1": float(w[:, 0].max()), "argmax_width_x1": int(w[:, 0].argmax()),
                   "steps_x1_wider_than_1": [int(k) for k in wide],
                   "width_x1_k91": float(w[91, 0]) if K >= 91 else None, **info}
            rows.append(row)
            print(f"k_max={K} {label}: {t:.4f} s, mean x1 {row['mean_width']['x1']:.4f}, "
                  f"max x1 {row['max_width_x1']:.3f}, {len(wide)} steps > 1", file=sys.stderr)

    # soundness on simulated trajectories: the truth in every box of every mode
    sound = []
    for seed in range(args.seed_start, args.seed_start + args.seeds):
        truth, meas = sat.simulate(200, seed=seed)
        tape = compile_model(sat.build_model(meas))
        idx = _state_idx(tape, 200)
        names = [f"x{i}_{k}" for k in range(202) for i in (1, 2, 3, 4)]
        run = [m for m in modes if seed - args.seed_start < args.lp_seeds
               or not _lp_like(m[1])]
        sound.append({"seed": seed, **_soundness_record(truth, tape, names, idx, run)})

    if args.update and args.out and Path(args.out).exists():
        old = json.loads(Path(args.out).read_text())
        new_keys = {(r["k_max"], r["mode"]) for r in rows}
        kept = [r for r in old["rows"] if (r["k_max"], r["mode"]) not in new_keys]
        rows = sorted(kept + rows, key=lambda r: (r["k_max"], [m[0] for m in _modes()].index(
            r["mode"]) if r["mode"] in [m[0] for m in _modes()] else 99))
        by_seed = {r["seed"]: dict(r) for r in old["soundness"]["per_seed"]}
        for r in sound:
            by_seed.setdefault(r["seed"], {"seed": r["seed"]}).update(r)
        sound = [by_seed[k] for k in sorted(by_seed)]
        parts = old.get("parts", [])
    else:
        parts = []
    parts.append({"k_max": args.k_max, "only": args.only, "repeat": args.repeat,
                  "seed_start": args.seed_start, "seeds": args.seeds, "lp_seeds": args.lp_seeds,
                  "wall_s": time.perf_counter() - t_start})
    all_inside = all(v["truth_inside"] for r in sound for k, v in r.items() if k != "seed")

    codac = None
    ref = ROOT / "benchmarks" / "results" / "satellite.json"
    if ref.exists():
        d = json.loads(ref.read_text())
        codac = {"source": "benchmarks/results/satellite.json (Codac 1.5.7, hull consistency)",
                 "team_reference": d.get("team_codac_reference"),
                 "rows": {r["label"]: [{"variant": c["variant"], "time_s": c.get("time_s"),
                                        "mean_width_x1": c.get("mean_width", {}).get("x1")}
                                       for c in r.get("codac", [])]
                          for r in d["rows"] if r["label"] in ("k200", "k800[:801]")}}
    table = [{"k_max": r["k_max"], "mode": r["mode"], "time_s": round(r["time_s"], 4),
              "time_per_step_us": round(r["time_per_step_us"], 1),
              "mean_width_x1": round(r["mean_width"]["x1"], 4),
              "max_width_x1": round(r["max_width_x1"], 3),
              "steps_x1_over_1": len(r["steps_x1_wider_than_1"])} for r in rows]
    import numba

    doc = {"benchmark": "satellite (Jaulin 2002): propagation modes, width against time",
           "what": {"time_s": "median of --repeat propagate() calls after a warm-up (the "
                              "model's compilation excluded); 3b includes its hc4 phase",
                    "mean_width": "mean over k = 0..k_max of each state component's width",
                    "steps_x1_wider_than_1": "the k where the x1 box is wider than 1"},
           "config": {"rel_eps": 1e-3, "lp_repeat": 1,
                      "parts": "each run of the script merged here (--update), its arguments"},
           "parts": parts,
           "rows": rows, "table": table,
           "soundness": {"all_truth_inside": all_inside, "per_seed": sound},
           "codac_on_record": codac, "quoted": QUOTED,
           "machine": {"cpu_model": cpu_model(), "numpy": np.__version__,
                       "numba": numba.__version__, "python": sys.version.split()[0]},
           "total_wall_s": sum(q["wall_s"] for q in parts)}
    emit(doc, args.out)
    for t in table:
        print(t, file=sys.stderr)
    print(f"truth inside every box of every mode over {len(sound)} seeds: {all_inside}",
          file=sys.stderr)


if __name__ == "__main__":
    main()
