"""The magnitude distribution R(mu) of the inertial events, and the share of large ones (mu >= mu_c)."""
import numpy as np

from . import LAW, Criterion, Curve, Number, Option, Statistic, Table

MAGNITUDE = (-330.0, 310.0)    # log10 of a float64 slip: every magnitude lies here


def feed(acc, rows):
    if rows.ev is None:
        return
    mu = rows.ev["mu"]
    acc.count("mu", rows.block, mu, rows.opt.mu_edges)
    acc.add("numbers", "n_events", rows.block, 1)
    acc.add("numbers", "n_large", rows.block, mu >= rows.opt.mu_c)


def estimate(u, opt):
    n, large = u.column("numbers", "n_events"), u.column("numbers", "n_large")
    with np.errstate(invalid="ignore", divide="ignore"):
        return [n, large, large / n]


STATISTIC = Statistic(
    "magnitude", 10,
    tables=(Table("mu", "count", "events per magnitude bin, per task and stretch", bins="mu"),
            Table("numbers", "count or sum", "counts and sums of the inertial events",
                  columns=("n_events", "n_large"))),
    numbers=(Number("n_events", "count",
                    "inertial events (/events/kind 0: creep episodes are in none of these numbers)", "events"),
             Number("n_large", "count", "large events (mu >= mu_c)", "large"),
             Number("fraction_large", "1", "fraction of the events with mu >= mu_c", "frac(mu>=mu_c)")),
    curves=(Curve("mu", "mu", ("numbers", "n_events"), "mu", "all events", "1/mu"),),
    feed=feed, estimate=estimate, sets=("reduce", "compare"),
    options=(Option("mu_bins", "bins", LAW, "log10 model length", "magnitude bins lo:hi:n",
                    # the comparison's laws have magnitudes on different scales: one axis spans them
                    defaults={"compare": "-4:7:110"}),
             Option("mu_c", "number", LAW, "log10 model length", "large-event magnitude", *MAGNITUDE,
                    # only the share of large events reads it there, which the comparison does not report
                    defaults={"compare": 4.0})),
    criteria=(Criterion("mu", "mu", "mu_c"),))
