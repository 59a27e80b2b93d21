"""Localization of an AUV on a side-scan mine survey (Jaulin, Bertholom, Dabe 2007).

The Redermor AUV measures its attitude ``(phi, theta, psi)`` and its body velocity ``v`` at
every sample, each to within an interval, its depth with a pressure sensor, and gets a GPS fix
at the surface at the start and at the end. Its position is a tube ``p(.)`` whose derivative
is the world velocity ``R(phi, theta, psi) v``; ``CtcDeriv`` contracts it forward from the
first fix and backward from the last (dead reckoning both ways, a fixed point for these
constraints). Then the side-scan detections of the mines, each seen once or twice, are added
(SLAM): ``CtcDetections`` ties the position at each detection to its unknown mine box, and a
contractor network runs both to a fixed point, so a mine seen twice links the two passes.
(``boundest run auv`` also recomputes ``R v`` from the attitude the detections contract:
a little tighter; without it the sets are just as sound.)

Built from public blocks of ``boundest.scenarios.auv``: ``world_velocity`` (a tight enclosure
of ``R v`` over all samples at once; writing it by hand would take a page) and
``CtcDetections`` (the detection constraints as one CSP). The survey and its truth come from
``boundest.scenarios.auv_sim.simulate_survey``: 6000 samples of 0.1 s, a tenth of the
embedded mission (``boundest run auv``).

To adapt it: give your own sensor boxes as an ``AuvData`` (``load_auv(folder)`` reads the
files of ``docs/data-format.md``), or replace ``world_velocity`` by your own kinematics.
"""

from __future__ import annotations

import numpy as np

import boundest as bd
from boundest.scenarios.auv import CtcDetections, world_velocity
from boundest.scenarios.auv_sim import simulate_survey

data, truth = simulate_survey(seed=0, n_samples=6000, n_legs=4, n_mines=3)

# time runs in samples: gate k is sample k, and the derivative per sample is dt R v
t = np.arange(data.n, dtype=float)
dt = bd.Interval(np.nextafter(data.dt, -np.inf), np.nextafter(data.dt, np.inf))  # dt is a decimal
v = bd.Tube.piecewise_constant(t, dt * world_velocity(data.attitude, data.velocity)[:-1])

p = bd.Tube(t, bd.Interval(np.tile([-np.inf, -np.inf, 0.0], (data.n - 1, 1)), np.inf))
p.gates[:, 2] = p.gates[:, 2] & data.depth          # the pressure sensor at every sample
p.gates[data.fix_k] = p.gates[data.fix_k] & data.fix  # the two GPS fixes
bd.CtcDeriv().contract(p, v)
assert not p.is_empty(), "the localization came out empty: the data contradict the model"
loc = p.gates.copy()                                # keep the localization result

attitude, altitude = data.attitude.copy(), data.altitude.copy()
mines = bd.Interval.entire((data.n_mines, 3))
cn = bd.ContractorNetwork()
cn.add(CtcDetections(data), [p, attitude, altitude, mines])
cn.add(bd.CtcDeriv(), [p, v])
report = cn.contract(rel_eps=1e-4, progress=False)
assert not report.empty, "SLAM came out empty: the data contradict the model"

for name, box in (("localization", loc), ("SLAM", p.gates)):
    wn, we = box.width()[:, 0], box.width()[:, 1]
    print(f"{name:>12}: mean width north {wn.mean():5.2f} m, east {we.mean():5.2f} m; "
          f"largest {max(wn.max(), we.max()):5.2f} m")
for name, box in (("localization", loc), ("SLAM", p.gates)):
    out = np.argwhere(~box.contains(truth.p))
    assert out.size == 0, f"{name}: the truth leaves its box at (sample, axis) {out[:5].tolist()}"
out = np.argwhere(~mines.contains(truth.mines))
assert out.size == 0, f"a true mine leaves its box at (mine, axis) {out.tolist()}"
print(f"OK: the truth lies in every position box (k = 0..{data.n - 1}, both modes) and every "
      f"mine box ({data.n_mines} mines)")
