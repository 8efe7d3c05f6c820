"""Synthetic long UR10e logs for the end-to-end benchmark of ``dynid identify`` (a 1-hour log at 1 kHz).

The log is a UR RTDE log of 19 columns (preset ``ur-rtde-19``: t, q, qd, i): a smooth multi-sine motion
and currents from dynid's model with the description's nominal values (plus noise), so that the log is
identifiable; the values matter less than the size. Writing a 1-hour log takes about a minute, so it is
kept in ``~/.cache/dynid-bench`` (or ``$DYNID_BENCH_CACHE``) and written again only when missing.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

RATE = 1000.0
BLOCK = 100_000


def cache_folder() -> Path:
    folder = Path(os.environ.get("DYNID_BENCH_CACHE", Path.home() / ".cache" / "dynid-bench"))
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def _block(robot, phi, start: int, stop: int, rng) -> np.ndarray:
    from dynid.dynamics.regressor import regressor

    t = np.arange(start, stop) / RATE
    q = np.zeros((t.size, robot.n_dof))
    dq = np.zeros_like(q)
    ddq = np.zeros_like(q)
    amp = np.linspace(0.8, 1.4, robot.n_dof)
    for h in range(1, 5):
        w = 2 * np.pi * 0.1 * h
        phase = 0.7 * h + np.arange(robot.n_dof)
        s, c = np.sin(w * t[:, None] + phase), np.cos(w * t[:, None] + phase)
        q += amp / h * s
        dq += amp / h * w * c
        ddq -= amp / h * w * w * s
    tau = np.einsum("nip,p->ni", regressor(robot, q, dq, ddq), phi)
    current = tau / robot.drive_gains + rng.normal(0.0, 0.01, tau.shape)
    return np.column_stack([t, q + rng.normal(0, 1e-6, q.shape), dq, current])


def long_log(minutes: float) -> Path:
    """Path of a config identifying a ``minutes``-long 1 kHz UR10e log (written on first use)."""
    from dynid.model.description import load_robot

    folder = cache_folder()
    csv = folder / f"ur10e_{minutes:g}min_1khz.csv"
    if not csv.is_file():
        robot = load_robot("ur10e")
        phi = robot.standard_parameters()
        rng = np.random.default_rng(0)
        n = int(minutes * 60 * RATE)
        tmp = csv.with_suffix(".tmp")
        with open(tmp, "w") as fh:
            for start in range(0, n, BLOCK):
                np.savetxt(fh, _block(robot, phi, start, min(start + BLOCK, n), rng), fmt="%.7g", delimiter=",")
        tmp.replace(csv)
    config = folder / f"ur10e_{minutes:g}min.toml"
    config.write_text(f'robot = "ur10e"\ndata_root = "."\n[identification]\npreset = "ur-rtde-19"\nfile = "{csv.name}"\n')
    return config
