"""Statistics of a catalog as plug-ins: one module per statistic, as the friction laws are one file each.

A statistic (a module of this package that defines STATISTIC) declares

- its tables: additive per-unit arrays, one row per (task, stretch), stored as /per_task/<table>.
  A table is a histogram over a set of bins (`bins`, the options' `<bins>_edges`) or named columns
  of counts and sums (`columns`); statistics may share a table of columns, each adding its own
  columns (the columns are laid out in the order of the statistics, then of their declaration).
  Additive, so that merging tasks and ranks and resampling units are exact: every estimate is a
  function of a sum over units. `bins` may name two sets of bins, (rows, columns): a 2-d histogram
  stored flattened, row by row; `weights` makes a histogram table hold float sums instead of counts.
  `chain_edges` makes the bins the chain's own, a function of its N (the blocks slipped, 0..N): each point
  then has its bins and no option sets them.
- its samples: a table with `sample` set holds the values themselves (float), a list per unit in the order
  fed, for estimators that are no function of sums (a median, a mode of values scaled by it). A resample
  concatenates the lists of the units it draws, in the order drawn, so that its estimate is that of the
  resampled values exactly, as with the additive tables. Samples are not stored in the summary: a
  statistic with one belongs to a set of its own (`sets`, below).
- `feed(acc, rows)`: add one chunk of a task's rows to the tables (rows: `Rows`, below). What a statistic
  must carry from one chunk of a task to the next (events waiting for their partners) it keeps in
  `acc.carry[<its name>]`, a dict the engine gives each task and drops at its end; `rows.last` tells the
  chunk that holds the task's last inertial event.
- its numbers (name, unit, meaning) and `estimate(u, opt)`: their values from summed tables `u`
  (u.table(name) the array, u.column(table, column) one column), in the order declared.
- its curves: densities of a histogram table (`table`), normalised by a count column (`total`), over
  the table's bins; or, with `values`, any curve of the summed tables (`values(u, opt, edges)`).
- its recurrences (`needs`): "recurrences" for those of the large events mu >= mu_c, "recurrences:<criterion>"
  for another criterion of a large event (`criteria`, a Criterion declared by some statistic: "n_slipped",
  n_slipped >= n_large, is rupture.py's); `rows.scans` holds them by criterion.
- its options (`options`, each an Option: name, kind, default, unit, help, range), declared once, by the
  statistic that reads it; one that reads another's names it in `uses_options`, and the tables of other
  statistics that its estimate reads in `uses_tables` (checked when the registry loads, and by a test that
  watches what each estimate reads). analysis/options.py builds from them the options record, the command
  line's arguments and their checks, and the summary's stored options.
- its sets (`sets`): the commands that reduce with it, "reduce" (the summary) and "compare" (the friction-law
  comparison, analysis/compare.py); `Layout(of("compare"))` lays out a set.
- optionally `extra(units, opt, rng)`: {name: array} per point beyond numbers and curves, computed after
  the bootstrap of the numbers and curves (the recurrence peaks).
- the geometries it holds on (`geometries`, analysis/geometry.py; empty: every one), and why not on the others
  (`why_not`): a statistic whose meaning is a chain's (an interval of blocks, the ends of the chain) refuses a
  plane. The engine feeds it no task of another geometry; that point's numbers, curves and extras are NaN, the
  report says `refusal` in one line instead, and its figures refuse such a point in one line. Distances between
  blocks come from the geometry (Rows.shape: Euclidean in block units, |i - j| on the chain), and block counts
  from Rows.n_blocks (N M on a plane).

The engine (analysis/reduce.py) streams each task once, hands every statistic the same rows, stacks the
tables of a point's units, bootstraps them all alike, and the summary stores and describes what the
statistics declare. Adding a statistic is one module here and its test.

The statistics today (the registry finds a module by its STATISTIC; this list is for the reader):

    magnitude.py          R(mu) of the inertial events, and the share of large ones
    recurrence.py         local recurrence times T nu of large events: their distribution, its peaks
    intervals.py          how regular the events come: the coefficient of variation of the recurrence times
    gutenberg_richter.py  the Gutenberg-Richter exponent above mu = b_cut, its standard error and KS distance
    creep.py              the slow side: the creep episodes' size and duration, the aseismic slip fraction
    seismicity.py         seismicity around large events: foreshocks, aftershocks, quiescence, the rate map
    rupture.py            rupture lengths n (the comparison's size axis): R(log10 n), the dip, the power law
    regularity.py         how periodic the large events by rupture length recur (the comparison's)
    rupture_length.py     P(L_r) of the rupture lengths and its exponential tail: the correlation length L_0
    rupture_classes.py    unilateral and bilateral ruptures: their shares, R(mu), epicenters at a past rim
    slip_scaling.py       the mean slip per block and the stress drop against the rupture length
    nucleation.py         the nucleation of large events: the onset zone, the initial phase, the widest zone
"""
import importlib
import math
import pkgutil
from dataclasses import dataclass, field
from typing import Callable, Optional

