"""Each joint's friction model chosen by blocked cross-validation on the identification log.

Friction is the part of a real robot's torque that the rigid-body model leaves to an assumption, and the best
assumption differs from joint to joint and from robot to robot. The candidates here all keep the torque linear
in the parameters (paper eq. 6); where one has a nonlinear constant (a Stribeck or smoothing velocity, a
relaxation time), a small grid of it is searched, each point fitted by linear least squares (a separable search):

* the **state at rest** of the Coulomb-like terms (:func:`dynid.friction.held_direction`): the friction of the
  last motion held while the joint rests (a controller with integral action), relaxing with a time constant of
  1 or 0.3 s, or none at rest;
* the **family**: Coulomb + viscous (+ the description's offset, rotor inertia, counterbalance), asymmetric
  Coulomb (``fca``: while the joint moves, the same as an offset; at rest, 0 where an offset stays), Stribeck with
  its velocity, smooth Coulomb ``tanh(q̇/v_s)`` with its velocity — fitted only on the joint's rows at least
  :data:`SMOOTH_FIT_FACTOR` × ``v_s`` fast, where it is Coulomb-like — and load-dependent Coulomb (``fcl·|τ_load|``,
  harmonic drives).

A smooth Coulomb term describes how the friction fades below ``v_s``; fitted on rows slower than that, its coefficient
trades with the viscous one. On the zoo's simulated Panda (point-to-point moves, ``fc·sign(q̇)`` under a PID loop, which
chatters at rest) ``v_s`` at twice J3's ``min_speed`` gave fc3 = 2.42 and fv3 = 0.70 against the truth's 2.23 and 1.01
(2.24 and 0.99 on the rows at least 2·v_s fast), and the model predicted a faster log 3.2× worse on J3 than the
truth's parameters. A joint given a smooth Coulomb term keeps those rows out of the estimation too
(:meth:`FrictionChoice.fit_speeds`).

Every candidate is applied to all joints at once; its parameters are fitted on all contiguous blocks of the log but
one (rows of moving joints only, as the estimation) and scored on the block left out, **all** its rows, rests and
reversals included, joint by joint (Bergmeir & Benítez, Information Sciences 191, 2012). Each joint keeps the
candidate with its smallest out-of-fold error; a candidate other than the plain model must lower it by
:data:`MARGIN` to be chosen. One pass over the log accumulates, per block and joint, the Gram matrix of the
rigid-body base columns, every candidate's columns and the torque (all parallel-filtered and decimated like the
estimation's rows), so each candidate costs one small solve per block, not a pass.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from .._util.column_store import root_mean_square
from .._util.grams import joint_gram
from .._util.reprs import short_repr
from ..dynamics.base_parameters import base_parameters
from ..dynamics.regressor import regressor
from ..exceptions import IdentifiabilityError
from ..friction import TERMS, Velocities, held_direction
from ..model.friction_model import COULOMB_LIKE, JointFriction, robot_with, smoothing_velocities
from ..model.robot import Robot
from ..preprocessing.filters import parallel_decimation
from ..preprocessing.prepared import PreparedData, min_speeds, rest_decay

__all__ = ["FOLDS", "FrictionChoice", "choose_friction"]

FOLDS = 5

MARGIN = 0.01
"""A candidate other than the plain model (held at rest, Coulomb + viscous) must lower a joint's out-of-fold RMS
error by this fraction to be chosen."""

MAX_SAMPLES = 60_000
"""A longer log is cross-validated on one contiguous segment of ``MAX_SAMPLES / folds`` samples in the middle of each
block (a minute of a 1 kHz log in all): the choice needs the log's kinds of motion, not all its hours."""

REST_SHARE = 0.05
"""A joint's state at rest is judged only when at least this share of its samples are at rest in the log;
otherwise it stays "held" (what a controller with integral action does)."""

LOAD_SHARE = 0.25
"""The load-dependent term is a candidate for a joint whose nominal rigid-body torque has an RMS of at least this
share of its measured RMS torque (a transmission that carries little load cannot tell it from Coulomb)."""

REVERSAL_SHARE = 0.01
"""A joint whose moving samples go each way at least this share of the time reverses in the log; only then are the
shapes of friction near a reversal (asymmetric, Stribeck, smooth Coulomb) candidates: on a joint that moves one way
they are not determined, and a Stribeck term fitted where the speed never comes near its velocity predicts any
slower motion with a coefficient of 1e31."""

