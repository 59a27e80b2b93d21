"""``boundest --help`` and argument errors load neither NumPy nor Numba; the parser imports
only the scenario it runs; a run that compiles says so once on standard error, and so does
library use (through ``logging``)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from boundest.cli import build_parser
from boundest.commands import SCENARIOS

PROBE = """
import sys
from boundest.cli import main
try:
    main({argv!r})
except SystemExit as e:
    print("exit", e.code)
heavy = [m for m in ("numpy", "numba", "matplotlib", "boundest.interval") if m in sys.modules]
print("loaded", heavy)
"""


@pytest.mark.parametrize("argv", [["--help"], ["run", "--help"], ["run", "satellite", "--help"],
                                  ["run", "satellite", "--kmax", "3"], ["solve"],
                                  ["run", "nosuch"], ["--version"]])
def test_help_and_argument_errors_load_no_numerical_layer(argv):
    out = subprocess.run([sys.executable, "-c", PROBE.format(argv=argv)], capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().endswith("loaded []"), out.stdout


def test_the_parser_lists_every_scenario_and_registers_the_one_named():
    for name in SCENARIOS:
        args = build_parser(["run", name]).parse_args(["run", name])
        assert args.scenario == name and callable(args.func)
    full = build_parser()
    assert full.parse_args(["run", "satellite", "--kmax", "800"]).kmax == 800
    with pytest.raises(SystemExit):
        build_parser(["run", "pool"]).parse_args(["run", "satellite", "--kmax", "800"])


def test_boundest_package_attributes_are_loaded_on_access():
    import boundest as bd

    assert bd.Box is bd.IntervalVector and bd.sin.__module__ == "boundest.expr.functions"
    assert "Interval" in bd.__all__ and "abs" not in bd.__all__ and "Tube" in dir(bd)
    assert bd.tube.Tube is bd.Tube
    with pytest.raises(AttributeError):
        bd.no_such_name  # noqa: B018


COMPILES = """
from boundest.cli import main
main(["solve", {model!r}])
"""


@pytest.mark.slow  # subprocesses compiling with an empty cache, about 11 s
def test_a_compiling_run_says_so_once_and_a_cached_run_does_not(tmp_path):
    model = tmp_path / "m.txt"
    model.write_text("x in [0, 1], y in [0, 1];\nConstraints\nx + y = 1.5, x * y >= 0.1;\n")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"),
               BOUNDEST_KERNEL_ARCHIVE="0")  # compiling, not loading the shipped kernels
    errs = []
    for _ in range(2):
        out = subprocess.run([sys.executable, "-c", COMPILES.format(model=str(model))], env=env,
                             capture_output=True, text=True, timeout=900)
        assert out.returncode == 0, out.stderr[-2000:]
        errs.append([line for line in out.stderr.splitlines() if "compiling" in line])
    assert len(errs[0]) == 1 and "boundest solve" in errs[0][0] and "about" in errs[0][0]
    assert errs[1] == []


def test_library_use_logs_its_first_compilation_once(caplog, monkeypatch):
    """A ``numba:compile`` event of one of boundest's kernels (what Numba sends on a cache miss)
    logs one WARNING on ``boundest.kernels``, once per process; a user's own function, none."""
    import logging

    import numba
    from numba.core import event

    from boundest import _kernels
    from boundest.interval import rounding

    for listener in getattr(_kernels, "_LIBRARY_NOTICE", []):
        monkeypatch.setattr(listener, "said", False)  # as in a fresh process
    monkeypatch.setattr(_kernels, "_CLI_ANNOUNCES", False, raising=False)
    users = numba.njit(lambda v: v + 1.0)  # compiled only when called: never here

    def compile_event(dispatcher):
        with event.trigger_event("numba:compile", data={"dispatcher": dispatcher}):
            pass

    with caplog.at_level(logging.WARNING):
        compile_event(users)
        assert caplog.records == []
        compile_event(rounding.next_up)
        compile_event(rounding.next_down)
    notes = [(r.name, r.levelno, r.getMessage()) for r in caplog.records]
    assert len(notes) == 1, notes
    name, level, text = notes[0]
    assert (name, level) == ("boundest.kernels", logging.WARNING)
    assert "compiling" in text and "next_up" in text and "setLevel(logging.ERROR)" in text


