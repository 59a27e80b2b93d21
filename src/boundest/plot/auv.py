"""Figures of the AUV survey: the north/east map, position widths against time, depth profile."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from .boxes import _axes

if TYPE_CHECKING:
    from ..scenarios.auv import AuvResult
    from ..scenarios.auv_data import AuvData
    from ..scenarios.auv_sim import AuvTruth

#: colours of the figures, one meaning each (every one is in a legend)
LOC, SLAM, GPS, MINE, DET, TRUTH = "#9ecae1", "#3182bd", "#d62728", "#ff7f0e", "#636363", "k"


def _rects(ax: Any, lo: np.ndarray, hi: np.ndarray, **kw: Any) -> Any:
    """Rectangles ``[lo_x, hi_x] x [lo_y, hi_y]`` as one collection."""
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Rectangle

    ok = np.all(np.isfinite(lo) & np.isfinite(hi), axis=1)
    patches = [Rectangle((a[0], a[1]), b[0] - a[0], b[1] - a[1])
               for a, b in zip(lo[ok], hi[ok], strict=True)]
    coll = PatchCollection(patches, **kw)
    ax.add_collection(coll)
    return coll


def plot_auv_map(data: AuvData, results: list[AuvResult], truth: AuvTruth | None = None,
                 every_s: float = 120.0, ax: Any = None) -> Any:
    """North (up) against east (right): the position boxes every ``every_s`` seconds for each
    result (localization pale, SLAM dark), the GPS boxes, the mine boxes and the detection
    geometry (a line from the vehicle's box centre to its mine's box centre)."""
    ax = _axes(ax)
    step = max(1, round(every_s / data.dt))
    for res in results:
        if not res.consistent:
            continue
        p = res.positions[::step]
        colour = SLAM if res.mode == "slam" else LOC
        _rects(ax, np.stack([p.lo[:, 1], p.lo[:, 0]], 1), np.stack([p.hi[:, 1], p.hi[:, 0]], 1),
               facecolor=colour, edgecolor=colour, alpha=0.35, lw=0.5)
        ax.plot([], [], "s", color=colour, alpha=0.6,
                label=f"position box every {every_s:g} s ({res.mode})")
        mid = res.positions.mid()
        ax.plot(mid[:, 1], mid[:, 0], color=colour, lw=0.6, label=f"box centres ({res.mode})")
    f = data.fix
    _rects(ax, np.stack([f.lo[:, 1], f.lo[:, 0]], 1), np.stack([f.hi[:, 1], f.hi[:, 0]], 1),
           facecolor="none", edgecolor=GPS, lw=1.5)
    # a fix box is metres wide on a map of kilometres: a marker at its centre shows where it is
    fc = f.mid()
    ax.plot(fc[:, 1], fc[:, 0], "s", mfc="none", mec=GPS, ms=8, mew=1.5, ls="none", zorder=4,
            label="GPS fix (first, last sample)")
    slam = [r for r in results if r.mode == "slam" and r.consistent]
    if slam:
        m, p = slam[0].mines, slam[0].positions
        _rects(ax, np.stack([m.lo[:, 1], m.lo[:, 0]], 1), np.stack([m.hi[:, 1], m.hi[:, 0]], 1),
               facecolor=MINE, edgecolor=MINE, alpha=0.45, lw=1)
        ax.plot([], [], "s", color=MINE, alpha=0.6, label="mine box (SLAM)")
        mm, pm = m.mid(), p.mid()
        for k, j in zip(data.det_k, data.det_mine, strict=True):
            ax.plot([pm[k, 1], mm[j, 1]], [pm[k, 0], mm[j, 0]], color=DET, lw=0.8, ls="--")
        ax.plot([], [], color=DET, lw=0.8, ls="--", label="detection (vehicle to mine)")
        for j in range(m.shape[0]):
            ax.annotate(f"mine {j}", (m.hi[j, 1], m.hi[j, 0]), xytext=(3, 3),
                        textcoords="offset points", fontsize=8, color="#a04000",
                        bbox=dict(facecolor="white", alpha=0.8, edgecolor="none", pad=1))
    if truth is not None:
        ax.plot(truth.p[:, 1], truth.p[:, 0], color=TRUTH, lw=0.6, label="true path")
        ax.plot(truth.mines[:, 1], truth.mines[:, 0], "k*", ms=6, label="true mine")
    ax.set_xlabel("east (m)")
    ax.set_ylabel("north (m)")
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.legend(loc="best", fontsize=8)
    return ax


def plot_auv_widths(data: AuvData, results: list[AuvResult], ax: Any = None) -> Any:
    """Width of the north and east position boxes against time, for each result."""
    ax = _axes(ax)
    t = data.t
    for res in results:
        if not res.consistent:
            continue
        w = res.widths()
        colour = SLAM if res.mode == "slam" else LOC
        ax.plot(t, w[:, 0], color=colour, lw=1.2, label=f"north ({res.mode})")
        ax.plot(t, w[:, 1], color=colour, lw=1.2, ls="--", label=f"east ({res.mode})")
    for k in data.det_k:
        ax.axvline(t[k], color=DET, lw=0.5, alpha=0.6)
    ax.plot([], [], color=DET, lw=0.5, label="detection times")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("width of the position box (m)")
    ax.legend(loc="upper right", fontsize=8)
    return ax


def plot_auv_depth(data: AuvData, res: AuvResult, truth: AuvTruth | None = None,
                   ax: Any = None) -> Any:
    """The depth ``p_z`` against time: the estimated boxes and the depth sensor's boxes."""
    ax = _axes(ax)
    t = data.t
    ax.fill_between(t, data.depth.lo, data.depth.hi, color=LOC, alpha=0.6, lw=0,
                    label="depth sensor box")
    if res.consistent:
        z = res.positions[:, 2]
        ax.plot(t, z.lo, color=SLAM, lw=0.6, label=f"estimated depth bounds ({res.mode})")
        ax.plot(t, z.hi, color=SLAM, lw=0.6)
    if truth is not None:
        ax.plot(t, truth.p[:, 2], color=TRUTH, lw=0.6, label="true depth")
    ax.invert_yaxis()
    ax.set_xlabel("time (s)")
    ax.set_ylabel("depth (m, down)")
    ax.legend(loc="center", fontsize=8)
    return ax
