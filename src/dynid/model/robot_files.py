"""What the readers of robot files share (:mod:`dynid.model.urdf`, :mod:`dynid.model.mjcf`): the XML check, which kind
a file is, and what a refusal of a joint dynid cannot identify says to do."""

from __future__ import annotations

import re
from pathlib import Path
from xml.parsers import expat

from ..exceptions import ConfigError

HELD_HINT = "hold it fixed with held = [{names}] in the config's [robot] table (a gripper's fingers)"
"""What a refusal of a joint dynid cannot identify says to do (:func:`dynid.model.urdf.check_urdf_text`,
:func:`dynid.model.urdf.joints_from_urdf`, :mod:`dynid.model.mjcf`)."""


def check_xml(path: Path, parser=None) -> None:
    """Refuse a file that is not well-formed XML, naming the line and column.

    Parameters
    ----------
    path : Path
    parser : xml.parsers.expat.XMLParserType, optional
        A parser with handlers set (a new one by default).

    Raises
    ------
    ConfigError
        ``FILE: line L, column C: malformed XML (reason)``.
    """
    parser = parser or expat.ParserCreate()
    try:
        parser.Parse(path.read_bytes(), True)
    except expat.ExpatError as exc:
        raise ConfigError(f"{path}: line {exc.lineno}, column {exc.offset + 1}: malformed XML "
                          f"({expat.ErrorString(exc.code)})") from None


def is_mjcf(path: str | Path) -> bool:
    """Whether a robot file is a MuJoCo model (MJCF): a ``.xml`` or ``.mjcf`` file whose root element is ``<mujoco>``.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    bool
    """
    path = Path(path)
    if path.suffix.lower() not in (".xml", ".mjcf") or not path.is_file():
        return False
    with open(path, "rb") as f:
        head = f.read(4096)
    return re.search(rb"<mujoco[\s>]", re.sub(rb"<!--.*?-->", b"", head, flags=re.S)) is not None
