import numpy as np
import pinocchio as pin
import pytest

from dynid.dynamics.rnea import pinocchio_model, rnea_torques
from dynid.exceptions import ConfigError
from dynid.model.description import load_robot
from dynid.model.spatial import transform_inertial
from dynid.model.urdf import inertial_from_pinocchio, pinocchio_from_inertial


def test_transform_inertial_matches_pinocchio(rng):
    inertia = pin.Inertia.Random()
    m = pin.SE3.Random()
    phi = inertial_from_pinocchio(inertia)
    moved = transform_inertial(phi, m.rotation, m.translation)
    np.testing.assert_allclose(moved, inertial_from_pinocchio(m.act(inertia)), atol=1e-12)
    np.testing.assert_allclose(inertial_from_pinocchio(pin.Inertia.FromDynamicParameters(pinocchio_from_inertial(phi))), phi)


@pytest.mark.parametrize("k", [1, 2, 3, 5])
def test_submodel_carries_the_held_links(rng, k):
    """Torques of the first k joints with the wrist held at rest equal the full robot's (Pinocchio)."""
    full = load_robot("er16")
    q_rest = rng.uniform(-1, 1, 6 - k)
    sub = full.submodel(k, q_rest)
    n = 20
    q, dq, ddq = (rng.uniform(-2, 2, (n, k)) for _ in range(3))
    q_full = np.hstack([q, np.tile(q_rest, (n, 1))])
    zeros = np.zeros((n, 6 - k))
    tau_full = rnea_torques(full, q_full, np.hstack([dq, zeros]), np.hstack([ddq, zeros]))[:, :k]
    np.testing.assert_allclose(rnea_torques(sub, q, dq, ddq), tau_full, atol=1e-9)
    # tool point moves with the held links
    model = pinocchio_model(full)
    data = model.createData()
    pin.forwardKinematics(model, data, q_full[0])
    tool_full = data.oMi[6].act(np.asarray(full.tool_translation))
    from dynid.dynamics.kinematics import tool_positions

    np.testing.assert_allclose(tool_positions(sub, q[:1])[0], tool_full, atol=1e-12)


def test_submodel_rejects_out_of_range():
    full = load_robot("er16")
    for k in (0, 7):
        with pytest.raises(ConfigError, match="between 1 and 6"):
            full.submodel(k)
    with pytest.raises(ConfigError, match="rest angles"):
        full.submodel(3, np.zeros(2))


def test_robot_is_immutable():
    robot = load_robot("er16")
    with pytest.raises(ValueError):
        robot.inertial[0, 0] = 1.0
    with pytest.raises(AttributeError):
        robot.name = "x"
