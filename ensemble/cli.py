"""Command line: python -m ensemble run|resume|validate|status|compile|slurm ...

Under mpirun every rank runs the same command. An exception on any rank is
printed with the rank (and the task, where there is one) and aborts all ranks
at once, instead of leaving the others hanging in MPI.
"""
import argparse
import os
import signal
import sys

from .version import __version__
from .run.abort import abort
from .store.errors import CatalogError
from .store.files import partial_path
from .store.reader import read_tasks
from .config import ConfigError, load, loads, parse_override, replace
from .run.lock import LockError



def _parser():
    p = argparse.ArgumentParser(prog="python -m ensemble", description=__doc__)
    p.add_argument("--version", action="version", version=__version__)
    sub = p.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run every task of a config into one event catalog")
    val = sub.add_parser("validate", help="print the resolved config and the task list")
    for s in (run, val):
        s.add_argument("config", help="TOML config file")
        s.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                       help="override one config value (repeatable)")
    run.add_argument("-o", "--output", help="catalog path (default: output.path of the config)")
    run.add_argument("--force", action="store_true", help="overwrite an existing catalog")
    run.add_argument("--resume", action="store_true", help="continue an interrupted run from its checkpoints")
    res = sub.add_parser("resume", help="continue an interrupted or partly failed run from its catalog's "
                                        "stored config")
    res.add_argument("catalog", help="catalog path (PATH or PATH.partial)")
    res.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                     help="integrator.KEY=VALUE reruns the failed tasks from their start with that "
                          "integrator; output.KEY=VALUE and run.poll_seconds=VALUE change how the run "
                          "goes on (repeatable)")
    st = sub.add_parser("status", help="summarise a catalog (finished, or being written)")
    st.add_argument("catalog", help="catalog path (PATH.partial is found automatically)")
    comp = sub.add_parser("compile", help="compile the kernels of every friction law (or those named) into the "
                                          "numba cache ahead of the first run (make setup does)")
    comp.add_argument("--law", action="append", default=[], help="only this model.law (repeatable)")
    comp.add_argument("--jobs", type=int, default=None, help="laws compiled at once (default: the cores)")
    from .slurm.command import add_arguments
    add_arguments(sub.add_parser("slurm", help="write (and submit) Slurm job scripts for a config"))
    return p


def _config(args):
    cfg = load(args.config, args.set)
    if getattr(args, "output", None):
        cfg = replace(cfg, "output", path=args.output)
    return cfg


def _validate(args):
    from . import environment
    from .run.tasks import describe
    from .sweep import task_list
    cfg = _config(args)
    # before any output: a writer this stack cannot provide fails here, before a job is submitted
    stack = environment.describe(cfg.output.writer)
    print(cfg.to_toml())
    tasks = task_list(cfg)
    print(f"# {len(tasks)} tasks")
    print("\n".join("# " + line for line in [*describe(tasks, cfg), *stack]))
    return 0


def _status(args):
    from .run.status import summary
    print(summary(args.catalog))
    return 0


# what `resume` may change: how the run goes on, and the integrator of the failed tasks
_RESUMABLE = {"integrator": None, "output": None, "run": ("poll_seconds",)}


def _resume_config(args):
    """(stored config with the allowed overrides, catalog path, [integrator] to rerun failed tasks or None)."""
    path = str(args.catalog).removesuffix(".partial")
    partial = partial_path(path)
    if not os.path.exists(partial):
        if not os.path.exists(path):
            return None, path, None
        _, _, attrs = read_tasks(path)     # (verified: a damaged catalog is not called complete)
        if args.set:
            # a finished catalog: nothing to go on with, and nothing to change
            for text in args.set:
                parse_override(text)
            loads(attrs["config"], args.set, source=f"the config stored in {path}")
            raise ConfigError(f"{path} is complete: resume has nothing to continue, and --set "
                              f"{' --set '.join(args.set)} cannot apply (start a new run instead)")
        return None, path, None
    _, _, attrs = read_tasks(partial, damaged_ok=True)
    rerun = False
    for text in args.set:
        section, key, _ = parse_override(text)
        allowed = _RESUMABLE.get(section, ())
        if (allowed is not None and key not in allowed) or (section, key) == ("output", "path"):
            raise ConfigError(f"--set {section}.{key}: resume continues the stored run and cannot change it "
                              f"(only integrator.*, output.* and run.poll_seconds); start a new run instead")
        rerun = rerun or section == "integrator"
    cfg = replace(loads(attrs["config"], args.set, source=f"the config stored in {partial}"), "output", path=path)
    return cfg, path, cfg.integrator if rerun else None


