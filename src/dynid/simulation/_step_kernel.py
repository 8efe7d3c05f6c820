"""The closed-loop simulator's arithmetic between two calls of the direct dynamics, compiled (numba).

:func:`dynid.simulation.closed_loop.simulate_closed_loop` steps a controller and a fourth-order Runge–Kutta integrator
at the control rate; at 1 kHz each step is a few dozen operations on arrays of ``n_dof`` values, which NumPy runs one
call at a time. These kernels do them in place, element by element, in the same order as the NumPy expressions they
replace (no fast-math): the simulated runs are the same to the last bit.
"""

from __future__ import annotations

import numpy as np

__all__ = ["compiled"]


def _control(y, previous, first, velocity, alpha, h, q_ref, dq_ref, ff, kp, kd, ki, integral, tau):  # pragma: no cover - compiled
    """The controller at one instant: velocity estimate, integral and commanded torque, in place."""
    for i in range(y.shape[0]):
        if not first:
            velocity[i] = velocity[i] + alpha * ((y[i] - previous[i]) / h - velocity[i])
        error = q_ref[i] - y[i]
        integral[i] += error * h
        tau[i] = ff[i] + kp[i] * error + kd[i] * (dq_ref[i] - velocity[i]) + ki[i] * integral[i]


def _stage(q, direction, dq, a, c, tau, fc, fv, offset, out_q, out_v, out_u):  # pragma: no cover - compiled
    """A Runge–Kutta stage's state ``q + c·direction``, ``q̇ + c·a`` and the torque left for the rigid body, ``τ`` less
    the drive terms ``fc·sign(q̇) + fv·q̇ + offset`` at that velocity."""
    for i in range(q.shape[0]):
        out_q[i] = q[i] + c * direction[i]
        v = dq[i] + c * a[i]
        out_v[i] = v
        out_u[i] = tau[i] - (fc[i] * np.sign(v) + fv[i] * v + offset[i])


def _first_input(dq, tau, fc, fv, offset, out_u):  # pragma: no cover - compiled
    """The first stage's torque left for the rigid body (its state is the step's own)."""
    for i in range(dq.shape[0]):
        v = dq[i]
        out_u[i] = tau[i] - (fc[i] * np.sign(v) + fv[i] * v + offset[i])


def _advance(q, dq, v2, v3, v4, a1, a2, a3, a4, h):  # pragma: no cover - compiled
    """The Runge–Kutta step's new state, in place."""
    c = h / 6.0
    for i in range(q.shape[0]):
        q[i] = q[i] + c * (dq[i] + 2 * v2[i] + 2 * v3[i] + v4[i])
        dq[i] = dq[i] + c * (a1[i] + 2 * a2[i] + 2 * a3[i] + a4[i])


control = stage = first_input = advance = None
_kernels = None  # the four, set at once: IDIM-IV and DIDIM run side by side on two threads


def compiled():
    """The four kernels, compiled on first use into numba's on-disk cache.

    Returns
    -------
    tuple
        ``(control, stage, first_input, advance)``.
    """
    global control, stage, first_input, advance, _kernels
    if _kernels is None:
        import numba

        jit = numba.njit(cache=True, nogil=True)
        four = tuple(jit(f) for f in (_control, _stage, _first_input, _advance))
        control, stage, first_input, advance = four
        _kernels = four
    return _kernels
