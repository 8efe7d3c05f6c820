"""Robot logs simulated in MuJoCo, outside dynid's model, with the imperfections of real logs.

The robot is a URDF read by MuJoCo's own parser (not dynid's, not Pinocchio's), with MuJoCo's joint
``armature`` (rotor inertia), ``damping`` (viscous friction) and ``frictionloss`` (dry friction: a
constraint, so at rest it is whatever torque holds the joint, at most ``frictionloss``). A joint-space
controller drives it: the feed-forward of a frictionless rigid model plus a PID loop on the *measured*
positions, at the control rate; the log records what the controller commands (as a motor current or a
torque sensor would), with

* positions quantised by an encoder and carrying broadband noise, scaled so that the noise holds a given
  share of the velocity energy of the positions' spectrum (the quantity dynid's band rule looks at);
* torques with Gaussian noise;
* time stamps with jitter (the samples are taken at the jittered instants), a few gaps of 5-10 ms, and
  optionally a sampling rate that changes by a given fraction half-way through the file;
* a slow Fourier excitation, or point-to-point moves with long rests.

The truth is the URDF's inertia plus ``armature → Ia``, ``damping → fv``, ``frictionloss → fc`` per joint.

A joint that follows another (a URDF ``<mimic>``, which MuJoCo's parser reads as a joint equality) is passive: the
controller drives its master only, whose command holds the follower's feed-forward (virtual work), and MuJoCo's
equality, made stiff (its time constant two integration steps), moves the follower; the log still holds every joint's
columns, the follower's torque 0 (a writer keeps the coordinates' columns, as a robot's log holds them).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np


def stripped_urdf(text: str) -> str:
    """The URDF without visual, collision, gazebo and transmission elements (MuJoCo would look for meshes)."""
    for tag in ("visual", "collision", "gazebo", "transmission"):
        text = re.sub(rf"<{tag}\b.*?</{tag}>", "", text, flags=re.S)
    return re.sub(r"<!--.*?-->", "", text, flags=re.S)


@dataclass(frozen=True)
class Drives:
    """Per-joint drive truth: rotor inertia Ia [kg·m²], viscous fv [N·m·s/rad], dry friction fc [N·m]."""

    ia: np.ndarray
    fv: np.ndarray
    fc: np.ndarray


def mujoco_model(urdf_text: str, drives: Drives | None, timestep: float):
    """A MuJoCo model of the URDF with the drives' armature, damping and frictionloss on its hinges and slides."""
    import mujoco

    # MuJoCo's URDF extension: its compiler tag sits inside <robot>
    xml = re.sub(r"(<robot\b[^>]*>)", r'\1<mujoco><compiler discardvisual="true" fusestatic="false" balanceinertia="false"/></mujoco>',
                 stripped_urdf(urdf_text), count=1)
    spec = mujoco.MjSpec.from_string(xml)
    spec.option.timestep = timestep
    for equality in spec.equalities:  # a <mimic>: a rigid coupling, not MuJoCo's default soft one
        equality.solref = [2 * timestep, 1.0]
        equality.solimp = [0.9999, 0.9999, 0.001, 0.5, 2.0]
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    hinges = [j for j in spec.joints if j.type in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)]
    if drives is not None:
        for j, h in enumerate(hinges):
            h.armature = float(drives.ia[j])
            h.damping = [float(drives.fv[j]), 0.0, 0.0]  # MuJoCo 4: linear, then higher-order terms
            h.frictionloss = float(drives.fc[j])
    return spec.compile()


def couplings(model) -> list[tuple[int, int, float, float]]:
    """The model's joint equalities (MuJoCo's reading of a URDF's ``<mimic>``) as ``(follower, master, multiplier,
    offset)`` dof indices: ``q_follower = offset + multiplier·q_master``."""
    import mujoco

    return [(int(model.jnt_dofadr[model.eq_obj1id[e]]), int(model.jnt_dofadr[model.eq_obj2id[e]]),
             float(model.eq_data[e, 1]), float(model.eq_data[e, 0]))
            for e in range(model.neq) if model.eq_type[e] == mujoco.mjtEq.mjEQ_JOINT and model.eq_obj2id[e] >= 0]


