"""Optimal excitation trajectories (paper §3.2, eq. 15): Fourier coefficients minimising cond(W_base).

The design variables are the coefficients of eq. 14 (and the offsets q_o when they are free). Positions,
velocities and accelerations are linear in them, so their limits are linear constraints with exact
Jacobians. The criterion (:mod:`dynid.excitation.criteria`), the torques and the tool point are not; their
gradients follow by the chain rule from the per-sample derivatives of the regressor and of the tool point
with respect to the joint state (:mod:`dynid.dynamics.sensitivity`): one batched regressor call of
``5·n_dof + 1`` blocks per iterate, instead of one finite difference of the whole problem per coefficient.

SciPy's SLSQP solves the constrained problem from several starts drawn with a seeded ``rng``. The
constraints are imposed on a grid of ``grid_points`` samples per period with limits tightened by
``safety``; each start's design is checked on a grid ten times finer with the true limits; one that fails
is solved again (at most :data:`RETRIES` times, see there), and only designs that pass are kept.

References: Swevers, Ganseman, Tükel, de Schutter, Van Brussel, "Optimal robot excitation and
identification", IEEE TRA 13(5), 1997; Gautier & Khalil, "Exciting trajectories for the identification of
base inertial parameters of robots", IJRR 11(4), 1992.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from .._util.keywords import keyword_only_after_data
from .._util.reprs import short_repr
from ..dynamics.base_parameters import BaseParameters, base_parameters
from ..dynamics.kinematics import tip_positions
from ..dynamics.regressor import regressor
from ..dynamics.sensitivity import regressor_state_derivatives, tips_jacobian
from ..exceptions import ConfigError, DynIdError
from ..model.loading import as_robot
from ..model.robot import Limits, Robot
from ..runtime.processes import Claims, ForkedCall, can_fork
from ..runtime.threads import with_single_blas_thread
from .constraints import ConstraintMargin, Workspace, check_limits, constraint_margins
from .criteria import CRITERIA, criterion_function
from .floor import FloorDistances
from .fourier import FourierTrajectory
from .link_geometry import self_distances

VERIFY_REFINEMENT = 10
"""The verification grid is this many times finer than the design grid."""

RETRIES = 2
"""How often a start whose design fails the verification grid is solved again: from its result with the
safety doubled when SLSQP converged, else from the start with half its amplitudes."""


class InfeasibleDesignError(DynIdError, ValueError):
    """No trajectory satisfying every constraint was found (the message says which constraint).

    Parameters
    ----------
    message : str
        One line: what was expected, what was found, how to fix it.
    field : str, optional
        The setting at fault when the message starts with it (the CLI names its option instead).
    """


@short_repr
@dataclass(frozen=True)
class ExcitationProblem:
    """What to design: robot, Fourier series, criterion and the constraints of eq. 15.

    Attributes
    ----------
    robot : Robot
        The identified model (e.g. ``er16.submodel(3)``); given as a built-in robot's name or a description's path, it
        is loaded (:func:`dynid.model.loading.as_robot`).
    omega_f : float
        Fundamental pulsation [rad/s]; the trajectory is periodic with period ``2π/omega_f``.
    n_harmonics : int
        Harmonics per joint (N of eq. 14).
    limits : Limits, optional
        Joint limits of eq. 15 (default: the robot's). Infinite entries are not constrained.
    workspace : Workspace
        ``W_o``: box and floor for the tool point.
    offsets : (n_dof,) array, optional
        Fixed offsets q_o [rad]; ``None`` optimises them (starting from the middle of the position limits).
    rest : bool
        Start and end at rest at the offset pose: ``q(0) = q_o``, ``dq(0) = ddq(0) = 0`` (linear
        equalities; the trajectory is periodic, so the end equals the start).
    criterion : {"cond", "d-optimal"}
    grid_points : int
        Samples per period of the design grid.
    safety : float
        Limits are tightened by this fraction during the optimisation (of the range for positions, of
        the robot's reach for the workspace), so that the design holds between grid points.
    phi : (n_params,) array, optional
        Standard parameters for the torque constraints (default: the robot's nominal values).
    base : BaseParameters, optional
        Base parameters of ``robot`` (computed when omitted).
    """

    robot: Robot
    omega_f: float
    n_harmonics: int
    # given or None; __post_init__ fills in the robot's limits, the nominal parameters and the base parameters
    limits: Limits = None  # type: ignore[assignment]
    workspace: Workspace = field(default_factory=Workspace)
    offsets: np.ndarray | None = None
    rest: bool = False
    criterion: str = "cond"
    grid_points: int = 100
    safety: float = 0.02
    phi: np.ndarray = None  # type: ignore[assignment]
    base: BaseParameters = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        robot = as_robot(self.robot)
        object.__setattr__(self, "robot", robot)
        if self.limits is None:
            object.__setattr__(self, "limits", robot.limits)
        if self.phi is None:
            object.__setattr__(self, "phi", robot.standard_parameters())
        if self.base is None:
            object.__setattr__(self, "base", base_parameters(robot))
        if not (np.isfinite(self.omega_f) and self.omega_f > 0):
            raise ConfigError(f"trajectory.omega_f must be a positive pulsation in rad/s, got {self.omega_f}")
        if int(self.n_harmonics) != self.n_harmonics or self.n_harmonics < 1:
            raise ConfigError(f"trajectory.harmonics must be a positive integer, got {self.n_harmonics}")
        if self.criterion not in CRITERIA:
            raise ConfigError(f"design.criterion must be one of {', '.join(CRITERIA)}, got {self.criterion!r}")
        if self.grid_points < 4 * self.n_harmonics:
            raise ConfigError(f"design.grid_points must be at least 4 per harmonic ({4 * self.n_harmonics}), got {self.grid_points}")
        if not 0 <= self.safety < 0.5:
            raise ConfigError(f"design.safety must be in [0, 0.5), got {self.safety}")
        check_limits(self.limits, robot.n_dof)
        if self.offsets is not None:
            off = np.asarray(self.offsets, dtype=float)
            if off.shape != (robot.n_dof,) or not np.all(np.isfinite(off)):
                raise ConfigError(f"trajectory.offsets: expected {robot.n_dof} finite angles in rad, got {self.offsets!r}")
            object.__setattr__(self, "offsets", off)
        self._check_start_pose()

    @property
    def period(self) -> float:
        """The period ``2π / ω_f`` [s]."""
        return 2.0 * np.pi / self.omega_f

    def start_pose(self) -> np.ndarray:
        """The offsets: the fixed ones, or the middle of the position limits (0 where unlimited).

        Returns
        -------
        (n_dof,) array [rad]
        """
        if self.offsets is not None:
            return self.offsets.copy()
        lim = self.limits
        bounded = np.isfinite(lim.q_min) & np.isfinite(lim.q_max)  # a continuous joint has neither
        mid = np.zeros(bounded.shape)
        mid[bounded] = 0.5 * (lim.q_min[bounded] + lim.q_max[bounded])
        return mid

    def unlimited_joints(self) -> list[int]:
        """The joints (0-based) without position limits (continuous joints, or ``±inf`` in ``[limits]``): the
        design swings them about their offset, bounded by their velocity and acceleration limits only.

        Returns
        -------
        list of int
        """
        lim = self.limits
        return [int(j) for j in np.flatnonzero(~(np.isfinite(lim.q_min) & np.isfinite(lim.q_max)))]

    def _check_start_pose(self) -> None:
        """The offset (start) pose must satisfy every constraint at rest, or no trajectory can."""
        q0 = self.start_pose()
        lim = self.limits
        bad = np.flatnonzero((q0 <= lim.q_min) | (q0 >= lim.q_max))
        if bad.size:
            j = bad[0]
            raise ConfigError(f"trajectory.offsets: joint {j + 1} offset {q0[j]:g} rad is not inside its limits "
                              f"[{lim.q_min[j]:g}, {lim.q_max[j]:g}] rad")
        g, h, labels = self.workspace.inequalities()
        for tip, p in zip(self.robot.tips[::-1], tip_positions(self.robot, q0[None])[0][::-1]):  # the tool's first
            out = [lbl for gi, hi, lbl in zip(g, h, labels) if gi @ p > hi]
            if out:
                what = "the tool point" if tip == self.robot.n_dof - 1 else f"the tip of {self.robot.joints[tip].name}"
                raise ConfigError(f"workspace excludes the start pose: at the offsets q_o = {np.round(q0, 4).tolist()} rad "
                                  f"{what} is at {np.round(p, 3).tolist()} m, which violates {', '.join(out)}")
        needs = self.workspace.floor_needs(self.robot, q0)
        if needs is not None and needs.shapes.size and needs.start.min() < 0 and self.workspace.geometry is not None:
            c = int(np.argmin(needs.start))
            raise ConfigError(f"workspace: at the start pose (offsets q_o = {np.round(q0, 4).tolist()} rad) "
                              f"{self.workspace.shapes(self.robot).names[int(needs.shapes[c])]} is {-needs.start[c]:.3g} m "
                              f"under the floor ({self.workspace.floor:g} m): start higher, or give the floor's height "
                              "in the base frame")
        self._check_start_clear(q0)
        zero = np.zeros((1, self.robot.n_dof))
        tau = (regressor(self.robot, q0[None], zero, zero) @ self.phi)[0]
        bad = np.flatnonzero(np.abs(tau) > lim.tau_max)
        if bad.size:
            j = bad[0]
            raise ConfigError(f"limits.tau_max: holding the start pose needs {abs(tau[j]):.1f} N·m on joint {j + 1}, "
                              f"above its limit {lim.tau_max[j]:g} N·m")

    def _check_start_clear(self, q0: np.ndarray) -> None:
        """Every link off the cell's bodies, and the links' shapes off each other, at the start pose: the optimiser
        cannot pull a link out of a body."""
        ws = self.workspace
        pairs = ws.self_pairs(self.robot)
        if pairs and ws.geometry is not None:
            apart = self_distances(self.robot, q0[None], ws.geometry, pairs).distance[0]
            if apart.min() < 0:
                g, h = pairs[int(np.argmin(apart))]
                raise ConfigError(f"trajectory.offsets: at the start pose (q_o = {np.round(q0, 4).tolist()} rad) the "
                                  f"collision shapes {ws.geometry.names[g]!r} and {ws.geometry.names[h]!r} touch: start "
                                  "elsewhere; where they touch by construction (a convex hull over a housing), give the "
                                  "robot's SRDF as workspace.srdf (its <disable_collisions> leave such pairs out); or set "
                                  'workspace.geometry = "capsules"')
        if not ws.obstacles:
            return
        found = ws.cell_distances(self.robot, q0[None])
        if found.pairs and found.distance.min() < 0:
            c = int(np.argmin(found.distance[0]))
            k, i = found.links[c], found.pairs[c][1]
            raise ConfigError(f"workspace.obstacles: at the start pose (offsets q_o = {np.round(q0, 4).tolist()} rad) link "
                              f"{k + 1} comes within workspace.clearance = {ws.clearance:g} m of obstacle "
                              f"{ws.obstacles[i].name!r} (by {-found.distance.min():.3g} m): move the body, start "
                              "elsewhere, or lower the clearance")

    def design_grid(self) -> np.ndarray:
        """One period sampled with ``grid_points`` samples.

        Returns
        -------
        (grid_points,) array [s]
        """
        return np.arange(self.grid_points) * (self.period / self.grid_points)

    def verification_grid(self) -> np.ndarray:
        """The design grid refined :data:`VERIFY_REFINEMENT` times.

        Returns
        -------
        array [s]
        """
        n = self.grid_points * VERIFY_REFINEMENT
        return np.arange(n) * (self.period / n)

    def margins(self, trajectory: FourierTrajectory, t: np.ndarray | None = None) -> list[ConstraintMargin]:
        """Margins of every constraint (eq. 15) of a trajectory.

        Parameters
        ----------
        trajectory : FourierTrajectory
        t : array [s], optional
            Where to check (default: the verification grid).

        Returns
        -------
        list of ConstraintMargin
        """
        t = self.verification_grid() if t is None else t
        return constraint_margins(self.robot, trajectory, t, self.limits, self.workspace, self.phi,
                                  start_pose=self.start_pose())

    def criterion_value(self, trajectory: FourierTrajectory) -> float:
        """The design criterion of a trajectory on the design grid.

        Parameters
        ----------
        trajectory : FourierTrajectory

        Returns
        -------
        float
            cond(W_base), or −log det of the information matrix ("d-optimal").
        """
        w = _stacked_base_observation(self.robot, self.base, trajectory, self.design_grid())
        value, _ = criterion_function(self.criterion)(w)
        return float(np.exp(value)) if self.criterion == "cond" else value


def condition_number(problem: ExcitationProblem, trajectory: FourierTrajectory, t: np.ndarray | None = None) -> float:
    """cond(W_base) of a trajectory.

    Parameters
    ----------
    problem : ExcitationProblem
    trajectory : FourierTrajectory
    t : array [s], optional
        Where to sample it (default: the design grid).

    Returns
    -------
    float
    """
    t = problem.design_grid() if t is None else t
    return float(np.linalg.cond(_stacked_base_observation(problem.robot, problem.base, trajectory, t)))


def base_condition_number(robot: Robot, base: BaseParameters, trajectory: FourierTrajectory, n_samples: int = 100) -> float:
    """cond(W_base) of a trajectory sampled over one period (no limits involved).

    Parameters
    ----------
    robot : Robot
    base : BaseParameters
    trajectory : FourierTrajectory
    n_samples : int
        Samples over the period.

    Returns
    -------
    float

    Raises
    ------
    ConfigError
        If the trajectory's number of joints is not the robot's.
    """
    t = np.arange(n_samples) * (trajectory.period / n_samples)
    return float(np.linalg.cond(_stacked_base_observation(robot, base, trajectory, t)))


def _stacked_base_observation(robot: Robot, base: BaseParameters, trajectory: FourierTrajectory, t: np.ndarray) -> np.ndarray:
    if trajectory.n_dof != robot.n_dof:
        raise ConfigError(f"trajectory has {trajectory.n_dof} joints, the robot model {robot.n_dof}")
    return base.base_observation(regressor(robot, *trajectory.evaluate(t))).reshape(-1, base.n_base)


@short_repr
@dataclass(frozen=True)
class ExcitationDesign:
    """An optimised excitation trajectory and how good it is (``to_dict`` is JSON-ready).

    Attributes
    ----------
    trajectory : FourierTrajectory
    initial : FourierTrajectory
        The start the design came from (the given initial trajectory when one was given).
    criterion : str
        "cond" or "d-optimal".
    cond, initial_cond : float
        cond(W_base) on the design grid after and before the optimisation.
    cond_verification : float
        cond(W_base) on the verification grid.
    log_det, initial_log_det : float
        ``log det(W_b^T W_b / N)`` after and before.
    margins : list of ConstraintMargin
        On the verification grid, with the true limits.
    initial_violations : list of ConstraintMargin
        The constraints the initial trajectory violates on the verification grid (empty: it satisfies all).
    success : bool
        SLSQP's own flag for the kept start.
    message : str
    nit, nfev : int
        Iterations and criterion evaluations over all starts.
    start_values : list of float
        Criterion reached from every start (cond(W_base), or −log det for "d-optimal"; ``inf`` when the
        start's result failed verification even after :data:`RETRIES` more solves).
    seconds : float
    """

    trajectory: FourierTrajectory
    initial: FourierTrajectory
    criterion: str
    cond: float
    initial_cond: float
    cond_verification: float
    log_det: float
    initial_log_det: float
    margins: list
    initial_violations: list
    success: bool
    message: str
    nit: int
    nfev: int
    start_values: list
    seconds: float

    @property
    def feasible(self) -> bool:
        """Whether the trajectory satisfies every constraint on the verification grid."""
        return all(m.satisfied for m in self.margins)

    @keyword_only_after_data
    def to_dict(self, *, form: str = "paper") -> dict:
        """The design as excitation.json stores it.

        Parameters
        ----------
        form : {"paper", "swevers"}
            How the trajectory's coefficients are written (eq. 14 or the Swevers form).

        Returns
        -------
        dict
        """
        return {"criterion": self.criterion, "cond": self.cond, "initial_cond": self.initial_cond,
                "cond_verification_grid": self.cond_verification, "log_det_information": self.log_det,
                "initial_log_det_information": self.initial_log_det, "success": self.success,
                "message": self.message, "nit": self.nit, "nfev": self.nfev, "start_values": self.start_values,
                "seconds": self.seconds, "feasible": self.feasible, "margins": [m.to_dict() for m in self.margins],
                "initial_violations": [m.to_dict() for m in self.initial_violations],
                "trajectory": self.trajectory.to_dict(form=form), "initial_trajectory": self.initial.to_dict(form=form)}


class _Layout:
    """Design variables ``x = [q_o (when free), a (n·H), b (n·H)]`` and the linear maps to the joint states."""

    def __init__(self, problem: ExcitationProblem, t: np.ndarray):
        n, h = problem.robot.n_dof, problem.n_harmonics
        self.n, self.h, self.omega_f = n, h, problem.omega_f
        self.free_offsets = problem.offsets is None
        self.n_off = n if self.free_offsets else 0
        self.nx = self.n_off + 2 * n * h
        wk = problem.omega_f * np.arange(1, h + 1)
        s, c = np.sin(np.outer(t, wk)), np.cos(np.outer(t, wk))
        per_a = (s, c * wk, -s * wk**2)
        per_b = (c, -s * wk, -c * wk**2)
        lin = np.zeros((3, t.size, n, self.nx))  # state c of joint i at sample k = lin[c, k, i] @ x + const
        for i in range(n):
            ia = self.n_off + i * h + np.arange(h)
            ib = self.n_off + n * h + i * h + np.arange(h)
            for kind in range(3):
                lin[kind, :, i, ia] = per_a[kind].T
                lin[kind, :, i, ib] = per_b[kind].T
            if self.free_offsets:
                lin[0, :, i, i] = 1.0
        self.lin = lin
        self.const = np.zeros((3, t.size, n))
        if not self.free_offsets:
            self.const[0] += problem.offsets

    def states(self, x: np.ndarray) -> np.ndarray:
        """(3, N, n): q, dq, ddq on the grid."""
        return self.lin @ x + self.const

    def to_x(self, traj: FourierTrajectory) -> np.ndarray:
        parts = [traj.q0] if self.free_offsets else []
        return np.concatenate(parts + [traj.a.ravel(), traj.b.ravel()])

    def to_trajectory(self, x: np.ndarray, offsets: np.ndarray | None) -> FourierTrajectory:
        n, h = self.n, self.h
        q0 = x[:n].copy() if self.free_offsets else np.asarray(offsets, dtype=float).copy()
        a = x[self.n_off:self.n_off + n * h].reshape(n, h).copy()
        b = x[self.n_off + n * h:].reshape(n, h).copy()
        return FourierTrajectory(self.omega_f, q0, a, b)


SHARPNESS = 1000.0
"""[1/m] The sharpness ρ of the soft minimum (:func:`soft_min`) of the links' own shapes' distances that the design
keeps at or above zero, one row per design-grid sample in place of a row per pair (75 pairs on the Panda): it lies at
most ``log(pairs) / ρ`` below the smallest distance (4.3 mm for the Panda's 75 pairs, where every pair is equally near),
so the design is never less safe for it. The cell's bodies keep a row per pair: they are few, and where a body binds,
its soft minimum took the optimiser more iterations (benchmarks/NOTEBOOK.md)."""

CAPSULE_WINDOW = 10
"""Design-grid samples whose capsules' distances (``avoid_self_collision`` without collision shapes) one constraint row
holds: their soft minimum over the samples and the pairs, a lower bound of each, so every sample is held as with a
row per sample. Measured on the shipped configs (benchmarks/NOTEBOOK.md, stop 86): with a row per sample the TX40's
design ended infeasible from 3 of its 4 starts at cond(W_base) 1.14× the design without the constraint; with rows of
10 samples from 1, at 1.03×."""


def _windows(values: np.ndarray, jacobian: np.ndarray | None, window: int):
    """``values`` (N, P) and ``jacobian`` (N, P, nx) regrouped as rows of ``window`` samples (N/window rows, the last
    padded with values that weigh nothing in :func:`soft_min`)."""
    if window <= 1:
        return values, jacobian
    pad = (-values.shape[0]) % window
    v = np.concatenate([values, np.full((pad, values.shape[1]), np.inf)]).reshape(-1, window * values.shape[1])
    if jacobian is None:
        return v, None
    j = np.concatenate([jacobian, np.zeros((pad, *jacobian.shape[1:]))])
    return v, j.reshape(v.shape[0], v.shape[1], jacobian.shape[-1])


NEGLIGIBLE = 20.0
"""A pair's weight in the soft minimum below ``exp(-NEGLIGIBLE)`` (a pair at least ``NEGLIGIBLE / SHARPNESS`` = 2 cm
farther than a sample's nearest one): coal is not asked for its distance, its bounding volumes' (a lower bound) stands."""


def soft_min(values: np.ndarray, jacobian: np.ndarray | None = None, *,
             sharpness: float = SHARPNESS) -> tuple[np.ndarray, np.ndarray | None]:
    """The Kreisselmeier-Steinhauser soft minimum of each row, ``m - log(sum(exp(-ρ (v - m)))) / ρ`` with ``m`` the
    row's minimum, and its gradient, the rows' gradients weighted by ``softmax(-ρ v)``.

    It is smooth and a lower bound of the minimum, within ``log(P) / ρ`` of it: constraining it at or above zero keeps
    every value there (constraint aggregation; G. Kreisselmeier and R. Steinhauser, "Systematic control design by
    optimizing a vector performance index", IFAC 1979; J. R. R. A. Martins and N. M. K. Poon, "On structural
    optimization using constraint aggregation", WCSMO 2005).

    Parameters
    ----------
    values : (N, P) array
    jacobian : (N, P, nx) array, optional
        Each value's gradient.
    sharpness : float
        ρ, in the inverse of the values' unit.

    Returns
    -------
    soft : (N,) array
    gradient : (N, nx) array or None
        None without ``jacobian``.
    """
    low = values.min(axis=1, keepdims=True)
    weight = np.exp(-sharpness * (values - low))
    total = weight.sum(axis=1, keepdims=True)
    soft = (low - np.log(total) / sharpness)[:, 0]
    if jacobian is None:
        return soft, None
    return soft, np.einsum("np,npx->nx", weight / total, jacobian)


class _Objective:
    """Criterion and nonlinear constraints with their gradients at one iterate (cached per ``x``)."""

    def __init__(self, problem: ExcitationProblem, layout: _Layout):
        self.p, self.lay = problem, layout
        self._x: np.ndarray | None = None
        self._xg: bool | None = None
        self.nfev = 0
        lim, s = problem.limits, problem.safety
        self.tau_idx = np.flatnonzero(np.isfinite(lim.tau_max))
        self.tau_lim = lim.tau_max[self.tau_idx] * (1 - s)
        g, h, _ = problem.workspace.inequalities()
        reach = problem.robot.reach
        self.ws_g, self.ws_h = g, h - s * reach
        ws = problem.workspace  # every link's shape above the floor (Workspace.floor_needs), tightened as the cell's
        found = ws.floor_needs(problem.robot, problem.start_pose())
        self.needs = None if found is None or not found.shapes.size else replace(
            found, height=np.where(found.height < ws.clearance, found.height, found.height + s * reach))
        self.pairs = ws.cell_pairs(problem.robot) if ws.obstacles else []  # every link off the cell's bodies
        self.gap = s * reach
        self.self_pairs = ws.self_pairs(problem.robot)  # and off each other (shapes or capsules): tightened as the
        if self.self_pairs:  # cell's, but never past half a pair's distance at the start
            start = ws.self_measure(problem.robot, problem.start_pose()[None], self.self_pairs).dist[0]
            if ws.geometry is None:  # capsules that overlap at the start are the skeleton's, not the motion's
                self.self_pairs = [pair for pair, d in zip(self.self_pairs, start) if d >= 0]
                start = start[start >= 0]
            self.self_gap = np.minimum(self.gap, 0.5 * start)
        self.window = CAPSULE_WINDOW if ws.geometry is None else 1  # a row per sample for the shapes' many pairs
        self.crit = criterion_function(problem.criterion)

    def _eval(self, x: np.ndarray) -> None:
        """Values only: one regressor call (SLSQP's line search needs no more)."""
        if self._x is not None and np.array_equal(x, self._x):
            return
        p, lay = self.p, self.lay
        self.q, self.dq, self.ddq = lay.states(x)
        y = regressor(p.robot, self.q, self.dq, self.ddq)
        idx = p.base.independent
        self.value, self.m = self.crit(y[..., idx].reshape(-1, idx.size))
        self.tau = y[:, self.tau_idx, :] @ p.phi
        if self.ws_h.size:  # every branch's tip (the tool alone on a chain): (N, tips · m)
            self.ws = (self.ws_h - tip_positions(p.robot, self.q) @ self.ws_g.T).reshape(self.q.shape[0], -1)
        if self.needs is not None:
            self.lifted = FloorDistances(p.robot, self.q, p.workspace.shapes(p.robot), p.workspace.floor, self.needs)
        if self.pairs:  # measured once here, as the self distances below
            self.cell = p.workspace.cell_measure(p.robot, self.q, pairs=self.pairs)
            self.clear = self.cell.dist - self.gap  # (N, pairs)
        if self.self_pairs:  # measured once here; their gradient at the same iterate from the same measurement
            self.measured = p.workspace.self_measure(p.robot, self.q, self.self_pairs, within=NEGLIGIBLE / SHARPNESS)
            self.apart = self.measured.dist - self.self_gap
        self.nfev += 1
        self._x, self._xg = x.copy(), None

    def _eval_gradients(self, x: np.ndarray) -> None:
        """Gradients by the chain rule through the regressor's state derivatives."""
        self._eval(x)
        if self._xg is not None:
            return
        p, lay = self.p, self.lay
        _, dy = regressor_state_derivatives(p.robot, self.q, self.dq, self.ddq)
        idx = p.base.independent
        m = self.m.reshape(self.q.shape[0], lay.n, idx.size)
        g = np.einsum("cikjp,kjp->cik", dy[..., idx], m)
        self.grad = np.einsum("cik,ckix->x", g, lay.lin)
        tau_sens = dy[..., self.tau_idx, :] @ p.phi  # (3, n, N, n_tau)
        self.tau_jac = np.einsum("cikj,ckix->kjx", tau_sens, lay.lin)
        if self.ws_h.size:
            _, jac = tips_jacobian(p.robot, self.q)
            self.ws_jac = -np.einsum("md,ktdi,kix->ktmx", self.ws_g, jac, lay.lin[0]).reshape(self.q.shape[0], -1, x.size)
        if self.needs is not None:
            lift = self.lifted.distances(gradient=True).gradient
            assert lift is not None  # asked, with shapes
            self.lift_jac = np.einsum("kmi,kix->kmx", lift, lay.lin[0])
        if self.pairs:
            self.clear_jac = np.einsum("kmi,kix->kmx", self.cell.distances(gradient=True).gradient, lay.lin[0])
        if self.self_pairs:
            apart = self.measured.distances(gradient=True).gradient
            assert apart is not None  # asked, with pairs
            self.apart_jac = np.einsum("kmi,kix->kmx", apart, lay.lin[0])
        self._xg = True

    def fun(self, x):
        self._eval(x)
        return self.value

    def jac(self, x):
        self._eval_gradients(x)
        return self.grad

    def cons(self, x):
        self._eval(x)
        lim = self.tau_lim
        parts = [((lim - self.tau) / lim).ravel(), ((lim + self.tau) / lim).ravel()]
        if self.ws_h.size:
            parts.append(self.ws.ravel())
        if self.needs is not None:
            parts.append(self.lifted.dist.ravel())
        if self.pairs:
            parts.append(self.clear.ravel())
        if self.self_pairs:  # one row per sample: the soft minimum over the pairs
            parts.append(soft_min(*_windows(self.apart, None, self.window))[0])
        return np.concatenate(parts)

    def cons_jac(self, x):
        self._eval_gradients(x)
        lim = self.tau_lim[None, :, None]
        parts = [(-self.tau_jac / lim).reshape(-1, x.size), (self.tau_jac / lim).reshape(-1, x.size)]
        if self.ws_h.size:
            parts.append(self.ws_jac.reshape(-1, x.size))
        if self.needs is not None:
            parts.append(self.lift_jac.reshape(-1, x.size))
        if self.pairs:
            parts.append(self.clear_jac.reshape(-1, x.size))
        if self.self_pairs:
            parts.append(soft_min(*_windows(self.apart, self.apart_jac, self.window))[1])
        return np.concatenate(parts)


def _linear_constraints(problem: ExcitationProblem, lay: _Layout) -> tuple[np.ndarray, np.ndarray]:
    """``A x + c >= 0`` for positions, velocities and accelerations (tightened, scaled by their limit)."""
    lim, s = problem.limits, problem.safety
    rows, consts = [], []
    span = lim.q_max - lim.q_min
    for j in range(lay.n):
        lq, cq = lay.lin[0][:, j], lay.const[0][:, j]
        if np.isfinite(lim.q_max[j]):
            hi = lim.q_max[j] - s * span[j] if np.isfinite(span[j]) else lim.q_max[j]
            scale = span[j] if np.isfinite(span[j]) else 1.0
            rows.append(-lq / scale)
            consts.append((hi - cq) / scale)
        if np.isfinite(lim.q_min[j]):
            lo = lim.q_min[j] + s * span[j] if np.isfinite(span[j]) else lim.q_min[j]
            scale = span[j] if np.isfinite(span[j]) else 1.0
            rows.append(lq / scale)
            consts.append((cq - lo) / scale)
        for kind, vmax in ((1, lim.dq_max[j]), (2, lim.ddq_max[j])):
            if np.isfinite(vmax):
                l_ = lay.lin[kind][:, j] / vmax
                rows += [-l_, l_]
                consts += [np.full(l_.shape[0], 1 - s)] * 2
    if not rows:
        return np.zeros((0, lay.nx)), np.zeros(0)
    return np.concatenate(rows), np.concatenate(consts)


def _rest_equalities(lay: _Layout) -> np.ndarray:
    """Rows ``E`` with ``E x = 0``: ``q(0) - q_o``, ``dq(0)`` and ``ddq(0)`` of every joint (t = 0 is grid sample 0)."""
    e = lay.lin[:, 0].reshape(3 * lay.n, lay.nx).copy()
    if lay.free_offsets:
        e[:lay.n, :lay.n] = 0.0
    return e


def _coupling_equalities(problem, lay: _Layout) -> tuple[np.ndarray, np.ndarray] | None:
    """Rows ``E`` and values ``e`` with ``E x = e`` for each joint that follows another (``<mimic>``,
    :attr:`dynid.model.robot.Joint.mimic`): its harmonics ``multiplier`` times that joint's, and its offset (where the
    design chooses the offsets) ``multiplier · q_o,k + offset``, so that the trajectory keeps the coupling at every
    instant and every limit and shape is checked on the motion the joint makes. None without such joints."""
    robot, n, h = problem.robot, lay.n, lay.h
    rows, values = [], []
    for j in robot.followers:
        k, multiplier, offset = robot.joints[j].mimic
        blocks = [(lay.n_off + part * n * h + j * h, lay.n_off + part * n * h + k * h) for part in (0, 1)]
        for mine, theirs in blocks:
            for m in range(h):
                row = np.zeros(lay.nx)
                row[mine + m], row[theirs + m] = 1.0, -multiplier
                rows.append(row)
                values.append(0.0)
        if lay.free_offsets:
            row = np.zeros(lay.nx)
            row[j], row[k] = 1.0, -multiplier
            rows.append(row)
            values.append(offset)
    return (np.array(rows), np.array(values)) if rows else None


def _start_direction(lay, rng) -> np.ndarray:
    """A random start's amplitudes (:func:`_random_start`), decaying as 1/k: drawn for every start before any is
    solved, in their order, so that a start's draw does not hang on which core solves the starts before it."""
    n, h = lay.n, lay.h
    k = np.arange(1, h + 1)
    return np.concatenate([(rng.standard_normal((n, h)) / k).ravel(), (rng.standard_normal((n, h)) / k).ravel()])


def _random_start(problem, lay, a_lin, c_lin, eq, objective, amp, coupling) -> np.ndarray:
    """The amplitudes ``amp`` (:func:`_start_direction`) projected on the rest and coupling equalities
    (:func:`_coupling_equalities`), scaled into the limits."""
    n = lay.n
    x0 = np.zeros(lay.nx)
    if lay.free_offsets:
        x0[:n] = problem.start_pose()
    if coupling is not None:  # the start pose and the amplitudes on the coupling (E x0 = e, E d = 0)
        e_rows, e_values = coupling
        x0 -= np.linalg.pinv(e_rows) @ (e_rows @ x0 - e_values)
        eq = e_rows if eq is None else np.vstack([eq, e_rows])
    d = np.concatenate([np.zeros(lay.n_off), amp])
    if eq is not None:
        d -= np.linalg.pinv(eq) @ (eq @ d)
    slope = a_lin @ d
    room = a_lin @ x0 + c_lin
    neg = slope < -1e-15
    scale = 0.8 * float(np.min(room[neg] / -slope[neg])) if np.any(neg) else 1.0
    for _ in range(12):  # shrink until torques and workspace hold too
        x = x0 + scale * d
        if np.all(objective.cons(x) >= 0):
            return x
        scale *= 0.6
    return x


def _slsqp(objective, x0: np.ndarray, cons: list, maxiter: int, iteration: Callable[[int, int], None] | None):
    """One SLSQP run of :func:`design_excitation`, ``iteration(k, maxiter)`` said after its ``k``-th iteration."""
    from scipy.optimize import minimize  # here: checking a config or computing cond(W_base) needs no optimiser

    done = [0]

    def iterated(_x) -> None:
        done[0] += 1
        if iteration is not None:
            iteration(done[0], maxiter)

    return minimize(objective.fun, x0, jac=objective.jac, method="SLSQP", constraints=cons,
                    options={"maxiter": maxiter, "ftol": 1e-7}, callback=iterated)


def _check_budget(n_starts: int, maxiter: int) -> None:
    """:func:`design_excitation`'s starts and SLSQP iterations, each at least 1 (a ``ConfigError`` naming it)."""
    if n_starts < 1:
        raise ConfigError(f"design.starts must be at least 1, got {n_starts}")
    if isinstance(maxiter, bool) or not isinstance(maxiter, (int, np.integer)) or maxiter < 1:
        raise ConfigError(f"design.maxiter must be a positive integer, got {maxiter!r}")


@dataclass
class _Start:
    """One start of :func:`design_excitation`: its first point, its design and margins, SLSQP's last answer, and
    its iterations and criterion evaluations."""

    x0: np.ndarray
    trajectory: FourierTrajectory
    margins: list
    res: Any
    nit: int
    nfev: int


class _StartSolver:
    """One start of :func:`design_excitation` at a time: its first point (``given`` for a start whose direction is
    None, else :func:`_random_start` along it), SLSQP from there, and again where the finer grid finds a limit crossed
    (at most :data:`RETRIES` times). The objective and constraints of each ``safety`` are built once."""

    def __init__(self, problem: ExcitationProblem, lay: _Layout, maxiter: int, given: np.ndarray | None,
                 directions: list):
        self.problem, self.lay, self.maxiter, self.given, self.directions = problem, lay, maxiter, given, directions
        self.eq = _rest_equalities(lay) if problem.rest else None
        self.coupling = _coupling_equalities(problem, lay)
        self.solvers: dict[float, tuple] = {}

    def solver(self, safety: float) -> tuple:
        """Objective, linear constraints ``(a_lin, c_lin)`` and SLSQP's constraints with the limits tightened by
        ``safety``."""
        if safety not in self.solvers:
            tightened, eq, coupling = replace(self.problem, safety=safety), self.eq, self.coupling
            objective = _Objective(tightened, self.lay)
            a_lin, c_lin = _linear_constraints(tightened, self.lay)
            cons = [{"type": "ineq", "fun": lambda x: a_lin @ x + c_lin, "jac": lambda x: a_lin},
                    {"type": "ineq", "fun": objective.cons, "jac": objective.cons_jac}]
            if eq is not None:
                cons.append({"type": "eq", "fun": lambda x: eq @ x, "jac": lambda x: eq})
            if coupling is not None:
                cons.append({"type": "eq", "fun": lambda x: coupling[0] @ x - coupling[1], "jac": lambda x: coupling[0]})
            self.solvers[safety] = (objective, a_lin, c_lin, cons)
        return self.solvers[safety]

    def __call__(self, i: int, progress: Callable[[int, int], None] | None) -> _Start:
        """Start ``i``, ``progress(k, maxiter)`` after each SLSQP iteration."""
        problem, lay = self.problem, self.lay
        before = sum(v[0].nfev for v in self.solvers.values())
        objective, a_lin, c_lin, _ = self.solver(problem.safety)
        direction = self.directions[i]
        x0 = self.given if direction is None else _random_start(problem, lay, a_lin, c_lin, self.eq, objective,
                                                                direction, self.coupling)
        assert x0 is not None  # a start without a direction is the given trajectory's
        x, safety, nit = x0, problem.safety, 0
        for _ in range(RETRIES + 1):
            objective, _, _, cons = self.solver(safety)
            res = _slsqp(objective, x, cons, self.maxiter, progress)
            nit += int(res.nit)
            traj = lay.to_trajectory(res.x, problem.offsets)
            margins = problem.margins(traj)
            if all(m.satisfied for m in margins):
                break
            if res.status == 0:  # converged, but violates between grid points: polish with tighter limits
                x, safety = res.x, min(0.45, 2 * max(safety, 0.01))
            else:  # SLSQP lost its way (e.g. incompatible linearised constraints): again from half the amplitudes
                x = x.copy()
                x[lay.n_off:] *= 0.5
        return _Start(x0, traj, margins, res, nit, sum(v[0].nfev for v in self.solvers.values()) - before)

    def claimed(self, claims: Claims) -> list[tuple[int, _Start]]:
        """The starts this process claims as it comes free, with their indices, saying nothing (a forked child's
        share)."""
        return [(i, self(i, None)) for i in claims]


def _solved_starts(solve: _StartSolver, n: int, callback: Callable[[int, int, float], None] | None,
                   iteration: Callable[[int, int], None] | None) -> _Starts:
    """Every start of :func:`design_excitation`, weighed in their order: inside
    :func:`~dynid.runtime.processes.allow_forks` a forked child on the second core and this process each take the next
    start as they come free (their draws were made before, so a start's answer does not depend on who solved it: the
    same design to the bit); ``iteration`` said for this process's starts. A start the child claimed and left no answer
    for is solved here."""
    starts = _Starts(solve.problem, n, callback)
    if n < 2 or not can_fork():
        for i in range(n):
            starts.take(i, solve(i, iteration))
        return starts
    claims = Claims(n)
    with ForkedCall(solve.claimed, claims) as child:
        for i in claims:
            starts.take(i, solve(i, iteration))
        for i, start in child.result():
            starts.take(i, start)
    for i in starts.missing():
        starts.take(i, solve(i, iteration))
    return starts


class _Starts:
    """:func:`design_excitation`'s starts, weighed in their order whichever core solved them: the best feasible design
    (the first of equal ones), and ``callback(done, n, best cond)`` as each start before it is known."""

    def __init__(self, problem: ExcitationProblem, n: int, callback: Callable[[int, int, float], None] | None):
        self.problem, self.n, self.callback = problem, n, callback
        self.found: dict[int, _Start] = {}
        self.done: list[_Start] = []
        self.values: list[float] = []
        self.best: _Start | None = None
        self.best_cond = np.inf

    def take(self, i: int, start: _Start) -> None:
        """Start ``i`` solved; those it completes the order of are weighed."""
        self.found[i] = start
        while len(self.done) in self.found:
            start = self.found.pop(len(self.done))
            self.done.append(start)
            feasible = all(m.satisfied for m in start.margins)
            score = float(self.problem.criterion_value(start.trajectory)) if feasible else np.inf
            if score < min(self.values, default=np.inf):
                self.best, self.best_cond = start, condition_number(self.problem, start.trajectory)
            self.values.append(score)
            if self.callback is not None:
                self.callback(len(self.done), self.n, self.best_cond)

    def missing(self) -> list[int]:
        """The starts not taken yet."""
        return [i for i in range(len(self.done), self.n) if i not in self.found]

    @property
    def nit(self) -> int:
        """SLSQP's iterations over every start."""
        return sum(s.nit for s in self.done)

    @property
    def nfev(self) -> int:
        """Criterion evaluations over every start."""
        return sum(s.nfev for s in self.done)


@with_single_blas_thread
@keyword_only_after_data
def design_excitation(problem: ExcitationProblem, *, n_starts: int = 4, rng: np.random.Generator | int | None = 0,
                      initial: FourierTrajectory | None = None, maxiter: int = 150,
                      callback: Callable[[int, int, float], None] | None = None,
                      iteration: Callable[[int, int], None] | None = None) -> ExcitationDesign:
    """Optimise an excitation trajectory for ``problem`` (paper eq. 15).

    Parameters
    ----------
    problem : ExcitationProblem
    n_starts : int
        Number of SLSQP starts (the ``initial`` trajectory, when given, is the first). Inside
        :func:`dynid.runtime.processes.allow_forks` (the CLI) a forked child on the second core and this process each
        take the next start as they come free; the design is the same to the bit either way.
    rng : Generator or int seed
        Draws the random starts (every start's draw before any is solved, in their order).
    initial : FourierTrajectory, optional
        A trajectory to start from and to compare with (e.g. the paper's β1); its harmonics must match.
    maxiter : int
        SLSQP iterations per start.
    callback : callable, optional
        ``callback(done_starts, n_starts, best_cond)`` after every start, in their order (a start the child solved is
        said once it and every start before it are known).
    iteration : callable, optional
        ``iteration(k, maxiter)`` after every SLSQP iteration of the starts this process solves (``k`` from 1 in each
        SLSQP run; a start polished again with tighter limits is a run of its own), so that a long start can say how
        far it has come.

    Returns
    -------
    ExcitationDesign

    Raises
    ------
    ConfigError
        Invalid settings, or an ``initial`` trajectory of another shape or fundamental pulsation.
    InfeasibleDesignError
        If no start ends with every constraint satisfied on the verification grid.
    """
    t0 = time.perf_counter()
    _check_budget(n_starts, maxiter)
    rng = np.random.default_rng(rng)
    if problem.robot.followers and problem.offsets is not None:  # a <mimic> joint's offset follows its joint's
        problem = replace(problem, offsets=problem.robot.coupled(np.asarray(problem.offsets, dtype=float)[None])[0][0])
    lay = _Layout(problem, problem.design_grid())
    if initial is not None:
        if (initial.n_dof, initial.n_harmonics) != (lay.n, lay.h):
            raise ConfigError(f"initial trajectory has {initial.n_dof} joints and {initial.n_harmonics} harmonics, "
                              f"the design {lay.n} and {lay.h}")
        if not np.isclose(initial.omega_f, problem.omega_f, rtol=1e-9, atol=0.0):
            raise ConfigError(f"initial trajectory has the fundamental pulsation {initial.omega_f:.6g} rad/s, the design "
                              f"{problem.omega_f:.6g} rad/s: its harmonics would be re-timed; design at its omega_f or start elsewhere")
        initial = FourierTrajectory(problem.omega_f, initial.q0 if lay.free_offsets or problem.offsets is None else problem.offsets,
                                    initial.a, initial.b)
    given = lay.to_x(initial) if initial is not None else None
    directions = [None if i == 0 and given is not None else _start_direction(lay, rng) for i in range(n_starts)]
    starts = _solved_starts(_StartSolver(problem, lay, maxiter, given, directions), n_starts, callback, iteration)
    chosen, first = starts.best, lay.to_trajectory(starts.done[0].x0, problem.offsets)
    if chosen is None:
        worst = min(starts.done[-1].margins, key=lambda m: m.relative if np.isfinite(m.relative) else m.margin)
        raise InfeasibleDesignError(
            f"no start satisfied every constraint on the verification grid (last start: {worst.constraint} on "
            f"{worst.where} reaches {worst.worst:.4g} against {worst.limit:.4g}); raise design.safety, "
            f"design.grid_points or design.starts, or relax the limits")
    ref, best = initial if initial is not None else first, chosen.trajectory
    return ExcitationDesign(
        trajectory=best, initial=ref, criterion=problem.criterion, cond=starts.best_cond,
        initial_cond=condition_number(problem, ref), cond_verification=condition_number(problem, best, problem.verification_grid()),
        log_det=_log_det(problem, best), initial_log_det=_log_det(problem, ref), margins=chosen.margins,
        initial_violations=[m for m in problem.margins(ref) if not m.satisfied], success=bool(chosen.res.success),
        message=str(chosen.res.message), nit=starts.nit, nfev=starts.nfev, start_values=starts.values,
        seconds=time.perf_counter() - t0)


def _log_det(problem: ExcitationProblem, traj: FourierTrajectory) -> float:
    """``log det(W_b^T W_b / N)`` on the design grid (``-inf`` when singular)."""
    w = _stacked_base_observation(problem.robot, problem.base, traj, problem.design_grid())
    sign, value = np.linalg.slogdet(w.T @ w / w.shape[0])
    return float(value) if sign > 0 else -np.inf
