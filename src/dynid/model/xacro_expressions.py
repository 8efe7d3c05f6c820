"""xacro's expressions evaluated by dynid's own interpreter: a robot description computes, it never runs code.

xacro 2.x evaluates ``${...}`` and ``$(eval ...)`` with Python's ``eval``, behind a guard that only refuses names starting
with two underscores; its ``python`` namespace holds ``type`` and ``vars``, so a hostile description can reach any
object by subscripts with strings (``python['vars'](...)['__subclasses__']``) and run programs. dynid expands xacro files
itself (:mod:`dynid.model.xacro_expansion`), and every expression goes to :func:`evaluate`, an interpreter of a small
part of Python's syntax tree (:mod:`ast`) that admits

- literals (numbers, strings, booleans, ``None``), lists, tuples, dicts and sets of them;
- the file's properties and arguments by name, and a namespace's or a YAML mapping's members (``math.pi``,
  ``props.link1.mass``, ``props['link1']['mass']``);
- arithmetic, comparisons, ``and``/``or``/``not``, conditional expressions, subscripts and slices, comprehensions;
- calls of an allow-list of functions (:data:`ALLOWED_BUILTINS`, the ``math`` module, xacro's ``xacro.*`` helpers,
  ``arg``/``dirname``/``env``/``optenv`` inside ``$(eval ...)``) and of a few string and dict methods
  (:data:`ALLOWED_METHODS`).

Everything else (a lambda, an assignment expression, a name or member starting with an underscore, an attribute of any
other object, a call of anything outside the allow-list, an integer power or a repetition that would fill the memory)
refuses the file in one line naming the expression. That is what xacro files of robot arms use (``${pi/2}``,
``${radians(90)}``, ``${d1 + 0.1}``, ``${props['link1']['mass']}``, ``$(eval arg('prefix') + 'base')``). A YAML file
loaded with ``xacro.load_yaml`` is read by ``yaml.safe_load`` (data only), and its ``!degrees`` values go through
:func:`evaluate` too. Reference: the Python language reference's expression grammar; xacro 2.x's ``safe_eval``.
"""

from __future__ import annotations

import ast
import operator
import re
from collections.abc import Callable, Mapping
from typing import Any

from ..exceptions import ConfigError

__all__ = ["ALLOWED_BUILTINS", "ALLOWED_METHODS", "evaluate"]

ALLOWED_BUILTINS = ("abs", "all", "any", "bool", "complex", "dict", "divmod", "enumerate", "filter", "float",
                    "frozenset", "int", "isinstance", "len", "list", "map", "max", "min", "ord", "range", "repr",
                    "reversed", "round", "set", "sorted", "str", "sum", "tuple", "zip")
"""Python's built-in functions an expression may call (xacro's ``python`` namespace less ``type``, ``vars``,
``hash``, ``issubclass`` and ``slice``)."""

ALLOWED_METHODS = {
    str: frozenset({"lower", "upper", "strip", "lstrip", "rstrip", "split", "rsplit", "replace", "startswith",
                    "endswith", "join", "find", "count", "capitalize", "title", "zfill", "isdigit"}),
    dict: frozenset({"get", "keys", "values", "items"}),
    list: frozenset({"index", "count"}),
    tuple: frozenset({"index", "count"}),
}
"""Methods an expression may call on a value of each type (never ``format``, which reaches attributes itself)."""

_LARGEST = 10_000_000  # elements or characters one operation may make, and the largest integer power's bits
_STEPS = 1_000_000  # the steps of an expression's comprehensions, all loops counted (a few seconds of this interpreter)
_BINARY: dict[type, Callable[[Any, Any], Any]] = {
    ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
    ast.FloorDiv: operator.floordiv, ast.Mod: operator.mod, ast.Pow: operator.pow, ast.BitAnd: operator.and_,
    ast.BitOr: operator.or_, ast.BitXor: operator.xor, ast.LShift: operator.lshift, ast.RShift: operator.rshift,
}
_UNARY: dict[type, Callable[[Any], Any]] = {ast.UAdd: operator.pos, ast.USub: operator.neg, ast.Not: operator.not_,
                                           ast.Invert: operator.invert}
