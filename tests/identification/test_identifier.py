"""dynid.Identifier and dynid.load_results: the identification as a scikit-learn style estimator, checked against
the simulation's truth and Pinocchio's inverse dynamics."""

import json
import re

import numpy as np
import pytest

import dynid
from dynid.exceptions import ConfigError, DataError, DynIdError, ShapeError

from ..simulated_logs import simulated_case, truth_beta


@pytest.fixture(scope="module")
def er16():
    robot = dynid.load_robot("er16")
    return robot, dynid.simulated_log(robot, seconds=30, rng=1), dynid.simulated_log(robot, seconds=20, rng=2)


@pytest.fixture(scope="module")
def fitted(er16):
    robot, log, _ = er16
    return dynid.Identifier(robot, estimators=["WLS", "sdp"]).fit(log.t, log.q, log.tau)


def test_fit_on_arrays_finds_the_truth_within_its_sigma(er16, fitted):
    robot, _, _ = er16
    truth = fitted.result_.base.base_from_standard(robot.standard_parameters())
    wls = fitted.parameters("wls")
    assert wls.names == fitted.feature_names_out_ and len(wls) == truth.size
    assert np.all(np.abs(wls.values - truth) <= np.maximum(5 * wls.std, 1e-6 * np.abs(truth).max()))
    assert wls["ZZ1R"].unit == "kg·m²" and wls["ZZ1R"].value == wls.values[0] and np.isfinite(wls["ZZ1R"].std)
    assert set(fitted.estimates_) == {"dynid WLS", "dynid SDP"} and fitted.params_ is fitted.estimates_[fitted.result_.main]


def test_predict_matches_pinocchio_inverse_dynamics(er16, fitted):
    robot, _, _ = er16
    assert robot.drive_terms == ("fc", "fv")
    rng = np.random.default_rng(3)
    q, dq, ddq = (rng.uniform(-1, 1, (50, robot.n_dof)) for _ in range(3))
    fc, fv = robot.drive.T
    rigid = dynid.rnea_torques(robot, q, dq, ddq, drive=np.zeros_like(robot.drive))  # Pinocchio's RNEA, no drive terms
    truth = rigid + fc * np.sign(dq) + fv * dq
    for estimate in ("wls", "sdp"):
        with pytest.warns(UserWarning, match="mostly noise"):  # random states: their accelerations are white noise
            predicted = fitted.predict_states(q, dq, ddq, estimate=estimate)
        rms = np.sqrt(np.mean((predicted - truth) ** 2, axis=0))
        assert np.all(rms < 0.01 * np.sqrt(np.mean(truth**2, axis=0))), (estimate, rms)


@pytest.mark.filterwarnings("ignore:predict_states. the accelerations:UserWarning")  # random states: white noise
def test_score_on_another_log_and_on_arrays(er16, fitted):
    robot, _, other = er16
    assert 0.99 < fitted.score(other) <= 1.0
    q, dq, ddq = (np.random.default_rng(4).uniform(-1, 1, (30, robot.n_dof)) for _ in range(3))
    tau = dynid.regressor(robot, q, dq, ddq) @ robot.standard_parameters()
    with pytest.warns(FutureWarning, match="score\\(q, dq, ddq, tau\\) scores states of one's own"):
        assert fitted.score(q, dq, ddq, tau) > 0.99
    with pytest.warns(FutureWarning):
        assert fitted.score(q, dq, ddq, tau + 100.0 * np.random.default_rng(5).normal(size=tau.shape)) < 0.5


def test_save_and_load_back_give_the_same_model(tmp_path, er16, fitted):
    robot, _, other = er16
    path = fitted.save(tmp_path / "results.json")
    model = dynid.load_results(path)  # the robot from the results' settings (a built-in name)
    assert model.main == fitted.result_.main and list(model.estimates) == list(fitted.estimates_)
    for label, beta in fitted.estimates_.items():
        np.testing.assert_array_equal(model.params(label), beta)
    np.testing.assert_array_equal(model.parameters("wls").std, fitted.parameters("wls").std)
    q, dq, ddq = (np.random.default_rng(6).uniform(-1, 1, (10, robot.n_dof)) for _ in range(3))
    with pytest.warns(UserWarning, match="mostly noise"):
        np.testing.assert_array_equal(model.predict_states(q, dq, ddq), fitted.predict_states(q, dq, ddq))
    assert model.score(other) == pytest.approx(fitted.score(other), rel=1e-12)
    assert model.urdf() == fitted.model_.urdf() and "<robot name=\"er16\">" in model.urdf()
    assert json.loads(path.read_text())["kind"] == "identify"


