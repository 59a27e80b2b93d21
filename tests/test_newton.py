"""Soundness of the centered-form contractors and interval Newton (boundest.ctc.centered,
boundest.paving.roots).

- ``CtcCentered`` (with and without preconditioning), ``CtcNewton`` and their compositions
  never remove a solution: random polynomial / trig constraints with a known solution ``x*``
  (targets ``f(x*)`` rounded outward, widened, or one-sided), boxes holding ``x*``.
- ``CtcNewton.prove`` never claims existence and uniqueness falsely: square systems built in
  triangular / product form (then mixed by integer unimodular changes of variables and of
  equations), whose roots are known exactly (dyadic) or to 77 digits (mpmath) and checked by
  ``mpmath.findroot``: a proved box holds exactly one root, a simple one, and keeps it; double
  roots, pairs of roots closer than the box, and systems without a real root are never proved.
- ``solve_square``: every root lies in a returned box, each proved box holds exactly one root,
  distinct proved boxes distinct roots, and ``mpmath.findroot`` from a proved box's midpoint
  (50 digits) converges inside it; with an inequality or a domain cutting a root off, that
  root is never proved.

Regression cases kept: a root on a bisection face reported twice, a proof kept through a
contraction by the other constraints, and false proofs from swapped atan2 derivatives.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from itertools import product

import mpmath
import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import boundest as bd
from boundest import Interval
from boundest.ctc import CtcFwdBwd, Fixpoint
from boundest.ctc.centered import CtcCentered, CtcNewton
from boundest.expr import Model, Var
from boundest.expr.function_tape import function_tape
from boundest.expr.nodes import Expr, variables
from boundest.paving.roots import solve_square

from .strategies import CSP_VARS, _outward, expression_trees, tree_expr, tree_value
from .test_derivatives import TooBigError, UndefinedError
from .test_derivatives import tree_eval as wild_eval
from .test_derivatives import tree_expr as wild_expr
from .test_derivatives import trees as wild_trees

INF = math.inf
mpf = mpmath.mpf


def mp_in_box(r, lo, hi) -> bool:
    """Whether the exact point ``r`` (mpmath) lies in the float box ``[lo, hi]``."""
    return all((a == -INF or mpf(a) <= v) and (b == INF or v <= mpf(b))
               for v, a, b in zip(r, lo, hi, strict=True))


def _float_in_box(x, box: Interval) -> bool:
    return bool(np.all((box.lo <= np.asarray(x)) & (np.asarray(x) <= box.hi)))


# -------------------------------------------------------------------------------------------
# random constraints with a known solution x*
# -------------------------------------------------------------------------------------------


@st.composite
def offsets(draw) -> tuple[float, float]:
    """Distances from ``x*`` to the box's faces: 0 (``x*`` on the face) to infinite."""
    def one():
        w = draw(st.sampled_from([0.0, 1e-10, 1e-6, 1e-3, 0.05, 0.5, 2.0, INF]))
        return w * draw(st.sampled_from([1.0, 0.5])) if math.isfinite(w) else w
    return one(), one()


@st.composite
def boxes_around(draw, x: tuple[float, ...], k: int) -> Interval:
    """``k`` boxes holding the point ``x`` (float bounds: ``x - a`` rounds to at most ``x``)."""
    lo, hi = np.empty((k, len(x))), np.empty((k, len(x)))
    for i in range(k):
        for j, v in enumerate(x):
            a, b = draw(offsets())
            lo[i, j], hi[i, j] = v - a, v + b
    return Interval(lo, hi)


def _wild_value(t, p):
    """A wild tree's value at ``p`` (mpmath), or None where undefined or beyond 1e150.

    At 2600 bits, so that a domain's edge is decided exactly for float inputs: at 256 bits
    ``exp(4.3e-90)`` rounds to 1 and ``asin`` of it looked defined, although the exact value
    lies above 1 (hypothesis found that point, and every contractor rightly emptied it)."""
    try:
        with mpmath.workprec(2600):
            return wild_eval(t, p)[0]
    except (UndefinedError, TooBigError):
        return None


