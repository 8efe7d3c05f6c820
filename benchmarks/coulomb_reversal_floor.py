"""Where the simulated TX40's least-squares floor comes from: Coulomb friction stepping at velocity reversals.

The closed-loop grid found least squares 0.6-1.0 % off on the TX40 in every cell, already at 1e-4° (benchmarks/README.md),
while the ER-16 reaches 0.004 %. This script takes the noise-free closed-loop run of the grid's TX40
(configs/robots/tx40_simulation.toml: FIGAROH's drive values, hard Coulomb friction of 7-8 N·m on joints 1-2, a
coupled motor 6 with its own Coulomb term) and fits ordinary least squares on the rows ``dynid identify`` builds, with
parts of them replaced by the simulation's truth:

- exact states (the simulated q, q̇, q̈ and applied torques) and the exact direction of motion: the identity of the
  filtered, decimated rows (independent truth: the Pinocchio simulation);
- exact states, the pipeline's direction of motion; the pipeline's states, the exact direction;
- the pipeline's rows with those of each joint near a reversal of a Coulomb term acting on it (its own direction, and
  motor 6's for joints 5 and 6) left out, within the half-width holding 95 % of the parallel filter's response.

Then the same exclusion at the grid's noisiest cell (1e-2°, 0.1 N·m) on the TX40 and the ER-16: bias, spread and
RMSE over realisations (medians over the base parameters, relative to |β|).

    .venv/bin/python benchmarks/coulomb_reversal_floor.py [realisations]
"""

from __future__ import annotations

import dataclasses
import os
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from scipy import signal  # noqa: E402

from dynid.io.logs.datasets import Recording  # noqa: E402
from dynid.preprocessing.preparation import Preprocessing, prepare  # noqa: E402
from dynid.preprocessing.strategies import strategy_for  # noqa: E402
from dynid.simulation.closed_loop import ClosedLoopNoise, simulate_closed_loop  # noqa: E402
from dynid.studies.closed_loop_montecarlo import ClosedLoopStudyConfig, _prepare, zero_order_hold_delay  # noqa: E402

SHARE = 0.95


def response_half_width(rate, cutoff, order, share):
    """Half-width [s] holding ``share`` of the zero-phase Butterworth filter's absolute impulse response."""
    half = int(np.ceil(20 * rate / cutoff))
    x = np.zeros(2 * half + 1)
    x[half] = 1.0
    h = np.abs(signal.sosfiltfilt(signal.butter(order, cutoff, fs=rate, output="sos"), x))
    within = np.cumsum(np.r_[h[half], h[half + 1:] + h[half - 1::-1]]) / h.sum()
    return float(np.searchsorted(within, share)) / rate


def rows(setup, data):
    parts = [[], [], [], []]
    for block in strategy_for(data.settings).chunks(setup.robot, setup.base, data):
        for part, x in zip(parts, block):
            part.append(x)
    return [np.concatenate(p) for p in parts]


def ols(y, tau, keep):
    return np.linalg.lstsq(y[keep], tau[keep], rcond=None)[0]


def off(setup, beta):
    big = np.abs(setup.truth) > 1e-9 * np.abs(setup.truth).max()
    return float(np.median(np.abs(beta - setup.truth)[big] / np.abs(setup.truth)[big])) * 100


def reversal_keep(setup, data, index, keep):
    """``keep`` with the rows near a reversal of a Coulomb term acting on the joint left out."""
    w = response_half_width(data.rate, data.settings.parallel_cutoff, data.settings.order, SHARE)
    tr = setup.robot.transmission
    out = keep.copy()
    motors = [tr.ratios(k) for k in tr.coupled_motors] if "fcm" in tr.coupled_terms else []
    for j in range(keep.shape[1]):
        signs = [np.sign(np.asarray(data.direction[:, j]))] + [np.sign(np.asarray(data.dq) @ c) for c in motors if c[j]]
        for s in signs:
            events = np.flatnonzero(np.diff(s) != 0) + 1
            if events.size:
                near = np.min(np.abs(index[:, None] - events[None, :]), axis=1) <= round(w * data.rate)
                out[near, j] = False
    return out, w


