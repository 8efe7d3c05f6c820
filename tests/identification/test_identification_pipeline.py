"""One identification pipeline: a log identified from a config (``dynid identify``) and the same log given as arrays
(``dynid.Identifier``, ``dynid.identify_from_arrays``) go through the same parts and make the same choices."""

import json

import numpy as np
import pytest

import dynid
from dynid.exceptions import ConfigError
from dynid.identification.pipeline import IdentificationPipeline
from dynid.io.config.identification_config import load_identification_config
from dynid.io.logs.datasets import load_recording

from ..simulated_logs import config_text, point_to_point_motion, robot_toml, truth_robot, write_log, write_truth


def _plain(x):
    """A settings entry as results.json holds it (arrays as lists)."""
    return json.loads(json.dumps(x, default=lambda a: np.asarray(a).tolist()))


def _same(a, b, where=""):
    """The same structure, strings and choices equal, numbers to 1e-9 (the arrays' grid rate is 1 / median step, the
    reader's its fit: their last digits differ)."""
    if isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for k in a:
            _same(a[k], b[k], f"{where}/{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{where}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        assert a == pytest.approx(b, rel=1e-9, abs=1e-12), where
    else:
        assert a == b, where


@pytest.fixture(scope="module")
def slow_quiet_log(tmp_path_factory):
    """Slow moves logged by 20-bit encoders at 1 kHz: the positions' noise knee lies far above 10x the band, so the
    default cross-validates the cutoffs (what the arrays' path skipped before issue 23's pipeline)."""
    folder = tmp_path_factory.mktemp("pipeline")
    rng = np.random.default_rng(2)
    robot, friction = truth_robot("er16", rng)
    t = np.arange(int(40 * 1000.0)) / 1000.0
    q, dq, ddq = point_to_point_motion(robot, t, rng, segment=4.0, rest=1.0)
    write_log(folder / "ident.csv", robot, t, q, dq, ddq, friction, rng, 0.01)
    write_log(folder / "valid.csv", robot, t, *point_to_point_motion(robot, t, rng, segment=4.0, rest=1.0), friction, rng, 0.01)
    write_truth(folder / "truth.csv", robot, robot.parameter_names)
    cfg = folder / "config.toml"
    cfg.write_text(config_text(robot_toml("er16", folder), folder, "ident.csv", "valid.csv", robot.n_dof))
    return load_identification_config(cfg)


def test_arrays_and_a_config_of_the_same_log_give_the_same_identification(slow_quiet_log):
    config = slow_quiet_log
    from_config = dynid.run_identification(config, validate=False)
    recording = load_recording(config.identification, config.robot)
    ident = dynid.Identifier(config.robot, estimators=list(config.estimation.estimators), friction=config.estimation.friction,
                             rng=config.estimation.seed)
    from_arrays = ident.fit(recording.t, recording.q, recording.tau).result_
    cv = from_config.settings["preprocessing_cross_validation"]  # the case this test is about: the cutoffs were chosen
    assert len(cv["candidates"]) == 3
    for key in ("preprocessing_cross_validation", "coulomb_velocity", "friction_models"):
        _same(_plain(from_arrays.settings[key]), _plain(from_config.settings[key]), key)
    pre_a, pre_c = from_arrays.settings["preprocessing"], from_config.settings["preprocessing"]
    _same(_plain({k: v for k, v in pre_a.items() if k != "derivation"}), _plain({k: v for k, v in pre_c.items() if k != "derivation"}))
    assert from_arrays.base.names == from_config.base.names
    np.testing.assert_allclose(from_arrays.solution.params, from_config.solution.params, rtol=1e-9, atol=1e-12)


def test_settings_given_to_the_arrays_path_are_applied(slow_quiet_log):
    """A Coulomb smoothing velocity and a seed given with arrays: the arrays' path used to ignore both."""
    config = slow_quiet_log
    rec = load_recording(config.identification, config.robot)
    fit = lambda **kw: dynid.identify_from_arrays(config.robot, rec.t, rec.q, rec.tau, estimators=("ols",),
                                                  friction="description", **kw)  # the description's terms: sign(q̇)
    smooth = fit(preprocessing=dynid.Preprocessing(coulomb_velocity=0.05, auto=False))
    sign = fit(preprocessing=dynid.Preprocessing(auto=False))
    assert smooth.settings["coulomb_velocity"] == [0.05] * 6 and sign.settings["coulomb_velocity"] == [0.0] * 6
    assert smooth.model.coulomb_velocity.tolist() == [0.05] * 6
    assert not np.allclose(smooth.solution.params, sign.solution.params, rtol=1e-6)
    boot = lambda r: np.array(list(r.diagnostics["bootstrap_std"].values()))
    one, again = fit(preprocessing=dynid.Preprocessing(auto=False), rng=1), fit(preprocessing=dynid.Preprocessing(auto=False), rng=1)
    np.testing.assert_array_equal(boot(one), boot(again))
    assert not np.array_equal(boot(one), boot(sign))  # seed 0 against seed 1: another bootstrap


def test_the_pipeline_refuses_an_unknown_friction_choice():
    with pytest.raises(ConfigError, match='friction: expected "description" or "auto", got \'magic\''):
        IdentificationPipeline(dynid.load_robot("er16"), friction="magic")


def test_what_the_data_chose_is_a_value_of_the_result_and_the_description_stays_as_read(slow_quiet_log):
    """Issue "Re-zone the top floors", item 5: the choices (filters, smoothing, friction models) are a typed value of
    the prepared identification and of the result; the model identified is that value applied to the description,
    and the description is not modified."""
    config = slow_quiet_log
    description = config.robot
    before = (description.drive_terms, description.drive_mask.copy(), description.coulomb_velocity.copy(),
              description.stribeck_velocity.copy())
    pipeline = IdentificationPipeline(description, config.preprocessing, estimators=("wls",), friction="auto")
    recording = load_recording(config.identification, description)
    prepared = pipeline.prepare(recording)
    choices = prepared.choices
    assert choices.friction is not None and choices.preprocessing is not None  # both choices were made on this log
    model = choices.model(description)
    assert model.drive_terms == prepared.robot.drive_terms
    np.testing.assert_array_equal(model.drive_mask, prepared.robot.drive_mask)
    np.testing.assert_array_equal(model.coulomb_velocity, prepared.robot.coulomb_velocity)
    np.testing.assert_array_equal(model.stribeck_velocity, prepared.robot.stribeck_velocity)
    # the model's smoothing is each chosen friction model's: a smooth Coulomb's velocity, 0 (sign) for the others
    expected = [m.velocity if m.kind == "smooth" else 0.0 for m in choices.friction.models]
    np.testing.assert_array_equal(choices.smoothing_velocity(), expected)
    after = (description.drive_terms, description.drive_mask, description.coulomb_velocity, description.stribeck_velocity)
    assert before[0] == after[0] and all(np.array_equal(a, b) for a, b in zip(before[1:], after[1:]))
    result = pipeline.estimate(prepared)
    assert result.choices is choices
    for key, value in choices.to_dict().items():
        _same(_plain(result.settings[key]), _plain(value), key)
    assert result.settings["coulomb_velocity"] == list(expected)


def test_the_estimators_the_pipeline_feeds_unfitted_hold_the_rows_its_estimate_fits(slow_quiet_log):
    """``IdentificationPipeline.estimation`` (what dynid run and montecarlo fit in their own box) feeds the prepared log's
    rows: least squares on them is numpy's on the kept rows, and it is the OLS estimate ``estimate`` gives; a seed
    given as ``rng`` draws each estimator's generator from (seed..., its registry index), as a dict of generators does."""
    from dynid.estimators.registry import FitData, SearchBudget, estimate_label, seed_index
    from dynid.identification.result import search_box
    from dynid.preprocessing.settings import Preprocessing

    config = slow_quiet_log
    recording = load_recording(config.identification, config.robot)
    pipeline = IdentificationPipeline(config.robot, Preprocessing(auto=False), estimators=("ols", "abc"))
    prepared = pipeline.prepare(recording)
    fed = pipeline.estimation(prepared, FitData(n_dof=config.robot.n_dof, base=prepared.base), keep_rows=True)
    w, tau = fed.rows()
    sol = fed.solve_reference().solution_
    np.testing.assert_allclose(sol.params, np.linalg.lstsq(w, tau, rcond=None)[0], rtol=1e-7,
                               atol=1e-9 * np.abs(sol.params).max())
    ols = pipeline.estimate(prepared).estimates[estimate_label("ols")].params
    np.testing.assert_allclose(ols, sol.params, rtol=1e-10, atol=1e-12 * np.abs(sol.params).max())

    box, budget = search_box(sol.params, sol.params_std), SearchBudget(8, 5, 3)
    by_seed = fed.fit(box, rng=(7, 2), budget=budget, keys=("abc",), workers=1)["abc"].params
    given = {"abc": np.random.default_rng([7, 2, seed_index("abc")])}
    np.testing.assert_array_equal(by_seed, fed.fit(box, given, budget=budget, keys=("abc",), workers=1)["abc"].params)
    other = fed.fit(box, rng=(8, 2), budget=budget, keys=("abc",), workers=1)["abc"].params
    assert not np.array_equal(by_seed, other)
    with pytest.raises(TypeError, match="rng .* or rngs .*, not both"):
        fed.fit(box, given, rng=(7, 2), budget=budget, keys=("abc",), workers=1)


def test_the_cross_validations_say_their_share_done_as_they_go(slow_quiet_log):
    """Issue "Fast where users wait", item 3: the cutoffs' and the friction models' cross-validations report how much
    is done (a terminal's bar and time left come from it), rising to the whole, not only that they started."""
    from dynid.identification.pipeline import IdentificationPipeline

    config = slow_quiet_log
    calls = []
    pipeline = IdentificationPipeline(config.robot, estimators=("ols",), friction="auto")
    pipeline.prepare(load_recording(config.identification, config.robot),
                     progress=lambda label, done, total: calls.append((label, done, total)))
    for step in ("preprocessing", "preprocessing: cross-validation of the cutoffs",
                 "friction model of each joint (cross-validation)"):
        shares = [done / total for label, done, total in calls if label == step]
        assert shares[0] == 0 and shares[-1] == 1.0 and len(shares) >= 3, (step, shares)
        assert all(b >= a for a, b in zip(shares, shares[1:])), (step, shares)
