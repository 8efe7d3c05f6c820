"""Compile dynid's kernels into their on-disk caches once, at installation (``make`` runs
``python -m dynid.warm_up`` after installing), so that the first command a user runs does not pay the
compilation (about 2 s of a cold ``dynid run``).

The regressor's SIMD code of the built-in robots (:mod:`dynid.dynamics._regressor_simd`, 0.5 s each) and
numba's regressor kernel (:mod:`dynid.dynamics._regressor_kernel`) are compiled first. Then a short paper
experiment with every estimator passes through eq. 9's compiled objective
(:mod:`dynid.estimators._objective_kernel`) with the argument types of real runs. Without a writable cache
it only costs its own time.
"""

from __future__ import annotations


def warm_up() -> None:
    """Compile the regressors of the built-in robots (their SIMD code, and numba's kernel), then run a 2 s,
    200 Hz paper experiment with every estimator (2 ABC iterations, 2 bootstrap resamples), and compile the recursive
    least squares of ``dynid monitor``, the closed-loop simulator's steps and a long log's parallel filter."""
    from .dynamics import regressor
    from .model.description import load_robot

    er16 = load_robot("er16")
    regressor.compile_kernels([er16, er16.submodel(3), load_robot("ur10e"), load_robot("tx40")])
    from .studies.paper import PaperExperimentConfig, run_paper_experiment

    run_paper_experiment(PaperExperimentConfig(duration=2.0, rate=200.0, bootstrap=2, maxiter=2))
    import numpy as np

    from .estimators.recursive import RecursiveLeastSquares

    RecursiveLeastSquares(np.zeros((6, 3))).update(np.ones((2, 6, 3)), np.ones((2, 6)))  # dynid monitor's kernel
    from .simulation.closed_loop import Controller, simulate_closed_loop

    t = np.arange(10) / 1000.0  # the closed-loop simulator's steps (IDIM-IV, DIDIM)
    simulate_closed_loop(er16, t, np.zeros((10, 6)), np.zeros((10, 6)), Controller.for_robot(er16))
    from scipy import signal

    from .preprocessing._filter_kernel import gaussian_nearest, gaussian_weights, zero_phase

    sos = signal.butter(4, 0.1, output="sos")  # a long log's parallel filter and Gaussian smoothing
    zero_phase(sos, np.ones((20, 3)), 5, signal.sosfilt_zi(sos))
    gaussian_nearest(np.ones(20), gaussian_weights(2.0))


if __name__ == "__main__":
    warm_up()
