"""Figures a person reads: every drawn colour has a legend entry, the Jaulin et al. 2001 set
sequence is one zoomed panel per step with ticks, boxes and pavings carry their labels."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

import boundest as bd
from boundest.plot import plot_boxes, plot_paving, plot_set_sequence

FRAME = bd.Interval([-4.0, -4.0], [4.0, 4.0])


def _ring(cx: float, cy: float) -> bd.Subpaving:
    x, y = bd.Var("x"), bd.Var("y")
    box = bd.Interval([cx - 1, cy - 1], [cx + 1, cy + 1])
    return bd.sivia(box, f=(x - cx) ** 2 + (y - cy) ** 2, y=bd.Interval([0.09], [0.25]),
                    eps=0.05)


def _legend_texts(fig) -> list[str]:
    return [t.get_text() for leg in fig.legends for t in leg.get_texts()]


def test_plot_boxes_and_paving_carry_legend_labels():
    fig, ax = plt.subplots()
    plot_boxes(bd.Interval([0, 1], [1, 2]), bd.Interval([0, 0], [1, 1]), ax=ax, label="boxes")
    plot_paving(_ring(0, 0), ax=ax)
    _, labels = ax.get_legend_handles_labels()
    assert labels == ["boxes", "boundary", "inside"]
    plt.close(fig)


@pytest.mark.parametrize("boxes", [False, True])
def test_set_sequence_has_one_zoomed_panel_per_step_and_a_legend(boxes):
    centres = [(-2.0, 1.0), (2.0, 2.0), (1.0, -2.5)]
    if boxes:
        causal = [FRAME] + [bd.Interval([cx - 0.6, cy - 0.6], [cx + 0.6, cy + 0.6])
                            for cx, cy in centres[1:]]
        noncausal = [bd.Interval([cx - 0.5, cy - 0.5], [cx + 0.5, cy + 0.5])
                     for cx, cy in centres]
    else:
        causal = [FRAME] + [_ring(cx, cy) for cx, cy in centres[1:]]
        noncausal = [_ring(cx, cy) for cx, cy in centres]
    truth = np.array(centres)
    fig = plot_set_sequence([causal, noncausal], ["causal (RCSE)", "non-causal (NCSE)"], FRAME,
                            truth=truth)
    visible = [ax for ax in fig.axes if ax.get_visible() and ax.get_label() != "<colorbar>"]
    assert len(visible) == 1 + len(centres)           # the overview, then one panel per k
    for k, ax in enumerate(visible[1:]):
        assert ax.get_title().startswith(f"k = {k}")
        assert len(ax.get_xticks()) >= 2 and len(ax.get_yticks()) >= 2
        lo, hi = ax.get_xlim()
        cx = centres[k][0]
        assert lo < cx < hi and hi - lo < 4.0          # zoomed on the set, not the frame
    texts = _legend_texts(fig)
    assert "true state" in texts
    if boxes:
        assert "non-causal (NCSE): box domain (encloses the set)" in texts
    else:
        for name in ("causal (RCSE)", "non-causal (NCSE)"):
            assert any(t.startswith(f"{name}: inside") for t in texts)
            assert any(t.startswith(f"{name}: boundary") for t in texts)
    plt.close(fig)


def test_set_sequence_counts_boxes_outside_the_zoom():
    far = _ring(-2.5, -2.5).union(_ring(2.5, 2.5))   # two pieces, the zoom shows one
    fig = plot_set_sequence([[far], [_ring(2.5, 2.5)]], ["causal (RCSE)", "non-causal (NCSE)"],
                            FRAME)
    title = fig.axes[1].get_title()
    assert "RCSE boxes out of view" in title
    plt.close(fig)


def test_set_sequence_refuses_mismatched_labels():
    with pytest.raises(ValueError, match="one label per estimator"):
        plot_set_sequence([[FRAME]], ["a", "b"], FRAME)


def test_set_sequence_says_which_sets_are_empty():
    empty = bd.Subpaving.empty(2)
    fig = plot_set_sequence([[FRAME, empty], [empty, empty]],
                            ["causal (RCSE)", "non-causal (NCSE)"], FRAME)
    assert "NCSE: empty" in fig.axes[1].get_title()
    assert "RCSE, NCSE: empty" in fig.axes[2].get_title()
    plt.close(fig)


def test_command_figures_are_written_without_pyplot(tmp_path):
    from PIL import Image

    from boundest.commands import save_figure, subplots

    before = plt.get_fignums()
    fig, ax = subplots(figsize=(4, 3))
    plot_boxes(bd.Interval([0, 1], [1, 2]), bd.Interval([0, 0], [1, 1]), ax=ax, label="boxes")
    ax.legend()
    png = save_figure(fig, tmp_path / "new", "boxes", dpi=100)
    assert plt.get_fignums() == before                  # never registered with pyplot
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["boxes"]
    with Image.open(png) as im:
        assert im.format == "PNG" and im.size == (400, 300)


def test_save_figure_closes_a_pyplot_figure(tmp_path):
    from boundest.commands import save_figure

    fig, ax = plt.subplots(figsize=(3, 2))
    ax.plot([0, 1], [0, 1])
    save_figure(fig, tmp_path, "line")
    assert fig.number not in plt.get_fignums()
    assert (tmp_path / "line.png").stat().st_size > 1000


SUBPLOTS_ALONE = """
import sys
from boundest.commands import save_figure, subplots
fig, ax = subplots()
ax.plot([0, 1], [0, 1])
save_figure(fig, sys.argv[1], "line")
print("pyplot" if "matplotlib.pyplot" in sys.modules else "no pyplot")
"""


def test_command_figures_do_not_import_pyplot(tmp_path):
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", SUBPLOTS_ALONE, str(tmp_path)],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().endswith("no pyplot"), out.stdout


def _drawn(monkeypatch, module) -> list:
    """Figures that ``module``'s draw functions save, laid out and drawn, not written."""
    figs = []

    def keep(fig, out, name, dpi=120, tight=True):
        if tight and fig.get_layout_engine() is None:
            fig.tight_layout()
        fig.canvas.draw()
        figs.append((name, fig))

    monkeypatch.setattr(module, "save_figure", keep)
    return figs


