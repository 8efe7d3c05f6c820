"""The cell's bodies in the excitation design: distances of the links' capsules (a robot file without collision
shapes) against a brute-force truth, their gradients, a design that keeps clear of a body its collision-free
counterpart crosses, and the errors a user sees."""

from pathlib import Path

import numpy as np
import pytest

from dynid.dynamics.kinematics import forward_kinematics
from dynid.exceptions import ConfigError
from dynid.excitation.cell_replay import cell_contacts, cell_mjcf
from dynid.excitation.constraints import Workspace
from dynid.excitation.design import ExcitationProblem, design_excitation
from dynid.excitation.obstacles import Obstacle
from dynid.excitation.paper_trajectories import PAPER_OMEGA_F, paper_identification_trajectory
from dynid.identification.excite import run_excitation
from dynid.io.config.excitation_config import load_excitation_config
from dynid.model.description import load_robot
from dynid.report.excitation_run import save_excitation
from dynid.report.excitation_summary import excitation_blocks

RADIUS = 0.05


def _capsule_distances(robot, q, bodies, *, gradient=False):
    """The links' capsules of :data:`RADIUS`, surface to surface, as the design measures them (no clearance beyond)."""
    return Workspace(obstacles=tuple(bodies), clearance=0.0, link_radius=RADIUS).cell_distances(robot, q, gradient=gradient)


@pytest.fixture(scope="module")
def er16():
    return load_robot("er16")


def _segment_points(robot, q, samples=4001):
    """(N, n_dof, samples, 3): points along each link's segment, from forward kinematics alone."""
    rots, orig = forward_kinematics(robot, q)
    flange = orig[:, -1] + rots[:, -1] @ robot.tool_translation
    ends = np.concatenate([orig[:, 1:], flange[:, None]], axis=1)
    s = np.linspace(0.0, 1.0, samples)[None, None, :, None]
    return orig[:, :, None] + s * (ends - orig)[:, :, None]


def _brute_force(robot, q, ob):
    """(N, n_dof) surface distance of each link's capsule to an axis-aligned box (outside it) or a sphere."""
    pts = _segment_points(robot, q)
    if ob.shape == "sphere":
        return np.linalg.norm(pts - ob.position, axis=-1).min(axis=-1) - ob.size[0] - RADIUS
    half = 0.5 * ob.size
    gap = np.maximum(np.abs(pts - ob.position) - half, 0.0)
    return np.linalg.norm(gap, axis=-1).min(axis=-1) - RADIUS


BOX = Obstacle("box", np.array([0.4, 0.5, 0.3]), np.array([0.9, 0.3, 0.2]), name="table")
BALL = Obstacle("sphere", np.array([0.2]), np.array([0.6, 0.4, 1.0]), name="ball")
POST = Obstacle("cylinder", np.array([0.1, 1.0]), np.array([0.5, -0.6, 0.5]), np.array([0.3, 0.0, 0.2]), name="post")


def test_distances_equal_a_brute_force_segment_distance(er16, rng, monkeypatch):
    import dynid.excitation.link_geometry as link_geometry

    monkeypatch.setattr(link_geometry, "FAR", 10.0)  # every pair measured by coal, none left at its bounding volumes'
    q = rng.uniform(-1.5, 1.5, (40, er16.n_dof))
    found = _capsule_distances(er16, q, [BOX, BALL])
    truth = {i: _brute_force(er16, q, ob) for i, ob in enumerate([BOX, BALL])}
    checked = 0
    for c, (k, i) in enumerate(found.pairs):
        d = found.distance[:, c]
        keep = d > 1e-3 if i == 0 else np.ones(d.size, bool)  # the brute force reads 0 inside the box
        np.testing.assert_allclose(d[keep], truth[i][keep, k], atol=1e-5)
        checked += keep.sum()
    assert checked > 200
    assert (found.distance < 0).any() and (found.distance > 0).any()  # both sides of contact were met


