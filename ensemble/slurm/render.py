"""Filling the templates: the placeholders, fill(), and render(), which writes a job directory whole."""
import os
import re
from dataclasses import dataclass
from pathlib import Path

from .. import checks
from ..config import Config
from . import options
from .kinds import KINDS
from .options import JobOptions, SlurmError, check_path, defaults, time_seconds

TEMPLATES = Path(__file__).resolve().parents[2] / "jobs"
PLACEHOLDER = re.compile(r"@([A-Z][A-Z0-9_]*)@")

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
    "REGION": "1 for a run with a [population]: the reduction job also writes the regional summary (reduce --region)",
}


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


def check(opt):
    """The options' checks (options.check), with the kinds of job there are (kinds.KINDS)."""
    options.check(opt, KINDS)


def render(cfg: Config, opt: JobOptions, directory, name="run", templates=TEMPLATES, force=False):
    """Write the run script, reduce.sbatch, submit.sh and the configs into `directory`.

    A `directory` that exists and is not empty is refused unless `force`: it is another job's (its
    config snapshot is what its queued run reads); with force its scripts and configs are replaced
    and any catalogs in it kept (describe() says what the jobs will make of them)."""
    check(opt)
    limit = time_seconds(opt.time)
    signal, startup = defaults(opt, limit)
    time_seconds(opt.reduce_time, "--reduce-time")
    directory = Path(directory).resolve()
    if not force and directory.is_dir() and any(directory.iterdir()):
        raise SlurmError(f"{rel(directory)}: a job directory exists (scripts, config snapshot, catalogs); "
                         f"use --force to write over it, or -o another directory")
    if directory.exists() and not directory.is_dir():
        raise SlurmError(f"{rel(directory)}: exists and is not a directory")
    template, configs = KINDS[opt.kind]
    try:
        for d in (directory, directory / "logs"):
            d.mkdir(parents=True, exist_ok=True)
        values, files, catalogs = configs(cfg, directory)
    except OSError as err:      # (a folder that cannot be written, a file where a folder goes)
        raise SlurmError(f"{rel(directory)}: cannot write the job there ({err.strerror})") from None
    except checks.UsageError as err:
        raise SlurmError(str(err)) from None
    # one summary of the run: named after its catalog, or after the config for an array's catalogs
    result_name = Path(catalogs[0]).stem if opt.kind != "array" else name
    check_path(result_name)
    if opt.kind == "array" and opt.array_limit:
        values["ARRAY"] += f"%{opt.array_limit}"
    run_script = directory / template
    values.update({
        "JOB_NAME": opt.job_name or f"bk-{name}", "PARTITION": opt.partition, "ACCOUNT": opt.account,
        "NTASKS": opt.ntasks, "CPUS_PER_TASK": opt.cpus_per_task, "TIME": opt.time.strip(),
        "MEM": opt.mem.strip(), "REDUCE_TIME": opt.reduce_time.strip(), "REDUCE_MEM": opt.reduce_mem.strip(),
        "REDUCE_PARTITION": opt.partition if opt.reduce_partition is None else opt.reduce_partition,
        "MPI": opt.mpi.strip(),
        "WORK_DIR": check_path(directory), "LOG_DIR": check_path(directory / "logs"),
        "EXTRA_SBATCH": "\n".join(f"#SBATCH {o}" for o in opt.sbatch),
        "PYTHON": check_path(opt.python), "LAUNCHER": opt.launcher, "SRUN_MPI": opt.srun_mpi,
        "SETUP": "\n".join(opt.setup), "NUMBA_CACHE_DIR": opt.numba_cache,
        "HDF5_USE_FILE_LOCKING": "" if opt.file_locking else "FALSE",
        "SIGNAL_SECONDS": signal, "STARTUP_SECONDS": startup, "MAX_REQUEUES": opt.max_requeues,
        "SCRIPT": check_path(run_script), "REDUCE_NTASKS": opt.reduce_ntasks,
        "CATALOGS": " ".join(check_path(c) for c in catalogs),
        "SUMMARY_DIR": check_path(directory / "results"), "RESULT_NAME": result_name,
        "REGION": "1" if cfg.population is not None else "0",
    })
    reduce_script = directory / "reduce.sbatch"
    submit_sh = directory / "submit.sh"
    texts = {run_script: fill((Path(templates) / template).read_text(), values),
             reduce_script: fill((Path(templates) / "reduce.sbatch").read_text(), values),
             submit_sh: "#!/bin/bash\n# Submit the run job, then the reduction, which starts when the run has "
                        "succeeded.\nset -euo pipefail\n"
                        f"run=$(sbatch --parsable {run_script})\nrun=${{run%%;*}}\n"
                        f"reduce=$(sbatch --parsable --dependency=afterok:$run {reduce_script})\n"
                        "reduce=${reduce%%;*}\n"
                        f'echo "run job $run ({run_script.name}); reduction job $reduce (after job $run has '
                        'succeeded)"\n'}
    try:
        for script, text in texts.items():
            checks.write_text(script, text, "job script")
            script.chmod(0o755)
    except checks.UsageError as err:
        raise SlurmError(str(err)) from None
    return Rendered(directory, run_script, reduce_script, tuple(catalogs), directory / "results",
                    tuple([run_script, reduce_script, submit_sh] + files),
                    directory / "results" / f"{result_name}.summary.h5")


def rel(path):
    try:
        return os.path.relpath(path)
    except ValueError:
        return str(path)
