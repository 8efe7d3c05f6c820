"""No two modules of dynid import each other, at the top or inside a function (issue "Parts carry their settings",
item 4: ``model/mjcf`` and ``model/urdf`` did, through imports inside functions): a pair that needs each other is one
job split wrong, or shares a third module's."""

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "dynid"


def _module(path: Path) -> str:
    parts = path.relative_to(SRC.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path, known: set[str]) -> set[str]:
    """The dynid modules a file imports anywhere in it (a name imported from a package that is a module of its own
    counts as that module)."""
    here = _module(path)
    package = here if path.name == "__init__.py" else here.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name in known}
        elif isinstance(node, ast.ImportFrom):
            base = package
            for _ in range(max(node.level - 1, 0)):
                base = base.rpartition(".")[0]
            module = ((base + "." + node.module) if node.module else base) if node.level else (node.module or "")
            found |= {f"{module}.{a.name}" for a in node.names if f"{module}.{a.name}" in known}
            if module in known:
                found.add(module)
    return found - {here}


def _graph() -> dict[str, set[str]]:
    files = sorted(SRC.rglob("*.py"))
    known = {_module(p) for p in files}
    return {_module(p): _imports(p, known) for p in files}


def _pairs(graph: dict[str, set[str]]) -> list[tuple[str, str]]:
    packages = {m for m in graph if any(other.startswith(m + ".") for other in graph)}
    return sorted((a, b) for a, targets in graph.items() for b in targets
                  if a < b and a in graph.get(b, ()) and a not in packages and b not in packages)


def test_no_two_modules_import_each_other():
    assert _pairs(_graph()) == []


def test_the_check_finds_a_pair():
    graph = {"dynid.model.mjcf": {"dynid.model.urdf"}, "dynid.model.urdf": {"dynid.model.mjcf"}, "dynid.x": set()}
    assert _pairs(graph) == [("dynid.model.mjcf", "dynid.model.urdf")]


def _circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan's algorithm, iterative), packages left out
    (a package's __init__ hands its modules' names on)."""
    packages = {m for m in graph if any(other.startswith(m + ".") for other in graph)}
    edges = {m: sorted(t for t in targets if t not in packages) for m, targets in graph.items() if m not in packages}
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    for root in edges:
        if root in index:
            continue
        work = [(root, iter(edges[root]))]
        index[root] = low[root] = len(index)
        stack.append(root), on.add(root)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w), on.add(w)
                    work.append((w, iter(edges.get(w, ()))))
                elif w in on:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                component = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    component.append(w)
                    if w == v:
                        break
                if len(component) > 1:
                    out.append(sorted(component))
    return out


def test_no_circle_of_imports_of_any_length():
    """issue "One route, four named parts": identification/run -> pipeline -> identify -> identified -> run (with
    closed_loop) was a circle of five modules, closed by imports inside functions, which the pair check above missed."""
    assert _circles(_graph()) == []


def test_the_check_finds_a_circle_of_three():
    graph = {"dynid.a": {"dynid.b"}, "dynid.b": {"dynid.c"}, "dynid.c": {"dynid.a"}, "dynid.d": {"dynid.a"}}
    assert _circles(graph) == [["dynid.a", "dynid.b", "dynid.c"]]
