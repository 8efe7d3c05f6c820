"""MoveIt's semantic robot description (SRDF): the pairs of links it says never to check for collisions.

Pinocchio removes those pairs from a geometry model itself (``pinocchio.removeCollisionPairs``); this reader only
lists them, so that an SRDF naming links the robot does not have (another robot's file) is refused, not ignored.
Reference: MoveIt's SRDF format (``<disable_collisions link1="..." link2="..." reason="..."/>``).
"""

from __future__ import annotations

from pathlib import Path
from xml.parsers import expat

from ..exceptions import ConfigError
from .robot_files import check_xml

__all__ = ["disabled_link_pairs"]


def disabled_link_pairs(path: str | Path) -> tuple[frozenset[str], ...]:
    """The ``<disable_collisions>`` pairs of an SRDF.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    tuple of frozenset of str
        Link names, two to a pair (one for a link disabled against itself).

    Raises
    ------
    ConfigError
        A missing file, malformed XML (line and column), or a ``<disable_collisions>`` without ``link1`` or ``link2``.
    """
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"{path}: SRDF not found")
    check_xml(path)
    parser = expat.ParserCreate()
    pairs: list[frozenset[str]] = []
    problems: list[str] = []

    def start(name, attrs):
        if name != "disable_collisions":
            return
        if not attrs.get("link1") or not attrs.get("link2"):
            problems.append(f"{path}: line {parser.CurrentLineNumber}: <disable_collisions> needs link1 and link2")
        else:
            pairs.append(frozenset((attrs["link1"], attrs["link2"])))

    parser.StartElementHandler = start
    parser.Parse(path.read_bytes(), True)
    if problems:
        raise ConfigError(problems[0])
    return tuple(pairs)
