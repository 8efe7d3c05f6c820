"""The links' own collision geometry, read from the robot's URDF or MJCF, for the cell's distances (issue "An excitation safe
to run on the real robot", item 1: distances from the description's collision meshes).

Pinocchio reads the URDF's ``<collision>`` elements into a geometry model (Carpentier et al., "The Pinocchio C++
library", SII 2019); coal holds the shapes. A mesh is replaced by its convex hull (coal's qhull), which contains it:
a distance to the hull is never larger than the distance to the mesh, and GJK measures it in microseconds where the
mesh's BVH takes a millisecond. Each shape rides on one of dynid's links: the joint that carries it in the URDF, or
the nearest of its ancestors that is one of the robot's joints (a gripper held at 0 rides on the last link), or on
the base (the links keep off it; the cell's bodies are not measured against it: no motion moves it). Its pose in
that link's frame is read once at ``q = 0``. An MJCF's collision geoms are read as MuJoCo compiles them
(:func:`link_geometry_from_mjcf`), so that the MuJoCo check (:mod:`dynid.excitation.cell_replay`) collides the user's own
shapes.
"""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import coal
import numpy as np

from .._util.reprs import short_repr
from ..dynamics.kinematics import forward_kinematics
from ..dynamics.sensitivity import frames_and_axes
from ..exceptions import ConfigError
from ..model.mjcf import collision_geoms, excluded_bodies
from ..model.robot import Robot
from ..model.srdf import disabled_link_pairs
from .obstacles import GJK_TOLERANCE, ObstacleDistances, capsule_ends, distance_above, nearest_points

__all__ = ["LINK_RADIUS_SHARE", "LinkGeometry", "capsule_geometry", "estimated_link_radius", "link_geometry_from_mjcf",
           "link_geometry_from_urdf", "shape_distances"]

LINK_RADIUS_SHARE = 0.15
"""The links' capsule radius, as a share of the arm's reach (the sum of its joint offsets and the flange's), where the
robot file has no collision shapes and ``[workspace] link_radius`` is not given. On the collision meshes of the nine
public arms of benchmarks/zoo (UR3, UR5, UR10, Panda, Kinova Jaco 2, xArm7, Unitree Z1, SO-100, TALOS's arm), a capsule
of this radius about the joint origins holds the whole mesh of 45 of the 55 links; the other ten are hands, grippers
and offset housings (up to 0.37 of the reach): an estimate, said as one wherever it is used."""


