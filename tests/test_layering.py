"""Lower layers never import higher ones (DESIGN.md)."""

import ast
from pathlib import Path

import dynid

ORDER = ["conventions", "exceptions", "checks", "friction", "threads", "model", "dynamics",
         "excitation", "simulation", "preprocessing", "optim", "estimators", "validation", "io",
         "experiment", "report", "cli"]
LEVEL = {"conventions": 0, "exceptions": 0, "checks": 0, "friction": 0, "threads": 0, "_lazy": 0, "model": 1, "dynamics": 2, "excitation": 3, "simulation": 3,
         "preprocessing": 3, "optim": 3, "estimators": 4, "validation": 5, "io": 5, "experiment": 6, "report": 7, "cli": 8}


def test_no_upward_imports():
    root = Path(dynid.__file__).parent
    bad = []
    for path in root.rglob("*.py"):
        rel = path.relative_to(root).parts
        top = rel[0].removesuffix(".py")
        if top not in LEVEL:
            continue
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.level >= 1 and node.module:
                depth = len(rel) - 1
                if node.level > depth:  # relative import reaching the package root
                    target = node.module.split(".")[0]
                elif node.level == depth and depth >= 1:
                    target = top
                else:
                    continue
                if target in LEVEL and LEVEL[target] > LEVEL[top]:
                    bad.append(f"{'/'.join(rel)} imports {target}")
    assert not bad, bad
