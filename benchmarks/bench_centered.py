"""Centered-form contractors (``boundest.ctc.centered``) against Codac 2.x ``CtcInverse`` and
Codac 1.5.7 ``CtcNewton``, box by box on batches of random narrow boxes.

Problems (the same expression strings build boundest's model and Codac's function; targets,
boxes and results cross the process boundary as ``float.hex``):

* ``jaulin``: the example of Jaulin's centered-form paper in Codac's examples,
  ``(-x2^2 + 2 x2 sin(x2 x0) + cos(x2 x1), 2 x2 cos(x2 x0) - sin(x2 x1)) = 0`` on
  ``[0, 2] x [2, 4] x [0, 10]`` (a curve: 2 equations, 3 unknowns);
* ``range_only``: ``(x - a_i)^2 + (y - b_i)^2 in [d_i - e, d_i + e]``, 3 beacons, ``d_i`` the
  squared distance of a true position plus noise, ``e = 1``, domain ``[0, 10]^2``;
* ``satellite``: one step of Jaulin 2002, ``x(k), x(k+1)`` (8 unknowns, 7 constraints): the
  dynamics with ``w in [-0.01, 0.01]`` and the three outputs within +-0.1 of noisy measurements
  of ``x0 = (4, 0.5, -0.2, 0.5)``;
* ``katsura``: Katsura's polynomial system with 3 unknowns (PoSSo test suite, 4 real roots) on
  ``[-1, 1]^3``.

Boxes: per problem and relative radius ``rel`` (``1e-3, 1e-2, 1e-1`` of the domain's width,
per component), ``--n`` boxes (default 10,000): 90 % around a true solution (anywhere in the
box; its enclosure, see below, lies in the box), 10 % centred uniformly in the domain (most hold
no solution). One contraction per box on each side.

* boundest, in-process, warm (a first call loads or compiles the kernels), one batched call:
  ``centered`` (``CtcCentered(precondition=False)``: each constraint linearised on its own),
  ``centered_P`` (``precondition=True``: plus Gauss-Jordan preconditioned rows), ``fwdbwd``
  (``CtcFwdBwd``, HC4-revise), ``fwdbwd+centered_P`` (the two in sequence, the counterpart of
  Codac's ``CtcInverse``), ``centered_P+fwdbwd`` (the other order, Codac's: centered step, then
  the backward sweep), ``fwdbwd+centered_P[fX&Y]`` (the centered step with the targets
  ``f(X) & Y``, Codac's right-hand side, through ``CtcCentered.contract(x, targets=...)``) and
  ``fwdbwd+centered_P+centered_P`` (a second centered step, re-linearised on the contracted
  box);
* Codac 2.x (``centered_codac2.py`` in ``.bench-venv-codac2/``, a subprocess): ``default``
  (``CtcInverse(f, y)``: forward evaluation, ``f(X)`` intersected with ``y``, the centered
  step on ``f(X) & y - f(mid)`` with its ``MulOp::bwd`` -- Gauss-Jordan preconditioned rows
  when ``m <= n`` --, then the backward sweep) and ``hc4`` (``CtcInverse(f, y, False)``), a
  Python loop of ``ctc.contract(box)`` over prebuilt ``IntervalVector``.

Per problem, radius and boundest variant against Codac's ``default`` (and ``fwdbwd`` against
``hc4``): the median over boxes of the per-component width ratio boundest / Codac (boxes
non-empty on both sides), the ratio of the mean max-width (an empty box counts 0), the fraction
of boxes where boundest is wider than Codac in some component by more than 1e-12 relative (or
non-empty where Codac's is empty), narrower likewise, the empty boxes on each side, the boxes
holding a known solution whose contracted box lost it (must be 0), and the times (median of
``--repeat``; Codac per box and in total; ratio Codac / boundest).

Reference solutions: ``range_only`` and ``satellite`` points satisfy every constraint with a
margin of 1e-9 in float64 (checked), so they are solutions; ``jaulin`` fixes ``x2`` to a float
and ``katsura`` refines float Newton roots with mpmath (40 digits) to an enclosure of width
about 1e-30 (then one ulp outward). "Lost" means a contracted box is empty or misses that
enclosure in some component.

Interval Newton (``CtcNewton``, k steps) against Codac 1.5.7's ``CtcNewton``
(``newton_codac1.py`` in ``.bench-venv-codac1/``): two circles ``x^2 + y^2 = 4``,
``(x - 1)^2 + y^2 = 2`` and Broyden's banded function with 10 unknowns, boxes around roots.

Diagnosis (``--diagnose`` boxes per batch, default 1,000): the centered step replayed box by
box with boundest's own Jacobian, centre and row kernel (``contract_rows``) but other orders of
the row sweeps (``basic,P``: boundest's; ``P_rev,P,basic``: Codac 2.1.2's ``MulOp::bwd`` for
``m <= n``: the Gauss-Jordan preconditioned rows last to first, first to last, then the rows of
``J``; ``P,P,P,basic``), with ``Y`` or ``f(X) & Y``, alone or after ``CtcFwdBwd``; and Codac's
Jacobian enclosure (``f.diff``, forward mode) against boundest's (reverse-mode slopes).
Breakdown: the parts of one ``CtcCentered`` / ``CtcNewton`` call in µs per box.

First use: the first call of ``CtcCentered`` in a fresh process with an empty
``NUMBA_CACHE_DIR`` (and ``BOUNDEST_KERNEL_ARCHIVE=0``: everything compiles), then with that
cache filled.

Usage (hold the machine's benchmark lock)::

    flock /tmp/bench.lock env PYTHONPATH=src .venv/bin/python benchmarks/bench_centered.py \\
        --out benchmarks/results/centered.json [--n 10000] [--repeat 5] [--quick]

JSON on stdout (and ``--out``), progress and a table on stderr.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _machine import cpu_model, emit
from _subprocess import run_json_script

ROOT = Path(__file__).resolve().parent.parent
HERE = Path(__file__).resolve().parent
CODAC2_PY = ROOT / ".bench-venv-codac2" / "bin" / "python"
CODAC2_SCRIPT = HERE / "centered_codac2.py"
CODAC1_PY = ROOT / ".bench-venv-codac1" / "bin" / "python"
CODAC1_SCRIPT = HERE / "newton_codac1.py"
RADII = (1e-3, 1e-2, 1e-1)
REL_TOL = 1e-12
VARIANTS = ("centered", "centered_P", "fwdbwd", "fwdbwd+centered_P", "centered_P+fwdbwd",
            "fwdbwd+centered_P[fX&Y]", "fwdbwd+centered_P+centered_P")


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


# ---------------------------------------------------------------------------------------------
# problems


@dataclass
class Problem:
    name: str
    exprs: list[str]
    t_lo: np.ndarray
    t_hi: np.ndarray
    dom_lo: np.ndarray
    dom_hi: np.ndarray
    #: ``sampler(rng, k) -> (E_lo, E_hi)``: enclosures of ``k`` true solutions, shape (k, n)
    sampler: Callable[[np.random.Generator, int], tuple[np.ndarray, np.ndarray]]

    @property
    def n(self) -> int:
        return len(self.dom_lo)


def _np_ns() -> dict:
    return {"sin": np.sin, "cos": np.cos, "sqrt": np.sqrt, "sqr": np.square,
            "cube": lambda e: e ** 3, "__builtins__": {}}


@functools.cache
def _code(expr: str):
    return compile(expr, "<expr>", "eval")


def _f_np(exprs: list[str], x: np.ndarray) -> np.ndarray:
    """The expressions on points ``x`` (k, n), in float64: shape (k, m)."""
    ns = {**_np_ns(), "x": x.T}
    return np.stack([np.broadcast_to(eval(_code(e), ns), len(x)) for e in exprs], axis=-1)


def _point_sampler(exprs: list[str], t_lo: np.ndarray, t_hi: np.ndarray,
                   propose: Callable[[np.random.Generator, int], np.ndarray]):
    """Rejection sampling of points that satisfy every constraint with a margin of 1e-9
    (relative to the target's width) in float64: true solutions (rounding error ~1e-15)."""
    margin = 1e-9 * np.maximum(t_hi - t_lo, 1.0)

    def sampler(rng: np.random.Generator, k: int) -> tuple[np.ndarray, np.ndarray]:
        got: list[np.ndarray] = []
        total = 0
        while total < k:
            p = propose(rng, 4 * k)
            v = _f_np(exprs, p)
            ok = np.all((v >= t_lo + margin) & (v <= t_hi - margin), axis=1)
            got.append(p[ok])
            total += int(ok.sum())
        pts = np.concatenate(got)[:k]
        return pts, pts.copy()

    return sampler


def _mp_enclosure(v) -> tuple[float, float]:
    """A float interval around an mpmath value known to ~1e-35: +-1e-30, then one ulp out."""
    import mpmath as mp

    return (float(np.nextafter(float(v - mp.mpf("1e-30")), -np.inf)),
            float(np.nextafter(float(v + mp.mpf("1e-30")), np.inf)))


def jaulin() -> Problem:
    exprs = ["-sqr(x[2]) + 2*x[2]*sin(x[2]*x[0]) + cos(x[2]*x[1])",
             "2*x[2]*cos(x[2]*x[0]) - sin(x[2]*x[1])"]
    lo, hi = np.array([0.0, 2.0, 0.0]), np.array([2.0, 4.0, 10.0])

    cache: dict = {}

    def sampler(rng: np.random.Generator, k: int) -> tuple[np.ndarray, np.ndarray]:
        if len(cache.get("lo", [])) < min(k, 600):
            cache["lo"], cache["hi"] = _jaulin_pool(rng, min(k, 600), lo, hi)
        idx = rng.integers(0, len(cache["lo"]), k)
        return cache["lo"][idx], cache["hi"][idx]

    return Problem("jaulin", exprs, np.zeros(2), np.zeros(2), lo, hi, sampler)


def _jaulin_pool(rng: np.random.Generator, pool: int, lo: np.ndarray, hi: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Enclosures of ``pool`` points of the curve: Gauss-Newton from random points (minimal
    norm steps, vectorised), then ``x2`` fixed to the float found and ``x0, x1`` refined by
    mpmath (a regular 2 x 2 system, 50 digits)."""
    import mpmath as mp

    mp.mp.dps = 50
    elo: list = []
    ehi: list = []
    while len(elo) < pool:
        p = rng.uniform(lo, hi, (4 * pool, 3))
        with np.errstate(all="ignore"):
            for _ in range(40):
                a, b, c = p.T
                f = np.stack([-c * c + 2 * c * np.sin(c * a) + np.cos(c * b),
                              2 * c * np.cos(c * a) - np.sin(c * b)], -1)
                p = p - (np.linalg.pinv(_jaulin_jac(a, b, c)) @ f[..., None])[..., 0]
        ok = np.all((p >= lo + 1e-6) & (p <= hi - 1e-6), axis=1)
        for a, b, c in p[ok]:
            jac = _jaulin_jac(a, b, c)[:, :2]
            if not abs(np.linalg.det(jac)) > 1e-3 or len(elo) >= pool:
                continue  # x2 fixed: the 2 x 2 system in x0, x1 must be regular
            cm = mp.mpf(c)
            try:
                r = mp.findroot(
                    [lambda u, v, cm=cm: -cm**2 + 2 * cm * mp.sin(cm * u) + mp.cos(cm * v),
                     lambda u, v, cm=cm: 2 * cm * mp.cos(cm * u) - mp.sin(cm * v)],
                    (mp.mpf(a), mp.mpf(b)), tol=mp.mpf("1e-80"),
                    J=lambda u, v, cm=cm: [[2 * cm**2 * mp.cos(cm * u), -cm * mp.sin(cm * v)],
                                           [-2 * cm**2 * mp.sin(cm * u), -cm * mp.cos(cm * v)]])
            except (ValueError, ZeroDivisionError):
                continue
            if abs(float(r[0]) - a) > 1e-9 or abs(float(r[1]) - b) > 1e-9:
                continue
            e0, e1 = _mp_enclosure(r[0]), _mp_enclosure(r[1])
            elo.append([e0[0], e1[0], c])
            ehi.append([e0[1], e1[1], c])
    return np.array(elo), np.array(ehi)


def _jaulin_jac(a, b, c):
    """The Jacobian of the ``jaulin`` function, ``(..., 2, 3)``."""
    sa, ca, sb, cb = np.sin(c * a), np.cos(c * a), np.sin(c * b), np.cos(c * b)
    return np.stack([
        np.stack([2 * c * c * ca, -c * sb, -2 * c + 2 * sa + 2 * c * a * ca - b * sb], -1),
        np.stack([-2 * c * c * sa, -c * cb, 2 * ca - 2 * c * a * sa - b * cb], -1)], -2)


def range_only() -> Problem:
    beacons = [(0.0, 0.0), (10.0, 0.0), (5.0, 8.0)]
    truth = np.array([4.0, 3.0])
    noise = np.random.default_rng(11).uniform(-0.5, 0.5, 3)
    e = 1.0
    d = np.array([(truth[0] - a) ** 2 + (truth[1] - b) ** 2 for a, b in beacons]) + noise
    exprs = [f"sqr(x[0] - {a!r}) + sqr(x[1] - {b!r})" for a, b in beacons]
    t_lo, t_hi = d - e, d + e

    def propose(rng: np.random.Generator, k: int) -> np.ndarray:
        return truth + rng.uniform(-0.4, 0.4, (k, 2))

    return Problem("range_only", exprs, t_lo, t_hi, np.zeros(2), np.full(2, 10.0),
                   _point_sampler(exprs, t_lo, t_hi, propose))


def _sat_step(x: np.ndarray) -> np.ndarray:
    x1, x2, x3, x4 = x.T
    r3 = np.sqrt(x1**2 + x2**2) ** 3
    return np.stack([x1 + 0.5 * x3, x2 + 0.5 * x4, x3 - 0.5 * x1 / r3, x4 - 0.5 * x2 / r3], -1)


def satellite() -> Problem:
    x0 = np.array([4.0, 0.5, -0.2, 0.5])
    r3 = "cube(sqrt(sqr(x[0]) + sqr(x[1])))"
    exprs = ["x[4] - (x[0] + 0.5*x[2])", "x[5] - (x[1] + 0.5*x[3])",
             f"x[6] - (x[2] - 0.5*x[0]/{r3})", f"x[7] - (x[3] - 0.5*x[1]/{r3})",
             "x[1]/x[0]", "x[0]*x[2] + x[1]*x[3]", "sqr(x[0]) + sqr(x[1])"]
    y_true = np.array([x0[1] / x0[0], x0[0] * x0[2] + x0[1] * x0[3], x0[0]**2 + x0[1]**2])
    y = y_true + np.random.default_rng(12).uniform(-0.09, 0.09, 3)
    t_lo = np.concatenate([np.full(4, -0.01), y - 0.1])
    t_hi = np.concatenate([np.full(4, 0.01), y + 0.1])
    d = np.array([0.05, 0.5, 0.05, 0.3])

    def propose(rng: np.random.Generator, k: int) -> np.ndarray:
        xk = x0 + rng.uniform(-d, d, (k, 4))
        return np.hstack([xk, _sat_step(xk) + rng.uniform(-0.0099, 0.0099, (k, 4))])

    dom = np.array([8.0, 8.0, 4.0, 4.0])
    dlo = np.array([0.0, -4.0, -2.0, -2.0])
    return Problem("satellite", exprs, t_lo, t_hi, np.tile(dlo, 2), np.tile(dlo + dom, 2),
                   _point_sampler(exprs, t_lo, t_hi, propose))


def _newton_roots(F, J, lo: np.ndarray, hi: np.ndarray, starts: int, seed: int) -> list:
    """Distinct roots in [lo, hi] of a square system, by float Newton from random starts."""
    rng = np.random.default_rng(seed)
    roots: list[np.ndarray] = []
    for _ in range(starts):
        p = rng.uniform(lo, hi)
        with np.errstate(all="ignore"):
            for _ in range(60):
                try:
                    step = np.linalg.solve(J(p), F(p))
                except np.linalg.LinAlgError:
                    break
                p = p - step
                if not np.max(np.abs(p)) < 1e6 or np.max(np.abs(step)) < 1e-15:
                    break
        if (np.all(np.isfinite(p)) and np.max(np.abs(F(p))) < 1e-12 and np.all(p >= lo)
                and np.all(p <= hi) and not any(np.allclose(p, r, atol=1e-8) for r in roots)):
            roots.append(p)
    return roots


def _mp_refine(exprs: list[str], roots: list) -> tuple[np.ndarray, np.ndarray]:
    """Enclosures (40-digit mpmath Newton, then +-1e-30 and one ulp out) of float roots."""
    import mpmath as mp

    mp.mp.dps = 50
    ns = {"sin": mp.sin, "cos": mp.cos, "sqrt": mp.sqrt, "sqr": lambda v: v * v,
          "cube": lambda v: v ** 3, "__builtins__": {}}
    n = len(roots[0])
    fs = [eval(f"lambda *x: {e}", ns) for e in exprs]
    elo, ehi = [], []
    for r in roots:
        sol = mp.findroot(fs, tuple(mp.mpf(float(v)) for v in r), tol=mp.mpf("1e-80"))
        sol = [sol] if n == 1 else [sol[i] for i in range(n)]
        enc = [_mp_enclosure(v) for v in sol]
        elo.append([a for a, _ in enc])
        ehi.append([b for _, b in enc])
    return np.array(elo), np.array(ehi)


def katsura() -> Problem:
    exprs = ["x[0] + 2*x[1] + 2*x[2] - 1",
             "sqr(x[0]) + 2*sqr(x[1]) + 2*sqr(x[2]) - x[0]",
             "2*x[0]*x[1] + 2*x[1]*x[2] - x[1]"]
    lo, hi = np.full(3, -1.0), np.full(3, 1.0)

    def F(p: np.ndarray) -> np.ndarray:
        return _f_np(exprs, p[None])[0]

    def J(p: np.ndarray) -> np.ndarray:
        a, b, c = p
        return np.array([[1, 2, 2], [2 * a - 1, 4 * b, 4 * c], [2 * b, 2 * a + 2 * c - 1, 2 * b]])

    roots = _newton_roots(F, J, lo, hi, 300, 13)
    elo, ehi = _mp_refine(exprs, roots)

    def sampler(rng: np.random.Generator, k: int) -> tuple[np.ndarray, np.ndarray]:
        idx = rng.integers(0, len(elo), k)
        return elo[idx], ehi[idx]

    return Problem("katsura", exprs, np.zeros(3), np.zeros(3), lo, hi, sampler)


def boxes_for(prob: Problem, rel: float, n_boxes: int, seed: int
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(lo, hi, sol, e_lo, e_hi)``: boxes of radius ``rel`` x the domain's width, the first
    90 % around the enclosures ``e_lo, e_hi`` of true solutions (``sol`` marks them), the rest
    centred uniformly in the domain."""
    rng = np.random.default_rng(seed)
    k = round(0.9 * n_boxes)
    e_lo, e_hi = prob.sampler(rng, k)
    r = rel * (prob.dom_hi - prob.dom_lo)
    p = 0.5 * (e_lo + e_hi)
    u = rng.uniform(0, 1, p.shape)
    lo = np.minimum(p - 2 * r * u, e_lo)
    hi = np.maximum(p + 2 * r * (1 - u), e_hi)
    c = rng.uniform(prob.dom_lo, prob.dom_hi, (n_boxes - k, prob.n))
    lo = np.vstack([lo, c - r])
    hi = np.vstack([hi, c + r])
    sol = np.arange(n_boxes) < k
    return lo, hi, sol, e_lo, e_hi


# ---------------------------------------------------------------------------------------------
# boundest side


def _bd_ns(x: list) -> dict:
    from boundest.expr import functions as fn

    return {"x": x, "sin": fn.sin, "cos": fn.cos, "sqrt": fn.sqrt, "sqr": fn.sqr,
            "cube": lambda e: e ** 3, "__builtins__": {}}


def bd_model(exprs: list[str], t_lo: np.ndarray, t_hi: np.ndarray):
    """The model ``expr_k in [t_lo[k], t_hi[k]]`` over ``x0 .. x{n-1}`` (declared in order,
    entire domains: Codac's function knows no domain either)."""
    from boundest.expr import Model, Var

    n = 1 + max(int(s.split("]")[0]) for e in exprs for s in e.split("x[")[1:])
    x = [Var(f"x{i}") for i in range(n)]
    m = Model()
    for v in x:
        m.declare(v)
    ns = _bd_ns(x)
    for e, a, b in zip(exprs, t_lo, t_hi, strict=True):
        m.add(eval(e, ns).in_((float(a), float(b))))
    return m, [v.name for v in x]


def bd_contractors(prob: Problem) -> dict:
    """The boundest variants (module docstring), by name."""
    from boundest import Interval
    from boundest.ctc import CtcFwdBwd, FunctionContractor
    from boundest.ctc.centered import CtcCentered
    from boundest.ctc.derivatives import evaluate
    from boundest.interval import intersect

    m, names = bd_model(prob.exprs, prob.t_lo, prob.t_hi)
    cen, cen_p, fb = CtcCentered(m, precondition=False), CtcCentered(m), CtcFwdBwd(m, names)
    assert cen.tape.names == names

    def centered_fx(x: Interval) -> Interval:
        """``CtcCentered`` with the targets ``f(X) & Y`` (Codac's right-hand side)."""
        v = evaluate(cen_p.tape, x)
        y = Interval(np.broadcast_to(prob.t_lo, v.shape), np.broadcast_to(prob.t_hi, v.shape))
        return cen_p.contract(x, targets=intersect(v, y))

    return {"centered": cen, "centered_P": cen_p, "fwdbwd": fb,
            "fwdbwd+centered_P": fb & cen_p, "centered_P+fwdbwd": cen_p & fb,
            "fwdbwd+centered_P[fX&Y]": fb & FunctionContractor(centered_fx, prob.n),
            "fwdbwd+centered_P+centered_P": fb & cen_p & cen_p}


def timed(ctc, box, repeat: int):
    ctc(box[:16])  # load / compile
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = ctc(box)
        times.append(time.perf_counter() - t0)
    return times, out


# ---------------------------------------------------------------------------------------------
# comparison


def _widths(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    return hi - lo  # NaN where empty


def compare(b_lo, b_hi, c_lo, c_hi) -> dict:
    """boundest (b) against Codac (c), box by box."""
    eb, ec = np.isnan(b_lo).any(1), np.isnan(c_lo).any(1)
    wb, wc = _widths(b_lo, b_hi), _widths(c_lo, c_hi)
    both = ~eb & ~ec
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(wc[both] > 0, wb[both] / wc[both],
                         np.where(wb[both] > 0, np.inf, 1.0))
    wider = np.zeros(len(eb), bool)
    narrower = np.zeros(len(eb), bool)
    wider[both] = (wb[both] > wc[both] * (1 + REL_TOL)).any(1)
    narrower[both] = (wb[both] < wc[both] * (1 - REL_TOL)).any(1)
    wider |= ~eb & ec
    narrower |= eb & ~ec
    with np.errstate(divide="ignore", invalid="ignore"):
        excess = (wb[both] - wc[both]) / wc[both]
    excess = excess[wb[both] > wc[both] * (1 + REL_TOL)]
    mb = np.where(eb, 0.0, np.nan_to_num(wb, nan=0.0).max(1))
    mc = np.where(ec, 0.0, np.nan_to_num(wc, nan=0.0).max(1))
    with np.errstate(divide="ignore", invalid="ignore"):
        box_ratio = np.where(mc[both] > 0, mb[both] / mc[both], np.where(mb[both] > 0, np.inf,
                                                                          1.0))
    return {
        "median_width_ratio": (np.median(ratio, axis=0).tolist() if both.any() else None),
        "median_max_width_ratio": float(np.median(box_ratio)) if both.any() else None,
        "mean_max_width_ratio": float(mb.mean() / mc.mean()) if mc.mean() > 0 else None,
        "frac_wider": float(wider.mean()), "frac_narrower": float(narrower.mean()),
        "frac_mixed": float((wider & narrower).mean()),
        "n_wider": int(wider.sum()), "n_narrower": int(narrower.sum()),
        "wider_components_median_excess": float(np.median(excess)) if excess.size else 0.0,
        "wider_components_max_excess": float(np.max(excess)) if excess.size else 0.0,
    }


def lost(lo, hi, sol, e_lo, e_hi) -> dict:
    """Boxes known to hold a solution (enclosed in ``e``) whose contraction misses it."""
    lo, hi = lo[sol], hi[sol]
    empty = np.isnan(lo).any(1)
    miss = ~empty & ((hi < e_lo) | (lo > e_hi)).any(1)
    partial = ~empty & ~miss & ((lo > e_lo) | (hi < e_hi)).any(1)
    return {"lost": int(empty.sum() + miss.sum()), "emptied": int(empty.sum()),
            "enclosure_not_inside": int(partial.sum())}


def summarize_side(lo, hi, in_lo, in_hi, sol) -> dict:
    empty = np.isnan(lo).any(1)
    w, w0 = _widths(lo, hi), _widths(in_lo, in_hi)
    keep = ~empty & sol
    return {"empty_solution_boxes": int((empty & sol).sum()),
            "empty_random_boxes": int((empty & ~sol).sum()),
            "median_width_over_input": (np.median(w[keep] / w0[keep], axis=0).tolist()
                                        if keep.any() else None),
            "mean_max_width": float(np.where(empty, 0.0, np.nan_to_num(w).max(1)).mean())}


# ---------------------------------------------------------------------------------------------
# diagnosis: the centered step's row sweeps, replayed box by box with boundest's kernels

#: Orders of row contractions on ``J d in Z``: ``basic`` the rows of ``J`` (each constraint on
#: its own), ``P`` the preconditioned rows ``P J`` first to last, ``P_rev`` last to first.
SWEEPS = {"basic,P": ("basic", "P"),  # what CtcCentered(precondition=True) does
          "P_rev,P,basic": ("P_rev", "P", "basic"),  # Codac 2.1.2's MulOp::bwd when m <= n
          "P,P,P,basic": ("P", "P", "P", "basic")}


def sweep_replay(prob: Problem, lo: np.ndarray, hi: np.ndarray, order: tuple[str, ...],
                 fx: bool) -> tuple[np.ndarray, np.ndarray]:
    """One centered step per box with the Jacobian, centre and ``f(c)`` of ``CtcCentered``,
    its row kernel ``contract_rows`` and preconditioner, but the rows in ``order`` and, with
    ``fx``, the right-hand side ``(f(X) & Y) - f(c)`` (Codac's) instead of ``Y - f(c)``."""
    from boundest import Interval
    from boundest.ctc.derivatives import evaluate, jacobian, midpoint
    from boundest.ctc.linear_forms import contract_rows, point_times, preconditioner
    from boundest.interval.rounding import add_dn, add_up, sub_dn, sub_up

    m, _ = bd_model(prob.exprs, prob.t_lo, prob.t_hi)
    from boundest.ctc.centered import CtcCentered

    tape = CtcCentered(m).tape
    box = Interval(lo, hi)
    c = midpoint(box)
    vals, jac = jacobian(tape, box)
    fc = evaluate(tape, Interval(c, c))
    olo, ohi = lo.copy(), hi.copy()
    n = prob.n
    for b in range(len(lo)):
        jl, jh = jac.lo[b], jac.hi[b]
        yl, yh = prob.t_lo, prob.t_hi
        if fx:
            yl, yh = np.maximum(yl, vals.lo[b]), np.minimum(yh, vals.hi[b])
        zl = np.array([sub_dn(a, f) for a, f in zip(yl, fc.hi[b], strict=True)])
        zh = np.array([sub_up(a, f) for a, f in zip(yh, fc.lo[b], strict=True)])
        dl = np.array([sub_dn(lo[b, j], c[b, j]) for j in range(n)])
        dh = np.array([sub_up(hi[b, j], c[b, j]) for j in range(n)])
        with np.errstate(invalid="ignore"):
            mid = np.where(np.isfinite(jl) & np.isfinite(jh), 0.5 * jl + 0.5 * jh, 0.0)
        P, _ = preconditioner(mid)
        ml, mh = point_times(P, jl, jh)
        rl, rh = point_times(P, zl.reshape(-1, 1), zh.reshape(-1, 1))
        rl, rh = rl[:, 0].copy(), rh[:, 0].copy()
        ok = bool(np.all(vals.lo[b] <= prob.t_hi) and np.all(vals.hi[b] >= prob.t_lo))
        for step in order if ok else ():
            if step == "basic":
                ok = contract_rows(jl, jh, zl, zh, dl, dh)
            elif step == "P":
                ok = contract_rows(ml, mh, rl, rh, dl, dh)
            else:
                ok = contract_rows(ml[::-1].copy(), mh[::-1].copy(), rl[::-1].copy(),
                                   rh[::-1].copy(), dl, dh)
            if not ok:
                break
        if not ok:
            olo[b] = ohi[b] = np.nan
            continue
        for j in range(n):
            olo[b, j] = max(lo[b, j], add_dn(c[b, j], dl[j]))
            ohi[b, j] = min(hi[b, j], add_up(c[b, j], dh[j]))
    return olo, ohi


def jacobian_compare(prob: Problem, lo, hi, cjac: dict) -> dict:
    """boundest's Jacobian enclosure (reverse-mode slopes) against Codac's ``f.diff`` (forward
    mode) entry by entry on the same boxes: interval products are not associative, so the two
    chain rules give different enclosures."""
    from boundest import Interval
    from boundest.ctc.centered import CtcCentered
    from boundest.ctc.derivatives import jacobian

    m, _ = bd_model(prob.exprs, prob.t_lo, prob.t_hi)
    _, jac = jacobian(CtcCentered(m).tape, Interval(lo, hi))
    k, mm, n = jac.lo.shape
    c_lo = np.array([float.fromhex(v) for v in cjac["lo"]]).reshape(k, mm, n)
    c_hi = np.array([float.fromhex(v) for v in cjac["hi"]]).reshape(k, mm, n)
    wb, wc = jac.hi - jac.lo, c_hi - c_lo
    live = (wc > 0) | (wb > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(wc > 0, wb / wc, np.inf)
    contains = (jac.lo <= c_lo) & (c_hi <= jac.hi)
    return {"entries": int(live.sum()),
            "frac_wider": float((wb > wc * (1 + REL_TOL))[live].mean()),
            "frac_narrower": float((wb < wc * (1 - REL_TOL))[live].mean()),
            "median_width_ratio": float(np.median(ratio[live])) if live.any() else None,
            "frac_boundest_contains_codac": float(contains[live].mean()),
            "boxes_any_entry_wider": float((wb > wc * (1 + REL_TOL)).any((1, 2)).mean())}


def diagnose(prob: Problem, lo, hi, c_lo, c_hi, ctcs: dict) -> dict:
    """Each sweep order, with ``Y`` and with ``f(X) & Y``, alone and after ``CtcFwdBwd``,
    against Codac's default on the same boxes; ``replay_matches_centered_P``: the replay of
    ``basic,P`` with ``Y`` gives CtcCentered's bounds exactly (a check of the replay)."""
    from boundest import Interval

    out: dict = {"boxes": len(lo)}
    ref = ctcs["centered_P"](Interval(lo, hi))
    fb = ctcs["fwdbwd"](Interval(lo, hi))
    flo, fhi = fb.lo.copy(), fb.hi.copy()
    for name, order in SWEEPS.items():
        for fx in (False, True):
            for pre in (False, True):
                key = ("fwdbwd+" if pre else "") + name + (" [fX&Y]" if fx else "")
                if pre:
                    keep = ~np.isnan(flo).any(1)
                    a, b = flo.copy(), fhi.copy()
                    a[keep], b[keep] = sweep_replay(prob, flo[keep], fhi[keep], order, fx)
                else:
                    a, b = sweep_replay(prob, lo, hi, order, fx)
                if name == "basic,P" and not fx and not pre:
                    same = np.array_equal(a, ref.lo, equal_nan=True) and np.array_equal(
                        b, ref.hi, equal_nan=True)
                    out["replay_matches_centered_P"] = bool(same)
                cm = compare(a, b, c_lo, c_hi)
                out[key] = {k: cm[k] for k in ("frac_wider", "frac_narrower",
                                               "mean_max_width_ratio", "median_width_ratio")}
    return out


# ---------------------------------------------------------------------------------------------
# runs


def _hex(a: np.ndarray) -> list[str]:
    return [float(v).hex() for v in np.asarray(a, dtype=float).ravel()]


def _unhex(a: list[str], n: int) -> np.ndarray:
    return np.array([float.fromhex(s) for s in a]).reshape(-1, n)


def run_centered(probs: list[Problem], a) -> dict:
    from boundest import Interval

    out: dict = {}
    batches: dict = {}
    for i, prob in enumerate(probs):
        log(f"{prob.name}: boxes ...")
        batches[prob.name] = {}
        for j, rel in enumerate(RADII):
            batches[prob.name][rel] = boxes_for(prob, rel, a.n, seed=100 * i + j)
    codac = None
    if not a.no_codac and CODAC2_PY.exists():
        spec = {"repeat": a.codac_repeat, "problems": [
            {"name": p.name, "n": p.n, "exprs": p.exprs, "t_lo": _hex(p.t_lo),
             "t_hi": _hex(p.t_hi), "modes": ["default", "hc4"], "jacobian_boxes": a.diagnose,
             "batches": [{"key": f"{rel:g}", "lo": _hex(b[0]), "hi": _hex(b[1])}
                         for rel, b in batches[p.name].items()]} for p in probs]}
        log("codac 2 ...")
        codac = run_json_script(CODAC2_PY, CODAC2_SCRIPT, spec)
        out["codac"] = {k: v for k, v in codac.items() if k != "problems"}
    elif not a.no_codac:
        out["codac"] = "not run (no .bench-venv-codac2)"
    rows = {}
    for pi, prob in enumerate(probs):
        ctcs = bd_contractors(prob)
        for rel, (lo, hi, sol, e_lo, e_hi) in batches[prob.name].items():
            key = f"{prob.name} {rel:g}"
            box = Interval(lo, hi)
            row: dict = {"problem": prob.name, "rel_radius": rel, "boxes": len(lo),
                         "solution_boxes": int(sol.sum()), "n": prob.n, "m": len(prob.exprs),
                         "boundest": {}, "codac": {}, "vs_codac": {}}
            res = {}
            for v in VARIANTS:
                times, r = timed(ctcs[v], box, a.repeat)
                res[v] = (r.lo, r.hi)
                t = statistics.median(times)
                row["boundest"][v] = {"time_s": t, "times_s": times,
                                      "us_per_box": 1e6 * t / len(lo),
                                      **summarize_side(r.lo, r.hi, lo, hi, sol),
                                      **lost(r.lo, r.hi, sol, e_lo, e_hi)}
            if codac is not None:
                cb = codac["problems"][pi]["batches"][f"{rel:g}"]
                cres = {}
                for mode in ("default", "hc4"):
                    rec = cb[mode]
                    c_lo, c_hi = _unhex(rec["lo"], prob.n), _unhex(rec["hi"], prob.n)
                    cres[mode] = (c_lo, c_hi)
                    row["codac"][mode] = {"time_s": rec["contract_s"],
                                          "times_s": rec["contract_times_s"],
                                          "us_per_box": 1e6 * rec["contract_s"] / len(lo),
                                          "build_and_contract_s": rec["build_contract_s"],
                                          **summarize_side(c_lo, c_hi, lo, hi, sol),
                                          **lost(c_lo, c_hi, sol, e_lo, e_hi)}
                for v in VARIANTS:
                    ref = "hc4" if v == "fwdbwd" else "default"
                    cmp = compare(*res[v], *cres[ref])
                    cmp["against"] = ref
                    cmp["time_ratio_codac_over_boundest"] = (
                        row["codac"][ref]["time_s"] / row["boundest"][v]["time_s"])
                    row["vs_codac"][v] = cmp
            if codac is not None and a.diagnose > 0:
                k = min(a.diagnose, len(lo))
                sel = np.r_[0:k - k // 10, int(sol.sum()):int(sol.sum()) + k // 10]
                row["diagnosis"] = diagnose(prob, lo[sel], hi[sel], cres["default"][0][sel],
                                            cres["default"][1][sel], ctcs)
                if "jacobian" in cb:
                    row["diagnosis"]["jacobian_vs_codac"] = jacobian_compare(
                        prob, lo[:k], hi[:k], cb["jacobian"])
            rows[key] = row
            log(_row_line(row))
    out["rows"] = rows
    return out


def _row_line(row: dict) -> str:
    main = "fwdbwd+centered_P"
    b = row["boundest"][main]
    s = f"{row['problem']:10s} rel={row['rel_radius']:<6g} {main}: {b['us_per_box']:.2f} us/box"
    if row["vs_codac"]:
        c = row["vs_codac"][main]
        s += (f"; codac {row['codac']['default']['us_per_box']:.1f} us/box "
              f"(x{c['time_ratio_codac_over_boundest']:.0f}); median ratio "
              f"{[f'{v:.4g}' for v in c['median_width_ratio'] or []]}, mean max "
              f"{c['mean_max_width_ratio']}, wider {c['frac_wider']:.3f}, narrower "
              f"{c['frac_narrower']:.3f}; lost b={b['lost']} "
              f"c={row['codac']['default']['lost']}")
    return s


# ---------------------------------------------------------------------------------------------
# interval Newton


def _broyden_exprs(n: int) -> list[str]:
    """Broyden's banded function: ``x_i (2 + 5 x_i^2) + 1 - sum_{j in J_i} x_j (1 + x_j)``,
    ``J_i = {max(0, i - 5) .. min(n - 1, i + 1)} - {i}``."""
    out = []
    for i in range(n):
        js = [j for j in range(max(0, i - 5), min(n - 1, i + 1) + 1) if j != i]
        s = " + ".join(f"x[{j}]*(1 + x[{j}])" for j in js)
        out.append(f"x[{i}]*(2 + 5*sqr(x[{i}])) + 1 - ({s})")
    return out


def newton_problems() -> list[tuple[str, list[str], np.ndarray, np.ndarray, int]]:
    circles = ["sqr(x[0]) + sqr(x[1]) - 4", "sqr(x[0] - 1) + sqr(x[1]) - 2"]
    return [("circles", circles, np.full(2, -3.0), np.full(2, 3.0), 2),
            ("broyden10", _broyden_exprs(10), np.full(10, -1.0), np.full(10, 1.0), 10)]


def _ibex(exprs: list[str]) -> str:
    return "(" + "; ".join(e.replace("**", "^") for e in exprs) + ")"


NEWTON_STEPS = (1, 2, 3, 5)
CODAC1_MODES = [{"name": "one_step", "prec": 1e300, "ratio": 1e300},
                {"name": "default", "prec": 1e-7, "ratio": 1e-4}]


def run_newton(a) -> dict:
    from boundest import Interval
    from boundest.ctc.centered import CtcNewton

    n_boxes = a.newton_n
    out: dict = {"steps": list(NEWTON_STEPS), "codac_modes": CODAC1_MODES, "rows": {}}
    data = []
    for pi, (name, exprs, dlo, dhi, n) in enumerate(newton_problems()):
        def F(p, exprs=exprs):
            return _f_np(exprs, p[None])[0]

        def J(p, F=F, n=n):  # central differences are enough to find the roots
            h = 1e-7
            return np.stack([(F(p + h * np.eye(n)[k]) - F(p - h * np.eye(n)[k])) / (2 * h)
                             for k in range(n)], axis=1)

        roots = _newton_roots(F, J, dlo, dhi, 12, 7)
        elo, ehi = _mp_refine(exprs, roots)
        log(f"{name}: {len(roots)} roots in the domain")
        batches = {}
        for j, rel in enumerate(RADII):
            rng = np.random.default_rng(1000 + 10 * pi + j)
            idx = rng.integers(0, len(elo), n_boxes)
            r = rel * (dhi - dlo)
            p = 0.5 * (elo[idx] + ehi[idx])
            u = rng.uniform(0, 1, p.shape)
            batches[rel] = (np.minimum(p - 2 * r * u, elo[idx]),
                            np.maximum(p + 2 * r * (1 - u), ehi[idx]), elo[idx], ehi[idx])
        data.append((name, exprs, n, batches, len(roots)))
    codac = None
    if not a.no_codac and CODAC1_PY.exists():
        spec = {"repeat": a.codac_repeat, "problems": [
            {"name": name, "n": n, "ibex": _ibex(exprs), "modes": CODAC1_MODES,
             "batches": [{"key": f"{rel:g}", "lo": _hex(b[0]), "hi": _hex(b[1])}
                         for rel, b in batches.items()]}
            for name, exprs, n, batches, _ in data]}
        log("codac 1.5.7 ...")
        codac = run_json_script(CODAC1_PY, CODAC1_SCRIPT, spec)
        out["codac"] = {k: v for k, v in codac.items() if k != "problems"}
    elif not a.no_codac:
        out["codac"] = "not run (no .bench-venv-codac1)"
    for pi, (name, exprs, n, batches, n_roots) in enumerate(data):
        m, _ = bd_model(exprs, np.zeros(n), np.zeros(n))
        newton = CtcNewton(m)
        for rel, (lo, hi, elo, ehi) in batches.items():
            box = Interval(lo, hi)
            sol = np.ones(len(lo), bool)
            row: dict = {"problem": name, "n": n, "roots": n_roots, "rel_radius": rel,
                         "boxes": len(lo),
                         "input_mean_max_width": float((hi - lo).max(1).mean()),
                         "boundest": {}, "codac": {}}
            newton.prove(box[:8])
            for k in NEWTON_STEPS:
                times = []
                for _ in range(a.repeat):
                    t0 = time.perf_counter()
                    x = box
                    proved_any = np.zeros(len(lo), bool)
                    for _ in range(k):
                        x, proved = newton.prove(x)
                        proved_any |= proved
                    times.append(time.perf_counter() - t0)
                t = statistics.median(times)
                row["boundest"][f"steps_{k}"] = {
                    "time_s": t, "us_per_box": 1e6 * t / len(lo),
                    "proved_last_step": int(proved.sum()), "proved_any_step": int(proved_any.sum()),
                    **summarize_side(x.lo, x.hi, lo, hi, sol),
                    **lost(x.lo, x.hi, sol, elo, ehi)}
                row["boundest"][f"steps_{k}"]["_bounds"] = (x.lo, x.hi)
            if codac is not None:
                cb = codac["problems"][pi]["batches"][f"{rel:g}"]
                for mode, rec in cb.items():
                    c_lo, c_hi = _unhex(rec["lo"], n), _unhex(rec["hi"], n)
                    row["codac"][mode] = {"time_s": rec["contract_s"],
                                          "us_per_box": 1e6 * rec["contract_s"] / len(lo),
                                          **summarize_side(c_lo, c_hi, lo, hi, sol),
                                          **lost(c_lo, c_hi, sol, elo, ehi)}
                    for k in NEWTON_STEPS:
                        b_lo, b_hi = row["boundest"][f"steps_{k}"]["_bounds"]
                        cmp = compare(b_lo, b_hi, c_lo, c_hi)
                        cmp["time_ratio_codac_over_boundest"] = (
                            rec["contract_s"] / row["boundest"][f"steps_{k}"]["time_s"])
                        row["codac"][mode][f"vs_boundest_steps_{k}"] = cmp
            for k in NEWTON_STEPS:
                del row["boundest"][f"steps_{k}"]["_bounds"]
            out["rows"][f"{name} {rel:g}"] = row
            b1, b5 = row["boundest"]["steps_1"], row["boundest"]["steps_5"]
            s = (f"newton {name} rel={rel:g}: 1 step {b1['us_per_box']:.2f} us/box mean max "
                 f"{b1['mean_max_width']:.3g}, 5 steps {b5['mean_max_width']:.3g} proved "
                 f"{b5['proved_any_step']} (last step {b5['proved_last_step']})")
            if row["codac"]:
                s += "; codac " + ", ".join(
                    f"{mo} {r['us_per_box']:.1f} us/box mean max {r['mean_max_width']:.3g}"
                    for mo, r in row["codac"].items())
            log(s)
    return out


# ---------------------------------------------------------------------------------------------
# where the time goes


def breakdown(probs: list[Problem], a) -> dict:
    """Per problem (boxes at ``rel = 1e-2``) and for Broyden's system under ``CtcNewton``: the
    medians of the parts of one call, in µs per box: the Jacobian kernel over the boxes
    (``jacobian_sparse``, which also gives the natural values), the natural evaluation at the
    centres (``evaluate`` on degenerate boxes), the whole ``contract`` (the rest is the
    row-contraction kernel and glue), and ``CtcFwdBwd`` (one vectorised pass per tape node)."""
    from boundest import Interval
    from boundest.ctc.centered import CtcNewton
    from boundest.ctc.derivatives import evaluate, jacobian_sparse, midpoint

    def med(fn) -> float:
        fn()
        times = []
        for _ in range(a.repeat):
            t0 = time.perf_counter()
            fn()
            times.append(time.perf_counter() - t0)
        return statistics.median(times)

    out = {}
    cases = []
    for i, prob in enumerate(probs):
        lo, hi, *_ = boxes_for(prob, 1e-2, a.n, seed=100 * i + 1)
        ctcs = bd_contractors(prob)
        cases.append((prob.name, ctcs["centered_P"], Interval(lo, hi), ctcs["fwdbwd"]))
    name, exprs, _, _, n = newton_problems()[1]
    m, _ = bd_model(exprs, np.zeros(n), np.zeros(n))
    rng = np.random.default_rng(5)
    c0 = rng.uniform(-0.7, -0.4, (a.newton_n, n))
    cases.append((f"{name} (CtcNewton)", CtcNewton(m), Interval(c0 - 0.01, c0 + 0.01), None))
    for name, ctc, box, fb in cases:
        k = box.shape[0]
        c = midpoint(box)
        rec = {"boxes": k, "tape_nodes": len(ctc.tape.op), "n": ctc.n,
               "m": ctc.tape.n_outputs,
               "contract": med(lambda ctc=ctc, box=box: ctc.contract(box)),
               "jacobian_sparse": med(lambda ctc=ctc, box=box: jacobian_sparse(
                   ctc.tape, box, with_defined=True)),
               "evaluate_centres": med(lambda ctc=ctc, c=c: evaluate(ctc.tape, Interval(c, c)))}
        if fb is not None:
            rec["fwdbwd"] = med(lambda fb=fb, box=box: fb(box))
        rec = {key: (1e6 * v / k if isinstance(v, float) else v) for key, v in rec.items()}
        rec["rest"] = rec["contract"] - rec["jacobian_sparse"] - rec["evaluate_centres"]
        out[name] = rec
        log(f"breakdown {name}: " + ", ".join(f"{key} {v:.2f}" for key, v in rec.items()
                                                if isinstance(v, float)) + " us/box")
    return out


# ---------------------------------------------------------------------------------------------
# first use

FIRST_USE = """
import json, sys, time
t0 = time.perf_counter()
import numpy as np
from boundest import Interval
from boundest.ctc import CtcFwdBwd
from boundest.ctc.centered import CtcCentered
sys.path.insert(0, {here!r})
from bench_centered import bd_model, jaulin
t1 = time.perf_counter()
prob = jaulin()
m, names = bd_model(prob.exprs, prob.t_lo, prob.t_hi)
box = Interval(np.array([[0.9, 2.5, 3.0]] * 4), np.array([[0.91, 2.51, 3.01]] * 4))
t2 = time.perf_counter()
CtcCentered(m)(box)
t3 = time.perf_counter()
CtcFwdBwd(m, names)(box)
t4 = time.perf_counter()
print(json.dumps({{"import_s": t1 - t0, "centered_first_call_s": t3 - t2,
                  "fwdbwd_first_call_s": t4 - t3}}))
"""


def first_use() -> dict:
    res = {}
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, NUMBA_CACHE_DIR=tmp, BOUNDEST_KERNEL_ARCHIVE="0")
        for key in ("empty_cache", "filled_cache"):
            t0 = time.perf_counter()
            proc = subprocess.run([sys.executable, "-c", FIRST_USE.format(here=str(HERE))],
                                  env=env, capture_output=True, text=True, check=True)
            res[key] = {**json.loads(proc.stdout.strip().splitlines()[-1]),
                        "process_wall_s": time.perf_counter() - t0}
            log(f"first use, {key}: {res[key]}")
    return res


def _g(v, fmt: str = ".3g") -> str:
    return "-" if v is None else format(v, fmt)


def tables(doc: dict) -> str:
    """The Markdown tables of the README from a result document."""
    lines = []
    rows = doc.get("centered", {}).get("rows", {})
    main = "fwdbwd+centered_P"
    if rows:
        lines += ["| problem | rel. radius | boundest µs/box | Codac µs/box | Codac / boundest "
                  "time | median width ratio per component | mean max-width ratio | wider | "
                  "median excess where wider | narrower | lost (boundest / Codac) |",
                  "|---|---|---:|---:|---:|---|---:|---:|---:|---:|---|"]
        for r in rows.values():
            b, c = r["boundest"][main], r["codac"].get("default")
            v = r["vs_codac"].get(main)
            if not (c and v):
                continue
            med = ", ".join(f"{x:.3f}" for x in v["median_width_ratio"])
            lines.append(f"| {r['problem']} | {r['rel_radius']:g} | {b['us_per_box']:.1f} | "
                         f"{c['us_per_box']:.1f} | {v['time_ratio_codac_over_boundest']:.1f} | "
                         f"{med} | {v['mean_max_width_ratio']:.3f} | {v['frac_wider']:.3f} | "
                         f"{v['wider_components_median_excess']:.2g} | "
                         f"{v['frac_narrower']:.3f} | {b['lost']} / {c['lost']} |")
        lines += ["", "| problem | rel. radius | " + " | ".join(VARIANTS) + " |",
                  "|---|---|" + "---|" * len(VARIANTS)]
        for r in rows.values():
            if not r["vs_codac"]:
                continue
            cells = []
            for vname in VARIANTS:
                v = r["vs_codac"][vname]
                t = v["time_ratio_codac_over_boundest"]
                cells.append(f"{v['mean_max_width_ratio']:.3f} / {v['frac_wider']:.2f} / "
                             f"{v['frac_narrower']:.2f} / x{t:.1f}")
            lines.append(f"| {r['problem']} | {r['rel_radius']:g} | " + " | ".join(cells)
                         + " |")
        diag = [r for r in rows.values() if "diagnosis" in r]
        if diag:
            keys = [k for k, v in diag[0]["diagnosis"].items()
                    if isinstance(v, dict) and "mean_max_width_ratio" in v]
            lines += ["", "| problem | rel. radius | " + " | ".join(keys) + " |",
                      "|---|---|" + "---|" * len(keys)]
            for r in diag:
                d = r["diagnosis"]
                lines.append(f"| {r['problem']} | {r['rel_radius']:g} | " + " | ".join(
                    f"{d[k]['mean_max_width_ratio']:.3f} / {d[k]['frac_wider']:.2f}"
                    for k in keys) + " |")
    jac = [r for r in rows.values() if "jacobian_vs_codac" in r.get("diagnosis", {})]
    if jac:
        lines += ["", "| problem | rel. radius | Jacobian entries: median width ratio | wider | "
                  "narrower | boxes with a wider entry |", "|---|---|---:|---:|---:|---:|"]
        for r in jac:
            j = r["diagnosis"]["jacobian_vs_codac"]
            lines.append(f"| {r['problem']} | {r['rel_radius']:g} | "
                         f"{_g(j['median_width_ratio'], '.4f')} | {j['frac_wider']:.2f} | "
                         f"{j['frac_narrower']:.2f} | {j['boxes_any_entry_wider']:.2f} |")
    nrows = doc.get("newton", {}).get("rows", {})
    if nrows:
        lines += ["", "| system | rel. radius | boundest 1 step: µs/box, mean max width | "
                  "5 steps: µs/box, mean max width, proved | Codac one step | Codac default "
                  "(iterated) | lost (boundest 5 / Codac) |", "|---|---|---|---|---|---|---|"]
        for r in nrows.values():
            b1, b5 = r["boundest"]["steps_1"], r["boundest"]["steps_5"]
            c1, cd = r["codac"].get("one_step"), r["codac"].get("default")
            lines.append(
                f"| {r['problem']} | {r['rel_radius']:g} | {b1['us_per_box']:.1f}, "
                f"{b1['mean_max_width']:.3g} | {b5['us_per_box']:.1f}, {b5['mean_max_width']:.3g},"
                f" {b5['proved_any_step']}/{r['boxes']} | "
                + (f"{c1['us_per_box']:.1f}, {c1['mean_max_width']:.3g} | "
                   f"{cd['us_per_box']:.1f}, {cd['mean_max_width']:.3g} | "
                   f"{b5['lost']} / {c1['lost']}, {cd['lost']} |" if c1 and cd else "- | - | - |"))
    brk = doc.get("breakdown_us_per_box")
    if brk:
        lines += ["", "| problem | n, m, tape nodes | contract | jacobian_sparse | evaluate at "
                  "centres | rest (row kernel, glue) | CtcFwdBwd |", "|---|---|---:|---:|---:|"
                  "---:|---:|"]
        for name, r in brk.items():
            lines.append(f"| {name} | {r['n']}, {r['m']}, {r['tape_nodes']} | "
                         f"{r['contract']:.2f} | {r['jacobian_sparse']:.2f} | "
                         f"{r['evaluate_centres']:.2f} | {r['rest']:.2f} | "
                         f"{_g(r.get('fwdbwd'), '.2f')} |")
    fu = doc.get("first_use")
    if fu:
        lines += ["", "first use (fresh process): " + "; ".join(
            f"{k}: import {v['import_s']:.2f} s, CtcCentered first call "
            f"{v['centered_first_call_s']:.2f} s, CtcFwdBwd first call "
            f"{v['fwdbwd_first_call_s']:.2f} s" for k, v in fu.items())]
    return "\n".join(lines)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", help="also write the JSON here")
    ap.add_argument("--n", type=int, default=10000, help="boxes per problem and radius")
    ap.add_argument("--newton-n", type=int, default=5000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--codac-repeat", type=int, default=3)
    ap.add_argument("--problems", default="jaulin,range_only,satellite,katsura")
    ap.add_argument("--no-codac", action="store_true")
    ap.add_argument("--no-newton", action="store_true")
    ap.add_argument("--no-first-use", action="store_true")
    ap.add_argument("--no-centered", action="store_true")
    ap.add_argument("--no-breakdown", action="store_true")
    ap.add_argument("--diagnose", type=int, default=1000,
                    help="boxes per batch for the sweep replay (0: none)")
    ap.add_argument("--quick", action="store_true", help="1,000 boxes, 2 repeats")
    ap.add_argument("--table", metavar="JSON", help="only print the tables of a result file")
    a = ap.parse_args()
    if a.table:
        print(tables(json.loads(Path(a.table).read_text())))
        return 0
    if a.quick:
        a.n, a.newton_n, a.repeat, a.codac_repeat, a.diagnose = 1000, 500, 2, 1, 200

    import numba

    makers = {"jaulin": jaulin, "range_only": range_only, "satellite": satellite,
              "katsura": katsura}
    probs = [makers[p]() for p in a.problems.split(",")]
    doc: dict = {
        "benchmark": "centered", "started": time.strftime("%Y-%m-%dT%H:%M:%S"),
        "machine": {"cpu": cpu_model(), "cores": os.cpu_count(),
                    "python": platform.python_version(), "numpy": np.__version__,
                    "numba": numba.__version__},
        "loadavg_start": os.getloadavg(), "args": vars(a), "radii": list(RADII),
        "problems": {p.name: {"exprs": p.exprs, "targets": [[float(lo), float(hi)] for lo, hi
                                                             in zip(p.t_lo, p.t_hi,
                                                                    strict=True)],
                              "domain": [p.dom_lo.tolist(), p.dom_hi.tolist()]}
                     for p in probs}}
    if not a.no_centered:
        doc["centered"] = run_centered(probs, a)
    if not a.no_newton:
        doc["newton"] = run_newton(a)
    if not a.no_breakdown:
        doc["breakdown_us_per_box"] = breakdown(probs, a)
    if not a.no_first_use:
        doc["first_use"] = first_use()
    doc["loadavg_end"] = os.getloadavg()
    doc["summary"] = summary(doc) if "centered" in doc else {}
    emit(doc, a.out)
    log(tables(doc))
    return 0


def summary(doc: dict) -> dict:
    """One line per problem and radius: the main variant against Codac's default."""
    out = {}
    for key, row in doc["centered"]["rows"].items():
        rec = {}
        for v in ("fwdbwd+centered_P", "centered_P+fwdbwd", "centered_P", "centered"):
            c = row["vs_codac"].get(v)
            rec[v] = {"us_per_box": row["boundest"][v]["us_per_box"],
                      "lost": row["boundest"][v]["lost"]}
            if c:
                rec[v].update({k: c[k] for k in ("median_width_ratio", "mean_max_width_ratio",
                                                  "frac_wider", "frac_narrower",
                                                  "time_ratio_codac_over_boundest")})
        if row["codac"]:
            rec["codac_default"] = {k: row["codac"]["default"][k]
                                    for k in ("us_per_box", "lost", "empty_random_boxes")}
        out[key] = rec
    all_rows = [r for r in doc["centered"]["rows"].values() if r["vs_codac"]]
    if all_rows:
        main = "fwdbwd+centered_P"
        out["all"] = {
            "max_frac_wider": max(r["vs_codac"][main]["frac_wider"] for r in all_rows),
            "min_time_ratio": min(r["vs_codac"][main]["time_ratio_codac_over_boundest"]
                                  for r in all_rows),
            "lost_boundest": sum(r["boundest"][v]["lost"] for r in all_rows for v in VARIANTS),
            "lost_codac": sum(r["codac"][m]["lost"] for r in all_rows for m in r["codac"]),
        }
    return out


if __name__ == "__main__":
    sys.exit(main())
