"""The compiled propagation kernels: AC3-style revisions of the primitive nodes of a tape, and
3B shaving on top of them.

Each node ``z = f(x, y)`` is revised by ``z ∩= f(x, y)`` then ``(x, y) = f_rev(z, x, y)``. When a
slot's domain shrinks by more than ``rel_eps`` of its width (or loses an infinite bound), every
other node using that slot becomes dirty again. Dirty nodes are revised window by window along
the tape order (the order of the constraints, i.e. of the time steps for a time series), in
alternating forward and backward passes, so that the work per time step does not grow with the
horizon.

``shave_kernel`` adds 3B consistency (shaving): it cuts a slice off a bound of a slot, propagates
the sliced network, and removes the slice when that propagation proves it empty. A probe only
revises the windows its change reaches and undoes its own writes from a trail, so its cost does
not depend on the size of the tape.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from ..ctc.revise import family_flags
from ..ctc.revise import revise as _revise

__all__ = ["BC_STATS", "DONE", "EMPTY", "RUNNING", "SHAVE_STATS", "bc_boxes", "bc_closures",
           "bc_kernel", "family_flags", "propagate_kernel", "repropagate_kernel",
           "shave_kernel"]

DONE, RUNNING, EMPTY = 0, 1, 2
#: A window that has not settled after this many local sweeps hands its remaining dirty nodes
#: to the next pass (a safeguard against slowly converging cycles; it never loses soundness).
_LOCAL_SWEEPS = 64
#: The counters ``shave_kernel`` writes into its ``stats`` argument, in this order.
SHAVE_STATS = ("rounds", "probes", "refuted", "probe_evaluations", "evaluations")


@nb.njit(cache=True, inline="always", error_model="numpy")
def _significant(ol, oh, nl, nh, rel_eps):
    """Whether ``[ol, oh] -> [nl, nh]`` is a shrink worth propagating."""
    if nl == ol and nh == oh:
        return False
    w0 = oh - ol
    if w0 == np.inf:
        return True  # a bound became finite or moved: cheap to propagate, often decisive
    return (w0 - (nh - nl)) > rel_eps * w0


@nb.njit(cache=True, inline="always", error_model="numpy")
def _record(s, lo, hi, trail, tval, tpos):
    """Push slot ``s``'s current domain on the trail (undone by ``_undo``)."""
    p = tpos[0]
    trail[p] = s
    tval[2 * p] = lo[s]
    tval[2 * p + 1] = hi[s]
    tpos[0] = p + 1


@nb.njit(cache=True, error_model="numpy")
def _undo(lo, hi, trail, tval, tpos):
    """Restore every slot written since the trail was empty, newest write first."""
    for p in range(tpos[0] - 1, -1, -1):
        s = trail[p]
        lo[s] = tval[2 * p]
        hi[s] = tval[2 * p + 1]
    tpos[0] = 0


@nb.njit(cache=True, inline="always", error_model="numpy")
def _update(s, nl, nh, lo, hi, rel_eps, trail, tval, tpos):
    """Intersect slot ``s`` with ``[nl, nh]``: -1 empty, 1 significant shrink, 0 otherwise.
    With a trail (``trail.size > 0``) the old domain is recorded before it changes. (An empty
    trail, not None, when there is none: one compiled version of the revisions serves both
    kernels, the probes and the plain propagation.)"""
    ol, oh = lo[s], hi[s]
    nl = max(nl, ol) if nl == nl else nl  # NaN (empty) must survive the max
    nh = min(nh, oh) if nh == nh else nh
    if trail.size > 0 and not (nl == ol and nh == oh):
        _record(s, lo, hi, trail, tval, tpos)
    if nl != nl or nh != nh or nl > nh:
        lo[s] = np.nan
        hi[s] = np.nan
        return -1
    sig = _significant(ol, oh, nl, nh, rel_eps)
    lo[s] = nl
    hi[s] = nh
    return 1 if sig else 0


@nb.njit(cache=True, inline="always", error_model="numpy")
def _mark(j, dirty, pending, span, window):
    """Make node ``j`` dirty (1 if it was not, else 0), widening the span of dirty windows."""
    if dirty[j]:
        return 0
    dirty[j] = True
    w = j // window
    pending[w] += 1
    if w < span[0]:
        span[0] = w
    if w > span[1]:
        span[1] = w
    return 1


