"""The summary numbers of every parameter point as a text table."""
import numpy as np

from . import reduce
from .reduce import NUMBERS, PARAMS

LABELS = {
    "n_events": "events", "n_large": "large", "fraction_large": "frac(mu>=mu_c)",
    "n_recurrences": "recurrences", "mean_tnu": "mean T*nu", "mode_tnu": "mode T*nu",
    "mean_tnu_interior": "mean T*nu (int.)", "gr_b": "GR b", "gr_b_se": "GR b std. error",
    "ks_gr": "KS to GR",
}


def level_text(level):
    """An interval level as a percentage: 0.975 -> "97.5%" (int(100 * level) would say 97%)."""
    return f"{100 * level:g}%"


def varying(s):
    """Model parameters that differ between points (for labels and legends)."""
    return [p for p in PARAMS if len(np.unique(s[f"points/{p}"])) > 1] or ["b"]


def point_label(s, i, keys=None):
    keys = keys or varying(s)
    return ", ".join(f"{k} = {s[f'points/{k}'][i]:g}" for k in keys
                     if not np.isnan(s[f'points/{k}'][i]))     # NaN: a key of another law


def unreliable(s, i):
    """A warning if point i's intervals rest on fewer than MIN_UNITS resampling units, else ''."""
    return reduce.unreliable(int(s["points/units"][i]), s["points/method"][i])


def _fmt(est, lo, hi):
    if not np.isfinite(est):
        return "-"
    if np.isfinite(lo):
        return f"{est:.4g} [{lo:.4g}, {hi:.4g}]"
    return f"{est:.4g}"


def partial_text(s):
    """The statement of a partial reduction ("" for a complete one)."""
    return str(s["attrs"].get("partial", ""))


def table(s):
    """The report; a partial reduction says so on its first line."""
    a = s["attrs"]
    lines = [partial_text(s)] if partial_text(s) else []
    lines += [f"summary of {a['catalog']}: mu_c = {a['mu_c']}, window = {a['window']} blocks, "
              f"GR b above mu = {a['b_cut']}, {level_text(a['level'])} intervals from "
              f"{a['bootstrap']} bootstrap resamples", ""]
    for i in range(len(s["points/N"])):
        lines.append(f"point {i}: " + point_label(s, i, list(PARAMS)) +
                     f"  (resampling {s['points/method'][i]}, {s['points/units'][i]} units)")
        if unreliable(s, i):
            lines.append(f"    WARNING: {unreliable(s, i)}")
        for name in NUMBERS:
            est, lo, hi = s[f"points/numbers/{name}"][i]
            lines.append(f"    {LABELS[name]:>18s}  {_fmt(est, lo, hi)}")
        peaks = [row for row in s["points/peaks"][i] if np.isfinite(row[0])]
        lines.append(f"    {'T*nu peaks':>18s}  " + ("; ".join(_fmt(*row) for row in peaks) or "-"))
        lines.append("")
    return "\n".join(lines)
