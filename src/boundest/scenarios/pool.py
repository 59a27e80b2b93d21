"""The pool robot of Jaulin's robust set-membership observer: a recursive q-relaxed box observer
over the sonar pings (:class:`boundest.estimation.robust.RobustObserver`).

- prediction: the interval Euler step of ``f(X, u) = (v cos theta, v sin theta, u2 - u1,
  u1 + u2 - v)`` with the input box of the step (exact model for these data);
- observation: the ping's first-hit constraint ``d = g(x, y, theta + alpha)``
  (:class:`boundest.ctc.CtcRayCast` on the pool map), which contracts ``x``, ``y``, ``theta``;
- at most ``q`` outliers among the last ``m`` pings (one sonar revolution is 80 pings).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .. import interval as iv
from ..ctc import CtcRayCast, Fixpoint
from ..estimation.robust import RobustObserver, window_probability
from ..interval import Interval
from .pool_data import PoolData

__all__ = ["PoolResult", "pool_observer", "restart_box", "solve_pool"]


def _dt(dt: float) -> Interval:
    return Interval(np.nextafter(dt, -np.inf), np.nextafter(dt, np.inf))


def predictor(dt: float):
    """The interval Euler step ``X + dt f(X, u)`` on boxes ``(..., 4)`` with input boxes
    ``(..., 2)`` (``v`` written ``(1 - dt) v + dt (u1 + u2)``: one occurrence of ``v``)."""
    h = _dt(dt)
    one_minus = 1.0 - h

    def predict(x: Interval, u: Interval) -> Interval:
        px, py, th, v = (x[..., i] for i in range(4))
        u1, u2 = u[..., 0], u[..., 1]
        hv = h * v
        out = [px + hv * iv.cos(th), py + hv * iv.sin(th), th + h * (u2 - u1),
               one_minus * v + h * (u1 + u2)]
        return Interval._new(np.stack([o.lo for o in out], -1), np.stack([o.hi for o in out], -1))

    return predict


def observer_of(ctc: CtcRayCast, passes: int = 3):
    """Contract state boxes ``(..., 4)`` with one ping ``(alpha, d)``: the ray-cast contractor
    on ``(x, y, theta + alpha, d)``, then ``theta`` from the contracted beam direction."""
    fix = Fixpoint(ctc, max_iter=passes) if passes > 1 else ctc

    def observe(x: Interval, ping: tuple[float, Interval]) -> Interval:
        alpha, d = ping
        beta = x[..., 2] + alpha
        d = Interval._new(np.broadcast_to(d.lo, beta.shape), np.broadcast_to(d.hi, beta.shape))
        box = Interval._new(np.stack([x.lo[..., 0], x.lo[..., 1], beta.lo, d.lo], -1),
                            np.stack([x.hi[..., 0], x.hi[..., 1], beta.hi, d.hi], -1))
        c = fix(box)
        th = x[..., 2] & (c[..., 2] - alpha)
        out = Interval._new(np.stack([c.lo[..., 0], c.lo[..., 1], th.lo, x.lo[..., 3]], -1),
                            np.stack([c.hi[..., 0], c.hi[..., 1], th.hi, x.hi[..., 3]], -1))
        bad = np.isnan(out.lo).any(-1, keepdims=True)
        return Interval._new(np.where(bad, np.nan, out.lo), np.where(bad, np.nan, out.hi))

    return observe


def restart_box(data: PoolData) -> Interval:
    """A box that holds the state at any time: the pool's rectangle, any heading, and
    ``|v| <= max(|v(0)|, max |u1 + u2|)`` (``v`` relaxes towards ``u1 + u2``)."""
    seg = data.map.segments.reshape(-1, 2)
    u = data.inputs
    vmax = max(float(np.max(np.abs(data.x0.lo[3]))), float(np.max(np.abs(data.x0.hi[3]))),
               float(np.max(np.abs(u.lo[..., 0] + u.lo[..., 1]))),
               float(np.max(np.abs(u.hi[..., 0] + u.hi[..., 1]))))
    vmax = float(np.nextafter(vmax, np.inf))
    return Interval([seg[:, 0].min(), seg[:, 1].min(), -np.inf, -vmax],
                    [seg[:, 0].max(), seg[:, 1].max(), np.inf, vmax])


def pool_observer(data: PoolData, q: int = 8, m: int = 80, passes: int = 3) -> RobustObserver:
    """The observer for ``data`` (a mission or a batch of simulated missions), ready for
    ``update(u_k, (alpha_k, d_k))``: ``u_k`` the input box since the previous ping."""
    x0 = data.x0
    if data.n_missions is not None:
        x0 = Interval._new(np.broadcast_to(x0.lo, (data.n_missions, 4)).copy(),
                           np.broadcast_to(x0.hi, (data.n_missions, 4)).copy())
    return RobustObserver(predictor(data.dt), observer_of(CtcRayCast(data.map), passes), x0,
                          m=m, q=q, restart=restart_box(data))


@dataclass(repr=False)
class PoolResult:
    """The observer's sets over a mission.

    Attributes
    ----------
    boxes : Interval, shape (n, 4) or (M, n, 4)
        ``X_k`` for every ping.
    rejected : ndarray of int, shape (n,) or (M, n)
        Pings of the window inconsistent with ``X_k``.
    empty : ndarray of bool
        Steps where the set came out empty (more than q outliers in the window): the observer
        restarted there.
    window_probability : ndarray, shape (n,)
        ``P(at most q outliers among the pings of the window at k)``: the probability that one
        window is fine; the recursive set at ``k`` needs every window since the last restart to
        be (module :mod:`boundest.estimation.robust`).
    """

    boxes: Interval
    rejected: NDArray[np.intp]
    empty: NDArray[np.bool_]
    window_probability: NDArray[np.float64]
    q: int
    m: int
    time_s: float

    def centre(self) -> NDArray[np.float64]:
        """The Chebyshev centre of each box (its midpoint; NaN where empty)."""
        return self.boxes.mid()

    def widths(self) -> NDArray[np.float64]:
        return self.boxes.width()

    def __repr__(self) -> str:
        w = np.nanmean(self.widths()[..., :2], axis=tuple(range(self.widths().ndim - 1)))
        return (f"PoolResult(steps={self.boxes.shape[-2]}, q={self.q}, m={self.m}, "
                f"mean_width_xy=({w[0]:.3g}, {w[1]:.3g}), empty_steps="
                f"{int(np.count_nonzero(self.empty))}, time_s={self.time_s:.3g})")


def solve_pool(data: PoolData, q: int = 8, m: int = 80, passes: int = 3) -> PoolResult:
    """Run the observer over the whole mission (or batch of missions) offline."""
    start = time.perf_counter()
    obs = pool_observer(data, q, m, passes)
    boxes, rejected, empty = [], [], []
    for k in range(data.n):  # sequential by nature: each step needs the previous set
        u = data.inputs[..., k - 1, :] if k else None
        step = obs.update(u, (float(data.alpha[k]), data.ranges[..., k]))
        boxes.append(step.box)
        rejected.append(step.rejected)
        empty.append(step.empty)
    axis = 0 if data.n_missions is None else 1
    b = Interval._new(np.stack([x.lo for x in boxes], axis), np.stack([x.hi for x in boxes], axis))
    probs = np.array([window_probability(min(k + 1, m), q, data.p_outlier)
                      for k in range(data.n)])
    return PoolResult(b, np.stack(rejected, axis), np.stack(empty, axis), probs, q, m,
                      time.perf_counter() - start)
