"""Bad input: every malformed form of every data file and of a model file gives exactly one
error line naming the file, the line and the value, with exit code 2; strict JSON out."""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from boundest.cli import main
from boundest.commands import dumps, jsonable
from boundest.interval import Interval
from boundest.scenarios import drifting_clock as dc
from boundest.scenarios import jaulin2001 as jw
from boundest.scenarios import range_only as ro
from boundest.scenarios import satellite as sat
from boundest.scenarios._data import embedded


@dataclass
class Loader:
    """A ``--data``-like option of one scenario, its embedded file and its columns."""

    name: str
    args: list[str]           # the command line, FILE stands for the file under test
    file: str                 # the embedded good file
    index: str | None         # the column that numbers the rows (None: beacon names)
    lo: int | None            # field of an interval lower bound (its upper bound follows)
    finite: int               # field of a column that must be finite (a time, an index)


LOADERS = [
    Loader("satellite", ["run", "satellite", "--data", "FILE"], "satellite_k200.csv", "k", 1, 0),
    Loader("jaulin2001", ["run", "jaulin2001", "--boxes", "--data", "FILE"], "jaulin2001.csv",
           "k", 1, 0),
    Loader("range-only", ["run", "range-only", "--dt", "0.5", "--data", "FILE"],
           "rohou2018_robot.csv", "i", 4, 2),
    Loader("beacons", ["run", "range-only", "--dt", "0.5", "--beacons", "FILE"],
           "rohou2018_beacons.csv", None, None, 1),
    Loader("drifting-clock", ["run", "drifting-clock", "--dt", "0.1", "--data", "FILE"],
           "rohou2018_clock.csv", "i", 2, 1),
]


def _lines(loader: Loader) -> list[list[str]]:
    text = embedded(loader.file).read_text()
    return [line.split(",") for line in text.splitlines()]


def _text(rows: list[list[str]]) -> str:
    return "".join(",".join(r) + "\n" for r in rows)


def _cases(loader: Loader) -> list[tuple[str, bytes, int, str]]:
    """(case, file content, line of the error, value the message must show)."""
    rows = _lines(loader)
    out: list[tuple[str, bytes, int, str]] = []

    def add(case: str, r: list[list[str]] | bytes, line: int, value: str) -> None:
        out.append((case, r if isinstance(r, bytes) else _text(r).encode(), line, value))

    add("extra column", [rows[0] + ["extar"]] + [[*r, "1"] for r in rows[1:]], 1, "'extar'")
    dup = [rows[0], rows[1], list(rows[1]), *rows[2:]]
    first = rows[1][0]
    add("duplicate row", dup, 3, f"{float(first)!r}" if loader.index else repr(first))
    if loader.index:
        add("unsorted rows", [rows[0], rows[2], rows[1], *rows[3:]], 2, f"{float(rows[2][0])!r}")
    add("utf-16", _text(rows).encode("utf-16"), 1, "ff fe")
    add("utf-16 without BOM", _text(rows).encode("utf-16-le"), 1, "NUL")
    add("binary garbage", bytes(range(256)) * 4, 2, "0x80")
    nan = [list(r) for r in rows]
    col = loader.lo if loader.lo is not None else loader.finite
    nan[1][col] = "nan"
    add("nan", nan, 2, "'nan'")
    inf = [list(r) for r in rows]
    inf[2][loader.finite] = "inf"
    add("infinite where it is meaningless", inf, 3, "'inf'")
    word = [list(r) for r in rows]
    word[2][loader.finite] = "1.2.3"
    add("not a number", word, 3, "'1.2.3'")
    if loader.lo is not None:
        inv = [list(r) for r in rows]
        inv[1][loader.lo], inv[1][loader.lo + 1] = rows[1][loader.lo + 1], rows[1][loader.lo]
        add("inverted bounds", inv, 2, f"{float(rows[1][loader.lo + 1])!r}")
        wrong = [list(r) for r in rows]
        wrong[2][loader.lo] = "+inf"
        add("+inf lower bound", wrong, 3, "'+inf'")
        wrong = [list(r) for r in rows]
        wrong[2][loader.lo + 1] = "-oo"
        add("-oo upper bound", wrong, 3, "'-oo'")
    add("empty file", b"", 1, "empty file")
    add("header only", rows[:1], 2, "no data rows")
    add("missing column", [r[:-1] for r in rows], 1, rows[0][-1])
    ragged = [list(r) for r in rows]
    ragged[2] = ragged[2] + ["9"]
    add("ragged row", ragged, 3, ",".join(ragged[2]))
    if loader.name in ("range-only", "drifting-clock"):
        # renumbered rows, so that only the time is repeated or unsorted
        t = 2 if loader.name == "range-only" else 1
        twice = [list(r) for r in [rows[0], rows[1], rows[1], *rows[2:]]]
        for k, r in enumerate(twice[1:], start=1):
            r[0] = str(k)
        add("repeated time", twice, 3, "repeats")
        swap = [rows[0], list(rows[2]), list(rows[1]), *rows[3:]]
        swap[1][0], swap[2][0] = "1", "2"
        add("unsorted times", swap, 3, f"{float(rows[1][t])!r} is below")
    return out


