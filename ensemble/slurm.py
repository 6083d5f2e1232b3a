"""`python -m ensemble slurm`: fill the job templates of jobs/ from a config, and submit them.

The templates are plain sbatch scripts with @NAME@ placeholders (listed in PLACEHOLDERS and
in jobs/README.md). Filling one replaces each placeholder by its value; a line holding a
placeholder whose value is empty (no partition, no account, ...) is dropped. Everything a job
needs goes into one directory: the scripts, a snapshot of the resolved config (so that editing
the original later does not change a queued run), the catalog(s), logs/ and results/.

Kinds of run job (KINDS): "single" (one MPI run), "requeue" (walltime-safe: checkpoint before
the limit, requeue, resume), "array" (one walltime-safe element per parameter point). Each comes
with reduce.sbatch, submitted with --dependency=afterok on the run job, which reduces the run's
catalog (an array's per-point catalogs together) into one summary, its figures and report; it has
a time limit, partition and memory of its own (a reduction is short and needs one rank).

A job directory that exists is not written over without force (its config snapshot is what a
queued run reads). mpi4py and h5py are built against one MPI, which the nodes must have too: the
scripts and the command's output name it (python_stack()).
"""
import dataclasses
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

from . import checks
from .config import Config, load, replace

TEMPLATES = Path(__file__).resolve().parents[1] / "jobs"
PLACEHOLDER = re.compile(r"@([A-Z][A-Z0-9_]*)@")
SAFE_PATH = re.compile(r"[\w./+,:=%-]+")   # nothing that #SBATCH lines or the shell would split
DEFAULT_REDUCE_TIME = "00:30:00"   # a reduction streams each catalog once (docs: jobs/README.md)
MEMORY = re.compile(r"\d+[KMGT]?")   # Slurm's --mem: an integer, megabytes unless a unit follows

PLACEHOLDERS = {
    "JOB_NAME": "job name (bk-<config file stem>)",
    "PARTITION": "partition (line dropped when not given)",
    "ACCOUNT": "account to charge (line dropped when not given)",
    "NTASKS": "MPI ranks of the run job (of each array element)",
    "CPUS_PER_TASK": "cores per rank (1: the kernels are single-threaded)",
    "TIME": "time limit of the run job (of each start of a requeued job)",
    "MEM": "memory per node of the run job, Slurm's --mem (line dropped when not given)",
    "WORK_DIR": "the job directory (--chdir)",
    "LOG_DIR": "where Slurm writes the job logs",
    "EXTRA_SBATCH": "further #SBATCH lines (line dropped when none)",
    "PYTHON": "python with this package installed",
    "CONFIG": "config snapshot the run reads",
    "CATALOG": "catalog the run writes",
    "LAUNCHER": "srun, or mpiexec for an MPI without Slurm PMI support",
    "SRUN_MPI": "srun's --mpi plugin (pmi2, pmix, ...)",
    "SETUP": "shell lines run before anything else, e.g. module load (dropped when none)",
    "NUMBA_CACHE_DIR": "numba's kernel cache (line dropped by default: the package's own, ensemble/kernel_cache.py)",
    "MPI": "the MPI PYTHON's mpi4py was built against, found when rendering (comment; dropped when unknown)",
    "HDF5_USE_FILE_LOCKING": "FALSE on filesystems without locks (line dropped when not set)",
    "SIGNAL_SECONDS": "USR1 this long before the time limit",
    "STARTUP_SECONDS": "a USR1 earlier than this after launch is held back until then",
    "MAX_REQUEUES": "cap on requeues; then exit 75 (submit again to go on)",
    "SCRIPT": "path of the rendered run script (for the resubmit hint)",
    "ARRAY": "array index range, e.g. 0-9 or 0-9%4",
    "POINTS_DIR": "per-point configs and catalogs of an array job",
    "REDUCE_NTASKS": "ranks of the reduction job",
    "REDUCE_TIME": "time limit of the reduction job",
    "REDUCE_PARTITION": "partition of the reduction job (the run's unless given; line dropped when empty)",
    "REDUCE_MEM": "memory per node of the reduction job, Slurm's --mem (line dropped when not given)",
    "CATALOGS": "catalogs the reduction job reduces together into one summary (space-separated)",
    "SUMMARY_DIR": "where the reduction writes the summary, figures and report",
    "RESULT_NAME": "name of the summary, figures and report (catalog stem; the config's for an array)",
}
PATH_PLACEHOLDERS = ("WORK_DIR", "LOG_DIR", "PYTHON", "CONFIG", "CATALOG", "SCRIPT", "POINTS_DIR",
                     "SUMMARY_DIR")


