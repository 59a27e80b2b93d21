"""How much would a linear relaxation of the window narrow the pool observer? A study, not an
observer.

The recursive box observer of the pool robot (Jaulin's robust set-membership observer,
``scenarios.pool``) reaches 0.74 / 0.66 m (mean x / y widths at q = 8 on the embedded mission),
and its smoothing is at its fixpoint there. ``bench_pool_exact.py`` proved that the exact causal
set is at least 0.26-0.31 / 0.17-0.20 m wide (witnesses: a lower bound, whose search looked
converged). This script measures how much of the gap a **linear programme over the window**
recovers, and what the q-relaxation costs inside it.

The programme, at ping ``k`` (window ``j = k - m + 1 .. k``), built from the observer's smoothed
window boxes ``S_j`` after its update ``k``:

- variables: the states ``(x, y, theta, v)_j`` in ``S_j``, the inputs ``(u1, u2)_j`` in their
  boxes, and for every ping two slacks ``s+, s- >= 0`` (0: the ping is imposed);
- the Euler steps: ``theta`` and ``v`` are linear; ``v cos theta`` and ``v sin theta`` are
  linearised at the centre of ``S_j`` with a bound on the Taylor remainder over ``S_j``;
- each ping whose ray hits one wall from every corner of ``S_j`` (a float test; pings near a
  corner or hitting a pillar are left out, which only relaxes): ``n . (p_j + d u(theta_j +
  alpha_j)) = c`` for the wall's line, ``d`` in the range box, linearised in ``theta_j`` at the
  centre, with its remainder;
- the pings the observer rejected (their set misses its box: outliers under the hypothesis
  "at most q outliers in the window") are left out; at most ``q' = q - rejected`` of the others
  may still be outliers.

The bounds of ``x_k, y_k, theta_k`` come from HiGHS through the project's Neumaier-Shcherbina
correction (``boundest.ctc.linear``), so they are rigorous for the linearised system; the
linearisation and the wall test are in float64 and are **not** rigorous: this is a measure of
what such a relaxation can reach, not a sound observer. How the ``q'`` possible outliers are
handled is what the variants compare:

- ``oracle``: the true outliers (simulated missions) are left out and every other ping is
  imposed. Not a valid observer (it knows the outliers): the reach of the relaxation itself.
- ``bigm``: every ping may be relaxed, ``sum (s+ + s-) / M <= q'``, ``M`` the largest violation
  over ``S_j`` (the LP relaxation of the exact mixed-integer programme).
- ``groups1``, ``groups2``: the pings are dealt into ``G = q' + 1`` (``q' + 2``) interleaved
  groups; any ``q'`` outliers spare ``G - q'`` groups, so the state is in the union, over the
  choices of ``q'`` groups, of the programme without them: ``C(G, q')`` programmes per bound.
- ``exact``: the exact q'-relaxed bound of the linearised window, ``max`` over every set of at
  most ``q'`` dropped pings, by branching on the pings binding at the optimum (dropping a ping
  whose multiplier is 0 does not move the optimum). Hundreds to thousands of programmes per
  bound. Also run without feeding, on the plain observer's windows at every
  ``--exact-every``-th step, next to ``groups2`` on the same windows.

By default (``--no-feed`` turns it off) the bounds replace the observer's box at ``k``, which
it carries forward: a recursive observer with an LP step.

Usage::

    .venv/bin/python benchmarks/bench_pool_lp.py [--seeds 1] [--steps 80:160]
        [--variants box,oracle,bigm,groups1,groups2,exact] [--exact-every 20] [--embedded]
        [--out benchmarks/results/pool_lp.json]

Needs SciPy (``pip install -e '.[lp]'``). JSON goes to stdout (and to ``--out``); progress to
stderr.
"""

from __future__ import annotations

import argparse
import itertools
import math
import os
import platform
import sys
import time
from typing import Any

import numpy as np
from _machine import cpu_model, emit

from boundest.ctc.linear import LinearSystem, _Solver
from boundest.ctc.obstacles import ObstacleMap
from boundest.scenarios.pool import PoolObserver
from boundest.scenarios.pool_data import load_pool
from boundest.scenarios.pool_sim import simulate_pool

H = 0.04


