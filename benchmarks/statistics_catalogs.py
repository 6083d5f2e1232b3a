"""Catalog mode of benchmarks/statistics.py (`--catalogs REF.h5 CAND.h5 ...`): the settings read from runs
already done, one per catalog, labelled by their stored [integrator]; each point's candidates against the
reference, with the noise floor, table and figure of statistics_distances.py (statistics.py's docstring)."""
import dataclasses
import tomllib

import numpy as np

from ensemble.config import LAW_KEYS, Integrator
from ensemble.integrators import INTEGRATORS
from ensemble.model import laws
from ensemble.store import reader

from .common import write_outputs
from .statistics_distances import (noise_floor, plot, pooled, rerun_lines, rerun_rows, seed_samples, summarize, table,
                                   with_rerun, within_noise)

# what tells parameter points apart (as analysis.reduce.PARAMS, with the law's name)
POINT_KEYS = ("N", "l", "nu", "law", *LAW_KEYS)


class Refused(ValueError):
    """Catalogs that cannot be compared (one line naming the file): exit 2."""


def short(value):
    """A number as a setting label writes it: 1e-3, 2.5e-4, 0.5."""
    if isinstance(value, float) and value and not 1e-2 <= abs(value) < 1e4:
        return np.format_float_scientific(value, trim="-", exp_digits=1)
    return f"{value:g}" if isinstance(value, float) else str(value)


# [integrator] keys only the adaptive methods read (config.Integrator)
ADAPTIVE_ONLY = ("rtol", "atol", "max_step")


def integrator_label(texts):
    """Tasks' stored [integrator] TOML -> a setting label: the method, its step or tolerance
    (rk4: dt; adaptive: rtol), and any other key off its default ("ark4:rtol=1e-3")."""
    defaults = dataclasses.asdict(Integrator())
    labels = []
    for text in dict.fromkeys(t for t in texts if t):
        fields = tomllib.loads(text)
        method = fields.pop("method")
        adaptive = INTEGRATORS[method].adaptive
        main_key = "rtol" if adaptive else "dt"
        unused = () if adaptive else ADAPTIVE_ONLY      # what RK4 ignores, whatever its value
        keys = [main_key] + [k for k, v in fields.items()
                             if k != main_key and k not in unused and v != defaults.get(k)]
        labels.append(f"{method}:" + ",".join(f"{k}={short(fields[k])}" for k in keys))
    return "+".join(labels) or "unknown"


def point_of(tasks, k):
    """Task k's parameter point: ((key, value), ...), NaN as None so that equal points compare equal."""
    values = []
    for key in POINT_KEYS:
        v = tasks[key][k]
        v = str(v) if key == "law" else float(v)
        values.append((key, None if isinstance(v, float) and np.isnan(v) else v))
    return tuple(values)


def read_catalog(path, mu_c, window):
    """One catalog -> its setting: root seed, transient, and per point each task's samples
    (seed_samples, as a simulated trajectory's), events/s, committed and planned events."""
    with reader.Reader(path) as cat:
        tasks = cat.tasks
        config = tomllib.loads(str(cat.attrs["config"]))
        out = {"path": str(path), "label": integrator_label(tasks["integrator"]),
               "root_seed": config["run"]["seed"], "transient": int(cat.attrs["transient"]), "points": {}}
        for k in range(len(tasks["point"])):
            point = point_of(tasks, k)
            c = laws.get(str(tasks["law"][k])).scales.mu_c if mu_c is None else mu_c
            p = out["points"].setdefault(point, {"mu_c": c, "window": window, "per_seed": {}, "rates": [],
                                                 "written": 0, "planned": 0})
            samples = seed_samples(cat.task_events(k), int(tasks["N"][k]), float(tasks["nu"][k]), c, window)
            rate = float(tasks["events_per_second"][k])
            seconds = len(samples["mu"]) / rate if rate > 0 else float("nan")   # NaN: not finished
            p["per_seed"][int(tasks["seed_index"][k])] = {"status": "ok", **samples, "seconds": seconds}
            p["rates"].append(rate)
            p["written"] += int(tasks["events_written"][k])
            p["planned"] += int(cat.per_task)
    return out


def point_text(point):
    return ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}" for k, v in point if v is not None)


def check_against(ref, cand):
    """Refused unless the candidate has the reference's points and their mu_c and window."""
    if set(cand["points"]) != set(ref["points"]):
        extra = [point_text(p) for p in cand["points"] if p not in ref["points"]]
        missing = [point_text(p) for p in ref["points"] if p not in cand["points"]]
        raise Refused(f"{cand['path']}: its points differ from the reference {ref['path']}'s"
                      + (f"; not in the reference: {'; '.join(extra)}" if extra else "")
                      + (f"; missing: {'; '.join(missing)}" if missing else ""))
    for point, p in cand["points"].items():
        r = ref["points"][point]
        if (p["mu_c"], p["window"]) != (r["mu_c"], r["window"]):
            raise Refused(f"{cand['path']}: mu_c = {p['mu_c']:g}, window = {p['window']} at {point_text(point)}; "
                          f"the reference {ref['path']} has {r['mu_c']:g}, {r['window']}")


