"""The zoo: dynid's defaults on public arm descriptions it was never tuned on (issue "Honest on any log").

Nine arms from the ``example-robot-data`` package (PyPI; ``pip install -e ".[zoo]"``): UR3, UR5, UR10, Franka Panda,
Kinova Jaco 2 (j2s6s200), UFACTORY xArm7, Unitree Z1, SO-100 and TALOS's left arm, their grippers made fixed joints.
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
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))

from tests.mujoco_logs import Drives, fourier_reference, simulate, stripped_urdf  # noqa: E402

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
}
CLASSES = ("excitation", "short", "ptp", "dead")
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
    """Rotor inertia, viscous and dry friction of a size industrial drives have, from the joints' torque limits."""
    tau = np.where(np.isfinite(robot.limits.tau_max), robot.limits.tau_max, 50.0)
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


def write_log(path: Path, log, rng) -> None:
    """time, positions, torques with 1-5 % of each joint's RMS torque as noise."""
    rms = np.sqrt(np.mean(log.tau**2, axis=0))
    tau = log.tau + rng.normal(size=log.tau.shape) * rms * rng.uniform(0.01, 0.05, rms.size)
    np.savetxt(path, np.column_stack([log.t, log.q_meas, tau]), delimiter=",", fmt="%.10g")


LOG_FITTED = "truth, one-way drive terms from the log"
"""The short class's second reference: the true parameters with each one-way joint's rotor inertia, Coulomb and viscous
friction refitted on the short log (:func:`log_fitted_drive_terms`)."""


def log_fitted_drive_terms(folder: Path, log: str, cutoff: float = 10.0, trim: float = 0.3) -> dict[str, float]:
    """The drive terms (Ia, fc, fv) of each joint that moves one way only in ``log``, fitted joint by joint on that log
    with the TRUE links: ``τ_j - RNEA_j(q, q̇, q̈) = Ia·q̈_j + fc·sign(q̇_j) + fv·q̇_j`` by least squares, outside dynid
    (Pinocchio's RNEA on truth.urdf, a 4th-order zero-phase Butterworth at ``cutoff`` Hz on the positions and torques,
    central differences, ``trim`` s left out at each end). Where this set fits the log as well as the truth and predicts
    the validation log worse, the log does not tell the two apart: no estimator that reads only that log can be
    expected to reach the truth's validation error."""
    import pinocchio as pin
    from scipy.signal import butter, sosfiltfilt

    model = pin.buildModelFromUrdf(str(folder / "truth.urdf"))
    data = model.createData()
    x = np.loadtxt(folder / log, delimiter=",")
    n = model.nv
    t = np.arange(x[0, 0], x[-1, 0], 1.0 / RATE)
    q = np.column_stack([np.interp(t, x[:, 0], x[:, 1 + k]) for k in range(n)])
    tau = np.column_stack([np.interp(t, x[:, 0], x[:, 1 + n + k]) for k in range(n)])
    sos = butter(4, cutoff, fs=RATE, output="sos")
    q, tau = sosfiltfilt(sos, q, axis=0), sosfiltfilt(sos, tau, axis=0)
    dq = np.gradient(q, t, axis=0)
    ddq = np.gradient(dq, t, axis=0)
    keep = slice(int(trim * RATE), t.size - int(trim * RATE))

    def configuration(angles):  # a continuous joint's configuration is (cos, sin) in Pinocchio
        x = np.empty(model.nq)
        for k, joint in enumerate(model.joints[1:]):
            x[joint.idx_q:joint.idx_q + joint.nq] = (np.cos(angles[k]), np.sin(angles[k]))[:joint.nq] if joint.nq == 2 \
                else angles[k]
        return x

    rigid = np.array([pin.rnea(model, data, configuration(q[i]), dq[i], ddq[i]) for i in range(keep.start, keep.stop)])
    out = {}
    for j in range(n):
        v, a = dq[keep, j], ddq[keep, j]
        if min(np.mean(v > 0.01), np.mean(v < -0.01)) >= 0.01:  # it reverses: not one of the one-way joints
            continue
        coef = np.linalg.lstsq(np.column_stack([a, np.sign(v), v]), tau[keep, j] - rigid[:, j], rcond=None)[0]
        out.update({f"Ia{j + 1}": float(coef[0]), f"fc{j + 1}": float(coef[1]), f"fv{j + 1}": float(coef[2])})
    return out


def config(folder: Path, n: int, ident: str, extra: str = "") -> Path:
    cols = lambda a: "[" + ", ".join(str(a + j) for j in range(n)) + "]"  # noqa: E731
    table = (lambda f: f'file = "{f}"\ntime = {{ column = 1 }}\npositions = {{ columns = {cols(2)} }}\n'
             f'torques = {{ columns = {cols(2 + n)} }}\n')
    text = (f'data_root = "."\n[robot]\nurdf = "arm.urdf"\ndrive_terms = ["Ia", "fc", "fv", "offset"]\n'
            f'[identification]\n{table(ident)}[estimation]\nestimators = ["wls", "sdp"]\n'
            f'[[validation]]\nname = "validation"\n{table("valid.csv")}'
            '[[references]]\nname = "truth"\nfile = "truth.csv"\nformat = "standard"\nheader = true\nnames = "name"\n'
            'values = "value"\n[[references]]\nname = "nominal"\nformat = "nominal"\n' + extra)
    path = folder / f"{ident.removesuffix('.csv')}.toml"
    path.write_text(text)
    return path


