"""The pool robot of Jaulin's robust set-membership observer: the compiled robust observer
(:mod:`boundest.scenarios.pool_observer`) over the sonar pings, offline or online.

- prediction: the interval Euler step of ``f(X, u) = (v cos theta, v sin theta, u2 - u1,
  u1 + u2 - v)`` with the input box of the step (the exact model of these data);
- observation: the ping's first-hit constraint ``d = g(x, y, theta + alpha)``
  (:func:`boundest.ctc.raycast.raycast_box` on the pool map), which contracts ``x``, ``y``,
  ``theta``;
- at most ``q`` outliers among the last ``m`` pings (one sonar revolution is 80 pings);
- ``sweeps`` rounds of smoothing inside the window per ping (0: the plain recursive observer,
  the fastest; each round contracts the window's past states with the later pings and brings
  them forward again).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..ctc.raycast import pack_tapes
from ..interval import Interval
from . import pool_observer as po
from .pool_data import PoolData, binomial_bound

__all__ = ["DEFAULT_PASSES", "DEFAULT_SLICES", "DEFAULT_SWEEPS", "PoolObserver", "PoolResult",
           "check_options", "restart_box", "solve_pool", "window_probabilities"]

#: Smoothing rounds per ping by default (see the benchmark: the widths it buys, its time).
DEFAULT_SWEEPS = 1
#: Passes of the ray-cast contractor per ping contraction.
DEFAULT_PASSES = 1
#: Most heading slices kept with ``paving_heading``.
DEFAULT_SLICES = 32


def _dt(dt: float) -> tuple[float, float]:
    return float(np.nextafter(dt, -np.inf)), float(np.nextafter(dt, np.inf))


def restart_box(data: PoolData) -> Interval:
    """A box that holds the state at any time: the pool's rectangle, any heading, and
    ``|v| <= max(|v(0)|, max |u1 + u2|)`` (``v`` relaxes towards ``u1 + u2``)."""
    seg = data.map.segments.reshape(-1, 2)
    u = data.inputs
    vmax = max(float(np.max(np.abs(data.x0.lo[3]))), float(np.max(np.abs(data.x0.hi[3]))),
               float(np.max(np.abs(u.lo[..., 0] + u.lo[..., 1]))),
               float(np.max(np.abs(u.hi[..., 0] + u.hi[..., 1]))))
    vmax *= 1.0 + 2.0**-40  # the data's float64 Euler steps may round a few ulps above
    return Interval([seg[:, 0].min(), seg[:, 1].min(), -np.inf, -vmax],
                    [seg[:, 0].max(), seg[:, 1].max(), np.inf, vmax])


def window_probabilities(n: int, m: int, q: int, p: float) -> NDArray[np.float64]:
    """``P(at most q outliers among the min(k + 1, m) pings of the window at k)``, k < n."""
    bound = {w: binomial_bound(w, q, p) for w in range(1, min(n, m) + 1)}
    return np.array([bound[min(k + 1, m)] for k in range(n)])


def _eps(paving: float | None, heading: float | None, slices: int, carry: bool) -> np.ndarray:
    """The sides of the paving's cells in ``(x, y)`` and the widest heading slice
    (``inf``: not cut)."""
    for name, v in (("paving", paving), ("paving_heading", heading)):
        if v is not None and not (np.isfinite(v) and v > 0):
            raise ValueError(f"the {name} precision must be a positive number, got {v!r}")
    if isinstance(slices, bool) or not isinstance(slices, (int, np.integer)) or slices < 1:
        raise ValueError(f"heading_slices must be a whole number >= 1, got {slices!r}")
    if heading is not None and not carry:
        raise ValueError("heading slices (--paving-heading) carry their own past: they need "
                         "the recursive observer, not the pure window observer "
                         "(--window-only, carry=False)")
    xy = np.inf if paving is None else float(paving)
    return np.array([xy, xy, np.inf if heading is None else float(heading)])


def check_options(q: int = 8, m: int = 80, sweeps: int = DEFAULT_SWEEPS,
                  passes: int = DEFAULT_PASSES, carry: bool = True, paving: float | None = None,
                  paving_heading: float | None = None, heading_slices: int | None = None
                  ) -> None:
    """Raise the ``ValueError`` that :func:`solve_pool` would raise for these options
    (``heading_slices`` None: the default), without running anything."""
    _check(q, m, sweeps, passes, carry)
    _eps(paving, paving_heading, DEFAULT_SLICES if heading_slices is None else heading_slices,
         carry)


def _slices(eps: np.ndarray, slices: int) -> int:
    return int(slices) if eps[2] < np.inf else 1


def _check(q: int, m: int, sweeps: int, passes: int, carry: bool) -> np.ndarray:
    if m < 1 or q < 0 or sweeps < 0 or passes < 1:
        raise ValueError(f"need m >= 1, q >= 0, sweeps >= 0 and passes >= 1, got m={m}, "
                         f"q={q}, sweeps={sweeps}, passes={passes}")
    return np.array([m, q, sweeps, passes, int(bool(carry))], dtype=np.int64)


class PoolObserver:
    """The online robust observer of one pool mission: ``update(u, alpha, d)`` per ping.

    Parameters
    ----------
    data : PoolData
        What the observer knows before the first ping: the map, ``dt``, ``x0`` and the
        bounds of the restart box (its pings and inputs are not read).
    q, m : int
        Outliers allowed among the last ``m`` pings.
    sweeps : int
        Smoothing rounds inside the window per ping (0: the plain recursive observer).
    passes : int
        Passes of the ray-cast contractor per contraction.
    carry : bool
        True: the recursive observer (its previous set carried forward); False: the pure
        window observer (each set from the open-loop prior and the window's pings alone).
    paving : float, optional
        Pave ``(x, y)`` of each set into cells of this side [m] and keep the hull of the
        cells whose window is consistent (tighter, slower); None: boxes only.
    paving_heading : float, optional
        Keep the set as a union of heading slices, each with its own window: a slice whose
        heading is wider than this [rad] is cut in two before the next ping, a slice that
        comes out empty is dropped (what pays most: on a thin heading slice the pings pin the
        position, and each slice keeps its past states thin too); None: one box.
    heading_slices : int
        Most slices kept (beyond it, neighbours are merged); with ``paving_heading``.

    Examples
    --------
    >>> from boundest.scenarios.pool_data import load_pool
    >>> data = load_pool()
    >>> obs = PoolObserver(data, q=8, m=80)
    >>> box, rejected, empty = obs.update(None, float(data.alpha[0]), data.ranges[0])
    >>> bool(data.x0.contains(box.mid()).all()), rejected, empty
    (True, 0, False)
    """

    def __init__(self, data: PoolData, q: int = 8, m: int = 80, sweeps: int = DEFAULT_SWEEPS,
                 passes: int = DEFAULT_PASSES, carry: bool = True,
                 paving: float | None = None, paving_heading: float | None = None,
                 heading_slices: int = DEFAULT_SLICES) -> None:
        self.par = _check(q, m, sweeps, passes, carry)
        self.eps = _eps(paving, paving_heading, heading_slices, carry)
        self.q, self.m = int(q), int(m)
        self.tapes = pack_tapes(data.map)
        self.x0 = data.x0
        self.restart = restart_box(data)
        self.h = _dt(data.dt)
        self.bank = po.make_bank(self.m, _slices(self.eps, heading_slices))
        self.work = po.make_work(self.m, self.tapes.lo0.size)
        self.cells = np.empty((0, 4)), np.empty((0, 4))
        self.paving = (paving, paving_heading) if np.isfinite(self.eps).any() else None
        #: cells of the paving (or heading slices) kept at the last update (0: neither)
        self.cells_kept = 0
        self.k = 0

    def update(self, u: Interval | None, alpha: float, d: Interval
               ) -> tuple[Interval, int, bool]:
        """Advance to the next ping: ``u`` the input box ``(u1, u2)`` applied since the
        previous ping (None at the first), ``alpha`` the beam angle relative to the robot,
        ``d`` the range interval. Returns ``(X_k, rejected, empty)``: the state box, the pings
        of the window inconsistent with it, and whether the set came out empty (then the
        observer restarted from the window alone)."""
        if u is None:
            if self.k:
                raise ValueError(f"update {self.k} needs the input box applied since the "
                                 "previous ping")
            ul = uh = np.zeros(2)
        else:
            ul = np.ascontiguousarray(u.lo, dtype=np.float64).reshape(2)
            uh = np.ascontiguousarray(u.hi, dtype=np.float64).reshape(2)
        xl, xh = np.empty(4), np.empty(4)
        rej, empty, self.cells_kept = po.bank_update(
            self.k, ul, uh, float(alpha), float(d.lo), float(d.hi), self.par, self.eps,
            self.x0.lo, self.x0.hi, self.restart.lo, self.restart.hi, self.h[0], self.h[1],
            self.tapes, self.bank, xl, xh, self.work, self.cells[0], self.cells[1])
        self.k += 1
        return Interval.trusted(xl, xh), int(rej), bool(empty)


@dataclass(repr=False)
class PoolResult:
    """The observer's sets over a mission.

    Attributes
    ----------
    boxes : Interval, shape (n, 4) or (M, n, 4)
        ``X_k`` for every ping.
    rejected : ndarray of int, shape (n,) or (M, n)
        Pings of the window inconsistent with ``X_k``.
    empty : ndarray of bool
        Steps where the set came out empty (more than q outliers in the window): the observer
        restarted there from the window alone.
    window_probability : ndarray, shape (n,)
        ``P(at most q outliers among the pings of the window at k)``: the probability that one
        window is fine, the guarantee of the pure window observer; the recursive set at ``k``
        needs every window since the last restart to be (:mod:`.pool_observer`).
    cells : ndarray of int, shape (n,) or (M, n)
        Heading slices kept at each step with ``paving_heading``; otherwise cells of the
        ``(x, y)`` paving (0 without either).
    paving : Interval, shape (n, C, 4) or (M, n, C, 4), optional
        The first ``C`` kept slices (or cells) of each step (NaN rows beyond ``cells``).
    eps : (float or None, float or None), optional
        The paving's cell sides in ``(x, y)`` [m] and the widest heading slice [rad] (None:
        not cut).
    """

    boxes: Interval
    rejected: NDArray[np.intp]
    empty: NDArray[np.bool_]
    window_probability: NDArray[np.float64]
    q: int
    m: int
    time_s: float
    cells: NDArray[np.intp]
    paving: Interval | None = None
    eps: tuple[float | None, float | None] | None = None

    def centre(self) -> NDArray[np.float64]:
        """The Chebyshev centre of each box (its midpoint; NaN where empty)."""
        return self.boxes.mid()

    def widths(self) -> NDArray[np.float64]:
        return self.boxes.width()

    def __repr__(self) -> str:
        w = np.nanmean(self.widths()[..., :2], axis=tuple(range(self.widths().ndim - 1)))
        return (f"PoolResult(steps={self.boxes.shape[-2]}, q={self.q}, m={self.m}, "
                f"mean_width_xy=({w[0]:.3g}, {w[1]:.3g}), empty_steps="
                f"{int(np.count_nonzero(self.empty))}, time_s={self.time_s:.3g})")


def solve_pool(data: PoolData, q: int = 8, m: int = 80, sweeps: int = DEFAULT_SWEEPS,
               passes: int = DEFAULT_PASSES, carry: bool = True, paving: float | None = None,
               paving_heading: float | None = None, heading_slices: int = DEFAULT_SLICES,
               keep_cells: int = 256) -> PoolResult:
    """Run the observer over the whole mission (or every mission of a batch) offline: the
    same updates as :class:`PoolObserver` (parameters there), all in one compiled call.
    With ``paving`` or ``paving_heading``, the first ``keep_cells`` kept cells (or slices)
    of each step are returned."""
    par = _check(q, m, sweeps, passes, carry)
    eps = _eps(paving, paving_heading, heading_slices, carry)
    paved = bool(np.isfinite(eps).any())
    n_cells = keep_cells if paved else 0
    start = time.perf_counter()
    tapes = pack_tapes(data.map)
    restart = restart_box(data)
    batch = data.n_missions is not None
    n_m = data.n_missions if batch else 1
    ul = np.ascontiguousarray(np.broadcast_to(data.inputs.lo, (n_m, data.n, 2)))
    uh = np.ascontiguousarray(np.broadcast_to(data.inputs.hi, (n_m, data.n, 2)))
    dl = np.ascontiguousarray(data.ranges.lo, dtype=np.float64).reshape(n_m, data.n)
    dh = np.ascontiguousarray(data.ranges.hi, dtype=np.float64).reshape(n_m, data.n)
    xl, xh = np.empty((n_m, data.n, 4)), np.empty((n_m, data.n, 4))
    rejected = np.zeros((n_m, data.n), dtype=np.int64)
    empty = np.zeros((n_m, data.n), dtype=np.bool_)
    cells = np.zeros((n_m, data.n), dtype=np.int64)
    cl = np.full((n_m, data.n, n_cells, 4), np.nan)
    ch = np.full((n_m, data.n, n_cells, 4), np.nan)
    h = _dt(data.dt)
    alpha = np.ascontiguousarray(data.alpha, dtype=np.float64)
    bank, work = po.make_bank(m, _slices(eps, heading_slices)), po.make_work(m, tapes.lo0.size)
    args = (par, eps, data.x0.lo, data.x0.hi, restart.lo, restart.hi, h[0], h[1], tapes, bank,
            work)
    # no mission: compiles (first run) or loads the kernel, outside the timed part
    po.run_missions(ul[:0], uh[:0], alpha, dl[:0], dh[:0], *args, xl[:0], xh[:0], rejected[:0],
                    empty[:0], cells[:0], cl[:0], ch[:0])
    start = time.perf_counter()
    po.run_missions(ul, uh, alpha, dl, dh, *args, xl, xh, rejected, empty, cells, cl, ch)
    elapsed = time.perf_counter() - start
    probs = window_probabilities(data.n, m, q, data.p_outlier)
    if not batch:
        xl, xh, rejected, empty, cells, cl, ch = (xl[0], xh[0], rejected[0], empty[0],
                                                  cells[0], cl[0], ch[0])
    return PoolResult(Interval.trusted(xl, xh), rejected, empty, probs, q, m, elapsed, cells,
                      Interval.trusted(cl, ch) if paved else None,
                      (paving, paving_heading) if paved else None)
