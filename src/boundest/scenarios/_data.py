"""Reading the scenarios' CSV data with one clear error per bad value.

Every data file is UTF-8 text (a byte-order mark is accepted) with a header line naming its
columns, exactly the columns its loader expects, in any order. Each column has a *kind* that
says which values it accepts:

``"text"``
    any text (a beacon name), surrounding blanks removed.
``"finite"``
    a finite number: times, sample indices, exact inputs (a beacon position, a clock time).
``"lo"``
    the lower bound of an interval whose upper bound is the column ``NAME_hi``: a number or an
    unbounded bound ``-inf`` (also written ``-infinity``, ``-oo``).
``"hi"``
    the upper bound of an interval: a number or ``inf`` (``+inf``, ``infinity``, ``oo``,
    ``+oo``).

NaN is never accepted, nor a number beyond the float64 range. ``NAME_lo <= NAME_hi`` is checked
for every pair. Blank lines are skipped; every other line is a row with one field per column.
Errors are :class:`DataError` with one line naming the file, the line and the value.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from .._textfile import read_text as _read_text
from ..interval import Interval

__all__ = ["KINDS", "DataError", "Table", "check_index", "check_sorted", "embedded", "outward",
           "read_csv", "read_text", "sample_index"]

#: the column kinds understood by :func:`read_csv`
KINDS = ("text", "finite", "lo", "hi")

_INF = {s: math.inf for s in ("inf", "+inf", "infinity", "+infinity", "oo", "+oo")}
_INF.update({s: -math.inf for s in ("-inf", "-infinity", "-oo")})


class DataError(ValueError):
    """Bad input data; the message names the file, line and value."""


def embedded(name: str) -> Path:
    """Path of a data file shipped inside the package (``boundest/data/NAME``)."""
    p = resources.files("boundest") / "data" / name
    return Path(str(p))


def read_text(path: str | Path) -> str:
    """The text of a UTF-8 file (a byte-order mark is dropped); :class:`DataError` naming the
    file and line for an unreadable, UTF-16, non-UTF-8 or binary file."""
    return _read_text(path, DataError)


@dataclass
class Table:
    """The rows of a CSV file: one array per column, and the file line of every row."""

    path: Path
    columns: dict[str, NDArray]
    lines: NDArray[np.intp]

    def __getitem__(self, name: str) -> NDArray:
        return self.columns[name]

    def __len__(self) -> int:
        return int(self.lines.size)

    def error(self, row: int, message: str) -> DataError:
        """A :class:`DataError` ``"PATH:LINE: message"`` for data row ``row`` (0-based)."""
        return DataError(f"{self.path}:{int(self.lines[row])}: {message}")


def _number(cell: str, column: str, kind: str, where: str) -> float:
    """The value of a numeric cell of a column of ``kind``, or a DataError."""
    v = _INF.get(cell.lower())
    if v is None:
        try:
            v = float(cell)
        except ValueError:
            raise DataError(f"{where}: column {column}: not a number: {cell!r}") from None
        if math.isnan(v):
            raise DataError(f"{where}: column {column}: non-finite value {cell!r} (NaN is never "
                            "a value)")
        if math.isinf(v):
            raise DataError(f"{where}: column {column}: {cell!r} is beyond the float64 range "
                            "(write inf for an unbounded bound)")
        return v
    if (kind == "lo" and v < 0) or (kind == "hi" and v > 0):
        return v
    allowed = {"lo": "a lower bound may be -inf, never +inf",
               "hi": "an upper bound may be +inf, never -inf"}.get(kind, "this column must be "
                                                                 "finite")
    raise DataError(f"{where}: column {column}: non-finite value {cell!r} ({allowed})")


def read_csv(path: str | Path, columns: Mapping[str, str] | list[str]) -> Table:
    """Read a CSV file whose header names exactly ``columns``.

    Parameters
    ----------
    path : str or Path
        The file (UTF-8, see :func:`read_text`).
    columns : mapping of column name to kind, or list of names
        The expected columns and their kinds (module doc); a list means every column is
        ``"finite"``, except names ending in ``_lo``/``_hi`` (kinds ``"lo"``/``"hi"``).

    Returns
    -------
    Table
        Float arrays for numeric columns, object arrays of ``str`` for text columns.

    Raises
    ------
    DataError
        For a missing, unexpected or repeated column, a ragged row, a bad cell, ``lo > hi``,
        an empty file or a file without data rows.
    """
    path = Path(path)
    if not isinstance(columns, Mapping):
        columns = {c: "lo" if c.endswith("_lo") else "hi" if c.endswith("_hi") else "finite"
                   for c in columns}
    for c, kind in columns.items():
        if kind not in KINDS:
            raise ValueError(f"column {c}: unknown kind {kind!r} (one of {', '.join(KINDS)})")
    text = read_text(path)
    header = [h.strip() for h in next(csv.reader([text.partition("\n")[0]]), [])]
    plain = set(header) == set(columns) and len(header) == len(columns)
    table = _numeric_table(path, text, header, columns) if plain else None
    if table is not None:
        _check_pairs(table, columns)
        return table
    reader = csv.reader(io.StringIO(text, newline=""))
    try:
        header = [h.strip() for h in next(reader, [])]
        if not any(header):
            raise DataError(f"{path}:1: empty file: expected the header line "
                            f"{','.join(columns)!r}")
        for j, h in enumerate(header):
            if h not in columns:
                raise DataError(f"{path}:1: unexpected column {h!r} (expected "
                                f"{', '.join(columns)})")
            if h in header[:j]:
                raise DataError(f"{path}:1: column {h!r} appears twice")
        missing = [c for c in columns if c not in header]
        if missing:
            raise DataError(f"{path}:1: missing column(s) {', '.join(missing)} "
                            f"(found {', '.join(header)})")
        idx = {c: header.index(c) for c in columns}
        values: dict[str, list] = {c: [] for c in columns}
        lines: list[int] = []
        last = 1
        for row in reader:
            line = last = reader.line_num
            if not row or all(not c.strip() for c in row):
                continue
            if len(row) != len(header):
                raise DataError(f"{path}:{line}: expected {len(header)} fields, got "
                                f"{len(row)}: {','.join(row)!r}")
            where = f"{path}:{line}"
            for c, kind in columns.items():
                cell = row[idx[c]].strip()
                values[c].append(cell if kind == "text" else _number(cell, c, kind, where))
            lines.append(line)
    except csv.Error as exc:
        raise DataError(f"{path}:{reader.line_num}: malformed CSV: {exc}") from None
    if not lines:
        raise DataError(f"{path}:{last + 1}: no data rows after the header")
    out = {c: np.array(v, dtype=object if columns[c] == "text" else np.float64)
           for c, v in values.items()}
    table = Table(path, out, np.array(lines, dtype=np.intp))
    _check_pairs(table, columns)
    return table


def _check_pairs(table: Table, columns: Mapping[str, str]) -> None:
    """``NAME_lo <= NAME_hi`` on every row."""
    out = table.columns
    for c in columns:
        hi = c[:-3] + "_hi"
        if c.endswith("_lo") and hi in out:
            bad = np.flatnonzero(out[c] > out[hi])
            if bad.size:
                j = int(bad[0])
                raise table.error(j, f"{c} = {float(out[c][j])!r} is above "
                                     f"{hi} = {float(out[hi][j])!r}")


def _numeric_table(path: Path, text: str, header: list[str],
                   columns: Mapping[str, str]) -> Table | None:
    """The table parsed by NumPy's C reader when the file is plain (numbers only, no blank line,
    no quote, no carriage return) and every value is finite, else None: then the row-by-row
    reader parses it and names the file, line and value of the first bad cell. The fast path
    decides nothing the row reader would decide otherwise."""
    if any(kind == "text" for kind in columns.values()):
        return None
    if '"' in text or "\r" in text:
        return None
    lines = text.split("\n")[1:]
    if lines and lines[-1] == "":
        lines.pop()
    if not lines or not all(lines):  # a blank line: the row reader skips it and counts it
        return None
    rows = len(lines)
    try:
        arr = np.loadtxt(lines, delimiter=",", dtype=np.float64, comments=None, ndmin=2)
    except ValueError:
        return None
    if arr.shape != (rows, len(header)) or not np.isfinite(arr).all():
        return None
    cols = {c: np.ascontiguousarray(arr[:, header.index(c)]) for c in columns}
    return Table(path, cols, np.arange(2, rows + 2, dtype=np.intp))


def check_index(table: Table, column: str, start: int) -> None:
    """Check that ``column`` runs ``start, start + 1, ...``: rows in order, none twice."""
    k = table[column]
    expected = np.arange(start, start + k.size, dtype=np.float64)
    bad = np.flatnonzero(k != expected)
    if bad.size:
        j = int(bad[0])
        seen = np.flatnonzero(k[:j] == k[j])
        why = f"repeats line {int(table.lines[seen[0]])}" if seen.size else "out of order"
        raise table.error(j, f"{column} = {float(k[j])!r}, expected {int(expected[j])} ({why}; "
                             f"rows {column} = {start}, {start + 1}, ... in order)")


def check_sorted(table: Table, column: str, strict: bool) -> None:
    """Check that ``column`` increases down the file (``strict``: no value twice)."""
    v = table[column]
    bad = np.flatnonzero(v[1:] <= v[:-1] if strict else v[1:] < v[:-1])
    if bad.size:
        j = int(bad[0]) + 1
        rel = "repeats" if v[j] == v[j - 1] else "is below"
        raise table.error(j, f"{column} = {float(v[j])!r} {rel} {float(v[j - 1])!r} on line "
                             f"{int(table.lines[j - 1])} (rows must be sorted by {column}"
                             f"{', each value once' if strict else ''})")


def outward(lo: NDArray, hi: NDArray) -> Interval:
    """One ulp outward: encloses the decimal numbers that ``lo``, ``hi`` were parsed from."""
    return Interval.trusted(np.nextafter(lo, -np.inf), np.nextafter(hi, np.inf))


def sample_index(table: Table, t0: float, dt: float, n: int, column: str = "t"
                 ) -> NDArray[np.intp]:
    """``k = round((t - t0) / dt)`` of every row, checked to lie on the grid (to 1e-6 dt) and in
    ``0 .. n - 1``; a :class:`DataError` names the first row that does not."""
    t = table[column]
    kf = (t - t0) / dt
    k = np.rint(kf)
    bad = np.flatnonzero((np.abs(kf - k) > 1e-6) | (k < 0) | (k > n - 1))
    if bad.size:
        j = int(bad[0])
        raise table.error(j, f"{column} = {float(t[j])!r} is not a sample time t0 + k dt "
                             f"(t0 = {t0!r}, dt = {dt!r}, k = 0..{n - 1})")
    return k.astype(np.intp)
