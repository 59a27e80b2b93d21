"""Helpers for the executed code blocks of the documentation (markdown-exec).

The pages import this module from a hidden block (``sys.path`` gets ``docs/``); what a reader
copies is the visible code, which uses only the public API of boundest. markdown-exec captures
the ``print`` of the page's own code, not ``sys.stdout``: these helpers return text, and the
page prints it.
"""

from __future__ import annotations

import base64
import contextlib
import io
import json
import re
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt

import boundest
from boundest.cli import main

_DATA = str(Path(boundest.__file__).parent)


def img(path_or_fig, alt: str, width: str = "100%") -> str:
    """An ``<img>`` tag holding the PNG inline (base64), so the site needs no image files:
    ``path_or_fig`` is a file, the bytes of a PNG or a matplotlib figure."""
    if isinstance(path_or_fig, bytes):
        data = path_or_fig
    elif isinstance(path_or_fig, (str, Path)):
        data = Path(path_or_fig).read_bytes()
    else:
        buf = io.BytesIO()
        path_or_fig.savefig(buf, format="png", dpi=100, bbox_inches="tight")
        plt.close(path_or_fig)
        data = buf.getvalue()
    b64 = base64.b64encode(data).decode("ascii")
    return f'\n<img alt="{alt}" style="width:{width}" src="data:image/png;base64,{b64}">\n'





#: the JSON written by each command run so far in this build, by its arguments
RESULTS: dict[tuple[str, ...], dict] = {}


def _name(argv: list[str]) -> str:
    """A file name for the JSON of ``argv``: ``satellite``, ``jaulin2001_boxes``, ``m``."""
    parts = [Path(a).stem if "/" in a else a.lstrip("-") for a in argv[1:] or argv]
    return "_".join(parts) or "result"


def run_json(argv: list[str], expect: int = 0) -> tuple[dict, str, str]:
    """Run ``boundest argv --json FILE`` (and ``--out DIR`` for ``run`` and ``demo``) in this
    process; returns the JSON it wrote, its standard output (temporary paths written as
    ``out/``) and the command line as shown. Results are kept in ``RESULTS``, so a page that
    needs the JSON of a command another page ran does not run it again."""
    with tempfile.TemporaryDirectory() as tmp:
        json_file = Path(tmp) / f"{_name(argv)}.json"
        extra = ["--out", tmp] if argv[0] in ("run", "demo") else []
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            rc = main([*argv, "--json", str(json_file), *extra])
        if rc != expect:
            raise RuntimeError(f"boundest {' '.join(argv)} exited {rc}:\n{err.getvalue()}")
        data = json.loads(json_file.read_text())
        RESULTS[tuple(argv)] = data
        text = out.getvalue().replace(tmp, "out").replace(_DATA, "<boundest>")
        shown = f"boundest {' '.join(argv)} --json out/{json_file.name}"
        _FILES.clear()
        _FILES.update({p.name: p.read_bytes() for p in Path(tmp).glob("*.png")})
        return data, text, shown


_FILES: dict[str, bytes] = {}


def command(argv: list[str], *, figures: list[tuple[str, str]] | None = None,
            width: str = "100%", expect: int = 0, max_lines: int = 40) -> str:
    """Run ``boundest argv`` (with ``--json`` and ``--out``, see :func:`run_json`) and return,
    as Markdown, the command, its output (standard output; progress bars go to standard error
    and are dropped) and the figures it wrote (``(file name, alt text)`` pairs), in that order.

    Raises if the exit code is not ``expect``: a page that documents a broken command fails
    the build.
    """
    _, text, shown = run_json(argv, expect)
    text = re.sub(r"[^\S\n]+\n", "\n", text)
    lines = text.rstrip("\n").split("\n")
    if len(lines) > max_lines:
        lines = [*lines[: max_lines - 1], f"... ({len(lines) - max_lines + 1} more lines)"]
    md = ["```console", f"$ {shown}", *lines, "```"]
    md += [img(_FILES[name], alt, width) for name, alt in figures or []]
    return "\n".join(md)
