"""Output folders: a run lands whole or not at all, and --out is checked before any computation."""

import json
import os
import sys

import numpy as np
import pytest

from dynid.exceptions import ConfigError
from dynid.report import output
from dynid.report.output import MANIFEST, check_output_folder, staged
from dynid.runtime.threads import cores


@staged
def _save(files, out, fail_after=None):
    paths = []
    for i, (name, text) in enumerate(files.items()):
        if fail_after is not None and i == fail_after:
            raise KeyboardInterrupt  # as Ctrl-C while saving
        (out / name).write_text(text)
        paths.append(out / name)
    return paths


def test_a_run_replaces_the_earlier_one_whole(tmp_path):
    out = tmp_path / "run"
    _save({"results.json": "1", "a.png": "A", "b.png": "B"}, out)
    (out / "notes.txt").write_text("mine")  # the user's own file stays
    paths = _save({"results.json": "2", "a.png": "A2"}, out)
    assert paths == [out / "results.json", out / "a.png"]
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "a.png", "notes.txt", "results.json"]
    assert json.loads((out / MANIFEST).read_text())["files"] == ["results.json", "a.png"]
    assert (out / "results.json").read_text() == "2"


def test_a_file_of_the_users_where_a_run_writes_one_is_refused_before_anything_moves(tmp_path):
    """``--out .`` in a folder that holds the user's own report.html: refused, the folder as it was; an earlier run's
    files (in its manifest) are still replaced, and a run after one killed there (its staging folder left) may
    replace the killed run's files, which no manifest lists."""
    out = tmp_path / "mine"
    out.mkdir()
    (out / "report.html").write_text("my notes")
    with pytest.raises(ConfigError, match=r"report.html: a file where this run writes one, which no earlier run"):
        _save({"results.json": "1", "report.html": "R1"}, out)
    assert sorted(p.name for p in out.iterdir()) == ["report.html"] and (out / "report.html").read_text() == "my notes"
    (out / "report.html").unlink()
    _save({"results.json": "1", "report.html": "R1"}, out)
    _save({"results.json": "2", "report.html": "R2"}, out)  # the earlier run's: replaced
    assert (out / "report.html").read_text() == "R2"
    (out / MANIFEST).unlink()  # as a run killed while its files moved leaves it, with its staging folder
    (out / ".dynid-staging-elsewhere-1-x").mkdir()
    _save({"results.json": "3", "report.html": "R3"}, out)
    assert (out / "report.html").read_text() == "R3"


def test_a_file_of_the_users_a_command_will_write_is_refused_before_computing(tmp_path):
    """The names a command writes whatever its result are checked with --out itself: the user's own refused, an
    earlier run's (in its manifest) and a killed run's (its staging folder left) not."""
    out = tmp_path / "mine"
    out.mkdir()
    (out / "report.html").write_text("my notes")
    with pytest.raises(ConfigError, match=r"report.html: a file where this run writes one, which no earlier run"):
        check_output_folder(out, ("results.json", "report.html"))
    assert check_output_folder(out, ("results.json",)) == out  # a name the command does not write
    (out / "report.html").unlink()
    _save({"results.json": "1", "report.html": "R1"}, out)
    assert check_output_folder(out, ("results.json", "report.html")) == out
    (out / MANIFEST).unlink()
    (out / ".dynid-staging-elsewhere-1-x").mkdir()
    assert check_output_folder(out, ("results.json", "report.html")) == out


def test_an_interrupted_save_leaves_the_earlier_run_unchanged(tmp_path):
    out = tmp_path / "run"
    _save({"results.json": "1", "a.png": "A"}, out)
    before = {p.name: p.read_text() for p in out.iterdir()}
    with pytest.raises(KeyboardInterrupt):
        _save({"results.json": "2", "a.png": "A2", "b.png": "B2"}, out, fail_after=2)
    assert {p.name: p.read_text() for p in out.iterdir()} == before  # no staging folder left, nothing mixed


