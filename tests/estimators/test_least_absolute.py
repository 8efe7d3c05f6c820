"""LAD on long problems: the banded ("globbing") LP gives the exact minimiser of the whole problem."""

import numpy as np
import pytest

from dynid.estimators import least_absolute as la
from dynid.estimators.base import paper_objective
from dynid.estimators.problem import FitData


def _problem(m=30_000, p=8, n_dof=2, seed=0):
    rng = np.random.default_rng(seed)
    w = rng.standard_normal((m, p))
    beta = rng.uniform(-2, 2, p)
    tau = w @ beta + rng.standard_t(2, m)  # heavy tails: LAD and least squares differ
    bounds = np.column_stack([beta - 3, beta + 3])
    bounds[0] = [beta[0] + 0.5, beta[0] + 3]  # one bound active at the optimum
    return w, tau, bounds, n_dof


def _direct(w, tau, bounds, n_dof):
    m = w.shape[0]
    row_w = np.full(m, 1.0 / (m // n_dof))
    none = np.array([], dtype=int)
    beta, _ = la._dual_lp(w, tau, row_w, bounds[:, 0], bounds[:, 1], rows=np.arange(m), fixed=none, fixed_y=none)
    return beta


@pytest.mark.parametrize("band", [la.BAND, 1])  # band 1: the first band is too narrow, the check must widen it
def test_banded_lad_equals_the_lp_on_every_row(monkeypatch, band):
    monkeypatch.setattr(la, "BAND", band)
    w, tau, bounds, n_dof = _problem()
    calls = []
    real = la._dual_lp
    monkeypatch.setattr(la, "_dual_lp", lambda *a, **k: calls.append(k["rows"].size) or real(*a, **k))
    est = la.LeastAbsoluteDeviations().fit(w, tau, problem=FitData(n_dof=n_dof, bounds=bounds))
    if band > 1:
        assert max(calls) < w.shape[0] // 2  # it solved on a band, not on every row
    else:
        assert len(calls) > 2  # the check found fixed rows across the fit and widened the band
    monkeypatch.setattr(la, "_dual_lp", real)
    exact = _direct(w, tau, bounds, n_dof)
    f = lambda b: float(paper_objective(tau - w @ b, n_dof))
    assert f(est.params_) == pytest.approx(f(exact), rel=1e-12)
    np.testing.assert_allclose(est.params_, exact, atol=1e-8)
    assert est.params_[0] == pytest.approx(bounds[0, 0])  # the active bound holds


def test_a_wide_box_on_poorly_conditioned_rows_needs_one_band(monkeypatch):
    """The paper's ER-16 data at 200 Hz in the wide box (±(2|β_OLS|+1), no bound active): LAD on the evenly
    spaced pilot rows is far from the optimum there, and its band failed the check twice before the LP on
    every row was solved. The pilot is now whichever of that fit and least squares in the box fits every
    row better: the first band holds the optimum (two LPs in all), and it is the exact minimiser."""
    from dynid.studies.paper import PaperExperimentConfig, run_paper_experiment

    calls = []
    real = la._dual_lp
    monkeypatch.setattr(la, "_dual_lp", lambda *a, **k: calls.append((a, k)) or real(*a, **k))
    result = run_paper_experiment(PaperExperimentConfig(estimators=("lad",), bootstrap=0, rate=200.0,
                                                        abc_bounds="scaled"))
    w, tau, row_w, lo, hi = calls[0][0][:5]
    assert len(calls) == 2 and calls[1][1]["rows"].size < w.shape[0] // 2
    none = np.array([], dtype=int)
    exact, _ = real(w, tau, row_w, lo, hi, rows=np.arange(w.shape[0]), fixed=none, fixed_y=none)
    np.testing.assert_allclose(result.estimates["lad"].params, exact, atol=1e-8 * np.abs(exact).max())
