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


def cache_folder_for(src_dir: Path) -> Path:
    """The folder Numba caches the kernels of the sources in ``src_dir`` in (this process)."""
    root = os.environ.get("NUMBA_CACHE_DIR")
    if not root:
        return Path(src_dir) / "__pycache__"
    sub = os.path.abspath(src_dir)
    name = f"{os.path.basename(sub)}_{hashlib.sha1(sub.encode()).hexdigest()}"
    return Path(os.path.abspath(root)) / name


def _cache_folders() -> tuple[list[Path], Path]:
    """The folders that may hold the package's cache files, and where to keep the stamp."""
    root = os.environ.get("NUMBA_CACHE_DIR")
    if not root:
        return [_PKG], _PKG / "__pycache__" / "numba-sources.sha256"
    base = Path(os.path.abspath(root))
    folders = [cache_folder_for(d) for d in sorted({p.parent for p in _PKG.rglob("*.py")})]
    pkg = os.path.abspath(_PKG)
    return folders, base / f"boundest_{hashlib.sha1(pkg.encode()).hexdigest()}.sha256"


def kernels_marker() -> Path:
    """Where ``_kernels`` records that the shipped kernel archive was unpacked (beside the
    stamp); dropped with the cache when a Numba source changes."""
    stamp = _cache_folders()[1]
    return stamp.with_name(stamp.name.replace("numba-sources.sha256", "boundest-kernels.json")
                           .replace(".sha256", ".kernels.json"))


#: Modules that mention Numba but define no kernel: editing them leaves every cached kernel
#: valid (and the shipped kernel archive current).
_NO_KERNELS = frozenset({"_numba_cache.py", "_kernels.py", "_kernels_build.py", "cli.py"})


def numba_sources_digest() -> str:
    """sha256 over the package's source files that use Numba (relative path and contents)."""
    digest = hashlib.sha256()
    for src in sorted(_PKG.rglob("*.py")):
        if src.parent == _PKG and src.name in _NO_KERNELS:
            continue
        text = src.read_bytes()
        if b"numba" in text:
            digest.update(src.relative_to(_PKG).as_posix().encode())
            digest.update(text)
    return digest.hexdigest()


def drop_stale_numba_cache() -> None:
    """Delete the package's ``*.nbi``/``*.nbc`` files if any Numba source changed."""
    digest = numba_sources_digest()
    folders, stamp = _cache_folders()
    try:
        if stamp.exists() and stamp.read_text() == digest:
            return
        for folder in folders:
            for f in (*folder.rglob("*.nbi"), *folder.rglob("*.nbc")):
                f.unlink(missing_ok=True)
        kernels_marker().unlink(missing_ok=True)
        stamp.parent.mkdir(parents=True, exist_ok=True)
        stamp.write_text(digest)
    except OSError:  # read-only install: Numba then caches elsewhere or not at all
        pass