@short_repr
@dataclass(frozen=True)
class LinkGeometry:
    """Collision shapes attached to the robot's links.

    Attributes
    ----------
    shapes : tuple of coal.CollisionGeometry
        Convex hulls of meshes, or the URDF's boxes, cylinders and spheres.
    link : (m,) int array
        The link (0-based: link ``k`` is the one joint ``k`` moves) each shape rides on; -1 for the base.
    placement : (m, 4, 4) array
        Each shape's pose in its link's frame (dynid's joint frame) [m].
    names : tuple of str
        The URDF's collision names, named in messages.
    source : str
        The URDF.
    excluded : frozenset of (int, int)
        Pairs of shapes (``g < h``) the robot's files say never to check against each other: an SRDF's
        ``<disable_collisions>`` (MoveIt's), an MJCF's ``<contact><exclude>`` or collision bit masks that do not meet.
    found : dict
        The pairs :func:`self_pairs` found, per joint range and sample: found once per run.
    memo : dict
        The shapes' bounding volumes, and the last trajectory's poses, bounding volumes and coal transforms.
    """

    shapes: tuple
    link: np.ndarray
    placement: np.ndarray
    names: tuple[str, ...]
    source: str
    excluded: frozenset = frozenset()
    found: dict = field(default_factory=dict, compare=False, repr=False)
    memo: dict = field(default_factory=dict, compare=False, repr=False)

    def bounds(self, robot: Robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Each shape's bounding sphere (coal's local box, half its diagonal) and bounding capsule
        (:func:`_bounding_capsule`) along ``q``: two volumes that contain it, the sphere the tighter about a round
        shape, the capsule about a long one.

        Parameters
        ----------
        robot : Robot
        q : (N, n_dof) array [rad]

        Returns
        -------
        centre : (N, m, 3) array [m]
        radius : (m,) array [m]
        ends : (N, m, 2, 3) array [m]
            The capsules' segments.
        capsule_radius : (m,) array [m]
        """
        if "local" not in self.memo:  # the shapes do not change
            for shape in self.shapes:
                shape.computeLocalAABB()
            found = [_bounding_capsule(shape) for shape in self.shapes]
            self.memo["local"] = (np.array([np.asarray(shape.aabb_center, dtype=float) for shape in self.shapes]),
                                  np.array([float(shape.aabb_radius) for shape in self.shapes]),
                                  np.array([f[0] for f in found]), np.array([f[1] for f in found]))
        centre, radius, ends, capsule_radius = self.memo["local"]
        placed = self._placed(robot, q)
        if "centre" not in placed:
            placed["centre"] = placed["position"] + np.einsum("nmij,mj->nmi", placed["rotation"], centre)
            placed["ends"] = placed["position"][:, :, None] + np.einsum("nmij,mkj->nmki", placed["rotation"], ends)
        return placed["centre"], radius, placed["ends"], capsule_radius

    def poses(self, robot: Robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every shape's rotation and position in the base frame.

        Parameters
        ----------
        robot : Robot
        q : (N, n_dof) array [rad]

        Returns
        -------
        rotation : (N, m, 3, 3) array
        position : (N, m, 3) array [m]
        """
        placed = self._placed(robot, q)
        return placed["rotation"], placed["position"]

    def pose_of(self, robot: Robot, q: np.ndarray) -> Callable[[int, int], Any]:
        """coal's pose of one shape at one sample of ``q``, each made when first asked and kept with the trajectory's
        placement (a design asks the pairs near each other only, a shape in several of them).

        Parameters
        ----------
        robot : Robot
        q : (N, n_dof) array [rad]

        Returns
        -------
        callable
            ``pose(n, g)``: shape ``g`` at sample ``n``, a ``coal.Transform3s``.
        """
        placed = self._placed(robot, q)
        made, rotation, position = placed["transforms"], placed["rotation"], placed["position"]
        m = rotation.shape[1]

        def pose(n: int, g: int):
            key = n * m + g
            found = made.get(key)
            if found is None:
                found = made[key] = coal.Transform3s(rotation[n, g], position[n, g])
            return found

        return pose

    def _placed(self, robot: Robot, q: np.ndarray) -> dict:
        """The shapes placed along ``q``: one entry of :attr:`memo` for the last trajectory asked (the design asks the
        cell's and the self distances, each with the bounding volumes, on the same grid), replaced whole, so that what it holds
        is always of one trajectory."""
        key = (id(robot), q.shape, q.tobytes())
        last = self.memo.get("last")
        if last is not None and last["key"] == key:
            return last
        rots, orig = forward_kinematics(robot, q)
        base = self.link < 0  # on the base: its frame
        r, p = rots[:, np.where(base, 0, self.link)], orig[:, np.where(base, 0, self.link)]
        r[:, base], p[:, base] = np.eye(3), 0.0
        last = {"key": key, "rotation": r @ self.placement[:, :3, :3],
                "position": p + np.einsum("nmij,mj->nmi", r, self.placement[:, :3, 3]), "transforms": {}}
        self.memo["last"] = last
        return last


SMALLEST_LINK_RADIUS = 0.01
"""[m] The estimate's floor: an arm whose joints all sit at one point (no offsets) still has links."""


def estimated_link_radius(robot: Robot) -> float:
    """:data:`LINK_RADIUS_SHARE` of the arm's reach, at least :data:`SMALLEST_LINK_RADIUS`.

    Parameters
    ----------
    robot : Robot

    Returns
    -------
    float [m]
    """
    return max(LINK_RADIUS_SHARE * robot.reach, SMALLEST_LINK_RADIUS)


def capsule_geometry(robot: Robot, radius: float, *, estimated: bool = True) -> LinkGeometry:
    """Each link as a capsule of ``radius`` about the segment from its joint's origin to the next joint's (the last
    link's to the flange; a sphere where they coincide; a link that carries two branches, one capsule to each, and a
    branch's tip other than the last a sphere): the shapes of a robot whose file has none.

    Parameters
    ----------
    robot : Robot
    radius : float [m]
    estimated : bool
        Whether ``radius`` is :func:`estimated_link_radius` (said in :attr:`LinkGeometry.source`).

    Returns
    -------
    LinkGeometry
        ``names`` "link k capsule", ``source`` what they are.
    """
    tool, still = np.asarray(robot.tool_translation, dtype=float), np.zeros(3)  # a branch's tip other than the last: a sphere
    ends = [(k, np.asarray(robot.joints[c].translation, dtype=float) if c >= 0 else tool if k == robot.n_dof - 1 else still)
            for k, c in capsule_ends(robot)]
    shapes, placement = [], []
    for _, end in ends:  # in the link's own frame the segment runs from its origin to the next joint's translation
        length = float(np.linalg.norm(end))
        frame = np.eye(4)
        if length > 1e-12:
            z = end / length
            x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
            x /= np.linalg.norm(x)
            frame[:3, :3] = np.stack([x, np.cross(z, x), z], axis=1)
            frame[:3, 3] = 0.5 * end
        shapes.append(coal.Capsule(float(radius), length))
        placement.append(frame)
    how = "estimated: [workspace] link_radius sets it" if estimated else "[workspace] link_radius"
    links = [k for k, _ in ends]
    return LinkGeometry(tuple(shapes), np.array(links), np.array(placement),
                        tuple(f"link {k + 1} capsule" + (f" {links[:i].count(k) + 1}" if links.count(k) > 1 else "")
                              for i, k in enumerate(links)),
                        f"capsules of radius {radius:.3g} m about the joint origins ({how})")


