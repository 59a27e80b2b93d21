"""Simulated missions of the pool robot with their truth, for tests and Monte Carlo studies of
Jaulin's robust set-membership observer (pool robot).

The data have exactly the structure of :class:`~boundest.scenarios.pool_data.PoolData` and the
definition of the pool mission:

- a waypoint-following controller visits the three waypoints of the setup in turn (acceptance
  radius 0.5 m) and switches the propellers off after the last one. It commands the
  accelerations ``u1 + u2 = speed`` and ``u2 - u1 = clip(gain * heading error, -1, 1)``;
- the true input is the command plus a per-mission bias (at most 0.025) plus a per-sample
  noise (at most 0.02): at most 90 % of the half-width 0.05 of the input boxes
  ``command +- 0.05``;
- the state is the float recursion ``X[k+1] = euler_step(X[k], u[k], dt)`` (the exact model),
  from a random point of the initial box (not its centre), at rest (``v = 0``);
- the sonar beam is ``alpha_k = (k pi / 40) mod 2 pi`` relative to the robot, and the true
  distance is ``map.distance(x, y, theta + alpha)``. An inlier reads ``d + e``, ``e`` uniform in
  ``(-0.1, 0.1)``, and its box ``reading +- 0.1`` contains ``d``; each ping is independently an
  outlier with probability ``p_outlier``, reading a fixed wrong distance (one constant per
  mission) plus the same noise: its box usually misses ``d`` (``PoolTruth.outlier`` marks it).

A batch of ``M`` missions is simulated at once (arrays with a leading mission axis; one loop
over the samples). Mission ``i`` of the batch of seed ``s`` is the single mission of seed
``s + i``, bit for bit: the random numbers are a counter-based hash (SplitMix64) of the mission
seed, the stream and the index, so they do not depend on the batch.

Examples
--------
>>> data, truth = simulate_pool(seed=1)
>>> data.n, truth.states.shape, truth.inputs.shape
(406, (406, 4), (406, 2))
>>> bool(data.inputs.contains(truth.inputs).all())
True
>>> bool(data.ranges[~truth.outlier].contains(truth.distance[~truth.outlier]).all())
True
>>> batch, truths = simulate_pool(seed=1, n_missions=3)
>>> batch.ranges.shape, bool((truths.states[0] == truth.states).all())
((3, 406), True)
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..ctc.obstacles import ObstacleMap
from ..interval import Interval
from ._data import embedded, read_text
from .pool_data import PoolData, euler_step

__all__ = ["INPUT_HALF_WIDTH", "RANGE_HALF_WIDTH", "PoolTruth", "simulate_pool"]

#: Half-width of the input boxes [m/s^2].
INPUT_HALF_WIDTH = 0.05
#: Half-width of the sonar boxes [m].
RANGE_HALF_WIDTH = 0.1
_BIAS = 0.025  # largest per-mission input bias
_NOISE = 0.02  # largest per-sample input noise (bias + noise <= 90 % of the half-width)

_GAMMA = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)


@dataclass(repr=False)
class PoolTruth:
    """The truth of a simulated mission (arrays with a leading mission axis for a batch).

    Attributes
    ----------
    states : ndarray, shape (n, 4) or (M, n, 4)
        ``(x, y, theta, v)`` at every sample.
    inputs : ndarray, shape (n, 2) or (M, n, 2)
        The true ``(u1, u2)`` applied on ``[t_k, t_{k+1})``.
    outlier : ndarray of bool, shape (n,) or (M, n)
        Which pings are outliers.
    distance : ndarray, shape (n,) or (M, n)
        True first-hit distance along the beam at every sample.
    outlier_range : float or ndarray, shape (M,)
        The fixed wrong distance of the outliers (before noise).
    waypoint_k : ndarray of int, shape (3,) or (M, 3)
        Sample at which each waypoint was reached (-1: not reached).
    """

    states: NDArray[np.float64]
    inputs: NDArray[np.float64]
    outlier: NDArray[np.bool_]
    distance: NDArray[np.float64]
    outlier_range: float | NDArray[np.float64]
    waypoint_k: NDArray[np.intp]

    def __repr__(self) -> str:
        shape = self.outlier.shape
        batch = f"missions={shape[0]}, " if len(shape) == 2 else ""
        return (f"PoolTruth({batch}samples={shape[-1]}, "
                f"outliers={int(self.outlier.sum())})")


def _mix(z: NDArray[np.uint64]) -> NDArray[np.uint64]:
    """The SplitMix64 finaliser (wrapping uint64 arithmetic)."""
    z = (z ^ (z >> np.uint64(30))) * _M1
    z = (z ^ (z >> np.uint64(27))) * _M2
    return z ^ (z >> np.uint64(31))


def _uniform(seeds: NDArray[np.uint64], stream: int, size: int) -> NDArray[np.float64]:
    """``(M, size)`` uniforms in ``[0, 1)``, a hash of (mission seed, stream, index)."""
    with np.errstate(over="ignore"):
        key = _mix(seeds * _GAMMA + np.uint64(stream + 1) * _M2)
        idx = np.arange(1, size + 1, dtype=np.uint64) * _GAMMA
        z = _mix(key[:, None] + idx[None, :])
    return (z >> np.uint64(11)).astype(np.float64) * 2.0**-53


def _setup() -> dict:
    return json.loads(read_text(embedded("pool_setup.json")))


def _check(ok: bool | np.bool_, what: str) -> None:
    if not ok:  # not an assert: must also hold under python -O
        raise AssertionError(f"simulate_pool: {what}")


def _in_free_space(pool: ObstacleMap, xy: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Strictly inside the bounding box of the walls (the pool rectangle) and outside every
    disc."""
    lo = pool.segments.reshape(-1, 2).min(axis=0)
    hi = pool.segments.reshape(-1, 2).max(axis=0)
    ok = np.all((xy > lo) & (xy < hi), axis=-1)
    for c, r in zip(pool.centers, pool.radii, strict=True):
        ok &= np.hypot(xy[..., 0] - c[0], xy[..., 1] - c[1]) > r
    return ok


