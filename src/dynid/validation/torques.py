"""Measured against predicted torques on the same preprocessed samples: per-joint relative error, RMSE,
correlation coefficient (eq. 18) and the global relative error, for any number of parameter sets; and figures that
say what they measure: the samples where a joint moves and those where it rests apart (at rest, the friction is
whatever holds the joint, within ``±f_s``: there the RMSE and the share of samples inside that static band are
given, not a relative error), and a joint whose torque is at the noise level flagged rather than given a
relative error of 1500 %."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .._util.column_store import root_mean_square
from .._util.grams import joint_gram
from .._util.reprs import short_repr
from ..conventions import joint_unit, sliding_note
from ..dynamics.base_parameters import BaseParameters
from ..model.friction_model import COULOMB_LIKE
from ..model.robot import Robot
from ..preprocessing.preparation import base_chunks
from ..preprocessing.prepared import PreparedData
from .metrics import correlation_coefficient, correlation_from_sums, global_relative_error, relative_error, rmse
from .noise_floor import noise_floor

__all__ = ["TorqueComparison", "TorqueSums", "compare_torques", "rests_throughout"]


@short_repr
@dataclass(frozen=True)
class TorqueComparison:
    """Measured and predicted torques of one dataset (decimated), with per-joint metrics (eq. 18, RMSE, relative error).

    Attributes
    ----------
    name : str
        The dataset.
    t : (M,) array [s]
        The samples a figure draws.
    measured : (M, n_dof) array [N·m]
        Measured torques on those samples (filtered like the predictions).
    predicted : dict
        label -> (M, n_dof) predicted torques [N·m] of each parameter set.
    summary : dict or None
        From :class:`TorqueSums`: the metrics, sample count and RMS torque of all samples, while ``t``, ``measured`` and
        ``predicted`` hold only the samples a figure draws.
    resting : (M, n_dof) bool array or None
        Where each joint rests (its velocity below its rest velocity).
    static : dict or None
        label -> (n_dof,) static friction ``f_s`` [N·m] of each parameter set (the band a resting joint's friction stays
        in).
    noise : (n_dof,) array [N·m] or None
        Each joint's residual level on the identification log; a joint whose RMS torque is below :data:`MEANINGFUL`
        times it has no meaningful relative error.
    speed : (n_dof,) array [rad/s] or None
        RMS speed of each joint in this dataset.
    spread : dict or None
        label -> (n_dof,) RMS over the samples of the prediction's standard deviation from that set's covariance [N·m]
        (for the sets whose covariance is known).
    dead : tuple of int
        Joints whose measured torque is constant over the log, or saturated throughout: left out of every metric.
    centre : dict or None
        label -> (M, n_dof) the prediction without its Coulomb-like terms [N·m] (the static-friction band's centre).
    band : (n_dof,) array [N·m] or None
        The band's half-width ``f_s``, the same for every set.
    floor : (n_dof,) array [N·m] or None
        The noise floor of these samples (:func:`dynid.validation.noise_floor.noise_floor`): the RMSE a perfect model
        would have.
    misread : str
        Where the log is read otherwise than the identification log, the warning that says how ("" where it is not).
    followers : tuple of int
        Joints that follow another (``<mimic>``): among ``dead``, scored in the rows of the joints they follow.
    repeats_fit : bool
        The log repeats the identification log's samples: its figures are the fit's.
    prismatic : tuple of bool
        Which joints slide: their torques are forces [N], their speeds [m/s].
    """

    name: str
    t: np.ndarray
    measured: np.ndarray
    predicted: dict
    summary: dict | None = None
    """From :class:`TorqueSums`: the metrics, sample count and RMS torque of all samples, while ``t``,
    ``measured`` and ``predicted`` hold only the samples a figure draws."""
    resting: np.ndarray | None = None
    """(M, n_dof) bool: where each joint rests (its velocity below its rest velocity)."""
    static: dict | None = None
    """label -> (n_dof,) static friction ``f_s`` [N·m] of each parameter set (the band a resting joint's friction
    stays in)."""
    noise: np.ndarray | None = None
    """(n_dof,) [N·m]: each joint's residual level on the identification log; a joint whose RMS torque is below
    :data:`MEANINGFUL` times it has no meaningful relative error."""
    speed: np.ndarray | None = None
    """(n_dof,) RMS speed of each joint in this dataset [rad/s]."""
    spread: dict | None = None
    """label -> (n_dof,) RMS over the samples of the prediction's standard deviation from that set's covariance [N·m]
    (for the sets whose covariance is known)."""
    dead: tuple[int, ...] = ()
    """Joints whose measured torque is constant over the log (:func:`dynid.preprocessing.prepared.dead_channels`) or
    saturated throughout (:func:`dynid.preprocessing.prepared.clipped_samples`): left out of every metric (their
    per-joint figures NaN, the global ones over the other joints)."""
    floor: np.ndarray | None = None
    """(n_dof,) [N·m]: the noise floor of these samples (:mod:`dynid.validation.noise_floor`)."""
    centre: dict | None = None
    """label -> (M, n_dof) the prediction without its Coulomb-like terms [N·m]: at rest, the friction that holds a joint
    can be anything within ``±f_s`` about it (:meth:`metrics` scores the distance to that band)."""
    band: np.ndarray | None = None
    """(n_dof,) [N·m]: the half-width ``f_s`` of that band, the same for every set (the robot's static friction as
    the first set, dynid's estimate, identified it): a set with more friction of its own gets no wider band."""
    misread: str = ""
    """Where the log is read otherwise than the identification log (its torque channels flipped or swapped:
    :mod:`dynid.validation.channel_checks`; its geometry not the robot file's: :mod:`dynid.validation.geometry_checks`),
    the warning that says how: its figures say little of any estimate, and the verdict does not weigh them."""
    followers: tuple[int, ...] = ()
    """Joints that follow another (``<mimic>``): among :attr:`dead`, their torque supplied through that joint's drive
    and scored in its row; no dead channel to speak of."""
    repeats_fit: bool = False
    """The log repeats the identification log's samples (:func:`dynid.io.logs.log_repairs.repeated_share`): its figures
    are the fit's, not a test on other motions."""
    prismatic: tuple[bool, ...] = ()
    """Which joints slide (:attr:`dynid.model.robot.Robot.prismatic`): their torques are forces [N], their speeds
    [m/s], as the lines and tables say; empty: none."""
    _computed: dict = field(default_factory=dict, init=False, repr=False, compare=False)
    """label -> the metrics :meth:`metrics` computed for that set (the evidence and the verdict read them many times)."""

    def scored(self, label: str) -> np.ndarray:
        """The prediction the metrics score: the set's own while a joint moves; at rest, the measured torque moved
        into the static-friction band ``centre ± f_s`` (widened to hold the set's own prediction; its distance to the
        band is the residual), for every set alike, since no single value of the friction that holds a resting joint
        can be predicted.

        Parameters
        ----------
        label : str

        Returns
        -------
        (M, n_dof) ndarray [N·m]
        """
        p = self.predicted[label]
        if self.resting is None or self.centre is None or self.band is None or label not in self.centre:
            return p
        centre, half = self.centre[label], np.asarray(self.band, dtype=float)
        # the band holds the set's own prediction too (its held asymmetric or load-dependent terms), so that a residual
        # at rest is never scored above its plain value
        lower, upper = np.minimum(centre - half, p), np.maximum(centre + half, p)
        inside = np.clip(self.measured, lower, upper)  # the band's point nearest the measurement
        return np.where(self.resting, inside, p)

    def floor_metrics(self) -> dict | None:
        """What a perfect model would score on these samples (:mod:`dynid.validation.noise_floor`).

        Returns
        -------
        dict or None
            ``rmse`` [N·m] and ``relative_error`` [%] per joint, ``global_relative_error`` [%] over the joints that
            count (dead channels left out); None when the floor is unknown.
        """
        if self.floor is None:
            return None
        floor = np.asarray(self.floor, dtype=float)
        rms = np.asarray(self.rms_torque, dtype=float)
        live = np.ones(floor.shape, dtype=bool)
        live[list(self.dead)] = False
        with np.errstate(invalid="ignore", divide="ignore"):
            rel = np.where(live & (rms > 0), 100.0 * floor / np.where(rms > 0, rms, 1.0), np.nan)
        total = float(np.sqrt(np.sum(rms[live] ** 2)))
        return {"rmse": floor, "relative_error": rel,
                "global_relative_error": 100.0 * float(np.sqrt(np.sum(floor[live] ** 2))) / total if total > 0 else float("nan")}

    def metrics(self) -> dict:
        """The paper's metrics of every parameter set on this dataset.

        Returns
        -------
        dict
            label -> {``relative_error`` [%], ``rmse`` [N·m], ``correlation`` (eq. 18), each (n_dof,);
            ``global_relative_error`` [%] over all joints and samples; at rest the distance to the static-friction band
            (:meth:`scored`)}; where the joints rest in the dataset, also ``plain_relative_error`` and
            ``plain_global_relative_error`` [%] (the set's own prediction at rest, as published figures are), and
            ``moving_relative_error`` [%], ``moving_rmse`` [N·m] on the samples where each joint moves, ``rest_rmse`` [N·m]
            and ``rest_in_static_band`` (share of the resting samples whose error is within the set's ``±f_s``).
        """
        if self.summary is not None:
            return self.summary["metrics"]
        for label in self.predicted:
            if label not in self._computed:
                self._computed[label] = self._set_metrics(label)
        return {label: dict(self._computed[label]) for label in self.predicted}  # a caller's change stays its own

    def _set_metrics(self, label: str) -> dict:
        """:meth:`metrics` of the set ``label``, computed."""
        live = np.ones(self.measured.shape[1], dtype=bool)
        live[list(self.dead)] = False

        def joints(values):
            full = np.full(live.shape, np.nan)
            full[live] = values
            return full

        p = self.scored(label)
        mm, pp = self.measured[:, live], p[:, live]
        m = {"relative_error": joints(relative_error(mm, pp)), "rmse": joints(rmse(mm, pp)),
             "correlation": joints(correlation_coefficient(mm, pp)),
             "global_relative_error": global_relative_error(mm, pp)}
        if self.centre is not None and self.resting is not None and self.resting.any():
            # the literature's figure: the set's own prediction at rest too (to compare with published errors)
            raw = self.predicted[label][:, live]
            m.update(plain_relative_error=joints(relative_error(mm, raw)),
                     plain_global_relative_error=global_relative_error(mm, raw))
        if self.resting is not None and self.resting.any():
            m.update(_moving_and_rest(self.measured, self.predicted[label], self.resting,
                                      None if self.static is None else self.static.get(label)))
        return m

    def without(self, *labels: str) -> TorqueComparison:
        """The same comparison with the sets ``labels`` left out (candidates scored beside the others and not kept).

        Parameters
        ----------
        *labels : str

        Returns
        -------
        TorqueComparison
            Every other set's curves and metrics unchanged (each set is scored on its own; the static-friction band is
            the first set's).
        """
        def drop(d):
            return d if d is None else {k: v for k, v in d.items() if k not in labels}

        summary = self.summary if self.summary is None else {**self.summary, "metrics": drop(self.summary["metrics"])}
        return replace(self, predicted=drop(self.predicted), summary=summary, static=drop(self.static),
                       spread=drop(self.spread), centre=drop(self.centre))

    @property
    def rest_share(self) -> np.ndarray | None:
        """(n_dof,) share of the samples where each joint rests."""
        if self.summary is not None:
            return self.summary.get("rest_share")
        return None if self.resting is None else self.resting.mean(axis=0)

    def meaningful(self) -> np.ndarray:
        """Whether each joint's relative error means something here.

        Returns
        -------
        (n_dof,) bool array
            True where the joint's RMS torque is at least :data:`MEANINGFUL` times its residual level on the
            identification log and times the noise floor of these samples (:attr:`floor`; each where known).
        """
        ok = np.ones(self.rms_torque.shape, dtype=bool) if self.noise is None else \
            self.rms_torque >= MEANINGFUL * np.asarray(self.noise)
        if self.floor is not None:  # a joint whose torque is at the noise floor (held still, or a light wrist)
            ok &= self.rms_torque >= MEANINGFUL * np.asarray(self.floor, dtype=float)
        ok[list(self.dead)] = False
        return ok

    def flags(self) -> list[str]:
        """The joints whose relative error means nothing here, each with its absolute figure.

        Returns
        -------
        list of str
            One line per such joint (its RMS torque against the noise, its RMSE).
        """
        out = []
        first = next(iter(self.metrics().values()), None)
        share, band = self.rest_share, self.band
        still = [] if share is None or band is None else [int(j) for j in np.flatnonzero(np.asarray(share) >= AT_REST_SHARE)]
        if still and share is not None and band is not None:
            which = "every joint" if len(still) == len(share) else ", ".join(f"J{j + 1}" for j in still)
            out.append(f"{self.name}: {which} at rest in 95 % of the log or more: the error there is the distance to the "
                       "static-friction band (±f_s, " + ", ".join(f"{float(band[j]):.3g}" for j in still) + " N·m"
                       f"{sliding_note('N·m', [j in still and p for j, p in enumerate(self.prismatic)], inside=True)}), "
                       "which says whether a model is consistent with the torque that holds the arm, not how it "
                       "predicts motion")
        for j in np.flatnonzero(~self.meaningful()):
            if j in self.followers:
                continue  # its torque is in the row of the joint it follows: nothing of its own to score
            if j in self.dead:
                out.append(f"{self.name}: J{j + 1}'s torque is constant, or at its limit, over the log (a dead or "
                           "saturated channel): left out of the metrics")
                continue
            torque = joint_unit("N·m", self.prismatic, int(j))
            moves = "" if self.speed is None else (f"barely moves (RMS speed {self.speed[j]:.2g} "
                                                   f"{joint_unit('rad/s', self.prismatic, int(j))}) and " if
                                                   self.speed[j] < 0.05 else "")
            rmse_j = "" if first is None else f"; RMSE {first['rmse'][j]:.2g} {torque}"
            residual = self.noise is not None and self.rms_torque[j] < MEANINGFUL * np.asarray(self.noise)[j]
            level, what = ((np.asarray(self.noise)[j], "the identification residual") if residual
                           else (np.asarray(self.floor, dtype=float)[j], "the noise floor of these samples"))
            out.append(f"{self.name}: J{j + 1} {moves}its torque is at the noise level (RMS {self.rms_torque[j]:.2g} {torque}, "
                       f"{self.rms_torque[j] / level:.2g}× {what}): relative error not meaningful{rmse_j}")
        return out

    @property
    def dead_said(self) -> tuple[int, ...]:
        """The dead or saturated channels a line names: :attr:`dead` less the joints that follow another."""
        return tuple(j for j in self.dead if j not in self.followers)

    @property
    def n_samples(self) -> int:
        """Samples compared (all of them, not only those drawn)."""
        return int(self.summary["n_samples"]) if self.summary is not None else int(self.t.shape[0])

    @property
    def torque_std(self) -> np.ndarray:
        """(n_dof,) standard deviation of each joint's measured torque [N·m] (what the correlation coefficient sees)."""
        if self.summary is not None and "torque_std" in self.summary:
            return self.summary["torque_std"]
        return self.measured.std(axis=0)

    def varies(self, beyond: str = "noise") -> np.ndarray:
        """Whether each joint's torque varies beyond its noise, so that its correlation coefficient (eq. 18) means
        something.

        Parameters
        ----------
        beyond : {"noise", "floor"}
            What it must vary beyond (:data:`MEANINGFUL` times): the residual level :attr:`noise` (the fit's, on an
            identification log), or the noise floor of these samples :attr:`floor`, which a torque the model cannot
            fit (a flipped sign, a swapped pair of columns) does not raise.

        Returns
        -------
        (n_dof,) bool array
        """
        level = self.noise if beyond == "noise" else self.floor
        if level is None:
            return np.ones(self.rms_torque.shape, dtype=bool)
        return self.torque_std >= MEANINGFUL * np.asarray(level)

    @property
    def rms_torque(self) -> np.ndarray:
        """(n_dof,) RMS of the measured torque of each joint over all samples [N·m]."""
        return self.summary["rms_torque"] if self.summary is not None else np.sqrt((self.measured**2).mean(axis=0))

    def to_dict(self) -> dict:
        """The comparison as results.json stores it (metrics, sample count, RMS torques, flags).

        Returns
        -------
        dict
        """
        out = {"name": self.name, "n_samples": self.n_samples, "rms_torque": self.rms_torque, "metrics": self.metrics()}
        if self.rest_share is not None:
            out["rest_share"] = self.rest_share
        if self.dead_said:
            out["dead_channels"] = list(self.dead_said)  # 0-based joints left out of every metric
        if self.followers:
            out["following_joints"] = list(self.followers)  # 0-based: <mimic> joints, in the rows of those they follow
        if self.noise is not None:
            out["relative_error_meaningful"] = self.meaningful().tolist()
            out["correlation_meaningful"] = self.varies().tolist()
            out["flags"] = self.flags()
        if self.spread:
            out["prediction_spread"] = self.spread
        floor = self.floor_metrics()
        if floor is not None:
            out["noise_floor"] = floor
        if self.misread:
            out["misread"] = self.misread
        if self.repeats_fit:
            out["repeats_identification_log"] = True
        if any(self.prismatic):
            out["prismatic_joints"] = [j for j, p in enumerate(self.prismatic) if p]  # 0-based: forces in N, speeds in m/s
        return out


AT_REST_SHARE = 0.95
"""A joint at rest in this share of a log's samples or more is flagged so: its error is then the distance to the
static-friction band."""


def rests_throughout(rest_share) -> bool:
    """Whether every joint of a log rests in :data:`AT_REST_SHARE` of its samples or more: its figure is then a check
    of the gravity model within friction, not a prediction of motion.

    Parameters
    ----------
    rest_share : (n_dof,) sequence or None
        :attr:`TorqueComparison.rest_share` (results.json ``rest_share``).

    Returns
    -------
    bool
        False when the share is unknown or empty.
    """
    return rest_share is not None and len(rest_share) > 0 and bool(np.all(np.asarray(rest_share, dtype=float) >= AT_REST_SHARE))


MEANINGFUL = 3.0
"""A joint's relative error is given only where its RMS torque is at least this many times its residual level."""


def _moving_and_rest(measured, predicted, resting, static) -> dict:
    """The metrics of the samples where each joint moves, and of those where it rests (module docstring)."""
    err = measured - predicted
    moving = ~resting
    with np.errstate(invalid="ignore", divide="ignore"):
        m_rmse = np.sqrt(np.where(moving, err**2, 0).sum(0) / moving.sum(0))
        m_rms = np.sqrt(np.where(moving, measured**2, 0).sum(0) / moving.sum(0))
        r_rmse = np.sqrt(np.where(resting, err**2, 0).sum(0) / resting.sum(0))
        out = {"moving_relative_error": 100 * m_rmse / m_rms, "moving_rmse": m_rmse, "rest_rmse": r_rmse}
        if static is not None:
            inside = (np.abs(err) <= np.asarray(static) * 1.05) & resting
            out["rest_in_static_band"] = inside.sum(0) / resting.sum(0)
    return out


class TorqueSums:
    """Per-joint statistics of a dataset's decimated regressor rows and torques, from which the metrics of any
    parameter vector follow without a second pass over the log.

    Per joint it keeps the mean of ``z = (Y, τ)`` and its centred Gram matrix ``Σ (z - z̄)(z - z̄)ᵀ``, merged
    chunk by chunk with Chan, Golub & LeVeque's update (Am. Stat. 37(3), 1983), which stays accurate where
    raw sums would cancel (a log at rest: an almost constant prediction). With ``p = Yβ``: the centred sums of
    eq. 18 are ``βᵀS_YYβ``, ``βᵀS_Yτ`` and ``S_ττ``; ``‖τ - p‖² = S_ττ - 2βᵀS_Yτ + βᵀS_YYβ + N (τ̄ - Ȳβ)²``.
    Memory: n_dof matrices of (n_columns + 1)², whatever the log's length, plus the rows a figure draws
    (every ``thin``-th).

    Parameters
    ----------
    n_dof, n_columns : int
    n_rows : int
        Decimated samples the dataset will give (for the figure's thinning, as :func:`dynid.report.figures`).
    max_points : int
        Samples a figure draws at most.
    dead : tuple of int
        Joints whose measured torque is constant over the log, or saturated throughout: left out of every metric.
    floor : (n_dof,) array [N·m], optional
        The noise floor of the samples (:mod:`dynid.validation.noise_floor`).
    """

    def __init__(self, n_dof: int, n_columns: int, n_rows: int, max_points: int = 2500, dead: tuple[int, ...] = (),
                 floor: np.ndarray | None = None):
        self.dead = tuple(dead)
        self.floor = floor
        self.mean = np.zeros((n_dof, n_columns + 1))
        self.m2 = np.zeros((n_dof, n_columns + 1, n_columns + 1))
        self.count = 0
        self.rest_gram = np.zeros((n_dof, n_columns + 1, n_columns + 1))  # raw sums of z zᵀ over resting rows
        self.rest_count = np.zeros(n_dof)
        self.thin = max(1, -(-n_rows // max_points))
        self.kept_t: list[np.ndarray] = []
        self.kept_y: list[np.ndarray] = []
        self.kept_tau: list[np.ndarray] = []

    @classmethod
    def for_data(cls, data: PreparedData, n_columns: int) -> TorqueSums:
        """Empty statistics sized for the decimated samples of ``data``.

        Parameters
        ----------
        data : PreparedData
            The dataset (its length and decimation size the thinning of the kept curves).
        n_columns : int
            Columns of the regressor blocks that will be added.

        Returns
        -------
        TorqueSums
        """
        return cls(data.tau.shape[1], n_columns, len(range(0, data.t.shape[0], data.settings.decimation or 1)),
                   dead=data.dead, floor=noise_floor(data))

    def add(self, t: np.ndarray, y: np.ndarray, tau: np.ndarray, resting: np.ndarray | None = None) -> None:
        """Fold one block of rows into the statistics.

        Parameters
        ----------
        t : (M,) array [s]
            Time of the block's samples.
        y : (M, n_dof, n_columns) array
            Regressor rows (filtered like the torques).
        tau : (M, n_dof) array [N·m]
            Measured torques.
        resting : (M, n_dof) bool array, optional
            Where each joint rests.
        """
        m = y.shape[0]
        z = np.concatenate([y, tau[:, :, None]], axis=2)
        if resting is not None and resting.any():
            zr = z * resting[:, :, None]
            self.rest_gram += joint_gram(zr)
            self.rest_count += resting.sum(axis=0)
        mean = z.mean(axis=0)
        zc = z - mean
        m2 = joint_gram(zc)
        n = self.count
        delta = mean - self.mean
        self.mean += delta * (m / (n + m))
        self.m2 += m2 + np.einsum("jc,jd->jcd", delta, delta) * (n * m / (n + m))
        first = (-n) % self.thin  # rows n, n+1, …: keep those at multiples of thin
        # copies of the kept rows: a slice would be a view that keeps the whole chunk alive, and the whole log with it
        self.kept_t.append(t[first::self.thin].copy())
        self.kept_y.append(y[first::self.thin].copy())
        self.kept_tau.append(tau[first::self.thin].copy())
        self.count = n + m

    def beyond(self, beta: np.ndarray, nuisance: dict) -> tuple[np.ndarray, np.ndarray]:
        """Each joint's measured torque against the prediction ``y·β`` once the columns ``nuisance[j]`` are regressed
        out of both: their partial correlation, and the slope of the torque on the prediction (1 where the torque
        has the prediction's size; a unit or gain error scales it).

        Parameters
        ----------
        beta : (n_columns,) array
            The parameter set.
        nuisance : dict
            Joint (0-based) -> indices of the regressor columns to regress out on that joint's rows.

        Returns
        -------
        correlation, slope : (n_dof,) arrays
            NaN where either part has no variance left.
        """
        b = np.asarray(beta, dtype=float)
        n_dof, size = self.m2.shape[0], self.m2.shape[1]
        rho, slope = np.full(n_dof, np.nan), np.full(n_dof, np.nan)
        for j in range(n_dof):
            cols = list(nuisance.get(j, ()))
            t = np.zeros((2 + len(cols), size))
            t[0, :-1], t[1, -1] = b, 1.0
            for k, c in enumerate(cols):
                t[2 + k, c] = 1.0
            cov = t @ self.m2[j] @ t.T  # centred sums of (prediction, torque, nuisance columns)
            if cols:
                cov = cov[:2, :2] - cov[:2, 2:] @ np.linalg.pinv(cov[2:, 2:]) @ cov[2:, :2]
            if cov[0, 0] > 1e-12 * max(abs(float(self.m2[j, -1, -1])), 1e-300) and cov[1, 1] > 0:
                rho[j] = cov[0, 1] / np.sqrt(cov[0, 0] * cov[1, 1])
                slope[j] = cov[0, 1] / cov[0, 0]
        return rho, slope

    def comparison(self, name: str, parameter_sets: dict) -> TorqueComparison:
        """The dataset's comparison: metrics from the statistics, curves on the kept rows.

        Parameters
        ----------
        name : str
            The dataset.
        parameter_sets : dict
            label -> (n_columns,) parameter vector.

        Returns
        -------
        TorqueComparison
        """
        n = self.count
        s_yy, s_yt, s_tt = self.m2[:, :-1, :-1], self.m2[:, :-1, -1], self.m2[:, -1, -1]
        y_mean, t_mean = self.mean[:, :-1], self.mean[:, -1]
        tau_sq = s_tt + n * t_mean**2  # Σ τ²
        metrics = {}
        for label, beta in parameter_sets.items():
            b = np.asarray(beta, dtype=float)
            s_pp = np.einsum("c,jcd,d->j", b, s_yy, b)
            s_pt = s_yt @ b
            # the size of the centred terms the prediction sums: the rounding of s_pp = bᵀ S b is ε of it
            terms = (np.sqrt(np.diagonal(s_yy, axis1=1, axis2=2)) @ np.abs(b)) ** 2
            sse = np.maximum(s_tt - 2 * s_pt + s_pp, 0.0) + n * (t_mean - y_mean @ b) ** 2
            live = np.ones(sse.shape, dtype=bool)
            live[list(self.dead)] = False  # a dead channel's rows count in no metric
            with np.errstate(invalid="ignore", divide="ignore"):
                relative = np.where(live, 100.0 * np.sqrt(sse / np.where(live, tau_sq, 1.0)), np.nan)
            metrics[label] = {"relative_error": relative, "rmse": np.where(live, np.sqrt(sse / n), np.nan),
                              "correlation": np.where(live, correlation_from_sums(s_pt, s_tt, s_pp, terms), np.nan),
                              "global_relative_error": float(100.0 * np.sqrt(sse[live].sum() / max(tau_sq[live].sum(), 1e-300)))}
            if self.rest_count.any():  # raw sums of the resting rows: Σ (τ - p)² = eᵀ G e with e = (β, -1)
                e = np.concatenate([b, [-1.0]])
                r_sse = np.maximum(np.einsum("c,jcd,d->j", e, self.rest_gram, e), 0.0)
                r_tau = self.rest_gram[:, -1, -1]
                moving = n - self.rest_count
                with np.errstate(invalid="ignore", divide="ignore"):
                    metrics[label].update({
                        "moving_relative_error": 100.0 * np.sqrt(np.maximum(sse - r_sse, 0) / np.maximum(tau_sq - r_tau, 1e-300)),
                        "moving_rmse": np.sqrt(np.maximum(sse - r_sse, 0) / moving), "rest_rmse": np.sqrt(r_sse / self.rest_count)})
        y = np.concatenate(self.kept_y)
        summary = {"metrics": metrics, "n_samples": n, "rms_torque": np.sqrt(tau_sq / n), "torque_std": np.sqrt(s_tt / n),
                   **({"rest_share": self.rest_count / n} if self.rest_count.any() else {})}
        return TorqueComparison(name, np.concatenate(self.kept_t), np.concatenate(self.kept_tau),
                                {label: y @ np.asarray(beta, dtype=float) for label, beta in parameter_sets.items()}, summary,
                                dead=self.dead, floor=self.floor)


def resting_rows(data: PreparedData, index: np.ndarray) -> np.ndarray:
    """Where each joint rests at some samples of a prepared log (:func:`dynid.friction.moving_joints`).

    Parameters
    ----------
    data : PreparedData
    index : (M,) int array
        Sample indices.

    Returns
    -------
    (M, n_dof) bool array
    """
    if data.resting is not None:
        return data.resting[index]
    given = data.settings.rest_velocity
    n = data.tau.shape[1]
    rest = np.broadcast_to(np.asarray(0.0 if given == "auto" else given, dtype=float), (n,))
    v = data.motion if data.motion is not None else data.dq
    return np.abs(np.asarray(v[index])) <= rest


def scored_rest(data: PreparedData) -> np.ndarray | None:
    """Where each joint's friction is that of a rest, for scoring: its rests (:attr:`PreparedData.resting`) widened
    on both sides by half the position filter's time support (``rate / (2 f_pos)`` samples), since the zero-phase
    filter spreads a start or a stop over that time and a joint still at rest reads as moving there (on simulated
    point-to-point logs, 95 % of the true parameters' remaining error on J1-J2 sat in those samples).

    Parameters
    ----------
    data : PreparedData

    Returns
    -------
    (N, n_dof) bool array, or None when the log's rests are not known
    """
    if data.resting is None:
        return None
    cutoff = float(data.settings.position_cutoff or 0.0)
    half = int(np.ceil(data.rate / (2 * cutoff))) if cutoff > 0 else 0
    if half == 0 or not data.resting.any():
        return data.resting
    from scipy.ndimage import maximum_filter1d

    return maximum_filter1d(data.resting, size=2 * half + 1, axis=0, mode="nearest")


def coulomb_like_columns(base: BaseParameters, n_dof: int) -> np.ndarray:
    """Which base columns are each joint's Coulomb-like friction (:data:`dynid.model.friction_model.COULOMB_LIKE`):
    the terms that take the friction's direction, held or not at rest.

    Parameters
    ----------
    base : BaseParameters
    n_dof : int

    Returns
    -------
    (n_dof, n_base) float array
        1 where column ``c`` is joint ``j``'s Coulomb-like term.
    """
    out = np.zeros((n_dof, len(base.names)))
    for j in range(n_dof):
        for term in COULOMB_LIKE:
            if f"{term}{j + 1}" in base.names:
                out[j, base.names.index(f"{term}{j + 1}")] = 1.0
    return out


def static_friction(base: BaseParameters, parameter_sets: dict, n_dof: int) -> dict:
    """The static friction of each parameter set: ``f_s = |fc| + max(fst, 0)`` per joint (its base parameters named
    ``fc<j>``, ``fst<j>``; 0 where absent).

    Parameters
    ----------
    base : BaseParameters
    parameter_sets : dict
        label -> (n_base,) base parameters.
    n_dof : int

    Returns
    -------
    dict
        label -> (n_dof,) array [N·m].
    """
    out = {}
    for label, beta in parameter_sets.items():
        fs = np.zeros(n_dof)
        for j in range(n_dof):
            for name, f in ((f"fc{j + 1}", abs), (f"fst{j + 1}", lambda x: max(x, 0.0))):
                if name in base.names:
                    fs[j] += f(float(beta[base.names.index(name)]))
        out[label] = fs
    return out


def compare_torques(robot: Robot, base: BaseParameters, data: PreparedData, parameter_sets: dict,
                    *, progress=None, noise: np.ndarray | None = None, covariance: dict | None = None) -> TorqueComparison:
    """Predict the torques of ``data`` with each base parameter vector of ``parameter_sets`` on the same
    parallel-decimated samples as the estimation, and score them (eq. 18, RMSE, relative error).

    The parameter sets are known before the pass, so the predictions are stored and the metrics computed from them
    directly (exact also for a log at rest, where a prediction is almost constant); :class:`TorqueSums` serves the fit,
    whose parameters come out of the same pass.

    Parameters
    ----------
    robot : Robot
        The model the sets belong to.
    base : BaseParameters
        Its base-parameter map.
    data : PreparedData
        The prepared log (:func:`dynid.preprocessing.preparation.prepare`).
    parameter_sets : dict
        label -> (n_base,) base parameters.
    progress : callable, optional
        ``progress(done, total)`` in samples.
    noise : (n_dof,) array [N·m], optional
        Each joint's residual level on the identification log, to flag joints whose torque is at that level
        (:meth:`TorqueComparison.flags`).
    covariance : dict, optional
        label -> (n_base, n_base) covariance of a set: its prediction's spread ``sqrt(diag(Y C Yᵀ))`` is kept
        (:attr:`TorqueComparison.spread`).

    Returns
    -------
    TorqueComparison
    """
    covariance = covariance or {}
    ts: list = []
    meas: list = []
    rest: list = []
    preds: dict[str, list] = {k: [] for k in parameter_sets}
    centres: dict[str, list] = {k: [] for k in parameter_sets}
    var = {k: np.zeros(robot.n_dof) for k in covariance}
    holding = coulomb_like_columns(base, robot.n_dof)  # (n_dof, n_base): the terms that hold a resting joint
    at_rest = scored_rest(data)
    for index, y, tau, _ in base_chunks(robot, base, data, progress):
        scored = data.scored(index)  # a clipped torque says only that it was at least that much
        if not scored.all():
            index, y, tau = index[scored], y[scored], tau[scored]
        ts.append(data.t[index])
        meas.append(tau)
        rest.append(resting_rows(data, index) if at_rest is None else at_rest[index])
        held = y * holding  # once a block, not once a set
        for label, beta in parameter_sets.items():
            preds[label].append(y @ beta)
            centres[label].append(preds[label][-1] - held @ beta)
        for label, cov in covariance.items():
            var[label] += np.einsum("mjc,mjc->j", y @ cov, y)  # the product first (BLAS), then the rows' sums

    m = sum(x.shape[0] for x in ts)
    static = static_friction(base, parameter_sets, robot.n_dof)
    return TorqueComparison(data.name, np.concatenate(ts), np.concatenate(meas),
                            {k: np.concatenate(v) for k, v in preds.items()}, resting=np.concatenate(rest),
                            static=static, noise=noise,
                            speed=root_mean_square(data.dq), spread={k: np.sqrt(v / max(m, 1)) for k, v in var.items()},
                            dead=data.dead, floor=noise_floor(data), centre={k: np.concatenate(v) for k, v in centres.items()},
                            band=next(iter(static.values()), None), prismatic=tuple(robot.prismatic.tolist()),
                            followers=robot.followers)