def log_of(setup, noise=None, rng=None):
    exp = setup.experiment
    run = simulate_closed_loop(setup.robot, setup.t, exp.q_ref, exp.dq_ref, exp.controller, noise or ClosedLoopNoise(), rng=rng,
                               feedforward=exp.feedforward)
    data = prepare(Recording("closed loop", setup.t, run.q, None, run.tau, setup.config.rate),
                   Preprocessing(torque_delay=zero_order_hold_delay(setup.config.rate)))
    return run, data


def decomposition(setup):
    run, data = log_of(setup)
    at = np.searchsorted(setup.t, data.t - 1e-9)
    exact_direction = np.sign(run.dq_true[at])
    exact = dataclasses.replace(data, q=run.q_true[at], dq=run.dq_true[at], ddq=run.ddq_true[at], tau=run.tau_applied[at])
    index, y, tau, keep = rows(setup, data)
    print(f"noise-free run, {keep.shape[0]} decimated instants, {keep.sum()} rows kept; OLS off by (median |β̂ - β|/|β|):")
    for words, d in (("the pipeline's rows", data),
                     ("exact states, exact direction", dataclasses.replace(exact, direction=exact_direction)),
                     ("exact states, the pipeline's direction", exact),
                     ("the pipeline's states, exact direction", dataclasses.replace(data, direction=exact_direction))):
        _, yy, tt, _ = rows(setup, d)
        print(f"- {words}: {off(setup, ols(yy, tt, keep)):.3g} %")
    mismatch = (np.sign(data.direction) != exact_direction).sum(axis=0)
    print(f"  samples where the pipeline's direction differs from the truth's, per joint: {mismatch.tolist()}")
    guarded, w = reversal_keep(setup, data, index, keep)
    print(f"- the pipeline's rows, those within ±{w:.3f} s of a reversal left out ({guarded.sum()} of {keep.sum()} kept): "
          f"{off(setup, ols(y, tau, guarded)):.3g} %")


def noisy(setup, realisations):
    est = {"all rows": [], "reversals left out": []}
    for r in range(realisations):
        noise = ClosedLoopNoise(position_std=float(np.deg2rad(1e-2)), torque_std=0.1)
        _, data = log_of(setup, noise, np.random.default_rng([0, 20, 99, r]))
        index, y, tau, keep = rows(setup, data)
        guarded, _ = reversal_keep(setup, data, index, keep)
        est["all rows"].append(ols(y, tau, keep))
        est["reversals left out"].append(ols(y, tau, guarded))
    big = np.abs(setup.truth) > 1e-9 * np.abs(setup.truth).max()
    for words, e in est.items():
        e = np.array(e)
        scale = np.abs(setup.truth)[big]
        bias = np.median(np.abs(e.mean(0) - setup.truth)[big] / scale) * 100
        spread = np.median(e.std(0, ddof=1)[big] / scale) * 100
        rmse = np.median(np.sqrt(((e - setup.truth) ** 2).mean(0))[big] / scale) * 100
        print(f"- OLS, {words}: |bias| {bias:.3g} %, spread {spread:.3g} %, RMSE {rmse:.3g} %")


def main(argv):
    realisations = int(argv[0]) if argv else 8
    start, load = time.perf_counter(), os.getloadavg()[0]
    for robot, joints in (("configs/robots/tx40_simulation.toml", 6), ("er16", 3)):
        setup = _prepare(ClosedLoopStudyConfig(robot=robot, joints=joints, realisations=2))
        print(f"\n## {robot} ({joints} joints)")
        decomposition(setup)
        print(f"1e-2° encoder noise, 0.1 N·m torque noise, {realisations} realisations:")
        noisy(setup, realisations)
    print(f"\n{time.perf_counter() - start:.0f} s on one process; load {load:.2f} at the start, {os.getloadavg()[0]:.2f} at the end")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
