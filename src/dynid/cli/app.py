"""dynid command-line interface (typer + rich): thin commands over the library.

Exit codes: 0 success, 1 user or data error (one-line message), 2 usage error.
"""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

import typer

from ..exceptions import DynIdError
from ..report.console import Reporter

app = typer.Typer(add_completion=True, no_args_is_help=True, rich_markup_mode=None,
                  help="dynid: dynamic model identification of industrial robot arms.")

QUIET = typer.Option(False, "--quiet", "-q", help="Print only warnings and errors (no progress, no tables).")

OPTIONS = {"out": "--out", "seed": "--seed", "joints": "--joints", "plant": "--plant", "abc_bounds": "--abc-bounds",
           "smoothing_passes": "--smoothing-passes", "bootstrap": "--bootstrap", "weights": "--weights",
           "excitation": "--excitation", "estimators": "--estimators", "noise_levels": "--noise-levels",
           "realisations": "--realisations", "scheduler": "--scheduler", "workers": "--workers", "data_root": "--data-root",
           "file": "--file", "robot": "--robot", "duration": "--duration", "rate": "--rate", "current_noise": "--current-noise",
           "colony_size": "--abc-colony", "limit": "--abc-limit", "maxiter": "--abc-iterations", "starts": "--starts",
           "preprocessing.strategy": "--strategy", "window": "--window", "reference_windows": "--reference-windows",
           "false_alarm_days": "--false-alarm-days", "logs": "--logs"}
"""Library fields (named by the library's messages) and the options that set them."""


HINTS = {"data_root": "; or give --data-root"}
"""Fields a message names inside a config, and the option that can also set them."""


def _message(exc: Exception) -> str:
    """The library's message, with the field it names translated to this command's option (``seed`` → ``--seed``)."""
    text = str(exc)
    field = getattr(exc, "field", None)
    if field in OPTIONS and text.startswith(field):
        return OPTIONS[field] + text[len(field):]
    if field in HINTS and text.endswith(")"):
        return text[:-1] + HINTS[field] + ")"
    return text


def _fail(exc: Exception, reporter: Reporter | None = None) -> None:
    (reporter or Reporter()).error(_message(exc))
    raise typer.Exit(1)


def _steps(progress):
    """The library's ``progress(step, done, total)`` shown as the step and its percentage."""
    return lambda step, done, total: progress.update(step, f"{100 * done / max(total, 1):.0f} %")


def _check_out(out, writes: tuple[str, ...] = ()) -> None:
    """An unusable --out is refused before any computation, and one holding a file of the user's named as one of
    ``writes``."""
    from ..report.output import check_output_folder

    check_output_folder(out, writes)


def _renamed(methods: str | None) -> None:
    """``--methods`` was renamed ``--estimators``: a one-line message, not a usage error."""
    if methods is not None:
        raise DynIdError(f"--methods is now --estimators (the same values): --estimators {methods}")


def _parse_weights(text: str | None):
    if text is None:
        return None
    try:
        return tuple(float(x) for x in text.split(","))
    except ValueError:
        raise DynIdError(f"--weights: expected comma-separated numbers like 1,1,0.5, got {text!r}") from None


def summary_blocks(result) -> list:
    """What a command prints of its result (:func:`dynid.report.summaries.blocks`).

    Parameters
    ----------
    result : object
        A command's result object.

    Returns
    -------
    list of Block
    """
    from ..report.summaries import blocks

    return blocks(result)


class _Command:
    """The frame every command shares: what it reads and checks (before any computation), what it computes under a
    live progress line, what it writes, and what it prints; a :class:`DynIdError` anywhere is one line and exit 1.

    Parameters
    ----------
    name : str
        The command, e.g. "dynid identify".
    quiet : bool
        Print only warnings and errors.
    out : Path, optional
        Output folder, refused before any computation when unusable.
    figures : bool
        Draw figures in a process forked before the live line starts (:func:`dynid.report.output.figure_process`).
    writes : tuple of str
        Files the command writes into ``out`` whatever the result: one of the user's there under such a name is refused
        before any computation (others, e.g. figures, when the files are saved).
    """

    def __init__(self, name: str, quiet: bool, out: Path | None = None, figures: bool = False, writes: tuple[str, ...] = ()):
        self.name, self.out, self.figures, self.writes = name, out, figures, writes
        self.reporter = Reporter(quiet)

    def run(self, prepare, compute, save, show=None) -> None:
        """Run the command.

        Parameters
        ----------
        prepare : callable
            ``prepare()`` reads and checks the inputs, returns what ``compute`` needs.
        compute : callable
            ``compute(prepared, progress)`` returns the result.
        save : callable
            ``save(result)`` writes the files, returns their paths.
        show : callable, optional
            ``show(reporter, result, paths)`` prints the outcome (default: the result's summary and the files).
        """
        rep = self.reporter
        try:
            prepared = prepare()  # a mistake is reported before any heavy import
            if self.out is not None:
                _check_out(self.out, self.writes)
            from ..report.output import figure_process

            with figure_process(self.figures):  # forked before the live line's thread starts: imports pyplot meanwhile
                with rep.progress(self.name) as progress:
                    result = compute(prepared, progress)
                    progress.update("writing results" + (" and figures" if self.figures else ""))
                paths = save(result)  # after the live progress line ended: the figures fork
        except DynIdError as exc:
            _fail(exc, rep)
        if show is None:
            rep.blocks(summary_blocks(result))
            rep.wrote(paths)
        else:
            show(rep, result, paths)


def _version(value: bool) -> None:
    if value:
        from .. import __version__

        print(f"dynid {__version__}")
        raise typer.Exit()


@app.callback()
def _root(version: bool = typer.Option(False, "--version", callback=_version, is_eager=True,
                                       help="Print dynid's version and exit."),
          plugin: list[str] | None = typer.Option(None, "--plugin", metavar="FILE_OR_MODULE",
                                                     help="A Python file or module that registers estimators or preprocessing "
                                                          "strategies of your own (repeatable; also DYNID_PLUGINS).")) -> None:
    """dynid: dynamic model identification of industrial robot arms."""
    if plugin:
        from ..plugins import add_plugins

        add_plugins(plugin)


PAPER_ESTIMATORS = "ols,abc"
"""What ``dynid run`` compares by default: the paper's ABC at its budget, beside ordinary least squares."""

RUN_DEFAULTS_CHANGED = ("dynid run now reproduces the paper's experiment as the paper set it (plant 'paper', its Table 3 "
                        "box, OLS and ABC at the paper's budget); before 0.2 it compared every estimator on the assumed "
                        "plant: --compare (docs/changelog.md)")
"""Said by a ``dynid run`` given none of --plant, --estimators, --compare, for the release that changed its defaults."""


