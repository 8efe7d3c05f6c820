"""Robot descriptions in TOML: DH table (modified or standard) or URDF, plus what a URDF does not say.

Layout (all values SI, angles in radians; an angle may be written ``"pi/2"``, ``"-pi"``, ``"3*pi/4"``)::

    name = "er16"
    convention = "modified"        # "modified" (Khalil/Craig) | "standard" | "urdf"
    urdf = "robot.urdf"            # with convention = "urdf", relative to this file
    gravity = [0.0, 0.0, -9.81]    # m/s², base frame
    drive_terms = ["fc", "fv"]     # identified per joint: names of dynid.friction.TERMS (Ia, fc, fv, offset, fst)
    notes = "where the numbers come from"

    [tool]                         # flange in the last link frame (optional)
    translation = [0.0, 0.0, 0.1]

    [transmission]                 # optional; default: joint-side data, no coupling
    gear_ratios = [32, 32, 45, -48, 45, 32]          # motor angle = ratio · joint angle
    coupling = [{motor = 6, joint = 5, ratio = 32}]  # motor 6 also turns with joint 5 (coupled wrist)
    coupled_terms = ["Iam", "fvm", "fcm"]            # identified per coupled motor

    [[joints]]                     # one table per joint, base to tip
    name = "joint1"
    alpha = "pi"                   # DH: alpha (alpha_{i-1} for modified), a, d, theta_offset
    a = 0.0
    d = 0.0
    theta_offset = 0.0
    q_min = -2.9                   # rad
    q_max = 2.9
    dq_max = 3.0                   # rad/s
    ddq_max = 15.0                 # rad/s²
    tau_max = 800.0                # N·m
    drive_gain = 20.0              # N·m/A, eq. 16: joint torque per measured current
    drive_terms = ["fv"]           # optional: this joint has only these of the robot's drive terms
    counterbalance = true          # optional: a weight counterbalance (spring, hydraulic cylinder) acts on this
                                   # joint: its torque, a smooth function of the angle, is identified too
    position_offset = "-pi/2"      # optional: added to measured angles to get the model's angles
    mass = 60.0                    # kg (DH conventions; a URDF brings its own)
    com = [0.0, 0.0, -0.1]         # m, link frame (standard DH: DH frame i)
    inertia = [2.0, 2.0, 1.5, 0.0, 0.0, 0.0]   # about the COM: Ixx, Iyy, Izz, Ixy, Ixz, Iyz
    fc = 8.0                       # one value per drive term
    fv = 5.0
    stribeck_velocity = 0.01       # rad/s, for the Stribeck term fst (default 0.01)

    [payload]                      # optional: a load carried by the last link (nominal values; identified
    mass = 151.0                   # with the last link's parameters), kg
    com = [0.0, 0.0, 0.1]          # m, in the last link's frame (DH conventions: as com)
    inertia = [0, 0, 0, 0, 0, 0]   # kg·m² about its centre of mass: Ixx, Iyy, Izz, Ixy, Ixz, Iyz (default 0)
"""

from __future__ import annotations

import re
import tomllib
from importlib import resources
from pathlib import Path

import numpy as np

from ..conventions import COUPLING_TERMS, DEFAULT_DRIVE_TERMS
from ..friction import COUNTERBALANCE_TERMS, DEFAULT_STRIBECK_VELOCITY, check_terms
from ..exceptions import ConfigError
from .dh import joints_from_modified_dh, joints_from_standard_dh, standard_dh_link_offset
from .robot import Limits, Robot
from .transmission import Transmission
from .spatial import inertial_from_physical, physical_problems, transform_inertial

_ANGLE = re.compile(r"^\s*([+-]?)\s*(\d*\.?\d*)\s*\*?\s*pi\s*(?:/\s*(\d+\.?\d*))?\s*$")


