"""AUV survey (Jaulin, Bertholom, Dabe 2007): localization and SLAM keep the simulated truth, the
tube and discrete formulations agree, the embedded data load, bad data are reported."""

from __future__ import annotations

import gzip
import json
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from boundest.cli import main
from boundest.csp import propagate
from boundest.expr import Model, Var, VarFamily
from boundest.expr.tape import compile_model, instantiate
from boundest.interval import Interval
from boundest.scenarios import auv
from boundest.scenarios._data import embedded
from boundest.scenarios.auv_data import AuvData, load_auv
from boundest.scenarios.auv_discrete import solve_discrete
from boundest.scenarios.auv_sim import AuvTruth, simulate_survey

SURVEYS = [(0, 6000, 4, 3), (5, 9000, 5, 4), (3, 60000, 4, 3)]


@cache
def survey(seed: int, n: int, legs: int, mines: int) -> tuple[AuvData, AuvTruth]:
    return simulate_survey(seed=seed, n_samples=n, n_legs=legs, n_mines=mines)


def _inside(box: Interval, x: np.ndarray) -> np.ndarray:
    return (box.lo <= x) & (x <= box.hi)


def assert_keeps(positions: Interval, mines: Interval | None, truth: AuvTruth) -> None:
    ok = _inside(positions, truth.p)
    bad = np.argwhere(~ok)
    assert ok.all(), f"truth outside at (sample, axis) {bad[:5].tolist()}"
    if mines is not None:
        assert _inside(mines, truth.mines).all(), (mines, truth.mines)


@pytest.mark.slow  # whole surveys, about 25 s on 2 cores
@pytest.mark.parametrize("case", SURVEYS, ids=[f"seed{c[0]}-n{c[1]}" for c in SURVEYS])
@pytest.mark.parametrize("form", ["best", "natural"])
def test_tube_formulation_keeps_the_truth(case, form):
    data, truth = survey(*case)
    loc = auv.localize(data, form)
    assert loc.consistent
    assert_keeps(loc.positions, None, truth)
    res = auv.slam(data, form, progress=False)
    assert res.consistent and res.report.converged
    assert_keeps(res.positions, res.mines, truth)
    assert_keeps(res.tube.slices, None, AuvTruth(  # slices hold the path between samples
        np.minimum(truth.p[:-1], truth.p[1:]), truth.attitude, truth.velocity, truth.altitude,
        truth.mines))
    assert_keeps(res.tube.slices, None, AuvTruth(
        np.maximum(truth.p[:-1], truth.p[1:]), truth.attitude, truth.velocity, truth.altitude,
        truth.mines))
    # the mines tie the trajectory together: SLAM is tighter, never wider
    w_loc, w_slam = loc.widths(), res.widths()
    assert np.all(w_slam <= w_loc + 1e-9)
    assert w_slam[:, :2].mean() < w_loc[:, :2].mean()
    assert np.all(np.isfinite(res.mines.lo)) and np.all(np.isfinite(res.mines.hi))


@pytest.mark.parametrize("case", SURVEYS[:2], ids=[f"seed{c[0]}-n{c[1]}" for c in SURVEYS[:2]])
def test_discrete_formulation_keeps_the_truth_and_matches_the_tube(case):
    data, truth = survey(*case)
    for slam in (False, True):
        disc = solve_discrete(data, slam=slam, rel_eps=1e-9)
        assert disc.consistent
        assert_keeps(disc.positions, disc.mines if slam else None, truth)
        tube = (auv.slam(data, "natural", rel_eps=0.0, max_iter=200, progress=False) if slam
                else auv.localize(data, "natural"))
        scale = np.maximum(1.0, tube.widths())
        for a, b in ((disc.positions.lo, tube.positions.lo),
                     (disc.positions.hi, tube.positions.hi)):
            assert np.max(np.abs(a - b) / scale) < 1e-6
        if not slam:  # the same operations in the same order: identical
            assert np.array_equal(disc.positions.lo, tube.positions.lo)
            assert np.array_equal(disc.positions.hi, tube.positions.hi)


