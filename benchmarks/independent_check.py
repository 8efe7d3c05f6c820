"""The independent check of ``tests/identification/test_independent_check.py``, with its figures printed, over several
seeds: UR10e logs simulated in MuJoCo outside dynid's model (tests/mujoco_logs.py), no [preprocessing] table.

For each case and seed: the validation error per joint of dynid's main estimate over that of the true parameters on
the same samples (the floor: 1.00 is at it), and the true parameters' RMS error at rest in dynid's table over that on
the raw samples (point-to-point logs with exact rests). Run from the repository root:
``.venv/bin/python benchmarks/independent_check.py`` (about a minute).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.experiment.test_independent_check import _case  # noqa: E402

CASES = [("ptp", "sign", False), ("fourier", "frictionloss", True), ("ptp", "frictionloss", True)]
NAMES = {("ptp", "sign", False): "point-to-point, inverse dynamics + fc·sign(q̇)",
         ("fourier", "frictionloss", True): "slow Fourier, PID loop, MuJoCo frictionloss",
         ("ptp", "frictionloss", True): "point-to-point, PID loop, MuJoCo frictionloss"}


def main(seeds=(1, 2, 3)) -> None:
    from dynid.identification.run import run_identification
    from dynid.io.identification_config import load_identification_config

    for case in CASES:
        ratios, globals_, kinds = [], [], set()
        for seed in seeds:
            folder = Path(tempfile.mkdtemp())
            cfg, _, _ = _case(folder, *case, seed)
            result = run_identification(load_identification_config(cfg))
            m = result.validations[0].metrics()
            ratios.append(m[result.main]["relative_error"] / m["truth"]["relative_error"])
            globals_.append(m[result.main]["global_relative_error"] / m["truth"]["global_relative_error"])
            kinds |= {f.kind for f in result.findings}
        r = np.array(ratios)
        print(f"{NAMES[case]}: per joint, estimate / truth error, worst over {len(seeds)} seeds: "
              + " ".join(f"{x:.2f}" for x in r.max(axis=0)) + f"; all joints {max(globals_):.2f}; findings: "
              + (", ".join(sorted(kinds)) or "none"))
        sys.stdout.flush()


if __name__ == "__main__":
    main()