def builtin_robots() -> list[str]:
    """Names of the robots shipped with dynid."""
    folder = resources.files("dynid.model") / "robots"
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def load_robot(name_or_path: str | Path) -> Robot:
    """A built-in robot by name (``"er16"``) or a robot description TOML file.

    Raises
    ------
    ConfigError
        Unknown robot, unreadable file, or a field with a wrong type or value (the message names the
        file and the field).
    """
    text = str(name_or_path)
    if text in builtin_robots():
        res = resources.files("dynid.model") / "robots" / f"{text}.toml"
        return robot_from_toml_text(res.read_text(encoding="utf-8"), source=f"built-in robot {text}", base=Path(str(res)).parent)
    path = Path(text)
    if path.suffix == ".urdf" and path.is_file():
        return robot_from_urdf(path)
    if not path.suffix == ".toml" or not path.is_file():
        raise ConfigError(f"unknown robot {text!r}: expected a built-in robot ({', '.join(builtin_robots())}), a .toml "
                          "description file or a .urdf file")
    return robot_from_toml_text(path.read_text(encoding="utf-8"), source=str(path), base=path.parent)


def parse_angle(value, where: str) -> float:
    """A number, or an angle written like ``"pi/2"``, ``"-pi"``, ``"3*pi/4"`` [rad]; ``where`` names the field in errors."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    if isinstance(value, str):
        m = _ANGLE.match(value)
        if m:
            sign = -1.0 if m.group(1) == "-" else 1.0
            num = float(m.group(2)) if m.group(2) not in ("", ".") else 1.0
            den = float(m.group(3)) if m.group(3) else 1.0
            return sign * num * np.pi / den
    raise ConfigError(f"{where}: expected a number or an angle like 'pi/2', got {value!r}")


def _number(table: dict, key: str, where: str, default=None) -> float:
    if key not in table:
        if default is None:
            raise ConfigError(f"{where}: missing field {key!r}")
        return float(default)
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(f"{where}.{key}: expected a number, got {value!r}")
    return float(value)


def _vector(table: dict, key: str, n: int, where: str, default=None) -> np.ndarray:
    if key not in table:
        if default is None:
            raise ConfigError(f"{where}: missing field {key!r}")
        return np.asarray(default, dtype=float)
    value = table[key]
    if not isinstance(value, list) or len(value) != n or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
        raise ConfigError(f"{where}.{key}: expected a list of {n} numbers, got {value!r}")
    return np.asarray(value, dtype=float)


TOP_FIELDS = {"name", "convention", "urdf", "gravity", "drive_terms", "notes", "tool", "transmission", "joints", "payload"}
"""The fields of a robot description."""

JOINT_FIELDS = {"name", "alpha", "a", "d", "theta_offset", "q_min", "q_max", "dq_max", "ddq_max", "tau_max", "drive_gain",
                "drive_terms", "position_offset", "mass", "com", "inertia", "stribeck_velocity", "counterbalance"}
"""The fields of a ``[[joints]]`` table (and one per drive term: its nominal value)."""

URDF_DRIVE_TERMS = ("Ia", "fc", "fv", "offset")
"""Drive terms of a robot given by its URDF alone: what a geared arm with current or torque sensing needs."""


def robot_from_toml_text(text: str, source: str, base: Path | None) -> Robot:
    """Parse a robot description (see the module docstring for the layout)."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{source}: invalid TOML ({exc})") from None
    return robot_from_document(doc, source, base)


def robot_from_urdf(path: str | Path, source: str | None = None) -> Robot:
    """A robot given by its URDF alone: its chain, inertias and limits; drive terms :data:`URDF_DRIVE_TERMS`,
    gravity along -z, drive gains 1 (a log of joint torques)."""
    path = Path(path)
    return robot_from_document({"convention": "urdf", "urdf": str(path), "drive_terms": list(URDF_DRIVE_TERMS),
                                "name": path.stem}, source or str(path), path.parent)


