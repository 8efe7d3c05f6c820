"""An import inside a function must keep a start-up cost away (issue "Re-zone the top floors", item 8).

Every other import stands at the top of its module. A function-level import outside ``dynid.cli`` is kept only when
it is one of these:

- a third-party package that costs start-up time (:data:`HEAVY`, NumPy among them; SciPy per subpackage:
  ``scipy.signal`` alone is 0.4-0.6 s with SciPy 1.17) that the module's own top-level imports do not load already;
- a dynid module whose top-level imports load such a package that the importing module does not, or that imports the
  importing module back (a cycle);
- a standard module inside ``try: ... except ImportError`` (one a platform may lack);
- in a module that ``dynid identify`` imports before it reads a config (:data:`CONFIG_CHECK`), any module that the
  modules of that path do not import at their top: a config's typo is answered in 0.23 s whole-process, and the 17
  imports of that path moved to the top made it 0.27 s (81 more modules: the MJCF reader, the closed-loop
  simulation, the exporters, ``concurrent.futures``; paired runs, ratio 1.16).

``dynid.cli`` is exempt as a whole: each command imports its own modules, so ``dynid --help`` and a config's typo are
answered from the light modules (tests/cli/test_cli.py shows it: no SciPy, Pinocchio, numba, cvxpy or matplotlib is
imported before a config is read). The graph is read from the sources (``ast``); nothing is imported."""

import ast
import sys
from pathlib import Path

import dynid

ROOT = Path(dynid.__file__).parent

HEAVY = {"numpy", "scipy", "pinocchio", "numba", "llvmlite", "cvxpy", "matplotlib", "mpl_toolkits", "PIL", "mujoco",
         "distributed", "dask", "pyarrow", "rosbags", "jinja2", "msgspec", "jsonschema", "sklearn", "xacro", "threadpoolctl", "typer",
         "rich", "numpydoc"}
"""Third-party packages whose import is a start-up cost worth keeping away from the commands that do not need them
(NumPy too: 0.1 s, and ``dynid --help`` loads none of these)."""

CONFIG_CHECK = ("dynid.cli.app", "dynid.identification.run", "dynid.io.config.identification_config")
"""What ``dynid identify`` imports before it reads and checks a config (tests/cli/test_cli.py)."""

EXEMPT = ("dynid.cli",)
"""Packages whose function-level imports are the command line's lazy loading (see the module docstring)."""


def _module_names(root: Path = ROOT) -> dict[str, Path]:
    out = {}
    for path in root.rglob("*.py"):
        parts = ("dynid", *path.relative_to(root).with_suffix("").parts)
        out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return out


def _is_package(path: Path) -> bool:
    return path.name == "__init__.py"


