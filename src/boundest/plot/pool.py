"""Figures of the pool robot (Jaulin's robust set-membership observer): snapshots of the mission
with the window's sonar pings, the emission diagram of one revolution, the trajectory with its
envelope and the widths against time.

A ping ``j`` is drawn as *kept* or *rejected* by :func:`ping_consistency`: a cheap per-ping test
made for the figures (the observer itself only reports how many pings of a window miss its set).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..interval import Interval
from .auv import _rects
from .boxes import _axes

if TYPE_CHECKING:
    from ..scenarios.pool import PoolResult
    from ..scenarios.pool_data import PoolData

#: colours of the figures, one meaning each (every one is in a legend)
WALL, PILLAR, BOX, PATH, KEPT, REJECTED = "k", "#8c564b", "#3182bd", "#08306b", "#fd8d3c", "0.35"
CELL = "#31a354"


def ping_consistency(data: PoolData, res: PoolResult) -> NDArray[np.bool_]:
    """Whether ping ``j`` is consistent with the observer's set at its own time, for every
    ``j``: the ray-cast contractor :class:`boundest.ctc.CtcRayCast` on the box
    ``(x_j, y_j, theta_j + alpha_j, d_j)`` (from ``X_j`` and the ping) does not empty it.

    A figure's approximation of the observer's rejection: the observer tests each ping of the
    window against the current set ``X_k`` with the ping's set propagated to ``k``; this test uses
    ``X_j`` and one contractor pass. ``False`` is sound (no state of ``X_j`` explains the ping),
    ``True`` only means the contractor could not prove the ping inconsistent.
    """
    from ..ctc import CtcRayCast

    b, d = res.boxes, data.ranges
    beta_lo, beta_hi = b.lo[:, 2] + data.alpha, b.hi[:, 2] + data.alpha
    with np.errstate(invalid="ignore"):
        box = Interval.trusted(np.stack([b.lo[:, 0], b.lo[:, 1], np.nextafter(beta_lo, -np.inf),
                                      d.lo], -1),
                            np.stack([b.hi[:, 0], b.hi[:, 1], np.nextafter(beta_hi, np.inf),
                                      d.hi], -1))
        out = CtcRayCast(data.map)(box)
    return ~np.isnan(out.lo).any(axis=-1) & ~np.isnan(b.lo).any(axis=-1)


def window_of(res: PoolResult, k: int) -> NDArray[np.intp]:
    """The pings of the observer's window at step ``k``: the last ``m`` ones (a restart keeps
    them: it solves the window again from the open-loop prior)."""
    return np.arange(max(k - res.m + 1, 0), k + 1)


def plot_pool_map(data: PoolData, ax: Any = None, legend: bool = True) -> Any:
    """The pool's walls (segments) and pillars (discs) from the map, equal aspect."""
    from matplotlib.patches import Circle

    ax = _axes(ax)
    seg = data.map.segments
    # above the boxes drawn later (zorder 1): a wide set does not hide the map it is read on
    for s in seg:
        ax.plot(s[:, 0], s[:, 1], color=WALL, lw=1.5, zorder=3)
    for c, r in zip(data.map.centers, data.map.radii, strict=True):
        ax.add_patch(Circle((c[0], c[1]), r, facecolor=PILLAR, edgecolor=PILLAR, alpha=0.8,
                            zorder=3))
    if legend:
        ax.plot([], [], color=WALL, lw=1.5, label="pool wall")
        ax.plot([], [], "o", color=PILLAR, label="pillar")
    pts = seg.reshape(-1, 2)
    pad = 0.5
    ax.set_xlim(pts[:, 0].min() - pad, pts[:, 0].max() + pad)
    ax.set_ylim(pts[:, 1].min() - pad, pts[:, 1].max() + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    return ax


def _rays(ax: Any, x0: NDArray, y0: NDArray, beta: NDArray, d: NDArray, **kw: Any) -> None:
    from matplotlib.collections import LineCollection

    ok = np.isfinite(x0) & np.isfinite(y0) & np.isfinite(beta) & np.isfinite(d)
    x0, y0, beta, d = x0[ok], y0[ok], beta[ok], d[ok]
    lines = np.stack([np.stack([x0, y0], -1),
                      np.stack([x0 + d * np.cos(beta), y0 + d * np.sin(beta)], -1)], 1)
    ax.add_collection(LineCollection(lines, **kw))


def plot_pool_snapshot(data: PoolData, res: PoolResult, k: int,
                       consistent: NDArray[np.bool_], ax: Any = None, pings: bool = True) -> Any:
    """The pool, the centre path up to step ``k``, the ``(x, y)`` box at ``k`` and (``pings``)
    the window's pings: ping ``j`` drawn from the centre of ``X_j`` along
    ``theta_centre_j + alpha_j`` with the length ``d_mid`` of its range box, kept pings in one
    colour and those :func:`ping_consistency` rejects in grey (none where ``theta_j`` is
    unbounded, after a restart)."""
    ax = plot_pool_map(data, ax)
    c = res.centre()
    ax.plot(c[: k + 1, 0], c[: k + 1, 1], color=PATH, lw=0.8, label="box centre path")
    if pings:
        j = window_of(res, k)
        d = data.ranges[j].mid()
        th = res.boxes[j, 2]
        bounded = np.isfinite(th.lo) & np.isfinite(th.hi)  # no heading after a restart
        beta = np.where(bounded, c[j, 2] + data.alpha[j], np.nan)
        ok = consistent[j]
        _rays(ax, c[j, 0][ok], c[j, 1][ok], beta[ok], d[ok], colors=KEPT, lw=0.5, alpha=0.5)
        _rays(ax, c[j, 0][~ok], c[j, 1][~ok], beta[~ok], d[~ok], colors=REJECTED, lw=1.6,
              zorder=3)
        ax.plot([], [], color=KEPT, lw=0.8, label=f"kept ping ({int(ok.sum())})")
        ax.plot([], [], color=REJECTED, lw=1.6,
                label=f"rejected ping ({int((~ok).sum())})")
    b = res.boxes[k]
    # the fill under the map and the rays (a wide box, as the window observer's, hid the
    # pillars and tinted the kept rays the grey of the rejected ones), its outline over them
    _rects(ax, b.lo[None, :2], b.hi[None, :2], facecolor=BOX, edgecolor="none", alpha=0.7,
           zorder=1)
    _rects(ax, b.lo[None, :2], b.hi[None, :2], facecolor="none", edgecolor=PATH, lw=1, zorder=4)
    ax.plot([], [], "s", color=BOX, alpha=0.7, mec=PATH, label="(x, y) box at this time")
    if res.paving is not None and res.cells[k]:
        cells = res.paving[k, : min(int(res.cells[k]), res.paving.shape[-2])]
        what = "heading slices" if res.eps and res.eps[1] is not None else "paving cells"
        # the box is a few pixels wide at the pool's scale: its cells are drawn in a zoom
        ins = ax.inset_axes([0.075, 0.56, 0.27, 0.41], zorder=6)  # tick labels inside ax
        _rects(ins, b.lo[None, :2], b.hi[None, :2], facecolor=BOX, edgecolor=PATH, alpha=0.5,
               lw=1)
        _rects(ins, cells.lo[:, :2], cells.hi[:, :2], facecolor="none", edgecolor=CELL, lw=0.8,
               zorder=5)
        lo, hi = b.lo[:2], b.hi[:2]
        half = 0.6 * float(np.max(hi - lo))
        mid = (lo + hi) / 2
        ins.set_xlim(mid[0] - half, mid[0] + half)
        ins.set_ylim(mid[1] - half, mid[1] + half)
        ins.set_aspect("equal")
        ins.tick_params(labelsize=6, pad=1)
        ax.indicate_inset_zoom(ins, edgecolor="0.3")
        ax.plot([], [], "s", mfc="none", mec=CELL,
                label=f"{what} kept ({int(res.cells[k])}; zoom, top left)")
    return ax


def plot_pool_emission(data: PoolData, consistent: NDArray[np.bool_], k: int | None = None,
                       pings: int = 80, ax: Any = None) -> Any:
    """The emission diagram at step ``k`` (default: the last): the last ``pings`` pings (one
    sonar revolution) in the robot frame, ray ``j`` along ``alpha_j`` with length ``d_mid`` and
    its range box ``[d_lo, d_hi]`` drawn thick; rejected pings (:func:`ping_consistency`) grey."""
    ax = _axes(ax)
    k = data.n - 1 if k is None else k
    j = np.arange(max(0, k - pings + 1), k + 1)
    a, d = data.alpha[j], data.ranges[j]
    mid = d.mid()
    ok = consistent[j]
    zero = np.zeros(j.size)
    for sel, colour, name in ((ok, KEPT, "kept"), (~ok, REJECTED, "rejected")):
        z = 3 if name == "rejected" else 2
        _rays(ax, zero[sel], zero[sel], a[sel], mid[sel], colors=colour, lw=0.8, zorder=z)
        lo = np.clip(d.lo[sel], 0, None)
        _rays(ax, lo * np.cos(a[sel]), lo * np.sin(a[sel]), a[sel], d.hi[sel] - lo,
              colors=colour, lw=3, zorder=z)
        ax.plot([], [], color=colour, lw=0.8, label=f"{name} ping: ray to d_mid "
                f"({int(sel.sum())})")
        ax.plot([], [], color=colour, lw=3, label=f"range box [d_lo, d_hi] of a {name} ping")
    ax.plot([0], [0], "^", color=PATH, ms=9, label="robot (heading +x)")
    ax.set_aspect("equal")
    end = np.stack([mid * np.cos(a), mid * np.sin(a)], -1)
    end = np.concatenate([end[np.isfinite(end).all(-1)], np.zeros((1, 2))])
    pad = 0.05 * float(np.ptp(end, axis=0).max()) + 0.5
    ax.set_xlim(end[:, 0].min() - pad, end[:, 0].max() + pad)
    ax.set_ylim(end[:, 1].min() - pad, end[:, 1].max() + pad)
    ax.set_xlabel("forward, robot frame (m)")
    ax.set_ylabel("left, robot frame (m)")
    ax.legend(loc="upper left", fontsize=7)
    return ax


def plot_pool_trajectory(data: PoolData, res: PoolResult, every: int = 10,
                         ax: Any = None) -> Any:
    """The pool, the ``(x, y)`` boxes every ``every`` steps (the envelope) and the centre path."""
    ax = plot_pool_map(data, ax)
    b = res.boxes[::every]
    _rects(ax, b.lo[:, :2], b.hi[:, :2], facecolor=BOX, edgecolor=BOX, alpha=0.25, lw=0.5,
           zorder=1)
    ax.plot([], [], "s", color=BOX, alpha=0.5,
            label=f"(x, y) box every {every} steps ({every * data.dt:g} s)")
    c = res.centre()
    ax.plot(c[:, 0], c[:, 1], color=PATH, lw=1, label="box centre path")
    ax.plot(c[:1, 0], c[:1, 1], "o", color=PATH, ms=4, label="start")
    restarts = np.flatnonzero(res.empty)
    if restarts.size:
        ax.plot(c[restarts - 1, 0], c[restarts - 1, 1], "x", color="r", ms=8,
                label="restart (empty set)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=3, fontsize=8,
              frameon=False)
    return ax


def plot_pool_widths(data: PoolData, res: PoolResult, ax: Any = None) -> Any:
    """Widths of ``x``, ``y`` (left axis, m) and ``theta`` (right axis, rad) against time."""
    ax = _axes(ax)
    t, w = data.t, res.widths()
    with np.errstate(invalid="ignore"):
        w = np.where(np.isfinite(w), w, np.nan)
    lx = ax.plot(t, w[:, 0], color="#1f77b4", lw=1.2, label="x width (m)")
    ly = ax.plot(t, w[:, 1], color="#2ca02c", lw=1.2, label="y width (m)")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("width of x, y (m)")
    ax2 = ax.twinx()
    lt = ax2.plot(t, w[:, 2], color="#d62728", lw=1.2, ls="--", label="theta width (rad)")
    ax2.set_ylabel("width of theta (rad)")
    handles = lx + ly + lt
    for k in np.flatnonzero(res.empty):
        ax.axvline(t[k], color="r", lw=0.8, ls=":")
    if res.empty.any():
        handles.append(ax.plot([], [], color="r", lw=0.8, ls=":", label="restart")[0])
    ax.set_ylim(bottom=0)
    ax2.set_ylim(bottom=0)
    ax.legend(handles=handles, loc="upper right", fontsize=8)
    return ax
