"""What ``dynid excite`` prints of a design (limits, margins, the cell's and the self clearances, MuJoCo's check), as
blocks of :mod:`dynid.tables`; :func:`dynid.report.summaries.blocks` dispatches to it."""

from __future__ import annotations

import math

from ..tables import Line, TextTable

__all__ = ["excitation_blocks", "no_floor_line", "set_point_lines"]


def excitation_blocks(run, tables: bool = True) -> list:
    """What ``dynid excite`` prints: the verdict first (the criterion before and after, whether every constraint holds
    and the tightest), how close the links' shapes come to the floor, the cell and each other, the set-points and the
    next step; with ``tables``, the design before and after and every constraint's margin (issue "Fast where users
    wait", item 4: ``dynid excite`` shows them with ``--verbose``, report.html always).

    Parameters
    ----------
    run : dynid.identification.excite.ExcitationRun
    tables : bool
        The before/after and margins tables (else one line on the design's search).

    Returns
    -------
    list of Line and TextTable
    """
    d, p, c = run.design, run.config.problem, run.config
    out: list = [_verdict_line(d, tables),
                 Line(f"dynid excite — robot {c.full_robot.name}, joints 1-{p.robot.n_dof}, {p.n_harmonics} harmonics, "
                      f"ω_f = {p.omega_f:.4g} rad/s (period {p.period:.4g} s), {p.base.n_base} base parameters, "
                      f"criterion {p.criterion}")]
    held = tuple(getattr(c.full_robot, "held", ()) or ())
    if held:
        out.append(Line(f"held fixed at 0, not the arm's joints: {', '.join(held)}"))
    if p.robot.followers:  # excitation.csv's columns of such a joint say what it does: no set-point to play
        out.append(Line(p.robot.followers_said(columns="their columns in excitation.csv are what they do, not set-points")))
    out += (_design_lines(d, f"initial: {c.initial_label}", f" (design grid of {p.grid_points} samples per period)")
            if tables else _search_lines(d))
    encoders, (start, kind) = set_point_lines(run.set_points())
    out += [Line(f"excitation.csv: {run.t.size} set-points at {c.rate:g} Hz" + encoders), Line(start, kind)]
    free = p.unlimited_joints()
    if free:
        swing = ", ".join(f"J{j + 1} {run.q[:, j].min():.3g} to {run.q[:, j].max():.3g} rad" for j in free)
        out.append(Line(f"no position limits on {', '.join(f'J{j + 1}' for j in free)} (continuous joints): the design "
                        f"swings them about their offset within their velocity and acceleration limits only ({swing}); "
                        "give q_min and q_max in [limits] to bound them", "warning"))
    lowest = getattr(run, "lowest", None)
    if lowest is not None:
        text, warned = no_floor_line(lowest.to_dict(), p.workspace.clearance)
        out.append(Line(text, "warning" if warned else "text"))
    out += (_shapes_lines(run) + _self_clearance_lines(run) + _floor_lines(run) + _cell_clearance_lines(run)
            + _mujoco_lines(run))
    warnings = sum(isinstance(line, Line) and line.kind == "warning" for line in out)
    if warnings:  # the first line says it too: "every constraint holds" is not "safe to run" while a warning stands
        out[0] = Line(f"{out[0].text}; {warnings} warning{'s' if warnings > 1 else ''} below to settle before it runs",
                      "warning")
    if d.feasible:
        first = "settle the warnings above, then " if warnings else ""
        out.append(Line(f"next: {first}play excitation.csv on the robot at its rate (docs: the workflow tutorial), log "
                        "positions and torques (or motor currents), and dynid identify the log"))
    return out


START_AT_REST = 1e-6
"""A speed [rad/s] below which the first set-point is taken as at rest."""


