"""Smooth Coulomb term: the regressor's columns against the formula and Pinocchio's RNEA."""

from dataclasses import replace

import numpy as np

from dynid.dynamics.regressor import regressor
from dynid.dynamics.rnea import pinocchio_model
from dynid.friction import coulomb_column
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


def test_smooth_coulomb_and_stribeck_derivatives_match_finite_differences(rng):
    from dynid.dynamics.sensitivity import regressor_state_derivatives

    robot = load_robot("er16").submodel(3)
    robot = replace(robot, drive_terms=("Ia", "fc", "fv", "fst"), drive=np.ones((3, 4)), drive_mask=None,
                    coulomb_velocity=np.array([0.0, 0.05, 0.2]), stribeck_velocity=np.array([0.1, 0.2, 0.3]))
    q, dq, ddq = (rng.uniform(-0.5, 0.5, (6, 3)) for _ in range(3))
    y, d = regressor_state_derivatives(robot, q, dq, ddq)
    h = 1e-6
    for i in range(3):
        e = np.zeros(3)
        e[i] = h
        fd = (regressor(robot, q, dq + e, ddq) - regressor(robot, q, dq - e, ddq)) / (2 * h)
        np.testing.assert_allclose(d[1, i], fd, atol=1e-6)


def test_adding_a_friction_term_is_one_table_entry(monkeypatch, rng):
    """A new term registered in dynid.friction.TERMS alone (here quadratic drag fq·dq·|dq|) reaches the
    description parser, the names and units, the regressor (checked against RNEA + the formula), the
    simulator's friction torques, the constrained estimators' layout and the sensitivities."""
    import pinocchio as pin

    from dynid import friction
    from dynid.conventions import canonical_name, unit_of
    from dynid.dynamics.layout import consistency_layout
    from dynid.dynamics.regressor import friction_torques
    from dynid.dynamics.sensitivity import regressor_state_derivatives
    from dynid.model.description import robot_from_toml_text

    term = friction.FrictionTerm("fq", "N·m·s²/rad²", True, lambda q, dq, ddq, v: dq * np.abs(dq),
                                 lambda q, dq, v: 2 * np.abs(dq), 0.0, ("Fq",), "quadratic drag")
    monkeypatch.setitem(friction.TERMS, "fq", term)
    text = """drive_terms = ["fv", "fq"]
[[joints]]
alpha = 0.0
mass = 2.0
com = [0.1, 0.0, 0.0]
inertia = [0.01, 0.02, 0.02, 0, 0, 0]
fv = 0.5
fq = 0.3
[[joints]]
alpha = "pi/2"
a = 0.3
mass = 1.0
com = [0.1, 0.0, 0.0]
inertia = [0.01, 0.01, 0.01, 0, 0, 0]
fv = 0.2
fq = 0.1
"""
    robot = robot_from_toml_text(text, "arm.toml", None)
    assert robot.parameter_names[10:12] == ("fv1", "fq1") and unit_of("fq2") == "N·m·s²/rad²"
    assert canonical_name("Fq2") == "fq2"
    q, dq, ddq = (rng.uniform(-1, 1, (20, 2)) for _ in range(3))
    model = pinocchio_model(robot)
    data = model.createData()
    rb = np.array([pin.rnea(model, data, a, b, c) for a, b, c in zip(q, dq, ddq)])
    drag = np.array([0.5, 0.2]) * dq + np.array([0.3, 0.1]) * dq * np.abs(dq)
    np.testing.assert_allclose(regressor(robot, q, dq, ddq) @ robot.standard_parameters(), rb + drag, atol=1e-10)
    np.testing.assert_allclose(friction_torques(robot, dq, ddq), drag, atol=1e-12)
    _, nonneg = consistency_layout(robot)
    assert [robot.parameter_names[k] for k in nonneg] == ["fv1", "fq1", "fv2", "fq2"]
    _, d = regressor_state_derivatives(robot, q, dq, ddq)
    np.testing.assert_allclose(d[1, 0, :, 0, 11], 2 * np.abs(dq[:, 0]))


def test_an_unknown_term_is_an_error_never_an_offset():
    import pytest

    from dynid.exceptions import ConfigError
    from dynid.model.description import robot_from_toml_text

    with pytest.raises(ConfigError, match=r"arm.toml: drive_terms: unknown drive term\(s\) \['stiction'\]"):
        robot_from_toml_text('drive_terms = ["fc", "stiction"]\n[[joints]]\nmass = 1.0\ncom = [0, 0, 0]\n'
                             'inertia = [0.1, 0.1, 0.1, 0, 0, 0]\n', "arm.toml", None)


