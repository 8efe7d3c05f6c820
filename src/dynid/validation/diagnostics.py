"""A verdict on the model itself: does it fit the data, and what do the figures that depend on it mean?

Least squares always returns parameters; whether they describe the robot is a separate question, which the
residuals answer (Ljung, *System Identification*, 2nd ed., 1999, §16.6, "model validation": residual analysis,
correlation of the residuals with inputs and with themselves; Swevers, Verdonck & De Schutter, IEEE Control
Systems 27(5), 2007, on robots). Each check here gives one line when it finds something:

* **a flipped torque sign**: the measured torques run against those of the description's nominal model;
* **friction misfit near reversals**: at low speed, the residual still correlates with the direction of motion;
* **an unmodelled position dependence**: the residual correlates with the joint's angle (a counterbalance, a
  cable, a wrong mass);
* **correlated residuals**: :math:`σ` of the covariance assumes white residuals; a moving-block bootstrap says how
  far off it is;
* **poorly excited parameters**: large relative σ on parameters that matter for the torques;
* **extrapolation**: a validation log whose predictions the parameters' covariance makes far less certain than on
  the identification log, and a validation error far above the identification's.

Significance accounts for the correlation of the (filtered, decimated) residuals: a regression's t statistic uses
the effective number of samples ``N·(1 - ρ₁)/(1 + ρ₁)`` with ``ρ₁`` the residuals' lag-1 autocorrelation
(Bartlett's approximation for an AR(1) series).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._util.column_store import correlation_matrix
from .._util.grams import joint_gram
from ..conventions import joint_unit
from .noise_floor import AT_FLOOR

__all__ = ["DELAY_ADVICE", "Finding", "OrderSums", "ResidualSums", "sign_findings", "scale_findings", "spiky_joints",
           "unlike_nominal_findings", "validation_findings", "prior_findings", "nominal_gate"]

SIGNIFICANT = 4.0
"""|t| above which a residual's correlation with a feature is reported."""

POSITION_SHARE = 0.01
"""A position dependence is reported when its spread over the joint's angles is at least this share of the joint's RMS
torque (and significant): what the model leaves of a counterbalance or a cable is small, since least squares takes
most of it into the gravity parameters."""

FEATURES = ("direction at low speed", "sin q", "cos q", "sin 2q", "cos 2q")
"""The features the residual is regressed on, per joint (besides a constant)."""


@dataclass(frozen=True)
class Finding:
    """One line of the verdict.

    Attributes
    ----------
    kind : str
        "sign", "scale", "order", "friction", "position", "correlated", "excitation", "extrapolation", "validation",
        "delay", "main" (the verdict's choice), "drive" (a drive term no drive has:
        :mod:`dynid.identification.plausibility`), "angles" (logged angles that do not match the robot file, a zero a
        quarter or half turn off, a joint counted the other way round or two columns swapped) and "gravity" (gravity
        along another axis of the base: :mod:`dynid.validation.geometry_checks`), "misread" (a validation log the verdict
        leaves out, read otherwise than the identification log: :mod:`dynid.validation.channel_checks`), "filtered"
        (torques without measurable noise: :func:`dynid.validation.noise_floor.looks_filtered`), "columns" (torques
        that follow the description on no joint: :func:`unlike_nominal_findings`), "spikes" (torques that follow it
        on no joint and are mostly spikes: a chattering controller or simulation, glitches), "yardstick" (the validation logs rank
        the candidates differently under another state filter: :func:`dynid.identification.verdict.decide`).
    text : str
        The line, naming the joint or dataset, the size, and what to do.
    joint : int or None
        0-based joint, when the finding is about one.
    fix : dict or None
        The setting the finding asks for, where it names one (a sign finding's ``{"sign": -1}`` or
        ``{"sign": [1, -1, ...]}``, a geometry finding's ``{"gravity": [...]}`` or ``{"position_offset": {joint:
        "pi/2"}}``): what ``dynid init`` writes (not in results.json, whose ``text`` says it).
    """

    kind: str
    text: str
    joint: int | None = None
    fix: dict | None = field(default=None, compare=False)

    def to_dict(self) -> dict:
        """The finding as results.json stores it.

        Returns
        -------
        dict
            ``kind``, ``text`` and, for a joint's finding, ``joint`` (1-based).
        """
        return {"kind": self.kind, "text": self.text, **({} if self.joint is None else {"joint": self.joint + 1})}


