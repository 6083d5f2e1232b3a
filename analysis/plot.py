"""Figures from one or more summaries: each statistic's own (statistics.Figure), `analysis plot --figure NAME`:
today R(mu) of every point overlaid, with bootstrap bands (magnitude); recurrence-time distributions, one panel
per point, each with its highest peak enlarged in an inset (recurrence); the slow side, the creep episodes' size
and duration densities and the aseismic slip fraction against the swept parameter (creep); the seismicity around
large events, one map per point of the rate at (distance from a mainshock's epicenter, time from its onset) over
the point's background rate (seismicity).

Points of several summaries are labelled by the parameters that differ between all the plotted points
(figure_labels.py: legend_labels, and the title); drawing.py draws the bands and places the insets.
Nothing drawn covers data: legends sit outside the axes, and an inset goes where the panel's
curves and bands stay below it over its whole width (place_inset; tests/test_figures.py checks
every figure in display coordinates). No text is smaller than FONT points."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from .drawing import DPI, save
from .figure_labels import legend_labels, summary_name, title_text
from .reduce import LAYOUT
from .statistics import refusal
from .summary import SummaryError, point_geometries

# every statistic's figures, by name (`analysis plot --figure NAME`), and the statistic each is of
FIGURES = {f.name: f for st in LAYOUT.statistics for f in st.figures}
OWNER = {f.name: st for st in LAYOUT.statistics for f in st.figures}


def figure(summaries, kind, title=None, names=None):
    """The figure `kind` (a name of FIGURES) of the points of one summary (a dict from summary.read) or several (a
    list), laid out and ready to save. names: the summaries' paths or names (to tell points of equal parameters
    apart)."""
    if isinstance(summaries, dict):
        summaries = [summaries]
    names = ([summary_name(n) for n in names] if names is not None
             else [f"summary {j + 1}" for j in range(len(summaries))])
    for s, name in zip(summaries, names):    # a statistic that refuses a point's geometry has nothing to draw of it
        why = [refusal(OWNER[kind], g) for g in dict.fromkeys(point_geometries(s)) if refusal(OWNER[kind], g)]
        if why:
            raise SummaryError(f"{name}: no figure {kind!r}: {why[0]}; plot the chains' summaries apart")
    keys, labels = legend_labels(summaries, names)
    chosen = FIGURES[kind]
    fig = plt.figure(figsize=chosen.size(len(labels)), dpi=DPI)
    try:
        chosen.draw(summaries, fig, keys, labels, names, title_text(summaries, names, title, chosen))
    except BaseException:
        plt.close(fig)
        raise
    return fig


def plot(summaries, figure_kind, path, title=None, names=None):
    """Draw figure(summaries, figure_kind, title, names) into `path`."""
    save(figure(summaries, figure_kind, title, names), path)
