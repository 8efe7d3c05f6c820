"""The docs' code runs as written: every ```python block of a tutorial, in order, in one namespace."""

import re
from pathlib import Path

import numpy as np
import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"


def _blocks(page: Path) -> list[str]:
    return re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), flags=re.S)


@pytest.mark.parametrize("page", ["tutorials/using-the-model.md"])
def test_the_tutorials_python_runs(page, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    blocks = _blocks(DOCS / page)
    assert blocks, f"no python blocks in {page}"
    namespace: dict = {}
    for code in blocks:
        exec(compile(code, str(DOCS / page), "exec"), namespace)
    out = capsys.readouterr().out
    contact, alarm = re.search(r"contact at ([\d.]+) s; first alarm at ([\d.]+) s on joint 2", out).groups()
    assert contact == alarm, out
    ratios = re.search(r"largest \|residual\| / σ per joint: \[(.*?)\]", out).group(1).split()
    assert all(float(r) < 8 for r in ratios), out  # no false alarm on the log before the contact


def test_the_extending_pages_python_runs(tmp_path, monkeypatch, capsys):
    """The pipeline's parts, a new estimator and a new strategy, as the page writes them."""
    from dynid.estimators import registry
    from dynid.preprocessing import strategies

    monkeypatch.chdir(tmp_path)
    estimators, known = dict(registry._REGISTRY), dict(strategies._STRATEGIES)
    namespace: dict = {}
    try:
        for code in _blocks(DOCS / "extending.md"):
            exec(compile(code, str(DOCS / "extending.md"), "exec"), namespace)
    finally:  # the page's registrations are the page's
        registry._REGISTRY.clear(), registry._REGISTRY.update(estimators)
        strategies._STRATEGIES.clear(), strategies._STRATEGIES.update(known)
    out = capsys.readouterr().out.splitlines()
    assert "excitation band" in out[0] and out[2].startswith("dynid WLS ")
    assert out[1] == str(namespace["prepared"].choices.to_dict()) and "coulomb_velocity" in out[1]
    ridge, ols = (float(x) for x in out[3].split()[:2])
    assert abs(ridge - ols) < 1e-6 * abs(ols)
    assert out[4] == f"Ridge ({len(namespace['ident'].feature_names_out_)},)"  # the fitted part, kept on the result
    sweep = {float(a): float(v) for a, v in (line.split() for line in out[5:7])}  # an object per value, one key
    assert sweep[1e-9] == pytest.approx(ridge, rel=1e-9) and abs(sweep[1e-3] - ridge) > 1e-4 * abs(ridge)
    assert "'sdp': {" in out[7] and "'prior_kind': 'geometric'" in out[7]
    robot, alone = namespace["robot"], namespace["alone"]  # the problem comes to fit: the prior the ridge pulls toward
    assert np.isfinite(float(out[8])) and out[9] == f"({robot.n_params},) ({robot.n_params},)"
    np.testing.assert_array_equal(alone.problem_.prior, robot.standard_parameters())
    assert out[10] == "central differences, no filter"


def test_every_page_of_the_site_is_in_its_navigation():
    import yaml  # mkdocs' own dependency

    nav = yaml.safe_load((DOCS.parent / "mkdocs.yml").read_text())["nav"]

    def pages(entries):
        for e in entries:
            for v in e.values():
                yield from (pages(v) if isinstance(v, list) else [v])

    listed = set(pages(nav))
    present = {p.relative_to(DOCS).as_posix() for p in DOCS.rglob("*.md")}
    assert present == listed, (present - listed, listed - present)


def test_the_readmes_python_runs(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (code,) = _blocks(DOCS.parent / "README.md")
    exec(compile(code, "README.md", "exec"), {})
    assert float(capsys.readouterr().out.strip().splitlines()[-1]) > 0.99
    assert (tmp_path / "results.json").is_file()


def test_the_workflow_tutorials_python_runs(tmp_path, monkeypatch, capsys):
    """docs/tutorials/workflow.md's design tried on a simulated log: the design lowers the criterion, the log runs the
    designed motion, and least squares finds the description's own base parameters within 5 σ."""
    monkeypatch.chdir(tmp_path)
    (code,) = _blocks(DOCS / "tutorials" / "workflow.md")
    namespace: dict = {}
    exec(compile(code, "workflow.md", "exec"), namespace)
    design, log = namespace["design"], namespace["log"]
    assert design.cond < design.initial_cond
    q, _, _ = design.trajectory.evaluate(log.t)
    assert np.abs(np.asarray(log.q) - q).max() <= np.pi / 2**20 + 1e-12  # the encoders' rounding alone
    fitted = namespace["dynid"].Identifier("ur10e", estimators=["wls"]).fit(log)
    truth = fitted.result_.base.base_from_standard(namespace["dynid"].load_robot("ur10e").standard_parameters())
    wls = fitted.parameters()
    assert np.all(np.abs(wls.values - truth) <= 5 * wls.std + 1e-9), np.abs(wls.values - truth) / wls.std
    assert "name" in capsys.readouterr().out


def test_the_readme_is_a_users_guide_under_250_lines():
    readme = (DOCS.parent / "README.md").read_text(encoding="utf-8")
    assert len(readme.splitlines()) < 250
    blocks = re.findall(r"```sh\n(.*?)```", readme, flags=re.S)
    setup = [line.split("#")[0].strip() for line in blocks[0].splitlines() if line.strip()]
    assert setup == ["make demo", "make test"]  # the two set-up commands, and only them


def test_the_closed_loop_pages_python_runs(tmp_path, monkeypatch):
    """docs/closed-loop.md as written: simulate, identify in closed loop, estimate the delay."""
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for code in _blocks(DOCS / "closed-loop.md"):
        exec(compile(code, str(DOCS / "closed-loop.md"), "exec"), namespace)
    assert set(namespace["estimates"]) == {"wls", "idim-iv", "didim"}
    d = namespace["d"]  # 1 kHz, an excitation below 0.3 Hz: a delay of a few samples is not determined, and said
    assert not d.determined and (d.at_bound or d.std > 0.5)


def test_the_fleet_tutorials_python_runs(tmp_path, monkeypatch, capsys):
    """docs/tutorials/fleets.md as written: a simulated fleet identified on Dask, the odd unit flagged; a service life
    monitored, the worn joint named."""
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for code in _blocks(DOCS / "tutorials" / "fleets.md"):
        exec(compile(code, "fleets.md", "exec"), namespace)
    out = capsys.readouterr().out
    assert re.search(r"^r03: K2 = [\d.]+, the other units [\d.]+ \(z \+\d+", out, flags=re.M), out
    alarms = [line for line in out.splitlines() if line.startswith("joint ")]
    assert len(alarms) == 1 and alarms[0].startswith("joint 3: viscous friction (fv3) rose"), out
    assert "since 2026-01-15T00-00.csv at 1 s; alarm in 2026-01-15T00-00.csv at 11 s, 10 s of logs later" in alarms[0]


def test_the_docs_build_counts_its_warnings():
    """make test builds the docs with --strict and nothing that hides warnings from it (--quiet did: a broken link
    passed)."""
    lines = [ln for ln in (DOCS.parent / "Makefile").read_text().splitlines() if "mkdocs build" in ln]
    assert lines, "make test builds no docs"
    for line in lines:
        command = line.split("#", 1)[0].split()
        assert "--strict" in command and "--quiet" not in command and "-q" not in command, line


def test_the_readme_and_docs_link_to_files_that_exist():
    """Every relative link of the README and of the docs' pages names a file of the repository (mkdocs checks the
    pages' links among themselves; this checks the README's and the docs' links out of docs/)."""
    root = DOCS.parent
    broken = []
    for page in [root / "README.md", *sorted(DOCS.rglob("*.md"))]:
        for target in re.findall(r"\]\(([^)\s]+)\)", page.read_text(encoding="utf-8")):
            path = target.split("#", 1)[0]
            if not path or re.match(r"^[a-z]+:", path):
                continue
            if not (page.parent / path).exists():
                broken.append(f"{page.relative_to(root)} -> {target}")
    assert broken == []


def test_the_docs_site_opened_from_disk_navigates():
    """The README says to open .site/index.html: with directory URLs every nav link showed a folder listing."""
    import re as _re

    text = (DOCS.parent / "mkdocs.yml").read_text()
    assert _re.search(r"^use_directory_urls:\s*false\b", text, flags=_re.M)


def test_the_extras_are_listed_once_and_as_pyproject_has_them():
    """docs/getting-started.md's table names exactly pyproject.toml's extras; the README points to it, lists none."""
    import tomllib

    root = DOCS.parent
    extras = set(tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))["project"]["optional-dependencies"])
    page = (DOCS / "getting-started.md").read_text(encoding="utf-8")
    rows = re.findall(r"^\| (`[^|]*`) \|", page, flags=re.M)
    listed = {name for row in rows for name in re.findall(r"`([\w-]+)`", row)}
    assert listed == extras
    readme = (root / "README.md").read_text(encoding="utf-8")
    assert "docs/getting-started.md#install" in readme and not any(f"`{e}`" in readme for e in extras - {"test"})
