"""The zoo: dynid's defaults on public arm descriptions it was never tuned on (issue "Honest on any log").

Arms from the ``example-robot-data`` package (PyPI; ``pip install -e ".[zoo]"``): UR3, UR5, UR10, Franka Panda,
Kinova Jaco 2 (j2s6s200), UFACTORY xArm7, Unitree Z1, SO-100, TALOS's left arm, TIAGo's torso lift and arm (a
prismatic joint first), Baxter's right arm (a two-arm robot: its left arm, head and grippers fixed), Baxter's two arms
as one model (a tree of 14 joints), the UR5 on a 2 m linear track (:func:`on_a_track`), a SCARA (:func:`scara_urdf`)
and a palletiser whose passive joint follows another (a ``<mimic>``: tests/dynamics/test_mimic_joints.py's), their
grippers made fixed joints. A follower is simulated as MuJoCo reads the ``<mimic>`` (a joint equality, made rigid
here), undriven, and the logs hold the driven joints' columns only, as a palletiser's controller logs them.
Each is simulated in MuJoCo (its own URDF parser, not dynid's or Pinocchio's; tests/mujoco_logs.py) under a
joint-space PID loop at 1 kHz, with MuJoCo's armature (rotor inertia) and damping (viscous friction) and, as the dry
friction truth, either MuJoCo's ``frictionloss`` constraint or ``fc·sign(q̇)``; encoder quantisation (20 bits) and
position noise, jittered time stamps with gaps, and torque noise of 1-5 % of each joint's RMS torque. Where a vendor
file's inertia is physically impossible, the simulated truth is its nearest consistent one (a real arm is physical)
while dynid is given the vendor file as it is.

Four identification logs per arm and friction truth, each validated on the same 20 s Fourier log:

* ``excitation``: a 60 s Fourier excitation (5 harmonics of 0.1 Hz, not optimised);
* ``short``: 5 s, with two joints that move one way only;
* ``ptp``: 40 s of point-to-point moves with rests;
* ``dead``: the excitation log with one joint's torque channel reading 0.

Three more classes look like reality (issue "Never worse than the description", item 6; ``--classes
cad,cad-sensor,cad-gear``, with the ``sign`` friction truth only): the simulated arm is the vendor file with every
link's mass, centre of mass and inertia off by 10-40 % (so the description dynid is given is CAD-like, not the truth), the identification log
lasts 5 s (a Fourier excitation of 0.2 Hz), and the logged torques hold what the rigid-body model cannot express: a
torque offset drifting over the log (about 1 % of each joint's RMS torque, another drift on the validation log) and a
cable spring on the first and the second-to-last joint (3 % of their RMS torque). ``cad`` logs the motor-side torque
(rotor inertia and friction included); ``cad-sensor`` the output side of a joint torque sensor (no rotor inertia, no
friction: ``sensor = "joint"`` in the config, which drops the rotor inertia from the drive terms). A third,
``cad-gear``, is ``cad`` with what a geared drive adds and the rigid-body model cannot express either: hysteresis of
the dry friction (Dahl's model with a presliding distance of 2 mrad: after a reversal the friction turns over that
distance instead of at once) and backlash read by a motor-side encoder (the logged angle is the link's plus half a
lash of 1 mrad, 3.4 arcmin, turned over as the torque through the gear crosses ±2 % of the joint's RMS torque); its
drifts and torque noise come from a stream of their own, so that the other two classes' logs do not change. Beside the
truth each is scored against "truth, drive terms from the log": the true links with every joint's drive terms fitted
on the identification log (what the log can determine; the target is dynid within 1.2× of it). A fourth,
``cad-inconsistent`` (issue "The better model wins", item 2), is ``cad`` identified with a careless description
(:func:`inconsistent_urdf`: one link's inertia outside the triangle inequality, another's mass doubled); its target is
the main estimate beating that file's nominal model on the validation log.

Each is identified by ``dynid identify`` with the defaults (a ``[robot]`` table with drive terms Ia, fc, fv,
offset; estimators WLS and SDP) and reports: the main estimate's validation error over the true parameters' on the
same samples (target ≤ 1.2), whether it refused (target: never where anything can be estimated), and the nominal
model's error (target on the short logs: dynid's ≤ the nominal's). Run from the repository root:
``.venv/bin/python benchmarks/zoo/zoo.py [--arms UR5,Panda] [--out DIR]`` (prints a Markdown table and writes
``zoo.json``; about 15 minutes on two cores for the whole zoo).
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))

from tests.mujoco_logs import Drives, coupled, folded, fourier_reference, simulate, stripped_urdf  # noqa: E402

ARMS = {
    # name: (file under example-robot-data's robots folder, the arm's joints: a regular expression)
    "UR3": ("ur_description/urdf/ur3_robot.urdf", r"^(shoulder_pan|shoulder_lift|elbow|wrist_1|wrist_2|wrist_3)_joint$"),
    "UR5": ("ur_description/urdf/ur5_robot.urdf", r"^(shoulder_pan|shoulder_lift|elbow|wrist_1|wrist_2|wrist_3)_joint$"),
    "UR10": ("ur_description/urdf/ur10_robot.urdf", r"^(shoulder_pan|shoulder_lift|elbow|wrist_1|wrist_2|wrist_3)_joint$"),
    "Panda": ("panda_description/urdf/panda.urdf", r"^panda_joint[1-7]$"),
    "Kinova Jaco 2": ("kinova_description/robots/kinova.urdf", r"^j2s6s200_joint_[1-6]$"),
    "xArm7": ("xarm_description/urdf/xarm7.urdf", r"^joint[1-7]$"),
    "Unitree Z1": ("z1_description/urdf/z1.urdf", r"^joint[1-6]$"),
    "SO-100": ("so_arm_description/urdf/so100.urdf", r"^(shoulder_pan|shoulder_lift|elbow_flex|wrist_flex|wrist_roll)$"),
    "TALOS left arm": ("talos_data/robots/talos_left_arm.urdf", r"^arm_left_[2-7]_joint$"),
    "TIAGo torso + arm": ("tiago_description/robots/tiago_no_hand.urdf", r"^(torso_lift_joint|arm_[1-7]_joint)$"),
    "Baxter right arm": ("baxter_description/urdf/baxter.urdf", r"^right_(s0|s1|e0|e1|w0|w1|w2)$"),  # two arms: the left held
    "Baxter both arms": ("baxter_description/urdf/baxter.urdf", r"^(left|right)_(s0|s1|e0|e1|w0|w1|w2)$"),  # a tree
    "UR5 on a track": ("ur_description/urdf/ur5_robot.urdf",
                       r"^(track_joint|shoulder_pan|shoulder_lift|elbow|wrist_1|wrist_2|wrist_3)(_joint)?$"),
    "SCARA": ("", r"^j[1-4]$"),
    "Palletiser": ("", r"^j[1-5]$"),  # j4 follows j3 (<mimic>); the gripper fixed
}
TRACKED = ("UR5 on a track",)
"""Arms put on a linear track here (:func:`on_a_track`): no public description has one."""
CLASSES = ("excitation", "short", "ptp", "dead")
CAD_CLASSES = ("cad", "cad-sensor", "cad-gear", "cad-inconsistent")
"""The realistic classes (module docstring), run with the ``sign`` truth alone."""
TRUTHS = ("frictionloss", "sign")
RATE = 1000.0


def robots_folder() -> Path:
    """example-robot-data's robots (installed by the ``zoo`` extra)."""
    import importlib.util

    spec = importlib.util.find_spec("cmeel")
    roots = [Path(p) for p in sys.path if p.endswith("site-packages")]
    for root in roots:
        folder = root / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if folder.is_dir():
            return folder
    raise SystemExit("example-robot-data is not installed: pip install -e '.[zoo]'" + ("" if spec else " (no cmeel)"))


