"""dynid command-line interface (typer + rich): thin commands over the library.

Exit codes: 0 success, 1 user or data error (one-line message), 2 usage error.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Optional

import typer
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
from rich import box
from rich.markup import escape
from rich.table import Table

from ..exceptions import DynIdError

app = typer.Typer(add_completion=False, no_args_is_help=True, rich_markup_mode=None,
                  help="dynid: dynamic model identification of industrial robot arms.")
console = Console()
if not console.is_terminal:  # logs and pipes: the width the environment states, else 100 columns
    import os

    console = Console(width=int(os.environ["COLUMNS"]) if os.environ.get("COLUMNS", "").isdigit() else 100)
err_console = Console(stderr=True)


def _fail(exc: Exception) -> None:
    err_console.print(f"[bold red]error:[/] {escape(str(exc))}", highlight=False, soft_wrap=True)
    raise typer.Exit(1)


def _check_out(out) -> None:
    """An unusable --out is refused before any computation."""
    from ..report.output import check_output_folder

    check_output_folder(out)


def _wrote(paths) -> None:
    """One line: the first file, the other files by name, and how many figures, in which folder."""
    pngs = [p for p in paths if p.suffix == ".png"]
    others = "".join(f", {p.name}" for p in paths[1:] if p.suffix != ".png")
    console.print(f"wrote {paths[0]}{others} and {_count(len(pngs), 'figure')} in {paths[0].parent}/")


def _count(n: int, noun: str) -> str:
    """``"no figures"``, ``"1 figure"``, ``"3 figures"``."""
    return f"no {noun}s" if n == 0 else f"1 {noun}" if n == 1 else f"{n} {noun}s"


def _parse_weights(text: Optional[str]):
    if text is None:
        return None
    try:
        return tuple(float(x) for x in text.split(","))
    except ValueError:
        raise DynIdError(f"--weights: expected comma-separated numbers like 1,1,0.5, got {text!r}") from None


def _version(value: bool) -> None:
    if value:
        from .. import __version__

        console.print(f"dynid {__version__}", highlight=False)
        raise typer.Exit()


@app.callback()
def _root(version: bool = typer.Option(False, "--version", callback=_version, is_eager=True,
                                       help="Print dynid's version and exit.")) -> None:
    """dynid: dynamic model identification of industrial robot arms."""


@app.command()
def run(
    robot: str = typer.Option("er16", help="Built-in robot name or description TOML."),
    joints: int = typer.Option(3, help="Number of joints identified (the paper: 3)."),
    plant: str = typer.Option("assumed", help="Simulation truth: 'assumed' (the robot file) or 'paper' (Table 2)."),
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
    weights: Optional[str] = typer.Option(None, help="Eq. 9 weights per joint, comma separated (default all 1)."),
    excitation: str = typer.Option("paper", help="Identification trajectory: paper (β1), optimized (designed for the run, min cond), or an excitation.json of dynid excite."),
    methods: str = typer.Option("all", help="Estimators compared, comma separated: ols, wls, irls, lad, sdp, abc, abc10, de, pso (default all)."),
    bootstrap: int = typer.Option(100, help="Moving-block bootstrap resamples for OLS and WLS confidence intervals (0: none)."),
    figures: bool = typer.Option(True, help="Write the figures (--no-figures: results.json only)."),
) -> None:
    """Reproduce the paper's identification experiment on a simulated robot (default: ER-16, joints 1-3)
    and compare the estimators on it."""
    from ..experiment import PaperExperimentConfig, run_paper_experiment
    from ..estimators.names import LABELS, parse_methods
    from ..report.paper_run import save_paper_run

    try:
        _check_out(out)
        config = PaperExperimentConfig(
            robot=robot, joints=joints, plant=plant, seed=seed, duration=duration, rate=rate,
            current_noise=current_noise, smoothing_passes=smoothing_passes, colony_size=abc_colony,
            limit=abc_limit, maxiter=abc_iterations, weights=_parse_weights(weights), abc_bounds=abc_bounds,
            excitation=excitation, methods=parse_methods(methods), bootstrap=bootstrap)
        with Progress(TextColumn("[bold]{task.description}[/]"), TextColumn("iteration {task.fields[it]}"),
                      TextColumn("best F = {task.fields[best]}"), TimeElapsedColumn(), console=console,
                      transient=True) as progress:
            task = progress.add_task("estimating", it="—", best="—")
            result = run_paper_experiment(config, progress=lambda k, i, f: progress.update(
                task, description=LABELS[k], it=str(i), best=f"{f:.4g}"))
        paths = save_paper_run(result, out, figures)
    except DynIdError as exc:
        _fail(exc)
    _print_run(result, paths)


def _joined(values, fmt: str) -> str:
    return " / ".join(format(v, fmt) for v in values)


def _print_run(result, paths) -> None:
    from ..estimators.physically_consistent import CONSISTENCY_TOL
    from ..experiment import paper_reference as ref
    from ..estimators.names import DESCRIPTIONS, LABELS

    d = result.to_dict()
    methods = {LABELS[k]: v for k, v in d["methods"].items()}
    cfg = result.config
    console.print(f"\n[bold]dynid run[/] — robot {result.robot.name}, joints 1-{cfg.joints}, plant '{cfg.plant}', "
                  f"seed {cfg.seed}: {len(d['parameters'])} base parameters "
                  f"({len(d['parameters']) - 2 * cfg.joints} inertial + {2 * cfg.joints} friction)")
    ex = d["trajectories"]["excitation"]
    console.print(f"identification trajectory: {ex['trajectory']}; cond(W_base) {ex['cond_base_regressor']:.2f} "
                  f"(β1: {ex['cond_base_regressor_beta1']:.2f})", soft_wrap=True)
    console.print("methods: " + "; ".join(f"{LABELS[k]} = {DESCRIPTIONS[k]}" for k in d["methods"]), soft_wrap=True, highlight=False)
    per_table = max(1, (console.width - 42) // 11)  # method columns that fit beside name, truth and Table 2
    labels = list(methods)
    for first in range(0, len(labels), per_table):
        group = labels[first:first + per_table]
        part = f" ({first // per_table + 1} of {-(-len(labels) // per_table)})" if len(labels) > per_table else ""
        t = Table(title=f"Base parameters: truth and estimates{part} (units in results.json)", box=box.SIMPLE_HEAD, padding=(0, 1))
        for col in ("name (paper)", "truth", *group, "Table 2"):
            t.add_column(col, justify="left" if col == "name (paper)" else "right", no_wrap=True)
        for n in d["parameters"]:
            sym = d["paper_symbols"][n]
            t.add_row(f"{n} ({sym})" if sym else n, f"{d['truth'][n]:.4g}",
                      *(f"{methods[label]['params'][n]:.4g}" for label in group), f"{ref.TABLE2[sym]:.4g}" if sym in ref.TABLE2 else "")
        console.print(t)
    t = Table(title="Estimators: F = eq. 9 on β1 (N·m); evals of eq. 9; wall s (run side by side); Δβ = ‖β̂−β‖/‖β‖ %; "
                    "mean over joints of ρ (eq. 18), RMSE (N·m) and error % on β2; physically consistent",
              box=box.SIMPLE_HEAD, padding=(0, 1))
    for col in ("method", "F", "evals", "s", "Δβ %", "ρ β2", "RMSE", "err %", "cons."):
        t.add_column(col, justify="left" if col == "method" else "right", no_wrap=True)
    for label, m in methods.items():
        t.add_row(label, f"{m['objective']:.4g}", str(m["n_evaluations"]) if m["n_evaluations"] else "—",
                  f"{m['seconds']:.1f}", f"{m['parameter_error_norm_percent']:.3g}",
                  *(f"{sum(m[k][s]) / cfg.joints:{f}}" for k, s, f in (
                    ("correlation", "validation", ".4f"), ("rmse", "validation", ".3g"), ("relative_error", "validation", ".3g"))),
                  "yes" if m["physically_consistent"] else "no")
    t.add_row("paper", f"{ref.OBJECTIVE:.4g}", "", "", "", f"{sum(ref.CORRELATION_VALIDATION) / 3:.4f}", "", "", "")
    console.print(t)
    for key, beta, paper_vals in (("identification", "β1" if cfg.excitation == "paper" else "(see above)", ref.CORRELATION_IDENTIFICATION),
                                  ("validation", "β2", ref.CORRELATION_VALIDATION)):
        for metric, title, fmt in (("correlation", "correlation coefficient ρ (eq. 18)", ".4f"),
                                   ("relative_error", "relative error %", ".3g")):
            t = Table(title=f"{key.capitalize()} trajectory {beta}: {title} per joint", box=box.SIMPLE_HEAD, padding=(0, 1))
            t.add_column("method")
            for j in range(cfg.joints):
                t.add_column(f"J{j + 1}", justify="right")
            for label, m in methods.items():
                t.add_row(label, *(format(x, fmt) for x in m[metric][key]))
            if metric == "correlation":
                t.add_row("paper (ABC)", *(f"{paper_vals[j]:.4f}" if j < len(paper_vals) else "—" for j in range(cfg.joints)))
            console.print(t)
    _print_uncertainty(d, methods)
    if "sdp" in d["methods"]:
        eig = d["methods"]["sdp"]["pseudo_inertia_min_eig"]
        verdict = "physically consistent" if min(eig) >= -CONSISTENCY_TOL else "NOT physically consistent"
        console.print(f"SDP: smallest pseudo-inertia eigenvalue per link {_joined(eig, '.3g')} → {verdict}", soft_wrap=True)
    console.print("consistent: some mass distribution with non-negative friction and rotor inertias has these base parameters "
                  "(feasibility SDP; the truth's margin is " f"{d['truth_consistency_margin']:.3g})", soft_wrap=True)
    tm = d["timings"]
    console.print("timings (s): " + ", ".join(f"{k.replace('_', ' ')} {v:.2f}" for k, v in tm.items()), soft_wrap=True)
    for w in d["warnings"]:
        console.print(f"[yellow]warning:[/] {escape(w)}")
    _wrote(paths)


def _print_uncertainty(d: dict, methods: dict) -> None:
    """Per bootstrapped method: σ from the covariance beside the bootstrap's, with the bootstrap interval."""
    boot = {label: m for label, m in methods.items() if "bootstrap" in m}
    covered = {}
    for label, m in boot.items():
        b = m["bootstrap"]
        t = Table(title=f"{label}: σ from the covariance, σ and {100 * b['level']:.0f} % interval from the moving-block "
                        f"bootstrap ({b['resamples']} resamples, blocks of {b['block_length_samples']} samples)",
                  box=box.SIMPLE_HEAD, padding=(0, 1))
        for col in ("name", "truth", "σ cov.", "σ boot.", "interval"):
            t.add_column(col, justify="left" if col == "name" else "right", no_wrap=True)
        covered[label] = 0
        for n in d["parameters"]:
            lo, hi = b["lower"][n], b["upper"][n]
            covered[label] += lo <= d["truth"][n] <= hi
            t.add_row(n, f"{d['truth'][n]:.4g}", f"{m['params_std'][n]:.3g}", f"{b['std'][n]:.3g}", f"[{lo:.4g}, {hi:.4g}]")
        console.print(t)
    if covered:
        console.print("intervals holding the truth: " + ", ".join(f"{label} {c}/{len(d['parameters'])}" for label, c in covered.items()))