@dataclass
class ResidualSums:
    """Sums from which the residual checks follow once the parameters are known, accumulated in the estimation's
    pass (memory independent of the log's length).

    Per joint ``j``, for the rows ``z = (y, τ, f, 1)`` with ``f`` the :data:`FEATURES` of joint ``j``: the Gram matrix
    ``Σ z zᵀ``, and ``Σ z_k z_{k-1}ᵀ`` of consecutive rows (the lag-1 autocorrelation of the residual).

    Attributes
    ----------
    n_dof : int
    n_columns : int
        Regressor columns.
    gram : (n_dof, size, size) array
        ``Σ z zᵀ`` per joint.
    lagged : (n_dof, size, size) array
        ``Σ z_k z_{k-1}ᵀ`` per joint.
    count : int
        Rows added.
    """

    n_dof: int
    n_columns: int
    gram: np.ndarray = field(init=False)
    lagged: np.ndarray = field(init=False)
    count: int = 0
    _last: np.ndarray | None = None

    def __post_init__(self):
        size = self.n_columns + 1 + len(FEATURES) + 1
        self.gram = np.zeros((self.n_dof, size, size))
        self.lagged = np.zeros((self.n_dof, size, size))

    def add(self, y: np.ndarray, tau: np.ndarray, q: np.ndarray, dq: np.ndarray, *, direction: np.ndarray,
            low_speed: np.ndarray, keep: np.ndarray) -> None:
        """Fold one block of rows into the sums.

        Parameters
        ----------
        y : (M, n_dof, p) array
            Regressor rows.
        tau : (M, n_dof) array [N·m]
        q : (M, n_dof) array [rad]
            Positions.
        dq : (M, n_dof) array [rad/s]
            Velocities.
        direction : (M, n_dof) array
            Direction of motion (-1, 0, 1 or in between).
        low_speed : (n_dof,) array [rad/s]
            Speed under which a joint is near a reversal.
        keep : (M, n_dof) bool array
            The rows of moving joints the estimation uses (at rest the friction is whatever holds the joint: no check
            applies).
        """
        m = y.shape[0]
        low = (np.abs(dq) < low_speed) * direction
        f = np.stack([low, np.sin(q), np.cos(q), np.sin(2 * q), np.cos(2 * q)], axis=2)
        z = np.concatenate([y, tau[:, :, None], f, np.ones((m, self.n_dof, 1))], axis=2) * keep[:, :, None]
        self.gram += joint_gram(z)
        if self._last is not None:
            self.lagged += np.einsum("jc,jd->jcd", z[0], self._last)
        if m > 1:
            self.lagged += joint_gram(z[1:], z[:-1])
        self._last = z[-1].copy()
        self.count += m

    def residual_checks(self, beta: np.ndarray, rms_torque: np.ndarray, fc: np.ndarray | None = None, *,
                        prismatic=()) -> tuple[list, dict]:
        """The findings on the residual ``τ - yβ``, and the statistics behind them.

        Parameters
        ----------
        beta : (p,) array
            The parameters (OLS: the residual is that of the fit).
        rms_torque : (n_dof,) array [N·m]
            RMS torque of each joint (the scale a finding is judged against).
        fc : (n_dof,) array [N·m], optional
            Coulomb friction of each joint (the scale of the friction features).
        prismatic : sequence of bool
            Which joints slide: their findings say forces [N] and positions.

        Returns
        -------
        findings : list of Finding
        stats : dict
            Per joint: lag-1 autocorrelation, effective samples, the amplitude and t statistic of each feature.
        """
        p = self.n_columns
        e = np.concatenate([-np.asarray(beta, dtype=float), [1.0]])  # r = e·(y, τ)
        findings: list = []
        stats: dict[str, list] = {"lag1_autocorrelation": [], "effective_samples": [], "friction_amplitude": [],
                               "friction_t": [], "position_amplitude": [], "position_t": []}
        for j in range(self.n_dof):
            g = self.gram[j]
            head = slice(0, p + 1)
            rr = float(e @ g[head, head] @ e)
            n = max(float(g[-1, -1]), 1.0)  # the kept rows of this joint
            # regress r on (features, 1) over the kept rows: normal equations from the Gram's feature block
            fi = slice(p + 1, g.shape[0])
            ff = g[fi, fi]
            fr = g[fi, head] @ e
            inv = np.linalg.pinv(ff, rcond=1e-12)
            coef = inv @ fr
            rss = max(rr - float(coef @ fr), 0.0)
            # the lag-1 autocorrelation of what the features leave (u = r - X c, mean 0): Σ u_k u_{k-1} / Σ u²
            full = np.concatenate([e, -coef])
            rho = float(np.clip(full @ self.lagged[j] @ full / max(rss, 1e-300), -0.99, 0.99))
            n_eff = max(n * (1 - rho) / (1 + rho), 2.0)
            # the coefficients' variance of independent rows, inflated by n / n_eff for the correlation
            s2 = rss / max(n - ff.shape[0], 1.0)
            se = np.sqrt(np.maximum(np.diag(inv) * s2 * (n / n_eff), 1e-300))
            t = coef / se
            stats["lag1_autocorrelation"].append(rho)
            stats["effective_samples"].append(n_eff)
            stats["friction_amplitude"].append(float(coef[0]))
            stats["friction_t"].append(float(t[0]))
            # the position dependence: its size is the spread of the fitted harmonic part over the angles the joint
            # went through (√2 times its RMS about its mean, the amplitude of a sine), from the features' Gram; the
            # coefficients' own amplitude is no size: over a narrow range of angles sin q, cos q, sin 2q, cos 2q and
            # the constant are nearly collinear, and large coefficients cancel (±100 N·m said of a 1 N·m joint)
            pos = coef[1:5]
            harmonic = slice(1, 5)
            mean = float(ff[harmonic, -1] @ pos) / n
            amp = float(np.sqrt(2 * max(float(pos @ ff[harmonic, harmonic] @ pos) / n - mean**2, 0.0)))
            t_pos = float(np.sqrt(np.sum(t[1:5] ** 2) / 4))
            stats["position_amplitude"].append(amp)
            stats["position_t"].append(t_pos)
            scale, unit = rms_torque[j], joint_unit("N·m", prismatic, j)
            friction_size = abs(coef[0]) >= 0.05 * scale or (fc is not None and abs(coef[0]) >= 0.2 * abs(fc[j]))
            if abs(t[0]) >= SIGNIFICANT and friction_size and abs(coef[0]) > 0:
                findings.append(Finding("friction", f"J{j + 1}: the residual follows the direction of motion at low speed "
                                        f"({coef[0]:+.3g} {unit}, t = {t[0]:.1f}): the friction model misfits near reversals",
                                        j))
            if t_pos >= SIGNIFICANT and amp >= POSITION_SHARE * scale:
                where = "position" if unit != "N·m" else "angle"
                findings.append(Finding("position", f"J{j + 1}: the residual depends on the joint's {where} (±{amp:.3g} "
                                        f"{unit} over its {where}s, {100 * amp / scale:.2g} % of its RMS torque, "
                                        f"t = {t_pos:.1f}): a counterbalance, a cable, a wrong mass or gravity? "
                                        "(counterbalance = true in the description models one)", j))
        return findings, stats


UNLIKE_NOMINAL = 0.5
"""A log whose measured torque correlates with the description's nominal model below this on every joint that varies
(beyond friction where that is known; either sign: a flipped sign is another finding's) is not read as torques. The
largest of these correlations is 0.97-1.0 on the five real configs of configs/ and 0.68-1.0 on the 36 windows of 3-6
s that benchmarks/short_windows.py cuts from them (the KR 300's 7-10 s the lowest); the UR10e example's log with its
joint velocities read as torques reaches 0.06."""

LIKE_A_STATE = 0.995
"""A torque column whose correlation with its joint's velocity or position reaches this is said to be that signal."""


UNFITTED = "and no fit follows them either"
"""What a "columns" finding says where no fit follows the torques either and no column is named (:func:`unlike_nominal_findings`):
both causes, the first line too (:func:`dynid.report.summaries.readiness`)."""


