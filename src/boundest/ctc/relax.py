"""Linear relaxation of the nonlinear nodes of a tape around a box (polytope hull).

Trombettoni, Araya, Neveu and Chabert 2011 (X-Newton, the polytope hull contractor of IBEX):
around the current box, every nonlinear primitive ``z = op(x[, y])`` is enclosed by a few
linear inequalities valid on the whole box, and the LP over them and the exactly linear rows
(``boundest.ctc.linear``) contracts the box. Smaller boxes give tighter inequalities, so the
contraction is iterated (``CtcPolytopeHull``).

Rows are ``sum_t a_t v_t <= r`` with **exact float coefficients** ``a_t`` and a right-hand
side ``r`` rounded outward: every point of the node's graph over the box satisfies the row
exactly, in real arithmetic. ``boundest.ctc.linear.safe_lower_bound`` then turns any LP dual
into a rigorous bound. Every rounding happens in ``boundest.interval`` (outward rounded
operations and elementary functions), only ever on the side that loosens the row. A row with
a non-finite or huge (``> 1e9``) number is dropped: fewer rows are always a sound relaxation.

**Products** ``z = x y`` with ``x in [xl, xh]``, ``y in [yl, yh]`` (McCormick, 1976): the four
products ``(x - xl)(y - yl)``, ``(xh - x)(yh - y)``, ``(x - xl)(yh - y)``, ``(xh - x)(y - yl)``
are ``>= 0`` on the box, that is

    yl x + xl y - z <= xl yl          yh x + xh y - z <= xh yh
    z - yh x - xl y <= -xl yh         z - yl x - xh y <= -xh yl.

The coefficients are domain bounds (exact floats); each right-hand side is the upper bound of
an interval product. A row needs only its two bounds finite. **Division** ``z = x / y``: every
solution has ``y != 0`` and so ``x = z y``, the McCormick rows of that product (``z`` and
``y`` bounded, which hull consistency gives when ``y`` is sign-definite). **min / max**:
``z <= x, z <= y`` and ``z >= x, z >= y``.

**Unary** ``z = f(x)`` where ``f`` is convex on ``[xl, xh]`` (``g = f``) or concave (``g =
-f``, the rows below written for ``-z``); ``f`` has no row where neither is proven.

* Secant (above ``g``): for *any* float slope ``s``, ``g(x) - s x`` is convex, so its maximum
  over ``[xl, xh]`` is at an end: ``g(x) <= s x + d`` with ``d = max(ub(G(xl) - s xl),
  ub(G(xh) - s xh))``, ``G`` an enclosure of ``g`` at a point. ``s`` is the float slope of the
  chord; its rounding error moves ``d``, never soundness.
* Tangents (below ``g``) at ``p in {xl, mid, xh}``: convexity gives ``g(x) >= g(p) +
  g'(p)(x - p)``. With ``s`` the midpoint of an enclosure ``S`` of ``g'(p)``, ``|g'(p) - s|
  <= mag(S - s)`` and ``|x - p| <= dmax = max(p - xl, xh - p)``, so ``g(x) >= s x + e`` with
  ``e = lb(G(p) - s p - mag(S - s) dmax)``: an exact slope, the derivative's error in ``e``.
  A tangent where the derivative is unbounded (``sqrt`` at 0, ``asin`` at 1) is dropped.

Convexity regions, proven on the box from interval enclosures (exact in sign):

======================== =========================================================
convex everywhere        ``sqr``, ``exp``, ``cosh``, ``abs``, ``pown`` with even ``n > 0``
concave                  ``sqrt`` (on ``[0, inf[``), ``log`` (on ``]0, inf[``)
by the sign of ``x``     ``pown`` odd ``n > 1``, ``sinh`` (convex for ``x >= 0``); ``atan``,
                         ``tanh`` (concave for ``x >= 0``); ``asin`` / ``acos`` on
                         ``[-1, 1]`` (convex / concave for ``x >= 0``); ``pown`` with
                         ``n < 0`` on sign-definite boxes (convex, but odd ``n`` on
                         ``x < 0``: concave)
by the sign of ``f``     ``sin``, ``cos`` (``f'' = -f``: concave where the enclosure of
                         ``f`` over the box is ``>= 0``, convex where ``<= 0``); ``tan``
                         (``f'' = 2 f (1 + f^2)``: a finite enclosure excludes a pole)
======================== =========================================================

``sqrt``, ``log``, ``asin`` and ``acos`` are taken over the part of the box in their domain
(a solution lies there). The derivatives are enclosed the same way (``exp``, ``1 / x``,
``1 / (2 sqrt x)``, ``cos``, ...).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..expr.tape import OPS, Tape
from ..interval import (
    Interval,
    acos,
    asin,
    atan,
    cos,
    cosh,
    exp,
    log,
    pown,
    sign,
    sin,
    sinh,
    sqr,
    sqrt,
    tan,
    tanh,
)
from ..interval.algebraic import _exponent
from ..interval.algebraic import abs as iabs
from .linear import CtcLinear

__all__ = ["CtcPolytopeHull", "RowBlock", "relaxation"]

_CODE = {name: i for i, name in enumerate(OPS)}
#: Rows with a coefficient or right-hand side beyond this are dropped (LP conditioning).
_BIG = 1e9


@dataclass
class RowBlock:
    """``m`` rows ``sum_t coefs[t][i] * v[cols[t][i]] <= rhs[i]`` over slot columns.

    Attributes
    ----------
    cols : list of (m,) int64
        The slot of each term.
    coefs : list of (m,) float64
        Exact coefficients.
    rhs : (m,) float64
        Right-hand sides (rounded upward).
    """

    cols: list[NDArray[np.int64]]
    coefs: list[NDArray[np.float64]]
    rhs: NDArray[np.float64]

    @property
    def n_rows(self) -> int:
        return len(self.rhs)


def _block(cols: list[NDArray], coefs: list[NDArray], rhs: NDArray, valid: NDArray
           ) -> RowBlock:
    """The rows of ``valid`` whose numbers are all finite and at most ``_BIG``."""
    m = len(rhs)
    coefs = [np.broadcast_to(np.asarray(c, dtype=np.float64), (m,)) for c in coefs]
    keep = np.asarray(valid, dtype=bool) & np.isfinite(rhs) & (np.abs(rhs) <= _BIG)
    for c in coefs:
        keep &= np.isfinite(c) & (np.abs(c) <= _BIG)
    return RowBlock([np.asarray(c, dtype=np.int64)[keep] for c in cols],
                    [c[keep] for c in coefs], np.asarray(rhs, dtype=np.float64)[keep])


def _pt(v: NDArray) -> Interval:
    """Degenerate intervals at finite points (non-finite ones replaced by 0; the caller
    drops their rows)."""
    v = np.where(np.isfinite(v), v, 0.0)
    return Interval.trusted(v, v.copy())


def _mccormick(z: NDArray, x: NDArray, y: NDArray, lo: NDArray, hi: NDArray) -> list[RowBlock]:
    """The four McCormick rows of ``z = x y`` over the box (slot arrays)."""
    xl, xh, yl, yh = lo[x], hi[x], lo[y], hi[y]
    fin = [np.isfinite(v) for v in (xl, xh, yl, yh)]
    one = np.ones(len(z))
    out = []
    for (a, fa), (b, fb), sg in (((xl, fin[0]), (yl, fin[2]), 1.0),
                                 ((xh, fin[1]), (yh, fin[3]), 1.0),
                                 ((xl, fin[0]), (yh, fin[3]), -1.0),
                                 ((xh, fin[1]), (yl, fin[2]), -1.0)):
        # sg = 1: b x + a y - z <= a b;  sg = -1: z - b x - a y <= -a b
        rhs = (_pt(sg * a) * _pt(b)).hi
        out.append(_block([x, y, z], [sg * b, sg * a, -sg * one], rhs, fa & fb))
    return out


def _convex(z: NDArray, x: NDArray, xl: NDArray, xh: NDArray, curv: NDArray,
            f: Callable[[Interval], Interval], df: Callable[[Interval], Interval]
            ) -> list[RowBlock]:
    """Secant and tangent rows of ``z = f(x)`` on ``[xl, xh]`` where ``curv`` is +1 (``f``
    convex there) or -1 (concave); nodes of ``curv = 0`` or a degenerate ``[xl, xh]`` get
    none. ``f`` and ``df`` (an enclosure of the derivative) act on arrays of all nodes."""
    ok = (curv != 0) & (xl < xh)
    if not ok.any():
        return []
    cv = np.asarray(curv, dtype=np.float64)
    fin = np.isfinite(xl) & np.isfinite(xh)
    neg = cv < 0

    def g(p: Interval) -> Interval:  # cv * f, exact negation
        v = f(p)
        return Interval.trusted(np.where(neg, -v.hi, v.lo), np.where(neg, -v.lo, v.hi))

    def dg(p: Interval) -> Interval:
        v = df(p)
        return Interval.trusted(np.where(neg, -v.hi, v.lo), np.where(neg, -v.lo, v.hi))

    out = []
    # secant: cv z - s x <= d
    L, H = _pt(xl), _pt(xh)
    gl, gh = g(L), g(H)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        s = (gh.mid() - gl.mid()) / (xh - xl)
    s = np.where(np.isfinite(s), s, 0.0)
    S = _pt(s)
    d = np.maximum((gl - S * L).hi, (gh - S * H).hi)
    out.append(_block([z, x], [cv, -s], d, ok & fin))
    # tangents at the ends and the midpoint: s x - cv z <= -e
    with np.errstate(invalid="ignore"):  # (the rows of unbounded boxes are dropped)
        mid = np.where(fin, np.clip(0.5 * xl + 0.5 * xh, xl, xh), np.nan)
    for p in (xl, mid, xh):
        P = _pt(p)
        D = dg(P)
        s = D.mid()
        s = np.where(np.isfinite(s), s, 0.0)
        S = _pt(s)
        err = S - D  # s - g'(p) lies in it
        mag = np.maximum(np.abs(err.lo), np.abs(err.hi))
        dmax = np.maximum((P - _pt(xl)).hi, (_pt(xh) - P).hi)
        # mag * dmax rounded up; an unbounded side still gives a row where mag = 0
        E = (_pt(mag) * _pt(dmax)).hi
        E = np.where(fin, E, np.where(mag == 0, 0.0, np.inf))
        e = (g(P) - S * P - Interval.trusted(E, E)).lo
        valid = ok & np.isfinite(p) & np.isfinite(D.lo) & np.isfinite(D.hi)
        out.append(_block([x, z], [s, -cv], -e, valid))
    return out


def _recip_sqrt_1m(p: Interval) -> Interval:
    """``1 / sqrt(1 - p^2)`` (the derivative of ``asin``)."""
    return 1.0 / sqrt(1.0 - sqr(p))


def _unary_rows(tape: Tape, lo: NDArray, hi: NDArray, keep: NDArray) -> list[RowBlock]:
    op, out, a = tape.op, tape.out.astype(np.int64), tape.a.astype(np.int64)
    rows: list[RowBlock] = []

    def sel(name: str) -> NDArray[np.bool_]:
        return keep & (op == _CODE[name])

    def add(m: NDArray, curv, f, df, xl=None, xh=None) -> None:
        if not m.any():
            return
        s = a[m]
        xl = lo[s] if xl is None else xl[m]
        xh = hi[s] if xh is None else xh[m]
        curv = np.full(s.shape, curv) if np.ndim(curv) == 0 else curv[m]
        rows.extend(_convex(out[m], s, xl, xh, curv, f, df))

    xl, xh = lo[a], hi[a]
    pos, nonpos = xl >= 0, xh <= 0
    sgn = np.where(pos, 1, np.where(nonpos, -1, 0))  # +1 / -1 where x >= 0 / x <= 0
    add(sel("sqr"), 1, sqr, lambda p: 2.0 * p)
    add(sel("exp"), 1, exp, exp)
    add(sel("cosh"), 1, cosh, sinh)
    add(sel("abs"), 1, iabs, sign)
    add(sel("sinh"), sgn, sinh, cosh)
    add(sel("atan"), -sgn, atan, lambda p: 1.0 / (1.0 + sqr(p)))
    add(sel("tanh"), -sgn, tanh, lambda p: 1.0 - sqr(tanh(p)))
    dom = np.maximum(xl, 0.0)
    add(sel("sqrt") & (xh >= 0), -1, sqrt, lambda p: 0.5 / sqrt(p), xl=dom)
    add(sel("log") & (xh > 0), -1, log, lambda p: 1.0 / p, xl=dom)
    al, ah = np.maximum(xl, -1.0), np.minimum(xh, 1.0)
    asg = np.where(al >= 0, 1, np.where(ah <= 0, -1, 0))
    add(sel("asin") & (al <= ah), asg, asin, _recip_sqrt_1m, xl=al, xh=ah)
    add(sel("acos") & (al <= ah), -asg, acos, lambda p: -_recip_sqrt_1m(p), xl=al, xh=ah)
    X = Interval.trusted(np.where(np.isfinite(xl), xl, 0.0), np.where(np.isfinite(xh), xh, 0.0))
    bounded = np.isfinite(xl) & np.isfinite(xh)
    for name, f, df in (("sin", sin, cos), ("cos", cos, lambda p: -sin(p)),
                        ("tan", tan, lambda p: 1.0 + sqr(tan(p)))):
        m = sel(name) & bounded
        if not m.any():
            continue
        F = f(X)
        fin = np.isfinite(F.lo) & np.isfinite(F.hi)
        curv = np.where(fin & (F.lo >= 0), 1, np.where(fin & (F.hi <= 0), -1, 0))
        if name != "tan":  # f'' = -f
            curv = -curv
        add(m, curv, f, df)
    n = tape.param
    m = sel("pown") & (n != 0) & (n != 1)
    if m.any():
        even = np.mod(n, 2) == 0
        sdef = (xl > 0) | (xh < 0)
        curv = np.where(n > 0, np.where(even, 1, sgn),
                        np.where(sdef, np.where(even | (xl > 0), 1, -1), 0))
        # the kernels' int64 exponents (any magnitude: not astype, undefined beyond 2**63);
        # the factor of the derivative is the exact n itself
        k = _exponent(n[m])
        add(m, curv, lambda p: pown(p, k), lambda p: _pt(n[m]) * pown(p, k - 1))
    return rows


def relaxation(tape: Tape, lo: NDArray[np.float64], hi: NDArray[np.float64],
               skip: NDArray[np.bool_] | None = None) -> list[RowBlock]:
    """Sound linear inequalities enclosing the nonlinear nodes of ``tape`` over ``[lo, hi]``.

    Parameters
    ----------
    tape : Tape
    lo, hi : (n_slots,) float64
        The box of the slots.
    skip : (n_nodes,) bool, optional
        Nodes to leave out (those the caller already holds as exact linear rows).

    Returns
    -------
    list of RowBlock
        Rows over slot columns (see the module docstring for each inequality).
    """
    keep = np.ones(tape.n_nodes, dtype=bool) if skip is None else ~np.asarray(skip, dtype=bool)
    op = tape.op
    out, a, b = tape.out.astype(np.int64), tape.a.astype(np.int64), tape.b.astype(np.int64)
    rows: list[RowBlock] = []
    m = keep & (op == _CODE["mul"])
    if m.any():
        rows += _mccormick(out[m], a[m], b[m], lo, hi)
    m = keep & (op == _CODE["div"])
    if m.any():  # a = out * b
        rows += _mccormick(a[m], out[m], b[m], lo, hi)
    one = np.ones(tape.n_nodes)
    for name, sg in (("min", 1.0), ("max", -1.0)):  # sg (z - arg) <= 0
        m = keep & (op == _CODE[name])
        for arg in (a, b):
            rows.append(_block([out[m], arg[m]], [sg * one[m], -sg * one[m]],
                               np.zeros(int(m.sum())), np.ones(int(m.sum()), dtype=bool)))
    rows += _unary_rows(tape, lo, hi, keep)
    return [r for r in rows if r.n_rows]


class CtcPolytopeHull(CtcLinear):
    """Polytope hull: LP contraction over the linear rows and a linear relaxation of the
    nonlinear nodes around the box, repeated while it pays.

    Each round relaxes every nonlinear node around the current box (``relaxation``), adds the
    linear and log-linear rows (``ctc.linear.extract``), and narrows each target by two LPs
    with rigorous bounds (``ctc.linear.contract_slots(relax=True)``); the next round relaxes
    around the narrower box, which gives tighter rows.

    Parameters
    ----------
    tape : Tape
        The CSP; boxes are over its slots (shape ``(..., tape.n_slots)``). Bounded boxes are
        needed for most rows: run hull consistency first (``CtcFwdBwd``, ``csp.propagate``).
    targets : array of int, optional
        Slots to narrow (default: every slot in a row; intermediate slots narrowed too give
        tighter rows in the next round).
    rounds : int
        Rounds at most.
    min_gain : float
        Stop when a round narrows the targets' total width by less than this fraction.
    log_linear : bool
        Also use the log-linear rows (``CtcLinear``).
    radius : int, optional
        Each target's LPs on the rows within this many row-steps of it (``CtcLinear``).

    Examples
    --------
    >>> from boundest.expr import Model, Var
    >>> from boundest.expr.tape import compile_model
    >>> x, y = Var("x"), Var("y")
    >>> m = Model()
    >>> _ = m.declare(x, (0.0, 4.0)), m.declare(y, (0.0, 4.0))
    >>> _ = m.add(x * y == 1, x + y == 2.5)
    >>> tape = compile_model(m)
    >>> box = CtcPolytopeHull(tape, rounds=8)(tape.domains())
    >>> bool(box[tape.slot_of["x"]].hi < 2.1)
    True
    """

    def __init__(self, tape: Tape, targets: NDArray[np.int64] | None = None, rounds: int = 4,
                 min_gain: float = 0.01, log_linear: bool = True,
                 radius: int | None = None) -> None:
        if rounds < 1:
            raise ValueError(f"rounds must be at least 1, got {rounds}")
        super().__init__(tape, targets, log_linear, radius, relax=True)
        self.rounds = rounds
        self.min_gain = min_gain

    def _contract_box(self, lo: NDArray[np.float64], hi: NDArray[np.float64]
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64], bool]:
        sl = slice(None) if self.targets is None else self.targets
        for _ in range(self.rounds):
            w0 = float(np.sum(hi[sl] - lo[sl]))
            lo, hi, ok = super()._contract_box(lo, hi)
            if not ok:
                return lo, hi, False
            if not np.sum(hi[sl] - lo[sl]) < (1.0 - self.min_gain) * w0:
                break
        return lo, hi, True
