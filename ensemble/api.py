"""The package's Python front door (docs/api.md): run a config in this process and get its catalog.

(The function is `simulate`: `ensemble.run` is the package that runs it, ensemble/run/.)

    import ensemble
    path = ensemble.simulate({"model": {"N": 50}, "run": {"seeds": 2, "events": 500}}, "small.h5")

(`import analysis` reads it: analysis.events(path), analysis.reduce(path), docs/api.md.)

`python -m ensemble run` is the same run (ensemble.run.runner.run) with the command line's log and exit codes;
here a run that cannot start raises (ConfigError for a bad config, RunError otherwise) and a run whose tasks
failed raises RunError naming the catalog, which keeps what they wrote (resume it with `python -m ensemble
resume`, or simulate(..., resume=True)).
"""
import copy
import os
from pathlib import Path

from .config import ConfigError, from_dict, load, loads, replace

__all__ = ["RunError", "load_config", "simulate"]


class RunError(RuntimeError):
    """A run that was refused, stopped or whose tasks failed; the message says which and names the catalog."""


def load_config(source, overrides=()):
    """A validated config (ensemble.config.Config) from a TOML file's path, a TOML text or a dict of sections
    ({"model": {"N": 50, "b": 20.0}, ...}); overrides: "section.key=value" texts, as `--set` takes them."""
    if isinstance(source, dict):
        from .config import _apply_overrides, parse_override
        raw = copy.deepcopy(source)
        return from_dict(raw, _apply_overrides(raw, [(o, parse_override(o)) for o in overrides]))
    if _path(source) is not None:
        return load(source, overrides)
    if isinstance(source, (str, bytes)):
        return loads(source, overrides)
    raise ConfigError(f"a config is a path, a TOML text or a dict of sections, not {type(source).__name__}")


def _path(source):
    """The config file `source` names (a path, or one line of text naming an existing file or ending in .toml,
    which load() then finds or says is missing), or None for a TOML text or a dict."""
    if isinstance(source, os.PathLike):
        return Path(source)
    if isinstance(source, str) and "\n" not in source and (source.strip().endswith(".toml")
                                                         or Path(source).is_file()):
        return Path(source)
    return None


def simulate(source, output=None, *, overrides=(), force=False, resume=False, log=None, comm=None):
    """Run every task of the config `source` (load_config()'s) into one event catalog and return its path.

    output: the catalog's path (default: the config's output.path); force: replace an existing catalog; resume:
    continue an interrupted run from its checkpoints. log: a print-like function for the run's lines (default:
    silent). comm: the MPI communicator whose ranks share the tasks (default: MPI.COMM_WORLD; one process, a
    serial run). Raises RunError when the run is refused, stopped by a signal, or some of its tasks failed."""
    from mpi4py import MPI

    from .run.context import RunContext
    from .run.decision import Refused
    from .run.lock import LockError
    from .run.runner import EXIT_INTERRUPTED, run as run_tasks
    cfg = load_config(source, overrides)
    if output is not None:
        cfg = replace(cfg, "output", path=str(output))
    inputs = () if _path(source) is None else (str(source),)
    try:
        code = run_tasks(RunContext(cfg, cfg.output.path, comm or MPI.COMM_WORLD, log=log or _quiet, resume=resume,
                                    force=force, command="ensemble.simulate(...)", inputs=inputs))
    except (LockError, Refused) as err:
        raise RunError(str(err)) from None
    if code == EXIT_INTERRUPTED:
        raise RunError(f"{cfg.output.path}: the run was stopped by a signal and checkpointed; "
                       "simulate(..., resume=True) continues it")
    if code != 0:
        raise RunError(f"{cfg.output.path}: some tasks failed (their errors are in the catalog's task table, "
                       "ensemble.tasks); the others finished")
    return Path(cfg.output.path)


def _quiet(*args, **kwargs):
    """A log that says nothing."""
