"""`dynid identify` and `dynid validate` as a user runs them."""

import json
from pathlib import Path

import numpy as np
import pytest

from ..conftest import shared_data
from .refusals import assert_refused, dynid
from .refusals import dynid as dynid_cli

REPO = Path(__file__).resolve().parents[2]


def test_identify_and_validate_ur10e_from_the_readme(tmp_path):
    root = shared_data("ur10e_mamedov2020")
    out = tmp_path / "ur"
    p = dynid("identify", str(REPO / "configs" / "ur10e.toml"), "--out", str(out), "--data-root", str(root), "--verbose",
              env={"COLUMNS": "80"})
    assert p.returncode == 0, p.stderr
    assert "Mamedov & Mikhel 2020" in p.stdout and "ptp_10_points" in p.stdout and "error %" in p.stdout
    # an 80-column terminal: every line fits and no number is cut; in a pipe, one progress line per step
    assert max(len(line) for line in p.stdout.splitlines()) <= 80 and "…" not in p.stdout
    steps = [line for line in p.stderr.splitlines() if line.startswith("dynid identify: ")]
    assert any("regressor" in s for s in steps) and any("validation" in s for s in steps) and len(steps) == len(set(steps))
    res = json.loads((out / "results.json").read_text())
    # 58 base parameters with the description's friction terms, more with those chosen for each joint
    models = res["settings"]["friction_models"]["models"]
    extra = sum(m["kind"] in ("stribeck", "asymmetric", "load") for m in models)
    assert len(res["base_parameters"]) == 58 + extra and {"name", "value", "std", "relative_std_percent"} <= set(res["base_parameters"][0])
    assert (out / "identification_fit.png").is_file() and (out / "validation_ptp_10_points.png").is_file()
    assert len(list(out.glob("validation_p*.png"))) == 11
    # the physically consistent estimate goes to work: URDF and MJCF beside results.json, and by dynid export
    import mujoco
    import pinocchio as pin

    assert pin.buildModelFromUrdf(str(out / "dynid-model.urdf")).nq == 6 and mujoco.MjModel.from_xml_path(str(out / "dynid-model.xml")).nv == 6
    p = dynid("export", str(REPO / "configs" / "ur10e.toml"), "--results", str(out / "results.json"), "--urdf",
              str(tmp_path / "u.urdf"), "--mjcf", str(tmp_path / "u.xml"), "--data-root", str(root))
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "u.urdf").read_text() == (out / "dynid-model.urdf").read_text()
    # into the user's own MuJoCo model: same joints' values as dynid's own MJCF, the user's bodies and meshes kept
    import numpy as np

    from dynid import load_robot

    from ..io.test_mjcf_write_back import TETRAHEDRON, _users_mjcf

    (tmp_path / "mine" / "meshes").mkdir(parents=True)
    (tmp_path / "mine" / "meshes" / "piece.obj").write_text(TETRAHEDRON)
    (tmp_path / "mine" / "arm.xml").write_text(_users_mjcf(load_robot("ur10e"), np.random.default_rng(1)))
    p = dynid_cli("export", str(REPO / "configs" / "ur10e.toml"), "--results", str(out / "results.json"), "--mjcf",
                  str(tmp_path / "mine_identified.xml"), "--mjcf-model", str(tmp_path / "mine" / "arm.xml"), "--data-root", str(root))
    assert p.returncode == 0, p.stderr
    assert "the MJCF is arm.xml with only its inertials and joint dynamics replaced" in " ".join(p.stdout.split())
    ours, theirs = (mujoco.MjModel.from_xml_path(str(f)) for f in (out / "dynid-model.xml", tmp_path / "mine_identified.xml"))
    np.testing.assert_allclose(theirs.dof_damping, ours.dof_damping)
    np.testing.assert_allclose(theirs.body_subtreemass[theirs.jnt_bodyid[0]], ours.body_subtreemass[ours.jnt_bodyid[0]])
    # the user's actuator kept first, then one of constant bias per torque offset the validation logs chose to hold
    from dynid.io.results import stored_standard

    res = json.loads((out / "results.json").read_text())
    held = [j for j, f in enumerate(res["diagnostics"]["file_terms"][stored_standard(res)[0]]["offset"]) if f]
    assert theirs.nmesh == 1 and theirs.nu == 1 + len(held) and ours.nu == len(held)
    assert theirs.actuator(0).name == "m1" and f"{len(held)} actuator(s) of constant bias added" in " ".join(p.stdout.split())
    np.testing.assert_allclose(theirs.actuator_biasprm[1:, 0], ours.actuator_biasprm[:, 0])
    # validate the result on another log given on the command line: the truncated-line log
    log = root / "identification_data" / "ur-20_02_19_15harm50secLoad.csv"
    p = dynid("validate", str(REPO / "configs" / "ur10e.toml"), "--results", str(out / "results.json"), "--file", str(log),
              "--rows", "11,999999", "--out", str(tmp_path / "val"), "--data-root", str(root))
    assert p.returncode == 0, p.stderr
    assert "line 6107 is truncated" in p.stderr and "ur-20_02_19_15harm50secLoad.csv" in p.stdout
    val = json.loads((tmp_path / "val" / "validation.json").read_text())
    assert set(val["validation"][0]["metrics"]) == {"dynid OLS", "dynid SDP", "Mamedov & Mikhel 2020"}


