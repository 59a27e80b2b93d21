"""The drifting clock of Rohou et al. 2018 (section 5): data, truth, soundness and the paper's
results."""

from __future__ import annotations

import json

import mpmath
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from boundest.scenarios import drifting_clock as dc
from boundest.scenarios._data import DataError

mpmath.mp.dps = 50


def _root(a, b, tau) -> mpmath.mpf:
    """The exact reference time: the positive root of ``a t^2 + b t = tau`` (mpmath, 50 digits;
    ``a``, ``b``, ``tau`` are taken exactly: floats, or decimal strings)."""
    a, b, tau = mpmath.mpf(a), mpmath.mpf(b), mpmath.mpf(tau)
    return 2 * tau / (b + mpmath.sqrt(b * b + 4 * a * tau))


def _inside(x: mpmath.mpf, lo: float, hi: float) -> bool:
    return mpmath.mpf(lo) <= x <= mpmath.mpf(hi)


def _assert_truth_inside(res: dc.ClockResult, truth: dc.ClockTruth) -> None:
    t = res.h.t
    rng = np.random.default_rng(0)
    s = np.concatenate([t, (t[:-1] + t[1:]) / 2,
                        t[:-1] + rng.uniform(0, 1, t.size - 1) * np.diff(t)])
    assert res.h.contains(s, truth.drift(s)), "true drift outside [h]"
    assert res.y.contains(s, truth.distance(s)), "true distance outside [y]"


# -- data -----------------------------------------------------------------------------------
def test_embedded_table_2():
    m = dc.load()
    assert len(m) == 8
    assert m.tau.lo[0] < 1.57 < m.tau.hi[0] and m.z.lo[7] < 175.88 < m.z.hi[7] < 179.89


@pytest.mark.parametrize(("rows", "message"), [
    ("1,1.5,3,2\n", r"clock\.csv:2: z_lo = 3\.0 is above z_hi = 2\.0"),
    ("1,1.5,1,2\n2,-1,1,2\n", r"clock\.csv:3: tau = -1\.0 is negative"),
    ("1,1.5,1,2\n\n2,1,-2,-1\n", r"clock\.csv:4: z_hi = -1\.0 is negative"),
    ("1,abc,1,2\n", r"clock\.csv:2: column tau: not a number: 'abc'"),
    ("1,nan,1,2\n", r"clock\.csv:2: column tau: non-finite value 'nan'"),
])
def test_bad_data(tmp_path, rows, message):
    p = tmp_path / "clock.csv"
    p.write_text("i,tau,z_lo,z_hi\n" + rows)
    with pytest.raises(DataError, match=message):
        dc.load(p)


def test_domain_must_hold_every_reference_time():
    with pytest.raises(ValueError, match="too short"):
        dc.solve(tf=8.0)


# -- the truth of the seed -----------------------------------------------------------------
def test_seed_truth_fits_table_2_and_the_model():
    truth, m = dc.ClockTruth(), dc.load()
    tau = ["1.57", "3.34", "5.32", "7.50", "9.88", "12.46", "15.25", "18.24"]
    for i, s in enumerate(tau):
        t_i = _root("0.045", "0.98", s)
        assert abs(t_i - 1.5 * (i + 1)) < 0.005 / 0.98  # tau rounded to 0.01
        assert m.z.contains(truth.distance(float(t_i)))[i]
    s = np.linspace(0, 13, 1301)
    assert dc.rate_tube(s).contains(s, truth.drift_rate(s))
    x, v = dc.ephemeris(s)
    assert x.contains(s, truth.boat(s)) and v.contains(s, truth.boat_velocity(s))


def test_seed_truth_inside_every_domain():
    """Rohou et al. 2018 section 5: the real drift (eq. 16) stays in [h]; every exact reference time
    h^{-1}(tau_i) stays in its contracted [t_i]."""
    res = dc.solve()
    assert res.consistent and res.converged
    _assert_truth_inside(res, dc.ClockTruth())
    tau = ["1.57", "3.34", "5.32", "7.50", "9.88", "12.46", "15.25", "18.24"]
    for i, s in enumerate(tau):
        assert _inside(_root("0.045", "0.98", s), res.t.lo[i], res.t.hi[i]), f"t_{i + 1}"


# -- soundness on simulations ---------------------------------------------------------------
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 2**32 - 1), st.sampled_from([0.01, 0.05]))
def test_simulated_truth_inside_every_domain(seed, dt):
    truth, _, meas = dc.simulate(seed)
    res = dc.solve(meas, dt=dt)
    assert res.consistent and res.converged
    _assert_truth_inside(res, truth)
    a, b = truth.h
    for i in range(len(meas)):
        t_exact = _root(a, b, float(meas.tau.lo[i]))  # tau_i is a float: exact root
        assert _inside(t_exact, res.t.lo[i], res.t.hi[i]), f"t_{i + 1}"
        assert _inside(t_exact, res.t_initial.lo[i], res.t_initial.hi[i])
        assert res.z.contains(truth.distance(float(t_exact)))[i]
    assert np.all(res.t.is_subset(res.t_initial)) and np.all(res.z.is_subset(meas.z))


def test_inconsistent_distance_is_proven_empty():
    meas = dc.load()
    meas.z.lo[2] -= 60.0  # 42-46 m: the boat is 100-110 m away whenever h(t) = 5.32
    meas.z.hi[2] -= 60.0
    res = dc.solve(meas)
    assert res.empty and not res.consistent


# -- the paper's results ---------------------------------------------------------------------
def test_seed_results():
    """Rohou et al. 2018 section 5: the fixed point within a few iterations (5 in the paper),
    every [t_i]
    after the first contracted by the ephemeris (Fig. 12), [h] thin (Fig. 12: about 1 s)."""
    res = dc.solve()
    assert res.converged and res.iterations <= 10
    w0, w = res.t_initial.width(), res.t.width()
    assert np.all(w <= w0) and np.all(w[1:] < 0.6 * w0[1:])
    assert float(np.max(w)) < 0.5
    assert float(np.max(res.h.gates.width())) < 2.0


def test_cli_json_and_figures(tmp_path):
    from boundest.cli import main

    out = tmp_path / "clock.json"
    assert main(["run", "drifting-clock", "--json", str(out), "--out", str(tmp_path)]) == 0
    data = json.loads(out.read_text())
    assert data["iterations"] >= 1 and data["time_s"] > 0
    assert len(data["t"]) == len(data["h_lo"]) == len(data["h_hi"])
    assert len(data["t_i_lo"]) == len(data["t_i_hi"]) == 8
    assert data["h_lo"][0] == data["h_hi"][0] == 0.0
    assert (tmp_path / "clock_distance.png").stat().st_size > 0
    assert (tmp_path / "clock_drift.png").stat().st_size > 0
