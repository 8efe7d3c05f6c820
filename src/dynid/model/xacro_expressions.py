"""The expressions of a xacro file checked before xacro evaluates them: a robot description computes, it never runs code.

xacro evaluates ``${...}`` and ``$(eval ...)`` with Python's ``eval``. Its own guard refuses names that start with two
underscores, but ``${...}`` still reaches ``type``, ``vars`` and generator frames, and ``$(eval ...)`` all of Python's
builtins (``open``, ``exec``), so a hostile description could write files or run programs when dynid reads it. Every
expression is therefore parsed first (:mod:`ast`) and evaluated only if it is plain arithmetic: literals, names,
operators, comparisons, conditionals, calls, subscripts, comprehensions and attributes, with no name or attribute that
starts with an underscore, no introspection or file name (:data:`REFUSED_NAMES`) and no frame, code or traceback
attribute (``gi_frame``, ``f_globals``, ``tb_frame``...). That is what xacro files of robot arms use (``${pi/2}``,
``${radians(90)}``, ``${d1 + 0.1}``, ``${props['link1']['mass']}``, ``$(eval arg('prefix') + 'base')``).
"""

from __future__ import annotations

import ast
import contextlib
import re

from ..exceptions import ConfigError

__all__ = ["REFUSED_NAMES", "check_expression", "guarded_xacro"]

REFUSED_NAMES = frozenset({
    "type", "vars", "mro", "dir", "getattr", "setattr", "delattr", "hasattr", "globals", "locals", "eval", "exec",
    "compile", "open", "input", "breakpoint", "help", "memoryview", "object", "super", "classmethod", "staticmethod",
    "property", "exit", "quit", "format", "format_map", "load_yaml", "abs_filename", "subclasses", "builtins", "os",
    "sys", "subprocess", "importlib", "system", "popen",
})
"""Names and attributes an expression of a robot description may not use: introspection, evaluation, files."""

_FRAME_ATTRIBUTE = re.compile(r"^(gi|cr|ag|f|tb|co)_")
_ALLOWED = (ast.Expression, ast.Constant, ast.Name, ast.Load, ast.Store, ast.Attribute, ast.Subscript, ast.Slice,
            ast.Tuple, ast.List, ast.Dict, ast.Set, ast.BinOp, ast.UnaryOp, ast.BoolOp, ast.Compare, ast.IfExp,
            ast.Call, ast.keyword, ast.Starred, ast.JoinedStr, ast.FormattedValue, ast.ListComp, ast.SetComp,
            ast.DictComp, ast.GeneratorExp, ast.comprehension, ast.operator, ast.unaryop, ast.boolop, ast.cmpop)


def check_expression(text: str, where: str = "") -> None:
    """Refuse an expression a robot description may not evaluate (module docstring).

    Parameters
    ----------
    text : str
        The expression, as xacro is about to evaluate it.
    where : str
        Where it comes from (the file), for the message.

    Raises
    ------
    ConfigError
        A name, attribute or construct outside plain arithmetic; one line naming it and the expression.
    """
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError:
        return  # xacro's own compile says what is wrong with it
    for node in ast.walk(tree):
        name = node.id if isinstance(node, ast.Name) else node.attr if isinstance(node, ast.Attribute) else None
        if not isinstance(node, _ALLOWED):
            reason = f"a {type(node).__name__.lower()}"
        elif name is not None and (name.startswith("_") or name in REFUSED_NAMES or _FRAME_ATTRIBUTE.match(name)):
            reason = f"{name!r}"
        else:
            continue
        short = " ".join(text.split())
        short = short if len(short) <= 60 else short[:57] + "..."
        raise ConfigError(f"{where + ': ' if where else ''}the xacro expression {short!r} uses {reason}, which a robot "
                          "description may not run in dynid (it reads descriptions as data: arithmetic, math functions "
                          "and the file's own properties only)")


@contextlib.contextmanager
def guarded_xacro(xacro, where: str = ""):
    """xacro's two evaluators, ``${...}`` and ``$(eval ...)``, with :func:`check_expression` in front, while the
    context lasts.

    Parameters
    ----------
    xacro : module
        The imported ``xacro`` package.
    where : str
        The file being expanded, for the messages.

    Yields
    ------
    list of ConfigError
        The refusals raised inside xacro (which wraps them in its own exceptions): the caller raises the first.
    """
    from xacro import substitution_args

    safe_eval, eval_arg = xacro.safe_eval, substitution_args._eval
    refused: list[ConfigError] = []

    def checked(text: str) -> None:
        try:
            check_expression(text, where)
        except ConfigError as exc:
            refused.append(exc)
            raise

    def checked_safe_eval(expr, *args, **kwargs):
        checked(expr)
        return safe_eval(expr, *args, **kwargs)

    def checked_eval(s, context):
        checked(s)
        return eval_arg(s, context)

    xacro.safe_eval, substitution_args._eval = checked_safe_eval, checked_eval
    try:
        yield refused
    finally:
        xacro.safe_eval, substitution_args._eval = safe_eval, eval_arg
