"""A URDF or MJCF that ``dynid export`` writes, read back by the tool it is meant for (Pinocchio, MuJoCo) and checked
against dynid's own model (issue "The model proven where it goes", item 1).

A converter or a writer that drops a value (a URDF→MJCF converter dropping off-diagonal inertia is a known case) gives
a file whose torques are not the model's. :func:`urdf_replay` parses the written text with Pinocchio's URDF parser (the
joints the robot holds fixed locked at 0, as dynid identified them), evaluates its inverse dynamics (RNEA) plus the
joints' ``<dynamics>`` friction (``damping·q̇ + friction·sign(q̇)``) at random states within the joint limits, and
compares them with dynid's torques of the same estimate restricted to what a URDF can hold: the links' inertial
parameters, viscous friction and Coulomb friction with ``sign(q̇)``. What URDF cannot hold (rotor inertia, offsets,
a smooth Coulomb term, Stribeck, asymmetric and load-dependent friction, counterbalances) is measured apart: each
joint's RMS torque of those terms over its RMS torque on the same states. Reference: Carpentier et al., "The
Pinocchio C++ library", SII 2019 (RNEA, the URDF parser).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from numpy.polynomial import polynomial

from ..._util.reprs import short_repr
from ...dynamics.regressor import regressor
from ...model.description_files import COUPLED_TENDON, OFFSET_ACTUATOR, WORLD_JOINT
from ...model.robot import Robot

__all__ = ["MJCF_TERMS", "URDF_TERMS", "ForwardCheck", "ReplayCheck", "mjcf_forward", "mjcf_replay", "urdf_replay"]

URDF_TERMS = ("fc", "fv")
"""The drive terms a URDF's ``<dynamics>`` holds (``friction``, ``damping``)."""

MJCF_TERMS = ("Ia", "fc", "fv")
"""The drive terms an MJCF hinge holds (``armature``, ``frictionloss``, ``damping``)."""


@short_repr
@dataclass(frozen=True)
class ReplayCheck:
    """A written file's torques against dynid's model.

    Attributes
    ----------
    relative_error : float
        ``||τ_file - τ_dynid|| / ||τ_dynid||`` over the states, dynid's torques of what the format holds.
    missing : tuple of str
        The drive terms of the model the format cannot hold (non-zero in the estimate).
    missing_share : (n_dof,) array [%]
        Each joint's RMS torque of those terms over its RMS torque, on the same states.
    n_states : int
    frictionloss_gap : float
        MJCF only: how far MuJoCo's ``frictionloss`` constraint force in ``mj_inverse`` is from
        ``frictionloss·sign(q̇)`` on the same states, over the norm of the latter (0 without dry friction).
    file_vs_measured, model_vs_measured : float [%] or None
        On a log's states (``measured`` given): the file's torques as its simulator computes them (MuJoCo's
        ``frictionloss`` its constraint's) and dynid's whole model against the log's measured torque, ``100·||τ - τ_measured|| / ||τ_measured||`` on the same samples. Their difference is what the format's
        missing terms cost on that log.
    simulator_gap : (n_dof,) array [%]
        What the target simulator computes from the file, with its own semantics (Pinocchio's RNEA and the URDF's
        ``<dynamics>``; MuJoCo's ``mj_inverse`` with its ``frictionloss`` constraint as MuJoCo solves it), against
        dynid's whole model on the same states: each joint's RMS difference over its RMS torque.
    followers : tuple of int
        The joints that follow another (``<mimic>``): their torque is in the row of the joint they follow, on both
        sides, so their own figures above are 0.
    """

    relative_error: float
    missing: tuple[str, ...]
    missing_share: np.ndarray
    n_states: int
    frictionloss_gap: float = 0.0
    file_vs_measured: float | None = None
    model_vs_measured: float | None = None
    simulator_gap: np.ndarray | None = None
    followers: tuple[int, ...] = ()