def test_world_velocity_encloses_sampled_rotations():
    rng = np.random.default_rng(3)
    n = 2000
    mid_a = rng.normal(0, [0.05, 0.05, 3.0], (n, 3))
    mid_v = rng.normal([1.5, 0.0, 0.0], 0.3, (n, 3))
    att = Interval(mid_a).inflate(rng.uniform(0, 0.02, (n, 3)))
    vel = Interval(mid_v).inflate(rng.uniform(0, 0.05, (n, 3)))
    best, nat = auv.world_velocity(att, vel), auv.world_velocity(att, vel, "natural")
    assert np.all(best.width() <= nat.width())
    from boundest.scenarios.auv_sim import rotation

    for u in rng.uniform(0, 1, (20, 6)):
        a = att.lo + u[:3] * (att.hi - att.lo)
        v = vel.lo + u[3:] * (vel.hi - vel.lo)
        w = np.einsum("nij,nj->ni", rotation(a), v)
        # float error of the sample itself: far below the widths
        assert np.all((best.lo - 1e-12 <= w) & (w <= best.hi + 1e-12))


def test_inconsistent_fix_is_reported():
    data, _ = survey(0, 6000, 4, 3)
    far = Interval.trusted(data.fix.lo.copy(), data.fix.hi.copy())
    far.lo[-1, 0] += 5000.0
    far.hi[-1, 0] += 5000.0
    bad = AuvData(**{**data.__dict__, "fix": far})
    assert not auv.localize(bad).consistent
    assert not auv.slam(bad, progress=False).consistent
    assert not solve_discrete(bad, slam=True).consistent


def test_embedded_survey():
    data = load_auv()
    assert data.n == 60000 and data.n_mines == 6 and data.det_k.size == 12
    assert data.fix_k.tolist() == [0, 59999] and data.dt == 0.1
    # the decimals of the file enclosed one ulp outward
    assert float(data.attitude.lo[0, 0]) < -0.0114997 < float(data.attitude.hi[0, 0])
    assert data.det_mine.tolist() == [4, 2, 2, 1, 1, 0, 0, 5, 5, 3, 3, 1]


def test_instantiate_equals_compiling_every_copy():
    # x[k+1] = x[k] + [0.9, 1.1] u[k], u[k] in [-1, 1], x[5] in [5, 5.5]: template vs unrolled
    x, u = VarFamily("x"), VarFamily("u")
    n = 5
    m = Model()
    m.declare(x[0], (0.0, 0.0))
    for k in range(n):
        m.declare(u[k], (-1.0, 1.0))
        m.add(x[k + 1] == x[k] + Interval(0.9, 1.1) * u[k])
    m.add(x[n].in_((5.0, 5.5)))
    ref = propagate(m, rel_eps=0.0, mode="hc4")
    step = compile_model([Var("b") == Var("a") + Interval(0.9, 1.1) * Var("w")])
    names = [str(x[k]) for k in range(n + 1)] + [str(u[k]) for k in range(n)]
    lo = np.r_[0.0, np.full(n, -np.inf), np.full(n, -1.0)]
    hi = np.r_[0.0, np.full(n - 1, np.inf), 5.5, np.full(n, 1.0)]
    lo[n] = 5.0
    k = np.arange(n)
    tape = instantiate(names, lo, hi, [(step, {"a": k, "b": k + 1, "w": n + 1 + k})])
    got = propagate(tape, rel_eps=0.0, mode="hc4")
    for name in names:
        assert float(got[name].lo) == float(ref[name].lo), name
        assert float(got[name].hi) == float(ref[name].hi), name
    assert float(got[str(u[0])].lo) > 0.5  # x[n] >= 5 forces every u up: the CSP did contract


def test_instantiate_rejects_bad_placements():
    step = compile_model([Var("b") == 2 * Var("a")])
    with pytest.raises(ValueError, match="differ from the template"):
        instantiate(["p"], np.zeros(1), np.ones(1), [(step, {"a": np.array([0])})])
    with pytest.raises(ValueError, match="outside the 1 global"):
        instantiate(["p"], np.zeros(1), np.ones(1),
                    [(step, {"a": np.array([0]), "b": np.array([1])})])


# -- the command --------------------------------------------------------------------------
def _strict(text: str) -> object:
    def refuse(name: str) -> None:
        raise ValueError(f"non-standard JSON constant {name}")
    return json.loads(text, parse_constant=refuse)


