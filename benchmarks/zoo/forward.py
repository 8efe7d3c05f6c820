"""Benchmark: the exported MJCF simulated along the zoo's MuJoCo logs (issue "The model proven where it goes", item 3:
"on the zoo's MuJoCo logs and the real logs"; the real logs are benchmarks/forward_check.py's).

For each zoo arm and dry-friction truth (benchmarks/zoo/zoo.py: the vendor URDF simulated in MuJoCo under a PID loop,
MuJoCo's own ``frictionloss`` constraint or ``fc·sign(q̇)`` as the dry friction), the ``excitation`` cell (60 s
Fourier log) is identified by ``dynid identify`` with the defaults, and the MJCF ``dynid export`` writes from it is
simulated in MuJoCo along the 20 s validation log, as ``dynid export --mjcf F --forward`` does
(:func:`dynid.identification.run.forward_check`: the file's own computed torque plus a 30 Hz PD loop). Beside it, the
same simulation of an MJCF written from the simulated arm's true parameters (what a perfect identification would
give: the floor of this check on these logs). Printed: the tracking torque against the logged one for both, dynid's
inverse dynamics against the logged torque on the same samples, and the largest tracking error.

    .venv/bin/python benchmarks/zoo/forward.py [--arms UR5,Panda] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import warnings
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from zoo import ARMS, TRUTHS, run_arm  # noqa: E402


def forward(folder: Path) -> dict:
    """The forward check of one zoo cell's identified MJCF and of its truth's."""
    from dynid.identification.run import forward_check, moving_validation
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.exported.export import consistent_estimate
    from dynid.io.exported.replay import mjcf_forward
    from dynid.model.description_files import mjcf_from_robot

    config = load_identification_config(folder / "excitation.toml")
    identified = json.loads((folder / "out-excitation" / "results.json").read_text())
    robot, phi = consistent_estimate(config.robot, identified, str(folder))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        name, check = forward_check(config, identified, mjcf_from_robot(robot, phi), source=str(folder))
        truth = dict(np.genfromtxt(folder / "truth.csv", delimiter=",", names=True, dtype=None, encoding="utf-8"))
        phi_truth = np.array([float(truth.get(n, 0.0)) for n in robot.parameter_names])
        _, arrays = moving_validation(config, identified, robot)
        floor = mjcf_forward(mjcf_from_robot(robot, phi_truth), robot, phi_truth, *arrays)
    return dict(log=name, samples=check.n_samples, simulated=check.simulated_vs_measured,
                model=check.model_vs_measured, tracking=float(check.tracking_error.max()),
                truth_simulated=floor.simulated_vs_measured, truth_model=floor.model_vs_measured,
                main=identified["main_estimate"])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arms", default=",".join(ARMS))
    parser.add_argument("--out", default=str(REPO / "dynid-zoo-forward"))
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args(argv)
    out = Path(args.out)
    rows = []
    for arm in [a.strip() for a in args.arms.split(",") if a.strip()]:
        run_arm(arm, out, args.seed, ("excitation",))
        for truth in TRUTHS:
            row = {"arm": arm, "truth": truth, **forward(out / re.sub(r"\W+", "_", arm.lower()) / truth)}
            rows.append(row)
            print(json.dumps(row), flush=True)
    print("\n| arm | dry friction | samples | main estimate | simulated vs logged % | dynid's model vs logged % | "
          "truth's MJCF simulated vs logged % | largest tracking error [rad] |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['arm']} | {r['truth']} | {r['samples']} | {r['main']} | {r['simulated']:.2f} | {r['model']:.2f} | "
              f"{r['truth_simulated']:.2f} | {r['tracking']:.1e} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