EXCITED_SHARE = 0.01
"""A Stribeck or load-dependent column is a candidate only where its RMS over the fitted rows is at least this share
of the Coulomb column's."""

REST_GRID: tuple = ("held", 1.0, 0.3, "zero")
"""Candidate states at rest: held, relaxing with these time constants [s], none."""

STRIBECK_GRID = (0.01, 0.03, 0.1, 0.3)
"""Candidate Stribeck velocities, as fractions of the joint's RMS speed."""

SMOOTH_GRID = (0.003, 0.01, 0.03, 0.1)
"""Candidate smoothing velocities of ``tanh(q̇/v_s)``, as fractions of the joint's RMS speed."""

SMOOTH_FIT_FACTOR = 2.0
"""A joint's smooth Coulomb term ``tanh(q̇/v_s)`` is fitted on its rows at least this many times ``v_s`` fast (where
``tanh`` is above 0.96), and the estimation leaves its slower rows out (module docstring)."""



@short_repr
@dataclass(frozen=True)
class FrictionChoice:
    """Friction models chosen per joint, with the out-of-fold errors behind the choice.

    Attributes
    ----------
    models : tuple of JointFriction
    candidates : tuple of str
        Labels of the candidates tried (each applied to all joints).
    error : (n_candidates, n_dof) array [N·m]
        Out-of-fold RMS torque error of each candidate, per joint, on all rows of the held-out blocks.
    plain : (n_dof,) array [N·m]
        That of the plain model (held at rest, Coulomb + viscous).
    chosen : (n_dof,) array [N·m]
        That of the chosen mixture.
    folds : int
    rest_share : (n_dof,) array
        Share of each joint's samples at rest in the log (its state at rest is judged from :data:`REST_SHARE` on).
    load_candidate : (n_dof,) bool array
        Joints for which the load-dependent term was a candidate (:data:`LOAD_SHARE`).
    """

    models: tuple[JointFriction, ...]
    candidates: tuple[str, ...]
    error: np.ndarray
    plain: np.ndarray
    chosen: np.ndarray
    folds: int
    rest_share: np.ndarray | None = None
    load_candidate: np.ndarray | None = None

    def robot(self, robot: Robot) -> Robot:
        """A robot with each joint's chosen terms (drive terms and mask) and velocities (Stribeck, smoothing).

        Parameters
        ----------
        robot : Robot

        Returns
        -------
        Robot
        """
        return robot_with(robot, self.models)

    def fit_speeds(self, min_speed) -> np.ndarray:
        """Each joint's slowest speed the estimation fits under these models.

        Parameters
        ----------
        min_speed : (n_dof,) array [rad/s]
            The prepared log's ``min_speed``.

        Returns
        -------
        (n_dof,) array [rad/s]
            ``min_speed``, raised to :data:`SMOOTH_FIT_FACTOR` × ``v_s`` for a joint with a smooth Coulomb term.
        """
        return np.maximum(np.asarray(min_speed, dtype=float), SMOOTH_FIT_FACTOR * smoothing_velocities(self.models))

    def rest_friction(self) -> tuple:
        """Each joint's state at rest, as ``Preprocessing.rest_friction``.

        Returns
        -------
        tuple
        """
        return tuple(m.rest for m in self.models)

    def to_dict(self) -> dict:
        """JSON-ready choice.

        Returns
        -------
        dict
            The models chosen, the candidates and their out-of-fold errors.
        """
        return {"models": [m.to_dict() for m in self.models], "candidates": list(self.candidates),
                "out_of_fold_rms_error": self.error, "plain_out_of_fold_rms_error": self.plain,
                "chosen_out_of_fold_rms_error": self.chosen, "folds": self.folds, "margin": MARGIN,
                "rest_share": self.rest_share, "rest_share_judged_from": REST_SHARE,
                "load_candidate": None if self.load_candidate is None else self.load_candidate.tolist()}


