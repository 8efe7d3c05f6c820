"""Every public function, class and method of dynid has a numpydoc docstring, checked by numpydoc's own validation:
a summary, every parameter documented under its name (dataclasses and typed config tables: every field under
"Attributes"), and what it returns or yields. Public: defined in a module of the package whose path has no part
starting with "_", under a name without a leading "_" (methods: of such classes, defined in them)."""

import dataclasses
import importlib
import inspect
import pkgutil

import pytest

import dynid

numpydoc_validate = pytest.importorskip("numpydoc.validate")

CHECKS = {"GL08", "SS01", "PR01", "PR02", "RT01", "YD01"}
"""GL08 no docstring; SS01 no summary; PR01 a parameter not documented; PR02 a documented one that does not exist;
RT01 no Returns section; YD01 no Yields section (numpydoc's codes)."""


def _public_modules():
    for info in pkgutil.walk_packages(dynid.__path__, "dynid."):
        if any(part.startswith("_") for part in info.name.split(".")[1:]) or info.name.endswith("__main__"):
            continue
        yield info.name


def _public_objects():
    for name in sorted(_public_modules()):
        module = importlib.import_module(name)
        for attr, obj in sorted(vars(module).items()):
            if attr.startswith("_") or getattr(obj, "__module__", None) != name:
                continue
            if inspect.isfunction(obj):
                yield f"{name}.{attr}", obj, None
            elif inspect.isclass(obj):
                yield f"{name}.{attr}", obj, None
                for meth, value in vars(obj).items():
                    if meth.startswith("_"):
                        continue
                    func = value.fget if isinstance(value, property) else getattr(value, "__func__", value)
                    if inspect.isfunction(func):
                        yield f"{name}.{attr}.{meth}", func, obj


def _field_names(cls) -> list[str]:
    if dataclasses.is_dataclass(cls):
        return [f.name for f in dataclasses.fields(cls)]
    fields = getattr(cls, "__struct_fields__", None)  # msgspec structures
    return list(fields) if fields is not None else []


def _problems(qualname: str, obj, owner) -> list[str]:
    result = numpydoc_validate.validate(qualname)
    errors = [(code, msg) for code, msg in result["errors"] if code in CHECKS]
    fields = _field_names(obj) if inspect.isclass(obj) else []
    if fields:  # a record: its fields are documented as Attributes
        errors = [(c, m) for c, m in errors if c not in ("PR01", "PR02")]
        documented = _described_fields(obj)
        for cls in inspect.getmro(obj):  # a base's fields are documented on the base (a study's result)
            doc = (cls.__doc__ and inspect.cleandoc(cls.__doc__)) or ""
            documented |= _section_names(doc, "Attributes") | _section_names(doc, "Parameters")
        missing = [f for f in fields if f not in documented and not f.startswith("_")]
        if missing:
            errors.append(("PR01", f"fields not documented under Attributes: {missing}"))
    if inspect.isfunction(obj) and _typer_options(obj) is not None:  # a CLI command: its options' help= documents them
        errors = [(c, m) for c, m in errors if c != "PR01"]
        errors += [("PR01", f"option {name!r} has no help text") for name, ok in _typer_options(obj).items() if not ok]
    if isinstance(getattr(owner, "__dict__", {}).get(qualname.rsplit(".", 1)[1]), property):
        errors = [(c, m) for c, m in errors if c != "RT01"]  # a property's docstring says what it is
    return [f"{qualname}: {code} {msg}" for code, msg in errors]


def _typer_options(func) -> dict[str, bool] | None:
    """For a typer command (every parameter's default a typer option or argument): name -> whether it has help
    (hidden options need none: ``--help`` shows their help, not a docstring). None for other functions."""
    from typer.models import ParameterInfo

    params = inspect.signature(func).parameters.values()
    if not params or not all(isinstance(p.default, ParameterInfo) for p in params):
        return None
    return {p.name: bool(p.default.help) or bool(getattr(p.default, "hidden", False)) for p in params}


def _described_fields(cls) -> set[str]:
    """Fields of a typed config table documented by a description in their type (what the JSON Schema shows)."""
    if not hasattr(cls, "__struct_fields__"):
        return set()
    import msgspec

    out = set()
    for f in msgspec.inspect.type_info(cls).fields:
        stack = [f.type]
        while stack:
            t = stack.pop()
            if isinstance(t, msgspec.inspect.Metadata) and (t.extra_json_schema or {}).get("description"):
                out.add(f.name)
                break
            stack.extend(getattr(t, "types", ()) or ([t.type] if isinstance(t, msgspec.inspect.Metadata) else []))
    return out


def _section_names(doc: str, section: str) -> set[str]:
    """Names documented in a numpydoc section (``a, b : type`` lines).

    Parameters
    ----------
    doc : str
        A docstring.
    section : str
        The section's title, e.g. "Attributes".

    Returns
    -------
    set of str
    """
    lines = doc.splitlines()
    names: set[str] = set()
    inside = False
    for i, line in enumerate(lines):
        if line.strip() == section and i + 1 < len(lines) and set(lines[i + 1].strip()) == {"-"}:
            inside = True
            continue
        if inside:
            if line and not line.startswith(" ") and i + 1 < len(lines) and set(lines[i + 1].strip()) == {"-"}:
                break
            if line and not line.startswith(" ") and not set(line.strip()) <= {"-"}:
                names.update(n.strip() for n in line.split(":")[0].split(","))
    return names


def test_every_public_object_has_a_numpydoc_docstring():
    problems = [p for qualname, obj, owner in _public_objects() for p in _problems(qualname, obj, owner)]
    assert not problems, f"{len(problems)} docstring problem(s):\n" + "\n".join(problems[:60])


def _badly_documented(x, y):
    """Sum of ``x`` and ``y``, in prose only."""
    return x + y


def _command(config: str = __import__("typer").Option("a.toml", help="A config."),
             out: str = __import__("typer").Option("out")):
    """A CLI command whose ``out`` option has no help."""


def test_the_check_sees_a_missing_parameter_and_a_missing_returns_section():
    assert _problems("tests.test_docstrings._section_names", _section_names, None) == []
    bad = _problems("tests.test_docstrings._badly_documented", _badly_documented, None)
    assert any("PR01" in p for p in bad) and any("RT01" in p for p in bad)
    command = _problems("tests.test_docstrings._command", _command, None)
    assert command == ["tests.test_docstrings._command: PR01 option 'out' has no help text"]
