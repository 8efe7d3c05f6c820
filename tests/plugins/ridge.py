"""A new estimator in one file: ridge regression, registered as "ridge_test". Importing this module is all it takes
for dynid identify, run, montecarlo and Identifier to use it."""

import numpy as np

from dynid.estimators import Estimator, register, weighted_rows


class Ridge(Estimator):
    """``argmin Σ s_i (τ_i - W_i p)² + α·(mean squared column norm)·||p||²`` (Tikhonov)."""

    def __init__(self, *, alpha: float = 1e-9):
        self.alpha = alpha

    def fit(self, w, tau, sample_weight=None):
        w, tau = weighted_rows(w, tau, sample_weight, 0.5)
        w = np.asarray(w, dtype=float)
        tau = np.asarray(tau, dtype=float).reshape(-1)
        gram = w.T @ w
        self.params_ = np.linalg.solve(gram + self.alpha * np.trace(gram) / gram.shape[0] * np.eye(gram.shape[0]), w.T @ tau)
        return self


register("ridge_test", Ridge, label="Ridge", description="ridge regression (a test's estimator)", replace=True)
