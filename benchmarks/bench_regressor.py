"""Benchmark: batched regressor vs a loop over Pinocchio's computeJointTorqueRegressor.

25,000 random samples of the 6-DOF er16 (the paper's 25 s at 1 kHz). Both sides produce the full
(N, n_dof, n_params) array. Prints the time per sample of each and the ratio (target: >= 6x).
Each side is timed as the best of several repeats after a warm-up (compilation, page faults).
dynid's side is its compiled regressor, the er16's SIMD code (a process's first 60 000 samples would
otherwise go through the NumPy form, timed on its own line, as is numba's kernel, used where the SIMD code
cannot be built).
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pinocchio as pin
from timing import best_of  # benchmarks/timing.py (run as scripts from benchmarks/)

from dynid.dynamics import _regressor_kernel
from dynid.dynamics import regressor as regressor_module
from dynid.dynamics.regressor import friction_torques, regressor
from dynid.dynamics.rnea import pinocchio_model
from dynid.model.description import load_robot

N = 25_000
REPEATS = 5


def _measure(n: int, repeats: int) -> tuple[float, float]:
    """:func:`measure`, with the NumPy budget spent."""
    robot = load_robot("er16")
    rng = np.random.default_rng(0)
    q, dq, ddq = (rng.uniform(-2, 2, (n, robot.n_dof)) for _ in range(3))
    model = pinocchio_model(robot)
    data = model.createData()
    n_inertial = 10 * robot.n_dof

    def reference():
        out = np.empty((n, robot.n_dof, n_inertial))
        for k in range(n):
            out[k] = pin.computeJointTorqueRegressor(model, data, q[k], dq[k], ddq[k])
        return out

    def batched():
        return regressor(robot, q, dq, ddq)

    # same physics: both regressors times their own parameter vectors give the same torques
    phi_pin = np.concatenate([np.asarray(i.toDynamicParameters()).ravel() for i in model.inertias[1:]])
    y_ref, y_dyn = reference()[:200], batched()[:200]
    tau_dyn = y_dyn @ robot.standard_parameters() - friction_torques(robot, dq[:200], ddq[:200])
    assert np.allclose(y_ref @ phi_pin, tau_dyn, atol=1e-8), "regressors disagree"
    assert regressor_module._simd["used"], "the SIMD code did not run"
    return best_of(reference, repeats), best_of(batched, repeats)


def measure(n: int = N, repeats: int = REPEATS) -> tuple[float, float]:
    """Best wall times [s] of Pinocchio's loop and of dynid's batched regressor (its compiled form, from the
    first sample) on ``n`` random er16 samples, each producing the full (n, n_dof, n_params) array; checks
    first that both give the same torques."""
    budget = regressor_module.NUMPY_SAMPLES
    regressor_module.NUMPY_SAMPLES = 0
    try:
        return _measure(n, repeats)
    finally:
        regressor_module.NUMPY_SAMPLES = budget


def numpy_form(n: int = N, repeats: int = 3) -> float:
    """Best wall time [s] of ``regressor`` on the same samples in its NumPy form (what a process computes before
    the compiled regressor takes over): run before :func:`measure`, with the NumPy budget raised."""
    assert not (_regressor_kernel.compiled() or regressor_module._simd["used"]), "the NumPy form is timed first"
    robot = load_robot("er16")
    q, dq, ddq = (np.random.default_rng(0).uniform(-2, 2, (n, robot.n_dof)) for _ in range(3))
    budget = regressor_module.NUMPY_SAMPLES
    regressor_module.NUMPY_SAMPLES = 10**12
    try:
        return best_of(lambda: regressor(robot, q, dq, ddq), repeats)
    finally:
        regressor_module.NUMPY_SAMPLES = budget


def numba_kernel(n: int = N, repeats: int = 3) -> float:
    """Best wall time [s] of numba's kernel on the same samples (the compiled regressor where the SIMD code
    cannot be built)."""
    robot = load_robot("er16")
    q, dq, ddq = (np.random.default_rng(0).uniform(-2, 2, (n, robot.n_dof)) for _ in range(3))
    return best_of(lambda: regressor_module._fill(robot, q, dq, ddq, np.empty((n, robot.n_dof, robot.n_params)),
                                                  np.arange(robot.n_params), form="numba"), repeats)


def fill_floor(n: int = N, repeats: int = REPEATS, threads: int = 1) -> float:
    """Best wall time [s] of allocating the er16's (n, n_dof, n_params) array and writing each entry once, on
    ``threads`` threads: the floor of any regressor that returns that array (issue 40), measured beside it."""
    robot = load_robot("er16")

    def fill():
        out = np.empty((n, robot.n_dof, robot.n_params))
        bounds = np.linspace(0, n, threads + 1).astype(int)
        with ThreadPoolExecutor(threads) as pool:
            list(pool.map(lambda k: out[bounds[k]:bounds[k + 1]].fill(1.0), range(threads)))
        return out

    return best_of(fill, repeats)


def main() -> None:
    t_np = numpy_form()
    t_ref, t_dyn = measure()
    t_numba = numba_kernel()
    t_fill, t_fill2 = fill_floor(), fill_floor(threads=2)
    print(f"samples: {N}, robot: er16 (6 DOF), best of {REPEATS}")
    print(f"pinocchio computeJointTorqueRegressor loop: {1e6 * t_ref / N:8.3f} µs/sample ({t_ref:.3f} s)")
    print(f"dynid batched regressor (with friction):    {1e6 * t_dyn / N:8.3f} µs/sample ({t_dyn:.3f} s)")
    print(f"its NumPy form (a process's first {regressor_module.NUMPY_SAMPLES} samples):                        "
          f"{1e6 * t_np / N:.3f} µs/sample")
    print(f"numba's kernel (where the SIMD code cannot be built):          {1e6 * t_numba / N:.3f} µs/sample")
    print(f"the fill floor (allocate the array, write each entry once): {1e6 * t_fill / N:.3f} µs/sample on one thread, "
          f"{1e6 * t_fill2 / N:.3f} on two")
    print(f"ratio (reference / dynid): {t_ref / t_dyn:.1f}x   target >= 6x: {'met' if t_ref / t_dyn >= 6 else 'NOT met'}")
    print(f"ratio (dynid / one thread's fill floor): {t_dyn / t_fill:.2f}x   target <= 1.2x: "
          f"{'met' if t_dyn / t_fill <= 1.2 else 'NOT met'}")


if __name__ == "__main__":
    main()
