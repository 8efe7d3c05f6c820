"""Every estimator on a log (the paper's ABC included): one registry for run and identify."""

import json
import re
import warnings
from dataclasses import replace

import numpy as np
import pytest

from dynid.exceptions import ConfigError
from dynid.identification.run import run_identification, run_validation
from dynid.io.config.identification_config import load_identification_config
from dynid.report.identification_run import save_identification

from ..simulated_logs import simulated_case, truth_beta

ALL = ["wls", "ols", "sdp", "irls", "lad", "abc", "abc10", "de", "pso"]


def test_identify_runs_every_estimator_side_by_side(tmp_path):
    cfg, truth_robot = simulated_case(tmp_path, "ur10e", 125.0, "fourier", seed=4, duration=30.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]\n', f'estimators = {json.dumps(ALL)}\nseed = 3\n'))
    config = load_identification_config(cfg)
    assert config.estimation.estimators == tuple(ALL)
    result = run_identification(config)
    labels = ["dynid WLS", "dynid OLS", "dynid SDP", "dynid IRLS", "dynid LAD", "dynid ABC", "dynid ABC×10", "dynid DE", "dynid PSO"]
    assert list(result.parameter_sets())[:9] == labels
    for cmp in (result.fit, *result.validations):
        assert set(labels) <= set(cmp.metrics())
    # LAD is the exact minimiser of eq. 9 in the box: no box search goes below it
    f = result.objective
    assert all(f["dynid LAD"] <= f[k] + 1e-9 for k in ("dynid ABC", "dynid ABC×10", "dynid DE", "dynid PSO"))
    lo, hi = result.box.T
    others = [e for e in result.estimates.values() if e.key != "wls"]
    for o in others:
        if o.key in ("lad", "abc", "abc10", "de", "pso"):
            assert np.all(o.params >= lo - 1e-9) and np.all(o.params <= hi + 1e-9)
    # the least-squares family recovers the truth on this simulated log
    truth = truth_beta(result, truth_robot)
    for o in others:
        if o.key in ("ols", "irls", "lad"):
            assert np.linalg.norm(o.params - truth) / np.linalg.norm(truth) < 0.02, o.key
    # the same seed gives the same box searches
    again = run_identification(config, validate=False)
    for a, b in zip(result.estimates.values(), again.estimates.values()):
        np.testing.assert_array_equal(a.params, b.params)
    # dynid validate reads every set back from results.json
    save_identification(result, tmp_path / "out")
    stored = json.loads((tmp_path / "out" / "results.json").read_text())
    comparisons, _ = run_validation(config, stored)
    assert set(labels) <= set(comparisons[0].metrics())
    np.testing.assert_allclose(comparisons[0].metrics()["dynid ABC"]["relative_error"],
                               result.validations[0].metrics()["dynid ABC"]["relative_error"], rtol=1e-9)


def test_unknown_estimator_in_the_config_names_the_field(tmp_path):
    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=5.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]\n', 'estimators = ["wls", "magic"]\n'))
    with pytest.raises(ConfigError, match=r"config.toml: estimation.estimators: expected .*got \['wls', 'magic'\]"):
        load_identification_config(cfg)


@pytest.mark.parametrize("old, new", [
    ('method = "wls"\nphysically_consistent = true\n', 'estimators = ["wls", "sdp"]'),
    ('methods = ["ols", "lad", "sdp"]\n', 'estimators = ["ols", "sdp", "lad"]'),
    ('physically_consistent = true\n', 'estimators = ["wls", "sdp"]'),
])
def test_the_old_estimation_keys_say_how_to_write_them_now(tmp_path, old, new):
    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=5.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]\n', old))
    with pytest.raises(ConfigError) as err:
        load_identification_config(cfg)
    text = str(err.value)
    assert "no longer exists" in text and f"{new} (dynid migrate {cfg} rewrites it)" in text and "\n" not in text


def test_estimator_names_are_case_insensitive(tmp_path):
    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=5.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]\n', 'estimators = ["OLS", "Wls"]\n'))
    assert load_identification_config(cfg).estimation.estimators == ("ols", "wls")