def robot_from_document(doc: dict, source: str, base: Path | None) -> Robot:
    """A robot from a parsed description (the module docstring's layout; a table of a config alike). With
    ``convention = "urdf"`` the ``[[joints]]`` tables are optional: the URDF gives the chain, inertias and limits.

    Raises
    ------
    ConfigError
        Names the file (``source``) and the field.
    """
    if not isinstance(doc, dict):
        raise ConfigError(f"{source}: expected a robot description table")
    unknown = sorted(set(doc) - TOP_FIELDS)
    if unknown:
        raise ConfigError(f"{source}: unknown field(s) {unknown}, expected some of {sorted(TOP_FIELDS)}")
    name = doc.get("name", Path(source).stem)
    convention = doc.get("convention", "urdf" if "urdf" in doc else "modified")
    if convention not in ("modified", "standard", "urdf"):
        raise ConfigError(f"{source}: convention: expected 'modified', 'standard' or 'urdf', got {convention!r}")
    terms = doc.get("drive_terms", DEFAULT_DRIVE_TERMS)
    if not isinstance(terms, (list, tuple)) or not all(isinstance(t, str) for t in terms):
        raise ConfigError(f"{source}: drive_terms: expected a list of term names, got {terms!r}")
    try:
        terms = check_terms(terms, f"{source}: drive_terms")
    except ValueError as exc:
        raise ConfigError(str(exc)) from None
    urdf_model = None
    if convention == "urdf":
        from .urdf import joints_from_urdf, urdf_limits

        if "urdf" not in doc or not isinstance(doc["urdf"], str):
            raise ConfigError(f"{source}: convention 'urdf' needs a field 'urdf' with the file path")
        upath = Path(doc["urdf"])
        if not upath.is_absolute() and base is not None:
            upath = base / upath
        urdf_model = joints_from_urdf(upath)
        if "joints" not in doc:
            doc = {**doc, "joints": [{} for _ in urdf_model[0]]}
    rows = doc.get("joints")
    if not isinstance(rows, list) or not rows or not all(isinstance(r, dict) for r in rows):
        raise ConfigError(f"{source}: expected one or more [[joints]] tables")
    n = len(rows)
    where = [f"{source}: joints[{i}]" for i in range(n)]
    for r, w in zip(rows, where):
        bad = sorted(set(r) - JOINT_FIELDS - set(terms))
        if bad:
            raise ConfigError(f"{w}: unknown field(s) {bad}, expected some of {sorted(JOINT_FIELDS | set(terms))}")
    names = [str(r.get("name", f"joint{i + 1}")) for i, r in enumerate(rows)]

    tool = doc.get("tool", {})
    tool_t = _vector(tool, "translation", 3, f"{source}: tool", default=[0.0, 0.0, 0.0])
    tool_r = np.eye(3)

    alpha = a = d = None
    urdf_lim = None
    if convention == "urdf":
        joints, inertial, _ = urdf_model
        urdf_lim = urdf_limits(upath)
        if len(joints) != n:
            raise ConfigError(f"{source}: {upath} has {len(joints)} revolute joints but {n} [[joints]] tables are given")
    else:
        alpha = [parse_angle(r.get("alpha", 0.0), f"{w}.alpha") for r, w in zip(rows, where)]
        a = [_number(r, "a", w, 0.0) for r, w in zip(rows, where)]
        d = [_number(r, "d", w, 0.0) for r, w in zip(rows, where)]
        off = [parse_angle(r.get("theta_offset", 0.0), f"{w}.theta_offset") for r, w in zip(rows, where)]
        if convention == "modified":
            joints = joints_from_modified_dh(alpha, a, d, off, names)
        else:
            joints, tool_r0, tool_t0 = joints_from_standard_dh(alpha, a, d, off, names)
            tool_t = tool_t0 + tool_r0 @ tool_t
            tool_r = tool_r0
        inertial = np.zeros((n, 10))
        for i, (r, w) in enumerate(zip(rows, where)):
            mass = _number(r, "mass", w)
            com = _vector(r, "com", 3, w)
            ixx, iyy, izz, ixy, ixz, iyz = _vector(r, "inertia", 6, w)
            inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
            if not np.isfinite(mass) or mass < 0:
                raise ConfigError(f"{w}.mass: expected a mass >= 0 (kg), got {mass}")
            phi = inertial_from_physical(mass, com, inertia)
            if convention == "standard":  # given in DH frame i: express in dynid's link frame
                rr, pp = standard_dh_link_offset(alpha[i], a[i], d[i])
                phi = transform_inertial(phi, rr, pp)
            inertial[i] = phi

    balanced = [j for j, (r, w) in enumerate(zip(rows, where)) if _flag(r, "counterbalance", w)]
    if balanced:
        terms = check_terms(tuple(terms) + COUNTERBALANCE_TERMS, source)
    mask = np.ones((n, len(terms)), dtype=bool)
    for j in range(n):  # the counterbalance terms belong to the joints that have one
        mask[j] = [t not in COUNTERBALANCE_TERMS or j in balanced for t in terms]
    for i, (r, w) in enumerate(zip(rows, where)):
        if "drive_terms" in r:
            own = r["drive_terms"]
            if not isinstance(own, list) or any(t not in terms for t in own):
                raise ConfigError(f"{w}.drive_terms: expected a list drawn from the robot's drive terms {list(terms)}, got {own!r}")
            mask[i] = [t in own or (t in COUNTERBALANCE_TERMS and i in balanced) for t in terms]
    drive = np.array([[_number(r, t, w, 0.0) for t in terms] for r, w in zip(rows, where)]).reshape(n, len(terms)) * mask
    offsets = np.array([parse_angle(r.get("position_offset", 0.0), f"{w}.position_offset") for r, w in zip(rows, where)])
    transmission = _transmission(doc.get("transmission", {}), n, offsets, source)
    gains = np.array([_number(r, "drive_gain", w, 1.0) for r, w in zip(rows, where)])
    if np.any(gains <= 0):
        i = int(np.argmax(gains <= 0))
        raise ConfigError(f"{where[i]}.drive_gain: expected a positive gain (N·m/A), got {gains[i]}")
    inf = np.inf
    default = (lambda k, j, d: d) if urdf_lim is None else (lambda k, j, d: urdf_lim[k][j])  # noqa: E731
    lim = {k: np.array([_number(r, k, w, default(k, j, dflt)) for j, (r, w) in enumerate(zip(rows, where))])
           for k, dflt in (("dq_max", inf), ("ddq_max", inf), ("tau_max", inf))}
    for k, dflt in (("q_min", -inf), ("q_max", inf)):  # angles may be written like "-2*pi"
        lim[k] = np.array([parse_angle(r.get(k, default(k, j, dflt)), f"{w}.{k}") for j, (r, w) in enumerate(zip(rows, where))])
    for i in range(n):
        if not lim["q_min"][i] < lim["q_max"][i]:
            raise ConfigError(f"{where[i]}: expected q_min < q_max, got {lim['q_min'][i]} >= {lim['q_max'][i]}")
        for k in ("dq_max", "ddq_max", "tau_max"):
            if not lim[k][i] > 0:
                raise ConfigError(f"{where[i]}.{k}: expected a positive limit, got {lim[k][i]}")
    gravity = _vector(doc, "gravity", 3, source, default=[0.0, 0.0, -9.81])
    if "payload" in doc:
        inertial = inertial.copy()
        inertial[-1] = inertial[-1] + _payload(doc["payload"], f"{source}: payload", convention, alpha, a, d)
    link_names = [r.get("name", f"joint{i + 1}") for i, r in enumerate(rows)]
    problems = tuple(f"{source}: link {i + 1} ({link_names[i]}): nominal {p}" for i in range(n)
                     for p in physical_problems(inertial[i]))
    return Robot(
        name=str(name), joints=joints, gravity=gravity, inertial=inertial, drive_terms=terms, drive=drive,
        drive_gains=gains, limits=Limits(**lim), tool_rotation=tool_r, tool_translation=tool_t,
        notes=str(doc.get("notes", "")), transmission=transmission, drive_mask=mask, nominal_problems=problems,
        stribeck_velocity=_positive([_number(r, "stribeck_velocity", w, DEFAULT_STRIBECK_VELOCITY) for r, w in zip(rows, where)],
                                    [f"{w}.stribeck_velocity" for w in where]),
    )


