"""Every channel checked where a log is prepared (issue "Honest on any log", item 3): a torque held at its extreme (a
drive's current or torque limit) found on either side of the channel, with the filter's reach around it, a dead
channel and a noisy one not clipped; measured velocities that are not the positions' derivative refused."""

import re

import numpy as np
import pytest

from dynid.exceptions import DataError
from dynid.preprocessing.prepared import SATURATION_SAMPLES, clipped_samples


def _channels(rng, n=400):
    t = np.arange(n) * 0.01
    tau = rng.normal(0.0, 1.0, (n, 3))
    return t, tau


def test_a_limit_on_one_side_is_found_though_the_other_side_reaches_further(rng):
    """J2 clipped at -4 N·m (samples 100-159) while it reaches +9 N·m once: the clipped side is its minimum, not its
    largest magnitude; the warning names the dataset, the joint, the value and the time range."""
    t, tau = _channels(rng)
    tau[20, 1] = 9.0
    tau[100:160, 1] = -4.0
    mask, words, _ = clipped_samples(tau, t, "identification (log.csv)")
    assert mask is not None and mask.shape == tau.shape
    assert np.flatnonzero(mask[:, 1]).tolist() == list(range(100, 160)) and not mask[:, [0, 2]].any()
    assert words == ("identification (log.csv): J2's torque stays at its extreme -4 N·m for 60 samples "
                     "(t = 1.000-1.590 s): saturated? its 60 samples there and within the filter's reach are left "
                     "out of the estimation and of the metrics",)


def test_both_sides_and_the_filters_reach_are_marked(rng):
    t, tau = _channels(rng)
    tau[50:80, 0] = 5.0
    tau[200:230, 0] = -5.0
    mask, words, _ = clipped_samples(tau, t, "log", reach=7)
    expected = set(range(43, 87)) | set(range(193, 237))
    assert set(np.flatnonzero(mask[:, 0]).tolist()) == expected
    assert len(words) == 1 and "its 88 samples there" in words[0]


def test_short_runs_dead_and_noisy_channels_are_not_clipped(rng):
    """A run one sample shorter than SATURATION_SAMPLES, a channel reading one value throughout (a dead one, said by
    dead_channels) and plain noise: nothing is marked, nothing said."""
    t, tau = _channels(rng)
    tau[100:100 + SATURATION_SAMPLES - 1, 0] = 6.0
    tau[:, 1] = 2.5
    mask, words, _ = clipped_samples(tau, t, "log")
    assert mask is None and words == ()


def test_a_channel_clipped_almost_everywhere_is_left_out_and_the_others_keep_their_samples(rng):
    """J3 at ±3 N·m in 90 % of the samples: it was refused ("no sample is left to score") though J1 and J2 are live.
    Now J3 is saturated throughout (its rows left out as a dead channel's, said naming the log, the joint, the value
    and the share) and no sample is taken from the metrics for it."""
    t, tau = _channels(rng, 100)
    tau[:, 2] = np.where(np.arange(100) % 50 < 45, 3.0, -3.0)
    mask, words, saturated = clipped_samples(tau, t, "log", reach=5)
    assert saturated == (2,) and mask is None
    assert words == ("log: J3's torque is at its extreme 3 N·m in 100 % of the samples (with the filter's reach): "
                     "saturated throughout? its rows are left out of the estimation and of the metrics, as a dead "
                     "channel's, so that the other joints keep their samples",)


def test_the_metrics_keep_half_the_samples_the_longest_clipped_joint_left_out_first(rng):
    """J1 clipped over samples 0-219 and J2 over 200-379 of 400: together 95 % of the samples would leave the metrics.
    J1, the longer, is taken as saturated throughout; J2 keeps its own clipped samples masked; half or more remain."""
    t, tau = _channels(rng, 400)
    tau[:220, 0] = 5.0
    tau[200:380, 1] = -5.0
    mask, words, saturated = clipped_samples(tau, t, "log")
    assert saturated == (0,)
    assert mask is not None and not mask[:, [0, 2]].any()
    assert np.flatnonzero(mask[:, 1]).tolist() == list(range(200, 380))
    assert (~mask.any(axis=1)).mean() >= 0.5
    assert "J1's torque is at its extreme 5 N·m in 55 % of the samples" in words[0]
    assert words[1].startswith("log: J2's torque stays at its extreme -5 N·m for 180 samples")


def test_a_log_whose_every_joint_is_dead_or_saturated_is_refused_in_one_line(rng):
    """Nothing can be estimated: one line naming the log, no traceback."""
    from dynid.io.logs.datasets import Recording
    from dynid.preprocessing.preparation import prepare
    from dynid.preprocessing.settings import Preprocessing

    rate = 200.0
    t = np.arange(2000) / rate
    w = 2 * np.pi * np.array([0.1, 0.17, 0.23])
    q = np.sin(w * t[:, None])
    tau = np.column_stack([np.clip(np.sin(3 * w[0] * t), -0.2, 0.2), np.full(t.size, 1.5),
                           np.where(np.sin(w[2] * t) > 0, 2.0, -2.0)])
    with pytest.raises(DataError, match=r"^identification: every joint's torque reads one value or its limit "
                                        r"throughout \(dead or saturated channels\): nothing can be identified"):
        prepare(Recording("identification", t, q, None, tau, rate), Preprocessing())