def _package_dirs(path: Path) -> list[str]:
    """Folders ``package://name/...`` may be found under: the URDF's own ancestors (a description package)."""
    return [str(p) for p in path.resolve().parents]


def link_geometry_from_urdf(robot: Robot, path, srdf=None) -> LinkGeometry | None:
    """The collision shapes of a URDF on the robot's links (module docstring).

    Parameters
    ----------
    robot : Robot
        The robot read from that URDF (its joints carry the URDF's joint names).
    path : str or Path
        The URDF.
    srdf : str or Path, optional
        MoveIt's semantic description of the robot: the pairs of links its ``<disable_collisions>`` name are
        :attr:`LinkGeometry.excluded` (read by Pinocchio's ``removeCollisionPairs``).

    Returns
    -------
    LinkGeometry or None
        None where the URDF has no collision element on a moving link.

    Raises
    ------
    ConfigError
        A collision mesh that cannot be found or read (the message names the file and the mesh), or an SRDF that is
        not XML or names a link the URDF does not have.
    """
    import pinocchio as pin

    path = Path(path)
    _check_meshes(path)
    model = pin.buildModelFromUrdf(str(path))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            geometry = pin.buildGeomFromUrdf(model, str(path), pin.GeometryType.COLLISION, package_dirs=_package_dirs(path))
    except (ValueError, RuntimeError, OSError) as exc:
        raise ConfigError(f"{path}: its collision geometry could not be read ({str(exc).splitlines()[0]}); give the "
                          "meshes beside it, or set workspace.geometry = \"capsules\"") from None
    index = {j.name: k for k, j in enumerate(robot.joints)}
    data = model.createData()
    geometry_data = pin.GeometryData(geometry)
    pin.updateGeometryPlacements(model, data, geometry, geometry_data, pin.neutral(model))
    rots, orig = forward_kinematics(robot, np.zeros((1, robot.n_dof)))
    shapes, link, placement, names = [], [], [], []
    for g, obj in enumerate(geometry.geometryObjects):
        joint = obj.parentJoint
        while joint > 0 and model.names[joint] not in index:
            joint = model.parents[joint]
        k = index[model.names[joint]] if joint > 0 else -1  # -1: on the base
        frame = np.eye(4)
        if k >= 0:
            frame[:3, :3], frame[:3, 3] = rots[0, k], orig[0, k]
        world = geometry_data.oMg[g].homogeneous
        shape = obj.geometry
        if isinstance(shape, coal.BVHModelBase):
            shape.buildConvexHull(True, "Qt")
            shape = shape.convex
        shapes.append(shape)
        link.append(k)
        placement.append(np.linalg.solve(frame, world))
        names.append(obj.name)
    if not any(k >= 0 for k in link):
        return None
    excluded = _srdf_excluded(model, geometry, Path(srdf)) if srdf is not None else frozenset()
    return LinkGeometry(tuple(shapes), np.array(link), np.array(placement), tuple(names), str(path), excluded)


LARGEST_MESH = 256 * 2**20
"""[bytes] A collision mesh larger than this is refused before it is read (a robot's are a few MB; /dev/zero never
ends)."""


def _check_meshes(path: Path) -> None:
    """Refuse a ``<collision>`` mesh that is not a regular file or is over :data:`LARGEST_MESH`, naming it (Pinocchio's
    own message named a C++ source file): ``package://`` found as Pinocchio finds it, among the URDF's ancestors."""
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError):
        return  # Pinocchio's parser says why
    for mesh in root.iterfind("./link/collision/geometry/mesh"):
        name = mesh.get("filename", "")
        rest = name.removeprefix("file://")
        candidates = ([Path(d) / rest.removeprefix("package://") for d in _package_dirs(path)]
                      if rest.startswith("package://") else [path.parent / rest])
        found = next((c for c in candidates if c.exists()), None)
        if found is None:
            continue
        if not found.is_file():
            raise ConfigError(f"{path}: collision mesh {name}: {found} is not a regular file (a device, a FIFO or a "
                              "folder)")
        if found.stat().st_size > LARGEST_MESH:
            raise ConfigError(f"{path}: collision mesh {name}: {found.stat().st_size / 2**20:.0f} MiB, more than a "
                              f"collision mesh dynid reads ({LARGEST_MESH // 2**20} MiB): give a simplified mesh, or "
                              'set workspace.geometry = "capsules"')


