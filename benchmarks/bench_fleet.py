"""Benchmark of ``dynid fleet`` and ``dynid monitor``'s recursive update.

1. A simulated UR10e fleet (:func:`dynid.studies.simulated_fleet.simulate_fleet`: units of 6-minute identification
   logs at 500 Hz and 1-minute validation logs, no drive-gain runs) identified by :func:`dynid.fleet.identification.run_fleet`
   on a LocalCluster of 1 worker, then of 2 workers (the same fleet, read from disk each time): wall time, speed-up, the
   units' median task time, and each worker's peak resident memory after its first units and after its last ones (flat:
   a worker's memory does not grow with the units it has identified).
2. The recursive least squares of ``dynid monitor`` (6 joints × 3 terms): microseconds per sample over 10⁶ samples.

    .venv/bin/python benchmarks/bench_fleet.py [units]      (default 100; the fleet takes 3 GB of disk in /tmp)
"""

from __future__ import annotations

import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402


def fleet(units: int) -> None:
    from dynid.fleet.identification import run_fleet
    from dynid.io.config.fleet_manifest import load_fleet_manifest
    from dynid.studies.simulated_fleet import simulate_fleet

    folder = Path(tempfile.mkdtemp(prefix="dynid-fleet-bench-"))
    try:
        t0 = time.perf_counter()
        simulate_fleet(folder, units=units, seconds=360.0, rate=500.0, validation_seconds=60.0, odd_unit=None,
                       calibration=False, rng=0)
        print(f"simulated {units} units (6 min at 500 Hz each) in {time.perf_counter() - t0:.0f} s")
        manifest = load_fleet_manifest(folder / "fleet.toml")
        walls = {}
        for workers in (1, 2):
            t0 = time.perf_counter()
            result = run_fleet(manifest, workers=workers)
            walls[workers] = time.perf_counter() - t0
            tasks = np.array([u.seconds for u in result.units])
            memory = np.array([u.memory_mb for u in result.units])
            half = len(memory) // 2
            print(f"{workers} worker(s): {walls[workers]:.0f} s for {units} units ({walls[workers] / units:.2f} s per unit), "
                  f"median task {np.median(tasks):.2f} s; peak worker memory after the first half of the units "
                  f"{memory[:half].max():.0f} MB, after the second {memory[half:].max():.0f} MB; "
                  f"{len(result.identified)} identified, {len(result.outliers)} flags, pooled: {result.pooled is not None}")
        print(f"speed-up 1 -> 2 workers: {walls[1] / walls[2]:.2f}")
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def recursive_update() -> float:
    from dynid.estimators.recursive import RecursiveLeastSquares

    rng = np.random.default_rng(0)
    m, n, q = 1_000_000, 6, 3
    block = 10_000
    phi, y = rng.normal(size=(block, n, q)), rng.normal(size=(block, n))
    rls = RecursiveLeastSquares(np.zeros((n, q)), 1e2, 0.9999)
    rls.update(phi[:10], y[:10])  # compiled (or loaded from the cache) before timing
    t0 = time.perf_counter()
    for _ in range(m // block):
        rls.update(phi, y)
    per = (time.perf_counter() - t0) / m
    print(f"recursive least squares, 6 joints x 3 terms: {per * 1e6:.3f} us per sample (target < 50 us)")
    return per * 1e6


if __name__ == "__main__":
    print(f"load before: {os.getloadavg()[0]:.2f}")
    recursive_update()
    fleet(int(sys.argv[1]) if len(sys.argv) > 1 else 100)
    print(f"load after: {os.getloadavg()[0]:.2f}")
