"""The compiled filters of long logs, and the short logs' filter with its initial state computed once, against SciPy's
own (an independent implementation): the parallel decimation's zero-phase filters against ``sosfiltfilt``, the Gaussian smoothing against ``gaussian_filter1d``, the same numbers bit for
bit whatever the order, cutoff, width, padding, columns, threads and values."""

import numpy as np
import pytest
from scipy import signal
from scipy.ndimage import gaussian_filter1d

from dynid.preprocessing._filter_kernel import gaussian_nearest, gaussian_weights, zero_phase
from dynid.preprocessing.filters import even_filtfilt


@pytest.mark.parametrize(("order", "cutoff", "rate", "n", "c", "padlen"),
                         [(4, 20.0, 1000.0, 3000, 7, 300), (2, 5.0, 250.0, 800, 1, 0), (6, 40.0, 500.0, 1200, 33, 1199),
                          (4, 1.0, 1000.0, 5000, 16, 2600)])
def test_the_compiled_filter_is_scipys_sosfiltfilt_bit_for_bit(order, cutoff, rate, n, c, padlen):
    rng = np.random.default_rng(order + c)
    x = rng.standard_normal((n, c)) * np.logspace(-6, 4, c) + np.linspace(0, 50, n)[:, None]
    x[:, 0] = 0.0 if c > 2 else x[:, 0]  # a dead column stays zero
    sos = signal.butter(order, cutoff, fs=rate, output="sos")
    expected = signal.sosfiltfilt(sos, x, axis=0, padtype="even", padlen=padlen)
    got = zero_phase(sos, x, padlen, signal.sosfilt_zi(sos))
    assert got.shape == expected.shape
    assert np.array_equal(got, expected)
    assert not np.array_equal(got, x)  # it filtered
    cols, rows = np.array([c - 1, 0]), np.array([0, n // 2, n - 1])  # columns read in place, rows picked
    assert np.array_equal(zero_phase(sos, x, padlen, signal.sosfilt_zi(sos), cols, rows), expected[rows][:, cols])
    # the short logs' path: SciPy's own steps with the initial state computed once, the same numbers
    lean = even_filtfilt(signal, sos, x, padlen, signal.sosfilt_zi(sos))
    assert np.array_equal(lean, expected) and lean.shape == expected.shape
    assert np.array_equal(even_filtfilt(signal, sos, x[:, 1:], padlen, signal.sosfilt_zi(sos)), expected[:, 1:])


def test_the_parallel_decimation_of_a_long_log_is_the_same_through_either_filter(monkeypatch):
    """The compiled filter takes over from the log's length (:data:`COMPILED_FILTER_VALUES`): chunk by chunk, with
    their margins and the log's padded ends, the kept samples are SciPy's to the last bit."""
    from dynid.preprocessing import filters

    rng = np.random.default_rng(5)
    x = np.cumsum(rng.standard_normal((9000, 12)), axis=0)
    x[:, 3] = 0.0
    x[2000:6000, 5] = 0.0  # zero through a chunk and its margin: filtered on from its carried state, not taken as zero

    def run():
        return [(i.copy(), v.copy()) for i, v in filters.parallel_decimation(lambda a, b: x[a:b], 9000, 500.0, 5,
                                                                             chunk=2000)]

    monkeypatch.setattr(filters, "COMPILED_FILTER_VALUES", 10**12)
    scipys = run()
    monkeypatch.setattr(filters, "COMPILED_FILTER_VALUES", 0)
    compiled = run()
    assert len(scipys) == len(compiled) == 5
    for (i, a), (j, b) in zip(scipys, compiled):
        assert np.array_equal(i, j) and np.array_equal(a, b)
    assert np.all(np.concatenate([v for _, v in compiled])[:, 3] == 0.0) and np.ptp(compiled[0][1][:, 0]) > 0


def test_a_regressor_and_its_torques_go_through_one_filter_together(monkeypatch):
    """A regressor block and its torques, filtered together: the narrow torques take the compiled filter with the wide
    regressor where their columns together reach :data:`COMPILED_FILTER_VALUES` (the torques alone would not), and
    both are SciPy's numbers to the last bit."""
    from dynid.preprocessing import _filter_kernel, filters

    rng = np.random.default_rng(8)
    y = np.cumsum(rng.standard_normal((9000, 3, 4)), axis=0)
    tau = np.cumsum(rng.standard_normal((9000, 3)), axis=0)
    calls = []
    original = _filter_kernel.zero_phase
    monkeypatch.setattr(filters, "zero_phase", lambda sos, x, *a, **k: calls.append(x.shape[1]) or original(sos, x, *a, **k))

    def run():
        return [(i.copy(), a.copy(), b.copy()) for i, (a, b) in
                filters.parallel_decimation(lambda a, b: (y[a:b], tau[a:b]), 9000, 500.0, 5, chunk=2000)]

    monkeypatch.setattr(filters, "COMPILED_FILTER_VALUES", 10**12)
    scipys = run()
    assert not calls
    monkeypatch.setattr(filters, "COMPILED_FILTER_VALUES", 9000 * 15)  # more than the torques' 3 columns, less than 15
    compiled = run()
    assert sorted(set(calls)) == [3, 12]  # the torques' block too
    for (i, a, b), (j, c, d) in zip(scipys, compiled):
        assert np.array_equal(i, j) and np.array_equal(a, c) and np.array_equal(b, d)


@pytest.mark.parametrize(("n", "sigma", "workers"), [(5000, 13.25, 1), (9000, 66.3, 2), (4099, 0.7, 2), (300, 40.0, 2),
                                                      (1, 3.0, 1), (2, 150.0, 2)])
def test_the_compiled_gaussian_smoothing_is_scipys_bit_for_bit(n, sigma, workers):
    rng = np.random.default_rng(n)
    x = np.cumsum(rng.standard_normal(n)) * 1e3 + np.sin(np.arange(n) / 50.0)  # the ends differ: "nearest" matters
    weights = gaussian_weights(sigma)
    assert weights.size % 2 == 1 and np.array_equal(weights, weights[::-1]) and np.isclose(weights.sum(), 1.0)
    expected = gaussian_filter1d(x, sigma, mode="nearest")
    got = gaussian_nearest(x, weights, workers)
    assert np.array_equal(got, expected)
    assert n < 3 or not np.array_equal(got, x)  # it smoothed


def test_gaussian_smoothing_is_the_same_through_either_path(monkeypatch):
    """The compiled smoothing takes over from the work's size (:data:`COMPILED_GAUSSIAN_WORK`), on arrays in memory and
    on a long log's stored columns alike."""
    from dynid._util.column_store import StoredColumns
    from dynid.preprocessing import filters

    rng = np.random.default_rng(3)
    x = np.cumsum(rng.standard_normal((6000, 4)), axis=0)
    stored = StoredColumns.from_columns(x.T)
    monkeypatch.setattr(filters, "COMPILED_GAUSSIAN_WORK", 10**15)
    scipys = filters.gaussian_smooth(x, 1000.0, 2.0), np.asarray(filters.gaussian_smooth(stored, 1000.0, 2.0))
    calls = []
    monkeypatch.setattr(filters, "gaussian_nearest", lambda *a: calls.append(1) or gaussian_nearest(*a))
    monkeypatch.setattr(filters, "COMPILED_GAUSSIAN_WORK", 0)
    compiled = filters.gaussian_smooth(x, 1000.0, 2.0), np.asarray(filters.gaussian_smooth(stored, 1000.0, 2.0))
    assert len(calls) == 8  # four columns, twice
    for a, b in zip(scipys, compiled):
        assert np.array_equal(a, b)
    assert not np.array_equal(scipys[0], x)


def test_the_live_columns_of_a_large_block_are_found_by_blocks_of_rows_as_by_one_pass():
    """The columns the parallel decimation filters (any non-zero value), found a block of rows per core on a large
    block: a column non-zero at one sample of the last rows only, or of the first only, is live; a zero one is not."""
    from dynid.preprocessing.filters import PARALLEL_VALUES, _live_columns

    rng = np.random.default_rng(9)
    flat = rng.standard_normal((4001, 60))
    flat[:, [3, 17, 40, 59]] = 0.0
    flat[4000, 17] = 1e-300  # the last row's only value
    flat[0, 40] = -2.0  # the first row's only value
    assert flat.size >= PARALLEL_VALUES
    live = _live_columns(flat)
    assert np.array_equal(live, np.flatnonzero(np.any(flat, axis=0)))
    assert 17 in live and 40 in live and 3 not in live and 59 not in live


def test_a_chunk_computes_the_signal_from_its_own_start_and_matches_the_whole_signal_filtered():
    """The forward pass goes on from one chunk to the next (its state carried): each chunk asks for its samples and the
    margin after it only, never the samples before it again, and the result is the whole signal filtered at once to
    the last digits (1e-12 of its range; a column zero from the middle on rings out as it does there)."""
    from dynid.preprocessing import filters

    rng = np.random.default_rng(11)
    x = np.cumsum(rng.standard_normal((50_000, 6)), axis=0)
    x[20_000:, 4] = 0.0
    asked = []

    def block(a, b):
        asked.append((a, b))
        return x[a:b]

    rate, cutoff = 1000.0, 10.0
    values = np.concatenate([v for _, v in filters.parallel_decimation(block, 50_000, rate, 1, chunk=10_000,
                                                                        cutoff=cutoff)])
    margin = int(np.ceil(10 * 4 * 0.4 * rate / cutoff))
    assert asked == [(a, min(50_000, a + 10_000 + margin)) for a in range(0, 50_000, 10_000)]
    sos = signal.butter(4, cutoff, fs=rate, output="sos")
    whole = signal.sosfiltfilt(sos, x, axis=0, padtype="even", padlen=filters.edge_padding(rate, cutoff, 4))
    np.testing.assert_allclose(values, whole, rtol=0, atol=1e-12 * np.abs(whole).max())
    assert np.abs(values[20_000:25_000, 4]).max() > 0  # the ringing after the column's last motion