def run_arm(name: str, out: Path, seed: int, classes=CLASSES) -> list[dict]:
    """Every friction truth and log class of one arm (module docstring)."""
    from dynid.model.description import load_robot

    file, keep = ARMS[name]
    text = arm_urdf((robots_folder() / file).read_text(encoding="utf-8"), keep)
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
        n = robot.n_dof
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
                "short": simulate(truth_text, drives, "fourier", 5.0, rng, reference=one_way((1, n - 2)), **common),
                "ptp": simulate(truth_text, drives, "ptp", 40.0, rng, **common)}
        simulated = time.perf_counter() - t0
        for key, log in logs.items():
            write_log(folder / f"{key}.csv", log, rng)
        dead = np.loadtxt(folder / "excitation.csv", delimiter=",")
        dead[:, 1 + n + n // 2] = 0.0
        np.savetxt(folder / "dead.csv", dead, delimiter=",", fmt="%.10g")
        for kind in classes:
            extra = ""
            if kind == "short":
                fitted = log_fitted_drive_terms(folder, "short.csv")
                (folder / "short_fitted.csv").write_text("name,value\n" + "".join(
                    f"{k},{fitted.get(k, v):.12g}\n" for k, v in zip(names, values)))
                extra = (f'[[references]]\nname = "{LOG_FITTED}"\nfile = "short_fitted.csv"\nformat = "standard"\n'
                         'header = true\nnames = "name"\nvalues = "value"\n')
            cfg = config(folder, n, f"{kind}.csv", extra)
            t1 = time.perf_counter()
            p = subprocess.run([sys.executable, "-m", "dynid", "identify", str(cfg), "--out", str(folder / f"out-{kind}"),
                                "--no-figures", "-q"], capture_output=True, text=True, timeout=1800)
            row = {"arm": name, "joints": n, "truth": truth_kind, "class": kind, "repaired_links": repaired,
                   "seconds": time.perf_counter() - t1, "simulation_seconds": simulated}
            if p.returncode != 0:
                row.update(refused=True, message=(p.stderr.strip().splitlines() or [""])[-1])
            else:
                r = json.loads((folder / f"out-{kind}" / "results.json").read_text())
                v = r["validation"][0]
                main = r["main_estimate"]
                err = {k: m["global_relative_error"] for k, m in v["metrics"].items()}
                if kind == "dead":  # the dead joint's own drive terms are in no live row: over the other joints too
                    live = [j for j in range(n) if j != n // 2]
                    rms = np.asarray(v["rms_torque"], dtype=float)[live]

                    def over_live(label):
                        e = np.asarray(v["metrics"][label]["relative_error"], dtype=float)[live]
                        return float(np.sqrt(np.sum((e * rms) ** 2) / np.sum(rms**2)))

                    row["live_ratio"] = over_live(main) / over_live("truth")
                if LOG_FITTED in v["metrics"]:  # what the log cannot tell from the truth (log_fitted_drive_terms)
                    fit = r["identification"]["metrics"]
                    row.update(fitted_fit=fit[LOG_FITTED]["global_relative_error"],
                               truth_fit=fit["truth"]["global_relative_error"],
                               fitted_validation=v["metrics"][LOG_FITTED]["global_relative_error"])
                row.update(refused=False, main=main, estimate=err[main], truth_error=err["truth"], nominal=err["nominal"],
                           ratio=err[main] / err["truth"] if err["truth"] > 0 else float("nan"),
                           floor=(v.get("noise_floor") or {}).get("global_relative_error"),
                           from_prior=r["diagnostics"].get("from_prior", []),
                           findings=[f["kind"] for f in r["findings"]])
            rows.append(row)
            print(json.dumps({k: row[k] for k in row if k not in ("findings", "from_prior", "repaired_links")}),
                  flush=True)
    return rows


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
                    cells.append(f"{r['ratio']:.2f}× ({r['estimate']:.3g} / {r['truth_error']:.3g} %; nominal "
                                 f"{r['nominal']:.3g} %{live})")
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
    args = parser.parse_args(argv)
    out = Path(args.out)
    rows = []
    for name in [a.strip() for a in args.arms.split(",") if a.strip()]:
        rows += run_arm(name, out, args.seed, tuple(c.strip() for c in args.classes.split(",") if c.strip()))
    (out / "zoo.json").write_text(json.dumps(rows, indent=1))
    print(table(rows))
    print()
    print(short_table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
