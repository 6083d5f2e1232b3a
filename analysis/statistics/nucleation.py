"""The nucleation of large events (Ueda, Morimoto, Kakui, Yamamoto & Kawamura, 2015, arXiv:1407.2693: an initial
phase and an acceleration phase before the high-speed rupture, two nucleation lengths, hardly dependent on the size
of the ensuing mainshock).

Per inertial event the kernel records (ensemble/model/workspace.py, D_N_ONSET ...; the catalog's columns):
n_onset, the blocks sliding at its onset (1: a block reached its threshold; more: a creeping cluster handed over
to inertia at the end of a quasi-static phase, ensemble/model/creep.py); t_spread, the time from the onset until
a block beyond those starts to slide (the initial phase, in which the sliding zone does not grow; NaN if it never
does); n_widest, the most blocks sliding at once, and t_widest, the time from the onset until it first was that
wide. In a large event at b = 20 the zone grows crack-like after the initial phase, everything behind its fronts
sliding, until the epicenter stops and the rupture goes on as two pulses of a few blocks each
(docs/successors/history_b20.png): n_widest is then the nucleation's zone at its widest (the second nucleation
length L_c) and t_widest - t_spread the acceleration phase. Each time is that of the end of a step. These
definitions are this code's: the paper's text was not at hand (docs/successors.md).

The numbers, over the large events (mu >= mu_c) that carry the columns (catalogs from bk-catalog-7): the mean
onset zone L_sc = n_onset, the mean initial phase t_spread (of those whose zone grew) and the share whose zone
grew, and the means of n_widest (L_c) and t_widest; the curve: the mean n_widest per mu bin (its dependence on
the size of the event).
"""
import numpy as np

from . import Curve, Number, Statistic, Table

NAME = "nucleation"
COLUMNS = ("n_known", "sum_onset", "n_spread", "sum_spread", "sum_n_widest", "sum_t_widest")


def feed(acc, rows):
    if rows.ev is None:
        return
    ev, opt = rows.ev, rows.opt
    has = ev["n_onset"] > 0       # (0: a catalog before bk-catalog-7)
    known = has & (ev["mu"] >= opt.mu_c)
    spread = known & ~np.isnan(ev["t_spread"])
    for count, total, mask, values in (("n_known", "sum_onset", known, ev["n_onset"]),
                                       ("n_spread", "sum_spread", spread, ev["t_spread"])):
        acc.add(NAME, count, rows.block[mask], 1)
        acc.add(NAME, total, rows.block[mask], values[mask])
    for total, values in (("sum_n_widest", ev["n_widest"]), ("sum_t_widest", ev["t_widest"])):
        acc.add(NAME, total, rows.block[known], values[known])
    acc.count("nuc_n", rows.block[has], ev["mu"][has], opt.mu_edges)
    acc.count("nuc_len", rows.block[has], ev["mu"][has], opt.mu_edges, weights=ev["n_widest"][has])


def estimate(u, opt):
    c = {name: u.column(NAME, name) for name in COLUMNS}
    with np.errstate(invalid="ignore", divide="ignore"):
        return [c["sum_onset"] / c["n_known"], c["sum_spread"] / c["n_spread"], c["n_spread"] / c["n_known"],
                c["sum_n_widest"] / c["n_known"], c["sum_t_widest"] / c["n_known"]]


def nucleation_length(u, opt, edges):
    """Mean n_widest of the events in each mu bin (NaN where none)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return u["nuc_len"] / u["nuc_n"]


STATISTIC = Statistic(
    NAME, 95,
    tables=(Table(NAME, "count or sum", "large events with the nucleation columns, and their sums: onset zones, "
                                        "initial phases (of those whose zone grew), widest zones and their times",
                  columns=COLUMNS),
            Table("nuc_n", "count", "inertial events with the nucleation columns per mu bin, per task and stretch",
                  bins="mu"),
            Table("nuc_len", "count", "their summed widest zones n_widest per mu bin, per task and stretch",
                  bins="mu", weights=True)),
    numbers=(Number("L_sc", "count", "mean blocks sliding at the onset of a large event (more than 1: handed over "
                                     "from creep)", "L_sc (onset zone)"),
             Number("t_initial", "model time", "mean time from a large event's onset until its sliding zone grows "
                                               "(of those whose zone grew)", "initial phase"),
             Number("spread_share", "1", "share of the large events whose sliding zone grew beyond the onset's",
                    "zone grew"),
             Number("L_c", "count", "mean of the most blocks sliding at once in a large event", "L_c (widest zone)"),
             Number("t_nucleation", "model time", "mean time from a large event's onset until its zone was widest",
                    "to widest zone")),
    curves=(Curve("nucleation_length", "nuc_len", (), "mu", "the events of each magnitude", "count",
                  values=nucleation_length),),
    feed=feed, estimate=estimate, uses_tables=(), uses_options=("mu_bins", "mu_c"))
