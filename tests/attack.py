"""Attacks at the edges, repeatable: full disks under MPI, file-size limits, damaged tables and config,
collective steps failing on one rank, and inputs nobody meant. Each attack says what must hold.

    python tests/attack.py              # every attack; a table of held / FAILED / skipped; exit 1 if any failed
    python tests/attack.py flip mpi     # those whose name contains one of the words

tests/test_attacks.py runs each attack as a test (the suite, and so CI); run this script for
the table. The tmpfs attacks need root (mount); elsewhere they are skipped, saying so. Every command
runs under a deadline (tests/processes.py): a hang is a failure, not a stuck suite. Commands that only
read or refuse (status, validate, reduce, export) run mostly in this process (`_here`, which sees what a
process of their own would print); every kind keeps a process of its own in some attack, and every run and
resume has one.
"""
import contextlib
import importlib
import io
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))
# E402 below: `python tests/attack.py` finds the packages only once the repository is on sys.path (above)
import h5py  # noqa: E402
import numpy as np  # noqa: E402

from ensemble.run import lock  # noqa: E402
from ensemble.model.workspace import Workspace  # noqa: E402
from ensemble.store import reader, schema  # noqa: E402
from ensemble.store.errors import CatalogError  # noqa: E402
from ensemble.store.files import partial_path  # noqa: E402
from tests import inject  # noqa: E402
from tests.processes import child_env, run_bounded, wait_for  # noqa: E402
from tests.same_catalogs import common_fields  # noqa: E402

DEADLINE = 120        # seconds for any command: what they take is a few (a hang fails the attack)
QUICK = 30            # ... for a run that must end at once (a full disk, a failed collective step)
COMPILE = 600         # ... for a run of an older commit, which compiles its own kernels first
# the last commits that write bk-catalog-4 (before the creep phase) and bk-catalog-5 (before creep episodes kept
# their energy, a creep state of another layout): their catalogs are real older catalogs
FORMAT_4_COMMIT = "2383acc5f5f0bb6d46cf41bdfe915c3f0db86193"
FORMAT_5_COMMIT = "d10345f72faa30b4b82c7f6fd3a7d08bf8ec7b33"
MPIEXEC = shutil.which("mpiexec")
# the aging law's own method (exp4): these runs take less than half the time they take with rk4 at dt = 1e-3
CONFIG = """[model]
N = 60
b = 20.0
[run]
seeds = 2
events = 60
transient = 10
[output]
batch = 20
flush_seconds = 1000.0
"""
# the commit of bk-catalog-4 has no exp4: its run of the config and this version's take rk4
FORMAT_4_CONFIG = CONFIG.replace("[output]", '[integrator]\nmethod = "rk4"\ndt = 1e-3\n[output]')
# a point whose chain creeps (b below the block stiffness 19: creep states in its checkpoint slots) and one
# whose chain cannot
CREEP_CONFIG = """[model]
N = 40
[sweep]
b = [15.0, 25.0]
[run]
seeds = 2
events = 60
transient = 10
[integrator]
method = "ark4"   # the default of the format-5 commit, so that its events and this version's are the same
[output]
batch = 20
flush_seconds = 1000.0
"""


class Skip(Exception):
    """The attack cannot be made here (the reason says why)."""


def _python(*argv, setup=None, ranks=None, shell_prefix=None, timeout=DEADLINE):
    """`python -m ensemble|analysis ...` (argv[0] names the package), after `setup` (tests.inject code), under
    mpiexec -n ranks if given, after a shell prefix (e.g. 'ulimit -f 100')."""
    package, *args = [str(a) for a in argv]
    if setup is None:
        cmd = [sys.executable, "-m", package, *args]
    else:
        main = "inject.main" if package == "ensemble" else "__import__('analysis.cli').cli.main"
        cmd = [sys.executable, "-c", f"import sys; sys.path.insert(0, {str(ROOT)!r}); from tests import inject; "
                                     f"{setup}; sys.exit({main}({args!r}) or 0)"]
    if ranks:
        if MPIEXEC is None:
            raise Skip("mpiexec not found")
        cmd = [MPIEXEC, "-n", str(ranks), *cmd]
    if shell_prefix:
        cmd = ["bash", "-c", f"{shell_prefix}; exec \"$@\"", "bash", *cmd]
    return run_bounded(cmd, timeout, env=child_env())


def _here(*argv):
    """`python -m ensemble|analysis ...` (argv[0] names the package) run by the package's cli.main in this
    process, for a command that only reads or refuses (status, validate, reduce, export: no signal handler, lock
    or MPI job of its own; a process costs 1-2.5 s of imports). A CompletedProcess with its exit code and what
    it wrote, file descriptors 1 and 2 included (where HDF5's own messages would go), as a process would show."""
    package, *args = [str(a) for a in argv]
    main = importlib.import_module(f"{package}.cli").main
    out, err = io.StringIO(), io.StringIO()
    with tempfile.TemporaryFile() as fd_out, tempfile.TemporaryFile() as fd_err:
        sys.stdout.flush()
        sys.stderr.flush()
        saved = os.dup(1), os.dup(2)
        os.dup2(fd_out.fileno(), 1)
        os.dup2(fd_err.fileno(), 2)
        try:
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                try:
                    code = main(args)
                except SystemExit as done:      # argparse's own errors
                    code = done.code
        finally:
            for fd, saved_fd in zip((1, 2), saved):
                os.dup2(saved_fd, fd)
                os.close(saved_fd)
        fd_out.seek(0)
        fd_err.seek(0)
        stdout = out.getvalue() + fd_out.read().decode(errors="replace")
        stderr = err.getvalue() + fd_err.read().decode(errors="replace")
    return subprocess.CompletedProcess([package, *args], code, stdout, stderr)


