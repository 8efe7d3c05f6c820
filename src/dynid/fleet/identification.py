"""``dynid fleet``: every unit of a fleet identified on a Dask cluster, one table of the fleet, the units that stand out
flagged, and every unit's estimate helped by the others' (pooled identification).

Each unit is identified by the standard pipeline (:func:`dynid.identification.run.run_identification`)
in a Dask task that reads its logs where the worker runs: on a :class:`distributed.LocalCluster` of the local cores
by default, or on the cluster of a scheduler's address. A task returns what the fleet needs (the main estimate with
its covariance, the validation errors, the drive gains) and, when given a writer, writes the unit's results as
``dynid identify`` does. The fleet's statistics run on the client: robust z-scores
(:mod:`dynid.fleet.outliers`) and the hierarchical pooled estimate (:mod:`dynid.estimators.pooled`),
which a second round of tasks validates on each unit's validation logs.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .._util.reprs import short_repr
from ..estimators.pooled import PooledEstimate, pooled_estimate, shared_parameters
from ..exceptions import ConfigError, DataError, DynIdError
from ..identification.evidence import validate_sets
from ..identification.run import run_identification
from ..io.config.fleet_manifest import FleetManifest, FleetUnit
from ..io.config.identification_config import stored_preprocessing
from ..io.files import write_json
from ..io.logs.datasets import load_recording
from ..io.results import read_results
from ..runtime.cluster import dask_client
from ..runtime.extras import require
from .outliers import fleet_outliers

__all__ = ["UnitSummary", "FleetResult", "identify_unit", "run_fleet", "add_pooled_estimates"]

POOLED = "pooled"
"""Label of the pooled estimate in the units' validations."""


@short_repr
@dataclass(frozen=True)
class UnitSummary:
    """What the fleet keeps of one unit's identification.

    Attributes
    ----------
    id : str
    date : str or None
        ISO date.
    payload : float or None [kg]
    names : tuple of str
        Base parameters.
    params, std : (n_base,) arrays
        The main estimate (the least-squares one with σ).
    covariance : (n_base, n_base) array
    label : str
        That estimate's label.
    validation_error : float [%]
        Global relative error on the unit's validation logs (their mean); NaN for a unit without validation logs.
    joint_errors : (n_dof,) array [%]
        Each joint's relative error on the validation logs (mean over them).
    consistency : str
        "yes" or "no: why" (:func:`dynid.estimators.physically_consistent.consistency_verdict`).
    gains, gains_std : (n_dof,) arrays or None [N·m/A]
        Drive gains when the unit's config has ``[drive_gains]`` (NaN / inf where not observable).
    seconds : float
        Wall time of the unit's task.
    memory_mb : float
        Peak resident memory of the process that ran it, when it ended [MB] (NaN where unknown).
    error : str
        The one-line message of a unit that failed ("" when it did not); its arrays are then empty.
    files : tuple of str
        What the unit's task wrote.
    model : Robot or None
        The robot as identified (for the pooled estimate's validation; not in the table).
    preprocessing : Preprocessing or None
        The identification's resolved preprocessing, carried over to the validation logs.
    tool : (n_base,) array or None
        The unit's stated tool as base parameters: ``params - tool`` is its arm alone, what the fleet compares and pools.
    warnings : tuple of str
        What the unit's identification warned of (a truncated log, gaps filled, a dead channel...).
    """

    id: str
    date: str | None
    payload: float | None
    names: tuple[str, ...] = ()
    params: np.ndarray = field(default_factory=lambda: np.zeros(0))
    std: np.ndarray = field(default_factory=lambda: np.zeros(0))
    covariance: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    label: str = ""
    validation_error: float = float("nan")
    joint_errors: np.ndarray = field(default_factory=lambda: np.zeros(0))
    consistency: str = ""
    gains: np.ndarray | None = None
    gains_std: np.ndarray | None = None
    seconds: float = 0.0
    memory_mb: float = float("nan")
    error: str = ""
    files: tuple[str, ...] = ()
    model: object = None  # the robot as identified (for the second round's validation); not in the table
    preprocessing: object = None  # the identification's resolved preprocessing, carried over to the validation logs
    tool: np.ndarray | None = None
    warnings: tuple[str, ...] = ()

    @property
    def arm(self) -> np.ndarray:
        """The estimate without the unit's stated tool (:attr:`tool`): what is compared across the fleet."""
        return self.params if self.tool is None else self.params - self.tool


