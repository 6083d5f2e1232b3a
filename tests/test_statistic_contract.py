"""A statistic declares what it reads and writes (analysis/statistics/__init__.py), and this holds it to that.

Every statistic of every set is fed the committed catalog of tests/test_summary_identity.py (both sides: the
inertial events at b = 20 and the creep episodes at b = 15) and then estimated, through tables and options
that watch what it touches: its feed writes only its own tables, its estimate (and its extras) reads only
its own tables and those it names in `uses_tables`, and both read only the options it declares, those it
names in `uses_options`, those of the criteria whose recurrences it needs, and the engine's. A statistic
that reads what it does not declare would break when the one that declares it leaves its set, or change its
numbers when that one's option is set; here it fails by name.
"""
import numpy as np
import pytest

from analysis import options, reduce
from analysis.statistics import CRITERIA, ENGINE_OPTIONS, Layout, Tables, of
from ensemble.model import laws
from ensemble.store import reader, schema

from .test_summary_identity import CATALOG, gunzip

COMMANDS = ("reduce", "compare")


class Watched:
    """The options record, noting each option read."""

    def __init__(self, opt):
        self.opt, self.read = opt, set()

    def __getattr__(self, name):
        value = getattr(self.opt, name)
        if name != "chunk":
            self.read.add(name.removesuffix("_edges") + "_bins" if name.endswith("_edges") else name)
        return value


class WatchedTables(Tables):
    """Tables noting each table read or written (by name, through every way in: [], column, add, count, append)."""

    def __init__(self, layout, arrays, seen):
        super().__init__(layout, arrays)
        self.seen = seen

    def __getitem__(self, name):
        self.seen.add(name)
        return super().__getitem__(name)


def allowed_options(st):
    names = {o.name for o in st.options} | set(st.uses_options) | {o.name for o in ENGINE_OPTIONS}
    for need in st.needs:
        if need.startswith("recurrences"):
            c = CRITERIA[need.partition(":")[2] or "mu"]
            names |= {c.threshold, c.window}
    return names


@pytest.fixture(scope="module")
def catalog(tmp_path_factory):
    return gunzip(CATALOG, tmp_path_factory.mktemp("contract") / "catalog.h5")


@pytest.mark.parametrize("command", COMMANDS)
def test_every_statistic_touches_only_what_it_declares(catalog, command):
    opt = options.make(command, laws.get("aging").scales)
    layout = Layout(of(command))
    with reader.Reader(str(catalog)) as cat:
        tasks = cat.tasks
        parts = [next(iter(cat.task_events(k, 1 << 20))) for k in range(len(tasks["N"]))]
    kinds = set()
    for k, part in enumerate(parts):      # b = 20 (inertial events) and b = 15 (creep episodes beside them)
        n_blocks, nu = int(tasks["N"][k]), float(tasks["nu"][k])
        kinds |= set(np.unique(part["kind"]))
        edges = reduce.bin_edges(opt, n_blocks, layout)
        written = int(np.count_nonzero(part["kind"] == schema.KIND_EVENT))
        tables = reduce.reduce_task(iter([part]), written, nu, n_blocks, opt, len(part["t"]), layout)
        for st in layout.statistics:
            own, allowed = {t.name for t in st.tables}, allowed_options(st)
            # feed: the task's rows as one chunk, into fresh tables
            seen, watch = set(), Watched(opt)
            rows = next(reduce.task_rows(iter([part]), written, nu, n_blocks, watch, len(part["t"]), layout))
            watch.read.clear()        # the recurrences' criteria read theirs: the statistic has not yet
            st.feed(WatchedTables(layout, dict(layout.empty(opt.blocks, edges)), seen), rows)
            assert seen <= own, f"{st.name}'s feed touches the tables {sorted(seen - own)} of others"
            assert watch.read <= allowed, \
                f"{st.name}'s feed reads the undeclared options {sorted(watch.read - allowed)}"
            # estimate and extras: on the task's tables (summed over its stretches; the extras take them as units)
            seen, watch = set(), Watched(opt)
            summed = {name: np.concatenate(v) if name in layout.samples else v.sum(axis=0)
                      for name, v in tables.items()}
            st.estimate(WatchedTables(layout, summed, seen), watch)
            if st.extra is not None:
                st.extra(WatchedTables(layout, dict(tables), seen), watch, np.random.default_rng(0))
            reads = own | set(st.uses_tables)
            assert seen <= reads, \
                f"{st.name}'s estimate reads the tables {sorted(seen - reads)}: name them in uses_tables"
            assert watch.read <= allowed, \
                f"{st.name}'s estimate reads the undeclared options {sorted(watch.read - allowed)}"
    assert kinds == {schema.KIND_EVENT, schema.KIND_CREEP} and len(layout.statistics) >= 3


@pytest.mark.parametrize("command", COMMANDS)
def test_the_stored_columns_do_not_follow_the_statistics_order(command):
    """The columns of a table shared by several statistics sit where the summaries store them (STORED_COLUMNS),
    whatever the statistics' places: the registry in the reverse order lays them out the same."""
    forward, backward = Layout(of(command)), Layout(tuple(reversed(of(command))))
    assert forward.columns == backward.columns
    assert Layout().columns["numbers"][:3] == ["n_events", "n_large", "n_rec"]
