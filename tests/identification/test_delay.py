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


def _late(log, samples: float):
    from dataclasses import replace

    tau = np.asarray(log.tau)
    f = np.fft.rfftfreq(log.t.size, 1.0 / log.rate)
    late = np.fft.irfft(np.fft.rfft(tau, axis=0) * np.exp(-2j * np.pi * f * samples / log.rate)[:, None], n=log.t.size,
                        axis=0)
    return replace(log, tau=late, name=f"{log.name} late")


def test_a_delay_is_proposed_only_where_the_validation_logs_agree(tmp_path):
    """Issue "Every assurance checked on what the user meets", item 5. A simulated UR10e whose identification and
    validation logs both log the torques 2.5 samples late: the finding is kept, saying that the log identified again
    with the delay predicts the validation log better. The LBR Med7's real log shows a 1.9-sample lead that its own
    held-out blocks favour by 11 %; identified again with it (dynid's second identification keeps the first's cutoffs
    and friction models; an independent run of the config with [preprocessing] torque_delay set, which chooses them
    anew, agrees), its validation log is predicted worse: the finding is withdrawn, its figures kept in the
    diagnostics."""
    import re
    from pathlib import Path

    from dynid.identification.pipeline import IdentificationPipeline
    from dynid.identification.run import run_identification
    from dynid.io.config.identification_config import load_identification_config
    from dynid.runtime.processes import allow_forks, can_fork
    from tests.conftest import shared_data

    robot = dynid.load_robot("ur10e")
    ident = _late(simulated_log(robot, seconds=30.0, rate=250.0, rng=3), 2.5)
    check = _late(simulated_log(robot, seconds=20.0, rate=250.0, rng=4), 2.5)
    result = IdentificationPipeline(robot, estimators=("ols",)).fit(ident, validation=(check,))
    [found] = [f.text for f in result.findings if f.kind == "delay"]
    weighed = result.diagnostics["torque_delay"]["validation"]
    assert weighed["with"] * 1.02 < weighed["without"] and "identify again with it: the validation logs agree" in found
    assert f"{weighed['with']:.3g} % against {weighed['without']:.3g} %" in found
    with allow_forks():  # the CLI's way: the second identification on the second core, the same figures
        assert can_fork()
        forked = IdentificationPipeline(robot, estimators=("ols",)).fit(ident, validation=(check,))
    assert forked.diagnostics["torque_delay"] == result.diagnostics["torque_delay"]
    assert [f.text for f in forked.findings] == [f.text for f in result.findings]

    repo = Path(__file__).resolve().parents[2]
    text = (repo / "configs" / "kuka_med7.toml").read_text().replace('robot = "robots/', f'robot = "{repo}/configs/robots/')
    root = shared_data("kuka_med7_lbrstack")
    path = tmp_path / "med7.toml"
    path.write_text(text)
    r = run_identification(load_identification_config(path, data_root=root))
    delay = r.diagnostics["torque_delay"]
    assert not [f for f in r.findings if f.kind == "delay"] and delay["held_out_ratio"] < 0.95
    path.write_text(re.sub(r"^\[estimation\]", f"[preprocessing]\ntorque_delay = {delay['seconds']!r}\n[estimation]",
                           text, count=1, flags=re.M))
    again = run_identification(load_identification_config(path, data_root=root))

    def mean(res):
        yard = res.diagnostics["yardstick"]
        return (yard.get("mean_over_logs_that_move") or yard["mean_global_relative_error"])[res.main]

    assert mean(again) >= mean(r) / 1.02  # the delay does not make the validation log's prediction better
    assert delay["validation"]["with"] >= delay["validation"]["without"] / 1.02
    np.testing.assert_allclose(delay["validation"]["without"], mean(r), rtol=1e-9)
