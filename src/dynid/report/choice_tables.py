"""The tables and lines of the choices the data made (cutoffs, friction model, Coulomb smoothing velocity) and of
the drive gains, as :mod:`dynid.report.summaries` prints them beside an identification."""

from __future__ import annotations

import math

import numpy as np

from ..conventions import joint_unit, sliding_note
from ..tables import Line, TextTable

__all__ = ["coulomb_choice_table", "drive_gains_blocks", "filter_choice_table", "friction_choice_table"]


def _number(x) -> str:
    """A figure of a table, "—" for one that was not computed (None or not finite in results.json)."""
    return f"{x:.4g}" if x is not None and np.isfinite(x) else "—"


def filter_choice_table(cv: dict, prismatic=()) -> TextTable:
    """``preprocessing.auto``: each candidate's cutoffs and out-of-fold errors on the common held-out samples.

    Parameters
    ----------
    cv : dict
        ``settings["preprocessing_cross_validation"]`` of an identification.
    prismatic : sequence of bool
        Which joints slide (their errors are forces, in N).

    Returns
    -------
    TextTable
    """
    n = len(cv["out_of_fold_rms_error"][0])
    rows = tuple((f"{c['position_cutoff']:.3g}{'*' if i == cv['chosen'] else ''}", f"{c['parallel_cutoff']:.3g}", str(c["decimation"]),
                  *(_number(x) for x in e), _number(s))
                 for i, (c, e, s) in enumerate(zip(cv["candidates"], cv["out_of_fold_rms_error"], cv["score"])))
    return TextTable(f"Cutoffs by cross-validation: out-of-fold RMS torque error (N·m{sliding_note('N·m', prismatic, inside=True)}) on the same "
                     "held-out samples; chosen: *",
                     ("positions Hz", "parallel Hz", "decimation", *(f"J{j + 1}" for j in range(n)), "score"), rows, labels=3)


def friction_choice_table(choice: dict, prismatic=()) -> TextTable:
    """Each joint's friction model chosen by cross-validation, its out-of-fold error against the plain model's.

    Parameters
    ----------
    choice : dict
        ``settings["friction_models"]`` of an identification.
    prismatic : sequence of bool
        Which joints slide (their errors are forces, in N).

    Returns
    -------
    TextTable
    """
    plain, chosen = np.asarray(choice["plain_out_of_fold_rms_error"]), np.asarray(choice["chosen_out_of_fold_rms_error"])
    share = choice.get("rest_share")
    rows = tuple((f"J{j + 1}", m["label"], f"{plain[j]:.3g}", f"{chosen[j]:.3g}",
                  "" if share is None else f"{100 * share[j]:.0f}") for j, m in enumerate(choice["models"]))
    return TextTable(f"Friction model of each joint, chosen by {choice['folds']}-fold blocked cross-validation "
                     f"(out-of-fold RMS torque error, N·m{sliding_note('N·m', prismatic, inside=True)}; the state at rest is judged "
                     "where 5 % of the samples rest)",
                     ("joint", "model", "plain", "chosen", "at rest %"), rows, labels=2)


def coulomb_choice_table(cv: dict, prismatic=()) -> TextTable:
    """The candidates of the Coulomb smoothing velocity and their out-of-fold errors, per joint.

    Parameters
    ----------
    cv : dict
        ``settings["coulomb_cross_validation"]`` of an identification.
    prismatic : sequence of bool
        Which joints slide (their errors are forces, in N).

    Returns
    -------
    TextTable
    """
    rows = tuple(("sign" if frac == 0 else f"{frac:g}", *(f"{e:.4g}{'*' if v == c else ''}" for e, v, c in zip(e_row, vs_row, cv["velocity"])))
                 for frac, vs_row, e_row in zip(cv["grid_fraction_of_rms_speed"], cv["candidates"], cv["out_of_fold_rms_error"]))
    return TextTable(f"Coulomb term tanh(q̇/v_s): out-of-fold RMS torque error (N·m{sliding_note('N·m', prismatic, inside=True)}), "
                     f"{cv['folds']} contiguous folds; chosen: *",
                     ("v_s / RMS speed", *(f"J{j + 1}" for j in range(len(cv["velocity"])))), rows)


def drive_gains_blocks(gains, prismatic=()) -> list:
    """The drive gains beside the description's, and the payload (``[drive_gains]`` of an identification).

    Parameters
    ----------
    gains : dynid.identification.drive_gains.GainsAndPayload
    prismatic : sequence of bool
        Which joints slide (their gains are forces per ampere, N/A).

    Returns
    -------
    list of Line and TextTable
    """
    g, p = gains.gains, gains.payload
    rows = []
    for j, (k, s, d) in enumerate(zip(g.gains, g.gains_std, gains.description_gains)):
        rows.append((f"J{j + 1}", f"{k:.4g}", f"{s:.2g}", f"{d:.4g}", f"{100 * (k - d) / d:+.1f}") if math.isfinite(k)
                    else (f"J{j + 1}", "not determined", "", f"{d:.4g}", ""))
    table = TextTable(f"Drive gains K (eq. 16) from the runs without and with the {g.payload_mass:g} kg payload "
                      f"(Gautier & Briot; {g.n_rows} equations)",
                      ("joint", f"K (N·m/A{sliding_note('N·m/A', prismatic, inside=True)})", "σ", "description", "diff. %"),
                      tuple(rows))
    why = [Line(f"K{j + 1} not determined: {g.why_not_observable(j)}; the description's {d:.4g} "
                f"{joint_unit('N·m/A', prismatic, j)} is used",
                "warning") for j, d in enumerate(gains.description_gains) if not math.isfinite(g.gains[j])]
    vals = dict(zip(p.names, zip(p.values, p.std)))
    line = f"payload, from the loaded run with these gains: mass {p.mass:.4g} kg (σ {vals['M'][1]:.2g}; given {g.payload_mass:g} kg)"
    lost = p.not_determined
    if all(k in vals for k in ("MX", "MY", "MZ")):
        line += ", centre of mass in the last link's frame (" + ", ".join(
            "not determined" if k in lost else f"{vals[k][0] / p.mass:.3g}" for k in ("MX", "MY", "MZ")) + ") m"
    out = [table, *why, *_gains_not_given(gains), Line(line)]
    if lost:
        out.append(Line(f"payload parameters not determined by the loaded run (σ ≥ 100 % of the value): {', '.join(lost)}: "
                        "the noise sets them; a loaded run that turns the payload about more axes determines them", "warning"))
    return out


def _gains_not_given(gains) -> list:
    """Where the description gives no drive gains (every one 1: currents taken as N·m in the identification) and the
    runs determine gains far from 1: the line that says so, with the values to give."""
    g = gains.gains
    far = [j for j, (k, s) in enumerate(zip(g.gains, g.gains_std))
           if math.isfinite(k) and abs(k - 1.0) > max(0.1, 3 * s)]
    if not far or any(d != 1.0 for d in gains.description_gains):
        return []
    values = ", ".join(f"J{j + 1} {g.gains[j]:.4g}" for j in far)
    unknown = [f"J{j + 1}" for j, k in enumerate(g.gains) if not math.isfinite(k)]
    rest = f" ({', '.join(unknown)}: not determined by these runs, a datasheet's value)" if unknown else ""
    return [Line("the description gives no drive gains (1 N·m/A: the identification above took the currents as "
                 f"N·m); these runs give {values} N·m/A: give them as drive_gain in the description's [[joints]] "
                 f"tables{rest} and identify again", "warning")]