class SlurmError(ValueError):
    """Options that cannot make a working job; the message says which."""


class SubmitError(RuntimeError):
    """sbatch refused a script or is missing."""


@dataclass(frozen=True)
class JobOptions:
    kind: str = "requeue"           # see KINDS
    ntasks: int = 1                 # MPI ranks of the run job (of each array element)
    time: str = "01:00:00"          # Slurm time limit (of each start of a requeued job)
    partition: str = ""
    account: str = ""
    cpus_per_task: int = 1
    signal_seconds: int | None = None   # USR1 this long before the limit (default 300, <= limit / 2)
    startup_seconds: int | None = None  # hold an earlier USR1 until then (default 60, <= limit / 4)
    max_requeues: int = 10
    launcher: str = "srun"          # or "mpiexec"
    srun_mpi: str = "pmi2"
    python: str = sys.executable
    setup: tuple = ()               # shell lines, e.g. "module load mpich"
    sbatch: tuple = ()              # further sbatch options, e.g. "--mem-per-cpu=2G"
    numba_cache: str = ""           # "": the package's own cache (ensemble/kernel_cache.py)
    mem: str = ""                   # Slurm's --mem of the run job (per node), e.g. 4G
    file_locking: bool = True       # False: HDF5_USE_FILE_LOCKING=FALSE
    array_limit: int = 0            # at most this many array elements at once (0: no limit)
    reduce_ntasks: int = 1
    reduce_time: str = DEFAULT_REDUCE_TIME
    reduce_partition: str | None = None   # None: the run's partition
    reduce_mem: str = ""
    job_name: str = ""
    mpi: str = ""                   # the MPI PYTHON was built against (python_stack()), for a comment


@dataclass(frozen=True)
class Rendered:
    """What render() wrote: the scripts to submit, in order, and where results will be."""
    directory: Path
    run_script: Path
    reduce_script: Path
    catalogs: tuple
    summary_dir: Path
    files: tuple
    summary: Path = None    # the summary the reduction writes (its figures and report beside it)


