"""Keep freed heap memory in the process, so that array temporaries are not faulted in again.

The contractors allocate and free many NumPy temporaries of 10 kB to a few MB per sweep. With
glibc's default thresholds the heap is trimmed back to the system after such frees and grown
again by the next sweep, and every regrown page costs a page fault: on the range-only robot
(Rohou et al. 2018, dt = 0.01) that was 0.4-0.5 s of system time in a 2.4 s solve
(``benchmarks/bench_malloc.py``). Raising the trim threshold (freed memory at the top of the
heap is kept up to that size) and fixing the mmap threshold (arrays under it come from the
heap) removes it. The cost: a process may hold up to ``TRIM_THRESHOLD`` of freed memory.

The ``boundest`` command applies it to its own process (``cli.main``), on glibc only.
Importing the library changes nothing: an allocator is process-wide state, which a notebook,
a service or another library importing boundest did not ask to change. A library user who
wants the gain calls ``boundest.keep_freed_memory()`` once. ``BOUNDEST_MALLOC=default`` in the
environment leaves the allocator as it is; glibc's own ``MALLOC_TRIM_THRESHOLD_`` and
``MALLOC_MMAP_THRESHOLD_`` variables also take precedence (nothing is changed when either is
set).
"""

from __future__ import annotations

import os
import sys

__all__ = ["MMAP_THRESHOLD", "TRIM_THRESHOLD", "keep_freed_memory"]

#: Freed memory at the top of the heap is returned to the system only beyond this size.
TRIM_THRESHOLD = 256 * 2**20
#: Allocations of at least this size are served by ``mmap`` (and unmapped when freed).
MMAP_THRESHOLD = 32 * 2**20

_M_TRIM_THRESHOLD = -1  # glibc <malloc.h>
_M_MMAP_THRESHOLD = -3


def keep_freed_memory(trim: int = TRIM_THRESHOLD, mmap: int = MMAP_THRESHOLD) -> bool:
    """Set glibc's trim and mmap thresholds (bytes) with ``mallopt``, for the whole process.

    Measured (``benchmarks/bench_malloc.py``): the range-only robot of Rohou et al. 2018 runs
    1.33 times faster, the other scenarios 1.03-1.04 times; the process may then keep up to
    ``trim`` bytes of freed memory instead of returning it to the system.

    Returns ``True`` when both were set; ``False`` off Linux/glibc, when the user set the
    glibc variables or ``BOUNDEST_MALLOC=default``, or when ``mallopt`` refused.
    """
    if not sys.platform.startswith("linux") or os.environ.get("BOUNDEST_MALLOC") == "default":
        return False
    if "MALLOC_TRIM_THRESHOLD_" in os.environ or "MALLOC_MMAP_THRESHOLD_" in os.environ:
        return False
    import ctypes

    try:
        libc = ctypes.CDLL(None)
        mallopt = libc.mallopt
        libc.gnu_get_libc_version.restype = ctypes.c_char_p
        if not libc.gnu_get_libc_version():
            return False
    except (OSError, AttributeError):  # musl and others: no mallopt or no glibc
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    mallopt.restype = ctypes.c_int
    return bool(mallopt(_M_TRIM_THRESHOLD, int(trim))) and bool(
        mallopt(_M_MMAP_THRESHOLD, int(mmap)))
