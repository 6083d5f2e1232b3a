"""The deadlines of tests/processes.py: a command past its time is killed with everything below it
(mpiexec's ranks too) and the test fails showing what it printed."""
import os
import shutil
import sys

import pytest

from .processes import Started, poll_until, run_bounded, wait_for


def sleeper(directory):
    """A command that says hello, leaves a file named by its pid in `directory`, then sleeps far
    longer than any deadline below (files, not output: mpiexec may interleave the ranks' lines)."""
    return [sys.executable, "-c", "import os, sys, time; print('hello', flush=True); "
            "open(os.path.join(sys.argv[1], str(os.getpid())), 'w').close(); time.sleep(600)", directory]


def pids(directory):
    return [int(name) for name in os.listdir(directory)]


def gone(pid):
    """True if `pid` has ended (a zombie waiting for its parent counts as ended)."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] == "Z"
    except FileNotFoundError:
        return True


def assert_all_gone(found):
    assert poll_until(lambda: all(gone(p) for p in found), 30), [p for p in found if not gone(p)]


def test_run_bounded_kills_a_command_past_its_timeout_and_shows_its_output(tmp_path):
    with pytest.raises(pytest.fail.Exception, match=r"still running after 2 s, killed") as failure:
        run_bounded(sleeper(tmp_path), 2)
    found = pids(tmp_path)        # (empty if it did not get as far in 2 s)
    assert_all_gone(found)
    assert "hello" in str(failure.value) or not found     # what it printed, in the failure


@pytest.mark.mpi
@pytest.mark.skipif(shutil.which("mpiexec") is None, reason="mpiexec not found")
def test_the_ranks_of_mpiexec_are_killed_too(tmp_path):
    """hydra starts each rank in a session of its own: out of reach of mpiexec's process group."""
    with Started(["mpiexec", "-n", "2", *sleeper(tmp_path)]) as proc:
        wait_for(lambda: len(pids(tmp_path)) == 2, 120, "both ranks started", proc)
        with pytest.raises(pytest.fail.Exception, match="still running after 1 s, killed"):
            proc.wait(1)
    assert_all_gone(pids(tmp_path))


def test_wait_for_fails_when_the_command_ends_first_or_time_runs_out(tmp_path):
    with Started([sys.executable, "-c", "print('bye')"]) as proc:
        with pytest.raises(pytest.fail.Exception, match=r"a line 'never': .* ended \(exit 0\) before that"):
            wait_for(lambda: "never" in proc.output, 60, "a line 'never'", proc)
    with Started(sleeper(tmp_path)) as proc:
        with pytest.raises(pytest.fail.Exception, match=r"a line 'never': not within 0.2 s"):
            wait_for(lambda: "never" in proc.output, 0.2, "a line 'never'", proc)
    assert proc.proc.returncode is not None       # killed on leaving the block
