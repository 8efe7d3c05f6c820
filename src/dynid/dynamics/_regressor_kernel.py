"""The batched joint-torque regressor's arithmetic (see :mod:`dynid.dynamics.regressor`), written once and
executed two ways.

:func:`sample_columns` holds the arithmetic for sample ``k``: forward Newton–Euler recursion in link
frames, then for every link ``j`` and joint ``i <= j`` the ten closed-form columns ``tau_i = z·n_j + l·f_j``.

* Compiled: :func:`joint_torque_regressor` compiles it with numba on first use (numba is imported only
  then; the machine code comes from numba's on-disk cache after the first time) and calls it for one
  sample after another, ``k`` an integer and every quantity a float. Samples are split into contiguous
  ranges run side by side in threads (the compiled loop releases the GIL); no allocation per sample. A
  serial kernel loads from numba's cache in a fraction of the time a ``parallel=True`` one takes.
* NumPy: :func:`numpy_regressor` runs the same statements in the interpreter with ``k = slice(None)`` on
  a block of samples, each quantity then a vector of the block's samples and the scratch arrays with a
  trailing sample axis. The operations and their order are the same, so both give the same numbers
  (a test compares them bit for bit); it spares a short computation numba's start-up.
"""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor
from typing import NamedTuple

import numpy as np

from ..runtime.threads import cores


class RobotArrays(NamedTuple):
    """What the kernel reads of a robot: each joint's fixed rotation ``rp`` (n, 3, 3) and translation ``pp`` (n, 3)
    from its parent's frame, its axis ``axes`` (n, 3), ``gravity`` (3,) [m/s²], the standard parameters per joint
    ``npj``, where each standard column goes (``colmap`` (n_params,), skipped where negative), where each joint's
    drive columns go (``drive_map`` (n, T), skipped where negative), which joints slide (``prismatic`` (n,): 1.0
    for a prismatic joint, 0.0 for a revolute one) and which joint carries each (``parent`` (n,) int, -1: the base;
    ``j - 1`` along a serial chain)."""

    rp: np.ndarray
    pp: np.ndarray
    axes: np.ndarray
    gravity: np.ndarray
    npj: int
    colmap: np.ndarray
    drive_map: np.ndarray
    prismatic: np.ndarray
    parent: np.ndarray