@st.composite
def solved_systems(draw, square: bool = False, wild: bool = False):
    """Constraints ``f_k(x) in T_k`` over ``x0..x{n-1}``, a point ``x*`` and targets holding
    ``f_k(x*)`` (computed in mpmath, rounded outward): tight, widened, ``<=`` or ``>=``. The
    trees are random polynomial / trig ones (+, -, *, sqr, sin, cos, a / (1 + a^2)), or with
    ``wild`` of depth <= 3 over every primitive (tests/test_derivatives.py; ``x*`` then also
    at special points, and inside every primitive's domain). Square systems are
    ``x_k + f_k(x) in T_k`` (every variable present). Returns the constraints, the tape-style
    targets, the variables and ``x*`` (in the variables' order)."""
    n = 3 if wild else draw(st.integers(2, 3))
    m = n if square else draw(st.integers(1, n + 1))
    if wild:
        trees = draw(st.lists(wild_trees(3), min_size=m, max_size=m))
        xs = tuple(draw(st.one_of(st.floats(-3, 3), st.sampled_from([0.0, 0.5, 1.0, -1.0])))
                   for _ in range(n))
        exprs = [wild_expr(t) for t in trees]
        values = [_wild_value(t, xs) for t in trees]
        assume(all(v is not None for v in values))
    else:
        trees = draw(st.lists(expression_trees(n, 6), min_size=m, max_size=m))
        xs = tuple(draw(st.floats(-2, 2)) for _ in range(n))
        exprs = [tree_expr(t) for t in trees]
        values = [tree_value(t, xs) for t in trees]
    if square:
        exprs = [CSP_VARS[k] + e for k, e in enumerate(exprs)]
        values = [None if v is None else v + mpf(xs[k]) for k, v in enumerate(values)]
    # a constant tree (a number, an interval, a constant expression) constrains nothing
    keep = [isinstance(e, Expr) and bool(variables([e])) for e in exprs]
    names = [v.name for v in variables([e for e, k in zip(exprs, keep, strict=True) if k])]
    assume(names and (len(names) == n or not square) and (all(keep) or not square))
    constraints, targets = [], []
    for e, v, k in zip(exprs, values, keep, strict=True):
        if not k:
            continue
        lo, hi = _outward(v, False), _outward(v, True)
        kind = draw(st.sampled_from(["tight", "wide", "le", "ge"] if not square
                                    else ["tight", "wide"]))
        if kind == "wide":
            lo -= draw(st.sampled_from([1e-9, 1e-3, 0.5]))
            hi += draw(st.sampled_from([0.0, 1e-3, 0.5]))
        if kind == "le":
            constraints.append(e <= hi)
            targets.append((-INF, hi))
        elif kind == "ge":
            constraints.append(e >= lo)
            targets.append((lo, INF))
        else:
            constraints.append(e.in_((lo, hi)))
            targets.append((lo, hi))
    point = {f"x{i}": xs[i] for i in range(n)}
    return constraints, targets, names, tuple(point[v] for v in names)


@st.composite
def centered_cases(draw, square: bool = False, wild: bool = False):
    constraints, targets, names, xs = draw(solved_systems(square, wild))
    boxes = draw(boxes_around(xs, draw(st.integers(1, 4))))
    return constraints, targets, names, xs, boxes


def _check_keeps(ctc, boxes: Interval, xs, what) -> None:
    out = ctc(boxes)
    assert out.shape == boxes.shape
    for i in range(len(boxes)):
        assert _float_in_box(xs, out[i]), (what, boxes[i], out[i], xs)
        assert bool(out[i].is_subset(boxes[i]).all()), (what, boxes[i], out[i])


def check_centered_keeps_solution(constraints, targets, names, xs, boxes) -> None:
    """CtcCentered from the model and from a tape with explicit targets, preconditioned or
    not, alone, composed with HC4 and in a fixpoint, each box alone and all as a batch."""
    model = Model().add(*constraints)
    exprs = [c.lhs for c in constraints]
    tape = function_tape(exprs, names, targets)
    for pre, h in ((True, False), (False, False), (True, True)):
        from_model = CtcCentered(model, precondition=pre, hc4=h)
        assert from_model.tape.names == names
        ctcs = [from_model, CtcCentered(tape, precondition=pre, hc4=h)]
        hc4 = CtcFwdBwd(model, names)
        ctcs += [ctcs[0] & hc4, hc4 & ctcs[1], Fixpoint(ctcs[0] & hc4, ratio=0.01, max_iter=30)]
        for ctc in ctcs:
            _check_keeps(ctc, boxes, xs, (pre, type(ctc).__name__))
            _check_keeps(ctc, boxes[:1], xs, (pre, type(ctc).__name__))
        # other data per box: the targets widened by a different amount for each box
        k = len(boxes)
        tg = Interval([t[0] for t in targets], [t[1] for t in targets])
        grow = np.linspace(0.0, 1.0, k)[:, None]
        per_box = Interval(tg.lo - grow, tg.hi + grow)
        out = CtcCentered(tape, precondition=pre, hc4=h).contract(boxes, targets=per_box)
        for i in range(k):
            assert _float_in_box(xs, out[i]), ("per-box targets", boxes[i], out[i], xs)


