"""One-file HTML report beside results.json: settings, the tables of the terminal, the figures embedded as
PNG data URIs (no external resource), warnings and versions, from a jinja2 template
(``templates/report.html.j2``). Built from the results dictionaries the commands write, so the report and
results.json always agree.
"""

from __future__ import annotations

import base64
import datetime
import math
from dataclasses import dataclass, field
from pathlib import Path

from .. import __version__
from ..estimators.registry import OTHER_LABELS
from ..io import atomic_write_text
from .excitation_summary import mujoco_clear_said, no_floor_line, set_point_lines


@dataclass
class Table:
    """A table of the report.

    Attributes
    ----------
    caption : str
    headers : list of str
    rows : list of list
        Cells; numbers are formatted by the report.
    text_columns : tuple of int
        Columns that hold text (left-aligned).
    flagged : set of (int, int)
        Cells (row, column) whose values are outside their good range: highlighted.
    """
    caption: str
    headers: list
    rows: list
    text_columns: tuple = ()
    flagged: set = field(default_factory=set)


@dataclass
class Section:
    """A titled part of the report.

    Attributes
    ----------
    title : str
    tables : list of Table
    texts : list of str
        Paragraphs after the tables.
    """
    title: str
    tables: list = field(default_factory=list)
    texts: list = field(default_factory=list)


BAD_ERROR = 50.0
"""[%] A joint's relative torque error from here on is highlighted."""


def _human(value) -> str:
    """A setting as people write it: yes/no, —, numbers to 4 digits, lists joined."""
    if value is None or value == "":
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return format(value, ".4g")
    if isinstance(value, (list, tuple)):
        return ", ".join(_human(v) for v in value)
    return str(value)


def _fmt(x, spec: str = ".4g") -> str:
    if x is None:
        return "—"
    if isinstance(x, int) and not isinstance(x, bool):
        return str(x)
    if isinstance(x, float):
        return format(x, spec)
    return str(x)


def _comparison_tables(comparisons: list[dict]) -> list[Table]:
    from ..conventions import sliding_note  # here: the page's module loads no NumPy until a page is written

    tables = []
    for c in comparisons:
        sets = c["metrics"]
        n = len(next(iter(sets.values()))["relative_error"])
        rows: list[list] = []
        flagged: set = set()
        ok = c.get("relative_error_meaningful") or [True] * n
        varies = c.get("correlation_meaningful") or [True] * n
        sliding = sliding_note("N·m", [j in c.get("prismatic_joints", ()) for j in range(n)])
        for label, m in sets.items():
            flagged |= {(len(rows), 2 + j) for j, x in enumerate(m["relative_error"]) if x is not None and ok[j] and x >= BAD_ERROR}
            rows.append([label, "error %", *(_fmt(x, ".3g") if ok[j] else "n/m" for j, x in enumerate(m["relative_error"])),
                         _fmt(m.get("global_relative_error"), ".3g")])
            rows.append(["", f"RMSE N·m{sliding}", *(_fmt(x, ".3g") for x in m["rmse"]), ""])
            rows.append(["", "correlation ρ (eq. 18)", *(_fmt(x, ".4f") if varies[j] and x is not None else "n/m" for j, x in enumerate(m["correlation"])), ""])
        tables.append(Table(f"{c['name']}: {c['n_samples']} samples (error of {BAD_ERROR:g} % and more highlighted; n/m: the "
                            "joint's torque is at the noise level, or does not vary beyond it: its relative error or correlation "
                            "means nothing)",
                            ["parameters", "metric", *(f"J{j + 1}" for j in range(n)), "all"], rows, flagged=flagged))
    return tables


def _beside_least_squares(d: dict) -> list[tuple[str, dict]]:
    """The estimates a results.json's base-parameter table shows beside least squares', as (header, name -> value):
    IDIM-IV, DIDIM, the drive-only estimate and the main estimate where it is not least squares' (the SDP)."""
    from ..identification.drive_only import DRIVE_ONLY_KEY

    main = d.get("main_estimate")
    return [(label + (" (main)" if label == main else ""), e["values"]) for label, e in (d.get("estimates") or {}).items()
            if isinstance(e.get("values"), dict) and (e.get("key") in OTHER_LABELS or e.get("key") == DRIVE_ONLY_KEY
                                                       or (label == main and e.get("key") != d.get("least_squares")))]


