"""CtcEval: the evaluation constraint ``z = y(t)`` with ``t ∈ [t]``, ``z ∈ [z]``, ``y' ∈ [w]``.

Rohou et al. 2018 Proposition 2:

- ``[t] ← [t] ∩ [y]^{-1}([z])`` (hull of the time slices and gates where the tube meets ``[z]``);
- ``[z] ← [z] ∩ [y]([t])``;
- ``[y](.) ← [y](.) ∩ ⊔_{t1 ∈ [t]} (([y](t1) ∩ [z]) + ∫_{t1}^{.} [w])``.

The tube part is computed on the slices and gates by a compiled recurrence. Let ``F(s)`` be the
values at time ``s`` of the trajectories that met ``[z]`` at some ``t1 ∈ [t]`` with
``t1 <= s``, and ``B(s)`` the same with ``t1 >= s``. Every feasible trajectory has
``y(s) ∈ F(s) ∪ B(s)``. On the gates:

``F(t_{i+1}) = [y](t_{i+1}) ∩ ( (F(t_i) + h_i [w_i]) ∪ ((z ∩ [y_i]) + [d_i] [w_i]) ∪ Z_{i+1} )``

where the middle term exists when slice ``i`` meets ``[t]`` (``[d_i]``: the possible durations
``t_{i+1} - t1`` for ``t1`` in slice ``i`` and ``[t]``) and ``Z_k = z ∩ [y](t_k)`` when
``t_k ∈ [t]``; ``B`` is the mirror image backward in time. Slices inside ``[t]`` are bounded
by the box ``(F(t_i) ∪ (z ∩ [y_i])) + [0, h_i] [w_i]`` (and its mirror) and by the polygon of
the two cones between the contracted gates (as in CtcDeriv: ``y' = w`` holds on every
trajectory); slices outside ``[t]`` by the polygon between ``F`` (or ``B``) gates. Away from
``[t]`` the recurrence stops as soon as ``F`` (``B``) contains the gate: from there on it could
only repeat what CtcDeriv does. All arithmetic is rounded outward.
"""

from __future__ import annotations

import numba as nb
import numpy as np
from numpy.typing import NDArray

from ..interval import Interval, as_interval
from ..interval.rounding import (
    INF,
    add_dn,
    add_up,
    div_dn,
    div_up,
    mul_dn,
    mul_up,
    sub_dn,
    sub_up,
)
from .deriv import _lin_dn, _lin_up, slice_hi
from .tube import Tube

__all__ = ["CtcEval", "eval_kernel", "invert_kernel", "invert_pieces", "values_over_pieces"]

_njit = nb.njit(cache=True, error_model="numpy")


@_njit
def _mul_lo(d0: float, d1: float, w: float) -> float:
    """Lower bound of ``d w`` for ``d ∈ [d0, d1]``, ``d0 >= 0``."""
    return min(mul_dn(d0, w), mul_dn(d1, w))


@_njit
def _mul_hi(d0: float, d1: float, w: float) -> float:
    return max(mul_up(d0, w), mul_up(d1, w))


@_njit
def _dur(a: float, b: float) -> tuple[float, float]:
    """Enclosure of ``b - a`` clamped at 0 below."""
    lo = sub_dn(b, a)
    return (lo if lo > 0.0 else 0.0), sub_up(b, a)


@_njit
def _half(b: float, d: float) -> tuple[float, float]:
    """An enclosure of ``{u : b u <= d}`` (``d`` an upper bound; ``(INF, -INF)`` when empty).
    A non-finite ``b`` or a NaN ``d`` gives the whole line (a dropped constraint)."""
    if not (-INF < b < INF) or d != d:
        return -INF, INF
    if b > 0.0:
        return -INF, div_up(d, b)
    if b < 0.0:
        return div_dn(d, b), INF
    return (-INF, INF) if d >= 0.0 else (INF, -INF)


