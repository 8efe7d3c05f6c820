"""Published parameter sets (reference values) read from CSV, as base parameters of a robot.

Two formats, declared in the config::

    [[references]]
    name = "Mamedov & Mikhel 2020"
    file = "ur10e_reference_parameters.csv"
    format = "standard"        # one standard parameter per row (names like XX1 or Ixx1, m1, fs1, f01 …)
    header = true
    names = "name"             # column of the names (header name or 1-based number)
    values = "value"           # column of the values

    [[references]]
    name = "FIGAROH OLS"
    file = "reference/TX40_bp_5.csv"
    format = "base"            # one base parameter per row, written as an expression of standard ones
    header = false             # e.g. "Izz1 + 1.0*Ia1 + 0.07*mz3 + 0.05185*m3"
    names = 1
    values = 2
    rel_std = 3                # optional column: relative standard deviation [%]

    [[references]]
    name = "nominal"
    format = "nominal"         # the robot description's own (nominal) values, no file

A standard set is read in dynid's link frames: link ``j``'s frame has its z axis on joint ``j`` (modified
DH, Khalil & Kleinfinger); for a URDF, the frame of the joint that moves link ``j``. For a description in
standard DH, these are not the DH frames ``i`` in which its ``com`` and ``inertia`` are written: convert
such a set first. First moments (MX, MY, MZ) and inertias are about the frame's origin (eq. 5).

A standard set becomes base parameters through the robot's regrouping. A base set is matched row by
row to dynid's base parameters by comparing the expressions' coefficients, so a set computed by
another tool (FIGAROH, SymPyBotics) is checked against dynid's regrouping as it is read.
"""

from __future__ import annotations

import csv
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..._util.reprs import short_repr
from ...conventions import canonical_name, split_name
from ...dynamics.base_parameters import BaseParameters
from ...exceptions import ConfigError, DataError
from ...model.friction_model import COULOMB_LIKE


@short_repr
@dataclass(frozen=True)
class ReferenceSet:
    """A published parameter set expressed as dynid's base parameters.

    Attributes
    ----------
    name : str
    beta : (n_base,) array
    relative_std : (n_base,) array [%] or None
        The publication's relative standard deviations (NaN where not given).
    source : str
    warnings : tuple of str
    """

    name: str
    beta: np.ndarray
    relative_std: np.ndarray | None
    source: str
    warnings: tuple[str, ...] = ()


_TERM = re.compile(r"([+-]?)(?:(\d+\.?\d*(?:[eE][+-]?\d+)?)\*)?([A-Za-z_]\w*)")


def parse_expression(text: str, names: tuple[str, ...], where: str) -> np.ndarray:
    """Coefficients of a linear expression of standard parameters, e.g. ``"Ixx2 - 1.0*Iyy2 - 0.050625*m3"``.

    Names may use the aliases of :func:`dynid.conventions.canonical_name`.

    Parameters
    ----------
    text : str
    names : tuple of str
        The standard parameters' names.
    where : str
        Named in errors.

    Returns
    -------
    (n_params,) ndarray

    Raises
    ------
    DataError
        A term that is not ``[coef*]name`` or names an unknown parameter.
    """
    coef = np.zeros(len(names))
    body = text.replace(" ", "")
    if not body:
        raise DataError(f"{where}: empty expression")
    pos = 0
    while pos < len(body):
        m = _TERM.match(body, pos)
        if not m or (pos > 0 and not m.group(1)):
            raise DataError(f"{where}: cannot read {text!r} from {body[pos:]!r} on, expected terms like '+ 0.5*m3'")
        try:
            name = canonical_name(m.group(3))
        except ValueError as exc:
            raise DataError(f"{where}: {exc}") from None
        if name not in names:
            raise DataError(f"{where}: {text!r} uses {m.group(3)!r} ({name}), which this robot does not have")
        sign = -1.0 if m.group(1) == "-" else 1.0
        coef[names.index(name)] += sign * (float(m.group(2)) if m.group(2) else 1.0)
        pos = m.end()
    return coef


def _column(header: list[str] | None, col, path: Path, key: str) -> int:
    if isinstance(col, int) and not isinstance(col, bool):
        if col < 1:
            raise ConfigError(f"{path}: {key}: column numbers are 1-based, got {col}")
        return col - 1
    if header is None or col not in header:
        raise ConfigError(f"{path}: {key}: no column {col!r} (header: {header})")
    return header.index(col)


