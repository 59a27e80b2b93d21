"""Jaulin et al. 2001 test case (section 5, equation 21): causal and non-causal set state
estimation.

    x(k) = 3 (sin(x1(k-1) + x2(k-1)), cos(x1(k-1) + x2(k-1))),   y(k) = |x1(k)|,   k = 1..10

with measurement sets ``Y(k) = y_m(k) + [-0.1, 0.1]`` (embedded ``jaulin2001.csv``: columns k,
y_lo, y_hi). All domains start as ``R^2`` and ``R``. For subpavings, ``x(0)`` is paved in the
frame ``[-4, 4]^2`` of Jaulin et al. 2001 Fig. 7: this changes no other set, because ``x1 + x2``
spans
``[-8, 8]``, more than a period, so ``f([-4, 4]^2) = f(R^2)`` (the whole circle of radius 3).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..estimation import ChainEstimate, DiscreteSystem, rcse_ncse
from ..expr.functions import cos as _cos
from ..expr.functions import sin as _sin
from ..interval import Interval
from ..paving import Subpaving
from ._data import check_index, embedded, read_csv

if TYPE_CHECKING:
    import mpmath

__all__ = ["FRAME", "NOISE", "Jaulin2001", "Simulation", "load", "simulate", "solve", "system",
           "to_json"]

#: the frame of Jaulin et al. 2001 Fig. 7, also the prior of x(0) for subpavings
FRAME = Interval([-4.0, -4.0], [4.0, 4.0])
#: bound of the measurement noise
NOISE = 0.1


def system() -> DiscreteSystem:
    """The system of Jaulin et al. 2001 equation 21."""
    return DiscreteSystem(lambda x: [3 * _sin(x[0] + x[1]), 3 * _cos(x[0] + x[1])],
                          lambda x: [abs(x[0])], nx=2, ny=1)


def load(path: str | Path | None = None) -> Interval:
    """The measurement sets ``Y(k)``, k = 1..K, as an Interval of shape ``(K, 1)``.

    Columns ``k, y_lo, y_hi`` (no others), rows ``k = 1, 2, ...`` in order; ``y_lo`` may be
    ``-inf`` and ``y_hi`` ``inf`` (no measurement at ``k``: ``Y(k)`` unbounded).
    """
    path = embedded("jaulin2001.csv") if path is None else Path(path)
    d = read_csv(path, {"k": "finite", "y_lo": "lo", "y_hi": "hi"})
    check_index(d, "k", 1)
    return Interval(d["y_lo"][:, None], d["y_hi"][:, None])


@dataclass
class Simulation:
    """A simulated run: the true states (mpmath, 40 digits) and the measurement sets."""

    x: list[tuple[mpmath.mpf, mpmath.mpf]]  # x(0..K)
    y: Interval  # (K, 1)


def simulate(x0: tuple[float, float], K: int = 10, seed: int | None = None,
             noise: float = NOISE) -> Simulation:
    """Simulate equation 21 from ``x0`` with uniform noise in ``[-noise, noise]``.

    The trajectory is computed with mpmath at 40 digits (the map expands errors about 6 times
    per step: 1e-40 * 6^10 is far below a float's resolution), so it is the exact trajectory to
    float precision; ``Y(k) = y_m(k) + [-noise, noise]`` is rounded outward, and it is checked
    exactly that it contains ``y*(k)``. Needs mpmath (``pip install mpmath``; the ``test``
    extra has it), which the commands do not.
    """
    try:
        import mpmath
    except ImportError as exc:
        raise ImportError("jaulin2001.simulate needs mpmath for its exact trajectory: "
                          "pip install mpmath (or boundest[test])") from exc
    rng = np.random.default_rng(seed)
    with mpmath.workdps(40):
        x = [(mpmath.mpf(x0[0]), mpmath.mpf(x0[1]))]
        for _ in range(K):
            s = x[-1][0] + x[-1][1]
            x.append((3 * mpmath.sin(s), 3 * mpmath.cos(s)))
        ystar = [abs(p[0]) for p in x[1:]]
        ym = np.array([float(v) for v in ystar]) + rng.uniform(-noise, noise, K)
        y = Interval(ym[:, None]) + Interval(-noise, noise)
        for k in range(K):
            if not (mpmath.mpf(float(y.lo[k, 0])) <= ystar[k] <= mpmath.mpf(float(y.hi[k, 0]))):
                raise AssertionError(f"simulate: y*({k + 1}) outside its measurement set")
    return Simulation(x, y)


@dataclass
class Jaulin2001:
    """The causal (RCSE) and non-causal (NCSE) sets of x(k), k = 0..K."""

    rcse: ChainEstimate
    ncse: ChainEstimate
    domains: str
    eps: float


def solve(y: Interval, *, domains: str = "subpavings", eps: float = 0.01,
          progress: bool = False) -> Jaulin2001:
    """RCSE and NCSE on the measurement sets ``y`` (``(K, 1)``, or ``(..., K, 1)`` for boxes):
    NCSE continues from the RCSE's domains (:func:`boundest.estimation.rcse_ncse`)."""
    x0 = FRAME if domains == "subpavings" else None
    causal, smoothed = rcse_ncse(system(), y, x0=x0, domains=domains, eps=eps,
                                 progress=progress)
    return Jaulin2001(causal, smoothed, domains, eps)


def _areas(d: Interval | Subpaving) -> tuple[int, float, float]:
    if isinstance(d, Subpaving):
        return len(d), d.volume_outer(), d.volume_inner()
    # a box domain encloses the set; it proves no part of it inside
    return 1, float(d.volume()), 0.0


def to_json(res: Jaulin2001) -> dict:
    """Per k and estimator: interval hull, number of boxes, outer and inner areas.

    An empty set has NaN hull bounds, an unbounded one infinite bounds or area
    (``boundest.commands.jsonable`` writes them as ``null`` and ``"inf"``).
    """
    out: dict = {"domains": res.domains, "eps": res.eps,
                 "x0_prior": [[float(a), float(b)] for a, b in zip(FRAME.lo, FRAME.hi,
                                                                   strict=True)]
                 if res.domains == "subpavings" else None}
    for name, est in (("rcse", res.rcse), ("ncse", res.ncse)):
        hull = est.hull()
        rows = []
        for k, d in enumerate(est.x):
            n, outer, inner = _areas(d)
            rows.append({"k": k, "hull_lo": [float(v) for v in hull.lo[k]],
                         "hull_hi": [float(v) for v in hull.hi[k]], "boxes": n,
                         "area_outer": float(outer), "area_inner": float(inner)})
        out[name] = {"time_s": est.time_s, "stats": est.stats, "sets": rows}
    return out
