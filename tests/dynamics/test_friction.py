"""Smooth Coulomb term: the regressor's columns against the formula and Pinocchio's RNEA."""

from dataclasses import replace

import numpy as np

from dynid.dynamics.friction import coulomb_column
from dynid.dynamics.regressor import regressor
from dynid.dynamics.rnea import pinocchio_model
from dynid.model.description import load_robot


def test_coulomb_column_formula():
    dq = np.array([[-0.2, 0.0, 0.01], [0.3, -0.001, 0.0]])
    np.testing.assert_array_equal(coulomb_column(dq, 0.0), np.sign(dq))
    vs = np.array([0.0, 0.01, 0.1])
    expect = np.column_stack([np.sign(dq[:, 0]), np.tanh(dq[:, 1] / 0.01), np.tanh(dq[:, 2] / 0.1)])
    np.testing.assert_allclose(coulomb_column(dq, vs), expect)


def test_regressor_with_smooth_coulomb_equals_rnea_plus_friction(rng):
    """Y·phi = Pinocchio RNEA + Ia·ddq + fc·tanh(dq/v_s) + fv·dq, friction written out here."""
    import pinocchio as pin

    robot = load_robot("ur10e")
    vs = np.array([0.0, 0.01, 0.02, 0.05, 0.1, 0.3])
    drive = np.column_stack([rng.uniform(0.1, 1, 6), rng.uniform(1, 10, 6), rng.uniform(1, 5, 6), rng.uniform(-1, 1, 6)])
    robot = replace(robot, drive=drive, coulomb_velocity=vs)
    q, dq, ddq = (rng.uniform(-0.3, 0.3, (40, 6)) for _ in range(3))
    model = pinocchio_model(robot)
    data = model.createData()
    rb = np.array([pin.rnea(model, data, a, b, c) for a, b, c in zip(q, dq, ddq)])
    smooth = np.where(vs > 0, np.tanh(dq / np.where(vs > 0, vs, 1.0)), np.sign(dq))
    expect = rb + drive[:, 0] * ddq + drive[:, 1] * smooth + drive[:, 2] * dq + drive[:, 3]
    np.testing.assert_allclose(regressor(robot, q, dq, ddq) @ robot.standard_parameters(), expect, atol=1e-9)
