"""One module per `boundest run` scenario: `register(subparsers)` adds it, `run(args)` runs it.

A scenario module imports matplotlib inside ``run`` only, so that ``boundest --help`` stays fast.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..interval import Interval


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the Agg backend: figures are written to files, never shown."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig: Any, out: str | Path, name: str, dpi: int = 120) -> Path:
    """Lay out ``fig`` (unless it has its own layout engine), write it to ``out/name.png``
    (creating the folder), close it, say so."""
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    if fig.get_layout_engine() is None:
        fig.tight_layout()
    png = folder / f"{name}.png"
    fig.savefig(png, dpi=dpi)
    pyplot().close(fig)
    print(f"wrote {png}")
    return png


def jsonable(obj: Any) -> Any:
    """``obj`` made of plain JSON values, by the convention of every ``--json`` output.

    Finite numbers stay numbers; an infinite bound is the string ``"inf"`` or ``"-inf"``; NaN,
    the bound of an empty interval, is ``null``; an ``Interval`` is ``[lo, hi]`` (``null`` when
    empty; arrays of intervals are nested lists); NumPy scalars and arrays become numbers and
    lists, tuples lists. The result always passes ``json.dumps(..., allow_nan=False)``.
    """
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        if math.isnan(v):
            return None
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return v
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, Interval):
        pairs = np.stack([obj.lo, obj.hi], axis=-1)
        empty = np.isnan(obj.lo)
        out = jsonable(pairs.tolist())
        if not empty.any():
            return out
        if obj.ndim == 0:
            return None
        for idx in zip(*np.nonzero(empty), strict=True):
            row = out
            for i in idx[:-1]:
                row = row[i]
            row[idx[-1]] = None
        return out
    return obj


def dumps(data: Any) -> str:
    """``data`` as indented strict JSON (:func:`jsonable`; NaN and infinities never leak)."""
    return json.dumps(jsonable(data), indent=2, allow_nan=False)


def write_json(data: dict, path: str | None) -> None:
    """Write ``data`` as strict JSON (:func:`dumps`) to ``path`` (if given), creating its
    folder."""
    if path:
        text = dumps(data)
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        Path(path).write_text(text + "\n")
        print(f"wrote {path}")


from . import auv, drifting_clock, jaulin2001, pool, range_only, satellite  # noqa: E402

# add a scenario by importing its module above and listing it here
RUNS = [satellite, jaulin2001, range_only, drifting_clock, auv, pool]