def _peak_memory() -> float:
    """This process's peak resident memory [MB] (NaN where the platform does not say)."""
    try:
        import resource

        kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        return kb / (1024 * 1024) if sys.platform == "darwin" else kb / 1024
    except (ImportError, OSError):
        return float("nan")


def _mean_errors(validations, label: str) -> tuple[float, np.ndarray]:
    metrics = [v.metrics()[label] for v in validations]
    return (float(np.mean([m["global_relative_error"] for m in metrics])),
            np.mean([np.asarray(m["relative_error"], dtype=float) for m in metrics], axis=0))


def identify_unit(unit: FleetUnit, out: str | Path | None = None, save: Callable | None = None) -> UnitSummary:
    """Identify one unit (a Dask task of :func:`run_fleet`; also runs alone).

    Parameters
    ----------
    unit : FleetUnit
    out : path, optional
        The fleet's output folder: the unit's results go to ``out/units/<id>`` through ``save``.
    save : callable, optional
        ``save(result, folder, robot)`` writes a unit's results (e.g. :func:`dynid.report.identification_run
        .save_identification` without figures) and returns the paths.

    Returns
    -------
    UnitSummary
        With ``error`` set (one line) when the unit's data or config fail; nothing is raised for them.
    """
    t0 = time.perf_counter()
    date = None if unit.date is None else unit.date.isoformat()
    try:
        result = run_identification(unit.config, validate=True)
    except DynIdError as exc:
        return UnitSummary(unit.id, date, unit.payload, seconds=time.perf_counter() - t0, error=str(exc))
    label = result.label
    if result.validations:
        err, joints = _mean_errors(result.validations, label)
    else:
        err, joints = float("nan"), np.full(unit.config.robot.n_dof, np.nan)
    gains = gains_std = None
    if result.drive_gains is not None:
        gains, gains_std = result.drive_gains.gains.gains, result.drive_gains.gains.gains_std
    files: tuple[str, ...] = ()
    if save is not None and out is not None:
        files = tuple(str(p) for p in save(result, Path(out) / "units" / unit.id, result.model or unit.config.robot))
    sol = result.solution
    # the least-squares covariance assumes white residuals; the moving-block bootstrap sees their correlation: its σ
    # over the covariance's (median over the parameters) scales the covariance the fleet weighs the unit by
    ratio = float(result.diagnostics.get("bootstrap_over_covariance_std", 1.0) or 1.0)
    scale = max(1.0, ratio if np.isfinite(ratio) else 1.0)
    robot = result.model or unit.config.robot
    tool = result.base.base_from_standard(unit.tool_standard(robot)) if unit.payload else None
    return UnitSummary(unit.id, date, unit.payload, tuple(result.base.names), sol.params, scale * sol.params_std,
                       scale ** 2 * sol.covariance, label,
                       err, joints, str(result.consistency_verdicts.get(label, "")), gains, gains_std,
                       time.perf_counter() - t0, _peak_memory(), "", files, robot,
                       stored_preprocessing({"settings": result.settings}), tool, tuple(result.warnings))


