import numpy as np
import pytest
from scipy import signal

from dynid.exceptions import ConfigError
from dynid.preprocessing.filters import (
    butterworth_filtfilt,
    decimation_cutoff,
    differentiate,
    edge_padding,
    parallel_decimation,
)


def test_filtfilt_keeps_slow_sine_without_phase_lag_and_removes_fast_one():
    rate = 1000.0
    t = np.arange(5000) / rate
    slow = np.sin(2 * np.pi * 1.0 * t)
    y = butterworth_filtfilt(slow + 0.5 * np.sin(2 * np.pi * 150.0 * t), rate, cutoff=20.0)
    inner = slice(500, -500)
    np.testing.assert_allclose(y[inner], slow[inner], atol=2e-3)


@pytest.mark.parametrize("shape", [(3000,), (3000, 6), (800, 3, 2)])
def test_the_filter_gives_each_columns_own_numbers_in_one_call_or_column_by_column(shape, monkeypatch):
    """An array filtered in one call along time (up to WHOLE_ARRAY_VALUES) or a column at a time: SciPy's numbers for
    each column filtered alone, to the last bit."""
    import dynid.preprocessing.filters as filters

    x = np.random.default_rng(6).standard_normal(shape)
    sos = signal.butter(4, 20.0, btype="low", fs=500.0, output="sos")
    flat = x.reshape(shape[0], -1)
    alone = np.column_stack([signal.sosfiltfilt(sos, flat[:, c]) for c in range(flat.shape[1])]).reshape(shape)
    for limit in (x.size, x.size - 1):  # one call, then column by column
        monkeypatch.setattr(filters, "WHOLE_ARRAY_VALUES", limit)
        np.testing.assert_array_equal(butterworth_filtfilt(x, 500.0, 20.0), alone)


def test_differentiate_sine():
    rate = 500.0
    t = np.arange(2000) / rate
    np.testing.assert_allclose(differentiate(np.sin(3 * t), rate)[1:-1], 3 * np.cos(3 * t)[1:-1], atol=1e-4)


@pytest.mark.parametrize("factor", [1, 7])
def test_chunked_parallel_decimation_equals_whole_signal(rng, factor):
    x = rng.normal(size=(30000, 2, 3)).cumsum(0)
    rate = 1000.0
    parts = list(parallel_decimation(lambda a, b: x[a:b], x.shape[0], rate, factor, chunk=4000))
    index = np.concatenate([i for i, _ in parts])
    values = np.concatenate([v for _, v in parts])
    np.testing.assert_array_equal(index, np.arange(0, x.shape[0], factor))
    if factor == 1:
        np.testing.assert_array_equal(values, x)
    else:  # the same as SciPy's filtfilt on the whole signal, then every factor-th sample
        cutoff = decimation_cutoff(rate, factor)
        sos = signal.butter(4, cutoff, fs=rate, output="sos")
        whole = signal.sosfiltfilt(sos, x, axis=0, padtype="even", padlen=edge_padding(rate, cutoff, 4))[::factor]
        np.testing.assert_allclose(values, whole, rtol=0, atol=1e-9 * np.abs(whole).max())


def test_bad_cutoff_is_a_config_error():
    with pytest.raises(ConfigError, match="cutoff < rate/2"):
        butterworth_filtfilt(np.zeros((100, 1)), 100.0, 60.0)


def test_column_by_column_filters_equal_whole_array_calls_bit_for_bit(rng):
    """The filter and the derivative run one column at a time (a long log's temporaries stay one column
    long); the numbers are those of SciPy's and NumPy's calls on the whole array."""
    x = rng.normal(size=(7000, 2, 3)).cumsum(0)
    sos = signal.butter(4, 20.0, fs=1000.0, output="sos")
    np.testing.assert_array_equal(butterworth_filtfilt(x, 1000.0, 20.0, 4), signal.sosfiltfilt(sos, x, axis=0))
    np.testing.assert_array_equal(differentiate(x, 1000.0), np.gradient(x, 1e-3, axis=0))
    np.testing.assert_array_equal(butterworth_filtfilt(x[:, 0, 0], 1000.0, 20.0, 4), signal.sosfiltfilt(sos, x[:, 0, 0]))


