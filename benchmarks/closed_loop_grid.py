"""Closed-loop Monte Carlo on BIRDy's noise grid (Leboutet et al., Applied Sciences 2021), on a Dask local cluster.

The paper's ER-16 (3 joints, its excitation β1, 25 s at 1 kHz) driven by a PID with model feed-forward
(:meth:`dynid.simulation.closed_loop.Controller.for_robot`: 5 Hz bandwidth, velocity filtered at 50 Hz); encoder
noise 1e-4, 1e-3, 1e-2 degrees; torque noise 0.05 and 0.1 N·m; two preprocessings of the same logs: dynid's
data-derived default, and cutoffs at 30 Hz (``band = 3`` Hz), which lets the loop's noise into the observation
matrix. Per cell and estimator (IDIM-WLS, IDIM-IV, DIDIM): the median over the base parameters of |bias| and of the
spread (both relative to |truth|), the coverage of the 95 % intervals, and the wall time of one IDIM-IV and one DIDIM
run on the default preprocessing.

    .venv/bin/python benchmarks/closed_loop_grid.py [realisations]
"""

from __future__ import annotations

import os
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

ENCODER = (1e-4, 1e-3, 1e-2)  # degrees
TORQUE = (0.05, 0.1)  # N·m
FILTERS = {"default": None, "30 Hz": 3.0}
METHODS = ("wls", "idim-iv", "didim")


def _setup():
    import dynid
    from dynid.dynamics.base_parameters import base_parameters
    from dynid.dynamics.rnea import rnea_torques
    from dynid.excitation.paper_trajectories import paper_identification_trajectory
    from dynid.experiment.closed_loop import ClosedLoopExperiment
    from dynid.simulation.closed_loop import Controller

    robot = dynid.load_robot("er16").submodel(3)
    t = np.arange(25000) / 1000.0
    q, dq, ddq = paper_identification_trajectory(n_dof=3).evaluate(t)
    experiment = ClosedLoopExperiment(Controller.for_robot(robot), q, dq, rnea_torques(robot, q, dq, ddq))
    base = base_parameters(robot, rng=0)
    return robot, base, t, experiment


def realisation(encoder_deg: float, torque_std: float, seed: int) -> dict:
    """Every estimator on both preprocessings of one closed-loop log."""
    from dynid.experiment.closed_loop import closed_loop_identify
    from dynid.io.datasets import Recording
    from dynid.preprocessing.pipeline import Preprocessing
    from dynid.simulation.closed_loop import ClosedLoopNoise, simulate_closed_loop

    robot, base, t, experiment = _setup()
    run = simulate_closed_loop(robot, t, experiment.q_ref, experiment.dq_ref, experiment.controller,
                               ClosedLoopNoise(position_std=np.deg2rad(encoder_deg), torque_std=torque_std),
                               np.random.default_rng(seed), feedforward=experiment.feedforward)
    log = Recording("closed loop", t, run.q, None, run.tau, 1000.0)
    out = {}
    for label, band in FILTERS.items():
        estimates = closed_loop_identify(robot, base, log, experiment, preprocessing=Preprocessing(band=band) if band else None)
        out[label] = {k: (e.params, e.params_std, e.converged) for k, e in estimates.items()}
    return out


def _timing() -> dict:
    from dynid.experiment.closed_loop import closed_loop_identify
    from dynid.io.datasets import Recording
    from dynid.simulation.closed_loop import ClosedLoopNoise, simulate_closed_loop

    robot, base, t, experiment = _setup()
    run = simulate_closed_loop(robot, t, experiment.q_ref, experiment.dq_ref, experiment.controller,
                               ClosedLoopNoise(position_std=np.deg2rad(1e-2), torque_std=0.1), np.random.default_rng(99),
                               feedforward=experiment.feedforward)
    log = Recording("closed loop", t, run.q, None, run.tau, 1000.0)
    times = {}
    for method in ("idim-iv", "didim"):
        start = time.perf_counter()
        closed_loop_identify(robot, base, log, experiment, methods=(method,))
        times[method] = time.perf_counter() - start
    return times


def main(argv: list[str]) -> int:
    from dynid.experiment.montecarlo import dask_client

    realisations = int(argv[0]) if argv else 10
    robot, base, _, _ = _setup()
    truth = base.base_from_standard(robot.standard_parameters())
    cells = [(e, s) for e in ENCODER for s in TORQUE]
    start = time.perf_counter()
    with dask_client(workers=2) as client:
        futures = {(e, s, r): client.submit(realisation, e, s, r, pure=False) for e, s in cells for r in range(realisations)}
        results = {key: f.result() for key, f in futures.items()}
    wall = time.perf_counter() - start
    load = os.getloadavg()[0]
    print(f"ER-16 (3 joints), {realisations} realisations per cell, Dask local cluster of 2 workers: {wall:.0f} s; load {load:.2f}")
    print("| encoder noise | torque noise | preprocessing | estimator | median abs bias | median spread | 95 % coverage | converged |")
    print("|---|---|---|---|---|---|---|---|")
    scale = np.maximum(np.abs(truth), 1e-3)
    for e, s in cells:
        for label in FILTERS:
            for method in METHODS:
                params = np.array([results[(e, s, r)][label][method][0] for r in range(realisations)])
                std = np.array([results[(e, s, r)][label][method][1] for r in range(realisations)])
                ok = np.array([results[(e, s, r)][label][method][2] for r in range(realisations)])
                bias = np.median(np.abs(params.mean(axis=0) - truth) / scale)
                spread = np.median(params.std(axis=0) / scale)
                coverage = np.mean(np.abs(params - truth) <= 1.96 * std)
                print(f"| {e:g}° | {s:g} N·m | {label} | {method} | {100 * bias:.2f} % | {100 * spread:.2f} % | "
                      f"{100 * coverage:.0f} % | {ok.sum()}/{realisations} |")
    times = _timing()
    print(f"one run at 1e-2°, 0.1 N·m, default preprocessing (one process): IDIM-IV {times['idim-iv']:.2f} s, "
          f"DIDIM {times['didim']:.2f} s; load {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
