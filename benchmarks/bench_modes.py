"""Which propagation mode by default: width against time of every mode of
``boundest.csp.propagate`` over a set of problems.

Problems (each a CSP run through ``propagate``, the model compiled once outside the timing):

* small nonlinear chains, discretised and simulated (so the truth is known): a pendulum
  (explicit Euler, measuring ``sin(theta)``; the same with the midpoint (RK2) step written
  with auxiliary variables for the half step; Euler measuring ``theta``), Van der Pol (Euler,
  measuring ``x1``) and Lotka-Volterra (Euler measuring the prey; midpoint measuring the
  product ``x y``), with bounded process noise and interval measurements;
* the satellite of Jaulin 2002 (``satellite.build_model(satellite.load())``, k_max = 200, the
  embedded data), and its text form ``boundest/data/satellite_k200.txt`` read by
  ``parse_model`` (what ``boundest solve`` propagates);
* the CSPs of the documentation: the model of ``docs/model-format.md`` (the satellite's first
  step), the cart of ``docs/tutorials/first-estimate.md`` (Python and text), the smoother of
  ``docs/tutorials/kalman-to-sets.md`` and the chain of the README.

Variants: every mode with its default settings (``shave``/``targets`` = every variable: what a
user who reads nothing gets), and a few settings (``Centered(window=...)``, cheaper shaving,
``targets`` restricted to the states or to the variables that occur in two constraints or more,
the satellite scenario's own settings).

Per problem and variant: the mean width of each state family over the steps (and the widest
state), the median propagation time of ``--repeat`` warm runs (``Propagation.time_s``; the
variants of a problem take turns, one run each per round), the
ratio of the width to the best of the seven modes at their default settings on that problem
(the worst over the state families),
the ratio of the time to ``hc4``'s in the same run, and whether the truth lies in every state's
domain (the problem's own data, and ``--seeds`` more simulated data sets, one run each; the
satellite on ``satellite.simulate(200, seed)``). ``--compile`` adds the Numba compile time a
user pays on the first use of each mode (a fresh ``NUMBA_CACHE_DIR`` per mode,
``BOUNDEST_KERNEL_ARCHIVE=0``, one subprocess each).

Usage (the table without ``lp``: about 12 min on a loaded 2-core machine; ``lp``: 15 min more,
``--compile``: 10 min more; parts merge into the JSON with ``--update``; ``--report`` prints
the tables of benchmarks/README.md section 16 from the JSON)::

    flock /tmp/bench.lock .venv/bin/python benchmarks/bench_modes.py \\
        --out benchmarks/results/modes.json [--problems REGEX] [--variants REGEX] \\
        [--repeat 5] [--seeds 1,2] [--update] [--compile] [--scaling] [--report]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass, field, is_dataclass
from pathlib import Path

import numpy as np
from _machine import cpu_model, emit

ROOT = Path(__file__).resolve().parent.parent
#: a width ratio is ``(w + TINY) / (best + TINY)``: degenerate domains do not divide by zero
TINY = 1e-12
#: "within 1.5x of the best mode's widths on each problem" (the issue's criterion)
TARGET_RATIO = 1.5


@dataclass
class Problem:
    """A CSP with the names of its states (by family, for the widths), their truth when known,
    and a builder of more simulated data sets (seed -> (model, truth)) for soundness."""

    name: str
    group: str
    model: object
    states: dict[str, list[str]]
    truth: dict[str, float] | None = None
    resimulate: object = None
    note: str = ""
    extra: dict = field(default_factory=dict)


# --- small nonlinear chains -----------------------------------------------------------------

def _chain(step, x0, doms, w_bound, measure, meas_half, K, dt, seed, aux=None,
           measurements_last=False):
    """Simulate ``x[k+1] = step(x[k]) + w[k]`` (``|w| <= 0.99 w_bound``, so that the float
    simulation stays inside the model's ``[-w_bound, w_bound]``) and measure
    ``measure(x[k]) +- meas_half`` (the reading drawn within ``0.99 meas_half`` of the truth);
    the model writes the same step with expressions (``aux``: a step written with auxiliary
    variables for its half step). Returns ``(model, truth)``."""
    import boundest as bd
    from boundest.expr import Model, VarFamily

    rng = np.random.default_rng(seed)
    n = len(x0)
    x = np.empty((K + 1, n))
    x[0] = x0
    w = rng.uniform(-0.99, 0.99, size=(K, n)) * np.asarray(w_bound)
    for k in range(K):
        x[k + 1] = np.asarray(step(np, x[k], dt), dtype=float) + w[k]
    y = np.array([measure(np, x[k]) for k in range(K + 1)])
    y = y + rng.uniform(-0.99 * meas_half, 0.99 * meas_half, size=y.shape)
    names = [v for v, _ in doms]
    X = [VarFamily(v) for v in names]
    W = [VarFamily(f"w{i + 1}") for i in range(n)]
    m = Model()

    def reading(k):
        lo, hi = float(y[k] - meas_half), float(y[k] + meas_half)
        return measure(bd, [xi[k] for xi in X]).in_((lo, hi))

    for (_, dom), xi in zip(doms, X, strict=True):
        m.declare(xi[0], dom)
    for k in range(K):
        for i in range(n):
            m.declare(W[i][k], (-w_bound[i], w_bound[i]))
        xs = [xi[k] for xi in X]
        nxt = aux(bd, m, xs, k, dt) if aux else step(bd, xs, dt)
        m.add(*(X[i][k + 1] == nxt[i] + W[i][k] for i in range(n)))
        if not measurements_last:
            m.add(reading(k))
    for k in range(K + 1) if measurements_last else [K]:
        m.add(reading(k))
    truth = {f"{v}_{k}": float(x[k, i]) for i, v in enumerate(names) for k in range(K + 1)}
    return m, truth


def _pendulum_step(mod, x, dt, a=9.81):
    th, om = x[0], x[1]
    c = dt * a  # one float, the same in the simulation and the model
    return [th + dt * om, om - c * mod.sin(th)]


def _pendulum_midpoint_aux(bd, m, x, k, dt, a=9.81):
    """The midpoint step with the half step as variables ``thm_k``, ``omm_k`` (how one writes
    a Runge-Kutta step without repeating the state in it)."""
    from boundest.expr import Var

    th, om = x
    h, c, ch = dt / 2, dt * a, dt / 2 * a
    thm, omm = Var(f"thm_{k}"), Var(f"omm_{k}")
    m.add(thm == th + h * om, omm == om - ch * bd.sin(th))
    return [th + dt * omm, om - c * bd.sin(thm)]


def _vdp_step(_mod, x, dt, mu=1.0):
    x1, x2 = x[0], x[1]
    return [x1 + dt * x2, x2 + dt * (mu * (1 - x1 ** 2) * x2 - x1)]


def _lv_step(_mod, x, dt, a=1.0, b=0.5, c=1.0, d=0.25):
    p, q = x[0], x[1]
    return [p + dt * (a * p - b * p * q), q + dt * (d * p * q - c * q)]


def _lv_midpoint_aux(_bd, m, x, k, dt, a=1.0, b=0.5, c=1.0, d=0.25):
    from boundest.expr import Var

    p, q = x
    h = dt / 2
    pm, qm = Var(f"pm_{k}"), Var(f"qm_{k}")
    m.add(pm == p + h * (a * p - b * p * q), qm == q + h * (d * p * q - c * q))
    return [p + dt * (a * pm - b * pm * qm), q + dt * (d * pm * qm - c * qm)]


def _lv_midpoint_sim(_mod, x, dt, a=1.0, b=0.5, c=1.0, d=0.25):
    p, q = x[0], x[1]
    h = dt / 2
    pm, qm = p + h * (a * p - b * p * q), q + h * (d * p * q - c * q)
    return [p + dt * (a * pm - b * pm * qm), q + dt * (d * pm * qm - c * qm)]


def _pendulum_midpoint_sim(mod, x, dt, a=9.81):
    th, om = x[0], x[1]
    h, c, ch = dt / 2, dt * a, dt / 2 * a
    thm, omm = th + h * om, om - ch * mod.sin(th)
    return [th + dt * omm, om - c * mod.sin(thm)]


#: name -> (note, keyword arguments of ``_chain``)
CHAINS = {
    "pendulum_euler_sin": (
        "pendulum theta'' = -9.81 sin(theta), Euler dt = 0.05, 150 steps, |w| <= 1e-3, "
        "sin(theta) measured +-0.05; theta_0 in [-pi, pi], omega_0 in [-10, 10]",
        {"step": _pendulum_step, "x0": (0.8, 0.0),
         "doms": [("theta", (-math.pi, math.pi)), ("omega", (-10.0, 10.0))],
         "w_bound": (1e-3, 1e-3), "measure": lambda mod, x: mod.sin(x[0]), "meas_half": 0.05,
         "K": 150, "dt": 0.05}),
    "pendulum_rk2_sin": (
        "the same pendulum, midpoint (RK2) step with the half step as variables thm_k, omm_k",
        {"step": _pendulum_midpoint_sim, "aux": _pendulum_midpoint_aux, "x0": (0.8, 0.0),
         "doms": [("theta", (-math.pi, math.pi)), ("omega", (-10.0, 10.0))],
         "w_bound": (1e-3, 1e-3), "measure": lambda mod, x: mod.sin(x[0]), "meas_half": 0.05,
         "K": 150, "dt": 0.05}),
    "pendulum_euler_theta": (
        "the Euler pendulum, theta measured +-0.05 (instead of sin(theta))",
        {"step": _pendulum_step, "x0": (0.8, 0.0),
         "doms": [("theta", (-math.pi, math.pi)), ("omega", (-10.0, 10.0))],
         "w_bound": (1e-3, 1e-3), "measure": lambda _mod, x: x[0], "meas_half": 0.05,
         "K": 150, "dt": 0.05}),
    "vanderpol_euler": (
        "Van der Pol, mu = 1, Euler dt = 0.05, 150 steps, |w| <= 1e-3, x1 measured +-0.05; "
        "x_0 in [-5, 5]^2",
        {"step": _vdp_step, "x0": (2.0, 0.0), "doms": [("x1", (-5.0, 5.0)), ("x2", (-5.0, 5.0))],
         "w_bound": (1e-3, 1e-3), "measure": lambda _mod, x: x[0], "meas_half": 0.05,
         "K": 150, "dt": 0.05}),
    "lotka_volterra_euler": (
        "Lotka-Volterra p' = p - 0.5 p q, q' = 0.25 p q - q, Euler dt = 0.05, 200 steps, "
        "|w| <= 1e-3, the prey p measured +-0.1; p_0, q_0 in [0, 20]",
        {"step": _lv_step, "x0": (6.0, 1.0), "doms": [("p", (0.0, 20.0)), ("q", (0.0, 20.0))],
         "w_bound": (1e-3, 1e-3), "measure": lambda _mod, x: x[0], "meas_half": 0.1,
         "K": 200, "dt": 0.05}),
    "lotka_volterra_rk2": (
        "the same Lotka-Volterra, midpoint (RK2) step with the half step as variables pm_k, "
        "qm_k, the prey measured +-0.1",
        {"step": _lv_midpoint_sim, "aux": _lv_midpoint_aux, "x0": (6.0, 1.0),
         "doms": [("p", (0.0, 20.0)), ("q", (0.0, 20.0))],
         "w_bound": (1e-3, 1e-3), "measure": lambda _mod, x: x[0], "meas_half": 0.1,
         "K": 200, "dt": 0.05}),
    "lotka_volterra_euler_product": (
        "the Euler Lotka-Volterra, the product p q measured +-0.2 (instead of the prey)",
        {"step": _lv_step, "x0": (6.0, 1.0), "doms": [("p", (0.0, 20.0)), ("q", (0.0, 20.0))],
         "w_bound": (1e-3, 1e-3), "measure": lambda _mod, x: x[0] * x[1], "meas_half": 0.2,
         "K": 200, "dt": 0.05}),
}


for _name in ("pendulum_euler_sin", "pendulum_rk2_sin"):
    _note, _kw = CHAINS[_name]
    CHAINS[f"{_name} (readings last)"] = (
        f"{_name}, the readings added after all the steps (the same CSP, constraints in "
        "another order)", {**_kw, "measurements_last": True})


def _chain_problem(name: str, seed: int = 0) -> Problem:
    note, kw = CHAINS[name]
    model, truth = _chain(seed=seed, **kw)
    fams = [v for v, _ in kw["doms"]]
    states = {f: [f"{f}_{k}" for k in range(kw["K"] + 1)] for f in fams}
    return Problem(name, "chain", model, states, truth,
                   lambda s: _chain(seed=s, **kw), note,
                   {"K": kw["K"], "dt": kw["dt"], "seed": seed})


# --- the satellite ----------------------------------------------------------------------------

def _sat_states(K: int, last: int | None = None) -> dict[str, list[str]]:
    last = K if last is None else last
    return {f"x{i}": [f"x{i}_{k}" for k in range(last + 1)] for i in (1, 2, 3, 4)}


def _satellite() -> Problem:
    from boundest.scenarios import satellite as sat

    def resim(seed):
        truth, meas = sat.simulate(200, seed=seed)
        t = {f"x{i + 1}_{k}": float(truth[k, i]) for k in range(202) for i in range(4)}
        return sat.build_model(meas), t

    return Problem("satellite", "satellite", sat.build_model(sat.load()), _sat_states(200),
                   None, resim, "Jaulin 2002, k_max = 200, satellite_k200.csv (embedded); "
                   "soundness on satellite.simulate(200, seed)", {"K": 200})


def _satellite_k800() -> Problem:
    from boundest.scenarios import satellite as sat

    return Problem("satellite k800", "scaling", sat.build_model(sat.load(k_max=800)),
                   _sat_states(800), None, None,
                   "Jaulin 2002, k_max = 800, satellite_k800.csv (embedded): the cost per step "
                   "at four times the horizon", {"K": 800})


def _satellite_txt() -> Problem:
    import boundest as bd
    from boundest.scenarios._data import embedded

    path = embedded("satellite_k200.txt")
    model = bd.parse_model(Path(path).read_text(), source=str(path))
    return Problem("satellite_k200.txt", "model file", model, _sat_states(200), None, None,
                   "boundest/data/satellite_k200.txt through parse_model (boundest solve)",
                   {"K": 200})


# --- the CSPs of the documentation ------------------------------------------------------------

def _model_format() -> Problem:
    import boundest as bd

    page = (ROOT / "docs" / "model-format.md").read_text()
    text = re.search(r"```text\n(.*?)```", page, flags=re.S).group(1)
    model = bd.parse_model(text, source="model-format.md")
    names = model.variable_names()
    return Problem("model-format first step", "docs", model, {v: [v] for v in names}, None,
                   None, "docs/model-format.md: the satellite's first step (7 variables)")


def _first_estimate(seed: int = 1) -> tuple[object, dict[str, float]]:
    """docs/tutorials/first-estimate.md, its data and model as written there."""
    import boundest as bd
    from boundest.expr import Model, VarFamily

    rng = np.random.default_rng(seed)
    K, dt = 60, 0.1
    v_true = 1.0 + 0.5 * np.sin(0.15 * np.arange(K))
    x_true = np.concatenate([[2.0], 2.0 + np.cumsum(v_true * dt)])
    V = bd.Interval(v_true + rng.uniform(-0.05, 0.05, K)) + bd.Interval(-0.05, 0.05)
    gps_k = np.arange(0, K + 1, 10)
    y_m = x_true[gps_k] + rng.uniform(-0.5, 0.5, gps_k.size)
    Y = bd.Interval(y_m) + bd.Interval(-0.5, 0.5)
    x, v = VarFamily("x"), VarFamily("v")
    m = Model()
    for k in range(K):
        m.declare(v[k], V[k])
        m.add(x[k + 1] == x[k] + dt * v[k])
    for i, k in enumerate(gps_k):
        m.declare(x[k], Y[i])
    return m, {f"x_{k}": float(x_true[k]) for k in range(K + 1)}


def _first_estimate_problem() -> Problem:
    m, truth = _first_estimate()
    return Problem("tutorial first-estimate", "docs", m,
                   {"x": [f"x_{k}" for k in range(61)]}, truth, None,
                   "docs/tutorials/first-estimate.md: a cart, 60 steps (linear chain); the "
                   "truth is the tutorial's simulation (its cumulative sum in floats: checked, "
                   "not guaranteed to the last ulp)")


def _first_estimate_text() -> Problem:
    import boundest as bd

    text = """
Variables
  x0 in [1.5, 2.5], v0 in [0.95, 1.05], v1 in [0.95, 1.05],
  x1 in ]-oo, +oo[, x2 in ]-oo, +oo[;
Constraints
  x1 = x0 + 0.1 * v0,
  x2 = x1 + 0.1 * v1;
"""
    model = bd.parse_model(text)
    return Problem("tutorial first-estimate (text)", "docs", model,
                   {v: [v] for v in ("x0", "x1", "x2")}, None, None,
                   "docs/tutorials/first-estimate.md: the model text example (2 steps)")


def _kalman_smoother() -> Problem:
    """docs/tutorials/kalman-to-sets.md: the smoother, its data as written there."""
    import boundest as bd
    from boundest.expr import Model, VarFamily

    rng = np.random.default_rng(4)
    K, dt, du, dy = 100, 0.1, 0.1, 0.5
    u_true = 1.0 + 0.4 * np.sin(0.1 * np.arange(K))
    x_true = np.concatenate([[0.0], np.cumsum(u_true * dt)])
    u_meas = u_true + rng.uniform(-du, du, K)
    meas_k = np.arange(5, K + 1, 5)
    y_meas = x_true[meas_k] + rng.uniform(0.2, 0.5, meas_k.size)
    U = bd.Interval(u_meas) + bd.Interval(-du, du)
    Y = bd.Interval(y_meas) + bd.Interval(-dy, dy)
    x, u = VarFamily("x"), VarFamily("u")
    m = Model()
    m.declare(x[0], (-3.0, 3.0))
    for k in range(K):
        m.declare(u[k], U[k])
        m.add(x[k + 1] == x[k] + dt * u[k])
    for i, k in enumerate(meas_k):
        m.declare(x[int(k)], Y[i])
    truth = {f"x_{k}": float(x_true[k]) for k in range(K + 1)}
    return Problem("tutorial kalman-to-sets", "docs", m, {"x": [f"x_{k}" for k in range(K + 1)]},
                   truth, None, "docs/tutorials/kalman-to-sets.md: the smoother, 100 steps "
                   "(linear chain); truth as in first-estimate")


def _readme_chain() -> Problem:
    from boundest.expr import Model, VarFamily

    x, w = VarFamily("x"), VarFamily("w")
    m = Model()
    m.declare(x[0], (0, 1))
    for k in range(100):
        m.declare(w[k], (-0.01, 0.01))
        m.add(x[k + 1] == 0.9 * x[k] + w[k])
    return Problem("README chain", "docs", m, {"x": [f"x_{k}" for k in range(101)]}, None, None,
                   "README.md 'Constraints and propagation': x[k+1] = 0.9 x[k] + w[k]")


def problems() -> list[tuple[str, object]]:
    """``(name, builder)`` in the order of the table."""
    return ([(n, (lambda n=n: _chain_problem(n))) for n in CHAINS]
            + [("satellite", _satellite), ("satellite_k200.txt", _satellite_txt),
               ("model-format first step", _model_format),
               ("tutorial first-estimate", _first_estimate_problem),
               ("tutorial first-estimate (text)", _first_estimate_text),
               ("tutorial kalman-to-sets", _kalman_smoother),
               ("README chain", _readme_chain)])


#: problems run with ``--scaling`` only (kept out of the table and the summary)
SCALING = [("satellite k800", _satellite_k800)]


# --- the variants -----------------------------------------------------------------------------

def multi_occurrence(model) -> list[str]:
    """The variables that occur in two constraints or more, in the model's order (a candidate
    default for ``targets``: it leaves out the noise and output variables of one constraint)."""
    from boundest.expr.function_tape import constraint_functions

    ftape, _ = constraint_functions(model)
    rows = np.repeat(np.arange(ftape.n_outputs), np.diff(ftape.row_ptr))
    pairs = np.unique(np.stack([ftape.cols, rows]), axis=1)
    count = np.bincount(pairs[0], minlength=ftape.n_vars)
    return [v for j, v in enumerate(ftape.names) if count[j] >= 2]


def _targets(p: Problem, which: str) -> list[str]:
    if which == "states":
        if p.group in ("satellite", "model file"):
            return [v for k in range(p.extra["K"] + 2) for v in
                    (f"x{i}_{k}" for i in (1, 2, 3, 4))]
        return [v for names in zip(*p.states.values(), strict=True) for v in names]
    if which == "multi":
        return p.extra.setdefault("_multi", multi_occurrence(p.model))
    raise ValueError(which)


def variants() -> list[tuple[str, str, object]]:
    """``(label, mode, problem -> keyword arguments of propagate)``: the modes with their
    defaults first."""
    from boundest.csp import Centered, Shaving
    from boundest.scenarios import satellite as sat

    def fixed(**kw):
        return lambda _p: kw

    def on_shave(which, **kw):
        return lambda p: {**kw, "targets": _targets(p, which), "shave": _targets(p, which)}

    def on_targets(which, **kw):
        return lambda p: {**kw, "targets": _targets(p, which)}

    return [
        ("hc4", "hc4", fixed()),
        ("bc", "bc", fixed()),
        ("3b", "3b", fixed()),
        ("bc+3b", "bc+3b", fixed()),
        ("lp", "lp", fixed()),
        ("centered", "centered", fixed()),
        ("3b+centered", "3b+centered", fixed()),
        ("centered window=14", "centered", fixed(centered=Centered(window=14))),
        ("centered window=28", "centered", fixed(centered=Centered(window=28))),
        ("centered window=84", "centered", fixed(centered=Centered(window=84))),
        ("centered rounds=4", "centered", fixed(centered=Centered(rounds=4))),
        ("centered targets=states", "centered", on_targets("states")),
        ("centered targets=multi", "centered", on_targets("multi")),
        ("3b probe_evals=200 rounds=1", "3b", fixed(shaving=Shaving(probe_evals=200, rounds=1))),
        ("3b+centered probe_evals=200 rounds=1", "3b+centered",
         fixed(shaving=Shaving(probe_evals=200, rounds=1))),
        ("3b+centered multi, probe_evals=200 rounds=1", "3b+centered",
         on_shave("multi", shaving=Shaving(probe_evals=200, rounds=1))),
        ("3b+centered rounds=1", "3b+centered", fixed(shaving=Shaving(rounds=1))),
        ("3b+centered multi", "3b+centered", on_shave("multi")),
        ("3b+centered multi, rounds=1", "3b+centered",
         on_shave("multi", shaving=Shaving(rounds=1))),
        ("3b+centered window=84", "3b+centered", fixed(centered=Centered(window=84))),
        ("3b states (satellite 3b)", "3b", on_shave("states", shaving=sat.SHAVING)),
        ("3b+centered states (satellite default)", "3b+centered",
         on_shave("states", shaving=sat.SHAVING_CENTERED, centered=sat.CENTERED)),
    ]


#: variants whose run takes seconds to minutes on the satellite: timed once, no warm-up
SLOW = {"lp"}


# --- measuring --------------------------------------------------------------------------------

def _settings(kw: dict) -> dict:
    out = {}
    for k, v in kw.items():
        if is_dataclass(v):
            out[k] = asdict(v)
        elif isinstance(v, list):
            out[k] = f"{len(v)} variables"
        else:
            out[k] = v
    return out


def _widths(res, p: Problem) -> dict:
    fams = {}
    for fam, names in p.states.items():
        w = np.array([float(res.domains[v].hi) - float(res.domains[v].lo) for v in names])
        fams[fam] = {"mean": float(np.mean(w)), "max": float(np.max(w))}
    return fams


def _inside(res, truth: dict[str, float] | None) -> bool | None:
    if truth is None:
        return None
    if not res.consistent:
        return False
    return all(float(res.domains[v].lo) <= t <= float(res.domains[v].hi)
               for v, t in truth.items())


def _outside(res, truth: dict[str, float]) -> list[str]:
    return [f"{v}: {t!r} not in [{float(res.domains[v].lo)!r}, {float(res.domains[v].hi)!r}]"
            for v, t in truth.items()
            if not float(res.domains[v].lo) <= t <= float(res.domains[v].hi)][:5]


def _counters(res) -> dict:
    out = {}
    for key in ("shaving", "boxcons", "linear", "centered"):
        d = getattr(res, key)
        if d:
            out[key] = {k: v for k, v in d.items() if k not in ("widths",)}
            if "widths" in d:
                out[key]["target_widths"] = [round(x, 6) for x in d["widths"]]
    return out


def measure(p: Problem, runs: list[tuple[str, str, dict]], repeat: int, seeds: list[int],
            slow_seeds: bool = False) -> list[dict]:
    """The variants ``runs`` (label, mode, keyword arguments) on one problem: a warm-up of
    each, then ``repeat`` rounds in which every variant runs once (round robin, so that a
    change of the machine's load falls on every variant alike; the slow ones run in the first
    round only), on the problem's compiled tape; then one run per seed of re-simulated data
    (soundness; the slow variants only with ``slow_seeds``)."""
    from boundest.csp import propagate
    from boundest.expr.tape import compile_model

    tape = p.extra.get("_tape")
    if tape is None:
        t0 = time.perf_counter()
        tape = p.extra["_tape"] = compile_model(p.model)
        p.extra["compile_model_s"] = time.perf_counter() - t0
    for label, mode, kw in runs:
        if label not in SLOW:
            propagate(tape, mode=mode, progress=False, **kw)
    times: dict[str, list[float]] = {label: [] for label, _, _ in runs}
    walls: dict[str, list[float]] = {label: [] for label, _, _ in runs}
    last = {}
    for rep in range(repeat):
        for label, mode, kw in runs:
            if label in SLOW and rep > 0:
                continue
            t0 = time.perf_counter()
            last[label] = propagate(tape, mode=mode, progress=False, **kw)
            walls[label].append(time.perf_counter() - t0)
            times[label].append(last[label].time_s)
    rows = []
    for label, mode, kw in runs:
        res = last[label]
        fams = _widths(res, p)
        row = {"problem": p.name, "variant": label, "mode": mode, "settings": _settings(kw),
               "time_s": statistics.median(times[label]), "times_s": times[label],
               "wall_s": statistics.median(walls[label]), "consistent": res.consistent,
               "widths": fams,
               "mean_width_states": float(np.mean([f["mean"] for f in fams.values()])),
               "max_width_states": float(np.max([f["max"] for f in fams.values()])),
               "evaluations": res.evaluations, "counters": _counters(res),
               "truth_inside": _inside(res, p.truth)}
        if p.truth is not None and not row["truth_inside"]:
            row["outside"] = _outside(res, p.truth)
        sound = {}
        if p.resimulate is not None and (label not in SLOW or slow_seeds):
            for s in seeds:
                model, truth = p.resimulate(s)
                r = propagate(compile_model(model), mode=mode, progress=False,
                              **_rebind(kw, p, model))
                sound[str(s)] = _inside(r, truth)
                if not sound[str(s)]:
                    row.setdefault("outside_seeds", {})[str(s)] = (
                        _outside(r, truth) if r.consistent else ["proven inconsistent"])
        row["truth_inside_seeds"] = sound
        rows.append(row)
        print(f"{p.name} | {label}: {row['time_s']:.4f} s, mean width "
              f"{row['mean_width_states']:.4g}, max {row['max_width_states']:.4g}, "
              f"truth {row['truth_inside']} {row['truth_inside_seeds']}",
              file=sys.stderr, flush=True)
    return rows


def _rebind(kw: dict, p: Problem, model) -> dict:
    """The keyword arguments for another data set of the same problem: the variable lists are
    the same names (the multi-occurrence list is recomputed on the new model)."""
    out = dict(kw)
    if "targets" in kw and kw["targets"] is p.extra.get("_multi"):
        t = multi_occurrence(model)
        out["targets"] = t
        if "shave" in kw:
            out["shave"] = t
    return out


def _ratio(w: float, best: float) -> float:
    if w == best:
        return 1.0
    if not math.isfinite(best):
        return 1.0 if not math.isfinite(w) else 0.0
    return (w + TINY) / (best + TINY)


def annotate(rows: list[dict], modes: tuple[str, ...]) -> None:
    """Ratios to the best width and to hc4's time, per problem (in place): ``width_ratio`` to
    the best of the modes with their default settings (the issue's "best mode"),
    ``width_ratio_any`` to the best of every variant measured."""
    for prob in {r["problem"] for r in rows}:
        rs = [r for r in rows if r["problem"] == prob and r["consistent"]]
        fams = list(rs[0]["widths"])
        ref = [r for r in rs if r["variant"] in modes] or rs
        best = {f: min(r["widths"][f]["mean"] for r in ref) for f in fams}
        best_any = {f: min(r["widths"][f]["mean"] for r in rs) for f in fams}
        hc4 = next((r for r in rs if r["variant"] == "hc4"), None)
        for r in rs:
            per = {f: _ratio(r["widths"][f]["mean"], best[f]) for f in fams}
            r["width_ratio_per_family"] = per
            r["width_ratio"] = max(per.values())
            r["width_ratio_any"] = max(_ratio(r["widths"][f]["mean"], best_any[f])
                                       for f in fams)
            r["best_mode_per_family"] = {
                f: min(ref, key=lambda q, f=f: q["widths"][f]["mean"])["variant"] for f in fams}
            r["best_variant_per_family"] = {
                f: min(rs, key=lambda q, f=f: q["widths"][f]["mean"])["variant"] for f in fams}
            r["time_ratio_hc4"] = (r["time_s"] / hc4["time_s"] if hc4 and hc4["time_s"] > 0
                                   else None)
            r["wall_ratio_hc4"] = r["wall_s"] / hc4["wall_s"] if hc4 else None


def summarize(rows: list[dict]) -> dict:
    """Per variant: the worst width ratio (and where), the time ratios to hc4, soundness; the
    variants within TARGET_RATIO of the best on every problem, cheapest first."""
    probs = list(dict.fromkeys(r["problem"] for r in rows))
    out = {}
    for label in dict.fromkeys(r["variant"] for r in rows):
        rs = {r["problem"]: r for r in rows if r["variant"] == label}
        ratios = {p: rs[p].get("width_ratio", math.inf) for p in probs if p in rs}
        tr = [rs[p]["time_ratio_hc4"] for p in rs if rs[p].get("time_ratio_hc4")]
        sound = [v for r in rs.values() for v in
                 [r["truth_inside"], *r["truth_inside_seeds"].values()] if v is not None]
        worst = max(ratios, key=ratios.get) if ratios else None
        out[label] = {
            "problems": len(rs), "missing": [p for p in probs if p not in rs],
            "worst_width_ratio": ratios[worst] if worst else None, "worst_problem": worst,
            "problems_over_target": [p for p, v in ratios.items() if v > TARGET_RATIO],
            "time_ratio_hc4_geomean": (float(np.exp(np.mean(np.log(tr)))) if tr else None),
            "time_ratio_hc4_max": max(tr) if tr else None,
            "total_time_s": float(sum(r["time_s"] for r in rs.values())),
            "truth_checks": len(sound), "truth_always_inside": all(sound)}
    meets = sorted((k for k, v in out.items() if not v["problems_over_target"]
                    and not v["missing"]),
                   key=lambda k: out[k]["total_time_s"])
    return {"per_variant": out, "within_target_on_every_problem": meets,
            "target_ratio": TARGET_RATIO}


# --- compile times ----------------------------------------------------------------------------

_CHILD = """
import json, sys, time
t0 = time.perf_counter()
sys.path.insert(0, {bench!r})
import boundest  # noqa
from boundest.csp import propagate
from boundest.expr.tape import compile_model
import bench_modes as bm
t1 = time.perf_counter()
p = bm._chain_problem({problem!r})
tape = compile_model(p.model)
t2 = time.perf_counter()
mode = {mode!r}
propagate(tape, mode=mode, progress=False)
t3 = time.perf_counter()
r = propagate(tape, mode=mode, progress=False)
t4 = time.perf_counter()
import boundest._kernels as kk
print(json.dumps({{"import_s": t1 - t0, "model_s": t2 - t1, "first_call_s": t3 - t2,
                  "second_call_s": t4 - t3, "kernel_archive": str(kk.STATUS)}}))
"""


def compile_times(modes: list[str], problem: str) -> dict:
    """Per mode, a fresh process with an empty NUMBA_CACHE_DIR and no kernel archive: the import
    of boundest, the first ``propagate(mode=...)`` on a small chain (compiling), a second call
    (warm); then a second fresh process on the filled cache (loading the kernels)."""
    out = {}
    for mode in modes:
        with tempfile.TemporaryDirectory(prefix="bench-modes-cache-") as tmp:
            env = dict(os.environ, NUMBA_CACHE_DIR=tmp, BOUNDEST_KERNEL_ARCHIVE="0")
            env.pop("NUMBA_CPU_NAME", None)
            env.pop("NUMBA_CPU_FEATURES", None)
            code = _CHILD.format(bench=str(Path(__file__).parent), problem=problem, mode=mode)
            rec = {}
            for phase in ("cold", "cached"):
                t0 = time.perf_counter()
                pr = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                                    text=True, check=False, timeout=1800)
                wall = time.perf_counter() - t0
                if pr.returncode != 0:
                    rec[phase] = {"error": pr.stderr[-1500:]}
                    continue
                d = json.loads(pr.stdout.strip().splitlines()[-1])
                d["process_wall_s"] = wall
                d["compile_s"] = d["first_call_s"] - d["second_call_s"]
                rec[phase] = d
                print(f"compile {mode} {phase}: first call {d['first_call_s']:.1f} s, "
                      f"import {d['import_s']:.1f} s", file=sys.stderr)
            out[mode] = rec
    return out


# --- output -----------------------------------------------------------------------------------

def markdown(rows: list[dict], labels: list[str]) -> str:
    """Problem x variant: width ratio to the best / time ratio to hc4, a mark where the truth
    fell outside."""
    probs = list(dict.fromkeys(r["problem"] for r in rows))
    by = {(r["problem"], r["variant"]): r for r in rows}
    head = "| problem | " + " | ".join(f"`{v}`" for v in labels) + " |"
    lines = [head, "|---" * (len(labels) + 1) + "|"]
    for p in probs:
        cells = []
        for v in labels:
            r = by.get((p, v))
            if r is None or "width_ratio" not in r:
                cells.append("-" if r is None else "inconsistent")
                continue
            sound = [x for x in [r["truth_inside"], *r["truth_inside_seeds"].values()]
                     if x is not None]
            mark = "" if all(sound) else " **UNSOUND**"
            wr = r["width_ratio"]
            ws = f"{wr:.2f}" if wr < 100 else ("inf" if not math.isfinite(wr) else f"{wr:.0f}")
            tr = r["time_ratio_hc4"]
            ts = "-" if tr is None else (f"{tr:.1f}" if tr < 100 else f"{tr:.0f}")
            cells.append(f"{ws} / {ts}{mark}")
        lines.append(f"| {p} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _floats(obj):
    """The JSON's ``"inf"``/``"-inf"`` strings back to floats (lists and dicts recursively)."""
    if isinstance(obj, dict):
        return {k: _floats(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_floats(v) for v in obj]
    return float(obj) if obj in ("inf", "-inf") else obj


def report(doc: dict, variants_re: str | None, problems_re: str | None) -> None:
    """The markdown tables of a JSON document: ratios (problem x variant), then absolute
    times and mean widths, then the summary per variant."""
    rows = [r for r in doc["rows"] if (variants_re is None or re.search(variants_re,
                                                                      r["variant"]))
            and (problems_re is None or re.search(problems_re, r["problem"]))]
    labels = list(dict.fromkeys(r["variant"] for r in rows))
    print(markdown(rows, labels))
    print()
    print("| problem | variant | time | mean widths (per state family) | widest |")
    print("|---|---|---|---|---|")
    for r in rows:
        ws = ", ".join(f"{f} {w['mean']:.4g}" for f, w in r["widths"].items())
        if len(r["widths"]) > 4:
            ws = f"{len(r['widths'])} variables, mean {r['mean_width_states']:.4g}"
        t = r["time_s"]
        ts = f"{1e3 * t:.1f} ms" if t < 1 else f"{t:.2f} s"
        print(f"| {r['problem']} | `{r['variant']}` | {ts} | {ws} | "
              f"{r['max_width_states']:.4g} |")
    print()
    summ = summarize(rows)
    print("| variant | worst width ratio (problem) | problems over 1.5 | time / hc4, "
          "geometric mean | max | total time | truth checks |")
    print("|---|---|---|---|---|---|---|")
    for v, d in summ["per_variant"].items():
        print(f"| `{v}` | {d['worst_width_ratio']:.3g} ({d['worst_problem']}) | "
              f"{len(d['problems_over_target'])} | {d['time_ratio_hc4_geomean']:.3g} | "
              f"{d['time_ratio_hc4_max']:.3g} | {d['total_time_s']:.2f} s | "
              f"{d['truth_checks']}, {'all inside' if d['truth_always_inside'] else 'OUTSIDE'}"
              " |")
    print()
    print("within 1.5x of the best mode on every problem, cheapest first:",
          summ["within_target_on_every_problem"])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", help="also write the JSON to this file")
    p.add_argument("--problems", help="only the problems whose name matches this regex")
    p.add_argument("--variants", help="only the variants whose label matches this regex")
    p.add_argument("--repeat", type=int, default=5, help="timed warm runs per variant")
    p.add_argument("--seeds", default="1,2",
                   help="more simulated data sets for the soundness check (one run each)")
    p.add_argument("--update", action="store_true",
                   help="merge into the JSON of --out: its other rows are kept")
    p.add_argument("--compile", action="store_true",
                   help="also measure the compile time of each mode (fresh NUMBA_CACHE_DIR)")
    p.add_argument("--compile-only", action="store_true", help="only the compile times")
    p.add_argument("--scaling", action="store_true",
                   help="run the scaling problems (the satellite at k_max = 800) instead of the "
                        "table's; their rows go to 'scaling' in the JSON")
    p.add_argument("--slow-seeds", action="store_true",
                   help="run the --seeds soundness checks for lp too (minutes per problem)")
    p.add_argument("--report", action="store_true",
                   help="print the tables of the JSON of --out (the --variants, --problems "
                        "matching), measure nothing")
    args = p.parse_args()
    if args.report:
        report(_floats(json.loads(Path(args.out).read_text())), args.variants, args.problems)
        return
    t_start = time.perf_counter()
    import numba

    from boundest.csp import MODES

    seeds = [int(s) for s in args.seeds.split(",") if s]
    labels = [v for v in variants() if args.variants is None or re.search(args.variants, v[0])]
    rows, meta = [], {}
    if not args.compile_only:
        if any(v[1] == "lp" for v in labels):  # SciPy's import and HiGHS' first use, untimed
            from boundest.csp import propagate

            propagate(_chain_problem("pendulum_euler_sin").model, mode="lp", progress=False)
        for name, build in (SCALING if args.scaling else problems()):
            if args.problems and not re.search(args.problems, name):
                continue
            t0 = time.perf_counter()
            prob = build()
            meta[name] = {"group": prob.group, "note": prob.note,
                          "variables": len(prob.model.variable_names()),
                          "constraints": len(prob.model.constraints),
                          "states": sum(len(v) for v in prob.states.values()),
                          "truth_known": prob.truth is not None,
                          "build_s": time.perf_counter() - t0,
                          **{k: v for k, v in prob.extra.items() if not k.startswith("_")}}
            runs = [(label, mode, make(prob)) for label, mode, make in labels]
            rows += measure(prob, runs, args.repeat, seeds, args.slow_seeds)
            meta[name]["compile_model_s"] = prob.extra.get("compile_model_s")
            meta[name]["multi_occurrence_variables"] = (len(prob.extra["_multi"])
                                                        if "_multi" in prob.extra else None)
    compile_rec = None
    if args.compile or args.compile_only:
        compile_rec = {"problem": "pendulum_euler_sin (150 steps)",
                       "modes": compile_times(list(MODES), "pendulum_euler_sin")}
    old = {}
    if args.update and args.out and Path(args.out).exists():
        old = _floats(json.loads(Path(args.out).read_text()))
        meta = {k: {**old.get("problems", {}).get(k, {}),
                    **{a: b for a, b in meta.get(k, {}).items() if b is not None}}
                for k in {**old.get("problems", {}), **meta}}
        if compile_rec is None:
            compile_rec = old.get("compile")
    key = "scaling" if args.scaling else "rows"
    new = {(r["problem"], r["variant"]) for r in rows}
    rows = [r for r in old.get(key, []) if (r["problem"], r["variant"]) not in new] + rows
    order_p = [n for n, _ in problems() + SCALING]
    order_v = [v[0] for v in variants()]
    rows.sort(key=lambda r: (order_p.index(r["problem"]) if r["problem"] in order_p else 99,
                             order_v.index(r["variant"]) if r["variant"] in order_v else 99))
    annotate(rows, MODES)
    table_rows = rows if key == "rows" else old.get("rows", [])
    scaling_rows = rows if key == "scaling" else old.get("scaling", [])
    parts = [*old.get("parts", []), {"problems": args.problems, "variants": args.variants,
                                     "scaling": args.scaling,
                                     "repeat": args.repeat, "seeds": seeds,
                                     "loadavg_end": list(os.getloadavg()),
                                     "wall_s": time.perf_counter() - t_start}]
    doc = {"benchmark": "which propagation mode by default: width against time over problems",
           "what": {"time_s": "median of --repeat warm propagate() calls on the compiled tape "
                              "(Propagation.time_s); lp: one call",
                    "width_ratio": "max over the state families of mean width / the best "
                                   "mean width of the modes with their default settings on "
                                   "that problem",
                    "width_ratio_any": "the same against the best of every variant measured",
                    "time_ratio_hc4": "time_s / hc4's time_s in the same run",
                    "truth_inside": "every state's truth in its domain (the problem's data); "
                                    "truth_inside_seeds: on re-simulated data, one run each"},
           "problems": meta, "rows": table_rows,
           "summary": summarize(table_rows) if table_rows else None, "scaling": scaling_rows,
           "compile": compile_rec, "parts": parts,
           "machine": {"cpu_model": cpu_model(), "cpus": os.cpu_count(),
                       "numpy": np.__version__, "numba": numba.__version__,
                       "python": sys.version.split()[0]}}
    emit(doc, args.out)
    if rows:
        print(markdown(rows, [v for v in order_v if any(r["variant"] == v for r in rows)]),
              file=sys.stderr)


if __name__ == "__main__":
    main()
