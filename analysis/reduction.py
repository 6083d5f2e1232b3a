"""A reduction as one call: catalogs -> summary, on the ranks of a communicator (`python -m analysis reduce` and
analysis.reduce, the Python front door, both call reduce_on).

Every check comes before the work: the options (analysis/options.py), the output path (checks.output: not one
of the inputs, a missing or read-only folder, an existing file without force, which replaces only a summary),
the catalogs (analysis/merge.py: their kinds, unfinished runs without `partial`, the same trajectory twice) and
the memory the options ask for. Rank 0 reads the task table and decides; every rank reduces its share of the
tasks; rank 0 gathers them, computes each point's statistics and writes the summary (summary.write).
"""
import os
from dataclasses import dataclass, field

from ensemble import checks, filekind
from ensemble.store.errors import CatalogError

from . import merge, options, summary
from .geometry import CHAIN
from .reduce import LAYOUT, MIN_UNITS, NUMBERS, bin_edges, point_statistics, unreliable

# errors that reduce's rank 0 finds before the work starts and every rank then raises alike
# (ensemble.run.abort.on_root), with their exit codes; any other error on any rank aborts them all
# (merge.MergeError is a ValueError: exit 2)
COLLECTIVE = {ValueError: 2, CatalogError: 1, summary.SummaryError: 1, OSError: 1}


@dataclass(frozen=True)
class Request:
    """What a reduction is asked: its catalogs, the summary's path (None: beside the one catalog), whether an
    unfinished run may be reduced (`partial`) and an existing summary replaced (`force`), a regional reduction
    (`region`, its window's span and skip, T nu), and the options given ({name: value}, checked; the others take
    their defaults)."""
    catalogs: list
    output: object = None
    partial: bool = False
    force: bool = False
    region: bool = False
    region_span: object = None
    region_skip: object = None
    given: dict = field(default_factory=dict)


def default_output(catalogs):
    if len(catalogs) > 1:
        raise ValueError("reducing several catalogs into one summary: give its path with -o")
    name = str(catalogs[0])
    if name.endswith(".partial"):   # X.h5.partial -> X.partial.summary.h5, beside the final one's name
        return name.removesuffix(".partial").removesuffix(".h5") + ".partial.summary.h5"
    return name.removesuffix(".h5") + ".summary.h5"


def _scales(given, inputs):
    """The friction law's scales (Law.scales) of the catalogs, for the options whose default is the law's and that
    were not given; None when every such option was given."""
    missing = [o for o in options.declared("reduce").values() if o.name not in given and options.default(o) is None]
    if not missing:
        return None
    from ensemble.model import laws
    names = sorted({merge.law_name(law) for law in inputs.tasks["law"]})
    for name in names:
        if name not in laws.LAWS:
            raise ValueError(f"friction law {name!r} is unknown to this version: give "
                             + ", ".join(o.flag for o in missing))
    if len({laws.get(name).scales for name in names}) > 1:
        raise ValueError(f"the catalogs hold points of several friction laws ({', '.join(names)}), whose "
                         "magnitudes lie on different scales: give " + ", ".join(o.flag for o in missing))
    return laws.get(names[0]).scales


def check_summary_output(out, catalogs, force):
    """The summary's path (checks.output: before any file is read); --force replaces a summary,
    never anything else (a catalog, a config)."""
    checks.output(out, inputs=catalogs, force=force, what="summary")
    checks.output(f"{out}.partial", inputs=catalogs, force=True, what="summary")   # written first, then renamed
    if os.path.exists(out) and filekind.identify(out)[0] != "summary":
        raise checks.UsageError(f"{out} {filekind.describe(out)}; --force replaces only a reduction summary")
    return out


def _memory(opt, n_tasks):
    """Refuse options whose arrays this machine cannot hold: rank 0 gathers every task's (stretches, entries) tables
    and stacks them for the summary; a point's bootstrap keeps, per resample, its picks of units (at most tasks x
    blocks), its numbers and its curves, and a statistic's extras about as much again as its curves (the recurrence
    peaks' resampled counts)."""
    edges = bin_edges(opt)
    per_task = opt.blocks * sum(LAYOUT.width(name, edges) for name in LAYOUT.tables)
    curves = sum(len(edges[LAYOUT.tables[c.table].bins]) - 1 for c in LAYOUT.curves if c.values is None)
    resamples = opt.bootstrap * (2 * curves + len(NUMBERS) + n_tasks * opt.blocks)
    checks.memory(f"--blocks {opt.blocks}, --bootstrap {opt.bootstrap} and {curves} bins of curves over {n_tasks} "
                  "tasks", 8 * (2 * n_tasks * per_task + resamples))


