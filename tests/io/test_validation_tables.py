"""What a ``[[validation]]`` table takes from the identification's column layout (README: "a name and a file are
enough, the identification's columns are taken")."""

import numpy as np

HEADER = "t," + ",".join(f"q{j}" for j in range(1, 7)) + "," + ",".join(f"tau{j}" for j in range(1, 7))
TORQUES = '["tau1", "tau2", "tau3", "tau4", "tau5", "tau6"]'


def _config(tmp_path, validation: str):
    rng = np.random.default_rng(0)
    for name in ("ident.csv", "other.csv"):
        t = np.arange(200) * 0.01
        x = np.column_stack([t, 0.3 * np.sin(np.outer(t, np.arange(1, 7))), rng.normal(size=(200, 6))])
        np.savetxt(tmp_path / name, x, delimiter=",", header=HEADER, comments="", fmt="%.9g")
    (tmp_path / "c.toml").write_text(
        'robot = "ur10e"\ndata_root = "."\n[identification]\nfile = "ident.csv"\nheader = true\ntime = { column = "t" }\n'
        'positions = { columns = ["q1", "q2", "q3", "q4", "q5", "q6"] }\n'
        f"torques = {{ columns = {TORQUES} }}\n[[validation]]\n" + validation)
    return tmp_path / "c.toml"


def test_a_validation_table_with_only_its_torques_takes_the_identifications_other_columns(tmp_path):
    """A user flipping the sign of a validation log's torques (``torques = {..., sign = -1}``, the Med7's logs) was
    told "validation[0]: expected 'positions'": a table that gave its torques took none of the identification's
    columns. It now takes the time and positions it does not give; its own torques replace the identification's."""
    from dynid.io.config.identification_config import load_identification_config
    from dynid.io.logs.datasets import load_recording
    from dynid.model.description import load_robot

    cfg = load_identification_config(_config(tmp_path, f'name = "other"\nfile = "other.csv"\ntorques = {{ columns = '
                                                       f'{TORQUES}, sign = -1 }}\n'))
    robot = load_robot("ur10e")
    rec = load_recording(cfg.validation[0], robot)
    x = np.loadtxt(tmp_path / "other.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(rec.t, x[:, 0] - x[0, 0], atol=1e-12)
    np.testing.assert_allclose(rec.q, x[:, 1:7], atol=1e-9)
    np.testing.assert_allclose(rec.tau, -x[:, 7:13], atol=1e-9)
    ident = load_recording(cfg.identification, robot)  # the identification's own sign is untouched
    np.testing.assert_allclose(ident.tau, np.loadtxt(tmp_path / "ident.csv", delimiter=",", skiprows=1)[:, 7:13], atol=1e-9)


def test_a_validation_table_with_currents_does_not_also_take_the_identifications_torques(tmp_path):
    """Its own signal kind replaces the identification's: currents there, no torques carried over beside them (which
    would be two torque channels, refused)."""
    from dynid.io.config.identification_config import with_inherited_layout

    doc = {"identification": {"file": "a.csv", "header": True, "time": {"column": "t"}, "positions": {"columns": [1]},
                              "torques": {"columns": [2]}},
           "validation": [{"file": "b.csv", "currents": {"columns": [3]}}, {"file": "c.csv", "positions": {"columns": [4]},
                                                                            "torques": {"columns": [5]}}]}
    currents, own = with_inherited_layout(doc)["validation"]
    assert currents == {"file": "b.csv", "header": True, "time": {"column": "t"}, "positions": {"columns": [1]},
                        "currents": {"columns": [3]}}
    assert own == {"file": "c.csv", "positions": {"columns": [4]}, "torques": {"columns": [5]}}  # its own layout, as given


def test_a_validation_table_with_only_a_time_range_scores_another_stretch_of_the_identification_log(tmp_path):
    """One long log split into an identification part and a validation part: ``[[validation]] name = "later",
    time_range = [...]`` was refused ("validation[0].positions: expected a 'file'"), as a ROS 2 bag's table already
    did right. It takes the identification's file and columns; with signals in files of their own (a motor-side log),
    those files."""
    from dynid.io.config.identification_config import load_identification_config, with_inherited_layout
    from dynid.io.logs.datasets import load_recording
    from dynid.model.description import load_robot

    cfg = load_identification_config(_config(tmp_path, 'name = "later"\ntime_range = [1.0, 1.5]\n'))
    rec = load_recording(cfg.validation[0], load_robot("ur10e"))
    x = np.loadtxt(tmp_path / "ident.csv", delimiter=",", skiprows=1)
    part = (x[:, 0] >= 1.0 - 1e-9) & (x[:, 0] <= 1.5 + 1e-9)
    np.testing.assert_allclose(rec.q, x[part, 1:7], atol=1e-9)
    np.testing.assert_allclose(rec.tau, x[part, 7:13], atol=1e-9)
    own = {"identification": {"header": True, "rate": 5000.0, "positions": {"file": "pos.csv", "columns": [1]},
                              "torques": {"file": "cur.csv", "columns": [1]}, "time_range": [0.0, 6.0]},
           "validation": [{"name": "end", "time_range": [6.0, 8.0]}, {"name": "other", "file": "b.csv"}]}
    end, other = with_inherited_layout(own)["validation"]
    assert end == {"header": True, "rate": 5000.0, "positions": {"file": "pos.csv", "columns": [1]},
                   "torques": {"file": "cur.csv", "columns": [1]}, "name": "end", "time_range": [6.0, 8.0]}
    assert other == {"name": "other", "file": "b.csv"}  # another file: the signals' own files are not its
    own["validation"] = [{"name": "end", "time_range": [6.0, 8.0], "currents": {"file": "i.csv", "columns": [1]}}]
    (currents,) = with_inherited_layout(own)["validation"]
    assert "torques" not in currents and currents["positions"] == {"file": "pos.csv", "columns": [1]}


def test_validate_file_reads_the_whole_other_log_not_the_identifications_time_range(tmp_path):
    """``dynid validate CONFIG --file LOG`` cut LOG to the identification's ``time_range`` (a Med7 config identified on
    0-70 s scored a 16 s log with "time_range ends at 70 s, after the recording's end"); ``rows`` were already reset."""
    from dynid.io.config.identification_config import dataset_for_file, load_identification_config
    from dynid.io.logs.datasets import load_recording
    from dynid.model.description import load_robot

    path = _config(tmp_path, 'name = "other"\nfile = "other.csv"\n')
    path.write_text(path.read_text().replace('file = "ident.csv"\n', 'file = "ident.csv"\ntime_range = [0.5, 1.0]\n', 1))
    config = load_identification_config(path)
    robot = load_robot("ur10e")
    assert load_recording(config.identification, robot).n_samples == 51  # the identification's part: 0.5-1.0 s
    rec = load_recording(dataset_for_file(config, tmp_path / "other.csv"), robot)
    assert rec.n_samples == 200 and not any("time_range" in w for w in rec.warnings)
    assert load_recording(dataset_for_file(config, tmp_path / "other.csv", rows=(11, 60)), robot).n_samples == 50
