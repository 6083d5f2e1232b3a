"""The package's Python front door (docs/api.md): a catalog's rows, a reduction, and a summary's numbers, curves,
report and figures, as arrays and DataFrames with units and meanings.

    import analysis
    summary = analysis.summarize("small.h5", bootstrap=200)  # -> analysis.Summary (written beside the catalog)
    summary.numbers(frame=True)                              # one row per point: parameters, every number, lo, hi
    summary.curve("mu", point=0)                             # the bins and R(mu) with its band
    summary.figure("magnitude")                              # a matplotlib Figure (any of summary.figures)
    analysis.events("small.h5")                              # every committed row of the catalog

(The function is `summarize`: `analysis.reduce` is the module of the reduction's engine.)
`python -m analysis reduce` is the same reduction (reduction.reduce_on) with the command line's output and exit
codes; here a bad option or path raises checks.UsageError (a ValueError), a bad file CatalogError or SummaryError.
"""
import warnings
from pathlib import Path

import numpy as np

from . import export, options, report, summary as summary_file
from .reduce import LAYOUT
from .reduction import Request, default_output, reduce_on

__all__ = ["Summary", "events", "summarize", "tasks"]


def events(path, frame=False):
    """Every committed row of a catalog (inertial events and creep episodes: the column `kind`), verified, as a numpy
    structured array, or a pandas DataFrame with frame=True (pandas is optional); export.columns(path, "events")
    gives each column's unit and meaning."""
    return export.events(path, frame)


def tasks(path, frame=False):
    """One row per task of a catalog: its parameters, counts, status, provenance and integrator."""
    return export.tasks(path, frame)


def summarize(catalogs, output=None, *, partial=False, force=False, region=False, region_span=None, region_skip=None,
              comm=None, say=None, **given):
    """Reduce one catalog (a path) or several (a list) to a summary; returns it (a Summary).

    output: the summary's path (default beside the one catalog: X.summary.h5); partial: reduce an unfinished run as
    far as written; force: replace an existing summary (never another file); region, region_span, region_skip: a
    regional reduction (analysis/region.py). given: the reduction's options by name (`analysis.options.declared()`:
    mu_bins="0:7:70" or edges, mu_c=4.0, bootstrap=1000, ...), the others their defaults (the friction law's scale
    where so declared). comm: the MPI communicator whose ranks share the tasks (default: MPI.COMM_WORLD); say: a
    print-like function for what the reduction reports (default: silent); its warnings (intervals resting on
    fewer than 10 resampling units, ...) are Python warnings (UserWarning)."""
    from mpi4py import MPI

    paths = [str(p) for p in ([catalogs] if isinstance(catalogs, (str, Path)) else catalogs)]
    decl = options.declared("reduce")
    unknown = sorted(set(given) - set(decl))
    if unknown:
        raise TypeError(f"analysis.summarize: no option {', '.join(unknown)} (the options: {', '.join(decl)})")
    checked = {name: options.check(decl[name], value) for name, value in given.items() if value is not None}
    request = Request(paths, None if output is None else str(output), partial=partial, force=force, region=region,
                      region_span=region_span, region_skip=region_skip, given=checked)
    comm = comm or MPI.COMM_WORLD
    reduce_on(comm, request, say=say or (lambda *args, **kwargs: None),
              warn=lambda line: warnings.warn(line, stacklevel=3))
    comm.Barrier()     # the summary is written (by rank 0) before any rank reads it
    return Summary(request.output or default_output(paths))


class Summary:
    """A reduction summary (the file `python -m analysis reduce` writes), read and verified once.

    points: its parameter points, one row each (parameters, law, resampling method and units). numbers(): every
    number with its interval; number(name): one of them, (points, 3) estimate, lo, hi; curve(name, point): a
    density with its band and bins; report(): the text of `analysis report`; figure(name): any statistic's figure;
    table(name): any table `analysis export` writes. meanings(): {number or curve: (unit, meaning)}."""

    def __init__(self, path):
        self.path = Path(path)
        self.data = summary_file.read(path)        # {dataset: array, "attrs": {...}}: the file as read

    def __repr__(self):
        return f"Summary({str(self.path)!r}: {len(self)} points)"

    def __len__(self):
        return len(self.data["points/N"])

    @property
    def figures(self):
        """The names of the figures of its statistics (`analysis plot --figure`)."""
        return [f.name for st in LAYOUT.statistics for f in st.figures]

    @property
    def tables(self):
        """The names of its tables (`analysis export`)."""
        return list(export.SUMMARY_TABLES)

    def table(self, name, frame=False):
        """A table of the summary by name (self.tables), as `analysis export` writes it."""
        return export.table(self.path, name, frame)

    def numbers(self, frame=False):
        """One row per point: its parameters, method, units, and every number with the ends of its interval
        (name, name_lo, name_hi)."""
        return self.table("numbers", frame)

    def number(self, name):
        """(points, 3): the estimate of number `name` at every point, and its interval's ends (NaN without)."""
        return np.asarray(self.data[f"points/numbers/{name}"])

    def curve(self, name, point=0):
        """A curve of one point: {"edges", "center", "density", "lo", "hi"} (the bins' edges and centres, the
        density and its band), name one of meanings()' curves ("mu", "tnu", "creep_mu", ...)."""
        bins = summary_file.CURVES[name][0]
        edges = np.asarray(self.data[f"bins/{bins}"])
        return {"edges": edges, "center": 0.5 * (edges[:-1] + edges[1:]),
                **{key: np.asarray(self.data[f"points/{name}_{part}"][point])
                   for key, part in (("density", "density"), ("lo", "lo"), ("hi", "hi"))}}

    def meanings(self):
        """{name: (unit, meaning)} of every number and curve the statistics declare."""
        out = {name: (unit, meaning) for name, (unit, meaning) in summary_file.NUMBER_MEANINGS.items()}
        out.update({name: (unit, f"the density of {variable} of {whose}")
                    for name, (_, variable, whose, unit) in summary_file.CURVES.items()})
        return out

    def report(self):
        """The text of `python -m analysis report`."""
        return report.table(self.data)

    def draw_curve(self, ax, name, point=0, label=None, color="C0", log=None):
        """Curve `name` of one point with its band onto the matplotlib axes `ax` (log: a log y axis; default for the
        densities of mu, whose tails span decades)."""
        from .drawing import band
        c = self.curve(name, point)
        log = name in ("mu", "creep_mu", "creep_duration") if log is None else log
        band(ax, c["center"], c["density"], c["lo"], c["hi"], label, color, log=log, open_ends=log)
        if log:
            ax.set_yscale("log")
        return ax

    def figure(self, name, title=None):
        """The figure `name` (self.figures) of this summary's points, as `analysis plot --figure` draws it: a
        matplotlib Figure to show, change or save (fig.savefig)."""
        from .plot import figure
        return figure(self.data, name, title, names=[self.path])
