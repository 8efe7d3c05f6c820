"""Columns that name the robot description's joints in another order than its chain's (a ROS driver's alphabetical
JointState order) are refused with the order that reads them right, before anything is fitted."""

import json
import re

import pytest

from dynid.io.logs.columns import named_out_of_order

from ..cli.refusals import dynid, snapshot

UR = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint")


def test_the_joint_each_column_names_is_found_only_where_they_name_every_joint_out_of_order():
    """The alphabetical order of the UR joints gives J3, J2, J1, J4, J5, J6; the chain's order, numbers, a column that
    names no joint, a joint named twice or too few columns give None; the longest joint name wins (joint_1, joint_10)."""
    alphabetical = sorted(UR)
    assert named_out_of_order([f"{n}_position" for n in alphabetical], UR) == [2, 1, 0, 3, 4, 5]
    assert named_out_of_order([f"/joint_states/{n}/effort" for n in alphabetical], UR) == [2, 1, 0, 3, 4, 5]
    assert named_out_of_order([f"{n}_position" for n in UR], UR) is None
    assert named_out_of_order([3, 2, 1, 4, 5, 6], UR) is None
    assert named_out_of_order(["q1"] + [f"{n}_position" for n in alphabetical[1:]], UR) is None
    assert named_out_of_order([f"{n}_position" for n in alphabetical[:2] + alphabetical[:1] + alphabetical[3:]], UR) is None
    assert named_out_of_order([f"{n}_position" for n in alphabetical[:5]], UR) is None
    ten = tuple(f"joint_{k}" for k in range(1, 11))
    order = [f"joint_{k}_pos" for k in (10, 2, 3, 4, 5, 6, 7, 8, 9, 1)]
    assert named_out_of_order(order, ten) == [9, 1, 2, 3, 4, 5, 6, 7, 8, 0]


@pytest.mark.parametrize("signal", ["positions", "torques"])
def test_a_config_listing_the_joints_alphabetically_is_refused_with_the_chains_order(tmp_path, signal):
    """``dynid example ur10e``'s config with one signal's columns in alphabetical order (J1's and J3's swapped): dynid
    fitted it, called the model ready and wrote it. It is refused in one line naming the table, the signal and the
    order to write, and writes nothing; written in that order, the config identifies at the noise floor again."""
    assert dynid("example", "ur10e", tmp_path / "try", "-q").returncode == 0
    folder = tmp_path / "try"
    config = folder / "ur10e.toml"
    kind = {"positions": "position", "torques": "effort"}[signal]
    right = ", ".join(f'"{n}_{kind}"' for n in UR)
    text = config.read_text()
    assert right in text
    config.write_text(text.replace(right, ", ".join(f'"{n}_{kind}"' for n in sorted(UR))))
    p = dynid("identify", config, "--out", tmp_path / "out", "--no-figures", "-q")
    assert p.returncode != 0
    said = (p.stdout + p.stderr).strip()
    assert len(said.splitlines()) == 1 and "Traceback" not in said
    assert said.startswith(f"error: [identification]: the {signal}' columns name the robot description's joints")
    assert "elbow_joint_" in said and "J3's" in said
    assert re.search(rf"{signal} = {{ columns = \[{re.escape(right)}\] }}", said), said
    assert snapshot(tmp_path / "out") is None
    config.write_text(text)
    p = dynid("identify", config, "--out", tmp_path / "out", "--no-figures")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    assert results["readiness"].startswith("model ready")