def unlike_nominal_findings(correlation: np.ndarray, varies: np.ndarray, dataset: str, *, q: np.ndarray,
                            dq: np.ndarray, tau: np.ndarray, table: str = "[identification]",
                            explained: bool = False, unfitted: bool = False) -> list[Finding]:
    """Torques that are not torques: the measured torque follows the description's nominal model on no joint that
    varies (:data:`UNLIKE_NOMINAL`), so no scale, sign or order of the columns can be judged and a fit of another
    signal (a log's velocities read as torques fit to 0.0007 % by the viscous terms) would look perfect; or every
    joint's torque column equals its velocity or position (:data:`LIKE_A_STATE`; positions can follow gravity's shape);
    or two joints' columns are one signal (:data:`SAME_SIGNAL`: a column read for another joint's). The columns that
    equal a state or each other are named.

    Parameters
    ----------
    correlation : (n_dof,) array
        Each joint's correlation of the measured torque with the nominal model's (beyond friction where known).
    varies : (n_dof,) bool array
        Joints whose measured torque varies beyond its noise.
    dataset : str
    q, dq, tau : (N, n_dof) arrays
        The log's positions [rad], velocities [rad/s] and torques [N·m], as prepared.
    table : str
        The config table whose columns to check.
    explained : bool
        Another check explains why the torques do not follow the nominal model (the log's geometry: gravity along
        another axis, a joint's zero): only columns that equal a state are then said.
    unfitted : bool
        No fit follows the torques either (:func:`unexplained_finding`): torques read right that no model of the arm
        follows (a controller or a simulation oscillating) look the same, so both causes are said unless a column is
        named as a state.

    Returns
    -------
    list of Finding
        One finding of kind "columns" (the log is not read as the robot file says) or "spikes" (it is, but its torques
        are mostly spikes: :func:`spiky_joints`), or none.
    """
    same = _same_columns(tau, varies)
    if same:
        return [Finding("columns", f"{dataset}: {', '.join(f'J{j + 1} and J{k + 1}' for j, k in same)} log one torque "
                                   f"(their columns correlate to {SAME_SIGNAL} or more): a column read for another "
                                   f"joint's; check the torques (or currents) columns of {table}")]
    rho = np.asarray(correlation, dtype=float)
    judged = [j for j in range(rho.size) if varies[j] and np.isfinite(rho[j])]
    if not judged:
        return []
    named = state_columns(q, dq, tau, judged)
    if len(named) == len(judged):  # each joint's column a state: not torques, whatever shape gravity gives them
        return [Finding("columns", f"{dataset}: every joint's measured torque equals one of its states "
                                   f"({', '.join(named)}): these columns are not read as the robot's torques; check "
                                   f"the torques (or currents) columns of {table}")]
    best = max(abs(rho[j]) for j in judged)  # a torque whose sign is flipped follows the model all the same
    if best >= UNLIKE_NOMINAL or explained:
        return []
    spikes = spiky_joints(tau, judged)
    if spikes:  # torques, read right, that no model of the arm's motion follows: say what they are
        return [Finding("spikes", f"{dataset}: the measured torques of {', '.join(f'J{j + 1}' for j, _ in spikes)} are "
                                  "mostly spikes (single samples up to " + ", ".join(f"{jump:.3g}" for _, jump in spikes)
                                  + "× the joint's RMS torque from the one before, which carry much of its variance) and "
                                  f"on no joint do the torques follow the description's nominal model (largest "
                                  f"correlation {best:.2f}): a controller or a simulation chattering, or glitches in the "
                                  "torque channel, which no model of the arm follows; look at these columns of "
                                  f"{table} (a plot of the log) and log a motion without them before identifying")]
    which = f" ({', '.join(named)}: a column taken for another?)" if named else ""
    said = ("these columns are not read as the robot's torques" if named or not unfitted else
            f"{UNFITTED}: these columns read another signal, or torques that no model of the arm follows (a controller "
            "or a simulation oscillating, a resonance)")
    return [Finding("columns", f"{dataset}: the measured torques follow the description's nominal model on no joint (its "
                               f"largest correlation with them {best:.2f}, where the real logs' reach 0.68-1.0){which}: "
                               f"{said}; check the torques (or currents) columns of {table}, a plot of the log and the "
                               "robot file before trusting any fit of them")]


SPIKES = 10.0
"""A torque column whose second differences' RMS is this many times their robust spread (1.4826·MAD, as the noise
floor estimates it: :mod:`dynid.validation.noise_floor`) is carried by a few samples far from their neighbours: spikes,
not noise (white noise gives 1; the torque columns of ../shared/data's logs 1.0-6.2, their position columns up to 9.2;
benchmarks/NOTEBOOK.md, stop 117)."""

SPIKE_SHARE = 0.1
"""...and whose second differences (over 6, their white-noise variance) reach this share of the column's variance:
the spikes are much of what the column holds (the moving logs of ../shared/data 0-0.18, their position columns 0; a
joint at rest holds its noise alone, whose share is high but which is not spikes)."""


UNEXPLAINED = 50.0
"""[%] A log whose best fit leaves more than this share of its RMS torque unexplained beyond the torques' own noise
(``√(fit² − floor²)`` over all joints, each set's error on the samples the fit is scored on) holds torques that the
arm's model with friction cannot express: half its RMS, three quarters of its mean square. The four real logs of
../shared/data and their 36 windows of 3-6 s leave 0-15.6 % (the KR 300's 0-4 s the most), the zoo's cells 0-26.8 %
(the SO-100's `cad-gear`), but for the xArm7 whose MuJoCo simulation chatters (`sign` friction: 65-113 %;
benchmarks/NOTEBOOK.md, stop 118)."""


def unexplained_finding(fit, dataset: str) -> list[Finding]:
    """The log's torques that no set fits beyond their noise (:data:`UNEXPLAINED`).

    Parameters
    ----------
    fit : TorqueComparison
        The identification log's comparison of every set (its metrics and noise floor).
    dataset : str

    Returns
    -------
    list of Finding
        One of kind "unexplained" (the best set's error, the floor, the joints the best set misses by more than
        :data:`UNEXPLAINED`), or none.
    """
    metrics = fit.metrics()
    if not metrics:
        return []
    best = min(metrics, key=lambda k: float(metrics[k]["global_relative_error"]))
    error = float(metrics[best]["global_relative_error"])
    floor_metrics = fit.floor_metrics()
    floor = float(floor_metrics["global_relative_error"]) if floor_metrics is not None else 0.0
    floor = floor if np.isfinite(floor) else 0.0
    if not np.isfinite(error) or np.sqrt(max(error**2 - floor**2, 0.0)) <= UNEXPLAINED:
        return []
    per_joint = np.asarray(metrics[best]["relative_error"], dtype=float)
    missed = [j for j in np.argsort(-np.nan_to_num(per_joint, nan=-1.0)) if per_joint[j] > UNEXPLAINED][:4]
    joints = ", ".join(f"J{j + 1} {per_joint[j]:.3g} %" for j in missed)
    return [Finding("unexplained", f"{dataset}: the best fit to this log, {best}, misses {error:.3g} % of its torque over "
                                   f"all joints ({joints}), where the torques' own noise accounts for {floor:.3g} %: "
                                   "what the arm's model with friction cannot express carries most of these torques (a "
                                   "controller or a simulation oscillating or chattering, a spring or a cable, a contact, "
                                   "another signal in a column); look at a plot of the log before using any model fitted "
                                   "to it")]


def spiky_joints(tau, joints) -> list[tuple[int, float]]:
    """The joints among ``joints`` whose torque column is mostly spikes (:data:`SPIKES`, :data:`SPIKE_SHARE`), each
    with its largest sample-to-sample change over its RMS torque.

    Parameters
    ----------
    tau : (N, n_dof) array or StoredColumns [N·m or N]
        Torques, as prepared (unfiltered: a filtered column's spikes are spread out and not found).
    joints : sequence of int
        0-based joints to look at.

    Returns
    -------
    list of (int, float)
    """
    out = []
    for j in joints:
        x = np.asarray(tau[:, j], dtype=float)
        d2 = np.diff(x, 2)
        if d2.size < 3:
            continue
        energy, variance = float(np.mean(d2**2)), float(np.var(x))
        spread = 1.4826 * float(np.median(np.abs(d2 - np.median(d2))))
        if variance > 0 and energy / 6 >= SPIKE_SHARE * variance and energy >= (SPIKES * spread) ** 2:
            out.append((j, float(np.max(np.abs(np.diff(x)))) / float(np.sqrt(np.mean(x**2)))))
    return out


