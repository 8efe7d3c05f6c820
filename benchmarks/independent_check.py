"""The independent check of ``tests/identification/test_independent_check.py``, with its figures printed, over several
seeds: UR10e logs simulated in MuJoCo outside dynid's model (tests/mujoco_logs.py), no [preprocessing] table.

For each case and seed: the validation error per joint of dynid's main estimate over that of the true parameters on
the same samples (the floor: 1.00 is at it); and, on the point-to-point logs, the true parameters' error as dynid
reports it over their error on the raw samples (the simulation's true states, unfiltered, every sample of the
validation half, dynid's model of the truth with sign(q̇) exact at rest): over every sample (``relative_error``) and
at rest (``rest_rmse`` against the raw RMS error where the true velocity is exactly 0: the prescribed motions').
Run from the repository root:
``.venv/bin/python benchmarks/independent_check.py`` (two to three minutes).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.identification.test_independent_check import _case  # noqa: E402

CASES = [("ptp", "sign", False), ("fourier", "frictionloss", True), ("ptp", "frictionloss", True)]
NAMES = {("ptp", "sign", False): "point-to-point, inverse dynamics + fc·sign(q̇)",
         ("fourier", "frictionloss", True): "slow Fourier, PID loop, MuJoCo frictionloss",
         ("ptp", "frictionloss", True): "point-to-point, PID loop, MuJoCo frictionloss"}


def _against_raw(result, log, half) -> tuple[np.ndarray, np.ndarray]:
    """The truth's error in dynid's table over its error on the raw samples, per joint: over every sample, at rest."""
    from dynid.dynamics.regressor import regressor

    truth = next(r for r in result.references if r.name == "truth").beta
    q, dq, ddq, tau = (x[half:] for x in (log.q, log.dq, log.ddq, log.tau_meas))
    error = tau - result.base.base_observation(regressor(result.model, q, dq, ddq)) @ truth
    raw = 100.0 * np.linalg.norm(error, axis=0) / np.linalg.norm(tau, axis=0)
    resting = np.abs(dq) < 1e-9  # exact rests: the prescribed motions'; under a PID loop the joints never stop exactly
    m = result.validations[0].metrics()["truth"]
    if not np.all(resting.any(axis=0)):
        return m["relative_error"] / raw, np.full(raw.shape, np.nan)
    raw_rest = np.sqrt(np.where(resting, error**2, 0).sum(0) / resting.sum(0))
    return m["relative_error"] / raw, m["rest_rmse"] / raw_rest


def main(seeds=(1, 2, 3)) -> None:
    from dynid.identification.run import run_identification
    from dynid.io.config.identification_config import load_identification_config

    for case in CASES:
        ratios, globals_, kinds, overall, rest = [], [], set(), [], []
        for seed in seeds:
            folder = Path(tempfile.mkdtemp())
            cfg, log, half = _case(folder, *case, seed)
            result = run_identification(load_identification_config(cfg))
            m = result.validations[0].metrics()
            ratios.append(m[result.main]["relative_error"] / m["truth"]["relative_error"])
            globals_.append(m[result.main]["global_relative_error"] / m["truth"]["global_relative_error"])
            kinds |= {f.kind for f in result.findings}
            if case[0] == "ptp":
                a, b = _against_raw(result, log, half)
                overall.append(a)
                rest.append(b)
        line = (f"{NAMES[case]}: per joint, estimate / truth error, worst over {len(seeds)} seeds: "
                + " ".join(f"{x:.2f}" for x in np.array(ratios).max(axis=0)) + f"; all joints {max(globals_):.2f}; "
                + "findings: " + (", ".join(sorted(kinds)) or "none"))
        if overall:
            line += ("\n  the truth as dynid scores it / on the raw samples, worst over the seeds: every sample "
                     + " ".join(f"{x:.2f}" for x in np.array(overall).max(axis=0)) + "; at rest "
                     + (" ".join(f"{x:.2f}" for x in np.array(rest).max(axis=0)) if np.isfinite(rest).all()
                        else "— (no exact rest under the loop)"))
        print(line)
        sys.stdout.flush()


if __name__ == "__main__":
    main()
