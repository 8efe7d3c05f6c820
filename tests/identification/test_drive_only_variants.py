"""A joint that moves one way only in a short log: the drive terms of it that the log does not determine, judged by how
they move with the cutoffs, are held at the description's values where it gives them, or said (issue "Honest on any
log", item 1; :func:`dynid.identification.drive_only.drive_only`).

A UR10e simulated in MuJoCo (outside dynid's model, tests/mujoco_logs.py) under its PID loop against MuJoCo's own dry
friction: 5 s in which the shoulder (J2) and J5 crawl one way while the others swing, then a 20 s Fourier log. The
shoulder barely accelerates, so its rotor inertia is set by how the filters shape a tiny acceleration. Each estimate is
checked against the estimate without the judgement (``variants=()``) on the validation log's TRUE states, outside
dynid's preprocessing. Then the real UR10e's log: a 3 s window in which J3 and J5 move one way."""

import json
from dataclasses import replace
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

import dynid.identification.pipeline as pipeline_module
from dynid.dynamics.regressor import regressor
from dynid.identification.run import pipeline_of, run_identification
from dynid.io.config.identification_config import load_identification_config
from dynid.io.logs.datasets import load_recording
from dynid.report.summaries import in_short

from ..cli.refusals import dynid
from ..conftest import shared_data
from ..mujoco_logs import Drives, fourier_reference, simulate, write_csv

DRIVES = Drives(ia=np.array([0.066, 0.066, 0.03, 0.011, 0.011, 0.011]), fv=np.array([3.3, 3.3, 1.5, 0.56, 0.56, 0.56]),
                fc=np.array([6.6, 6.6, 3.0, 1.1, 1.1, 1.1]))
"""Drive terms of the size the zoo gives an arm with the UR10e's torque limits (benchmarks/zoo)."""
DATA_SHEET = 1.2 * DRIVES.ia
"""Rotor inertias as a drive's data sheet gives them: 20 % off the truth."""
ONE_WAY = (1, 4)


def _crawl(t, n, rng, amplitude, centre):
    """A Fourier motion in which the joints of ONE_WAY drift one way with a slow swing (the zoo's short logs)."""
    q, dq, ddq = fourier_reference(t, n, rng, 0.2, 4, amplitude, centre)
    span = t[-1] - t[0]
    for j in ONE_WAY:
        speed = 1.2 * amplitude[j] / span
        q[:, j] = centre[j] - 0.6 * speed * span + speed * t + 0.1 * amplitude[j] * np.sin(0.9 * t)
        dq[:, j] = speed + 0.09 * amplitude[j] * np.cos(0.9 * t)
        ddq[:, j] = -0.081 * amplitude[j] * np.sin(0.9 * t)
    return q, dq, ddq


@pytest.fixture(scope="module")
def crawled(tmp_path_factory):
    """The logs, and the config without and with the data sheet's rotor inertias."""
    folder = tmp_path_factory.mktemp("crawl")
    urdf = (resources.files("dynid.model") / "robots" / "ur10e.urdf").read_text()
    (folder / "ur10e.urdf").write_text(urdf)
    rng = np.random.default_rng(3)
    common = dict(noise_share=0.02, torque_std=np.array([1.0, 2.0, 1.0, 0.2, 0.2, 0.2]), dry="frictionloss",
                  centre=np.array([0, -1.5, 1.2, -1.2, 0, 0]), amplitude=0.5)
    short = simulate(urdf, DRIVES, "fourier", 5.0, rng, reference=_crawl, **common)
    valid = simulate(urdf, DRIVES, "fourier", 20.0, rng, f0=0.15, harmonics=5, **common)
    write_csv(folder / "short.csv", short)
    write_csv(folder / "valid.csv", valid)
    cols = lambda a: "[" + ", ".join(str(a + j) for j in range(6)) + "]"  # noqa: E731
    table = lambda f: (f'file = "{f}"\ntime = {{ column = 1 }}\npositions = {{ columns = {cols(2)} }}\n'  # noqa: E731
                       f'torques = {{ columns = {cols(8)} }}\n')
    rest = (f'[identification]\n{table("short.csv")}[estimation]\nestimators = ["wls", "sdp"]\n[[validation]]\n'
            f'name = "v"\n{table("valid.csv")}')
    robot = f'data_root = "{folder}"\n[robot]\nurdf = "ur10e.urdf"\ndrive_terms = ["Ia", "fc", "fv", "offset"]\n'
    (folder / "urdf.toml").write_text(robot + rest)
    (folder / "sheet.toml").write_text(robot + "".join(f"[[robot.joints]]\nIa = {float(v)!r}\n" for v in DATA_SHEET) + rest)
    return folder, valid


def _error(robot, phi, log) -> np.ndarray:
    """Each joint's RMS torque error [N·m] of ``phi`` on the TRUE states and torques of ``log``."""
    y = regressor(robot, log.q, log.dq, log.ddq)
    return np.sqrt(np.mean((log.tau - y @ phi) ** 2, axis=0))


