"""One table of dynid's speed targets (issue "Fast on two cores"), each measured in this run.

Whole commands are timed as child processes (wall time and peak memory from ``os.wait4``); the
regressor and the bootstrap are timed in this process against their references. Each row prints the
figure, its reference measured in the same run where one exists, the target and "met" / "NOT met".
Run from the repository root after ``make test`` or ``make demo`` created ``.venv``: ``make bench``.
The real-data rows need ``../shared/data`` (or ``DYNID_DATA_ROOT``'s parent); they are skipped without.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
DATA = Path(os.environ.get("DYNID_SHARED_DATA", REPO.parent / "shared" / "data"))
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"} | {"MPLBACKEND": "Agg"}
"""The children's environment: as a user's, whose install holds its modules' bytecode (pip writes it; an editable
install writes it at the first import). Some shells set PYTHONDONTWRITEBYTECODE; a child would then compile every
dynid module from source at each start (0.13 s of ``dynid identify`` on the UR10e, paired whole-process runs), while
the plain script's imports come from site-packages, compiled at install. :func:`main` runs one warm-up first."""


def command(args, repeats: int = 1) -> tuple[float, float]:
    """Best wall time [s] and the peak memory [MB, 2**20 bytes: ru_maxrss / 1024] of ``args`` run as a child process."""
    best, peak = np.inf, 0.0
    for _ in range(repeats):
        t0 = time.perf_counter()
        proc = subprocess.Popen(args, cwd=tempfile.gettempdir(), env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        _, status, usage = os.wait4(proc.pid, 0)
        best = min(best, time.perf_counter() - t0)
        peak = max(peak, usage.ru_maxrss / 1024)
        proc.returncode = os.waitstatus_to_exitcode(status)
    return best, peak


ROWS = []

INIT_CASES = (
    ("TX40", ["tx40", "staubli_tx40_figaroh/pos_read_data.csv", "staubli_tx40_figaroh/curr_data.csv", "--rate", "5000"]),
    ("LBR Med7", ["kuka_med7_lbrstack/urdf/med7dock.urdf", "kuka_med7_lbrstack/measurements_with_ext_tau_1_dgr.csv",
                  "kuka_med7_lbrstack/measurements.csv", "--rate", "100"]),
    ("UR10e", ["ur10e_mamedov2020/urdf/ur10e.urdf", "ur10e_mamedov2020/identification_data/ur-20_02_10-30sec_12harm.csv",
               "ur10e_mamedov2020/validation_data/ur-20_01_17-ptp_10_points.csv"]),
    ("KR 300", [str(REPO / "configs" / "robots" / "kuka_kr300.toml"), "kuka_kr300_weigand2021/recorded/traj_A.csv",
                "kuka_kr300_weigand2021/recorded/traj_B.csv"]),
)
"""``dynid init`` on each shipped real log, as a user who has never seen dynid types it (relative paths are under
``DATA``; the KR 300's description is the one in ``configs/``)."""


def row(what: str, value: float, unit: str, target: float, reference: str = "—", smaller_is_better: bool = True) -> None:
    ok = value < target if smaller_is_better else value >= target
    ROWS.append((what, f"{value:.3g} {unit}", reference, f"{'<' if smaller_is_better else '>='} {target:g} {unit}",
                 "met" if ok else "NOT met"))


def main() -> None:
    dynid = str(BIN / "dynid")
    out = Path(tempfile.mkdtemp())
    load = os.getloadavg()[0]
    command([dynid, "identify", str(REPO / "configs" / "ur10e.toml"), "--no-figures", "--out", str(out / "warm-up")])  # bytecode
    t, _ = command([dynid, "--help"], repeats=3)
    row("dynid --help", t, "s", 0.5)
    (out / "typo.toml").write_text('robot = "ur10e"\n[identificaton]\n')
    t, _ = command([dynid, "identify", str(out / "typo.toml")], repeats=3)
    row("a config typo reported (dynid identify)", t, "s", 0.5)
    t, _ = command([dynid, "run", "--out", str(out / "run1")])
    row("dynid run (default: the paper's experiment, OLS and ABC, figures)", t, "s", 5.0)
    t, _ = command([dynid, "run", "--compare", "--out", str(out / "run1c")])
    row("dynid run --compare (all estimators, figures)", t, "s", 10.0)
    t, _ = command([dynid, "run", "--estimators", "ols", "--bootstrap", "0", "--out", str(out / "run2")], repeats=2)
    row("dynid run --estimators ols --bootstrap 0", t, "s", 2.0)
    t, _ = command([dynid, "run", "--estimators", "ols", "--bootstrap", "0", "--no-figures", "--out", str(out / "run3")], repeats=2)
    row("  the same, --no-figures", t, "s", 2.0)

    ur = DATA / "ur10e_mamedov2020"
    if ur.is_dir():
        cfg = ["--data-root", str(ur)]
        t, _ = command([dynid, "identify", str(REPO / "configs" / "ur10e.toml"), *cfg, "--out", str(out / "u1")])
        row("dynid identify configs/ur10e.toml (11 validation logs, drive gains, SDP, figures)", t, "s", 4.0)
        t_ref, _ = command([str(BIN / "python"), str(REPO / "benchmarks" / "reference_ur10e_ols.py"), str(ur)], repeats=2)
        t, _ = command([dynid, "identify", str(REPO / "configs" / "ur10e.toml"), *cfg, "--no-validate", "--no-figures",
                        "--out", str(out / "u2")], repeats=2)
        row("  --no-validate --no-figures, against the plain script (ratio)", t / t_ref, "x", 1.2,
            f"script {t_ref:.2f} s, dynid {t:.2f} s")
    tx = DATA / "staubli_tx40_figaroh"
    if tx.is_dir():
        t, mb = command([dynid, "identify", str(REPO / "configs" / "tx40-full.toml"), "--data-root", str(tx), "--out", str(out / "t1")])
        row("dynid identify configs/tx40-full.toml: time", t, "s", 4.0)
        row("  peak memory", mb, "MB", 290.0)

    for name, args in INIT_CASES:  # a user's first command on each real log (issue "Fast where users wait")
        if (DATA / args[1].split("/")[0]).is_dir():
            paths = [str(DATA / a) if "/" in a and not a.startswith("/") else a for a in args]
            t, _ = command([dynid, "init", *paths, "--out", str(out / f"init-{name}.toml"), "--force"], repeats=3)
            row(f"dynid init on the {name}'s log", t, "s", 3.0)

    # long logs, end to end from the CSV (benchmarks/long_log.py writes them once, ~1 min for the hour)
    from long_log import long_log

    short, long = long_log(6), long_log(60)
    _, mb_short = command([dynid, "identify", str(short), "--out", str(out / "l6")])
    t, mb_long = command([dynid, "identify", str(long), "--out", str(out / "l60")])
    row("1 h of UR10e log at 1 kHz (700 MB CSV), dynid identify end to end", t, "s", 60.0)
    row("  its peak memory against the 6-minute log's (flat: < 1.5)", mb_long / mb_short, "x", 1.5,
        f"6 min {mb_short:.0f} MB, 1 h {mb_long:.0f} MB")

    # regressor: dynid's batched kernel against a loop over Pinocchio's computeJointTorqueRegressor, both
    # writing the full array (benchmarks/bench_regressor.py)
    from bench_regressor import N as n
    from bench_regressor import measure

    t_pin, t_dyn = measure(repeats=10)  # best of ten: a moment when both cores are free
    row("regressor, er16, 25 000 samples: dynid vs Pinocchio loop (ratio)", t_pin / t_dyn, "x", 6.0,
        f"Pinocchio {1e6 * t_pin / n:.2f} µs/sample", smaller_is_better=False)
    row("  dynid per sample", 1e6 * t_dyn / n, "µs", 0.5)
    from bench_regressor import fill_floor

    t_fill = fill_floor(repeats=10)
    row("  dynid against the fill floor (the array allocated and written once, one thread)", t_dyn / t_fill, "x", 1.2,
        f"floor {1e6 * t_fill / n:.3f} µs/sample")

    t, _ = command([str(BIN / "python"), str(REPO / "benchmarks" / "bench_excitation_design.py")])
    row("bench_excitation_design.py (6 joints, 5 harmonics, 4 starts)", t, "s", 15.0)

    # closed loop: IDIM-IV and DIDIM on the paper's ER-16 experiment (benchmarks/bench_closed_loop.py)
    from bench_closed_loop import measure as closed_loop

    for key, (seconds, iterations, _) in closed_loop().items():
        row(f"{key.upper()}, ER-16 paper experiment in closed loop (25 s at 1 kHz, {iterations} simulations)", seconds, "s", 10.0)

    # dynid monitor's recursive least squares (benchmarks/bench_fleet.py)
    from bench_fleet import recursive_update

    row("recursive least squares of dynid monitor, 6 joints x 3 terms, per sample", recursive_update(), "µs", 50.0)

    widths = [max(len(r[i]) for r in ROWS + [("what", "dynid", "reference", "target", "")]) for i in range(5)]
    print(f"machine: {os.cpu_count()} cores, load average {load:.2f} at the start of the table")
    for r in [("what", "dynid", "reference", "target", "")] + ROWS:
        print("  ".join(c.ljust(w) for c, w in zip(r, widths)))


if __name__ == "__main__":
    main()
