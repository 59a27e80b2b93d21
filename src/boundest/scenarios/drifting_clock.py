"""The drifting clock of Rohou et al. 2018 (section 5, equations 16-22, Table 2).

An underwater beacon at ``(0, 0, -10)`` keeps a clock ``tau = h(t)`` that drifts from the
reference time ``t`` (the truth, unknown to the solver, is ``h(t) = 0.045 t^2 + 0.98 t``, eq. 16)
with ``h(0) = 0`` and a bounded rate (eq. 17)::

    h'(t) in [0.08, 0.12] t + [0.97, 1.08]

A boat follows a known schedule up to bounded errors (eqs. 18, 19)::

    x(t) in ([70, 90], [10, 30]) + 100 (cos t, sin t)
    v(t) in ([-0.1, 0.1], [-0.1, 0.1]) + 100 (-sin t, cos t)

and the beacon measures its distance ``z_i in [z_i]`` at clock times ``tau_i`` (Table 2). The
constraint network (CN 20)::

    x' = v,  y = sqrt(x1^2 + x2^2 + 100),  w = (x1 v1 + x2 v2) / y,  y' = w,
    h' = phi,  h(0) = 0,  tau_i = h(t_i),  z_i = y(t_i)       (two CtcEval per measurement)

contracts ``[h]`` and the unknown reference times ``[t_i]``. The data of Table 2 are consistent
with ``t_i = 1.5 i`` and the boat at ``(90, 20) + 100 (cos t, sin t)`` (every ``[z_i]`` holds the
distance at ``h^{-1}(tau_i)``; tests check it).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import interval as iv
from ..expr import Var
from ..expr import functions as ef
from ..interval import Interval
from ..tube import ContractorNetwork, CtcDeriv, CtcEval, CtcSlices, Tube, time_grid
from ._data import check_index, check_sorted, embedded, read_csv

__all__ = [
    "DEPTH",
    "H_TRUE",
    "ClockMeasurements",
    "ClockResult",
    "ClockTruth",
    "load",
    "simulate",
    "solve",
    "t_final",
]

#: Depth of the beacon (m).
DEPTH = 10.0
#: Coefficients ``(a, b)`` of the true drift ``h(t) = a t^2 + b t`` (equation 16).
H_TRUE = (0.045, 0.98)

def _dec(lo: float, hi: float) -> Interval:
    """An interval enclosing the decimal bounds ``lo``, ``hi`` (one ulp outward)."""
    return Interval(np.nextafter(lo, -np.inf), np.nextafter(hi, np.inf))


#: Equation 17: h'(t) in RATE t + OFFSET.
RATE, OFFSET = _dec(0.08, 0.12), _dec(0.97, 1.08)
#: Equations 18-19: the boat's offset from the circle and the error on its velocity.
X_OFFSET = (_dec(70.0, 90.0), _dec(10.0, 30.0))
V_ERROR = _dec(-0.1, 0.1)


@dataclass
class ClockMeasurements:
    """Distances ``z_i in [z_i]`` measured at clock times ``tau_i`` (``tau`` is an interval
    enclosing the decimal datum)."""

    tau: Interval
    z: Interval
    source: str = "<memory>"

    def __post_init__(self) -> None:
        if self.tau.ndim != 1 or self.z.shape != self.tau.shape:
            raise ValueError(f"tau and z must be 1-D of one length, got {self.tau.shape}, "
                             f"{self.z.shape}")

    def __len__(self) -> int:
        return self.tau.shape[0]


def load(path: str | Path | None = None) -> ClockMeasurements:
    """Read Table 2 (default: the embedded ``rohou2018_clock.csv``).

    Columns ``i, tau, z_lo, z_hi`` (no others); rows ``i = 1, 2, ...`` in order, ``tau``
    strictly increasing (a clock time is exact and finite); ``z_lo`` may be ``-inf`` and
    ``z_hi`` ``inf`` (a distance bounded on one side only). Values are decimals, enclosed one
    ulp outward. Errors (one ``DataError`` naming file, line and value): missing or unexpected
    columns, non-numbers, ``z_lo > z_hi``, a repeated or unsorted row, a negative ``tau`` or
    ``z_hi``.
    """
    path = Path(embedded("rohou2018_clock.csv") if path is None else path)
    cols = read_csv(path, {"i": "finite", "tau": "finite", "z_lo": "lo", "z_hi": "hi"})
    for name in ("tau", "z_hi"):
        bad = np.flatnonzero(cols[name] < 0)
        if bad.size:
            k = int(bad[0])
            raise cols.error(k, f"{name} = {float(cols[name][k])!r} is negative")
    check_index(cols, "i", 1)
    check_sorted(cols, "tau", strict=True)
    tau = Interval.trusted(np.nextafter(cols["tau"], -np.inf), np.nextafter(cols["tau"], np.inf))
    z = Interval.trusted(np.nextafter(cols["z_lo"], -np.inf), np.nextafter(cols["z_hi"], np.inf))
    return ClockMeasurements(tau, z, str(path))


@dataclass(frozen=True)
class ClockTruth:
    """A drift ``h(t) = a t^2 + b t`` and a boat at ``c(t) + 100 (cos t, sin t)`` with the
    offset ``c_j(t) = m_j + A_j sin(omega_j t + phase_j)`` (``offset`` rows
    ``(m, A, omega, phase)``)."""

    h: tuple[float, float] = H_TRUE
    offset: tuple[tuple[float, float, float, float], ...] = ((90.0, 0.0, 1.0, 0.0),
                                                             (20.0, 0.0, 1.0, 0.0))

    def drift(self, t: ArrayLike) -> NDArray[np.float64]:
        """``h(t)``."""
        t = np.asarray(t, dtype=np.float64)
        return (self.h[0] * t + self.h[1]) * t

    def drift_rate(self, t: ArrayLike) -> NDArray[np.float64]:
        """``h'(t)``."""
        return 2 * self.h[0] * np.asarray(t, dtype=np.float64) + self.h[1]

    def inverse_drift(self, tau: ArrayLike) -> NDArray[np.float64]:
        """The reference time ``t >= 0`` with ``h(t) = tau`` (float)."""
        a, b = self.h
        tau = np.asarray(tau, dtype=np.float64)
        return 2 * tau / (b + np.sqrt(b * b + 4 * a * tau))

    def boat(self, t: ArrayLike) -> NDArray[np.float64]:
        """Boat position ``x(t)``, shape ``(m, 2)``."""
        t = np.asarray(t, dtype=np.float64).ravel()
        c = [m + A * np.sin(w * t + p) for m, A, w, p in self.offset]
        return np.stack([c[0] + 100 * np.cos(t), c[1] + 100 * np.sin(t)], axis=1)

    def boat_velocity(self, t: ArrayLike) -> NDArray[np.float64]:
        """``x'(t)``, shape ``(m, 2)``."""
        t = np.asarray(t, dtype=np.float64).ravel()
        c = [A * w * np.cos(w * t + p) for _, A, w, p in self.offset]
        return np.stack([c[0] - 100 * np.sin(t), c[1] + 100 * np.cos(t)], axis=1)

    def distance(self, t: ArrayLike) -> NDArray[np.float64]:
        """``y(t) = |(x(t), -10)|``."""
        x = self.boat(t)
        return np.sqrt(x[:, 0] ** 2 + x[:, 1] ** 2 + DEPTH**2)


