import zlib

import numpy as np
import pinocchio as pin
import pytest

from dynid.dynamics.regressor import friction_torques, observation_matrix, regressor
from dynid.dynamics.rnea import rnea_torques
from dynid.exceptions import ShapeError
from dynid.model.description import load_robot, robot_from_toml_text
from dynid.model.urdf import joints_from_urdf

from ..conftest import random_states


def _check_against_rnea(robot, rng, n=64, atol=1e-9):
    q, dq, ddq = random_states(rng, n, robot.n_dof)
    y = regressor(robot, q, dq, ddq)
    assert y.shape == (n, robot.n_dof, robot.n_params)
    np.testing.assert_allclose(y @ robot.standard_parameters(), rnea_torques(robot, q, dq, ddq), atol=atol, rtol=0)


def test_er16_regressor_equals_pinocchio_rnea(rng):
    _check_against_rnea(load_robot("er16"), rng)


def test_er16_submodel_regressor_equals_rnea(rng):
    _check_against_rnea(load_robot("er16").submodel(3), rng)


def test_random_parameters_and_all_drive_terms(rng):
    """Y·φ == RNEA for random (even non-physical) parameters, with Ia, fc, fv and offset columns."""
    robot = load_robot("er16")
    from dataclasses import replace

    robot = replace(robot, drive_terms=("Ia", "fc", "fv", "offset"), drive=rng.uniform(0.1, 3, (6, 4)), drive_mask=None)
    phi = rng.normal(size=robot.n_params)
    phi[9::robot.n_params_per_joint] = rng.uniform(1.0, 5.0, robot.n_dof)  # masses away from 0 for Pinocchio's lever = h/m
    robot = robot.with_parameters(phi)
    _check_against_rnea(robot, rng)


def test_urdf_robot_against_pinocchio_parsed_directly(urdf_path, rng):
    """dynid's URDF chain (unaligned axis, rpy, merged fixed link) against Pinocchio's own URDF model."""
    toml = f'name = "t"\nconvention = "urdf"\nurdf = "{urdf_path}"\n' + "[[joints]]\nfc = 0.5\nfv = 0.2\n" * 4
    robot = robot_from_toml_text(toml, "t.toml", None)
    model = pin.buildModelFromUrdf(str(urdf_path))
    data = model.createData()
    q, dq, ddq = random_states(rng, 40, 4)
    y = regressor(robot, q, dq, ddq)
    tau_pin = np.array([pin.rnea(model, data, q[k], dq[k], ddq[k]) for k in range(40)])
    tau_pin += 0.5 * np.sign(dq) + 0.2 * dq
    np.testing.assert_allclose(y @ robot.standard_parameters(), tau_pin, atol=1e-9, rtol=0)
    joints, inertial, names, _ = joints_from_urdf(urdf_path)
    assert names == ("j1", "j2", "j3", "j4") and inertial.shape == (4, 10)


def test_observation_matrix_rows_are_sample_major(rng):
    robot = load_robot("er16").submodel(3)
    q, dq, ddq = random_states(rng, 5, 3)
    w = observation_matrix(robot, q, dq, ddq)
    y = regressor(robot, q, dq, ddq)
    np.testing.assert_array_equal(w[3 * 2 + 1], y[2, 1])


def test_friction_torques_is_eq3(rng):
    robot = load_robot("er16")
    dq = rng.normal(size=(10, 6))
    fc, fv = robot.drive[:, 0], robot.drive[:, 1]
    np.testing.assert_allclose(friction_torques(robot, dq, np.zeros_like(dq)), fc * np.sign(dq) + fv * dq)


def test_bad_shapes_are_rejected(rng):
    robot = load_robot("er16")
    q = rng.normal(size=(6, 20))
    with pytest.raises(ShapeError, match="joints-first"):
        regressor(robot, q, q, q)
    q = rng.normal(size=(20, 6))
    with pytest.raises(ShapeError, match="same number of samples"):
        regressor(robot, q, q[:10], q)
    q[3, 2] = np.nan
    with pytest.raises(ShapeError, match="sample 3"):
        regressor(robot, q, q, q)


