"""An excitation checked a second time, by MuJoCo's collision detection (issue "An excitation safe to run on the real
robot", item 2: checked twice).

The robot is written as MJCF (:func:`dynid.io.export.mjcf_from_robot`) with each link's capsule as a geom (radius
``clearance`` about the segment from its joint's origin to the next, the last to the flange: the capsules of
:mod:`dynid.excitation.obstacles`), the cell's bodies as geoms of the world, and the floor as a plane. MuJoCo places
the links at every set-point (``mj_forward``) and reports its contacts: a link's capsule touching a body or the floor
is a failure. Links collide with the cell only, not with each other (:mod:`dynid.excitation.collision` reports
those). The floor is checked against the links whose two ends the design holds above it (joint origins that move);
a link with a fixed end (the first, on the base) rests where the description puts it. Reference: Todorov, Erez &
Tassa, "MuJoCo: a physics engine for model-based control", IROS 2012.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

import coal
import numpy as np
from scipy.spatial.transform import Rotation

from .._util.reprs import short_repr
from ..excitation.constraints import Workspace
from ..model.robot import Robot
from .export import mjcf_from_robot

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
    """

    set_points: int
    touching: int
    first: dict | None
    deepest: float

    def to_dict(self) -> dict:
        """JSON-ready.

        Returns
        -------
        dict
        """
        return {"set_points": self.set_points, "touching": self.touching, "first": self.first, "deepest": self.deepest}


def _vec(v) -> str:
    return " ".join(f"{float(x):.17g}" for x in v)


def _quat(rpy) -> str:
    x, y, z, w = Rotation.from_euler("xyz", rpy).as_quat()
    return _vec([w, x, y, z])


def cell_mjcf(robot: Robot, workspace: Workspace) -> str:
    """The robot with its links' capsules, the cell's bodies and the floor, as MJCF (module docstring).

    Parameters
    ----------
    robot : Robot
    workspace : Workspace
        Its ``clearance`` is the capsules' radius; its ``obstacles`` and ``floor`` the cell.

    Returns
    -------
    str
        An MJCF document: geoms named ``link<k>`` (contype 1, conaffinity 0; ``link<k>_floor`` for the floor's
        check, contype 2), the bodies by their names (conaffinity 1), ``floor`` (conaffinity 2).
    """
    root = ET.fromstring(mjcf_from_robot(robot))
    bodies = {b.get("name"): b for b in root.iter("body")}
    ends = [jt.translation for jt in robot.joints[1:]] + [robot.tool_translation]
    r = workspace.clearance
    held = set(int(k) for k in workspace.moving_origins(robot))  # joint origins the design holds above the floor
    for k, end in enumerate(ends):
        body = bodies[f"link{k + 1}"]
        shape = ({"type": "capsule", "fromto": f"0 0 0 {_vec(end)}"} if np.linalg.norm(end) > 1e-12
                 else {"type": "sphere"})
        common = {**shape, "size": f"{max(r, 1e-9):.17g}", "conaffinity": "0", "mass": "0", "group": "3"}
        if workspace.geometry is None:
            ET.SubElement(body, "geom", {"name": f"link{k + 1}", "contype": "1", **common})
        if k in held and (k + 1 in held):
            ET.SubElement(body, "geom", {"name": f"link{k + 1}_floor", "contype": "2", **common})
    if workspace.geometry is not None:
        _shape_geoms(root, bodies, workspace.geometry)
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


def _shape_geoms(root, bodies: dict, geometry) -> None:
    """The links' own collision shapes as geoms of their bodies (a convex hull as a mesh of its points: MuJoCo
    collides a mesh by its convex hull, the same one)."""
    asset = root.find("asset")
    if asset is None:
        asset = ET.Element("asset")
        root.insert(1, asset)
    for g, (shape, k) in enumerate(zip(geometry.shapes, geometry.link)):
        if k < 0:
            continue  # the base's: the cell is not measured against it
        x = geometry.placement[g]
        geom = {"name": f"link{k + 1}_shape{g}", "pos": _vec(x[:3, 3]), "quat": _quat_of(x[:3, :3]), "contype": "1",
                "conaffinity": "0", "mass": "0", "group": "3"}
        if isinstance(shape, coal.Box):
            geom.update(type="box", size=_vec(shape.halfSide))
        elif isinstance(shape, coal.Sphere):
            geom.update(type="sphere", size=f"{shape.radius:.17g}")
        elif isinstance(shape, coal.Ellipsoid):
            geom.update(type="ellipsoid", size=_vec(shape.radii))
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


def cell_contacts(robot: Robot, t: np.ndarray, q: np.ndarray, workspace: Workspace) -> CellContacts | None:
    """MuJoCo's contacts between the links' capsules and the cell at every set-point.

    Parameters
    ----------
    robot : Robot
    t : (N,) array [s]
    q : (N, n_dof) array [rad]
    workspace : Workspace

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
    model = mujoco.MjModel.from_xml_string(cell_mjcf(robot, workspace))
    data = mujoco.MjData(model)
    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) for g in range(model.ngeom)]
    within = np.zeros(model.ngeom)  # a shape must keep the clearance itself; a capsule holds it in its radius
    if workspace.geometry is not None:
        shapes = np.array(["_shape" in (n or "") for n in names])
        within[shapes] = workspace.clearance
        model.geom_margin[shapes] = workspace.clearance  # MuJoCo reports contacts up to the margin apart
    touching, first, deepest = 0, None, 0.0
    for n in range(q.shape[0]):
        data.qpos[:robot.n_dof] = q[n]
        mujoco.mj_forward(model, data)
        found = [c for c in data.contact[:data.ncon] if c.dist < within[c.geom1] + within[c.geom2] - 1e-9]
        if not found:
            continue
        touching += 1
        depth = [float(within[c.geom1] + within[c.geom2] - c.dist) for c in found]
        deepest = min(deepest, -max(depth))
        if first is None:
            a, b = names[found[0].geom1], names[found[0].geom2]
            link, body = (a, b) if a.startswith("link") else (b, a)
            first = {"link": int(link.removeprefix("link").split("_")[0]), "body": body, "time": float(t[n]),
                     "depth": depth[0]}
    return CellContacts(int(q.shape[0]), touching, first, max(0.0, -deepest))