def _srdf_excluded(model, geometry, srdf: Path) -> frozenset:
    """The pairs of ``geometry``'s objects an SRDF's ``<disable_collisions>`` leave out, as Pinocchio removes them from
    every pair; an SRDF naming a link the URDF does not have is refused (it is another robot's)."""
    import pinocchio as pin

    links = {f.name for f in model.frames}
    for pair in disabled_link_pairs(srdf):
        unknown = sorted(pair - links)
        if unknown:
            raise ConfigError(f"{srdf}: <disable_collisions> names link {unknown[0]!r}, which the URDF does not have: "
                              "is it this robot's SRDF?")
    geometry.addAllCollisionPairs()
    every = {(p.first, p.second) for p in geometry.collisionPairs}
    pin.removeCollisionPairs(model, geometry, str(srdf))
    kept = {(p.first, p.second) for p in geometry.collisionPairs}
    return frozenset((min(a, b), max(a, b)) for a, b in every - kept)


def link_geometry_from_mjcf(robot: Robot, path) -> LinkGeometry | None:
    """The collision geoms of an MJCF on the robot's links (:func:`dynid.model.mjcf.collision_geoms`): boxes, spheres,
    capsules, cylinders and ellipsoids as coal's shapes of the same size, a mesh as its convex hull (coal's qhull, the
    hull MuJoCo collides it by), each at its pose in its link's frame; the robot's held joints at 0, as for a URDF.

    Parameters
    ----------
    robot : Robot
        The robot read from that MJCF.
    path : str or Path
        The MJCF.

    Returns
    -------
    LinkGeometry or None
        None where no geom on a moving link collides (every one ``contype = conaffinity = 0``).

    Raises
    ------
    ConfigError
        MuJoCo is not installed, or the file cannot be compiled.
    """
    geoms = collision_geoms(path, dict.fromkeys(robot.held, 0.0))
    if not any(g.link >= 0 for g in geoms):
        return None
    bodies = excluded_bodies(path)
    excluded = frozenset((i, j) for i, a in enumerate(geoms) for j, b in enumerate(geoms) if i < j and (
        not (a.contype & b.conaffinity or b.contype & a.conaffinity) or frozenset((a.body, b.body)) in bodies))
    return LinkGeometry(tuple(_coal_shape(g) for g in geoms), np.array([g.link for g in geoms]),
                        np.array([g.placement for g in geoms]), tuple(g.name for g in geoms), str(path), excluded)


def _coal_shape(geom):
    """coal's shape of an MJCF geom (MuJoCo's sizes are radii and half-lengths; coal's cylinders and capsules take
    the whole length, its boxes the whole sides)."""
    r = geom.size
    if geom.kind == "sphere":
        return coal.Sphere(r[0])
    if geom.kind in ("capsule", "cylinder"):
        return (coal.Capsule if geom.kind == "capsule" else coal.Cylinder)(r[0], 2 * r[1])
    if geom.kind == "ellipsoid":
        return coal.Ellipsoid(*r)
    if geom.kind == "box":
        return coal.Box(*(2 * r))
    mesh = coal.BVHModelOBBRSS()
    mesh.beginModel(0, len(geom.vertices))
    mesh.addVertices(geom.vertices)
    mesh.endModel()
    mesh.buildConvexHull(True, "Qt")
    return mesh.convex


def _bounding_capsule(shape) -> tuple[np.ndarray, float]:
    """A capsule that contains ``shape``, in its own frame: the ends of its segment (2, 3) and its radius. A cylinder
    or a capsule gives its own; the points of a box or a convex hull give the capsule about their principal axis with
    the smallest radius and the shortest segment that hold every point; any other shape, its local box's bounding
    sphere (a segment of no length)."""
    if isinstance(shape, (coal.Cylinder, coal.Capsule)):
        return np.array([[0.0, 0.0, -shape.halfLength], [0.0, 0.0, shape.halfLength]]), float(shape.radius)
    if isinstance(shape, coal.Box):
        points = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * np.asarray(shape.halfSide)
    elif isinstance(shape, coal.ConvexBase):
        points = np.asarray(shape.points(), dtype=float)
    else:  # a sphere, an ellipsoid
        shape.computeLocalAABB()
        return np.array([shape.aabb_center, shape.aabb_center], dtype=float), float(shape.aabb_radius)
    middle = points.mean(axis=0)
    axis = np.linalg.svd(points - middle, full_matrices=False)[2][0]
    along = (points - middle) @ axis
    off = np.linalg.norm(points - middle - along[:, None] * axis, axis=1)
    radius = float(off.max())
    slack = np.sqrt(np.maximum(radius**2 - off**2, 0.0))  # how far past each point the segment may stop
    low, high = float(np.min(along + slack)), float(np.max(along - slack))
    if low > high:  # every point within the radius of one point of the axis
        low = high = 0.5 * (low + high)
    return middle + np.array([low, high])[:, None] * axis, radius


