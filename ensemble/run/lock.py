"""One run per catalog: an exclusive lock file beside it, held by rank 0 for the run's lifetime.

`PATH.lock` is taken before anything of the run is opened or decided (so a second
`run`, `--force` or `--resume` on the same output is refused while the first one
lives) and removed on every orderly exit. The lock itself is an flock() on the
file, which the operating system drops when the holding process dies, however it
dies; the file's text (host, pid, start, a heartbeat and the latest progress line,
rewritten every few seconds by a thread) is for people and for `status`.

A lock file left behind by a run that died (kill -9, MPI_Abort, node failure) is
recognised by the free flock plus either a dead pid on this host or a heartbeat
older than STALE_SECONDS; it is then taken over with a note. A lock file whose
flock is free but whose heartbeat is fresh and whose host is another one can
mean a file system without shared locks (Lustre `localflock`): that is refused
with the command that removes it, not guessed at.
"""
import errno
import fcntl
import os
import socket
import stat
import threading
import time

HEARTBEAT_SECONDS = 5.0
STALE_SECONDS = 60.0
# file systems without flock() support answer with one of these
_NO_FLOCK = (errno.ENOSYS, errno.EOPNOTSUPP, errno.ENOLCK, errno.EINVAL)


class LockError(RuntimeError):
    """The output is in use by another run, or its lock cannot be taken; the message says which."""


def lock_path(path):
    """The lock file of the catalog `path` (its final name, not the .partial)."""
    return str(path) + ".lock"


def _parse(text):
    """The key: value lines of a lock file (tolerant: it may be read while it is rewritten)."""
    out = {}
    for line in text.splitlines():
        key, sep, value = line.partition(": ")
        if sep:
            out[key.strip()] = value.strip()
    return out


def _pid_alive(pid):
    """Whether process `pid` of this host runs (a zombie, killed but not yet reaped, does not)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return True


def read_info(path):
    """The fields of the lock file of catalog `path` ({} if there is none)."""
    try:
        with open(lock_path(path)) as fh:
            return _parse(fh.read())
    except (FileNotFoundError, IsADirectoryError, UnicodeDecodeError):
        return {}


def is_held(path):
    """True if a live process holds the lock of catalog `path` (checked without taking it for long)."""
    try:
        fd = os.open(lock_path(path), os.O_RDONLY)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except OSError as err:
        if err.errno in _NO_FLOCK:
            info = read_info(path)
            return time.time() - float(info.get("heartbeat", 0) or 0) < STALE_SECONDS
        return True
    finally:
        os.close(fd)
    return False


def describe(info):
    """'pid P on host H, started ..., last heartbeat N s ago' from the fields of a lock file."""
    age = time.time() - float(info.get("heartbeat", 0) or 0)
    return (f"pid {info.get('pid', '?')} on host {info.get('host', '?')}, started {info.get('started', '?')}, "
            f"last heartbeat {age:.0f} s ago")


class RunLock:
    """The lock of one catalog path; `acquire` raises LockError if another run holds it."""

    def __init__(self, path, command=""):
        self.path = str(path)
        self.file = lock_path(path)
        self.command = command
        self.fd = None
        self.note = None          # set when a stale lock was taken over
        self.started = time.strftime("%Y-%m-%d %H:%M:%S")
        self._progress = "starting"
        self._stop = threading.Event()
        self._thread = None
        self._flock = True

    def acquire(self):
        """Take the lock (retrying briefly: `status` may hold a shared lock for a moment)."""
        deadline = time.monotonic() + 1.0
        while True:
            try:
                return self._try_acquire()
            except _Busy as busy:
                if time.monotonic() > deadline:
                    raise LockError(f"{self.path}: in use by another run ({describe(busy.info)}); "
                                    f"wait for it to finish or stop it") from None
                time.sleep(0.05)

    def _try_acquire(self):
        try:
            # never through a link (ELOOP), and never blocking on a FIFO put there (a regular file is checked next).
            # decision.check_output refuses a link here before the run starts; this is the guard for one made
            # after that check (the lock is the one file not written by space.write_file: it stays open)
            fd = os.open(self.file, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK, 0o644)
        except OSError as err:
            if err.errno == errno.ELOOP:
                raise LockError(f"{self.file}: the lock file is a symbolic link; a lock is never written through "
                                f"a link: remove it (rm {self.file}) and start again") from None
            raise LockError(f"{self.file}: cannot create the lock file ({err.strerror})") from None
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            os.close(fd)
            raise LockError(f"{self.file}: not a regular file, so not a lock of this package: remove it and start "
                            f"again")
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as err:
            if err.errno not in _NO_FLOCK:
                info = _parse(os.pread(fd, 4096, 0).decode(errors="replace"))
                os.close(fd)
                raise _Busy(info) from None
            self._flock = False   # only the heartbeat can tell a live run here
        # The file may have been removed (and another run created a new one) between
        # our open and our flock: then we hold a lock nobody else sees. Start over.
        try:
            same = os.stat(self.file).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            same = False
        if not same:
            os.close(fd)
            return self._try_acquire()
        text = os.pread(fd, 4096, 0).decode(errors="replace")
        info = _parse(text)
        if text.strip() and not {"host", "pid"} <= set(info):
            os.close(fd)        # a file of someone else's at the lock's name: not ours to overwrite
            raise LockError(f"{self.file}: exists and is not a lock of this package (no host and pid); it is left "
                            f"as it is: move it away and start again")
        if info:
            self._judge_leftover(fd, info)
        self.fd = fd
        self._write()
        self._thread = threading.Thread(target=self._beat, name="lock-heartbeat", daemon=True)
        self._thread.start()
        return self

    def _judge_leftover(self, fd, info):
        """A lock file whose lock is free: a dead run's (taken over) or unclear (refused)."""
        host = info.get("host")
        try:
            pid = int(info.get("pid", ""))
        except ValueError:
            pid = None
        age = time.time() - float(info.get("heartbeat", 0) or 0)
        dead_here = host == socket.gethostname() and pid is not None and not _pid_alive(pid)
        if dead_here or age > STALE_SECONDS:
            self.note = f"took over the lock left by a run that died ({describe(info)})"
            return
        os.close(fd)
        if not self._flock:
            raise _Busy(info)
        raise LockError(f"{self.file}: left by {describe(info)}, which this file system cannot confirm "
                        f"as dead; if no run is using {self.path}, remove the lock file "
                        f"(rm {self.file}) and start again")

    def _write(self):
        text = (f"host: {socket.gethostname()}\npid: {os.getpid()}\nstarted: {self.started}\n"
                f"heartbeat: {time.time():.1f}\ncommand: {self.command}\nprogress: {self._progress}\n")
        data = text.encode()
        os.pwrite(self.fd, data, 0)
        os.ftruncate(self.fd, len(data))

    def _beat(self):
        while not self._stop.wait(HEARTBEAT_SECONDS):
            try:
                self._write()
            except OSError:
                pass    # a full disk must not kill the run from here; the writer reports it

    def progress(self, line):
        """The latest progress line (shown by `status` while the run lives)."""
        self._progress = line.replace("\n", " ")

    def release(self):
        """Remove the lock file, then drop the lock (in that order: see _try_acquire)."""
        if self.fd is None:
            return
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
        try:
            os.unlink(self.file)
        except FileNotFoundError:
            pass
        os.close(self.fd)
        self.fd = None

    def __enter__(self):
        return self.acquire()

    def __exit__(self, *exc):
        self.release()


class _Busy(Exception):
    def __init__(self, info):
        super().__init__("busy")
        self.info = info
