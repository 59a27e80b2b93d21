"""Contraction of the linear and log-linear sub-networks of a CSP by linear programming.

Jaulin 2002 (section 5.1, equations 17-19): a state-estimation CSP holds large sub-networks of
linear constraints (``x1' = x1 + 0.5 x3 + w1``, ``y3 = z1 + z2``), and its multiplicative
constraints over sign-definite variables (``z = x y``, ``z = x / y``, ``z = x^n``,
``z = sqrt(x)``) are linear in the logarithms ``X = log|x|``. A linear programme over each
sub-network contracts its variables globally, where hull consistency only contracts one
constraint at a time.

The LP is solved in floating point by HiGHS (``scipy.optimize.linprog``, the ``lp`` extra);
its optimum is an approximation and is never used as a bound. Each bound comes from the LP's
dual ``y`` through the correction of Neumaier and Shcherbina (2004): for rows
``A x = z`` with ``z in [b]`` and ``x in [l, u]``, every feasible ``x`` satisfies
``c^T x = y^T z + r^T x`` with ``r = c - A^T y``, so

    c^T x >= lb( y^T [b] + sum_j [r_j] [l_j, u_j] ),

evaluated in interval arithmetic (``boundest.interval``), for *any* ``y``: a poor dual only
loosens the bound. Interval coefficients ``[A]`` (decimal constants, a narrow factor) are
handled the same way, ``[r] = c - [A]^T y``. Infeasibility is only declared on a certificate:
the phase-one LP ``min sum(s+ + s-)``, ``A x + s+ - s- in [b]``, whose rigorous lower bound is
positive (a Farkas certificate checked in interval arithmetic).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..expr.tape import OPS, Tape
from ..interval import Interval, exp, log
from .base import Contractor

__all__ = ["CtcLinear", "LinearSystem", "extract", "lp_bound", "safe_lower_bound"]

_CODE = {name: i for i, name in enumerate(OPS)}


def _linprog():
    """``scipy.optimize.linprog``, or an error naming the extra that provides it."""
    try:
        from scipy.optimize import linprog
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("linear-programming contraction needs SciPy: "
                          "pip install 'boundest[lp]'") from exc
    return linprog


@dataclass
class LinearSystem:
    """Rows ``sum_j A_ij x_j in [b_lo_i, b_hi_i]`` with ``A_ij in [a_lo, a_hi]`` (COO).

    Attributes
    ----------
    rows, cols : (nnz,) int64
        Positions of the nonzero coefficients (a position appears at most once).
    a_lo, a_hi : (nnz,) float64
        Coefficient intervals (``a_lo == a_hi`` for exact coefficients).
    b_lo, b_hi : (n_rows,) float64
        Row ranges (``b_lo == b_hi`` for equalities; infinite bounds allowed).
    n_cols : int
    """

    rows: NDArray[np.int64]
    cols: NDArray[np.int64]
    a_lo: NDArray[np.float64]
    a_hi: NDArray[np.float64]
    b_lo: NDArray[np.float64]
    b_hi: NDArray[np.float64]
    n_cols: int

    @property
    def n_rows(self) -> int:
        return len(self.b_lo)

    @classmethod
    def dense(cls, A: NDArray, b_lo: NDArray, b_hi: NDArray,
              A_hi: NDArray | None = None) -> LinearSystem:
        """From a dense matrix (``A_hi`` given: the interval matrix ``[A, A_hi]``)."""
        A = np.asarray(A, dtype=np.float64)
        A_hi = A if A_hi is None else np.asarray(A_hi, dtype=np.float64)
        r, c = np.nonzero((A != 0) | (A_hi != 0))
        return cls(r.astype(np.int64), c.astype(np.int64), A[r, c], A_hi[r, c],
                   np.asarray(b_lo, dtype=np.float64).copy(),
                   np.asarray(b_hi, dtype=np.float64).copy(), A.shape[1])

    def mid_csr(self):
        """The midpoint matrix as a SciPy CSR matrix (what the LP solver sees)."""
        from scipy.sparse import csr_matrix

        mid = 0.5 * self.a_lo + 0.5 * self.a_hi
        return csr_matrix((mid, (self.rows, self.cols)), shape=(self.n_rows, self.n_cols))

    def select(self, keep_rows: NDArray[np.bool_]) -> LinearSystem:
        """The sub-system of the rows ``keep_rows`` (a relaxation: fewer constraints)."""
        new = np.cumsum(keep_rows) - 1
        nz = keep_rows[self.rows]
        return LinearSystem(new[self.rows[nz]], self.cols[nz], self.a_lo[nz], self.a_hi[nz],
                            self.b_lo[keep_rows], self.b_hi[keep_rows], self.n_cols)


_U = 2.0**-53  # unit roundoff of float64


def _segment_sum(lo: NDArray[np.float64], hi: NDArray[np.float64], seg: NDArray[np.int64],
                 n: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Enclosures of the sums of the intervals ``[lo_i, hi_i]`` grouped by ``seg`` (``n``
    groups), rounded outward.

    The float sums (``np.bincount``, a recursive summation) are widened by Higham's bound on
    recursive summation, ``|fl(sum) - sum| <= gamma_(k-1) sum |p_i|`` with
    ``gamma_k = k u / (1 - k u)`` for ``k`` terms; ``sum |p_i|`` is itself computed in float
    and taken ``(1 + gamma_k)`` larger, and every step of the widening is rounded outward
    (additions in gradual underflow are exact, so no underflow term is needed). Where the
    bound is zero (one term, or all terms zero) the float sum is exact and kept as it is:
    a zero reduced cost of a free variable must stay exactly zero. Infinite
    terms give an infinite sum on their side; ``-inf + inf`` in a bound's sum cannot happen
    (a lower bound is never ``+inf``).
    """
    k = np.maximum(np.bincount(seg, minlength=n).astype(np.float64) - 1.0, 0.0)
    gamma = np.nextafter(k * _U / (1.0 - k * _U), np.inf)
    gamma = np.where(k > 0, np.nextafter(gamma * (1.0 + gamma) * (1.0 + 4 * _U), np.inf), 0.0)
    out = []
    for v, side in ((lo, -np.inf), (hi, np.inf)):
        fin = np.isfinite(v)
        sv = np.bincount(seg, weights=np.where(fin, v, 0.0), minlength=n)
        sa = np.bincount(seg, weights=np.where(fin, np.abs(v), 0.0), minlength=n)
        err = gamma * sa
        err = np.where(err > 0, np.nextafter(err, np.inf), 0.0)
        r = np.where(err > 0, np.nextafter(sv + err if side > 0 else sv - err, side), sv)
        inf = np.bincount(seg, weights=(~fin).astype(np.float64), minlength=n) > 0
        out.append(np.where(inf, side, r))
    return out[0], out[1]


