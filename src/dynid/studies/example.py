"""A working folder to try dynid on before a real log exists: ``dynid example ur10e DIR`` (issue "A user's first hour",
item 9).

The folder holds what a user brings: the robot's URDF (a copy of the one shipped with dynid), an identification log
and a validation log, and the config ``dynid identify`` runs on as it stands. The logs are simulated from the
description with drive friction and rotor inertia of an industrial drive's size, 20-bit encoders and current noise
(:func:`dynid.studies.simulated_logs.simulated_log`): the real robots' logs that dynid was checked on may not be
redistributed, and a simulated one is small and the same on every machine.
"""

from __future__ import annotations

import io
from dataclasses import replace
from importlib import resources

import numpy as np

from .._util.keywords import seed_of
from ..exceptions import ConfigError
from ..model.description import builtin_robots, load_robot
from .simulated_logs import simulated_log

__all__ = ["EXAMPLES", "FROM_URDF", "example_files"]

EXAMPLES = ("ur10e", "tx40", "er16")
"""The robots ``dynid example`` knows: the built-in ones."""
FROM_URDF = ("ur10e",)
"""Examples whose config names the robot's URDF, as a user's does (the TX40's coupled wrist and gear ratios are in its
built-in description, not in its URDF; the ER-16 has a DH table): ``dynid identify`` writes the identified values into
a copy of that URDF."""

IDENTIFICATION_SECONDS = 60.0
VALIDATION_SECONDS = 20.0
RATE = 250.0


def _with_drives(robot, rng):
    """The robot with rotor inertia and Coulomb and viscous friction of an industrial drive's size (from its torque
    limits, 50 N·m where none is set): the example's simulation truth."""
    tau = np.where(np.isfinite(robot.limits.tau_max), robot.limits.tau_max, 50.0)
    size = {"Ia": 2e-4, "fc": 0.02, "fv": 0.01}
    drive = robot.drive.copy()
    for k, term in enumerate(robot.drive_terms):
        if term in size:
            drive[:, k] = size[term] * tau * rng.uniform(0.7, 1.3, robot.n_dof)

    return replace(robot, drive=drive * robot.drive_mask)


def _csv(log, robot) -> str:
    """The log as the robot's encoders and drives write it: the angles without the description's position offsets
    (the TX40's J2 and J3 zeros a quarter turn from its DH table's), which ``dynid identify`` adds back."""
    buffer = io.StringIO()
    kept = robot.independent  # the robot's coordinates: a joint that follows another (<mimic>) has no drive to log
    names = [j.name for j, k in zip(robot.joints, kept) if k]
    header = ["time"] + [f"{n}_position" for n in names] + [f"{n}_effort" for n in names]
    np.savetxt(buffer, np.column_stack([log.t, robot.transmission.logged_positions(log.q)[:, kept], log.tau[:, kept]]),
               delimiter=",", fmt="%.9g", header=",".join(header), comments="")
    return buffer.getvalue()


def example_files(name: str, rng=0) -> dict[str, str]:
    """The files of an example folder for a built-in robot: its URDF (where it has one), two simulated logs and a config.

    Parameters
    ----------
    name : str
        One of :data:`EXAMPLES`.
    rng : int or numpy.random.Generator
        Seeds the trajectories, the drive values and the noise (the same files for the same int; a generator gives one
        draw as the seed).

    Returns
    -------
    dict
        File name -> text: ``<name>.urdf`` (:data:`FROM_URDF`), ``identification.csv`` (60 s at 250 Hz),
        ``validation.csv`` (20 s, another trajectory), ``<name>.toml`` (the config).

    Raises
    ------
    ConfigError
        ``name`` is not an example robot (the message lists them).
    """
    if name not in EXAMPLES or name not in builtin_robots():
        raise ConfigError(f"no example for robot {name!r}: choose one of {', '.join(EXAMPLES)}")
    seed = seed_of(rng)
    rng = np.random.default_rng(seed)
    robot = _with_drives(load_robot(name), rng)
    files: dict[str, str] = {}
    if name in FROM_URDF:
        files[f"{name}.urdf"] = (resources.files("dynid.model") / "robots" / f"{name}.urdf").read_text(encoding="utf-8")
    names = [j.name for j in robot.joints]
    files["identification.csv"] = _csv(simulated_log(robot, seconds=IDENTIFICATION_SECONDS, rate=RATE, rng=seed), robot)
    files["validation.csv"] = _csv(simulated_log(robot, seconds=VALIDATION_SECONDS, rate=RATE, rng=seed + 1), robot)
    columns = lambda what: "[" + ", ".join(f'"{n}_{what}"' for n in names) + "]"  # noqa: E731
    layout = (f'header = true\ntime = {{ column = "time" }}\npositions = {{ columns = {columns("position")} }}\n'
              f'torques = {{ columns = {columns("effort")} }}\n')
    robot_line = (f'robot = "{name}.urdf"       # your robot\'s URDF; identify writes the identified values into a copy of it'
                  if name in FROM_URDF else f'robot = "{name}"            # a robot built into dynid')
    files[f"{name}.toml"] = (
        f"# dynid example {name}: simulated logs of the {name} (dynid identify {name}.toml, then open report.html)\n"
        f'{robot_line}\ndata_root = "."\n\n[identification]\nfile = "identification.csv"\n{layout}\n'
        '[[validation]]                 # another motion: the model is scored where it was not fitted\n'
        'name = "validation"\nfile = "validation.csv"\n\n'
        '[estimation]\nestimators = ["wls", "sdp"]    # sdp: the physically consistent estimate, written as URDF and MJCF\n')
    return files