@app.command()
def run(
    robot: str = typer.Option("er16", help="Built-in robot name or description TOML."),
    joints: int = typer.Option(3, help="Number of joints identified (the paper: 3)."),
    plant: str | None = typer.Option(None, help="Simulation truth: 'paper' (Table 2; the default) or 'assumed' (the robot "
                                                "file; the default of --compare)."),
    compare: bool = typer.Option(False, "--compare", help="The harder comparison instead of the paper's experiment: the "
                                 "assumed plant, a search box from the data, and every built-in estimator (ABC at 10x the "
                                 "paper's budget, DE, PSO, LAD, SDP ...)."),
    seed: int = typer.Option(0, help="Seed of every random number of the run."),
    out: Path = typer.Option(Path("dynid-run"), help="Output folder for results.json and figures."),
    duration: float = typer.Option(25.0, help="Recording length [s]."),
    rate: float = typer.Option(1000.0, help="Sampling rate [Hz]."),
    current_noise: float = typer.Option(0.05, help="Motor current noise standard deviation [A]."),
    smoothing_passes: int = typer.Option(1, help="Applications of eq. 17 to the torques."),
    abc_colony: int = typer.Option(30, help="ABC colony size Ns (Ne = Nu = Ns/2)."),
    abc_limit: int = typer.Option(15, help="ABC scout limit."),
    abc_iterations: int = typer.Option(50, help="ABC iterations Tmax."),
    abc_bounds: str = typer.Option("auto", help="ABC search box: auto, table3 (paper Table 3) or scaled (±(2|β_OLS|+1))."),
    weights: str | None = typer.Option(None, help="Eq. 9 weights per joint, comma separated (default all 1)."),
    excitation: str = typer.Option("paper", help="Identification trajectory: paper (β1), optimized (designed for the run, min cond), or an excitation.json of dynid excite."),
    estimators: str | None = typer.Option(None, help="Estimators compared, comma separated: ols, wls, irls, lad, sdp, abc, "
                                          "abc10, de, pso, or all registered (default: ols,abc, the paper's; with "
                                          "--compare every built-in one)."),
    methods: str | None = typer.Option(None, hidden=True),
    bootstrap: int = typer.Option(100, help="Moving-block bootstrap resamples for OLS and WLS confidence intervals (0: none)."),
    strategy: str = typer.Option("paper", help="Preprocessing strategy of the simulated logs: paper (eq. 17 and the Fourier fit), parallel, or one registered."),
    figures: bool = typer.Option(True, help="Write the figures (--no-figures: results.json only)."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help="Print every table (parameters, per joint, bootstrap); "
                                                                 "report.html has them too."),
    quiet: bool = QUIET,
) -> None:
    """Reproduce the paper's identification experiment on a simulated robot as the paper set it (ER-16, joints 1-3, the
    paper's plant and Table 3 box, ABC at the paper's budget beside OLS); --compare runs the harder comparison of every
    estimator on the assumed plant."""
    from ..estimators.registry import label, parse_estimators
    from ..report.paper_run import save_paper_run
    from ..studies.paper import PaperExperimentConfig, run_paper_experiment

    notices: list[str] = []

    def prepare():
        from ..model.description import load_robot

        _renamed(methods)
        paper_first = not compare and plant is None and estimators is None
        chosen_plant = plant or ("assumed" if compare or robot != "er16" or joints != 3 else "paper")
        chosen = estimators if estimators is not None else (None if compare or chosen_plant != "paper" else PAPER_ESTIMATORS)
        config = PaperExperimentConfig(
            robot=robot, joints=joints, plant=chosen_plant, seed=seed, duration=duration, rate=rate,
            current_noise=current_noise, smoothing_passes=smoothing_passes, colony_size=abc_colony,
            limit=abc_limit, maxiter=abc_iterations, weights=_parse_weights(weights), abc_bounds=abc_bounds,
            excitation=excitation, estimators=parse_estimators(chosen), bootstrap=bootstrap, strategy=strategy)
        if paper_first and chosen_plant == "paper":
            notices.append(RUN_DEFAULTS_CHANGED)
        config.validate(load_robot(config.robot))  # every option checked before the run starts
        return config

    def compute(config, progress):
        return run_paper_experiment(config, progress=lambda k, i, f: progress.update(
            label(k), "" if i is None else f"iteration {i}, best F = {f:.4g}"))

    def show(rep, result, paths):
        from ..report.paper_summary import run_summary_blocks

        for text in notices:
            rep.warning(text)
        rep.blocks(run_summary_blocks(result, verbose))
        rep.wrote(paths)

    _Command("dynid run", quiet, out, figures).run(prepare, compute, lambda result: save_paper_run(result, out, figures), show)


@app.command()
def identify(
    config: Path = typer.Argument(..., help="Identification config (TOML), e.g. configs/ur10e.toml."),
    *,
    out: Path = typer.Option(Path("dynid-identify"), help="Output folder for results.json and figures."),
    data_root: Path | None = typer.Option(None, help="Folder of the data files (overrides the config's data_root)."),
    validate: bool = typer.Option(True, help="Also validate on the config's [[validation]] datasets."),
    figures: bool = typer.Option(True, help="Write the torque figures (--no-figures: results.json only)."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help="Print every table (parameters, preprocessing, "
                                                                 "fit and validation per joint); report.html has them too."),
    quiet: bool = QUIET,
) -> None:
    """Identify a robot's base parameters from its logs (OLS/WLS with σ), then validate them."""
    from ..identification.run import run_identification
    from ..io.config.identification_config import load_identification_config

    def prepare():
        cfg = load_identification_config(config, data_root=data_root)  # a mistake is reported before any heavy import
        from ..report import identification_run  # noqa: F401  imported before the figure process forks: once for both

        return cfg

    def compute(cfg, progress):
        return cfg.robot, run_identification(cfg, progress=_steps(progress), validate=validate), cfg

    def save(identified):
        from ..report.identification_run import model_file_name, save_identification

        urdf, mjcf = identified[2].urdf, identified[2].mjcf_model
        return save_identification(identified[1], out, figures_too=figures, robot=identified[0], urdf=urdf,
                                   urdf_name=None if urdf is None else model_file_name(urdf, out), mjcf_model=mjcf,
                                   mjcf_name=None if mjcf is None else model_file_name(mjcf, out), mjcf_folder=out,
                                   config=identified[2])

    def show(rep, identified, paths):
        from ..report.summaries import identification_brief

        blocks = summary_blocks(identified[1]) if verbose else identification_brief(identified[1])
        rep.blocks(_runnable_advice(blocks, config, out, skipped=0 if validate else len(identified[2].validation)))
        rep.blocks(_taken_away(out, config))
        rep.wrote(paths)

    _Command("dynid identify", quiet, out, figures, ("results.json", "report.html")).run(prepare, compute, save, show)


def _taken_away(out: Path, config: Path) -> list:
    """The lines on the files ``dynid identify`` wrote, read back (results.json's ``files_taken_away``), or why it wrote
    none (``files_withheld``); and, for an MJCF read back on a validation log, that it was not simulated forward here,
    with the command that does (issue "Every assurance checked on what the user meets", item 3)."""
    import json
    import shlex

    from ..report.summaries import taken_away_lines
    from ..tables import Line

    path = out / "results.json"
    data = json.loads(path.read_text(encoding="utf-8")) if path.is_file() else {}
    withheld = [Line(data["files_withheld"], "warning")] if data.get("files_withheld") else []
    taken = data.get("files_taken_away")
    if not taken:
        return withheld
    lines = taken_away_lines(taken)
    mjcf = next((f for f in taken["files"] if f["format"] == "MJCF" and "not_read_back" not in f), None)
    if mjcf is not None and taken.get("log"):
        command = (f"dynid export {shlex.quote(str(config))} --results {shlex.quote(str(path))} --mjcf "
                   f"{shlex.quote(config.stem)}-identified.xml --forward")
        lines.append(Line(f"{mjcf['file']} not simulated forward by dynid identify (MuJoCo stepping the file along "
                          f"{taken['log']} under a PD loop: the torques a simulated arm needs against the measured ones): "
                          f"{command} runs it"))
    return withheld + lines


