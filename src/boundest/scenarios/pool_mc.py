"""Monte Carlo check of what the pool robot's robust observer claims (Jaulin's robust
set-membership observer), on any ``concurrent.futures.Executor``.

``pool_monte_carlo`` simulates missions with random outliers
(:func:`~boundest.scenarios.pool_sim.simulate_pool`, each ping an outlier with probability
``p_outlier``), runs the batched observer :func:`~boundest.scenarios.pool.solve_pool` on each
chunk of missions, and counts, per step ``k``, the missions whose set ``X_k`` contains the true
state. The observer's claim at ``k`` is ``PoolResult.window_probability[k]``, the probability
that ONE window of ``m`` pings holds at most ``q`` outliers. The recursive set holds the truth
whenever every window since the last restart did, an event of probability at most that: the
one-window probability is not a proven lower bound of the containment, which is exactly what a
Monte Carlo can confront. The frequency comes with its Wilson (1927) score interval.

Chunk ``c`` of missions is the batch of seed ``seed + c * chunk`` (``simulate_pool``: mission
``i`` of it is the single mission of seed ``seed + c * chunk + i``), so the counts do not
depend on the executor, the number of workers or the order the chunks finish in.

Examples
--------
>>> mc = pool_monte_carlo(2, chunk=2, n_samples=60, progress=False)
>>> mc.missions, mc.inside.shape, bool((mc.inside <= 2).all())
(2, (60,), True)
"""

from __future__ import annotations

import math
import time
from concurrent.futures import Executor
from dataclasses import dataclass, field
from functools import partial

import numpy as np
from numpy.typing import NDArray

from ..parallel import executor_workers, map_chunked
from .pool import DEFAULT_SLICES, check_options, solve_pool
from .pool_sim import simulate_pool

__all__ = ["MonteCarloResult", "pool_monte_carlo", "wilson"]

_Z95 = 1.959963984540054  # the standard normal's 0.975 quantile


def wilson(x: NDArray, n: int, z: float = _Z95) -> tuple[NDArray, NDArray]:
    """The Wilson (1927) score interval of the binomial frequencies ``x / n`` (95 % for the
    default ``z``), as arrays ``(lo, hi)``."""
    if n < 1:
        raise ValueError(f"need at least one trial, got n = {n}")
    p = np.asarray(x, dtype=float) / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return np.maximum(0.0, centre - half), np.minimum(1.0, centre + half)


def _windows_ok(outlier: NDArray[np.bool_], m: int, q: int) -> NDArray[np.bool_]:
    """Every window of ``m`` pings ending at or before ``k`` held at most ``q`` outliers."""
    c = np.cumsum(outlier, axis=-1)
    prev = np.concatenate([np.zeros_like(c[..., :m]), c[..., :-m]], axis=-1)
    return ~np.maximum.accumulate((c - prev) > q, axis=-1)


@dataclass
class _Counts:
    """What one chunk of missions contributes (sums over its missions, per step)."""

    inside: NDArray[np.int64]
    windows_ok: NDArray[np.int64]
    inside_when_ok: NDArray[np.int64]
    empty_steps: int
    window_probability: NDArray[np.float64]
    t: NDArray[np.float64]
    solve_s: float


def _chunk_counts(seed_size: tuple[int, int], q: int, m: int, p_outlier: float,
                  n_samples: int, observer: dict) -> _Counts:
    """Simulate the missions of one chunk, run the observer on them, count (on a worker)."""
    seed, size = seed_size
    sim, truth = simulate_pool(seed=seed, n_missions=size, p_outlier=p_outlier,
                               n_samples=n_samples)
    res = solve_pool(sim, q=q, m=m, keep_cells=0, **observer)
    hit = ((res.boxes.lo <= truth.states) & (truth.states <= res.boxes.hi)).all(-1)
    ok = _windows_ok(truth.outlier, m, q)
    return _Counts(hit.sum(0), ok.sum(0), (hit & ok).sum(0), int(res.empty.sum()),
                   np.asarray(res.window_probability, dtype=float), np.asarray(sim.t), res.time_s)


