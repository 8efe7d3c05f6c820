"""The exported MJCF simulated along a real validation log (issue "The model proven where it goes", item 3).

For each real config of ``configs/`` (its defaults' main estimate, or the physically consistent one export writes):
the MJCF ``dynid export`` writes, simulated in MuJoCo from the first moving validation log's first state and driven
along its positions by the file's own computed torque plus a 30 Hz PD loop, as ``dynid export --mjcf F --forward``
does (:func:`dynid.identification.run.forward_check`); the log prepared as ``dynid validate`` prepares it, without
decimation. Prints the torque the simulation needed
against the measured one, dynid's own inverse dynamics against the measured one on the same samples, and the two
against each other (what the simulator adds). From the repository root: ``.venv/bin/python
benchmarks/forward_check.py`` (about a minute).
"""

from __future__ import annotations

import json
import sys
import tempfile
import warnings
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
CONFIGS = ("ur10e", "tx40", "kuka_kr300", "kuka_med7")


def main() -> int:
    from dynid.identification.run import forward_check, run_identification
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.exported.export import consistent_estimate
    from dynid.model.description_files import mjcf_from_robot
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
        text = mjcf_from_robot(*consistent_estimate(config.robot, identified, name))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            log, check = forward_check(config, identified, text, source=name)
        print(f"{name} | {log} | {check.n_samples} | {check.simulated_vs_measured:.2f} | "
              f"{check.model_vs_measured:.2f} | {check.simulated_vs_model:.2f} | {check.tracking_error.max():.2e}")
        sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
