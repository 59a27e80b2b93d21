"""Expressions of any width and depth, at every stage (issue 27, item 1).

A constraint with a few hundred terms used to die with a RecursionError: the model file's
parse tree was as deep as its sum was long and lark's transformer recursed on it, and the tape
builder, the printer, pickling and deepcopy recursed once per level of an expression. Each test
below failed so on the code before the fix (10**4 terms or levels, far beyond Python's default
limit of 1000 frames; 500 terms for the smallest). Expected domains are derived by hand:

* ``x_k in [0, 1]``, ``x_0 + ... + x_{n-1} = n - 0.5``: the hull of the solutions is
  ``x_k in [0.5, 1]`` (the others sum to at most ``n - 1``), which hull consistency reaches
  along the chain of partial sums;
* ``y = sqrt(1 + sqrt(1 + ... sqrt(1 + x)))``, ``x in [0, 1]``: each level maps ``[a, b]`` into
  an interval ``1 / (2 sqrt(1 + a)) <= 1/2`` times as wide around the golden ratio, its fixed
  point, so after 10**4 levels ``y`` is the golden ratio to the last bit;
* ``e_k = 0.5 * e_{k-1} + 1`` from ``e_0 = x in [0, 1]``: ``e_N = 2 - (2 - x) / 2**N``, which is
  2 to the last bit for ``N = 10**4``.
"""

from __future__ import annotations

import copy
import json
import math
import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import boundest
from boundest.cli import main
from boundest.csp import propagate
from boundest.ctc import derivatives
from boundest.ctc.fwdbwd import CtcFwdBwd
from boundest.expr import Const, Constraint, Model, Op, Var, parse_model
from boundest.expr import functions as ef
from boundest.expr.function_tape import function_tape
from boundest.expr.nodes import _INFIX
from boundest.expr.tape import _CODE, _Builder, compile_model
from boundest.interval import Interval

WIDE = 10_000
DEEP = 10_000
PHI = (1 + math.sqrt(5)) / 2


def sum_model_text(n: int) -> str:
    names = [f"x{k}" for k in range(n)]
    return ("Variables\n" + ",\n".join(f"  {v} in [0, 1]" for v in names) + ";\n"
            "Constraints\n  " + " + ".join(names) + f" = {n - 0.5};\n")


def check_sum_hull(domains, n: int) -> None:
    """Every ``x_k`` is the hull ``[0.5, 1]``, enclosed outward by at most a rounding error."""
    lo = np.array([float(domains[f"x{k}"][0]) for k in range(n)])
    hi = np.array([float(domains[f"x{k}"][1]) for k in range(n)])
    assert np.all(lo <= 0.5) and np.all(lo >= 0.5 - 1e-9) and np.all(hi == 1.0)


def sum_model(n: int, *, loop: bool) -> Model:
    xs = [Var(f"x{k}") for k in range(n)]
    m = Model()
    for v in xs:
        m.declare(v, (0, 1))
    if loop:
        e = xs[0]
        for v in xs[1:]:
            e = e + v
    else:
        e = sum(xs)  # 0 + x0 + x1 + ...
    return m.add(e == n - 0.5)


def halving_chain(depth: int, x: Var):
    """``0.5 * (0.5 * (... 0.5 * x + 1 ...) + 1) + 1``, ``depth`` times."""
    e = x
    for _ in range(depth):
        e = 0.5 * e + 1
    return e


# -------------------------------------------------------------------------------------------
# the model file, through `boundest solve`
# -------------------------------------------------------------------------------------------

@pytest.mark.parametrize(("n", "mode"), [
    (500, "3b+centered"),
    pytest.param(WIDE, "hc4", marks=pytest.mark.slow),  # 10**4 declarations: about 9 s
])
def test_a_long_sum_in_a_model_file_is_solved(tmp_path, capsys, n, mode):
    f, js = tmp_path / "sum.txt", tmp_path / "sum.json"
    f.write_text(sum_model_text(n))
    assert main(["solve", str(f), "--mode", mode, "--json", str(js)]) == 0
    out = capsys.readouterr().out
    assert f"{n} variables, 1 constraints: consistent; mode {mode}" in out
    check_sum_hull(json.loads(js.read_text())["domains"], n)


