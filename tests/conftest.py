import os
from pathlib import Path

import numpy as np
import pytest

os.environ.setdefault("MPLBACKEND", "Agg")

TEST_URDF = """<?xml version="1.0"?>
<robot name="testarm">
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="0.01 0.02 0.1" rpy="0.1 0 0.2"/><mass value="4.0"/>
    <inertia ixx="0.05" ixy="0.001" ixz="0.002" iyy="0.04" iyz="0.003" izz="0.03"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0.2 0.0 0.03" rpy="0 0.3 0"/><mass value="3.0"/>
    <inertia ixx="0.01" ixy="0.0" ixz="0.0" iyy="0.08" iyz="0.0" izz="0.08"/></inertial></link>
  <link name="l2b"><inertial><origin xyz="0.05 0.01 0.0" rpy="0 0 0"/><mass value="0.7"/>
    <inertia ixx="0.002" ixy="0.0" ixz="0.0" iyy="0.002" iyz="0.0" izz="0.002"/></inertial></link>
  <link name="l3"><inertial><origin xyz="0.1 0.02 -0.01" rpy="0 0 0"/><mass value="1.5"/>
    <inertia ixx="0.004" ixy="0.0002" ixz="0.0" iyy="0.02" iyz="0.0" izz="0.02"/></inertial></link>
  <link name="l4"><inertial><origin xyz="0.0 0.0 0.05" rpy="0 0 0"/><mass value="0.5"/>
    <inertia ixx="0.001" ixy="0.0" ixz="0.0" iyy="0.001" iyz="0.0" izz="0.0005"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.3" rpy="0 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="100" velocity="3"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.05 0 0.1" rpy="1.5707963 0.2 0"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="100" velocity="3"/></joint>
  <joint name="fixed" type="fixed"><parent link="l2"/><child link="l2b"/><origin xyz="0.3 0 0" rpy="0 0 0.4"/></joint>
  <joint name="j3" type="revolute"><parent link="l2b"/><child link="l3"/><origin xyz="0.1 0.02 0" rpy="0 0 0.3"/>
    <axis xyz="0 0.6 0.8"/><limit lower="-3" upper="3" effort="100" velocity="3"/></joint>
  <joint name="j4" type="revolute"><parent link="l3"/><child link="l4"/><origin xyz="0.25 0 0" rpy="0 1.5707963 0"/>
    <axis xyz="1 0 0"/><limit lower="-3" upper="3" effort="100" velocity="3"/></joint>
</robot>
"""


REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def shipped_identification():
    """``shipped_identification(name, validate=True)``: :func:`dynid.run_identification` of ``configs/<name>.toml`` on
    its real data (``shared/data``), run once for the whole test run (once per test worker) and read by every test that
    checks that identification, with one BLAS thread as the stored digests are computed. Each call gives a deep copy, so
    that no test sees another's changes; skipped, with the reason, where the data are absent."""
    import copy

    from threadpoolctl import threadpool_limits

    from dynid.identification.run import run_identification
    from dynid.io.config.identification_config import load_identification_config

    from .digests import data_root

    done: dict = {}

    def identified(name: str, *, validate: bool = True):
        if (name, validate) not in done:
            path = REPO / "configs" / f"{name}.toml"
            root = data_root(path)
            if root is None:
                pytest.skip(f"data of {path.name} not found (set DYNID_SHARED_DATA to the shared/data folder)")
            with threadpool_limits(1):
                done[name, validate] = run_identification(load_identification_config(path, data_root=root),
                                                          validate=validate)
        return copy.deepcopy(done[name, validate])

    return identified


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


@pytest.fixture
def urdf_path(tmp_path):
    p = tmp_path / "testarm.urdf"
    p.write_text(TEST_URDF)
    return p


def random_states(rng, n_samples, n_dof, scale=2.0):
    return tuple(rng.uniform(-scale, scale, (n_samples, n_dof)) for _ in range(3))


def shared_data(name: str):
    """Folder of a real data set in the workplace's shared/data (``DYNID_SHARED_DATA`` overrides).

    These data sets are not part of the repository (the UR10e one has no license). The CI machine has
    them; elsewhere the tests that need them are skipped, with the reason.
    """

    roots = [os.environ.get("DYNID_SHARED_DATA"), Path(__file__).resolve().parents[2] / "shared" / "data", "/work/shared/data"]
    for root in roots:
        if root and (Path(root) / name).is_dir():
            return Path(root) / name
    pytest.skip(f"real data set {name} not found (set DYNID_SHARED_DATA to the shared/data folder)")


def sine_motion(rng, t, n_dof, n_harmonics=4, omega=2 * np.pi * 0.2, amplitude=0.4):
    """A smooth multi-sine joint motion with exact derivatives: q, dq, ddq (N, n_dof)."""
    a = rng.uniform(-1, 1, (n_harmonics, n_dof)) * amplitude / np.arange(1, n_harmonics + 1)[:, None]
    phase = rng.uniform(0, 2 * np.pi, (n_harmonics, n_dof))
    k = np.arange(1, n_harmonics + 1)[:, None, None] * omega
    arg = k * t[None, :, None] + phase[:, None, :]
    q = (a[:, None, :] * np.sin(arg)).sum(0)
    dq = (a[:, None, :] * k * np.cos(arg)).sum(0)
    ddq = -(a[:, None, :] * k**2 * np.sin(arg)).sum(0)
    return q, dq, ddq


def without_wall_times(obj):
    """A results dictionary without its ``seconds`` entries (wall times), to compare two runs' results."""
    if isinstance(obj, dict):
        return {k: without_wall_times(v) for k, v in obj.items() if k != "seconds"}
    if isinstance(obj, list):
        return [without_wall_times(v) for v in obj]
    return obj