def _flag(table: dict, key: str, where: str) -> bool:
    value = table.get(key, False)
    if not isinstance(value, bool):
        raise ConfigError(f"{where}.{key}: expected true or false, got {value!r}")
    return value


def _payload(table, where: str, convention: str, alpha, a, d) -> np.ndarray:
    """The payload's inertial parameters in the last link's frame (eq. 5 order)."""
    if not isinstance(table, dict):
        raise ConfigError(f"{where}: expected a table with mass, com (and inertia)")
    unknown = sorted(set(table) - {"mass", "com", "inertia"})
    if unknown:
        raise ConfigError(f"{where}: unknown field(s) {unknown}, expected mass, com, inertia")
    mass = _number(table, "mass", where)
    if not (np.isfinite(mass) and 0 < mass <= 10_000):
        raise ConfigError(f"{where}.mass: expected a mass in (0, 10000] kg, got {mass}")
    com = _vector(table, "com", 3, where)
    if not np.all(np.isfinite(com)) or np.abs(com).max() > 10:
        raise ConfigError(f"{where}.com: expected a centre of mass within 10 m of the last link's origin, got {com.tolist()}")
    ixx, iyy, izz, ixy, ixz, iyz = _vector(table, "inertia", 6, where, default=[0.0] * 6)
    phi = inertial_from_physical(mass, com, np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]))
    if convention == "standard":  # given in DH frame n: in dynid's link frame
        rr, pp = standard_dh_link_offset(alpha[-1], a[-1], d[-1])
        phi = transform_inertial(phi, rr, pp)
    return phi


