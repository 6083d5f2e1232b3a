"""Catalogs and summaries as tables: numpy structured arrays, pandas DataFrames, CSV files.

    from analysis import export
    ev = export.events("my.h5")                  # every committed event (verified), one row each
    for part in export.iter_events("my.h5"):     # ... in chunks, for a catalog too large to hold
        ...
    tk = export.tasks("my.h5")                   # one row per task: parameters, counts, status, ...
    cu = export.curves("my.summary.h5")          # one row per point, curve and bin: density, lo, hi
    nb = export.numbers("my.summary.h5")         # one row per point: parameters, every number, lo, hi
    pk = export.peaks("my.summary.h5")           # one row per recurrence peak of a point
    sm = export.seismicity("my.summary.h5")      # one row per point, time bin and distance bin of its map
    df = export.numbers("my.summary.h5", frame=True)   # a pandas DataFrame (pandas is optional)
    export.columns("my.h5", "events")            # {column: (unit, meaning)}
    export.write("my.h5", "tables/")             # what `python -m analysis export my.h5 -o tables/` does

Events join tasks on `task`; curves and peaks join numbers on `point` (the row of the summary's
/points datasets). Units and meanings come from the tables that also describe the HDF5 datasets
(ensemble/store/schema.py's and analysis/summary.py's DATASETS), so the files and the exports say the
same. Text is returned on one line (newlines as spaces); a task's [integrator] is split into
typed columns integrator_<key>.

CSV (the only format so far; FORMATS maps a format to its writer, `--format` chooses). Each file
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
import os
import tomllib
from dataclasses import dataclass

import numpy as np

from ensemble import __version__, checks, filekind
from ensemble.store import reader, schema
from ensemble.store.errors import CatalogError
from ensemble.config import LAW_KEYS

from . import merge, summary

TITLES = {   # table -> what its rows are (said in its file's header)
    "events": "one row per committed event",
    "tasks": "one row per task",
    "curves": "one row per point, curve and bin",
    "numbers": "one row per parameter point",
    "peaks": "one row per recurrence peak of a point",
    "seismicity": "one row per point, time bin and distance bin of the seismicity around its mainshocks",
}
SUMMARY_SETTINGS = ("mu_c", "window", "b_cut", "bootstrap", "level", "blocks", "seed", *summary.SEIS_ATTRS)


@dataclass
class Table:
    columns: dict           # name -> (unit, meaning), in column order
    parts: object           # iterable of structured arrays with these fields
    free_text: tuple = ()   # columns of free text (last): quoted where needed, left out for genfromtxt


# -- the tables ------------------------------------------------------------------------------

def _one_line(text):
    return " ".join(str(text).splitlines())


def _structured(columns, values):
    """Structured array with the given {name: 1-D array}, text as unicode of its longest length."""
    arrays = {}
    for name in columns:
        a = np.asarray(values[name])
        if a.dtype.kind in "SUO":
            a = np.array([_one_line(x.decode(errors="replace") if isinstance(x, bytes) else x) for x in a],
                         dtype=str)
        arrays[name] = a
    n = len(next(iter(arrays.values()))) if arrays else 0
    out = np.empty(n, dtype=[(name, a.dtype) for name, a in arrays.items()])
    for name, a in arrays.items():
        out[name] = a
    return out


def _events(path, chunk=schema.READ_CHUNK):
    names = list(schema.EVENT_FIELDS)
    columns = {name: schema.DATASETS[f"events/{name}"][::2] for name in names}
    dtype = [(name, schema.EVENT_FIELDS[name]) for name in names]

    def parts():
        # the catalog checks each chunk's ranges as it streams and each task's checksum after it
        with filekind.reading(path, "the event catalog", CatalogError), reader.Reader(path) as cat:
            for task in range(len(cat.tasks["point"])):
                for part in cat.task_events(task, chunk):
                    out = np.empty(len(part["t"]), dtype=dtype)
                    for name in names:
                        out[name] = part[name]
                    yield out
    return Table(columns, parts())


INTEGRATOR_MEANINGS = {   # key -> (unit, meaning), the keys of ensemble.config.Integrator
    "method": ("text", "event integrator (exp4 exponential in the aging law's state, its default; ark4, ark3, ark5 adaptive IMEX; rk4 fixed step)"),
    "dt": ("model time", "step of rk4; first step of the adaptive methods"),
    "rtol": ("1", "adaptive methods: relative tolerance of the local error per step"),
    "atol": ("model length", "adaptive methods: absolute tolerance (slip, velocity)"),
    "max_step": ("model time", "adaptive methods: largest step"),
    "max_duration": ("model time", "an event lasting longer is an error"),
    "creep_tol": ("1", "creep phase: local error of the state psi per creep step"),
}


def _integrator_columns(path, texts):
    """{integrator_<key>: values} from each task's [integrator] TOML; numbers as float64."""
    parsed = []
    for k, text in enumerate(texts):
        try:
            parsed.append(tomllib.loads(text))
        except tomllib.TOMLDecodeError as err:
            raise CatalogError(f"{path}: task {k}: stored integrator cannot be read ({err})") from None
    keys = list(dict.fromkeys(key for p in parsed for key in p))
    out = {}
    for key in keys:
        values = [p.get(key) for p in parsed]
        if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values if v is not None):
            out[key] = np.array([np.nan if v is None else float(v) for v in values], dtype=np.float64)
        else:
            out[key] = np.array(["" if v is None else str(v) for v in values], dtype=str)
    return out


