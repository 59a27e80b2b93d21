"""The stale-cache guard drops the package's Numba cache files in both cache locations."""

from __future__ import annotations

import hashlib
import os

from boundest import _numba_cache as nc


def test_a_changed_source_drops_the_cache_under_numba_cache_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    sub = os.path.abspath(nc._PKG / "interval")
    folder = tmp_path / f"interval_{hashlib.sha1(sub.encode()).hexdigest()}"
    folder.mkdir()
    stale = [folder / "arith._add_lo-10.py311.nbi", folder / "arith._add_lo-10.py311.1.nbc"]
    for f in stale:
        f.write_bytes(b"old machine code")
    other = tmp_path / "someone_else_0123" / "x.nbi"  # another package's cache is left alone
    other.parent.mkdir()
    other.write_bytes(b"")
    folders, stamp = nc._cache_folders()
    assert folder in folders and stamp.parent == tmp_path
    stamp.write_text("a digest of other sources")
    nc.drop_stale_numba_cache()
    assert not any(f.exists() for f in stale) and other.exists()
    # the stamp now records the current sources: a second call keeps new cache files
    new = folder / "arith._add_lo-10.py311.nbi"
    new.write_bytes(b"fresh")
    nc.drop_stale_numba_cache()
    assert new.exists()


def test_without_numba_cache_dir_the_stamp_sits_in_the_package(monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    folders, stamp = nc._cache_folders()
    assert folders == [nc._PKG] and stamp.parent == nc._PKG / "__pycache__"
