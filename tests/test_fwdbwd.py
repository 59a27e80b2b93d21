"""``CtcFwdBwd`` runs one compiled kernel over the batch: each box gets the classic HC4 pass
(every image forward, then every projection backward). It is checked against a node-by-node
reference written with the NumPy interval functions (the contractor's former implementation),
on batches of every shape, empty boxes, and variables sharing a slot."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from boundest import interval as iv
from boundest.ctc import CtcFwdBwd
from boundest.ctc.fwdbwd import FORWARD
from boundest.expr import Var, parse_model
from boundest.expr.tape import OPS
from boundest.interval import Interval

from .strategies import solvable_csps

#: NumPy projection of each primitive: ``f_rev(z, x) -> x'`` or ``f_rev(z, x, y) -> (x', y')``.
BACKWARD = {
    "neg": iv.neg_rev, "sqr": iv.sqr_rev, "sqrt": iv.sqrt_rev, "exp": iv.exp_rev,
    "log": iv.log_rev, "sin": iv.sin_rev, "cos": iv.cos_rev, "tan": iv.tan_rev,
    "asin": iv.asin_rev, "acos": iv.acos_rev, "atan": iv.atan_rev, "sinh": iv.sinh_rev,
    "cosh": iv.cosh_rev, "tanh": iv.tanh_rev, "abs": iv.abs_rev, "sign": iv.sign_rev,
    "floor": iv.floor_rev, "ceil": iv.ceil_rev,
    "pown": lambda z, x, n: iv.pown_rev(z, x, int(n)),
    "add": iv.add_rev, "sub": iv.sub_rev, "mul": iv.mul_rev, "div": iv.div_rev,
    "pow": iv.pow_rev, "atan2": iv.atan2_rev, "min": iv.min_rev, "max": iv.max_rev,
}
assert set(BACKWARD) == set(OPS)


def reference(ctc: CtcFwdBwd, x: Interval) -> Interval:
    """The HC4 pass node by node over whole columns of the batch (NumPy interval functions)."""
    t, slots = ctc.tape, ctc._slots
    batch = x.shape[:-1]
    lo = np.broadcast_to(t.lo.reshape(-1, *[1] * len(batch)), (t.n_slots, *batch)).copy()
    hi = np.broadcast_to(t.hi.reshape(-1, *[1] * len(batch)), (t.n_slots, *batch)).copy()
    xlo, xhi = np.moveaxis(x.lo, -1, 0), np.moveaxis(x.hi, -1, 0)
    for j, s in enumerate(slots):
        lo[s] = np.maximum(lo[s], xlo[j])
        hi[s] = np.minimum(hi[s], xhi[j])
    bad = ~(lo <= hi)
    bad |= bad.any(axis=0)
    lo[bad] = hi[bad] = np.nan

    def dom(s):
        return Interval._new(lo[s], hi[s])

    def put(s, v):
        lo[s], hi[s] = v.lo, v.hi

    for i in range(t.n_nodes):
        name, o, a, b = OPS[t.op[i]], t.out[i], t.a[i], t.b[i]
        args = (dom(a), t.param[i]) if name == "pown" else (
            (dom(a),) if b < 0 else (dom(a), dom(b)))
        put(o, iv.intersect(dom(o), FORWARD[name](*args)))
    for i in range(t.n_nodes - 1, -1, -1):
        name, o, a, b = OPS[t.op[i]], t.out[i], t.a[i], t.b[i]
        if name == "pown":
            put(a, BACKWARD[name](dom(o), dom(a), t.param[i]))
        elif b < 0:
            put(a, BACKWARD[name](dom(o), dom(a)))
        else:
            xa, xb = BACKWARD[name](dom(o), dom(a), dom(b))
            if a == b:
                put(a, iv.intersect(xa, xb))
            else:
                put(a, xa)
                put(b, xb)
    empty = np.isnan(lo).any(axis=0)
    rlo, rhi = np.moveaxis(lo[slots], 0, -1), np.moveaxis(hi[slots], 0, -1)
    rlo, rhi = np.maximum(rlo, x.lo), np.minimum(rhi, x.hi)
    rlo[empty] = rhi[empty] = np.nan
    return Interval._new(rlo, rhi)


def assert_same(r: Interval, s: Interval) -> None:
    assert r.shape == s.shape
    assert np.array_equal(r.lo, s.lo, equal_nan=True), (r, s)
    assert np.array_equal(r.hi, s.hi, equal_nan=True), (r, s)


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(solvable_csps((1, 3), 3, [0.0, 1e-9, 0.01, 0.3], 7), st.integers(0, 2**32 - 1))
def test_the_kernel_is_the_hc4_pass_of_the_reference(csp, seed):
    """On random CSPs (add, sub, mul, sqr, sin, cos, div: the same scalar kernels either way)
    and a batch of random sub-boxes, the compiled pass equals the NumPy one bit for bit."""
    model, _, pts = csp
    ctc = CtcFwdBwd(model)
    rng = np.random.default_rng(seed)
    m = len(ctc.variables)
    a, b = rng.uniform(-3, 3, (2, 7, m))
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    lo[0], hi[0] = -np.inf, np.inf
    lo[1] = hi[1] = np.nan  # an empty box stays empty
    x = Interval._new(lo, hi)
    r = ctc(x)
    assert_same(r, reference(ctc, x))
    assert np.isnan(r.lo[1]).all()
    for p in pts:  # the known solutions stay in the entire box's contraction
        for j, v in enumerate(ctc.variables):
            if v.startswith("x"):
                assert r.lo[0, j] <= p[int(v[1:])] <= r.hi[0, j]


MODEL = parse_model("""
x in [-3, 3], y in [0.1, 4], z in [-10, 10];
Constraints
  exp(x) + log(y) - z = 1,
  x^3 + abs(y - 2) <= 5,
  atan2(y, x) + tan(x / 4) >= -1,
  min(x, y) + max(x, floor(z)) = 1,
  asin(x / 4) + pow(y, 1.5) <= 6;
