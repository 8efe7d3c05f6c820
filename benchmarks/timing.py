"""Timing helper shared by the benchmarks."""

from __future__ import annotations

import time


def best_of(fn, repeats: int = 5) -> float:
    """Best wall time of ``repeats`` calls of ``fn`` after one warm-up call (JIT compilation, page faults) [s]."""
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)
