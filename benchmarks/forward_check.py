"""The exported MJCF simulated along a real validation log (issue "The model proven where it goes", item 3).

For each real config of ``configs/`` (its defaults' main estimate, or the physically consistent one export writes):
the MJCF ``dynid export`` writes, simulated in MuJoCo from the first moving validation log's first state and driven
along its positions by the file's own computed torque plus a 30 Hz PD loop (:func:`dynid.io.replay.mjcf_forward`);
the log prepared as ``dynid validate`` prepares it, without decimation. Prints the torque the simulation needed
against the measured one, dynid's own inverse dynamics against the measured one on the same samples, and the two
against each other (what the simulator adds). From the repository root: ``.venv/bin/python
benchmarks/forward_check.py`` (about a minute).
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
CONFIGS = ("ur10e", "tx40", "kuka_kr300", "kuka_med7")


def main() -> int:
    from dynid.identification.run import run_identification
    from dynid.io.datasets import load_recording
    from dynid.io.export import consistent_estimate, mjcf_from_robot
    from dynid.io.identification_config import load_identification_config
    from dynid.io.replay import mjcf_forward
    from dynid.preprocessing.pipeline import prepare
    from dynid.preprocessing.strategies import carried_over
    from dynid.report.output import write_results

    folder = Path(tempfile.mkdtemp())
    print("config | log | samples | simulated against measured % | dynid's model against measured % | simulated "
          "against dynid's model % | largest tracking error, rad")
    for name in CONFIGS:
        config = load_identification_config(REPO / "configs" / f"{name}.toml")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = run_identification(config)
        write_results(folder / f"{name}.json", result.to_dict(), "identify")
        identified = json.loads((folder / f"{name}.json").read_text())
        robot, phi = consistent_estimate(result.model, identified, name)
        text = mjcf_from_robot(robot, phi)
        moving = next(v for v in result.validations if v.rest_share is None or float(np.mean(v.rest_share)) < 0.5)
        spec = next(s for s in config.validation if s.name == moving.name)
        settings = replace(carried_over(None, config.preprocessing), decimation=1, parallel_cutoff=0.0)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            data = prepare(load_recording(spec, robot), settings, strict=False)
        q, dq, ddq, tau = (np.asarray(x, dtype=float) for x in (data.q, data.dq, data.ddq, data.tau))
        check = mjcf_forward(text, robot, phi, np.asarray(data.t), q, dq, ddq, tau)
        print(f"{name} | {moving.name} | {check.n_samples} | {check.simulated_vs_measured:.2f} | "
              f"{check.model_vs_measured:.2f} | {check.simulated_vs_model:.2f} | {check.tracking_error.max():.2e}")
        sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