def state_columns(q, dq, tau, joints) -> list[str]:
    """The joints among ``joints`` whose torque column equals its velocity or position (:data:`LIKE_A_STATE`).

    Parameters
    ----------
    q, dq, tau : (N, n_dof) arrays
        Positions [rad], velocities [rad/s] and torques [N·m] of a log (stored columns are read one at a time).
    joints : iterable of int
        The joints to look at (0-based).

    Returns
    -------
    list of str
        ``"J1's is its velocity"`` for each such joint, in the order of ``joints``.
    """
    named = []
    for j in joints:
        torque = _centred(tau[:, j])  # each column read once (a long log's are stored), none stacked with another
        for signal, states in (("velocity", dq), ("position", q)):
            if _correlation(_centred(states[:, j]), torque) >= LIKE_A_STATE:
                named.append(f"J{j + 1}'s is its {signal}")
                break
    return named


def _centred(column) -> np.ndarray:
    """A column less its mean, as a new array."""
    column = np.asarray(column, dtype=float)
    return column - column.mean()


def _correlation(a: np.ndarray, b: np.ndarray) -> float:
    """The correlation coefficient of two centred columns (0 where one does not vary)."""
    aa, bb = float(a @ a), float(b @ b)
    return float(a @ b) / np.sqrt(aa * bb) if aa > 0 and bb > 0 else 0.0


SAME_SIGNAL = 0.9999
"""Two joints' torque columns that correlate to this or more log one signal (a column read for another joint's): two
joints of a real arm move different links, and no real log in ../shared/data comes near (benchmarks/misread_logs.py
runs the logs as recorded)."""


def _same_columns(tau: np.ndarray, varies) -> list[tuple[int, int]]:
    """Pairs of joints (0-based, j < k) whose varying torque columns correlate to :data:`SAME_SIGNAL` or more."""
    moving = [j for j in range(tau.shape[1]) if varies[j] and np.std(tau[:, j]) > 0]
    if len(moving) < 2:
        return []
    rho = correlation_matrix(tau, moving)  # by blocks of rows: a long log's torques are not copied whole
    return [(moving[a], moving[b]) for a in range(len(moving)) for b in range(a + 1, len(moving)) if rho[a, b] >= SAME_SIGNAL]


def sign_findings(correlation: np.ndarray, varies: np.ndarray, dataset: str, table: str = "[identification]",
                  slope: np.ndarray | None = None) -> list[Finding]:
    """A flipped torque sign: the measured torques of the joints whose torque varies correlate strongly
    negatively (ρ < -0.5) with those of the description's nominal model, with about the size the other joints' have.

    Parameters
    ----------
    correlation : (n_dof,) array
        Correlation coefficient (eq. 18) of the nominal model's torques with the measured ones.
    varies : (n_dof,) bool array
        Joints whose measured torque varies beyond its noise.
    dataset : str
        The log, named in the finding.
    table : str
        The config table to fix (its ``sign``).
    slope : (n_dof,) array, optional
        The slope of each joint's measured torque on the nominal model's (beside ``correlation``). Where given, a joint
        is named only where its |slope| is within :data:`SCALE_LIMIT` of the median |slope| of the other joints whose
        |ρ| ≥ 0.5: a flipped channel keeps its size, while a joint whose small nominal torque the description misstates
        (a light wrist of a CAD model: ρ -0.5, slope -13.7 where the others' are 0.7-0.8) is not a flip. The other
        joints': with two such joints, a joint's own slope was half the median it was judged against.

    Returns
    -------
    list of Finding
    """
    corr = np.asarray(correlation, dtype=float)
    judged = [j for j in range(corr.size) if varies[j] and np.isfinite(corr[j]) and abs(corr[j]) >= 0.5]
    if slope is not None:
        k = np.abs(np.asarray(slope, dtype=float))
        sized = [j for j in judged if np.isfinite(k[j]) and k[j] > 0]

        others = {j: [i for i in sized if i != j] for j in judged}  # a joint's own slope is no yardstick for itself
        typical = {j: float(np.median(k[o])) if o else float("nan") for j, o in others.items()}
        judged = [j for j in judged if not np.isfinite(typical[j]) or not np.isfinite(k[j])
                  or 1 / SCALE_LIMIT <= k[j] / typical[j] <= SCALE_LIMIT]
    bad = [j for j in judged if corr[j] < -0.5]
    if not bad:
        return []
    n = corr.size
    joints = ", ".join(f"J{j + 1}" for j in bad)
    values = ", ".join(f"{corr[j]:.3f}" for j in bad)
    unjudged = [j for j in range(n) if j not in judged]
    why = ""
    setting: int | list[int]
    if len(bad) >= 2 and len(bad) == len(judged):  # every joint the nominal model judges: one convention for the log
        setting = -1
        if unjudged:
            why = (f"every joint's: the nominal model cannot judge {', '.join(f'J{j + 1}' for j in unjudged)}, whose "
                   "torques it barely predicts, and a log's torques usually share one sign convention; ")
    else:
        setting = [-1 if j in bad else 1 for j in range(n)]
    fix = "sign = " + (str(setting) if isinstance(setting, int) else "[" + ", ".join(map(str, setting)) + "]")
    return [Finding("sign", f"{dataset}: {joints}: the measured torques run against the description's nominal model "
                            f"(ρ = {values}): is their sign flipped? Set torques = {{ ..., {fix} }} in {table} and the "
                            f"other datasets ({why}or check the description's gravity, and whether a joint's zero is a "
                            'half turn from the robot file\'s: position_offset = "pi")', fix={"sign": setting})]


SCALE_LIMIT = 3.0
"""The measured torques this many times the nominal model's, or less than its inverse, on the joints where their
shapes agree, are a unit or gain error (:func:`scale_findings`): a description's masses are rarely that far off."""

GAINS_APART = 1.2
"""Joints whose torques stand to the nominal model's in ratios this far apart, read through no drive gains (each
1 N·m/A), are motor currents through gains of their own (a UR10e's 8.5-10.7 N·m/A): one scale cannot read them."""

SCALE_SHAPE = 0.9
"""Correlation beyond friction from which a joint's torque and the nominal model's have the same shape, so that the
slope between them is a scale."""


SCALE_MISFIT = 2.0
"""One joint's scale is named only where no estimate fits that joint's torque within this many times its noise floor.
A channel in another unit is what a fit cannot follow (the links' parameters are shared with the other joints'); a
description that misstates one joint's small torque leaves the fit at the floor (a UR10's URDF read for a UR10e's
log: J4's torque 11.7× its nominal one, every joint fitted at 0.96-1.04× its floor; J2 in N·mm: 35× and more)."""