def on_a_track(text: str) -> str:
    """The URDF with its arm on a 2 m linear track along x: a prismatic joint ``track_joint`` from the root link to a
    25 kg carriage, which carries what the root carried (an industrial track's)."""
    root = ET.fromstring(text)
    joints = root.findall("joint")  # not a <transmission>'s joints
    children = {j.find("child").get("link") for j in joints}
    base = next(link for link in root.findall("link") if link.get("name") not in children).get("name")
    for joint in joints:
        if joint.find("parent").get("link") == base:
            joint.find("parent").set("link", "carriage")
    carriage = ET.SubElement(root, "link", name="carriage")
    inertial = ET.SubElement(carriage, "inertial")
    ET.SubElement(inertial, "origin", xyz="0 0 -0.05", rpy="0 0 0")
    ET.SubElement(inertial, "mass", value="25")
    ET.SubElement(inertial, "inertia", ixx="0.6", ixy="0", ixz="0", iyy="0.9", iyz="0", izz="1.2")
    track = ET.SubElement(root, "joint", name="track_joint", type="prismatic")
    ET.SubElement(track, "parent", link=base)
    ET.SubElement(track, "child", link="carriage")
    ET.SubElement(track, "origin", xyz="0 0 0.3", rpy="0 0 0")
    ET.SubElement(track, "axis", xyz="1 0 0")
    ET.SubElement(track, "limit", lower="0", upper="2", effort="2000", velocity="1.5")
    return ET.tostring(root, encoding="unicode")


def scara_urdf() -> str:
    """A SCARA (issue "Every arm a user has", item 4): two revolute axes about the vertical (arms of 0.325 and 0.275 m),
    a quill sliding 0.2 m down and a turning tool; each link a solid box of its size and mass (6, 4, 1 and 0.3 kg), so
    its inertia is a real one. example-robot-data has no SCARA, and no public SCARA description was found: this is an
    arm of a common small SCARA's proportions, not a vendor's."""
    def link(name, mass, size, com):
        a, b, c = size
        ixx, iyy, izz = (mass * (b * b + c * c) / 12, mass * (a * a + c * c) / 12, mass * (a * a + b * b) / 12)
        return (f'<link name="{name}"><inertial><origin xyz="{com}" rpy="0 0 0"/><mass value="{mass}"/><inertia '
                f'ixx="{ixx!r}" ixy="0" ixz="0" iyy="{iyy!r}" iyz="0" izz="{izz!r}"/></inertial></link>')

    def joint(name, kind, parent, child, xyz, axis, lower, upper, velocity):
        return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/><origin xyz="{xyz}" '
                f'rpy="0 0 0"/><axis xyz="{axis}"/><limit lower="{lower}" upper="{upper}" effort="400" '
                f'velocity="{velocity}"/></joint>')

    return ('<robot name="scara"><link name="base"/>'
            + link("arm1", 6.0, (0.42, 0.12, 0.1), "0.16 0 0.05") + link("arm2", 4.0, (0.36, 0.1, 0.15), "0.14 0 0.02")
            + link("quill", 1.0, (0.03, 0.03, 0.35), "0 0 -0.1") + link("tool", 0.3, (0.06, 0.06, 0.05), "0 0.01 -0.02")
            + joint("j1", "revolute", "base", "arm1", "0 0 0.4", "0 0 1", -2.6, 2.6, 7.0)
            + joint("j2", "revolute", "arm1", "arm2", "0.325 0 0", "0 0 1", -2.5, 2.5, 7.0)
            + joint("j3", "prismatic", "arm2", "quill", "0.275 0 0", "0 0 -1", 0.0, 0.2, 1.0)
            + joint("j4", "revolute", "quill", "tool", "0 0 -0.25", "0 0 1", -3.14, 3.14, 12.0) + "</robot>")