@settings(max_examples=5, deadline=None)
@given(centered_cases())
def test_ctc_centered_keeps_the_solution(case):
    """CtcCentered (both modes, composed with HC4, in a Fixpoint) keeps the known solution
    ``x*`` of equalities, ``in``, ``<=`` and ``>=`` constraints in every box holding it."""
    check_centered_keeps_solution(*case)


def check_newton_keeps_solution(constraints, names, xs, boxes) -> None:
    """CtcNewton alone, composed with HC4, in a Fixpoint and iterated by ``prove``."""
    model = Model().add(*constraints)
    newton = CtcNewton(model)
    assert newton.tape.names == names
    hc4 = CtcFwdBwd(model, names)
    for ctc in (newton, newton & hc4, Fixpoint(newton & hc4, ratio=0.01, max_iter=30)):
        _check_keeps(ctc, boxes, xs, type(ctc).__name__)
    x = boxes
    for _ in range(4):
        x, proved = newton.prove(x)
        assert not proved.any()  # non-degenerate targets are never proved
        for i in range(len(boxes)):
            assert _float_in_box(xs, x[i]), (boxes[i], x[i], xs)


@settings(max_examples=40, deadline=None)
@given(centered_cases(square=True))
def test_ctc_newton_keeps_the_solution(case):
    """CtcNewton (alone, iterated, composed with HC4, in a Fixpoint) keeps the known solution
    of square systems with interval targets in every box holding it."""
    constraints, _, names, xs, boxes = case
    check_newton_keeps_solution(constraints, names, xs, boxes)


@pytest.mark.slow  # about 1 s per system; the _long test below draws hundreds more
@settings(max_examples=25, deadline=None)
@given(centered_cases(wild=True), centered_cases(square=True, wild=True))
def test_contractors_keep_the_solution_of_wild_constraints(case, square_case):
    """Constraints over every primitive (sqrt, log, asin, pow, atan2, floor, min, ...): the
    centered contractors keep the known solution, whatever the domains and jumps."""
    check_centered_keeps_solution(*case)
    constraints, _, names, xs, boxes = square_case
    check_newton_keeps_solution(constraints, names, xs, boxes)


@pytest.mark.slow
@settings(max_examples=600, deadline=None)
@given(st.one_of(centered_cases(), centered_cases(wild=True)),
       st.one_of(centered_cases(square=True), centered_cases(square=True, wild=True)))
def test_centered_contractors_keep_the_solution_long(case, square_case):
    """Many more random systems (polynomial / trig and wild): CtcCentered and CtcNewton keep
    the known solution."""
    check_centered_keeps_solution(*case)
    constraints, _, names, xs, boxes = square_case
    check_newton_keeps_solution(constraints, names, xs, boxes)


def test_centered_contractors_on_empty_and_unbounded_boxes():
    """An empty box stays empty, an unbounded one holding the solution keeps it; batched."""
    x, y = Var("x"), Var("y")
    model = Model().add(x * y == 2.0, x + y == 3.0)  # (1, 2) and (2, 1)
    boxes = Interval.trusted(np.array([[np.nan, 0.0], [-INF, -INF], [0.0, 1.5], [1.5, 0.0]]),
                          np.array([[np.nan, 1.0], [INF, INF], [INF, INF], [INF, 1.5]]))
    for ctc in (CtcCentered(model), CtcCentered(model, precondition=False),
                CtcCentered(model, hc4=True), CtcNewton(model)):
        out = ctc(boxes)
        assert out[0].is_empty().all()
        assert _float_in_box((1.0, 2.0), out[1]) and _float_in_box((2.0, 1.0), out[1])
        assert _float_in_box((1.0, 2.0), out[2]) and _float_in_box((2.0, 1.0), out[3])


# -------------------------------------------------------------------------------------------
# square systems with exactly known roots
# -------------------------------------------------------------------------------------------

DYADIC = [k / 8 for k in range(-12, 13)]


@dataclass
class KnownSystem:
    """``G(u) = N F(M u) = 0`` with ``F`` triangular in product form: its roots ``u``,
    whether each is simple (nonsingular Jacobian), and a description."""

    n: int
    equations: Callable  # (u, m) -> list of n values; m is boundest or mpmath
    roots: list[tuple]
    simple: list[bool]
    what: str

    def model(self) -> Model:
        u = [Var(f"u{i}") for i in range(self.n)]
        m = Model()
        for i in range(self.n):
            m.declare(u[i], (-INF, INF))
        return m.add(*[g == 0 for g in self.equations(u, bd)])

    def value(self, r) -> list:
        return self.equations([mpf(v) for v in r], mpmath)