def _base_parameter_section(d: dict) -> Section:
    """The "Base parameters" section of ``dynid identify``'s report: least squares' values and σ, the estimates and
    reference sets beside them, and the consistency verdicts."""
    from .summaries import (  # summaries loads NumPy
        BAD_RELATIVE_STD,
        NEGLIGIBLE_TORQUE,
        SIGMA_WORDS,
        larger_relative_std,
        undetermined,
    )

    refs = d.get("references", [])
    diagnostics = d.get("diagnostics") or {}
    kept = set(diagnostics.get("from_prior") or [])  # directions the log did not determine: the prior's
    boot = diagnostics.get("bootstrap_std") or {}
    rel = {p["name"]: larger_relative_std(p["name"], p["value"], p.get("relative_std_percent"), boot)
           for p in d["base_parameters"]}
    named = {r["name"] for r in refs}  # the description's values as the main estimate: its reference column says so
    beside = [(h, v) for h, v in _beside_least_squares(d) if h.removesuffix(" (main)") not in named]
    rows = [[p["name"], p["unit"], _fmt(p["value"]),
             "prior" if p["name"] in kept else _fmt(p["std"], ".2g"),
             *(("prior" if p["name"] in kept else _fmt(boot.get(p["name"]), ".2g"),) if boot else ()),
             "—" if p["name"] in kept else _fmt(rel[p["name"]], ".3g"),
             *(_fmt(values.get(p["name"])) for _, values in beside),
             *(_fmt(r["values"].get(p["name"])) for r in refs), p["expression"]] for p in d["base_parameters"]]
    share = diagnostics.get("sigma_torque_percent") or {}
    column = 5 if boot else 4
    loose, _ = undetermined([p["name"] for p in d["base_parameters"]], [p["value"] for p in d["base_parameters"]],
                            [p.get("relative_std_percent") for p in d["base_parameters"]], kept, share, boot)
    flagged = {(i, column) for i, p in enumerate(d["base_parameters"]) if p["name"] in loose}
    ls_label = next((k for k, e in (d.get("estimates") or {}).items() if e.get("key") == d.get("least_squares")), "")
    caption = (f"{ls_label + ' with ' if ls_label else ''}condition number {d['condition_number']:.4g}; {d['n_rows']} "
               f"equations; σ{SIGMA_WORDS if boot else ''}; σ of {BAD_RELATIVE_STD:g} % and more (not determined by the "
               f"data) highlighted, but a parameter whose ±σ is under {NEGLIGIBLE_TORQUE:g} % of its joint's torque on "
               "this log (about 0 on this motion)")
    headers = ["name", "unit", "value", "σ", *(("σ boot.",) if boot else ()), "σ %", *(name for name, _ in beside),
               *(r["name"] + (" (main)" if r["name"] == d.get("main_estimate") else "") for r in refs), "expression"]
    section = Section("Base parameters", [Table(caption, headers, rows, (column + 1 + len(beside) + len(refs),), flagged)])
    verdicts = d.get("physically_consistent_verdict", {})
    if verdicts:
        section.tables.append(Table("Physically consistent? (some mass distribution with friction, rotor inertias ≥ 0)",
                                    ["parameters", "verdict"], [[k, v] for k, v in verdicts.items()], (1,)))
    return section