def test_identify_tx40(tmp_path):
    root = shared_data("staubli_tx40_figaroh")
    p = dynid("identify", str(REPO / "configs" / "tx40.toml"), "--out", str(tmp_path / "tx"), "--data-root", str(root),
              "--verbose")
    assert p.returncode == 0, p.stderr
    assert "FIGAROH OLS: dynid's values lie within 1σ / 2σ / 3σ" in p.stdout and "time split" in p.stdout


def _ur_config(tmp_path, csv_text):
    (tmp_path / "log.csv").write_text(csv_text)
    (tmp_path / "c.toml").write_text('robot = "ur10e"\n[identification]\npreset = "ur-rtde"\nfile = "log.csv"\n')
    return tmp_path / "c.toml"


_ROW = ",".join(["0.5"] * 30)


@pytest.mark.parametrize("csv_text, message", [
    ("".join(f"{t},{_ROW}\n" for t in (0.0, 0.01)) + "0.02,1,2\n", "log.csv: line 3: expected 31 columns, got 3"),
    ("".join(f"{t},{_ROW}\n" for t in (0.0, 0.01, 0.005, 0.02)), "log.csv: line 3: time stamps must increase"),
    (f"0.0,{_ROW}\n0.01,inf{_ROW[3:]}\n", "log.csv: line 2, column 2: infinite value"),
])
def test_damaged_logs_get_one_line_errors_and_leave_nothing_behind(tmp_path, csv_text, message):
    cfg = _ur_config(tmp_path, csv_text)
    out = tmp_path / "out"
    p = dynid("identify", str(cfg), "--out", str(out))
    assert_refused(p, message, out)


def test_validate_needs_results_of_the_same_robot(tmp_path):
    cfg = _ur_config(tmp_path, "".join(f"{t / 100},{_ROW}\n" for t in range(200)))
    (tmp_path / "r.json").write_text(json.dumps({"base_parameters": [{"name": "ZZ1R", "value": 1.0}]}))
    p = dynid("validate", str(cfg), "--results", str(tmp_path / "r.json"), "--file", str(tmp_path / "log.csv"), "--out", str(tmp_path / "v"))
    assert p.returncode == 1 and "r.json: robot: missing" in p.stderr
    p = dynid("validate", str(cfg), "--results", str(tmp_path / "missing.json"))
    assert p.returncode == 1 and "run dynid identify first" in p.stderr