def _errors(res):
    """stderr's lines but the process manager's own (MPICH prints one per aborted rank)."""
    return [line for line in res.stderr.strip().splitlines()
            if line and not line.startswith(("Abort(", "[unset]", "application called MPI_Abort"))]


def one_line(res, codes=(1, 2), *words):
    lines = _errors(res)
    assert res.returncode in codes, f"exit {res.returncode} (wanted {codes}): {res.stderr[-1500:]}"
    assert len(lines) == 1, f"{len(lines)} lines on stderr, not one: {res.stderr[-1500:]}"
    for word in words:
        assert word in lines[0], f"{word!r} not in {lines[0]!r}"
    return lines[0]


def nothing_left(folder, name):
    left = [p.name for p in Path(folder).iterdir() if p.name.startswith(name)]
    assert not left, f"left behind: {left}"


class Workshop:
    """A folder with the config, a finished catalog and an interrupted one (made once, copied per attack)."""

    def __init__(self, root):
        self.root = Path(root)
        self.cfg = self.root / "cfg.toml"
        self.cfg.write_text(CONFIG)
        self.full = self.root / "full.h5"
        # (the first run of a session may compile the kernels: about a minute alone, more beside other tests)
        log = self.root / "writes.log"
        res = _python("ensemble", "run", self.cfg, "-o", self.full, setup=f"inject.log_writes({str(log)!r})",
                      timeout=COMPILE)
        assert res.returncode == 0, res.stderr
        # crashed just before its last write before the first finish: task 0 committed, not finished
        self.crashed = self.root / "crashed.h5"
        res = _python("ensemble", "run", self.cfg, "-o", self.crashed,
                      setup=f"inject.crash_at_write({inject.before_finish(log)})")
        assert res.returncode == 99, res.stderr

    def older(self, version=4):
        """The finished catalog of bk-catalog-`version` written by the last commit of that format (4: of
        FORMAT_4_CONFIG, FORMAT_4_COMMIT; 5: of CREEP_CONFIG, FORMAT_5_COMMIT): its tree taken from git, run with
        its own numba cache; made once. Its final path."""
        out = self.root / f"format{version}.h5"
        if out.exists():
            return out
        commit, cfg = {4: (FORMAT_4_COMMIT, self.format_4_config()),
                       5: (FORMAT_5_COMMIT, self.creep_config())}[version]
        tree = self.root / f"format{version}-tree"
        tree.mkdir()
        archive = subprocess.run(f"git -C '{ROOT}' archive {commit} | tar -x -C '{tree}'", shell=True,
                                 capture_output=True, text=True)
        assert archive.returncode == 0, (f"the commit {commit} (the last to write bk-catalog-{version}) is not in "
                                         f"the repository (a shallow clone?): {archive.stderr}")
        env = child_env(PYTHONPATH=str(tree), NUMBA_CACHE_DIR=str(self.root / f"format{version}-cache"))
        res = run_bounded([sys.executable, "-m", "ensemble", "run", str(cfg), "-o", str(out)], COMPILE,
                          cwd=tree, env=env)
        assert res.returncode == 0, res.stdout + res.stderr
        return out

    def creep_config(self):
        path = self.root / "creep.toml"
        path.write_text(CREEP_CONFIG)
        return path

    def format_4_config(self):
        path = self.root / "format4.toml"
        path.write_text(FORMAT_4_CONFIG)
        return path

    def copy(self, which, name):
        """A copy of the finished ('full') or interrupted ('crashed': its .partial) catalog; its final path."""
        dest = self.root / name
        source = self.full if which == "full" else partial_path(self.crashed)
        shutil.copy(source, dest if which == "full" else partial_path(dest))
        return dest


def _mount_tmpfs(size):
    mount = Path(tempfile.mkdtemp(prefix="attack-disk-"))
    res = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(mount)],
                         capture_output=True, text=True)
    if res.returncode != 0:
        mount.rmdir()
        raise Skip(f"cannot mount a small tmpfs here, which needs root ({res.stderr.strip()})")
    return mount


def _unmount(mount):
    subprocess.run(["umount", "-l", str(mount)], capture_output=True)
    mount.rmdir()


def _flip(path, dataset, index=0, byte=3):
    """Flip one byte of element `index` of a contiguous dataset, in the file's bytes."""
    with h5py.File(path, "r") as h5:
        ds = h5[dataset]
        if ds.id.get_offset() is None:
            raise Skip(f"/{dataset} has no bytes in the file (never written: HDF5 allocates at the first write)")
        offset = ds.id.get_offset() + index * ds.dtype.itemsize + min(byte, ds.dtype.itemsize - 1)
    with open(path, "r+b") as fh:
        fh.seek(offset)
        old = fh.read(1)[0]
        fh.seek(offset)
        fh.write(bytes([old ^ 0x10]))


def _replace_bytes(path, old, new):
    data = Path(path).read_bytes()
    assert data.count(old) == 1, f"{old!r} found {data.count(old)} times"
    Path(path).write_bytes(data.replace(old, new))


