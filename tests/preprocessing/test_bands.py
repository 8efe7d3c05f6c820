"""Data-derived preprocessing defaults: the excitation band and the rules that follow from it."""

import numpy as np
import pytest
from scipy import signal

from dynid.exceptions import ConfigError
from dynid.preprocessing.bands import PARALLEL_FACTOR, POSITION_FACTOR, cutoffs_from_band, excitation_band
from dynid.preprocessing.filters import decimation_cutoff, parallel_decimation
from dynid.preprocessing.pipeline import Preprocessing


@pytest.mark.parametrize("f_top", [0.3, 1.2, 4.0])
def test_band_of_a_multisine_is_its_highest_harmonic(rng, f_top):
    """Harmonics up to f_top with equal velocity amplitudes: 99 % of the velocity energy lies at or
    below f_top, and more than 1 % lies in the top harmonic, so the band is f_top (to a bin)."""
    rate, n = 500.0, 20000
    t = np.arange(n) / rate
    freqs = np.linspace(f_top / 4, f_top, 4)
    q = sum(np.sin(2 * np.pi * f * t + rng.uniform(0, 6))[:, None] / f for f in freqs) * np.array([1.0, 0.5])
    q = q + rng.normal(0, 1e-6, q.shape)  # encoder-like noise
    band = excitation_band(q, rate)
    assert abs(band - f_top) <= 3 * rate / n


def test_cutoffs_follow_the_stated_rules():
    d = cutoffs_from_band(0.5, 1000.0)
    assert d.position_cutoff == POSITION_FACTOR * 0.5 and d.parallel_cutoff == PARALLEL_FACTOR * 0.5
    # the largest decimation whose anti-aliasing cutoff is still at or above the parallel cutoff
    assert decimation_cutoff(1000.0, d.decimation) >= d.parallel_cutoff > decimation_cutoff(1000.0, d.decimation + 1)
    capped = cutoffs_from_band(30.0, 100.0)  # a band near Nyquist: capped at 0.8 f_N, no decimation
    assert capped.position_cutoff == capped.parallel_cutoff == 40.0 and capped.decimation == 1


def test_resolved_settings_say_what_was_derived(rng):
    rate = 200.0
    t = np.arange(4000) / rate
    q = np.sin(2 * np.pi * 0.5 * t)[:, None] * np.ones((1, 3))
    s = Preprocessing().resolved(rate, q, measured_velocity=False)
    assert s.band == pytest.approx(0.5, abs=0.1) and s.parallel_cutoff == pytest.approx(PARALLEL_FACTOR * s.band)
    assert "excitation band" in s.derivation and "parallel" in s.derivation
    given = Preprocessing(decimation=4).resolved(rate, q)  # a decimation alone: filtered at its own cutoff
    assert given.parallel_cutoff == pytest.approx(decimation_cutoff(rate, 4)) and given.decimation == 4
    with pytest.raises(ConfigError, match=r"preprocessing.parallel_cutoff: expected below the Nyquist"):
        Preprocessing(parallel_cutoff=150.0).resolved(rate, q)


def test_parallel_filter_without_decimation_equals_scipy(rng):
    x = rng.normal(size=(12000, 4)).cumsum(0)
    rate, cutoff = 1000.0, 7.0
    parts = list(parallel_decimation(lambda a, b: x[a:b], x.shape[0], rate, 1, chunk=3000, cutoff=cutoff))
    values = np.concatenate([v for _, v in parts])
    sos = signal.butter(4, cutoff, fs=rate, output="sos")
    whole = signal.sosfiltfilt(sos, x, axis=0, padlen=3 * (2 * len(sos) + 1))
    np.testing.assert_allclose(values, whole, rtol=0, atol=1e-8 * np.abs(whole).max())
    with pytest.raises(ConfigError, match="aliases when decimating by 10"):
        list(parallel_decimation(lambda a, b: x[a:b], x.shape[0], rate, 10, cutoff=100.0))


def test_band_computed_joint_by_joint_equals_the_whole_array_formula(rng):
    """The spectrum is summed one joint at a time (temporaries one column long): the same energy as the
    formula of the docstring on the whole (N, n_dof) array, so the same band."""
    rate, n = 500.0, 20011
    q = rng.normal(size=(n, 4)).cumsum(0) * 1e-3 + np.sin(np.linspace(0.0, 40.0, n))[:, None] * [1, 2, 3, 4]
    x = (q - q[:1] - np.linspace(0.0, 1.0, n)[:, None] * (q[-1:] - q[:1])) * np.hanning(n)[:, None]
    f = np.fft.rfftfreq(n, 1.0 / rate)
    energy = ((f[:, None] ** 2) * np.abs(np.fft.rfft(x, axis=0)) ** 2).sum(axis=1)
    expected = min(max(f[min(int(np.searchsorted(np.cumsum(energy) / energy.sum(), 0.99)), f.size - 1)], 2 * rate / n), rate / 2)
    assert excitation_band(q, rate) == expected