import numba as nb
import numpy as np

import ensemble.model  # noqa: F401  (first: numba caches the kernels in the package's cache, ensemble/kernel_cache.py)

from ..geometry import GEOMETRIES


@dataclass(frozen=True)
class Table:
    """An additive per-unit array: a histogram over `bins`, or the named `columns` (counts and sums)."""
    name: str
    unit: str
    meaning: str
    bins: object = ""      # a bins name, or (rows, columns) of a 2-d histogram (flattened row by row)
    columns: tuple = ()
    weights: bool = False  # a histogram of float sums (weights), not of counts
    sample: bool = False   # the values themselves, a list per unit (concatenated on resample)
    chain_edges: Optional[Callable] = None   # the bins' edges from the chain's N (per point), not an option


@dataclass(frozen=True)
class Number:
    name: str
    unit: str
    meaning: str
    label: str = ""      # a few characters for `analysis report` (default: the name)


@dataclass(frozen=True)
class Curve:
    """The density of histogram table `table` over its bins, `total` = (table, column) counting the
    values in and out of range; described as the density of `variable` of `whose` (unit `unit`)."""
    name: str
    table: str
    total: tuple
    variable: str
    whose: str
    unit: str
    values: Optional[Callable] = None   # (summed tables, opt, edges) -> the curve, instead of the density


LAW = "the friction law's"   # an Option's default that is the friction law's scale (Law.scales.<name>)
OPTION_KINDS = ("number", "count", "bins")


@dataclass(frozen=True)
class Option:
    """An option of the reduction, declared once, by the statistic that reads it first (others name it in
    `uses_options`); analysis/options.py builds from these the options record, the command line's arguments and
    their checks, the summary's stored options and compare's options.

    kind: "number" (a finite float in [low, high]; in (low, high) if `exclusive`), "count" (an integer in [low,
    high]) or "bins" ("lo:hi:n" text; the record also holds its edges as <name without _bins>_edges, and the
    summary stores them as /bins/<that name> instead of an attribute). default: a value, or LAW (the friction
    law's, Law.scales.<name>); defaults: {command: default} where a command other than reduce ("compare") takes
    another. The command line's argument is --<name with dashes>."""
    name: str
    kind: str
    default: object
    unit: str
    help: str
    low: float = -math.inf
    high: float = math.inf
    exclusive: bool = False
    defaults: dict = field(default_factory=dict)

    @property
    def flag(self):
        return "--" + self.name.replace("_", "-")

    @property
    def bins(self):
        """The bins' name of a bins option ("mu" of mu_bins), else ""."""
        return self.name.removesuffix("_bins") if self.kind == "bins" else ""


@dataclass(frozen=True)
class Criterion:
    """What makes an event large for the recurrences a statistic needs ("recurrences:<name>"): its `column` at
    least option `threshold`; the next large event counts when its epicenter lies within option `window` blocks."""
    name: str
    column: str
    threshold: str
    window: str = "window"


@dataclass(frozen=True)
class Figure:
    """A figure that `analysis plot --figure <name>` draws for a statistic, of the points of one or more summaries
    (analysis/plot.py). draw(summaries, fig, keys, labels, names, title): draws into the empty matplotlib figure
    `fig`, sized size(n) inches for n points, with the points' legend `labels`, the parameters `keys` that vary
    between them and the summaries' `names`, and lays it out under the `title` text (analysis/drawing.py helps).
    describe(summaries): the title's words on what the figure rests on (default: the events per point, mu_c and
    window); bands: whether its curves carry bootstrap bands (else the title says where the intervals are).
    A figure imports matplotlib when it draws, not before: a reduction under MPI never loads it."""
    name: str
    help: str
    size: Callable
    draw: Callable
    describe: Optional[Callable] = None
    bands: bool = True


@dataclass(frozen=True)
class ExportTable:
    """A table that `analysis export` writes of a summary for a statistic (a file <name>.csv, analysis/export.py).
    build(s): of the summary `s` (as read), (columns {name: (unit, meaning)} in order, values {name: 1-d array});
    a summary that does not hold the statistic gives the columns with no rows."""
    name: str
    title: str          # what its rows are (said in the file's header)
    build: Callable