def _progress(label: str):
    return Progress(TextColumn(f"[bold]{label}[/]"), BarColumn(), TextColumn("{task.percentage:>3.0f}%"),
                    TimeElapsedColumn(), console=console, transient=True)


def _comparison_tables(comparisons, n_dof: int) -> None:
    """Per dataset: relative error, RMSE and correlation coefficient per joint for every parameter set."""
    for cmp in comparisons:
        rms = (cmp.measured**2).mean(axis=0) ** 0.5
        t = Table(title=f"{cmp.name}: {cmp.t.shape[0]} samples; RMS torque " + ", ".join(f"{x:.3g}" for x in rms) + " N·m",
                  box=box.SIMPLE_HEAD, padding=(0, 1))
        t.add_column("parameters", no_wrap=True)
        t.add_column("metric", no_wrap=True)
        for j in range(n_dof):
            t.add_column(f"J{j + 1}", justify="right")
        t.add_column("all", justify="right")
        for label, m in cmp.metrics().items():
            t.add_row(label, "error %", *(f"{x:.1f}" for x in m["relative_error"]), f"{m['global_relative_error']:.2f}")
            t.add_row("", "RMSE N·m", *(f"{x:.3g}" for x in m["rmse"]), "")
            t.add_row("", "ρ (eq. 18)", *(f"{x:.4f}" for x in m["correlation"]), "", end_section=True)
        console.print(t)


