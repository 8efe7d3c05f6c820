"""The floor measured on the links' shapes (issue "Every assurance checked on what the user meets", item 1): each
shape's lowest point against the shape's own vertices placed by Pinocchio and against dense samples of its surface,
the gradient against central differences, and ``dynid excite`` over a table checked by an independent Pinocchio +
coal pass over the written excitation.csv; a pose whose joint origins clear the table while a link's mesh is under it
is found by dynid's margins and by MuJoCo's check, and the assurance is withdrawn."""

import json
import re
from importlib import resources
from pathlib import Path

import coal
import numpy as np
import pytest

from dynid.dynamics.kinematics import forward_kinematics
from dynid.excitation.cell_replay import cell_contacts
from dynid.excitation.constraints import Workspace, floor_margins
from dynid.excitation.floor import FloorDistances, floor_needs, lowest_points
from dynid.excitation.link_geometry import LinkGeometry, link_geometry_from_urdf
from dynid.model.description import load_robot

from ..cli.refusals import dynid
from .test_link_geometry import ur10e_with_meshes  # noqa: F401  (the fixture: the UR10e URDF with box meshes)

HOME = np.array([0.0, -np.pi / 2, np.pi / 2, -np.pi / 2, -np.pi / 2, 0.0])


@pytest.fixture(scope="module")
def er16():
    return load_robot("er16")


def _pinocchio(urdf: Path):
    """Pinocchio's model and collision geometry of the URDF, each mesh replaced by its convex hull (as dynid and
    MuJoCo collide it), and a function giving every shape's distance to the floor plane at ``q``, by coal."""
    import pinocchio as pin

    model = pin.buildModelFromUrdf(str(urdf))
    geom = pin.buildGeomFromUrdf(model, str(urdf), pin.GeometryType.COLLISION, package_dirs=[str(p) for p in urdf.parents])
    for obj in geom.geometryObjects:
        if isinstance(obj.geometry, coal.BVHModelBase):
            obj.geometry.buildConvexHull(True, "Qt")
            obj.geometry = obj.geometry.convex
    data, gdata = model.createData(), pin.GeometryData(geom)

    def heights(q: np.ndarray, floor: float) -> dict:
        pin.updateGeometryPlacements(model, data, geom, gdata, q)
        plane = coal.Halfspace(np.array([0.0, 0.0, 1.0]), floor)
        out = {}
        for g, obj in enumerate(geom.geometryObjects):
            result = coal.DistanceResult()
            pose = coal.Transform3s(gdata.oMg[g].rotation, gdata.oMg[g].translation)
            coal.distance(obj.geometry, pose, plane, coal.Transform3s(), coal.DistanceRequest(), result)
            out[obj.name] = (result.min_distance, obj.parentJoint)
        return out

    return model, heights


def test_the_lowest_points_are_the_shapes_lowest_by_pinocchio_and_coal(ur10e_with_meshes, rng):  # noqa: F811
    robot = load_robot(ur10e_with_meshes)
    geometry = link_geometry_from_urdf(robot, ur10e_with_meshes)
    _, heights = _pinocchio(ur10e_with_meshes)
    q = rng.uniform(-2.0, 2.0, (10, robot.n_dof))
    low = lowest_points(robot, q, geometry)[..., 2]
    for n in range(q.shape[0]):
        truth = heights(q[n], 0.0)
        np.testing.assert_allclose(low[n], [truth[name][0] for name in geometry.names], atol=1e-8)


@pytest.mark.parametrize("shape", [coal.Box(0.3, 0.1, 0.2), coal.Sphere(0.07), coal.Capsule(0.05, 0.3),
                                   coal.Cylinder(0.06, 0.25), coal.Ellipsoid(0.1, 0.05, 0.2)])
def test_each_primitives_lowest_point_against_coal_and_a_plane(er16, rng, shape):
    """One primitive on every link of the ER-16, turned: its lowest point's height is coal's own signed distance to
    the plane z = 0."""
    placement = np.tile(np.eye(4), (er16.n_dof, 1, 1))
    placement[:, :3, 3] = [0.1, -0.05, 0.2]
    geometry = LinkGeometry((shape,) * er16.n_dof, np.arange(er16.n_dof), placement, tuple(map(str, range(6))), "test")
    q = rng.uniform(-2.0, 2.0, (8, er16.n_dof))
    low = lowest_points(er16, q, geometry)[..., 2]
    rotation, position = geometry.poses(er16, q)
    plane = coal.Halfspace(np.array([0.0, 0.0, 1.0]), 0.0)
    for n in range(q.shape[0]):
        for g in range(er16.n_dof):
            result = coal.DistanceResult()
            coal.distance(shape, coal.Transform3s(rotation[n, g], position[n, g]), plane, coal.Transform3s(),
                          coal.DistanceRequest(), result)
            assert low[n, g] == pytest.approx(result.min_distance, abs=1e-6)


