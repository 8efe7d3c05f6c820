"""Output folders and figure files shared by the reports (every file written atomically)."""

from __future__ import annotations

import io
from pathlib import Path

from ..exceptions import ConfigError
from ..io import atomic_write_bytes


def output_folder(out: str | Path) -> Path:
    """Create ``out`` if needed and return it.

    Raises
    ------
    ConfigError
        If ``out`` exists and is not a folder, or cannot be created.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out}: exists and is not a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"--out {out}: cannot create the folder ({exc.strerror})") from None
    return out


def save_figure(fig_or_axes, path: Path) -> None:
    """Write the figure of ``fig_or_axes`` (a Figure, an Axes or an array of Axes) as PNG, atomically."""
    import matplotlib.pyplot as plt

    fig = fig_or_axes.figure if hasattr(fig_or_axes, "figure") else fig_or_axes.flat[0].figure
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, pil_kwargs={"compress_level": 1})  # fast zlib: 3x quicker, 1.3x larger
    plt.close(fig)
    atomic_write_bytes(path, buf.getvalue())


SCHEMA_VERSION = 1
"""Version of the layout of the JSON files dynid writes; raised when a field changes meaning or goes."""


def write_results(path: Path, data: dict, kind: str) -> None:
    """Write a results JSON atomically, headed by what wrote it: ``schema_version``, ``dynid_version`` and
    ``kind`` (run, identify, validate, excite, montecarlo)."""
    from .. import __version__
    from ..io import write_json

    write_json(path, {"schema_version": SCHEMA_VERSION, "dynid_version": __version__, "kind": kind, **data})