def _column_sums(system: LinearSystem, y: NDArray[np.float64]) -> Interval:
    """``[A]^T y`` in interval arithmetic, shape ``(n_cols,)``."""
    prod = Interval.trusted(system.a_lo, system.a_hi) * Interval(y[system.rows])
    lo, hi = _segment_sum(prod.lo, prod.hi, system.cols, system.n_cols)
    return Interval.trusted(lo, hi)


def safe_lower_bound(system: LinearSystem, c: NDArray[np.float64], y: NDArray[np.float64],
                     lo: NDArray[np.float64], hi: NDArray[np.float64]) -> float:
    """A rigorous lower bound of ``c^T x`` over the feasible set, from any multipliers ``y``.

    ``c^T x = y^T (A x) + r^T x`` with ``[r] = c - [A]^T y``; with ``A x in [b]`` and
    ``x in [lo, hi]`` the bound is the lower end of ``y^T [b] + [r]^T [lo, hi]``, in interval
    arithmetic (a product ``0 * inf`` is 0; a bound of a column that is infinite on the side
    its reduced cost needs makes the result ``-inf``). NaN multipliers count as 0, and so do
    multipliers of the sign that needs a row's infinite bound.

    Parameters
    ----------
    system : LinearSystem
    c : (n_cols,) float64
        The objective (exact floats).
    y : (n_rows,) float64
        Row multipliers (typically an LP dual).
    lo, hi : (n_cols,) float64
        The box of the variables.
    """
    y = np.where(np.isfinite(y), y, 0.0)
    # a multiplier of the wrong sign on a one-sided row (solver noise) would make the bound
    # -inf; 0 is as valid a multiplier as any
    y = np.where(system.b_lo == -np.inf, np.minimum(y, 0.0), y)
    y = np.where(system.b_hi == np.inf, np.maximum(y, 0.0), y)
    r = Interval(np.asarray(c, dtype=np.float64)) - _column_sums(system, y)
    terms_x = r * Interval.trusted(lo, hi)
    terms_b = Interval(y) * Interval.trusted(system.b_lo, system.b_hi)
    lo_terms = np.concatenate([terms_x.lo, terms_b.lo])
    if np.isnan(lo_terms).any():
        return -np.inf
    total, _ = _segment_sum(lo_terms, lo_terms, np.zeros(lo_terms.size, dtype=np.int64), 1)
    return float(total[0])


