"""Drive and friction terms of a joint (paper eq. 3 and its usual extensions): one table, stated once.

Every term is linear in its coefficient, so the joint torque stays linear in the parameters
(τ = Φ·θ). Each :class:`FrictionTerm` says its name, unit, sign constraint, other spellings found in
published sets, its regressor column as a function of the joint state, and that column's derivative
with respect to the velocity (for the excitation design's chain rule). The regressor, the simulator,
the sensitivities, the constrained estimators' layout, the description parser and the name/unit
conventions all read this table: **adding a term is one entry in** :data:`TERMS`.

The smooth Coulomb and Stribeck columns use per-joint velocities that the robot carries
(:attr:`dynid.model.robot.Robot.coulomb_velocity`, :attr:`~dynid.model.robot.Robot.stribeck_velocity`).

This module sits at the bottom layer (beside :mod:`dynid.conventions`) because the robot description
(model layer) and the conventions read it, and lower layers never import higher ones.

References: Armstrong-Hélouvry, Dupont & Canudas de Wit, "A survey of models, analysis tools and
compensation methods for the control of machines with friction", Automatica 30(7), 1994 (Coulomb,
viscous, Stribeck); Olsson, Åström et al., Eur. J. Control 4(3), 1998 (smooth Coulomb approximations).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np


def moving_sign(dq: np.ndarray, rest=0.0) -> np.ndarray:
    """``sign(dq)`` where the joint moves, 0 where it rests: with a rest velocity ``v_r > 0``,
    ``sign(dq)·clip(|dq|/v_r - 1, 0, 1)`` (0 below ``v_r``, a ramp to ±1 at ``2·v_r``).

    Below ``v_r`` the measured velocity is noise (``v_r`` is :data:`dynid.preprocessing.bands.REST_FACTOR` × its
    standard deviation), so its sign says nothing about the direction of motion;
    the friction of a joint at rest is whatever holds it, within ``±f_s`` (static friction). This is the
    memoryless form ("zero at rest"); :func:`held_direction` keeps the last direction instead.

    Parameters
    ----------
    dq : (N, n_dof) array [rad/s]
    rest : (n_dof,) array or float [rad/s]
        Rest velocity ``v_r`` per joint (0: plain sign).

    Returns
    -------
    (N, n_dof) array, in [-1, 1].
    """
    dq = np.asarray(dq, dtype=float)
    vr = np.broadcast_to(np.asarray(rest, dtype=float), dq.shape[-1:])
    out = np.sign(dq)
    on = vr > 0
    if on.any():
        out[..., on] *= np.clip(np.abs(dq[..., on]) / vr[on] - 1.0, 0.0, 1.0)
    return out


def held_direction(dq: np.ndarray, rest, decay=np.inf, *, presliding=0.0, rate: float = 1.0, guide=None,
                   min_travel=0.0) -> np.ndarray:
    """Direction of motion per joint: the state of the Coulomb-like friction terms, held or relaxed at rest and
    reversed over a presliding distance.

    Where ``|dq| > v_r`` the joint moves; where it rests, the direction keeps the value of its last motion (0
    before the first), relaxing towards 0 with the time constant ``T_r`` (``decay``): a joint stopped by its
    position controller keeps the friction of its last motion, since the static friction holds the link while
    the controller's integral action keeps the torque it had (``T_r = ∞``, seen on the UR10e's point-to-point
    logs); a controller without integral action, or a joint that creeps, lets it relax (finite ``T_r``); ``T_r =
    0`` is :func:`moving_sign` (0 at rest, with its ramp). With a presliding distance ``x_0 > 0`` the direction
    ``z`` follows Dahl's model (α = 1) while the joint moves: along the distance ``s`` travelled in one direction
    ``σ = sign(dq)``, ``dz/ds = (σ - z)/x_0``, so ``z = σ + (z_0 - σ)·exp(-s/x_0)``: a short move after a
    reversal reverses the friction only partly, as the contact deflects before it slips; ``x_0 = 0`` reverses
    at once.

    Parameters
    ----------
    dq : (N, n_dof) array [rad/s], in time order on a uniform grid
    rest : (n_dof,) array or float [rad/s]
        Rest velocity ``v_r`` per joint.
    decay : (n_dof,) array or float [s]
        Relaxation time ``T_r`` at rest (``inf``: held; 0: none at rest).
    presliding : (n_dof,) array or float [rad]
        Dahl's presliding distance ``x_0`` per joint.
    rate : float [Hz]
        Sampling rate (distances ``Σ |dq|/rate``, times ``k/rate``).
    guide : (N, n_dof) array [rad/s], optional
        A velocity that does not overshoot where a joint stops abruptly (a Butterworth filter's ringing would look
        like a short reversal): it says where the joint moves (``|guide| > v_r``), while the sign of ``dq`` (flat in
        the motion's band, so its crossings are the motion's) gives the direction. Default ``dq``.
    min_travel : (n_dof,) array or float [rad]
        A move against the last direction (or the first move) that travels less than this before the joint rests or
        turns back is not a reversal (a velocity blip where a joint stops: the controller's velocity estimate rings);
        a longer one reverses at its start.

    Returns
    -------
    (N, n_dof) array in [-1, 1]

    References
    ----------
    P. R. Dahl, "A solid friction model", Aerospace Corp. TOR-0158(3107-18)-1, 1968; Armstrong-Hélouvry, Dupont &
    Canudas de Wit, Automatica 30(7), 1994, §2.2 (presliding displacement, stiction).
    """
    dq = np.asarray(dq, dtype=float)
    n, k = dq.shape
    vr = np.broadcast_to(np.asarray(rest, dtype=float), (k,))
    tr = np.broadcast_to(np.asarray(decay, dtype=float), (k,))
    x0 = np.broadcast_to(np.asarray(presliding, dtype=float), (k,))
    guide = dq if guide is None else np.asarray(guide, dtype=float)
    travel = np.broadcast_to(np.asarray(min_travel, dtype=float), (k,))
    # decay 0: the sign of dq where the joint moves (the guide says where, with moving_sign's ramp), 0 at rest
    out = np.sign(dq) * np.abs(moving_sign(guide, np.where(tr > 0, 0.0, vr)))
    for j in np.flatnonzero(tr > 0):
        out[:, j] = _held_column(dq[:, j], vr[j], tr[j], x0[j], rate=rate, guide=guide[:, j], min_travel=travel[j])
    return out


def moving_joints(dq: np.ndarray, guide: np.ndarray, rest) -> np.ndarray:
    """Where each joint moves; the complement is where it rests.

    Parameters
    ----------
    dq : (N, n_dof) array [rad/s]
        Velocities.
    guide : (N, n_dof) array [rad/s]
        The velocity compared with the rest velocity (e.g. a smoothed one).
    rest : (n_dof,) array or float [rad/s]
        Rest velocity of each joint (0: a joint moves wherever ``dq != 0``).

    Returns
    -------
    (N, n_dof) bool ndarray
    """
    dq, guide = np.asarray(dq, dtype=float), np.asarray(guide, dtype=float)
    vr = np.broadcast_to(np.asarray(rest, dtype=float), dq.shape[-1:])
    return np.column_stack([_moving(dq[:, j], guide[:, j], vr[j]) != 0 if vr[j] > 0 else dq[:, j] != 0
                            for j in range(dq.shape[1])])


def _moving(v: np.ndarray, guide: np.ndarray, vr: float) -> np.ndarray:
    """``sign(v)`` where the joint moves (``|guide| > v_r``), 0 at rest."""
    return np.where(np.abs(guide) > vr, np.sign(v), 0.0)


def _held_column(v: np.ndarray, vr: float, tr: float, x0: float, *, rate: float, guide: np.ndarray,
                 min_travel: float = 0.0) -> np.ndarray:
    """:func:`held_direction` of one joint. Runs of one direction of motion and runs of rest alternate; a rest run
    between motions in opposite directions is a reversal, which happens at the velocity's last sign change inside
    it (a joint that passes through zero does so at its crossing; one that rests, then moves back, keeps the
    friction of its last motion until it leaves)."""
    n = v.shape[0]
    sign = np.sign(v)
    sigma = _moving(v, guide, vr)
    if not sigma.any():
        return np.zeros(n)
    bounds = np.concatenate([[0], np.flatnonzero(np.diff(sigma) != 0) + 1, [n]])
    if min_travel > 0:  # short moves against the last direction (or before any) are blips: rest
        last = 0.0
        for a, b in zip(bounds[:-1], bounds[1:]):
            d = sigma[a]
            if d == 0:
                continue
            if d != last and np.abs(v[a:b]).sum() / rate < min_travel:
                following = sigma[b:b + 1]
                if b == n or following[0] != d:  # it rests or turns back after it
                    sigma[a:b] = 0.0
                    continue
            last = d
        bounds = np.concatenate([[0], np.flatnonzero(np.diff(sigma) != 0) + 1, [n]])
    z = np.zeros(n)
    z0, last = 0.0, 0.0

    def moving(a, b, d, z0):
        if x0 > 0:
            return d + (z0 - d) * np.exp(-np.cumsum(np.abs(v[a:b])) / rate / x0)
        return np.full(b - a, d)

    for a, b in zip(bounds[:-1], bounds[1:]):
        d = sigma[a]
        if d != 0:
            z[a:b] = moving(a, b, d, z0)
            last = d
        else:
            after = sigma[b] if b < n else 0.0
            c = b
            if last != 0 and after != 0 and after != last:  # a reversal: at the last crossing inside the run
                other = np.flatnonzero(sign[a:b] != after)
                c = a + (other[-1] + 1 if other.size else 0)
            held = np.arange(1, c - a + 1)
            z[a:c] = z0 * np.exp(-held / (rate * tr)) if np.isfinite(tr) else z0
            if c < b:
                z[c:b] = moving(c, b, after, z[c - 1] if c > a else z0)
        z0 = z[b - 1]
    return z


def _direction(dq, v):
    """The direction of motion the Coulomb-like columns use: the log's held direction when given, else
    :func:`moving_sign`."""
    return moving_sign(dq, v.rest) if v.direction is None else v.direction


def coulomb_column(dq: np.ndarray, velocity, rest=0.0) -> np.ndarray:
    """``sign(dq)`` (with a rest band, :func:`moving_sign`), or ``tanh(dq / v_s)`` for the joints with ``v_s > 0``.

    Parameters
    ----------
    dq : (N, n_dof) array [rad/s]
    velocity : (n_dof,) array or float [rad/s]
        Smoothing velocity ``v_s`` per joint (0: sign).
    rest : (n_dof,) array or float [rad/s]
        Rest velocity per joint of the sign (:func:`moving_sign`; 0: none).

    Returns
    -------
    (N, n_dof) array, in [-1, 1].
    """
    dq = np.asarray(dq, dtype=float)
    vs = np.broadcast_to(np.asarray(velocity, dtype=float), dq.shape[-1:])
    smooth = vs > 0
    out = moving_sign(dq, rest)
    if smooth.any():
        out[..., smooth] = np.tanh(dq[..., smooth] / vs[smooth])
    return out


def _coulomb_dq(q, dq, v):
    """d/d(dq) of :func:`coulomb_column`: 0 for sign (almost everywhere; the rest band's ramp counted), (1 - tanh²)/v_s
    for tanh."""
    vs = np.broadcast_to(np.asarray(v.coulomb, dtype=float), dq.shape[-1:])
    safe = np.where(vs > 0, vs, 1.0)
    return np.where(vs > 0, (1.0 - np.tanh(dq / safe) ** 2) / safe, _ramp_dq(dq, v))


def _ramp_dq(dq, v):
    """d/d(dq) of :func:`moving_sign`: 1/v_r on the ramp ``v_r < |dq| < 2·v_r``, else 0."""
    vr = np.broadcast_to(np.asarray(v.rest, dtype=float), dq.shape[-1:])
    safe = np.where(vr > 0, vr, 1.0)
    a = np.abs(dq)
    return np.where((vr > 0) & (a > vr) & (a < 2 * vr), 1.0 / safe, 0.0)


def _coulomb(q, dq, v):
    vs = np.broadcast_to(np.asarray(v.coulomb, dtype=float), dq.shape[-1:])
    out = np.array(_direction(dq, v), dtype=float)
    smooth = vs > 0
    if smooth.any():
        out[..., smooth] = np.tanh(dq[..., smooth] / vs[smooth])
    return out


def _stribeck(q, dq, v):
    return _direction(dq, v) * np.exp(-(dq / v.stribeck) ** 2)


def _stribeck_dq(q, dq, v):
    e = np.exp(-(dq / v.stribeck) ** 2)
    return -2.0 * np.abs(dq) / v.stribeck**2 * e * np.abs(_direction(dq, v)) + _ramp_dq(dq, v) * e


def _asymmetric(q, dq, v):
    return np.abs(_direction(dq, v))


def _load_dependent(q, dq, v):
    if v.load is None:
        raise ValueError("the load-dependent Coulomb term fcl needs the transmitted torque (Velocities.load)")
    return np.abs(v.load) * _direction(dq, v)


def _asymmetric_dq(q, dq, v):
    return np.sign(dq) * _ramp_dq(dq, v)


@dataclass(frozen=True)
class Velocities:
    """What the friction columns need beyond the joint state.

    The rest velocity and the direction are properties of a log, not of the robot.

    Attributes
    ----------
    coulomb : (n_dof,) array [rad/s]
        Coulomb smoothing velocity of each joint (0: an exact sign).
    stribeck : (n_dof,) array [rad/s]
        Stribeck velocity of each joint.
    rest : (n_dof,) array or float [rad/s]
        Below this speed a joint rests (0: never).
    direction : (N, n_dof) array or None
        A log's direction of motion held at rest (:func:`held_direction`).
    load : (N, n_dof) array [N·m] or None
        Torque each joint's transmission carries, for the load-dependent Coulomb term ``fcl``: the rigid-body torque
        of the robot's nominal parameters (:func:`dynid.dynamics.regressor.regressor` fills it).
    """

    coulomb: np.ndarray
    stribeck: np.ndarray
    rest: np.ndarray | float = 0.0
    direction: np.ndarray | None = None
    load: np.ndarray | None = None

    def rows(self, a: int, b: int) -> Velocities:
        """The same, with the direction and load of some samples only.

        Parameters
        ----------
        a, b : int
            First sample and one past the last.

        Returns
        -------
        Velocities
        """
        cut = lambda x: None if x is None else x[a:b]  # noqa: E731
        return replace(self, direction=cut(self.direction), load=cut(self.load))


@dataclass(frozen=True)
class FrictionTerm:
    """One drive/friction term of a joint.

    Attributes
    ----------
    name : str
        Parameter stem (``"fc"`` → ``fc1``, ``fc2`` …).
    unit : str
        Unit of the coefficient.
    nonnegative : bool
        Physically ≥ 0 (constrained estimators and the consistency check impose it).
    column : callable ``(q, dq, ddq, velocities) -> (N, n_dof)``
        Regressor column of each joint (the torque is ``coefficient × column``).
    d_dq : callable ``(q, dq, velocities) -> (N, n_dof)``
        Derivative of the column with respect to the joint's own velocity.
    d_ddq : float
        Derivative with respect to the joint's own acceleration (constant: the columns are linear in ddq).
    aliases : tuple of str
        Other spellings in published sets (FIGAROH, MATLAB toolboxes).
    description : str
    d_q : callable ``(q, dq, velocities) -> (N, n_dof)`` or None
        Derivative with respect to the joint's own position (None: the column does not depend on it).
    """

    name: str
    unit: str
    nonnegative: bool
    column: Callable
    d_dq: Callable
    d_ddq: float
    aliases: tuple[str, ...]
    description: str
    d_q: Callable | None = None


def _zeros(q, dq, v):
    return np.zeros_like(dq)


TERMS: dict[str, FrictionTerm] = {t.name: t for t in (
    FrictionTerm("Ia", "kg·m²", True, lambda q, dq, ddq, v: ddq, _zeros, 1.0, ("Jm",),
                 "rotor (reflected motor) inertia, Ia·ddq"),
    FrictionTerm("fc", "N·m", True, lambda q, dq, ddq, v: _coulomb(q, dq, v), _coulomb_dq, 0.0, ("fs", "Fc"),
                 "Coulomb friction, fc·sign(dq) (eq. 3), 0 at rest, or fc·tanh(dq/v_s) with a smoothing velocity"),
    FrictionTerm("fv", "N·m·s/rad", True, lambda q, dq, ddq, v: dq, lambda q, dq, v: np.ones_like(dq), 0.0, ("Fv",),
                 "viscous friction, fv·dq (eq. 3)"),
    FrictionTerm("offset", "N·m", False, lambda q, dq, ddq, v: np.ones_like(dq), _zeros, 0.0,
                 ("f0", "off"), "constant torque offset (a current or torque sensor's offset), also at rest"),
    FrictionTerm("fst", "N·m", False, lambda q, dq, ddq, v: _stribeck(q, dq, v), _stribeck_dq, 0.0, (),
                 "Stribeck friction, fst·sign(dq)·exp(-(dq/v_st)²) with a Stribeck velocity v_st: fst > 0, the static "
                 "friction fc + fst falls to fc as the joint speeds up; fst < 0, friction that builds up to fc over v_st "
                 "(harmonic drives)"),
    FrictionTerm("fca", "N·m", False, lambda q, dq, ddq, v: _asymmetric(q, dq, v), _asymmetric_dq, 0.0, (),
                 "asymmetric Coulomb friction, fca·|sign(dq)|: f⁺ = fc + fca moving forwards, f⁻ = fc - fca backwards, "
                 "0 at rest (an offset acts at rest too)"),
    FrictionTerm("fcl", "1", True, lambda q, dq, ddq, v: _load_dependent(q, dq, v), lambda q, dq, v: np.zeros_like(dq), 0.0, (),
                 "load-dependent Coulomb friction, fcl·|τ_load|·sign(dq): friction growing with the torque the transmission "
                 "carries (harmonic drives), τ_load the rigid-body torque of the nominal model; fcl is a ratio"),
    # A weight counterbalance (a spring or a hydraulic cylinder on the joint): a smooth function of the joint angle,
    # written as its Fourier series to the second harmonic, linear in the coefficients. The first harmonic is the
    # shape of a link's own weight on its joint, so it regroups with that link's first moments (MX, MY).
    FrictionTerm("cbs", "N·m", False, lambda q, dq, ddq, v: np.sin(q), _zeros, 0.0, (),
                 "counterbalance torque, first harmonic: cbs·sin(q)", lambda q, dq, v: np.cos(q)),
    FrictionTerm("cbc", "N·m", False, lambda q, dq, ddq, v: np.cos(q), _zeros, 0.0, (),
                 "counterbalance torque, first harmonic: cbc·cos(q)", lambda q, dq, v: -np.sin(q)),
    FrictionTerm("cbsd", "N·m", False, lambda q, dq, ddq, v: np.sin(2 * q), _zeros, 0.0, (),
                 "counterbalance torque, second harmonic: cbsd·sin(2q)", lambda q, dq, v: 2 * np.cos(2 * q)),
    FrictionTerm("cbcd", "N·m", False, lambda q, dq, ddq, v: np.cos(2 * q), _zeros, 0.0, (),
                 "counterbalance torque, second harmonic: cbcd·cos(2q)", lambda q, dq, v: -2 * np.sin(2 * q)),
)}

COUNTERBALANCE_TERMS: tuple[str, ...] = ("cbs", "cbc", "cbsd", "cbcd")
"""The terms of a weight counterbalance on a joint (``counterbalance = true`` in a joint's description table)."""
"""The table: every drive/friction term dynid knows, in the order of the parameter vector."""

DEFAULT_TERMS: tuple[str, ...] = ("fc", "fv")
"""The paper's friction model (eq. 3): Coulomb and viscous friction."""

DEFAULT_STRIBECK_VELOCITY = 0.01
"""Stribeck velocity [rad/s] when a description uses ``fst`` without giving one."""


def term_names() -> tuple[str, ...]:
    """Names of the terms of :data:`TERMS`.

    Returns
    -------
    tuple of str
        In table order.
    """
    return tuple(TERMS)


def check_terms(terms, where: str) -> tuple[str, ...]:
    """Friction term names checked against :data:`TERMS`, in table order.

    Parameters
    ----------
    terms : iterable of str
        Term names, e.g. ``("fv", "fc", "off")``.
    where : str
        Where the names come from, named in the error.

    Returns
    -------
    tuple of str
        The terms in table order.

    Raises
    ------
    ValueError
        An unknown name, naming ``where``.
    """
    bad = [t for t in terms if t not in TERMS]
    if bad:
        raise ValueError(f"{where}: unknown drive term(s) {bad}, expected a subset of {list(TERMS)}")
    return tuple(t for t in TERMS if t in terms)


def nonnegative_terms() -> tuple[str, ...]:
    """Names of the terms that are non-negative on a physical robot (viscous and Coulomb friction…).

    Returns
    -------
    tuple of str
    """
    return tuple(t.name for t in TERMS.values() if t.nonnegative)