# -- the attacks: name -> function(workshop) ----------------------------------------------------------

def full_disk_under_mpi(writer):
    def attack(w):
        mount = _mount_tmpfs("2m")
        try:
            start = time.monotonic()
            res = _python("ensemble", "run", w.cfg, "-o", mount / "p.h5", "--set", "run.events=20000",
                          "--set", f'output.writer="{writer}"', ranks=2, timeout=QUICK)
            one_line(res, (1, 2), "No space left on device")
            nothing_left(mount, "p.h5")       # no lock, no .partial
            assert time.monotonic() - start < QUICK
            res = _python("ensemble", "resume", mount / "p.h5")
            one_line(res, (2,), "no interrupted run")
        finally:
            _unmount(mount)
    return attack


def full_disk_inside_hdf5_under_mpi(writer):
    """The check before creation bypassed (space taken by another process meanwhile): HDF5 itself fails to
    write while the ranks are inside its collective create. All ranks leave; the file is removed."""
    def attack(w):
        mount = _mount_tmpfs("2m")
        try:
            res = _python("ensemble", "run", w.cfg, "-o", mount / "p.h5", "--set", "model.N=5000",
                          "--set", "run.seeds=50", "--set", "run.events=10", "--set", f'output.writer="{writer}"',
                          setup="from ensemble import space; space.check_fits = lambda path, nbytes: None",
                          ranks=2, timeout=QUICK)
            one_line(res, (1,), "cannot create catalog")
            left = [p.name for p in mount.iterdir()]
            assert "p.h5.partial" not in left and "p.h5" not in left, left
        finally:
            _unmount(mount)
    return attack


def file_size_limit(ranks, writer):
    def attack(w):
        out = w.root / f"big-{ranks}-{writer}.h5"
        res = _python("ensemble", "run", w.cfg, "-o", out, "--set", "run.events=1000000",
                      "--set", f'output.writer="{writer}"', ranks=ranks, shell_prefix="ulimit -f 50000",
                      timeout=QUICK)
        one_line(res, (1,), "ulimit -f")   # (MPI's own files need more than a few MB: 50 MB)
        nothing_left(w.root, out.name)
    return attack


# every /tasks dataset; flipped in a finished catalog, each read refuses naming the task or the tables
TASK_DATASETS = ("point", "seed_index", "N", "l", "nu", "a", "b", "c", "alpha", "sigma", "law", "events_written",
                 "rank", "wall_time", "events_per_second", "seed_entropy", "spawn_key", "status", "error",
                 "integrator", "branch_of", "record_crc")


def flipped_table(name):
    def attack(w):
        bad = w.copy("full", f"flip-{name}.h5")
        _flip(bad, f"tasks/{name}")
        try:
            reader.read_tasks(bad)
        except CatalogError as err:
            assert "damaged" in str(err) or "corrupt" in str(err), err
        else:
            raise AssertionError(f"a flipped byte in /tasks/{name} was read without a word")
    return attack


def flipped_table_every_command(name):
    """reduce, export and status each say it in one line; a resume of a .partial so damaged too."""
    def attack(w):
        bad = w.copy("full", f"cmd-{name}.h5")
        _flip(bad, f"tasks/{name}")
        one_line(_here("ensemble", "status", bad), (1,), str(bad))
        one_line(_here("analysis", "reduce", bad, "-o", w.root / f"cmd-{name}.summary.h5"), (1,), str(bad))
        one_line(_here("analysis", "export", bad, "-o", w.root / f"cmd-{name}-export"), (1,), str(bad))
        part = w.copy("crashed", f"res-{name}.h5")
        try:
            _flip(partial_path(part), f"tasks/{name}")
        except Skip:
            return      # (not written yet in the interrupted run)
        res = _python("ensemble", "resume", part)
        if name in ("status", "wall_time"):      # a task's record: the task is rerun, the catalog completes
            assert res.returncode == 0 and "rerun from its start" in res.stderr, res.stderr
            a, _, _ = reader.read(part)
            b, _, _ = reader.read(w.full)
            for column in schema.EVENT_FIELDS:
                np.testing.assert_array_equal(a[column], b[column], err_msg=column)
        else:
            one_line(res, (1,), "damaged")
    return attack


def changed_config(where):
    """One changed byte in the stored config ("b = 20.0" -> "b = 30.0"): every command refuses."""
    def attack(w):
        bad = w.copy(where, f"config-{where}.h5")
        path = bad if where == "full" else partial_path(bad)
        _replace_bytes(path, b"b = 20.0", b"b = 30.0")
        one_line(_here("ensemble", "status", bad), (1,), "stored config")
        one_line(_python("ensemble", "resume", bad), (1, 2))
        args = ["--partial"] if where == "crashed" else []
        one_line(_here("analysis", "reduce", path, "-o", w.root / f"config-{where}.s.h5", *args), (1,))
        one_line(_here("analysis", "export", path, "-o", w.root / f"config-{where}-x", *args), (1,))
    return attack