def _solve(system: LinearSystem, A, c: NDArray[np.float64], lo: NDArray[np.float64],
           hi: NDArray[np.float64]):
    """``min c^T x`` by HiGHS: ``(status, y)`` with ``y`` the row multipliers (None when the
    solver gave none). Equality rows go to ``A_eq``, ranges to two ``A_ub`` rows."""
    linprog = _linprog()
    eq = system.b_lo == system.b_hi
    up = ~eq & np.isfinite(system.b_hi)
    dn = ~eq & np.isfinite(system.b_lo)
    kw = {}
    if eq.any():
        kw["A_eq"], kw["b_eq"] = A[eq], system.b_lo[eq]
    if up.any() or dn.any():
        from scipy.sparse import vstack

        kw["A_ub"] = vstack([A[up], -A[dn]]).tocsr()
        kw["b_ub"] = np.concatenate([system.b_hi[up], -system.b_lo[dn]])
    bounds = np.stack([np.where(np.isfinite(lo), lo, -np.inf),
                       np.where(np.isfinite(hi), hi, np.inf)], axis=1)
    res = linprog(c, bounds=bounds, method="highs", **kw)
    y = np.zeros(system.n_rows)
    if res.status != 0:
        return res.status, None
    # HiGHS' marginals are d(objective)/d(right-hand side): the Lagrange multipliers
    if eq.any():
        y[eq] = res.eqlin.marginals
    if up.any() or dn.any():
        m = res.ineqlin.marginals
        nu = int(up.sum())
        y[up] += m[:nu]
        y[dn] -= m[nu:]
    return 0, y


class _Solver:
    """``min c^T x`` over one system for many objectives and boxes: a HiGHS instance kept
    between calls (each solve starts from the previous basis), through SciPy's bundled HiGHS
    bindings; ``scipy.optimize.linprog(method="highs")`` where those are not available.
    Returns rigorous lower bounds only (``bound``)."""

    def __init__(self, system: LinearSystem, A=None) -> None:
        self.system = system
        self.A = system.mid_csr() if A is None else A
        self.highs = None
        try:
            from scipy.optimize._highspy import _core as hc
        except ImportError:  # pragma: no cover - older or newer SciPy: the public API
            _linprog()
            return
        self.hc = hc
        h = hc._Highs()
        h.setOptionValue("output_flag", False)
        lp = hc.HighsLp()
        lp.num_col_, lp.num_row_ = system.n_cols, system.n_rows
        lp.col_cost_ = np.zeros(system.n_cols)
        lp.col_lower_ = np.full(system.n_cols, -np.inf)
        lp.col_upper_ = np.full(system.n_cols, np.inf)
        lp.row_lower_, lp.row_upper_ = system.b_lo.copy(), system.b_hi.copy()
        csc = self.A.tocsc()
        lp.a_matrix_.format_ = hc.MatrixFormat.kColwise
        lp.a_matrix_.start_ = csc.indptr.astype(np.int32)
        lp.a_matrix_.index_ = csc.indices.astype(np.int32)
        lp.a_matrix_.value_ = csc.data.astype(np.float64)
        # (a warning: HiGHS dropped tiny coefficients; the bounds stay rigorous, since
        # safe_lower_bound uses the system's own coefficients)
        if h.passModel(lp) == hc.HighsStatus.kError:  # pragma: no cover - malformed model
            raise RuntimeError("HiGHS rejected the LP")
        self.highs = h
        self.idx = np.arange(system.n_cols, dtype=np.int32)
        self.solves = 0

    def bound(self, c: NDArray[np.float64], lo: NDArray[np.float64],
              hi: NDArray[np.float64]) -> float:
        """A rigorous lower bound of ``c^T x`` (``+inf``: proven infeasible; ``-inf``: none)."""
        if self.highs is None:
            return _linprog_bound(self.system, self.A, c, lo, hi)
        h, hc, n = self.highs, self.hc, self.system.n_cols
        self.solves += 1
        h.changeColsCost(n, self.idx, np.asarray(c, dtype=np.float64))
        h.changeColsBounds(n, self.idx, lo, hi)
        if h.run() == hc.HighsStatus.kError:
            return -np.inf
        status = h.getModelStatus()
        if status == hc.HighsModelStatus.kOptimal:
            y = np.asarray(h.getSolution().row_dual, dtype=np.float64)
            return safe_lower_bound(self.system, c, y, lo, hi)
        if status == hc.HighsModelStatus.kInfeasible:
            _, has_ray, ray = h.getDualRay()
            zero = np.zeros(n)
            if has_ray:
                ray = np.asarray(ray, dtype=np.float64)
                for y in (ray, -ray):  # a Farkas certificate, checked in interval arithmetic
                    if safe_lower_bound(self.system, zero, y, lo, hi) > 0.0:
                        return np.inf
            if infeasible(self.system, lo, hi, self.A):
                return np.inf
        return -np.inf


