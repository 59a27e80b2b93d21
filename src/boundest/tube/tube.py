"""Sliced tubes: enclosures of trajectories over a time grid, held as interval arrays.

A tube over ``[t0, tf]`` has gate times ``t[0] < ... < t[n]``, one slice enclosure per time
interval ``[t[i], t[i+1]]`` and one gate enclosure per gate time. A tube vector is the same with
a trailing dimension ``d`` (``slices`` of shape ``(n, d)``).

Two kinds of tube say what a slice encloses:

- **continuous** (the default): a trajectory ``x(.)`` belongs to the tube when
  ``x(s) ∈ slices[i]`` for every ``s`` in the *closed* ``[t[i], t[i+1]]`` and
  ``x(t[i]) ∈ gates[i]``, so a gate lies in both neighbouring slices. This holds for every
  continuous trajectory (states, anything with a derivative).
- **with jumps** (``continuous=False``): ``x(s) ∈ slices[i]`` on the *open* ``]t[i], t[i+1][``
  only, and the gates are independent values: neighbouring slices need not overlap. This is
  the tube of a piecewise-continuous signal: a derivative, a bang-bang input, sensor boxes held
  over each sample (:meth:`Tube.piecewise_constant`). Its default gates are the hull of the
  neighbouring slices (the value at a jump is the left or the right one).

A tube with one empty slice or gate is empty as a whole (no trajectory can cross it); every
operation keeps it wholly empty (all bounds NaN).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..interval import Interval, as_interval, hull, intersect
from .integral import integral_bounds, primitive_gates

__all__ = ["Tube", "TubeVector", "time_grid"]


def time_grid(t0: float, tf: float, dt_or_n: float | int) -> NDArray[np.float64]:
    """Gate times from ``t0`` to ``tf``: ``n`` equal slices for an ``int``, else steps of
    ``dt`` (the last slice is shorter when ``dt`` does not divide the domain)."""
    t0, tf = float(t0), float(tf)
    if not (np.isfinite(t0) and np.isfinite(tf) and t0 < tf):
        raise ValueError(f"tube domain must be finite with t0 < tf, got [{t0}, {tf}]")
    if isinstance(dt_or_n, (int, np.integer)) and not isinstance(dt_or_n, bool):
        if dt_or_n < 1:
            raise ValueError(f"number of slices must be >= 1, got {dt_or_n}")
        t = np.linspace(t0, tf, int(dt_or_n) + 1)
    else:
        dt = float(dt_or_n)
        if not (np.isfinite(dt) and dt > 0):
            raise ValueError(f"time step must be a positive float, got {dt_or_n!r}")
        n = int(np.ceil((tf - t0) / dt * (1 - 1e-12)))
        t = t0 + dt * np.arange(n + 1, dtype=np.float64)
        t = t[t < tf]
        t = np.append(t, tf)
    t[0], t[-1] = t0, tf
    if np.any(np.diff(t) <= 0):
        raise ValueError(f"time step {dt_or_n!r} too small for the domain [{t0}, {tf}]")
    return t


def _check_times(t: ArrayLike, what: str = "gate times") -> NDArray[np.float64]:
    t = np.array(t, dtype=np.float64)
    if t.ndim != 1 or t.size < 2:
        raise ValueError(f"{what} must be a 1-D array of at least 2 times, got shape {t.shape}")
    bad = ~np.isfinite(t)
    if bad.any():
        raise ValueError(f"{what}: non-finite time {t[bad][0]} at index {np.argmax(bad)}")
    step = np.diff(t) <= 0
    if step.any():
        k = int(np.argmax(step))
        raise ValueError(f"{what} must be strictly increasing: t[{k}] = {t[k]!r}, "
                         f"t[{k + 1}] = {t[k + 1]!r}")
    return t


class Tube:
    """A tube (or tube vector) over a sliced time domain.

    Parameters
    ----------
    t : array_like, shape (n+1,)
        Gate times, strictly increasing.
    slices : Interval, shape (n,) or (n, d)
        Enclosure over each slice ``[t[i], t[i+1]]``.
    gates : Interval, shape (n+1,) or (n+1, d), optional
        Enclosure at each gate time; default: the intersection of the neighbouring slices
        (a continuous trajectory's value at a gate lies in both), or their hull for a tube with
        jumps.
    continuous : bool
        ``True`` (default): the trajectories are continuous, each slice encloses them over its
        closed time interval, and two neighbouring slices must overlap (else ``ValueError``:
        no continuous trajectory crosses their gate). ``False``: the trajectories may jump at
        the gates (see the module docstring); the slices enclose them on open time intervals.

    Examples
    --------
    >>> x = Tube.constant(0, 1, 4, Interval(-1, 1))
    >>> x.n_slices, x.dim
    (4, 1)
    >>> x(0.5)
    Interval([-1.0, 1.0])
    """

    __slots__ = ("continuous", "gates", "slices", "t")
    __array_ufunc__ = None
    __hash__ = None  # type: ignore[assignment]

    t: NDArray[np.float64]
    slices: Interval
    gates: Interval
    continuous: bool

    def __init__(self, t: ArrayLike, slices: Interval, gates: Interval | None = None,
                 continuous: bool = True) -> None:
        t = _check_times(t)
        slices = as_interval(slices)
        n = t.size - 1
        if slices.ndim not in (1, 2) or slices.shape[0] != n:
            raise ValueError(f"slices must have shape ({n},) or ({n}, d) for {n + 1} gate "
                             f"times, got {slices.shape}")
        if continuous:
            _check_overlap(t, slices)
        if gates is None:
            gates = _default_gates(slices) if continuous else _hull_gates(slices)
        else:
            gates = as_interval(gates)
            if gates.shape != (n + 1, *slices.shape[1:]):
                raise ValueError(f"gates must have shape {(n + 1, *slices.shape[1:])}, got "
                                 f"{gates.shape}")
            if continuous:
                gates = intersect(gates, _default_gates(slices))
        self.t = t
        self.continuous = bool(continuous)
        self.slices = Interval.trusted(np.array(slices.lo, dtype=np.float64),
                                    np.array(slices.hi, dtype=np.float64))
        self.gates = Interval.trusted(np.array(gates.lo, dtype=np.float64),
                                   np.array(gates.hi, dtype=np.float64))
        self._normalize_empty()

    @classmethod
    def _wrap(cls, t: NDArray, slices: Interval, gates: Interval,
              continuous: bool = True) -> Tube:
        """Wrap arrays without checks or copies (they must satisfy the invariants)."""
        obj = object.__new__(cls)
        obj.t, obj.slices, obj.gates, obj.continuous = t, slices, gates, continuous
        return obj

    # -- constructors -----------------------------------------------------------------------
    @classmethod
    def constant(cls, t0: float, tf: float, dt_or_n: float | int,
                 value: Interval | ArrayLike | None = None) -> Tube:
        """The tube equal to ``value`` (an interval, or a box for a tube vector; default: the
        entire real line) over ``[t0, tf]`` sliced by ``dt`` (float) or into ``n`` (int)."""
        t = time_grid(t0, tf, dt_or_n)
        v = Interval.entire() if value is None else as_interval(value)
        if v.ndim > 1:
            raise ValueError(f"a constant tube takes an interval or a box, got shape {v.shape}")
        n = t.size - 1
        slices = Interval.trusted(np.broadcast_to(v.lo, (n, *v.shape)).copy(),
                               np.broadcast_to(v.hi, (n, *v.shape)).copy())
        gates = Interval.trusted(np.broadcast_to(v.lo, (n + 1, *v.shape)).copy(),
                              np.broadcast_to(v.hi, (n + 1, *v.shape)).copy())
        return cls._wrap(t, slices, gates)._normalize_empty()

    @classmethod
    def piecewise_constant(cls, t: ArrayLike, values: Interval | ArrayLike,
                           gates: Interval | None = None) -> Tube:
        """A tube with jumps from per-slice boxes: the signal lies in ``values[i]`` on
        ``]t[i], t[i+1][`` and may jump at every gate (sampled data held over each sample, a
        piecewise-constant or bang-bang input, the derivative of a state).

        Parameters
        ----------
        t : array_like, shape (n+1,)
            Gate times, strictly increasing (for held samples: the sample times and the end).
        values : Interval or array_like, shape (n,) or (n, d)
            The box of each slice (an array gives degenerate boxes). Neighbouring boxes need
            not overlap.
        gates : Interval, shape (n+1,) or (n+1, d), optional
            The values at the gate times; default: the hull of the neighbouring slices.

        Examples
        --------
        >>> v = Tube.piecewise_constant([0, 1, 2], Interval([1, -1], [1, -1]))
        >>> v.continuous, v(0.5), v(1.5), v(1.0)
        (False, Interval([1.0, 1.0]), Interval([-1.0, -1.0]), Interval([-1.0, 1.0]))
        """
        return cls(t, as_interval(values), gates, continuous=False)

    @classmethod
    def from_function(cls, t0: float, tf: float, dt_or_n: float | int,
                      f: Callable[[Interval], Interval]) -> Tube:
        """The tube ``f([t])`` where ``f`` is an interval extension of a function of time,
        vectorised over an ``Interval`` of time intervals of shape ``(m,)`` and returning shape
        ``(m,)`` or ``(m, d)``: slices are ``f`` over each slice's time interval, gates ``f`` at
        each gate time."""
        t = time_grid(t0, tf, dt_or_n)
        return cls.from_function_on(t, f)

    @classmethod
    def from_function_on(cls, t: ArrayLike, f: Callable[[Interval], Interval]) -> Tube:
        """As :meth:`from_function` on given gate times ``t``."""
        t = _check_times(t)
        slices = as_interval(f(Interval.trusted(t[:-1], t[1:])))
        gates = as_interval(f(Interval.trusted(t, t)))
        n = t.size - 1
        if slices.shape[:1] != (n,) or gates.shape != (n + 1, *slices.shape[1:]):
            raise ValueError(f"f must map an Interval of shape (m,) to shape (m,) or (m, d); "
                             f"got {slices.shape} for m = {n}")
        return cls(t, slices, gates)

    @classmethod
    def from_samples(cls, t_samples: ArrayLike, values: ArrayLike,
                     inflation: ArrayLike = 0.0) -> Tube:
        """A tube on the sample times from sampled values ``(m,)`` or ``(m, d)``.

        The gates are the samples widened by ``inflation`` (>= 0, a scalar or one per
        component); each slice is the hull of its two end samples widened by ``inflation``,
        which encloses the trajectory if it deviates by at most ``inflation`` from its linear
        interpolation (the modelling assumption behind the inflation).
        """
        t = _check_times(t_samples, "sample times")
        y = np.array(values, dtype=np.float64)
        if y.ndim not in (1, 2) or y.shape[0] != t.size:
            raise ValueError(f"values must have shape ({t.size},) or ({t.size}, d), "
                             f"got {y.shape}")
        bad = ~np.isfinite(y)
        if bad.any():
            k = tuple(int(i) for i in np.argwhere(bad)[0])
            raise ValueError(f"sample value at index {k} is not finite: {y[k]}")
        r = np.asarray(inflation, dtype=np.float64)
        if np.any(~np.isfinite(r)) or np.any(r < 0):
            raise ValueError(f"inflation must be finite and non-negative, got {inflation!r}")
        gates = Interval.trusted(y, y).inflate(r)
        slices = hull(gates[:-1], gates[1:])
        return cls(t, slices, gates)

    # -- shape and domain ---------------------------------------------------------------------
    @property
    def dim(self) -> int:
        """Number of components (1 for a scalar tube)."""
        return 1 if self.slices.ndim == 1 else self.slices.shape[1]

    @property
    def is_vector(self) -> bool:
        return self.slices.ndim == 2

    @property
    def n_slices(self) -> int:
        return self.t.size - 1

    def __len__(self) -> int:
        return self.n_slices

    @property
    def domain(self) -> tuple[float, float]:
        return float(self.t[0]), float(self.t[-1])

    @property
    def dt(self) -> NDArray[np.float64]:
        """Slice durations ``t[i+1] - t[i]`` (rounded to nearest)."""
        return np.diff(self.t)

    def __repr__(self) -> str:
        kind = f"TubeVector(dim={self.dim}, " if self.is_vector else "Tube("
        t0, tf = self.domain
        jumps = "" if self.continuous else ", continuous=False"
        return (f"{kind}domain=[{t0!r}, {tf!r}], slices={self.n_slices}, "
                f"max_thickness={self.max_thickness()!r}{jumps})")

    def copy(self) -> Tube:
        return Tube._wrap(self.t.copy(), self.slices.copy(), self.gates.copy(), self.continuous)

    def __getitem__(self, i: int) -> Tube:
        """Component ``i`` of a tube vector, as a scalar tube sharing its storage (a view:
        contracting it contracts the vector)."""
        if not self.is_vector:
            raise TypeError("only a tube vector has components")
        return Tube._wrap(self.t, self.slices[:, i], self.gates[:, i], self.continuous)

    def make_continuous(self) -> Tube:
        """Declare the trajectories continuous (a constraint such as ``x' = v`` proves it):
        the gates are intersected with both neighbouring slices, in place. Returns ``self``."""
        if not self.continuous:
            self.continuous = True
            g = intersect(self.gates, _default_gates(self.slices))
            self.gates.lo[...], self.gates.hi[...] = g.lo, g.hi
            self._normalize_empty()
        return self

    @staticmethod
    def stack(tubes: list[Tube]) -> Tube:
        """A tube vector from scalar tubes on the same gate times (copies)."""
        if not tubes:
            raise ValueError("stack needs at least one tube")
        t = tubes[0].t
        for k, y in enumerate(tubes):
            if y.is_vector or not _same_grid(t, y.t):
                raise ValueError(f"stack: tube {k} is not a scalar tube on the same gate times")
        s = Interval.trusted(np.stack([y.slices.lo for y in tubes], axis=1),
                          np.stack([y.slices.hi for y in tubes], axis=1))
        g = Interval.trusted(np.stack([y.gates.lo for y in tubes], axis=1),
                          np.stack([y.gates.hi for y in tubes], axis=1))
        cont = all(y.continuous for y in tubes)
        return Tube._wrap(t.copy(), s, g, cont)._normalize_empty()

    # -- emptiness -----------------------------------------------------------------------------
    def is_empty(self) -> bool:
        """Whether no trajectory lies in the tube."""
        return bool(np.isnan(self.slices.lo).any() or np.isnan(self.gates.lo).any())

    def set_empty(self) -> None:
        """Make the tube empty in place (all bounds NaN)."""
        for a in (self.slices.lo, self.slices.hi, self.gates.lo, self.gates.hi):
            a[...] = np.nan

    def _normalize_empty(self) -> Tube:
        if self.is_empty():
            self.set_empty()
        return self

    # -- evaluation ----------------------------------------------------------------------------
    def _check_in_domain(self, lo: NDArray, hi: NDArray) -> None:
        t0, tf = self.domain
        bad = (lo < t0) | (hi > tf) | ~np.isfinite(lo) | ~np.isfinite(hi)
        if bad.any():
            k = int(np.argmax(bad.ravel()))
            raise ValueError(f"time [{lo.ravel()[k]!r}, {hi.ravel()[k]!r}] is outside the tube "
                             f"domain [{t0!r}, {tf!r}]")

    def _eval_points(self, s: NDArray) -> Interval:
        """Values at times ``s`` (1-D): the gate at a gate time, else the slice."""
        i = np.searchsorted(self.t, s, side="right") - 1
        i = np.clip(i, 0, self.n_slices - 1)
        at_gate = self.t[i] == s
        at_end = s == self.t[-1]
        gi = np.where(at_end, self.n_slices, i)
        use_gate = at_gate | at_end
        lo = np.where(_col(use_gate, self), self.gates.lo[gi], self.slices.lo[i])
        hi = np.where(_col(use_gate, self), self.gates.hi[gi], self.slices.hi[i])
        return Interval.trusted(lo, hi)

    def _eval_interval(self, a: float, b: float) -> Interval:
        """Hull of the slices meeting ``]a, b[`` and of the gates in ``[a, b]``."""
        if a == b:
            return self._eval_points(np.array([a]))[0]
        i0, i1 = self.slice_range(a, b)
        g0 = np.searchsorted(self.t, a, side="left")
        g1 = np.searchsorted(self.t, b, side="right")
        lo = np.fmin(np.min(self.slices.lo[i0:i1], axis=0), np.min(self.gates.lo[g0:g1], axis=0,
                                                                   initial=np.inf))
        hi = np.fmax(np.max(self.slices.hi[i0:i1], axis=0), np.max(self.gates.hi[g0:g1], axis=0,
                                                                   initial=-np.inf))
        if self.is_empty():
            lo, hi = lo * np.nan, hi * np.nan
        return Interval.trusted(lo, hi)

    def slice_range(self, a: float, b: float) -> tuple[int, int]:
        """Indices ``i0, i1`` such that slices ``i0 .. i1-1`` are those whose open time
        interval meets ``[a, b]`` (``a < b``), or the one slice holding ``a`` (``a == b``)."""
        i0 = int(np.searchsorted(self.t, a, side="right")) - 1
        i1 = int(np.searchsorted(self.t, b, side="left"))
        i0 = min(max(i0, 0), self.n_slices - 1)
        return i0, max(min(i1, self.n_slices), i0 + 1)

    def __call__(self, t: float | ArrayLike | Interval) -> Interval:
        """``[y]([t])``: the values the tube allows at time ``t`` (a float, an array of times,
        or an ``Interval`` of time intervals: the hull over each)."""
        if isinstance(t, Interval):
            if t.ndim == 0:
                if t.is_empty():
                    return Interval.empty(self.slices.shape[1:])
                self._check_in_domain(t.lo, t.hi)
                return self._eval_interval(float(t.lo), float(t.hi))
            if np.any(t.is_empty()):
                raise ValueError("cannot evaluate a tube over an empty time interval in an array")
            self._check_in_domain(t.lo, t.hi)
            parts = [self._eval_interval(float(a), float(b))
                     for a, b in zip(t.lo.ravel(), t.hi.ravel(), strict=True)]
            lo = np.array([p.lo for p in parts]).reshape(*t.shape, *self.slices.shape[1:])
            hi = np.array([p.hi for p in parts]).reshape(*t.shape, *self.slices.shape[1:])
            return Interval.trusted(lo, hi)
        s = np.asarray(t, dtype=np.float64)
        self._check_in_domain(s, s)
        out = self._eval_points(s.ravel())
        return out.reshape((*s.shape, *self.slices.shape[1:]))

    def contains(self, t_samples: ArrayLike, y_samples: ArrayLike) -> bool:
        """Whether the sampled trajectory ``y(t_k)`` lies in the tube at every sample (a sample at
        a gate time is checked against the gate, and for a continuous tube also against both
        neighbouring slices)."""
        s = np.asarray(t_samples, dtype=np.float64).ravel()
        y = np.asarray(y_samples, dtype=np.float64).reshape(s.size, *self.slices.shape[1:])
        self._check_in_domain(s, s)
        if self.is_empty():
            return False
        ok = self._eval_points(s).contains(y)
        if self.continuous:
            i = np.clip(np.searchsorted(self.t, s, side="right") - 1, 0, self.n_slices - 1)
            j = np.clip(np.searchsorted(self.t, s, side="left") - 1, 0, self.n_slices - 1)
            ok &= self.slices[i].contains(y) & self.slices[j].contains(y)
        return bool(np.all(ok))

    def inverse(self, z: Interval | ArrayLike, hull: bool = False,
                within: Interval | None = None) -> list[Interval] | Interval:
        """``[y]^{-1}([z])``: the times at which the tube may take a value in ``[z]`` (Rohou et
        al. 2018
        Fig. 5), as a list of disjoint time intervals in increasing order (or their hull).

        A run of consecutive slices meeting ``[z]`` gives one interval, split where the gate
        between two slices misses ``[z]``; a gate alone meeting ``[z]`` gives a degenerate
        interval. ``within`` restricts the search to a time interval. Scalar tubes only.
        """
        if self.is_vector:
            raise ValueError("inverse needs a scalar tube; take a component: y[i].inverse(z)")
        z = as_interval(z)
        if z.ndim != 0:
            raise ValueError(f"inverse takes a scalar interval, got shape {z.shape}")
        empty: list[Interval] = []
        if self.is_empty() or z.is_empty():
            return Interval.empty() if hull else empty
        a, b = self.domain
        if within is not None:
            if within.is_empty():
                return Interval.empty() if hull else empty
            a, b = max(a, float(within.lo)), min(b, float(within.hi))
            if a > b:
                return Interval.empty() if hull else empty
        if a == b:
            hit = self._eval_points(np.array([a]))[0].intersects(z)
            pt = Interval(a, a)
            return (pt if hit else Interval.empty()) if hull else ([pt] if hit else empty)
        i0, i1 = self.slice_range(a, b)
        ms = np.asarray(self.slices[i0:i1].intersects(z))
        mg = np.asarray(self.gates[i0:i1 + 1].intersects(z))
        lo_t = np.maximum(self.t[i0:i1], a)
        hi_t = np.minimum(self.t[i0 + 1:i1 + 1], b)
        gt = np.clip(self.t[i0:i1 + 1], a, b)
        # interval pieces: each hit slice, plus each hit gate (degenerate); merge overlaps
        starts = np.concatenate([lo_t[ms], gt[mg]])
        ends = np.concatenate([hi_t[ms], gt[mg]])
        if starts.size == 0:
            return Interval.empty() if hull else empty
        if hull:
            return Interval(starts.min(), ends.max())
        order = np.lexsort((ends, starts))
        starts, ends = starts[order], ends[order]
        # a new piece starts where its start exceeds every earlier end, or where it touches
        # only at a gate that misses [z]
        run_end = np.maximum.accumulate(ends)
        gap = starts[1:] > run_end[:-1]
        touch = starts[1:] == run_end[:-1]
        g_at = np.searchsorted(self.t, starts[1:])
        g_at = np.clip(g_at, 0, self.n_slices)
        gate_miss = ~np.asarray(self.gates[g_at].intersects(z))
        new = np.concatenate([[True], gap | (touch & gate_miss & (self.t[g_at] == starts[1:]))])
        idx = np.flatnonzero(new)
        piece_end = np.maximum.reduceat(ends, idx)
        return [Interval(starts[k], e) for k, e in zip(idx, piece_end, strict=True)]

    # -- integrals -------------------------------------------------------------------------------
    def integral(self, t1: float | Interval, t2: float | Interval | None = None) -> Interval:
        """Enclosure of ``∫_{t1}^{t2} y(s) ds`` for every trajectory of the tube (for all
        ``t1 ∈ [t1]``, ``t2 ∈ [t2]`` when they are intervals; ``t2`` omitted: ``∫_{t0}^{t1}``).
        Requires ``t1 <= t2`` (``ub([t1]) <= lb([t2])``); a tube vector gives a box."""
        if t2 is None:
            t1, t2 = self.t[0], t1
        a, b = as_interval(t1), as_interval(t2)
        if a.ndim or b.ndim:
            raise ValueError("integral bounds must be scalars or scalar intervals")
        self._check_in_domain(np.array([a.lo, b.lo]), np.array([a.hi, b.hi]))
        if float(a.hi) > float(b.lo):
            raise ValueError(f"integral needs t1 <= t2, got [{float(a.lo)!r}, {float(a.hi)!r}] "
                             f"and [{float(b.lo)!r}, {float(b.hi)!r}]")
        shape = self.slices.shape[1:]
        if self.is_empty():
            return Interval.empty(shape)
        lo2 = self.slices.lo.reshape(self.n_slices, -1)
        hi2 = self.slices.hi.reshape(self.n_slices, -1)
        out = [integral_bounds(self.t, np.ascontiguousarray(lo2[:, j]),
                               np.ascontiguousarray(hi2[:, j]), (float(a.lo), float(a.hi)),
                               (float(b.lo), float(b.hi))) for j in range(lo2.shape[1])]
        lo = np.array([o[0] for o in out]).reshape(shape)
        hi = np.array([o[1] for o in out]).reshape(shape)
        return Interval.trusted(lo, hi)

    def primitive(self, x0: Interval | ArrayLike = 0.0) -> Tube:
        """The tube of ``x0 + ∫_{t0}^{t} y(s) ds`` (outward-rounded cumulative sums)."""
        x0 = as_interval(x0)
        n = self.n_slices
        lo2 = self.slices.lo.reshape(n, -1)
        hi2 = self.slices.hi.reshape(n, -1)
        d = lo2.shape[1]
        x0 = Interval.trusted(np.broadcast_to(x0.lo, (d,)), np.broadcast_to(x0.hi, (d,)))
        cols = [primitive_gates(self.t, lo2[:, [j]], hi2[:, [j]], float(x0.lo[j]),
                                float(x0.hi[j])) for j in range(d)]
        glo, ghi, slo, shi = (np.concatenate([c[k] for c in cols], axis=1) for k in range(4))
        shape = self.slices.shape[1:]
        # a primitive is continuous whether or not the integrand jumps
        out = Tube._wrap(self.t.copy(), Interval.trusted(slo.reshape(n, *shape),
                                                      shi.reshape(n, *shape)),
                         Interval.trusted(glo.reshape(n + 1, *shape), ghi.reshape(n + 1, *shape)))
        if self.is_empty() or np.any(x0.is_empty()):
            out.set_empty()
        return out

    # -- measures ---------------------------------------------------------------------------------
    def width(self) -> NDArray[np.float64]:
        """Width of each slice, shape ``(n,)`` or ``(n, d)``."""
        return self.slices.width()

    def volume(self) -> float:
        """Sum over slices (and components) of ``width * duration``; ``inf`` if unbounded."""
        w = self.slices.width().reshape(self.n_slices, -1)
        with np.errstate(invalid="ignore"):
            return float(np.sum(w * self.dt[:, None]))

    def max_thickness(self) -> float:
        """Largest slice width over time and components."""
        return float(np.max(self.slices.width())) if not self.is_empty() else float("nan")

    # -- set operations and sub-tubes ------------------------------------------------------------
    def _check_grid(self, other: Tube) -> None:
        if not _same_grid(self.t, other.t):
            raise ValueError("tubes must share their gate times")

    def __and__(self, other: Tube | Interval | ArrayLike) -> Tube:
        """Intersection (slice- and gate-wise). It is continuous when either tube is: its
        trajectories belong to both."""
        if isinstance(other, Tube):
            self._check_grid(other)
            out = Tube._wrap(self.t, intersect(self.slices, other.slices),
                             intersect(self.gates, other.gates), self.continuous)
            if other.continuous and not self.continuous:
                out.make_continuous()
            return out._normalize_empty()
        return Tube._wrap(self.t, intersect(self.slices, other), intersect(self.gates, other),
                          self.continuous)._normalize_empty()

    def __or__(self, other: Tube) -> Tube:
        """Hull (slice- and gate-wise); continuous when both tubes are."""
        self._check_grid(other)
        if self.is_empty():
            return other.copy()
        if other.is_empty():
            return self.copy()
        return Tube._wrap(self.t, hull(self.slices, other.slices), hull(self.gates, other.gates),
                          self.continuous and other.continuous)

    def is_subset(self, other: Tube) -> bool:
        self._check_grid(other)
        return bool(np.all(self.slices.is_subset(other.slices))
                    and np.all(self.gates.is_subset(other.gates)))

    def subtube(self, t0: float, tf: float) -> Tube:
        """The tube restricted to ``[t0, tf]`` (a copy). A bound inside a slice becomes a new
        gate, enclosed by that slice."""
        a, b = self.domain
        if not (a <= t0 < tf <= b):
            raise ValueError(f"subtube domain [{t0!r}, {tf!r}] is not a proper part of "
                             f"[{a!r}, {b!r}]")
        i0, i1 = self.slice_range(t0, tf)
        t = self.t[i0:i1 + 1].copy()
        t[0], t[-1] = t0, tf
        slices = self.slices[i0:i1].copy()
        gates = self.gates[i0:i1 + 1].copy()
        if self.t[i0] != t0:
            gates[0] = self.slices[i0]
        if self.t[i1] != tf:
            gates[-1] = self.slices[i1 - 1]
        return Tube._wrap(t, slices, gates, self.continuous)

    # -- arithmetic --------------------------------------------------------------------------------
    def map(self, f: Callable[..., Interval], *others: Tube | Interval | ArrayLike) -> Tube:
        """The tube ``f(self, *others)`` of an interval function applied to all slices and gates
        at once (others: tubes on the same grid, or intervals broadcast over time). The result
        is continuous (each slice encloses it over its closed time interval) when every tube
        argument is, whatever ``f``: ``f`` of closed-slice enclosures encloses the values there.
        """
        s_args, g_args = [self.slices], [self.gates]
        cont = self.continuous
        for o in others:
            if isinstance(o, Tube):
                self._check_grid(o)
                s_args.append(o.slices)
                g_args.append(o.gates)
                cont = cont and o.continuous
            else:
                s_args.append(as_interval(o))
                g_args.append(as_interval(o))
        out = Tube._wrap(self.t, as_interval(f(*s_args)), as_interval(f(*g_args)), cont)
        if self.is_empty() or any(isinstance(o, Tube) and o.is_empty() for o in others):
            out = Tube._wrap(self.t, out.slices.copy(), out.gates.copy(), cont)
            out.set_empty()
        return out._normalize_empty()

    def _rmap(self, f: Callable[..., Interval], other: Any) -> Tube:
        return self.map(lambda a, b: f(b, a), other)

    def __neg__(self) -> Tube:
        return self.map(lambda a: -a)

    def __add__(self, other: Any) -> Tube:
        return self.map(lambda a, b: a + b, other)

    def __radd__(self, other: Any) -> Tube:
        return self._rmap(lambda a, b: a + b, other)

    def __sub__(self, other: Any) -> Tube:
        return self.map(lambda a, b: a - b, other)

    def __rsub__(self, other: Any) -> Tube:
        return self._rmap(lambda a, b: a - b, other)

    def __mul__(self, other: Any) -> Tube:
        return self.map(lambda a, b: a * b, other)

    def __rmul__(self, other: Any) -> Tube:
        return self._rmap(lambda a, b: a * b, other)

    def __truediv__(self, other: Any) -> Tube:
        return self.map(lambda a, b: a / b, other)

    def __rtruediv__(self, other: Any) -> Tube:
        return self._rmap(lambda a, b: a / b, other)


#: A tube vector is a ``Tube`` whose slices and gates have a trailing dimension.
TubeVector = Tube


def _same_grid(a: NDArray, b: NDArray) -> bool:
    return a is b or (a.shape == b.shape and bool(np.array_equal(a, b)))


def _col(mask: NDArray, y: Tube) -> NDArray:
    return mask[:, None] if y.is_vector else mask


def _default_gates(slices: Interval) -> Interval:
    """Gates enclosed by both neighbouring slices."""
    first, last = slices[:1], slices[-1:]
    inner = intersect(slices[:-1], slices[1:])
    return Interval.trusted(np.concatenate([first.lo, inner.lo, last.lo]),
                         np.concatenate([first.hi, inner.hi, last.hi]))


def _hull_gates(slices: Interval) -> Interval:
    """Gates of a tube with jumps: the hull of the neighbouring slices."""
    first, last = slices[:1], slices[-1:]
    inner = hull(slices[:-1], slices[1:])
    return Interval.trusted(np.concatenate([first.lo, inner.lo, last.lo]),
                         np.concatenate([first.hi, inner.hi, last.hi]))


def _check_overlap(t: NDArray, slices: Interval) -> None:
    """Reject non-empty neighbouring slices that do not overlap in a continuous tube."""
    lo = slices.lo.reshape(slices.shape[0], -1)
    hi = slices.hi.reshape(slices.shape[0], -1)
    with np.errstate(invalid="ignore"):
        gap = (np.maximum(lo[:-1], lo[1:]) > np.minimum(hi[:-1], hi[1:]))
    if gap.any():
        i, j = (int(k) for k in np.argwhere(gap)[0])
        comp = f" (component {j})" if slices.ndim == 2 else ""
        a, b = (float(v) for v in (lo[i, j], hi[i, j]))
        c, d = (float(v) for v in (lo[i + 1, j], hi[i + 1, j]))
        raise ValueError(
            f"slices {i} [{a!r}, {b!r}] and {i + 1} [{c!r}, {d!r}]{comp} do not overlap: no "
            f"continuous trajectory crosses the gate t = {float(t[i + 1])!r}; for a signal that "
            f"jumps (a derivative, held samples) use Tube.piecewise_constant or continuous=False")