def an_older_format(w):
    """Catalogs of the formats before this one still read, and a run of them is not continued (it would
    write rows and checkpoints of another layout, or records without their checksums):

    - bk-catalog-4, written by the last commit of that format (Workshop.older): every row reads as an
      inertial event (kind 0, ending 0, supplied by the reader; its events checksum covers its own ten
      columns), the same events as this version's run of FORMAT_4_CONFIG; reduce and export read it;
    - bk-catalog-3, that catalog without tables_crc and /tasks/record_crc.
    """
    old = w.older()
    events, tasks, attrs = reader.read(old)
    assert attrs["format"] == "bk-catalog-4"
    with h5py.File(old, "r") as h5:
        assert "kind" not in h5["events"] and "creep" not in h5["checkpoint"]
    assert len(events["t"]) == len(tasks["point"]) * int(attrs["events_per_task"])
    assert np.all(events["kind"] == 0) and np.all(events["ending"] == 0) and np.all(np.isnan(events["stress_drop"]))
    now = w.root / "format4-now.h5"
    res = _python("ensemble", "run", w.format_4_config(), "-o", now)
    assert res.returncode == 0, res.stderr
    now, _, now_attrs = reader.read(now)          # (the aging law at b = 20 is unchanged by the creep phase)
    for column in common_fields(attrs, now_attrs):
        np.testing.assert_array_equal(events[column], now[column], err_msg=column)
    res = _python("analysis", "reduce", old, "-o", w.root / "format4.summary.h5")
    assert res.returncode == 0, res.stderr
    res = _python("analysis", "export", old, "-o", w.root / "format4-export")
    assert res.returncode == 0, res.stderr
    lines = (w.root / "format4-export" / "events.csv").read_text().splitlines()
    assert next(line for line in lines if not line.startswith("#")) == ",".join(schema.EVENT_FIELDS), lines[:30]
    part = w.root / "format4-resume.h5"
    shutil.copy(old, partial_path(part))     # (an interrupted run of that format, as far as resume sees)
    one_line(_python("ensemble", "resume", part), (1,), "bk-catalog-4")
    three = w.root / "format3.h5"
    shutil.copy(old, partial_path(three))
    with h5py.File(partial_path(three), "r+") as h5:
        h5.attrs["format"] = "bk-catalog-3"
        del h5.attrs["tables_crc"]
        del h5["tasks/record_crc"]
    events, _, _ = reader.read(partial_path(three))
    assert np.all(events["kind"] == 0)
    one_line(_python("ensemble", "resume", three), (1,), "bk-catalog-3")


def format_5_with_creep(w):
    """A bk-catalog-5 catalog, written by the last commit of that format with creep states in its checkpoint
    slots (their episode table of 14 columns, not 16), reads: its events are those of this version's run of the
    config (the creep's slips are unchanged, only its energy is kept now) and its states unpack with their
    own layout; a run of it is not continued (its checkpoints could not be restored): one line naming it."""
    old = w.older(5)
    events, tasks, attrs = reader.read(old)
    assert attrs["format"] == "bk-catalog-5"
    assert np.count_nonzero(events["kind"] == 1) > 20
    now = w.root / "format5-now.h5"
    res = _python("ensemble", "run", w.creep_config(), "-o", now)
    assert res.returncode == 0, res.stderr
    events_now, _, now_attrs = reader.read(now)
    for column in common_fields(attrs, now_attrs):
        np.testing.assert_array_equal(events[column], events_now[column], err_msg=column)
    with reader.Reader(old) as cat:
        creeps = cat.layout.creep
        assert creeps.any() and not creeps.all()
        for k in range(len(tasks["point"])):
            state = cat.layout.read_state(k, cat.layout.head(k))
            assert (state.creep is None if not creeps[k]
                    else len(state.creep) == Workspace.creep_size(int(tasks["N"][k]), 14))
    part = w.root / "format5-resume.h5"
    shutil.copy(old, partial_path(part))
    one_line(_python("ensemble", "resume", part), (1,), "bk-catalog-5")


def flipped_creep_layout(w):
    """/checkpoint/creep (which records keep a creep state) is fixed at creation: a flipped byte is refused."""
    bad = w.copy("full", "flip-creep.h5")
    _flip(bad, "checkpoint/creep", 0, 0)
    try:
        reader.read_tasks(bad)
    except CatalogError as err:
        assert "damaged" in str(err), err
    else:
        raise AssertionError("a flipped byte in /checkpoint/creep was read without a word")


def status_of_an_unknown_code(w):
    bad = w.copy("full", "code.h5")
    with h5py.File(bad, "r+") as h5:
        h5["tasks/status"][0] = 7
    one_line(_python("ensemble", "status", bad), (1,), "status code 7")


def resume_of_a_finished_catalog_with_set(w):
    for change in ("model.b=30", "garbage"):
        one_line(_python("ensemble", "resume", w.full, "--set", change), (2,))


def empty_config(w):
    empty = w.root / "empty.toml"
    empty.write_text("# nothing\n")
    for path in (empty, "/dev/null"):
        one_line(_python("ensemble", "run", path, "-o", w.root / "e.h5"), (2,), "empty config")
    nothing_left(w.root, "e.h5")


def output_is_the_config(w):
    before = w.cfg.read_bytes()
    for extra in ([], ["--force"]):
        one_line(_python("ensemble", "run", w.cfg, "-o", w.cfg, *extra), (2,), "input")
    assert w.cfg.read_bytes() == before


def force_replaces_only_a_catalog(w):
    notes = w.root / "notes.txt"
    notes.write_text("mine\n")
    one_line(_python("ensemble", "run", w.cfg, "-o", notes, "--force"), (2,), "replaces only an event catalog")
    assert notes.read_text() == "mine\n"