def _print_filter_choice(cv: dict) -> None:
    """preprocessing = "auto": each candidate's cutoffs and out-of-fold errors on the common held-out samples."""
    t = Table(title="preprocessing = \"auto\": out-of-fold RMS torque error (N·m) on the same held-out samples; chosen: *",
              box=box.SIMPLE_HEAD, padding=(0, 1))
    for col in ("positions (Hz)", "parallel (Hz)", "decimation", *(f"J{j + 1}" for j in range(len(cv["out_of_fold_rms_error"][0]))), "score"):
        t.add_column(col, justify="right")
    for i, (c, e, s) in enumerate(zip(cv["candidates"], cv["out_of_fold_rms_error"], cv["score"])):
        mark = "*" if i == cv["chosen"] else ""
        t.add_row(f"{c['position_cutoff']:.3g}{mark}", f"{c['parallel_cutoff']:.3g}", str(c["decimation"]),
                  *(f"{x:.4g}" for x in e), f"{s:.4g}")
    console.print(t)


def _print_coulomb_choice(cv: dict) -> None:
    """The candidates of the Coulomb smoothing velocity and their out-of-fold errors, per joint."""
    cand, err = cv["candidates"], cv["out_of_fold_rms_error"]
    n = len(cv["velocity"])
    t = Table(title=f"Coulomb term tanh(q̇/v_s): out-of-fold RMS torque error (N·m), {cv['folds']} contiguous folds; "
                    "chosen: *", box=box.SIMPLE_HEAD, padding=(0, 1))
    t.add_column("v_s / RMS speed", justify="right")
    for j in range(n):
        t.add_column(f"J{j + 1}", justify="right")
    for frac, vs_row, e_row in zip(cv["grid_fraction_of_rms_speed"], cand, err):
        t.add_row("sign" if frac == 0 else f"{frac:g}",
                  *(f"{e:.4g}{'*' if v == c else ''}" for e, v, c in zip(e_row, vs_row, cv["velocity"])))
    console.print(t)


