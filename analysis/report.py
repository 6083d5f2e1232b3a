"""The summary numbers of every parameter point as a text table."""
import numpy as np

from . import reduce, summary
from .geometry import GEOMETRIES
from .reduce import GEOMETRY_PARAMS, LAYOUT
from .statistics import holds, number_lines, refusal

# every number's label in the report (the statistics': Number.label, else its name)
LABELS = {n.name: n.label or n.name for n in LAYOUT.numbers}


def level_text(level):
    """An interval level as a percentage: 0.975 -> "97.5%" (int(100 * level) would say 97%)."""
    return f"{100 * level:g}%"


def varying(s):
    """Model parameters that differ between points (for labels and legends)."""
    return [p for p in summary.point_keys(s) if len(np.unique(s[f"points/{p}"])) > 1] or ["b"]


def point_label(s, i, keys=None, law=False):
    """"b = 20", or "slip: b = 20" where the summary's points are of more than one law or `law` asks for it; in a
    summary that holds a plane, the point's geometry after the law, "lattice: N = 8, ..., M = 6, l_across = 3" (a
    chain's point there without the plane's keys)."""
    keys = keys or varying(s)
    geometry = summary.point_geometries(s)[i]
    theirs = set(GEOMETRY_PARAMS) - set(GEOMETRIES[geometry].keys)    # keys of another geometry than the point's
    text = ", ".join(f"{k} = {s[f'points/{k}'][i]:g}" for k in keys
                     if k not in theirs and not np.isnan(s[f'points/{k}'][i]))     # NaN: a key of another law
    if "points/geometry" in s:
        text = f"{geometry}: {text}"
    laws = summary.point_laws(s)
    return f"{laws[i]}: {text}" if law or len(set(laws)) > 1 else text


def unreliable(s, i):
    """A warning if point i's intervals rest on fewer than MIN_UNITS resampling units, else ''."""
    return reduce.unreliable(int(s["points/units"][i]), s["points/method"][i])


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


def table(s):
    """The report: the summary's line, each statistic's lines about the whole summary, then per point its line and
    each statistic's lines (Statistic.report; by default its numbers with their intervals), in the statistics'
    order, of those the summary holds; a statistic that refuses the point's geometry, its one line why
    (statistics.refusal). A partial reduction says so on its first line."""
    a = s["attrs"]
    held = [st for st in LAYOUT.statistics if holds(s, st)]
    lines = [partial_text(s)] if partial_text(s) else []
    lines += [f"summary of {a['catalog']}: mu_c = {a['mu_c']}, window = {a['window']} blocks, "
              f"GR b above mu = {a['b_cut']}, {level_text(a['level'])} intervals from "
              f"{a['bootstrap']} bootstrap resamples"]
    lines += [line for st in held if st.report_header is not None for line in st.report_header(s)]
    lines.append("")
    keys, geometries = summary.point_keys(s), summary.point_geometries(s)
    for i in range(len(s["points/N"])):
        if "points/region" in s:    # a regional reduction (analysis/region.py)
            lines.append(f"region {i}: {s['points/region_label'][i]}; {point_label(s, i, keys, law=True)}  "
                         f"(resampling {s['points/method'][i]}, {s['points/units'][i]} units; "
                         f"window {s['points/region_span'][i]:.6g} T*nu per fault)")
        else:
            lines.append(f"point {i}: " + point_label(s, i, keys, law=True) +
                         f"  (resampling {s['points/method'][i]}, {s['points/units'][i]} units)")
        if unreliable(s, i):
            lines.append(f"    WARNING: {unreliable(s, i)}")
        for st in LAYOUT.statistics:
            if refusal(st, geometries[i]):
                lines.append(f"    {refusal(st, geometries[i])}")
                continue
            # (a statistic a summary holds only in part, an older format's, shows the numbers it has)
            lines += st.report(s, i) if st.report is not None and holds(s, st) else number_lines(st, s, i)
        lines.append("")
    return "\n".join(lines)
