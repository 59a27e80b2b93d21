"""The satellite of Jaulin 2002 (equations 14-16, Remarks 2-3): state estimation as a CSP.

State ``x = (x1, x2, x3, x4)`` (position and velocity), Euler step ``delta = 0.5``::

    x1(k+1) = x1(k) + 0.5 x3(k) + w1(k)
    x2(k+1) = x2(k) + 0.5 x4(k) + w2(k)
    x3(k+1) = x3(k) - 0.5 x1(k) / sqrt(x1(k)^2 + x2(k)^2)^3 + w3(k)
    x4(k+1) = x4(k) - 0.5 x2(k) / sqrt(x1(k)^2 + x2(k)^2)^3 + w4(k)
    y1(k) = x2(k) / x1(k),  y2(k) = x1(k) x3(k) + x2(k) x4(k),  y3(k) = x1(k)^2 + x2(k)^2

with ``w(k) in [-0.01, 0.01]^4``, ``y(k)`` measured to +-0.1, and (Remark 2, identifiability)
``x1(0), x2(0), x4(0) >= 0``, ``x3(0) <= 0``. For ``k_max = 200``: 2215 variables, 1407
constraints. The CSP is decomposed into primitive constraints with shared sub-expressions
(``x1^2 + x2^2`` is computed once per step and shared by ``y3`` and the dynamics) and propagated
to a fixed point by the compiled queue (``boundest.csp.propagate``), then (by default) shaved:
3B consistency on the state variables, step by step (``mode="3b"``; ``mode="hc4"`` stops at
hull consistency). Hull consistency cannot tell the sign of ``x1`` where ``y1 = x2 / x1`` says
little and ``y3 = x1^2 + x2^2`` is symmetric (the steps around k = 91 of the embedded data);
a slice of ``x1`` propagated through the next steps' dynamics can.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..csp import propagate
from ..csp.beta import BetaResult, beta_tuning
from ..csp.propagate import Centered, Shaving
from ..expr import Model, VarFamily
from ..expr.functions import sqrt
from ..expr.tape import Tape, compile_model
from ..interval import Interval
from ._data import check_index, embedded, read_csv

__all__ = [
    "CENTERED",
    "DELTA",
    "MODES",
    "SHAVING",
    "SHAVING_CENTERED",
    "W_BOUND",
    "X0_TRUE",
    "Measurements",
    "SatelliteResult",
    "build_model",
    "load",
    "model_text",
    "simulate",
    "solve",
    "tune",
]

DELTA = 0.5
W_BOUND = 0.01
NOISE = 0.1
#: Initial state used by Jaulin 2002 to generate its data (Remark 2).
X0_TRUE = (4.0, 0.5, -0.2, 0.5)
#: Sign restrictions of Remark 2 on x(0).
X0_DOMAINS = ((0.0, np.inf), (0.0, np.inf), (-np.inf, 0.0), (0.0, np.inf))
#: The propagation modes of ``solve``, the default first: 3B shaving of the states after hull
#: consistency, then the centered form of windows of steps; 3B shaving alone; or hull
#: consistency alone (benchmarks/README.md has the table of widths and times).
MODES = ("3b+centered", "3b", "hc4")
#: Shaving settings of the ``3b`` mode (``boundest.csp.propagate.Shaving``).
SHAVING = Shaving()
#: Shaving settings of the ``3b+centered`` mode: one round of cheaper probes, since the
#: centered form then narrows the boxes further
SHAVING_CENTERED = Shaving(probe_evals=200, rounds=1)
#: Centered-form settings of the ``3b+centered`` mode: windows of 6 steps (42 constraints)
CENTERED = Centered(window=56, rounds=2)
#: CSV columns and their kinds: an output bound may be infinite (an output not measured at k)
_COLUMNS = {"k": "finite", **{f"y{i}_{s}": s for i in (1, 2, 3) for s in ("lo", "hi")}}


@dataclass
class Measurements:
    """Output intervals ``y_lo[k, i] <= y_i(k) <= y_hi[k, i]`` for ``k = 0..k_max``."""

    y_lo: np.ndarray
    y_hi: np.ndarray
    source: str = "<memory>"

    @property
    def k_max(self) -> int:
        return len(self.y_lo) - 1

    def __repr__(self) -> str:
        """The size and source, not the data (``y_lo``, ``y_hi`` hold them)."""
        return f"Measurements(k_max={self.k_max}, source={self.source!r})"


def load(path: str | Path | None = None, k_max: int | None = None) -> Measurements:
    """Read measurements (default: the embedded ``satellite_k200.csv`` or ``_k800`` file).

    Columns ``k, y1_lo, y1_hi, y2_lo, y2_hi, y3_lo, y3_hi`` (no others); ``k`` must run 0, 1,
    ..., without gaps or repeats; an output bound may be ``-inf``/``inf`` (that output is not
    measured at ``k``). ``k_max`` (if given) truncates the data and must not exceed what the
    file holds.
    """
    if path is None:
        path = embedded("satellite_k800.csv" if (k_max or 200) > 200 else "satellite_k200.csv")
    cols = read_csv(path, _COLUMNS)
    check_index(cols, "k", 0)
    k = cols["k"]
    y_lo = np.stack([cols[f"y{i}_lo"] for i in (1, 2, 3)], axis=1)
    y_hi = np.stack([cols[f"y{i}_hi"] for i in (1, 2, 3)], axis=1)
    if k_max is not None:
        if not 1 <= k_max <= len(k) - 1:
            raise cols.error(len(k) - 1, f"the file ends at k = {len(k) - 1}, but k_max = "
                                         f"{k_max} was asked")
        y_lo, y_hi = y_lo[: k_max + 1], y_hi[: k_max + 1]
    return Measurements(y_lo, y_hi, str(path))


def step(x: np.ndarray, w: np.ndarray) -> np.ndarray:
    """One step of equation 14 on float arrays ``x[..., 4]``, ``w[..., 4]``."""
    x1, x2, x3, x4 = np.moveaxis(x, -1, 0)
    r3 = np.sqrt(x1**2 + x2**2) ** 3
    return np.stack([x1 + DELTA * x3, x2 + DELTA * x4, x3 - DELTA * x1 / r3,
                     x4 - DELTA * x2 / r3], axis=-1) + w


def outputs(x: np.ndarray) -> np.ndarray:
    """The outputs ``(y1, y2, y3)`` of equation 14."""
    x1, x2, x3, x4 = np.moveaxis(x, -1, 0)
    return np.stack([x2 / x1, x1 * x3 + x2 * x4, x1**2 + x2**2], axis=-1)


def simulate(k_max: int, x0: tuple[float, ...] = X0_TRUE, seed: int | None = 0,
             w_bound: float = W_BOUND, noise: float = NOISE
             ) -> tuple[np.ndarray, Measurements]:
    """Simulate equation 14 with uniform perturbations and output noise.

    Returns the true states ``x[k]`` for ``k = 0..k_max+1`` and measurement intervals of
    half-width ``noise`` around the noisy outputs (each interval contains the true output).
    The perturbations are drawn in ``[-0.99, 0.99] w_bound`` so that rounding in this float
    simulation cannot push the truth out of the model's ``[-w_bound, w_bound]``.
    """
    rng = np.random.default_rng(seed)
    x = np.empty((k_max + 2, 4))
    x[0] = x0
    w = rng.uniform(-0.99 * w_bound, 0.99 * w_bound, size=(k_max + 1, 4))
    for k in range(k_max + 1):  # a simulator: sequential by nature, not a hot path
        x[k + 1] = step(x[k], w[k])
    y = outputs(x[: k_max + 1])
    meas = y + rng.uniform(-0.99 * noise, 0.99 * noise, size=y.shape)
    return x, Measurements(meas - noise, meas + noise, "<simulated>")


def _scaled_outputs(meas: Measurements, beta: float) -> tuple[np.ndarray, np.ndarray]:
    """Output intervals ``mid + beta ([y] - mid)``, rounded outward (beta >= 1 keeps the data).

    An interval with an infinite bound has no midpoint: it is kept as it is.
    """
    bounded = np.isfinite(meas.y_lo) & np.isfinite(meas.y_hi)
    lo = np.where(bounded, meas.y_lo, 0.0)
    hi = np.where(bounded, meas.y_hi, 0.0)
    mid = 0.5 * (lo + hi)
    rad = 0.5 * (hi - lo)
    ylo = np.nextafter(mid - beta * rad, -np.inf)
    yhi = np.nextafter(mid + beta * rad, np.inf)
    if beta >= 1:
        ylo, yhi = np.minimum(ylo, lo), np.maximum(yhi, hi)
    return np.where(bounded, ylo, meas.y_lo), np.where(bounded, yhi, meas.y_hi)


def build_model(meas: Measurements, beta: float = 1.0, w_bound: float = W_BOUND) -> Model:
    """The CSP of equations 14-16, with perturbation and output intervals scaled by ``beta``
    (Jaulin 2002 section 5.2: ``[w] = beta [w]``, ``[y] = mid + beta ([y] - mid)``)."""
    if beta <= 0:
        raise ValueError(f"beta must be positive, got {beta}")
    K = meas.k_max
    x = [VarFamily(f"x{i}") for i in (1, 2, 3, 4)]
    w = [VarFamily(f"w{i}") for i in (1, 2, 3, 4)]
    y = [VarFamily(f"y{i}") for i in (1, 2, 3)]
    ylo, yhi = _scaled_outputs(meas, beta)
    m = Model()
    for i in range(4):
        m.declare(x[i][0], X0_DOMAINS[i])
    wb = w_bound * beta
    for k in range(K + 1):
        for i in range(4):
            m.declare(w[i][k], (-wb, wb))
        for i in range(3):
            m.declare(y[i][k], (float(ylo[k, i]), float(yhi[k, i])))
    for k in range(K + 1):
        x1, x2, x3, x4 = (xi[k] for xi in x)
        r2 = x1**2 + x2**2
        r3 = sqrt(r2) ** 3
        m.add(x[0][k + 1] == x1 + DELTA * x3 + w[0][k],
              x[1][k + 1] == x2 + DELTA * x4 + w[1][k],
              x[2][k + 1] == x3 - DELTA * x1 / r3 + w[2][k],
              x[3][k + 1] == x4 - DELTA * x2 / r3 + w[3][k],
              y[0][k] == x2 / x1,
              y[1][k] == x1 * x3 + x2 * x4,
              y[2][k] == r2)
    return m


def _domain_text(lo: float, hi: float) -> str:
    """A domain in the model text format: ``[lo, hi]``, ``]-oo, hi]``, ``[lo, +oo[``."""
    a = "]-oo" if lo == -np.inf else f"[{float(lo)!r}"
    b = "+oo[" if hi == np.inf else f"{float(hi)!r}]"
    return f"{a}, {b}"


def model_text(meas: Measurements) -> str:
    """The same CSP in the model text format (RealPaver-like, Jaulin 2002 section 4)."""
    K = meas.k_max
    lines = ["// Satellite of Jaulin 2002 (equations 14-16), written by boundest", "Variables"]
    decl = []
    names = ("x1_0", "x2_0", "x3_0", "x4_0")
    doms = ("[0, +oo[", "[0, +oo[", "]-oo, 0]", "[0, +oo[")
    decl += [f"  {n} in {d}" for n, d in zip(names, doms, strict=True)]
    for k in range(K + 1):
        decl += [f"  w{i}_{k} in [-{W_BOUND!r}, {W_BOUND!r}]" for i in (1, 2, 3, 4)]
        for i in (1, 2, 3):
            decl.append(f"  y{i}_{k} in {_domain_text(meas.y_lo[k, i - 1], meas.y_hi[k, i - 1])}")
        decl += [f"  x{i}_{k + 1} in ]-oo, +oo[" for i in (1, 2, 3, 4)]
    lines.append(",\n".join(decl) + ";")
    lines.append("Constraints")
    cons = []
    for k in range(K + 1):
        n = k + 1
        r3 = f"(sqrt(x1_{k}^2+x2_{k}^2))^3"
        cons += [f"  x1_{n} = x1_{k} + 0.5*x3_{k} + w1_{k}",
                 f"  x2_{n} = x2_{k} + 0.5*x4_{k} + w2_{k}",
                 f"  x3_{n} = x3_{k} - 0.5*x1_{k}/{r3} + w3_{k}",
                 f"  x4_{n} = x4_{k} - 0.5*x2_{k}/{r3} + w4_{k}",
                 f"  y1_{k} = x2_{k}/x1_{k}",
                 f"  y2_{k} = x1_{k}*x3_{k} + x2_{k}*x4_{k}",
                 f"  y3_{k} = x1_{k}^2 + x2_{k}^2"]
    lines.append(",\n".join(cons) + ";")
    return "\n".join(lines) + "\n"


@dataclass
class SatelliteResult:
    """Enclosures of the states, ``x_lo[k], x_hi[k]`` for ``k = 0..k_max+1``."""

    k_max: int
    consistent: bool
    iterations: float
    evaluations: int
    time_s: float
    x_lo: np.ndarray
    x_hi: np.ndarray
    beta: float = 1.0
    mode: str = "hc4"
    shaving: dict | None = None
    centered: dict | None = None

    def to_json(self) -> dict:
        """The fields of ``boundest run satellite --json`` (floats may be infinite or NaN:
        ``boundest.commands.jsonable`` writes them)."""
        def rows(a: np.ndarray) -> list:
            return np.asarray(a, dtype=float).tolist()

        return {"scenario": "satellite", "k_max": self.k_max, "consistent": self.consistent,
                "iterations": self.iterations, "evaluations": self.evaluations,
                "time_s": self.time_s, "beta": self.beta, "mode": self.mode,
                "shaving": self.shaving or {}, "centered": self.centered or {},
                "k": list(range(self.k_max + 2)), "x_lo": rows(self.x_lo),
                "x_hi": rows(self.x_hi)}

    def box(self, k: int) -> Interval:
        return Interval.trusted(self.x_lo[k], self.x_hi[k])

    def __repr__(self) -> str:
        """Counts and mean widths, not the enclosures (``x_lo``, ``x_hi`` hold them)."""
        with np.errstate(invalid="ignore"):
            w = np.nanmean(self.x_hi - self.x_lo, axis=0) if self.consistent else []
        widths = ", ".join(f"{v:.3g}" for v in w)
        return (f"SatelliteResult(k_max={self.k_max}, consistent={self.consistent}, "
                f"beta={self.beta:g}, mode={self.mode!r}, evaluations={self.evaluations}, "
                f"time_s={self.time_s:.3g}, mean_widths=[{widths}])")


def _state_names(K: int) -> list[list[str]]:
    return [[f"x{i}_{k}" for i in (1, 2, 3, 4)] for k in range(K + 2)]


def _result(tape: Tape, prop, K: int, beta: float) -> SatelliteResult:
    slots = np.array(_state_names(K), dtype=object)
    idx = np.vectorize(tape.slot_of.__getitem__)(slots).astype(np.intp)
    settings = SHAVING_CENTERED if prop.mode == "3b+centered" else SHAVING
    shaving = ({"settings": vars(settings).copy(), **prop.shaving} if prop.shaving else None)
    return SatelliteResult(K, prop.consistent, prop.iterations, prop.evaluations, prop.time_s,
                           prop.slots.lo[idx], prop.slots.hi[idx], beta, prop.mode, shaving,
                           prop.centered or None)


def solve(meas: Measurements, rel_eps: float = 1e-3, progress: bool | None = None,
          mode: str = "3b+centered") -> SatelliteResult:
    """Propagate the satellite CSP to its fixed point (``time_s``: propagation only).

    ``mode="3b+centered"`` (default) shaves the states ``x1..x4`` of every step, in time
    order, after hull consistency (``SHAVING_CENTERED``), then contracts them with the
    centered form of windows of eight steps (``CENTERED``: the linearised constraints of a window
    aggregated with optimal multipliers, which keeps what the measurements of the neighbouring
    steps say together); ``mode="3b"`` shaves harder (``SHAVING``) and stops there;
    ``mode="hc4"`` is hull consistency alone.
    """
    _check_mode(mode)
    tape = compile_model(build_model(meas))
    return _result(tape, _propagate(tape, meas.k_max, rel_eps, mode, progress), meas.k_max, 1.0)


def _check_mode(mode: str) -> None:
    if mode not in MODES:
        raise ValueError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")


def _propagate(tape: Tape, K: int, rel_eps: float, mode: str, progress: bool | None = False):
    """The propagation of :func:`solve` in ``mode`` (the states shaved and centered)."""
    names = [v for row in _state_names(K) for v in row]
    return propagate(tape, rel_eps=rel_eps, progress=progress, mode=mode, shave=names,
                     shaving=SHAVING_CENTERED if mode == "3b+centered" else SHAVING,
                     targets=names, centered=CENTERED)


def tune(meas: Measurements, beta_max: float = 16.0, tol: float = 1e-3, rel_eps: float = 1e-3,
         mode: str = "hc4") -> tuple[BetaResult, SatelliteResult]:
    """Beta-tuning (Jaulin 2002 section 5.2): the smallest ``beta`` in ``]0, beta_max]`` for which
    the CSP contracted in ``mode`` (as :func:`solve`) is not empty, and the domains at that
    ``beta``.

    The bisection runs with hull consistency (``"hc4"``), the cheapest mode. Every other mode
    starts with hull consistency and contracts further, so a ``beta`` at which hull consistency
    proves the CSP empty is one at which ``mode`` does too: with another ``mode``, the CSP is
    then propagated in ``mode`` at the ``beta`` found, and when ``mode`` proves it empty there,
    the bisection goes on in ``mode`` above it. ``BetaResult.trials`` holds every propagation
    of both searches; the domains returned are ``mode``'s.
    """
    _check_mode(mode)
    K = meas.k_max
    tape = compile_model(build_model(meas, beta=beta_max))
    w_slots = np.array([tape.slot_of[f"w{i}_{k}"] for k in range(K + 1) for i in (1, 2, 3, 4)])
    y_slots = np.array([tape.slot_of[f"y{i}_{k}"] for k in range(K + 1) for i in (1, 2, 3)])

    def at(beta: float) -> Tape:
        """The tape with the perturbation and output domains scaled by ``beta``."""
        lo, hi = tape.lo.copy(), tape.hi.copy()
        lo[w_slots] = np.maximum(lo[w_slots], -W_BOUND * beta)
        hi[w_slots] = np.minimum(hi[w_slots], W_BOUND * beta)
        ylo, yhi = _scaled_outputs(meas, beta)
        lo[y_slots] = np.maximum(lo[y_slots], ylo.ravel())
        hi[y_slots] = np.minimum(hi[y_slots], yhi.ravel())
        return replace(tape, lo=lo, hi=hi)

    t0 = time.perf_counter()
    res = beta_tuning(lambda b: propagate(at(b), rel_eps=rel_eps, mode="hc4"),
                      beta_max=beta_max, tol=tol)
    if mode != "hc4":
        first = _propagate(at(res.beta), K, rel_eps, mode)
        trials = [*res.trials, (res.beta, first.consistent)]
        if first.consistent:
            res = BetaResult(res.beta, first, trials)
        else:
            more = beta_tuning(lambda b: _propagate(at(b), K, rel_eps, mode),
                               beta_max=beta_max, tol=tol, beta_min=res.beta)
            res = BetaResult(more.beta, more.propagation, trials + more.trials)
    res.time_s = time.perf_counter() - t0
    return res, _result(tape, res.propagation, K, res.beta)