def test_save_takes_a_folder_as_its_docstring_says_and_creates_a_missing_one(tmp_path, fitted):
    """save(folder) raised IsADirectoryError naming a temporary file, and save("new/r.json") a FileNotFoundError:
    a folder holds results.json, a missing folder is created, and a file standing where a folder must be is a
    one-line ConfigError; each file written reads back as the same model."""
    (tmp_path / "out").mkdir()
    written = [fitted.save(tmp_path / "out"), fitted.model_.save(tmp_path / "new" / "deeper" / "r.json"),
               fitted.save(tmp_path / "fresh")]  # a path without a suffix is a folder (it wrote a file named "fresh")
    assert written == [tmp_path / "out" / "results.json", tmp_path / "new" / "deeper" / "r.json",
                       tmp_path / "fresh" / "results.json"]
    for path in written:
        np.testing.assert_array_equal(dynid.load_results(path).params(), fitted.params_)
    (tmp_path / "plain").write_text("not a folder")
    with pytest.raises(ConfigError, match=r"plain: cannot create the folder for r.json"):
        fitted.save(tmp_path / "plain" / "r.json")
    assert (tmp_path / "plain").read_text() == "not a folder"


def test_a_parameter_without_a_standard_deviation_reads_back_as_not_known(tmp_path, fitted):
    """issue "The better model wins", item 4: results.json writes a σ that is not known as null (an estimate of a
    prior-only direction, a drive-only term); load_results raised TypeError (float(None)) on it. It reads as NaN; a σ
    that is neither is one line naming it (the results' schema)."""
    data = json.loads(fitted.save(tmp_path / "r.json").read_text())
    key = next(k for k, e in data["estimates"].items() if isinstance(e.get("std"), dict))
    name = next(iter(data["estimates"][key]["std"]))
    data["estimates"][key]["std"][name] = None
    (tmp_path / "r.json").write_text(json.dumps(data))
    model = dynid.load_results(tmp_path / "r.json")
    std = model.parameters(key).std
    assert np.isnan(std[model.base.names.index(name)]) and np.isfinite(np.delete(std, model.base.names.index(name))).all()
    data["estimates"][key]["std"][name] = "big"
    (tmp_path / "r.json").write_text(json.dumps(data))
    with pytest.raises(DataError, match=rf"r.json: estimates.{re.escape(key)}.std.{name}: 'big' is not of type 'number'"):
        dynid.load_results(tmp_path / "r.json")


def test_load_results_says_when_the_robot_cannot_be_found(tmp_path, fitted):
    data = json.loads(fitted.save(tmp_path / "r.json").read_text())
    data["settings"]["robot_source"] = ""
    (tmp_path / "r.json").write_text(json.dumps(data))
    with pytest.raises(DataError, match=r"r.json: the robot's description is not found .*load_results\(path, robot=\.\.\.\)"):
        dynid.load_results(tmp_path / "r.json")
    assert dynid.load_results(tmp_path / "r.json", robot="er16").robot.name == "er16"
    with pytest.raises(DataError, match="r.json: results of robot 'er16', the robot given is 'ur10e'"):
        dynid.load_results(tmp_path / "r.json", robot="ur10e")
    (tmp_path / "bad.json").write_text("{")
    with pytest.raises(DataError, match="bad.json: cannot read it as JSON"):
        dynid.load_results(tmp_path / "bad.json")


