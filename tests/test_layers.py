"""The package's layers import one way: each module imports only modules of its own layer or of
the layers below it (README, "The layers"), at the top of the file or inside a function."""

from __future__ import annotations

import ast
from pathlib import Path

import boundest

PKG = Path(boundest.__file__).parent

#: From the bottom. The floor holds the modules below ``interval``: the Numba cache guard, then
#: the kernel archive's runtime (it reads the guard's paths), and helpers that import nothing
#: of the package. The kernel archive's builder runs the command line: it sits on top.
LAYERS: list[set[str]] = [
    {"_numba_cache", "_malloc", "_textfile", "_progress", "parallel"},
    {"_kernels"},
    {"interval"},
    {"expr"},
    {"ctc"},
    {"csp"},
    {"paving"},
    {"tube"},
    {"estimation"},
    {"scenarios"},
    {"plot"},
    {"commands"},
    {"cli", "", "__main__"},  # "": the package's own __init__, the lazy facade over every
    # layer; __main__: ``python -m boundest``, the command line
    {"_kernels_build"},
]


def _modules() -> dict[str, Path]:
    mods = {}
    for f in PKG.rglob("*.py"):
        parts = list(f.relative_to(PKG.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        mods[".".join(parts)] = f
    return mods


def _imports(name: str, path: Path, mods: dict[str, Path]) -> set[str]:
    """The package modules that ``name`` imports anywhere in its source."""
    base = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        targets = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parent = base[: len(base) - node.level + 1]
                module = ".".join(parent + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            subs = [f"{module}.{a.name}" for a in node.names if f"{module}.{a.name}" in mods]
            # ``from .. import interval`` imports the subpackage, not the package's facade
            targets = subs if subs and len(subs) == len(node.names) else [module, *subs]
        for t in targets:
            if not t.startswith("boundest"):
                continue
            while t not in mods and "." in t:
                t = t.rsplit(".", 1)[0]
            if t != name:
                found.add(t)
    return found


def _layer(module: str) -> int:
    top = module.split(".")[1] if "." in module else ""
    for i, names in enumerate(LAYERS):
        if top in names:
            return i
    raise AssertionError(f"{module}: no layer (add its folder to LAYERS)")


def test_every_import_goes_down_or_stays_in_its_layer():
    mods = _modules()
    upward = sorted(f"{m} -> {t}" for m, p in mods.items() for t in _imports(m, p, mods)
                    if _layer(t) > _layer(m))
    assert upward == []


def test_no_module_imports_the_kernel_archive_builder():
    mods = _modules()
    users = sorted(m for m, p in mods.items() if "boundest._kernels_build" in _imports(m, p, mods))
    assert users == []


def test_the_check_sees_an_upward_import(tmp_path):
    """The walk finds imports inside functions and relative imports (what today's layering
    would miss if it only read the top of each file)."""
    f = tmp_path / "x.py"
    f.write_text("def late():\n    from ..cli import main\n    from .. import interval\n")
    mods = {"boundest.interval.x": f, "boundest.cli": f, "boundest.interval": f}
    assert _imports("boundest.interval.x", f, mods) == {"boundest.cli", "boundest.interval"}
    assert _layer("boundest.cli") > _layer("boundest.interval.x")


def test_outside_interval_trusted_bounds_use_the_public_constructor():
    """``Interval._new`` is private to ``interval/``; the rest of the package says
    ``Interval.trusted``."""
    private = []
    for f in sorted(PKG.rglob("*.py")):
        if "interval" in f.relative_to(PKG).parts[:1]:
            continue
        for node in ast.walk(ast.parse(f.read_text())):
            if isinstance(node, ast.Attribute) and node.attr == "_new":
                private.append(f"{f.relative_to(PKG)}:{node.lineno}")
    assert private == []
