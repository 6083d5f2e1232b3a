"""Catalog -> per-task histograms (streamed) -> per-point statistics with bootstrap intervals.

R(mu), the recurrences and GR b are those of the inertial events (/events/kind 0). The creep
episodes (kind 1, below the block stiffness) have statistics of their own, the slow side: their
size (mu = log10 of the slip released by creep) and duration (log10 of duration nu) densities, the
share of rows they are, the share taken over by an inertial event, and the aseismic slip fraction
(creep slip over all slip). Each task is cut into `blocks` stretches of consecutive inertial
events; a creep row belongs to the stretch of the inertial events before it in the task's rows
(it is written when its episode ends; a task without inertial events is cut by its rows). Histograms and
sums are kept per (task, stretch). Error bars come from resampling
independent realisations: the seeds of a parameter point when it has at least
MIN_UNITS of them, else the stretches of every one of its trajectories (a block
bootstrap: a few long trajectories, as in the paper's one seed per point, give
many stretches but only a few seeds), which the summary says. Events within a
trajectory are correlated, so resampling single events would understate the errors.
"""
import numpy as np

from ensemble import checks, filekind
from ensemble.store import reader, schema
from ensemble.store.errors import CatalogError
from ensemble.config import LAW_KEYS

from . import geometry, stats
from .recurrence import RecurrenceScanner
from .statistics import CRITERIA, Layout, Rows, refusal

# the parameters that tell points apart: the chain's, and every friction law's keys (NaN where a
# key is not of the task's law, so tasks of two laws never pool); a plane's shape besides (GEOMETRY_PARAMS,
# analysis/geometry.py: a point of another geometry than the chain has them, and a summary holding one says them)
PARAMS = ("N", "l", "nu", *LAW_KEYS)
GEOMETRY_PARAMS = schema.GEOMETRY_TASKS


# every statistic of analysis/statistics/, laid out: its tables, numbers and curves in the registry's order
LAYOUT = Layout()
# the densities of a point, in the order of its curves (name -> the bins of its table)
CURVES = {c.name: LAYOUT.tables[c.table].bins for c in LAYOUT.curves}


def bin_edges(opt, n_blocks=None, layout=LAYOUT):
    """{bins name: edges} of the options (the summary's /bins/<name>): option <name>_edges; bins of the
    chain's own (Table.chain_edges) from its number of blocks, `n_blocks` (N, or N M on a plane)."""
    return {name: layout.chain_bins[name](n_blocks) if name in layout.chain_bins else getattr(opt, f"{name}_edges")
            for name in layout.bins}


def _criteria(layout):
    """The criteria of a large event (statistics.CRITERIA, each declared by a statistic) whose recurrences the
    layout's statistics need ("recurrences:<criterion>"; "recurrences" alone: mu), in order."""
    need = [n.partition(":")[2] or "mu" for s in layout.statistics for n in s.needs if n.startswith("recurrences")]
    return [CRITERIA[name] for name in dict.fromkeys(need)]


MAX_BINS = 10 ** 6   # bins of a histogram: beyond a million, (tasks, stretches, bins) counts outgrow memory


def parse_bins(text, name="bins"):
    """'lo:hi:n' -> n + 1 equally spaced edges, finite and strictly increasing (checks.UsageError
    naming the option `name` otherwise, before any file is read)."""
    parts = str(text).split(":")
    if len(parts) != 3:
        raise checks.UsageError(f"{name} must be lo:hi:n, got {text!r}")
    lo, hi = (checks.number(f"{name} {end}", value) for end, value in zip(("lo", "hi"), parts))
    n = checks.count(f"{name} n", parts[2], lo=1, hi=MAX_BINS)
    if not hi > lo:
        raise checks.UsageError(f"{name} must have hi > lo, got {text!r}")
    with np.errstate(over="ignore", invalid="ignore"):
        edges = np.linspace(lo, hi, n + 1)
        if not (np.all(np.isfinite(edges)) and np.all(np.diff(edges) > 0)):
            raise checks.UsageError(f"{name} {text!r}: its edges are not distinct finite float64 values")
    return edges


def reduce_task(chunks, written, nu, blocks, opt, rows=None, layout=LAYOUT):
    """Stream one task's rows (chunks of dicts of columns, `written` inertial events and `rows`
    rows of every kind in all) into its tables (statistics.Tables: {table: (stretches, width)}; the
    attribute `rows` the rows read). blocks: the task's geometry.Shape (or its number of blocks: a chain).
    Every statistic is fed each chunk once, but one that refuses the task's geometry (statistics.refusal):
    its tables stay empty. The chunks are consumed to their end (the catalog checks a task's checksum there)."""
    shape = geometry.shape(blocks)
    out = layout.empty(opt.blocks, bin_edges(opt, shape.n_blocks, layout))
    out.rows = 0
    fed = [statistic for statistic in layout.statistics if not refusal(statistic, shape.geometry)]
    for seen in task_rows(chunks, written, nu, shape, opt, rows, layout):
        for statistic in fed:
            statistic.feed(out, seen)
    out.carry.clear()    # the statistics' carry of this task ends with it
    for name in layout.samples:   # a stretch's sample: one array of its values in the order fed
        out[name] = [np.concatenate(parts) if parts else np.zeros(0) for parts in out[name]]
    return out