def test_identify_takes_the_estimators_as_a_text_too(tmp_path):
    """``identify(..., "wls")`` is WLS, not the estimators "w", "l", "s"."""
    from dynid.dynamics.base_parameters import base_parameters
    from dynid.identification.estimation_pass import identify
    from dynid.io.logs.datasets import load_recording
    from dynid.preprocessing.preparation import prepare

    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=5.0)
    config = load_identification_config(cfg)
    base = base_parameters(config.robot)
    data = prepare(load_recording(config.identification, config.robot), config.preprocessing)
    as_text = identify(config.robot, base, data, "ols,wls")
    as_tuple = identify(config.robot, base, data, ("ols", "wls"))
    assert [e.key for e in as_text.estimates.values()] == ["ols", "wls"]
    for a, b in zip(as_text.estimates.values(), as_tuple.estimates.values()):
        np.testing.assert_array_equal(a.params, b.params)


def test_the_output_opens_with_how_it_went_and_what_to_do_next(tmp_path):
    """The first lines of dynid identify: whether the model is ready and what to do (the first line), then the estimate
    to use, each log's error and worst joint, the next step."""
    from dynid.report.summaries import identification_blocks
    from dynid.tables import render_text

    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=20.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]\n', 'estimators = ["ols", "sdp"]\n'))
    result = run_identification(load_identification_config(cfg))
    text = render_text(identification_blocks(result), 200)
    lines = text.splitlines()
    assert lines[0].startswith(("model ready", "warning: not ready"))
    assert lines[2].startswith("In short")  # right after the title
    tail = lines[2:lines.index("", 2)]  # "In short", to the blank line before the verdict
    label = result.main_estimate.label
    assert tail[1].startswith(f"main estimate: {label}, ") and "physically consistent" in tail[1]
    main = result.fit.metrics()[label]
    assert tail[2].startswith(f"{result.fit.name}: torque error {main['global_relative_error']:.3g} % over all joints, worst J")
    assert len([t for t in tail if "torque error" in t]) == 1 + len(result.validations)
    to_do = any(f.kind not in ("main", "floor", "nominal") for f in result.findings) or not result.validations
    assert tail[-1].startswith("next: ") == to_do  # a next step only where there is something to do
    boot = result.diagnostics["bootstrap_std"]  # σ % from the larger of the covariance's and the bootstrap's
    assert set(boot) == set(result.base.names)
    larger = {n: max(rel, 100 * boot[n] / abs(v))
              for n, v, rel in zip(result.base.names, result.solution.params, result.solution.relative_std)}
    loose = [n for n in result.base.names if larger[n] >= 100]
    assert loose != [n for n, rel in zip(result.base.names, result.solution.relative_std) if rel >= 100]  # the bootstrap's say
    share = result.diagnostics["sigma_torque_percent"]  # ±σ torque over the joint's, % (covariance's σ): scaled
    small = [n for n, rel in zip(result.base.names, result.solution.relative_std)
             if n in loose and share[n] * larger[n] / rel < 1.0]

    def listed(start: str) -> list[str]:
        said = [t for t in tail if t.startswith(start)]
        return said[0].split("): ")[1].split(": ")[0].split(", ") if said else []

    assert listed("not determined by this log") == [n for n in loose if n not in small]
    assert listed("about 0 on this log's motion") == small


def _configured(config, **given) -> dict:
    """The config's estimators given as objects (an entry with settings): key -> their parameters named in ``given``
    (scikit-learn's ``get_params``)."""
    from dynid.estimators.registry import estimator_choices

    objects = [x for x in config.estimation.estimators if not isinstance(x, str)]
    return {key: {k: est.get_params()[k] for k in given[key]}
            for key, est in (estimator_choices(objects)[1] if objects else {}).items()}


