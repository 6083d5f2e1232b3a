"""CSV files of an export's tables (analysis/export.py: FORMATS["csv"]; the format is described there).

An export format is one module analysis/export_<name>.py that defines FORMAT = (file suffix, writer), the
writer(path, name, table, source, settings) writing one table (export_tables.Table) into `path`, through
ensemble.space.write_file; export.py finds it, and `analysis export --format <name>` takes it."""
from ensemble import space
from ensemble.version import __version__

from .export_tables import TITLES

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
    """One table into the CSV file `path`, streamed part by part (space.write_file)."""
    names = list(table.columns)

    def text():
        yield _csv_header(name, table, source, settings)
        for part in table.parts:
            if len(part):
                cells = [_cells(part, n) for n in names]
                yield "\n".join(map(",".join, zip(*cells))) + "\n"
    space.write_file(path, text(), f"the table {name}")


FORMAT = (".csv", write_csv)