_COMPARE: dict[type, Callable[[Any, Any], Any]] = {
    ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt,
    ast.GtE: operator.ge, ast.In: lambda a, b: a in b, ast.NotIn: lambda a, b: a not in b,
    ast.Is: operator.is_, ast.IsNot: operator.is_not,
}


class _Refused(Exception):
    """What an expression may not do, said by the caller with the expression and the file."""


class _Interpreter:
    """One expression's evaluation: names from ``symbols`` (a xacro table or ``$(eval)``'s argument wrapper),
    calls only of ``allowed`` (by identity) and of :data:`ALLOWED_METHODS`."""

    def __init__(self, symbols, allowed: Mapping[int, str]):
        self.symbols, self.allowed = symbols, allowed
        self.scopes: list[dict[str, Any]] = []
        self.steps = 0

    def value(self, v: Any) -> Any:
        """Every value an expression makes passes here: a callable outside the allow-list is refused at once, so it
        can be neither called nor handed to an allowed function (``map(python.vars, ...)``)."""
        if callable(v) and id(v) not in self.allowed and not self._allowed_method(v):
            raise _Refused(f"{getattr(v, '__name__', type(v).__name__)!r}, a function outside the allow-list")
        return v

    @staticmethod
    def _allowed_method(v: Any) -> bool:
        owner = getattr(v, "__self__", None)
        names = next((m for t, m in ALLOWED_METHODS.items() if isinstance(owner, t)), frozenset())
        return type(v).__name__ == "builtin_function_or_method" and getattr(v, "__name__", "") in names

    def run(self, node: ast.AST) -> Any:
        method = getattr(self, f"_{type(node).__name__}", None)
        if method is None:
            raise _Refused(f"a {type(node).__name__.lower()}")
        return self.value(method(node))

    def _Expression(self, node: ast.Expression) -> Any:
        return self.run(node.body)

    def _Constant(self, node: ast.Constant) -> Any:
        if not isinstance(node.value, (int, float, complex, str, bool, type(None))):
            raise _Refused(f"the constant {node.value!r}")
        return node.value

    def _Name(self, node: ast.Name) -> Any:
        if node.id.startswith("_"):
            raise _Refused(f"{node.id!r}")
        for scope in reversed(self.scopes):
            if node.id in scope:
                return scope[node.id]
        try:
            return self.symbols[node.id]
        except KeyError:
            raise NameError(f"name '{node.id}' is not defined") from None

    def _Attribute(self, node: ast.Attribute) -> Any:
        if node.attr.startswith("_"):
            raise _Refused(f"{node.attr!r}")
        owner = self.run(node.value)
        if isinstance(owner, dict) and type(owner) is not dict:  # xacro's namespaces, tables and YAML mappings
            try:
                return owner[node.attr]
            except KeyError:
                raise AttributeError(f"no member {node.attr!r}") from None
        method = getattr(owner, node.attr, None)
        if method is None or not self._allowed_method(method):
            raise _Refused(f"the attribute {node.attr!r} of a {type(owner).__name__}")
        return method

    def _Subscript(self, node: ast.Subscript) -> Any:
        owner, key = self.run(node.value), self.run(node.slice)
        if not isinstance(owner, (dict, list, tuple, str)):
            raise _Refused(f"a subscript of a {type(owner).__name__}")
        if isinstance(key, str) and key.startswith("_"):
            raise _Refused(f"the key {key!r}")
        return owner[key]

    def _Slice(self, node: ast.Slice) -> slice:
        return slice(*(None if part is None else self.run(part) for part in (node.lower, node.upper, node.step)))

    def _Tuple(self, node: ast.Tuple) -> tuple:
        return tuple(self._elements(node.elts))

    def _List(self, node: ast.List) -> list:
        return self._elements(node.elts)

    def _Set(self, node: ast.Set) -> set:
        return set(self._elements(node.elts))

    def _Dict(self, node: ast.Dict) -> dict:
        if any(k is None for k in node.keys):
            raise _Refused("a ** in a dict")
        return {self.run(k): self.run(v) for k, v in zip(node.keys, node.values)}  # type: ignore[arg-type]

    def _elements(self, nodes: list[ast.expr]) -> list:
        out: list = []
        for e in nodes:
            if isinstance(e, ast.Starred):
                out.extend(self._bounded(list(self.run(e.value))))
            else:
                out.append(self.run(e))
        return out

    @staticmethod
    def _bounded(v: Any) -> Any:
        if isinstance(v, (str, list, tuple, set, dict, range)) and len(v) > _LARGEST:
            raise _Refused(f"a value of {len(v)} elements")
        return v

    def _BinOp(self, node: ast.BinOp) -> Any:
        left, right = self.run(node.left), self.run(node.right)
        op = type(node.op)
        if op not in _BINARY:
            raise _Refused(f"the operator {op.__name__}")
        if op is ast.Pow and isinstance(left, int) and isinstance(right, int) and abs(left) > 1 and \
                abs(right) * abs(left).bit_length() > _LARGEST:  # the result's bits, whatever the exponent
            raise _Refused(f"the power {_digits(left)}**{_digits(right)}")
        if op is ast.LShift and isinstance(right, int) and right > _LARGEST:
            raise _Refused(f"the shift by {right}")
        if op is ast.Mult:
            for seq, n in ((left, right), (right, left)):
                if isinstance(seq, (str, list, tuple)) and isinstance(n, int) and len(seq) * n > _LARGEST:
                    raise _Refused(f"a repetition of {len(seq) * n} elements")
        if op is ast.Mod and isinstance(left, str):  # printf-style widths and precisions allocate before any check
            for width in re.findall(r"%[-#0 +]*(\d*)(?:\.(\d*))?", left):
                if any(w and int(w) > _LARGEST for w in width):
                    raise _Refused(f"a format width of {max(int(w) for w in width if w)} characters")
        return self._bounded(_BINARY[op](left, right))  # a sum of strings doubling itself stops at the bound

    def _UnaryOp(self, node: ast.UnaryOp) -> Any:
        return _UNARY[type(node.op)](self.run(node.operand))

    def _BoolOp(self, node: ast.BoolOp) -> Any:
        result: Any = None
        for v in node.values:
            result = self.run(v)
            if bool(result) is isinstance(node.op, ast.Or):
                return result
        return result

    def _Compare(self, node: ast.Compare) -> bool:
        left = self.run(node.left)
        for op, right_node in zip(node.ops, node.comparators):
            right = self.run(right_node)
            if not _COMPARE[type(op)](left, right):
                return False
            left = right
        return True

    def _IfExp(self, node: ast.IfExp) -> Any:
        return self.run(node.body) if self.run(node.test) else self.run(node.orelse)

    def _Call(self, node: ast.Call) -> Any:
        function = self.run(node.func)
        args = self._elements(node.args)
        kwargs: dict[str, Any] = {}
        for k in node.keywords:
            if k.arg is None:
                raise _Refused("a ** in a call")
            kwargs[k.arg] = self.run(k.value)
        if function is range:
            span = range(*args)
            self._bounded(span)
            return span
        result = function(*args, **kwargs)
        if function in (map, filter, zip, enumerate, reversed):  # lazy: made here, so a size limit holds
            result = self._bounded(list(result))
        return self._bounded(result)

    def _JoinedStr(self, node: ast.JoinedStr) -> str:
        parts = []
        for v in node.values:
            if isinstance(v, ast.FormattedValue):
                if v.format_spec is not None or v.conversion not in (-1, 115):  # plain {x} or {x!s} only
                    raise _Refused("a formatted value with a format specification")
                parts.append(str(self.run(v.value)))
            else:
                parts.append(str(self.run(v)))
        return self._bounded("".join(parts))

    def _comprehension(self, generators: list[ast.comprehension], emit: Callable[[], None]) -> None:
        first, rest = generators[0], generators[1:]
        if first.is_async:
            raise _Refused("an async comprehension")
        for item in self._bounded(list(self.run(first.iter))):
            self.steps += 1
            if self.steps > _STEPS:  # nested loops multiply: each is bounded, their product is not
                raise _Refused(f"a comprehension of more than {_STEPS:,} steps")
            self._bind(first.target, item)
            if not all(self.run(cond) for cond in first.ifs):
                continue
            if rest:
                self._comprehension(rest, emit)
            else:
                emit()

    def _bind(self, target: ast.expr, item: Any) -> None:
        if isinstance(target, ast.Name) and not target.id.startswith("_"):
            self.scopes[-1][target.id] = item
        elif isinstance(target, ast.Tuple):
            items = list(item)
            if len(items) != len(target.elts):
                raise ValueError(f"cannot unpack {len(items)} values into {len(target.elts)}")
            for t, v in zip(target.elts, items):
                self._bind(t, v)
        else:
            raise _Refused(f"a comprehension target {type(target).__name__}")

    def _collect(self, node: ast.ListComp | ast.SetComp | ast.GeneratorExp | ast.DictComp) -> list:
        out: list = []
        self.scopes.append({})
        try:
            if isinstance(node, ast.DictComp):
                self._comprehension(node.generators, lambda: out.append((self.run(node.key), self.run(node.value))))
            else:
                self._comprehension(node.generators, lambda: out.append(self.run(node.elt)))
        finally:
            self.scopes.pop()
        return self._bounded(out)

    def _ListComp(self, node: ast.ListComp) -> list:
        return self._collect(node)

    def _GeneratorExp(self, node: ast.GeneratorExp) -> list:
        return self._collect(node)

    def _SetComp(self, node: ast.SetComp) -> set:
        return set(self._collect(node))

    def _DictComp(self, node: ast.DictComp) -> dict:
        return dict(self._collect(node))


