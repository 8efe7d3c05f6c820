"""Every config of the compatibility corpus through the release it came from and through this one, figure by figure.

``tests/data/compat/<config>@<commit>.toml`` holds each version of the real configs ever shipped (issue "Safe and
stable", item 2). For each, this script checks out ``<commit>`` into a temporary git worktree, runs its
``dynid identify`` on the real data (``../shared/data``) with this virtual environment, runs today's on the same
file (after ``dynid migrate`` where today's refuses an old key), and prints, per log and estimate, the global
relative torque error then and now. A figure that moved is a changed meaning to be named in docs/changelog.md, or a
regression. Run from the repository root (about 5 minutes on two cores; the data must be beside the repository). Each
config runs where it was in its release (``configs/``, beside that release's robot descriptions): a user upgrading
keeps both:

    .venv/bin/python benchmarks/compat_figures.py [--only ur10e@7b90d67,...] [--jobs 2] [--record FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from tests.results_figures import global_errors  # noqa: E402 - the repository's root on the path first

CORPUS = REPO / "tests" / "data" / "compat"
DATA = {"ur10e": "ur10e_mamedov2020", "tx40": "staubli_tx40_figaroh", "tx40-full": "staubli_tx40_figaroh",
        "kuka_kr300": "kuka_kr300_weigand2021", "kuka_med7": "kuka_med7_lbrstack"}
"""The data folder under ../shared/data of each config."""


def _identify(src: Path, config: Path, data_root: Path, out: Path) -> tuple[dict | None, str]:
    """``dynid identify`` of the code under ``src`` on ``config``: results.json, or None and the error's last line."""
    env = {**os.environ, "PYTHONPATH": str(src), "DYNID_DATA_ROOT": str(data_root), "MPLBACKEND": "Agg",
           "COLUMNS": "200"}
    usage = subprocess.run([sys.executable, "-m", "dynid", "identify", "--help"], env=env, capture_output=True,
                           text=True).stdout  # an earlier release may lack an option
    options = [o for o in (["--data-root", str(data_root)], ["--no-figures"], ["-q"])
               if re.search(rf"(^|[\s,]){re.escape(o[0])}([\s,]|$)", usage, re.MULTILINE)]
    p = subprocess.run([sys.executable, "-m", "dynid", "identify", str(config), "--out", str(out),
                        *[w for o in options for w in o]], env=env, capture_output=True, text=True, timeout=1800)
    if p.returncode != 0:
        lines = [line.strip(" │╭╮╰╯─") for line in p.stderr.splitlines()]
        return None, ([line for line in lines if line] or [f"exit {p.returncode}"])[-1]
    return json.loads((out / "results.json").read_text()), ""


RECORDED: dict = {}
"""name -> {"migrated", "then", "now"}: the figures of each version, for ``--record``."""


def _case(name: str, work: Path) -> tuple[list[str], str]:
    """The table rows of one corpus version, and its summary row."""
    family, commit = name.split("@")
    data_root = REPO.parent / "shared" / "data" / DATA[family]
    tree = work / f"tree-{commit}"
    # the config where it was, beside the robot descriptions of its release: a user keeps both
    config = tree / "configs" / f"{family}.toml"
    if config.read_bytes() != (CORPUS / f"{name}.toml").read_bytes():
        row = f"| {name} | — | — | not the corpus file | — | — |"
        return [row], row
    then, why_then = _identify(tree / "src", config, data_root, work / f"{name}-then")
    now_config = config
    now, why_now = _identify(REPO / "src", config, data_root, work / f"{name}-now")
    if now is None and "migrate" in why_now:
        now_config = config.with_name(f"{family}-migrated.toml")
        subprocess.run([sys.executable, "-m", "dynid", "migrate", str(config), "--out", str(now_config)],
                       env={**os.environ, "PYTHONPATH": str(REPO / "src")}, capture_output=True, text=True, check=True)
        now, why_now = _identify(REPO / "src", now_config, data_root, work / f"{name}-now")
    if then is None or now is None:
        row = f"| {name} | — | — | {why_then or 'ran'} | {why_now or 'ran'} | — |"
        return [row], row
    a, b = global_errors(then), global_errors(now)
    RECORDED[name] = {"migrated": now_config != config, "then": {f"{k[0]}\t{k[1]}": v for k, v in sorted(a.items())},
                      "now": {f"{k[0]}\t{k[1]}": v for k, v in sorted(b.items())}}
    rows = []
    moved = {k: (b[k] - a[k]) / max(abs(a[k]), 1e-12) for k in set(a) & set(b)}
    big = {k: v for k, v in moved.items() if abs(v) > 0.01}
    worst = max(moved, key=lambda k: abs(moved[k]), default=None)
    summary = (f"| {name}{' (migrated)' if now_config != config else ''} | {len(moved)} | {len(moved) - len(big)} | "
               + ("—" if worst is None else f"{worst[0]}, {worst[1]}: {a[worst]:.3g} → {b[worst]:.3g} %") + " |")
    for key in sorted(set(a) | set(b)):
        x, y = a.get(key), b.get(key)
        change = "" if x is None or y is None else f"{(y - x) / max(abs(x), 1e-12) * 100:+.1f} %"
        rows.append(f"| {name}{' (migrated)' if now_config != config else ''} | {key[0]} | {key[1]} | "
                    f"{'—' if x is None else f'{x:.3g}'} | {'—' if y is None else f'{y:.3g}'} | {change} |")
    return rows, summary


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default="", help="comma-separated corpus names (config@commit)")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--record", type=Path, default=None,
                        help="also write every figure then and now as JSON (tests/data/compat/figures.json is this "
                             "file: the suite checks today's figures against the releases' own)")
    args = parser.parse_args(argv)
    names = sorted(p.stem for p in CORPUS.glob("*@*.toml"))
    if args.only:
        names = [n for n in names if n in args.only.split(",")]
    with tempfile.TemporaryDirectory(prefix="dynid-compat-") as tmp:
        work = Path(tmp)
        for commit in sorted({n.split("@")[1] for n in names}):
            subprocess.run(["git", "-C", str(REPO), "worktree", "add", "--detach", "-q", str(work / f"tree-{commit}"), commit],
                           check=True)
        try:
            load = os.getloadavg()[0]
            with ThreadPoolExecutor(args.jobs) as pool:
                tables = list(pool.map(lambda n: _case(n, work), names))
            print(f"compatibility corpus, {len(names)} config versions, {args.jobs} at a time; load {load:.2f} at the start, "
                  f"{os.getloadavg()[0]:.2f} at the end")
            print("| config@commit | figures in both | within 1 % | the largest move |")
            print("|---|---|---|---|")
            for _, summary in tables:
                print(summary)
            print()
            print("| config@commit | log | estimate | then [%] | now [%] | change |")
            print("|---|---|---|---|---|---|")
            for rows, _ in tables:
                print("\n".join(rows))
            if args.record is not None:
                args.record.write_text(json.dumps({"measured_at": subprocess.run(
                    ["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip(),
                    "versions": dict(sorted(RECORDED.items()))}, indent=1) + "\n")
        finally:
            for commit in sorted({n.split("@")[1] for n in names}):
                subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force", str(work / f"tree-{commit}")],
                               check=False)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
