"""Every command checks its command line before any work (``boundest.commands.options``): a
value outside its meaning, a run larger than the machine, options that cannot go together, an
output path that cannot be written, a missing optional extra: one line on standard error, exit
code 2, nothing computed, nothing written."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from boundest.cli import main
from boundest.commands import drifting_clock as dc_cmd
from boundest.commands import jaulin2001 as jw_cmd
from boundest.commands import pool as pool_cmd
from boundest.commands import pool_mc as mc_cmd
from boundest.commands import range_only as ro_cmd
from boundest.commands import satellite as sat_cmd
from boundest.commands import solve as solve_cmd

MODEL = "x in [0, 2], y in [0, 2];\nConstraints\nx^2 + y^2 = 1;\n"


def _never(*args, **kwargs):
    raise AssertionError("the command ran although its options were refused")


@pytest.fixture
def no_work(monkeypatch):
    """Every command's work refused: a test passes only if the checks stop the command first
    (``register`` binds the module's ``run`` when ``main`` builds the parser)."""
    for module in (ro_cmd, dc_cmd, jw_cmd, pool_cmd, sat_cmd, solve_cmd):
        monkeypatch.setattr(module, "run", _never)
    monkeypatch.setattr(mc_cmd, "run_monte_carlo", _never)


def _refused(argv: list[str], capsys) -> str:
    """The one error line of ``main(argv)``, which must exit with code 2 (returned, or as the
    parser's ``SystemExit``)."""
    try:
        rc = main(argv)
    except SystemExit as exc:
        rc = exc.code
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1, (rc, err)
    return err[0]


def _nothing_in(folder: Path) -> None:
    assert not folder.exists() or not any(folder.iterdir()), list(folder.iterdir())


# -- item 2: numeric values outside their meaning -------------------------------------------
BAD_VALUES = [
    (["run", "range-only", "--dt", "0"], "argument --dt: must be a finite number > 0, got '0'"),
    (["run", "range-only", "--dt", "-0.01"], "argument --dt: must be a finite number > 0"),
    (["run", "range-only", "--dt", "nan"], "argument --dt: must be a finite number > 0"),
    (["run", "range-only", "--dt", "inf"], "argument --dt: must be a finite number > 0"),
    (["run", "range-only", "--dt", "ten"], "argument --dt: not a number: 'ten'"),
    (["run", "range-only", "--rel-eps", "1"], "argument --rel-eps: must lie in [0, 1[, got '1'"),
    (["run", "range-only", "--max-iter", "0"], "argument --max-iter: must be a whole number >= 1"),
    (["run", "range-only", "--max-iter", "2.5"], "argument --max-iter: must be a whole number"),
    (["run", "drifting-clock", "--dt", "0"], "argument --dt: must be a finite number > 0"),
    (["run", "drifting-clock", "--rel-eps", "-0.1"], "argument --rel-eps: must lie in [0, 1["),
    (["run", "jaulin2001", "--eps", "0"], "argument --eps: must be a finite number > 0"),
    (["run", "satellite", "--rel-eps", "2"], "argument --rel-eps: must lie in [0, 1["),
    (["run", "auv", "--max-iter", "0"], "argument --max-iter: must be a whole number >= 1"),
    (["run", "auv", "--rel-eps", "1.5"], "argument --rel-eps: must lie in [0, 1["),
    (["run", "pool", "--q", "-1"], "argument --q: must be a whole number >= 0, got '-1'"),
    (["run", "pool", "--m", "0"], "argument --m: must be a whole number >= 1, got '0'"),
    (["run", "pool", "--sweeps", "-1"], "argument --sweeps: must be a whole number >= 0"),
    (["run", "pool", "--paving", "0"], "argument --paving: must be a finite number > 0"),
    (["run", "pool", "--paving-heading", "-0.1"], "argument --paving-heading: must be a finite"),
    (["run", "pool", "--paving-heading", "0.1", "--heading-slices", "0"],
     "argument --heading-slices: must be a whole number >= 1"),
    (["solve", "MODEL", "--paving", "0"], "argument --paving: must be a finite number > 0"),
    (["solve", "MODEL", "--max-boxes", "0"], "argument --max-boxes: must be a whole number >= 1"),
    (["solve", "MODEL", "--rel-eps", "1"], "argument --rel-eps: must lie in [0, 1["),
]


@pytest.mark.parametrize(("argv", "says"), BAD_VALUES, ids=lambda a: " ".join(a) if
                         isinstance(a, list) else None)
def test_a_value_outside_its_meaning_is_one_line_naming_the_option(tmp_path, capsys, no_work,
                                                                   argv, says):
    model = tmp_path / "m.txt"
    model.write_text(MODEL)
    out = tmp_path / "out"
    argv = [str(model) if a == "MODEL" else a for a in argv]
    line = _refused([*argv, "--out", str(out), "--json", str(tmp_path / "r.json")], capsys)
    assert says in line, line
    _nothing_in(out)
    assert not (tmp_path / "r.json").exists()


@pytest.mark.parametrize(("argv", "says"), [
    (["run", "pool", "--q", "9", "--m", "8"], "--q 9 outliers cannot be more than the --m 8"),
    (["solve", "MODEL", "--max-boxes", "10"], "--max-boxes 10 bounds a subpaving, and there is "
                                              "none"),
], ids=["q above m", "max-boxes without a paving"])
def test_values_that_contradict_each_other(tmp_path, capsys, monkeypatch, argv, says):
    for module in (pool_cmd, ro_cmd):
        monkeypatch.setattr(module, "run", _never)
    model = tmp_path / "m.txt"
    model.write_text(MODEL)
    argv = [str(model) if a == "MODEL" else a for a in argv]
    assert says in _refused([*argv, "--out", str(tmp_path / "out")], capsys)
    _nothing_in(tmp_path / "out")


def test_dt_zero_in_a_real_process(tmp_path):
    """The issue's case: ``run range-only --dt 0`` raised ZeroDivisionError."""
    p = subprocess.run([sys.executable, "-m", "boundest", "run", "range-only", "--dt", "0",
                        "--out", str(tmp_path / "out")], capture_output=True, text=True,
                       timeout=120)
    err = p.stderr.strip().splitlines()
    assert p.returncode == 2 and len(err) == 1 and "argument --dt" in err[0], p.stderr
    assert not (tmp_path / "out").exists()


# -- item 2: runs larger than the machine ----------------------------------------------------
@pytest.mark.parametrize(("argv", "says"), [
    (["run", "range-only", "--dt", "1e-9"], "--dt 1e-09: 64,000,000,000 slices over [0, 64] s"),
    (["run", "range-only", "--dt", "5e-324"], "--dt 4.94066e-324: more than 1e308 slices"),
    (["run", "drifting-clock", "--dt", "1e-9"], "--dt 1e-09: 12,431,"),
    (["run", "drifting-clock", "--dt", "1e-320"], "more memory than any machine has"),
    (["run", "pool", "--m", "2000000"], "--m 2000000: the observer's windows of 2000000 pings"),
    (["run", "pool", "--paving-heading", "0.1", "--heading-slices", "1000000000"],
     "--m 80 --heading-slices 1000000000"),
    (["run", "pool", "--monte-carlo", "100000000", "--mc-chunk", "100000000"],
     "--mc-chunk 100000000: 1 process(es) at a time, each on a chunk of 100,000,000 missions"),
    (["solve", "MODEL", "--paving", "0.1", "--max-boxes", "1000000000000"],
     "--max-boxes 1000000000000: a subpaving of up to 1,000,000,000,000 boxes of 2 variables"),
], ids=["range-only dt", "range-only tiny dt", "drifting-clock dt", "drifting-clock tiny dt",
        "pool m", "pool heading slices", "monte carlo chunk", "solve max-boxes"])
def test_a_run_larger_than_the_machine_is_refused_with_its_estimate(tmp_path, capsys,
                                                                    monkeypatch, argv, says):
    """The estimates are far beyond any machine's memory (the drifting clock's follows the
    loading of its data, whose times set its horizon)."""
    from boundest.scenarios import drifting_clock as dc
    from boundest.scenarios import pool_mc

    monkeypatch.setattr(dc, "solve", _never)
    monkeypatch.setattr(pool_mc, "pool_monte_carlo", _never)
    monkeypatch.setattr("boundest.csp.propagate", _never)
    for module in (ro_cmd, pool_cmd):
        monkeypatch.setattr(module, "run", _never)
    model = tmp_path / "m.txt"
    model.write_text(MODEL)
    argv = [str(model) if a == "MODEL" else a for a in argv]
    out, js = tmp_path / "out", tmp_path / "r.json"
    line = _refused([*argv, "--out", str(out), "--json", str(js)], capsys)
    assert says in line and ("of memory, more than the" in line or "any machine" in line), line
    _nothing_in(out)
    assert not js.exists()


def test_a_large_feasible_run_says_how_large_before_it_starts(tmp_path, capsys, monkeypatch):
    """``--dt 0.0005``: 128,000 slices, 20 times the default's; announced, then it starts."""
    from boundest.scenarios import range_only as ro

    def started(*args, **kwargs):
        raise ValueError("started")

    monkeypatch.setattr(ro, "load", started)
    monkeypatch.setattr("boundest.commands.options.available_memory", lambda: 64 << 30)
    assert main(["run", "range-only", "--dt", "0.0005", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[0].startswith("boundest: a large run: --dt 0.0005: 128,000 slices over [0, 64] s,"
                             " 20 times the default --dt 0.01's"), err
    assert "of the 64 GiB available" in err[0]
    assert err[-1] == "boundest: error: started"


def test_jaulin2001_small_eps_is_announced(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(jw_cmd, "run", lambda args: 0)
    assert main(["run", "jaulin2001", "--eps", "0.001", "--out", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert "a large run: --eps 0.001: about 100 times the work of the default --eps 0.01" in err


@pytest.mark.parametrize(("argv", "said"), [
    (["--sweeps", "200"], "a long run: 1 mission(s), 200 smoothing round(s) per ping: about 3 min"),
    (["--monte-carlo", "100000"], "a long run: 100,000 mission(s), 0 smoothing round(s) per "
                                  "ping: about 35 min"),
    (["--monte-carlo", "2000", "--sweeps", "2", "--workers", "2"],
     "a long run: 2,000 mission(s) on 2 workers, 2 smoothing round(s) per ping: about 27 min"),
])
def test_a_long_pool_run_says_how_long_before_it_starts(argv, said, tmp_path, capsys, no_work):
    """Runs whose memory is small but whose time is long (many rounds, many missions) are
    announced with their estimated time before they start (the work itself is refused by
    ``no_work``: the line comes from the checks)."""
    with pytest.raises(AssertionError, match="the command ran"):
        main(["run", "pool", *argv, "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert f"boundest: {said}" in err, err


def test_a_short_pool_run_is_not_announced(tmp_path, capsys, no_work):
    with pytest.raises(AssertionError, match="the command ran"):
        main(["run", "pool", "--monte-carlo", "100", "--out", str(tmp_path)])
    assert "long run" not in capsys.readouterr().err


def test_check_size_refuses_beyond_the_memory_given():
    from boundest.commands.options import check_size, count, gib

    assert check_size(1 << 20, "x", "--opt 1", available=1 << 30) is False
    with pytest.raises(ValueError, match=r"^--opt 3: three things: about 3 GiB of memory, more "
                                         r"than the 2 GiB available here$"):
        check_size(3 << 30, "three things", "--opt 3", available=2 << 30)
    assert count(6400) == "6,400" and count(6.4e13) == "6.4e+13"
    assert gib(480 << 20) == "480 MiB" and gib(1.5 * (1 << 30)) == "1.5 GiB"


def test_the_commands_constants_agree_with_the_scenarios():
    """The checks import nothing numerical: the constants they spell out must be the
    scenarios' own, and their slice count that of the tubes."""
    import numpy as np

    from boundest.scenarios import pool, pool_observer
    from boundest.scenarios import range_only as ro
    from boundest.tube import time_grid

    assert ro_cmd.HORIZON_S == ro.TF - ro.T0
    assert pool_cmd.DEFAULT_SLICES == pool.DEFAULT_SLICES
    assert pool_cmd.MAX_SIDE == pool_observer.MAX_SIDE
    for dt in (0.01, 0.5, 0.3, 1e-3, 7.0, 64.0, 100.0):
        assert ro_cmd.slices(dt) == len(np.asarray(time_grid(ro.T0, ro.TF, dt))) - 1, dt


# -- item 3: optional extras ----------------------------------------------------------------
def test_mode_lp_without_scipy_is_one_line_naming_the_extra(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "scipy.optimize", None)
    monkeypatch.setitem(sys.modules, "scipy", None)
    model = tmp_path / "m.txt"
    model.write_text(MODEL)
    line = _refused(["solve", str(model), "--mode", "lp", "--out", str(tmp_path / "out")],
                    capsys)
    assert line == ("boundest: error: --mode lp needs SciPy (linear programming): "
                    "pip install 'boundest[lp]'")


# -- item 4: options that cannot go together ------------------------------------------------
@pytest.mark.parametrize(("argv", "says"), [
    (["run", "jaulin2001", "--boxes", "--eps", "0.02"], "--eps 0.02 is the precision of the "
                                                         "subpavings; --boxes"),
    (["run", "auv", "--mode", "localization", "--rel-eps", "0.01"],
     "--rel-eps 0.01: the SLAM's iterations (--mode slam)"),
    (["run", "auv", "--mode", "localization", "--max-iter", "5"], "--max-iter 5: the SLAM's"),
    (["run", "pool", "--paving-heading", "0.1", "--window-only"], "needs the recursive observer"),
    (["run", "pool", "--heading-slices", "8"], "--heading-slices 8 goes with --paving-heading"),
    (["run", "pool", "--workers", "2"], "--workers goes with --monte-carlo N"),
    (["run", "pool", "--monte-carlo", "4", "--data", "DIR"], "it does not read --data"),
], ids=lambda a: " ".join(a[1:3]) if isinstance(a, list) else None)
def test_options_that_cannot_go_together_are_refused(tmp_path, capsys, no_work, argv, says):
    argv = [str(tmp_path) if a == "DIR" else a for a in argv]
    line = _refused([*argv, "--out", str(tmp_path / "out")], capsys)
    assert says in line, line
    _nothing_in(tmp_path / "out")


def test_paving_over_the_files_bisection_says_so(tmp_path, capsys):
    model = tmp_path / "m.txt"
    model.write_text("Bisection 0.5;\n" + MODEL)
    assert main(["solve", str(model), "--paving", "0.25", "--out", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert f"--paving 0.25 overrides 'Bisection 0.5;' of {model}:1" in err


# -- item 5: output and input paths, before any work ----------------------------------------
def _path_cases(tmp: Path) -> list[tuple[list[str], str]]:
    a_file = tmp / "a_file.csv"
    a_file.write_text("x\n")
    return [
        (["run", "pool", "--paving", "0.25", "--out", str(a_file)],
         f"--out {a_file}: is a file, not a folder"),
        (["run", "satellite", "--json", str(tmp)], f"--json {tmp}: is a folder; name a file"),
        (["run", "range-only", "--json", str(tmp / "nowhere" / "dir" / "x.json")],
         f"--json {tmp / 'nowhere' / 'dir' / 'x.json'}: {tmp / 'nowhere' / 'dir'} does not "
         "exist (it is not created)"),
        (["run", "jaulin2001", "--json", str(a_file / "x.json")],
         f"--json {a_file / 'x.json'}: {a_file} is a file, not a folder"),
        (["run", "drifting-clock", "--out", str(a_file / "figs")],
         f"--out {a_file / 'figs'}: cannot create it, {a_file} is a file"),
        (["run", "auv", "--json", str(tmp / "nowhere" / "a.json")], "does not exist"),
        (["run", "auv", "--data", str(tmp / "nowhere")], f"--data {tmp / 'nowhere'}: no such "
                                                         "folder"),
        (["run", "range-only", "--beacons", str(tmp)], f"--beacons {tmp}: is a folder"),
        (["run", "drifting-clock", "--data", str(tmp / "none.csv")], "--data"),
        (["solve", str(tmp / "none.txt")], f"model file {tmp / 'none.txt'}: no such file"),
        (["demo", "--json", str(tmp)], f"--json {tmp}: is a folder"),
        (["run", "pool", "--monte-carlo", "3", "--json", str(tmp / "nowhere" / "mc.json")],
         "does not exist (it is not created)"),
    ]


def test_output_and_input_paths_are_checked_before_any_work(tmp_path, capsys, no_work,
                                                             monkeypatch):
    monkeypatch.setattr("boundest.cli._demo", _never)
    for argv, says in _path_cases(tmp_path):
        before = sorted(tmp_path.rglob("*"))
        line = _refused(argv + (["--out", str(tmp_path / "figs")] if "--out" not in argv
                                else []), capsys)
        assert line.startswith("boundest: error: ") and says in line, (argv, line)
        assert sorted(tmp_path.rglob("*")) == before, argv  # no folder created, nothing written


def test_a_path_error_in_a_real_process(tmp_path):
    """``--json`` in a folder that does not exist: refused at once, and the folder not made."""
    js = tmp_path / "nonexistent" / "dir" / "x.json"
    p = subprocess.run([sys.executable, "-m", "boundest", "demo", "--out", str(tmp_path / "o"),
                        "--json", str(js)], capture_output=True, text=True, timeout=120)
    err = p.stderr.strip().splitlines()
    assert p.returncode == 2 and len(err) == 1 and err[0].startswith(f"boundest: error: --json "
                                                                     f"{js}:"), p.stderr
    assert not (tmp_path / "nonexistent").exists() and not (tmp_path / "o").exists()


def test_out_creates_its_missing_folders(tmp_path, capsys):
    out = tmp_path / "a" / "b"
    assert main(["run", "jaulin2001", "--boxes", "--out", str(out)]) == 0
    assert (out / "jaulin2001_rcse_ncse.png").exists() or any(out.glob("*.png"))


def _inconsistent_satellite(tmp: Path) -> Path:
    """The first 11 rows of the embedded data, y2 and y3 of k = 4 moved by 0.8: hull consistency
    finds no contradiction, 3B shaving proves the CSP empty."""
    from boundest.scenarios._data import embedded

    rows = [r.split(",") for r in embedded("satellite_k200.csv").read_text().splitlines()[:12]]
    for j in (5, 6):
        rows[5][j] = repr(float(rows[5][j]) + 0.8)
    f = tmp / "sat.csv"
    f.write_text("".join(",".join(r) + "\n" for r in rows))
    return f


def test_beta_tuning_tunes_in_the_mode_asked_for(tmp_path, capsys):
    """``--beta-tuning --mode 3b``: the beta found is one at which 3B shaving (not hull
    consistency alone) leaves the CSP non-empty, and the enclosures are 3B's."""
    import json

    from boundest.csp import propagate
    from boundest.scenarios import satellite as sat

    f, js = _inconsistent_satellite(tmp_path), tmp_path / "s.json"
    meas = sat.load(f)
    assert sat.solve(meas, mode="hc4").consistent and not sat.solve(meas, mode="3b").consistent
    assert main(["run", "satellite", "--data", str(f), "--mode", "3b", "--beta-tuning",
                 "--out", str(tmp_path), "--json", str(js)]) == 0
    out = capsys.readouterr().out
    data = json.loads(js.read_text())
    assert data["mode"] == "3b" and data["consistent"] and data["shaving"], data["mode"]
    assert "mode 3b: hull consistency, then shaving" in out and "  mode hc4:" not in out
    beta = data["beta"]
    hc4_beta = sat.tune(meas, mode="hc4")[0].beta
    assert beta > hc4_beta  # hull consistency's beta: 3B proves the CSP empty there

    def in_3b(b: float) -> bool:
        tape = sat.compile_model(sat.build_model(meas, beta=b))
        names = [v for row in sat._state_names(meas.k_max) for v in row]
        return propagate(tape, mode="3b", shave=names, shaving=sat.SHAVING, targets=names,
                         rel_eps=1e-3).consistent

    assert in_3b(beta) and not in_3b(hc4_beta) and not in_3b(beta * (1 - 2e-3))


# -- item 6: every worker asked for gets a part ---------------------------------------------
@pytest.mark.parametrize(("missions", "chunk", "workers", "size", "why"), [
    (10, 250, 2, 5, "--mc-chunk 250 cut to 5 so that each of the 2 workers gets a part"),
    (9, 250, 4, 2, "cut to 2"),
    (1000, 250, 2, 250, ""),
    (10, 250, 1, 10, ""),
    (3, 250, 8, 1, "one mission per task: 3 mission(s) for 8 workers, so 3 worker process(es)"),
])
def test_tasks_for_gives_every_worker_a_part(missions, chunk, workers, size, why):
    got, said = mc_cmd.tasks_for(missions, chunk, workers)
    assert got == size and why in said and bool(said) == bool(why)
    assert -(-missions // got) >= min(workers, missions)  # a task for every worker used


def test_workers_with_fewer_missions_than_a_chunk_all_get_work(tmp_path, capsys, monkeypatch):
    """``--workers 2 --monte-carlo 10`` with the default chunk of 250: two tasks of 5, said."""
    from boundest.scenarios import pool_mc

    seen = {}

    def record(missions, q, m, *, chunk, executor, **kwargs):
        seen.update(missions=missions, chunk=chunk, workers=executor._max_workers)
        raise ValueError("recorded")

    monkeypatch.setattr(pool_mc, "pool_monte_carlo", record)
    assert main(["run", "pool", "--monte-carlo", "10", "--workers", "2", "--out",
                 str(tmp_path)]) == 2
    assert seen == {"missions": 10, "chunk": 5, "workers": 2}
    assert "chunks of 5 missions (--mc-chunk 250 cut to 5 so that each of the 2 workers gets " \
           "a part), on 2 local worker processes" in capsys.readouterr().out
