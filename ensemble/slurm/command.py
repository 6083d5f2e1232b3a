"""`python -m ensemble slurm`: its options, and what it says of the job directory it wrote."""
import dataclasses
import os
import sys
from pathlib import Path

from ..config import load
from .kinds import KINDS
from .options import JobOptions, SlurmError
from .render import check, rel, render
from .stack import WHEEL_MPI, mpi_note, python_stack
from .submit import SubmitError, submit


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
    p.add_argument("--launcher", choices=("srun", "mpiexec"), default=None,
                   help=f"how the job starts its ranks (default {d.launcher}; mpiexec where the jobs' python has "
                        f"the mpich wheel, whose ranks srun cannot start)")
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
                     max_requeues=args.max_requeues, launcher=args.launcher or JobOptions.launcher,
                     srun_mpi=args.srun_mpi,
                     python=args.python, setup=tuple(args.setup), sbatch=tuple(args.sbatch),
                     numba_cache=args.numba_cache, file_locking=not args.no_file_locking,
                     array_limit=args.array_limit, reduce_ntasks=args.reduce_ntasks,
                     reduce_time=args.reduce_time, reduce_partition=args.reduce_partition,
                     mem=args.mem, reduce_mem=args.reduce_mem, job_name=args.job_name)
    name = Path(args.config).stem
    directory = Path(args.output or f"slurm-{name}")
    try:
        check(opt)     # a bad option is refused before python_stack() starts the jobs' python
        problem, mpi = python_stack(opt.python)
        opt = dataclasses.replace(opt, mpi=mpi)
        if args.launcher is None and mpi.endswith(WHEEL_MPI):    # what the note would otherwise ask for
            opt = dataclasses.replace(opt, launcher="mpiexec")
        out = render(cfg, opt, directory, name, force=args.force)
    except SlurmError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    print(describe(cfg, opt, out))
    print(mpi_note(opt))
    if problem:
        print(problem, file=sys.stderr)
    if not args.submit:
        print(f"submit with: bash {rel(out.directory / 'submit.sh')}   (or add --submit)")
        return 0
    try:
        run_id, reduce_id = submit(out)
    except SubmitError as err:
        print(f"error: {err}", file=sys.stderr)
        return 1
    print(f"submitted run job {run_id} ({out.run_script.name})")
    print(f"submitted reduction job {reduce_id} (reduce.sbatch), after job {run_id} has succeeded")
    return 0


def describe(cfg, opt, out):
    """A few lines on what was written and what the jobs will do."""
    from ..sweep import task_list
    n_tasks = len(task_list(cfg))
    per_job = n_tasks // len(out.catalogs)
    lines = [f"wrote {rel(out.directory)}/: "
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
    where = (rel(out.catalogs[0]) if len(out.catalogs) == 1
             else f"{rel(out.catalogs[0].parent)}/point-*.h5")
    lines.append(f"  catalog{'s' if len(out.catalogs) > 1 else ''}: {where}; "
                 f"reduced {'together ' if len(out.catalogs) > 1 else ''}into {rel(out.summary)} "
                 f"(figures and report beside it)")
    partition = opt.partition if opt.reduce_partition is None else opt.reduce_partition
    lines.append(f"  reduction job: {opt.reduce_ntasks} rank{'s' if opt.reduce_ntasks > 1 else ''}, "
                 f"time {opt.reduce_time}" + (f", partition {partition}" if partition else "")
                 + (f", memory {opt.reduce_mem}" if opt.reduce_mem else ""))
    for catalog in out.catalogs:   # left from before in a directory written over (--force)
        if os.path.exists(catalog):
            lines.append(f"  note: {rel(catalog)} exists: the run job will find it complete and do nothing "
                         f"(remove it to run again)")
        elif os.path.exists(f"{catalog}.partial"):
            lines.append(f"  note: {rel(catalog)}.partial exists: the run job will resume it")
    return "\n".join(lines)