def test_get_and_set_params_follow_scikit_learns_contract():
    ident = dynid.Identifier("er16", estimators=["ols"])
    assert ident.get_params() == {"robot": "er16", "estimators": ["ols"], "preprocessing": None, "friction": None, "rng": None,
                                  "controller": None}
    assert ident.set_params(rng=3, friction="auto") is ident and ident.get_params()["rng"] == 3
    with pytest.raises(ValueError, match="no parameter 'alpha'"):
        ident.set_params(alpha=1)
    with pytest.raises(AttributeError, match="not fitted yet"):
        ident.predict_states(np.zeros((1, 6)), np.zeros((1, 6)), np.zeros((1, 6)))
    from dynid.exceptions import NotFittedError  # scikit-learn's bases: ValueError and AttributeError

    for call in (lambda: ident.predict(np.arange(10) / 100, np.zeros((10, 6))),
                 lambda: ident.score(np.arange(10) / 100, np.zeros((10, 6)), np.zeros((10, 6))),
                 lambda: dynid.estimators.OrdinaryLeastSquares().predict(np.zeros((6, 3)))):
        with pytest.raises(NotFittedError, match="not fitted yet") as info:
            call()
        assert isinstance(info.value, ValueError) and isinstance(info.value, AttributeError)
    with pytest.raises(ConfigError, match="robot's description is needed"):
        dynid.Identifier().fit(np.arange(10.0), np.zeros((10, 6)), np.zeros((10, 6)))
    with pytest.raises(ConfigError, match="unknown estimator|expected a comma-separated subset"):
        dynid.Identifier("er16", estimators=["magic"]).fit(np.arange(1000) / 100, np.zeros((1000, 6)), np.zeros((1000, 6)))


def test_scikit_learns_check_is_fitted_and_clone(fitted):
    """scikit-learn's own functions on an Identifier: check_is_fitted raised AttributeError (no ``__sklearn_tags__``);
    now NotFittedError before fit and nothing after; clone copies the settings, not the fitted state."""
    from sklearn.base import clone
    from sklearn.exceptions import NotFittedError
    from sklearn.utils.validation import check_is_fitted

    fresh = dynid.Identifier("er16", estimators=["wls"], rng=3)
    with pytest.raises(NotFittedError):
        check_is_fitted(fresh)
    check_is_fitted(fitted)
    copy = clone(fitted)
    given, copied = fitted.get_params(), copy.get_params()
    assert copied.keys() == given.keys() and copied["estimators"] == given["estimators"] and copy is not fitted
    assert copied["robot"].name == given["robot"].name
    with pytest.raises(NotFittedError):
        check_is_fitted(copy)
    assert len(repr(fitted).splitlines()) == 1


def test_fit_on_a_config_with_the_identifiers_settings_on_top(tmp_path):
    cfg, truth_robot = simulated_case(tmp_path, "ur10e", 125.0, "fourier", seed=4, duration=30.0)
    ident = dynid.Identifier.from_config(cfg, estimators=["wls", "ols"], rng=2)
    with pytest.warns(FutureWarning, match=r"fit\(config_path\) is Identifier\.from_config"):  # the earlier form
        earlier = dynid.Identifier(estimators=["wls", "ols"], rng=2).fit(cfg, validate=False)
    np.testing.assert_array_equal(earlier.params_, ident.params_)
    assert ident.result_.estimators == ("wls", "ols") and ident.result_.validations  # the config's validation log
    truth = truth_beta(ident.result_, truth_robot)
    assert np.linalg.norm(ident.params_ - truth) / np.linalg.norm(truth) < 0.02
    saved = ident.save(tmp_path / "results.json")
    model = dynid.load_results(saved)  # the robot: the config's description file, found from the results
    np.testing.assert_array_equal(model.params(), ident.params_)


def test_fit_takes_a_recording_as_the_readers_and_the_simulations_give_one(er16, fitted):
    """A log from dynid.simulated_log or dynid.load_recording is fitted as it is (the Identifier refused it: "positions
    and torques are needed with time stamps"): the same estimates as its arrays give (its rate exact, where the arrays'
    is one over their median step), its name and its reader's warnings kept; arrays beside it, or time stamps alone,
    are refused by a one-line ConfigError."""
    from dataclasses import replace

    robot, log, _ = er16
    noted = replace(log, warnings=("a reader's note",))
    ident = dynid.Identifier(robot, estimators=["WLS", "sdp"]).fit(noted)
    assert ident.result_.main == fitted.result_.main and "a reader's note" in ident.result_.warnings
    np.testing.assert_allclose(ident.params_, fitted.params_, rtol=1e-5, atol=1e-9 * np.abs(fitted.params_).max())
    assert ident.result_.fit.name == log.name != fitted.result_.fit.name
    with pytest.raises(ConfigError, match=f"^{log.name}: a recording holds its positions"):
        dynid.Identifier(robot).fit(log, log.q, log.tau)
    for call in (lambda: dynid.Identifier(robot).fit(log.t), lambda: dynid.identify_from_arrays(robot, log.t, log.q)):
        with pytest.raises(ConfigError, match="^positions q and torques tau are needed with the time stamps t"):
            call()
    # a recording made by hand is checked as arrays are (it gave a NumPy broadcast error, or was fitted silently with
    # three positions fewer than its time stamps)
    n = log.t.size
    for bad, what in ((replace(log, q=log.q[:, :5], tau=log.tau[:, :5]), f"q has shape \\({n}, 5\\), expected \\({n}, 6\\)"),
                      (replace(log, q=log.q[:-3]), f"q has shape \\({n - 3}, 6\\), expected \\({n}, 6\\)"),
                      (replace(log, tau=np.where(log.t[:, None] > 1.0, np.nan, log.tau)), "tau holds a NaN")):
        for call in (lambda: dynid.Identifier(robot).fit(bad), lambda: fitted.validate(bad)):
            with pytest.raises(ShapeError, match=f"^{log.name}: {what}"):
                call()