def identify_sections(d: dict) -> tuple[dict, list[Section]]:
    """Settings and sections of ``dynid identify`` (or ``dynid validate``).

    Parameters
    ----------
    d : dict
        The command's results dictionary (results.json).

    Returns
    -------
    settings : dict
        Setting -> value shown at the top.
    sections : list of Section
    """
    settings = {"robot": d.get("robot", ""), "estimators": _human(d.get("estimators", d.get("method", ""))),
                "main estimate": d.get("main_estimate", ""),
                "preprocessing": d.get("settings", {}).get("preprocessing", {}).get("derivation", ""),
                "Coulomb smoothing velocity (rad/s)": _human(d.get("settings", {}).get("coulomb_velocity", ""))}
    sections = [Section("In short", [], _identify_summary(d))] if "identification" in d or "validation" in d else []
    if "base_parameters" in d:
        sections.append(_base_parameter_section(d))
    if d.get("objective_eq9"):
        others = d.get("estimates", {})
        rows = [[label, _fmt(f), _fmt(others.get(label, {}).get("n_evaluations")), _fmt(others.get(label, {}).get("seconds"), ".2f")]
                for label, f in d["objective_eq9"].items()]
        sections.append(Section("Estimators", [Table("F (eq. 9) on the identification rows", ["parameters", "F (N·m)", "evaluations", "time (s)"], rows)]))
    if d.get("drive_gains"):
        g = d["drive_gains"]
        rows = [[f"J{j + 1}", "not determined" if k is None else _fmt(k), "" if k is None else _fmt(s, ".2g"), _fmt(ref)]
                for j, (k, s, ref) in enumerate(zip(g["gains"], g["gains_std"], g["description_gains"]))]
        sections.append(Section("Drive gains", [Table(f"K from the runs without and with the {g['payload_mass']} kg payload",
                                                      ["joint", "K (N·m/A)", "σ", "description"], rows)],
                                [f"{k} not determined: {why}" for k, why in g.get("not_observable", {}).items()]
                                + ([f"payload from the loaded run: mass {g['payload']['M']['value']:.4g} kg"] if "M" in g.get("payload", {}) else [])))
    fit = d.get("identification") or {}
    from ..conventions import sliding_note  # here: the page's module loads no NumPy until a page is written

    sliding = sliding_note("N·m", [j in fit.get("prismatic_joints", ()) for j in range(len(fit.get("rms_torque", ())))],
                           inside=True)
    cv = d.get("settings", {}).get("preprocessing_cross_validation")
    if cv:
        rows = [[_fmt(c["position_cutoff"], ".3g") + ("*" if i == cv["chosen"] else ""), _fmt(c["parallel_cutoff"], ".3g"),
                 _fmt(c["decimation"]), *(_fmt(x) for x in e), _fmt(sc)]
                for i, (c, e, sc) in enumerate(zip(cv["candidates"], cv["out_of_fold_rms_error"], cv["score"]))]
        sections.append(Section("preprocessing = \"auto\"", [Table(
            f"out-of-fold RMS torque error (N·m{sliding}) on the same held-out samples; chosen: *",
            ["positions (Hz)", "parallel (Hz)", "decimation", *(f"J{j + 1}" for j in range(len(cv["out_of_fold_rms_error"][0]))), "score"], rows)]))
    cc = d.get("settings", {}).get("coulomb_cross_validation")
    if cc:
        rows = [["sign" if f == 0 else _fmt(f), *(_fmt(e) + ("*" if v == c else "") for e, v, c in zip(er, vr, cc["velocity"]))]
                for f, vr, er in zip(cc["grid_fraction_of_rms_speed"], cc["candidates"], cc["out_of_fold_rms_error"])]
        sections.append(Section("Coulomb smoothing", [Table(f"tanh(q̇/v_s): out-of-fold RMS torque error (N·m{sliding}); chosen: *",
                                                            ["v_s / RMS speed", *(f"J{j + 1}" for j in range(len(cc["velocity"])))], rows)]))
    comparisons = ([d["identification"]] if "identification" in d else []) + list(d.get("validation", []))
    if comparisons:
        sections.append(Section("Measured against predicted torques", _comparison_tables(comparisons)))
    if d.get("files_taken_away"):
        sections.append(_taken_away_section(d["files_taken_away"]))
    elif d.get("files_withheld"):
        sections.append(Section("The files you take away", [], [d["files_withheld"]]))
    return settings, sections


