"""A delay between the torque and position channels, recovered to a fraction of a sample."""

import numpy as np
import pytest

import dynid
from dynid.exceptions import ConfigError
from dynid.identification.delay import delayed, estimate_delay
from dynid.studies.simulated_logs import simulated_log


@pytest.mark.parametrize("delay", [2.5, -1.25])
def test_a_delay_of_a_fraction_of_a_sample_is_recovered(delay):
    """A simulated UR10e log (250 Hz, noisy currents, quantised positions) whose torques are logged ``delay``
    samples late (read from the exact torques' band-limited interpolation): the estimate lies within 0.25
    samples, within 3σ, and once undone the log shows no delay beyond its σ."""
    robot = dynid.load_robot("ur10e")
    log = simulated_log(robot, seconds=30.0, rate=250.0, rng=3)
    t, tau = log.t, np.asarray(log.tau)
    spectrum = np.fft.rfft(tau, axis=0)  # a delay in the frequency domain: exact for the periodic excitation
    f = np.fft.rfftfreq(t.size, 1.0 / log.rate)
    late = np.fft.irfft(spectrum * np.exp(-2j * np.pi * f * delay / log.rate)[:, None], n=t.size, axis=0)
    from dataclasses import replace

    found = estimate_delay(robot, replace(log, tau=late))
    assert abs(found.samples - delay) < 0.25 and abs(found.samples - delay) < 3 * found.std + 0.05
    assert found.seconds == pytest.approx(found.samples / log.rate) and found.determined
    again = estimate_delay(robot, delayed(replace(log, tau=late), found.samples))
    assert abs(again.samples) < 3 * again.std  # undone, within its own σ (the decimated rows now fall elsewhere)


def test_the_bound_is_checked():
    robot = dynid.load_robot("ur10e")
    with pytest.raises(ConfigError, match="max_samples"):
        estimate_delay(robot, simulated_log(robot, seconds=5.0, rate=250.0), max_samples=0)


def test_identify_says_which_torque_delay_to_give():
    """dynid identify's verdict on a log whose torques come 2.5 samples late: the finding names the delay and the
    setting that undoes it; identified again with that setting, or on the log without delay, no delay finding."""

    robot = dynid.load_robot("ur10e")
    log = simulated_log(robot, seconds=30.0, rate=250.0, rng=3)
    tau = np.asarray(log.tau)
    spectrum = np.fft.rfft(tau, axis=0)
    f = np.fft.rfftfreq(log.t.size, 1.0 / log.rate)
    late = np.fft.irfft(spectrum * np.exp(-2j * np.pi * f * 2.5 / log.rate)[:, None], n=log.t.size, axis=0)
    delays = lambda result: [f.text for f in result.findings if f.kind == "delay"]

    found = delays(dynid.identify_from_arrays(robot, log.t, log.q, late, estimators=("ols",)))
    assert len(found) == 1 and "as if they lag the positions by" in found[0], found
    assert float(found[0].split("positions by ")[1].split()[0]) == pytest.approx(2.5, abs=0.25)
    given = float(found[0].split("torque_delay = ")[1].split()[0])
    assert given == pytest.approx(2.5 / log.rate, abs=0.25 / log.rate)
    again = dynid.identify_from_arrays(robot, log.t, log.q, late, estimators=("ols",),
                                       preprocessing=dynid.Preprocessing(torque_delay=given))
    assert delays(again) == [] and abs(again.diagnostics["torque_delay"]["samples"]) < 0.25
    assert delays(dynid.identify_from_arrays(robot, log.t, log.q, tau, estimators=("ols",))) == []