def set_point_lines(set_points: dict) -> tuple[str, tuple[str, str]]:
    """What excitation.csv's angles are and where it starts, from :meth:`ExcitationRun.set_points
    <dynid.identification.excite.ExcitationRun.set_points>` (excitation.json's ``set_points``).

    A position controller handed the first row from another pose jumps there, so the arm is brought there first; a
    design that starts moving is a warning.

    Parameters
    ----------
    set_points : dict
        ``position_offset``, ``first`` [rad] and ``first_velocity`` [rad/s], one per joint.

    Returns
    -------
    encoders : str
        Appended to the excitation.csv line where the description sets position offsets (the file then holds the
        encoders' angles); empty otherwise.
    start : (str, str)
        The line on the start and its kind ("text" or "warning").
    """
    from ..conventions import joint_angles_text  # numpy's import kept from report.html's

    offset, speeds = set_points["position_offset"], [abs(v) for v in set_points["first_velocity"]]
    turned = joint_angles_text(offset)
    encoders = (f", at the angles the joints' encoders read (the description's minus its position_offset, {turned}), "
                "as the controller takes them; excitation.json and the figures hold the description's" if turned else "")
    sliding = set_points.get("prismatic") or [False] * len(speeds)
    pose = ", ".join(f"J{j + 1} {v:.3f} m" if sliding[j] else f"J{j + 1} {math.degrees(round(v, 6)) + 0.0:.1f}°"
                     for j, v in enumerate(set_points["first"]))
    units = "in radians there, metres for a prismatic joint" if any(sliding) else "in radians there"
    if max(speeds) <= START_AT_REST:
        return encoders, (f"it starts at rest at {pose} (its first row, {units}): bring the arm there with a "
                          "slow point-to-point move before playing it", "text")
    j = speeds.index(max(speeds))
    return encoders, (f"it starts moving ({speeds[j]:.3g} {'m/s' if sliding[j] else 'rad/s'} on J{j + 1}) at {pose} "
                      f"(its first row, {units}): "
                      "a controller at rest there takes that step in speed; bring the arm there slowly and ramp in, or "
                      "design from rest ([trajectory] rest = true)", "warning")


def no_floor_line(lowest: dict, clearance: float) -> tuple[str, bool]:
    """What a design without a floor says of the surface the robot stands on: where the arm goes lowest
    (:func:`dynid.excitation.constraints.lowest_point`), a warning where that is below the base frame's origin or
    within the links' clearance above it.

    Parameters
    ----------
    lowest : dict
        excitation.json's ``lowest``: ``height`` [m], ``point``, ``time`` [s].
    clearance : float [m]
        The links' clearance (``workspace.clearance``).

    Returns
    -------
    text : str
    warning : bool
        Whether the arm's links reach below the base frame's origin.
    """
    h, point, t = float(lowest["height"]), lowest["point"], float(lowest["time"])
    if h >= clearance:
        return (f"no floor given ([workspace] floor): the lowest point, {point}, stays {h:.3g} m above the base frame's "
                f"origin (t = {t:.3g} s)"), False
    where = (f"goes {-h:.3g} m below the base frame's origin" if h < 0 else
             f"comes {h:.3g} m above the base frame's origin, its link within its {clearance:g} m clearance of that level")
    return (f"no floor given ([workspace] floor), so nothing kept the arm off what it stands on: {point} {where} at "
            f"t = {t:.3g} s. If the robot stands on a table or the floor, "
            "give its height in the base frame as [workspace] floor (0 where the base frame sits on it; every link's "
            "shape then stays workspace.clearance above it) and design again"), True


def design_blocks(design) -> list:
    """What an excitation design says of itself (:func:`dynid.excitation.design.design_excitation`'s result, designed
    from the library: ``dynid.summary(design)``): the criterion before and after, the starts, the constraint margins.

    Parameters
    ----------
    design : dynid.excitation.design.ExcitationDesign

    Returns
    -------
    list of Line and TextTable
    """
    return [Line(f"excitation design — criterion {design.criterion}", "title"), *_design_lines(design, "initial", ""),
            _verdict_line(design)]