@dataclass(frozen=True)
class Statistic:
    name: str
    order: int                      # place among the statistics (report lines, numbers, curves; not on disk)
    needs: tuple = ()               # "recurrences": the engine scans the task's recurrence times for it
    tables: tuple = ()
    numbers: tuple = ()
    curves: tuple = ()
    feed: Callable = None
    estimate: Callable = None
    extra: Optional[Callable] = None
    extra_datasets: dict = field(default_factory=dict)   # /points/<name>: (unit, shape, meaning) of extra's
    sets: tuple = ("reduce",)       # the commands that reduce with it ("reduce": the summary; "compare")
    # opt -> {histogram table: the entries its numbers read}: a resample sums only those (default: all; the
    # others are NaN in the resample's tables, so reading one shows); the estimate of all units has every entry
    drawn: Optional[Callable] = None
    options: tuple = ()             # the Options it declares
    uses_options: tuple = ()        # the names of options other statistics declare that it reads
    uses_tables: tuple = ()         # the tables of other statistics that its estimate reads (checked: registered)
    criteria: tuple = ()            # the Criteria of a large event it declares (for any statistic's `needs`)
    # `analysis report`: its lines for point i of a summary (s, i) -> [lines] (default: number_lines, each number
    # with its interval), and its lines under the report's first, about the whole summary (s) -> [lines]
    report: Optional[Callable] = None
    report_header: Optional[Callable] = None
    exports: tuple = ()             # its ExportTables (`analysis export` of a summary)
    figures: tuple = ()             # its Figures (`analysis plot --figure NAME`)
    geometries: tuple = ()          # the geometries it holds on (analysis/geometry.py); empty: every one
    why_not: str = ""               # why it refuses the others (a few words: the report's and the figures' line)


def refusal(statistic, geometry):
    """Why `statistic` has no numbers on a point of `geometry` (a geometry's name), in one line; '' where it has."""
    if not statistic.geometries or geometry in statistic.geometries:
        return ""
    return f"{statistic.name}: not on a {geometry} ({statistic.why_not})"


def holds(s, statistic):
    """Whether summary `s` (as read) holds `statistic`: its numbers and extras (a summary of an older format lacks
    the statistics that came after it, and shows none of their lines or figures)."""
    return (all(f"points/numbers/{n.name}" in s for n in statistic.numbers)
            and all(f"points/{name}" in s for name in statistic.extra_datasets))


def number_text(est, lo, hi, digits=".4g", missing="-"):
    """A number as the report prints it: "0.84 [0.77, 0.91]", the estimate alone without an interval, `missing` if
    NaN; digits: the format of each (".2f" in a figure's label)."""
    if not np.isfinite(est):
        return missing
    if np.isfinite(lo) and np.isfinite(hi):
        return f"{est:{digits}} [{lo:{digits}}, {hi:{digits}}]"
    return f"{est:{digits}}"


def report_line(label, text):
    """One line of a point in the report: the label right-aligned, then the value."""
    return f"    {label:>18s}  {text}"


def number_lines(statistic, s, i):
    """The report's lines of point i for each number of `statistic` the summary holds, with its interval."""
    return [report_line(n.label or n.name, number_text(*s[f"points/numbers/{n.name}"][i])) for n in statistic.numbers
            if f"points/numbers/{n.name}" in s]


def _discover():
    found = []
    for info in pkgutil.iter_modules(__path__):
        module = importlib.import_module(f"{__name__}.{info.name}")
        if hasattr(module, "STATISTIC"):
            found.append(module.STATISTIC)
    found.sort(key=lambda s: (s.order, s.name))
    names = [s.name for s in found]
    if len(set(names)) != len(names):
        raise ImportError(f"analysis.statistics: two statistics share a name ({names})")
    _check(found)
    return tuple(found)


# The engine's own options (analysis/reduce.py: the resampling), which every command that reduces has
ENGINE_OPTIONS = (
    Option("bootstrap", "count", 1000, "1", "bootstrap resamples", 1, 10 ** 6),
    Option("level", "number", 0.95, "1", "interval coverage", 0.0, 1.0, exclusive=True),
    Option("blocks", "count", 20, "1", "stretches per task, resampled when a point has fewer than 10 seeds",
           1, 10 ** 6),
    Option("seed", "count", 0, "1", "seed of the bootstrap; a point's resamples are drawn from it and the point's "
                                    "parameters", 0, 2 ** 63 - 1),     # stored as an HDF5 int64
)


