"""What an estimator sees of one identification problem (:class:`FitData`: the observation rows, the joints, the
search box, the eq. 9 weights, the prior and the layout), and the box searches' budget (:class:`SearchBudget`, the
paper's §4.1)."""

from __future__ import annotations

import dataclasses
import inspect
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from .._util.reprs import short_value

if TYPE_CHECKING:
    from ..dynamics.base_parameters import BaseParameters

__all__ = ["SearchBudget", "FitData", "with_problem", "MOVED_TO_PROBLEM"]

MOVED_TO_PROBLEM = frozenset({"n_dof", "bounds", "weights", "prior", "links", "nonnegative", "joint_weights",
                              "base_prior", "base_prior_std", "prior_std"})
"""The estimators' constructor arguments that are the problem's since 0.2.0 (``fit(..., problem=FitData(...))``):
refused by a built-in's constructor, still filled in a plugin's that names them."""


@dataclass(frozen=True)
class SearchBudget:
    """ABC settings of §4.1; DE and PSO get ``10 · colony_size · maxiter`` evaluations.

    Attributes
    ----------
    colony_size : int
        ABC's ``Ns`` (employed plus onlooker bees); PSO's swarm size.
    limit : int
        ABC's scout limit.
    maxiter : int
        ABC's ``Tmax``.
    """

    colony_size: int = 30
    limit: int = 15
    maxiter: int = 50

    @property
    def evaluations(self) -> int:
        """Evaluations of eq. 9 given to DE and PSO: ``10 · colony_size · maxiter``."""
        return 10 * self.colony_size * self.maxiter


@dataclass
class FitData:
    """What the estimators see of one identification problem: given to an estimator's ``fit`` as ``problem=``
    (each estimator reads the fields of its ``PROBLEM_FIELDS``), every field optional.

    Examples
    --------
    >>> import numpy as np
    >>> from dynid.estimators import BeeColonyEstimator, FitData
    >>> w, beta = np.random.default_rng(0).normal(size=(60, 2)), np.array([1.0, -2.0])
    >>> box = FitData(n_dof=3, bounds=np.array([[0.0, 2.0], [-3.0, -1.0]]))
    >>> est = BeeColonyEstimator(maxiter=30, rng=0).fit(w, w @ beta, problem=box)
    >>> bool(np.abs(est.params_ - beta).max() < 0.1)
    True

    Attributes
    ----------
    w_base : (M, n_base) array, or None
        Base observation matrix, row ``k·n_dof + j`` = sample ``k``, joint ``j`` (None when the rows were streamed
        into the estimators that accumulate, and none needs them in memory).
    tau : (M,) array or None
        Measured torques [N·m], same rows.
    n_dof : int or None
        Joints per sample (None: inferred from torques given as (N, n_dof), else 1).
    bounds : (n_base, 2) array or None
        Search box of the box searches and LAD.
    base : BaseParameters or None
        The base-parameter map (``sdp`` maps its standard estimate through it).
    w_standard : (M, p) array, optional
        Standard observation matrix (estimators of the standard space, ``sdp``, fitted on arrays).
    layout : tuple, optional
        ``(links, nonnegative)`` of :func:`dynid.dynamics.layout.consistency_layout` (``sdp``).
    prior : (p,) array, optional
        Standard parameters the SDP pulls unidentifiable directions towards.
    weights : (n_dof,) array, optional
        ``delta`` of eq. 9.
    joint_weights : (n_dof,) array, optional
        Row weight of each joint for the estimators that take them (``sdp``: the WLS weights of the main
        estimate on real logs).
    base_prior : (n_base,) array, optional
        Base parameters least squares keeps along the directions the rows do not determine (the nominal ones).
    prior_std : (p,) array, optional
        Standard deviation of ``prior``'s values where the description states one (NaN elsewhere): ``sdp`` pulls
        those as a Gaussian prior (:meth:`dynid.model.robot.Robot.prior_sigmas`).
    base_prior_std : (n_base,) array, optional
        The same of ``base_prior``'s values, for the base parameters that are one stated standard parameter each
        (NaN elsewhere): least squares pulls those as a Gaussian prior.
    """

    w_base: Any = None
    tau: Any = None
    n_dof: int | None = None
    bounds: Any = None
    base: BaseParameters | None = None
    w_standard: Any = None
    layout: tuple | None = None
    prior: Any = None
    weights: Any = None
    joint_weights: Any = None
    base_prior: Any = None
    prior_std: Any = None
    base_prior_std: Any = None

    def __repr__(self) -> str:
        """The fields that are set, each as :func:`dynid._util.reprs.short_value` shows it (``FitData(n_dof=6,
        prior=<array (72,)>)``).

        Returns
        -------
        str
        """
        values = ((f.name, getattr(self, f.name)) for f in dataclasses.fields(self))
        shown = [f"{name}={short_value(v)}" for name, v in values if v is not None and not (isinstance(v, dict) and not v)]
        return f"FitData({', '.join(shown)})"


def with_problem(method, data: FitData) -> dict:
    """``{"problem": data}`` when ``method`` (an estimator's ``fit`` or ``solve``) takes the problem, else nothing (a
    plugin written before ``fit`` took it: :data:`dynid.estimators.registry.PROBLEM_FILLED`).

    Parameters
    ----------
    method : callable
    data : FitData

    Returns
    -------
    dict
        Keyword arguments for ``method``.
    """
    parameters = inspect.signature(method).parameters.values()
    takes = any(p.name == "problem" or p.kind is inspect.Parameter.VAR_KEYWORD for p in parameters)
    return {"problem": data} if takes else {}
