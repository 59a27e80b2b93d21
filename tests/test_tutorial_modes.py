"""The first tutorial's figures for the propagation modes are what its code prints.

``docs/tutorials/first-estimate.md`` runs a discretised pendulum through four modes and states,
in its prose, the mean width of the angular rate each leaves and what each costs in node
revisions and linear programmes (counts, the same on every machine). This runs the tutorial's
own block and checks the figures its prose states, so that a change of a mode that moves them
fails here rather than leaving the page wrong.
"""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import numpy as np

import boundest as bd
from boundest.csp import propagate
from boundest.expr import Model, VarFamily

from .test_doc_code import shown_python

PAGE = Path(__file__).resolve().parents[1] / "docs" / "tutorials" / "first-estimate.md"
LINE = re.compile(r"^(\S+)\s+rate\s+([\d.]+) wide\s+([\d,]+) node revisions\s+(\d+) LPs$")


def _printed() -> dict[str, tuple[float, int, int]]:
    block = [code for _, _, code in shown_python(PAGE) if "for mode in" in code]
    assert len(block) == 1, "the tutorial has one loop over the modes"
    ns = {"np": np, "bd": bd, "Model": Model, "VarFamily": VarFamily, "propagate": propagate}
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(block[0], ns)
    rows = {}
    for line in out.getvalue().splitlines():
        m = LINE.match(line.strip())
        assert m, f"unexpected line {line!r}"
        rows[m[1]] = (float(m[2]), int(m[3].replace(",", "")), int(m[4]))
    return rows


def test_the_tutorial_states_the_widths_and_costs_its_code_prints():
    rows = _printed()
    assert set(rows) == {"hc4", "3b", "centered", "3b+centered"}
    prose = " ".join(PAGE.read_text(encoding="utf-8").split())
    # the figures of the prose, each with the tolerance its rounding allows
    stated = [("hc4", "**2.0**", 2.0, 0.05), ("3b", "**0.15**", 0.15, 0.005),
              ("centered", "**0.10**", 0.10, 0.005), ("3b+centered", "same 0.10", 0.10, 0.005)]
    for mode, text, width, tol in stated:
        assert text in prose, f"the tutorial no longer says {text!r}"
        assert abs(rows[mode][0] - width) <= tol, (mode, rows[mode])
    hc4, shaved, centered = rows["hc4"][1], rows["3b"][1], rows["centered"]
    assert "a few hundred revisions" in prose and 200 <= hc4 < 1000
    assert "about 270 times the revisions" in prose
    assert 250 <= shaved / hc4 <= 290, shaved / hc4
    assert "some 330 here" in prose and 300 <= centered[2] <= 360, centered
    assert centered[1] < 2 * hc4 and rows["hc4"][2] == rows["3b"][2] == 0
    assert "twenty times narrower" in prose
    assert 18 <= rows["hc4"][0] / rows["3b+centered"][0] <= 22
