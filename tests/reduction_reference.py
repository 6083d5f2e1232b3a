"""A plain, independent recomputation of everything `python -m analysis reduce` writes.

Shares no code with analysis/: only the documented definitions (docs/running.md, the
docstrings of analysis/summary.py, stats.py, recurrence.py and reduce.py), each written
here the slow and obvious way, from the raw events:

- bins are half-open [lo, hi), the last one too (a value on the top edge is out of range);
  values outside the bins still count in the totals that normalise the densities;
- R(mu) = counts / (n_events * width); the T nu densities = counts / (recurrences * width),
  for all recurrences and for those whose starting event is interior (boundary false);
- the recurrence time of a large event i (mu_i >= mu_c) is t_j - t_i for the first j > i of
  the same task with mu_j >= mu_c and |epicenter_j - epicenter_i| <= window (O(n^2) loop);
- a task of n events is cut into k stretches; event i belongs to stretch floor(i k / n) and a
  recurrence to the stretch of its starting event;
- the mode is the centre of the highest bin of the T nu histogram (the lowest such bin on a tie);
- GR b (Aki) = log10(e) / (mean(mu >= cut) - cut), NaN with fewer than two magnitudes; its
  standard error (Shi & Bolt) ln(10) b^2 sqrt(sum (mu - mean)^2 / (n (n - 1)));
- the KS distance compares, at the upper edge of each bin lying at or above the cut, the share
  of the binned magnitudes (from the first such bin to the top edge) below that edge with the
  fitted law 1 - 10^(-b (edge - cut));
- catalogs (one or more, in the order given) pool: tasks of exactly equal (N, l, nu, a, b, c)
  form one point, points numbered by first appearance (catalog by catalog, task by task); a
  task's stream is its recorded (seed_entropy, spawn_key), or (run.seed of its catalog's config,
  its index) where nothing is recorded (-1: not finished); the tasks of a point are its
  resampling units in the order of their streams;
- resampling units: the tasks of a point if it has at least MIN_SEEDS, else the stretches of
  every task (task by task, in the order above); bootstrap resamples drawn as
  rng.integers(0, units, (bootstrap, units)) from
  default_rng(SeedSequence(seed, spawn_key=(N, bits(l), bits(nu), bits(a), bits(b), bits(c))))
  with bits(x) the binary64 pattern of x as an unsigned integer, first for the numbers and
  curves, then (with >= 2 units and recurrences) for the peaks; intervals are the
  (1 - level) / 2 and (1 + level) / 2 quantiles of the resampled values, NaNs left out (linear
  interpolation between order statistics);
- peaks: PEAK_RULE below, a plain transcription of the rule documented in stats.find_peaks, with
  the noise of each smoothed bin the larger of its Poisson value and the sample standard deviation
  of the smoothed bootstrap resamples (drawn after those of the numbers, when there are >= 2 units
  and recurrences); each peak's interval from the nearest peak of every resample within
  PEAK_RULE["match_bins"];
- the inertial events are the rows of kind 0 (every row where there is no `kind`); all of the above
  is of them alone. The creep episodes are the rows of kind 1; a creep row belongs to the stretch
  floor(j k / n) of the number j of inertial events before it among the task's rows (k - 1 when j = n),
  or with no inertial event floor(r k / rows) of its row r. Their densities: of mu (creep_mu bins)
  and of log10(duration nu) (creep_duration bins), each over all creep episodes; the numbers
  n_creep, creep_share = n_creep / (n_creep + n_events), taken_over_share = (ending 2) / n_creep
  and aseismic_fraction = creep slip / (creep slip + inertial slip), NaN where nothing is shared;
  per stretch: n_creep, n_taken_over, creep slip, inertial slip;
- the seismicity around large events: every pair (mainshock m: mu_m >= mu_c; event i != m of the same
  task, any size) with dt = t_i nu - t_m nu in the seis_time bins and d = |epicenter_i - epicenter_m| in
  the seis_distance bins, counted in the mainshock's stretch; a mainshock's exposure of a cell is the
  length of its time bin (shifted to the mainshock's onset) within [t nu of the task's first inertial
  event, of its last] times the number of blocks 0..N-1 at a distance in its distance bin; its map is the
  summed counts over the summed exposures (NaN where 0); its numbers: background = (events - 1) / (N x
  span) summed over tasks, the rates of the cells lying wholly inside near (d < seis_near) x just before
  [-seis_short, 0) and x just after [0, seis_short), and the ratios of near to the ring (seis_near <= d <
  seis_ring) in [-seis_long, -seis_short) and in [-seis_short, 0); defaults SEIS below;
- rupture lengths L = n_slipped of the inertial events: their histogram on the lr bins over all inertial
  events; the fit's events lr_min <= L <= top = min(lr_max, N - 1), per event (1, L - lr_min, top - lr_min);
  L_0 solves 1 / expm1(x) - (K + 1) / expm1((K + 1) x) = m for x = 1 / L_0 (the mean of k = L - lr_min under
  exp(-x k) on 0..K equals the events' mean m, K = top - lr_min), NaN with fewer than 2 events, K < 1 or m
  outside (0, K / 2); defaults RUPTURE below;
- classes: an inertial event with n_slipped >= class_min, first > 0 and last < N - 1 is classified; unilateral
  if min(e - first, last - e) <= uni_edge (last - first), else bilateral; it has a predecessor if a large event
  (mu >= mu_c) came before it in its task, and is at its rim if its epicenter lies within `window` of that
  last such event's first or last block; R(mu) of each class over its own count;
- mean slip per block slip / n_slipped: its sum per lr bin over the events in the bin (the curve; NaN for an
  empty bin); over the fit's events, those with 2 L >= lr_min + top (upper half) and the others (lower): the
  mean over all of them, and the upper half's mean over the lower's;
- stress drop (/events/stress_drop, NaN in catalogs before bk-catalog-7): the same over the events that have one
  (not NaN): its sum and their count per lr bin (the curve their quotient), the mean over the fit's events and
  the upper half's mean over the lower's;
- nucleation: of the large inertial events (mu >= mu_c) with n_onset > 0 (catalogs from bk-catalog-7): their count
  and the means of n_onset (L_sc), n_widest (L_c) and t_widest; of those with a t_spread (not NaN) its mean and
  their share of the count; per mu bin, of all inertial events with n_onset > 0, the mean n_widest (the curve;
  NaN for an empty bin);
- slow slip: mainshocks are the inertial events with mu >= mu_c; a mainshock has precursory creep if a creep episode
  with ending 2 ends at its onset (within 8 spacings of the time) with its epicenter among the episode's blocks or
  next to them; a
  creep episode is afterslip of the last mainshock that ended (onset + duration) at or before its start if it began
  at most afterslip_window (T nu) after that end and its blocks meet first - 1 .. last + 1 of the mainshock: the
  mainshock then has afterslip (counted once, with its slip) and the episode's slip is summed; a silent earthquake
  is a creep episode with ending 1 and mu >= mu_c (in its creep row's stretch); the numbers: the mainshocks, the
  shares with precursory creep and with afterslip, the summed afterslip over the summed slip of the mainshocks
  with afterslip, the silent earthquakes and their share of silent and mainshocks together;
- a reduction is partial if a catalog's name ends in .partial or one of its tasks is not
  finished (status 1) or holds fewer than events_per_task events; the summary then states the
  events reduced of those expected and names those catalogs.

expected_summary(catalogs, opt) gives every dataset of the summary; check_summary compares
a summary file with it, key by key (a key it does not know fails: new outputs need a check).
"""
import math
import struct
import tomllib

import h5py
import numpy as np

LOG10_E = math.log10(math.e)
NUMBERS = ("n_events", "n_large", "fraction_large", "n_recurrences", "mean_tnu", "mode_tnu",
           "mean_tnu_interior", "cv_tnu", "mean_gap", "cv_gap", "gr_b", "gr_b_se", "ks_gr")
