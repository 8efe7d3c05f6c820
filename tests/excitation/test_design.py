"""Excitation design (paper eq. 15): gradients, constraints on a finer grid, criterion, errors."""

from dataclasses import replace

import numpy as np
import pytest

from dynid.dynamics.kinematics import forward_kinematics, tool_positions
from dynid.dynamics.rnea import rnea_torques
from dynid.exceptions import ConfigError
from dynid.excitation.constraints import Workspace
from dynid.excitation.design import ExcitationProblem, _Layout, _Objective, condition_number, design_excitation
from dynid.excitation.obstacles import Obstacle
from dynid.excitation.paper_trajectories import PAPER_OMEGA_F, paper_identification_trajectory
from dynid.model.description import load_robot


@pytest.fixture(scope="module")
def er16_3():
    return load_robot("er16").submodel(3)


def _finite_difference(f, x, h=1e-5):
    cols = []
    for i in range(x.size):
        e = np.zeros_like(x)
        e[i] = h
        cols.append((np.asarray(f(x + e)) - np.asarray(f(x - e))) / (2 * h))
    return np.stack(cols, axis=-1)


def jacobians_checked(robot, q):
    """The joint origins' and the tool point's Jacobians at ``q`` (N, n_dof), each checked against central
    differences of the kinematics to 1e-8; returned ``(origins', tool's)``."""
    from dynid.dynamics.kinematics import forward_kinematics, tool_positions
    from dynid.dynamics.sensitivity import origins_jacobian, tool_jacobian

    _, jo = origins_jacobian(robot, q)
    _, jt = tool_jacobian(robot, q)
    for k in range(q.shape[0]):
        np.testing.assert_allclose(jo[k], _finite_difference(lambda x: forward_kinematics(robot, x[None])[1][0], q[k]),
                                   atol=1e-8)
        np.testing.assert_allclose(jt[k], _finite_difference(lambda x: tool_positions(robot, x[None])[0], q[k]),
                                   atol=1e-8)
    return jo, jt


