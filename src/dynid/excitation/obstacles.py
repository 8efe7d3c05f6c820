"""The cell's bodies an excitation trajectory keeps its links clear of (issue "An excitation safe to run on the real
robot", item 1): boxes, cylinders and spheres placed in the base frame, and every link's signed distance to them with
its gradient in the joint angles.

Each link is the capsule of radius ``clearance`` about the segment from its joint's origin to the next joint's (the
last link's to the flange), as in :mod:`dynid.excitation.collision`; a distance of zero is the skeleton ``clearance``
from the body's surface. Distances are coal's (Pan, Chitta & Manocha, "FCL: a general purpose library for collision
and proximity queries", ICRA 2012), signed (negative: overlap). Their gradient is the envelope theorem's: moving the
segment's point nearest to the body by ``δ`` changes the distance by ``n·δ``, ``n`` the unit normal away from the
body, and that point moves with ``(1 - s) J_a + s J_b`` (``J`` the positional Jacobians of the segment's ends,
:func:`dynid.dynamics.sensitivity.origins_jacobian`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import coal
import numpy as np
from scipy.spatial.transform import Rotation

from .._util.reprs import short_repr
from ..dynamics.kinematics import forward_kinematics
from ..dynamics.sensitivity import origins_jacobian, tool_jacobian
from ..exceptions import ConfigError
from ..model.robot import Robot

__all__ = ["Obstacle", "ObstacleDistances", "CapsuleDistances", "obstacle_distances", "reachable_pairs"]

SIZES = {"box": 3, "cylinder": 2, "sphere": 1}
"""How many numbers each shape's ``size`` holds: a box's full lengths along x, y, z; a cylinder's radius and length
(along its own z); a sphere's radius [m]."""


@dataclass(frozen=True)
class Obstacle:
    """A body of the robot's cell, in the base frame.

    Attributes
    ----------
    shape : {"box", "cylinder", "sphere"}
    size : (k,) array [m]
        Box: full lengths along its x, y, z; cylinder: radius and length (along its z); sphere: radius.
    position : (3,) array [m]
        The body's centre.
    rpy : (3,) array [rad]
        Its orientation as roll, pitch, yaw about the base's fixed x, y, z axes (URDF's ``rpy``).
    name : str
        Named in messages.

    Raises
    ------
    ConfigError
        An unknown shape, a size with the wrong count or a non-positive entry, a position or rpy that is not three
        finite numbers.
    """

    shape: str
    size: np.ndarray
    position: np.ndarray
    rpy: np.ndarray = field(default_factory=lambda: np.zeros(3))
    name: str = "obstacle"

    def __post_init__(self) -> None:
        where = f"obstacle {self.name!r}"
        if self.shape not in SIZES:
            raise ConfigError(f"{where}: shape: expected one of {', '.join(SIZES)}, got {self.shape!r}")
        size = np.atleast_1d(np.asarray(self.size, dtype=float))
        if size.shape != (SIZES[self.shape],) or not np.all(np.isfinite(size) & (size > 0)):
            raise ConfigError(f"{where}: size: a {self.shape} takes {SIZES[self.shape]} positive lengths in metres "
                              f"({_SIZE_TEXT[self.shape]}), got {np.asarray(self.size).tolist()}")
        object.__setattr__(self, "size", size)
        for name in ("position", "rpy"):
            v = np.asarray(getattr(self, name), dtype=float)
            if v.shape != (3,) or not np.all(np.isfinite(v)):
                raise ConfigError(f"{where}: {name}: expected three finite numbers, got {np.asarray(getattr(self, name)).tolist()}")
            object.__setattr__(self, name, v)

    def geometry(self):
        """coal's shape and pose.

        Returns
        -------
        (coal.ShapeBase, coal.Transform3s)
        """
        s = self.size
        shape = {"box": lambda: coal.Box(*s), "cylinder": lambda: coal.Cylinder(s[0], s[1]),
                 "sphere": lambda: coal.Sphere(s[0])}[self.shape]()
        return shape, coal.Transform3s(Rotation.from_euler("xyz", self.rpy).as_matrix(), self.position)

    def bounding_radius(self) -> float:
        """Radius of a sphere about :attr:`position` that holds the body.

        Returns
        -------
        float [m]
        """
        s = self.size
        return float({"box": lambda: 0.5 * np.linalg.norm(s), "cylinder": lambda: np.hypot(s[0], 0.5 * s[1]),
                      "sphere": lambda: s[0]}[self.shape]())

    def to_dict(self) -> dict:
        """JSON-ready.

        Returns
        -------
        dict
        """
        return {"name": self.name, "shape": self.shape, "size": self.size.tolist(), "position": self.position.tolist(),
                "rpy": self.rpy.tolist()}


