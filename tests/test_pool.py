"""The pool robot data (loader, model, binomial bound) and its simulator."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from boundest.scenarios._data import DataError, embedded
from boundest.scenarios.pool_data import PoolData, binomial_bound, euler_step, load_pool
from boundest.scenarios.pool_sim import simulate_pool

FILES = ("pool_setup.json", "pool_inputs.csv", "pool_sonar.csv", "pool_map.json")


# -- loader ---------------------------------------------------------------------------------
def test_embedded_data_load():
    d = load_pool()
    assert isinstance(d, PoolData) and d.n == 406 and d.n_missions is None
    assert d.inputs.shape == (406, 2) and d.ranges.shape == (406,) and d.x0.shape == (4,)
    assert d.alpha.shape == (406,) and d.t0 == 0.0 and d.dt == 0.04
    assert d.p_outlier == 0.05 and d.max_range == 30.0 and d.map.n_obstacles == 6
    k = np.arange(406)
    assert np.abs(d.alpha - np.mod(k * np.pi / 40, 2 * np.pi)).max() < 1e-12
    box = [(2.153, 3.154), (1.435, 2.436), (0.272, 0.473), (-0.036, 0.065)]
    for i, (lo, hi) in enumerate(box):
        assert d.x0.lo[i] < lo < d.x0.hi[i] and d.x0.lo[i] < hi < d.x0.hi[i]
        assert d.x0.lo[i] == np.nextafter(lo, -np.inf) and d.x0.hi[i] == np.nextafter(hi, np.inf)
    # decimal bounds one ulp outward
    assert d.inputs.lo[0, 0] == np.nextafter(0.64303, -np.inf)
    assert d.ranges.hi[0] == np.nextafter(18.7973, np.inf)
    assert "samples=406" in repr(d)


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    for name in FILES:
        shutil.copy(embedded(name), tmp_path / name)
    return tmp_path


def _edit(path: Path, line: int, new: str) -> None:
    """Replace 1-based line ``line`` of ``path`` with ``new``."""
    lines = path.read_text().split("\n")
    lines[line - 1] = new
    path.write_text("\n".join(lines))


def test_copied_folder_loads_the_same(folder):
    a, b = load_pool(), load_pool(folder)
    assert np.array_equal(a.inputs.lo, b.inputs.lo) and np.array_equal(a.alpha, b.alpha)
    assert b.source == str(folder)


@pytest.mark.parametrize(("file", "line", "row", "needle"), [
    ("pool_inputs.csv", 6, "0.16,0.6,0.7,0.4,0.5,9", "6: expected 5 fields"),
    ("pool_inputs.csv", 6, "0.08,0.6,0.7,0.4,0.5", "6: k = 2.0, expected 4"),
    ("pool_sonar.csv", 6, "0.17,0.3,1.0,1.2", "6: t = 0.17 is not a sample time"),
    ("pool_sonar.csv", 6, "0.16,nan,1.0,1.2", "6: column alpha: non-finite value 'nan'"),
    ("pool_sonar.csv", 6, "0.16,0.3,1.3,1.2", "6: d_lo = 1.3 is above d_hi = 1.2"),
    ("pool_inputs.csv", 6, "0.16,0.8,0.7,0.4,0.5", "6: u1_lo = 0.8 is above u1_hi = 0.7"),
])
def test_bad_rows(folder, file, line, row, needle):
    _edit(folder / file, line, row)
    with pytest.raises(DataError) as exc:
        load_pool(folder)
    msg = str(exc.value)
    assert "\n" not in msg and f"{file}:" in msg and needle in msg


def test_extra_column(folder):
    p = folder / "pool_sonar.csv"
    p.write_text(p.read_text().replace("t,alpha,d_lo,d_hi", "t,alpha,d_lo,d_hi,q", 1))
    with pytest.raises(DataError, match=r"pool_sonar\.csv:1: unexpected column 'q'"):
        load_pool(folder)


def test_row_count(folder):
    p = folder / "pool_inputs.csv"
    lines = p.read_text().rstrip("\n").split("\n")
    p.write_text("\n".join(lines[:-1]) + "\n")  # drop the last row
    with pytest.raises(DataError, match=r"pool_inputs\.csv:406: 405 rows, but pool_setup\.json "
                                        r"says n_samples = 406"):
        load_pool(folder)
    p.write_text("\n".join([*lines, "16.24,0,0,0,0"]) + "\n")  # one row too many
    with pytest.raises(DataError, match=r"pool_inputs\.csv:408: 407 rows"):
        load_pool(folder)


def test_bad_json(folder):
    p = folder / "pool_setup.json"
    text = p.read_text()
    p.write_text(text.replace('"dt": 0.04,', '"dt": 0.04', 1))
    with pytest.raises(DataError, match=r"pool_setup\.json:\d+: not JSON"):
        load_pool(folder)
    p.write_text(text.replace('"n_samples": 406', '"n_samples": "x"', 1))
    with pytest.raises(DataError, match=r"pool_setup\.json: n_samples must be a finite number, "
                                        r"got 'x'"):
        load_pool(folder)
    p.write_text(text.replace('"outlier_probability": 0.05,', '', 1))
    with pytest.raises(DataError, match=r"missing key sonar\.outlier_probability"):
        load_pool(folder)


def test_bad_map(folder):
    (folder / "pool_map.json").write_text('{"walls": [}')
    with pytest.raises(DataError, match=r"pool_map\.json:1: not JSON"):
        load_pool(folder)


# -- model ----------------------------------------------------------------------------------
def test_binomial_bound_table():
    table = {6: 0.894715, 8: 0.981597, 10: 0.997901, 12: 0.999836}
    for q, p in table.items():
        assert round(binomial_bound(80, q, 0.05), 6) == p
    assert binomial_bound(80, 80, 0.05) == 1.0 and binomial_bound(80, -1, 0.05) == 0.0
    assert binomial_bound(3, 0, 0.5) == 0.125


def test_euler_step_vectorised():
    x = np.array([[1.0, 2.0, 0.5, 0.3], [0.0, 0.0, -1.0, 2.0]])
    u = np.array([0.2, 0.7])
    out = euler_step(x, u, 0.04)
    th, v = x[:, 2], x[:, 3]
    expected = x + 0.04 * np.stack([v * np.cos(th), v * np.sin(th), np.full(2, 0.7 - 0.2),
                                    (0.2 + 0.7) - v], axis=-1)
    assert np.array_equal(out, expected)
    assert euler_step(x[0], u, 0.04).shape == (4,)


# -- simulator ------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def batch():
    return simulate_pool(seed=3, n_missions=200)


def test_simulated_mission_is_consistent(batch):
    data, truth = batch
    assert data.n_missions == 200 and truth.states.shape == (200, 406, 4)
    inl = ~truth.outlier
    assert np.all(data.inputs.contains(truth.inputs))
    assert np.all(data.ranges.contains(truth.distance)[inl])
    assert np.all(data.x0.contains(truth.states[:, 0])) and np.all(truth.states[:, 0, 3] == 0)
    # explicit Euler recursion, bit for bit
    assert np.array_equal(truth.states[:, 1:],
                          euler_step(truth.states[:, :-1], truth.inputs[:, :-1], data.dt))
    # in the free space of the pool
    xy = truth.states[..., :2]
    assert np.all((xy > 0) & (xy < (20.0, 10.0)))
    for c, r in zip(data.map.centers, data.map.radii, strict=True):
        assert np.all(np.hypot(*(xy - c).transpose(2, 0, 1)) > r)
    # the true distance is the first hit along theta + alpha
    d = data.map.distance(xy[..., 0], xy[..., 1], truth.states[..., 2] + data.alpha)
    assert np.array_equal(d, truth.distance)
    assert np.abs(data.alpha - np.mod(np.arange(406) * np.pi / 40, 2 * np.pi)).max() < 1e-12
    # every mission visits the three waypoints, in order
    assert np.all(truth.waypoint_k >= 0) and np.all(np.diff(truth.waypoint_k, axis=1) > 0)


def test_outlier_rate(batch):
    data, truth = batch
    m, p = truth.outlier.size, data.p_outlier
    sd = math.sqrt(m * p * (1 - p))
    assert abs(int(truth.outlier.sum()) - m * p) < 6 * sd
    # an outlier box mostly misses the truth
    assert data.ranges.contains(truth.distance)[truth.outlier].mean() < 0.1
    _, none = simulate_pool(seed=3, p_outlier=0.0)
    assert not none.outlier.any()


def test_batch_equals_single_runs(batch):
    data, truth = batch
    for i in (0, 1, 199):
        d1, t1 = simulate_pool(seed=3 + i)
        assert np.array_equal(t1.states, truth.states[i])
        assert np.array_equal(t1.outlier, truth.outlier[i])
        assert np.array_equal(d1.ranges.lo, data.ranges.lo[i])
        assert np.array_equal(d1.inputs.hi, data.inputs.hi[i])
        assert d1.n_missions is None
    assert np.array_equal(data.mission(5).ranges.hi, data.ranges.hi[5])


def test_deterministic():
    (a, ta), (b, tb) = simulate_pool(seed=7), simulate_pool(seed=7)
    assert np.array_equal(ta.states, tb.states) and np.array_equal(a.ranges.lo, b.ranges.lo)
    _, tc = simulate_pool(seed=8)
    assert not np.array_equal(ta.states, tc.states)


def test_fixed_outlier_range():
    data, truth = simulate_pool(seed=2, outlier_range=0.5)
    r = data.ranges[truth.outlier]
    assert truth.outlier_range == 0.5 and np.all((r.lo > 0.3) & (r.hi < 0.7))


def test_bad_arguments():
    with pytest.raises(ValueError, match="seed >= 0"):
        simulate_pool(seed=-1)
    with pytest.raises(ValueError, match="p_outlier"):
        simulate_pool(p_outlier=1.5)