def arm_text(name: str) -> str:
    """The arm's URDF as :data:`ARMS` names it (on a track for :data:`TRACKED`; :func:`scara_urdf` for the SCARA), its
    other joints fixed."""
    file, keep = ARMS[name]
    if name == "Palletiser":
        from tests.dynamics.test_mimic_joints import PALLETISER as text
    else:
        text = scara_urdf() if name == "SCARA" else (robots_folder() / file).read_text(encoding="utf-8")
    return arm_urdf(on_a_track(text) if name in TRACKED else text, keep)


def arm_urdf(text: str, keep: str) -> str:
    """The URDF with every movable joint but the arm's made fixed (grippers, fingers), no visuals or collisions."""
    root = ET.fromstring(stripped_urdf(text))
    for joint in root.iter("joint"):
        if joint.get("type") in ("revolute", "continuous", "prismatic") and not re.search(keep, joint.get("name", "")):
            joint.set("type", "fixed")
            for child in list(joint):
                if child.tag in ("mimic", "limit", "dynamics", "axis", "safety_controller"):
                    joint.remove(child)
    return ET.tostring(root, encoding="unicode")


def physical_urdf(text: str) -> tuple[str, list[str]]:
    """The URDF with each link's inertia about its centre of mass made physical where it is not (its principal
    moments raised to meet the triangle inequality and a small floor), and the links so changed."""
    root = ET.fromstring(text)
    changed = []
    for link in root.iter("link"):
        inertia = link.find("inertial/inertia")
        mass = link.find("inertial/mass")
        if inertia is None or mass is None:
            continue
        k = {a: float(inertia.get(a, 0.0)) for a in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
        m = np.array([[k["ixx"], k["ixy"], k["ixz"]], [k["ixy"], k["iyy"], k["iyz"]], [k["ixz"], k["iyz"], k["izz"]]])
        ev, vec = np.linalg.eigh(m)
        floor = max(1e-6 * float(mass.get("value", 1.0)), 1e-9)
        fixed = np.maximum(ev, floor)
        for _ in range(3):  # each principal moment at most the sum of the other two
            fixed = np.minimum(fixed, fixed.sum() - fixed)
            fixed = np.maximum(fixed, floor)
        if np.allclose(fixed, ev, rtol=1e-9, atol=1e-12):
            continue
        changed.append(link.get("name"))
        new = (vec * fixed) @ vec.T
        for a, (i, j) in zip(("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))):
            inertia.set(a, repr(float(new[i, j])))
    return ET.tostring(root, encoding="unicode"), changed


def drives_for(robot, rng) -> Drives:
    """Rotor inertia, viscous and dry friction of a size industrial drives have, from the joints' torque limits; none
    on a joint that follows another (it has no drive)."""
    tau = np.where(np.isfinite(robot.limits.tau_max), robot.limits.tau_max, 50.0) * robot.independent
    return Drives(ia=0.0002 * tau * rng.uniform(0.5, 1.5, tau.size), fv=0.01 * tau * rng.uniform(0.5, 1.5, tau.size),
                  fc=0.02 * tau * rng.uniform(0.7, 1.3, tau.size))


def one_way(moving: tuple[int, ...]):
    """A Fourier reference in which joints ``moving`` drift one way only (a steady ramp and a slow swing)."""

    def reference(t, n, rng, amplitude, centre):
        q, dq, ddq = fourier_reference(t, n, rng, 0.2, 4, amplitude, centre)
        span = t[-1] - t[0]
        for j in moving:
            speed = 1.2 * amplitude[j] / span * (1 if j % 2 else -1)
            q[:, j] = centre[j] - 0.6 * speed * span + speed * t + 0.1 * amplitude[j] * np.sin(0.9 * t)
            dq[:, j] = speed + 0.09 * amplitude[j] * np.cos(0.9 * t)
            ddq[:, j] = -0.081 * amplitude[j] * np.sin(0.9 * t)
        return q, dq, ddq

    return reference


def write_log(path: Path, log, rng, logged=slice(None)) -> None:
    """time, positions, torques with 1-5 % of each joint's RMS torque as noise; the columns of the joints ``logged``
    (the driven ones: a follower's are not in a robot's log)."""
    rms = np.sqrt(np.mean(log.tau**2, axis=0))
    tau = log.tau + rng.normal(size=log.tau.shape) * rms * rng.uniform(0.01, 0.05, rms.size)
    np.savetxt(path, np.column_stack([log.t, log.q_meas[:, logged], tau[:, logged]]), delimiter=",", fmt="%.10g")


LOG_FITTED = "truth, one-way drive terms from the log"
"""The short class's second reference: the true parameters with each one-way joint's rotor inertia, Coulomb and viscous
friction refitted on the short log (:func:`log_fitted_drive_terms`)."""


DRIVE_FITTED = "truth, drive terms from the log"
"""The realistic classes' second reference: the true links with every joint's drive terms fitted on the
identification log (:func:`log_fitted_drive_terms` with ``every_joint``)."""


def cad_urdf(text: str, rng) -> str:
    """The URDF with every link's mass, centre of mass and inertia off by 10-40 % (each a random sign): a CAD model's
    error, the result still physical (the inertia about the centre of mass scaled as a whole)."""
    root = ET.fromstring(text)
    off = lambda: float(1.0 + rng.choice((-1.0, 1.0)) * rng.uniform(0.1, 0.4))  # noqa: E731
    for inertial in root.iter("inertial"):
        mass, inertia, origin = inertial.find("mass"), inertial.find("inertia"), inertial.find("origin")
        if mass is not None:
            mass.set("value", repr(float(mass.get("value", 0.0)) * off()))
        if inertia is not None:
            factor = off()
            for a in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
                inertia.set(a, repr(float(inertia.get(a, 0.0)) * factor))
        if origin is not None:
            xyz = np.array([float(x) for x in origin.get("xyz", "0 0 0").split()])
            size = max(float(np.linalg.norm(xyz)), 0.02)  # a centre of mass on the axis still moves by a few cm
            xyz = xyz + rng.normal(size=3) / np.sqrt(3) * size * rng.uniform(0.1, 0.4)
            origin.set("xyz", " ".join(repr(float(x)) for x in xyz))
    return ET.tostring(root, encoding="unicode")


def inconsistent_urdf(text: str) -> tuple[str, list[str]]:
    """The vendor file as a careless CAD export leaves it (``cad-inconsistent``, issue "The better model wins", item 2):
    the second moving link's inertia outside the triangle inequality (its ``ixx`` 1.2 times ``iyy + izz``, no mass
    distribution has that) and the third's mass doubled. Returns the text and what was changed, one line each."""
    root = ET.fromstring(text)
    links = {link.get("name"): link for link in root.iter("link")}
    moving = [j.find("child").get("link") for j in root.iter("joint")
              if j.get("type") in ("revolute", "continuous", "prismatic") and j.find("child") is not None]
    said = []
    for k, link in enumerate(links.get(name) for name in moving[1:3]):
        inertial = None if link is None else link.find("inertial")
        if inertial is None:
            continue
        if k == 0 and inertial.find("inertia") is not None:
            inertia = inertial.find("inertia")
            iyy, izz = float(inertia.get("iyy", 0.0)), float(inertia.get("izz", 0.0))
            inertia.set("ixx", repr(1.2 * (iyy + izz) + 1e-4))
            said.append(f"{link.get('name')}: ixx {inertia.get('ixx')} > iyy + izz")
        elif k == 1 and inertial.find("mass") is not None:
            mass = inertial.find("mass")
            mass.set("value", repr(2.0 * float(mass.get("value", 0.0))))
            said.append(f"{link.get('name')}: mass doubled")
    return ET.tostring(root, encoding="unicode"), said


def measured_side(log, drives, sensor: bool) -> np.ndarray:
    """The torque a log holds: the motor side (the simulated command) or, with ``sensor``, a joint torque sensor's
    output side (the command less the rotor's inertia torque and the friction, with the ``sign`` truth's exact dry
    friction)."""
    if not sensor:
        return log.tau
    return log.tau - drives.ia * log.ddq - drives.fv * log.dq - drives.fc * np.sign(log.dq)


def unmodelled(log, drives, rng, sensor: bool, spring: tuple) -> np.ndarray:
    """A realistic log's torques (module docstring): :func:`measured_side` plus a torque offset drifting over the log
    (each joint's start and drift about 1 % of ``rms``) and the cable spring ``k·(q − q₀)``, ``spring = (rms, k, q₀)``
    from the validation log (:func:`cable_spring`): one physical spring on every log."""
    rms, k, q0 = spring
    n = log.tau.shape[1]
    ramp = (log.t[:, None] - log.t[0]) / (log.t[-1] - log.t[0])
    drift = 0.01 * rms * (rng.normal(size=n) + rng.normal(size=n) * ramp)
    return measured_side(log, drives, sensor) + drift + k * (log.q - q0)


PRESLIDING, BACKLASH, LASH_BAND = 0.002, 0.001, 0.02
"""``cad-gear``'s geared drive (module docstring): Dahl's presliding distance [rad], the gear's lash [rad] and the torque
band, a share of each joint's RMS torque, over which the lash turns over."""


def dahl_direction(q: np.ndarray, x0: float) -> np.ndarray:
    """The state ``z`` of Dahl's friction model (α = 1) along the true positions: ``dz/ds = (σ − z)/x₀`` over the
    distance ``s`` travelled in the direction ``σ``, so that ``z = σ + (z₀ − σ)·exp(−Δs/x₀)`` from sample to sample
    (P. R. Dahl 1968); written here, not dynid's, so that the simulated truth does not borrow dynid's model."""
    z = np.zeros_like(q)
    step = np.diff(q, axis=0)
    for k in range(1, q.shape[0]):
        sigma = np.sign(step[k - 1])
        z[k] = np.where(sigma != 0, sigma + (z[k - 1] - sigma) * np.exp(-np.abs(step[k - 1]) / x0), z[k - 1])
    return z


def geared(log, drives, spring: tuple):
    """``cad-gear``'s log (module docstring): the dry friction's ``fc·sign(q̇)`` in the command replaced by Dahl's
    ``fc·z``, and the logged angles those of a motor-side encoder across a backlash."""
    rms = spring[0]
    tau = log.tau + drives.fc * (dahl_direction(log.q, PRESLIDING) - np.sign(log.dq))
    through = tau - drives.ia * log.ddq  # the torque the gear carries to the link
    lash = 0.5 * BACKLASH * np.tanh(through / np.maximum(LASH_BAND * rms, 1e-9))
    return replace(log, tau=tau, q_meas=log.q_meas + lash)


def cable_spring(valid, drives, sensor: bool, driven: np.ndarray) -> tuple:
    """``(rms, k, q₀)``: each joint's RMS torque on the validation log, a cable spring on the first and the
    second-to-last of the ``driven`` joints whose torque has 3 % of that RMS over the validation motion, and its rest
    angle (the motion's mean)."""
    tau = measured_side(valid, drives, sensor)
    rms = np.sqrt(np.mean(tau**2, axis=0))
    k = np.zeros(tau.shape[1])
    sprung = [driven[0], driven[-2]]
    k[sprung] = 0.03 * rms[sprung] / np.maximum(np.std(valid.q, axis=0)[sprung], 1e-6)
    return rms, k, np.mean(valid.q, axis=0)


def run_cad(name: str, out: Path, seed: int, classes) -> list[dict]:
    """The realistic classes of one arm (module docstring), with the ``sign`` dry-friction truth."""
    from dynid.model.description import load_robot

    text = arm_text(name)
    physical, repaired = physical_urdf(text)
    folder = out / re.sub(r"\W+", "_", name.lower()) / "cad"
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng([seed, 7])  # its own stream: the other classes' logs do not change
    truth_text = cad_urdf(physical, rng)
    (folder / "arm.urdf").write_text(text)  # the vendor file: the description dynid is given
    (folder / "truth.urdf").write_text(truth_text)
    careless, changed = inconsistent_urdf(text)
    (folder / "arm_inconsistent.urdf").write_text(careless)
    robot, truth_robot = load_robot(str(folder / "arm.urdf")), load_robot(str(folder / "truth.urdf"))
    n, driven = robot.n_dof, np.flatnonzero(robot.independent)
    drives = drives_for(robot, rng)
    lo, hi = np.maximum(robot.limits.q_min, -np.pi), np.minimum(robot.limits.q_max, np.pi)
    common = dict(rate=RATE, dry="sign", centre=(lo + hi) / 2, amplitude=np.minimum(0.6, 0.35 * (hi - lo)),
                  torque_std=0.0, noise_share=0.02)
    t0 = time.perf_counter()
    valid = simulate(truth_text, drives, "fourier", 20.0, rng, f0=0.15, harmonics=5, **common)
    ident = simulate(truth_text, drives, "fourier", 5.0, rng, f0=0.2, harmonics=4, **common)
    simulated = time.perf_counter() - t0
    names = [f"{t}{j + 1}" for j in range(n) for t in ("XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M",
                                                              "Ia", "fc", "fv", "offset")]
    phi = truth_robot.standard_parameters().reshape(n, -1)[:, :10]
    rows = []
    for kind in CAD_CLASSES:  # every class's logs, in one order: the noise each draws does not hang on --classes
        sensor = kind == "cad-sensor"
        stem = kind.replace("-", "_")
        spring = cable_spring(valid, drives, sensor, driven)
        noise = np.random.default_rng([seed, 7, 3]) if kind == "cad-gear" else rng  # its own stream (module docstring)
        for label, log in (("valid", valid), ("ident", ident)):
            log = geared(log, drives, spring) if kind == "cad-gear" else log
            noisy = replace(log, tau=unmodelled(log, drives, noise, sensor, spring))
            write_log(folder / f"{stem}_{label}.csv", noisy, noise, driven)
        if kind not in classes:
            continue
        drive = np.zeros((n, 4)) if sensor else np.column_stack([drives.ia, drives.fc, drives.fv, np.zeros(n)])
        values = np.concatenate([phi, drive], axis=1).ravel()
        (folder / f"{stem}_truth.csv").write_text("name,value\n" + "".join(f"{k},{v:.12g}\n" for k, v in zip(names, values)))
        terms = ("fc", "fv", "offset") if sensor else ("Ia", "fc", "fv", "offset")
        fitted = log_fitted_drive_terms(folder, f"{stem}_ident.csv", every_joint=True, terms=terms)
        (folder / f"{stem}_fitted.csv").write_text("name,value\n" + "".join(
            f"{k},{fitted.get(k, v):.12g}\n" for k, v in zip(names, values)))
        extra = (f'[[references]]\nname = "{DRIVE_FITTED}"\nfile = "{stem}_fitted.csv"\nformat = "standard"\n'
                 'header = true\nnames = "name"\nvalues = "value"\n')
        cfg = config(folder, driven.size, f"{stem}_ident.csv", extra, valid=f"{stem}_valid.csv",
                     truth=f"{stem}_truth.csv", sensor=sensor,
                     urdf="arm_inconsistent.urdf" if kind == "cad-inconsistent" else "arm.urdf")
        rows.append(identify_cell(cfg, folder, kind, {"arm": name, "joints": driven.size, "truth": "sign", "class": kind,
                                                      "repaired_links": repaired, "simulation_seconds": simulated,
                                                      **({"file_changed": changed} if kind == "cad-inconsistent" else {})}))
    return rows


def log_fitted_drive_terms(folder: Path, log: str, cutoff: float = 10.0, trim: float = 0.3, *, urdf: str = "truth.urdf",
                           every_joint: bool = False, terms: tuple[str, ...] = ("Ia", "fc", "fv")) -> dict[str, float]:
    """The drive terms (Ia, fc, fv) of each joint that moves one way only in ``log``, fitted joint by joint on that log
    with the TRUE links: ``τ_j - RNEA_j(q, q̇, q̈) = Ia·q̈_j + fc·sign(q̇_j) + fv·q̇_j`` by least squares, outside dynid
    (Pinocchio's RNEA on truth.urdf, a 4th-order zero-phase Butterworth at ``cutoff`` Hz on the positions and torques,
    central differences, ``trim`` s left out at each end). Where this set fits the log as well as the truth and predicts
    the validation log worse, the log does not tell the two apart: no estimator that reads only that log can be
    expected to reach the truth's validation error. ``every_joint``: every joint's ``terms`` (``offset`` among them: a
    column of ones), with the links of ``urdf``."""
    import pinocchio as pin
    from scipy.signal import butter, sosfiltfilt

    model = pin.buildModelFromUrdf(str(folder / urdf))  # a <mimic> joint a free joint of its own
    data = model.createData()
    x = np.loadtxt(folder / log, delimiter=",")
    coupling = mimic_dofs(model, (folder / urdf).read_text())
    driven = [k for k in range(model.nv) if k not in {f for f, *_ in coupling}]
    n = len(driven)  # the log's joints: the driven ones
    t = np.arange(x[0, 0], x[-1, 0], 1.0 / RATE)
    q = np.column_stack([np.interp(t, x[:, 0], x[:, 1 + k]) for k in range(n)])
    tau = np.column_stack([np.interp(t, x[:, 0], x[:, 1 + n + k]) for k in range(n)])
    sos = butter(4, cutoff, fs=RATE, output="sos")
    q, tau = sosfiltfilt(sos, q, axis=0), sosfiltfilt(sos, tau, axis=0)
    dq = np.gradient(q, t, axis=0)
    ddq = np.gradient(dq, t, axis=0)
    keep = slice(int(trim * RATE), t.size - int(trim * RATE))
    every = [np.zeros((t.size, model.nv)) for _ in range(3)]  # every joint's, the followers' from their masters'
    for whole, logged in zip(every, (q, dq, ddq)):
        whole[:, driven] = logged
    q_all, dq_all, ddq_all = coupled(tuple(every), coupling)

    def configuration(angles):  # a continuous joint's configuration is (cos, sin) in Pinocchio
        x = np.empty(model.nq)
        for k, joint in enumerate(model.joints[1:]):
            x[joint.idx_q:joint.idx_q + joint.nq] = (np.cos(angles[k]), np.sin(angles[k]))[:joint.nq] if joint.nq == 2 \
                else angles[k]
        return x

    rigid = folded(np.array([pin.rnea(model, data, configuration(q_all[i]), dq_all[i], ddq_all[i])
                             for i in range(keep.start, keep.stop)]), coupling)[:, driven]
    out = {}
    for col, j in enumerate(driven):
        v, a = dq[keep, col], ddq[keep, col]
        if not every_joint and min(np.mean(v > 0.01), np.mean(v < -0.01)) >= 0.01:  # it reverses: not one-way
            continue
        columns = {"Ia": a, "fc": np.sign(v), "fv": v, "offset": np.ones_like(v)}
        coef = np.linalg.lstsq(np.column_stack([columns[k] for k in terms]), tau[keep, col] - rigid[:, col], rcond=None)[0]
        out.update({f"{k}{j + 1}": float(c) for k, c in zip(terms, coef)})
    return out


def mimic_dofs(model, text: str) -> list[tuple[int, int, float, float]]:
    """The URDF's ``<mimic>`` joints as ``(follower, master, multiplier, offset)`` velocity indices of Pinocchio's
    ``model`` (read from the file here, not by dynid)."""
    found = []
    for joint in ET.fromstring(text).iter("joint"):
        mimic = joint.find("mimic")
        if mimic is not None and model.existJointName(joint.get("name")):
            index = lambda name: model.joints[model.getJointId(name)].idx_v  # noqa: E731
            found.append((index(joint.get("name")), index(mimic.get("joint")), float(mimic.get("multiplier", 1.0)),
                          float(mimic.get("offset", 0.0))))
    return found


CHOICE: list[str] = []
"""``--choice``: the ``[estimation] choice`` every config is written with (none: dynid's default)."""


def config(folder: Path, n: int, ident: str, extra: str = "", valid: str = "valid.csv", truth: str = "truth.csv",
           sensor: bool = False, urdf: str = "arm.urdf") -> Path:
    cols = lambda a: "[" + ", ".join(str(a + j) for j in range(n)) + "]"  # noqa: E731
    side = ', sensor = "joint"' if sensor else ""
    table = (lambda f: f'file = "{f}"\ntime = {{ column = 1 }}\npositions = {{ columns = {cols(2)} }}\n'
             f'torques = {{ columns = {cols(2 + n)}{side} }}\n')
    text = (f'data_root = "."\n[robot]\nurdf = "{urdf}"\ndrive_terms = ["Ia", "fc", "fv", "offset"]\n'
            f'[identification]\n{table(ident)}[estimation]\nestimators = ["wls", "sdp"]\n'
            + (f'choice = "{CHOICE[0]}"\n' if CHOICE else "") +
            f'[[validation]]\nname = "validation"\n{table(valid)}'
            f'[[references]]\nname = "truth"\nfile = "{truth}"\nformat = "standard"\nheader = true\nnames = "name"\n'
            'values = "value"\n[[references]]\nname = "nominal"\nformat = "nominal"\n' + extra)
    path = folder / f"{ident.removesuffix('.csv')}.toml"
    path.write_text(text)
    return path


def run_arm(name: str, out: Path, seed: int, classes=CLASSES) -> list[dict]:
    """Every friction truth and log class of one arm (module docstring)."""
    from dynid.model.description import load_robot

    text = arm_text(name)
    truth_text, repaired = physical_urdf(text)
    rows = []
    for truth_kind in TRUTHS:
        folder = out / re.sub(r"\W+", "_", name.lower()) / truth_kind
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "arm.urdf").write_text(text)  # the vendor file, as a user has it
        (folder / "truth.urdf").write_text(truth_text)
        rng = np.random.default_rng(seed)
        robot = load_robot(str(folder / "arm.urdf"))
        truth_robot = load_robot(str(folder / "truth.urdf"))
        n, driven = robot.n_dof, np.flatnonzero(robot.independent)
        drives = drives_for(robot, rng)
        lo, hi = np.maximum(robot.limits.q_min, -np.pi), np.minimum(robot.limits.q_max, np.pi)
        centre, amplitude = (lo + hi) / 2, np.minimum(0.6, 0.35 * (hi - lo))
        phi = truth_robot.standard_parameters().reshape(n, -1)[:, :10]
        drive = np.column_stack([drives.ia, drives.fc, drives.fv, np.zeros(n)])
        names = [f"{t}{j + 1}" for j in range(n) for t in ("XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M",
                                                                  "Ia", "fc", "fv", "offset")]
        values = np.concatenate([phi, drive], axis=1).ravel()
        (folder / "truth.csv").write_text("name,value\n" + "".join(f"{k},{v:.12g}\n" for k, v in zip(names, values)))
        common = dict(rate=RATE, dry=truth_kind, centre=centre, amplitude=amplitude, torque_std=0.0, noise_share=0.02)
        t0 = time.perf_counter()
        logs = {"valid": simulate(truth_text, drives, "fourier", 20.0, rng, f0=0.15, harmonics=5, **common),
                "excitation": simulate(truth_text, drives, "fourier", 60.0, rng, f0=0.1, harmonics=5, **common),
                "short": simulate(truth_text, drives, "fourier", 5.0, rng, reference=one_way((driven[1], driven[-2])),
                                  **common),
                "ptp": simulate(truth_text, drives, "ptp", 40.0, rng, **common)}
        simulated = time.perf_counter() - t0
        for key, log in logs.items():
            write_log(folder / f"{key}.csv", log, rng, driven)
        dead = np.loadtxt(folder / "excitation.csv", delimiter=",")
        dead[:, 1 + driven.size + driven.size // 2] = 0.0
        np.savetxt(folder / "dead.csv", dead, delimiter=",", fmt="%.10g")
        for kind in classes:
            extra = ""
            if kind == "short":
                fitted = log_fitted_drive_terms(folder, "short.csv")
                (folder / "short_fitted.csv").write_text("name,value\n" + "".join(
                    f"{k},{fitted.get(k, v):.12g}\n" for k, v in zip(names, values)))
                extra = (f'[[references]]\nname = "{LOG_FITTED}"\nfile = "short_fitted.csv"\nformat = "standard"\n'
                         'header = true\nnames = "name"\nvalues = "value"\n')
            cfg = config(folder, driven.size, f"{kind}.csv", extra)
            rows.append(identify_cell(cfg, folder, kind, {"arm": name, "joints": driven.size, "truth": truth_kind, "class": kind,
                                                          "repaired_links": repaired, "simulation_seconds": simulated,
                                                          "driven": driven.tolist()}))
    return rows


def identify_cell(cfg: Path, folder: Path, kind: str, row: dict) -> dict:
    """``dynid identify`` on one cell's config, its row of the table: the main estimate's validation error over the
    truth's, the nominal model's, and what the log cannot tell (the log-fitted reference, where the config has one)."""
    driven = row.get("driven", list(range(row["joints"])))  # the joints the log holds (not a follower)
    t1 = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "dynid", "identify", str(cfg), "--out", str(folder / f"out-{kind}"),
                        "--no-figures", "-q"], capture_output=True, text=True, timeout=1800)
    row = {**row, "seconds": time.perf_counter() - t1}
    if p.returncode != 0:
        row.update(refused=True, message=(p.stderr.strip().splitlines() or [""])[-1])
    else:
        r = json.loads((folder / f"out-{kind}" / "results.json").read_text())
        v = r["validation"][0]
        main = r["main_estimate"]
        err = {k: m["global_relative_error"] for k, m in v["metrics"].items()}
        if kind == "dead":  # the dead joint's own drive terms are in no live row: over the other joints too
            live = [j for j in driven if j != driven[len(driven) // 2]]
            rms = np.asarray(v["rms_torque"], dtype=float)[live]

            def over_live(label):
                e = np.asarray(v["metrics"][label]["relative_error"], dtype=float)[live]
                return float(np.sqrt(np.sum((e * rms) ** 2) / np.sum(rms**2)))

            row["live_ratio"] = over_live(main) / over_live("truth")
        fitted = next((k for k in (LOG_FITTED, DRIVE_FITTED) if k in v["metrics"]), None)
        if fitted is not None:  # what the log cannot tell from the truth (log_fitted_drive_terms)
            fit = r["identification"]["metrics"]
            row.update(fitted_fit=fit[fitted]["global_relative_error"],
                       truth_fit=fit["truth"]["global_relative_error"],
                       fitted_validation=v["metrics"][fitted]["global_relative_error"])
        from dynid.io.results import stored_standard

        exported = (stored_standard(r) or (main,))[0]  # what the written URDF and MJCF hold (dynid export's choice)
        row.update(refused=False, main=main, estimate=err[main], truth_error=err["truth"], nominal=err["nominal"],
                   exported=exported, exported_estimate=err.get(exported, float("nan")),
                   ratio=err[main] / err["truth"] if err["truth"] > 0 else float("nan"),
                   floor=(v.get("noise_floor") or {}).get("global_relative_error"),
                   from_prior=r["diagnostics"].get("from_prior", []),
                   findings=[f["kind"] for f in r["findings"]], readiness=r.get("readiness", ""))
    print(json.dumps({k: row[k] for k in row if k not in ("findings", "from_prior", "repaired_links", "driven")}), flush=True)
    return row


MISREAD_KINDS = ("sign", "columns", "order", "angles", "rate", "gravity", "scale")
"""The verdict's findings that say a log was read wrongly (:func:`dynid.report.summaries.readiness`'s first reasons):
on the zoo's logs, all read right, each is a false alarm (issue "Every assurance checked on what the user meets",
item 2). The ``dead`` class's silent channel is a real fault, not counted; so are torques that are mostly spikes (a
simulation chattering: the finding "spikes", said apart) and torques that no fit follows beyond their noise (the
finding "unexplained", said apart)."""


def false_alarms(rows: list[dict]) -> str:
    """The line that counts the cells whose log, read right, got a misread finding (:data:`MISREAD_KINDS`)."""
    cells = [r for r in rows if not r["refused"] and r["class"] != "dead"]
    alarmed = [f"{r['arm']} {r.get('truth', '')} {r['class']}: {', '.join(k for k in r['findings'] if k in MISREAD_KINDS)}"
               for r in cells if set(r["findings"]) & set(MISREAD_KINDS)]
    ready = sum(r.get("readiness", "").startswith("model ready") for r in cells)
    apart = {kind: [f"{r['arm']} {r.get('truth', '')} {r['class']}" for r in cells if kind in r["findings"]]
             for kind in ("spikes", "unexplained")}
    said = {"spikes": "torques that are mostly spikes", "unexplained": "torques that no fit follows beyond their noise"}
    return (f"misread findings on logs read right: {len(alarmed)} of {len(cells)} cells"
            f"{' (' + '; '.join(alarmed) + ')' if alarmed else ''}; \"model ready\" on {ready} of them"
            + "".join(f"; {said[k]} (not ready, not counted as misread): {'; '.join(v)}" for k, v in apart.items() if v))


def table(rows: list[dict]) -> str:
    """The Markdown table of benchmarks/README.md: one row per arm and friction truth, a column per log class."""
    head = ("| arm | dry friction | " + " | ".join(CLASSES) + " |\n|---|---|" + "---|" * len(CLASSES))
    lines = [head]
    for arm in dict.fromkeys(r["arm"] for r in rows):
        for truth in TRUTHS:
            cells = []
            for kind in CLASSES:
                r = next((x for x in rows if x["arm"] == arm and x["truth"] == truth and x["class"] == kind), None)
                if r is None:
                    cells.append("-")
                elif r["refused"]:
                    cells.append("refused")
                else:
                    live = f"; live joints {r['live_ratio']:.2f}×" if "live_ratio" in r else ""
                    files = (f"; files: {r['exported']} {r['exported_estimate'] / r['truth_error']:.2f}×"
                             if r.get("exported", r["main"]) != r["main"] else "")
                    cells.append(f"{r['ratio']:.2f}× ({r['estimate']:.3g} / {r['truth_error']:.3g} %; nominal "
                                 f"{r['nominal']:.3g} %{live}{files})")
            lines.append(f"| {arm} | {truth} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def short_table(rows: list[dict]) -> str:
    """The short logs beside what they cannot tell from the truth: the log-fitted set's error on the identification
    log and on the validation log, each over the truth's (:func:`log_fitted_drive_terms`)."""
    lines = ["| arm | dry friction | dynid / truth (validation) | log-fitted / truth, identification log | "
             "log-fitted / truth, validation |", "|---|---|---|---|---|"]
    for r in rows:
        if r["class"] == "short" and not r["refused"] and "fitted_fit" in r:
            lines.append(f"| {r['arm']} | {r['truth']} | {r['ratio']:.2f}× | {r['fitted_fit'] / r['truth_fit']:.3f}× "
                         f"({r['fitted_fit']:.3g} / {r['truth_fit']:.3g} %) | {r['fitted_validation'] / r['truth_error']:.2f}× "
                         f"({r['fitted_validation']:.3g} / {r['truth_error']:.3g} %) |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arms", default=",".join(ARMS), help="comma-separated names of ARMS")
    parser.add_argument("--out", default=str(REPO / "dynid-zoo"), help="working folder (logs, configs, results)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--classes", default=",".join(CLASSES), help="comma-separated log classes to identify (every "
                        "class is simulated all the same, so a cell's log does not depend on this)")
    parser.add_argument("--choice", choices=("torques", "states"), default=None,
                        help="[estimation] choice of every config (default: not written, dynid's default)")
    args = parser.parse_args(argv)
    CHOICE[:] = [args.choice] if args.choice else []
    out = Path(args.out)
    rows = []
    classes = tuple(c.strip() for c in args.classes.split(",") if c.strip())
    for name in [a.strip() for a in args.arms.split(",") if a.strip()]:
        if set(classes) & set(CLASSES):
            rows += run_arm(name, out, args.seed, tuple(c for c in classes if c in CLASSES))
        if set(classes) & set(CAD_CLASSES):
            rows += run_cad(name, out, args.seed, classes)
    out.mkdir(parents=True, exist_ok=True)
    (out / "zoo.json").write_text(json.dumps(rows, indent=1))
    print(table([r for r in rows if r["class"] in CLASSES]))
    print()
    print(short_table(rows))
    print()
    print(cad_table(rows))
    print()
    print(false_alarms(rows))
    return 0


def cad_table(rows: list[dict]) -> str:
    """The realistic classes: the main estimate against the truth, against the log-fitted set (target ≤ 1.2) and
    against the description's nominal model (target ≤ 1.02), each on the validation log; where the files dynid writes
    hold another estimate (a main least-squares estimate has no standard parameters: export writes the SDP's), that
    one's error and ratios after a slash."""
    lines = ["| arm | class | main estimate | its error % | truth % | log-fitted % | nominal % | × log-fitted | × nominal |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["class"] not in CAD_CLASSES:
            continue
        if r["refused"]:
            lines.append(f"| {r['arm']} | {r['class']} | refused: {r['message']} | | | | | | |")
            continue
        fitted = r.get("fitted_validation", float("nan"))
        other = r.get("exported", r["main"]) != r["main"]
        written = r.get("exported_estimate", r["estimate"])

        def both(main, files, form):  # the main estimate's figure, and the files' after a slash where they differ
            return f"{main:{form}}" + (f" / {files:{form}}" if other else "")

        lines.append(f"| {r['arm']} | {r['class']} | {r['main']}{' / files: ' + r['exported'] if other else ''} | "
                     f"{both(r['estimate'], written, '.3g')} | {r['truth_error']:.3g} | {fitted:.3g} | {r['nominal']:.3g} | "
                     f"{both(r['estimate'] / fitted, written / fitted, '.2f')} | "
                     f"{both(r['estimate'] / r['nominal'], written / r['nominal'], '.2f')} |")
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
