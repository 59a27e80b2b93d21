"""The simulated AUV survey: its boxes contain its truth, the truth obeys the model exactly."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from boundest.interval import Interval
from boundest.scenarios.auv_data import AuvData
from boundest.scenarios.auv_sim import (
    HALF_WIDTH,
    AuvTruth,
    integrate,
    rotation,
    simulate_survey,
    step,
)

CASES = [(0, 6000, 4, 3), (1, 6000, 4, 3), (7, 12000, 6, 5), (3, 60000, 4, 3), (11, 30000, 3, 4)]
IDS = [f"seed{s}-n{n}-legs{lg}-mines{m}" for s, n, lg, m in CASES]


@cache
def survey(seed: int, n: int, legs: int, mines: int) -> tuple[AuvData, AuvTruth]:
    return simulate_survey(seed=seed, n_samples=n, n_legs=legs, n_mines=mines)


@pytest.fixture(params=CASES, ids=IDS)
def case(request) -> tuple[AuvData, AuvTruth]:
    return survey(*request.param)


def _rotation_from_matrices(att: np.ndarray) -> np.ndarray:
    """``R_psi R_theta R_phi`` as the product of the three matrices of the data definition."""
    phi, theta, psi = att[:, 0], att[:, 1], att[:, 2]
    o, z = np.ones_like(phi), np.zeros_like(phi)
    r_psi = np.array([[np.cos(psi), -np.sin(psi), z], [np.sin(psi), np.cos(psi), z], [z, z, o]])
    r_theta = np.array([[np.cos(theta), z, np.sin(theta)], [z, o, z],
                        [-np.sin(theta), z, np.cos(theta)]])
    r_phi = np.array([[o, z, z], [z, np.cos(phi), -np.sin(phi)], [z, np.sin(phi), np.cos(phi)]])
    to_k = (2, 0, 1)
    return (r_psi.transpose(to_k) @ r_theta.transpose(to_k)) @ r_phi.transpose(to_k)


def _sensor_pairs(data: AuvData, truth: AuvTruth):
    """(name, box, truth, half-width) of every sensor quantity."""
    out = []
    for i, q in enumerate(("phi", "theta", "psi")):
        out.append((q, data.attitude[:, i], truth.attitude[:, i], HALF_WIDTH[q]))
    for i, q in enumerate(("vx", "vy", "vz")):
        out.append((q, data.velocity[:, i], truth.velocity[:, i], HALF_WIDTH[q]))
    out.append(("a", data.altitude, truth.altitude, HALF_WIDTH["a"]))
    out.append(("depth", data.depth, truth.p[:, 2], HALF_WIDTH["depth"]))
    return out


def test_structure_like_the_loader(case):
    data, truth = case
    n = data.n
    assert isinstance(data.attitude, Interval) and data.attitude.shape == (n, 3)
    assert data.velocity.shape == (n, 3)
    assert data.altitude.shape == (n,) and data.depth.shape == (n,)
    assert data.fix.shape == (2, 3) and data.fix_k.tolist() == [0, n - 1]
    m = data.det_k.size
    assert data.det_range.shape == (m,) and data.det_mine.shape == (m,)
    assert data.det_k.dtype == np.intp and data.det_mine.dtype == np.intp
    assert np.all(np.diff(data.det_k) >= 0)
    assert data.seabed_tol == 0.5 and data.source.startswith("<simulated seed=")
    assert truth.p.shape == truth.attitude.shape == truth.velocity.shape == (n, 3)
    assert truth.altitude.shape == (n,) and truth.mines.shape == (data.n_mines, 3)


def test_every_box_contains_the_truth(case):
    data, truth = case
    for name, box, true, half in _sensor_pairs(data, truth):
        assert box.contains(true).all(), name
        np.testing.assert_allclose(box.rad(), half, rtol=1e-9, err_msg=name)
    assert data.fix.contains(truth.p[data.fix_k]).all()
    np.testing.assert_allclose(data.fix.rad()[:, :2], HALF_WIDTH["gps"], rtol=1e-12)
    assert data.fix.lo[:, 2].tolist() == [0.0, 0.0] and data.fix.hi[:, 2].tolist() == [0.8, 0.8]
    r = np.linalg.norm(truth.mines[data.det_mine] - truth.p[data.det_k], axis=1)
    assert data.det_range.contains(r).all()
    np.testing.assert_allclose(data.det_range.rad(), HALF_WIDTH["range"], rtol=1e-12)


def test_rotation_is_the_product_of_the_given_matrices():
    rng = np.random.default_rng(0)
    att = rng.uniform(-4, 4, size=(500, 3))
    np.testing.assert_allclose(rotation(att), _rotation_from_matrices(att), atol=1e-15)
    R = rotation(att)
    np.testing.assert_allclose(R @ R.transpose(0, 2, 1), np.broadcast_to(np.eye(3), R.shape),
                               atol=1e-15)


def test_kinematics_hold_exactly(case):
    data, truth = case
    p, att, v = truth.p, truth.attitude, truth.velocity
    # bit for bit: the float recursion of the simulator's own step
    inc = step(att[:-1], v[:-1], data.dt)
    assert np.array_equal(p[1:], p[:-1] + inc)
    assert np.array_equal(integrate(p[0], inc), p)
    # to 1e-9 m with an independent rotation and product
    R = _rotation_from_matrices(att[:-1])
    resid = p[1:] - p[:-1] - data.dt * (R @ v[:-1, :, None])[..., 0]
    assert np.abs(resid).max() <= 1e-9


def test_detections_satisfy_the_three_constraints(case):
    data, truth = case
    counts = np.bincount(data.det_mine, minlength=data.n_mines)
    assert counts.size == data.n_mines and counts.min() >= 1 and counts.max() <= 3
    assert counts.sum() > data.n_mines  # some mines are seen more than once
    d = truth.mines[data.det_mine] - truth.p[data.det_k]
    body = (_rotation_from_matrices(truth.attitude[data.det_k]).transpose(0, 2, 1)
            @ d[..., None])[..., 0]
    assert np.abs(body[:, 0]).max() <= 1e-9  # (1): in the body y-z plane ...
    assert np.all(body[:, 1] >= 0) and np.all(body[:, 2] >= 0)  # ... starboard, below
    r = np.linalg.norm(d, axis=1)
    assert data.det_range.contains(r).all() and r.min() >= 10 and r.max() <= 50  # (2)
    gap = truth.mines[data.det_mine, 2] - truth.p[data.det_k, 2] - truth.altitude[data.det_k]
    assert np.abs(gap).max() <= data.seabed_tol  # (3)
    # the detections of one mine are separate passes, not neighbouring samples
    for j in range(data.n_mines):
        assert np.all(np.diff(data.det_k[data.det_mine == j]) > 100)


def test_errors_bounded_and_not_centred(case):
    data, truth = case
    means = {}
    for name, box, true, half in _sensor_pairs(data, truth):
        err = box.mid() - true
        assert np.abs(err).max() <= 0.97 * half + 1e-15 * (1 + np.abs(true).max()), name
        means[name] = float(np.mean(err / half))
        assert np.std(err / half) > 0.01, name  # not a constant offset only
    assert max(abs(m) for m in means.values()) > 0.1, means
    assert sum(abs(m) > 0.05 for m in means.values()) >= 3, means
    gps = data.fix.mid()[:, :2] - truth.p[data.fix_k, :2]
    assert np.abs(gps).max() <= 0.97 * HALF_WIDTH["gps"] and np.abs(gps).min() > 0
    r = np.linalg.norm(truth.mines[data.det_mine] - truth.p[data.det_k], axis=1)
    r_err = data.det_range.mid() - r
    assert np.abs(r_err).max() <= 0.97 * HALF_WIDTH["range"] and np.abs(r_err).min() > 0


def test_trajectory_shape(case):
    data, truth = case
    p, att, v = truth.p, truth.attitude, truth.velocity
    assert 0 <= p[0, 2] <= 0.8 and 0 <= p[-1, 2] <= 0.8  # surface at both GPS fixes
    assert np.mean(np.abs(p[:, 2] - 5.0) < 0.5) > 0.7  # mostly at the survey depth
    assert p[:, 2].min() >= 0 and p[:, 2].max() < 5.5
    psi = att[:, 2]
    assert np.abs(np.diff(psi)).max() < 0.1  # unwrapped: continuous
    # legs: the heading alternates between two directions pi apart
    rel = psi - psi[data.n // 2 // 10]  # during the first leg, after the dive
    label = np.where(np.abs(np.cos(rel) - 1) < 0.1, 0, np.where(np.abs(np.cos(rel) + 1) < 0.1,
                                                                 1, -1))
    runs = label[label >= 0]
    turns = int(np.count_nonzero(np.diff(runs)))
    assert turns >= 2
    assert np.ptp(psi) > 0.8 * np.pi
    speed = np.linalg.norm(v, axis=1)
    assert speed.min() > 1.2 and speed.max() < 1.8
    assert np.abs(v[:, 1]).max() > 0.05  # crab in the current
    assert np.abs(att[:, 0]).max() < 0.1 and np.abs(att[:, 1]).max() < 0.3
    legs = np.abs(p[:, 2] - 5.0) < 0.2
    assert np.abs(att[~legs, 1]).max() > 2 * np.abs(att[legs, 1]).max()  # pitch in the dive
    assert np.all(truth.altitude > 5)  # water of about 15 m


def test_legs_count_heading_reversals():
    _, truth = survey(7, 12000, 6, 5)
    psi = truth.attitude[:, 2]
    rel = psi - psi[600]
    near = np.abs(np.cos(rel)) > 0.99
    side = np.cos(rel[near]) > 0
    assert int(np.count_nonzero(np.diff(side))) == 5  # 6 legs, 5 turns


def test_deterministic_for_a_seed():
    a, ta = simulate_survey(seed=5, n_samples=5000)
    b, tb = simulate_survey(seed=5, n_samples=5000)
    _, tc = simulate_survey(seed=6, n_samples=5000)
    assert np.array_equal(ta.p, tb.p) and np.array_equal(a.attitude.lo, b.attitude.lo)
    assert np.array_equal(a.det_k, b.det_k) and np.array_equal(ta.mines, tb.mines)
    assert not np.array_equal(ta.p, tc.p)
    assert a.source == "<simulated seed=5>"


def test_no_mines_and_too_short():
    data, truth = simulate_survey(n_mines=0)
    assert data.det_k.size == 0 and truth.mines.shape == (0, 3)
    with pytest.raises(ValueError, match="too few"):
        simulate_survey(n_samples=2000)
