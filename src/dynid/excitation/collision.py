"""How close an excitation trajectory brings the arm's links to each other (issue "An excitation safe to run on the
real robot", item 2: checked at the controller's rate, said before it runs).

Each link is a capsule of the workspace's radius (:meth:`dynid.excitation.constraints.Workspace.capsule_radius`) about the
segment from its joint's origin to the next joint's (the last link's to the flange; on a robot with branches, one to
each joint the link carries, :func:`~dynid.excitation.obstacles.capsule_ends`): the robot's skeleton, which a
description without collision meshes still gives. Distances between capsules are coal's (the collision library of
Pinocchio's geometry models; Pan, Chitta & Manocha, "FCL: a general purpose library for collision and proximity
queries", ICRA 2012) for the checks; the design keeps the capsules apart by the segments' closest points
(:func:`closest_points`, Ericson, "Real-Time Collision Detection", 2005, §5.1.9) with their gradient, every sample
of its grid at once (:class:`CapsuleSelfDistances`), so that the check measures with another code. The pairs that can touch are, as MoveIt's setup assistant finds them, every pair of links that
are not neighbours (a link and the one that carries it), less the pairs whose capsules overlap on almost every pose of a random sample (a
wrist whose axes meet: such a pair is in contact by construction of the skeleton, not by the motion).
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np

from ..model.robot import Robot
from .link_geometry import LinkGeometry, self_distances, self_pairs
from .obstacles import ObstacleDistances, _capsules, _segment_jacobians, capsule_ends, link_segments

__all__ = ["CapsuleSelfDistances", "SelfClearance", "closest_points", "self_clearance", "shape_clearance",
           "touching_pairs"]

ALWAYS = 0.95
"""A pair whose capsules overlap on this share of random poses or more is in contact by construction: not checked."""


@dataclass(frozen=True)
class SelfClearance:
    """The smallest distance between two links' capsules along a trajectory.

    Attributes
    ----------
    distance : float [m]
        Surface to surface (negative: the capsules overlap).
    pair : (int, int)
        The links (1-based: link ``k`` is the one joint ``k`` moves).
    time : float [s]
        When.
    pairs : int
        How many pairs were checked.
    shapes : tuple of str
        The two collision shapes where the links are their URDF's own (:func:`shape_clearance`); empty for capsules.
    """

    distance: float
    pair: tuple[int, int]
    time: float
    pairs: int
    shapes: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        """JSON-ready.

        Returns
        -------
        dict
        """
        return {"distance": self.distance, "links": list(self.pair), "time": self.time, "pairs_checked": self.pairs,
                **({"shapes": list(self.shapes)} if self.shapes else {})}


def _distance(a: np.ndarray, b: np.ndarray, radius: float) -> float:
    """Surface distance of two capsules of ``radius`` about segments ``a`` and ``b`` (2, 3) (coal)."""
    (cap_a, [pose_a]), (cap_b, [pose_b]) = _capsules(a[None], radius), _capsules(b[None], radius)
    result = coal.DistanceResult()
    coal.distance(cap_a, pose_a, cap_b, pose_b, coal.DistanceRequest(), result)
    return float(result.min_distance)


def touching_pairs(robot: Robot, radius: float, samples: int = 200, rng=0) -> list[tuple[int, int]]:
    """The pairs of the links' capsules (0-based, :func:`~dynid.excitation.obstacles.capsule_ends`: one per link on a
    serial chain) that can touch: not on one link or on neighbours (a link and the one that carries it), and not
    overlapping on :data:`ALWAYS` of random poses within the joint limits (module docstring).

    Parameters
    ----------
    robot : Robot
    radius : float [m]
    samples : int
    rng : int

    Returns
    -------
    list of (int, int)
    """
    q = robot.limits.random_positions(samples, rng)
    links, parents = [k for k, _ in capsule_ends(robot)], robot.parents
    candidates = [(a, b) for a in range(len(links)) for b in range(a + 1, len(links))  # links[a] <= links[b]: the
                  if links[a] != links[b] and parents[links[b]] != links[a]]  # carrier comes first
    if not candidates:
        return []
    overlap = (CapsuleSelfDistances(robot, q, radius, candidates).dist < 0).mean(axis=0)
    return [pair for pair, share in zip(candidates, overlap) if share < ALWAYS]


SCREEN = 1e-3
"""coal measures a trajectory's self-distances only at the samples and pairs whose capsules' distance in closed form
(:class:`CapsuleSelfDistances`, the design's own: the segments' distance less the radii) lies within this of the
smallest [m]. coal's capsule distance is that same quantity to far less than this, so its minimum over every sample and
pair is its minimum over these."""


def self_clearance(robot: Robot, t: np.ndarray, q: np.ndarray, radius: float) -> SelfClearance | None:
    """The smallest distance between links that can touch (:func:`touching_pairs`) along ``q``.

    Parameters
    ----------
    robot : Robot
    t : (N,) array [s]
    q : (N, n_dof) array [rad]
        The trajectory at the controller's rate (or any grid).
    radius : float [m]
        The links' capsule radius.

    Returns
    -------
    SelfClearance or None
        None where no pair can touch (a short chain).
    """
    pairs = touching_pairs(robot, radius)
    if not pairs:
        return None
    q = np.asarray(q, dtype=float)
    seg = link_segments(robot, q)
    closed_form = CapsuleSelfDistances(robot, q, radius, pairs).dist  # (N, pairs): where to ask coal
    best = (np.inf, pairs[0], 0)
    for k, p in np.argwhere(closed_form <= closed_form.min() + SCREEN):  # in the order of every sample and pair
        i, j = pairs[p]
        d = _distance(seg[k, i], seg[k, j], radius)
        if d < best[0]:
            best = (d, (i, j), int(k))
    d, (i, j), k = best
    links = capsule_ends(robot)
    return SelfClearance(float(d), (links[i][0] + 1, links[j][0] + 1), float(np.asarray(t)[k]), len(pairs))


def shape_clearance(robot: Robot, t: np.ndarray, q: np.ndarray, geometry: LinkGeometry) -> SelfClearance | None:
    """The smallest distance between the links' own collision shapes that can touch
    (:func:`dynid.excitation.link_geometry.self_pairs`) along ``q``.

    Parameters
    ----------
    robot : Robot
    t : (N,) array [s]
    q : (N, n_dof) array [rad]
    geometry : LinkGeometry

    Returns
    -------
    SelfClearance or None
        ``pair`` the links (0 for the base); None where no pair can touch.
    """
    pairs = self_pairs(robot, geometry)
    if not pairs:
        return None
    d = self_distances(robot, q, geometry, pairs).distance
    n, c = np.unravel_index(int(np.argmin(d)), d.shape)
    g, h = pairs[c]
    return SelfClearance(float(d[n, c]), (int(geometry.link[g]) + 1, int(geometry.link[h]) + 1), float(np.asarray(t)[n]),
                         len(pairs), (geometry.names[g], geometry.names[h]))


def closest_points(p1: np.ndarray, q1: np.ndarray, p2: np.ndarray, q2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The parameters of the closest points of segments ``p1 q1`` and ``p2 q2`` (Ericson 2005, §5.1.9), for arrays of
    segments at once.

    Parameters
    ----------
    p1, q1, p2, q2 : (..., 3) arrays
        The segments' ends.

    Returns
    -------
    s, t : (...) arrays in [0, 1]
        The closest points are ``p1 + s (q1 - p1)`` and ``p2 + t (q2 - p2)``; a segment of no length has 0.
    """
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a, e = np.einsum("...i,...i", d1, d1), np.einsum("...i,...i", d2, d2)
    b, c, f = np.einsum("...i,...i", d1, d2), np.einsum("...i,...i", d1, r), np.einsum("...i,...i", d2, r)
    tiny = 1e-24
    a_safe, e_safe = np.where(a > tiny, a, 1.0), np.where(e > tiny, e, 1.0)
    denom = a * e - b * b
    s = np.where(denom > tiny * np.maximum(a * e, tiny), np.clip((b * f - c * e) / np.where(denom > 0, denom, 1.0), 0, 1), 0.0)
    t = (b * s + f) / e_safe
    s = np.where(t < 0, np.clip(-c / a_safe, 0, 1), np.where(t > 1, np.clip((b - c) / a_safe, 0, 1), s))
    t = np.clip(t, 0, 1)
    s = np.where(a > tiny, s, 0.0)  # a point: s = 0, t its projection on the other
    t = np.where(e > tiny, np.where(a > tiny, t, np.clip(f / e_safe, 0, 1)), 0.0)
    s = np.where((e <= tiny) & (a > tiny), np.clip(-c / a_safe, 0, 1), s)
    return s, t


