"""Contractors (boundest.ctc) and propagation (boundest.csp): soundness, composition, emptiness.

Soundness is checked against an independent oracle: random expression trees are drawn as plain
tuples, evaluated exactly at a float point ``p`` with mpmath (at 256 and 512 bits; a point where
the two disagree beyond 2**-120 of the largest intermediate magnitude is ill-conditioned, e.g.
a cancellation under a log or a division, and is skipped), and the constraint
``f(x) in [lo, hi]`` is built with a float interval ``[lo, hi]`` around the exact value. Every
contractor, and ``propagate``, must keep ``p``. Expected values of the explicit cases are derived
by hand in the comments.
"""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, note, settings
from hypothesis import strategies as st

from boundest import Interval
from boundest.csp import beta_tuning, propagate
from boundest.ctc import (
    CtcFwdBwd,
    Fixpoint,
    FunctionContractor,
    Inflate,
    Sequence,
    Union,
    shrink_ratio,
)
from boundest.expr import Const, Model, Op, Var, parse_model
from boundest.expr.tape import compile_model

from .checks import examples
from .strategies import ulps_apart

decimal_interval = Interval.from_decimal  # the public entry of boundest.interval.decimal

MAX = 1.7976931348623157e308
INF = math.inf
x, y, z, w, u = Var("x"), Var("y"), Var("z"), Var("w"), Var("u")
NAMES = ("x", "y", "z")


# -------------------------------------------------------------------------------------------
# exact evaluation of expression trees (an oracle independent of boundest)
# -------------------------------------------------------------------------------------------

UNARY_OPS = ("neg", "sqr", "sqrt", "exp", "log", "sin", "cos", "tan", "asin", "acos", "atan",
             "sinh", "cosh", "tanh", "abs", "sign", "floor", "ceil")
BINARY_OPS = ("add", "sub", "mul", "div", "pow", "atan2", "min", "max")
DECIMALS = ("0.1", "-2.3", "1.7", "3.14159", "0.001")


class SkipPointError(Exception):
    """The point is outside the function's domain, or the exact value is not trustworthy."""


def to_expr(t):
    kind = t[0]
    if kind == "var":
        return Var(t[1])
    if kind == "const":
        return Const(Interval(t[1], t[2]))
    _, name, args, param = t
    return Op(name, tuple(to_expr(a) for a in args), param)


def show(t) -> str:
    return str(to_expr(t))


def _near(a, target, tol) -> bool:
    """Whether ``a`` is within ``tol`` of ``target``, equality included: a value that rounded
    onto ``target`` (1 - 1e-248 onto 1) may lie on either side of it exactly."""
    return abs(a - target) < tol


def mp_eval(t, point: dict[str, mpmath.mpf], scale: list) -> mpmath.mpf:
    """Value of the tree at ``point`` (current mpmath precision); ``scale[0]`` collects the
    largest magnitude met. Raises ``SkipPointError`` outside the domain or near a discontinuity."""
    kind = t[0]
    if kind == "var":
        v = point[t[1]]
    elif kind == "const":
        v = (mpmath.mpf(t[1]) + mpmath.mpf(t[2])) / 2  # a point of the constant interval
    else:
        _, name, args, n = t
        vals = [mp_eval(a, point, scale) for a in args]
        a = vals[0]
        b = vals[1] if len(vals) == 2 else None
        tol = mpmath.ldexp(scale[0], -100)
        if name in ("exp", "sinh", "cosh") and abs(a) > 5000:
            raise SkipPointError  # astronomically large or small: keep mpmath fast
        if name == "neg":
            v = -a
        elif name == "sqr":
            v = a * a
        elif name == "sqrt":
            if a < 0 or abs(a) < tol:  # a rounded value this close to 0 may be negative
                raise SkipPointError
            v = mpmath.sqrt(a)
        elif name == "exp":
            v = mpmath.exp(a)
        elif name == "log":
            if a <= tol:
                raise SkipPointError
            v = mpmath.log(a)
        elif name in ("sin", "cos", "tan", "atan", "sinh", "cosh", "tanh"):
            v = getattr(mpmath, name)(a)
        elif name in ("asin", "acos"):
            # |a| this close to 1 may be above 1 exactly: asin(exp(1e-300)) is undefined,
            # though exp(1e-300) rounds to 1 at any working precision
            if abs(a) > 1 or abs(abs(a) - 1) < tol:
                raise SkipPointError
            v = getattr(mpmath, name)(a)
        elif name == "abs":
            v = abs(a)
        elif name == "sign":
            if _near(a, 0, tol):
                raise SkipPointError
            v = mpmath.mpf(mpmath.sign(a))
        elif name in ("floor", "ceil"):
            if _near(a, mpmath.nint(a), tol):
                raise SkipPointError
            v = getattr(mpmath, name)(a)
        elif name == "pown":
            if n < 0 and a == 0:
                raise SkipPointError
            v = mpmath.mpf(1) if n == 0 else a**n
        elif name == "add":
            v = a + b
        elif name == "sub":
            v = a - b
        elif name == "mul":
            v = a * b
        elif name == "div":
            if b == 0:
                raise SkipPointError
            v = a / b
        elif name == "pow":  # IEEE 1788: x > 0, or x = 0 and y > 0
            if a > 0:
                if abs(b * mpmath.log(a)) > 5000:
                    raise SkipPointError
                v = mpmath.power(a, b)
            elif a == 0 and b > 0:
                v = mpmath.mpf(0)
            else:
                raise SkipPointError
        elif name == "atan2":  # atan2(y, x) = atan2(a, b)
            if a == 0 and b == 0:
                raise SkipPointError
            if b < 0 and _near(a, 0, tol):  # the branch cut on the negative x axis
                raise SkipPointError
            v = mpmath.atan2(a, b)
        elif name == "min":
            v = min(a, b)
        elif name == "max":
            v = max(a, b)
        else:  # pragma: no cover
            raise AssertionError(name)
    if abs(v) > mpmath.mpf("1e400"):
        raise SkipPointError
    scale[0] = max(scale[0], abs(v))
    return v


def exact(t, point: dict[str, float]):
    """``(v, delta)``: the value of the tree at the float point and a bound on its error, or
    ``SkipPointError``."""
    vals, scales = [], []
    for prec in (256, 512):
        with mpmath.workprec(prec):
            scale = [mpmath.mpf(0)]
            pt = {k: mpmath.mpf(val) for k, val in point.items()}
            for val in pt.values():
                scale[0] = max(scale[0], abs(val))
            vals.append(mp_eval(t, pt, scale))
            scales.append(scale[0])
    with mpmath.workprec(600):
        d = abs(vals[0] - vals[1])
        s = max(scales)
        if d > mpmath.ldexp(s, -120):
            raise SkipPointError  # ill-conditioned at this point
        return vals[1], 2 * d + mpmath.ldexp(s, -400)


