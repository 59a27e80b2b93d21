"""``boundest run pool``: the summary, strict JSON, the figures and the table, bad data."""

from __future__ import annotations

import contextlib
import io
import json
import shutil

import pytest

from boundest.cli import main
from boundest.scenarios._data import embedded


def _refuse(name: str) -> None:
    raise ValueError(f"non-strict JSON constant {name}")


@pytest.fixture(scope="module")
def pool_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("pool")
    js = out / "pool.json"
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        rc = main(["run", "pool", "--m", "40", "--q", "4", "--out", str(out), "--json", str(js)])
    return rc, out, js, buf.getvalue()


@pytest.mark.slow  # a whole pool run (its kernels compile here in a fresh clone, about 40 s)
def test_pool_command_runs_and_writes_strict_json(pool_run):
    rc, _, js, _ = pool_run
    assert rc == 0
    data = json.loads(js.read_text(), parse_constant=_refuse)
    assert data["scenario"] == "pool" and data["q"] == 4 and data["m"] == 40
    assert 0.0 < data["window_probability"] <= 1.0
    steps = data["steps"]
    assert len(steps) == data["samples"] == 406
    first = steps[0]
    assert set(first) >= {"t", "box", "centre", "window_probability", "rejected", "empty"}
    assert len(first["box"]) == 4 and all(len(b) == 2 for b in first["box"])
    assert len(first["centre"]) == 4
    assert first["window_probability"] == 1.0  # a window of one ping
    assert data["max_rejected"] == max(s["rejected"] for s in steps)
    assert data["empty_steps"] == [s["k"] for s in steps if s["empty"]]
    assert all(lo <= c <= hi for s in steps if not s["empty"]
               for (lo, hi), c in zip(s["box"], s["centre"], strict=True))


@pytest.mark.slow  # a whole pool run (its kernels compile here in a fresh clone, about 40 s)
def test_pool_figures_and_table(pool_run):
    _, out, _, _ = pool_run
    for name in ("pool_snapshots", "pool_emission", "pool_trajectory"):
        assert (out / f"{name}.png").stat().st_size > 10_000, name
    table = (out / "pool_table.txt").read_text().splitlines()
    rows = [line for line in table if line and not line.startswith("#")]
    assert rows[0].split()[:2] == ["k", "t"]
    assert len(rows) == 11  # the header and 10 regular times


@pytest.mark.slow  # a whole pool run (its kernels compile here in a fresh clone, about 40 s)
def test_pool_summary_states_the_guarantee(pool_run):
    text = pool_run[3]
    assert "P(at most 4 outliers in 40 pings)" in text
    assert "every window since the last restart" in text
    assert "empty steps (restarts):" in text and "most pings rejected in a window" in text
    assert "mode: smoothing inside the window" in text and "--sweeps 0: 0.02 s" in text


def test_pool_bad_data_folder(tmp_path, capsys):
    src = embedded("pool_setup.json").parent
    for f in src.glob("pool_*"):
        shutil.copy(f, tmp_path / f.name)
    (tmp_path / "pool_map.json").write_text("{not json")
    assert main(["run", "pool", "--data", str(tmp_path), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pool_map.json" in err[0]


def test_pool_missing_data_folder(tmp_path, capsys):
    missing = tmp_path / "nowhere"
    assert main(["run", "pool", "--data", str(missing), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"--data {missing}: no such folder" in err[0], err


@pytest.mark.slow  # a whole online run, about 12 s
def test_pool_online_paved_window_only_run(tmp_path):
    js = tmp_path / "p.json"
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        rc = main(["run", "pool", "--online", "--window-only", "--paving", "2",
                   "--m", "30", "--out", str(tmp_path), "--json", str(js)])
    assert rc == 0
    data = json.loads(js.read_text(), parse_constant=_refuse)
    assert data["observer"] == "window" and data["paving"] == 2
    assert data["paving_heading"] is None and data["heading_slices"] is None
    assert data["online"]["updates"] == 405 and data["online"]["median_s"] > 0
    assert "P(x_k in X_k) >=" in data["guarantee"]  # the pure window observer's guarantee
    assert all(s["cells"] >= 1 for s in data["steps"] if not s["empty"])
    assert "online updates: median" in buf.getvalue()


@pytest.mark.parametrize("bad", [["--paving", "0"], ["--paving-heading", "-0.1"],
                                 ["--sweeps", "-1"],
                                 ["--heading-slices", "0", "--paving-heading", "0.1"],
                                 ["--window-only", "--paving-heading", "0.1"],
                                 ["--heading-slices", "8"]])
def test_pool_bad_options(tmp_path, capsys, bad):
    try:  # a value outside its meaning is the parser's error (SystemExit), the rest main's
        rc = main(["run", "pool", *bad, "--out", str(tmp_path)])
    except SystemExit as exc:
        rc = exc.code
    assert rc == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and bad[0].strip("-").replace("-", "_").split("_")[0] in err[0]


def test_pool_help_states_the_default_slices(capsys):
    from boundest.scenarios.pool import DEFAULT_SLICES

    with pytest.raises(SystemExit):
        main(["run", "pool", "--help"])
    assert f"(default {DEFAULT_SLICES};" in " ".join(capsys.readouterr().out.split())
