"""Correcting a drifting clock with distance measurements (Rohou et al. 2018, section 5).

An underwater beacon at depth 10 m keeps a clock ``tau = h(t)`` that drifts from the
reference time ``t``: only ``h(0) = 0`` and the rate bounds ``h'(t) in [0.08, 0.12] t +
[0.97, 1.08]`` are known. A boat follows a known circle up to bounded errors, and the beacon
measures its distance ``z_i`` at its own clock times ``tau_i``. The contractor network ties
the tubes of the boat, its distance ``y`` and the drift ``h`` together; two ``CtcEval`` per
measurement (``tau_i = h(t_i)`` and ``z_i = y(t_i)``) contract the unknown reference times
``[t_i]``, which in turn correct the drift tube ``[h]``.

The data and the truth (a drift and a boat inside the model) come from
``boundest.scenarios.drifting_clock.simulate``; ``t_final`` bounds every reference time the
clock times allow.

To adapt it: write your own ephemeris in ``boat`` and ``boat_velocity``, your own bounds on
the drift rate in ``rate``, and give your clock times and distance intervals.
"""

from __future__ import annotations

import numpy as np

import boundest as bd
from boundest.scenarios import drifting_clock

DT = 0.01  # time step of the tubes [s]


def dec(lo: float, hi: float) -> bd.Interval:
    """An interval enclosing the decimals lo, hi (0.08 is not a float: one float outward)."""
    return bd.Interval(np.nextafter(lo, -np.inf), np.nextafter(hi, np.inf))


def boat(s: bd.Interval) -> bd.Interval:  # equation 18, over the time intervals s
    return bd.Interval.stack([dec(70, 90) + 100 * bd.cos(s), dec(10, 30) + 100 * bd.sin(s)])


def boat_velocity(s: bd.Interval) -> bd.Interval:  # equation 19
    return bd.Interval.stack([dec(-0.1, 0.1) - 100 * bd.sin(s), dec(-0.1, 0.1) + 100 * bd.cos(s)])


def rate(s: bd.Interval) -> bd.Interval:  # equation 17: the bounds of h'(t)
    return dec(0.08, 0.12) * s + dec(0.97, 1.08)


truth, t_true, meas = drifting_clock.simulate(seed=0)   # meas.tau, meas.z: intervals
tf = drifting_clock.t_final(meas)
t = bd.tube.time_grid(0.0, tf, DT)
n = t.size - 1
x, v = bd.Tube.from_function_on(t, boat), bd.Tube.from_function_on(t, boat_velocity)
phi = bd.Tube.from_function_on(t, rate)
h = bd.Tube(t, bd.Interval.entire(n))                   # the drift, h(0) = 0
h.gates[0] = bd.Interval(0.0)
y = bd.Tube(t, bd.Interval(np.full(n, 10.0), np.inf))  # the distance (at least the depth)
w = bd.Tube(t, bd.Interval.entire(n))                   # its derivative

x1, x2, v1, v2, yv, wv = (bd.Var(name) for name in ("x1", "x2", "v1", "v2", "y", "w"))
distance = bd.CtcSlices([yv == bd.sqrt(bd.sqr(x1) + bd.sqr(x2) + 100),
                         wv == (x1 * v1 + x2 * v2) / yv], ["x1", "x2", "v1", "v2", "y", "w"])
t_i = [bd.Interval(0.0, tf) for _ in range(len(meas))]  # the unknown reference times
z_i = [meas.z[i].copy() for i in range(len(meas))]
deriv, ev = bd.CtcDeriv(), bd.CtcEval()
cn = bd.ContractorNetwork()
cn.add(deriv, [x, v])
cn.add(distance, [x, v, y, w])
cn.add(deriv, [y, w])
cn.add(deriv, [h, phi])
for i in range(len(meas)):
    tau = meas.tau[i].copy()
    cn.add(ev, [t_i[i], tau, h, phi])
    cn.add(ev, [t_i[i], z_i[i], y, w])
    # tau_i = h(t_i) once more: [h] gets the [t_i] the distance narrowed in the same
    # iteration (the same fixed point; 6 iterations instead of 8)
    cn.add(ev, [t_i[i], tau, h, phi])
report = cn.contract(rel_eps=1e-4, max_iter=100, progress=False)
assert not report.empty, "the network came out empty: the data contradict the model"

print(f"{report.iterations} iterations in {report.time_s:.2f} s; widest [h](t): "
      f"{h.gates.width().max():.3f} s; [t_i] widths: "
      + " ".join(f"{float(ti.width()):.3f}" for ti in t_i))
s = np.linspace(0.0, tf, 4 * n + 1)                    # the gates and three times in each slice
assert h.contains(s, truth.drift(s)), "the true drift leaves the tube [h]"
assert y.contains(s, truth.distance(s)), "the true distance leaves the tube [y]"
bad = [i for i in range(len(meas)) if not t_i[i].contains(t_true[i])]
assert not bad, f"the true reference time of measurement(s) {bad} left its interval"
print(f"OK: the truth lies in [h] and [y] at {s.size} times and in every [t_i] "
      f"(i = 1..{len(meas)})")
