"""Drive terms that no drive has: a negative friction (issue "Never worse than the description", item 3).

Viscous or Coulomb friction below 0 is no friction: least squares gives it where the log does not determine the term
or where the model misses what the term takes up. The physically consistent estimates bound it at 0; a main estimate
that has one is said, with the figure.

A rotor inertia "larger than the links' own inertia about the axis" is not judged: measured on the real logs of
``configs/`` (benchmarks/NOTEBOOK.md), the physically consistent estimates' wrist rotor inertias are 32-1954× the links'
inertia about those axes (UR10e J5 and J6, TX40 J5, KR 300 J6), as a drive behind a gear ratio of 100 has
(``Ia = J_m·N²``): no ratio separates those from an implausible one. A joint torque sensor's log, which holds no rotor
inertia, is said by the config instead (``torques = { ..., sensor = "joint" }``).
"""

from __future__ import annotations

import numpy as np

from ..conventions import split_name
from ..estimators.physically_consistent import margin_is_consistent
from ..validation.diagnostics import Finding

__all__ = ["drive_term_findings"]


def drive_term_findings(label: str, names, values) -> list[Finding]:
    """The negative friction terms of one estimate (module docstring).

    Parameters
    ----------
    label : str
        The estimate's label, named in the lines.
    names : sequence of str
        Its parameters' names (standard or base: a base parameter is judged where it is the term alone, ``fv3``).
    values : (p,) array
        Its values.

    Returns
    -------
    list of Finding
        One per negative viscous or Coulomb friction, kind "drive", naming the joint.
    """
    out = []
    values = np.asarray(values, dtype=float)
    for name, value in zip(names, values):
        if not name[-1:].isdigit():
            continue
        term, j = split_name(name)
        if term in ("fv", "fc") and not margin_is_consistent(value, values):  # a solver's 0 is no negative friction
            what = "viscous" if term == "fv" else "Coulomb"
            out.append(Finding("drive", (
                f"{label}: J{j + 1}'s {what} friction {name} = {value:.3g} is negative: no friction is; the log does not "
                "determine it, or the model misses what it takes up (a torque delay, another friction model: the "
                "verdict's other findings say which); the physically consistent estimate (sdp) bounds it at 0"), j))
    return out
