"""Reading back what ``dynid identify`` wrote (results.json): the estimates by label, each a base parameter vector.

results.json holds every estimate under ``estimates`` (label -> ``{key, values, std?, standard_values?, …}``).
Results written before that layout (``base_parameters`` and ``method``, ``physically_consistent``, ``methods``) are
read too.
"""

from __future__ import annotations

import numpy as np

from ..exceptions import DataError

__all__ = ["stored_estimates", "stored_standard"]


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


def _vector(entry, names: tuple, where: str) -> np.ndarray:
    try:
        return np.array([float(entry["values"][n]) for n in names])
    except (KeyError, TypeError, ValueError):
        raise DataError(f"{where}.values: expected a value for every base parameter") from None