def _states(robot: Robot, n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random states: positions within the joint limits (±π where there are none), a joint that others follow only where
    they stay within theirs too (out of range, a simulator's joint limit acts: not the model's torque), velocities and
    accelerations of a few rad/s and rad/s² (within their limits where given)."""
    lim = robot.limits
    q = lim.random_positions(n, rng, span=robot.coupled_span())
    dq = rng.uniform(-1.0, 1.0, (n, robot.n_dof)) * np.minimum(np.where(np.isfinite(lim.dq_max), lim.dq_max, 2.0), 2.0)
    ddq = rng.uniform(-1.0, 1.0, (n, robot.n_dof)) * np.minimum(np.where(np.isfinite(lim.ddq_max), lim.ddq_max, 5.0), 5.0)
    return q, dq, ddq


def urdf_replay(text: str, robot: Robot, phi: np.ndarray, *, n_states: int = 200, rng=0, states=None,
                measured=None, whole=None) -> ReplayCheck:
    """Pinocchio's torques of a written URDF against dynid's torques of ``phi`` (module docstring).

    Parameters
    ----------
    text : str
        The URDF as written.
    robot : Robot
        The model ``phi`` is of (its joints carry the URDF's joint names; its held joints are locked at 0).
    phi : (n_params,) array
        The standard parameters written.
    n_states : int
        Random states compared.
    rng : int or Generator
        Seeds the states.
    states : (q, dq, ddq) of (N, n_dof) arrays, optional
        A log's states instead of random ones [rad, rad/s, rad/s²].
    measured : (N, n_dof) array [N·m], optional
        The log's measured torque on ``states``: the file and dynid's model are also scored against it.
    whole : (n_params,) array, optional
        dynid's whole model, where the file holds another set (its friction folded,
        :func:`dynid.io.exported.export.file_parameters`); default ``phi``.

    Returns
    -------
    ReplayCheck
    """
    import pinocchio as pin

    rng = np.random.default_rng(rng)
    model = pin.buildModelFromXML(text)
    if robot.held:
        model = pin.buildReducedModel(model, [model.getJointId(h) for h in robot.held], pin.neutral(model))
    if not model.existFrame(WORLD_JOINT):  # the user's URDF written back: its root is the base, the gravity the config's
        model.gravity.linear = np.asarray(robot.gravity, dtype=float)
    data = model.createData()
    ids = [model.getJointId(j.name) for j in robot.joints]
    q, dq, ddq = robot.coupled(*(_states(robot, n_states, rng) if states is None else states))
    q, dq, ddq = (np.asarray(x, dtype=float) for x in (q, dq, ddq))
    n_s = q.shape[0]
    big_q = np.tile(pin.neutral(model), (n_s, 1))  # every sample's configuration, velocity, acceleration at once
    big_v, big_a = np.zeros((n_s, model.nv)), np.zeros((n_s, model.nv))
    idx = [model.joints[jid].idx_v for jid in ids]
    for j, jid in enumerate(ids):
        iq = model.joints[jid].idx_q
        if model.joints[jid].nq == 2:  # continuous: (cos, sin)
            big_q[:, iq], big_q[:, iq + 1] = np.cos(q[:, j]), np.sin(q[:, j])
        else:
            big_q[:, iq] = q[:, j]
    big_v[:, idx], big_a[:, idx] = dq, ddq
    tau_file = np.empty(q.shape)
    for k in range(n_s):
        tau_file[k] = pin.rnea(model, data, big_q[k], big_v[k], big_a[k])[idx]
    tau_file += model.damping[idx] * dq + model.friction[idx] * np.sign(dq)
    return _compared(robot.fold(tau_file), robot, phi, (q, dq, ddq), URDF_TERMS, measured, whole=whole)


def _compared(tau_file: np.ndarray, robot: Robot, phi: np.ndarray, states: tuple, held_terms: tuple[str, ...],
              measured: np.ndarray | None = None, simulated: np.ndarray | None = None,
              whole: np.ndarray | None = None) -> ReplayCheck:
    """The file's torques against dynid's of ``phi`` restricted to the links and the drive terms ``held_terms`` a format
    holds (Coulomb friction with ``sign(q̇)``), each joint's share of what the format cannot hold, both against the
    ``measured`` torque where given, and the ``simulated`` torque (default the file's) against dynid's whole model
    (``whole``, default ``phi``: the model the file was written from, where its friction is folded)."""
    q, dq, ddq = states
    whole = phi if whole is None else np.asarray(whole, dtype=float)
    full = regressor(robot, q, dq, ddq) @ whole
    coupled = {n for n in robot.transmission.coupled_parameter_names if n.rstrip("0123456789") not in held_terms}
    drive = set(robot.drive_terms)
    kept = np.array([n not in coupled and (n.rstrip("0123456789") not in drive or n.rstrip("0123456789") in held_terms)
                     for n in robot.parameter_names])
    held_phi = np.where(kept, phi, 0.0)
    plain = replace(robot, coulomb_velocity=np.zeros(robot.n_dof))  # the formats' friction is fc·sign(q̇)
    model_tau = regressor(plain, q, dq, ddq) @ held_phi
    missing = tuple(sorted({n.rstrip("0123456789") for n, v, k in zip(robot.parameter_names, whole, kept)
                            if not k and v != 0} | ({"smooth Coulomb"} if np.any(robot.coulomb_velocity > 0) else set())))
    rms = np.sqrt(np.mean(full**2, axis=0))
    rms[list(robot.followers)] = np.inf  # a joint that follows another has no row of its own: 0 on both sides
    share = 100.0 * np.sqrt(np.mean((full - model_tau) ** 2, axis=0)) / np.maximum(rms, 1e-300)
    error = float(np.linalg.norm(tau_file - model_tau) / np.maximum(np.linalg.norm(model_tau), 1e-300))
    simulated = tau_file if simulated is None else simulated
    gap = 100.0 * np.sqrt(np.mean((full - simulated) ** 2, axis=0)) / np.maximum(rms, 1e-300)
    if measured is None:
        return ReplayCheck(error, missing, share, q.shape[0], simulator_gap=gap, followers=robot.followers)
    scale = max(float(np.linalg.norm(measured)), 1e-300)
    return ReplayCheck(error, missing, share, q.shape[0], file_vs_measured=100.0 * float(np.linalg.norm(simulated - measured)) / scale,
                       model_vs_measured=100.0 * float(np.linalg.norm(full - measured)) / scale, simulator_gap=gap,
                       followers=robot.followers)


def _offset_forces(model, robot: Robot, vadr: np.ndarray) -> np.ndarray:
    """(n_dof,) [N·m]: the constant joint forces of the actuators that hold torque offsets
    (:func:`dynid.model.description_files.offset_actuators`, named by :data:`dynid.model.description_files.OFFSET_ACTUATOR`), 0 where there is none:
    the torque a joint needs is MuJoCo's inverse dynamics less this force."""
    import mujoco

    out = np.zeros(robot.n_dof)
    for j, joint in enumerate(robot.joints):
        k = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, OFFSET_ACTUATOR.format(joint=joint.name))
        if k >= 0:
            out[j] = float(model.actuator_biasprm[k, 0]) * float(model.actuator_gear[k, 0])
    return out


def _tendon_friction(tendons: tuple, qvel: np.ndarray, vadr: np.ndarray) -> np.ndarray:
    """(n_dof,) [N·m]: the dry friction of dynid's coupled-motor tendons (:func:`_coupled_tendons`) as
    ``frictionloss·sign(J·q̇)·Jᵀ`` at the velocities ``qvel`` (nv,): what MuJoCo's constraint holds, as a joint's
    ``frictionloss·sign(q̇)`` is."""
    loss, jac = tendons
    return ((loss * np.sign(jac @ qvel)) @ jac)[vadr]


def _coupled_tendons(model) -> tuple | None:
    """dynid's coupled-motor tendons in a model (named by :data:`dynid.model.description_files.COUPLED_TENDON`): their
    ``frictionloss`` (n,) and Jacobians (n, nv), a fixed tendon's coefficients on its joints' dofs; None without one."""
    import mujoco

    stem = COUPLED_TENDON.split("{")[0]
    ids = [t for t in range(model.ntendon) if (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_TENDON, t) or "").startswith(stem)]
    if not ids:
        return None
    jac = np.zeros((len(ids), model.nv))
    for row, t in enumerate(ids):
        for w in range(int(model.tendon_adr[t]), int(model.tendon_adr[t] + model.tendon_num[t])):
            jac[row, int(model.jnt_dofadr[model.wrap_objid[w]])] += float(model.wrap_prm[w])
    return np.array([float(model.tendon_frictionloss[t]) for t in ids]), jac


