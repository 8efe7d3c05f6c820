import re

import numpy as np
import pytest

from dynid.dynamics.kinematics import forward_kinematics
from dynid.exceptions import ConfigError
from dynid.model.description import builtin_robots, load_robot

TABLE1 = [  # alpha_{i-1}, a_{i-1}, d_i, theta offset (paper Table 1)
    (np.pi, 0.0, 0.0, 0.0), (np.pi / 2, 0.16, 0.0, -np.pi / 2), (0.0, 0.68, 0.0, 0.0),
    (np.pi / 2, 0.13, -0.75, 0.0), (-np.pi / 2, 0.0, 0.0, 0.0), (np.pi / 2, 0.0, 0.0, 0.0),
]


def modified_dh_matrix(alpha, a, d, theta):
    """Craig's modified DH transform written out as one 4x4 matrix."""
    ca, sa, ct, st = np.cos(alpha), np.sin(alpha), np.cos(theta), np.sin(theta)
    return np.array([[ct, -st, 0, a], [st * ca, ct * ca, -sa, -sa * d], [st * sa, ct * sa, ca, ca * d], [0, 0, 0, 1]])


def test_er16_geometry_is_table1(rng):
    robot = load_robot("er16")
    assert robot.n_dof == 6 and "er16" in builtin_robots()
    q = rng.uniform(-2, 2, (5, 6))
    rots, orig = forward_kinematics(robot, q)
    for k in range(5):
        t = np.eye(4)
        for j, (al, a, d, off) in enumerate(TABLE1):
            t = t @ modified_dh_matrix(al, a, d, q[k, j] + off)
            np.testing.assert_allclose(rots[k, j], t[:3, :3], atol=1e-12)
            np.testing.assert_allclose(orig[k, j], t[:3, 3], atol=1e-12)


def test_er16_assumed_values_are_documented_and_consistent():
    from dynid.model.spatial import is_physically_consistent

    robot = load_robot("er16")
    assert "assumed" in robot.notes
    assert all(is_physically_consistent(p) for p in robot.inertial)


def test_standard_dh_matches_explicit_product(tmp_path, rng):
    # UR10e standard DH table of shared/data/ur10e_mamedov2020/SOURCE.md
    rows = [(0, 0.181, "pi/2"), (-0.613, 0, 0), (-0.571, 0, 0), (0, 0.174, "pi/2"), (0, 0.120, "-pi/2"), (0, 0.117, 0)]
    text = 'name = "ur"\nconvention = "standard"\n'
    for a, d, al in rows:
        al_s = f'"{al}"' if isinstance(al, str) else al
        text += f"[[joints]]\na = {a}\nd = {d}\nalpha = {al_s}\nmass = 1.0\ncom = [0.0, 0.0, 0.0]\ninertia = [0.01, 0.01, 0.01, 0, 0, 0]\n"
    p = tmp_path / "ur.toml"
    p.write_text(text)
    robot = load_robot(p)
    q = rng.uniform(-2, 2, (3, 6))
    from dynid.dynamics.kinematics import tool_positions

    alphas = [np.pi / 2, 0, 0, np.pi / 2, -np.pi / 2, 0]
    for k in range(3):
        t = np.eye(4)
        for j, (a, d, _) in enumerate(rows):
            ct, st, ca, sa = np.cos(q[k, j]), np.sin(q[k, j]), np.cos(alphas[j]), np.sin(alphas[j])
            t = t @ np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d], [0, 0, 0, 1]])
        np.testing.assert_allclose(tool_positions(robot, q[k:k + 1])[0], t[:3, 3], atol=1e-12)


@pytest.mark.parametrize("field, value, message", [
    ("q_min", "5.0", "q_min < q_max"),
    ("mass", "-1.0", "mass"),
    ("alpha", '"half pi"', "alpha"),
    ("drive_gain", "0.0", "drive_gain"),
    ("dq_max", "-2.0", "dq_max"),
    ("com", "[0.0, 1.0]", "com"),
])
def test_bad_fields_name_file_and_field(tmp_path, field, value, message):
    base = {"alpha": "0.0", "mass": "1.0", "com": "[0.0, 0.0, 0.0]", "inertia": "[0.1, 0.1, 0.1, 0, 0, 0]",
            "q_min": "-1.0", "q_max": "1.0", "drive_gain": "2.0", "dq_max": "1.0"}
    base[field] = value
    p = tmp_path / "bad.toml"
    p.write_text("[[joints]]\n" + "\n".join(f"{k} = {v}" for k, v in base.items()) + "\n")
    with pytest.raises(ConfigError, match=message) as err:
        load_robot(p)
    assert "bad.toml" in str(err.value) and "\n" not in str(err.value)


