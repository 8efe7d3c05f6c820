"""xacro robot descriptions expanded by dynid itself: no code of the file runs, and no other program reads it.

A xacro file is a URDF written with properties, macros, arguments, conditionals, includes and YAML data. dynid expands
it on the standard library's XML parser (:mod:`xml.dom.minidom`), and every ``${...}`` and ``$(eval ...)`` is computed
by dynid's interpreter (:func:`dynid.model.xacro_expressions.evaluate`), never by Python's ``eval``. What is expanded
follows xacro 2.x (ROS 2), the format's reference implementation (wiki.ros.org/xacro):

- ``<xacro:property>`` with ``value``, ``default``, ``remove``, ``scope="parent|global"`` and ``lazy_eval``, and block
  properties (children, inserted with ``<xacro:insert_block>``); ``'quoted'`` values stay strings, numbers become
  numbers, ``true``/``false`` booleans;
- ``<xacro:macro name params>`` with defaults (``a:=1``, ``a:=^``, ``a:=^|1``), block parameters (``*origin``,
  ``**content``), macros calling macros, ``<xacro:call macro="...">``; the macro's body sees the caller's properties;
- ``<xacro:arg>`` and ``$(arg ...)``, ``$(eval ...)``, ``$(env ...)``, ``$(optenv ...)``, ``$(dirname)``, ``$(cwd)``,
  and ``$(find pkg)`` without ROS: the package folder beside the file (a cloned description package or workspace), on
  ``ROS_PACKAGE_PATH`` or under ``AMENT_PREFIX_PATH`` (:meth:`XacroExpansion.find`);
- ``<xacro:if value>`` / ``<xacro:unless value>``, ``<xacro:element xacro:name>``, ``<xacro:attribute>``;
- ``<xacro:include filename ns optional>`` by path relative to the including file (globs too), namespaced;
- ``xacro.load_yaml(file)`` read by ``yaml.safe_load`` (data only) with xacro's unit tags (``!degrees 90``).

A file that would expand without end (a macro calling itself, a file including itself, macros doubling each other's
output) is refused at :data:`MAX_DEPTH` nested calls or :data:`MAX_ELEMENTS` elements made.
"""

from __future__ import annotations

import builtins
import contextlib
import glob
import math
import os
import re
import xml.dom
import xml.dom.minidom
from pathlib import Path
from typing import Any
from xml.parsers import expat

from ..exceptions import ConfigError
from ..runtime.extras import require
from .xacro_expressions import ALLOWED_BUILTINS, evaluate

__all__ = ["MAX_DEPTH", "MAX_ELEMENTS", "XacroExpansion", "expand_xacro_text"]

MAX_DEPTH = 200
"""Macro calls and includes nested deeper than this refuse the file (a macro or a file that calls itself)."""

LARGEST_FILE = 64 * 2**20
"""[bytes] A file a xacro description includes or loads as YAML: larger ones are refused (a robot description's
files are kilobytes; a 2 GB file or /dev/zero would fill the memory)."""


def _regular(path: str, what: str) -> None:
    """Refuse what is not a regular file of at most :data:`LARGEST_FILE` bytes: a FIFO blocks its reader forever, a
    device never ends."""
    if os.path.exists(path) and not os.path.isfile(path):
        raise XacroError(f"{what}: {path} is not a regular file (a device, a FIFO or a socket)")
    if os.path.isfile(path) and os.path.getsize(path) > LARGEST_FILE:
        raise XacroError(f"{what}: {path} is {os.path.getsize(path) / 2**20:.0f} MiB, more than a robot description "
                         f"reads ({LARGEST_FILE // 2**20} MiB)")
MAX_ELEMENTS = 50_000
"""Elements one expansion may make (a URDF of a robot arm has a few hundred, with its ROS 2 control and Gazebo tags a
few thousand)."""

_UNITS = {"!radians": 1.0, "!degrees": math.pi / 180.0, "!meters": 1.0, "!millimeters": 0.001, "!foot": 0.3048,
          "!inches": 0.0254}