def _g2(kind: str, c: float):
    return {"lin": lambda x, m: c * x, "sqr": lambda x, m: c * x ** 2,
            "sin": lambda x, m: m.sin(x), "zero": lambda x, m: 0.0}[kind]


def _g3(kind: str):
    return {"mul": lambda x, y, m: x * y, "cos": lambda x, y, m: m.cos(y) - x,
            "zero": lambda x, y, m: 0.0}[kind]


UNIMODULAR = {
    2: [((1, 0), (0, 1)), ((1, 1), (0, 1)), ((1, 0), (-1, 1)), ((2, 1), (1, 1))],
    3: [((1, 0, 0), (0, 1, 0), (0, 0, 1)), ((1, 1, 0), (0, 1, 0), (0, 1, 1)),
        ((1, 0, 0), (1, 1, 0), (0, -1, 1))],
}


def make_system(n, a, b, c, g2, c2, g3, mix, emix, offset=0.0) -> KnownSystem:
    """The triangular system ``prod_i (x1 - a_i) [+ offset] = 0``, ``prod_j (x2 - g2(x1) -
    b_j) = 0``, ``prod_k (x3 - g3(x1, x2) - c_k) = 0`` in ``x = M u``, equations mixed by
    ``N``. Roots: every ``(a_i, g2(a_i) + b_j, g3(..) + c_k)``, simple when the three values
    are simple in their lists; none when ``offset > 0`` (then ``a`` has one value, squared)."""
    M, N = UNIMODULAR[n][mix], UNIMODULAR[n][emix]
    f2, f3 = _g2(g2, c2), _g3(g3)

    def F(x, m):
        p1 = (x[0] - a[0]) ** 2 + offset if offset else math.prod([x[0] - ai for ai in a])
        eqs = [p1, math.prod([x[1] - f2(x[0], m) - bj for bj in b])]
        if n == 3:
            eqs.append(math.prod([x[2] - f3(x[0], x[1], m) - ck for ck in c]))
        return eqs

    def G(u, m):
        x = [sum(M[i][j] * u[j] for j in range(n) if M[i][j]) for i in range(n)]
        f = F(x, m)
        return [sum(N[i][j] * f[j] for j in range(n) if N[i][j]) for i in range(n)]

    roots, simple = [], []
    if not offset:
        # the inverse of a unimodular integer matrix is an integer matrix: exact
        minv = mpmath.inverse(mpmath.matrix(M)).apply(mpmath.nint)
        for ai, bj, ck in product(sorted(set(a)), sorted(set(b)),
                                  sorted(set(c)) if n == 3 else [0.0]):
            x1 = mpf(ai)
            x2 = f2(x1, mpmath) + bj
            xs = [x1, x2, f3(x1, x2, mpmath) + ck][:n]
            roots.append(tuple(minv * mpmath.matrix(xs)))
            simple.append(a.count(ai) == 1 and b.count(bj) == 1
                          and (n == 2 or c.count(ck) == 1))
    what = (f"n={n} a={a} b={b} c={c} g2={g2}({c2}) g3={g3} M={M} N={N} offset={offset}")
    return KnownSystem(n, G, roots, simple, what)


@st.composite
def known_systems(draw, kinds=("simple", "simple", "double", "near", "none")) -> KnownSystem:
    """Square systems of 2 or 3 equations with known roots: ``simple`` (1 to 3 distinct
    values per layer, so up to 12 simple roots), ``double`` (a repeated first-layer value:
    every root double), ``near`` (two first-layer values ``2^-k`` apart, k up to 40),
    ``none`` (``(x1 - a)^2 + 2^-k = 0``: no real root)."""
    n = draw(st.sampled_from([2, 3]))
    kind = draw(st.sampled_from(kinds))
    vals = st.lists(st.sampled_from(DYADIC), min_size=1, max_size=2, unique=True)
    a = draw(st.lists(st.sampled_from(DYADIC), min_size=1, max_size=3, unique=True))
    offset = 0.0
    if kind == "double":
        a = [a[0], a[0]]
    elif kind == "near":
        a = [a[0], a[0] + 2.0 ** -draw(st.integers(6, 40))]
    elif kind == "none":
        a, offset = [a[0]], 2.0 ** -draw(st.integers(0, 40))
    b, c = draw(vals), draw(vals)
    g2 = draw(st.sampled_from(["lin", "sqr", "sin", "zero"]))
    c2 = draw(st.sampled_from([1.0, -0.5, 0.25]))
    g3 = draw(st.sampled_from(["mul", "cos", "zero"]))
    mix = draw(st.integers(0, len(UNIMODULAR[n]) - 1))
    emix = draw(st.integers(0, len(UNIMODULAR[n]) - 1))
    return make_system(n, a, b, c, g2, c2, g3, mix, emix, offset)