@_njit
def _slice_times(t0: float, t1: float, g0lo: float, g0hi: float, g1lo: float, g1hi: float,
                 wlo: float, whi: float, x: float, y: float) -> tuple[float, float]:
    """Enclosure of the times ``s ∈ [t0, t1]`` at which a trajectory of the slice polygon (entry
    gate ``g0``, exit gate ``g1``, ``y' ∈ [wlo, whi]``) may take a value in ``[x, y]``.

    With ``τ = s - t0`` and ``σ = t1 - s`` the values at ``s`` are bounded by the cones
    ``[g0lo + τ wlo, g0hi + τ whi]`` and ``[g1lo - σ whi, g1hi - σ wlo]``; the value set meets
    ``[x, y]`` (already inside the slice envelope) iff each cone bound is on the right side of
    ``[x, y]`` (the other pairs of bounds do not depend on ``s``: they hold for consistent
    gates). Each of the four conditions is a half-line in ``τ`` or ``σ`` (Fourier-Motzkin on
    the polygon), so the result is the exact projection, rounded outward."""
    a_lo, a_hi = _half(wlo, sub_up(y, g0lo))            # g0lo + τ wlo <= y
    b_lo, b_hi = _half(-whi, sub_up(g0hi, x))           # g0hi + τ whi >= x
    c_lo, c_hi = _half(-whi, sub_up(y, g1lo))           # g1lo - σ whi <= y
    d_lo, d_hi = _half(wlo, sub_up(g1hi, x))            # g1hi - σ wlo >= x
    tau_lo, tau_hi = max(a_lo, b_lo), min(a_hi, b_hi)
    sig_lo, sig_hi = max(c_lo, d_lo), min(c_hi, d_hi)
    if not (tau_lo <= tau_hi and sig_lo <= sig_hi):
        return INF, -INF
    lo = max(t0, add_dn(t0, tau_lo), sub_dn(t1, sig_hi))
    hi = min(t1, add_up(t0, tau_hi), sub_up(t1, sig_lo))
    return (lo, hi) if lo <= hi else (INF, -INF)


@_njit
def invert_pieces(t: NDArray, slo: NDArray, shi: NDArray, glo: NDArray, ghi: NDArray,
                  wlo: NDArray, whi: NDArray, tlo: float, thi: float, zlo: float, zhi: float,
                  plo: NDArray, phi: NDArray) -> None:
    """Intersect, slice by slice, the time pieces ``[plo[i], phi[i]]`` (``plo > phi``: none)
    with the times in ``[tlo, thi]`` (inside the domain, ``tlo <= thi``) at which a trajectory
    of the scalar tube with ``y' ∈ [w]`` may lie in ``[z]`` (on each slice, the polygon of the
    two cones from its gates inside its envelope, projected exactly; Rohou et al. 2018 use the
    same polygon), in place. Start from ``(-INF, INF)`` everywhere and call it once per
    component: the pieces are then the times at which every component may meet its ``[z]``
    at the same time, slice by slice (a hull per component would lose that dependency)."""
    n = slo.size
    i0 = min(max(np.searchsorted(t, tlo, side="right") - 1, 0), n - 1)
    i1 = min(max(np.searchsorted(t, thi, side="left"), i0 + 1), n)
    for i in range(n):
        if not (i0 <= i < i1 and plo[i] <= phi[i]):
            plo[i], phi[i] = INF, -INF
            continue
        p, q = max(t[i], tlo, plo[i]), min(t[i + 1], thi, phi[i])
        x, y = max(slo[i], zlo), min(shi[i], zhi)
        a, b = INF, -INF
        if p <= q and x <= y:
            a, b = _slice_times(t[i], t[i + 1], glo[i], ghi[i], glo[i + 1], ghi[i + 1], wlo[i],
                                whi[i], x, y)
            a, b = max(a, p), min(b, q)
        plo[i], phi[i] = (a, b) if a <= b else (INF, -INF)


