"""Each joint's Gram matrix of a block of regressor rows, by BLAS."""

from __future__ import annotations

import numpy as np


def joint_gram(a: np.ndarray, b: np.ndarray | None = None) -> np.ndarray:
    """``Σ_m a[m, j, :]ᵀ b[m, j, :]`` for every joint ``j``: ``einsum("mjc,mjd->jcd", a, b)`` as one batched matrix
    product (BLAS; equal to rounding, and faster: benchmarks/NOTEBOOK.md).

    Parameters
    ----------
    a : (M, n_dof, c) array
    b : (M, n_dof, d) array, optional
        ``a`` by default.

    Returns
    -------
    (n_dof, c, d) ndarray
    """
    a = np.asarray(a, dtype=float)
    b = a if b is None else np.asarray(b, dtype=float)
    return np.matmul(a.transpose(1, 2, 0), b.transpose(1, 0, 2))