def test_unusable_out_is_refused_before_computing(tmp_path):
    (tmp_path / "file").write_text("x")
    with pytest.raises(ConfigError, match=r"^out .*file: exists and is not a folder"):
        check_output_folder(tmp_path / "file")
    ro = tmp_path / "ro"
    ro.mkdir()
    os.chmod(ro, 0o500)
    try:
        if os.access(ro, os.W_OK):  # root ignores permissions
            pytest.skip("running as root: permissions are not enforced")
        with pytest.raises(ConfigError, match="is not writable"):
            check_output_folder(ro / "sub")
    finally:
        os.chmod(ro, 0o700)


def test_a_kill_while_files_move_leaves_no_manifest_and_its_staging_folder_goes_later(tmp_path, monkeypatch):
    out = tmp_path / "run"
    _save({"results.json": "1", "a.png": "A"}, out)
    moved = []
    real_replace = os.replace

    def replace_then_die(src, dst):  # SIGKILL after the first file moved: nothing runs after it
        if moved:
            raise SystemExit("killed")
        moved.append(dst)
        real_replace(src, dst)

    monkeypatch.setattr(os, "replace", replace_then_die)
    monkeypatch.setattr("shutil.rmtree", lambda *a, **k: None)  # a kill runs no clean-up
    with pytest.raises(SystemExit):
        _save({"results.json": "2", "a.png": "A2"}, out)
    monkeypatch.undo()
    assert not (out / MANIFEST).exists()  # the mix is marked: files without a manifest
    stale = list(out.glob(".dynid-staging-*"))
    assert stale
    os.utime(stale[0], (0, 0))  # an hour and more later
    _save({"results.json": "3"}, out)
    assert not list(out.glob(".dynid-staging-*")) and json.loads((out / MANIFEST).read_text())["files"] == ["results.json"]


def test_a_staging_folder_of_a_process_that_is_gone_goes_at_once(tmp_path):
    """SIGKILL or power loss during staging: the next run removes the folder without waiting an hour; a fresh
    staging folder of a live process (a run saving now) stays."""
    import socket
    import subprocess
    import sys

    from dynid.report.output import _STAGING

    out = tmp_path / "out"
    out.mkdir()
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()  # its pid is free now
    host = socket.gethostname().replace("-", "_")
    dead = out / f"{_STAGING}{host}-{child.pid}-abc"
    live = out / f"{_STAGING}{host}-{os.getpid()}-def"
    for folder in (dead, live):
        folder.mkdir()
        (folder / "results.json").write_text("half")
    _save({"results.json": "1"}, out)
    assert not dead.exists() and live.exists()


def test_a_folder_where_a_file_goes_is_refused_before_anything_moves(tmp_path):
    out = tmp_path / "out"
    _save({"results.json": "1", "a.png": "A1"}, out)
    (out / "a.png").unlink()
    (out / "a.png").mkdir()
    with pytest.raises(ConfigError, match="a.png: a folder where this run writes a file"):
        _save({"results.json": "2", "a.png": "A2"}, out)
    assert (out / "results.json").read_text() == "1" and json.loads((out / MANIFEST).read_text())["files"] == ["results.json", "a.png"]
    assert not list(out.glob(".dynid-staging-*"))


def _writer_jobs(folder, n, parent=None):
    """Jobs that write ``{i}.png`` holding the writer's pid; with ``parent``, they fail in any other process."""
    def job(i):
        def run():
            if parent is not None and os.getpid() != parent:
                raise RuntimeError("the drawing failed in another process")
            (folder / f"{i}.png").write_text(str(os.getpid()))
        return run

    return [job(i) for i in range(n)]


def _writers(folder, n):
    return [(folder / f"{i}.png").read_text() for i in range(n)]


FORKS = sys.platform.startswith("linux") and cores() >= 2