@_njit
def values_over_pieces(t: NDArray, slo: NDArray, shi: NDArray, glo: NDArray, ghi: NDArray,
                       wlo: NDArray, whi: NDArray, plo: NDArray, phi: NDArray
                       ) -> tuple[float, float]:
    """The hull of the values that trajectories of the scalar tube with ``y' ∈ [w]`` take over
    the time pieces ``[plo[i], phi[i]] ⊂`` slice ``i`` (each bounded by the polygon between
    virtual gates at the piece's ends: the cone bounds there, inside the envelope);
    ``(INF, -INF)`` when there is no piece."""
    ylo, yhi = INF, -INF
    for i in range(slo.size):
        a, b = plo[i], phi[i]
        if not a <= b:
            continue
        va = _cone(t[i], t[i + 1], a, glo[i], ghi[i], glo[i + 1], ghi[i + 1], wlo[i], whi[i])
        vb = _cone(t[i], t[i + 1], b, glo[i], ghi[i], glo[i + 1], ghi[i + 1], wlo[i], whi[i])
        h_dn, h_up = _dur(a, b)
        hi = min(shi[i], slice_hi(va[1], vb[1], wlo[i], whi[i], h_dn, h_up))
        lo = max(slo[i], -slice_hi(-va[0], -vb[0], -whi[i], -wlo[i], h_dn, h_up))
        ylo, yhi = min(ylo, lo), max(yhi, hi)
    return ylo, yhi


@_njit
def invert_kernel(t: NDArray, slo: NDArray, shi: NDArray, glo: NDArray, ghi: NDArray,
                  wlo: NDArray, whi: NDArray, tlo: float, thi: float, zlo: float, zhi: float
                  ) -> tuple[float, float, float, float]:
    """``[t] ∩ [y]^{-1}([z])`` with the derivative, for a scalar tube: the hull of the pieces
    of :func:`invert_pieces`, and ``[z]`` ∩ the values over them
    (:func:`values_over_pieces`). Returns ``(t_lo, t_hi, z_lo, z_hi)``, ``t_lo > t_hi`` when
    no trajectory meets ``[z]`` in ``[t]``."""
    plo, phi = np.full(slo.size, -INF), np.full(slo.size, INF)
    invert_pieces(t, slo, shi, glo, ghi, wlo, whi, tlo, thi, zlo, zhi, plo, phi)
    rlo, rhi = _pieces_hull(plo, phi)
    if not rlo <= rhi:
        return INF, -INF, INF, -INF
    ylo, yhi = values_over_pieces(t, slo, shi, glo, ghi, wlo, whi, plo, phi)
    return rlo, rhi, max(ylo, zlo), min(yhi, zhi)


@_njit
def _pieces_hull(plo: NDArray, phi: NDArray) -> tuple[float, float]:
    rlo, rhi = INF, -INF
    for i in range(plo.size):
        if plo[i] <= phi[i]:
            rlo, rhi = min(rlo, plo[i]), max(rhi, phi[i])
    return rlo, rhi


@_njit
def _cone(t0: float, t1: float, s: float, g0lo: float, g0hi: float, g1lo: float, g1hi: float,
          wlo: float, whi: float) -> tuple[float, float]:
    """Bounds at ``s ∈ [t0, t1]`` of the trajectories through the gates with ``y' ∈ [w]``."""
    if s == t0:
        return g0lo, g0hi
    if s == t1:
        return g1lo, g1hi
    tau_dn, tau_up = _dur(t0, s)
    sig_dn, sig_up = _dur(s, t1)
    lo, hi = -INF, INF
    for c in (_lin_dn(g0lo, tau_dn, tau_up, wlo), _lin_dn(g1lo, sig_dn, sig_up, -whi)):
        if c > lo:  # a NaN bound (inf - inf) is dropped
            lo = c
    for c in (_lin_up(g0hi, tau_dn, tau_up, whi), _lin_up(g1hi, sig_dn, sig_up, -wlo)):
        if c < hi:
            hi = c
    return lo, hi