@nb.njit(cache=True, inline="always", error_model="numpy")
def _revise_node(i, op, out, a, b, param, lo, hi, ptr, adj, dirty, pending, span, window,
                 rel_eps, buf, changed, trail, tval, tpos, piecewise, pown, explog, trig):
    """Revise node ``i`` and mark the nodes whose slots it shrank significantly. Returns the
    number of nodes newly marked dirty, or -1 when a domain became empty."""
    o, ia, ib = out[i], a[i], b[i]
    # the node itself is revised again only when it reads what it writes
    again = (o == ia) | (o == ib) | (ia == ib)
    xl, xh = lo[ia], hi[ia]
    yl, yh = (lo[ib], hi[ib]) if ib >= 0 else (0.0, 0.0)
    zl, zh, xl, xh, yl, yh = _revise(op[i], lo[o], hi[o], xl, xh, yl, yh, param[i], buf,
                                       piecewise, pown, explog, trig)
    # when o aliases an argument, each update is still a sound intersection
    nch = 0
    r = _update(o, zl, zh, lo, hi, rel_eps, trail, tval, tpos)
    if r < 0:
        return -1
    if r > 0:
        changed[nch] = o
        nch += 1
    r = _update(ia, xl, xh, lo, hi, rel_eps, trail, tval, tpos)
    if r < 0:
        return -1
    if r > 0:
        changed[nch] = ia
        nch += 1
    if ib >= 0:
        r = _update(ib, yl, yh, lo, hi, rel_eps, trail, tval, tpos)
        if r < 0:
            return -1
        if r > 0:
            changed[nch] = ib
            nch += 1
    added = 0
    for c in range(nch):
        s = changed[c]
        for k in range(ptr[s], ptr[s + 1]):
            j = adj[k]
            if j != i or again:
                added += _mark(j, dirty, pending, span, window)
    return added


@nb.njit(cache=True, error_model="numpy")
def _settle(w, d, op, out, a, b, param, lo, hi, ptr, adj, dirty, pending, span, window,
            rel_eps, buf, changed, cnt, max_evals, trail, tval, tpos, piecewise, pown, explog,
            trig):
    """Bring window ``w`` to its local fixed point by alternating sweeps (the first in direction
    ``d``), until ``cnt[1]`` (revisions) reaches ``max_evals``. ``cnt = [dirty count,
    revisions]`` is updated. Returns False when a domain became empty."""
    first, last = w * window, min((w + 1) * window, op.size)
    sweeps = 0
    while pending[w] > 0 and sweeps < _LOCAL_SWEEPS and cnt[1] < max_evals:
        sweeps += 1
        i = first if d > 0 else last - 1
        while first <= i < last and cnt[1] < max_evals:
            if dirty[i]:
                dirty[i] = False
                pending[w] -= 1
                cnt[0] -= 1
                cnt[1] += 1
                r = _revise_node(i, op, out, a, b, param, lo, hi, ptr, adj, dirty, pending,
                                 span, window, rel_eps, buf, changed, trail, tval, tpos,
                                 piecewise, pown, explog, trig)
                if r < 0:
                    return False
                cnt[0] += r
            i += d
        d = -d
    return True