CREEP_NUMBERS = ("n_creep", "creep_share", "taken_over_share", "aseismic_fraction")   # the summary's numbers too
CURVES = ("mu", "tnu", "tnu_interior", "creep_mu", "creep_duration")
# the documented defaults of reduce --creep-mu-bins -12:3:75 and --creep-duration-bins -7:3:50
CREEP_EDGES = {"creep_mu_edges": np.linspace(-12, 3, 76), "creep_duration_edges": np.linspace(-7, 3, 51)}
# columns of /per_task/numbers, in the order analysis/stats.py documents
PER_TASK_COLUMNS = ("n_events", "n_large", "n_rec", "sum_tnu", "n_rec_int", "sum_tnu_int",
                    "n_gr", "sum_mu_gr", "sum_mu2_gr")
CREEP_COLUMNS = ("n_creep", "n_taken_over", "sum_slip_creep", "sum_slip_events")   # of /per_task/creep
INTERVAL_COLUMNS = ("sum_tnu2", "n_gaps", "sum_gap", "sum_gap2")   # of /per_task/intervals
SEISMICITY_NUMBERS = ("background_rate", "foreshock_rate", "aftershock_rate", "quiescence_ratio", "doughnut_ratio")
# the documented defaults of reduce --seis-time-bins -1000:1000:40, --seis-distance-bins 0:40:20, --seis-near 2,
# --seis-ring 10, --seis-short 50, --seis-long 500
RUPTURE = {"lr_edges": np.linspace(0.5, 1600.5, 321), "lr_min": 200, "lr_max": 10 ** 9, "class_min": 10,
           "uni_edge": 0.1}
RUPTURE_NUMBERS = ("L0", "n_L0", "n_classified", "fraction_unilateral", "uni_at_rim", "bi_at_rim", "mean_slip_large",
                   "slip_ratio", "mean_drop_large", "drop_ratio", "L_sc", "t_initial", "spread_share", "L_c",
                   "t_nucleation")
RUPTURE_CURVES = ("lr", "mu_uni", "mu_bi", "mean_slip", "mean_drop", "nucleation_length")
CLASS_COLUMNS = ("n_classified", "n_uni", "n_bi", "n_uni_prev", "n_uni_rim", "n_bi_prev", "n_bi_rim")
SLOW_SLIP_NUMBERS = ("n_main", "precursor_share", "afterslip_share", "afterslip_ratio", "n_silent", "silent_share")
AFTERSLIP_WINDOW = 0.01    # the documented default of reduce --afterslip-window
SEIS = {"seis_time_edges": np.linspace(-1000, 1000, 41), "seis_distance_edges": np.linspace(0, 40, 21),
        "seis_near": 2.0, "seis_ring": 10.0, "seis_short": 50.0, "seis_long": 500.0}
# the chain's parameters and every friction law's keys (NaN where a key is not the task's law's)
PARAMS = ("N", "l", "nu", "a", "b", "c", "alpha", "sigma")
GEOMETRY_TASKS = ("geometry", "M", "l_across")    # a catalog's columns of model.geometry (bk-catalog-8)
MIN_SEEDS = 10

# -- the documented peak rule, in one place (replace this block when the finder changes) -----

PEAK_RULE = {
    "kernel": (1, 4, 6, 4, 1),   # smoothing weights (/ 16), the histogram padded with its edge values
    "z": 3.0,                    # prominence > z * sqrt(noise(peak)^2 + noise(base)^2)
    "match_bins": 5,             # a resample's nearest peak counts for a base peak within this many bins
}


def smoothed(counts):
    c = [float(x) for x in counts]
    w = PEAK_RULE["kernel"]
    padded = [c[0], c[0]] + c + [c[-1], c[-1]]
    return [sum(w[k] * padded[i + k] for k in range(5)) / sum(w) for i in range(len(c))]


def poisson_sd(counts):
    """sd of each smoothed bin for independent Poisson counts: sqrt(sum w_k^2 c_k) / 16."""
    c = [float(x) for x in counts]
    w = PEAK_RULE["kernel"]
    padded = [c[0], c[0]] + c + [c[-1], c[-1]]
    return [math.sqrt(sum(w[k] ** 2 * padded[i + k] for k in range(5))) / sum(w) for i in range(len(c))]


def plain_peaks(counts, edges, noise):
    """Peak positions (bin centres), highest first (lower bin first on a tie), by PEAK_RULE: local
    maxima (right end of a plateau) of the smoothed histogram padded with a zero on each side whose
    prominence (height above the higher of the lowest points on each side before a higher value)
    exceeds z times the combined noise of the peak and that lowest point."""
    if sum(float(x) for x in counts) <= 0:
        return []
    s = [0.0] + smoothed(counts) + [0.0]
    sd = [0.0] + list(noise) + [0.0]
    chosen = []
    for i in range(1, len(s) - 1):
        if not (s[i] >= s[i - 1] and s[i] > s[i + 1]):
            continue
        sides = []
        for step in (-1, 1):
            j, low = i + step, None
            while 0 <= j < len(s) and s[j] <= s[i]:
                if low is None or s[j] < s[low]:
                    low = j
                j += step
            if low is not None:
                sides.append(low)
        base = max(sides, key=lambda j: s[j])
        if s[i] - s[base] > PEAK_RULE["z"] * math.sqrt(sd[i] ** 2 + sd[base] ** 2):
            chosen.append(i)
    chosen.sort(key=lambda i: (-s[i], i))
    return [0.5 * (edges[i - 1] + edges[i]) for i in chosen]


def tied_peaks(counts):
    """True if the smoothed histogram has two equal neighbouring values (a plateau: the rule decides)."""
    if sum(float(x) for x in counts) <= 0:
        return False
    s = smoothed(counts)
    return any(s[i] == s[i + 1] and s[i] > 0 for i in range(len(s) - 1))


# -- plain statistics ---------------------------------------------------------------------

def percentile(values, q):
    """q-th percentile (0..100) of the finite values, linear between order statistics; NaN if none."""
    x = sorted(v for v in values if not math.isnan(v))
    if not x:
        return math.nan
    h = (len(x) - 1) * q / 100.0
    i = int(math.floor(h))
    if i + 1 >= len(x):
        return x[-1]
    return x[i] + (h - i) * (x[i + 1] - x[i])


def histogram(values, edges):
    """Counts in half-open bins [e_k, e_k+1), the last one too."""
    v = np.asarray(values, dtype=float)
    return np.histogram(v[np.isfinite(v) & (v < edges[-1])], bins=edges)[0]


def binned_sums(values, weights, edges):
    """Sums of `weights` over the values in each half-open bin [e_k, e_k+1), the last one too, added one by one in
    the values' order (the bin of each by np.digitize, not the statistics' searchsorted)."""
    v, w = np.asarray(values, dtype=float), np.asarray(weights, dtype=float)
    ok = np.isfinite(v) & (v < edges[-1])
    sums = [0.0] * (len(edges) - 1)
    for j, x in zip((np.digitize(v[ok], edges) - 1).tolist(), w[ok].tolist()):
        if 0 <= j < len(sums):
            sums[j] += x
    return np.array(sums)


def density(counts, edges, total):
    if total == 0:
        return np.full(len(edges) - 1, np.nan)
    return np.asarray(counts) / total / np.diff(edges)


def recurrences(t, epi, mu, boundary, mu_c, window):
    """[(index of the starting event, T, interior, index of the closing event)], the O(n^2) way."""
    t, epi, mu, boundary = (list(map(float, t)), list(map(int, epi)), list(map(float, mu)),
                            list(map(bool, boundary)))
    out = []
    for i in range(len(t)):
        if mu[i] < mu_c:
            continue
        for j in range(i + 1, len(t)):
            if mu[j] >= mu_c and abs(epi[j] - epi[i]) <= window:
                out.append((i, t[j] - t[i], not boundary[i], j))
                break
    return out


