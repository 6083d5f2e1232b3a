"""Catalogs and summaries as tables: numpy structured arrays, pandas DataFrames, CSV files.

    from analysis import export
    ev = export.events("my.h5")                  # every committed event (verified), one row each
    for part in export.iter_events("my.h5"):     # ... in chunks, for a catalog too large to hold
        ...
    tk = export.tasks("my.h5")                   # one row per task: parameters, counts, status, ...
    cu = export.curves("my.summary.h5")          # one row per point, curve and bin: density, lo, hi
    nb = export.numbers("my.summary.h5")         # one row per point: parameters, every number, lo, hi
    pk = export.table("my.summary.h5", "peaks")  # a statistic's own table: one row per recurrence peak of a point
    sm = export.table("my.summary.h5", "seismicity")   # one row per point, time bin and distance bin of its map
    df = export.numbers("my.summary.h5", frame=True)   # a pandas DataFrame (pandas is optional)
    export.columns("my.h5", "events")            # {column: (unit, meaning)}
    export.write("my.h5", "tables/")             # what `python -m analysis export my.h5 -o tables/` does

Events join tasks on `task`; curves and peaks join numbers on `point` (the row of the summary's
/points datasets). Units and meanings come from the tables that also describe the HDF5 datasets
(ensemble/store/schema.py's and analysis/summary.py's DATASETS), so the files and the exports say the
same (export_tables.py builds the tables, export_csv.py writes them). Text is returned on one line
(newlines as spaces); a task's [integrator] is split into typed columns integrator_<key>.

CSV (the only format so far; FORMATS maps a format to its writer, found in analysis/export_<format>.py,
`--format` chooses). Each file
starts with comment lines: the first says how many there are and how to read the file with pandas
or numpy, one line per column follows, "# column: unit, meaning"; then one row of column names,
then the rows. numpy.genfromtxt(names=True) takes the names from the first line even when it is a
comment, so it reads these files with skip_header (the count in the first line) and comments=None;
pandas.read_csv with comment="#". Floats are written as the shortest text that reads back to the
same float64 (nan, inf, -inf included; pandas 3 reads them exactly, older pandas with
float_precision="round_trip"), booleans as True/False. Text is quoted as in RFC 4180 where it holds
a comma, a quote or a '#'; only a task's error (free text, the last column of tasks.csv) ever
does, and genfromtxt, which knows no quotes, is told to leave that column out (usecols). An empty
text reads as "" with numpy and as NaN with pandas.

An unfinished run (a *.partial catalog, or tasks unfinished) is exported only when asked
(write(partial=True), `--partial`), as reduce reduces it; then every table's header states it in
one line, "PARTIAL export of an unfinished run (...): events written of expected" (a format
without comment lines would carry that line in its metadata), as the tables of a --partial
reduction carry the summary's statement.

A catalog is streamed in chunks of schema.READ_CHUNK rows, each verified as it is read (ranges,
and each task's checksum after its last chunk); the files of an export are written beside their
names and renamed into place only when all are complete, so an export that fails writes nothing.
"""
import contextlib
import importlib
import os
import pkgutil

from ensemble import checks, filekind
from ensemble.store import reader, schema
from ensemble.store.errors import CatalogError

from . import merge, summary
from .export_tables import (STATISTIC_EXPORTS, SUMMARY_SETTINGS, curves_table, events_table, numbers_table, one_line,
                            statistic_table, tasks_table, whole)


def _result(arr, frame):
    return as_dataframe(arr) if frame else arr


# -- the API ---------------------------------------------------------------------------------

def events(path, frame=False):
    """Every committed event of a catalog (structured array, tasks in order; verified).

    Fields: schema.EVENT_FIELDS (task, t, epicenter, mu, slip, first, last, n_slipped, boundary,
    duration, kind, ending): inertial events (kind 0) and creep episodes (kind 1) alike. Holds the
    whole catalog in memory: iter_events streams it.
    """
    return _result(whole(events_table(path)), frame)


def iter_events(path, chunk=schema.READ_CHUNK):
    """The catalog's committed events as structured arrays of at most `chunk` rows, verified as
    they stream (a task's checksum after its last chunk: consume them all)."""
    return iter(events_table(path, chunk).parts)


def tasks(path, frame=False):
    """One row per task of a catalog: task, its parameters, committed and simulated event counts,
    status, provenance, integrator_<key> columns, error."""
    return _result(tasks_table(path).parts[0], frame)


def curves(path, frame=False):
    """The densities of a summary (R(mu), T nu of all and of interior recurrences), long format:
    one row per point, curve and bin, with the bin's edges and centre and the density's interval."""
    return _result(curves_table(summary.read(path)).parts[0], frame)


def numbers(path, frame=False):
    """One row per parameter point of a summary: its parameters, method, units, and every number
    with the ends of its interval (name, name_lo, name_hi)."""
    return _result(numbers_table(summary.read(path)).parts[0], frame)


def table(path, name, frame=False):
    """Any table of a catalog or a summary by its name (CATALOG_TABLES, SUMMARY_TABLES: among them each
    statistic's own, statistics.ExportTable: "peaks", the recurrence peaks of each point, highest first;
    "seismicity", one row per point, time bin and distance bin of the rate around its mainshocks)."""
    return _result(whole(_tables(path, [name])[0][name]), frame)


def columns(path, table):
    """{column: (unit, meaning)} of one table (CATALOG_TABLES, SUMMARY_TABLES)."""
    return dict(_tables(path, [table])[0][table].columns)


