"""Sweep x seeds -> tasks, each with its own random stream and initial state; with a [population], sweep x
faults (ensemble/population.py)."""
import dataclasses
import itertools
from dataclasses import dataclass

import numpy as np

from ..config import MODEL_TYPES, Model
from ..model import laws
from ..population import draw_values


@dataclass(frozen=True)
class Task:
    index: int        # position in the task list; also the spawn key of its seed
    point: int        # parameter point (row of the sweep's cartesian product)
    seed_index: int   # realisation at that point
    model: Model      # parameters of this task
    region: int = -1  # with a [population]: the point of the sweep whose population the fault is of
    fault: int = -1   # ... and the fault's index in it (the spawn key of its draws)


def task_list(cfg):
    """All tasks: the cartesian product of the sweep values (in the order given) x seeds. With a
    [population], each point of the sweep is a region of population.faults faults, each fault a point
    of its own with one task: task = point = region * faults + fault."""
    tasks = []
    types = MODEL_TYPES
    for point, (model, draws) in enumerate(sweep_points(cfg)):
        if cfg.population is None:
            for s in range(cfg.run.seeds):
                tasks.append(Task(len(tasks), point, s, model))
            continue
        for f in range(cfg.population.faults):
            drawn = draw_values(cfg.population, f, draws, types)
            tasks.append(Task(len(tasks), len(tasks), 0, dataclasses.replace(model, **drawn), point, f))
    return tasks


def sweep_points(cfg):
    """(model, draws) of each point of the sweep: its [model] values, and with a [population] its
    ((key, population.Draw), ...) (the swept specs in place of the [population]'s), else ()."""
    keys = [k for k, _ in cfg.sweep]
    out = []
    for values in itertools.product(*[vals for _, vals in cfg.sweep]):
        chosen = dict(zip(keys, values))
        model = dataclasses.replace(cfg.model, **{k: v for k, v in chosen.items() if not k.startswith("population.")})
        draws = dict(cfg.population.draws) if cfg.population is not None else {}
        draws.update({k.partition(".")[2]: v for k, v in chosen.items() if k.startswith("population.")})
        out.append((model, tuple(draws.items())))
    return out


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
    psi = np.zeros(task.model.N)
    force = law.threshold(law.kernel_params(task.model), 0.0) - cfg.run.init_stress * rng.random(task.model.N)
    return force, psi


# second spawn-key entry of a branch's perturbation stream: task k draws its perturbation from
# SeedSequence(run.seed, spawn_key=(k, BRANCH_STREAM)), independent of its own initial-state stream (k,)
BRANCH_STREAM = 1


def point_tasks(cfg, tasks, point):
    """The tasks of one point (task_list is point-major: task = point * run.seeds + seed_index)."""
    return tasks[point * cfg.run.seeds:(point + 1) * cfg.run.seeds]


def spinups(cfg, tasks):
    """The spin-ups of a run, one per point in point order, each named by the task whose initial
    state it starts from: the point's seed 0, so that an unperturbed branch records exactly what that
    task records without branching; none without run.branch. Spin-up p is catalog record
    len(tasks) + p (after the tasks' records)."""
    return list(tasks[::cfg.run.seeds]) if cfg.run.branch else []


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