class _Orbit:
    """A satellite result whose boxes drift along a long strip, as with ``--kmax 800``."""

    def __init__(self, k_max: int = 800) -> None:
        k = np.arange(k_max + 1)
        c = np.stack([4.0 - 80.0 * k / k_max + 3 * np.cos(k / 25), -15.0 * k / k_max
                      + 3 * np.sin(k / 25)], 1)
        c[0] = (4.0, 0.0)
        half = 0.05 + 0.5 * k[:, None] / k_max
        self.x_lo, self.x_hi = c - half, c + half

    def box(self, k: int) -> bd.Interval:
        return bd.Interval(self.x_lo[k], self.x_hi[k])


@pytest.mark.parametrize("k_max", [200, 800])
def test_satellite_figure_takes_the_orbits_shape_and_labels_stay_clear(monkeypatch, k_max):
    from matplotlib.text import Text
    from matplotlib.transforms import Bbox

    from boundest.commands import satellite

    figs = _drawn(monkeypatch, satellite)
    res = _Orbit(k_max)
    satellite.draw_figure(res, k_max, "unused")
    (name, fig), = figs
    assert name == f"satellite_k{k_max}"
    ax = fig.axes[0]
    r = fig.canvas.get_renderer()
    frame = ax.get_window_extent(r)
    # the canvas follows the data: the axes (of equal scales) fill most of it
    w, h = fig.get_size_inches() * fig.dpi
    assert frame.width * frame.height > 0.45 * w * h, (frame.bounds, w, h)
    labels = [t for t in ax.texts if t.get_text().startswith("k = ")]
    assert [t.get_text() for t in labels] == ["k = 0", f"k = {k_max}"]
    ex, ey = ax.transData.transform((0.0, 0.0))
    earth = Bbox.from_extents(ex - 4, ey - 4, ex + 4, ey + 4)
    ticks = [t.get_window_extent(r) for t in ax.get_yticklabels() + ax.get_xticklabels()
             if t.get_text()]
    for t in labels:
        ext = Text.get_window_extent(t, r)  # the text, not its leader line
        assert frame.x0 <= ext.x0 and ext.x1 <= frame.x1, (t.get_text(), ext, frame)
        assert frame.y0 <= ext.y0 and ext.y1 <= frame.y1, (t.get_text(), ext, frame)
        assert not ext.overlaps(earth) and not any(ext.overlaps(b) for b in ticks)
    fig.clf()