def _tasks(path):
    with filekind.reading(path, "the event catalog", CatalogError):
        _, tasks, _ = reader.read_tasks(path)
    described = {**{name.split("/", 1)[1]: entry for name, entry in schema.DATASETS.items()
                    if name.startswith("tasks/")}, **schema.READER_TASKS}
    values = {"task": np.arange(len(tasks["point"]), dtype=np.int64)}
    columns = {"task": ("index", "task index (events join on it)")}
    first = ("point", "seed_index", "N", "l", "nu", "law", *LAW_KEYS, "events_written", "events_done",
             "status", "rank", "wall_time", "events_per_second", "seed_entropy", "spawn_key")
    for name in (*first, *sorted(set(tasks) - set(first) - {"integrator", "error"})):
        values[name], columns[name] = tasks[name], described.get(name, (None, "", ""))[::2]
    for key, v in _integrator_columns(path, tasks["integrator"]).items():
        unit, meaning = INTEGRATOR_MEANINGS.get(key, ("", ""))
        values[f"integrator_{key}"] = v
        columns[f"integrator_{key}"] = (unit, f"[integrator] {key} of the task: {meaning}" if meaning else "")
    values["error"], columns["error"] = tasks["error"], described["error"][::2]
    return Table(columns, [_structured(columns, values)], free_text=("error",))


def _summary_column(key):
    """(unit, meaning) of a summary dataset of one value per point, or ("", "") if undocumented."""
    entry = summary.DATASETS.get(key)
    return entry[::2] if entry else ("", "")


def _numbers(s):
    n = len(s["points/N"])
    values = {"point": np.arange(n, dtype=np.int64)}
    columns = {"point": ("index", "parameter point: row of the summary's /points (curves and peaks join on it)")}
    known = [k for k in summary.DATASETS if k.startswith("points/") and k.count("/") == 1]
    single = [k for k in known if k in s] + sorted(
        k for k in s if k.startswith("points/") and k.count("/") == 1 and k not in known)
    for key in single:
        if np.ndim(s[key]) == 1:
            name = key.split("/", 1)[1]
            values[name], columns[name] = s[key], _summary_column(key)
    order = list(summary.NUMBER_MEANINGS)
    numbers = sorted((k.rsplit("/", 1)[1] for k in s if k.startswith("points/numbers/")),
                     key=lambda name: (order.index(name) if name in order else len(order), name))
    for name in numbers:
        data = s[f"points/numbers/{name}"]
        unit, meaning = _summary_column(f"points/numbers/{name}")
        if data.ndim == 1:
            values[name], columns[name] = data, (unit, meaning)
            continue
        for j, (suffix, what) in enumerate((("", "estimate"), ("_lo", "lower end of the interval"),
                                            ("_hi", "upper end of the interval"))):
            values[name + suffix] = data[:, j]
            columns[name + suffix] = (unit, f"{meaning}: {what}" if meaning else "")
    return Table(columns, [_structured(columns, values)])


