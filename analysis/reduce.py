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
from dataclasses import dataclass, field

import numpy as np

from ensemble import checks, filekind
from ensemble.store import reader, schema
from ensemble.store.errors import CatalogError
from ensemble.config import LAW_KEYS

from . import stats
from .recurrence import RecurrenceScanner
from .statistics import Layout, Rows

# the parameters that tell points apart: the chain's, and every friction law's keys (NaN where a
# key is not of the task's law, so tasks of two laws never pool)
PARAMS = ("N", "l", "nu", *LAW_KEYS)


# default bins of the creep episodes (`reduce --creep-mu-bins`, `--creep-duration-bins`): measured
# at N = 100, b = 8..18.5 (aging law), creep slips reach mu = -11 and durations 10^-6.4 / nu
CREEP_MU_BINS = "-12:3:75"
CREEP_DURATION_BINS = "-7:3:50"
# default bins and regions of the seismicity around large events (analysis/statistics/seismicity.py), chosen
# for the aging law at b = 20, N = 800 (inter-event times of about 37 T nu, large events recurring
# after T nu ~ 530): time from the mainshock's onset (T nu) and distance from its epicenter (blocks)
SEIS_TIME_BINS = "-1000:1000:40"
SEIS_DISTANCE_BINS = "0:40:20"
SEIS_NEAR, SEIS_RING, SEIS_SHORT, SEIS_LONG = 2.0, 10.0, 50.0, 500.0


@dataclass(frozen=True)
class Options:
    mu_edges: np.ndarray
    tnu_edges: np.ndarray
    mu_c: float = 4.0
    window: int = 10
    b_cut: float = 3.0
    bootstrap: int = 1000
    level: float = 0.95
    blocks: int = 20
    seed: int = 0
    chunk: int = 1 << 16
    creep_mu_edges: np.ndarray = field(default_factory=lambda: parse_bins(CREEP_MU_BINS))
    creep_duration_edges: np.ndarray = field(default_factory=lambda: parse_bins(CREEP_DURATION_BINS))
    seis_time_edges: np.ndarray = field(default_factory=lambda: parse_bins(SEIS_TIME_BINS))
    seis_distance_edges: np.ndarray = field(default_factory=lambda: parse_bins(SEIS_DISTANCE_BINS))
    seis_near: float = SEIS_NEAR      # blocks: the epicentral neighbourhood is distance < seis_near
    seis_ring: float = SEIS_RING      # blocks: the ring around it is seis_near <= distance < seis_ring
    seis_short: float = SEIS_SHORT    # T nu: "just before" is [-seis_short, 0), "just after" [0, seis_short)
    seis_long: float = SEIS_LONG      # T nu: "some time before" is [-seis_long, -seis_short)


# every statistic of analysis/statistics/, laid out: its tables, numbers and curves in the registry's order
LAYOUT = Layout()
# the densities of a point, in the order of its curves (name -> the bins of its table)
CURVES = {c.name: LAYOUT.tables[c.table].bins for c in LAYOUT.curves}


def bin_edges(opt):
    """{bins name: edges} of the options (the summary's /bins/<name>): option <name>_edges."""
    return {name: getattr(opt, f"{name}_edges") for name in LAYOUT.bins}


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