def f_down(v) -> float:
    """Largest float <= v."""
    if v > MAX:
        return MAX
    if v < -MAX:
        return -INF
    f = float(v)
    if mpmath.mpf(f) > v:
        f = float(np.nextafter(f, -INF))
    return f


def f_up(v) -> float:
    """Smallest float >= v."""
    return -f_down(-v)


def mp_in(v, lo: float, hi: float) -> bool:
    if math.isnan(lo) or math.isnan(hi):
        return False
    return mpmath.mpf(lo) <= v <= mpmath.mpf(hi)


# -------------------------------------------------------------------------------------------
# strategies
# -------------------------------------------------------------------------------------------

leaf = st.one_of(
    st.sampled_from(NAMES).map(lambda n: ("var", n)),
    st.sampled_from(NAMES).map(lambda n: ("var", n)),
    st.floats(-4, 4, allow_nan=False).map(lambda c: ("const", c, c)),
    st.sampled_from(DECIMALS).map(
        lambda s: ("const", float(decimal_interval(s).lo), float(decimal_interval(s).hi))),
)


def _extend(children):
    return st.one_of(
        st.tuples(st.sampled_from((*UNARY_OPS, "pown", "pown")), children,
                  st.integers(-3, 5)).map(
            lambda t: ("op", t[0], (t[1],), t[2] if t[0] == "pown" else None)),
        st.tuples(st.sampled_from(BINARY_OPS), children, children).map(
            lambda t: ("op", t[0], (t[1], t[2]), None)),
    )


trees = st.recursive(leaf, _extend, max_leaves=6)

points = st.one_of(
    st.floats(-5, 5, allow_nan=False),
    st.sampled_from([0.0, -0.0, 1.0, -1.0, 0.5, 2.0, -2.0, 3.0, 1e-300]),
    st.floats(-1e8, 1e8, allow_nan=False),
    st.integers(-10, 10).map(float),
)
margins = st.one_of(st.just(0.0), st.floats(0, 1e-6), st.floats(0, 10), st.floats(0, 1e6),
                    st.just(INF))


@st.composite
def box_around(draw, p: dict[str, float], names=NAMES) -> Interval:
    lo = [p[n] - draw(margins) for n in names]
    hi = [p[n] + draw(margins) for n in names]
    return Interval(lo, hi)


@st.composite
def target_around(draw, v, delta) -> Interval:
    """A float interval containing ``[v - delta, v + delta]``: the tightest one (half of the
    draws), a wider one, or a half-infinite one."""
    with mpmath.workprec(600):
        lo = f_down(mpmath.fsub(v, delta, exact=True))
        hi = f_up(mpmath.fadd(v, delta, exact=True))
    kind = draw(st.integers(0, 3))
    if kind == 1:
        lo, hi = lo - draw(st.floats(0, 10)), hi + draw(st.floats(0, 10))
    elif kind == 2:
        lo = -INF if draw(st.booleans()) else lo
        hi = INF if lo != -INF else hi
    return Interval(lo, hi)


@st.composite
def scenarios(draw, n_constraints=(1, 2)):
    """A point, a box around it and constraints ``f_i(x, y, z) in Z_i`` that the point
    satisfies exactly."""
    p = {n: draw(points) for n in NAMES}
    cons = []
    for _ in range(draw(st.sampled_from(n_constraints))):
        t = draw(trees)
        try:
            v, delta = exact(t, p)
        except SkipPointError:
            assume(False)
        note(f"f = {show(t)}, exact value {mpmath.nstr(v, 20)} (error <= {delta})")
        cons.append((t, v, delta, draw(target_around(v, delta))))
    return p, draw(box_around(p)), cons


def model_of(cons) -> Model:
    m = Model()
    for n in NAMES:
        m.declare(n)
    m.add(to_expr(t).in_(target) for t, _, _, target in cons)
    return m


def assert_point_kept(result: Interval, box: Interval, p: dict[str, float], names=NAMES):
    lo, hi = np.asarray(result.lo), np.asarray(result.hi)
    for i, n in enumerate(names):
        assert mp_in(mpmath.mpf(p[n]), float(lo[i]), float(hi[i])), (
            f"lost the solution {n} = {p[n]!r}: {result}")
    assert np.all(result.is_subset(box)), f"{result} is not inside {box}"


# -------------------------------------------------------------------------------------------
# 4. soundness on random constraints
# -------------------------------------------------------------------------------------------

@pytest.mark.slow  # 300 examples, about 75 s on 2 cores
@settings(max_examples=300, suppress_health_check=[HealthCheck.filter_too_much,
                                                   HealthCheck.too_slow])
@given(scenarios())
def test_fwdbwd_keeps_every_solution(scenario):
    p, box, cons = scenario
    model = model_of(cons)
    note(f"box {box}; constraints {[str(c) for c in model.constraints]}")
    ctc = CtcFwdBwd(model, list(NAMES))
    before = box.copy()
    r = ctc(box)
    assert np.all(box == before)  # the argument is not modified
    assert_point_kept(r, box, p)
    fix = Fixpoint(ctc, max_iter=30)
    assert_point_kept(fix(box), box, p)
    # a batch: the box, a wider one, the degenerate box at p and the entire box, at once
    pt = [p[n] for n in NAMES]
    boxes = Interval(np.stack([box.lo, np.nextafter(box.lo, -INF), pt, np.full(3, -INF)]),
                     np.stack([box.hi, np.nextafter(box.hi, INF), pt, np.full(3, INF)]))
    rb = ctc(boxes)
    assert rb.shape == (4, 3)
    for k in range(4):
        assert_point_kept(rb[k], boxes[k], p)
        one = ctc(boxes[k])  # batching changes nothing
        assert np.array_equal(rb[k].lo, one.lo, equal_nan=True)
        assert np.array_equal(rb[k].hi, one.hi, equal_nan=True)
    r4 = ctc(boxes.reshape(2, 2, 3))
    assert np.array_equal(r4.lo.reshape(4, 3), rb.lo, equal_nan=True)
    rf = fix(boxes)
    for k in range(4):
        assert_point_kept(rf[k], boxes[k], p)
    # one contractor per constraint, composed; a union with a contractor that has no solution
    # near p keeps p as well
    per = [CtcFwdBwd(model_of([c]), list(NAMES)) for c in cons]
    far = CtcFwdBwd([x.in_((1e300, 1e301)), y.in_((0, 1)), z.in_((0, 1))], list(NAMES))
    assert_point_kept(Sequence(*per)(box), box, p)
    assert_point_kept((per[0] | far)(box), box, p)
    assert_point_kept(Fixpoint(Sequence(*per), max_iter=30)(boxes)[0], box, p)
    # propagation to a fixed point on the primitive network
    # (hull consistency, and the default mode: shaving then the centered form)
    for mode in ("hc4", None):
        res = propagate(model, domains={n: box[i] for i, n in enumerate(NAMES)}, mode=mode)
        assert res.consistent
        dom = Interval.trusted([float(res[n].lo) for n in NAMES], [float(res[n].hi) for n in NAMES])
        assert_point_kept(dom, box, p)


