"""Configs of ``dynid excite`` (TOML): design an excitation trajectory for a robot (paper §3.2, eq. 15).
Parsing only; :mod:`dynid.experiment.excitation` runs them.

Layout (SI units, radians; angles may be written ``"pi/2"``; paths relative to the config file)::

    robot = "er16"               # built-in robot name or description TOML
    joints = 3                   # identify the first joints (default all); the others are held at 0

    [trajectory]
    harmonics = 5                # N of eq. 14
    frequency = 0.05             # fundamental frequency [Hz] (or omega_f = rad/s)
    form = "paper"               # coefficients written as eq. 14 ("paper") or in the Swevers form
    offsets = [-0.3857, 0.0011, 0.0]   # fixed q_o [rad]; omit to optimise them
    rest = false                 # true: start and end at rest at the offsets

    [limits]                     # optional: override the robot's limits, one value or one per joint
    dq_max = 2.0                 # rad/s; also q_min, q_max [rad], ddq_max [rad/s²], tau_max [N·m]

    [workspace]                  # optional: where the tool point may go, base frame [m]
    box_min = [-1.5, -1.5, -0.5]
    box_max = [1.5, 1.5, 1.8]
    floor = -0.4

    [design]                     # all optional
    criterion = "cond"           # or "d-optimal"
    starts = 6
    seed = 0
    grid_points = 100            # per period
    safety = 0.02
    maxiter = 150
    initial = "paper"            # first start and "before" reference: "paper" (β1) or an excitation JSON

    [output]
    rate = 500                   # controller rate of the CSV [Hz]
    periods = 1
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
import numpy as np

from ..exceptions import ConfigError
from ..excitation.constraints import Workspace
from ..excitation.design import ExcitationProblem
from ..excitation.fourier import FORMS, FourierTrajectory
from ..excitation.paper_trajectories import paper_identification_trajectory
from .configs import config_robot, read_config
from .trajectories import load_trajectory
from ..model.description import parse_angle
from ..model.robot import Robot

_SECTIONS = {"robot", "joints", "name", "notes", "trajectory", "limits", "workspace", "design", "output"}
_FIELDS = {
    "trajectory": {"harmonics", "frequency", "omega_f", "form", "offsets", "rest"},
    "limits": {"q_min", "q_max", "dq_max", "ddq_max", "tau_max"},
    "workspace": {"box_min", "box_max", "floor"},
    "design": {"criterion", "starts", "seed", "grid_points", "safety", "maxiter", "initial"},
    "output": {"rate", "periods"},
}


@dataclass(frozen=True)
class ExcitationConfig:
    """A parsed ``dynid excite`` config (module docstring)."""

    path: Path
    full_robot: Robot
    problem: ExcitationProblem
    form: str
    starts: int
    seed: int
    maxiter: int
    initial: FourierTrajectory | None
    initial_label: str
    rate: float
    periods: int


def _number(v, where: str, *, positive=False, integer=False):
    if isinstance(v, bool) or not isinstance(v, (int, float)) or (integer and v != int(v)) or (positive and not v > 0):
        kind = ("positive " if positive else "") + ("integer" if integer else "number")
        raise ConfigError(f"{where}: expected a {kind}, got {v!r}")
    return int(v) if integer else float(v)


def _per_joint(v, n: int, where: str, angle: bool = False) -> np.ndarray:
    vals = v if isinstance(v, list) else [v] * n
    if len(vals) != n:
        raise ConfigError(f"{where}: expected one value or {n} (one per joint), got {len(vals)}")
    return np.array([parse_angle(x, where) if angle else _number(x, where) for x in vals], dtype=float)


def _table(doc: dict, key: str, path: Path) -> dict:
    t = doc.get(key, {})
    if not isinstance(t, dict):
        raise ConfigError(f"{path}: {key}: expected a [{key}] table")
    unknown = sorted(set(t) - _FIELDS[key])
    if unknown:
        raise ConfigError(f"{path}: {key}: unknown field(s) {unknown}, expected some of {sorted(_FIELDS[key])}")
    return t


def load_excitation_config(path: str | Path) -> ExcitationConfig:
    """Parse a ``dynid excite`` config.

    Raises
    ------
    ConfigError
        Unreadable file, invalid TOML, unknown or malformed fields, or constraints no trajectory can
        satisfy (q_max <= q_min, a workspace that excludes the start pose …); the message names the file
        and the field.
    """
    path = Path(path)
    doc = read_config(path, _SECTIONS)
    here = path.parent
    full = config_robot(doc, path)
    k = _number(doc.get("joints", full.n_dof), f"{path}: joints", positive=True, integer=True)
    if k > full.n_dof:
        raise ConfigError(f"{path}: joints: robot {full.name!r} has {full.n_dof} joints, got {k}")
    robot = full.submodel(k) if k < full.n_dof else full

    tr = _table(doc, "trajectory", path)
    if "harmonics" not in tr:
        raise ConfigError(f"{path}: trajectory.harmonics: expected the number of harmonics N of eq. 14")
    harmonics = _number(tr["harmonics"], f"{path}: trajectory.harmonics", positive=True, integer=True)
    if ("frequency" in tr) == ("omega_f" in tr):
        raise ConfigError(f"{path}: trajectory: give exactly one of frequency (Hz) or omega_f (rad/s)")
    omega_f = (2 * np.pi * _number(tr["frequency"], f"{path}: trajectory.frequency", positive=True) if "frequency" in tr
               else _number(tr["omega_f"], f"{path}: trajectory.omega_f", positive=True))
    form = tr.get("form", "paper")
    if form not in FORMS:
        raise ConfigError(f"{path}: trajectory.form: expected one of {', '.join(FORMS)}, got {form!r}")
    offsets = _per_joint(tr["offsets"], k, f"{path}: trajectory.offsets", angle=True) if "offsets" in tr else None
    rest = tr.get("rest", False)
    if not isinstance(rest, bool):
        raise ConfigError(f"{path}: trajectory.rest: expected true or false, got {rest!r}")

    lim_t = _table(doc, "limits", path)
    limits = robot.limits
    for key, val in lim_t.items():
        limits = replace(limits, **{key: _per_joint(val, k, f"{path}: limits.{key}", angle=key.startswith("q_"))})

    ws_t = _table(doc, "workspace", path)
    ws_kw = {}
    for key in ("box_min", "box_max"):
        if key in ws_t:
            v = ws_t[key]
            if not isinstance(v, list) or len(v) != 3:
                raise ConfigError(f"{path}: workspace.{key}: expected [x, y, z] in metres (inf for an open side), got {v!r}")
            ws_kw[key] = np.array([_number(x, f"{path}: workspace.{key}") for x in v])
    if "floor" in ws_t:
        ws_kw["floor"] = _number(ws_t["floor"], f"{path}: workspace.floor")
    try:
        workspace = Workspace(**ws_kw)
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from None

    de = _table(doc, "design", path)
    starts = _number(de.get("starts", 6), f"{path}: design.starts", positive=True, integer=True)
    seed = _number(de.get("seed", 0), f"{path}: design.seed", integer=True)
    maxiter = _number(de.get("maxiter", 150), f"{path}: design.maxiter", positive=True, integer=True)
    grid = _number(de.get("grid_points", max(100, 20 * harmonics)), f"{path}: design.grid_points", positive=True, integer=True)
    safety = _number(de.get("safety", 0.02), f"{path}: design.safety")
    initial, initial_label = None, "best random start"
    if "initial" in de:
        init = de["initial"]
        if init == "paper":
            if harmonics != 5:
                raise ConfigError(f"{path}: design.initial = \"paper\" is β1 with 5 harmonics, the design has {harmonics}")
            initial, initial_label = paper_identification_trajectory(omega_f, k), "paper β1 (eq. A.1)"
        elif isinstance(init, str):
            try:
                initial, initial_label = load_trajectory(here / init), init
            except ConfigError as exc:
                raise ConfigError(f"{path}: design.initial: {exc}") from None
        else:
            raise ConfigError(f"{path}: design.initial: expected \"paper\" or an excitation JSON file, got {init!r}")

    out = _table(doc, "output", path)
    rate = _number(out.get("rate", 500.0), f"{path}: output.rate", positive=True)
    periods = _number(out.get("periods", 1), f"{path}: output.periods", positive=True, integer=True)
    try:
        problem = ExcitationProblem(robot, omega_f, harmonics, limits=limits, workspace=workspace, offsets=offsets,
                                    rest=rest, criterion=de.get("criterion", "cond"), grid_points=grid, safety=safety)
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from None
    return ExcitationConfig(path, full, problem, form, starts, seed, maxiter, initial, initial_label, rate, periods)
