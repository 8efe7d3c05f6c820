"""ROS bags of sensor_msgs/JointState as datasets (ROS 2, and ROS 1 .bag files): a bag written here, read back through a config."""

import numpy as np
import pytest

from dynid.exceptions import ConfigError, DataError
from dynid.io.logs.datasets import dataset_spec, load_recording
from dynid.model.description import load_robot


def _write_bag(path, t, names, q, dq, effort, topic="/joint_states", storage="sqlite3"):
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    JointState, Header, Time = ts.types["sensor_msgs/msg/JointState"], ts.types["std_msgs/msg/Header"], ts.types["builtin_interfaces/msg/Time"]
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    with Writer(path, version=8, storage_plugin=plugin) as writer:
        conn = writer.add_connection(topic, JointState.__msgtype__, typestore=ts)
        for k, tk in enumerate(t):
            stamp = Time(sec=int(tk), nanosec=int(round((tk - int(tk)) * 1e9)))
            row = lambda x: np.ascontiguousarray(x[k], dtype=np.float64).copy()  # noqa: E731
            msg = JointState(header=Header(stamp=stamp, frame_id=""), name=list(names), position=row(q), velocity=row(dq), effort=row(effort))
            writer.write(conn, int(tk * 1e9), ts.serialize_cdr(msg, JointState.__msgtype__))


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_bag_of_joint_states_reads_like_a_log(tmp_path, rng, storage):
    """Both rosbag2 storages (MCAP: the default since ROS 2 Iron)."""
    robot = load_robot("ur10e")
    names = [j.name for j in robot.joints]
    t = 100.0 + np.arange(200) * 0.008  # 125 Hz
    q = np.outer(np.sin(t), np.arange(1, 7) * 0.1)
    dq = np.outer(np.cos(t), np.arange(1, 7) * 0.1)
    tau = rng.normal(0, 1, (200, 6))
    order = [3, 0, 5, 1, 4, 2]  # the bag lists the joints in another order
    _write_bag(tmp_path / "bag", t, [names[i] for i in order], q[:, order], dq[:, order], tau[:, order], storage=storage)
    assert any(p.suffix == (".mcap" if storage == "mcap" else ".db3") for p in (tmp_path / "bag").iterdir())
    rec = load_recording(dataset_spec({"bag": "bag"}, tmp_path, "cfg: identification", "ident", 6), robot)
    assert rec.n_samples == 200 and rec.rate == pytest.approx(125.0)
    np.testing.assert_allclose(rec.q, q + robot.transmission.position_offset, atol=1e-12)
    np.testing.assert_allclose(rec.dq, dq, atol=1e-12)
    np.testing.assert_allclose(rec.tau, tau, atol=1e-12)
    currents = load_recording(dataset_spec({"bag": "bag", "effort": "currents"}, tmp_path, "cfg", "ident", 6), robot)
    np.testing.assert_allclose(currents.tau, tau * robot.drive_gains, atol=1e-12)


def test_bag_errors_name_the_bag_topic_and_joint(tmp_path):
    robot = load_robot("ur10e")
    t = np.arange(5) * 0.01
    moving = 0.01 * np.outer(np.arange(5), np.ones(6))
    _write_bag(tmp_path / "bag", t, ["a", "b", "c", "d", "e", "f"], moving, np.zeros((5, 6)), np.zeros((5, 6)))
    with pytest.raises(DataError, match=r"bag: message 1 on /joint_states lacks joint\(s\) shoulder_pan_joint"):
        load_recording(dataset_spec({"bag": "bag"}, tmp_path, "cfg", "ident", 6), robot)
    with pytest.raises(DataError, match=r"no topic '/other' in the bag \(it has /joint_states\)"):
        load_recording(dataset_spec({"bag": "bag", "topic": "/other"}, tmp_path, "cfg", "ident", 6), robot)
    with pytest.raises(DataError, match=r"nosuch: ROS bag not found"):
        load_recording(dataset_spec({"bag": "nosuch"}, tmp_path, "cfg", "ident", 6), robot)
    with pytest.raises(ConfigError, match=r"cfg.joint_names: expected 6 joint names"):
        dataset_spec({"bag": "bag", "joint_names": ["a"]}, tmp_path, "cfg", "ident", 6)
    names = dataset_spec({"bag": "bag", "joint_names": list("abcdef")}, tmp_path, "cfg", "ident", 6)
    assert load_recording(names, robot).n_samples == 5


