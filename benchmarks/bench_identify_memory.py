"""Benchmark: memory of the chunked identification does not grow with the log's length.

Synthetic 6-DOF er16 logs at 1 kHz of 6 minutes and of 1 hour (smooth multi-sine motion, torques from
dynid's regressor — the values do not matter here, only the sizes). Each is identified by
``dynid.identification.estimation_pass.identify`` (parallel decimation by 10, WLS by incremental QR).
Prints the peak memory allocated during the identification (tracemalloc; the input signals are
allocated before and not counted), the time, and the ratios: 1-hour peak / 6-minute peak, and the
1-hour peak against the size the stacked base observation matrix would have (the reference: what a
non-chunked least squares would hold). Targets: the peak barely grows with the length (ratio near 1,
well below the 10x of the data), and stays far below the full matrix. The compiled regressor is loaded
first, so that both logs go through it (a process's first samples would otherwise take the NumPy form).
"""

from __future__ import annotations

import time
import tracemalloc

import numpy as np

from dynid.dynamics.base_parameters import base_parameters
from dynid.identification.estimation_pass import identify
from dynid.model.description import load_robot
from dynid.preprocessing.preparation import PreparedData, Preprocessing

RATE = 1000.0
DECIMATION = 10


def prepared(robot, minutes: float) -> PreparedData:
    n = int(minutes * 60 * RATE)
    t = np.arange(n) / RATE
    k = np.arange(1, 5)[:, None] * 2 * np.pi * 0.1
    amp = np.linspace(0.3, 0.8, robot.n_dof)
    q = np.zeros((n, robot.n_dof))
    dq = np.zeros_like(q)
    ddq = np.zeros_like(q)
    for h, w in enumerate(k[:, 0]):
        phase = 0.7 * h + np.arange(robot.n_dof)
        s, c = np.sin(w * t[:, None] + phase), np.cos(w * t[:, None] + phase)
        q += amp / (h + 1) * s
        dq += amp / (h + 1) * w * c
        ddq -= amp / (h + 1) * w * w * s
    tau = np.random.default_rng(0).normal(size=q.shape) * 0.1 + np.sin(q) * 10 + dq
    settings = Preprocessing(decimation=DECIMATION, trim=0.0, min_speed=0.0).resolved(RATE, q)
    return PreparedData(f"{minutes:g} min", t, q, dq, ddq, tau, RATE, settings)


def measure(robot, base, minutes: float) -> tuple[float, float, int]:
    data = prepared(robot, minutes)
    tracemalloc.start()
    t0 = time.perf_counter()
    result = identify(robot, base, data, "wls")
    seconds = time.perf_counter() - t0
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak / 1e6, seconds, result.n_rows


def main() -> None:
    from dynid.dynamics import regressor as regressor_module

    regressor_module.NUMPY_SAMPLES = 0  # both logs through the compiled regressor
    robot = load_robot("er16")
    base = base_parameters(robot, rng=0)
    identify(robot, base, prepared(robot, 0.2), "wls")  # warm-up (compilation or the cache)
    short_peak, short_s, _ = measure(robot, base, 6)
    long_peak, long_s, rows = measure(robot, base, 60)
    full = rows * base.n_base * 8 / 1e6
    print(f"er16, {base.n_base} base parameters, 1 kHz, decimation {DECIMATION}, WLS by incremental QR")
    print(f"   6 min log: peak {short_peak:8.1f} MB, {short_s:6.1f} s")
    print(f"  60 min log: peak {long_peak:8.1f} MB, {long_s:6.1f} s  ({rows} equations)")
    print(f"  stacked base observation matrix of the 60 min log would be {full:8.1f} MB")
    print(f"ratio peak(60 min) / peak(6 min) = {long_peak / short_peak:.2f}  (data ratio 10)")
    print(f"ratio peak(60 min) / full matrix  = {long_peak / full:.3f}")


if __name__ == "__main__":
    main()