@pytest.fixture
def forks():
    """As in the CLI's commands, which run inside allow_forks (the library alone draws in its process)."""
    from dynid.runtime.processes import allow_forks

    with allow_forks():
        yield


@pytest.mark.parametrize("n", [1, 2, 6])
def test_figures_drawn_on_two_processes_are_all_written_even_if_the_child_fails(tmp_path, forks, n):
    """From two figures on (an identification without validation logs draws two: 0.3 s less on the UR10e example)."""
    from dynid.report.output import draw_figures

    parent = os.getpid()
    draw_figures(_writer_jobs, tmp_path, n)
    assert len(set(_writers(tmp_path, n))) == (2 if FORKS and n > 1 else 1)  # both processes drew
    for p in tmp_path.glob("*.png"):
        p.unlink()
    draw_figures(_writer_jobs, tmp_path, n, parent)
    assert set(_writers(tmp_path, n)) == {str(parent)}  # the parent redrew the child's half


@pytest.mark.skipif(not FORKS, reason="the figure process needs fork and two cores")
def test_the_figure_process_draws_every_figure_and_leaves(tmp_path, forks):
    from dynid.report.output import draw_figures, figure_process

    parent = os.getpid()
    with figure_process():
        pid = output._waiting._child.pid
        draw_figures(_writer_jobs, tmp_path, 6)
        writers = set(_writers(tmp_path, 6))
        assert len(writers) == 2 and str(parent) not in writers and str(pid) in writers  # it and its fork drew
        draw_figures(_writer_jobs, tmp_path / "again", 0)  # a second call in the block draws here
    with pytest.raises(ChildProcessError):
        os.waitpid(pid, os.WNOHANG)  # it was waited for: no zombie is left


@pytest.mark.skipif(not FORKS, reason="the figure process needs fork and two cores")
@pytest.mark.parametrize("failure", ["drawing", "pickling"])
def test_when_the_figure_process_fails_this_process_draws_every_figure(tmp_path, failure, forks):
    from dynid.report.output import draw_figures, figure_process

    parent = os.getpid()
    with figure_process():
        if failure == "drawing":
            draw_figures(_writer_jobs, tmp_path, 6, parent)  # fails in the figure process
        else:
            draw_figures(lambda folder, n: _writer_jobs(folder, n), tmp_path, 6)  # a lambda does not pickle
    writers = _writers(tmp_path, 6)  # every file is there
    assert set(writers) == {str(parent)} if failure == "drawing" else str(parent) in writers


@pytest.mark.skipif(not FORKS, reason="the figure process needs fork and two cores")
def test_an_unused_figure_process_leaves_with_the_block(tmp_path, forks):
    from dynid.report.output import figure_process

    with pytest.raises(ValueError):
        with figure_process():
            pid = output._waiting._child.pid
            raise ValueError("the computation failed")  # no figures sent
    with pytest.raises(ChildProcessError):
        os.waitpid(pid, os.WNOHANG)


def test_the_report_holds_every_finding_and_warning_the_terminal_printed(tmp_path):
    """The verdict said "see the warnings" and the report had no findings: now a section the table of contents links
    to holds each finding, each warning (a dead torque channel here) and each log's flags."""
    import html as html_lib

    from ..cli.refusals import dynid
    from ..simulated_logs import simulated_case

    cfg, robot = simulated_case(tmp_path, "er16", 250.0, "fourier", seed=2, duration=20.0)
    data = np.loadtxt(tmp_path / "valid.csv", delimiter=",")
    data[:, 1 + robot.n_dof + 3] = 0.0  # J4's channel dead in the validation log
    np.savetxt(tmp_path / "valid.csv", data, delimiter=",", fmt="%.10g")
    p = dynid("identify", cfg, "--out", tmp_path / "out", "--no-figures")
    assert p.returncode == 0, p.stderr
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    page = html_lib.unescape((tmp_path / "out" / "report.html").read_text())
    section = page[page.index('id="warnings"'):]
    assert results["findings"] and results["warnings"]
    for f in results["findings"]:
        assert f"finding: {f['text']}" in section
    for w in results["warnings"] + [x for v in results["validation"] for x in v.get("flags", [])]:
        assert w in section
    assert 'href="#warnings">Findings and warnings' in page and "see Findings and warnings below" in page


