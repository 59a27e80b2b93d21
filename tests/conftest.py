"""Test session set-up.

Numba's on-disk cache is keyed on the file that defines each kernel, not on the helpers it
inlines from ``rounding.py``: after editing a helper, stale machine code would be loaded. The
suite therefore drops the package's Numba cache whenever any interval source file changed.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import boundest

_PKG = Path(boundest.__file__).parent


def _drop_stale_numba_cache() -> None:
    digest = hashlib.sha256()
    for src in sorted(_PKG.rglob("*.py")):
        digest.update(src.read_bytes())
    stamp = _PKG / "__pycache__" / "numba-sources.sha256"
    if stamp.exists() and stamp.read_text() == digest.hexdigest():
        return
    for f in (*_PKG.rglob("*.nbi"), *_PKG.rglob("*.nbc")):
        f.unlink(missing_ok=True)
    stamp.parent.mkdir(exist_ok=True)
    stamp.write_text(digest.hexdigest())


_drop_stale_numba_cache()
