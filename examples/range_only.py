"""A robot localised by ranges to beacons taken at uncertain times (Rohou et al. 2018, sec. 4).

State ``x = (x1, x2, x3, x4)``: position, heading and speed, with ``x1' = x4 cos(x3)``,
``x2' = x4 sin(x3)``, ``x3' = u1``, ``x4' = u2`` and the input known to +-1e-3. Only the
initial heading and speed are known; the position comes from eleven ranges to three beacons,
each known to within an interval and taken at a time known only to within an interval. The
estimator is a contractor network on tubes (one box per time slice): ``CtcSlices`` for the
algebraic constraints at every time, ``CtcDeriv`` for each derivative, one ``CtcEval`` per
measurement ``z_i = y(t_i)``, which contracts the tube, the range and the time at once (the
plain tube inverse, ``time_deriv=False``, as ``boundest run range-only`` does).

The data and the truth come from ``boundest.scenarios.range_only.simulate`` (Table 1's
beacons and times, a random truth inside the model; its positions are a quadrature with an
error far below 1e-10 m, negligible against the tube). The distance rate is constrained in
the bearing form of the paper's network only (``boundest run range-only`` adds a product
form, a few percent tighter).

To adapt it: change the evolution constraints and the input tube, put your own beacons and
measurements in ``t_meas``, ``z_meas``, and keep one ``CtcEval`` per measurement.
"""

from __future__ import annotations

import math

import numpy as np

import boundest as bd
from boundest.scenarios import range_only

DT = 0.01  # the time step of the tubes [s]
truth, t_true, meas = range_only.simulate(seed=0)     # meas.t, meas.z, meas.beacon, beacons

t = bd.tube.time_grid(0.0, 64.0, DT)
n, n_beacons = t.size - 1, meas.beacons.shape[0]
x = bd.Tube(t, bd.Interval.entire((n, 4)))            # the state: nothing known yet
pi = bd.Interval(math.pi, np.nextafter(math.pi, np.inf))
x.gates[0, 2] = pi / 2 + bd.Interval(-0.01, 0.01)    # initial heading
x.gates[0, 3] = bd.Interval(-0.01, 0.01)             # initial speed
v = bd.Tube(t, bd.Interval.entire((n, 4)))            # its derivative


def inputs(s: bd.Interval) -> bd.Interval:
    """Equation 14 over the time intervals s, widened by the input error 1e-3."""
    e = bd.Interval(-1e-3, 1e-3)
    u1 = -bd.Interval(9.0) / 20 * bd.cos(s / 5) + e
    u2 = bd.Interval(1.0) / 10 + bd.sin(s / 4) + e
    return bd.Interval.stack([u1, u2])


u = bd.Tube.from_function_on(t, inputs)
y = bd.Tube(t, bd.Interval(np.zeros((n, n_beacons)), np.inf))  # distances to the beacons
w = bd.Tube(t, bd.Interval.entire((n, n_beacons)))             # and their derivatives

x1, x2, x3, x4, v1, v2, v3, v4, u1, u2, yk, wk = (bd.Var(name) for name in (
    "x1", "x2", "x3", "x4", "v1", "v2", "v3", "v4", "u1", "u2", "y", "w"))
cn = bd.ContractorNetwork()
cn.add(bd.CtcSlices([v1 == x4 * bd.cos(x3), v2 == x4 * bd.sin(x3), v3 == u1, v4 == u2],
                    ["x3", "x4", "v1", "v2", "v3", "v4", "u1", "u2"]), [x[2], x[3], v, u])
cn.add(bd.CtcDeriv(), [x, v])
for k in range(n_beacons):
    dx, dy = x1 - meas.beacons[k, 0], x2 - meas.beacons[k, 1]
    cn.add(bd.CtcSlices([yk == bd.sqrt(bd.sqr(dx) + bd.sqr(dy)),
                         wk == x4 * bd.cos(x3 - bd.atan2(dy, dx))],
                        ["x1", "x2", "x3", "x4", "y", "w"]), [x, y[k], w[k]])
cn.add(bd.CtcDeriv(), [y, w])
t_meas = [meas.t[i].copy() for i in range(len(meas))]  # contracted in place
z_meas = [meas.z[i].copy() for i in range(len(meas))]
for i, k in enumerate(meas.beacon):
    cn.add(bd.CtcEval(time_deriv=False), [t_meas[i], z_meas[i], y[k], w[k]])
report = cn.contract(rel_eps=1e-4, max_iter=100, progress=False)
assert not report.empty, "the network came out empty: the data contradict the model"

d = np.hypot(*x.gates.width()[:, :2].T)
print(f"{report.iterations} iterations in {report.time_s:.2f} s, converged: {report.converged};"
      f" mean diagonal of the position box {d.mean():.2f} m")
s = np.linspace(0.0, 64.0, 4 * n + 1)                # the gates and three times in each slice
assert x.contains(s, truth.states(s)), "the true trajectory leaves the tube [x]"
bad = [i for i in range(len(meas)) if not t_meas[i].contains(t_true[i])]
assert not bad, f"the true time of measurement(s) {bad} left its contracted interval"
print(f"OK: the truth lies in the tube at {s.size} times and in every [t_i] (i = 1..{len(meas)})")