CORPUS = [pytest.param(ld, case, content, line, value, id=f"{ld.name}-{case}")
          for ld in LOADERS for case, content, line, value in _cases(ld)]


def _run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, list[str]]:
    rc = main(argv)
    return rc, capsys.readouterr().err.strip().splitlines()


@pytest.mark.parametrize(("loader", "case", "content", "line", "value"), CORPUS)
def test_bad_data_file(tmp_path, capsys, loader, case, content, line, value):
    f = tmp_path / "bad.csv"
    f.write_bytes(content)
    argv = [str(f) if a == "FILE" else a for a in loader.args] + ["--out", str(tmp_path)]
    rc, err = _run(argv, capsys)
    assert rc == 2, case
    assert len(err) == 1, err
    assert f"{f}:{line}:" in err[0] and value in err[0], err[0]


def test_missing_data_file_is_named(tmp_path, capsys):
    f = tmp_path / "nowhere.csv"
    rc, err = _run(["run", "satellite", "--data", str(f)], capsys)
    assert rc == 2 and len(err) == 1 and str(f) in err[0]


# -- forms that must be accepted ------------------------------------------------------------
def _variant(tmp_path: Path, loader: Loader, edit: dict[tuple[int, int], str] | None = None,
             bom: bool = False) -> Path:
    rows = [list(r) for r in _lines(loader)]
    for (i, j), v in (edit or {}).items():
        rows[i][j] = v
    f = tmp_path / f"{loader.name}.csv"
    f.write_bytes((b"\xef\xbb\xbf" if bom else b"") + _text(rows).encode())
    return f


def _same(a: object, b: object) -> None:
    for name in ("y_lo", "y_hi", "t", "z", "tau", "beacons"):
        if hasattr(a, name):
            x, y = getattr(a, name), getattr(b, name)
            if isinstance(x, Interval):
                x, y = np.stack([x.lo, x.hi]), np.stack([y.lo, y.hi])
            np.testing.assert_array_equal(x, y)


def test_a_byte_order_mark_is_accepted(tmp_path):
    by = {ld.name: ld for ld in LOADERS}
    _same(sat.load(_variant(tmp_path, by["satellite"], bom=True)), sat.load())
    y = jw.load(_variant(tmp_path, by["jaulin2001"], bom=True))
    np.testing.assert_array_equal(y.lo, jw.load().lo)
    _same(ro.load(_variant(tmp_path, by["range-only"], bom=True),
                  _variant(tmp_path, by["beacons"], bom=True)), ro.load())
    assert ro.load(beacons=_variant(tmp_path, by["beacons"], bom=True)).beacon_names == [
        "alpha", "beta", "gamma"]
    _same(dc.load(_variant(tmp_path, by["drifting-clock"], bom=True)), dc.load())


