"""Numba kernels divide like IEEE 754, whichever kernel compiles first.

Numba compiles a helper called from several kernels once, with the flags of the first caller
compiled in a process, and caches that machine code on disk. A helper first compiled from a
kernel with Numba's default ``error_model="python"`` raises ``ZeroDivisionError`` on ``a / 0``
for every later caller, in every later process: ``[entire] / [0, 0]`` crashed after a run that
had compiled ``CtcDeriv`` first. Every ``njit`` of the package must say ``error_model="numpy"``.
"""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

import boundest

SRC = Path(boundest.__file__).parent


def _njit_calls():
    for path in sorted(SRC.rglob("*.py")):
        tree = ast.parse(path.read_text(), str(path))
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and getattr(node.func, "attr", None) == "njit":
                yield path, node


def test_every_njit_uses_the_numpy_error_model():
    calls = list(_njit_calls())
    assert len(calls) >= 10  # the scan sees the package's kernels
    bad = [f"{p.relative_to(SRC)}:{n.lineno}" for p, n in calls
           if not any(k.arg == "error_model" and isinstance(k.value, ast.Constant)
                      and k.value.value == "numpy" for k in n.keywords)]
    assert not bad, f"njit without error_model='numpy': {', '.join(bad)}"


SCRIPT = """
import boundest as bd
from boundest.tube import CtcDeriv, Tube
x = Tube.constant(0, 1, 4, bd.Interval.entire())
x.gates[0] = bd.Interval(0, 0)
CtcDeriv().contract(x, Tube.constant(0, 1, 4, bd.Interval(1, 2)))
q = bd.Interval.entire() / bd.Interval(0.0, 0.0)
r = bd.Interval(1, 2) / bd.Interval(0.0, 1.0)
print(bool(q.is_empty()), float(r.lo), float(r.hi))
"""


@pytest.mark.slow  # two subprocesses that compile with the archive off, 8-10 s
def test_division_by_zero_after_a_tube_kernel_compiled_first(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), BOUNDEST_KERNEL_ARCHIVE="0")
    for _ in range(2):  # compiling, then loading what the first run cached
        out = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True,
                             text=True, timeout=900)
        assert out.returncode == 0, out.stderr[-2000:]
        assert out.stdout.split() == ["True", "1.0", "inf"]