@examples(200, 40)
def test_equality_with_a_result_variable_keeps_the_solution(n_examples):
    """``w == f(x, y, z)`` with ``w`` a variable whose value is the exact ``f(p)``."""
    @settings(max_examples=n_examples,
              suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])
    @given(scenarios(n_constraints=(1,)), st.data())
    def check(scenario, data):
        p, box, cons = scenario
        t, v, _, target = cons[0]
        m = Model()
        for n in NAMES:
            m.declare(n)
        m.add(w == to_expr(t))
        names = [*NAMES, "w"]
        box4 = Interval([*box.lo, target.lo], [*box.hi, target.hi])
        note(f"box {box4}")
        ctc = CtcFwdBwd(m, names)
        for c in (ctc, Fixpoint(ctc, max_iter=30)):
            r = c(box4)
            assert_point_kept(r[:3], box, p)
            assert mp_in(v, float(r.lo[3]), float(r.hi[3])), f"lost w = f(p): {r}"
            assert np.all(r.is_subset(box4))
        doms = {n: box4[i] for i, n in enumerate(names)}
        if data.draw(st.booleans()):  # the same through a compiled tape
            res = propagate(compile_model(m), domains=doms, mode="hc4")
        else:
            res = propagate(m, domains=doms, mode="hc4")
        assert res.consistent
        for i, n in enumerate(NAMES):
            assert mp_in(mpmath.mpf(p[n]), float(res[n].lo), float(res[n].hi)), n
            assert res[n].is_subset(box[i])
        assert mp_in(v, float(res["w"].lo), float(res["w"].hi))

    check()


@settings(max_examples=100)
@given(st.floats(-3, 3), st.floats(-3, 3), st.floats(0, 2), st.floats(0, 2))
def test_shared_subexpressions_and_repeated_variables(a, b, da, db):
    """``x*x``, ``x - x`` and a subtree used twice (one node after hash-consing)."""
    s = Op("sin", (x * y,))
    f = (x * x - y) * s + s / (2 + Op("cos", (x - x,)))
    with mpmath.workprec(300):
        ma, mb = mpmath.mpf(a), mpmath.mpf(b)
        ms = mpmath.sin(ma * mb)
        v = (ma * ma - mb) * ms + ms / 3
        lo, hi = f_down(v) - 1e-12, f_up(v) + 1e-12
    box = Interval([a - da, b - db], [a + da, b + db])
    ctc = CtcFwdBwd([f.in_(Interval(lo, hi))], ["x", "y"])
    assert_point_kept(Fixpoint(ctc)(box), box, {"x": a, "y": b}, names=("x", "y"))


# -------------------------------------------------------------------------------------------
# explicit contractions, derived by hand
# -------------------------------------------------------------------------------------------

def test_linear_pair_by_hand():
    # x + y = 3, x - y = 1 on [0, 10]^2. Forward: x+y = 3, x-y = 1. Backward (last node first):
    # x - y = 1 gives x = 1 + y = [1, 10], y = x - 1 = [0, 9]; x + y = 3 gives x = 3 - y = [1, 3],
    # y = 3 - x = [0, 2]. A second pass changes nothing: HC4's fixed point is not the solution
    # (2, 1).
    ctc = CtcFwdBwd([x + y == 3, x - y == 1], ["x", "y"])
    box = Interval([0, 0], [10, 10])
    r = ctc(box)
    assert np.all(r == Interval([1, 0], [3, 2]))
    assert np.all(Fixpoint(ctc)(box) == Interval([1, 0], [3, 2]))
    # the components follow the requested order
    r2 = CtcFwdBwd([x + y == 3, x - y == 1], ["y", "x"])(box)
    assert np.all(r2 == Interval([0, 1], [2, 3]))
    # an array of [lo, hi] pairs is accepted as a box
    assert np.all(ctc(np.array([[0.0, 10.0], [0.0, 10.0]])) == r)


def test_nonlinear_contractions_by_hand():
    sqrt2 = mpmath.sqrt(2)
    # x^2 = 2 on [-10, 10]: the hull of -sqrt(2) and sqrt(2)
    r = CtcFwdBwd([x**2 == 2], ["x"])(Interval([-10], [10]))
    lo, hi = float(r.lo[0]), float(r.hi[0])
    assert mpmath.mpf(lo) <= -sqrt2 and sqrt2 <= mpmath.mpf(hi)
    assert ulps_apart(lo, -float(sqrt2)) <= 2 and ulps_apart(hi, float(sqrt2)) <= 2
    # on [0, 10]: only the positive root
    r = CtcFwdBwd([x**2 == 2], ["x"])(Interval([0], [10]))
    lo, hi = float(r.lo[0]), float(r.hi[0])
    assert mpmath.mpf(lo) <= sqrt2 <= mpmath.mpf(hi) and ulps_apart(lo, hi) <= 4
    # sin(x) = 0 on [3, 4]: pi
    r = CtcFwdBwd([Op("sin", (x,)) == 0], ["x"])(Interval([3], [4]))
    assert mp_in(mpmath.pi, float(r.lo[0]), float(r.hi[0])) and float(r.width()[0]) < 1e-14
    # x * y = 1 with x in [1, 2], y in [0, 10]: y = 1 / x = [0.5, 1]
    r = CtcFwdBwd([x * y == 1], ["x", "y"])(Interval([1, 0], [2, 10]))
    assert np.all(r == Interval([1, 0.5], [2, 1]))
    # 1 / x in [1, 2] with x in [-5, 5]: x = [0.5, 1]
    r = CtcFwdBwd([(1 / x).in_((1, 2))], ["x"])(Interval([-5], [5]))
    assert np.all(r == Interval([0.5], [1]))
    # min(x, y) = 5 with x in [6, 10]: y = 5
    r = CtcFwdBwd([Op("min", (x, y)) == 5], ["x", "y"])(Interval([6, 0], [10, 10]))
    assert np.all(r == Interval([6, 5], [10, 5]))
    # exp(x) = 1: x = 0 up to rounding
    r = CtcFwdBwd([Op("exp", (x,)) == 1], ["x"])(Interval([-5], [5]))
    assert mp_in(0, float(r.lo[0]), float(r.hi[0])) and float(r.width()[0]) < 1e-15
    # an equality between variables shares their slot: both get the intersection
    r = CtcFwdBwd([x == y], ["x", "y"])(Interval([0, 1], [2, 3]))
    assert np.all(r == Interval([1, 1], [2, 2]))
    # declared domains of a model meet every box
    m = Model()
    m.declare("x", (0, 1))
    m.add(x + y == 2)
    r = CtcFwdBwd(m, ["x", "y"])(Interval.entire((2,)))
    assert np.all(r == Interval([0, 1], [1, 2]))


