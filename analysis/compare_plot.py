"""The friction-law comparison's figures (analysis/compare.py): the rupture-length distribution
R(log10 n), R(mu) on each law's own magnitude scale, and the recurrence times over their median."""
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from .drawing import band, save
from .stats import centers

TNU_BINS = np.linspace(0.0, 5.0, 101)      # T / median(T)


def _colors(n):
    return plt.rcParams["axes.prop_cycle"].by_key()["color"] * (n // 10 + 1)


def _with_events(p):
    """A point's legend label with its sample: the events its distributions are made of."""
    return f"{p['label']} ({int(p['numbers'][0])} events)"


def _legend(ax):
    """The legend right of the axes, on no curve (six laws' points with their samples are long labels)."""
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)


def _chains(points):
    """' at N = 800' (the points' chain length), or ' at N = 400-1600'; with a plane among them, ' of 48 blocks'."""
    sizes = sorted({int(p["n_blocks"]) for p in points})
    span = f"{sizes[0]}" if len(sizes) == 1 else f"{sizes[0]}-{sizes[-1]}"
    return f" of {span} blocks" if any("geometry" in p.get("params", {}) for p in points) else f" at N = {span}"


def figures(points, opt, out_dir, mu_edges):
    """size.png, magnitude.png and recurrence.png of the points; mu_edges: the magnitude bins of their
    R(mu) (the options' mu_edges, passed in)."""
    colors = _colors(len(points))
    at = _chains(points)

    fig, ax = plt.subplots(figsize=(9.6, 4.4))
    for p, color in zip(points, colors):
        e = p["size_edges"]
        x = np.sqrt(e[:-1] * (e[1:] - 1.0))          # geometric middle of the integers of the bin
        band(ax, x, p["size_density"], p["size_lo"], p["size_hi"], _with_events(p), color, log=True, style=".-")
        tau = p["numbers"][3]
        if np.isfinite(tau):
            n = np.arange(opt.n_min, opt.n_large, dtype=float)
            law = n ** -tau
            ax.plot(n, p["fit_share"] * law / law.sum() * n * np.log(10.0), ":", color=color, lw=1)
    ax.axvline(opt.n_large, color="0.5", lw=0.8, ls="--")
    ax.set_ylim(bottom=min(p["size_density"][p["size_density"] > 0].min() for p in points) / 3)
    ax.set(xscale="log", yscale="log", xlabel="blocks slipped in an event, n", ylabel="R(log10 n)",
           title=f"rupture length{at} (dotted: power law fitted below n = {opt.n_large})")
    _legend(ax)
    fig.tight_layout()
    save(fig, os.path.join(out_dir, "size.png"))

    fig, ax = plt.subplots(figsize=(9.6, 4.4))
    for p, color in zip(points, colors):
        band(ax, centers(mu_edges), p["mu_density"], p["mu_lo"], p["mu_hi"], _with_events(p), color, log=True)
    lowest = min(p["mu_density"][p["mu_density"] > 0].min() for p in points)
    highest = max(np.nanmax(p["mu_density"]) for p in points)
    # (a lower bound of 0 would stretch the axis to 1e-300; the top is set too: autoscaling after a bound cut
    # the Carlson-Langer curves' small-mu end)
    ax.set_ylim(bottom=lowest / 3, top=highest * 3)
    ax.set(yscale="log", xlabel="mu = log10(total slip) (each law's own scale)", ylabel="R(mu)",
           title=f"magnitude distribution{at}")
    _legend(ax)
    fig.tight_layout()
    save(fig, os.path.join(out_dir, "magnitude.png"))

    fig, ax = plt.subplots(figsize=(9.6, 4.4))
    x = centers(TNU_BINS)
    for p, color in zip(points, colors):
        T = p["T"]
        if len(T) >= 2:
            h, _ = np.histogram(T / np.median(T), TNU_BINS)
            ax.plot(x, h / len(T) / np.diff(TNU_BINS), color=color, lw=1.4,
                    label=f"{p['label']} ({len(T)} recurrences, CV {p['numbers'][6]:.2f})")
    ax.plot(x, np.log(2.0) * 2.0 ** -x, "k:", lw=1, label="Poisson (exponential)")
    ax.set(xlabel=f"T / median(T), large events (n >= {opt.n_large}) within {opt.window} blocks",
           ylabel="density", title=f"local recurrence time{at}")
    _legend(ax)
    fig.tight_layout()
    save(fig, os.path.join(out_dir, "recurrence.png"))