@_njit
def eval_kernel(t: NDArray, slo: NDArray, shi: NDArray, glo: NDArray, ghi: NDArray,
                wlo: NDArray, whi: NDArray, tlo: float, thi: float, zlo: float, zhi: float
                ) -> bool:
    """Contract the scalar tube ``(slo, shi, glo, ghi)`` in place with ``z = y(t)``,
    ``t ∈ [tlo, thi]`` (inside the domain, non-empty), ``z ∈ [zlo, zhi]``, ``y' ∈ [w]``.
    Returns ``False`` when no trajectory meets the measurement."""
    n = slo.size
    # slices meeting [t] with a positive-length part: i0 .. i1-1; gates in [t]: k0 .. k1-1
    k0 = np.searchsorted(t, tlo, side="left")
    k1 = np.searchsorted(t, thi, side="right")
    i0 = np.searchsorted(t, tlo, side="right") - 1
    i1 = np.searchsorted(t, thi, side="left")
    i0 = min(max(i0, 0), n - 1)
    i1 = max(min(i1, n), i0)
    if i1 == i0 + 1 and not (t[i0] < thi and t[i0 + 1] > tlo):
        i1 = i0  # [t] is a gate time: no slice interior
    if i1 == i0 and not (t[i0] < thi and t[i0 + 1] > tlo) and k0 >= k1:
        return False
    # the region of gates touched by [t]: ra .. rb (inclusive)
    ra = min(i0, k0) if i1 > i0 else k0
    rb = max(i1, k1 - 1) if i1 > i0 else k1 - 1
    m = rb - ra + 1
    # B over the region (gates and slices), backward
    Blo = np.full(m, INF)
    Bhi = np.full(m, -INF)
    SBlo = np.full(max(m - 1, 1), INF)
    SBhi = np.full(max(m - 1, 1), -INF)
    for k in range(rb, ra - 1, -1):
        lo, hi = INF, -INF
        if k < rb:
            i = k  # slice between gate k and k+1
            h_dn, h_up = _dur(t[i], t[i + 1])
            blo, bhi = Blo[k + 1 - ra], Bhi[k + 1 - ra]
            slo_b, shi_b = INF, -INF
            if blo <= bhi:
                lo = _lin_dn(blo, h_dn, h_up, -whi[i])
                hi = _lin_up(bhi, h_dn, h_up, -wlo[i])
                slo_b = add_dn(blo, min(0.0, _mul_lo(h_dn, h_up, -whi[i])))
                shi_b = add_up(bhi, max(0.0, _mul_hi(h_dn, h_up, -wlo[i])))
            if i0 <= i < i1:
                zl, zh = max(zlo, slo[i]), min(zhi, shi[i])
                if zl <= zh:
                    p, q = max(t[i], tlo), min(t[i + 1], thi)
                    d0, _ = _dur(t[i], p)
                    _, d1 = _dur(t[i], q)
                    lo = min(lo, add_dn(zl, _mul_lo(d0, d1, -whi[i])))
                    hi = max(hi, add_up(zh, _mul_hi(d0, d1, -wlo[i])))
                    # B on the slice from t1 <= q: durations t1 - s in [0, q - t_i]
                    slo_b = min(slo_b, add_dn(zl, _mul_lo(0.0, d1, -whi[i])))
                    shi_b = max(shi_b, add_up(zh, _mul_hi(0.0, d1, -wlo[i])))
            SBlo[k - ra], SBhi[k - ra] = slo_b, shi_b
        if k0 <= k < k1:
            lo, hi = min(lo, max(zlo, glo[k])), max(hi, min(zhi, ghi[k]))
        lo, hi = max(lo, glo[k]), min(hi, ghi[k])
        if k < rb:  # and inside the backward cone of the next gate (y' = w on every trajectory)
            h_dn, h_up = _dur(t[k], t[k + 1])
            lo = max(lo, _lin_dn(glo[k + 1], h_dn, h_up, -whi[k]))
            hi = min(hi, _lin_up(ghi[k + 1], h_dn, h_up, -wlo[k]))
        if not lo <= hi:
            lo, hi = INF, -INF
        Blo[k - ra], Bhi[k - ra] = lo, hi
    # F forward from ra to the end, contracting the region and beyond
    flo, fhi = INF, -INF
    for k in range(ra, n + 1):
        lo, hi = INF, -INF
        if k > ra:
            i = k - 1
            h_dn, h_up = _dur(t[i], t[i + 1])
            slo_f, shi_f = INF, -INF
            if flo <= fhi:
                lo = _lin_dn(flo, h_dn, h_up, wlo[i])
                hi = _lin_up(fhi, h_dn, h_up, whi[i])
                slo_f = add_dn(flo, min(0.0, _mul_lo(h_dn, h_up, wlo[i])))
                shi_f = add_up(fhi, max(0.0, _mul_hi(h_dn, h_up, whi[i])))
            if i0 <= i < i1:
                zl, zh = max(zlo, slo[i]), min(zhi, shi[i])
                if zl <= zh:
                    p, q = max(t[i], tlo), min(t[i + 1], thi)
                    d0, _ = _dur(q, t[i + 1])
                    _, d1 = _dur(p, t[i + 1])
                    lo = min(lo, add_dn(zl, _mul_lo(d0, d1, wlo[i])))
                    hi = max(hi, add_up(zh, _mul_hi(d0, d1, whi[i])))
                    # F on the slice from t1 >= p: durations s - t1 in [0, t_{i+1} - p]
                    slo_f = min(slo_f, add_dn(zl, _mul_lo(0.0, d1, wlo[i])))
                    shi_f = max(shi_f, add_up(zh, _mul_hi(0.0, d1, whi[i])))
        if k0 <= k < k1:
            lo, hi = min(lo, max(zlo, glo[k])), max(hi, min(zhi, ghi[k]))
        covers = lo <= glo[k] and hi >= ghi[k]
        lo, hi = max(lo, glo[k]), min(hi, ghi[k])
        if not lo <= hi:
            lo, hi = INF, -INF
        if k <= rb:  # gate inside the region: F ∪ B, inside the cone of the previous gate
            gl, gh = min(lo, Blo[k - ra]), max(hi, Bhi[k - ra])
            if k > ra:
                h_dn, h_up = _dur(t[k - 1], t[k])
                gl = max(gl, _lin_dn(glo[k - 1], h_dn, h_up, wlo[k - 1]))
                gh = min(gh, _lin_up(ghi[k - 1], h_dn, h_up, whi[k - 1]))
        else:
            gl, gh = lo, hi
        if not gl <= gh:
            return False
        if k > ra:
            i = k - 1
            h_dn, h_up = _dur(t[i], t[i + 1])
            if k <= rb:
                # slice inside the region: hull of the F and B boxes, and the polygon between
                # the contracted gates (the constraint y' = w holds on every trajectory)
                sl = max(min(slo_f, SBlo[i - ra]),
                         -slice_hi(-glo[i], -gl, -whi[i], -wlo[i], h_dn, h_up))
                sh = min(max(shi_f, SBhi[i - ra]),
                         slice_hi(ghi[i], gh, wlo[i], whi[i], h_dn, h_up))
            else:  # after [t]: the polygon between F gates
                sl, sh = INF, -INF
                if flo <= fhi and lo <= hi:
                    sh = slice_hi(fhi, hi, wlo[i], whi[i], h_dn, h_up)
                    sl = -slice_hi(-flo, -lo, -whi[i], -wlo[i], h_dn, h_up)
            sl, sh = max(sl, slo[i]), min(sh, shi[i])
            if not sl <= sh:
                return False
            slo[i], shi[i] = sl, sh
        glo[k], ghi[k] = gl, gh
        flo, fhi = lo, hi
        if k > rb and covers:
            break
    # B backward from ra to the start
    blo, bhi = Blo[0], Bhi[0]
    for k in range(ra - 1, -1, -1):
        i = k
        h_dn, h_up = _dur(t[i], t[i + 1])
        lo = _lin_dn(blo, h_dn, h_up, -whi[i])
        hi = _lin_up(bhi, h_dn, h_up, -wlo[i])
        covers = lo <= glo[k] and hi >= ghi[k]
        lo, hi = max(lo, glo[k]), min(hi, ghi[k])
        if not lo <= hi:
            return False
        sh = slice_hi(hi, bhi, wlo[i], whi[i], h_dn, h_up)
        sl = -slice_hi(-lo, -blo, -whi[i], -wlo[i], h_dn, h_up)
        sl, sh = max(sl, slo[i]), min(sh, shi[i])
        if not sl <= sh:
            return False
        slo[i], shi[i] = sl, sh
        glo[k], ghi[k] = lo, hi
        blo, bhi = lo, hi
        if covers:
            break
    return True