def test_a_deeply_nested_model_file_is_solved(tmp_path, capsys):
    f, js = tmp_path / "deep.txt", tmp_path / "deep.json"
    f.write_text("Variables x in [0, 1], y in [0, 10];\nConstraints\n  y = "
                 + "sqrt(1 + " * DEEP + "x" + ")" * DEEP + ";\n")
    assert main(["solve", str(f), "--json", str(js)]) == 0
    y = json.loads(js.read_text())["domains"]["y"]
    assert y[0] <= PHI + 1e-15 and y[1] >= PHI - 1e-15 and y[1] - y[0] < 1e-12
    assert "consistent" in capsys.readouterr().out


def test_deep_parentheses_and_operators_parse_as_python_builds_them():
    n = 2_000
    text = ("x in [0, 1], y in [-oo, +oo];\nConstraints\n  y = "
            + "0.5 * (" * (n - 1) + "0.5 * x + 1" + ") + 1" * (n - 1) + ",\n"
            + "  y <= " + "-(" * n + "x" + ")" * n + " + 3 - x * x / 2 ^ 2;\n")
    m = parse_model(text)
    x = Var("x")
    assert str(m.constraints[0].rhs) == str(halving_chain(n, x))
    assert str(m.constraints[1].rhs) == "-" * n + "x + 3 - x * x / 2^2"  # --x is -(-x)
    neg = m.constraints[1].rhs.args[0].args[0]  # ((--...x) + 3) - ...: the negations
    for _ in range(n):
        assert neg.name == "neg"
        neg = neg.args[0]
    assert neg is m.constraints[1].rhs.args[1].args[0].args[0]  # one declared variable x


# -------------------------------------------------------------------------------------------
# the Python front end: building, compiling, propagating, differentiating
# -------------------------------------------------------------------------------------------

@pytest.mark.parametrize(("n", "loop", "mode"), [(500, False, None), (WIDE, True, "hc4")])
def test_a_long_sum_built_in_python_propagates(n, loop, mode):
    res = propagate(sum_model(n, loop=loop), mode=mode)
    assert res.consistent and res.n_nodes == n - loop  # sum() starts from 0 + x0
    check_sum_hull({k: (v.lo, v.hi) for k, v in res.domains.items()}, n)


def test_a_deep_expression_built_in_python_propagates():
    x, y = Var("x"), Var("y")
    m = Model()
    m.declare(x, (0, 1))
    m.add(y == halving_chain(DEEP, x))
    res = propagate(m)  # the default mode: shaving, then the centered form of the chain
    t = compile_model(m)
    assert t.n_nodes == 2 * DEEP  # one mul and one add per level, in forward order
    assert all(t.a[i] < t.out[i] for i in range(t.n_nodes) if t.out[i] != t.slot_of["y"])
    lo, hi = float(res["y"].lo), float(res["y"].hi)
    assert lo <= 2.0 <= hi + 1e-15 and hi - lo < 1e-12
    assert float(res["x"].lo) == 0.0 and float(res["x"].hi) == 1.0


def test_a_deep_function_tape_is_evaluated_and_differentiated():
    x = Var("x")
    e = x
    for _ in range(DEEP):
        e = ef.sin(e)
    tape = function_tape([e])
    assert tape.n_outputs == 1 and len(tape.op) == DEEP
    box = Interval([0.5], [0.5])
    v = derivatives.evaluate(tape, box)
    s = 0.5
    for _ in range(DEEP):
        s = math.sin(s)
    assert float(v.lo[0]) <= s + 1e-12 and float(v.hi[0]) >= s - 1e-12  # sin^N(0.5) ~ 0.0173
    assert float(v.hi[0] - v.lo[0]) < 1e-9
    _, jac = derivatives.jacobian(tape, Interval([0.0], [1.0]))
    # the derivative is the product of the cosines along the chain: in ]0, 1]
    assert float(jac.lo[0, 0]) >= 0.0 and 0.0 < float(jac.hi[0, 0]) <= 1.0


