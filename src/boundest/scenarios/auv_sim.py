"""A simulated AUV side-scan mine survey with its truth, for tests of the AUV estimator.

The data have exactly the structure of :class:`~boundest.scenarios.auv_data.AuvData` and the
definition of the Redermor survey (Jaulin, Bertholom, Dabe 2007 (Redermor)): world frame
North-East-Down ``p = (north, east, depth)``, body x forward, y starboard, z down, attitude
``(phi, theta, psi)`` with ``psi`` unwrapped, body to world ``R = R_psi R_theta R_phi``, and the
zero-order-hold kinematics ``p[k+1] = p[k] + dt R[k] v[k]``, which is the truth here to the bit
(the positions are its float recursion, :func:`integrate`).

The vehicle starts at the surface, dives to the survey depth, flies lawn-mower legs (parallel,
alternating direction, half-circle turns between them) at a constant speed through the water
in a slowly turning tidal current (so it crabs: the lateral body velocity is not zero), and
surfaces at the end. The seabed is a gently sloping plane with a small undulation. Mines lie on
the seabed between an outbound leg and the next (return) leg, where both see them on
starboard. Each detection satisfies the three constraints of the data definition for the
truth; the body-x coordinate of the mine is zero to float rounding, by construction (a later
sighting turns the true heading of its one sample by the small angle that makes it so).

The sensor boxes are ``measurement +- half-width`` with the half-widths of the real data; the
errors are biased and correlated in time, at most 97 % of the half-width, so the boxes contain
the truth but are not centred on it.

Examples
--------
>>> data, truth = simulate_survey(seed=1, n_samples=3000, n_legs=2)
>>> data.n, truth.p.shape, data.det_k.size > 0
(3000, (3000, 3), True)
>>> bool(data.attitude.contains(truth.attitude).all())
True
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..interval import Interval
from .auv_data import AuvData

__all__ = ["HALF_WIDTH", "AuvTruth", "integrate", "rotation", "simulate_survey", "step"]

#: Half-widths of the sensor boxes of the real survey.
HALF_WIDTH = {"phi": 1.75e-4, "theta": 1.75e-4, "psi": 5.27e-3, "vx": 0.02, "vy": 0.02,
              "vz": 0.02, "a": 0.1, "depth": 0.1, "gps": 2.5, "range": 0.5}
#: Largest error, as a fraction of its half-width.
MAX_ERROR = 0.97
_SURFACE = (0.0, 0.8)  # depth box of the vehicle floating at the surface


@dataclass(repr=False)
class AuvTruth:
    """The true state of a simulated survey.

    Attributes
    ----------
    p : ndarray, shape (n, 3)
        Positions ``(north, east, depth)`` at every sample.
    attitude : ndarray, shape (n, 3)
        ``(phi, theta, psi)``, held over ``[t_k, t_{k+1})``; ``psi`` unwrapped.
    velocity : ndarray, shape (n, 3)
        Body velocity over the ground, held likewise.
    altitude : ndarray, shape (n,)
        Seabed depth below the vehicle minus ``p_z``.
    mines : ndarray, shape (n_mines, 3)
        Mine positions (on the seabed).
    """

    p: NDArray[np.float64]
    attitude: NDArray[np.float64]
    velocity: NDArray[np.float64]
    altitude: NDArray[np.float64]
    mines: NDArray[np.float64]

    def __repr__(self) -> str:
        return f"AuvTruth(samples={self.p.shape[0]}, mines={self.mines.shape[0]})"


def rotation(attitude: ArrayLike) -> NDArray[np.float64]:
    """Body-to-world rotation ``R = R_psi R_theta R_phi``, multiplied out.

    Parameters
    ----------
    attitude : array_like, shape (..., 3)
        ``(phi, theta, psi)``.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        ``R[..., i, j]``: world axis ``i`` of body axis ``j``.
    """
    att = np.asarray(attitude, dtype=np.float64)
    cf, sf = np.cos(att[..., 0]), np.sin(att[..., 0])
    ct, st = np.cos(att[..., 1]), np.sin(att[..., 1])
    cp, sp = np.cos(att[..., 2]), np.sin(att[..., 2])
    rows = ((cp * ct, cp * st * sf - sp * cf, cp * st * cf + sp * sf),
            (sp * ct, sp * st * sf + cp * cf, sp * st * cf - cp * sf),
            (-st, ct * sf, ct * cf))
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


def step(attitude: ArrayLike, velocity: ArrayLike, dt: float) -> NDArray[np.float64]:
    """World displacement ``dt R(attitude) v`` over one sample (sums in a fixed order).

    Parameters
    ----------
    attitude, velocity : array_like, shape (..., 3)
        Attitude and body velocity held over the sample.
    dt : float
        Sampling period.

    Returns
    -------
    ndarray, shape (..., 3)
    """
    R = rotation(attitude)
    v = np.asarray(velocity, dtype=np.float64)
    return dt * (R[..., 0] * v[..., None, 0] + R[..., 1] * v[..., None, 1]
                 + R[..., 2] * v[..., None, 2])


def integrate(p0: ArrayLike, increments: NDArray[np.float64]) -> NDArray[np.float64]:
    """Positions of the recursion ``p[k+1] = p[k] + increments[k]`` (one float add per step).

    Parameters
    ----------
    p0 : array_like, shape (3,)
        Initial position.
    increments : ndarray, shape (n - 1, 3)
        Displacements, e.g. from :func:`step`.

    Returns
    -------
    ndarray, shape (n, 3)
    """
    rows = np.concatenate([np.asarray(p0, dtype=np.float64)[None], increments])
    return np.add.accumulate(rows, axis=0)  # sequential: exactly the float recursion


def _check(ok: bool | np.bool_, what: str) -> None:
    if not ok:  # not an assert: must also hold under python -O
        raise AssertionError(f"simulate_survey: {what}")


def _slow(t: NDArray, rng: np.random.Generator, periods: tuple[float, float]) -> NDArray:
    """A slow signal in [-1, 1]: two sinusoids of random periods in ``periods`` and phases."""
    period = rng.uniform(*periods, size=2)
    phase = rng.uniform(0, 2 * np.pi, size=2)
    weight = rng.dirichlet((2.0, 2.0))
    return (weight[0] * np.sin(2 * np.pi * t / period[0] + phase[0])
            + weight[1] * np.sin(2 * np.pi * t / period[1] + phase[1]))


def _bias(rng: np.random.Generator, lo: float, hi: float) -> float:
    """A constant of magnitude in [lo, hi] and random sign."""
    return float(rng.choice((-1.0, 1.0)) * rng.uniform(lo, hi))


def _boxes(truth: NDArray, error: NDArray, half: float | NDArray, what: str) -> Interval:
    """``truth + error +- half``, checked to contain the truth."""
    _check(bool(np.all(np.abs(error) <= MAX_ERROR * half)), f"{what} error above the bound")
    mid = truth + error
    box = Interval.trusted(mid - half, mid + half)
    _check(bool(np.all(box.contains(truth))), f"a {what} box misses the truth")
    return box


def _smoothstep(x: NDArray) -> NDArray:
    """0 below 0, 1 above 1, a cosine ramp in between."""
    return 0.5 - 0.5 * np.cos(np.pi * np.clip(x, 0.0, 1.0))


def _heading_for_zero_x(att: NDArray, d: NDArray) -> float:
    """The heading nearest ``att[2]`` that puts the world offset ``d`` in the body y-z plane.

    Body x in the world is ``(cos psi cos theta, sin psi cos theta, -sin theta)``, so
    ``x_body = 0`` is ``rho cos(psi - beta) = tan(theta) d_z`` with ``d_h = rho (cos beta,
    sin beta)``.
    """
    rho, beta = np.hypot(d[0], d[1]), np.arctan2(d[1], d[0])
    c = np.tan(att[1]) * d[2] / rho
    if abs(c) >= 1:
        return float("nan")
    best = float("nan")
    for root in (beta + np.arccos(c), beta - np.arccos(c)):
        psi = root + 2 * np.pi * np.round((att[2] - root) / (2 * np.pi))
        if not abs(psi - att[2]) >= abs(best - att[2]):  # also true while best is nan
            best = float(psi)
    return best


def simulate_survey(seed: int = 0, n_samples: int = 6000, dt: float = 0.1, t0: float = 0.0,
                    n_legs: int = 4, n_mines: int = 3, *, speed: float = 1.5,
                    survey_depth: float = 5.0, leg_spacing: float = 50.0,
                    water_depth: float = 15.0) -> tuple[AuvData, AuvTruth]:
    """Simulate a lawn-mower side-scan survey: the data an estimator gets, and the truth.

    Parameters
    ----------
    seed : int
        Seed of the random generator; the result is a function of the arguments.
    n_samples, dt, t0 : int, float, float
        The sample grid ``t0 + k dt``; the mission lasts ``n_samples dt``.
    n_legs : int
        Number of survey legs (alternating direction, half-circle turns of diameter
        ``leg_spacing`` between them). The legs share the time left after the surface phases
        (20 s at each end), the dive and the ascent (30 s each) and the turns.
    n_mines : int
        Number of mines, each seen from starboard first from an outbound leg, then from the
        next leg, which passes the mine on starboard too. A mine is given 1 to 3 sightings at
        random, cut to the passes that see it: without a tie line only these two legs do, so
        in practice a mine is seen once or twice.
    speed : float
        Speed through the water (m/s); the tidal current (0.1-0.2 m/s) adds to it.
    survey_depth : float
        Depth of the legs (m).
    leg_spacing : float
        Distance between the legs (m).
    water_depth : float
        Mean seabed depth (m); the slope is at most 0.005.

    Returns
    -------
    data : AuvData
        Sensor boxes of every sample, GPS and surface boxes at the first and last sample,
        side-scan detections (sorted by sample) with their range boxes.
    truth : AuvTruth
        The positions, attitude, body velocity, altitude and mines that every box contains.

    Raises
    ------
    ValueError
        When the mission is too short for the legs (under 40 s a leg) or an argument is out of
        range.
    """
    if n_legs < 1 or n_mines < 0 or not dt > 0 or speed <= 0.3:
        raise ValueError("need n_legs >= 1, n_mines >= 0, dt > 0 and speed > 0.3 m/s")
    rng = np.random.default_rng(seed)
    n = int(n_samples)
    t = dt * np.arange(n)  # mission time (t0 only names the samples)
    duration = n * dt

    # -- the plan: surface, dive, legs and turns, ascent, surface --------------------------
    t_surface, t_dive = 20.0, 30.0
    radius = leg_spacing / 2
    t_turn = np.pi * radius / speed
    t_leg = (duration - 2 * (t_surface + t_dive) - (n_legs - 1) * t_turn) / n_legs
    if t_leg < 40.0:
        raise ValueError(f"{n} samples of {dt} s are too few for {n_legs} legs "
                         f"(legs of {t_leg:.0f} s; need 40 s)")
    leg_start = t_surface + t_dive + np.arange(n_legs) * (t_leg + t_turn)
    chi0 = rng.uniform(0, 2 * np.pi)  # track of the outbound legs
    chi = np.full(n, chi0)
    for i, start in enumerate(leg_start[:-1]):  # right turn after an outbound leg, then left
        chi += (1.0 if i % 2 == 0 else -1.0) * np.pi * np.clip((t - start - t_leg) / t_turn,
                                                               0.0, 1.0)
    z_end = rng.uniform(0.2, 0.6)
    z_start = rng.uniform(0.2, 0.6)
    wobble = 0.08 * np.sin(2 * np.pi * t / rng.uniform(60, 120) + rng.uniform(0, 2 * np.pi))
    dive = _smoothstep((t - t_surface) / t_dive)
    rise = _smoothstep((t - (duration - t_surface - t_dive)) / t_dive)
    z_plan = (z_start + (survey_depth - z_start) * dive - (survey_depth - z_end) * rise
              + wobble * dive * (1 - rise))

    # tidal current, slowly turning (a semidiurnal tidal ellipse), 0.1-0.2 m/s
    c_mag = 0.15 + 0.05 * np.sin(2 * np.pi * t / 44712 + rng.uniform(0, 2 * np.pi))
    c_dir = rng.uniform(0, 2 * np.pi) + 2 * np.pi * t / 44712
    current = c_mag[:, None] * np.stack([np.cos(c_dir), np.sin(c_dir)], axis=-1)
    # heading crabs into the current so that the ground track follows chi
    across = -np.sin(chi) * current[:, 0] + np.cos(chi) * current[:, 1]
    psi = chi - np.arcsin(across / speed)
    ground_h = speed * np.stack([np.cos(psi), np.sin(psi)], axis=-1) + current
    w_z = np.append(np.diff(z_plan) / dt, 0.0)
    ground = np.column_stack([ground_h, w_z])
    ground_speed = np.hypot(ground_h[:, 0], ground_h[:, 1])

    # small roll and pitch: oscillations, a bank in the turns, pitch with the dive
    turn_rate = np.gradient(psi, dt)
    phi = (0.02 * _slow(t, rng, (20.0, 90.0)) + 0.01 * _slow(t, rng, (5.0, 15.0))
           + np.arctan(ground_speed * turn_rate / 9.81))
    theta = (-np.arctan2(w_z, ground_speed) + 0.01 + 0.015 * _slow(t, rng, (15.0, 60.0)))
    att = np.column_stack([phi, theta, psi])
    R = rotation(att)
    vel = np.einsum("kji,kj->ki", R, ground)  # R^T g: the body velocity over the ground

    p0 = np.array([rng.uniform(-20, 20), rng.uniform(-20, 20), z_start])
    inc = step(att[:-1], vel[:-1], dt)
    p = integrate(p0, inc)

    # seabed: a gentle plane plus an undulation, gradient at most 0.0038 < 0.005
    centre = p[:, :2].mean(axis=0)
    grad = 0.002 * np.array([np.cos(a := rng.uniform(0, 2 * np.pi)), np.sin(a)])
    wave_dir = rng.uniform(0, 2 * np.pi)
    wave_k = 2 * np.pi / 700.0 * np.array([np.cos(wave_dir), np.sin(wave_dir)])
    wave_phase = rng.uniform(0, 2 * np.pi)

    def seabed(h: NDArray) -> NDArray:
        dh = h - centre
        return water_depth + dh @ grad + 0.2 * np.sin(dh @ wave_k + wave_phase)

    # -- mines and detections, in time order -------------------------------------------------
    legs = [i for i in range(0, n_legs - 1, 2)] or list(range(n_legs))
    first_k = []
    for j in range(n_mines):
        i = legs[j % len(legs)]
        share = sum(1 for jj in range(n_mines) if legs[jj % len(legs)] == i)
        slot = sum(1 for jj in range(j) if legs[jj % len(legs)] == i)
        lo, hi = 0.3 + 0.5 * slot / share, 0.3 + 0.5 * (slot + 1) / share
        f = rng.uniform(lo + 0.1 * (hi - lo), hi - 0.1 * (hi - lo))
        first_k.append(round(float(leg_start[i] + f * t_leg) / dt))
    _check(len(set(first_k)) == n_mines, "two mines first seen at one sample")
    sightings = rng.choice([1, 2, 2, 3], size=n_mines)
    lateral = rng.uniform(0.3, 0.7, size=n_mines) * leg_spacing
    used = set(first_k)
    gap = round(30.0 / dt)
    mines = np.zeros((n_mines, 3))
    events = [(k, 0, j) for j, k in enumerate(first_k)]  # (sample, later?, mine)
    heapq.heapify(events)
    det: list[tuple[int, int]] = []
    while events:
        k, later, j = heapq.heappop(events)
        if not later:
            zb = 10.0
            for _ in range(8):  # fixed point: the mine on the seabed (converges fast)
                m = p[k] + R[k] @ np.array([0.0, lateral[j], zb])
                zb += seabed(m[:2]) - m[2]
            mines[j] = m
            _check(abs(seabed(m[:2]) - m[2]) < 1e-9, "mine not on the seabed")
            det.append((k, j))
            # later sightings: the body x of the mine changes sign, mine on starboard
            ks = np.arange(k + gap, n - 1)
            d = mines[j] - p[ks]
            body = np.einsum("kji,kj->ki", R[ks], d)
            rng_ = np.linalg.norm(d, axis=1)
            cand = ks[(np.sign(body[:, 0]) != np.sign(np.append(body[1:, 0], body[-1, 0])))
                      & (body[:, 1] > 0) & (body[:, 2] > 0) & (rng_ > 11) & (rng_ < 48)]
            chosen: list[int] = []
            for kc in cand:
                if len(chosen) == sightings[j] - 1:
                    break
                if (not chosen or kc - chosen[-1] >= gap) and not used & {kc - 1, kc, kc + 1}:
                    chosen.append(int(kc))
                    used.add(int(kc))
                    heapq.heappush(events, (int(kc), 1, j))
            continue
        d = mines[j] - p[k]
        psi_new = _heading_for_zero_x(att[k], d)
        if not abs(psi_new - att[k, 2]) < 0.05:  # also false for nan: drop the sighting
            continue
        R_new = rotation(np.array([att[k, 0], att[k, 1], psi_new]))
        body = R_new.T @ d
        if body[1] <= 0 or body[2] <= 0:
            continue  # cannot happen for a small turn; the old heading is a fine truth too
        att[k, 2], R[k] = psi_new, R_new
        if k < n - 1:
            inc[k] = step(att[k], vel[k], dt)
            p[k + 1:] = integrate(p[k], inc[k:])[1:]
        det.append((k, j))

    # -- truth and checks -------------------------------------------------------------------
    altitude = seabed(p[:, :2]) - p[:, 2]
    det.sort()
    order = np.argsort(first_k)  # mine ids in the order of their first sighting
    rank = np.empty(n_mines, dtype=np.intp)
    rank[order] = np.arange(n_mines)
    mines = mines[order]
    det_k = np.array([k for k, _ in det], dtype=np.intp)
    det_mine = rank[np.array([j for _, j in det], dtype=np.intp)]
    offset = mines[det_mine] - p[det_k]
    body = np.einsum("kji,kj->ki", R[det_k], offset)
    r_true = np.linalg.norm(offset, axis=1)
    _check(bool(np.all(np.abs(body[:, 0]) <= 1e-9)), "x_body of a detection is not 0")
    _check(bool(np.all(body[:, 1:] >= 0)), "a detection is not starboard and below")
    seabed_gap = mines[det_mine, 2] - p[det_k, 2] - altitude[det_k]
    _check(bool(np.all(np.abs(seabed_gap) <= 0.5)), "seabed constraint of a detection")
    _check(bool(np.all(altitude > 1.0)), "the vehicle touches the seabed")
    for end in (0, n - 1):
        _check(_SURFACE[0] <= p[end, 2] <= _SURFACE[1], "not at the surface at a GPS fix")

    # -- sensor errors: biased, correlated in time, at most 97 % of the bound ---------------
    def error(half: float, slow: NDArray, white: float) -> NDArray:
        e = _bias(rng, 0.15, 0.35) + 0.3 * slow + rng.uniform(-white, white, size=n)
        return half * np.clip(e, -MAX_ERROR, MAX_ERROR)

    h = HALF_WIDTH
    schuler = np.sin(2 * np.pi * t / 5040.0 + rng.uniform(0, 2 * np.pi))
    att_err = np.column_stack([
        error(h["phi"], _slow(t, rng, (200.0, 2000.0)), 0.25),
        error(h["theta"], _slow(t, rng, (200.0, 2000.0)), 0.25),
        error(h["psi"], schuler, 0.2)])
    vel_err = np.column_stack([
        np.clip(_bias(rng, 0.001, 0.003) * vel[:, i]
                + h[q] * (_bias(rng, 0.1, 0.25) + 0.15 * _slow(t, rng, (300.0, 3000.0))
                          + np.clip(rng.normal(0, 0.1, size=n), -0.25, 0.25)),
                -MAX_ERROR * h[q], MAX_ERROR * h[q])
        for i, q in enumerate(("vx", "vy", "vz"))])
    a_err = error(h["a"], _slow(t, rng, (100.0, 1000.0)), 0.25)
    drift = _bias(rng, 0.1, 0.25) * t / max(t[-1], dt)
    depth_err = h["depth"] * np.clip(_bias(rng, 0.15, 0.35) + drift
                                     + rng.uniform(-0.2, 0.2, size=n), -MAX_ERROR, MAX_ERROR)
    fix_k = np.array([0, n - 1], dtype=np.intp)
    gps_err = h["gps"] * rng.uniform(-0.8, 0.8, size=(2, 2))
    fix_h = _boxes(p[fix_k, :2], gps_err, h["gps"], "GPS")
    fix = Interval.trusted(np.column_stack([fix_h.lo, np.full(2, _SURFACE[0])]),
                        np.column_stack([fix_h.hi, np.full(2, _SURFACE[1])]))
    r_err = h["range"] * (_bias(rng, 0.05, 0.3)
                          + rng.uniform(-0.3, 0.3, size=det_k.size))
    halves = np.array([h["phi"], h["theta"], h["psi"]])
    data = AuvData(
        t0=float(t0), dt=float(dt),
        attitude=_boxes(att, att_err, halves, "attitude"),
        velocity=_boxes(vel, vel_err, h["vx"], "velocity"),
        altitude=_boxes(altitude, a_err, h["a"], "altitude"),
        depth=_boxes(p[:, 2], depth_err, h["depth"], "depth"),
        fix_k=fix_k, fix=fix, det_k=det_k, det_mine=det_mine,
        det_range=_boxes(r_true, r_err, h["range"], "range"),
        n_mines=n_mines, seabed_tol=0.5, source=f"<simulated seed={seed}>")
    truth = AuvTruth(p=p, attitude=att, velocity=vel, altitude=altitude, mines=mines)
    return data, truth