def _unapplied_gains(dataset: str, low: float, high: float, joints: str, described: np.ndarray, table: str) -> str:
    """:func:`scale_findings`' text where the torques look like motor currents and the description's drive gains
    were not applied (they were read, or given, as torques)."""
    said = ", ".join(f"{g:.4g}" for g in described)
    return (f"{dataset}: the measured torques are {low:.3g}-{high:.3g}× the description's nominal model's on {joints}, "
            f"where their shapes agree beyond friction (ρ ≥ {SCALE_SHAPE:g}), and they were read as torques: are these "
            f"motor currents? The description's drive gains ({said} N·m/A) were not applied; read them as currents "
            f"(currents = {{ ... }} in place of torques in {table} and the other datasets), or, for arrays, pass the "
            "currents times the robot's drive_gains (eq. 16)")


def scale_findings(correlation: np.ndarray, slope: np.ndarray, varies: np.ndarray, dataset: str, *,
                   table: str = "[identification]", gains: np.ndarray | None = None,
                   misfit: np.ndarray | None = None, mass: float | None = None,
                   described: np.ndarray | None = None) -> list[Finding]:
    """Torques in the wrong unit or through the wrong drive gains: on the joints whose measured torque has the shape
    of the description's nominal model beyond friction (ρ ≥ :data:`SCALE_SHAPE`), the median slope of the torque on
    that model is outside ``[1/SCALE_LIMIT, SCALE_LIMIT]``; or, where the median is within, some joints' slopes are
    outside while at least two others' are within (one channel's unit or gain). A fit absorbs such a scale (a model
    with masses 1000× the robot's, from currents in mA, fits as well as the right one), so only the description can
    see it.

    Parameters
    ----------
    correlation : (n_dof,) array
        Each joint's partial correlation of the measured torque with the nominal model's beyond its friction terms
        (:meth:`dynid.validation.torques.TorqueSums.beyond`).
    slope : (n_dof,) array
        The slope of the measured torque on the nominal model's, beyond friction.
    varies : (n_dof,) bool array
        Joints whose measured torque varies beyond its noise.
    dataset : str
        The log, named in the finding.
    table : str
        The config table to fix (its ``scale``).
    gains : (n_dof,) array, optional
        The drive gains the torques were read through [N·m/A]: each joint's gain that would bring its slope to 1 is
        said, for a log of motor currents (eq. 16) whose description states none (a URDF's are 1).
    misfit : (n_dof,) bool array, optional
        Joints that no estimate fits within :data:`SCALE_MISFIT` times their noise floor: only these may have a scale
        of their own (default: every joint).
    mass : float, optional
        The description's moving links' mass in all [kg], said beside a scale of every joint: the description's
        masses in another unit (grams) or placeholders are as likely as the log's unit.
    described : (n_dof,) array, optional
        The description's drive gains [N·m/A]. Where the torques were read through none (``gains`` all 1) and these
        are not all 1, torques that look like motor currents are said to be read as currents through them.

    Returns
    -------
    list of Finding
    """
    rho, k = np.asarray(correlation, dtype=float), np.asarray(slope, dtype=float)
    judged = [j for j in range(rho.size) if varies[j] and np.isfinite(rho[j]) and rho[j] >= SCALE_SHAPE
              and np.isfinite(k[j]) and k[j] > 0]
    if not judged:
        return []
    median = float(np.median(k[judged]))
    if 1 / SCALE_LIMIT <= median <= SCALE_LIMIT:
        return _joint_scale_findings(k, judged, dataset, table, misfit)
    fix = scale_text(median)
    joints = ", ".join(f"J{j + 1}" for j in judged)
    per_joint = "" if gains is None else (
        f" (motor currents: about {', '.join(f'{gains[j] / k[j]:.3g}' for j in judged)} N·m/A on {joints} by the "
        "description's nominal model, as right as its masses; [drive_gains] identifies them from a run with a known "
        "payload)")
    said = "" if mass is None else f"; its moving links weigh {mass:.3g} kg in all"
    cause = (f"a unit (currents in mA? torques in N·mm?), the drive gains, or the description's masses far too small "
             f"(placeholders?{said})" if median > 1 else
             f"the description's masses in another unit (grams?{said}) or far too large, or the log's unit or drive gains")
    low, high = float(np.min(k[judged])), float(np.max(k[judged]))
    if gains is not None and np.all(np.asarray(gains) == 1.0) and high > GAINS_APART * low:
        # currents read at 1 N·m/A: one scale leaves each joint's rows scaled by its own gain, which no rigid body fits
        if described is not None and not np.all(np.asarray(described) == 1.0):
            return [Finding("scale", _unapplied_gains(dataset, low, high, joints, np.asarray(described), table))]
        return [Finding("scale", f"{dataset}: the measured torques are {low:.3g}-{high:.3g}× the description's nominal "
                                 f"model's on {joints}, where their shapes agree beyond friction (ρ ≥ {SCALE_SHAPE:g}), "
                                 "and the description states no drive gains: are these motor currents? Give each "
                                 f"joint's drive_gain in [[robot.joints]]{per_joint}: one scale = {fix} would leave "
                                 "the joints' rows scaled apart by their gains, which no rigid body fits (else "
                                 f"{cause})")]
    return [Finding("scale", f"{dataset}: the measured torques are about {median:.3g}× the description's nominal "
                             f"model's on {joints}, where their shapes agree beyond friction (ρ ≥ {SCALE_SHAPE:g}): "
                             f"{cause}; set scale = {fix} in the torques (or currents) of {table} and the other "
                             f"datasets, or correct the description's masses or its drive_gain{per_joint}")]


def _joint_scale_findings(slope: np.ndarray, judged: list, dataset: str, table: str,
                          misfit: np.ndarray | None = None) -> list[Finding]:
    """Some joints' torques far from the nominal model's size where the other judged joints' agree with it (at least
    two, median within ``[1/SCALE_LIMIT, SCALE_LIMIT]``) and the fit cannot follow them (``misfit``): one channel in
    another unit or through another gain."""
    outside = [j for j in judged if not 1 / SCALE_LIMIT <= slope[j] <= SCALE_LIMIT]
    off = [j for j in outside if misfit is None or misfit[j]]
    if not off or len(judged) - len(outside) < 2:
        return []
    fixes = ", ".join(scale_text(slope[j]) if j in off else "1" for j in range(slope.size))
    joints = ", ".join(f"J{j + 1} ({slope[j]:.3g}×)" for j in off)
    return [Finding("scale", f"{dataset}: the measured torques are far from the description's nominal model's on "
                             f"{joints}, where the other joints' agree with it (ρ ≥ {SCALE_SHAPE:g} beyond friction): "
                             "a channel in another unit, or through another drive gain; set scale = "
                             f"[{fixes}] in the torques (or currents) of {table} and the other datasets, or check "
                             "those joints' drive_gain in the description", off[0])]


def scale_text(slope: float) -> str:
    """The scale that brings a slope to 1: a power of ten where the slope is one (to 0.1 decade), else 3 digits.

    Parameters
    ----------
    slope : float
        A measured torque over a predicted one (> 0).

    Returns
    -------
    str
        ``"0.001"``, ``"10"``, ``"0.0855"``: the value of a ``scale`` setting.
    """
    power = round(float(np.log10(slope)))
    return f"{10.0 ** -power:g}" if abs(np.log10(slope) - power) < 0.1 else f"{1 / slope:.3g}"