def gr_b(mu, cut):
    m = [x for x in mu if x >= cut]
    if len(m) < 2:
        return math.nan
    excess = sum(m) / len(m) - cut
    return LOG10_E / excess if excess > 0 else math.nan


def gr_b_se(mu, cut):
    """Shi & Bolt: ln(10) b^2 sqrt(sum (m - mean)^2 / (n (n - 1)))."""
    b = gr_b(mu, cut)
    if not math.isfinite(b):
        return math.nan
    m = [x for x in mu if x >= cut]
    mean = sum(m) / len(m)
    return math.log(10.0) * b * b * math.sqrt(sum((x - mean) ** 2 for x in m) / (len(m) * (len(m) - 1)))


def ks_distance(mu, edges, cut, b):
    if not math.isfinite(b):
        return math.nan
    kept = [k for k in range(len(edges) - 1) if edges[k] >= cut]
    if not kept:
        return math.nan
    lo, top = edges[kept[0]], edges[-1]
    inside = [x for x in mu if lo <= x < top]
    if not inside:
        return math.nan
    gaps = []
    for k in kept:
        upper = edges[k + 1]
        empirical = sum(1 for x in inside if x < upper) / len(inside)
        gaps.append(abs(empirical - (1.0 - 10.0 ** (-b * (upper - cut)))))
    return max(gaps)


def edges_of(opt, name):
    return opt[name] if name in opt else {**CREEP_EDGES, **SEIS, **RUPTURE, "afterslip_window": AFTERSLIP_WINDOW}[name]


def seis_cell(dt, d, te, de):
    """Flat cell index (time bin * distance bins + distance bin) of a pair, or None outside the bins: te and de
    the time and distance edges (lists of floats)."""
    if not (te[0] <= dt < te[-1] and de[0] <= d < de[-1]):
        return None
    rows = [j for j in range(len(te) - 1) if te[j] <= dt < te[j + 1]]
    cols = [k for k in range(len(de) - 1) if de[k] <= d < de[k + 1]]
    if dt >= te[-1] or not rows or not cols:
        return None
    return rows[-1] * (len(de) - 1) + cols[-1]


def seis_region(opt, time, distance):
    """Mask of the flat cells whose bins lie wholly within time [lo, hi) x distance [lo, hi)."""
    te, de = edges_of(opt, "seis_time_edges"), edges_of(opt, "seis_distance_edges")
    def inside(edges, lo, hi):
        tol = 1e-9 * min(edges[q + 1] - edges[q] for q in range(len(edges) - 1))
        return [edges[q] >= lo - tol and edges[q + 1] <= hi + tol for q in range(len(edges) - 1)]
    rows, cols = inside(te, *time), inside(de, *distance)
    return np.array([r and c for r in rows for c in cols])


def quotient(a, b):
    return a / b if b else math.nan


def cv(values):
    """Sample standard deviation (n - 1) over the mean, two-pass; NaN for fewer than two or a mean <= 0."""
    x = [float(v) for v in values]
    if len(x) < 2 or sum(x) <= 0:
        return math.nan
    mean = sum(x) / len(x)
    return math.sqrt(sum((v - mean) ** 2 for v in x) / (len(x) - 1)) / mean


def correlation_length(n, excess, span):
    """L_0 as the module's docstring defines it, by scipy's brentq on x = 1 / L_0."""
    from scipy.optimize import brentq
    if n < 2 or span < 1:
        return math.nan
    m, k = excess / n, float(span)
    if not 0.0 < m < k / 2.0:
        return math.nan

    def excess_at(x):
        return 1.0 / math.expm1(x) - (k + 1.0) / math.expm1((k + 1.0) * x) - m
    return 1.0 / brentq(excess_at, 1e-6, 700.0 / (k + 1.0), xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=500)


def statistics(mu, tnu, interior, event_slip, creep_mu, creep_log_duration, creep_taken, creep_slip, gaps,
               seis_cells, seis_exposure, block_span, lr, fit, cls, has_prev, at_rim, mean_slip, slip_half, drop,
               nuc, mains, silent, opt):
    """Curves and numbers of pooled raw data: mu (all inertial events), tnu and interior
    (recurrences), event_slip (the inertial events' slips), the creep episodes' mu, log10(duration
    nu), taken over (ending 2) and slip, and the inter-event times (times nu) of the inertial events."""
    mu = np.asarray(mu, dtype=float)
    tnu = np.asarray(tnu, dtype=float)
    interior = np.asarray(interior, dtype=bool)
    me, te = opt["mu_edges"], opt["tnu_edges"]
    h_t = histogram(tnu, te)
    mode = math.nan
    if h_t.sum() > 0:
        best = 0
        for k in range(len(h_t)):
            if h_t[k] > h_t[best]:
                best = k
        mode = 0.5 * (te[best] + te[best + 1])
    n, n_large = len(mu), int(np.count_nonzero(mu >= opt["mu_c"]))
    b = gr_b(mu, opt["b_cut"])
    numbers = {
        "n_events": n, "n_large": n_large, "fraction_large": n_large / n if n else math.nan,
        "n_recurrences": len(tnu), "mean_tnu": tnu.sum() / len(tnu) if len(tnu) else math.nan,
        "mode_tnu": mode,
        "mean_tnu_interior": tnu[interior].sum() / interior.sum() if interior.any() else math.nan,
        "cv_tnu": cv(tnu), "mean_gap": quotient(sum(float(g) for g in gaps), len(gaps)), "cv_gap": cv(gaps),
        "gr_b": b, "gr_b_se": gr_b_se(mu, opt["b_cut"]), "ks_gr": ks_distance(mu, me, opt["b_cut"], b),
    }
    m = len(creep_mu)
    creep_sum = sum(float(x) for x in creep_slip)
    numbers.update({"n_creep": m, "creep_share": quotient(m, m + n),
                    "taken_over_share": quotient(int(np.count_nonzero(creep_taken)), m),
                    "aseismic_fraction": quotient(creep_sum, creep_sum + sum(float(x) for x in event_slip))})
    counts, exposure = seis_sums(seis_cells, seis_exposure, opt)
    def rate(region):
        e = sum(float(x) for x in exposure[region])
        return int(counts[region].sum()) / e if e > 0 else math.nan
    def ratio(a, b):
        return a / b if b != 0 and not math.isnan(b) else (math.nan if a == 0 or math.isnan(a) or math.isnan(b)
                                                           else math.copysign(math.inf, a))
    near, ring = (0.0, edges_of(opt, "seis_near")), (edges_of(opt, "seis_near"), edges_of(opt, "seis_ring"))
    short, long_ = edges_of(opt, "seis_short"), edges_of(opt, "seis_long")
    before, after, earlier = (-short, 0.0), (0.0, short), (-long_, -short)
    fore = rate(seis_region(opt, before, near))
    quiet_near, quiet_ring = rate(seis_region(opt, earlier, near)), rate(seis_region(opt, earlier, ring))
    numbers.update({"background_rate": quotient(len(gaps), sum(float(x) for x in block_span)),
                    "foreshock_rate": fore, "aftershock_rate": rate(seis_region(opt, after, near)),
                    "quiescence_ratio": ratio(quiet_near, quiet_ring),
                    "doughnut_ratio": ratio(fore, rate(seis_region(opt, before, ring)))})
    fits = np.asarray(fit, dtype=float).reshape(-1, 3)
    n_fit = len(fits)
    numbers["L0"] = correlation_length(n_fit, fits[:, 1].sum(), fits[:, 2].sum() / n_fit if n_fit else 0.0)
    numbers["n_L0"] = n_fit
    cls = np.asarray(cls)
    n_cls, n_uni, n_bi = (int(np.count_nonzero(x)) for x in (cls > 0, cls == 1, cls == 2))
    numbers.update({"n_classified": n_cls, "fraction_unilateral": quotient(n_uni, n_cls),
                    "uni_at_rim": quotient(int(np.count_nonzero((cls == 1) & at_rim)),
                                           int(np.count_nonzero((cls == 1) & has_prev))),
                    "bi_at_rim": quotient(int(np.count_nonzero((cls == 2) & at_rim)),
                                          int(np.count_nonzero((cls == 2) & has_prev)))})
    lower, upper = mean_slip[slip_half == 0], mean_slip[slip_half == 1]
    numbers["mean_slip_large"] = quotient(sum(float(x) for x in lower) + sum(float(x) for x in upper),
                                          len(lower) + len(upper))
    numbers["slip_ratio"] = quotient(quotient(sum(float(x) for x in upper), len(upper)),
                                     quotient(sum(float(x) for x in lower), len(lower)))
    known = ~np.isnan(drop)
    lower, upper = drop[(slip_half == 0) & known], drop[(slip_half == 1) & known]
    numbers["mean_drop_large"] = quotient(sum(float(x) for x in lower) + sum(float(x) for x in upper),
                                          len(lower) + len(upper))
    numbers["drop_ratio"] = quotient(quotient(sum(float(x) for x in upper), len(upper)),
                                     quotient(sum(float(x) for x in lower), len(lower)))
    nuc = np.asarray(nuc, dtype=float).reshape(-1, 5)      # mu, n_onset, t_spread, t_widest, n_widest
    large = nuc[(nuc[:, 0] >= opt["mu_c"]) & (nuc[:, 1] > 0)]
    spread = large[~np.isnan(large[:, 2])]
    numbers.update({"L_sc": quotient(sum(float(x) for x in large[:, 1]), len(large)),
                    "t_initial": quotient(sum(float(x) for x in spread[:, 2]), len(spread)),
                    "spread_share": quotient(len(spread), len(large)),
                    "L_c": quotient(sum(float(x) for x in large[:, 4]), len(large)),
                    "t_nucleation": quotient(sum(float(x) for x in large[:, 3]), len(large))})
    mains = np.asarray(mains, dtype=float).reshape(-1, 4)     # precursor, after, slip if after, afterslip
    n_main, n_after, n_silent = len(mains), int(mains[:, 1].sum()), len(silent)
    numbers.update({"n_main": n_main, "precursor_share": quotient(int(mains[:, 0].sum()), n_main),
                    "afterslip_share": quotient(n_after, n_main),
                    "afterslip_ratio": quotient(sum(float(x) for x in mains[:, 3]), sum(float(x) for x in mains[:, 2])),
                    "n_silent": n_silent, "silent_share": quotient(n_silent, n_silent + n_main)})
    with_columns = nuc[nuc[:, 1] > 0]
    nuc_sums = binned_sums(with_columns[:, 0], with_columns[:, 4], me)
    nuc_in_bin = histogram(with_columns[:, 0], me)
    le = edges_of(opt, "lr_edges")
    drop_sums = binned_sums(lr[known], drop[known], le)
    drop_in_bin = histogram(lr[known], le)
    slip_sums = binned_sums(lr, mean_slip, le)
    in_bin = histogram(lr, le)
    ce, de = edges_of(opt, "creep_mu_edges"), edges_of(opt, "creep_duration_edges")
    curves = {"mu": density(histogram(mu, me), me, n),
              "tnu": density(h_t, te, len(tnu)),
              "tnu_interior": density(histogram(tnu[interior], te), te, int(interior.sum())),
              "creep_mu": density(histogram(creep_mu, ce), ce, m),
              "creep_duration": density(histogram(creep_log_duration, de), de, m),
              "lr": density(histogram(lr, le), le, n),
              "mu_uni": density(histogram(mu[cls == 1], me), me, n_uni),
              "mu_bi": density(histogram(mu[cls == 2], me), me, n_bi),
              "mean_slip": np.array([x / c if c else math.nan for x, c in zip(slip_sums, in_bin)]),
              "mean_drop": np.array([x / c if c else math.nan for x, c in zip(drop_sums, drop_in_bin)]),
              "nucleation_length": np.array([x / c if c else math.nan for x, c in zip(nuc_sums, nuc_in_bin)])}
    return curves, numbers


