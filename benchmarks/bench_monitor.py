"""Benchmark of ``dynid monitor`` on a day of logs of an unchanged robot: false alarms and time.

A simulated UR10e (:func:`dynid.studies.simulated_fleet.simulate_service_life`) logs one minute at 250 Hz every
minute for 24 hours (1440 logs, the same task with fresh noise, nothing wears); its reference log is identified by
``dynid identify``'s pipeline, then every log is monitored with the default settings (10 s windows, the first 60 the
reference, one false alarm per 30 days of logs by design). Prints the alarms (expected: none), the windows and the time
per minute of log.

    .venv/bin/python benchmarks/bench_monitor.py [hours]
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


def main(hours: float) -> None:
    from dynid.fleet.monitor import dated_logs, monitor_logs
    from dynid.identification.fitted_model import IdentifiedModel
    from dynid.identification.run import run_identification
    from dynid.io.config.identification_config import load_identification_config
    from dynid.studies.simulated_fleet import simulate_service_life

    folder = Path(tempfile.mkdtemp(prefix="dynid-monitor-bench-"))
    try:
        logs = int(round(hours * 60))
        t0 = time.perf_counter()
        simulate_service_life(folder, days=logs, logs_per_day=1, seconds=60.0, rate=250.0, wear_start_day=1e9, rng=0)
        # the logs are named a day apart; only their order matters to the monitor
        print(f"simulated {logs} one-minute logs at 250 Hz in {time.perf_counter() - t0:.0f} s")
        config = load_identification_config(folder / "unit.toml")
        model = IdentifiedModel.from_result(run_identification(config, validate=False))
        t0 = time.perf_counter()
        result = monitor_logs(config, model, dated_logs(folder / "logs"))
        seconds = time.perf_counter() - t0
        print(f"monitored {logs} logs ({len(result.windows)} windows of 10 s, {len(result.terms)} terms) in {seconds:.0f} s "
              f"({seconds / logs:.3f} s per minute of log); alarms: {len(result.alarms)}")
        for a in result.alarms:
            print("  ", a)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    print(f"load before: {os.getloadavg()[0]:.2f}")
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 24.0)
    print(f"load after: {os.getloadavg()[0]:.2f}")
