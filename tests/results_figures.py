"""The compatibility corpus's figures read from any release's results.json (tests/io/test_compat_figures.py and
benchmarks/compat_figures.py, which runs earlier releases: their results.json have other schemas)."""

import numpy as np


def global_errors(results: dict) -> dict[tuple[str, str], float]:
    """Every global relative torque error a results.json holds, of any schema: the identification log's and each
    validation log's, per parameter set.

    ``100·‖τ − τ̂‖_F / ‖τ‖_F`` (as :func:`dynid.validation.metrics.global_relative_error`), recomputed from the per-joint
    RMSE and RMS torque where an early results.json stored no global figure.

    Parameters
    ----------
    results : dict
        A parsed results.json of ``dynid identify`` (any release).

    Returns
    -------
    dict
        ``(log name, set label) -> error [%]``.
    """
    out = {}
    for part in [results.get("identification")] + list(results.get("validation", [])):
        if not part:
            continue
        rms = part.get("rms_torque")
        for label, m in part.get("metrics", {}).items():
            value = m.get("global_relative_error")
            if value is None and m.get("rmse") is not None and rms is not None:
                value = 100.0 * float(np.sqrt(sum(e * e for e in m["rmse"]) / sum(r * r for r in rms)))
            if value is not None:
                out[(part["name"], label)] = float(value)
    return out
