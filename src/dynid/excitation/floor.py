"""How high the links' shapes stay above the floor plane along a trajectory (issue "Every assurance checked on what the
user meets", item 1: the floor measured on the links' shapes, never on their joint origins).

Each shape's lowest point is its support point in the direction of gravity (the point of a convex shape farthest
along ``-z``): for a convex hull the lowest of its vertices, for a box, sphere, capsule, cylinder or ellipsoid the
point its closed form gives (Ericson, "Real-Time Collision Detection", 2005, §3.8 and §4.3.1). Its height above the
plane is the shape's signed distance to it (negative: under the floor). The gradient is the envelope theorem's:
moving joint ``j`` (up to the shape's link) moves the lowest point ``p`` by ``z_j × (p - o_j)``, and its height by
that vector's z component; the point itself is held (at a face or an edge parallel to the floor any lowest point
gives the same rate).

A shape whose lowest point does not move with the joints (a housing about a vertical first axis) rests where the
description puts it, as the base does: it is not constrained. A shape whose lowest point starts within the clearance
of the floor (a shoulder housing about a horizontal axis, a few centimetres above the table the robot stands on) is
held no lower than it starts (:data:`START_SLACK` below), since no motion can lift it; both are said. A collision
shape that starts under the floor is refused by the design (the floor's height or the start pose is wrong); an
estimated capsule may (its radius is a guess), and is held no lower than it starts, said as such.
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np

from ..dynamics.sensitivity import frames_and_axes, point_motion
from ..model.robot import Robot
from .obstacles import ObstacleDistances

__all__ = ["FloorDistances", "FloorNeeds", "floor_needs", "lowest_points"]

START_SLACK = 1e-3
"""[m] A shape that starts within the clearance of the floor is held no lower than this below its start height: a
tolerance for the optimiser's grid, far below what a table's flatness is known to."""


def _support_down(shape, rotation: np.ndarray, up: np.ndarray) -> np.ndarray:
    """The lowest point along ``up`` (3,) of ``shape`` (in its own frame) for each of ``rotation`` (N, 3, 3), the
    shape's orientation in the base frame: (N, 3)."""
    up = np.einsum("nij,i->nj", rotation, up)  # up in the shape's frame, one row per sample
    if isinstance(shape, coal.ConvexBase):
        points = np.asarray(shape.points(), dtype=float)
        return points[np.argmin(up @ points.T, axis=1)]
    if isinstance(shape, coal.Box):
        return -np.sign(up) * np.asarray(shape.halfSide, dtype=float)
    if isinstance(shape, coal.Sphere):
        return -float(shape.radius) * up
    if isinstance(shape, (coal.Capsule, coal.Cylinder)):
        end = np.zeros_like(up)
        end[:, 2] = -float(shape.halfLength) * np.where(up[:, 2] >= 0, 1.0, -1.0)
        if isinstance(shape, coal.Capsule):
            return end - float(shape.radius) * up
        flat = up.copy()
        flat[:, 2] = 0.0
        norm = np.linalg.norm(flat, axis=1, keepdims=True)
        return end - float(shape.radius) * np.where(norm > 1e-12, flat / np.where(norm > 1e-12, norm, 1.0), 0.0)
    if isinstance(shape, coal.Ellipsoid):
        radii2 = np.asarray(shape.radii, dtype=float) ** 2
        return -(radii2 * up) / np.sqrt((radii2 * up**2).sum(axis=1, keepdims=True))
    shape.computeLocalAABB()  # another shape (a cone): its bounding sphere's lowest point, lower than its own
    return np.asarray(shape.aabb_center, dtype=float) - float(shape.aabb_radius) * up


def lowest_points(robot: Robot, q: np.ndarray, geometry, shapes=None, *, up=(0.0, 0.0, 1.0)) -> np.ndarray:
    """Each shape's lowest point in the base frame along ``q`` (module docstring).

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array [rad]
    geometry : LinkGeometry
        The links' shapes (:mod:`dynid.excitation.link_geometry`).
    shapes : sequence of int, optional
        Which shapes (default every one).
    up : (3,) array
        The unit vector lowest is measured against (default the base's z).

    Returns
    -------
    (N, m, 3) array [m]
    """
    up = np.asarray(up, dtype=float)
    shapes = range(len(geometry.shapes)) if shapes is None else list(shapes)
    rotation, position = geometry.poses(robot, np.atleast_2d(np.asarray(q, dtype=float)))
    out = np.empty((rotation.shape[0], len(shapes), 3))
    for c, g in enumerate(shapes):
        local = _support_down(geometry.shapes[g], rotation[:, g], up)
        out[:, c] = position[:, g] + np.einsum("nij,nj->ni", rotation[:, g], local)
    return out