"""xacro's YAML unit tags and their factors to radians or metres."""
_TOKENS = re.compile(r"\$\$+[{(]|\$\{[^}]*\}|\$\([^)]*\)|[^$]+|\$[^{($]+|\$$")
"""xacro's lexer: ``$$``-escapes, ``${expression}``, ``$(extension)``, and text."""
_PARAM = re.compile(r"\s*([^\s:=]+?)\s*(?::?=\s*(\^\|?)?((?:\$\{[^}]*\}|\$\([^)]*\)|'[^']*'|\"[^\"]*\"|[^\s'\"$]+|\$)*))?"
                    r"(?:\s+|$)")
"""One macro parameter: its name, an optional ``:=`` default (``^`` forwards the caller's property of that name)."""


class XacroError(Exception):
    """A file xacro's format cannot expand (said as ``<file>: xacro cannot expand it: <reason>``)."""


class _Namespace(dict):
    """A mapping whose members an expression reaches as attributes (``math.pi``, ``ns.prop``): a ``dict`` subclass,
    which :func:`~dynid.model.xacro_expressions.evaluate` reads by key."""


class _YamlDict(_Namespace):
    """A YAML mapping: its members by key or as attributes, nested mappings and lists wrapped in turn."""

    def __getitem__(self, key):
        return _wrap(dict.__getitem__(self, key))


class _YamlList(list):
    """A YAML list whose mappings read as :class:`_YamlDict`."""

    def __getitem__(self, index):
        return _wrap(list.__getitem__(self, index))

    def __iter__(self):
        return (_wrap(v) for v in list.__iter__(self))


def _wrap(value):
    if isinstance(value, dict) and not isinstance(value, _YamlDict):
        return _YamlDict(value)
    if isinstance(value, list) and not isinstance(value, _YamlList):
        return _YamlList(value)
    return value


def _literal(value: Any) -> Any:
    """A property's text as xacro types it: ``'quoted'`` a string, a number a number, true/false a boolean."""
    if not isinstance(value, str):
        return value
    if len(value) >= 2 and value[0] == value[-1] == "'":
        return value[1:-1]
    if "_" in value:  # Python reads 1_000 as a number; xacro keeps it a string
        return value
    for convert in (int, float):
        try:
            return convert(value)
        except ValueError:
            pass
    return {"true": True, "True": True, "false": False, "False": False}.get(value, value)


def _boolean(value: Any, text: str) -> bool:
    """A condition's value (``xacro:if``, ``lazy_eval``): true/True/false/False, a number, or a boolean."""
    if isinstance(value, str):
        if value in ("true", "True", "false", "False"):
            return value in ("true", "True")
        try:
            return bool(int(value))
        except ValueError:
            raise XacroError(f"the condition {text!r} is {value!r}, not a boolean") from None
    return bool(value)


class _Table(_Namespace):
    """Properties of one scope, evaluated when first read (xacro's lazy evaluation), with the enclosing scope as
    ``parent``; the outermost parent is the global symbols."""

    def __init__(self, expansion: XacroExpansion, parent: dict, namespace: bool = False):
        super().__init__()
        self.expansion, self.parent, self.namespace = expansion, parent, namespace
        self.unevaluated: set[str] = set()
        self.resolving: list[str] = []

    def __getitem__(self, key):
        if not dict.__contains__(self, key):
            return self.parent[key]
        if key in self.unevaluated:
            if key in self.resolving:
                raise XacroError(f"circular property definition {' -> '.join([*self.resolving, key])}")
            self.resolving.append(key)
            try:
                value = _literal(self.expansion._text(dict.__getitem__(self, key), self))
            finally:
                self.resolving.remove(key)
            dict.__setitem__(self, key, value)
            self.unevaluated.discard(key)
        return dict.__getitem__(self, key)

    def __contains__(self, key):
        return dict.__contains__(self, key) or key in self.parent

    def define(self, key: str, value: Any, lazy: bool) -> None:
        """Set a property (a string read lazily keeps its text until first read)."""
        value = _literal(value)
        dict.__setitem__(self, key, value)
        if lazy and isinstance(value, str):
            self.unevaluated.add(key)
        else:
            self.unevaluated.discard(key)

    def remove(self, key: str) -> None:
        """Remove a property from this scope and every enclosing one up to the globals."""
        table: Any = self
        while isinstance(table, _Table):
            dict.pop(table, key, None)
            table.unevaluated.discard(key)
            table = table.parent

    def top(self) -> _Table:
        """The file's outermost scope (``scope="global"``)."""
        table = self
        while isinstance(table.parent, _Table):
            table = table.parent
        return table


