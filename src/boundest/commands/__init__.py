"""One module per `boundest run` scenario: `register(subparsers)` adds it, `run(args)` runs it.

A scenario module imports matplotlib inside ``run`` only, so that ``boundest --help`` stays fast.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the Agg backend: figures are written to files, never shown."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig: Any, out: str | Path, name: str, dpi: int = 120) -> Path:
    """Lay out ``fig``, write it to ``out/name.png`` (creating the folder), close it, say so."""
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    png = folder / f"{name}.png"
    fig.savefig(png, dpi=dpi)
    pyplot().close(fig)
    print(f"wrote {png}")
    return png


def write_json(data: dict, path: str | None) -> None:
    """Write ``data`` as indented JSON to ``path`` (if given), creating its folder."""
    if path:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        Path(path).write_text(json.dumps(data, indent=2))
        print(f"wrote {path}")


from . import drifting_clock, jaulin2001, range_only, satellite  # noqa: E402

# add a scenario by importing its module above and listing it here
RUNS = [satellite, jaulin2001, range_only, drifting_clock]