def _taken_away_section(taken: dict) -> Section:
    """"The files you take away": the URDF and MJCF written, read back by Pinocchio and MuJoCo."""
    def chosen(f: dict) -> str:  # what the validation logs chose the file to hold otherwise (dynid.identification.file_terms)
        said = [f"{what} {', '.join(f'J{j}' for j in f[key])}" for key, what in (
            ("friction_folded", "friction folded on"), ("offsets_held", "offsets held on")) if f.get(key)]
        return "; ".join(said) or "—"

    rows = [[f["file"], f["read_by"], "—" if "not_read_back" in f else _fmt(f["equals_model_to"], ".1e"),
             _fmt(f.get("file_vs_measured")), _fmt(f.get("model_vs_measured")), ", ".join(f.get("cannot_hold", [])) or "—",
             chosen(f)] for f in taken["files"]]
    where = f"the validation log {taken['log']}" if taken["log"] else "random states within the joint limits"
    return Section("The files you take away", [Table(
        f"Read back on {where}", ["file", "read by", "equals dynid's model to", "vs unfiltered measured (%)",
                                  "dynid's whole model vs the same (%)", "what the format cannot hold",
                                  "chosen by the validation logs"], rows)],
        [f["file"] + ": " + f["not_read_back"] for f in taken["files"] if "not_read_back" in f])


def _identify_summary(d: dict) -> list[str]:
    """How an identification went, from its results: the estimate to use, whether it is physically consistent, each
    log's error and worst joint, what was not determined (the terminal's "In short")."""
    from ..validation.torques import rests_throughout
    from .summaries import ScoredLog, log_summaries, worst_joint

    label = d.get("main_estimate", "")
    verdicts = d.get("physically_consistent_verdict", {})
    verdict = verdicts.get(label, "")
    # what dynid export writes when the main estimate is not consistent (the terminal's "In short" says it too)
    estimates = d.get("estimates") or {}
    export = next((n for n in sorted(estimates, key=lambda n: n != label) if isinstance(estimates[n], dict)
                   and estimates[n].get("standard_values") and str(verdicts.get(n, "")).startswith("yes")), None)
    writes = "" if export in (None, label) else (
        f"; dynid export writes {export}, the consistent estimate with a whole set of standard parameters (the main "
        "estimate's are base parameters alone)." if verdict.startswith("yes") else
        f"; dynid export writes {export}, which is consistent.")
    out = [f"Use {label}" + ("" if not verdict else ", physically consistent" + (writes or ".") if verdict.startswith("yes")
                              else ", not physically consistent" + (writes or "."))] if label else []
    if d.get("readiness") and not str(d["readiness"]).startswith("model ready:"):  # the terminal's first line
        out.insert(0, str(d["readiness"]) + ".")
    if d.get("files_withheld"):  # its first clause: what was not written and why
        withheld = str(d["files_withheld"]).split(";")[0]
        out.append(withheld[:1].upper() + withheld[1:] + ".")
    logs = []
    for c in ([d["identification"]] if "identification" in d else []) + list(d.get("validation", [])):
        m = c["metrics"].get(label) or next(iter(c["metrics"].values()), None)
        if not m:
            continue
        worst = worst_joint(m["relative_error"], c.get("relative_error_meaningful") or [True] * len(m["relative_error"]))
        error = m.get("global_relative_error")
        floor = (c.get("noise_floor") or {}).get("global_relative_error")
        fit = c is d.get("identification")
        logs.append(ScoredLog(c["name"], float("nan") if error is None else float(error), worst,
                              not fit and rests_throughout(c.get("rest_share")),
                              float("nan") if floor is None else float(floor), fit, tuple(c.get("dead_channels") or ())))
    out += [f"{line}." for line in log_summaries(logs)]
    out += [f"{c['name']}: read otherwise than the identification log (Findings and warnings say how): its figures say "
            "little of any estimate, and the verdict does not weigh them." for c in d.get("validation", []) if c.get("misread")]
    for k, why in (d.get("drive_gains") or {}).get("not_observable", {}).items():
        out.append(f"{k} not determined: {why}.")
    findings = d.get("findings") or []
    out.append(f"{len(findings)} finding(s) on the model: see Findings and warnings below." if findings else
               "No finding on the model.")
    return out


