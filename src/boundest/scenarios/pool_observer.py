"""The compiled robust observer of the pool robot (Jaulin's robust set-membership observer).

State boxes ``(x, y, theta, v)``; one update per sonar ping. The observer keeps, for the last
``m`` pings ``j`` (the window), the state box ``S_j`` at the ping's time, the input box
``U_j`` applied from ``j`` to ``j + 1``, the ping ``(alpha_j, [d_j])`` and ``F_j``: the set at the
current time ``k`` of the states consistent with ping ``j`` (its contraction at time ``j``,
carried to ``k`` by the dynamics). Under the hypothesis *H*: "at most ``q`` of the window's
pings are outliers" the state ``x_k`` is in every inlier's ``F_j``, hence in their q-relaxed
intersection::

    X_k = S_k ∩ ⋂^{q}_{j = k-m+1..k} F_j

One update:

1. **Prediction.** ``S_k = f(S_{k-1}, U_{k-1}) ∩ P_k`` (recursive) or ``S_j = P_j`` for the
   whole window (``carry=False``, the pure window observer), where ``P_k`` is the open-loop
   prediction of ``x0`` (every input box, no ping), kept inside the pool and the speed bound:
   a set that certainly holds ``x_k``.
2. **The new ping** contracts ``S_k`` (:func:`boundest.ctc.raycast_box` on
   ``(x, y, theta + alpha, d)``) into ``F_k``; the older ``F_j`` are carried one step
   (``F_j = f(F_j, U_{k-1}) ∩ S_k``) and ``X_k`` is their q-relaxed intersection.
3. **Smoothing inside the window** (``sweeps`` times): ``S_k = X_k``; the window's states are
   contracted backward (``S_j ∩= f^{-1}(S_{j+1})``) and forward again; every ping ``j`` is
   contracted again on its smaller ``S_j`` and carried to ``k`` through the ``S``; ``X_k`` is
   their q-relaxed intersection again. Each step is valid under *H*, so it keeps ``x_k``.

**Heading slices** (:func:`bank_update`). The set may be a union of boxes, each with its own
window (its own ``S_j`` and ``F_j``): before an update, every slice whose heading at ``k - 1``
is wider than ``eps[2]`` is cut in two there; each slice is updated as above; a slice that
comes out empty is dropped (under *H* the state is not in it); beyond the cap the two
neighbouring slices whose hull is thinnest in heading are merged (the hull of their windows).
A slice carries its own past: on a thin heading the pings pin the position, and the past
states stay thin too, which cutting the hull again at every step would not keep. ``X_k`` is
the hull of the slices; a ping is rejected when every slice rejects it.

**Guarantee.** The recursive set (``carry=True``) holds ``x_k`` when every window since the
start (or the last restart) held at most ``q`` outliers; the pure window set holds it when the
window at ``k`` did, an event of probability ``P(at most q outliers among m pings)``. When
``X_k`` comes out empty (more than ``q`` outliers, or a model error) the recursive observer says
so and restarts from the window alone (step 1 with ``carry=False``: the prior is ``P``, which
holds the state whatever the pings); if even that is empty, ``X_k = P_k``.

**Rounding.** Every operation is outward rounded, and each Euler step is widened by
``2^-50 (|result| + |increment|)`` on each side, which covers the float64 evaluation of
``X + dt f(X, u)`` by which the data were made (libm's cos/sin within 1 ulp, three roundings
in the increment, one in the sum); each range box is widened by a relative ``2^-40`` for the
float64 evaluation of the first-hit distance.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from ..ctc.raycast import raycast_box
from ..interval import arith as ar
from ..interval import trig as tr
from ..interval.relaxed import covered_hull

__all__ = ["bank_update", "make_bank", "observer_update", "run_missions"]

_njit = nb.njit(cache=True, error_model="numpy")
_inline = nb.njit(cache=True, inline="always", error_model="numpy")
_add_lo, _add_hi = ar._add_lo.scalar, ar._add_hi.scalar
_sub_lo, _sub_hi = ar._sub_lo.scalar, ar._sub_hi.scalar
_mul_lo, _mul_hi = ar._mul_lo.scalar, ar._mul_hi.scalar
_div_lo, _div_hi = ar._div_lo.scalar, ar._div_hi.scalar
_sin, _cos = tr._sin.scalar, tr._cos.scalar
_PAD = 2.0**-50
_D_PAD = 2.0**-40

# kernel parameters: par = [m, q, sweeps, passes, carry]
M, Q, SWEEPS, PASSES, CARRY = range(5)
#: Most cells per axis of the paving of (x, y) at one step.
MAX_SIDE = 64


@_inline
def _pad(lo, hi, mag):
    """``[lo, hi]`` widened by ``2^-50 mag`` on each side, then one ulp (rounding of the pad)."""
    e = _PAD * mag
    return np.nextafter(lo - e, -np.inf), np.nextafter(hi + e, np.inf)


@_inline
def _mag(lo, hi):
    return max(abs(lo), abs(hi))


@_njit
def _step(sl, sh, ul, uh, hl, hh, ol, oh, buf):
    """``o = f(s, u)``: one Euler step of the box ``s`` with the input box ``u`` (``h`` = dt)."""
    _cos(sl[2], sh[2], buf[0:1], buf[1:2])
    _sin(sl[2], sh[2], buf[2:3], buf[3:4])
    hvl, hvh = _mul_lo(hl, hh, sl[3], sh[3]), _mul_hi(hl, hh, sl[3], sh[3])
    for c in range(2):  # position: p + h v (cos, sin)
        il = _mul_lo(hvl, hvh, buf[2 * c], buf[2 * c + 1])
        ih = _mul_hi(hvl, hvh, buf[2 * c], buf[2 * c + 1])
        lo, hi = _add_lo(sl[c], sh[c], il, ih), _add_hi(sl[c], sh[c], il, ih)
        ol[c], oh[c] = _pad(lo, hi, _mag(lo, hi) + _mag(il, ih))
    dl, dh = _sub_lo(ul[1], uh[1], ul[0], uh[0]), _sub_hi(ul[1], uh[1], ul[0], uh[0])
    il, ih = _mul_lo(hl, hh, dl, dh), _mul_hi(hl, hh, dl, dh)
    lo, hi = _add_lo(sl[2], sh[2], il, ih), _add_hi(sl[2], sh[2], il, ih)
    ol[2], oh[2] = _pad(lo, hi, _mag(lo, hi) + _mag(il, ih))
    # v + h (u1 + u2 - v) = (1 - h) v + h (u1 + u2): one occurrence of v
    gl, gh = _sub_lo(1.0, 1.0, hl, hh), _sub_hi(1.0, 1.0, hl, hh)
    al, ah = _mul_lo(gl, gh, sl[3], sh[3]), _mul_hi(gl, gh, sl[3], sh[3])
    sl_, sh_ = _add_lo(ul[0], uh[0], ul[1], uh[1]), _add_hi(ul[0], uh[0], ul[1], uh[1])
    bl, bh = _mul_lo(hl, hh, sl_, sh_), _mul_hi(hl, hh, sl_, sh_)
    lo, hi = _add_lo(al, ah, bl, bh), _add_hi(al, ah, bl, bh)
    ol[3], oh[3] = _pad(lo, hi, _mag(lo, hi) + _mag(sl[3], sh[3]) + _mag(bl, bh))


@_inline
def _meet(l, h, ol, oh):
    """``[l, h] ∩= [ol, oh]`` componentwise; False when empty."""
    ok = True
    for c in range(l.size):
        l[c] = max(l[c], ol[c])
        h[c] = min(h[c], oh[c])
        ok = ok and l[c] <= h[c]
    return ok


@_inline
def _equal(al, ah, bl, bh):
    """Whether the boxes ``a`` and ``b`` have equal bounds (False where one is NaN)."""
    same = True
    for c in range(al.size):
        same = same and al[c] == bl[c] and ah[c] == bh[c]
    return same


@_njit
def _back(sl, sh, nl, nh, ul, uh, hl, hh, buf):
    """Contract ``s`` (in place) with ``n = f(s, u)``: the Euler step solved for ``s``."""
    dl, dh = _sub_lo(ul[1], uh[1], ul[0], uh[0]), _sub_hi(ul[1], uh[1], ul[0], uh[0])
    il, ih = _mul_lo(hl, hh, dl, dh), _mul_hi(hl, hh, dl, dh)
    lo, hi = _pad(_sub_lo(nl[2], nh[2], il, ih), _sub_hi(nl[2], nh[2], il, ih),
                  _mag(nl[2], nh[2]) + _mag(il, ih))
    sl[2], sh[2] = max(sl[2], lo), min(sh[2], hi)
    gl, gh = _sub_lo(1.0, 1.0, hl, hh), _sub_hi(1.0, 1.0, hl, hh)
    al, ah = _add_lo(ul[0], uh[0], ul[1], uh[1]), _add_hi(ul[0], uh[0], ul[1], uh[1])
    bl, bh = _mul_lo(hl, hh, al, ah), _mul_hi(hl, hh, al, ah)
    rl, rh = _pad(_sub_lo(nl[3], nh[3], bl, bh), _sub_hi(nl[3], nh[3], bl, bh),
                  2.0 * _mag(nl[3], nh[3]) + _mag(bl, bh))  # |v| ~ |v'|: the sum's terms
    lo, hi = _div_lo(rl, rh, gl, gh), _div_hi(rl, rh, gl, gh)
    sl[3], sh[3] = max(sl[3], lo), min(sh[3], hi)
    if not (sl[2] <= sh[2] and sl[3] <= sh[3]):
        return False
    _cos(sl[2], sh[2], buf[0:1], buf[1:2])
    _sin(sl[2], sh[2], buf[2:3], buf[3:4])
    hvl, hvh = _mul_lo(hl, hh, sl[3], sh[3]), _mul_hi(hl, hh, sl[3], sh[3])
    for c in range(2):
        il = _mul_lo(hvl, hvh, buf[2 * c], buf[2 * c + 1])
        ih = _mul_hi(hvl, hvh, buf[2 * c], buf[2 * c + 1])
        lo, hi = _pad(_sub_lo(nl[c], nh[c], il, ih), _sub_hi(nl[c], nh[c], il, ih),
                      _mag(nl[c], nh[c]) + _mag(il, ih))
        sl[c], sh[c] = max(sl[c], lo), min(sh[c], hi)
        if not sl[c] <= sh[c]:
            return False
    return True


@_njit
def _ping(sl, sh, alpha, dl, dh, par, tp, ol, oh, scratch):
    """``o`` = the state box ``s`` contracted with the ping ``(alpha, [dl, dh])``; False when
    empty. ``tp``: the packed ray-cast tapes (:class:`boundest.ctc.raycast.RayTapes`)."""
    bl, bh = scratch[0][:4], scratch[1][:4]
    bl[0], bh[0], bl[1], bh[1] = sl[0], sh[0], sl[1], sh[1]
    bl[2], bh[2] = _add_lo(sl[2], sh[2], alpha, alpha), _add_hi(sl[2], sh[2], alpha, alpha)
    # the data's distance is the float64 evaluation of the first-hit formulas: a relative
    # 2^-40 covers its rounding (the reading's box holds that float, not the exact distance)
    bl[3], bh[3] = dl - _D_PAD * abs(dl), dh + _D_PAD * abs(dh)
    # np.int64(3), not the literal 3: raycast_box would be compiled a second time for it
    if not raycast_box(bl, bh, par[PASSES], np.int64(3), tp[0], tp[1], tp[2], tp[3], tp[4],
                       tp[5], tp[6], tp[7], tp[8], tp[9], tp[10], tp[11], tp[12], tp[13],
                       tp[14], tp[15], tp[16], scratch[2], scratch[3], scratch[4]):
        return False
    ol[0], oh[0], ol[1], oh[1] = bl[0], bh[0], bl[1], bh[1]
    ol[2] = max(sl[2], _sub_lo(bl[2], bh[2], alpha, alpha))
    oh[2] = min(sh[2], _sub_hi(bl[2], bh[2], alpha, alpha))
    ol[3], oh[3] = sl[3], sh[3]
    return ol[2] <= oh[2]


@_njit
def _qinter(FL, FH, first, k, m, q, xl, xh, lows, highs, col_lo, col_hi):
    """``x ∩= `` the hull of the q-relaxed intersection of the ``F_j``, ``j = first..k``;
    False when empty.

    Per component, the projection hull (exact for intervals: the reals covered by at least
    ``w - q`` of the ``w`` projections). Then the pings whose ``F_j`` misses ``x`` (in any
    component) are dropped from the counts of every component and the projection is taken
    again, until no ping is dropped: a point of the q-relaxed set lies in ``x``, so it fails
    every dropped ping, and still lies in ``w - q`` of the others. The projections alone count
    each component apart; the drops carry what one component proves into the others.
    """
    w = k - first + 1
    need = w - q
    if need <= 0:
        return True
    dropped = -1
    while True:
        n = np.int64(0)  # not the literal 0: covered_hull would be compiled again for it
        for j in range(first, k + 1):  # the pings still in the count
            js = j % m
            hit = True
            for c in range(4):
                hit = hit and FL[js, c] <= FH[js, c] and FL[js, c] <= xh[c] and \
                    FH[js, c] >= xl[c]
            if hit:
                lows[n] = j  # (lows doubles as the list of kept pings)
                n += 1
        if n < need:
            return False
        if w - n == dropped:
            return True
        dropped = w - n
        kept = lows[:n].copy()
        for c in range(4):
            for i in range(n):
                js = int(kept[i]) % m
                col_lo[i] = FL[js, c]
                col_hi[i] = FH[js, c]
            lo, hi = covered_hull(col_lo, col_hi, n, need, lows, highs)
            xl[c] = max(xl[c], lo) if lo == lo else lo
            xh[c] = min(xh[c], hi) if hi == hi else hi
            if not xl[c] <= xh[c]:
                return False


@_njit
def _transport_all(SL, SH, UL, UH, AL, DL, DH, TL, TH, first, k, m, hl, hh, par, tp,
                   scratch, tmp_l, tmp_h, buf, memo):
    """``T[j, i]``: the states at time ``j`` consistent with ping ``i`` (ping ``i`` on ``S_i``,
    carried forward to ``k`` and backward to ``first`` through the window's states ``S``); NaN
    where empty.

    Most carried sets (about 70 % on the embedded mission) equal the window's state ``S_j``
    at some ``j``: the ping no longer contracts it there. The next one is then the transport of
    ``S_j`` itself, the same for every such ping, so it is computed once per ``j`` (``memo``:
    forward ``f(S_{j-1}) ∩ S_j`` and backward ``S_j ∩ f^{-1}(S_{j+1})``, NaN where empty) and
    copied: the same floats as the step it replaces.
    """
    FWL, FWH, BWL, BWH = memo
    for j in range(first + 1, k + 1):
        sj, sp = j % m, (j - 1) % m
        _step(SL[sp], SH[sp], UL[sp], UH[sp], hl, hh, FWL[sj], FWH[sj], buf)
        if not _meet(FWL[sj], FWH[sj], SL[sj], SH[sj]):
            FWL[sj, :] = np.nan
            FWH[sj, :] = np.nan
    for j in range(first, k):
        sj, sn = j % m, (j + 1) % m
        BWL[sj, :] = SL[sj]
        BWH[sj, :] = SH[sj]
        if not _back(BWL[sj], BWH[sj], SL[sn], SH[sn], UL[sj], UH[sj], hl, hh, buf):
            BWL[sj, :] = np.nan
            BWH[sj, :] = np.nan
    for i in range(first, k + 1):
        si = i % m
        if not _ping(SL[si], SH[si], AL[si], DL[si], DH[si], par, tp, TL[si, si],
                     TH[si, si], scratch):
            for j in range(first, k + 1):
                TL[j % m, si, :] = np.nan
                TH[j % m, si, :] = np.nan
            continue
        ok = True
        for j in range(i + 1, k + 1):
            sj, sp = j % m, (j - 1) % m
            if ok and _equal(TL[sp, si], TH[sp, si], SL[sp], SH[sp]):
                tmp_l[:] = FWL[sj]
                tmp_h[:] = FWH[sj]
                ok = FWL[sj, 0] == FWL[sj, 0]  # not NaN
            elif ok:
                _step(TL[sp, si], TH[sp, si], UL[sp], UH[sp], hl, hh, tmp_l, tmp_h, buf)
                ok = _meet(tmp_l, tmp_h, SL[sj], SH[sj])
            if not ok:
                tmp_l[:] = np.nan
                tmp_h[:] = np.nan
            TL[sj, si, :] = tmp_l
            TH[sj, si, :] = tmp_h
        ok = True
        for j in range(i - 1, first - 1, -1):
            sj, sn = j % m, (j + 1) % m
            if ok and _equal(TL[sn, si], TH[sn, si], SL[sn], SH[sn]):
                tmp_l[:] = BWL[sj]
                tmp_h[:] = BWH[sj]
                ok = BWL[sj, 0] == BWL[sj, 0]  # not NaN
            elif ok:
                tmp_l[:] = SL[sj]
                tmp_h[:] = SH[sj]
                ok = _back(tmp_l, tmp_h, TL[sn, si], TH[sn, si], UL[sj], UH[sj], hl, hh, buf)
            if not ok:
                tmp_l[:] = np.nan
                tmp_h[:] = np.nan
            TL[sj, si, :] = tmp_l
            TH[sj, si, :] = tmp_h


@_njit
def _smooth(SL, SH, UL, UH, first, k, m, hl, hh, tmp_l, tmp_h, buf):
    """The window's states contracted backward from ``S_k``, then forward; False when empty."""
    for i in range(k - 1, first - 1, -1):
        s = i % m
        if not _back(SL[s], SH[s], SL[(i + 1) % m], SH[(i + 1) % m], UL[s], UH[s], hl, hh,
                     buf):
            return False
    for i in range(first, k):
        s = i % m
        _step(SL[s], SH[s], UL[s], UH[s], hl, hh, tmp_l, tmp_h, buf)
        if not _meet(SL[(i + 1) % m], SH[(i + 1) % m], tmp_l, tmp_h):
            return False
    return True


@_njit
def _solve_window(SL, SH, UL, UH, AL, DL, DH, FL, FH, first, k, par, hl, hh, tp, xl, xh,
                  work):
    """``X_k`` from the window's states, smoothed: each round carries every ping to every
    time of the window (:func:`_transport_all`), replaces each state ``S_j`` by its
    q-relaxed intersection with the pings' sets at ``j``, and runs the dynamics backward and
    forward along the window. ``max(sweeps, 1)`` rounds; False when empty."""
    m, q, sweeps = par[M], par[Q], par[SWEEPS]
    scratch, tmp_l, tmp_h, buf, lows, highs, col_lo, col_hi, TL, TH, memo = work
    s = k % m
    for _ in range(max(sweeps, 1)):
        _transport_all(SL, SH, UL, UH, AL, DL, DH, TL, TH, first, k, m, hl, hh, par, tp,
                       scratch, tmp_l, tmp_h, buf, memo)
        for j in range(first, k + 1):
            sj = j % m
            if not _qinter(TL[sj], TH[sj], first, k, m, q, SL[sj], SH[sj], lows, highs,
                           col_lo, col_hi):
                return False
        if not _smooth(SL, SH, UL, UH, first, k, m, hl, hh, tmp_l, tmp_h, buf):
            return False
    FL[:] = TL[s]
    FH[:] = TH[s]
    xl[:] = SL[s]
    xh[:] = SH[s]
    return True


@_njit
def _pave(xl, xh, FL, FH, SL, SH, UL, UH, AL, DL, DH, first, k, par, eps, hl, hh, tp, work,
          cell_l, cell_h):
    """``x ∩=`` the hull of the kept cells of a regular paving of its ``(x, y)`` into cells of
    sides at most ``eps[0]``, ``eps[1]`` (``inf``: that component is not cut; at most
    ``MAX_SIDE`` cuts per component); returns the number of cells kept (0: the set is empty),
    the first ``cell_l.shape[0]`` of them written to ``cell_l``/``cell_h``.

    Each cell (with the ``theta``, ``v`` of ``x``) replaces ``S_k`` in a copy of the window,
    which is solved again (:func:`_smooth`, :func:`_solve_window`): on a small cell the pings
    contract the heading, which the whole box could not. A cell whose window comes out empty
    holds no state consistent with all but ``q`` pings. The window's states become the hull
    of the kept cells' windows.
    """
    m = par[M]
    tmp_l, tmp_h, buf = work[1], work[2], work[3]
    SL2, SH2, FL2, FH2 = SL.copy(), SH.copy(), FL.copy(), FH.copy()
    WL, WH = np.full(SL.shape, np.inf), np.full(SL.shape, -np.inf)
    n_side = np.empty(2, dtype=np.int64)
    for c in range(2):
        cuts = (xh[c] - xl[c]) / eps[c]  # inf: an unbounded side; 0: no paving of c
        n_side[c] = min(MAX_SIDE, max(1, int(np.ceil(cuts)))) if cuts < np.inf else 1
    bl, bh = np.empty(4), np.empty(4)
    kept = 0
    for cell in range(n_side[0] * n_side[1]):
        idx = (cell % n_side[0], cell // n_side[0])
        for c in range(2):
            step = (xh[c] - xl[c]) / n_side[c]
            bl[c] = xl[c] + idx[c] * step if idx[c] > 0 else xl[c]
            bh[c] = xl[c] + (idx[c] + 1) * step if idx[c] < n_side[c] - 1 else xh[c]
        bl[2:] = xl[2:]
        bh[2:] = xh[2:]
        SL2[:] = SL
        SH2[:] = SH
        SL2[k % m] = bl
        SH2[k % m] = bh
        if not (_smooth(SL2, SH2, UL, UH, first, k, m, hl, hh, tmp_l, tmp_h, buf)
                and _solve_window(SL2, SH2, UL, UH, AL, DL, DH, FL2, FH2, first, k, par, hl,
                                  hh, tp, bl, bh, work)):
            continue
        if kept < cell_l.shape[0]:
            cell_l[kept] = bl
            cell_h[kept] = bh
        kept += 1
        for j in range(first, k + 1):
            sj = j % m
            for c in range(4):
                WL[sj, c] = min(WL[sj, c], SL2[sj, c])
                WH[sj, c] = max(WH[sj, c], SH2[sj, c])
    if kept:
        for j in range(first, k + 1):
            _meet(SL[j % m], SH[j % m], WL[j % m], WH[j % m])
        xl[:] = SL[k % m]
        xh[:] = SH[k % m]
    return kept


@_njit
def observer_update(k, ul, uh, alpha, dl, dh, par, eps, x0l, x0h, rl, rh, hl, hh, tp, ring, xl,
                    xh, work, cell_l, cell_h, restart):
    """Update ``k`` (the ping's index, from 0) of one mission (one slice), in place.

    ``u``: the input box applied since ping ``k - 1`` (ignored at ``k = 0``); ``par``: ``[m, q,
    sweeps, passes, carry]``; ``x0``, ``r``: the initial and the restart box (pool and speed
    bound); ``h`` = dt as an interval; ``ring = (SL, SH, PL, PH, FL, FH, UL, UH, AL, DL, DH)``
    (``m`` rows each); ``x``: the result ``X_k``; ``eps``: the sides of the cells of a paving
    of ``(x, y)`` (:func:`_pave`; ``inf``: none; ``eps[2]`` is not read here), the kept cells
    into ``cell_l``/``cell_h``. Returns ``(rejected, empty, cells)``: the pings of the window
    whose ``F_j`` misses ``X_k``, whether the set came out empty, and the cells kept (0
    without paving). An empty set restarts the observer (:func:`_conclude`) when
    ``restart``; otherwise the update stops there, leaving the ring to be dropped.
    """
    SL, SH, PL, PH, FL, FH, UL, UH, AL, DL, DH = ring
    m, carry = par[M], par[CARRY]
    scratch, tmp_l, tmp_h, buf = work[0], work[1], work[2], work[3]
    s = k % m
    first = max(0, k - m + 1)
    if k == 0:
        PL[s, :] = x0l
        PH[s, :] = x0h
        _meet(PL[s], PH[s], rl, rh)
        SL[s, :] = PL[s]
        SH[s, :] = PH[s]
    else:
        p = (k - 1) % m
        UL[p, 0], UH[p, 0], UL[p, 1], UH[p, 1] = ul[0], uh[0], ul[1], uh[1]
        _step(PL[p], PH[p], UL[p], UH[p], hl, hh, tmp_l, tmp_h, buf)
        _meet(tmp_l, tmp_h, rl, rh)  # never empty: the state is always in the restart box
        PL[s, :] = tmp_l
        PH[s, :] = tmp_h
        if carry:
            _step(SL[p], SH[p], UL[p], UH[p], hl, hh, tmp_l, tmp_h, buf)
            _meet(tmp_l, tmp_h, PL[s], PH[s])
            SL[s, :] = tmp_l
            SH[s, :] = tmp_h
    AL[s], DL[s], DH[s] = alpha, dl, dh
    if not carry:
        for j in range(first, k + 1):
            SL[j % m, :] = PL[j % m]
            SH[j % m, :] = PH[j % m]
    xl[:] = SL[s]
    xh[:] = SH[s]
    ok = xl[0] <= xh[0] and xl[1] <= xh[1] and xl[2] <= xh[2] and xl[3] <= xh[3]
    if ok and carry and par[SWEEPS] == 0 and k > 0:
        # the recursive observer without smoothing: carry the F_j one step, add the new ping
        for j in range(first, k):
            js = j % m
            _step(FL[js], FH[js], UL[(k - 1) % m], UH[(k - 1) % m], hl, hh, tmp_l, tmp_h, buf)
            if not _meet(tmp_l, tmp_h, xl, xh):
                tmp_l[:] = np.nan
                tmp_h[:] = np.nan
            FL[js, :] = tmp_l
            FH[js, :] = tmp_h
        if not _ping(SL[s], SH[s], alpha, dl, dh, par, tp, FL[s], FH[s], scratch):
            FL[s, :] = np.nan
            FH[s, :] = np.nan
        ok = _qinter(FL, FH, first, k, m, par[Q], xl, xh, work[4], work[5], work[6], work[7])
    elif ok:
        ok = _solve_window(SL, SH, UL, UH, AL, DL, DH, FL, FH, first, k, par, hl, hh, tp, xl,
                           xh, work)
    cells = 0
    if ok and min(eps[0], eps[1]) < np.inf:
        cells = _pave(xl, xh, FL, FH, SL, SH, UL, UH, AL, DL, DH, first, k, par, eps, hl, hh, tp,
                      work, cell_l, cell_h)
        ok = cells > 0
    if not (ok or restart):
        return 0, True, 0
    return _conclude(ok, k, par, hl, hh, tp, ring, xl, xh, work), not ok, cells


@_njit
def _misses(FL, FH, js, xl, xh):
    """Whether ping ``js``'s set ``F_js`` misses the box ``x`` (or is empty)."""
    for c in range(4):
        if not (FL[js, c] <= FH[js, c] and FL[js, c] <= xh[c] and FH[js, c] >= xl[c]):
            return True
    return False


@_njit
def _conclude(ok, k, par, hl, hh, tp, ring, xl, xh, work):
    """The end of update ``k`` with ``X_k`` in ``x``, ``ok`` False when it came out empty:
    then the recursive observer restarts from the window alone (and, if that is empty too,
    takes ``P_k``); ``S_k = X_k``, and each ``F_j`` that meets ``X_k`` is cut to it. Returns
    the pings whose ``F_j`` misses ``X_k``."""
    SL, SH, PL, PH, FL, FH, UL, UH, AL, DL, DH = ring
    m, carry = par[M], par[CARRY]
    s = k % m
    first = max(0, k - m + 1)
    if not ok and carry:  # restart from the window alone
        for j in range(first, k + 1):
            SL[j % m, :] = PL[j % m]
            SH[j % m, :] = PH[j % m]
        xl[:] = PL[s]
        xh[:] = PH[s]
        ok = _solve_window(SL, SH, UL, UH, AL, DL, DH, FL, FH, first, k, par, hl, hh, tp, xl,
                           xh, work)
    if not ok:  # more than q outliers even for the window alone: the certain set, and the
        # window's pings made neutral (their F_j: the certain set too)
        xl[:] = PL[s]
        xh[:] = PH[s]
        for j in range(first, k + 1):
            SL[j % m, :] = PL[j % m]
            SH[j % m, :] = PH[j % m]
            FL[j % m, :] = PL[s]
            FH[j % m, :] = PH[s]
    SL[s, :] = xl
    SH[s, :] = xh
    rejected = 0
    for j in range(first, k + 1):
        if _misses(FL, FH, j % m, xl, xh):
            rejected += 1
        else:
            _meet(FL[j % m], FH[j % m], xl, xh)
    return rejected


def make_work(m: int, n_slots: int) -> tuple:
    """Scratch arrays of one mission's updates (``n_slots``: slots of the ray-cast tapes)."""
    scratch = (np.empty(4), np.empty(4), np.empty(n_slots), np.empty(n_slots), np.empty(4))
    memo = (np.full((m, 4), np.nan), np.full((m, 4), np.nan), np.full((m, 4), np.nan),
            np.full((m, 4), np.nan))
    return (scratch, np.empty(4), np.empty(4), np.empty(4), np.empty(m), np.empty(m),
            np.empty(m), np.empty(m), np.full((m, m, 4), np.nan), np.full((m, m, 4), np.nan),
            memo)


def make_bank(m: int, slices: int = 1) -> tuple:
    """The arrays of one mission's set (see :func:`bank_update`): up to ``slices`` heading
    slices (room for twice as many while they are cut), each with its window's ``S_j`` and
    ``F_j`` (``m`` rows) and its box ``X_k``, the window's prior, inputs and pings (shared),
    and the number of live slices."""
    slots = 2 * slices
    own = tuple(np.full((slots, m, 4), np.nan) for _ in range(4))
    shared = (np.full((m, 4), np.nan), np.full((m, 4), np.nan), np.zeros((m, 2)),
              np.zeros((m, 2)), np.zeros(m), np.zeros(m), np.zeros(m))
    return own + shared + (np.full((slots, 4), np.nan), np.full((slots, 4), np.nan),
                           np.zeros(1, dtype=np.int64))


@_njit
def _hull_into(al, ah, bl, bh):
    """``a`` = the hull of the boxes ``a`` and ``b``, row by row (a NaN row is empty)."""
    for i in range(al.shape[0]):
        for c in range(al.shape[1]):
            if not bl[i, c] <= bh[i, c]:
                continue
            if al[i, c] <= ah[i, c]:
                al[i, c] = min(al[i, c], bl[i, c])
                ah[i, c] = max(ah[i, c], bh[i, c])
            else:
                al[i, c], ah[i, c] = bl[i, c], bh[i, c]


@_njit
def _move(bank, src, dst):
    """Slice ``src`` copied into slot ``dst``."""
    for a in (bank[0], bank[1], bank[2], bank[3]):
        a[dst] = a[src]
    bank[11][dst] = bank[11][src]
    bank[12][dst] = bank[12][src]


@_njit
def _merge_thinnest(bank, n):
    """Merge the two slices, neighbours in heading, whose hull is thinnest in heading; the
    last slice moves into the freed slot. Returns ``n - 1``."""
    BXL, BXH = bank[11], bank[12]
    order = np.argsort(BXL[:n, 2])
    best, at = np.inf, 0
    for i in range(n - 1):
        a, b = order[i], order[i + 1]
        w = max(BXH[a, 2], BXH[b, 2]) - min(BXL[a, 2], BXL[b, 2])
        if w < best:
            best, at = w, i
    a, b = order[at], order[at + 1]
    _hull_into(bank[0][a], bank[1][a], bank[0][b], bank[1][b])
    _hull_into(bank[2][a], bank[3][a], bank[2][b], bank[3][b])
    _hull_into(BXL[a:a + 1], BXH[a:a + 1], BXL[b:b + 1], BXH[b:b + 1])
    if b != n - 1:
        _move(bank, n - 1, b)
    return n - 1


@_njit
def bank_update(k, ul, uh, alpha, dl, dh, par, eps, x0l, x0h, rl, rh, hl, hh, tp, bank, xl, xh,
                work, cell_l, cell_h):
    """Update ``k`` of one mission whose set is a bank of heading slices (module docstring),
    in place; the arguments as in :func:`observer_update`, with ``bank`` (:func:`make_bank`)
    for ``ring``.

    ``eps[2]``: the widest heading [rad] a slice may have at ``k - 1`` before it is cut in two
    (``inf``: one slice, the plain observer); at most half the bank's slots are kept. Returns
    ``(rejected, empty, cells)``: the pings that every slice rejects, whether every slice came
    out empty (then the observer restarted from the window alone, as one slice), and the
    cells: with slices, the slices kept (their boxes into ``cell_l``/``cell_h``); otherwise
    the ``(x, y)`` paving's cells.
    """
    SL, SH, FL, FH, PL, PH, UL, UH, AL, DL, DH, BXL, BXH, live = bank
    m = par[M]
    first = max(0, k - m + 1)
    sliced = eps[2] < np.inf
    # np.int64 counters and a bool variable, not literals: the callees (_move, _merge_thinnest,
    # _conclude) would be compiled once more for Literal[int] / Literal[bool]
    n = np.int64(1) if k == 0 else live[0]
    if k > 0 and sliced:
        p = (k - 1) % m
        for b in range(n):
            lo, hi = SL[b, p, 2], SH[b, p, 2]
            if n < SL.shape[0] and eps[2] < hi - lo < np.inf:
                mid = 0.5 * (lo + hi)
                _move(bank, b, n)
                SH[b, p, 2] = mid
                SL[n, p, 2] = mid
                n += 1
    inner = eps.copy()
    inner[2] = np.inf
    n_in = 0 if sliced else cell_l.shape[0]
    kept, rejected, empty, cells = np.int64(0), np.int64(0), False, np.int64(0)
    for b in range(n):
        ring = (SL[b], SH[b], PL, PH, FL[b], FH[b], UL, UH, AL, DL, DH)
        rejected, empty, cells = observer_update(
            k, ul, uh, alpha, dl, dh, par, inner, x0l, x0h, rl, rh, hl, hh, tp, ring, BXL[b],
            BXH[b], work, cell_l[:n_in], cell_h[:n_in], n == 1)
        if n == 1 or not empty:
            if kept != b:
                _move(bank, b, kept)
            kept += 1
    if kept == 0:  # every slice empty: restart from the window alone, as one slice
        ring = (SL[0], SH[0], PL, PH, FL[0], FH[0], UL, UH, AL, DL, DH)
        ok = kept > 0  # False, as a variable (see above)
        rejected = _conclude(ok, k, par, hl, hh, tp, ring, BXL[0], BXH[0], work)
        kept, empty = np.int64(1), True
    elif n > 1:
        empty = False
        while kept > SL.shape[0] // 2:
            kept = _merge_thinnest(bank, kept)
        rejected = np.int64(0)
        for j in range(first, k + 1):
            every = True
            for b in range(kept):
                every = every and _misses(FL[b], FH[b], j % m, BXL[b], BXH[b])
            if every:
                rejected += 1
    live[0] = kept
    xl[:] = BXL[0]
    xh[:] = BXH[0]
    for b in range(1, kept):
        for c in range(4):
            xl[c] = min(xl[c], BXL[b, c])
            xh[c] = max(xh[c], BXH[b, c])
    if sliced:
        cells = kept
        for b in range(min(kept, cell_l.shape[0])):
            cell_l[b] = BXL[b]
            cell_h[b] = BXH[b]
    return rejected, empty, cells


@_njit
def run_missions(UL, UH, alpha, DLO, DHI, par, eps, x0l, x0h, rl, rh, hl, hh, tp, bank, work,
                 XL, XH, rejected, empty, cells, CL, CH):
    """Every update of every mission (``UL``: ``(M, n, 2)``, ``DLO``: ``(M, n)``), results into
    ``XL``/``XH`` ``(M, n, 4)``, ``rejected``, ``empty`` and ``cells`` ``(M, n)``, the kept
    cells (or slices) into ``CL``/``CH`` ``(M, n, C, 4)`` (``C = 0``: not kept)."""
    for i in range(DLO.shape[0]):
        for k in range(DLO.shape[1]):
            p = max(k - 1, 0)
            rej, emp, nc = bank_update(k, UL[i, p], UH[i, p], alpha[k], DLO[i, k], DHI[i, k],
                                       par, eps, x0l, x0h, rl, rh, hl, hh, tp, bank, XL[i, k],
                                       XH[i, k], work, CL[i, k], CH[i, k])
            rejected[i, k] = rej
            empty[i, k] = emp
            cells[i, k] = nc