def absurd_values(w):
    for key, value in (("model.nu", "1e100"), ("run.transient", "1000000000000000000"), ("model.N", "10000000"),
                       ("sweep.b", "[20, 20]"), ("sweep.b", "20,40"), ("output.batch", "1000000000")):
        one_line(_here("ensemble", "validate", w.cfg, "--set", f"{key}={value}"), (2,), key)


def byte_order_mark(w):
    bom = w.root / "bom.toml"
    bom.write_bytes(b"\xef\xbb\xbf" + CONFIG.encode())
    res = _python("ensemble", "validate", bom)
    assert res.returncode == 0 and "N = 60" in res.stdout, res.stderr


def output_name_not_utf8(w):
    folder = w.root / os.fsdecode(b"d\xff")
    folder.mkdir(exist_ok=True)
    one_line(_python("ensemble", "run", w.cfg, "-o", folder / "a.h5"), (2,), "UTF-8")
    nothing_left(folder, "a.h5")
    one_line(_python("analysis", "reduce", w.full, "-o", folder / "s.h5"), (2,), "UTF-8")


def missing_folder(w):
    one_line(_python("ensemble", "run", w.cfg, "-o", w.root / "nowhere" / "x.h5"), (2,), "nowhere")


def bad_analysis_numbers(w):
    for option, value in (("--mu-c", "nan"), ("--mu-c", "inf"), ("--b-cut", "nan"),
                          ("--tnu-bins", "0:1e308:10000000000")):
        one_line(_here("analysis", "reduce", w.full, "-o", w.root / "n.h5", f"{option}={value}"), (2,), option)


def export_of_an_unfinished_run(w):
    part = w.copy("crashed", "unfinished.h5")
    one_line(_python("analysis", "export", partial_path(part), "-o", w.root / "unfinished"), (1, 2),
             "--partial")


def links_are_never_written_through(w):
    """A symbolic link at the name of a run's lock, its .partial or its catalog, to a finished catalog or a text
    file, and at a summary's or its .partial's: refused in one line naming it, exit 2, the target unchanged (a
    PATH.lock link once had its target overwritten by the lock's text, exit 0)."""
    precious = w.root / "precious.h5"
    shutil.copy(w.full, precious)
    notes = w.root / "notes.txt"
    notes.write_text("mine\n")
    before = {target: target.read_bytes() for target in (precious, notes)}
    out = w.root / "linked.h5"
    for name, target, extra in (("linked.h5.lock", precious, []), ("linked.h5.lock", notes, []),
                                ("linked.h5.partial", precious, ["--force"]),
                                ("linked.h5.partial", precious, ["--resume"]), ("linked.h5", notes, ["--force"])):
        link = w.root / name
        link.symlink_to(target)
        try:
            one_line(_python("ensemble", "run", w.cfg, "-o", out, *extra), (2,), name, "symbolic link")
        finally:
            link.unlink()
    for name in ("s.h5", "s.h5.partial"):
        link = w.root / name
        link.symlink_to(notes)
        try:
            one_line(_here("analysis", "reduce", w.full, "-o", w.root / "s.h5", "--force"), (2,), name,
                     "symbolic link")
        finally:
            link.unlink()
    assert {target: target.read_bytes() for target in before} == before
    nothing_left(w.root, "linked.h5")
    nothing_left(w.root, "s.h5")


def a_file_at_the_locks_name_is_not_a_lock(w):
    """A file of someone else's where the lock goes (not a lock: no host, no pid) is left as it is."""
    mine = w.root / "other.h5.lock"
    mine.write_text("my notes\n")
    one_line(_python("ensemble", "run", w.cfg, "-o", w.root / "other.h5"), (2,), str(mine), "not a lock")
    assert mine.read_text() == "my notes\n"
    mine.unlink()
    nothing_left(w.root, "other.h5")


def slurm_job_where_it_cannot_be_written(w):
    """`ensemble slurm -o` below a plain file (the folder cannot be made), and a job directory whose submit.sh is a
    link to a file of the user's: one line naming the path, exit 2, the file unchanged (a PermissionError's
    traceback before)."""
    plain = w.root / "plain.txt"
    plain.write_text("mine\n")
    one_line(_here("ensemble", "slurm", w.cfg, "--ntasks", 2, "--time", 10, "-o", plain / "job"), (2,),
             "plain.txt", "cannot write the job")
    job = w.root / "job-with-a-link"
    job.mkdir()
    (job / "submit.sh").symlink_to(plain)
    one_line(_here("ensemble", "slurm", w.cfg, "--ntasks", 2, "--time", 10, "-o", job, "--force"), (2,),
             "submit.sh", "symbolic link")
    assert plain.read_text() == "mine\n"
    # an option's error names that option (--reduce-time's once named --time)
    one_line(_here("ensemble", "slurm", w.cfg, "--ntasks", 2, "--time", 10, "--reduce-time", 0, "-o",
                   w.root / "job-reduce-time"), (2,), "--reduce-time must be positive")
    nothing_left(w.root, "job-reduce-time")


def _whole_summary(w):
    """The finished catalog's summary (made once)."""
    whole = w.root / "whole.summary.h5"
    if not whole.exists():
        assert _here("analysis", "reduce", w.full, "-o", whole, "--bootstrap", 20).returncode == 0
    return whole


