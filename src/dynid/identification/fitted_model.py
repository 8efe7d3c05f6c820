"""An identified robot model: what ``dynid identify`` (or :class:`dynid.Identifier`) found, ready to predict torques,
be validated on other logs and be exported — built from an identification or read back from its results.json.
"""

from __future__ import annotations

import json
import tomllib
import warnings
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .. import __version__
from .._util.keywords import keyword_only_after_data
from ..conventions import unit_of
from ..dynamics.base_parameters import BaseParameters, base_parameters
from ..dynamics.regressor import regressor
from ..estimators.registry import label
from ..exceptions import ConfigError, DataError
from ..io.exported.export import mjcf_from_results, urdf_from_results
from ..io.files import _clean, write_json
from ..io.logs.datasets import recording_from_arrays
from ..io.results import check_fingerprint, read_results, stored_estimates, stored_residual_level
from ..model.friction_model import robot_from_settings
from ..model.robot import Robot
from ..preprocessing.preparation import prepare
from ..preprocessing.prepared import rest_velocities
from ..preprocessing.settings import Preprocessing
from ..preprocessing.strategies import carried_over
from ..validation.noise_floor import torque_noise
from ..validation.torques import compare_torques

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
    units : sequence of str, optional
        Each parameter's unit (by default from its name, a revolute joint's: :func:`dynid.conventions.unit_of`).

    Attributes
    ----------
    names : tuple of str
    values : (n_base,) array
    std : (n_base,) array
        NaN where the estimator gives none.
    """

    def __init__(self, names, values, std=None, expressions=None, units=None):
        self.names = tuple(names)
        self.units = tuple(units) if units is not None else tuple(map(unit_of, self.names))
        self.values = np.asarray(values, dtype=float)
        self.std = np.full(self.values.shape, np.nan) if std is None else np.asarray(std, dtype=float)
        self._expressions = tuple(expressions) if expressions is not None else ("",) * len(self.names)

    def __getitem__(self, name: str) -> Parameter:
        i = self.names.index(name) if name in self.names else None
        if i is None:
            raise KeyError(f"no base parameter {name!r}; expected one of {', '.join(self.names)}")
        return Parameter(name, float(self.values[i]), float(self.std[i]), self.units[i], self._expressions[i])

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
        return {n: {"value": float(v), "std": None if np.isnan(s) else float(s), "unit": u}
                for n, v, s, u in zip(self.names, self.values, self.std, self.units)}

    def __repr__(self) -> str:
        rows = [f"{'name':>10s} {'value':>13s} {'σ':>10s}  unit"]
        rows += [f"{n:>10s} {v:13.6g} {'—' if np.isnan(s) else f'{s:.3g}':>10s}  {u}"  # no σ: the SDP's
                 for n, v, s, u in zip(self.names, self.values, self.std, self.units)]
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
    estimators_ : dict
        label -> the fitted estimator object of an estimate (its learned attributes: the bee colony's ``history_``, the
        SDP's ``status_``, a plugin's own), for the estimates an estimator object made; empty for a model read back
        from results.json (:func:`load_results`), which holds values, not objects.

    The fitted attributes :class:`~dynid.identification.identifier.Identifier` has after ``fit`` are this model's
    (``params_``, ``params_std_``, ``feature_names_out_``, ``parameters_``, ``estimates_``, ``estimators_``): a model
    identified here and one read back answer by the same names.
    """

    robot: Robot
    base: BaseParameters
    estimates: dict
    std: dict = field(default_factory=dict)
    main: str = ""
    preprocessing: Preprocessing | None = None
    results: dict = field(default_factory=dict)
    estimators_: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def params_(self) -> np.ndarray:
        """(n_base,) base parameters of the main estimate (SI units, the base parameters' order)."""
        return self.params()

    @property
    def params_std_(self) -> np.ndarray:
        """(n_base,) standard deviations of the main estimate's base parameters (NaN where it has none)."""
        std = self.std.get(self.main)
        return np.full(self.params_.shape, np.nan) if std is None else np.asarray(std)

    @property
    def feature_names_out_(self) -> tuple[str, ...]:
        """The base parameters' names, in their order."""
        return tuple(self.base.names)

    @property
    def parameters_(self) -> Parameters:
        """The main estimate's base parameters by name (:meth:`parameters`)."""
        return self.parameters()

    @property
    def estimates_(self) -> dict:
        """label -> (n_base,) base parameters of every estimate, the main one first."""
        return dict(self.estimates)

    def __repr__(self) -> str:
        return (f"IdentifiedModel(robot={self.robot.name!r}, {self.robot.n_dof} joints, {len(self.base.names)} base "
                f"parameters, estimates={list(self.estimates)}, main={self.label()!r})")

    def summary(self, *, estimate: str | None = None) -> str:
        """What :func:`repr` says and an estimate's base parameters (name, value, σ, unit).

        Parameters
        ----------
        estimate : str, optional
            A label or key of :attr:`estimates` (default the main one).

        Returns
        -------
        str

        Raises
        ------
        ConfigError
            An estimate the model does not hold.
        """
        return f"{self!r}\n{self.parameters(estimate)!r}"

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
                          [e.split(" = ", 1)[1] for e in self.base.expressions], map(self.base.unit, self.base.names))

    @keyword_only_after_data
    def predict(self, t, q=None, dq=None, ddq=None, *, estimate: str | None = None) -> np.ndarray:
        """Joint torques of the model along a logged motion, its positions prepared as the identification log's were
        (the fitted filters and derivatives): symmetric with ``Identifier.fit(t, q, tau)``.

        ``predict(t, q)`` takes a raw log's time stamps and positions (and measured velocities ``dq`` if the fit had
        them); ``predict(recording)`` a log read with :func:`dynid.load_recording`, at its own time stamps, as
        ``predict(recording.t, recording.q, recording.dq)`` (:meth:`predict_log` gives the samples a comparison keeps).
        For states one has computed oneself,
        :meth:`predict_states` (``predict(q, dq, ddq)``, the earlier form, still does that, with a FutureWarning).

        Parameters
        ----------
        t : (N,) array [s], or a recording
            Time stamps of the log.
        q : (N, n_dof) array [rad]
            Its joint positions, as measured.
        dq : (N, n_dof) array [rad/s], optional
            Its measured velocities.
        ddq : None
            Only in the earlier state form.
        estimate : str, optional
            Label of the estimate (default the main one).

        Returns
        -------
        (N, n_dof) array [N·m]
            At the given time stamps; NaN at the few samples at each end that the filters' settling leaves out.

        Raises
        ------
        ShapeError
            Arrays not (N, n_dof), or holding NaN.
        DataError
            Time stamps that do not increase, or a gap in them.
        """
        if hasattr(t, "tau") and hasattr(t, "rate"):  # a recording: at its own time stamps, as its arrays
            return self.predict(t.t, np.asarray(t.q), None if t.dq is None else np.asarray(t.dq), estimate=estimate)
        if np.ndim(t) == 2 and q is not None and dq is not None:  # the earlier predict(q, dq, ddq)

            warnings.warn("predict(q, dq, ddq) is predict_states(q, dq, ddq): predict(t, q) prepares a raw log as the "
                          "fit did", FutureWarning, stacklevel=2)
            return self.predict_states(t, q, dq, estimate=estimate)
        if q is None:
            raise ValueError("predict(t, q): the positions are needed with the time stamps (or give a log)")

        q = np.asarray(q, dtype=float)
        times = np.asarray(t, dtype=float).reshape(-1)
        recording = recording_from_arrays(self.robot, times, q, np.zeros_like(q), dq, name="predict")
        data = prepare(recording, self._settings(), strict=False)
        v = rest_velocities(data, self.robot)
        if data.direction is not None:
            v = replace(v, direction=np.asarray(data.direction))
        y = regressor(self.robot, np.asarray(data.q), np.asarray(data.dq), np.asarray(data.ddq), columns=self.base.independent,
                      velocities=v)
        pred = y @ self.params(estimate)
        at = times - times[0]
        return np.column_stack([np.interp(at, data.t, pred[:, j], left=np.nan, right=np.nan)
                                for j in range(pred.shape[1])])

    def predict_states(self, q, dq, ddq, *, estimate: str | None = None) -> np.ndarray:
        """Joint torques of the model at given states (inverse dynamics with friction: ``Y(q, q̇, q̈)·β``), as they are.

        The accelerations are the caller's: a second difference of measured positions is mostly noise, and a warning
        says so when the given ones look like that (their high-frequency part against their spread; the MAD estimate of
        :mod:`dynid.validation.noise_floor`); :meth:`predict` prepares a raw log as the fit did.

        Parameters
        ----------
        q, dq, ddq : (N, n_dof) arrays [rad, rad/s, rad/s²]
        estimate : str, optional

        Returns
        -------
        (N, n_dof) array [N·m]
            The Coulomb-like terms take the sign of ``dq``.

        Raises
        ------
        ShapeError
            Arrays not (N, n_dof), or holding NaN.
        """
        acc = np.asarray(ddq, dtype=float)
        if acc.ndim == 2 and acc.shape[0] >= 10:
            noise, spread = torque_noise(acc), acc.std(axis=0)
            noisy = [j for j in range(acc.shape[1]) if spread[j] > 0 and noise[j] > 0.3 * spread[j]]
            if noisy:
                warnings.warn(f"predict_states: the accelerations of {', '.join(f'J{j + 1}' for j in noisy)} are mostly "
                              f"noise (its level {max(noise[j] / spread[j] for j in noisy):.0%} of their spread): "
                              "differentiate filtered positions, or give the raw log to predict(t, q)", UserWarning,
                              stacklevel=2)
        y = regressor(self.robot, q, dq, ddq, columns=self.base.independent)
        return y @ self.params(estimate)

    def _settings(self):
        """The preprocessing a log other than the identification one gets (:meth:`validate`): the settings as given,
        carried over as ``dynid validate`` does, so that the API and the CLI keep the same samples of a log."""
        from ..io.config.identification_config import stored_preprocessing

        given = stored_preprocessing(self.results, "given_preprocessing") if self.results else None
        if given is None:  # results written before they held it: the resolved settings stand for the config's, the
            # decimation (derived, not known to be given) following this log's own band
            given = replace(self.preprocessing or Preprocessing(), decimation=None)
        return carried_over(self.preprocessing, given)

    @keyword_only_after_data
    def predict_log(self, recording, *, estimate: str | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Measured and predicted torques of a log, prepared as the identification log was (its filters, carried
        over: :func:`dynid.preprocessing.strategies.carried_over`), on the samples the comparison keeps.

        Parameters
        ----------
        recording : dynid.io.logs.datasets.Recording
        estimate : str, optional

        Returns
        -------
        t : (M,) array [s]
        predicted : (M, n_dof) array [N·m]
        measured : (M, n_dof) array [N·m]
            Filtered like the prediction (parallel filtering).
        """
        comparison = self.validate(recording, estimate=estimate)
        return comparison.t, comparison.predicted[self.label(estimate)], comparison.measured

    @keyword_only_after_data
    def validate(self, t, q=None, tau=None, *, estimate: str | None = None):
        """The paper's metrics (eq. 18, RMSE, relative error) of the estimates on a log.

        Parameters
        ----------
        t : (N,) array [s], or a recording
            A raw log's time stamps (with ``q`` and ``tau``, as :meth:`score` takes them), or a log read with
            :func:`dynid.load_recording`.
        q, tau : (N, n_dof) arrays [rad, N·m], optional
            Its positions and measured torques (with time stamps).
        estimate : str, optional
            Only this estimate (default every one).

        Returns
        -------
        dynid.validation.torques.TorqueComparison

        Raises
        ------
        ShapeError
            A recording not one row per time stamp and one column per joint (:meth:`Recording.check
            <dynid.io.logs.datasets.Recording.check>`).
        ValueError
            Time stamps without positions and torques.
        """
        recording = self._scored_log(t, q, tau, "validate")
        recording.check(self.robot.n_dof)
        data = prepare(recording, self._settings(), strict=False)
        sets = self.estimates if estimate is None else {self.label(estimate): self.params(estimate)}
        # the identification's residual level says which joints' errors and correlations mean something, as in dynid validate
        return compare_torques(self.robot, self.base, data, sets, noise=stored_residual_level(self.results, self.robot.n_dof))

    @keyword_only_after_data
    def score(self, t, q=None, tau=None, *, estimate: str | None = None) -> float:
        """Coefficient of determination R² of the predicted torques of a log, over its joints and samples (1 is a
        perfect prediction; scikit-learn's ``score``), on the samples ``dynid validate`` scores: the log prepared as the
        identification log was.

        Parameters
        ----------
        t : (N,) array [s], or a recording
            A raw log's time stamps, or a log read with :func:`dynid.load_recording`.
        q, tau : (N, n_dof) arrays [rad, N·m]
            Its positions and measured torques (with time stamps).
        estimate : str, optional

        Returns
        -------
        float

        Raises
        ------
        ValueError
            Time stamps without positions and torques.
        """
        _, pred, meas = self.predict_log(self._scored_log(t, q, tau, "score"), estimate=estimate)
        res = meas - pred
        return 1.0 - float(np.sum(res**2)) / float(np.sum((meas - meas.mean(axis=0)) ** 2))

    def relative_error(self, t, q=None, tau=None, *, estimate: str | None = None) -> float:
        """The global relative torque error [%] ``dynid validate`` prints for a log, on the same samples (the log
        prepared as the identification's settings carry over to it): ``100·||τ - τ̂|| / ||τ||`` over its joints.

        Parameters
        ----------
        t : (N,) array [s], or a recording
            A raw log's time stamps, or a log read with :func:`dynid.load_recording`.
        q, tau : (N, n_dof) arrays [rad, N·m]
            Its positions and measured torques (with time stamps).
        estimate : str, optional

        Returns
        -------
        float [%]

        Raises
        ------
        ValueError
            Time stamps without positions and torques.
        """
        recording = self._scored_log(t, q, tau, "relative_error")
        return float(self.validate(recording, estimate=estimate).metrics()[self.label(estimate)]["global_relative_error"])

    def _scored_log(self, t, q, tau, what: str):
        """A recording given as one, or made of a raw log's arrays as the log readers make it."""
        if hasattr(t, "tau") and hasattr(t, "rate"):
            return t
        if q is None or tau is None:
            raise ValueError(f"{what}(t, q, tau): positions and measured torques are needed with the time stamps")

        return recording_from_arrays(self.robot, t, q, tau, name=what)

    def urdf(self) -> str:
        """The physically consistent estimate as URDF text (:func:`dynid.io.exported.export.urdf_from_results`).

        Returns
        -------
        str
            A URDF document.

        Raises
        ------
        ConfigError
            No physically consistent estimate that passed the consistency check.
        """
        return urdf_from_results(self.robot, self.results)

    def mjcf(self) -> str:
        """The physically consistent estimate as MuJoCo MJCF text (:func:`dynid.io.exported.export.mjcf_from_results`).

        Returns
        -------
        str
            An MJCF document.

        Raises
        ------
        ConfigError
            No physically consistent estimate that passed the consistency check.
        """
        return mjcf_from_results(self.robot, self.results)

    def save(self, path: str | Path) -> Path:
        """Write results.json atomically, to be read back by :func:`load_results`.

        Parameters
        ----------
        path : str or Path
            A file, or a folder to hold ``results.json``: one that exists, or a path without a suffix (``"out"``). A
            missing folder is created, as ``dynid identify --out`` creates its own.

        Returns
        -------
        Path
            The file written.

        Raises
        ------
        ConfigError
            A folder that cannot be created (a file stands in its place).
        """
        path = Path(path)
        if path.is_dir() or (path.suffix == "" and not path.exists()):
            path = path / "results.json"
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ConfigError(f"{path.parent}: cannot create the folder for {path.name} ({exc.strerror})") from None
        write_json(path, {**self.results, "schema_version": RESULTS_SCHEMA_VERSION, "dynid_version": __version__,
                          "kind": "identify"})
        return path

    @classmethod
    def from_results(cls, results: dict, robot: Robot, source: str = "results") -> IdentifiedModel:
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
        from ..io.config.identification_config import stored_preprocessing

        try:
            robot = robot_from_settings(robot, results.get("settings", {}))
        except (TypeError, ValueError, KeyError, AttributeError, ConfigError) as exc:
            raise DataError(f"{source}: settings: {exc}") from None
        base = base_parameters(robot, rng=0)
        estimates = stored_estimates(results, base.names, source, robot.name)
        std = {}
        for key, e in (results.get("estimates") or {}).items():
            if isinstance(e, dict) and isinstance(e.get("std"), dict):  # a σ written as null is not known: NaN
                std[str(key)] = np.array([np.nan if e["std"].get(n) is None else float(e["std"][n]) for n in base.names])
        stated = results.get("main_estimate")
        main = str(stated) if stated in estimates else next(iter(estimates))
        return cls(robot, base, estimates, std, main, stored_preprocessing(results), results)

    @classmethod
    def from_result(cls, result) -> IdentifiedModel:
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
                   result.main_estimate.label, _stored(result.settings), json.loads(json.dumps(_plain(result.to_dict()))),
                   {label: e.estimator for label, e in result.estimates.items() if e.estimator is not None})


def _stored(settings: dict) -> Preprocessing | None:
    from ..io.config.identification_config import stored_preprocessing

    return stored_preprocessing({"settings": settings})


def _plain(obj):
    """numpy values as JSON-ready Python values (NaN and inf as None)."""
    return _clean(obj)


@keyword_only_after_data
def load_results(path: str | Path, *, robot: Robot | str | Path | None = None) -> IdentifiedModel:
    """Read the results.json of ``dynid identify`` (or :meth:`IdentifiedModel.save`) back as the identified model.

    Parameters
    ----------
    path : path
        results.json, or the folder dynid identify wrote it into.
    robot : Robot, built-in name or description path, optional
        The robot's description; default: the one the results name (``settings.robot_source``: a built-in name, a
        description or URDF file, or the config that held it).

    Returns
    -------
    IdentifiedModel

    Raises
    ------
    DataError
        An unreadable file, results of another robot, or no way to find the robot's description; a description whose
        kinematics differ from those the results were identified with (``settings.robot_fingerprint``, from this
        release on: :meth:`dynid.model.robot.Robot.kinematic_fingerprint`).
    """
    path = Path(path)
    if path.is_dir() and (path / "results.json").is_file():  # the output folder of dynid identify
        path = path / "results.json"
    results = read_results(path)
    model_robot = _robot(robot, results, path)
    if isinstance(results.get("robot"), str) and results["robot"] != model_robot.name:
        raise DataError(f"{path}: results of robot {results['robot']!r}, the robot given is {model_robot.name!r}")
    check_fingerprint(results, model_robot, str(path))
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
        from ..io.config.configs import config_robot

        config = Path(source[len("config:"):])
        if config.is_file():
            doc = tomllib.loads(config.read_text(encoding="utf-8-sig"))  # as the config was read (io.configs)
            return config_robot(doc, config, config.parent / str(doc.get("data_root", ".")))
    elif isinstance(source, str) and source:
        try:
            return load_robot(source)
        except ConfigError:
            pass
    raise DataError(f"{path}: the robot's description is not found (results name {source or results.get('robot')!r}): "
                    "give it, load_results(path, robot=...)")
