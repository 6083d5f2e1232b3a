"""One event's history (output.history; ensemble/store/histories.py) drawn: the slip velocity of every block
against time on a log scale, from the onset to the end, so that the slow initial phase, the acceleration and
the rupture's spread can be seen.

    python -m analysis history CATALOG -o FIG.png [--task K] [--index J]

Left: log10 of the velocity over (block, time) on the rupture zone and MARGIN blocks beside it, the time axis
of each snapshot in turn (their spacing is the kernel's: one per change of the largest velocity by
output.history_dlogv, or per output.history_dt); the labels give the snapshots' times. Right: against time, the
largest velocity and the epicenter's (log scale) and the number of blocks sliding: the initial phase (one or a
few blocks accelerating slowly), the acceleration and the rupture's spread.

On a plane (model.geometry = "lattice") the left panel is the epicenter's row along strike (block i at
x = i % N, y = i // N): the rupture's extent along it and MARGIN blocks beside it; the right panel is the
whole plane's.
"""
import numpy as np

from ensemble.store import reader
from ensemble.store.errors import CatalogError

from .drawing import FONT, layout, plt, save

V_FLOOR = 1e-12    # velocities below this (and 0: at rest) are drawn as it
MARGIN = 20        # blocks drawn on either side of the rupture zone


def pick(path, task=None, index=0):
    """(task, its history number `index`, the history, the event's row of /events as a dict) of a catalog;
    task None: the first task with a history. CatalogError where there is none."""
    with reader.Reader(path) as cat:
        tasks = range(len(cat.tasks["point"])) if task is None else [task]
        if task is not None and not 0 <= task < len(cat.tasks["point"]):
            raise CatalogError(f"{path}: no task {task} (it has {len(cat.tasks['point'])})")
        for k in tasks:
            kept = cat.histories(k)
            if len(kept) > index:
                h = kept[index]
                row = k * cat.per_task + h["row"]
                event = {name: ds[row] for name, ds in cat.layout.events.items()}
                event["run"] = ", ".join(f"{name} = {cat.tasks[name][k]:g}" for name in ("N", "M", "l", "a", "b")
                                         if np.isfinite(cat.tasks[name][k]) and (name != "M" or cat.tasks[name][k] > 1))
                # blocks along strike (a row of the plane, or the chain) and rows across
                event["along"], event["rows"] = int(cat.tasks["N"][k]), int(cat.tasks["M"][k])
                return k, index, h, event
    where = "any task" if task is None else f"task {task}"
    raise CatalogError(f"{path}: {where} has no event history {index} (output.history: the events whose "
                       f"history a run keeps)")


def draw(path, output, task=None, index=0):
    """The figure of one history; returns a line that says which event it shows."""
    k, j, h, ev = pick(path, task, index)
    time, v = h["time"], np.maximum(h["velocity"], V_FLOOR)
    logv = np.log10(v)
    n = ev["along"]
    epicenter = int(ev["epicenter"])
    row = epicenter // n    # (0 on a chain) the epicenter's row along strike, blocks row * n .. row * n + n - 1
    plane = ev["rows"] > 1
    # the rupture zone and a margin: the blocks that moved (first and last are positions along strike)
    lo, hi = max(int(ev["first"]) - MARGIN, 0), min(int(ev["last"]) + MARGIN, n - 1)
    fig, (left, right) = plt.subplots(1, 2, figsize=(9.0, 4.2))
    image = left.imshow(logv[:, row * n + lo:row * n + hi + 1], origin="lower", aspect="auto", cmap="viridis",
                        interpolation="nearest", extent=(lo - 0.5, hi + 0.5, -0.5, len(time) - 0.5),
                        vmin=np.log10(V_FLOOR))
    ticks = np.unique(np.linspace(0, len(time) - 1, 7).round().astype(int))
    left.set_yticks(ticks)
    left.set_yticklabels([f"{time[t]:.3g}" for t in ticks], fontsize=FONT)
    left.set_xlabel(f"block along strike, the epicenter's row {row} across" if plane else "block", fontsize=FONT + 1)
    left.set_ylabel("time since the onset (one row per snapshot)", fontsize=FONT + 1)
    left.tick_params(labelsize=FONT)
    bar = fig.colorbar(image, ax=left)
    bar.set_label("log10 velocity", fontsize=FONT + 1)
    bar.ax.tick_params(labelsize=FONT)
    # the phases in time: the largest velocity and the epicenter's, and how many blocks slide
    right.semilogy(time, v.max(axis=1), color="C0", lw=1.2, label="largest velocity")
    right.semilogy(time, v[:, epicenter], color="C1", lw=1.0, ls="--", label=f"epicenter (block {epicenter})")
    right.set_ylim(V_FLOOR, v.max() * 3)
    right.set_xlabel("time since the onset", fontsize=FONT + 1)
    right.set_ylabel("velocity", fontsize=FONT + 1)
    right.tick_params(labelsize=FONT)
    count = right.twinx()
    count.plot(time, h["sliding"], color="C2", lw=1.0, label="blocks sliding")
    count.set_ylabel("blocks sliding", fontsize=FONT + 1, color="C2")
    count.tick_params(labelsize=FONT)
    lines = right.get_lines() + count.get_lines()
    right.legend(lines, [line.get_label() for line in lines], fontsize=FONT, loc="upper center", ncol=3,
                 bbox_to_anchor=(0.5, -0.14), frameon=False)
    across = f" along, {int(ev['across_first'])}..{int(ev['across_last'])} across" if plane else ""
    what = (f"task {k} ({ev['run']}), row {h['row']}: mu = {float(ev['mu']):.2f}, epicenter {int(ev['epicenter'])}, "
            f"blocks {int(ev['first'])}..{int(ev['last'])}{across}, duration {float(ev['duration']):.4g}, "
            f"{len(time)} snapshots"
            + (f" ({h['dropped']} dropped)" if h["dropped"] else ""))
    layout(fig, f"event history {j} of {what}", 0.15)
    save(fig, output)
    return what