def test_jittered_time_stamps_are_resampled_as_the_readers_do(er16):
    robot, log, _ = er16
    jitter = np.random.default_rng(7).uniform(-20e-6, 20e-6, log.t.shape)
    exact = dynid.identify_from_arrays(robot, log.t, log.q, log.tau, estimators=("ols",))
    jittered = dynid.identify_from_arrays(robot, log.t + jitter, log.q, log.tau, estimators=("ols",))
    assert any("interpolated onto a uniform grid at 249.99" in w for w in jittered.warnings)  # 1 / median step, as read from a CSV
    # 20 µs of jitter at 250 Hz moves samples by 0.5 % of a step: the estimate moves far less than its σ
    assert np.all(np.abs(jittered.solution.params - exact.solution.params) < 0.5 * exact.solution.params_std + 1e-9)


def test_predict_and_score_take_a_raw_log_as_fit_does(er16, fitted):
    """predict(t, q) and score(t, q, tau) prepare a raw log as fit(t, q, tau) prepared its own (issue "A user's first
    hour", item 1): on another simulated log, the prediction is within the torques' own noise of what was measured,
    where states differentiated by hand (np.gradient twice) gave R² = -37 and a warning now says why; score(t, q, tau)
    is score(recording) on the very samples dynid validate scores; the earlier predict(q, dq, ddq) is predict_states,
    with a FutureWarning."""
    from dynid.simulation.measurements import NoiseModel
    from dynid.validation.noise_floor import torque_noise

    robot, _, _ = er16  # another log at 1 kHz with 16-bit encoders: differences of its positions are mostly noise
    other = dynid.simulated_log(robot, seconds=10, rate=1000.0, rng=2,
                                noise=NoiseModel(encoder_resolution=2 * np.pi / 2**16))
    t, q, tau = other.t, np.asarray(other.q), np.asarray(other.tau)
    predicted = fitted.predict(t, q)
    assert predicted.shape == q.shape
    inside = np.all(np.isfinite(predicted), axis=1)
    assert inside.mean() >= 0.8  # NaN only where the filters' settling leaves the ends out (a tenth at most at each end)
    rmse = np.sqrt(np.mean((predicted[inside] - tau[inside]) ** 2, axis=0))
    noise = torque_noise(tau)
    rms = np.sqrt(np.mean(tau**2, axis=0))
    assert np.all(rmse < 3 * noise + 0.01 * rms), (rmse, noise)
    dq = np.gradient(q, t, axis=0)
    with pytest.warns(UserWarning, match="mostly noise"):
        by_hand = fitted.predict_states(q, dq, np.gradient(dq, t, axis=0))
    assert np.sqrt(np.mean((by_hand - tau) ** 2)) > 10 * np.sqrt(np.mean((predicted[inside] - tau[inside]) ** 2))
    # (the same samples; the rate from the time stamps is 1000.0000000001 Hz where the recording holds 1000 exactly)
    assert fitted.score(t, q, tau) == pytest.approx(fitted.score(other), rel=1e-7)
    assert fitted.model_.score(t, q, tau) == pytest.approx(fitted.score(other), rel=1e-7)
    with pytest.warns(FutureWarning, match="predict\\(q, dq, ddq\\) is predict_states"):
        old = fitted.predict(q[:20], q[:20] * 0, q[:20] * 0)
    np.testing.assert_array_equal(old, fitted.predict_states(q[:20], q[:20] * 0, q[:20] * 0))