def test_a_bag_with_missing_efforts_is_filled_as_a_log_is(tmp_path):
    """A driver that publishes NaN for an effort it has not read yet, and NaN velocities: the efforts are filled by
    interpolation in time as a log's empty fields are (were refused: "NaN or infinite torques"), the velocities derived
    from the positions; a long hole is refused naming the message."""
    robot = load_robot("ur10e")
    names = [j.name for j in robot.joints]
    t = 100.0 + np.arange(200) * 0.008
    q = np.outer(np.sin(t), np.arange(1, 7) * 0.1)
    tau = np.outer(1.0 + t - t[0], np.arange(1, 7))  # linear: interpolation gives it back exactly
    effort = tau.copy()
    effort[[0, 1, 50, 51, 52], 2] = np.nan
    _write_bag(tmp_path / "bag", t, names, q, np.full_like(q, np.nan), effort)
    rec = load_recording(dataset_spec({"bag": "bag"}, tmp_path, "cfg", "ident", 6), robot)
    assert rec.dq is None and rec.n_samples == 198  # the first two messages, before J3's effort, dropped
    np.testing.assert_allclose(rec.tau, tau[2:], atol=1e-9)
    assert any("3 missing value(s) (empty or NaN fields) in torques of joint 3" in w for w in rec.warnings)
    assert any("message 1 on /joint_states has NaN or infinite velocities: the bag's velocities are left out" in w
               for w in rec.warnings)
    effort[60:100, 4] = np.nan
    _write_bag(tmp_path / "hole", t, names, q, np.zeros_like(q), effort)
    with pytest.raises(DataError, match=r"hole: message 61 on /joint_states: joint 5's torques are missing for 40 rows"):
        load_recording(dataset_spec({"bag": "hole"}, tmp_path, "cfg", "ident", 6), robot)


def test_a_validation_table_of_a_bag_config_inherits_the_bags_reader_settings(tmp_path):
    """issue "Nothing runs, nothing silent": a [[validation]] bag table inherited neither ``bag`` nor ``joint_names``
    (a table with only ``time_range`` was refused, one naming another bag read it with the default joint order)."""
    from dynid.io.config.identification_config import with_inherited_layout

    names = list("abcdef")
    doc = {"identification": {"bag": "ident", "topic": "/arm/joint_states", "joint_names": names, "effort": "currents",
                              "time_range": [0.0, 10.0]},
           "validation": [{"time_range": [10.0, 20.0]}, {"bag": "other"}, {"bag": "third", "joint_names": names[::-1]},
                          {"file": "log.csv", "positions": {"columns": [1, 2, 3, 4, 5, 6]}}]}
    same, other, own, csv = with_inherited_layout(doc)["validation"]
    assert same == {"bag": "ident", "topic": "/arm/joint_states", "joint_names": names, "effort": "currents",
                    "time_range": [10.0, 20.0]}
    assert other == {"bag": "other", "topic": "/arm/joint_states", "joint_names": names, "effort": "currents"}
    assert own["joint_names"] == names[::-1] and own["bag"] == "third"
    assert csv == {"file": "log.csv", "positions": {"columns": [1, 2, 3, 4, 5, 6]}}


def test_validate_file_reads_the_file_it_is_given_with_the_configs_reader(tmp_path):
    """``dynid validate CONFIG --file LOG`` on a bag config scored the identification bag and labelled it LOG, even
    for a LOG that did not exist; a CSV config's --file lost its time unit (milliseconds read as seconds)."""
    from dynid.exceptions import DataError
    from dynid.io.config.identification_config import dataset_for_file, load_identification_config

    names = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]
    t = np.arange(50) * 0.01
    for bag in ("ident", "other"):
        _write_bag(tmp_path / bag, t, names, np.zeros((50, 6)), np.zeros((50, 6)), np.zeros((50, 6)))
    (tmp_path / "bag.toml").write_text('robot = "ur10e"\n[identification]\nbag = "ident"\ntopic = "/joint_states"\n')
    cfg = load_identification_config(tmp_path / "bag.toml")
    spec = dataset_for_file(cfg, tmp_path / "other")
    assert spec.bag.path == tmp_path / "other" and spec.name == "other" and spec.bag.topic == cfg.identification.bag.topic
    for given, message in ((tmp_path / "nope", "no such file or bag"), (tmp_path / "bag.toml", "expected a bag's folder")):
        with pytest.raises(DataError, match=message):
            dataset_for_file(cfg, given)
    np.savetxt(tmp_path / "log.csv", np.zeros((5, 13)), delimiter=",", comments="",
               header=",".join(["ms", *(f"q{j}" for j in range(1, 7)), *(f"tau{j}" for j in range(1, 7))]))
    (tmp_path / "csv.toml").write_text('robot = "ur10e"\n[identification]\nfile = "log.csv"\nheader = true\n'
                                       'time = { column = "ms", unit = "ms" }\n'
                                       f'positions = {{ columns = {[f"q{j}" for j in range(1, 7)]} }}\n'.replace("'", '"')
                                       + f'torques = {{ columns = {[f"tau{j}" for j in range(1, 7)]} }}\n'.replace("'", '"'))
    cfg = load_identification_config(tmp_path / "csv.toml")
    spec = dataset_for_file(cfg, tmp_path / "log.csv")
    assert spec.time.scale == cfg.identification.time.scale == 1e-3
    with pytest.raises(DataError, match="a ROS bag, but the config's logs are CSV files"):
        dataset_for_file(cfg, tmp_path / "other")