def _curves(s):
    rows = {k: [] for k in ("point", "curve", "bin", "edge_lo", "edge_hi", "center", "density",
                            "density_lo", "density_hi")}
    for curve, (bins, *_) in summary.CURVES.items():
        if f"points/{curve}_density" not in s:
            continue
        edges = s[f"bins/{bins}"]
        est, lo, hi = (s[f"points/{curve}_{part}"] for part in ("density", "lo", "hi"))
        for point in range(len(est)):
            m = len(edges) - 1
            for key, col in (("point", np.full(m, point)), ("curve", np.full(m, curve)),
                             ("bin", np.arange(m)), ("edge_lo", edges[:-1]), ("edge_hi", edges[1:]),
                             ("center", 0.5 * (edges[:-1] + edges[1:])), ("density", est[point]),
                             ("density_lo", lo[point]), ("density_hi", hi[point])):
                rows[key].append(col)
    values = {k: np.concatenate(v) if v else np.zeros(0) for k, v in rows.items()}
    for k in ("point", "bin"):
        values[k] = values[k].astype(np.int64)
    values["curve"] = values["curve"].astype(str)
    kinds = "; ".join(f"{c}: the {var} of {whose}" for c, (_, var, whose, _) in summary.CURVES.items())
    var_units = " or ".join(dict.fromkeys(summary.DATASETS[f"bins/{b}"][0] for b, *_ in summary.CURVES.values()))
    where = ", ".join(f"{var} for {c}" for c, (_, var, _, _) in summary.CURVES.items())
    columns = {
        "point": ("index", "parameter point (row of numbers.csv)"),
        "curve": ("text", f"which density: {kinds}"),
        "bin": ("index", "bin of the curve's variable (0 = lowest)"),
        "edge_lo": (var_units, f"lower edge of the bin, in the curve's variable ({where}); bins are half-open"),
        "edge_hi": (var_units, "upper edge of the bin"),
        "center": (var_units, "centre of the bin"),
        "density": ("1 / unit of the variable", "probability density (NaN with nothing to count)"),
        "density_lo": ("1 / unit of the variable", "lower end of its bootstrap interval (NaN with one unit)"),
        "density_hi": ("1 / unit of the variable", "upper end of its bootstrap interval (NaN with one unit)"),
    }
    return Table(columns, [_structured(columns, values)])


def _peaks(s):
    peaks = s["points/peaks"]
    point, rank = np.nonzero(np.isfinite(peaks[..., 0]))
    values = {"point": point.astype(np.int64), "peak": rank.astype(np.int64),
              "tnu": peaks[point, rank, 0], "tnu_lo": peaks[point, rank, 1], "tnu_hi": peaks[point, rank, 2]}
    unit, _ = _summary_column("points/peaks")
    columns = {
        "point": ("index", "parameter point (row of numbers.csv)"),
        "peak": ("index", "0 for the highest peak of the point, 1 for the next, ..."),
        "tnu": (unit, "T nu at the peak (centre of its bin in the smoothed histogram)"),
        "tnu_lo": (unit, "lower end of its bootstrap interval (NaN with one unit or no match)"),
        "tnu_hi": (unit, "upper end of its bootstrap interval (NaN with one unit or no match)"),
    }
    return Table(columns, [_structured(columns, values)])