@nb.njit(cache=True, error_model="numpy")
def propagate_kernel(op, out, a, b, param, lo, hi, ptr, adj, dirty, state, rel_eps, max_evals,
                     window, piecewise=None, pown=None, explog=None, trig=None):
    """Revise dirty nodes window by window, for at most about ``max_evals`` node revisions.

    The tape is cut into windows of ``window`` consecutive nodes. A pass visits the windows in
    tape order (or in reverse order: passes alternate) and brings each window to its local fixed
    point by alternating sweeps over its nodes before moving on (block Gauss-Seidel). Along a
    time series one pass carries information through the whole horizon, where a FIFO queue
    moves it by one step per wave, and a window settles before it passes its change on, so its
    neighbours are revised once for a burst of small changes rather than once per change.
    ``state = [window index in the pass, dirty count, status, evals_total, direction]`` is read
    and written so that a long run can be continued in chunks (progress reports); a call that
    reaches ``max_evals`` inside a window leaves the rest of that window to the next pass.
    ``ptr``/``adj`` list, for each slot, the nodes using it (CSR). Returns the status (DONE,
    RUNNING or EMPTY).
    """
    n = op.size
    nw = (n + window - 1) // window
    pending = np.zeros(nw, dtype=np.int64)
    for i in range(n):
        if dirty[i]:
            pending[i // window] += 1
    span = np.array([0, nw - 1], dtype=np.int64)  # every window is visited by a pass
    cnt = np.array([state[1], 0], dtype=np.int64)
    wpos, direction = state[0], state[4]
    buf = np.empty(4)
    changed = np.empty(3, dtype=np.int64)
    tpos = np.zeros(1, dtype=np.int64)
    status = RUNNING
    while cnt[0] > 0 and cnt[1] < max_evals:
        if wpos >= nw:  # end of a pass: turn round
            wpos = 0
            direction = -direction
        w = wpos if direction > 0 else nw - 1 - wpos
        wpos += 1
        if not _settle(w, direction, op, out, a, b, param, lo, hi, ptr, adj, dirty, pending,
                       span, window, rel_eps, buf, changed, cnt, max_evals, tpos[:0], buf[:0], tpos,
                       piecewise, pown, explog, trig):
            status = EMPTY
            break
    if status != EMPTY and cnt[0] == 0:
        status = DONE
    state[0], state[1], state[2], state[3], state[4] = wpos, cnt[0], status, state[3] + cnt[1], \
        direction
    return status


@nb.njit(cache=True, error_model="numpy")
def _drain(op, out, a, b, param, lo, hi, ptr, adj, dirty, pending, span, window, rel_eps, buf,
           changed, cnt, max_evals, trail, tval, tpos, piecewise, pown, explog, trig):
    """Revise the dirty nodes in alternating passes over the span of dirty windows only (it
    grows as changes spread and is trimmed between passes), until none is dirty or ``cnt[1]``
    reaches ``max_evals``. Returns False when a domain became empty."""
    d = np.int64(1)  # not the literal 1: _settle would be compiled again for Literal[int](1)
    while cnt[0] > 0 and cnt[1] < max_evals:
        w = span[0] if d > 0 else span[1]
        while span[0] <= w <= span[1] and cnt[1] < max_evals:
            if pending[w] > 0 and not _settle(w, d, op, out, a, b, param, lo, hi, ptr, adj,
                                              dirty, pending, span, window, rel_eps, buf,
                                              changed, cnt, max_evals, trail, tval, tpos,
                                              piecewise, pown, explog, trig):
                return False
            w += d
        d = -d
        while span[0] < span[1] and pending[span[0]] == 0:
            span[0] += 1
        while span[1] > span[0] and pending[span[1]] == 0:
            span[1] -= 1
    return True


@nb.njit(cache=True, error_model="numpy")
def _forget(dirty, pending, span, window, cnt):
    """Clear the dirty nodes a drain left (they all lie in the span), and reset the span."""
    n = dirty.size
    for w in range(span[0], span[1] + 1):
        if pending[w] > 0:
            for i in range(w * window, min((w + 1) * window, n)):
                dirty[i] = False
            pending[w] = 0
    cnt[0] = 0
    span[0] = pending.size
    span[1] = -1


@nb.njit(cache=True, error_model="numpy")
def _touch(s, ptr, adj, dirty, pending, span, window, cnt):
    """Mark every node using slot ``s`` dirty."""
    for k in range(ptr[s], ptr[s + 1]):
        cnt[0] += _mark(adj[k], dirty, pending, span, window)


@nb.njit(cache=True, error_model="numpy")
def shave_kernel(op, out, a, b, param, lo, hi, ptr, adj, cand, rel_eps, probe_eps, probe_evals,
                 frac, max_rounds, reach, min_gain, window, stats, piecewise=None, pown=None,
                 explog=None, trig=None):
    """3B consistency by shaving, with an adaptive (ACID-like) choice of what to shave.

    First the whole tape is propagated to its fixed point (hull consistency). Then, round by
    round, for each candidate slot ``cand[j]`` still active (in ``cand`` order, then in reverse
    order on the next round) and each of its bounds: the slice ``[lo, lo + f w]`` (or
    ``[hi - f w, hi]``, ``w`` the slot's width) is imposed and propagated, at tolerance
    ``probe_eps`` and for at most ``probe_evals`` revisions; when that proves the sliced network
    empty, no solution lies in the slice, the bound moves to the cut, the change is propagated to
    the fixed point at ``rel_eps``, and the next slice, twice as wide (``f`` doubles, up to 1/2),
    is tried; the first slice not refuted ends that bound. A candidate stays active in the next
    round only when it or one within ``reach`` positions of it in ``cand`` lost more than
    ``min_gain`` of its width in this round; the rounds stop when none did, or after
    ``max_rounds``.

    A probe revises only the windows its change reaches and undoes its writes from a trail, so
    its cost depends on how far its change travels, not on the length of the tape. Every
    contraction is either hull consistency or the removal of a slice proven empty: no solution
    is lost. ``stats`` receives the counters named in :data:`SHAVE_STATS`. Returns DONE, or
    EMPTY when the network was proven to have no solution. (``ctc.CtcShave`` is the other
    shaving, over any contractor and a batch of boxes; its module says why both exist.)
    """
    n = op.size
    nw = (n + window - 1) // window
    m = cand.size
    dirty = np.ones(n, dtype=np.bool_)
    pending = np.zeros(nw, dtype=np.int64)
    for i in range(n):
        pending[i // window] += 1
    span = np.array([0, nw - 1], dtype=np.int64)
    cnt = np.array([n, 0], dtype=np.int64)
    buf = np.empty(4)
    changed = np.empty(3, dtype=np.int64)
    cap = 3 * probe_evals + 3
    trail = np.empty(cap, dtype=np.int64)
    tval = np.empty(2 * cap)
    tpos = np.zeros(1, dtype=np.int64)
    big = np.iinfo(np.int64).max
    for k in range(stats.size):
        stats[k] = 0
    if not _drain(op, out, a, b, param, lo, hi, ptr, adj, dirty, pending, span, window, rel_eps,
                  buf, changed, cnt, big, tpos[:0], buf[:0], tpos, piecewise, pown, explog, trig):
        stats[4] = cnt[1]
        return EMPTY
    total = cnt[1]
    _forget(dirty, pending, span, window, cnt)
    active = np.ones(m, dtype=np.bool_)
    gained = np.zeros(m, dtype=np.bool_)
    for rnd in range(max_rounds):
        stats[0] += 1
        for jj in range(m):
            j = jj if rnd % 2 == 0 else m - 1 - jj
            gained[j] = False
            if not active[j]:
                continue
            s = cand[j]
            w0 = hi[s] - lo[s]
            for side in range(2):
                f = frac
                while True:
                    l, h = lo[s], hi[s]
                    cut = l + f * (h - l) if side == 0 else h - f * (h - l)
                    if not (l < cut < h):  # a point, an unbounded or too thin a domain
                        break
                    # probe: the slice alone, propagated on a trail, then undone
                    _record(s, lo, hi, trail, tval, tpos)
                    if side == 0:
                        hi[s] = cut
                    else:
                        lo[s] = cut
                    _touch(s, ptr, adj, dirty, pending, span, window, cnt)
                    cnt[1] = 0
                    ok = _drain(op, out, a, b, param, lo, hi, ptr, adj, dirty, pending, span,
                                window, probe_eps, buf, changed, cnt, probe_evals, trail, tval,
                                tpos, piecewise, pown, explog, trig)
                    stats[1] += 1
                    stats[3] += cnt[1]
                    total += cnt[1]
                    _forget(dirty, pending, span, window, cnt)
                    _undo(lo, hi, trail, tval, tpos)
                    if ok:
                        break
                    # the slice holds no solution: cut it off and propagate for good
                    stats[2] += 1
                    if side == 0:
                        lo[s] = cut
                    else:
                        hi[s] = cut
                    _touch(s, ptr, adj, dirty, pending, span, window, cnt)
                    cnt[1] = 0
                    ok = _drain(op, out, a, b, param, lo, hi, ptr, adj, dirty, pending, span,
                                window, rel_eps, buf, changed, cnt, big, tpos[:0], buf[:0], tpos,
                                piecewise, pown, explog, trig)
                    total += cnt[1]
                    if not ok:
                        stats[4] = total
                        return EMPTY
                    _forget(dirty, pending, span, window, cnt)
                    f = min(2.0 * f, 0.5)
            w1 = hi[s] - lo[s]
            gained[j] = w0 > 0 and w1 < w0 and (w0 == np.inf or w0 - w1 > min_gain * w0)
        anyg = False
        for j in range(m):
            active[j] = False
            anyg |= gained[j]
        if not anyg:
            break
        for j in range(m):
            if gained[j]:
                for q in range(max(0, j - reach), min(m, j + reach + 1)):
                    active[q] = True
    stats[4] = total
    return DONE


# --- box consistency (BC3) on the tape ----------------------------------------------------

#: The counters ``bc_kernel`` writes into its ``stats`` argument, in this order.
BC_STATS = ("rounds", "searches", "narrowed", "bc_evaluations", "evaluations")


@nb.njit(cache=True, error_model="numpy")
def bc_closures(out, a, b, aptr, aadj, stop, cand, max_nodes):
    """The sub-networks on which box consistency narrows each candidate slot.

    For slot ``x = cand[j]``: the nodes reachable from ``x`` forward (from an argument to the
    node's output), through slots that are not ``stop`` (the variables narrowed: a constraint's
    expression ends at them), breadth first, at most ``max_nodes`` of them, in tape order.
    ``aptr``/``aadj`` list, for each slot, the nodes that read it as an argument (CSR). A
    candidate is kept only when ``x`` occurs several times in its sub-network: some node reads
    two slots (or one slot twice) that depend on ``x``; where it occurs once, hull consistency
    is already as tight. Returns ``(keep, cptr, cnodes)``: the kept candidates' positions in
    ``cand`` and the CSR lists of their nodes.
    """
    n_nodes, n_slots, m = out.size, stop.size, cand.size
    seen_node = np.full(n_nodes, -1, dtype=np.int64)
    seen_slot = np.full(n_slots, -1, dtype=np.int64)
    queue = np.empty(max_nodes + 1, dtype=np.int64)
    found = np.empty(max_nodes, dtype=np.int64)
    keep = np.empty(m, dtype=np.int64)
    cptr = np.zeros(m + 1, dtype=np.int64)
    cnodes = np.empty(m * max_nodes, dtype=np.int64)
    nk, nn = 0, 0
    for j in range(m):
        x = cand[j]
        seen_slot[x] = j
        queue[0] = x
        qlen, head, nf = 1, 0, 0
        while head < qlen and nf < max_nodes:
            s = queue[head]
            head += 1
            for k in range(aptr[s], aptr[s + 1]):
                i = aadj[k]
                if seen_node[i] == j:
                    continue
                if nf >= max_nodes:
                    break
                seen_node[i] = j
                found[nf] = i
                nf += 1
                o = out[i]
                if seen_slot[o] != j:
                    seen_slot[o] = j
                    if not stop[o]:
                        queue[qlen] = o
                        qlen += 1
        multi = False
        for q in range(nf):
            i = found[q]
            c = 1 if seen_slot[a[i]] == j else 0
            if b[i] >= 0 and seen_slot[b[i]] == j:
                c += 1
            if c >= 2:
                multi = True
                break
        if multi:
            keep[nk] = j
            srt = np.sort(found[:nf])
            cnodes[nn:nn + nf] = srt
            nn += nf
            nk += 1
            cptr[nk] = nn
    return keep[:nk], cptr[:nk + 1], cnodes[:nn]


@nb.njit(cache=True, inline="always", error_model="numpy")
def _point(lo, hi, t):
    """``lo + t (hi - lo)`` for dyadic ``t`` in [0, 1]: exactly ``lo`` at 0 and ``hi`` at 1
    and non-decreasing in ``t`` (rounding is monotone), so adjacent slices of the bisection
    tree share their endpoints exactly and cover the domain; no overflow when ``hi - lo``
    does."""
    if t == 0.0:
        return lo
    if t == 1.0:
        return hi
    w = hi - lo
    p = lo + t * w if np.isfinite(w) else 2.0 * (0.5 * lo + t * (0.5 * hi - 0.5 * lo))
    return min(max(p, lo), hi)


@nb.njit(cache=True, error_model="numpy")
def _image_meets(x, sl, sh, k0, k1, cnodes, op, out, a, b, param, lo, hi, slo, shi, stamp,
                 ev, buf, piecewise, pown, explog, trig):
    """Whether the slice ``[sl, sh]`` of slot ``x`` may hold a solution: the nodes
    ``cnodes[k0:k1]`` are evaluated forward with ``x`` in the slice and every other input at
    its domain, each image intersected with its output's domain (the natural interval
    extension, outward rounded by the revisions' operators). False when one image is empty:
    no solution has ``x`` in the slice. ``slo/shi`` hold the images, valid where ``stamp ==
    ev``."""
    stamp[x] = ev
    slo[x], shi[x] = sl, sh
    for k in range(k0, k1):
        i = cnodes[k]
        o, ia, ib = out[i], a[i], b[i]
        xl, xh = (slo[ia], shi[ia]) if stamp[ia] == ev else (lo[ia], hi[ia])
        yl, yh = 0.0, 0.0
        if ib >= 0:
            yl, yh = (slo[ib], shi[ib]) if stamp[ib] == ev else (lo[ib], hi[ib])
        zl, zh = (slo[o], shi[o]) if stamp[o] == ev else (lo[o], hi[o])
        zl, zh, xl, xh, yl, yh = _revise(op[i], zl, zh, xl, xh, yl, yh, param[i], buf,
                                           piecewise, pown, explog, trig)
        if not zl <= zh:  # NaN (empty) or crossed bounds
            return False
        stamp[o] = ev
        slo[o], shi[o] = zl, zh
    return True


@nb.njit(cache=True, error_model="numpy")
def _bc3_bound(x, side, k0, k1, cnodes, op, out, a, b, param, lo, hi, slo, shi, stamp, cnt,
               eps, max_depth, max_steps, buf, piecewise, pown, explog, trig):
    """BC3 (Benhamou, McAllester, Van Hentenryck 1999) on one bound of slot ``x``: the
    depth-first leftmost (``side`` 0) or rightmost (1) search, over the dyadic bisection tree
    of ``x``'s domain, of a slice whose image meets the domains (``_image_meets``). A slice
    that meets them is the answer when it is at most ``eps`` wide, ``max_depth`` bisections
    deep or unbounded, else it is bisected; a refuted slice gives way to the next one in
    depth-first order. After ``max_steps`` evaluations the search keeps the end of its current
    slice (every slice before it was refuted). Returns ``(bound, empty)``; ``cnt[0]`` (the
    evaluation stamp) and ``cnt[1]`` (node evaluations) are advanced."""
    L, U = lo[x], hi[x]
    finite = np.isfinite(L) and np.isfinite(U)
    d, k = 0, 0
    for _ in range(max_steps):
        scale = 2.0 ** (-d)  # exact: d <= 52
        t0, t1 = k * scale, (k + 1) * scale
        if side == 1:
            t0, t1 = 1.0 - t1, 1.0 - t0
        sl, sh = _point(L, U, t0), _point(L, U, t1)
        cnt[0] += 1
        cnt[1] += k1 - k0
        if _image_meets(x, sl, sh, k0, k1, cnodes, op, out, a, b, param, lo, hi, slo, shi,
                        stamp, cnt[0], buf, piecewise, pown, explog, trig):
            if sh - sl <= eps or d >= max_depth or not finite:
                return (sl if side == 0 else sh), False
            d += 1
            k *= 2
        else:
            while (k & 1) == 1 and d > 0:
                k >>= 1
                d -= 1
            if d == 0:  # the whole domain refuted
                return np.nan, True
            k += 1
    scale = 2.0 ** (-d)
    return _point(L, U, k * scale if side == 0 else 1.0 - k * scale), False


@nb.njit(cache=True, error_model="numpy")
def _bc3(x, k0, k1, cnodes, op, out, a, b, param, lo, hi, slo, shi, stamp, cnt, eps,
         max_depth, max_steps, buf, piecewise, pown, explog, trig):
    """Both bounds of slot ``x`` by ``_bc3_bound``, the lower one first (the upper search runs
    on what is left). Returns False when ``x``'s whole domain was refuted (the slot is then
    empty)."""
    for side in range(2):
        bound, empty = _bc3_bound(x, side, k0, k1, cnodes, op, out, a, b, param, lo, hi, slo,
                                  shi, stamp, cnt, eps, max_depth, max_steps, buf, piecewise,
                                  pown, explog, trig)
        if empty:
            lo[x] = np.nan
            hi[x] = np.nan
            return False
        if side == 0:
            lo[x] = max(lo[x], bound)
        else:
            hi[x] = min(hi[x], bound)
    return True


@nb.njit(cache=True, error_model="numpy")
def bc_boxes(op, out, a, b, param, lo0, hi0, var_slot, blo, bhi, cand, cptr, cnodes, eps,
             max_depth, max_steps, piecewise=None, pown=None, explog=None, trig=None):
    """One pass of box consistency over the candidates, for each box of a batch (in place).

    Box ``r`` gives the domains ``[blo[r, v], bhi[r, v]]`` of the variables, which live in the
    slots ``var_slot[v]`` (two variables merged into one slot are intersected); every other
    slot starts at ``[lo0, hi0]``. Candidate ``j`` (slot ``cand[j]``, nodes
    ``cnodes[cptr[j]:cptr[j + 1]]``, from ``bc_closures``) is narrowed by ``_bc3``, each
    narrowing seen by the next. A box with an empty domain becomes all NaN. Returns the node
    evaluations spent."""
    m, nv = blo.shape
    n_slots = lo0.size
    slo, shi = np.empty(n_slots), np.empty(n_slots)
    stamp = np.full(n_slots, -1, dtype=np.int64)
    cnt = np.zeros(2, dtype=np.int64)
    buf = np.empty(4)
    lo, hi = np.empty(n_slots), np.empty(n_slots)
    for r in range(m):
        lo[:] = lo0
        hi[:] = hi0
        ok = True
        for v in range(nv):
            s = var_slot[v]
            nl, nh = blo[r, v], bhi[r, v]
            if not nl <= nh:
                ok = False
                break
            lo[s] = max(lo[s], nl)
            hi[s] = min(hi[s], nh)
            if not lo[s] <= hi[s]:
                ok = False
                break
        j = 0
        while ok and j < cand.size:
            ok = _bc3(cand[j], cptr[j], cptr[j + 1], cnodes, op, out, a, b, param, lo, hi, slo,
                      shi, stamp, cnt, eps, max_depth, max_steps, buf, piecewise, pown, explog,
                      trig)
            j += 1
        for v in range(nv):
            s = var_slot[v]
            blo[r, v] = lo[s] if ok else np.nan
            bhi[r, v] = hi[s] if ok else np.nan
    return cnt[1]


@nb.njit(cache=True, error_model="numpy")
def bc_kernel(op, out, a, b, param, lo, hi, ptr, adj, cand, cptr, cnodes, rel_eps, eps,
              max_depth, max_steps, max_rounds, reach, min_gain, window, stats, piecewise=None,
              pown=None, explog=None, trig=None):
    """Hull consistency with box consistency (BC3) on top, in place on ``lo``/``hi``.

    First the whole tape is propagated to its fixed point. Then, round by round, each
    candidate still active (in ``cand`` order, then in reverse order on the next round; the
    candidates and their sub-networks from ``bc_closures``) has both bounds narrowed by BC3
    (``_bc3``: slices at most ``eps`` wide or ``max_depth`` bisections deep, ``max_steps``
    evaluations per bound); when that shrinks its domain by more than ``rel_eps`` of its width,
    the nodes using it become dirty and the dirty windows are propagated to the fixed point
    again (only those the change reaches). A candidate stays active in the next round only when
    it or one within ``reach`` positions of it lost more than ``min_gain`` of its width in this
    round; the rounds stop when none did, or after ``max_rounds``. Each BC3 search costs at most
    ``2 max_steps`` evaluations of a sub-network of bounded size, so the cost per candidate
    does not grow with the tape. ``stats`` receives the counters named in :data:`BC_STATS`.
    Returns DONE, or EMPTY when the network was proven to have no solution.
    """
    n = op.size
    nw = (n + window - 1) // window
    m = cand.size
    dirty = np.ones(n, dtype=np.bool_)
    pending = np.zeros(nw, dtype=np.int64)
    for i in range(n):
        pending[i // window] += 1
    span = np.array([0, nw - 1], dtype=np.int64)
    cnt = np.array([n, 0], dtype=np.int64)
    buf = np.empty(4)
    changed = np.empty(3, dtype=np.int64)
    tpos = np.zeros(1, dtype=np.int64)
    big = np.iinfo(np.int64).max
    n_slots = lo.size
    slo, shi = np.empty(n_slots), np.empty(n_slots)
    stamp = np.full(n_slots, -1, dtype=np.int64)
    bcnt = np.zeros(2, dtype=np.int64)
    for k in range(stats.size):
        stats[k] = 0
    if not _drain(op, out, a, b, param, lo, hi, ptr, adj, dirty, pending, span, window, rel_eps,
                  buf, changed, cnt, big, tpos[:0], buf[:0], tpos, piecewise, pown, explog, trig):
        stats[4] = cnt[1]
        return EMPTY
    total = cnt[1]
    _forget(dirty, pending, span, window, cnt)
    active = np.ones(m, dtype=np.bool_)
    gained = np.zeros(m, dtype=np.bool_)
    for rnd in range(max_rounds):
        stats[0] += 1
        for jj in range(m):
            j = jj if rnd % 2 == 0 else m - 1 - jj
            gained[j] = False
            if not active[j]:
                continue
            x = cand[j]
            l0, h0 = lo[x], hi[x]
            stats[1] += 1
            ok = _bc3(x, cptr[j], cptr[j + 1], cnodes, op, out, a, b, param, lo, hi, slo, shi,
                      stamp, bcnt, eps, max_depth, max_steps, buf, piecewise, pown, explog, trig)
            if not ok:
                stats[3] = bcnt[1]
                stats[4] = total
                return EMPTY
            if _significant(l0, h0, lo[x], hi[x], rel_eps):
                stats[2] += 1
                _touch(x, ptr, adj, dirty, pending, span, window, cnt)
                cnt[1] = 0
                ok = _drain(op, out, a, b, param, lo, hi, ptr, adj, dirty, pending, span,
                            window, rel_eps, buf, changed, cnt, big, tpos[:0], buf[:0], tpos,
                            piecewise, pown, explog, trig)
                total += cnt[1]
                if not ok:
                    stats[3] = bcnt[1]
                    stats[4] = total
                    return EMPTY
                _forget(dirty, pending, span, window, cnt)
            w0, w1 = h0 - l0, hi[x] - lo[x]
            gained[j] = w0 > 0 and w1 < w0 and (w0 == np.inf or w0 - w1 > min_gain * w0)
        anyg = False
        for j in range(m):
            active[j] = False
            anyg |= gained[j]
        if not anyg:
            break
        for j in range(m):
            if gained[j]:
                for q in range(max(0, j - reach), min(m, j + reach + 1)):
                    active[q] = True
    stats[3] = bcnt[1]
    stats[4] = total
    return DONE


@nb.njit(cache=True, error_model="numpy")
def repropagate_kernel(op, out, a, b, param, lo, hi, ptr, adj, slots, rel_eps, window, stats,
                       piecewise=None, pown=None, explog=None, trig=None):
    """Propagate the change of the domains of ``slots`` (made outside the engine, e.g. by an
    LP) from a fixed point: only the nodes using them become dirty, and only the windows the
    change reaches are revised, to the fixed point at ``rel_eps``. ``stats[0]`` receives the
    node revisions. Returns DONE or EMPTY."""
    n = op.size
    nw = (n + window - 1) // window
    dirty = np.zeros(n, dtype=np.bool_)
    pending = np.zeros(nw, dtype=np.int64)
    span = np.array([nw, -1], dtype=np.int64)
    cnt = np.zeros(2, dtype=np.int64)
    buf = np.empty(4)
    changed = np.empty(3, dtype=np.int64)
    tpos = np.zeros(1, dtype=np.int64)
    for s in slots:
        _touch(s, ptr, adj, dirty, pending, span, window, cnt)
    ok = _drain(op, out, a, b, param, lo, hi, ptr, adj, dirty, pending, span, window, rel_eps,
                buf, changed, cnt, np.iinfo(np.int64).max, tpos[:0], buf[:0], tpos, piecewise,
                pown, explog, trig)
    stats[0] = cnt[1]
    return DONE if ok else EMPTY
