"""The figure processes of the commands (``boundest.commands.figures``): jobs run in forked
children, their output comes back in the order submitted, a failure is raised in the parent,
the in-process fallback gives the same, and no child outlives its command."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

from boundest.commands.figures import FigureError, FigureWorker

linux = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="forks on Linux only")


def say(text: str, delay: float) -> None:
    time.sleep(delay)
    print(f"{text} from {os.getpid()}")


def fail(text: str, kind: type[Exception] = RuntimeError) -> None:
    print("before the failure")
    raise kind(text)


def _gone(pid: int) -> bool:
    """Whether ``pid`` has exited (a zombie nobody reaped counts as exited)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError):
        return True
    return state in ("Z", "X")


def _wait_gone(pids: list[int], timeout: float = 5.0) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if all(_gone(p) for p in pids):
            return True
        time.sleep(0.05)
    return False


@pytest.fixture
def single_threaded(monkeypatch):
    """Earlier tests may leave threads behind (Dask, tqdm's monitor), in which case the worker
    draws in-process (:func:`test_in_process_beside_other_threads`); these tests are about
    the children."""
    monkeypatch.setattr(threading, "active_count", lambda: 1)


@linux
def test_jobs_run_in_two_children_and_print_in_submission_order(capsys, single_threaded):
    w = FigureWorker(processes=2)
    assert w.forked
    # the first job is the slowest: the others finish before it, and still print after it
    w.submit(say, "one", 0.6)
    w.submit(say, "two", 0.0)
    w.submit(say, "three", 0.0)
    w.finish()
    lines = capsys.readouterr().out.splitlines()
    assert [ln.split(" from ")[0] for ln in lines] == ["one", "two", "three"]
    pids = {int(ln.split(" from ")[1]) for ln in lines}
    assert len(pids) == 2 and os.getpid() not in pids  # two children drew
    assert _wait_gone(sorted(pids)), "a figure process outlived finish()"


@linux
def test_a_failure_is_raised_in_the_parent_after_the_other_jobs(capsys, single_threaded):
    w = FigureWorker()
    w.submit(fail, "no such axis")
    w.submit(say, "after", 0.0)
    with pytest.raises(FigureError, match="no such axis"):
        w.finish()
    out = capsys.readouterr().out
    assert "before the failure" in out and "after from" in out


@linux
@pytest.mark.parametrize("kind", [OSError, ValueError])
def test_bad_input_in_a_child_is_raised_as_it_is(kind, single_threaded):
    """An --out that cannot be written gives the command's one-line error, not a traceback."""
    w = FigureWorker()
    w.submit(fail, "cannot write out/x.png", kind)
    with pytest.raises(kind, match="cannot write") as info:
        w.finish()
    assert not isinstance(info.value, FigureError)


def test_in_process_when_disabled(monkeypatch, capsys):
    monkeypatch.setenv("BOUNDEST_FIGURE_PROCESS", "0")
    w = FigureWorker()
    assert not w.forked
    w.submit(say, "here", 0.0)  # at once, in this process
    assert capsys.readouterr().out == f"here from {os.getpid()}\n"
    w.finish()
    with pytest.raises(RuntimeError, match="in-process"):
        w.submit(fail, "in-process")


def test_in_process_beside_other_threads(capsys):
    """A fork would copy none of the other threads, and keep the locks they hold."""
    stop = threading.Event()
    t = threading.Thread(target=stop.wait, daemon=True)
    t.start()
    try:
        w = FigureWorker()
        assert not w.forked
        w.submit(say, "here", 0.0)
        w.finish()
    finally:
        stop.set()
        t.join()
    assert capsys.readouterr().out == f"here from {os.getpid()}\n"


@linux
def test_the_children_exit_when_the_command_is_killed(tmp_path):
    script = tmp_path / "cmd.py"
    script.write_text(textwrap.dedent("""
        import sys, time
        from boundest.commands.figures import FigureWorker
        w = FigureWorker()
        print(w._proc.pid, flush=True)
        time.sleep(60)
    """))
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True)
    try:
        first = int(proc.stdout.readline())
        children: list[int] = []
        end = time.monotonic() + 20
        while not children and time.monotonic() < end:  # the second child, once warm
            p = Path(f"/proc/{first}/task/{first}/children")
            children = [int(c) for c in p.read_text().split()] if p.exists() else []
            time.sleep(0.05)
        assert children, "the first figure process did not start the second"
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=10)
        assert _wait_gone([first, *children]), "a figure process outlived its killed parent"
    finally:
        if proc.poll() is None:
            proc.kill()


def _children() -> set[int]:
    pid = os.getpid()
    return {int(c) for p in Path(f"/proc/{pid}/task").glob("*/children")
            for c in p.read_text().split()}


@linux
def test_a_command_that_fails_leaves_no_figure_process(tmp_path, monkeypatch, single_threaded):
    from boundest.cli import main
    from boundest.commands import figures

    started = []
    monkeypatch.setattr(figures.FigureWorker, "__enter__",
                        lambda self: started.append(self.forked) or self)

    before = _children()
    bad = tmp_path / "bad.csv"  # read once the command runs (a missing file: refused before)
    bad.write_text("i,beacon,t_lo,t_hi,z_lo,z_hi\n1,alpha,nan,1,1,2\n")
    assert main(["run", "range-only", "--data", str(bad), "--out", str(tmp_path)]) == 2
    assert started == [True]  # the command did fork its figure processes
    end = time.monotonic() + 5
    while _children() - before and time.monotonic() < end:
        time.sleep(0.05)
    assert not _children() - before


@linux
def test_an_out_folder_that_is_a_file_is_one_line_of_error(tmp_path, capsys, single_threaded):
    from boundest.cli import main

    blocker = tmp_path / "file"
    blocker.write_text("")
    assert main(["run", "drifting-clock", "--out", str(blocker / "figs")]) == 2
    err = capsys.readouterr().err
    assert "boundest: error:" in err and "Traceback" not in err