def test_the_geometric_prior_keeps_exported_links_plausible_at_no_cost_in_accuracy(tmp_path):
    """``estimators = ["ols", { key = "sdp", prior_kind = "geometric" }]``: the SDP keeps what the data do not determine near the nominal links by
    the pseudo-inertias' log-det divergence (Lee, Wensing & Park 2020): the fit is the Euclidean prior's, and every
    link of the estimate is a non-degenerate mass distribution (principal inertias of the nominal's order)."""
    from dynid.io.exported.export import consistent_estimate
    from dynid.model.spatial import physical_from_inertial

    cfg, _ = simulated_case(tmp_path, "ur10e", 125.0, "fourier", seed=4, duration=30.0)
    text = cfg.read_text()
    runs = {}
    for kind in ("euclidean", "geometric"):
        cfg.write_text(text.replace('estimators = ["ols"]\n', f'estimators = ["ols", {{ key = "sdp", prior_kind = "{kind}" }}]\n'))
        config = load_identification_config(cfg)
        assert _configured(config, sdp=["prior_kind"]) == {"sdp": {"prior_kind": kind}}
        runs[kind] = (config, run_identification(config, validate=True))
    fit = {k: r.validations[0].metrics()["dynid SDP"]["global_relative_error"] for k, (_, r) in runs.items()}
    assert fit["geometric"] <= 1.01 * fit["euclidean"], fit
    config, result = runs["geometric"]
    from dynid.io.files import _clean  # results.json's own conversion (NaN and arrays)

    robot, phi = consistent_estimate(config.robot, json.loads(json.dumps(_clean(result.to_dict()))))
    fitted = robot.with_parameters(phi)
    for j in range(robot.n_dof):
        smallest = np.linalg.eigvalsh(physical_from_inertial(fitted.inertial[j])[2]).min()
        nominal = np.linalg.eigvalsh(physical_from_inertial(config.robot.inertial[j])[2]).min()
        assert smallest > 1e-3 * nominal, (j, smallest, nominal)


@pytest.mark.parametrize("estimation, message", [
    ('estimators = ["ols", { key = "sdp", prior_kind = "round" }]',
     "estimation.estimators[1]: sdp's prior_kind: expected one of euclidean, geometric, got 'round'"),
    ('estimators = ["ols", { key = "abc", colonysize = 8 }]',
     "estimation.estimators[1]: abc has no hyper-parameter 'colonysize'; expected some of colony_size, limit, maxiter"),
    ('estimators = ["ols", { key = "abc", rng = 8 }]', "abc has no hyper-parameter 'rng' (dynid fills it"),
    ('estimators = ["ols", { prior_kind = "geometric" }]', 'estimation.estimators[1]: a table in the list names its '
                                                          'estimator, { key = "sdp"'),
    ('estimators = ["ols", { key = "nosuch" }]', "nosuch"),
])
def test_an_estimators_bad_hyperparameters_are_refused_in_one_line(tmp_path, estimation, message):
    """An estimator's hyper-parameters in the estimators list: a name its class does not take, a value outside its
    choices, a table naming no estimator are said with the entry, when the config is read."""
    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=5.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]\n', estimation + "\n"))
    with pytest.raises(ConfigError, match=re.escape(message)), warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        load_identification_config(cfg)


def test_a_drafts_sdp_prior_is_refused_in_one_line_saying_the_estimators_entry(tmp_path):
    """``[estimation] sdp_prior`` (an earlier 0.2.0 draft's key; no release had it) is refused when the config is read,
    in one line naming the file, the key and the estimators list's entry that says it; that entry gives the SDP its
    prior."""
    from dynid.io.config.migrate import migrate_text

    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=5.0)
    text = cfg.read_text().replace('estimators = ["ols"]\n', 'estimators = ["ols", "sdp"]\nsdp_prior = "geometric"\n')
    cfg.write_text(text)
    with pytest.raises(ConfigError, match=re.escape(f'{cfg}: estimation.sdp_prior: no longer exists') + r'.*'
                       + re.escape('{ key = "sdp", prior_kind = "geometric" } in place of "sdp"')):
        load_identification_config(cfg)
    assert migrate_text(text, str(cfg)) == (text, [])  # nothing a release wrote: dynid migrate leaves it
    cfg.write_text(text.replace('["ols", "sdp"]\nsdp_prior = "geometric"', '["ols", { key = "sdp", prior_kind = "geometric" }]'))
    assert _configured(load_identification_config(cfg), sdp=["prior_kind"]) == {"sdp": {"prior_kind": "geometric"}}


