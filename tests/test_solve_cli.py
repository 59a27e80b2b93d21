"""``boundest solve``: a summary by default, every domain with --all, header options honoured
or refused with file:line, and a subpaving with --paving / ``Bisection EPS;``."""

from __future__ import annotations

import json

import pytest

from boundest.cli import main
from boundest.commands.solve import families, summary_lines
from boundest.interval import Interval

SMALL = "x in [0, 2], y in [0, 2];\nConstraints\nx^2 + y^2 = 1, y >= 0.1;\n"


def test_the_satellite_model_prints_a_summary_not_every_variable(capsys):
    from importlib.resources import files

    path = str(files("boundest") / "data" / "satellite_k200.txt")
    assert main(["solve", path]) == 0
    out = capsys.readouterr().out.splitlines()
    assert len(out) < 40
    assert any(line.startswith("domains: 2215 variables") for line in out)
    x1 = next(line.split() for line in out if line.split()[:1] == ["x1"])
    assert x1[1:3] == ["202", "0..201"]  # x1(0) ... x1(k_max + 1)
    assert main(["solve", path, "--all"]) == 0
    assert len(capsys.readouterr().out.splitlines()) >= 2215


def test_families_and_summary():
    assert families(["x1_0", "x1_1", "w3_2", "t", "y10"]) == {
        "x1": ["x1_0", "x1_1"], "w3": ["w3_2"], "t": ["t"], "y": ["y10"]}
    lines = summary_lines({"a_0": Interval(0, 1), "a_1": Interval(0, 3),
                           "b": Interval(0, float("inf"))})
    assert lines[0] == "domains: 3 variables, 2 bounded, 1 unbounded, 0 empty"
    row = lines[2].split()
    assert row[:3] == ["a", "2", "0..1"] and float(row[3]) == 1 and float(row[5]) == 3
    assert any(line.startswith("unbounded: b") for line in lines)
    empty = summary_lines({"a": Interval.empty()})
    assert empty == ["domains: 1 variables, 0 bounded, 0 unbounded, 1 empty"]


