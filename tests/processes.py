"""Commands that tests start, under deadlines: nothing a test starts can hang the suite.

- `run_bounded`: subprocess.run with a timeout that kills the whole process tree and fails the
  test with the output so far. (hydra's mpiexec puts its proxy and every rank in a session of
  their own: killing mpiexec, or its process group, does not reach them.)
- `Started`: a command in the background whose output threads collect, so that the test never
  blocks on a read; it waits on conditions (`wait_for`) and for the exit (`wait`), each with a
  deadline, and leaving its `with` block kills whatever is left.
- `wait_for`: poll a condition until a deadline, instead of sleeping a guessed length.
- `package_copy`: the packages copied into a folder, for a test that adds a file to them, and the
  environment of a command run on the copy.
- `ensemble_here`: `python -m ensemble ...` in this process, for a command that needs no process of
  its own (no signal, kill or crash, no mpiexec): a process costs ~2.5 s of imports and kernel
  loading, more than a test's small run.

Every command gets no standard input (CI has none; a read must not wait for a terminal).
"""
import os
import shutil
import signal
import subprocess
import threading
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
POLL_SECONDS = 0.05
REAP_SECONDS = 30        # after SIGKILL: for the process to be reaped and its pipes to close
SHOWN_CHARS = 6000       # of a command's output in a failure message (its end)


def child_env(**extra):
    """The environment of a command a test starts: the session's, the numba cache of this checkout
    unless the session names one, one thread per process (the ranks are the parallelism)."""
    env = dict(os.environ)
    env.setdefault("NUMBA_CACHE_DIR", str(ROOT / ".numba_cache"))
    env.update(OMP_NUM_THREADS="1", NUMBA_NUM_THREADS="1")
    env.update(extra)
    return env


def package_copy(tree, *packages, own_cache=False):
    """Copy this checkout's `packages` ("ensemble", "analysis") into the folder `tree`, for a test that adds a
    file to the copy; returns the environment of a command run on the copy (own_cache: a numba cache of its
    own in the tree, for a copy whose kernel sources differ)."""
    for name in packages:
        shutil.copytree(ROOT / name, tree / name, ignore=shutil.ignore_patterns("__pycache__"))
    return child_env(PYTHONPATH=str(tree), **({"NUMBA_CACHE_DIR": str(tree / ".numba_cache")} if own_cache else {}))


def _children():
    """{parent pid: [child pids]} of every process on this machine, from /proc."""
    out = {}
    for entry in os.scandir("/proc"):
        if not entry.name.isdigit():
            continue
        try:
            with open(f"/proc/{entry.name}/stat") as fh:
                ppid = int(fh.read().rsplit(")", 1)[1].split()[1])
        except (OSError, IndexError, ValueError):
            continue        # ended meanwhile
        out.setdefault(ppid, []).append(int(entry.name))
    return out