def mjcf_replay(text: str, robot: Robot, phi: np.ndarray, *, n_states: int = 200, rng=0, states=None,
                measured=None, whole=None) -> ReplayCheck:
    """MuJoCo's torques of a written MJCF against dynid's torques of ``phi``: the links, ``armature`` (rotor inertia),
    ``damping`` (viscous friction), ``frictionloss`` (Coulomb friction) and, where the file has dynid's offset actuators
    (:func:`dynid.model.description_files.offset_actuators`), the torque offsets (module docstring).

    MuJoCo's inverse dynamics (``mj_inverse``) is evaluated with the dry-friction constraint off, and the file's
    ``frictionloss`` added as ``frictionloss·sign(q̇)``: that checks the value the file holds. How MuJoCo's own
    ``frictionloss`` constraint differs from ``fc·sign(q̇)`` is measured apart (:attr:`ReplayCheck.frictionloss_gap`):
    it is a soft constraint whose force the solver finds, not a function of the velocity alone. Joints of the file
    that are not the robot's (a gripper's, held) stay at 0. Reference: Todorov, Erez & Tassa, "MuJoCo", IROS 2012.

    Parameters
    ----------
    text : str
        The MJCF as written (no assets beside it: a file whose meshes are elsewhere is loaded with them by path).
    robot : Robot
        The model ``phi`` is of (its joints carry the MJCF's joint names).
    phi : (n_params,) array
        The standard parameters written.
    n_states : int
    rng : int or Generator
    states : (q, dq, ddq) of (N, n_dof) arrays, optional
        A log's states instead of random ones [rad, rad/s, rad/s²].
    measured : (N, n_dof) array [N·m], optional
        The log's measured torque on ``states``: the file and dynid's model are also scored against it.
    whole : (n_params,) array, optional
        dynid's whole model, where the file holds another set (its friction folded,
        :func:`dynid.io.exported.export.file_parameters`); default ``phi``.

    Returns
    -------
    ReplayCheck

    Raises
    ------
    ValueError
        MuJoCo cannot load the text.
    """
    import mujoco

    rng = np.random.default_rng(rng)
    model = mujoco.MjModel.from_xml_string(text)
    data = mujoco.MjData(model)
    joints = [model.joint(j.name) for j in robot.joints]
    qadr = np.array([int(j.qposadr[0]) for j in joints])
    vadr = np.array([int(j.dofadr[0]) for j in joints])
    q, dq, ddq = robot.coupled(*(_states(robot, n_states, rng) if states is None else states))
    q, dq, ddq = (np.asarray(x, dtype=float) for x in (q, dq, ddq))
    dry = model.dof_frictionloss[vadr].copy()
    bias = _offset_forces(model, robot, vadr)
    coupled = _coupled_tendons(model)
    tau_file, with_constraint, tendons = np.empty(q.shape), np.empty(q.shape), np.zeros(q.shape)
    # a <mimic> joint's equality holds on the coupled states (its force 0); each joint's own torque is folded after
    for flags, out in ((mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS, tau_file), (0, with_constraint)):
        model.opt.disableflags = int(flags)
        for k in range(q.shape[0]):
            data.qpos[:], data.qvel[:], data.qacc[:] = model.qpos0, 0.0, 0.0
            data.qpos[qadr], data.qvel[vadr], data.qacc[vadr] = q[k], dq[k], ddq[k]
            mujoco.mj_inverse(model, data)
            out[k] = data.qfrc_inverse[vadr] - bias
            if flags and coupled is not None:
                tendons[k] = _tendon_friction(coupled, data.qvel, vadr)
    tau_file = robot.fold(tau_file + dry * np.sign(dq) + tendons)
    robot.fold(with_constraint)
    held = MJCF_TERMS + (("offset",) if np.any(bias) else ()) + (("fvm", "fcm") if coupled is not None else ())
    check = _compared(tau_file, robot, phi, (q, dq, ddq), held, measured, simulated=with_constraint, whole=whole)
    sliding = dry * np.sign(dq)
    gap = float(np.linalg.norm(with_constraint - tau_file) / np.maximum(np.linalg.norm(sliding), 1e-300)) if np.any(dry) else 0.0
    return replace(check, frictionloss_gap=gap)


