"""Simulated robot logs for checking identification against an independent truth.

Torques: Pinocchio's RNEA for the rigid bodies (not dynid's regressor) plus rotor inertia, viscous and
**asymmetric** Coulomb friction written out here (not dynid's friction code); motor currents
``I = τ/K`` with Gaussian noise and encoder-quantised positions, written to CSV like a controller log.
Asymmetric Coulomb friction ``f⁺`` for q̇ > 0 and ``-f⁻`` for q̇ < 0 equals dynid's symmetric Coulomb term
``(f⁺ + f⁻)/2·sign(q̇)`` plus an offset ``(f⁺ − f⁻)/2`` while moving, so the truth is exactly representable
with drive terms Ia, fc, fv, offset.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from dynid.model.description import builtin_robots, load_robot


def truth_robot(name: str, rng: np.random.Generator):
    """The built-in robot with drive terms (Ia, fc, fv, offset) and plausible friction; also (f⁺, f⁻, fv, Ia)."""
    robot = load_robot(name)
    n = robot.n_dof
    scale = np.abs(robot.limits.tau_max) if np.all(np.isfinite(robot.limits.tau_max)) else np.full(n, 100.0)
    f_plus = 0.01 * scale * rng.uniform(0.6, 1.4, n)
    f_minus = f_plus * rng.uniform(0.6, 0.9, n)
    fv = 0.008 * scale * rng.uniform(0.5, 1.5, n)
    ia = 0.002 * scale * rng.uniform(0.5, 1.5, n) / 10
    drive = np.column_stack([ia, (f_plus + f_minus) / 2, fv, (f_plus - f_minus) / 2])
    truth = replace(robot, drive_terms=("Ia", "fc", "fv", "offset"), drive=drive, drive_mask=None)
    return truth, (f_plus, f_minus, fv, ia)


def fourier_motion(robot, t, rng, f0=0.1, n_harmonics=5, fill=0.6):
    """Sum of ``n_harmonics`` harmonics of ``f0`` Hz around the middle of each joint's range."""
    n = robot.n_dof
    lo, hi = np.maximum(robot.limits.q_min, -np.pi), np.minimum(robot.limits.q_max, np.pi)
    mid, half = (lo + hi) / 2, (hi - lo) / 2
    k = np.arange(1, n_harmonics + 1)[:, None]
    a = rng.normal(size=(n_harmonics, n)) / k
    b = rng.normal(size=(n_harmonics, n)) / k
    w = 2 * np.pi * f0 * k
    arg = w[:, :, None] * t[None, None, :]  # (H, 1, N)
    q = (a[:, :, None] * np.sin(arg) + b[:, :, None] * np.cos(arg)).sum(0).T
    dq = (a[:, :, None] * w[:, :, None] * np.cos(arg) - b[:, :, None] * w[:, :, None] * np.sin(arg)).sum(0).T
    ddq = -(a[:, :, None] * w[:, :, None] ** 2 * np.sin(arg) + b[:, :, None] * w[:, :, None] ** 2 * np.cos(arg)).sum(0).T
    amp = np.abs(q).max(axis=0)
    vmax = np.abs(dq).max(axis=0)
    s = np.minimum(fill * half / amp, 0.8 * np.minimum(robot.limits.dq_max, 3.0) / vmax)
    return mid + q * s, dq * s, ddq * s