def test_float_integer_exponent_keeps_negative_solutions():
    r = CtcFwdBwd([x**2.0 == 4], ["x"])(Interval([-3], [3]))
    assert mp_in(-2, float(r.lo[0]), float(r.hi[0]))


@pytest.mark.parametrize("n", [1e20, 2.0**64, 1e300])
def test_huge_integer_exponent_keeps_negative_solutions(n):
    """Issue 27 item 7: x**n for an integer-valued float n beyond 2**63 is an (even) integer
    power, forward and backward, in the Python contractor and in the compiled engine (whose
    int64 conversion of the tape's exponent was undefined there: 1e20 became -2**63)."""
    # |x|**n >= 2 holds for |x| > 1 (2**(1/n) - 1 is below one ulp of 1), fails for |x| <= 1
    for ctc in (CtcFwdBwd([x**n >= 2], ["x"]),):
        r = ctc(Interval([-3], [0.5]))
        assert float(r.lo[0]) == -3.0 and -1.0 - 2**-52 <= float(r.hi[0]) < -1.0 + 2**-52, r
    res = propagate([x**n >= 2], domains={"x": Interval(-3, 0.5)}, mode="hc4")
    assert res.consistent and float(res["x"].lo) == -3.0, res["x"]
    assert -1.0 - 2**-52 <= float(res["x"].hi) < -1.0 + 2**-52, res["x"]
    # |x|**n <= 1: exactly |x| <= 1 (the bounds may keep one ulp more)
    res = propagate([x**n <= 1], domains={"x": Interval(-3, 3)}, mode="hc4")
    assert res.consistent and -1.0 - 2**-51 <= float(res["x"].lo) <= -1.0, res["x"]
    assert 1.0 <= float(res["x"].hi) <= 1.0 + 2**-51, res["x"]
    # a negative exponent: |x|**-n <= 1 for |x| >= 1, x**-n > 0 everywhere
    res = propagate([x ** (-n) >= 0.5, y == x ** (-n)],
                    domains={"x": Interval(-3, -2), "y": Interval(-1, 1)}, mode="hc4")
    assert not res.consistent  # x**-n in ]0, 5e-324] there: never >= 0.5
    res = propagate([y == x ** (-n)], domains={"x": Interval(-3, -2), "y": Interval(-1, 1)},
                    mode="hc4")
    assert res.consistent and float(res["y"].lo) == 0.0 and float(res["y"].hi) == 2.0**-1074


def test_revise_pown_with_huge_tape_exponents():
    """The compiled image and reverse step of a pown node (``revise``, their composition) take
    the tape's float64 exponent of any magnitude (an integer-valued float, hence even beyond
    2**53) as the integer power: ``np.int64(p)`` is undefined beyond 2**63."""
    from boundest.ctc.revise import POWN, revise

    buf = np.empty(4)
    # x in [-3, -2]: x**n >= 2**n > MAX for n >= 2**62, and 0 < x**n <= 2**n < 2**-1074 for
    # n <= -2**62 (n even)
    for p, (zl, zh) in ((1e20, (MAX, INF)), (2.0**64, (MAX, INF)), (-1e300, (0.0, 2.0**-1074)),
                        (2.0**62, (MAX, INF)), (-(2.0**63), (0.0, 2.0**-1074))):
        got = revise(POWN, -INF, INF, -3.0, -2.0, 0.0, 0.0, p, buf, None, True, None, None)
        assert got[:4] == (zl, zh, -3.0, -2.0), (p, got)
    # backward: x**1e20 in [0, 1] keeps exactly [-1, 1] (to an ulp)
    z0, z1, x0, x1 = revise(POWN, 0.0, 1.0, -3.0, 3.0, 0.0, 0.0, 1e20, buf, None, True, None,
                            None)[:4]
    assert (z0, z1) == (0.0, 1.0)
    assert -1.0 - 2**-52 <= x0 <= -1.0 and 1.0 <= x1 <= 1.0 + 2**-52


# -------------------------------------------------------------------------------------------
# 5. composition
# -------------------------------------------------------------------------------------------

C_SUM = CtcFwdBwd([x + y == 3], ["x", "y"])  # on [0, 10]^2: [[0, 3], [0, 3]]
C_DIFF = CtcFwdBwd([x - y == 1], ["x", "y"])  # on [0, 10]^2: [[1, 10], [0, 9]]
C_NONE = CtcFwdBwd([x + y == 30], ["x", "y"])  # on [0, 10]^2: empty
BOX = Interval([0, 0], [10, 10])


def same(a: Interval, b: Interval) -> bool:
    return (np.array_equal(a.lo, b.lo, equal_nan=True)
            and np.array_equal(a.hi, b.hi, equal_nan=True))


def test_sequence_applies_both():
    assert same(C_SUM(BOX), Interval([0, 0], [3, 3]))
    assert same(C_DIFF(BOX), Interval([1, 0], [10, 9]))
    seq = C_SUM & C_DIFF
    assert isinstance(seq, Sequence)
    # C_DIFF on [[0, 3], [0, 3]]: x = 1 + y = [1, 3], y = x - 1 = [0, 2]
    assert same(seq(BOX), Interval([1, 0], [3, 2]))
    assert same(seq(BOX), C_DIFF(C_SUM(BOX)))
    assert same(Sequence(C_DIFF, C_SUM)(BOX), C_SUM(C_DIFF(BOX)))
    assert np.all((C_SUM & C_NONE)(BOX).is_empty())


