"""The plane's events against the claims of the two-dimensional model's paper (docs/plane.md):

    python -m examples.plane.study CATALOG[@K] [...] [--histories CATALOG ...] [--events K] [-o docs/plane/study]

Each CATALOG holds tasks of a chain or a plane (its *.partial file while its run goes on: the numbers then say how
many events they rest on; CATALOG@K: the first K inertial events of each of its tasks, --events K: of every
catalog's); tasks of the same shape and b (seeds of one point, in one catalog or several) pool, one's events after
the other's (a plane's l_across, where it is not l, tells its points apart too). For each, of its inertial events
(the creep episodes between them are counted):

- R(mu): the magnitudes in bins of 0.01; the fraction of events that slip every block (a plane's characteristic
  event); Gutenberg-Richter over the best two decades of mu and over the top two decades (KS distance and b,
  examples/populations/answer.py's fits, at least 1000 events in a stretch);
- the fraction of events that slip every block, and of those whose extent spans the fault both ways;
- the large events (LARGE_BLOCKS blocks or more): of those that do not run from one end of the fault to the other,
  how often their epicenter lies at an end of the rupture's extent along strike (within a tenth of its length:
  UNILATERAL; a uniformly placed epicenter is there 1 time in 5); of those that reach none of the fault's edges
  (a shape the edges did not cut), how often their epicenter lies at a side of their bounding box (within a tenth
  of its extent of one of its four sides; against the fraction of the box's blocks that are), the median of their
  extent along over across strike (anisotropy along
  strike), of the longer extent over the shorter one (elongation, either way) and of the blocks slipped over their
  bounding box (fill: a disc fills pi / 4 of it, a jagged zone less), overall and in bins of size (blocks slipped,
  SIZE_BINS); of all of them, how often the epicenter lies near the fault's own edges (within EDGE_BAND of its
  length of an end, or of its width of an edge), beside a uniformly placed epicenter's chance;
- intervals: 95 %, over the catalog cut into CHUNKS stretches of consecutive events resampled (a block bootstrap:
  events close in time are not independent).

With --histories (catalogs of planes run with output.history; the histories of every task, pooled by plane and
b): each kept event's rupture zone (the blocks that slipped), whether its epicenter lies on the zone's
rim (a slipped block beside one that did not slip or beside the plane's edge; against the fraction of the zone's
blocks on its rim, what a uniformly placed epicenter gives), whether it lies next to the edge of one of the PAST
kept zones of its seed before it, and, of the first plane given, two figures of the largest kept event that slips
at most half the plane (else the largest that does not slip all of it): its slip on the plane and the time each
block started to slip (the rupture's growth).

Writes OUT.json (every number), OUT.md (the table) and OUT_{mu,zone,growth}.png.
"""
import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

from analysis.drawing import FONT, palette, save
from analysis.stats import percentile_interval
from ensemble.model.workspace import KIND_EVENT
from ensemble.store import reader

from examples.populations.answer import best_decades, top_decades

EDGES = np.round(np.arange(0.0, 9.0 + 1e-9, 0.01), 2)
LARGE_BLOCKS = 100      # a large event slips at least this many blocks (and not every block)
UNILATERAL = 0.1        # an epicenter within this fraction of the extent's length from one of its ends
EDGE_BAND = 0.1         # ... within this fraction of the fault's length (width) from its ends (edges)
SIZE_BINS = (100, 200, 400, 800, 1600, math.inf)     # blocks slipped: the shape's bins of size
PAST = 10               # an epicenter next to the zones of this many kept events before it
CHUNKS = 20             # stretches of consecutive events the bootstrap resamples
RESAMPLES = 400
LEVEL = 0.95


def shape(tasks, k=0):
    """(geometry, N, M) of a catalog's task k."""
    geometry = tasks["geometry"][k]
    geometry = geometry.decode() if isinstance(geometry, bytes) else str(geometry)
    return geometry, int(tasks["N"][k]), int(tasks["M"][k])