def test_the_main_estimate_line_names_what_export_writes_in_a_whole_sentence():
    """The "main estimate" line of ``dynid identify`` read "…; dynid export writes dynid SDP, which is" and stopped
    (found on a zoo log where WLS is the main estimate): the sentence now ends by saying why export writes it."""
    from types import SimpleNamespace

    from dynid.report.summaries import in_short

    empty_log = SimpleNamespace(name="identification", metrics=lambda: {})
    result = SimpleNamespace(
        main_estimate=SimpleNamespace(label="dynid WLS"),
        consistency_verdicts={"dynid WLS": "no: link 2's inertia", "dynid SDP": "yes"},
        estimates={"dynid WLS": SimpleNamespace(standard=None), "dynid SDP": SimpleNamespace(standard=np.zeros(3))},
        fit=empty_log, validations=[], findings=[], estimators=["wls", "sdp"],
        solution=SimpleNamespace(from_prior=[], params=[], relative_std=[]), base=SimpleNamespace(names=[]), diagnostics={})
    lines = [line.text for line in in_short(result)]
    assert lines[1] == ("main estimate: dynid WLS, not physically consistent; dynid export writes dynid SDP, which is "
                        "physically consistent")
    # a consistent WLS (base parameters alone) exported as the SDP: said too (the simulated palletiser's; the line said
    # "physically consistent" and the first line "model ready: dynid SDP", with nothing between)
    consistent = SimpleNamespace(**{**vars(result), "consistency_verdicts": {"dynid WLS": "yes", "dynid SDP": "yes"}})
    assert [line.text for line in in_short(consistent)][1] == (
        "main estimate: dynid WLS, physically consistent; dynid export writes dynid SDP, the consistent estimate with a "
        "whole set of standard parameters (the main estimate's are base parameters alone)")
    exported = SimpleNamespace(**{**vars(consistent), "main_estimate": SimpleNamespace(label="dynid SDP"), "main": "dynid SDP"})
    assert [line.text for line in in_short(exported)][1] == "main estimate: dynid SDP, physically consistent"


def test_a_cutoff_candidate_not_scored_shows_a_dash_not_inf():
    """A candidate whose folds could not be fitted is stored as null in results.json: the table shows "—" (it
    showed "inf" in every cell, under a title that said the cutoffs were chosen by cross-validation)."""
    from dynid.report.choice_tables import filter_choice_table
    from dynid.tables import render_text

    cv = {"chosen": 0, "candidates": [{"position_cutoff": 10.0, "parallel_cutoff": 10.0, "decimation": 39},
                                      {"position_cutoff": 18.1, "parallel_cutoff": 18.1, "decimation": 22}],
          "out_of_fold_rms_error": [[None, None], [0.25, float("inf")]], "score": [None, 0.5]}
    text = render_text([filter_choice_table(cv)], 200)
    assert "inf" not in text and "None" not in text
    rows = [line.split() for line in text.splitlines() if line.strip().startswith(("10*", "18.1"))]
    assert rows == [["10*", "10", "39", "—", "—", "—"], ["18.1", "18.1", "22", "0.25", "—", "0.5"]]