@dataclass(frozen=True)
class FloorNeeds:
    """Which shapes the floor constraint holds and how high each must stay.

    Attributes
    ----------
    shapes : (m,) int array
        Shape indices whose lowest point moves with the joints.
    height : (m,) array [m]
        The lowest each may go, above the floor: the clearance, or less for a shape that starts within it.
    start : (m,) array [m]
        Each one's height above the floor at the start pose.
    clearance : float [m]
    resting : tuple of int
        The shapes on a moving link whose lowest point never moves (not constrained).
    """

    shapes: np.ndarray
    height: np.ndarray
    start: np.ndarray
    clearance: float
    resting: tuple[int, ...] = ()

    @property
    def within(self) -> list[int]:
        """The positions (into :attr:`shapes`) of the shapes held at their start height, below the clearance."""
        return [int(c) for c in np.flatnonzero(self.height < self.clearance)]


def floor_needs(robot: Robot, geometry, floor: float, clearance: float, start_pose: np.ndarray) -> FloorNeeds:
    """The shapes the floor holds and the height each must keep (module docstring).

    Parameters
    ----------
    robot : Robot
    geometry : LinkGeometry
    floor : float [m]
    clearance : float [m]
    start_pose : (n_dof,) array [rad]

    Returns
    -------
    FloorNeeds
    """
    q = robot.limits.random_positions(24, 0)
    on_links = np.flatnonzero(np.asarray(geometry.link) >= 0)
    z = lowest_points(robot, q, geometry, on_links)[..., 2]
    moves = np.ptp(z, axis=0) > 1e-6
    shapes = on_links[moves]
    start = lowest_points(robot, np.asarray(start_pose, dtype=float)[None], geometry, shapes)[0, :, 2] - floor
    height = np.minimum(clearance, start - START_SLACK)  # below the floor at the start: the caller says so
    return FloorNeeds(shapes, height, start, float(clearance), tuple(int(g) for g in on_links[~moves]))


class FloorDistances:
    """The shapes' heights above the floor along ``q`` less the height each must keep (zero: held), measured once
    (``dist`` (N, m)), their gradient on demand (module docstring).

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array [rad]
    geometry : LinkGeometry
    floor : float [m]
    needs : FloorNeeds
    """

    def __init__(self, robot: Robot, q: np.ndarray, geometry, floor: float, needs: FloorNeeds):
        self.robot, self.geometry, self.needs = robot, geometry, needs
        self.q = np.atleast_2d(np.asarray(q, dtype=float))
        self.points = lowest_points(robot, self.q, geometry, needs.shapes)
        self.height = self.points[..., 2] - floor  # (N, m)
        self.dist = self.height - needs.height[None]

    def distances(self, *, gradient: bool = False) -> ObstacleDistances:
        """The distances, with their gradient ``∂/∂q`` (N, m, n_dof) [m/rad] if asked.

        Parameters
        ----------
        gradient : bool

        Returns
        -------
        ObstacleDistances
            ``pairs`` (shape, -1); ``links`` each shape's link.
        """
        links = tuple(int(self.geometry.link[g]) for g in self.needs.shapes)
        grad = None
        if gradient and links:
            _, orig, axes = frames_and_axes(self.robot, self.q)
            lever = self.points[:, :, None, :] - orig[:, None, :, :]  # (N, m, n_dof, 3)
            moved = point_motion(self.robot, axes, lever)  # z_j × (p - o_j), or z_j along a prismatic joint
            grad = moved[..., 2] * self.robot.carries[:, list(links)].T[None]
        return ObstacleDistances([(int(g), -1) for g in self.needs.shapes], self.dist.copy(), grad, links)