def _pool_result(window_only: bool = False, cells: bool = False):
    """The embedded pool mission with made-up sets: boxes 0.4 m wide along a straight path
    (or, ``window_only``, as wide as the pool), cut into four cells each (``cells``)."""
    from boundest.scenarios.pool import PoolResult
    from boundest.scenarios.pool_data import load_pool

    data = load_pool()
    n = data.n
    c = np.stack([np.linspace(2.5, 17.0, n), np.linspace(2.0, 5.0, n), np.zeros(n),
                  np.zeros(n)], 1)
    half = np.array([10.0, 5.0, 0.1, 0.1]) if window_only else np.array([0.2, 0.2, 0.1, 0.1])
    boxes = bd.Interval(c - half, c + half)
    paving = None
    if cells:
        lo, hi = boxes.lo, boxes.hi
        mid = (lo + hi) / 2
        quads = []
        for qx in (0, 1):
            for qy in (0, 1):
                a, b = lo.copy(), hi.copy()
                a[:, 0], b[:, 0] = (lo[:, 0], mid[:, 0]) if qx == 0 else (mid[:, 0], hi[:, 0])
                a[:, 1], b[:, 1] = (lo[:, 1], mid[:, 1]) if qy == 0 else (mid[:, 1], hi[:, 1])
                quads.append((a, b))
        paving = bd.Interval(np.stack([a for a, _ in quads], 1), np.stack([b for _, b in quads], 1))
    res = PoolResult(boxes, np.zeros(n, dtype=np.intp), np.zeros(n, dtype=bool),
                     np.ones(n), 8, 80, 0.0, np.full(n, 4 if cells else 0, dtype=np.intp),
                     paving, (None, 0.01) if cells else None)
    return data, res


def test_pool_trajectory_names_its_observer_and_draws_the_map_over_the_boxes(monkeypatch):
    import argparse

    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle

    from boundest.commands import pool

    figs = _drawn(monkeypatch, pool)
    data, res = _pool_result(window_only=True)
    args = argparse.Namespace(q=8, m=80, window_only=True, out="unused")
    pool.draw_trajectory(data, res, np.ones(data.n, dtype=bool), args)
    (_, fig), = figs
    ax = fig.axes[0]
    assert "window observer" in ax.get_title() and "recursive" not in ax.get_title()
    pillars = [p for p in ax.patches if isinstance(p, Circle)]
    boxes = [c for c in ax.collections if isinstance(c, PatchCollection)]
    assert pillars and boxes
    assert min(p.get_zorder() for p in pillars) > max(c.get_zorder() for c in boxes)
    fig.clf()


def test_pool_snapshot_shows_its_cells_in_a_zoom():
    from matplotlib.colors import to_rgba

    from boundest.plot.pool import CELL, plot_pool_snapshot

    data, res = _pool_result(cells=True)
    fig, ax = plt.subplots(figsize=(5, 2.6))
    k = data.n // 2
    plot_pool_snapshot(data, res, k, np.ones(data.n, dtype=bool), ax=ax, pings=False)
    zoom, = ax.child_axes
    lo, hi = zoom.get_xlim()
    box = res.boxes[k]
    assert lo < box.lo[0] and box.hi[0] < hi and hi - lo < 3 * float(box.width()[0])
    cells = [c for c in zoom.collections if tuple(c.get_edgecolor()[0]) == to_rgba(CELL)]
    assert [len(c.get_paths()) for c in cells] == [4]     # the four cells, in the legend's colour
    _, labels = ax.get_legend_handles_labels()
    assert any(lb.startswith("heading slices kept (4") for lb in labels)
    plt.close(fig)


