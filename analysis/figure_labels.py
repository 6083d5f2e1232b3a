"""The words of the summaries' figures: a summary's name, the legend labels of their points (the parameters
that differ between them), and the figure's title (events per point, mu_c, window, what the bands resample,
and a line for each partial reduction)."""
import os

from . import summary as summary_file
from .geometry import CHAIN, GEOMETRIES
from .reduce import GEOMETRY_PARAMS, PARAMS
from .report import level_text, partial_text, size_text

def summary_name(path):
    """A summary's name in labels and titles: its file name without .summary.h5 (or .h5)."""
    base = os.path.basename(str(path))
    return base.removesuffix(".h5").removesuffix(".summary")


def legend_labels(summaries, names=None):
    """(keys, labels) for the points of all `summaries`, in order (summary by summary).

    keys: the parameters that differ between the plotted points (in PARAMS order; ["b"] if
    none do); a label gives their values, e.g. "N = 1600, b = 40" (6 significant digits, or
    all where that is needed to tell two points apart). A point whose parameters appear in
    several summaries gets the summary's name appended, "b = 20 (run2)" (names: one per
    summary, default "summary 1", "summary 2", ...). Summaries that hold a plane add its M and l_across to the
    parameters, and points of several geometries are told apart by it as by the law: "lattice: b = 20".
    """
    names = list(names) if names is not None else [f"summary {j + 1}" for j in range(len(summaries))]
    params = list(PARAMS) + [k for k in GEOMETRY_PARAMS if k != "geometry"
                             and any(f"points/{k}" in s for s in summaries)]
    owner, rows = [], []
    for j, s in enumerate(summaries):
        geometries = summary_file.point_geometries(s)
        for i in range(len(s["points/N"])):
            owner.append(j)
            # None for a key of another friction law (NaN in the summary, which equals nothing), or of a plane
            # where the summary holds none
            own = GEOMETRIES[geometries[i]].keys     # (a chain's point has no M, l_across of its own)
            rows.append(tuple(None if v != v else v for v in (s[f"points/{k}"][i].item() if f"points/{k}" in s
                                                              and (k in PARAMS or k in own) else None
                                                              for k in params))
                        + (str(geometries[i]), str(summary_file.point_laws(s)[i])))
    keys = [k for n, k in enumerate(params) if len({r[n] for r in rows}) > 1] or ["b"]
    laws = len({r[-1] for r in rows}) > 1      # points of several laws: "slip: b = 20"
    shapes = len({r[-2] for r in rows}) > 1    # of several geometries: "lattice: b = 20"
    for exact in (False, True):
        labels = [(f"{r[-1]}: " if laws else "") + (f"{r[-2]}: " if shapes else "")
                  + ", ".join(f"{k} = {repr(r[params.index(k)]) if exact else format(r[params.index(k)], 'g')}"
                              for k in keys if r[params.index(k)] is not None) for r in rows]
        if all(labels[a] != labels[b] or rows[a] == rows[b]
               for a in range(len(rows)) for b in range(a)):
            break
    if any("points/region" in s for s in summaries):   # regions: their drawn keys, then what differs
        regions = [s["points/region_label"][i] if "points/region" in s else "single fault" for s in summaries
                   for i in range(len(s["points/N"]))]
        labels = [f"{r}; {label}" if label else r for r, label in zip(regions, labels)]
    repeated = {r for r in rows if rows.count(r) > 1}
    labels = [f"{label} ({names[j]})" if r in repeated else label
              for label, r, j in zip(labels, rows, owner)]
    return keys, labels


def points_of(summaries):
    """[(summary, point index)] of every plotted point."""
    return [(s, i) for s in summaries for i in range(len(s["points/N"]))]


def _values(values, fmt="{}"):
    """Distinct values, " / " between them."""
    return " / ".join(dict.fromkeys(fmt.format(v) for v in values))


def _units(s):
    """What a summary's bands resample: "20 stretches", "4 seeds", "200 faults" (or a range of counts)."""
    words = {"blocks": "stretches", "seeds": "seeds", "faults": "faults"}
    return " / ".join(dict.fromkeys(
        f"{min(n)}-{max(n)} {words[m]}" if min(n) != max(n) else f"{n[0]} {words[m]}"
        for m in dict.fromkeys(s["points/method"])
        for n in [[int(u) for u, k in zip(s["points/units"], s["points/method"]) if k == m]]))


def _shapes(summaries):
    """' (lattice 8 x 6)', N x M blocks (' / ' between several), where a summary holds a plane; '' for chains."""
    if not any("points/geometry" in s for s in summaries):
        return ""
    return " (" + _values(
        f"{g} {int(s['points/N'][i])} x {int(s['points/M'][i])}" if g != CHAIN else CHAIN
        for s in summaries for i, g in enumerate(summary_file.point_geometries(s))) + ")"


def title_text(summaries, names, title=None, figure=None):
    """The figure's title: `title` (then the description below) or by default the description
    alone: the friction law(s), what the figure rests on (statistics.Figure.describe; by default the events per
    point, mu_c and window) and the bands (never the file names); then one line for each partial reduction
    (events reduced of expected), whatever the title. figure: the statistics.Figure drawn (None: the default)."""
    levels = " / ".join(dict.fromkeys(level_text(s["attrs"]["level"]) for s in summaries))
    bands = f"bands: {levels} bootstrap over {_values(_units(s) for s in summaries)}"
    if figure is not None and not figure.bands:   # a map has no band: its numbers (analysis report) have the intervals
        bands = (f"\nmaps without intervals; the numbers' {levels} intervals (analysis report) over "
                 f"{_values(_units(s) for s in summaries)}")
    # the friction law(s) first: a slip-law figure must not pass for the paper's aging law; nor a plane's a chain's
    laws = f"{_values(str(law) for s in summaries for law in summary_file.point_laws(s))} law{_shapes(summaries)}: "
    if figure is not None and figure.describe is not None:
        description = f"{laws}{figure.describe(summaries)}; {bands}"
    else:
        description = (f"{laws}{_values(size_text(s) for s in summaries)}, "
                       f"mu_c = {_values((s['attrs']['mu_c'] for s in summaries), '{:g}')}, "
                       f"window = {_values((s['attrs']['window'] for s in summaries), '{:g}')} blocks; {bands}")
    partials = []
    for s, name in zip(summaries, names):
        partial = partial_text(s).split(";")[0]
        if partial:
            partials.append(partial if len(summaries) == 1 else f"{name}: {partial}")
    return "\n".join(([description] + partials) if title is None else ([title] + partials + [description]))
