"""An identified robot model: what ``dynid identify`` (or :class:`dynid.Identifier`) found, ready to predict torques,
be validated on other logs and be exported — built from an identification or read back from its results.json.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Iterator

import numpy as np

from ..conventions import unit_of
from ..dynamics.base_parameters import BaseParameters
from ..exceptions import ConfigError, DataError
from ..model.robot import Robot
from ..preprocessing.settings import Preprocessing

__all__ = ["Parameter", "Parameters", "IdentifiedModel", "load_results"]

RESULTS_SCHEMA_VERSION = 2
"""The layout of results.json this module writes and reads (:data:`dynid.report.output.SCHEMA_VERSION`)."""


@dataclass(frozen=True)
class Parameter:
    """One base parameter of an estimate.

    Attributes
    ----------
    name : str
        E.g. ``"ZZ1R"``; its regrouping is :attr:`expression`.
    value : float
        In SI units (:attr:`unit`).
    std : float
        Standard deviation (NaN when the estimator gives none).
    unit : str
    expression : str
        The standard parameters it regroups (``"ZZ1 + YY2 + ..."``).
    """

    name: str
    value: float
    std: float
    unit: str
    expression: str = ""


class Parameters:
    """An estimate's base parameters by name, each with its σ.

    ``params["ZZ1R"]`` is a :class:`Parameter`, iterating gives the names, :attr:`values` and :attr:`std` the arrays in
    the base parameters' order.

    Parameters
    ----------
    names : sequence of str
        Base parameter names.
    values : (n_base,) array_like
        Values in SI units.
    std : (n_base,) array_like, optional
        Standard deviations, NaN where the estimator gives none.
    expressions : sequence of str, optional
        Each base parameter's regrouping of standard parameters.

    Attributes
    ----------
    names : tuple of str
    values : (n_base,) array
    std : (n_base,) array
        NaN where the estimator gives none.
    """

    def __init__(self, names, values, std=None, expressions=None):
        self.names = tuple(names)
        self.values = np.asarray(values, dtype=float)
        self.std = np.full(self.values.shape, np.nan) if std is None else np.asarray(std, dtype=float)
        self._expressions = tuple(expressions) if expressions is not None else ("",) * len(self.names)

    def __getitem__(self, name: str) -> Parameter:
        i = self.names.index(name) if name in self.names else None
        if i is None:
            raise KeyError(f"no base parameter {name!r}; expected one of {', '.join(self.names)}")
        return Parameter(name, float(self.values[i]), float(self.std[i]), unit_of(name), self._expressions[i])

    def __iter__(self) -> Iterator[str]:
        return iter(self.names)

    def __len__(self) -> int:
        return len(self.names)

    def __contains__(self, name: object) -> bool:
        return name in self.names

    def keys(self) -> tuple[str, ...]:
        """The base parameters' names.

        Returns
        -------
        tuple of str
        """
        return self.names

    def items(self) -> list[tuple[str, Parameter]]:
        """``(name, Parameter)`` pairs in the base parameters' order.

        Returns
        -------
        list of (str, Parameter)
        """
        return [(n, self[n]) for n in self.names]

    def to_dict(self) -> dict:
        """JSON-ready parameters.

        Returns
        -------
        dict
            name -> {"value", "std", "unit"}; a missing σ is None.
        """
        return {n: {"value": float(v), "std": None if np.isnan(s) else float(s), "unit": unit_of(n)}
                for n, v, s in zip(self.names, self.values, self.std)}

    def __repr__(self) -> str:
        rows = [f"{'name':>10s} {'value':>13s} {'σ':>10s}  unit"]
        rows += [f"{n:>10s} {v:13.6g} {s:10.3g}  {unit_of(n)}" for n, v, s in zip(self.names, self.values, self.std)]
        return "\n".join(rows)


@dataclass(frozen=True)
class IdentifiedModel:
    """The identified model of a robot: its description with the friction models chosen for its joints, the base-
    parameter map and every estimate.

    Attributes
    ----------
    robot : Robot
        As identified (drive terms: each joint's friction model).
    base : BaseParameters
    estimates : dict
        label -> (n_base,) base parameters of every estimate (the main one first).
    std : dict
        label -> (n_base,) standard deviations, for the estimates that have them.
    main : str
        Label of the estimate to trust.
    preprocessing : Preprocessing or None
        The identification's resolved preprocessing (carried over to other logs).
    results : dict
        results.json as a dictionary.
    """

    robot: Robot
    base: BaseParameters
    estimates: dict
    std: dict = field(default_factory=dict)
    main: str = ""
    preprocessing: Preprocessing | None = None
    results: dict = field(default_factory=dict)

    def label(self, estimate: str | None = None) -> str:
        """The label of an estimate.

        Parameters
        ----------
        estimate : str, optional
            A label (``"dynid SDP"``), an estimator's key (``"sdp"``, any case), or None for the main estimate.

        Returns
        -------
        str
            The estimate's label as results.json names it.

        Raises
        ------
        KeyError
            An unknown estimate (the message lists the known ones).
        """
        if estimate is None:
            return self.main
        if estimate in self.estimates:
            return estimate
        from ..estimators.registry import label

        named = f"dynid {label(estimate)}"
        if named in self.estimates:
            return named
        raise KeyError(f"no estimate {estimate!r}; expected one of {', '.join(self.estimates)}")

    def params(self, estimate: str | None = None) -> np.ndarray:
        """Base parameters of an estimate.

        Parameters
        ----------
        estimate : str, optional
            A label (``"dynid SDP"``), an estimator's key (``"sdp"``, any case), or None for the main estimate.

        Returns
        -------
        (n_base,) ndarray
            In SI units, in the base parameters' order.

        Raises
        ------
        KeyError
            An unknown estimate.
        """
        return self.estimates[self.label(estimate)]

    def parameters(self, estimate: str | None = None) -> Parameters:
        """The base parameters of an estimate by name, with σ where known.

        Parameters
        ----------
        estimate : str, optional
            A label (``"dynid SDP"``), an estimator's key (``"sdp"``, any case), or None for the main estimate.

        Returns
        -------
        Parameters

        Raises
        ------
        KeyError
            An unknown estimate.
        """
        label = self.label(estimate)
        return Parameters(self.base.names, self.params(label), self.std.get(label),
                          [e.split(" = ", 1)[1] for e in self.base.expressions])

    def predict(self, q, dq=None, ddq=None, estimate: str | None = None) -> np.ndarray:
        """Joint torques of the model along a motion (inverse dynamics with friction: ``Y(q, q̇, q̈)·β``).

        Parameters
        ----------
        q : (N, n_dof) array [rad], or a recording
            Joint positions; or a log (:class:`dynid.io.datasets.Recording`, e.g. from
            :func:`dynid.io.datasets.load_recording`), prepared as the identification log was
            (:meth:`predict_log`).
        dq, ddq : (N, n_dof) arrays [rad/s, rad/s²]
            Velocities and accelerations (required with positions).
        estimate : str, optional
            Label of the estimate (default the main one).

        Returns
        -------
        (N, n_dof) array [N·m]
            The Coulomb-like terms take the sign of ``dq`` (a log's state at rest: :meth:`predict_log`).

        Raises
        ------
        ShapeError
            Arrays not (N, n_dof), or holding NaN.
        ValueError
            Positions without velocities and accelerations.
        """
        if hasattr(q, "tau") and hasattr(q, "rate"):
            return self.predict_log(q, estimate)[1]
        if dq is None or ddq is None:
            raise ValueError("predict(q, dq, ddq): velocities and accelerations are needed with positions (or give a log)")
        from ..dynamics.regressor import regressor

        y = regressor(self.robot, q, dq, ddq, self.base.independent)
        return y @ self.params(estimate)

    def predict_log(self, recording, estimate: str | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Measured and predicted torques of a log, prepared as the identification log was (its filters, carried
        over: :func:`dynid.preprocessing.strategies.carried_over`), on the samples the comparison keeps.

        Parameters
        ----------
        recording : dynid.io.datasets.Recording
        estimate : str, optional

        Returns
        -------
        t : (M,) array [s]
        predicted : (M, n_dof) array [N·m]
        measured : (M, n_dof) array [N·m]
            Filtered like the prediction (parallel filtering).
        """
        comparison = self.validate(recording, estimate)
        return comparison.t, comparison.predicted[self.label(estimate)], comparison.measured

    def validate(self, recording, estimate: str | None = None):
        """The paper's metrics (eq. 18, RMSE, relative error) of the estimates on a log.

        Parameters
        ----------
        recording : dynid.io.datasets.Recording
        estimate : str, optional
            Only this estimate (default every one).

        Returns
        -------
        dynid.validation.torques.TorqueComparison
        """
        from ..preprocessing.pipeline import prepare
        from ..preprocessing.strategies import carried_over
        from ..validation.torques import compare_torques

        # the resolved settings stand for the config's here: the decimation (derived, not known to be given) follows
        # this log's own band
        settings = carried_over(self.preprocessing, replace(self.preprocessing or Preprocessing(), decimation=None))
        data = prepare(recording, settings, strict=False)
        sets = self.estimates if estimate is None else {self.label(estimate): self.params(estimate)}
        return compare_torques(self.robot, self.base, data, sets)

    def score(self, recording, estimate: str | None = None) -> float:
        """Coefficient of determination R² of the predicted torques of a log, over its joints and samples (1 is a
        perfect prediction; scikit-learn's ``score``).

        Parameters
        ----------
        recording : dynid.io.datasets.Recording
        estimate : str, optional

        Returns
        -------
        float
        """
        _, pred, meas = self.predict_log(recording, estimate)
        res = meas - pred
        return 1.0 - float(np.sum(res**2)) / float(np.sum((meas - meas.mean(axis=0)) ** 2))

    def urdf(self) -> str:
        """The physically consistent estimate as URDF text (:func:`dynid.io.export.urdf_from_results`).

        Returns
        -------
        str
            A URDF document.

        Raises
        ------
        ConfigError
            No physically consistent estimate that passed the consistency check.
        """
        from ..io.export import urdf_from_results

        return urdf_from_results(self.robot, self.results)

    def mjcf(self) -> str:
        """The physically consistent estimate as MuJoCo MJCF text (:func:`dynid.io.export.mjcf_from_results`).

        Returns
        -------
        str
            An MJCF document.

        Raises
        ------
        ConfigError
            No physically consistent estimate that passed the consistency check.
        """
        from ..io.export import mjcf_from_results

        return mjcf_from_results(self.robot, self.results)

    def save(self, path: str | Path) -> Path:
        """Write results.json atomically, to be read back by :func:`load_results`.

        Parameters
        ----------
        path : str or Path
            A file, or a folder to hold ``results.json``.

        Returns
        -------
        Path
            The file written.
        """
        from ..io.files import write_json

        path = Path(path)
        from .. import __version__

        write_json(path, {**self.results, "schema_version": RESULTS_SCHEMA_VERSION, "dynid_version": __version__,
                          "kind": "identify"})
        return path

    @classmethod
    def from_results(cls, results: dict, robot: Robot, source: str = "results") -> "IdentifiedModel":
        """The model of a results.json dictionary of ``dynid identify``.

        Parameters
        ----------
        results : dict
            The parsed results.json.
        robot : Robot
            The robot's description the results were identified for.
        source : str
            Where the results come from (their file), named in errors.

        Returns
        -------
        IdentifiedModel

        Raises
        ------
        DataError
            Results of another robot, or malformed.
        """
        from ..dynamics.base_parameters import base_parameters
        from ..io.identification_config import stored_preprocessing
        from ..io.results import stored_estimates
        from ..model.friction_model import robot_from_settings

        try:
            robot = robot_from_settings(robot, results.get("settings", {}))
        except (TypeError, ValueError, KeyError, AttributeError, ConfigError) as exc:
            raise DataError(f"{source}: settings: {exc}") from None
        base = base_parameters(robot, rng=0)
        estimates = stored_estimates(results, base.names, source, robot.name)
        std = {}
        for label, e in (results.get("estimates") or {}).items():
            if isinstance(e, dict) and isinstance(e.get("std"), dict):
                std[str(label)] = np.array([float(e["std"].get(n, np.nan)) for n in base.names])
        stated = results.get("main_estimate")
        main = str(stated) if stated in estimates else next(iter(estimates))
        return cls(robot, base, estimates, std, main, stored_preprocessing(results), results)

    @classmethod
    def from_result(cls, result) -> "IdentifiedModel":
        """The model of an identification run's result.

        Parameters
        ----------
        result : IdentificationResult
            What :func:`dynid.run_identification` returned.

        Returns
        -------
        IdentifiedModel
        """
        return cls(result.model, result.base, {label: e.params for label, e in result.estimates.items()},
                   {label: e.std for label, e in result.estimates.items() if e.std is not None},
                   result.main_estimate.label, _stored(result.settings), json.loads(json.dumps(_plain(result.to_dict()))))


def _stored(settings: dict) -> Preprocessing | None:
    from ..io.identification_config import stored_preprocessing

    return stored_preprocessing({"settings": settings})


def _plain(obj):
    """numpy values as JSON-ready Python values (NaN and inf as None)."""
    from ..io.files import _clean

    return _clean(obj)


def load_results(path: str | Path, robot: Robot | str | Path | None = None) -> IdentifiedModel:
    """Read the results.json of ``dynid identify`` (or :meth:`IdentifiedModel.save`) back as the identified model.

    Parameters
    ----------
    path : path
        results.json.
    robot : Robot, built-in name or description path, optional
        The robot's description; default: the one the results name (``settings.robot_source``: a built-in name, a
        description or URDF file, or the config that held it).

    Returns
    -------
    IdentifiedModel

    Raises
    ------
    DataError
        An unreadable file, results of another robot, or no way to find the robot's description.
    """
    from ..io.results import read_results

    path = Path(path)
    results = read_results(path)
    model_robot = _robot(robot, results, path)
    if isinstance(results.get("robot"), str) and results["robot"] != model_robot.name:
        raise DataError(f"{path}: results of robot {results['robot']!r}, the robot given is {model_robot.name!r}")
    return IdentifiedModel.from_results(results, model_robot, str(path))


def _robot(robot, results: dict, path: Path) -> Robot:
    """The robot description for results: given, or the one the results name."""
    from ..model.description import load_robot

    if isinstance(robot, Robot):
        return robot
    if robot is not None:
        return load_robot(robot)
    settings: dict = results["settings"] if isinstance(results.get("settings"), dict) else {}
    source = settings.get("robot_source")
    if isinstance(source, str) and source.startswith("config:"):
        import tomllib

        from ..io.configs import config_robot

        config = Path(source[len("config:"):])
        if config.is_file():
            doc = tomllib.loads(config.read_text(encoding="utf-8"))
            return config_robot(doc, config, config.parent / str(doc.get("data_root", ".")))
    elif isinstance(source, str) and source:
        try:
            return load_robot(source)
        except ConfigError:
            pass
    raise DataError(f"{path}: the robot's description is not found (results name {source or results.get('robot')!r}): "
                    "give it, load_results(path, robot=...)")