def _seismicity(s):
    """The maps of the seismicity around large events, long format (no rows for a summary before format 5)."""
    columns = {
        "point": ("index", "parameter point (row of numbers.csv)"),
        "time_lo": ("model length", "lower edge of the time bin: T nu from the mainshock's onset, negative before it"),
        "time_hi": ("model length", "upper edge of the time bin (bins are half-open)"),
        "distance_lo": ("blocks", "lower edge of the distance bin: blocks from the mainshock's epicenter"),
        "distance_hi": ("blocks", "upper edge of the distance bin (bins are half-open)"),
        "rate": _summary_column("points/seismicity_rate")[:1] + (
            "events per mainshock per block per unit T nu in the cell (NaN where nothing was exposed); the "
            "background rate is in numbers.csv",),
    }
    values = {name: np.zeros(0) for name in columns}
    if summary.has_seismicity(s):
        rate, te, de = s["points/seismicity_rate"], s["bins/seis_time"], s["bins/seis_distance"]
        point, j, k = (a.ravel() for a in np.meshgrid(np.arange(len(rate)), np.arange(len(te) - 1),
                                                       np.arange(len(de) - 1), indexing="ij"))
        values = {"point": point.astype(np.int64), "time_lo": te[j], "time_hi": te[j + 1], "distance_lo": de[k],
                  "distance_hi": de[k + 1], "rate": rate[point, j, k]}
    values["point"] = values["point"].astype(np.int64)
    return Table(columns, [_structured(columns, values)])


def _whole(table):
    parts = list(table.parts)
    if not parts:
        return np.zeros(0, dtype=[(name, schema.EVENT_FIELDS[name]) for name in table.columns])
    return np.concatenate(parts) if len(parts) > 1 else parts[0]


def _result(arr, frame):
    return as_dataframe(arr) if frame else arr


# -- the API ---------------------------------------------------------------------------------

def events(path, frame=False):
    """Every committed event of a catalog (structured array, tasks in order; verified).

    Fields: schema.EVENT_FIELDS (task, t, epicenter, mu, slip, first, last, n_slipped, boundary,
    duration, kind, ending): inertial events (kind 0) and creep episodes (kind 1) alike. Holds the
    whole catalog in memory: iter_events streams it.
    """
    return _result(_whole(_events(path)), frame)


def iter_events(path, chunk=schema.READ_CHUNK):
    """The catalog's committed events as structured arrays of at most `chunk` rows, verified as
    they stream (a task's checksum after its last chunk: consume them all)."""
    return iter(_events(path, chunk).parts)


def tasks(path, frame=False):
    """One row per task of a catalog: task, its parameters, committed and simulated event counts,
    status, provenance, integrator_<key> columns, error."""
    return _result(_tasks(path).parts[0], frame)


def curves(path, frame=False):
    """The densities of a summary (R(mu), T nu of all and of interior recurrences), long format:
    one row per point, curve and bin, with the bin's edges and centre and the density's interval."""
    return _result(_curves(summary.read(path)).parts[0], frame)


def numbers(path, frame=False):
    """One row per parameter point of a summary: its parameters, method, units, and every number
    with the ends of its interval (name, name_lo, name_hi)."""
    return _result(_numbers(summary.read(path)).parts[0], frame)


def peaks(path, frame=False):
    """The recurrence peaks of a summary: one row per peak of a point, highest first."""
    return _result(_peaks(summary.read(path)).parts[0], frame)


def seismicity(path, frame=False):
    """The seismicity around the large events of a summary: one row per point, time bin and distance bin,
    with the rate of events per mainshock per block per unit T nu (none before summary format 5)."""
    return _result(_seismicity(summary.read(path)).parts[0], frame)


