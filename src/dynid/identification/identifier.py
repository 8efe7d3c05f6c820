"""``dynid.Identifier``: the identification as a scikit-learn style estimator — ``fit`` on a robot's arrays or on a
config, ``predict`` torques, ``score``, the parameters by name with σ, ``get_params``/``set_params``.

Example::

    ident = dynid.Identifier("ur10e", estimators=["wls", "sdp"]).fit(t, q, tau)
    tau_hat = ident.predict(t2, q2)          # another raw log, prepared as the fit prepared its own
    print(ident.parameters_)                 # name, value, σ, unit
    ident.save("results.json"); model = dynid.load_results("results.json")
"""

from __future__ import annotations

import warnings
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from .._util.keywords import keyword_only_after_data, renamed_keyword, seed_of
from ..estimators.base import HyperParameters
from ..estimators.registry import DEFAULT_ESTIMATORS, estimator_choices
from ..exceptions import ConfigError, NotFittedError
from ..model.loading import as_robot
from ..model.robot import Robot
from ..preprocessing.settings import Preprocessing

__all__ = ["Identifier", "FITTED"]

FITTED = ("params_", "params_std_", "feature_names_out_", "parameters_", "estimates_", "estimators_")
"""The fitted attributes an :class:`Identifier` takes from its :class:`~dynid.identification.fitted_model.IdentifiedModel`
(the same names on both)."""


