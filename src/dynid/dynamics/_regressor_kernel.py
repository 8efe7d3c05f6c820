"""Compiled kernel of the batched joint-torque regressor (see :mod:`dynid.dynamics.regressor`).

One pass per sample: forward Newton–Euler recursion in link frames, then for every link ``j`` and
joint ``i <= j`` the ten closed-form columns ``tau_i = z·n_j + l·f_j``. Samples are split into
contiguous ranges run side by side in threads (the compiled loop releases the GIL); no allocation per
sample. A serial kernel loads from numba's cache in a fraction of the time a ``parallel=True`` one takes.
"""

from __future__ import annotations

import numba as nb
import numpy as np

@nb.njit(cache=True, fastmath=False, boundscheck=False, nogil=True, inline="always")
def _put(out, k, i, colmap, col, value):
    """``out[k, i, colmap[col]] = value`` for a kept column (``colmap[col] >= 0``)."""
    c = colmap[col]
    if c >= 0:
        out[k, i, c] = value


@nb.njit(cache=True, fastmath=False, boundscheck=False, nogil=True)
def _chunk(rp, pp, axes, gravity, q, dq, ddq, out, npj, colmap, start, stop, r0, o, w, dw, acc, z0, rl):
    n = q.shape[1]
    m = out.shape[2]
    for k in range(start, stop):
        # ---- zero every entry first: links j < i stay zero, and the drive columns are filled by the caller
        #      from the friction table (dynid.friction) -----
        for i in range(n):
            for c in range(m):
                out[k, i, c] = 0.0
        # ---- forward recursion -------------------------------------------------------------
        for j in range(n):
            ax0, ax1, ax2 = axes[j, 0], axes[j, 1], axes[j, 2]
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
            if j == 0:
                wpx = wpy = wpz = 0.0
                dwx = dwy = dwz = 0.0
                apx, apy, apz = -gravity[0], -gravity[1], -gravity[2]
                for a in range(3):
                    o[0, a] = pp[0, a]
                    for b in range(3):
                        r0[0, a, b] = rl[a, b]
            else:
                wpx, wpy, wpz = w[j - 1, 0], w[j - 1, 1], w[j - 1, 2]
                dwx, dwy, dwz = dw[j - 1, 0], dw[j - 1, 1], dw[j - 1, 2]
                apx, apy, apz = acc[j - 1, 0], acc[j - 1, 1], acc[j - 1, 2]
                for a in range(3):
                    o[j, a] = o[j - 1, a] + r0[j - 1, a, 0] * px + r0[j - 1, a, 1] * py + r0[j - 1, a, 2] * pz
                    for b in range(3):
                        r0[j, a, b] = r0[j - 1, a, 0] * rl[0, b] + r0[j - 1, a, 1] * rl[1, b] + r0[j - 1, a, 2] * rl[2, b]
            # acceleration of the new origin, parent frame: a + dw×p + w×(w×p)
            cx = wpy * pz - wpz * py
            cy = wpz * px - wpx * pz
            cz = wpx * py - wpy * px
            hx = apx + (dwy * pz - dwz * py) + (wpy * cz - wpz * cy)
            hy = apy + (dwz * px - dwx * pz) + (wpz * cx - wpx * cz)
            hz = apz + (dwx * py - dwy * px) + (wpx * cy - wpy * cx)
            qd, qdd = dq[k, j], ddq[k, j]
            for b in range(3):  # rotate into link j frame (rl^T)
                wi = rl[0, b] * wpx + rl[1, b] * wpy + rl[2, b] * wpz
                w[j, b] = wi
                dw[j, b] = rl[0, b] * dwx + rl[1, b] * dwy + rl[2, b] * dwz + qdd * axes[j, b]
                acc[j, b] = rl[0, b] * hx + rl[1, b] * hy + rl[2, b] * hz
            # dw += w_in × (qd axis), then w += qd axis
            wix, wiy, wiz = w[j, 0], w[j, 1], w[j, 2]
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
            for i in range(j + 1):
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
                lx = zy * rz - zz * ry
                ly = zz * rx - zx * rz
                lz = zx * ry - zy * rx
                ux = zy * wz - zz * wy
                uy = zz * wx - zx * wz
                uz = zx * wy - zy * wx
                _put(out, k, i, colmap, col + 0, zx * ex + ux * wx)
                _put(out, k, i, colmap, col + 1, zx * ey + zy * ex + ux * wy + uy * wx)
                _put(out, k, i, colmap, col + 2, zx * ez + zz * ex + ux * wz + uz * wx)
                _put(out, k, i, colmap, col + 3, zy * ey + uy * wy)
                _put(out, k, i, colmap, col + 4, zy * ez + zz * ey + uy * wz + uz * wy)
                _put(out, k, i, colmap, col + 5, zz * ez + uz * wz)
                lw = lx * wx + ly * wy + lz * wz
                _put(out, k, i, colmap, col + 6, (ly * ez - lz * ey) + lw * wx - w2 * lx + (gy * zz - gz * zy))
                _put(out, k, i, colmap, col + 7, (lz * ex - lx * ez) + lw * wy - w2 * ly + (gz * zx - gx * zz))
                _put(out, k, i, colmap, col + 8, (lx * ey - ly * ex) + lw * wz - w2 * lz + (gx * zy - gy * zx))
                _put(out, k, i, colmap, col + 9, lx * gx + ly * gy + lz * gz)


@nb.njit(cache=True, fastmath=False, boundscheck=False, nogil=True)
def _samples(rp, pp, axes, gravity, q, dq, ddq, out, npj, colmap, start, stop):
    """Samples ``start:stop`` with their own scratch arrays (releases the GIL: threads run ranges side by side)."""
    n = q.shape[1]
    _chunk(rp, pp, axes, gravity, q, dq, ddq, out, npj, colmap, start, stop, np.empty((n, 3, 3)), np.empty((n, 3)), np.empty((n, 3)),
           np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3)), np.empty((3, 3)))


PARALLEL_SAMPLES = 4096
"""From this many samples on, the samples are split over the cores (threads); below, one call."""


def joint_torque_regressor(rp, pp, axes, gravity, q, dq, ddq, out, npj, colmap):
    """Fill every entry of ``out`` (N, n, m): column ``colmap[c]`` holds standard column ``c`` (the ten
    inertial columns of each link; skipped where ``colmap[c] < 0``), the drive columns hold 0 (the caller
    fills them from :mod:`dynid.friction`). Every sample is computed on its own, so the result does not
    depend on how the samples are split over threads."""
    from ..threads import cores

    n_s = q.shape[0]
    workers = min(cores(), max(1, n_s // PARALLEL_SAMPLES))
    if workers == 1:
        _samples(rp, pp, axes, gravity, q, dq, ddq, out, npj, colmap, 0, n_s)
        return
    from concurrent.futures import ThreadPoolExecutor

    bounds = np.linspace(0, n_s, workers + 1).astype(np.int64)
    with ThreadPoolExecutor(max_workers=workers) as pool:
        list(pool.map(lambda k: _samples(rp, pp, axes, gravity, q, dq, ddq, out, npj, colmap, int(bounds[k]), int(bounds[k + 1])),
                      range(workers)))