def time_seconds(text):
    """A Slurm time limit (M, M:S, H:M:S, D-H, D-H:M, D-H:M:S) -> seconds, as Slurm rounds it
    (up to whole minutes)."""
    days, dash, rest = text.strip().partition("-")
    if not dash:
        days, rest = "", days
    parts = rest.split(":")
    if (dash and not days.isdigit()) or not all(p.isdigit() for p in parts) or len(parts) > 3:
        raise SlurmError(f"--time must be a Slurm time limit like 90, 02:00:00 or 1-12:00, got {text!r}")
    nums = [int(p) for p in parts]
    if days:
        h, m, s = (nums + [0, 0])[:3]
        seconds = int(days) * 86400 + h * 3600 + m * 60 + s
    else:
        seconds = {1: lambda m: m * 60, 2: lambda m, s: m * 60 + s,
                   3: lambda h, m, s: h * 3600 + m * 60 + s}[len(nums)](*nums)
    if seconds <= 0:
        raise SlurmError(f"--time must be positive, got {text!r}")
    return -(-seconds // 60) * 60


def fill(text, values):
    """Replace each @NAME@ by values[NAME]; drop every line that holds an empty value."""
    out = []
    for line in text.splitlines():
        names = PLACEHOLDER.findall(line)
        missing = [n for n in names if n not in values]
        if missing:
            raise SlurmError(f"template placeholder @{missing[0]}@ has no value")
        if any(values[n] == "" for n in names):
            continue
        out.append(PLACEHOLDER.sub(lambda m: str(values[m.group(1)]), line))
    return "\n".join(out) + "\n"


def element_seed(root_seed, point):
    """run.seed of the array element of parameter point `point`: drawn from
    SeedSequence(root_seed, spawn_key=(point,)), so that elements are independent of each
    other and reproducible from the root seed (63 bits: run.seed is a TOML integer)."""
    import numpy as np
    state = np.random.SeedSequence(root_seed, spawn_key=(point,)).generate_state(1, np.uint64)[0]
    return int(state >> np.uint64(1))


def point_configs(cfg):
    """One standalone config per parameter point of the sweep: the point's model values, no
    sweep, all seeds, run.seed from element_seed()."""
    from .tasks import task_list
    tasks = task_list(cfg)
    firsts = [t for t in tasks if t.seed_index == 0]
    return [dataclasses.replace(cfg, model=t.model, sweep=(),
                                run=dataclasses.replace(cfg.run, seed=element_seed(cfg.run.seed, t.point)))
            for t in firsts]


def _check_path(path):
    if not SAFE_PATH.fullmatch(str(path)):
        raise SlurmError(f"{path}: paths in job scripts may hold only letters, digits and ./_+,:=%- "
                         f"(#SBATCH lines cannot quote)")
    return str(path)


def _defaults(opt, limit):
    """Fill the defaults that depend on the time limit, and check the walltime settings."""
    signal = opt.signal_seconds if opt.signal_seconds is not None else min(300, limit // 2)
    startup = opt.startup_seconds if opt.startup_seconds is not None else min(60, limit // 4)
    if not 0 < signal < limit:
        raise SlurmError(f"--signal-seconds must be in (0, {limit}) for --time {opt.time}, got {signal}")
    if not 0 <= startup <= limit - 30:
        raise SlurmError(f"--startup-seconds must be in [0, {limit - 30}] for --time {opt.time} "
                         f"(the run needs time to checkpoint after it), got {startup}")
    return signal, startup


def _check(opt):
    if opt.kind not in KINDS:
        raise SlurmError(f"--kind must be one of {', '.join(KINDS)}, got {opt.kind!r}")
    if opt.launcher not in ("srun", "mpiexec"):
        raise SlurmError(f"--launcher must be srun or mpiexec, got {opt.launcher!r}")
    # (checks.py: the one validator of every command's numeric options)
    sizes = {"ntasks": (1, 10 ** 7), "cpus_per_task": (1, 10 ** 4), "reduce_ntasks": (1, 10 ** 7),
             "max_requeues": (0, 10 ** 4), "array_limit": (0, 10 ** 7)}
    try:
        for name, (lo, hi) in sizes.items():
            checks.count(f"--{name.replace('_', '-')}", getattr(opt, name), lo, hi)
    except checks.UsageError as err:
        raise SlurmError(str(err)) from None
    for word in (opt.partition, opt.reduce_partition, opt.account, opt.job_name, opt.srun_mpi):
        if word and not SAFE_PATH.fullmatch(word):
            raise SlurmError(f"{word!r}: not a valid Slurm name")
    for name in ("mem", "reduce_mem"):
        value = getattr(opt, name).strip()
        if value and not MEMORY.fullmatch(value):
            raise SlurmError(f"--{name.replace('_', '-')} must be a Slurm memory size like 4G, 500M or 2000, "
                             f"got {value!r}")
    if "\n" in opt.mpi:
        raise SlurmError("the MPI description must be one line")


def _single_configs(cfg, directory):
    """single, requeue: one config snapshot and one catalog."""
    path = Path(cfg.output.path)
    catalog = path if path.is_absolute() else directory / path
    snapshot = directory / "config.toml"
    snapshot.write_text(replace(cfg, "output", path=str(catalog)).to_toml())
    return {"CONFIG": _check_path(snapshot), "CATALOG": _check_path(catalog)}, [snapshot], [catalog]


def _array_configs(cfg, directory):
    """array: points/point-<i>.toml and points/point-<i>.h5 for each parameter point i."""
    points_dir = directory / "points"
    points_dir.mkdir(exist_ok=True)
    files, catalogs = [], []
    for i, sub in enumerate(point_configs(cfg)):
        catalog = points_dir / f"point-{i:04d}.h5"
        path = points_dir / f"point-{i:04d}.toml"
        values = ", ".join(f"{key}={getattr(sub.model, key)!r}" for key, _ in cfg.sweep)
        path.write_text(f"# array element {i}: point {i} of the sweep ({values or 'no sweep'}); "
                        f"run.seed from SeedSequence({cfg.run.seed}, spawn_key=({i},))\n"
                        + replace(sub, "output", path=str(catalog)).to_toml())
        files.append(path)
        catalogs.append(catalog)
    return {"POINTS_DIR": _check_path(points_dir), "ARRAY": f"0-{len(catalogs) - 1}"}, files, catalogs


KINDS = {   # kind: (template, what it writes besides the scripts)
    "single": ("single.sbatch", _single_configs),
    "requeue": ("requeue.sbatch", _single_configs),
    "array": ("array.sbatch", _array_configs),
}


def render(cfg: Config, opt: JobOptions, directory, name="run", templates=TEMPLATES, force=False):
    """Write the run script, reduce.sbatch, submit.sh and the configs into `directory`.

    A `directory` that exists and is not empty is refused unless `force`: it is another job's (its
    config snapshot is what its queued run reads); with force its scripts and configs are replaced
    and any catalogs in it kept (describe() says what the jobs will make of them)."""
    _check(opt)
    limit = time_seconds(opt.time)
    signal, startup = _defaults(opt, limit)
    time_seconds(opt.reduce_time)
    directory = Path(directory).resolve()
    if not force and directory.is_dir() and any(directory.iterdir()):
        raise SlurmError(f"{_rel(directory)}: a job directory exists (scripts, config snapshot, catalogs); "
                         f"use --force to write over it, or -o another directory")
    if directory.exists() and not directory.is_dir():
        raise SlurmError(f"{_rel(directory)}: exists and is not a directory")
    template, configs = KINDS[opt.kind]
    for d in (directory, directory / "logs"):
        d.mkdir(parents=True, exist_ok=True)
    values, files, catalogs = configs(cfg, directory)
    # one summary of the run: named after its catalog, or after the config for an array's catalogs
    result_name = Path(catalogs[0]).stem if opt.kind != "array" else name
    _check_path(result_name)
    if opt.kind == "array" and opt.array_limit:
        values["ARRAY"] += f"%{opt.array_limit}"
    run_script = directory / template
    values.update({
        "JOB_NAME": opt.job_name or f"bk-{name}", "PARTITION": opt.partition, "ACCOUNT": opt.account,
        "NTASKS": opt.ntasks, "CPUS_PER_TASK": opt.cpus_per_task, "TIME": opt.time.strip(),
        "MEM": opt.mem.strip(), "REDUCE_TIME": opt.reduce_time.strip(), "REDUCE_MEM": opt.reduce_mem.strip(),
        "REDUCE_PARTITION": opt.partition if opt.reduce_partition is None else opt.reduce_partition,
        "MPI": opt.mpi.strip(),
        "WORK_DIR": _check_path(directory), "LOG_DIR": _check_path(directory / "logs"),
        "EXTRA_SBATCH": "\n".join(f"#SBATCH {o}" for o in opt.sbatch),
        "PYTHON": _check_path(opt.python), "LAUNCHER": opt.launcher, "SRUN_MPI": opt.srun_mpi,
        "SETUP": "\n".join(opt.setup), "NUMBA_CACHE_DIR": opt.numba_cache,
        "HDF5_USE_FILE_LOCKING": "" if opt.file_locking else "FALSE",
        "SIGNAL_SECONDS": signal, "STARTUP_SECONDS": startup, "MAX_REQUEUES": opt.max_requeues,
        "SCRIPT": _check_path(run_script), "REDUCE_NTASKS": opt.reduce_ntasks,
        "CATALOGS": " ".join(_check_path(c) for c in catalogs),
        "SUMMARY_DIR": _check_path(directory / "results"), "RESULT_NAME": result_name,
    })
    reduce_script = directory / "reduce.sbatch"
    for src, dst in ((template, run_script), ("reduce.sbatch", reduce_script)):
        dst.write_text(fill((Path(templates) / src).read_text(), values))
    submit_sh = directory / "submit.sh"
    submit_sh.write_text(
        "#!/bin/bash\n# Submit the run job, then the reduction, which starts when the run has succeeded.\n"
        "set -euo pipefail\n"
        f"run=$(sbatch --parsable {run_script})\nrun=${{run%%;*}}\n"
        f"reduce=$(sbatch --parsable --dependency=afterok:$run {reduce_script})\nreduce=${{reduce%%;*}}\n"
        f'echo "run job $run ({run_script.name}); reduction job $reduce (after job $run has succeeded)"\n')
    for script in (run_script, reduce_script, submit_sh):
        script.chmod(0o755)
    return Rendered(directory, run_script, reduce_script, tuple(catalogs), directory / "results",
                    tuple([run_script, reduce_script, submit_sh] + files),
                    directory / "results" / f"{result_name}.summary.h5")


# run by the jobs' python: the MPI library, the libmpi file mpi4py loaded (Linux), the mpich wheel if any
_STACK_PROBE = """
import importlib.metadata, os, mpi4py, ensemble, analysis, h5py
from ensemble import environment
try:
    importlib.metadata.version("mpich")
    wheel = "1"
except importlib.metadata.PackageNotFoundError:
    wheel = ""
print(environment.mpi_line().removeprefix("mpi: "))
try:
    with open("/proc/self/maps") as maps:
        paths = {line.split()[-1] for line in maps if "/" in line}
    print(" ".join(sorted(p for p in paths if os.path.basename(p).startswith("libmpi"))))
except OSError:
    print()
print(wheel)
"""


def python_stack(python):
    """(problem, mpi) for the jobs' `python`, started outside the repository as the jobs are:
    problem is None or a warning (not on this machine, cannot import what the jobs need); mpi
    describes the MPI its mpi4py was built against ("" when unknown)."""
    if not os.path.exists(python):
        return f"note: {python} is not on this machine; not checked that it has this package", ""
    res = subprocess.run([python, "-c", _STACK_PROBE], cwd="/", capture_output=True, text=True,
                         stdin=subprocess.DEVNULL, timeout=120)
    if res.returncode != 0:
        why = (res.stderr.strip().splitlines() or ["?"])[-1]
        return (f"warning: {python}, started outside the repository, cannot import what the jobs need "
                f"({why}); install the package into it (pip install -e .)"), ""
    library, files, wheel = (res.stdout.splitlines() + ["", "", ""])[:3]
    if wheel:
        return None, f"{library}, the mpich wheel inside the environment"
    return None, f"{library}" + (f", {files}" if files else "")


def mpi_note(opt):
    """The command's line on the MPI the nodes need (opt.mpi from python_stack())."""
    if not opt.mpi:
        return ("note: the nodes need the MPI that mpi4py and h5py of the jobs' python were built against "
                "(load it with --setup 'module load ...')")
    if opt.mpi.endswith("the mpich wheel inside the environment"):
        hint = ("" if opt.launcher == "mpiexec"
                else "; start its ranks with --launcher mpiexec (docs/install.md: srun and PMI)")
        return f"note: MPI: {opt.mpi}; the nodes need no MPI of their own{hint}"
    return (f"note: the nodes need the MPI this environment was built against ({opt.mpi}): "
            f"the same MPI on every node, loaded in the jobs (--setup 'module load ...') where it is a module")


def _sbatch(*args):
    if shutil.which("sbatch") is None:
        raise SubmitError("sbatch not found: submit on a login node with bash submit.sh")
    res = subprocess.run(["sbatch", "--parsable", *map(str, args)], capture_output=True, text=True,
                         stdin=subprocess.DEVNULL)
    if res.returncode != 0:
        raise SubmitError(f"sbatch {' '.join(map(str, args))}: {res.stderr.strip() or res.stdout.strip()}")
    return res.stdout.strip().split(";")[0]


def submit(rendered):
    """Submit the run job, then the reduction after it; returns (run job id, reduction job id)."""
    run_id = _sbatch(rendered.run_script)
    reduce_id = _sbatch(f"--dependency=afterok:{run_id}", rendered.reduce_script)
    return run_id, reduce_id


def add_arguments(p):
    """The options of `python -m ensemble slurm` (see JobOptions for their meaning)."""
    d = JobOptions()
    p.add_argument("config", help="TOML config file")
    p.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="override one config value (repeatable)")
    p.add_argument("--ntasks", type=int, required=True, help="MPI ranks (of each array element)")
    p.add_argument("--time", required=True,
                   help="time limit of the run job, e.g. 02:00:00 (of each start of a requeued job)")
    p.add_argument("--kind", choices=list(KINDS), default=d.kind,
                   help="single: one MPI run; requeue (default): checkpoint before the limit, requeue "
                        "and resume until done; array: one requeueing element per parameter point")
    p.add_argument("--partition", default="")
    p.add_argument("--account", default="")
    p.add_argument("--mem", default="", help="memory per node of the run job (Slurm's --mem, e.g. 4G; "
                   "default: the partition's)")
    p.add_argument("-o", "--output", help="job directory (default: slurm-<config stem>)")
    p.add_argument("--force", action="store_true", help="write over an existing job directory")
    p.add_argument("--submit", action="store_true", help="submit the run and the reduction after it")
    p.add_argument("--signal-seconds", type=int, help="USR1 this long before the limit "
                   "(default 300, at most half the limit)")
    p.add_argument("--startup-seconds", type=int, help="hold a USR1 that comes earlier than this "
                   "after launch (default 60, at most a quarter of the limit)")
    p.add_argument("--max-requeues", type=int, default=d.max_requeues, help="default %(default)s")
    p.add_argument("--launcher", choices=("srun", "mpiexec"), default=d.launcher)
    p.add_argument("--srun-mpi", default=d.srun_mpi, help="srun --mpi plugin (default %(default)s)")
    p.add_argument("--python", default=d.python, help="python on the nodes (default: this one)")
    p.add_argument("--setup", action="append", default=[], metavar="LINE",
                   help="shell line run first in every job, e.g. 'module load mpich' (repeatable)")
    p.add_argument("--sbatch", action="append", default=[], metavar="OPTION",
                   help="further sbatch option, e.g. --sbatch=--mem-per-cpu=2G (repeatable)")
    p.add_argument("--cpus-per-task", type=int, default=d.cpus_per_task)
    p.add_argument("--numba-cache", default=d.numba_cache,
                   help="numba's cache (default: the package's own, as for every entry point)")
    p.add_argument("--no-file-locking", action="store_true",
                   help="set HDF5_USE_FILE_LOCKING=FALSE (filesystems without locks)")
    p.add_argument("--array-limit", type=int, default=0, help="array elements running at once (0: all)")
    p.add_argument("--reduce-ntasks", type=int, default=d.reduce_ntasks)
    p.add_argument("--reduce-time", default=d.reduce_time, help="time limit of the reduction job "
                   "(default %(default)s)")
    p.add_argument("--reduce-partition", help="partition of the reduction job (default: the run's)")
    p.add_argument("--reduce-mem", default="", help="memory per node of the reduction job (default: the "
                   "partition's)")
    p.add_argument("--job-name", default="")


def command(args):
    """`python -m ensemble slurm`: render, report, submit if asked; returns the exit code."""
    cfg = load(args.config, args.set)
    opt = JobOptions(kind=args.kind, ntasks=args.ntasks, time=args.time, partition=args.partition,
                     account=args.account, cpus_per_task=args.cpus_per_task,
                     signal_seconds=args.signal_seconds, startup_seconds=args.startup_seconds,
                     max_requeues=args.max_requeues, launcher=args.launcher, srun_mpi=args.srun_mpi,
                     python=args.python, setup=tuple(args.setup), sbatch=tuple(args.sbatch),
                     numba_cache=args.numba_cache, file_locking=not args.no_file_locking,
                     array_limit=args.array_limit, reduce_ntasks=args.reduce_ntasks,
                     reduce_time=args.reduce_time, reduce_partition=args.reduce_partition,
                     mem=args.mem, reduce_mem=args.reduce_mem, job_name=args.job_name)
    name = Path(args.config).stem
    directory = Path(args.output or f"slurm-{name}")
    try:
        _check(opt)     # a bad option is refused before python_stack() starts the jobs' python
        problem, mpi = python_stack(opt.python)
        opt = dataclasses.replace(opt, mpi=mpi)
        out = render(cfg, opt, directory, name, force=args.force)
    except SlurmError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    print(describe(cfg, opt, out))
    print(mpi_note(opt))
    if problem:
        print(problem, file=sys.stderr)
    if not args.submit:
        print(f"submit with: bash {_rel(out.directory / 'submit.sh')}   (or add --submit)")
        return 0
    try:
        run_id, reduce_id = submit(out)
    except SubmitError as err:
        print(f"error: {err}", file=sys.stderr)
        return 1
    print(f"submitted run job {run_id} ({out.run_script.name})")
    print(f"submitted reduction job {reduce_id} (reduce.sbatch), after job {run_id} has succeeded")
    return 0


def _rel(path):
    try:
        return os.path.relpath(path)
    except ValueError:
        return str(path)


def describe(cfg, opt, out):
    """A few lines on what was written and what the jobs will do."""
    from .tasks import task_list
    n_tasks = len(task_list(cfg))
    per_job = n_tasks // len(out.catalogs)
    lines = [f"wrote {_rel(out.directory)}/: "
             + ", ".join(str(f.relative_to(out.directory)) for f in out.files[:6])
             + (f" and {len(out.files) - 6} more" if len(out.files) > 6 else "")]
    if opt.kind == "array":
        lines.append(f"  array of {len(out.catalogs)} elements (one per parameter point), each {per_job} "
                     f"tasks on {opt.ntasks} ranks, time {opt.time}")
    else:
        lines.append(f"  {opt.kind} job: {n_tasks} tasks on {opt.ntasks} ranks, time {opt.time}")
    if opt.ntasks > per_job:
        lines.append(f"  note: {opt.ntasks} ranks for {per_job} tasks; "
                     f"{opt.ntasks - per_job} ranks will idle")
    where = (_rel(out.catalogs[0]) if len(out.catalogs) == 1
             else f"{_rel(out.catalogs[0].parent)}/point-*.h5")
    lines.append(f"  catalog{'s' if len(out.catalogs) > 1 else ''}: {where}; "
                 f"reduced {'together ' if len(out.catalogs) > 1 else ''}into {_rel(out.summary)} "
                 f"(figures and report beside it)")
    partition = opt.partition if opt.reduce_partition is None else opt.reduce_partition
    lines.append(f"  reduction job: {opt.reduce_ntasks} rank{'s' if opt.reduce_ntasks > 1 else ''}, "
                 f"time {opt.reduce_time}" + (f", partition {partition}" if partition else "")
                 + (f", memory {opt.reduce_mem}" if opt.reduce_mem else ""))
    for catalog in out.catalogs:   # left from before in a directory written over (--force)
        if os.path.exists(catalog):
            lines.append(f"  note: {_rel(catalog)} exists: the run job will find it complete and do nothing "
                         f"(remove it to run again)")
        elif os.path.exists(f"{catalog}.partial"):
            lines.append(f"  note: {_rel(catalog)}.partial exists: the run job will resume it")
    return "\n".join(lines)
