"""Compile dynid's numba kernels into numba's on-disk cache once, at installation (``make`` runs
``python -m dynid.warm_up`` after installing), so that the first command a user runs does not pay the
compilation (about 2 s of a cold ``dynid run``).

A short paper experiment with every estimator passes through every compiled kernel with the argument
types of real runs: the regressor (:mod:`dynid.dynamics._regressor_kernel`) and eq. 9's objective
(:mod:`dynid.estimators._objective_kernel`). Without a writable cache it only costs its own time.
"""

from __future__ import annotations


def warm_up() -> None:
    """Run a 2 s, 200 Hz paper experiment with every estimator (2 ABC iterations, 2 bootstrap resamples)."""
    from .dynamics import _regressor_kernel

    _regressor_kernel.load_compiled()  # compiled, the kernel computes every regressor (not the NumPy form)
    from .estimators.names import parse_methods
    from .experiment import PaperExperimentConfig, run_paper_experiment

    run_paper_experiment(PaperExperimentConfig(duration=2.0, rate=200.0, methods=parse_methods("all"), bootstrap=2, maxiter=2))


if __name__ == "__main__":
    warm_up()
