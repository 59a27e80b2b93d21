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

_njit = nb.njit(cache=True, error_model="numpy")


@_njit
def _dur_dn(a: float, b: float) -> float:
    """Lower bound of ``b - a >= 0`` (0 when ``a >= b``)."""
    d = sub_dn(b, a)
    return d if d > 0.0 else 0.0


@_njit
def _walk_dn(t: NDArray, v: NDArray, a: float, b: float, forward: bool
             ) -> tuple[float, float]:
    """Lower bounds of the integral over ``[a, b]`` of the piecewise constant ``f`` worth
    ``v[i]`` on ``[t[i], t[i+1]]``, summed slice by slice from ``a`` (``forward``) or from
    ``b``: ``(total, minimum of the partial sums at the breakpoints, 0 included)``."""
    n = v.size
    total = least = 0.0
    if forward:
        i, step = np.searchsorted(t, a, side="right") - 1, 1
    else:
        i, step = np.searchsorted(t, b, side="left") - 1, -1
    i = min(max(i, 0), n - 1)
    while 0 <= i < n and t[i] < b and t[i + 1] > a:
        lo, hi = max(t[i], a), min(t[i + 1], b)
        if hi > lo:
            d_dn, d_up = _dur_dn(lo, hi), sub_up(hi, lo)
            total = add_dn(total, min(mul_dn(v[i], d_dn), mul_dn(v[i], d_up)))
            least = min(least, total)
        i += step
    return total, least


@_njit
def _low_integral(t: NDArray, v: NDArray, a0: float, a1: float, b0: float, b1: float) -> float:
    """Lower bound of ``min over s in [a0, a1], u in [b0, b1] of ∫_s^u f`` for the piecewise
    constant ``f`` worth ``v[i]`` on ``[t[i], t[i+1]]`` (``a1 <= b0``, all inside the grid).

    ``∫_s^u f = ∫_s^{a1} f + ∫_{a1}^{b0} f + ∫_{b0}^u f``: the first and last terms are
    piecewise linear in ``s`` and ``u``, so their minima are at the gates or the ends."""
    mid = _walk_dn(t, v, a1, b0, True)[0]
    first = _walk_dn(t, v, a0, a1, False)[1]  # ∫_s^{a1}, s walking back from a1
    last = _walk_dn(t, v, b0, b1, True)[1]
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
