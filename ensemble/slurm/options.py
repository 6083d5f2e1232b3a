"""The options of a Slurm job (JobOptions), their checks, and Slurm's time limits in seconds."""
import re
import sys
from dataclasses import dataclass

from .. import checks

SAFE_PATH = re.compile(r"[\w./+,:=%-]+")   # nothing that #SBATCH lines or the shell would split
DEFAULT_REDUCE_TIME = "00:30:00"   # a reduction streams each catalog once (docs: jobs/README.md)
MEMORY = re.compile(r"\d+[KMGT]?")   # Slurm's --mem: an integer, megabytes unless a unit follows


class SlurmError(ValueError):
    """Options that cannot make a working job; the message says which."""


@dataclass(frozen=True)
class JobOptions:
    kind: str = "requeue"           # see kinds.KINDS
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


def time_seconds(text, option="--time"):
    """A Slurm time limit (M, M:S, H:M:S, D-H, D-H:M, D-H:M:S) -> seconds, as Slurm rounds it
    (up to whole minutes); `option` names it in the error."""
    days, dash, rest = text.strip().partition("-")
    if not dash:
        days, rest = "", days
    parts = rest.split(":")
    if (dash and not days.isdigit()) or not all(p.isdigit() for p in parts) or len(parts) > 3:
        raise SlurmError(f"{option} must be a Slurm time limit like 90, 02:00:00 or 1-12:00, got {text!r}")
    nums = [int(p) for p in parts]
    if days:
        h, m, s = (nums + [0, 0])[:3]
        seconds = int(days) * 86400 + h * 3600 + m * 60 + s
    else:
        seconds = {1: lambda m: m * 60, 2: lambda m, s: m * 60 + s,
                   3: lambda h, m, s: h * 3600 + m * 60 + s}[len(nums)](*nums)
    if seconds <= 0:
        raise SlurmError(f"{option} must be positive, got {text!r}")
    return -(-seconds // 60) * 60


def check_path(path):
    if not SAFE_PATH.fullmatch(str(path)):
        raise SlurmError(f"{path}: paths in job scripts may hold only letters, digits and ./_+,:=%- "
                         f"(#SBATCH lines cannot quote)")
    return str(path)


def defaults(opt, limit):
    """Fill the defaults that depend on the time limit, and check the walltime settings."""
    signal = opt.signal_seconds if opt.signal_seconds is not None else min(300, limit // 2)
    startup = opt.startup_seconds if opt.startup_seconds is not None else min(60, limit // 4)
    if not 0 < signal < limit:
        raise SlurmError(f"--signal-seconds must be in (0, {limit}) for --time {opt.time}, got {signal}")
    if not 0 <= startup <= limit - 30:
        raise SlurmError(f"--startup-seconds must be in [0, {limit - 30}] for --time {opt.time} "
                         f"(the run needs time to checkpoint after it), got {startup}")
    return signal, startup


def check(opt, kinds):
    """Refuse (SlurmError) options that cannot make a working job; `kinds`: the kinds of job there are."""
    if opt.kind not in kinds:
        raise SlurmError(f"--kind must be one of {', '.join(kinds)}, got {opt.kind!r}")
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
