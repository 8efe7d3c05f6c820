"""A tool's payload from a short log with the arm's model known (issue "The model proven where it goes", item 4).

The arm's identified (or nominal) base parameters predict the torques of the arm alone; what the log holds beyond them
is the payload's, linear in its ten inertial parameters about the frame of the link carrying it (the last by default):
``τ - Y β = Y_L φ_payload`` with ``Y_L`` that link's ten standard regressor columns (Khalil & Dombre, "Modeling, Identification and Control of
Robots", 2002, §12.5: payload identification with the robot's parameters known). Least squares on the identifiable
ones gives σ (:func:`dynid.identification.drive_gains.identify_payload`); the estimate handed on is physically
consistent: the same rows solved with the payload's pseudo-inertia positive semidefinite (Wensing, Kim & Slotine 2018),
pulled by a weak prior toward a point mass of least squares' mass at least squares' centre of mass, so that what the log
does not determine (a payload turned about one axis only leaves some inertia undetermined) stays at that point mass's
values rather than at noise. It is given in the flange's frame (the robot's tool frame; another link's own frame), as a controller's payload
setting takes it, and as a URDF link and an MJCF body to attach.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._util.reprs import short_repr
from ..conventions import INERTIAL_TERMS
from ..dynamics.base_parameters import BaseParameters
from ..estimators.accumulate import LeastSquaresAccumulator
from ..estimators.physically_consistent import PhysicallyConsistentLeastSquares
from ..estimators.problem import FitData
from ..model.robot import Robot
from ..model.spatial import inertial_from_physical, physical_from_inertial, transform_inertial
from ..preprocessing.preparation import base_chunks
from ..preprocessing.prepared import PreparedData
from ..validation.noise_floor import noise_floor
from .drive_gains import _link_columns, identify_payload

FLOOR_FACTOR = 3.0
"""A payload fit over this many times what a right payload leaves is said (:attr:`Payload.misfit`): the log's noise
floor, or the arm model's own residual on its identification log where that is larger. On the UR10e's real log with
its 2.805 kg payload the fit is 7.7 times the noise floor (the arm model itself leaves more than the noise): the floor
alone would flag a right payload."""

SLID = 1e-3
"""[m] A last link that slides on its prismatic joint by more than this during the payload's log moves relative to
the flange (a gripper's jaw): said (:attr:`Payload.rides_a_sliding_link`)."""

__all__ = ["Payload", "payload_from_log"]


@short_repr
@dataclass(frozen=True)
class Payload:
    """A payload identified from a log (module docstring).

    Attributes
    ----------
    mass : float [kg]
    com : (3,) array [m]
        Its centre of mass in the flange's frame.
    inertia : (3, 3) array [kg·m²]
        About its centre of mass, the flange's axes.
    mass_std : float [kg]
        Least squares' σ of the mass (NaN where the log does not act on it).
    com_std : (3,) array [m]
        σ of the centre of mass from least squares' σ of the first moments over the mass.
    not_determined : tuple of str
        The payload's link's parameters (eq. 5 names, about that link's frame) the log does not determine: σ at least
        their value, or no action on the joints at all; the consistent estimate keeps the point mass's values there.
    parameters : (10,) array
        The consistent estimate about the frame of the link carrying it (the last by default; eq. 5 order).
    error_without, error_with : float [%]
        The log's global relative torque error of the arm's model alone and with the payload.
    error_floor : float [%]
        What a perfect model would leave of the log's torques, on the same samples (the noise floor,
        :func:`dynid.validation.noise_floor.noise_floor`); NaN where the torques carry no measurable noise.
    error_arm : float [%]
        What the arm's model leaves of its own identification log (its residual σ per joint), on the same samples;
        NaN where the results hold no such figure.
    last_joint_travel : float [m]
        How far the link the payload is put on slid on its joint during the log, where that joint is prismatic (a
        gripper's jaw as the chain's last link; :attr:`rides_a_sliding_link`); 0 for a revolute last joint.
    """

    mass: float
    com: np.ndarray
    inertia: np.ndarray
    mass_std: float
    com_std: np.ndarray
    not_determined: tuple[str, ...]
    parameters: np.ndarray
    error_without: float
    error_with: float
    error_floor: float = float("nan")
    error_arm: float = float("nan")
    last_joint_travel: float = 0.0

    @property
    def expected(self) -> float:
        """[%] What a right payload leaves: the larger of :attr:`error_floor` and :attr:`error_arm` (NaN: neither
        known)."""
        known = [e for e in (self.error_floor, self.error_arm) if np.isfinite(e)]
        return max(known) if known else float("nan")

    @property
    def misfit(self) -> bool:
        """Whether the fit with the payload stays over :data:`FLOOR_FACTOR` times :attr:`expected`: something beyond a
        rigid payload on the flange (the arm's model off, a last link that moves, torques read otherwise)."""
        return bool(np.isfinite(self.expected) and self.error_with > FLOOR_FACTOR * self.expected)

    @property
    def rides_a_sliding_link(self) -> bool:
        """Whether the link the payload was fitted on slid by more than :data:`SLID` during the log: a tool on the
        flange rides on the link before it, and this payload's figures are not a rigid tool's."""
        return self.last_joint_travel > SLID

    def to_dict(self) -> dict:
        """JSON-ready payload.

        Returns
        -------
        dict
            SI units; the frame is the flange's.
        """
        return {"frame": "flange (the robot's tool frame); inertia about the centre of mass", "mass": self.mass,
                "mass_std": self.mass_std, "com": self.com.tolist(), "com_std": self.com_std.tolist(),
                "inertia": self.inertia.tolist(), "not_determined": list(self.not_determined),
                "last_link_parameters": dict(zip(INERTIAL_TERMS, self.parameters.tolist())),
                "global_relative_error_without": self.error_without, "global_relative_error_with": self.error_with,
                "global_relative_error_floor": None if not np.isfinite(self.error_floor) else self.error_floor,
                "global_relative_error_arm": None if not np.isfinite(self.error_arm) else self.error_arm,
                "last_joint_travel": self.last_joint_travel}


def payload_from_log(robot: Robot, base: BaseParameters, beta: np.ndarray, loaded: PreparedData, *, rng=0,
                     gain_ratio=None, residual=None, link: int | None = None) -> Payload:
    """The payload a log shows beyond the arm's model (module docstring).

    Parameters
    ----------
    robot : Robot
        The arm as identified (its friction model), its tool frame the flange.
    base : BaseParameters
    beta : (n_base,) array
        The arm's base parameters without the payload (an identification's main estimate, or the nominal ones).
    loaded : PreparedData
        The log with the payload, its ``tau`` in N·m.
    rng : int
        Seeds the random states that find the identifiable parameters.
    gain_ratio : (n_dof,) array, optional
        Each joint's identified drive gain over the one its torques were read with (eq. 16): the arm's model and the
        log both carry the gain the torques were read with, so what the payload adds is scaled by this ratio to newtons
        and metres (default 1: the gains are right).
    residual : (n_dof,) array [N·m], optional
        Each joint's residual σ of the arm's model on its identification log (results.json's ``joint_residual_std``):
        what a right payload's fit leaves at least, beside the noise floor.
    link : int, optional
        The link carrying the payload, 0-based (default: the last, whose flange is the robot's tool frame). On a
        robot with branches, another arm's hand: the payload is then given in that link's own frame.

    Returns
    -------
    Payload

    Raises
    ------
    IdentifiabilityError
        Too few rows, or a motion that determines none of the payload's parameters.
    """
    ratio = np.ones(robot.n_dof) if gain_ratio is None else np.asarray(gain_ratio, dtype=float)
    link = robot.n_dof - 1 if link is None else int(link)
    ls = identify_payload(robot, base, beta, loaded, rng=rng, gain_ratio=ratio, link=link)
    cols = _link_columns(robot, link)
    acc = LeastSquaresAccumulator(10, robot.n_dof)
    sse = np.zeros(2)
    total = 0.0
    kept = np.zeros(robot.n_dof)
    for _, y, tau, keep in base_chunks(robot, base, loaded, standard=True):
        extra = (tau - base.base_observation(y) @ beta) * ratio
        acc.add(y[:, :, cols].reshape(-1, 10), extra.reshape(-1), keep.reshape(-1))
        total += float(np.sum((tau * ratio)[keep] ** 2))
        sse[0] += float(np.sum(extra[keep] ** 2))
        kept += keep.sum(axis=0)
    values = dict(zip(ls.names, ls.values))
    mass = max(values.get("M", 0.0), 0.0)
    first = np.array([values.get(k, 0.0) for k in ("MX", "MY", "MZ")])
    prior = inertial_from_physical(mass, first / mass if mass > 0 else np.zeros(3), np.zeros((3, 3)))
    reduced = acc.reduced()
    sdp = PhysicallyConsistentLeastSquares().fit(reduced[:, :10], reduced[:, 10],
                                                 problem=FitData(layout=(np.arange(10)[None, :], ()), prior=prior))
    phi = sdp.params_
    sse[1] = float(np.sum(acc.joint_residual_sumsq(phi)))
    rotation, translation = robot.flange(link=link)
    in_flange = transform_inertial(phi, rotation.T, -rotation.T @ translation)
    m, com, inertia = physical_from_inertial(in_flange)
    std = dict(zip(ls.names, ls.std))
    mass_std = float(std.get("M", np.nan))
    com_std = np.abs(rotation.T @ np.array([std.get(k, np.nan) for k in ("MX", "MY", "MZ")])) / max(m, 1e-12)
    lost = tuple(k for k in INERTIAL_TERMS if k not in ls.names) + ls.not_determined
    error = 100.0 * np.sqrt(sse / max(total, 1e-300))
    def share(sigma) -> float:  # each joint's σ on the samples kept, as a global relative error [%]
        return np.nan if sigma is None else 100.0 * float(np.sqrt(np.sum((sigma * ratio) ** 2 * kept) / max(total, 1e-300)))

    travel = float(np.ptp(np.asarray(loaded.q[:, link]))) if robot.joints[link].prismatic else 0.0  # one column read
    return Payload(m, com, inertia, mass_std, com_std, lost, phi, float(error[0]), float(error[1]),
                   share(noise_floor(loaded)), share(None if residual is None else np.asarray(residual, dtype=float)),
                   travel)
