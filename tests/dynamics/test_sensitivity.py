import numpy as np
import pinocchio as pin

from dynid.dynamics.kinematics import tool_positions
from dynid.dynamics.rnea import pinocchio_model
from dynid.dynamics.sensitivity import coulomb_columns, regressor_state_derivatives, tool_jacobian
from dynid.model.description import load_robot

from ..conftest import random_states


def test_regressor_derivatives_times_parameters_equal_pinocchio_rnea_derivatives(rng):
    """(∂Y/∂s)·φ == Pinocchio's ∂τ/∂q, ∂τ/∂dq, ∂τ/∂ddq (inertial part; viscous friction added)."""
    robot = load_robot("er16")
    q, dq, ddq = random_states(rng, 12, robot.n_dof)
    y, d = regressor_state_derivatives(robot, q, dq, ddq)
    phi = robot.standard_parameters()
    model = pinocchio_model(robot)
    data = model.createData()
    fv = np.diag(robot.drive[:, list(robot.drive_terms).index("fv")])
    for k in range(q.shape[0]):
        dtq, dtv, dta = (np.array(x) for x in pin.computeRNEADerivatives(model, data, q[k], dq[k], ddq[k]))
        dta = np.triu(dta) + np.triu(dta, 1).T  # Pinocchio fills the upper triangle of M
        # column i of pinocchio's matrices is ∂τ/∂s_i; d[kind, i, k] @ phi is the same column
        np.testing.assert_allclose(np.stack([d[0, i, k] @ phi for i in range(6)], axis=1), dtq, atol=1e-6, rtol=1e-7)
        np.testing.assert_allclose(np.stack([d[1, i, k] @ phi for i in range(6)], axis=1), dtv + fv, atol=1e-8, rtol=1e-9)
        np.testing.assert_allclose(np.stack([d[2, i, k] @ phi for i in range(6)], axis=1), dta, atol=1e-8, rtol=1e-9)


def test_coulomb_columns_have_zero_derivative_even_at_rest(rng):
    robot = load_robot("er16").submodel(3)
    q, dq, ddq = random_states(rng, 5, 3)
    dq[0] = 0.0  # sign() jumps here
    _, d = regressor_state_derivatives(robot, q, dq, ddq)
    fc = [k for k, name in enumerate(robot.parameter_names) if name.startswith("fc")]
    assert [robot.parameter_names[k] for k in fc] == ["fc1", "fc2", "fc3"]
    assert np.all(d[..., fc] == 0.0) and np.all(np.isfinite(d))
    assert coulomb_columns(robot).size == 0  # no coupled motors on this robot


def test_tool_jacobian_equals_finite_differences_of_tool_positions(rng):
    robot = load_robot("ur10e")
    q = rng.uniform(-3, 3, (7, robot.n_dof))
    p, jac = tool_jacobian(robot, q)
    np.testing.assert_allclose(p, tool_positions(robot, q), atol=1e-12)
    h = 1e-6
    for j in range(robot.n_dof):
        e = np.zeros(robot.n_dof)
        e[j] = h
        fd = (tool_positions(robot, q + e) - tool_positions(robot, q - e)) / (2 * h)
        np.testing.assert_allclose(jac[:, :, j], fd, atol=1e-8)
