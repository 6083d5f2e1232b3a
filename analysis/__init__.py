"""Reduction of event catalogs to the statistics of Ohmura & Kawamura (2007), and their figures.

    __main__.py       `python -m analysis`
    cli.py            the command line: reduce, plot, report, paper, export, compare
    statistics/       the statistics as plug-ins, one module each, and their registry (statistics/__init__.py)
    options.py        a reduction's options, from what the statistics declare: the record, the arguments, the checks
    merge.py          catalogs -> the one task table a reduction works on: which tasks pool, in which order
    region.py         `reduce --region`: the faults of a population pooled as one region observes them
    reduce.py         catalog -> per-task tables (streamed) -> per-point statistics with bootstrap intervals
    recurrence.py     local recurrence times of large events (the streamed scan, a numba kernel)
    stats.py          estimators on histograms: densities, peaks, the Gutenberg-Richter exponent, bootstrap
    summary.py        the summary HDF5 that `reduce` writes, and its reader
    report.py         the summary numbers of every parameter point as a text table
    plot.py           figures from one or more summaries
    figure_labels.py  the words of the figures: a summary's name, legend labels, titles
    drawing.py        what every figure draws with: bands, colours, the grid of panels, insets that cover no data
    paper.py          did this run reproduce the paper? its claims beside the summary's numbers
    compare.py        friction laws side by side, on a size axis that means the same under every law
    compare_plot.py   the comparison's figures
    export.py         catalogs and summaries as tables: numpy structured arrays, pandas DataFrames, CSV files
    export_tables.py  what each exported table's columns are, and their rows
    export_csv.py     CSV files of an export's tables (a format is one module export_<name>.py)
    history.py        `history`: one event history of a catalog (output.history) drawn in space and time
    reduction.py      a reduction as one call: catalogs -> summary on the ranks of a communicator
    api.py            the Python front door: summarize (catalogs -> Summary), Summary, events, tasks
"""
# the Python front door (api.py, docs/api.md), found when first asked for: `import analysis` stays light
API = ("Summary", "events", "summarize", "tasks")
__all__ = list(API)


def __getattr__(name):
    if name in API:
        from . import api
        return getattr(api, name)
    raise AttributeError(f"module 'analysis' has no attribute {name!r}")