def _log(*args, **kwargs):
    """print for a run's log: flushed line by line, and a closed stdout (`run ... | head`) does
    not stop the run (its log goes to /dev/null from there on)."""
    try:
        print(*args, **kwargs, flush=True)
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())


def _late_signal(signum, frame):
    """After the work (and before it starts): a signal is acknowledged, not obeyed, so that a
    run that has renamed its catalog cannot end with the signal's exit status over a good catalog."""
    os.write(2, f"{signal.Signals(signum).name} received outside the work loop: ignored\n".encode())


def _run(args):
    from mpi4py import MPI

    from .run.context import RunContext
    from .run.decision import Refused
    from .run.parallel import INTERRUPT_SIGNALS
    from .run.runner import run
    comm = MPI.COMM_WORLD
    rank = comm.Get_rank()
    for sig in INTERRUPT_SIGNALS:
        signal.signal(sig, _late_signal)
    try:
        command = " ".join(["python -m ensemble", *sys.argv[1:]])
        if args.command == "resume":
            cfg, path, rerun = _resume_config(args)
            if cfg is None:
                if os.path.exists(path):
                    if rank == 0:
                        _log(f"{path} is complete; nothing to resume")
                    return 0
                raise Refused(f"{partial_path(path)}: no interrupted run to resume")
            return run(RunContext(cfg, path, comm, log=_log, resume=True, rerun=rerun, command=command))
        cfg = _config(args)
        return run(RunContext(cfg, cfg.output.path, comm, log=_log, resume=args.resume, force=args.force,
                              command=command, inputs=(args.config,)))
    except (ConfigError, LockError, Refused) as err:
        # raised on every rank alike (decisions are made on rank 0 and broadcast)
        if rank == 0:
            print(f"error: {err}", file=sys.stderr, flush=True)
        return 2
    except CatalogError as err:
        if comm.Get_size() > 1 and not err.collective:
            abort(comm, err)
        if rank == 0 or not err.collective:
            print(f"error: {err}", file=sys.stderr, flush=True)
        if err.broken:
            # HDF5 crashes when the broken file's objects are freed at exit: leave at once
            sys.stdout.flush()
            os._exit(1)
        return 1
    except Exception as err:  # noqa: BLE001 - the guard that turns any failure into an abort
        abort(comm, err)     # with more ranks it does not return
        return 1


def _compile(args):
    from . import compiled
    from .model import geometry, laws
    unknown = [name for name in args.law if name not in laws.LAWS]
    if unknown:
        raise ConfigError(f"--law {unknown[0]!r}: not a friction law (one of {', '.join(sorted(laws.LAWS))})")
    if args.jobs is not None and args.jobs < 1:
        raise ConfigError(f"--jobs {args.jobs}: must be at least 1")
    names = args.law or sorted(laws.LAWS)
    shapes = sorted(geometry.GEOMETRIES, key=lambda name: name != geometry.DEFAULT)
    jobs = min(args.jobs or compiled.default_jobs(), len(names) * len(shapes))
    print(f"compiling the kernels of {', '.join(names)} on {', '.join(shapes)} ({len(names)} law(s) x "
          f"{len(shapes)} geometries, {jobs} at once; about {compiled.SECONDS_PER_LAW} s a pair where not yet "
          f"compiled) into {compiled.cache_directory()}", flush=True)
    return compiled.compile_laws(names, jobs, say=lambda line: print(line, flush=True), geometries=shapes)


def _slurm(args):
    from .slurm.command import command
    return command(args)


def main(argv=None):
    args = _parser().parse_args(argv)
    try:
        return {"run": _run, "resume": _run, "validate": _validate, "status": _status,
                "compile": _compile, "slurm": _slurm}[args.command](args)
    except (ConfigError, CatalogError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2 if isinstance(err, ConfigError) else 1