""")


def test_every_family_is_sound_and_as_tight_as_the_reference():
    """Transcendental images use glibc's values in the kernel and NumPy's in the reference
    (each widened by its error bound), so the two agree to a few ulps; a solution is kept."""
    ctc = CtcFwdBwd(MODEL)
    boxes = Interval(np.array([[-3, 0.1, -10], [-1, 1, -5], [0, 0.5, 0]], dtype=float),
                     np.array([[3, 4, 10], [2, 3, 5], [1, 4, 8]], dtype=float))
    r, s = ctc(boxes), reference(ctc, boxes)
    assert not np.isnan(r.lo).any()
    assert np.allclose(r.lo, s.lo, rtol=1e-12, atol=1e-300)
    assert np.allclose(r.hi, s.hi, rtol=1e-12, atol=1e-300)
    # x = 0.5, y = 1: z = exp(0.5) - 1, and min + max = 0.5 + floor(z) = 1 holds
    p = np.array([0.5, 1.0, np.exp(0.5) - 1.0])
    assert np.all((r.lo[0] <= p) & (p <= r.hi[0]))


C = CtcFwdBwd([Var("x") + Var("y") == 3, Var("x") - Var("y") == 1], ["x", "y"])


@pytest.mark.parametrize("shape", [(), (1,), (5,), (2, 3), (2, 1, 3)])
def test_batches_of_every_shape_give_each_box_its_own_contraction(shape):
    rng = np.random.default_rng(len(shape))
    lo = rng.uniform(-1, 1, (*shape, 2))
    x = Interval._new(lo, lo + rng.uniform(0, 4, (*shape, 2)))
    r = C(x)
    assert r.shape == x.shape
    for k in np.ndindex(*shape):
        assert_same(r[k], C(x[k]))
    assert_same(r, reference(C, x))


def test_broadcast_transposed_and_read_only_batches():
    box = Interval([0, 0], [10, 10])
    want = C(box)
    lo = np.broadcast_to(box.lo, (4, 2))  # read-only, stride 0
    hi = np.broadcast_to(box.hi, (4, 2))
    r = C(Interval._new(lo, hi))
    assert_same(r, Interval._new(np.tile(want.lo, (4, 1)), np.tile(want.hi, (4, 1))))
    t = Interval._new(np.asfortranarray(np.tile(box.lo, (3, 1))),
                      np.asfortranarray(np.tile(box.hi, (3, 1))))
    assert_same(C(t), Interval._new(np.tile(want.lo, (3, 1)), np.tile(want.hi, (3, 1))))
    assert np.array_equal(box.lo, [0, 0])  # the argument is not modified


def test_variables_sharing_a_slot_meet():
    x, y = Var("x"), Var("y")
    ctc = CtcFwdBwd([x == y], ["x", "y"])
    assert ctc.tape.slot_of["x"] == ctc.tape.slot_of["y"]
    r = ctc(Interval([[0, 1], [0, 5]], [[2, 3], [1, 6]]))
    assert np.array_equal(r.lo[0], [1, 1]) and np.array_equal(r.hi[0], [2, 2])
    assert np.isnan(r.lo[1]).all() and np.isnan(r.hi[1]).all()  # [0, 1] and [5, 6] do not meet
    twice = CtcFwdBwd([x + 1 == 3], ["x", "x"])  # one variable listed twice
    assert_same(twice(Interval([0, 1], [5, 9])), Interval([2, 2], [2, 2]))
    assert np.isnan(twice(Interval([0, 2.5], [5, 9])).lo).all()  # x in [0, 5] and [2.5, 9]


def test_empty_boxes_and_empty_domains():
    r = C(Interval._new(np.array([[0, 0], [np.nan, 0], [5, 5]]),
                        np.array([[10, 10], [np.nan, 10], [10, 10]])))
    assert np.array_equal(r.lo[0], [1, 0]) and np.array_equal(r.hi[0], [3, 2])
    assert np.isnan(r.lo[1:]).all() and np.isnan(r.hi[1:]).all()  # no solution in row 2
    x = Var("x")
    never = CtcFwdBwd([x.in_((1, 2)), (x * x).in_((9, 10))], ["x"])
    assert np.isnan(never(Interval([[-5], [0]], [[5], [1.5]])).lo).all()
    no_nodes = CtcFwdBwd([x.in_((1, 2))], ["x"])  # a domain, no node
    assert_same(no_nodes(Interval([[0], [3]], [[1.5], [4]])),
                Interval._new(np.array([[1], [np.nan]]), np.array([[1.5], [np.nan]])))
    assert C(Interval._new(np.empty((0, 2)), np.empty((0, 2)))).shape == (0, 2)


SCRIPT = """
import numpy as np
from boundest.ctc import CtcFwdBwd, revise
from boundest.expr import Var
from boundest.interval import Interval
x, y = Var("x"), Var("y")
print(CtcFwdBwd([x * y + x == 2], ["x", "y"])(Interval([0, 0], [4, 4])))
print(*(len(f.signatures) for f in (revise._revise_piecewise, revise._revise_pown,
                                   revise._revise_explog, revise._revise_trig)))
"""


@pytest.mark.slow  # a subprocess compiling the kernel with an empty cache, about 15 s
def test_an_arithmetic_tape_compiles_no_other_family(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True,
                         text=True, timeout=900)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split("\n")[1] == "0 0 0 0"
