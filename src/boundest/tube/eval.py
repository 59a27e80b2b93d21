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
from ..interval.rounding import INF, add_dn, add_up, mul_dn, mul_up, sub_dn, sub_up
from .deriv import _lin_dn, _lin_up, slice_hi
from .tube import Tube

__all__ = ["CtcEval", "eval_kernel"]

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
                    slo_b = min(slo_b, add_dn(zl, min(0.0, _mul_lo(h_dn, h_up, -whi[i]))))
                    shi_b = max(shi_b, add_up(zh, max(0.0, _mul_hi(h_dn, h_up, -wlo[i]))))
            SBlo[k - ra], SBhi[k - ra] = slo_b, shi_b
        if k0 <= k < k1:
            lo, hi = min(lo, max(zlo, glo[k])), max(hi, min(zhi, ghi[k]))
        lo, hi = max(lo, glo[k]), min(hi, ghi[k])
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
                    slo_f = min(slo_f, add_dn(zl, min(0.0, _mul_lo(h_dn, h_up, wlo[i]))))
                    shi_f = max(shi_f, add_up(zh, max(0.0, _mul_hi(h_dn, h_up, whi[i]))))
        if k0 <= k < k1:
            lo, hi = min(lo, max(zlo, glo[k])), max(hi, min(zhi, ghi[k]))
        covers = lo <= glo[k] and hi >= ghi[k]
        lo, hi = max(lo, glo[k]), min(hi, ghi[k])
        if not lo <= hi:
            lo, hi = INF, -INF
        if k <= rb:  # gate inside the region: F ∪ B
            gl, gh = min(lo, Blo[k - ra]), max(hi, Bhi[k - ra])
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
    constraint holds componentwise at the same time ``t``. When the measurement cannot be met,
    ``t``, ``z`` and ``y`` all become empty.

    Only the slices of ``w`` are read: the derivative may jump at every gate (a tube with
    ``continuous=False``). ``y`` has a derivative, so a tube ``y`` with jumps is made
    continuous first (:meth:`Tube.make_continuous`).

    Examples
    --------
    >>> y = Tube.constant(0, 10, 100, Interval(-10, 10))
    >>> w = Tube.constant(0, 10, 100, Interval(1, 1))
    >>> t, z = Interval(2, 8), Interval(0, 0)
    >>> _ = CtcEval().contract(t, z, y, w)
    >>> bool(y(9).hi <= 7.0)
    True
    """

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
        zs = [z[j] for j in range(y.dim)] if y.is_vector else [z]
        if ok:  # [t] ∩ [y]^{-1}([z]) for every component, then [z] ∩ [y]([t])
            for yj, zj in zip(comps, zs, strict=True):
                inv = yj.inverse(zj, hull=True, within=Interval(tl, th))
                if inv.is_empty():
                    ok = False
                    break
                tl, th = float(inv.lo), float(inv.hi)
        znew = z & y(Interval(tl, th)) if ok else z
        ok = ok and not np.any(znew.is_empty())
        if ok:
            zs = [znew[j] for j in range(y.dim)] if y.is_vector else [znew]
            for yj, wj, zj in zip(comps, [w[j] for j in range(w.dim)] if w.is_vector else [w],
                                  zs, strict=True):
                ok = eval_kernel(yj.t, yj.slices.lo, yj.slices.hi, yj.gates.lo, yj.gates.hi,
                                 wj.slices.lo, wj.slices.hi, tl, th, float(zj.lo), float(zj.hi))
                if not ok:
                    break
        if ok:
            t.lo[...], t.hi[...] = tl, th
            z.lo[...], z.hi[...] = znew.lo, znew.hi
        else:
            t.lo[...] = t.hi[...] = np.nan
            z.lo[...] = z.hi[...] = np.nan
            y.set_empty()
        return t, z

    __call__ = contract