ORDER_GAIN = 0.25
"""A joint's measured torque fits another joint's nominal torque (with that joint's friction) with at most this share
of the residual power of its own: the two channels are swapped (:class:`OrderSums`)."""


class OrderSums:
    """Sums over a log's samples to tell torque channels in another order than the joints: each joint's measured
    torque regressed on each joint's nominal torque (the description's model) with that joint's friction terms —
    its direction of motion, its velocity, a constant. Channels j and k are swapped when each fits the other's
    nominal torque with at most :data:`ORDER_GAIN` of the residual power it has on its own, at a slope within
    [1/3, 3] (the nominal model's size). Shapes alone cannot tell them: on the UR10e the nominal J2 and J3 torques
    correlate at 0.9 and more; the residuals with friction differ 40-400×.

    Parameters
    ----------
    n_dof : int
    """

    def __init__(self, n_dof: int):
        self.n = n_dof
        self.gram = np.zeros((4 * n_dof + 1, 4 * n_dof + 1))

    def add(self, nominal: np.ndarray, direction: np.ndarray, dq: np.ndarray, tau: np.ndarray) -> None:
        """Fold one block of samples into the sums.

        Parameters
        ----------
        nominal, direction, dq, tau : (M, n_dof) arrays
            The nominal model's torques [N·m], each joint's direction of motion (-1, 0, 1), velocities [rad/s] and the
            measured torques [N·m].
        """
        z = np.column_stack([nominal, direction, dq, np.ones(nominal.shape[0]), tau])
        self.gram += z.T @ z

    def _fit(self, j: int, k: int) -> tuple[float, float]:
        """Residual power of measured torque ``j`` on joint ``k``'s nominal torque and friction terms, and the slope."""
        n = self.n
        cols = [k, n + k, 2 * n + k, 3 * n]
        a, b = self.gram[np.ix_(cols, cols)], self.gram[cols, 3 * n + 1 + j]
        coef = np.linalg.lstsq(a, b, rcond=None)[0]
        return float(self.gram[3 * n + 1 + j, 3 * n + 1 + j] - coef @ b), float(coef[0])

    def findings(self, varies: np.ndarray, dataset: str, table: str = "[identification]") -> list[Finding]:
        """The swapped pairs, one finding naming them.

        Parameters
        ----------
        varies : (n_dof,) bool array
            Joints whose measured torque varies beyond its noise.
        dataset : str
            The log, named in the finding.
        table : str
            The config table to fix (its torque or current columns).

        Returns
        -------
        list of Finding
        """
        n = self.n
        fits = [[self._fit(j, k) for k in range(n)] for j in range(n)]
        swapped = []
        for j in range(n):
            for k in range(j + 1, n):
                (r_jk, s_jk), (r_kj, s_kj) = fits[j][k], fits[k][j]
                own_j, own_k = fits[j][j][0], fits[k][k][0]
                if (varies[j] and varies[k] and own_j > 0 and own_k > 0 and r_jk <= ORDER_GAIN * own_j
                        and r_kj <= ORDER_GAIN * own_k and 1 / 3 <= s_jk <= 3 and 1 / 3 <= s_kj <= 3):
                    swapped.append(f"J{j + 1} and J{k + 1} (each fits the other's nominal torque with "
                                   f"{100 * r_jk / own_j:.2g} % and {100 * r_kj / own_k:.2g} % of the residual of its "
                                   "own)")
        if not swapped:
            return []
        return [Finding("order", f"{dataset}: the torques of {'; '.join(swapped)} look swapped: check the order of the "
                                 f"torque or current columns of {table} and the other datasets")]


DELAY_SIGNIFICANT = 3.0
"""A torque channel's delay is reported when it lies this many of its σ from 0 …"""

DELAY_MIN_SAMPLES = 0.25
"""… and is at least this many samples (half a control period, a zero-order hold's, biased the ER-16's least squares by
0.13 %)."""


DELAY_ADVICE = "identify again with it, and keep it if validation logs (other motions) agree"
"""The delay finding's last words, which :meth:`dynid.identification.pipeline.IdentificationPipeline.fit` replaces
with the validation logs' answer where it has them."""


def delay_findings(samples: float, std: float, determined: bool, rate: float, given: float, dataset: str,
                   held_out: float = float("nan")) -> list[Finding]:
    """A delay between the torque (current) and position channels that the log determines and that matters.

    Worded as what to try: a real log's residual is also smallest at a delay that trades off against a misfit of the
    model (measured on the LBR Med7's identification log: -1.88 ± 0.04 samples; identified again with it, its
    validation errors moved both ways), so the validation logs decide.

    Parameters
    ----------
    samples, std : float
        The delay the log shows on top of the one given, and its σ [samples] (:func:`dynid.identification.delay.estimate_delay`).
    determined : bool
        Whether the log determines it (:attr:`dynid.identification.delay.DelayEstimate.determined`).
    rate : float [Hz]
        The log's rate.
    given : float [s]
        ``preprocessing.torque_delay`` already applied.
    dataset : str
        The log, named in the finding.
    held_out : float
        The held-out residual with the delay over that without (:attr:`dynid.identification.delay.DelayEstimate.held_out`):
        no finding unless it is below 1 (a delay that does not improve what the model predicts of blocks of the log it
        was not fitted on is a trade-off with a misfit of the model, not a delay of the drive); NaN: not measured.

    Returns
    -------
    list of Finding
        One finding with the ``torque_delay`` to try, or none when the log determines no delay that matters.
    """
    if not determined or abs(samples) < max(DELAY_SIGNIFICANT * std, DELAY_MIN_SAMPLES) or not held_out < 1.0:
        return []
    way = "lag" if samples > 0 else "lead"
    total = given + samples / rate
    more = " more than the torque_delay given" if given else ""
    return [Finding("delay", f"{dataset}: the residual is smallest with the torques read as if they {way} the positions by "
                             f"{abs(samples):.2g} ± {std:.1g} samples ({1e3 * abs(samples) / rate:.3g} ms{more}), and so "
                             f"its squared residual on held-out blocks of the log is {100 * (1 - held_out):.2g} % smaller: if the "
                             f"drive logs them so, give [preprocessing] torque_delay = {total:.4g} (seconds; "
                             f"Preprocessing(torque_delay=...) for arrays) and {DELAY_ADVICE}")]