def test_known_roots_are_roots():
    """The construction: every listed root zeroes the system (exactly for dyadic data, to 70
    digits with sin/cos), and ``mpmath.findroot`` started near a simple root comes back to it;
    a system with a squared factor plus an offset has no root listed."""
    cases = [make_system(2, [0.5, -1.0], [0.25], [], "sqr", 1.0, "zero", 3, 1),
             make_system(3, [0.125, 1.0], [0.5, -0.5], [1.5], "sin", 1.0, "cos", 1, 2),
             make_system(3, [0.25, 0.25], [0.0], [0.0], "lin", -0.5, "mul", 2, 0),
             make_system(2, [1.0], [0.0], [], "lin", 1.0, "zero", 0, 0, offset=2.0 ** -30)]
    assert [len(s.roots) for s in cases] == [2, 4, 1, 0]
    assert [sum(s.simple) for s in cases] == [2, 4, 0, 0]
    for sys in cases:
        for r, simple in zip(sys.roots, sys.simple, strict=True):
            assert all(abs(v) < mpf(10) ** -70 for v in sys.value(r)), (sys.what, r)
            if simple:
                with mpmath.workdps(50):
                    start = [v + mpf(10) ** -6 for v in r]
                    z = mpmath.findroot(lambda *u, s=sys: s.value(u), start)
                    assert all(abs(z[i] - r[i]) < mpf(10) ** -40 for i in range(sys.n))


@st.composite
def prove_cases(draw, kinds=("simple", "simple", "double", "near", "none")):
    """A known system and boxes: around a root (widths 1e-12 to 3, the root anywhere inside
    or on a face), around the middle of two roots, or anywhere in ``[-3, 3]^n``."""
    sys = draw(known_systems(kinds))
    k = draw(st.integers(1, 6))
    lo, hi = np.empty((k, sys.n)), np.empty((k, sys.n))
    for i in range(k):
        where = draw(st.integers(0, 3))
        if sys.roots and where <= 1:
            centre = [float(v) for v in draw(st.sampled_from(sys.roots))]
        elif len(sys.roots) >= 2 and where == 2:
            r1, r2 = draw(st.sampled_from(sys.roots)), draw(st.sampled_from(sys.roots))
            centre = [float((u + v) / 2) for u, v in zip(r1, r2, strict=True)]
        else:
            centre = [draw(st.floats(-3, 3)) for _ in range(sys.n)]
        w = draw(st.sampled_from([1e-12, 1e-8, 1e-5, 1e-3, 0.1, 1.0, 3.0]))
        for j in range(sys.n):
            lo[i, j] = centre[j] - w * draw(st.sampled_from([0.0, 0.3, 1.0]))
            hi[i, j] = centre[j] + w * draw(st.sampled_from([0.0, 0.6, 1.0]))
            hi[i, j] = max(hi[i, j], lo[i, j])
    return sys, Interval(lo, hi)


def check_prove(sys: KnownSystem, boxes: Interval, rounds: int = 5) -> int:
    """Iterate ``CtcNewton.prove``: no root is ever removed; a proved box holds exactly one
    root, a simple one, and the contracted box keeps it. Returns the number of proofs."""
    newton = CtcNewton(sys.model())
    x = boxes
    proofs = 0
    for _ in range(rounds):
        out, proved = newton.prove(x)
        assert out.shape == x.shape and proved.shape == (len(x),)
        for i in range(len(x)):
            lo, hi = x.lo[i], x.hi[i]
            if np.isnan(lo).any():
                assert not proved[i]
                continue
            inside = [q for q, r in enumerate(sys.roots) if mp_in_box(r, lo, hi)]
            for q in inside:
                assert mp_in_box(sys.roots[q], out.lo[i], out.hi[i]), (
                    "root removed", sys.what, x[i], out[i], sys.roots[q])
            if proved[i]:
                proofs += 1
                assert len(inside) == 1, ("false proof", sys.what, x[i], len(inside))
                assert sys.simple[inside[0]], ("proof of a multiple root", sys.what, x[i])
        x = out
    return proofs


