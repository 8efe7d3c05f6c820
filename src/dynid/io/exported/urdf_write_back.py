"""The user's own URDF with the identified values written into it, as a text edit: only the ``<inertial>`` of each
moving link and the ``<dynamics>`` of each moving joint change, every other byte of the file stays as it was (its
declaration, the comments before ``<robot>``, the layout of each line, ``/>`` or ``" />"``), so that ``diff`` against
the user's file shows only the identified values (issue "A user's first hour", item 5).

The file is read by expat (the standard library's XML parser), which gives each element's byte offset in the file;
the edits are spans of the original bytes replaced by new text at the indentation the file already uses.
"""

from __future__ import annotations

import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from xml.parsers import expat
from xml.parsers.expat import ExpatError

import numpy as np

from ...exceptions import ConfigError
from ...model.description_files import _exportable, _world_from_base, position_offset_note
from ...model.robot import Robot
from ...model.spatial import is_physically_consistent, nearest_consistent, physical_from_inertial
from .export import identified_header, moved_far

__all__ = ["urdf_written_back"]


@dataclass
class _Element:
    """An element of the file: its tag, attributes, and byte spans (``start``: ``<``; ``open_end``: after the start
    tag's ``>``; ``close``: the end tag's ``<``, or ``open_end`` when the element is empty, ``<x/>``; ``end``: after
    its last ``>``)."""

    tag: str
    attrs: dict
    start: int
    open_end: int = 0
    close: int = 0
    end: int = 0
    children: list = field(default_factory=list)

    def child(self, tag: str):
        return next((c for c in self.children if c.tag == tag), None)


def _tag_end(data: bytes, start: int) -> int:
    """The offset after the ``>`` that closes the tag starting at ``start`` (quotes respected: ``>`` may appear in an
    attribute's value)."""
    quote = None
    for i in range(start + 1, len(data)):
        c = data[i:i + 1]
        if quote is not None:
            if c == quote:
                quote = None
        elif c in (b'"', b"'"):
            quote = c
        elif c == b">":
            return i + 1
    raise ValueError("unterminated tag")


def _parse(data: bytes) -> _Element:
    """The element tree of ``data`` with byte spans (expat's ``CurrentByteIndex`` at each start and end tag)."""
    parser = expat.ParserCreate()
    stack: list[_Element] = []
    top: list[_Element] = []

    def start(tag, attrs):
        i = parser.CurrentByteIndex
        e = _Element(tag, attrs, i, _tag_end(data, i))
        (stack[-1].children if stack else top).append(e)
        stack.append(e)

    def end(tag):
        e = stack.pop()
        i = parser.CurrentByteIndex
        empty = data[e.open_end - 2:e.open_end] == b"/>" and i == e.start
        e.close, e.end = (e.open_end, e.open_end) if empty else (i, _tag_end(data, i))

    parser.StartElementHandler, parser.EndElementHandler = start, end
    parser.Parse(data, True)
    return top[0]


def _column(data: bytes, at: int) -> bytes:
    """The whitespace that begins the line of offset ``at`` (up to it, when only whitespace precedes it)."""
    line = data.rfind(b"\n", 0, at) + 1
    lead = data[line:at]
    return lead if not lead.strip() else b""


def _unit(data: bytes, root: _Element) -> bytes:
    """The file's indentation step: the first child of the root's indentation (two spaces if the file has none)."""
    for e in root.children:
        lead = _column(data, e.start)
        if lead:
            return lead
    return b"  "


def _empty_close(data: bytes) -> str:
    """How the file closes an empty element: ``" />"`` where it does so more often than ``"/>"``."""
    spaced = data.count(b" />")
    return " />" if spaced > data.count(b"/>") - spaced else "/>"


def _number(x: float) -> str:
    """The shortest text that reads back as the same double (``repr``): 7.778, not 7.7779999999999996."""
    return repr(float(x))


