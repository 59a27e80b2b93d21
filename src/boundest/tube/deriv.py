"""CtcDeriv: the differential constraint ``x'(.) = v(.)`` on tubes (a compiled recurrence).

For a trajectory with ``x' = v`` and ``v(s) ∈ [v_i]`` on slice ``i`` of duration ``h``:

- gates: ``x(t_{i+1}) ∈ x(t_i) + h [v_i]`` (forward pass) and ``x(t_i) ∈ x(t_{i+1}) - h [v_i]``
  (backward pass). After one forward and one backward pass the gates are consistent with each
  other (for intervals the backward pass cannot undo what the forward pass proved).
- slices: at ``s = t_i + τ``, ``x(s) ∈ ([x](t_i) + τ [v_i]) ∩ ([x](t_{i+1}) - (h - τ) [v_i])``.
  The slice becomes the hull over ``τ ∈ [0, h]`` of this intersection of two cones (the
  polygon of Rohou's thesis). Its upper bound is ``max_τ min(L1(τ), L2(τ))`` for the two lines
  ``L1 = a + τ v+`` and ``L2 = b - (h - τ) v-``; by LP duality it equals
  ``min_{λ ∈ [0,1]} max_{τ ∈ {0, h}} (λ L1 + (1-λ) L2)(τ)``. Any ``λ`` gives a sound upper
  bound; the kernel takes the minimum over ``λ = 0``, ``λ = 1`` (the box bounds) and the ``λ``
  that makes the combination flat (the exact polygon bound), all rounded upward, with
  ``λ + (1-λ) = 1`` exactly.

All sums and products use the directed-rounding helpers; no solution is lost under float64
rounding. An empty gate or slice empties the whole tube.
"""

from __future__ import annotations

import numba as nb
import numpy as np
from numpy.typing import NDArray

from ..interval.rounding import INF, add_dn, add_up, div_dn, mul_dn, mul_up, sub_dn, sub_up
from .tube import Tube

__all__ = ["CtcDeriv", "deriv_kernel"]

_njit = nb.njit(cache=True, error_model="numpy")


@_njit
def _lin_up(c: float, h_dn: float, h_up: float, v: float) -> float:
    """Upper bound of ``c + h v`` for the exact duration ``h ∈ [h_dn, h_up]``."""
    return add_up(c, max(mul_up(h_dn, v), mul_up(h_up, v)))


@_njit
def _lin_dn(c: float, h_dn: float, h_up: float, v: float) -> float:
    """Lower bound of ``c + h v``."""
    return add_dn(c, min(mul_dn(h_dn, v), mul_dn(h_up, v)))


@_njit
def _comb_up(lam: float, mu: float, p: float, q: float) -> float:
    """Upper bound of ``lam p + mu q`` (``lam, mu >= 0``; ``p, q`` upper bounds)."""
    return add_up(mul_up(lam, p), mul_up(mu, q))


@_njit
def slice_hi(a: float, b: float, vlo: float, vhi: float, h_dn: float, h_up: float) -> float:
    """Upper bound over the slice of ``min(a + τ v+, b - (h - τ) v-)``, ``τ ∈ [0, h]``
    (``a``: upper bound of the entry gate, ``b``: of the exit gate)."""
    l1_0 = a
    l1_h = _lin_up(a, h_dn, h_up, vhi)
    l2_0 = _lin_up(b, h_dn, h_up, -vlo)
    l2_h = b
    best = min(max(l1_0, l1_h), max(l2_0, l2_h))
    if vlo < 0.0 < vhi and vhi < INF and vlo > -INF:
        # λ v+ + (1 - λ) v- = 0: λ = -v- / (v+ - v-); any λ in [0, 1] is sound
        lam = div_dn(-vlo, sub_up(vhi, vlo))
        lam = min(max(lam, 0.0), 1.0)
        if lam >= 0.5:
            mu = 1.0 - lam  # exact (Sterbenz)
        else:
            mu = 1.0 - lam
            lam = 1.0 - mu  # exact: mu in [0.5, 1]
        c = max(_comb_up(lam, mu, l1_0, l2_0), _comb_up(lam, mu, l1_h, l2_h))
        if c < best:
            best = c
    return best