def _print_drive_gains(gp) -> None:
    """Identified drive gains beside the description's, and the payload."""
    g = gp.gains
    t = Table(title=f"Drive gains K (eq. 16) from the runs without and with the {g.payload_mass:g} kg payload "
                    f"(Gautier & Briot; {g.n_rows} equations)", box=box.SIMPLE_HEAD, padding=(0, 1))
    for col in ("joint", "K identified (N·m/A)", "σ", "robot description", "difference %"):
        t.add_column(col, justify="right", no_wrap=True)
    for j, (k, s_, d) in enumerate(zip(g.gains, g.gains_std, gp.description_gains)):
        if math.isfinite(k):
            t.add_row(f"J{j + 1}", f"{k:.4g}", f"{s_:.2g}", f"{d:.4g}", f"{100 * (k - d) / d:+.1f}")
        else:
            t.add_row(f"J{j + 1}", "not observable", "", f"{d:.4g}", "")
    console.print(t)
    p = gp.payload
    vals = dict(zip(p.names, zip(p.values, p.std)))
    line = f"payload, from the loaded run with these gains: mass {p.mass:.4g} kg (σ {vals['M'][1]:.2g}; given {g.payload_mass:g} kg)"
    if "M" in vals and all(k in vals for k in ("MX", "MY", "MZ")):
        com = [vals[k][0] / p.mass for k in ("MX", "MY", "MZ")]
        line += ", centre of mass in the last link's frame (" + ", ".join(f"{c:.3g}" for c in com) + ") m"
    console.print(line, soft_wrap=True)


def _print_estimators(result) -> None:
    """Every estimator on the identification rows: F of eq. 9, evaluations, time; then the box's rule."""
    from ..experiment.identification import BOX_FRACTION, BOX_SIGMAS

    t = Table(title=f"Estimators on {result.fit.name} (the validation tables follow)", box=box.SIMPLE_HEAD, padding=(0, 1))
    for col in ("parameters", "F eq. 9 (N·m)", "evaluations", "time (s)"):
        t.add_column(col, justify="left" if col == "parameters" else "right", no_wrap=True)
    others = {o.label: o for o in result.others}
    for label, f in result.objective.items():
        o = others.get(label)
        t.add_row(escape(label), f"{f:.4f}", "" if o is None else (str(o.n_evaluations) if o.n_evaluations else "solve"),
                  "" if o is None else f"{o.seconds:.2f}")
    console.print(t)
    console.print(f"LAD, ABC, DE and PSO search the box {result.label} ± ({BOX_SIGMAS:g}·σ + {BOX_FRACTION:g}·|value|); "
                  "ABC at the paper's budget (Ns = 30, limit = 15, Tmax = 50), ABC×10, DE and PSO at 10× its evaluations",
                  soft_wrap=True)


