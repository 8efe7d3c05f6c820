"""The run ``dynid excite`` describes: design the trajectory of a parsed config
(:mod:`dynid.io.config.excitation_config`) and sample it at the controller's rate."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._util.reprs import short_repr
from ..excitation.cell_replay import CellContacts, cell_contacts
from ..excitation.collision import SelfClearance, self_clearance, shape_clearance
from ..excitation.constraints import ConstraintMargin, LowestPoint, floor_margins, lowest_point, obstacle_margins
from ..excitation.design import ExcitationDesign, InfeasibleDesignError, design_excitation
from ..io.config.excitation_config import ExcitationConfig


@short_repr
@dataclass(frozen=True)
class ExcitationRun:
    """What ``dynid excite`` produced: the design and the sampled trajectory.

    Attributes
    ----------
    config : ExcitationConfig
    design : ExcitationDesign
    t : (N,) array [s]
        Set-point times at the config's rate.
    q, dq, ddq : (N, n_dof) arrays
        [rad], [rad/s], [rad/s²].
    self_clearance : SelfClearance or None
        The smallest distance between links that can touch, over the set-points
        (:func:`dynid.excitation.collision.self_clearance`; None for a chain too short to fold onto itself).
    cell_clearance : list of ConstraintMargin
        The links' shapes' smallest distance to the floor and to each of the cell's bodies over the set-points
        (:func:`dynid.excitation.constraints.floor_margins`, :func:`~dynid.excitation.constraints.obstacle_margins`;
        empty without a floor and ``[[workspace.obstacles]]``).
    mujoco_contacts : CellContacts or None
        The set-points checked a second time by MuJoCo (:func:`dynid.excitation.cell_replay.cell_contacts`; None without a
        floor or bodies, or without MuJoCo).
    lowest : LowestPoint or None
        Without a floor (``[workspace] floor``): where the set-points take the arm lowest, which nothing in the design
        kept off the surface the robot stands on (:func:`dynid.excitation.constraints.lowest_point`).
    """

    config: ExcitationConfig
    design: ExcitationDesign
    t: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    self_clearance: SelfClearance | None = None
    cell_clearance: tuple[ConstraintMargin, ...] = ()
    mujoco_contacts: CellContacts | None = None
    lowest: LowestPoint | None = None

    def to_dict(self) -> dict:
        """The run as ``excitation.json``.

        Returns
        -------
        dict
            Robot, settings, limits, the trajectory's coefficients and the design's figures.
        """
        c, p = self.config, self.config.problem
        lim = p.limits
        return {
            "robot": c.full_robot.name, "joints": p.robot.n_dof, "config": str(c.path),
            "harmonics": p.n_harmonics, "omega_f": p.omega_f, "period": p.period, "rest": p.rest,
            "base_parameters": list(p.base.names),
            "limits": {f: getattr(lim, f).tolist() for f in ("q_min", "q_max", "dq_max", "ddq_max", "tau_max")},
            "workspace": p.workspace.to_dict(),
            "settings": {"starts": c.starts, "seed": c.seed, "maxiter": c.maxiter, "grid_points": p.grid_points,
                         "safety": p.safety, "initial": c.initial_label, "csv_rate": c.rate, "csv_periods": c.periods},
            "trajectory": self.design.trajectory.to_dict(form=c.form),
            "design": {k: v for k, v in self.design.to_dict(form=c.form).items() if k != "trajectory"},
            **({} if self.self_clearance is None else {"self_clearance": self.self_clearance.to_dict()}),
            **({"cell_clearance": [m.to_dict() for m in self.cell_clearance]} if self.cell_clearance else {}),
            **({} if self.mujoco_contacts is None else {"mujoco_contacts": self.mujoco_contacts.to_dict()}),
            **({} if self.lowest is None else {"lowest": self.lowest.to_dict()}),
            "set_points": self.set_points(),
        }

    def set_points(self) -> dict:
        """What excitation.csv holds beside the design: the description's position offsets taken off its angles (the
        joints' encoders', which the controller plays), its first row's angles and velocities.

        Returns
        -------
        dict
            ``position_offset`` (n_dof,) [rad], ``first`` (n_dof,) [rad] and ``first_velocity`` (n_dof,) [rad/s]
            ([m], [m/s] for a prismatic joint), and ``prismatic`` (n_dof,) bool where a joint slides.
        """
        robot = self.config.problem.robot
        transmission = robot.transmission
        return {"position_offset": transmission.position_offset.tolist(),
                "first": transmission.logged_positions(self.q[:1])[0].tolist(), "first_velocity": self.dq[0].tolist(),
                **({"prismatic": robot.prismatic.tolist()} if robot.prismatic.any() else {})}


def run_excitation(config: ExcitationConfig, callback: Callable[[int, int, float], None] | None = None,
                   iteration: Callable[[int, int], None] | None = None) -> ExcitationRun:
    """Design the trajectory of a config and sample it at the controller's rate.

    Parameters
    ----------
    config : ExcitationConfig
    callback : callable, optional
        ``callback(done_starts, n_starts, best_cond)`` after every start of the design.
    iteration : callable, optional
        ``iteration(k, maxiter)`` after every SLSQP iteration of a start
        (:func:`dynid.excitation.design.design_excitation`).

    Returns
    -------
    ExcitationRun
    """
    design = design_excitation(config.problem, n_starts=config.starts, rng=config.seed, initial=config.initial,
                               maxiter=config.maxiter, callback=callback, iteration=iteration)
    n = int(round(config.periods * config.problem.period * config.rate))
    t = np.arange(n + 1) / config.rate  # both ends: the controller's last set-point is the start again
    q, dq, ddq = design.trajectory.evaluate(t)
    every = max(1, int(np.ceil(t.size / CLEARANCE_SAMPLES)))  # the set-points, at most this many of them
    p = config.problem
    ws, start = p.workspace, p.start_pose()
    clearance = (self_clearance(p.robot, t[::every], q[::every], ws.capsule_radius(p.robot)) if ws.geometry is None
                 else shape_clearance(p.robot, t[::every], q[::every], ws.geometry))
    # every set-point: a few µs per shape and body
    cell = tuple(floor_margins(p.robot, t, q, ws, start) + obstacle_margins(p.robot, t, q, ws))
    lowest = None if np.isfinite(ws.floor) else lowest_point(p.robot, t, q, ws)
    run = ExcitationRun(config, design, t, q, dq, ddq, clearance, cell, cell_contacts(p.robot, t, q, ws, start), lowest)
    _refuse_unsafe(run)
    return run


def _refuse_unsafe(run: ExcitationRun) -> None:
    """A trajectory whose set-points bring a link into the cell, or two of the links' own shapes together, is not
    written as if it were safe (the design's verification grid is coarser than the set-points)."""
    bad = [m for m in run.cell_clearance if m.margin < 0]
    if bad:
        m = min(bad, key=lambda m: m.margin)
        body = "the floor's" if m.constraint.startswith("floor") else "the cell's"
        raise InfeasibleDesignError(f"the designed trajectory brings a link's shape {-m.margin:.3g} m inside {body} "
                                    f"clearance at a set-point ({m.where}) between the verification grid's samples: "
                                    "nothing written; raise design.grid_points")
    found = run.mujoco_contacts
    if found is not None and found.touching:
        f = found.first or {}
        raise InfeasibleDesignError(f"MuJoCo finds link {f.get('link')} touching {f.get('body')} at t = "
                                    f"{f.get('time', float('nan')):.3g} s on {found.touching} set-points: nothing "
                                    "written; raise design.grid_points or workspace.clearance")
    c = run.self_clearance
    if c is not None and c.shapes and c.distance < 0:
        raise InfeasibleDesignError(f"the designed trajectory brings {c.shapes[0]} and {c.shapes[1]} together at t = "
                                    f"{c.time:.3g} s, between the verification grid's samples: nothing written; raise "
                                    "design.grid_points")


CLEARANCE_SAMPLES = 2000
"""Set-points the links' distances are checked on, evenly spaced (every one of a shorter trajectory): 5-10 ms apart
on a trajectory of 10-20 s, where a link moves a few millimetres at most."""
