"""Constraints of the excitation design (paper eq. 15) and their margins on a time grid.

``q_min <= q(t) <= q_max``, ``|dq(t)| <= dq_max``, ``|ddq(t)| <= ddq_max``, ``|tau(t)| <= tau_max`` with the
nominal parameters, and the tool point in the workspace ``W_o`` (a box and/or above a floor plane).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._util.reprs import short_repr
from ..dynamics.kinematics import tip_positions
from ..dynamics.regressor import regressor
from ..exceptions import ConfigError
from ..model.robot import Limits, Robot
from .collision import CapsuleSelfDistances, shape_clearance, touching_pairs
from .floor import FloorDistances, FloorNeeds, floor_needs, lowest_points
from .fourier import FourierTrajectory
from .link_geometry import (
    LinkGeometry,
    SelfDistances,
    ShapeDistances,
    capsule_geometry,
    estimated_link_radius,
    self_pairs,
)
from .obstacles import Obstacle, ObstacleDistances, capsule_ends

AXES = "xyz"


@short_repr
@dataclass(frozen=True)
class Workspace:
    """Where the tool point may go (``W_o`` of eq. 15), in the base frame [m]; on a robot with branches, each branch's tip
    (:attr:`dynid.model.robot.Robot.tips`) too.

    Attributes
    ----------
    box_min, box_max : (3,) arrays
        Axis-aligned box; ``±inf`` leaves a side open.
    floor : float
        Height of a horizontal floor plane (a table, the floor); the tool point stays at ``z >= floor``, and every
        link's shape (:meth:`shapes`) at least ``clearance`` above it, measured from its lowest point
        (:mod:`dynid.excitation.floor`; ``-inf``: none).
    clearance : float [m]
        How far the links' shapes keep off the floor and the cell's bodies: their surface-to-surface distance (default
        0.05 m). A shape that starts within it of the floor (a shoulder housing just above the table) is held no lower
        than it starts.
    obstacles : tuple of Obstacle
        The cell's bodies (a table top, a fixture, a wall): every link's shape stays ``clearance`` off each
        (:mod:`dynid.excitation.obstacles`).
    geometry : LinkGeometry or None
        The links' own collision shapes (:mod:`dynid.excitation.link_geometry`); None: each link is a capsule of
        :attr:`link_radius` about its joint origins (:func:`~dynid.excitation.link_geometry.capsule_geometry`).
    link_radius : float or None [m]
        The capsules' radius without :attr:`geometry`; None (default): estimated,
        :func:`~dynid.excitation.link_geometry.estimated_link_radius` (said as an estimate).
    unread : str
        Why the robot file's collision shapes were not read, where it names some that do not load (a mesh missing
        beside the URDF); "" otherwise.
    made : dict
        The capsules :meth:`shapes` made, per robot (not compared).
    avoid_self_collision : bool or None
        Whether the design keeps the links off each other (:meth:`self_pairs`): their collision shapes with
        :attr:`geometry`, else their capsules. None (default): the shapes yes, the capsules no (their self clearance
        is checked on the set-points and said; keeping them apart costs the design time and some conditioning:
        docs, the workflow tutorial). False: neither.
    """

    box_min: np.ndarray = field(default_factory=lambda: np.full(3, -np.inf))
    box_max: np.ndarray = field(default_factory=lambda: np.full(3, np.inf))
    floor: float = -np.inf
    clearance: float = 0.05
    obstacles: tuple[Obstacle, ...] = ()
    geometry: LinkGeometry | None = None
    avoid_self_collision: bool | None = None
    link_radius: float | None = None
    unread: str = ""
    made: dict = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "obstacles", tuple(self.obstacles))
        for name in ("box_min", "box_max"):
            v = np.asarray(getattr(self, name), dtype=float)
            if v.shape != (3,) or np.any(np.isnan(v)):
                raise ConfigError(f"workspace.{name}: expected three numbers [x, y, z] in metres, got {getattr(self, name)!r}")
            object.__setattr__(self, name, v)
        bad = [AXES[i] for i in range(3) if not self.box_min[i] < self.box_max[i]]
        if bad:
            raise ConfigError(f"workspace: box_min must be below box_max, not on axis {', '.join(bad)} "
                              f"(box_min {self.box_min.tolist()}, box_max {self.box_max.tolist()})")
        if np.isnan(self.floor) or self.floor == np.inf:
            raise ConfigError(f"workspace.floor: expected a height in metres, got {self.floor}")
        if not (np.isfinite(self.clearance) and self.clearance >= 0):
            raise ConfigError(f"workspace.clearance: expected a distance of at least 0 m, got {self.clearance}")
        if self.link_radius is not None and not (np.isfinite(self.link_radius) and self.link_radius > 0):
            raise ConfigError(f"workspace.link_radius: expected a radius above 0 m, got {self.link_radius}")

    def shapes(self, robot) -> LinkGeometry:
        """The links' shapes every distance is measured on: :attr:`geometry`, else capsules of :meth:`capsule_radius`
        (made once per robot).

        Parameters
        ----------
        robot : Robot

        Returns
        -------
        LinkGeometry
        """
        if self.geometry is not None:
            return self.geometry
        key = (id(robot), self.capsule_radius(robot))
        if key not in self.made:  # the robot is kept with its capsules: its id stays its own
            self.made[key] = (robot, capsule_geometry(robot, key[1], estimated=self.link_radius is None))
        return self.made[key][1]

    def capsule_radius(self, robot) -> float:
        """The links' capsule radius without collision shapes: :attr:`link_radius`, else the estimate.

        Parameters
        ----------
        robot : Robot

        Returns
        -------
        float [m]
        """
        return float(self.link_radius) if self.link_radius is not None else estimated_link_radius(robot)

    def floor_needs(self, robot, start_pose: np.ndarray) -> FloorNeeds | None:
        """The shapes the floor holds and the height each keeps (:func:`dynid.excitation.floor.floor_needs`); None
        without a floor.

        Parameters
        ----------
        robot : Robot
        start_pose : (n_dof,) array [rad]

        Returns
        -------
        FloorNeeds or None
        """
        if not np.isfinite(self.floor):
            return None
        return floor_needs(robot, self.shapes(robot), self.floor, self.clearance, start_pose)

    def cell_pairs(self, robot) -> list[tuple[int, int]]:
        """The (link or shape, obstacle) pairs the cell's distances are measured for.

        Parameters
        ----------
        robot : Robot

        Returns
        -------
        list of (int, int)
            (shape, obstacle) of :meth:`shapes` on a moving link (the base's shapes do not move).
        """
        shapes = self.shapes(robot)
        return [(g, i) for g in np.flatnonzero(shapes.link >= 0).tolist() for i in range(len(self.obstacles))]

    def self_pairs(self, robot) -> list[tuple[int, int]]:
        """The pairs the design keeps apart: of the links' own collision shapes with :attr:`geometry`
        (:func:`dynid.excitation.link_geometry.self_pairs`), else of the links' capsules
        (:func:`dynid.excitation.collision.touching_pairs`) where :attr:`avoid_self_collision` asks for them.

        Parameters
        ----------
        robot : Robot

        Returns
        -------
        list of (int, int)
            Shape indices with :attr:`geometry`, else links (0-based).
        """
        if self.avoid_self_collision is False or (self.geometry is None and self.avoid_self_collision is None):
            return []
        return touching_pairs(robot, self.capsule_radius(robot)) if self.geometry is None else self_pairs(robot, self.geometry)

    def self_measure(self, robot, q, pairs, *, within: float | None = None):
        """The distances of :meth:`self_pairs` along ``q``, measured once, their gradient on demand: the shapes'
        (:class:`dynid.excitation.link_geometry.SelfDistances`) or the capsules'
        (:class:`dynid.excitation.collision.CapsuleSelfDistances`).

        Parameters
        ----------
        robot : Robot
        q : (N, n_dof) array [rad]
        pairs : list of (int, int)
            From :meth:`self_pairs`.
        within : float, optional
            [m] The shapes' pairs measured exactly only within this of each sample's nearest
            (:class:`~dynid.excitation.link_geometry.SelfDistances`); the capsules' are all measured.

        Returns
        -------
        SelfDistances or CapsuleSelfDistances
            ``dist`` (N, n_pairs) [m], zero at contact (the capsules' surfaces); ``distances(gradient=True)``.
        """
        if self.geometry is None:
            return CapsuleSelfDistances(robot, q, self.capsule_radius(robot), pairs)
        return SelfDistances(robot, q, self.geometry, pairs, within=within)

    def cell_distances(self, robot, q, *, pairs=None, gradient: bool = False) -> ObstacleDistances:
        """The links' shapes' (:meth:`shapes`) distances to the cell's bodies beyond the clearance (zero: the
        clearance kept).

        Parameters
        ----------
        robot : Robot
        q : (N, n_dof) array [rad]
        pairs : list of (int, int), optional
            Default :meth:`cell_pairs`.
        gradient : bool

        Returns
        -------
        ObstacleDistances
        """
        return self.cell_measure(robot, q, pairs=pairs).distances(gradient=gradient)

    def cell_measure(self, robot, q, *, pairs=None):
        """:meth:`cell_distances` measured once: ``dist`` (N, pairs) [m], and ``distances(gradient=...)`` with their
        gradient at the same ``q``, from the same coal results.

        Parameters
        ----------
        robot : Robot
        q : (N, n_dof) array [rad]
        pairs : list of (int, int), optional
            Default :meth:`cell_pairs`.

        Returns
        -------
        ShapeDistances
        """
        pairs = self.cell_pairs(robot) if pairs is None else pairs
        return ShapeDistances(robot, q, self.obstacles, self.shapes(robot), self.clearance, pairs=pairs)

    def inequalities(self) -> tuple[np.ndarray, np.ndarray, list[str]]:
        """``G p <= h`` for the finite sides of the box and the floor.

        Returns
        -------
        G : (m, 3) ndarray
        h : (m,) ndarray [m]
        labels : list of str
            One per row.
        """
        rows, h, labels = [], [], []
        for i in range(3):
            if np.isfinite(self.box_min[i]):
                rows.append(-np.eye(3)[i])
                h.append(-self.box_min[i])
                labels.append(f"{AXES[i]} >= {self.box_min[i]:g} m")
            if np.isfinite(self.box_max[i]):
                rows.append(np.eye(3)[i])
                h.append(self.box_max[i])
                labels.append(f"{AXES[i]} <= {self.box_max[i]:g} m")
        if np.isfinite(self.floor):
            rows.append(-np.eye(3)[2])
            h.append(-self.floor)
            labels.append(f"z >= floor {self.floor:g} m")
        return np.array(rows).reshape(-1, 3), np.array(h, dtype=float), labels

    def shapes_said(self) -> str:
        """What the floor's and the cell's distances are measured on, in words (:meth:`shapes`).

        Returns
        -------
        str
        """
        if self.geometry is not None:
            return f"collision shapes of {self.geometry.source}"
        if self.link_radius is not None:
            return f"capsules of radius {self.link_radius:g} m about the joint origins ([workspace] link_radius)"
        return "capsules about the joint origins, their radius estimated (no collision shapes; [workspace] link_radius)"

    def to_dict(self) -> dict:
        """JSON-ready workspace (infinite sides as None).

        Returns
        -------
        dict
        """
        fin = lambda v: [float(x) if np.isfinite(x) else None for x in v]  # noqa: E731
        return {"box_min": fin(self.box_min), "box_max": fin(self.box_max),
                "floor": float(self.floor) if np.isfinite(self.floor) else None, "clearance": float(self.clearance),
                **({"obstacles": [ob.to_dict() for ob in self.obstacles]} if self.obstacles else {}),
                **({"geometry": self.shapes_said()} if self.obstacles or np.isfinite(self.floor) else {}),
                **({} if self.avoid_self_collision is None else {"avoid_self_collision": self.avoid_self_collision})}


@dataclass(frozen=True)
class ConstraintMargin:
    """How close a trajectory comes to one constraint: ``margin = limit - worst`` (≥ 0 when satisfied).

    Attributes
    ----------
    constraint : str
        Position, velocity, acceleration, torque or workspace.
    where : str
        The joint or workspace side.
    limit : float
        The limit, in the constraint's unit.
    worst : float
        The trajectory's worst value.
    margin : float
        ``limit - worst``.
    relative : float
        The margin divided by the limit (by the range for positions), in [0, 1] when satisfied.
    """

    constraint: str
    where: str
    limit: float
    worst: float
    margin: float
    relative: float

    @property
    def satisfied(self) -> bool:
        """Whether the margin is not negative."""
        return self.margin >= 0.0

    def to_dict(self) -> dict:
        """JSON-ready margin.

        Returns
        -------
        dict
        """
        return {k: getattr(self, k) for k in ("constraint", "where", "limit", "worst", "margin", "relative")}


def check_limits(limits: Limits, n_dof: int, source: str = "limits") -> None:
    """Refuse limits no trajectory can satisfy.

    Parameters
    ----------
    limits : Limits
    n_dof : int
    source : str
        Named in the error.

    Raises
    ------
    ConfigError
        ``q_max <= q_min`` for a joint, or a velocity, acceleration or torque limit that is not positive.
    """
    for name in ("q_min", "q_max", "dq_max", "ddq_max", "tau_max"):
        v = getattr(limits, name)
        if v.shape != (n_dof,) or np.any(np.isnan(v)):
            raise ConfigError(f"{source}.{name}: expected {n_dof} numbers, got shape {v.shape}")
    bad = np.flatnonzero(~(limits.q_max > limits.q_min))
    if bad.size:
        j = bad[0]
        raise ConfigError(f"{source}: joint {j + 1} has q_max = {limits.q_max[j]:g} rad not above q_min = {limits.q_min[j]:g} rad")
    for name, unit in (("dq_max", "rad/s"), ("ddq_max", "rad/s²"), ("tau_max", "N·m")):
        v = getattr(limits, name)
        bad = np.flatnonzero(~(v > 0))
        if bad.size:
            raise ConfigError(f"{source}.{name}: joint {bad[0] + 1} has {v[bad[0]]:g} {unit}, expected a positive limit")


def constraint_margins(robot: Robot, trajectory: FourierTrajectory, t: np.ndarray, limits: Limits,
                       workspace: Workspace, phi: np.ndarray | None = None, *,
                       start_pose: np.ndarray | None = None) -> list[ConstraintMargin]:
    """Margin of every finite constraint of eq. 15, per joint (per side for the workspace), on times ``t``.

    Parameters
    ----------
    robot : Robot
    trajectory : FourierTrajectory
    t : (N,) array [s]
        Time grid the constraints are checked on.
    limits : Limits
    workspace : Workspace
    phi : (n_params,) array, optional
        Parameters the torques are computed with (default: the robot's nominal ones).
    start_pose : (n_dof,) array [rad], optional
        The pose a shape that starts within the clearance of the floor is held at (default the trajectory's offsets).

    Returns
    -------
    list of ConstraintMargin
        Positions (lower and upper), velocities, accelerations, torques, the floor, the workspace's sides, then the
        cell's bodies (the closest link to each; a body no link can reach is left out).
    """
    q, dq, ddq = trajectory.evaluate(t)
    phi = robot.standard_parameters() if phi is None else phi
    tau = regressor(robot, q, dq, ddq) @ phi
    out = []
    span = limits.q_max - limits.q_min
    for j in range(robot.n_dof):
        lbl = f"joint {j + 1}"
        unit = "m" if robot.joints[j].prismatic else "rad"
        if np.isfinite(limits.q_min[j]):
            worst = float(q[:, j].min())
            m = worst - limits.q_min[j]
            out.append(ConstraintMargin(f"q_min [{unit}]", lbl, float(limits.q_min[j]), worst, float(m), float(m / span[j]) if np.isfinite(span[j]) else np.nan))
        if np.isfinite(limits.q_max[j]):
            worst = float(q[:, j].max())
            m = limits.q_max[j] - worst
            out.append(ConstraintMargin(f"q_max [{unit}]", lbl, float(limits.q_max[j]), worst, float(m), float(m / span[j]) if np.isfinite(span[j]) else np.nan))
    for name, values, lim in (("|dq| [rad/s]", dq, limits.dq_max), ("|ddq| [rad/s²]", ddq, limits.ddq_max),
                              ("|tau| [N·m]", tau, limits.tau_max)):
        for j in range(robot.n_dof):
            if np.isfinite(lim[j]):
                worst = float(np.abs(values[:, j]).max())
                label = name.replace("rad", "m").replace("N·m", "N") if robot.joints[j].prismatic else name
                out.append(ConstraintMargin(label, f"joint {j + 1}", float(lim[j]), worst, float(lim[j] - worst), float((lim[j] - worst) / lim[j])))
    out += floor_margins(robot, t, q, workspace, trajectory.q0 if start_pose is None else start_pose)
    g, h, labels = workspace.inequalities()
    if len(h):
        for tip, p in zip(robot.tips, np.moveaxis(tip_positions(robot, q), 1, 0)):  # each branch's, the tool last
            what = "tool" if tip == robot.n_dof - 1 else f"tip of {robot.joints[tip].name}"
            for gi, hi, lbl in zip(g, h, labels):
                m = float(hi - (p @ gi).max())
                sign = float(gi.sum())  # +1: upper side, -1: lower side (limit and worst in the axis' own sign)
                out.append(ConstraintMargin("workspace [m]", f"{what} {lbl}", sign * float(hi), sign * float(hi) - sign * m,
                                            m, np.nan))
    return out + obstacle_margins(robot, t, q, workspace) + self_margins(robot, t, q, workspace)


def floor_margins(robot: Robot, t: np.ndarray, q: np.ndarray, workspace: Workspace,
                  start_pose: np.ndarray) -> list[ConstraintMargin]:
    """How close the links' shapes (:meth:`Workspace.shapes`) come to the floor along ``q``: one margin, the shape whose
    height above the floor is least beyond what it must keep (:mod:`dynid.excitation.floor`); none without a floor.

    Parameters
    ----------
    robot : Robot
    t : (N,) array [s]
    q : (N, n_dof) array [rad]
    workspace : Workspace
    start_pose : (n_dof,) array [rad]

    Returns
    -------
    list of ConstraintMargin
        ``limit`` the height above the floor the shape keeps, ``worst`` its lowest; ``where`` names it and when.
    """
    needs = workspace.floor_needs(robot, start_pose)
    if needs is None or not needs.shapes.size:
        return []
    found = FloorDistances(robot, q, workspace.shapes(robot), workspace.floor, needs)
    n, c = np.unravel_index(int(np.argmin(found.dist)), found.dist.shape)
    name = workspace.shapes(robot).names[int(needs.shapes[c])]
    return [ConstraintMargin("floor clearance [m]", f"{name} at t = {float(t[n]):.3g} s", float(needs.height[c]),
                             float(found.height[n, c]), float(found.dist[n, c]), np.nan)]


def self_margins(robot: Robot, t: np.ndarray, q: np.ndarray, workspace: Workspace) -> list[ConstraintMargin]:
    """How close the links' own collision shapes come to each other along ``q`` (:meth:`Workspace.self_pairs`), or
    their capsules where the design keeps them apart: one margin, ``worst`` the smallest distance (limit 0: contact);
    none for capsules the design does not keep apart (:attr:`Workspace.avoid_self_collision`).

    Parameters
    ----------
    robot : Robot
    t : (N,) array [s]
    q : (N, n_dof) array [rad]
    workspace : Workspace

    Returns
    -------
    list of ConstraintMargin
        ``where`` names the two shapes and when.
    """
    if workspace.geometry is None:
        pairs = workspace.self_pairs(robot)
        if not pairs:
            return []
        d = CapsuleSelfDistances(robot, q, workspace.capsule_radius(robot), pairs).dist  # the design's own capsules
        n, c = np.unravel_index(int(np.argmin(d)), d.shape)
        worst, links = float(d[n, c]), capsule_ends(robot)
        return [ConstraintMargin("self clearance [m]", f"links {links[pairs[c][0]][0] + 1} and {links[pairs[c][1]][0] + 1}' "
                                 f"capsules at t = {float(t[n]):.3g} s", 0.0, worst, worst, np.nan)]
    found = shape_clearance(robot, t, q, workspace.geometry)
    if found is None:
        return []
    return [ConstraintMargin("self clearance [m]", f"{found.shapes[0]} and {found.shapes[1]} at t = {found.time:.3g} s",
                             0.0, found.distance, found.distance, np.nan)]


def obstacle_margins(robot: Robot, t: np.ndarray, q: np.ndarray, workspace: Workspace) -> list[ConstraintMargin]:
    """How close the links come to each of the cell's bodies along ``q``: one margin per body that a link can reach,
    ``worst`` the smallest distance beyond the clearance (:meth:`Workspace.cell_distances`; limit 0).

    Parameters
    ----------
    robot : Robot
    t : (N,) array [s]
    q : (N, n_dof) array [rad]
    workspace : Workspace

    Returns
    -------
    list of ConstraintMargin
        ``where`` names the body, the closest link and when.
    """
    if not workspace.obstacles:
        return []
    found = workspace.cell_measure(robot, q)
    shapes = workspace.shapes(robot)
    out = []
    for i, ob in enumerate(workspace.obstacles):
        cols = [c for c, (_, o) in enumerate(found.pairs) if o == i]
        if not cols:
            continue
        n, c, worst = found.smallest(cols)
        g = found.pairs[c][0]
        out.append(ConstraintMargin("obstacle clearance [m]", f"{ob.name}: link {int(shapes.link[g]) + 1} "
                                    f"({shapes.names[g]}) at t = {float(t[n]):.3g} s", 0.0, worst, worst, np.nan))
    return out


@dataclass(frozen=True)
class LowestPoint:
    """The lowest point the arm's shapes reach along a trajectory, against gravity.

    Attributes
    ----------
    height : float [m]
        Above the base frame's origin, along the robot's up (``-gravity``); below 0, the arm goes below its base.
    point : str
        The shape's name (:meth:`Workspace.shapes`).
    time : float [s]
        When.
    """

    height: float
    point: str
    time: float

    def to_dict(self) -> dict:
        """JSON-ready.

        Returns
        -------
        dict
        """
        return {"height": self.height, "point": self.point, "time": self.time}


def lowest_point(robot: Robot, t: np.ndarray, q: np.ndarray, workspace: Workspace) -> LowestPoint:
    """Where a trajectory takes the arm's shapes (:meth:`Workspace.shapes`) lowest: what a design without a floor
    (:attr:`Workspace.floor`) leaves unchecked, the surface the robot stands on.

    Parameters
    ----------
    robot : Robot
    t : (N,) array [s]
    q : (N, n_dof) array [rad]
    workspace : Workspace

    Returns
    -------
    LowestPoint
        Heights along ``-robot.gravity`` (``+z`` without gravity), from the base frame's origin.
    """
    g = np.asarray(robot.gravity, dtype=float)
    up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0 else np.array([0.0, 0.0, 1.0])
    shapes = workspace.shapes(robot)
    moving = np.flatnonzero(shapes.link >= 0)
    heights = lowest_points(robot, q, shapes, moving, up=up) @ up  # (N, m)
    n, k = np.unravel_index(int(np.argmin(heights)), heights.shape)
    return LowestPoint(float(heights[n, k]), shapes.names[int(moving[k])], float(t[n]))