def _print_identification(result, paths) -> None:

    sol, base = result.solution, result.base
    console.print(f"\n[bold]dynid identify[/] — robot {result.robot}, {result.method.upper()} on {result.fit.name}: "
                  f"{base.n_base} base parameters from {result.n_rows} equations, cond = {sol.condition_number:.4g}")
    pre = result.settings.get("preprocessing", {})
    if pre.get("derivation"):
        console.print(escape("preprocessing: " + pre["derivation"]), soft_wrap=True)
    filters = result.settings.get("preprocessing_cross_validation")
    if filters is not None:
        _print_filter_choice(filters)
    cv = result.settings.get("coulomb_cross_validation")
    if cv is not None:
        _print_coulomb_choice(cv)
    refs = result.references
    t = Table(title="Base parameters (σ: standard deviation; reference values beside)", box=box.SIMPLE_HEAD, padding=(0, 1))
    for col in ("name", "unit", "value", "σ", "σ %", *(r.name for r in refs)):
        t.add_column(col, justify="left" if col in ("name", "unit") else "right", no_wrap=True)
    from ..conventions import unit_of

    for i, name in enumerate(base.names):
        t.add_row(name, unit_of(name), f"{sol.params[i]:.4g}", f"{sol.params_std[i]:.2g}", f"{sol.relative_std[i]:.1f}",
                  *(f"{r.beta[i]:.4g}" for r in refs))
    console.print(t)
    for r in refs:
        if r.relative_std is not None:
            a = result.reference_agreement(r)
            console.print(f"{r.name}: dynid's values lie within 1σ / 2σ / 3σ of its stated standard deviations for "
                          f"{a['within_1_sigma']} / {a['within_2_sigma']} / {a['within_3_sigma']} of {a['compared']} base parameters")
    console.print("residual σ per joint (N·m): " + ", ".join(f"{x:.3g}" for x in result.joint_std))
    if result.consistent is not None:
        console.print(f"dynid SDP: physically consistent least squares, prior: {result.consistent.prior}; "
                      "smallest pseudo-inertia eigenvalue per link " + ", ".join(f"{x:.3g}" for x in result.consistent.pseudo_inertia_min_eig),
                      soft_wrap=True)
    if result.consistency_verdicts:
        console.print("physically consistent (some mass distribution with friction and rotor inertias ≥ 0 has these base "
                      "parameters)? " + "; ".join(f"{escape(label)}: {escape(v)}" for label, v in result.consistency_verdicts.items()),
                      soft_wrap=True)
    if result.others:
        _print_estimators(result)
    if result.drive_gains is not None:
        _print_drive_gains(result.drive_gains)
    _comparison_tables((result.fit,) + tuple(result.validations), len(result.joint_std))
    for w in result.warnings:
        console.print(f"[yellow]warning:[/] {escape(w)}", soft_wrap=True)
    _wrote(paths)


@app.command()
def identify(
    config: Path = typer.Argument(..., help="Identification config (TOML), e.g. configs/ur10e.toml."),
    out: Path = typer.Option(Path("dynid-identify"), help="Output folder for results.json and figures."),
    data_root: Optional[Path] = typer.Option(None, help="Folder of the data files (overrides the config's data_root)."),
    validate: bool = typer.Option(True, help="Also validate on the config's [[validation]] datasets."),
    figures: bool = typer.Option(True, help="Write the torque figures (--no-figures: results.json only)."),
) -> None:
    """Identify a robot's base parameters from its logs (OLS/WLS with σ), then validate them."""
    from ..experiment.identification_run import run_identification
    from ..io.identification_config import load_identification_config

    try:
        cfg = load_identification_config(config, data_root)  # a mistake is reported before any heavy import
        _check_out(out)
        from ..report.identification_run import save_identification
        with _progress("regressor") as progress:
            task = progress.add_task("x", total=1)
            result = run_identification(cfg, progress=lambda done, total: progress.update(task, completed=done, total=total),
                                        validate=validate)
        paths = save_identification(result, out, figures, robot=cfg.robot)
    except DynIdError as exc:
        _fail(exc)
    _print_identification(result, paths)