def what_a_reader_sees_says_what_it_is(w):
    """The report names each point's law (it printed the parameters alone); the run's last line tells rows,
    inertial events and creep episodes apart (it called every row an event)."""
    res = _here("analysis", "report", _whole_summary(w))
    assert res.returncode == 0 and "point 0: aging: N = 60" in res.stdout, res.stdout
    res = _python("ensemble", "run", w.creep_config(), "-o", w.root / "rows.h5", "--set", "run.events=40")
    assert res.returncode == 0, res.stderr
    line = res.stdout.strip().splitlines()[-1]
    assert "160 rows: " in line and " inertial events, " in line and " creep episodes in " in line, line
    assert "wrote " in _python("ensemble", "run", w.cfg, "-o", w.root / "plain.h5").stdout.strip().splitlines()[-1]


def flipped_summary(w):
    """One flipped byte in a summary's number, parameter, law, peak or unit count, or a changed attribute: report,
    plot, export and paper refuse it in one line naming what fails its checksum, exit 1 (each passed with exit 0,
    showing the wrong value, before summaries had checksums)."""
    whole = _whole_summary(w)
    commands = {"report": [], "plot": ["--figure", "magnitude", "-o", w.root / "flipped.png"],
                "export": ["-o", w.root / "flipped-tables"], "paper": []}
    for target in ("points/numbers/gr_b", "points/b", "points/law", "points/peaks", "points/units", "level"):
        flipped = w.root / "flipped.summary.h5"
        shutil.copy(whole, flipped)
        if target == "level":
            with h5py.File(flipped, "r+") as h5:
                h5.attrs["level"] = 0.9
        else:
            _flip(flipped, target, byte=0 if target == "points/law" else 3)
        for command, out in commands.items():
            one_line(_here("analysis", command, flipped, *out), (1,), "flipped.summary.h5",
                     "its attributes" if target == "level" else target, "fails its checksum")
        nothing_left(w.root, "flipped.png")
        nothing_left(w.root, "flipped-tables")


def slurm_with_the_mpich_wheel(w):
    """The jobs' python has the mpich wheel (whose ranks srun cannot start): without --launcher the job takes
    mpiexec (it once said so in a note and wrote srun); an explicit --launcher srun is kept, with the note."""
    from ensemble.slurm import command, stack
    real = command.python_stack
    command.python_stack = lambda python: (None, f"MPICH 4, {stack.WHEEL_MPI}")
    try:
        for extra, launcher, note in (([], "mpiexec", False), (["--launcher", "srun"], "srun", True)):
            job = w.root / f"job-wheel-{launcher}"
            res = _here("ensemble", "slurm", w.cfg, "--ntasks", 2, "--time", 10, "-o", job, *extra)
            assert res.returncode == 0, res.stderr
            script = (job / "requeue.sbatch").read_text()
            assert f'LAUNCHER="{launcher}"' in script or f"LAUNCHER={launcher}" in script, script
            assert ("--launcher mpiexec" in res.stdout) == note, res.stdout
    finally:
        command.python_stack = real


def summary_missing_what_a_reader_needs(w):
    """A summary without a dataset or an attribute its readers need (written by another version, or damaged):
    report, plot, export and paper each either do without it (exit 0) or say so in one line naming it, exit 1
    (KeyError tracebacks before); each is needed by one of them at least."""
    whole = _whole_summary(w)
    # each with the commands that must refuse it (the others may do without it)
    for name, commands in (("points/mu_density", ("plot",)), ("bins/mu", ("plot", "export")),
                           ("points/units", ("report", "plot")), ("tasks/catalog", ("paper",)),
                           ("catalogs", ("paper",)), ("configs", ("paper",))):
        lacking = w.root / "lacking.summary.h5"
        shutil.copy(whole, lacking)
        with h5py.File(lacking, "r+") as h5:   # as a summary of format 5 (no checksums) would lack it
            h5.attrs["format"] = "bk-summary-5"
            del h5.attrs["attrs_crc32"]
            h5.visititems(lambda _, obj: obj.attrs.__delitem__("crc32") if isinstance(obj, h5py.Dataset) else None)
            if name in h5.attrs:
                del h5.attrs[name]
            else:
                del h5[name]
        refused = 0
        for command in ("report", "plot", "export", "paper"):
            out = {"plot": ["--figure", "magnitude", "-o", w.root / "lacking.png", "--force"],
                   "export": ["-o", w.root / "lacking-tables", "--force"]}.get(command, [])
            res = _here("analysis", command, lacking, *out)
            if res.returncode != 0 or command in commands:
                one_line(res, (1,), "lacking.summary.h5", repr(name))
                refused += 1
        assert refused, f"no reader needs {name}"


