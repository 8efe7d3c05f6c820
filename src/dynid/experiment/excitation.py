"""The run ``dynid excite`` describes: design the trajectory of a parsed config
(:mod:`dynid.io.excitation_config`) and sample it at the controller's rate."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..excitation.design import ExcitationDesign, design_excitation
from ..io.excitation_config import ExcitationConfig
from ..tables import Line, TextTable, render_text


@dataclass(frozen=True)
class ExcitationRun:
    """What ``dynid excite`` produced: the design and the sampled trajectory."""

    config: ExcitationConfig
    design: ExcitationDesign
    t: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray

    def summary_blocks(self) -> list:
        """What ``dynid excite`` prints, as blocks of :mod:`dynid.tables`."""
        d, p, c = self.design, self.config.problem, self.config
        out = [Line(f"dynid excite — robot {c.full_robot.name}, joints 1-{p.robot.n_dof}, {p.n_harmonics} harmonics, "
                    f"ω_f = {p.omega_f:.4g} rad/s (period {p.period:.4g} s), {p.base.n_base} base parameters, criterion {p.criterion}", "title"),
               TextTable(f"Before / after (design grid of {p.grid_points} samples per period)", ("trajectory", "cond(W_base)", "log det(WᵀW/N)"),
                         ((f"initial: {c.initial_label}", f"{d.initial_cond:.2f}", f"{d.initial_log_det:.2f}"),
                          ("optimised", f"{d.cond:.2f}", f"{d.log_det:.2f}")))]
        if d.initial_violations:
            out.append(Line("the initial trajectory violates: " + "; ".join(
                f"{m.constraint} on {m.where} ({m.worst:.4g} against {m.limit:.4g})" for m in d.initial_violations), "warning"))
        else:
            out.append(Line("the initial trajectory satisfies every constraint too (same limits for both)"))
        out.append(Line(f"cond on the 10× finer verification grid: {d.cond_verification:.2f}; ratio optimised/initial "
                        f"{d.cond / d.initial_cond:.3f}; criterion from each start " + ("(cond)" if d.criterion == "cond" else "(−log det)")
                        + ": " + ", ".join(f"{v:.2f}" for v in d.start_values)
                        + f"; {d.nit} SLSQP iterations, {d.nfev} evaluations, {d.seconds:.1f} s"))
        rows = tuple((m.constraint, m.where, f"{m.limit:.4g}", f"{m.worst:.4g}", f"{m.margin:.4g}",
                      "" if math.isnan(m.relative) else f"{100 * m.relative:.1f}") for m in d.margins)
        out.append(TextTable("Constraint margins on the verification grid (margin = limit − worst; ≥ 0 holds)",
                             ("constraint", "where", "limit", "worst", "margin", "margin %"), rows, labels=2))
        out.append(Line(f"excitation.csv: {self.t.size} set-points at {c.rate:g} Hz"))
        return out

    def summary(self, width: int = 100) -> str:
        """Plain-text summary of the design."""
        return render_text(self.summary_blocks(), width)

    def to_dict(self) -> dict:
        c, p = self.config, self.config.problem
        lim = p.limits
        return {
            "robot": c.full_robot.name, "joints": p.robot.n_dof, "config": str(c.path),
            "harmonics": p.n_harmonics, "omega_f": p.omega_f, "period": p.period, "rest": p.rest,
            "base_parameters": list(p.base.names),
            "limits": {f: getattr(lim, f).tolist() for f in ("q_min", "q_max", "dq_max", "ddq_max", "tau_max")},
            "workspace": p.workspace.to_dict(),
            "settings": {"starts": c.starts, "seed": c.seed, "maxiter": c.maxiter, "grid_points": p.grid_points,
                         "safety": p.safety, "initial": c.initial_label, "csv_rate": c.rate, "csv_periods": c.periods},
            "trajectory": self.design.trajectory.to_dict(c.form),
            "design": {k: v for k, v in self.design.to_dict(c.form).items() if k != "trajectory"},
        }


def run_excitation(config: ExcitationConfig, callback: Callable[[int, int, float], None] | None = None) -> ExcitationRun:
    """Design the trajectory of ``config`` and sample it at the controller's rate."""
    design = design_excitation(config.problem, n_starts=config.starts, rng=config.seed, initial=config.initial,
                               maxiter=config.maxiter, callback=callback)
    n = int(round(config.periods * config.problem.period * config.rate))
    t = np.arange(n + 1) / config.rate  # both ends: the controller's last set-point is the start again
    q, dq, ddq = design.trajectory.evaluate(t)
    return ExcitationRun(config, design, t, q, dq, ddq)
