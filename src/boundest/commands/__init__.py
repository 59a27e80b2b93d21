"""One module per `boundest run` scenario: `register(subparsers)` adds it, `run(args)` runs it.

``SCENARIOS`` names them without importing them: the command line imports only the module of the
scenario it runs, and this package imports neither NumPy nor Numba at import, so that
``boundest --help`` and argument errors stay fast. A scenario module imports the numerical
layers and matplotlib inside ``run``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

#: ``boundest run NAME`` -> (module of this package, one-line help for ``boundest run --help``);
#: add a scenario by writing its module and listing it here
SCENARIOS: dict[str, tuple[str, str]] = {
    "satellite": ("satellite", "Jaulin 2002: satellite localisation as a CSP"),
    "jaulin2001": ("jaulin2001", "Jaulin et al. 2001: causal and non-causal set estimation"),
    "range-only": ("range_only", "Rohou et al. 2018: range-only robot with uncertain times"),
    "drifting-clock": ("drifting_clock", "Rohou et al. 2018: correcting a drifting clock"),
    "auv": ("auv", "AUV mine survey (Jaulin et al. 2007): localization and SLAM over 60,000 "
                   "samples"),
    "pool": ("pool", "pool robot (Jaulin's robust set-membership observer): a recursive "
                     "q-relaxed observer over sonar pings"),
}


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the Agg backend: figures are written to files, never shown."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def subplots(nrows: int = 1, ncols: int = 1, *, figsize: tuple[float, float] | None = None,
             layout: Any = None, **kwargs: Any) -> tuple[Any, Any]:
    """``plt.subplots`` without pyplot: a ``Figure`` on an Agg canvas, and its axes.

    The figure is not registered with pyplot (nothing to close); :func:`save_figure` writes it.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout=layout)
    FigureCanvasAgg(fig)
    return fig, fig.subplots(nrows, ncols, **kwargs)


#: zlib level of the PNG files: 1 saves 10-40 ms per figure against PIL's default 6 (measured on the
#: figures of `boundest run`), for files about 10 % larger
PNG_COMPRESSION = 1


def save_figure(fig: Any, out: str | Path, name: str, dpi: int = 120, tight: bool = True
                ) -> Path:
    """Lay out ``fig`` (``tight_layout``, unless it has its own layout engine or ``tight`` is
    False: margins set by the caller), write it to ``out/name.png`` (creating the folder, zlib
    level :data:`PNG_COMPRESSION`), close it if pyplot made it, say so."""
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    if tight and fig.get_layout_engine() is None:
        fig.tight_layout()
    png = folder / f"{name}.png"
    fig.savefig(png, dpi=dpi, pil_kwargs={"compress_level": PNG_COMPRESSION})
    if fig.canvas.manager is not None:  # a pyplot figure
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
    import numpy as np

    from ..interval import Interval

    return _jsonable(obj, np, Interval)


def _jsonable(obj: Any, np: Any, Interval: type) -> Any:
    """:func:`jsonable` with the modules passed in (imported once per call of ``jsonable``)."""
    def jsonable(v: Any) -> Any:
        return _jsonable(v, np, Interval)

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
    """Write ``data`` as strict JSON (:func:`dumps`) to ``path`` (if given), in an existing
    folder: a command checks ``--json`` before it starts (``options.check_outputs``), and no
    folder is created for it."""
    if path:
        text = dumps(data)
        Path(path).write_text(text + "\n")
        print(f"wrote {path}")