class _Macro:
    """A macro's body, parameters and defaults (``{name: (forwarded name or None, default text or None)}``)."""

    def __init__(self, body, params: list[str], defaults: dict[str, tuple[str | None, str | None]]):
        self.body, self.params, self.defaults = body, params, defaults


def _macro_params(text: str) -> tuple[list[str], dict[str, tuple[str | None, str | None]]]:
    """A ``params`` attribute's names and defaults, in order (``a b:=1 c:=^ d:=^|2 *origin **content``)."""
    params: list[str] = []
    defaults: dict[str, tuple[str | None, str | None]] = {}
    rest = text.strip()
    while rest:
        match = _PARAM.match(rest)
        if match is None or not match.group(0):
            raise XacroError(f"cannot read the macro parameters {text!r}")
        name, forward, default = match.groups()
        params.append(name)
        if default is not None or forward:
            defaults[name] = (name if forward else None, default or None)
        rest = rest[match.end():].strip()
    return params, defaults


def _taken(node) -> list:
    """``node``'s children, taken out of it (to be put elsewhere by :func:`_replace`)."""
    items = list(node.childNodes)
    node.childNodes[:] = []
    return items


def _replace(node, items=()) -> None:
    """Put ``items`` (nodes no other node holds) where ``node`` is, and take ``node`` out: one splice of the parent's
    children (minidom's ``insertBefore`` looks the place up again for every node it moves)."""
    parent = node.parentNode
    items = list(items)
    children = parent.childNodes
    at = children.index(node)
    children[at:at + 1] = items
    for item in items:
        item.parentNode = parent
    for k in range(max(at - 1, 0), min(at + len(items) + 1, len(children))):
        children[k].previousSibling = children[k - 1] if k > 0 else None
        children[k].nextSibling = children[k + 1] if k + 1 < len(children) else None
    node.parentNode = node.previousSibling = node.nextSibling = None


def _elements(node) -> list:
    return [c for c in node.childNodes if c.nodeType == xml.dom.Node.ELEMENT_NODE]


def _size(node) -> int:
    return 1 + sum(_size(c) for c in _elements(node))


def _attributes(node, required: tuple[str, ...], optional: tuple[str, ...] = ()) -> list:
    """Values of a xacro element's attributes (None where an optional one is absent); a missing or unknown one
    refuses the file."""
    names = set(node.attributes.keys())
    missing = [a for a in required if a not in names]
    unknown = names - set(required) - set(optional)
    if missing:
        raise XacroError(f"<{node.tagName}> needs the attribute {missing[0]!r}")
    if unknown:
        raise XacroError(f"<{node.tagName}> has an unknown attribute {sorted(unknown)[0]!r}")
    return [node.getAttribute(a) if a in names else None for a in (*required, *optional)]