class CtcEval:
    """Contractor for ``z = y(t)``, ``t ∈ [t]``, ``z ∈ [z]``, ``y'(.) ∈ [w](.)`` (Rohou et al. 2018
    Proposition 2).

    ``contract(t, z, y, w)`` contracts the scalar intervals ``t`` and ``z`` and the tube ``y`` in
    place (``w`` is unchanged) and returns ``(t, z)``. For a tube vector, ``z`` is a box and the
    constraint holds componentwise at the same time ``t``: the times are those at which every
    component may meet its ``[z_j]``, intersected slice by slice (not the hull of each
    component's times, which would lose the dependency on ``t``), and ``[z_j]`` the values of
    component ``j`` over them. When the measurement cannot be met,
    ``t``, ``z`` and ``y`` all become empty.

    Only the slices of ``w`` are read: the derivative may jump at every gate (a tube with
    ``continuous=False``). ``y`` has a derivative, so a tube ``y`` with jumps is made
    continuous first (:meth:`Tube.make_continuous`).

    Parameters
    ----------
    time_deriv : bool
        ``True`` (default): ``[t]`` is contracted with the derivative, to the times at which a
        trajectory of the slice polygons (the cones of ``y' = w`` from the gates, inside the
        envelope) meets ``[z]``, so ``[t]`` shrinks inside a slice; ``[z]`` to the values of
        those trajectories over the new ``[t]`` (virtual gates at its bounds); and both again
        after the tube is contracted (as Codac's ``CtcEval`` does with ``y.invert(z, w, t)``).
        ``False``: the plain tube inverse ``[y]^{-1}([z])`` (whole slices and gates) and
        ``[y]`` over them, once; cheaper, wider.

    Examples
    --------
    >>> y = Tube.constant(0, 10, 100, Interval(-10, 10))
    >>> w = Tube.constant(0, 10, 100, Interval(1, 1))
    >>> t, z = Interval(2, 8), Interval(0, 0)
    >>> _ = CtcEval().contract(t, z, y, w)
    >>> bool(y(9).hi <= 7.0)
    True
    """

    def __init__(self, time_deriv: bool = True) -> None:
        self.time_deriv = bool(time_deriv)

    def __repr__(self) -> str:
        return f"CtcEval(time_deriv={self.time_deriv})"

    def contract(self, t: Interval, z: Interval, y: Tube, w: Tube) -> tuple[Interval, Interval]:
        t, z = as_interval(t), as_interval(z)
        if t.ndim != 0:
            raise ValueError(f"CtcEval: t must be a scalar interval, got shape {t.shape}")
        if z.shape != y.slices.shape[1:]:
            raise ValueError(f"CtcEval: z of shape {z.shape} does not match the tube's values "
                             f"{y.slices.shape[1:]}")
        if not np.array_equal(y.t, w.t) or y.slices.shape != w.slices.shape:
            raise ValueError("CtcEval: y and w must share their gate times and dimension")
        y.make_continuous()
        t0, tf = y.domain
        ok = not (t.is_empty() or np.any(z.is_empty()) or y.is_empty() or w.is_empty())
        tl, th = (max(float(t.lo), t0), min(float(t.hi), tf)) if ok else (1.0, 0.0)
        ok = ok and tl <= th
        comps = [y[j] for j in range(y.dim)] if y.is_vector else [y]
        wcomps = [w[j] for j in range(w.dim)] if w.is_vector else [w]
        zlo = np.array(z.lo, dtype=np.float64).reshape(-1)
        zhi = np.array(z.hi, dtype=np.float64).reshape(-1)
        if ok and self.time_deriv:
            ok, tl, th = _invert_all(comps, wcomps, tl, th, zlo, zhi)
        elif ok:  # [t] ∩ [y]^{-1}([z]) and [z] ∩ [y]([t]), slices and gates common to all
            ok, tl, th = _plain_invert_all(y, tl, th, zlo, zhi)
        if ok:
            for j, (yj, wj) in enumerate(zip(comps, wcomps, strict=True)):
                ok = eval_kernel(yj.t, yj.slices.lo, yj.slices.hi, yj.gates.lo, yj.gates.hi,
                                 wj.slices.lo, wj.slices.hi, tl, th, float(zlo[j]),
                                 float(zhi[j]))
                if not ok:
                    break
        if ok and self.time_deriv:  # again on the contracted tube
            ok, tl, th = _invert_all(comps, wcomps, tl, th, zlo, zhi)
        if ok:
            t.lo[...], t.hi[...] = tl, th
            z.lo[...], z.hi[...] = zlo.reshape(z.shape), zhi.reshape(z.shape)
        else:
            t.lo[...] = t.hi[...] = np.nan
            z.lo[...] = z.hi[...] = np.nan
            y.set_empty()
        return t, z

    __call__ = contract


