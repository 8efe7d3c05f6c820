"""Base (minimal) parameters by QR decomposition of the observation matrix on random samples.

Columns of ``W`` are taken in the standard-parameter order (link 1 first, eq. 5 order inside a
link). A QR decomposition *without* pivoting keeps a column when it is independent of the columns
before it, so each dependent parameter is regrouped into earlier ones — the same choice as Khalil's
symbolic rules (e.g. ``ZZ1R = ZZ1 + YY2 + YY3 + …``, ``XX2R = XX2 - YY2``). Refs: Gautier, "Numerical
calculation of the base inertial parameters of robots", J. Robot. Syst. 8(4), 1991; Khalil &
Dombre, "Modeling, Identification and Control of Robots", 2002, ch. 12.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.linalg

from .._util.keywords import keyword_only_after_data
from .._util.reprs import short_repr
from ..conventions import unit_of
from ..exceptions import ConfigError, IdentifiabilityError
from ..model.loading import as_robot
from ..model.robot import Robot
from .regressor import observation_matrix


@short_repr
@dataclass(frozen=True)
class BaseParameters:
    """Selection and regrouping of the standard parameters into the base parameters.

    Invariant: ``W @ phi == W[:, independent] @ (regrouping @ phi)`` for every observation matrix
    ``W`` of the robot.

    Attributes
    ----------
    names : tuple of str
        Base parameter names; an ``R`` suffix marks a regrouped one (``"ZZ1R"``).
    standard_names : tuple of str
    independent : (n_base,) int array
        Columns of ``W`` kept (the base regressor is ``W[:, independent]``).
    regrouping : (n_base, n_params) array
        ``beta = regrouping @ phi``.
    expressions : tuple of str
        Readable regroupings, e.g. ``"ZZ1R = ZZ1 + YY2 + 0.4624·M3"``.
    prismatic : tuple of bool
        Which joints slide (their drive terms in N, kg, N·s/m: :meth:`unit`); empty for a revolute chain.
    """

    names: tuple[str, ...]
    standard_names: tuple[str, ...]
    independent: np.ndarray
    regrouping: np.ndarray
    expressions: tuple[str, ...]
    prismatic: tuple[bool, ...] = ()

    def unit(self, name: str) -> str:
        """The unit of a base or standard parameter (:func:`dynid.conventions.unit_of`).

        Parameters
        ----------
        name : str

        Returns
        -------
        str
        """
        return unit_of(name, self.prismatic)

    @property
    def n_base(self) -> int:
        """Number of base parameters."""
        return len(self.names)

    def base_from_standard(self, phi: np.ndarray) -> np.ndarray:
        """Base parameters of a standard vector: ``beta = regrouping @ phi``.

        Parameters
        ----------
        phi : (n_params,) array
            Standard parameters, SI units.

        Returns
        -------
        (n_base,) ndarray
        """
        return self.regrouping @ np.asarray(phi, dtype=float)

    def base_std(self, std: np.ndarray) -> tuple[np.ndarray, tuple[str, ...]]:
        """Standard deviations of the base parameters that are one standard parameter each, from the standard
        parameters' (a prior's σ: the others' cannot be carried, since a regrouped one mixes terms without one).

        Parameters
        ----------
        std : (n_params,) array
            Each standard parameter's σ, NaN where none.

        Returns
        -------
        base_std : (n_base,) ndarray
            ``|c|·σ`` of a base parameter ``c·φ_k`` whose ``φ_k`` has a σ; NaN elsewhere.
        not_carried : tuple of str
            The standard parameters with a σ that no base parameter is alone (regrouped, or not in the model's
            torques).
        """
        std = np.asarray(std, dtype=float)
        out = np.full(self.n_base, np.nan)
        not_carried = []
        for k in np.flatnonzero(np.isfinite(std)):
            rows = np.flatnonzero(self.regrouping[:, k])
            if rows.size == 1 and np.count_nonzero(self.regrouping[rows[0]]) == 1:
                out[rows[0]] = abs(self.regrouping[rows[0], k]) * std[k]
            else:
                not_carried.append(self.standard_names[k])
        return out, tuple(not_carried)

    def base_from_named(self, values: dict) -> np.ndarray:
        """Base parameters of standard parameters given by name.

        Parameters
        ----------
        values : dict
            ``{"ZZ1": 0.3, …}``; a standard parameter not given is 0, a name this robot does not have is ignored.

        Returns
        -------
        (n_base,) ndarray
        """
        return self.regrouping @ np.array([float(values.get(n, 0.0)) for n in self.standard_names])

    def standard_from_base(self, beta: np.ndarray, reference: np.ndarray | None = None) -> np.ndarray:
        """A standard vector whose base parameters are ``beta``.

        Without ``reference``: ``beta`` on the kept columns, 0 elsewhere. With a reference standard vector (e.g. nominal
        values): ``reference + E (beta - regrouping @ reference)``, which keeps the reference's masses and other
        unidentifiable parameters (so a rigid-body simulator can use it).

        Parameters
        ----------
        beta : (n_base,) array
        reference : (n_params,) array, optional

        Returns
        -------
        (n_params,) ndarray
        """
        ref = np.zeros(len(self.standard_names)) if reference is None else np.asarray(reference, dtype=float).copy()
        ref[self.independent] += np.asarray(beta, dtype=float) - self.regrouping @ ref
        return ref

    def base_observation(self, w: np.ndarray) -> np.ndarray:
        """Base regressor: the kept columns of the standard one.

        Parameters
        ----------
        w : (..., n_params) array

        Returns
        -------
        (..., n_base) ndarray
        """
        return w[..., self.independent]

    def to_dict(self) -> dict:
        """Names and regrouping expressions, JSON-ready.

        Returns
        -------
        dict
            ``names`` and ``expressions``, lists of str.
        """
        return {"names": list(self.names), "expressions": list(self.expressions)}


def _format_term(coef: float, name: str, first: bool) -> str:
    sign = "-" if coef < 0 else "+"
    mag = abs(coef)
    body = name if abs(mag - 1.0) < 1e-9 else f"{mag:.6g}·{name}"
    if first:
        return body if sign == "+" else f"-{body}"
    return f" {sign} {body}"


@keyword_only_after_data
def base_parameters(robot: Robot | str | Path, *, rng: np.random.Generator | int | None = 0, n_samples: int = 400,
                    tol: float = 1e-8) -> BaseParameters:
    """Compute the base parameters of ``robot`` numerically.

    Parameters
    ----------
    robot : Robot, str or Path
        A built-in robot's name or a description's path is loaded (:func:`dynid.model.loading.as_robot`).
    rng : Generator or int seed
        Random states are drawn uniformly within the joint limits (±π where unlimited).
    n_samples : int
        Number of random states; ``n_samples * n_dof`` must exceed the number of parameters.
    tol : float
        Relative threshold on ``|R_ii| / max|R_ii|`` under which a column is dependent.

    Returns
    -------
    BaseParameters

    Raises
    ------
    IdentifiabilityError
        If the rank found by QR disagrees with the SVD rank (numerically ill-posed chain).
    ConfigError
        ``n_samples`` not a positive integer, or ``tol`` not in (0, 1).
    """
    if isinstance(n_samples, bool) or not isinstance(n_samples, (int, np.integer)) or n_samples < 1:
        raise ConfigError(f"base_parameters: n_samples: expected a positive integer, got {n_samples!r}")
    if not 0 < tol < 1:
        raise ConfigError(f"base_parameters: tol: expected a relative tolerance in (0, 1), got {tol!r}")
    robot = as_robot(robot)
    rng = np.random.default_rng(rng)
    n = robot.n_dof
    lo, hi = robot.limits.position_span()
    q = rng.uniform(lo, hi, (n_samples, n))
    dq = rng.uniform(-1.0, 1.0, (n_samples, n)) * 2.0
    ddq = rng.uniform(-1.0, 1.0, (n_samples, n)) * 5.0
    if {"fca", "fst"} & set(robot.drive_terms) or np.any(robot.coulomb_velocity > 0):
        # velocity-shaped friction (Stribeck, smooth Coulomb) lives at low speed, asymmetric Coulomb friction differs
        # from an offset only at rest: speeds spread over four decades, and some states at rest
        dq = np.sign(dq) * 10.0 ** rng.uniform(-4.0, 0.3, (n_samples, n))
        dq[rng.uniform(size=(n_samples, n)) < 0.2] = 0.0
    w = observation_matrix(robot, q, dq, ddq)
    r = scipy.linalg.qr(w, mode="r")[0]
    diag = np.abs(np.diag(r))
    keep = diag > tol * diag.max()
    indep = np.flatnonzero(keep)
    dep = np.flatnonzero(~keep)
    sv = np.linalg.svd(w, compute_uv=False)
    rank = int(np.sum(sv > tol * sv[0]))
    if rank != indep.size:
        raise IdentifiabilityError(f"base parameters of {robot.name!r}: QR kept {indep.size} columns but the SVD rank is {rank}")
    w1, w2 = w[:, indep], w[:, dep]
    coef = np.linalg.lstsq(w1, w2, rcond=None)[0] if dep.size else np.zeros((indep.size, 0))
    coef[np.abs(coef) < 1e-9] = 0.0
    resid = np.abs(w1 @ coef - w2).max() if dep.size else 0.0
    if resid > 1e-6 * max(1.0, np.abs(w).max()):
        raise IdentifiabilityError(f"base parameters of {robot.name!r}: regrouping residual {resid:.3g} is too large")
    names_std = robot.parameter_names
    regroup = np.zeros((indep.size, len(names_std)))
    regroup[np.arange(indep.size), indep] = 1.0
    regroup[:, dep] = coef
    names, exprs = [], []
    for b, col in enumerate(indep):
        others = [(coef[b, d], names_std[c]) for d, c in enumerate(dep) if coef[b, d] != 0.0]
        name = names_std[col] + ("R" if others else "")
        names.append(name)
        expr = names_std[col] + "".join(_format_term(cf, nm, False) for cf, nm in others)
        exprs.append(f"{name} = {expr}")
    sliding = tuple(bool(p) for p in robot.prismatic) if robot.prismatic.any() else ()
    return BaseParameters(tuple(names), names_std, indep, regroup, tuple(exprs), sliding)