def _wall_hits(pool: ObstacleMap, x, y, beta) -> np.ndarray:
    """Index of the first obstacle hit (walls first, then pillars) at each ray, float64."""
    c, s = np.cos(beta), np.sin(beta)
    best, which = np.full(x.shape, np.inf), np.full(x.shape, -1)
    with np.errstate(divide="ignore", invalid="ignore"):
        for o, ((ax, ay), (bx, by)) in enumerate(pool.segments):
            ex, ey, wx, wy = bx - ax, by - ay, ax - x, ay - y
            den = c * ey - s * ex
            dist = (wx * ey - wy * ex) / den
            tau = (wx * s - wy * c) / den
            hit = (den != 0) & (dist > 0) & (tau >= 0) & (tau <= 1) & (dist < best)
            best, which = np.where(hit, dist, best), np.where(hit, o, which)
        for o, ((cx, cy), r) in enumerate(zip(pool.centers, pool.radii, strict=True)):
            wx, wy = x - cx, y - cy
            b = c * wx + s * wy
            disc = b * b - (wx * wx + wy * wy - r * r)
            dist = -b - np.sqrt(disc)
            hit = (disc >= 0) & (dist > 0) & (dist < best)
            best, which = np.where(hit, dist, best), np.where(hit, len(pool.segments) + o, which)
    return which


def _one_wall(pool: ObstacleMap, lo: np.ndarray, hi: np.ndarray, alpha: float) -> int:
    """The wall that every corner of the box (three headings) hits first; -1 if they differ or
    hit a pillar."""
    g = np.array(list(itertools.product((lo[0], hi[0]), (lo[1], hi[1]),
                                        (lo[2], 0.5 * (lo[2] + hi[2]), hi[2]))))
    which = np.unique(_wall_hits(pool, g[:, 0], g[:, 1], g[:, 2] + alpha))
    return int(which[0]) if which.size == 1 and which[0] < len(pool.segments) else -1