def test_parallel_filter_edges_average_the_noise_rather_than_amplify_one_sample():
    """White noise through the parallel filter: at the log's first and last kept samples its spread is that of the
    interior's (the padding averages the edge's samples), not that of one raw sample. A log of a robot in closed loop
    carries the loop's torque noise (tens of N·m at 1 kHz); with an odd extension pivoting on the first sample, the
    first decimated rows held a large part of that one sample's noise and biased every estimate."""
    rate, factor, cutoff = 1000.0, 100, 2.8
    firsts, lasts, middles = [], [], []
    for seed in range(200):
        x = np.random.default_rng(seed).normal(0.0, 100.0, (5000, 1))
        _, y = zip(*parallel_decimation(lambda a, b: x[a:b], x.shape[0], rate, factor, cutoff=cutoff))
        y = np.concatenate(y)[:, 0]
        firsts.append(y[0]), lasts.append(y[-1]), middles.append(y[y.size // 2])
    interior = np.std(middles)
    assert interior < 15.0  # the filter keeps a few % of the noise's band
    assert np.std(firsts) < 2.0 * interior and np.std(lasts) < 2.0 * interior, (np.std(firsts), np.std(lasts), interior)


def test_a_fractional_shift_read_at_some_samples_equals_the_whole_shift_there():
    """The delay check reads the shifted torques only at the decimated rows: the same numbers as shifting the whole log
    (a sinusoid within the band shifted by 2.3 samples, independent truth: its own value 2.3 samples later)."""
    from dynid.preprocessing.filters import FractionalShift

    k = np.arange(2000)
    x = np.column_stack([np.sin(2 * np.pi * 0.01 * k), np.cos(2 * np.pi * 0.02 * k)])
    at = np.arange(5, 2000, 37)
    shift = FractionalShift(x)
    np.testing.assert_array_equal(shift.read(2.3, at=at), shift.read(2.3)[at])
    np.testing.assert_array_equal(shift.read(-3.0, at=at), shift.read(-3.0)[at])
    inside = at[(at > 40) & (at < 1950)]
    truth = np.column_stack([np.sin(2 * np.pi * 0.01 * (inside + 2.3)), np.cos(2 * np.pi * 0.02 * (inside + 2.3))])
    np.testing.assert_allclose(shift.read(2.3, at=inside), truth, atol=1e-3)
    # the mirrored ends made once for the largest shift so far: a read after a farther one, and a farther one than the
    # first, equal a fresh object's (the ends' mirror image, 60 samples out, as np.pad gives it for that shift alone)
    for d in (57.4, 0.7, -60.0, 3.0):
        np.testing.assert_array_equal(shift.read(d), FractionalShift(x).read(d))
    pad = np.pad(x, [(80, 80), (0, 0)], mode="symmetric")
    np.testing.assert_array_equal(shift.read(-60.0), pad[20:20 + x.shape[0]])


def test_parallel_decimation_gives_the_same_numbers_on_any_number_of_cores(rng, monkeypatch):
    """Column blocks are filtered on the process's cores from PARALLEL_VALUES on: the numbers are those of one
    thread's column-by-column loop, bit for bit, with zero columns left zero and every column in its place."""
    import dynid.preprocessing.filters as filters

    x = rng.normal(size=(9000, 3, 7)).cumsum(0)
    x[:, 1, 2] = 0.0  # a zero column: skipped, and zero in the result
    x[:, 0, 5] = 1e6 * np.sin(np.arange(9000) / 50.0)  # one column far from the others: a swap would show

    def run(parallel_values, cores):
        monkeypatch.setattr(filters, "PARALLEL_VALUES", parallel_values)
        monkeypatch.setattr(filters, "cores", lambda: cores)
        return np.concatenate([v for _, v in parallel_decimation(lambda a, b: x[a:b], x.shape[0], 1000.0, 5, chunk=4000)])

    one = run(10**12, 1)
    np.testing.assert_array_equal(run(0, 2), one)
    np.testing.assert_array_equal(run(0, 3), one)
    assert not one[:, 1, 2].any() and np.abs(one[:, 0, 5]).max() > 1e5
    sos = signal.butter(4, decimation_cutoff(1000.0, 5), fs=1000.0, output="sos")
    whole = signal.sosfiltfilt(sos, x, axis=0, padtype="even", padlen=edge_padding(1000.0, decimation_cutoff(1000.0, 5), 4))[::5]
    np.testing.assert_allclose(one, whole, rtol=0, atol=1e-9 * np.abs(whole).max())


@pytest.mark.parametrize("decimation,cutoff", [(1, 0.0), (5, 0.0), (1, 20.0)])  # 0: no filter but decimation's
def test_every_chunk_of_the_prepared_rows_keeps_its_values_after_the_next_is_computed(decimation, cutoff):
    """The parallel filter's chunks computed into one buffer (a new array each time is memory the system clears
    again): what each chunk yields is its own, filtered or not."""
    from dynid.dynamics.base_parameters import base_parameters
    from dynid.dynamics.regressor import regressor
    from dynid.io.logs.datasets import Recording
    from dynid.model.description import load_robot
    from dynid.preprocessing.preparation import ParallelFiltering
    from dynid.preprocessing.settings import Preprocessing

    from ..conftest import sine_motion

    robot = load_robot("er16")
    base = base_parameters(robot, rng=0)
    t = np.arange(6000) / 1000.0
    q, dq, ddq = sine_motion(np.random.default_rng(4), t, robot.n_dof)
    tau = np.einsum("kjp,p->kj", regressor(robot, q, dq, ddq), robot.standard_parameters())
    strategy = ParallelFiltering()
    settings = Preprocessing(decimation=decimation, parallel_cutoff=cutoff, chunk=1000).resolved(1000.0, q)
    data = strategy.prepare(Recording("sine", t, q, dq, tau, 1000.0), settings)
    seen = []
    kept = [(index, y, tau_) for index, y, tau_, _ in strategy.chunks(robot, base, data)
            if not seen.append(y.copy())]  # each chunk as it was yielded, kept before the next one is computed
    assert len(kept) >= 5
    for (_, y, _), first in zip(kept, seen):
        np.testing.assert_array_equal(y, first)
