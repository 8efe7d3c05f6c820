"""Benchmark: time to design the 6-joint, 5-harmonic ER-16 excitation (configs/excite-er16-6dof.toml).

Target: under 60 s on 2 cores for the whole design (4 SLSQP starts, one of them β1). Prints the design
time against that target, and the cost of one gradient of the criterion and of every nonlinear
constraint by dynid's chain rule (regressor state derivatives) against forward finite differences of
the whole problem (one evaluation per design variable), both measured in this run.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from timing import best_of  # benchmarks/timing.py (run as scripts from benchmarks/)

from dynid.excitation.design import _Layout, _Objective
from dynid.identification.excite import run_excitation
from dynid.io.config.excitation_config import load_excitation_config

CONFIG = Path(__file__).resolve().parents[1] / "configs" / "excite-er16-6dof.toml"
TARGET_SECONDS = 60.0


def main() -> None:
    cfg = load_excitation_config(CONFIG)
    problem = cfg.problem
    lay = _Layout(problem, problem.design_grid())
    x = lay.to_x(cfg.initial)

    def chain_rule():
        obj = _Objective(problem, lay)
        obj.jac(x), obj.cons_jac(x)

    def finite_differences():
        obj = _Objective(problem, lay)
        f0, c0 = obj.fun(x), obj.cons(x)
        for i in range(x.size):
            e = x.copy()
            e[i] += 1e-7
            obj.fun(e), obj.cons(e)
        return f0, c0

    t_chain = best_of(chain_rule)
    t_fd = best_of(finite_differences, repeats=3)
    print(f"one gradient ({x.size} variables, criterion + {problem.grid_points} samples of torque and workspace constraints):")
    print(f"  chain rule {1e3 * t_chain:.1f} ms, finite differences {1e3 * t_fd:.1f} ms, ratio {t_fd / t_chain:.1f}x")

    t0 = time.perf_counter()
    run = run_excitation(cfg)
    seconds = time.perf_counter() - t0
    d = run.design
    print(f"6-joint 5-harmonic design, {cfg.starts} starts: {seconds:.1f} s (target {TARGET_SECONDS:.0f} s: "
          f"{seconds / TARGET_SECONDS:.2f} of it); cond(W_base) {d.initial_cond:.2f} (β1) -> {d.cond:.2f}; "
          f"{d.nit} iterations, {d.nfev} evaluations; feasible on the 10x grid: {d.feasible}")
    np.testing.assert_array_less(d.cond, d.initial_cond)


if __name__ == "__main__":
    main()
