"""Satellite localisation as one constraint satisfaction problem (Jaulin 2002).

A satellite orbits the earth with an Euler step of 0.5 and a perturbation bounded by 0.01;
every step measures its bearing tangent ``y1 = x2 / x1``, radial speed ``y2 = x1 x3 + x2 x4``
and squared distance ``y3 = x1^2 + x2^2``, each to within +-0.1. Written over the whole
horizon, the problem is one CSP in the model text format (``docs/model-format.md``), which
``boundest.propagate`` contracts to a fixed point and then shaves (3B consistency): every box
holds every state that agrees with the model and the data.

The data and the truth come from ``boundest.scenarios.satellite.simulate`` (a float
simulation whose perturbations stay within 0.99 of their bound, so that its rounding cannot
push the truth out of the model), over the paper's horizon ``K = 200``: 2215 variables and
1407 constraints.

To adapt it: write your own dynamics and outputs in ``step_text``, declare your
measurement intervals, and pick the variables to shave (or use ``mode="hc4"``, hull
consistency alone: faster, wider). A model kept in a file is read by ``bd.load_model(path)``,
and ``boundest solve path`` propagates it from the command line.
"""

from __future__ import annotations

import numpy as np

import boundest as bd
from boundest.scenarios import satellite

K = 200  # steps k = 0..K


def interval_text(lo: float, hi: float) -> str:
    """A domain of the text format: repr writes the shortest decimal that reads back as the float,
    and the parser encloses that decimal, so the domain holds [lo, hi]."""
    return f"[{float(lo)!r}, {float(hi)!r}]"


def step_text(k: int) -> list[str]:
    """The constraints of step k: the dynamics to k + 1 and the three outputs at k."""
    r3 = f"(sqrt(x1_{k}^2 + x2_{k}^2))^3"
    return [f"x1_{k + 1} = x1_{k} + 0.5*x3_{k} + w1_{k}",
            f"x2_{k + 1} = x2_{k} + 0.5*x4_{k} + w2_{k}",
            f"x3_{k + 1} = x3_{k} - 0.5*x1_{k}/{r3} + w3_{k}",
            f"x4_{k + 1} = x4_{k} - 0.5*x2_{k}/{r3} + w4_{k}",
            f"y1_{k} = x2_{k}/x1_{k}",
            f"y2_{k} = x1_{k}*x3_{k} + x2_{k}*x4_{k}",
            f"y3_{k} = x1_{k}^2 + x2_{k}^2"]


truth, meas = satellite.simulate(K, seed=1)  # truth[k] for k = 0..K+1; meas.y_lo[k, i] ...

# the sign restrictions of Jaulin 2002 (Remark 2) make the problem identifiable
decl = ["x1_0 in [0, +oo[", "x2_0 in [0, +oo[", "x3_0 in ]-oo, 0]", "x4_0 in [0, +oo["]
for k in range(K + 1):
    decl += [f"w{i}_{k} in [-0.01, 0.01]" for i in (1, 2, 3, 4)]
    decl += [f"y{i + 1}_{k} in {interval_text(meas.y_lo[k, i], meas.y_hi[k, i])}"
             for i in range(3)]
    decl += [f"x{i}_{k + 1} in ]-oo, +oo[" for i in (1, 2, 3, 4)]
constraints = [c for k in range(K + 1) for c in step_text(k)]
text = ("Variables\n  " + ",\n  ".join(decl) + ";\n"
        "Constraints\n  " + ",\n  ".join(constraints) + ";\n")

model = bd.parse_model(text, source="satellite.txt")
states = [f"x{i}_{k}" for k in range(K + 2) for i in (1, 2, 3, 4)]
res = bd.propagate(model, mode="3b", shave=states)
assert res.consistent, "the CSP came out empty: the data contradict the model"

lo = np.array([[float(res[f"x{i}_{k}"].lo) for i in (1, 2, 3, 4)] for k in range(K + 2)])
hi = np.array([[float(res[f"x{i}_{k}"].hi) for i in (1, 2, 3, 4)] for k in range(K + 2)])
print(f"{len(decl)} variables, {len(constraints)} constraints, {res.time_s:.2f} s; "
      f"mean width of x1: {np.mean(hi[:, 0] - lo[:, 0]):.3f}")

outside = np.argwhere(~((lo <= truth) & (truth <= hi)))
assert outside.size == 0, f"the truth leaves its box at (k, component) {outside[:5].tolist()}"
print(f"OK: the truth lies in every box (k = 0..{K + 1})")