def run_sections(d: dict) -> tuple[dict, list[Section]]:
    """Settings and sections of ``dynid run``.

    Parameters
    ----------
    d : dict
        The command's results dictionary (results.json).

    Returns
    -------
    settings : dict
        Setting -> value shown at the top.
    sections : list of Section
    """
    settings = {k: v for k, v in d.get("settings", {}).items() if not isinstance(v, (list, dict)) or k == "estimators"}
    names = d["parameters"]
    methods = d["estimates"]
    rows = [[n, _fmt(d["truth"][n]), *(_fmt(m["params"][n]) for m in methods.values())] for n in names]
    params = Table("Base parameters: truth and estimates", ["name", "truth", *(m["label"] for m in methods.values())], rows)
    rows = [[m["label"], _fmt(m["objective"]), _fmt(m["n_evaluations"]), _fmt(m["seconds"], ".2f"), _fmt(m["parameter_error_norm_percent"], ".3g"),
             _fmt(sum(m["correlation"]["validation"]) / len(m["correlation"]["validation"]), ".4f"),
             _fmt(sum(m["relative_error"]["validation"]) / len(m["relative_error"]["validation"]), ".3g"),
             "yes" if m["physically_consistent"] else "no"] for m in methods.values()]
    comparison = Table(f"Estimators (paper: F = {d['paper']['objective']})",
                       ["method", "F (N·m)", "evaluations", "time (s)", "‖β̂−β‖/‖β‖ %", "ρ on β2", "error % on β2", "consistent"], rows)
    n = d["joints"]
    per_joint = []
    for key, paper in (("identification", d["paper"]["correlation"]["identification"]), ("validation", d["paper"]["correlation"]["validation"])):
        for metric, title, fmt in (("correlation", "correlation coefficient ρ (eq. 18)", ".4f"), ("relative_error", "relative error %", ".3g")):
            rows = [[m["label"], *(_fmt(x, fmt) for x in m[metric][key])] for m in methods.values()]
            if metric == "correlation":
                rows.append(["paper (ABC)", *(_fmt(paper[j], ".4f") if j < len(paper) else "—" for j in range(n))])
            per_joint.append(Table(f"{key} trajectory: {title} per joint", ["method", *(f"J{j + 1}" for j in range(n))], rows))
    uncertainty = []
    for m in methods.values():
        b = m.get("bootstrap")
        if b:
            rows = [[p, _fmt(d["truth"][p]), _fmt(m["params_std"][p], ".3g"), _fmt(b["std"][p], ".3g"),
                     f"[{_fmt(b['lower'][p])}, {_fmt(b['upper'][p])}]"] for p in names]
            uncertainty.append(Table(f"{m['label']}: σ from the covariance, σ and {100 * b['level']:.0f} % interval from the "
                                     f"moving-block bootstrap ({b['resamples']} resamples)",
                                     ["name", "truth", "σ cov.", "σ boot.", "interval"], rows))
    timings = Table("Timings (s)", ["step", "seconds"], [[k, _fmt(v, ".2f")] for k, v in d.get("timings", {}).items()])
    return settings, [Section("Estimators", [comparison]), Section("Parameters", [params]), Section("Per joint", per_joint),
                      *([Section("Uncertainty", uncertainty)] if uncertainty else []), Section("Timings", [timings])]


def generic_sections(d: dict) -> tuple[dict, list[Section]]:
    """Settings and the top-level numbers of ``dynid excite`` and ``dynid montecarlo``.

    Parameters
    ----------
    d : dict
        The command's results dictionary (results.json).

    Returns
    -------
    settings : dict
        Setting -> value shown at the top.
    sections : list of Section
    """
    given = d.get("settings", d.get("config"))
    settings = dict(given) if isinstance(given, dict) else {}
    scalars = [[k, _fmt(v)] for k, v in d.items() if isinstance(v, (int, float, str)) and k not in ("schema_version", "dynid_version", "kind")]
    return settings, [Section("Summary", [Table("values", ["field", "value"], scalars)])]