class Window:
    """The linearised window programme at ping ``k`` (module docstring)."""

    def __init__(self, obs: PoolObserver, pool: ObstacleMap, k: int, leave_out: set[int],
                 budget: float) -> None:
        SL, SH, _, _, _, _, UL, UH, AL, DL, DH = obs.ring
        m = obs.m
        first = max(0, k - m + 1)
        n = k - first + 1
        self.k, self.first, self.n = k, first, n
        rows: list[int] = []
        cols: list[int] = []
        vals: list[float] = []
        blo: list[float] = []
        bhi: list[float] = []

        def add(cs, vs, a, b):
            r = len(blo)
            rows.extend([r] * len(cs))
            cols.extend(cs)
            vals.extend(vs)
            blo.append(a)
            bhi.append(b)

        pings = []
        for j in range(first, k + 1):
            if j not in leave_out:
                o = _one_wall(pool, SL[j % m], SH[j % m], AL[j % m])
                if o >= 0:
                    pings.append((j, o))
        n_state, n_in = 4 * n, 2 * (n - 1)
        nv = n_state + n_in + 2 * len(pings)
        lo, hi = np.empty(nv), np.empty(nv)
        for t in range(n):
            lo[4 * t:4 * t + 4], hi[4 * t:4 * t + 4] = SL[(first + t) % m], SH[(first + t) % m]
        for t in range(n - 1):
            js = (first + t) % m
            lo[n_state + 2 * t:n_state + 2 * t + 2] = UL[js]
            hi[n_state + 2 * t:n_state + 2 * t + 2] = UH[js]
        for t in range(n - 1):
            js = (first + t) % m
            th0, v0 = 0.5 * (SL[js, 2] + SH[js, 2]), 0.5 * (SL[js, 3] + SH[js, 3])
            dth, dv = 0.5 * (SH[js, 2] - SL[js, 2]), 0.5 * (SH[js, 3] - SL[js, 3])
            vmax = max(abs(SL[js, 3]), abs(SH[js, 3]))
            c, s = math.cos(th0), math.sin(th0)
            rem = H * (vmax * (dth * dth / 2 + dth ** 3 / 6) + dv * dth) * (1 + 1e-6) + 1e-12
            a, b, u = 4 * t, 4 * (t + 1), n_state + 2 * t
            # x' = x + h (c v - v0 s (theta - th0)) + rem, and y' likewise
            add([b, a, a + 3, a + 2], [1, -1, -H * c, H * v0 * s],
                H * v0 * s * th0 - rem, H * v0 * s * th0 + rem)
            add([b + 1, a + 1, a + 3, a + 2], [1, -1, -H * s, -H * v0 * c],
                -H * v0 * c * th0 - rem, -H * v0 * c * th0 + rem)
            add([b + 2, a + 2, u + 1, u], [1, -1, -H, H], 0.0, 0.0)
            add([b + 3, a + 3, u, u + 1], [1, -(1 - H), -H, -H], 0.0, 0.0)
        self.ping_rows, self.slack_cols, self.big_m = [], [], []
        weights = []
        for i, (j, o) in enumerate(pings):
            js, t = j % m, j - first
            (ax, ay), (bx, by) = pool.segments[o]
            nx, ny = (by - ay), -(bx - ax)
            norm = math.hypot(nx, ny)
            nx, ny = nx / norm, ny / norm
            cw, phi = nx * ax + ny * ay, math.atan2(ny, nx)
            th0, dth = 0.5 * (SL[js, 2] + SH[js, 2]), 0.5 * (SH[js, 2] - SL[js, 2])
            d0, dd = 0.5 * (DL[js] + DH[js]), 0.5 * (DH[js] - DL[js])
            C, S = math.cos(th0 + AL[js] - phi), math.sin(th0 + AL[js] - phi)
            rem = (DH[js] * (abs(C) * dth * dth / 2 + abs(S) * dth ** 3 / 6)
                   + dd * abs(S) * dth) * (1 + 1e-6) + 1e-9
            cd = sorted((C * DL[js], C * DH[js]))
            r_lo = cw - d0 * S * th0 - rem - cd[1]
            r_hi = cw - d0 * S * th0 + rem - cd[0]
            ex = sorted((nx * SL[js, 0], nx * SH[js, 0]))
            ey = sorted((ny * SL[js, 1], ny * SH[js, 1]))
            et = sorted((-d0 * S * SL[js, 2], -d0 * S * SH[js, 2]))
            e_lo, e_hi = ex[0] + ey[0] + et[0], ex[1] + ey[1] + et[1]
            big = max(e_hi - r_lo, r_hi - e_lo, 1e-6)
            sc = n_state + n_in + 2 * i
            self.ping_rows.append(len(blo))
            add([4 * t, 4 * t + 1, 4 * t + 2, sc, sc + 1], [nx, ny, -d0 * S, 1, -1], r_lo, r_hi)
            self.slack_cols.append(sc)
            self.big_m.append(big)
            weights.append(1 / big)
        sc = np.array(self.slack_cols, dtype=np.int64)
        w = np.array(weights)
        add(list(sc) + list(sc + 1), list(w) + list(w), -np.inf, budget)  # the relaxation budget
        self.pings = [j for j, _ in pings]
        self.lo, self.hi = lo, hi
        lo[n_state + n_in:] = 0.0
        hi[n_state + n_in:] = 0.0
        r, c, v = np.array(rows, dtype=np.int64), np.array(cols, dtype=np.int64), np.array(vals)
        self.system = LinearSystem(r, c, v, v, np.array(blo), np.array(bhi), nv)
        self.solver = _Solver(self.system)
        self.tk = 4 * (n - 1)
        self.lps = 0

    def bounds(self, dropped=(), relax_all: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Rigorous bounds (for the linearised system) of ``x_k, y_k, theta_k`` with the
        ``dropped`` pings' slacks free (``relax_all``: every slack up to its ``M``)."""
        hi = self.hi.copy()
        for i in (range(len(self.pings)) if relax_all else dropped):
            hi[self.slack_cols[i]:self.slack_cols[i] + 2] = self.big_m[i]
        out_lo, out_hi = np.full(3, -np.inf), np.full(3, np.inf)
        for c in range(3):
            e = np.zeros(self.system.n_cols)
            e[self.tk + c] = 1.0
            out_lo[c] = self.solver.bound(e, self.lo, hi)
            out_hi[c] = -self.solver.bound(-e, self.lo, hi)
            self.lps += 2
        return out_lo, out_hi

    def max_dropped(self, c: int, sign: float, budget: int) -> float:
        """``max sign * state_k[c]`` over every choice of at most ``budget`` dropped pings
        (module docstring, ``exact``)."""
        if self.solver.highs is None:
            raise SystemExit("the exact variant needs SciPy's bundled HiGHS bindings "
                             "(scipy.optimize._highspy) for the multipliers")
        e = np.zeros(self.system.n_cols)
        e[self.tk + c] = -sign
        cache: dict[frozenset, float] = {}

        def best(drop: frozenset, left: int) -> float:
            if drop in cache:
                return cache[drop]
            hi = self.hi.copy()
            for i in drop:
                hi[self.slack_cols[i]:self.slack_cols[i] + 2] = self.big_m[i]
            val = -self.solver.bound(e, self.lo, hi)
            self.lps += 1
            if left and np.isfinite(val):
                y = np.asarray(self.solver.highs.getSolution().row_dual)
                for i, row in enumerate(self.ping_rows):
                    if i not in drop and abs(y[row]) > 1e-9:
                        val = max(val, best(drop | {i}, left - 1))
            cache[drop] = val
            return val

        return best(frozenset(), budget)


def _rejected(obs: PoolObserver, k: int, xl: np.ndarray, xh: np.ndarray) -> set[int]:
    FL, FH, m = obs.ring[4], obs.ring[5], obs.m
    out = set()
    for j in range(max(0, k - m + 1), k + 1):
        f_lo, f_hi = FL[j % m], FH[j % m]
        if not (np.all(f_lo <= f_hi) and np.all(f_lo <= xh) and np.all(f_hi >= xl)):
            out.add(j)
    return out


def _lp_box(variant: str, obs, pool, k, box, outliers, q) -> tuple[np.ndarray, np.ndarray, int]:
    """The variant's bounds of ``(x, y, theta)_k`` and the number of programmes solved."""
    rej = _rejected(obs, k, box.lo, box.hi)
    qp = q - len(rej)
    if variant == "oracle":
        win = Window(obs, pool, k, set(np.flatnonzero(outliers[:k + 1])), np.inf)
        lo, hi = win.bounds()
        return lo, hi, win.lps
    if variant == "bigm":
        win = Window(obs, pool, k, rej, float(qp))
        lo, hi = win.bounds(relax_all=True)
        return lo, hi, win.lps
    win = Window(obs, pool, k, rej, np.inf)
    if variant == "exact":
        hi = np.array([win.max_dropped(c, 1.0, qp) for c in range(3)])
        lo = np.array([-win.max_dropped(c, -1.0, qp) for c in range(3)])
        return lo, hi, win.lps
    extra = {"groups1": 1, "groups2": 2}[variant]
    g = qp + extra
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for drop in itertools.combinations(range(g), qp):
        blo, bhi = win.bounds([i for i in range(len(win.pings)) if i % g in drop])
        lo, hi = np.minimum(lo, blo), np.maximum(hi, bhi)
    return lo, hi, win.lps


def _run(variant: str, data, truth, q: int, m: int, steps: range, feed: bool) -> dict:
    pool = data.map
    obs = PoolObserver(data, q=q, m=m)
    widths, outside, lps, t_lp = [], 0, 0, 0.0
    outliers = None if truth is None else truth.outlier
    for k in range(steps.stop):
        u = None if k == 0 else data.inputs[k - 1]
        box, _, empty = obs.update(u, float(data.alpha[k]), data.ranges[k])
        if k < steps.start or empty:
            continue
        if variant == "box":
            lo, hi = box.lo[:3].copy(), box.hi[:3].copy()
        else:
            t0 = time.perf_counter()
            lo, hi, n_lp = _lp_box(variant, obs, pool, k, box, outliers, q)
            t_lp += time.perf_counter() - t0
            lps += n_lp
            lo, hi = np.maximum(lo, box.lo[:3]), np.minimum(hi, box.hi[:3])
            if feed and np.all(lo <= hi):
                s = k % m
                obs.ring[0][s, :3], obs.ring[1][s, :3] = lo, hi
        widths.append(hi - lo)
        if truth is not None:
            tr = truth.states[k, :3]
            outside += int(not np.all((lo <= tr) & (tr <= hi)))
        print(f"  {variant} k={k} widths {np.round(hi - lo, 3)}", file=sys.stderr, flush=True)
    w = np.array(widths)
    return {"mean_width_x": float(w[:, 0].mean()), "mean_width_y": float(w[:, 1].mean()),
            "mean_width_theta": float(w[:, 2].mean()), "steps_scored": len(w),
            "truth_outside": outside if truth is not None else None, "lps": lps,
            "lp_time_s": round(t_lp, 2)}


def _exact(data, q: int, m: int, steps: range, every: int) -> dict:
    """``exact`` and ``groups2`` on the plain observer's windows at every ``every``-th step."""
    pool = data.map
    obs = PoolObserver(data, q=q, m=m)
    rows = []
    for k in range(steps.stop):
        u = None if k == 0 else data.inputs[k - 1]
        box, _, empty = obs.update(u, float(data.alpha[k]), data.ranges[k])
        if k < steps.start or empty or (k - steps.start) % every:
            continue
        rej = _rejected(obs, k, box.lo, box.hi)
        qp = q - len(rej)
        t0 = time.perf_counter()
        win = Window(obs, pool, k, rej, np.inf)
        hi = [win.max_dropped(c, 1.0, qp) for c in range(2)]
        lo = [-win.max_dropped(c, -1.0, qp) for c in range(2)]
        ex = np.minimum(hi, box.hi[:2]) - np.maximum(lo, box.lo[:2])
        t_ex = time.perf_counter() - t0
        glo, ghi, _ = _lp_box("groups2", obs, pool, k, box, None, q)
        gw = np.minimum(ghi[:2], box.hi[:2]) - np.maximum(glo[:2], box.lo[:2])
        rows.append({"k": k, "q_left": qp, "box": (box.hi - box.lo)[:2].tolist(),
                     "exact": ex.tolist(), "groups2": gw.tolist(), "exact_lps": win.lps,
                     "exact_time_s": round(t_ex, 1)})
        print(f"  exact k={k} q'={qp} box {np.round(rows[-1]['box'], 3)} exact "
              f"{np.round(ex, 3)} groups2 {np.round(gw, 3)} ({win.lps} LPs)", file=sys.stderr,
              flush=True)
    mean = {key: np.mean([r[key] for r in rows], axis=0).tolist()
            for key in ("box", "exact", "groups2")}
    return {"steps": rows, "mean_widths_xy": mean}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", default="1", help="simulated missions (comma-separated)")
    ap.add_argument("--embedded", action="store_true", help="also the embedded mission")
    ap.add_argument("--steps", default="80:160", help="the steps scored, FIRST:LAST")
    ap.add_argument("--variants", default="box,oracle,bigm,groups1,groups2,exact")
    ap.add_argument("--exact-every", type=int, default=20, help="0: no exact variant")
    ap.add_argument("--no-feed", action="store_true", help="do not feed the bounds back")
    ap.add_argument("--q", type=int, default=8)
    ap.add_argument("--m", type=int, default=80)
    ap.add_argument("--out", default=None)
    args = ap.parse_args(argv)
    a, b = (int(v) for v in args.steps.split(":"))
    steps = range(a, b + 1)
    missions: list[tuple[str, Any, Any]] = []
    for seed in (int(s) for s in args.seeds.split(",") if s):
        data, truth = simulate_pool(seed)
        missions.append((f"sim_seed{seed}", data, truth))
    if args.embedded:
        missions.append(("embedded", load_pool(), None))
    rec: dict[str, Any] = {
        "benchmark": "pool_lp", "started": time.strftime("%Y-%m-%dT%H:%M:%S"),
        "machine": {"cpu": cpu_model(), "cores": os.cpu_count(),
                    "python": platform.python_version()},
        "args": vars(args), "missions": {}}
    for name, data, truth in missions:
        res: dict[str, Any] = {}
        for variant in args.variants.split(","):
            if variant == "oracle" and truth is None:
                continue
            print(f"{name}: {variant}", file=sys.stderr, flush=True)
            res[variant] = _run(variant, data, truth, args.q, args.m, steps, not args.no_feed)
        if args.exact_every:
            print(f"{name}: exact", file=sys.stderr, flush=True)
            res["exact_one_pass"] = _exact(data, args.q, args.m, steps, args.exact_every)
        rec["missions"][name] = res
    emit(rec, args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
