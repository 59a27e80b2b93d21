"""Each layer imports only from the layers before it (the architecture's layer order)."""

from __future__ import annotations

import ast
from pathlib import Path

import boundest

ORDER = ["interval", "expr", "ctc", "csp", "paving", "tube", "estimation", "scenarios"]
TOP = {"plot", "commands", "cli", "io"}  # what a person touches: may import any layer
ROOT = Path(boundest.__file__).parent


def _layer(module: str) -> str | None:
    head = module.split(".")[0]
    return head if head in ORDER or head in TOP else None


def _imports(path: Path) -> list[tuple[str, int]]:
    """The ``boundest`` sub-packages a module imports (relative or absolute), with lines."""
    pkg = path.relative_to(ROOT).parts[:-1]
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = list(pkg[: len(pkg) - node.level + 1])
                target = ".".join(base + ([node.module] if node.module else []))
            elif node.module and node.module.startswith("boundest."):
                target = node.module[len("boundest."):]
            else:
                continue
            names = [target] if target else [a.name for a in node.names]
            found += [(n, node.lineno) for n in names]
        elif isinstance(node, ast.Import):
            found += [(a.name[len("boundest."):], node.lineno) for a in node.names
                      if a.name.startswith("boundest.")]
    return found


def test_layers_import_only_lower_layers():
    bad = []
    for path in sorted(ROOT.rglob("*.py")):
        rel = path.relative_to(ROOT)
        own = _layer(rel.parts[0]) if len(rel.parts) > 1 else None
        if own is None or own in TOP:
            continue
        for target, line in _imports(path):
            other = _layer(target)
            if other is None or other == own:
                continue
            if other in TOP or ORDER.index(other) > ORDER.index(own):
                bad.append(f"{rel}:{line} ({own}) imports {target} ({other})")
    assert not bad, "\n".join(bad)


def test_the_check_sees_imports():
    # the checker must find the imports it is meant to police
    targets = {t for t, _ in _imports(ROOT / "csp" / "engine.py")}
    assert "ctc.revise" in targets
