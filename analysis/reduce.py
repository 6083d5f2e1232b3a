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

from ensemble import catalog, checks, filekind
from ensemble.config import LAW_KEYS

from . import stats
from .recurrence import RecurrenceScanner

# the parameters that tell points apart: the chain's, and every friction law's keys (NaN where a
# key is not of the task's law, so tasks of two laws never pool)
PARAMS = ("N", "l", "nu", *LAW_KEYS)


# default bins of the creep episodes (`reduce --creep-mu-bins`, `--creep-duration-bins`): measured
# at N = 100, b = 8..18.5 (aging law), creep slips reach mu = -11 and durations 10^-6.4 / nu
CREEP_MU_BINS = "-12:3:75"
CREEP_DURATION_BINS = "-7:3:50"


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


# the densities of a point, in the order of its curves (analysis/summary.py CURVES), with their bins
CURVES = {"mu": "mu", "tnu": "tnu", "tnu_interior": "tnu", "creep_mu": "creep_mu",
          "creep_duration": "creep_duration"}


def bin_edges(opt):
    """{bins name: edges} of the options (the summary's /bins/<name>)."""
    return {"mu": opt.mu_edges, "tnu": opt.tnu_edges, "creep_mu": opt.creep_mu_edges,
            "creep_duration": opt.creep_duration_edges}


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


@dataclass
class TaskHistograms:
    """Additive statistics of one task, per stretch (leading axis)."""
    mu: np.ndarray            # (blocks, n_mu) counts of mu
    tnu: np.ndarray           # (blocks, n_tnu) counts of T * nu, all large events
    tnu_interior: np.ndarray  # (blocks, n_tnu) counts of T * nu, interior starting events
    numbers: np.ndarray       # (blocks, stats.N_STATS) counts and sums
    creep_mu: np.ndarray      # (blocks, n_creep_mu) counts of the creep episodes' mu
    creep_duration: np.ndarray  # (blocks, n_creep_duration) counts of their log10(duration nu)
    creep: np.ndarray         # (blocks, stats.N_CREEP_STATS) counts and sums of the slow side
    rows: int = 0             # the task's committed rows read, of every kind (analysis/cli.py checks them)


def _bin_add(hist, block, values, edges):
    idx = np.searchsorted(edges, values, side="right") - 1
    ok = (idx >= 0) & (idx < len(edges) - 1)
    np.add.at(hist, (block[ok], idx[ok]), 1)


def reduce_task(chunks, written, nu, n_blocks_chain, opt, rows=None):
    """Stream one task's rows (chunks of dicts of columns, `written` inertial events and `rows`
    rows of every kind in all) into TaskHistograms. The chunks are consumed to their end (the
    catalog checks a task's checksum there)."""
    k = opt.blocks
    out = TaskHistograms(np.zeros((k, len(opt.mu_edges) - 1), np.int64),
                         np.zeros((k, len(opt.tnu_edges) - 1), np.int64),
                         np.zeros((k, len(opt.tnu_edges) - 1), np.int64),
                         np.zeros((k, stats.N_STATS)),
                         np.zeros((k, len(opt.creep_mu_edges) - 1), np.int64),
                         np.zeros((k, len(opt.creep_duration_edges) - 1), np.int64),
                         np.zeros((k, stats.N_CREEP_STATS)))
    scanner = RecurrenceScanner(n_blocks_chain, opt.mu_c, opt.window) if written else None
    lo = row = 0
    for part in chunks:
        inertial = part["kind"] == catalog.KIND_EVENT
        _creep_add(out, part, inertial, lo, row, written, rows, nu, opt)
        row += len(inertial)
        if not inertial.any():
            continue
        ev = part if inertial.all() else {name: column[inertial] for name, column in part.items()}
        hi = lo + len(ev["t"])
        t, mu, epicenter, boundary = ev["t"], ev["mu"], ev["epicenter"], ev["boundary"]
        block = (np.arange(lo, hi) * k) // written
        _bin_add(out.mu, block, mu, opt.mu_edges)
        np.add.at(out.numbers[:, stats.N_EVENTS], block, 1)
        np.add.at(out.numbers[:, stats.N_LARGE], block, mu >= opt.mu_c)
        np.add.at(out.creep[:, stats.SUM_SLIP_EVENTS], block, ev["slip"])
        gr = mu >= opt.b_cut
        np.add.at(out.numbers[:, stats.N_GR], block[gr], 1)
        np.add.at(out.numbers[:, stats.SUM_MU_GR], block[gr], mu[gr])
        np.add.at(out.numbers[:, stats.SUM_MU2_GR], block[gr], mu[gr] ** 2)
        src, T, interior = scanner.feed(t, epicenter, mu, boundary)
        rblock = (src * k) // written
        tnu = T * nu
        _bin_add(out.tnu, rblock, tnu, opt.tnu_edges)
        _bin_add(out.tnu_interior, rblock[interior], tnu[interior], opt.tnu_edges)
        np.add.at(out.numbers[:, stats.N_REC], rblock, 1)
        np.add.at(out.numbers[:, stats.SUM_TNU], rblock, tnu)
        np.add.at(out.numbers[:, stats.N_REC_INT], rblock[interior], 1)
        np.add.at(out.numbers[:, stats.SUM_TNU_INT], rblock[interior], tnu[interior])
        lo = hi
    return out


