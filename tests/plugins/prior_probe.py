"""A plugin estimator that asks for the documented ``prior`` (the robot file's standard parameters): registered as
"prior_probe_test"; it records what it was given and returns least squares."""

import numpy as np

from dynid.estimators import Estimator, register, weighted_rows


class PriorProbe(Estimator):
    """Least squares that keeps the prior it was built with (``given_prior_``; every fit's also in :attr:`seen`)."""

    seen: list = []

    def __init__(self, *, prior=None):
        self.prior = prior

    def fit(self, w, tau, sample_weight=None):
        w, tau = weighted_rows(w, tau, sample_weight, 0.5)
        self.given_prior_ = None if self.prior is None else np.array(self.prior, dtype=float)
        PriorProbe.seen.append(self.given_prior_)
        self.params_ = np.linalg.lstsq(np.asarray(w, dtype=float), np.asarray(tau, dtype=float).reshape(-1), rcond=None)[0]
        return self


register("prior_probe_test", PriorProbe, label="PriorProbe", description="records its prior (a test's estimator)",
         space="standard", replace=True)
