"""python -m analysis reduce|plot|report|paper|export|compare ...

reduce streams one or more catalogs into per-task histograms (ranks split the tasks of all
catalogs under mpirun and rank 0 merges them), pools the tasks of equal parameters (N, l, nu and
the friction law's keys) into one point whichever catalog holds them, computes per point the
merged densities and summary numbers with bootstrap intervals and writes a summary; its bins and
large-event magnitude default to the friction law's scale (Law.scales). The same trajectory (random
stream and parameters) in two catalogs is refused; so is an unfinished run (a *.partial
catalog, unfinished tasks) unless --partial is given. plot overlays the points of one or more
summaries; report prints a summary's numbers; paper sets the paper's claims beside them; export
writes a catalog's or a summary's tables; compare sets the points of catalogs of several friction
laws side by side (analysis/compare.py).

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
import os
import sys

from ensemble import checks, filekind
from ensemble.store.errors import CatalogError

from . import merge, summary
from .reduce import (CREEP_DURATION_BINS, CREEP_MU_BINS, LAYOUT, NUMBERS, SEIS_DISTANCE_BINS, SEIS_LONG, SEIS_NEAR,
                     SEIS_RING, SEIS_SHORT, SEIS_TIME_BINS, Options, bin_edges, parse_bins)

# errors that reduce's rank 0 finds before the work starts and every rank then raises alike
# (ensemble.run.abort.on_root), with their exit codes; any other error on any rank aborts them all
# (merge.MergeError is a ValueError: exit 2)
COLLECTIVE = {ValueError: 2, CatalogError: 1, summary.SummaryError: 1, OSError: 1}

# Every numeric option of every command (argparse dest -> its check), applied to the options a
# command has before it reads a file: argparse hands them over as text, so that "nan", "inf" and
# "1e400" reach one check that names the option (checks.UsageError, exit 2). Magnitudes are
# log10 of a float64 slip; a million bootstrap resamples or stretches per task is more than any
# interval needs (and what they allocate together is checked by _memory once the tasks are known).
MAGNITUDE = (-330.0, 310.0)
NUMERIC = {
    "mu_c": lambda v: checks.number("--mu-c", v, *MAGNITUDE),
    "b_cut": lambda v: checks.number("--b-cut", v, *MAGNITUDE),
    "mu_bins": lambda v: _bins("--mu-bins", v),
    "tnu_bins": lambda v: _bins("--tnu-bins", v),
    "creep_mu_bins": lambda v: _bins("--creep-mu-bins", v),
    "creep_duration_bins": lambda v: _bins("--creep-duration-bins", v),
    "seis_time_bins": lambda v: _bins("--seis-time-bins", v),
    "seis_distance_bins": lambda v: _bins("--seis-distance-bins", v),
    "seis_near": lambda v: checks.number("--seis-near", v, 0.0, 1e9),
    "seis_ring": lambda v: checks.number("--seis-ring", v, 0.0, 1e9),
    "seis_short": lambda v: checks.number("--seis-short", v, 0.0, 1e300),
    "seis_long": lambda v: checks.number("--seis-long", v, 0.0, 1e300),
    "window": lambda v: checks.count("--window", v, lo=0, hi=10 ** 9),
    "bootstrap": lambda v: checks.count("--bootstrap", v, lo=1, hi=10 ** 6),
    "level": lambda v: checks.number("--level", v, 0.0, 1.0, exclusive=True),
    "blocks": lambda v: checks.count("--blocks", v, lo=1, hi=10 ** 6),
    "seed": lambda v: checks.count("--seed", v, lo=0, hi=2 ** 63 - 1),   # stored as an HDF5 int64
    "n_large": lambda v: checks.count("--n-large", v, lo=2, hi=10 ** 9),
    "n_min": lambda v: checks.count("--n-min", v, lo=1, hi=10 ** 9),
    "region_span": lambda v: checks.number("--region-span", v, 0.0, 1e300, exclusive=True),
    "region_skip": lambda v: checks.number("--region-skip", v, 0.0, 1e300),
}


def _bins(option, text):
    parse_bins(text, option)   # lo:hi:n, finite, at most reduce.MAX_BINS bins; kept as text
    return text


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
    # the defaults of these four are the friction law's (model/laws: Law.scales), the aging law's
    # being the paper's axes; catalogs of several laws need them given
    r.add_argument("--mu-bins", help="magnitude bins lo:hi:n (default: the law's; aging 0:7:70)")
    r.add_argument("--tnu-bins", help="T*nu bins lo:hi:n (default: the law's; aging 0:2000:80)")
    r.add_argument("--creep-mu-bins", default=CREEP_MU_BINS,
                   help=f"bins lo:hi:n of the creep episodes' mu = log10(slip) (default {CREEP_MU_BINS}; "
                        "a negative lo after '=': --creep-mu-bins=-8:2:50)")
    r.add_argument("--creep-duration-bins", default=CREEP_DURATION_BINS,
                   help="bins lo:hi:n of the creep episodes' log10(duration nu), duration in units of the "
                        f"loading time 1/nu (default {CREEP_DURATION_BINS})")
    r.add_argument("--seis-time-bins", default=SEIS_TIME_BINS,
                   help="seismicity around mainshocks (mu >= mu_c): bins lo:hi:n of the time T*nu from a mainshock's "
                        f"onset, negative before it (default {SEIS_TIME_BINS}, for the aging law; a negative lo "
                        "after '=')")
    r.add_argument("--seis-distance-bins", default=SEIS_DISTANCE_BINS,
                   help=f"its bins lo:hi:n of the distance from the epicenter, blocks (default {SEIS_DISTANCE_BINS})")
    r.add_argument("--seis-near", default=SEIS_NEAR,
                   help=f"its epicentral neighbourhood: distance < this, blocks (default {SEIS_NEAR:g})")
    r.add_argument("--seis-ring", default=SEIS_RING,
                   help=f"its ring: from --seis-near to this, blocks (default {SEIS_RING:g})")
    r.add_argument("--seis-short", default=SEIS_SHORT,
                   help=f"its 'just before' and 'just after' the onset, T*nu (default {SEIS_SHORT:g})")
    r.add_argument("--seis-long", default=SEIS_LONG,
                   help=f"its 'some time before': from -this to --seis-short, T*nu (default {SEIS_LONG:g})")
    r.add_argument("--mu-c", help="large-event magnitude (default: the law's; aging 4)")
    r.add_argument("--window", default=10, help="epicenter window in blocks (default 10)")
    r.add_argument("--b-cut", help="magnitude cut of the GR b fit (default: the law's; aging 3)")
    r.add_argument("--bootstrap", default=1000, help="bootstrap resamples (default 1000)")
    r.add_argument("--level", default=0.95, help="interval coverage (default 0.95)")
    r.add_argument("--blocks", default=20,
                   help="stretches per task, resampled when a point has one seed (default 20)")
    r.add_argument("--seed", default=0,
                   help="seed of the bootstrap; a point's resamples are drawn from it and the "
                        "point's parameters (default 0)")
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
    pl.add_argument("--figure", choices=("magnitude", "recurrence", "creep", "seismicity"), required=True,
                    help="creep: the creep episodes' size and duration densities and the aseismic slip "
                         "fraction (points with creep episodes; an error if none has any); seismicity: the "
                         "rate of events around mainshocks by distance and time, one map per point")
    pl.add_argument("-o", "--output", required=True, help="FILE.png or FILE.pdf")
    pl.add_argument("--title", default=None)
    pl.add_argument("--force", action="store_true", help="overwrite an existing figure")
    rp = sub.add_parser("report", help="print the summary numbers as a table")
    rp.add_argument("summary")
    pa = sub.add_parser("paper", help="the paper's claims beside the numbers of one or more summaries, "
                                      "labelled full size or reduced (analysis/paper.py)")
    pa.add_argument("summaries", nargs="+", metavar="summary",
                    help="each claim reads the summary with the most of the points it needs (the first of equals)")
    from .export import FORMATS
    ex = sub.add_parser("export", help="catalog (events, tasks) or summary (curves, numbers, peaks, seismicity) -> "
                                       "tables for other tools (docs/running.md)")
    ex.add_argument("source", help="an event catalog or a reduction summary")
    ex.add_argument("--format", choices=sorted(FORMATS), default="csv", help="file format (default csv)")
    ex.add_argument("-o", "--output", required=True, help="directory of the tables (made if missing)")
    ex.add_argument("--force", action="store_true", help="overwrite tables already in the directory")
    ex.add_argument("--partial", action="store_true",
                    help="export an unfinished run as far as written (every table's header says so)")
    cp = sub.add_parser("compare", help="catalogs of several friction laws -> table and figures on a "
                                         "law-independent size axis (docs/laws.md)")
    cp.add_argument("catalogs", nargs="+", metavar="catalog")
    cp.add_argument("-o", "--output", required=True, help="directory of comparison.md, .json and the figures")
    cp.add_argument("--n-large", default=50, help="large event: at least this many blocks slip (default 50)")
    cp.add_argument("--n-min", default=1, help="smallest n of the power-law fit (default 1)")
    cp.add_argument("--window", default=10, help="epicenter window in blocks (default 10)")
    cp.add_argument("--bootstrap", default=1000, help="bootstrap resamples (default 1000)")
    cp.add_argument("--level", default=0.95, help="interval coverage (default 0.95)")
    cp.add_argument("--blocks", default=20, help="stretches per task when a point has fewer "
                                                 "than 10 seeds (default 20)")
    cp.add_argument("--seed", default=0, help="bootstrap seed (default 0)")
    cp.add_argument("--force", action="store_true", help="overwrite an existing comparison")
    return p


def _compare(args):
    from .compare import Options, check_output, compare, write
    check_numbers(args)
    opt = Options(args.n_large, args.n_min, args.window, args.bootstrap, args.level, args.blocks, args.seed)
    command = "python -m analysis compare " + " ".join(
        [str(c) for c in args.catalogs] + ["-o", args.output]
        + [f"--{k.replace('_', '-')} {v}" for k, v in opt.__dict__.items() if v != getattr(Options, k)])
    check_output(args.output, args.force, args.catalogs)   # before the work
    for path in write(compare(args.catalogs, opt), opt, args.output, command, force=args.force,
                      inputs=args.catalogs):
        print(f"wrote {path}")
    return 0


def _reduce(args):
    from mpi4py import MPI

    from ensemble.run.abort import run_guarded
    comm = MPI.COMM_WORLD
    return run_guarded(comm, lambda: _reduce_on(comm, args), COLLECTIVE)


def _default_output(catalogs):
    if len(catalogs) > 1:
        raise ValueError("reducing several catalogs into one summary: give its path with -o")
    name = str(catalogs[0])
    if name.endswith(".partial"):   # X.h5.partial -> X.partial.summary.h5, beside the final one's name
        return name.removesuffix(".partial").removesuffix(".h5") + ".partial.summary.h5"
    return name.removesuffix(".h5") + ".summary.h5"


SCALE_OPTIONS = ("mu_bins", "mu_c", "b_cut", "tnu_bins")


def _scales(args, inputs):
    """--mu-bins, --mu-c, --b-cut, --tnu-bins as given, else the catalogs' friction law's."""
    missing = [name for name in SCALE_OPTIONS if getattr(args, name) is None]
    if not missing:
        return {name: getattr(args, name) for name in SCALE_OPTIONS}
    from ensemble.model import laws
    names = sorted({merge.law_name(law) for law in inputs.tasks["law"]})
    for name in names:
        if name not in laws.LAWS:
            raise ValueError(f"friction law {name!r} is unknown to this version: give "
                             + ", ".join("--" + key.replace("_", "-") for key in missing))
    if len({laws.get(name).scales for name in names}) > 1:
        raise ValueError(f"the catalogs hold points of several friction laws ({', '.join(names)}), whose "
                         "magnitudes lie on different scales: give " + ", ".join(
                             "--" + name.replace("_", "-") for name in missing))
    law = laws.get(names[0]).scales
    return {name: getattr(args, name) if getattr(args, name) is not None else getattr(law, name)
            for name in SCALE_OPTIONS}


def check_summary_output(out, catalogs, force):
    """The summary's path (checks.output: before any file is read); --force replaces a summary,
    never anything else (a catalog, a config)."""
    checks.output(out, inputs=catalogs, force=force, what="summary")
    checks.output(f"{out}.partial", inputs=catalogs, force=True, what="summary")   # written first, then renamed
    if os.path.exists(out) and filekind.identify(out)[0] != "summary":
        raise checks.UsageError(f"{out} {filekind.describe(out)}; --force replaces only a reduction summary")
    return out


def _memory(opt, n_tasks):
    """Refuse options whose arrays this machine cannot hold: rank 0 gathers every task's
    (stretches, bins) counts and stacks them for the summary; a point's bootstrap keeps, per resample, its picks
    of units (at most tasks x blocks), its numbers and its curves: R(mu) (n_mu bins), three arrays on the T nu bins
    (the curves of all recurrences and of the interior ones, and the recurrence peaks' resampled counts: 3 x n_tnu)
    and the two creep curves (n_creep bins)."""
    n_mu, n_tnu = len(opt.mu_edges) - 1, len(opt.tnu_edges) - 1
    n_creep = len(opt.creep_mu_edges) + len(opt.creep_duration_edges) - 2
    edges = bin_edges(opt)
    per_task = opt.blocks * sum(LAYOUT.width(name, edges) for name in LAYOUT.tables)
    resamples = opt.bootstrap * (n_mu + 3 * n_tnu + n_creep + len(NUMBERS) + n_tasks * opt.blocks)
    checks.memory(f"--blocks {opt.blocks}, --bootstrap {opt.bootstrap} and {n_mu} + 3 x {n_tnu} + {n_creep} bins "
                  f"over {n_tasks} tasks", 8 * (2 * n_tasks * per_task + resamples))


def _prepare(args):
    """Options, output path, and the catalogs' task table (merge.Inputs); every check before the work."""
    check_numbers(args)                      # every option before any file is read
    out = check_summary_output(args.output or _default_output(args.catalogs), args.catalogs, args.force)
    for given in ("region_span", "region_skip"):
        if getattr(args, given) is not None and not args.region:
            raise checks.UsageError(f"--{given.replace('_', '-')} sets the window of a regional reduction: "
                                    f"give --region too")
    # (checks each file's kind first)
    inputs = merge.read(args.catalogs, allow_partial=args.partial, region=args.region, span=args.region_span,
                        skip=args.region_skip or 0.0)
    scale = _scales(args, inputs)
    opt = Options(parse_bins(scale["mu_bins"], "--mu-bins"), parse_bins(scale["tnu_bins"], "--tnu-bins"),
                  scale["mu_c"], args.window, scale["b_cut"], args.bootstrap, args.level, args.blocks, args.seed,
                  creep_mu_edges=parse_bins(args.creep_mu_bins, "--creep-mu-bins"),
                  creep_duration_edges=parse_bins(args.creep_duration_bins, "--creep-duration-bins"),
                  seis_time_edges=parse_bins(args.seis_time_bins, "--seis-time-bins"),
                  seis_distance_edges=parse_bins(args.seis_distance_bins, "--seis-distance-bins"),
                  seis_near=args.seis_near, seis_ring=args.seis_ring, seis_short=args.seis_short,
                  seis_long=args.seis_long)
    _memory(opt, len(inputs.tasks["point"]))
    return opt, out, inputs


def _check_counts(inputs, per_task):
    """Every rank reduced as many rows as rank 0 read from the commit rows (a run still writing
    the catalog could have committed more in between)."""
    for g, h in per_task.items():
        if h.rows != int(inputs.tasks["events_written"][g]):
            path = inputs.paths[inputs.tasks["catalog"][g]]
            raise CatalogError(f"{path}: task {inputs.tasks['catalog_task'][g]}: its event count "
                               "changed while it was reduced (is a run still writing it?)")


def _reduce_on(comm, args):
    from ensemble.run.abort import abort_on_error, on_root

    from .reduce import MIN_UNITS, point_statistics, unreliable
    rank, size = comm.Get_rank(), comm.Get_size()
    opt, out, inputs = on_root(comm, lambda: _prepare(args), tuple(COLLECTIVE))
    mine = [g for g in range(len(inputs.tasks["point"])) if g % size == rank]
    with abort_on_error(comm):   # rank 0 waits in gather for every other rank's part
        parts = comm.gather(merge.reduce_share(inputs, mine, opt), root=0)
    if rank != 0:
        return 0
    per_task = {k: h for part in parts for k, h in part.items()}
    _check_counts(inputs, per_task)
    points = []
    for params, ids in inputs.points:
        result = point_statistics(per_task, ids, opt, merge.bootstrap_rng(opt.seed, params),
                                  whole="faults" if args.region else "seeds")
        result["params"] = params
        points.append(result)
    for line in inputs.warnings:
        print(f"warning: {line}", file=sys.stderr)
    summary.write(out, inputs, per_task, points, opt, force=args.force)
    if inputs.partial:
        print(inputs.partial)
    for i, p in enumerate(points):
        why = unreliable(p["units"], p["method"])
        if why:
            what = (f"region {i} ({p['params']['region']})" if args.region else f"point {i} ({p['params']['law']}: "
                    f"{', '.join(f'{k} = {v:g}' for k, v in p['params'].items() if k != 'law' and v == v)})")
            print(f"warning: {what}: {why}", file=sys.stderr)
    methods = sorted({p["method"] for p in points})
    print(f"wrote {out}: {len(points)} {'regions' if args.region else 'parameter points'}, {len(per_task)} tasks"
          + (f" from {len(inputs.paths)} catalogs" if len(inputs.paths) > 1 else "")
          + "; intervals from "
          f"{opt.bootstrap} bootstrap resamples over {' / '.join(methods)}"
          + (f" (fewer than {MIN_UNITS} seeds per point: block bootstrap over stretches of each trajectory)"
             if "blocks" in methods else ""))
    return 0


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


def _export(args):
    from .export import write
    for path in write(args.source, args.output, args.format, force=args.force, partial=args.partial):
        print(f"wrote {path}")
    return 0


def main(argv=None):
    args = _parser().parse_args(argv)
    try:
        return {"reduce": _reduce, "plot": _plot, "report": _report, "export": _export,
                "compare": _compare, "paper": _paper}[args.command](args)
    except BrokenPipeError:
        raise   # the reader of stdout went away: not a file error; __main__ ends quietly
    except (CatalogError, summary.SummaryError, ValueError, OSError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2 if isinstance(err, ValueError) else 1