def _runnable_advice(blocks, config: Path, out: Path, skipped: int = 0) -> list:
    """The summary's advice as commands that run as printed: ``dynid export CONFIG --urdf FILE [--mjcf FILE]`` with
    this config, the results just written and files named after the config; ``(dynid excite)`` as ``dynid excite
    CONFIG`` (an identification config is an excitation config: its robot and ``[excitation]`` table).

    Parameters
    ----------
    blocks : list of Block
        What :mod:`dynid.report.summaries` builds for the identification.
    config : Path
        The config ``dynid identify`` was given.
    out : Path
        Its output folder.
    skipped : int
        The config's validation logs ``--no-validate`` left out: the advice to add some says to run with them instead.

    Returns
    -------
    list of Block
        The same blocks, the lines' placeholders replaced.
    """
    import dataclasses
    import shlex

    from ..tables import Line

    cfg, stem = shlex.quote(str(config)), shlex.quote(config.stem)
    export = f"dynid export {cfg} --results {shlex.quote(str(out / 'results.json'))} --urdf {stem}-identified.urdf"
    words = {"dynid export CONFIG --urdf FILE --mjcf FILE": f"{export} --mjcf {stem}-identified.xml",
             "dynid export CONFIG --urdf FILE": export, "(dynid excite)": f"(dynid excite {cfg})"}
    if skipped:
        words["add [[validation]] logs (other motions)"] = (f"run again without --no-validate (the config's {skipped} "
                                                            f"validation log{'s' if skipped > 1 else ''}: other motions)")

    def concrete(text: str) -> str:
        for placeholder, command in words.items():
            text = text.replace(placeholder, command)
        return text

    return [dataclasses.replace(b, text=concrete(b.text)) if isinstance(b, Line) else b for b in blocks]