def test_a_torque_offset_determined_to_be_about_zero_is_not_said_undetermined():
    """σ ≥ 100 % of a value near 0 is not "not determined" when ±σ is a negligible torque: the UR10e example listed its
    six offsets (truth 0, σ a few hundredths of a N·m) beside the inertial directions the log really leaves open. An
    offset whose ±σ is 1 % of its joint's torque or more is still listed; another term under 1 % is said "about 0 on
    this log's motion" (test below), since its ±σ torque on another motion may differ."""
    from types import SimpleNamespace

    from dynid.report.summaries import in_short

    names = ["offset1", "offset2", "MX2", "fc1"]
    empty_log = SimpleNamespace(name="identification", metrics=lambda: {})
    result = SimpleNamespace(
        main_estimate=SimpleNamespace(label="dynid WLS"), consistency_verdicts={}, estimates={}, fit=empty_log,
        validations=[], findings=[], estimators=["wls"], base=SimpleNamespace(names=names),
        solution=SimpleNamespace(from_prior=[], params=[0.01, 0.5, 0.2, 1.0], relative_std=[300.0, 300.0, 300.0, 2.0]),
        diagnostics={"sigma_torque_percent": {"offset1": 0.2, "offset2": 4.0, "MX2": 0.1, "fc1": 0.01}})
    lines = [ln.text for ln in in_short(result)]
    (line,) = [t for t in lines if t.startswith("not determined by this log")]
    assert ": offset2: " in line
    (line,) = [t for t in lines if t.startswith("about 0 on this log's motion")]
    assert ": MX2: " in line and "offset1" not in line


def test_a_sigma_the_bootstrap_finds_larger_decides_what_is_determined(tmp_path):
    """The covariance's σ assumes white residuals (the LBR Med7's is 9× below the moving-block bootstrap's): a
    parameter at 20 % by the covariance and 150 % by the bootstrap is not determined, in the summary and in the
    report's table, which shows both σ and the relative σ from the larger; one the bootstrap puts lower keeps the
    covariance's."""
    from types import SimpleNamespace

    from dynid.report.html import identify_sections
    from dynid.report.summaries import in_short, larger_relative_std

    assert larger_relative_std("MX2", -0.2, 20.0, {"MX2": 0.3}) == pytest.approx(150.0)
    assert larger_relative_std("MX2", 0.2, 20.0, {"MX2": 0.01}) == 20.0
    assert larger_relative_std("MX2", 0.2, 20.0, {}) == 20.0
    assert larger_relative_std("MX2", 0.2, None, {"MX2": 0.3}) is None
    names = ["MX2", "fc1"]
    boot = {"MX2": 0.3, "fc1": 0.001}
    empty_log = SimpleNamespace(name="identification", metrics=lambda: {})
    result = SimpleNamespace(
        main_estimate=SimpleNamespace(label="dynid WLS"), consistency_verdicts={}, estimates={}, fit=empty_log,
        validations=[], findings=[], estimators=["wls"], base=SimpleNamespace(names=names),
        solution=SimpleNamespace(from_prior=[], params=[-0.2, 1.0], relative_std=[20.0, 2.0]),
        diagnostics={"sigma_torque_percent": {}, "bootstrap_std": boot})
    (line,) = [ln.text for ln in in_short(result) if ln.text.startswith("not determined by this log")]
    assert ": MX2: " in line
    d = {"base_parameters": [{"name": n, "unit": "", "value": v, "std": s, "relative_std_percent": r, "expression": n}
                             for n, v, s, r in (("MX2", -0.2, 0.04, 20.0), ("fc1", 1.0, 0.02, 2.0))],
         "condition_number": 10.0, "n_rows": 100, "diagnostics": {"bootstrap_std": boot}}
    _, sections = identify_sections(d)
    (table,) = [t for sec in sections if sec.title == "Base parameters" for t in sec.tables][:1]
    assert table.headers[:6] == ["name", "unit", "value", "σ", "σ boot.", "σ %"]
    assert [row[3:6] for row in table.rows] == [["0.04", "0.3", "150"], ["0.02", "0.001", "2"]]
    assert table.flagged == {(0, 5)}


