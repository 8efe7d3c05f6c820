"""The write-back into a user's MJCF whose arm holds a gripper, on the Franka Panda with its fingers (issue "Nothing
runs, nothing silent", item 4's target): the Panda's URDF from example-robot-data (``pip install -e ".[zoo]"``)
compiled by MuJoCo and saved as MJCF, read by dynid with the fingers held, its links written back 10 % heavier; the
written file loaded by MuJoCo and by Pinocchio's MJCF parser, and the 9-joint mass matrix's condition number and the
fingers' masses printed. From the repository root: ``.venv/bin/python benchmarks/zoo/gripper_write_back.py``.
"""

from __future__ import annotations

import re
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(Path(__file__).resolve().parent))


def main() -> int:
    import mujoco
    import pinocchio as pin
    from tests.mujoco_logs import stripped_urdf
    from zoo import robots_folder

    from dynid.io.exported.mjcf_write_back import mjcf_written_back
    from dynid.model.description import load_robot

    text = stripped_urdf((robots_folder() / "panda_description/urdf/panda.urdf").read_text(encoding="utf-8"))
    xml = re.sub(r"(<robot\b[^>]*>)", r'\1<mujoco><compiler discardvisual="true" fusestatic="false" '
                 r'balanceinertia="true"/></mujoco>', text, count=1)
    compiled = mujoco.MjModel.from_xml_string(xml)
    folder = Path(tempfile.mkdtemp())
    path = folder / "panda.xml"
    mujoco.mj_saveLastXML(str(path), compiled)
    held = tuple(compiled.joint(k).name for k in range(compiled.njnt) if "finger" in compiled.joint(k).name)
    robot = load_robot(path, held=held)
    phi = robot.standard_parameters().copy()
    phi[: 10 * robot.n_dof] *= 1.1
    written, _ = mjcf_written_back(path, robot, phi)
    out = folder / "panda_identified.xml"
    out.write_text(written)
    model = mujoco.MjModel.from_xml_path(str(out))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    full = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, full)
    eig = np.linalg.eigvalsh(full)
    print(f"MuJoCo: {model.nv} joints, mass matrix eigenvalues {eig.min():.4g}-{eig.max():.4g} (cond {eig.max() / eig.min():.4g}); "
          f"fingers {', '.join(f'{model.body(model.joint(h).bodyid[0]).mass[0]:.4g} kg' for h in held)}")
    pm = pin.buildModelFromMJCF(str(out))
    mass = pin.crba(pm, pm.createData(), pin.neutral(pm))
    eig = np.linalg.eigvalsh(np.triu(mass) + np.triu(mass, 1).T)
    print(f"Pinocchio (its MJCF parser): {pm.nv} joints, cond {eig.max() / eig.min():.4g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
