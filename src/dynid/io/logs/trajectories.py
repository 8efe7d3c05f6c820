"""Excitation trajectories on disk: Fourier coefficients (JSON) and sampled set-points (CSV)."""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np

from ...exceptions import ConfigError
from ...excitation.fourier import FourierTrajectory, trajectory_from_dict
from ..files import atomic_write_text


def load_trajectory(path: str | Path) -> FourierTrajectory:
    """Read Fourier coefficients.

    The ``excitation.json`` of ``dynid excite`` (its ``trajectory``), or a bare ``{"form", "omega_f", "q0", "a", "b"}``
    object.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    FourierTrajectory

    Raises
    ------
    ConfigError
        Missing file, invalid JSON, or malformed coefficients (the message names the file and field).
    """
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"{path}: trajectory file not found")
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: invalid JSON ({exc})") from None
    if isinstance(doc, dict) and "trajectory" in doc:
        return trajectory_from_dict(doc["trajectory"], f"{path}: trajectory")
    return trajectory_from_dict(doc, str(path))


def write_trajectory_csv(path: str | Path, t: np.ndarray, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray,
                         prismatic=None) -> None:
    """Write set-points for a controller, atomically.

    Columns ``t [s], q1..qn [rad], dq1..dqn [rad/s], ddq1..ddqn [rad/s^2]`` (``[m]``, ``[m/s]``, ``[m/s^2]`` for a
    prismatic joint).

    Parameters
    ----------
    path : str or Path
    t : (N,) array [s]
    q, dq, ddq : (N, n_dof) arrays
        [rad], [rad/s], [rad/s²] (or m, m/s, m/s²).
    prismatic : (n_dof,) bools, optional
        Which joints slide (default: none).
    """
    n = q.shape[1]
    unit = ["m" if s else "rad" for s in (np.zeros(n, dtype=bool) if prismatic is None else prismatic)]
    header = ["t [s]"] + [f"q{j + 1} [{unit[j]}]" for j in range(n)] + [f"dq{j + 1} [{unit[j]}/s]" for j in range(n)] + \
             [f"ddq{j + 1} [{unit[j]}/s^2]" for j in range(n)]
    buf = io.StringIO()
    np.savetxt(buf, np.column_stack([t, q, dq, ddq]), fmt="%.9g", delimiter=",", header=",".join(header), comments="")
    atomic_write_text(path, buf.getvalue())
