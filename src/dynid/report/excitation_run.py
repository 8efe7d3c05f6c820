"""Write a ``dynid excite`` run to a folder: coefficients (JSON), set-points (CSV) and the figures."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..dynamics.kinematics import forward_kinematics, tool_positions
from ..dynamics.regressor import regressor
from ..excitation.floor import FloorDistances
from ..excitation.obstacles import link_segments
from ..identification.excite import ExcitationRun
from ..io.logs.trajectories import write_trajectory_csv
from ..tables import Line
from . import figures
from .excitation_summary import excitation_blocks
from .html import write_html_report
from .output import save_animation, save_figure, staged, write_results

FIGURES = {
    "excitation_joints.png": "positions, velocities, accelerations and torques against their limits (cf. paper Fig. 4)",
    "excitation_tool_path.png": "3-D tool path in the workspace and the cell's bodies (cf. paper Fig. 5)",
    "excitation_clearance.png": "the links' smallest distance to the floor and to each of the cell's bodies over time "
                                "(with a floor or [[workspace.obstacles]])",
}


ANIMATION = "excitation_animation.gif"
"""The arm moving along one period of the design among the cell's bodies (``dynid excite --animation``)."""

ANIMATION_FRAMES = 60
"""Frames over one period (shown at 10 per second)."""


@staged
def save_excitation(run: ExcitationRun, out: str | Path, *, animation: bool = False) -> list[Path]:
    """Write ``excitation.json``, ``excitation.csv``, the figures and, asked for, :data:`ANIMATION`.

    Parameters
    ----------
    run : ExcitationRun
    out : str or Path
        Output folder.
    animation : bool
        Also write :data:`ANIMATION` (a few seconds more).
    """
    out = Path(out)  # staged passes its staging folder
    problem, design = run.config.problem, run.design
    robot = problem.robot
    t = problem.verification_grid()
    states = {}
    for label, traj in (("optimised", design.trajectory), (f"initial ({run.config.initial_label})", design.initial)):
        q, dq, ddq = traj.evaluate(t)
        states[label] = (q, dq, ddq, regressor(robot, q, dq, ddq) @ problem.phi)
    ws = problem.workspace
    clearance = _clearance_series(robot, t, states["optimised"][0], ws, problem.start_pose())
    paths = [out / name for name in FIGURES if clearance or name != "excitation_clearance.png"]
    save_figure(figures.plot_excitation_states(
        t, states, problem.limits, title=f"{robot.name}: optimised excitation, cond(W_base) {design.initial_cond:.1f} → "
                                          f"{design.cond:.1f} (dotted: limits)", prismatic=robot.prismatic), paths[0])
    box = (problem.workspace.box_min, problem.workspace.box_max)
    paths_xyz = {label: tool_positions(robot, s[0]) for label, s in states.items()}
    optimised = paths_xyz.pop("optimised")
    save_figure(figures.plot_tool_path(optimised, others=paths_xyz, box=box, floor=ws.floor, obstacles=ws.obstacles,
                                       title=f"{robot.name}: tool path of the optimised excitation"), paths[1])
    if clearance:
        save_figure(figures.plot_clearance(t, clearance, title=f"{robot.name}: how close the links come to the cell "
                                                               f"(beyond their {ws.clearance:g} m capsules)"), paths[2])
    csv_path = out / "excitation.csv"
    # the controller's angles: the encoders' zeros where the description sets position offsets (excitation_summary)
    write_trajectory_csv(csv_path, run.t, robot.transmission.logged_positions(run.q), run.dq, run.ddq, robot.prismatic)
    json_path = out / "excitation.json"
    # the terminal's warnings below its verdict line (the floor, the cell, the links' shapes, the held links, the
    # start) in the file and the report too: what a user reads later says what the terminal said
    data = {**run.to_dict(), "warnings": [line.text for line in excitation_blocks(run, tables=False)[1:]
                                          if isinstance(line, Line) and line.kind == "warning"]}
    write_results(json_path, data, "excite")
    write_html_report(out / "report.html", data, "excite", paths, f"dynid excite — {robot.name}")
    moving = [_animation(run, out / ANIMATION)] if animation else []
    return [json_path, csv_path, out / "report.html"] + paths + moving


def arm_skeleton(robot, q: np.ndarray) -> np.ndarray:
    """The lines the animation draws at each of ``q``'s rows: the base, the joint origins and the tool point in turn
    on a serial chain; on a robot with branches, the base to each branch's first joint and each link's segments
    (:func:`dynid.excitation.obstacles.link_segments`), broken by NaN rows.

    Parameters
    ----------
    robot : Robot
    q : (F, n_dof) array [rad]

    Returns
    -------
    (F, P, 3) array [m]
    """
    rots, origins = forward_kinematics(robot, q)
    if not robot.is_tree:
        tip = origins[:, -1] + rots[:, -1] @ np.asarray(robot.tool_translation)
        return np.concatenate([np.zeros((q.shape[0], 1, 3)), origins, tip[:, None]], axis=1)
    roots = origins[:, robot.parents == -1]
    pieces = np.concatenate([np.stack([np.zeros_like(roots), roots], axis=2), link_segments(robot, q)], axis=1)
    gaps = np.full(pieces.shape[:2] + (1, 3), np.nan)
    return np.concatenate([pieces, gaps], axis=2).reshape(q.shape[0], -1, 3)


def _animation(run: ExcitationRun, path: Path) -> Path:
    """:data:`ANIMATION`: the skeleton (base, joint origins, tool point) on :data:`ANIMATION_FRAMES` instants."""
    problem = run.config.problem
    robot, ws = problem.robot, problem.workspace
    t = np.arange(ANIMATION_FRAMES) * (problem.period / ANIMATION_FRAMES)
    skeleton = arm_skeleton(robot, run.design.trajectory.evaluate(t)[0])
    path_t = problem.verification_grid()
    frames = figures.animate_arm(t, skeleton, tool_positions(robot, run.design.trajectory.evaluate(path_t)[0]),
                                 title=robot.name, floor=ws.floor, obstacles=ws.obstacles)
    save_animation(frames, path)
    return path


def _clearance_series(robot, t: np.ndarray, q: np.ndarray, ws, start: np.ndarray) -> dict:
    """label -> (N,) the links' shapes' smallest distance beyond what they keep to the floor and to each body, on
    ``t``."""
    out = {}
    needs = ws.floor_needs(robot, start)
    if needs is not None and needs.shapes.size:
        out["floor (lowest shape)"] = FloorDistances(robot, q, ws.shapes(robot), ws.floor, needs).dist.min(axis=1)
    if ws.obstacles:
        found = ws.cell_distances(robot, q)
        for i, ob in enumerate(ws.obstacles):
            cols = [c for c, (_, o) in enumerate(found.pairs) if o == i]
            if cols:
                out[ob.name] = found.distance[:, cols].min(axis=1)
    return out