def test_union_is_the_hull():
    uni = C_SUM | C_DIFF
    assert isinstance(uni, Union)
    assert same(uni(BOX), Interval([0, 0], [10, 9]))  # hull of [[0,3],[0,3]] and [[1,10],[0,9]]
    # an empty result does not count
    assert same((C_NONE | C_SUM)(BOX), C_SUM(BOX))
    assert same((C_SUM | C_NONE)(BOX), C_SUM(BOX))
    assert np.all((C_NONE | C_NONE)(BOX).is_empty())
    # batch: row 0 is [0, 10]^2, row 1 is [0, 1]^2 where only C_DIFF's x - y = 1 holds
    batch = Interval([[0, 0], [0, 0]], [[10, 10], [1, 1]])
    r = (C_SUM | C_DIFF)(batch)
    assert same(r[0], Interval([0, 0], [10, 9]))
    assert same(r[1], Interval([1, 0], [1, 0]))  # x - y = 1 on [0, 1]^2: the point (1, 0)
    assert same(Union(C_SUM, C_DIFF, C_NONE)(BOX), uni(BOX))


def test_fixpoint_converges_beyond_one_pass():
    # x = sqrt(x) on [0, 10]: each pass maps hi to sqrt(hi), towards the solutions 0 and 1;
    # the relative shrink of a pass is about ln(10) / 2^(k+1), below 1e-3 after ~11 passes,
    # where hi - 1 is about 1e-3
    ctc = CtcFwdBwd([x == Op("sqrt", (x,))], ["x"])
    fix = Fixpoint(ctc, ratio=1e-3)
    r = fix(Interval([0], [10]))
    assert float(r.lo[0]) == 0.0 and 1.0 <= float(r.hi[0]) <= 1.01
    assert 5 <= fix.iterations <= 30
    # one more pass shrinks by no more than the ratio
    assert np.all(shrink_ratio(r, ctc(r)) <= 1e-3)
    # with ratio 0 the result is an exact fixed point of the contractor
    exact_fix = Fixpoint(C_SUM & C_DIFF, ratio=0.0)
    r0 = exact_fix(BOX)
    assert same((C_SUM & C_DIFF)(r0), r0)
    y_half = CtcFwdBwd([y == 0.5 * z, z == 0.5 * y], ["y", "z"])
    r1 = Fixpoint(y_half, ratio=0.0)(Interval([0, 0], [10, 10]))
    assert same(y_half(r1), r1) and np.all(r1.contains(0.0)) and float(r1.hi.max()) < 1e-300
    # max_iter caps the passes
    capped = Fixpoint(y_half, ratio=0.0, max_iter=3)
    capped(Interval([0, 0], [10, 10]))
    assert capped.iterations == 3


def test_fixpoint_with_an_unbounded_component():
    ctc = CtcFwdBwd([y == 0.5 * z, z == 0.5 * y, u >= -1], ["y", "z", "u"])
    r = Fixpoint(ctc, ratio=1e-3)(Interval([0, 0, -INF], [10, 10, INF]))
    assert float(r.hi[0]) <= 1e-3 and float(r.hi[1]) <= 1e-3


def test_propagate_converges_with_an_unbounded_component():
    res = propagate([y == 0.5 * z, z == 0.5 * y, u >= -1],
                    domains={"y": Interval(0, 10), "z": Interval(0, 10)}, mode="hc4")
    assert res.consistent and float(res["y"].lo) == 0.0 and float(res["y"].hi) < 1e-300
    assert float(res["z"].hi) < 1e-300
    assert float(res["u"].lo) == -1.0 and float(res["u"].hi) == INF


def test_propagate_revises_a_self_referencing_node_again():
    res = propagate([x == Op("sqrt", (x,))], domains={"x": Interval(0, 10)}, mode="hc4")
    assert float(res["x"].hi) <= 1.01


def test_inflate():
    inner = C_SUM(BOX)  # [[0, 3], [0, 3]]
    r = Inflate(C_SUM, 0.5)(BOX)
    assert np.all(inner.is_subset(r)) and np.all(r.is_subset(BOX))
    assert np.all(r.lo == 0.0) and np.all(r.hi >= 3.5) and np.all(r.hi <= 3.5 + 1e-12)
    r0 = Inflate(C_SUM, 0.0)(BOX)
    assert np.all(inner.is_subset(r0)) and np.all(r0.is_subset(BOX))
    assert np.all(Inflate(C_NONE, 1.0)(BOX).is_empty())
    # a huge radius gives back the input box, never more
    assert same(Inflate(C_SUM, 1e9)(BOX), BOX)


def test_function_contractor():
    half = FunctionContractor(lambda b: Interval(b.lo, b.mid()), n=2)
    assert same(half(BOX), Interval([0, 0], [5, 5]))
    # a result outside the box is intersected with it: a disjoint result empties the box
    away = FunctionContractor(lambda b: Interval(b.lo + 100, b.hi + 100))
    assert np.all(away(BOX).is_empty())
    # a superset result leaves the box as it is
    assert same(FunctionContractor(lambda b: Interval.entire(b.shape))(BOX), BOX)
    assert same((half & C_SUM)(BOX), C_SUM(Interval([0, 0], [5, 5])))


def test_empty_boxes_stay_empty():
    empty = Interval.empty((2,))
    fix = Fixpoint(C_SUM)
    for c in (C_SUM, C_SUM & C_DIFF, C_SUM | C_DIFF, fix, Inflate(C_SUM, 1.0),
              FunctionContractor(lambda b: b, n=2)):
        assert np.all(c(empty).is_empty()), c
    # one empty component empties the whole box
    part = Interval.trusted(np.array([0.0, np.nan]), np.array([10.0, np.nan]))
    for c in (C_SUM, C_SUM | C_DIFF, C_SUM & C_DIFF, Inflate(C_SUM, 1.0)):
        assert np.all(c(part).is_empty()), c
    # in a batch, only the empty box
    batch = Interval.trusted(np.array([[0.0, 0.0], [np.nan, 0.0]]),
                          np.array([[10.0, 10.0], [np.nan, 10.0]]))
    r = C_SUM(batch)
    assert same(r[0], Interval([0, 0], [3, 3])) and np.all(r[1].is_empty())