class Identifier(HyperParameters):
    """Identify a robot's dynamic model (module docstring).

    Parameters
    ----------
    robot : Robot, str or path, optional
        The robot's description: a :class:`~dynid.model.robot.Robot`, a built-in name (``"ur10e"``) or a description
        TOML / URDF path. Required to fit arrays; a config names its own.
    estimators : sequence of str and Estimator, optional
        Keys of :mod:`dynid.estimators.registry`, case-insensitive, or unfitted estimators of registered classes
        carrying their hyper-parameters (e.g. the SDP with the geometric prior:
        :class:`~dynid.estimators.physically_consistent.PhysicallyConsistentLeastSquares`); the first is the main
        estimate (default ``["wls", "sdp"]``, or the config's). Every list a config's ``[estimation] estimators`` takes: the closed-loop ones
        (``idim-iv``, ``didim``, ``didim-sdp``) too, with ``controller`` for arrays, or fitting a config with a
        ``[controller]`` table.
    preprocessing : Preprocessing or dict, optional
        Preprocessing settings (default: every setting derived from the data, or the config's).
    friction : {"description", "auto"}, optional
        Each joint's friction model chosen by cross-validation, or the description's terms (default: as a config
        without the setting: "auto" unless a Coulomb smoothing velocity is given; the config's for a config).
    rng : int or numpy.random.Generator, optional
        Seeds the box searches (default 0, or the config's ``seed``); a generator gives one draw as the seed. Was
        ``seed`` (still taken, with a FutureWarning).
    controller : ClosedLoopSetup, optional
        How the arrays were recorded in closed loop (:class:`dynid.simulation.closed_loop.ClosedLoopSetup`: the
        controller, one set-point per sample, the feed-forward), for the closed-loop estimators; a config gives its
        ``[controller]`` table instead.

    Attributes
    ----------
    result_ : dynid.identification.result.IdentificationResult
        Everything the identification found (fit, validations, verdict).
    model_ : dynid.identification.fitted_model.IdentifiedModel
        The identified model (predict, validate, export, save).
    params_ : (n_base,) array
        The main estimate's base parameters.
    params_std_ : (n_base,) array
        Their standard deviations (NaN when the main estimator gives none).
    parameters_ : Parameters
        The same by name: ``ident.parameters_["ZZ1R"].value``, ``.std``, ``.unit``.
    feature_names_out_ : tuple of str
        The base parameters' names.
    estimates_ : dict
        label -> (n_base,) array of every estimate.
    estimators_ : dict
        label -> the fitted estimator object of an estimate (the bee colony's ``history_``, a plugin's attributes).

    These fitted attributes but ``result_`` and ``model_`` are the model's own (:data:`FITTED`): a model read back
    with :func:`dynid.load_results` answers by the same names (its ``estimators_`` empty: results.json holds values).
    """

    @renamed_keyword("seed", "rng")
    def __init__(self, robot: Robot | str | Path | None = None, *, estimators=None, preprocessing=None,
                 friction: str | None = None, rng=None, controller=None):
        self.robot = robot
        self.estimators = estimators
        self.preprocessing = preprocessing
        self.friction = friction
        self.rng = rng
        self.controller = controller

    def __sklearn_is_fitted__(self) -> bool:
        """Whether :meth:`fit` ran (scikit-learn's ``check_is_fitted`` asks this).

        Returns
        -------
        bool
        """
        return hasattr(self, "result_")

    def __sklearn_tags__(self):
        """scikit-learn's tags (asked by its ``check_is_fitted``, ``clone`` and meta-estimators; scikit-learn is then
        imported already): no estimator type of its own (it fits a robot's log, not ``X, y``), fitting required, its
        input not validated by scikit-learn, its box searches seeded (``rng``), so deterministic.

        Returns
        -------
        sklearn.utils.Tags
        """
        from sklearn.utils import Tags, TargetTags

        return Tags(estimator_type=None, target_tags=TargetTags(required=True), no_validation=True, requires_fit=True)

    @classmethod
    def from_config(cls, path: str | Path, *, data_root=None, validate: bool = True, **params) -> Identifier:
        """Identify the robot of an identification config (TOML) as ``dynid identify`` does, the ``params`` given
        (the constructor's: ``estimators``, ``preprocessing``, ``friction``, ``rng``, ``robot``, ``controller``) over
        the config's.

        Parameters
        ----------
        path : str or Path
            The config.
        data_root : path, optional
            Its data folder (overrides the config's ``data_root``).
        validate : bool
            Validate on the config's validation logs.
        **params
            Keyword arguments of :class:`Identifier`.

        Returns
        -------
        Identifier
            Fitted.

        Raises
        ------
        ConfigError
            A malformed config or setting.
        DataError, IdentifiabilityError
            Logs that cannot be read or identified from (the message says why).
        """
        ident = cls(**params)
        return ident._fitted(ident._config_result(Path(path), data_root, validate))

    def fit(self, t, q=None, tau=None, dq=None, *, data_root=None, validate: bool = True) -> Identifier:
        """Identify the robot from arrays or a recording (a config: :meth:`from_config`).

        Parameters
        ----------
        t : (N,) array [s], or a recording
            Time stamps (jittered ones are interpolated onto a uniform grid, as the log readers do), or a log as
            :func:`dynid.load_recording` or :func:`dynid.simulated_log` give it (alone). A config's path here still
            works, with a FutureWarning: it is :meth:`from_config`.
        q : (N, n_dof) array [rad]
            Joint positions (with time stamps), the description's angles: a log's with the description's
            ``position_offset`` added, as :func:`dynid.load_recording` reads them (the TX40's and the KR 300's J2 and
            J3 a quarter turn from their encoders').
        tau : (N, n_dof) array [N·m]
            Joint torques (with time stamps).
        dq : (N, n_dof) array [rad/s], optional
            Measured velocities.
        data_root : path, optional
            A config's data folder (overrides the config's).
        validate : bool
            Validate on a config's validation logs.

        Returns
        -------
        self

        Raises
        ------
        ConfigError
            A malformed config or setting, no robot for arrays, time stamps without positions and torques, or arrays
            beside a recording.
        DataError, ShapeError, IdentifiabilityError
            Data that cannot be identified from (the message says why).
        """
        if isinstance(t, (str, Path)):
            warnings.warn("Identifier(...).fit(config_path) is Identifier.from_config(config_path, ...): fit takes the "
                          "arrays t, q, tau", FutureWarning, stacklevel=2)
            result = self._config_result(Path(t), data_root, validate)
        else:
            from ..io.config.identification_config import split_estimators
            from .run import identify_from_arrays

            closed_loop = () if self.estimators is None else split_estimators(self.estimators, "Identifier(estimators=...)")[1]
            if closed_loop and self.controller is None:
                raise ConfigError(f"Identifier(estimators=...): {closed_loop[0]} simulates the "
                                  "run in closed loop and needs its controller: fit a config with a [controller] table "
                                  "(Identifier.from_config('arm.toml', estimators=...)), give "
                                  "Identifier(controller=ClosedLoopSetup(...)), or leave it out", field="estimators")
            result = identify_from_arrays(self._robot(), t, q, tau, dq, preprocessing=self._preprocessing(),
                                          estimators=tuple(self.estimators or DEFAULT_ESTIMATORS), friction=self.friction,
                                          rng=seed_of(self.rng), controller=self.controller)
        return self._fitted(result)

    def _fitted(self, result) -> Identifier:
        """Set the fitted attributes from an identification's result."""
        from .fitted_model import IdentifiedModel

        self.result_ = result
        self.model_ = model = IdentifiedModel.from_result(result)
        for name in FITTED:  # the model's own fitted attributes: one set of names for both (IdentifiedModel)
            setattr(self, name, getattr(model, name))
        return self

    def _config_result(self, path: Path, data_root, validate: bool):
        from ..io.config.identification_config import load_identification_config, split_estimators
        from .run import run_identification

        config = load_identification_config(path, data_root=data_root)
        changes: dict[str, Any] = {}
        if self.robot is not None:
            changes["robot"] = self._robot()
        if self.controller is not None:  # in place of the config's [controller]
            changes["controller"] = self.controller
        if self.preprocessing is not None:
            changes["preprocessing"] = self._preprocessing()
        estimation: dict[str, Any] = {}  # over the config's [estimation]
        if self.estimators is not None:
            open_loop, closed_loop = split_estimators(self.estimators, "Identifier(estimators=...)")
            # a key the config gives settings for ({ key = "abc", colony_size = 60 }) takes the config's estimator
            objects = [x for x in config.estimation.estimators if not isinstance(x, str)]
            configured = estimator_choices(objects)[1] if objects else {}
            estimation["estimators"] = tuple(configured.get(x, x) if isinstance(x, str) else x
                                             for x in (*open_loop, *closed_loop))
            if closed_loop and config.controller is None and self.controller is None:
                raise ConfigError(f"Identifier(estimators=...): {closed_loop[0]} simulates the run in closed loop "
                                  f"and needs its controller: {path} has no [controller] table (kp, kd, rate, the "
                                  "reference trajectory)", field="estimators")
        if self.friction is not None:
            estimation["friction"] = self.friction
        if self.rng is not None:  # the config's seed
            estimation["seed"] = seed_of(self.rng)
        changes["estimation"] = replace(config.estimation, **estimation)
        return run_identification(replace(config, **changes), validate=validate)

    def _robot(self) -> Robot:
        if self.robot is None:
            raise ConfigError("Identifier(robot=...): the robot's description is needed to fit arrays", field="robot")
        return as_robot(self.robot, "Identifier(robot=...)")

    def _preprocessing(self) -> Preprocessing | None:
        p = self.preprocessing
        if p is None or isinstance(p, Preprocessing):
            return p
        if isinstance(p, dict):
            try:
                return Preprocessing(**p)
            except TypeError as exc:
                raise ConfigError(f"preprocessing: {exc}", field="preprocessing") from None
        raise ConfigError(f"preprocessing: expected Preprocessing settings or a dict of them, got {type(p).__name__}",
                          field="preprocessing")

    def _model(self):
        if not hasattr(self, "model_"):
            raise NotFittedError("this Identifier is not fitted yet: call fit(t, q, tau) or fit(recording), or Identifier.from_config(config), "
                                 "first")
        return self.model_

    def summary(self) -> str:
        """The fitted identification in a few lines (:meth:`IdentificationResult.summary
        <dynid.identification.result.IdentificationResult.summary>`).

        Returns
        -------
        str

        Raises
        ------
        NotFittedError
            Before :meth:`fit` or :meth:`from_config`.
        """
        self._model()
        return self.result_.summary()

    def parameters(self, estimate: str | None = None):
        """The base parameters of an estimate by name, with σ where the estimator gives it.

        Parameters
        ----------
        estimate : str, optional
            A label such as ``"dynid WLS"`` or a key such as ``"wls"``; default the main one.

        Returns
        -------
        dynid.identification.fitted_model.Parameters
        """
        return self._model().parameters(estimate)

    @keyword_only_after_data
    def predict(self, t, q=None, dq=None, ddq=None, *, estimate: str | None = None) -> np.ndarray:
        """Joint torques of the identified model along a raw log, prepared as the fit prepared its own
        (:meth:`dynid.identification.fitted_model.IdentifiedModel.predict`): ``predict(t, q)``, symmetric with
        ``fit(t, q, tau)``; ``predict(recording)``; states of one's own: :meth:`predict_states`.

        Parameters
        ----------
        t : (N,) array [s], or a recording
        q : (N, n_dof) array [rad]
        dq : (N, n_dof) array [rad/s], optional
            Measured velocities.
        ddq : None
            Only in the earlier state form ``predict(q, dq, ddq)`` (a FutureWarning).
        estimate : str, optional
            Label of the estimate (default the main one).

        Returns
        -------
        (N, n_dof) array [N·m]
        """
        if np.ndim(t) == 2 and q is not None and dq is not None:  # the earlier predict(q, dq, ddq)

            warnings.warn("predict(q, dq, ddq) is predict_states(q, dq, ddq): predict(t, q) prepares a raw log as the "
                          "fit did", FutureWarning, stacklevel=2)
            return self._model().predict_states(t, q, dq, estimate=estimate)
        return self._model().predict(t, q, dq, ddq, estimate=estimate)

    def validate(self, t, q=None, tau=None, *, estimate: str | None = None):
        """The paper's metrics (eq. 18's correlation, RMSE, relative error) of the estimates on another log, on the
        samples ``dynid validate`` scores (:meth:`dynid.identification.fitted_model.IdentifiedModel.validate`).

        Parameters
        ----------
        t : (N,) array [s], or a recording
            A raw log's time stamps (with ``q`` and ``tau``, as :meth:`score` takes them), or a log as
            :func:`dynid.load_recording` or :func:`dynid.simulated_log` give it.
        q, tau : (N, n_dof) arrays [rad, N·m], optional
            Its positions and measured torques (with time stamps).
        estimate : str, optional
            Only this estimate (default every one).

        Returns
        -------
        dynid.validation.torques.TorqueComparison
            ``dynid.summary`` of it prints what ``dynid validate`` does.

        Raises
        ------
        NotFittedError
            Before :meth:`fit` or :meth:`from_config`.
        """
        return self._model().validate(t, q, tau, estimate=estimate)

    def predict_states(self, q, dq, ddq, *, estimate: str | None = None) -> np.ndarray:
        """Joint torques at states one computed oneself (:meth:`dynid.identification.fitted_model.IdentifiedModel.predict_states`).

        Parameters
        ----------
        q, dq, ddq : (N, n_dof) arrays [rad, rad/s, rad/s²]
        estimate : str, optional

        Returns
        -------
        (N, n_dof) array [N·m]
        """
        return self._model().predict_states(q, dq, ddq, estimate=estimate)

    def score(self, t, q=None, tau=None, *args, estimate: str | None = None) -> float:
        """R² of the predicted torques of a raw log (``score(t, q, tau)``, symmetric with ``fit``) or of a recording
        (``score(recording)``), on the samples ``dynid validate`` scores
        (:meth:`dynid.identification.fitted_model.IdentifiedModel.score`).

        The earlier form ``score(q, dq, ddq, tau)`` on states of one's own still works, with a FutureWarning.

        Parameters
        ----------
        t : (N,) array [s], or a recording
        q : (N, n_dof) array [rad]
        tau : (N, n_dof) array [N·m]
        *args
            The earlier form's torques.
        estimate : str, optional
            Label or key (default the main estimate).

        Returns
        -------
        float
            1 is a perfect prediction.
        """
        if np.ndim(t) == 2 and args:  # the earlier score(q, dq, ddq, tau)

            warnings.warn("score(q, dq, ddq, tau) scores states of one's own: score(t, q, tau) prepares a raw log as the "
                          "fit did", FutureWarning, stacklevel=2)
            measured = np.asarray(args[0], dtype=float)
            pred = self._model().predict_states(t, q, tau, estimate=estimate)
            return 1.0 - float(np.sum((measured - pred) ** 2)) / float(np.sum((measured - measured.mean(axis=0)) ** 2))
        return self._model().score(t, q, tau, estimate=estimate)

    def relative_error(self, t, q=None, tau=None, *, estimate: str | None = None) -> float:
        """The global relative torque error [%] ``dynid validate`` prints for a raw log (``relative_error(t, q, tau)``)
        or a recording, on the same samples
        (:meth:`dynid.identification.fitted_model.IdentifiedModel.relative_error`).

        Parameters
        ----------
        t : (N,) array [s], or a recording
        q : (N, n_dof) array [rad]
        tau : (N, n_dof) array [N·m]
        estimate : str, optional
            Label or key (default the main estimate).

        Returns
        -------
        float [%]
        """
        return self._model().relative_error(t, q, tau, estimate=estimate)

    def save(self, path: str | Path) -> Path:
        """Write the identification's results.json (read back by :func:`dynid.load_results`).

        Parameters
        ----------
        path : str or Path
            A file, or a folder to hold ``results.json`` (one that exists, or a path without a suffix; a missing
            folder is created).

        Returns
        -------
        Path
            The file written.

        Raises
        ------
        ConfigError
            A folder that cannot be created.
        NotFittedError
            Before :meth:`fit` or :meth:`from_config`.
        """
        return self._model().save(path)

    def __repr__(self) -> str:
        given = {k: v for k, v in self.get_params().items() if v is not None}

        def short(v) -> str:  # a Robot object by its name and joints (its arrays made a repr of 40 lines)
            return f"<Robot {v.name!r}, {v.n_dof} joints>" if isinstance(v, Robot) else repr(v)

        return f"Identifier({', '.join(f'{k}={short(v)}' for k, v in given.items())})"