GJK_TOLERANCE = 1e-9
"""coal's convergence tolerance for the shapes it measures by GJK/EPA (a cylinder) [m]: its default (1e-6) makes the
distance a staircase too coarse for the optimiser's line search."""

_SIZE_TEXT = {"box": "lengths along x, y, z", "cylinder": "radius, length", "sphere": "radius"}


def _segments(robot: Robot, q: np.ndarray) -> np.ndarray:
    """(N, n_dof, 2, 3): each link's segment from its joint's origin to the next (the flange for the last)."""
    rots, orig = forward_kinematics(robot, q)
    flange = orig[:, -1] + rots[:, -1] @ robot.tool_translation
    ends = np.concatenate([orig[:, 1:], flange[:, None]], axis=1)
    return np.stack([orig, ends], axis=2)


def _segment_jacobians(robot: Robot, q: np.ndarray) -> np.ndarray:
    """(N, n_dof, 2, 3, n_dof): the positional Jacobians of each link segment's two ends."""
    _, jo = origins_jacobian(robot, q)
    _, jt = tool_jacobian(robot, q)
    ends = np.concatenate([jo[:, 1:], jt[:, None]], axis=1)
    return np.stack([jo, ends], axis=2)


def _capsules(seg: np.ndarray, radius: float):
    """coal's capsule of ``radius`` about one link's segments (N, 2, 3) and its N poses (of no length, a sphere, for a
    segment of no length). A link's segment keeps its length (revolute joints), so one shape serves every pose."""
    axis = seg[:, 1] - seg[:, 0]
    length = np.linalg.norm(axis, axis=1)
    if length.max() <= 1e-12:
        rotations = np.broadcast_to(np.eye(3), (seg.shape[0], 3, 3))
        shape = coal.Capsule(radius, 0.0)  # a sphere: coal measures it as the capsule of no length
    else:  # coal's capsule lies along z: turn z onto the segment
        z = axis / length[:, None]
        x = np.cross(z, np.where(np.abs(z[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]]))
        x /= np.linalg.norm(x, axis=1, keepdims=True)
        rotations = np.stack([x, np.cross(z, x), z], axis=2)
        shape = coal.Capsule(radius, float(length[0]))
    centres = 0.5 * (seg[:, 0] + seg[:, 1])
    return shape, [coal.Transform3s(r, c) for r, c in zip(rotations, centres)]


def reachable_pairs(robot: Robot, obstacles, radius: float) -> list[tuple[int, int]]:
    """The (link, obstacle) pairs (0-based) that can come within ``radius`` of each other: a link whose segment moves
    and whose reach from the first joint's origin (the sum of the joint offsets up to its far end) meets the body's
    bounding sphere. A bound, not a sample: a pair left out cannot touch on any pose.

    Parameters
    ----------
    robot : Robot
    obstacles : sequence of Obstacle
    radius : float [m]

    Returns
    -------
    list of (int, int)
    """
    lengths = [float(np.linalg.norm(jt.translation)) for jt in robot.joints[1:]] + [float(np.linalg.norm(robot.tool_translation))]
    reach = np.cumsum(lengths)  # link k's far end is at most reach[k] from joint 1's origin
    centre = forward_kinematics(robot, np.zeros((1, robot.n_dof)))[1][0, 0]
    out = []
    for i, ob in enumerate(obstacles):
        gap = float(np.linalg.norm(ob.position - centre)) - ob.bounding_radius() - radius
        out += [(k, i) for k in range(robot.n_dof) if reach[k] >= gap]
    return sorted(out)


