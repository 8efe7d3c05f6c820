"""The excitation design of two arms on a turning torso (issue "Every arm a user has", item 3): one design for every
branch at once, each arm's joints moving its own links only, and the arms kept apart from each other."""

import json

import numpy as np
import pytest

from dynid.excitation.constraints import Workspace
from dynid.excitation.design import ExcitationProblem, _Layout, _Objective
from dynid.excitation.link_geometry import capsule_geometry, self_pairs
from dynid.excitation.obstacles import Obstacle
from dynid.model.description import load_robot

from ..dynamics.test_tree_robots import TWO_ARMS
from .test_design import _finite_difference, jacobians_checked


@pytest.fixture(scope="module")
def two_arms(tmp_path_factory):
    path = tmp_path_factory.mktemp("tree") / "two_arms.urdf"
    path.write_text(TWO_ARMS)
    return load_robot(path), path


def test_the_jacobians_of_two_arms_equal_finite_differences(two_arms, rng):
    """Each origin moves with the joints that carry it alone (the left arm's joints do not move the right arm), and the
    tool (on the last joint) with its own branch's."""
    robot, _ = two_arms
    jo, jt = jacobians_checked(robot, robot.limits.random_positions(4, rng))
    assert np.all(jt[:, :, 1:4] == 0.0) and np.all(jo[:, 4:, :, 1:4] == 0.0)  # the left arm moves no right-arm point


def test_the_torso_carries_a_capsule_to_each_arm_and_the_arms_are_kept_apart(two_arms):
    """Capsules about the joint origins: the torso's link one to each arm's shoulder, a hand (no joint after it) a
    sphere; the self-collision pairs hold shapes of the two arms, never a link and the one that carries it."""
    robot, _ = two_arms
    geometry = capsule_geometry(robot, 0.03)
    assert geometry.link.tolist() == [0, 0, 1, 2, 3, 4, 5, 6]
    assert geometry.names[:2] == ("link 1 capsule 1", "link 1 capsule 2")
    assert geometry.shapes[4].halfLength == 0.0 < geometry.shapes[3].halfLength  # the left hand a sphere, its forearm not
    length = [float(np.linalg.norm(j.translation)) for j in robot.joints]
    assert robot.reach == pytest.approx(max(sum(length[:4]), length[0] + sum(length[4:]) + 0.2))  # the longest branch
    pairs = self_pairs(robot, geometry)
    links = [(int(geometry.link[g]), int(geometry.link[h])) for g, h in pairs]
    parents = robot.parents
    assert (3, 6) in links and (2, 5) in links  # the hands, the forearms
    assert all(a != b and parents[a] != b and parents[b] != a for a, b in links)


