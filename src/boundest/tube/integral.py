"""Sound integrals and primitives of tubes: cumulative sums with directed rounding (Numba).

A tube's lower (upper) bound is a piecewise constant function of time, one value per slice.
Its integral over ``[a, b]`` is a finite sum of ``value * duration`` terms; each term and each
partial sum is rounded outward (``mul_dn``/``add_dn`` for the lower bound, ``*_up`` for the
upper one), so the computed bounds enclose the exact real integrals of every trajectory of the
tube.
"""

from __future__ import annotations

import numba as nb
import numpy as np
from numpy.typing import NDArray

from ..interval.rounding import INF, add_dn, add_up, mul_dn, mul_up, sub_dn, sub_up

__all__ = ["integral_bounds", "primitive_gates"]

_njit = nb.njit(cache=True)


@_njit
def _dur_dn(a: float, b: float) -> float:
    """Lower bound of ``b - a >= 0`` (0 when ``a >= b``)."""
    d = sub_dn(b, a)
    return d if d > 0.0 else 0.0


@_njit
def _low_integral(t: NDArray, v: NDArray, a0: float, a1: float, b0: float, b1: float) -> float:
    """Lower bound of ``min over s in [a0, a1], u in [b0, b1] of ∫_s^u f`` for the piecewise
    constant ``f`` worth ``v[i]`` on ``[t[i], t[i+1]]`` (``a1 <= b0``, all inside the grid).

    ``∫_s^u f = ∫_s^{a1} f + ∫_{a1}^{b0} f + ∫_{b0}^u f``: the first and last terms are
    piecewise linear in ``s`` and ``u``, so their minima are at the gates or the ends."""
    n = v.size
    # middle part [a1, b0]
    mid = 0.0
    i = np.searchsorted(t, a1, side="right") - 1
    i = min(max(i, 0), n - 1)
    while i < n and t[i] < b0:
        lo = max(t[i], a1)
        hi = min(t[i + 1], b0)
        if hi > lo:
            d_dn, d_up = _dur_dn(lo, hi), sub_up(hi, lo)
            term = min(mul_dn(v[i], d_dn), mul_dn(v[i], d_up))
            mid = add_dn(mid, term)
        i += 1
    # backward from a1 to a0: partial sums of ∫_s^{a1}, minimum over breakpoints (and 0)
    first = 0.0
    acc = 0.0
    i = np.searchsorted(t, a1, side="left") - 1
    i = min(max(i, 0), n - 1)
    while i >= 0 and t[i + 1] > a0:
        lo = max(t[i], a0)
        hi = min(t[i + 1], a1)
        if hi > lo:
            d_dn, d_up = _dur_dn(lo, hi), sub_up(hi, lo)
            acc = add_dn(acc, min(mul_dn(v[i], d_dn), mul_dn(v[i], d_up)))
            first = min(first, acc)
        i -= 1
    # forward from b0 to b1
    last = 0.0
    acc = 0.0
    i = np.searchsorted(t, b0, side="right") - 1
    i = min(max(i, 0), n - 1)
    while i < n and t[i] < b1:
        lo = max(t[i], b0)
        hi = min(t[i + 1], b1)
        if hi > lo:
            d_dn, d_up = _dur_dn(lo, hi), sub_up(hi, lo)
            acc = add_dn(acc, min(mul_dn(v[i], d_dn), mul_dn(v[i], d_up)))
            last = min(last, acc)
        i += 1
    r = add_dn(add_dn(first, mid), last)
    return -INF if r != r else r


def integral_bounds(t: NDArray, lo: NDArray, hi: NDArray, a: tuple[float, float],
                    b: tuple[float, float]) -> tuple[float, float]:
    """Enclosure ``[l, u]`` of ``∫_s^u y`` over ``s in [a]``, ``u in [b]`` for every function
    ``y`` with ``lo <= y <= hi`` slice-wise (1-D bound arrays, ``a[1] <= b[0]``)."""
    low = _low_integral(t, lo, a[0], a[1], b[0], b[1])
    up = -_low_integral(t, -hi, a[0], a[1], b[0], b[1])
    return low, up


@_njit
def _primitive(t: NDArray, lo: NDArray, hi: NDArray, x0lo: float, x0hi: float,
               glo: NDArray, ghi: NDArray, slo: NDArray, shi: NDArray) -> None:
    """Gates ``x0 + ∫_{t0}^{t_i} y`` and slices (hull of the two neighbouring gates: the bound
    functions are linear on each slice) of the primitive, rounded outward; 2-D ``(n, d)``."""
    n, d = lo.shape
    for j in range(d):
        a, b = x0lo, x0hi
        glo[0, j], ghi[0, j] = a, b
        for i in range(n):
            d_dn, d_up = _dur_dn(t[i], t[i + 1]), sub_up(t[i + 1], t[i])
            na = add_dn(a, min(mul_dn(lo[i, j], d_dn), mul_dn(lo[i, j], d_up)))
            nb_ = add_up(b, max(mul_up(hi[i, j], d_dn), mul_up(hi[i, j], d_up)))
            slo[i, j] = min(a, na)
            shi[i, j] = max(b, nb_)
            a, b = na, nb_
            glo[i + 1, j], ghi[i + 1, j] = a, b


def primitive_gates(t: NDArray, lo: NDArray, hi: NDArray, x0lo: float, x0hi: float
                    ) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Bounds ``(gate_lo, gate_hi, slice_lo, slice_hi)`` of the primitive from ``[x0]``
    of a tube with slice bounds ``lo, hi`` of shape ``(n, d)``."""
    n, d = lo.shape
    glo, ghi = np.empty((n + 1, d)), np.empty((n + 1, d))
    slo, shi = np.empty((n, d)), np.empty((n, d))
    _primitive(t, np.ascontiguousarray(lo), np.ascontiguousarray(hi), x0lo, x0hi,
               glo, ghi, slo, shi)
    return glo, ghi, slo, shi
