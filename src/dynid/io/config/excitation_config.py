"""Configs of ``dynid excite`` (TOML): design an excitation trajectory for a robot (paper §3.2, eq. 15).
Parsing only; :mod:`dynid.identification.excite` runs them.

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

Every table is optional (a robot's URDF, xacro or MJCF given in place of the config is a config of it alone): without
``[trajectory]`` the design has :data:`DEFAULT_TRAJECTORY` (5 harmonics of 0.1 Hz,
from and to rest), and a ``[trajectory]`` table without ``harmonics`` or a frequency takes those two from it.
An identification config (``dynid identify``'s) is an excitation config too: its robot, and its optional
``[excitation]`` table holding the tables above (``joints``, ``[excitation.trajectory]``, ``[excitation.limits]`` …).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import msgspec
import numpy as np

from ..._util.typed import convert
from ...exceptions import ConfigError
from ...excitation.constraints import Workspace
from ...excitation.design import ExcitationProblem
from ...excitation.fourier import FourierTrajectory
from ...excitation.link_geometry import link_geometry_from_mjcf, link_geometry_from_urdf
from ...excitation.obstacles import Obstacle
from ...excitation.paper_trajectories import paper_identification_trajectory
from ...model.description import parse_angle
from ...model.robot import Robot
from ...model.urdf import joints_to_hold
from ..logs.trajectories import load_trajectory
from .config_types import ExcitationDocument, IdentificationDocument, TrajectoryTable
from .configs import config_mjcf, config_robot, config_urdf, read_config

DEFAULT_TRAJECTORY = {"harmonics": 5, "frequency": 0.1, "rest": True}
"""The trajectory designed without a ``[trajectory]`` table (``[excitation.trajectory]`` of an identification config):
5 harmonics of 0.1 Hz (a 10 s period, as the UR10e's example) starting and ending at rest at offsets chosen by the
design."""


DESCRIPTION_SUFFIXES = (".urdf", ".xacro", ".xml")
"""A robot's description given to ``dynid excite`` in place of a config: its default design (``robot`` alone)."""


def _description_alone(path: Path) -> dict:
    """A config of a robot's description alone: its robot, with the joints off the arm held fixed as ``dynid init``
    holds them (:func:`dynid.model.urdf.joints_to_hold`: a gripper's fingers) for a URDF or MJCF."""
    held = () if path.suffix.lower() == ".xacro" else joints_to_hold(path)
    return {"robot": {"urdf": path.name, "held": list(held)}} if held else {"robot": path.name}


def _from_identification(doc: dict, path: Path) -> dict:
    """An identification config as an excitation document: its robot and its ``[excitation]`` table (an excitation
    table at its top, which ``dynid identify`` refuses and this would leave unread, is refused naming its place)."""
    misplaced = [k for k in doc if k in ExcitationDocument.__struct_fields__ and k not in IdentificationDocument.__struct_fields__]
    if misplaced:
        raise ConfigError(f"{path}: {misplaced[0]}: an identification config holds the excitation's settings in its "
                          f"[excitation] table: [excitation.{misplaced[0]}]")
    table = doc.get("excitation", {})
    if not isinstance(table, dict):
        raise ConfigError(f"{path}: excitation: expected a table ([excitation]), got {type(table).__name__}")
    return {"robot": doc.get("robot"), **table}


def _link_geometry(setting: str, robot, urdf: Path | None, mjcf: Path | None = None, srdf: Path | None = None):
    """``[workspace] geometry``: the URDF's collision shapes (:func:`link_geometry_from_urdf`, less ``srdf``'s
    disabled pairs) or the MJCF's collision geoms (:func:`link_geometry_from_mjcf`), or None (capsules), and why they
    were not read ("" where they were, or where the file has none). "auto" takes them where the robot's file has them
    and they load; "collision" insists."""
    if srdf is not None and (urdf is None or setting == "capsules"):
        raise ConfigError(f"workspace.srdf = {str(srdf)!r}: an SRDF names pairs of a URDF's collision shapes, but "
                          + ("the robot is not read from a URDF" if urdf is None else
                             'workspace.geometry = "capsules" leaves them out'))
    file = urdf or mjcf
    if setting == "capsules" or (file is None and setting == "auto"):
        return None, ""
    if file is None:
        raise ConfigError('workspace.geometry = "collision" needs a robot read from a URDF with <collision> elements '
                          "or an MJCF with colliding geoms, and [[workspace.obstacles]] to keep them off")
    try:
        found = link_geometry_from_urdf(robot, file, srdf) if urdf is not None else link_geometry_from_mjcf(robot, file)
    except ConfigError as exc:
        if setting == "auto" and srdf is None:
            return None, str(exc).split("; ")[0]  # what failed, without the advice for a config that insists
        raise
    if found is None and setting == "collision":
        raise ConfigError(f'workspace.geometry = "collision": {file} has no '
                          + ("<collision> element" if urdf is not None else "colliding geom (contype or conaffinity "
                             "not 0)") + " on a moving link")
    return found, ""


@dataclass(frozen=True)
class ExcitationConfig:
    """A parsed ``dynid excite`` config (module docstring).

    Attributes
    ----------
    path : Path
        The config file.
    full_robot : Robot
        The robot before the joints are selected.
    problem : ExcitationProblem
        The design problem (joints, limits, workspace, criterion).
    form : str
        Coefficient form written: "paper" (eq. 14) or "swevers".
    starts : int
        Optimisation starts.
    seed : int
    maxiter : int
        Iterations per start.
    initial : FourierTrajectory or None
        A first start given by the user.
    initial_label : str
    rate : float [Hz]
        Rate of the set-point CSV.
    periods : int
        Periods written to the set-point CSV.
    """

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


def _per_joint(v, n: int, where: str, angle: bool = False) -> np.ndarray:
    vals = v if isinstance(v, list) else [v] * n
    if len(vals) != n:
        raise ConfigError(f"{where}: expected one value or {n} (one per joint), got {len(vals)}")
    return np.array([parse_angle(x, where) if angle else float(x) for x in vals], dtype=float)


def load_excitation_config(path: str | Path) -> ExcitationConfig:
    """Parse a ``dynid excite`` config.

    Parameters
    ----------
    path : str or Path
        An excitation config, an identification config (its robot and ``[excitation]`` table), or a robot's
        description (:data:`DESCRIPTION_SUFFIXES`: a config of its ``robot`` alone).

    Returns
    -------
    ExcitationConfig

    Raises
    ------
    ConfigError
        Unreadable file, invalid TOML, unknown or malformed fields, or constraints no trajectory can satisfy
        (q_max <= q_min, a workspace that excludes the start pose …); the message names the file and the field.
    """
    path = Path(path)
    doc = _description_alone(path) if path.suffix.lower() in DESCRIPTION_SUFFIXES and path.is_file() else read_config(path, None)
    if "identification" in doc:  # dynid identify's config: its robot, and its [excitation] table
        doc = _from_identification(doc, path)
    c = convert({**doc, "robot": "-"} if isinstance(doc.get("robot"), dict) else doc, ExcitationDocument, str(path))
    here = path.parent
    full = config_robot(doc, path)
    k = c.joints if c.joints is not None else full.n_dof
    if k > full.n_dof:
        raise ConfigError(f"{path}: joints: robot {full.name!r} has {full.n_dof} joints, got {k}")
    robot = full.submodel(k) if k < full.n_dof else full

    tr = c.trajectory if c.trajectory is not None else convert(DEFAULT_TRAJECTORY, TrajectoryTable, str(path))
    harmonics = int(tr.harmonics if tr.harmonics is not None else DEFAULT_TRAJECTORY["harmonics"])
    if tr.frequency is not None and tr.omega_f is not None:
        raise ConfigError(f"{path}: trajectory: give one of frequency (Hz) or omega_f (rad/s), not both")
    omega_f = (float(tr.omega_f) if tr.omega_f is not None
               else 2 * np.pi * (tr.frequency if tr.frequency is not None else DEFAULT_TRAJECTORY["frequency"]))
    form = tr.form or "paper"
    offsets = _per_joint(tr.offsets, k, f"{path}: trajectory.offsets", angle=True) if tr.offsets is not None else None
    rest = bool(tr.rest)

    limits = robot.limits
    for f in msgspec.structs.fields(c.limits):
        val = getattr(c.limits, f.name)
        if val is not None:
            limits = replace(limits, **{f.name: _per_joint(val, k, f"{path}: limits.{f.name}", angle=f.name.startswith("q_"))})

    workspace = _workspace(c.workspace, doc, path, robot)

    de = c.design
    starts = de.starts if de.starts is not None else 6
    seed = de.seed if de.seed is not None else 0
    maxiter = de.maxiter if de.maxiter is not None else 150
    grid = de.grid_points if de.grid_points is not None else max(100, 20 * harmonics)
    safety = float(de.safety) if de.safety is not None else 0.02
    initial, initial_label = None, "best random start"
    if de.initial == "paper":
        if harmonics != 5:
            raise ConfigError(f"{path}: design.initial = \"paper\" is β1 with 5 harmonics, the design has {harmonics}")
        initial, initial_label = paper_identification_trajectory(omega_f, k), "paper β1 (eq. A.1)"
    elif de.initial is not None:
        try:
            initial, initial_label = load_trajectory(here / de.initial), de.initial
        except ConfigError as exc:
            raise ConfigError(f"{path}: design.initial: {exc}") from None

    rate = float(c.output.rate) if c.output.rate is not None else 500.0
    periods = c.output.periods if c.output.periods is not None else 1
    try:
        problem = ExcitationProblem(robot, omega_f, harmonics, limits=limits, workspace=workspace, offsets=offsets,
                                    rest=rest, criterion=de.criterion or "cond", grid_points=grid, safety=safety)
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from None
    return ExcitationConfig(path, full, problem, form, starts, seed, maxiter, initial, initial_label, rate, periods)


def _workspace(ws, doc: dict, path: Path, robot) -> Workspace:
    """The ``[workspace]`` table: its box, floor, clearance, obstacles and the links' geometry that keeps clear of them
    (the robot file's collision shapes, the SRDF's pairs) or of each other."""
    ws_kw: dict[str, Any] = {key: np.asarray(getattr(ws, key), dtype=float) for key in ("box_min", "box_max")
                             if getattr(ws, key) is not None}
    if ws.floor is not None:
        ws_kw["floor"] = float(ws.floor)
    if ws.clearance is not None:
        ws_kw["clearance"] = float(ws.clearance)
    if ws.avoid_self_collision is not None:
        ws_kw["avoid_self_collision"] = bool(ws.avoid_self_collision)
    if ws.link_radius is not None:
        ws_kw["link_radius"] = float(ws.link_radius)
    try:
        ws_kw["obstacles"] = [Obstacle(ob.shape, np.asarray(ob.size, dtype=float), np.asarray(ob.position, dtype=float),
                                   np.zeros(3) if ob.rpy is None else np.asarray(ob.rpy, dtype=float),
                                   ob.name or f"obstacle {i + 1}") for i, ob in enumerate(ws.obstacles or [])]
        srdf = None if ws.srdf is None else (path.parent / ws.srdf).resolve()
        # the links' shapes are read where something is kept off: a floor, obstacles, or the links of held joints (a
        # second arm, a head, a gripper), which capsules about the arm's joint origins leave out
        shaped = bool(ws.obstacles) or ws.floor is not None or bool(robot.held)
        if srdf is not None and not shaped:
            raise ConfigError(f"workspace.srdf = {ws.srdf!r}: the links' own shapes are kept apart only where a floor, "
                              "[[workspace.obstacles]] or held joints are given (without them the links are capsules)")
        ws_kw["geometry"], ws_kw["unread"] = (
            _link_geometry(ws.geometry or "auto", robot, config_urdf(doc, path), config_mjcf(doc, path), srdf) if shaped
            else _link_geometry(ws.geometry or "auto", robot, None))
        return Workspace(**ws_kw)
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from None