def _inertial_values(mass: float, com: np.ndarray, inertia: np.ndarray) -> dict[str, dict[str, str]]:
    """The attributes of an ``<inertial>``'s children: the centre of mass and the inertia about it, in the link's
    frame (``rpy = 0 0 0``); entries below 1e-12 of the inertia's trace are written as 0."""
    i = np.where(np.abs(inertia) < 1e-12 * np.trace(inertia), 0.0, inertia)  # a rotation's rounding, not a value
    return {"origin": {"xyz": " ".join(_number(x) for x in com), "rpy": "0 0 0"}, "mass": {"value": _number(mass)},
            "inertia": {a: _number(i[r, c]) for a, (r, c) in zip(("ixx", "ixy", "ixz", "iyy", "iyz", "izz"),
                                                                  ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)))}}


def _inertial_text(values: dict[str, dict[str, str]], indent: str, unit: str, close: str) -> str:
    """An ``<inertial>`` block whose first line starts at the caller's position and whose other lines at ``indent``."""
    inner = indent + unit
    lines = [f"{inner}<{tag}" + "".join(f' {k}="{v}"' for k, v in attrs.items()) + close for tag, attrs in values.items()]
    return "<inertial>\n" + "\n".join(lines) + f"\n{indent}</inertial>"


def _set_attributes(tag: str, values: dict[str, str]) -> str:
    """The start tag ``tag`` with each attribute of ``values`` given that value (replaced where present, added before
    the tag's end otherwise); every other byte kept."""
    for name, value in values.items():
        pattern = re.compile(rf"(\s{name}\s*=\s*)([\"'])(.*?)\2", re.S)
        found = pattern.search(tag)
        if found and _same_numbers(found.group(3), value):  # the file's own text where the value is the same
            continue
        if found:
            tag = f"{tag[:found.start(3)]}{value}{tag[found.end(3):]}"
        else:
            cut = len(tag) - (2 if tag.endswith("/>") else 1)
            cut -= len(tag[:cut]) - len(tag[:cut].rstrip())
            tag = f"{tag[:cut]} {name}=\"{value}\"{tag[cut:]}"
    return tag


def _same_numbers(old: str, new: str) -> bool:
    """Whether two attribute values hold the same numbers to 1e-12 (a value read and written back, rounding aside)."""
    try:
        a, b = np.array(old.split(), dtype=float), np.array(new.split(), dtype=float)
    except ValueError:
        return False
    return a.shape == b.shape and bool(np.allclose(a, b, rtol=1e-12, atol=1e-300))


def _comment(text: str) -> str:
    return "<!--" + text.replace("--", "- -") + "-->"


def _write_joint(text, links: dict, children: dict, joint, link_name: str, robot, fitted, k: int, own) -> list[str]:
    """:func:`urdf_written_back`'s joint ``k``: its child link's identified inertial values (less its held links' own,
    ``own``, the nearest consistent ones where that is not physically consistent; the fixed links merged into it
    emptied) and its ``<dynamics>``; what moved far from the file's values, said."""
    moved = []
    alone = fitted.inertial[k] - (0.0 if own is None else own)
    if own is not None and np.any(own != 0) and not is_physically_consistent(alone):
        alone = nearest_consistent(alone)  # the identified link lighter than its held links' nominal values
        moved.append(f"{link_name}: its identified values less the held links' own are not physically consistent; "
                     "the nearest consistent ones are written (the held links keep the file's)")
    mass, com, inertia = physical_from_inertial(alone)
    merged = _remove_fixed_inertials(text, links, children, link_name)
    _write_inertial(text, links[link_name], _inertial_values(mass, com, inertia), merged)
    _write_dynamics(text, joint, robot, fitted, k)
    m0, c0, _ = physical_from_inertial(robot.inertial[k]) if robot.inertial[k][9] > 0 else (0.0, np.zeros(3), None)
    far = moved_far(link_name, mass, com, m0, c0, "URDF")
    return moved + ([far] if far else [])