def test_rnea_refuses_states_or_parameters_of_another_shape(rng):
    """The RNEA took any shape: a (10,)-long inertial vector raised "cannot unpack non-iterable numpy.float64" from
    inside the model's construction, and states of the wrong width went to Pinocchio."""
    robot = load_robot("er16")
    q = rng.normal(size=(20, 6))
    with pytest.raises(ShapeError, match="joints-first"):
        rnea_torques(robot, q.T, q.T, q.T)
    with pytest.raises(ShapeError, match="same number of samples"):
        rnea_torques(robot, q, q[:10], q)
    with pytest.raises(ShapeError, match=r"^inertial: expected shape \(6, 10\) \(er16's\), got \(10,\)$"):
        rnea_torques(robot, q, q, q, inertial=robot.inertial[0])
    with pytest.raises(ShapeError, match=r"^drive: expected shape"):
        rnea_torques(robot, q, q, q, drive=robot.drive[:3])
    np.testing.assert_array_equal(rnea_torques(robot, q, q, q, inertial=robot.inertial), rnea_torques(robot, q, q, q))


@pytest.mark.parametrize("name", ["er16", "ur10e", "tx40"])
def test_selected_columns_are_the_same_numbers_as_the_full_regressor(name):
    from dynid.dynamics.base_parameters import base_parameters
    from dynid.model.description import load_robot as _load

    robot = _load(name)
    rng = np.random.default_rng(3)
    q, dq, ddq = (rng.uniform(-2, 2, (300, robot.n_dof)) for _ in range(3))
    full = regressor(robot, q, dq, ddq)
    cols = base_parameters(robot, rng=0).independent
    np.testing.assert_array_equal(regressor(robot, q, dq, ddq, columns=cols), full[..., cols])
    some = np.array([robot.n_params - 1, 3, 0])  # any order, drive and coupled columns included
    np.testing.assert_array_equal(regressor(robot, q, dq, ddq, columns=some), full[..., some])
    held = np.full((300, robot.n_dof, cols.size), np.nan)  # a buffer given is written over and returned
    assert regressor(robot, q, dq, ddq, columns=cols, out=held) is held
    np.testing.assert_array_equal(held, full[..., cols])
    for bad in (np.empty((300, robot.n_dof, cols.size + 1)), np.empty((300, robot.n_dof, cols.size), dtype=np.float32),
                np.empty((cols.size, robot.n_dof, 300)).T):
        with pytest.raises(ShapeError, match="out: expected a C-contiguous float64 array"):
            regressor(robot, q, dq, ddq, columns=cols, out=bad)


@pytest.mark.parametrize("name", ["er16", "ur10e", "tx40"])
def test_the_numpy_form_gives_the_compiled_kernels_numbers(name, monkeypatch):
    """The arithmetic is written once and run two ways: compiled per sample (numba, on two threads here) and by
    NumPy on blocks of samples. Both give the same numbers bit for bit, and equal Pinocchio's RNEA."""
    import dynid.dynamics.regressor as module

    robot = load_robot(name)
    q, dq, ddq = random_states(np.random.default_rng(5), 5000, robot.n_dof)  # several NumPy blocks
    some = np.arange(robot.n_params - 1, -1, -3)
    forms = {}
    for numpy in (True, False):
        monkeypatch.setattr(module, "_numpy_form", lambda n, numpy=numpy: numpy)
        forms[numpy] = regressor(robot, q, dq, ddq), regressor(robot, q, dq, ddq, columns=some)
    np.testing.assert_array_equal(forms[True][0], forms[False][0])
    np.testing.assert_array_equal(forms[True][1], forms[False][1])
    np.testing.assert_allclose(forms[True][0][:500] @ robot.standard_parameters(), rnea_torques(robot, q[:500], dq[:500], ddq[:500]),
                               atol=1e-9, rtol=0)