def lp_bound(system: LinearSystem, c: NDArray[np.float64], lo: NDArray[np.float64],
             hi: NDArray[np.float64], A=None) -> float:
    """A rigorous lower bound of ``min c^T x`` over the rows and the box.

    ``+inf`` only when infeasibility is *proven* (Farkas certificate); ``-inf`` when no
    useful bound was found (unbounded LP, solver failure, an infinite box bound in the way).
    """
    return _Solver(system, A).bound(np.asarray(c, dtype=np.float64), lo, hi)


def _linprog_bound(system: LinearSystem, A, c: NDArray[np.float64], lo: NDArray[np.float64],
                   hi: NDArray[np.float64]) -> float:
    """``lp_bound`` through ``scipy.optimize.linprog(method="highs")``."""
    status, y = _solve(system, A, np.asarray(c, dtype=np.float64), lo, hi)
    if status == 0:
        return safe_lower_bound(system, c, y, lo, hi)
    if status == 2 and infeasible(system, lo, hi, A):
        return np.inf
    return -np.inf


def infeasible(system: LinearSystem, lo: NDArray[np.float64], hi: NDArray[np.float64],
               A=None) -> bool:
    """Whether the rows have *provably* no solution in the box.

    Phase one: ``min sum(s+ + s-)`` over ``A x + s+ - s- in [b]``, ``x`` in the box,
    ``s+, s- >= 0``, which is always feasible; its rigorous lower bound (multipliers clipped
    to ``[-1, 1]``, which keeps the slack columns' reduced costs non-negative) is positive
    only when no ``x`` satisfies the rows.
    """
    from scipy.sparse import eye, hstack

    if bool(np.any(lo > hi)) or bool(np.any(np.isnan(lo) | np.isnan(hi))):
        return True
    A = system.mid_csr() if A is None else A
    m, n = system.n_rows, system.n_cols
    I = eye(m, format="csr")
    ext = LinearSystem(
        np.concatenate([system.rows, np.arange(m), np.arange(m)]),
        np.concatenate([system.cols, n + np.arange(m), n + m + np.arange(m)]),
        np.concatenate([system.a_lo, np.ones(m), -np.ones(m)]),
        np.concatenate([system.a_hi, np.ones(m), -np.ones(m)]),
        system.b_lo, system.b_hi, n + 2 * m)
    c = np.concatenate([np.zeros(n), np.ones(2 * m)])
    elo = np.concatenate([lo, np.zeros(2 * m)])
    ehi = np.concatenate([hi, np.full(2 * m, np.inf)])
    status, y = _solve(ext, hstack([A, I, -I]).tocsr(), c, elo, ehi)
    if status != 0:
        return False
    return safe_lower_bound(ext, c, np.clip(y, -1.0, 1.0), elo, ehi) > 0.0


# --- extraction from a tape ----------------------------------------------------------------

def _is_const(tape: Tape) -> NDArray[np.bool_]:
    """Slots that no node writes and no variable names: the constants of the tape."""
    const = np.ones(tape.n_slots, dtype=bool)
    const[tape.out] = False
    const[list(tape.slot_of.values())] = False
    return const


