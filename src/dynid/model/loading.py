"""A robot as dynid's entry points take it: a :class:`~dynid.model.robot.Robot`, a built-in robot's name or a
description's path (what :class:`dynid.Identifier` takes too)."""

from __future__ import annotations

from pathlib import Path

from .robot import Robot

__all__ = ["as_robot"]


def as_robot(robot, what: str = "robot") -> Robot:
    """A robot given as a :class:`Robot`, a built-in name or a description's path
    (:func:`dynid.model.description.load_robot`), as dynid's entry points take it (``Identifier``, ``simulated_log``,
    ``regressor``, ``load_recording``, the exports …; lower-level functions take a :class:`Robot`).

    Parameters
    ----------
    robot : Robot, str or Path
    what : str
        The argument's name, for the message.

    Returns
    -------
    Robot

    Raises
    ------
    TypeError
        Anything else (the message says what is expected).
    ConfigError
        An unknown name or an unreadable description (:func:`dynid.model.description.load_robot`).
    """
    if isinstance(robot, Robot):
        return robot
    if isinstance(robot, (str, Path)):
        from .description import load_robot  # the readers of robot files (msgspec, TOML), only for a name or a path

        return load_robot(robot)
    raise TypeError(f"{what}: expected a Robot (dynid.load_robot(...)), a built-in robot's name or a description's "
                    f"path, got {type(robot).__name__}")