def test_dimension_mismatch_and_bad_arguments():
    c3 = CtcFwdBwd([x + y + z == 1], ["x", "y", "z"])
    with pytest.raises(ValueError, match="dimension 2"):
        C_SUM(Interval.entire((3,)))
    with pytest.raises(ValueError, match="dimension 2"):
        C_SUM(Interval(0, 1))
    with pytest.raises(ValueError, match="dimension 2"):
        C_SUM(Interval.entire((5, 3)))
    with pytest.raises(ValueError, match="cannot compose"):
        Sequence(C_SUM, c3)
    with pytest.raises(ValueError, match="cannot compose"):
        C_SUM | c3
    with pytest.raises(ValueError, match="cannot compose"):
        C_SUM & c3
    with pytest.raises(ValueError, match="dimension 2"):
        Fixpoint(C_SUM)(Interval.entire((3,)))
    with pytest.raises(ValueError, match="not in the constraints: q"):
        CtcFwdBwd([x + y == 1], ["x", "q"])
    with pytest.raises(ValueError, match="ratio"):
        Fixpoint(C_SUM, ratio=1.0)
    with pytest.raises(ValueError, match="non-negative"):
        Inflate(C_SUM, -1.0)
    with pytest.raises(ValueError, match="at least one"):
        Sequence()
    with pytest.raises(ValueError, match="at least one"):
        Union()
    with pytest.raises(ValueError, match="rel_eps"):
        propagate([x + y == 1], rel_eps=1.0)
    with pytest.raises(ValueError, match="unknown variable"):
        propagate([x + y == 1], domains={"q": Interval(0, 1)})


# -------------------------------------------------------------------------------------------
# 6. proven inconsistency
# -------------------------------------------------------------------------------------------

def test_inconsistent_sum():
    m = Model()
    m.declare("x", (0, 1))
    m.declare("y", (0, 1))
    m.add(x + y == 3)
    res = propagate(m, mode="hc4")
    assert res.consistent is False
    assert all(np.all(d.is_empty()) for d in res.domains.values())
    ctc = CtcFwdBwd(m, ["x", "y"])
    for c in (ctc, Fixpoint(ctc)):
        r = c(Interval.entire((2,)))
        assert r.shape == (2,) and np.all(r.is_empty())
    r = CtcFwdBwd([x + y == 3], ["x", "y"])(Interval([[0, 0], [0, 0]], [[1, 1], [2, 2]]))
    assert np.all(r[0].is_empty())  # x + y <= 2 < 3
    assert same(r[1], Interval([1, 1], [2, 2]))  # x = 3 - y = [1, 3] & [0, 2]


@pytest.mark.parametrize("cons", [
    [x**2 == -1],
    [Op("sqrt", (x,)) == -1],
    [Op("sin", (x,)) == 2],
    [Op("exp", (x,)) <= 0],
    [Op("log", (x,)) == y, x <= -1],
    [x == 1, x == 2],
    [x.in_((0, 1)), x.in_((2, 3))],
    [x**2 + y**2 <= -1],
    [Op("abs", (x,)) + 1 == 0.5],
])
def test_inconsistent_csps(cons):
    res = propagate(cons, mode="hc4")
    assert res.consistent is False
    names = list(compile_model(cons).slot_of)
    r = CtcFwdBwd(cons, names)(Interval.entire((len(names),)))
    assert np.all(r.is_empty())


def test_propagate_with_an_empty_domain_is_inconsistent():
    res = propagate([x + y == 1], domains={"x": Interval.empty()}, mode="hc4")
    assert res.consistent is False


# -------------------------------------------------------------------------------------------
# propagate: result object, budget, tapes; an end-to-end model in the text format
# -------------------------------------------------------------------------------------------

def test_propagation_result():
    cons = [x + y == 3, x - y == 1, x.in_((0, 10)), y.in_((0, 10))]
    res = propagate(cons, rel_eps=0.0, mode="hc4")
    # the primitive network: add(x, y) = 3 and sub(x, y) = 1, as in the hand computation of
    # test_linear_pair_by_hand: the fixed point is [1, 3] x [0, 2]
    assert res.consistent and res.n_nodes == 2
    assert same(res["x"], Interval(1, 3)) and same(res["y"], Interval(0, 2))
    assert res.evaluations >= 2 and res.iterations == res.evaluations / 2
    assert res.time_s >= 0.0 and res.slots.shape == (res.n_slots,)
    # a one-revision budget stops after one node
    one = propagate(cons, max_evaluations=1, mode="hc4")
    assert one.evaluations == 1 and one.consistent
    # a compiled tape, and domains overriding the model's
    tape = compile_model(cons)
    # x in [1, 2]: add gives y = 3 - x = [1, 2]; sub gives x - y = 1, x = 1 + y = [2, 3] & [1, 2]
    # = 2 and y = x - 1 = 1: the solution
    r2 = propagate(tape, domains={"x": Interval(1, 2)}, mode="hc4")
    assert same(r2["x"], Interval(2, 2)) and same(r2["y"], Interval(1, 1))


def test_beta_tuning_by_hand():
    # y = x + w, x in [0, 1], y in [2.5, 3], w in beta * [-1, 1]: consistent iff 1 + beta >= 2.5
    cons = [y == x + w, x.in_((0, 1)), y.in_((2.5, 3))]
    tape = compile_model(cons)

    def contract(beta):
        return propagate(tape, domains={"w": Interval(-beta, beta)}, mode="hc4")

    r = beta_tuning(contract, beta_max=16.0, tol=1e-3)
    assert 1.5 - 1e-9 <= r.beta <= 1.5 * (1 + 1e-3) + 1e-9
    assert r.propagation.consistent
    for beta, ok in r.trials:
        assert ok == (beta >= 1.5 - 1e-9) or abs(beta - 1.5) < 1e-9
    with pytest.raises(ValueError, match="raise beta_max"):
        beta_tuning(contract, beta_max=1.0)


def satellite_text(k_max: int) -> tuple[str, dict[str, mpmath.mpf]]:
    """The paper's satellite CSP in the text format, with measurements simulated exactly
    (w = 0) from x(0) = (4, 0.5, -0.2, 0.5); returns the text and the true values."""
    with mpmath.workprec(256):
        xs = [[mpmath.mpf(4), mpmath.mpf("0.5"), mpmath.mpf("-0.2"), mpmath.mpf("0.5")]]
        for _ in range(k_max):
            x1, x2, x3, x4 = xs[-1]
            r3 = mpmath.sqrt(x1**2 + x2**2) ** 3
            xs.append([x1 + 0.5 * x3, x2 + 0.5 * x4, x3 - 0.5 * x1 / r3, x4 - 0.5 * x2 / r3])
        truth, cons = {}, []
        decl = ["x1_0 in [0,+oo[", "x2_0 in [0,+oo[", "x3_0 in ]-oo,0]", "x4_0 in [0,+oo["]
        for k, (x1, x2, x3, x4) in enumerate(xs):
            for i, v in enumerate((x1, x2, x3, x4), 1):
                truth[f"x{i}_{k}"] = v
                if k > 0:
                    decl.append(f"x{i}_{k} in ]-oo,+oo[")
            if k == k_max:
                break
            for i in range(1, 5):
                truth[f"w{i}_{k}"] = mpmath.mpf(0)
                decl.append(f"w{i}_{k} in [-0.01, 0.01]")
            for i, v in enumerate((x2 / x1, x1 * x3 + x2 * x4, x1**2 + x2**2), 1):
                truth[f"y{i}_{k}"] = v
                yh = round(float(v), 6)
                decl.append(f"y{i}_{k} in [{yh - 0.1:.6f}, {yh + 0.1:.6f}]")
            cons += [f"x1_{k + 1}=x1_{k}+0.5*x3_{k}+w1_{k}",
                     f"x2_{k + 1}=x2_{k}+0.5*x4_{k}+w2_{k}",
                     f"x3_{k + 1}=x3_{k}-0.5*x1_{k}/(sqrt(x1_{k}^2+x2_{k}^2))^3+w3_{k}",
                     f"x4_{k + 1}=x4_{k}-0.5*x2_{k}/(sqrt(x1_{k}^2+x2_{k}^2))^3+w4_{k}",
                     f"y1_{k}=x2_{k}/x1_{k}",
                     f"y2_{k}=x1_{k}*x3_{k}+x2_{k}*x4_{k}",
                     f"y3_{k}=x1_{k}^2+x2_{k}^2"]
    text = ("Bisection none;\n" + ",\n".join(decl) + ";\nConstraints\n" + ",\n".join(cons)
            + ";\n")
    return text, truth


