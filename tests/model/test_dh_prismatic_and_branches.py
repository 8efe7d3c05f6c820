"""DH tables with prismatic joints and branches (issue "Every arm a user has", items 1 and 3): a SCARA written as a
modified or standard DH table, and a torso with two arms in Khalil-Kleinfinger's notation. The truth is the DH
formula itself (each row's matrix product, written here), and Pinocchio's reading of the URDF dynid writes."""

import numpy as np
import pinocchio as pin
import pytest

from dynid.dynamics.kinematics import forward_kinematics
from dynid.dynamics.regressor import _fill
from dynid.exceptions import ConfigError
from dynid.model.description import load_robot
from dynid.model.description_files import urdf_from_robot

INERTIAL = 'mass = {m}\ncom = [0.05, 0.01, -0.02]\ninertia = [0.02, 0.03, 0.025, 0.001, 0.0, 0.002]\n'


def _toml(convention: str, rows: list[dict]) -> str:
    head = f'name = "dh_{convention}"\nconvention = "{convention}"\n'
    body = ""
    for k, row in enumerate(rows):
        body += "[[joints]]\n" + "".join(f"{key} = {value!r}\n".replace("'", '"') for key, value in row.items())
        body += INERTIAL.format(m=4.0 - 0.5 * k)
    return head + body


SCARA = [  # alpha, a, d, theta_offset, type: two turning arms, a quill sliding down, a turning tool
    {"name": "j1", "d": 0.4, "q_min": -2.5, "q_max": 2.5},
    {"name": "j2", "a": 0.4, "theta_offset": 0.3, "q_min": -2.5, "q_max": 2.5},
    {"name": "quill", "type": "prismatic", "alpha": "pi", "a": 0.35, "d": 0.1, "q_min": 0.0, "q_max": 0.3},
    {"name": "j4", "d": 0.05, "theta_offset": -0.2, "q_min": -3.0, "q_max": 3.0},
]

TREE = [  # a torso turning, a left arm (two joints, the second sliding) and a right arm (two joints), Khalil-Kleinfinger
    {"name": "torso", "d": 0.8},
    {"name": "l1", "parent": "torso", "gamma": "pi/2", "b": 0.3, "alpha": "-pi/2", "a": 0.1, "d": 0.05},
    {"name": "l2", "type": "prismatic", "alpha": "pi/2", "a": 0.3, "d": 0.1, "q_min": -0.1, "q_max": 0.2},
    {"name": "r1", "parent": "torso", "gamma": "-pi/2", "b": 0.3, "alpha": "pi/2", "a": 0.1, "theta_offset": 0.4},
    {"name": "r2", "alpha": "-pi/2", "a": 0.25, "d": -0.02},
]


def _angle(v) -> float:
    return {"pi": np.pi, "pi/2": np.pi / 2, "-pi/2": -np.pi / 2}.get(v, v) if isinstance(v, str) else float(v)


def _h(rot=None, trans=(0.0, 0.0, 0.0)):
    out = np.eye(4)
    if rot is not None:
        out[:3, :3] = rot
    out[:3, 3] = trans
    return out


def _rx(a):
    c, s = np.cos(a), np.sin(a)
    return _h(np.array([[1, 0, 0], [0, c, -s], [0, s, c]]))


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    return _h(np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]))


def _tx(x):
    return _h(trans=(x, 0.0, 0.0))


def _tz(z):
    return _h(trans=(0.0, 0.0, z))


def _variables(row, q):
    """theta and d of a row at joint position q: q adds to theta (revolute) or to d (prismatic)."""
    theta, d = _angle(row.get("theta_offset", 0.0)), float(row.get("d", 0.0))
    return (theta, d + q) if row.get("type") == "prismatic" else (theta + q, d)


def _modified_frames(rows, q):
    """Each joint's frame: T_a(j) RotZ(gamma) TransZ(b) RotX(alpha) TransX(a) RotZ(theta) TransZ(d)."""
    frames, names = [], [r["name"] for r in rows]
    for j, row in enumerate(rows):
        parent = row.get("parent")
        before = np.eye(4) if parent == "base" or (parent is None and j == 0) else \
            frames[names.index(parent) if parent else j - 1]
        theta, d = _variables(row, q[j])
        frames.append(before @ _rz(_angle(row.get("gamma", 0.0))) @ _tz(row.get("b", 0.0))
                      @ _rx(_angle(row.get("alpha", 0.0))) @ _tx(row.get("a", 0.0)) @ _rz(theta) @ _tz(d))
    return frames


def _standard_frames(rows, q):
    """DH frames 1..n: the product of RotZ(theta) TransZ(d) TransX(a) RotX(alpha)."""
    frames, t = [], np.eye(4)
    for j, row in enumerate(rows):
        theta, d = _variables(row, q[j])
        t = t @ _rz(theta) @ _tz(d) @ _tx(row.get("a", 0.0)) @ _rx(_angle(row.get("alpha", 0.0)))
        frames.append(t)
    return frames


def _robot(tmp_path, convention, rows):
    path = tmp_path / f"{convention}.toml"
    path.write_text(_toml(convention, rows))
    return load_robot(path)


