"""End-to-end experiments assembled from the library's parts."""

from .paper import PaperExperimentConfig, PaperRunResult, run_paper_experiment

__all__ = ["PaperExperimentConfig", "PaperRunResult", "run_paper_experiment"]
