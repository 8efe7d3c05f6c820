"""A log read wrongly never gets "model ready" (issue "Every assurance checked on what the user meets", item 2).

Each real config of ``configs/`` (the four real logs of ``../shared/data``: UR10e, Stäubli TX40, KUKA KR 300, KUKA
LBR Med7) has its identification log read wrongly in each of the ways users do: joint velocities or positions taken
for torques, torques scaled by 10³ or 10⁻³ (a unit), by 10 or 0.1 (currents with drive gains off by 10×), the torque
columns shuffled (a cyclic shift), one joint's torque column read for another's, degrees read as radians. Each is
identified with the config's settings as a user with one log would (no validation log) and as one with the config's
validation logs, and the first line of ``dynid identify`` (:func:`dynid.report.summaries.readiness`) is read: the
target is that none says "model ready". The logs as recorded are run too: none of them may lose its "ready" (no
false alarm). From the repository root: ``.venv/bin/python benchmarks/misread_logs.py`` (about five minutes on two
cores).
"""

from __future__ import annotations

import sys
import tempfile
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from real_logs import DATA, _config  # noqa: E402

CONFIGS = (("ur10e", "ur10e_mamedov2020"), ("tx40", "staubli_tx40_figaroh"), ("kuka_kr300", "kuka_kr300_weigand2021"),
           ("kuka_med7", "kuka_med7_lbrstack"))


def _dense(x) -> np.ndarray:
    if hasattr(x, "column"):
        return np.column_stack([np.asarray(x.column(j), dtype=float) for j in range(x.shape[1])])
    return np.asarray(x, dtype=float)


def misreads(recording) -> dict:
    """name -> the recording read that way."""
    q, tau = _dense(recording.q), _dense(recording.tau)
    dq = _dense(recording.dq) if recording.dq is not None else np.gradient(q, 1.0 / recording.rate, axis=0)
    n = tau.shape[1]
    other = tau.copy()
    other[:, 1] = tau[:, 2]  # J2's column read from J3's
    return {
        "velocities as torques": replace(recording, tau=dq),
        "positions as torques": replace(recording, tau=q),
        "torques ×1e3": replace(recording, tau=tau * 1e3),
        "torques ×1e-3": replace(recording, tau=tau * 1e-3),
        "gains ×10": replace(recording, tau=tau * 10.0),
        "gains ×0.1": replace(recording, tau=tau * 0.1),
        "columns shifted": replace(recording, tau=tau[:, np.roll(np.arange(n), 1)]),
        "J2 from J3": replace(recording, tau=other),
        "degrees as radians": replace(recording, q=np.degrees(q), dq=None if recording.dq is None else np.degrees(dq)),
    }


def first_line(config, recording, validation: tuple) -> str:
    from dynid.exceptions import DynIdError
    from dynid.identification.run import pipeline_of
    from dynid.report.summaries import readiness

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = pipeline_of(config).fit(recording, validation=validation, held_out=not validation)
    except DynIdError as exc:
        return f"refused: {str(exc)[:90]}"
    return readiness(result).text


def main() -> int:
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording

    folder = Path(tempfile.mkdtemp())
    ready, alarms, total = [], [], 0
    print("arm | log | validation logs | first line")
    for name, data_name in CONFIGS:
        if not (DATA / data_name).is_dir():
            print(f"{name}: {DATA / data_name} not found, skipped")
            continue
        config = load_identification_config(_config(name, folder, None, None), data_root=DATA / data_name)
        recording = load_recording(config.identification, config.robot)
        validation = tuple(load_recording(s, config.robot) for s in config.validation)
        for with_validation in (False, True):
            logs = validation if with_validation else ()
            line = first_line(config, recording, logs)
            if not line.startswith("model ready"):
                alarms.append(f"{name} as recorded{' + validation' if with_validation else ''}")
            print(f"{name} | as recorded | {len(logs)} | {line[:150]}", flush=True)
            for kind, wrong in misreads(recording).items():
                total += 1
                line = first_line(config, wrong, logs)
                if line.startswith("model ready"):
                    ready.append(f"{name} {kind}{' + validation' if with_validation else ''}")
                print(f"{name} | {kind} | {len(logs)} | {line[:150]}", flush=True)
    print(f"misread logs that got \"model ready\": {len(ready)} of {total} ({', '.join(ready) or 'none'})")
    print(f"logs as recorded that lost it: {len(alarms)} ({', '.join(alarms) or 'none'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
