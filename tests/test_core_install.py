"""The core install (no extra) imports every module of boundest and runs a command.

An import of an extra (mpmath, SciPy, ...) at the top of a library module would pass every
other test, which run with the ``test`` extra, and break ``pip install boundest``
(``core_install.HIDE_EXTRAS``).
"""

from __future__ import annotations

import subprocess
import sys

from .core_install import HIDE_EXTRAS


def _run(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", HIDE_EXTRAS + code], capture_output=True,
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
