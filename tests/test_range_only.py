"""The range-only robot of Rohou et al. 2018 (section 4): data, truth, soundness and the paper's
results."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from boundest.scenarios import range_only as ro
from boundest.scenarios._data import DataError

COARSE = 0.1  # slice duration of the soundness tests (the paper's results: dt = 0.01)


def _rk4(truth: ro.RobotTruth, t_end: float, h: float = 1e-3) -> np.ndarray:
    """An independent integration of equation 13 (classical RK4, all four states)."""
    def f(s: float, x: np.ndarray) -> np.ndarray:
        u = truth.inputs(np.array([s]))[0]
        return np.array([x[3] * math.cos(x[2]), x[3] * math.sin(x[2]), u[0], u[1]])
    x, s = np.array(truth.x0, dtype=float), 0.0
    for _ in range(round(t_end / h)):
        k1 = f(s, x)
        k2 = f(s + h / 2, x + h / 2 * k1)
        k3 = f(s + h / 2, x + h / 2 * k2)
        k4 = f(s + h, x + h * k3)
        x, s = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4), s + h
    return x


def _samples(tube, rng: np.random.Generator) -> np.ndarray:
    """Every gate time, every slice midpoint and one random time in every slice."""
    t = tube.t
    inner = t[:-1] + rng.uniform(0.0, 1.0, t.size - 1) * np.diff(t)
    return np.concatenate([t, (t[:-1] + t[1:]) / 2, inner])


def _assert_truth_inside(res: ro.RangeOnlyResult, truth: ro.RobotTruth, seed: int = 0) -> None:
    rng = np.random.default_rng(seed)
    s = _samples(res.x, rng)
    x = truth.states(s)
    assert res.x.contains(s, x), "true state outside [x]"
    assert res.v.contains(s, truth.velocities(s)), "true derivative outside [v]"
    b = (res.meas.beacons.lo + res.meas.beacons.hi) / 2
    dist = np.hypot(x[:, None, 0] - b[None, :, 0], x[:, None, 1] - b[None, :, 1])
    assert res.y.contains(s, dist), "true distances outside [y]"
    # derivative of the distance: (x - b).v / |x - b|
    v = truth.velocities(s)
    rate = ((x[:, None, 0] - b[None, :, 0]) * v[:, None, 0]
            + (x[:, None, 1] - b[None, :, 1]) * v[:, None, 1]) / dist
    assert res.w.contains(s, rate), "true distance rates outside [w]"


# -- data -----------------------------------------------------------------------------------
def test_embedded_table_1():
    m = ro.load()
    assert len(m) == 11
    assert m.beacon_names == ["alpha", "beta", "gamma"]
    assert m.beacon.tolist() == [1, 0, 0, 0, 0, 0, 2, 2, 2, 2, 1]
    # the decimals of the file lie inside the parsed intervals
    assert m.t.lo[0] < 14.75 <= m.t.hi[0] and m.z.lo[10] <= 18.45 < m.z.hi[10]
    assert bool(m.beacons[1].contains(np.array([80.0, -5.0])).all())


def _write(tmp_path, rows: str, beacons: str = "beacon,bx,by\na,0,0\nb,10,0\n"):
    p, q = tmp_path / "meas.csv", tmp_path / "beacons.csv"
    p.write_text("i,beacon,t_lo,t_hi,z_lo,z_hi\n" + rows)
    q.write_text(beacons)
    return p, q


@pytest.mark.parametrize(("rows", "beacons", "message"), [
    ("1,c,1,2,3,4\n", None, r"meas\.csv:2: unknown beacon 'c'"),
    ("1,a,1,2,3,4\n2,a,2,1,3,4\n", None, r"meas\.csv:3: t_lo = 2\.0 is above t_hi"),
    ("1,a,1,2,x,4\n", None, r"meas\.csv:2: column z_lo: not a number: 'x'"),
    ("1,a,60,65,3,4\n", None, r"meas\.csv:2: time interval \[60\.0, 65\.0\] is outside"),
    ("1,a,1,2,-3,-2\n", None, r"meas\.csv:2: z_hi = -2\.0 is negative"),
    ("1,a,1,2,3,4\n", "beacon,bx,by\na,0,0\na,1,1\n", r"beacons\.csv:3: beacon 'a' defined twice"),
    ("1,a,1,2,3,4\n", "beacon,bx\na,0\n", r"beacons\.csv:1: missing column\(s\) by"),
])
def test_bad_data(tmp_path, rows, beacons, message):
    p, q = _write(tmp_path, rows, *([beacons] if beacons else []))
    with pytest.raises(DataError, match=message):
        ro.load(p, q)


# -- the truth ------------------------------------------------------------------------------
def test_truth_matches_an_independent_integration():
    truth = ro.simulate(3)[0]
    for t_end in (7.0, 23.5):
        assert np.allclose(truth.states(np.array([t_end]))[0], _rk4(truth, t_end), atol=1e-7)


def test_seed_truth_meets_every_measurement_of_table_1():
    m, truth = ro.load(), ro.RobotTruth()
    b = (m.beacons.lo + m.beacons.hi) / 2
    for i in range(len(m)):
        s = np.linspace(m.t.lo[i], m.t.hi[i], 2001)
        d = np.hypot(*(truth.states(s)[:, :2] - b[m.beacon[i]]).T)
        assert np.any((d >= m.z.lo[i]) & (d <= m.z.hi[i])), f"measurement {i + 1}"


def test_simulated_measurements_hold_the_truth():
    truth, t_true, m = ro.simulate(5)
    assert np.all(m.t.contains(t_true))
    b = (m.beacons.lo + m.beacons.hi) / 2
    d = np.hypot(*(truth.states(t_true)[:, :2] - b[m.beacon]).T)
    assert np.all(m.z.contains(d))
    u = truth.inputs(np.linspace(0, 64, 1001))
    assert bool(ro.input_tube(np.linspace(0, 64, 1001)).contains(np.linspace(0, 64, 1001), u))


# -- soundness ------------------------------------------------------------------------------
@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 2**32 - 1))
def test_simulated_truth_inside_every_domain(seed):
    truth, t_true, meas = ro.simulate(seed)
    res = ro.solve(meas, dt=COARSE, progress=False)
    assert res.consistent and res.converged
    _assert_truth_inside(res, truth, seed)
    assert np.all(res.t.contains(t_true)), "a true measurement time left its [t_i]"
    b = (meas.beacons.lo + meas.beacons.hi) / 2
    d = np.hypot(*(truth.states(t_true)[:, :2] - b[meas.beacon]).T)
    assert np.all(res.z.contains(d)), "a true range left its [z_i]"
    assert np.all(res.t.is_subset(meas.t)) and np.all(res.z.is_subset(meas.z))


def test_wider_time_uncertainty_still_sound():
    truth, t_true, meas = ro.simulate(11, t_width=2.0, z_width=0.5)
    res = ro.solve(meas, dt=COARSE, progress=False)
    assert res.consistent
    _assert_truth_inside(res, truth)
    assert np.all(res.t.contains(t_true))


def test_wide_time_uncertainty_is_contracted():
    """With 4-s time intervals and 0.1-m ranges, the first measurements' [t_i] shrink (and keep
    the true times)."""
    truth, t_true, meas = ro.simulate(0, t_width=4.0, z_width=0.1)
    res = ro.solve(meas, dt=0.05, progress=False)
    assert res.consistent
    assert np.all(res.t.contains(t_true))
    assert np.sum(res.t.width() < 0.9 * meas.t.width()) >= 2
    _assert_truth_inside(res, truth)


def test_dead_reckoning_is_final_after_its_own_fixed_point():
    """The decomposition of ``solve``: the position network leaves the heading, the speed and
    [v] untouched, and one more pass of the whole network contracts nothing noticeable."""
    meas = ro.load()
    net = ro._network(meas, ro.time_grid(ro.T0, ro.TF, COARSE))
    assert net.dead_reckoning.contract(rel_eps=1e-4, progress=False).converged
    before = [a.copy() for a in (net.x.slices.lo[:, 2:], net.x.slices.hi[:, 2:], net.v.gates.lo,
                                 net.v.gates.hi, net.v.slices.lo, net.v.slices.hi)]
    assert net.position.contract(rel_eps=1e-4, max_iter=200, progress=False).converged
    after = (net.x.slices.lo[:, 2:], net.x.slices.hi[:, 2:], net.v.gates.lo, net.v.gates.hi,
             net.v.slices.lo, net.v.slices.hi)
    assert all(np.array_equal(a, b) for a, b in zip(before, after, strict=True))
    rep = net.dead_reckoning.contract(rel_eps=1e-4, max_iter=1, progress=False)
    assert rep.converged and rep.contraction[0] < 1e-4


@pytest.mark.parametrize("seed", [1, 7])
def test_product_rate_form_tightens_and_keeps_the_truth(seed):
    """The product form ``w y = (x12 - b).v12`` added to the bearing form: the truth stays in
    every domain, and the position tube is narrower on average."""
    truth, t_true, meas = ro.simulate(seed)
    both = ro.solve(meas, dt=COARSE, progress=False, rate="both")
    bearing = ro.solve(meas, dt=COARSE, progress=False, rate="bearing")
    for res in (both, bearing):
        assert res.consistent and res.converged
        _assert_truth_inside(res, truth, seed)
        assert np.all(res.t.contains(t_true))
    db, dr = both.position_diagonal(), bearing.position_diagonal()
    assert np.mean(db) < np.mean(dr)
    assert both.to_json()["rate_forms"] == "both" and bearing.to_json()["rate_forms"] == "bearing"


def test_unknown_rate_form_is_refused():
    with pytest.raises(ValueError, match="rate must be one of both, bearing"):
        ro.solve(dt=COARSE, rate="quotient")


def test_inconsistent_range_is_proven_empty():
    meas = ro.load()
    meas.z.lo[3] += 30.0  # beacon alpha at 41-42 m: the robot is never that far at t = 27 s
    meas.z.hi[3] += 30.0
    res = ro.solve(meas, dt=COARSE, progress=False)
    assert res.empty and not res.consistent


# -- the paper's results ---------------------------------------------------------------------
def test_seed_results_at_dt_001():
    """Rohou et al. 2018 Fig. 8: fixed point reached (52 iterations in the paper), the position-box
    diagonal of the order of 10 m (5-30 m over the mission in Fig. 8), the truth inside."""
    res = ro.solve(dt=0.01, progress=False)
    assert res.consistent and res.converged and res.iterations < 52
    d = res.position_diagonal()
    assert 3.0 < float(np.mean(d)) < 20.0 and float(np.max(d)) < 60.0
    assert np.all(np.diff([np.mean(r) for r in res.diag]) <= 0)  # monotone contraction
    _assert_truth_inside(res, ro.RobotTruth())


def test_cli_json_and_figures(tmp_path):
    from boundest.cli import main

    out = tmp_path / "res.json"
    assert main(["run", "range-only", "--dt", "0.1", "--json", str(out),
                 "--out", str(tmp_path / "figs")]) == 0
    data = json.loads(out.read_text())
    n = round(64 / 0.1)
    assert data["iterations"] >= 1 and data["time_s"] > 0
    assert len(data["t"]) == n + 1 and np.array(data["x_lo"]).shape == (n + 1, 4)
    assert len(data["t_lo"]) == len(data["z_hi"]) == 11
    assert len(data["diag"]) == data["iterations"]
    assert np.all(np.array(data["x_lo"]) <= np.array(data["x_hi"]))
    assert (tmp_path / "figs" / "range_only_diagonal.png").stat().st_size > 0
    assert (tmp_path / "figs" / "range_only_map.png").stat().st_size > 0
