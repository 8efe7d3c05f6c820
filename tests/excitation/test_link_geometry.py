"""The links' own collision shapes against the cell (issue "An excitation safe to run on the real robot", item 1):
read from a URDF whose collision meshes are boxes written here as STL files, placed as Pinocchio places them, their
distances against a hand-computed truth, their gradients, and the config's geometry setting."""

import re
from dataclasses import replace
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from dynid.dynamics.kinematics import forward_kinematics
from dynid.exceptions import ConfigError
from dynid.excitation.cell_replay import cell_contacts
from dynid.excitation.constraints import Workspace
from dynid.excitation.design import ExcitationProblem, design_excitation
from dynid.excitation.link_geometry import FAR, LinkGeometry, link_geometry_from_urdf, self_distances, self_pairs
from dynid.excitation.obstacles import Obstacle
from dynid.io.config.excitation_config import load_excitation_config
from dynid.model.description import load_robot

UR10E = Path(str(resources.files("dynid.model") / "robots" / "ur10e.urdf"))
HALF = np.array([0.06, 0.05, 0.12])  # every mesh is this box about its mesh frame's origin


def _box_stl(path: Path) -> None:
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * HALF
    faces = []
    for axis in range(3):
        for side in (-1, 1):
            quad = [i for i in range(8) if np.sign(corners[i, axis]) == side]
            a, b, c, d = sorted(quad, key=lambda i: np.arctan2(*np.delete(corners[i], axis)[::-1]))
            faces += [(a, b, c), (a, c, d)]
    triangles = np.array([[corners[i] for i in f] for f in faces], dtype="<f4")  # binary STL: header, count, facets
    record = np.zeros(len(faces), dtype=[("normal", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])
    record["vertices"] = triangles
    path.write_bytes(b"box".ljust(80, b" ") + np.uint32(len(faces)).tobytes() + record.tobytes())


@pytest.fixture(scope="module")
def ur10e_with_meshes(tmp_path_factory):
    """The built-in UR10e URDF with its collision meshes present, in a package layout ``package://`` resolves."""
    root = tmp_path_factory.mktemp("pkg")
    text = UR10E.read_text()
    for name in set(re.findall(r"package://ur_e_description/meshes/ur10e/collision/(\w+)\.stl", text)):
        target = root / "ur_e_description" / "meshes" / "ur10e" / "collision" / f"{name}.stl"
        target.parent.mkdir(parents=True, exist_ok=True)
        _box_stl(target)
    urdf = root / "ur_e_description" / "urdf" / "ur10e.urdf"
    urdf.parent.mkdir(parents=True)
    urdf.write_text(text)
    return urdf


def test_shapes_ride_on_the_links_where_pinocchio_places_them(ur10e_with_meshes, rng):
    import pinocchio as pin

    robot = load_robot(ur10e_with_meshes)
    geometry = link_geometry_from_urdf(robot, ur10e_with_meshes)
    assert geometry is not None and len(geometry.shapes) > robot.n_dof and list(geometry.link).count(-1) == 1  # the base's
    model = pin.buildModelFromUrdf(str(ur10e_with_meshes))
    geom = pin.buildGeomFromUrdf(model, str(ur10e_with_meshes), pin.GeometryType.COLLISION,
                                 package_dirs=[str(p) for p in ur10e_with_meshes.parents])
    data, gdata = model.createData(), pin.GeometryData(geom)
    q = rng.uniform(-2.0, 2.0, (5, robot.n_dof))
    rotation, position = geometry.poses(robot, q)
    for n in range(q.shape[0]):
        pin.updateGeometryPlacements(model, data, geom, gdata, q[n])
        for s, name in enumerate(geometry.names):
            placed = gdata.oMg[geom.getGeometryId(name)]
            np.testing.assert_allclose(position[n, s], placed.translation, atol=1e-12)
            np.testing.assert_allclose(rotation[n, s], placed.rotation, atol=1e-12)


def test_a_shapes_distance_and_gradient_against_a_hand_computed_truth(ur10e_with_meshes, rng):
    """A ball against box meshes: the distance is the ball centre's distance to each box (clipped in the box's
    frame) less the radius and the clearance; the gradient equals central differences."""
    robot = load_robot(ur10e_with_meshes)
    ball = Obstacle("sphere", np.array([0.25]), np.array([0.3, 0.2, 0.8]), name="ball")
    ws = Workspace(clearance=0.03, obstacles=(ball,), geometry=link_geometry_from_urdf(robot, ur10e_with_meshes))
    q = rng.uniform(-2.0, 2.0, (40, robot.n_dof))
    found = ws.cell_distances(robot, q, gradient=True)
    rotation, position = ws.geometry.poses(robot, q)
    local = np.einsum("nsji,nsj->nsi", rotation, ball.position - position)  # the centre in each box's frame
    half = np.array([np.asarray(s.halfSide) if hasattr(s, "halfSide") else HALF for s in ws.geometry.shapes])  # ee_link: a <box>
    truth = np.linalg.norm(np.maximum(np.abs(local) - half, 0.0), axis=-1) - 0.25 - 0.03
    shapes = [g for g, _ in found.pairs]
    assert shapes == np.flatnonzero(ws.geometry.link >= 0).tolist()  # every shape but the base's
    truth = truth[:, shapes]
    outside = truth > 1e-3 - 0.28
    near = outside & (found.distance < FAR)  # GJK's; farther, the bounding spheres' lower bound
    np.testing.assert_allclose(found.distance[near], truth[near], atol=1e-7)
    assert near.sum() >= 20 and np.all(found.distance[~near & outside] <= truth[~near & outside] + 1e-9)
    assert found.distance.min() < 0 < found.distance.max()
    h = 1e-6
    for j in range(robot.n_dof):
        e = np.zeros(robot.n_dof)
        e[j] = h
        fd = (ws.cell_distances(robot, q + e).distance - ws.cell_distances(robot, q - e).distance) / (2 * h)
        clear = found.distance > 1e-3 - 0.03
        np.testing.assert_allclose(found.gradient[:, :, j][clear], fd[clear], atol=1e-6)
    assert list(found.links) == [int(ws.geometry.link[g]) for g in shapes]


def test_a_measurement_gives_its_gradient_from_the_same_coal_results(ur10e_with_meshes, rng, monkeypatch):
    """A design asks the distances at an iterate, then their gradient there: the measurement's gradient is the one
    measured afresh with the gradient, to the bit, and coal is not asked again (each shape pair within FAR once)."""
    from dynid.excitation import link_geometry as lg

    robot = load_robot(ur10e_with_meshes)
    ball = Obstacle("sphere", np.array([0.25]), np.array([0.3, 0.2, 0.8]), name="ball")
    ws = Workspace(clearance=0.03, obstacles=(ball,), geometry=link_geometry_from_urdf(robot, ur10e_with_meshes))
    pairs = self_pairs(robot, ws.geometry)
    q = rng.uniform(-2.0, 2.0, (30, robot.n_dof))
    fresh = [self_distances(robot, q, ws.geometry, pairs, gradient=True), ws.cell_distances(robot, q, gradient=True)]
    calls = []
    real = lg.distance_above
    monkeypatch.setattr(lg, "distance_above", lambda *a: calls.append(1) or real(*a))
    for measured, expected in zip((lambda: lg.SelfDistances(robot, q, ws.geometry, pairs), lambda: ws.cell_measure(robot, q)),
                                  fresh):
        measure = measured()
        asked = len(calls)
        assert asked > 0  # coal asked while measuring (pairs within FAR)
        got = measure.distances(gradient=True)
        assert len(calls) == asked  # and not again for the gradient
        np.testing.assert_array_equal(got.distance, expected.distance)
        np.testing.assert_array_equal(got.gradient, expected.gradient)
        np.testing.assert_array_equal(measure.dist, expected.distance)
        calls.clear()


def test_coal_measures_only_the_pairs_that_can_be_near_each_samples_nearest(ur10e_with_meshes, rng, monkeypatch):
    """With ``within``, every sample's smallest distance is coal's, every pair coal was not asked for keeps its bounding
    spheres' distance (a lower bound of coal's) and lies at least ``within`` above the sample's smallest; coal is asked
    fewer times."""
    from dynid.excitation import link_geometry as lg

    robot = load_robot(ur10e_with_meshes)
    geometry = link_geometry_from_urdf(robot, ur10e_with_meshes)
    pairs = self_pairs(robot, geometry)
    q = rng.uniform(-2.0, 2.0, (40, robot.n_dof))
    calls = []
    real = lg.distance_above
    monkeypatch.setattr(lg, "distance_above", lambda *a: calls.append(1) or real(*a))
    exact = lg.SelfDistances(robot, q, geometry, pairs).dist
    every = len(calls)
    calls.clear()
    within = 0.02
    pruned = lg.SelfDistances(robot, q, geometry, pairs, within=within).dist
    assert 0 < len(calls) < every
    np.testing.assert_array_equal(pruned.min(axis=1), exact.min(axis=1))
    kept = pruned != exact
    assert kept.any()
    assert np.all(pruned[kept] < exact[kept])  # the spheres' bound, below coal's distance
    floor = np.broadcast_to(exact.min(axis=1)[:, None] + within, exact.shape)
    assert np.all(pruned[kept] >= floor[kept] - 1e-12)


def test_coal_measures_each_samples_pairs_in_the_order_of_their_bounds_until_none_can_be_nearest(rng):
    """The branch and bound of ``within``: at each sample coal is asked exactly the pairs a plain loop over the bounds
    in ascending order asks, stopping at the first bound ``within`` or more above the smallest distance found so far;
    pairs of spheres at known distances, their bounds loose by up to 4 cm (so that the lowest bound is often not the
    nearest pair)."""
    import coal

    from dynid.excitation import link_geometry as lg

    n_samples, n_pairs, within, radius = 50, 8, 0.02, 0.05
    true = rng.uniform(0.0, 0.08, (n_samples, n_pairs))
    bounds = true - rng.uniform(0.0, 0.04, true.shape)
    sphere = coal.Sphere(radius)
    apart = [[(coal.Transform3s(np.eye(3), np.zeros(3)), coal.Transform3s(np.eye(3), np.array([d + 2 * radius, 0, 0])))
              for d in row] for row in true]
    asked: set = set()
    dist = bounds.copy()

    def shapes_at(n, c):
        asked.add((n, c))
        return sphere, apart[n][c][0], sphere, apart[n][c][1]

    found = lg._coal_results(dist, 0.0, shapes_at, within=within)
    expected = set()
    for n in range(n_samples):
        best = np.inf
        for c in np.argsort(bounds[n], kind="stable"):
            if bounds[n, c] >= lg.FAR or bounds[n, c] >= best + within:
                break
            expected.add((n, int(c)))
            best = min(best, true[n, c])
    assert asked == expected and len(found) == len(expected)
    np.testing.assert_allclose(dist.min(axis=1), true.min(axis=1), atol=1e-9)  # every sample's nearest, coal's
    unasked = np.ones(true.shape, bool)
    unasked[tuple(np.array(sorted(expected)).T)] = False
    np.testing.assert_array_equal(dist[unasked], bounds[unasked])
    assert np.all(dist[unasked] >= true.min(axis=1, keepdims=True).repeat(n_pairs, 1)[unasked] + within - 1e-12)

def test_the_nearest_points_of_two_segments_against_a_dense_search(rng):
    """Ericson's closest points of two segments: their distance is the smallest over a dense grid of the first
    segment (each grid point's exact distance to the second), on random segments and on parallel, collinear and
    zero-length ones; each point lies on its segment."""
    from dynid.excitation.link_geometry import _nearest_on_segments

    p1, q1, p2, q2 = rng.uniform(-1.0, 1.0, (4, 40, 3))
    q2[:8] = p2[:8] + (q1[:8] - p1[:8]) * rng.uniform(-2.0, 2.0, (8, 1))  # parallel, some reversed
    p2[8:12] = p1[8:12] + 0.5 * (q1[8:12] - p1[8:12])  # collinear, overlapping
    q2[8:12] = p1[8:12] + 1.7 * (q1[8:12] - p1[8:12])
    q1[12:16] = p1[12:16]  # the first a point
    q2[16:20] = p2[16:20]  # the second a point
    q1[20:22], q2[20:22] = p1[20:22], p2[20:22]  # both
    c1, c2 = _nearest_on_segments(p1, q1, p2, q2)
    grid = p1[:, None] + np.linspace(0.0, 1.0, 4001)[None, :, None] * (q1 - p1)[:, None]  # (40, 4001, 3)
    d = q2 - p2
    t = np.clip(np.einsum("gki,gi->gk", grid - p2[:, None], d) / np.maximum(np.einsum("gi,gi->g", d, d), 1e-300)[:, None],
                0.0, 1.0)
    dense = np.linalg.norm(grid - p2[:, None] - t[..., None] * d[:, None], axis=-1).min(axis=1)
    found = np.linalg.norm(c2 - c1, axis=-1)
    assert np.all(found <= dense + 1e-12) and np.all(found >= dense - 1e-6)
    for p, q, c in ((p1, q1, c1), (p2, q2, c2)):  # on the segment: its distances to the ends add up to the length
        np.testing.assert_allclose(np.linalg.norm(c - p, axis=-1) + np.linalg.norm(q - c, axis=-1),
                                   np.linalg.norm(q - p, axis=-1), atol=1e-12)


def test_the_bounding_capsules_hold_their_shapes_and_tighten_the_spheres_bound(ur10e_with_meshes, rng, monkeypatch):
    """Each shape's capsule holds its points (a hull's, a box's corners, a cylinder's rims); the self distances' bound
    is the larger of the bounding spheres' and the capsules', never above coal's distance, and above the spheres'
    alone on most pairs of these long boxes, so that coal is asked about fewer pairs."""
    import coal

    from dynid.excitation import link_geometry as lg
    from dynid.excitation.link_geometry import _bounding_capsule

    cylinder = coal.Cylinder(0.05, 0.4)
    angle = np.linspace(0.0, 2 * np.pi, 50)
    rims = np.concatenate([np.stack([0.05 * np.cos(angle), 0.05 * np.sin(angle), np.full(50, z)], axis=1)
                           for z in (-0.2, 0.2)])
    robot = load_robot(ur10e_with_meshes)
    geometry = link_geometry_from_urdf(robot, ur10e_with_meshes)
    shapes = [(s, np.asarray(s.points())) for s in geometry.shapes if isinstance(s, coal.ConvexBase)]
    box = coal.Box(0.3, 0.1, 0.05)
    shapes += [(box, np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * [0.15, 0.05, 0.025]),
               (cylinder, rims)]
    for shape, points in shapes:
        (a, b), radius = _bounding_capsule(shape)
        on = a + np.clip((points - a) @ (b - a) / max((b - a) @ (b - a), 1e-300), 0.0, 1.0)[:, None] * (b - a)
        assert np.linalg.norm(points - on, axis=1).max() <= radius + 1e-12
    assert _bounding_capsule(box)[1] == pytest.approx(np.hypot(0.05, 0.025))  # about the long axis
    pairs = self_pairs(robot, geometry)
    q = rng.uniform(-2.0, 2.0, (40, robot.n_dof))
    centre, radius, _, _ = geometry.bounds(robot, q)
    a, b = (np.array([p[k] for p in pairs]) for k in (0, 1))
    spheres = np.linalg.norm(centre[:, b] - centre[:, a], axis=-1) - radius[a] - radius[b]
    calls = []
    real = lg.distance_above
    monkeypatch.setattr(lg, "distance_above", lambda *args: calls.append(1) or real(*args))
    measured = lg.SelfDistances(robot, q, geometry, pairs).dist
    assert 0 < len(calls) < int((spheres < FAR).sum())  # coal was asked of every pair whose spheres are near
    assert np.all(measured >= spheres - 1e-12)
    monkeypatch.setattr(lg, "FAR", np.inf)  # coal's distance of every pair
    exact = lg.SelfDistances(robot, q, geometry, pairs).dist
    assert np.all(measured <= exact + 1e-9) and np.any(measured < exact - 1e-3)  # a lower bound where coal was not asked


def test_the_soft_minimum_is_a_smooth_lower_bound_of_the_minimum(rng):
    """Kreisselmeier-Steinhauser: at most the minimum and at least ``log(P) / ρ`` below it; its gradient against
    central differences."""
    from dynid.excitation.design import soft_min

    a = rng.normal(size=(8, 12, 5)) * 0.1
    x = rng.normal(size=5)
    values = lambda x: np.einsum("npx,x->np", a, x) + 0.05  # noqa: E731
    soft, grad = soft_min(values(x), a, sharpness=300.0)
    low = values(x).min(axis=1)
    assert np.all(soft <= low) and np.all(soft >= low - np.log(12) / 300.0)
    h = 1e-6
    fd = np.stack([(soft_min(values(x + h * e), sharpness=300.0)[0] - soft_min(values(x - h * e), sharpness=300.0)[0])
                   / (2 * h) for e in np.eye(5)], axis=1)
    np.testing.assert_allclose(grad, fd, atol=1e-7)
    one = np.array([[0.3, 0.5], [0.1, 0.1]])  # one pair far off: the minimum; two equal: log(2)/ρ below
    np.testing.assert_allclose(soft_min(one, sharpness=1e3)[0], [0.3, 0.1 - np.log(2) / 1e3], atol=1e-12)


def test_mujoco_sees_the_shapes_within_the_clearance_where_coal_does(ur10e_with_meshes, rng):
    robot = load_robot(ur10e_with_meshes)
    crate = Obstacle("box", np.array([0.5, 0.4, 0.4]), np.array([0.4, 0.2, 0.6]), np.array([0.2, 0.0, 0.5]), name="crate")
    ws = Workspace(clearance=0.03, obstacles=(crate,), geometry=link_geometry_from_urdf(robot, ur10e_with_meshes))
    q = rng.uniform(-2.0, 2.0, (120, robot.n_dof))
    d = ws.cell_distances(robot, q).distance.min(axis=1)
    clear = np.abs(d) > 1e-3
    touching = np.array([cell_contacts(robot, np.zeros(1), q[n:n + 1], ws).touching > 0 for n in range(q.shape[0])])
    assert (d[clear] < 0).sum() >= 10 and (d[clear] > 0).sum() >= 10
    np.testing.assert_array_equal(touching[clear], d[clear] < 0)


def _config(tmp_path: Path, urdf: Path, geometry: str | None) -> Path:
    cfg = tmp_path / f"excite-{geometry}.toml"
    cfg.write_text(f'robot = "{urdf}"\n[trajectory]\nharmonics = 2\nfrequency = 0.1\n'
                   '[workspace]\n' + (f'geometry = "{geometry}"\n' if geometry else "")
                   + '[[workspace.obstacles]]\nshape = "box"\nsize = [0.2, 0.2, 0.2]\nposition = [0.8, 0.6, 0.3]\n')
    return cfg


def test_the_config_takes_the_urdfs_shapes_by_default_and_says_when_it_cannot(ur10e_with_meshes, tmp_path):
    assert load_excitation_config(_config(tmp_path, ur10e_with_meshes, None)).problem.workspace.geometry is not None
    assert load_excitation_config(_config(tmp_path, ur10e_with_meshes, "capsules")).problem.workspace.geometry is None
    # the shipped URDF names meshes that are not shipped: "auto" keeps the capsules, "collision" says why not
    assert load_excitation_config(_config(tmp_path, UR10E, None)).problem.workspace.geometry is None
    with pytest.raises(ConfigError, match=r"ur10e\.urdf: its collision geometry could not be read \(Mesh package://"):
        load_excitation_config(_config(tmp_path, UR10E, "collision"))


def test_self_distances_gradient_and_the_pairs_that_can_touch(ur10e_with_meshes, rng):
    robot = load_robot(ur10e_with_meshes)
    geometry = link_geometry_from_urdf(robot, ur10e_with_meshes)
    pairs = self_pairs(robot, geometry)
    links = [(int(geometry.link[g]), int(geometry.link[h])) for g, h in pairs]
    assert pairs and all(abs(a - b) >= 2 for a, b in links)  # never the same link or neighbours
    assert any(a == -1 for a, _ in links)  # the base is kept off too
    q = rng.uniform(-2.0, 2.0, (30, robot.n_dof))
    found = self_distances(robot, q, geometry, pairs, gradient=True)
    h = 1e-6
    for j in range(robot.n_dof):
        e = np.zeros(robot.n_dof)
        e[j] = h
        fd = (self_distances(robot, q + e, geometry, pairs).distance - self_distances(robot, q - e, geometry, pairs).distance) / (2 * h)
        clear = found.distance > 1e-3
        np.testing.assert_allclose(found.gradient[:, :, j][clear], fd[clear], atol=1e-6)


def test_the_design_keeps_the_links_shapes_apart_by_pinocchios_own_check(ur10e_with_meshes):
    """A design with the URDF's shapes: on a 10× finer grid, Pinocchio's geometry model of the same file (its own
    kinematics and the meshes themselves) finds every checked pair apart."""
    import pinocchio as pin

    robot = load_robot(ur10e_with_meshes)
    geometry = link_geometry_from_urdf(robot, ur10e_with_meshes)
    q0 = np.array([0.0, -np.pi / 2, np.pi / 2, -np.pi / 2, -np.pi / 2, 0.0])
    limits = replace(robot.limits, q_min=np.full(6, -np.pi), q_max=np.full(6, np.pi), ddq_max=np.full(6, 4.0))
    prob = ExcitationProblem(robot, 2 * np.pi * 0.1, 2, limits=limits, offsets=q0, rest=True, grid_points=40,
                             workspace=Workspace(geometry=geometry))
    design = design_excitation(prob, n_starts=1, rng=0, maxiter=60)
    assert design.feasible and [m for m in design.margins if m.constraint.startswith("self clearance")]
    model = pin.buildModelFromUrdf(str(ur10e_with_meshes))
    geom = pin.buildGeomFromUrdf(model, str(ur10e_with_meshes), pin.GeometryType.COLLISION,
                                 package_dirs=[str(p) for p in ur10e_with_meshes.parents])
    ids = {name: geom.getGeometryId(name) for name in geometry.names}
    for g, h in self_pairs(robot, geometry):
        geom.addCollisionPair(pin.CollisionPair(ids[geometry.names[g]], ids[geometry.names[h]]))
    data, gdata = model.createData(), pin.GeometryData(geom)
    t = np.linspace(0, design.trajectory.period, 400, endpoint=False)
    for qn in design.trajectory.evaluate(t)[0]:
        pin.computeDistances(model, data, geom, gdata, qn)
        assert min(r.min_distance for r in gdata.distanceResults) > -1e-6


def test_an_srdfs_disabled_pairs_are_not_kept_apart(ur10e_with_meshes, tmp_path):
    """MoveIt's SRDF: the shapes on the links a ``<disable_collisions>`` names are excluded from the self pairs, the
    others kept; an SRDF of another robot and one given where it cannot apply are refused in one line."""
    import pinocchio as pin

    robot = load_robot(ur10e_with_meshes)
    plain = link_geometry_from_urdf(robot, ur10e_with_meshes)
    model = pin.buildModelFromUrdf(str(ur10e_with_meshes))
    geom = pin.buildGeomFromUrdf(model, str(ur10e_with_meshes), pin.GeometryType.COLLISION,
                                 package_dirs=[str(p) for p in ur10e_with_meshes.parents])
    link_of = [model.frames[o.parentFrame].name for o in geom.geometryObjects]  # each shape's URDF link
    pairs = self_pairs(robot, plain)
    disabled = {frozenset((link_of[g], link_of[h])) for g, h in pairs[:2]}
    srdf = tmp_path / "ur10e.srdf"
    srdf.write_text('<?xml version="1.0"?>\n<robot name="ur10e">\n' + "".join(
        f'  <disable_collisions link1="{a}" link2="{b}" reason="Never"/>\n' for a, b in map(sorted, disabled)) + "</robot>\n")
    geometry = link_geometry_from_urdf(robot, ur10e_with_meshes, srdf)
    assert {frozenset((link_of[g], link_of[h])) for g, h in geometry.excluded} == disabled
    kept = self_pairs(robot, geometry)
    assert set(kept) == {(g, h) for g, h in pairs if frozenset((link_of[g], link_of[h])) not in disabled}
    other = tmp_path / "other.srdf"
    other.write_text('<robot name="x"><disable_collisions link1="base_link" link2="gripper_palm" reason="Adjacent"/></robot>')
    with pytest.raises(ConfigError, match=r"other\.srdf: <disable_collisions> names link 'gripper_palm', which the URDF "
                                          r"does not have"):
        link_geometry_from_urdf(robot, ur10e_with_meshes, other)
    cfg = _config(tmp_path, ur10e_with_meshes, None)
    cfg.write_text(cfg.read_text().replace("[workspace]\n", f'[workspace]\nsrdf = "{srdf.name}"\n'))
    assert load_excitation_config(cfg).problem.workspace.geometry.excluded == geometry.excluded
    cfg.write_text(cfg.read_text().replace("[workspace]\n", '[workspace]\ngeometry = "capsules"\n'))
    with pytest.raises(ConfigError, match='workspace.geometry = "capsules" leaves them out'):
        load_excitation_config(cfg)


def test_the_last_trajectorys_poses_are_reused_only_for_that_trajectory(ur10e_with_meshes, rng):
    """The poses, bounding volumes and coal transforms kept for the last trajectory asked are those of the trajectory asked:
    alternating two trajectories, each answer equals a fresh geometry's."""
    robot = load_robot(ur10e_with_meshes)
    kept = link_geometry_from_urdf(robot, ur10e_with_meshes)
    one, two = rng.uniform(-2.0, 2.0, (2, 7, robot.n_dof))
    for q in (one, two, one, two.copy()):
        fresh = replace(kept, memo={})
        for mine, theirs in zip(kept.poses(robot, q) + kept.bounds(robot, q), fresh.poses(robot, q) + fresh.bounds(robot, q)):
            np.testing.assert_array_equal(mine, theirs)
        pose = kept.pose_of(robot, q)  # coal's, made when asked: one shape at one sample
        np.testing.assert_array_equal(pose(3, 2).getTranslation(), fresh.poses(robot, q)[1][3, 2])
        np.testing.assert_array_equal(pose(3, 2).getRotation(), fresh.poses(robot, q)[0][3, 2])
        assert fresh.pose_of(robot, q)(3, 2) is not None and len(fresh.memo["last"]["transforms"]) == 1
    assert kept.memo["last"]["key"][2] == two.tobytes()


def test_the_same_arm_as_mjcf_has_the_same_shapes_where_it_matters(ur10e_with_meshes, tmp_path, rng):
    """The URDF with its meshes read by MuJoCo and saved as MJCF (what a MuJoCo user holds): its collision geoms,
    read through MuJoCo, measure the distances the URDF's, read through Pinocchio, measure, wherever a shape is near
    the body (far away each stands by its own bounding sphere: MuJoCo moves a mesh's frame to its centre of mass)."""
    import shutil

    import mujoco

    from dynid.excitation.link_geometry import link_geometry_from_mjcf

    text = ur10e_with_meshes.read_text()
    meshes = tmp_path / "meshes"
    meshes.mkdir()
    for name in set(re.findall(r"package://ur_e_description/meshes/ur10e/collision/(\w+\.stl)", text)):
        shutil.copy(ur10e_with_meshes.parents[1] / "meshes" / "ur10e" / "collision" / name, meshes / name)
    flat = re.sub(r'filename="package://[^"]*/([^"/]+)"', r'filename="\1"', text)
    flat = re.sub(r"(<robot\b[^>]*>)", rf'\1<mujoco><compiler meshdir="{meshes}" discardvisual="true" '
                  'fusestatic="false" balanceinertia="true"/></mujoco>', flat, count=1)
    mujoco.mj_saveLastXML(str(tmp_path / "ur10e.xml"), mujoco.MjModel.from_xml_string(flat))
    robot_u, robot_m = load_robot(ur10e_with_meshes), load_robot(tmp_path / "ur10e.xml")
    from_urdf = link_geometry_from_urdf(robot_u, ur10e_with_meshes)
    from_mjcf = link_geometry_from_mjcf(robot_m, tmp_path / "ur10e.xml")
    assert sorted(from_urdf.link.tolist()) == sorted(from_mjcf.link.tolist())
    ball = Obstacle("sphere", np.array([0.2]), np.array([0.4, 0.3, 0.6]), name="ball")
    q = rng.uniform(-2.5, 2.5, (300, robot_u.n_dof))
    near = []
    for geometry, robot in ((from_urdf, robot_u), (from_mjcf, robot_m)):
        found = Workspace(clearance=0.0, obstacles=(ball,), geometry=geometry).cell_distances(robot, q).distance
        near.append(np.sort(found, axis=1)[:, 0])
    close = (near[0] < FAR) & (near[1] < FAR)
    assert close.sum() >= 10
    np.testing.assert_allclose(near[1][close], near[0][close], atol=1e-6)


def test_a_failed_penetration_depth_never_stands_as_a_distance():
    """Two cylinders overlapping deeply (met on the Unitree Z1's base and forearm at random poses): coal's EPA, at the
    tolerance dynid asks of it, returns -DBL_MAX. The distance dynid reports is finite, no further below zero than the
    shapes can overlap, and coal's own at its default tolerance."""
    import coal

    robot = load_robot("ur10e")
    q = np.zeros((1, robot.n_dof))
    rots, orig = forward_kinematics(robot, q)
    world_a = np.eye(4)
    world_a[:3, :3] = _orthonormal([[-0.75376635, 0.64351775, 0.13312098], [-0.1012432, 0.08643501, -0.9910998],
                                    [-0.64929662, -0.76053527, 0.0]])
    world_a[:3, 3] = [0.0, 0.0, 0.1035]
    world_b = np.eye(4)
    world_b[:3, :3] = _orthonormal([[-0.03125238, 0.54853752, -0.83554167], [-0.13271962, 0.82627017, 0.54741494],
                                    [0.99066078, 0.1280008, 0.04697878]])
    world_b[:3, 3] = [0.00570798, 0.05004193, 0.15288241]
    frame = np.eye(4)
    frame[:3, :3], frame[:3, 3] = rots[0, 2], orig[0, 2]
    shapes = (coal.Cylinder(0.0325, 0.102), coal.Cylinder(0.0325, 0.051))
    geometry = LinkGeometry(shapes, np.array([-1, 2]), np.stack([world_a, np.linalg.solve(frame, world_b)]),
                            ("base", "forearm"), "test")
    found = self_distances(robot, q, geometry, [(0, 1)], gradient=True)
    loose = coal.DistanceResult()
    coal.distance(shapes[0], coal.Transform3s(world_a[:3, :3], world_a[:3, 3]), shapes[1],
                  coal.Transform3s(world_b[:3, :3], world_b[:3, 3]), coal.DistanceRequest(), loose)
    assert -0.0325 * 2 < found.distance[0, 0] < 0
    np.testing.assert_allclose(found.distance[0, 0], loose.min_distance, atol=1e-5)
    assert np.all(np.isfinite(found.gradient))


def _orthonormal(rows) -> np.ndarray:
    u, _, vt = np.linalg.svd(np.asarray(rows, dtype=float))
    return u @ vt