@pytest.mark.parametrize(("name", "cell", "text", "expected"), [
    ("satellite", (2, 3), "-inf", -np.inf),
    ("satellite", (2, 6), "+oo", np.inf),
    ("jaulin2001", (2, 1), "-oo", -np.inf),
    ("jaulin2001", (2, 2), "Infinity", np.inf),
    ("range-only", (2, 4), "-infinity", -np.inf),
    ("range-only", (2, 5), "oo", np.inf),
    ("drifting-clock", (2, 2), "-inf", -np.inf),
    ("drifting-clock", (2, 3), "inf", np.inf),
])
def test_unbounded_interval_bounds_are_accepted(tmp_path, name, cell, text, expected):
    loader = {ld.name: ld for ld in LOADERS}[name]
    f = _variant(tmp_path, loader, {cell: text})
    if name == "satellite":
        m = sat.load(f)
        got = (m.y_lo if cell[1] % 2 else m.y_hi)[cell[0] - 1, (cell[1] - 1) // 2]
    elif name == "jaulin2001":
        y = jw.load(f)
        got = (y.lo if cell[1] == 1 else y.hi)[cell[0] - 1, 0]
    else:
        m = ro.load(f) if name == "range-only" else dc.load(f)
        got = (m.z.lo if text.startswith("-") else m.z.hi)[cell[0] - 1]
    assert got == expected


@pytest.mark.slow  # a whole satellite run, about 6 s
def test_satellite_model_text_writes_unbounded_outputs(tmp_path):
    f = _variant(tmp_path, LOADERS[0], {(1, 1): "-inf", (1, 6): "inf"})
    text = sat.model_text(sat.load(f, k_max=2))
    assert "y1_0 in ]-oo, 0.19809953851554396]" in text
    assert "y3_0 in [16.054682759904146, +oo[" in text
    model = tmp_path / "m.txt"
    model.write_text(text)
    assert main(["solve", str(model)]) == 0


# -- boundest solve -------------------------------------------------------------------------
GOOD = "x in [0, 1], y in [0, 1];\nConstraints\nx + y = 1;\n"
MODELS = [
    ("unknown variable", "x in [0, 1];\nConstraints\nx + zz = 3;\n", 3, "zz"),
    ("inverted bounds", "x in [2, 1];\nConstraints\nx = 1;\n", 1, "[2, 1]"),
    ("nan", "x in [0, 1], y in [nan, 1];\nConstraints\nx = y;\n", 1, "nan"),
    ("bad token", "x in [0, 1];\nConstraints\nx = 1 $ 2;\n", 3, "'$'"),
    ("unterminated constraint", "x in [0, 1];\nConstraints\nx = \n", 3, "end of file"),
    ("declared twice", "x in [0, 1], x in [0, 2];\nConstraints\nx = 1;\n", 1, "x"),
]


@pytest.mark.parametrize(("case", "text", "line", "value"), MODELS,
                         ids=[m[0] for m in MODELS])
def test_bad_model_text(tmp_path, capsys, case, text, line, value):
    f = tmp_path / "m.txt"
    f.write_text(text)
    rc, err = _run(["solve", str(f)], capsys)
    assert rc == 2 and len(err) == 1, err
    assert f"{f}:{line}:" in err[0] and value in err[0], err[0]


@pytest.mark.parametrize(("case", "content", "line", "value"), [
    ("utf-16", GOOD.encode("utf-16"), 1, "UTF-16"),
    ("binary garbage", bytes(range(256)) * 4, 2, "0x80"),
    ("NUL", b"x in [0, 1];\x00", 1, "NUL"),
])
def test_undecodable_model_file(tmp_path, capsys, case, content, line, value):
    f = tmp_path / "m.txt"
    f.write_bytes(content)
    rc, err = _run(["solve", str(f)], capsys)
    assert rc == 2 and len(err) == 1, err
    assert f"{f}:{line}:" in err[0] and value in err[0], err[0]


def test_model_file_with_a_byte_order_mark(tmp_path, capsys):
    f = tmp_path / "m.txt"
    f.write_bytes(b"\xef\xbb\xbf" + GOOD.encode())
    assert main(["solve", str(f)]) == 0
    assert "consistent" in capsys.readouterr().out


def test_load_model_reads_like_solve(tmp_path):
    """The library's ``load_model`` decodes as ``boundest solve`` does."""
    from boundest.expr import load_model
    from boundest.expr.parser import ModelSyntaxError

    f = tmp_path / "m.txt"
    f.write_bytes(b"\xef\xbb\xbf" + GOOD.encode())
    assert load_model(f).domains
    f.write_bytes(GOOD.encode("utf-16"))
    with pytest.raises(ModelSyntaxError, match=f"{f}:1: UTF-16"):
        load_model(f)


def test_errors_from_a_real_process(tmp_path):
    """The console script itself: exit code 2, one line on stderr, no traceback."""
    bad = tmp_path / "bad.csv"
    bad.write_bytes(bytes(range(256)))
    model = tmp_path / "m.txt"
    model.write_text(MODELS[0][1])
    for argv, where in ((["run", "satellite", "--data", str(bad)], f"{bad}:2:"),
                        (["solve", str(model)], f"{model}:3:")):
        p = subprocess.run([sys.executable, "-m", "boundest.cli", *argv], capture_output=True,
                           text=True, timeout=120)
        err = p.stderr.strip().splitlines()
        assert p.returncode == 2 and len(err) == 1 and where in err[0], p.stderr


# -- strict JSON ----------------------------------------------------------------------------
def _strict(text: str) -> object:
    def refuse(name: str) -> None:
        raise ValueError(f"non-standard JSON constant {name}")
    return json.loads(text, parse_constant=refuse)


def test_the_json_convention():
    data = {"a": Interval.trusted(np.array([0.0, -np.inf, np.nan]), np.array([1.0, 2.0, np.nan])),
            "b": Interval.empty(), "c": Interval.entire(), "d": np.array([np.nan, np.inf]),
            "e": (np.float64(-np.inf), np.int64(3), np.bool_(True))}
    assert _strict(dumps(data)) == {"a": [[0.0, 1.0], ["-inf", 2.0], None], "b": None,
                                    "c": ["-inf", "inf"], "d": [None, "inf"],
                                    "e": ["-inf", 3, True]}
    assert jsonable(Interval.trusted(np.array([[0.0, np.nan]]), np.array([[1.0, np.nan]]))) == [
        [[0.0, 1.0], None]]


@pytest.mark.slow  # whole scenario runs, about 80 s for the seven
@pytest.mark.parametrize("argv", [
    ["demo"],
    ["run", "satellite"],
    ["run", "jaulin2001", "--boxes"],
    ["run", "range-only", "--dt", "0.5", "--max-iter", "3"],
    ["run", "drifting-clock", "--dt", "0.1"],
    ["run", "auv", "--mode", "localization"],
    ["run", "pool", "--m", "40"],
], ids=lambda a: " ".join(a[:3]))
def test_every_command_writes_strict_json(tmp_path, capsys, argv):
    js = tmp_path / "out.json"
    assert main([*argv, "--out", str(tmp_path), "--json", str(js)]) == 0
    assert isinstance(_strict(js.read_text()), dict)


def test_solve_json_with_unbounded_and_empty_domains(tmp_path, capsys):
    m, js = tmp_path / "m.txt", tmp_path / "m.json"
    m.write_text("x in [0, +oo[, y in ]-oo, 1], z in ]-oo, +oo[;\nConstraints\nx >= y;\n")
    assert main(["solve", str(m), "--json", str(js)]) == 0
    assert _strict(js.read_text())["domains"] == {"x": [0.0, "inf"], "y": ["-inf", 1.0],
                                                  "z": ["-inf", "inf"]}
    m.write_text("x in [0, 1], y in [0, 1];\nConstraints\nx + y = 3;\n")
    assert main(["solve", str(m), "--json", str(js)]) == 1
    data = _strict(js.read_text())
    assert data["consistent"] is False and data["domains"] == {"x": None, "y": None}


@pytest.mark.slow  # a whole satellite run (in a fresh clone, the compile too)
def test_satellite_data_is_never_truncated_silently(tmp_path, capsys):
    rows = _lines(LOADERS[0])[:42]
    f, js = tmp_path / "k40.csv", tmp_path / "s.json"
    f.write_text(_text(rows))
    assert main(["run", "satellite", "--data", str(f), "--out", str(tmp_path), "--json",
                 str(js)]) == 0
    assert _strict(js.read_text())["k_max"] == 40
    rc, err = _run(["run", "satellite", "--data", str(f), "--kmax", "200"], capsys)
    err = [e for e in err if not e.startswith("boundest: compiling")]  # with an empty cache
    assert rc == 2 and len(err) == 1 and f"{f}:42: the file ends at k = 40" in err[0], err