@dataclass
class MonteCarloResult:
    """Per-step containment counts of a Monte Carlo run of the pool observer.

    Attributes
    ----------
    missions, q, m, seed, chunk : int
        The run: missions simulated, outliers allowed in a window, window length, first seed,
        missions per task.
    p_outlier : float
        Probability that a ping is an outlier.
    t : ndarray, shape (n,)
        Time of each step.
    inside : ndarray of int, shape (n,)
        Missions whose set ``X_k`` contains the true state.
    windows_ok : ndarray of int, shape (n,)
        Missions in which every window of pings up to ``k`` held at most ``q`` outliers.
    inside_when_ok : ndarray of int, shape (n,)
        Missions of ``windows_ok`` whose ``X_k`` contains the truth (the guarantee: all).
    window_probability : ndarray, shape (n,)
        The observer's claim ``P(at most q outliers in the window at k)``.
    empty_steps : int
        Steps (over all missions) where the set came out empty and the observer restarted.
    time_s, solve_s : float
        Wall-clock seconds of the run; seconds the observer ran (summed over the tasks).
    workers : int
        Tasks the executor ran at once.
    observer : dict
        The observer's options (:func:`~boundest.scenarios.pool.solve_pool`).
    """

    missions: int
    q: int
    m: int
    p_outlier: float
    seed: int
    chunk: int
    t: NDArray[np.float64]
    inside: NDArray[np.int64]
    windows_ok: NDArray[np.int64]
    inside_when_ok: NDArray[np.int64]
    window_probability: NDArray[np.float64]
    empty_steps: int
    time_s: float
    solve_s: float
    workers: int
    observer: dict = field(default_factory=dict)

    def frequency(self) -> NDArray[np.float64]:
        """Empirical ``P(x_k in X_k)`` per step."""
        return self.inside / self.missions

    def ci(self, z: float = _Z95) -> tuple[NDArray, NDArray]:
        """The Wilson score interval of :meth:`frequency` (95 % by default)."""
        return wilson(self.inside, self.missions, z)

    def to_json(self) -> dict:
        """The fields of ``boundest run pool --monte-carlo N --json FILE`` (docs/json.md)."""
        freq = self.frequency()
        lo, hi = self.ci()
        below = freq < self.window_probability
        return {"scenario": "pool-monte-carlo", "missions": self.missions, "q": self.q,
                "m": self.m, "p_outlier": self.p_outlier, "seed": self.seed,
                "chunk": self.chunk, "workers": self.workers, "observer": self.observer,
                "time_s": self.time_s,
                "solve_s": self.solve_s, "empty_steps_total": self.empty_steps,
                "min_containment": float(freq.min()), "step_of_min": int(freq.argmin()),
                "steps_below_bound": int(below.sum()),
                "steps_ci_hi_below_bound": int((hi < self.window_probability).sum()),
                "guarantee_violations": int((self.windows_ok - self.inside_when_ok).sum()),
                "k": np.arange(self.t.size), "t": self.t,
                "containment_frequency": freq, "ci95_lo": lo, "ci95_hi": hi,
                "window_probability": self.window_probability,
                "all_windows_ok_frequency": self.windows_ok / self.missions}


def pool_monte_carlo(missions: int, q: int = 8, m: int = 80, *, p_outlier: float = 0.05,
                     seed: int = 0, chunk: int = 250, n_samples: int = 406,
                     sweeps: int = 0, carry: bool = True, paving: float | None = None,
                     paving_heading: float | None = None,
                     heading_slices: int = DEFAULT_SLICES,
                     executor: Executor | None = None, progress: bool | None = None
                     ) -> MonteCarloResult:
    """Simulate ``missions`` pool missions, run the robust observer on each, count per step
    how often its set contains the truth.

    Parameters
    ----------
    missions : int
        Missions to simulate (``>= 1``).
    q, m : int
        Outliers allowed in a window of ``m`` pings.
    p_outlier : float
        Probability that a ping is an outlier.
    seed : int
        Seed of the first mission (mission ``i`` has the seed ``seed + i``).
    chunk : int
        Missions per task (the observer runs on a whole chunk as one batch: its cost per step
        is mostly fixed, so large chunks are much cheaper per mission).
    n_samples : int
        Pings per mission (default: the 406 of the embedded mission's setup).
    sweeps, carry, paving, paving_heading, heading_slices
        The observer (:func:`~boundest.scenarios.pool.solve_pool`): smoothing rounds (default
        0, the recursive box observer: 0.02 s a mission, against about 1 s smoothed),
        recursive (True) or pure window (False), an ``(x, y)`` paving, heading slices (about
        1 s a mission at 0.01 rad).
    executor : concurrent.futures.Executor, optional
        Where the chunks run (``boundest.parallel``); None: in this process.
    progress : bool or None
        A progress bar over the chunks (None: only on a terminal).
    """
    if missions < 1 or chunk < 1:
        raise ValueError(f"need missions >= 1 and chunk >= 1, got {missions} and {chunk}")
    if q < 0 or m < 1:
        raise ValueError(f"need q >= 0 and m >= 1, got q = {q}, m = {m}")
    observer = {"sweeps": sweeps, "carry": carry, "paving": paving,
                "paving_heading": paving_heading,
                "heading_slices": None if paving_heading is None else heading_slices}
    check_options(q, m, **observer)  # one clear error here, not one per task
    t0 = time.perf_counter()
    tasks = [(seed + s, min(chunk, missions - s)) for s in range(0, missions, chunk)]
    parts = map_chunked(partial(_chunk_counts, q=q, m=m, p_outlier=p_outlier,
                                n_samples=n_samples, observer=_given(observer)), tasks,
                        executor,
                        chunk=1, progress=progress, desc=f"missions/{chunk}")
    first = parts[0]
    for p in parts[1:]:
        if not np.array_equal(p.window_probability, first.window_probability):
            raise RuntimeError("the chunks of missions disagree on the observer's bound")
    return MonteCarloResult(
        missions, q, m, p_outlier, seed, chunk, first.t,
        sum((p.inside for p in parts), np.zeros_like(first.inside)),
        sum((p.windows_ok for p in parts), np.zeros_like(first.windows_ok)),
        sum((p.inside_when_ok for p in parts), np.zeros_like(first.inside_when_ok)),
        first.window_probability, sum(p.empty_steps for p in parts),
        time.perf_counter() - t0, math.fsum(p.solve_s for p in parts),
        executor_workers(executor), observer)


def _given(observer: dict) -> dict:
    return {k: v for k, v in observer.items() if v is not None}