def _ratio(num: np.ndarray, den: np.ndarray) -> np.ndarray:
    """``num / den`` clipped to [0, 1], 0 where ``den`` vanishes (a segment of no length)."""
    return np.where(den > 1e-18, np.clip(num / np.where(den > 1e-18, den, 1.0), 0.0, 1.0), 0.0)


def _nearest_on_segments(p1: np.ndarray, q1: np.ndarray, p2: np.ndarray, q2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The nearest points of segments ``p1q1`` and ``p2q2`` (arrays (..., 3)), each pair's (C. Ericson, Real-Time
    Collision Detection, 2005, §5.1.9, with its branches as masks)."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a, e = np.einsum("...i,...i", d1, d1), np.einsum("...i,...i", d2, d2)
    b, c, f = np.einsum("...i,...i", d1, d2), np.einsum("...i,...i", d1, r), np.einsum("...i,...i", d2, r)
    s = _ratio(b * f - c * e, a * e - b * b)  # 0 where parallel
    t = (b * s + f) / np.where(e > 1e-18, e, 1.0)
    s = np.where(t < 0.0, _ratio(-c, a), np.where(t > 1.0, _ratio(b - c, a), s))
    t = np.clip(t, 0.0, 1.0)
    s, t = np.where(e > 1e-18, s, _ratio(-c, a)), np.where(e > 1e-18, t, 0.0)  # the second a point
    s, t = np.where(a > 1e-18, s, 0.0), np.where(a > 1e-18, t, _ratio(f, e))  # the first a point
    return p1 + s[..., None] * d1, p2 + t[..., None] * d2