def _design_lines(d, initial: str, grid: str) -> list:
    """The before/after table, the initial trajectory's violations, the verification line and the margins table."""
    out: list = [TextTable(f"Before / after{grid}", ("trajectory", "cond(W_base)", "log det(WᵀW/N)"),
                           ((initial, f"{d.initial_cond:.2f}", f"{d.initial_log_det:.2f}"),
                            ("optimised", f"{d.cond:.2f}", f"{d.log_det:.2f}")))]
    if d.initial_violations:
        out.append(Line("the initial trajectory violates: " + "; ".join(
            f"{m.constraint} on {m.where} ({m.worst:.4g} against {m.limit:.4g})" for m in d.initial_violations), "warning"))
    else:
        out.append(Line("the initial trajectory satisfies every constraint too (same limits for both)"))
    out.append(Line(f"cond on the 10× finer verification grid: {d.cond_verification:.2f}; ratio optimised/initial "
                    f"{d.cond / d.initial_cond:.3f}; criterion from each start " + ("(cond)" if d.criterion == "cond" else "(−log det)")
                    + ": " + ", ".join(f"{v:.2f}" for v in d.start_values)
                    + f"; {d.nit} SLSQP iterations, {d.nfev} evaluations, {d.seconds:.1f} s"))
    rows = tuple((m.constraint, m.where, f"{m.limit:.4g}", f"{m.worst:.4g}", f"{m.margin:.4g}",
                  "" if math.isnan(m.relative) else f"{100 * m.relative:.1f}") for m in d.margins)
    out.append(TextTable("Constraint margins on the verification grid (margin = limit − worst; ≥ 0 holds)",
                         ("constraint", "where", "limit", "worst", "margin", "margin %"), rows, labels=2))
    return out


def _verdict_line(d, tables: bool = True) -> Line:
    """cond before and after, whether every constraint holds and the tightest one (margins in units of their limit)."""
    relative = [m for m in d.margins if not math.isnan(m.relative)]
    tight = min(relative, key=lambda m: m.relative) if relative else None
    where = "the margins table" if tables else "dynid excite --verbose, or report.html"
    violated = [m for m in d.margins if m.margin < 0]
    return Line(f"cond(W_base) {d.initial_cond:.2f} → {d.cond:.2f} ({d.initial_cond / d.cond:.2g}× better conditioned); "
                + ("every constraint holds" if d.feasible else
                   f"a constraint is violated ({', '.join(f'{m.constraint} on {m.where}' for m in violated[:2])}: {where})")
                + ("" if tight is None else f", the tightest: {tight.constraint} on {tight.where} "
                                            f"({100 * tight.relative:.1f} % of its limit to spare)"), "title")


def _search_lines(d) -> list:
    """One line on the design's search, for the terminal without its tables: the verification grid's figure, the
    starts, the iterations and the time; the initial trajectory's violations where it has any."""
    out = [Line(f"cond on the 10× finer verification grid {d.cond_verification:.2f}; {len(d.start_values)} starts, "
                f"{d.nit} SLSQP iterations, {d.seconds:.1f} s (the tables: --verbose, and report.html)")]
    if d.initial_violations:
        out.append(Line("the initial trajectory violates: " + "; ".join(
            f"{m.constraint} on {m.where} ({m.worst:.4g} against {m.limit:.4g})" for m in d.initial_violations), "warning"))
    return out