def test_satellite_model_end_to_end():
    k_max = 12
    text, truth = satellite_text(k_max)
    model = parse_model(text, "satellite.txt")
    assert len(model.constraints) == 7 * k_max
    res = propagate(model, mode="hc4")
    assert res.consistent
    for name, v in truth.items():
        assert mp_in(v, float(res[name].lo), float(res[name].hi)), (name, res[name])
    # y3_0 = 16.25 measured to +-0.1 and x2_0 >= 0: x1_0 <= sqrt(16.35) < 4.05
    assert 4.0 <= float(res["x1_0"].hi) < 4.05
    # the same model through the batched contractor, to a fixed point, keeps the truth too
    names = list(model.domains)
    ctc = CtcFwdBwd(model, names)
    r = Fixpoint(ctc, ratio=1e-3, max_iter=200)(Interval.entire((len(names),)))
    for i, n in enumerate(names):
        assert mp_in(truth[n], float(r.lo[i]), float(r.hi[i])), (n, r[i])
    assert float(r.hi[names.index("x1_0")]) < 4.05


# -------------------------------------------------------------------------------------------
# interval constants: every occurrence is its own value (never merged into one variable)
# -------------------------------------------------------------------------------------------

def contains(iv: Interval, q: Fraction) -> bool:
    """Whether the non-empty scalar interval ``iv`` contains the exact rational ``q``."""
    lo, hi = float(iv.lo), float(iv.hi)
    return lo == lo and (lo == -INF or Fraction(lo) <= q) and (hi == INF or q <= Fraction(hi))


def survives(model: Model, point: dict[str, Fraction]) -> None:
    """``point`` (a solution of ``model``) is kept by ``CtcFwdBwd`` and by ``propagate``."""
    names = list(point)
    box = Interval([float(model.domains[n].lo) if n in model.domains else -INF for n in names],
                   [float(model.domains[n].hi) if n in model.domains else INF for n in names])
    r = CtcFwdBwd(model, names)(box)
    for j, n in enumerate(names):
        assert contains(r[j], point[n]), (n, point[n], r[j])
    res = propagate(model, rel_eps=0.0, mode="hc4")
    assert res.consistent
    for n in names:
        assert contains(res[n], point[n]), (n, point[n], res[n])


def unit_box_model(*cons) -> Model:
    m = Model()
    m.declare("x", (0, 1))
    m.declare("y", (0, 1))
    return m.add(*cons)


def test_two_equal_interval_constants_are_two_values():
    # x == [0, 1], y == [0, 1], x - y == 1: (x, y) = (1, 0) is a solution
    m = unit_box_model(x == Interval(0, 1), y == Interval(0, 1), x - y == 1)
    survives(m, {"x": Fraction(1), "y": Fraction(0)})
    # one Const object used twice is two occurrences as well
    c = Const(Interval(0, 1))
    survives(unit_box_model(x == c, y == c, x - y == 1), {"x": Fraction(1), "y": Fraction(0)})


def test_one_interval_constant_in_two_products():
    # x*c == 1/4, y*c == 3/4, x == y with c in [0, 1]: x = y = 1 (c = 1/4, then c = 3/4)
    for c in (Interval(0, 1), Const(Interval(0, 1))):
        survives(unit_box_model(x * c == 0.25, y * c == 0.75, x == y),
                 {"x": Fraction(1), "y": Fraction(1)})


def test_equal_trees_over_an_interval_constant_stay_apart():
    # x == c + 1, y == c + 1, x - y == 1: x = 2 (c = 1), y = 1 (c = 0)
    c = Const(Interval(0, 1))
    e = c + 1
    for cons in ([x == c + 1, y == c + 1], [x == e, y == e]):
        m = Model()
        m.declare("x", (0, 3))
        m.declare("y", (0, 3))
        survives(m.add(*cons, x - y == 1), {"x": Fraction(2), "y": Fraction(1)})


def test_decimals_in_one_float_gap_are_two_numbers():
    # the text format's interval constants are decimals between two floats: 0.1 + 1e-20 and
    # 0.1 + 2e-20 have the same enclosure but are two numbers (tape level: test_expr)
    a, b = "0.10000000000000000001", "0.10000000000000000002"
    text = (f"x in [0, 1], y in [0, 1];\nConstraints\n x = {a}, y = {b},\n"
            " x - y = -0.00000000000000000001;")
    survives(parse_model(text), {"x": Fraction(a), "y": Fraction(b)})
    # 1e400 and 3e400 are both [MAX, +oo]: one shared slot C would make x*C = 1 and y*C = 3
    # with x == y one node equal to both 1 and 3 (inconsistent); x = y = 1e-400 is a solution
    text = "x in [0, 1], y in [0, 1];\nConstraints\n x = y, x*1e400 = 1, y*3e400 = 3;"
    survives(parse_model(text), {"x": Fraction(1, 10**400), "y": Fraction(1, 10**400)})


# a random model: base variables at exact dyadic values, interval constants each used several
# times (a fresh value of the interval per occurrence), expression trees reused by identity,
# definitions w_k == tree, and relations on the trees' exact values

DYADIC = st.integers(-16, 16).map(lambda k: Fraction(k, 4))