def coupled(pair: tuple, coupling) -> tuple:
    """``(q, dq, ddq)`` with each follower's columns set from its master's (:func:`couplings`)."""
    q, dq, ddq = (x.copy() for x in pair)
    for follower, master, multiplier, offset in coupling:
        q[:, follower] = offset + multiplier * q[:, master]
        dq[:, follower], ddq[:, follower] = multiplier * dq[:, master], multiplier * ddq[:, master]
    return q, dq, ddq


def folded(tau: np.ndarray, coupling) -> np.ndarray:
    """Joint torques ``(..., n)`` with each follower's added to its master's times the multiplier and its own 0: what
    the master's drive gives for both (virtual work); the follower has no drive."""
    tau = np.array(tau, dtype=float)
    for follower, master, multiplier, _ in coupling:
        tau[..., master] += multiplier * tau[..., follower]
        tau[..., follower] = 0.0
    return tau


def fourier_reference(t, n, rng, f0, harmonics, amplitude, centre):
    """A sum of ``harmonics`` harmonics of ``f0`` Hz per joint (amplitude ``amplitude`` rad at most), with
    exact derivatives; it starts and ends at rest where the log is a whole number of periods."""
    k = np.arange(1, harmonics + 1)[:, None]
    a = rng.normal(size=(harmonics, n)) / k
    b = rng.normal(size=(harmonics, n)) / k
    b -= b.sum(axis=0) / harmonics  # q(0) = centre
    w = 2 * np.pi * f0 * k
    arg = w[:, :, None] * t[None, None, :]
    q = (a[:, :, None] * np.sin(arg) + b[:, :, None] * np.cos(arg)).sum(0).T
    dq = (a[:, :, None] * w[:, :, None] * np.cos(arg) - b[:, :, None] * w[:, :, None] * np.sin(arg)).sum(0).T
    ddq = -(a[:, :, None] * w[:, :, None] ** 2 * np.sin(arg) + b[:, :, None] * w[:, :, None] ** 2 * np.cos(arg)).sum(0).T
    s = amplitude / np.abs(q).max(axis=0)
    return centre + q * s, dq * s, ddq * s


