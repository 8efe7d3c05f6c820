"""Validation logs read otherwise than the identification log (``dynid.validation.channel_checks``, and the geometry
check on validation logs), on real logs: what is named, and that the logs as recorded are not.

Each real config (``configs/ur10e.toml``, ``tx40.toml``, ``kuka_kr300.toml``, ``kuka_med7.toml``) is identified with its
settings; then each of its validation logs whose torques vary is scored again (``run_validation``, as ``dynid validate``
does) as recorded, with each joint's torque negated in turn, with each pair of neighbouring joints' torque columns
swapped, with every joint's torque times 0.1 and 1000 (another unit or drive gain), and with J2's times 1000 (N·mm). A
flipped joint must be named as flipped, a swapped pair as swapped (naming the pair), a scale as a scale, the log as
recorded not at all. A flip or a swap the fitted estimate cannot tell (a joint whose torque does not vary on that log beyond its
noise floor, or that the estimate does not fit on the identification log) is counted as "not judged", not as a miss.

From the repository root, with the shared data beside it: ``.venv/bin/python benchmarks/read_otherwise.py``. The 36
short windows of ``benchmarks/short_windows.py`` as configured are checked by ``--windows``: none of their validation
logs may be named.
"""

from __future__ import annotations

import json
import sys
import tempfile
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))

CONFIGS = ("ur10e", "tx40", "kuka_kr300", "kuka_med7")


def _named(comparison) -> str:
    """What the checks said of a scored log: "" (nothing), or the warning's first words."""
    return comparison.misread


def _case(config, identified, recording, tau, label: str):
    from dynid.identification.run import run_validation

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        (scored,), _ = run_validation(config, identified, datasets=(replace(recording, tau=tau),))
    return label, _named(scored)


def real() -> int:
    """Flips and swaps on the real configs' validation logs (module docstring)."""
    from dynid.identification.run import run_identification
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.files import write_json
    from dynid.io.logs.datasets import load_recording

    counts = {"named right": 0, "named wrong": 0, "not judged": 0, "as recorded, named": 0, "as recorded": 0}
    print("config | log | change | named")
    for name in CONFIGS:
        config = load_identification_config(REPO / "configs" / f"{name}.toml")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = run_identification(config)
        folder = Path(tempfile.mkdtemp())
        write_json(folder / "results.json", result.to_dict())  # what dynid validate reads
        identified = json.loads((folder / "results.json").read_text())
        moving = {v.name for v in result.validations if np.any(v.varies(beyond="floor"))}
        for spec in config.validation:
            if spec.name not in moving:
                continue
            recording = load_recording(spec, config.robot)
            tau = np.asarray(recording.tau, dtype=float)
            label, said = _case(config, identified, recording, tau, "as recorded")
            counts["as recorded"] += 1
            counts["as recorded, named"] += bool(said)
            print(f"{name} | {spec.name} | as recorded | {said[:100] or '-'}")
            n = tau.shape[1]
            changes = [(f"J{j + 1} negated", f"J{j + 1}'s measured torque runs against", tau * np.where(np.arange(n) == j, -1, 1))
                       for j in range(n)]
            changes += [(f"J{j + 1}, J{j + 2} swapped", f"J{j + 1}'s and J{j + 2}'s measured torques fit each other's",
                         tau[:, [*range(j), j + 1, j, *range(j + 2, n)]]) for j in range(n - 1)]
            changes += [(f"every joint ×{f:g}", "are that many times", tau * f) for f in (0.1, 1000.0)]
            changes += [("J2 ×1000", "the measured torques of J2 (", tau * np.where(np.arange(n) == 1, 1000.0, 1.0))]
            for label, expected, changed in changes:
                _, said = _case(config, identified, recording, changed, label)
                said_right = expected in said
                key = "named right" if said_right else "not judged" if not said else "named wrong"
                counts[key] += 1
                print(f"{name} | {spec.name} | {label} | {key}: {said[:110] or '-'}")
            sys.stdout.flush()
    print(", ".join(f"{k}: {v}" for k, v in counts.items()))
    return 0


def windows() -> int:
    """The 36 windows as configured: none of their validation logs may be named."""
    import short_windows as sw

    from dynid.identification.run import run_identification
    from dynid.io.config.identification_config import load_identification_config

    folder = Path(tempfile.mkdtemp())
    cases = [("ur10e", w) for w in sw.WINDOWS] + [(n, w) for n, ws in sw.OTHER_WINDOWS.items() for w in ws]
    cases += [(n, w) for n, ws in sw.FRESH_WINDOWS.items() for w in ws]
    named = []
    for name, window in cases:
        path, root = sw._window_config(name, window, folder)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = run_identification(load_identification_config(path, data_root=root))
        said = [v.name for v in result.validations if v.misread]
        named += [f"{name} {window}: {', '.join(said)}"] if said else []
        print(f"{name} | {window} | {result.main} | {', '.join(said) or '-'}")
        sys.stdout.flush()
    print(f"windows: {len(cases)}, with a validation log named: {len(named)} {named}")
    return 0


if __name__ == "__main__":
    sys.exit(windows() if "--windows" in sys.argv[1:] else real())
