"""The propagation kernel compiles only the op families a tape uses, and every family still
contracts (a family left out would leave its nodes uncontracted: sound, but useless)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from boundest.csp import propagate
from boundest.ctc.revise import FAMILIES, family_flags
from boundest.expr import Var, parse_model
from boundest.expr.tape import OPS, compile_model

SCRIPT = """
from boundest.csp import propagate
from boundest.ctc import revise as engine
from boundest.expr import parse_model
res = propagate(parse_model("x in [0, 10], y in [0, 10]; Constraints x^3 + y = 2, x*y >= 0.5;"))
print(res.consistent, float(res["x"].hi) < 1.26)
for f in (engine._back_piecewise, engine._image_explog, engine._back_explog,
          engine._image_trig, engine._back_trig, engine._f_pown):
    print(f.__name__, len(f.signatures))
"""


@pytest.mark.slow  # a subprocess compiling with an empty cache, about 12 s
def test_an_arithmetic_tape_compiles_no_transcendental_kernel(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), BOUNDEST_KERNEL_ARCHIVE="0")
    out = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True,
                         text=True, timeout=900)
    assert out.returncode == 0, out.stderr[-2000:]
    lines = out.stdout.split("\n")
    assert lines[0] == "True True"
    assert lines[1:7] == ["_back_piecewise 0", "_image_explog 0", "_back_explog 0",
                          "_image_trig 0", "_back_trig 0", "_pown 1"]


def test_the_families_cover_every_op_outside_the_basic_arithmetic():
    basic = {"add", "sub", "mul", "div", "sqr", "sqrt", "neg"}
    covered = [OPS[c] for codes in FAMILIES.values() for c in codes]
    assert len(covered) == len(set(covered))
    assert set(covered) | basic == set(OPS) and not set(covered) & basic


def test_family_flags():
    tape = compile_model([Var("y") == Var("x") + 1])
    assert family_flags(tape.op) == (None, None, None, None)
    tape = compile_model([Var("y") == abs(Var("x")) + Var("x") ** 3])
    assert family_flags(tape.op) == (True, True, None, None)


@pytest.mark.parametrize(("constraint", "var", "hi"), [
    ("y = abs(x)", "x", 0.5), ("y = max(x, -x)", "x", 0.5), ("y = exp(x) - 1", "x", 0.406),
    ("y = atan2(x, 1)", "x", 0.547), ("y = sin(x / 2)", "x", 1.047), ("y = x^3", "x", 0.794),
    ("y = pow(x, 2.5)", "x", 0.758)])
def test_every_family_contracts(constraint, var, hi):
    m = parse_model(f"x in [0, 3], y in [0, 0.5]; Constraints {constraint};")
    res = propagate(m, rel_eps=1e-9, mode="hc4")
    assert res.consistent and float(res[var].lo) == 0.0
    assert hi - 1e-3 < float(res[var].hi) < hi + 1e-3