@pytest.mark.parametrize(("header", "line", "what"), [
    ("Precision 1e-8;\n", 1, "Precision"),
    ("Bisection none;\nBisection2 round;\n", 2, "Bisection2"),
    ("Bisection round;\n", 1, "Bisection round"),
    ("Bisection 0;\n", 1, "Bisection 0"),
])
def test_unsupported_header_options_are_refused_with_file_and_line(tmp_path, capsys, header,
                                                                   line, what):
    f = tmp_path / "m.txt"
    f.write_text(header + SMALL)
    assert main(["solve", str(f)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"{f}:{line}:" in err[0] and what in err[0], err


def test_bisection_none_is_propagation_only(tmp_path, capsys):
    f = tmp_path / "m.txt"
    f.write_text("Bisection none;\n" + SMALL)
    assert main(["solve", str(f), "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "subpaving" not in out and not list(tmp_path.glob("*.png"))


@pytest.mark.parametrize("how", ["option", "header"])
def test_paving_encloses_the_solution_set(tmp_path, capsys, how):
    f, js = tmp_path / "circle.txt", tmp_path / "c.json"
    f.write_text(("Bisection 0.05;\n" if how == "header" else "") + SMALL)
    argv = ["solve", str(f), "--out", str(tmp_path), "--json", str(js)]
    assert main([*argv, *(["--paving", "0.05"] if how == "option" else [])]) == 0
    assert "subpaving (SIVIA, eps = 0.05)" in capsys.readouterr().out
    assert (tmp_path / "circle_paving.png").stat().st_size > 5_000
    data = json.loads(js.read_text())
    boxes = data["paving"]["boxes"]
    assert data["paving"]["variables"] == ["x", "y"] and len(boxes) > 10
    import math
    for t in [0.1 + 0.01 * i for i in range(91)]:  # points of the arc, y >= 0.1
        y = t
        x = math.sqrt(1 - y * y)
        assert any(b[0][0] <= x <= b[0][1] and b[1][0] <= y <= b[1][1] for b in boxes), (x, y)
    assert all(b[0][1] - b[0][0] <= 0.05 and b[1][1] - b[1][0] <= 0.05 for b in boxes)


def test_paving_refuses_large_or_unbounded_models(tmp_path, capsys):
    f = tmp_path / "m.txt"
    f.write_text("x in [0, +oo[, y in [0, 1];\nConstraints\nx >= y;\n")
    assert main(["solve", str(f), "--paving", "0.1"]) == 2
    assert "x is unbounded" in capsys.readouterr().err
    decl = ", ".join(f"v{i} in [0, 1]" for i in range(13))
    f.write_text(decl + ";\nConstraints\nv0 + v1 = 1;\n")
    assert main(["solve", str(f), "--paving", "0.1"]) == 2
    assert "at most 12 variables" in capsys.readouterr().err


@pytest.mark.slow  # box consistency's kernels compile on first use (not in the archive): 10-13 s
def test_mode_option_runs_each_mode_and_reports_its_cost(tmp_path, capsys):
    from boundest.commands.solve import PROPAGATION_MODES
    from boundest.csp import MODES

    assert PROPAGATION_MODES == MODES
    f = tmp_path / "m.txt"
    f.write_text("Variables\nx in [-10, 10];\nConstraints\nx * x - x = 0;\n")
    widths = {}
    for mode in ("hc4", "bc", "bc+3b"):
        out = tmp_path / f"{mode}.json"
        assert main(["solve", str(f), "--mode", mode, "--json", str(out)]) == 0
        first = capsys.readouterr().out.splitlines()[0]
        assert f"mode {mode}:" in first
        assert ("box consistency" in first) == (mode != "hc4")
        d = json.loads(out.read_text())
        assert d["mode"] == mode
        x = d["domains"]["x"]
        widths[mode] = x[1] - x[0]
    assert widths["hc4"] == 20.0 and widths["bc"] < 1.1 and widths["bc+3b"] <= widths["bc"]
    with pytest.raises(SystemExit):
        main(["solve", str(f), "--mode", "bc3"])


def test_a_square_system_is_solved_by_interval_newton_with_proofs(tmp_path, capsys):
    """Two circles meet in two points: --paving on a square model proves both, writes them as
    proved in the JSON and draws them; the boxes hold the exact intersections."""
    import math

    f, js = tmp_path / "circles.txt", tmp_path / "c.json"
    f.write_text("x in [-3, 3], y in [-3, 3];\nConstraints\nx^2 + y^2 = 4, "
                 "(x - 1)^2 + y^2 = 2;\n")
    assert main(["solve", str(f), "--paving", "1e-8", "--out", str(tmp_path), "--json",
                 str(js)]) == 0
    out = capsys.readouterr().out
    assert "interval Newton" in out and "2 solutions proved" in out and "0 undecided" in out
    data = json.loads(js.read_text())["paving"]
    assert data["method"] == "newton" and data["proved"] == [True, True]
    x = 1.5  # x^2 - (x - 1)^2 = 2
    for y in (math.sqrt(4 - x * x), -math.sqrt(4 - x * x)):
        assert any(b[0][0] <= x <= b[0][1] and b[1][0] <= y <= b[1][1]
                   for b in data["boxes"]), y
    assert (tmp_path / "circles_paving.png").stat().st_size > 5_000


def test_a_double_root_is_undecided_never_proved(tmp_path, capsys):
    f, js = tmp_path / "double.txt", tmp_path / "d.json"
    f.write_text("x in [-1, 1], y in [-1, 1];\nConstraints\nx^2 = 0, y - x = 0;\n")
    assert main(["solve", str(f), "--paving", "1e-6", "--out", str(tmp_path), "--json",
                 str(js)]) == 0
    assert "0 solutions proved" in capsys.readouterr().out
    data = json.loads(js.read_text())["paving"]
    assert data["boxes"] and not any(data["proved"])
    assert any(b[0][0] <= 0 <= b[0][1] and b[1][0] <= 0 <= b[1][1] for b in data["boxes"])


@pytest.mark.parametrize("mode", ["centered", "3b+centered"])
def test_centered_modes_narrow_what_hull_consistency_cannot(tmp_path, capsys, mode):
    """x + y = 1 and x - y = 0 on [0, 1]^2: each constraint alone allows all of [0, 1], the
    linearisation of the pair gives the point 1/2."""
    f, js = tmp_path / "m.txt", tmp_path / "m.json"
    f.write_text("x in [0, 1], y in [0, 1];\nConstraints\nx + y + 0.1 * x * y = 1.1, "
                 "x - y = 0;\n")
    assert main(["solve", str(f), "--mode", "hc4", "--json", str(tmp_path / "h.json")]) == 0
    hc = json.loads((tmp_path / "h.json").read_text())["domains"]["x"]
    assert hc == [0.0, 1.0]
    assert main(["solve", str(f), "--mode", mode, "--json", str(js)]) == 0
    assert f"mode {mode}:" in capsys.readouterr().out
    x = json.loads(js.read_text())["domains"]["x"]
    import mpmath

    with mpmath.workdps(50):  # the decimal literals are exact: 0.1 x^2 + 2 x - 1.1 = 0
        a, c = mpmath.mpf("0.1"), mpmath.mpf("1.1")
        root = (-2 + mpmath.sqrt(4 + 4 * a * c)) / (2 * a)
        assert mpmath.mpf(x[0]) <= root <= mpmath.mpf(x[1]) and x[1] - x[0] < 1e-6


def test_default_mode_is_3b_centered(tmp_path, capsys):
    """With no --mode, solve runs the measured default (shaving, then the centered form), which
    narrows the pair of constraints above to the root where hull consistency keeps [0, 1]."""
    f = tmp_path / "m.txt"
    f.write_text("x in [0, 1], y in [0, 1];\nConstraints\nx + y + 0.1 * x * y = 1.1, "
                 "x - y = 0;\n")
    assert main(["solve", str(f), "--json", str(tmp_path / "d.json")]) == 0
    assert "mode 3b+centered:" in capsys.readouterr().out
    x = json.loads((tmp_path / "d.json").read_text())["domains"]["x"]
    assert 0.5356 < x[0] <= x[1] < 0.5357
