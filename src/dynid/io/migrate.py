"""``dynid migrate``: an identify config of an earlier release rewritten for this one, line by line, so that its comments
and layout stay as the user wrote them.

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

import re
import tomllib

from ..exceptions import ConfigError

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
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{where}: invalid TOML ({exc})") from None
    changes: list[str] = []
    est = doc.get("estimation")
    old = [k for k in OLD_ESTIMATION_KEYS if isinstance(est, dict) and k in est]
    if old and isinstance(est, dict):
        from .identification_config import _estimators_from_old

        new = _estimators_from_old(est)
        if "estimators" in est:
            raise ConfigError(f"{where}: [estimation] has both estimators and {', '.join(old)}: keep estimators only")
        text = _replace_keys(text, "estimation", old, f"estimators = {new}")
        said = ", ".join(f"{k} = {_toml(est[k])}" for k in old)
        changes.append(f"[estimation] {said} -> estimators = {new}")
    for (table, key), (new_key, why) in RENAMED.items():
        section = doc.get(table)
        if isinstance(section, dict) and key in section:
            if new_key in section:
                text = _replace_keys(text, table, [key], "")
                changes.append(f"[{table}] {key} = {_toml(section[key])} removed ({new_key} is given): {why}")
            else:
                text = _replace_keys(text, table, [key], f"{new_key} = {_toml(section[key])}")
                changes.append(f"[{table}] {key} = {_toml(section[key])} -> {new_key} = {_toml(section[key])}: its "
                               f"meaning changed: {why}")
    for (table, key), why in CHANGED_MEANINGS.items():
        if isinstance(doc.get(table), dict) and key in doc[table]:
            changes.append(f"[{table}] {key} = {_toml(doc[table][key])}: its meaning changed: {why} (kept as written)")
    return text, changes


def _toml(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, list):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    return str(value)


def _replace_keys(text: str, table: str, keys: list[str], replacement: str) -> str:
    """``text`` with the lines of ``keys`` in ``[table]`` removed (a multi-line array with them) and ``replacement``
    where the first of them stood."""
    lines = text.splitlines(keepends=True)
    out, inside, placed, skipping = [], False, False, False
    key_line = re.compile(rf"^\s*({'|'.join(map(re.escape, keys))})\s*=")
    for line in lines:
        header = re.match(r"^\s*\[+\s*([^\]]+?)\s*\]+", line)
        if header and not skipping:
            inside = header.group(1) == table
        if skipping:
            skipping = "]" not in line.split("#", 1)[0]
            continue
        if inside and key_line.match(line):
            value = line.split("=", 1)[1].split("#", 1)[0]
            skipping = value.count("[") > value.count("]")
            if not placed and replacement:
                comment = line.split("#", 1)[1].rstrip("\n") if "#" in line and len(keys) == 1 else ""
                out.append(replacement + (f"  # {comment.strip()}" if comment else "") + "\n")
                placed = True
            continue
        out.append(line)
    return "".join(out)
