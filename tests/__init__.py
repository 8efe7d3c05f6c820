"""dynid's tests.

Before NumPy or SciPy is imported: OpenBLAS picks its kernels by the CPU (DYNAMIC_ARCH), and the digests of
tests/test_digests.py compare results to 1e-6 across machines. An ill-conditioned real log (the KR 300, cond 3e8) or
an SDP's weakly determined directions (the Med7) move by 1e-5 to 1e-3 between the AVX-512 kernels a Zen 4 or Skylake-X
gets and the AVX2 ones of a Zen 3 or Haswell, where the stored digests were made. Every x86-64 CPU with AVX2 and FMA
runs the Haswell kernels here, so the digests compare the code, not the CPU (tests/test_digests.py checks that the pin
took effect). ``OPENBLAS_CORETYPE`` set by the caller is left as it is.
"""

import os
from pathlib import Path


def _cpu_flags() -> set[str]:
    try:
        text = Path("/proc/cpuinfo").read_text(encoding="utf-8", errors="replace")
    except OSError:
        return set()
    line = next((x for x in text.splitlines() if x.startswith("flags")), "")
    return set(line.partition(":")[2].split())


SAME_BLAS_KERNELS = "Haswell" if {"avx2", "fma"} <= _cpu_flags() else None
"""The OpenBLAS kernels every test process uses (None: the CPU's own, where it lacks AVX2 or FMA)."""

if SAME_BLAS_KERNELS is not None:
    os.environ.setdefault("OPENBLAS_CORETYPE", SAME_BLAS_KERNELS)