@settings(max_examples=60, deadline=None)
@given(prove_cases())
def test_newton_never_proves_falsely(case):
    """CtcNewton.prove on random boxes of systems with known roots: proofs only of boxes
    holding exactly one simple root; no root removed."""
    check_prove(*case)


@pytest.mark.slow
@settings(max_examples=1500, deadline=None)
@given(prove_cases())
def test_newton_never_proves_falsely_long(case):
    """CtcNewton.prove, many more systems and boxes."""
    check_prove(*case)


@pytest.mark.parametrize("sys", [
    make_system(2, [0.5, -1.0], [0.25], [], "sqr", 1.0, "zero", 3, 1),
    make_system(2, [0.0, 1.0], [0.5, 0.0], [], "sin", 1.0, "zero", 1, 2),
    make_system(3, [0.125, 1.0], [0.5, -0.5], [1.5], "sin", 1.0, "cos", 1, 2),
    make_system(3, [-1.5, 0.75], [1.0], [0.0, 0.5], "lin", -0.5, "mul", 2, 1),
], ids=lambda s: s.what)
def test_newton_proves_simple_roots(sys):
    """Not vacuous: a box of radius 1e-6 around each simple root is proved within five
    Newton steps (so the soundness tests above do meet proofs)."""
    for r in sys.roots:
        c = np.array([float(v) for v in r])
        assert check_prove(sys, Interval(c - 1e-6, c + 1e-6)[None, :]) >= 1, (sys.what, r)


@pytest.mark.parametrize("sys", [
    make_system(2, [0.0, 0.0], [0.0], [], "lin", 1.0, "zero", 0, 0),  # x^2 = 0, y = x
    make_system(2, [0.5, 0.5], [0.25], [], "sqr", -0.5, "zero", 3, 1),
    make_system(3, [1.0, 1.0], [0.0], [0.5], "sin", 1.0, "mul", 1, 2),
    make_system(2, [0.0], [0.0], [], "lin", 1.0, "zero", 0, 0, offset=1.0),  # x^2 + 1 = 0
    make_system(2, [0.5], [0.0], [], "lin", 1.0, "zero", 2, 3, offset=2.0 ** -40),
    make_system(3, [0.5], [0.0], [1.0], "lin", 1.0, "cos", 1, 1, offset=2.0 ** -20),
], ids=lambda s: s.what)
def test_double_and_missing_roots_are_never_proved(sys):
    """Double roots (``x^2 = 0, y = x`` among them) and systems without a real root
    (``x^2 + 1 = 0``, ``(x - 1/2)^2 + 2^-40 = 0``): no box around the double root or the
    near-miss is ever proved, at any width."""
    c = np.array([float(v) for v in sys.roots[0]]) if sys.roots else np.full(sys.n, 0.5)
    boxes = np.concatenate([[c - w, c + w] for w in (1e-14, 1e-10, 1e-6, 1e-3, 0.1, 1.0)])
    x = Interval(boxes[0::2], boxes[1::2])
    assert check_prove(sys, x, rounds=8) == 0


# -------------------------------------------------------------------------------------------
# solve_square
# -------------------------------------------------------------------------------------------


def _search_box(sys: KnownSystem) -> Interval:
    lo = np.full(sys.n, -2.0)
    hi = np.full(sys.n, 2.0)
    for r in sys.roots:
        lo = np.minimum(lo, [math.floor(float(v)) - 1 for v in r])
        hi = np.maximum(hi, [math.ceil(float(v)) + 1 for v in r])
    return Interval(lo, hi)


