"""The excitation design of an arm on a linear track (issue "Every arm a user has", item 1): its gradients with a
prismatic joint, where a point moves along the axis rather than about it."""

import re

import numpy as np
import pytest

from dynid.excitation.constraints import Workspace
from dynid.excitation.design import ExcitationProblem, _Layout, _Objective
from dynid.excitation.link_geometry import link_geometry_from_urdf
from dynid.excitation.obstacles import Obstacle
from dynid.model.description import load_robot

from ..dynamics.test_prismatic_joints import TRACKED
from .test_design import _finite_difference, jacobians_checked

BOXES = '<collision><origin xyz="0 0 0.05"/><geometry><box size="0.12 0.1 0.2"/></geometry></collision></link>'


@pytest.fixture(scope="module")
def tracked(tmp_path_factory):
    path = tmp_path_factory.mktemp("tracked") / "tracked.urdf"
    path.write_text(TRACKED.replace("</inertial></link>", "</inertial>" + BOXES))
    return load_robot(path), path


def test_the_jacobians_of_a_tracked_arm_equal_finite_differences(tracked, rng):
    robot, _ = tracked
    jacobians_checked(robot, robot.limits.random_positions(4, rng))


@pytest.mark.parametrize("shapes", ["capsules", "collision boxes"])
def test_the_design_gradients_of_a_tracked_arm_equal_finite_differences(tracked, rng, shapes):
    """Criterion, torques, workspace box, floor and a cell's body, by the chain rule through a prismatic joint."""
    robot, path = tracked
    robot = robot.without_drive_terms(robot.drive_terms)  # the rigid links: a W whose cond W^T W resolves
    geometry = link_geometry_from_urdf(robot, path) if shapes == "collision boxes" else None
    ball = Obstacle("sphere", np.array([0.2]), np.array([1.6, 0.9, 0.9]))
    ws = Workspace(box_min=np.array([-5.0, -5.0, -5.0]), box_max=np.array([5.0, 5.0, 5.0]), floor=-0.3,
                   obstacles=(ball,), geometry=geometry, **({} if geometry else {"link_radius": 0.03}))
    prob = ExcitationProblem(robot, 2 * np.pi / 10, 3, workspace=ws, grid_points=36)
    lay = _Layout(prob, prob.design_grid())
    obj = _Objective(prob, lay)
    assert obj.pairs and obj.needs is not None
    x = np.concatenate([prob.start_pose(), 0.3 * rng.standard_normal(lay.nx - robot.n_dof)])
    assert np.exp(obj.fun(x)) < 1e6  # a W whose cond W^T W resolves: the criterion is smooth there
    np.testing.assert_allclose(obj.jac(x), _finite_difference(obj.fun, x), rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(obj.cons_jac(x), _finite_difference(obj.cons, x).reshape(-1, x.size), rtol=1e-4,
                               atol=1e-4 if geometry else 1e-6)


def test_dynid_excite_designs_a_tracked_arm_and_says_metres(tracked, tmp_path, monkeypatch):
    """`dynid excite arm.urdf` on a tracked arm: the design improves on its start (a flat criterion ended it there,
    cond 1.9e10 kept), the first row's track position is said in metres, the margins and excitation.csv's columns in m and m/s; each start's
    progress line says the best design so far, and on a terminal each SLSQP iteration of it (issue "Fast where users
    wait", item 3)."""
    import json

    from dynid.report.console import Progress

    from ..cli.refusals import dynid

    shown = []  # what a terminal's live line is given: a long start says its SLSQP iterations
    update = Progress.update
    monkeypatch.setattr(Progress, "update", lambda self, step, detail="": (shown.append((step, detail)),
                                                                          update(self, step, detail))[1])
    _, path = tracked
    p = dynid("excite", str(path), "--out", str(tmp_path / "out"), "--starts", "2")
    assert ("design, 0 of 2 starts done", "(SLSQP iteration 1, at most 150)") in shown, shown[:5]
    assert any(step.startswith("design, 1 of 2 starts done, best cond so far") for step, _ in shown), shown[-5:]
    said = " ".join(p.stdout.split())
    assert p.returncode == 0, p.stderr
    assert re.search(r"^dynid excite: design, 1 of 2 starts done, best cond so far \d", p.stderr, re.M), p.stderr  # a pipe
    assert re.search(r"it starts at rest at J1 \d\.\d{3} m, J2 -?\d+\.\d°", said), said
    design = json.loads((tmp_path / "out" / "excitation.json").read_text())["design"]
    assert design["cond"] < 0.5 * design["initial_cond"]
    track = {m["constraint"] for m in design["margins"] if m["where"] == "joint 1"}
    assert {"q_min [m]", "q_max [m]", "|dq| [m/s]", "|tau| [N]"} <= track, track
    header = (tmp_path / "out" / "excitation.csv").read_text().splitlines()[0].split(",")  # the set-points' units
    assert {"q1 [m]", "dq1 [m/s]", "ddq1 [m/s^2]", "q2 [rad]", "dq2 [rad/s]"} <= set(header), header
