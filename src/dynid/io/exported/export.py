"""The identified model handed over: the estimate a results.json holds written as URDF and MJCF (by the robot's writers,
:mod:`dynid.model.description_files`), with what the files hold of it and what they cannot said in their comments.

:func:`consistent_estimate` takes the physically consistent estimate (and the robot it was identified with) from a
results.json; :func:`file_parameters` the terms each joint's file holds, as the validation logs chose them (friction
as identified or folded into the Coulomb and viscous pair a URDF and an MJCF hold, the torque offset left out or held
by an MJCF actuator); :func:`urdf_from_results` and :func:`mjcf_from_results` the files. A robot described by a URDF
or an MJCF gets its own file written back instead (:func:`dynid.io.exported.urdf_write_back.urdf_written_back`,
:mod:`dynid.io.exported.mjcf_write_back`). Only physically consistent parameters are exported: a file with a negative
mass or an impossible inertia makes simulators fail or behave wrongly.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from ..._util.keywords import keyword_only_after_data
from ...exceptions import ConfigError
from ...model.description_files import (
    OFFSET_ACTUATOR,
    _rpy,
    _vec,
    mjcf_from_robot,
    mujoco_inertia,
    quoteattr,
    urdf_from_robot,
)
from ...model.friction_model import robot_from_settings
from ...model.loading import as_robot
from ...model.robot import Robot
from ..results import LARGEST_VALUE, stored_standard


def consistent_estimate(robot: Robot, results: dict, source: str = "results") -> tuple[Robot, np.ndarray]:
    """The robot and the physically consistent standard parameters stored in a results file.

    The robot carries the Coulomb smoothing it was identified with; the parameters are the ``standard_values`` of the
    results' physically consistent estimate.

    Parameters
    ----------
    robot : Robot
        The robot's description the results were identified for.
    results : dict
        A parsed ``results.json`` of ``dynid identify``.
    source : str
        Where the results come from, named in errors.

    Returns
    -------
    robot : Robot
    phi : (n_params,) ndarray
        Standard parameters, SI units.

    Raises
    ------
    ConfigError
        No physically consistent estimate in the results, results of another robot, or a set that did not pass the
        consistency check (the verdict says why).
    """
    found = stored_standard(results)
    if found is None:
        raise ConfigError(f"{source}: no physically consistent estimate to export; identify with "
                          '[estimation] estimators including "sdp"')
    label, values = found
    verdict = results.get("physically_consistent_verdict", {}).get(label, "yes")
    if verdict != "yes":
        raise ConfigError(f"{source}: the physically consistent estimate did not pass the consistency check ({verdict})")

    try:
        robot = robot_from_settings(robot, results.get("settings", {}))
    except (ValueError, KeyError, TypeError) as exc:
        raise ConfigError(f"{source}: {exc}") from None
    missing = [n for n in robot.parameter_names if n not in values]
    if missing:
        raise ConfigError(f"{source}: its standard parameters are not those of robot {robot.name!r} (missing {', '.join(missing[:4])})")
    for n in robot.parameter_names:
        v = values[n]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
            raise ConfigError(f"{source}: estimates.{label}.standard_values.{n}: expected a finite number, got "
                              f"{'null' if v is None else repr(v)}")
    phi = np.array([float(values[n]) for n in robot.parameter_names])
    for n, v in zip(robot.parameter_names, phi):
        heavy = re.fullmatch(r"M\d+", n) is not None and not 0.0 <= v <= LARGEST_LINK_MASS
        if heavy or abs(v) > LARGEST_VALUE:
            what = (f"a link mass in [0, {LARGEST_LINK_MASS:g}] kg" if heavy else
                    f"a value within ±{LARGEST_VALUE:g} (SI units)")
            raise ConfigError(f"{source}: estimates.{label}.standard_values.{n}: expected {what}, got {float(v)!r}")
    return robot, phi


def file_parameters(robot: Robot, phi: np.ndarray, results: dict, source: str = "results", form: str = "URDF"
                    ) -> tuple[np.ndarray, str]:
    """The standard parameters a written URDF or MJCF holds, as the validation logs chose joint by joint for the estimate
    it is written from (results' ``diagnostics.file_terms``, :mod:`dynid.identification.file_terms`): the joints whose friction is folded hold the
    folded Coulomb and viscous pair and no Stribeck or load-dependent Coulomb term; in an MJCF, the torque offsets not
    held are 0 (those held become actuators' constant bias, :func:`offset_actuators`); a URDF keeps every offset, as
    its comments say.

    Parameters
    ----------
    robot : Robot
        As :func:`consistent_estimate` gives it.
    phi : (n_params,) array
        The physically consistent estimate's standard parameters.
    results : dict
        results.json.
    source : str
        Where the results come from, named in errors.
    form : {"URDF", "MJCF"}

    Returns
    -------
    phi : (n_params,) ndarray
        What the file holds (``phi`` itself where the results chose nothing).
    note : str
        What differs from dynid's model, for a comment in the file ("" where nothing does).

    Raises
    ------
    ConfigError
        A ``file_terms`` entry that is not a ``folded`` and an ``offset`` flag per joint, with a non-negative ``fc`` and
        ``fv`` per joint where a joint is folded.
    """
    out = np.array(phi, dtype=float)
    written, found = file_terms_entry(results)
    if found is None:
        return out, ""
    n = robot.n_dof
    try:
        folded = [j for j, f in enumerate(found["folded"]) if f is True]
        held = [j for j, f in enumerate(found["offset"]) if f is True]
        ok = len(found["folded"]) == len(found["offset"]) == n
        if folded:
            fc, fv = (np.array(found[k], dtype=float) for k in ("fc", "fv"))
            ok = ok and fc.shape == fv.shape == (n,) and bool(np.all(np.isfinite(fc + fv)) and np.all(fc >= 0) and np.all(fv >= 0))
    except (KeyError, TypeError, ValueError):
        ok = False
    if not ok:
        raise ConfigError(f"{source}: diagnostics.file_terms.{written}: expected folded and offset (true or false) for each of "
                          f"the {n} joints, and fc, fv (finite, >= 0) for each where one is folded")
    names = list(robot.parameter_names)
    for j in folded:
        for term in ("fc", "fv", "fst", "fcl"):
            if f"{term}{j + 1}" in names:
                out[names.index(f"{term}{j + 1}")] = {"fc": fc[j], "fv": fv[j]}.get(term, 0.0)
    said = []
    if folded:
        terms = " and ".join(found.get("terms") or ["Stribeck", "load-dependent Coulomb"])
        said.append(f"the friction of {_joints(folded)} holds its {terms} terms folded into the Coulomb and viscous "
                    "pair (the nearest pair on the identification log)")
    if form == "MJCF":
        left = [j for j in range(n) if j not in held and f"offset{j + 1}" in names and out[names.index(f"offset{j + 1}")] != 0]
        for j in left:
            out[names.index(f"offset{j + 1}")] = 0.0
        if held:
            said.append(f"the torque offsets of {_joints(held)} are held by actuators of constant bias "
                        f"({', '.join(OFFSET_ACTUATOR.format(joint=robot.joints[j].name) for j in held)})")
        if left:
            said.append(f"the torque offsets of {_joints(left)} are left out")
    if not said:
        return out, ""
    return out, ("dynid: " + "; ".join(said) + ", where the validation logs say that predicts the joint better; "
                 "dynid's own values are in results.json")


def file_terms_entry(results: dict) -> tuple[str, Any]:
    """The choice results.json holds of what the files hold (``diagnostics.file_terms``,
    :mod:`dynid.identification.file_terms`) for the estimate they are written from (:func:`stored_standard`).

    Parameters
    ----------
    results : dict
        results.json.

    Returns
    -------
    label : str
        The estimate the files are written from ("" where there is none).
    entry : object or None
        Its entry as stored (checked by :func:`file_parameters`); None where the results chose nothing for it.
    """
    chosen = (results.get("diagnostics") or {}).get("file_terms")
    written = stored_standard(results)
    if written is None or not isinstance(chosen, dict):
        return "" if written is None else written[0], None
    return written[0], chosen.get(written[0])


def _joints(indices) -> str:
    return ", ".join(f"J{j + 1}" for j in indices)


def with_note(text: str, note: str) -> str:
    """A written URDF or MJCF with ``note`` as a comment after its root element.

    Parameters
    ----------
    text : str
        The file's text.
    note : str
        The comment ("" leaves the text as it is; ``--`` is written ``-``, which an XML comment cannot hold).

    Returns
    -------
    str
    """
    if not note:
        return text
    return text.rstrip("\n") + f"\n<!-- {note.replace('--', '-')} -->\n"


LARGEST_LINK_MASS = 1e5
"""kg: a robot link's mass above this in a results file is no identification (the largest industrial arms' links
weigh a few tonnes); export refuses it rather than write it."""

def nominal_warning(results: dict) -> str | None:
    """One line when the exported (physically consistent) estimate predicted some joints of the validation logs worse
    than the description's nominal model (the gate of ``dynid identify``), naming them; or when it is the robot file's
    own values (``dynid identify`` kept them as the main estimate: its log could not improve them), so that the file
    written is not taken for an identified model; None otherwise.

    Parameters
    ----------
    results : dict
        A parsed ``results.json`` of ``dynid identify``.

    Returns
    -------
    str or None
    """
    found = stored_standard(results)
    nominal = (results.get("diagnostics") or {}).get("nominal_set")
    if found is None or not isinstance(nominal, str):
        return None
    label, worse = found[0], []
    if label == nominal:
        return (f"the estimate written is {nominal}, the robot file's own values: dynid identify kept them as the main "
                "estimate, as its log could not improve them (its verdict says what would)")
    for v in results.get("validation") or []:
        metrics = v.get("metrics") or {}
        if label not in metrics or nominal not in metrics:
            continue
        own, nom = metrics[label].get("relative_error") or [], metrics[nominal].get("relative_error") or []
        meaningful = v.get("relative_error_meaningful") or [True] * len(own)
        for j, (a, b, ok) in enumerate(zip(own, nom, meaningful)):
            if ok and a is not None and b is not None and a > b:
                worse.append(f"J{j + 1} of {v.get('name')} ({a:.3g} % against {b:.3g} %)")
    if not worse:
        return None
    return (f"{label} predicts {', '.join(worse[:4])}{f' and {len(worse) - 4} more' if len(worse) > 4 else ''} worse "
            f"than the description's nominal model ({nominal}): keep the nominal values for those joints, or identify "
            "on a log that excites them")


READINESS_KINDS = ("columns", "spikes", "sign", "scale", "order", "angles", "gravity", "rate", "unexplained")
"""Findings of ``dynid identify``'s verdict that say the log itself is wrong (the torques' sign, unit or gain, channels
swapped or mostly spikes, angles or a mounting that do not match the robot file, its sample rate, torques that no fit
follows): a model fitted to it is exported with a warning."""


def verdict_warnings(results: dict) -> list[str]:
    """One line per finding of ``dynid identify``'s verdict that says the log the model was fitted to is wrong
    (:data:`READINESS_KINDS`), for ``dynid export`` to repeat.

    Parameters
    ----------
    results : dict
        A parsed ``results.json`` of ``dynid identify``.

    Returns
    -------
    list of str
    """
    what = {"angles": "angles", "gravity": "a mounting", "rate": "a sample rate"}
    return [f"the model was fitted to {what.get(str(f.get('kind')), 'torques')} dynid identify doubts: "
            f"{f.get('text')}"
            for f in results.get("findings") or [] if isinstance(f, dict) and f.get("kind") in READINESS_KINDS]


def withheld_files(results: dict) -> str | None:
    """Why ``dynid identify`` writes no URDF or MJCF of a model: the identification log is read otherwise than the robot
    file (a :data:`READINESS_KINDS` finding of its own, not only of a validation log), so the model fitted to it is not
    the robot's; ``dynid export`` still writes it when asked, with the findings as warnings.

    Parameters
    ----------
    results : dict
        A parsed ``results.json`` of ``dynid identify`` (its ``findings``, each ``kind`` and ``text``).

    Returns
    -------
    str or None
        One line, or None where the files are written.
    """
    name = str((results.get("identification") or {}).get("name") or "identification")
    kinds = sorted({str(f.get("kind")) for f in results.get("findings") or [] if isinstance(f, dict)
                    and f.get("kind") in READINESS_KINDS and str(f.get("text", "")).startswith(f"{name}:")})
    if not kinds:
        return None
    what = {"columns": "columns that are not its torques", "sign": "a torque's sign", "scale": "the torques' unit or drive gains", "order": "torque columns swapped",
            "angles": "its angles", "gravity": "the mounting", "rate": "its sample rate"}
    misread = [k for k in kinds if k not in ("spikes", "unexplained")]
    if not misread:  # read right, but its torques are mostly spikes or what no model of the arm follows
        held = "mostly spikes" if "spikes" in kinds else "mostly what the arm's model cannot express"
        return (f"no URDF or MJCF written: the log {name} holds torques that are {held}, which no model of the arm "
                "follows (the verdict names the joints), so a model fitted to it is not the robot's; log a motion "
                "without them and identify that (dynid export CONFIG --urdf FILE writes this one all the same)")
    return (f"no URDF or MJCF written: the log {name} is read otherwise than the robot file "
            f"({', '.join(what[k] for k in misread)}: the verdict names the setting that fixes it), so a model fitted to "
            "it is not the robot's; identify again with that setting (dynid export CONFIG --urdf FILE writes this one "
            "all the same)")


@keyword_only_after_data
def urdf_from_results(robot: Robot | str | Path, results: dict, *, source: str = "results") -> str:
    """URDF of the physically consistent estimate of a ``results.json`` (:func:`consistent_estimate`), its friction as
    the results chose to write it (:func:`file_parameters`).

    Parameters
    ----------
    robot : Robot, str or Path
        The robot's description the results were identified for (a built-in robot's name or a description's path is
        loaded: :func:`dynid.model.loading.as_robot`).
    results : dict
        A parsed ``results.json`` of ``dynid identify``.
    source : str
        Where the results come from, named in errors.

    Returns
    -------
    str
        A URDF document.

    Raises
    ------
    ConfigError
        As :func:`consistent_estimate`.
    """
    fitted, phi = consistent_estimate(as_robot(robot), results, source)
    phi, note = file_parameters(fitted, phi, results, source)
    return with_note(urdf_from_robot(fitted, phi), note)


@keyword_only_after_data
def mjcf_from_results(robot: Robot, results: dict, *, source: str = "results") -> str:
    """MJCF of the physically consistent estimate of a ``results.json`` (:func:`consistent_estimate`), its friction as
    the results chose to write it (:func:`file_parameters`).

    Parameters
    ----------
    robot : Robot
        The robot's description the results were identified for.
    results : dict
        A parsed ``results.json`` of ``dynid identify``.
    source : str
        Where the results come from, named in errors.

    Returns
    -------
    str
        An MJCF document.

    Raises
    ------
    ConfigError
        As :func:`consistent_estimate`.
    """
    fitted, phi = consistent_estimate(robot, results, source)
    phi, note = file_parameters(fitted, phi, results, source, "MJCF")
    return with_note(mjcf_from_robot(fitted, phi, offsets_held=True), note)


MOVED_MASS = 0.5
"""A link whose identified mass differs from its nominal one by more than this fraction is said in the export."""
MOVED_COM = 0.1
"""[m] A link whose identified centre of mass lies this far from its nominal one is said in the export."""


def moved_far(link: str, mass: float, com: np.ndarray, nominal_mass: float, nominal_com: np.ndarray,
              form: str) -> str | None:
    """A line saying that a link's written values are far from its description's own, or None when they are not
    (mass by over :data:`MOVED_MASS`, centre of mass by over :data:`MOVED_COM` m).

    Parameters
    ----------
    link : str
    mass, nominal_mass : float [kg]
    com, nominal_com : (3,) arrays [m]
        Centres of mass, in one frame.
    form : str
        "URDF" or "MJCF", for the line.

    Returns
    -------
    str or None
    """
    if abs(mass - nominal_mass) <= MOVED_MASS * max(nominal_mass, 1e-12) and np.linalg.norm(com - nominal_com) <= MOVED_COM:
        return None
    def point(v):
        return " ".join(f"{x:.3g}" for x in v)

    return (f"{link}: mass {mass:.4g} kg (the {form}'s {nominal_mass:.4g}), centre of mass at ({point(com)}) m "
            f"(the {form}'s ({point(nominal_com)}))")


def identified_header(file: str, replaced: str, estimate: str, moved: list[str], form: str) -> str:
    """The header comment of a written-back description: what holds identified values, and what they are.

    Parameters
    ----------
    file : str
        The description's file name.
    replaced : str
        Which elements hold identified values.
    estimate : str
        What the values are.
    moved : list of str
        :func:`moved_far` lines.
    form : str
        "URDF" or "MJCF".

    Returns
    -------
    str
        The comment's text.
    """
    header = [f" written by dynid into {file}: {replaced} hold {estimate}; every other element is the original's.",
              "dynid identifies base parameters: the values written are one physically consistent choice among the many",
              "that predict the same torques (the split between a link and its motor's rotor inertia, and what the",
              "experiment does not excite, are that choice's). Use them to simulate or control the robot, not as each",
              "link's measured mass."]
    if moved:
        header += [f"Far from the {form}'s own values (a choice, as said above, or a description to check):"] + moved
    return "\n     ".join(header) + " "


def _replace(parent, tag: str, new) -> None:
    """Put ``new`` where ``parent``'s ``tag`` child is (or first), keeping the surrounding whitespace."""
    old = parent.find(tag)
    if old is not None:
        index = list(parent).index(old)
        new.tail = old.tail
        parent.remove(old)
        parent.insert(index, new)
    else:
        new.tail = parent.text if parent.text and not parent.text.strip() else "\n    "
        parent.insert(0, new)


