"""Running the CLI as a user does, and what a clean refusal is (issue "Every bad input refused cleanly")."""

import os
import re
import subprocess
import sys
from types import SimpleNamespace

PROGRESS = re.compile(r"^dynid \w+: ")


def dynid_process(*args, cwd=None, env=None, stdin=None):
    """``dynid ARGS`` in a fresh process, output captured (a pipe: no terminal). For what only a process shows:
    what C++ libraries print on the process's standard error, signals, the console script itself."""
    return subprocess.run([sys.executable, "-m", "dynid", *args], capture_output=True, text=True, cwd=cwd, timeout=600,
                          env=None if env is None else {**os.environ, **env}, input=stdin)


def dynid(*args, cwd=None, env=None, stdin=None):
    """``dynid ARGS`` in this process (typer's runner), output captured as a pipe would: the same exit code,
    standard output and standard error as :func:`dynid_process`, without starting Python and importing the
    libraries again for every call. An exception that escapes a command is raised here."""
    import contextlib

    from typer.testing import CliRunner

    from dynid.cli.app import app

    with contextlib.chdir(cwd) if cwd is not None else contextlib.nullcontext():
        result = CliRunner().invoke(app, [str(a) for a in args], env=env, input=stdin)
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        raise result.exception
    return SimpleNamespace(returncode=result.exit_code, stdout=result.stdout, stderr=result.stderr)


def snapshot(folder):
    """Names and contents of the files in ``folder`` (None if it does not exist)."""
    if not folder.exists():
        return None
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def check_refusal(code, stdout, stderr, message, out=None, before=None):
    """Exit code 1, no traceback, exactly one error line holding ``message`` (the other lines on standard error
    are progress lines or warnings), and ``out`` absent or as it was (``before``: :func:`snapshot` taken
    earlier)."""
    assert code == 1, (code, stdout, stderr)
    assert "Traceback" not in stderr + stdout, stderr
    lines = [line for line in stderr.splitlines() if line.strip()]
    errors = [line for line in lines if line.startswith("error: ")]
    assert len(errors) == 1 and message in errors[0], lines
    if os.environ.get("DYNID_SHOW_REFUSALS"):  # to read the messages: DYNID_SHOW_REFUSALS=1 pytest -s
        print("\n" + errors[0])
    assert all(PROGRESS.match(line) or line.startswith("warning: ") for line in lines if not line.startswith("error: ")), lines
    if out is not None:
        assert snapshot(out) == before, f"{out} changed"


def assert_refused(p, message, out=None, before=None):
    """:func:`check_refusal` of a finished process."""
    check_refusal(p.returncode, p.stdout, p.stderr, message, out, before)
