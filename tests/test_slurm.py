"""Slurm job templates: rendering (fast), and the rendered jobs on a real single-node Slurm (slow).

The slow tests install Slurm from Debian packages if it is missing, start munged, slurmctld and
slurmd on this machine (own ports, own munge socket, state under a temporary directory, nothing
in /etc touched) and submit the rendered jobs. They skip, naming the reason, where Slurm cannot
be installed or started. Every command runs under a timeout (tests/processes.py); each test has a
limit of its own (pytest-timeout) that covers installing and starting the cluster.
"""
import contextlib
import os
import re
import shutil
import socket
import subprocess
import sys
import time

import pytest

from analysis import summary
from ensemble.store import reader
from ensemble.config import load, loads
from ensemble import environment
from ensemble.slurm.kinds import KINDS, element_seed
from ensemble.slurm.options import JobOptions, SlurmError, time_seconds
from ensemble.slurm.render import PLACEHOLDER, PLACEHOLDERS, TEMPLATES, fill, render
from ensemble.slurm.stack import python_stack

from .conftest import write_config
from .processes import child_env, ensemble_here, poll_until, run_bounded
from .same_catalogs import assert_same_events

PACKAGES = ["slurmctld", "slurmd", "slurm-client", "munge"]
RELEASE_DELAY = 3   # seconds between a requeue and the release of the job (Cluster.wait)
DAEMONS = ["munged", "slurmctld", "slurmd", "sbatch", "srun", "scontrol", "sinfo"]
FINISHED = {"COMPLETED", "FAILED", "CANCELLED", "TIMEOUT", "NODE_FAIL", "OUT_OF_MEMORY",
            "BOOT_FAIL", "DEADLINE", "PREEMPTED"}


def tiny_config(path, **sections):
    """Two points x two seeds, about 2 s per task (N = 60, 200 events); the catalog path is
    relative, so the rendered jobs write it into their job directory."""
    base = {"sweep": {"b": [20.0, 30.0]}, "run": {"seeds": 2, "events": 200, "transient": 20},
            "output": {"batch": 50, "flush_seconds": 0.5, "path": path.stem + ".h5"},
            # the default integrator: RK4 at dt = 1e-3 is not stable for every event at b = 30
            "integrator": {"method": "ark4"}}
    for name, values in sections.items():
        base.setdefault(name, {}).update(values)
    return write_config(path, **base)


# ---------------------------------------------------------------- rendering (no Slurm needed)

def test_time_limits_as_slurm_reads_them():
    assert time_seconds("90") == 5400
    assert time_seconds("1:30") == 120          # minutes:seconds, rounded up to whole minutes
    assert time_seconds("02:00:00") == 7200
    assert time_seconds("1-12") == 36 * 3600
    assert time_seconds("1-0:30") == 86400 + 1800
    assert time_seconds("2-00:00:30") == 2 * 86400 + 60
    for bad in ("", "1:2:3:4", "x", "-5", "0", "1h"):
        with pytest.raises(SlurmError):
            time_seconds(bad)


def test_every_placeholder_is_known_and_documented():
    readme = (TEMPLATES / "README.md").read_text()
    used = set()
    for path in TEMPLATES.glob("*.sbatch"):
        used |= set(PLACEHOLDER.findall(path.read_text()))
    assert used == set(PLACEHOLDERS)
    for name in PLACEHOLDERS:
        assert f"@{name}@" in readme, name
    assert {t for t, _ in KINDS.values()} | {"reduce.sbatch"} == {p.name for p in TEMPLATES.glob("*.sbatch")}


def test_fill_drops_lines_with_empty_values_and_refuses_unknown_ones():
    text = "#SBATCH --partition=@PARTITION@\n#SBATCH --ntasks=@NTASKS@\n@SETUP@\necho\n"
    out = fill(text, {"PARTITION": "", "NTASKS": 4, "SETUP": "module load a\nmodule load b"})
    assert out == "#SBATCH --ntasks=4\nmodule load a\nmodule load b\necho\n"
    with pytest.raises(SlurmError, match="@NTASKS@"):
        fill(text, {"PARTITION": "p", "SETUP": ""})