def prepare(request):
    """(options, output path, the catalogs' task table: merge.Inputs); every check before the work."""
    out = check_summary_output(request.output or default_output(request.catalogs), request.catalogs, request.force)
    for name in ("region_span", "region_skip"):
        if getattr(request, name) is not None and not request.region:
            raise checks.UsageError(f"--{name.replace('_', '-')} sets the window of a regional reduction: "
                                    f"give --region too")
    # (checks each file's kind first)
    inputs = merge.read(request.catalogs, allow_partial=request.partial, region=request.region,
                        span=request.region_span, skip=request.region_skip or 0.0)
    opt = options.make("reduce", _scales(request.given, inputs), **request.given)
    _memory(opt, len(inputs.tasks["point"]))
    return opt, out, inputs


def _check_counts(inputs, per_task):
    """Every rank reduced as many rows as rank 0 read from the commit rows (a run still writing
    the catalog could have committed more in between)."""
    for g, h in per_task.items():
        if h.rows != int(inputs.tasks["events_written"][g]):
            path = inputs.paths[inputs.tasks["catalog"][g]]
            raise CatalogError(f"{path}: task {inputs.tasks['catalog_task'][g]}: its event count "
                               "changed while it was reduced (is a run still writing it?)")


def reduce_on(comm, request, say=print, warn=None):
    """The reduction `request` on the ranks of `comm`; rank 0 writes the summary. say: what rank 0 reports (the
    summary written, a partial reduction); warn: its warnings (default: to stderr). Returns 0 and, on rank 0, sets
    nothing else: the summary's path is request.output or default_output(request.catalogs)."""
    import sys

    from ensemble.run.abort import abort_on_error, on_root
    if warn is None:
        def warn(line):
            print(f"warning: {line}", file=sys.stderr)
    rank, size = comm.Get_rank(), comm.Get_size()
    opt, out, inputs = on_root(comm, lambda: prepare(request), tuple(COLLECTIVE))
    mine = [g for g in range(len(inputs.tasks["point"])) if g % size == rank]
    with abort_on_error(comm):   # rank 0 waits in gather for every other rank's part
        parts = comm.gather(merge.reduce_share(inputs, mine, opt), root=0)
    if rank != 0:
        return 0
    per_task = {k: h for part in parts for k, h in part.items()}
    _check_counts(inputs, per_task)
    points = []
    for params, ids in inputs.points:
        result = point_statistics(per_task, ids, opt, merge.bootstrap_rng(opt.seed, params),
                                  whole="faults" if request.region else "seeds",
                                  geometry_name=params.get("geometry", CHAIN))
        result["params"] = params
        points.append(result)
    for line in inputs.warnings:
        warn(line)
    summary.write(out, inputs, per_task, points, opt, force=request.force)
    if inputs.partial:
        say(inputs.partial)
    for i, p in enumerate(points):
        why = unreliable(p["units"], p["method"])
        if why:
            what = (f"region {i} ({p['params']['region']})" if request.region else f"point {i} ({p['params']['law']}: "
                    + ", ".join(f"{k} = {v}" if isinstance(v, str) else f"{k} = {v:g}"
                                for k, v in p["params"].items() if k != "law" and v == v) + ")")
            warn(f"{what}: {why}")
    methods = sorted({p["method"] for p in points})
    say(f"wrote {out}: {len(points)} {'regions' if request.region else 'parameter points'}, {len(per_task)} tasks"
        + (f" from {len(inputs.paths)} catalogs" if len(inputs.paths) > 1 else "")
        + "; intervals from "
        f"{opt.bootstrap} bootstrap resamples over {' / '.join(methods)}"
        + (f" (fewer than {MIN_UNITS} seeds per point: block bootstrap over stretches of each trajectory)"
           if "blocks" in methods else ""))
    return 0