def test_the_floors_gradient_equals_central_differences(ur10e_with_meshes, rng):  # noqa: F811
    robot = load_robot(ur10e_with_meshes)
    geometry = link_geometry_from_urdf(robot, ur10e_with_meshes)
    needs = floor_needs(robot, geometry, -0.5, 0.05, HOME)
    # the shoulder's housing turns about the vertical first axis: it never moves down
    assert [int(geometry.link[g]) for g in needs.resting] == [0]
    q = rng.uniform(-2.0, 2.0, (20, robot.n_dof))
    found = FloorDistances(robot, q, geometry, -0.5, needs).distances(gradient=True)
    h = 1e-6
    for j in range(robot.n_dof):
        e = np.zeros(robot.n_dof)
        e[j] = h
        fd = (FloorDistances(robot, q + e, geometry, -0.5, needs).dist
              - FloorDistances(robot, q - e, geometry, -0.5, needs).dist) / (2 * h)
        np.testing.assert_allclose(found.gradient[:, :, j], fd, atol=1e-6)


def test_a_mesh_under_the_table_with_every_joint_origin_above_it_is_found(ur10e_with_meshes, rng):  # noqa: F811
    """What the floor was kept on before (joint origins) passes a pose whose wrist mesh is under the table: the
    margins and MuJoCo's check both find it, by the shapes."""
    robot = load_robot(ur10e_with_meshes)
    ws = Workspace(floor=0.0, clearance=0.05, geometry=link_geometry_from_urdf(robot, ur10e_with_meshes))
    _, heights = _pinocchio(ur10e_with_meshes)
    q = HOME + rng.uniform(-1.5, 1.5, (4000, robot.n_dof))
    origins = forward_kinematics(robot, q)[1][:, 1:, 2]  # the joints that move up and down
    shapes = lowest_points(robot, q, ws.geometry, np.flatnonzero(ws.geometry.link >= 1))[..., 2]
    found = np.flatnonzero((origins.min(axis=1) >= 0.05) & (shapes.min(axis=1) < -0.01))
    assert found.size, "no pose with the origins clear and a mesh under the table"
    pose = q[found[0]]
    truth = min(d for d, joint in heights(pose, 0.0).values() if joint > 1)
    assert truth < -0.01
    [margin] = floor_margins(robot, np.zeros(1), pose[None], ws, HOME)
    assert margin.worst == pytest.approx(truth, abs=1e-8) and not margin.margin >= 0
    contacts = cell_contacts(robot, np.zeros(1), pose[None], ws, HOME)
    assert contacts.touching == 1 and contacts.first["body"] == "floor" and contacts.deepest > 0.05


@pytest.mark.parametrize("clearance", [0.05, 0.2])
def test_dynid_excite_over_a_table_holds_every_shape_by_pinocchio_and_coal(ur10e_with_meshes, tmp_path, clearance):  # noqa: F811
    """``dynid excite`` with ``[workspace] floor = 0.0`` under the UR10e's base: at every set-point of excitation.csv
    each moving collision shape stays the clearance above the table (or, a housing that starts within it, no more than
    1 mm lower than it starts, which the output says with the start heights), by Pinocchio's placement of the URDF's
    meshes and coal's distance to the plane; the printed lowest shape and height are that pass's to 1 mm, and MuJoCo's
    check is said to be on the same shapes. With a clearance of 0.2 m the upper arm starts within it."""
    cfg = tmp_path / "excite.toml"
    cfg.write_text(f'robot = "{ur10e_with_meshes}"\n[trajectory]\nharmonics = 2\nfrequency = 0.1\n'
                   f"offsets = {HOME.tolist()}\nrest = true\n"
                   '[limits]\nq_min = ["-pi", "-pi", "-pi", "-pi", "-pi", "-pi"]\nq_max = ["pi", 0.0, "pi", "pi", "pi", "pi"]\n'
                   f"dq_max = 1.0\nddq_max = 4.0\n[workspace]\nfloor = 0.0\nclearance = {clearance}\n"
                   "[design]\nstarts = 1\nmaxiter = 60\ngrid_points = 40\n[output]\nrate = 100\n")
    p = dynid("excite", str(cfg), "--out", str(tmp_path / "out"))
    assert p.returncode == 0, p.stderr
    csv = np.loadtxt(tmp_path / "out" / "excitation.csv", delimiter=",", skiprows=1)
    _, heights = _pinocchio(ur10e_with_meshes)
    start = heights(csv[0, 1:7], 0.0)
    tightest = (np.inf, None, None, None)
    for row in csv:
        for name, (d, joint) in heights(row[1:7], 0.0).items():
            if joint == 0 or abs(d - start[name][0]) < 1e-9 and joint == 1:
                continue  # the base's and the first link's (turning about the vertical axis) never move down
            need = min(clearance, start[name][0] - 1e-3)
            assert d >= need - 1e-6, (name, row[0], d)
            if d - need < tightest[0]:
                tightest = (d - need, name, row[0], d)
    said = " ".join(p.stdout.split())
    _, name, _, lowest = tightest
    found = re.search(rf"the tightest: {name} at t = ([0-9.]+) s, {lowest:.3g} m above it", said)
    assert found, said  # at that time (or another with the same height: a trajectory can be symmetric)
    row = csv[int(np.argmin(np.abs(csv[:, 0] - float(found.group(1)))))]
    assert heights(row[1:7], 0.0)[name][0] == pytest.approx(lowest, abs=1e-3)
    assert "measured on the collision shapes of" in said
    # a shape that starts within the clearance is said with the start height the pass finds and what it is held to
    held = re.search(r"those that start within it, at most 1 mm lower than they start: ([^)]*)\)", said)
    within = {n: d for n, (d, joint) in start.items() if joint > 1 and d < clearance}
    assert bool(held) == bool(within), said
    for part in held.group(1).split(", ") if held else ():
        shape, height = re.fullmatch(r"(\S+) from ([0-9.e-]+) m", part).groups()
        assert start[shape][0] == pytest.approx(float(height), abs=1e-3)
    doc = json.loads((tmp_path / "out" / "excitation.json").read_text())
    [floor] = [m for m in doc["cell_clearance"] if m["constraint"].startswith("floor")]
    assert floor["worst"] == pytest.approx(lowest, abs=1e-3)
    assert doc["workspace"]["geometry"].startswith("collision shapes of")
    mujoco = doc.get("mujoco_contacts")
    # MuJoCo's check held the same shapes to their start height as the pass finds starting within the clearance
    assert mujoco is None or mujoco["touching"] == 0 and set(mujoco["held"]) == set(within), (mujoco, within)