def as_dataframe(arr):
    """A structured array as a pandas DataFrame (pandas is optional: ImportError if missing)."""
    try:
        import pandas
    except ImportError:
        raise ImportError("pandas is not installed (it is optional: pip install pandas), so no DataFrame; "
                          "the structured arrays hold the same data") from None
    return pandas.DataFrame({name: arr[name] for name in arr.dtype.names})


CATALOG_TABLES = ("events", "tasks")
SUMMARY_TABLES = ("curves", "numbers", *STATISTIC_EXPORTS)


def source_kind(path):
    """"summary" or "catalog"; anything else raises the catalog's error saying what the file is."""
    found = filekind.identify(path)
    if found[0] == "summary":
        return "summary"
    filekind.require(path, "catalog", CatalogError, found)
    return "catalog"


def _unfinished_run(path):
    """("", "") for a finished run, else (why, statement): why it is unfinished, worded as reduce's
    refusal (analysis/merge.py, which counts its tasks the same way: not finished, or with fewer
    events than events_per_task; or a run's *.partial), and the line every table's header states."""
    with filekind.reading(path, "the event catalog", CatalogError):
        per_task, tasks, _ = reader.read_tasks(path)
    n_open, named = merge._unfinished(path, tasks, per_task)
    if not (n_open or named):
        return "", ""
    n_tasks = len(tasks["point"])
    written, expected = int(tasks["events_written"].sum()), n_tasks * int(per_task)
    share = f" ({100 * written / expected:.1f}%)" if expected else ""
    why = f"{n_open} of {n_tasks} tasks unfinished" if n_open else "named *.partial"
    return why, f"PARTIAL export of an unfinished run ({why}): {written} of {expected} events{share}"


def _tables(path, names, chunk=schema.READ_CHUNK, partial=True):
    """({name: Table}, a line of the reduction's settings, or of what an unfinished run lacks, or "")
    of a catalog's or a summary's tables; an unfinished run is refused unless partial."""
    kind = source_kind(path)
    wanted = CATALOG_TABLES if kind == "catalog" else SUMMARY_TABLES
    for name in names:
        if name not in wanted:
            raise ValueError(f"{path} is {filekind.NOUNS[kind]}: its tables are {', '.join(wanted)}, not {name}")
    if kind == "catalog":
        why, statement = _unfinished_run(path)
        if why and not partial:
            path = str(path)
            raise CatalogError(
                f"{path} is an unfinished run ({why}); continue it with `python -m ensemble resume "
                f"{path.removesuffix('.partial')}`, or export what it holds with --partial")
        build = {"events": lambda: events_table(path, chunk), "tasks": lambda: tasks_table(path)}
        return {name: build[name]() for name in names}, statement
    s = summary.read(path)
    build = {"curves": lambda: curves_table(s), "numbers": lambda: numbers_table(s),
             **{name: (lambda e=e: statistic_table(s, e)) for name, e in STATISTIC_EXPORTS.items()}}
    a = s["attrs"]
    settings = (f"reduced from {a.get('catalog', '?')} with "
                + ", ".join(f"{k} = {a[k]}" for k in SUMMARY_SETTINGS if k in a))
    if str(a.get("partial", "")):   # an unfinished run's reduction says so (analysis/merge.py)
        settings += "; " + one_line(a["partial"])
    return {name: build[name]() for name in names}, settings


def _formats():
    """{format: (file suffix, writer(path, name, table, source, settings))}: every module analysis/export_<format>.py
    that defines FORMAT (export_csv.py: csv)."""
    found = {}
    for info in pkgutil.iter_modules([os.path.dirname(__file__)]):
        if info.name.startswith("export_"):
            module = importlib.import_module(f"{__package__}.{info.name}")
            if hasattr(module, "FORMAT"):
                found[info.name.removeprefix("export_")] = module.FORMAT
    return found


FORMATS = _formats()


def write(source, directory, fmt="csv", force=False, chunk=schema.READ_CHUNK, partial=False):
    """Every table of a catalog (CATALOG_TABLES) or a summary (SUMMARY_TABLES) into files
    DIRECTORY/<table><suffix>; returns their paths.

    Refuses (checks.UsageError naming the path, nothing written) a directory that cannot be made
    or written, the source as the directory or a table, and a table that exists unless force. An
    unfinished run (a *.partial catalog, unfinished tasks) is refused (CatalogError, as
    reduce refuses it) unless partial; then every table's header says what it lacks. Files are
    written beside their names and renamed into place when all are complete.
    """
    suffix, writer = FORMATS[fmt]
    checks.output(directory, inputs=[source], force=force, directory=True, what="export directory")
    kind = source_kind(source)
    names = CATALOG_TABLES if kind == "catalog" else SUMMARY_TABLES
    paths = [os.path.join(directory, name + suffix) for name in names]
    beside = [p + ".partial" for p in paths]
    if os.path.isdir(directory):
        for path in paths:   # not the source, not a directory, not there unless force
            checks.output(path, inputs=[source], force=force, what="table")
        for tmp in beside:   # (a link there would be written through)
            checks.output(tmp, inputs=[source], force=True, what="table")
    tables, settings = _tables(source, names, chunk, partial)
    made = not os.path.isdir(directory)
    os.makedirs(directory, exist_ok=True)
    done = False
    try:
        for name, tmp in zip(names, beside):
            writer(tmp, name, tables[name], source, settings)
        for tmp, path in zip(beside, paths):
            os.replace(tmp, path)
        done = True
    finally:
        for tmp in beside:
            if os.path.exists(tmp):
                os.remove(tmp)
        if made and not done:   # a directory this export made and could not fill (a full disk) goes too
            with contextlib.suppress(OSError):
                os.rmdir(directory)
    return paths
