"""The core install (no extra) imports every module of boundest and runs a command.

The test suite runs with the ``test`` extra, which brings mpmath, SciPy, hypothesis and Dask:
an import of one of them at the top of a library module would pass every other test and break
``pip install boundest``. Here they are hidden from a subprocess.
"""

from __future__ import annotations

import subprocess
import sys

#: what the extras bring; the library may import them only inside the functions that need them
EXTRAS_ONLY = ("mpmath", "scipy", "hypothesis", "dask", "distributed", "pytest", "filterpy",
               "mkdocs", "codac")

_HIDE = f"""
import importlib.abc, sys
class Hide(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in {EXTRAS_ONLY!r}:
            raise ImportError(f"{{name}} is not in the core install (hidden by the test)")
        return None
sys.meta_path.insert(0, Hide())
"""


def _run(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", _HIDE + code], capture_output=True,
                          text=True, timeout=600)


def test_every_module_imports_without_the_extras():
    code = """
import pkgutil, importlib, boundest
bad = []
for m in pkgutil.walk_packages(boundest.__path__, "boundest."):
    try:
        importlib.import_module(m.name)
    except ImportError as exc:
        bad.append(f"{m.name}: {exc}")
print("\\n".join(bad))
sys.exit(1 if bad else 0)
"""
    r = _run(code)
    assert r.returncode == 0, r.stdout + r.stderr


def test_the_jaulin2001_command_runs_without_the_extras(tmp_path):
    r = _run(f"from boundest.cli import main; sys.exit(main(['run', 'jaulin2001', '--boxes', "
             f"'--out', {str(tmp_path)!r}]))")
    assert r.returncode == 0, r.stdout + r.stderr
    assert (tmp_path / "jaulin2001_boxes.png").is_file()