def test_the_design_gradients_of_two_arms_equal_finite_differences(two_arms, rng):
    """Criterion, torques, workspace box, floor, a cell's body and the arms' distance to each other, by the chain rule
    through the tree."""
    robot, _ = two_arms
    robot = robot.without_drive_terms(robot.drive_terms)
    ball = Obstacle("sphere", np.array([0.2]), np.array([1.6, 0.9, 0.9]))
    ws = Workspace(box_min=np.array([-5.0, -5.0, -5.0]), box_max=np.array([5.0, 5.0, 5.0]), floor=-0.3,
                   obstacles=(ball,), link_radius=0.03, avoid_self_collision=True)
    prob = ExcitationProblem(robot, 2 * np.pi / 10, 3, workspace=ws, grid_points=36)
    lay = _Layout(prob, prob.design_grid())
    obj = _Objective(prob, lay)
    assert obj.pairs and obj.needs is not None
    x = np.concatenate([prob.start_pose(), 0.3 * rng.standard_normal(lay.nx - robot.n_dof)])
    assert np.exp(obj.fun(x)) < 1e7
    np.testing.assert_allclose(obj.jac(x), _finite_difference(obj.fun, x), rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(obj.cons_jac(x), _finite_difference(obj.cons, x).reshape(-1, x.size), rtol=1e-4,
                               atol=1e-6)


def test_dynid_excite_designs_both_arms_at_once_and_holds_every_constraint(two_arms, tmp_path):
    """A config whose robot is the whole tree (as dynid init writes for a log of both arms): one design of every joint, every
    constraint held on the 10× finer check, the prismatic lift's margins in metres, the arms' distance to each other
    among the margins, and the workspace's box kept by both hands, as Pinocchio places them along excitation.csv (the
    box held the tool alone: the left hand rose to 1.66 m under a 1.6 m ceiling while every constraint was said to
    hold)."""
    import pinocchio as pin

    from ..cli.refusals import dynid

    _, path = two_arms
    config = tmp_path / "arm.toml"
    config.write_text(f'robot = "{path}"\n\n[design]\nstarts = 1\n\n[trajectory]\nharmonics = 3\n\n[workspace]\n'
                      'floor = 0.0\nlink_radius = 0.04\navoid_self_collision = true\nbox_max = [inf, inf, 1.6]\n')
    p = dynid("excite", str(config), "--out", str(tmp_path / "out"))
    assert p.returncode == 0, p.stderr
    design = json.loads((tmp_path / "out" / "excitation.json").read_text())["design"]
    assert design["cond"] < 0.5 * design["initial_cond"] and design["feasible"]
    assert all(m["margin"] >= 0 for m in design["margins"] if m["margin"] is not None and np.isfinite(m["margin"]))
    assert {"q_min [m]", "q_max [m]"} <= {m["constraint"] for m in design["margins"] if m["where"] == "joint 6"}
    apart = [m for m in design["margins"] if m["constraint"] == "self clearance [m]"]
    assert len(apart) == 1 and apart[0]["margin"] >= 0, apart
    said_apart = json.loads((tmp_path / "out" / "excitation.json").read_text())["self_clearance"]["distance"]
    # one figure, the 0.04 m capsules the design keeps apart, as minima over two samplings of the motion (the design's
    # 10x finer check, the set-points): 4e-6 m apart on one CPU's optimum, printed to the millimetre
    assert abs(apart[0]["worst"] - said_apart) < 1e-4
    said = " ".join(p.stdout.split())
    assert "joints 1-7" in said, said
    boxed = {m["where"] for m in design["margins"] if m["constraint"] == "workspace [m]"}
    assert {"tip of left_j3 z <= 1.6 m", "tool z <= 1.6 m"} <= boxed, boxed
    q = np.loadtxt(tmp_path / "out" / "excitation.csv", delimiter=",", skiprows=1)[:, 1:8]
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    for k in range(q.shape[0]):
        pin.forwardKinematics(model, data, q[k])
        assert max(data.oMi[4].translation[2], data.oMi[7].translation[2]) <= 1.6, k  # the left hand, the right


def _skeleton_from_pinocchio(urdf, q):
    """Every link's segments by Pinocchio's kinematics of the URDF: from its joint's origin to each child joint's (or,
    a tip, to itself; the last joint's link to the flange, at its origin here: no tool)."""
    import pinocchio as pin

    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    parents = [p - 1 for p in model.parents[1:]]
    n = len(parents)
    out = []
    for k in range(n):
        children = [c for c in range(n) if parents[c] == k] or [k]
        out += [(k, data.oMi[k + 1].translation.copy(), data.oMi[c + 1].translation.copy()) for c in children]
    return out, parents


def test_each_capsule_runs_on_its_own_link_across_every_pose(two_arms, rng):
    """The capsules the self-collision check measures without collision shapes: one per link and joint it carries,
    their ends where Pinocchio puts the link's origin and its child's (a capsule from the left hand to the right
    shoulder, which the serial rule drew, changed length as the arms moved)."""
    from dynid.excitation.obstacles import link_segments

    robot, path = two_arms
    q = robot.limits.random_positions(20, rng)
    seg = link_segments(robot, q)
    for k in range(q.shape[0]):
        truth, _ = _skeleton_from_pinocchio(path, q[k])
        assert seg.shape[1] == len(truth) == 8
        for (_, start, stop), s in zip(truth, seg[k]):
            np.testing.assert_allclose(s[0], start, atol=1e-12)
            np.testing.assert_allclose(s[1], stop, atol=1e-12)


def test_the_arms_capsule_clearance_is_the_closest_pair_of_their_links(two_arms, rng):
    """The self clearance said for capsules (coal, the pairs that can touch) equals a brute-force measure on Pinocchio's
    skeleton, 400 points per segment, over every pair of links that are neither one link nor a link and its carrier."""
    from dynid.excitation.collision import self_clearance

    robot, path = two_arms
    radius = 0.04
    q = robot.limits.random_positions(12, rng)
    found = self_clearance(robot, np.arange(12.0), q, radius)
    measured = {}
    s = np.linspace(0.0, 1.0, 400)[:, None]
    for k in range(q.shape[0]):
        truth, parents = _skeleton_from_pinocchio(path, q[k])
        points = [(link, a + s * (b - a)) for link, a, b in truth]
        for i, (li, pi) in enumerate(points):
            for lj, pj in points[i + 1:]:
                if li == lj or parents[lj] == li or parents[li] == lj:
                    continue
                d = np.linalg.norm(pi[:, None] - pj[None], axis=-1).min() - 2 * radius
                measured[li + 1, lj + 1] = min(measured.get((li + 1, lj + 1), np.inf), d)
    best = min(measured.values())
    assert found is not None and abs(found.distance - best) < 2e-3, (found, best)
    assert measured[found.pair] < best + 2e-3  # a hand's point ends its forearm: either may be named


def test_the_animation_draws_each_arm_on_its_own_links(two_arms, rng):
    """The animation's lines (consecutive points between NaN breaks) are the base to the torso and each link to the
    joints it carries, where Pinocchio puts them: none joins the left hand to the right shoulder, as the serial
    polyline did. A serial chain keeps its polyline: the base, the joint origins, the tool point."""
    import pinocchio as pin

    from dynid.dynamics.kinematics import forward_kinematics
    from dynid.report.excitation_run import arm_skeleton

    robot, path = two_arms
    q = robot.limits.random_positions(3, rng)
    skeleton = arm_skeleton(robot, q)
    for k in range(3):
        truth, _ = _skeleton_from_pinocchio(path, q[k])
        model = pin.buildModelFromUrdf(str(path))
        data = model.createData()
        pin.forwardKinematics(model, data, q[k])
        expected = {(tuple(np.round(a, 9)), tuple(np.round(b, 9))) for _, a, b in truth}
        expected.add(((0.0, 0.0, 0.0), tuple(np.round(data.oMi[1].translation, 9))))  # the base to the torso
        drawn = {(tuple(np.round(a, 9)), tuple(np.round(b, 9))) for a, b in zip(skeleton[k, :-1], skeleton[k, 1:])
                 if np.isfinite(a).all() and np.isfinite(b).all()}
        assert drawn == expected
    er16 = load_robot("er16")
    q = er16.limits.random_positions(2, rng)
    rots, origins = forward_kinematics(er16, q)
    np.testing.assert_array_equal(arm_skeleton(er16, q)[:, 1:-1], origins)