def test_direction_is_held_at_rest_and_reverses_at_the_crossing():
    """held_direction: the sign of the last motion while the joint rests (0 before its first), relaxing with a time
    constant when one is given, 0 at rest with decay 0; a reversal through zero happens where the velocity
    crosses zero, not where it leaves the rest band."""
    from dynid.friction import held_direction

    rate = 100.0
    v = np.concatenate([np.zeros(10), np.full(20, 0.5), np.zeros(50), np.linspace(0.5, -0.5, 21), np.full(10, -0.5)])
    held = held_direction(v[:, None], 0.1, rate=rate)[:, 0]
    assert np.all(held[:10] == 0) and np.all(held[10:80] == 1.0)  # before the first motion, moving, resting
    crossing = 80 + 10  # linspace(0.5, -0.5, 21) is 0 at its 11th sample
    assert np.all(held[80:crossing] == 1.0) and np.all(held[crossing + 1:] == -1.0)
    relaxed = held_direction(v[:, None], 0.1, decay=0.2, rate=rate)[:, 0]
    np.testing.assert_allclose(relaxed[30:80], np.exp(-np.arange(1, 51) / (rate * 0.2)))
    zero = held_direction(v[:, None], 0.1, decay=0.0, rate=rate)[:, 0]
    np.testing.assert_array_equal(zero[30:80], 0.0)


def test_a_short_move_against_the_direction_is_a_blip_and_a_long_one_a_reversal():
    from dynid.friction import held_direction

    rate = 100.0
    blip = np.concatenate([np.full(20, 0.5), np.zeros(5), np.full(2, -0.2), np.zeros(20)])
    z = held_direction(blip[:, None], 0.1, rate=rate, min_travel=0.01)[:, 0]
    np.testing.assert_array_equal(z, 1.0)  # 2 samples at 0.2 rad/s travel 0.004 rad < 0.01
    move = np.concatenate([np.full(20, 0.5), np.zeros(5), np.full(20, -0.2), np.zeros(20)])
    z = held_direction(move[:, None], 0.1, rate=rate, min_travel=0.01)[:, 0]
    assert np.all(z[25:] == -1.0) and np.all(z[:25] == 1.0)


def test_dahl_presliding_reverses_over_the_distance_travelled():
    """With a presliding distance x0 the direction follows z = σ + (z0 - σ)·exp(-s/x0) along the distance s."""
    from dynid.friction import held_direction

    rate, x0 = 1000.0, 0.002
    v = np.concatenate([np.full(200, 0.3), np.full(200, -0.1)])
    z = held_direction(v[:, None], 0.01, presliding=x0, rate=rate)[:, 0]
    s = np.cumsum(np.full(200, 0.1)) / rate
    z_end = 1 + (0 - 1) * np.exp(-np.cumsum(np.full(200, 0.3))[-1] / rate / x0)
    np.testing.assert_allclose(z[200:], -1 + (z_end + 1) * np.exp(-s / x0))


def test_velocity_noise_through_the_filters_matches_a_simulation(rng):
    """The noise the pipeline's velocities carry, computed from the positions' (or velocities') white-noise level,
    agrees with filtering and differentiating simulated noise (Butterworth and Gaussian)."""
    from dynid.preprocessing.bands import white_noise_std
    from dynid.preprocessing.filters import butterworth_filtfilt, differentiate, gaussian_smooth, velocity_noise_std

    rate, n = 1000.0, 200_000
    sigma = np.array([1e-4, 5e-4])
    noise = rng.normal(size=(n, 2)) * sigma
    np.testing.assert_allclose(white_noise_std(noise + np.sin(np.arange(n) / rate)[:, None], rate), sigma, rtol=0.05)
    for gaussian in (False, True):
        smooth = gaussian_smooth(noise, rate, 5.0) if gaussian else butterworth_filtfilt(noise, rate, 5.0, 4)
        measured = differentiate(smooth, rate)[2000:-2000].std(axis=0)
        np.testing.assert_allclose(velocity_noise_std(sigma, rate, 5.0, 4, True, gaussian), measured, rtol=0.05)
        direct = (gaussian_smooth(noise, rate, 5.0) if gaussian else butterworth_filtfilt(noise, rate, 5.0, 4))[2000:-2000].std(axis=0)
        np.testing.assert_allclose(velocity_noise_std(sigma, rate, 5.0, 4, False, gaussian), direct, rtol=0.05)