def urdf_written_back(urdf: str | Path, robot: Robot, phi: np.ndarray, estimate: str = "the physically consistent "
                      "estimate") -> tuple[str, list[str]]:
    """The user's own URDF with the identified values written into it, and nothing else changed.

    Every byte of the URDF stays as it is — link and joint names, frames, visuals, collisions, meshes, limits,
    transmissions, comments, the layout of each line — but each moving link's ``<inertial>`` and each moving joint's
    ``<dynamics>`` ``damping`` and ``friction`` (its other attributes kept). A link attached by fixed joints to a
    moving one (a flange, a tool frame) is identified together with it: its ``<inertial>`` moves into the moving link's
    (a comment says so). The links of joints the robot holds fixed (:attr:`dynid.model.robot.Robot.held`: a gripper's
    fingers) keep their own ``<inertial>``, and the moving link they hang on gets the identified values less theirs,
    so that the model with those joints free loads and moves. What a URDF cannot hold (rotor inertia, offsets, a smooth Coulomb term, coupled
    motors) is written in comments, and a header comment inside ``<robot>`` says what was identified: only the base
    parameters are; the values written are one physically consistent choice among the many with the same base
    parameters (the split between a link and the rotor inertia, and unidentifiable directions, are that choice's).

    Parameters
    ----------
    urdf : str or Path
        The URDF the robot was described by (UTF-8).
    robot : Robot
        The robot read from it (its joints carry the URDF's joint names).
    phi : (n_params,) array
        Standard parameters to write (physically consistent).
    estimate : str
        What the values are, for the header comment.

    Returns
    -------
    text : str
        The URDF.
    moved : list of str
        One line per link whose values moved far from the URDF's own (:func:`dynid.io.exported.export.moved_far`), also in the
        header comment.

    Raises
    ------
    ConfigError
        The URDF cannot be read, its joints are not the robot's, or the values are not exportable
        (:func:`dynid.model.description_files.urdf_from_robot`'s checks).
    """
    path = Path(urdf)
    fitted = _exportable(robot, phi)

    try:
        data = path.read_bytes()
        data.decode("utf-8")
        text = _TextEdits(data, _parse(data))
    except (OSError, ValueError, ExpatError) as exc:  # UnicodeDecodeError is a ValueError
        raise ConfigError(f"{path}: cannot read it as URDF ({exc})") from None
    root = text.root
    joints = {e.attrs.get("name"): e for e in root.children if e.tag == "joint"}  # not a <transmission>'s <joint>
    links = {e.attrs.get("name"): e for e in root.children if e.tag == "link"}
    missing = [j.name for j in robot.joints if j.name not in joints]
    if missing:
        raise ConfigError(f"{path}: has no joint {missing[0]!r}: the results are of another robot than this URDF's")

    def end(joint: _Element, which: str) -> str:  # the link a joint's <parent> or <child> names
        e = joint.child(which)
        if e is None or not e.attrs.get("link"):
            raise ConfigError(f"{path}: joint {joint.attrs.get('name')!r} has no <{which} link=...>")
        if e.attrs["link"] not in links:
            raise ConfigError(f"{path}: joint {joint.attrs.get('name')!r} names link {e.attrs['link']!r}, which the file does not have")
        return str(e.attrs["link"])

    children: dict[str, list[str]] = {}  # link -> links attached to it by fixed joints
    for j in joints.values():
        if j.attrs.get("type") == "fixed" and j.attrs.get("name") not in robot.held:
            children.setdefault(end(j, "parent"), []).append(end(j, "child"))
    held_links = _held_subtrees(joints, robot.held, end)
    own = _held_contributions(path, data, text, links, held_links, robot) if held_links else None
    moved: list[str] = []
    for k, joint in enumerate(robot.joints):
        moved.extend(_write_joint(text, links, children, joints[joint.name], end(joints[joint.name], "child"), robot,
                                  fitted, k, None if own is None else own[k]))
    head = _header_comments(path, robot, fitted, estimate, moved)
    inner = text.indent_in(root)
    text.insert(root.open_end, "".join(f"\n{inner}{h}" for h in head))
    return text.result(), moved