def test_the_base_parameter_table_shows_the_main_estimate_beside_least_squares():
    """The table's value and σ are least squares' (σ is theirs); where the main estimate is another (the SDP on
    the KR300's log: ZZ1R 1446 kg·m² against least squares' 1.5e5), its values stand beside them, marked, and the
    title names least squares. Where least squares is the main estimate, no column is added."""
    from dynid.report.html import identify_sections

    d = {"base_parameters": [{"name": n, "unit": "", "value": v, "std": 0.1, "relative_std_percent": 10.0,
                              "expression": n} for n, v in (("ZZ1R", 1.5e5), ("fc1", 344.0))],
         "condition_number": 10.0, "n_rows": 100, "least_squares": "wls", "main_estimate": "dynid SDP",
         "estimates": {"dynid WLS": {"key": "wls", "values": {"ZZ1R": 1.5e5, "fc1": 344.0}},
                       "dynid SDP": {"key": "sdp", "values": {"ZZ1R": 1446.0, "fc1": 436.0}}}}
    _, sections = identify_sections(d)
    table = next(t for sec in sections if sec.title == "Base parameters" for t in sec.tables)
    assert table.caption.startswith("dynid WLS with condition number")
    assert table.headers[:7] == ["name", "unit", "value", "σ", "σ %", "dynid SDP (main)", "expression"]
    assert [row[5] for row in table.rows] == ["1446", "436"]
    d["main_estimate"] = "dynid WLS"
    _, sections = identify_sections(d)
    table = next(t for sec in sections if sec.title == "Base parameters" for t in sec.tables)
    assert "dynid SDP (main)" not in table.headers and "dynid WLS (main)" not in table.headers


def test_a_parameter_near_zero_within_the_noise_is_said_apart_from_the_undetermined():
    """σ ≥ 100 % of a value near 0 (a link's MX2 where the link is symmetric) is not a poor excitation: where its ±σ
    torque on the identification log, scaled to the larger σ, is under 1 % of its joint's torque, the summary says
    "about 0 on this log's motion" instead of "not determined … a richer excitation determines them"."""
    from types import SimpleNamespace

    from dynid.report.summaries import in_short

    names = ["MX2", "XZ3", "MY4", "fc1"]
    share = {"MX2": 0.2, "XZ3": 0.6, "MY4": 3.0, "fc1": 0.1}  # ±σ torque, % of the joint's, from the covariance's σ
    boot = {"MX2": 0.001, "XZ3": 0.02, "MY4": 0.001, "fc1": 0.001}  # XZ3's bootstrap σ twice its covariance's: 1.2 %
    empty_log = SimpleNamespace(name="identification", metrics=lambda: {})
    result = SimpleNamespace(
        main_estimate=SimpleNamespace(label="dynid WLS"), consistency_verdicts={}, estimates={}, fit=empty_log,
        validations=[], findings=[], estimators=["wls"], base=SimpleNamespace(names=names),
        solution=SimpleNamespace(from_prior=[], params=[0.001, 0.01, 0.001, 1.0], relative_std=[150.0, 100.0, 150.0, 2.0]),
        diagnostics={"sigma_torque_percent": share, "bootstrap_std": boot})
    lines = [ln.text for ln in in_short(result)]
    (loose,) = [t for t in lines if t.startswith("not determined by this log")]
    (small,) = [t for t in lines if t.startswith("about 0 on this log's motion")]
    assert "): XZ3, MY4: " in loose and "): MX2: " in small and "fc1" not in loose + small
    from dynid.report.html import identify_sections  # the report highlights the undetermined ones only

    d = {"base_parameters": [{"name": n, "unit": "", "value": v, "std": v * r / 100, "relative_std_percent": r,
                              "expression": n} for n, v, r in zip(names, result.solution.params, result.solution.relative_std)],
         "condition_number": 10.0, "n_rows": 100, "diagnostics": result.diagnostics}
    _, sections = identify_sections(d)
    table = next(t for sec in sections if sec.title == "Base parameters" for t in sec.tables)
    assert table.flagged == {(1, 5), (2, 5)} and "about 0 on this motion" in table.caption