def numbers(ev, n_blocks):
    """The catalog's numbers from its events (dict of columns)."""
    mu, slipped, N = ev["mu"], ev["n_slipped"], ev["N"]
    M = n_blocks // N
    counts = np.histogram(mu, EDGES)[0]
    best, top = best_decades(counts, EDGES), top_decades(counts, EDGES)
    length = ev["last"] - ev["first"] + 1
    width = ev["across_last"] - ev["across_first"] + 1
    large = slipped >= LARGE_BLOCKS
    # the ends along strike are the rupture's own where it does not run from one end of the fault to the other;
    # its shape is its own where it reaches none of the fault's edges (ends and, on a plane, sides)
    own_ends = large & (length < N)
    own_shape = large & (ev["first"] > 0) & (ev["last"] < N - 1)
    if M > 1:
        own_shape &= (ev["across_first"] > 0) & (ev["across_last"] < M - 1)
    x, y = ev["epicenter"] % N, ev["epicenter"] // N
    at_end = np.minimum(x - ev["first"], ev["last"] - x) <= UNILATERAL * np.maximum(length - 1, 1)
    # on a plane, at a side of its bounding box (within a tenth of its extent of one of its four sides), against
    # the fraction of the box's blocks that are (a uniformly placed epicenter's chance)
    at_side = at_end | (np.minimum(y - ev["across_first"], ev["across_last"] - y)
                        <= UNILATERAL * np.maximum(width - 1, 1))
    band = [np.minimum(n, 2 * (np.floor(UNILATERAL * np.maximum(n - 1, 1)) + 1)) / n for n in (length, width)]
    side_chance = 1 - (1 - band[0]) * (1 - band[1])
    # the epicenter near the fault's own edges: within EDGE_BAND of its length of an end, or of its width of an
    # edge across strike (a plane); a uniformly placed one is there with the chance `edge_chance`
    near = (np.minimum(x, N - 1 - x) < EDGE_BAND * N) | ((M > 1) & (np.minimum(y, M - 1 - y) < EDGE_BAND * M))
    elongation = np.maximum(length, width) / np.minimum(length, width)
    fill = slipped / (length * width)
    bins = np.digitize(slipped, SIZE_BINS) - 1

    def median(values, where):
        return float(np.median(values[where])) if where.any() else math.nan

    shapes = {"along_over_across": length / width, "elongation": elongation, "fill": fill}
    by_size = {"count": [int(np.sum(own_shape & (bins == k))) for k in range(len(SIZE_BINS) - 1)],
               **{key: [median(v, own_shape & (bins == k)) for k in range(len(SIZE_BINS) - 1)]
                  for key, v in shapes.items()}}
    return {"events": int(len(mu)), "whole": float(np.mean(slipped == n_blocks)),
            "spanning": float(np.mean((length == N) & (width == M))),
            "best_two_decades": dict(zip(("ks", "from_mu", "b"), best)),
            "top_two_decades": dict(zip(("ks", "from_mu", "b"), top)),
            "large": int(large.sum()), "large_own_ends": int(own_ends.sum()), "large_own_shape": int(own_shape.sum()),
            "unilateral": float(np.mean(at_end[own_ends])) if own_ends.any() else math.nan,
            "box_side": float(np.mean(at_side[own_shape])) if own_shape.any() else math.nan,
            "box_side_chance": float(np.mean(side_chance[own_shape])) if own_shape.any() else math.nan,
            "near_edge": float(np.mean(near[large])) if large.any() else math.nan,
            "edge_chance": 1 - (1 - 2 * EDGE_BAND) ** (2 if M > 1 else 1),
            "anisotropy_median": median(length / width, own_shape),
            "elongation_median": median(elongation, own_shape), "fill_median": median(fill, own_shape),
            "by_size": by_size}


def stretches(lengths):
    """The bootstrap's stretches of consecutive events (index arrays) of seeds of these lengths, one after another:
    about CHUNKS in all, each seed cut into its share of them (at least one), none across the seam of two seeds."""
    starts = np.cumsum([0] + list(lengths))
    return [cut for s, n in zip(starts, lengths)
            for cut in np.array_split(np.arange(s, s + n), max(1, round(CHUNKS * n / starts[-1])))]


