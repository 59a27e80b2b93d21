"""The compiled propagation kernel: AC3-style revisions of the primitive nodes of a tape.

Each node ``z = f(x, y)`` is revised by ``z ∩= f(x, y)`` then ``(x, y) = f_rev(z, x, y)``. When a
slot's domain shrinks by more than ``rel_eps`` of its width (or loses an infinite bound), every
other node using that slot becomes dirty again. Dirty nodes are revised window by window along
the tape order (the order of the constraints, i.e. of the time steps for a time series), in
alternating forward and backward passes, so that the work per time step does not grow with the
horizon.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from ..ctc.revise import family_flags
from ..ctc.revise import revise as _revise

__all__ = ["DONE", "EMPTY", "RUNNING", "family_flags", "propagate_kernel"]

DONE, RUNNING, EMPTY = 0, 1, 2
#: A window that has not settled after this many local sweeps hands its remaining dirty nodes
#: to the next pass (a safeguard against slowly converging cycles; it never loses soundness).
_LOCAL_SWEEPS = 64
@nb.njit(cache=True, inline="always", error_model="numpy")
def _significant(ol, oh, nl, nh, rel_eps):
    """Whether ``[ol, oh] -> [nl, nh]`` is a shrink worth propagating."""
    if nl == ol and nh == oh:
        return False
    w0 = oh - ol
    if w0 == np.inf:
        return True  # a bound became finite or moved: cheap to propagate, often decisive
    return (w0 - (nh - nl)) > rel_eps * w0


@nb.njit(cache=True, error_model="numpy")
def _update(s, nl, nh, lo, hi, rel_eps):
    """Intersect slot ``s`` with ``[nl, nh]``: -1 empty, 1 significant shrink, 0 otherwise."""
    ol, oh = lo[s], hi[s]
    nl = max(nl, ol) if nl == nl else nl  # NaN (empty) must survive the max
    nh = min(nh, oh) if nh == nh else nh
    if nl != nl or nh != nh or nl > nh:
        lo[s] = np.nan
        hi[s] = np.nan
        return -1
    sig = _significant(ol, oh, nl, nh, rel_eps)
    lo[s] = nl
    hi[s] = nh
    return 1 if sig else 0


@nb.njit(cache=True, inline="always", error_model="numpy")
def _revise_node(i, op, out, a, b, param, lo, hi, ptr, adj, dirty, pending, window, rel_eps,
                 buf, changed, piecewise, pown, explog, trig):
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
    r = _update(o, zl, zh, lo, hi, rel_eps)
    if r < 0:
        return -1
    if r > 0:
        changed[nch] = o
        nch += 1
    r = _update(ia, xl, xh, lo, hi, rel_eps)
    if r < 0:
        return -1
    if r > 0:
        changed[nch] = ia
        nch += 1
    if ib >= 0:
        r = _update(ib, yl, yh, lo, hi, rel_eps)
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
            if (j != i or again) and not dirty[j]:
                dirty[j] = True
                pending[j // window] += 1
                added += 1
    return added


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
    wpos, count, evals, direction = state[0], state[1], 0, state[4]
    buf = np.empty(4)
    changed = np.empty(3, dtype=np.int64)
    status = RUNNING
    while count > 0 and evals < max_evals and status == RUNNING:
        if wpos >= nw:  # end of a pass: turn round
            wpos = 0
            direction = -direction
        w = wpos if direction > 0 else nw - 1 - wpos
        wpos += 1
        first, last = w * window, min((w + 1) * window, n)
        d = direction
        sweeps = 0
        while pending[w] > 0 and sweeps < _LOCAL_SWEEPS and evals < max_evals:
            sweeps += 1
            i = first if d > 0 else last - 1
            while first <= i < last and evals < max_evals:
                if dirty[i]:
                    dirty[i] = False
                    pending[w] -= 1
                    count -= 1
                    evals += 1
                    r = _revise_node(i, op, out, a, b, param, lo, hi, ptr, adj, dirty, pending,
                                     window, rel_eps, buf, changed, piecewise, pown,
                                     explog, trig)
                    if r < 0:
                        status = EMPTY
                        break
                    count += r
                i += d
            if status == EMPTY:
                break
            d = -d
    if status != EMPTY and count == 0:
        status = DONE
    state[0], state[1], state[2], state[3], state[4] = wpos, count, status, state[3] + evals, \
        direction
    return status