def a_chain_that_never_has_an_event(w):
    """b below the loader's stiffness 1 (the chain's softest: every block moving together): the chain creeps at
    v = nu for ever and no event starts (a run of it once ran at full CPU without end). validate and run refuse it
    in one line naming the key, for either rate-and-state law, a sweep and a population (b = 1 runs:
    tests/test_creep.py)."""
    population = w.root / "never.toml"
    population.write_text("[model]\nN = 5\n[run]\nevents = 1\ntransient = 0\n[population]\nfaults = 3\n"
                          'b = {distribution = "uniform", min = 0.1, max = 0.9}\n')
    for cfg, sets, key in ((w.cfg, ["model.N=1", "model.b=0.5"], "model.b = 0.5"),
                           (w.cfg, ["model.N=5", "model.b=0.99", 'model.law="slip"'], "model.b = 0.99"),
                           (w.cfg, ["sweep.b=[20, 0.9]"], "sweep.b = 0.9"),
                           (population, [], "population.b = 0.1")):
        args = [a for s in sets for a in ("--set", s)]
        one_line(_here("ensemble", "validate", cfg, *args), (2,), key, "never has an event")
    one_line(_python("ensemble", "run", w.cfg, "--set", "model.N=1", "--set", "model.b=0.5", "--set",
                     "run.events=1", "-o", w.root / "never.h5"), (2,), "model.b = 0.5", "never has an event")
    nothing_left(w.root, "never.h5")


def creep_tol_out_of_reach(w):
    """integrator.creep_tol below what a creep step can resolve (1e-14 was accepted, then failed the task at its
    first event with a message that named max_duration, dt and rtol): refused in one line naming the key and its
    floor. A creeping task that fails names creep_tol among the integrator's keys, and so does the hint."""
    one_line(_here("ensemble", "validate", w.creep_config(), "--set", "integrator.creep_tol=1e-14"), (2,),
             "integrator.creep_tol", "[1e-12, 1)", "got 1e-14")
    res = _python("ensemble", "run", w.creep_config(), "-o", w.root / "tight.h5", "--set",
                  "integrator.max_duration=1e-3")
    assert res.returncode == 1, res.stdout + res.stderr
    assert "exceeded integrator.max_duration" in res.stdout and "creep_tol=" in res.stdout, res.stdout
    assert "(or method, rtol, creep_tol)" in res.stdout, res.stdout


def steps_that_stop_advancing_time(w):
    """N = 5, a = 100, b = 18 with exp4 (the aging law's default): task 1's event 130 had two blocks on their
    thresholds within rounding take turns, one starting by loading at the start of a step cut to no length while
    the other, just started, stopped; 4e7 steps at one time in 4 minutes, the progress line frozen and nothing said.
    A block now cannot stop at the time it started (event.continue_event), and the run ends: every row, each
    within the chain's physics (positive slips, a creep episode's or an event's duration)."""
    cfg = w.root / "stall.toml"
    cfg.write_text("[model]\nN = 5\na = 100.0\nb = 18.0\n[run]\nseeds = 2\nevents = 300\ntransient = 20\n")
    out = w.root / "stall.h5"
    res = _python("ensemble", "run", cfg, "-o", out, timeout=300)     # 6 s here; the stall ran for minutes
    assert res.returncode == 0 and "wrote " in res.stdout, res.stdout + res.stderr
    events, _, _ = reader.read(out)
    assert len(events["t"]) == 600, len(events["t"])
    assert np.all(events["slip"] > 0) and np.all(np.isfinite(events["duration"])), events
    # both kinds of row: the chain creeps (b below the stiffness 19) and ruptures
    assert set(np.unique(events["kind"])) == {0, 1}, np.unique(events["kind"])


def reduce_and_export_onto_a_full_disk(w):
    """`analysis reduce` and `export` onto a 100 KB tmpfs: one line, exit 1, nothing left behind (reduce once
    crashed in HDF5's close, exit 139 with a backtrace, leaving S.h5.partial; export left an empty folder). Each
    in a process of its own: a crash must show as one."""
    mount = _mount_tmpfs("100k")
    try:
        one_line(_python("analysis", "reduce", w.full, "-o", mount / "S.h5"), (1,), "S.h5.partial",
                 "No space left on device")
        nothing_left(mount, "S.h5")
        stat = os.statvfs(mount)        # the rest of the disk taken: the tables (a few KB) cannot be written
        (mount / "filler").write_bytes(bytes(stat.f_bavail * stat.f_frsize))
        one_line(_python("analysis", "export", w.full, "-o", mount / "tables"), (1,), "No space left on device")
        nothing_left(mount, "tables")
    finally:
        _unmount(mount)


def one_rank_fails(target, rank, writer="auto", branch=False):
    """A step of a collective path fails on one rank: every rank leaves, at once, with a non-zero exit."""
    def attack(w):
        out = w.root / f"one-{target.replace(':', '-')}-{rank}.h5"
        extra = ["--set", "run.branch=true", "--set", "run.seeds=2"] if branch else []
        res = _python("ensemble", "run", w.cfg, "-o", out, "--set", f'output.writer="{writer}"', *extra,
                      setup=f"inject.fail_in({rank}, {target!r})", ranks=2, timeout=QUICK)
        assert res.returncode != 0, res.stdout + res.stderr
        assert "injected failure" in res.stderr, res.stderr
        # rank 0, killed by the abort, leaves its lock to be taken over (dead pid) once the process is gone
        wait_for(lambda: not lock.is_held(out), 10, "the lock of the aborted run released")
    return attack


