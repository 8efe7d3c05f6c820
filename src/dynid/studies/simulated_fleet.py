"""Simulated fleets and service lives, written as ordinary logs: for ``dynid fleet`` and ``dynid monitor``'s tests,
demos and benchmarks.

A fleet is ``units`` arms of one model. Each unit differs from the description by its friction (Coulomb and
viscous, each joint within ±``friction_spread``), a permanently mounted tool (a point mass up to ``payload_max`` kg
on the flange) and, for one chosen unit, one drive gain off by ``gain_error`` (its controller converts currents with
the nominal gain, eq. 16, while the motor's is different). Every log is a CSV of time, positions and motor currents,
simulated by :func:`dynid.simulation.measurements.simulate_measurements` (Pinocchio's RNEA with the unit's truth,
quantised encoders, current noise) on a random Fourier excitation (eq. 14) of its own.

A service life is one unit's dated logs over weeks while one joint's viscous and Coulomb friction rise.
"""

from __future__ import annotations

import datetime
import json
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .._util.keywords import seed_of
from ..exceptions import ConfigError
from ..excitation.fourier import FourierTrajectory
from ..model.description import load_robot
from ..model.robot import Robot
from ..simulation.measurements import NoiseModel, simulate_measurements

__all__ = ["NOMINAL_FRICTION", "UnitTruth", "simulate_fleet", "simulate_service_life", "random_excitation",
           "unit_robot"]

TOOL_COM = (0.0, 0.0, 0.05)
"""Where each simulated unit's tool sits: its centre of mass in the last link's frame [m] (the manifest states it)."""

NOMINAL_FRICTION = {
    "ur10e": ((9.0, 9.0, 7.0, 2.5, 2.5, 2.5), (6.0, 6.0, 4.0, 1.2, 1.2, 1.2)),
    "tx40": ((7.14, 8.26, 6.34, 2.48, 3.03, 0.282), (8.05, 5.53, 1.97, 1.11, 1.86, 0.65)),
}
"""Coulomb [N·m] and viscous [N·m·s/rad] friction per joint of the simulated units (the built-in descriptions carry
none): for the UR10e, typical of an arm of its size; for the TX40, FIGAROH's values identified on the real robot
(configs/robots/tx40_simulation.toml). The logs are written joint side, with the description's drive gains and its
position offsets taken off the angles (the TX40's joints 2-3), as an encoder reads them."""


@dataclass(frozen=True)
class UnitTruth:
    """What makes one simulated unit differ from the description.

    Attributes
    ----------
    id : str
    coulomb : (n_dof,) array [N·m]
    viscous : (n_dof,) array [N·m·s/rad]
    payload : float [kg]
        Point mass 0.05 m along the flange's z axis.
    gain_factor : (n_dof,) array
        The motors' true drive gains over the nominal ones the controller uses.
    """

    id: str
    coulomb: np.ndarray
    viscous: np.ndarray
    payload: float = 0.0
    gain_factor: np.ndarray = field(default_factory=lambda: np.ones(0))

    def to_dict(self) -> dict:
        """JSON-ready truth.

        Returns
        -------
        dict
        """
        return {"id": self.id, "coulomb": self.coulomb.tolist(), "viscous": self.viscous.tolist(),
                "payload_kg": self.payload, "gain_factor": self.gain_factor.tolist()}


def unit_robot(robot: Robot, truth: UnitTruth) -> Robot:
    """The robot a unit is: the description with the unit's friction and tool (the drive gains stay nominal).

    Parameters
    ----------
    robot : Robot
        A description with ``fc`` and ``fv`` drive terms.
    truth : UnitTruth

    Returns
    -------
    Robot
        The unit: the description's links, the unit's friction and tool.

    Raises
    ------
    ConfigError
        A description without Coulomb and viscous friction terms.
    """
    terms = robot.drive_terms
    if "fc" not in terms or "fv" not in terms:
        raise ConfigError(f"{robot.name}: a simulated unit needs the drive terms fc and fv, the description has {terms}")
    drive = robot.drive.copy()
    drive[:, terms.index("fc")] = truth.coulomb
    drive[:, terms.index("fv")] = truth.viscous
    inertial = robot.inertial.copy()
    if truth.payload > 0:  # a point mass m at c in the last link's frame: first and second moments about its origin
        c, m = np.array(TOOL_COM), truth.payload
        second = m * (c @ c * np.eye(3) - np.outer(c, c))
        inertial[-1, :6] += second[[0, 0, 0, 1, 1, 2], [0, 1, 2, 1, 2, 2]]
        inertial[-1, 6:9] += m * c
        inertial[-1, 9] += m
    return replace(robot, drive=drive, inertial=inertial)