def choose_friction(robot: Robot, data: PreparedData, folds: int = FOLDS,
                    progress: Callable[[int, int], None] | None = None) -> FrictionChoice:
    """Choose each joint's friction model by blocked cross-validation (module docstring).

    Parameters
    ----------
    robot : Robot
        Its drive terms other than the Coulomb-like ones (rotor inertia, viscous, offset, counterbalance) are in
        every candidate.
    data : PreparedData
        The identification log after :func:`dynid.preprocessing.prepare`.
    folds : int
        Contiguous blocks (at least 2).
    progress : callable, optional
        ``progress(done, total)`` in samples of the log's one pass (most of the time the choice takes).

    Returns
    -------
    FrictionChoice
    """
    cv = _CrossValidation(robot, data, folds)
    cv.accumulate(progress)
    n = robot.n_dof
    # Stage 1: the state at rest, with the plain model; stage 2: the family, with each joint's state at rest.
    # Each candidate is first tried on all joints at once (a table of how each fares), then each joint's choice is
    # refined with the other joints at their current choices (coordinate descent): a joint whose own friction is
    # misfitted spoils the shared rigid-body parameters, and so every joint's error, under the plain model.
    labels, errors = [], []
    for r in REST_GRID:
        errors.append(cv.out_of_fold([JointFriction("coulomb", 0.0, r)] * n))
        labels.append(JointFriction("coulomb", 0.0, r).label)
    plain = errors[0]
    family = [("coulomb", 0.0), ("asymmetric", 0.0)] + [("stribeck", g) for g in STRIBECK_GRID] + \
        [("smooth", g) for g in SMOOTH_GRID] + ([("load", 0.0)] if cv.load_ok else [])
    for kind, g in family[1:]:
        errors.append(cv.out_of_fold([JointFriction(kind, g, "held")] * n))
        labels.append(JointFriction(kind, g).label.split(",")[0])
    # a smooth Coulomb term is 0 at rest (tanh(0) = 0): its state at rest is "zero"
    options = [JointFriction(kind, g, r) for kind, g in family for r in REST_GRID if kind != "smooth" or r == "zero"]
    chosen_rel = cv.descend(options)
    final = cv.out_of_fold(chosen_rel)
    models = tuple(JointFriction(m.kind, float(m.velocity * cv.speed[j]) if m.kind in ("stribeck", "smooth") else 0.0,
                                 m.rest) for j, m in enumerate(chosen_rel))
    return FrictionChoice(models, tuple(labels), np.array(errors), plain, final, folds, cv.resting / cv.rows, cv.loaded)


