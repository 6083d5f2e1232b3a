"""The tasks a config asks for: its sweep's points x seeds (with a [population], x faults, whose parameters
population.py draws), and the spin-ups of run.branch.

A pure function of the config, shared by every layer that must know which tasks a run has: the run
(ensemble/run/), the catalog that lays out and verifies one record per task (ensemble/store/), the Slurm
jobs (ensemble/slurm/) and the regional reduction (analysis/region.py). Each task's random stream and
initial state are the run's (ensemble/run/tasks.py).
"""
import dataclasses
import itertools
from dataclasses import dataclass

from .config import MODEL_TYPES, Model
from .population import draw_values


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


def point_tasks(cfg, tasks, point):
    """The tasks of one point (task_list is point-major: task = point * run.seeds + seed_index)."""
    return tasks[point * cfg.run.seeds:(point + 1) * cfg.run.seeds]


def spinups(cfg, tasks):
    """The spin-ups of a run, one per point in point order, each named by the task whose initial
    state it starts from: the point's seed 0, so that an unperturbed branch records exactly what that
    task records without branching; none without run.branch. Spin-up p is catalog record
    len(tasks) + p (after the tasks' records)."""
    return list(tasks[::cfg.run.seeds]) if cfg.run.branch else []