def _check_targets(targets: list) -> None:
    """The files ``dynid export`` is to write, checked before any work (it writes nothing unless it can write
    everything): each a writable file in an existing folder, not the same file twice."""
    import os

    from ..exceptions import DataError

    for flag, path in targets:
        if path.is_dir():
            raise DataError(f"{flag} {path}: a folder; give the name of the file to write")
        if path.exists() and not path.is_file():  # /dev/null as root would be replaced by a regular file
            raise DataError(f"{flag} {path}: not a regular file (a device, a FIFO or a socket): give the name of a "
                            "file to write")
        if not path.parent.is_dir():
            raise DataError(f"{flag} {path}: its folder does not exist")
        if not os.access(path.parent, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
            raise DataError(f"{flag} {path}: cannot be written (permissions)")
    if len(targets) == 2 and targets[0][1].resolve() == targets[1][1].resolve():
        raise DataError(f"--urdf and --mjcf name the same file ({targets[0][1]}): give each its own")


@app.command()
def export(
    config: Path = typer.Argument(..., help="Identification config (TOML) the results were identified with."),
    results: Path = typer.Option(Path("dynid-identify/results.json"), help="results.json written by dynid identify."),
    urdf: Path | None = typer.Option(None, help="URDF file to write (inertials and joint friction of the physically consistent estimate)."),
    mjcf: Path | None = typer.Option(None, help="MuJoCo MJCF file to write (inertials, armature, damping, frictionloss)."),
    mjcf_model: Path | None = typer.Option(None, help="Your own MuJoCo model of the arm: --mjcf writes the values into a copy of it (names, frames, geoms, meshes kept). Default: the config's mjcf_model."),
    data_root: Path | None = typer.Option(None, help="Folder of the data files (overrides the config's data_root)."),
    forward: bool = typer.Option(False, "--forward", help="Simulate the MJCF in MuJoCo along the config's first moving "
                                 "validation log and compare the torques it needs with the measured ones."),
    quiet: bool = QUIET,
) -> None:
    """Export the physically consistent estimate as URDF and/or MuJoCo MJCF (for Pinocchio, simulators, controllers)."""
    from ..io.config.identification_config import load_identification_config

    def _users_mjcf(cfg):  # the model --mjcf writes into: --mjcf-model, else the config's mjcf_model
        return mjcf_model if mjcf_model is not None else cfg.mjcf_model

    def prepare():
        from ..exceptions import DataError

        if forward and mjcf is None:
            raise DataError("--forward simulates the MJCF: give --mjcf FILE too")
        cfg = load_identification_config(config, data_root=data_root)
        identified = _read_results(results, cfg.robot)
        return cfg, identified, _export_targets(urdf, mjcf, mjcf_model, cfg, (results,))

    def compute(prepared, progress):
        from ..io.exported.export import consistent_estimate

        cfg, identified, targets = prepared
        moved: list[str] = []
        progress.update("writing the model's files")
        texts = [(path, _export_text(flag, cfg, identified, str(results), _users_mjcf(cfg), mjcf, moved))
                 for flag, path in targets]
        estimate = consistent_estimate(cfg.robot, identified, str(results))
        progress.update("reading the files back (" + ", ".join("Pinocchio" if flag == "--urdf" else "MuJoCo"
                                                               for flag, _ in targets) + ")")
        log = _replay_log(cfg, identified, estimate[0])
        checks = {path: _replayed(flag, text, (*estimate, identified), log) for (flag, path), (_, text) in zip(targets, texts)}
        shown = _steps(progress)
        simulated = _simulated(cfg, identified, texts, targets, str(results), progress=lambda done, total: shown(
            "simulating the MJCF in MuJoCo along a validation log", done, total)) if forward else None
        return cfg, texts, moved, identified, checks, simulated, None if log is None else log[0]

    def save(computed):
        from ..io.files import atomic_write_text

        for path, text in computed[1]:
            atomic_write_text(path, text)
        return [path for path, _ in computed[1]]

    def show(rep, computed, paths):
        cfg = computed[0]
        _export_report(rep, computed, paths, urdf=cfg.urdf if urdf is not None else None,
                       mjcf=_users_mjcf(cfg) if mjcf is not None else None)

    _Command("dynid export", quiet).run(prepare, compute, save, show)


def _export_report(rep, computed, paths, *, urdf: Path | None, mjcf: Path | None) -> None:
    """``dynid export``'s lines: the files written (``urdf``, ``mjcf``: the user's files written into, if any), the
    warnings of the estimate and the results, what each file's tool reads back, and the forward simulation's line."""
    from ..io.exported.export import nominal_warning, verdict_warnings
    from ..report.identification_run import file_choice, read_back_entry
    from ..report.summaries import taken_away_lines

    cfg, _, moved, identified, checks, simulated, log = computed
    robot = cfg.robot
    held = file_choice(identified, "MJCF")["offsets_held"]
    added = {"URDF": "", "MJCF": f", and {len(held)} actuator(s) of constant bias added after its own for the torque "
             "offsets" if held else ""}
    into = "".join(f"; the {form} is {given.name} with only its inertials and joint dynamics replaced{added[form]}"
                   for form, given in (("URDF", urdf), ("MJCF", mjcf)) if given is not None)
    for line in moved:
        rep.warning(f"far from the description's own values: {line}")
    for line in verdict_warnings(identified):
        rep.warning(line)
    gate = nominal_warning(identified)
    if gate is not None:
        rep.warning(gate)
    rep.line(f"wrote {', '.join(str(p) for p in paths)} (robot {robot.name}, {robot.n_dof} joints{into}; what the "
             "format cannot hold, e.g. a URDF's offsets, is stated in comments)")
    files = [read_back_entry(path.name, form, check, file_choice(identified, form)) for path, (form, check) in checks.items()]
    for line in taken_away_lines({"log": log, "files": files}):
        (rep.warning if line.kind == "warning" else rep.line)(line.text)
    if simulated is not None:
        rep.line(simulated)


def _init_robot(urdf: Path, log: Path, arm: str | None, args: dict):
    """``dynid init``'s robot: the robot file with the joints held that are not the arm's (those off the chain the log
    names, or the chain holding ``arm``; on a log of several branches' chains, every joint but those:
    :func:`dynid.model.urdf.joints_to_hold`)."""
    from ..io.logs.columns import joints_named
    from ..model.description import load_robot, robot_from_urdf
    from ..model.urdf import expand_xacro, is_mjcf, is_xacro, joints_to_hold

    read = (expand_xacro(urdf, args) if is_xacro(urdf) else urdf) if urdf.is_file() else None

    def logged(names: tuple[str, ...]) -> set[str]:
        if arm is None:
            return joints_named(log, names)
        if arm not in names:
            raise DynIdError(f"--arm {arm}: no moving joint of {urdf.name} is named so (it has {', '.join(names)})")
        return {arm}

    held = (joints_to_hold(read, logged) if read is not None and (read.suffix.lower() == ".urdf" or is_mjcf(read))
            else ())
    if arm is not None and not held:
        raise DynIdError(f"--arm {arm}: {urdf.name} is one serial chain (no other arm to leave out); leave --arm out")
    return robot_from_urdf(urdf, held=held, xacro_args=args) if held else load_robot(urdf, xacro_args=args)


def _simulated(cfg, identified: dict, texts, targets, source: str, progress=None) -> str:
    """``dynid export --forward``'s line: the MJCF written simulated along the first moving validation log
    (:func:`dynid.identification.run.forward_check`)."""
    from ..identification.run import forward_check

    mjcf = next((path, text) for (flag, _), (path, text) in zip(targets, texts) if flag == "--mjcf")
    found = forward_check(cfg, identified, mjcf[1], source=source, progress=progress)
    if found is None:
        return f"{mjcf[0].name} not simulated: the config has no validation log that moves (--forward follows one)"
    log, check = found
    return (f"{mjcf[0].name} simulated in MuJoCo along {log} ({check.n_samples} samples; computed torque and a PD loop, "
            f"tracking within {check.tracking_error.max():.2g} rad): the torques it needs are {check.simulated_vs_measured:.3g} % "
            f"off the measured ones, against {check.model_vs_measured:.3g} % for dynid's model on the same samples "
            f"({check.simulated_vs_model:.3g} % between the two: MuJoCo's frictionloss, what MJCF cannot hold)")


def _replay_log(cfg, identified: dict, robot):
    """The states the written files are read back on: the config's first moving validation log
    (:func:`dynid.identification.run.moving_validation`) as ``(name, (q, dq, ddq), tau)``, or None (random states)."""
    from ..exceptions import DataError
    from ..identification.run import moving_validation

    try:
        found = moving_validation(cfg, identified, robot) if cfg.validation else None
    except DataError:  # a log that cannot be read here: the replay falls back to random states
        return None
    if found is None:
        return None
    name, (_, q, dq, ddq, tau) = found
    return name, (q, dq, ddq), tau


def _replayed(flag: str, text: str, estimate, log=None) -> tuple[str, object]:
    """The written file read back by its tool (:mod:`dynid.io.exported.replay`): ``(format, ReplayCheck)``, or the format and
    why it was not read back. ``estimate``: the robot, dynid's whole model and results.json (what the file holds:
    :func:`dynid.io.exported.export.file_parameters`). On ``log`` (:func:`_replay_log`) where given, else on random states."""
    from ..io.exported.export import file_parameters

    robot, whole, identified = estimate
    on = {"whole": whole} if log is None else {"states": log[1], "measured": log[2], "whole": whole}
    held = file_parameters(robot, whole, identified, form="URDF" if flag == "--urdf" else "MJCF")[0]
    if flag == "--urdf":
        from ..io.exported.replay import urdf_replay

        return "URDF", urdf_replay(text, robot, held, **on)
    try:
        import mujoco  # noqa: F401  the MJCF's own reader
    except ImportError:
        return "MJCF", "MuJoCo is not installed (pip install 'dynid[mujoco]')"
    from ..io.exported.replay import mjcf_replay

    try:
        return "MJCF", mjcf_replay(text, robot, held, **on)
    except (ValueError, KeyError) as exc:  # a user's model whose meshes MuJoCo finds only beside the original
        return "MJCF", f"MuJoCo could not load it from its text ({str(exc).splitlines()[0]})"


def _export_targets(urdf: Path | None, mjcf: Path | None, mjcf_model: Path | None, cfg,
                    read: tuple[Path, ...] = ()) -> list[tuple[str, Path]]:
    """The files ``dynid export`` is to write, as (flag, path), checked before any work: at least one, a
    ``--mjcf-model`` only with ``--mjcf`` and with the robot's joints, writable places (:func:`_check_targets`),
    none of the files the run reads (the config's, ``cfg.files_read``, ``--mjcf-model`` and ``read``)."""
    from ..exceptions import DataError

    robot = cfg.robot
    targets = [(flag, path) for flag, path in (("--urdf", urdf), ("--mjcf", mjcf)) if path is not None]
    if mjcf_model is not None and mjcf is None:
        raise DataError("--mjcf-model is the model --mjcf writes into: give --mjcf FILE too")
    if not targets:
        raise DataError("give --urdf FILE and/or --mjcf FILE")
    if mjcf_model is not None and not mjcf_model.is_file():
        raise DataError(f"--mjcf-model {mjcf_model}: no such file")
    if mjcf_model is not None:
        from ..io.exported.mjcf_write_back import read_users_mjcf

        read_users_mjcf(mjcf_model, robot)  # its joints are the robot's, before any work
    _check_targets(targets)
    users = () if mjcf_model is None else (mjcf_model,)
    models = {p.resolve() for p in (*cfg.description_files, *users)}
    inputs = {p.resolve() for p in (*cfg.files_read, *read, *users)}
    for flag, path in targets:
        if path.resolve() in inputs:
            what = ("the robot's description this run reads: the identified values would become the description's "
                    "nominal values on the next run" if path.resolve() in models else "a file this run reads")
            raise DataError(f"{flag} {path}: {what}; give another file name, e.g. "
                            f"{path.stem}-identified{'.urdf' if flag == '--urdf' else '.xml'}")
    return targets


def _export_text(flag: str, cfg, identified: dict, source: str, users_mjcf: Path | None, mjcf: Path | None,
                 moved: list[str]) -> str:
    """The text of one ``dynid export`` file (``flag``: "--urdf" or "--mjcf"): the user's URDF or MJCF with the
    identified values written in, or a file of dynid's own where the description has none; values far from the
    description's own are appended to ``moved``."""
    from ..io.exported.model_files import written_model

    if flag == "--urdf":  # the user's URDF, the values written in; a DH description: a URDF of its own
        text, far = written_model("URDF", cfg.robot, identified, source, users_file=cfg.urdf)
    else:
        text, far = written_model("MJCF", cfg.robot, identified, source, users_file=users_mjcf,
                                  out_dir=mjcf.parent if mjcf else None)
    moved.extend(far)
    return text


def _read_results(results: Path, robot) -> dict:
    """The results.json of dynid identify for ``robot`` (a Robot), checked (:func:`dynid.io.results.read_results`,
    :func:`dynid.io.results.check_fingerprint`)."""
    from ..io.results import check_fingerprint, read_results

    found = read_results(results, robot.name, "; run dynid identify first or give --results")
    check_fingerprint(found, robot, str(results))
    return found


def _parse_rows(text: str | None):
    if text is None:
        return None
    try:
        first, last = (int(x) for x in text.split(","))
    except ValueError:
        raise DynIdError(f"--rows: expected two 1-based row numbers like 700,4200, got {text!r}") from None
    return [first, last]


@app.command()
def validate(
    config: Path = typer.Argument(..., help="Identification config (TOML) the results were identified with."),
    results: Path = typer.Option(Path("dynid-identify/results.json"), help="results.json written by dynid identify."),
    file: Path | None = typer.Option(None, help="Validate on this log instead (same column map as the identification data)."),
    rows: str | None = typer.Option(None, help="Rows of --file, 1-based inclusive: first,last."),
    out: Path = typer.Option(Path("dynid-validate"), help="Output folder for validation.json and figures."),
    data_root: Path | None = typer.Option(None, help="Folder of the data files (overrides the config's data_root)."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help="Print every log's table (error, RMSE and ρ per joint "
                                                                 "and parameter set); report.html has them too."),
    yardstick: bool = typer.Option(False, "--yardstick", help="Filter every log by dynid's default rules, whatever "
                                   "settings the results were identified with: results of other settings, or "
                                   "another tool's model, scored on the same samples."),
    quiet: bool = QUIET,
) -> None:
    """Validate identified parameters (and the config's reference sets) on other logs."""
    from ..exceptions import DataError
    from ..identification.run import run_validation
    from ..io.config.identification_config import dataset_for_file, load_identification_config

    def prepare():
        cfg = load_identification_config(config, data_root=data_root)
        from ..report import identification_run  # noqa: F401  imported before the figure process forks: once for both

        identified = _read_results(results, cfg.robot)
        if file is not None:
            return cfg, identified, (dataset_for_file(cfg, file, _parse_rows(rows)),)
        if rows is not None:
            raise DataError("--rows needs --file")
        return cfg, identified, None

    def save(validated):
        from ..report.identification_run import save_validation

        return save_validation(validated[0], out, validated[1])

    def show(rep, validated, paths):
        from ..identification.evidence import YARDSTICK
        from ..report.summaries import validation_blocks
        from ..tables import Line

        comparisons, warnings = validated
        said = [Line(f"on one yardstick: {YARDSTICK}")] if yardstick else []
        rep.blocks([*said, *validation_blocks(comparisons, tables=verbose)])
        for w in warnings:
            rep.warning(w)
        rep.wrote(paths)

    _Command("dynid validate", quiet, out, figures=True, writes=("validation.json", "report.html")).run(
        prepare, lambda p, progress: run_validation(p[0], p[1], datasets=p[2], progress=_steps(progress), source=str(results),
                                                 yardstick=yardstick), save, show)


@app.command()
def payload(
    config: Path = typer.Argument(..., help="Identification config (TOML) of the arm the results were identified with."),
    file: Path = typer.Option(..., help="Log with the new tool on the flange (same column map as the identification data)."),
    results: Path = typer.Option(Path("dynid-identify/results.json"), help="results.json of dynid identify: the arm without the tool."),
    rows: str | None = typer.Option(None, help="Rows of --file, 1-based inclusive: first,last."),
    out: Path = typer.Option(Path("dynid-payload"), help="Output folder for payload.json, payload.urdf and payload.xml."),
    data_root: Path | None = typer.Option(None, help="Folder of the data files (overrides the config's data_root)."),
    joint: str | None = typer.Option(None, help="The joint whose link carries the tool (default: the last; on a robot "
                                                "with branches, the last joint of the other arm)."),
    quiet: bool = QUIET,
) -> None:
    """Identify a tool's payload (mass, centre of mass, inertia) from a log with it, the arm's model known."""
    from ..identification.run import run_payload
    from ..io.config.identification_config import dataset_for_file, load_identification_config

    def prepare():
        cfg = load_identification_config(config, data_root=data_root)
        return cfg, _read_results(results, cfg.robot), dataset_for_file(cfg, file, _parse_rows(rows)), \
            _payload_link(cfg.robot, joint)

    def compute(p, progress):
        return p[0], p[3], run_payload(p[0], p[1], p[2], source=str(results), link=p[3])

    def save(computed):
        from ..report.identification_run import save_payload

        cfg, link, (found, label, _) = computed
        return save_payload(found, out, robot=cfg.robot, parent=_urdf_link(cfg, link), estimate=label, link=link)

    def show(rep, computed, paths):
        cfg, link, (found, label, ratio) = computed
        for line in payload_lines(found, label, ratio):
            rep.line(line)
        if cfg.robot.is_tree:  # which hand: the last joint's unless named
            rep.line(f"on the link of {cfg.robot.joints[link].name}" + ("" if joint is not None else
                     ", the robot's last joint (--joint names another arm's)"))
        for line in payload_warnings(found, f"joint {link + 1} ({cfg.robot.joints[link].name})"):
            rep.warning(line)
        rep.wrote(paths)

    _Command("dynid payload", quiet, out, writes=("payload.json", "payload.urdf", "payload.xml")).run(prepare, compute, save, show)


def payload_warnings(found, last_joint: str) -> list[str]:
    """What ``dynid payload`` warns of: a fit far above what a right payload leaves
    (:attr:`~dynid.identification.payload.Payload.misfit`), and a last link that slid during the log
    (:attr:`~dynid.identification.payload.Payload.rides_a_sliding_link`).

    Parameters
    ----------
    found : dynid.identification.payload.Payload
    last_joint : str
        The chain's last joint, as named in the warning.

    Returns
    -------
    list of str
    """
    out = []
    if found.misfit:  # a rigid payload on the flange leaves the log's noise
        out.append(f"the fit with the payload is {found.error_with / found.expected:.2g} times the log's noise floor "
                   f"or the arm model's own residual, the larger ({found.error_with:.3g} % against "
                   f"{found.expected:.3g} %): something beyond a rigid payload on the flange (a last link that moves, "
                   "such as a gripper's jaw; the arm's model; torques read otherwise): check it before using the "
                   "payload")
    if found.rides_a_sliding_link:
        out.append(f"the payload is fitted on the link of {last_joint}, which is prismatic and slid "
                   f"{1000 * found.last_joint_travel:.3g} mm during this log (a gripper's jaw?): a tool on the flange "
                   "rides on the link before it, so these figures are not a rigid tool's; hold that joint ([robot] "
                   "held) and identify the arm and its payload again")
    return out


def payload_lines(found, label: str, ratio=None) -> list[str]:
    """What ``dynid payload`` prints: the payload in the flange's frame with σ, what the log did not determine, and
    the log's error without and with it.

    Parameters
    ----------
    found : dynid.identification.payload.Payload
    label : str
        The arm's estimate.
    ratio : (n_dof,) array, optional
        The identified drive gains over those the torques were read with (said where not all 1).

    Returns
    -------
    list of str
    """
    import numpy as np

    inertia = found.inertia
    lines = [f"payload: {found.mass:.4g} kg (σ {found.mass_std:.2g}), centre of mass "
             f"({', '.join(f'{1000 * c:.1f}' for c in found.com)}) mm in the flange's frame "
             f"(σ {', '.join(f'{1000 * c:.1g}' for c in found.com_std)} mm), inertia about it: Ixx {inertia[0, 0]:.3g}, "
             f"Iyy {inertia[1, 1]:.3g}, Izz {inertia[2, 2]:.3g}, Ixy {inertia[0, 1]:.3g}, Ixz {inertia[0, 2]:.3g}, "
             f"Iyz {inertia[1, 2]:.3g} kg·m² (physically consistent)",
             f"the log's torque error: {found.error_without:.3g} % with the arm's model alone ({label}), "
             f"{found.error_with:.3g} % with the payload"]
    if ratio is not None and not np.allclose(ratio, 1.0):
        lines.append("with the drive gains the results identified ([drive_gains]): the torques the payload adds scaled "
                     f"by {', '.join(f'{r:.3g}' for r in ratio)} (J1-J{len(ratio)}) from the gains the log was read with")
    if not found.mass > 3 * found.mass_std:
        lines.append(f"the log shows no payload: its mass is within 3σ of 0 ({found.mass:.3g} ± {found.mass_std:.2g} kg), "
                     "so its centre of mass and inertia mean nothing")
    if found.not_determined:
        lines.append(f"not determined by this log (σ ≥ 100 % of the value, or no action on the joints): "
                     f"{', '.join(found.not_determined)} (about the last link's frame): kept at a point mass's values; a "
                     "motion that turns the tool about more axes determines them")
    return lines


def _payload_link(robot, joint: str | None) -> int:
    """``dynid payload --joint``: the link carrying the tool, 0-based (the last joint's by default).

    Raises
    ------
    ConfigError
        A name that is not one of the robot's joints.
    """
    from ..exceptions import ConfigError

    names = [jt.name for jt in robot.joints]
    if joint is None:
        return robot.n_dof - 1
    if joint not in names:
        raise ConfigError(f"--joint: expected one of {robot.name}'s joints ({', '.join(names)}), got {joint!r}")
    return names.index(joint)


def _urdf_link(cfg, link: int) -> str:
    """The URDF link joint ``link`` (0-based) moves (its child) where the config has a URDF, else dynid's own name for
    it."""
    import xml.etree.ElementTree as ET

    last = cfg.robot.joints[link].name
    if cfg.urdf is not None:
        try:
            for joint in ET.parse(cfg.urdf).getroot().iter("joint"):
                child = joint.find("child")
                if joint.get("name") == last and child is not None:
                    return child.get("link", "")
        except (OSError, ET.ParseError):
            pass
    return f"link{link + 1}"


@app.command()
def excite(
    config: Path = typer.Argument(..., help="Excitation config (TOML), e.g. configs/excite-er16.toml, or the robot's URDF "
                                            "(xacro) or MJCF alone: the default design for it."),
    out: Path = typer.Option(Path("dynid-excite"), help="Output folder for excitation.json, excitation.csv and figures."),
    starts: int | None = typer.Option(None, help="Number of optimisation starts (overrides design.starts)."),
    seed: int | None = typer.Option(None, help="Seed of the random starts (overrides design.seed)."),
    animation: bool = typer.Option(False, help="Also write excitation_animation.gif: the arm moving along one period "
                                               "among the cell's bodies."),
    verbose: bool = typer.Option(False, "--verbose", "-v", help="Print the design's before/after and constraint "
                                                                 "margins tables; report.html has them too."),
    quiet: bool = QUIET,
) -> None:
    """Design an optimal excitation trajectory (min cond(W_base) under the constraints of eq. 15)."""
    from dataclasses import replace

    from ..identification.excite import run_excitation
    from ..io.config.excitation_config import load_excitation_config

    def prepare():
        cfg = load_excitation_config(config)
        return replace(cfg, starts=cfg.starts if starts is None else starts, seed=cfg.seed if seed is None else seed)

    def compute(cfg, progress):
        step = [f"design, 0 of {cfg.starts} starts done"]  # on two cores two starts are solved at once
        progress.update(step[0])

        def started(done: int, n: int, best: float) -> None:  # each start's line says the best design so far
            if done < n:
                step[0] = f"design, {done} of {n} starts done, best cond so far {best:.4g}"
                progress.update(step[0])

        def iterated(k: int, maxiter: int) -> None:  # a long start says how far it has come (on a terminal)
            progress.update(step[0], f"(SLSQP iteration {k}, at most {maxiter})")

        return run_excitation(cfg, callback=started, iteration=iterated)

    def save(run):
        from ..report.excitation_run import save_excitation

        return save_excitation(run, out, animation=animation)

    def show(rep, run, paths):
        from ..report.excitation_summary import excitation_blocks

        rep.blocks(excitation_blocks(run, tables=verbose))
        rep.wrote(paths)

    _Command("dynid excite", quiet, out, writes=("excitation.json", "excitation.csv", "report.html")).run(prepare, compute, save, show)


@app.command()
def init(
    urdf: Path = typer.Argument(..., help="The robot's URDF (or xacro file), or its MuJoCo model (MJCF, .xml)."),
    log: Path = typer.Argument(..., help="A CSV log of the robot moving (time, joint angles, joint torques or currents), or a ROS 2 bag."),
    validation: list[Path] | None = typer.Argument(None, help="Other logs, to validate on (one of another layout gets its own reader); where the log holds one signal per "
                                                    "file (Joint_1 … Joint_n), the first is its other signal's file (pos_… and curr_…)."),
    out: Path = typer.Option(Path("arm.toml"), help="The config to write."),
    force: bool = typer.Option(False, help="Overwrite --out if it exists."),
    rate: float | None = typer.Option(None, help="The logs' sample rate [Hz], for CSV logs without a time column.",
                                      min=1e-9),
    xacro_arg: list[str] | None = typer.Option(None, "--xacro-arg",
                                               help="A xacro file's argument, name:=value (repeat for several)."),
    arm: str | None = typer.Option(None, help="A joint of the arm to identify, where the robot file has several "
                                   "(two arms): the chain holding it (default: the one whose joints the log names)."),
    quiet: bool = QUIET,
) -> None:
    """Write a starter identification config for a URDF and a log, with the columns it detected."""
    from ..io.config.starter import check_target, starter_config, xacro_arguments

    args: dict[str, str] = {}

    def prepare():
        args.update(xacro_arguments(xacro_arg or []))  # a malformed one is refused in one line, as every mistake here
        if rate is not None and not (math.isfinite(rate) and rate > 0):
            raise DynIdError(f"--rate: expected the logs' sample rate, a positive number of Hz, got {rate:g}")
        check_target(out, force, (urdf, log, *(validation or ())))
        if not out.parent.is_dir():
            raise DynIdError(f"--out {out}: its folder does not exist")
        return _init_robot(urdf, log, arm, args)

    def compute(robot, progress):
        for v in validation or ():
            if not v.exists():
                raise DynIdError(f"{v}: no such validation log")
        from ..identification.starter_check import checked_against_description

        progress.update("reading the log's columns")
        text, notes = starter_config(urdf, log, int(robot.independent.sum()), out, tuple(validation or ()),
                                     tuple(j.name for j in robot.joints if j.mimic is None), robot.held, robot=robot,
                                     rate=rate, xacro_args=args)
        shown = _steps(progress)  # the check's identification of the log's first seconds, step by step
        text, found = checked_against_description(
            text, out, progress=lambda step, done, total: shown(f"checking the log against the robot file: {step}", done,
                                                                total))
        return text, notes + found

    def save(written):
        from ..io.files import atomic_write_text

        atomic_write_text(out, written[0])
        return [out]

    def show(rep, written, paths):
        for note in written[1]:
            rep.line(note)
        rep.line(f"wrote {out}: check the columns and units, then: dynid identify {out}")

    _Command("dynid init", quiet).run(prepare, compute, save, show)


@app.command()
def example(
    robot: str = typer.Argument(..., help="A robot built into dynid: ur10e, tx40 or er16."),
    out: Path = typer.Argument(..., help="The folder to write (new, or empty)."),
    quiet: bool = QUIET,
) -> None:
    """Write a folder to try dynid on: the robot's URDF, two simulated logs and the config identify runs on."""

    def prepare():
        if out.exists() and (not out.is_dir() or any(p for p in out.iterdir() if not p.name.startswith("."))):
            raise DynIdError(f"{out}: exists and is not an empty folder; give a new folder")
        from ..studies.example import EXAMPLES

        if robot not in EXAMPLES:
            raise DynIdError(f"no example for robot {robot!r}: choose one of {', '.join(EXAMPLES)}")
        return robot

    def compute(name, progress):
        from ..studies.example import example_files

        progress.update("simulating the logs")
        return example_files(name)

    def save(files):
        from ..report.output import save_texts

        return save_texts(files, out)

    def show(rep, files, paths):
        config = next(name for name in files if name.endswith(".toml"))
        rep.line(f"wrote {', '.join(files)} in {out}/ (simulated logs of the {robot}): now cd {out} and run "
                 f"dynid identify {config}, then open dynid-identify/report.html")

    _Command("dynid example", quiet, out).run(prepare, compute, save, show)


@app.command()
def migrate(
    config: Path = typer.Argument(..., help="An identify config (TOML) of an earlier release."),
    out: Path | None = typer.Option(None, help="Write the migrated config here (default: rewrite CONFIG in place)."),
    quiet: bool = QUIET,
) -> None:
    """Rewrite an identify config of an earlier release for this one (renamed keys), keeping its comments and layout,
    and name the settings it uses whose meaning changed."""
    from ..io.config.migrate import migrate_text

    target = out or config

    def prepare():
        if not config.is_file():
            raise DynIdError(f"{config}: no such config")
        if out is not None and not out.parent.is_dir():
            raise DynIdError(f"--out {out}: its folder does not exist")
        if out is not None and out.exists() and out.resolve() != config.resolve():  # a log, the robot file, another config
            raise DynIdError(f"--out {out}: exists; give the migrated config a new file name (or leave --out out to "
                             f"rewrite {config} in place)")
        try:
            return config.read_text(encoding="utf-8-sig")  # as identify reads a config: a byte-order mark skipped
        except UnicodeDecodeError as exc:
            raise DynIdError(f"{config}: not a text file (byte {exc.start} is no UTF-8): expected a TOML config") from None

    def compute(text, progress):
        return migrate_text(text, str(config))

    def save(migrated):
        from ..io.files import atomic_write_text

        if migrated[0] == config.read_text(encoding="utf-8-sig") and out is None:
            return []
        atomic_write_text(target, migrated[0])
        return [target]

    def show(rep, migrated, paths):
        for change in migrated[1]:
            rep.line(f"{config}: {change}")
        rep.line(f"wrote {target}" if paths else f"{config}: nothing to rewrite")

    _Command("dynid migrate", quiet).run(prepare, compute, save, show)


def _parse_levels(text: str, option: str = "--noise-levels", unit: str = "A", example: str = "0.02,0.05,0.1"):
    try:
        return tuple(float(x) for x in text.split(","))
    except ValueError:
        raise DynIdError(f"{option}: expected comma-separated noise levels in {unit} like {example}, got {text!r}") from None


def _closed_loop_estimators(text: str | None) -> tuple[str, ...]:
    """The estimators of a closed-loop study (checked by :meth:`ClosedLoopStudyConfig.validate`)."""
    from ..studies.closed_loop_montecarlo import CLOSED_LOOP_ESTIMATORS

    return CLOSED_LOOP_ESTIMATORS if text is None else tuple(k.strip().lower() for k in text.split(","))


@app.command()
def montecarlo(
    robot: str = typer.Option("er16", help="Built-in robot name or description TOML."),
    joints: int = typer.Option(3, help="Number of joints identified."),
    noise_levels: str = typer.Option("0.02,0.05,0.1", help="Motor current noise standard deviations [A], comma separated."),
    realisations: int = typer.Option(100, help="Noise realisations per level."),
    estimators: str | None = typer.Option(None, help="Estimators, comma separated: ols, wls, irls, lad, sdp, abc, abc10, de, pso, "
                                                        "any registered, or all (default: ols,wls,irls,lad,sdp,abc); with --closed-loop also idim-iv, didim, didim-sdp (default: the first six and idim-iv, didim)."),
    methods: str | None = typer.Option(None, hidden=True),
    seed: int = typer.Option(0, help="Seed of every random number of the study."),
    duration: float = typer.Option(25.0, help="Recording length [s]."),
    rate: float | None = typer.Option(None, help="Sampling rate [Hz] (default 200; 1000 in closed loop, the control rate; the paper: 1000)."),
    abc_bounds: str = typer.Option("scaled", help="Search box of ABC/DE/PSO/LAD: scaled (±(2|β_OLS|+1), holds the truth) or table3."),
    excitation: str = typer.Option("paper", help="Identification trajectory: paper (β1), optimized, or an excitation.json."),
    strategy: str = typer.Option("paper", help="Preprocessing strategy of the simulated logs: paper (eq. 17 and the Fourier fit), parallel, or one registered."),
    closed_loop: bool = typer.Option(False, "--closed-loop", help="Simulate the robot under its own PID (the loop sees the noisy positions) on the "
                                                                  "noise grid of Leboutet et al. 2021, and fit IDIM-IV and DIDIM beside the others."),
    encoder_noise: str = typer.Option("1e-4,1e-3,1e-2", help="Closed loop: encoder noise standard deviations [°], comma separated."),
    torque_noise: str = typer.Option("0.05,0.1", help="Closed loop: torque noise standard deviations [N·m], comma separated."),
    band: float | None = typer.Option(None, help="Closed loop: the excitation band [Hz] given to the preprocessing (default: derived from each log)."),
    bandwidth: float = typer.Option(5.0, help="Closed loop: the PID's bandwidth [Hz]."),
    scheduler: str | None = typer.Option(None, help="Dask scheduler address (e.g. tcp://host:8786); default: a LocalCluster of this machine's cores."),
    workers: int | None = typer.Option(None, help="Worker processes of the LocalCluster (default: number of cores)."),
    out: Path = typer.Option(Path("dynid-montecarlo"), help="Output folder for montecarlo.json, the estimates CSV and figures."),
    quiet: bool = QUIET,
) -> None:
    """Monte Carlo study: bias and spread of each estimator over noise realisations against the Cramér–Rao bound."""
    from ..estimators.registry import parse_estimators
    from ..report.montecarlo_run import save_montecarlo
    from ..studies.montecarlo import DEFAULT_ESTIMATORS, MonteCarloConfig, run_montecarlo

    def prepare():
        _renamed(methods)
        if closed_loop:
            from ..studies.closed_loop_montecarlo import ClosedLoopStudyConfig

            study = ClosedLoopStudyConfig(robot=robot, joints=joints, encoder_noise=_parse_levels(encoder_noise, "--encoder-noise", "°", "1e-4,1e-3,1e-2"),
                                          torque_noise=_parse_levels(torque_noise, "--torque-noise", "N·m", "0.05,0.1"),
                                          realisations=realisations, estimators=_closed_loop_estimators(estimators), seed=seed,
                                          duration=duration, rate=1000.0 if rate is None else rate, bandwidth=bandwidth, band=band,
                                          excitation=excitation)
            study.validate()
            config = study
        else:
            config = MonteCarloConfig(robot=robot, joints=joints, noise_levels=_parse_levels(noise_levels), realisations=realisations,
                                      estimators=parse_estimators(estimators, DEFAULT_ESTIMATORS), seed=seed, duration=duration,
                                      rate=200.0 if rate is None else rate, abc_bounds=abc_bounds, excitation=excitation, strategy=strategy)
            config.validate()  # every option checked before the workers start
        from ..runtime.extras import require

        require("distributed", "montecarlo", "dynid montecarlo")
        return config

    def compute(cfg, progress):
        progress.update("starting the workers")
        report = lambda i, n: progress.update(f"realisations, {10 * (10 * i // max(n, 1))} % done", f"{i}/{n}")  # noqa: E731
        if closed_loop:
            from ..studies.closed_loop_montecarlo import run_closed_loop_study

            return run_closed_loop_study(cfg, scheduler=scheduler, workers=workers, progress=report)
        return run_montecarlo(cfg, scheduler=scheduler, workers=workers, progress=report)

    def save(result):
        if closed_loop:
            from ..report.montecarlo_run import save_closed_loop_study

            return save_closed_loop_study(result, out)
        return save_montecarlo(result, out)

    _Command("dynid montecarlo", quiet, out, writes=("montecarlo.json", "report.html")).run(prepare, compute, save)


@app.command()
def fleet(
    manifest: Path = typer.Argument(..., help="Fleet manifest (TOML): the units, their logs, a template config."),
    out: Path = typer.Option(Path("dynid-fleet"), help="Output folder: fleet.json, fleet.parquet, fleet.html, units/<id>/."),
    data_root: Path | None = typer.Option(None, help="Data root of units given by their own config."),
    scheduler: str | None = typer.Option(None, help="Dask scheduler address (e.g. tcp://host:8786); its workers read the "
                                                       "logs at the manifest's paths. Default: a LocalCluster of this machine's cores."),
    workers: int | None = typer.Option(None, help="Worker processes of the LocalCluster (default: number of cores)."),
    quiet: bool = QUIET,
) -> None:
    """Identify every unit of a fleet on a Dask cluster, flag the units that stand out, pool their estimates."""
    from ..fleet.identification import check_fleet_options, run_fleet
    from ..io.config.fleet_manifest import load_fleet_manifest

    def prepare():
        check_fleet_options(workers)
        parsed = load_fleet_manifest(manifest, data_root)  # every unit's config checked before the workers start
        from ..runtime.extras import require

        require("distributed", "fleet", "dynid fleet")
        require("pyarrow", "fleet", "dynid fleet")
        return parsed

    def compute(parsed, progress):
        from ..report.fleet_run import save_unit

        progress.update("starting the workers")
        return run_fleet(parsed, out=out, save=save_unit, scheduler=scheduler, workers=workers, progress=_steps(progress))

    def save(result):
        from ..report.fleet_run import save_fleet

        return save_fleet(result, out)

    _Command("dynid fleet", quiet, out, writes=("fleet.json", "fleet.parquet", "fleet.html")).run(prepare, compute, save)


@app.command()
def monitor(
    config: Path = typer.Argument(..., help="The robot's identify config (its identification log's columns read the logs)."),
    logs: Path = typer.Option(..., help="Folder of the robot's logs; time order from the dates in their names "
                                        "(2026-01-15T08-30.csv), else their names."),
    results: Path = typer.Option(Path("dynid-identify/results.json"), help="results.json of the last full identification."),
    out: Path = typer.Option(Path("dynid-monitor"), help="Output folder: monitor.json, monitor.parquet, monitor.png, "
                                                         "and the state the next run goes on from."),
    data_root: Path | None = typer.Option(None, help="Folder of the config's data files."),
    window: float = typer.Option(10.0, help="Seconds of log per window of re-identified friction terms."),
    reference_windows: int = typer.Option(60, help="Windows that set each term's reference (the first ones)."),
    false_alarm_days: float = typer.Option(30.0, help="One false alarm per this many days of logs, on average."),
    restart: bool = typer.Option(False, "--restart", help="Monitor every log anew, not going on from the state an "
                                                          "earlier run left in --out (monitor-state.json)."),
    quiet: bool = QUIET,
) -> None:
    """Follow a robot's friction and drive terms through its logs and raise an alarm when one changes (wear).

    Run again on a growing folder, it goes on from the state the last run left in --out and reads only the new logs.
    """
    from ..exceptions import DataError
    from ..fleet.monitor import (
        STATE_FILE,
        MonitorSettings,
        dated_logs,
        legacy_state_refusal,
        monitor_fingerprint,
        monitor_logs,
        resumed_monitor,
    )
    from ..io.config.identification_config import load_identification_config

    def prepare():
        settings = MonitorSettings(window, reference_windows, false_alarm_days)
        cfg = load_identification_config(config, data_root=data_root)
        files = dated_logs(logs)
        from ..identification.fitted_model import load_results

        model = load_results(results, robot=cfg.robot)
        fingerprint = monitor_fingerprint(results, settings)
        state = out / STATE_FILE
        refusal = None if restart else legacy_state_refusal(out)
        if refusal is not None:
            raise DataError(refusal)
        resume = resumed_monitor(state, fingerprint, model, settings) if state.is_file() and not restart else None
        return cfg, model, files, settings, resume, fingerprint

    def compute(prepared, progress):
        cfg, model, files, settings, resume, fingerprint = prepared
        return monitor_logs(cfg, model, files, settings, progress=_steps(progress), resume=resume, fingerprint=fingerprint)

    def save(result):
        from ..report.monitor_run import save_monitor

        return save_monitor(result, out)

    _Command("dynid monitor", quiet, out, writes=("monitor.json",)).run(prepare, compute, save)


class Interrupted(BaseException):
    """Ctrl-C or SIGTERM, raised by dynid's signal handler: a BaseException that is no KeyboardInterrupt, so no
    library on the way swallows it and the atomic writes' and staging's clean-up still runs.

    Parameters
    ----------
    signum : int
        The signal received.
    """

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


def _interrupt(signum, frame):
    raise Interrupted(signum)


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Python's warnings as a command prints them: a setting that changed (a ``FutureWarning``: it names the
    setting and the new spelling) as one warning line; any other as Python shows it, with where it came from."""
    if issubclass(category, FutureWarning):
        Reporter().warning(str(message))
    else:
        sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))


def main(argv: list[str] | None = None) -> int:
    """Console-script entry point.

    Ctrl-C ends with one line and exit code 130 (128 + SIGINT), SIGTERM likewise with 143 (128 + SIGTERM): the
    output folder is left as it was before the command (its staged files are removed).

    Parameters
    ----------
    argv : list of str, optional
        The arguments after ``dynid`` (default: the command line's).

    Returns
    -------
    int
        The exit code: 0 success, 1 user or data error, 2 usage error, 130/143 interrupted.
    """
    import os
    import signal

    os.environ.setdefault("MPLBACKEND", "Agg")  # figures go to files: no display needed, none opened
    if argv is None:  # the console script's own process: freed memory kept for reuse (a caller's allocator is its own)
        from ..runtime.memory import keep_freed_memory

        keep_freed_memory()

    from ..runtime.processes import allow_forks

    handlers = {sig: signal.signal(sig, _interrupt) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        # this process is dynid's: figures and drive gains may go to forked children
        with allow_forks(), warnings.catch_warnings():
            warnings.showwarning = _show_warning
            app(args=argv, prog_name="dynid")
    except SystemExit as exc:  # typer ends every command this way
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    except DynIdError as exc:  # pragma: no cover - commands already catch theirs
        Reporter().error(_message(exc))
        return 1
    except Interrupted as exc:
        name = "Ctrl-C" if exc.signum == signal.SIGINT else "SIGTERM"
        print(f"interrupted ({name})", file=sys.stderr)
        return 128 + exc.signum
    finally:
        for sig, handler in handlers.items():
            signal.signal(sig, handler)
        # The process ends here. Its objects leave the garbage collector's sight, so that the interpreter's
        # last collection does not walk every object of SciPy, cvxpy and Pinocchio (0.1 s of every command);
        # modules, files and atexit handlers are still finalised as usual, and the system frees the memory.
        if argv is None:  # the process ends here; a caller's process goes on
            import gc

            gc.freeze()
    return 0


if __name__ == "__main__":
    sys.exit(main())