def test_a_bag_without_message_definitions_is_read_with_humbles_types(tmp_path, rng):
    """A rosbag2 of ROS 2 Humble or earlier holds no message definitions: it was refused with the reading library's
    own advice ("Instantiate AnyReader with a default_typestore argument"); it is read with ROS 2 Humble's standard
    types, and said."""
    import sqlite3

    robot = load_robot("ur10e")
    names = [j.name for j in robot.joints]
    t = np.arange(60) * 0.01
    q = 0.1 * rng.normal(size=(60, 6))
    tau = rng.normal(size=(60, 6))
    _write_bag(tmp_path / "humble", t, names, q, np.zeros((60, 6)), tau)
    db = next((tmp_path / "humble").glob("*.db3"))
    with sqlite3.connect(db) as con:  # what a Humble recording lacks
        con.execute("delete from message_definitions")
    spec = dataset_spec({"bag": "humble"}, tmp_path, "cfg", "ident", 6)
    rec = load_recording(spec, robot)
    np.testing.assert_allclose(rec.q, q, atol=1e-12)
    assert any("holds no message definitions" in w and "ROS 2 Humble's standard types" in w for w in rec.warnings)


def _write_ros1_bag(path, t, names, q, dq, effort, topic="/joint_states"):
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC)
    JointState, Header, Time = ts.types["sensor_msgs/msg/JointState"], ts.types["std_msgs/msg/Header"], ts.types["builtin_interfaces/msg/Time"]
    with Writer(path) as writer:
        conn = writer.add_connection(topic, JointState.__msgtype__, typestore=ts)
        for k, tk in enumerate(t):
            stamp = Time(sec=int(tk), nanosec=int(round((tk - int(tk)) * 1e9)))
            row = lambda x: np.ascontiguousarray(x[k], dtype=np.float64).copy()  # noqa: E731
            msg = JointState(header=Header(seq=k, stamp=stamp, frame_id=""), name=list(names), position=row(q),
                             velocity=row(dq), effort=row(effort))
            writer.write(conn, int(tk * 1e9), ts.serialize_ros1(msg, JointState.__msgtype__))


def test_a_ros1_bag_reads_like_a_ros2_bag_and_init_takes_it(tmp_path, rng):
    """A ROS 1 .bag of JointState messages (rosbags reads ROS 1 too): read by bag = "run.bag" as the same numbers as a
    ROS 2 bag of the same messages; dynid init took the .bag for a CSV ("not a UTF-8 text table (a binary file?)")."""
    from tests.cli.refusals import dynid as run

    robot = load_robot("ur10e")
    names = [j.name for j in robot.joints]
    t = 100.0 + np.arange(200) * 0.008
    q = np.outer(np.sin(t), np.arange(1, 7) * 0.1)
    dq = np.outer(np.cos(t), np.arange(1, 7) * 0.1)
    tau = rng.normal(0, 1, (200, 6))
    _write_ros1_bag(tmp_path / "run.bag", t, names, q, dq, tau)
    _write_bag(tmp_path / "ros2", t, names, q, dq, tau)
    one, two = (load_recording(dataset_spec({"bag": b}, tmp_path, "cfg: identification", "ident", 6), robot)
                for b in ("run.bag", "ros2"))
    for signal in ("t", "q", "dq", "tau"):
        np.testing.assert_array_equal(getattr(one, signal), getattr(two, signal))
    p = run("init", "ur10e", tmp_path / "run.bag", "--out", tmp_path / "arm.toml")
    assert p.returncode == 0, p.stderr
    assert "run.bag: a ROS 1 bag" in p.stdout and 'bag = "run.bag"' in (tmp_path / "arm.toml").read_text()