def test_without_collision_shapes_the_capsules_are_an_estimate_said_as_one(tmp_path):
    """The built-in UR10e's URDF names meshes that are not shipped: the floor is kept off capsules about the joint
    origins whose radius is estimated, and the output says so, with the setting that replaces the estimate."""
    cfg = tmp_path / "excite.toml"
    urdf = Path(str(resources.files("dynid.model") / "robots" / "ur10e.urdf"))
    cfg.write_text(f'robot = "{urdf}"\n[trajectory]\nharmonics = 2\nfrequency = 0.1\noffsets = {HOME.tolist()}\n'
                   "rest = true\n[limits]\nddq_max = 4.0\n[workspace]\nfloor = -0.3\n"
                   "[design]\nstarts = 1\nmaxiter = 30\ngrid_points = 40\n[output]\nrate = 50\n")
    p = dynid("excite", str(cfg), "--out", str(tmp_path / "out"))
    assert p.returncode == 0, p.stderr
    said = " ".join((p.stdout + p.stderr).split())
    assert "no collision shapes dynid could read" in said and "give [workspace] link_radius" in said
    given = cfg.read_text().replace("floor = -0.3\n", "floor = -0.3\nlink_radius = 0.08\n")
    cfg.write_text(given)
    p = dynid("excite", str(cfg), "--out", str(tmp_path / "given"))
    assert p.returncode == 0, p.stderr
    said = " ".join((p.stdout + p.stderr).split())
    assert "no collision shapes dynid could read" not in said
    assert "capsules of radius 0.08 m about the joint origins ([workspace] link_radius)" in said


def test_a_collision_mesh_that_is_a_device_is_named_and_a_point_arm_still_has_capsules(tmp_path):
    """Round five: a collision mesh that is /dev/zero (or 2 GB) was refused naming a C++ source file of Pinocchio's; it
    is named now. Read as capsules, an arm whose joints sit at one point had capsules of radius 0, which MuJoCo's
    check refused with a traceback."""
    from dynid.exceptions import ConfigError
    from dynid.excitation.link_geometry import SMALLEST_LINK_RADIUS

    urdf = tmp_path / "point.urdf"
    urdf.write_text('<robot name="r"><link name="base"/><link name="l1"><inertial><mass value="1"/><inertia ixx="0.1" '
                    'iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry><mesh '
                    'filename="/dev/zero"/></geometry></collision></link><joint name="j1" type="revolute"><parent '
                    'link="base"/><child link="l1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" '
                    'velocity="1"/></joint></robot>')
    robot = load_robot(urdf)
    with pytest.raises(ConfigError, match=r"point.urdf: collision mesh /dev/zero: /dev/zero is not a regular file"):
        link_geometry_from_urdf(robot, urdf)
    assert Workspace().capsule_radius(robot) == SMALLEST_LINK_RADIUS
    cfg = tmp_path / "excite.toml"
    cfg.write_text(f'robot = "{urdf}"\n[trajectory]\nharmonics = 2\nfrequency = 0.2\n[workspace]\nfloor = -1.0\n'
                   "[design]\nstarts = 1\nmaxiter = 5\n[output]\nrate = 50\n")
    p = dynid("excite", str(cfg), "--out", str(tmp_path / "out"))
    assert p.returncode == 0 and "Traceback" not in p.stderr, p.stderr