def test_gradients_equal_finite_differences(er16, rng):
    q = rng.uniform(-1.5, 1.5, (25, er16.n_dof))
    bodies = [BOX, BALL, POST]
    found = _capsule_distances(er16, q, bodies, gradient=True)
    h = 1e-6
    fd = np.zeros_like(found.gradient)
    for j in range(er16.n_dof):
        e = np.zeros(er16.n_dof)
        e[j] = h
        fd[:, :, j] = (_capsule_distances(er16, q + e, bodies).distance
                       - _capsule_distances(er16, q - e, bodies).distance) / (2 * h)
    outside = found.distance > 1e-3  # away from contact: overlap depth is not smooth where the medial axis turns
    exact = np.array([i == 1 for _, i in found.pairs])[None, :] & outside  # a ball: coal's closed form
    np.testing.assert_allclose(found.gradient[exact], fd[exact], atol=1e-7)
    gjk = np.array([i != 1 for _, i in found.pairs])[None, :] & outside  # a box and a cylinder by GJK, to 1e-9
    np.testing.assert_allclose(found.gradient[gjk], fd[gjk], atol=1e-3)


def test_the_design_keeps_clear_of_a_body_beta1_passes_through():
    """A ball on β1's wrist path: β1 goes through it, the design from β1 keeps every link clear on a 10× finer
    grid by the brute-force distance."""
    robot = load_robot("er16").submodel(3)
    beta1 = paper_identification_trajectory()
    ball = Obstacle("sphere", np.array([0.15]), np.array([0.609, 0.161, 1.274]), name="lamp")
    prob = ExcitationProblem(robot, PAPER_OMEGA_F, 5, offsets=beta1.q0, workspace=Workspace(obstacles=(ball,)))
    t = np.linspace(0, beta1.period, 10 * prob.grid_points, endpoint=False)
    assert _brute_force(robot, beta1.evaluate(t)[0], ball).min() < -0.05
    [before] = [m for m in prob.margins(beta1) if m.constraint.startswith("obstacle")]
    assert not before.satisfied and before.where.startswith("lamp: link 3")
    design = design_excitation(prob, n_starts=1, rng=0, initial=beta1)
    assert design.feasible
    assert _brute_force(robot, design.trajectory.evaluate(t)[0], ball).min() >= -1e-6
    assert design.cond < design.initial_cond
    # checked twice: MuJoCo's collision detection finds β1 in the ball and the design clear of it
    before, after = (cell_contacts(robot, t, traj.evaluate(t)[0], prob.workspace) for traj in (beta1, design.trajectory))
    assert before.touching > 0 and before.first["body"] == "lamp" and before.deepest > 0.05
    assert after.touching == 0 and after.deepest == 0.0


def test_mujoco_places_the_capsules_on_dynids_skeleton(er16, rng):
    """The MJCF of the cell check: MuJoCo's capsule centres equal the midpoints of dynid's link segments."""
    import mujoco

    q = rng.uniform(-1.5, 1.5, (5, er16.n_dof))
    model = mujoco.MjModel.from_xml_string(cell_mjcf(er16, Workspace(obstacles=(BALL,))))
    data = mujoco.MjData(model)
    pts = _segment_points(er16, q, samples=3)
    for n in range(q.shape[0]):
        data.qpos[:] = q[n]
        mujoco.mj_forward(model, data)
        for k in range(er16.n_dof):
            g = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"link{k + 1}_shape{k}")
            np.testing.assert_allclose(data.geom_xpos[g], pts[n, k, 1], atol=1e-9)


def test_a_start_pose_inside_a_body_is_refused_in_one_line(er16):
    q0 = np.zeros(er16.n_dof)
    wrist = forward_kinematics(er16, q0[None])[1][0, 4]
    inside = Obstacle("box", np.array([0.2, 0.2, 0.2]), wrist, name="fixture")
    with pytest.raises(ConfigError, match=r"start pose .* obstacle 'fixture'") as err:
        ExcitationProblem(er16, PAPER_OMEGA_F, 2, offsets=q0, workspace=Workspace(obstacles=(inside,)))
    assert "\n" not in str(err.value)


