"""Data-derived preprocessing defaults: the excitation band and the rules that follow from it."""

import numpy as np
import pytest
from scipy import signal

from dynid.exceptions import ConfigError
from dynid.preprocessing.bands import (
    PARALLEL_FACTOR,
    POSITION_FACTOR,
    cutoffs_from_band,
    estimate_band,
    excitation_band,
)
from dynid.preprocessing.filters import decimation_cutoff, edge_padding, parallel_decimation
from dynid.preprocessing.preparation import Preprocessing


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


@pytest.mark.parametrize("share", [0.0, 0.01, 0.05, 0.15])
@pytest.mark.parametrize("rate", [100.0, 1000.0])
def test_band_is_found_above_broadband_noise(rng, share, rate):
    """Broadband noise holding ``share`` of the positions' velocity-weighted spectral energy (the quantity the
    99 % rule reads) leaves the band on the excitation's highest harmonic (0.375 Hz), and the noise's share is
    measured; without the noise floor, 1 % of noise moves the 99 % point to the noise."""
    n = int(60 * rate)
    t = np.arange(n) / rate
    harmonics = 0.075 * np.arange(1, 6)
    q = sum(np.sin(2 * np.pi * f * t + rng.uniform(0, 6))[:, None] / f for f in harmonics) * np.array([1.0, 0.3, 2.0])
    x = (q - q[:1] - np.linspace(0, 1, n)[:, None] * (q[-1:] - q[:1])) * np.hanning(n)[:, None]
    f = np.fft.rfftfreq(n, 1 / rate)
    e_signal = (f[:, None] ** 2 * np.abs(np.fft.rfft(x, axis=0)) ** 2).sum(0)
    white = rng.normal(size=q.shape)
    w = white * np.hanning(n)[:, None]
    e_white = (f[:, None] ** 2 * np.abs(np.fft.rfft(w, axis=0)) ** 2).sum(0)
    noisy = q + white * np.sqrt(share / (1 - share) * e_signal / e_white) if share else q
    found = estimate_band(noisy, rate)
    assert abs(found.band - 0.375) <= 3 * rate / n, found
    assert found.noise_share == pytest.approx(share, abs=0.1 * share + 1e-3)
    assert not found.warnings("log")


def test_an_implausible_band_is_named_with_the_setting_that_fixes_it(rng):
    """Positions that are all noise, or a motion close to the Nyquist frequency (an undersampled log): one warning
    naming the dataset and preprocessing.band."""
    rate, n = 500.0, 20000
    t = np.arange(n) / rate
    for q in (rng.normal(size=(n, 2)), np.sin(2 * np.pi * 0.3 * rate * t)[:, None] + 0.01 * rng.normal(size=(n, 2))):
        found = estimate_band(q, rate)
        lines = found.warnings("identification (log.csv)")
        assert len(lines) == 1 and lines[0].startswith("identification (log.csv): ") and "preprocessing.band" in lines[0]


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
    # a decimation alone keeps the derived parallel cutoff (it moves no other setting) while that cutoff
    # cannot alias; where it would, the cutoff is lowered to the decimation's own and the derivation says so
    given = Preprocessing(decimation=4).resolved(rate, q)
    assert given.parallel_cutoff == pytest.approx(s.parallel_cutoff) and given.decimation == 4
    coarse = Preprocessing(decimation=40).resolved(rate, q)
    assert coarse.parallel_cutoff == pytest.approx(decimation_cutoff(rate, 40)) and coarse.parallel_cutoff < s.parallel_cutoff
    assert "anti-aliasing cutoff of decimation = 40" in coarse.derivation
    with pytest.raises(ConfigError, match=r"preprocessing.parallel_cutoff: expected below the Nyquist"):
        Preprocessing(parallel_cutoff=150.0).resolved(rate, q)
    # settings carried over to a log of another rate are lowered there, with a warning naming the log
    other = Preprocessing(parallel_cutoff=80.0).resolved(rate * 0.99, q, name="validation 1", strict=False)
    assert other.parallel_cutoff == pytest.approx(0.8 * rate * 0.99 / 2)
    assert other.warnings and other.warnings[0].startswith("validation 1: preprocessing.parallel_cutoff = 80 Hz")


def test_parallel_filter_without_decimation_equals_scipy(rng):
    x = rng.normal(size=(12000, 4)).cumsum(0)
    rate, cutoff = 1000.0, 7.0
    parts = list(parallel_decimation(lambda a, b: x[a:b], x.shape[0], rate, 1, chunk=3000, cutoff=cutoff))
    values = np.concatenate([v for _, v in parts])
    sos = signal.butter(4, cutoff, fs=rate, output="sos")
    whole = signal.sosfiltfilt(sos, x, axis=0, padtype="even", padlen=edge_padding(rate, cutoff, 4))
    np.testing.assert_allclose(values, whole, rtol=0, atol=1e-8 * np.abs(whole).max())
    with pytest.raises(ConfigError, match="aliases when decimating by 10"):
        list(parallel_decimation(lambda a, b: x[a:b], x.shape[0], rate, 10, cutoff=100.0))


def test_band_of_stored_columns_equals_that_of_the_array(rng, tmp_path, monkeypatch):
    """The spectrum is summed one joint at a time (temporaries one column long): a log held in stored columns
    gives the same band and noise share as the same log in memory."""
    from dynid._util.column_store import StoredColumns

    monkeypatch.setenv("TMPDIR", str(tmp_path))
    rate, n = 500.0, 20011
    q = rng.normal(size=(n, 4)).cumsum(0) * 1e-3 + np.sin(np.linspace(0.0, 40.0, n))[:, None] * [1, 2, 3, 4]
    stored = StoredColumns.from_columns(q[:, j] for j in range(4))
    assert estimate_band(stored, rate) == estimate_band(q, rate)
