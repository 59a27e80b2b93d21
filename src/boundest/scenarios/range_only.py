"""The range-only robot of Rohou et al. 2018 (section 4, equations 13-15, Table 1).

State ``x = (x1, x2, x3, x4)``: position, heading ``psi`` and speed ``theta``::

    x1' = x4 cos(x3),  x2' = x4 sin(x3),  x3' = u1,  x4' = u2                      (13)
    u(t) in (-9/20 cos(t/5), 1/10 + sin(t/4)) + 1e-3 [-1, 1]^2                        (14)

over ``t in [0, 64]``, with ``x3(0) in pi/2 + [-0.01, 0.01]``, ``x4(0) in [-0.01, 0.01]`` and
the position unknown. Range measurements ``z_i = |x12(t_i) - b_k|`` to three beacons, with
``t_i in [t_i]`` and ``z_i in [z_i]`` (Table 1). The constraint network (CN 15)::

    v = f(x, u),  x' = v,
    y_k = |x12 - b_k|,  w_k = x4 cos(x3 - atan2(x2 - b_k2, x1 - b_k1)),  y_k' = w_k,
    w_k y_k = (x12 - b_k).v12,
    z_i = y_k(t_i)                                          (CtcEval, uncertain t_i)

``w_k`` is the derivative of the distance, ``(x12 - b_k).v12 / y_k`` of the paper. It is
constrained in two forms that are equal wherever ``x12 != b_k``: with the bearing of the robot
from the beacon, which gives ``|w_k| <= |x4|`` even while the position is still unbounded (the
paper's quotient gives nothing then, and no measurement could ever be used), and as the product
``w_k y_k = (x12 - b_k).v12``, the tighter of the two once the position box is small (the
bearing of a box seen from the beacon is wide; the dot product uses ``v12`` directly). Together
they bring the mean position-box diagonal at ``dt = 0.01`` from 10.48 m (the bearing form
alone, which is also what Codac 1.5.7 gets with it) to 10.18 m. The truth used by the paper
starts at ``x(0) = (0, 0, pi/2, 0)`` with the centre of equation 14 as input.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import interval as iv
from .._progress import Progress
from ..expr import Var
from ..expr import functions as ef
from ..interval import Interval
from ..tube import ContractorNetwork, CtcDeriv, CtcEval, CtcSlices, Tube, time_grid
from ._data import check_index, check_sorted, embedded, outward, read_csv

__all__ = [
    "RATE_FORMS",
    "T0",
    "TF",
    "U_BOUND",
    "X0_TRUE",
    "Measurements",
    "RangeOnlyResult",
    "RobotTruth",
    "input_tube",
    "load",
    "simulate",
    "solve",
]

T0, TF = 0.0, 64.0
#: Bound on the input error in equation 14.
U_BOUND = 1e-3
#: Initial state of the paper's simulation (only x3(0) and x4(0) are known to the solver).
X0_TRUE = (0.0, 0.0, math.pi / 2, 0.0)
#: Half-widths of the known initial heading and speed: x3(0) in pi/2 +- 0.01, x4(0) in +- 0.01.
X3_0_RAD, X4_0_RAD = 0.01, 0.01


@dataclass
class Measurements:
    """Range measurements ``z_i = |x12(t_i) - b_{beacon[i]}|`` with ``t_i in [t_i]``,
    ``z_i in [z_i]``; beacon positions ``beacons`` (shape ``(K, 2)``, intervals enclosing the
    decimal data)."""

    t: Interval
    z: Interval
    beacon: NDArray[np.intp]
    beacons: Interval
    beacon_names: list[str] = field(default_factory=list)
    source: str = "<memory>"

    def __post_init__(self) -> None:
        m = self.t.shape
        if self.t.ndim != 1 or self.z.shape != m or self.beacon.shape != m:
            raise ValueError(f"t, z and beacon must be 1-D of one length, got {self.t.shape}, "
                             f"{self.z.shape}, {self.beacon.shape}")
        if self.beacons.ndim != 2 or self.beacons.shape[1] != 2:
            raise ValueError(f"beacons must have shape (K, 2), got {self.beacons.shape}")
        bad = (self.beacon < 0) | (self.beacon >= self.beacons.shape[0])
        if bad.any():
            raise ValueError(f"measurement {int(np.argmax(bad))} refers to beacon "
                             f"{int(self.beacon[bad][0])}; there are {self.beacons.shape[0]}")

    def __len__(self) -> int:
        return self.t.shape[0]


def load(path: str | Path | None = None, beacons: str | Path | None = None,
         domain: tuple[float, float] = (T0, TF)) -> Measurements:
    """Read Table 1 (default: the embedded ``rohou2018_robot.csv`` and
    ``rohou2018_beacons.csv``).

    The measurement file has columns ``i, beacon, t_lo, t_hi, z_lo, z_hi`` (no others), rows
    ``i = 1, 2, ...`` in order and sorted by ``t_lo``; the beacon file ``beacon, bx, by``.
    Times and beacon positions must be finite; ``z_lo`` may be ``-inf`` and ``z_hi`` ``inf``
    (a range bounded on one side only). Every value is taken as a decimal number and enclosed
    one ulp outward. Errors (one ``DataError`` naming file, line and value): missing or
    unexpected columns, non-numbers, ``lo > hi``, an unknown or duplicated beacon name, a
    repeated or unsorted row, a time interval outside ``domain``, a negative distance bound
    ``z_hi < 0``.
    """
    path = Path(embedded("rohou2018_robot.csv") if path is None else path)
    bpath = Path(embedded("rohou2018_beacons.csv") if beacons is None else beacons)
    bcols = read_csv(bpath, {"beacon": "text", "bx": "finite", "by": "finite"})
    names: dict[str, int] = {}
    for j, name in enumerate(bcols["beacon"]):
        if not name:
            raise bcols.error(j, "empty beacon name")
        if name in names:
            raise bcols.error(j, f"beacon {name!r} defined twice")
        names[name] = len(names)
    cols = read_csv(path, {"i": "finite", "beacon": "text", "t_lo": "finite", "t_hi": "finite",
                           "z_lo": "lo", "z_hi": "hi"})
    beacon = np.empty(len(cols), dtype=np.intp)
    for k, name in enumerate(cols["beacon"]):
        if name not in names:
            raise cols.error(k, f"unknown beacon {name!r} (known: {', '.join(names)} in "
                                f"{bpath})")
        beacon[k] = names[name]
    for k in range(len(cols)):
        a, b = float(cols["t_lo"][k]), float(cols["t_hi"][k])
        if a < domain[0] or b > domain[1]:
            raise cols.error(k, f"time interval [{a!r}, {b!r}] is outside the mission "
                                f"[{domain[0]!r}, {domain[1]!r}]")
        if cols["z_hi"][k] < 0:
            raise cols.error(k, f"z_hi = {float(cols['z_hi'][k])!r} is negative (a distance)")
    check_index(cols, "i", 1)
    check_sorted(cols, "t_lo", strict=False)
    tl, th = cols["t_lo"], cols["t_hi"]
    twice = np.flatnonzero((tl[1:] == tl[:-1]) & (th[1:] == th[:-1]) & (beacon[1:] == beacon[:-1]))
    if twice.size:
        j = int(twice[0]) + 1
        raise cols.error(j, f"beacon {cols['beacon'][j]!r} at t in [{float(tl[j])!r}, "
                            f"{float(th[j])!r}] repeats line {int(cols.lines[j - 1])} (the same "
                            "measurement twice)")
    t = outward(cols["t_lo"], cols["t_hi"])
    t = Interval.trusted(np.maximum(t.lo, domain[0]), np.minimum(t.hi, domain[1]))
    z = outward(cols["z_lo"], cols["z_hi"])
    bxy = np.stack([bcols["bx"], bcols["by"]], axis=1)
    return Measurements(t, z, beacon, outward(bxy, bxy), list(names),
                        str(path))


# -- the truth ------------------------------------------------------------------------------
_GL_X, _GL_W = np.polynomial.legendre.leggauss(10)


@dataclass(frozen=True)
class RobotTruth:
    """One trajectory of equation 13: initial state ``x0`` and input
    ``u_j(t) = centre_j(t) + a_j sin(omega_j t + phase_j)`` (``du`` rows ``(a, omega, phase)``;
    zero amplitudes for the paper's truth).

    ``x3`` and ``x4`` are closed-form integrals of ``u``; ``x1``, ``x2`` are integrated by
    10-point Gauss-Legendre quadrature on sub-intervals of at most ``0.05`` s (error far below
    1e-10 m for these smooth integrands).
    """

    x0: tuple[float, float, float, float] = X0_TRUE
    du: tuple[tuple[float, float, float], ...] = ((0.0, 1.0, 0.0), (0.0, 1.0, 0.0))

    def inputs(self, t: ArrayLike) -> NDArray[np.float64]:
        """``u(t)``, shape ``(m, 2)``."""
        t = np.asarray(t, dtype=np.float64)
        (a1, w1, p1), (a2, w2, p2) = self.du
        return np.stack([-0.45 * np.cos(t / 5) + a1 * np.sin(w1 * t + p1),
                         0.1 + np.sin(t / 4) + a2 * np.sin(w2 * t + p2)], axis=-1)

    def _heading_speed(self, t: NDArray) -> tuple[NDArray, NDArray]:
        (a1, w1, p1), (a2, w2, p2) = self.du
        x3 = self.x0[2] - 2.25 * np.sin(t / 5) + a1 / w1 * (np.cos(p1) - np.cos(w1 * t + p1))
        x4 = (self.x0[3] + 0.1 * t + 4.0 * (1.0 - np.cos(t / 4))
              + a2 / w2 * (np.cos(p2) - np.cos(w2 * t + p2)))
        return x3, x4

    def states(self, t: ArrayLike) -> NDArray[np.float64]:
        """``x(t)`` at times ``t >= 0`` (any order), shape ``(m, 4)``."""
        t = np.asarray(t, dtype=np.float64).ravel()
        if t.size and (t.min() < 0 or not np.all(np.isfinite(t))):
            raise ValueError("truth times must be finite and >= 0")
        grid = np.union1d(np.arange(0.0, t.max(initial=0.0), 0.05), t)
        grid = np.union1d(grid, [0.0])
        a, b = grid[:-1, None], grid[1:, None]
        s = (a + b) / 2 + (b - a) / 2 * _GL_X                      # (m-1, 10) nodes
        x3, x4 = self._heading_speed(s)
        wts = (b - a)[:, 0:1] / 2 * _GL_W
        p1 = np.concatenate([[0.0], np.cumsum(np.sum(wts * x4 * np.cos(x3), axis=1))])
        p2 = np.concatenate([[0.0], np.cumsum(np.sum(wts * x4 * np.sin(x3), axis=1))])
        k = np.searchsorted(grid, t)
        h3, h4 = self._heading_speed(t)
        return np.stack([self.x0[0] + p1[k], self.x0[1] + p2[k], h3, h4], axis=1)

    def velocities(self, t: ArrayLike) -> NDArray[np.float64]:
        """``x'(t) = f(x(t), u(t))``, shape ``(m, 4)``."""
        t = np.asarray(t, dtype=np.float64).ravel()
        x3, x4 = self._heading_speed(t)
        return np.column_stack([x4 * np.cos(x3), x4 * np.sin(x3), self.inputs(t)])


def simulate(seed: int | None = 0, meas: Measurements | None = None,
             t_width: float = 0.8, z_width: float = 1.0
             ) -> tuple[RobotTruth, NDArray[np.float64], Measurements]:
    """A random truth and measurements generated from it.

    The truth starts at a random position in ``[-2, 2]^2`` with a heading and speed inside the
    known initial intervals (0.9 of their half-widths) and follows an input that deviates from
    the centre of equation 14 by a sinusoid of amplitude below ``0.9 U_BOUND``. One measurement
    per row of ``meas`` (default: Table 1), to the same beacon: a true time near the centre of
    the row's interval, the exact range at that time, and intervals of widths ``t_width``,
    ``z_width`` placed at random around them (never closer than 1 % of the width to a bound).
    Returns the truth, the true times ``t_i`` and the measurements.
    """
    rng = np.random.default_rng(seed)
    meas = load() if meas is None else meas
    x0 = (rng.uniform(-2, 2), rng.uniform(-2, 2),
          math.pi / 2 + rng.uniform(-0.9, 0.9) * X3_0_RAD, rng.uniform(-0.9, 0.9) * X4_0_RAD)
    du = tuple((rng.uniform(0, 0.9) * U_BOUND, rng.uniform(0.05, 2.0), rng.uniform(0, 2 * np.pi))
               for _ in range(2))
    truth = RobotTruth(x0, du)
    m = len(meas)
    centre = (meas.t.lo + meas.t.hi) / 2
    t_true = np.clip(centre + rng.uniform(-0.3, 0.3, m), T0, TF)
    b = (meas.beacons.lo + meas.beacons.hi)[meas.beacon] / 2
    z_true = np.hypot(*(truth.states(t_true)[:, :2] - b).T)
    t_lo = np.clip(t_true - rng.uniform(0.01, 0.99, m) * t_width, T0, TF)
    t_hi = np.clip(t_lo + t_width, T0, TF)
    z_lo = z_true - rng.uniform(0.01, 0.99, m) * z_width
    sim = Measurements(Interval(t_lo, t_hi), Interval(z_lo, z_lo + z_width),
                       meas.beacon.copy(), meas.beacons.copy(), list(meas.beacon_names),
                       f"simulate(seed={seed})")
    return truth, t_true, sim


# -- the constraint network -----------------------------------------------------------------
def input_tube(t: NDArray[np.float64]) -> Tube:
    """``[u](.)`` of equation 14 on gate times ``t``: the centre evaluated in interval arithmetic
    over each slice and gate, inflated by ``U_BOUND``."""
    def f(s: Interval) -> Interval:
        e = Interval(-U_BOUND, U_BOUND)
        u1 = -(Interval(9.0) / 20) * iv.cos(s / 5) + e
        u2 = Interval(1.0) / 10 + iv.sin(s / 4) + e
        return Interval.trusted(np.stack([u1.lo, u2.lo], axis=-1),
                                np.stack([u1.hi, u2.hi], axis=-1))
    return Tube.from_function_on(t, f)


def initial_heading_speed() -> tuple[Interval, Interval]:
    """``x3(0) in pi/2 + [-0.01, 0.01]`` and ``x4(0) in [-0.01, 0.01]``, enclosed outward
    (``math.pi`` lies below pi, its successor above; the float 0.01 exceeds 1/100)."""
    pi = Interval(math.pi, np.nextafter(math.pi, np.inf))
    return pi / 2 + Interval(-X3_0_RAD, X3_0_RAD), Interval(-X4_0_RAD, X4_0_RAD)


@dataclass
class RangeOnlyResult:
    """The contracted domains of CN (15) and how the propagation went.

    ``x``, ``v``: 4-D tubes of the state and its derivative; ``y``, ``w``: K-D tubes of the
    distances to the beacons and their derivatives; ``t``, ``z``: the contracted measurement
    intervals; ``diag[k]``: the position-box diagonal ``d`` (Rohou et al. 2018 Fig. 8) at the gate
    times
    ``diag_t`` after iteration ``k``.
    """

    meas: Measurements
    x: Tube
    v: Tube
    y: Tube
    w: Tube
    t: Interval
    z: Interval
    iterations: int
    converged: bool
    empty: bool
    time_s: float
    build_s: float
    contraction: list[float]
    diag_t: NDArray[np.float64]
    diag: list[NDArray[np.float64]]
    time_deriv: bool = False
    rate: str = "both"

    @property
    def consistent(self) -> bool:
        return not self.empty

    def __repr__(self) -> str:
        """Counts and summary numbers, not the tubes (the fields hold them)."""
        d = self.position_diagonal()
        mean = f"{float(np.mean(d)):.3g}" if d.size and not self.empty else "nan"
        return (f"RangeOnlyResult(measurements={len(self.meas)}, slices={self.x.n_slices}, "
                f"consistent={self.consistent}, converged={self.converged}, "
                f"iterations={self.iterations}, time_s={self.time_s:.3g}, "
                f"mean_diagonal={mean})")

    def position_diagonal(self) -> NDArray[np.float64]:
        """``d`` at every gate: the diagonal of the position box ``[x1] x [x2]``."""
        return np.hypot(self.x.gates.width()[:, 0], self.x.gates.width()[:, 1])

    def to_json(self) -> dict:
        """The fields of ``boundest run range-only --json``."""
        def fl(a: ArrayLike) -> list:
            return np.asarray(a, dtype=float).tolist()
        d = self.position_diagonal()
        return {
            "scenario": "range-only robot (Rohou et al. 2018, section 4)",
            "source": self.meas.source,
            "consistent": self.consistent,
            "iterations": self.iterations,
            "converged": self.converged,
            "time_s": self.time_s,
            "build_s": self.build_s,
            "n_slices": self.x.n_slices,
            "ctc_eval": "time-deriv" if self.time_deriv else "plain",
            "rate_forms": self.rate,
            "contraction": fl(self.contraction),
            "t": fl(self.x.t),
            "x_lo": fl(self.x.gates.lo),
            "x_hi": fl(self.x.gates.hi),
            "beacon": [self.meas.beacon_names[k] if self.meas.beacon_names else int(k)
                       for k in self.meas.beacon],
            "t_lo": fl(self.t.lo), "t_hi": fl(self.t.hi),
            "z_lo": fl(self.z.lo), "z_hi": fl(self.z.hi),
            "t_lo_data": fl(self.meas.t.lo), "t_hi_data": fl(self.meas.t.hi),
            "mean_diagonal": float(np.mean(d)) if d.size else None,
            "max_diagonal": float(np.max(d)) if d.size else None,
            "diag_t": fl(self.diag_t),
            "diag": [fl(r) for r in self.diag],
        }


def _item(a: Interval, i: int) -> Interval:
    """Element ``i`` of a 1-D interval array as a 0-d view (contracting it writes into ``a``)."""
    return Interval.trusted(a.lo[i, ...], a.hi[i, ...])


@dataclass
class _Network:
    """The domains of CN (15) and its two sub-networks (see :func:`solve`)."""

    x: Tube
    v: Tube
    y: Tube
    w: Tube
    t: Interval
    z: Interval
    dead_reckoning: ContractorNetwork
    position: ContractorNetwork


#: The forms of the distance rate ``w_k`` that ``solve`` can constrain (see the module docstring).
RATE_FORMS = ("both", "bearing")


def _network(meas: Measurements, t: NDArray[np.float64], time_deriv: bool = False,
             rate: str = "both") -> _Network:
    n_b = meas.beacons.shape[0]
    full = Interval.entire(4)
    x = Tube(t, Interval.trusted(np.broadcast_to(full.lo, (t.size - 1, 4)).copy(),
                              np.broadcast_to(full.hi, (t.size - 1, 4)).copy()))
    x3_0, x4_0 = initial_heading_speed()
    x.gates[0, 2] = x3_0
    x.gates[0, 3] = x4_0
    v = x.copy()
    v.gates[0] = Interval.entire(4)
    u = input_tube(t)
    y = Tube(t, Interval.trusted(np.zeros((t.size - 1, n_b)), np.full((t.size - 1, n_b), np.inf)))
    w = Tube(t, Interval.entire((t.size - 1, n_b)))
    x1, x2, x3, x4 = (Var(f"x{j}") for j in range(1, 5))
    v1, v2, v3, v4, u1, u2, yk, wk = (Var(n) for n in ("v1", "v2", "v3", "v4", "u1", "u2",
                                                        "y", "w"))
    evolution = CtcSlices([v1 == x4 * ef.cos(x3), v2 == x4 * ef.sin(x3), v3 == u1, v4 == u2],
                          ["x3", "x4", "v1", "v2", "v3", "v4", "u1", "u2"])
    distance, rates = [], []
    for k in range(n_b):
        bx, by = meas.beacons[k, 0], meas.beacons[k, 1]
        dx, dy = x1 - bx, x2 - by
        distance.append(CtcSlices([yk == ef.sqrt(ef.sqr(dx) + ef.sqr(dy))], ["x1", "x2", "y"]))
        bearing = wk == x4 * ef.cos(x3 - ef.atan2(dy, dx))
        if rate == "both":
            rates.append((CtcSlices([bearing, wk * yk == dx * v1 + dy * v2],
                                    ["x1", "x2", "x3", "x4", "v1", "v2", "y", "w"]),
                          [x, v[0], v[1], y[k], w[k]]))
        else:
            rates.append((CtcSlices([bearing], ["x1", "x2", "x3", "x4", "w"]), [x, w[k]]))
    t_meas, z_meas = meas.t.copy(), meas.z.copy()
    deriv = CtcDeriv()
    dead = ContractorNetwork()
    dead.add(evolution, [x[2], x[3], v, u])
    dead.add(deriv, [x, v])
    pos = ContractorNetwork()
    pos.add(deriv, [x, v])
    for k in range(n_b):
        pos.add(distance[k], [x[0], x[1], y[k]])
        pos.add(*rates[k])
    pos.add(deriv, [y, w])
    ctc_eval = CtcEval(time_deriv)
    for i in range(len(meas)):
        k = int(meas.beacon[i])
        pos.add(ctc_eval, [_item(t_meas, i), _item(z_meas, i), y[k], w[k]])
    for k in range(n_b):
        pos.add(distance[k], [x[0], x[1], y[k]])
    return _Network(x, v, y, w, t_meas, z_meas, dead, pos)


def solve(meas: Measurements | None = None, dt: float = 0.01, rel_eps: float = 1e-4,
          max_iter: int = 200, progress: bool | None = None, time_deriv: bool = False,
          rate: str = "both") -> RangeOnlyResult:
    """Contract CN (15) to its fixed point over ``[T0, TF]`` sliced every ``dt``.

    The network splits in two. Dead reckoning, ``v = f(x, u)`` and ``x' = v``, determines the
    heading, the speed and ``[v]`` from ``[u]`` and the initial conditions alone; it is run to
    its fixed point first and not again: the position network can still narrow ``[v12]``
    (through ``w_k y_k = (x12 - b_k).v12``), but the heading and speed are not recomputed from
    it (sound; the whole network's fixed point could be a little tighter). The position
    network is then iterated, in order: ``x' = v``,
    the distance ``y_k`` and its rate ``w_k`` (both forms) for every beacon, ``y' = w``, one
    ``CtcEval`` per
    measurement, and the distances again (to carry the measurements back to the position). It
    stops when an iteration decreases the total width of its domains by less than ``rel_eps``
    (relative) while bounding no new bound, after ``max_iter`` iterations, or when a domain
    becomes empty (the data contradict the model). ``iterations`` counts the position
    network's iterations (Rohou et al. 2018's Fig. 8 steps).

    ``time_deriv``: contract the measurement times with the derivative in :class:`CtcEval`
    (``False``, the default: the plain tube inverse; on Table 1 at ``dt = 0.01`` both give the
    same tubes and the same ``[t_i]``, at the same cost, so the simpler one is kept).

    ``rate``: ``"both"`` (default) constrains the distance rate ``w_k`` with the bearing form
    and the product form ``w_k y_k = (x12 - b_k).v12``; ``"bearing"`` with the bearing form
    only, the network of Rohou et al. 2018 and of the Codac comparison (cheaper, wider: on
    Table 1 at ``dt = 0.01``, mean diagonal 10.48 m against 10.18 m).
    """
    meas = load() if meas is None else meas
    if not (np.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be a positive number, got {dt!r}")
    if rate not in RATE_FORMS:
        raise ValueError(f"rate must be one of {', '.join(RATE_FORMS)}, got {rate!r}")
    start = time.perf_counter()
    t = time_grid(T0, TF, dt)
    net = _network(meas, t, time_deriv, rate)
    build_s = time.perf_counter() - start
    step = max(1, round(0.1 / dt))
    diag_t = t[::step]
    diag, contraction = [], []
    converged = empty = False
    iterations = 0
    start = time.perf_counter()
    rep = net.dead_reckoning.contract(rel_eps=rel_eps, max_iter=max_iter, progress=False)
    empty = rep.empty
    # a counter, not a total: the fixed point comes long before the cap (max_iter)
    with Progress(False if empty else progress, desc="range-only") as bar:
        while iterations < max_iter and not empty:
            rep = net.position.contract(rel_eps=rel_eps, max_iter=1, progress=False)
            iterations += 1
            bar.update(1)
            contraction.append(rep.contraction[-1])
            if rep.empty:
                empty = True
                bar.stop("empty: the measurements are inconsistent")
                break
            g = net.x.gates.width()[::step]
            diag.append(np.hypot(g[:, 0], g[:, 1]))
            bar.set_postfix(contraction=f"{contraction[-1]:.2e}", stop_below=f"{rel_eps:.0e}")
            if rep.converged:
                converged = True
                bar.stop("converged")
                break
        else:
            bar.stop(f"max_iter={max_iter} reached")
    spent = time.perf_counter() - start
    return RangeOnlyResult(meas, net.x, net.v, net.y, net.w, net.t, net.z, iterations,
                           converged, empty, spent, build_s, contraction, diag_t, diag,
                           time_deriv, rate)