def _latest_reference_time(meas: ClockMeasurements) -> float:
    """An upper bound of every reference time ``t_i`` with ``h(t_i) = tau_i``.

    With ``h(0) = 0`` and the slowest rate of eq. 17, ``h(t) >= r t^2 / 2 + o t`` (``r``, ``o``
    the lower bounds of RATE and OFFSET), so ``t_i`` lies below the positive root of
    ``r t^2 / 2 + o t = max tau``; the root is computed in floats, plus 1e-9 for its rounding.
    """
    r, o = float(RATE.lo), float(OFFSET.lo)
    tau = float(np.max(meas.tau.hi))
    return (-o + math.sqrt(o * o + 2 * r * tau)) / r + 1e-9


def t_final(meas: ClockMeasurements, step: float = 0.5) -> float:
    """End of the time domain: the first multiple of ``step`` above every possible reference
    time (12.44 for Table 2 with ``step = 0.01``)."""
    return max(step, math.ceil(_latest_reference_time(meas) / step) * step)


def simulate(seed: int | None = 0, n: int = 8, period: float = 1.5, z_width: float = 4.0
             ) -> tuple[ClockTruth, NDArray[np.float64], ClockMeasurements]:
    """A random drift and boat inside the model, and ``n`` measurements generated from them.

    ``h(t) = a t^2 + b t`` with ``2a in [0.082, 0.118]``, ``b in [0.975, 1.075]`` (inside eq. 17);
    the boat offset stays in ``[71, 89] x [11, 29]`` with a rate below 0.09 (inside eqs. 18-19).
    Reference times ``t_i = period i + U(-0.2, 0.2)``, clock times ``tau_i = h(t_i)`` (as floats:
    the exact reference time of ``tau_i`` differs from ``t_i`` by rounding only) and distance
    intervals of width ``z_width`` placed at random around ``y(t_i)`` (never closer than 0.5 %
    of the width to a bound). Returns the truth, the ``t_i`` and the measurements.
    """
    rng = np.random.default_rng(seed)
    h = (rng.uniform(0.041, 0.059), rng.uniform(0.975, 1.075))
    offset = []
    for m_lo, m_hi in ((71.0, 89.0), (11.0, 29.0)):
        amp = rng.uniform(0.0, 1.0)
        omega = rng.uniform(0.01, 0.09) / max(amp, 1e-3)
        mid = rng.uniform(m_lo + amp, m_hi - amp)
        offset.append((mid, amp, omega, rng.uniform(0, 2 * math.pi)))
    truth = ClockTruth(h, tuple(offset))
    t = period * np.arange(1, n + 1) + rng.uniform(-0.2, 0.2, n)
    tau = truth.drift(t)
    z_lo = truth.distance(t) - rng.uniform(0.005, 0.995, n) * z_width
    meas = ClockMeasurements(Interval(tau, tau), Interval(z_lo, z_lo + z_width),
                             f"simulate(seed={seed})")
    return truth, t, meas