def test_identify_prints_how_it_went_and_the_tables_only_with_verbose(tmp_path):
    """Without --verbose, dynid identify on the UR10e prints its verdict in a screenful: each log's error and worst
    joint, what the log does not determine, the next step where there is one, the verdict; the tables (419 lines at 100 columns before)
    are behind --verbose and in the report."""
    root = shared_data("ur10e_mamedov2020")
    p = dynid("identify", str(REPO / "configs" / "ur10e.toml"), "--out", str(tmp_path / "u"), "--data-root", str(root),
              "--no-figures", env={"COLUMNS": "100"})
    assert p.returncode == 0, p.stderr
    lines = p.stdout.strip().splitlines()
    assert len(lines) < 60, len(lines)
    text = " ".join(p.stdout.split())
    assert "In short (every table and finding: --verbose, and report.html)" in text and "Verdict on the model" in text
    assert "ptp_10_points: torque error" in text and "payload, from the loaded run" in text
    # the ten logs that hold the arm still share one line (they took twenty to say "0 %" ten times)
    assert "p1, p2, p3, p4, p5, p6, p7, p8, p9, p10 (10 logs at rest throughout): torque error 0 % over all joints" in text
    assert "p10: torque error" not in text
    assert "Base parameters" not in text and "RMSE" not in text
    assert (tmp_path / "u" / "report.html").is_file()
    # dynid validate the same way: each log's line, the mean over the logs with the best set, the next step
    p = dynid("validate", str(REPO / "configs" / "ur10e.toml"), "--results", str(tmp_path / "u" / "results.json"),
              "--out", str(tmp_path / "v"), "--data-root", str(root), env={"COLUMNS": "100"})
    assert p.returncode == 0, p.stderr
    text = " ".join(p.stdout.split())
    val = json.loads((tmp_path / "v" / "validation.json").read_text())["validation"]
    # the mean is over the logs that move: p1-p10 hold the arm still (scored against the static-friction band, 0 %)
    moving = [v for v in val if min(v["rest_share"]) < 0.95]
    assert [v["name"] for v in moving] == ["ptp_10_points"]
    means = {name: np.mean([v["metrics"][name]["global_relative_error"] for v in moving]) for name in val[0]["metrics"]}
    assert len(p.stdout.strip().splitlines()) < 40 and "RMSE" not in text and "next:" in text
    assert (f"mean torque error over the one log that moves ({len(val) - 1} at rest throughout left out: they check the "
            "gravity model): ") in text and "best: dynid" in text
    assert all(f"{name} {m:.3g} %" in text for name, m in means.items())


def test_identify_says_its_verdict_in_25_lines_and_every_finding_with_verbose(tmp_path):
    """issue "Fast where users wait", item 4 (at most 25 lines): on the LBR Med7's config dynid identify printed 26
    lines besides its progress: one naming the 27 parameters the log leaves open and two more saying what each name
    means, and all 8 findings. Without --verbose it counts the parameters and prints the verdict's choice and the two
    findings that ask most, counting the others by kind; --verbose prints them all."""
    root = shared_data("kuka_med7_lbrstack")
    args = ("identify", str(REPO / "configs" / "kuka_med7.toml"), "--data-root", str(root), "--no-figures")
    wide = {"COLUMNS": "10000"}  # a pipe: one line per line
    p = dynid(*args, "--out", str(tmp_path / "brief"), env=wide)
    assert p.returncode == 0, p.stderr
    said = [ln for ln in (p.stdout + p.stderr).splitlines() if ln.strip() and not ln.startswith("dynid identify: ")]
    assert len(said) <= 25, said
    findings = json.loads((tmp_path / "brief" / "results.json").read_text())["findings"]
    assert len(findings) > 3
    printed = [f for f in findings if f["text"] in p.stdout]
    (more,) = [ln for ln in said if ln.startswith("and ") and ln.endswith(": --verbose, or report.html")]
    assert int(more.split()[1]) == len(findings) - len(printed) and len(printed) == 3, more
    hidden = [f["kind"] for f in findings if f not in printed]
    assert all(kind in more for kind in hidden) and printed[0]["kind"] == "main"
    assert "base parameters this log leaves open: " in p.stdout and "the link parameters named" not in p.stdout
    v = dynid(*args, "--out", str(tmp_path / "verbose"), "--verbose", env=wide)
    assert v.returncode == 0, v.stderr
    assert all(f["text"] in v.stdout for f in findings) and ": --verbose, or report.html" not in v.stdout
    assert "the link parameters named" in v.stdout