def excite_sections(d: dict) -> tuple[dict, list[Section]]:
    """Settings, the before/after table and the constraint margins of ``dynid excite``.

    Parameters
    ----------
    d : dict
        The command's results dictionary (results.json).

    Returns
    -------
    settings : dict
        Setting -> value shown at the top.
    sections : list of Section
    """
    settings, _ = generic_sections(d)
    g = d["design"]
    before = Table("Before / after (design grid)", ["trajectory", "cond(W_base)", "log det(WᵀW/N)"],
                   [["initial", _fmt(g["initial_cond"], ".2f"), _fmt(g["initial_log_det_information"], ".2f")],
                    ["optimised", _fmt(g["cond"], ".2f"), _fmt(g["log_det_information"], ".2f")]])
    margins = Table(f"Constraint margins on the verification grid (cond there: {g['cond_verification_grid']:.2f})",
                    ["constraint", "where", "limit", "worst", "margin", "margin %"],
                    [[m["constraint"], m["where"], _fmt(m["limit"]), _fmt(m["worst"]), _fmt(m["margin"]),
                      _fmt(_percent(m.get("relative")), ".3g")] for m in g.get("margins", [])], (1,))
    notes = [f"{g['nit']} iterations, {g['nfev']} evaluations; feasible on the 10× grid: {g['feasible']}"]
    if "set_points" in d:
        encoders, (start, _) = set_point_lines(d["set_points"])
        said_already = start in (d.get("warnings") or [])  # a start in motion: under "Findings and warnings"
        notes += ([f"excitation.csv{encoders}"] if encoders else []) + ([] if said_already else [start])
    if "lowest" in d:
        notes.append(no_floor_line(d["lowest"], d["workspace"]["clearance"])[0])
    return settings, [Section("In short", [], _excite_verdict(d)), Section("Design", [before], notes),
                      Section("Constraints", [margins])]


def _percent(relative) -> float | None:
    """A margin's share of its limit in %, None for a constraint without one (an absolute distance: NaN or null)."""
    return None if relative is None or not math.isfinite(relative) else 100 * relative


def _excite_verdict(d: dict) -> list[str]:
    """report.html's first lines for ``dynid excite`` (issue "Fast where users wait", item 5): the constraints and the
    tightest, the smallest distances to the floor and the cell and between the links' shapes, MuJoCo's check."""
    g = d["design"]
    relative = [m for m in g.get("margins", []) if _percent(m.get("relative")) is not None]
    tight = min(relative, key=lambda m: m["relative"]) if relative else None
    out = [f"cond(W_base) {g['initial_cond']:.2f} → {g['cond']:.2f}; "
           + ("every constraint holds on the 10× verification grid" if g["feasible"] else "a constraint is violated (table below)")
           + ("" if tight is None else f", the tightest: {tight['constraint']} on {tight['where']} "
                                       f"({100 * tight['relative']:.1f} % of its limit to spare)")]
    for m in d.get("cell_clearance") or []:
        verdict = "holds" if m["margin"] >= 0 else "VIOLATED"
        out.append(f"{m['constraint']}: the closest, {m['where']}, {m['worst']:.4g} against {m['limit']:.4g} ({verdict})")
    own = d.get("self_clearance") or {}
    if own.get("links"):
        a, b = own["links"]
        gap = own["distance"]
        out.append(f"the links' own shapes: links {a} and {b} come closest at t = {own['time']:.3g} s, "
                   + (f"{gap:.3g} m apart" if gap >= 0 else f"overlapping by {-gap:.3g} m: check them before it runs"))
    contacts = d.get("mujoco_contacts") or {}
    if contacts:
        out.append("checked again by MuJoCo: " + (mujoco_clear_said(contacts) if not contacts["touching"] else
                      f"{contacts['touching']} set-points with a shape within the clearance (the deepest "
                      f"{contacts['deepest']:.3g} m): do not run it as is"))
    return out


def closed_loop_sections(d: dict) -> tuple[dict, list[Section]]:
    """Settings, the verdict and the table of ``dynid montecarlo --closed-loop``.

    Parameters
    ----------
    d : dict
        The study's montecarlo.json.

    Returns
    -------
    settings : dict
        Setting -> value shown at the top.
    sections : list of Section
    """
    from .study_summaries import closed_loop_study_rows, closed_loop_verdict

    settings, _ = generic_sections(d)
    headers, rows, _ = closed_loop_study_rows(d)
    flagged = {(i, 6) for i, r in enumerate(rows) if r[6] != "—" and not 90 <= float(r[6].split()[0]) <= 99}
    return settings, [Section("Estimators on the noise grid", [Table(
        "Per cell and estimator: medians over the base parameters of |bias|/|β| and spread/|β| (%), and in units of "
        "√CRB; the share of 95 % intervals that hold the truth (flagged outside 90-99 %)", list(headers),
        [list(r) for r in rows], (0, 1), flagged)], closed_loop_verdict(d))]