NOTICE = """
import logging, sys
import numpy as np
if sys.argv[1] == "quiet":
    logging.getLogger("boundest").setLevel(logging.ERROR)
from boundest.interval import rounding
rounding.next_up(np.float32(1.0))  # a signature no cache holds: Numba compiles it
rounding.next_down(np.float32(1.0))
"""


@pytest.mark.slow  # three subprocesses, each compiling two small kernels: about 15 s
def test_a_first_compilation_in_library_use_is_said_once_on_stderr(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), BOUNDEST_KERNEL_ARCHIVE="0")
    errs = {}
    for run, cache in (("quiet", "q"), ("first", "c"), ("cached", "c")):
        env["NUMBA_CACHE_DIR"] = str(tmp_path / cache)
        out = subprocess.run([sys.executable, "-c", NOTICE, run], env=env, capture_output=True,
                             text=True, timeout=300)
        assert out.returncode == 0, out.stderr[-2000:]
        errs[run] = [line for line in out.stderr.splitlines() if "compiling" in line]
    assert errs["quiet"] == [] and errs["cached"] == [], errs
    assert len(errs["first"]) == 1 and "next_up" in errs["first"][0], errs


CONSOLE = """
import atexit, sys
atexit.register(lambda: print("exit handler ran"))
from boundest.cli import console
sys.argv = ["boundest", "demo", "--out", {out!r}]
console()
print("not reached: console() exits")
"""


def test_the_console_script_runs_the_exit_handlers_and_flushes_its_output(tmp_path):
    """``console`` skips the interpreter's teardown, not the exit handlers nor the output."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}  # buffered pipes
    out = subprocess.run([sys.executable, "-c", CONSOLE.format(out=str(tmp_path))], env=env,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    lines = out.stdout.splitlines()
    assert lines[-1] == "exit handler ran", lines[-3:]
    assert any(ln.startswith("wrote ") for ln in lines) and "not reached" not in out.stdout
    assert list(tmp_path.glob("*.png"))


def test_each_command_in_one_process_announces_itself_once(capsys, monkeypatch):
    """``boundest.cli.main`` called again in one process (docs, notebooks, tests) keeps one
    compilation notice, aimed at the latest command: one line per command at most, naming it
    (each call used to register one more listener, so a compilation printed the earlier
    commands' lines too)."""
    from numba.core import event

    from boundest import _kernels
    from boundest.interval import rounding

    monkeypatch.setattr(_kernels, "_CLI_ANNOUNCES", False, raising=False)
    monkeypatch.setattr(_kernels, "STATUS", "not used: test")

    def compile_event():
        with event.trigger_event("numba:compile", data={"dispatcher": rounding.next_up}):
            pass

    try:
        _kernels.announce_compilation("'boundest run satellite'", 62.0)
        _kernels.announce_compilation("'boundest run pool'", 45.0)
        compile_event()
        compile_event()
        lines = [ln for ln in capsys.readouterr().err.splitlines() if "compiling" in ln]
        assert len(lines) == 1 and "'boundest run pool'" in lines[0], lines
        assert "about 45 s" in lines[0]
        _kernels.announce_compilation("'boundest demo'", None)
        compile_event()
        lines = [ln for ln in capsys.readouterr().err.splitlines() if "compiling" in ln]
        assert len(lines) == 1 and "'boundest demo'" in lines[0], lines
    finally:
        for notice in getattr(_kernels, "_COMMAND_NOTICE", []):
            notice.said = True  # silent for the rest of this process