def simulate_pool(seed: int = 0, n_missions: int | None = None, p_outlier: float = 0.05, *,
                  n_samples: int = 406, dt: float = 0.04, t0: float = 0.0,
                  speed: float = 1.2, gain: float = 2.0,
                  outlier_range: float | None = None) -> tuple[PoolData, PoolTruth]:
    """Simulate pool missions: the data an observer gets, and the truth.

    Parameters
    ----------
    seed : int
        Seed (``>= 0``) of the single mission, or of mission 0 of a batch: mission ``i`` has
        the seed ``seed + i``.
    n_missions : int, optional
        Simulate a batch of this many missions (a leading axis on every per-mission array);
        None: one mission, without that axis.
    p_outlier : float
        Probability that a ping is an outlier, in ``[0, 1]``.
    n_samples, dt, t0 : int, float, float
        The sample grid (default: that of the setup, 406 samples of 0.04 s).
    speed : float
        Commanded ``u1 + u2`` while steering (the speed it tends to) [m/s].
    gain : float
        Heading gain: ``u2 - u1 = clip(gain * error, -1, 1)``.
    outlier_range : float, optional
        The fixed wrong distance of outliers; None: one per mission, uniform in [1, 25] m.

    Returns
    -------
    data : PoolData
        With the initial box, map, ``max_range`` of the setup.
    truth : PoolTruth

    Raises
    ------
    AssertionError
        If the truth leaves the free space of the pool, or a box misses its truth (never for
        the defaults).
    """
    if seed < 0 or (n_missions is not None and n_missions < 1) or not 0 <= p_outlier <= 1:
        raise ValueError(f"need seed >= 0, n_missions >= 1 and 0 <= p_outlier <= 1, got "
                         f"seed = {seed!r}, n_missions = {n_missions!r}, "
                         f"p_outlier = {p_outlier!r}")
    setup = _setup()
    pool = ObstacleMap.pool()
    waypoints = np.array(setup["mission"]["waypoints"], dtype=np.float64)
    radius = float(setup["mission"]["acceptance_radius_m"])
    box = setup["initial_state_box"]
    x0_lo = np.array([box[s][0] for s in ("x", "y", "theta", "v")])
    x0_hi = np.array([box[s][1] for s in ("x", "y", "theta", "v")])
    M, n = 1 if n_missions is None else int(n_missions), int(n_samples)
    seeds = np.uint64(seed) + np.arange(M, dtype=np.uint64)

    # initial state: a random point of the inner 80 % of the box, at rest
    x0 = x0_lo + (x0_hi - x0_lo) * (0.1 + 0.8 * _uniform(seeds, 0, 4))
    x0[:, 3] = 0.0
    bias = _BIAS * (2 * _uniform(seeds, 1, 2) - 1)                               # (M, 2)
    noise = _NOISE * (2 * _uniform(seeds, 2, 2 * n).reshape(M, n, 2) - 1)       # (M, n, 2)

    states = np.empty((M, n, 4))
    command = np.empty((M, n, 2))
    states[:, 0] = x0
    target = np.zeros(M, dtype=np.intp)
    waypoint_k = np.full((M, len(waypoints)), -1, dtype=np.intp)
    rows = np.arange(M)
    for k in range(n):
        X = states[:, k]
        wp = waypoints[np.minimum(target, len(waypoints) - 1)]
        reached = (np.hypot(wp[:, 0] - X[:, 0], wp[:, 1] - X[:, 1]) < radius) & (
            target < len(waypoints))
        waypoint_k[rows[reached], target[reached]] = k
        target = target + reached
        wp = waypoints[np.minimum(target, len(waypoints) - 1)]
        err = np.arctan2(wp[:, 1] - X[:, 1], wp[:, 0] - X[:, 0]) - X[:, 2]
        err = (err + np.pi) % (2 * np.pi) - np.pi
        turn = np.clip(gain * err, -1.0, 1.0)
        on = target < len(waypoints)
        command[:, k, 0] = np.where(on, 0.5 * (speed - turn), 0.0)
        command[:, k, 1] = np.where(on, 0.5 * (speed + turn), 0.0)
        if k + 1 < n:
            states[:, k + 1] = euler_step(X, command[:, k] + bias + noise[:, k], dt)
    u_true = command + bias[:, None, :] + noise
    u_box = Interval.trusted(command - INPUT_HALF_WIDTH, command + INPUT_HALF_WIDTH)
    _check(bool(np.all(u_box.contains(u_true))), "an input box misses the true input")
    _check(bool(np.all(_in_free_space(pool, states[..., :2]))),
           "the robot left the free space of the pool")

    # sonar
    alpha = np.mod(np.arange(n) * np.pi / 40, 2 * np.pi)
    distance = pool.distance(states[..., 0], states[..., 1], states[..., 2] + alpha)
    _check(bool(np.all(np.isfinite(distance))), "a beam hits nothing")
    outlier = _uniform(seeds, 3, n) < p_outlier
    wrong = (np.full(M, float(outlier_range)) if outlier_range is not None
             else 1.0 + 24.0 * _uniform(seeds, 4, 1)[:, 0])
    # noise in (-0.1, 0.1), a hair inside so that the float box surely contains the truth
    e = RANGE_HALF_WIDTH * (1 - 1e-9) * (2 * _uniform(seeds, 5, n) - 1)
    reading = np.where(outlier, wrong[:, None], distance) + e
    ranges = Interval.trusted(reading - RANGE_HALF_WIDTH, reading + RANGE_HALF_WIDTH)
    _check(bool(np.all(ranges.contains(distance)[~outlier])), "an inlier box misses the truth")

    x0_box = Interval.trusted(np.nextafter(x0_lo, -np.inf), np.nextafter(x0_hi, np.inf))
    sonar = setup["sonar"]
    data = PoolData(t0=float(t0), dt=float(dt), inputs=u_box, alpha=alpha, ranges=ranges,
                    x0=x0_box, map=pool, p_outlier=float(p_outlier),
                    max_range=float(sonar["max_range_m"]),
                    source=f"simulate_pool(seed={seed})")
    truth = PoolTruth(states, u_true, outlier, distance, wrong, waypoint_k)
    if n_missions is None:
        data = data.mission(0)
        data.source = f"simulate_pool(seed={seed})"
        truth = PoolTruth(states[0], u_true[0], outlier[0], distance[0], float(wrong[0]),
                          waypoint_k[0])
    return data, truth