SECTIONS = {"identify": identify_sections, "validate": identify_sections, "run": run_sections,
            "excite": excite_sections, "montecarlo": generic_sections, "montecarlo_closed_loop": closed_loop_sections}


def write_html_report(path: Path, data: dict, kind: str, figures: list[Path], title: str) -> None:
    """Write ``report.html``: one file, figures embedded, nothing fetched from elsewhere.

    Parameters
    ----------
    path : Path
        The file to write.
    data : dict
        The command's results dictionary.
    kind : str
        run, identify, validate, excite or montecarlo.
    figures : list of Path
        PNG files to embed.
    title : str
    """
    import jinja2
    import numpy
    import pinocchio

    env = jinja2.Environment(loader=jinja2.PackageLoader("dynid.report", "templates"), autoescape=True)
    settings, sections = SECTIONS[kind](data)
    figs = [{"name": _caption(p.name), "data": base64.b64encode(p.read_bytes()).decode("ascii")}  # already compact:
            for p in figures if p.suffix == ".png"]                                                 # save_figure
    html = env.get_template("report.html.j2").render(
        title=title, versions={"dynid": __version__, "numpy": numpy.__version__, "pinocchio": pinocchio.__version__},
        written=datetime.datetime.now().isoformat(timespec="seconds"), settings={k: _human(v) for k, v in settings.items()},
        sections=sections,
        figures=figs, warnings=said(data))
    atomic_write_text(path, html)


def said(data: dict) -> list[str]:
    """Everything the terminal said of a run beside its tables: the verdict's findings, the warnings, the flags of each
    log (a joint whose figure means nothing there), in that order.

    Parameters
    ----------
    data : dict
        A command's results dictionary (results.json).

    Returns
    -------
    list of str
    """
    out = [f"finding: {f['text']}" for f in data.get("findings") or [] if isinstance(f, dict) and f.get("text")]
    out += [str(w) for w in data.get("warnings") or []]
    flags: dict[str, list[str]] = {}  # a flag several logs share (ten resting logs: "every joint at rest …") once
    for c in ([data["identification"]] if isinstance(data.get("identification"), dict) else []) + \
            [v for v in data.get("validation") or [] if isinstance(v, dict)]:
        name = str(c.get("name", ""))
        for f in c.get("flags") or []:
            text = str(f)
            own = bool(name) and text.startswith(f"{name}: ")
            flags.setdefault(text[len(name) + 2:] if own else text, []).extend([name] if own else [])
    out += [f"{', '.join(names)}: {text}" if names else text for text, names in flags.items()]
    return list(dict.fromkeys(out))


CAPTIONS = {"identification_fit": "Measured and predicted torques on the identification log",
            "fig4_identification_trajectory": "Identification trajectory β1 (the paper's Figure 4)",
            "fig5_tool_path": "Tool path of β1 (Figure 5)", "fig6_abc_convergence": "Convergence of the ABC (Figure 6)",
            "fig7_torques_identification": "Measured and predicted torques on β1 (Figure 7)",
            "fig8_validation_trajectory": "Validation trajectory β2 (Figure 8)",
            "fig9_torques_validation": "Measured and predicted torques on β2 (Figure 9)",
            "methods_comparison": "The estimators compared", "methods_convergence": "Convergence of the box searches",
            "excitation_joints": "The excitation against the joints' limits", "excitation_tool_path": "Tool path of the excitation",
            "excitation_clearance": "How close the links come to the floor and the cell",
            "montecarlo_std_vs_crb": "Spread of each estimator against the Cramér–Rao bound",
            "montecarlo_noise_levels": "Spread against the noise level"}


def _caption(name: str) -> str:
    """A figure's caption from its file name (``validation_p3.png``: the validation log p3)."""
    stem = name.rsplit(".", 1)[0]
    if stem in CAPTIONS:
        return CAPTIONS[stem]
    if stem.startswith("validation_"):
        return f"Measured and predicted torques on the validation log {stem[len('validation_'):]}"
    return stem.replace("_", " ")
