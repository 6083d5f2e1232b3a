"""Command line: python -m ensemble run|validate CONFIG.toml ..."""
import argparse
import sys

from . import __version__
from .catalog import CatalogError
from .config import ConfigError, load, replace
from .runner import SimulationError, run_serial
from .tasks import describe, task_list


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
    return p


def main(argv=None):
    args = _parser().parse_args(argv)
    try:
        cfg = load(args.config, args.set)
        if getattr(args, "output", None):
            cfg = replace(cfg, "output", path=args.output)
        if args.command == "validate":
            print(cfg.to_toml())
            tasks = task_list(cfg)
            print(f"# {len(tasks)} tasks")
            print("\n".join("# " + line for line in describe(tasks)))
            return 0
        run_serial(cfg, cfg.output.path, force=args.force)
        return 0
    except (ConfigError, CatalogError, SimulationError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2 if isinstance(err, ConfigError) else 1
