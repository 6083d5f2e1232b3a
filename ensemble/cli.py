"""Command line: python -m ensemble run|validate|status|slurm ...

Under mpirun every rank runs the same command. An exception on any rank is
printed with the rank (and the task, where there is one) and aborts all ranks
at once, instead of leaving the others hanging in MPI.
"""
import argparse
import sys
import time

from . import __version__
from .catalog import CatalogError
from .config import ConfigError, load, replace

ABORT_GRACE_SECONDS = 1.0


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
    st = sub.add_parser("status", help="summarise a catalog (finished, or being written)")
    st.add_argument("catalog", help="catalog path (PATH.partial is found automatically)")
    from .slurm import add_arguments
    add_arguments(sub.add_parser("slurm", help="write (and submit) Slurm job scripts for a config"))
    return p


def _config(args):
    cfg = load(args.config, args.set)
    if getattr(args, "output", None):
        cfg = replace(cfg, "output", path=args.output)
    return cfg


def _validate(args):
    from .tasks import describe, task_list
    cfg = _config(args)
    print(cfg.to_toml())
    tasks = task_list(cfg)
    print(f"# {len(tasks)} tasks")
    print("\n".join("# " + line for line in describe(tasks)))
    return 0


def _status(args):
    from .status import summary
    print(summary(args.catalog))
    return 0


def _run(args):
    from mpi4py import MPI

    from .runner import run
    comm = MPI.COMM_WORLD
    rank = comm.Get_rank()
    try:
        cfg = _config(args)
        return run(cfg, cfg.output.path, comm, resume=args.resume, force=args.force)
    except (ConfigError, CatalogError) as err:
        # raised on every rank alike (decisions are made on rank 0 and broadcast)
        if rank == 0:
            print(f"error: {err}", file=sys.stderr, flush=True)
        return 2 if isinstance(err, ConfigError) else 1
    except Exception as err:  # noqa: BLE001 - the guard that turns any failure into an abort
        print(f"error: rank {rank}: {err}", file=sys.stderr, flush=True)
        if comm.Get_size() > 1:
            # MPI_Abort makes the process manager kill every rank, and what a rank
            # wrote to its stderr pipe but the manager has not yet forwarded is lost
            # (seen with MPICH's Hydra): give the message a moment to get out.
            time.sleep(ABORT_GRACE_SECONDS)
            comm.Abort(1)
        return 1


def _slurm(args):
    from .slurm import command
    return command(args)


def main(argv=None):
    args = _parser().parse_args(argv)
    try:
        return {"run": _run, "validate": _validate, "status": _status, "slurm": _slurm}[args.command](args)
    except (ConfigError, CatalogError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2 if isinstance(err, ConfigError) else 1
