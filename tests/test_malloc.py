"""``boundest._malloc``: glibc's heap thresholds are set by the command and on request, never
by an import, and left alone when the user says so."""

from __future__ import annotations

import os
import platform
import subprocess
import sys

import pytest

from boundest import _malloc

GLIBC = sys.platform.startswith("linux") and platform.libc_ver()[0] == "glibc"

PROBE = "import boundest._malloc as m; print(m.keep_freed_memory())"


def _probe(**env: str) -> str:
    base = {k: v for k, v in os.environ.items()
            if k not in ("BOUNDEST_MALLOC", "MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_")}
    out = subprocess.run([sys.executable, "-c", PROBE], env={**base, **env}, check=True,
                         capture_output=True, text=True)
    return out.stdout.strip()


@pytest.mark.skipif(not GLIBC, reason="mallopt is glibc's")
def test_thresholds_are_set_on_glibc():
    assert _probe() == "True"


def test_opt_outs_leave_the_allocator_alone():
    assert _probe(BOUNDEST_MALLOC="default") == "False"
    assert _probe(MALLOC_TRIM_THRESHOLD_="131072") == "False"
    assert _probe(MALLOC_MMAP_THRESHOLD_="131072") == "False"


def test_thresholds_are_bounded():
    # what a process may keep of freed memory stays a small part of a laptop's memory
    assert 0 < _malloc.MMAP_THRESHOLD <= _malloc.TRIM_THRESHOLD <= 2**30


SPY = r"""
import ctypes, sys
calls = []
real = ctypes.CDLL


class _Handle:  # the process's own symbols, with every mallopt lookup recorded
    def __init__(self, h):
        self._h = h

    def __getattr__(self, name):
        if name == "mallopt":
            calls.append(name)
        return getattr(self._h, name)


def _spy(name, *a, **k):
    h = real(name, *a, **k)
    return _Handle(h) if name is None else h


ctypes.CDLL = _spy
import boundest
import boundest.csp, boundest.interval, boundest.scenarios.satellite
boundest.Interval(0, 1) + 1
print(len(calls))
if sys.argv[1] == "ask":
    print(boundest.keep_freed_memory(), len(calls))
"""


def _spy(arg: str) -> list[str]:
    env = {k: v for k, v in os.environ.items()
           if k not in ("BOUNDEST_MALLOC", "MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_")}
    out = subprocess.run([sys.executable, "-c", SPY, arg], env=env, check=True,
                         capture_output=True, text=True)
    return out.stdout.split()


def test_importing_boundest_leaves_the_allocator_alone():
    """A fresh process that imports the library (its top, its layers, an interval operation)
    never looks up ``mallopt``."""
    assert _spy("import") == ["0"]


@pytest.mark.skipif(not GLIBC, reason="mallopt is glibc's")
def test_a_library_user_asks_for_the_tuning_in_one_call():
    assert _spy("ask") == ["0", "True", "1"]


def test_the_command_tunes_its_own_process(monkeypatch, tmp_path):
    from boundest import cli

    asked = []
    monkeypatch.setattr(_malloc, "keep_freed_memory", lambda: asked.append(1) or True)
    model = tmp_path / "m.txt"
    model.write_text("x in [0, 1];\nConstraints\nx >= 0.5;\n")
    assert cli.main(["solve", str(model), "--mode", "hc4"]) == 0
    assert asked == [1]