def _check(found):
    """What the statistics declare fits together (an ImportError naming the statistic otherwise): every option
    declared once, of a known kind; every option, table and criterion a statistic uses declared by one."""
    def fail(statistic, what):
        raise ImportError(f"analysis/statistics/{statistic.name}.py: {what}")
    options = {o.name: None for o in ENGINE_OPTIONS}
    for st in found:
        for o in st.options:
            if o.name in options:
                fail(st, f"option {o.name!r} is declared twice (once is enough: name it in uses_options)")
            if o.kind not in OPTION_KINDS:
                fail(st, f"option {o.name!r}: kind {o.kind!r} is none of {OPTION_KINDS}")
            options[o.name] = st
    criteria = {c.name: c for st in found for c in st.criteria}
    for st in found:
        unknown = sorted(set(st.geometries) - set(GEOMETRIES))
        if unknown:
            fail(st, f"geometry {unknown[0]!r} is none of the analysis' ({', '.join(GEOMETRIES)}: "
                     "analysis/geometry.py)")
        if st.geometries and not st.why_not:
            fail(st, "holds on some geometries only: say why not on the others (why_not)")
        for name in st.uses_options:
            if name not in options:
                fail(st, f"uses option {name!r}, which no statistic declares")
        for c in st.criteria:
            for name in (c.threshold, c.window):
                if name not in options:
                    fail(st, f"criterion {c.name!r}: option {name!r} is declared by no statistic")
        for need in st.needs:
            criterion = need.partition(":")[2] or "mu"
            if need.startswith("recurrences") and criterion not in criteria:
                fail(st, f"needs the recurrences of criterion {criterion!r}, which no statistic declares")
        for table in st.uses_tables:
            for command in st.sets:
                if not any(table in (t.name for t in other.tables) for other in found if command in other.sets):
                    fail(st, f"reads table {table!r}, which no statistic of its set {command!r} declares")


STATISTICS = _discover()
CRITERIA = {c.name: c for st in STATISTICS for c in st.criteria}    # name -> Criterion of a large event


def of(name):
    """The statistics of set `name` ("reduce", "compare"), in order."""
    return tuple(s for s in STATISTICS if name in s.sets)


# The order of the columns of a table that several statistics share, as the summaries store them (formats 2 to 6):
# those of these that the statistics declare come first, in this order, then any other in the statistics' order.
# So no place among the statistics (Statistic.order) moves a stored column; a new column goes after these, and
# another order is a new summary format (and its readers).
STORED_COLUMNS = {
    "numbers": ("n_events", "n_large", "n_rec", "sum_tnu", "n_rec_int", "sum_tnu_int", "n_gr", "sum_mu_gr",
                "sum_mu2_gr"),
}


class Layout:
    """Where every table and column lives: the tables in the statistics' order, columns of shared tables
    concatenated (STORED_COLUMNS first, then by first declaration), and the numbers and curves in order."""

    def __init__(self, statistics=None):
        self.statistics = of("reduce") if statistics is None else statistics
        self.tables = {}           # name -> Table (bins) or merged column table
        self.columns = {}          # table -> [column names]
        for s in self.statistics:
            for t in s.tables:
                if t.bins:
                    if t.name in self.tables:
                        raise ValueError(f"table {t.name}: declared twice")
                    self.tables[t.name] = t
                else:
                    self.tables.setdefault(t.name, t)
                    self.columns.setdefault(t.name, [])
                    clash = set(self.columns[t.name]) & set(t.columns)
                    if clash:
                        raise ValueError(f"table {t.name}: columns {sorted(clash)} declared twice")
                    self.columns[t.name] += list(t.columns)
        for name, columns in self.columns.items():
            stored = [c for c in STORED_COLUMNS.get(name, ()) if c in columns]
            self.columns[name] = stored + [c for c in columns if c not in stored]
        self.numbers = [n for s in self.statistics for n in s.numbers]
        self.curves = [c for s in self.statistics for c in s.curves]
        self.bins = list(dict.fromkeys(name for t in self.tables.values() if t.bins for name in bin_names(t)))
        self._column = {(table, name): i for table, names in self.columns.items() for i, name in enumerate(names)}
        self.chain_bins = {t.bins: t.chain_edges for t in self.tables.values() if t.chain_edges is not None}
        self.samples = [name for name, t in self.tables.items() if t.sample]

    def drawn(self, opt):
        """{table: the entries a resample needs} of the tables whose statistic names them (Statistic.drawn)."""
        return {table: np.asarray(idx, dtype=np.int64) for s in self.statistics if s.drawn is not None
                for table, idx in s.drawn(opt).items()}

    def width(self, table, edges):
        """Entries per unit of `table`: its bins (of a 2-d histogram, their product), or its columns."""
        t = self.tables[table]
        if t.sample:
            return 0
        return int(np.prod([len(edges[name]) - 1 for name in bin_names(t)])) if t.bins else len(self.columns[table])

    def column(self, table, name):
        return self._column[table, name]

    def sum_of(self, arrays):
        """Tables of summed units (1-d arrays) with columns by name."""
        return Tables(self, arrays)

    def empty(self, blocks, edges):
        """Zeroed tables of one task: {table: (blocks, width)} (histograms int64, columns float64; a sample:
        a list per stretch of the arrays fed to it)."""
        return Tables(self, {name: [[] for _ in range(blocks)] if t.sample else
                             np.zeros((blocks, self.width(name, edges)),
                                      np.int64 if t.bins and not t.weights else np.float64)
                             for name, t in self.tables.items()})