def _header_comments(path: Path, robot: Robot, fitted, estimate: str, moved: list[str]) -> list[str]:
    """The comments written at the top of the robot element: what was identified and where it moved far, then what a URDF
    cannot hold (the mounting's gravity, the encoders' position offsets, coupled motors' terms)."""
    head = [_comment(identified_header(path.name, "the <inertial> of every moving link and the <dynamics> of every "
                                       "moving joint", estimate, moved, "URDF"))]
    if _world_from_base(robot.gravity) is not None:  # the config's mounting, which a URDF cannot hold
        vector = " ".join(f"{x:g}" for x in robot.gravity)
        head.append(_comment(f" dynid: gravity is {vector} m/s² in this robot's base frame (the root "
                             "link's), as identified: a URDF cannot hold it; give it to the simulator or controller that "
                             "loads this file (Pinocchio: model.gravity.linear) "))
    if note := position_offset_note(robot):
        head.append(_comment(note))
    if robot.transmission.n_coupled_params:
        names = robot.transmission.coupled_parameter_names
        head.append(_comment(" dynid: coupled motors (not representable in URDF), add their torques: " + ", ".join(
            f"{n} = {v:.17g}" for n, v in zip(names, fitted.transmission.coupled_values.ravel())) + " "))
    return head


class _TextEdits:
    """Spans of a file's bytes to replace, applied at the end from the last to the first (offsets stay valid)."""

    def __init__(self, data: bytes, root: _Element):
        self.data, self.root = data, root
        self.unit, self.close = _unit(data, root).decode(), _empty_close(data)
        self.edits: list[tuple[int, int, str]] = []  # (start, end, new text) of the original bytes

    def replace(self, start: int, stop: int, text: str) -> None:
        self.edits.append((start, stop, text))

    def insert(self, at: int, text: str) -> None:
        self.edits.append((at, at, text))

    def source(self, e: _Element) -> str:
        """An element's start tag as the file has it."""
        return self.data[e.start:e.open_end].decode()

    def column(self, at: int) -> str:
        return _column(self.data, at).decode()

    def indent_in(self, parent: _Element) -> str:
        """The indentation of the parent's children (its first child's, or the parent's plus the file's step)."""
        first = next((c for c in parent.children), None)
        lead = _column(self.data, first.start) if first is not None else b""
        return lead.decode() if lead else self.column(parent.start) + self.unit

    def append_inside(self, parent: _Element, text: str) -> None:
        """``text`` (lines at the parent's child indentation) as the parent's last content."""
        inner = self.indent_in(parent)
        if parent.close == parent.open_end:  # <link name="x"/>: opened
            head = self.source(parent)[:-2].rstrip() + ">"
            self.replace(parent.start, parent.open_end, f"{head}\n{inner}{text}\n{self.column(parent.start)}</{parent.tag}>")
        else:
            at = parent.close
            lead = _column(self.data, at)
            self.insert(at - len(lead), f"{inner}{text}\n" if lead else f"\n{inner}{text}\n")

    def remove(self, e: _Element) -> None:
        """An element, with its line where it stood alone on it."""
        lead = _column(self.data, e.start)
        after = e.end + 1 if self.data[e.end:e.end + 1] == b"\n" and lead else e.end
        self.replace(e.start - len(lead), after, "")

    def result(self) -> str:
        out = self.data
        for start, stop, text in sorted(self.edits, key=lambda e: (e[0], e[1]), reverse=True):
            out = out[:start] + text.encode() + out[stop:]
        return out.decode("utf-8")


def _held_subtrees(joints: dict, held, end) -> set[str]:
    """The links a held joint carries (a gripper's fingers), with every link attached below them."""
    below: dict[str, list[str]] = {}
    for j in joints.values():
        below.setdefault(end(j, "parent"), []).append(end(j, "child"))
    stack = [end(j, "child") for name, j in joints.items() if name in held]
    out: set[str] = set()
    while stack:
        name = stack.pop()
        if name not in out:
            out.add(name)
            stack.extend(below.get(name, ()))
    return out


