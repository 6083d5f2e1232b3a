"""python -m analysis reduce|plot|report ...

reduce streams a catalog into per-task histograms (ranks split the tasks under
mpirun and rank 0 merges them), then computes per parameter point the merged
densities and summary numbers with bootstrap intervals and writes a summary.

Exit codes: 0 done, 1 file error (missing, damaged or of the wrong kind: a summary or a
config given for a catalog, ...), 2 bad options. Under mpirun an error on one rank aborts all.
"""
import argparse
import os
import sys

import numpy as np

from ensemble import filekind
from ensemble.catalog import CatalogError

from . import summary
from .reduce import Options, parse_bins

# errors that reduce's rank 0 finds before the work starts and every rank then raises alike
# (ensemble.abort.on_root), with their exit codes; any other error on any rank aborts them all
COLLECTIVE = {ValueError: 2, CatalogError: 1, summary.SummaryError: 1, OSError: 1}


def _parser():
    p = argparse.ArgumentParser(prog="python -m analysis", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("reduce", help="catalog -> summary HDF5")
    r.add_argument("catalog")
    r.add_argument("-o", "--output", help="summary path (default: CATALOG with .summary.h5)")
    r.add_argument("--mu-bins", default="0:7:70", help="magnitude bins lo:hi:n (default 0:7:70)")
    r.add_argument("--tnu-bins", default="0:2000:80", help="T*nu bins lo:hi:n (default 0:2000:80)")
    r.add_argument("--mu-c", type=float, default=4.0, help="large-event magnitude (default 4)")
    r.add_argument("--window", type=int, default=10, help="epicenter window in blocks (default 10)")
    r.add_argument("--b-cut", type=float, default=3.0, help="magnitude cut of the b-value fit (default 3)")
    r.add_argument("--bootstrap", type=int, default=1000, help="bootstrap resamples (default 1000)")
    r.add_argument("--level", type=float, default=0.95, help="interval coverage (default 0.95)")
    r.add_argument("--blocks", type=int, default=20,
                   help="stretches per task, resampled when a point has one seed (default 20)")
    r.add_argument("--seed", type=int, default=0, help="seed of the bootstrap (default 0)")
    r.add_argument("--force", action="store_true", help="overwrite an existing summary")
    pl = sub.add_parser("plot", help="summary -> figure")
    pl.add_argument("summary")
    pl.add_argument("--figure", choices=("magnitude", "recurrence"), required=True)
    pl.add_argument("-o", "--output", required=True, help="FILE.png or FILE.pdf")
    pl.add_argument("--title", default=None)
    rp = sub.add_parser("report", help="print the summary numbers as a table")
    rp.add_argument("summary")
    from .export import FORMATS
    ex = sub.add_parser("export", help="catalog (events, tasks) or summary (curves, numbers, peaks) -> "
                                       "tables for other tools (docs/running.md)")
    ex.add_argument("source", help="an event catalog or a reduction summary")
    ex.add_argument("--format", choices=sorted(FORMATS), default="csv", help="file format (default csv)")
    ex.add_argument("-o", "--output", required=True, help="directory of the tables (made if missing)")
    ex.add_argument("--force", action="store_true", help="overwrite tables already in the directory")
    return p


def _reduce(args):
    from mpi4py import MPI

    from ensemble.abort import run_guarded
    comm = MPI.COMM_WORLD
    return run_guarded(comm, lambda: _reduce_on(comm, args), COLLECTIVE)


def _prepare(args):
    """Options, output path, and the catalog's task table; every check before the work."""
    from ensemble import catalog
    opt = Options(parse_bins(args.mu_bins), parse_bins(args.tnu_bins), args.mu_c, args.window,
                  args.b_cut, args.bootstrap, args.level, args.blocks, args.seed)
    if not (0 < opt.level < 1) or opt.bootstrap < 1 or opt.blocks < 1 or opt.window < 0:
        raise ValueError("--level must be in (0, 1); --bootstrap, --blocks >= 1; --window >= 0")
    out = args.output or str(args.catalog).removesuffix(".h5") + ".summary.h5"
    filekind.require(args.catalog, "catalog", CatalogError)
    if os.path.exists(out):
        # checked now, not after the work; and --force replaces a summary, never anything else
        if not args.force:
            raise summary.SummaryError(f"{out}: summary exists (use --force to overwrite it)")
        if os.path.samefile(out, args.catalog) or filekind.identify(out)[0] != "summary":
            raise summary.SummaryError(f"{out} {filekind.describe(out)}; --force replaces only "
                                       "a reduction summary")
    with filekind.reading(args.catalog, "the event catalog", CatalogError):
        _, tasks, attrs = catalog.read_tasks(args.catalog)
    return opt, out, tasks, attrs


def _reduce_on(comm, args):
    from ensemble.abort import abort_on_error, on_root

    from .reduce import MIN_UNITS, PARAMS, point_statistics, reduce_tasks
    rank, size = comm.Get_rank(), comm.Get_size()
    opt, out, tasks, attrs = on_root(comm, lambda: _prepare(args), tuple(COLLECTIVE))
    mine = [k for k in range(len(tasks["point"])) if k % size == rank]
    with abort_on_error(comm):   # rank 0 waits in gather for every other rank's part
        parts = comm.gather(reduce_tasks(args.catalog, mine, opt), root=0)
    if rank != 0:
        return 0
    per_task = {k: h for part in parts for k, h in part.items()}
    points = []
    for point in np.unique(tasks["point"]):
        ids = [int(k) for k in np.flatnonzero(tasks["point"] == point)]
        rng = np.random.default_rng(np.random.SeedSequence(opt.seed, spawn_key=(int(point),)))
        result = point_statistics(per_task, ids, len(ids), opt, rng)
        result["params"] = {name: tasks[name][ids[0]] for name in PARAMS}
        points.append(result)
    summary.write(out, args.catalog, attrs, tasks, per_task, points, opt, force=args.force)
    for i, p in enumerate(points):
        if p["units"] < MIN_UNITS:
            print(f"warning: point {i} ({', '.join(f'{k} = {v:g}' for k, v in p['params'].items())}): "
                  f"intervals from {p['units']} {p['method']} are unreliable; at least {MIN_UNITS} are "
                  f"needed", file=sys.stderr)
    methods = sorted({p["method"] for p in points})
    print(f"wrote {out}: {len(points)} parameter points, {len(per_task)} tasks; intervals from "
          f"{opt.bootstrap} bootstrap resamples over {' / '.join(methods)}"
          + (" (one seed per point: block bootstrap over stretches of the trajectory)"
             if "blocks" in methods else ""))
    return 0


def _plot(args):
    from .plot import plot
    plot(summary.read(args.summary), args.figure, args.output, args.title)
    print(f"wrote {args.output}")
    return 0


def _report(args):
    from .report import table
    print(table(summary.read(args.summary)))
    return 0


def _export(args):
    from .export import write
    for path in write(args.source, args.output, args.format, force=args.force):
        print(f"wrote {path}")
    return 0


def main(argv=None):
    args = _parser().parse_args(argv)
    try:
        return {"reduce": _reduce, "plot": _plot, "report": _report, "export": _export}[args.command](args)
    except BrokenPipeError:
        raise   # the reader of stdout went away: not a file error; __main__ ends quietly
    except (CatalogError, summary.SummaryError, ValueError, OSError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2 if isinstance(err, ValueError) else 1
