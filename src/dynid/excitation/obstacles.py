"""The cell's bodies an excitation trajectory keeps its links clear of (issue "An excitation safe to run on the real
robot", item 1): boxes, cylinders and spheres placed in the base frame, and what measuring against them shares.

The links' distances to the bodies are measured on the links' shapes (:mod:`dynid.excitation.link_geometry`: the
robot file's collision shapes, or capsules about the joint origins). Distances are coal's (Pan, Chitta & Manocha,
"FCL: a general purpose library for collision and proximity queries", ICRA 2012), signed (negative: overlap).
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

__all__ = ["Obstacle", "ObstacleDistances", "capsule_ends", "link_segments"]

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


def capsule_ends(robot: Robot) -> list[tuple[int, int]]:
    """The links' skeleton as segments: ``(link, end)`` for each, 0-based, in the links' order. A link runs from its
    joint's origin to each joint it carries (``end`` that joint), or, carrying none, to the flange (the last link) or
    nowhere (another branch's tip: ``end`` -1, a point). A serial chain has one segment per link, ``(k, k + 1)`` and
    ``(n - 1, -1)``; a torso that carries two arms has one to each arm's first joint.

    Parameters
    ----------
    robot : Robot

    Returns
    -------
    list of (int, int)
    """
    parents, n = robot.parents, robot.n_dof
    ends = [(k, c) for k in range(n) for c in range(n) if parents[c] == k]
    ends += [(k, -1) for k in range(n) if not np.any(parents == k)]
    return sorted(ends, key=lambda e: e[0])  # stable: a link's segments in its children's order


def link_segments(robot: Robot, q: np.ndarray) -> np.ndarray:
    """The links' segments of :func:`capsule_ends` along ``q`` (the last link's to the flange).

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array [rad, or m for a prismatic joint]

    Returns
    -------
    (N, n_segments, 2, 3) ndarray [m]
        Each segment's two ends in the base frame.
    """
    rots, orig = forward_kinematics(robot, q)
    flange = orig[:, -1] + rots[:, -1] @ robot.tool_translation
    ends = capsule_ends(robot)
    start = orig[:, [k for k, _ in ends]]
    stop = np.stack([orig[:, c] if c >= 0 else flange if k == robot.n_dof - 1 else orig[:, k] for k, c in ends], axis=1)
    return np.stack([start, stop], axis=2)


def _segment_jacobians(robot: Robot, q: np.ndarray) -> np.ndarray:
    """(N, n_segments, 2, 3, n_dof): the positional Jacobians of each :func:`link_segments` segment's two ends."""
    _, jo = origins_jacobian(robot, q)
    _, jt = tool_jacobian(robot, q)
    ends = capsule_ends(robot)
    stop = np.stack([jo[:, c] if c >= 0 else jt if k == robot.n_dof - 1 else jo[:, k] for k, c in ends], axis=1)
    return np.stack([jo[:, [k for k, _ in ends]], stop], axis=2)


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