def _positions(robot, rng, n):
    lo, hi = robot.limits.position_span()
    return rng.uniform(np.maximum(lo, -3.0), np.minimum(hi, 3.0), (n, robot.n_dof))


@pytest.mark.parametrize("rows", [SCARA, TREE], ids=["scara", "tree"])
def test_modified_dh_link_frames_are_the_formulas(tmp_path, rng, rows):
    robot = _robot(tmp_path, "modified", rows)
    assert robot.prismatic.tolist() == [r.get("type") == "prismatic" for r in rows]
    q = _positions(robot, rng, 30)
    rots, origins = forward_kinematics(robot, q)
    for k in range(q.shape[0]):
        for j, frame in enumerate(_modified_frames(rows, q[k])):
            np.testing.assert_allclose(rots[k, j], frame[:3, :3], atol=1e-12)
            np.testing.assert_allclose(origins[k, j], frame[:3, 3], atol=1e-12)


def test_a_tables_branches_are_the_robots_tree(tmp_path):
    robot = _robot(tmp_path, "modified", TREE)
    assert robot.is_tree and robot.parents.tolist() == [-1, 0, 1, 0, 3]
    assert not _robot(tmp_path, "modified", SCARA).is_tree


def test_standard_dh_frames_and_flange_are_the_formulas(tmp_path, rng):
    """A standard-DH SCARA: dynid's link frame i carried by the fixed part of row i is DH frame i, and the flange is
    DH frame n, with the quill's d moving."""
    from dynid.model.dh import standard_dh_link_offset

    robot = _robot(tmp_path, "standard", SCARA)
    assert robot.prismatic.tolist() == [False, False, True, False]
    q = _positions(robot, rng, 30)
    rots, origins = forward_kinematics(robot, q)
    for k in range(q.shape[0]):
        for j, frame in enumerate(_standard_frames(SCARA, q[k])):
            row = SCARA[j]
            r, p = standard_dh_link_offset(_angle(row.get("alpha", 0.0)), row.get("a", 0.0), row.get("d", 0.0))
            np.testing.assert_allclose(rots[k, j] @ r, frame[:3, :3], atol=1e-12)
            np.testing.assert_allclose(origins[k, j] + rots[k, j] @ p, frame[:3, 3], atol=1e-12)
        np.testing.assert_allclose(origins[k, -1] + rots[k, -1] @ robot.tool_translation, frame[:3, 3], atol=1e-12)


@pytest.mark.parametrize(("convention", "rows"), [("modified", SCARA), ("standard", SCARA), ("modified", TREE)],
                         ids=["modified-scara", "standard-scara", "modified-tree"])
def test_the_regressor_of_a_dh_table_equals_pinocchios_of_its_urdf(tmp_path, rng, convention, rows):
    """The URDF dynid writes of the table, read by Pinocchio: its joint frames are the DH formulas' (so the file holds
    the geometry), its regressor and RNEA equal dynid's on 200 random states to 1e-10 (a slide feels force along z)."""
    robot = _robot(tmp_path, convention, rows)
    model = pin.buildModelFromXML(urdf_from_robot(robot))
    data = model.createData()
    q = _positions(robot, rng, 200)
    dq, ddq = rng.normal(size=q.shape), 3 * rng.normal(size=q.shape)
    if convention == "modified":
        for k in range(5):
            pin.forwardKinematics(model, data, q[k])
            for j, frame in enumerate(_modified_frames(rows, q[k])):
                np.testing.assert_allclose(data.oMi[j + 1].homogeneous, frame, atol=1e-12)
    y = np.empty((200, robot.n_dof, robot.n_params))
    _fill(robot, q, dq, ddq, y, np.arange(robot.n_params), form="numpy")
    tau = np.array([pin.rnea(model, data, q[k], dq[k], ddq[k]) for k in range(200)])
    npj = robot.n_params_per_joint
    rigid = y[..., [c for c in range(robot.n_params) if c % npj < 10]] @ robot.inertial.ravel()
    assert np.abs(rigid - tau).max() < 1e-10 * np.sqrt(np.mean(tau ** 2))


@pytest.mark.parametrize(("convention", "row", "expected"), [
    ("modified", {"parent": "r9"}, "joints[1].parent: expected \"base\" or the name of a joint before it (j1), got 'r9'"),
    ("modified", {"parent": "j2"}, "joints[1].parent: expected \"base\" or the name of a joint before it (j1)"),
    ("standard", {"parent": "j1"}, "joints[1]: parent given, but a branch is placed in modified DH only"),
    ("modified", {"type": "spherical"}, "joints[1].type"),
    ("modified", {"name": "j1"}, "joints[1].name: 'j1' names joints[0] too: expected each joint's own name"),
])
def test_a_wrong_joint_type_or_parent_is_one_line_naming_the_field(tmp_path, convention, row, expected):
    rows = [SCARA[0], {**SCARA[1], **row}]
    with pytest.raises(ConfigError) as err:
        _robot(tmp_path, convention, rows)
    assert expected in str(err.value) and "\n" not in str(err.value)