def random_excitation(robot: Robot, rng: np.random.Generator, harmonics: int = 5, pulsation: float = 2 * np.pi * 0.1,
                      share: float = 0.6) -> FourierTrajectory:
    """A random Fourier excitation (eq. 14) within ``share`` of each joint's range and 80 % of its speed limit.

    Parameters
    ----------
    robot : Robot
    rng : numpy.random.Generator
    harmonics : int
    pulsation : float [rad/s]
        The fundamental pulsation ω_f.
    share : float
        Share of each joint's range (limited to ±π) the motion spans at most.

    Returns
    -------
    FourierTrajectory
    """
    n = robot.n_dof
    lo, hi = np.maximum(robot.limits.q_min, -np.pi), np.minimum(robot.limits.q_max, np.pi)
    k = np.arange(1, harmonics + 1)
    a, b = rng.normal(size=(n, harmonics)) / k, rng.normal(size=(n, harmonics)) / k
    amplitude = np.abs(a).sum(axis=1) + np.abs(b).sum(axis=1)
    speed = pulsation * (np.abs(a) * k + np.abs(b) * k).sum(axis=1)
    scale = np.minimum(share * (hi - lo) / 2 / amplitude, 0.8 * np.minimum(robot.limits.dq_max, 3.0) / speed)
    return FourierTrajectory(pulsation, (lo + hi) / 2, a * scale[:, None], b * scale[:, None])


def _write_log(path: Path, robot: Robot, truth_robot: Robot, gains: np.ndarray, trajectory: FourierTrajectory,
               seconds: float, rate: float, noise: NoiseModel, rng: np.random.Generator, t0: float = 0.0) -> None:
    """One CSV log ``t, q1..qn, i1..in`` of a unit running ``trajectory`` (its motors' true ``gains``)."""
    t = np.arange(int(round(seconds * rate))) / rate
    q, dq, ddq = trajectory.evaluate(t + t0)
    meas = simulate_measurements(replace(truth_robot, drive_gains=gains), t, q, dq, ddq, noise, rng)
    n = robot.n_dof
    header = ",".join(["t"] + [f"q{j + 1}" for j in range(n)] + [f"i{j + 1}" for j in range(n)])
    path.parent.mkdir(parents=True, exist_ok=True)
    logged = robot.transmission.logged_positions(meas.q)  # a reader adds the position offsets back
    np.savetxt(path, np.column_stack([t, logged, meas.current]), delimiter=",", header=header, comments="", fmt="%.9g")


def _columns(n: int) -> str:
    q = ", ".join(f'"q{j + 1}"' for j in range(n))
    i = ", ".join(f'"i{j + 1}"' for j in range(n))
    return f'header = true\ntime = {{ column = "t" }}\npositions = {{ columns = [{q}] }}\ncurrents = {{ columns = [{i}] }}\n'


def _nominal_friction(robot: Robot, name: str) -> tuple[np.ndarray, np.ndarray]:
    if name not in NOMINAL_FRICTION:
        raise ConfigError(f"robot: simulated fleets exist for {', '.join(NOMINAL_FRICTION)}, got {name!r}", field="robot")
    fc, fv = NOMINAL_FRICTION[name]
    return np.array(fc[:robot.n_dof]), np.array(fv[:robot.n_dof])


