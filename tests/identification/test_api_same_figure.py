"""The API gives the CLI's figure for the same log (issue "Nothing runs, nothing silent", item 5): a fitted model keeps
the samples ``dynid validate`` keeps, with the settings as the config gave them (a given decimation included), and
``relative_error`` returns the figure the CLI prints."""

from __future__ import annotations

import json
import re

import numpy as np


def test_a_given_decimation_keeps_the_clis_samples_and_relative_error_is_its_figure(tmp_path):
    from dynid.identification.fitted_model import load_results
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording
    from tests.cli.refusals import dynid
    from tests.simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "ur10e", 100.0, "fourier", duration=10.0)
    cfg.write_text(re.sub(r"^\[estimation\]", "[preprocessing]\ndecimation = 4\n[estimation]", cfg.read_text(), count=1,
                          flags=re.M))
    assert dynid("identify", cfg, "--out", tmp_path / "out", "--no-figures", "-q").returncode == 0
    assert dynid("validate", cfg, "--results", tmp_path / "out" / "results.json", "--out", tmp_path / "val",
                 "-q").returncode == 0
    cli = json.loads((tmp_path / "val" / "validation.json").read_text())["validation"][0]
    model = load_results(tmp_path / "out" / "results.json")
    config = load_identification_config(cfg)
    recording = load_recording(config.validation[0], config.robot)
    api = model.validate(recording)
    assert api.t.shape[0] == cli["n_samples"]  # 180 against 225 before: the given decimation was dropped
    label = model.label()
    np.testing.assert_allclose(model.relative_error(recording), cli["metrics"][label]["global_relative_error"], rtol=1e-12)
    np.testing.assert_allclose(api.metrics()[label]["global_relative_error"],
                               cli["metrics"][label]["global_relative_error"], rtol=1e-12)


def test_a_models_validation_marks_the_joints_dynid_validate_marks(tmp_path, shipped_identification):
    """A model's ``validate`` judges which joints' relative errors and correlations mean something against the
    identification's residual level, as ``dynid validate`` does: on the UR10e's static holds it showed ρ = 1.0000 and
    errors of 0.0 % for joints whose torque sits at the noise (``dynid validate``: n/m)."""
    from pathlib import Path

    import dynid
    from dynid.identification.fitted_model import IdentifiedModel
    from dynid.identification.run import run_validation
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording
    from tests.conftest import shared_data

    repo = Path(__file__).resolve().parents[2]
    cfg = load_identification_config(repo / "configs" / "ur10e.toml", data_root=shared_data("ur10e_mamedov2020"))
    result = shipped_identification("ur10e", validate=False)
    held = [spec for spec in cfg.validation if spec.name == "p1"]
    model = IdentifiedModel.from_result(result)
    (cli,), _ = run_validation(cfg, model.results, datasets=tuple(held))
    api = model.validate(load_recording(held[0], cfg.robot))
    assert not cli.meaningful().all() and not cli.varies().any()  # the case: a static hold, joints at the noise
    np.testing.assert_array_equal(api.meaningful(), cli.meaningful())
    np.testing.assert_array_equal(api.varies(), cli.varies())
    assert "1.0000" not in dynid.summary(api, width=300)


def test_every_route_gives_one_model_and_one_figure_with_the_defaults(tmp_path):
    """issue "Every assurance checked on what the user meets", item 4: a config without [estimation] friction, the
    :class:`Identifier` on arrays and :func:`identify_from_arrays` on the same samples share one set of defaults (the
    friction models chosen by cross-validation: arrays took the description's terms), so they give the same estimate
    and the same figure to 1e-9."""
    from dynid import Identifier, identify_from_arrays
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording
    from tests.simulated_logs import simulated_case

    cfg, _ = simulated_case(tmp_path, "ur10e", 100.0, "fourier", duration=10.0)
    config = load_identification_config(cfg)
    assert config.estimation.friction == "auto"
    log = load_recording(config.identification, config.robot)
    by_config = Identifier.from_config(cfg, validate=False)
    by_arrays = Identifier(config.robot, estimators=["ols"]).fit(log.t, log.q, log.tau)
    direct = identify_from_arrays(config.robot, log.t, log.q, log.tau, estimators=("ols",))
    chosen = [m["label"] for m in by_config.result_.settings["friction_models"]["models"]]
    assert [m["label"] for m in by_arrays.result_.settings["friction_models"]["models"]] == chosen
    for other in (by_arrays.result_, direct):
        assert other.main == by_config.result_.main
        np.testing.assert_allclose(other.main_estimate.params, by_config.result_.main_estimate.params, rtol=1e-9,
                                   atol=1e-12)
        ours, theirs = other.fit.metrics()[other.main], by_config.result_.fit.metrics()[other.main]
        np.testing.assert_allclose(ours["global_relative_error"], theirs["global_relative_error"], rtol=1e-9)


def test_a_robot_table_of_a_urdf_fits_what_the_urdf_alone_fits(tmp_path):
    """issue "Every assurance checked on what the user meets", item 4: moving ``robot = "ur10e.urdf"`` into a
    ``[robot]`` table (the README's recipe for holding a gripper) dropped the rotor inertia and the torque offset in
    silence (validation 0.292 % -> 0.716 %): the table's default drive terms are now the URDF's, and both give one
    model."""
    from dynid import Identifier
    from dynid.io.config.identification_config import load_identification_config
    from tests.cli.refusals import dynid

    folder = tmp_path / "try"
    assert dynid("example", "ur10e", folder, "-q").returncode == 0
    text = (folder / "ur10e.toml").read_text()
    assert 'robot = "ur10e.urdf"' in text
    (folder / "table.toml").write_text(text.replace('robot = "ur10e.urdf"', "") + '\n[robot]\nurdf = "ur10e.urdf"\n')
    alone, table = (load_identification_config(folder / name) for name in ("ur10e.toml", "table.toml"))
    assert table.robot.drive_terms == alone.robot.drive_terms == ("Ia", "fc", "fv", "offset")
    first, second = (Identifier.from_config(folder / name, validate=False) for name in ("ur10e.toml", "table.toml"))
    np.testing.assert_allclose(second.params_, first.params_, rtol=1e-9, atol=1e-12)
