"""The interval array type: two float64 arrays ``lo`` and ``hi`` with NumPy semantics.

A scalar interval has shape ``()``, a box shape ``(n,)``, a batch of boxes ``(b, n)``. The empty
set is ``[nan, nan]`` in every position, so it propagates through kernels without branches.
Bounds are never ``lo = +inf`` or ``hi = -inf``.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .decimal import decimal_bounds

__all__ = ["Interval", "IntervalVector", "as_interval", "hull", "intersect"]

_MAX = float(np.finfo(np.float64).max)


def _fmt(v: float) -> str:
    if v == np.inf:
        return "inf"
    if v == -np.inf:
        return "-inf"
    return repr(float(v))


#: an Interval's repr shows every element up to this size, and summarises beyond it
_REPR_THRESHOLD = 1000
#: elements shown at each end of every axis of a summarised repr
_REPR_EDGE = 3


def _nested(lo: NDArray, hi: NDArray, edge: int | None) -> str:
    """``[[a, b], ...]`` for arrays of bounds; with ``edge``, an axis longer than ``2 edge`` shows
    its first and last ``edge`` entries around ``...`` (only those elements are formatted)."""
    if lo.ndim == 0:
        return Interval._str_scalar(lo, hi)
    n = lo.shape[0]
    if edge is not None and n > 2 * edge:
        head = [_nested(lo[i], hi[i], edge) for i in range(edge)]
        tail = [_nested(lo[i], hi[i], edge) for i in range(n - edge, n)]
        return "[" + ", ".join([*head, "...", *tail]) + "]"
    return "[" + ", ".join(_nested(lo[i], hi[i], edge) for i in range(n)) + "]"


def _bad_value(lo: NDArray, hi: NDArray, mask: NDArray, why: str) -> ValueError:
    idx = tuple(int(i) for i in np.argwhere(mask)[0]) if mask.ndim else ()
    where = f" at index {idx}" if idx else ""
    return ValueError(f"invalid interval{where}: [{_fmt(lo[idx])}, {_fmt(hi[idx])}] ({why})")


def _width_up(lo: NDArray, hi: NDArray) -> NDArray:
    """``hi - lo`` rounded upward (TwoSum decides whether a step is needed)."""
    with np.errstate(invalid="ignore", over="ignore"):
        w = hi - lo
        bb = w - hi
        err = (hi - (w - bb)) + (-lo - bb)
        return np.where(err > 0, np.nextafter(w, np.inf), w)


class Interval:
    """An n-dimensional array of closed real intervals ``[lo, hi]``.

    Parameters
    ----------
    lo, hi : array_like
        Lower and upper bounds, broadcast together. With ``hi`` omitted the interval is
        degenerate (``[lo, lo]``); an ``Interval`` argument is copied.

    Examples
    --------
    >>> Interval(1, 2)
    Interval([1.0, 2.0])
    >>> Interval([0, 1], [2, 3]).width()
    array([2., 2.])
    """

    __slots__ = ("hi", "lo")
    __array_ufunc__ = None  # NumPy scalars and arrays defer to our reflected operators
    __hash__ = None  # type: ignore[assignment]

    lo: NDArray[np.float64]
    hi: NDArray[np.float64]

    def __init__(self, lo: ArrayLike | Interval, hi: ArrayLike | None = None) -> None:
        if isinstance(lo, Interval):
            if hi is not None:
                raise ValueError("Interval(x, hi): x is already an interval, hi must be omitted")
            self.lo, self.hi = lo.lo.copy(), lo.hi.copy()
            return
        try:
            a = np.array(lo, dtype=np.float64)
            b = a.copy() if hi is None else np.array(hi, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"interval bounds must be real numbers: {lo!r}, {hi!r}") from exc
        try:
            a, b = np.broadcast_arrays(a, b)
        except ValueError as exc:
            raise ValueError(f"interval bounds of shapes {a.shape} and {b.shape} do not "
                             "broadcast together") from exc
        a, b = a.copy(), b.copy()
        for mask, why in ((np.isnan(a) | np.isnan(b), "NaN bound; use Interval.empty()"),
                          (a > b, "lower bound above upper bound"),
                          ((a == np.inf) | (b == -np.inf), "infinite bound on the wrong side")):
            if mask.any():
                raise _bad_value(a, b, mask, why)
        self.lo, self.hi = a, b

    # -- construction ---------------------------------------------------------------------
    @classmethod
    def _new(cls, lo: ArrayLike, hi: ArrayLike) -> Interval:
        """Wrap bounds without validation (for kernels that guarantee the invariants)."""
        obj = object.__new__(cls)
        obj.lo = np.asarray(lo, dtype=np.float64)
        obj.hi = np.asarray(hi, dtype=np.float64)
        return obj

    @classmethod
    def trusted(cls, lo: ArrayLike, hi: ArrayLike) -> Interval:
        """Wrap bounds that the caller vouches for: no checks, no copies.

        For code that computed the bounds itself, rounded outward (a kernel, a contractor):
        ``lo`` and ``hi`` of one shape, ``lo <= hi``, no ``+inf`` lower bound or ``-inf``
        upper bound, and NaN in both bounds of an empty component. Float64 arrays are wrapped
        as they are, so later writes to them change the interval. Nothing is checked: bounds
        that break these rules give wrong results, not errors. Use ``Interval(lo, hi)`` for
        anything a user or a file gave.

        Examples
        --------
        >>> lo, hi = np.array([0.0, np.nan]), np.array([1.0, np.nan])
        >>> x = Interval.trusted(lo, hi)
        >>> x.lo is lo, x.is_empty()
        (True, array([False,  True]))
        """
        return cls._new(lo, hi)

    @classmethod
    def empty(cls, shape: int | tuple[int, ...] = ()) -> Interval:
        """The empty set (``[nan, nan]``), of the given shape."""
        return cls._new(np.full(shape, np.nan), np.full(shape, np.nan))

    @classmethod
    def entire(cls, shape: int | tuple[int, ...] = ()) -> Interval:
        """The whole real line ``]-oo, +oo[``, of the given shape."""
        return cls._new(np.full(shape, -np.inf), np.full(shape, np.inf))

    @classmethod
    def from_bounds(cls, bounds: ArrayLike) -> Interval:
        """Build from an array of shape ``(..., 2)`` holding ``[lo, hi]`` pairs."""
        arr = np.asarray(bounds, dtype=np.float64)
        if arr.ndim == 0 or arr.shape[-1] != 2:
            raise ValueError(f"bounds must have a last axis of length 2, got shape {arr.shape}")
        return cls(arr[..., 0], arr[..., 1])

    @classmethod
    def stack(cls, parts: Sequence[ArrayLike | Interval], axis: int = -1) -> Interval:
        """Join intervals of one shape (broadcast together) along a new axis, as ``np.stack``.

        The usual use is a box from its components: ``Interval.stack([x, y])`` of two intervals
        of shape ``(n,)`` is ``n`` boxes of shape ``(n, 2)``. Empty components stay empty;
        numbers are degenerate intervals.

        Examples
        --------
        >>> Interval.stack([Interval(0, 1), Interval(2, 3)])
        Interval([[0.0, 1.0], [2.0, 3.0]])
        >>> Interval.stack([Interval([0, 1], [1, 2]), 5.0]).shape
        (2, 2)
        """
        ivs = [as_interval(p) for p in parts]
        if not ivs:
            raise ValueError("Interval.stack needs at least one interval")
        try:
            shape = np.broadcast_shapes(*(v.shape for v in ivs))
        except ValueError as exc:
            raise ValueError("Interval.stack: the shapes "
                             f"{', '.join(str(v.shape) for v in ivs)} do not broadcast "
                             "together") from exc
        lo = np.stack([np.broadcast_to(v.lo, shape) for v in ivs], axis=axis)
        hi = np.stack([np.broadcast_to(v.hi, shape) for v in ivs], axis=axis)
        return cls._new(lo, hi)

    @classmethod
    def from_decimal(cls, text: str | Sequence | NDArray) -> Interval:
        """The tightest intervals containing numbers written in decimal: ``"0.1"``, which no
        float equals, gives the two floats around it; a string that a float represents
        exactly (``"0.5"``, ``"3"``) a degenerate interval. A nested sequence or array of
        strings gives an Interval of its shape.

        The comparison with the floats is exact (rational arithmetic on up to 40 significant
        digits, then digit by digit), whatever the length of the literal. Beyond the float
        range the enclosure is ``[MAX, +oo]`` (or its negative). ``Interval(0.1)`` is the
        float nearest 0.1 instead, which does not contain it.

        Raises
        ------
        ValueError
            When a string is not a decimal literal (``"1e-3"``, ``"-.5"``, ``"+2."`` are).

        Examples
        --------
        >>> x = Interval.from_decimal("0.1")
        >>> float(x.hi) == 0.1, float(x.lo) < 0.1  # the double 0.1 lies above one tenth
        (True, True)
        >>> Interval.from_decimal(["0.5", "-3"])
        Interval([[0.5, 0.5], [-3.0, -3.0]])
        """
        if isinstance(text, str):
            lo, hi, _ = decimal_bounds(text)
            return cls._new(np.asarray(lo), np.asarray(hi))
        texts = np.asarray(text, dtype=object)
        lo, hi = np.empty(texts.shape), np.empty(texts.shape)
        for i, t in enumerate(texts.flat):
            if not isinstance(t, str):
                raise ValueError(f"Interval.from_decimal takes strings, got {t!r}")
            lo.flat[i], hi.flat[i], _ = decimal_bounds(t)
        return cls._new(lo, hi)

    def to_bounds(self) -> NDArray[np.float64]:
        """The bounds as one array of shape ``(..., 2)``."""
        return np.stack([self.lo, self.hi], axis=-1)

    def copy(self) -> Interval:
        return Interval._new(self.lo.copy(), self.hi.copy())

    # -- array protocol -------------------------------------------------------------------
    @property
    def shape(self) -> tuple[int, ...]:
        return self.lo.shape

    @property
    def ndim(self) -> int:
        return self.lo.ndim

    @property
    def size(self) -> int:
        return self.lo.size

    def __len__(self) -> int:
        if self.lo.ndim == 0:
            raise TypeError("len() of a scalar interval")
        return len(self.lo)

    def __getitem__(self, key: Any) -> Interval:
        return Interval._new(self.lo[key], self.hi[key])

    def __setitem__(self, key: Any, value: ArrayLike | Interval) -> None:
        v = as_interval(value)
        self.lo[key] = v.lo
        self.hi[key] = v.hi

    def __iter__(self) -> Iterator[Interval]:
        for i in range(len(self)):
            yield self[i]

    def reshape(self, *shape: Any) -> Interval:
        return Interval._new(self.lo.reshape(*shape), self.hi.reshape(*shape))

    def __repr__(self) -> str:
        """``Interval([[0.0, 1.0], [1.0, inf]])``; beyond ``_REPR_THRESHOLD`` elements, only the
        first and last ``_REPR_EDGE`` along each axis, ``...`` between, and the shape (as NumPy
        summarises)."""
        if self.lo.ndim == 0:
            return f"Interval({self._str_scalar(self.lo, self.hi)})"
        if self.size <= _REPR_THRESHOLD:
            return f"Interval({_nested(self.lo, self.hi, None)})"
        return f"Interval({_nested(self.lo, self.hi, _REPR_EDGE)}, shape={self.shape})"

    @staticmethod
    def _str_scalar(a: float, b: float) -> str:
        if np.isnan(a):
            return "[empty]"
        return f"[{_fmt(a)}, {_fmt(b)}]"

    __str__ = __repr__

    def __bool__(self) -> bool:
        raise TypeError("the truth value of an Interval is ambiguous; use is_empty(), "
                        "contains() or is_subset()")

    # -- predicates -----------------------------------------------------------------------
    def is_empty(self) -> NDArray[np.bool_]:
        return np.isnan(self.lo)

    def is_entire(self) -> NDArray[np.bool_]:
        return (self.lo == -np.inf) & (self.hi == np.inf)

    def is_degenerate(self) -> NDArray[np.bool_]:
        return self.lo == self.hi

    def is_bounded(self) -> NDArray[np.bool_]:
        return np.isfinite(self.lo) & np.isfinite(self.hi) | self.is_empty()

    def contains(self, x: ArrayLike | Interval) -> NDArray[np.bool_]:
        """Whether the real ``x`` lies in the interval (or the interval ``x`` is a subset)."""
        if isinstance(x, Interval):
            return x.is_subset(self)
        x = np.asarray(x, dtype=np.float64)
        return (self.lo <= x) & (x <= self.hi) & np.isfinite(x)  # infinities are not reals

    def __contains__(self, x: ArrayLike | Interval) -> bool:
        return bool(np.all(self.contains(x)))

    def is_subset(self, other: ArrayLike | Interval) -> NDArray[np.bool_]:
        """Whether ``self`` is a subset of ``other`` (the empty set is a subset of anything)."""
        o = as_interval(other)
        return self.is_empty() | ((o.lo <= self.lo) & (self.hi <= o.hi))

    def is_interior_subset(self, other: ArrayLike | Interval) -> NDArray[np.bool_]:
        o = as_interval(other)
        inner_lo = (o.lo < self.lo) | (o.lo == -np.inf)
        inner_hi = (self.hi < o.hi) | (o.hi == np.inf)
        return self.is_empty() | (inner_lo & inner_hi)

    def intersects(self, other: ArrayLike | Interval) -> NDArray[np.bool_]:
        o = as_interval(other)
        return (self.lo <= o.hi) & (o.lo <= self.hi)

    def __eq__(self, other: object) -> Any:  # set equality, elementwise
        try:
            o = as_interval(other)  # type: ignore[arg-type]
        except (TypeError, ValueError):
            return NotImplemented
        both_empty = self.is_empty() & o.is_empty()
        return both_empty | ((self.lo == o.lo) & (self.hi == o.hi))

    def __ne__(self, other: object) -> Any:
        eq = self.__eq__(other)
        return eq if eq is NotImplemented else ~eq

    # -- measures (rounded upward where a bound is computed) --------------------------------
    def lb(self) -> NDArray[np.float64]:
        return self.lo

    def ub(self) -> NDArray[np.float64]:
        return self.hi

    def width(self) -> NDArray[np.float64]:
        """``hi - lo`` rounded upward; NaN for the empty set, ``inf`` when unbounded."""
        return _width_up(self.lo, self.hi)

    diam = width

    def mid(self) -> NDArray[np.float64]:
        """A float in the interval near its centre (IEEE 1788 ``mid``; 0 for the entire line)."""
        lo, hi = self.lo, self.hi
        with np.errstate(invalid="ignore", over="ignore"):
            s = lo + hi
            m = np.where(np.isfinite(s), 0.5 * s, 0.5 * lo + 0.5 * hi)
        m = np.where(lo == -np.inf, np.where(hi == np.inf, 0.0, -_MAX), m)
        m = np.where((hi == np.inf) & (lo > -np.inf), _MAX, m)
        return np.clip(m, lo, hi)

    def rad(self) -> NDArray[np.float64]:
        """An upper bound of the distance from ``mid()`` to either bound."""
        m = self.mid()
        return np.maximum(_width_up(self.lo, m), _width_up(m, self.hi))

    def mag(self) -> NDArray[np.float64]:
        """``max |x|`` over the interval."""
        return np.maximum(np.abs(self.lo), np.abs(self.hi))

    def mig(self) -> NDArray[np.float64]:
        """``min |x|`` over the interval."""
        m = np.minimum(np.abs(self.lo), np.abs(self.hi))
        return np.where((self.lo <= 0) & (self.hi >= 0), 0.0, m)

    def volume(self) -> NDArray[np.float64]:
        """Product of the widths over the last axis (a box's volume; 0-d: the width), rounded
        up: an upper bound of the exact volume (0 exactly when a width is 0)."""
        from .arith import _mul_hi  # arith builds on this module

        w = self.width()
        if w.ndim == 0:
            return w
        v = w[..., 0].copy()
        for i in range(1, w.shape[-1]):  # a loop over the dimension, not over boxes
            v = _mul_hi(v, v, w[..., i], w[..., i])
        return v

    def max_diam(self) -> NDArray[np.float64]:
        """Largest width over the last axis (a box's diameter)."""
        w = self.width()
        return w if w.ndim == 0 else np.max(w, axis=-1)

    # -- set operations -------------------------------------------------------------------
    def __and__(self, other: ArrayLike | Interval) -> Interval:
        return intersect(self, other)

    __rand__ = __and__

    def __or__(self, other: ArrayLike | Interval) -> Interval:
        return hull(self, other)

    __ror__ = __or__

    def inflate(self, rad: ArrayLike, rel: ArrayLike = 0.0) -> Interval:
        """Widen each bound by ``rad + rel * |bound|`` (rounded outward); empty stays empty."""
        rad = np.asarray(rad, dtype=np.float64)
        rel = np.asarray(rel, dtype=np.float64)
        if np.any(rad < 0) or np.any(rel < 0):
            raise ValueError(f"inflate needs non-negative radii, got rad={rad}, rel={rel}")
        with np.errstate(invalid="ignore", over="ignore"):
            dlo = np.nextafter(rad + rel * np.abs(self.lo), np.inf)
            dhi = np.nextafter(rad + rel * np.abs(self.hi), np.inf)
            lo = np.nextafter(self.lo - dlo, -np.inf)
            hi = np.nextafter(self.hi + dhi, np.inf)
        lo = np.where(np.isinf(self.lo), self.lo, lo)
        hi = np.where(np.isinf(self.hi), self.hi, hi)
        return Interval._new(lo, hi)

    def bisect(self, ratio: float = 0.5) -> tuple[Interval, Interval]:
        """Split in two.

        A scalar (shape ``()``) interval is split at ``lo + ratio * width``. A box (last axis =
        dimensions) is split along its widest component; a batch of boxes ``(..., n)`` splits each
        box along its own widest component. Both halves share the split point.
        """
        if not 0.0 < ratio < 1.0:
            raise ValueError(f"bisect ratio must lie in ]0, 1[, got {ratio}")
        if np.any(self.is_empty()):
            raise ValueError("cannot bisect an empty interval or box")
        if self.ndim == 0:
            p = self._split_point(self.lo, self.hi, ratio)
            return Interval._new(self.lo, p), Interval._new(p, self.hi)
        w = self.width()
        axis = np.argmax(w, axis=-1)[..., None]
        lo_k = np.take_along_axis(self.lo, axis, -1)
        hi_k = np.take_along_axis(self.hi, axis, -1)
        p = self._split_point(lo_k, hi_k, ratio)
        left, right = self.copy(), self.copy()
        np.put_along_axis(left.hi, axis, p, -1)
        np.put_along_axis(right.lo, axis, p, -1)
        return left, right

    @staticmethod
    def _split_point(lo: NDArray, hi: NDArray, ratio: float) -> NDArray:
        if np.any(lo == hi):
            raise ValueError("cannot bisect a degenerate interval")
        finite = np.isfinite(lo) & np.isfinite(hi)
        with np.errstate(over="ignore", invalid="ignore"):
            p = lo + ratio * (hi - lo)
            p = np.where(np.isfinite(p), p, (1 - ratio) * lo + ratio * hi)
        unb = np.where(lo == -np.inf, np.where(hi == np.inf, 0.0, np.minimum(-1.0, 2 * hi - 1)),
                       np.maximum(1.0, 2 * lo + 1))
        unb = np.clip(np.where(np.isfinite(unb), unb, np.where(lo == -np.inf, -_MAX, _MAX)),
                      -_MAX, _MAX)
        p = np.where(finite, p, unb)
        # the split point must be strictly inside so that both halves are proper
        p = np.clip(p, np.nextafter(lo, np.inf), np.nextafter(hi, -np.inf))
        return np.where(p <= lo, hi, p)

    # -- arithmetic (bodies in arith.py / elementary.py) -----------------------------------
    def __pos__(self) -> Interval:
        return self.copy()

    def __neg__(self) -> Interval:
        return Interval._new(-self.hi, -self.lo)

    def __add__(self, other: Any) -> Interval:
        return NotImplemented if _defers(other) else _arith.add(self, other)

    def __radd__(self, other: Any) -> Interval:
        return NotImplemented if _defers(other) else _arith.add(other, self)

    def __sub__(self, other: Any) -> Interval:
        return NotImplemented if _defers(other) else _arith.sub(self, other)

    def __rsub__(self, other: Any) -> Interval:
        return NotImplemented if _defers(other) else _arith.sub(other, self)

    def __mul__(self, other: Any) -> Interval:
        return NotImplemented if _defers(other) else _arith.mul(self, other)

    def __rmul__(self, other: Any) -> Interval:
        return NotImplemented if _defers(other) else _arith.mul(other, self)

    def __truediv__(self, other: Any) -> Interval:
        return NotImplemented if _defers(other) else _arith.div(self, other)

    def __rtruediv__(self, other: Any) -> Interval:
        return NotImplemented if _defers(other) else _arith.div(other, self)

    def __pow__(self, other: Any) -> Interval:
        """``self ** other``: the integer power for an integer-valued exponent (an int, an
        integer-valued float, a degenerate integer ``Interval``; any magnitude), else IEEE 1788
        ``pow`` (see ``explog.power``)."""
        if _defers(other):
            return NotImplemented
        from . import explog
        return explog.power(self, other)

    def __abs__(self) -> Interval:
        from . import algebraic
        return algebraic.abs(self)


def _defers(x: Any) -> bool:
    """Whether ``x`` is a non-interval object that asks NumPy-style operands to defer to its
    reflected operators (``__array_ufunc__ = None``: expressions, tubes), so that
    ``Interval(0, 1) * expr`` builds an expression as ``expr * Interval(0, 1)`` does."""
    return not isinstance(x, Interval) and getattr(type(x), "__array_ufunc__", 0) is None


def as_interval(x: ArrayLike | Interval) -> Interval:
    """``x`` itself when it is an ``Interval``, else the degenerate interval ``[x, x]``."""
    if isinstance(x, Interval):
        return x
    a = np.asarray(x, dtype=np.float64)
    if np.isnan(a).any():
        raise ValueError(f"cannot make an interval from NaN: {x!r}")
    # a float point is exact; an infinite point is not a real number
    if np.isinf(a).any():
        raise ValueError(f"cannot make a degenerate interval from an infinite value: {x!r}")
    return Interval._new(a, a)


def IntervalVector(bounds: ArrayLike | int, value: Interval | None = None) -> Interval:  # noqa: N802
    """A box (or array of boxes) from ``[[lo0, hi0], [lo1, hi1], ...]``.

    ``IntervalVector(n)`` is the entire box of dimension ``n``; ``IntervalVector(n, x)`` repeats
    the interval ``x``. The result is an ``Interval`` of shape ``(n,)`` (or ``(..., n)``).
    """
    if isinstance(bounds, (int, np.integer)):
        if bounds < 0:
            raise ValueError(f"dimension must be non-negative, got {bounds}")
        base = Interval.entire() if value is None else as_interval(value)
        return Interval._new(np.full(bounds, base.lo), np.full(bounds, base.hi))
    return Interval.from_bounds(bounds)


def intersect(x: ArrayLike | Interval, y: ArrayLike | Interval) -> Interval:
    """Elementwise intersection (empty where disjoint)."""
    x, y = as_interval(x), as_interval(y)
    lo = np.maximum(x.lo, y.lo)  # NaN (empty) propagates
    hi = np.minimum(x.hi, y.hi)
    bad = lo > hi
    if bad.any():
        lo = np.where(bad, np.nan, lo)
        hi = np.where(bad, np.nan, hi)
    return Interval._new(lo, hi)


def hull(x: ArrayLike | Interval, y: ArrayLike | Interval | None = None, axis: int | None = None
         ) -> Interval:
    """Interval hull of ``x`` and ``y`` elementwise, or of ``x`` over ``axis`` (``y`` omitted)."""
    x = as_interval(x)
    if y is None:
        if axis is None:
            return Interval._new(np.fmin.reduce(x.lo, axis=None), np.fmax.reduce(x.hi, axis=None))
        return Interval._new(np.fmin.reduce(x.lo, axis=axis), np.fmax.reduce(x.hi, axis=axis))
    y = as_interval(y)
    return Interval._new(np.fmin(x.lo, y.lo), np.fmax(x.hi, y.hi))


from . import arith as _arith  # noqa: E402  (arith needs Interval defined above)
