"""Simulated experiments: the paper's run (:mod:`.paper`), the Monte Carlo study (:mod:`.montecarlo`), the closed-loop
grid (:mod:`.closed_loop_montecarlo`), simulated fleets and service lives (:mod:`.simulated_fleet`, :mod:`.simulated_logs`)."""

from .._lazy import lazy_exports

_EXPORTS = {
    "PaperExperimentConfig": "paper",
    "PaperRunResult": "paper",
    "run_paper_experiment": "paper",
}

__all__ = list(_EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