def validation_findings(name: str, global_error: float, fit_error: float, *, prediction_spread: np.ndarray | None,
                        fit_spread: np.ndarray | None, label: str, floor: float = float("nan")) -> list[Finding]:
    """Extrapolation and a validation error far above the identification's, for one validation log.

    Parameters
    ----------
    name : str
        The validation log.
    global_error : float [%]
        Its global relative error (NaN: not judged).
    fit_error : float [%]
        The identification's.
    prediction_spread, fit_spread : (n_dof,) arrays [N·m] or None
        RMS over the samples of the prediction's standard deviation from the parameters' covariance, on the validation
        log and on the identification log.
    label : str
        The estimate judged.
    floor : float [%]
        The log's noise floor over all joints (:mod:`dynid.validation.noise_floor`; NaN: unknown).

    Returns
    -------
    list of Finding
    """
    out = []
    if np.isfinite(global_error) and np.isfinite(floor) and global_error <= AT_FLOOR * floor:
        return [Finding("floor", f"{name}: {label} scores {global_error:.3g} %, at the noise floor of this log's samples "
                                 f"({floor:.3g} %: what a perfect model scores there, from the torques' own noise); "
                                 "nothing is left for a better model to explain")]
    if prediction_spread is not None and fit_spread is not None:
        ratio = np.asarray(prediction_spread) / np.maximum(np.asarray(fit_spread), 1e-12)
        far = np.flatnonzero(ratio > 5.0)
        if far.size:
            j = int(far[np.argmax(ratio[far])])
            out.append(Finding("extrapolation", f"{name}: {label}'s predictions leave the range the identification log "
                               f"supports: J{j + 1}'s prediction σ is {ratio[j]:.0f}× that on the identification log "
                               f"({prediction_spread[j]:.3g} N·m); trust a physically consistent estimate there, or "
                               "identify on a log that covers this motion", j))
    if np.isfinite(global_error) and fit_error > 0 and global_error > 3 * fit_error:
        times = global_error / fit_error
        # 4.5, 2964 (not 2963.8), 1.37e+16 (not 13696171289551554.0: an estimate gone astray)
        shown = f"{times:.1f}" if times < 10 else f"{times:.0f}" if times < 1e4 else f"{times:.3g}"
        out.append(Finding("validation", f"{name}: {label} predicts it {shown}× worse than it fits the "
                           f"identification log ({global_error:.3g} % against {fit_error:.3g} %): over-fitting, "
                           "extrapolation or a model that misses something this motion shows"))
    return out


def nominal_gate(validations, label: str, nominal: str) -> tuple[list[Finding], dict]:
    """Whether an estimate predicts the validation logs better than the description's nominal model, joint by joint:
    the gate before a model is published (exported to a controller or simulator).

    Parameters
    ----------
    validations : sequence of TorqueComparison
        The validation logs, each scored with ``label`` and ``nominal``.
    label : str
        The estimate judged.
    nominal : str
        The nominal model's set.

    Returns
    -------
    findings : list of Finding
        One: the joints where the nominal model predicts better, with both figures; or that the estimate is better
        on every joint.
    stats : dict
        Per validation log: both per-joint errors [%] and the joints (1-based) where the nominal predicts better.
    """
    stats, worse_lines, better = {}, [], []
    for v in validations:
        metrics = v.metrics()
        if label not in metrics or nominal not in metrics:
            continue
        own = np.asarray(metrics[label]["relative_error"], dtype=float)
        nom = np.asarray(metrics[nominal]["relative_error"], dtype=float)
        judged = v.meaningful() & np.isfinite(own) & np.isfinite(nom)
        worse = [int(j) for j in np.flatnonzero(judged & (own > nom))]
        stats[v.name] = {"estimate": label, "nominal": nominal, "estimate_error_percent": own.tolist(),
                         "nominal_error_percent": nom.tolist(), "worse_joints": [j + 1 for j in worse]}
        if worse:
            shown = ", ".join(f"J{j + 1} {own[j]:.3g} % against {nom[j]:.3g} %" for j in worse[:4])
            worse_lines.append(f"{v.name}: {shown}" + (f" and {len(worse) - 4} more" if len(worse) > 4 else ""))
        else:
            own_g, nom_g = float(metrics[label]["global_relative_error"]), float(metrics[nominal]["global_relative_error"])
            without = (f" without {', '.join(f'J{j + 1}' for j in v.dead_said)} (a dead or saturated torque channel)"
                       if v.dead_said else "")
            better.append((own_g < nom_g, v.name, f"{v.name}: {own_g:.3g} % against {nom_g:.3g} %{without}"))
    if worse_lines:
        more = f"; and {len(worse_lines) - 3} more logs" if len(worse_lines) > 3 else ""
        return [Finding("nominal", f"the description's nominal model predicts some joints of the validation logs better "
                                   f"than {label} ({'; '.join(worse_lines[:3])}{more}; results.json: "
                                   "diagnostics.versus_nominal): keep the nominal values for those joints, or identify "
                                   "on a log that excites them (dynid excite)")], stats
    if better:
        return [Finding("nominal", _no_worse_than_nominal(label, better))], stats
    return [], stats


def _no_worse_than_nominal(label: str, logs: list) -> str:
    """:func:`nominal_gate`'s sentence when no joint is worse; ``logs``: (strictly better overall, name, figures) per
    log. A log where both score the same (at rest within the static-friction band both read 0 %) is said to be equal,
    not better, and the logs that show a difference come first."""
    strict = [text for better, _, text in logs if better]
    same = [name for better, name, _ in logs if not better]
    shown = strict[:3]
    more = f"; and {len(strict) - 3} more logs" if len(strict) > 3 else ""
    if not same:
        return (f"{label} predicts every joint of the validation logs better than the description's nominal model "
                f"({'; '.join(shown)}{more}, over all joints)")
    equal = ", ".join(same[:4]) + (f" and {len(same) - 4} more" if len(same) > 4 else "")
    head = (f"{label} predicts no joint of the validation logs worse than the description's nominal model: better on "
            f"{len(strict)} of the {len(logs)} logs")
    return head + (f" ({'; '.join(shown)}{more}, over all joints)" if strict else "") + f", the same on {equal}"


BOOTSTRAP_BLOCKS = 20
"""Contiguous blocks of the identification log for the moving-block bootstrap of σ."""

BOOTSTRAP_RESAMPLES = 200