@dataclass
class _Rows:
    """Rows under construction: lists of (row, col, a_lo, a_hi)."""

    r: list
    c: list
    lo: list
    hi: list
    n: int = 0
    b: list = field(default_factory=list)  # (first row, b_hi) of inequality blocks

    def add(self, cols: list[NDArray], coef_lo: list[NDArray], coef_hi: list[NDArray],
            b_hi: NDArray | None = None) -> None:
        """One row per element of the (equal-length) column arrays, ``sum coef * col = 0``
        (with ``b_hi``: ``sum coef * col <= b_hi``)."""
        m = len(cols[0])
        rows = self.n + np.arange(m)
        if b_hi is not None:
            self.b.append((self.n, np.asarray(b_hi, dtype=np.float64)))
        for col, a, b in zip(cols, coef_lo, coef_hi, strict=True):
            self.r.append(rows)
            self.c.append(np.asarray(col, dtype=np.int64))
            self.lo.append(np.broadcast_to(np.asarray(a, dtype=np.float64), (m,)))
            self.hi.append(np.broadcast_to(np.asarray(b, dtype=np.float64), (m,)))
        self.n += m

    def system(self, n_cols: int) -> LinearSystem:
        if not self.r:
            e = np.zeros(0)
            return LinearSystem(e.astype(np.int64), e.astype(np.int64), e, e, e, e, n_cols)
        rows, cols = np.concatenate(self.r), np.concatenate(self.c)
        lo, hi = np.concatenate(self.lo), np.concatenate(self.hi)
        # a column twice in a row (x = y + y): one coefficient, their interval sum, added
        # occurrence by occurrence (one vectorised addition per rank of repetition)
        key = rows * n_cols + cols
        uniq, inv = np.unique(key, return_inverse=True)
        order = np.argsort(inv, kind="stable")
        g = inv[order]
        start = np.searchsorted(g, np.arange(uniq.size))
        rank = np.arange(g.size) - start[g]
        acc = Interval.trusted(np.zeros(uniq.size), np.zeros(uniq.size))
        for k in range(int(rank.max()) + 1 if rank.size else 0):
            sel = order[rank == k]
            part = acc[inv[sel]] + Interval.trusted(lo[sel], hi[sel])
            acc.lo[inv[sel]], acc.hi[inv[sel]] = part.lo, part.hi
        acc_lo, acc_hi = acc.lo, acc.hi
        b_lo, b_hi = np.zeros(self.n), np.zeros(self.n)
        for first, rhs in self.b:
            b_lo[first:first + rhs.size] = -np.inf
            b_hi[first:first + rhs.size] = rhs
        return LinearSystem(uniq // n_cols, uniq % n_cols, acc_lo, acc_hi, b_lo, b_hi, n_cols)


def _log_abs(lo: NDArray, hi: NDArray) -> tuple[NDArray, NDArray]:
    """An enclosure of ``log|x|`` over sign-definite ``[lo, hi]`` (``lo > 0`` or ``hi < 0``)."""
    neg = hi < 0
    mlo, mhi = np.where(neg, -hi, lo), np.where(neg, -lo, hi)
    L = log(Interval.trusted(mlo, mhi))
    return L.lo, L.hi


@dataclass
class Extraction:
    """The linear and log-linear rows of a tape at a box.

    Columns ``0 .. n_slots - 1`` are the slots; column ``n_slots + i`` is ``log|slot
    log_slots[i]|``.
    """

    system: LinearSystem
    n_slots: int
    log_slots: NDArray[np.int64]

    def column_bounds(self, lo: NDArray, hi: NDArray) -> tuple[NDArray, NDArray]:
        """The box of all columns from the slots' domains."""
        llo, lhi = _log_abs(lo[self.log_slots], hi[self.log_slots])
        return np.concatenate([lo, llo]), np.concatenate([hi, lhi])


def extract(tape: Tape, lo: NDArray[np.float64], hi: NDArray[np.float64],
            log_linear: bool = True, relax: bool = False) -> Extraction:
    """The linear rows of ``tape``, (``log_linear``) the log-linear rows valid at ``[lo, hi]``
    and (``relax``) a linear relaxation of its nonlinear nodes over ``[lo, hi]``.

    Linear rows: ``add``, ``sub``, ``neg``, and ``mul``/``div`` where one factor (the divisor
    for ``div``) is a constant slot or has a degenerate domain, which becomes an interval
    coefficient. Log-linear rows (Jaulin 2002 equations 17-19), for nodes all of whose slots
    are sign-definite (domain in ``]0, inf[`` or ``]-inf, 0[``) at the box: ``mul``, ``div``,
    ``sqr``, ``pown``, ``neg``, ``abs``, ``sqrt`` and ``pow`` with a degenerate exponent, in
    ``X = log|x|``; ``exp`` and ``log`` link a slot to the logarithm of another. Relaxed rows
    (``ctc.relax.relaxation``: McCormick rows of products and quotients, secants and tangents
    of the unary functions where their convexity is proven on the box) are inequalities over
    the slots, for the nodes that have no exact linear row.
    """
    n = tape.n_slots
    op, out, a, b = tape.op, tape.out.astype(np.int64), tape.a.astype(np.int64), \
        tape.b.astype(np.int64)
    point = _is_const(tape) | (lo == hi)
    rows = _Rows([], [], [], [])
    one = np.ones(1)

    def code(name: str) -> NDArray[np.bool_]:
        return op == _CODE[name]

    m = code("add")
    rows.add([out[m], a[m], b[m]], [one, -one, -one], [one, -one, -one])
    m = code("sub")
    rows.add([out[m], a[m], b[m]], [one, -one, one], [one, -one, one])
    m = code("neg")
    rows.add([out[m], a[m]], [one, one], [one, one])
    bb = np.maximum(b, 0)
    for first in (True, False):  # mul(c, x) and mul(x, c)
        cst, var = (a, bb) if first else (bb, a)
        m = code("mul") & point[cst] & (first | ~point[a])
        rows.add([out[m], var[m]], [one, -hi[cst[m]]], [one, -lo[cst[m]]])
    m = code("div") & point[bb] & ((lo[bb] > 0) | (hi[bb] < 0))  # c out - x = 0
    rows.add([out[m], a[m]], [lo[bb[m]], -one], [hi[bb[m]], -one])
    if relax:
        from .relax import relaxation  # (relax imports this module)

        exact = (code("mul") & (point[a] | point[bb])) | m
        for blk in relaxation(tape, lo, hi, skip=exact):
            rows.add(blk.cols, blk.coefs, blk.coefs, blk.rhs)
    if not log_linear:
        return Extraction(rows.system(n), n, np.zeros(0, dtype=np.int64))

    sdef = (lo > 0) | (hi < 0)
    slots: list[NDArray] = []
    lrows: list[tuple] = []  # (cols_in_slot_space, is_log, coefs)

    def ok(*ss: NDArray) -> NDArray[np.bool_]:
        m = np.ones(op.size, dtype=bool)
        for s in ss:
            m &= sdef[s]
        return m

    for name in ("mul", "div"):
        m = code(name) & ok(out, a, bb) & (b >= 0)
        sgn = 1.0 if name == "mul" else -1.0
        lrows.append(([out[m], a[m], b[m]], [True] * 3, [1.0, -1.0, -sgn]))
    for name in ("neg", "abs"):
        m = code(name) & ok(out, a)
        lrows.append(([out[m], a[m]], [True] * 2, [1.0, -1.0]))
    m = code("sqr") & ok(out, a)
    lrows.append(([out[m], a[m]], [True] * 2, [1.0, -2.0]))
    m = code("pown") & ok(out, a) & (tape.param != 0)
    lrows.append(([out[m], a[m]], [True] * 2, [np.ones(m.sum()), -tape.param[m]]))
    m = code("sqrt") & ok(out, a) & (lo[a] > 0)
    lrows.append(([out[m], a[m]], [True] * 2, [1.0, -0.5]))
    m = code("pow") & ok(out, a) & (lo[a] > 0) & (b >= 0) & (lo[bb] == hi[bb]) \
        & np.isfinite(lo[bb])
    lrows.append(([out[m], a[m]], [True] * 2, [np.ones(m.sum()), -lo[bb[m]]]))
    m = code("exp") & ok(out)  # log(out) = a
    lrows.append(([out[m], a[m]], [True, False], [1.0, -1.0]))
    m = code("log") & ok(a) & (lo[a] > 0)  # out = log(a)
    lrows.append(([out[m], a[m]], [False, True], [1.0, -1.0]))
    for cols, is_log, _ in lrows:
        slots += [c for c, lg in zip(cols, is_log, strict=True) if lg]
    log_slots = np.unique(np.concatenate(slots)) if slots else np.zeros(0, dtype=np.int64)
    log_col = np.full(n, -1, dtype=np.int64)
    log_col[log_slots] = n + np.arange(log_slots.size)
    for cols, is_log, coefs in lrows:
        if cols[0].size == 0:
            continue
        cc = [log_col[c] if lg else c for c, lg in zip(cols, is_log, strict=True)]
        cf = [np.broadcast_to(np.asarray(k, dtype=np.float64), cols[0].shape) for k in coefs]
        rows.add(cc, cf, cf)
    return Extraction(rows.system(n + log_slots.size), n, log_slots)


# --- the contractor ------------------------------------------------------------------------

def _incidence(system: LinearSystem):
    """The row-column incidence as CSR index arrays: ``(row_ptr, row_cols, col_ptr,
    col_rows)``."""
    from scipy.sparse import csr_matrix

    inc = csr_matrix((np.ones(system.rows.size), (system.rows, system.cols)),
                     shape=(system.n_rows, system.n_cols))
    inc_t = inc.T.tocsr()
    return inc.indptr, inc.indices, inc_t.indptr, inc_t.indices


def _gather(ptr: NDArray, ind: NDArray, items: NDArray) -> NDArray:
    """The CSR entries of the rows ``items``, concatenated."""
    start, lens = ptr[items], ptr[items + 1] - ptr[items]
    total = int(lens.sum())
    first = np.cumsum(lens) - lens
    return ind[np.repeat(start - first, lens) + np.arange(total)]


def _local(system: LinearSystem, incidence, j: int, radius: int | None
           ) -> tuple[LinearSystem, NDArray[np.int64]]:
    """The rows within ``radius`` row-steps of column ``j`` (all rows reachable for None),
    on the columns they use: ``(sub-system, its columns' indices in system)``."""
    row_ptr, row_cols, col_ptr, col_rows = incidence
    cols = np.zeros(system.n_cols, dtype=bool)
    cols[j] = True
    rows = np.zeros(system.n_rows, dtype=bool)
    frontier = np.array([j], dtype=np.int64)
    step = 0
    while radius is None or step < radius:
        new_rows = _gather(col_ptr, col_rows, frontier)  # rows touching the new columns
        new_rows = np.unique(new_rows[~rows[new_rows]])
        if not new_rows.size:
            break
        rows[new_rows] = True
        new_cols = _gather(row_ptr, row_cols, new_rows)
        frontier = np.unique(new_cols[~cols[new_cols]])
        cols[frontier] = True
        step += 1
    sub = system.select(rows)
    used = np.nonzero(cols)[0]
    remap = np.full(system.n_cols, -1, dtype=np.int64)
    remap[used] = np.arange(used.size)
    return LinearSystem(sub.rows, remap[sub.cols], sub.a_lo, sub.a_hi, sub.b_lo, sub.b_hi,
                        used.size), used


def contract_columns(system: LinearSystem, lo: NDArray[np.float64], hi: NDArray[np.float64],
                     targets: NDArray[np.int64], radius: int | None = None
                     ) -> tuple[NDArray[np.float64], NDArray[np.float64], bool]:
    """Narrow the bounds of the ``targets`` columns by two LPs each (min and max).

    Bounds are tightened in turn (each LP sees the bounds the previous ones proved). With
    ``radius``, column ``j``'s LPs use only the rows within ``radius`` row-steps of it (a
    relaxation: still sound, smaller LPs). Returns ``(lo, hi, feasible)``; ``feasible`` is
    False only on a proof of infeasibility.
    """
    lo, hi = lo.copy(), hi.copy()
    used_cols = np.zeros(system.n_cols, dtype=bool)
    used_cols[system.cols[(system.a_lo != 0) | (system.a_hi != 0)]] = True
    whole = None if radius is not None else (_Solver(system), np.arange(system.n_cols))
    inc = None
    for j in targets:
        if not used_cols[j]:
            continue
        if whole is not None:
            solver, idx = whole
        else:
            if inc is None:
                inc = _incidence(system)
            sub, idx = _local(system, inc, int(j), radius)
            solver = _Solver(sub)
        k = int(np.searchsorted(idx, j))
        for sense in (1.0, -1.0):
            c = np.zeros(idx.size)
            c[k] = sense
            bound = solver.bound(c, lo[idx], hi[idx])
            if bound == np.inf:
                return lo, hi, False
            if sense > 0:
                lo[j] = max(lo[j], bound)
            else:
                hi[j] = min(hi[j], -bound)
            if lo[j] > hi[j]:  # both bounds rigorous: no solution
                return lo, hi, False
    return lo, hi, True


class CtcLinear(Contractor):
    """Contract a tape's slots by LPs over its linear and log-linear sub-networks.

    Parameters
    ----------
    tape : Tape
        The CSP; boxes are over its slots (shape ``(..., tape.n_slots)``).
    targets : array of int, optional
        The slots to contract (default: every slot in a linear or log-linear row). Each costs
        up to four LPs (its value and, where it is sign-definite, ``log|x|``).
    log_linear : bool
        Also use the log-linear rows of the multiplicative constraints (Jaulin 2002 eq. 19).
    radius : int, optional
        Solve each target's LPs on the rows within this many row-steps of it (default: the
        whole connected sub-network).
    relax : bool
        Also use a linear relaxation of the nonlinear nodes around the box
        (``ctc.relax.relaxation``; ``CtcPolytopeHull`` repeats it as the box shrinks).

    Notes
    -----
    The rows are extracted again at every call, since which constraints are log-linear
    depends on the signs in the box. Each box of a batch is contracted by its own LPs.
    """

    def __init__(self, tape: Tape, targets: NDArray[np.int64] | None = None,
                 log_linear: bool = True, radius: int | None = None,
                 relax: bool = False) -> None:
        _linprog()  # fail at construction, naming the extra, when SciPy is missing
        self.tape = tape
        self.n = tape.n_slots
        self.targets = None if targets is None else np.asarray(targets, dtype=np.int64)
        self.log_linear = log_linear
        self.radius = radius
        self.relax = relax

    def contract(self, x: Interval) -> Interval:
        if x.ndim > 1:  # each box of a batch by its own LPs
            flat = x.reshape(-1, self.n)
            parts = [self.contract(flat[i]) for i in range(flat.shape[0])]
            return Interval.trusted(np.stack([p.lo for p in parts]).reshape(x.shape),
                                 np.stack([p.hi for p in parts]).reshape(x.shape))
        lo, hi, ok = self._contract_box(x.lo, x.hi)
        return Interval.trusted(lo, hi) if ok else Interval.empty(x.shape)

    def _contract_box(self, lo: NDArray[np.float64], hi: NDArray[np.float64]
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64], bool]:
        """One box's slot bounds contracted: ``(lo, hi, feasible)``."""
        return contract_slots(self.tape, lo, hi, self.targets, self.log_linear, self.radius,
                              self.relax)


