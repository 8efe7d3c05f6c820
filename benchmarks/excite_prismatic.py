"""Excitation designs of arms with a prismatic joint, checked at 1 kHz outside dynid's model (issue "Every arm a user
has": "every constraint held on the 1 kHz check, metres and m/s said where they apply").

The tracked arm and the SCARA of ``tests/dynamics/test_prismatic_joints.py`` (a 3-axis arm on a linear track with a
sliding and a turning tool; a SCARA with its quill), each designed by ``dynid excite ROBOT.urdf`` with its defaults
(``--starts 2``). The written trajectory (``excitation.json``) is sampled at 1 kHz over a period and checked against the
URDF's limits as Pinocchio reads them: positions, velocities (m/s on a prismatic joint) and the joint forces and
torques of Pinocchio's RNEA of the same URDF (not dynid's regressor). Prints each design's cond and the smallest share
of a limit left; run from the repository root: ``.venv/bin/python benchmarks/excite_prismatic.py``.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from tests.dynamics.test_prismatic_joints import SCARA, TRACKED  # noqa: E402


def check(name: str, text: str, folder: Path) -> str:
    import pinocchio as pin

    from dynid.excitation.fourier import FourierTrajectory
    from dynid.model.urdf import joints_to_hold

    urdf = folder / f"{name}.urdf"
    urdf.write_text(text)
    out = folder / name
    subprocess.run([sys.executable, "-m", "dynid", "excite", str(urdf), "--out", str(out), "--starts", "2", "-q"],
                   check=True, capture_output=True)
    run = json.loads((out / "excitation.json").read_text())
    tr = run["trajectory"]
    traj = FourierTrajectory(tr["omega_f"], np.array(tr["q0"]), np.array(tr["a"]), np.array(tr["b"]))
    t = np.arange(0.0, traj.period, 1e-3)
    q, dq, ddq = traj.evaluate(t)
    held = joints_to_hold(urdf)
    full = pin.buildModelFromUrdf(str(urdf))
    model = pin.buildReducedModel(full, [full.getJointId(h) for h in held], np.zeros(full.nq))
    data = model.createData()
    tau = np.array([pin.rnea(model, data, q[k], dq[k], ddq[k]) for k in range(t.size)])
    lo, hi = model.lowerPositionLimit, model.upperPositionLimit
    shares = {"position": float(np.min(np.minimum(q - lo, hi - q) / (hi - lo))),
              "velocity": float(np.min(1 - np.abs(dq) / model.velocityLimit)),
              "force/torque (RNEA, links alone)": float(np.min(1 - np.abs(tau) / model.effortLimit))}
    kinds = ["prismatic" if model.joints[j].shortname().startswith("JointModelP") else "revolute"
             for j in range(1, model.njoints)]
    worst = min(shares, key=shares.get)
    held_all = all(v >= 0 for v in shares.values())
    return (f"| {name} | {', '.join(kinds)} | {run['design']['initial_cond']:.4g} → {run['design']['cond']:.4g} | "
            f"{t.size} | {'yes' if held_all else 'NO'} | {worst} {100 * shares[worst]:.1f} % |")


def main() -> None:
    print("| arm | joints | cond (start → design) | samples (1 kHz, a period) | every limit held | tightest (share left) |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name, text in (("tracked", TRACKED), ("scara", SCARA)):
            print(check(name, text, Path(tmp)))


if __name__ == "__main__":
    main()