def check_solve(sys: KnownSystem, box: Interval | None = None, eps: float = 1e-6,
                cut: float | None = None) -> None:
    """solve_square: every root in the search box lies in a returned box; each proved box
    holds exactly one root, a simple one, and distinct proved boxes distinct roots;
    mpmath.findroot from a proved box's midpoint (50 digits) converges inside it. With
    ``cut``, the model also says ``u0 <= cut``: the roots beyond it are no solutions (a
    proved box may hold none of them)."""
    box = _search_box(sys) if box is None else box
    model = sys.model()
    if cut is not None:
        model.add(Var("u0") <= cut)
    res = solve_square(model, box, eps=eps, max_boxes=3000)
    lo, hi = res.boxes.lo, res.boxes.hi
    assert res.variables == [f"u{i}" for i in range(sys.n)]
    feasible = [cut is None or r[0] <= cut for r in sys.roots]
    in_search = [q for q, r in enumerate(sys.roots) if mp_in_box(r, box.lo, box.hi)]
    for q in in_search:
        assert not feasible[q] or any(mp_in_box(sys.roots[q], lo[i], hi[i])
                                      for i in range(len(res))), (
            "root lost", sys.what, sys.roots[q], res)
    owner = {}
    for i in np.nonzero(res.proved)[0]:
        inside = [q for q, r in enumerate(sys.roots) if mp_in_box(r, lo[i], hi[i])]
        assert len(inside) == 1, ("false proof", sys.what, res.boxes[i], inside)
        assert sys.simple[inside[0]], ("proved a multiple root", sys.what, res.boxes[i])
        assert feasible[inside[0]], ("proved a root beyond the cut", sys.what, cut)
        assert inside[0] not in owner, ("one root, two proved boxes", sys.what,
                                         res.boxes[owner[inside[0]]], res.boxes[i])
        owner[inside[0]] = i
        with mpmath.workdps(50):
            mid = [mpf(0.5 * a + 0.5 * b) for a, b in zip(lo[i], hi[i], strict=True)]
            z = mpmath.findroot(lambda *u, s=sys: s.value(u), mid)
            z = [z[j] for j in range(sys.n)]
            slack = mpf(10) ** -40
            assert all(mpf(a) - slack <= v <= mpf(b) + slack
                       for v, a, b in zip(z, lo[i], hi[i], strict=True)), (sys.what, z)
    if not any(s and f for s, f in zip(sys.simple, feasible, strict=True)):
        assert not res.proved.any()


@st.composite
def cuts(draw, sys: KnownSystem):
    """None mostly, else a bound on ``u0``: at a root's ``u0`` (rounded), a float next to it,
    or anywhere."""
    kind = draw(st.integers(0, 5))
    if kind <= 2:
        return None
    if kind <= 4 and sys.roots:
        v = float(draw(st.sampled_from(sys.roots))[0])
        return v if kind == 3 else math.nextafter(v, draw(st.sampled_from([-INF, INF])))
    return draw(st.floats(-3, 3))


@settings(max_examples=20, deadline=None)
@given(st.data())
def test_solve_square_finds_and_proves(data):
    """solve_square on random systems with known roots (simple, double, close pairs, none),
    now and then with an inequality cutting through or next to a root."""
    sys = data.draw(known_systems(), label="system")
    check_solve(sys, cut=data.draw(cuts(sys), label="cut"))


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(st.data())
def test_solve_square_finds_and_proves_long(data):
    """solve_square, many more systems, inequalities, and search boxes cutting through the
    roots."""
    sys = data.draw(known_systems(), label="system")
    box = _search_box(sys)
    if data.draw(st.booleans()):  # a box whose faces pass through roots or near them
        box = Interval(box.lo, np.full(sys.n, 0.5))
    check_solve(sys, box, cut=data.draw(cuts(sys), label="cut"))


@pytest.mark.parametrize("sys", [
    make_system(2, [0.0, 0.0], [0.0], [], "lin", 1.0, "zero", 0, 0),
    make_system(2, [0.0], [0.0], [], "lin", 1.0, "zero", 0, 0, offset=1.0),
    make_system(3, [0.25, -0.5, 1.0], [0.5, -1.0], [0.0, 1.5], "sqr", 0.25, "cos", 2, 1),
], ids=lambda s: s.what)
def test_solve_square_by_hand(sys):
    """The double root of ``x^2 = 0, y = x`` and ``x^2 + 1 = 0`` prove nothing; a 3x3 system
    with 12 simple roots (mixed variables and equations) proves each exactly once."""
    check_solve(sys)
    if sum(sys.simple) == 12:
        res = solve_square(sys.model(), _search_box(sys), eps=1e-8)
        assert int(res.proved.sum()) == 12