def distance_above(shape_a, pose_a, shape_b, pose_b, request, bound: float):
    """coal's distance of two shapes where it is at least ``bound``, a lower bound of it (their bounding spheres'
    distance). On a deep overlap coal's penetration depth (EPA) can fail at :data:`GJK_TOLERANCE` and return
    ``-DBL_MAX`` (two cylinders of the Unitree Z1 do; coal-library/coal#325 describes another case), which a design
    would take as an overlap of 1.8e308 m and a check would report: the distance is then asked again at coal's default
    tolerances, and where that fails too, ``bound`` stands for it.

    Parameters
    ----------
    shape_a, shape_b : coal.CollisionGeometry
    pose_a, pose_b : coal.Transform3s
    request : coal.DistanceRequest
    bound : float [m]
        A distance the shapes' cannot fall below (``-inf``: none known).

    Returns
    -------
    coal.DistanceResult or None
        None where coal's distance lies below ``bound`` by more than coal's tolerance: ``bound`` stands for it.
    """
    result = coal.DistanceResult()
    coal.distance(shape_a, pose_a, shape_b, pose_b, request, result)
    if result.min_distance >= bound - 1e-6:
        return result
    result = coal.DistanceResult()  # again at coal's defaults (made only here: most distances are asked once)
    coal.distance(shape_a, pose_a, shape_b, pose_b, coal.DistanceRequest(), result)
    return result if result.min_distance >= bound - 1e-6 else None


def away_from(result) -> np.ndarray:
    """The unit vector from the first object's nearest point to the second's (coal's normal where they overlap).

    Parameters
    ----------
    result : coal.DistanceResult

    Returns
    -------
    (3,) array
    """
    return nearest_points(result)[2]


def nearest_points(result) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """coal's two nearest points and the unit vector from the first to the second (coal's normal where they overlap).

    Parameters
    ----------
    result : coal.DistanceResult

    Returns
    -------
    first, second : (3,) arrays [m]
    unit : (3,) array
    """
    first, second = result.getNearestPoint1(), result.getNearestPoint2()
    gap = second - first  # divided by its norm as np.linalg.norm computes it (sqrt of the dot), without its checks
    return first, second, gap / math.sqrt(gap.dot(gap)) if result.min_distance > 1e-9 else np.asarray(result.normal)


def _distance_gradient(result, seg: np.ndarray, jac: np.ndarray) -> np.ndarray:
    """(n_dof,) ``∂distance/∂q`` of one capsule from coal's result: the envelope theorem (module docstring)."""
    a, b = seg
    ab = b - a
    near = result.getNearestPoint1()
    s = float(np.clip((near - a) @ ab / (ab @ ab), 0.0, 1.0)) if ab @ ab > 1e-24 else 0.0
    # moving the capsule away from the body raises the distance
    return -away_from(result) @ ((1 - s) * jac[0] + s * jac[1])


def _sphere_gradient(gap: np.ndarray, jac: np.ndarray) -> np.ndarray:
    """(n_dof,) ``∂distance/∂q`` of the bounding spheres' distance, ``gap`` from the body's centre to the capsule's
    middle, which moves as the mean of its segment's ends (``jac`` (2, 3, n_dof))."""
    return gap / max(float(np.linalg.norm(gap)), 1e-12) @ (0.5 * (jac[0] + jac[1]))