def _creep_add(out, part, inertial, before, row, written, rows, nu, opt):
    """Add a chunk's creep episodes (its rows of kind KIND_CREEP) to `out`; `before` inertial
    events and `row` rows of the task precede the chunk. A creep row's stretch is that of the
    inertial events before it (the last one after the last event); without events, by its row."""
    creep = part["kind"] == catalog.KIND_CREEP
    if not creep.any():
        return
    k = opt.blocks
    if written:
        events_before = before + np.cumsum(inertial) - inertial
        block = np.minimum((events_before[creep] * k) // written, k - 1)
    else:
        block = ((row + np.flatnonzero(creep)) * k) // max(rows or 0, row + len(creep))
    with np.errstate(divide="ignore"):      # a duration of 0 is out of every bin (still counted)
        log_duration = np.log10(part["duration"][creep] * nu)
    _bin_add(out.creep_mu, block, part["mu"][creep], opt.creep_mu_edges)
    _bin_add(out.creep_duration, block, log_duration, opt.creep_duration_edges)
    np.add.at(out.creep[:, stats.N_CREEP], block, 1)
    np.add.at(out.creep[:, stats.N_CREEP_TAKEN_OVER], block, part["ending"][creep] == catalog.ENDING_TAKEN_OVER)
    np.add.at(out.creep[:, stats.SUM_SLIP_CREEP], block, part["slip"][creep])


def reduce_tasks(path, task_indices, opt):
    """TaskHistograms for the given tasks of a catalog (one rank's share)."""
    out = {}
    # the catalog checks the ranges of the rows as they stream (an epicenter outside the chain
    # would also overflow RecurrenceScanner's buffers) and each task's checksum after its last chunk
    with filekind.reading(path, "the event catalog", catalog.CatalogError), catalog.Reader(path) as cat:
        tasks = cat.tasks
        for k in task_indices:
            # every row read once: reduce_task keeps the creep episodes out of R(mu) and the recurrences
            rows = int(tasks["events_written"][k])
            out[k] = reduce_task(cat.task_events(k, opt.chunk), cat.count(k, catalog.KIND_EVENT),
                                 float(tasks["nu"][k]), int(tasks["N"][k]), opt, rows)
            out[k].rows = rows
    return out


# -- per point ------------------------------------------------------------------------------

NUMBERS = ("n_events", "n_large", "fraction_large", "n_recurrences", "mean_tnu", "mode_tnu",
           "mean_tnu_interior", "gr_b", "gr_b_se", "ks_gr",
           # the slow side (creep episodes, /events/kind 1): NaN where there are none to share
           "n_creep", "creep_share", "taken_over_share", "aseismic_fraction")
CREEP_NUMBERS = NUMBERS[NUMBERS.index("n_creep"):]
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
        pack = lambda name: np.stack([getattr(h, name).sum(axis=0) for h in stack])  # noqa: E731
        return pack, "seeds"
    pack = lambda name: np.concatenate([getattr(h, name) for h in stack])  # noqa: E731
    return pack, "blocks"


UNIT_ARRAYS = ("mu", "tnu", "tnu_interior", "creep_mu", "creep_duration", "numbers", "creep")


def point_statistics(per_task, task_ids, opt, rng):
    """Merged densities and summary numbers of one parameter point, with bootstrap intervals."""
    pack, method = _units(per_task, task_ids)
    units = {name: pack(name) for name in UNIT_ARRAYS}
    # every unit's arrays side by side in one row: one resample draws them all alike
    ends = np.cumsum([units[name].shape[1] for name in UNIT_ARRAYS])
    flat = np.concatenate([units[name] for name in UNIT_ARRAYS], axis=1)
    edges = bin_edges(opt)

    def split(row):
        return dict(zip(UNIT_ARRAYS, np.split(row, ends[:-1])))

    def numbers(row):
        u = split(row)
        mu, tnu, s, c = u["mu"], u["tnu"], u["numbers"], u["creep"]
        b = stats.gr_b(s[stats.N_GR], s[stats.SUM_MU_GR], opt.b_cut)
        b_se = stats.gr_b_standard_error(s[stats.N_GR], s[stats.SUM_MU_GR], s[stats.SUM_MU2_GR], opt.b_cut)
        mode = stats.centers(opt.tnu_edges)[np.argmax(tnu)] if tnu.sum() > 0 else np.nan
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.array([
                s[stats.N_EVENTS], s[stats.N_LARGE], s[stats.N_LARGE] / s[stats.N_EVENTS],
                s[stats.N_REC], s[stats.SUM_TNU] / s[stats.N_REC], mode,
                s[stats.SUM_TNU_INT] / s[stats.N_REC_INT], b, b_se,
                stats.gr_ks_distance(mu, opt.mu_edges, opt.b_cut, b),
                c[stats.N_CREEP], c[stats.N_CREEP] / (c[stats.N_CREEP] + s[stats.N_EVENTS]),
                c[stats.N_CREEP_TAKEN_OVER] / c[stats.N_CREEP],
                c[stats.SUM_SLIP_CREEP] / (c[stats.SUM_SLIP_CREEP] + c[stats.SUM_SLIP_EVENTS])])

    def curves(row):
        u = split(row)
        totals = {"mu": u["numbers"][stats.N_EVENTS], "tnu": u["numbers"][stats.N_REC],
                  "tnu_interior": u["numbers"][stats.N_REC_INT], "creep_mu": u["creep"][stats.N_CREEP],
                  "creep_duration": u["creep"][stats.N_CREEP]}
        return np.concatenate([stats.density(u[name], edges[bins], totals[name]) for name, bins in CURVES.items()])

    total = flat.sum(axis=0)
    samples = stats.bootstrap(flat, lambda row: np.concatenate([curves(row), numbers(row)]),
                              opt.bootstrap, rng) if len(flat) >= 2 else None
    est = np.concatenate([curves(total), numbers(total)])
    if samples is None:
        lo = hi = np.full_like(est, np.nan)
    else:
        lo, hi = stats.percentile_interval(samples, opt.level)
    n_curve = len(est) - len(NUMBERS)
    peaks = _peaks_with_intervals(units["tnu"], opt, rng)
    return {"curves": (est[:n_curve], lo[:n_curve], hi[:n_curve]),
            "numbers": np.stack([est[n_curve:], lo[n_curve:], hi[n_curve:]], axis=1),
            "peaks": peaks, "method": method, "units": len(flat)}


def _peaks_with_intervals(tnu_units, opt, rng):
    """Significant recurrence peaks of the merged histogram (stats.find_peaks), each with the
    interval of the nearest peak across bootstrap resamples. Rows: (position, lo, hi).

    The noise of each smoothed bin is the standard deviation of its bootstrap resamples over the
    units, at least the Poisson value (with one unit, or few, the bootstrap understates it).
    """
    total = tnu_units.sum(axis=0)
    noise = stats.poisson_noise(total)
    resampled = None
    if len(tnu_units) >= 2 and total.sum() > 0:
        picks = rng.integers(0, len(tnu_units), size=(opt.bootstrap, len(tnu_units)))
        resampled = np.array([tnu_units[p].sum(axis=0) for p in picks])
        spread = np.array([stats.smooth(c) for c in resampled]).std(axis=0, ddof=1)
        noise = np.maximum(noise, spread)
    base = stats.find_peaks(total, opt.tnu_edges, noise)
    if len(base) == 0 or resampled is None:
        return np.array([[p, np.nan, np.nan] for p in base]).reshape(-1, 3)
    width = opt.tnu_edges[1] - opt.tnu_edges[0]
    found = [[] for _ in base]
    for counts in resampled:
        peaks = stats.find_peaks(counts, opt.tnu_edges, noise)
        for i, b in enumerate(base):
            if len(peaks):
                near = peaks[np.argmin(np.abs(peaks - b))]
                if abs(near - b) <= 5 * width:
                    found[i].append(near)
    rows = []
    for b, f in zip(base, found):
        lo, hi = (np.percentile(f, [50 * (1 - opt.level), 100 - 50 * (1 - opt.level)])
                  if len(f) else (np.nan, np.nan))
        rows.append([b, lo, hi])
    return np.array(rows)