def seis_sums(cells, exposure, opt):
    """(counts, exposures) of the flat cells from pooled pairs (their cells) and mainshocks' exposures."""
    width = (len(edges_of(opt, "seis_time_edges")) - 1) * (len(edges_of(opt, "seis_distance_edges")) - 1)
    counts = np.bincount(np.asarray(cells, dtype=np.int64), minlength=width)
    total = np.zeros(width)
    for row in exposure:
        total += row
    return counts, total


def seis_rate_map(units, opt):
    """(time bins, distance bins) summed counts over summed exposures of all units, NaN where nothing exposed."""
    counts, total = seis_sums(np.concatenate([u[9] for u in units]), [r for u in units for r in u[10]], opt)
    shape = (len(edges_of(opt, "seis_time_edges")) - 1, len(edges_of(opt, "seis_distance_edges")) - 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(total > 0, counts / np.where(total > 0, total, 1), np.nan).reshape(shape)


# -- the whole summary ------------------------------------------------------------------

class Task:
    """One task's raw events and its recurrences (T nu), each with its stretch."""

    def __init__(self, ev, nu, opt, n_blocks=0):
        rows = len(ev["t"])
        kind = np.asarray(ev["kind"]) if "kind" in ev else np.zeros(rows, dtype=np.int8)
        k = opt["blocks"]
        inertial = [r for r in range(rows) if kind[r] == 0]
        creep = [r for r in range(rows) if kind[r] == 1]
        n = len(inertial)
        self.creep_stretch = np.zeros(len(creep), dtype=np.int64)
        for c, r in enumerate(creep):
            before = sum(1 for q in inertial if q < r)
            self.creep_stretch[c] = min(before * k // n, k - 1) if n else r * k // rows
        column = {name: np.asarray(ev[name]) for name in ev}
        self.event_slip = column["slip"][inertial].astype(float) if n else np.zeros(0)
        self.creep_mu = column["mu"][creep].astype(float) if creep else np.zeros(0)
        with np.errstate(divide="ignore"):
            self.creep_log_duration = (np.log10(column["duration"][creep].astype(float) * nu) if creep
                                       else np.zeros(0))
        self.creep_taken = column["ending"][creep] == 2 if creep else np.zeros(0, dtype=bool)
        self.creep_slip = column["slip"][creep].astype(float) if creep else np.zeros(0)
        self.ruptures({name: column[name][inertial] for name in ("mu", "epicenter", "first", "last", "n_slipped",
                                                                 "slip", "stress_drop", "n_onset", "t_spread",
                                                                 "t_widest", "n_widest")},
                      n_blocks, opt, k, n)
        self.slow_slip(column, inertial, creep, nu, opt, k)
        ev = {name: column[name][inertial] for name in ("t", "mu", "epicenter", "boundary")}
        self.n = n
        self.mu = np.asarray(ev["mu"], dtype=float)
        self.stretch = np.array([i * k // n for i in range(n)], dtype=np.int64)
        rec = recurrences(ev["t"], ev["epicenter"], ev["mu"], ev["boundary"], opt["mu_c"], opt["window"])
        self.rec_start = np.array([r[0] for r in rec], dtype=np.int64)
        self.rec_end = np.array([r[3] for r in rec], dtype=np.int64)
        self.tnu = np.array([r[1] * nu for r in rec], dtype=float)
        self.interior = np.array([r[2] for r in rec], dtype=bool)
        self.rec_stretch = self.stretch[self.rec_start] if len(rec) else np.zeros(0, dtype=np.int64)
        # the inter-event times, each in the stretch of the event that closes it
        t = [float(x) for x in ev["t"]]
        self.gaps = np.array([(t[i] - t[i - 1]) * nu for i in range(1, n)], dtype=float)
        self.gap_stretch = self.stretch[1:]
        self.block_span = self.gaps * n_blocks
        self.seis(ev, nu, n_blocks, opt)

    def ruptures(self, ev, n_blocks, opt, k, n):
        """Per inertial event: its length, its fit row (or none), its class (0 none, 1 unilateral, 2 bilateral),
        whether a large event came before it and whether its epicenter lies at that event's rim."""
        lo, top = edges_of(opt, "lr_min"), min(edges_of(opt, "lr_max"), n_blocks - 1)
        self.lr = np.array([float(x) for x in ev["n_slipped"]])
        fit, fit_stretch, cls, has_prev, at_rim, mean_slip, slip_half = [], [], [], [], [], [], []
        previous = None
        for i in range(n):
            length, f, last, e = (int(ev[c][i]) for c in ("n_slipped", "first", "last", "epicenter"))
            mean_slip.append(float(ev["slip"][i]) / length)
            slip_half.append(-1)
            if lo <= length <= top:
                fit.append((1.0, float(length - lo), float(top - lo)))
                fit_stretch.append(i * k // n)
                slip_half[-1] = 1 if 2 * length >= lo + top else 0
            c = 0
            if length >= edges_of(opt, "class_min") and f > 0 and last < n_blocks - 1:
                c = 1 if min(e - f, last - e) <= edges_of(opt, "uni_edge") * (last - f) else 2
            cls.append(c)
            has_prev.append(previous is not None)
            at_rim.append(previous is not None and min(abs(e - previous[0]), abs(e - previous[1])) <= opt["window"])
            if float(ev["mu"][i]) >= opt["mu_c"]:
                previous = (f, last)
        self.fit = np.array(fit, dtype=float).reshape(-1, 3)
        self.fit_stretch = np.array(fit_stretch, dtype=np.int64)
        self.cls = np.array(cls, dtype=np.int64)
        self.has_prev = np.array(has_prev, dtype=bool)
        self.at_rim = np.array(at_rim, dtype=bool)
        self.mean_slip = np.array(mean_slip, dtype=float)
        self.slip_half = np.array(slip_half, dtype=np.int64)
        self.drop = np.array([float(x) for x in ev["stress_drop"]], dtype=float)
        self.nuc = np.array([[float(ev[c][i]) for c in ("mu", "n_onset", "t_spread", "t_widest", "n_widest")]
                             for i in range(n)], dtype=float).reshape(-1, 5)

    def slow_slip(self, column, inertial, creep, nu, opt, k):
        """Per mainshock (mu >= mu_c) its row (precursory creep, afterslip, its slip if afterslip, the afterslip's
        slip) and stretch; the silent earthquakes' stretches: every creep episode against every mainshock."""
        n = len(inertial)
        t, duration = column["t"], column["duration"]
        mains = [(i, r) for i, r in enumerate(inertial) if float(column["mu"][r]) >= opt["mu_c"]]
        rows = {r: [0.0, 0.0, 0.0, 0.0] for _, r in mains}
        silent = []
        for c, r in enumerate(creep):
            start, first, last = float(t[r]), int(column["first"][r]), int(column["last"][r])
            end = start + float(duration[r])
            if int(column["ending"][r]) == 1 and float(column["mu"][r]) >= opt["mu_c"]:
                silent.append(self.creep_stretch[c])
            if int(column["ending"][r]) == 2:
                for _, m in mains:
                    if (abs(float(t[m]) - end) <= 8 * math.ulp(abs(end))
                            and first - 1 <= int(column["epicenter"][m]) <= last + 1):
                        rows[m][0] = 1.0
            ended = [m for _, m in mains if float(t[m]) + float(duration[m]) <= start + 8 * math.ulp(abs(start))]
            if not ended:
                continue
            m = ended[-1]
            if ((start - (float(t[m]) + float(duration[m]))) * nu <= edges_of(opt, "afterslip_window")
                    and first <= int(column["last"][m]) + 1 and int(column["first"][m]) - 1 <= last):
                if not rows[m][1]:
                    rows[m][1], rows[m][2] = 1.0, float(column["slip"][m])
                rows[m][3] += float(column["slip"][r])
        self.mains = np.array([rows[r] for _, r in mains], dtype=float).reshape(-1, 4)
        self.main_stretch = np.array([i * k // n for i, _ in mains], dtype=np.int64)
        self.silent = np.array(silent, dtype=np.int64)

    def seis(self, ev, nu, n_blocks, opt):
        """Every pair's cell and stretch (of its mainshock), every mainshock's exposure row and stretch."""
        T = [float(x) * nu for x in ev["t"]]
        x = [int(e) for e in ev["epicenter"]]
        # the edges as Python floats: half a million pairs, each compared with every edge
        te = [float(e) for e in edges_of(opt, "seis_time_edges")]
        de = [float(e) for e in edges_of(opt, "seis_distance_edges")]
        cells, cell_stretch, exposure, main_stretch = [], [], [], []
        for m in range(self.n):
            if float(ev["mu"][m]) < opt["mu_c"]:
                continue
            for i in range(self.n):
                if i != m:
                    c = seis_cell(T[i] - T[m], abs(x[i] - x[m]), te, de)
                    if c is not None:
                        cells.append(c)
                        cell_stretch.append(self.stretch[m])
            blocks = [sum(1 for b in range(n_blocks) if de[k] <= abs(b - x[m]) < de[k + 1]) for k in range(len(de) - 1)]
            cover = [max(0.0, min(T[m] + te[j + 1], T[-1]) - max(T[m] + te[j], T[0])) for j in range(len(te) - 1)]
            exposure.append(np.array([c * b for c in cover for b in blocks], dtype=float))
            main_stretch.append(self.stretch[m])
        self.seis_cells = np.array(cells, dtype=np.int64)
        self.seis_cell_stretch = np.array(cell_stretch, dtype=np.int64)
        width = (len(te) - 1) * (len(de) - 1)
        self.seis_exposure = np.array(exposure).reshape(-1, width)
        self.seis_main_stretch = np.array(main_stretch, dtype=np.int64)

    def unit(self, stretch=None):
        """(mu, tnu, interior, event slip, creep mu, creep log10(duration nu), creep taken over,
        creep slip) of the whole task or of one stretch."""
        creep = (self.creep_mu, self.creep_log_duration, self.creep_taken, self.creep_slip)
        ruptures = (self.lr, self.fit, self.cls, self.has_prev, self.at_rim, self.mean_slip, self.slip_half,
                    self.drop, self.nuc, self.mains, self.silent)
        if stretch is None:
            return (self.mu, self.tnu, self.interior, self.event_slip, *creep, self.gaps, self.seis_cells,
                    self.seis_exposure, self.block_span, *ruptures)
        e, r, c = self.stretch == stretch, self.rec_stretch == stretch, self.creep_stretch == stretch
        return (self.mu[e], self.tnu[r], self.interior[r], self.event_slip[e], *(x[c] for x in creep),
                self.gaps[self.gap_stretch == stretch], self.seis_cells[self.seis_cell_stretch == stretch],
                self.seis_exposure[self.seis_main_stretch == stretch], self.block_span[self.gap_stretch == stretch],
                self.lr[e], self.fit[self.fit_stretch == stretch], self.cls[e], self.has_prev[e], self.at_rim[e],
                self.mean_slip[e], self.slip_half[e], self.drop[e], self.nuc[e],
                self.mains[self.main_stretch == stretch], self.silent[self.silent == stretch])

    def per_stretch(self, opt):
        k, me, te = opt["blocks"], opt["mu_edges"], opt["tnu_edges"]
        mu_h = np.zeros((k, len(me) - 1), dtype=np.int64)
        t_h = np.zeros((k, len(te) - 1), dtype=np.int64)
        ti_h = np.zeros((k, len(te) - 1), dtype=np.int64)
        numbers = np.zeros((k, len(PER_TASK_COLUMNS)))
        ce, de = edges_of(opt, "creep_mu_edges"), edges_of(opt, "creep_duration_edges")
        cm_h = np.zeros((k, len(ce) - 1), dtype=np.int64)
        cd_h = np.zeros((k, len(de) - 1), dtype=np.int64)
        creep = np.zeros((k, len(CREEP_COLUMNS)))
        intervals = np.zeros((k, len(INTERVAL_COLUMNS)))
        width = (len(edges_of(opt, "seis_time_edges")) - 1) * (len(edges_of(opt, "seis_distance_edges")) - 1)
        pairs, seis_exposure = np.zeros((k, width), dtype=np.int64), np.zeros((k, width))
        seis_columns = np.zeros((k, 3))
        le = edges_of(opt, "lr_edges")
        lr_h, fit_sums = np.zeros((k, len(le) - 1), dtype=np.int64), np.zeros((k, 3))
        classes = np.zeros((k, len(CLASS_COLUMNS)))
        uni_h, bi_h = np.zeros((k, len(me) - 1), dtype=np.int64), np.zeros((k, len(me) - 1), dtype=np.int64)
        slip_h, slip_columns = np.zeros((k, len(le) - 1)), np.zeros((k, 4))
        drop_n, drop_h = np.zeros((k, len(le) - 1), dtype=np.int64), np.zeros((k, len(le) - 1))
        drop_columns = np.zeros((k, 4))
        nuc_columns, nuc_len = np.zeros((k, 6)), np.zeros((k, len(me) - 1))
        nuc_n = np.zeros((k, len(me) - 1), dtype=np.int64)
        slow = np.zeros((k, 6))
        for s in range(k):
            (mu, tnu, interior, event_slip, creep_mu, creep_log_duration, taken, creep_slip, gaps, cells,
             exposure, block_span, lr, fit, cls, has_prev, at_rim, mean_slip, slip_half, drop, nuc, mains,
             silent) = self.unit(s)
            slow[s] = [len(mains), mains[:, 0].sum(), mains[:, 1].sum(), mains[:, 2].sum(), mains[:, 3].sum(),
                       len(silent)]
            large = nuc[(nuc[:, 0] >= opt["mu_c"]) & (nuc[:, 1] > 0)]
            spread = large[~np.isnan(large[:, 2])]
            nuc_columns[s] = [len(large), large[:, 1].sum(), len(spread), spread[:, 2].sum(), large[:, 4].sum(),
                              large[:, 3].sum()]
            with_columns = nuc[nuc[:, 1] > 0]
            nuc_n[s] = histogram(with_columns[:, 0], me)
            nuc_len[s] = [with_columns[(with_columns[:, 0] >= me[j]) & (with_columns[:, 0] < me[j + 1]), 4].sum()
                          for j in range(len(me) - 1)]
            known = ~np.isnan(drop)
            drop_n[s] = histogram(lr[known], le)
            drop_h[s] = [drop[known & (lr >= le[j]) & (lr < le[j + 1])].sum() for j in range(len(le) - 1)]
            lo, hi = known & (slip_half == 0), known & (slip_half == 1)
            drop_columns[s] = [lo.sum(), drop[lo].sum(), hi.sum(), drop[hi].sum()]
            slip_h[s] = [mean_slip[(lr >= le[j]) & (lr < le[j + 1])].sum() for j in range(len(le) - 1)]
            slip_columns[s] = [(slip_half == 0).sum(), mean_slip[slip_half == 0].sum(), (slip_half == 1).sum(),
                               mean_slip[slip_half == 1].sum()]
            lr_h[s], fit_sums[s] = histogram(lr, le), fit.sum(axis=0)
            uni, bi = cls == 1, cls == 2
            classes[s] = [np.count_nonzero(cls > 0), uni.sum(), bi.sum(), (uni & has_prev).sum(), (uni & at_rim).sum(),
                          (bi & has_prev).sum(), (bi & at_rim).sum()]
            uni_h[s], bi_h[s] = histogram(mu[uni], me), histogram(mu[bi], me)
            intervals[s] = [(tnu ** 2).sum(), len(gaps), gaps.sum(), (gaps ** 2).sum()]
            pairs[s], seis_exposure[s] = seis_sums(cells, exposure, opt)
            seis_columns[s] = [len(exposure), len(gaps), block_span.sum()]
            mu_h[s], t_h[s], ti_h[s] = histogram(mu, me), histogram(tnu, te), histogram(tnu[interior], te)
            cm_h[s], cd_h[s] = histogram(creep_mu, ce), histogram(creep_log_duration, de)
            creep[s] = [len(creep_mu), np.count_nonzero(taken), creep_slip.sum(), event_slip.sum()]
            gr = mu[mu >= opt["b_cut"]]
            numbers[s] = [len(mu), np.count_nonzero(mu >= opt["mu_c"]), len(tnu), tnu.sum(),
                          interior.sum(), tnu[interior].sum(), len(gr), gr.sum(), (gr ** 2).sum()]
        return (mu_h, t_h, ti_h, numbers, cm_h, cd_h, creep, intervals, pairs, seis_exposure, seis_columns, lr_h,
                fit_sums, classes, uni_h, bi_h, slip_h, slip_columns, drop_n, drop_h, drop_columns,
                nuc_columns, nuc_n, nuc_len, slow)


def _pool(units, pick):
    return tuple(np.concatenate([units[p][c] for p in pick]) for c in range(len(units[0])))


def bits(x):
    """The IEEE-754 binary64 pattern of x as an unsigned integer."""
    return struct.unpack("<Q", struct.pack("<d", float(x)))[0]


def point(tasks, params, opt):
    """Estimates, intervals, peaks, method and unit count of one parameter point."""
    if len(tasks) >= MIN_SEEDS:
        units, method = [t.unit() for t in tasks], "seeds"
    else:
        units, method = [t.unit(s) for t in tasks for s in range(opt["blocks"])], "blocks"
    m = len(units)
    curves, numbers = statistics(*_pool(units, range(m)), opt)
    key = (int(params["N"]),) + tuple(bits(params[name]) for name in PARAMS[1:] if not np.isnan(params[name]))
    rng = np.random.default_rng(np.random.SeedSequence(opt["seed"], spawn_key=key))
    q = 50.0 * (1.0 - opt["level"])
    out = {"method": method, "units": m, "curves": {}, "numbers": {}}
    if m >= 2:
        picks = rng.integers(0, m, size=(opt["bootstrap"], m))
        resampled = [statistics(*_pool(units, p), opt) for p in picks]
    for name, est in curves.items():
        if m >= 2:
            rows = np.array([r[0][name] for r in resampled])
            lo = np.array([percentile(rows[:, j], q) for j in range(len(est))])
            hi = np.array([percentile(rows[:, j], 100 - q) for j in range(len(est))])
        else:
            lo = hi = np.full(len(est), np.nan)
        out["curves"][name] = (est, lo, hi)
    for name, est in numbers.items():
        if m >= 2:
            values = [r[1][name] for r in resampled]
            out["numbers"][name] = (est, percentile(values, q), percentile(values, 100 - q))
        else:
            out["numbers"][name] = (est, math.nan, math.nan)
    out["peaks"], out["tied"] = _peaks(units, m, opt, rng, q)
    out["seismicity_rate"] = seis_rate_map(units, opt)
    return out


def _peaks(units, m, opt, rng, q):
    te = opt["tnu_edges"]
    hist = [histogram(u[1], te) for u in units]
    total = sum(hist)
    noise = poisson_sd(total)
    resamples = []
    if m >= 2 and total.sum() > 0:
        resamples = [sum(hist[p] for p in pick) for pick in rng.integers(0, m, size=(opt["bootstrap"], m))]
        sm = [smoothed(c) for c in resamples]
        for k in range(len(noise)):
            values = [r[k] for r in sm]      # sample standard deviation over the resamples
            mean = sum(values) / len(values)
            spread = math.sqrt(sum((v - mean) ** 2 for v in values) / (len(values) - 1))
            noise[k] = max(noise[k], spread)
    base = plain_peaks(total, te, noise)
    tied = tied_peaks(total)
    if not base or not resamples:
        return [(b, math.nan, math.nan) for b in base], tied
    width = te[1] - te[0]
    found = [[] for _ in base]
    for counts in resamples:
        tied = tied or tied_peaks(counts)
        resampled = plain_peaks(counts, te, noise)
        for i, b in enumerate(base):
            if not resampled:
                continue
            near = resampled[0]
            for r in resampled[1:]:
                if abs(r - b) < abs(near - b):
                    near = r
            if abs(near - b) <= PEAK_RULE["match_bins"] * width:
                found[i].append(near)
    rows = [(b, percentile(f, q), percentile(f, 100 - q)) if f else (b, math.nan, math.nan)
            for b, f in zip(base, found)]
    return rows, tied


def _catalog_facts(path):
    """(run.seed of the stored config, events_per_task) of a catalog, read with h5py and tomllib."""
    with h5py.File(path, "r", locking=False) as h5:
        config = tomllib.loads(h5.attrs["config"])
        return int(config.get("run", {}).get("seed", 0)), int(h5.attrs["events_per_task"])


def expected_tasks(catalogs):
    """The summary's /tasks table of `catalogs` [(path, events, tasks)] and its points:
    (table, [(params, rows in stream order)])."""
    table = {}
    for c, (path, _, tasks) in enumerate(catalogs):
        seed, _ = _catalog_facts(path)
        n = len(tasks["point"])
        # (a chain's geometry columns are not the summary's: the analysis reads chains only so far)
        part = {name: np.asarray(values).copy() for name, values in tasks.items() if name not in GEOMETRY_TASKS}
        for k in range(n):
            if part["seed_entropy"][k] < 0 or part["spawn_key"][k] < 0:
                part["seed_entropy"][k], part["spawn_key"][k] = seed, k
        part["catalog"] = np.full(n, c, dtype=np.int64)
        part["catalog_task"] = np.arange(n, dtype=np.int64)
        part["catalog_point"] = part["point"].copy()
        for name, values in part.items():
            table.setdefault(name, []).append(values)
    table = {name: np.concatenate(parts) for name, parts in table.items()}
    keys, values = [], []
    for g in range(len(table["point"])):
        law = table["law"][g].decode() if isinstance(table["law"][g], bytes) else str(table["law"][g])
        key = (law, *(bits(table[name][g]) for name in PARAMS))     # NaN == NaN by bits; laws may share keys
        if key not in keys:
            keys.append(key)
            values.append((law, *(table[name][g].item() for name in PARAMS)))
        table["point"][g] = keys.index(key)
    points = []
    for i, (law, *key) in enumerate(values):
        rows = [g for g in range(len(table["point"])) if table["point"][g] == i]
        rows.sort(key=lambda g: (table["seed_entropy"][g], table["spawn_key"][g]))
        points.append(({**dict(zip(PARAMS, key)), "law": law}, rows))
    return table, points


def expected_partial(catalogs):
    """(events reduced, events expected, paths of the unfinished catalogs)."""
    written = expected = 0
    unfinished = []
    for path, _, tasks in catalogs:
        _, per_task = _catalog_facts(path)
        written += int(sum(tasks["events_written"]))
        expected += len(tasks["point"]) * per_task
        if (str(path).endswith(".partial") or any(s != 1 for s in tasks["status"])
                or any(w < per_task for w in tasks["events_written"])):
            unfinished.append(str(path))
    return written, expected, unfinished


def expected_summary(catalogs, opt):
    """What the summary of `catalogs` must hold: {summary key: array}, plus 'tied' (peak ties
    met), 'tasks' (the /tasks table), 'partial' (expected_partial) and 'raw' (per-task data).

    catalogs: [(path, events, tasks)] in the order given to reduce; events: dict of columns of
    every committed event of the catalog (ensemble/store/reader.py: read), tasks: its task table.
    opt: mu_edges, tnu_edges, mu_c, window, b_cut, bootstrap, level, blocks, seed.
    """
    table, points = expected_tasks(catalogs)
    per_task = []
    for path, events, tasks in catalogs:
        per_task += [Task({c: events[c][events["task"] == k] for c in events if c != "task"},
                          float(tasks["nu"][k]), opt, int(tasks["N"][k])) for k in range(len(tasks["point"]))]
    exp = {"bins/mu": opt["mu_edges"], "bins/tnu": opt["tnu_edges"],
           "bins/creep_mu": edges_of(opt, "creep_mu_edges"),
           "bins/creep_duration": edges_of(opt, "creep_duration_edges"),
           "bins/seis_time": edges_of(opt, "seis_time_edges"),
           "bins/seis_distance": edges_of(opt, "seis_distance_edges"), "bins/lr": edges_of(opt, "lr_edges")}
    stacks = [t.per_stretch(opt) for t in per_task]
    for j, name in enumerate(("mu", "tnu", "tnu_interior", "numbers", "creep_mu", "creep_duration", "creep",
                              "intervals", "seis_pairs", "seis_exposure", "seismicity", "lr", "rupture_length",
                              "rupture_classes", "mu_uni", "mu_bi", "slip_lr", "slip_scaling", "drop_n", "drop_lr",
                              "stress_drop", "nucleation", "nuc_n", "nuc_len", "slow_slip")):
        exp[f"per_task/{name}"] = np.stack([s[j] for s in stacks])
    results = []
    for params, rows in points:
        r = point([per_task[g] for g in rows], params, opt)
        r["params"] = params
        results.append(r)
    for name in PARAMS:
        exp[f"points/{name}"] = np.array([r["params"][name] for r in results])
    exp["points/law"] = np.array([r["params"]["law"] for r in results])
    exp["points/method"] = np.array([r["method"] for r in results])
    exp["points/units"] = np.array([r["units"] for r in results])
    for name in CURVES + RUPTURE_CURVES:
        for j, suffix in enumerate(("density", "lo", "hi")):
            exp[f"points/{name}_{suffix}"] = np.stack([r["curves"][name][j] for r in results])
    for name in NUMBERS + CREEP_NUMBERS + SEISMICITY_NUMBERS + RUPTURE_NUMBERS + SLOW_SLIP_NUMBERS:
        exp[f"points/numbers/{name}"] = np.array([r["numbers"][name] for r in results], dtype=float)
    exp["points/seismicity_rate"] = np.stack([r["seismicity_rate"] for r in results])
    most = max([len(r["peaks"]) for r in results] + [1])
    peaks = np.full((len(results), most, 3), np.nan)
    for i, r in enumerate(results):
        if r["peaks"]:
            peaks[i, :len(r["peaks"])] = r["peaks"]
    exp["points/peaks"] = peaks
    exp["tied"] = any(r["tied"] for r in results)
    exp["tasks"] = table
    exp["partial"] = expected_partial(catalogs)
    exp["paths"] = [str(path) for path, _, _ in catalogs]
    exp["raw"] = per_task      # for the tests' preconditions (what the catalog exercises)
    return exp


# -- the comparison ------------------------------------------------------------------------

def read_summary(path):
    """Every dataset and attribute of a summary, read with h5py alone."""
    out = {}
    with h5py.File(path, "r") as h5:
        h5.visititems(lambda name, obj: out.__setitem__(name, obj[...]) if isinstance(obj, h5py.Dataset) else None)
        out["attrs"] = dict(h5.attrs)
    return out


# Floating-point tolerances. Counts, bins, peak positions, modes and unit counts are compared
# exactly. Sums and quotients are computed here in another order or form (a sum over a list
# against np.add.at, counts / n / width against counts / (n * width), our percentile against
# numpy's): the largest relative differences measured (tests/test_reduction.py's summaries and the
# real catalog's of tests/test_analysis.py) were 1.5e-14 for
# ks_gr (a small difference of nearly equal CDFs, inheriting b's ulps through 10 ** (-b x)),
# 2.5e-15 for gr_b, 3.7e-15 for interval ends and 4e-16 for the per-task sums. 1e-12 leaves
# room for other data and still tells any real change apart.
RTOL = 1e-12


def check_summary(s, expected, opt):
    """Every dataset and attribute of summary `s` (read_summary) against expected_summary."""
    tasks = expected["tasks"]
    tasks_keys = {f"tasks/{k}" for k in tasks}
    numbers = {f"points/numbers/{n}" for n in NUMBERS + CREEP_NUMBERS + SEISMICITY_NUMBERS + RUPTURE_NUMBERS
               + SLOW_SLIP_NUMBERS}
    curves = {f"points/{c}_{x}" for c in CURVES + RUPTURE_CURVES for x in ("density", "lo", "hi")}
    known = ({"bins/mu", "bins/tnu", "bins/creep_mu", "bins/creep_duration", "points/method", "points/units",
              "points/law", "bins/seis_time", "bins/seis_distance", "points/seismicity_rate",
              "points/peaks", "attrs", "bins/lr"}
             | {f"per_task/{k}" for k in ("mu", "tnu", "tnu_interior", "numbers", "creep_mu", "creep_duration",
                                          "creep", "intervals", "seis_pairs", "seis_exposure", "seismicity", "lr",
                                          "rupture_length", "rupture_classes", "mu_uni", "mu_bi", "slip_lr",
                                          "slip_scaling", "drop_n", "drop_lr", "stress_drop", "nucleation", "nuc_n",
                                          "nuc_len", "slow_slip")}
             | {f"points/{p}" for p in PARAMS} | tasks_keys | numbers | curves)
    # a new output must get its brute-force check here
    assert set(s) == known, f"unchecked {set(s) - known}, missing {known - set(s)}"
    a = s["attrs"]
    for key in ("mu_c", "window", "b_cut", "bootstrap", "level", "blocks", "seed"):
        assert a[key] == opt[key], key
    for key in ("seis_near", "seis_ring", "seis_short", "seis_long", "lr_min", "lr_max", "class_min", "uni_edge",
                "afterslip_window"):
        assert a[key] == edges_of(opt, key), key
    paths = expected["paths"]
    assert a["format"].startswith("bk-summary-")
    configs = []
    for path in paths:
        with h5py.File(path, "r", locking=False) as h5:
            configs.append(h5.attrs["config"])
    assert list(a["catalogs"]) == paths and list(a["configs"]) == configs
    if len(paths) == 1:
        assert a["catalog"] == paths[0] and a["config"] == configs[0]
    else:
        assert "config" not in a
        assert a["catalog"] == (", ".join(paths) if len(paths) <= 3
                                else f"{paths[0]} ... {paths[-1]} ({len(paths)} catalogs)")
    check_partial(a["partial"], expected["partial"], paths)
    for k, v in tasks.items():
        got = s[f"tasks/{k}"]
        want = np.char.encode(v) if v.dtype.kind == "U" else v
        np.testing.assert_array_equal(got, want, err_msg=k)
    for key in ("bins/mu", "bins/tnu", "per_task/mu", "per_task/tnu", "per_task/tnu_interior",
                "bins/creep_mu", "bins/creep_duration", "per_task/creep_mu", "per_task/creep_duration",
                "points/units", *(f"points/{p}" for p in PARAMS)):
        np.testing.assert_array_equal(s[key], expected[key], err_msg=key)
    assert [m.decode() for m in s["points/method"]] == list(expected["points/method"])
    assert [law.decode() for law in s["points/law"]] == list(expected["points/law"])
    got, want = s["per_task/numbers"], expected["per_task/numbers"]
    counts = [PER_TASK_COLUMNS.index(c) for c in ("n_events", "n_large", "n_rec", "n_rec_int", "n_gr")]
    np.testing.assert_array_equal(got[..., counts], want[..., counts], err_msg="per_task/numbers counts")
    np.testing.assert_allclose(got, want, rtol=RTOL, atol=0, err_msg="per_task/numbers sums")
    got, want = s["per_task/creep"], expected["per_task/creep"]
    np.testing.assert_array_equal(got[..., :2], want[..., :2], err_msg="per_task/creep counts")
    np.testing.assert_allclose(got, want, rtol=RTOL, atol=0, err_msg="per_task/creep sums")
    for key in ("bins/seis_time", "bins/seis_distance", "per_task/seis_pairs", "bins/lr", "per_task/lr",
                "per_task/rupture_classes", "per_task/mu_uni", "per_task/mu_bi"):
        np.testing.assert_array_equal(s[key], expected[key], err_msg=key)
    for key in ("per_task/seis_exposure", "per_task/seismicity", "points/seismicity_rate"):
        np.testing.assert_allclose(s[key], expected[key], rtol=RTOL, atol=0, err_msg=key)
    np.testing.assert_array_equal(s["per_task/seismicity"][..., :2], expected["per_task/seismicity"][..., :2])
    got, want = s["per_task/intervals"], expected["per_task/intervals"]
    np.testing.assert_array_equal(got[..., 1], want[..., 1], err_msg="per_task/intervals counts")
    np.testing.assert_allclose(got, want, rtol=RTOL, atol=0, err_msg="per_task/intervals sums")
    for key in sorted(curves):
        np.testing.assert_allclose(s[key], expected[key], rtol=RTOL, atol=0, err_msg=key)
    np.testing.assert_array_equal(s["per_task/rupture_length"][..., 0], expected["per_task/rupture_length"][..., 0])
    np.testing.assert_array_equal(s["per_task/slip_scaling"][..., ::2], expected["per_task/slip_scaling"][..., ::2])
    np.testing.assert_array_equal(s["per_task/drop_n"], expected["per_task/drop_n"])
    np.testing.assert_array_equal(s["per_task/stress_drop"][..., ::2], expected["per_task/stress_drop"][..., ::2])
    np.testing.assert_array_equal(s["per_task/nuc_n"], expected["per_task/nuc_n"])
    counts = [0, 2]
    np.testing.assert_array_equal(s["per_task/nucleation"][..., counts], expected["per_task/nucleation"][..., counts])
    counts = [0, 1, 2, 5]
    np.testing.assert_array_equal(s["per_task/slow_slip"][..., counts], expected["per_task/slow_slip"][..., counts],
                                  err_msg="per_task/slow_slip counts")
    for key in ("per_task/slip_lr", "per_task/slip_scaling", "per_task/drop_lr", "per_task/stress_drop",
                "per_task/nucleation", "per_task/nuc_len", "per_task/slow_slip"):
        np.testing.assert_allclose(s[key], expected[key], rtol=RTOL, atol=0, err_msg=key)
    np.testing.assert_allclose(s["per_task/rupture_length"], expected["per_task/rupture_length"], rtol=RTOL, atol=0)
    for key in sorted(numbers):
        # L_0: a root found two ways (bisection there, brentq on a closed form here) agrees to 1e-9 relative
        rtol = 1e-9 if key.endswith("/L0") else RTOL
        np.testing.assert_allclose(s[key], expected[key], rtol=rtol, atol=0, err_msg=key)
    for name in ("n_events", "n_large", "n_recurrences", "fraction_large", "mode_tnu", "n_creep"):
        np.testing.assert_array_equal(s[f"points/numbers/{name}"][:, 0], expected[f"points/numbers/{name}"][:, 0])
    assert s["points/peaks"].shape == expected["points/peaks"].shape
    np.testing.assert_array_equal(s["points/peaks"][..., 0], expected["points/peaks"][..., 0])
    np.testing.assert_allclose(s["points/peaks"], expected["points/peaks"], rtol=RTOL, atol=0, err_msg="peaks")


def check_partial(statement, partial, paths):
    """The `partial` attribute: empty for finished runs; else it gives the events reduced of
    those expected and names exactly the unfinished catalogs."""
    written, expected, unfinished = partial
    if not unfinished:
        assert statement == ""
        return
    assert statement.startswith("PARTIAL") and f" {written} of {expected} events" in statement
    for path in paths:
        assert (f"{path} (" in statement) == (path in unfinished), (path, statement)