@dataclass(frozen=True)
class ForwardCheck:
    """A written MJCF simulated along a log (:func:`mjcf_forward`).

    Attributes
    ----------
    simulated_vs_measured : float [%]
        The tracking torque MuJoCo needed against the log's measured torque, ``100·||τ_sim - τ||/||τ||``.
    model_vs_measured : float [%]
        dynid's inverse dynamics of the same estimate on the log's states against the measured torque, same samples.
    simulated_vs_model : float [%]
        The tracking torque against dynid's inverse dynamics (what the simulator adds: MuJoCo's frictionloss, the
        terms MJCF cannot hold, the tracking error).
    tracking_error : (n_dof,) array [rad]
        Each joint's largest distance from the log's positions during the simulation.
    n_samples : int
    substeps : int
        Integration steps per log sample.
    """

    simulated_vs_measured: float
    model_vs_measured: float
    simulated_vs_model: float
    tracking_error: np.ndarray
    n_samples: int
    substeps: int


SUBSTEPS, MIN_STEP = 40, 25e-6
"""[1, s] :func:`mjcf_forward`'s integration steps per log sample by default: 40, none shorter than 25 µs (a 5 kHz log
takes 8). 40 track every real log at 100-250 Hz; 10 on a 100 Hz log with a 10 Hz loop let the LBR Med7's simulation
lose stability (benchmarks/NOTEBOOK.md, "Stop 108", has the step sweep)."""


