"""A robot identified while its own controller drives it: closed-loop simulation.

A joint-space PD or PID controller (optional feed-forward torques) runs at its control rate on the *measured*
positions (encoder quantisation plus noise), as a real one does, so the loop's noise reaches the motion; the
torque it commands is held over the control period and drives the direct dynamics

    M(q) q̈ = τ − h(q, q̇),  M = M_rigid + M_drive,  h = h_rigid + τ_drive(q̇),

with ``M_rigid`` and ``h_rigid`` from Pinocchio (CRBA and the non-linear effects of RNEA), and the drive terms of
dynid's friction table (rotor inertia, Coulomb, viscous, offset, coupled motors) added, integrated by a fixed-step
fourth-order Runge–Kutta at the control rate. The logged torques are the commanded ones plus measurement noise.

A joint that follows another (a ``<mimic>``: ``q_f = m·q_k + c``) has no drive: the motion lives in the independent
joints' coordinates ``q̇ = G ν``, where ``G`` puts ``m`` in the follower's row, and ``Gᵀ M G ν̇ = Gᵀ (τ − h)`` (the
equations of motion projected onto the coupling, virtual work: the follower's torque goes to its master times ``m``),
so the follower stays on its coupling; its commanded torque is 0.

The same simulator, given a model's standard parameters instead of the truth, is what the closed-loop estimators
(IDIM-IV, DIDIM) simulate at each iteration.

References: Gautier, Janot & Vandanjon, "A new closed-loop output error method for parameter identification of
robot dynamics", IEEE TCST 21(2), 2013; Janot, Vandanjon & Gautier, "A generic instrumental variable approach for
industrial robot identification", IEEE TCST 22(1), 2014; Leboutet et al., "Inertial parameter identification in
robotics: a survey", Applied Sciences 11(9), 2021 (the noise grid).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._util.reprs import short_repr
from ..dynamics.regressor import friction_torques
from ..dynamics.rnea import pinocchio_model
from ..exceptions import ConfigError, ShapeError
from ..model.robot import Robot
from . import _step_kernel as kernel

__all__ = ["Controller", "ClosedLoopNoise", "ClosedLoopRun", "ClosedLoopSetup", "JointDynamics", "simulate_closed_loop"]

_FAST_TERMS = frozenset({"Ia", "fc", "fv", "offset"})


def _gains(value, n: int, name: str, positive: bool) -> np.ndarray:
    arr = np.broadcast_to(np.asarray(value, dtype=float), (n,)).copy() if np.ndim(value) == 0 else np.asarray(value, dtype=float)
    if arr.shape != (n,):
        raise ConfigError(f"controller.{name}: expected one value per joint ({n}), got {np.shape(value)}", field=name)
    if not np.all(np.isfinite(arr)) or np.any(arr < 0) or (positive and np.any(arr <= 0)):
        raise ConfigError(f"controller.{name}: expected {'positive' if positive else 'non-negative'} finite gains, got "
                          f"{arr.tolist()}", field=name)
    return arr


@short_repr
@dataclass(frozen=True)
class Controller:
    """A joint-space PD/PID controller on the measured positions.

    ``τ_k = τ_ff,k + Kp (q_ref,k − q_meas,k) + Kd (q̇_ref,k − q̇_est,k) + Ki Σ (q_ref − q_meas)/f``, with ``q̇_est`` the
    backward difference of the measured positions (what a drive computes from its encoder), through a first-order
    low-pass filter at ``velocity_cutoff``.

    Attributes
    ----------
    kp : (n_dof,) array [N·m/rad]
    kd : (n_dof,) array [N·m·s/rad]
    ki : (n_dof,) array [N·m/(rad·s)]
        Zero for a PD controller.
    rate : float [Hz]
        Control rate, also the integrator's and the log's.
    velocity_cutoff : float [Hz]
        Cutoff of the velocity estimate's first-order filter (0: the raw difference).
    """

    kp: np.ndarray
    kd: np.ndarray
    ki: np.ndarray
    rate: float
    velocity_cutoff: float = 0.0

    @classmethod
    def for_robot(cls, robot: Robot, bandwidth: float = 5.0, rate: float = 1000.0, integral: bool = True,
                  velocity_cutoff: float = 50.0, phi: np.ndarray | None = None) -> Controller:
        """A PID (or PD) tuned per joint on the diagonal of the mass matrix at q = 0: ``Kp = I ω²``, ``Kd = 2 I ω``
        (critical damping), ``Ki = Kp ω / 10``, with ``ω = 2π · bandwidth``.

        Parameters
        ----------
        robot : Robot
        bandwidth : float [Hz]
        rate : float [Hz]
        integral : bool
            PID (True) or PD.
        velocity_cutoff : float [Hz]
        phi : (n_params,) array, optional
            Standard parameters of the robot (its nominal ones by default).

        Returns
        -------
        Controller

        Raises
        ------
        ConfigError
            A joint with no inertia at q = 0 (no gain can be derived), or the checks of :meth:`of`.
        """
        n = robot.n_dof
        m, _ = JointDynamics(robot, phi).mass_and_bias(np.zeros(n), np.zeros(n))
        inertia = np.diag(m)
        if np.any(inertia <= 0):
            k = int(np.argmin(inertia))
            raise ConfigError(f"controller: joint {k + 1} has no inertia at q = 0 (no rotor inertia Ia, no link inertia "
                              "about its axis), so no gain can be derived from it: give kp and kd")
        w = 2 * np.pi * bandwidth
        kp = inertia * w**2
        return cls.of(n, kp, 2 * inertia * w, kp * w / 10 if integral else 0.0, rate, velocity_cutoff)

    @classmethod
    def of(cls, n_dof: int, kp, kd, ki=0.0, rate: float = 1000.0, velocity_cutoff: float = 0.0) -> Controller:
        """A controller with gains checked (a scalar is every joint's).

        Parameters
        ----------
        n_dof : int
        kp, kd, ki : float or (n_dof,) array
            [N·m/rad], [N·m·s/rad], [N·m/(rad·s)].
        rate : float [Hz]
        velocity_cutoff : float [Hz]
            0 for the raw backward difference; below half the rate.

        Returns
        -------
        Controller

        Raises
        ------
        ConfigError
            A gain of the wrong length, negative or not finite (``kp``, ``kd`` must be positive), a rate that is
            not positive, or a velocity cutoff outside [0, rate/2).
        """
        if not (np.isfinite(rate) and rate > 0):
            raise ConfigError(f"controller.rate: expected a positive rate in Hz, got {rate!r}", field="rate")
        if not (np.isfinite(velocity_cutoff) and 0 <= velocity_cutoff < rate / 2):
            raise ConfigError(f"controller.velocity_cutoff: expected 0 (none) or a cutoff below half the rate ({rate / 2:g} Hz), "
                              f"got {velocity_cutoff!r}", field="velocity_cutoff")
        return cls(_gains(kp, n_dof, "kp", True), _gains(kd, n_dof, "kd", True), _gains(ki, n_dof, "ki", False), float(rate),
                   float(velocity_cutoff))


@short_repr
@dataclass(frozen=True, eq=False)
class ClosedLoopSetup:
    """How the identification log was recorded in closed loop: what IDIM-IV and DIDIM need beside the log, as a
    config's ``[controller]`` table gives it (:attr:`dynid.io.config.identification_config.IdentificationConfig.controller`;
    :class:`dynid.identification.closed_loop_estimators.ClosedLoopEstimator` parts carry it).

    Attributes
    ----------
    controller : Controller
        The joint controller and its rate.
    reference : (N, n_dof) array [rad], or an object with ``read() -> (N, n_dof) array``
        The position set-points, one per sample of the log as read (a config's reference file is read when the
        estimators run); for a robot whose joints follow others (``<mimic>``), the driven joints' columns alone may be
        given, as its log holds them.
    feedforward : bool
        Whether the controller added the model's torques along the reference (computed with the identified model's
        description, :func:`dynid.dynamics.rnea.rnea_torques`).
    """

    controller: Controller
    reference: object
    feedforward: bool = False

    def reference_positions(self) -> np.ndarray:
        """The set-points as an array.

        Returns
        -------
        (N, n_dof) array [rad]
        """
        read = getattr(self.reference, "read", None)
        return np.asarray(read() if callable(read) else self.reference, dtype=float)


@dataclass(frozen=True)
class ClosedLoopNoise:
    """What the loop and the log see of the truth.

    Attributes
    ----------
    position_std : float [rad]
        Gaussian noise on the measured positions (before quantisation).
    encoder_resolution : float [rad]
        Quantisation step of the measured positions (0: none).
    torque_std : float [N·m]
        Gaussian noise on the logged torques (currents through the drive gains).
    """

    position_std: float = 0.0
    encoder_resolution: float = 0.0
    torque_std: float = 0.0

    def __post_init__(self) -> None:
        for name in ("position_std", "encoder_resolution", "torque_std"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ConfigError(f"noise.{name}: expected a non-negative number, got {value!r}", field=name)

    def measured_positions(self, q: np.ndarray, rng: np.random.Generator, draw: np.ndarray | None = None) -> np.ndarray:
        """Positions as the encoder gives them.

        Parameters
        ----------
        q : array [rad]
        rng : numpy.random.Generator
        draw : array [rad], optional
            The noise, drawn already (``rng`` is then not used).

        Returns
        -------
        array [rad], same shape
        """
        if self.position_std > 0:
            y = q + (rng.normal(0.0, self.position_std, np.shape(q)) if draw is None else draw)
        else:
            y = np.array(q, dtype=float)
        return np.round(y / self.encoder_resolution) * self.encoder_resolution if self.encoder_resolution > 0 else y


@short_repr
@dataclass(frozen=True)
class ClosedLoopRun:
    """One closed-loop run, time-first arrays of shape (N, n_dof) unless noted.

    Attributes
    ----------
    t : (N,) array [s]
    q : measured positions [rad] (what the loop saw and the log holds)
    tau : logged torques [N·m] (commanded, plus measurement noise)
    q_true, dq_true, ddq_true : the motion [rad, rad/s, rad/s²] (``ddq_true`` at the start of each step)
    tau_applied : the commanded torques [N·m], held over each control period
    q_ref, dq_ref : the reference [rad, rad/s]
    """

    t: np.ndarray
    q: np.ndarray
    tau: np.ndarray
    q_true: np.ndarray
    dq_true: np.ndarray
    ddq_true: np.ndarray
    tau_applied: np.ndarray
    q_ref: np.ndarray = field(repr=False)
    dq_ref: np.ndarray = field(repr=False)


class JointDynamics:
    """Direct dynamics of a robot with given standard parameters: ``q̈ = M(q)⁻¹ (τ − h(q, q̇))``, or, with joints
    that follow others (``<mimic>``), ``q̈ = G (GᵀMG)⁻¹ Gᵀ (τ − h)`` with the followers' torques 0 (module docstring).

    The rigid bodies are Pinocchio's (CRBA and non-linear effects); the drive terms are dynid's friction table:
    their inertia (rotor inertia, coupled motors) is constant and joins ``M``; their velocity terms join ``h``.

    Parameters
    ----------
    robot : Robot
    phi : (n_params,) array, optional
        Standard parameters (the robot's nominal ones by default). They need not be physically consistent (a model
        of base parameters embedded in the standard space): CRBA and RNEA are linear in them, but each link's mass
        must not be zero.

    Raises
    ------
    ConfigError
        A link of zero mass in ``phi`` (Pinocchio cannot place its centre of mass).
    """

    def __init__(self, robot: Robot, phi: np.ndarray | None = None):
        robot = robot if phi is None else robot.with_parameters(np.asarray(phi, dtype=float))
        masses = robot.inertial[:, 9]
        if np.any(np.abs(masses) < 1e-12):
            k = int(np.argmin(np.abs(masses)))
            raise ConfigError(f"closed-loop simulation: link {k + 1} has zero mass in the parameters simulated")
        import pinocchio as pin

        self._pin = pin
        self.robot = robot
        self.model = pinocchio_model(robot, robot.inertial)
        self.data = self.model.createData()
        n = robot.n_dof
        zeros = np.zeros((n, n))
        self.drive_inertia = (friction_torques(robot, zeros, np.eye(n)) - friction_torques(robot, zeros[:1], zeros[:1])[0]).T
        self._fast = set(robot.drive_terms) <= _FAST_TERMS
        values = dict(zip(robot.drive_terms, (robot.drive * robot.drive_mask).T))
        self._fc, self._fv, self._offset = (values.get(k, np.zeros(n)) for k in ("fc", "fv", "offset"))
        self._vs = np.asarray(robot.coulomb_velocity, dtype=float)
        self._smooth = bool(np.any(self._vs > 0))
        self._coupled = robot.transmission.n_coupled_params > 0
        if self._coupled:  # the coupled motors' velocity terms: their columns at zero acceleration
            self._coupled_values = np.ravel(robot.transmission.coupled_values)
            self._no_acceleration = np.zeros((1, n))
        self._lower = np.tril_indices(n, -1)
        # a diagonal drive inertia (rotor inertias, no coupled motor) is Pinocchio's armature: ABA then gives q̈ in one
        # call; a coupled motor's inertia is off the diagonal, and a <mimic> joint moves with its master: M from CRBA,
        # solved (projected onto the coupling, module docstring)
        off_diagonal = self.drive_inertia - np.diag(np.diag(self.drive_inertia))
        self.followers = list(robot.followers)
        self._coupling = np.eye(n)[:, robot.independent]  # G: q̇ = G ν
        for j in self.followers:
            k, multiplier, _ = robot.joints[j].mimic  # type: ignore[misc]
            self._coupling[j] = multiplier * self._coupling[k]
        self._aba = not np.any(off_diagonal) and not self.followers
        if self._aba:
            self.model.armature = np.diag(self.drive_inertia).copy()

    def simple_drive_terms(self) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The drive terms as three per-joint vectors, when they are only these and the rotor inertias (Pinocchio's
        armature): the simulator's compiled stages then add them (:mod:`dynid.simulation._step_kernel`).

        Returns
        -------
        (fc, fv, offset) : (n_dof,) arrays [N·m, N·m·s/rad, N·m], or None
            None with coupled motors, joints that follow others, a smoothed Coulomb friction or other drive terms.
        """
        if self._aba and self._fast and not self._smooth and not self._coupled:
            return self._fc, self._fv, self._offset
        return None

    def drive_torques(self, dq: np.ndarray) -> np.ndarray:
        """Torques of the drive terms at zero acceleration (friction, offset, coupled motors' friction).

        Parameters
        ----------
        dq : (n_dof,) array [rad/s]

        Returns
        -------
        (n_dof,) array [N·m]
        """
        if not self._fast:
            return friction_torques(self.robot, dq[None], np.zeros((1, dq.size)))[0]
        if self._smooth:
            s = np.where(self._vs > 0, np.tanh(dq / np.where(self._vs > 0, self._vs, 1.0)), np.sign(dq))
        else:
            s = np.sign(dq)
        tau = self._fc * s + self._fv * dq + self._offset
        if self._coupled:
            tau = tau + self.robot.transmission.coupling_columns(dq[None], self._no_acceleration)[0] @ self._coupled_values
        return tau

    def mass_and_bias(self, q: np.ndarray, dq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``M(q)`` and ``h(q, q̇)``, so that the joint torque is ``M q̈ + h``.

        Parameters
        ----------
        q, dq : (n_dof,) arrays [rad, rad/s]

        Returns
        -------
        m : (n_dof, n_dof) array [kg·m²]
        h : (n_dof,) array [N·m]
        """
        pin = self._pin
        m = pin.crba(self.model, self.data, q).copy()  # CRBA fills the upper triangle
        m[self._lower] = m.T[self._lower]
        m = m + (0.0 if self._aba else self.drive_inertia)  # armature: in CRBA's M already
        return m, pin.nonLinearEffects(self.model, self.data, q, dq) + self.drive_torques(dq)

    def accelerations(self, q: np.ndarray, dq: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Direct dynamics.

        Parameters
        ----------
        q, dq, tau : (n_dof,) arrays [rad, rad/s, N·m]

        Returns
        -------
        (n_dof,) array [rad/s²]
        """
        if self._aba:
            return self._pin.aba(self.model, self.data, q, dq, tau - self.drive_torques(dq))
        m, h = self.mass_and_bias(q, dq)
        if not self.followers:
            return np.linalg.solve(m, tau - h)
        g = self._coupling
        tau = tau.copy()
        tau[self.followers] = 0.0  # a follower has no drive
        return g @ np.linalg.solve(g.T @ m @ g, g.T @ (tau - h))


def simulate_closed_loop(robot: Robot, t, q_ref, dq_ref, controller: Controller, noise: ClosedLoopNoise = ClosedLoopNoise(),
                         *, rng: np.random.Generator | None = None, phi: np.ndarray | None = None,
                         feedforward=None) -> ClosedLoopRun:
    """Run the controller on the robot along a reference, at the control rate.

    Parameters
    ----------
    robot : Robot
    t : (N,) array [s]
        Control instants, ``1/controller.rate`` apart.
    q_ref, dq_ref : (N, n_dof) arrays
        The reference [rad, rad/s]; the run starts on it, at rest or moving as it does.
    controller : Controller
    noise : ClosedLoopNoise
    rng : numpy.random.Generator, optional
        Draws the noise (required when there is noise).
    phi : (n_params,) array, optional
        Standard parameters simulated (the robot's nominal ones by default; an estimate's, for IDIM-IV and DIDIM).
    feedforward : (N, n_dof) array [N·m], optional
        Torques added to the feedback at each instant (e.g. a nominal model's inverse dynamics of the reference).

    Returns
    -------
    ClosedLoopRun

    Raises
    ------
    ShapeError
        Arrays of other shapes than (N, n_dof), or instants not ``1/rate`` apart.
    ConfigError
        Noise without ``rng`` or parameters with a massless link.

    Notes
    -----
    A joint that follows another (``<mimic>``) moves as it says whatever its reference columns hold, and its commanded
    torque is 0 (module docstring).
    """
    n = robot.n_dof
    t = np.asarray(t, dtype=float).reshape(-1)
    q_ref, dq_ref = (np.asarray(x, dtype=float) for x in (q_ref, dq_ref))
    ff = np.zeros((t.size, n)) if feedforward is None else np.asarray(feedforward, dtype=float)
    for name, x in (("q_ref", q_ref), ("dq_ref", dq_ref), ("feedforward", ff)):
        if x.shape != (t.size, n):
            raise ShapeError(f"{name}: expected shape ({t.size}, {n}), got {x.shape}")
    q_ref, dq_ref = robot.coupled(q_ref, dq_ref)[:2]
    h = 1.0 / controller.rate
    if t.size < 2 or not np.allclose(np.diff(t), h, rtol=1e-6, atol=1e-12):
        raise ShapeError(f"t: expected instants 1/rate = {h:.6g} s apart")
    noisy = noise.position_std > 0 or noise.encoder_resolution > 0 or noise.torque_std > 0
    if noisy and rng is None:
        raise ConfigError("closed-loop simulation with noise needs an rng (np.random.default_rng(seed))")
    rng = rng if rng is not None else np.random.default_rng(0)
    dynamics = JointDynamics(robot, phi)
    with np.errstate(over="ignore", invalid="ignore"):  # a diverging run is refused in one line, not warned about
        return _run_loop(t, q_ref, dq_ref, ff, controller=controller, dynamics=dynamics, noise=noise, rng=rng)


def _run_loop(t, q_ref, dq_ref, ff, *, controller: Controller, dynamics: JointDynamics, noise: ClosedLoopNoise, rng):
    """:func:`simulate_closed_loop`'s loop over the control instants (the arithmetic between two calls of the direct
    dynamics in :mod:`dynid.simulation._step_kernel`, in place in its work array)."""
    control, stage, advance = kernel.compiled()
    n = q_ref.shape[1]
    h = 1.0 / controller.rate
    # first-order low-pass of the differenced positions (backward Euler): v ← v + α (raw − v)
    alpha = 1.0 if controller.velocity_cutoff == 0 else 1.0 - np.exp(-2 * np.pi * controller.velocity_cutoff * h)
    w = np.zeros((kernel.ROWS, n))
    w[kernel.Q], w[kernel.DQ], w[kernel.VELOCITY] = q_ref[0], dq_ref[0], dq_ref[0]
    w[kernel.KP], w[kernel.KD], w[kernel.KI] = controller.kp, controller.kd, controller.ki
    followers = dynamics.followers
    w[kernel.DRIVEN] = 1.0
    w[kernel.DRIVEN, followers] = 0.0  # a <mimic> joint has no drive: its master moves it
    drive = dynamics.simple_drive_terms()
    if drive is not None:  # the drive terms in the stages, the rigid body by Pinocchio's ABA
        w[kernel.FC], w[kernel.FV], w[kernel.OFFSET] = drive
        aba, model, data = dynamics._pin.aba, dynamics.model, dynamics.data

        def accelerations(x, v, tau, u):
            return aba(model, data, x, v, u)
    else:  # coupled motors, smoothed Coulomb friction, other drive terms: the dynamics' own (the stages' terms 0)

        def accelerations(x, v, tau, u):
            return dynamics.accelerations(x, v, tau)
    # the encoder's noise drawn at once: the same numbers as one draw per instant (a Generator's stream)
    draws = rng.normal(0.0, noise.position_std, (t.size, n)) if noise.position_std > 0 else None
    reading = (kernel.READING_GIVEN if noise.encoder_resolution > 0 else kernel.READING_NOISY if draws is not None
               else kernel.READING_ITSELF)
    refs, out = np.stack([q_ref, dq_ref, ff]), np.empty((5, t.size, n))
    noise_rows = draws if draws is not None else refs[0]  # read by the kernel only for READING_NOISY
    q, dq, tau, u, qs, v2, v3, v4 = (w[r] for r in (kernel.Q, kernel.DQ, kernel.TAU, kernel.U, kernel.QS, kernel.V2,
                                                    kernel.V3, kernel.V4))
    for k in range(t.size):
        if reading == kernel.READING_GIVEN:
            w[kernel.Y] = noise.measured_positions(q, rng, None if draws is None else draws[k])
        control(k, w, refs, noise_rows, reading, alpha, h)
        # classic Runge-Kutta on (q, q̇) with the torque held
        stage(k, w, accelerations(q, dq, tau, u), 0, 0.5 * h, out)
        stage(k, w, accelerations(qs, v2, tau, u), 1, 0.5 * h, out)
        stage(k, w, accelerations(qs, v3, tau, u), 2, h, out)
        finite = advance(w, accelerations(qs, v4, tau, u), h)
        if followers:  # on its coupling to the last bit, not to the integrator's rounding
            q[:], dq[:] = dynamics.robot.coupled(q, dq)[:2]
            finite = math.isfinite(q.dot(q) + dq.dot(dq))
        if not finite:  # a NaN or an infinity anywhere (or a state beyond 1e154) makes it one
            raise ConfigError(f"closed-loop simulation diverged at t = {t[k]:.3f} s: gains too high for the control rate, "
                              "or a model that cannot be simulated")
    q_true, dq_true, ddq_true, tau_applied, q_meas = out
    tau_log = tau_applied + rng.normal(0.0, noise.torque_std, tau_applied.shape) if noise.torque_std > 0 else tau_applied.copy()
    return ClosedLoopRun(t, q_meas, tau_log, q_true, dq_true, ddq_true, tau_applied, q_ref, dq_ref)