class _CrossValidation:
    """:func:`choose_friction`'s blocked cross-validation: a bank of candidate friction columns per joint (the
    description's other drive terms, then per state at rest the Coulomb, asymmetric, Stribeck (grid) and load
    columns, then the smooth Coulomb ones), the Gram matrices of each block from one pass over the log, and the
    out-of-fold error of any assignment of models to joints."""

    def __init__(self, robot: Robot, data: PreparedData, folds: int):
        n = robot.n_dof
        s = data.settings
        self.robot, self.data, self.n_folds = robot, data, folds
        self.rest_v = np.broadcast_to(np.asarray(0.0 if s.rest_velocity == "auto" else s.rest_velocity, dtype=float), (n,))
        self.speed = np.maximum(root_mean_square(data.dq), 1e-9)
        self.rigid = replace(robot, drive_terms=(), drive=np.zeros((n, 0)), drive_mask=np.ones((n, 0), dtype=bool))
        self.rigid_base = base_parameters(self.rigid, rng=0)
        self.p = self.rigid_base.n_base
        self.nominal = self.rigid_base.base_from_standard(self.rigid.standard_parameters())
        self.load_ok = bool(np.any(self.rigid.inertial != 0))
        self.others = [t for t in robot.drive_terms if t not in COULOMB_LIKE]
        names = list(self.others)
        for r in REST_GRID:
            names += [f"fc|{r}", f"fca|{r}"] + [f"fst|{r}|{g}" for g in STRIBECK_GRID] + ([f"fcl|{r}"] if self.load_ok else [])
        names += [f"tanh|{g}" for g in SMOOTH_GRID]
        self.index = {name: i for i, name in enumerate(names)}
        self.k_bank = len(names)
        self.has = {t: robot.drive_mask[:, robot.drive_terms.index(t)] for t in self.others}
        size = self.p + self.k_bank + 1
        self.fit = np.zeros((folds, n, size, size))
        # each smooth term's kept rows too slow for it, by band of speed: [0, 2·g_0·s), [2·g_0·s, 2·g_1·s), ...
        self.slow = np.zeros((len(SMOOTH_GRID), folds, n, size, size))
        self.score = np.zeros((folds, n, size, size))
        self.n_rows = np.zeros((folds, n))
        self.load_sq, self.tau_sq, self.resting = np.zeros(n), np.zeros(n), np.zeros(n)

    def block(self, a: int, b: int, directions, start: int):
        """Rigid-body base rows, the bank's columns and the torques of samples ``a:b`` (``directions``: each state
        at rest's direction of motion on the segment from ``start``)."""
        data, n = self.data, self.robot.n_dof
        q, dq, ddq, tau = (np.asarray(x[a:b]) for x in (data.q, data.dq, data.ddq, data.tau))
        y = regressor(self.rigid, q, dq, ddq, columns=self.rigid_base.independent)
        bank = np.zeros((b - a, n, self.k_bank))
        velocities = self.robot.friction_velocities
        v = Velocities(velocities.coulomb, velocities.stribeck, self.rest_v)
        for t in self.others:
            bank[:, :, self.index[t]] = TERMS[t].column(q, dq, ddq, v) * self.has[t]
        load = np.abs(y @ self.nominal) if self.load_ok else None
        for r, direction in zip(REST_GRID, directions):
            z = np.asarray(direction[a - start:b - start])
            bank[:, :, self.index[f"fc|{r}"]] = z
            bank[:, :, self.index[f"fca|{r}"]] = np.abs(z)
            for g in STRIBECK_GRID:
                bank[:, :, self.index[f"fst|{r}|{g}"]] = z * np.exp(-(dq / (g * self.speed)) ** 2)
            if self.load_ok:
                bank[:, :, self.index[f"fcl|{r}"]] = load * z
        for g in SMOOTH_GRID:
            bank[:, :, self.index[f"tanh|{g}"]] = np.tanh(dq / (g * self.speed))
        return y, bank, tau

    def _add(self, idx, y, bank, tau, fold, vmin) -> None:
        """One block's Gram matrices into its folds: all rows to score, the moving rows to fit."""
        data = self.data
        z = np.concatenate([y, bank, tau[:, :, None]], axis=2)
        self.tau_sq += (tau**2).sum(axis=0)
        if self.load_ok:
            self.load_sq += ((y @ self.nominal) ** 2).sum(axis=0)
        self.resting += (data.resting[idx] if data.resting is not None else
                         np.abs(np.asarray(data.dq[idx])) <= self.rest_v).sum(axis=0)
        keep = data.kept(idx, vmin)
        band = np.searchsorted(SMOOTH_FIT_FACTOR * np.asarray(SMOOTH_GRID), np.abs(np.asarray(data.dq[idx])) / self.speed,
                               side="right")  # (M, n): the first smooth term each row is fast enough for
        for f in np.unique(fold):
            sel = fold == f
            zf = z[sel]
            self.score[f] += joint_gram(zf)
            zk = zf * keep[sel][:, :, None]
            self.fit[f] += joint_gram(zk)
            bf = band[sel]
            slow = keep[sel] & (bf < len(SMOOTH_GRID))
            for j in np.flatnonzero(slow.any(axis=0)):
                for i in np.unique(bf[slow[:, j], j]):
                    rows = zf[slow[:, j] & (bf[:, j] == i), j]
                    self.slow[i, f, j] += rows.T @ rows
            self.n_rows[f] += sel.sum()

    def accumulate(self, progress: Callable[[int, int], None] | None = None) -> None:
        """The one pass over the log (or a segment of each block of a long one), parallel-filtered and decimated as
        the estimation's; then what the choice needs to know of the log (rests, load, reversals). ``progress(done,
        total)`` in samples."""
        data, s, n = self.data, self.data.settings, self.robot.n_dof
        decays = [rest_decay(r, n) for r in REST_GRID]
        cutoff = s.velocity_cutoff or s.position_cutoff or data.rate / 4
        vmin = min_speeds(s, n)
        segments = list(_segments(data.t.shape[0], self.n_folds))
        total, done = sum(stop - start for start, stop, _ in segments), 0
        for start, stop, fold_of in segments:
            directions = [_directions(data, self.rest_v, d, cutoff, start, stop) for d in decays]  # from its start

            def segment_block(a: int, b: int, start: int = start, directions: list = directions):
                return self.block(start + a, start + b, directions, start)

            for idx, (y, bank, tau) in parallel_decimation(segment_block, stop - start, data.rate, s.decimation or 1,
                                                           order=s.order, chunk=s.chunk, cutoff=s.parallel_cutoff or None):
                idx = idx + start
                self._add(idx, y, bank, tau, fold_of(idx), vmin)
                if progress is not None:
                    progress(done + int(idx[-1]) + 1 - start, total)
            done += stop - start
            if progress is not None:
                progress(done, total)
        if not self.n_rows.any():
            raise IdentifiabilityError(f"{data.name}: no samples left for the friction models' cross-validation")
        self.total = self.fit.sum(axis=0)
        self.fit_smooth = self.fit[None] - np.cumsum(self.slow, axis=0)  # each smooth term's rows fast enough for it
        self.sets = np.concatenate([self.total[None], self.total[None] - self.fit])  # every block, and every block but one
        self.rows = max(self.n_rows.sum(axis=0).max(), 1)
        self.judged = self.resting / self.rows >= REST_SHARE
        self.loaded = self.load_ok & (np.sqrt(self.load_sq) >= LOAD_SHARE * np.sqrt(self.tau_sq))
        dq_all = np.asarray(data.dq)
        moving = np.abs(dq_all) >= vmin
        moving[:, list(data.dead) + list(data.still)] = False
        if data.clipped is not None:
            moving &= ~data.clipped
        forwards = np.array([np.mean(dq_all[moving[:, j], j] > 0) if moving[:, j].any() else 0.0 for j in range(n)])
        self.reverses = np.minimum(forwards, 1 - forwards) >= REVERSAL_SHARE

    def columns(self, model: JointFriction, j: int) -> list[int]:
        """Joint ``j``'s bank columns under ``model``."""
        index = self.index
        own = [index[t] for t in self.others if self.has[t][j]]
        r = model.rest
        if model.kind == "smooth":
            return own + [index[f"tanh|{model.velocity}"]]
        cols = own + [index[f"fc|{r}"]]
        if model.kind == "asymmetric":
            cols.append(index[f"fca|{r}"])
        elif model.kind == "stribeck":
            cols.append(index[f"fst|{r}|{model.velocity}"])
        elif model.kind == "load":
            cols.append(index[f"fcl|{r}"])
        return cols

    def out_of_fold(self, assignment, signs=False):
        """Out-of-fold errors per joint; with ``signs`` also whether a load-dependent coefficient (the last column
        of that model) comes out >= 0, as friction that grows with the load must."""
        cols = [self.columns(m, j) for j, m in enumerate(assignment)]
        fit, sets = self.fit, self.sets
        smooth = [(j, SMOOTH_GRID.index(m.velocity)) for j, m in enumerate(assignment) if m.kind == "smooth"]
        if smooth:  # a smooth Coulomb joint is fitted on its rows fast enough for its term
            fit = fit.copy()
            for j, i in smooth:
                fit[:, j] = self.fit_smooth[i, :, j]
            total = fit.sum(axis=0)
            sets = np.concatenate([total[None], total[None] - fit])
        err, coef = _out_of_fold(fit, self.score, self.n_rows, self.p, cols, sets)
        if not signs:
            return err
        ok = np.array([m.kind != "load" or coef[j][-1] >= 0 for j, m in enumerate(assignment)])
        return err, ok

    def excited(self, j: int, m: JointFriction) -> bool:
        """Whether the model's own column carries enough of the rows to be determined (:data:`EXCITED_SHARE`)."""
        if m.kind not in ("stribeck", "load"):
            return True
        own, coulomb = self.columns(m, j)[-1], self.index[f"fc|{m.rest}"]
        energy = self.total[j, self.p + own, self.p + own]
        return bool(energy >= EXCITED_SHARE**2 * self.total[j, self.p + coulomb, self.p + coulomb])

    def allowed(self, j: int, m: JointFriction) -> bool:
        """Whether joint ``j`` may have model ``m``: load-dependent friction needs a loaded transmission; smooth
        Coulomb has no state at rest (tanh(q̇/v_s) is 0 there) and asymmetric Coulomb differs from the offset only
        where the friction is not held at rest, so they are candidates only where the log shows how the joint rests;
        the shapes near a reversal need reversals."""
        judged = bool(self.judged[j])
        return ((m.kind != "load" or bool(self.loaded[j])) and (m.kind not in ("smooth", "asymmetric") or judged)
                and (m.rest == "held" or judged) and not (m.kind == "asymmetric" and m.rest == "held")
                and (m.kind not in ("asymmetric", "stribeck", "smooth") or bool(self.reverses[j])) and self.excited(j, m))

    def descend(self, options: list[JointFriction]) -> list[JointFriction]:
        """Each joint's model by coordinate descent (up to three sweeps) over ``options``, from the plain model."""
        n = self.robot.n_dof
        assignment = [JointFriction()] * n
        for _ in range(3):
            changed = False
            for j in range(n):
                trial = []
                for m in options:
                    if not self.allowed(j, m):
                        trial.append(np.inf)
                        continue
                    err, ok = self.out_of_fold(assignment[:j] + [m] + assignment[j + 1:], signs=True)
                    trial.append(err[j] if ok[j] else np.inf)
                best = options[_pick(trial)]
                if best != assignment[j]:
                    assignment[j], changed = best, True
            if not changed:
                break
        return assignment