def test_unknown_robot_and_bad_toml(tmp_path):
    with pytest.raises(ConfigError, match="unknown robot 'nosuch'"):
        load_robot("nosuch")
    # a file's name that is not there is said so (`dynid init arm.urdf log.csv` said "unknown robot 'arm.urdf':
    # expected ... a .urdf" of a missing arm.urdf)
    with pytest.raises(ConfigError, match=r"missing.urdf: no such file \(the robot: a built-in robot"):
        load_robot(tmp_path / "missing.urdf")
    p = tmp_path / "x.toml"
    p.write_text("[[joints]\n")
    with pytest.raises(ConfigError, match="invalid TOML"):
        load_robot(p)
    p.write_text('convention = "weird"\n[[joints]]\n')
    with pytest.raises(ConfigError, match="convention"):
        load_robot(p)
    p.write_text('drive_terms = ["stiction"]\n[[joints]]\n')
    with pytest.raises(ConfigError, match="stiction"):
        load_robot(p)
    p.write_text('name = "x"\n')
    with pytest.raises(ConfigError, match="joints"):
        load_robot(p)


def _one_link(tmp_path, mass, inertia, urdf=False):
    if not urdf:
        p = tmp_path / "arm.toml"
        p.write_text(f"[[joints]]\nmass = {mass}\ncom = [0.1, 0.0, 0.0]\ninertia = {inertia}\n")
        return p
    ixx, iyy, izz = inertia[:3]
    (tmp_path / "arm.urdf").write_text(f"""<?xml version="1.0"?><robot name="arm"><link name="base"/>
<link name="l1"><inertial><origin xyz="0.1 0 0"/><mass value="{mass}"/>
<inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"/></inertial></link>
<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
<limit lower="-3" upper="3" effort="10" velocity="2"/></joint></robot>""")
    p = tmp_path / "arm.toml"
    p.write_text('convention = "urdf"\nurdf = "arm.urdf"\n[[joints]]\n')
    return p


@pytest.mark.parametrize("urdf", [False, True])
@pytest.mark.parametrize("mass, inertia, rule, realisable", [
    (1.0, [1.0, 1.0, 5.0, 0, 0, 0], "triangle inequality", False),
    (1.0, [0.1, 0.1, -0.01, 0, 0, 0], "not positive definite", False),
    (0.0, [0.0, 0.0, 0.0, 0, 0, 0], "mass 0 kg is not positive", True),   # a massless link
    (1.0, [0.0, 0.0, 0.0, 0, 0, 0], "singular .*a point mass", True),     # a point mass
    (1.0, [0.0, 0.2, 0.2, 0, 0, 0], "singular .*a thin rod", True),        # a thin rod along x
])
def test_unphysical_nominal_values_are_accepted_with_a_warning_and_refused_where_used(tmp_path, urdf, mass, inertia, rule,
                                                                                      realisable):
    """The same rules for DH descriptions and URDFs: least squares does not use the nominal values, so
    the robot loads and says which link breaks which rule; where they are used (simulation truth, SDP
    prior) values that no mass distribution has are refused, degenerate but real ones pass."""
    from dynid.exceptions import ConfigError

    robot = load_robot(_one_link(tmp_path, mass, inertia, urdf))
    assert len(robot.nominal_problems) == 1 and "link 1" in robot.nominal_problems[0]
    assert re.search(rule, robot.nominal_problems[0])
    if realisable:
        robot.require_physical_nominal("the simulation truth")
    else:
        with pytest.raises(ConfigError, match=f"link 1 .*{rule}.*the simulation truth needs physically consistent"):
            robot.require_physical_nominal("the simulation truth")
    assert not load_robot("er16").nominal_problems


def test_urdf_continuous_joints_are_revolute_joints_without_limits(tmp_path, rng):
    """A URDF with continuous joints (Pinocchio's unbounded revolute joints) loads; its regressor equals
    Pinocchio's RNEA of the same file with the angles as (cos, sin)."""
    import pinocchio as pin

    from dynid.dynamics.regressor import regressor

    from ..conftest import TEST_URDF

    text = TEST_URDF.replace('name="j1" type="revolute"', 'name="j1" type="continuous"').replace(
        'name="j3" type="revolute"', 'name="j3" type="continuous"')
    (tmp_path / "c.urdf").write_text(text)
    (tmp_path / "c.toml").write_text('convention = "urdf"\nurdf = "c.urdf"\ndrive_terms = []\n' + "[[joints]]\n" * 4)
    robot = load_robot(tmp_path / "c.toml")
    model = pin.buildModelFromUrdf(str(tmp_path / "c.urdf"))
    assert model.nq == 6 and model.nv == 4  # two joints with (cos, sin)
    data = model.createData()
    q, dq, ddq = (rng.uniform(-2, 2, (10, 4)) for _ in range(3))
    for k in range(10):
        qp = np.concatenate([[np.cos(q[k, 0]), np.sin(q[k, 0])], q[k, 1:2], [np.cos(q[k, 2]), np.sin(q[k, 2])], q[k, 3:]])
        tau = pin.rnea(model, data, qp, dq[k], ddq[k])
        np.testing.assert_allclose(regressor(robot, q[k:k + 1], dq[k:k + 1], ddq[k:k + 1])[0] @ robot.standard_parameters(), tau, atol=1e-10)