def test_predict_of_a_recording_is_at_its_own_time_stamps_and_the_identifier_validates(er16, fitted):
    """predict(recording) gave the torques at the samples a comparison keeps (263 rows for this log of 5,000: decimated
    and trimmed), where predict(t, q) of the same log gives one row per time stamp: it is now predict(recording.t,
    recording.q), row for row. The Identifier validates another log as its model does (it had no validate)."""
    _, _, other = er16
    by_arrays = fitted.predict(other.t, np.asarray(other.q))
    assert fitted.predict(other).shape == np.shape(other.q) == by_arrays.shape
    np.testing.assert_array_equal(fitted.predict(other), by_arrays)
    np.testing.assert_array_equal(fitted.model_.predict(other), by_arrays)
    comparison = fitted.validate(other)
    label = fitted.model_.label()
    assert comparison.metrics()[label]["global_relative_error"] == pytest.approx(fitted.model_.relative_error(other))
    assert dynid.summary(comparison) == dynid.summary(fitted.model_.validate(other))


def test_validate_takes_a_raw_logs_arrays_as_score_and_relative_error_do(er16, fitted):
    """``ident.validate(t, q, tau)`` raised "takes 2 positional arguments but 4 were given" where ``score(t, q, tau)``
    and ``relative_error(t, q, tau)`` take a raw log's arrays: it takes them too, and scores the samples the log's
    recording gives (the arrays made into a recording as the log readers make one)."""
    from dynid.io.logs.datasets import recording_from_arrays

    _, _, other = er16
    t, q, tau = other.t, np.asarray(other.q), np.asarray(other.tau)
    by_arrays = fitted.validate(t, q, tau)
    label = fitted.model_.label()
    expected = fitted.relative_error(t, q, tau)
    assert by_arrays.metrics()[label]["global_relative_error"] == pytest.approx(expected, rel=1e-12)
    made = fitted.model_.validate(recording_from_arrays(fitted.model_.robot, t, q, tau, name="validate"))
    assert dynid.summary(by_arrays) == dynid.summary(made)
    with pytest.raises(ValueError, match=r"validate\(t, q, tau\): positions and measured torques are needed"):
        fitted.validate(t)


def test_load_recording_takes_a_logs_path_and_load_results_a_folder(tmp_path, fitted):
    """dynid.load_recording("log.csv", robot) raised a raw AttributeError: a path is read with the columns dynid init
    finds, anything else refused in one line; load_results takes the folder dynid identify wrote."""
    robot = dynid.load_robot("er16")
    t = np.arange(500) / 100.0
    q, tau = np.sin(np.outer(t, np.arange(1, 7))), np.cos(np.outer(t, np.arange(1, 7)))
    names = ["time"] + [f"q{j}" for j in range(1, 7)] + [f"tau{j}" for j in range(1, 7)]
    np.savetxt(tmp_path / "log.csv", np.column_stack([t, q, tau]), delimiter=",", header=",".join(names), comments="")
    rec = dynid.load_recording(tmp_path / "log.csv", robot)
    np.testing.assert_allclose(np.asarray(rec.q), q, atol=1e-12)
    np.testing.assert_allclose(np.asarray(rec.tau), tau, atol=1e-12)
    with pytest.raises(TypeError, match="load_recording: expected a log's path or a DatasetSpec .*, got int"):
        dynid.load_recording(42, robot)
    with pytest.raises(DataError, match="nothere.csv: no such log"):
        dynid.load_recording(tmp_path / "nothere.csv", robot)
    (tmp_path / "out").mkdir()
    fitted.save(tmp_path / "out" / "results.json")
    assert dynid.load_results(tmp_path / "out").main == fitted.result_.main


