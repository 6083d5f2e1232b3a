"""The tables of docs/paper/tables.md from the committed full-size summaries (docs/paper/*.summary.h5).

    python examples/paper/tables.py [DIR]  > docs/paper/tables.md      (DIR default docs/paper)

1. The runs: per task its parameters, events, wall time and events/s as the runner recorded them
   (events/s: recorded events per second of kernel time; the wall time is that of the task's
   last run segment, so a task resumed after an interruption is marked and undercounted).
2. The paper's claims beside the full-size numbers: `python -m analysis paper` on the five panels'
   summaries (analysis/paper.py; the README's table).
3. One model, independent trajectories: the spread of the points that are one model in several
   panels, against their intervals.
"""
import sys
from pathlib import Path

import numpy as np

from analysis import paper, summary

PANELS = ("fig1_b", "fig1_a", "fig1_c", "fig2", "large_b")


def load(d):
    """{panel: its summary, or None where it has not been reduced}, each read once."""
    paths = {name: Path(d) / f"{name}.summary.h5" for name in PANELS}
    return {name: summary.read(path) if path.exists() else None for name, path in paths.items()}


def point_of(s, **params):
    rows = [i for i in range(len(s["points/N"])) if all(s[f"points/{k}"][i] == v for k, v in params.items())]
    assert len(rows) == 1, (params, rows)
    return rows[0]


def runs_table(panels):
    out = ["| run | N | a | b | c | events | wall time [s] | events/s |", "|---|---|---|---|---|---|---|---|"]
    total_events = total_wall = 0.0
    for name, s in panels.items():
        if s is None:
            out.append(f"| {name} | not run yet | | | | | | |")
            continue
        for k in range(len(s["tasks/N"])):
            events, wall = int(s["tasks/events_written"][k]), float(s["tasks/wall_time"][k])
            total_events += events
            total_wall += wall
            rate = float(s["tasks/events_per_second"][k])
            # wall_time covers the task's last run segment only: after a resume it misses the
            # part before (recognised by a wall time too short for the recorded events)
            resumed = wall * rate < 0.9 * events
            out.append(f"| {name} | {int(s['tasks/N'][k])} | {s['tasks/a'][k]:g} | {s['tasks/b'][k]:g} | "
                       f"{s['tasks/c'][k]:g} | {events} | {wall:.0f}{' (after a resume)' if resumed else ''} | "
                       f"{rate:.0f} |")
    out.append(f"\nAll tasks: {int(total_events)} events in {total_wall:.0f} s of task time "
               f"({total_wall / 3600:.2f} core-hours).")
    return "\n".join(out)


# Points that are one model in several panels (c drops out exactly, so every b = 20, a = 0, N = 800
# point is the same model): independent trajectories whose spread tests the intervals.
SAME_MODEL = {"b = 20, a = 0, N = 800": [("fig1_b", {"b": 20.0}), ("fig1_c", {"c": 100.0}), ("fig1_c", {"c": 1000.0}),
                                         ("fig1_c", {"c": 10000.0}), ("fig2", {"b": 20.0, "N": 800})],
              "b = 50, a = 0, N = 800": [("fig1_b", {"b": 50.0}), ("fig1_a", {"a": 0.0})]}


def consistency_table(panels):
    """Per model and number: the trajectories' values and chi^2 / dof of their spread."""
    out = ["| model | number | independent trajectories | chi^2 / dof |", "|---|---|---|---|"]
    for model, members in SAME_MODEL.items():
        found = [(name, panels[name], params) for name, params in members]
        found = [(name, s, point_of(s, **params), params) for name, s, params in found if s is not None]
        if len(found) < 2:
            continue
        for key in ("fraction_large", "gr_b", "ks_gr", "mean_tnu"):
            rows = np.array([s[f"points/numbers/{key}"][i] for _, s, i, _ in found])
            sigma = (rows[:, 2] - rows[:, 1]) / (2 * 1.96)
            w = 1 / sigma ** 2
            mean = np.sum(w * rows[:, 0]) / np.sum(w)
            chi2 = np.sum(w * (rows[:, 0] - mean) ** 2) / (len(rows) - 1)
            values = "; ".join(f"{paper.fmt(r[0], 4)} ({name} {', '.join(f'{k} = {v:g}' for k, v in params.items())})"
                               for r, (name, _, _, params) in zip(rows, found))
            out.append(f"| {model} | {key} | {values} | {chi2:.2f} ({len(rows) - 1}) |")
    return "\n".join(out)


def main(d="docs/paper"):
    panels = load(d)
    print("<!-- written by `python examples/paper/tables.py` from docs/paper/*.summary.h5 -->")
    print("## Runs\n")
    print(runs_table(panels))
    found = [s for s in panels.values() if s is not None]
    # the heading says what the table's column says: full size, or reduced (python -m analysis paper)
    print(f"\n## The paper's claims {'at full size' if paper.is_full_size(found) else 'in a reduced run'}\n")
    print(paper.claims_table(found))
    print("\n## One model, independent trajectories\n")
    print("c drops out of the equations exactly, so every b = 20, a = 0, N = 800 point of the panels is one "
          "model; each panel ran it from its own seed. chi^2 / dof of the values about their weighted mean, "
          "sigma = 95% half-width / 1.96: about 1 if the intervals are right, much more if too narrow.\n")
    print(consistency_table(panels))


if __name__ == "__main__":
    main(*sys.argv[1:])
