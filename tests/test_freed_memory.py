"""The command line keeps freed memory for reuse (dynid.runtime.memory): a process that makes and frees arrays of tens
of megabytes again and again, as a long log's preparation does, is not handed the same memory cleared anew each time.

Measured in fresh processes by the system's own count of the memory it cleared for them (minor page faults)."""

import subprocess
import sys

import pytest

SCRIPT = """
import resource, sys
import numpy as np
if sys.argv[1] == "kept":
    from dynid.runtime.memory import keep_freed_memory
    assert keep_freed_memory()
def rounds(k):
    for _ in range(k):
        arrays = [np.ones(30 * 2**20 // 8) for _ in range(3)]  # three 30 MB columns, written
        del arrays
rounds(2)
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
rounds(5)
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


def _faults(mode: str) -> int:
    p = subprocess.run([sys.executable, "-c", SCRIPT, mode], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    return int(p.stdout.split()[-1])


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's allocator: Linux only")
def test_freed_columns_are_reused_instead_of_cleared_anew():
    default, kept = _faults("default"), _faults("kept")
    assert default >= 5 * 15, default  # glibc's default gives the 90 MB back each round: at least 2 MB pages again
    assert kept < default / 5, (kept, default)


def test_the_console_script_keeps_freed_memory_and_a_callers_process_is_left_alone(monkeypatch):
    import gc

    import dynid.runtime.memory as memory
    from dynid.cli.app import main

    calls = []
    monkeypatch.setattr(gc, "freeze", lambda: None)  # the console script's end of process, not this one's
    monkeypatch.setattr(memory, "keep_freed_memory", lambda: calls.append(1) or True)
    assert main(["--help"]) == 0 and calls == []  # a caller's process: its allocator as it was
    monkeypatch.setattr(sys, "argv", ["dynid", "--help"])
    assert main() == 0 and calls == [1]