# -- the constraint network -----------------------------------------------------------------
def _box(*comps: Interval) -> Interval:
    return Interval.trusted(np.stack([c.lo for c in comps], axis=-1),
                         np.stack([c.hi for c in comps], axis=-1))


def ephemeris(t: NDArray[np.float64]) -> tuple[Tube, Tube]:
    """The tubes ``[x](.)``, ``[v](.)`` of equations 18 and 19 on gate times ``t``."""
    def pos(s: Interval) -> Interval:
        return _box(X_OFFSET[0] + 100 * iv.cos(s), X_OFFSET[1] + 100 * iv.sin(s))

    def vel(s: Interval) -> Interval:
        return _box(V_ERROR - 100 * iv.sin(s), V_ERROR + 100 * iv.cos(s))
    return Tube.from_function_on(t, pos), Tube.from_function_on(t, vel)


def rate_tube(t: NDArray[np.float64]) -> Tube:
    """``[phi](.)``: the bounds of equation 17 on ``h'``."""
    return Tube.from_function_on(t, lambda s: RATE * s + OFFSET)


@dataclass
class ClockResult:
    """The contracted domains of CN (20): the drift ``h``, the distance ``y``, the reference
    times ``t_i`` (``t_initial``: ``[h]^{-1}(tau_i)`` before any distance was used), the
    measured distances ``z``."""

    meas: ClockMeasurements
    h: Tube
    y: Tube
    t: Interval
    t_initial: Interval
    z: Interval
    iterations: int
    converged: bool
    empty: bool
    time_s: float
    build_s: float
    contraction: list[float]
    time_deriv: bool = True

    @property
    def consistent(self) -> bool:
        return not self.empty

    def __repr__(self) -> str:
        """Counts and summary numbers, not the tubes (the fields hold them)."""
        with np.errstate(invalid="ignore"):
            width = float(np.nanmean(self.t.width())) if len(self.meas) else float("nan")
        return (f"ClockResult(measurements={len(self.meas)}, slices={self.h.n_slices}, "
                f"consistent={self.consistent}, converged={self.converged}, "
                f"iterations={self.iterations}, time_s={self.time_s:.3g}, "
                f"mean_t_i_width={width:.3g})")

    def to_json(self) -> dict:
        """The fields of ``boundest run drifting-clock --json``."""
        def fl(a: ArrayLike) -> list:
            return np.asarray(a, dtype=float).tolist()
        return {
            "scenario": "drifting clock (Rohou et al. 2018, section 5)",
            "source": self.meas.source,
            "consistent": self.consistent,
            "iterations": self.iterations,
            "converged": self.converged,
            "time_s": self.time_s,
            "build_s": self.build_s,
            "n_slices": self.h.n_slices,
            "ctc_eval": "time-deriv" if self.time_deriv else "plain",
            "contraction": fl(self.contraction),
            "t": fl(self.h.t),
            "h_lo": fl(self.h.gates.lo), "h_hi": fl(self.h.gates.hi),
            "y_lo": fl(self.y.gates.lo), "y_hi": fl(self.y.gates.hi),
            "tau": fl((self.meas.tau.lo + self.meas.tau.hi) / 2),
            "t_i_lo": fl(self.t.lo), "t_i_hi": fl(self.t.hi),
            "t_i_lo_initial": fl(self.t_initial.lo), "t_i_hi_initial": fl(self.t_initial.hi),
            "z_lo": fl(self.z.lo), "z_hi": fl(self.z.hi),
            "z_lo_data": fl(self.meas.z.lo), "z_hi_data": fl(self.meas.z.hi),
            "max_h_width": float(np.max(self.h.gates.width())),
            "mean_t_i_width": float(np.mean(self.t.width())),
        }


