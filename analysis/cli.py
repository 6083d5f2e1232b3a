"""python -m analysis reduce|plot|report|paper|successors|export|compare|history ...

reduce streams one or more catalogs into per-task histograms (ranks split the tasks of all
catalogs under mpirun and rank 0 merges them), pools the tasks of equal parameters (N, l, nu and
the friction law's keys) into one point whichever catalog holds them, computes per point the
merged densities and summary numbers with bootstrap intervals and writes a summary; its bins and
large-event magnitude default to the friction law's scale (Law.scales). The same trajectory (random
stream and parameters) in two catalogs is refused; so is an unfinished run (a *.partial
catalog, unfinished tasks) unless --partial is given. plot overlays the points of one or more
summaries; report prints a summary's numbers; paper sets the paper's claims beside them; successors
sets the claims of its authors' three later papers beside them (analysis/successors.py); export
writes a catalog's or a summary's tables; compare sets the points of catalogs of several friction
laws side by side (analysis/compare.py); history draws an event history a run kept (analysis/history.py).

Every numeric option is checked before any file is read (NUMERIC below: finite, in its range,
sizes this machine can hold), and every output path before any work (ensemble/checks.py: not
UTF-8, one of the inputs, a missing or read-only folder, an existing file without --force; reduce's
--force replaces only a reduction summary).

Exit codes: 0 done, 1 file error (missing, damaged or of the wrong kind: a summary or a
config given for a catalog, an unfinished run without --partial, ...), 2 bad options or output
paths (an existing output without --force, as in `python -m ensemble run`; and the same
trajectory given twice). Under mpirun an error on one rank aborts all.
"""
import argparse
import sys

from ensemble import checks
from ensemble.store.errors import CatalogError

from . import options, summary
from .reduce import LAYOUT

# Every numeric option of every command (argparse dest -> its check), applied to the options a
# command has before it reads a file: argparse hands them over as text, so that "nan", "inf" and
# "1e400" reach one check that names the option (checks.UsageError, exit 2). The reduction's options
# are declared by the statistics (analysis/options.py, each with its range); a regional reduction's
# window is this command's own.
NUMERIC = {
    **{name: (lambda v, o=o: options.check(o, v)) for name, o in options.every_option().items()},
    "region_span": lambda v: checks.number("--region-span", v, 0.0, 1e300, exclusive=True),
    "region_skip": lambda v: checks.number("--region-skip", v, 0.0, 1e300),
    "task": lambda v: checks.count("--task", v, 0),
    "index": lambda v: checks.count("--index", v, 0),
}


def check_numbers(args):
    """Every numeric option of the command given (not None) replaced by its checked value."""
    for dest, check in NUMERIC.items():
        if getattr(args, dest, None) is not None:
            setattr(args, dest, check(getattr(args, dest)))
    return args