def _segments(n_s: int, folds: int):
    """(start, stop, fold of each index) of the segments the cross-validation reads: the whole log in one (its blocks the
    folds), or for a log longer than :data:`MAX_SAMPLES` one segment in the middle of each block (its fold)."""
    if n_s <= MAX_SAMPLES:
        return [(0, n_s, lambda idx: idx * folds // n_s)]
    length = MAX_SAMPLES // folds
    out = []
    for f in range(folds):
        mid = (2 * f + 1) * n_s // (2 * folds)
        out.append((mid - length // 2, mid - length // 2 + length, lambda idx, f=f: np.full(idx.shape, f)))
    return out


def _directions(data: PreparedData, rest_v, decay, cutoff: float, start: int, stop: int):
    """The direction of motion of every joint for one state at rest, on samples ``start:stop`` (column by column)."""
    travel = rest_v / cutoff
    guide = data.motion if data.motion is not None else data.dq
    dq, guide = np.asarray(data.dq[start:stop]), np.asarray(guide[start:stop])  # stored columns: these rows read here
    return held_direction(dq, rest_v, decay, presliding=0.0, rate=data.rate, guide=guide, min_travel=travel)


def _pick(errors) -> int:
    """Index of the smallest error; the first (plainest) unless another is at least :data:`MARGIN` better."""
    errors = np.asarray(errors, dtype=float)
    best = int(np.argmin(errors))
    return best if errors[best] < (1.0 - MARGIN) * errors[0] else 0


def _out_of_fold(fit, score, n_rows, p: int, cols, sets=None) -> tuple[np.ndarray, list]:
    """Out-of-fold RMS error per joint when each joint ``j`` has the bank columns ``cols[j]`` (plus the shared
    rigid-body columns), fitted on the other blocks' moving rows and scored on all rows of the block left out;
    and each joint's own coefficients fitted on every block.

    The normal equations of all blocks are assembled and solved together (column scaling, a ridge of 1e-10 on the
    scaled diagonal for the rank-deficient directions, which change no prediction). ``sets`` (folds + 1, n, size,
    size): the Gram matrices of every block and of every block but one, when the caller has them.
    """
    folds, n, size, _ = fit.shape
    t = size - 1
    if sets is None:
        total = fit.sum(axis=0)
        sets = np.concatenate([total[None], total[None] - fit])
    offsets = np.cumsum([p] + [len(c) for c in cols])
    m = offsets[-1]
    a = np.zeros((folds + 1, m, m))
    b = np.zeros((folds + 1, m))
    a[:, :p, :p] = sets[:, :, :p, :p].sum(axis=1)
    b[:, :p] = sets[:, :, :p, t].sum(axis=1)
    owns = [p + np.asarray(c, dtype=int) for c in cols]
    for j, own in enumerate(owns):
        sl = slice(offsets[j], offsets[j + 1])
        gj = sets[:, j]
        a[:, :p, sl] = gj[:, :p][:, :, own]
        a[:, sl, :p] = gj[:, own][:, :, :p]
        a[:, sl, sl] = gj[:, own][:, :, own]
        b[:, sl] = gj[:, own, t]
    scale = np.sqrt(np.maximum(np.diagonal(a, axis1=1, axis2=2), 1e-300))
    scaled = a / scale[:, :, None] / scale[:, None, :] + 1e-10 * np.eye(m)
    theta = np.linalg.solve(scaled, (b / scale)[:, :, None])[:, :, 0] / scale
    own_coef = [theta[0, offsets[j]:offsets[j + 1]] for j in range(n)]
    sse = np.zeros(n)
    for j, own in enumerate(owns):
        idx = np.concatenate([np.arange(p), own, [t]])
        sub = score[:, j][:, idx][:, :, idx]
        e = np.concatenate([theta[1:, :p], theta[1:, offsets[j]:offsets[j + 1]], -np.ones((folds, 1))], axis=1)
        sse[j] = np.maximum(np.einsum("kl,klm,km->k", e, sub, e), 0.0).sum()
    return np.sqrt(sse / np.maximum(n_rows.sum(axis=0), 1)), own_coef
