"""Figures from a summary: R(mu) with bootstrap bands; recurrence-time distributions."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .report import level_text, point_label, varying  # noqa: E402
from .stats import centers  # noqa: E402


def _band(ax, x, y, lo, hi, label, color, log=False, style="-"):
    ok = np.isfinite(y) & ((y > 0) if log else True)
    ax.plot(x[ok], y[ok], style, color=color, label=label, lw=1.4)
    okb = ok & np.isfinite(lo) & np.isfinite(hi)
    if okb.any():
        # on a log axis a lower bound of 0 is drawn down to the axis' bottom
        low = np.where(lo > 0, lo, 1e-300) if log else lo
        ax.fill_between(x[okb], low[okb], hi[okb], color=color, alpha=0.25, lw=0)


def magnitude(s, ax):
    x = centers(s["bins/mu"])
    keys = varying(s)
    for i in range(len(s["points/N"])):
        _band(ax, x, s["points/mu_density"][i], s["points/mu_lo"][i], s["points/mu_hi"][i],
              point_label(s, i, keys), f"C{i}", log=True)
    ax.set_yscale("log")
    positive = s["points/mu_density"][s["points/mu_density"] > 0]
    if positive.size:
        ax.set_ylim(positive.min() / 3, positive.max() * 3)
    ax.set_xlabel(r"magnitude $\mu$")
    ax.set_ylabel(r"$R(\mu)$")
    ax.legend(title="varying " + ", ".join(keys), fontsize=8)


def recurrence(s, fig):
    n = len(s["points/N"])
    cols = min(n, 2)
    rows = int(np.ceil(n / cols))
    x = centers(s["bins/tnu"])
    keys = varying(s)
    for i in range(n):
        ax = fig.add_subplot(rows, cols, i + 1)
        _band(ax, x, s["points/tnu_density"][i], s["points/tnu_lo"][i], s["points/tnu_hi"][i],
              "all large events", "C0")
        _band(ax, x, s["points/tnu_interior_density"][i], s["points/tnu_interior_lo"][i],
              s["points/tnu_interior_hi"][i], "interior events", "C3", style="--")
        ax.set_title(point_label(s, i, keys), fontsize=9)
        ax.set_xlabel(r"$T\nu$")
        ax.set_ylabel(r"$P(T\nu)$")
        ax.legend(fontsize=7, loc="upper right")
        peak = s["points/peaks"][i][0][0]
        if np.isfinite(peak):
            inset = ax.inset_axes([0.55, 0.35, 0.4, 0.35])
            w = 6 * (x[1] - x[0])
            near = (x > peak - w) & (x < peak + w)
            _band(inset, x[near], s["points/tnu_density"][i][near], s["points/tnu_lo"][i][near],
                  s["points/tnu_hi"][i][near], None, "C0")
            _band(inset, x[near], s["points/tnu_interior_density"][i][near],
                  s["points/tnu_interior_lo"][i][near], s["points/tnu_interior_hi"][i][near],
                  None, "C3", style="--")
            inset.tick_params(labelsize=6)
            inset.set_title("main peak", fontsize=6)


def plot(s, figure, path, title=None):
    if figure == "magnitude":
        fig, ax = plt.subplots(figsize=(6, 4.5))
        magnitude(s, ax)
    else:
        n = len(s["points/N"])
        fig = plt.figure(figsize=(5.5 * min(n, 2), 4 * int(np.ceil(n / 2))))
        recurrence(s, fig)
    a = s["attrs"]
    fig.suptitle(title or f"{a['catalog']}  (bands: {level_text(a['level'])} bootstrap)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
