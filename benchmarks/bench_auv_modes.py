"""AUV survey as one discrete CSP (``scenarios.auv_discrete``): width against time for each
propagation mode of ``boundest.csp.propagate``, on the embedded survey (60,000 samples, GPS
fixes at the first and the last; ``--samples`` takes a prefix, without the last fix).

Per mode and problem (localization; SLAM with the detections and mines): the propagation time
(median of ``--repeat`` runs after a warm-up; one run for ``lp``), the mean and max width of the
positions (x, y, z) and of the mines, and the mode's counters. ``bc`` narrows every variable
occurring several times in its constraints (the attitudes, through their sines and cosines);
``3b`` shaves the positions in time order; ``lp`` contracts, by LPs over the linear rows within
12 row-steps (``radius``), the positions of every ``--lp-stride``-th sample and the mines (each
target costs two LPs: all 180,000 positions would take hours).

Usage::

    .venv/bin/python benchmarks/bench_auv_modes.py --out benchmarks/results/auv_modes.json \
        [--samples 60000] [--repeat 3] [--only REGEX] [--problems localization,slam]
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


def _prefix(data, n):
    """The survey's first ``n`` samples (the fixes and detections among them)."""
    fix = data.fix_k < n
    det = data.det_k < n
    return replace(data, attitude=data.attitude[:n], velocity=data.velocity[:n],
                   altitude=data.altitude[:n], depth=data.depth[:n], fix_k=data.fix_k[fix],
                   fix=data.fix[fix], det_k=data.det_k[det], det_mine=data.det_mine[det],
                   det_range=data.det_range[det])


def _modes():
    from boundest.csp import BoxConsistency, LinearRelaxation, Shaving

    return [("hc4", "hc4", {}),
            ("bc default", "bc", {"boxcons": BoxConsistency()}),
            ("bc, max_nodes=16", "bc", {"boxcons": BoxConsistency(max_nodes=16)}),
            ("3b default (Shaving())", "3b", {"shaving": Shaving()}),
            ("3b, probe_evals=100", "3b", {"shaving": Shaving(probe_evals=100)}),
            ("bc+3b", "bc+3b", {"boxcons": BoxConsistency(), "shaving": Shaving()}),
            ("lp (radius=12, linear rows)", "lp",
             {"linear": LinearRelaxation(radius=12, log_linear=False)})]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", help="also write the JSON to this file")
    ap.add_argument("--samples", type=int, default=60000)
    ap.add_argument("--lp-stride", type=int, default=600)
    ap.add_argument("--problems", default="localization,slam")
    ap.add_argument("--no-warmup", action="store_true",
                    help="time the first run too (the kernels load outside the timing)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--only", help="only the modes whose label matches this regex")
    ap.add_argument("--update", action="store_true",
                    help="merge into the JSON of --out (its other rows are kept)")
    args = ap.parse_args()
    t_start = time.perf_counter()
    from boundest.csp import propagate
    from boundest.scenarios.auv_data import load_auv
    from boundest.scenarios.auv_discrete import discrete_tape

    data = load_auv()
    if args.samples < data.n:
        data = _prefix(data, args.samples)
    n = data.n
    rows = []
    modes = [m for m in _modes() if args.only is None or re.search(args.only, m[0])]
    for slam in (p == "slam" for p in args.problems.split(",")):
        tape = discrete_tape(data, slam)
        pos = np.arange(3 * n)  # the layout puts the positions first (auv_discrete._Layout)
        names = list(tape.slot_of)
        pos_names = names[: 3 * n]
        mines = np.arange(10 * n, 10 * n + 3 * data.n_mines) if slam else np.zeros(0, int)
        lp_names = [names[s] for s in np.concatenate([pos.reshape(n, 3)[::args.lp_stride].ravel(),
                                                      mines])]
        for label, mode, kw in modes:
            def once(mode=mode, kw=kw, tape=tape, pos_names=pos_names, lp_names=lp_names):
                return propagate(tape, rel_eps=1e-6, mode=mode, shave=pos_names,
                                 targets=lp_names if mode == "lp" else None, progress=False,
                                 **kw)
            reps = 1 if mode == "lp" else args.repeat
            if mode == "lp":  # SciPy's import and HiGHS' first use, on a short prefix
                propagate(discrete_tape(_prefix(data, 50), slam), mode="lp", progress=False)
            elif not args.no_warmup:
                once()  # a warm-up (propagate loads its kernels outside its timing anyway)
            runs = [once() for _ in range(reps)]
            r = runs[-1]
            w = r.slots.hi - r.slots.lo
            wp = w[pos].reshape(n, 3)
            row = {"problem": "slam" if slam else "localization", "samples": n,
                   "n_nodes": r.n_nodes, "mode": label, "propagate_mode": mode,
                   "settings": {k: asdict(v) for k, v in kw.items()},
                   "time_s": statistics.median(q.time_s for q in runs),
                   "times_s": [q.time_s for q in runs],
                   "time_per_sample_us": 1e6 * statistics.median(q.time_s for q in runs) / n,
                   "consistent": r.consistent,
                   "position_mean_width": wp.mean(axis=0).tolist(),
                   "position_max_width": wp.max(axis=0).tolist(),
                   "mine_mean_width": float(w[mines].mean()) if mines.size else None,
                   "evaluations": r.evaluations, "shaving": r.shaving, "boxcons": r.boxcons,
                   "linear": {k: v for k, v in r.linear.items() if k != "widths"}}
            rows.append(row)
            print(f"{row['problem']} {label}: {row['time_s']:.3f} s, position widths "
                  f"{np.round(wp.mean(axis=0), 3).tolist()}, mines {row['mine_mean_width']}",
                  file=sys.stderr)
    parts = []
    if args.update and args.out and Path(args.out).exists():
        old = json.loads(Path(args.out).read_text())
        new = {(r["problem"], r["mode"]) for r in rows}
        order = [m[0] for m in _modes()]
        rows = sorted([r for r in old["rows"] if (r["problem"], r["mode"]) not in new] + rows,
                      key=lambda r: (r["problem"], order.index(r["mode"])))
        parts = old.get("parts", [])
    parts.append({"only": args.only, "problems": args.problems, "repeat": args.repeat,
                  "warmup": not args.no_warmup,
                  "wall_s": time.perf_counter() - t_start})
    import numba

    doc = {"benchmark": "AUV discrete CSP: propagation modes, width against time",
           "config": {"samples": n, "rel_eps": 1e-6, "lp_stride": args.lp_stride,
                      "lp_repeat": 1},
           "parts": parts,
           "rows": rows,
           "table": [{"problem": r["problem"], "mode": r["mode"], "time_s": round(r["time_s"], 4),
                      "position_mean_width": [round(v, 4) for v in r["position_mean_width"]],
                      "mine_mean_width": r["mine_mean_width"]} for r in rows],
           "machine": {"cpu_model": cpu_model(), "numpy": np.__version__,
                       "numba": numba.__version__, "python": sys.version.split()[0]},
           "total_wall_s": sum(q["wall_s"] for q in parts)}
    emit(doc, args.out)


if __name__ == "__main__":
    main()