def add_pooled_estimates(out: str | Path, units: tuple[UnitSummary, ...], pooled) -> list[Path]:
    """Write each unit's pooled estimate into its results.json (``out/units/<id>``) as one more estimate, ``"pooled"``,
    beside the unit's own: ``dynid.load_results(...).predict_states(q, dq, ddq, estimate="pooled")`` uses it.

    Parameters
    ----------
    out : path
        The fleet's output folder.
    units : tuple of UnitSummary
        The units pooled, in the order of ``pooled``'s rows.
    pooled : PooledEstimate

    Returns
    -------
    list of Path
        The results files rewritten (atomically; a unit without one is left out).
    """
    written = []
    for i, unit in enumerate(units):
        path = Path(out) / "units" / unit.id / "results.json"
        if not path.is_file():
            continue
        results = read_results(path)
        names = list(unit.names)
        results.setdefault("estimates", {})[POOLED] = {
            "key": POOLED, "values": dict(zip(names, pooled.params[i].tolist())),
            "std": dict(zip(names, pooled.std[i].tolist())), "seconds": 0.0, "n_evaluations": None}
        write_json(path, results)
        written.append(path)
    return written


def validate_unit(unit: FleetUnit, model, sets: dict, preprocessing=None) -> dict:
    """The global validation error [%] of each parameter set on the unit's validation logs (mean over them).

    Parameters
    ----------
    unit : FleetUnit
    model : Robot
        The robot as identified (its friction terms and Coulomb smoothing).
    sets : dict
        label -> (n_base,) base parameters.
    preprocessing : Preprocessing, optional
        The identification's resolved preprocessing.

    Returns
    -------
    dict
        label -> error [%]; empty when the unit has no validation log.
    """
    from ..dynamics.base_parameters import base_parameters

    if not unit.config.validation:
        return {}
    config = replace(unit.config, robot=model)
    logs = (load_recording(spec, model) for spec in config.validation)
    comparisons, _ = validate_sets(config, base_parameters(model, rng=0), sets, logs, resolved=preprocessing)
    return {label: float(np.mean([c.metrics()[label]["global_relative_error"] for c in comparisons])) for label in sets}


