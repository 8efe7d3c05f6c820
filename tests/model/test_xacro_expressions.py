"""dynid's interpreter of xacro expressions (:func:`dynid.model.xacro_expressions.evaluate`), form by form: what a
robot description computes gives Python's own value, and what would reach code is refused in one line."""

import math

import pytest

from dynid.exceptions import ConfigError
from dynid.model.xacro_expressions import evaluate

FUNCTIONS = {"len": len, "sorted": sorted, "range": range, "zip": zip, "str": str, "radians": math.radians}
SYMBOLS = {"d1": 0.5, "links": ["base", "upper", "fore"], "props": {"m": 2.0, "name": "arm"}, "n": 3, **FUNCTIONS,
           "open": open}  # a function the file's namespace holds but the allow-list does not
ALLOWED = {id(f): name for name, f in FUNCTIONS.items()}


@pytest.mark.parametrize("text, expected", [
    ("-d1 + +n", -0.5 + 3),
    ("not n", False),
    ("~n", -4),
    ("(d1, n)", (0.5, 3)),
    ("{n, n, 1}", {3, 1}),
    ("{'a': n, 'b': d1}", {"a": 3, "b": 0.5}),
    ("links[1:]", ["upper", "fore"]),
    ("links[::-1][0]", "fore"),
    ("[*links, 'tool']", ["base", "upper", "fore", "tool"]),
    ("f'{props[\"name\"]}_{n}'", "arm_3"),
    ("f'{n!s}'", "3"),
    ("{i: 2 * i for i in range(n)}", {0: 0, 1: 2, 2: 4}),
    ("{x for x in links if len(x) > 4}", {"upper"}),
    ("sorted(a + str(b) for a, b in zip(links, range(n)))", ["base0", "fore2", "upper1"]),
    ("1 < n <= 3 != 4", True),
    ("[a + b for a in links for b in links if a < b]", ["baseupper", "basefore", "foreupper"]),
    ("sorted(links, reverse=True)", ["upper", "fore", "base"]),
    ("n > 5 or d1", 0.5),
    ("radians(180) if props.get('m') else 0", math.pi),
    ("'A_b'.lower().split('_')", ["a", "b"]),
])
def test_a_descriptions_expression_has_pythons_value(text, expected):
    value = evaluate(text, SYMBOLS, ALLOWED, "arm.urdf.xacro")
    assert value == expected and type(value) is type(expected)


@pytest.mark.parametrize("text, said", [
    ("f'{d1:.3}'", "a formatted value with a format specification"),
    ("f'{links!r}'", "a formatted value with a format specification"),
    ("{**props}", "a ** in a dict"),
    ("str(**props)", "a ** in a call"),
    ("[x for x.attr in links]", "a comprehension target Attribute"),
    ("[x for _x in links]", "a comprehension target Name"),
    ("(lambda: 1)()", "a lambda"),
    ("open('/etc/passwd')", "'open', a function outside the allow-list"),
    ("len(open)", "'open', a function outside the allow-list"),
    ("b'x'", "the constant b'x'"),
    ("_private", "'_private'"),
    ("n[0]", "a subscript of a int"),
    ("n @ n", "the operator MatMult"),
    ("[x async for x in links]", "an async comprehension"),
    ("links.__class__", "'__class__'"),
    ("props['__class__']", "the key '__class__'"),
    ("'{0.__class__}'.format(n)", "the attribute 'format' of a str"),
    ("links[0:1].copy", "the attribute 'copy' of a list"),
    ("[0] * 10 ** 8", "a repetition of 100000000 elements"),
    ("2 ** 10 ** 8", "the power 2**100000000"),
    ("1 << 10 ** 8", "the shift by 100000000"),
    ("[*range(10 ** 8)]", "a value of 100000000 elements"),
])
def test_what_would_reach_code_or_fill_the_memory_is_refused_in_one_line(text, said):
    with pytest.raises(ConfigError) as refused:
        evaluate(text, SYMBOLS, ALLOWED, "arm.urdf.xacro")
    message = str(refused.value)
    assert message.startswith("arm.urdf.xacro: the xacro expression ") and f"uses {said}," in message
    assert "\n" not in message


def test_a_name_the_file_does_not_define_and_a_bad_unpacking_are_pythons_errors():
    """xacro wraps them in its own message, as it does Python's."""
    with pytest.raises(NameError, match="name 'd9' is not defined"):
        evaluate("d9 + 1", SYMBOLS, ALLOWED)
    with pytest.raises(ValueError, match="cannot unpack 3 values into 2"):
        evaluate("[a for a, b in [links]]", SYMBOLS, ALLOWED)
