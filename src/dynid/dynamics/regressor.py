"""Joint-torque regressor ``Y(q, dq, ddq)`` with drive/friction columns, batched over samples.

``tau = Y(q, dq, ddq) @ phi`` (paper eqs. 2-4) where ``phi`` holds the standard parameters of every
joint: the ten inertial parameters of its link about the link origin (eq. 5) and its drive terms:
rotor inertia ``Ia·ddq``, Coulomb ``fc·sign(dq)`` and viscous ``fv·dq`` friction (eq. 3), offset.

Method: Newton–Euler. The wrench of link ``j`` about its origin is linear in its parameters,
``f = M a + dw×MS + w×(w×MS)``, ``n = I dw + w×(I w) + MS×a``, and joint ``i <= j`` feels
``tau_i = z·n + l·f`` with ``z`` the axis of joint ``i`` and ``l = z × (o_j - o_i)``, both in link ``j``'s
frame. All ten columns follow in closed form, written once (:mod:`dynid.dynamics._regressor_kernel`) and
run three ways with the same numbers:

* until a process has computed :data:`NUMPY_SAMPLES` samples, by NumPy on blocks of samples (no start-up
  cost: a short identification, like the UR10e or TX40 logs of ``configs/``, compiles nothing);
* then by the robot's own compiled code (:mod:`dynid.dynamics._regressor_simd`): the statements traced
  once, the robot's constants folded in, four samples per SIMD vector, on the cores in parallel; compiled by
  llvmlite in about 0.5 s and cached on disk;
* where that code cannot be built, by numba's kernel, one sample after another.
"""

from __future__ import annotations

import threading
from dataclasses import replace
from pathlib import Path

import numpy as np

from .._util.checks import check_states
from .._util.keywords import keyword_only_after_data
from ..exceptions import ShapeError
from ..friction import TERMS, Velocities
from ..model.loading import as_robot
from ..model.robot import Robot
from . import _regressor_kernel as kernel
from . import _regressor_simd

NUMPY_SAMPLES = 60_000
"""Samples a process computes with the NumPy form before the compiled regressor takes over: NumPy takes
1.2 µs (3 joints) to 4.8 µs (6 joints) a sample, the compiled code 0.5 µs after loading it (0.015 s from the
cache, 0.5 s compiled). The budget holds the paper experiment's 50 500 samples and the identifications of
``configs/`` (30 000-46 000); a computation that needs more loads the compiled code, which then does
everything."""

NUMPY_CALL_SAMPLES = 400
"""What one call of the NumPy form costs beyond its samples, in samples (its 3000-odd NumPy operations take
about 1.7 ms whatever the samples): many small calls, like the excitation design's, use up the budget
sooner."""

_numpy_used = 0
_numpy_lock = threading.Lock()


@keyword_only_after_data
def regressor(robot: Robot | str | Path, q, dq, ddq, *, columns=None, velocities=None,
              out: np.ndarray | None = None) -> np.ndarray:
    """Per-sample joint-torque regressor.

    Parameters
    ----------
    robot : Robot, str or Path
        A built-in robot's name or a description's path is loaded (:func:`dynid.model.loading.as_robot`).
    q, dq, ddq : (N, n_dof) arrays
        Joint positions [rad], velocities [rad/s], accelerations [rad/s²].
    columns : (m,) int array, optional
        Only these columns, in this order (e.g. the base parameters' independent columns): the same
        values as ``regressor(...)[..., columns]`` without computing the full array and copying it.
    velocities : dynid.friction.Velocities, optional
        The friction columns' velocities (default ``robot.friction_velocities``; a log's rest velocity and held
        direction of motion are properties of the log, :func:`dynid.friction.held_direction`); a direction has
        the samples' rows (N, n_dof).
    out : (N, n_dof, n_params) or (N, n_dof, m) C-contiguous float64 array, optional
        Written and returned instead of a new array (a loop over a long log's chunks keeps one, so that the memory
        of each chunk is not handed back to the system and cleared again).

    Returns
    -------
    Y : (N, n_dof, n_params) array, or (N, n_dof, m) with ``columns``
        ``Y[k] @ phi`` is the joint torque vector [N·m] of sample ``k``; columns follow
        ``robot.parameter_names``. A joint that follows another (:attr:`dynid.model.robot.Joint.mimic`) moves as that
        joint says, whatever its columns of ``q, dq, ddq`` hold, and its row is folded into that joint's
        (:meth:`dynid.model.robot.Robot.fold`): the rows of the robot's coordinates, its own row zero.

    Raises
    ------
    ShapeError
        If an input is not (N, n_dof) or holds NaN, or ``out`` is not a C-contiguous float64 array of that shape.
    """
    robot = as_robot(robot)
    n = robot.n_dof
    q, dq, ddq, n_s = check_states(q, dq, ddq, n)
    colmap = np.full(robot.n_params, -1, dtype=np.int64)
    columns = np.arange(robot.n_params) if columns is None else np.asarray(columns, dtype=np.int64)
    colmap[columns] = np.arange(columns.size)
    if out is None:
        out = np.empty((n_s, n, columns.size))
    elif out.shape != (n_s, n, columns.size) or out.dtype != np.float64 or not out.flags.c_contiguous:
        raise ShapeError(f"out: expected a C-contiguous float64 array of shape {(n_s, n, columns.size)}, "
                         f"got {out.dtype} {out.shape}")
    q, dq, ddq = robot.coupled(q, dq, ddq)
    _fill(robot, q, dq, ddq, out, colmap, velocities=velocities)
    return robot.fold(out)


