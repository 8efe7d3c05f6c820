"""A xacro robot description, expanded by dynid without ROS: the same robot as the URDF it stands for."""

from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from dynid.exceptions import ConfigError
from dynid.model.description import load_robot

URDF = Path(str(resources.files("dynid.model") / "robots" / "ur10e.urdf"))


def _xacro_of_ur10e(folder: Path, tool_mass: str = "${tool_mass}") -> Path:
    """The shipped UR10e URDF as a xacro file: a property for the last link's mass, a macro for the base's inertia
    block, the rest included unchanged."""
    text = URDF.read_text(encoding="utf-8")
    text = text.replace('<robot name="ur10e" xmlns:xacro="http://ros.org/wiki/xacro">',
                        '<robot name="ur10e" xmlns:xacro="http://ros.org/wiki/xacro">\n'
                        '  <xacro:property name="tool_mass" value="${0.2 + 0.002}"/>\n'
                        '  <xacro:macro name="mass_of" params="value"><mass value="${value}"/></xacro:macro>')
    assert text.count('<mass value="0.202"/>') == 1
    text = text.replace('<mass value="0.202"/>', f'<xacro:mass_of value="{tool_mass}"/>')
    path = folder / "ur10e.urdf.xacro"
    path.write_text(text, encoding="utf-8")
    return path


def test_a_xacro_description_is_the_robot_of_its_urdf(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    from_xacro, from_urdf = load_robot(_xacro_of_ur10e(tmp_path)), load_robot(URDF)
    assert from_xacro.name == "ur10e" and from_xacro.n_dof == from_urdf.n_dof == 6
    np.testing.assert_allclose(from_xacro.inertial, from_urdf.inertial, rtol=1e-12, atol=1e-15)
    for a, b in zip(from_xacro.joints, from_urdf.joints):
        np.testing.assert_allclose(a.rotation, b.rotation, atol=1e-12)
        np.testing.assert_allclose(a.translation, b.translation, atol=1e-12)
    np.testing.assert_allclose(from_xacro.limits.dq_max, from_urdf.limits.dq_max)
    cached = list((tmp_path / "cache" / "dynid" / "xacro").glob("*/*.urdf"))
    assert [p.name for p in cached] == ["ur10e.urdf"]  # expanded once, into the cache, under the robot's name
    load_robot(tmp_path / "ur10e.urdf.xacro")
    assert list((tmp_path / "cache" / "dynid" / "xacro").glob("*/*.urdf")) == cached  # and reused


def test_a_config_names_a_xacro_robot_and_export_writes_into_its_expansion(tmp_path, monkeypatch):
    from dynid.io.config.configs import config_robot, config_urdf

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    _xacro_of_ur10e(tmp_path)
    doc = {"robot": "ur10e.urdf.xacro"}
    robot = config_robot(doc, tmp_path / "c.toml")
    assert robot.n_dof == 6
    urdf = config_urdf(doc, tmp_path / "c.toml")
    assert urdf is not None and urdf.name == "ur10e.urdf"  # identify and export write the identified URDF by this name
    assert "<mass value=\"0.202\"/>" in urdf.read_text().replace("  ", "")


def test_a_xacro_that_cannot_be_expanded_is_refused_in_one_line(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    bad = _xacro_of_ur10e(tmp_path, "${undefined_property}")
    with pytest.raises(ConfigError, match=r"ur10e.urdf.xacro: xacro cannot expand it: .*undefined_property") as info:
        load_robot(bad)
    assert "\n" not in str(info.value)
    (tmp_path / "ros.urdf.xacro").write_text('<robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">'
                                             '<xacro:include filename="$(find ur_description)/urdf/ur.xacro"/></robot>')
    with pytest.raises(ConfigError, match=r"ros.urdf.xacro: xacro cannot expand it: \$\(find ur_description\) names a "
                                          "ROS package dynid cannot find .*ROS_PACKAGE_PATH") as info:
        load_robot(tmp_path / "ros.urdf.xacro")
    assert "\n" not in str(info.value)


def test_an_unwritable_cache_falls_back_to_the_temporary_folder(tmp_path, monkeypatch):
    (tmp_path / "not-a-folder").write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "not-a-folder"))
    assert load_robot(_xacro_of_ur10e(tmp_path)).n_dof == 6


def test_init_holds_a_xacro_grippers_fingers(tmp_path, monkeypatch):
    """dynid init on a xacro file whose arm carries two prismatic fingers (one a mimic): the fingers are held, as for
    a URDF, and the config it writes names the xacro file."""
    import tomllib

    from tests.cli.refusals import dynid as run

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    fingers = "".join(
        f'<link name="{n}_link"><inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" '
        f'izz="1e-4"/></inertial></link><joint name="{n}" type="prismatic"><parent link="wrist_3_link"/>'
        f'<child link="{n}_link"/><axis xyz="0 1 0"/><limit lower="0" upper="0.04" effort="20" velocity="0.2"/>{m}'
        '</joint>' for n, m in (("f1", ""), ("f2", '<mimic joint="f1"/>')))
    path = _xacro_of_ur10e(tmp_path)
    path.write_text(path.read_text(encoding="utf-8").replace("</robot>", fingers + "</robot>"), encoding="utf-8")
    sim = np.column_stack([np.arange(200) * 0.01, np.zeros((200, 12))])
    np.savetxt(tmp_path / "log.csv", sim, delimiter=",", comments="",
               header=",".join(["t", *(f"q{j}" for j in range(1, 7)), *(f"tau{j}" for j in range(1, 7))]))
    p = run("init", str(path), str(tmp_path / "log.csv"), "--out", str(tmp_path / "arm.toml"),
            env={"XDG_CACHE_HOME": str(tmp_path / "cache")})
    assert p.returncode == 0, p.stderr
    robot = tomllib.loads((tmp_path / "arm.toml").read_text())["robot"]
    assert robot["urdf"] == "ur10e.urdf.xacro" and robot["held"] == ["f1", "f2"]