@pytest.mark.parametrize("kind", list(KINDS))
def test_rendered_scripts_are_complete_and_valid_bash(tmp_path, kind):
    cfg = load(tiny_config(tmp_path / "tiny.toml"))
    opt = JobOptions(kind=kind, ntasks=8, time="02:00:00", partition="short", account="geo",
                     setup=("module load mpich",), sbatch=("--mem-per-cpu=2G",), file_locking=False)
    out = render(cfg, opt, tmp_path / "job", "tiny")
    for script in (out.run_script, out.reduce_script, out.directory / "submit.sh"):
        text = script.read_text()
        assert not PLACEHOLDER.search(text), script
        assert run_bounded(["bash", "-n", script], 60).returncode == 0, script
    text = out.run_script.read_text()
    header = text[:text.index("set -u")]
    for line in ("#SBATCH --partition=short", "#SBATCH --account=geo", "#SBATCH --ntasks=8",
                 "#SBATCH --cpus-per-task=1", "#SBATCH --time=02:00:00", "#SBATCH --mem-per-cpu=2G"):
        assert line in header, line
    assert "module load mpich" in text and "export HDF5_USE_FILE_LOCKING=FALSE" in text
    assert f"PYTHON={sys.executable}" in text
    if kind != "single":
        assert "#SBATCH --signal=B:USR1@300" in header and "#SBATCH --requeue" in header
    reduce = out.reduce_script.read_text()
    assert "#SBATCH --kill-on-invalid-dep=yes" in reduce
    # one reduction of every catalog of the run into one summary, named after the catalog
    assert f"CATALOGS=({' '.join(map(str, out.catalogs))})" in reduce and "NAME=tiny\n" in reduce
    assert out.summary == out.directory / "results" / "tiny.summary.h5"
    # one reduction of them all; a second, of the regions, only where the run has a [population]
    assert reduce.count("-m analysis reduce") == 2 and "REGION=0\n" in reduce
    assert '"${launch[@]}" "$PYTHON" -m analysis reduce "${CATALOGS[@]}" -o "$summary" --force' in reduce
    # without partition, account and locking advice those lines are gone
    plain = render(cfg, JobOptions(kind=kind, ntasks=2, time="30"), tmp_path / "plain", "tiny")
    text = plain.run_script.read_text()
    assert "--partition" not in text and "--account" not in text
    assert "HDF5_USE_FILE_LOCKING=" not in text.replace("#   export HDF5_USE_FILE_LOCKING=FALSE", "")


def test_array_elements_are_standalone_configs_one_per_point(tmp_path):
    cfg = load(tiny_config(tmp_path / "tiny.toml", sweep={"b": [20.0, 30.0, 40.0]},
                           run={"seed": 7, "branch": True, "decorrelation": 30}))
    out = render(cfg, JobOptions(kind="array", ntasks=2, time="10", array_limit=2), tmp_path / "job")
    assert "#SBATCH --array=0-2%2" in out.run_script.read_text()
    assert [c.name for c in out.catalogs] == ["point-0000.h5", "point-0001.h5", "point-0002.h5"]
    seeds = set()
    for i, b in enumerate([20.0, 30.0, 40.0]):
        sub = load(out.directory / "points" / f"point-{i:04d}.toml")
        assert sub.sweep == () and sub.model.b == b and sub.run.seeds == 2
        assert sub.run.seed == element_seed(7, i) and sub.output.path == str(out.catalogs[i])
        # an element branches its seeds from its own spin-up, as the point would in one run
        assert sub.run.branch and sub.run.decorrelation == 30 and sub.run.transient == 20
        seeds.add(sub.run.seed)
    assert len(seeds) == 3
    # the reduction merges the elements' catalogs into one summary of the sweep, named after the config
    reduce = out.reduce_script.read_text()
    assert f"CATALOGS=({' '.join(map(str, out.catalogs))})" in reduce and "NAME=run\n" in reduce
    assert out.summary == out.directory / "results" / "run.summary.h5"


