"""The run context: what every step of a run needs, in one record instead of a dozen arguments.

A RunContext is made once by the command line (cli.py) from the config and the options; the run
(runner.py) adds its lock, and once the catalog is open its writer, task counter and progress line
(`with_`, which returns a new record: a context is never changed in place). Every function of a run
takes it whole and reads the field it needs.
"""
import dataclasses
from dataclasses import dataclass
from typing import Any, Callable

from ..store.files import partial_path


def _quiet(*args, **kwargs):
    """The log of the ranks other than 0: they say nothing (rank 0 speaks for the run)."""


@dataclass(frozen=True)
class RunContext:
    cfg: Any                        # the resolved config (config.Config)
    path: str                       # the finished catalog's path; the run writes `partial` until the end
    comm: Any                       # the MPI communicator of the run's ranks
    log: Callable = print           # the run's log, a print, on every rank (`say`: rank 0's log, silence elsewhere)
    resume: bool = False            # continue an interrupted run from its checkpoints (--resume, resume)
    force: bool = False             # overwrite an existing catalog (--force)
    rerun: Any = None               # an [integrator] (config.Integrator) to rerun the failed tasks with, or None
    command: str = ""               # the command line, for the lock file (status shows it)
    inputs: tuple = ()              # the run's input files (its config), which the output must not be
    lock: Any = None                # rank 0: the run's lock (lock.RunLock), once taken; else None
    writer: Any = None              # the catalog writer (store.writers), once the catalog is open
    coord: Any = None               # the task counter and stop requests (parallel.Coordinator)
    progress: Any = None            # the progress line (progress.Progress)

    def __post_init__(self):
        object.__setattr__(self, "path", str(self.path))
        object.__setattr__(self, "inputs", tuple(self.inputs))

    @property
    def rank(self):
        return self.comm.Get_rank()

    @property
    def n_ranks(self):
        return self.comm.Get_size()

    @property
    def partial(self):
        """The catalog's name while the run writes it (store/files.py)."""
        return partial_path(self.path)

    @property
    def say(self):
        """The log on rank 0, silence on the others: for what the run says once."""
        return self.log if self.rank == 0 else _quiet

    def with_(self, **changes):
        """A copy with these fields changed (the lock, then the writer, counter and progress)."""
        return dataclasses.replace(self, **changes)
