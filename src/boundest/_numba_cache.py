"""Guard against stale Numba caches.

Numba keys its on-disk cache of a compiled function on the file that defines it, not on the
helpers it inlines from other files. After editing ``rounding.py`` (say), the kernels in
``arith.py`` would be loaded from cache with the old helpers, wrong or even crashing. At import,
boundest hashes every source file that uses Numba; when the hash differs from the one recorded
beside the cache, the package's cached machine code is dropped and recompiled on demand. Both
cache locations are covered: ``__pycache__`` beside the sources, and the folders Numba makes
under ``NUMBA_CACHE_DIR`` when that is set (one per source folder, named
``<folder>_<sha1 of its absolute path>``).
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

_PKG = Path(__file__).parent


def _cache_folders() -> tuple[list[Path], Path]:
    """The folders that may hold the package's cache files, and where to keep the stamp."""
    root = os.environ.get("NUMBA_CACHE_DIR")
    if not root:
        return [_PKG], _PKG / "__pycache__" / "numba-sources.sha256"
    base = Path(os.path.abspath(root))
    folders = []
    for src_dir in sorted({p.parent for p in _PKG.rglob("*.py")}):
        sub = os.path.abspath(src_dir)
        name = f"{os.path.basename(sub)}_{hashlib.sha1(sub.encode()).hexdigest()}"
        folders.append(base / name)
    pkg = os.path.abspath(_PKG)
    return folders, base / f"boundest_{hashlib.sha1(pkg.encode()).hexdigest()}.sha256"


def drop_stale_numba_cache() -> None:
    """Delete the package's ``*.nbi``/``*.nbc`` files if any Numba source changed."""
    digest = hashlib.sha256()
    for src in sorted(_PKG.rglob("*.py")):
        text = src.read_bytes()
        if b"numba" in text:
            digest.update(src.relative_to(_PKG).as_posix().encode())
            digest.update(text)
    folders, stamp = _cache_folders()
    try:
        if stamp.exists() and stamp.read_text() == digest.hexdigest():
            return
        for folder in folders:
            for f in (*folder.rglob("*.nbi"), *folder.rglob("*.nbc")):
                f.unlink(missing_ok=True)
        stamp.parent.mkdir(parents=True, exist_ok=True)
        stamp.write_text(digest.hexdigest())
    except OSError:  # read-only install: Numba then caches elsewhere or not at all
        pass


def announce_compilation(what: str, estimate_s: float | None = None) -> None:
    """Print one line on standard error when Numba first compiles a kernel in this process.

    Numba reports a compilation (a ``numba:compile`` event) only on a cache miss, so a run
    that finds every kernel in the on-disk cache prints nothing. Called by the command line
    before a command runs; ``what`` names the command, ``estimate_s`` is its measured
    empty-cache compile time on 2 cores (printed as "about N s").
    """
    import sys

    from numba.core import event

    class _Notice(event.Listener):
        def __init__(self) -> None:
            self.said = False

        def on_start(self, ev: event.Event) -> None:  # noqa: ARG002 - numba's signature
            if self.said:
                return
            self.said = True
            how_long = (f"about {estimate_s:.0f} s on 2 cores" if estimate_s is not None
                        else "it may take a minute")
            print(f"boundest: compiling the Numba kernels {what} uses ({how_long}; once: they "
                  f"are cached on disk for later runs) ...", file=sys.stderr, flush=True)

        def on_end(self, ev: event.Event) -> None:
            pass

    event.register("numba:compile", _Notice())