def _invert_all(comps: list[Tube], wcomps: list[Tube], tl: float, th: float, zlo: NDArray,
                zhi: NDArray) -> tuple[bool, float, float]:
    """``[t]`` and every ``[z_j]`` by the time pieces common to all components
    (:func:`invert_pieces`, slice by slice: the same ``t`` for every component), ``[t]`` their
    hull and ``[z_j]`` the values of component ``j`` over them, in place. Returns
    ``(ok, t_lo, t_hi)``."""
    n = comps[0].n_slices
    plo, phi = np.full(n, -INF), np.full(n, INF)
    for j, (yj, wj) in enumerate(zip(comps, wcomps, strict=True)):
        invert_pieces(yj.t, yj.slices.lo, yj.slices.hi, yj.gates.lo, yj.gates.hi,
                      wj.slices.lo, wj.slices.hi, tl, th, float(zlo[j]), float(zhi[j]), plo,
                      phi)
    a, b = _pieces_hull(plo, phi)
    if not a <= b:
        return False, tl, th
    for j, (yj, wj) in enumerate(zip(comps, wcomps, strict=True)):
        c, d = values_over_pieces(yj.t, yj.slices.lo, yj.slices.hi, yj.gates.lo, yj.gates.hi,
                                  wj.slices.lo, wj.slices.hi, plo, phi)
        c, d = max(c, float(zlo[j])), min(d, float(zhi[j]))
        if not c <= d:
            return False, tl, th
        zlo[j], zhi[j] = c, d
    return True, max(tl, a), min(th, b)


