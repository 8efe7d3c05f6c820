"""Blocked cross-validation: out-of-fold errors against a direct computation, and the Coulomb choice."""

import numpy as np

from dynid.estimators.accumulate import LeastSquaresAccumulator
from dynid.identification.cross_validation import out_of_fold_error


def test_out_of_fold_error_equals_refitting_without_each_block(rng):
    n_dof, p, m = 2, 4, 300
    w = rng.normal(size=(m * n_dof, p))
    tau = w @ rng.normal(size=p) + rng.normal(0, 0.1, m * n_dof)
    blocks = np.array_split(np.arange(m), 3)
    accs = []
    for b in blocks:
        rows = (b[:, None] * n_dof + np.arange(n_dof)).ravel()
        a = LeastSquaresAccumulator(p, n_dof)
        a.add(w[rows], tau[rows])
        accs.append(a)
    got = out_of_fold_error(accs)
    sumsq = np.zeros(n_dof)
    for b in blocks:  # direct: lstsq on the other blocks, residual on this one
        held = (b[:, None] * n_dof + np.arange(n_dof)).ravel()
        rest = np.setdiff1d(np.arange(m * n_dof), held)
        theta = np.linalg.lstsq(w[rest], tau[rest], rcond=None)[0]
        r = (tau[held] - w[held] @ theta).reshape(-1, n_dof)
        sumsq += (r**2).sum(0)
    np.testing.assert_allclose(got, np.sqrt(sumsq / m), rtol=1e-10)


def test_coulomb_cross_validation_prefers_smoothing_when_the_truth_is_smooth(tmp_path):
    """A log simulated with tanh(dq/v) Coulomb friction on every joint: the cross-validation chooses a
    smoothing velocity (not sign) for the joints whose Coulomb torque is large."""
    from dataclasses import replace

    from dynid.dynamics.base_parameters import base_parameters
    from dynid.dynamics.rnea import rnea_torques
    from dynid.identification.cross_validation import choose_coulomb_velocity
    from dynid.model.description import load_robot
    from dynid.preprocessing.preparation import Preprocessing
    from dynid.preprocessing.prepared import PreparedData

    from ..conftest import sine_motion

    robot = load_robot("er16").submodel(3)
    rate = 200.0
    t = np.arange(int(40 * rate)) / rate
    q, dq, ddq = sine_motion(np.random.default_rng(2), t, 3, amplitude=1.0)
    rms = np.sqrt((dq**2).mean(0))
    truth = replace(robot, drive=robot.drive * np.array([5.0, 1.0]), coulomb_velocity=0.1 * rms)
    tau = rnea_torques(truth, q, dq, ddq) + np.random.default_rng(3).normal(0, 0.05, q.shape)
    s = Preprocessing(parallel_cutoff=0, decimation=1, min_speed=0.0).resolved(rate, q)
    data = PreparedData("sim", t, q, dq, ddq, tau, rate, s)
    choice = choose_coulomb_velocity(robot, base_parameters(robot, rng=0), data)
    assert np.all(choice.velocity > 0), choice.velocity
    assert np.all(choice.error.min(axis=0) < choice.error[0])  # better than sign, out of fold