@pytest.mark.parametrize("factor, hint", [(180 / np.pi, "(deg/s read as rad/s?)"), (-1.0, "(a flipped sign?)"),
                                          (100.0, "× the derivative of its positions: check")])
def test_measured_velocities_in_another_unit_sign_or_side_are_refused(rng, factor, hint):
    """Measured velocities that are not the positions' derivative (deg/s read as rad/s, a flipped sign, a motor-side
    velocity through a gear of 100): refused in one line naming the dataset, the joint and the ratio; the same
    velocities in rad/s pass (they were taken as they were, and every velocity-dependent term fitted to them)."""
    from dynid.io.logs.datasets import Recording
    from dynid.preprocessing.preparation import prepare
    from dynid.preprocessing.settings import Preprocessing

    rate = 200.0
    t = np.arange(4000) / rate
    w = 2 * np.pi * np.array([0.1, 0.17, 0.23])
    q = np.sin(w * t[:, None])
    dq = w * np.cos(w * t[:, None])
    tau = rng.normal(0.0, 1.0, q.shape)
    prepare(Recording("identification", t, q, dq, tau, rate), Preprocessing())
    wrong = dq.copy()
    wrong[:, 1] *= factor
    with pytest.raises(DataError, match=r"^identification: joint 2's measured velocities are .*" + re.escape(hint)):
        prepare(Recording("identification", t, q, wrong, tau, rate), Preprocessing())


@pytest.mark.parametrize("wrong", ["another joint's", "currents"])
def test_measured_velocities_unlike_the_positions_are_refused_where_the_joint_moves(rng, wrong):
    """Joint 2's velocity column holding joint 3's velocities, or its motor current (which a viscous term then fits as
    the torque, below the noise floor): refused naming the joint and the correlation, with the setting that leaves
    them out. A joint that hardly moves (positions spanning 0.02 rad) is not required to follow."""
    from dynid.io.logs.datasets import Recording
    from dynid.preprocessing.preparation import prepare
    from dynid.preprocessing.settings import Preprocessing

    rate = 200.0
    t = np.arange(4000) / rate
    w = 2 * np.pi * np.array([0.1, 0.17, 0.23])
    q = np.sin(w * t[:, None])
    dq = w * np.cos(w * t[:, None])
    tau = np.column_stack([np.sin(3 * w[j] * t) + rng.normal(0.0, 0.1, t.size) for j in range(3)])
    bad = dq.copy()
    bad[:, 1] = dq[:, 2] if wrong == "another joint's" else tau[:, 1]
    with pytest.raises(DataError, match=r"^identification: joint 2's measured velocities do not follow the derivative "
                                        r"of its positions \(correlation -?0\.\d+ over a motion of 2 rad\): .* leave "
                                        r"them out \(velocities = false\)"):
        prepare(Recording("identification", t, q, bad, tau, rate), Preprocessing())
    still = q.copy()
    still[:, 1] *= 0.01  # a span of 0.02 rad: its derivative's shape is not required of the velocities
    prepare(Recording("identification", t, still, bad, tau, rate), Preprocessing())


def _logged_in_steps(x, step):
    return np.round(x / step) * step


def test_a_quantised_channel_is_not_clipped_at_its_smooth_peaks(rng):
    """Torques logged in steps of 0.1 N·m at 1 kHz (a wrist of ±1.6 N·m): a smooth peak reads its top step for tens of
    samples, as a clipped torque would, but the torque on both sides of it does not head beyond: nothing is marked.
    The same channel clipped at ±1.2 N·m and then logged in steps: the clipped runs are marked, on both sides."""
    t = np.arange(40000) * 1e-3
    smooth = 1.6 * np.sin(2 * np.pi * 0.15 * t) * np.cos(2 * np.pi * 0.05 * t) + rng.normal(0.0, 0.01, t.size)
    tau = np.column_stack([_logged_in_steps(smooth, 0.1), rng.normal(0.0, 1.0, t.size)])
    top = np.abs(tau[:, 0] - tau[:, 0].max()) < 1e-9
    longest = max(len(r) for r in np.split(top, np.flatnonzero(np.diff(top)) + 1) if r[0])
    assert longest >= SATURATION_SAMPLES  # a run the plain rule takes for saturation
    mask, words, _ = clipped_samples(tau, t, "log")
    assert mask is None and words == ()
    tau[:, 0] = _logged_in_steps(np.clip(smooth, -1.2, 1.2), 0.1)
    mask, words, _ = clipped_samples(tau, t, "log")
    assert mask is not None and not mask[:, 1].any()
    held = np.abs(np.abs(tau[:, 0]) - 1.2) < 1e-9
    assert mask[:, 0].sum() >= 0.9 * held.sum()
    assert (tau[mask[:, 0], 0] > 0).any() and (tau[mask[:, 0], 0] < 0).any()
    assert len(words) == 1 and words[0].startswith("log: J1's torque stays at its extreme")