def load_reference(table: dict, base: Path, where: str, basep: BaseParameters, nominal=None) -> ReferenceSet:
    """Read a reference set (module docstring) and express it as base parameters.

    Parameters
    ----------
    table : dict
        The ``[[references]]`` table.
    base : Path
        Folder its file is relative to.
    where : str
        The table, named in errors.
    basep : BaseParameters
    nominal : (n_params,) array, optional
        The values of ``format = "nominal"``.

    Returns
    -------
    ReferenceSet

    Raises
    ------
    ConfigError
        Bad config fields (names the field).
    DataError
        Unreadable file, a value that is not a number, a standard set that lacks parameters, a base set whose
        expressions do not determine dynid's base parameters (names file and line).
    """
    if not isinstance(table, dict) or "name" not in table or ("file" not in table and table.get("format") != "nominal"):
        raise ConfigError(f"{where}: expected a table with 'name' and 'file' (or format = \"nominal\")")
    fmt = table.get("format", "standard")
    if fmt not in ("standard", "base", "nominal"):
        raise ConfigError(f"{where}.format: expected 'standard', 'base' or 'nominal', got {fmt!r}")
    if fmt == "nominal":
        if nominal is None:
            raise ConfigError(f"{where}.format: 'nominal' needs the robot's nominal parameters")
        return ReferenceSet(str(table["name"]), basep.base_from_standard(nominal), None, "the robot description's nominal values")
    path = Path(table["file"])
    path = path if path.is_absolute() else base / path
    if not path.is_file():
        raise DataError(f"{path}: reference file not found")
    with open(path, newline="", encoding="utf-8-sig") as fh:
        rows = [r for r in csv.reader(fh) if any(f.strip() for f in r)]
    header = [h.strip() for h in rows.pop(0)] if table.get("header", False) and rows else None
    i_name = _column(header, table.get("names", 1), path, f"{where}.names")
    i_value = _column(header, table.get("values", 2), path, f"{where}.values")
    i_std = _column(header, table["rel_std"], path, f"{where}.rel_std") if "rel_std" in table else None
    first_line = 2 if header is not None else 1
    std_names = basep.standard_names
    warnings = []
    funcs, values, stds = [], [], []
    ignored = []
    first_seen: dict[str, int] = {}
    for k, r in enumerate(rows):
        line = first_line + k
        try:
            name, value = r[i_name].strip(), float(r[i_value])
            std = float(r[i_std]) if i_std is not None else np.nan
        except (IndexError, ValueError):
            raise DataError(f"{path}: line {line}: expected a name and numeric value(s) in the configured columns, got {r}") from None
        if not np.isfinite(value):
            raise DataError(f"{path}: line {line}: {name}'s value is {r[i_value].strip()}: expected a finite number")
        if fmt == "standard":
            try:
                cname = canonical_name(name)
            except ValueError:
                ignored.append(name)
                continue
            if cname not in std_names:
                ignored.append(name)
                continue
            f = np.zeros(len(std_names))
            f[std_names.index(cname)] = 1.0
        else:
            f = parse_expression(name, std_names, f"{path}: line {line}")
            cname = " ".join(name.split())
        if cname in first_seen:
            raise DataError(f"{path}: line {line}: {cname} given twice (line {first_seen[cname]}); keep one")
        first_seen[cname] = line
        funcs.append(f)
        values.append(value)
        stds.append(std)
    ignored = [n for n in ignored if not re.fullmatch(r"K\d+", n)]  # drive gains K1.. beside a parameter set: not parameters
    if ignored:
        warnings.append(f"{path}: rows that are not parameters of this robot were ignored: {', '.join(ignored)}")
    if not funcs:
        raise DataError(f"{path}: no parameters of this robot found")
    v, b, s = np.array(funcs), np.array(values), np.array(stds)
    g = basep.regrouping
    if fmt == "standard":
        given = v.sum(axis=0) > 0
        missing = [std_names[i] for i in np.flatnonzero(~given) if np.any(g[:, i]) and not _friction_like(std_names[i])]
        if missing:
            raise DataError(f"{path}: the reference lacks parameter(s) {', '.join(missing)}")
        phi = np.zeros(len(std_names))
        phi[np.argmax(v, axis=1)] = b
        beta, rel = g @ phi, None
    else:
        beta, rel = _match_base(v, b, s, g, names=basep.names, path=path, std_names=std_names)
    return ReferenceSet(str(table["name"]), beta, rel if i_std is not None else None, str(path), tuple(warnings))


def _friction_like(name: str) -> bool:
    """Whether a standard parameter is a friction term a published model may lack (then it has the value 0 there):
    the Coulomb-like terms of :mod:`dynid.model.friction_model`."""
    return split_name(name)[0] in COULOMB_LIKE[1:]


def _match_base(v, b, s, g, *, names, path, std_names=()):
    """Match each of dynid's base parameters (rows of ``g``) to a row of ``v``; base parameters made only of
    friction terms the reference never mentions (:func:`_friction_like`) are 0 in it."""
    absent = [i for i, row in enumerate(g) if std_names and all(_friction_like(std_names[c]) and not v[:, c].any()
                                                                 for c in np.flatnonzero(row))]
    if absent:
        keep = np.setdiff1d(np.arange(g.shape[0]), absent)
        beta, rel = np.zeros(g.shape[0]), np.full(g.shape[0], np.nan)
        beta[keep], rel[keep] = _match_base(v, b, s, g[keep], names=[names[i] for i in keep], path=path)
        return beta, rel
    beta = np.full(g.shape[0], np.nan)
    rel = np.full(g.shape[0], np.nan)
    for i, row in enumerate(g):
        scale = np.abs(row).max()
        hit = np.flatnonzero(np.all(np.abs(v - row) <= 1e-4 * max(scale, 1.0), axis=1))
        if hit.size:
            beta[i], rel[i] = b[hit[0]], s[hit[0]]
    if np.isnan(beta).any():
        # not the same regrouping: accept if the reference's functionals still determine every base parameter
        phi, *_ = np.linalg.lstsq(v, b, rcond=None)
        proj = g @ np.linalg.pinv(v) @ v
        if np.abs(proj - g).max() > 1e-6 * max(1.0, np.abs(g).max()):
            missing = [names[i] for i in np.flatnonzero(np.isnan(beta))]
            raise DataError(f"{path}: the reference's expressions do not determine the base parameter(s) {', '.join(missing)}")
        beta = g @ phi
    return beta, rel