SHORT_RUN = """
import sys
import numpy as np
from dynid.dynamics import regressor as module
from dynid.identification.run import run_identification
from dynid.io.config.identification_config import load_identification_config
from dynid.model.description import load_robot
run_identification(load_identification_config(sys.argv[1], data_root=sys.argv[2]))
assert "numba" not in sys.modules, "numba loaded"
module.NUMPY_SAMPLES = 0
z = np.zeros((1, 6))
module.regressor(load_robot("er16"), z, z, z)
assert module._simd["used"], "the compiled regressor did not take over"
assert "numba" not in sys.modules, "numba loaded for the compiled regressor"
"""


def test_a_short_identification_never_loads_numba():
    """An identification of the TX40 log never imports numba and its LLVM: where it computes the regressor past the
    NumPy form's budget, or from the start where it will (:func:`dynid.dynamics.regressor.expect_samples`; 93,801
    samples counted at stop 112), the compiled regressor is the robot's SIMD code, built by llvmlite alone."""
    import subprocess
    import sys
    from pathlib import Path

    from ..conftest import shared_data

    root = shared_data("staubli_tx40_figaroh")
    config = Path(__file__).resolve().parents[2] / "configs" / "tx40-full.toml"
    out = subprocess.run([sys.executable, "-c", SHORT_RUN, str(config), str(root)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]


def test_the_numpy_budget_counts_samples_and_calls(monkeypatch):
    """A process's NumPy budget: each call costs its samples plus a call's fixed cost; past the budget, or once
    a compiled regressor has run, the compiled one computes."""
    import dynid.dynamics.regressor as module

    monkeypatch.setattr(module, "_numpy_used", 0)
    monkeypatch.setattr(module, "NUMPY_SAMPLES", 1000)
    monkeypatch.setattr(module, "NUMPY_CALL_SAMPLES", 400)
    monkeypatch.setattr(module.kernel, "compiled", lambda: False)
    monkeypatch.setattr(module, "_simd", {"used": False, "failed": False})
    assert [module._numpy_form(100) for _ in range(3)] == [True, True, False]
    monkeypatch.setattr(module, "_numpy_used", 0)
    assert not module._numpy_form(601)
    assert module._numpy_form(1)
    monkeypatch.setattr(module, "_simd", {"used": True, "failed": False})  # once the SIMD code has run
    assert not module._numpy_form(1)
    monkeypatch.setattr(module, "_simd", {"used": False, "failed": False})
    monkeypatch.setattr(module.kernel, "compiled", lambda: True)  # or numba's kernel is loaded
    assert not module._numpy_form(1)
    # a process that says it will compute more than the budget goes compiled at once; a smaller one keeps the budget
    monkeypatch.setattr(module.kernel, "compiled", lambda: False)
    monkeypatch.setattr(module, "_numpy_used", 0)
    module.expect_samples(1000)
    assert module._numpy_form(1)
    module.expect_samples(1001)
    assert not module._numpy_form(1)


@pytest.mark.parametrize("name", ["er16", "ur10e", "tx40"])
def test_the_robots_simd_code_gives_the_other_forms_numbers(name, monkeypatch):
    """The robot's SIMD code (sample_columns traced, its constants folded, four samples a vector), the NumPy
    form and numba's kernel: the same numbers bit for bit, for full and selected columns, a number of samples
    that is not a multiple of the lanes, and on one thread as on two."""
    import dynid.dynamics.regressor as module
    from dynid.dynamics import _regressor_simd

    robot = load_robot(name)
    q, dq, ddq = random_states(np.random.default_rng(7), 9003, robot.n_dof)  # two threads, and a padded tail
    for columns in (np.arange(robot.n_params), np.arange(robot.n_params - 1, -1, -3)):
        colmap = np.full(robot.n_params, -1)
        colmap[columns] = np.arange(columns.size)
        forms = {}
        for form in ("numpy", "compiled", "numba"):
            forms[form] = np.full((q.shape[0], robot.n_dof, columns.size), np.nan)
            monkeypatch.setattr(module, "_simd", {"used": False, "failed": False})
            module._fill(robot, q, dq, ddq, forms[form], colmap, form=form)
            assert module._simd["used"] == (form == "compiled")  # the SIMD code ran, not numba's kernel
        monkeypatch.setattr(_regressor_simd, "PARALLEL_SAMPLES", 10**9)
        forms["one thread"] = np.full_like(forms["numpy"], np.nan)
        module._fill(robot, q, dq, ddq, forms["one thread"], colmap, form="compiled")
        monkeypatch.undo()
        for form, y in forms.items():
            np.testing.assert_array_equal(y, forms["numpy"], err_msg=form)


SIMD_CACHE = """
import numpy as np, sys
from dynid.dynamics import regressor as module
from dynid.model.description import load_robot
module.NUMPY_SAMPLES = 0
q = np.random.default_rng(1).uniform(-2, 2, (50, 3))
np.save(sys.argv[1], module.regressor(load_robot("er16").submodel(3), q, q, q))
"""


def test_the_simd_code_is_cached_on_disk_and_loaded_from_there(tmp_path):
    """The first process compiles the robot's SIMD code into $XDG_CACHE_HOME/dynid; the next one loads it."""
    import os
    import subprocess
    import sys

    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "cache")}
    for run in ("first", "second"):
        out = subprocess.run([sys.executable, "-c", SIMD_CACHE, str(tmp_path / f"{run}.npy")], env=env, capture_output=True,
                             text=True, timeout=300)
        assert out.returncode == 0, out.stderr[-2000:]
        cached = list((tmp_path / "cache" / "dynid").glob("regressor-*.o"))
        assert len(cached) == 1 and cached[0].stat().st_size > 1000
        (traced,) = (tmp_path / "cache" / "dynid").glob("regressor-ir-*.ll.z")  # the traced IR, kept beside it
        assert b"define void @kernel" in zlib.decompress(traced.read_bytes()[:-32])  # less its checksum
        if run == "first":
            stamp, ir_stamp = cached[0].stat().st_mtime_ns, traced.stat().st_mtime_ns
    assert cached[0].stat().st_mtime_ns == stamp and traced.stat().st_mtime_ns == ir_stamp  # loaded, not written again
    np.testing.assert_array_equal(np.load(tmp_path / "first.npy"), np.load(tmp_path / "second.npy"))
    cached[0].write_bytes(cached[0].read_bytes()[:-100])  # cut short (a full disk, say): ignored, compiled again
    out = subprocess.run([sys.executable, "-c", SIMD_CACHE, str(tmp_path / "third.npy")], env=env, capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert cached[0].stat().st_mtime_ns != stamp  # written again, whole
    np.testing.assert_array_equal(np.load(tmp_path / "first.npy"), np.load(tmp_path / "third.npy"))
    traced.write_bytes(traced.read_bytes()[:-100])  # the IR cut short too: traced again, the same numbers
    out = subprocess.run([sys.executable, "-c", SIMD_CACHE, str(tmp_path / "fourth.npy")], env=env, capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert traced.stat().st_mtime_ns != ir_stamp and b"define void @kernel" in zlib.decompress(traced.read_bytes()[:-32])
    np.testing.assert_array_equal(np.load(tmp_path / "first.npy"), np.load(tmp_path / "fourth.npy"))


def test_without_its_source_the_simd_code_is_traced_each_time_with_the_same_numbers(tmp_path, monkeypatch):
    """The traced IR is cached under a hash of the tracing's source; where that source cannot be read (an install
    without the .py files), the IR is not cached, the machine code still is, and the numbers are the same."""
    from dynid.dynamics import _regressor_simd as simd
    from dynid.dynamics import regressor as module
    from dynid.model.description import load_robot

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setattr(module, "NUMPY_SAMPLES", 0)
    robot = load_robot("er16").submodel(3)
    q = np.random.default_rng(2).uniform(-2, 2, (40, 3))
    found, source = {}, simd._source_digest
    for readable in (False, True):
        monkeypatch.setattr(simd, "_kernels", {})  # a fresh process's kernels
        monkeypatch.setattr(simd, "_source_digest", source if readable else (lambda: None))
        found[readable] = module.regressor(robot, q, q, q)
        traced = list((tmp_path / "dynid").glob("regressor-ir-*.ll.z"))
        assert len(traced) == int(readable) and list((tmp_path / "dynid").glob("regressor-*.o"))
    np.testing.assert_array_equal(found[False], found[True])