class BlockGrams:
    """Per contiguous block of the log, each joint's Gram matrix of ``(y, τ)`` over the rows the estimation uses: a
    moving-block bootstrap resamples blocks, not rows (the residuals are correlated in time), and refits by the normal
    equations (Künsch, Ann. Statist. 17(3), 1989).

    Parameters
    ----------
    n_dof, n_columns, n_samples : int
        Joints, regressor columns, samples of the log (blocks by sample index).
    blocks : int
    """

    def __init__(self, n_dof: int, n_columns: int, n_samples: int, blocks: int = BOOTSTRAP_BLOCKS):
        self.blocks = blocks
        self.n_samples = max(int(n_samples), 1)
        self.gram = np.zeros((blocks, n_dof, n_columns + 1, n_columns + 1))

    def add(self, index: np.ndarray, y: np.ndarray, tau: np.ndarray, keep: np.ndarray) -> None:
        """Fold one block of rows into the Gram matrix of its contiguous block of the log.

        Parameters
        ----------
        index : (M,) int array
            Sample indices of the rows.
        y : (M, n_dof, p) array
            Regressor rows.
        tau : (M, n_dof) array [N·m]
        keep : (M, n_dof) bool array
            Rows the estimation uses.
        """
        z = np.concatenate([y, tau[:, :, None]], axis=2) * keep[:, :, None]
        block = np.minimum(index * self.blocks // self.n_samples, self.blocks - 1)
        for b in np.unique(block):
            zb = z[block == b]
            self.gram[b] += joint_gram(zb)

    def bootstrap_std(self, weights: np.ndarray | None = None, rng=0, resamples: int = BOOTSTRAP_RESAMPLES) -> np.ndarray:
        """Moving-block bootstrap standard deviation of the (weighted) least-squares parameters: the blocks' Gram
        matrices resampled with replacement, each resample solved (Künsch 1989; blocks keep the residuals' correlation).

        Parameters
        ----------
        weights : (n_dof,) array, optional
            Row weight of each joint (the WLS weights).
        rng : int or numpy.random.Generator
            Seeds the resampling.
        resamples : int

        Returns
        -------
        (p,) array
        """
        rng = np.random.default_rng(rng)
        w = np.ones(self.gram.shape[1]) if weights is None else np.asarray(weights, dtype=float)
        g = np.einsum("j,bjcd->bcd", w**2, self.gram)  # joints weighted, summed: one Gram per block
        p = g.shape[1] - 1
        counts = np.zeros((resamples, self.blocks))  # each resample: how often it drew each block
        for r in range(resamples):
            counts[r] = np.bincount(rng.integers(0, self.blocks, self.blocks), minlength=self.blocks)
        totals = np.einsum("rb,bcd->rcd", counts, g)
        a, b = totals[:, :p, :p], totals[:, :p, p]
        scale = np.sqrt(np.maximum(np.diagonal(a, axis1=1, axis2=2), 1e-300))
        scaled = a / scale[:, :, None] / scale[:, None, :] + 1e-12 * np.eye(p)  # a ridge for unexcited directions
        draws = np.linalg.solve(scaled, (b / scale)[:, :, None])[:, :, 0] / scale
        return np.std(draws, axis=0, ddof=1)


def bootstrap_finding(covariance_std: np.ndarray, bootstrap_std: np.ndarray) -> tuple[list[Finding], float]:
    """σ from the covariance against the bootstrap's: a finding when the covariance understates the spread by 2×
    or more.

    Parameters
    ----------
    covariance_std : (p,) array
    bootstrap_std : (p,) array

    Returns
    -------
    findings : list of Finding
    ratio : float
        Median over the parameters of bootstrap σ / covariance σ.
    """
    cov = np.asarray(covariance_std, dtype=float)
    known = np.isfinite(cov)  # parameters kept at the prior have no σ from the data
    ratio = float(np.median(np.asarray(bootstrap_std)[known] / np.maximum(cov[known], 1e-300))) if known.any() else float("nan")
    if ratio >= 2.0:
        return [Finding("correlated", f"σ from the covariance is {ratio:.1f}× below the moving-block bootstrap's (median over "
                                      "the parameters): the residuals are correlated or the model misfits; read the "
                                      "bootstrap's σ (results.json: bootstrap_std)")], ratio
    return [], ratio


def prior_findings(names, from_prior, one_way: list[int], dataset: str, *, dead: tuple[int, ...] = (),
                   still: list[int] | tuple[int, ...] = (), anchored=()) -> list[Finding]:
    """The parameters a log does not determine, whose values are the description's nominal ones (least squares with a
    prior, :meth:`dynid.estimators.accumulate.LeastSquaresAccumulator.solve`).

    Parameters
    ----------
    names : sequence of str
        Base parameters.
    from_prior : sequence of int
        The indices of those left at the prior.
    one_way : list of int
        Joints (0-based) that moved in one direction only in the log: their Coulomb friction and offset are one term.
    dataset : str
    dead : tuple of int
        Joints whose torque channel is dead in the log (their rows were left out).
    still : sequence of int
        Joints that never moved in the log (their friction and rotor inertia appear in no row).
    anchored : sequence of int
        The Coulomb friction parameters that took their joint's one Coulomb + offset term, its offset kept at the
        prior (:attr:`dynid.estimators.accumulate.LeastSquaresSolution.anchored`).

    Returns
    -------
    list of Finding
    """
    if not len(from_prior):
        return []
    shown = [names[i] for i in from_prior]
    both = [j for j in one_way if f"fc{j + 1}" in shown and f"offset{j + 1}" in shown]
    why = (f" ({', '.join(f'J{j + 1}' for j in both)} moved one way only: Coulomb friction and offset act as one term, "
           "their sum is estimated)" if both else "")
    taken = [names[i][2:] for i in anchored if names[i].startswith("fc")]
    if taken:
        why += (f" ({', '.join(f'J{j}' for j in taken)} moved one way only: the one term of Coulomb friction and offset is "
                "estimated and taken as Coulomb friction, the same in the direction not moved)")
    if dead:
        why += f" ({', '.join(f'J{j + 1}' for j in dead)}: a dead or saturated torque channel, its rows left out)"
    if still:
        why += f" ({', '.join(f'J{j + 1}' for j in still)} never moved in the log)"
    listed = ", ".join(shown[:10]) + (f" and {len(shown) - 10} more" if len(shown) > 10 else "")
    return [Finding("prior", f"{dataset}: the log does not determine {listed}{why}: along those directions the estimate "
                             "keeps the description's nominal values (no σ); a log that moves every joint both ways "
                             "with every torque channel live (dynid excite) determines them")]


def excitation_findings(names, params: np.ndarray, std: np.ndarray, column_rms: np.ndarray, rms_torque: float, *,
                        consistent: bool = False) -> list[Finding]:
    """Parameters the log hardly excites yet that matter: relative σ above 50 % and a torque of ±σ above 5 % of
    the RMS torque; the remedy a richer excitation and, where it is not among the estimates yet, the physically
    consistent one.

    Parameters
    ----------
    names : sequence of str
        Base parameters.
    params, std : (p,) arrays
        Estimate and standard deviations.
    column_rms : (p,) array
        RMS of each regressor column (largest over the joints).
    rms_torque : float [N·m]
    consistent : bool
        The physically consistent estimate (SDP) is among the estimates: it is said to keep them plausible, not
        suggested.

    Returns
    -------
    list of Finding
    """
    rel = np.abs(std) / np.maximum(np.abs(params), 1e-300)
    weak = [i for i in range(len(names)) if rel[i] > 0.5 and std[i] * column_rms[i] > 0.05 * rms_torque]
    if not weak:
        return []
    shown = ", ".join(names[i] for i in weak[:8]) + (f" and {len(weak) - 8} more" if len(weak) > 8 else "")
    also = ("; the physically consistent estimate keeps them plausible meanwhile (near the description's values where "
            "the log says little)") if consistent else ' or a physically consistent estimate (add "sdp" to the estimators)'
    return [Finding("excitation", f"the identification log hardly excites {shown} (σ above half their value, yet worth "
                                  f"over 5 % of the torque): a richer excitation (dynid excite){also}")]
