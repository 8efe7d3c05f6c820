"""Fleet manifests of ``dynid fleet`` (TOML): the units of one robot model and their logs; parsing only
(:mod:`dynid.fleet.identification` runs them).

Layout (logs relative to the manifest; the template relative to it too)::

    name = "line 3"
    template = "unit.toml"        # an identify config every unit shares: robot, the logs' column maps, estimators,
                                  # preprocessing, [drive_gains] payload; its own files are replaced by each unit's

    [[units]]
    id = "r01"                                      # letters, digits, _ - . : the unit's output folder
    identification = "r01/identification.csv"      # read with the template's [identification] column map
    validation = ["r01/validation.csv"]            # read with the template's first [[validation]] map
    drive_gains = { unloaded = "r01/unloaded.csv", loaded = "r01/loaded.csv" }   # the template has [drive_gains]
    payload = 1.2                                  # kg, the unit's tool: taken out of its estimate before the fleet
    payload_com = [0.0, 0.0, 0.05]                 # compares and pools (a point mass; m, in the last link's frame,
                                                   # default the description's tool frame)
    date = 2026-11-01                              # when the logs were recorded

    [[units]]
    id = "r02"
    config = "r02/identify.toml"                    # or: the unit's own identify config
"""

from __future__ import annotations

import copy
import datetime
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..._util.typed import convert
from ...exceptions import ConfigError
from ...model.spatial import inertial_from_physical
from .config_types import FleetDocument, UnitTable
from .configs import read_config
from .identification_config import IdentificationConfig, config_from_document, load_identification_config

__all__ = ["FleetUnit", "FleetManifest", "load_fleet_manifest"]


@dataclass(frozen=True)
class FleetUnit:
    """One unit of a fleet.

    Attributes
    ----------
    id : str
    config : IdentificationConfig
        Its identification, as ``dynid identify`` would run it.
    payload : float or None [kg]
    date : datetime.date or None
    payload_com : (3,) array or None [m]
        The tool's centre of mass in the last link's frame (None: the description's tool frame).
    """

    id: str
    config: IdentificationConfig
    payload: float | None = None
    date: datetime.date | None = None
    payload_com: tuple[float, float, float] | None = None

    def tool_standard(self, robot) -> np.ndarray:
        """The stated tool as standard parameters of ``robot`` (a point mass on the last link; zeros without one).

        Parameters
        ----------
        robot : Robot
            The robot as identified (its parameter layout).

        Returns
        -------
        (n_params,) ndarray
        """
        phi = np.zeros(robot.n_params)
        if self.payload:
            com = np.asarray(self.payload_com if self.payload_com is not None else robot.tool_translation, dtype=float)
            last = (robot.n_dof - 1) * robot.n_params_per_joint
            phi[last:last + 10] = inertial_from_physical(float(self.payload), com, np.zeros((3, 3)))
        return phi


@dataclass(frozen=True)
class FleetManifest:
    """A parsed fleet manifest (module docstring).

    Attributes
    ----------
    path : Path
    name : str
    units : tuple of FleetUnit
    """

    path: Path
    name: str
    units: tuple[FleetUnit, ...]


def _unit_document(template: dict, unit: UnitTable, here: Path, where: str) -> dict:
    """The template's document with the unit's files (absolute: the template's data root does not apply to them)."""
    doc: dict = copy.deepcopy(template)
    if unit.identification is None:
        raise ConfigError(f"{where}: expected identification (a log, read with the template's columns) or config")
    doc["identification"] = {**doc["identification"], "file": str((here / unit.identification).resolve())}
    for key in ("rows", "time_range"):  # the template's rows belong to its own log
        doc["identification"].pop(key, None)
    if unit.validation:
        maps = template.get("validation") or [template["identification"]]
        doc["validation"] = [{**{k: v for k, v in maps[0].items() if k not in ("rows", "time_range")}, "name": Path(f).stem,
                              "file": str((here / f).resolve())} for f in unit.validation]
    else:
        doc.pop("validation", None)
    if unit.drive_gains is not None:
        if "drive_gains" not in template:
            raise ConfigError(f"{where}.drive_gains: the template has no [drive_gains] table (payload mass, column maps)")
        for key in ("unloaded", "loaded"):
            table = {k: v for k, v in template["drive_gains"][key].items() if k not in ("rows", "time_range")}
            doc["drive_gains"][key] = {**table, "file": str((here / getattr(unit.drive_gains, key)).resolve())}
    else:
        doc.pop("drive_gains", None)
    return doc


def load_fleet_manifest(path: str | Path, data_root: str | Path | None = None) -> FleetManifest:
    """Parse a fleet manifest and every unit's config.

    Parameters
    ----------
    path : path of the TOML manifest
    data_root : path, optional
        Data root of units given by their own config (as ``dynid identify --data-root``).

    Returns
    -------
    FleetManifest

    Raises
    ------
    ConfigError
        Unreadable manifest or template, unknown or malformed fields, two units of one id, units of different robots
        (one line naming the manifest, the unit and the field).
    """
    path = Path(path)
    typed = convert(read_config(path, None), FleetDocument, str(path))
    here = path.parent
    template, template_path = None, None
    if typed.template is not None:
        template_path = here / typed.template
        template = read_config(template_path, None)
        if "identification" not in template or not isinstance(template["identification"], dict):
            raise ConfigError(f"{template_path}: a fleet template needs an [identification] table (the logs' columns)")
    units: list[FleetUnit] = []
    seen: dict[str, int] = {}
    for i, u in enumerate(typed.units):
        where = f"{path}: units[{i}] ({u.id})"
        if u.id in seen:
            raise ConfigError(f"{path}: units[{i}].id: {u.id!r} names two units (units[{seen[u.id]}] too); give each its own")
        seen[u.id] = i
        try:
            if u.config is not None:
                config = load_identification_config(here / u.config, data_root=data_root)
            elif template is None or template_path is None:
                raise ConfigError(f"{where}: expected config (the unit's own identify config), or a template in the manifest")
            else:
                config = config_from_document(_unit_document(template, u, here, where), template_path)
        except ConfigError as exc:
            text = str(exc)
            raise ConfigError(text if text.startswith(where) else f"{where}: {text}") from None
        com = None if u.payload_com is None else (float(u.payload_com[0]), float(u.payload_com[1]), float(u.payload_com[2]))
        if com is not None and (not np.all(np.isfinite(com)) or max(abs(x) for x in com) > 10):
            raise ConfigError(f"{where}.payload_com: expected a centre of mass within 10 m of the last link's origin, got "
                              f"{list(com)}")
        units.append(FleetUnit(u.id, config, u.payload, u.date, com))
    models = {(c.config.robot.name, c.config.robot.n_dof) for c in units}
    if len(models) > 1:
        raise ConfigError(f"{path}: units: a fleet is of one robot model, got {sorted(m[0] for m in models)}")
    return FleetManifest(path, typed.name or path.stem, tuple(units))