class XacroExpansion:
    """One expansion of a xacro file: its arguments, the files it read, and the global symbols its expressions see.

    Parameters
    ----------
    arguments : dict of str to str, optional
        xacro arguments (``name:=value`` on xacro's command line), which ``<xacro:arg>`` defaults do not override (a
        number or a boolean is taken as its text, ``true``/``false``).
    """

    def __init__(self, arguments: dict | None = None):
        self.arguments = {str(k): _argument_text(v) for k, v in (arguments or {}).items()}
        self.files: list[str] = []
        self.read: list[str] = []
        self.found: list[Path] = []
        self.depth = 0
        self.made = 0
        self.symbols, self.allowed = self._globals()

    @property
    def here(self) -> str:
        """The file being expanded (an expression's message names it)."""
        return self.files[-1] if self.files else ""

    def _globals(self) -> tuple[dict, dict[int, str]]:
        """The names every expression sees (xacro 2.x's: a few built-ins directly, the ``python``, ``math`` and
        ``xacro`` namespaces, ``math``'s names directly), and the ``id`` of each callable among them."""
        python = _Namespace({n: getattr(builtins, n) for n in ALLOWED_BUILTINS} | {"True": True, "False": False})
        direct = ("list", "dict", "map", "len", "str", "float", "int", "bool", "True", "False", "min", "max", "round",
                  "sorted", "range")
        maths = _Namespace({k: v for k, v in vars(math).items() if not k.startswith("_")})
        helpers = _Namespace(load_yaml=self._load_yaml, abs_filename=self._beside, dotify=_YamlDict,
                             arg=lambda name: self.arguments[name], tokenize=_tokenize, fatal=self._fatal,
                             message=_quiet, warning=_quiet, error=_quiet, print_location=_quiet)
        symbols = {n: python[n] for n in direct} | dict(maths) | {"python": python, "math": maths, "xacro": helpers}
        symbols |= {k: helpers[k] for k in ("load_yaml", "abs_filename", "dotify")}
        functions = [*python.values(), *maths.values(), *helpers.values()]
        return symbols, {id(v): getattr(v, "__name__", "") for v in functions if callable(v)}

    @staticmethod
    def _fatal(*parts) -> None:
        raise XacroError(" ".join(map(str, parts)))

    def _beside(self, name: str) -> str:
        """A file name relative to the file being expanded (xacro's ``abs_filename``)."""
        return name if os.path.isabs(name) or not self.here else os.path.join(os.path.dirname(self.here), name)

    def _load_yaml(self, name: str):
        """A YAML file's data (``xacro.load_yaml``): ``yaml.safe_load`` with xacro's unit tags, mappings readable as
        attributes."""
        safe: Any = require("yaml", "xacro", "xacro.load_yaml in a xacro robot description").SafeLoader
        path = self._beside(str(name))
        where = self.here

        class Loader(safe):
            """safe_load's loader with the unit tags (a subclass: the shared SafeLoader stays as it was)."""

        for tag, factor in _UNITS.items():
            Loader.add_constructor(tag, lambda loader, node, f=factor: f * float(
                evaluate(loader.construct_scalar(node), self.symbols, self.allowed, where)))
        self.read.append(path)
        self._beside_description(path, "xacro.load_yaml")
        _regular(path, "xacro.load_yaml")
        with open(path, encoding="utf-8") as stream:
            loader = Loader(stream)  # safe_load's own steps, with the subclass: data only
            try:
                return _wrap(loader.get_single_data())
            finally:
                loader.dispose()

    def _beside_description(self, path: str, what: str) -> None:
        """Refuse a data file outside the description's folders: the top file's folder and its package (the nearest
        folder above it with a package.xml), and the packages ``$(find)`` found. A YAML file's values end up in the
        robot file and in messages: ``load_yaml('/etc/passwd')`` put that file into one."""
        top = Path(self.files[0]).resolve().parent if self.files else Path.cwd()
        package = next((f for f in (top, *top.parents) if (f / "package.xml").is_file()), top)
        target = Path(path).resolve()
        if not any(target.is_relative_to(root) for root in (top, package, *self.found)):
            raise XacroError(f"{what}: {path} is outside the robot description's folders ({package}, and the packages "
                             "$(find) names): dynid reads only files beside the description")

    def _parse(self, path: str):
        """A file's XML (minidom; expat resolves no external entity)."""
        _regular(path, "xacro")
        try:
            with open(path, "rb") as stream:
                return xml.dom.minidom.parse(stream)
        except OSError as exc:
            raise XacroError(f"cannot read {path} ({exc.strerror})") from None
        except expat.ExpatError as exc:
            raise XacroError(f"{path} is not XML ({exc})") from None

    def expand(self, path: str | Path):
        """The expanded document of a xacro file.

        Parameters
        ----------
        path : str or Path
            The xacro file; the files it includes and the YAML it loads are added to ``read``.

        Returns
        -------
        xml.dom.minidom.Document
            The URDF.

        Raises
        ------
        XacroError
            The file cannot be expanded (the reason, with the file that holds it where that is an included one).
        ConfigError
            An expression does what a robot description may not (:func:`~dynid.model.xacro_expressions.evaluate`).
        """
        path = str(path)
        self.files.append(path)
        self.read.append(path)
        doc = self._parse(path)
        root = doc.documentElement
        target = root.getAttribute("xacro:targetNamespace")
        if target:
            root.removeAttribute("xacro:targetNamespace")
            root.setAttribute("xmlns", target)
        self._count(root)
        self._evaluate_all(root, _Table(self, {}), _Table(self, self.symbols))
        return doc

    # -- text ------------------------------------------------------------------------------------------------------

    def _text(self, text: str, symbols) -> Any:
        """A text with its ``${...}`` and ``$(...)`` computed: a single expression's typed value, else a string."""
        tokens = _TOKENS.findall(text)
        if "".join(tokens) != text:  # a "$" the lexer cannot place (an unclosed "${")
            raise XacroError(f"cannot read {text!r}")
        parts: list[Any] = []
        for token in tokens:
            if token.startswith("$$"):
                parts.append(token[1:])
            elif token.startswith("${"):
                parts.append(self._expression(str(self._text(token[2:-1], symbols)), symbols))
            elif token.startswith("$("):
                parts.append(self._extension(str(self._text(token[2:-1], symbols))))
            else:
                parts.append(token)
        return parts[0] if len(parts) == 1 else "".join(map(str, parts))

    def _expression(self, text: str, symbols, allowed: dict[int, str] | None = None, what: str = "") -> Any:
        """One expression's value (dynid's interpreter), its errors said as the file's."""
        try:
            return evaluate(text, symbols, self.allowed if allowed is None else allowed, self.here)
        except (ConfigError, XacroError):
            raise
        except Exception as exc:
            raise XacroError(f"{exc} (in {what or 'the expression'} {' '.join(text.split())!r})") from None

    def _argument(self, name: str) -> str:
        """An argument's text (``$(arg name)``), refused in one line where neither the file nor the user gives it."""
        if name not in self.arguments:
            raise XacroError(f"the argument {name!r} is not defined (an <xacro:arg> or name:=value)")
        return self.arguments[name]

    def _extension(self, text: str) -> str:
        """A ``$(command ...)``: arg, eval, env, optenv, dirname, cwd, find (:meth:`find`)."""
        command, _, rest = text.strip().partition(" ")
        words = rest.split()
        if command == "eval":
            return str(self._eval(rest))
        if command == "arg" and len(words) == 1:
            return self._argument(words[0])
        if command == "env" and len(words) == 1:
            if words[0] not in os.environ:
                raise XacroError(f"the environment variable {words[0]} is not set")
            return os.environ[words[0]]
        if command == "optenv" and words:
            return os.environ.get(words[0], " ".join(words[1:]))
        if command == "dirname" and not words:
            return os.path.dirname(os.path.abspath(self.here))
        if command == "cwd" and not words:
            return os.getcwd()
        if command == "find" and len(words) == 1:
            return self.find(words[0])
        raise XacroError(f"cannot read the substitution $({text.strip()})")

    def find(self, package: str) -> str:
        """``$(find package)``: the package's folder (one holding a ``package.xml``), found without ROS among the
        folders around the top file (its ancestors and their subfolders: a cloned description package or workspace),
        then on ``ROS_PACKAGE_PATH`` and under ``AMENT_PREFIX_PATH``'s ``share`` folders.

        Parameters
        ----------
        package : str
            The ROS package's name.

        Returns
        -------
        str
            Its folder.

        Raises
        ------
        XacroError
            No such folder (the message says where dynid looked and what to set).
        """
        top = Path(self.files[0] if self.files else ".").resolve().parent
        around = [p for folder in (top, *top.parents) for p in (folder, folder / package, folder / "src" / package,
                                                                folder / "share" / package)]
        listed = [Path(p) for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
        listed = [p for root in listed for p in (root, root / package)]
        ament = [Path(p) / "share" / package for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
        for folder in (*around, *listed, *ament):
            if folder.name == package and (folder / "package.xml").is_file():
                self.found.append(folder.resolve())  # a package whose files the description may read
                return str(folder)
        raise XacroError(f"$(find {package}) names a ROS package dynid cannot find (no folder {package} with a "
                         "package.xml beside the file, on ROS_PACKAGE_PATH or AMENT_PREFIX_PATH): set "
                         "ROS_PACKAGE_PATH to the folder holding it, or write the path relative to the file")

    def _eval(self, text: str) -> Any:
        """``$(eval ...)``: the arguments by name (numbers and booleans typed), ``arg(name)``, ``dirname()``,
        ``env``/``optenv`` and ``math``'s names."""
        def typed(name: str) -> Any:
            value = self._argument(name)
            try:
                return float(value) if "." in value else int(value)
            except ValueError:
                return {"true": True, "false": False}.get(value.lower(), value)

        functions = {"arg": typed, "dirname": lambda: os.path.dirname(os.path.abspath(self.here)),
                     "env": lambda n: os.environ[n], "optenv": lambda n, d="": os.environ.get(n, d), "find": self.find,
                     "true": True, "false": False, "True": True, "False": False}
        functions |= {k: v for k, v in vars(math).items() if not k.startswith("_")}
        allowed = dict(self.allowed) | {id(v): k for k, v in functions.items() if callable(v)}
        names = _Namespace(functions | {k: typed(k) for k in self.arguments if k not in functions})
        return self._expression(text, names, allowed, "$(eval ...)")

    # -- elements --------------------------------------------------------------------------------------------------

    def _evaluate_all(self, node, macros: _Table, symbols: _Table) -> None:
        """Expand one element in place: its attributes' expressions, then its children (xacro's ``eval_all``)."""
        for name, value in list(node.attributes.items()):
            if name.startswith("xacro:"):
                node.removeAttribute(name)
            else:
                node.setAttribute(name, str(self._text(value, symbols)))
        if node.hasAttribute("xmlns:xacro"):
            node.removeAttribute("xmlns:xacro")
        child = node.firstChild
        while child is not None:
            after = child.nextSibling
            if child.nodeType == xml.dom.Node.ELEMENT_NODE:
                if child.tagName == "xacro:element":
                    name = str(self._text(_attributes(child, ("xacro:name",), _any(child))[0], symbols))
                    if not name:
                        raise XacroError("<xacro:element> has an empty name")
                    child.removeAttribute("xacro:name")
                    child.tagName = child.nodeName = name
                    continue  # the same element again, under its new name
                self._element(child, macros, symbols)
            elif child.nodeType == xml.dom.Node.TEXT_NODE:
                child.data = str(self._text(child.data, symbols))
            child = after

    def _element(self, node, macros: _Table, symbols: _Table) -> None:
        """One child element: a xacro directive, a macro call, or a plain element expanded in turn."""
        tag = node.tagName
        handlers = {"xacro:insert_block": self._insert_block, "xacro:include": self._include,
                    "xacro:property": self._property, "xacro:macro": self._macro, "xacro:arg": self._arg,
                    "xacro:attribute": self._attribute, "xacro:if": self._conditional,
                    "xacro:unless": self._conditional, "xacro:call": self._call}
        if tag in handlers:
            handlers[tag](node, macros, symbols)
        elif tag.startswith("xacro:"):
            self._expand_macro(node, tag[len("xacro:"):], macros, symbols)
        else:
            self._evaluate_all(node, macros, symbols)

    def _insert_block(self, node, macros: _Table, symbols: _Table) -> None:
        (name,) = _attributes(node, ("name",))
        for key, content_only in ((f"**{name}", True), (f"*{name}", False)):
            if key in symbols:
                block = self._clone(symbols[key])
                self._evaluate_all(block, macros, symbols)
                _replace(node, _taken(block) if content_only else [block])
                return
        raise XacroError(f"<xacro:insert_block name={name!r}>: no such block")

    def _count(self, node) -> None:
        """Count the elements an expansion makes, and refuse past :data:`MAX_ELEMENTS`."""
        self.made += _size(node)
        if self.made > MAX_ELEMENTS:
            raise XacroError(f"the expansion makes more than {MAX_ELEMENTS:,} elements (a macro that multiplies "
                             "itself?)")

    def _clone(self, node):
        self._count(node)
        return node.cloneNode(True)

    def _include(self, node, macros: _Table, symbols: _Table) -> None:
        spec, namespace, optional = _attributes(node, ("filename",), ("ns", "optional"))
        if namespace:
            name = str(self._text(namespace, symbols))
            macros.define(name, _Table(self, macros, namespace=True), lazy=False)
            symbols.define(name, _Table(self, symbols, namespace=True), lazy=False)
            macros, symbols = dict.__getitem__(macros, name), dict.__getitem__(symbols, name)
        pattern = self._beside(str(self._text(spec, symbols)))
        names = sorted(glob.glob(pattern)) if re.search(r"[*?\[]", pattern) else [pattern]
        skip_missing = bool(optional) and _boolean(self._text(optional, symbols), optional)
        included: list = []
        for name in names:
            if skip_missing and not os.path.isfile(name):
                continue
            with self._deeper(name):
                self.read.append(name)
                root = self._parse(name).documentElement
                self._count(root)
                self._evaluate_all(root, macros, symbols)
            _lift_namespaces(root, node.parentNode)
            included += _taken(root)
        _replace(node, included)

    @contextlib.contextmanager
    def _deeper(self, name: str | None = None):
        """One level deeper: a macro's body, or an included file (the file an error names while inside it)."""
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise XacroError(f"macro calls or includes nested deeper than {MAX_DEPTH} (one that calls itself?)")
        if name is not None:
            self.files.append(name)
        yield
        self.depth -= 1
        if name is not None:
            self.files.pop()

    def _property(self, node, macros: _Table, symbols: _Table) -> None:
        name, value, default, remove, scope, lazy = _attributes(
            node, ("name",), ("value", "default", "remove", "scope", "lazy_eval"))
        name = str(self._text(name, symbols))
        if not name.isidentifier() or name.startswith("__"):
            raise XacroError(f"the property name {name!r} is not a name (letters, digits, _; not starting with __)")
        removing = _boolean(self._text(remove or "false", symbols), remove or "false")
        if sum([value is not None, default is not None, removing]) > 1:
            raise XacroError(f"the property {name!r} has more than one of value, default and remove")
        _replace(node)
        if removing:
            symbols.remove(name)
            return
        if default is not None:
            if name in symbols:
                return
            value = default
        content: Any = value
        if value is None:  # a block property: its children
            name, content = f"**{name}", node
        lazy_eval = _boolean(self._text(lazy or "true", symbols), lazy or "true")
        target: Any = symbols
        if scope == "global":
            target, lazy_eval = symbols.top(), False
        elif scope == "parent":
            target, lazy_eval = symbols.parent, False
            if not symbols.namespace:
                while isinstance(target, _Table) and target.namespace:
                    target = target.parent
            if not isinstance(target, _Table):
                return
        if not lazy_eval and isinstance(content, str):
            content = self._text(content, symbols)
        target.define(name, content, lazy=lazy_eval)

    def _macro(self, node, macros: _Table, symbols: _Table) -> None:
        name, params = _attributes(node, ("name",), ("params",))
        name = name.removeprefix("xacro:")
        if name == "call" or "." in name or not name:
            raise XacroError(f"{name!r} cannot name a macro (call is taken; . separates namespaces)")
        macros.define(name, _Macro(node, *_macro_params(params or "")), lazy=False)
        _replace(node)

    def _arg(self, node, macros: _Table, symbols: _Table) -> None:
        name, default = _attributes(node, ("name",), ("default",))
        if name not in self.arguments and default is not None:
            self.arguments[name] = str(self._text(default, symbols))
        _replace(node)

    def _attribute(self, node, macros: _Table, symbols: _Table) -> None:
        name, value = (str(self._text(a, symbols)) for a in _attributes(node, ("name", "value")))
        if not name:
            raise XacroError("<xacro:attribute> has an empty name")
        node.parentNode.setAttribute(name, value)
        _replace(node)

    def _conditional(self, node, macros: _Table, symbols: _Table) -> None:
        (condition,) = _attributes(node, ("value",))
        keep = _boolean(self._text(condition, symbols), condition) != (node.tagName == "xacro:unless")
        if keep:
            self._evaluate_all(node, macros, symbols)
        _replace(node, _taken(node) if keep else ())

    def _call(self, node, macros: _Table, symbols: _Table) -> None:
        name = node.getAttribute("macro")
        if not name:
            raise XacroError("<xacro:call> needs the attribute 'macro'")
        node.removeAttribute("macro")
        self._expand_macro(node, str(self._text(name, symbols)), macros, symbols)

    def _lookup(self, name: str, macros: _Table, symbols: _Table) -> tuple[_Macro, Any]:
        """A macro by name (``ns.name`` through namespaces) and the symbols its body sees."""
        if name in macros and isinstance(macros[name], _Macro):
            return macros[name], symbols
        *spaces, last = name.split(".")
        try:
            for space in spaces:
                macros, symbols = macros[space], symbols[space]
            macro = macros[last]
        except (KeyError, TypeError):
            raise XacroError(f"no macro named {name!r}") from None
        if not isinstance(macro, _Macro):
            raise XacroError(f"no macro named {name!r}")
        return macro, symbols

    def _expand_macro(self, node, name: str, macros: _Table, symbols: _Table) -> None:
        """A macro call: its attributes and blocks bound in a new scope, its body expanded there, put in its place."""
        macro, seen = self._lookup(name, macros, symbols)
        scope, local = _Table(self, seen), _Table(self, macros)
        params = list(macro.params)
        for attr, value in list(node.attributes.items()):
            if attr not in params:
                raise XacroError(f"the macro {name!r} has no parameter {attr!r}")
            params.remove(attr)
            scope.define(attr, self._text(value, symbols), lazy=False)
            node.removeAttribute(attr)
        self._evaluate_all(node, macros, symbols)  # the blocks, in the caller's scope
        blocks = _elements(node)
        for param in [p for p in params if p.startswith("*")]:
            if not blocks:
                raise XacroError(f"the macro {name!r} needs a block for {param!r}")
            scope.define(param, blocks.pop(0), lazy=False)
            params.remove(param)
        if blocks:
            raise XacroError(f"the macro {name!r} got a block <{blocks[0].tagName}> it has no parameter for")
        for param in list(params):
            forward, default = macro.defaults.get(param, (None, None))
            if forward is not None and forward in symbols:
                scope.define(param, symbols[forward], lazy=False)
            elif default is not None:
                scope.define(param, self._text(default, symbols), lazy=False)
            elif forward is not None:
                raise XacroError(f"the macro {name!r} forwards {forward!r}, which is not defined")
            else:
                continue
            params.remove(param)
        if params:
            raise XacroError(f"the macro {name!r} needs the parameters {', '.join(params)}")
        body = self._clone(macro.body)
        with self._deeper():
            self._evaluate_all(body, local, scope)
        _lift_namespaces(body, node.parentNode)
        _replace(node, _taken(body))


def _lift_namespaces(source, target) -> None:
    """The ``xmlns:`` declarations of an expanded body or included file, onto the element that takes its content."""
    for attr, value in source.attributes.items():
        if attr.startswith("xmlns:") and not target.hasAttribute(attr):
            target.setAttribute(attr, value)


def _argument_text(value: Any) -> str:
    """An argument as xacro's command line gives it: text (a TOML boolean as ``true``/``false``)."""
    return ("true" if value else "false") if isinstance(value, bool) else str(value)


def _any(node) -> tuple[str, ...]:
    """Every attribute of an element but ``xacro:name`` (``<xacro:element>`` keeps the others)."""
    return tuple(a for a in node.attributes.keys() if a != "xacro:name")


def _quiet(*args, **kwargs) -> str:
    """xacro's message helpers (``xacro.message``, ``xacro.warning``...): nothing printed, an empty string."""
    return ""


def _tokenize(text: str, sep: str = ",; ", skip_empty: bool = True) -> list[str]:
    """xacro's ``xacro.tokenize``: a string split at any of ``sep``'s characters."""
    parts = re.split(f"[{re.escape(sep)}]", text)
    return [p for p in parts if p] if skip_empty else parts


def expand_xacro_text(path: str | Path, arguments: dict | None = None) -> tuple[str, list[str]]:
    """The URDF text a xacro file expands to, and every file the expansion read (the file, includes, YAML).

    Parameters
    ----------
    path : str or Path
        The xacro file.
    arguments : dict of str to str, optional
        xacro arguments (``name:=value``).

    Returns
    -------
    urdf : str
    read : list of str

    Raises
    ------
    ConfigError
        The file cannot be expanded or does what a robot description may not: one line naming the file.
    """
    expansion = XacroExpansion(arguments)
    try:
        doc = expansion.expand(path)
    except XacroError as exc:
        inner = f" (in {expansion.here})" if expansion.here and expansion.here != str(path) else ""
        raise ConfigError(f"{path}: xacro cannot expand it: {' '.join(str(exc).split())}{inner}") from None
    except RecursionError:
        raise ConfigError(f"{path}: xacro cannot expand it: it nests too deep") from None
    return doc.toprettyxml(indent="  "), expansion.read