def point_to_point_motion(robot, t, rng, segment=1.5, rest=0.3, fill=0.6):
    """Random targets joined by quintic segments of ``segment`` s, each followed by ``rest`` s at rest."""
    n = robot.n_dof
    lo, hi = np.maximum(robot.limits.q_min, -np.pi), np.minimum(robot.limits.q_max, np.pi)
    mid, half = (lo + hi) / 2, (hi - lo) / 2
    period = segment + rest
    n_seg = int(np.ceil(t[-1] / period)) + 1
    pts = mid + fill * half * rng.uniform(-1, 1, (n_seg + 1, n))
    vmax = 0.8 * np.minimum(robot.limits.dq_max, 3.0)
    # limit the step so that the quintic's peak speed 1.875·Δ/T stays under vmax
    for i in range(1, n_seg + 1):
        step = np.clip(pts[i] - pts[i - 1], -vmax * segment / 1.875, vmax * segment / 1.875)
        pts[i] = pts[i - 1] + step
    i = np.minimum((t // period).astype(int), n_seg - 1)
    s = np.clip((t - i * period) / segment, 0.0, 1.0)[:, None]
    moving = ((t - i * period) < segment)[:, None]
    d = pts[i + 1] - pts[i]
    q = pts[i] + d * (10 * s**3 - 15 * s**4 + 6 * s**5)
    dq = d * (30 * s**2 - 60 * s**3 + 30 * s**4) / segment * moving
    ddq = d * (60 * s - 180 * s**2 + 120 * s**3) / segment**2 * moving
    return q, dq, ddq


def torques(robot, q, dq, ddq, friction):
    """RNEA (Pinocchio) + rotor inertia + viscous + asymmetric Coulomb friction, (N, n) [N·m]."""
    import pinocchio as pin

    from dynid.dynamics.rnea import pinocchio_model

    model = pinocchio_model(robot)
    data = model.createData()
    tau = np.array([pin.rnea(model, data, a, b, c) for a, b, c in zip(q, dq, ddq)])
    f_plus, f_minus, fv, ia = friction
    coulomb = np.where(dq > 0, f_plus, np.where(dq < 0, -f_minus, 0.0))
    return tau + ia * ddq + fv * dq + coulomb


def write_log(path, robot, t, q, dq, ddq, friction, rng, current_std=0.02, encoder_bits=20):
    """A controller log: time, quantised positions, noisy currents; returns the true torques."""
    tau = torques(robot, q, dq, ddq, friction)
    step = 2 * np.pi / 2**encoder_bits
    q_meas = np.round(q / step) * step
    current = tau / robot.drive_gains + rng.normal(0.0, current_std, tau.shape)
    np.savetxt(path, np.column_stack([t, q_meas, current]), delimiter=",", fmt="%.10g")
    return tau


def config_text(robot_toml: str, data_root, ident: str, validation: str, n: int, extra: str = "") -> str:
    cols = lambda a: "[" + ", ".join(str(a + j) for j in range(n)) + "]"
    table = lambda f: (f'file = "{f}"\ntime = {{ column = 1 }}\npositions = {{ columns = {cols(2)} }}\n'
                       f'currents = {{ columns = {cols(2 + n)} }}\n')
    return (f'robot = "{robot_toml}"\ndata_root = "{data_root}"\n[identification]\n{table(ident)}{extra}'
            f'[estimation]\nestimators = ["ols"]\n[[validation]]\nname = "validation"\n{table(validation)}'
            f'[[references]]\nname = "truth"\nfile = "truth.csv"\nformat = "standard"\nheader = true\nnames = "name"\nvalues = "value"\n')


def robot_toml(name: str, folder) -> str:
    """A copy of a built-in robot's description with drive terms Ia, fc, fv, offset, in ``folder``."""
    import re
    from importlib import resources

    res = resources.files("dynid.model") / "robots"
    text = (res / f"{name}.toml").read_text(encoding="utf-8")
    text = re.sub(r"^drive_terms = .*$", 'drive_terms = ["Ia", "fc", "fv", "offset"]', text, count=1, flags=re.M)
    if "drive_terms" not in text:
        text = 'drive_terms = ["Ia", "fc", "fv", "offset"]\n' + text
    text = re.sub(r'^urdf = "(.*)"$', lambda m: f'urdf = "{res / m.group(1)}"', text, flags=re.M)
    path = folder / f"{name}_truth.toml"
    path.write_text(text, encoding="utf-8")
    return str(path)


def write_truth(path, robot, names) -> None:
    phi = robot.standard_parameters()
    path.write_text("name,value\n" + "".join(f"{n},{v:.12g}\n" for n, v in zip(names, phi)))


def simulated_case(folder, name: str, rate: float, motion: str, seed: int = 0, duration: float = 30.0,
                   current_std: float = 0.02):
    """Identification and validation logs of robot ``name`` (a built-in, or a URDF's path: its drive terms are
    dynid's default for a URDF, Ia, fc, fv, offset) at ``rate`` Hz with ``motion`` ("fourier" or "ptp"), their config
    (no [preprocessing]: the defaults) and the truth; returns (config path, truth robot)."""
    rng = np.random.default_rng(seed)
    robot, friction = truth_robot(name, rng)
    t = np.arange(int(duration * rate)) / rate
    make = fourier_motion if motion == "fourier" else point_to_point_motion
    for label in ("ident", "valid"):
        q, dq, ddq = make(robot, t, rng)
        write_log(folder / f"{label}.csv", robot, t, q, dq, ddq, friction, rng, current_std)
    write_truth(folder / "truth.csv", robot, robot.parameter_names)
    toml = robot_toml(name, folder) if name in builtin_robots() else str(name)  # a URDF's path: as it is
    cfg = folder / "config.toml"
    cfg.write_text(config_text(toml, folder, "ident.csv", "valid.csv", robot.n_dof))
    return cfg, robot


def truth_beta(result, truth_robot) -> np.ndarray:
    """The truth's base parameters in the identified model's layout: the terms the truth lacks (a friction model
    dynid chose beyond the simulated one) are 0 there."""
    return result.base.base_from_named(dict(zip(truth_robot.parameter_names, truth_robot.standard_parameters())))