def _plain_invert_all(y: Tube, tl: float, th: float, zlo: NDArray, zhi: NDArray
                      ) -> tuple[bool, float, float]:
    """``[t] ∩ [y]^{-1}([z])`` on whole slices and gates (no derivative): the slices meeting
    ``]tl, th[`` and the gates in ``[tl, th]`` where every component meets its ``[z_j]`` (the
    same time for all: a hull per component would lose that dependency); ``[t]`` their hull
    within ``[tl, th]``, ``[z_j]`` ∩ the hull of component ``j`` over them, in place.
    Returns ``(ok, t_lo, t_hi)``."""
    t = y.t
    d = zlo.size

    def common(v: Interval) -> tuple[NDArray, NDArray, NDArray]:
        lo, hi = np.asarray(v.lo).reshape(-1, d), np.asarray(v.hi).reshape(-1, d)
        return np.all((lo <= zhi) & (hi >= zlo), axis=1), lo, hi

    if tl == th:
        hit, lo, hi = common(y._eval_points(np.array([tl])))
        starts = ends = np.array([tl])
    else:
        i0, i1 = y.slice_range(tl, th)
        g0 = int(np.searchsorted(t, tl, side="left"))
        g1 = int(np.searchsorted(t, th, side="right"))
        ms, slo, shi = common(y.slices[i0:i1])
        mg, glo, ghi = common(y.gates[g0:g1])
        hit = np.concatenate([ms, mg])
        lo, hi = np.concatenate([slo, glo]), np.concatenate([shi, ghi])
        starts = np.concatenate([np.maximum(t[i0:i1], tl), t[g0:g1]])
        ends = np.concatenate([np.minimum(t[i0 + 1:i1 + 1], th), t[g0:g1]])
    if not hit.any():
        return False, tl, th
    zlo[:] = np.maximum(zlo, lo[hit].min(axis=0))
    zhi[:] = np.minimum(zhi, hi[hit].max(axis=0))
    return bool(np.all(zlo <= zhi)), float(starts[hit].min()), float(ends[hit].max())