def columns(path, table):
    """{column: (unit, meaning)} of one table ("events", "tasks", "curves", "numbers", "peaks", "seismicity")."""
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
SUMMARY_TABLES = ("curves", "numbers", "peaks", "seismicity")


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
        build = {"events": lambda: _events(path, chunk), "tasks": lambda: _tasks(path)}
        return {name: build[name]() for name in names}, statement
    s = summary.read(path)
    build = {"curves": lambda: _curves(s), "numbers": lambda: _numbers(s), "peaks": lambda: _peaks(s),
             "seismicity": lambda: _seismicity(s)}
    a = s["attrs"]
    settings = (f"reduced from {a.get('catalog', '?')} with "
                + ", ".join(f"{k} = {a[k]}" for k in SUMMARY_SETTINGS if k in a))
    if str(a.get("partial", "")):   # an unfinished run's reduction says so (analysis/merge.py)
        settings += "; " + _one_line(a["partial"])
    return {name: build[name]() for name in names}, settings


# -- CSV ----------------------------------------------------------------------------------------

_SPECIAL = (",", '"', "#", "\r", "\n")


def _text_cell(text):
    if any(c in text for c in _SPECIAL):
        return '"' + text.replace('"', '""') + '"'
    return text


def _cells(arr, name):
    col = arr[name]
    if col.dtype.kind == "U":
        return [_text_cell(x) for x in col.tolist()]
    # numpy's str of a float64 is the shortest text that reads back to the same value
    return col.astype(str).tolist()


def _csv_header(name, table, source, settings):
    names = list(table.columns)
    usecols = ""
    if table.free_text:
        usecols = f", usecols=range({len(names) - len(table.free_text)})"
    lines = [
        None,   # the first line, which needs the count of lines
        f"# from {source} by `python -m analysis export` (bk-ensemble {__version__}); {TITLES[name]}",
        "# floats exact (shortest text of the same float64; nan, inf), booleans True/False"
        + (f"; {', '.join(table.free_text)}: free text, quoted as in RFC 4180 where needed" if table.free_text else ""),
    ]
    if settings:
        lines.append(f"# {settings}")
    lines.append("# column: unit, meaning")
    lines += [f"# {col}: {unit}, {meaning}" for col, (unit, meaning) in table.columns.items()]
    lines[0] = (f"# {name}.csv: {len(lines)} comment lines, then a row of column names; read with "
                f"pandas.read_csv(FILE, comment='#') or numpy.genfromtxt(FILE, delimiter=',', names=True, "
                f"dtype=None, encoding='utf-8', comments=None, skip_header={len(lines)}{usecols})")
    return "\n".join(lines) + "\n" + ",".join(names) + "\n"


def write_csv(path, name, table, source, settings=""):
    """One table into the CSV file `path` (streamed part by part)."""
    with open(path, "w", encoding="utf-8", newline="") as fh:
        fh.write(_csv_header(name, table, source, settings))
        names = list(table.columns)
        for part in table.parts:
            if len(part):
                cells = [_cells(part, n) for n in names]
                fh.write("\n".join(map(",".join, zip(*cells))) + "\n")


FORMATS = {"csv": (".csv", write_csv)}   # format -> (file suffix, writer(path, name, table, source, settings))


def write(source, directory, fmt="csv", force=False, chunk=schema.READ_CHUNK, partial=False):
    """Every table of a catalog (events, tasks) or a summary (curves, numbers, peaks, seismicity) into files
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
    if os.path.isdir(directory):
        for path in paths:   # not the source, not a directory, not there unless force
            checks.output(path, inputs=[source], force=force, what="table")
    tables, settings = _tables(source, names, chunk, partial)
    os.makedirs(directory, exist_ok=True)
    beside = [p + ".partial" for p in paths]
    try:
        for name, tmp in zip(names, beside):
            writer(tmp, name, tables[name], source, settings)
        for tmp, path in zip(beside, paths):
            os.replace(tmp, path)
    finally:
        for tmp in beside:
            if os.path.exists(tmp):
                os.remove(tmp)
    return paths