def _held_contributions(path: Path, data: bytes, text: _TextEdits, links: dict, held_links: set[str],
                        robot: Robot) -> np.ndarray:
    """Each moving link's share of the held links' own (nominal) inertials, in its frame at the held pose: the robot
    read from the URDF lumps them into the link they hang on; the same URDF without their ``<inertial>`` gives the
    links alone, and the difference is theirs (the lumping is a sum). The written URDF keeps their ``<inertial>`` as
    the file has them and gives the moving link the identified values less this share, so that the full model's
    mass matrix stays positive definite (with the lumped values written into the last link and the fingers massless,
    a 9-joint Panda's was singular)."""
    from ...model.description import robot_from_urdf

    bare = _TextEdits(data, text.root)
    for name in held_links:
        if links[name].child("inertial") is not None:
            bare.remove(links[name].child("inertial"))
    with tempfile.TemporaryDirectory() as folder:
        copy = Path(folder) / path.name
        copy.write_text(bare.result(), encoding="utf-8")
        alone = robot_from_urdf(copy, held=robot.held)
    return np.asarray(robot.inertial, dtype=float) - np.asarray(alone.inertial, dtype=float)


def _remove_fixed_inertials(text: _TextEdits, links: dict, children: dict, link_name: str) -> list[str]:
    """Remove the ``<inertial>`` of the links fixed (directly or not) to ``link_name``: identified with it. Returns
    their names."""
    stack, merged = list(children.get(link_name, ())), []
    while stack:
        name = stack.pop()
        stack.extend(children.get(name, ()))
        old = links[name].child("inertial")
        if old is not None:
            text.remove(old)
            merged.append(name)
    return merged


def _write_inertial(text: _TextEdits, link: _Element, inertial: dict, merged: list[str]) -> None:
    """A link's identified ``<inertial>``: its three children's values edited in place where the file has exactly
    them, the element rewritten at its place otherwise, or added as the link's last child."""
    note = (_comment(f" dynid: the inertials of {', '.join(merged)} (fixed to this link) are identified with it and "
                     "written here ") if merged else "")
    current = link.child("inertial")
    parts = {c.tag: c for c in current.children} if current is not None else {}
    if current is not None and set(parts) == set(inertial) and len(current.children) == 3:  # values edited in place
        for tag, attrs in inertial.items():
            e = parts[tag]
            text.replace(e.start, e.open_end, _set_attributes(text.source(e), attrs))
        if note:
            text.insert(current.start, f"{note}\n{text.column(current.start)}")
    elif current is not None:
        indent = text.column(current.start)
        text.replace(current.start, current.end,
                     (f"{note}\n{indent}" if note else "") + _inertial_text(inertial, indent, text.unit, text.close))
    else:
        inner = text.indent_in(link)
        text.append_inside(link, (f"{note}\n{inner}" if note else "") + _inertial_text(inertial, inner, text.unit, text.close))


def _write_dynamics(text: _TextEdits, element: _Element, robot: Robot, fitted: Robot, k: int) -> None:
    """Joint ``k``'s ``<dynamics>`` damping (viscous) and friction (Coulomb), and comments for what URDF cannot hold."""
    terms = dict(zip(robot.drive_terms, fitted.drive[k]))
    values = {"damping": _number(terms.get("fv", 0.0)), "friction": _number(terms.get("fc", 0.0))}
    notes = []
    extra = {t: v for t, v in terms.items() if t not in ("fc", "fv") and v != 0}
    if extra:
        notes.append(_comment(" dynid: drive terms URDF cannot hold, add them to the torques: "
                              + ", ".join(f"{t}{k + 1} = {v:.17g}" for t, v in extra.items()) + " "))
    if robot.coulomb_velocity[k] > 0:
        notes.append(_comment(f" dynid: Coulomb term tanh(dq/{robot.coulomb_velocity[k]:.6g}) instead of sign(dq) "))
    dynamics = element.child("dynamics")
    inner = text.indent_in(element)
    if dynamics is not None:
        tag = _set_attributes(text.source(dynamics), values)
        text.replace(dynamics.start, dynamics.open_end, tag + "".join(f"\n{inner}{n}" for n in notes))
    else:
        text.append_inside(element, f"<dynamics damping=\"{values['damping']}\" friction=\"{values['friction']}\"{text.close}"
                           + "".join(f"\n{inner}{n}" for n in notes))