def observation_matrix(robot: Robot, q, dq, ddq) -> np.ndarray:
    """Stacked regressor (observation matrix) ``W``, eq. 7.

    Parameters
    ----------
    robot : Robot
    q, dq, ddq : (N, n_dof) arrays
        [rad], [rad/s], [rad/s²].

    Returns
    -------
    (N·n_dof, n_params) ndarray
        Row ``k·n_dof + j`` is sample ``k``, joint ``j``.
    """
    y = regressor(robot, q, dq, ddq)
    return y.reshape(-1, y.shape[2])


def compile_kernels(robots) -> None:
    """Compile, or load from their caches, the compiled regressors (the install step's warm-up).

    numba's kernel (where the SIMD code cannot be built) and each robot's SIMD code (:mod:`dynid.warm_up`).

    Parameters
    ----------
    robots : iterable of Robot
    """
    def run(robot, form):
        z = np.zeros((8, robot.n_dof))
        _fill(robot, z, z, z, np.empty((8, robot.n_dof, robot.n_params)), np.arange(robot.n_params), form=form)

    run(robots[0], "numba")  # one robot is enough: numba's kernel is the same code for every robot
    for robot in robots:
        run(robot, "compiled")


def _fill(robot: Robot, q, dq, ddq, out, colmap, *, form: str | None = None, velocities=None) -> None:
    """Fill ``out`` by the NumPy form, the compiled regressor, or numba's kernel (``form``: "numpy",
    "compiled", "numba"; by default the NumPy form while the process's budget lasts, then the compiled one)."""
    rp = np.ascontiguousarray([jt.rotation for jt in robot.joints], dtype=np.float64)
    pp = np.ascontiguousarray([jt.translation for jt in robot.joints], dtype=np.float64)
    axes = np.ascontiguousarray([jt.axis for jt in robot.joints], dtype=np.float64)
    gravity = np.ascontiguousarray(robot.gravity, dtype=np.float64)
    npj = robot.n_params_per_joint
    v = robot.friction_velocities if velocities is None else velocities
    if "fcl" in robot.drive_terms and v.load is None:
        v = replace(v, load=nominal_rigid_torque(robot, q, dq, ddq))

    def drive(a, b):
        """Each joint's own drive terms (friction table) for samples a:b, written by the kernel with the sample's
        other columns; the terms are elementwise, so any split gives the same numbers."""
        return np.ascontiguousarray(drive_columns(robot.drive_terms, q[a:b], dq[a:b], ddq[a:b], v.rows(a, b)) * robot.drive_mask)

    drive_map = np.ascontiguousarray(colmap[np.arange(robot.n_dof)[:, None] * npj + 10 + np.arange(len(robot.drive_terms))])
    arrays = kernel.RobotArrays(rp, pp, axes, gravity, npj, colmap, drive_map, robot.prismatic.astype(np.float64),
                                robot.parents)
    form = form or ("numpy" if _numpy_form(q.shape[0]) else "compiled")
    if form == "compiled":
        _compiled_regressor(arrays, (q, dq, ddq), out, drive)
    elif form == "numpy":
        kernel.numpy_regressor(arrays, (q, dq, ddq), out, drive)
    else:
        kernel.joint_torque_regressor(arrays, (q, dq, ddq), out, drive(0, q.shape[0]))
    n_joint = robot.n_dof * npj
    if robot.n_params > n_joint:  # coupled motors (see dynid.model.transmission)
        src = np.arange(n_joint, robot.n_params)
        kept = colmap[src] >= 0
        if kept.any():
            out[:, :, colmap[src[kept]]] = robot.transmission.coupling_columns(dq, ddq)[:, :, kept]


_simd = {"used": False, "failed": False}


