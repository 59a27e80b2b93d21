"""The figures of Rohou et al. 2018: range-only robot (Figs. 8-9) and drifting clock (Figs. 11-12).

Each function takes a result of :mod:`boundest.scenarios.range_only` or
:mod:`boundest.scenarios.drifting_clock`, ``ax=None`` and an optional truth, and returns the
artists it drew.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..interval import Interval
from .boxes import _axes, plot_boxes
from .tube import plot_tube

if TYPE_CHECKING:
    from ..scenarios.drifting_clock import ClockResult, ClockTruth
    from ..scenarios.range_only import RangeOnlyResult, RobotTruth

__all__ = ["plot_clock_distance", "plot_clock_drift", "plot_range_only_diagonal",
           "plot_range_only_map"]


def plot_range_only_diagonal(res: RangeOnlyResult, ax: Any = None,
                             cmap: str = "viridis") -> list[Any]:
    """Rohou et al. 2018 Fig. 8: the position-box diagonal ``d(t)`` after each iteration (log
    scale),
    with the measurement time intervals ``[t_i]`` shaded in grey."""
    import matplotlib as mpl

    ax = _axes(ax)
    artists = [ax.axvspan(a, b, color="0.85", zorder=0,
                          label="measurement time intervals [t_i]" if i == 0 else None)
               for i, (a, b) in enumerate(zip(res.meas.t.lo, res.meas.t.hi, strict=True))]
    colours = mpl.colormaps[cmap](np.linspace(0, 0.9, max(len(res.diag), 1)))
    n = len(res.diag)
    for k, (d, c) in enumerate(zip(res.diag, colours, strict=False)):
        d = np.where(np.isfinite(d), d, np.nan)
        last = k == n - 1
        label = (f"iteration {k + 1}" if k == 0 or last else
                 (f"iterations 2..{n - 1} (dark to light)" if k == 1 else None))
        artists += ax.plot(res.diag_t, d, color="tab:red" if last else c,
                           linewidth=1.6 if last else 0.9, label=label)
    ax.set_yscale("log")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("diagonal of [x1](t) x [x2](t) (m)")
    ax.set_xlim(res.x.t[0], res.x.t[-1])
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    return artists


def plot_range_only_map(res: RangeOnlyResult, truth: RobotTruth | None = None, ax: Any = None,
                        range_max: float = 20.0) -> list[Any]:
    """Rohou et al. 2018 Fig. 9: the tube ``[x1](.) x [x2](.)`` projected on the plane (slice
    boxes),
    the positions over the contracted ``[t_i]`` darker, the beacons with their range circles and
    the true path."""
    from matplotlib.patches import Circle, Rectangle

    ax = _axes(ax)
    x = res.x
    artists = [plot_boxes(x.slices[:, 0], x.slices[:, 1], ax=ax, facecolor="lightgrey",
                          edgecolor="none", alpha=0.6,
                          label="position tube: one box per time slice")]
    mid = (x.t[:-1] + x.t[1:]) / 2
    inside = np.zeros(mid.size, dtype=bool)
    for a, b in zip(res.t.lo, res.t.hi, strict=True):
        if np.isfinite(a):
            inside |= (mid >= a) & (mid <= b)
    if inside.any():
        artists.append(plot_boxes(x.slices[inside, 0], x.slices[inside, 1], ax=ax,
                                  facecolor="tab:blue", edgecolor="none", alpha=0.5,
                                  label="slices within a contracted [t_i]"))
    bc = (res.meas.beacons.lo + res.meas.beacons.hi) / 2
    for k, (bx, by) in enumerate(bc):
        artists.append(ax.add_patch(Circle(
            (bx, by), range_max, fill=False, color="tab:red", linestyle="--", linewidth=0.8,
            label=f"beacon signal range ({range_max:g} m)" if k == 0 else None)))
        artists.append(ax.add_patch(Rectangle((bx - 1.5, by - 1.5), 3, 3, color="tab:red",
                                              label="beacon" if k == 0 else None)))
        name = res.meas.beacon_names[k] if res.meas.beacon_names else str(k)
        artists.append(ax.annotate(name, (bx, by - 2.5), color="darkred", ha="center",
                                   va="top", fontsize=9,
                                   bbox=dict(facecolor="white", alpha=0.7, edgecolor="none",
                                             pad=1)))
    if truth is not None:
        s = np.linspace(x.t[0], x.t[-1], 4 * x.n_slices + 1)
        p = truth.states(s)
        artists += ax.plot(p[:, 0], p[:, 1], color="black", linewidth=1.0,
                           label="true path (simulation)")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_aspect("equal")
    ax.set_xlabel("x1 (m)")
    ax.set_ylabel("x2 (m)")
    ax.autoscale_view()
    return artists


def plot_clock_distance(res: ClockResult, truth: ClockTruth | None = None,
                        ax: Any = None) -> list[Any]:
    """Rohou et al. 2018 Fig. 11: the ephemeris tube ``[y](.)`` with the measurements before (blue:
    ``[h]^{-1}(tau_i) x [z_i]`` from the derivative bounds alone) and after (red) contraction."""
    ax = _axes(ax)
    artists = plot_tube(res.y, ax=ax, color="tab:grey", alpha=0.4, gates=False,
                        truth=(lambda s: truth.distance(s)) if truth is not None else None,
                        label="tube [y](t)", truth_label="true distance (simulation)")
    artists.append(plot_boxes(res.t_initial, res.meas.z, ax=ax, facecolor="tab:blue",
                              edgecolor="navy", alpha=0.35,
                              label="measurement [t_i] x [z_i], [t_i] from the drift bounds"))
    artists.append(plot_boxes(res.t, res.z, ax=ax, facecolor="tab:red", edgecolor="darkred",
                              alpha=0.6, label="the same after contraction"))
    ax.set_xlabel("t: reference time (s)")
    ax.set_ylabel("y(t): boat-beacon distance (m)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, fontsize=8)
    return artists


def plot_clock_drift(res: ClockResult, truth: ClockTruth | None = None,
                     ax: Any = None) -> list[Any]:
    """Rohou et al. 2018 Fig. 12: the drift tube ``[h](.)``, the enclosures ``[t_i]`` of the
    reference
    times at each ``tau_i`` and the true drift."""
    ax = _axes(ax)
    artists = plot_tube(res.h, ax=ax, color="tab:grey", alpha=0.45, gates=False,
                        truth=(lambda s: truth.drift(s)) if truth is not None else None,
                        truth_color="black", label="tube [h](t)",
                        truth_label="true drift (simulation)")
    tau = res.meas.tau
    eps = Interval.trusted(tau.lo - 0.08, tau.hi + 0.08)
    artists.append(plot_boxes(res.t_initial, eps, ax=ax, facecolor="tab:blue",
                              edgecolor="navy", alpha=0.35,
                              label="[t_i] at clock time tau_i, from the drift bounds"))
    artists.append(plot_boxes(res.t, eps, ax=ax, facecolor="tab:red", edgecolor="darkred",
                              alpha=0.7, label="[t_i] after contraction"))
    ax.set_xlabel("t: reference time (s)")
    ax.set_ylabel("tau = h(t): clock time (s)")
    ax.legend(loc="upper left", fontsize=8)
    return artists