def test_printing_a_wide_or_deep_expression():
    xs = [Var(f"x{k}") for k in range(WIDE)]
    wide = sum(xs[1:], xs[0])
    assert str(wide) == " + ".join(f"x{k}" for k in range(WIDE))
    assert repr(wide == 1) == "Constraint(" + " + ".join(f"x{k}" for k in range(WIDE)) + " == 1)"
    assert str(xs[0] - (xs[1] - (xs[2] - xs[3]))) == "x0 - (x1 - (x2 - x3))"
    x = Var("x")
    deep = halving_chain(DEEP, x)
    text = "0.5 * (" * (DEEP - 1) + "0.5 * x + 1" + ") + 1" * (DEEP - 1)
    assert str(deep) == text and repr(deep) == f"Expr({text})"
    e = x
    for _ in range(DEEP):
        e = ef.sqrt(-e)
    assert str(e) == "sqrt(-" * DEEP + "x" + ")" * DEEP


# -------------------------------------------------------------------------------------------
# Python's own machinery: pickling for worker processes, deepcopy
# -------------------------------------------------------------------------------------------

def same_tape(t1, t2) -> None:
    for f in ("lo", "hi", "op", "out", "a", "b", "param"):
        np.testing.assert_array_equal(getattr(t1, f), getattr(t2, f))
    assert t1.slot_of == t2.slot_of


def test_deep_models_pickle_and_deepcopy():
    # 2000 levels: pickle and deepcopy recursed a few C frames per level, and a level costs
    # about 100 us to pickle (its constants are Intervals of NumPy scalars)
    x, y, z = Var("x"), Var("y"), Var("z")
    shared = halving_chain(2_000, x) + Const(Interval(0, 1))  # an interval: one value per use
    m = Model()
    m.declare(x, (0, 1))
    m.add(y == shared, z == shared * shared, y <= sum([x] * 600))
    for m2 in (pickle.loads(pickle.dumps(m)), copy.deepcopy(m)):
        assert m2.domains.keys() == m.domains.keys()
        assert [c.rel for c in m2.constraints] == ["==", "==", "<="]
        c0, c1 = m2.constraints[0], m2.constraints[1]
        assert c0.rhs is c1.rhs.args[0] is c1.rhs.args[1]  # sharing kept across constraints
        same_tape(compile_model(m2), compile_model(m))
    e = pickle.loads(pickle.dumps(shared * shared))
    assert e.args[0] is e.args[1] and str(e) == str(shared * shared)
    c = copy.deepcopy(y == shared)
    assert isinstance(c, Constraint) and str(c) == str(y == shared)
    ctc = CtcFwdBwd(m, ["x", "y", "z"])
    box = Interval([0.0, -10, -10], [1.0, 10, 10])
    back = pickle.loads(pickle.dumps(ctc))  # what sivia(executor=...) sends to a worker
    got, want = back(box), ctc(box)
    np.testing.assert_array_equal(got.lo, want.lo)
    np.testing.assert_array_equal(got.hi, want.hi)


# -------------------------------------------------------------------------------------------
# the walks keep the recursive definitions' results: the old code as the oracle
# -------------------------------------------------------------------------------------------

def recursive_str(e) -> str:
    """Op.__str__ as it was, recursive."""
    def paren(a, prec, right=False):
        if isinstance(a, Op):
            p = _INFIX.get(a.name, (None, 5 if a.name not in ("neg",) else 3))[1]
            if p < prec or (right and p == prec):
                return f"({recursive_str(a)})"
        elif isinstance(a, Const) and float(a.value.lo) < 0:
            return f"({recursive_str(a)})"
        return recursive_str(a)

    if not isinstance(e, Op):
        return str(e)
    if e.name in _INFIX:
        sym, prec = _INFIX[e.name]
        return f"{paren(e.args[0], prec)} {sym} {paren(e.args[1], prec, right=True)}"
    if e.name == "neg":
        return f"-{paren(e.args[0], 3)}"
    if e.name == "sqr":
        return f"{paren(e.args[0], 4)}^2"
    if e.name == "pown":
        return f"{paren(e.args[0], 4)}^{e.param}"
    return f"{e.name}({', '.join(recursive_str(a) for a in e.args)})"