def _self_clearance_lines(run) -> list:
    """:func:`excitation_blocks`' line on how close the links come to each other
    (:func:`dynid.excitation.collision.self_clearance`): a warning where their capsules overlap."""
    c = getattr(run, "self_clearance", None)
    if c is None:
        return []
    p = run.config.problem
    radius = p.workspace.capsule_radius(p.robot)
    where = f"links {c.pair[0]} and {c.pair[1]} at t = {c.time:.3g} s"
    if c.shapes and c.distance < 0:  # the URDF's own shapes (a held arm's among them), kept apart by the design
        return [Line(f"the links' collision shapes meet: {c.shapes[0]} and {c.shapes[1]} overlap by {-c.distance:.3g} m "
                     f"at t = {c.time:.3g} s ({c.pairs} pairs checked on the set-points): check this pose on the robot "
                     "(or in a simulator) before running it, or lower the amplitudes", "warning")]
    if c.shapes:
        return [Line(f"the links' collision shapes stay {c.distance:.3g} m apart or more (closest: {c.shapes[0]} and "
                     f"{c.shapes[1]} at t = {c.time:.3g} s; {c.pairs} pairs checked on the set-points)")]
    if c.distance < 0:
        kept = run.config.problem.workspace.avoid_self_collision
        how = ("the design kept them apart on its grid, not between its samples: raise design.grid_points" if kept else
               "the design keeps the capsules apart where asked: [workspace] avoid_self_collision = true (a slower "
               "design); else check this pose on the robot (or in a simulator) before running it, or lower the "
               "amplitudes")
        return [Line(f"links that can touch come together: their {radius:.3g} m capsules overlap by "
                     f"{-c.distance:.3g} m ({where}; {c.pairs} pairs checked on the set-points): {how}", "warning")]
    return [Line(f"links that can touch stay {c.distance:.3g} m apart or more beyond their {radius:.3g} m capsules "
                 f"(closest: {where}; {c.pairs} pairs checked on the set-points)")]


def _shapes_lines(run) -> list:
    """:func:`excitation_blocks`' warning where the robot file's collision shapes did not load: the floor's and the
    cell's distances are then measured on estimated capsules (unless ``[workspace] link_radius`` is given), and the
    links of held joints (another arm, a head) are in no check at all."""
    ws = run.config.problem.workspace
    held = run.config.problem.robot.held
    capsules = ws.link_radius is None and bool(ws.obstacles or math.isfinite(ws.floor))
    if ws.geometry is not None or not (held or capsules):
        return []
    from ..excitation.link_geometry import LINK_RADIUS_SHARE  # coal's import stays out of a summary's

    said = ["the robot file has no collision shapes dynid could read" + (f" ({ws.unread})" if ws.unread else "")]
    if capsules:
        r = ws.capsule_radius(run.config.problem.robot)
        said.append(f"the floor and the cell are kept off capsules of radius {r:.3g} m about the joint origins, an "
                    f"estimate ({100 * LINK_RADIUS_SHARE:g} % of the arm's reach) that a hand, a gripper or a wide "
                    "housing can exceed; give [workspace] link_radius, or a URDF with <collision> shapes and its meshes")
    if held:
        said.append(f"the held joints' links ({', '.join(held)}: another arm, a head, a gripper) are in no clearance "
                    "check; give the robot file's meshes beside it, and design again")
    return [Line(": ".join(said[:2]) + "".join(f"; {x}" for x in said[2:]), "warning")]


def _floor_lines(run) -> list:
    """:func:`excitation_blocks`' line on how close the links' shapes come to the floor at the set-points
    (:func:`dynid.excitation.constraints.floor_margins`): a warning where one comes within what it must keep."""
    found = [m for m in getattr(run, "cell_clearance", ()) if m.constraint.startswith("floor")]
    if not found:
        return []
    p = run.config.problem
    ws, low = p.workspace, found[0]
    if low.margin < 0:
        return [Line(f"a link's shape comes within the floor's clearance at a set-point: {low.where} at {low.worst:.3g} m "
                     f"above the floor, {-low.margin:.3g} m inside (between the verification grid's samples): do not "
                     "run it; raise design.grid_points", "warning")]
    from ..excitation.floor import START_SLACK  # coal's import stays out of a summary's

    needs = ws.floor_needs(p.robot, p.start_pose())
    names = ws.shapes(p.robot).names
    held = [] if needs is None else needs.within
    within = "" if not held else (
        f" (those that start within it, at most {1000 * START_SLACK:g} mm lower than they start: "
        + ", ".join(f"{names[int(needs.shapes[c])]} from {needs.start[c]:.3g} m" for c in held) + ")")
    under = needs is not None and any(needs.start[c] < 0 for c in held)  # estimated capsules only: shapes are refused
    return [Line(f"every link's shape stays {ws.clearance:g} m or more above the floor ({ws.floor:g} m) at the set-points"
                 f"{within}; the tightest: {low.where}, {low.worst:.3g} m above it (measured on the {ws.shapes_said()})"
                 + ("; a capsule that starts under the floor is wider than the link or the floor is set too high: "
                    "give [workspace] link_radius or the robot's collision shapes" if under else ""),
                 "warning" if under else "text")]


