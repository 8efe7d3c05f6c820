"""``dynid migrate``: an identify config of an earlier release rewritten for this one with tomlkit (a TOML document that
keeps the comments and layout the user wrote; an inline table is rewritten as one).

What an earlier release accepted and this one does not:

* ``[estimation] method``, ``methods`` and ``physically_consistent`` (up to the estimator registry): one list,
  ``estimators``, the main estimate first (``method = "wls"`` with ``physically_consistent = true`` is
  ``estimators = ["wls", "sdp"]``);
* ``[preprocessing] torque_cutoff`` (a filter on the torques alone, which biased the estimate near velocity
  reversals): ``parallel_cutoff``, the same cutoff on the torques and every regressor column, a changed meaning the
  migration names.

The settings whose meaning changed while their spelling stayed are listed in the changelog under "Changed"; the
migration names them in its report when a config uses them (:data:`CHANGED_MEANINGS`).
"""

from __future__ import annotations

import tomllib

import tomlkit
from tomlkit.exceptions import TOMLKitError

from ...exceptions import ConfigError

__all__ = ["OLD_ESTIMATION_KEYS", "CHANGED_MEANINGS", "migrate_text"]

OLD_ESTIMATION_KEYS = ("method", "methods", "physically_consistent")
"""``[estimation]`` keys of earlier releases, said now as ``estimators``."""

RENAMED = {
    ("preprocessing", "torque_cutoff"): ("parallel_cutoff", "it filtered the torques alone, which biased the estimate "
                                                            "near velocity reversals; parallel_cutoff filters the torques "
                                                            "and every regressor column alike, so the estimate changes"),
}
"""(table, old key) -> (new key, how the meaning changed)."""

CHANGED_MEANINGS = {
    ("preprocessing", "decimation"): "a given decimation is every log's (validation logs too), as before the validation "
                                     "logs had settings of their own; in between it was the identification log's only",
}
"""(table, key) -> how its meaning changed, for the settings whose spelling stayed (docs/changelog.md, "Changed")."""


def migrate_text(text: str, where: str = "config") -> tuple[str, list[str]]:
    """The config rewritten for this release, and one line per change.

    Parameters
    ----------
    text : str
        The TOML text of an identify config.
    where : str
        Its name, for the messages.

    Returns
    -------
    text : str
        The rewritten config (the same text when nothing needed a change).
    changes : list of str
        What was rewritten, then the settings whose meaning changed that the config uses.

    Raises
    ------
    ConfigError
        Text that is no TOML.
    """
    try:
        doc = tomllib.loads(text)
        edited = tomlkit.parse(text)  # the same text as a document that keeps its comments and layout
    except (tomllib.TOMLDecodeError, TOMLKitError) as exc:
        raise ConfigError(f"{where}: invalid TOML ({exc})") from None
    changes: list[str] = []
    est = doc.get("estimation")
    old = [k for k in OLD_ESTIMATION_KEYS if isinstance(est, dict) and k in est]
    if old and isinstance(est, dict):
        from .identification_config import _estimators_from_old

        new = _estimators_from_old(est)
        if "estimators" in est:
            raise ConfigError(f"{where}: [estimation] has both estimators and {', '.join(old)}: keep estimators only")
        _replace(edited["estimation"], old, "estimators", tomllib.loads(f"x = {new}")["x"])
        said = ", ".join(f"{k} = {_toml(est[k])}" for k in old)
        changes.append(f"[estimation] {said} -> estimators = {new}")
    for (table, key), (new_key, why) in RENAMED.items():
        section = doc.get(table)
        if isinstance(section, dict) and key in section:
            if new_key in section:
                _replace(edited[table], [key], None, None)
                changes.append(f"[{table}] {key} = {_toml(section[key])} removed ({new_key} is given): {why}")
            else:
                _replace(edited[table], [key], new_key, section[key])
                changes.append(f"[{table}] {key} = {_toml(section[key])} -> {new_key} = {_toml(section[key])}: its "
                               f"meaning changed: {why}")
    for (table, key), why in CHANGED_MEANINGS.items():
        if isinstance(doc.get(table), dict) and key in doc[table]:
            changes.append(f"[{table}] {key} = {_toml(doc[table][key])}: its meaning changed: {why} (kept as written)")
    renamed = [(t, k) for t, k in RENAMED if isinstance(doc.get(t), dict) and k in doc[t]]
    if not old and not renamed:
        return text, changes
    out = tomlkit.dumps(edited)
    after = tomllib.loads(out)
    left = [f"[{t}] {k}" for t, k in [*(("estimation", k) for k in old), *renamed] if k in (after.get(t) or {})]
    if left:  # never report a rewrite that was not made
        raise ConfigError(f"{where}: cannot rewrite {', '.join(left)}: edit it by hand as the changelog says")
    return out, changes


def _replace(table, keys: list[str], new_key: str | None, value) -> None:
    """``table`` (a table or an inline table of a tomlkit document) without ``keys``, and ``new_key = value`` in it
    (at its end; nothing where ``new_key`` is None)."""
    for k in keys:
        del table[k]
    if new_key is not None:
        table[new_key] = value


def _toml(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, list):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    return str(value)
