"""Localization and SLAM of an AUV on a side-scan mine survey (Jaulin, Bertholom, Dabe 2007).

The position is a tube ``p(.)`` whose derivative is the world velocity ``R(phi, theta, psi) v``
of the attitude and body-velocity boxes, held over each sample (a tube with jumps). Time runs
in samples: gate ``k`` is sample ``k`` and the derivative per unit of this time is
``dt R v`` (``dt`` enclosed as the decimal it is), so the durations of the tube are exact.

- **Localization**: dead reckoning by ``CtcDeriv`` forward and backward from both GPS fixes,
  the depth boxes on every gate and ``p_z >= 0``.
- **SLAM**: the mines are unknown boxes; the three constraints of each side-scan detection
  (abeam on the starboard side below the vehicle, slant range, mine on the seabed) link the
  position, attitude and altitude at the detection sample to its mine. The detections and
  ``CtcDeriv`` form one ``ContractorNetwork``, propagated to a fixed point: a mine seen twice
  ties the two parts of the trajectory together, both ways.

The world velocity is enclosed by two natural interval extensions of ``R v`` (through the
levelled velocity, and with ``R`` multiplied out) intersected with a mean-value (centred) form,
computed over all samples at once.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from .. import interval as iv
from ..csp import propagate
from ..expr import Var
from ..expr.functions import cos, sin
from ..expr.tape import compile_model, instantiate
from ..interval import Interval
from ..tube import ContractorNetwork, CtcDeriv, NetworkReport, Tube
from .auv_data import AuvData

__all__ = ["AuvResult", "CtcDetections", "detection_constraints", "localize", "slam",
           "world_velocity"]


# -- the world velocity R v ------------------------------------------------------------------
def _stack(parts: list[Interval]) -> Interval:
    return Interval.trusted(np.stack([q.lo for q in parts], axis=-1),
                         np.stack([q.hi for q in parts], axis=-1))


def _rv(c: dict[str, Interval], v: tuple[Interval, Interval, Interval]
        ) -> tuple[Interval, ...]:
    """``R v`` through the levelled velocity ``u = R_theta R_phi v``: returns
    ``(wx, wy, wz, ux, uy, s)`` with ``s = sin(phi) vy + cos(phi) vz``."""
    vx, vy, vz = v
    s = c["sf"] * vy + c["cf"] * vz
    ux = c["ct"] * vx + c["st"] * s
    uy = c["cf"] * vy - c["sf"] * vz
    uz = c["ct"] * s - c["st"] * vx
    return c["cp"] * ux - c["sp"] * uy, c["sp"] * ux + c["cp"] * uy, uz, ux, uy, s


def _trig(phi: Interval, theta: Interval, psi: Interval) -> dict[str, Interval]:
    return {"cf": iv.cos(phi), "sf": iv.sin(phi), "ct": iv.cos(theta), "st": iv.sin(theta),
            "cp": iv.cos(psi), "sp": iv.sin(psi)}


def world_velocity(attitude: Interval, velocity: Interval, form: str = "best") -> Interval:
    """Enclosure of ``R(phi, theta, psi) v`` for boxes of shape ``(n, 3)``, shape ``(n, 3)``.

    Parameters
    ----------
    form : {"best", "natural"}
        ``"natural"``: the natural interval extension of ``R v`` written through the levelled
        velocity ``u = R_theta R_phi v`` (``w_x = cos(psi) u_x - sin(psi) u_y``, ...).
        ``"best"``: that, intersected with the natural extension of ``R v`` with ``R``
        multiplied out and with the mean-value form around the box centre (the rotation of a
        box is not a box; the centred form takes the correlation of ``w_x`` and ``w_y``
        through ``psi`` into account). It is never wider than Codac 2.1.2's intersection of
        its natural and centred forms (beyond one ulp; ``benchmarks/bench_auv.py``).
    """
    if form not in ("best", "natural"):
        raise ValueError(f"form must be 'best' or 'natural', got {form!r}")
    n = attitude.shape[0]
    if n > _CHUNK:  # bounded memory: some 70 temporaries per sample
        parts = [_world_velocity(attitude[i:i + _CHUNK], velocity[i:i + _CHUNK], form)
                 for i in range(0, n, _CHUNK)]
        return Interval.trusted(np.concatenate([q.lo for q in parts]),
                             np.concatenate([q.hi for q in parts]))
    return _world_velocity(attitude, velocity, form)


#: Samples per block of ``world_velocity``.
_CHUNK = 8192


def _matrix(c: dict[str, Interval]) -> list[list[Interval]]:
    """The entries of ``R = R_psi R_theta R_phi`` multiplied out."""
    cf, sf, ct, st, cp, sp = (c[k] for k in ("cf", "sf", "ct", "st", "cp", "sp"))
    sts, stc = st * sf, st * cf
    return [[cp * ct, cp * sts - sp * cf, cp * stc + sp * sf],
            [sp * ct, sp * sts + cp * cf, sp * stc - cp * sf],
            [-st, ct * sf, ct * cf]]


def _dot(row: list[Interval], v: tuple[Interval, ...]) -> Interval:
    return row[0] * v[0] + row[1] * v[1] + row[2] * v[2]


def _world_velocity(attitude: Interval, velocity: Interval, form: str) -> Interval:
    phi, theta, psi = (attitude[:, i] for i in range(3))
    v = tuple(velocity[:, i] for i in range(3))
    c = _trig(phi, theta, psi)
    wx, wy, wz, ux, uy, s = _rv(c, v)
    if form == "natural":
        return _stack([wx, wy, wz])
    # two natural extensions with other dependencies: through the levelled velocity, and with
    # R written out entry by entry; each is the tighter one on some samples
    R = _matrix(c)
    w = [a & _dot(row, v) for a, row in zip((wx, wy, wz), R, strict=True)]
    # mean-value form: w(X) ⊆ w(m) + J(X) (X - m), J an interval Jacobian over the box, each
    # entry the intersection of its two forms
    q = (phi, theta, psi, *v)
    mids = [Interval(x.mid()) for x in q]
    cm = _trig(*mids[:3])
    vm = tuple(mids[3:])
    wm = [a & _dot(row, vm) for a, row in zip(_rv(cm, vm)[:3], _matrix(cm), strict=True)]
    dq = [x - m for x, m in zip(q, mids, strict=True)]
    ct, st, cp, sp = c["ct"], c["st"], c["cp"], c["sp"]
    uz = ct * s - st * v[0]
    # d/dphi: levelled (cp st uy + sp s, sp st uy - cp s, ct uy), or R[:, 2] vy - R[:, 1] vz
    # d/dtheta: levelled (cp uz, sp uz, -ux), or (cp, sp, -) times the third row's derivative
    jac = [
        [(cp * (st * uy) + sp * s) & (R[0][2] * v[1] - R[0][1] * v[2]),
         (sp * (st * uy) - cp * s) & (R[1][2] * v[1] - R[1][1] * v[2]),
         (ct * uy) & (R[2][2] * v[1] - R[2][1] * v[2])],
        [cp * (uz & w[2]), sp * (uz & w[2]), -ux],
        [-w[1], w[0], None],
        [R[0][0], R[1][0], R[2][0]],
        [R[0][1], R[1][1], R[2][1]],
        [R[0][2], R[1][2], R[2][2]],
    ]
    acc = list(wm)
    for j, col in enumerate(jac):
        for i in range(3):
            if col[i] is not None:
                acc[i] = acc[i] + col[i] * dq[j]
    return _stack([a & b for a, b in zip(w, acc, strict=True)])


# -- the detection constraints ----------------------------------------------------------------
#: Variables of one detection, in the order of the boxes given to ``CtcDetections``:
#: position, attitude and altitude at the detection sample, the mine, the slant range and the
#: elevation ``alpha`` of the mine in the body y-z plane.
DETECTION_VARS = ("px", "py", "pz", "phi", "theta", "psi", "a", "mx", "my", "mz", "r", "alpha")


def detection_constraints(seabed_tol: float = 0.5) -> list:
    """The constraints of one side-scan detection over ``DETECTION_VARS``.

    The data's three constraints are ``R^T (m - p) ∈ {0} x [0, oo) x [0, oo)`` (abeam,
    starboard, below), ``|m - p| ∈ [r]`` and ``m_z - p_z - a ∈ [-tol, tol]``. Since ``R`` is a
    rotation, the first two hold exactly when ``m - p = r (cos(alpha) R e_y + sin(alpha) R
    e_z)`` for some ``alpha ∈ [0, pi/2]``: the mine lies on a quarter circle of radius ``r``
    in the vehicle's y-z plane. That parametrisation (which the depth difference pins down
    through ``alpha``) gives the relative vector ``m - p`` to within about a metre, where
    hull consistency on the data's form alone leaves it about ``2 r`` wide; both forms are
    kept (the data's form also contracts the attitude).
    """
    px, py, pz, phi, theta, psi, a, mx, my, mz, r, alpha = (Var(n) for n in DETECTION_VARS)
    dx, dy, dz = mx - px, my - py, mz - pz
    cp, sp, ct, st, cf, sf = cos(psi), sin(psi), cos(theta), sin(theta), cos(phi), sin(phi)
    ex = cp * dx + sp * dy  # R_psi^T d
    ey = cp * dy - sp * dx
    fz = st * ex + ct * dz  # R_theta^T (ex, ey, dz), z component
    yb, zb = r * cos(alpha), r * sin(alpha)  # the body coordinates of m - p
    return [
        ct * ex - st * dz == 0,  # abeam: body x = 0
        cf * ey + sf * fz >= 0,  # starboard
        cf * fz - sf * ey >= 0,  # below
        dx**2 + dy**2 + dz**2 == r**2,
        (mz - pz - a).in_((-seabed_tol, seabed_tol)),
        r >= 0,
        alpha.in_((0.0, float(np.nextafter(np.pi / 2, np.inf)))),
        dx == yb * (cp * st * sf - sp * cf) + zb * (cp * st * cf + sp * sf),  # m - p = R b
        dy == yb * (sp * st * sf + cp * cf) + zb * (sp * st * cf - cp * sf),
        dz == ct * (yb * sf + zb * cf),
    ]


class CtcDetections:
    """The detections of a survey as one tube contractor.

    ``contract(p, attitude, altitude, mines)`` contracts, in place, the gates of the position
    tube ``p`` at the detection samples, the attitude ``(n, 3)`` and altitude ``(n,)`` boxes at
    those samples and the mine boxes ``(n_mines, 3)``. The constraints of all detections form
    one CSP (each detection a copy of ``detection_constraints``, the copies of a mine sharing
    its variables), propagated to its fixed point at ``rel_eps`` by
    :func:`boundest.csp.propagate`.
    """

    def __init__(self, data: AuvData, rel_eps: float = 1e-9) -> None:
        self.k, self.mine, self.rel_eps = data.det_k, data.det_mine, rel_eps
        nd, nm = self.k.size, data.n_mines
        # variables: per detection p (3), attitude (3), a, r, alpha; then the mines (3 each)
        per = 9
        d = np.arange(nd)
        place = {v: per * d + i for i, v in enumerate(("px", "py", "pz", "phi", "theta", "psi",
                                                       "a", "r", "alpha"))}
        for i, c in enumerate("xyz"):
            place[f"m{c}"] = per * nd + 3 * self.mine + i
        self.n_vars = per * nd + 3 * nm
        names = [f"v{i}" for i in range(self.n_vars)]
        lo, hi = np.full(self.n_vars, -np.inf), np.full(self.n_vars, np.inf)
        lo[place["r"]], hi[place["r"]] = data.det_range.lo, data.det_range.hi
        template = compile_model(detection_constraints(data.seabed_tol))
        self.tape = instantiate(names, lo, hi, [(template, place)])
        self.per, self.nm = per, nm

    def contract(self, p: Tube, attitude: Interval, altitude: Interval,
                 mines: Interval) -> None:
        k, nd, per = self.k, self.k.size, self.per
        lo, hi = self.tape.lo.copy(), self.tape.hi.copy()
        rows = Interval.trusted(lo[: per * nd].reshape(nd, per), hi[: per * nd].reshape(nd, per))
        for cols, dom in ((slice(0, 3), p.gates[k]), (slice(3, 6), attitude[k]),
                          (slice(6, 7), altitude[k][:, None])):
            cut = rows[:, cols] & dom
            rows.lo[:, cols], rows.hi[:, cols] = cut.lo, cut.hi
        lo[: per * nd], hi[: per * nd] = rows.lo.ravel(), rows.hi.ravel()
        mv = slice(per * nd, self.n_vars)
        m = Interval.trusted(lo[mv], hi[mv]) & mines.reshape(-1)
        lo[mv], hi[mv] = m.lo, m.hi
        res = propagate(replace(self.tape, lo=lo, hi=hi), rel_eps=self.rel_eps, progress=False,
                        mode="hc4")
        if not res.consistent:
            p.set_empty()
            for dom in (attitude, altitude, mines):
                dom.lo[...] = dom.hi[...] = np.nan
            return
        out = res.slots
        rows = Interval.trusted(out.lo[: per * nd].reshape(nd, per),
                             out.hi[: per * nd].reshape(nd, per))
        p.gates[k] = rows[:, 0:3]
        attitude[k] = rows[:, 3:6]
        altitude[k] = rows[:, 6]
        m = out[per * nd: self.n_vars].reshape(self.nm, 3)
        mines.lo[...], mines.hi[...] = m.lo, m.hi

    __call__ = contract


# -- the estimators ------------------------------------------------------------------------------
@dataclass(repr=False)
class AuvResult:
    """The enclosures of a survey.

    Attributes
    ----------
    mode : str
        ``"localization"`` or ``"slam"``.
    positions : Interval, shape (n, 3)
        The box of ``(north, east, depth)`` at every sample (the gates of the tube).
    tube : Tube
        The position tube (gates at the samples; its slices enclose the path between them).
    mines : Interval, shape (n_mines, 3)
        The mine boxes (entire in localization mode).
    consistent : bool
        ``False`` when the data were proven inconsistent (every set empty).
    report : NetworkReport
        Iterations and contraction of the fixed point.
    time_s : float
        Wall time of the estimation (data already loaded), ``rv_s`` of it for ``R v``.
    """

    mode: str
    positions: Interval
    tube: Tube
    mines: Interval
    consistent: bool
    report: NetworkReport = field(default_factory=NetworkReport)
    time_s: float = 0.0
    rv_s: float = 0.0

    def widths(self) -> NDArray[np.float64]:
        """Width of every position box, shape ``(n, 3)``."""
        return self.positions.width()

    def __repr__(self) -> str:
        w = self.widths()
        mean = ", ".join(f"{x:.3g}" for x in w.mean(axis=0)) if self.consistent else "empty"
        return (f"AuvResult(mode={self.mode!r}, samples={w.shape[0]}, consistent="
                f"{self.consistent}, mean_width=({mean}), iterations={self.report.iterations},"
                f" time_s={self.time_s:.3g})")


def _dt_interval(dt: float) -> Interval:
    """The decimal ``dt`` (as written in the setup) enclosed one ulp outward."""
    return Interval(np.nextafter(dt, -np.inf), np.nextafter(dt, np.inf))


def position_tube(data: AuvData) -> Tube:
    """The position tube before contraction: gates at the samples (time in samples), the
    GPS boxes at the fixes, the depth boxes on every gate, ``p_z >= 0`` everywhere."""
    n = data.n
    t = np.arange(n, dtype=np.float64)
    slices = Interval.trusted(np.tile([-np.inf, -np.inf, 0.0], (n - 1, 1)),
                           np.full((n - 1, 3), np.inf))
    x = Tube(t, slices)
    x.gates.lo[:, 2] = np.maximum(x.gates.lo[:, 2], data.depth.lo)
    x.gates.hi[:, 2] = np.minimum(x.gates.hi[:, 2], data.depth.hi)
    g = x.gates[data.fix_k] & data.fix
    x.gates[data.fix_k] = g
    if x.is_empty():  # a fix outside the depth boxes
        x.set_empty()
    return x


def _velocity_tube(data: AuvData, w: Interval) -> Tube:
    """``dt R v`` held over each sample: the derivative per sample of the position."""
    return Tube.piecewise_constant(np.arange(data.n, dtype=np.float64),
                                   _dt_interval(data.dt) * w[:-1])


def _result(mode: str, x: Tube, mines: Interval, report: NetworkReport, t0: float,
            rv_s: float) -> AuvResult:
    ok = not x.is_empty() and not np.isnan(mines.lo).any()
    return AuvResult(mode, x.gates, x, mines, ok, report, time.perf_counter() - t0, rv_s)


def localize(data: AuvData, form: str = "best") -> AuvResult:
    """Dead reckoning with both GPS fixes, the depth sensor and ``p_z >= 0`` (one forward and
    one backward ``CtcDeriv`` pass: a fixed point for these constraints)."""
    start = time.perf_counter()
    w = world_velocity(data.attitude, data.velocity, form)
    rv_s = time.perf_counter() - start
    x = position_tube(data)
    CtcDeriv().contract(x, _velocity_tube(data, w))
    report = NetworkReport(iterations=1, converged=True, empty=x.is_empty())
    return _result("localization", x, Interval.entire((data.n_mines, 3)), report, start, rv_s)


def slam(data: AuvData, form: str = "best", rel_eps: float = 1e-4, max_iter: int = 100,
         progress: bool | None = None) -> AuvResult:
    """Localization and mapping: the detections and ``CtcDeriv`` in one contractor network,
    to a relative fixed point ``rel_eps``.

    The attitude and altitude boxes at the detection samples are contracted too; the world
    velocity of those samples is then recomputed from them (``_CtcWorldVelocity`` keeps the
    derivative tube consistent with the contracted attitude).
    """
    start = time.perf_counter()
    att = data.attitude.copy()
    alt = data.altitude.copy()
    w = world_velocity(att, data.velocity, form)
    rv_s = time.perf_counter() - start
    x = position_tube(data)
    v = _velocity_tube(data, w)
    mines = Interval.entire((data.n_mines, 3))
    cn = ContractorNetwork()
    cn.add(CtcDetections(data), [x, att, alt, mines])
    cn.add(_CtcWorldVelocity(data, form), [v, att])
    cn.add(CtcDeriv(), [x, v])
    report = cn.contract(rel_eps=rel_eps, max_iter=max_iter, progress=progress)
    return _result("slam", x, mines, report, start, rv_s)


class _CtcWorldVelocity:
    """Recompute ``dt R v`` at the detection samples from their contracted attitude."""

    def __init__(self, data: AuvData, form: str) -> None:
        self.k = data.det_k[data.det_k < data.n - 1]
        self.velocity = data.velocity[self.k]
        self.dt = _dt_interval(data.dt)
        self.form = form

    def contract(self, v: Tube, attitude: Interval) -> None:
        if self.k.size == 0:
            return
        w = self.dt * world_velocity(attitude[self.k], self.velocity, self.form)
        v.slices[self.k] = v.slices[self.k] & w
        if np.isnan(v.slices.lo).any():
            v.set_empty()
