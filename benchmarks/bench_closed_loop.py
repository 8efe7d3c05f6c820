"""Time of IDIM-IV and DIDIM on the paper's ER-16 experiment in closed loop (issue: under 10 s each on two cores).

The paper's ER-16 (3 joints, excitation β1, 25 s at 1 kHz) under a PID with model feed-forward
(:meth:`dynid.simulation.closed_loop.Controller.for_robot`), encoder noise 1e-2 degrees and torque noise 0.1 N·m, the
log prepared by dynid's defaults; each estimator timed on its own (least squares, then its closed-loop iterations).

    .venv/bin/python benchmarks/bench_closed_loop.py
"""

from __future__ import annotations

import time

import numpy as np


def measure() -> dict:
    """Seconds of one IDIM-IV and one DIDIM run, with their iterations."""
    import dynid
    from dynid.dynamics.base_parameters import base_parameters
    from dynid.dynamics.rnea import rnea_torques
    from dynid.excitation.paper_trajectories import paper_identification_trajectory
    from dynid.identification.closed_loop_estimators import ClosedLoopExperiment, closed_loop_identify
    from dynid.io.logs.datasets import Recording
    from dynid.simulation.closed_loop import ClosedLoopNoise, Controller, simulate_closed_loop

    robot = dynid.load_robot("er16").submodel(3)
    t = np.arange(25000) / 1000.0
    q, dq, ddq = paper_identification_trajectory(n_dof=3).evaluate(t)
    experiment = ClosedLoopExperiment(Controller.for_robot(robot), q, dq, rnea_torques(robot, q, dq, ddq))
    run = simulate_closed_loop(robot, t, q, dq, experiment.controller,
                               ClosedLoopNoise(position_std=np.deg2rad(1e-2), torque_std=0.1), rng=np.random.default_rng(0),
                               feedforward=experiment.feedforward)
    log = Recording("closed loop", t, run.q, None, run.tau, 1000.0)
    base = base_parameters(robot, rng=0)
    out = {}
    for key in ("idim-iv", "didim"):
        t0 = time.perf_counter()
        est = closed_loop_identify(robot, base, log, experiment, methods=(key,))[key]
        out[key] = (time.perf_counter() - t0, est.iterations, est.converged)
    return out


if __name__ == "__main__":
    import os

    print(f"load before: {os.getloadavg()[0]:.2f}")
    for key, (seconds, iterations, converged) in measure().items():
        print(f"{key}: {seconds:.2f} s, {iterations} closed-loop simulations, converged {converged}")