@short_repr
@dataclass(frozen=True)
class FleetResult:
    """A fleet's identification.

    Attributes
    ----------
    manifest : FleetManifest
    units : tuple of UnitSummary
    outliers : tuple of Outlier
        Parameters (and drive gains) of units that stand out, largest first.
    threshold : float
        The lowest ``|z|`` flagged (:func:`dynid.fleet.outliers.fleet_outliers`).
    pooled : PooledEstimate or None
        None when fewer than 2 units were identified, or their base parameters differ.
    pooled_errors : dict
        unit id -> global validation error [%] of its pooled estimate.
    pooled_note : str
        Why there is no pooled estimate ("" when there is).
    cluster : str
        The Dask cluster.
    seconds : float
    """

    manifest: FleetManifest
    units: tuple[UnitSummary, ...]
    outliers: tuple = ()
    threshold: float = float("inf")
    pooled: PooledEstimate | None = None
    pooled_errors: dict = field(default_factory=dict)
    pooled_note: str = ""
    cluster: str = ""
    seconds: float = 0.0

    @property
    def identified(self) -> tuple[UnitSummary, ...]:
        """The units that were identified (no error)."""
        return tuple(u for u in self.units if not u.error)

    def flagged(self, unit: str) -> tuple:
        """The outliers of one unit.

        Parameters
        ----------
        unit : str
            Its id.

        Returns
        -------
        tuple of Outlier
        """
        return tuple(o for o in self.outliers if o.unit == unit)

    def table(self) -> dict:
        """The fleet table, one row per unit, as columns (for Parquet and the report).

        Returns
        -------
        dict
            column name -> list: ``unit``, ``date``, ``payload_kg``, ``validation_error_pct``,
            ``pooled_validation_error_pct``, ``worst_joint``, ``consistent``, ``flags``, ``error``, then per joint
            ``fc<j>``, ``fv<j>`` (with ``_std``) and ``K<j>`` (with ``_std``, when drive gains were identified).
        """
        ok = self.identified
        n = ok[0].joint_errors.size if ok else 0
        cols: dict = {"unit": [], "date": [], "payload_kg": [], "validation_error_pct": [], "pooled_validation_error_pct": [],
                      "worst_joint": [], "consistent": [], "flags": [], "error": []}
        friction = [f"{t}{j + 1}" for j in range(n) for t in ("fc", "fv")]
        for name in friction:
            cols[name], cols[name + "_std"] = [], []
        has_gains = any(u.gains is not None for u in ok)
        for j in range(n if has_gains else 0):
            cols[f"K{j + 1}"], cols[f"K{j + 1}_std"] = [], []
        for u in self.units:
            cols["unit"].append(u.id)
            cols["date"].append(u.date)
            cols["payload_kg"].append(u.payload)
            cols["validation_error_pct"].append(None if u.error else u.validation_error)
            cols["pooled_validation_error_pct"].append(self.pooled_errors.get(u.id))
            worst = None if u.error or not np.isfinite(u.joint_errors).any() else f"joint {int(np.nanargmax(u.joint_errors)) + 1}"
            cols["worst_joint"].append(worst)
            cols["consistent"].append(None if u.error else u.consistency.startswith("yes"))
            cols["flags"].append("; ".join(f"{o.parameter} (z {o.z:+.1f})" for o in self.flagged(u.id)))
            cols["error"].append(u.error)
            index = {name: i for i, name in enumerate(u.names)}
            for name in friction:
                i = index.get(name)
                cols[name].append(None if i is None else float(u.params[i]))
                cols[name + "_std"].append(None if i is None else float(u.std[i]))
            for j in range(n if has_gains else 0):
                ok_gain = u.gains is not None and np.isfinite(u.gains[j])
                cols[f"K{j + 1}"].append(float(u.gains[j]) if ok_gain else None)  # type: ignore[index]
                cols[f"K{j + 1}_std"].append(float(u.gains_std[j]) if ok_gain else None)  # type: ignore[index]
        return cols

    def to_dict(self) -> dict:
        """JSON-ready summary.

        Returns
        -------
        dict
            The table, the outliers, the pooled fleet values, the cluster and timings.
        """
        pooled = None
        if self.pooled is not None:
            names = self.identified[0].names
            pooled = {"fleet": {n: float(v) for n, v in zip(names, self.pooled.fleet) if np.isfinite(v)},  # shared ones
                      "unit_to_unit_std": {n: float(s) for n, s in zip(names, self.pooled.spread) if np.isfinite(s)},
                      "shared": [n for n, s in zip(names, self.pooled.shared) if s],
                      "units": {u.id: dict(zip(names, self.pooled.params[i].tolist())) for i, u in enumerate(self.identified)},
                      "iterations": self.pooled.iterations}
        return {"kind": "fleet", "name": self.manifest.name, "manifest": str(self.manifest.path), "table": self.table(),
                "outliers": [o.to_dict() for o in self.outliers], "flag_threshold": self.threshold,
                "pooled": pooled, "pooled_note": self.pooled_note, "cluster": self.cluster,
                "seconds": {"total": self.seconds, **{u.id: u.seconds for u in self.units}},
                "peak_memory_mb": {u.id: u.memory_mb for u in self.units},
                "warnings": {u.id: list(u.warnings) for u in self.units if u.warnings}}


def _flag(units: tuple[UnitSummary, ...]):
    names = list(units[0].names)
    differ = list(~shared_parameters(names))
    values = np.array([u.arm for u in units])  # each unit's stated tool taken out
    std = np.array([u.std for u in units])
    if all(u.gains is not None for u in units):
        n = units[0].gains.size  # type: ignore[union-attr]
        names += [f"K{j + 1}" for j in range(n)]
        differ += [False] * n
        values = np.column_stack([values, [u.gains for u in units]])
        std = np.column_stack([std, [u.gains_std for u in units]])
    return fleet_outliers([u.id for u in units], names, values, std, may_differ=np.array(differ))


