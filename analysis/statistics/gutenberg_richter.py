"""The Gutenberg-Richter exponent of the inertial events above mu = b_cut (Aki's estimator), its standard
error, and the Kolmogorov-Smirnov distance of the magnitudes from the fitted law."""
from .. import stats
from . import LAW, Number, Option, Statistic, Table
from .magnitude import MAGNITUDE


def feed(acc, rows):
    if rows.ev is None:
        return
    mu = rows.ev["mu"]
    gr = mu >= rows.opt.b_cut
    acc.add("numbers", "n_gr", rows.block[gr], 1)
    acc.add("numbers", "sum_mu_gr", rows.block[gr], mu[gr])
    acc.add("numbers", "sum_mu2_gr", rows.block[gr], mu[gr] ** 2)


def estimate(u, opt):
    n, s1, s2 = (u.column("numbers", c) for c in ("n_gr", "sum_mu_gr", "sum_mu2_gr"))
    b = stats.gr_b(n, s1, opt.b_cut)
    return [b, stats.gr_b_standard_error(n, s1, s2, opt.b_cut),
            stats.gr_ks_distance(u["mu"], opt.mu_edges, opt.b_cut, b)]


STATISTIC = Statistic(
    "gutenberg_richter", 30,
    tables=(Table("numbers", "count or sum", "counts and sums of the magnitudes above b_cut",
                  columns=("n_gr", "sum_mu_gr", "sum_mu2_gr")),),
    numbers=(Number("gr_b", "1", "Aki's maximum-likelihood Gutenberg-Richter b (not the model's b) above mu = b_cut",
                    "GR b"),
             Number("gr_b_se", "1",
                    "Shi & Bolt standard error of gr_b (assumes independent events; trust the interval)",
                    "GR b std. error"),
             Number("ks_gr", "1", "Kolmogorov-Smirnov distance of the binned mu >= b_cut from the fitted GR law",
                    "KS to GR")),
    feed=feed, estimate=estimate, uses_options=("mu_bins",), uses_tables=("mu",),
    options=(Option("b_cut", "number", LAW, "log10 model length", "magnitude cut of the GR b fit", *MAGNITUDE),))