@short_repr
@dataclass(frozen=True)
class ObstacleDistances:
    """Every checked link's signed distance to every body along a trajectory.

    Attributes
    ----------
    pairs : list of (int, int)
        (link, obstacle), 0-based; (shape, obstacle) for a link's own collision shapes
        (:func:`dynid.excitation.link_geometry.shape_distances`).
    distance : (N, n_pairs) array [m]
        Capsule surface to the body's surface (negative: overlap); a shape's distance less the clearance.
    gradient : (N, n_pairs, n_dof) array [m/rad] or None
        ``∂distance/∂q``.
    links : tuple of int
        The link (0-based) of each pair (default: the pair's first index).
    """

    pairs: list[tuple[int, int]]
    distance: np.ndarray
    gradient: np.ndarray | None = None
    links: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        if not self.links:
            object.__setattr__(self, "links", tuple(k for k, _ in self.pairs))


class CapsuleDistances:
    """:func:`obstacle_distances` measured once along ``q`` (``dist``), with :meth:`distances` giving them again with
    their gradient (:meth:`dynid.excitation.constraints.Workspace.cell_measure` by the links' capsules).

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array [rad]
    obstacles : sequence of Obstacle
    clearance : float [m]
    pairs : list of (int, int)
        (link, obstacle) pairs.
    """

    def __init__(self, robot: Robot, q: np.ndarray, obstacles, clearance: float, pairs):
        self._args = (robot, q, obstacles, clearance, pairs)
        self._values = obstacle_distances(robot, q, obstacles, clearance, pairs=pairs)
        self.dist = self._values.distance

    def distances(self, *, gradient: bool = False) -> ObstacleDistances:
        """The distances, with their gradient if asked (computed again).

        Parameters
        ----------
        gradient : bool

        Returns
        -------
        ObstacleDistances
        """
        if not gradient:
            return self._values
        robot, q, obstacles, clearance, pairs = self._args
        return obstacle_distances(robot, q, obstacles, clearance, pairs=pairs, gradient=True)


def obstacle_distances(robot: Robot, q: np.ndarray, obstacles, radius: float, *, pairs=None,
                       gradient: bool = False) -> ObstacleDistances:
    """Signed distances of the links' capsules to the cell's bodies along ``q`` (module docstring).

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array [rad]
    obstacles : sequence of Obstacle
    radius : float [m]
        The links' capsule radius (:attr:`dynid.excitation.constraints.Workspace.clearance`).
    pairs : list of (int, int), optional
        (link, obstacle) pairs to check (default :func:`reachable_pairs`).
    gradient : bool
        Also the distances' gradient in ``q``.

    Returns
    -------
    ObstacleDistances
    """
    q = np.atleast_2d(np.asarray(q, dtype=float))
    pairs = reachable_pairs(robot, obstacles, radius) if pairs is None else list(pairs)
    seg = _segments(robot, q)
    jac = _segment_jacobians(robot, q) if gradient and pairs else None
    bodies = [ob.geometry() for ob in obstacles]
    dist = np.empty((q.shape[0], len(pairs)))
    grad = np.zeros((q.shape[0], len(pairs), robot.n_dof)) if jac is not None else None
    request = coal.DistanceRequest()
    request.gjk_tolerance, request.epa_tolerance = GJK_TOLERANCE, GJK_TOLERANCE
    capsules: dict = {}
    for c, (k, i) in enumerate(pairs):
        body, pose = bodies[i]
        if k not in capsules:
            capsules[k] = _capsules(seg[:, k], radius)
        cap, cap_poses = capsules[k]
        middle, half = seg[:, k].mean(axis=1), 0.5 * np.linalg.norm(seg[:, k, 1] - seg[:, k, 0], axis=1)
        bound = (np.linalg.norm(middle - obstacles[i].position, axis=1) - half - radius
                 - obstacles[i].bounding_radius())  # the spheres holding the capsule and the body
        for n in range(q.shape[0]):
            result = distance_above(cap, cap_poses[n], body, pose, request, bound[n])
            dist[n, c] = bound[n] if result is None else result.min_distance
            if grad is not None and jac is not None:
                grad[n, c] = (_sphere_gradient(middle[n] - obstacles[i].position, jac[n, k]) if result is None
                              else _distance_gradient(result, seg[n, k], jac[n, k]))
    return ObstacleDistances(pairs, dist, grad)
