"""Reading back what ``dynid identify`` wrote (results.json): the estimates by label, each a base parameter vector.

results.json holds every estimate under ``estimates`` (label -> ``{key, values, std?, standard_values?, …}``).
Results written before that layout (``base_parameters`` and ``method``, ``physically_consistent``, ``methods``) are
read too.
"""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path

import numpy as np

from ..exceptions import DataError

__all__ = ["read_results", "stored_estimates", "stored_standard", "stored_residual_level"]

OLD_LAYOUT = 1
"""``schema_version`` of results written before the estimates table: read without the schema's check."""


def check_fingerprint(results: dict, robot, source: str) -> None:
    """Refuse results identified with a description whose kinematics differ from ``robot``'s (its
    ``settings.robot_fingerprint``, :meth:`dynid.model.robot.Robot.kinematic_fingerprint`; results of earlier releases
    have none and are not checked).

    Parameters
    ----------
    results : dict
        A parsed results.json.
    robot : Robot
        The description the results are used with.
    source : str
        The results' file, named in the error.

    Raises
    ------
    DataError
        The fingerprints differ.
    """
    settings = results.get("settings")
    stored = settings.get("robot_fingerprint") if isinstance(settings, dict) else None
    now = robot.kinematic_fingerprint()
    if isinstance(stored, str) and stored != now:
        raise DataError(f"{source}: identified with a description of {robot.name!r} whose joint frames, tool, gravity "
                        f"or gear ratios differ from the one given now (fingerprint {stored} against {now}): use the "
                        "description it was identified with")


def read_results(path: str | Path, robot: str | None = None, missing_hint: str = "") -> dict:
    """The results.json of ``dynid identify``, checked against the shipped schema and against the robot.

    Parameters
    ----------
    path : str or Path
    robot : str, optional
        The name of the robot the results are read for (a config's robot): results of another robot are refused.
    missing_hint : str
        Said after "not found" (e.g. what to run first).

    Returns
    -------
    dict
        The parsed results.

    Raises
    ------
    DataError
        One line naming the file and the first field that does not follow ``dynid/schema/results.schema.json``
        (JSON path, what was expected), a file of another kind, or results of another robot.
    """
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise DataError(f"{path}: not found{missing_hint}") from None
    except IsADirectoryError:
        raise DataError(f"{path}: a folder; give the results.json in it") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise DataError(f"{path}: cannot read it as JSON ({exc})") from None
    if not isinstance(data, dict):
        raise DataError(f"{path}: expected the results.json of dynid identify (a JSON object), got a {type(data).__name__}")
    kind = data.get("kind", "identify")
    if kind != "identify":
        raise DataError(f"{path}: expected the results.json of dynid identify, got the results of dynid {kind}")
    if data.get("schema_version") != OLD_LAYOUT:
        problem = schema_problem(data)
        if problem:
            raise DataError(f"{path}: {problem}")
    if robot is not None and isinstance(data.get("robot"), str) and data["robot"] != robot:
        raise DataError(f"{path}: results of robot {data['robot']!r}, the config's robot is {robot!r}; give the config "
                        "they were identified with")
    return data


def schema_problem(data: dict) -> str:
    """The first place where results depart from the shipped schema, as ``field.path: what was expected``.

    Parameters
    ----------
    data : dict
        Parsed results of any kind.

    Returns
    -------
    str
        Empty when the results follow the schema.
    """
    import jsonschema

    schema = json.loads((resources.files("dynid") / "schema" / "results.schema.json").read_text(encoding="utf-8"))
    error = jsonschema.exceptions.best_match(jsonschema.Draft202012Validator(schema).iter_errors(data))
    if error is None:
        return ""
    where = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in error.absolute_path).lstrip(".")
    if error.validator == "required":
        missing = error.message.split("'")[1] if "'" in error.message else error.message
        return f"{where + '.' if where else ''}{missing}: missing"
    if error.validator == "const" and where == "schema_version":
        return f"schema_version: expected {error.validator_value}, got {error.instance!r} (written by another version of dynid?)"
    return f"{where or 'the file'}: {error.message}"