def _cell_clearance_lines(run) -> list:
    """:func:`excitation_blocks`' line on how close the links' shapes come to the cell's bodies at the set-points
    (:func:`dynid.excitation.constraints.obstacle_margins`): a warning where one comes within the clearance."""
    found = [m for m in getattr(run, "cell_clearance", ()) if not m.constraint.startswith("floor")]
    if not found:
        return []
    ws = run.config.problem.workspace
    low = min(found, key=lambda m: m.worst)
    if low.worst < 0:
        return [Line(f"a link's shape comes within {ws.clearance:g} m of the cell at a set-point: {low.where} (by "
                     f"{-low.worst:.3g} m, between the verification grid's samples): do not run it; raise "
                     "design.grid_points", "warning")]
    n = len(ws.obstacles)
    return [Line(f"every link's shape stays {ws.clearance + low.worst:.3g} m or more off the cell at the set-points, "
                 f"{low.worst:.3g} m beyond the {ws.clearance:g} m clearance ({n} {'body' if n == 1 else 'bodies'}; "
                 f"closest: {low.where}; measured on the {ws.shapes_said()})")]


def _mujoco_lines(run) -> list:
    """:func:`excitation_blocks`' line on the second check, MuJoCo's contacts at the set-points
    (:func:`dynid.excitation.cell_replay.cell_contacts`)."""
    ws = run.config.problem.workspace
    if not ws.obstacles and not math.isfinite(ws.floor):
        return []
    found = getattr(run, "mujoco_contacts", None)
    if found is None:
        return [Line("the set-points were checked against the cell once: MuJoCo is not installed for the second check "
                     "(pip install 'dynid[mujoco]')")]
    if found.touching:
        f = found.first
        return [Line(f"MuJoCo finds link {f['link']}'s shape within the clearance of {f['body']} at t = {f['time']:.3g} s "
                     f"({found.touching} of {found.set_points} set-points, up to {found.deepest:.3g} m inside): do not "
                     "run it", "warning")]
    return [Line("checked again by MuJoCo on the same shapes (the floor as a plane, each shape's margin the clearance): "
                 + mujoco_clear_said(found.to_dict()))]


def mujoco_clear_said(contacts: dict) -> str:
    """What MuJoCo's second check found where no shape touched (``CellContacts.to_dict()``): the links against the
    cell and the floor only (their own shapes are checked apart), and the shapes that start within the floor's
    clearance held to their start height, named, as the check held them.

    Parameters
    ----------
    contacts : dict
        :meth:`dynid.excitation.cell_replay.CellContacts.to_dict` (``held`` missing in an older excitation.json).

    Returns
    -------
    str
    """
    held = list(contacts.get("held") or ())
    one = len(held) == 1
    but = (f", but {', '.join(held)} start{'s' if one else ''} within the floor's clearance and {'was' if one else 'were'}"
           f" held only to no lower than {'it starts' if one else 'they start'}") if held else ""
    return (f"no link's shape comes within the clearance of the cell or the floor on the {contacts['set_points']} "
            f"set-points{but} (each link against the cell and the floor: the links' own shapes against each other are "
            "checked apart)")