def sample_columns(k, robot, motion, out, drive, scratch):
    """Fill ``out[k]`` (n, m): column ``colmap[c]`` holds standard column ``c`` of the ten inertial columns of
    each link (skipped where ``colmap[c] < 0``), column ``drive_map[i, t]`` of joint ``i`` its drive column
    ``drive[k, i, t]`` (skipped where ``drive_map[i, t] < 0``); the other columns hold 0.

    A revolute joint ``i`` feels ``z·n_j + l·f_j`` of each link ``j`` it carries (``j`` itself and every link after
    it along a serial chain; on a robot with branches, the links of its own branch); a prismatic one, the force along
    its axis, ``z·f_j``. A prismatic joint's link does not turn with ``q``: its origin moves by ``q`` along the axis,
    and its origin's acceleration gains ``ddq·z + 2 w × (dq·z)`` (Khalil & Dombre, *Modeling, Identification and
    Control of Robots*, §9.3).

    Parameters
    ----------
    k : int or slice
        The sample (compiled) or ``slice(None)``: every sample of ``q`` at once (NumPy).
    robot : RobotArrays
    motion : tuple of (N, n) arrays
        ``q, dq, ddq`` [rad, rad/s, rad/s²; m, m/s, m/s² for a prismatic joint].
    out : (N, n, m) array
    drive : (N, n, T) array
        Each joint's own drive columns (rotor inertia, friction, offset: :mod:`dynid.friction`), written here
        while the sample's row is in the cache.
    scratch : tuple of arrays
        ``r0, o, w, dw, acc, z0, rl``: (n, 3, 3), (n, 3) ×5, (3, 3), each with a trailing sample axis when ``k`` is
        a slice.
    """
    rp, pp, axes, gravity, npj, colmap, drive_map, prismatic, parent = robot
    q, dq, ddq = motion
    r0, o, w, dw, acc, z0, rl = scratch
    n = q.shape[1]
    m = out.shape[2]
    # ---- zero every entry first (links joint i does not carry stay zero), then each joint's drive columns
    for i in range(n):
        for c in range(m):
            out[k, i, c] = 0.0
        for t in range(drive_map.shape[1]):
            dst = drive_map[i, t]
            if dst >= 0:
                out[k, i, dst] = drive[k, i, t]
    # ---- forward recursion -------------------------------------------------------------
    for j in range(n):
        ax0, ax1, ax2 = axes[j, 0], axes[j, 1], axes[j, 2]
        if prismatic[j] > 0.0:  # the link slides along the axis: rl = rp_j, its origin moves by q
            for a in range(3):
                for b in range(3):
                    rl[a, b] = rp[j, a, b]
            qj = q[k, j]
            px = pp[j, 0] + qj * (rp[j, 0, 0] * ax0 + rp[j, 0, 1] * ax1 + rp[j, 0, 2] * ax2)
            py = pp[j, 1] + qj * (rp[j, 1, 0] * ax0 + rp[j, 1, 1] * ax1 + rp[j, 1, 2] * ax2)
            pz = pp[j, 2] + qj * (rp[j, 2, 0] * ax0 + rp[j, 2, 1] * ax1 + rp[j, 2, 2] * ax2)
        else:
            c = np.cos(q[k, j])
            s = np.sin(q[k, j])
            v = 1.0 - c
            # Rodrigues rotation about the joint axis
            m00 = c + v * ax0 * ax0
            m01 = v * ax0 * ax1 - s * ax2
            m02 = v * ax0 * ax2 + s * ax1
            m10 = v * ax0 * ax1 + s * ax2
            m11 = c + v * ax1 * ax1
            m12 = v * ax1 * ax2 - s * ax0
            m20 = v * ax0 * ax2 - s * ax1
            m21 = v * ax1 * ax2 + s * ax0
            m22 = c + v * ax2 * ax2
            for a in range(3):  # rl = rp_j @ rot
                rl[a, 0] = rp[j, a, 0] * m00 + rp[j, a, 1] * m10 + rp[j, a, 2] * m20
                rl[a, 1] = rp[j, a, 0] * m01 + rp[j, a, 1] * m11 + rp[j, a, 2] * m21
                rl[a, 2] = rp[j, a, 0] * m02 + rp[j, a, 1] * m12 + rp[j, a, 2] * m22
            px, py, pz = pp[j, 0], pp[j, 1], pp[j, 2]
        p = parent[j]
        if p < 0:
            wpx = wpy = wpz = 0.0
            dwx = dwy = dwz = 0.0
            apx, apy, apz = -gravity[0], -gravity[1], -gravity[2]
            o[j, 0] = px
            o[j, 1] = py
            o[j, 2] = pz
            for a in range(3):
                for b in range(3):
                    r0[j, a, b] = rl[a, b]
        else:
            wpx, wpy, wpz = w[p, 0], w[p, 1], w[p, 2]
            dwx, dwy, dwz = dw[p, 0], dw[p, 1], dw[p, 2]
            apx, apy, apz = acc[p, 0], acc[p, 1], acc[p, 2]
            for a in range(3):
                o[j, a] = o[p, a] + r0[p, a, 0] * px + r0[p, a, 1] * py + r0[p, a, 2] * pz
                for b in range(3):
                    r0[j, a, b] = r0[p, a, 0] * rl[0, b] + r0[p, a, 1] * rl[1, b] + r0[p, a, 2] * rl[2, b]
        # acceleration of the new origin, parent frame: a + dw×p + w×(w×p)
        cx = wpy * pz - wpz * py
        cy = wpz * px - wpx * pz
        cz = wpx * py - wpy * px
        hx = apx + (dwy * pz - dwz * py) + (wpy * cz - wpz * cy)
        hy = apy + (dwz * px - dwx * pz) + (wpz * cx - wpx * cz)
        hz = apz + (dwx * py - dwy * px) + (wpx * cy - wpy * cx)
        qd, qdd = dq[k, j], ddq[k, j]
        slides = prismatic[j] > 0.0
        for b in range(3):  # rotate into link j frame (rl^T)
            wi = rl[0, b] * wpx + rl[1, b] * wpy + rl[2, b] * wpz
            w[j, b] = wi
            dwi = rl[0, b] * dwx + rl[1, b] * dwy + rl[2, b] * dwz
            acci = rl[0, b] * hx + rl[1, b] * hy + rl[2, b] * hz
            if slides:
                dw[j, b] = dwi
                acc[j, b] = acci + qdd * axes[j, b]
            else:
                dw[j, b] = dwi + qdd * axes[j, b]
                acc[j, b] = acci
        wix, wiy, wiz = w[j, 0], w[j, 1], w[j, 2]
        if slides:  # acc += 2 w × (qd axis): the sliding origin's Coriolis term
            acc[j, 0] += 2.0 * qd * (wiy * ax2 - wiz * ax1)
            acc[j, 1] += 2.0 * qd * (wiz * ax0 - wix * ax2)
            acc[j, 2] += 2.0 * qd * (wix * ax1 - wiy * ax0)
        else:  # dw += w_in × (qd axis), then w += qd axis
            dw[j, 0] += qd * (wiy * ax2 - wiz * ax1)
            dw[j, 1] += qd * (wiz * ax0 - wix * ax2)
            dw[j, 2] += qd * (wix * ax1 - wiy * ax0)
            w[j, 0] += qd * ax0
            w[j, 1] += qd * ax1
            w[j, 2] += qd * ax2
        for a in range(3):
            z0[j, a] = r0[j, a, 0] * ax0 + r0[j, a, 1] * ax1 + r0[j, a, 2] * ax2
    # ---- regressor columns -------------------------------------------------------------
    for j in range(n):
        wx, wy, wz = w[j, 0], w[j, 1], w[j, 2]
        ex, ey, ez = dw[j, 0], dw[j, 1], dw[j, 2]
        gx, gy, gz = acc[j, 0], acc[j, 1], acc[j, 2]
        w2 = wx * wx + wy * wy + wz * wz
        col = j * npj
        i = j
        while i >= 0:  # the joints that carry link j: j itself, then each parent back to the base
            # axis of joint i and o_j - o_i, in frame j
            dx = o[j, 0] - o[i, 0]
            dy = o[j, 1] - o[i, 1]
            dz = o[j, 2] - o[i, 2]
            zx = r0[j, 0, 0] * z0[i, 0] + r0[j, 1, 0] * z0[i, 1] + r0[j, 2, 0] * z0[i, 2]
            zy = r0[j, 0, 1] * z0[i, 0] + r0[j, 1, 1] * z0[i, 1] + r0[j, 2, 1] * z0[i, 2]
            zz = r0[j, 0, 2] * z0[i, 0] + r0[j, 1, 2] * z0[i, 1] + r0[j, 2, 2] * z0[i, 2]
            rx = r0[j, 0, 0] * dx + r0[j, 1, 0] * dy + r0[j, 2, 0] * dz
            ry = r0[j, 0, 1] * dx + r0[j, 1, 1] * dy + r0[j, 2, 1] * dz
            rz = r0[j, 0, 2] * dx + r0[j, 1, 2] * dy + r0[j, 2, 2] * dz
            if prismatic[i] > 0.0:  # the force along the axis: z·f_j
                c0 = c1 = c2 = c3 = c4 = c5 = 0.0
                lw = zx * wx + zy * wy + zz * wz
                c6 = (zy * ez - zz * ey) + lw * wx - w2 * zx
                c7 = (zz * ex - zx * ez) + lw * wy - w2 * zy
                c8 = (zx * ey - zy * ex) + lw * wz - w2 * zz
                c9 = zx * gx + zy * gy + zz * gz
            else:  # z·n_j + l·f_j
                lx = zy * rz - zz * ry
                ly = zz * rx - zx * rz
                lz = zx * ry - zy * rx
                ux = zy * wz - zz * wy
                uy = zz * wx - zx * wz
                uz = zx * wy - zy * wx
                c0 = zx * ex + ux * wx
                c1 = zx * ey + zy * ex + ux * wy + uy * wx
                c2 = zx * ez + zz * ex + ux * wz + uz * wx
                c3 = zy * ey + uy * wy
                c4 = zy * ez + zz * ey + uy * wz + uz * wy
                c5 = zz * ez + uz * wz
                lw = lx * wx + ly * wy + lz * wz
                c6 = (ly * ez - lz * ey) + lw * wx - w2 * lx + (gy * zz - gz * zy)
                c7 = (lz * ex - lx * ez) + lw * wy - w2 * ly + (gz * zx - gx * zz)
                c8 = (lx * ey - ly * ex) + lw * wz - w2 * lz + (gx * zy - gy * zx)
                c9 = lx * gx + ly * gy + lz * gz
            values = (c0, c1, c2, c3, c4, c5, c6, c7, c8, c9)
            for t in range(10):
                dst = colmap[col + t]
                if dst >= 0:
                    out[k, i, dst] = values[t]
            i = parent[i]


