"""Work handed to a forked child gives what calling it here gives: its value, its user errors, and when the
child leaves no answer, the value computed here."""

import os
import signal
import sys

import numpy as np
import pytest

from dynid.exceptions import ConfigError
from dynid.runtime.processes import ForkedCall, allow_forks, can_fork
from dynid.runtime.threads import cores

PARENT = os.getpid()
needs_fork = pytest.mark.skipif(not (sys.platform.startswith("linux") and cores() >= 2), reason="needs fork and two cores")


@pytest.fixture
def forks():
    with allow_forks():
        yield


def _where_and_value(n):
    return os.getpid(), np.arange(n) ** 2


def _config_error():
    raise ConfigError("estimation.method: expected ols or wls, got 'x'", field="estimation.method")


def _fails_in_a_child():
    if os.getpid() != PARENT:
        raise RuntimeError("a bug that only the child meets")
    return "computed here"


def _dies_in_a_child():
    if os.getpid() != PARENT:
        os.kill(os.getpid(), signal.SIGKILL)
    return "computed here"


def _unpicklable_in_a_child():
    return (lambda: None) if os.getpid() != PARENT else "computed here"


@needs_fork
def test_the_value_is_computed_in_the_child_and_returned(forks):
    pid, value = ForkedCall(_where_and_value, 5).result()
    assert pid != PARENT
    np.testing.assert_array_equal(value, [0, 1, 4, 9, 16])


@needs_fork
def test_a_user_error_in_the_child_is_raised_here_with_its_field(forks):
    call = ForkedCall(_config_error)
    with pytest.raises(ConfigError, match="expected ols or wls") as info:
        call.result()
    assert info.value.field == "estimation.method"


@needs_fork
@pytest.mark.parametrize("fn", [_fails_in_a_child, _dies_in_a_child, _unpicklable_in_a_child])
def test_without_an_answer_from_the_child_the_call_is_made_here(fn, forks):
    assert ForkedCall(fn).result() == "computed here"


def test_outside_allow_forks_the_call_is_made_here():
    """The library alone never forks: a caller's process may run threads whose locks a child would inherit."""
    assert not can_fork()
    pid, value = ForkedCall(_where_and_value, 3).result()
    assert pid == PARENT and value.tolist() == [0, 1, 4]
    with pytest.raises(ConfigError):
        ForkedCall(_config_error).result()
    with allow_forks():
        assert can_fork() == (sys.platform.startswith("linux") and cores() >= 2)
    assert not can_fork()


def _sleeps():
    import time

    time.sleep(60)
    return "late"


@needs_fork
def test_a_child_whose_answer_is_not_taken_is_stopped_when_the_block_ends(forks):
    with pytest.raises(ValueError):
        with ForkedCall(_sleeps) as call:
            child = call._child
            assert child is not None and child.is_alive()
            raise ValueError("the work the answer was for failed")
    assert child.exitcode == -signal.SIGKILL  # stopped and waited for, not left for a minute
    with pytest.raises(ChildProcessError):
        os.waitpid(child.pid, os.WNOHANG)
