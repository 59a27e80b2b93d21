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