def point_stem(name, point, points):
    """{name}_N{N}_b{b}, and every other key that differs between the points."""
    values = dict(point)
    keys = ["N"] + (["b"] if values["b"] is not None else [])
    keys += [k for k in POINT_KEYS if k not in keys and len({dict(q)[k] for q in points}) > 1]
    return name + "".join(f"_{k}{short(values[k]) if isinstance(values[k], float) else values[k]}"
                          for k in keys if values[k] is not None)


def compare_catalogs(args):
    """Catalog mode: per point, the candidates' distances from the reference; the data per point."""
    settings = [read_catalog(path, args.mu_c, args.window) for path in args.catalogs]
    ref = settings[0]
    rerun = read_catalog(args.rerun, args.mu_c, args.window) if args.rerun else None
    for cand in settings[1:] + ([rerun] if rerun else []):
        check_against(ref, cand)
    for s, label in zip(settings, args.label or [s["label"] for s in settings]):
        s["label"] = label
    results = {}
    for point in ref["points"]:
        with_events = {k: r for k, r in ref["points"][point]["per_seed"].items() if len(r["mu"])}
        if len(with_events) < 2:
            raise Refused(f"{ref['path']}: committed events in {len(with_events)} seed(s) at {point_text(point)}; "
                          "the noise floor needs two")
        pools = [pooled(s["points"][point]["per_seed"], float(np.nanmean(s["points"][point]["rates"]))
                        if np.isfinite(s["points"][point]["rates"]).any() else float("nan")) for s in settings]
        rows = [summarize(ref["label"], pools[0], None)]
        rows += [summarize(s["label"], pool, pools[0]) for s, pool in zip(settings[1:], pools[1:])]
        floor = noise_floor(with_events)
        if rerun:
            floor = with_rerun(floor, with_events, rerun["points"][point]["per_seed"])
        title = f"{point_text(point)}, from catalogs, reference {ref['label']}"
        stem = point_stem(args.name, point, list(ref["points"]))
        inside = within_noise(rows, floor)
        lines = table(rows, floor, title) + catalog_notes(settings + ([rerun] if rerun else []), point)
        against_rerun = []
        if rerun:
            lines.append(f"noise floor: also the halves of the rerun {rerun['path']} (root seed "
                         f"{rerun['root_seed']}) and its distance from the reference")
            against_rerun = rerun_rows(rows, pools, rerun["points"][point]["per_seed"])
            lines += rerun_lines(against_rerun)
        lines.append(f"within the noise (every distance <= the floor's max): {', '.join(inside) or 'none'}")
        data = {"config": vars(args), "point": dict(point), "rows": rows, "noise_floor": floor,
                "within_noise": inside, "against_rerun": against_rerun,
                "catalogs": [{"path": s["path"], "label": s["label"], "root_seed": s["root_seed"],
                              "transient": s["transient"], "events_written": s["points"][point]["written"],
                              "events_planned": s["points"][point]["planned"],
                              "task_events_per_second": s["points"][point]["rates"]} for s in settings]}
        write_outputs(args.out, stem, data, lines)
        plot(rows, floor, f"{args.out}/{stem}.png", title,
             xlabel="events per second (mean over the catalog's tasks, as its run measured)",
             floor_label="noise floor (halves of the reference and its rerun, and their distance)" if rerun
             else "noise floor (reference halves)")
        results[stem] = data
    return results


def catalog_notes(settings, point):
    ref = settings[0]
    lines = ["events/s: the mean of each catalog's /tasks/events_per_second (recorded events per second of "
             "kernel time, as its run measured it; those runs may have shared the machine, so the rates "
             "compare only roughly; nan until a task has finished)",
             "catalogs (events committed / planned at this point, root seed, transient):"]
    for s in settings:
        p = s["points"][point]
        notes = [] if p["written"] == p["planned"] else ["INCOMPLETE"]
        if p["written"] < ref["points"][point]["written"]:
            notes.append("fewer events than the reference: more noise than the floor says")
        if s is not ref and s["root_seed"] == ref["root_seed"]:
            notes.append("the reference's root seed: not an independent sample")
        if s["transient"] != ref["transient"]:
            notes.append("another transient than the reference's")
        lines.append(f"  {s['label']:22s} {p['written']:8d} / {p['planned']:<8d} seed {s['root_seed']:<4d} "
                     f"transient {s['transient']:<6d} {s['path']}" + "".join(f"  [{n}]" for n in notes))
    return lines