@st.composite
def const_models(draw):
    n_vars = draw(st.integers(1, 3))
    values = {f"v{i}": draw(DYADIC) for i in range(n_vars)}
    consts = []
    for _ in range(draw(st.integers(1, 2))):
        lo = draw(st.integers(-8, 7))
        hi = draw(st.integers(lo + 1, 8))
        consts.append((Fraction(lo, 4), Fraction(hi, 4)))
    const_objs = [Const(Interval(float(lo), float(hi))) for lo, hi in consts]

    def tree(depth):
        kind = draw(st.integers(0, 3 if depth > 0 else 2))
        if kind == 0:
            return ("var", draw(st.sampled_from(sorted(values))))
        if kind == 1:
            return ("const", draw(st.integers(0, len(consts) - 1)))
        if kind == 2:
            return ("num", draw(DYADIC))
        op = draw(st.sampled_from(["add", "sub", "mul", "sqr", "neg"]))
        args = (tree(depth - 1),) if op in ("sqr", "neg") else (tree(depth - 1), tree(depth - 1))
        return (op, *args)

    def build(t):
        """The expression (interval constants as Intervals or as the shared Const objects)."""
        if t[0] == "var":
            return Var(t[1])
        if t[0] == "const":
            j = t[1]
            return const_objs[j] if draw(st.booleans()) else Interval(float(consts[j][0]),
                                                                      float(consts[j][1]))
        if t[0] == "num":
            return Const(float(t[1]))
        a = [build(s) for s in t[1:]]
        if t[0] == "sqr":
            return a[0] ** 2 if isinstance(a[0], Var | Op | Const) else Const(a[0]) ** 2
        if t[0] == "neg":
            return -(a[0] if not isinstance(a[0], Interval) else Const(a[0]))
        l, r = (e if not isinstance(e, Interval) else Const(e) for e in a)
        return {"add": l + r, "sub": l - r, "mul": l * r}[t[0]]

    def value(t, occ):
        """Exact value with a fresh value of each constant occurrence (drawn into ``occ``)."""
        if t[0] == "var":
            return values[t[1]]
        if t[0] == "const":
            lo, hi = consts[t[1]]
            v = lo + (hi - lo) * draw(st.sampled_from([Fraction(0), Fraction(1, 4),
                                                       Fraction(1, 2), Fraction(1)]))
            occ.append(v)
            return v
        if t[0] == "num":
            return t[1]
        a = [value(s, occ) for s in t[1:]]
        return {"add": lambda: a[0] + a[1], "sub": lambda: a[0] - a[1],
                "mul": lambda: a[0] * a[1], "sqr": lambda: a[0] ** 2,
                "neg": lambda: -a[0]}[t[0]]()

    m = Model()
    for n, v in values.items():
        r = draw(st.sampled_from([0, 1, 4]))
        m.declare(n, (float(v - r), float(v + r)))
    point = dict(values)
    trees = [tree(2) for _ in range(draw(st.integers(1, 3)))]
    built = [build(t) for t in trees]
    defs = []
    for k in range(draw(st.integers(2, 5))):
        i = draw(st.integers(0, len(trees) - 1))
        # the same tree object (memoised by identity) or a rebuilt one
        e = built[i] if draw(st.booleans()) else build(trees[i])
        e = e if not isinstance(e, Interval) else Const(e)
        occ: list[Fraction] = []
        val = value(trees[i], occ)
        how = draw(st.sampled_from(["define", "equal", "le", "in"]))
        if how == "define":
            w_ = Var(f"w{k}")
            m.add(w_ == e)
            point[w_.name] = val
            defs.append(w_)
        elif how == "equal":  # exact dyadic value: a float
            m.add(e == float(val))
        elif how == "le":
            m.add(e <= float(val) + draw(st.sampled_from([0, 1])))
        else:
            m.add(e.in_((float(val), float(val) + 1)))
    if len(defs) >= 2:  # relate two definitions through their exact difference
        a_, b_ = defs[0], defs[1]
        m.add(a_ - b_ == float(point[a_.name] - point[b_.name]))
    return m, point


@settings(max_examples=150, suppress_health_check=[HealthCheck.too_slow])
@given(const_models())
def test_solutions_with_interval_constants_survive(mp):
    model, point = mp
    note("\n".join(str(c) for c in model.constraints))
    note(str(point))
    survives(model, point)


# -------------------------------------------------------------------------------------------
# powers: pow(x, n), x^n, bd.pow(x, n), x**n are the integer power for an integer constant n
# -------------------------------------------------------------------------------------------

def test_pow_2_in_a_model_file_keeps_negative_solutions():
    import boundest as bd

    for text in ("pow(x, 2) = 4", "x^2 = 4", "pow(x, 2.0) = 4", "x^2.0 = 4"):
        res = propagate(parse_model(f"x in [-3, 10]; Constraints {text};"), rel_eps=0.0,
                        mode="hc4")
        assert res.consistent and float(res["x"].lo) == -2.0 and float(res["x"].hi) == 2.0
    for e in (bd.pow(x, 2), x**2, x**2.0, bd.pow(x, 2.0)):
        m = Model()
        m.declare("x", (-3, 10))
        res = propagate(m.add(e == 4), rel_eps=0.0, mode="hc4")
        assert float(res["x"].lo) == -2.0 and float(res["x"].hi) == 2.0
    # a non-integer exponent is the real power: x >= 0
    res = propagate(parse_model("x in [-3, 10]; Constraints pow(x, 0.5) = 2;"), rel_eps=0.0,
                    mode="hc4")
    assert contains(res["x"], Fraction(4)) and float(res["x"].lo) >= 0.0


@settings(max_examples=150)
@given(st.integers(-6, 6), st.integers(-24, 24).map(lambda k: Fraction(k, 8)),
       st.sampled_from(["pow(x, {n})", "x^{n}", "x^({n})", "pow(x, {n}.0)", "x^{n}.0",
                        "py_pow", "py_starstar", "py_float"]))
def test_integer_powers_keep_sampled_solutions(n, xv, spelling):
    import boundest as bd

    assume(not (n < 0 and xv == 0))
    zv = xv ** n  # exact
    lo, hi = float(zv), float(zv)
    if Fraction(lo) > zv:
        lo = float(np.nextafter(lo, -INF))
    if Fraction(hi) < zv:
        hi = float(np.nextafter(hi, INF))
    if spelling.startswith("py"):
        e = {"py_pow": bd.pow(x, n), "py_starstar": x**n, "py_float": x ** float(n)}[spelling]
        m = Model()
        m.declare("x", (-3, 3))
        m.add(e.in_((lo, hi)))
    else:
        lit = spelling.format(n=n)  # x^-3, x^(-3), pow(x, -3.0), ...
        m = parse_model(f"x in [-3, 3]; Constraints {lit} in [{lo!r}, {hi!r}];")
    survives(m, {"x": xv})
