import json

import pytest

from .refusals import assert_refused, dynid, dynid_process

FAST = ["--duration", "8", "--rate", "100", "--abc-iterations", "3"]


def test_run_is_the_papers_experiment_and_says_its_defaults_changed(tmp_path):
    """The main job as the paper set it: its Table 2 plant, its Table 3 box (amended where it misses Table 2, and
    said), OLS and the ABC at the paper's budget; the former default is --compare, and the change is said."""
    from dynid.studies import paper_reference as ref

    out = tmp_path / "run"
    p = dynid("run", "--out", str(out), *FAST, "--bootstrap", "0", "--no-figures")
    assert p.returncode == 0, p.stderr
    data = json.loads((out / "results.json").read_text())
    assert data["plant"] == "paper" and data["search_box"] == "table3" and list(data["estimates"]) == ["ols", "abc"]
    assert data["settings"]["colony_size"] == 30 and data["settings"]["limit"] == 15  # the paper's colony
    assert "now reproduces the paper's experiment" in p.stderr and "--compare" in p.stderr
    assert "±12" in p.stdout and "truth outside" not in p.stdout + p.stderr
    assert data["abc_bounds"]["fc2"] == [-12.0, 12.0] and -10 <= ref.TABLE3["f_c2"][0]  # the paper's printed scope kept
    assert ref.TABLE3["f_c2"][1] < ref.TABLE2["f_c2"] <= data["abc_bounds"]["fc2"][1]
    given = dynid("run", "--out", str(tmp_path / "given"), *FAST, "--plant", "paper", "--bootstrap", "0", "--no-figures")
    assert given.returncode == 0 and "now reproduces" not in given.stderr  # a user who chose says nothing


def test_run_compare_writes_results_and_figures(tmp_path):
    out = tmp_path / "run"
    p = dynid("run", "--out", str(out), *FAST, "--compare", "--verbose")
    assert p.returncode == 0, p.stderr
    assert "ρ (eq. 18)" in p.stdout and "0.3182" in p.stdout and "Base parameters: truth and estimates" in p.stdout
    data = json.loads((out / "results.json").read_text())
    assert data["robot"] == "er16" and data["joints"] == 3 and len(data["parameters"]) == 21 and data["plant"] == "assumed"
    assert "now reproduces" not in p.stderr
    assert set(data["estimates"]) == {"ols", "wls", "irls", "lad", "sdp", "abc", "abc10", "de", "pso"}
    assert "Estimators:" in p.stdout and "ABC×10" in p.stdout and "physically consistent" in p.stdout
    assert "moving-block" in p.stdout and set(data["estimates"]["ols"]["bootstrap"]) >= {"lower", "upper", "std"}
    assert len(list(out.glob("fig*.png"))) == 6 and len(list(out.glob("methods_*.png"))) == 2
    assert not list(out.glob(".*tmp"))


@pytest.mark.parametrize("args, message", [
    (["--robot", "nosuch"], "unknown robot"),
    (["--joints", "9"], "between 1 and 6"),
    (["--seed", "-1"], "--seed must be a non-negative integer, got -1"),
    (["--rate", "-5"], "rate"),
    (["--weights", "1,x"], "weights"),
    (["--estimators", "ols,bogus"], "--estimators"),
    (["--bootstrap", "1"], "--bootstrap"),
])
def test_bad_options_get_one_line_errors(tmp_path, args, message):
    p = dynid("run", "--out", str(tmp_path / "o"), *FAST, *args)
    assert_refused(p, message, tmp_path / "o")


def test_methods_subset_without_abc(tmp_path):
    out = tmp_path / "run"
    p = dynid("run", "--out", str(out), *FAST, "--estimators", "ols,lad", "--bootstrap", "0")
    assert p.returncode == 0, p.stderr
    data = json.loads((out / "results.json").read_text())
    assert list(data["estimates"]) == ["ols", "lad"] and "bootstrap" not in data["estimates"]["ols"]
    assert not (out / "fig6_abc_convergence.png").exists() and (out / "methods_comparison.png").exists()
    # piped: one progress line per step on standard error, each once, the tables on standard output
    steps = [line for line in p.stderr.splitlines() if line.startswith("dynid run: ")]
    names = [s.split(" (at")[0].removeprefix("dynid run: ") for s in steps]
    assert names[0] == "simulation and preprocessing" and names[-1] == "writing results and figures"
    assert sorted(names[1:-1]) == ["LAD", "OLS"]  # side by side: in either order
    assert "Estimators:" in p.stdout and "dynid run:" not in p.stdout
    # without --verbose: the estimators' table and the verdict, not the parameters' and per-joint tables
    data = json.loads((out / "results.json").read_text())
    best = min(data["estimates"], key=lambda k: data["estimates"][k]["parameter_error_norm_percent"])
    assert f"nearest the truth: {best.upper()} (Δβ" in p.stdout and "--verbose" in p.stdout
    assert "ρ (eq. 18) per joint" not in p.stdout and "truth and estimates" not in p.stdout