def test_run_auv_writes_json_npz_and_figures(tmp_path, capsys):
    js = tmp_path / "auv.json"
    assert main(["run", "auv", "--out", str(tmp_path), "--json", str(js)]) == 0
    out = capsys.readouterr().out
    assert "slam: consistent" in out and "mine 4" in out
    doc = _strict(js.read_text())
    assert doc["mode"] == "slam" and doc["samples"] == 60000 and len(doc["mines"]) == 6
    assert doc["width_mean"][0] < 70 and doc["converged"]
    npz = np.load(doc["positions_npz"])
    assert npz["lo"].shape == (60000, 3) and np.all(npz["lo"] <= npz["hi"])
    for name in ("map", "widths", "depth"):
        assert (tmp_path / f"auv_slam_{name}.png").stat().st_size > 10_000


# -- bad data -------------------------------------------------------------------------------
def _small_survey(folder: Path, n: int = 40) -> dict[str, list[str]]:
    """A valid survey folder of the first ``n`` embedded samples (one detection)."""
    rows = gzip.decompress(embedded("auv_sensors.csv.gz").read_bytes()).decode().splitlines()
    setup = json.loads(embedded("auv_setup.json").read_text())
    setup["n_samples"] = n
    files = {
        "auv_sensors.csv": rows[: n + 1],
        "auv_gps.csv": ["t,north_lo,north_hi,east_lo,east_hi,depth_lo,depth_hi",
                        "6000.0,3.398,8.399,-4.481,0.520,0.000,0.800",
                        f"{6000 + 0.1 * (n - 1):.1f},0,12,-6,4,0.000,0.800"],
        "auv_detections.csv": ["t,mine_id,r_lo,r_hi", "6002.0,1,20.0,21.0"],
    }
    (folder / "auv_setup.json").write_text(json.dumps(setup))
    for name, lines in files.items():
        (folder / name).write_text("\n".join(lines) + "\n")
    return files


def test_small_survey_folder_runs(tmp_path, capsys):
    _small_survey(tmp_path)
    data = load_auv(tmp_path)
    assert data.n == 40 and data.det_k.tolist() == [20]
    assert main(["run", "auv", "--mode", "localization", "--data", str(tmp_path),
                 "--out", str(tmp_path)]) == 0


BAD = [  # file, edit (line index -> new line, or a function of the lines), line, value
    ("auv_sensors.csv", lambda r: [r[0] + ",extra"] + [x + ",1" for x in r[1:]], 1, "'extra'"),
    ("auv_sensors.csv", lambda r: [r[0], r[2], r[1], *r[3:]], 3, "6000.0"),
    ("auv_sensors.csv", lambda r: [r[0], r[1], r[1], *r[2:]], 3, "repeats"),
    ("auv_sensors.csv", lambda r: [r[0], r[1].replace("-0.01149970", "nan"), *r[2:]], 2,
     "'nan'"),
    ("auv_sensors.csv", lambda r: [r[0], r[1].replace("6000.0", "6000.05"), *r[2:]], 2,
     "6000.05"),
    ("auv_sensors.csv", lambda r: r[:-1], 40, "n_samples = 40"),
    ("auv_sensors.csv", lambda r: [r[0], *r[1:3], r[3] + ",9", *r[4:]], 4, "17"),
    ("auv_gps.csv", lambda r: [r[0], r[1].replace("6000.0", "6000.03"), r[2]], 2, "6000.03"),
    ("auv_gps.csv", lambda r: [r[0], r[1].replace("3.398,8.399", "8.399,3.398"), r[2]], 2,
     "8.399"),
    ("auv_detections.csv", lambda r: [r[0], r[1].replace(",1,", ",9,")], 2, "mine_id = 9.0"),
    ("auv_detections.csv", lambda r: [r[0], "7000.0,1,20.0,21.0"], 2, "7000.0"),
]


@pytest.mark.parametrize(("name", "edit", "line", "value"), BAD,
                         ids=[f"{b[0]}-{i}" for i, b in enumerate(BAD)])
def test_bad_survey_file(tmp_path, capsys, name, edit, line, value):
    files = _small_survey(tmp_path)
    (tmp_path / name).write_text("\n".join(edit(files[name])) + "\n")
    rc = main(["run", "auv", "--data", str(tmp_path), "--out", str(tmp_path)])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1, err
    assert f"{tmp_path / name}:{line}:" in err[0] and value in err[0], err[0]


def test_bad_setup_file(tmp_path, capsys):
    _small_survey(tmp_path)
    (tmp_path / "auv_setup.json").write_text('{"t0": 6000.0,\n "dt": }')
    rc = main(["run", "auv", "--data", str(tmp_path), "--out", str(tmp_path)])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and "auv_setup.json:2:" in err[0], err
