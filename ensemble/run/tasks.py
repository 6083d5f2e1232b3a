"""Each task's own random stream and initial state, and a branch's perturbation; `validate`'s lines of the
tasks. Which tasks a run has (sweep x seeds, or x faults) is ensemble/sweep.py, shared with the store."""
import dataclasses

import numpy as np

from ..model import laws
from ..sweep import point_tasks, spinups


def rng_for(cfg, task):
    """The task's own generator: independent of ranks, reproducible from (seed, task index)."""
    return np.random.default_rng(np.random.SeedSequence(cfg.run.seed, spawn_key=(task.index,)))


def initial_state(cfg, task):
    """Forces and states of all blocks at t = 0 (all at rest), c-free frame.

    Every block starts with psi = 0 (theta = 1: the aging law's static threshold is exactly c)
    and a force uniformly distributed in (-init_stress, 0] below its threshold: a small seeded
    perturbation of a uniform state. The transient events are discarded.
    """
    rng = rng_for(cfg, task)
    law = laws.get(task.model.law)
    psi = np.zeros(task.model.blocks)
    force = law.threshold(law.kernel_params(task.model), 0.0) - cfg.run.init_stress * rng.random(task.model.blocks)
    return force, psi


# second spawn-key entry of a branch's perturbation stream: task k draws its perturbation from
# SeedSequence(run.seed, spawn_key=(k, BRANCH_STREAM)), independent of its own initial-state stream (k,)
BRANCH_STREAM = 1


def branch_rng(cfg, task):
    """The generator of a branch's perturbation (not of its initial state)."""
    return np.random.default_rng(np.random.SeedSequence(cfg.run.seed, spawn_key=(task.index, BRANCH_STREAM)))


def perturb(force, perturbation, rng):
    """Forces lowered by independent amounts uniform in [0, perturbation) (model force units).

    Lowering keeps every block at rest below its threshold, so a spun-up state between events
    stays one; perturbation = 0 leaves the state exactly as it was.
    """
    return force - perturbation * rng.random(len(force))


def describe(tasks, cfg=None):
    """One line per task for `validate`, then one per spin-up (cfg given, run.branch)."""
    lines = [f"task {t.index}: point {t.point} " + (f"region {t.region} fault {t.fault} " if t.fault >= 0 else
                                                    f"seed {t.seed_index} ")
             + " ".join(f"{f.name}={getattr(t.model, f.name)}" for f in dataclasses.fields(t.model))
             for t in tasks]
    for spin in spinups(cfg, tasks) if cfg is not None else []:
        mine = [t.index for t in point_tasks(cfg, tasks, spin.point)]
        lines.append(f"spin-up of point {spin.point}: {cfg.run.transient} events from task {spin.index}'s initial "
                     f"state; tasks {mine[0]}-{mine[-1]} start from it, forces lowered by up to "
                     f"{cfg.run.perturbation:g}, and discard {cfg.run.decorrelation} events")
    return lines
