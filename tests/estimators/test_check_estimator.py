"""check_estimator: every registered base-space estimator passes it, and each of its checks catches the estimator
that breaks it (a plugin's author runs it on theirs)."""

import numpy as np
import pytest

from dynid.estimators import Estimator, check_estimator, register, unregister
from dynid.estimators import registry as reg
from dynid.estimators.base import weighted_rows
from dynid.estimators.contract import EstimatorCheckError

BASE_SPACE = [k for k in reg.keys() if reg.spec(k).space == "base"]


@pytest.mark.parametrize("key", BASE_SPACE)
def test_every_registered_base_space_estimator_passes(key):
    check_estimator(key)


def test_a_standard_space_estimator_is_refused_in_one_line():
    with pytest.raises(EstimatorCheckError, match="sdp: estimates standard parameters, which need a robot's layout"):
        check_estimator("sdp")


class _LeastSquares(Estimator):
    def __init__(self, *, n_dof=None):
        self.n_dof = n_dof

    def solution(self, w, tau):
        return np.linalg.lstsq(w, np.asarray(tau, dtype=float).reshape(-1), rcond=None)[0]

    def fit(self, w, tau, sample_weight=None):
        self.params_ = self.solution(*weighted_rows(w, tau, sample_weight, 0.5))
        return self


class _NoSampleWeight(_LeastSquares):
    def fit(self, w, tau):
        self.params_ = self.solution(w, tau)
        return self


class _WeightsMisread(_LeastSquares):
    def fit(self, w, tau, sample_weight=None):  # the weights taken as the row scale of an absolute loss
        self.params_ = self.solution(*weighted_rows(w, tau, None if sample_weight is None else 2 * sample_weight, 1.0))
        self.params_ = self.params_ * (1.0 if sample_weight is None else 1.001)
        return self


class _Biased(_LeastSquares):
    def fit(self, w, tau):
        self.params_ = 1.01 * self.solution(w, tau)
        return self


class _Unseeded(_LeastSquares):
    def fit(self, w, tau):
        self.params_ = self.solution(w, tau) + 1e-9 * np.random.default_rng().standard_normal(w.shape[1])
        return self


class _InPlace(_LeastSquares):
    def fit(self, w, tau):
        tau -= 0.0 * tau + 1e-12  # the caller's array, changed
        self.params_ = self.solution(w, tau)
        return self


class _WrongLength(_LeastSquares):
    def fit(self, w, tau):
        self.params_ = self.solution(w, tau)[:-1]
        return self


class _BoxCentre(Estimator):
    def __init__(self, *, bounds=None, n_dof=None):
        self.bounds, self.n_dof = bounds, n_dof

    def fit(self, w, tau):
        self.params_ = np.asarray(self.bounds, dtype=float).mean(axis=1)
        return self


@pytest.mark.parametrize("cls, box, said", [
    (_LeastSquares, False, None),
    (_Biased, False, "more than 5 σ from the truth"),
    (_Unseeded, False, "the same rng gave other parameters"),
    (_InPlace, False, "fit changed the W or tau it was given"),
    (_WrongLength, False, r"fit failed on a well-posed problem: .*returned parameters of shape \(5,\), expected \(6,\)"),
    (_BoxCentre, True, "did not improve eq. 9 on the box's centre"),
    (_NoSampleWeight, False, r"fit takes no sample_weight: the contract is fit\(W, tau, sample_weight=None\)"),
    (_WeightsMisread, False, "sample_weight of ones gave other parameters than no sample_weight"),
])
def test_each_check_catches_the_estimator_that_breaks_it(cls, box, said):
    register("checked", cls, needs_box=box, replace=True)
    try:
        if said is None:
            check_estimator("checked")
        else:
            with pytest.raises(EstimatorCheckError, match=said):
                check_estimator("checked")
    finally:
        unregister("checked")


def test_a_class_is_checked_before_it_is_registered_and_the_registry_stays_as_it_was():
    from dynid.estimators.bee_colony import BeeColonyEstimator

    before = dict(reg._REGISTRY)
    check_estimator(_LeastSquares)
    check_estimator(BeeColonyEstimator)  # a box search: checked inside its box, against the box's centre
    with pytest.raises(EstimatorCheckError, match=r"^_Biased: estimates \d parameter\(s\) more than 5 σ from the truth"):
        check_estimator(_Biased)
    with pytest.raises(EstimatorCheckError, match="^_NoSampleWeight: fit takes no sample_weight"):
        check_estimator(_NoSampleWeight)
    assert reg._REGISTRY == before


def test_a_class_named_like_a_registered_key_leaves_that_key_as_it_was():
    register("check__leastsquares", _Biased, replace=True)
    try:
        check_estimator(_LeastSquares)  # registered for the check under the same key, then the earlier entry back
        assert reg.spec("check__leastsquares").build is _Biased
    finally:
        unregister("check__leastsquares")


def test_neither_a_key_nor_an_estimator_class_is_a_type_error():
    with pytest.raises(TypeError, match="expected a registry key or an Estimator subclass, got 3"):
        check_estimator(3)
