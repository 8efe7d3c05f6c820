"""Benchmark: the files dynid writes, read back on every arm of the zoo (issue "The model proven where it goes", the
replay target: "on every config of configs/ and every zoo arm, the MJCF in MuJoCo and the URDF in Pinocchio reproduce
dynid's predicted torques to 1e-6 of the RMS torque where the format can hold the model, and the printed cost
elsewhere is right").

For each arm of the zoo (benchmarks/zoo/zoo.py's ``ARMS``: example-robot-data's vendor URDFs, grippers fixed, the
tracked UR5, the SCARA and the palletiser), the model dynid would export is the vendor file's links made physical (dynid's own ``physical_prior``) plus drive terms of
the zoo's sizes (rotor inertia, Coulomb and viscous friction, and a torque offset, which neither format holds). dynid
writes it as a URDF (``urdf_from_robot``) and an MJCF (``mjcf_from_robot``); Pinocchio's parser and RNEA (plus the
URDF's ``<dynamics>`` friction) and MuJoCo's ``mj_inverse`` (armature, damping, frictionloss) read them back on 200
random states within the joint limits (``urdf_replay``, ``mjcf_replay``). Reported per arm and file: the gap to
dynid's model of what the format holds (target 1e-6), what the format cannot hold and its largest share of a joint's
RMS torque as dynid prints it, and the file's torques against dynid's whole model beside the same figure computed
here from the regressor with the terms the format cannot hold removed, which must agree.

    .venv/bin/python benchmarks/zoo/replay.py [--arms UR5,Panda]
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from zoo import ARMS, arm_text, drives_for  # noqa: E402

TARGET = 1e-6


def arm_model(name: str, folder: Path, rng: np.random.Generator):
    """The zoo arm's robot (drive terms Ia, fc, fv, offset) and the standard parameters dynid would export."""
    from dynid.model.description import robot_from_urdf

    path = folder / "arm.urdf"
    path.write_text(arm_text(name))  # on its track, the SCARA's and the palletiser's own
    robot = robot_from_urdf(path)
    phi = robot.physical_prior()[0].copy()
    drives = drives_for(robot, rng)
    names = list(robot.parameter_names)
    offsets = 0.01 * np.where(np.isfinite(robot.limits.tau_max), robot.limits.tau_max, 50.0) * robot.independent
    for j in range(robot.n_dof):
        for term, value in (("Ia", drives.ia[j]), ("fc", drives.fc[j]), ("fv", drives.fv[j]), ("offset", offsets[j])):
            phi[names.index(f"{term}{j + 1}")] = value
    return robot, phi


NOT_HELD = {"URDF": ("Ia", "offset"), "MJCF": ("offset",)}
"""The drive terms each format cannot hold (rotor inertia: MJCF's armature; a torque offset: neither)."""


def without(robot, phi, terms) -> np.ndarray:
    """``phi`` with the drive terms ``terms`` of every joint set to 0."""
    names = robot.parameter_names
    return np.array([0.0 if n.rstrip("0123456789") in terms else v for n, v in zip(names, phi)])


def run_arm(name: str, folder: Path, seed: int = 0) -> list[dict]:
    from dynid.dynamics.regressor import regressor
    from dynid.io.exported.replay import _states, mjcf_replay, urdf_replay
    from dynid.model.description_files import mjcf_from_robot, urdf_from_robot

    rng = np.random.default_rng(seed)
    robot, phi = arm_model(name, folder, rng)
    states = _states(robot, 200, np.random.default_rng(seed + 1))
    y = regressor(robot, *states)
    full = y @ phi
    rows = []
    for form, write, read in (("URDF", urdf_from_robot, urdf_replay), ("MJCF", mjcf_from_robot, mjcf_replay)):
        check = read(write(robot, phi), robot, phi, states=states, measured=full)  # "measured": dynid's whole model
        held = y @ without(robot, phi, NOT_HELD[form])  # what the file should give, computed here
        expected = 100.0 * float(np.linalg.norm(full - held) / np.linalg.norm(full))
        rows.append(dict(arm=name, form=form, gap=check.relative_error, missing=check.missing,
                         share=float(np.max(check.missing_share)), cost=check.file_vs_measured, expected=expected,
                         n_dof=robot.n_dof))
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arms", default=",".join(ARMS))
    args = parser.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.arms.split(","):
            folder = Path(tmp) / re.sub(r"\W+", "_", name.lower())
            folder.mkdir()
            rows += run_arm(name, folder)
            for r in rows[-2:]:
                print(f"  {r['arm']} {r['form']}: gap {r['gap']:.2e}, not held {', '.join(r['missing'])} "
                      f"(largest share {r['share']:.1f} %), the file against dynid's whole model {r['cost']:.3f} % "
                      f"(computed here without those terms: {r['expected']:.3f} %)", flush=True)
    print("\n| arm | joints | file | gap to what the format holds | not held | largest share of a joint (printed) | "
          "file vs dynid's whole model | the same, computed here |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['arm']} | {r['n_dof']} | {r['form']} | {r['gap']:.1e} | {', '.join(r['missing'])} | "
              f"{r['share']:.1f} % | {r['cost']:.3f} % | {r['expected']:.3f} % |")
    worst = max(r["gap"] for r in rows)
    agree = max(abs(r["cost"] - r["expected"]) for r in rows)
    print(f"\nworst gap {worst:.1e} (target {TARGET:g}): {'met' if worst <= TARGET else 'MISSED'}; the cost computed "
          f"two ways agrees to {agree:.1e} points")
    return 0 if worst <= TARGET else 1


if __name__ == "__main__":
    raise SystemExit(main())