def test_solve_square_root_on_a_bisection_face_regression():
    """``x (x - 1/2) = 0, x + y = 1`` on ``[-1, 1] x [-1, 3]``: the roots (0, 1) and (1/2,
    1/2) lie on bisection faces, both halves contract to the same point box and are proved;
    that point was reported twice (4 proved solutions instead of 2: _merge only tried a
    proof on the hull, which a point box cannot pass). Then the same with two overlapping
    boxes a few ulps wide."""
    x, y = Var("x"), Var("y")
    res = solve_square(Model().add(x * (x - 0.5) == 0, x + y == 1), Interval([-1, -1], [1, 3]))
    sols = sorted(map(tuple, res.solutions.lo.tolist()))
    assert int(res.proved.sum()) == 2 and len(res) == 2, res.boxes
    assert bool(res.solutions.contains(np.array([0.0, 1.0])).all(axis=-1).any())
    assert bool(res.solutions.contains(np.array([0.5, 0.5])).all(axis=-1).any()), sols
    sys = make_system(2, [-0.5, 0.5, -0.75], [-1.5], [], "zero", 1.0, "zero", 2, 0)
    check_solve(sys)
    assert int(solve_square(sys.model(), _search_box(sys), eps=1e-6).proved.sum()) == 3
    # two proved boxes a few ulps wide, overlapping but not nested, around the root
    # (1/32, -11/16): their hull is too narrow for Krawczyk's test beyond the rounding errors
    sys = make_system(2, [-1.25, -0.625], [-0.5, 1.25], [-1.5], "lin", 0.25, "mul", 3, 2)
    check_solve(sys)
    assert int(solve_square(sys.model(), _search_box(sys), eps=1e-6).proved.sum()) == 4


@pytest.mark.parametrize("extra", ["inequality", "domain"])
def test_solve_square_other_constraints_regression(extra):
    """``x^2 = 2, y = 1`` with ``x >= 1.4142135623730951`` (or that domain declared): no
    solution, sqrt(2) = 1.41421356237309504... lies below the float. Hull consistency cannot
    refute the point x = 1.4142135623730951 (x^2 rounds to [2, 2 + 4e-16]); a Newton proof
    on a wider box (of the equations' root sqrt(2)) was kept through that contraction: the
    point box was reported proved (it holds no solution at all), and on [0, 2]^2 the
    inflated undecided box was proved with sqrt(2) outside the model. A proof now needs the
    whole contracted box inside the other constraints and the declared domains."""
    x, y = Var("x"), Var("y")
    t = 1.4142135623730951
    assert mpmath.sqrt(2) < t
    m = Model().add(x ** 2 == 2, y == 1)
    if extra == "inequality":
        m.add(x >= t)
    else:
        m = Model(domains={"x": Interval(t, 2.0), "y": Interval(0.0, 2.0)},
                  constraints=m.constraints)
    for box in (Interval([1.4, 0.5], [1.5, 1.5]), Interval([0.0, 0.0], [2.0, 2.0])):
        res = solve_square(m, box)
        assert not res.proved.any(), (box, res.boxes)
    # the same with a feasible bound: proved, the root inside the reported box
    m = Model().add(x ** 2 == 2, y == 1, x >= 1.4142135623730949)
    res = solve_square(m, Interval([0.0, 0.0], [2.0, 2.0]))
    assert int(res.proved.sum()) == 1
    assert mp_in_box((mpmath.sqrt(2), mpf(1)), res.solutions.lo[0], res.solutions.hi[0])


@pytest.mark.parametrize(("theta", "a", "b", "c", "lo", "hi"), [
    (-0.2994083225038464, -0.5, -2.0, 1.0, [8.518948120084008, -2.6299282363615286],
     [8.519220561564577, -2.6296557948809594]),
    (1.8620411048180596, -2.0, 0.5, 1.0, [-0.2838701692426068, 0.8750776112526567],
     [-0.26006674593254664, 0.8988810345627168]),
])
def test_newton_atan2_regression(theta, a, b, c, lo, hi):
    """``atan2(y, x) = theta, a x + b y = c`` (one root, on the ray at angle theta): with the
    partial derivatives of atan2 swapped (tests/test_derivatives.py), Krawczyk's test passed
    on these boxes, which miss the root: a false proof of existence. Boxes around the root
    are proved."""
    x, y = Var("x"), Var("y")
    tape = function_tape([bd.atan2(y, x), a * x + b * y], [x, y], [(theta, theta), (c, c)])
    t = c / (a * mpmath.cos(theta) + b * mpmath.sin(theta))
    root = (t * mpmath.cos(theta), t * mpmath.sin(theta))
    assert t > 0 and not mp_in_box(root, lo, hi)
    sys = KnownSystem(2, lambda u, m: [m.atan2(u[1], u[0]) - theta, a * u[0] + b * u[1] - c],
                      [root], [True], "atan2")
    box = Interval(lo, hi)[None, :]
    newton = CtcNewton(tape)
    for _ in range(3):
        box, proved = newton.prove(box)
        assert not proved.any(), box
    c0 = np.array([float(v) for v in root])
    assert check_prove(sys, Interval(c0 - 1e-6, c0 + 1e-6)[None, :]) >= 1