def test_an_estimator_object_carries_its_hyperparameters_through_the_identifier(er16):
    """issue "Parts carry their settings": the SDP given as an object with the geometric prior is the config's
    [estimation] sdp_prior = "geometric" (the same estimate as identify_from_arrays given the same object, not the
    Euclidean prior's); the object's settings are said in results.json; an object of a class not registered, or an
    unknown prior, is a one-line error."""
    from dynid.estimators import Estimator, PhysicallyConsistentLeastSquares
    from dynid.identification.run import identify_from_arrays

    robot, log, _ = er16
    sdp = PhysicallyConsistentLeastSquares(prior_kind="geometric")
    ident = dynid.Identifier(robot, estimators=["wls", sdp])
    assert ident.get_params()["estimators"] == ["wls", sdp]
    geometric = ident.fit(log.t, log.q, log.tau).estimates_["dynid SDP"]
    assert ident.result_.settings["estimator_hyperparameters"]["sdp"]["prior_kind"] == "geometric"
    direct = identify_from_arrays(robot, log.t, log.q, log.tau, estimators=("wls", sdp))
    euclidean = identify_from_arrays(robot, log.t, log.q, log.tau, estimators=("wls", "sdp"))
    np.testing.assert_array_equal(geometric, direct.estimates["dynid SDP"].params)
    assert not np.array_equal(geometric, euclidean.estimates["dynid SDP"].params)
    assert not hasattr(sdp, "problem_") and not hasattr(sdp, "params_")  # the object given is not fitted itself
    with pytest.raises(ConfigError, match="identify_from_arrays: unknown setting 'sdp_prior'; expected one of choice, "
                                          "controller, estimators, friction, preprocessing, rng, torque_sensor"):
        identify_from_arrays(robot, log.t, log.q, log.tau, sdp_prior="geometric")

    class Mine(Estimator):
        pass

    with pytest.raises(ConfigError, match="Mine is not a registered estimator: dynid.estimators.register"):
        dynid.Identifier(robot, estimators=["wls", Mine()]).fit(log.t, log.q, log.tau)
    with pytest.raises(DynIdError, match="prior_kind: expected one of euclidean, geometric, got 'logdet'"):
        dynid.Identifier(robot, estimators=["wls", PhysicallyConsistentLeastSquares(prior_kind="logdet")]).fit(
            log.t, log.q, log.tau)


def test_a_model_fitted_with_the_papers_preprocessing_scores_other_logs_filtered():
    """issue "Nothing runs, nothing silent": a model fitted with eq. 17 and Fourier-fit derivatives predicted every
    later log with the parallel strategy and the paper strategy's resolved 0 Hz cutoffs: raw double differences of
    the positions. With 16-bit encoders (1e-4 rad) R² on another log was 0.964 (J1's eq. 18 correlation 0.86); the
    other log's filters are now derived from it: R² 0.99999, J1 0.998 (measured)."""
    from dynid.preprocessing.settings import Preprocessing
    from dynid.simulation.measurements import NoiseModel

    robot = dynid.load_robot("er16")
    ident = dynid.simulated_log(robot, seconds=30, rng=1)
    other = dynid.simulated_log(robot, seconds=30, rng=2, noise=NoiseModel(current_std=0.05, encoder_resolution=1e-4))
    paper = Preprocessing(strategy="paper", fourier=(2 * np.pi * 0.1, 5))  # the simulated excitation's harmonics
    model = dynid.Identifier(robot, estimators=["ols"], preprocessing=paper).fit(ident.t, ident.q, ident.tau)
    assert model.score(other.t, other.q, other.tau) > 0.999
    tau = model.predict(other.t, other.q)
    kept = np.all(np.isfinite(tau), axis=1)
    assert np.corrcoef(tau[kept, 0], other.tau[kept, 0])[0, 1] > 0.99


def test_every_fitted_object_has_a_short_repr_and_a_summary(tmp_path):
    """Issue "Parts carry their settings", item 6: the result's repr was 2,395 lines and the model's a line of 33,444
    characters, and none had summary(). Each repr is now one line that names the main estimate; each summary() gives
    the main estimate's base parameters (the table of ``parameters()``), within a screen's width."""
    from dynid import Identifier
    from dynid.exceptions import NotFittedError
    from tests.simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=10.0)
    ident = Identifier.from_config(cfg)
    for fitted in (ident.result_, ident.model_):
        line = repr(fitted)
        assert "\n" not in line and len(line) <= 200 and repr(ident.result_.main) in line
    table = repr(ident.parameters_)
    for text in (ident.summary(), ident.result_.summary(), ident.model_.summary()):
        assert table in text and max(len(r) for r in text.splitlines()) <= 200
    assert ident.model_.summary(estimate="dynid OLS").startswith(repr(ident.model_))
    with pytest.raises(NotFittedError):
        Identifier().summary()
    # dynid.summary takes the fitted objects too: an Identifier's is its result's, a model's its summary()
    assert dynid.summary(ident) == dynid.summary(ident.result_)
    assert dynid.summary(ident.model_).split() == ident.model_.summary().split()  # its words, wrapped to the width
    with pytest.raises(NotFittedError):
        dynid.summary(Identifier())