@pytest.mark.parametrize("criterion", ["cond", "d-optimal"])
def test_gradients_equal_finite_differences_of_the_whole_problem(er16_3, rng, criterion):
    """The chain-rule gradients (criterion, torque, workspace and obstacle constraints) against central differences."""
    ball = Obstacle("sphere", np.array([0.2]), np.array([0.6, 0.4, 1.0]))
    ws = Workspace(box_min=np.array([-3.0, -3.0, -3.0]), box_max=np.array([3.0, 3.0, 3.0]), floor=-1.5, obstacles=(ball,),
                   link_radius=0.02)
    prob = ExcitationProblem(er16_3, PAPER_OMEGA_F, 2, workspace=ws, criterion=criterion, grid_points=24)
    lay = _Layout(prob, prob.design_grid())
    obj = _Objective(prob, lay)
    assert obj.pairs and obj.needs is not None and obj.needs.shapes.tolist() == [1, 2]  # link 1 turns about z
    x = np.concatenate([prob.start_pose(), 0.3 * rng.standard_normal(lay.nx - 3)])
    np.testing.assert_allclose(obj.jac(x), _finite_difference(obj.fun, x), rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(obj.cons_jac(x), _finite_difference(obj.cons, x).reshape(-1, x.size), rtol=1e-5, atol=1e-6)


def _check_every_constraint_independently(robot, prob, traj):
    """Positions, velocities, accelerations, Pinocchio RNEA torques and tool point on a 10× finer grid."""
    t = np.linspace(0, traj.period, 10 * prob.grid_points, endpoint=False)
    q, dq, ddq = traj.evaluate(t)
    lim = prob.limits
    assert np.all(q >= lim.q_min) and np.all(q <= lim.q_max)
    assert np.all(np.abs(dq) <= lim.dq_max) and np.all(np.abs(ddq) <= lim.ddq_max)
    assert np.all(np.abs(rnea_torques(robot, q, dq, ddq)) <= lim.tau_max)
    p = tool_positions(robot, q)
    ws = prob.workspace
    assert np.all(p >= ws.box_min) and np.all(p <= ws.box_max) and np.all(p[:, 2] >= ws.floor)
    if np.isfinite(ws.floor):  # every link's capsule above the floor by the clearance, or as high as it starts
        low = _capsule_bottoms(robot, q, ws.capsule_radius(robot))
        start = _capsule_bottoms(robot, prob.start_pose()[None], ws.capsule_radius(robot))[0]
        moving = np.ptp(low, axis=0) > 1e-6
        need = np.minimum(ws.floor + ws.clearance, start - 1e-3)
        assert np.all(low[:, moving] >= need[moving] - 1e-9)


def _capsule_bottoms(robot, q, radius):
    """(N, n_dof) the lowest point of each link's capsule of ``radius`` about its joint origin and the next's (the
    flange's for the last), by forward kinematics alone: a segment's lowest point is one of its ends."""
    rots, orig = forward_kinematics(robot, q)
    flange = orig[:, -1] + rots[:, -1] @ robot.tool_translation
    ends = np.concatenate([orig[:, 1:], flange[:, None]], axis=1)
    return np.minimum(orig[..., 2], ends[..., 2]) - radius


def test_er16_design_halves_cond_of_beta1_and_satisfies_every_constraint(er16_3):
    beta1 = paper_identification_trajectory()
    prob = ExcitationProblem(er16_3, PAPER_OMEGA_F, 5, offsets=beta1.q0)
    assert not [m for m in prob.margins(beta1) if not m.satisfied]  # β1 satisfies the robot's limits
    said = []  # every SLSQP iteration said as it ends: each run counts 1, 2, …, at most maxiter, one run per start or more
    design = design_excitation(prob, n_starts=2, rng=0, initial=beta1, iteration=lambda k, most: said.append((k, most)))
    assert said[0][0] == 1 and all(k == 1 or k == before + 1 for (before, _), (k, _) in zip(said, said[1:]))
    assert all(most == 150 and k <= most for k, most in said) and sum(k == 1 for k, _ in said) >= 2
    assert len(said) <= design.nit  # SciPy's count holds each run's last steps too (134 against 128 said here)
    assert design.initial_cond == pytest.approx(condition_number(prob, beta1))
    assert design.cond <= 0.5 * design.initial_cond
    assert design.cond == pytest.approx(condition_number(prob, design.trajectory))
    np.testing.assert_array_equal(design.trajectory.q0, beta1.q0)
    assert design.feasible
    _check_every_constraint_independently(er16_3, prob, design.trajectory)


def test_rest_workspace_and_torque_constraints_hold_and_seed_reproduces(er16_3):
    """Tight torque limits, a floor and a box that bind; start and end at rest; same seed, same design."""
    tau_max = np.array([300.0, 600.0, 250.0])
    ws = Workspace(box_min=np.array([-1.5, -1.5, -0.6]), box_max=np.array([1.5, 1.5, 1.5]), floor=-0.3)
    prob = ExcitationProblem(er16_3, PAPER_OMEGA_F, 3, limits=replace(er16_3.limits, tau_max=tau_max),
                             workspace=ws, rest=True, grid_points=60)
    a = design_excitation(prob, n_starts=2, rng=3)
    b = design_excitation(prob, n_starts=2, rng=3)
    np.testing.assert_array_equal(a.trajectory.a, b.trajectory.a)
    assert a.cond < a.initial_cond
    _check_every_constraint_independently(er16_3, prob, a.trajectory)
    q, dq, ddq = a.trajectory.evaluate(np.array([0.0, a.trajectory.period]))
    np.testing.assert_allclose(q, np.tile(a.trajectory.q0, (2, 1)), atol=1e-8)
    np.testing.assert_allclose(dq, 0.0, atol=1e-8)
    np.testing.assert_allclose(ddq, 0.0, atol=1e-7)
    binding = [m for m in a.margins if m.constraint.startswith(("|tau|", "workspace")) and m.margin < 0.1 * abs(m.limit) + 0.05]
    assert binding, "expected the torque or workspace limits to shape the design"


@pytest.mark.parametrize("change, message", [
    (lambda lim: dict(limits=replace(lim, q_min=lim.q_max.copy(), q_max=lim.q_min.copy())),
     "joint 1 has q_max = -2.96 rad not above q_min = 2.96 rad"),
    (lambda lim: dict(workspace=Workspace(floor=2.0)), "workspace excludes the start pose"),
    (lambda lim: dict(workspace=Workspace(box_min=np.zeros(3), box_max=np.array([0.0, 1.0, 1.0]))), "box_min must be below box_max"),
    (lambda lim: dict(limits=replace(lim, tau_max=np.array([1200.0, 10.0, 700.0]))), "holding the start pose needs"),
    (lambda lim: dict(limits=replace(lim, dq_max=np.array([0.0, 1.0, 1.0]))), "dq_max: joint 1 has 0 rad/s"),
    (lambda lim: dict(offsets=np.array([0.0, 2.0, 0.0])), "joint 2 offset 2 rad is not inside its limits"),
    (lambda lim: dict(criterion="a-optimal"), "design.criterion must be one of cond, d-optimal"),
])
def test_infeasible_settings_get_a_clear_error(er16_3, change, message):
    with pytest.raises(ConfigError, match=message):
        ExcitationProblem(er16_3, PAPER_OMEGA_F, 5, **change(er16_3.limits))


@pytest.mark.parametrize("maxiter", [0, -1, 2.5, True])
def test_an_iteration_budget_that_is_not_a_positive_integer_is_refused(er16_3, maxiter):
    """SLSQP ran with ``maxiter=-1`` in silence."""
    with pytest.raises(ConfigError, match=r"^design.maxiter must be a positive integer"):
        design_excitation(ExcitationProblem(er16_3, PAPER_OMEGA_F, 3), n_starts=1, maxiter=maxiter)


def test_initial_trajectory_at_another_fundamental_pulsation_is_refused(er16_3):
    beta1 = paper_identification_trajectory(2 * PAPER_OMEGA_F)
    prob = ExcitationProblem(er16_3, PAPER_OMEGA_F, 5, offsets=beta1.q0)
    with pytest.raises(ConfigError, match="fundamental pulsation"):
        design_excitation(prob, n_starts=1, rng=0, initial=beta1)


def test_the_origins_jacobian_equals_finite_differences(er16_3, rng):
    from dynid.dynamics.sensitivity import origins_jacobian

    q = rng.uniform(-1.0, 1.0, (4, 3))
    _, jac = origins_jacobian(er16_3, q)
    for k in range(4):
        fd = _finite_difference(lambda x: forward_kinematics(er16_3, x[None])[1][0], q[k])
        np.testing.assert_allclose(jac[k], fd, rtol=1e-6, atol=1e-8)


def test_a_floor_keeps_every_links_shape_above_it_not_only_the_tool(er16_3):
    """The paper's β1 trajectory, its offsets kept, designed over a floor 0.65 m below the base: the er16 has no
    collision shapes, so each link is a capsule about its joint origins (radius estimated, 0.255 m), and β1 takes link
    3's capsule to -0.661 m, under the floor, though joint 3's origin never goes below 0.44 m (what the floor was kept
    on before). The design holds every capsule the clearance above the floor, checked on a
    10× finer grid by forward kinematics alone."""
    beta1 = paper_identification_trajectory()
    ws = Workspace(floor=-0.65, clearance=0.05)
    prob = ExcitationProblem(er16_3, PAPER_OMEGA_F, 5, offsets=beta1.q0, workspace=ws)
    [floor] = [m for m in prob.margins(beta1) if m.constraint.startswith("floor clearance")]
    assert floor.where.startswith("link 3 capsule") and floor.worst < 0 and floor.margin < -0.05
    q = beta1.evaluate(prob.verification_grid())[0]
    assert floor.worst == pytest.approx(float(_capsule_bottoms(er16_3, q, 0.255)[:, 2].min()) + 0.65, abs=2e-3)
    assert forward_kinematics(er16_3, q)[1][:, 2, 2].min() > -0.65 + 0.05 + 1.0  # the origin was far above it
    design = design_excitation(prob, n_starts=2, rng=0, initial=beta1)
    assert design.feasible
    _check_every_constraint_independently(er16_3, prob, design.trajectory)


def test_starts_solved_on_the_second_core_give_the_design_of_one_process(er16_3, monkeypatch):
    """Inside the CLI's ``allow_forks`` a forked child and this process each take the next start as they come free: the
    design, each start's criterion value, SLSQP's iterations and the criterion's evaluations are those of the starts
    solved one after the other in this process, and a child did solve some (issue "Fast where users wait")."""
    from dynid.excitation import design as design_module
    from dynid.runtime import processes

    forked, by_child = [], []

    class Recorded(processes.ForkedCall):
        def __init__(self, fn, *args):
            super().__init__(fn, *args)
            forked.append(self._child is not None)

        def result(self):
            value = super().result()
            by_child.extend(i for i, _ in value)
            return value

    monkeypatch.setattr(design_module, "ForkedCall", Recorded)
    monkeypatch.setattr(processes, "cores", lambda: 2)
    tau_max = np.array([300.0, 600.0, 250.0])
    prob = ExcitationProblem(er16_3, PAPER_OMEGA_F, 3, limits=replace(er16_3.limits, tau_max=tau_max),
                             workspace=Workspace(floor=-0.3), grid_points=60)
    said = []
    alone = design_excitation(prob, n_starts=3, rng=5)
    assert not forked  # the library alone never forks
    with processes.allow_forks():
        beside = design_excitation(prob, n_starts=3, rng=5, callback=lambda done, n, best: said.append((done, n, best)))
    assert forked == [True] and by_child  # the child took starts as it came free
    for field in ("a", "b", "q0"):
        np.testing.assert_array_equal(getattr(beside.trajectory, field), getattr(alone.trajectory, field))
    assert beside.start_values == alone.start_values and len(set(alone.start_values)) == 3
    assert (beside.nit, beside.nfev, beside.cond) == (alone.nit, alone.nfev, alone.cond)
    assert [d for d, _, _ in said] == [1, 2, 3] and said[-1][2] == beside.cond


def test_starts_a_child_claimed_and_left_no_answer_for_are_solved_here(er16_3, monkeypatch):
    """A child whose answer is lost (killed) after claiming starts: this process solves those starts too, and the
    design is the one process's."""
    from dynid.excitation import design as design_module
    from dynid.runtime import processes

    lost = []

    class Lost(processes.ForkedCall):
        def result(self):
            lost.extend(i for i, _ in super().result())
            return []

    monkeypatch.setattr(design_module, "ForkedCall", Lost)
    monkeypatch.setattr(processes, "cores", lambda: 2)
    prob = ExcitationProblem(er16_3, PAPER_OMEGA_F, 3, limits=replace(er16_3.limits, tau_max=np.array([300.0, 600.0, 250.0])),
                             workspace=Workspace(floor=-0.3), grid_points=60)
    alone = design_excitation(prob, n_starts=3, rng=5)
    with processes.allow_forks():
        here = design_excitation(prob, n_starts=3, rng=5)
    assert lost  # the child had claimed starts
    assert here.start_values == alone.start_values and (here.nit, here.nfev, here.cond) == (alone.nit, alone.nfev, alone.cond)
