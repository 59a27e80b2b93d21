"""Inner witnesses of the pool robot's exact q-relaxed set: how wide must any sound observer be?

The robust observer of the pool robot (Jaulin's robust set-membership observer; data of
``scenarios.pool_data``) encloses, at each ping ``K``, the **exact set**

    E_K = { x_K : there are x_0 in the initial box, u_k in the input boxes (k < K) such that
            X[k+1] = X[k] + dt f(X[k], u[k]) (the exact Euler model, in real arithmetic) and
            every window of m consecutive pings ending at or before K holds at most q pings
            j <= K whose first-hit range g(x_j, y_j, theta_j + alpha_j) is outside [d_j] }.

The recursive observer of ``scenarios.pool`` is causal (its set at ``K`` uses the pings up to
``K``), so ``E_K`` is the set that any sound causal observer's box at ``K`` contains, and the
width of the hull of ``E_K`` in ``x`` (``y``) is a lower bound on the observer's. This script
finds **pairs of trajectories in that set** whose ``x_K`` (``y_K``) lie far apart: the
difference is a proven lower bound on the hull width of ``E_K``, hence on the width of every
sound causal observer at ``K``.

Method (per mission, per sampled step ``K``, per objective ``max / min x_K``, ``max / min y_K``)
-------------------------------------------------------------------------------------------
1. **A feasible nominal.** Simulated missions (``scenarios.pool_sim.simulate_pool``): the truth
   (its true inputs, its initial state; its violated pings are the outliers). The embedded
   mission (no truth): a trajectory fitted to the centres of the smoothed observer's boxes
   (bounded Gauss-Newton on the initial state and the inputs, ``scipy.optimize.lsq_linear``),
   then an elastic L1 linear programme on the ranges (sequential, with a line search on the
   exact residual) until every window holds at most ``q`` violated pings.
2. **Sequential linear programming.** The decision variables are the initial state and the
   inputs, perturbed block-wise (the same perturbation over ``--block`` consecutive inputs: a
   restriction, so still inside the set). The dynamics and the first-hit range are linearised
   around the current (feasible) trajectory (forward sensitivities; central finite differences
   of ``ObstacleMap.distance``, pings whose finite differences disagree are near a
   discontinuity of the first hit and are not imposed). A linear programme (HiGHS through
   ``scipy.optimize.linprog``) maximises ``+- x_K`` subject to the linearised ranges of the
   pings ``j <= K`` that the current trajectory satisfies, shrunk by a margin, inside the input
   and initial boxes and a trust region. **Outliers:** the range constraints with the largest
   duals are released greedily, each as long as every window keeps at most ``q`` pings that are
   violated or released, and the programme is solved again. A **line search** on the step
   keeps only trajectories that, simulated exactly (float64 Euler from the inputs), satisfy the
   window condition with the float64 first-hit range inside ``[d_lo + 1e-9, d_hi - 1e-9]``;
   the trust region shrinks when no step passes.
3. **Verification** of every final witness, without linearisation, in outward-rounded interval
   arithmetic (``boundest.interval``): the inputs are checked inside their float boxes shrunk
   by ``1e-12`` (inside the decimal boxes of the data, which the float boxes enclose one ulp
   outward) and likewise the initial state; the exact (real-arithmetic) Euler recursion from
   those float inputs is enclosed step by step (``dt`` as the interval of the two floats
   around 0.04); for every ping ``j <= K`` the first-hit range over the enclosing box of
   ``(x_j, y_j, theta_j + alpha_j)`` is enclosed by the project's ray-cast contractor
   (``boundest.ctc.CtcRayCast`` on ``(x, y, beta, [0, 1000])``), and the ping counts as
   satisfied only when that enclosure lies inside ``[d_lo + 1e-9, d_hi - 1e-9]``; every window
   of ``m`` pings ending at or before ``K`` must hold at most ``q`` pings not satisfied. The
   witnessed width at ``K`` is ``inf x_K(max witness) - sup x_K(min witness)`` over the
   enclosures (0 when a witness fails). So, as far as the interval library and the ray-cast
   contractor are sound, the reported widths are **proven** lower bounds of the hull width of
   ``E_K``; the float64 parts (simulation, ranges and finite differences inside the search)
   only steer the search and are not relied on. The free-space condition (robot in the pool,
   outside the pillars) is checked as well, in interval arithmetic, and reported. Not exact:
   the map is taken as its float64 values (walls, centres, radii as ``ObstacleMap`` holds them,
   as the observer does), not the decimals of ``pool_map.json``; the ``1e-9`` range margin is
   meant to cover that difference but it is not proven to (a ray at grazing incidence would
   amplify it).

Simulated seeds whose truth has more than ``q`` outliers in some window are skipped (the truth
is then not in the set and is no nominal); they are recorded.

What it does not show: the search is local (linearised around a trajectory that starts at the
truth or the fitted nominal, greedy in the released pings, ``--restarts`` extra searches with a
randomised release order), so the hull of the exact set may be wider than witnessed, e.g. by a
component far from the truth where another choice of pings is dropped; the numbers are lower
bounds only. Two diagnostics are recorded: ``first_order_gap_mean_xy``, what the linear model at
the final witnesses still offers (no margin, no trust region, same released pings: a measure of
how far the search stopped from its local linearised optimum, not a bound), and
``restart_gain_mean_xy``, what the randomised release orders added. ``E_K`` is the causal set;
an offline smoother using all pings has a smaller exact set, not bounded here.

Usage::

    .venv/bin/python benchmarks/bench_pool_exact.py [--out benchmarks/results/pool_exact.json]
        [--seeds 1,2,3,4] [--every 20] [--block 1] [--restarts 1] [--q 8] [--m 80]

Needs SciPy (a benchmark-only dependency: ``pip install scipy``). JSON goes to stdout (and to
``--out``); progress goes to stderr.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from _machine import cpu_model, emit

SAFE_D = 1e-9   # range margin of the verification [m]
SAFE_U = 1e-12  # input / initial-state margin inside the float boxes
MU = 2e-3       # margin of the linearised ranges in the search [m]
FD = 1e-7       # finite-difference step of the first-hit range


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


@dataclass
class Mission:
    """What the search needs about one mission (float arrays)."""

    name: str
    dt: float
    alpha: np.ndarray
    dlo: np.ndarray
    dhi: np.ndarray
    ulo: np.ndarray
    uhi: np.ndarray
    x0lo: np.ndarray
    x0hi: np.ndarray
    pool: Any
    q: int
    m: int
    info: dict = field(default_factory=dict)

    @property
    def n(self) -> int:
        return int(self.alpha.shape[0])


def mission_from(data: Any, name: str, q: int, m: int) -> Mission:
    return Mission(name, float(data.dt), np.asarray(data.alpha, float),
                   np.asarray(data.ranges.lo, float), np.asarray(data.ranges.hi, float),
                   np.asarray(data.inputs.lo, float)[:-1], np.asarray(data.inputs.hi, float)[:-1],
                   np.asarray(data.x0.lo, float), np.asarray(data.x0.hi, float), data.map, q, m)


# --- float64 model (steers the search only) ------------------------------------------------

def simulate(ms: Mission, x0: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Float64 Euler trajectories: ``x0`` (..., 4), ``u`` (..., n - 1, 2) -> (..., n, 4)."""
    from boundest.scenarios.pool_data import euler_step
    X = np.empty((*x0.shape[:-1], ms.n, 4))
    X[..., 0, :] = x0
    for k in range(ms.n - 1):
        X[..., k + 1, :] = euler_step(X[..., k, :], u[..., k, :], ms.dt)
    return X


