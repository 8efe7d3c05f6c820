"""Files written whole or not at all: write to a temporary file beside the target, then rename."""

from __future__ import annotations

import json
import math
import os
import tempfile
from pathlib import Path

from ..exceptions import DataError


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    """Write a file atomically (no half-written file on error).

    With the permissions an ordinary new file gets under the user's umask (a temporary file would otherwise keep mode
    0600).

    Parameters
    ----------
    path : str or Path
    data : bytes

    Raises
    ------
    DataError
        ``path`` exists and is not a regular file (a device such as /dev/null, a FIFO, a socket): it is never replaced.
    """
    path = Path(path)
    if path.exists() and not path.is_file():
        raise DataError(f"{path}: not a regular file (a device, a FIFO or a socket): give the name of a file to write")
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write_text(path: str | Path, text: str) -> None:
    """Write UTF-8 text atomically (:func:`atomic_write_bytes`).

    Parameters
    ----------
    path : str or Path
    text : str
    """
    atomic_write_bytes(path, text.encode("utf-8"))


def _clean(obj):
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if hasattr(obj, "tolist"):
        return _clean(obj.tolist())
    return obj


def write_json(path: str | Path, data: dict) -> None:
    """Write indented JSON atomically; NaN and inf become ``null``.

    Parameters
    ----------
    path : str or Path
    data : dict
    """
    atomic_write_text(path, json.dumps(_clean(data), indent=2, ensure_ascii=False) + "\n")


def text_encoding_hint(path: Path) -> str:
    """A hint from a file's first bytes when it is not UTF-8 text.

    Parameters
    ----------
    path : Path

    Returns
    -------
    str
        ``" (UTF-16: save it as UTF-8)"``, ``" (a spreadsheet's workbook? save the sheet as CSV)"``,
        ``" (a binary file?)"``, or ``""`` if none applies.
    """
    try:
        with open(path, "rb") as fh:
            head = fh.read(4096)
    except OSError:
        return ""
    if head.startswith((b"\xff\xfe", b"\xfe\xff")) or (len(head) > 3 and head[1:2] == b"\x00" and head[3:4] == b"\x00"):
        return " (it looks like UTF-16: save it as UTF-8)"
    if head.startswith((b"PK\x03\x04", b"\xd0\xcf\x11\xe0")):  # a zip archive (.xlsx, .ods), an OLE file (.xls)
        return " (a spreadsheet's workbook? save the sheet as CSV)"
    if b"\x00" in head:
        return " (a binary file?)"
    return ""