def with_intervals(ev, n_blocks, rng, lengths=None):
    """numbers() of all the events, each number with its block-bootstrap interval.

    lengths: the events of each seed, one seed's after another's (default: one seed). Each seed is cut into its
    share of the CHUNKS stretches, so that no stretch spans the seam between two seeds."""
    whole = numbers(ev, n_blocks)
    cuts = stretches(lengths or [len(ev["mu"])])
    draws = []
    for _ in range(RESAMPLES):
        pick = np.concatenate([cuts[k] for k in rng.integers(0, len(cuts), len(cuts))])
        draws.append(numbers({k: v[pick] if np.ndim(v) else v for k, v in ev.items()}, n_blocks))

    def interval(get):
        return [float(v) for v in percentile_interval(np.array([get(d) for d in draws], dtype=float), LEVEL)]

    for key in ("whole", "spanning", "unilateral", "box_side", "near_edge", "anisotropy_median", "elongation_median",
                "fill_median"):
        whole[f"{key}_interval"] = interval(lambda d, key=key: d[key])
    for key in ("along_over_across", "elongation", "fill"):
        whole["by_size"][f"{key}_interval"] = [interval(lambda d, key=key, k=k: d["by_size"][key][k])
                                               for k in range(len(SIZE_BINS) - 1)]
    for key in ("best_two_decades", "top_two_decades"):
        whole[key]["ks_interval"] = interval(lambda d, key=key: d[key]["ks"])
        whole[key]["b_interval"] = interval(lambda d, key=key: d[key]["b"])
    return whole, np.histogram(ev["mu"], EDGES)[0]


def point_name(tasks, task):
    """The name of a task's point, which its seeds share: geometry, size, b and (on a plane, if not l) l_across."""
    geometry, N, M = shape(tasks, task)
    b = float(tasks["b"][task])
    name = f"chain N = {N}, b = {b:g}" if geometry == "chain" else f"plane {N} x {M}, b = {b:g}"
    if geometry != "chain" and tasks["l_across"][task] != tasks["l"][task]:
        name += f", l_across = {tasks['l_across'][task]:g}"
    return name


def zones(path):
    """Per task of the catalog at `path` that kept histories: (its point's name, N, M, b, its kept events in order:
    row, slip at the end, first-slip time per block, epicenter, mu)."""
    with reader.Reader(path) as cat:
        every = cat.events()
        out = []
        for task in range(len(cat.tasks["N"])):
            _, N, M = shape(cat.tasks, task)
            ev = {k: every[k][every["task"] == task] for k in ("epicenter", "mu")}
            kept = []
            for h in cat.histories(task):
                slip = h["slip"]
                moved = slip > 0.0
                started = np.where(moved.any(axis=0), h["time"][np.argmax(moved, axis=0)], np.nan)
                kept.append({"row": int(h["row"]), "slip": slip[-1], "start": started,
                             "epicenter": int(ev["epicenter"][h["row"]]), "mu": float(ev["mu"][h["row"]])})
            if kept:
                out.append((point_name(cat.tasks, task), N, M, float(cat.tasks["b"][task]), kept))
    return out


def rim(zone, N, M):
    """Blocks of the zone (bool, N x M as rows of N) with a neighbour outside it or beside the plane's edge."""
    z = zone.reshape(M, N)
    padded = np.pad(z, 1, constant_values=False)
    inside = padded[:-2, 1:-1] & padded[2:, 1:-1] & padded[1:-1, :-2] & padded[1:-1, 2:]
    return (z & ~inside).ravel()


def rim_numbers(N, M, kept):
    rows = []
    for k in kept:
        zone = k["slip"] > 0.0
        if zone.sum() < LARGE_BLOCKS or zone.all():
            continue
        edge = rim(zone, N, M)
        rows.append((bool(edge[k["epicenter"]]), edge.sum() / zone.sum()))
    if not rows:
        return {"kept": 0}
    at, share = np.array(rows).T
    return {"kept": len(rows), "epicenter_on_rim": float(at.mean()),
            "epicenter_on_rim_interval": wilson(int(at.sum()), len(rows)), "rim_share_of_zone": float(share.mean())}