def ranges(ms: Mission, X: np.ndarray) -> np.ndarray:
    return ms.pool.distance(X[..., 0], X[..., 1], X[..., 2] + ms.alpha)


def violated(ms: Mission, d: np.ndarray) -> np.ndarray:
    return ~((d >= ms.dlo + SAFE_D) & (d <= ms.dhi - SAFE_D))


def window_max(ms: Mission, bad: np.ndarray, K: int) -> np.ndarray:
    """Most flagged pings in a window of ``m`` pings ending at or before ``K`` (last axis)."""
    b = bad[..., :K + 1].astype(np.int64)
    c = np.cumsum(b, axis=-1)
    prev = np.concatenate([np.zeros((*c.shape[:-1], 1), np.int64), c], axis=-1)
    lo = np.maximum(np.arange(K + 1) - ms.m + 1, 0)
    return np.max(c - np.take(prev, lo, axis=-1), axis=-1)


def sensitivities(ms: Mission, X: np.ndarray, block: int) -> np.ndarray:
    """``dX_k / dp``, shape (n, 4, P), for ``p = (x0, block perturbations of u)``."""
    n, nb = ms.n, (ms.n - 2) // block + 1
    P = 4 + 2 * nb
    S = np.zeros((n, 4, P))
    S[0, :, :4] = np.eye(4)
    dt = ms.dt
    for k in range(n - 1):
        th, v = X[k, 2], X[k, 3]
        A = np.array([[1, 0, -dt * v * np.sin(th), dt * np.cos(th)],
                      [0, 1, dt * v * np.cos(th), dt * np.sin(th)],
                      [0, 0, 1, 0], [0, 0, 0, 1 - dt]])
        S[k + 1] = A @ S[k]
        c = 4 + 2 * (k // block)
        S[k + 1, 2, c] -= dt      # u1
        S[k + 1, 2, c + 1] += dt  # u2
        S[k + 1, 3, c] += dt
        S[k + 1, 3, c + 1] += dt
    return S


def range_rows(ms: Mission, X: np.ndarray, S: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Linearised ranges ``dd_j / dp`` (n, P) and whether the linearisation is trusted."""
    x, y, b = X[:, 0], X[:, 1], X[:, 2] + ms.alpha
    g = ms.pool.distance
    grads, ok = [], np.ones(ms.n, bool)
    for e in np.eye(3):
        fp = g(x + FD * e[0], y + FD * e[1], b + FD * e[2])
        fm = g(x - FD * e[0], y - FD * e[1], b - FD * e[2])
        f0 = g(x, y, b)
        central = (fp - fm) / (2 * FD)
        fwd, bwd = (fp - f0) / FD, (f0 - fm) / FD
        ok &= np.isfinite(central) & (np.abs(fwd - bwd) <= 1e-3 * (1 + np.abs(central)))
        ok &= np.abs(central) < 1e3
        grads.append(np.where(np.isfinite(central), central, 0.0))
    gx, gy, gb = grads
    rows = gx[:, None] * S[:, 0] + gy[:, None] * S[:, 1] + gb[:, None] * S[:, 2]
    return rows, ok


class Point:
    """A trajectory of the search: initial state, inputs, and what follows from them."""

    def __init__(self, ms: Mission, x0: np.ndarray, u: np.ndarray) -> None:
        self.x0, self.u = x0, u
        self.X = simulate(ms, x0, u)
        self.d = ranges(ms, self.X)
        self.bad = violated(ms, self.d)


def _bounds(ms: Mission, pt: Point, block: int, rho_x: float, rho_u: float) -> list:
    nb = (ms.n - 2) // block + 1
    lo = np.empty(4 + 2 * nb)
    hi = np.empty(4 + 2 * nb)
    lo[:4] = np.maximum(ms.x0lo + SAFE_U - pt.x0, -rho_x)
    hi[:4] = np.minimum(ms.x0hi - SAFE_U - pt.x0, rho_x)
    dl = ms.ulo + SAFE_U - pt.u
    dh = ms.uhi - SAFE_U - pt.u
    for b in range(nb):
        sl = slice(b * block, min((b + 1) * block, ms.n - 1))
        lo[4 + 2 * b:6 + 2 * b] = np.maximum(dl[sl].max(axis=0), -rho_u)
        hi[4 + 2 * b:6 + 2 * b] = np.minimum(dh[sl].min(axis=0), rho_u)
    lo = np.minimum(lo, 0.0)
    hi = np.maximum(hi, 0.0)
    return list(zip(lo, hi, strict=True))


def _apply(ms: Mission, pt: Point, step: np.ndarray, block: int) -> tuple[np.ndarray, np.ndarray]:
    """Initial states and inputs after the steps ``step`` (T, P), clipped into the boxes."""
    du = np.repeat(step[:, 4:].reshape(len(step), -1, 2), block, axis=1)[:, :ms.n - 1]
    x0 = np.clip(pt.x0 + step[:, :4], ms.x0lo + SAFE_U, ms.x0hi - SAFE_U)
    u = np.clip(pt.u + du, ms.ulo + SAFE_U, ms.uhi - SAFE_U)
    return x0, u


def _lp(c: np.ndarray, rows: np.ndarray, lo: np.ndarray, hi: np.ndarray, bounds: list):
    from scipy.optimize import linprog
    A = np.vstack([rows, -rows])
    b = np.concatenate([hi, -lo])
    return linprog(c, A_ub=A, b_ub=b, bounds=bounds, method="highs")


def release(ms: Mission, bad: np.ndarray, cand: np.ndarray, dual: np.ndarray, K: int
            ) -> np.ndarray:
    """Greedily release imposed pings ``cand`` by decreasing dual, keeping every window's
    count of violated or released pings at most ``q``."""
    flag = bad[:K + 1].astype(np.int64)
    c = np.concatenate([[0], np.cumsum(flag)])
    e = np.arange(K + 1)
    cnt = c[e + 1] - c[np.maximum(e - ms.m + 1, 0)]  # count in the window ending at e
    out = np.zeros(ms.n, bool)
    for j in cand[np.argsort(-dual[cand])]:
        if dual[j] <= 1e-12:
            break
        hi_e = min(j + ms.m - 1, K)
        if cnt[j:hi_e + 1].max() < ms.q:
            cnt[j:hi_e + 1] += 1
            out[j] = True
    return out


def extremise(ms: Mission, start: Point, K: int, comp: int, sign: float, block: int,
              max_iter: int = 30, rng: np.random.Generator | None = None) -> Point:
    """Local maximum of ``sign * X_K[comp]`` over the exact set (float64-checked steps);
    with ``rng``, the release order of the duals is randomised (a log-normal factor)."""
    pt = start
    rho_x, rho_u = 1.0, 0.1
    ts = np.array([1.0, 0.5, 0.25, 0.1, 0.03])
    stall = 0
    for _ in range(max_iter):
        S = sensitivities(ms, pt.X, block)
        rows, ok = range_rows(ms, pt.X, S)
        c = -sign * S[K, comp]
        bounds = _bounds(ms, pt, block, rho_x, rho_u)
        imposed = np.zeros(ms.n, bool)
        imposed[:K + 1] = ~pt.bad[:K + 1] & ok[:K + 1]
        lo = np.minimum(ms.dlo + MU, pt.d) - pt.d
        hi = np.maximum(ms.dhi - MU, pt.d) - pt.d
        idx = np.flatnonzero(imposed)
        res = _lp(c, rows[idx], lo[idx], hi[idx], bounds)
        if res.status != 0:
            break
        dual = np.zeros(ms.n)
        mm = np.abs(res.ineqlin.marginals)
        dual[idx] = mm[:len(idx)] + mm[len(idx):]
        # pings not imposed (kinks) that the point satisfies count as free budget users too
        if rng is not None:
            dual *= np.exp(rng.normal(0.0, 1.0, dual.shape))
        rel = release(ms, pt.bad | (~ok & ~pt.bad & (np.arange(ms.n) <= K)), idx, dual, K)
        step = res.x
        if rel.any():
            keep = np.flatnonzero(imposed & ~rel)
            res2 = _lp(c, rows[keep], lo[keep], hi[keep], bounds)
            if res2.status == 0:
                step = res2.x
        x0s, us = _apply(ms, pt, ts[:, None] * step[None, :], block)
        X = simulate(ms, x0s, us)
        d = ranges(ms, X)
        bad = violated(ms, d)
        good = window_max(ms, bad, K) <= ms.q
        gain = sign * (X[:, K, comp] - pt.X[K, comp])
        good &= gain > 1e-7
        if not good.any():
            rho_x *= 0.3
            rho_u *= 0.3
            stall += 1
            if rho_u < 1e-4 or stall > 6:
                break
            continue
        i = int(np.argmax(np.where(good, gain, -np.inf)))
        pt = Point(ms, x0s[i], us[i])
        stall = stall + 1 if gain[i] < 1e-4 else 0
        if i == 0:
            rho_x, rho_u = min(2 * rho_x, 1.0), min(2 * rho_u, 0.1)
        if stall >= 3:
            break
    return pt


def linear_gain(ms: Mission, pt: Point, K: int, comp: int, sign: float, block: int) -> float:
    """What the linear model at ``pt`` still offers on ``sign * X_K[comp]`` (no margin, no
    trust region, the pings ``pt`` satisfies imposed, no further release): a first-order
    diagnostic of how far the local search stopped from its linearised optimum, not a bound."""
    S = sensitivities(ms, pt.X, block)
    rows, ok = range_rows(ms, pt.X, S)
    idx = np.flatnonzero(~pt.bad[:K + 1] & ok[:K + 1])
    res = _lp(-sign * S[K, comp], rows[idx], (ms.dlo - pt.d)[idx], (ms.dhi - pt.d)[idx],
              _bounds(ms, pt, block, np.inf, np.inf))
    return float(-res.fun) if res.status == 0 else float("nan")


# --- the nominal of a mission without truth ------------------------------------------------

def fit_nominal(ms: Mission, centres: np.ndarray, block: int, log_every: bool = True) -> Point:
    """A feasible trajectory near the observer's box centres (embedded mission)."""
    from scipy.optimize import linprog, lsq_linear
    u = np.clip(0.5 * (ms.ulo + ms.uhi), ms.ulo + SAFE_U, ms.uhi - SAFE_U)
    x0 = np.clip(centres[0], ms.x0lo + SAFE_U, ms.x0hi - SAFE_U)
    pt = Point(ms, x0, u)
    w = np.array([1.0, 1.0, 3.0])
    for _ in range(12):  # bounded Gauss-Newton on the tracking error
        S = sensitivities(ms, pt.X, block)
        J = (S[:, :3] * w[None, :, None]).reshape(-1, S.shape[2])
        r = ((pt.X[:, :3] - centres[:, :3]) * w).reshape(-1)
        b = _bounds(ms, pt, block, 1.0, 0.1)
        sol = lsq_linear(J, -r, bounds=(np.array([a for a, _ in b]), np.array([c for _, c in b])))
        x0s, us = _apply(ms, pt, np.array([1.0, 0.5, 0.25])[:, None] * sol.x[None, :], block)
        X = simulate(ms, x0s, us)
        cost = np.sum(((X[..., :3] - centres[:, :3]) * w) ** 2, axis=(-1, -2))
        old = np.sum(((pt.X[:, :3] - centres[:, :3]) * w) ** 2)
        i = int(np.argmin(cost))
        if cost[i] >= old * (1 - 1e-6):
            break
        pt = Point(ms, x0s[i], us[i])
    # elastic L1 on the ranges (pings far off treated as outliers)
    K = ms.n - 1
    rho = 0.1
    for it in range(40):
        wm = int(window_max(ms, pt.bad, K))
        res_d = np.maximum(ms.dlo + SAFE_D - pt.d, 0) + np.maximum(pt.d - ms.dhi + SAFE_D, 0)
        thr = 0.5 if it < 10 else 0.3
        cand = np.flatnonzero(res_d < thr)
        if log_every:
            log(f"  fit {it}: violated {int(pt.bad.sum())}, window max {wm}, "
                f"L1 {res_d[cand].sum():.4f}")
        S = sensitivities(ms, pt.X, block)
        rows, _ = range_rows(ms, pt.X, S)
        P, nc = rows.shape[1], len(cand)
        lo = ms.dlo[cand] + MU - pt.d[cand]
        hi = ms.dhi[cand] - MU - pt.d[cand]
        A = np.block([[rows[cand], -np.eye(nc)], [-rows[cand], -np.eye(nc)]])
        bnd = _bounds(ms, pt, block, rho, rho) + [(0, None)] * nc
        c = np.concatenate([np.zeros(P), np.ones(nc)])
        res = linprog(c, A_ub=A, b_ub=np.concatenate([hi, -lo]), bounds=bnd, method="highs")
        if res.status != 0:
            break
        x0s, us = _apply(ms, pt, np.array([1.0, 0.5, 0.25, 0.1])[:, None] * res.x[None, :P],
                         block)
        X = simulate(ms, x0s, us)
        d = ranges(ms, X)
        rd = np.maximum(ms.dlo + SAFE_D - d, 0) + np.maximum(d - ms.dhi + SAFE_D, 0)
        cost = np.minimum(rd, thr).sum(axis=1) + 0.01 * violated(ms, d).sum(axis=1)
        old = np.minimum(res_d, thr).sum() + 0.01 * pt.bad.sum()
        i = int(np.argmin(cost))
        if cost[i] >= old - 1e-9:
            rho *= 0.3
            if rho < 1e-4:
                break
            continue
        pt = Point(ms, x0s[i], us[i])
        res_d = np.maximum(ms.dlo + SAFE_D - pt.d, 0) + np.maximum(pt.d - ms.dhi + SAFE_D, 0)
        if window_max(ms, pt.bad, K) <= ms.q and np.all((res_d == 0) | (res_d >= thr)):
            break
    return pt


# --- rigorous verification ----------------------------------------------------------------

def verify(ms: Mission, x0: np.ndarray, u: np.ndarray, K: np.ndarray) -> dict[str, np.ndarray]:
    """Interval verification of witnesses ``x0`` (W, 4), ``u`` (W, n - 1, 2) at steps ``K``
    (W,): enclosures of the exact Euler states, ping by ping first-hit enclosures, the
    window condition. Returns the state enclosures and whether each witness passes."""
    from boundest.ctc import CtcRayCast
    from boundest.interval import Interval, cos, sin
    W, n = len(K), ms.n
    inputs_ok = np.all((u >= ms.ulo + SAFE_U) & (u <= ms.uhi - SAFE_U), axis=(1, 2))
    x0_ok = np.all((x0 >= ms.x0lo + SAFE_U) & (x0 <= ms.x0hi - SAFE_U), axis=1)
    dt = Interval(np.nextafter(ms.dt, -np.inf), np.nextafter(ms.dt, np.inf))
    lo, hi = np.empty((W, n, 4)), np.empty((W, n, 4))
    st = [Interval(x0[:, i], x0[:, i]) for i in range(4)]
    for k in range(n):
        for i in range(4):
            lo[:, k, i], hi[:, k, i] = st[i].lo, st[i].hi
        if k == n - 1:
            break
        x, y, th, v = st
        u1 = Interval(u[:, k, 0], u[:, k, 0])
        u2 = Interval(u[:, k, 1], u[:, k, 1])
        st = [x + dt * (v * cos(th)), y + dt * (v * sin(th)), th + dt * (u2 - u1),
              v + dt * (u1 + u2 - v)]
    beta_lo = (Interval(lo[..., 2], hi[..., 2]) + ms.alpha).lo
    beta_hi = (Interval(lo[..., 2], hi[..., 2]) + ms.alpha).hi
    box = Interval(np.stack([lo[..., 0], lo[..., 1], beta_lo, np.zeros((W, n))], axis=-1),
                   np.stack([hi[..., 0], hi[..., 1], beta_hi, np.full((W, n), 1e3)], axis=-1))
    dbox = CtcRayCast(ms.pool).contract(box)
    sat = (dbox.lo[..., 3] >= ms.dlo + SAFE_D) & (dbox.hi[..., 3] <= ms.dhi - SAFE_D)
    sat &= ~np.isnan(dbox.lo[..., 3])
    wmax = np.array([window_max(ms, ~sat[w], int(K[w])) for w in range(W)])
    # free space: inside the rectangle, outside the pillars
    seg = ms.pool.segments.reshape(-1, 2)
    free = np.ones((W, n), bool)
    free &= (lo[..., 0] > seg[:, 0].min()) & (hi[..., 0] < seg[:, 0].max())
    free &= (lo[..., 1] > seg[:, 1].min()) & (hi[..., 1] < seg[:, 1].max())
    for (cx, cy), r in zip(ms.pool.centers, ms.pool.radii, strict=True):
        dx = np.maximum(np.maximum(cx - hi[..., 0], lo[..., 0] - cx), 0)
        dy = np.maximum(np.maximum(cy - hi[..., 1], lo[..., 1] - cy), 0)
        free &= dx * dx + dy * dy > r * r * (1 + 1e-9)
    free_ok = np.array([free[w, :int(K[w]) + 1].all() for w in range(W)])
    return {"lo": lo, "hi": hi, "ok": inputs_ok & x0_ok & (wmax <= ms.q), "wmax": wmax,
            "free": free_ok, "unsat": np.array([int((~sat[w, :int(K[w]) + 1]).sum())
                                                 for w in range(W)])}


def witness_mission(ms: Mission, nominal: Point, steps: np.ndarray, block: int,
                    restarts: int = 0) -> dict[str, Any]:
    t0 = time.perf_counter()
    objs = [(0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0)]
    x0s, us, Ks, lin, gain_restarts = [], [], [], [], []
    for K in steps:
        ends = []
        for comp, sign in objs:
            p = extremise(ms, nominal, int(K), comp, sign, block)
            greedy = p.X[K, comp]
            rng = np.random.default_rng(int(K))
            for _ in range(restarts if ms.q > 0 else 0):
                r = extremise(ms, nominal, int(K), comp, sign, block, rng=rng)
                if sign * (r.X[K, comp] - p.X[K, comp]) > 0:
                    p = r
            gain_restarts.append(sign * (p.X[K, comp] - greedy))
            lin.append(linear_gain(ms, p, int(K), comp, sign, block))
            x0s.append(p.x0)
            us.append(p.u)
            Ks.append(int(K))
            ends.append(p.X[K, comp])
        log(f"  {ms.name} K={K}: float64 widths x {ends[0] - ends[1]:.3f} "
            f"y {ends[2] - ends[3]:.3f} ({time.perf_counter() - t0:.0f} s)")
    V = verify(ms, np.array(x0s), np.array(us), np.array(Ks))
    ok = V["ok"].reshape(len(steps), 4)
    lo, hi = V["lo"], V["hi"]
    wx, wy = [], []
    for i, K in enumerate(steps):
        a, b, c, d = 4 * i, 4 * i + 1, 4 * i + 2, 4 * i + 3
        wx.append(max(lo[a, K, 0] - hi[b, K, 0], 0.0) if ok[i, 0] and ok[i, 1] else 0.0)
        wy.append(max(lo[c, K, 1] - hi[d, K, 1], 0.0) if ok[i, 2] and ok[i, 3] else 0.0)
    lin_a = np.array(lin).reshape(len(steps), 4)
    g = np.array(gain_restarts).reshape(len(steps), 4)
    nom = verify(ms, nominal.x0[None], nominal.u[None], np.array([ms.n - 1]))
    return {"steps": [int(k) for k in steps], "width_x": wx, "width_y": wy,
            "mean_width_x": float(np.mean(wx)), "mean_width_y": float(np.mean(wy)),
            "first_order_gap_mean_xy": [float(np.nanmean(lin_a[:, 0] + lin_a[:, 1])),
                                        float(np.nanmean(lin_a[:, 2] + lin_a[:, 3]))],
            "restarts": restarts,
            "restart_gain_mean_xy": [float(np.mean(g[:, 0] + g[:, 1])),
                                     float(np.mean(g[:, 2] + g[:, 3]))],
            "witnesses_verified": int(V["ok"].sum()), "witnesses": int(V["ok"].size),
            "witnesses_in_free_space": int(V["free"].sum()),
            "most_pings_unsatisfied_in_a_window": int(V["wmax"].max()),
            "nominal_verified": bool(nom["ok"][0]),
            "nominal_window_max_unsatisfied": int(nom["wmax"][0]),
            "time_s": time.perf_counter() - t0}


def observer_widths(data: Any, q: int, m: int, steps: np.ndarray) -> dict[str, Any]:
    from boundest.scenarios.pool import solve_pool
    out: dict[str, Any] = {}
    modes = {"box": {"sweeps": 0}, "smoothed": {"sweeps": 1},
             "heading_paving_0.05": {"sweeps": 0, "paving_heading": 0.05}}
    for name, opt in modes.items():
        r = solve_pool(data, q=q, m=m, **opt)
        w = r.widths()
        out[name] = {"mean_width_xy_all_steps": [float(np.nanmean(w[:, 0])),
                                                 float(np.nanmean(w[:, 1]))],
                     "mean_width_xy_at_steps": [float(np.nanmean(w[steps, 0])),
                                                float(np.nanmean(w[steps, 1]))],
                     "empty_steps": int(np.count_nonzero(r.empty)), "time_s": r.time_s,
                     "box_mid": r.boxes.mid()}
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out")
    ap.add_argument("--seeds", default="1,2,3,4")
    ap.add_argument("--q0-seed", type=int, default=1)
    ap.add_argument("--q", type=int, default=8)
    ap.add_argument("--m", type=int, default=80)
    ap.add_argument("--every", type=int, default=20, help="sample every this many steps")
    ap.add_argument("--block", type=int, default=1, help="inputs per perturbation block")
    ap.add_argument("--restarts", type=int, default=1,
                    help="extra searches per objective with a randomised release order (q > 0)")
    ap.add_argument("--no-embedded", action="store_true")
    args = ap.parse_args()

    from boundest.scenarios.pool_data import load_pool
    from boundest.scenarios.pool_sim import simulate_pool

    rec: dict[str, Any] = {
        "benchmark": "pool_exact", "started": time.strftime("%Y-%m-%dT%H:%M:%S"),
        "machine": {"cpu": cpu_model(), "cores": os.cpu_count(),
                    "python": platform.python_version()},
        "args": vars(args), "missions": {}}
    n = 406
    steps = np.arange(args.every, n, args.every)

    jobs: list[tuple[str, Any, Any, int]] = []
    skipped = {}
    for s in [int(v) for v in args.seeds.split(",") if v]:
        data, truth = simulate_pool(seed=s)
        most = int(window_max(mission_from(data, "", args.q, args.m), truth.outlier, n - 1))
        if most > args.q:  # the truth is outside the q-relaxed set: not a nominal
            skipped[f"seed{s}"] = most
            continue
        jobs.append((f"sim_seed{s}_q{args.q}", data, truth, args.q))
    rec["seeds_skipped_most_outliers_in_a_window"] = skipped
    data0, truth0 = simulate_pool(seed=args.q0_seed, p_outlier=0.0)
    jobs.append((f"sim_seed{args.q0_seed}_no_outliers_q0", data0, truth0, 0))
    if not args.no_embedded:
        jobs.append((f"embedded_q{args.q}", load_pool(), None, args.q))

    for name, data, truth, q in jobs:
        log(f"{name}")
        obs = observer_widths(data, q, args.m, steps)
        ms = mission_from(data, name, q, args.m)
        if truth is not None:
            nominal = Point(ms, truth.states[0].copy(), truth.inputs[:-1].copy())
            out_w = window_max(ms, truth.outlier, n - 1)
        else:
            nominal = fit_nominal(ms, obs["smoothed"]["box_mid"], args.block)
            out_w = None
        res = witness_mission(ms, nominal, steps, args.block, args.restarts)
        for v in obs.values():
            v.pop("box_mid")
        res["observer"] = obs
        res["q"], res["m"] = q, args.m
        if out_w is not None:
            res["most_outliers_in_a_window"] = int(out_w)
        rec["missions"][name] = res
        log(f"  witnessed mean widths x {res['mean_width_x']:.3f} y {res['mean_width_y']:.3f}"
            f"; observer smoothed {obs['smoothed']['mean_width_xy_at_steps']}, heading paving "
            f"{obs['heading_paving_0.05']['mean_width_xy_at_steps']}; verified "
            f"{res['witnesses_verified']}/{res['witnesses']}")
    rec["finished"] = time.strftime("%Y-%m-%dT%H:%M:%S")
    emit(rec, args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
