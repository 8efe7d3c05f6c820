"""End-to-end experiments assembled from the library's parts."""

_EXPORTS = {
    "PaperExperimentConfig": "paper",
    "PaperRunResult": "paper",
    "run_paper_experiment": "paper",
}

__all__ = ["PaperExperimentConfig", "PaperRunResult", "run_paper_experiment"]


def __getattr__(name):  # exports are imported on first use, so that importing a submodule stays light
    if name in _EXPORTS:
        import importlib

        return getattr(importlib.import_module(f"{__name__}.{_EXPORTS[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(__all__)