def _chunk(robot, motion, out, drive, span, scratch):
    for k in range(span[0], span[1]):
        _sample(k, robot, motion, out, drive, scratch)


def _samples(robot, motion, out, drive, start, stop):
    """Samples ``start:stop`` with their own scratch arrays (releases the GIL: threads run ranges side by side)."""
    n = motion[0].shape[1]
    _chunk(robot, motion, out, drive, (start, stop), (np.empty((n, 3, 3)), np.empty((n, 3)), np.empty((n, 3)),
                                                     np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3)), np.empty((3, 3))))


_sample = sample_columns  # load_compiled() binds these names to their compiled versions (numba resolves globals then)
_compiled = False
_compile_lock = threading.Lock()


def compiled() -> bool:
    """Whether the compiled kernel is loaded in this process (then it computes every regressor)."""
    return _compiled


def load_compiled() -> None:
    global _sample, _chunk, _samples, _compiled
    with _compile_lock:
        if _compiled:
            return
        import numba as nb

        options = {"cache": True, "fastmath": False, "boundscheck": False, "nogil": True}
        _sample = nb.njit(inline="always", **options)(sample_columns)  # type: ignore[call-overload]  # numba's stubs
        _chunk = nb.njit(**options)(_chunk)  # type: ignore[call-overload]
        _samples = nb.njit(**options)(_samples)  # type: ignore[call-overload]
        _compiled = True