def bin_names(table):
    """The bins names of a histogram table: (name,) or (rows, columns) of a 2-d one."""
    return (table.bins,) if isinstance(table.bins, str) else tuple(table.bins)


class Tables(dict):
    """{table: array} of one task (rows: stretches) or of a sum (1-d), with columns by name."""

    def __init__(self, layout, arrays):
        super().__init__(arrays)
        self.layout = layout
        self.carry = {}     # what statistics keep between the chunks of one task (their name -> anything)

    def column(self, table, name):
        return self[table][..., self.layout.column(table, name)]

    def __reduce__(self):
        """For pickle (a rank's tables go to rank 0): the arrays and the rows read, without the layout, whose
        statistics may hold what pickle cannot (a lambda); rank 0 reads the arrays by name."""
        return _unpickled, (dict(self), getattr(self, "rows", None))

    def add(self, table, name, block, values):
        """Add `values` to column `name` of `table` at stretches `block` (unbuffered, repeated indices add, one
        after the other in their order: the sums do not depend on how a task is cut into chunks)."""
        out = self[table]
        block = np.asarray(block, dtype=np.int64)
        if len(block) and (block.min() < 0 or block.max() >= len(out)):
            raise IndexError(f"table {table}: stretch out of range 0..{len(out) - 1}")
        values = np.ascontiguousarray(np.broadcast_to(np.asarray(values, dtype=out.dtype), block.shape))
        _add_at(out, self.layout.column(table, name), block, values)

    def count(self, table, block, values, edges, weights=None):
        """Histogram `values` into `table` (bins `edges`) at stretches `block`; out of range: not counted. A table
        of sums (Table.weights) adds `weights` (one per value; default 1), one after the other in their order."""
        idx = np.searchsorted(edges, values, side="right") - 1
        ok = (idx >= 0) & (idx < len(edges) - 1)
        out = self[table]
        if out.dtype.kind == "i":   # counts: a sum in any order is exact
            out += np.bincount(block[ok] * out.shape[1] + idx[ok], minlength=out.size).reshape(out.shape)
        else:
            np.add.at(out, (block[ok], idx[ok]), 1.0 if weights is None else np.asarray(weights, float)[ok])

    def append(self, table, block, values):
        """Append `values` to sample `table`, each to the list of its stretch (`block`), in order."""
        for b in np.unique(block):
            self[table][b].append(np.asarray(values, dtype=float)[block == b])


def _unpickled(arrays, rows):
    tables = Tables(None, arrays)
    if rows is not None:
        tables.rows = rows
    return tables


@nb.njit(cache=True)
def _add_at(out, column, block, values):
    for i in range(block.shape[0]):
        out[block[i], column] += values[i]


@dataclass
class Rows:
    """One chunk of a task's rows, as every statistic sees it.

    part: the chunk's columns (every kind); inertial: bool mask of its inertial events; ev: the inertial
    events' columns; block: the stretch of each inertial event; creep: mask of its creep episodes and
    creep_block their stretches; recurrences: (stretch of the starting event, T nu, interior) of the
    recurrences closed in this chunk, or None when no statistic asks for them; t_before: the time of the
    task's last inertial event before this chunk (NaN before its first); nu, opt; n_blocks: the task's blocks, N on
    a chain, N M on a plane (what block counts such as n_slipped reach); last: whether this chunk holds the task's
    last inertial event (none come after it); scans: the recurrences by criterion of a large event (Criterion),
    those the statistics need; shape: the task's geometry.Shape (where its blocks lie: Shape.position).
    """
    part: dict
    inertial: np.ndarray
    ev: Optional[dict]
    block: Optional[np.ndarray]
    creep: np.ndarray
    creep_block: Optional[np.ndarray]
    recurrences: Optional[tuple]
    t_before: float
    nu: float
    opt: object
    n_blocks: int = 0
    last: bool = False
    scans: dict = field(default_factory=dict)   # criterion -> recurrences as `recurrences` ("mu": the same)
    shape: object = None