ATTACKS = {
    "full disk, mpi, parallel writer": full_disk_under_mpi("parallel"),
    "full disk, mpi, rank0 writer": full_disk_under_mpi("rank0"),
    "full disk inside HDF5, mpi, parallel writer": full_disk_inside_hdf5_under_mpi("parallel"),
    "full disk inside HDF5, mpi, rank0 writer": full_disk_inside_hdf5_under_mpi("rank0"),
    "ulimit -f, serial": file_size_limit(None, "auto"),
    "ulimit -f, mpi, parallel writer": file_size_limit(2, "parallel"),
    "ulimit -f, mpi, rank0 writer": file_size_limit(2, "rank0"),
    **{f"flip /tasks/{name}": flipped_table(name) for name in TASK_DATASETS},
    **{f"flip /tasks/{name}, every command": flipped_table_every_command(name)
       for name in ("b", "status", "wall_time")},
    "changed stored config, finished": changed_config("full"),
    "changed stored config, partial": changed_config("crashed"),
    "status of an unknown status code": status_of_an_unknown_code,
    "an older catalog format reads, and is not continued": an_older_format,
    "a bk-catalog-5 catalog with creep states reads, and is not continued": format_5_with_creep,
    "flip /checkpoint/creep": flipped_creep_layout,
    "resume of a finished catalog with --set": resume_of_a_finished_catalog_with_set,
    "empty config and /dev/null": empty_config,
    "output is the config": output_is_the_config,
    "run --force replaces only a catalog": force_replaces_only_a_catalog,
    "absurd values": absurd_values,
    "config with a byte-order mark": byte_order_mark,
    "output name not UTF-8": output_name_not_utf8,
    "output folder missing": missing_folder,
    "non-finite and huge analysis options": bad_analysis_numbers,
    "export of an unfinished run": export_of_an_unfinished_run,
    "links at a run's and a summary's output names are never written through": links_are_never_written_through,
    "a file at the lock's name that is not a lock is left alone": a_file_at_the_locks_name_is_not_a_lock,
    "a Slurm job where it cannot be written": slurm_job_where_it_cannot_be_written,
    "a Slurm job for the mpich wheel starts its ranks with mpiexec": slurm_with_the_mpich_wheel,
    "a summary without a dataset or an attribute its readers need": summary_missing_what_a_reader_needs,
    "a flipped byte or a changed attribute in a summary": flipped_summary,
    "what a reader sees says what it is": what_a_reader_sees_says_what_it_is,
    "a chain that can never have an event is refused": a_chain_that_never_has_an_event,
    "analysis reduce and export onto a full disk": reduce_and_export_onto_a_full_disk,
    "a creep_tol no creep step can honour is refused; a creeping task's failure names creep_tol":
        creep_tol_out_of_reach,
    "two blocks on their thresholds within rounding do not take turns at one time for ever":
        steps_that_stop_advancing_time,
    **{f"mpi: {target} fails on rank {rank} ({writer})": one_rank_fails(target, rank, writer)
       for target, rank, writer in (
           ("ensemble.store.create:create_layout", 1, "parallel"),
           ("ensemble.store.files:reserve_space", 0, "parallel"),
           ("ensemble.store.create:create_layout", 0, "rank0"),
           ("ensemble.run.parallel:Coordinator.__init__", 1, "parallel"),
           ("ensemble.store.writers:ParallelWriter.close", 1, "parallel"),
           ("ensemble.store.writers:Rank0Writer.close", 1, "rank0"),
           ("ensemble.run.parallel:Coordinator.close", 0, "parallel"),
           ("ensemble.run.runner:_compile_kernels", 1, "parallel"))},
    "mpi: a spin-up fails on the rank that takes it (run.branch)": one_rank_fails(
        "ensemble.run.worker:TaskRunner.spin_up", -1, "parallel", branch=True),
}


def main(words):
    chosen = {name: fn for name, fn in ATTACKS.items() if not words or any(w in name for w in words)}
    results = []
    with tempfile.TemporaryDirectory(prefix="attack-") as tmp:
        workshop = Workshop(tmp)
        for name, attack in chosen.items():
            start = time.monotonic()
            try:
                attack(workshop)
                outcome, detail = "held", ""
            except Skip as why:
                outcome, detail = "skipped", str(why)
            except KeyboardInterrupt:
                raise
            except BaseException as err:  # noqa: BLE001 - a report, not a guard (pytest.fail too): every failure is listed
                lines = [line for line in str(err).splitlines() if line.strip()]
                outcome, detail = "FAILED", f"{type(err).__name__}: {' / '.join(lines[:1] + lines[-3:])}"
            results.append((name, outcome, time.monotonic() - start, detail))
            print(f"{outcome:8s} {results[-1][2]:5.1f} s  {name}" + (f"  ({detail})" if detail else ""), flush=True)
    print("\n" + "\n".join(table([(name, outcome, seconds) for name, outcome, seconds, _ in results])))
    return 1 if any(outcome == "FAILED" for _, outcome, _, _ in results) else 0


def table(results):
    """The lines of the attacks' table from (name, outcome, seconds) rows: this script's and, for the attacks
    `make test` runs, its summary's (tests/conftest.py)."""
    width = max(len(name) for name, *_ in results)
    lines = [f"| {'attack':{width}s} | outcome | s |", f"|{'-' * (width + 2)}|---------|---|"]
    lines += [f"| {name:{width}s} | {outcome:7s} | {seconds:.0f} |" for name, outcome, seconds in results]
    failed = sum(outcome == "FAILED" for _, outcome, _ in results)
    return lines + ["", f"{len(results) - failed} of {len(results)} held or skipped; {failed} failed"]


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