def mjcf_forward(text: str, robot: Robot, phi: np.ndarray, t, q, dq, ddq, tau, *, substeps: int | None = None,
                 bandwidth: float = 30.0, progress: Callable[[int, int], None] | None = None) -> ForwardCheck:
    """Simulate a written MJCF along a log's motion and compare the torques it needs with the measured ones (issue
    "The model proven where it goes", item 3).

    MuJoCo's forward dynamics of the file (its frictionloss a constraint, its armature and damping as written), from
    the log's first state, driven by a computed-torque controller: the file's own inverse dynamics at the log's
    state (``mj_inverse`` with frictionloss off, plus ``frictionloss·sign(q̇)``) and a PD loop of ``bandwidth`` Hz on
    the inertia each joint's torque meets (``1/(M⁻¹)_jj`` at the first state), at the log's rate with ``substeps``
    integration steps per sample (the reference between samples the quintic Hermite of the two samples' positions,
    velocities and accelerations: at every sample the arm is asked for the log's own state and acceleration, where
    the feed-forward was computed). What a simulator user sees: the torque the simulated arm needs to make
    the log's motion, against the torque the real arm needed.

    Parameters
    ----------
    text : str
        The MJCF as written.
    robot : Robot
        The model ``phi`` is of (its joint names are the MJCF's).
    phi : (n_params,) array
        The standard parameters written.
    t : (N,) array [s]
    q, dq, ddq : (N, n_dof) arrays [rad, rad/s, rad/s²]
        The log's states (filtered, as dynid prepares them).
    tau : (N, n_dof) array [N·m]
        The measured torques on the same samples.
    substeps : int, optional
        Integration steps per log sample; default :data:`SUBSTEPS`, fewer where a step would be shorter than
        :data:`MIN_STEP` (it was 40 whatever the log's rate).
    bandwidth : float [Hz]
    progress : callable, optional
        ``progress(done, total)`` in samples simulated, every :data:`PROGRESS_SAMPLES` and at the end.

    Returns
    -------
    ForwardCheck

    Raises
    ------
    ValueError
        MuJoCo cannot load the text.
    """
    import mujoco

    model = mujoco.MjModel.from_xml_string(text)
    data = mujoco.MjData(model)
    vadr = np.array([int(model.joint(j.name).dofadr[0]) for j in robot.joints])
    qadr = np.array([int(model.joint(j.name).qposadr[0]) for j in robot.joints])
    t, q, dq, ddq, tau = (np.asarray(x, dtype=float) for x in (t, q, dq, ddq, tau))
    interval = float(np.median(np.diff(t)))
    if substeps is None:
        substeps = int(np.clip(np.floor(interval / MIN_STEP + 1e-9), 1, SUBSTEPS))
    step = interval / substeps
    model.opt.timestep = step
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST  # stable where a light wrist meets its frictionloss
    frictionless = mujoco.MjModel.from_xml_string(text)  # the file's inverse dynamics, its dry friction as sign(q̇)
    frictionless.opt.timestep, frictionless.opt.integrator = model.opt.timestep, model.opt.integrator
    frictionless.opt.disableflags = int(mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS)
    inverse = mujoco.MjData(frictionless)
    dry = model.dof_frictionloss[vadr].copy()
    bias = _offset_forces(model, robot, vadr)  # the offset actuators act in the simulation: the torque applied is less
    coupled = _coupled_tendons(model)

    inverse.qpos[:], inverse.qvel[:], inverse.qacc[:] = model.qpos0, 0.0, 0.0  # mj_inverse reads them, never writes

    def feed_forward(qk, vk, ak):
        inverse.qpos[qadr], inverse.qvel[vadr], inverse.qacc[vadr] = qk, vk, ak
        mujoco.mj_inverse(frictionless, inverse)
        own = inverse.qfrc_inverse[vadr] + dry * np.sign(vk) - bias + (_tendon_friction(coupled, inverse.qvel, vadr) if coupled is not None else 0.0)
        return robot.fold(own[None])[0]  # a joint that follows another is driven through its equality by that joint

    data.qpos[:] = model.qpos0
    data.qpos[qadr], data.qvel[vadr] = q[0], dq[0]
    mujoco.mj_forward(model, data)
    full = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, full)
    inertia = 1.0 / np.diag(np.linalg.inv(full))[vadr]  # the inertia a joint's torque meets with the others free:
    # a light wrist coupled to its heavier neighbours meets far less than its own diagonal, and gains from the diagonal
    # made the LBR Med7's simulation unstable
    inertia[list(robot.followers)] = 0.0  # no drive of its own: no loop
    kp, kd = inertia * (2 * np.pi * bandwidth) ** 2, 2 * 0.9 * inertia * 2 * np.pi * bandwidth
    applied = np.empty_like(tau)
    worst = np.zeros(robot.n_dof)
    weights = _hermite_weights(substeps)
    for k in range(t.size):
        if progress is not None and k % PROGRESS_SAMPLES == 0:
            progress(k, t.size)
        references = _between(t, q, dq, ddq, k, weights if k < t.size - 1 else weights[:, :, :1])
        for s in range(substeps if k < t.size - 1 else 1):
            ref = [x[s] for x in references]
            u = feed_forward(*ref) + kp * (ref[0] - data.qpos[qadr]) + kd * (ref[1] - data.qvel[vadr])
            if s == 0:
                applied[k] = u
                worst = np.maximum(worst, np.abs(data.qpos[qadr] - q[k]))
            data.qfrc_applied[:] = 0.0
            data.qfrc_applied[vadr] = u
            mujoco.mj_step(model, data)
    if progress is not None:
        progress(t.size, t.size)
    modelled = regressor(robot, q, dq, ddq) @ phi
    rel = lambda a, b: 100.0 * float(np.linalg.norm(a - b)) / max(float(np.linalg.norm(b)), 1e-300)  # noqa: E731
    return ForwardCheck(rel(applied, tau), rel(modelled, tau), rel(applied, modelled), worst, int(t.size), substeps)