@app.command()
def export(
    config: Path = typer.Argument(..., help="Identification config (TOML) the results were identified with."),
    results: Path = typer.Option(Path("dynid-identify/results.json"), help="results.json written by dynid identify."),
    urdf: Optional[Path] = typer.Option(None, help="URDF file to write (inertials and joint friction of the physically consistent estimate)."),
    mjcf: Optional[Path] = typer.Option(None, help="MuJoCo MJCF file to write (inertials, armature, damping, frictionloss)."),
    data_root: Optional[Path] = typer.Option(None, help="Folder of the data files (overrides the config's data_root)."),
) -> None:
    """Export the physically consistent estimate as URDF and/or MuJoCo MJCF (for Pinocchio, simulators, controllers)."""
    from ..exceptions import DataError
    from ..io.identification_config import load_identification_config

    try:
        cfg = load_identification_config(config, data_root)
        identified = _read_results(results)
        from ..io.export import mjcf_from_results, urdf_from_results
        from ..io.files import atomic_write_text

        targets = [(flag, path, fn) for flag, path, fn in (("--urdf", urdf, urdf_from_results), ("--mjcf", mjcf, mjcf_from_results))
                   if path is not None]
        if not targets:
            raise DataError("give --urdf FILE and/or --mjcf FILE")
        texts = []
        for flag, path, fn in targets:
            if not path.parent.is_dir():
                raise DataError(f"{flag} {path}: its folder does not exist")
            texts.append((path, fn(cfg.robot, identified, str(results))))
        for path, text in texts:
            atomic_write_text(path, text)
    except DynIdError as exc:
        _fail(exc)
    console.print(f"wrote {', '.join(str(p) for p, _ in texts)} (robot {cfg.robot.name}, {cfg.robot.n_dof} joints; what the "
                  "format cannot hold, e.g. offsets and coupled motors, is stated in comments)", highlight=False, soft_wrap=True)


def _read_results(results: Path) -> dict:
    """The results.json of dynid identify, or a one-line DataError."""
    import json

    from ..exceptions import DataError

    try:
        return json.loads(results.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise DataError(f"{results}: not found; run dynid identify first or give --results") from None
    except (OSError, json.JSONDecodeError) as exc:
        raise DataError(f"{results}: cannot read it as JSON ({exc})") from None


def _parse_rows(text: Optional[str]):
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
    file: Optional[Path] = typer.Option(None, help="Validate on this log instead (same column map as the identification data)."),
    rows: Optional[str] = typer.Option(None, help="Rows of --file, 1-based inclusive: first,last."),
    out: Path = typer.Option(Path("dynid-validate"), help="Output folder for validation.json and figures."),
    data_root: Optional[Path] = typer.Option(None, help="Folder of the data files (overrides the config's data_root)."),
) -> None:
    """Validate identified parameters (and the config's reference sets) on other logs."""
    from ..exceptions import DataError
    from ..experiment.identification_run import run_validation
    from ..io.identification_config import dataset_for_file, load_identification_config

    try:
        cfg = load_identification_config(config, data_root)
        _check_out(out)
        from ..report.identification_run import save_validation
        identified = _read_results(results)
        datasets = None
        if file is not None:
            datasets = (dataset_for_file(cfg, file, _parse_rows(rows)),)
        elif rows is not None:
            raise DataError("--rows needs --file")
        with _progress("validation") as progress:
            task = progress.add_task("x", total=1)
            comparisons, warnings = run_validation(cfg, identified, datasets,
                                                   progress=lambda d, t: progress.update(task, completed=d, total=t))
        paths = save_validation(comparisons, out, warnings)
    except DynIdError as exc:
        _fail(exc)
    _comparison_tables(comparisons, cfg.robot.n_dof)
    for w in warnings:
        console.print(f"[yellow]warning:[/] {escape(w)}", soft_wrap=True)
    _wrote(paths)


@app.command()
def excite(
    config: Path = typer.Argument(..., help="Excitation config (TOML), e.g. configs/excite-er16.toml."),
    out: Path = typer.Option(Path("dynid-excite"), help="Output folder for excitation.json, excitation.csv and figures."),
    starts: Optional[int] = typer.Option(None, help="Number of optimisation starts (overrides design.starts)."),
    seed: Optional[int] = typer.Option(None, help="Seed of the random starts (overrides design.seed)."),
) -> None:
    """Design an optimal excitation trajectory (min cond(W_base) under the constraints of eq. 15)."""
    from dataclasses import replace

    from ..experiment.excitation import run_excitation
    from ..io.excitation_config import load_excitation_config

    try:
        cfg = load_excitation_config(config)
        _check_out(out)
        from ..report.excitation_run import save_excitation
        cfg = replace(cfg, starts=cfg.starts if starts is None else starts, seed=cfg.seed if seed is None else seed)
        with Progress(TextColumn("[bold]design[/]"), BarColumn(), TextColumn("{task.completed}/{task.total} starts"),
                      TextColumn("best cond = {task.fields[best]}"), TimeElapsedColumn(), console=console) as progress:
            task = progress.add_task("x", total=cfg.starts, best="—")
            run = run_excitation(cfg, callback=lambda i, n, c: progress.update(task, completed=i, best=f"{c:.4g}"))
        paths = save_excitation(run, out)
    except DynIdError as exc:
        _fail(exc)
    _print_excitation(run, paths)


