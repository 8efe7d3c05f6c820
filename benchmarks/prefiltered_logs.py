"""Real logs low-pass filtered before dynid reads them (issue "Never worse than the description", item 5).

A driver or a bag recorder may filter positions, velocities and torques before they are logged. Such a log keeps no
sample-to-sample noise, so the rest thresholds dynid reads from the positions' noise fall to nearly 0. This script
takes the four real configs of ``configs/`` (no [preprocessing] table: every choice dynid's), filters every channel
of the identification log at 3 Hz before dynid sees it (zero-phase 4th-order Butterworth, and a causal 2nd-order
one as a driver would run), and identifies it twice: with the thresholds dynid reads from the filtered log, and with
those it reads from the raw log. The validation logs stay raw, so that every figure is on the one yardstick of the
raw validation samples. Run from the repository root: ``.venv/bin/python benchmarks/prefiltered_logs.py`` (about two
minutes on two cores; ``DYNID_PREFILTER_HZ=10`` filters at 10 Hz).
"""

from __future__ import annotations

import os
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.signal import butter, sosfilt, sosfiltfilt

REPO = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("DYNID_SHARED_DATA", REPO.parent / "shared" / "data"))
CONFIGS = {"ur10e": "ur10e_mamedov2020", "tx40": "staubli_tx40_figaroh", "kuka_kr300": "kuka_kr300_weigand2021",
           "kuka_med7": "kuka_med7_lbrstack"}
CUTOFF = float(os.environ.get("DYNID_PREFILTER_HZ", "3"))  # [Hz]


def _filtered(x: np.ndarray, rate: float, causal: bool) -> np.ndarray:
    if causal:  # from the first sample held since before the log began, as a running filter
        sos = butter(2, CUTOFF / (rate / 2), output="sos")
        return sosfilt(sos, x - x[0], axis=0) + x[0]
    pad = min(x.shape[0] - 1, int(10 * rate / CUTOFF))  # its transients at the ends decayed within the padding
    return sosfiltfilt(butter(4, CUTOFF / (rate / 2), output="sos"), x, axis=0, padlen=pad)


def identify(name: str, filtering: str | None, rest=None):
    """The config identified with its identification log filtered (``None``: raw) and the rest thresholds given."""
    import dynid.identification.run as run
    from dynid.io.config.identification_config import load_identification_config

    config = load_identification_config(REPO / "configs" / f"{name}.toml", data_root=DATA / CONFIGS[name])
    if rest is not None:
        config = replace(config, preprocessing=replace(config.preprocessing, rest_velocity=tuple(rest)))
    read = run.load_recording

    def load(spec, robot, **options):
        recording = read(spec, robot, **{**options, "spool": False})
        if filtering is None or spec is not config.identification:
            return recording
        causal = filtering == "causal"
        return replace(recording, q=_filtered(recording.q, recording.rate, causal), tau=_filtered(recording.tau, recording.rate, causal),
                       dq=None if recording.dq is None else _filtered(recording.dq, recording.rate, causal))

    run.load_recording = load
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return run.run_identification(config)
    finally:
        run.load_recording = read


def main() -> None:
    print(f"Every channel of the identification log filtered at {CUTOFF:g} Hz before dynid reads it; the validation "
          "logs raw. Mean global validation error % on the one yardstick.")
    print("config | log | rest thresholds, rad/s (max) | filtered said | main estimate | its % | with the raw log's "
          "thresholds: main, % | nominal %")
    for name in CONFIGS:
        if not (DATA / CONFIGS[name]).is_dir():
            print(f"{name}: {DATA / CONFIGS[name]} not found, skipped")
            continue
        raw = identify(name, None)
        thresholds = raw.settings["preprocessing"]["rest_velocity"]
        for filtering in (None, "zero-phase", "causal"):
            result = raw if filtering is None else identify(name, filtering)
            given = raw if filtering is None else identify(name, filtering, thresholds)
            figures = result.diagnostics["yardstick"]["mean_global_relative_error"]
            again = given.diagnostics["yardstick"]["mean_global_relative_error"]
            said = any(f.kind == "filtered" for f in result.findings)
            print(f"{name} | {filtering or 'raw'} | {max(result.settings['preprocessing']['rest_velocity']):.2g} | "
                  f"{'yes' if said else 'no'} | {result.main} | {figures[result.main]:.2f} | {given.main}, "
                  f"{again[given.main]:.2f} | {figures[result.diagnostics['nominal_set']]:.2f}", flush=True)


if __name__ == "__main__":
    main()