def test_a_box_searchs_hyperparameters_reach_it_from_the_config(tmp_path):
    """``{ key = "abc", colony_size = 8, maxiter = 4 }``: the paper's bee colony with its Table 3 settings of the
    user's, which a config could not set before (only the SDP's prior): the colony searched 8 food sources for 4
    cycles, as results.json's settings and the fitted estimator's history say."""
    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=5.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]\n',
                                           'estimators = ["ols", { key = "abc", colony_size = 8, maxiter = 4 }]\n'))
    config = load_identification_config(cfg)
    assert _configured(config, abc=["colony_size", "maxiter"]) == {"abc": {"colony_size": 8, "maxiter": 4}}
    result = run_identification(config, validate=False)
    given = result.settings["estimator_hyperparameters"]["abc"]
    assert given["colony_size"] == 8 and given["maxiter"] == 4
    fitted = result.estimates["dynid ABC"].estimator
    assert fitted.colony_size == 8 and len(fitted.history_) <= 4 + 1  # the best before the first cycle, one per cycle


def test_validate_opens_with_each_logs_errors_and_the_best_set(tmp_path):
    from dynid.report.summaries import validation_in_short
    from dynid.tables import render_text

    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=20.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]\n', 'estimators = ["ols", "sdp"]\n'))
    config = load_identification_config(cfg)
    save_identification(run_identification(config, validate=False), tmp_path / "out", figures_too=False)
    comparisons, _ = run_validation(config, json.loads((tmp_path / "out" / "results.json").read_text()))
    lines = render_text(validation_in_short(comparisons), 400).splitlines()
    assert lines[0].startswith("In short") and len(lines) == 1 + len(comparisons)
    for c, line in zip(comparisons, lines[1:]):
        m = c.metrics()
        assert line.startswith(f"{c.name}: torque error over all joints: ")
        assert all(f"{label} {v['global_relative_error']:.3g} %" in line for label, v in m.items())
        low = min(v["global_relative_error"] for v in m.values())  # sets equal at the three digits shown: named together
        tied = [k for k, v in m.items() if f"{v['global_relative_error']:.3g}" == f"{low:.3g}"]
        assert line.endswith(f"best: {tied[0]}" if len(tied) == 1 else f"equal best: {', '.join(tied)}"), line


def test_validate_sums_up_resting_logs_in_one_line_and_leaves_them_out_of_the_mean(rng):
    """The UR10e's validate printed ten lines "p1: … dynid OLS 0 % (worst J2 0 %) …; best: dynid OLS" (every set
    0 %: no best), and its mean over the 11 logs, 0.206 %, was the moving log's 2.27 % diluted by ten zeros."""
    from dynid.report.summaries import validation_in_short, validation_verdict
    from dynid.tables import render_text
    from dynid.validation.torques import TorqueComparison

    t = np.arange(300) * 0.01
    measured = np.column_stack([np.sin(t), np.cos(0.5 * t)])
    held = np.tile([1.0, -2.0], (t.size, 1))
    rest = [TorqueComparison(f"p{k}", t, held, {"A": held, "B": held}, resting=np.ones(held.shape, bool))
            for k in (1, 2)]
    moving = TorqueComparison("moving", t, measured, {"A": 1.02 * measured, "B": 1.2 * measured})
    comparisons = [moving, *rest]
    lines = render_text([*validation_in_short(comparisons), *validation_verdict(comparisons)], 400).splitlines()
    assert [x for x in lines if "at rest" in x and x.startswith("p")] == [
        "p1, p2 (2 logs at rest throughout): torque error over all joints: A 0 %; B 0 % (the distance to the "
        "static-friction band, a check of the gravity model to within friction, not of motion)"]
    a, b = (moving.metrics()[k]["global_relative_error"] for k in "AB")
    assert f"mean torque error over the one log that moves (2 at rest throughout left out: they check the gravity model): " \
           f"A {a:.3g} %; B {b:.3g} % — best: A" in lines


