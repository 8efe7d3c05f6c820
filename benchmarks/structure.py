"""The structure measures of issue "Parts carry their settings, one route", read from the source (nothing is run).

    python benchmarks/structure.py [--walk WALK.txt] [--src src/dynid]

- hubs: functions calling 15 or more distinct dynid functions and classes by name (exceptions and warnings not counted;
  a method called on an object is not counted: the callee is not known from the text);
- modules naming ``sdp_prior`` or ``prior_kind``;
- with ``--walk``, the output of ``farm-studio walk src/dynid/identification/run.py:run_identification:config --stops
  1600``: its stays, and the pairs of modules on different floors that the route crosses back and forth 4 times or
  more (consecutive stays).
"""

from __future__ import annotations

import argparse
import ast
import collections
import re
from pathlib import Path

HUB = 13
"""Distinct dynid callables that make a function a hub (issue "One route, four named parts": none calls more than 12)."""
CROSSINGS = 4
"""Back-and-forth crossings of a pair of modules that count."""


def _callables(trees: dict) -> set[str]:
    """Names of every function and class defined in the package, exceptions and warnings left out."""
    kinds = (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)
    return {n.name for t in trees.values() for n in ast.walk(t)
            if isinstance(n, kinds) and not n.name.startswith("__") and not n.name.endswith(("Error", "Warning"))}


def hubs(root: Path) -> list[tuple[int, str]]:
    """``(count, "module:function")`` of each hub, most calls first."""
    trees = {p: ast.parse(p.read_text(encoding="utf-8")) for p in sorted(root.rglob("*.py"))}
    defined = _callables(trees)
    out = []
    for path, tree in trees.items():
        imported = {a.asname or a.name for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)
                    and (n.level > 0 or (n.module or "").startswith("dynid")) for a in n.names}
        local = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
        for fn in ast.walk(tree):
            if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            called = {c.func.id for c in ast.walk(fn) if isinstance(c, ast.Call) and isinstance(c.func, ast.Name)
                      and c.func.id in defined and (c.func.id in imported or c.func.id in local)}
            if len(called) >= HUB:
                out.append((len(called), f"{path.relative_to(root).as_posix()}:{fn.name}"))
    return sorted(out, reverse=True)


def prior_modules(root: Path) -> list[str]:
    """Modules naming ``sdp_prior`` or ``prior_kind``."""
    return [p.relative_to(root).as_posix() for p in sorted(root.rglob("*.py"))
            if re.search(r"sdp_prior|prior_kind", p.read_text(encoding="utf-8"))]


def crossings(walk: Path) -> tuple[int, list[tuple[int, tuple[str, str]]]]:
    """The walk's stays, and each pair of modules on different floors crossed :data:`CROSSINGS` times or more."""
    stays = [(int(m.group(1)), m.group(2)) for line in walk.read_text(encoding="utf-8").splitlines()
             if (m := re.match(r"\s*\d+\.\s+floor\s+(\d+)\s+(\S+)", line))]
    pairs: collections.Counter = collections.Counter()
    for (f1, m1), (f2, m2) in zip(stays, stays[1:]):
        if f1 != f2:
            pairs[tuple(sorted((m1, m2)))] += 1
    return len(stays), [(n, pair) for pair, n in pairs.most_common() if n >= CROSSINGS]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--src", type=Path, default=Path(__file__).resolve().parents[1] / "src" / "dynid")
    parser.add_argument("--walk", type=Path, help="farm-studio walk output of run_identification's config")
    args = parser.parse_args()
    found = hubs(args.src)
    print(f"hubs (>= {HUB} distinct dynid functions and classes called): {len(found)}")
    for n, name in found:
        print(f"  {n:3d}  {name}")
    named = prior_modules(args.src)
    print(f"modules naming sdp_prior or prior_kind: {len(named)} ({', '.join(named)})")
    if args.walk is not None:
        n_stays, pairs = crossings(args.walk)
        print(f"route: {n_stays} stays; pairs of modules on different floors crossed >= {CROSSINGS} times: {len(pairs)}")
        for n, (a, b) in pairs:
            print(f"  {n:3d}  {a} <-> {b}")


if __name__ == "__main__":
    main()
