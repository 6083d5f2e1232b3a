"""Helpers shared by the benchmark scripts: settings, chains, distances, output files.

A *setting* names how events are integrated, as text on the command line:

    rk4:dt=1e-3   ark3:rtol=1e-5   ark3:rtol=1e-6,atol=1e-12   numpy-rk4:dt=1e-3   scipy:method=LSODA,rtol=1e-8

The part before the colon is a kernel integrator (any name in ensemble.integrators.INTEGRATORS,
so new methods work without changes here) or a baseline that only work_precision knows; the
part after it are keyword arguments (numbers where they parse as numbers).
"""
import argparse
import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ensemble.config import Config, Integrator, Model, Run
from ensemble.integrators import INTEGRATORS
from ensemble.run.trajectory import Trajectory
from ensemble.sweep import task_list

# right-hand-side evaluations per block-step of the kernel's methods
STAGES = {name: method.stages for name, method in INTEGRATORS.items()}


@dataclass(frozen=True)
class Setting:
    label: str      # as given on the command line
    name: str       # integrator or baseline name
    params: tuple   # ((key, value), ...)

    @property
    def kwargs(self):
        return dict(self.params)

    @property
    def is_kernel(self):
        return self.name in INTEGRATORS

    def integrator(self):
        """The kernel's Integrator config for this setting (kernel methods only)."""
        if not self.is_kernel:
            raise ValueError(f"{self.label}: not a kernel integrator ({', '.join(INTEGRATORS)})")
        return Integrator(method=self.name, **self.kwargs)


def parse_setting(text, baselines=()):
    """'name:key=value,key=value' -> Setting; the name must be a kernel integrator or a baseline."""
    name, _, rest = text.partition(":")
    known = sorted(INTEGRATORS) + sorted(baselines)
    if name not in known:
        raise ValueError(f"setting {text!r}: unknown method {name!r} (known: {', '.join(known)})")
    params = []
    for item in filter(None, rest.split(",")):
        key, eq, value = item.partition("=")
        if not eq:
            raise ValueError(f"setting {text!r}: expected key=value, got {item!r}")
        try:
            value = float(value)
        except ValueError:
            pass
        params.append((key.strip(), value))
    setting = Setting(text, name, tuple(params))
    if setting.is_kernel:
        try:
            setting.integrator()
        except TypeError as err:
            raise ValueError(f"setting {text!r}: {err}") from None
    return setting


def trajectory(N, b, setting, seed_index, seeds, root_seed=0, M=None):
    """A fresh chain (task `seed_index` of `seeds`) integrated with a kernel setting; with M, a plane of N x M
    blocks (model.geometry = "lattice").

    The initial state depends only on (root_seed, seed_index), not on the setting.
    """
    shape = {} if M is None else {"geometry": "lattice", "M": M}
    cfg = Config(model=Model(N=N, b=b, **shape), run=Run(seeds=seeds, seed=root_seed),
                 integrator=setting.integrator())
    return Trajectory(cfg, task_list(cfg)[seed_index])


def rough_events_per_second(setting):
    """A guess of a kernel setting's events/s on one core of this machine, for time estimates.

    Calibrated at N = 800, b = 20 (rk4 dt = 1e-3: 120/s, ark3 rtol = 1e-5: 71/s); at N = 100 the
    rates are about the same (102/s), so N and b are not used: elsewhere this is a guess.
    """
    kw = setting.kwargs
    if setting.name == "rk4":
        return 120.0 * kw.get("dt", 1e-3) / 1e-3
    return 71.0 * (kw.get("rtol", 1e-6) / 1e-5) ** 0.25


def ks_distance(x, y):
    """Two-sample Kolmogorov-Smirnov distance sup |F_x - F_y| of the empirical distributions."""
    x, y = np.sort(x), np.sort(y)
    grid = np.concatenate([x, y])
    fx = np.searchsorted(x, grid, side="right") / len(x)
    fy = np.searchsorted(y, grid, side="right") / len(y)
    return float(np.max(np.abs(fx - fy)))


def wasserstein1(x, y):
    """1-Wasserstein distance: integral of |F_x - F_y| over the real line."""
    x, y = np.sort(x), np.sort(y)
    grid = np.sort(np.concatenate([x, y]))
    fx = np.searchsorted(x, grid[:-1], side="right") / len(x)
    fy = np.searchsorted(y, grid[:-1], side="right") / len(y)
    return float(np.sum(np.abs(fx - fy) * np.diff(grid)))


def cost_at_error(errors, seconds, target):
    """Wall time a method needs for error `target`, from its measured (error, seconds) points.

    Returns (seconds, how): "interpolated" log-log between the two points that bracket the
    target; "bound" if every point is already below the target (the cheapest such run, an
    upper bound on the cost); (None, "not reached") if every point is above it.
    """
    pts = sorted((e, s) for e, s in zip(errors, seconds) if e is not None and np.isfinite(e) and e > 0)
    if not pts or min(e for e, _ in pts) > target:
        return None, "not reached"
    if max(e for e, _ in pts) <= target:
        return min(s for _, s in pts), "bound"
    for (e0, s0), (e1, s1) in zip(pts, pts[1:]):
        if e0 <= target <= e1:
            w = np.log(target / e0) / np.log(e1 / e0) if e1 > e0 else 0.0
            return float(np.exp(np.log(s0) + w * (np.log(s1) - np.log(s0)))), "interpolated"
    raise AssertionError("unreachable")


def single_event_parser(doc, runs, sizes, runs_help):
    """The options of the benchmarks on single events from pre-event states of a developed chain:
    --N, --b, --transient, --seed, --runs (default `runs`), --sizes (default `sizes`), --out."""
    p = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--N", type=int, default=800, help="blocks")
    p.add_argument("--b", type=float, default=20.0)
    p.add_argument("--transient", type=int, default=1000, help="events before the pre-event states are taken")
    p.add_argument("--seed", type=int, default=0, help="root seed of the developed chain")
    p.add_argument("--runs", nargs="+", default=runs, help=runs_help)
    p.add_argument("--sizes", nargs="+", default=sizes, metavar="LABEL:LOW:HIGH",
                   help="event classes by magnitude, LOW <= mu < HIGH (one event of each)")
    p.add_argument("--out", default="benchmarks/results")
    return p


def write_outputs(out, stem, data, lines):
    """Print the table lines and write them to OUT/STEM.txt, the data to OUT/STEM.json."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    print("\n".join(lines))
    (out / f"{stem}.txt").write_text("\n".join(lines) + "\n")
    (out / f"{stem}.json").write_text(json.dumps(data, indent=1, default=_jsonable))
    return out / f"{stem}.json"


def _jsonable(x):
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    raise TypeError(f"cannot write {type(x).__name__} to JSON")


def pyplot():
    """matplotlib.pyplot without a display."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def save_figure(fig, axes, title, path):
    """Legend in the first panel, title, tight layout; write to path and free the figure."""
    axes[0, 0].legend(fontsize=6)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    pyplot().close(fig)


def minutes(seconds):
    return f"{seconds / 60:.1f} min" if seconds >= 60 else f"{seconds:.0f} s"


class Clock:
    """Wall time since creation, and a deadline check."""

    def __init__(self, limit=float("inf")):
        self.start = time.perf_counter()
        self.limit = limit

    @property
    def elapsed(self):
        return time.perf_counter() - self.start

    @property
    def expired(self):
        return self.elapsed > self.limit
