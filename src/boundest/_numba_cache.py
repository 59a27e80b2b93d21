"""Guard against stale Numba caches.

Numba keys its on-disk cache of a compiled function on the file that defines it, not on the
helpers it inlines from other files. After editing ``rounding.py`` (say), the kernels in
``arith.py`` would be loaded from cache with the old helpers, wrong or even crashing. At import,
boundest hashes every source file that uses Numba; when the hash differs from the one recorded
beside the cache, the package's cached machine code is dropped and recompiled on demand.
(This covers the default cache location, ``__pycache__`` beside the sources; with
``NUMBA_CACHE_DIR`` set, clear that folder yourself after editing kernels.)
"""

from __future__ import annotations

import hashlib
from pathlib import Path

_PKG = Path(__file__).parent


def drop_stale_numba_cache() -> None:
    """Delete the package's ``*.nbi``/``*.nbc`` files if any Numba source changed."""
    digest = hashlib.sha256()
    for src in sorted(_PKG.rglob("*.py")):
        text = src.read_bytes()
        if b"numba" in text:
            digest.update(src.relative_to(_PKG).as_posix().encode())
            digest.update(text)
    stamp = _PKG / "__pycache__" / "numba-sources.sha256"
    try:
        if stamp.exists() and stamp.read_text() == digest.hexdigest():
            return
        for f in (*_PKG.rglob("*.nbi"), *_PKG.rglob("*.nbc")):
            f.unlink(missing_ok=True)
        stamp.parent.mkdir(exist_ok=True)
        stamp.write_text(digest.hexdigest())
    except OSError:  # read-only install: Numba then caches elsewhere or not at all
        pass