def simulate_fleet(folder: str | Path, robot: str = "ur10e", units: int = 6, *, seconds: float = 30.0,
                   rate: float = 250.0, validation_seconds: float = 20.0, friction_spread: float = 0.2,
                   payload_max: float = 2.0, odd_unit: int | None = 2, odd_joint: int = 2, gain_error: float = 0.05,
                   calibration_payload: float = 5.0, noise: NoiseModel = NoiseModel(),
                   validation_noise: NoiseModel | None = None, calibration: bool = True, rng=0) -> list[UnitTruth]:
    """Write a simulated fleet: its manifest ``fleet.toml``, the unit config template ``unit.toml``, each unit's logs
    and ``truth.json``.

    Each unit has an identification log (``seconds``), a validation log (``validation_seconds``) on another
    excitation, and the two drive-gain runs (without and with a calibration payload of known mass).

    Parameters
    ----------
    folder : path
        Created if missing.
    robot : {"ur10e", "tx40"}
        Built-in robot the units are (the TX40 with its coupled wrist).
    units : int
    seconds, validation_seconds : float [s]
    rate : float [Hz]
    friction_spread : float
        Each unit's Coulomb and viscous friction: nominal × (1 + uniform(±spread)).
    payload_max : float [kg]
        Each unit's tool: uniform(0, payload_max).
    odd_unit : int or None
        The unit (0-based) whose joint ``odd_joint`` (1-based) has a drive gain off by ``gain_error`` (None: none).
    odd_joint : int
    gain_error : float
        Relative error of the odd unit's drive gain.
    calibration_payload : float [kg]
        Mass of the payload of the drive-gain runs (``[drive_gains]`` of the template).
    noise : NoiseModel
    validation_noise : NoiseModel, optional
        Of the validation logs (default ``noise``); without current noise, a validation error is the model's alone.
    calibration : bool
        Write the drive-gain runs (and ``[drive_gains]`` in the template).
    rng : int or numpy.random.Generator
        Seeds the units, their logs and noise (a generator gives one draw as the seed).

    Returns
    -------
    list of UnitTruth

    Raises
    ------
    ConfigError
        An unknown robot or an odd unit outside the fleet.
    """
    folder = Path(folder)
    nominal = load_robot(robot)
    n = nominal.n_dof
    fc, fv = _nominal_friction(nominal, robot)
    if odd_unit is not None and not (0 <= odd_unit < units and 1 <= odd_joint <= n):
        raise ConfigError(f"odd_unit {odd_unit} / odd_joint {odd_joint}: outside a fleet of {units} units of {n} joints")
    seed = seed_of(rng)
    rng = np.random.default_rng(seed)
    truths = []
    lines = [f'name = "simulated {robot} fleet of {units} units (seed {seed})"', 'template = "unit.toml"', ""]
    for u in range(units):
        uid = f"r{u + 1:02d}"
        factor = np.ones(n)
        if u == odd_unit:
            factor[odd_joint - 1] += gain_error
        truth = UnitTruth(uid, fc * (1 + rng.uniform(-friction_spread, friction_spread, n)),
                          fv * (1 + rng.uniform(-friction_spread, friction_spread, n)),
                          float(rng.uniform(0.0, payload_max)), factor)
        truths.append(truth)
        real = unit_robot(nominal, truth)
        gains = nominal.drive_gains * factor
        unit_rng = np.random.default_rng([seed, u])
        _write_log(folder / uid / "identification.csv", nominal, real, gains, random_excitation(nominal, unit_rng), seconds,
                   rate, noise, unit_rng)
        _write_log(folder / uid / "validation.csv", nominal, real, gains, random_excitation(nominal, unit_rng),
                   validation_seconds, rate, noise if validation_noise is None else validation_noise, unit_rng)
        lines += ["[[units]]", f'id = "{uid}"', f'identification = "{uid}/identification.csv"',
                  f'validation = ["{uid}/validation.csv"]']
        if calibration:
            runs = random_excitation(nominal, unit_rng)
            loaded = unit_robot(nominal, replace(truth, payload=truth.payload + calibration_payload))
            _write_log(folder / uid / "unloaded.csv", nominal, real, gains, runs, seconds, rate, noise, unit_rng)
            _write_log(folder / uid / "loaded.csv", nominal, loaded, gains, runs, seconds, rate, noise, unit_rng)
            lines.append(f'drive_gains = {{ unloaded = "{uid}/unloaded.csv", loaded = "{uid}/loaded.csv" }}')
        lines += [f"payload = {truth.payload:.3f}", f"payload_com = {list(TOOL_COM)}", ""]
    (folder / "fleet.toml").write_text("\n".join(lines))
    (folder / "unit.toml").write_text(
        f'# What every unit of the fleet shares: the robot, the logs\' columns, the estimators.\nrobot = "{robot}"\n\n'
        f"[identification]\n{_columns(n)}\n[[validation]]\nname = \"validation\"\n{_columns(n)}\n"
        '[estimation]\nestimators = ["wls"]\nfriction = "description"\n\n'
        + (f"[drive_gains]\npayload_mass = {calibration_payload}\n[drive_gains.unloaded]\n{_columns(n)}"
           f"[drive_gains.loaded]\n{_columns(n)}" if calibration else ""))
    (folder / "truth.json").write_text(json.dumps({"robot": robot, "seed": seed, "units": [t.to_dict() for t in truths]},
                                                  indent=1))
    return truths


