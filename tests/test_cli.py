"""The command line: the demo runs end to end and its enclosures are sound."""

import json

import mpmath
import numpy as np
import pytest

from boundest.cli import main
from boundest.scenarios import function_enclosure as fe


def test_demo_writes_figure_and_sound_json(tmp_path, capsys):
    js = tmp_path / "demo.json"
    assert main(["demo", "--out", str(tmp_path), "--json", str(js)]) == 0
    assert (tmp_path / "function_enclosure.png").stat().st_size > 10_000
    data = json.loads(js.read_text())
    lo, hi = data["sampled_range"]
    widths = []
    for row in data["enclosures"]:
        assert row["range_lo"] <= lo and hi <= row["range_hi"]
        widths.append(row["range_width"])
    assert widths == sorted(widths, reverse=True) and widths[-1] < 1.05 * (hi - lo)
    assert "guaranteed range" in capsys.readouterr().out


def test_every_box_contains_the_graph():
    enc = fe.enclose(64)
    rng = np.random.default_rng(0)
    t = rng.random((64, 6))
    xs = enc.x.lo[:, None] + t * (enc.x.hi - enc.x.lo)[:, None]
    for i, row in enumerate(xs):
        for x in row:
            with mpmath.workprec(200):
                m = mpmath.mpf(x)
                y = mpmath.sin(3 * m) * mpmath.exp(-m / 3) + m / 5
            assert enc.y.lo[i] <= y <= enc.y.hi[i]


def test_bad_arguments_exit_with_usage_error():
    with pytest.raises(SystemExit):
        main(["nonsense"])
    with pytest.raises(ValueError, match="positive"):
        fe.enclose(0)


def test_jaulin2001_summary_states_its_mode(tmp_path, capsys):
    # boxes: the quick mode; the line names the default it stands against
    assert main(["run", "jaulin2001", "--boxes", "--out", str(tmp_path)]) == 0
    text = capsys.readouterr().out
    assert "mode: boxes, hull consistency" in text and "the default subpavings" in text
