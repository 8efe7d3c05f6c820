"""Validators used at the public boundary: they return clean float64 arrays or raise one-line errors."""

from __future__ import annotations

import numpy as np

from ..exceptions import ShapeError


def check_trajectory_array(x, n_dof: int, name: str = "q") -> np.ndarray:
    """An array as a C-contiguous float64 array of shape (N, n_dof).

    Parameters
    ----------
    x : array_like
    n_dof : int
    name : str
        Named in the error.

    Returns
    -------
    (N, n_dof) ndarray

    Raises
    ------
    ShapeError
        If ``x`` is not 2-D with ``n_dof`` columns or holds non-finite values.
    """
    a = np.ascontiguousarray(x, dtype=np.float64)
    if a.ndim == 1 and n_dof == 1:
        a = a[:, None]
    if a.ndim != 2 or a.shape[1] != n_dof:
        hint = ""
        if a.ndim == 2 and a.shape[0] == n_dof:
            hint = ": joints-first data? transpose it"
        raise ShapeError(f"expected {name} with shape (N, {n_dof}), got {a.shape}{hint}")
    if not np.all(np.isfinite(a)):
        row = int(np.argwhere(~np.isfinite(a))[0, 0])
        raise ShapeError(f"{name} holds a NaN or infinite value at sample {row}")
    return a


def check_same_length(**arrays: np.ndarray) -> int:
    """Check that arrays have the same number of samples (axis 0).

    Parameters
    ----------
    **arrays : ndarray
        Named arrays; the names appear in the error.

    Returns
    -------
    int
        The common length N.

    Raises
    ------
    ShapeError
        If the lengths differ.
    """
    lengths = {k: len(v) for k, v in arrays.items()}
    if len(set(lengths.values())) > 1:
        raise ShapeError(f"expected the same number of samples, got {lengths}")
    return next(iter(lengths.values()))


def check_vector(x, n: int, name: str) -> np.ndarray:
    """A float64 vector of a given length (a scalar is broadcast).

    Parameters
    ----------
    x : float or array_like
    n : int
    name : str
        Named in the error.

    Returns
    -------
    (n,) ndarray

    Raises
    ------
    ShapeError
        A vector of another length.
    """
    a = np.asarray(x, dtype=np.float64)
    if a.ndim == 0:
        a = np.full(n, float(a))
    if a.shape != (n,):
        raise ShapeError(f"expected {name} with shape ({n},), got {a.shape}")
    return a


def check_states(q, dq, ddq, n_dof: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Joint positions, velocities and accelerations as (N, n_dof) float64 arrays of one length.

    Parameters
    ----------
    q, dq, ddq : (N, n_dof) array_like
        [rad], [rad/s], [rad/s²].
    n_dof : int

    Returns
    -------
    q, dq, ddq : (N, n_dof) ndarray
    n : int
        N.

    Raises
    ------
    ShapeError
        If an input is not (N, n_dof), holds NaN, or the lengths differ.
    """
    q = check_trajectory_array(q, n_dof, "q")
    dq = check_trajectory_array(dq, n_dof, "dq")
    ddq = check_trajectory_array(ddq, n_dof, "ddq")
    return q, dq, ddq, check_same_length(q=q, dq=dq, ddq=ddq)