def test_config_reads_obstacles_and_names_a_bad_one(tmp_path: Path):
    body = """robot = "er16"
joints = 3
[workspace]
link_radius = 0.05
[design]
starts = 1
maxiter = 20
[trajectory]
harmonics = 2
frequency = 0.1
[[workspace.obstacles]]
name = "table"
shape = "box"
size = [1.0, 1.0, 0.1]
position = [0.0, 1.2, -0.3]
[[workspace.obstacles]]
shape = "cylinder"
size = [0.1, 1.5]
position = [1.1, 0.0, 0.0]
rpy = [0.0, 1.5707963, 0.0]
"""
    good = tmp_path / "good.toml"
    good.write_text(body)
    ws = load_excitation_config(good).problem.workspace
    assert [ob.name for ob in ws.obstacles] == ["table", "obstacle 2"]
    assert ws.to_dict()["obstacles"][1]["rpy"] == [0.0, 1.5707963, 0.0]
    run = run_excitation(load_excitation_config(good))  # the set-points checked again, and said
    table = [m for m in run.cell_clearance if m.where.startswith("table")]
    pts = _segment_points(run.config.problem.robot, run.q[::10], samples=401)  # the brute force, every 10th set-point
    gap = np.maximum(np.abs(pts - ws.obstacles[0].position) - 0.5 * ws.obstacles[0].size, 0.0)
    brute = float(np.linalg.norm(gap, axis=-1).min()) - ws.capsule_radius(run.config.problem.robot) - ws.clearance
    assert table and table[0].worst <= brute + 1e-6 and table[0].worst == pytest.approx(brute, abs=5e-3)
    assert run.to_dict()["cell_clearance"][0]["where"].startswith("table")
    assert any("off the cell at the set-points" in getattr(line, "text", "") for line in excitation_blocks(run))
    written = {p.name for p in save_excitation(run, tmp_path / "out")}  # seen before it runs: the cell and the distances
    assert {"excitation_tool_path.png", "excitation_clearance.png"} <= written
    assert "How close the links come to the floor and the cell" in (tmp_path / "out" / "report.html").read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text(body.replace("size = [0.1, 1.5]", "size = [0.1]"))
    with pytest.raises(ConfigError, match=r"bad\.toml: obstacle 'obstacle 2': size: a cylinder takes 2 positive"):
        load_excitation_config(bad)


def test_mujoco_and_coal_agree_on_a_turned_cylinder_and_box(er16, rng):
    """The second check sees the bodies where the first does: a pose touches in MuJoCo exactly when coal's distance is
    below zero (poses within a millimetre of contact left out), for bodies turned by their rpy."""
    turned_box = Obstacle("box", np.array([0.5, 0.2, 0.3]), np.array([0.7, 0.2, 0.4]), np.array([0.0, 0.4, 0.8]), name="crate")
    bodies = (POST, turned_box)
    q = rng.uniform(-1.5, 1.5, (120, er16.n_dof))
    ws = Workspace(obstacles=bodies, link_radius=RADIUS)
    coal_d = ws.cell_distances(er16, q).distance.min(axis=1)
    clear = np.abs(coal_d) > 1e-3
    touching = np.array([cell_contacts(er16, np.zeros(1), q[n:n + 1], ws).touching > 0 for n in range(q.shape[0])])
    assert (coal_d[clear] < 0).sum() >= 10 and (coal_d[clear] > 0).sum() >= 10
    np.testing.assert_array_equal(touching[clear], coal_d[clear] < 0)


def test_a_trajectory_that_fails_at_the_set_points_is_not_written(tmp_path, monkeypatch):
    """The set-points are checked after the design: a contact MuJoCo reports there, or a link inside the cell's
    clearance between the verification grid's samples, stops the run before anything is written."""
    import dynid.identification.excite as er
    from dynid.excitation.cell_replay import CellContacts
    from dynid.excitation.constraints import ConstraintMargin
    from dynid.excitation.design import InfeasibleDesignError

    cfg = tmp_path / "excite.toml"
    cfg.write_text('robot = "er16"\njoints = 3\n[design]\nstarts = 1\nmaxiter = 20\n[trajectory]\nharmonics = 2\n'
                   'frequency = 0.1\n[[workspace.obstacles]]\nshape = "sphere"\nsize = [0.1]\nposition = [1.5, 1.5, 1.5]\n')
    config = load_excitation_config(cfg)
    assert run_excitation(config).mujoco_contacts.touching == 0  # clear: it runs
    touching = CellContacts(10, 2, {"link": 3, "body": "ball", "time": 1.25, "depth": 0.01}, 0.01)
    monkeypatch.setattr(er, "cell_contacts", lambda *a: touching)
    with pytest.raises(InfeasibleDesignError, match=r"MuJoCo finds link 3 touching ball at t = 1.25 s on 2 set-points: "
                                                    r"nothing written"):
        run_excitation(config)
    monkeypatch.setattr(er, "cell_contacts", lambda *a: None)
    inside = ConstraintMargin("obstacle clearance [m]", "ball: link 3 at t = 2 s", 0.0, -0.004, -0.004, np.nan)
    monkeypatch.setattr(er, "obstacle_margins", lambda *a: [inside])
    with pytest.raises(InfeasibleDesignError, match=r"0.004 m inside the cell's clearance .*ball: link 3 at t = 2 s"):
        run_excitation(config)
