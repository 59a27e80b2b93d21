"""A robot in a pool localised by a sonar despite outliers: the robust q-relaxed observer
(Jaulin's robust set-membership observer).

The robot ``(x, y, theta, v)`` moves by ``x' = v cos(theta)``, ``y' = v sin(theta)``,
``theta' = u2 - u1``, ``v' = u1 + u2 - v`` with input boxes known to +-0.05, sampled every
0.04 s. A sonar rotating on it measures at each ping the distance to the first wall or pillar
along its beam (``CtcRayCast`` on the pool's map); about 5 % of the pings are outliers, whose
intervals are simply wrong. ``RobustObserver`` keeps the states consistent with all but at most
``q`` of the last ``m`` pings: each ping contracts the predicted box, every ping's set is
carried forward by the dynamics, and the set is their q-relaxed intersection.

Built on ``boundest.estimation.robust.RobustObserver`` with this script's own Euler step and
sonar contractor; ``boundest run pool`` runs the compiled observer of
``boundest.scenarios.pool`` (``PoolObserver``), which also smooths inside the window and is
tighter. The mission and its truth come from ``boundest.scenarios.pool_sim.simulate_pool``.
The guarantee is conditional: the truth is in the set when no window held more than ``q``
outliers, which the script checks on the simulated truth first.

To adapt it: write your own ``predict`` (a sound image of boxes by one step) and ``observe``
(a contractor of the measurement), and choose ``m`` and ``q`` from your outlier rate
(``window_probability(m, q, p)``).
"""

from __future__ import annotations

import numpy as np

import boundest as bd
from boundest.estimation.robust import RobustObserver, window_probability
from boundest.scenarios.pool_sim import simulate_pool

Q, M = 8, 80                     # at most 8 outliers among the last 80 pings (one revolution)
data, truth = simulate_pool(seed=1)
sonar = bd.ctc.CtcRayCast(data.map)
PAD = 2.0**-50                   # covers the float64 rounding of the simulated Euler steps


def predict(X: bd.Interval, u: bd.Interval) -> bd.Interval:
    """One Euler step ``X + dt f(X, u)`` of boxes X (..., 4), widened by the float rounding."""
    x, y, th, v, u1, u2 = X[..., 0], X[..., 1], X[..., 2], X[..., 3], u[..., 0], u[..., 1]
    inc = data.dt * bd.Interval.stack([v * bd.cos(th), v * bd.sin(th), u2 - u1, u1 + u2 - v])
    # v + dt (u1 + u2 - v) written with v once: (1 - dt) v shrinks, v - dt v would grow
    v_next = (1 - bd.Interval(data.dt)) * v + data.dt * (u1 + u2)
    X_next = bd.Interval.stack([x + inc[..., 0], y + inc[..., 1], th + inc[..., 2], v_next])
    return X_next.inflate(PAD * inc.mag(), PAD)


def observe(X: bd.Interval, ping: tuple[float, bd.Interval]) -> bd.Interval:
    """X contracted by one ping: the first hit along the beam theta + alpha is at d."""
    alpha, d = ping
    d = d.inflate(0.0, 2.0**-40)  # the float64 evaluation of the simulated distance
    c = sonar(bd.Interval.stack([X[0], X[1], X[2] + alpha, d]))
    return bd.Interval.stack([c[0], c[1], X[2] & (c[2] - alpha), X[3]])


# at any time: inside the pool, any heading, |v| below the largest |u1 + u2| or |v(0)|
corners = data.map.segments.reshape(-1, 2)
vmax = max(float((data.inputs[:, 0] + data.inputs[:, 1]).mag().max()), float(data.x0[3].mag()))
anywhere = bd.Interval([*corners.min(axis=0), -np.inf, -vmax],
                       [*corners.max(axis=0), np.inf, vmax])
obs = RobustObserver(predict, observe, data.x0, m=M, q=Q, restart=anywhere)
steps = [obs.update(data.inputs[k - 1] if k else None, (data.alpha[k], data.ranges[k]))
         for k in range(data.n)]
X = bd.Interval.stack([s.box for s in steps], axis=0)

w = X.width()
print(f"{data.n} pings, P(at most {Q} outliers in {M} pings) = "
      f"{window_probability(M, Q, data.p_outlier):.4f}; mean widths x {w[:, 0].mean():.2f} m, "
      f"y {w[:, 1].mean():.2f} m; most pings rejected in a window: "
      f"{max(int(s.rejected) for s in steps)}; restarts: {sum(bool(s.empty) for s in steps)}")
in_window = np.convolve(truth.outlier, np.ones(M, dtype=int))[:data.n]
assert in_window.max() <= Q, "a window holds more than Q outliers: the guarantee does not apply"
out = np.argwhere(~X.contains(truth.states))
assert out.size == 0, f"the truth leaves its box at (k, component) {out[:5].tolist()}"
print(f"OK: the truth lies in every box (k = 0..{data.n - 1}; at most "
      f"{in_window.max()} outliers in a window, {int(truth.outlier.sum())} in all)")
