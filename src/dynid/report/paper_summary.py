"""What ``dynid run`` prints, as blocks of :mod:`dynid.tables`: the base parameters beside the truth and
the paper's Table 2, the comparison of estimators, per-joint metrics beside the paper's coefficients, the
OLS/WLS uncertainties and the timings."""

from __future__ import annotations

from ..estimators.registry import spec
from ..model.spatial import CONSISTENCY_TOL
from ..studies import paper_reference as ref
from ..tables import Line, TextTable


def _joined(values, fmt: str) -> str:
    return " / ".join(format(v, fmt) for v in values)


def run_summary_blocks(result, verbose: bool = True) -> list:
    """Blocks of a paper run's summary.

    Parameters
    ----------
    result : PaperRunResult
    verbose : bool
        Every table (the parameters, per joint, the bootstrap's); else the estimators' table and the verdict, which
        ``dynid run`` prints without ``--verbose``.

    Returns
    -------
    list of Line or TextTable
    """
    d = result.to_dict()
    methods = {spec(k).label: v for k, v in d["estimates"].items()}
    cfg = result.config
    n_par = len(d["parameters"])
    ex = d["trajectories"]["excitation"]
    out: list = [Line(f"dynid run — robot {result.robot.name}, joints 1-{cfg.joints}, plant '{cfg.plant}', seed {cfg.seed}: "
                f"{n_par} base parameters ({n_par - 2 * cfg.joints} inertial + {2 * cfg.joints} friction)", "title"),
           Line(f"identification trajectory: {ex['trajectory']}; cond(W_base) {ex['cond_base_regressor']:.2f} "
                f"(β1: {ex['cond_base_regressor_beta1']:.2f})"),
           Line("estimators: " + "; ".join(f"{spec(k).label} = {spec(k).description}" for k in d["estimates"]))]
    rows = []
    for n in d["parameters"]:
        sym = d["paper_symbols"][n]
        rows.append((f"{n} ({sym})" if sym else n, f"{d['truth'][n]:.4g}", *(f"{m['params'][n]:.4g}" for m in methods.values()),
                     f"{ref.TABLE2[sym]:.4g}" if sym in ref.TABLE2 else ""))
    if verbose:
        out.append(TextTable("Base parameters: truth and estimates (units in results.json)",
                             ("name (paper)", "truth", *methods, "Table 2"), tuple(rows), labels=2))
    rows = [(label, f"{m['objective']:.4g}", str(m["n_evaluations"]) if m["n_evaluations"] else "—", f"{m['seconds']:.1f}",
             f"{m['parameter_error_norm_percent']:.3g}",
             *(f"{sum(m[k]['validation']) / cfg.joints:{f}}" for k, f in (("correlation", ".4f"), ("rmse", ".3g"), ("relative_error", ".3g"))),
             "yes" if m["physically_consistent"] else "no") for label, m in methods.items()]
    rows.append(("paper", f"{ref.OBJECTIVE:.4g}", "", "", "", f"{sum(ref.CORRELATION_VALIDATION) / 3:.4f}", "", "", ""))
    out.append(TextTable("Estimators: F = eq. 9 on β1 (N·m); evals of eq. 9; wall s (run side by side); Δβ = ‖β̂−β‖/‖β‖ %; "
                         "mean over joints of ρ (eq. 18), RMSE (N·m) and error % on β2; physically consistent",
                         ("method", "F", "evals", "s", "Δβ %", "ρ β2", "RMSE", "err %", "cons."), tuple(rows)))
    searches = _box_searches(d)
    if searches and d.get("search_box") == "table3":
        out.append(Line(f"{searches} the paper's Table 3 box; " + ref.TABLE3_NOTE))
    elif searches and d.get("search_box") == "scaled":
        out.append(Line(f"{searches} the box ±(2|β_OLS| + 1), which holds the truth"
                        + (" (the paper's Table 3 box holds the paper's plant, not this one: --plant paper, or "
                           "--abc-bounds table3)" if cfg.robot == "er16" and cfg.joints == 3 else "")))
    per_joint = (("identification", "β1" if cfg.excitation == "paper" else "(see above)", ref.CORRELATION_IDENTIFICATION),
                 ("validation", "β2", ref.CORRELATION_VALIDATION)) if verbose else ()
    for key, beta, paper_vals in per_joint:
        for metric, title, fmt in (("correlation", "correlation coefficient ρ (eq. 18)", ".4f"), ("relative_error", "relative error %", ".3g")):
            rows = [(label, *(format(x, fmt) for x in m[metric][key])) for label, m in methods.items()]
            if metric == "correlation":
                rows.append(("paper (ABC)", *(f"{paper_vals[j]:.4f}" if j < len(paper_vals) else "—" for j in range(cfg.joints))))
            out.append(TextTable(f"{key.capitalize()} trajectory {beta}: {title} per joint", ("method", *(f"J{j + 1}" for j in range(cfg.joints))),
                                 tuple(rows)))
    out.extend(b for b in _uncertainty_blocks(d, methods) if verbose or isinstance(b, Line))
    if "sdp" in d["estimates"]:
        eig = d["estimates"]["sdp"]["pseudo_inertia_min_eig"]
        verdict = "physically consistent" if min(eig) >= -CONSISTENCY_TOL else "NOT physically consistent"
        out.append(Line(f"SDP: smallest pseudo-inertia eigenvalue per link {_joined(eig, '.3g')} → {verdict}"))
    out.append(Line("cons.: whether some mass distribution with non-negative friction and rotor inertias has the "
                    "estimate's base parameters (feasibility SDP); " + _truth_consistency(d)))
    out.append(Line("timings (s): " + ", ".join(f"{k.replace('_', ' ')} {v:.2f}" for k, v in d["timings"].items())))
    out.extend(Line(w, "warning") for w in d["warnings"])
    out.extend(_verdict(d, methods, verbose))
    return out