@_njit
def deriv_kernel(t: NDArray, slo: NDArray, shi: NDArray, glo: NDArray, ghi: NDArray,
                 vlo: NDArray, vhi: NDArray) -> bool:
    """Contract the tube ``(slo, shi, glo, ghi)`` of shape ``(n, d)``/``(n+1, d)`` in place with
    ``x' = v`` (``v`` slices ``(n, d)``). Returns ``False`` when the tube becomes empty (the
    arrays are then left partly contracted: the caller empties them)."""
    n, d = slo.shape
    for j in range(d):
        # gates inside the neighbouring slices
        for i in range(n + 1):
            lo, hi = glo[i, j], ghi[i, j]
            if i > 0:
                lo, hi = max(lo, slo[i - 1, j]), min(hi, shi[i - 1, j])
            if i < n:
                lo, hi = max(lo, slo[i, j]), min(hi, shi[i, j])
            if not lo <= hi:
                return False
            glo[i, j], ghi[i, j] = lo, hi
        # forward in time
        for i in range(n):
            h_dn, h_up = sub_dn(t[i + 1], t[i]), sub_up(t[i + 1], t[i])
            lo = max(glo[i + 1, j], _lin_dn(glo[i, j], h_dn, h_up, vlo[i, j]))
            hi = min(ghi[i + 1, j], _lin_up(ghi[i, j], h_dn, h_up, vhi[i, j]))
            if not lo <= hi:
                return False
            glo[i + 1, j], ghi[i + 1, j] = lo, hi
        # backward in time
        for i in range(n - 1, -1, -1):
            h_dn, h_up = sub_dn(t[i + 1], t[i]), sub_up(t[i + 1], t[i])
            lo = max(glo[i, j], _lin_dn(glo[i + 1, j], h_dn, h_up, -vhi[i, j]))
            hi = min(ghi[i, j], _lin_up(ghi[i + 1, j], h_dn, h_up, -vlo[i, j]))
            if not lo <= hi:
                return False
            glo[i, j], ghi[i, j] = lo, hi
        # slices: hull of the intersection of the forward and backward cones
        for i in range(n):
            h_dn, h_up = sub_dn(t[i + 1], t[i]), sub_up(t[i + 1], t[i])
            if h_dn < 0.0:
                h_dn = 0.0
            a, b = vlo[i, j], vhi[i, j]
            hi = slice_hi(ghi[i, j], ghi[i + 1, j], a, b, h_dn, h_up)
            lo = -slice_hi(-glo[i, j], -glo[i + 1, j], -b, -a, h_dn, h_up)
            lo, hi = max(slo[i, j], lo), min(shi[i, j], hi)
            if not lo <= hi:
                return False
            slo[i, j], shi[i, j] = lo, hi
    return True


def _as2d(a: NDArray) -> NDArray:
    return a[:, None] if a.ndim == 1 else a


class CtcDeriv:
    """Contractor for ``x'(.) = v(.)`` on tubes (or tube vectors) on the same gate times.

    ``contract(x, v)`` contracts ``x`` in place (forward and backward in time, tight at the
    gates, slices by the polygon envelope of the two cones); ``v`` is left unchanged (Rohou et
    al. 2018, Lemma 3: nothing can be learnt on the derivative). Returns ``x``.

    Only the slices of ``v`` are read: ``v`` may jump at every gate (a tube with
    ``continuous=False``, e.g. :meth:`Tube.piecewise_constant` of held sensor boxes), since
    ``x(t_{i+1}) - x(t_i)`` is the integral of ``v`` over the open slice. ``x`` has a
    derivative, so it is continuous: a tube ``x`` with jumps is made continuous first
    (:meth:`Tube.make_continuous`).

    Examples
    --------
    >>> from boundest import Interval
    >>> x = Tube.constant(0, 1, 4, Interval.entire())
    >>> x.gates[0] = Interval(0, 0)
    >>> v = Tube.constant(0, 1, 4, Interval(1, 1))
    >>> _ = CtcDeriv().contract(x, v)
    >>> x.gates[4]
    Interval([1.0, 1.0])
    """

    def contract(self, x: Tube, v: Tube) -> Tube:
        if not np.array_equal(x.t, v.t):
            raise ValueError("CtcDeriv: x and v must share their gate times")
        if x.slices.shape != v.slices.shape:
            raise ValueError(f"CtcDeriv: x and v have shapes {x.slices.shape} and "
                             f"{v.slices.shape}")
        if x.is_empty() or v.is_empty():
            x.set_empty()
            return x
        x.continuous = True  # the kernel's first step puts the gates inside both slices
        ok = deriv_kernel(x.t, _as2d(x.slices.lo), _as2d(x.slices.hi), _as2d(x.gates.lo),
                          _as2d(x.gates.hi), _as2d(v.slices.lo), _as2d(v.slices.hi))
        if not ok:
            x.set_empty()
        return x

    __call__ = contract