def _resolved(node, module: str, package: bool, known) -> list[str]:
    """The modules an import statement loads (dynid's by name, a third-party one by its dotted name)."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names]
    if node.level:
        base = module.split(".") if package else module.split(".")[:-1]
        base = base[:len(base) - (node.level - 1)]
        source = ".".join(base + ([node.module] if node.module else []))
    else:
        source = node.module or ""
    subs = [f"{source}.{a.name}" for a in node.names if f"{source}.{a.name}" in known]
    return [source, *subs]


def _key(name: str) -> str | None:
    """The start-up cost an imported name stands for: ``scipy.signal``, ``pinocchio``; None for a light one."""
    parts = name.split(".")
    if parts[0] == "scipy":
        return ".".join(parts[:2])
    return parts[0] if parts[0] in HEAVY else None


def _under_type_checking(node: ast.If) -> bool:
    return "TYPE_CHECKING" in ast.unparse(node.test)


def _top_level_imports(tree: ast.Module):
    """Imports run when the module is imported: the module's and its classes' bodies, not ``if TYPE_CHECKING``."""
    stack = list(tree.body)
    while stack:
        node = stack.pop()
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
        elif isinstance(node, ast.ClassDef):
            stack.extend(node.body)
        elif isinstance(node, ast.If) and not _under_type_checking(node):
            stack.extend(node.body + node.orelse)
        elif isinstance(node, ast.Try):
            stack.extend(node.body + node.orelse + node.finalbody + [s for h in node.handlers for s in h.body])


def _function_imports(tree: ast.Module):
    """``(function name, import node, inside a try that catches ImportError)`` for every function-level import."""
    for func in ast.walk(tree):
        if not isinstance(func, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        guarded = set()
        for node in ast.walk(func):
            if isinstance(node, ast.Try) and any("ImportError" in ast.unparse(h.type or ast.Name("BaseException"))
                                                 for h in node.handlers):
                guarded.update(id(s) for stmt in node.body for s in ast.walk(stmt))
        for node in ast.walk(func):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                yield func.name, node, id(node) in guarded


class ImportGraph:
    """dynid's modules with their top-level imports, from the sources."""

    def __init__(self, sources: dict[str, tuple[str, bool]]):
        self.trees = {m: ast.parse(text) for m, (text, _) in sources.items()}
        self.package = {m: package for m, (_, package) in sources.items()}
        self.edges = {m: [t for node in _top_level_imports(tree)
                          for t in _resolved(node, m, self.package[m], self.trees)]
                      for m, tree in self.trees.items()}
        self._closures: dict[str, tuple[frozenset, frozenset]] = {}
        self.config_path = frozenset().union(*(self.closure(m)[0] for m in CONFIG_CHECK if m in self.trees))
        self.config_path_external = frozenset(t for m in self.config_path for t in self.edges[m]
                                              if not t.startswith("dynid"))

    def closure(self, module: str) -> tuple[frozenset, frozenset]:
        """The dynid modules and the start-up costs (:func:`_key`) that importing ``module`` loads."""
        if module not in self._closures:
            seen, costs, stack = set(), set(), [module]
            while stack:
                m = stack.pop()
                if m in seen:
                    continue
                seen.add(m)
                parts = m.split(".")
                stack.extend(p for p in (".".join(parts[:i]) for i in range(1, len(parts))) if p in self.trees)
                for target in self.edges.get(m, ()):
                    if target in self.trees:
                        stack.append(target)
                    elif _key(target) is not None:
                        costs.add(_key(target))
            self._closures[module] = (frozenset(seen), frozenset(costs))
        return self._closures[module]

    def needless(self, module: str) -> list[str]:
        """The function-level imports of ``module`` that keep no start-up cost away, as
        ``"module.function: import"``."""
        if module.startswith(EXEMPT):
            return []
        own = self.closure(module)[1]
        out = []
        for func, node, guarded in _function_imports(self.trees[module]):
            targets = _resolved(node, module, self.package[module], self.trees)
            if guarded and all(t.split(".")[0] in sys.stdlib_module_names for t in targets):
                continue
            kept_away = False
            on_path = module in self.config_path
            for target in targets:
                if target in self.trees:
                    modules, costs = self.closure(target)
                    kept_away |= bool(costs - own) or module in modules or (on_path and not modules <= self.config_path)
                elif _key(target) is not None:
                    kept_away |= _key(target) not in own
                elif on_path:
                    kept_away |= target not in self.config_path_external
            if not kept_away:
                out.append(f"{module}.{func}: {ast.unparse(node)}")
        return out


def _dynid_graph() -> ImportGraph:
    return ImportGraph({m: (p.read_text(), _is_package(p)) for m, p in _module_names().items()})


def test_every_function_level_import_keeps_a_start_up_cost_away():
    graph = _dynid_graph()
    bad = [line for module in sorted(graph.trees) for line in graph.needless(module)]
    assert not bad, (f"{len(bad)} imports inside functions keep no start-up cost away (move them to the top):\n"
                     + "\n".join(bad))


def test_the_check_sees_a_needless_import_and_keeps_a_justified_one():
    sources = {
        "dynid": ("", True),
        "dynid.light": ("import numpy as np\n", False),
        "dynid.plots": ("import matplotlib.pyplot as plt\n", False),
        "dynid.user": ("from . import light\n"
                       "def a():\n    from .light import np\n"            # light is imported at the top already
                       "def b():\n    from . import plots\n"              # keeps matplotlib away
                       "def c():\n    import json\n"                      # a light standard module
                       "def d():\n    import scipy.signal\n"              # keeps SciPy's signal package away
                       "def e():\n    try:\n        import resource\n    except ImportError:\n        pass\n"
                       "def f():\n    from .back import x\n", False),     # a cycle
        "dynid.back": ("from .user import a\nx = 1\n", False),
        "dynid.cli": ("", True),
        "dynid.cli.app": ("from ..io import identification_config\n", False),
        "dynid.io": ("", True),
        "dynid.io.identification_config": ("import json\nfrom .. import light\n"
                                           "def g():\n    from .. import back\n"  # keeps dynid.back off the config's path
                                           "def h():\n    import json\n"          # on the path already
                                           "def i():\n    import csv\n", False),  # off the path
    }
    graph = ImportGraph(sources)
    assert graph.needless("dynid.user") == ["dynid.user.a: from .light import np", "dynid.user.c: import json"]
    assert graph.needless("dynid.io.identification_config") == ["dynid.io.identification_config.h: import json"]
