"""End-to-end experiments assembled from the library's parts."""

from .._lazy import lazy_exports

_EXPORTS = {
    "PaperExperimentConfig": "paper",
    "PaperRunResult": "paper",
    "run_paper_experiment": "paper",
}

__all__ = ["PaperExperimentConfig", "PaperRunResult", "run_paper_experiment"]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