def boundary(zone, N, M):
    """The blocks next to the zone's edge inside the plane (bool, N x M as rows of N): the zone's blocks with a
    neighbour outside it and the blocks outside with a neighbour in it; the plane's own edge is no boundary."""
    z = zone.reshape(M, N)
    padded = np.pad(z, 1, mode="edge")          # beyond the plane's edge: the edge block itself
    around = [padded[:-2, 1:-1], padded[2:, 1:-1], padded[1:-1, :-2], padded[1:-1, 2:]]
    differs = np.zeros_like(z)
    for other in around:
        differs |= other != z
    return differs.ravel()


def past_rims(N, M, kept, past=PAST):
    """How often a kept event's epicenter lies next to the edge of one of the `past` kept events before it (in one
    catalog's order: the first events of mu >= history_mu, consecutive), zones that slip the whole plane left out;
    against the same for the other kept events' epicenters (where events start, whenever they do)."""
    hits, chance = [], []
    epicenters = np.array([k["epicenter"] for k in kept])
    for i in range(1, len(kept)):
        band = np.zeros(N * M, bool)
        for k in kept[max(0, i - past):i]:
            zone = k["slip"] > 0.0
            if not zone.all():
                band |= boundary(zone, N, M)
        if not band.any():
            continue
        hits.append(band[epicenters[i]])
        chance.append(band[np.delete(epicenters, i)].mean())
    return hits, chance


def wilson(k, n, z=1.96):
    """The 95 % Wilson interval of a fraction k / n."""
    f, d = k / n, 1 + z * z / n
    centre, half = (f + z * z / (2 * n)) / d, z * math.sqrt(f * (1 - f) / n + z * z / (4 * n * n)) / d
    return [centre - half, centre + half]


def figure_mu(results, hists, path):
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5.2, 4.0))
    centres = (EDGES[:-1] + EDGES[1:]) / 2
    for (name, r), counts, color in zip(results.items(), hists, palette(len(results))):
        width = 10          # bins of 0.1
        c = counts[:len(counts) // width * width].reshape(-1, width).sum(axis=1)
        x = centres[:len(c) * width].reshape(-1, width).mean(axis=1)
        # empty bins break the line; a catalog of few events is drawn as points
        style = dict(ls="-", lw=1) if r["events"] >= 1000 else dict(ls="none", marker="o", ms=3)
        ax.plot(x, np.where(c > 0, c / c.sum() / 0.1, np.nan), color=color, label=f"{name} ({r['events']} events)",
                **style)
    ax.set_yscale("log")
    ax.set_xlabel("mu = log10(sum of slips)", fontsize=FONT)
    ax.set_ylabel("R(mu), per unit mu", fontsize=FONT)
    ax.tick_params(labelsize=FONT)
    ax.legend(fontsize=FONT - 1, frameon=False, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)
    ax.set_title("R(mu) in bins of 0.1: l = 3, a = 0, c = 1e3, nu = 1e-8", fontsize=FONT + 1)
    fig.tight_layout()
    save(fig, path)


def figure_zone(N, M, b, k, path, what):
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5.2, 4.8))
    zone = k["slip"] > 0.0
    if what == "slip":
        data, label = np.where(zone, k["slip"], np.nan), "slip"
        title = f"slip of an event on a {N} x {M} plane, b = {b:g} (mu = {k['mu']:.2f}, {zone.sum()} blocks)"
    else:
        data, label = k["start"], "model time since the onset when the block starts to slip"
        title = f"its growth on the {N} x {M} plane, b = {b:g}: when each block started to slip"
    image = ax.imshow(data.reshape(M, N), origin="lower", cmap="viridis", interpolation="nearest")
    x, y = k["epicenter"] % N, k["epicenter"] // N
    ax.plot([x], [y], "r*", ms=10, label="epicenter")
    ax.set_xlabel("along strike (block)", fontsize=FONT)
    ax.set_ylabel("across strike (block)", fontsize=FONT)
    ax.tick_params(labelsize=FONT)
    ax.legend(fontsize=FONT, loc="upper center", bbox_to_anchor=(0.5, -0.13), frameon=False)
    bar = fig.colorbar(image, ax=ax, shrink=0.85)
    bar.set_label(label, fontsize=FONT)
    bar.ax.tick_params(labelsize=FONT)
    ax.set_title(title, fontsize=FONT + 1)
    fig.tight_layout()
    save(fig, path)