def test_bad_options_are_refused(tmp_path):
    cfg = load(tiny_config(tmp_path / "tiny.toml"))
    for opt in (JobOptions(time="1", signal_seconds=60), JobOptions(time="1", startup_seconds=40),
                JobOptions(ntasks=0), JobOptions(launcher="ssh"), JobOptions(partition="a b")):
        with pytest.raises(SlurmError):
            render(cfg, opt, tmp_path / "job")
    with pytest.raises(SlurmError, match="paths in job scripts"):
        render(cfg, JobOptions(), tmp_path / "a job")


def slurm_cli(*args, cwd):
    """`python -m ensemble slurm ARGS` (rendering only) from the folder `cwd`, in this process."""
    with contextlib.chdir(cwd):
        return ensemble_here("slurm", *args)


def test_cli_renders_without_submitting(tmp_path):
    cfg = tiny_config(tmp_path / "tiny.toml")
    res = slurm_cli(cfg, "--ntasks", "4", "--time", "01:00:00", "-o", tmp_path / "job", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "submit with: bash job/submit.sh" in res.stdout
    assert (tmp_path / "job" / "requeue.sbatch").exists() and (tmp_path / "job" / "config.toml").exists()
    snapshot = loads((tmp_path / "job" / "config.toml").read_text())
    assert snapshot.output.path == str(tmp_path / "job" / "tiny.h5")
    res = slurm_cli(cfg, "--ntasks", "4", "--time", "1h", cwd=tmp_path)
    assert res.returncode == 2 and "--time" in res.stderr


def test_an_existing_job_directory_is_not_written_over_without_force(tmp_path):
    cfg = tiny_config(tmp_path / "tiny.toml")
    assert slurm_cli(cfg, "--ntasks", 2, "--time", 30, cwd=tmp_path).returncode == 0
    job = tmp_path / "slurm-tiny"
    snapshot = (job / "config.toml").read_text()
    (job / "tiny.h5").write_bytes(b"")       # as if the run had finished
    res = slurm_cli(cfg, "--ntasks", 2, "--time", 30, "--set", "run.seeds=3", cwd=tmp_path)
    assert res.returncode == 2 and res.stdout == "", res.stdout + res.stderr
    assert res.stderr.strip() == ("error: slurm-tiny: a job directory exists (scripts, config snapshot, catalogs); "
                                  "use --force to write over it, or -o another directory")
    assert (job / "config.toml").read_text() == snapshot
    # an empty directory is taken as it is
    (tmp_path / "empty").mkdir()
    assert slurm_cli(cfg, "--ntasks", 2, "--time", 30, "-o", "empty", cwd=tmp_path).returncode == 0
    # --force writes the scripts and the snapshot anew, and says what the jobs will make of the old catalog
    res = slurm_cli(cfg, "--ntasks", 2, "--time", 30, "--set", "run.seeds=3", "--force", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert load(job / "config.toml").run.seeds == 3
    assert "note: slurm-tiny/tiny.h5 exists: the run job will find it complete and do nothing" in res.stdout


def test_the_reduction_job_has_its_own_time_partition_and_memory(tmp_path):
    cfg = load(tiny_config(tmp_path / "tiny.toml"))

    def headers(opt, name):
        out = render(cfg, opt, tmp_path / name, "tiny")
        return [[line for line in script.read_text().splitlines() if line.startswith("#SBATCH")]
                for script in (out.run_script, out.reduce_script)]

    run, reduce = headers(JobOptions(ntasks=8, time="2-00:00:00", partition="long"), "defaults")
    assert "#SBATCH --time=2-00:00:00" in run and "#SBATCH --time=00:30:00" in reduce
    assert "#SBATCH --partition=long" in run and "#SBATCH --partition=long" in reduce   # the run's unless given
    assert not any(line.startswith("#SBATCH --mem") for line in run + reduce)
    run, reduce = headers(JobOptions(ntasks=8, time="2-00:00:00", partition="long", mem="4G", reduce_time="10",
                                     reduce_partition="short", reduce_mem="16G"), "own")
    assert "#SBATCH --mem=4G" in run and "#SBATCH --mem=16G" in reduce
    assert "#SBATCH --time=10" in reduce and "#SBATCH --partition=short" in reduce
    assert "#SBATCH --partition=long" in run and "#SBATCH --time=2-00:00:00" in run
    for opt in (JobOptions(mem="4 GB"), JobOptions(reduce_mem="-1"), JobOptions(reduce_time="1h"),
                JobOptions(reduce_partition="a b")):
        with pytest.raises(SlurmError):
            render(cfg, opt, tmp_path / "bad")
    res = slurm_cli(tmp_path / "tiny.toml", "--ntasks", 2, "--time", 30, "--reduce-mem", "lots", cwd=tmp_path)
    assert res.returncode == 2
    assert res.stderr.strip() == "error: --reduce-mem must be a Slurm memory size like 4G, 500M or 2000, got 'lots'"


def test_the_command_and_the_scripts_name_the_mpi_the_nodes_need(tmp_path):
    problem, mpi = python_stack(sys.executable)
    assert problem is None and mpi.startswith(environment.mpi_line().removeprefix("mpi: "))
    res = slurm_cli(tiny_config(tmp_path / "tiny.toml"), "--ntasks", 2, "--time", 30, cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    notes = [line for line in res.stdout.splitlines() if line.startswith("note: ") and mpi in line]
    assert len(notes) == 1, res.stdout
    assert "the nodes need" in notes[0]
    for script in ("requeue.sbatch", "reduce.sbatch"):
        text = (tmp_path / "slurm-tiny" / script).read_text()
        assert f"# built against: {mpi}\n" in text and "the nodes need that same MPI" in (
            (tmp_path / "slurm-tiny" / "requeue.sbatch").read_text())


# ---------------------------------------------------------------- a real Slurm (slow)

def _free_ports(n):
    """n distinct free ports (all bound at once: one released and asked again could come back)."""
    with contextlib.ExitStack() as stack:
        socks = [stack.enter_context(socket.socket()) for _ in range(n)]
        for s in socks:
            s.bind(("127.0.0.1", 0))
        return [s.getsockname()[1] for s in socks]


def _install():
    """Install Slurm and munge from Debian packages; returns None or why it failed."""
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    cmd = ["apt-get", "install", "-y", "-q", "--no-install-recommends", *PACKAGES]
    for attempt in (cmd, ["apt-get", "update", "-q"], cmd):
        res = run_bounded(attempt, 900, env=env)
        if res.returncode == 0 and attempt is cmd:
            return None
    return f"apt-get install {' '.join(PACKAGES)} failed: {res.stderr.strip()[-300:]}"


class Cluster:
    """munged, slurmctld and slurmd on this machine: one node (this host, 2 CPUs), one partition."""

    def __init__(self, base):
        self.base = base
        self.conf = base / "slurm.conf"
        self.procs = []
        self.env = dict(os.environ, SLURM_CONF=str(self.conf), TMPDIR=str(base / "tmp"))
        # jobs get the submitting environment: without a NUMBA_CACHE_DIR of the session's they
        # take the package's own cache, as a user's jobs do (ensemble/kernel_cache.py)
        self.env.pop("NUMBA_CACHE_DIR", None)

    def write_config(self):
        node = socket.gethostname().split(".")[0]
        for d in ("state", "spool", "log", "munge", "tmp"):
            (self.base / d).mkdir(mode=0o700, exist_ok=True)
        key = self.base / "munge" / "munge.key"
        key.write_bytes(os.urandom(1024))
        key.chmod(0o600)
        b = self.base
        ctld_port, slurmd_port = _free_ports(2)
        self.conf.write_text(f"""\
ClusterName=bktest
SlurmctldHost={node}(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort={ctld_port}
SlurmdPort={slurmd_port}
AuthType=auth/munge
AuthInfo=socket={b}/munge/munge.sock
CryptoType=crypto/munge
StateSaveLocation={b}/state
SlurmdSpoolDir={b}/spool
SlurmctldPidFile={b}/slurmctld.pid
SlurmdPidFile={b}/slurmd.pid
SlurmctldLogFile={b}/log/slurmctld.log
SlurmdLogFile={b}/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
JobRequeue=1
ReturnToService=2
MinJobAge=600
KillWait=10
InactiveLimit=0
SchedulerParameters=sched_interval=2
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MailProg=/bin/true
NodeName={node} NodeAddr=127.0.0.1 CPUs=2 RealMemory=1000 State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
""")
        return node

    def _start(self, *cmd):
        log = open(self.base / "log" / f"{os.path.basename(cmd[0])}.out", "w")
        self.procs.append(subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=self.env,
                                           stdin=subprocess.DEVNULL))

    def start(self):
        """Start the daemons; returns None or why the node did not come up."""
        self.write_config()
        b = self.base / "munge"
        self._start("munged", "-F", "--force", f"--key-file={b}/munge.key", f"--socket={b}/munge.sock",
                    f"--pid-file={b}/munged.pid", f"--log-file={b}/munged.log", f"--seed-file={b}/seed")
        if not poll_until(lambda: (b / "munge.sock").exists(), 60):
            return "munged did not start: " + self.tail(b / "munged.log")
        self._start("slurmctld", "-D", "-c", "-f", str(self.conf))
        self._start("slurmd", "-D", "-f", str(self.conf))
        if not poll_until(lambda: self.run("sinfo", "-h", "-o", "%T").stdout.strip() == "idle", 120):
            return ("the node did not become idle: " + self.tail(self.base / "log" / "slurmctld.log")
                    + " / " + self.tail(self.base / "log" / "slurmd.log"))
        return None

    def stop(self):
        self.run("scancel", "--user=root")
        poll_until(lambda: not self.run("squeue", "-h").stdout.strip(), 30)
        for proc in reversed(self.procs):
            proc.terminate()
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(timeout=30)

    @staticmethod
    def tail(path, n=5):
        try:
            return " | ".join(path.read_text().strip().splitlines()[-n:])
        except OSError:
            return f"(no {path.name})"

    def run(self, *cmd, check=False):
        res = run_bounded(cmd, 120, env=self.env)
        if check:
            assert res.returncode == 0, f"{' '.join(cmd)}: {res.stderr}"
        return res

    def cli(self, *args, cwd=None):
        """python -m ensemble ... with the cluster's environment (for --submit)."""
        return run_bounded([sys.executable, "-m", "ensemble", *args], 120, env=self.env, cwd=cwd)

    def jobs(self, job_id):
        """scontrol's view of a job (one dict per array element): {key: value}."""
        res = self.run("scontrol", "-o", "show", "job", str(job_id), check=True)
        return [dict(re.findall(r"(\w+)=(\S*)", line)) for line in res.stdout.strip().splitlines()]

    def wait(self, job_ids, timeout, check=None):
        """Wait until every job (every element) has finished. Requeued jobs are released early:
        Slurm holds a requeued job for 120 s before it may start again (hard-coded), which would
        only make the test longer. Not at once, though: a start within a few tens of ms of the
        requeue can meet the revocation of the previous start's credential, and slurmctld then
        kills the job ("Killing non-startable batch JobId=5: Job credential revoked", seen under
        load), so each requeue is released once, RELEASE_DELAY seconds on. `check()` runs at each
        poll while jobs are left."""
        end = time.monotonic() + timeout
        released = set()
        while time.monotonic() < end:
            states = [j for job_id in job_ids for j in self.jobs(job_id)]
            for j in states:
                if j["JobState"] == "PENDING" and j["Reason"] == "BeginTime" and int(j["Restarts"]) > 0 \
                        and (j["JobId"], j["Restarts"]) not in released:
                    released.add((j["JobId"], j["Restarts"]))
                    self.run("scontrol", "update", f"JobId={j['JobId']}", f"StartTime=now+{RELEASE_DELAY}")
            if all(j["JobState"] in FINISHED for j in states):
                return states
            if check is not None:
                check()
            time.sleep(1)
        raise AssertionError(f"jobs {job_ids} not finished after {timeout} s: "
                             + "; ".join(f"{j['JobId']} {j['JobState']} {j['Reason']}" for j in states))


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    if os.geteuid() != 0:
        pytest.skip("starting a Slurm cluster needs root")
    if any(shutil.which(d) is None for d in DAEMONS):
        if shutil.which("apt-get") is None:
            pytest.skip("Slurm is not installed and there is no apt-get to install it")
        why = _install()
        if why:
            pytest.skip(why)
    c = Cluster(tmp_path_factory.mktemp("slurm"))
    why = c.start()
    if why:
        c.stop()
        pytest.skip(f"Slurm did not start: {why}")
    yield c
    c.stop()


def submitted(res):
    """Job ids from the output of `python -m ensemble slurm --submit`: (run, reduce)."""
    assert res.returncode == 0, res.stdout + res.stderr
    run_id = re.search(r"submitted run job (\d+)", res.stdout).group(1)
    reduce_id = re.search(r"submitted reduction job (\d+)", res.stdout).group(1)
    return run_id, reduce_id


def slurm_time(text):
    return time.mktime(time.strptime(text, "%Y-%m-%dT%H:%M:%S"))


def reference_run(cfg, out, ranks=1):
    """An uninterrupted run outside Slurm (serial, or under mpiexec -n ranks)."""
    mpiexec = shutil.which("mpiexec")
    launch = [mpiexec, "-n", str(ranks)] if ranks > 1 and mpiexec else []
    res = run_bounded(launch + [sys.executable, "-m", "ensemble", "run", cfg, "-o", out], 900, env=child_env())
    assert res.returncode == 0, res.stderr


def logs(directory):
    return "\n".join(p.read_text() for p in sorted((directory / "logs").glob("*.out")))


@pytest.mark.slow
@pytest.mark.timeout(1800)    # the first test also installs (apt-get) and starts the cluster
@pytest.mark.parametrize("launcher", ["srun", "mpiexec"])
def test_single_run_job_equals_serial_run(cluster, tmp_path, launcher):
    cfg = tiny_config(tmp_path / "tiny.toml")
    reference_run(cfg, tmp_path / "serial.h5")
    job = tmp_path / "job"
    run_id, reduce_id = submitted(cluster.cli("slurm", cfg, "--kind", "single", "--ntasks", 2,
                                              "--time", 10, "--launcher", launcher, "-o", job, "--submit"))
    run, reduce = cluster.wait([run_id, reduce_id], 600)
    assert run["JobState"] == "COMPLETED", logs(job)
    assert_same_events(tmp_path / "serial.h5", job / "tiny.h5")
    # one MPI world of 2 ranks (not 2 singletons). Which ranks took tasks is not asserted: each
    # rank compiles the kernels first, and one that is done seconds earlier on a loaded machine
    # may take all four ~2 s tasks.
    assert "with 2 rank(s)" in logs(job), logs(job)
    _, tasks, _ = reader.read(job / "tiny.h5")
    assert set(tasks["rank"]) <= {0, 1}
    assert reduce["JobState"] == "COMPLETED", logs(job)
    for name in ("tiny.summary.h5", "tiny-magnitude.png", "tiny-recurrence.png", "tiny.report.txt"):
        assert (job / "results" / name).exists(), name


@pytest.mark.slow
@pytest.mark.timeout(4200)
def test_walltime_job_requeues_resumes_and_equals_uninterrupted_run(cluster, tmp_path):
    """A one-minute limit, USR1 30 s ahead: Slurm checks every ~30 s, so the signal comes 0-30 s
    after each start and is held until 20 s (--startup-seconds). The run needs about 45 s of
    computing on each of two ranks (4 x 6000 events with ark4 at N = 60, b = 20: 39 s of CPU per
    10000 on this kind of machine), one and a half times the most a start can do before the signal
    (30 s, less its start-up), so a requeue happens however Slurm's checks fall. Load can only make the
    run slower, hence more requeues (each start computes 20-30 s less its start-up): the cap (50) and
    the waits leave room for a several times slower run."""
    cfg = tiny_config(tmp_path / "long.toml", sweep={"b": [20.0]}, run={"seeds": 4, "events": 6000},
                      output={"progress_seconds": 5.0})
    reference_run(cfg, tmp_path / "full.h5", ranks=2)   # = serial (tests/test_mpi.py)
    job = tmp_path / "job"
    run_id, reduce_id = submitted(cluster.cli("slurm", cfg, "--ntasks", 2, "--time", 1,
                                              "--signal-seconds", 30, "--startup-seconds", 20,
                                              "--max-requeues", 50, "-o", job, "--submit"))
    run, reduce = cluster.wait([run_id, reduce_id], 3000)
    text = logs(job)
    assert run["JobState"] == "COMPLETED", text
    assert int(run["Restarts"]) >= 1, text
    print(f"walltime job: {int(run['Restarts'])} requeues")
    assert text.count("requeueing job") == int(run["Restarts"])
    assert "interrupted (SIGUSR1)" in text and f"finished: {job / 'long.h5'}" in text
    assert_same_events(tmp_path / "full.h5", job / "long.h5")
    # the reduction waited through the requeues for the final, successful end
    assert reduce["JobState"] == "COMPLETED", text
    assert slurm_time(reduce["StartTime"]) >= slurm_time(run["EndTime"])
    assert (job / "results" / "long.summary.h5").exists()


@pytest.mark.slow
@pytest.mark.timeout(1800)
def test_array_sweep_then_reduction_only_after_every_element_succeeded(cluster, tmp_path):
    cfg = tiny_config(tmp_path / "sweep.toml")
    good, bad = tmp_path / "good", tmp_path / "bad"
    # an array one of whose elements fails (its config is broken after rendering) ...
    res = cluster.cli("slurm", cfg, "--kind", "array", "--ntasks", 1, "--time", 5, "-o", bad)
    assert res.returncode == 0, res.stderr
    (bad / "points" / "point-0001.toml").write_text("[model]\nN = 'sixty'\n")
    res = cluster.run("bash", str(bad / "submit.sh"), check=True)
    bad_run, bad_reduce = re.search(r"run job (\d+).*reduction job (\d+)", res.stdout).groups()
    # ... and a good one
    run_id, reduce_id = submitted(cluster.cli("slurm", cfg, "--kind", "array", "--ntasks", 1, "--time", 5,
                                              "-o", good, "--submit"))

    def no_summary_before_the_end():
        # the reduction's state and the summaries first, then the elements': if an element is
        # still running after, it was at the first look too (the other order races the end)
        reduce_state = cluster.jobs(reduce_id)[0]["JobState"]
        summaries = list((good / "results").glob("*.summary.h5"))
        if any(e["JobState"] not in FINISHED for e in cluster.jobs(run_id)):
            assert not summaries and reduce_state == "PENDING", (summaries, reduce_state)

    states = cluster.wait([run_id, reduce_id, bad_run], 900, check=no_summary_before_the_end)
    elements, reduce = states[:2], states[2]
    assert [e["JobState"] for e in elements] == ["COMPLETED", "COMPLETED"], logs(good)
    assert reduce["JobState"] == "COMPLETED", logs(good)
    assert slurm_time(reduce["StartTime"]) >= max(slurm_time(e["EndTime"]) for e in elements)
    for i, b in enumerate([20.0, 30.0]):
        events, tasks, attrs = reader.read(good / "points" / f"point-{i:04d}.h5")
        assert list(tasks["b"]) == [b, b] and len(events["t"]) == 400
        assert loads(attrs["config"]).run.seed == element_seed(0, i)
    # one summary of the sweep from the elements' catalogs, its figures and report
    for suffix in (".summary.h5", "-magnitude.png", "-recurrence.png", ".report.txt"):
        assert (good / "results" / f"sweep{suffix}").exists(), suffix
    s = summary.read(good / "results" / "sweep.summary.h5")
    # two seeds per point, fewer than ten: 20 stretches of each are the units
    assert list(s["points/b"]) == [20.0, 30.0] and list(s["points/units"]) == [40, 40]
    assert list(s["tasks/catalog"]) == [0, 0, 1, 1] and s["attrs"]["partial"] == ""
    assert list(s["attrs"]["catalogs"]) == [str(good / "points" / f"point-{i:04d}.h5") for i in (0, 1)]
    # the failed element: the reduction never ran (Slurm cancelled it: --kill-on-invalid-dep)
    bad_elements = cluster.jobs(bad_run)
    assert sorted(e["JobState"] for e in bad_elements) == ["COMPLETED", "FAILED"], logs(bad)
    assert poll_until(lambda: cluster.jobs(bad_reduce)[0]["JobState"] == "CANCELLED", 120), \
        cluster.jobs(bad_reduce)
    assert not (bad / "results").exists()
