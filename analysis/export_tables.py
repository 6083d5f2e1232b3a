"""The tables of an export (analysis/export.py): what each table's columns are, and their rows as
structured arrays, from a catalog (events, tasks) or a summary (curves, numbers, and each statistic's own:
statistics.ExportTable, the recurrence peaks and the seismicity's maps today).

Units and meanings come from the tables that also describe the HDF5 datasets (ensemble/store/schema.py's
and analysis/summary.py's DATASETS) and from where a key is declared (a friction law's keys, the
[integrator] keys in ensemble.integrators.KEYS), so the files and the exports say the same.
"""
import tomllib
from dataclasses import dataclass

import numpy as np

from ensemble import filekind
from ensemble.config import LAW_KEYS
from ensemble.integrators import KEYS as INTEGRATOR_KEYS
from ensemble.store import reader, schema
from ensemble.store.errors import CatalogError

from . import summary
from .reduce import LAYOUT

# the statistics' own tables of a summary (statistics.ExportTable), by name
STATISTIC_EXPORTS = {e.name: e for st in LAYOUT.statistics for e in st.exports}
TITLES = {   # table -> what its rows are (said in its file's header)
    "events": "one row per committed event",
    "tasks": "one row per task",
    "curves": "one row per point, curve and bin",
    "numbers": "one row per parameter point",
    **{name: e.title for name, e in STATISTIC_EXPORTS.items()},
}
SUMMARY_SETTINGS = summary.STORED_OPTIONS


@dataclass
class Table:
    columns: dict           # name -> (unit, meaning), in column order
    parts: object           # iterable of structured arrays with these fields
    free_text: tuple = ()   # columns of free text (last): quoted where needed, left out for genfromtxt


def one_line(text):
    return " ".join(str(text).splitlines())


def _structured(columns, values):
    """Structured array with the given {name: 1-D array}, text as unicode of its longest length."""
    arrays = {}
    for name in columns:
        a = np.asarray(values[name])
        if a.dtype.kind in "SUO":
            a = np.array([one_line(x.decode(errors="replace") if isinstance(x, bytes) else x) for x in a],
                         dtype=str)
        arrays[name] = a
    n = len(next(iter(arrays.values()))) if arrays else 0
    out = np.empty(n, dtype=[(name, a.dtype) for name, a in arrays.items()])
    for name, a in arrays.items():
        out[name] = a
    return out


def events_table(path, chunk=schema.READ_CHUNK):
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


# key -> (unit, meaning) of the [integrator] keys (ensemble.integrators.KEYS, where each is declared)
INTEGRATOR_MEANINGS = {name: (key.unit, key.described) for name, key in INTEGRATOR_KEYS.items()}


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


def tasks_table(path):
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


def numbers_table(s):
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


def curves_table(s):
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


def statistic_table(s, export):
    """A statistic's table of summary `s` (statistics.ExportTable)."""
    columns, values = export.build(s)
    return Table(columns, [_structured(columns, values)])


def whole(table):
    """One structured array of a table's parts."""
    parts = list(table.parts)
    if not parts:
        return np.zeros(0, dtype=[(name, schema.EVENT_FIELDS[name]) for name in table.columns])
    return np.concatenate(parts) if len(parts) > 1 else parts[0]