def recursive_expr(self, e):
    """_Builder._expr as it was, recursive."""
    s = self.memo.get(id(e))
    if s is not None:
        return s, True
    shared = True
    if isinstance(e, Var):
        s = self.var(e.name)
    elif isinstance(e, Const):
        lo, hi = float(e.value.lo), float(e.value.hi)
        key = ("point", lo) if lo == hi else (None if e.exact is None else ("exact", e.exact))
        if key is None:
            s, shared = self.new_slot(lo, hi), False
        else:
            s = self.const_slot.get(key)
            if s is None:
                s = self.const_slot[key] = self.new_slot(lo, hi)
            else:
                self.restrict(s, lo, hi)
    else:
        args = [recursive_expr(self, a) for a in e.args]
        shared = all(sh for _, sh in args)
        a, b = args[0][0], (args[1][0] if len(args) == 2 else -1)
        param = float(e.param) if e.param is not None else 0.0
        key = (_CODE[e.name], a, b, param)
        node = self.node_of.get(key)
        if node is None:
            s = self.new_slot()
            self.node_of[key] = len(self.nodes)
            self.nodes.append((key[0], s, a, b, param))
        else:
            s = self.nodes[node][1]
    if shared:
        self.memo[id(e)] = s
        self.keep.append(e)
    return s, shared


LEAVES = [Var("x"), Var("y"), Const(2.0), Const(-1.5), Const(Interval(-1, 1)),
          Const(Interval(0.25, 0.5))]


@st.composite
def dags(draw):
    """Random expressions whose nodes are reused by identity (a DAG), with shared and
    interval constants, every operator's printing rule and negative constants."""
    pool = list(LEAVES)
    for _ in range(draw(st.integers(1, 25))):
        a, b = (pool[draw(st.integers(0, len(pool) - 1))] for _ in range(2))
        kind = draw(st.sampled_from(["add", "sub", "mul", "div", "neg", "sqr", "pown", "sin",
                                     "atan2", "pow"]))
        if kind in ("add", "sub", "mul", "div", "atan2", "pow"):
            pool.append(Op(kind, (a, b)))
        elif kind == "pown":
            pool.append(Op("pown", (a,), draw(st.sampled_from([-3, 3, 0]))))
        else:
            pool.append(Op(kind, (a,)))
    return pool[-3:]


@settings(max_examples=200)
@given(dags())
def test_iterative_walks_match_the_recursive_definitions(roots):
    for e in roots:
        assert str(e) == recursive_str(e)
    cons = [roots[0] == roots[1], roots[2] <= 1]
    t_new = compile_model(cons)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(_Builder, "_expr", recursive_expr)
        t_old = compile_model(cons)
    same_tape(t_new, t_old)
    f_new = function_tape(roots)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(_Builder, "_expr", recursive_expr)
        f_old = function_tape(roots)
    for f in ("lo", "hi", "op", "out", "a", "b", "param", "node_ptr", "out_slot", "cols"):
        np.testing.assert_array_equal(getattr(f_new, f), getattr(f_old, f))
    back = pickle.loads(pickle.dumps(Model(constraints=cons)))
    same_tape(compile_model(back), t_new)
    assert [str(c) for c in back.constraints] == [str(c) for c in cons]


def test_boundest_top_level_functions_build_deep_expressions():
    x = boundest.Var("x")
    e = x
    for _ in range(DEEP):
        e = boundest.exp(boundest.log(e))
    res = propagate([e == 3, x.in_((0, 10))], mode="hc4")
    assert float(res["x"].lo) <= 3 <= float(res["x"].hi) and float(res["x"].hi - res["x"].lo) < 1e-9
