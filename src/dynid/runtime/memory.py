"""Freed memory kept for reuse in dynid's commands, where the C library's allocator is glibc's.

glibc's ``malloc`` gives freed memory back to the system as soon as more than its trim threshold lies free at the top
of the heap, and that threshold follows the largest block freed so far (twice the mmap threshold, 64 MB at most). A
long log's preparation makes and frees column arrays of tens of megabytes again and again, so the system hands the
same memory back and clears it again for each new array (benchmarks/NOTEBOOK.md, stop 106, says how much).
:func:`keep_freed_memory` fixes both thresholds instead: blocks up to :data:`MMAP_BYTES` from the heap, and up to
:data:`TRIM_BYTES` kept free there. The command's peak memory grows by about the memory kept (benchmarks/README.md).

Only the command line calls it (:func:`dynid.cli.app.main`): a library leaves its caller's allocator as it is.
"""

from __future__ import annotations

import ctypes
import sys

__all__ = ["MMAP_BYTES", "TRIM_BYTES", "keep_freed_memory"]

M_TRIM_THRESHOLD = -1
M_MMAP_THRESHOLD = -3
"""``mallopt`` parameters (glibc's ``malloc.h``)."""

MMAP_BYTES = 32 * 2**20
"""Blocks up to this size come from the heap (glibc's largest mmap threshold on a 64-bit system)."""

TRIM_BYTES = 256 * 2**20
"""Free memory at the top of the heap kept up to this size before it goes back to the system."""


def keep_freed_memory() -> bool:
    """Set glibc's trim and mmap thresholds to :data:`TRIM_BYTES` and :data:`MMAP_BYTES` for this process.

    Returns
    -------
    bool
        Whether they were set (False on another C library or system, where nothing changes).
    """
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(None)
        libc.gnu_get_libc_version  # noqa: B018 - glibc's own function: another C library's mallopt means otherwise
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return bool(mallopt(M_MMAP_THRESHOLD, MMAP_BYTES)) and bool(mallopt(M_TRIM_THRESHOLD, TRIM_BYTES))