def _print_excitation(run, paths) -> None:
    d, p = run.design, run.config.problem
    console.print(f"\n[bold]dynid excite[/] — robot {run.config.full_robot.name}, joints 1-{p.robot.n_dof}, "
                  f"{p.n_harmonics} harmonics, ω_f = {p.omega_f:.4g} rad/s (period {p.period:.4g} s), "
                  f"{p.base.n_base} base parameters, criterion {p.criterion}")
    t = Table(title="Before / after (design grid of " f"{p.grid_points} samples per period)", box=box.SIMPLE_HEAD)
    for col in ("trajectory", "cond(W_base)", "log det(WᵀW/N)"):
        t.add_column(col, justify="left" if col == "trajectory" else "right")
    t.add_row(f"initial: {run.config.initial_label}", f"{d.initial_cond:.2f}", f"{d.initial_log_det:.2f}")
    t.add_row("optimised", f"{d.cond:.2f}", f"{d.log_det:.2f}")
    console.print(t)
    if d.initial_violations:
        console.print("[yellow]the initial trajectory violates:[/] " + "; ".join(
            escape(f"{m.constraint} on {m.where} ({m.worst:.4g} against {m.limit:.4g})") for m in d.initial_violations), soft_wrap=True)
    else:
        console.print("the initial trajectory satisfies every constraint too (same limits for both)")
    console.print(f"cond on the 10× finer verification grid: {d.cond_verification:.2f}; ratio optimised/initial "
                  f"{d.cond / d.initial_cond:.3f}; criterion from each start " + ("(cond)" if d.criterion == "cond" else "(−log det)") + ": " + ", ".join(f"{v:.2f}" for v in d.start_values)
                  + f"; {d.nit} SLSQP iterations, {d.nfev} evaluations, {d.seconds:.1f} s")
    t = Table(title="Constraint margins on the verification grid (margin = limit − worst; ≥ 0 holds)", box=box.SIMPLE_HEAD,
              padding=(0, 1))
    for col in ("constraint", "where", "limit", "worst", "margin", "margin %"):
        t.add_column(col, justify="left" if col in ("constraint", "where") else "right", no_wrap=True)
    for m in d.margins:
        rel = "" if math.isnan(m.relative) else f"{100 * m.relative:.1f}"
        t.add_row(escape(m.constraint), escape(m.where), f"{m.limit:.4g}", f"{m.worst:.4g}", f"{m.margin:.4g}", rel)
    console.print(t)
    console.print(f"{paths[1].name}: {run.t.size} set-points at {run.config.rate:g} Hz")
    _wrote(paths)


def _parse_levels(text: str):
    try:
        return tuple(float(x) for x in text.split(","))
    except ValueError:
        raise DynIdError(f"--noise-levels: expected comma-separated current noise levels in A like 0.02,0.05,0.1, got {text!r}") from None


