"""The closed-loop simulator's arithmetic between two calls of the direct dynamics, compiled (numba).

:func:`dynid.simulation.closed_loop.simulate_closed_loop` steps a controller and a fourth-order Runge–Kutta integrator
at the control rate; at 1 kHz each step is a few dozen operations on arrays of ``n_dof`` values, which NumPy runs one
call at a time. These kernels do them in place, element by element, in the same order as the NumPy expressions they
replace (no fast-math): the simulated runs are the same to the last bit. The loop's state lives in one work array of
:data:`ROWS` rows of ``n_dof`` values (the row constants below), so that each call hands numba a few arguments: its
dispatch grows with them (benchmarks/NOTEBOOK.md, stop 119).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["ROWS", "compiled"]

(Q, DQ, INTEGRAL, PREVIOUS, VELOCITY, TAU, U, QS, V2, V3, V4, Y, FC, FV, OFFSET, KP, KD, KI, DRIVEN, A1, A2,
 A3) = range(22)
ROWS = 22
"""Rows of the work array: the state ``q``, ``q̇``; the controller's integral, previous reading and velocity estimate;
the commanded torque, the torque left for the rigid body, a stage's state ``q`` and the stages' velocities; the
encoder's reading; the drive terms ``fc``, ``fv``, offset; the gains ``kp``, ``kd``, ``ki``; 1 for a driven joint, 0
for a follower; the first three stages' accelerations."""

READING_ITSELF, READING_NOISY, READING_GIVEN = 0, 1, 2
"""The encoder's reading: the position itself, the position plus the drawn noise, or set in the work array already."""


def _control(k, w, refs, draws, reading, alpha, h):  # pragma: no cover - compiled
    """Instant ``k``: the encoder's reading, the controller (velocity estimate, integral, commanded torque; a
    follower's 0) and the torque the first stage leaves for the rigid body, ``τ`` less the drive terms ``fc·sign(q̇) +
    fv·q̇ + offset``, in place. ``refs``: (3, N, n_dof) the reference positions, velocities and feed-forward."""
    for i in range(w.shape[1]):
        if reading == READING_ITSELF:
            w[Y, i] = w[Q, i]
        elif reading == READING_NOISY:
            w[Y, i] = w[Q, i] + draws[k, i]
        y = w[Y, i]
        if k > 0:
            w[VELOCITY, i] = w[VELOCITY, i] + alpha * ((y - w[PREVIOUS, i]) / h - w[VELOCITY, i])
        error = refs[0, k, i] - y
        w[INTEGRAL, i] += error * h
        tau = refs[2, k, i] + w[KP, i] * error + w[KD, i] * (refs[1, k, i] - w[VELOCITY, i]) + w[KI, i] * w[INTEGRAL, i]
        w[TAU, i] = tau if w[DRIVEN, i] != 0.0 else 0.0
        v = w[DQ, i]
        w[U, i] = w[TAU, i] - (w[FC, i] * np.sign(v) + w[FV, i] * v + w[OFFSET, i])


def _stage(k, w, a, s, c, out):  # pragma: no cover - compiled
    """Runge–Kutta stage ``s`` (0, 1, 2) from the accelerations ``a`` of the state before it: its state ``q +
    c·direction`` (``q̇``, then the stages' velocities), ``q̇ + c·a`` and the torque left for the rigid body at that
    velocity. Stage 0 first records instant ``k`` in ``out`` (5, N, n_dof): the state, ``a``, the commanded torque and
    the reading, which is kept as the previous one."""
    n = w.shape[1]
    if s == 0:
        for i in range(n):
            out[0, k, i], out[1, k, i], out[2, k, i] = w[Q, i], w[DQ, i], a[i]
            out[3, k, i], out[4, k, i] = w[TAU, i], w[Y, i]
            w[PREVIOUS, i] = w[Y, i]
    direction = DQ if s == 0 else V2 + s - 1
    for i in range(n):
        w[A1 + s, i] = a[i]
        w[QS, i] = w[Q, i] + c * w[direction, i]
        v = w[DQ, i] + c * a[i]
        w[V2 + s, i] = v
        w[U, i] = w[TAU, i] - (w[FC, i] * np.sign(v) + w[FV, i] * v + w[OFFSET, i])


def _advance(w, a4, h):  # pragma: no cover - compiled
    """The Runge–Kutta step's new state, in place; whether it is finite (no NaN, no infinity, no value beyond 1e154,
    whose square is one)."""
    c = h / 6.0
    total = 0.0
    for i in range(w.shape[1]):
        w[Q, i] = w[Q, i] + c * (w[DQ, i] + 2 * w[V2, i] + 2 * w[V3, i] + w[V4, i])
        w[DQ, i] = w[DQ, i] + c * (w[A1, i] + 2 * w[A2, i] + 2 * w[A3, i] + a4[i])
        total += w[Q, i] * w[Q, i] + w[DQ, i] * w[DQ, i]
    return math.isfinite(total)


control = stage = advance = None
_kernels = None  # the three, set at once: IDIM-IV and DIDIM run side by side on two threads


def compiled():
    """The three kernels, compiled on first use into numba's on-disk cache.

    Returns
    -------
    tuple
        ``(control, stage, advance)``.
    """
    global control, stage, advance, _kernels
    if _kernels is None:
        import numba

        jit = numba.njit(cache=True, nogil=True)
        three = tuple(jit(f) for f in (_control, _stage, _advance))
        control, stage, advance = three
        _kernels = three
    return _kernels
