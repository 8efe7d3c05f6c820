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


def arm_chain(parents: dict[int, int], revolute: set[int], sliding=frozenset(), named=frozenset()) -> list[int]:
    """The arm's joints in a robot file's tree of moving joints: the longest chain from the base of revolute and
    prismatic joints, each riding on the one before (of chains as long, the first in the file's reading order); where
    a log names joints, the chain that holds most of them (of those, the longest: the right arm of a two-arm robot
    whose log is the right arm's). The prismatic joints at a chain's tip are taken for a gripper's fingers, not the
    arm's, unless the chain has nothing else (a gantry); a SCARA whose quill ends the arm gives it back by its config's
    ``held``.

    Parameters
    ----------
    parents : dict of int to int
        Every moving joint -> the moving joint it rides on (-1: the base), in reading order: a joint after its parent.
    revolute : set of int
        The revolute joints that can be the arm's (a ``<mimic>`` joint only where it carries the arm on).
    sliding : set of int
        The prismatic joints that can be the arm's (a linear track, a lift, a SCARA's vertical axis).
    named : set of int
        The joints a log names (none: the longest chain).

    Returns
    -------
    list of int
        From the base outwards.
    """
    return max(_chains(parents, revolute, sliding).values(), key=lambda chain: (len(named.intersection(chain)), len(chain)))


def _chains(parents: dict[int, int], revolute: set[int], sliding=frozenset()) -> dict[int, list[int]]:
    """Each joint reached from the base through revolute and prismatic joints -> that chain less the prismatic joints
    at its tip (a gripper's fingers), unless they are all it has (``-1``: the empty one)."""
    chains: dict[int, list[int]] = {-1: []}
    for k, parent in parents.items():
        if (k in revolute or k in sliding) and parent in chains:
            chains[k] = chains[parent] + [k]
    trimmed = {}
    for k, chain in chains.items():
        end = len(chain)
        while end and chain[end - 1] in sliding:
            end -= 1
        trimmed[k] = chain[:end] if end else chain
    return trimmed


def joints_off_arm(parents: dict[int, int], revolute: set[int], sliding=frozenset(), logged=frozenset()) -> list[int]:
    """The joints ``dynid init`` holds: those off the arm (:func:`arm_chain`); where the joints a log names lie on
    several branches' chains (both arms of a two-arm robot), every joint but those (the robot is then their tree). A
    gripper's prismatic fingers and a mimic joint at a tip are on no chain: held, whether the log names them or not.

    Parameters
    ----------
    parents, revolute, sliding
        As :func:`arm_chain`.
    logged : set of int
        The joints a log names (none: the longest chain's).

    Returns
    -------
    list of int
        In reading order.
    """
    arm = arm_chain(parents, revolute, sliding, set(logged))
    on_chains = set(logged) & set().union(*_chains(parents, revolute, sliding).values())
    if on_chains - set(arm):
        return [k for k in parents if k not in on_chains]
    return [k for k in parents if k not in arm]


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