def _parser():
    p = argparse.ArgumentParser(prog="python -m analysis", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("reduce", help="catalog(s) -> summary HDF5")
    r.add_argument("catalogs", nargs="+", metavar="catalog",
                   help="event catalog(s); the tasks of equal parameters pool into one point")
    r.add_argument("-o", "--output", help="summary path (default with one catalog: CATALOG with "
                                          ".summary.h5; required with several)")
    r.add_argument("--partial", action="store_true",
                   help="reduce unfinished runs as far as written (the summary and report say so)")
    # the options of the statistics and the engine (analysis/options.py); a LAW default is the friction law's
    # (model/laws: Law.scales, the aging law's being the paper's axes): catalogs of several laws need them given
    options.add_arguments(r, "reduce")
    r.add_argument("--region", action="store_true",
                   help="pool each population's faults into its region over a common window of loading, each fault "
                        "in proportion to its event rate; intervals resample faults (analysis/region.py)")
    r.add_argument("--region-span", help="the window's span, T*nu (default: the shortest fault's)")
    r.add_argument("--region-skip", help="start every fault's window this far after its first onset, T*nu (default 0)")
    r.add_argument("--force", action="store_true", help="overwrite an existing summary")
    pl = sub.add_parser("plot", help="summaries -> figure (their points overlaid)")
    pl.add_argument("summaries", nargs="+", metavar="summary",
                    help="one or more summaries: their points in one figure, labelled by the "
                         "parameters that differ between them")
    figures = [f for st in LAYOUT.statistics for f in st.figures]     # each statistic's (statistics.Figure)
    pl.add_argument("--figure", choices=[f.name for f in figures], required=True,
                    help="; ".join(f"{f.name}: {f.help}" for f in figures))
    pl.add_argument("-o", "--output", required=True, help="FILE.png or FILE.pdf")
    pl.add_argument("--title", default=None)
    pl.add_argument("--force", action="store_true", help="overwrite an existing figure")
    rp = sub.add_parser("report", help="print the summary numbers as a table")
    rp.add_argument("summary")
    pa = sub.add_parser("paper", help="the paper's claims beside the numbers of one or more summaries, "
                                      "labelled full size or reduced (analysis/paper.py)")
    pa.add_argument("summaries", nargs="+", metavar="summary",
                    help="each claim reads the summary with the most of the points it needs (the first of equals)")
    su = sub.add_parser("successors", help="the claims of the seed's authors' later papers (rupture statistics, "
                                           "nucleation, slow slip) beside the numbers of summaries "
                                           "(analysis/successors.py)")
    su.add_argument("summaries", nargs="*", metavar="summary",
                    help="default: the committed summaries of docs/successors; each claim reads the summary with the "
                         "most of the points it needs, the slow-slip claims every point")
    from .export import FORMATS
    ex = sub.add_parser("export", help="catalog (events, tasks) or summary (curves, numbers, peaks, seismicity) -> "
                                       "tables for other tools (docs/running.md)")
    ex.add_argument("source", help="an event catalog or a reduction summary")
    ex.add_argument("--format", choices=sorted(FORMATS), default="csv", help="file format (default csv)")
    ex.add_argument("-o", "--output", required=True, help="directory of the tables (made if missing)")
    ex.add_argument("--force", action="store_true", help="overwrite tables already in the directory")
    ex.add_argument("--partial", action="store_true",
                    help="export an unfinished run as far as written (every table's header says so)")
    hi = sub.add_parser("history", help="an event history of a catalog (output.history) -> figure of its velocity "
                                         "in space and time (analysis/history.py)")
    hi.add_argument("catalog")
    hi.add_argument("-o", "--output", required=True, help="FILE.png or FILE.pdf")
    hi.add_argument("--task", help="the task (default: the first with a history)")
    hi.add_argument("--index", default="0", help="its history number (default 0: its first)")
    hi.add_argument("--force", action="store_true", help="overwrite an existing figure")
    cp = sub.add_parser("compare", help="catalogs of several friction laws -> table and figures on a "
                                         "law-independent size axis (docs/laws.md)")
    cp.add_argument("catalogs", nargs="+", metavar="catalog")
    cp.add_argument("-o", "--output", required=True, help="directory of comparison.md, .json and the figures")
    options.add_arguments(cp, "compare")
    cp.add_argument("--force", action="store_true", help="overwrite an existing comparison")
    return p


def _compare(args):
    from .compare import check_output, compare, write
    check_numbers(args)
    opt = options.make("compare", **options.given(args, "compare"))
    command = "python -m analysis compare " + " ".join(
        [str(c) for c in args.catalogs] + ["-o", args.output]
        + [f"{options.declared('compare')[k].flag} {v}" for k, v in opt.changed().items()])
    check_output(args.output, args.force, args.catalogs)   # before the work
    for path in write(compare(args.catalogs, opt), opt, args.output, command, force=args.force,
                      inputs=args.catalogs):
        print(f"wrote {path}")
    return 0


def _reduce(args):
    from mpi4py import MPI

    from ensemble.run.abort import run_guarded

    from .reduction import COLLECTIVE, Request, reduce_on
    check_numbers(args)                      # every option before any file is read
    request = Request(args.catalogs, args.output, partial=args.partial, force=args.force, region=args.region,
                      region_span=args.region_span, region_skip=args.region_skip,
                      given=options.given(args, "reduce"))
    comm = MPI.COMM_WORLD
    return run_guarded(comm, lambda: reduce_on(comm, request), COLLECTIVE)


def _plot(args):
    from .plot import plot
    checks.output(args.output, inputs=args.summaries, force=args.force, what="figure")   # before the work
    plot([summary.read(path) for path in args.summaries], args.figure, args.output, args.title,
         names=args.summaries)
    print(f"wrote {args.output}")
    return 0


def _report(args):
    from .report import table
    print(table(summary.read(args.summary)))
    return 0


def _paper(args):
    from .paper import text
    print(text([summary.read(path) for path in args.summaries], args.summaries))
    return 0


def _successors(args):
    from .successors import committed, text
    paths = args.summaries or committed()
    if not paths:
        raise summary.SummaryError("no summary given, and no committed one (docs/successors: a source checkout's)")
    names = args.summaries or [f"docs/successors/{p.name}" for p in paths]     # as from the checkout's root
    print(text([summary.read(path) for path in paths], names))
    return 0


def _history(args):
    from .history import draw
    check_numbers(args)
    checks.output(args.output, inputs=[args.catalog], force=args.force, what="figure")   # before the work
    print(f"wrote {args.output}: {draw(args.catalog, args.output, args.task, args.index)}")
    return 0


def _export(args):
    from .export import write
    for path in write(args.source, args.output, args.format, force=args.force, partial=args.partial):
        print(f"wrote {path}")
    return 0


def main(argv=None):
    args = _parser().parse_args(argv)
    try:
        return {"reduce": _reduce, "plot": _plot, "report": _report, "export": _export,
                "compare": _compare, "paper": _paper, "successors": _successors,
                "history": _history}[args.command](args)
    except BrokenPipeError:
        raise   # the reader of stdout went away: not a file error; __main__ ends quietly
    except (CatalogError, summary.SummaryError, ValueError, OSError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2 if isinstance(err, ValueError) else 1
