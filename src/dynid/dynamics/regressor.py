"""Joint-torque regressor ``Y(q, dq, ddq)`` with drive/friction columns, batched over samples.

``tau = Y(q, dq, ddq) @ phi`` (paper eqs. 2-4) where ``phi`` holds the standard parameters of every
joint: the ten inertial parameters of its link about the link origin (eq. 5) and its drive terms:
rotor inertia ``Ia·ddq``, Coulomb ``fc·sign(dq)`` and viscous ``fv·dq`` friction (eq. 3), offset.

Method: Newton–Euler. The wrench of link ``j`` about its origin is linear in its parameters,
``f = M a + dw×MS + w×(w×MS)``, ``n = I dw + w×(I w) + MS×a``, and joint ``i <= j`` feels
``tau_i = z·n + l·f`` with ``z`` the axis of joint ``i`` and ``l = z × (o_j - o_i)``, both in link ``j``'s
frame. All ten columns follow in closed form (:mod:`dynid.dynamics._regressor_kernel`); a compiled
kernel (numba) evaluates them for every sample, in parallel over chunks of samples, with no Python loop
per sample. Until a process has computed :data:`NUMPY_SAMPLES` samples, the same statements run in NumPy
on blocks of samples instead, with the same numbers: a short identification (the UR10e or TX40 logs of
``configs/``) then never loads numba and its LLVM (about 0.45 s and 100 MB).
"""

from __future__ import annotations

import threading

import numpy as np

from ..checks import check_states
from ..model.robot import Robot
from ..friction import drive_columns
from . import _regressor_kernel as kernel

NUMPY_SAMPLES = 60_000
"""Samples a process computes with the NumPy form before it loads the compiled kernel: NumPy takes 1.2 µs
(3 joints) to 4.8 µs (6 joints) a sample, the kernel under 1 µs after a start of about 0.45 s. The budget
holds the paper experiment's 50 500 samples and the identifications of ``configs/`` (30 000-46 000); a
computation that needs more loads the kernel, which then does everything."""

NUMPY_CALL_SAMPLES = 400
"""What one call of the NumPy form costs beyond its samples, in samples (its 3000-odd NumPy operations take
about 1.7 ms whatever the samples): many small calls, like the excitation design's, use up the budget
sooner."""

_numpy_used = 0
_numpy_lock = threading.Lock()


def regressor(robot: Robot, q, dq, ddq, columns=None) -> np.ndarray:
    """Per-sample joint-torque regressor.

    Parameters
    ----------
    robot : Robot
    q, dq, ddq : (N, n_dof) arrays
        Joint positions [rad], velocities [rad/s], accelerations [rad/s²].
    columns : (m,) int array, optional
        Only these columns, in this order (e.g. the base parameters' independent columns): the same
        values as ``regressor(...)[..., columns]`` without computing the full array and copying it.

    Returns
    -------
    Y : (N, n_dof, n_params) array, or (N, n_dof, m) with ``columns``
        ``Y[k] @ phi`` is the joint torque vector [N·m] of sample ``k``; columns follow
        ``robot.parameter_names``.

    Raises
    ------
    ShapeError
        If an input is not (N, n_dof) or holds NaN.
    """
    n = robot.n_dof
    q, dq, ddq, n_s = check_states(q, dq, ddq, n)
    colmap = np.full(robot.n_params, -1, dtype=np.int64)
    columns = np.arange(robot.n_params) if columns is None else np.asarray(columns, dtype=np.int64)
    colmap[columns] = np.arange(columns.size)
    out = np.empty((n_s, n, columns.size))
    _fill(robot, q, dq, ddq, out, colmap)
    return out


def observation_matrix(robot: Robot, q, dq, ddq) -> np.ndarray:
    """Stacked regressor ``W`` (N·n_dof, n_params); row ``k·n_dof + j`` is sample ``k``, joint ``j``."""
    y = regressor(robot, q, dq, ddq)
    return y.reshape(-1, y.shape[2])


def _fill(robot: Robot, q, dq, ddq, out, colmap) -> None:
    rp = np.ascontiguousarray([jt.rotation for jt in robot.joints], dtype=np.float64)
    pp = np.ascontiguousarray([jt.translation for jt in robot.joints], dtype=np.float64)
    axes = np.ascontiguousarray([jt.axis for jt in robot.joints], dtype=np.float64)
    gravity = np.ascontiguousarray(robot.gravity, dtype=np.float64)
    npj = robot.n_params_per_joint
    # each joint's own drive terms, from the friction table, written by the kernel with the sample's other columns
    drive = drive_columns(robot.drive_terms, dq, ddq, robot.friction_velocities) * robot.drive_mask
    drive_map = colmap[np.arange(robot.n_dof)[:, None] * npj + 10 + np.arange(drive.shape[2])]
    fill = kernel.numpy_regressor if _numpy_form(q.shape[0]) else kernel.joint_torque_regressor
    fill(rp, pp, axes, gravity, q, dq, ddq, out, npj, colmap, np.ascontiguousarray(drive), np.ascontiguousarray(drive_map))
    n_joint = robot.n_dof * npj
    if robot.n_params > n_joint:  # coupled motors (see dynid.model.transmission)
        src = np.arange(n_joint, robot.n_params)
        kept = colmap[src] >= 0
        if kept.any():
            out[:, :, colmap[src[kept]]] = robot.transmission.coupling_columns(dq, ddq)[:, :, kept]


def _numpy_form(n_samples: int) -> bool:
    """Whether these samples go through the NumPy form: the kernel is not loaded yet and the process's
    NumPy budget (:data:`NUMPY_SAMPLES`) holds them and the call (:data:`NUMPY_CALL_SAMPLES`)."""
    global _numpy_used
    if kernel.compiled():
        return False
    with _numpy_lock:
        cost = n_samples + NUMPY_CALL_SAMPLES
        if _numpy_used + cost > NUMPY_SAMPLES:
            return False
        _numpy_used += cost
        return True


def friction_torques(robot: Robot, dq: np.ndarray, ddq: np.ndarray, drive: np.ndarray | None = None,
                     coupled: np.ndarray | None = None) -> np.ndarray:
    """Torques of the drive terms alone (rotor inertia, eq. 3 friction, offset, coupled motors),
    (N, n_dof) [N·m]; ``drive`` and ``coupled`` default to the robot's nominal values."""
    drive = robot.drive if drive is None else drive
    coupled = robot.transmission.coupled_values if coupled is None else coupled
    cols = drive_columns(robot.drive_terms, dq, ddq, robot.friction_velocities)
    tau = np.einsum("njt,jt->nj", cols, drive * robot.drive_mask) if robot.drive_terms else np.zeros_like(np.asarray(dq, dtype=float))
    if robot.transmission.n_coupled_params:
        tau += robot.transmission.coupling_columns(dq, ddq) @ np.ravel(coupled)
    return tau