def descendants(pid):
    """PIDs below process `pid` (children, theirs, ...), whatever their session or group."""
    children = _children()
    found, todo = [], [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found.append(child)
            todo.append(child)
    return found


def _send(pid, sig, group=False):
    try:
        (os.killpg if group else os.kill)(pid, sig)
    except (ProcessLookupError, PermissionError):
        pass


def kill_tree(proc):
    """SIGKILL a Popen started with start_new_session=True and everything below it; reap it."""
    if proc.poll() is None:
        # Stop the tree before killing it, so that nothing forks, or exits and leaves its
        # children to init (out of our sight), while it is read.
        stopped = set()
        while True:
            new = [p for p in [proc.pid, *descendants(proc.pid)] if p not in stopped]
            if not new:
                break
            for pid in new:
                _send(pid, signal.SIGSTOP)
            stopped.update(new)
        for pid in stopped:
            _send(pid, signal.SIGKILL)
    # the process group outlives its leader: what is left of it after the leader ended
    _send(proc.pid, signal.SIGKILL, group=True)
    try:
        proc.wait(timeout=REAP_SECONDS)
    except subprocess.TimeoutExpired:
        pass            # in uninterruptible sleep: nothing more to be done from here


def _show(cmd):
    return " ".join(map(str, cmd))


def _tail(text):
    text = text or ""
    return text if len(text) <= SHOWN_CHARS else "[...]\n" + text[-SHOWN_CHARS:]


def _captured(out, err=None):
    parts = [f"--- output ---\n{_tail(out)}"]
    if err is not None:
        parts.append(f"--- stderr ---\n{_tail(err)}")
    return "\n".join(parts)


def run_bounded(cmd, timeout, **kwargs):
    """subprocess.run(cmd, capture_output=True, text=True, stdin=DEVNULL, **kwargs), for tests.

    After `timeout` seconds the command and every process below it are killed and the test
    fails with what they printed; an exception meanwhile (the per-test timeout, Ctrl-C) kills
    them too. Returns a CompletedProcess.
    """
    cmd = [str(c) for c in cmd]
    kwargs.setdefault("stdin", subprocess.DEVNULL)
    kwargs.setdefault("stdout", subprocess.PIPE)
    kwargs.setdefault("stderr", subprocess.PIPE)
    kwargs.setdefault("text", True)
    if kwargs["text"]:
        kwargs.setdefault("errors", "replace")
    proc = subprocess.Popen(cmd, start_new_session=True, **kwargs)
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        kill_tree(proc)
        try:
            out, err = proc.communicate(timeout=REAP_SECONDS)    # what was printed until then
        except (subprocess.TimeoutExpired, ValueError):
            out, err = "(not readable)", None
        pytest.fail(f"{_show(cmd)}: still running after {timeout} s, killed\n{_captured(out, err)}")
    except BaseException:
        kill_tree(proc)
        raise
    return subprocess.CompletedProcess(cmd, proc.returncode, out, err)


def _here(package, main, args):
    """`python -m PACKAGE ARGS` run by its `main` in this process: a CompletedProcess with its exit code
    (argparse's own errors exit) and what it printed."""
    import contextlib
    import io
    argv = [str(a) for a in args]
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        try:
            code = main(argv)
        except SystemExit as done:
            code = done.code
    return subprocess.CompletedProcess([f"python -m {package}", *argv], code, stdout.getvalue(), stderr.getvalue())


def ensemble_here(*args):
    """`python -m ensemble ARGS` run by ensemble.cli.main in this process (one rank). The handlers of the
    stop signals are put back afterwards (a run leaves its own, which acknowledge a late signal instead of
    obeying it)."""
    from ensemble import cli
    from ensemble.run.parallel import INTERRUPT_SIGNALS
    handlers = {sig: signal.getsignal(sig) for sig in INTERRUPT_SIGNALS}
    try:
        return _here("ensemble", cli.main, args)
    finally:
        for sig, handler in handlers.items():
            signal.signal(sig, handler)


def analysis_here(*args):
    """`python -m analysis ARGS` run by analysis.cli.main in this process."""
    from analysis import cli
    return _here("analysis", cli.main, args)


def poll_until(condition, timeout):
    """Poll `condition()` until it is true (returns True) or `timeout` seconds pass (False)."""
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(POLL_SECONDS)
    return True


def wait_for(condition, timeout, what, started=None):
    """Poll `condition()` until it is true; fail naming `what` after `timeout` seconds, or as soon
    as the command `started` (a Started) has ended without it, showing its output."""
    deadline = time.monotonic() + timeout
    while True:
        ended = started is not None and started.proc.poll() is not None
        if condition():         # checked after `ended`: a command may meet it and exit at once
            return
        if ended:
            pytest.fail(f"{what}: {_show(started.cmd)} ended (exit {started.proc.returncode}) "
                        f"before that\n{started.captured()}")
        if time.monotonic() > deadline:
            pytest.fail(f"{what}: not within {timeout} s"
                        + (f"\n{started.captured()}" if started is not None else ""))
        time.sleep(POLL_SECONDS)


def _collect(stream, lines, limit):
    """Read `stream` line by line into `lines` (in a thread); close it at EOF or after `limit` lines."""
    try:
        for line in stream:
            lines.append(line)
            if limit is not None and len(lines) >= limit:
                break
    except (OSError, ValueError):
        pass
    finally:
        stream.close()


class Started:
    """`cmd` running in the background in a session of its own, its output read by threads.

    stdout and stderr are one stream (`lines`, `output`) unless separate_stderr (then also
    `err_lines`, `errors`). stdout_lines=n: the reader closes stdout after n lines, as
    `| head -n` does. Use as a context manager: leaving the block kills what is left.
    """

    def __init__(self, cmd, *, env=None, cwd=None, separate_stderr=False, stdout_lines=None):
        self.cmd = [str(c) for c in cmd]
        self.proc = subprocess.Popen(
            self.cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
            stderr=subprocess.PIPE if separate_stderr else subprocess.STDOUT,
            text=True, errors="replace", env=env, cwd=cwd, start_new_session=True)
        self.pid = self.proc.pid
        self.lines, self.err_lines = [], []
        self._readers = [threading.Thread(target=_collect, args=(self.proc.stdout, self.lines, stdout_lines),
                                          daemon=True)]
        if separate_stderr:
            self._readers.append(threading.Thread(target=_collect, args=(self.proc.stderr, self.err_lines, None),
                                                  daemon=True))
        for reader in self._readers:
            reader.start()

    @property
    def output(self):
        return "".join(self.lines)

    @property
    def errors(self):
        return "".join(self.err_lines)

    def captured(self):
        return _captured(self.output, self.errors if len(self._readers) > 1 else None)

    @property
    def running(self):
        return self.proc.poll() is None

    def send_signal(self, sig):
        self.proc.send_signal(sig)

    def _join_readers(self):
        """Wait for the output to end (the pipes close when every process holding them ended)."""
        deadline = time.monotonic() + REAP_SECONDS
        for reader in self._readers:
            reader.join(max(0.0, deadline - time.monotonic()))
        if any(reader.is_alive() for reader in self._readers):
            _send(self.pid, signal.SIGKILL, group=True)    # left-overs of its group still hold them
            for reader in self._readers:
                reader.join(5)

    def wait(self, timeout, what=None):
        """The exit code, once the command has ended and its output is read; after `timeout`
        seconds the command is killed and the test fails showing the output."""
        try:
            self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.kill()
            pytest.fail(f"{what or _show(self.cmd)}: still running after {timeout} s, killed\n"
                        f"{self.captured()}")
        self._join_readers()
        return self.proc.returncode

    def kill(self):
        kill_tree(self.proc)
        self._join_readers()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self.running:
            self.kill()
