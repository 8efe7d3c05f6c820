"""Write a monitored service life: ``monitor.json`` (alarms, reference, every window), ``monitor.parquet`` (one row per
window and term) and ``monitor.png`` (each joint's terms against their reference, the alarms marked)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..fleet.monitor import STATE_FILE, MonitorResult
from .output import save_figure, staged, write_results

__all__ = ["save_monitor", "monitor_table"]


def monitor_table(result: MonitorResult) -> dict:
    """One row per window and term.

    Parameters
    ----------
    result : MonitorResult

    Returns
    -------
    dict
        column -> list: ``window``, ``log``, ``start_s``, ``end_s``, ``term``, ``joint``, ``value``, ``std``,
        ``tracked``, ``reference``, ``change_pct``.
    """
    cols: dict = {k: [] for k in ("window", "log", "start_s", "end_s", "term", "joint", "value", "std", "tracked",
                                  "reference", "change_pct")}
    for i, w in enumerate(result.windows):
        for k, term in enumerate(result.terms):
            ref = float(result.reference_mean[k]) if result.reference_mean.size else float("nan")
            value = float(w.theta[k])
            cols["window"].append(i)
            cols["log"].append(w.log)
            cols["start_s"].append(w.start)
            cols["end_s"].append(w.end)
            cols["term"].append(term)
            cols["joint"].append(result.joints[k])
            cols["value"].append(value if np.isfinite(value) else None)
            cols["std"].append(float(w.std[k]) if np.isfinite(w.std[k]) else None)
            cols["tracked"].append(float(w.tracked[k]))
            cols["reference"].append(ref)
            cols["change_pct"].append(100 * (value - ref) / abs(ref) if np.isfinite(value) and ref else None)
    return cols


def _figure(result: MonitorResult, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    joints = sorted(set(result.joints))
    fig, axes = plt.subplots(len(joints), 1, figsize=(9, 1.6 * len(joints) + 0.8), sharex=True, squeeze=False)
    x = np.arange(len(result.windows))
    values = np.array([w.theta for w in result.windows])
    for ax, j in zip(axes[:, 0], joints):
        for k in [k for k, jj in enumerate(result.joints) if jj == j]:
            ref, spread = result.reference_mean[k], result.reference_std[k]
            ax.plot(x, (values[:, k] - ref) / spread, lw=0.9, label=result.terms[k])
        for a in result.alarms:
            if a.joint == j:
                ax.axvline(next(i for i, w in enumerate(result.windows) if w.log == a.detected_log and w.end == a.detected),
                           color="crimson", lw=1.2)
        ax.axvline(result.settings.reference_windows - 0.5, color="black", ls="--", lw=0.8)
        ax.set_ylabel(f"joint {j}")
        ax.legend(loc="upper left", fontsize=7, ncol=4, frameon=False)
    axes[-1, 0].set_xlabel(f"window ({result.settings.window:g} s of log each; the reference before the dashed line; red: alarm)")
    fig.suptitle("Friction and offset terms against their reference, in reference spreads ((value - mean) / spread)")
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


@staged
def save_monitor(result: MonitorResult, out: str | Path) -> list[Path]:
    """Write ``monitor.json``, ``monitor.parquet`` (when pyarrow is installed), ``monitor.png`` and the state the next
    run goes on from (``monitor-state.json``, when the result keeps it).

    Parameters
    ----------
    result : MonitorResult
    out : str or Path

    """
    out = Path(out)
    write_results(out / "monitor.json", result.to_dict(), "monitor")
    paths = [out / "monitor.json"]
    if result.state is not None:
        (out / STATE_FILE).write_bytes(result.state)
        paths.append(out / STATE_FILE)
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        pass
    else:
        pq.write_table(pa.Table.from_pydict(monitor_table(result)), out / "monitor.parquet")
        paths.append(out / "monitor.parquet")
    _figure(result, out / "monitor.png")
    return paths + [out / "monitor.png"]