def _nearest_on_segment(p: np.ndarray, q: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The point of segment ``pq`` nearest ``x`` (arrays (..., 3))."""
    d = q - p
    return p + _ratio(np.einsum("...i,...i", x - p, d), np.einsum("...i,...i", d, d))[..., None] * d


def shape_distances(robot: Robot, q: np.ndarray, obstacles, geometry: LinkGeometry, clearance: float, *,
                    pairs=None, gradient: bool = False) -> ObstacleDistances:
    """The links' collision shapes' distances to the cell's bodies along ``q``, less ``clearance`` (zero: the
    clearance kept), with their gradient: moving the shape's nearest point ``p`` by joint ``j`` (``j`` up to the
    shape's link) changes the distance by ``-n·(z_j × (p - o_j))``, ``n`` the unit vector from ``p`` to the body.

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array [rad]
    obstacles : sequence of Obstacle
    geometry : LinkGeometry
    clearance : float [m]
    pairs : list of (int, int), optional
        (shape, obstacle) pairs (default every one).
    gradient : bool

    Returns
    -------
    ObstacleDistances
        ``pairs`` index the shapes; ``links`` names each pair's link.
    """
    return ShapeDistances(robot, q, obstacles, geometry, clearance, pairs=pairs).distances(gradient=gradient)


class _CoalDistances:
    """What :class:`ShapeDistances` and :class:`SelfDistances` share: the distances measured once (``dist`` (N, P),
    coal's results ``_found`` where the bounding volumes are near, their nearest points and normal ``_near``,
    ``_normal`` elsewhere), their gradient given on demand from the same results (a design asks the values at an
    iterate, then their gradient at the same iterate: coal is not asked twice)."""

    robot: Robot
    geometry: LinkGeometry
    pairs: list
    q: np.ndarray
    dist: np.ndarray
    _near: np.ndarray
    _normal: np.ndarray
    _found: list

    @staticmethod
    def _take_ends(near, normal, n_found, c_found, ends) -> None:  # pragma: no cover - each subclass's own
        raise NotImplementedError

    def _gradient(self, near, normal, orig, axes) -> np.ndarray:  # pragma: no cover - each subclass's own
        raise NotImplementedError

    def distances(self, *, gradient: bool = False) -> ObstacleDistances:
        """The distances, with their gradient if asked.

        Parameters
        ----------
        gradient : bool

        Returns
        -------
        ObstacleDistances
        """
        grad = None
        if gradient and self.pairs:
            near, normal = self._near.copy(), self._normal.copy()
            if self._found:
                self._take_ends(near, normal, *_found_ends(self._found))
            _, orig, axes = frames_and_axes(self.robot, self.q)
            grad = self._gradient(near, normal, orig, axes)
        return ObstacleDistances(list(self.pairs), self.dist.copy(), grad,
                                 tuple(int(self.geometry.link[g]) for g, _ in self.pairs))


class ShapeDistances(_CoalDistances):
    """The distances of :func:`shape_distances` measured once, their gradient given on demand from coal's results
    (:class:`_CoalDistances`).

    Parameters
    ----------
    robot, q, obstacles, geometry, clearance, pairs
        As :func:`shape_distances`.
    """

    def __init__(self, robot: Robot, q: np.ndarray, obstacles, geometry: LinkGeometry, clearance: float, *, pairs=None):
        self.robot, self.geometry = robot, geometry
        self.q = q = np.atleast_2d(np.asarray(q, dtype=float))
        self.pairs = pairs = ([(g, i) for g in np.flatnonzero(geometry.link >= 0).tolist() for i in range(len(obstacles))]
                              if pairs is None else list(pairs))
        bodies = [ob.geometry() for ob in obstacles]
        centre, radius, ends, capsule_radius = geometry.bounds(robot, q)
        g_of, i_of = (np.array([p[k] for p in pairs], dtype=int) for k in (0, 1))
        ob_centre = np.array([ob.position for ob in obstacles])[i_of][None] if pairs else np.zeros((1, 0, 3))
        ob_radius = np.array([ob.bounding_radius() for ob in obstacles])[i_of] if pairs else np.zeros(0)
        on_capsule = _nearest_on_segment(ends[:, g_of, 0], ends[:, g_of, 1], ob_centre)  # (N, P, 3)
        sphere = np.linalg.norm(centre[:, g_of] - ob_centre, axis=-1) - radius[g_of]
        capsule = np.linalg.norm(on_capsule - ob_centre, axis=-1) - capsule_radius[g_of]
        self._near = np.where((capsule > sphere)[..., None], on_capsule, centre[:, g_of])  # the tighter bound's
        gap = self._near - ob_centre  # the bound's direction, body to shape
        self.dist = np.maximum(sphere, capsule) - ob_radius - clearance  # a lower bound, exact far away
        self._normal = -gap / np.maximum(np.linalg.norm(gap, axis=-1, keepdims=True), 1e-12)
        pose = geometry.pose_of(robot, q)
        shapes = [(geometry.shapes[g], g, *bodies[i]) for g, i in pairs]
        self._clearance = clearance
        self._shapes_at = lambda n, c: (shapes[c][0], pose(n, shapes[c][1]), shapes[c][2], shapes[c][3])
        self._found = _coal_results(self.dist, clearance, self._shapes_at)

    def smallest(self, columns) -> tuple[int, int, float]:
        """The smallest distance of the pairs ``columns`` over the samples, measured by coal where the bounding
        volumes' bound stood (:data:`FAR` apart or more): samples are measured in the order of their bounds until the
        next bound lies above the smallest found, so the figure is a distance, never a bound.

        Parameters
        ----------
        columns : sequence of int
            Pairs (into :attr:`pairs`).

        Returns
        -------
        sample : int
        column : int
        distance : float [m]
            Less the clearance.
        """
        columns = np.asarray(columns, dtype=int)
        bound = self.dist[:, columns]
        request = coal.DistanceRequest()
        request.gjk_tolerance, request.epa_tolerance = GJK_TOLERANCE, GJK_TOLERANCE
        best = (0, int(columns[0]), np.inf)
        for flat in np.argsort(bound, axis=None, kind="stable"):
            n, k = np.unravel_index(int(flat), bound.shape)
            if bound[n, k] >= best[2]:
                break
            result = distance_above(*self._shapes_at(n, int(columns[k])), request, bound[n, k] + self._clearance)
            exact = bound[n, k] if result is None else float(result.min_distance) - self._clearance
            if exact < best[2]:
                best = (int(n), int(columns[k]), exact)
        return best

    @staticmethod
    def _take_ends(near, normal, n_found, c_found, ends) -> None:
        near[n_found, c_found], normal[n_found, c_found] = ends[0], ends[2]

    def _gradient(self, near, normal, orig, axes) -> np.ndarray:
        """``-z_j·((p - o_j) × n)`` for the joints up to the shape's link."""
        lever = near[:, :, None, :] - orig[:, None, :, :]  # (N, P, n_dof, 3)
        grad = -np.einsum("npjk,nkj->npj", np.cross(lever, normal[:, :, None, :]), axes)
        _along_sliding(self.robot, grad, normal, axes, -1.0)
        links = np.array([int(self.geometry.link[g]) for g, _ in self.pairs])
        grad *= self.robot.carries[:, links].T[None]
        return grad