def _positive(values, fields) -> np.ndarray:
    for v, f in zip(values, fields):
        if not v > 0:
            raise ConfigError(f"{f}: expected a positive velocity (rad/s), got {v}")
    return np.array(values)


def _transmission(table, n: int, offsets: np.ndarray, source: str) -> Transmission:
    where = f"{source}: transmission"
    if not isinstance(table, dict):
        raise ConfigError(f"{where}: expected a table")
    ratios = _vector(table, "gear_ratios", n, where, default=np.ones(n))
    if np.any(ratios == 0):
        raise ConfigError(f"{where}.gear_ratios: expected non-zero ratios, got {ratios.tolist()}")
    r = np.diag(ratios)
    coupling = table.get("coupling", [])
    if not isinstance(coupling, list):
        raise ConfigError(f"{where}.coupling: expected a list of {{motor, joint, ratio}} tables")
    for c, entry in enumerate(coupling):
        w = f"{where}.coupling[{c}]"
        if not isinstance(entry, dict):
            raise ConfigError(f"{w}: expected a table {{motor = 6, joint = 5, ratio = 32}}")
        motor, joint = (int(_number(entry, key, w)) for key in ("motor", "joint"))
        if not (1 <= motor <= n and 1 <= joint <= n) or motor == joint:
            raise ConfigError(f"{w}: expected two different joint numbers in 1..{n}, got motor {motor}, joint {joint}")
        r[motor - 1, joint - 1] = _number(entry, "ratio", w)
    terms = table.get("coupled_terms", list(COUPLING_TERMS) if coupling else [])
    if not isinstance(terms, list) or any(t not in COUPLING_TERMS for t in terms):
        raise ConfigError(f"{where}.coupled_terms: expected a subset of {list(COUPLING_TERMS)}, got {terms!r}")
    return Transmission(r, offsets, tuple(t for t in COUPLING_TERMS if t in terms))
