"""The summary numbers of every parameter point as a text table."""
import numpy as np

from . import reduce, summary
from .reduce import LAYOUT, NUMBERS, PARAMS

CREEP_NUMBERS = tuple(n.name for s in LAYOUT.statistics if s.name == "creep" for n in s.numbers)   # the slow side's

LABELS = {
    "n_events": "events", "n_large": "large", "fraction_large": "frac(mu>=mu_c)",
    "n_recurrences": "recurrences", "mean_tnu": "mean T*nu", "mode_tnu": "mode T*nu",
    "mean_tnu_interior": "mean T*nu (int.)", "gr_b": "GR b", "gr_b_se": "GR b std. error",
    "ks_gr": "KS to GR",
    "n_creep": "creep episodes", "creep_share": "creep share (rows)", "taken_over_share": "taken over",
    "aseismic_fraction": "aseismic fraction",
    **{n.name: n.label for n in LAYOUT.numbers if n.label},   # the statistics' own labels
}


def level_text(level):
    """An interval level as a percentage: 0.975 -> "97.5%" (int(100 * level) would say 97%)."""
    return f"{100 * level:g}%"


def varying(s):
    """Model parameters that differ between points (for labels and legends)."""
    return [p for p in PARAMS if len(np.unique(s[f"points/{p}"])) > 1] or ["b"]


def point_label(s, i, keys=None, law=False):
    """"b = 20", or "slip: b = 20" where the summary's points are of more than one law or `law` asks for it."""
    keys = keys or varying(s)
    text = ", ".join(f"{k} = {s[f'points/{k}'][i]:g}" for k in keys
                     if not np.isnan(s[f'points/{k}'][i]))     # NaN: a key of another law
    laws = summary.point_laws(s)
    return f"{laws[i]}: {text}" if law or len(set(laws)) > 1 else text


def unreliable(s, i):
    """A warning if point i's intervals rest on fewer than MIN_UNITS resampling units, else ''."""
    return reduce.unreliable(int(s["points/units"][i]), s["points/method"][i])


def _fmt(est, lo, hi):
    if not np.isfinite(est):
        return "-"
    if np.isfinite(lo):
        return f"{est:.4g} [{lo:.4g}, {hi:.4g}]"
    return f"{est:.4g}"


def count_text(n):
    """An event count as it is read: 8000, 2e5, 1.2e4 (exact, else all digits)."""
    n = int(n)
    mantissa, exponent = f"{n:.1e}".split("e")
    if n >= 10000 and float(mantissa) * 10 ** int(exponent) == n:
        return f"{float(mantissa):g}e{int(exponent)}"
    return str(n)


def events_per_task(s):
    """Events each task of the summary contributed (reduced, not discarded), (tasks,)."""
    return s["per_task/numbers"][:, :, LAYOUT.column("numbers", "n_events")].sum(axis=1).astype(np.int64)


def events_per_point(s):
    """Events each point rests on, (points,)."""
    return np.bincount(s["tasks/point"], weights=events_per_task(s), minlength=len(s["points/N"])).astype(np.int64)


def size_text(s):
    """The events behind each point: "2e5 events per point", "8000 events per point (4 seeds x
    2000)", or their range when the points differ: "2000-8000 events per point"."""
    per_point = events_per_point(s)
    per_task = events_per_task(s)
    seeds = np.bincount(s["tasks/point"], minlength=len(per_point))
    if len(set(per_point)) > 1:
        return f"{count_text(per_point.min())}-{count_text(per_point.max())} events per point"
    text = f"{count_text(per_point[0])} events per point"
    if len(set(seeds)) == 1 and len(set(per_task)) == 1 and seeds[0] > 1:
        text += f" ({seeds[0]} seeds x {count_text(per_task[0])})"
    return text


def partial_text(s):
    """The statement of a partial reduction ("" for a complete one)."""
    return str(s["attrs"].get("partial", ""))


def creep_lines(s, i):
    """The slow side of point i: its creep numbers with intervals, one line saying it has no creep
    episodes, or nothing for a summary that did not reduce them (format 2)."""
    if not summary.has_creep(s):
        return []
    if not summary.creeping(s)[i]:
        return [f"    {'creep episodes':>18s}  none"]
    return [f"    {LABELS[name]:>18s}  {_fmt(*s[f'points/numbers/{name}'][i])}" for name in CREEP_NUMBERS]


def table(s):
    """The report; a partial reduction says so on its first line."""
    a = s["attrs"]
    lines = [partial_text(s)] if partial_text(s) else []
    lines += [f"summary of {a['catalog']}: mu_c = {a['mu_c']}, window = {a['window']} blocks, "
              f"GR b above mu = {a['b_cut']}, {level_text(a['level'])} intervals from "
              f"{a['bootstrap']} bootstrap resamples"]
    if summary.has_seismicity(s):
        lines.append(f"seismicity around mainshocks (mu >= mu_c): near = distance < {a['seis_near']:g} blocks, ring = "
                     f"up to {a['seis_ring']:g}; just before/after = {a['seis_short']:g} T*nu, some time before = "
                     f"from -{a['seis_long']:g}; rates per mainshock per block per T*nu")
    lines.append("")
    for i in range(len(s["points/N"])):
        if "points/region" in s:    # a regional reduction (analysis/region.py)
            lines.append(f"region {i}: {s['points/region_label'][i]}; {point_label(s, i, list(PARAMS), law=True)}  "
                         f"(resampling {s['points/method'][i]}, {s['points/units'][i]} units; "
                         f"window {s['points/region_span'][i]:.6g} T*nu per fault)")
        else:
            lines.append(f"point {i}: " + point_label(s, i, list(PARAMS), law=True) +
                         f"  (resampling {s['points/method'][i]}, {s['points/units'][i]} units)")
        if unreliable(s, i):
            lines.append(f"    WARNING: {unreliable(s, i)}")
        for name in NUMBERS:
            if name not in CREEP_NUMBERS and f"points/numbers/{name}" in s:   # (older summaries lack newer ones)
                est, lo, hi = s[f"points/numbers/{name}"][i]
                lines.append(f"    {LABELS[name]:>18s}  {_fmt(est, lo, hi)}")
        peaks = [row for row in s["points/peaks"][i] if np.isfinite(row[0])]
        lines.append(f"    {'T*nu peaks':>18s}  " + ("; ".join(_fmt(*row) for row in peaks) or "-"))
        lines += creep_lines(s, i)
        lines.append("")
    return "\n".join(lines)
