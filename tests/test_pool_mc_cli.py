"""``boundest run pool --monte-carlo N``: table, strict JSON, figure; clear errors."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest

from boundest.cli import main
from boundest.scenarios.pool_mc import wilson


@pytest.mark.slow  # a whole Monte Carlo pool run
def test_monte_carlo_command_writes_strict_json_table_and_figure(tmp_path, capsys):
    js = tmp_path / "mc.json"
    rc = main(["run", "pool", "--monte-carlo", "2", "--mc-chunk", "2", "--out", str(tmp_path),
               "--json", str(js)])
    text = capsys.readouterr().out
    data = json.loads(js.read_text(), parse_constant=lambda c: pytest.fail(f"non-JSON {c}"))
    assert data["scenario"] == "pool-monte-carlo" and data["missions"] == 2
    n = len(data["k"])
    for key in ("containment_frequency", "ci95_lo", "ci95_hi", "window_probability"):
        assert len(data[key]) == n, key
    freq = np.array(data["containment_frequency"])
    assert rc == (0 if (freq >= np.array(data["window_probability"])).all() else 1)
    assert ((np.array(data["ci95_lo"]) <= freq) & (freq <= np.array(data["ci95_hi"]))).all()
    assert (tmp_path / "pool_monte_carlo.png").stat().st_size > 10_000
    assert "claimed P" in (tmp_path / "pool_monte_carlo.txt").read_text()
    assert "violations" in text


def test_scheduler_without_distributed_is_one_sentence(monkeypatch, tmp_path, capsys):
    monkeypatch.setitem(sys.modules, "distributed", None)
    rc = main(["run", "pool", "--monte-carlo", "10", "--scheduler", "tcp://127.0.0.1:1",
               "--out", str(tmp_path)])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1
    assert "pip install 'boundest[distributed]'" in err[0]


@pytest.mark.parametrize("argv, says", [
    (["--scheduler", "tcp://127.0.0.1:1"], "--scheduler goes with --monte-carlo"),
    (["--mc-chunk", "5", "--mc-seed", "1"], "--mc-chunk and --mc-seed go with --monte-carlo"),
    (["--monte-carlo", "10", "--workers", "2", "--scheduler", "x"], "not both"),
    (["--monte-carlo", "10", "--online"], "does not take --online"),
    (["--monte-carlo", "10", "--paving-heading", "0.1", "--window-only"], "recursive observer"),
])
def test_bad_monte_carlo_options(argv, says, tmp_path, capsys):
    assert main(["run", "pool", *argv, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and says in err[0], err


@pytest.mark.parametrize("argv, says", [
    (["--monte-carlo", "0"], "argument --monte-carlo: must be a whole number >= 1, got '0'"),
    (["--monte-carlo", "10", "--workers", "0"], "argument --workers: must be a whole number >= 1"),
    (["--monte-carlo", "10", "--mc-chunk", "0"], "argument --mc-chunk: must be a whole number"),
    (["--monte-carlo", "10", "--mc-seed", "-1"], "argument --mc-seed: must be a whole number >= 0"),
    (["--monte-carlo", "10", "--paving-heading", "0"],
     "argument --paving-heading: must be a finite number > 0, got '0'"),
])
def test_monte_carlo_values_out_of_range_are_parse_errors(argv, says, tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["run", "pool", *argv, "--out", str(tmp_path)])
    err = capsys.readouterr().err.strip().splitlines()
    assert exc.value.code == 2 and len(err) == 1 and says in err[0], err


def test_wilson_interval_known_values():
    lo, hi = wilson(np.array([0, 5, 10]), 10)
    # Wilson (1927): 0/10 -> [0, 0.2775], 5/10 -> [0.2366, 0.7634], 10/10 -> [0.7225, 1]
    assert np.allclose(lo, [0.0, 0.23659, 0.72246], atol=1e-4)
    assert np.allclose(hi, [0.27753, 0.76341, 1.0], atol=1e-4)


def test_monte_carlo_of_heading_slices(tmp_path, capsys):
    js = tmp_path / "mc.json"
    main(["run", "pool", "--monte-carlo", "2", "--mc-chunk", "2", "--paving-heading", "0.05",
          "--heading-slices", "4", "--out", str(tmp_path), "--json", str(js)])
    data = json.loads(js.read_text())
    assert data["observer"] == {"sweeps": 0, "carry": True, "paving": None,
                                "paving_heading": 0.05, "heading_slices": 4}
    assert data["guarantee_violations"] == 0
    assert "paving_heading = 0.05, heading_slices = 4" in capsys.readouterr().out