def test_the_fitted_parts_are_kept_and_a_model_read_back_answers_by_the_same_names(tmp_path, er16):
    """issue "Parts carry their settings, one route", item 6: the fitted estimator objects stay on the result (the bee
    colony's history_ of eq. 9's best value per generation; the least squares' covariance), and the identified model
    and a model read back from results.json answer by the Identifier's fitted attributes' names."""
    from dynid.estimators import BeeColonyEstimator
    from dynid.identification.identifier import FITTED

    robot, log, _ = er16
    given = BeeColonyEstimator(colony_size=20, maxiter=12)
    ident = dynid.Identifier(robot, estimators=["wls", given]).fit(log.t, log.q, log.tau)
    abc = ident.estimators_["dynid ABC"]
    assert isinstance(abc, BeeColonyEstimator) and abc is not given and not hasattr(given, "history_")
    history = np.asarray(abc.history_)
    assert history.size >= 12 and np.all(np.diff(history) <= 0) and history[-1] == pytest.approx(abc.objective_)
    np.testing.assert_array_equal(abc.params_, ident.estimates_["dynid ABC"])
    assert ident.result_.estimates["dynid ABC"].estimator is abc
    wls = ident.estimators_["dynid WLS"]
    np.testing.assert_allclose(np.sqrt(np.diag(wls.covariance_)), ident.params_std_, rtol=1e-12)
    model = dynid.load_results(ident.save(tmp_path / "results.json"))
    for name in FITTED:
        mine, kept, read = getattr(ident, name), getattr(ident.model_, name), getattr(model, name)
        if name == "estimators_":
            assert mine == kept and read == {}  # results.json holds values, not objects
        elif name == "parameters_":
            assert mine.names == read.names and np.array_equal(mine.values, read.values)
        elif name == "estimates_":
            assert list(mine) == list(read) and all(np.array_equal(mine[k], read[k]) for k in mine)
        else:
            np.testing.assert_array_equal(np.asarray(mine), np.asarray(read), err_msg=name)


def test_a_parameter_without_a_standard_deviation_reads_as_a_dash():
    """The SDP's parameters have no σ: its summary printed "nan" in every row of the σ column."""
    from dynid.identification.fitted_model import Parameters

    rows = repr(Parameters(("ZZ1R", "fc1"), np.array([1.5, 2.0]), np.array([np.nan, 0.01]))).splitlines()
    assert rows[1].split() == ["ZZ1R", "1.5", "—", "kg·m²"] and rows[2].split() == ["fc1", "2", "0.01", "N·m"]
    assert "nan" not in "\n".join(rows)


def test_the_estimator_object_given_is_the_one_fitted(er16):
    """A clone of the object given is fitted (scikit-learn's rule), not a new object of its registered key with the
    object's parameters set on it afterwards: a class whose constructor derives what ``fit`` reads from a parameter (here
    the ridge penalty from ``alpha``) fitted its default's derivation before. The fitted object is of the class given,
    with its parameters; the object given is left unfitted."""
    from dynid.estimators import Estimator, register, unregister, weighted_rows
    from dynid.identification.run import identify_from_arrays

    class Shrunk(Estimator):
        def __init__(self, *, alpha=1e-6):
            self.alpha = alpha
            self.penalty_ = alpha ** 2  # derived once, where the object is built

        def fit(self, w, tau, sample_weight=None):
            w, tau = weighted_rows(w, tau, sample_weight, 0.5)
            self.params_ = np.linalg.solve(w.T @ w + self.penalty_ * np.eye(w.shape[1]), w.T @ tau)
            return self

    robot, log, _ = er16
    register("shrunk", Shrunk, description="ridge whose penalty is derived in its constructor")
    try:
        given = Shrunk(alpha=300.0)
        result = identify_from_arrays(robot, log.t, log.q, log.tau, estimators=("wls", given))
        fitted = result.estimates["dynid SHRUNK"].estimator
        assert type(fitted) is Shrunk and fitted is not given and fitted.get_params() == given.get_params()
        assert fitted.penalty_ == 300.0 ** 2  # its constructor ran with the parameters given
        assert not hasattr(given, "params_")
        w = result.estimates["dynid WLS"].params  # the ridge at 300² pulls the estimate off least squares by far
        assert np.linalg.norm(result.estimates["dynid SHRUNK"].params - w) > 1e-3 * np.linalg.norm(w)
    finally:
        unregister("shrunk")