@pytest.mark.parametrize("signame, code, said", [("SIGINT", 130, "Ctrl-C"), ("SIGTERM", 143, "SIGTERM")])
def test_ctrl_c_and_sigterm_exit_with_one_line_and_leave_no_output(tmp_path, signame, code, said):
    """A real process and a real SIGINT (SIGTERM: what a process manager or a batch system sends), while the
    estimators run."""
    import os
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "o"
    proc = subprocess.Popen([sys.executable, "-m", "dynid", "run", "--out", str(out), "--estimators", "abc10,de", "--bootstrap", "0"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env={**os.environ, "MPLBACKEND": "Agg"})
    for line in proc.stderr:  # piped: one line per step; interrupt once the estimators started
        if line.startswith("dynid run: ABC×10") or line.startswith("dynid run: DE"):
            break
    time.sleep(0.3)
    proc.send_signal(getattr(signal, signame))
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == code, (proc.returncode, stderr)
    lines = stderr.strip().splitlines()
    assert lines[-1] == f"interrupted ({said})" and all(line.startswith("dynid run: ") for line in lines[:-1]), lines
    assert "Traceback" not in stdout + stderr
    assert not out.exists() or not any(out.iterdir())


def test_quiet_prints_nothing_but_warnings(tmp_path):
    p = dynid("run", "--out", str(tmp_path / "q"), *FAST, "--estimators", "ols,abc", "--bootstrap", "0", "--no-figures", "--quiet",
              "--abc-bounds", "table3", "--plant", "assumed")  # the paper's box misses the assumed plant: a warning
    assert p.returncode == 0, p.stderr
    assert p.stdout == "" and all(line.startswith("warning: ") for line in p.stderr.splitlines())
    assert "truth outside the ABC search box" in p.stderr and (tmp_path / "q" / "results.json").is_file()


def test_main_takes_argv_and_returns_the_exit_code(tmp_path, capsys):
    from dynid import __version__
    from dynid.cli.app import main

    assert main(["--version"]) == 0 and capsys.readouterr().out.strip() == f"dynid {__version__}"
    assert main(["run", "--no-such-option"]) == 2
    missing = tmp_path / "missing.toml"
    assert main(["identify", str(missing), "--out", str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err
    assert "missing.toml" in err and "Traceback" not in err and not (tmp_path / "o").exists()


def test_usage_error_exit_2():
    p = dynid("run", "--no-such-option")
    assert p.returncode == 2


def test_out_is_a_file(tmp_path):
    f = tmp_path / "file"
    f.write_text("x")
    p = dynid("run", "--out", str(f), *FAST)
    assert p.returncode == 1 and "not a folder" in p.stderr


def test_same_seed_gives_the_same_results_json_except_timings(tmp_path):
    """Two runs with the same seed write the same results.json, but for the fields named as timings."""

    def load(out):
        data = json.loads((out / "results.json").read_text())

        def strip(x):
            if isinstance(x, dict):
                return {k: strip(v) for k, v in x.items() if k not in ("timings", "seconds")}
            if isinstance(x, list):
                return [strip(v) for v in x]
            return x

        return strip(data)

    args = ("--estimators", "ols,wls,abc,pso,sdp", "--bootstrap", "10", "--duration", "6", "--no-figures", "--seed", "7")
    a, b = tmp_path / "a", tmp_path / "b"
    for out in (a, b):  # two processes, as two runs of a user (in one process the SDP's compiled problem is reused,
        p = dynid_process("run", "--out", str(out), *args)  # and its margin may differ in the 13th digit)
        assert p.returncode == 0, p.stderr
    assert load(a) == load(b)
    assert json.loads((a / "results.json").read_text())["estimates"]["abc"]["seconds"] >= 0  # the timings are there


def test_a_config_is_checked_before_any_heavy_import(tmp_path):
    """A typo in a config is reported from the light modules alone (the start-up target of make bench: < 0.5 s):
    neither SciPy nor Pinocchio is imported before the config is read (an import of the identification pipeline at the
    top of identification_run took it from 0.37 to 1.38 s)."""
    import subprocess
    import sys

    (tmp_path / "typo.toml").write_text('robot = "ur10e"\n[identificaton]\n')
    code = ("import sys\nfrom dynid.cli.app import main\nrc = main(['identify', sys.argv[1]])\n"
            "heavy = sorted(m for m in ('scipy', 'pinocchio', 'numba', 'cvxpy', 'matplotlib') if m in sys.modules)\n"
            "print(rc, heavy)\n")
    p = subprocess.run([sys.executable, "-c", code, str(tmp_path / "typo.toml")], capture_output=True, text=True, timeout=120)
    assert p.stdout.strip().splitlines()[-1] == "1 []", (p.stdout, p.stderr)
    assert "identificaton" in p.stderr


def test_a_setting_said_otherwise_now_is_one_warning_line(capfd, monkeypatch):
    """A setting that changed (a ``FutureWarning``: it names the setting and the new spelling) is said as the command's
    other warnings are, one line, not as Python's FutureWarning with a source line; any other warning as Python shows
    it, with where it came from. ``main`` shows a command's warnings this way."""
    import warnings

    from dynid.cli import app as cli
    from dynid.cli.app import _show_warning

    def command(args, prog_name):  # a command whose library call warns of a changed setting
        warnings.warn("f: seed= is now rng=", FutureWarning, stacklevel=1)

    monkeypatch.setattr(cli, "app", command)
    assert cli.main([]) == 0
    assert capfd.readouterr().err.splitlines() == ["warning: f: seed= is now rng="]

    _show_warning(FutureWarning('f: seed= is now rng='), FutureWarning, "lib.py", 7)
    err = capfd.readouterr().err
    assert err.splitlines() == ["warning: f: seed= is now rng="] and "FutureWarning" not in err and "lib.py" not in err
    _show_warning(RuntimeWarning("overflow"), RuntimeWarning, "lib.py", 7)
    assert capfd.readouterr().err == warnings.formatwarning("overflow", RuntimeWarning, "lib.py", 7)