def reduce_task(chunks, written, nu, n_blocks_chain, opt, rows=None, layout=LAYOUT):
    """Stream one task's rows (chunks of dicts of columns, `written` inertial events and `rows`
    rows of every kind in all) into its tables (statistics.Tables: {table: (stretches, width)}; the
    attribute `rows` the rows read). Every statistic is fed each chunk once. The chunks are consumed to
    their end (the catalog checks a task's checksum there)."""
    k = opt.blocks
    out = layout.empty(k, bin_edges(opt))
    out.rows = 0
    recurrences = any("recurrences" in s.needs for s in layout.statistics)
    scanner = RecurrenceScanner(n_blocks_chain, opt.mu_c, opt.window) if written and recurrences else None
    lo = row = 0
    t_before = np.nan
    for part in chunks:
        inertial = part["kind"] == schema.KIND_EVENT
        creep = part["kind"] == schema.KIND_CREEP
        creep_block = _creep_stretches(inertial, creep, lo, row, written, rows, k) if creep.any() else None
        row += len(inertial)
        ev = block = rec = None
        if inertial.any():
            ev = part if inertial.all() else {name: column[inertial] for name, column in part.items()}
            hi = lo + len(ev["t"])
            block = (np.arange(lo, hi) * k) // written
            if scanner is not None:
                src, T, interior = scanner.feed(ev["t"], ev["epicenter"], ev["mu"], ev["boundary"])
                rec = ((src * k) // written, T * nu, interior)
            lo = hi
        seen = Rows(part, inertial, ev, block, creep, creep_block, rec, t_before, nu, opt, n_blocks_chain,
                    ev is not None and lo == written)
        for statistic in layout.statistics:
            statistic.feed(out, seen)
        if ev is not None:
            t_before = ev["t"][-1]
    out.carry.clear()    # the statistics' carry of this task ends with it
    return out


def _creep_stretches(inertial, creep, before, row, written, rows, k):
    """The stretches of a chunk's creep episodes; `before` inertial events and `row` rows of the task
    precede the chunk. A creep row's stretch is that of the inertial events before it (the last one
    after the last event); without events, by its row."""
    if written:
        events_before = before + np.cumsum(inertial) - inertial
        return np.minimum((events_before[creep] * k) // written, k - 1)
    return ((row + np.flatnonzero(creep)) * k) // max(rows or 0, row + len(creep))


def reduce_tasks(path, task_indices, opt):
    """TaskHistograms for the given tasks of a catalog (one rank's share)."""
    out = {}
    # the catalog checks the ranges of the rows as they stream (an epicenter outside the chain
    # would also overflow RecurrenceScanner's buffers) and each task's checksum after its last chunk
    with filekind.reading(path, "the event catalog", CatalogError), reader.Reader(path) as cat:
        tasks = cat.tasks
        for k in task_indices:
            # every row read once: reduce_task keeps the creep episodes out of R(mu) and the recurrences
            rows = int(tasks["events_written"][k])
            out[k] = reduce_task(cat.task_events(k, opt.chunk), cat.count(k, schema.KIND_EVENT),
                                 float(tasks["nu"][k]), int(tasks["N"][k]), opt, rows)
            out[k].rows = rows
    return out


# -- per point ------------------------------------------------------------------------------

NUMBERS = tuple(n.name for n in LAYOUT.numbers)
CREEP_NUMBERS = tuple(n.name for s in LAYOUT.statistics if s.name == "creep" for n in s.numbers)   # the slow side's
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


def _units(per_task, task_ids):
    """Resampling units of a point: its tasks if it has at least MIN_UNITS, else the stretches
    of all its tasks (task by task, in task order)."""
    stack = [per_task[k] for k in task_ids]
    if len(stack) >= MIN_UNITS:
        pack = lambda name: np.stack([h[name].sum(axis=0) for h in stack])  # noqa: E731
        return pack, "seeds"
    pack = lambda name: np.concatenate([h[name] for h in stack])  # noqa: E731
    return pack, "blocks"


UNIT_ARRAYS = tuple(LAYOUT.tables)


def point_statistics(per_task, task_ids, opt, rng, layout=LAYOUT):
    """Merged densities and summary numbers of one parameter point, with bootstrap intervals, and each
    statistic's extras (the recurrence peaks)."""
    pack, method = _units(per_task, task_ids)
    names = list(layout.tables)
    units = {name: pack(name) for name in names}
    # every unit's tables side by side in one row: one resample draws them all alike
    ends = np.cumsum([0] + [units[name].shape[1] for name in names])
    flat = np.concatenate([units[name] for name in names], axis=1)
    edges = bin_edges(opt)
    where = [(name, slice(a, b)) for name, a, b in zip(names, ends[:-1], ends[1:])]
    widths = {c.table: np.diff(edges[layout.tables[c.table].bins]) for c in layout.curves}

    def split(row):
        return layout.sum_of({name: row[cut] for name, cut in where})

    def numbers(row):
        u = split(row)
        return np.array([x for s in layout.statistics if s.numbers for x in s.estimate(u, opt)], dtype=float)

    def curves(row):
        u = split(row)
        return np.concatenate([stats.density(u[c.table], None, u.column(*c.total), widths[c.table])
                               for c in layout.curves])

    total = flat.sum(axis=0)
    samples = stats.bootstrap(flat, lambda row: np.concatenate([curves(row), numbers(row)]),
                              opt.bootstrap, rng) if len(flat) >= 2 else None
    est = np.concatenate([curves(total), numbers(total)])
    if samples is None:
        lo = hi = np.full_like(est, np.nan)
    else:
        lo, hi = stats.percentile_interval(samples, opt.level)
    n_curve = len(est) - len(layout.numbers)
    out = {"curves": (est[:n_curve], lo[:n_curve], hi[:n_curve]),
           "numbers": np.stack([est[n_curve:], lo[n_curve:], hi[n_curve:]], axis=1),
           "method": method, "units": len(flat)}
    for statistic in layout.statistics:
        if statistic.extra is not None:
            out.update(statistic.extra(units, opt, rng))
    return out