def run_fleet(manifest: FleetManifest, *, out: str | Path | None = None, save: Callable | None = None,
              scheduler: str | None = None, workers: int | None = None,
              progress: Callable[[str, int, int], None] | None = None) -> FleetResult:
    """Identify every unit of a fleet on a Dask cluster, flag the units that stand out, pool their estimates.

    Parameters
    ----------
    manifest : FleetManifest
    out : path, optional
        Output folder of the units' results (through ``save``).
    save : callable, optional
        As :func:`identify_unit`.
    scheduler : str, optional
        Address of a Dask scheduler (its workers need dynid installed and the logs at the manifest's paths);
        default: a LocalCluster.
    workers : int, optional
        Worker processes of the LocalCluster (default: the local cores).
    progress : callable, optional
        ``progress(step, done, total)``.

    Returns
    -------
    FleetResult

    Raises
    ------
    ConfigError
        An unreachable scheduler; ``DataError`` when no unit could be identified (the first unit's message).
    """
    require("distributed", "fleet", "dynid fleet")
    from distributed import as_completed

    t0 = time.perf_counter()
    units = manifest.units
    summaries: dict[str, UnitSummary] = {}
    pooled, pooled_errors, note = None, {}, ""
    with dask_client(scheduler, workers, extra="fleet", what="dynid fleet",
                     preload=(identify_unit.__module__, "dynid.identification.run", "scipy.signal", "cvxpy")) as client:
        cluster = f"{len(client.scheduler_info()['workers'])} Dask workers at {client.scheduler.address}"
        futures = {client.submit(identify_unit, u, out, save, pure=False, key=f"identify-{u.id}"): u.id for u in units}
        for done, fut in enumerate(as_completed(futures), 1):
            summaries[futures[fut]] = fut.result()
            if progress is not None:
                progress(f"identified {futures[fut]}", done, len(units))
        ordered = tuple(summaries[u.id] for u in units)
        ok = tuple(s for s in ordered if not s.error)
        if not ok:
            raise DataError(f"{manifest.path}: no unit could be identified; {ordered[0].id}: {ordered[0].error}")
        names = {s.names for s in ok}
        if len(ok) < 2:
            note = "fewer than 2 units identified"
        elif len(names) > 1:
            note = "the units' base parameters differ (friction models or robot descriptions): nothing to pool"
        else:
            pooled = pooled_estimate(np.array([s.arm for s in ok]), np.array([s.covariance for s in ok]),
                                     shared_parameters(ok[0].names))
            # each unit's pooled estimate carries its own tool again
            pooled = replace(pooled, params=pooled.params + np.array([np.zeros(len(s.names)) if s.tool is None else s.tool
                                                                      for s in ok]))
            by_id = {u.id: u for u in units}
            checks = {client.submit(validate_unit, by_id[s.id], s.model, {s.label: s.params, POOLED: pooled.params[i]}, s.preprocessing,
                                    pure=False, key=f"validate-{s.id}"): s.id for i, s in enumerate(ok)}
            for done, fut in enumerate(as_completed(checks), 1):
                errors = fut.result()
                if POOLED in errors:
                    pooled_errors[checks[fut]] = errors[POOLED]
                if progress is not None:
                    progress(f"validated the pooled estimate of {checks[fut]}", done, len(checks))
            if out is not None and save is not None:
                add_pooled_estimates(out, ok, pooled)
    outliers, threshold = _flag(ok) if len(names) == 1 else ((), float("inf"))
    return FleetResult(manifest, ordered, outliers, threshold, pooled, pooled_errors, note, cluster,
                       time.perf_counter() - t0)


def check_fleet_options(workers: int | None) -> None:
    """Options refused before any computation.

    Parameters
    ----------
    workers : int or None

    Raises
    ------
    ConfigError
        ``workers`` < 1.
    """
    if workers is not None and workers < 1:
        raise ConfigError(f"workers must be at least 1, got {workers}", field="workers")