def _coal_results(dist: np.ndarray, offset: float, shapes_at, *, within: float | None = None) -> list:
    """coal's distance of every pair whose bounding volumes' bound ``dist`` (N, P) is below :data:`FAR`: ``dist``
    takes each (less ``offset``, the clearance), and the list of ``(n, c, result)`` is returned (a pair coal fails on
    keeps its bound). ``shapes_at(n, c)`` gives ``(shape_a, pose_a, shape_b, pose_b)``.

    With ``within`` [m], a branch and bound: coal measures each sample's pairs in the order of their bounds, and stops
    at the first whose bound lies ``within`` or more above the smallest distance measured so far (an upper bound of the
    sample's smallest): that pair and the rest are at least ``within`` farther than the sample's nearest pair, and keep
    their bound. One round of coal's calls measures the next pair of every sample still open."""
    request = coal.DistanceRequest()
    request.gjk_tolerance, request.epa_tolerance = GJK_TOLERANCE, GJK_TOLERANCE
    if within is None or dist.shape[1] < 2:
        return _measured(dist, offset, shapes_at, request, np.nonzero(dist < FAR))
    order = np.argsort(dist, axis=1, kind="stable")
    bound = np.take_along_axis(dist, order, axis=1)  # each sample's bounds, ascending (dist takes coal's below)
    best = np.full(dist.shape[0], np.inf)  # a pair coal fails on keeps its bound and leaves the best as it was
    found: list = []
    for k in range(dist.shape[1]):
        samples = np.flatnonzero((bound[:, k] < FAR) & (bound[:, k] < best + within))
        if not samples.size:
            break
        measured = _measured(dist, offset, shapes_at, request, (samples, order[samples, k]))
        if measured:
            n_found, c_found = (np.array(x) for x in tuple(zip(*measured))[:2])
            best[n_found] = np.minimum(best[n_found], dist[n_found, c_found])
        found += measured
    return found


def _measured(dist: np.ndarray, offset: float, shapes_at, request, asked: tuple) -> list:
    """coal's distances of the pairs ``asked`` (samples, columns), written into ``dist`` (:func:`_coal_results`)."""
    found = []
    for n, c, bound in zip(*asked, (dist[asked] + offset).tolist()):
        shape_a, pose_a, shape_b, pose_b = shapes_at(n, c)
        result = distance_above(shape_a, pose_a, shape_b, pose_b, request, bound)
        if result is not None:  # else coal failed on a deep overlap: the bounding volumes' bound stands
            found.append((n, c, result))
    if found:
        n_found, c_found, results = zip(*found)
        dist[np.array(n_found), np.array(c_found)] = [r.min_distance - offset for r in results]
    return found


def _found_ends(found: list) -> tuple:
    """The samples, the pairs and coal's nearest points of :func:`_coal_results`' list: ``(first, second, unit)`` as
    arrays (:func:`dynid.excitation.obstacles.nearest_points`)."""
    samples, columns, results = zip(*found)
    ends = tuple(np.array(x) for x in zip(*(nearest_points(r) for r in results)))
    return np.array(samples), np.array(columns), ends


FAR = 0.1
"""[m] Where two shapes' bounding volumes (:meth:`LinkGeometry.bounds`) are this far apart, their distance stands for the shapes' (a lower bound, continuous,
with its own gradient): the constraint is far from binding, and GJK runs only on the pairs that are near."""

ALWAYS = 0.95
"""A pair of shapes that touch on this share of random poses or more is in contact by construction (a joint's two
housings), as MoveIt's setup assistant finds it: left out of the self-clearance."""


def self_pairs(robot: Robot, geometry: LinkGeometry, *, samples: int = 200, rng=0) -> list[tuple[int, int]]:
    """The pairs of shapes (indices into ``geometry``) whose distance the motion changes and that can touch: on links
    that are not the same or neighbours in the chain, not excluded by the robot's files (:attr:`LinkGeometry.excluded`)
    and not touching on :data:`ALWAYS` of random poses within the joint limits (±π where there are none).

    Parameters
    ----------
    robot : Robot
    geometry : LinkGeometry
    samples : int
    rng : int or Generator

    Returns
    -------
    list of (int, int)
    """
    lo, hi = robot.limits.position_span()
    key = (robot.n_dof, lo.tobytes(), hi.tobytes(), samples, rng if isinstance(rng, int) else None)
    if key[-1] is not None and key in geometry.found:  # the design, its checks and the run ask for the same pairs
        return list(geometry.found[key])
    parents = {k: int(p) for k, p in enumerate(robot.parents)}

    def neighbours(a: int, b: int) -> bool:  # the same link, or one carried by the other's joint (the base is -1)
        return a == b or parents.get(a, -2) == b or parents.get(b, -2) == a

    candidates = [(g, h) for g in range(len(geometry.shapes)) for h in range(g + 1, len(geometry.shapes))
                  if not neighbours(int(geometry.link[g]), int(geometry.link[h])) and (g, h) not in geometry.excluded]
    pairs = []
    if candidates:
        q = robot.limits.random_positions(samples, rng)
        touching = self_distances(robot, q, geometry, candidates).distance < 0
        pairs = [pair for pair, share in zip(candidates, touching.mean(axis=0)) if share < ALWAYS]
    if key[-1] is not None:
        geometry.found[key] = tuple(pairs)
    return pairs


