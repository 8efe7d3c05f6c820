"""Joint friction columns (paper eq. 3) and the smooth Coulomb term.

Coulomb friction ``fc·sign(q̇)`` is undefined at rest, and a measured velocity that hovers around zero
(a joint at rest, encoder noise) makes ``sign`` flip between ±1: the model then predicts ±fc where the
real joint, held by its controller, shows no such torque. The smooth Coulomb column
``tanh(q̇ / v_s)`` (still linear in ``fc``) goes to 0 at rest and to ±1 once ``|q̇| ≫ v_s``; ``v_s = 0``
keeps ``sign``. Whether it helps depends on the joint: below ``v_s`` it also bends the model where the
joint really moves slowly, so dynid chooses ``v_s`` per joint by blocked cross-validation
(:mod:`dynid.estimators.cross_validation`) unless the config gives it.
Ref.: Olsson, Åström et al., "Friction models and friction compensation", Eur. J. Control 4(3), 1998
(smooth approximations of the Coulomb term).
"""

from __future__ import annotations

import numpy as np


def coulomb_column(dq: np.ndarray, velocity) -> np.ndarray:
    """``sign(dq)``, or ``tanh(dq / v_s)`` for the joints with ``v_s > 0``.

    Parameters
    ----------
    dq : (N, n_dof) array [rad/s]
    velocity : (n_dof,) array or float [rad/s]
        Smoothing velocity ``v_s`` per joint (0: sign).

    Returns
    -------
    (N, n_dof) array, in [-1, 1].
    """
    dq = np.asarray(dq, dtype=float)
    vs = np.broadcast_to(np.asarray(velocity, dtype=float), dq.shape[-1:])
    smooth = vs > 0
    out = np.sign(dq)
    if smooth.any():
        out[..., smooth] = np.tanh(dq[..., smooth] / vs[smooth])
    return out
