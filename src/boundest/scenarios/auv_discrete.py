"""The AUV survey as one discrete CSP propagated by ``boundest.csp.propagate``.

The same problem as :mod:`boundest.scenarios.auv`, written as constraints between variables:
``p[k+1] = p[k] + dt R(phi[k], theta[k], psi[k]) v[k]`` for every ``k`` (the natural form of
``R v``), the sensor boxes as domains, ``p_z >= 0``, the fixes, and the constraints of every
detection (:func:`boundest.scenarios.auv.detection_constraints`). For the embedded survey:
600,048 variables. One time step and one detection are compiled as template tapes and laid out
over all samples and detections with :func:`boundest.expr.tape.instantiate`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..csp import propagate
from ..csp.propagate import Propagation
from ..expr import Var
from ..expr.functions import cos, sin
from ..expr.tape import Tape, compile_model, instantiate
from ..interval import Interval
from .auv import DETECTION_VARS, detection_constraints
from .auv_data import AuvData

__all__ = ["DiscreteAuv", "discrete_tape", "solve_discrete"]

_STEP_VARS = ("px0", "py0", "pz0", "px1", "py1", "pz1", "phi", "theta", "psi", "vx", "vy", "vz")


def _step_template(dt: Interval) -> Tape:
    px0, py0, pz0, px1, py1, pz1, phi, theta, psi, vx, vy, vz = (Var(n) for n in _STEP_VARS)
    cf, sf, ct, st, cp, sp = cos(phi), sin(phi), cos(theta), sin(theta), cos(psi), sin(psi)
    s = sf * vy + cf * vz
    ux = ct * vx + st * s
    uy = cf * vy - sf * vz
    uz = ct * s - st * vx
    return compile_model([px1 == px0 + dt * (cp * ux - sp * uy),
                          py1 == py0 + dt * (sp * ux + cp * uy),
                          pz1 == pz0 + dt * uz])


@dataclass
class _Layout:
    """Global variable numbers of the discrete CSP."""

    n: int
    n_mines: int
    n_det: int

    def p(self, k: NDArray, i: int) -> NDArray:
        return 3 * k + i

    def att(self, k: NDArray, i: int) -> NDArray:
        return 3 * self.n + 3 * k + i

    def vel(self, k: NDArray, i: int) -> NDArray:
        return 6 * self.n + 3 * k + i

    def alt(self, k: NDArray) -> NDArray:
        return 9 * self.n + k

    def mine(self, j: NDArray, i: int) -> NDArray:
        return 10 * self.n + 3 * j + i

    def r(self, d: NDArray) -> NDArray:
        return 10 * self.n + 3 * self.n_mines + d

    def alpha(self, d: NDArray) -> NDArray:
        return 10 * self.n + 3 * self.n_mines + self.n_det + d

    @property
    def size(self) -> int:
        return 10 * self.n + 3 * self.n_mines + 2 * self.n_det


def discrete_tape(data: AuvData, slam: bool = True) -> Tape:
    """The tape of the discrete CSP (with the detections and mines when ``slam``)."""
    n, nd = data.n, data.det_k.size if slam else 0
    lay = _Layout(n, data.n_mines, nd)
    lo, hi = np.full(lay.size, -np.inf), np.full(lay.size, np.inf)
    k = np.arange(n)
    for i in range(3):
        lo[lay.att(k, i)], hi[lay.att(k, i)] = data.attitude.lo[:, i], data.attitude.hi[:, i]
        lo[lay.vel(k, i)], hi[lay.vel(k, i)] = data.velocity.lo[:, i], data.velocity.hi[:, i]
    lo[lay.alt(k)], hi[lay.alt(k)] = data.altitude.lo, data.altitude.hi
    lo[lay.p(k, 2)] = np.maximum(0.0, data.depth.lo)  # the vehicle never leaves the water
    hi[lay.p(k, 2)] = data.depth.hi
    for i in range(3):
        g = lay.p(data.fix_k, i)
        lo[g] = np.maximum(lo[g], data.fix.lo[:, i])
        hi[g] = np.minimum(hi[g], data.fix.hi[:, i])
    d = np.arange(nd)
    lo[lay.r(d)], hi[lay.r(d)] = data.det_range.lo[:nd], data.det_range.hi[:nd]
    names = ([f"p{c}[{j}]" for j in range(n) for c in "xyz"]
             + [f"{q}[{j}]" for j in range(n) for q in ("phi", "theta", "psi")]
             + [f"v{c}[{j}]" for j in range(n) for c in "xyz"]
             + [f"a[{j}]" for j in range(n)]
             + [f"m{c}[{j}]" for j in range(data.n_mines) for c in "xyz"]
             + [f"r[{j}]" for j in range(nd)] + [f"alpha[{j}]" for j in range(nd)])
    dt = Interval(np.nextafter(data.dt, -np.inf), np.nextafter(data.dt, np.inf))
    ks = np.arange(n - 1)
    step = {**{f"p{c}0": lay.p(ks, i) for i, c in enumerate("xyz")},
            **{f"p{c}1": lay.p(ks + 1, i) for i, c in enumerate("xyz")},
            **{q: lay.att(ks, i) for i, q in enumerate(("phi", "theta", "psi"))},
            **{f"v{c}": lay.vel(ks, i) for i, c in enumerate("xyz")}}
    pieces = [(_step_template(dt), step)]
    if slam:
        dk, dm = data.det_k, data.det_mine
        det = {"px": lay.p(dk, 0), "py": lay.p(dk, 1), "pz": lay.p(dk, 2),
               "phi": lay.att(dk, 0), "theta": lay.att(dk, 1), "psi": lay.att(dk, 2),
               "a": lay.alt(dk), "mx": lay.mine(dm, 0), "my": lay.mine(dm, 1),
               "mz": lay.mine(dm, 2), "r": lay.r(d), "alpha": lay.alpha(d)}
        assert set(det) == set(DETECTION_VARS)
        pieces.append((compile_model(detection_constraints(data.seabed_tol)), det))
    return instantiate(names, lo, hi, pieces)


@dataclass(repr=False)
class DiscreteAuv:
    """The result of :func:`solve_discrete`: position and mine boxes, the propagation."""

    positions: Interval
    mines: Interval
    propagation: Propagation
    build_s: float

    @property
    def consistent(self) -> bool:
        return self.propagation.consistent

    def __repr__(self) -> str:
        p = self.propagation
        return (f"DiscreteAuv(samples={self.positions.shape[0]}, consistent={p.consistent}, "
                f"variables={len(p.domains)}, n_nodes={p.n_nodes}, build_s={self.build_s:.3g},"
                f" time_s={p.time_s:.3g})")


def solve_discrete(data: AuvData, slam: bool = True, rel_eps: float = 1e-6,
                   progress: bool | None = None) -> DiscreteAuv:
    """Build the discrete CSP and propagate it to a fixed point (``rel_eps``: see
    :func:`boundest.csp.propagate`)."""
    start = time.perf_counter()
    tape = discrete_tape(data, slam)
    build_s = time.perf_counter() - start
    res = propagate(tape, rel_eps=rel_eps, progress=progress, mode="hc4")
    n = data.n
    s = res.slots
    pos = Interval.trusted(s.lo[: 3 * n].reshape(n, 3), s.hi[: 3 * n].reshape(n, 3))
    m0 = 10 * n
    mines = Interval.trusted(s.lo[m0: m0 + 3 * data.n_mines].reshape(-1, 3),
                          s.hi[m0: m0 + 3 * data.n_mines].reshape(-1, 3))
    if not slam:
        mines = Interval.entire((data.n_mines, 3))
    return DiscreteAuv(pos, mines, res, build_s)