@pytest.mark.parametrize(("name", "content"), [("run.csv", b"t,q1,tau1\n0,0.1,2.0\n"), ("run.mcap", b"\x89MCAP0\r\n\xff\xfe")])
@pytest.mark.parametrize("command", ["identify", "validate", "export"])
def test_a_log_given_for_the_config_is_told_how_to_get_one(tmp_path, name, content, command):
    """``dynid identify run.csv`` (a log where the config goes) said 'invalid TOML (Expected '=' after a key …)', or
    'not UTF-8 text' for a bag: it now names the log and the command that writes a config for it."""
    log = tmp_path / name
    log.write_bytes(content)
    assert_refused(dynid(command, log), f"{log}: a log, not a config (TOML): dynid init ROBOT {log} writes an "
                                        "identification config that reads it")


def test_no_next_step_when_nothing_is_left_to_do(tmp_path, monkeypatch):
    """The UR10e example identified with its validation log: every finding is good news (the choice, a fit at the
    noise floor, every joint better than the description) and the URDF and MJCF are written; "next: read the
    verdict's findings … where the model misses the data" was printed all the same (issue "Fast where users wait",
    item 4). Without the validation log there is a next step (add one), and the yardstick line gives the measured
    torques' own noise floor beside the main estimate's figure."""
    monkeypatch.chdir(tmp_path)
    assert dynid("example", "ur10e", "try", "-q").returncode == 0
    monkeypatch.chdir(tmp_path / "try")
    p = dynid("identify", "ur10e.toml", "--out", "id", "--no-figures")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "try" / "id" / "results.json").read_text())
    assert {f["kind"] for f in results["findings"]} <= {"main", "floor", "nominal"}
    assert "next:" not in p.stdout and p.stdout.lstrip().startswith("model ready: dynid SDP")
    floor = results["diagnostics"]["yardstick"]["noise_floor"]
    assert f"(noise floor {floor:.3g} %: the measured torques' own noise)" in " ".join(p.stdout.split())
    text = (tmp_path / "try" / "ur10e.toml").read_text()
    (tmp_path / "try" / "alone.toml").write_text(text[:text.index("[[validation]]")] + text[text.index("[estimation]"):])
    p = dynid("identify", "alone.toml", "--out", "id2", "--no-figures")
    assert p.returncode == 0 and "next: add [[validation]] logs" in " ".join(p.stdout.split())


def test_with_no_validate_the_first_line_says_to_run_with_the_configs_validation_logs(rng):
    """``dynid identify --no-validate`` on a config that has validation logs said "add [[validation]] logs (other
    motions) before you use it": the config has them; the line says to run again without the flag."""
    from dynid.cli.app import _runnable_advice
    from dynid.report.summaries import readiness

    from ..report.test_readiness import _result

    ready = _result(rng, 0.02)
    ready.validations = ()  # as --no-validate leaves them
    line = readiness(ready)
    assert "add [[validation]] logs (other motions)" in line.text
    (told,) = _runnable_advice([line], Path("arm.toml"), Path("out"), skipped=2)
    assert told.text.startswith("model ready to check: dynid SDP is physically consistent") and "[[validation]]" not in told.text
    assert "run again without --no-validate (the config's 2 validation logs: other motions) before you use it" in told.text
    (same,) = _runnable_advice([line], Path("arm.toml"), Path("out"))  # a config without validation logs: as before
    assert same.text == line.text