def payload_files(payload, robot: Robot, parent: str, link: int | None = None) -> tuple[str, str]:
    """A payload (:class:`dynid.identification.payload.Payload`) as a URDF link on a fixed joint and as an MJCF body,
    each to paste into the arm's file: the body sits at the flange (the robot's tool frame in its last link; another
    link's own frame, :meth:`dynid.model.robot.Robot.flange`), its inertial in the flange's frame.

    Parameters
    ----------
    payload : Payload
    robot : Robot
        Its tool frame is the flange.
    parent : str
        The URDF link the payload is fixed to (the arm's last link, or ``link``'s).
    link : int, optional
        The link carrying the payload, 0-based (default the last).

    Returns
    -------
    (str, str)
        The URDF snippet and the MJCF snippet.
    """
    import pinocchio as pin

    inertia = mujoco_inertia(np.asarray(payload.inertia, dtype=float))
    rotation, translation = robot.flange(link=link)
    q = pin.Quaternion(rotation)
    head = (f"identified by dynid payload: {payload.mass:.6g} kg (σ {payload.mass_std:.2g}); "
            f"not determined by the log, kept at a point mass's values: {', '.join(payload.not_determined) or 'none'}")
    urdf = "\n".join([
        f"<!-- {head} -->",
        '<joint name="payload_joint" type="fixed">',
        f"  <parent link={quoteattr(parent)}/>",
        '  <child link="payload"/>',
        f'  <origin xyz="{_vec(translation)}" rpy="{_vec(_rpy(rotation))}"/>',
        "</joint>",
        '<link name="payload">',
        "  <inertial>",
        f'    <origin xyz="{_vec(payload.com)}" rpy="0 0 0"/>',
        f'    <mass value="{payload.mass:.17g}"/>',
        f'    <inertia ixx="{inertia[0, 0]:.17g}" ixy="{inertia[0, 1]:.17g}" ixz="{inertia[0, 2]:.17g}" '
        f'iyy="{inertia[1, 1]:.17g}" iyz="{inertia[1, 2]:.17g}" izz="{inertia[2, 2]:.17g}"/>',
        "  </inertial>",
        "</link>", ""])
    mjcf = "\n".join([
        f"<!-- {head}; put this body inside the body of {parent} -->",
        f'<body name="payload" pos="{_vec(translation)}" quat="{q.w:.17g} {q.x:.17g} {q.y:.17g} {q.z:.17g}">',
        f'  <inertial pos="{_vec(payload.com)}" mass="{payload.mass:.17g}" fullinertia="{inertia[0, 0]:.17g} '
        f'{inertia[1, 1]:.17g} {inertia[2, 2]:.17g} {inertia[0, 1]:.17g} {inertia[0, 2]:.17g} {inertia[1, 2]:.17g}"/>',
        "</body>", ""])
    return urdf, mjcf