def _with_and_without(config):
    """The drive-only fits of the identification log with the judgement and without it, and the model."""
    pipeline = pipeline_of(config)
    prepared = pipeline.prepare(load_recording(config.identification, config.robot))
    assert {f for f, _ in prepared.variants} == {0.5, 2.0}
    judged = pipeline.estimate(prepared).drive_only
    plain = pipeline.estimate(replace(prepared, variants=())).drive_only
    return judged, plain, prepared.robot


def test_a_rotor_inertia_the_log_does_not_determine_takes_the_data_sheets_value(crawled):
    folder, valid = crawled
    config = load_identification_config(folder / "sheet.toml")
    judged, plain, robot = _with_and_without(config)
    index = {n: i for i, n in enumerate(robot.parameter_names)}
    assert "Ia2" in judged.held and judged.standard[index["Ia2"]] == pytest.approx(DATA_SHEET[1])
    runs = np.asarray(judged.held["Ia2"])  # the estimates at 0.5, 1 and 2 × the cutoffs moved by their own size
    assert judged.held["cutoff_factors"] == (0.5, 1.0, 2.0) and np.ptp(runs) >= abs(runs[1])
    assert plain.standard[index["Ia2"]] == runs[1] != DATA_SHEET[1]
    held = [k for k in judged.held if k != "cutoff_factors"]
    assert all(int(k.lstrip("Iafcvolsetd")) - 1 in ONE_WAY for k in held), held  # the one-way joints' terms only
    before, after = _error(robot, plain.standard, valid), _error(robot, judged.standard, valid)
    assert after[1] < before[1] and np.sqrt(np.mean(after**2)) < np.sqrt(np.mean(before**2)), (after, before)

    result = run_identification(config)
    main = next(f.text for f in result.findings if f.kind == "main")
    assert result.main == "dynid drive-only" and "kept at the description's values: Ia2 (" in main


def test_without_a_rotor_inertia_in_the_description_the_logs_value_stays_and_is_said(crawled):
    folder, _ = crawled
    config = load_identification_config(folder / "urdf.toml")
    judged, plain, robot = _with_and_without(config)
    index = {n: i for i, n in enumerate(robot.parameter_names)}
    assert "Ia2" in judged.undetermined and "Ia2" not in judged.held
    assert judged.standard[index["Ia2"]] == plain.standard[index["Ia2"]]  # a URDF's 0 is no knowledge of it
    result = run_identification(config)
    assert result.main == "dynid drive-only"
    main = next(f.text for f in result.findings if f.kind == "main")
    assert "kept at this log's values, as the description gives none: Ia2 (" in main
    lines = [line.text for line in in_short(result)]
    said = next(t for t in lines if t.startswith("dynid drive-only: the links' inertial parameters are the description's"))
    assert "not determined by this log either, kept at its values as the description gives none: " in said
    assert "Ia2" in said.split("gives none: ")[1]
    assert all(t.startswith("dynid WLS, beside it: ") for t in lines if "not determined by this log (" in t)


def _window(tmp_path) -> Path:
    root = shared_data("ur10e_mamedov2020")
    text = (Path(__file__).resolve().parents[2] / "configs" / "ur10e.toml").read_text()
    text = text.replace('data_root = "../../shared/data/ur10e_mamedov2020"', f'data_root = "{root}"')
    (tmp_path / "c.toml").write_text(text.replace("rows = [635, 3510]", "rows = [635, 935]"))
    return tmp_path / "c.toml"


def _mean(results: dict, label: str) -> float:
    return float(np.mean([v["metrics"][label]["global_relative_error"] for v in results["validation"]]))


def test_a_one_way_joints_unstable_coulomb_and_offset_split_keeps_their_sum_as_coulomb(tmp_path, monkeypatch):
    """Rows 635-935 of the real UR10e's log (3 s, J3 and J5 one way): J3's Coulomb friction and offset are 15.3 and
    -11.1 N·m at the log's cutoffs, 41.6 and -37.2 at half of them, 2973 and -2969 at twice: the offset is held at the
    description's value and the sum is Coulomb friction. The 11 validation logs are predicted better than by the same
    fit without the judgement."""
    config = _window(tmp_path)
    p = dynid("identify", config, "--out", tmp_path / "judged", "--no-figures", "-q")
    assert p.returncode == 0, p.stderr
    judged = json.loads((tmp_path / "judged" / "results.json").read_text())
    assert judged["main_estimate"] == "dynid drive-only"
    held = judged["diagnostics"]["drive_only_held"]
    assert {"offset3", "offset5"} <= set(held) and not {"fc3", "fc5"} & set(held)
    std = judged["estimates"]["dynid drive-only"]["standard_values"]
    assert std["offset3"] == 0.0 and std["fc3"] > 0

    monkeypatch.setattr(pipeline_module, "preprocessing_variants", lambda *args, **kw: ())
    plain = run_identification(load_identification_config(config))
    label = "dynid drive-only"
    before = float(np.mean([v.metrics()[label]["global_relative_error"] for v in plain.validations]))
    assert plain.main == label and "drive_only_held" not in plain.diagnostics
    assert _mean(judged, label) < before
