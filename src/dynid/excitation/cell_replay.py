"""An excitation checked a second time, by MuJoCo's collision detection (issue "An excitation safe to run on the real
robot", item 2: checked twice).

The robot is written as MJCF (:func:`dynid.model.description_files.mjcf_from_robot`) with the shapes the design measured as geoms
of its links (:meth:`dynid.excitation.constraints.Workspace.shapes`: the robot file's collision shapes, or the
capsules about the joint origins), the cell's bodies as geoms of the world, and the floor as a plane. Every shape's
``margin`` is the clearance, so MuJoCo reports each contact up to that far apart. MuJoCo places the links at every
set-point (``mj_forward``): a shape within the clearance of a body, or within its own floor height
(:mod:`dynid.excitation.floor`: the clearance, or its start height for a shape that starts within it) of the floor,
is a failure. Shapes whose lowest point never moves rest where the description puts them and are not checked against
the floor. Links collide with the cell only, not with each other (:mod:`dynid.excitation.collision` reports those).
Reference: Todorov, Erez & Tassa, "MuJoCo: a physics engine for model-based control", IROS 2012.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

import coal
import numpy as np
from scipy.spatial.transform import Rotation

from .._util.reprs import short_repr
from ..model.description_files import _vec, mjcf_from_robot
from ..model.robot import Robot
from .constraints import Workspace

__all__ = ["CellContacts", "cell_contacts", "cell_mjcf"]


@short_repr
@dataclass(frozen=True)
class CellContacts:
    """MuJoCo's contacts between the links and the cell along a trajectory.

    Attributes
    ----------
    set_points : int
        Set-points checked.
    touching : int
        Set-points with at least one contact.
    first : dict or None
        The first contact: ``link`` (1-based), ``body`` (an obstacle's name or "floor"), ``time`` [s], ``depth`` [m]
        (how far inside the clearance).
    deepest : float [m]
        The deepest a link came inside the clearance (0 without contact).
    held : tuple of str
        The shapes that start within the floor's clearance, checked against their start height instead (each
        shape's name, :attr:`dynid.excitation.link_geometry.LinkGeometry.names`).
    """

    set_points: int
    touching: int
    first: dict | None
    deepest: float
    held: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        """JSON-ready.

        Returns
        -------
        dict
        """
        return {"set_points": self.set_points, "touching": self.touching, "first": self.first, "deepest": self.deepest,
                "held": list(self.held)}


def _quat(rpy) -> str:
    x, y, z, w = Rotation.from_euler("xyz", rpy).as_quat()
    return _vec([w, x, y, z])


def cell_mjcf(robot: Robot, workspace: Workspace, floor_shapes=()) -> str:
    """The robot with its links' shapes, the cell's bodies and the floor, as MJCF (module docstring).

    Parameters
    ----------
    robot : Robot
    workspace : Workspace
        Its shapes (:meth:`~dynid.excitation.constraints.Workspace.shapes`), ``obstacles`` and ``floor``.
    floor_shapes : collection of int
        The shapes checked against the floor.

    Returns
    -------
    str
        An MJCF document: geoms named ``link<k>_shape<g>`` (contype 1, conaffinity 0; contype 3 for those checked
        against the floor), the bodies by their names (conaffinity 1), ``floor`` (conaffinity 2).
    """
    root = ET.fromstring(mjcf_from_robot(robot))
    bodies = {b.get("name"): b for b in root.iter("body")}
    _shape_geoms(root, bodies, workspace.shapes(robot), set(int(g) for g in floor_shapes))
    world = root.find("worldbody")
    assert world is not None  # mjcf_from_robot writes one
    for ob in workspace.obstacles:
        size = ob.size if ob.shape == "sphere" else (0.5 * ob.size if ob.shape == "box" else [ob.size[0], 0.5 * ob.size[1]])
        ET.SubElement(world, "geom", {"name": ob.name, "type": ob.shape, "size": _vec(size), "pos": _vec(ob.position),
                                      "quat": _quat(ob.rpy), "contype": "0", "conaffinity": "1"})
    if np.isfinite(workspace.floor):
        ET.SubElement(world, "geom", {"name": "floor", "type": "plane", "size": "0 0 1",
                                      "pos": f"0 0 {workspace.floor:.17g}", "contype": "0", "conaffinity": "2"})
    return ET.tostring(root, encoding="unicode")


def _shape_geoms(root, bodies: dict, geometry, floor_shapes: set) -> None:
    """The links' shapes as geoms of their bodies (a convex hull as a mesh of its points: MuJoCo collides a mesh by
    its convex hull, the same one); those in ``floor_shapes`` collide with the floor too."""
    asset = root.find("asset")
    if asset is None:
        asset = ET.Element("asset")
        root.insert(1, asset)
    for g, (shape, k) in enumerate(zip(geometry.shapes, geometry.link)):
        if k < 0:
            continue  # the base's: the cell is not measured against it
        x = geometry.placement[g]
        geom = {"name": f"link{k + 1}_shape{g}", "pos": _vec(x[:3, 3]), "quat": _quat_of(x[:3, :3]),
                "contype": "3" if g in floor_shapes else "1",
                "conaffinity": "0", "mass": "0", "group": "3"}
        if isinstance(shape, coal.Box):
            geom.update(type="box", size=_vec(shape.halfSide))
        elif isinstance(shape, coal.Sphere):
            geom.update(type="sphere", size=f"{shape.radius:.17g}")
        elif isinstance(shape, coal.Ellipsoid):
            geom.update(type="ellipsoid", size=_vec(shape.radii))
        elif isinstance(shape, coal.Capsule) and shape.halfLength <= 0:  # MuJoCo wants a length: a sphere
            geom.update(type="sphere", size=f"{shape.radius:.17g}")
        elif isinstance(shape, (coal.Cylinder, coal.Capsule)):
            geom.update(type="cylinder" if isinstance(shape, coal.Cylinder) else "capsule",
                        size=f"{shape.radius:.17g} {shape.halfLength:.17g}")
        else:
            points = np.array([shape.point(i) for i in range(shape.num_points)])
            ET.SubElement(asset, "mesh", {"name": f"shape{g}", "vertex": _vec(points.ravel())})
            geom.update(type="mesh", mesh=f"shape{g}")
        ET.SubElement(bodies[f"link{k + 1}"], "geom", geom)


def _quat_of(rotation) -> str:
    x, y, z, w = Rotation.from_matrix(rotation).as_quat()
    return _vec([w, x, y, z])


def cell_contacts(robot: Robot, t: np.ndarray, q: np.ndarray, workspace: Workspace,
                  start_pose: np.ndarray | None = None) -> CellContacts | None:
    """MuJoCo's contacts between the links' shapes and the cell at every set-point (module docstring).

    Parameters
    ----------
    robot : Robot
    t : (N,) array [s]
    q : (N, n_dof) array [rad]
    workspace : Workspace
    start_pose : (n_dof,) array [rad], optional
        The pose a shape that starts within the clearance of the floor is held at (default ``q[0]``).

    Returns
    -------
    CellContacts or None
        None where MuJoCo is not installed (the ``mujoco`` extra) or the cell has no floor and no bodies.
    """
    if not workspace.obstacles and not np.isfinite(workspace.floor):
        return None
    try:
        import mujoco
    except ImportError:
        return None
    needs = workspace.floor_needs(robot, q[0] if start_pose is None else start_pose)
    floor_height = {} if needs is None else {int(g): float(h) for g, h in zip(needs.shapes, needs.height)}
    held = () if needs is None else tuple(workspace.shapes(robot).names[int(needs.shapes[c])] for c in needs.within)
    model = mujoco.MjModel.from_xml_string(cell_mjcf(robot, workspace, floor_height))
    data = mujoco.MjData(model)
    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) for g in range(model.ngeom)]
    shape_of = {g: int(n.split("_shape")[1]) for g, n in enumerate(names) if n and "_shape" in n}
    model.geom_margin[list(shape_of)] = workspace.clearance  # MuJoCo reports contacts up to the margin apart
    floor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "floor")

    def kept(g1: int, g2: int) -> float:
        """How far apart a contact's two geoms must stay."""
        shape = shape_of.get(g1, shape_of.get(g2, -1))
        return floor_height.get(shape, 0.0) if floor in (g1, g2) else workspace.clearance

    touching, first, deepest = 0, None, 0.0
    for n in range(q.shape[0]):
        data.qpos[:robot.n_dof] = q[n]
        mujoco.mj_forward(model, data)
        if not data.ncon:
            continue
        contacts = data.contact  # read as arrays: a contact's own Python object costs more than MuJoCo's step
        dist, geom = contacts.dist[:data.ncon], contacts.geom[:data.ncon]
        found = [(g1, g2, kept(g1, g2) - d) for d, (g1, g2) in zip(dist.tolist(), geom.tolist()) if d < kept(g1, g2) - 1e-9]
        if not found:
            continue
        touching += 1
        deepest = max(deepest, max(depth for _, _, depth in found))
        if first is None:
            a, b = names[found[0][0]], names[found[0][1]]
            link, body = (a, b) if a.startswith("link") else (b, a)
            first = {"link": int(link.removeprefix("link").split("_")[0]), "shape": link, "body": body,
                     "time": float(t[n]), "depth": float(found[0][2])}
    return CellContacts(int(q.shape[0]), touching, first, float(deepest), held)
