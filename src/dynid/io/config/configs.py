"""Reading experiment configs (TOML): the file, its top-level fields and the robot it names."""

from __future__ import annotations

import tomllib
from pathlib import Path

from ...exceptions import ConfigError
from ...model.description import builtin_robots, load_robot, robot_from_document
from ...model.robot import Robot
from ..files import text_encoding_hint
from ..logs.bags import BAG_SUFFIXES

LOG_SUFFIXES = (".csv", ".tsv", *BAG_SUFFIXES)
"""File names of logs, which a command given one for its config says how to read (not ``.txt``: a config may be
named so, and its TOML error is what to say)."""


def read_config(path: Path, known: set[str] | None) -> dict:
    """A TOML config, its top-level fields checked.

    Parameters
    ----------
    path : Path
    known : set of str or None
        The top-level fields allowed (None: any; the typed structure checks them).

    Returns
    -------
    dict

    Raises
    ------
    ConfigError
        Missing file, invalid TOML or text, or an unknown top-level field (the message names the file).
    """
    if not path.is_file():
        raise ConfigError(f"{path}: config file not found")
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8-sig"))  # -sig: an editor's byte-order mark
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        if path.suffix.lower() in LOG_SUFFIXES:
            raise ConfigError(f"{path}: a log, not a config (TOML): dynid init ROBOT {path} writes an identification "
                              "config that reads it") from None
        if isinstance(exc, UnicodeDecodeError):
            raise ConfigError(f"{path}: not UTF-8 text{text_encoding_hint(path)}") from None
        raise ConfigError(f"{path}: invalid TOML ({exc})") from None
    unknown = sorted(set(doc) - known) if known is not None else []
    if unknown:
        raise ConfigError(f"{path}: unknown field(s) {unknown}, expected some of {sorted(known or ())}")
    return doc


def robot_source(doc: dict, path: Path, data_root: Path | None = None) -> str:
    """Where a config's robot comes from, for results to find it again.

    Parameters
    ----------
    doc : dict
        The parsed config.
    path : Path
        The config file (relative paths are resolved against its folder).
    data_root : Path, optional
        The data folder, searched second.

    Returns
    -------
    str
        A built-in name, the absolute path of its description or URDF, or ``"config:<absolute path of the config>"``
        for a ``[robot]`` table.
    """
    ref = doc.get("robot")
    if isinstance(ref, dict):
        return f"config:{path.resolve()}"
    if not isinstance(ref, str):
        return ""
    if ref in builtin_robots():
        return ref
    for folder in (path.parent, data_root):
        if folder is not None and (folder / ref).is_file():
            return str((folder / ref).resolve())
    return ref


def config_robot(doc: dict, path: Path, data_root: Path | None = None) -> Robot:
    """The robot of a config's ``robot`` field.

    A built-in name, a description TOML or a URDF (relative to the config, else to the data root), or a ``[robot]``
    table: a description inline (``urdf = "arm.urdf"`` and what a URDF cannot say: ``drive_terms``, ``gravity``,
    ``[robot.transmission]``, ``[robot.payload]``, ``[[robot.joints]]``).

    Parameters
    ----------
    doc : dict
        The parsed config.
    path : Path
        The config file (relative paths are resolved against its folder).
    data_root : Path, optional
        The data folder, searched second.

    Returns
    -------
    Robot
        The config's robot, with what the config adds to a named description.

    Raises
    ------
    ConfigError
        A missing field, or an unknown robot.
    """
    ref = doc.get("robot")
    if isinstance(ref, dict):
        table = dict(ref)
        if isinstance(table.get("urdf"), str) and not (path.parent / table["urdf"]).is_file():
            found = _located(table["urdf"], path.parent, data_root)
            if found is None and not Path(table["urdf"]).is_file():
                raise ConfigError(_not_found(path, "robot.urdf", table["urdf"], data_root), field="robot.urdf")
            table["urdf"] = str(found or table["urdf"])
        table.setdefault("name", Path(str(table.get("urdf", "robot"))).stem)
        return robot_from_document(table, f"{path}: robot", path.parent)
    if not isinstance(ref, str):
        raise ConfigError(f"{path}: expected a field robot = \"name, description.toml or robot.urdf\", or a [robot] table")
    local = None if ref in builtin_robots() else _located(ref, path.parent, data_root)  # relative to the config, else
    if local is not None:                                                               # to the data root
        return load_robot(local)
    if Path(ref).suffix.lower() in (".urdf", ".xacro", ".toml", ".xml", ".mjcf") and not Path(ref).is_file():
        raise ConfigError(_not_found(path, "robot", ref, data_root), field="robot")
    try:
        return load_robot(ref)
    except ConfigError as exc:  # an unknown name: said as the config wrote it, with the config and the field
        raise ConfigError(f"{path}: robot: {exc}") from None