def _compiled_regressor(arrays, motion, out, drive) -> None:
    """The compiled regressor: the robot's own SIMD code (:mod:`dynid.dynamics._regressor_simd`), or numba's
    kernel where that code cannot be built (no LLVM for this platform). Both give the NumPy form's numbers.
    ``arrays`` is the robot's :class:`~dynid.dynamics._regressor_kernel.RobotArrays`, ``motion`` ``(q, dq, ddq)``,
    and ``drive(a, b)`` gives the drive columns of samples ``a:b``."""
    if not _simd["failed"]:
        try:
            _regressor_simd.simd_regressor(arrays, motion, out, drive)
            _simd["used"] = True
            return
        except Exception:  # noqa: BLE001 - llvmlite cannot build it here: numba's kernel computes the same numbers
            _simd["failed"] = True
    kernel.joint_torque_regressor(arrays, motion, out, drive(0, motion[0].shape[0]))


def expect_samples(n_samples: int) -> None:
    """Say that this process will compute the regressor at ``n_samples`` samples (a log's, which the parallel filter
    reads at every sample): beyond the NumPy form's budget (:data:`NUMPY_SAMPLES`) the compiled regressor takes over
    at once, instead of after the budget is spent in the slower NumPy form. The same numbers either way.

    Parameters
    ----------
    n_samples : int
    """
    global _numpy_used
    if n_samples > NUMPY_SAMPLES:
        with _numpy_lock:
            _numpy_used = max(_numpy_used, NUMPY_SAMPLES)


def _numpy_form(n_samples: int) -> bool:
    """Whether these samples go through the NumPy form: no compiled regressor has run in this process yet and
    its NumPy budget (:data:`NUMPY_SAMPLES`) holds them and the call (:data:`NUMPY_CALL_SAMPLES`)."""
    global _numpy_used
    if kernel.compiled() or _simd["used"]:
        return False
    with _numpy_lock:
        cost = n_samples + NUMPY_CALL_SAMPLES
        if _numpy_used + cost > NUMPY_SAMPLES:
            return False
        _numpy_used += cost
        return True


def drive_columns(terms, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray, velocities: Velocities) -> np.ndarray:
    """Columns of the drive terms for every joint (eqs. 3-6 of the paper's friction model).

    Parameters
    ----------
    terms : sequence of str
        Drive term names (:data:`dynid.friction.TERMS`).
    q, dq, ddq : (N, n_dof) arrays
        [rad], [rad/s], [rad/s²].
    velocities : dynid.friction.Velocities

    Returns
    -------
    (N, n_dof, len(terms)) ndarray
        Column of each term for each joint and sample.
    """
    q, dq, ddq = (np.asarray(x, dtype=float) for x in (q, dq, ddq))
    if not terms:
        return np.zeros(dq.shape + (0,))
    return np.stack([TERMS[t].column(q, dq, ddq, velocities) for t in terms], axis=-1)


def nominal_rigid_torque(robot: Robot, q, dq, ddq) -> np.ndarray:
    """Rigid-body torques of the robot's nominal inertial parameters (no drive terms).

    The torque each transmission carries, for the load-dependent Coulomb term (:mod:`dynid.friction`).

    Parameters
    ----------
    robot : Robot
    q, dq, ddq : (N, n_dof) arrays
        [rad], [rad/s], [rad/s²].

    Returns
    -------
    (N, n_dof) ndarray [N·m]
    """
    rigid = replace(robot, drive_terms=(), drive=np.zeros((robot.n_dof, 0)), drive_mask=np.ones((robot.n_dof, 0), dtype=bool))
    return regressor(rigid, q, dq, ddq) @ rigid.standard_parameters()


def friction_torques(robot: Robot, dq: np.ndarray, ddq: np.ndarray, drive: np.ndarray | None = None,
                     coupled: np.ndarray | None = None, q: np.ndarray | None = None) -> np.ndarray:
    """Torques of the drive terms alone (rotor inertia, eq. 3 friction, offset, coupled motors).

    Parameters
    ----------
    robot : Robot
    dq, ddq : (N, n_dof) arrays
        [rad/s], [rad/s²].
    drive : (n_dof, n_drive) array, optional
        Drive parameters per joint (the robot's nominal ones by default).
    coupled : array, optional
        Coupled motors' rotor inertias (the robot's by default).
    q : (N, n_dof) array, optional
        [rad], for the terms that depend on the position (zeros by default).

    Returns
    -------
    (N, n_dof) ndarray [N·m]
    """
    drive = robot.drive if drive is None else drive
    coupled = robot.transmission.coupled_values if coupled is None else coupled
    q = np.zeros_like(np.asarray(dq, dtype=float)) if q is None else q
    v = robot.friction_velocities
    if "fcl" in robot.drive_terms:
        v = replace(v, load=nominal_rigid_torque(robot, q, dq, ddq))
    cols = drive_columns(robot.drive_terms, q, dq, ddq, v)
    tau = np.einsum("njt,jt->nj", cols, drive * robot.drive_mask) if robot.drive_terms else np.zeros_like(np.asarray(dq, dtype=float))
    if robot.transmission.n_coupled_params:
        tau += robot.transmission.coupling_columns(dq, ddq) @ np.ravel(coupled)
    return tau