def test_the_first_line_says_whether_the_model_is_ready(tmp_path):
    """issue "A user's first hour", item 6: the first line is the verdict and the next step: ready with a physically
    consistent estimate that beats the nominal model on the validation log; not ready, saying how to get there, with
    least squares alone; the main-estimate line says which estimate export writes."""
    from dynid.report.summaries import identification_brief
    from dynid.tables import render_text

    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=20.0)
    text = cfg.read_text()
    cfg.write_text(text.replace('estimators = ["ols"]\n', 'estimators = ["wls"]\n'))
    first = render_text(identification_brief(run_identification(load_identification_config(cfg))), 400).splitlines()[0]
    assert first == 'warning: not ready to export: add "sdp" to [estimation] estimators for a physically consistent estimate'
    cfg.write_text(text.replace('estimators = ["ols"]\n', 'estimators = ["wls", "sdp"]\n'))
    result = run_identification(load_identification_config(cfg))
    lines = render_text(identification_brief(result), 400).splitlines()
    worse = [s["worse_joints"] for s in result.diagnostics["versus_nominal"].values()]
    if any(worse):
        assert lines[0].startswith("warning: not ready: the description's nominal model predicts")
    else:
        exported = next(n for n, e in result.estimates.items()  # what dynid export writes: standard values, consistent
                        if e.standard is not None and result.consistency_verdicts[n].startswith("yes"))
        assert lines[0] == (f"model ready: {exported}, as the URDF and MJCF in the output folder (other names: dynid "
                            "export CONFIG --urdf FILE --mjcf FILE)")


def test_a_log_at_rest_throughout_says_what_its_figure_checks(tmp_path):
    """A validation log at rest throughout is scored by the distance to the static-friction band, so every set reads
    0 % there (the UR10e's resting logs p1-p10: 0 % for dynid's estimate and the published set alike, against 3-18 %
    before the band): "0 %" beside a noise floor read as a perfect model. The line now says the log rests and what
    the figure checks; a moving log keeps its noise floor."""
    from dynid.report.summaries import in_short
    from dynid.tables import render_text

    from ..simulated_logs import truth_robot, write_log

    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=20.0)
    robot, friction = truth_robot("er16", np.random.default_rng(0))
    t = np.arange(int(10 * 125.0)) / 125.0
    pose = np.tile([0.3, -0.8, 0.5, 0.2, -0.4, 0.1], (t.size, 1))
    pose = pose + np.random.default_rng(4).normal(0.0, 2e-5, pose.shape)  # the encoders' noise: a held arm
    write_log(tmp_path / "valid.csv", robot, t, pose, np.zeros_like(pose), np.zeros_like(pose), friction,
              np.random.default_rng(3))
    result = run_identification(load_identification_config(cfg))
    text = render_text(in_short(result), 400)
    rest = next(line for line in text.splitlines() if line.startswith("validation:"))
    assert "at rest throughout: the distance to the static-friction band" in rest and "noise floor" not in rest
    fit = next(line for line in text.splitlines() if line.startswith("identification:"))
    assert "noise floor" in fit and "at rest" not in fit
    # several resting logs share one line (the UR10e's p1-p10 took twenty lines to say "0 %" ten times)
    held = result.validations[0]
    twice = replace(result, validations=(held, replace(held, name="held again")))
    lines = [line for line in render_text(in_short(twice), 400).splitlines() if "at rest throughout" in line]
    assert len(lines) == 1 and lines[0].startswith("validation, held again (2 logs at rest throughout): torque error")


def test_a_configs_estimator_settings_stay_with_a_key_an_identifier_gives_over_it(tmp_path):
    """``Identifier.from_config(config, estimators=["wls", "abc"])`` over a config whose list says ``{ key = "abc",
    colony_size = 8, maxiter = 4 }``: the bee colony fitted is the config's (its settings are the config's object's,
    not a dict carried beside the keys), and an estimator object given in the Identifier's list is the one cloned."""
    import dynid
    from dynid.estimators import BeeColonyEstimator

    cfg, _ = simulated_case(tmp_path, "er16", 125.0, "fourier", duration=5.0)
    cfg.write_text(cfg.read_text().replace('estimators = ["ols"]\n',
                                           'estimators = ["ols", { key = "abc", colony_size = 8, maxiter = 4 }]\n'))
    fitted = dynid.Identifier.from_config(cfg, validate=False, estimators=["wls", "abc"]).estimators_["dynid ABC"]
    assert fitted.colony_size == 8 and fitted.maxiter == 4
    given = BeeColonyEstimator(colony_size=6, maxiter=2)
    fitted = dynid.Identifier.from_config(cfg, validate=False, estimators=["wls", given]).estimators_["dynid ABC"]
    assert fitted is not given and (fitted.colony_size, fitted.maxiter) == (6, 2)