def test_xacro_arguments_reach_the_expansion_from_a_config_and_the_api(tmp_path, monkeypatch):
    """``xacro_args`` in a ``[robot]`` table (and ``load_robot(..., xacro_args=)``) are the file's ``name:=value``: the
    robot and the URDF export writes into are the expansion with them; given for a file that is not xacro, refused."""
    from dynid.io.config.configs import config_robot, config_urdf

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    path = _xacro_of_ur10e(tmp_path, "$(arg tool_mass)")
    path.write_text(path.read_text(encoding="utf-8").replace(
        '<xacro:property name="tool_mass"', '<xacro:arg name="tool_mass" default="0.202"/>\n  <xacro:property name="x"'),
        encoding="utf-8")
    masses = {}
    for given in (None, {"tool_mass": "0.5"}, {"tool_mass": 0.5}):  # a TOML number is its text
        doc = {"robot": {"urdf": path.name, **({"xacro_args": given} if given else {})}}
        masses[str(given)] = (config_robot(doc, tmp_path / "c.toml").inertial[-1, 9],
                              load_robot(path, xacro_args=given).inertial[-1, 9])
        urdf = config_urdf(doc, tmp_path / "c.toml").read_text()
        assert f'<mass value="{(given or {}).get("tool_mass", "0.202")}"/>' in urdf.replace("  ", "")
    assert masses["None"] == pytest.approx((0.202, 0.202))
    assert masses["{'tool_mass': '0.5'}"] == masses["{'tool_mass': 0.5}"] == pytest.approx((0.5, 0.5))
    with pytest.raises(ConfigError, match=r"xacro arguments \['tool_mass'\] given, but ur10e.urdf is not a xacro file"):
        load_robot(URDF, xacro_args={"tool_mass": "0.5"})
    with pytest.raises(ConfigError, match=r"robot: xacro_args are a xacro file's arguments, but this description reads no "
                                          "robot file"):
        config_robot({"robot": {"joints": [{"a": 0.0, "alpha": 0.0, "d": 0.0, "mass": 1.0,
                                            "com": [0, 0, 0], "inertia": [1, 1, 1, 0, 0, 0]}],
                                "xacro_args": {"a": "1"}}}, tmp_path / "c.toml")


def test_init_writes_the_xacro_arguments_it_was_given(tmp_path, monkeypatch):
    """``dynid init arm.urdf.xacro LOG --xacro-arg tool_mass:=0.5``: the config's ``[robot]`` table holds the argument
    (with the URDF's drive terms), identify's robot is the expansion with it; a malformed one is one line."""
    import tomllib

    from dynid.io.config.configs import config_robot
    from tests.cli.refusals import dynid as run

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    path = _xacro_of_ur10e(tmp_path, "$(arg tool_mass)")
    path.write_text(path.read_text(encoding="utf-8").replace(
        '<xacro:property name="tool_mass"', '<xacro:arg name="tool_mass" default="0.202"/>\n  <xacro:property name="x"'),
        encoding="utf-8")
    sim = np.column_stack([np.arange(200) * 0.01, np.zeros((200, 12))])
    np.savetxt(tmp_path / "log.csv", sim, delimiter=",", comments="",
               header=",".join(["t", *(f"q{j}" for j in range(1, 7)), *(f"tau{j}" for j in range(1, 7))]))
    env = {"XDG_CACHE_HOME": str(tmp_path / "cache")}
    p = run("init", str(path), str(tmp_path / "log.csv"), "--out", str(tmp_path / "arm.toml"), "--xacro-arg",
            "tool_mass:=0.5", env=env)
    assert p.returncode == 0, p.stderr
    doc = tomllib.loads((tmp_path / "arm.toml").read_text())
    assert doc["robot"]["urdf"] == "ur10e.urdf.xacro" and doc["robot"]["xacro_args"] == {"tool_mass": "0.5"}
    assert config_robot(doc, tmp_path / "arm.toml").inertial[-1, 9] == pytest.approx(0.5)
    p = run("init", str(path), str(tmp_path / "log.csv"), "--out", str(tmp_path / "b.toml"), "--xacro-arg", "0.5",
            env=env)
    assert p.returncode != 0 and p.stderr.strip().splitlines() == [
        "error: --xacro-arg 0.5: expected name:=value (a xacro argument's name, then its value)"]
    assert not (tmp_path / "b.toml").exists()