class CapsuleSelfDistances:
    """Surface distances between pairs of the links' capsules of radius ``radius`` along ``q`` (the segments' distance
    less ``2·radius``: zero is contact), measured once (``dist``), with their gradient on demand: ``n·(v_i - v_j)``,
    ``v`` each closest point's velocity per joint (the envelope theorem: the closest points' parameters held), ``n``
    the unit vector from ``j``'s closest point to ``i``'s. The interface of
    :class:`dynid.excitation.link_geometry.SelfDistances`, for a design without collision shapes.

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array [rad]
    radius : float [m]
    pairs : list of (int, int)
        Capsules, 0-based (:func:`touching_pairs`; one per link on a serial chain).
    """

    def __init__(self, robot: Robot, q: np.ndarray, radius: float, pairs):
        self.robot, self.q, self.pairs = robot, np.atleast_2d(np.asarray(q, dtype=float)), list(pairs)
        seg = link_segments(robot, self.q)  # (N, n_segments, 2, 3)
        i, j = np.array([p[0] for p in self.pairs], dtype=int), np.array([p[1] for p in self.pairs], dtype=int)
        a, b = seg[:, i], seg[:, j]  # (N, P, 2, 3)
        self._s, self._t = closest_points(a[..., 0, :], a[..., 1, :], b[..., 0, :], b[..., 1, :])
        self._gap = (a[..., 0, :] + self._s[..., None] * (a[..., 1, :] - a[..., 0, :])
                     - b[..., 0, :] - self._t[..., None] * (b[..., 1, :] - b[..., 0, :]))
        self.dist = np.linalg.norm(self._gap, axis=-1) - 2.0 * radius

    def distances(self, *, gradient: bool = False) -> ObstacleDistances:
        """:attr:`dist` with the pairs (the class docstring).

        Parameters
        ----------
        gradient : bool
            Also ``∂distance/∂q`` (N, n_pairs, n_dof) [m/rad].

        Returns
        -------
        ObstacleDistances
            ``pairs`` as given, ``links`` the first link of each.
        """
        links = capsule_ends(self.robot)
        return ObstacleDistances(self.pairs, self.dist, self._gradient() if gradient else None,
                                 tuple(links[a][0] for a, _ in self.pairs))

    def _gradient(self) -> np.ndarray:
        """(N, n_pairs, n_dof) ``∂distance/∂q``: ``n·(v_i - v_j)`` at the closest points."""
        jac = _segment_jacobians(self.robot, self.q)  # (N, n_segments, 2, 3, n_dof)
        i, j = np.array([p[0] for p in self.pairs], dtype=int), np.array([p[1] for p in self.pairs], dtype=int)
        s, t = self._s[..., None, None], self._t[..., None, None]
        vi = (1 - s) * jac[:, i, 0] + s * jac[:, i, 1]  # (N, P, 3, n_dof)
        vj = (1 - t) * jac[:, j, 0] + t * jac[:, j, 1]
        norm = np.linalg.norm(self._gap, axis=-1, keepdims=True)
        n = self._gap / np.where(norm > 1e-12, norm, 1.0)  # segments that meet: no direction, no gradient
        return np.einsum("npx,npxd->npd", n, vi - vj)
