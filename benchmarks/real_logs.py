"""dynid's defaults against hand tuning, on every real log of ``../shared/data`` (issue "Right on a robot dynid has
never seen").

For each robot, the config of ``configs/`` (no [preprocessing] table: every choice dynid's) is identified as it is,
then again with each of a grid of hand-made settings an expert would try (cutoffs, the description's friction model
or dynid's choice, the authors' own settings where they published them). The figure of merit is the mean, over the
config's validation logs, of the global relative error of the estimate dynid reports as its main one; the best of
the grid stands for an expert who tuned on those very validation logs. Prints one table; run from the repository
root: ``.venv/bin/python benchmarks/real_logs.py`` (about two minutes on two cores).
"""

from __future__ import annotations

import os
import re
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("DYNID_SHARED_DATA", REPO.parent / "shared" / "data"))

FIGAROH = {"position_cutoff": 100.0, "decimation": 100,
           "min_speed": [0.05009095, 0.05009095, 0.07504916, 0.0715585, 0.05585054, 0.12217305]}
GRIDS = {
    # config, data folder, hand settings (preprocessing, friction); the authors' own settings first where published
    "ur10e": ("ur10e_mamedov2020", [({"position_cutoff": c, "parallel_cutoff": c}, f) for c in (3.0, 8.0) for f in ("auto", "description")]
              + [({"min_speed": 0.0}, "auto")]),
    "tx40": ("staubli_tx40_figaroh", [(FIGAROH, "description"), (FIGAROH, "auto")]
             + [({"position_cutoff": c, "parallel_cutoff": c}, f) for c in (20.0, 60.0) for f in ("auto", "description")]),
    "kuka_kr300": ("kuka_kr300_weigand2021", [({"position_cutoff": c, "parallel_cutoff": c}, f) for c in (3.0, 10.0, 20.0)
                                              for f in ("auto", "description")]),
    "kuka_med7": ("kuka_med7_lbrstack", [({"position_cutoff": 2.0, "parallel_cutoff": 2.0}, "description")]
                  + [({"position_cutoff": c, "parallel_cutoff": c}, f) for c in (5.0, 15.0) for f in ("auto", "description")]),
}


def _config(name: str, folder: Path, pre: dict | None, friction: str | None) -> Path:
    text = (REPO / "configs" / f"{name}.toml").read_text()
    text = re.sub(r"^\[preprocessing\].*?(?=^\[)", "", text, flags=re.S | re.M)
    text = re.sub(r"^friction = .*$", "", text, flags=re.M)
    lines = "".join(f"{k} = {v!r}\n".replace("'", '"') for k, v in (pre or {}).items())
    head = ("[preprocessing]\n" + lines if lines else "") + "[estimation]" + (f'\nfriction = "{friction}"' if friction else "")
    text = re.sub(r"^\[estimation\]", lambda m: head, text, count=1, flags=re.M)
    text = text.replace('robot = "robots/', f'robot = "{REPO / "configs" / "robots"}/')
    path = folder / f"{name}.toml"
    path.write_text(text)
    return path


def measure(path: Path, data: Path) -> tuple[float, str, np.ndarray]:
    from dynid.identification.run import run_identification
    from dynid.io.config.identification_config import load_identification_config

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = run_identification(load_identification_config(path, data_root=data))
    errors = [v.metrics()[result.main]["global_relative_error"] for v in result.validations]
    yardstick = result.diagnostics["yardstick"]["mean_global_relative_error"]
    return float(np.mean(errors)), result.main, np.array(errors), yardstick[result.main], yardstick[result.diagnostics["nominal_set"]]


def main() -> None:
    folder = Path(tempfile.mkdtemp())
    print("Each setting's own figure (its validation logs filtered by its settings) and the one yardstick's (every log's "
          "torques as measured, its states filtered by dynid's default rules, the same samples for every setting).")
    print("robot | defaults: main estimate, own % / yardstick % | best hand setting by its own figure: own % / "
          "yardstick % | best by the yardstick: yardstick % | defaults / best, on the yardstick | nominal on the "
          "yardstick, min-max over the settings %")
    for name, (data_name, grid) in GRIDS.items():
        data = DATA / data_name
        if not data.is_dir():
            print(f"{name}: {data} not found, skipped")
            continue
        default, main, _, yard, nominal = measure(_config(name, folder, None, None), data)
        tried = [(*measure(_config(name, folder, pre, fr), data), pre, fr) for pre, fr in grid]
        own = min(tried, key=lambda t: t[0])
        ruled = min(tried, key=lambda t: t[3])
        nominals = [nominal] + [t[4] for t in tried]
        print(f"{name} | {main}: {default:.2f} / {yard:.2f} | {own[5]}, friction {own[6]}: {own[0]:.2f} / {own[3]:.2f} | "
              f"{ruled[5]}, friction {ruled[6]}: {ruled[3]:.2f} | {yard / ruled[3]:.2f} | "
              f"{min(nominals):.3f}-{max(nominals):.3f}")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