def config_urdf(doc: dict, path: Path, data_root: Path | None = None) -> Path | None:
    """The URDF a config's robot comes from, if it comes from one (for the export to write the values back into it).

    Parameters
    ----------
    doc : dict
        The parsed config.
    path : Path
        The config file.
    data_root : Path, optional
        The data folder, searched second.

    Returns
    -------
    Path or None
        ``robot = "arm.urdf"``, ``[robot] urdf = ...``, or the ``urdf`` of a description file with
        ``convention = "urdf"`` (a xacro file: the URDF it expands to); None for a built-in robot, a DH description or
        a MuJoCo model (:func:`config_mjcf`).
    """
    from ...model.urdf import expand_xacro, is_mjcf, is_xacro

    file, xacro_args = _robot_file(doc, path, data_root)
    if file is None or is_mjcf(file):
        return None
    return expand_xacro(file, xacro_args) if is_xacro(file) else file


def config_mjcf(doc: dict, path: Path, data_root: Path | None = None) -> Path | None:
    """The MuJoCo model (MJCF) a config's robot comes from, if it comes from one (identify and export write the
    identified values into a copy of it, as into a URDF the robot comes from).

    Parameters
    ----------
    doc : dict
        The parsed config.
    path : Path
        The config file.
    data_root : Path, optional
        The data folder, searched second.

    Returns
    -------
    Path or None
        The file of ``robot = "arm.xml"``, ``[robot] urdf = "arm.xml"`` or a description's ``urdf``, where it is an
        MJCF (:func:`dynid.model.urdf.is_mjcf`); None otherwise.
    """
    from ...model.urdf import is_mjcf

    file, _ = _robot_file(doc, path, data_root)
    return file if file is not None and is_mjcf(file) else None


def _robot_file(doc: dict, path: Path, data_root: Path | None) -> tuple[Path | None, dict | None]:
    """The URDF, xacro or MJCF file a config's robot is read from (None: a built-in robot or a DH description), and
    the ``xacro_args`` its ``[robot]`` table or description file gives."""
    from ...model.urdf import is_mjcf, is_xacro

    ref = doc.get("robot")
    if isinstance(ref, dict):
        file = _located(str(ref["urdf"]), path.parent, data_root) if isinstance(ref.get("urdf"), str) else None
        return file, ref.get("xacro_args")
    if not isinstance(ref, str) or ref in builtin_robots():
        return None, None
    file = _located(ref, path.parent, data_root)
    if file is None:
        return None, None
    if file.suffix.lower() == ".urdf" or is_xacro(file) or is_mjcf(file):
        return file, None
    try:
        described = tomllib.loads(file.read_text(encoding="utf-8-sig"))
    except (OSError, ValueError):
        return None, None
    urdf = described.get("urdf")
    if described.get("convention") != "urdf" or not isinstance(urdf, str):
        return None, None
    return _located(urdf, file.parent, None), described.get("xacro_args")


def _not_found(path: Path, field: str, name: str, data_root: Path | None) -> str:
    """The one line saying that a file a config names is nowhere it is looked for (:func:`_located`)."""
    folder = path.parent.resolve()
    root = None if data_root is None else Path(data_root).resolve()
    where = f"in {folder}" + ("" if root is None or root == folder else f" (the config's folder) or {root} (the data root)")
    return f"{path}: {field}: file {name!r} not found {where}"


def _located(name: str, folder: Path, data_root: Path | None) -> Path | None:
    """A file a config names: relative to the config's folder (an absolute path stays as is), else to the data root."""
    for base in (folder, data_root):
        if base is not None and (base / name).is_file():
            return (base / name).resolve()
    return None
