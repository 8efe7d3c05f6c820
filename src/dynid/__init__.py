"""dynid: dynamic model identification of industrial robot arms.

The package follows the procedure of Ding et al., "Dynamic Model Identification for 6-DOF
Industrial Robots" (the ER-16 paper): linear model (eqs. 1-6), Fourier excitation (eq. 14-15),
torques from currents (eq. 16), smoothing (eq. 17), artificial bee colony and least-squares
estimation (eqs. 7-13) and validation by the correlation coefficient (eq. 18).

The main entry points, importable from the package (each loads its modules on first use)::

    import dynid
    robot = dynid.load_robot("ur10e")                       # built-in name or description TOML
    result = dynid.identify_from_arrays(robot, t, q, tau)   # or, from logs:
    result = dynid.run_identification(dynid.load_identification_config("configs/ur10e.toml"))
    comparisons, warnings = dynid.run_validation(config, results_json_dict)
    design = dynid.design_excitation(dynid.ExcitationProblem(robot, omega_f, n_harmonics))
    urdf_text = dynid.urdf_from_robot(robot, standard_parameters)
    run = dynid.run_paper_experiment(dynid.PaperExperimentConfig(estimators=("ols", "abc")))

``examples/`` holds short scripts that use them.
"""

from ._lazy import alias_moved_modules, lazy_exports

__version__ = "0.2.0"

MOVED_MODULES = {f"dynid.{name}": f"dynid.{package}.{name}" for package, names in (
    ("runtime", ("threads", "processes")), ("_util", ("typed", "checks", "column_store"))) for name in names} | {
    "dynid.preprocessing.pipeline": "dynid.preprocessing.preparation"}
"""Modules of 0.1.0 grouped into packages or renamed in 0.2 (``preprocessing.pipeline``: the identification's
pipeline has that name) -> where they went: their old paths import them, with a FutureWarning, for a release
(docs/changelog.md)."""
alias_moved_modules(MOVED_MODULES)

_EXPORTS = {
    "load_robot": "dynid.model.description",
    "Robot": "dynid.model.robot",
    "regressor": "dynid.dynamics.regressor",
    "base_parameters": "dynid.dynamics.base_parameters",
    "rnea_torques": "dynid.dynamics.rnea",
    "Preprocessing": "dynid.preprocessing.settings",
    "load_identification_config": "dynid.io.config.identification_config",
    "run_identification": "dynid.identification.run",
    "run_validation": "dynid.identification.run",
    "identify_from_arrays": "dynid.identification.run",
    "ExcitationProblem": "dynid.excitation.design",
    "design_excitation": "dynid.excitation.design",
    "FourierTrajectory": "dynid.excitation.fourier",
    "urdf_from_robot": "dynid.model.description_files",
    "urdf_from_results": "dynid.io.exported.export",
    "mjcf_from_robot": "dynid.model.description_files",
    "PaperExperimentConfig": "dynid.studies.paper",
    "run_paper_experiment": "dynid.studies.paper",
    "summary": "dynid.report.summaries",
    "Identifier": "dynid.identification.identifier",
    "IdentifiedModel": "dynid.identification.fitted_model",
    "load_results": "dynid.identification.fitted_model",
    "simulated_log": "dynid.studies.simulated_logs",
    "load_recording": "dynid.io.logs.datasets",
}

__all__ = ["__version__", *_EXPORTS]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