def contract_slots(tape: Tape, lo: NDArray[np.float64], hi: NDArray[np.float64],
                   targets: NDArray[np.int64] | None = None, log_linear: bool = True,
                   radius: int | None = None, relax: bool = False
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64], bool]:
    """``CtcLinear`` on the slot arrays of a tape: ``(lo, hi, feasible)`` (see there)."""
    lo, hi = np.asarray(lo, dtype=np.float64).copy(), np.asarray(hi, dtype=np.float64).copy()
    if np.isnan(lo).any() or (lo > hi).any():
        return lo, hi, False
    ext = extract(tape, lo, hi, log_linear, relax)
    if ext.system.n_rows == 0:
        return lo, hi, True
    clo, chi = ext.column_bounds(lo, hi)
    slots = np.arange(tape.n_slots) if targets is None else np.asarray(targets, dtype=np.int64)
    log_col = np.full(tape.n_slots, -1, dtype=np.int64)
    log_col[ext.log_slots] = tape.n_slots + np.arange(ext.log_slots.size)
    cols = np.concatenate([slots, log_col[slots][log_col[slots] >= 0]])
    clo, chi, ok = contract_columns(ext.system, clo, chi, cols, radius)
    if not ok:
        return lo, hi, False
    lo = np.maximum(lo, clo[:tape.n_slots])
    hi = np.minimum(hi, chi[:tape.n_slots])
    # back from log|x|: |x| in exp([L, U]), with the sign of the slot's domain
    s = ext.log_slots
    m = exp(Interval.trusted(clo[tape.n_slots:], chi[tape.n_slots:]))
    neg = hi[s] < 0
    lo[s] = np.where(neg, np.maximum(lo[s], -m.hi), np.maximum(lo[s], m.lo))
    hi[s] = np.where(neg, np.minimum(hi[s], -m.lo), np.minimum(hi[s], m.hi))
    if (lo > hi).any():
        return lo, hi, False
    return lo, hi, True