def stored_estimates(identified: dict, names, source: str = "results", robot: str = "") -> dict:
    """label -> base parameter vector of every estimate in a results.json.

    Parameters
    ----------
    identified : dict
        The parsed results.json of ``dynid identify``.
    names : sequence of str
        The base parameters expected, in order (those of the robot the results are read for).
    source : str
        Named in the messages.
    robot : str
        The robot's name, for the messages.

    Returns
    -------
    dict
        label -> (n_base,) array, in the order results.json holds them.

    Raises
    ------
    DataError
        Not results of ``dynid identify``, results of another robot (other base parameters), or an estimate
        without a value for every base parameter.
    """
    names = tuple(names)
    if not isinstance(identified, dict) or not isinstance(identified.get("base_parameters"), list):
        raise DataError(f"{source}: expected the results.json of dynid identify (a list base_parameters of {{name, value}})")
    try:
        stored = tuple(str(p["name"]) for p in identified["base_parameters"])
    except (KeyError, TypeError):
        raise DataError(f"{source}: base_parameters: expected a list of {{name, value}}") from None
    if stored != names:
        raise DataError(f"{source}: its base parameters ({len(stored)}) are not those of robot {robot or 'this'!r} ({len(names)}); "
                        "was it identified with this config?")
    sets = {}
    if isinstance(identified.get("estimates"), dict):
        for label, e in identified["estimates"].items():
            sets[str(label)] = _vector(e, names, f"{source}: estimates.{label}")
        return sets
    # results.json before the estimates table
    method = str(identified.get("method", "ls")).upper()
    try:
        sets[f"dynid {method}"] = np.array([float(p["value"]) for p in identified["base_parameters"]])
    except (KeyError, TypeError, ValueError):
        raise DataError(f"{source}: base_parameters: every entry needs a numeric value") from None
    if isinstance(identified.get("physically_consistent"), dict):
        sets["dynid SDP"] = _vector(identified["physically_consistent"], names, f"{source}: physically_consistent")
    for label, m in (identified.get("methods") or {}).items():
        sets[str(label)] = _vector(m, names, f"{source}: methods.{label}")
    return sets


def stored_standard(identified: dict) -> tuple[str, dict] | None:
    """The physically consistent estimate's label and standard parameters (name -> value), if the results hold one:
    the main estimate when it has standard values, else the first estimate that has.

    Parameters
    ----------
    identified : dict
        The parsed results.json of ``dynid identify``.

    Returns
    -------
    (label, dict) or None
    """
    if not isinstance(identified, dict):
        return None
    estimates = identified.get("estimates")
    if isinstance(estimates, dict):
        main = identified.get("main_estimate")
        ordered = ([main] if main in estimates else []) + [k for k in estimates if k != main]
        for label in ordered:
            e = estimates[label]
            if isinstance(e, dict) and isinstance(e.get("standard_values"), dict):
                return str(label), e["standard_values"]
        return None
    sdp = identified.get("physically_consistent")
    if isinstance(sdp, dict) and isinstance(sdp.get("standard_values"), dict):
        return str(sdp.get("label", "dynid SDP")), sdp["standard_values"]
    return None


def stored_residual_level(identified: dict, n_dof: int) -> np.ndarray | None:
    """Each joint's residual standard deviation on the identification log, as a results.json holds it
    (``joint_residual_std``): what a validation log's torque must exceed for its relative error and its correlation
    coefficient (eq. 18) to mean something (:meth:`dynid.validation.torques.TorqueComparison.meaningful`, ``varies``).

    Parameters
    ----------
    identified : dict
        The parsed results.json of ``dynid identify``.
    n_dof : int
        The robot's joints.

    Returns
    -------
    (n_dof,) array [N·m] or None
        None where the results hold no such figure, or not one per joint.
    """
    try:
        level = np.asarray(identified.get("joint_residual_std"), dtype=float)
    except (AttributeError, TypeError, ValueError):
        return None
    return level if level.shape == (n_dof,) else None


def _vector(entry, names: tuple, where: str) -> np.ndarray:
    try:
        out = np.array([float(entry["values"][n]) for n in names])
    except (KeyError, TypeError, ValueError):
        raise DataError(f"{where}.values: expected a value for every base parameter") from None
    if not np.all(np.isfinite(out)):
        bad = names[int(np.flatnonzero(~np.isfinite(out))[0])]
        raise DataError(f"{where}.values.{bad}: expected a finite number, got {entry['values'][bad]!r}")
    if np.any(np.abs(out) > LARGEST_VALUE):  # its squares overflow the scores (a 1e308 crashed dynid validate)
        bad = names[int(np.flatnonzero(np.abs(out) > LARGEST_VALUE)[0])]
        raise DataError(f"{where}.values.{bad}: expected a value within ±{LARGEST_VALUE:g} (SI units), got "
                        f"{entry['values'][bad]!r}")
    return out


LARGEST_VALUE = 1e12
"""The largest magnitude of a base or standard parameter (SI units) a results file may hold: beyond, its squares
overflow the scores dynid and a simulator form (a 1e308 crashed dynid validate, and export wrote a 1e308 kg link)."""