BOX_SEARCHES = ("lad", "abc", "abc10", "de", "pso")
"""The estimators of ``dynid run`` that search a box (LAD's bounds, the ABC's, DE's and PSO's)."""


def _box_searches(d: dict) -> str:
    """"ABC searches" or "LAD, ABC and DE search": the box searches that ran, for the line on their box ("" if none;
    it named all four when only the ABC ran)."""
    labels = [spec(k).label for k in d["estimates"] if k in BOX_SEARCHES]
    if not labels:
        return ""
    names = labels[0] if len(labels) == 1 else ", ".join(labels[:-1]) + " and " + labels[-1]
    return names + (" searches" if len(labels) == 1 else " search")


def _truth_consistency(d: dict) -> str:
    """Whether the simulated truth is physically consistent, in words (the paper's Table 2 is not: fc1 < 0, which a
    margin of -inf said without a word)."""
    truth = "the paper's Table 2 values are" if d.get("plant") == "paper" else "the simulated truth is"
    verdict = str(d.get("truth_consistency") or "")
    margin = d.get("truth_consistency_margin")
    if verdict.startswith("yes") or (not verdict and margin is not None and margin >= -CONSISTENCY_TOL):
        return f"{truth} consistent"
    return f"{truth} not consistent" + (f" ({verdict.removeprefix('no: ')})" if verdict.startswith("no") else "")


def _verdict(d: dict, methods: dict, verbose: bool) -> list:
    """The run's last lines: the estimator nearest the truth, where the paper's ABC budget stands, where the rest is."""
    best = min(methods, key=lambda k: methods[k]["parameter_error_norm_percent"])
    b = methods[best]
    text = (f"nearest the truth: {best} (Δβ {b['parameter_error_norm_percent']:.3g} %, error {_mean(b['relative_error']['validation']):.3g} % "
            f"on the validation trajectory β2)")
    abc = d["estimates"].get("abc")
    if abc is not None:
        text += (f"; the paper's ABC budget: Δβ {abc['parameter_error_norm_percent']:.3g} %, ρ on β2 "
                 f"{_mean(abc['correlation']['validation']):.4f} (the paper's: {sum(ref.CORRELATION_VALIDATION) / 3:.4f}; "
                 f"one draw of a stochastic search, seed {d.get('seed', 0)}: --seed gives others)")
    out = [Line(text, "title")]
    if not verbose:
        out.append(Line("the parameters and per-joint tables: --verbose, and report.html"))
    return out


def _mean(values) -> float:
    return sum(values) / len(values)


def _uncertainty_blocks(d: dict, methods: dict) -> list:
    """Per bootstrapped method: σ from the covariance beside the bootstrap's, with the bootstrap interval."""
    out: list = []
    covered: dict = {}
    for label, m in methods.items():
        if "bootstrap" not in m:
            continue
        b = m["bootstrap"]
        covered[label] = 0
        rows = []
        for n in d["parameters"]:
            lo, hi = b["lower"][n], b["upper"][n]
            covered[label] += lo <= d["truth"][n] <= hi
            rows.append((n, f"{d['truth'][n]:.4g}", f"{m['params_std'][n]:.3g}", f"{b['std'][n]:.3g}", f"[{lo:.4g}, {hi:.4g}]"))
        out.append(TextTable(f"{label}: σ from the covariance, σ and {100 * b['level']:.0f} % interval from the moving-block "
                             f"bootstrap ({b['resamples']} resamples, blocks of {b['block_length_samples']} samples)",
                             ("name", "truth", "σ cov.", "σ boot.", "interval"), tuple(rows)))
    if covered:
        out.append(Line("intervals holding the truth: " + ", ".join(f"{label} {c}/{len(d['parameters'])}" for label, c in covered.items())))
    return out