def self_distances(robot: Robot, q: np.ndarray, geometry: LinkGeometry, pairs, *, gradient: bool = False) -> ObstacleDistances:
    """Distances between pairs of the links' shapes along ``q`` (no clearance: zero is contact), with their gradient:
    ``-n·(v_g - v_h)``, ``v`` each nearest point's velocity per joint (``z_j × (p - o_j)`` for the joints up to its
    link), ``n`` the unit vector from ``g``'s nearest point to ``h``'s.

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array [rad]
    geometry : LinkGeometry
    pairs : list of (int, int)
        Shape indices (:func:`self_pairs`).
    gradient : bool

    Returns
    -------
    ObstacleDistances
        ``pairs`` as given; ``links`` the first shape's link of each.
    """
    return SelfDistances(robot, q, geometry, pairs).distances(gradient=gradient)


class SelfDistances(_CoalDistances):
    """The distances of :func:`self_distances` measured once, their gradient given on demand from coal's results
    (:class:`_CoalDistances`).

    Parameters
    ----------
    robot : Robot
    q : (N, n_dof) array [rad]
    geometry : LinkGeometry
    pairs : list of (int, int)
        Shape indices (:func:`self_pairs`).
    within : float, optional
        [m] coal measures only the pairs that can lie within this of each sample's nearest one; the others keep their
        bounding volumes' distance (a lower bound). Default: every pair within :data:`FAR`.
    """

    def __init__(self, robot: Robot, q: np.ndarray, geometry: LinkGeometry, pairs, *, within: float | None = None):
        self.robot, self.geometry, self.pairs = robot, geometry, list(pairs)
        self.q = q = np.atleast_2d(np.asarray(q, dtype=float))
        centre, radius, ends, capsule_radius = geometry.bounds(robot, q)
        a, b = (np.array([p[k] for p in pairs], dtype=int) for k in (0, 1))
        on_capsules = np.stack(_nearest_on_segments(ends[:, a, 0], ends[:, a, 1], ends[:, b, 0], ends[:, b, 1]))
        sphere = np.linalg.norm(centre[:, b] - centre[:, a], axis=-1) - radius[a] - radius[b]
        capsule = np.linalg.norm(on_capsules[1] - on_capsules[0], axis=-1) - capsule_radius[a] - capsule_radius[b]
        self._near = np.where((capsule > sphere)[None, ..., None], on_capsules, np.stack([centre[:, a], centre[:, b]]))
        gap = self._near[1] - self._near[0]  # (N, P, 3): the tighter bound's direction
        self.dist = np.maximum(sphere, capsule)  # a lower bound, exact far away
        self._normal = gap / np.maximum(np.linalg.norm(gap, axis=-1, keepdims=True), 1e-12)
        pose = geometry.pose_of(robot, q)
        shapes = [(geometry.shapes[g], g, geometry.shapes[h], h) for g, h in pairs]
        self._found = _coal_results(self.dist, 0.0, lambda n, c: (shapes[c][0], pose(n, shapes[c][1]), shapes[c][2],
                                                                  pose(n, shapes[c][3])), within=within)

    @staticmethod
    def _take_ends(near, normal, n_found, c_found, ends) -> None:
        near[0, n_found, c_found], near[1, n_found, c_found], normal[n_found, c_found] = ends

    def _gradient(self, near, normal, orig, axes) -> np.ndarray:
        """``-n·(v_g - v_h)``: each side's nearest point moved by the joints up to its shape's link."""
        robot, pairs = self.robot, self.pairs
        carries = np.c_[robot.carries, np.zeros(robot.n_dof, dtype=bool)]  # link -1 (the base): no joint moves it
        grad = np.zeros((self.q.shape[0], len(pairs), robot.n_dof))
        for side, sign in ((0, -1.0), (1, 1.0)):
            links = np.array([int(self.geometry.link[pair[side]]) for pair in pairs])
            lever = near[side][:, :, None, :] - orig[:, None, :, :]
            moved = np.einsum("npjk,nkj->npj", np.cross(lever, normal[:, :, None, :]), axes)  # z_j·((p - o_j) × n)
            _along_sliding(robot, moved, normal, axes, 1.0)
            grad += sign * moved * carries[:, links].T[None]
        return grad


def _along_sliding(robot, grad: np.ndarray, normal: np.ndarray, axes: np.ndarray, sign: float) -> None:
    """A distance gradient's columns of the prismatic joints, in place: a point moves along ``z_j`` with them, so the
    distance along ``n`` changes by ``sign · n·z_j`` (the revolute columns' ``z_j·((p - o_j) × n)`` is for turning).
    ``grad`` (N, P, n_dof), ``normal`` (N, P, 3), ``axes`` (N, 3, n_dof)."""
    slides = robot.prismatic
    if slides.any():
        grad[:, :, slides] = sign * np.einsum("npk,nkj->npj", normal, axes[:, :, slides])
