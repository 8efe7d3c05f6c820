"""How close an excitation trajectory brings the arm's links to each other (issue "An excitation safe to run on the
real robot", item 2: checked at the controller's rate, said before it runs).

Each link is a capsule of radius ``clearance`` (:attr:`dynid.excitation.constraints.Workspace.clearance`) about the
segment from its joint's origin to the next joint's (the last link's to the flange): the robot's skeleton, which a
description without collision meshes still gives. Distances between capsules are coal's (the collision library of
Pinocchio's geometry models; Pan, Chitta & Manocha, "FCL: a general purpose library for collision and proximity
queries", ICRA 2012). The pairs that can touch are, as MoveIt's setup assistant finds them, every pair of links that
are not neighbours in the chain, less the pairs whose capsules overlap on almost every pose of a random sample (a
wrist whose axes meet: such a pair is in contact by construction of the skeleton, not by the motion).
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np

from ..model.robot import Robot
from .link_geometry import LinkGeometry, self_distances, self_pairs
from .obstacles import _capsules, _segments

__all__ = ["SelfClearance", "self_clearance", "shape_clearance", "touching_pairs"]

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
    """The pairs of links (0-based) that can touch: not neighbours, and not overlapping on :data:`ALWAYS` of random
    poses within the joint limits (module docstring).

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
    lo = np.where(np.isfinite(robot.limits.q_min), robot.limits.q_min, -np.pi)
    hi = np.where(np.isfinite(robot.limits.q_max), robot.limits.q_max, np.pi)
    q = lo + np.random.default_rng(rng).random((samples, robot.n_dof)) * (hi - lo)
    seg = _segments(robot, q)
    out = []
    for i in range(robot.n_dof):
        for j in range(i + 2, robot.n_dof):
            overlap = np.mean([_distance(seg[k, i], seg[k, j], radius) < 0 for k in range(samples)])
            if overlap < ALWAYS:
                out.append((i, j))
    return out


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
    seg = _segments(robot, np.asarray(q, dtype=float))
    best = (np.inf, pairs[0], 0)
    for k in range(seg.shape[0]):
        for i, j in pairs:
            d = _distance(seg[k, i], seg[k, j], radius)
            if d < best[0]:
                best = (d, (i, j), k)
    d, (i, j), k = best
    return SelfClearance(float(d), (i + 1, j + 1), float(np.asarray(t)[k]), len(pairs))


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