_QUINTIC = np.array([[1, 0, 0, -10, 15, -6], [0, 1, 0, -6, 8, -3], [0, 0, 0.5, -1.5, 1.5, -0.5],
                     [0, 0, 0, 0.5, -1, 0.5], [0, 0, 0, -4, 7, -3], [0, 0, 0, 10, -15, 6]], dtype=float)
"""The quintic Hermite basis on ``w`` in [0, 1], coefficients of ``w⁰ … w⁵``, weighing in turn the first sample's
position, velocity·h and acceleration·h², the second's acceleration·h², velocity·h and position."""


PROGRESS_SAMPLES = 500
"""Samples :func:`mjcf_forward` simulates between two reports of its progress."""


def _hermite_weights(substeps: int) -> np.ndarray:
    """(3, 6, substeps, 1): for each fraction ``w = s / substeps`` of a sample interval, the quintic Hermite basis
    (:data:`_QUINTIC`) and its first and second derivatives in ``w``."""
    w = np.arange(substeps, dtype=float) / substeps
    return np.stack([polynomial.polyval(w, polynomial.polyder(_QUINTIC, d, axis=1).T) for d in range(3)])[..., None]


def _between(t, q, dq, ddq, k: int, weights: np.ndarray) -> list:
    """The references at the fractions of :func:`_hermite_weights` of the way from sample ``k`` to the next: the
    quintic Hermite of the two samples' positions, velocities and accelerations, and its derivatives; each
    (substeps, n_dof). At each sample the reference is the log's state itself, its acceleration the one the
    feed-forward is computed from (a cubic of positions and velocities alone has an acceleration of its own there,
    encoder noise over Δt², which a stiff loop then makes the arm follow)."""
    nxt = min(k + 1, t.size - 1)
    h = t[nxt] - t[k]
    if h <= 0:
        return [np.broadcast_to(x[k], (weights.shape[2], x.shape[1])) for x in (q, dq, ddq)]
    ends = np.stack([q[k], h * dq[k], h * h * ddq[k], h * h * ddq[nxt], h * dq[nxt], q[nxt]])  # (6, n_dof)
    return [np.einsum("bs,bj->sj", weights[d, :, :, 0], ends) / h**d for d in range(3)]
