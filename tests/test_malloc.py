"""``boundest._malloc``: glibc's heap thresholds are set on import, and left alone on request."""

from __future__ import annotations

import os
import platform
import subprocess
import sys

import pytest

from boundest import _malloc

GLIBC = sys.platform.startswith("linux") and platform.libc_ver()[0] == "glibc"

PROBE = "import boundest._malloc as m; print(m.keep_freed_memory())"


def _probe(**env: str) -> str:
    base = {k: v for k, v in os.environ.items()
            if k not in ("BOUNDEST_MALLOC", "MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_")}
    out = subprocess.run([sys.executable, "-c", PROBE], env={**base, **env}, check=True,
                         capture_output=True, text=True)
    return out.stdout.strip()


@pytest.mark.skipif(not GLIBC, reason="mallopt is glibc's")
def test_thresholds_are_set_on_glibc():
    assert _probe() == "True"


def test_opt_outs_leave_the_allocator_alone():
    assert _probe(BOUNDEST_MALLOC="default") == "False"
    assert _probe(MALLOC_TRIM_THRESHOLD_="131072") == "False"
    assert _probe(MALLOC_MMAP_THRESHOLD_="131072") == "False"


def test_thresholds_are_bounded():
    # what a process may keep of freed memory stays a small part of a laptop's memory
    assert 0 < _malloc.MMAP_THRESHOLD <= _malloc.TRIM_THRESHOLD <= 2**30
