"""Plugin estimators that ask for the documented ``prior`` (the robot file's standard parameters) and record what they
were given, returning least squares: ``prior_probe_test`` reads it from the problem given to ``fit`` (the contract),
``prior_probe_legacy_test`` from its constructor (a plugin written before ``fit`` took the problem)."""

import numpy as np

from dynid.estimators import Estimator, register, weighted_rows


def _least_squares(est, w, tau, sample_weight, prior):
    w, tau = weighted_rows(w, tau, sample_weight, 0.5)
    est.given_prior_ = None if prior is None else np.array(prior, dtype=float)
    type(est).seen.append(est.given_prior_)
    est.params_ = np.linalg.lstsq(np.asarray(w, dtype=float), np.asarray(tau, dtype=float).reshape(-1), rcond=None)[0]
    return est


class PriorProbe(Estimator):
    """Least squares that keeps the problem's prior (``given_prior_``; every fit's also in :attr:`seen`)."""

    seen: list = []
    PROBLEM_FIELDS = ("prior",)

    def fit(self, w, tau, sample_weight=None, *, problem=None):
        return _least_squares(self, w, tau, sample_weight, self.take_problem(problem).prior)


class LegacyPriorProbe(Estimator):
    """Least squares that keeps the prior it was built with (``given_prior_``; every fit's also in :attr:`seen`)."""

    seen: list = []

    def __init__(self, *, prior=None):
        self.prior = prior

    def fit(self, w, tau, sample_weight=None):
        return _least_squares(self, w, tau, sample_weight, self.prior)


register("prior_probe_test", PriorProbe, label="PriorProbe", description="records its prior (a test's estimator)",
         space="standard", replace=True)
register("prior_probe_legacy_test", LegacyPriorProbe, label="LegacyPriorProbe", space="standard", replace=True,
         description="records the prior it was built with (a test's estimator)")
