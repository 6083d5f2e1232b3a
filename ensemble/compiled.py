"""The compiled kernels: compiling them ahead for every friction law and geometry, and saying so when a run must
compile.

The kernels are compiled once per friction law and geometry (the integration method is chosen inside them at run
time, model/methods.py) into the package's numba cache (kernel_cache.py), in a minute or two per pair. `make setup`
runs `python -m ensemble compile`, which compiles every pair of the registries, each in a process of its own
(as many at once as there are cores), so that the first run of any law, geometry, method and regime loads them
instead; a pair already in the cache takes about 2 s to check.

`warm(law, geometry)` calls every kernel entry point that a run, a checkpoint and the single-event API
(ensemble.events) reach from Python, on a few blocks, with the types a run gives them.
`announced(say, law)` is the run's guard: if numba starts compiling inside it, `say` gets one line saying
so and how long it takes, and another when the kernels are ready.
"""
import contextlib
import os
import subprocess
import sys
import time

from numba.core import event as numba_event


# what a law's kernels take to compile on the machine this project is developed on: 72-99 s, two laws at
# once on its 2 cores (python -m ensemble compile, docs/benchmarks.md); said to a user who has to wait for it
SECONDS_PER_LAW = 90


def warm(law, geometry="chain"):
    """Compile (or load from the cache) every kernel entry point for the friction law `law` and the geometry
    `geometry` (their names)."""
    import warnings

    import numpy as np
    from numba.core.errors import NumbaIRAssumptionWarning

    from . import events
    from .config import from_dict
    from .model import geometry as geometries
    from .run.trajectory import Trajectory
    from .sweep import task_list

    # the law's own method; one compilation serves every method (model/methods.py)
    shape = {"N": 4, "geometry": geometry, **({"M": 2} if "M" in geometries.get(geometry).keys else {})}
    cfg = from_dict({"model": {**shape, "law": law}, "run": {"events": 2, "transient": 0, "seeds": 1}})
    task = task_list(cfg)[0]
    # numba's own inlining (inline="always") into a loop has put variables out of scope and dropped a loop's
    # stores in these kernels (docs/design/geometry.md): compiled code numba itself doubts is an error here
    with warnings.catch_warnings():
        warnings.simplefilter("error", NumbaIRAssumptionWarning)
        trajectory = Trajectory(cfg, task)
        trajectory.advance(2)
        trajectory.checkpoint()
        force, psi = trajectory.state()
        epicenter, _, force, psi = events.advance_to_onset(force, psi, task.model)
        events.run_event(force, psi, epicenter, task.model, cfg.integrator, trace=np.zeros((4, events.NTRACE)))


class _Compiles(numba_event.Listener):
    """Listens to numba's compilations: `start`, the time the first began (None: none has), and
    `first()` called then."""

    def __init__(self, first=lambda: None):
        self.start = None
        self.first = first

    def on_start(self, event):
        if self.start is None:
            self.start = time.perf_counter()
            self.first()

    def on_end(self, event):
        pass


@contextlib.contextmanager
def announced(say, law):
    """Within: the first compilation numba starts is said in one line (with its expected time), and its end."""
    listener = _Compiles(lambda: say(f"compiling kernels for model.law = {law!r} (about {SECONDS_PER_LAW} s, "
                                     f"once per checkout; `python -m ensemble compile` compiles every law "
                                     f"ahead, and `make setup` runs it)"))
    numba_event.register("numba:compile", listener)
    try:
        yield
    finally:
        numba_event.unregister("numba:compile", listener)
    if listener.start is not None:
        say(f"kernels ready in {time.perf_counter() - listener.start:.0f} s")


def compile_laws(names, jobs, say=print, geometries=("chain",)):
    """Compile the kernels of the laws `names` on each of `geometries`, each pair in a process of its own, `jobs`
    at once; returns 0, or 1 if any failed (its output said)."""
    pending = [(name, geometry) for name in names for geometry in geometries]
    running = {}
    failed = []
    while pending or running:
        while pending and len(running) < jobs:
            name = pending.pop(0)
            proc = subprocess.Popen([sys.executable, "-m", "ensemble.compiled", *name], stdout=subprocess.PIPE,
                                    stderr=subprocess.STDOUT, text=True)
            running[proc] = (name, time.perf_counter())
        proc = _wait_any(running)
        name, start = running.pop(proc)
        out = proc.stdout.read()
        proc.stdout.close()
        seconds = time.perf_counter() - start
        which = f"model.law = {name[0]!r}" + ("" if name[1] == "chain" else f", model.geometry = {name[1]!r}")
        if proc.returncode:
            failed.append(name)
            say(f"{which}: compiling failed (exit {proc.returncode}):\n{out.rstrip()}")
        else:
            say(f"{which}: {out.strip() or 'kernels compiled'} ({seconds:.0f} s)")
    return 1 if failed else 0


def _wait_any(running):
    """The first of the running processes to end (polled: a few of them, for a minute each)."""
    while True:
        for proc in running:
            if proc.poll() is not None:
                return proc
        time.sleep(0.2)


def cache_directory():
    """Where the kernels are cached (kernel_cache.directory of ensemble/model/)."""
    import numba
    return numba.config.CACHE_DIR


def default_jobs():
    """Processes at once: the cores this process may use."""
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1))


def _one(law, geometry):
    """A child of compile_laws: compile one law on one geometry, print what happened (compiled, or already in the
    cache)."""
    listener = _Compiles()
    numba_event.register("numba:compile", listener)
    warm(law, geometry)
    print("kernels compiled" if listener.start is not None else "kernels already compiled (loaded from the cache)")


if __name__ == "__main__":
    _one(*sys.argv[1:3])
