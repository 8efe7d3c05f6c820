"""The design criteria's values and gradients against the singular values a test builds its matrix from."""

import numpy as np
import pytest

from dynid.excitation.criteria import log_condition_number


@pytest.mark.parametrize("cond", [1e3, 1e7, 1e13])
def test_log_cond_and_its_gradient_hold_beyond_what_wtw_resolves(cond, rng):
    """W = U diag(σ) Vᵀ built with cond 1e3, 1e7 and 1e13 (the last two beyond what W^T W's eigenvalues resolve to
    1e-6: its smallest eigenvalue is 1e-14 and 1e-26 of its largest, rounding's 1e-16; at 1e13 one CPU's kernels gave a
    log cond of 19.2 for 29.9): the value is log cond
    and the gradient is d log σ_max - d log σ_min = u₁v₁ᵀ/σ₁ - u₆v₆ᵀ/σ₆. A prismatic arm's first excitation start sits
    there, and a flat zero gradient ended its design at its start (cond 1.9e10 kept)."""
    u, _ = np.linalg.qr(rng.normal(size=(200, 6)))
    v, _ = np.linalg.qr(rng.normal(size=(6, 6)))
    sigma = np.geomspace(1.0, 1.0 / cond, 6)
    value, grad = log_condition_number(u @ np.diag(sigma) @ v.T)
    assert value == pytest.approx(np.log(cond), rel=1e-6)
    projected = u.T @ grad @ v  # in the singular bases: diag(1/σ₁, 0, …, 0, -1/σ₆)
    expected = np.zeros((6, 6))
    expected[0, 0], expected[-1, -1] = 1 / sigma[0], -1 / sigma[-1]
    np.testing.assert_allclose(projected * sigma[-1], expected * sigma[-1], atol=1e-4)  # eps·cond: 1e-3 at worst