def task_rows(chunks, written, nu, blocks, opt, rows=None, layout=LAYOUT):
    """The statistics' view of each chunk of one task's rows (statistics.Rows: the inertial events and creep
    episodes apart, their stretches, the recurrences of each large-event criterion so far), as reduce_task feeds
    them; arguments as there."""
    k = opt.blocks
    shape = geometry.shape(blocks)
    scanners = {c: RecurrenceScanner(shape, float(getattr(opt, c.threshold)), getattr(opt, c.window))
                for c in _criteria(layout)} if written else {}
    lo = row = 0
    t_before = np.nan
    for part in chunks:
        inertial = part["kind"] == schema.KIND_EVENT
        creep = part["kind"] == schema.KIND_CREEP
        creep_block = _creep_stretches(inertial, creep, lo, row, written, rows, k) if creep.any() else None
        row += len(inertial)
        ev = block = None
        scans = {}
        if inertial.any():
            ev = part if inertial.all() else {name: column[inertial] for name, column in part.items()}
            hi = lo + len(ev["t"])
            block = (np.arange(lo, hi) * k) // written
            for criterion, scanner in scanners.items():
                values = np.asarray(ev[criterion.column], dtype=float)
                src, T, interior = scanner.feed(ev["t"], ev["epicenter"], values, ev["boundary"])
                scans[criterion.name] = ((src * k) // written, T * nu, interior)
            lo = hi
        yield Rows(part, inertial, ev, block, creep, creep_block, scans.get("mu"), t_before, nu, opt, shape.n_blocks,
                   ev is not None and lo == written, scans, shape)
        if ev is not None:
            t_before = ev["t"][-1]


def _creep_stretches(inertial, creep, before, row, written, rows, k):
    """The stretches of a chunk's creep episodes; `before` inertial events and `row` rows of the task
    precede the chunk. A creep row's stretch is that of the inertial events before it (the last one
    after the last event); without events, by its row."""
    if written:
        events_before = before + np.cumsum(inertial) - inertial
        return np.minimum((events_before[creep] * k) // written, k - 1)
    return ((row + np.flatnonzero(creep)) * k) // max(rows or 0, row + len(creep))


def reduce_tasks(path, task_indices, opt, layout=LAYOUT, windows=None):
    """TaskHistograms for the given tasks of a catalog (one rank's share). windows: {task: (start, end)}, the
    rows of a task with start <= t < end only (a region's window: analysis/region.py); the attribute `rows` is
    still every committed row read."""
    out = {}
    # the catalog checks the ranges of the rows as they stream (an epicenter outside the task's blocks would
    # also break RecurrenceScanner's packing bound; it checks them too) and each task's checksum after its last chunk
    with filekind.reading(path, "the event catalog", CatalogError), reader.Reader(path) as cat:
        tasks = cat.tasks
        for k in task_indices:
            # every row read once: reduce_task keeps the creep episodes out of R(mu) and the recurrences
            rows = int(tasks["events_written"][k])
            if windows is None:
                out[k] = reduce_task(cat.task_events(k, opt.chunk), cat.count(k, schema.KIND_EVENT),
                                     float(tasks["nu"][k]), geometry.task_shape(tasks, k), opt, rows, layout)
            else:
                start, end = windows[k]
                t, kind = cat.column(k, "t"), cat.column(k, "kind")
                inside = _inside(t, start, end)
                out[k] = reduce_task(reader.rows_where(cat.task_events(k, opt.chunk),
                                                       lambda part: _inside(part["t"], start, end)),
                                     int(np.count_nonzero(inside & (kind == schema.KIND_EVENT))),
                                     float(tasks["nu"][k]), geometry.task_shape(tasks, k), opt,
                                     int(np.count_nonzero(inside)), layout)
            out[k].rows = rows
    return out


def _inside(t, start, end):
    """The onsets in a window: start <= t < end (analysis/region.py)."""
    return (t >= start) & (t < end)


# -- per point ------------------------------------------------------------------------------

NUMBERS = tuple(n.name for n in LAYOUT.numbers)
# Fewer resampling units than this and the bootstrap intervals are not to be trusted (a
# percentile interval from a handful of seeds is too narrow and jumps with each one added).
MIN_UNITS = 10


def unreliable(units, method):
    """Why a point's intervals are not to be trusted ('' if they are): fewer than MIN_UNITS units."""
    if units >= MIN_UNITS:
        return ""
    return (f"intervals unreliable: {units} resampling unit{'s' * (units != 1)} ({method}); "
            f"at least {MIN_UNITS} are needed: {MIN_UNITS} seeds (run.seeds), or {MIN_UNITS} stretches over all "
            "its tasks (reduce --blocks stretches per task, each holding a few recurrences)")


def _units(per_task, task_ids, whole="seeds"):
    """Resampling units of a point: its tasks (`whole`: seeds, or a region's faults) if it has at least MIN_UNITS,
    else the stretches of all its tasks (task by task, in task order). pack(name): the units of an additive table
    stacked (units, width); of a sample, a list of one array per unit (a task's stretches one after the other)."""
    stack = [per_task[k] for k in task_ids]
    if len(stack) >= MIN_UNITS:
        def pack(name):
            if isinstance(stack[0][name], list):
                return [np.concatenate(h[name]) for h in stack]
            return np.stack([h[name].sum(axis=0) for h in stack])
        return pack, whole

    def pack(name):
        if isinstance(stack[0][name], list):
            return [stretch for h in stack for stretch in h[name]]
        return np.concatenate([h[name] for h in stack])
    return pack, "blocks"


UNIT_ARRAYS = tuple(LAYOUT.tables)


def point_statistics(per_task, task_ids, opt, rng, layout=LAYOUT, n_blocks=None, whole="seeds",
                     geometry_name=geometry.CHAIN):
    """Merged densities and summary numbers of one parameter point, with bootstrap intervals, and each
    statistic's extras (the recurrence peaks). n_blocks: its number of blocks, N M (for bins of the chain's own);
    geometry_name: its geometry's, whose refused statistics (statistics.refusal) give NaN numbers, curves and
    extras (the engine fed them nothing).

    A resample draws units with replacement, rng.integers(0, units, (bootstrap, units)); its additive tables
    are the sums of the drawn units', its samples the drawn units' values concatenated in the order drawn.
    Returns curves (est, lo, hi, the curves one after the other) and curve {name: (est, lo, hi)}, numbers
    (numbers, 3), method, units, sums (the summed tables of all units, samples concatenated), and the extras."""
    pack, method = _units(per_task, task_ids, whole)
    names = [name for name in layout.tables if name not in layout.samples]
    units = {name: pack(name) for name in layout.tables}
    m = len(units[names[0]]) if names else len(units[layout.samples[0]])
    # every unit's additive tables side by side in one row: one resample draws them all alike
    ends = np.cumsum([0] + [units[name].shape[1] for name in names])
    flat = np.concatenate([units[name] for name in names], axis=1) if names else np.zeros((m, 0))
    edges = bin_edges(opt, n_blocks, layout)
    where = [(name, slice(a, b)) for name, a, b in zip(names, ends[:-1], ends[1:])]
    widths = {c.table: np.diff(edges[layout.tables[c.table].bins]) for c in layout.curves if c.values is None}

    def split(row, picks):
        u = {name: row[cut] for name, cut in where}
        u.update({name: np.concatenate([units[name][i] for i in picks]) for name in layout.samples})
        return layout.sum_of(u)

    refused = {s.name for s in layout.statistics if refusal(s, geometry_name)}
    blank = {c.name for s in layout.statistics if s.name in refused for c in s.curves}

    def numbers(u):
        return np.array([x for s in layout.statistics if s.numbers
                         for x in (s.estimate(u, opt) if s.name not in refused else [np.nan] * len(s.numbers))],
                        dtype=float)

    def curves(u):
        out = [c.values(u, opt, edges) if c.values is not None else
               stats.density(u[c.table], None, u.column(*c.total), widths[c.table])
               for c in layout.curves]
        return [np.full(len(v), np.nan) if c.name in blank else v for c, v in zip(layout.curves, out)]

    def estimate(row, picks):
        u = split(row, picks)
        return np.concatenate([*curves(u), numbers(u)])

    samples = None
    if m >= 2:   # as stats.bootstrap, with the picks for the samples
        picks = rng.integers(0, m, size=(opt.bootstrap, m))
        need = layout.drawn(opt)
        if need:   # a resample sums only the entries its numbers and curves read (the same sums, in the same order)
            drawn = np.concatenate([np.arange(cut.start, cut.stop) if name not in need else cut.start + need[name]
                                    for name, cut in where]) if where else np.zeros(0, np.int64)
            sub = np.ascontiguousarray(flat[:, drawn])

            def resample(p):
                row = np.full(flat.shape[1], np.nan)
                row[drawn] = sub[p].sum(axis=0)
                return row
        else:
            def resample(p):
                return flat[p].sum(axis=0)
        samples = np.array([estimate(resample(p), p) for p in picks])
    sums = split(flat.sum(axis=0), range(m))
    each = curves(sums)
    est = np.concatenate([*each, numbers(sums)])
    if samples is None:
        lo = hi = np.full_like(est, np.nan)
    else:
        lo, hi = stats.percentile_interval(samples, opt.level)
    n_curve = len(est) - len(layout.numbers)
    out = {"curves": (est[:n_curve], lo[:n_curve], hi[:n_curve]),
           "numbers": np.stack([est[n_curve:], lo[n_curve:], hi[n_curve:]], axis=1),
           "method": method, "units": m, "sums": sums, "curve": {}}
    start = 0
    for c, values in zip(layout.curves, each):
        out["curve"][c.name] = tuple(x[start:start + len(values)] for x in out["curves"])
        start += len(values)
    for statistic in layout.statistics:
        if statistic.extra is not None:
            extra = statistic.extra(units, opt, rng)
            out.update({name: np.full(np.shape(v), np.nan) for name, v in extra.items()}
                       if statistic.name in refused else extra)
    return out