def test_set_sequence_says_when_a_set_spans_the_frame_and_draws_specks_in_colour():
    """A thin set across the whole frame (the non-causal x(0) of Jaulin et al. 2001): its
    panel cannot zoom and says so; its boxes, far below a point wide, keep the legend's colour
    instead of showing their black edges only."""
    from matplotlib.colors import to_rgba

    from boundest.plot.estimation import SET_STYLES

    x, y = bd.Var("x"), bd.Var("y")
    line = bd.sivia(FRAME, f=x + y, y=bd.Interval([-0.02], [0.02]), eps=0.05)
    fig = plot_set_sequence([[FRAME, _ring(1, 1)], [line, _ring(1, 1)]],
                            ["causal (RCSE)", "non-causal (NCSE)"], FRAME)
    k0, k1 = fig.axes[1], fig.axes[2]
    assert "spans the frame" in k0.get_title() and "spans" not in k1.get_title()
    # a box as tall as most of the frame but narrow is framed as usual, without the note
    fig2 = plot_set_sequence([[FRAME, bd.Interval([-0.1, -3.0], [0.1, 3.0])]] * 2,
                             ["causal (RCSE)", "non-causal (NCSE)"], FRAME)
    assert "spans" in fig2.axes[1].get_title() and "spans" not in fig2.axes[2].get_title()
    plt.close(fig2)
    boundary = to_rgba(SET_STYLES[1][1])
    drawn = [c for c in k0.collections if len(c.get_facecolor())
             and tuple(c.get_facecolor()[0]) == boundary]
    assert drawn and all(tuple(c.get_edgecolor()[0]) == boundary for c in drawn)
    # boxes a few points wide keep their black edges
    assert any(tuple(c.get_edgecolor()[0]) == to_rgba("black") for c in k1.collections)
    plt.close(fig)


def test_auv_map_marks_the_gps_fixes_it_lists():
    """A GPS fix box is metres wide on a map of kilometres: a marker at its centre, the one
    the legend shows, makes it visible."""
    from boundest.plot.auv import GPS, plot_auv_map
    from boundest.scenarios.auv_data import load_auv

    data = load_auv()
    fig, ax = plt.subplots(figsize=(6, 5))
    plot_auv_map(data, [], ax=ax)
    fixes = [ln for ln in ax.get_lines() if ln.get_label() == "GPS fix (first, last sample)"]
    (ln,) = fixes
    c = data.fix.mid()
    assert ln.get_marker() == "s" and ln.get_markersize() >= 6 and ln.get_markeredgecolor() == GPS
    np.testing.assert_allclose(ln.get_xdata(), c[:, 1])
    np.testing.assert_allclose(ln.get_ydata(), c[:, 0])
    plt.close(fig)


def test_pool_snapshot_box_fill_lies_under_the_map_and_the_rays():
    """The window observer's box covers most of the pool: filled over the map it hid the
    pillars, and over the kept rays it gave them the grey of the rejected ones."""
    from matplotlib.collections import LineCollection
    from matplotlib.colors import to_rgba
    from matplotlib.patches import Circle

    from boundest.plot.pool import BOX, plot_pool_snapshot

    data, res = _pool_result(window_only=True)
    fig, ax = plt.subplots(figsize=(5, 2.6))
    plot_pool_snapshot(data, res, data.n - 1, np.ones(data.n, dtype=bool), ax=ax, pings=True)
    fills = [c for c in ax.collections if len(c.get_facecolor())
             and tuple(c.get_facecolor()[0][:3]) == to_rgba(BOX)[:3]]
    rays = [c for c in ax.collections if isinstance(c, LineCollection)]
    pillars = [p for p in ax.patches if isinstance(p, Circle)]
    assert fills and rays and pillars
    top = max(c.get_zorder() for c in fills)
    assert top < min(c.get_zorder() for c in rays + pillars)
    plt.close(fig)
