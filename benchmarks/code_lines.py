"""Issue "Parts carry their settings, one route", T8: lines of code, read from git (nothing of dynid is run).

    python benchmarks/code_lines.py REV [REV ...]             # code lines of src/dynid at each commit
    python benchmarks/code_lines.py --commits BASE [HASH ...]  # each commit's change since BASE (first parent);
                                                              # with hashes, their sum as well

A line of code is a line of ``src/dynid/**/*.py`` holding a token other than a comment, that is no part of a docstring
(a module's, class's or function's first statement, or an attribute's string statement). Blank lines and comments do
not count. A commit's change is the count after it minus the count before it, summed over the files it touches
(renames counted as a removal and an addition, so the changes add up to the difference of the totals).
"""

from __future__ import annotations

import argparse
import ast
import io
import subprocess
import tokenize

_SKIPPED = (tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT, tokenize.ENDMARKER)


def code_lines(text: str) -> int:
    """Lines of ``text`` (a Python module) that hold code, docstrings, comments and blank lines left out."""
    docs: set[int] = set()
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str):
            docs.update(range(node.lineno, node.end_lineno + 1))
    code: set[int] = set()
    for token in tokenize.generate_tokens(io.StringIO(text).readline):
        if token.type not in _SKIPPED:
            code.update(range(token.start[0], token.end[0] + 1))
    return len(code - docs)


def _git(*args: str) -> str:
    return subprocess.run(["git", *args], capture_output=True, text=True, check=True).stdout


def _count(rev: str, path: str) -> int:
    """Code lines of ``path`` at ``rev`` (0 where the file does not exist there)."""
    shown = subprocess.run(["git", "show", f"{rev}:{path}"], capture_output=True, text=True)
    return code_lines(shown.stdout) if shown.returncode == 0 else 0


def total(rev: str) -> int:
    """Code lines of ``src/dynid`` at ``rev``."""
    return sum(_count(rev, f) for f in _git("ls-tree", "-r", "--name-only", rev, "src/dynid").split() if f.endswith(".py"))


def change(rev: str) -> int:
    """Code lines ``rev`` adds to ``src/dynid`` minus those it removes (against its first parent)."""
    files = _git("diff", "--name-only", "--no-renames", f"{rev}^", rev, "--", "src/dynid").split()
    return sum(_count(rev, f) - _count(f"{rev}^", f) for f in files if f.endswith(".py"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("revs", nargs="*", help="commits to count, or with --commits the commits to sum")
    parser.add_argument("--commits", metavar="BASE", help="print every commit's change since BASE")
    args = parser.parse_args()
    if args.commits is None:
        for rev in args.revs:
            print(f"{rev}\t{total(rev)}")
        return
    chain = _git("rev-list", "--reverse", "--first-parent", f"{args.commits}..HEAD").split()
    changes = {rev: change(rev) for rev in chain}
    for rev, lines in changes.items():
        print(f"{rev[:7]}\t{lines:+d}\t{_git('log', '-1', '--format=%s', rev).strip()[:100]}")
    print(f"all {len(chain)} commits\t{sum(changes.values()):+d}")
    if args.revs:
        picked = [rev for rev in changes if any(rev.startswith(h) for h in args.revs)]
        gained = [changes[rev] for rev in picked]
        print(f"the {len(picked)} named\t{sum(gained):+d} (added {sum(g for g in gained if g > 0):+d}, "
              f"removed {sum(g for g in gained if g < 0):+d})")


if __name__ == "__main__":
    main()