def _digits(n: int) -> str:
    """An integer for a message: its digits, or how many it has."""
    return str(n) if n.bit_length() < 64 else f"<an integer of {n.bit_length()} bits>"


def _short(text: str) -> str:
    short = " ".join(str(text).split())
    return short if len(short) <= 60 else short[:57] + "..."


def evaluate(text: str, symbols, allowed: Mapping[int, str], where: str = "") -> Any:
    """The value of one xacro expression, computed without ``eval`` (module docstring).

    Parameters
    ----------
    text : str
        The expression (the inside of ``${...}`` or ``$(eval ...)``).
    symbols : mapping
        Names to values: a xacro property table (lazy properties are evaluated by xacro through this function), or
        ``$(eval ...)``'s arguments and functions.
    allowed : mapping of int to str
        The ``id`` of each function an expression may call, to its name (:class:`dynid.model.xacro_expansion.XacroExpansion` builds it).
    where : str
        The file being expanded, for the message.

    Returns
    -------
    object
        The expression's value.

    Raises
    ------
    ConfigError
        The expression does what a robot description may not (one line naming it and the file).
    SyntaxError, NameError, KeyError, ValueError, TypeError, ArithmeticError
        As Python would for the same expression; xacro wraps them in its own message.
    """
    tree = ast.parse(str(text).strip(), mode="eval")
    try:
        return _Interpreter(symbols, allowed).run(tree)
    except _Refused as exc:
        raise ConfigError(f"{where + ': ' if where else ''}the xacro expression {_short(text)!r} uses {exc}, which a "
                          "robot description may not run in dynid (it reads descriptions as data: arithmetic, math "
                          "functions and the file's own properties only; docs/security.md)") from None