def ptp_reference(t, n, rng, amplitude, centre, segment=1.6, rest=1.2):
    """Random targets joined by quintic moves of ``segment`` s, each followed by ``rest`` s at rest; joints
    move one group at a time (some joints rest while others move)."""
    period = segment + rest
    n_seg = int(np.ceil(t[-1] / period)) + 1
    pts = centre + amplitude * rng.uniform(-1, 1, (n_seg + 1, n))
    pts[0] = centre
    moving_joints = rng.uniform(size=(n_seg, n)) < 0.7
    for i in range(1, n_seg + 1):
        pts[i] = np.where(moving_joints[i - 1], pts[i], pts[i - 1])
    i = np.minimum((t // period).astype(int), n_seg - 1)
    s = np.clip((t - i * period) / segment, 0.0, 1.0)[:, None]
    moving = ((t - i * period) < segment)[:, None]
    d = pts[i + 1] - pts[i]
    q = pts[i] + d * (10 * s**3 - 15 * s**4 + 6 * s**5)
    dq = d * (30 * s**2 - 60 * s**3 + 30 * s**4) / segment * moving
    ddq = d * (60 * s - 180 * s**2 + 120 * s**3) / segment**2 * moving
    return q, dq, ddq


@dataclass(frozen=True)
class SimulatedLog:
    """A simulated log: what the file holds and the true states at the same instants.

    Attributes
    ----------
    t : (N,) logged time stamps [s]
    q_meas, tau_meas : (N, n) measured positions [rad] and torques [N·m]
    q, dq, ddq, tau : (N, n) true states and the commanded (true) torques at the same instants
    """

    t: np.ndarray
    q_meas: np.ndarray
    tau_meas: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    tau: np.ndarray


def simulate(urdf_text: str, drives: Drives, motion: str, duration: float, rng: np.random.Generator, *,
             rate: float = 1000.0, substeps: int = 2, f0: float = 0.1, harmonics: int = 4, amplitude=0.6,
             encoder_bits: int = 20, noise_share: float = 0.05, torque_std=0.05, jitter: float = 0.02,
             gaps: int = 3, rate_change: float = 0.0, kp=None, kd=None, integral: float = 0.5,
             dry: str = "frictionloss", loop_noise: bool = False, controller: bool = True, centre=None,
             reference=None) -> SimulatedLog:
    """Simulate a log (module docstring).

    Parameters
    ----------
    motion : "fourier" or "ptp"
    rate : control and nominal logging rate [Hz]
    substeps : integration steps per control period
    f0, harmonics : the Fourier excitation's fundamental [Hz] and number of harmonics
    noise_share : share of the positions' velocity-weighted spectral energy that is broadband noise
    torque_std : float or (n,) [N·m]
    jitter : std of the sampling instants, as a fraction of the sampling period
    gaps : number of gaps of 5-10 samples in the log
    rate_change : the second half of the file is sampled at ``rate·(1 + rate_change)``
    kp, kd : PD gains per joint (default: from the joints' inertia)
    integral : float [Hz]
        Integral action of the loop, ``ki = kp·2π·integral`` (0: a PD loop); an industrial position loop has one,
        which keeps the torque a joint had when it stopped while static friction holds it.
    dry : "frictionloss" or "sign"
        The dry friction: MuJoCo's ``frictionloss`` constraint (at rest, whatever holds the joint, at most ``fc``),
        or ``fc·sign(q̇)`` applied as a force at every integration step (the textbook model, exactly dynid's
        Coulomb term while the joint moves).
    loop_noise : bool
        Whether the controller sees the positions' broadband noise (it always sees the encoder's quantisation):
        a loop that feeds noise back makes the torques' noise correlate with the positions', which biases least
        squares (the closed-loop identification problem); without it, the noise is the log's alone.
    centre : (n,) array, optional
        The pose the motion is about [rad] (default 0: every joint's zero, which some arms' ranges exclude).
    reference : callable, optional
        ``reference(t, n, rng, amplitude, centre) -> (q, dq, ddq)``: a motion of one's own instead of ``motion``'s.
    controller : bool
        False: the motion is the reference itself and the torques are MuJoCo's inverse dynamics of it (``mj_inverse``
        of the model without dry friction) plus ``fc·sign(q̇)`` (``dry = "sign"`` only): at rest the velocity is exactly
        0 and so is the dry friction.
    """
    import mujoco

    dt = 1.0 / rate / substeps
    model = mujoco_model(urdf_text, drives if dry == "frictionloss" else Drives(drives.ia, drives.fv, 0 * drives.fc), dt)
    sign_fc = drives.fc if dry == "sign" else None
    rigid = mujoco_model(urdf_text, None, dt)  # the controller's feed-forward model: no friction, no rotor
    data, rdata = mujoco.MjData(model), mujoco.MjData(rigid)
    n = model.nv
    centre = np.zeros(n) if centre is None else np.asarray(centre, dtype=float)
    amp = np.broadcast_to(np.asarray(amplitude, dtype=float), (n,))
    n_ctrl = int(round(duration * rate)) + 1
    t_ctrl = np.arange(n_ctrl) / rate
    if reference is not None:
        qr, dqr, ddqr = reference(t_ctrl, n, rng, amp, centre)
    elif motion == "fourier":
        qr, dqr, ddqr = fourier_reference(t_ctrl, n, rng, f0, harmonics, amp, centre)
    else:
        qr, dqr, ddqr = ptp_reference(t_ctrl, n, rng, amp, centre)
    coupling = couplings(model)
    qr, dqr, ddqr = coupled((qr, dqr, ddqr), coupling)
    # gains: a loop of about 8 Hz on each joint's own inertia at the centre pose
    data.qpos[:] = centre
    mujoco.mj_forward(model, data)
    mass = np.empty((n, n))
    mujoco.mj_fullM(model, data, mass)
    m_jj = np.diag(mass)
    wn = 2 * np.pi * 8.0
    kp = m_jj * wn**2 if kp is None else np.asarray(kp, dtype=float)
    kd = 2 * 0.9 * m_jj * wn if kd is None else np.asarray(kd, dtype=float)
    kp, kd = np.array(kp, dtype=float), np.array(kd, dtype=float)
    kp[[f for f, *_ in coupling]] = kd[[f for f, *_ in coupling]] = 0.0  # a follower is passive: no loop of its own
    step_q = 2 * np.pi / 2**encoder_bits
    if not controller:
        if dry != "sign":
            raise ValueError("inverse dynamics needs dry = 'sign' (a frictionloss constraint has no inverse of its own)")
        return _prescribed(model, qr, dqr, ddqr, rate, duration, drives.fc, rng, step_q, noise_share, torque_std, jitter,
                           gaps, rate_change, coupling)
    # fine-grained truth, every integration step, for the log's jittered instants
    n_fine = (n_ctrl - 1) * substeps + 1
    fine = {k: np.empty((n_fine, n)) for k in ("q", "dq", "ddq", "tau")}
    data.qpos[:] = qr[0]
    data.qvel[:] = dqr[0]
    # the noise's standard deviation per joint, from the reference motion (the share is of the log's spectrum)
    noise_std = noise_for_share(qr, rate, noise_share, rng).std(axis=0) if noise_share > 0 else np.zeros(n)
    q_prev = qr[0].copy()
    dq_est = np.zeros(n)
    ki = kp * 2 * np.pi * integral
    err_sum = np.zeros(n)
    for k in range(n_ctrl):
        rdata.qpos[:], rdata.qvel[:], rdata.qacc[:] = qr[k], dqr[k], ddqr[k]
        mujoco.mj_inverse(rigid, rdata)
        q_seen = np.round(data.qpos / step_q) * step_q + (rng.normal(0.0, 1.0, n) * noise_std if loop_noise else 0.0)
        dq_est = 0.7 * dq_est + 0.3 * (q_seen - q_prev) * rate if k else dqr[0]
        q_prev = q_seen
        err_sum += (qr[k] - q_seen) / rate
        tau = folded(rdata.qfrc_inverse, coupling) + kp * (qr[k] - q_seen) + kd * (dqr[k] - dq_est) + ki * err_sum
        for s in range(substeps if k < n_ctrl - 1 else 1):
            i = k * substeps + s
            data.qfrc_applied[:] = tau if sign_fc is None else tau - sign_fc * np.sign(data.qvel)
            mujoco.mj_forward(model, data)
            fine["q"][i], fine["dq"][i], fine["ddq"][i], fine["tau"][i] = data.qpos, data.qvel, data.qacc, tau
            if k < n_ctrl - 1:
                mujoco.mj_step(model, data)
    t_fine = np.arange(n_fine) * dt
    t_log = _log_instants(duration, rate, rate_change, jitter, gaps, t_fine[-1], rng)
    # the true states at the logged instants (linear interpolation between integration steps of dt ≤ 0.5 ms);
    # the torque is the command held over its control period
    interp = lambda x: np.column_stack([np.interp(t_log, t_fine, x[:, j]) for j in range(n)])  # noqa: E731
    q, dq, ddq = interp(fine["q"]), interp(fine["dq"]), interp(fine["ddq"])
    tau = fine["tau"][np.minimum(np.floor(t_log / dt + 1e-9).astype(int), n_fine - 1)]
    q_meas = np.round(q / step_q) * step_q + rng.normal(size=q.shape) * noise_std
    tau_meas = tau + rng.normal(size=tau.shape) * np.asarray(torque_std)
    return SimulatedLog(t_log, q_meas, tau_meas, q, dq, ddq, tau)


def _log_instants(duration, rate, rate_change, jitter, gaps, t_end, rng):
    """The logged instants: the nominal rate, then (1 + rate_change) × it half-way; jitter; gaps of 5-10 samples."""
    half = duration / 2
    n1 = int(half * rate)
    t_nom = np.concatenate([np.arange(n1) / rate, half + np.arange(int((duration - half) * rate * (1 + rate_change)) - 1)
                            / (rate * (1 + rate_change))])
    t_nom = t_nom[t_nom <= t_end - 2.0 / rate]
    period = np.diff(t_nom, append=t_nom[-1] + 1 / rate)
    t_log = t_nom + jitter * period * np.clip(rng.normal(size=t_nom.size), -3, 3)
    t_log[0] = 0.0
    t_log = np.maximum.accumulate(t_log)
    keep = np.ones(t_log.size, bool)
    for _ in range(gaps):
        start = int(rng.uniform(0.1, 0.9) * t_log.size)
        keep[start:start + int(rng.integers(5, 11))] = False
    return t_log[keep]


def _prescribed(model, qr, dqr, ddqr, rate, duration, fc, rng, step_q, noise_share, torque_std, jitter, gaps, rate_change,
                coupling=()):
    """A log of the reference motion itself, with MuJoCo's inverse dynamics plus fc·sign(q̇) as the torques."""
    import mujoco

    data = mujoco.MjData(model)
    t_ref = np.arange(qr.shape[0]) / rate
    t_log = _log_instants(duration, rate, rate_change, jitter, gaps, t_ref[-1], rng)
    interp = lambda x: np.column_stack([np.interp(t_log, t_ref, x[:, j]) for j in range(x.shape[1])])  # noqa: E731
    q, dq, ddq = interp(qr), interp(dqr), interp(ddqr)
    dq[np.abs(dq) < 1e-12] = 0.0
    tau = np.empty_like(q)
    for k in range(q.shape[0]):
        data.qpos[:], data.qvel[:], data.qacc[:] = q[k], dq[k], ddq[k]
        mujoco.mj_inverse(model, data)
        tau[k] = folded(data.qfrc_inverse + fc * np.sign(dq[k]), coupling)
    noise_std = noise_for_share(qr, rate, noise_share, rng).std(axis=0) if noise_share > 0 else np.zeros(q.shape[1])
    q_meas = np.round(q / step_q) * step_q + rng.normal(size=q.shape) * noise_std
    tau_meas = tau + rng.normal(size=tau.shape) * np.asarray(torque_std)
    return SimulatedLog(t_log, q_meas, tau_meas, q, dq, ddq, tau)


def velocity_energy(x: np.ndarray) -> float:
    """Σ_f f²·|X(f)|² of the detrended, Hann-windowed columns (the share dynid's band rule reads)."""
    n = x.shape[0]
    ramp = np.linspace(0.0, 1.0, n)[:, None]
    w = np.hanning(n)[:, None]
    f = np.fft.rfftfreq(n)
    y = (x - x[0] - ramp * (x[-1] - x[0])) * w
    return float((f[:, None] ** 2 * np.abs(np.fft.rfft(y, axis=0)) ** 2).sum())


def noise_for_share(q: np.ndarray, rate: float, share: float, rng: np.random.Generator) -> np.ndarray:
    """White noise on every joint, scaled per joint so that it holds ``share`` of the velocity energy."""
    out = np.empty_like(q)
    for j in range(q.shape[1]):
        e_signal = velocity_energy(q[:, j:j + 1])
        white = rng.normal(size=q.shape[0])
        e_noise = velocity_energy(white[:, None])
        out[:, j] = white * np.sqrt(share / (1 - share) * e_signal / e_noise)
    return out


def write_csv(path: Path, log: SimulatedLog) -> None:
    """time, positions, torques: one row per sample."""
    np.savetxt(path, np.column_stack([log.t, log.q_meas, log.tau_meas]), delimiter=",", fmt="%.10g")