def _item(a: Interval, i: int) -> Interval:
    """Element ``i`` of a 1-D interval array as a 0-d view (contracting it writes into ``a``)."""
    return Interval.trusted(a.lo[i, ...], a.hi[i, ...])


def solve(meas: ClockMeasurements | None = None, dt: float = 0.01, tf: float | None = None,
          rel_eps: float = 1e-4, max_iter: int = 100, progress: bool | None = None,
          time_deriv: bool = True) -> ClockResult:
    """Contract CN (20) over ``[0, tf]`` (default :func:`t_final`) sliced every ``dt``.

    Each iteration applies ``x' = v``, the distance functions, ``y' = w``, ``h' = phi``, then for
    every measurement ``tau_i = h(t_i)``, ``z_i = y(t_i)`` and ``tau_i = h(t_i)`` again (CtcEval
    each). It stops as :meth:`ContractorNetwork.contract` does (relative decrease of the total
    width below ``rel_eps``), or when a domain becomes empty. ``progress``: the network's
    iteration counter with the last contraction (``None``: only for runs longer than 2 s).
    ``time_deriv``: :class:`CtcEval` contracts the ``[t_i]`` with the derivative inside the
    slices (default: the ``[t_i]`` then lie inside slices, no wider than Codac's at equal
    ``dt``; ``benchmarks/bench_seed001.py``); ``False``: the plain tube inverse, whole slices
    (the ``[t_i]`` end on gate times; about as fast).
    """
    meas = load() if meas is None else meas
    if not (np.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be a positive number, got {dt!r}")
    latest = _latest_reference_time(meas)
    tf = t_final(meas, step=dt) if tf is None else float(tf)
    if not tf >= latest:
        raise ValueError(f"tf = {tf!r} is too short: tau up to {float(np.max(meas.tau.hi))!r} "
                         f"allows reference times up to {latest:.6f}")
    start = time.perf_counter()
    t = time_grid(0.0, tf, dt)
    x, v = ephemeris(t)
    phi = rate_tube(t)
    n = t.size - 1
    h = Tube(t, Interval.entire(n))
    h.gates[0] = Interval(0.0)
    y = Tube(t, Interval.trusted(np.full(n, DEPTH), np.full(n, np.inf)))
    w = Tube(t, Interval.entire(n))
    x1, x2, v1, v2, yv, wv = (Var(s) for s in ("x1", "x2", "v1", "v2", "y", "w"))
    distance = CtcSlices([yv == ef.sqrt(ef.sqr(x1) + ef.sqr(x2) + DEPTH**2),
                          wv == (x1 * v1 + x2 * v2) / yv], ["x1", "x2", "v1", "v2", "y", "w"])
    t_i = Interval.trusted(np.zeros(len(meas)), np.full(len(meas), tf))
    z = meas.z.copy()
    deriv, ev = CtcDeriv(), CtcEval(time_deriv)
    deriv.contract(h, phi)
    t_initial = Interval.trusted(*np.array([[float(r.lo), float(r.hi)] for r in
                                         (h.inverse(meas.tau[i], hull=True)
                                          for i in range(len(meas)))]).T)
    cn = ContractorNetwork()
    cn.add(deriv, [x, v])
    cn.add(distance, [x, v, y, w])
    cn.add(deriv, [y, w])
    cn.add(deriv, [h, phi])
    for i in range(len(meas)):
        ti, taui = _item(t_i, i), meas.tau[i].copy()
        cn.add(ev, [ti, taui, h, phi])
        cn.add(ev, [ti, _item(z, i), y, w])
        cn.add(ev, [ti, taui, h, phi])
    build_s = time.perf_counter() - start
    rep = cn.contract(rel_eps=rel_eps, max_iter=max_iter, progress=progress)
    return ClockResult(meas, h, y, t_i, t_initial, z, rep.iterations, rep.converged, rep.empty,
                       rep.time_s, build_s, list(rep.contraction), time_deriv)