@app.command()
def montecarlo(
    robot: str = typer.Option("er16", help="Built-in robot name or description TOML."),
    joints: int = typer.Option(3, help="Number of joints identified."),
    noise_levels: str = typer.Option("0.02,0.05,0.1", help="Motor current noise standard deviations [A], comma separated."),
    realisations: int = typer.Option(100, help="Noise realisations per level."),
    methods: Optional[str] = typer.Option(None, help="Estimators, comma separated: ols, wls, irls, lad, sdp, abc, abc10, de, pso, "
                                                     "or all (default: ols,wls,irls,lad,sdp,abc)."),
    seed: int = typer.Option(0, help="Seed of every random number of the study."),
    duration: float = typer.Option(25.0, help="Recording length [s]."),
    rate: float = typer.Option(200.0, help="Sampling rate [Hz] (the paper: 1000)."),
    abc_bounds: str = typer.Option("scaled", help="Search box of ABC/DE/PSO/LAD: scaled (±(2|β_OLS|+1), holds the truth) or table3."),
    excitation: str = typer.Option("paper", help="Identification trajectory: paper (β1), optimized, or an excitation.json."),
    scheduler: Optional[str] = typer.Option(None, help="Dask scheduler address (e.g. tcp://host:8786); default: a LocalCluster of this machine's cores."),
    workers: Optional[int] = typer.Option(None, help="Worker processes of the LocalCluster (default: number of cores)."),
    out: Path = typer.Option(Path("dynid-montecarlo"), help="Output folder for montecarlo.json, the estimates CSV and figures."),
) -> None:
    """Monte Carlo study: bias and spread of each estimator over noise realisations against the Cramér–Rao bound."""
    from ..estimators.names import parse_methods
    from ..experiment.montecarlo import DEFAULT_METHODS, MonteCarloConfig, run_montecarlo
    from ..report.montecarlo_run import save_montecarlo

    try:
        _check_out(out)
        cfg = MonteCarloConfig(robot=robot, joints=joints, noise_levels=_parse_levels(noise_levels), realisations=realisations,
                               methods=DEFAULT_METHODS if methods is None else parse_methods(methods), seed=seed, duration=duration, rate=rate, abc_bounds=abc_bounds,
                               excitation=excitation)
        with Progress(TextColumn("[bold]realisations[/]"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                      TimeElapsedColumn(), console=console, transient=True) as progress:
            task = progress.add_task("mc", total=None)
            result = run_montecarlo(cfg, scheduler=scheduler, workers=workers,
                                    progress=lambda i, n: progress.update(task, completed=i, total=n))
        paths = save_montecarlo(result, out)
    except DynIdError as exc:
        _fail(exc)
    _print_montecarlo(result, paths)


def _print_montecarlo(result, paths) -> None:
    import numpy as np

    from ..estimators.names import LABELS

    cfg = result.config
    stats = result.statistics()
    console.print(f"\n[bold]dynid montecarlo[/] — robot {cfg.robot}, joints 1-{cfg.joints}, {len(result.names)} base parameters, "
                  f"{cfg.realisations} realisations × {len(cfg.noise_levels)} noise levels, {cfg.duration:g} s at {cfg.rate:g} Hz; "
                  f"ran on {result.cluster} in {result.timings['total']:.1f} s", soft_wrap=True)
    t = Table(title="Spread and bias of the base parameters against the Cramér–Rao bound (CRB: raw-torque Gaussian noise); "
                    "medians and worst over the parameters", box=box.SIMPLE_HEAD, padding=(0, 1))
    for col in ("σ (A)", "method", "std/√CRB median", "std/√CRB worst", "|bias|/√CRB median", "|bias|/√CRB worst",
                "RMSE/|β| median %", "failures", "time/fit (s)"):
        t.add_column(col, justify="left" if col == "method" else "right")
    nonzero = np.abs(result.truth) > 1e-9 * np.abs(result.truth).max()
    for li, level in enumerate(cfg.noise_levels):
        for i, key in enumerate(cfg.methods):
            s = stats[key]
            t.add_row(f"{level:g}" if i == 0 else "", LABELS[key], f"{np.nanmedian(s['std_over_crb'][li]):.3g}",
                      f"{np.nanmax(s['std_over_crb'][li]):.3g}", f"{np.nanmedian(s['bias_over_crb'][li]):.3g}",
                      f"{np.nanmax(s['bias_over_crb'][li]):.3g}",
                      f"{100 * np.nanmedian(s['rmse'][li][nonzero] / np.abs(result.truth[nonzero])):.3g}",
                      str(int(s["failures"][li])), f"{s['seconds_median'][li]:.3g}", end_section=i == len(cfg.methods) - 1)
    console.print(t)
    if result.errors:
        console.print(f"[yellow]warning:[/] {len(result.errors)} fits failed; the first: " + escape(result.errors[0]["error"]), soft_wrap=True)
    _wrote(paths)


class Interrupted(BaseException):
    """Ctrl-C, raised by dynid's SIGINT handler: a BaseException that is no KeyboardInterrupt, so no library
    on the way swallows it and the atomic writes' clean-up still runs."""


def _interrupt(signum, frame):
    raise Interrupted()


def main() -> None:
    """Console-script entry point. Ctrl-C ends with one line and exit code 130 (128 + SIGINT)."""
    import signal

    signal.signal(signal.SIGINT, _interrupt)
    try:
        app()
    except DynIdError as exc:  # pragma: no cover - commands already catch theirs
        err_console.print(f"error: {escape(str(exc))}", highlight=False)
        sys.exit(1)
    except Interrupted:
        err_console.print("interrupted (Ctrl-C)", highlight=False)
        sys.exit(130)


if __name__ == "__main__":
    main()