def simulate_service_life(folder: str | Path, robot: str = "ur10e", *, days: int = 28, logs_per_day: int = 1,
                          seconds: float = 60.0, rate: float = 250.0, wear_joint: int = 3, wear_start_day: float = 14.0,
                          wear_per_day: float = 0.02, step: float = 0.0, coulomb: bool = True,
                          noise: NoiseModel = NoiseModel(), rng=0) -> UnitTruth:
    """Write one unit's dated logs (``YYYY-MM-DDTHH-MM.csv``, from 2026-01-01) while a joint wears: from
    ``wear_start_day`` on, its viscous (and Coulomb) friction is ``1 + step + wear_per_day · days`` times its own.

    Every log runs the same excitation (a task repeated), with fresh noise; ``reference.csv`` is a longer log of the
    unworn unit for the full identification.

    Parameters
    ----------
    folder : path
    robot : {"ur10e", "tx40"}
    days, logs_per_day : int
    seconds : float [s]
        Length of each log.
    rate : float [Hz]
    wear_joint : int
        1-based.
    wear_start_day, wear_per_day : float
    step : float
        Relative rise at ``wear_start_day`` (a sudden change).
    coulomb : bool
        The Coulomb friction rises with the viscous one.
    noise : NoiseModel
    rng : int or numpy.random.Generator
        Seeds the logs and noise (a generator gives one draw as the seed).

    Returns
    -------
    UnitTruth
        The unworn unit.
    """
    folder = Path(folder)
    nominal = load_robot(robot)
    fc, fv = _nominal_friction(nominal, robot)
    truth = UnitTruth("unit", fc, fv, 0.0, np.ones(nominal.n_dof))
    seed = seed_of(rng)
    rng = np.random.default_rng(seed)
    task = random_excitation(nominal, rng)
    _write_log(folder / "reference.csv", nominal, unit_robot(nominal, truth), nominal.drive_gains,
               random_excitation(nominal, rng), 4 * seconds, rate, noise, rng)
    start = datetime.datetime(2026, 1, 1)
    history = []
    for k in range(days * logs_per_day):
        day = k / logs_per_day
        rise = 1.0 + (step + wear_per_day * (day - wear_start_day) if day >= wear_start_day else 0.0)
        worn = replace(truth, coulomb=truth.coulomb.copy(), viscous=truth.viscous.copy())
        worn.coulomb[wear_joint - 1] *= rise if coulomb else 1.0
        worn.viscous[wear_joint - 1] *= rise
        stamp = start + datetime.timedelta(days=day)
        _write_log(folder / "logs" / f"{stamp:%Y-%m-%dT%H-%M}.csv", nominal, unit_robot(nominal, worn), nominal.drive_gains,
                   task, seconds, rate, noise, rng)
        history.append({"log": f"{stamp:%Y-%m-%dT%H-%M}.csv", "day": day, "friction_factor": rise})
    (folder / "unit.toml").write_text(f'robot = "{robot}"\n\n[identification]\nfile = "reference.csv"\n{_columns(nominal.n_dof)}'
                                      '\n[estimation]\nestimators = ["wls"]\nfriction = "description"\n')
    (folder / "truth.json").write_text(json.dumps({"robot": robot, "wear_joint": wear_joint, "wear_start_day": wear_start_day,
                                                   "wear_per_day": wear_per_day, "step": step, "coulomb": coulomb,
                                                   "unit": truth.to_dict(),
                                                   "logs": history}, indent=1))
    return truth