NUMPY_BLOCK = 1024
"""Samples per block of :func:`numpy_regressor` (its vectors stay in the cache; 1024 rather than 2048 halves its
temporary block, 8 MB for a 6-joint arm's 87 columns, at 0.8 µs a sample more in ``bench_regressor.py``)."""


def numpy_regressor(robot: RobotArrays, motion, out, drive) -> None:
    """What :func:`joint_torque_regressor` computes, by :func:`sample_columns` on blocks of samples at once
    (NumPy vectors; 4.4-5.3 µs an er16 sample against the kernel's 0.8 µs in ``bench_regressor.py``, but no
    start-up). ``drive(a, b)`` gives the drive columns of samples ``a:b`` (block by block: no array of the whole
    call's)."""
    q, dq, ddq = motion
    n_s, n = q.shape
    for a in range(0, n_s, NUMPY_BLOCK):
        b = min(a + NUMPY_BLOCK, n_s)
        m = b - a
        block = np.empty((n, out.shape[2], m))  # a column's samples side by side: written at full speed
        scratch = (np.empty((n, 3, 3, m)), np.empty((n, 3, m)), np.empty((n, 3, m)), np.empty((n, 3, m)),
                   np.empty((n, 3, m)), np.empty((n, 3, m)), np.empty((3, 3, m)))
        sample_columns(slice(None), robot, (q[a:b], dq[a:b], ddq[a:b]), block.transpose(2, 0, 1), drive(a, b), scratch)
        out[a:b] = block.transpose(2, 0, 1)


PARALLEL_SAMPLES = 4096
"""From this many samples on, the samples are split over the cores (threads); below, one call."""


def joint_torque_regressor(robot: RobotArrays, motion, out, drive) -> None:
    """Fill every entry of ``out`` (N, n, m): column ``colmap[c]`` holds standard column ``c`` (the ten
    inertial columns of each link; skipped where ``colmap[c] < 0``) and the drive columns of ``drive`` as
    ``drive_map`` places them (:func:`sample_columns`). Every sample is computed on its own, so the result does not
    depend on how the samples are split over threads."""
    load_compiled()
    n_s = motion[0].shape[0]
    workers = min(cores(), max(1, n_s // PARALLEL_SAMPLES))
    if workers == 1:
        _samples(robot, motion, out, drive, 0, n_s)
        return

    bounds = np.linspace(0, n_s, workers + 1).astype(np.int64)
    with ThreadPoolExecutor(max_workers=workers) as pool:
        list(pool.map(lambda k: _samples(robot, motion, out, drive, int(bounds[k]), int(bounds[k + 1])), range(workers)))
