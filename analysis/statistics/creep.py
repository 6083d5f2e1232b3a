"""The slow side: the creep episodes (/events/kind 1, below the block stiffness), their size and duration
densities, their share of the rows, the share taken over by an inertial event, and the aseismic slip fraction."""
import numpy as np

from ensemble.store import schema

from . import Curve, Number, Option, Statistic, Table, holds, number_lines, report_line


def feed(acc, rows):
    if rows.ev is not None:
        acc.add("creep", "sum_slip_events", rows.block, rows.ev["slip"])
    if rows.creep_block is None:
        return
    part, creep, block = rows.part, rows.creep, rows.creep_block
    with np.errstate(divide="ignore"):      # a duration of 0 is out of every bin (still counted)
        log_duration = np.log10(part["duration"][creep] * rows.nu)
    acc.count("creep_mu", block, part["mu"][creep], rows.opt.creep_mu_edges)
    acc.count("creep_duration", block, log_duration, rows.opt.creep_duration_edges)
    acc.add("creep", "n_creep", block, 1)
    acc.add("creep", "n_creep_taken_over", block, part["ending"][creep] == schema.ENDING_TAKEN_OVER)
    acc.add("creep", "sum_slip_creep", block, part["slip"][creep])


def estimate(u, opt):
    n, taken, slow, fast = (u.column("creep", c) for c in ("n_creep", "n_creep_taken_over", "sum_slip_creep",
                                                          "sum_slip_events"))
    with np.errstate(invalid="ignore", divide="ignore"):
        return [n, n / (n + u.column("numbers", "n_events")), taken / n, slow / (slow + fast)]


def creeping(s):
    """(points,) bool: the points of summary `s` (as read) with creep episodes (none in a summary without them)."""
    if not holds(s, STATISTIC):
        return np.zeros(len(s["points/N"]), dtype=bool)
    return s["points/numbers/n_creep"][:, 0] > 0


def report(s, i):
    """Point i's slow side: its numbers with intervals, one line saying it has no creep episodes, or nothing for a
    summary that did not reduce them (format 2)."""
    if not holds(s, STATISTIC):
        return []
    if not creeping(s)[i]:
        return [report_line("creep episodes", "none")]
    return number_lines(STATISTIC, s, i)


STATISTIC = Statistic(
    "creep", 40,
    tables=(Table("creep_mu", "count",
                  "creep episodes per mu bin, per task and stretch (of the inertial events before them)",
                  bins="creep_mu"),
            Table("creep_duration", "count", "creep episodes per log10(duration nu) bin, per task and stretch",
                  bins="creep_duration"),
            Table("creep", "count or sum",
                  "counts and sums of the slow side (sum_slip_events: the inertial events' slip)",
                  columns=("n_creep", "n_creep_taken_over", "sum_slip_creep", "sum_slip_events"))),
    numbers=(Number("n_creep", "count", "creep episodes (/events/kind 1, below the block stiffness 1 + 2 l^2)",
                    "creep episodes"),
             Number("creep_share", "1", "share of the rows that are creep episodes: n_creep / (n_creep + n_events)",
                    "creep share (rows)"),
             Number("taken_over_share", "1", "share of the creep episodes taken over by an inertial event "
                                             "(/events/ending 2); NaN without creep episodes", "taken over"),
             Number("aseismic_fraction", "1", "aseismic slip fraction (1 - seismic coupling): the slip of the creep "
                                              "episodes over all slip (creep episodes and inertial events) after the "
                                              "transient", "aseismic fraction")),
    curves=(Curve("creep_mu", "creep_mu", ("creep", "n_creep"), "mu",
                  "the creep episodes (/events/kind 1; mu = log10 of the slip creep released)", "1/mu"),
            Curve("creep_duration", "creep_duration", ("creep", "n_creep"), "log10(duration nu)",
                  "the creep episodes (duration in units of the loading time 1/nu)", "1/log10 unit")),
    feed=feed, estimate=estimate, uses_tables=("numbers",), report=report,
    # the default bins: measured at N = 100, b = 8..18.5 (aging law), creep slips reach mu = -11 and durations
    # 10^-6.4 / nu
    options=(Option("creep_mu_bins", "bins", "-12:3:75", "log10 model length",
                    "bins lo:hi:n of the creep episodes' mu = log10(slip) (a negative lo after '=': "
                    "--creep-mu-bins=-8:2:50)"),
             Option("creep_duration_bins", "bins", "-7:3:50", "log10(duration nu)",
                    "bins lo:hi:n of the creep episodes' log10(duration nu), duration in units of the loading "
                    "time 1/nu")))
