"""The package's namespace shows its public names only, and the API reference lists them all."""

from __future__ import annotations

import re
from pathlib import Path

import boundest as bd

API_INDEX = Path(__file__).parents[1] / "docs" / "api" / "index.md"
#: public, reachable as ``boundest.abs`` etc., but outside ``__all__`` (a star import must keep
#: Python's builtins)
NOT_STARRED = {"abs", "min", "max", "pow"}
#: the layers, each with its API page
LAYERS = {"interval", "expr", "ctc", "csp", "paving", "tube", "estimation", "scenarios", "plot"}


def test_dir_lists_the_public_names_and_nothing_else():
    import boundest.cli  # noqa: F401 - a loaded submodule that is not a layer stays hidden

    bd.Tube  # noqa: B018 - a name loaded on access is listed once, like the others
    names = dir(bd)
    assert names == sorted(names) and len(names) == len(set(names))
    others = {n for n in names if not (n.startswith("__") and n.endswith("__"))}
    assert others == set(bd.__all__) - {"__version__"} | NOT_STARRED | LAYERS
    for leak in ("Any", "annotations", "importlib", "cli", "commands", "_NAMES"):
        assert leak not in names
    assert not hasattr(bd, "importlib") and not hasattr(bd, "Any")
    assert all(getattr(bd, n) is not None for n in names if n != "__builtins__")


def test_the_api_reference_lists_every_name_of_all():
    text = API_INDEX.read_text().split("## The names of `boundest`")[1].split("\n## ")[0]
    listed = set(re.findall(r"`([A-Za-z_][A-Za-z0-9_]*)(?:\(\))?`", text))
    missing = sorted(set(bd.__all__) - listed)
    assert missing == [], f"docs/api/index.md does not list {missing}"
    assert listed >= NOT_STARRED
    stray = sorted(n for n in listed if n[0].isupper() and n not in bd.__all__)
    assert stray == [], f"docs/api/index.md lists names boundest does not export: {stray}"