def table(results, rims):
    def iv(v, i, d=3):
        return f"{v:.{d}f} [{i[0]:.{d}f}, {i[1]:.{d}f}]"
    lines = ["| catalog | events (creep episodes among them) | slip every block | span the fault both ways | "
             "best two decades: KS, from mu, b | "
             "top two decades: KS, from mu, b | large: all, own ends, own shape | epicenter at an end along strike | "
             "large events' epicenter near the fault's edge (uniform) | extent along / across (median) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    def decades(d):
        return f"{iv(d['ks'], d['ks_interval'])}, {d['from_mu']:.2f}, {iv(d['b'], d['b_interval'], 2)}"

    for name, r in results.items():
        best, top = r["best_two_decades"], r["top_two_decades"]
        seeds = f" ({r['seeds']} seeds)" if r.get("seeds", 1) > 1 else ""
        lines.append(f"| {name}{seeds} | {r['events']} ({r['creep_episodes']}) | "
                     f"{iv(r['whole'], r['whole_interval'])} | "
                     f"{iv(r['spanning'], r['spanning_interval'])} | "
                     f"{decades(best)} | {decades(top)} | "
                     f"{r['large']}, {r['large_own_ends']}, {r['large_own_shape']} | "
                     f"{iv(r['unilateral'], r['unilateral_interval'])} | "
                     f"{iv(r['near_edge'], r['near_edge_interval'])} ({r['edge_chance']:.2f}) | "
                     + (f"{iv(r['anisotropy_median'], r['anisotropy_median_interval'], 2)} |" if "plane" in name
                        else "- |"))
    lines += ["", "The large events' shapes (those that reach none of the fault's edges), by blocks "
              "slipped:",
              "", "| catalog | blocks slipped | events | extent along / across | longer / shorter | fill of the "
              "bounding box |", "|---|---|---|---|---|---|"]
    for name, r in results.items():
        if "plane" not in name or not r["large_own_shape"]:
            continue
        lines.append(f"| {name} | all | {r['large_own_shape']} | "
                     + " | ".join(iv(r[f"{key}_median"], r[f"{key}_median_interval"], 2)
                                  for key in ("anisotropy", "elongation", "fill")) + " |")
        s = r["by_size"]
        for k, (lo, hi) in enumerate(zip(SIZE_BINS[:-1], SIZE_BINS[1:])):
            if s["count"][k]:
                lines.append(f"| | {lo}-{hi - 1 if math.isfinite(hi) else ''} | {s['count'][k]} | "
                             + " | ".join(iv(s[key][k], s[f"{key}_interval"][k], 2)
                                          for key in ("along_over_across", "elongation", "fill")) + " |")
    for name, r in results.items():
        if "plane" in name and r["large_own_shape"]:
            lines += ["", f"{name}: of the {r['large_own_shape']} large events that reach none of the fault's edges, "
                          f"epicenter within a tenth of its extent of a side of the rupture's bounding box in "
                          f"{iv(r['box_side'], r['box_side_interval'], 2)}; a uniformly placed epicenter: "
                          f"{r['box_side_chance']:.2f}"]
    for name, r in rims.items():
        if r["kept"]:
            on_rim = iv(r["epicenter_on_rim"], r["epicenter_on_rim_interval"], 2)
            lines += ["", f"{name}: {r['kept']} kept large events: epicenter on the rupture zone's rim in "
                          f"{on_rim} of them; the rim holds {r['rim_share_of_zone']:.2f} of a "
                          f"zone's blocks (a uniformly placed epicenter's chance)"]
        if r.get("past_rim_events"):
            near = iv(r["next_to_past_rim"], r["next_to_past_rim_interval"], 2)
            lines += ["", f"{name}: {r['past_rim_events']} kept events after another: epicenter next to the edge of "
                          f"one of the {PAST} kept events' zones before it in {near} of them; the other kept "
                          f"events' epicenters are there in {r['next_to_past_rim_chance']:.2f}"]
    return lines


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("catalogs", nargs="+")
    p.add_argument("--histories", nargs="+", help="catalogs of planes with output.history (figures: the first plane)")
    p.add_argument("-o", "--out", default="docs/plane/study")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--events", type=int, help="the first this many inertial events of each catalog")
    args = p.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    pooled = {}     # name -> (blocks, [events of each task], creep episodes): the tasks (seeds) of one point pool
    for given in args.catalogs:
        path, _, first = given.rpartition("@") if "@" in given else (given, "", "")
        limit = int(first) if first else args.events
        with reader.Reader(path) as cat:
            tasks, every = cat.tasks, cat.events()
        for task in range(len(tasks["N"])):
            _, N, M = shape(tasks, task)
            ev = {k: v[every["task"] == task] for k, v in every.items()}
            inertial = np.flatnonzero(ev["kind"] == KIND_EVENT)[:limit]        # not the creep episodes
            creep = int(np.sum(ev["kind"][:inertial[-1] + 1] != KIND_EVENT)) if len(inertial) else 0
            name = point_name(tasks, task)
            print(f"{path} task {task}: {name}, {len(inertial)} events", flush=True)
            if not len(inertial):       # (a partial catalog's task still in its transient)
                continue
            blocks, parts, creeps = pooled.setdefault(name, (N * M, [], []))
            parts.append({**{k: v[inertial] for k, v in ev.items()}, "N": N})
            creeps.append(creep)
    results, hists = {}, []
    for name, (blocks, parts, creeps) in pooled.items():
        # one task's events after another's: the bootstrap's stretches of consecutive events stay within one task
        ev = {k: (np.concatenate([part[k] for part in parts]) if k != "N" else parts[0]["N"]) for k in parts[0]}
        results[name], counts = with_intervals(ev, blocks, rng, [len(part["mu"]) for part in parts])
        results[name].update(creep_episodes=sum(creeps), seeds=len(parts))
        hists.append(counts)
    rims = {}
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    planes = {}     # point -> (N, M, b, the kept events of each of its tasks (seeds) with histories)
    for path in args.histories or ():
        for name, N, M, b, own in zones(path):
            planes.setdefault(name, (N, M, b, []))[3].append(own)
    for name, (N, M, b, seeds) in planes.items():
        hits, chance = [], []
        for own in seeds:       # a past zone is one of the same seed's
            h, c = past_rims(N, M, own)
            hits += h
            chance += c
        rims[name] = {
            **rim_numbers(N, M, [k for own in seeds for k in own]), "seeds": len(seeds),
            "histories": sum(map(len, seeds)), "past_rim_events": len(hits),
            "next_to_past_rim": float(np.mean(hits)) if hits else math.nan,
            "next_to_past_rim_interval": wilson(sum(hits), len(hits)) if hits else None,
            "next_to_past_rim_chance": float(np.mean(chance)) if hits else math.nan}
    if planes:      # the figures: the first plane given
        N, M, b, seeds = next(iter(planes.values()))
        partial = [k for own in seeds for k in own if LARGE_BLOCKS <= (k["slip"] > 0).sum() < N * M]
        if partial:
            # the largest that slips at most half the plane, else the largest that does not slip all of it
            half = [k for k in partial if (k["slip"] > 0).sum() <= N * M // 2]
            k = max(half or partial, key=lambda k: k["mu"])
            figure_zone(N, M, b, k, f"{out}_zone.png", "slip")
            figure_zone(N, M, b, k, f"{out}_growth.png", "start")
    figure_mu(results, hists, f"{out}_mu.png")
    record = {"catalogs": args.catalogs, "histories": args.histories, "results": results, "rims": rims}
    Path(f"{out}.json").write_text(json.dumps(record, indent=1, default=float))
    text = "\n".join(table(results, rims)) + "\n"
    Path(f"{out}.md").write_text(text)
    sys.stdout.write(text)


if __name__ == "__main__":
    main()
