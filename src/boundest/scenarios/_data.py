"""Reading the scenarios' CSV data with one clear error per bad value."""

from __future__ import annotations

import csv
import math
from importlib import resources
from pathlib import Path

import numpy as np

__all__ = ["DataError", "embedded", "read_csv"]


class DataError(ValueError):
    """Bad input data; the message names the file, line and value."""


def embedded(name: str) -> Path:
    """Path of a data file shipped inside the package (``boundest/data/NAME``)."""
    p = resources.files("boundest") / "data" / name
    return Path(str(p))


def read_csv(path: str | Path, columns: list[str]) -> dict[str, np.ndarray]:
    """Read the named numeric columns of a CSV file with a header line.

    Every cell must parse as a finite float; columns ending in ``_lo``/``_hi`` must pair up
    with ``lo <= hi``. Errors name the file, line and value; nothing is dropped.
    """
    path = Path(path)
    try:
        handle = path.open(newline="")
    except OSError as exc:
        raise DataError(f"cannot read {path}: {exc.strerror}") from None
    with handle:
        reader = csv.reader(handle)
        header = next(reader, None)
        if header is None:
            raise DataError(f"{path}: empty file (expected a header line)")
        header = [h.strip() for h in header]
        missing = [c for c in columns if c not in header]
        if missing:
            raise DataError(f"{path}:1: missing column(s) {', '.join(missing)} "
                            f"(found {', '.join(header)})")
        idx = [header.index(c) for c in columns]
        rows, lines = [], []
        for line, row in enumerate(reader, start=2):
            if not row or all(not c.strip() for c in row):
                continue
            if len(row) != len(header):
                raise DataError(f"{path}:{line}: expected {len(header)} fields, got {len(row)}")
            vals = []
            for c, i in zip(columns, idx, strict=True):
                cell = row[i].strip()
                try:
                    v = float(cell)
                except ValueError:
                    raise DataError(f"{path}:{line}: column {c}: not a number: {cell!r}") from None
                if not math.isfinite(v):
                    raise DataError(f"{path}:{line}: column {c}: non-finite value {cell!r}")
                vals.append(v)
            rows.append(vals)
            lines.append(line)
    if not rows:
        raise DataError(f"{path}: no data rows")
    arr = np.array(rows)
    out = {c: arr[:, j] for j, c in enumerate(columns)}
    for c in columns:
        if c.endswith("_lo") and c[:-3] + "_hi" in out:
            bad = np.nonzero(out[c] > out[c[:-3] + "_hi"])[0]
            if bad.size:
                j = int(bad[0])
                lo, hi = float(out[c][j]), float(out[c[:-3] + "_hi"][j])
                raise DataError(f"{path}:{lines[j]}: {c} = {lo!r} is above {c[:-3]}_hi = {hi!r}")
    return out
