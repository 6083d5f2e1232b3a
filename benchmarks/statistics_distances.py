"""What benchmarks/statistics.py measures: each seed's magnitudes and recurrence times, the KS and
Wasserstein-1 distances between pooled samples, the noise floor from halves of the reference's seeds (widened
by a rerun of the reference), and the table and figure of a comparison (statistics.py's docstring says how)."""
import itertools

import numpy as np

from analysis.recurrence import RecurrenceScanner
from ensemble.store.schema import KIND_EVENT

from .common import ks_distance, pyplot, save_figure, wasserstein1

DISTANCES = {"ks": ks_distance, "w1": wasserstein1}
SAMPLES = ("mu", "tnu")
MAX_SPLITS = 10


def seed_samples(chunks, N, nu, mu_c, window):
    """One trajectory's recorded rows (dicts of columns t, epicenter, mu, boundary, kind) -> {"mu": the
    magnitudes of its inertial events, "tnu": the local recurrence times T nu of its large events}
    (creep episodes, kind 1, are no events here, as in analysis/reduce.py)."""
    scanner = RecurrenceScanner(N, mu_c, window)
    mu, T = [np.zeros(0)], [np.zeros(0)]
    for rows in chunks:
        keep = rows["kind"] == KIND_EVENT
        chunk = {name: rows[name][keep] for name in ("t", "epicenter", "mu", "boundary")}
        mu.append(chunk["mu"])
        T.append(scanner.feed(chunk["t"], chunk["epicenter"], chunk["mu"], chunk["boundary"])[1])
    return {"mu": np.concatenate(mu), "tnu": np.concatenate(T) * nu}


def distances(x, y):
    """{name: distance} of two samples (NaN if either is empty)."""
    return {name: (f(x, y) if len(x) and len(y) else float("nan")) for name, f in DISTANCES.items()}


def noise_floor(per_seed):
    """Distances between halves of the reference seeds, scaled to two samples of the full size."""
    seeds = sorted(per_seed)
    splits = [s for s in itertools.combinations(seeds, len(seeds) // 2) if seeds[0] in s][:MAX_SPLITS]
    floor = {}
    for sample in SAMPLES:
        values = {name: [] for name in DISTANCES}
        for half in splits:
            a = np.concatenate([per_seed[k][sample] for k in half])
            b = np.concatenate([per_seed[k][sample] for k in seeds if k not in half])
            scale = np.sqrt((2 / (len(a) + len(b))) / (1 / len(a) + 1 / len(b))) if len(a) and len(b) else 1.0
            for name, d in distances(a, b).items():
                values[name].append(d * scale)
        for name, v in values.items():
            floor[f"{name}_{sample}"] = {"splits": v, "min": float(np.min(v)), "mean": float(np.mean(v)),
                                         "max": float(np.max(v))}
    return floor


def pooled(per_seed, rate=None):
    """The seeds' samples pooled; events/s the pooled events over the pooled seconds, or `rate`."""
    ok = [r for r in per_seed.values() if r["status"] == "ok"]
    if len(ok) < len(per_seed):
        return {"status": next(r["status"] for r in per_seed.values() if r["status"] != "ok")}
    seconds = sum(r["seconds"] for r in ok)
    out = {s: np.concatenate([r[s] for r in ok]) for s in SAMPLES}
    if not len(out["mu"]):
        return {"status": "no events committed"}
    rate = len(out["mu"]) / seconds if rate is None else rate
    return {"status": "ok", "seconds": seconds, "events_per_second": rate, **out}


def summarize(label, pool, ref):
    row = {"setting": label, "status": pool["status"]}
    if pool["status"] == "ok":
        row.update(events=len(pool["mu"]), recurrences=len(pool["tnu"]), seconds=pool["seconds"],
                   events_per_second=pool["events_per_second"], fraction_large=float(np.mean(pool["mu"] >= 4)),
                   mean_tnu=float(np.mean(pool["tnu"])) if len(pool["tnu"]) else None)
        if ref is not None:
            for sample in SAMPLES:
                for name, d in distances(pool[sample], ref[sample]).items():
                    row[f"{name}_{sample}"] = d
    return row


def table(rows, floor, title):
    keys = [f"{n}_{s}" for s in SAMPLES for n in DISTANCES]
    lines = [f"statistical error against speed, {title}",
             f"{'setting':22s} {'events/s':>9s} {'events':>7s} {'T count':>7s} {'frac>=4':>7s} "
             + " ".join(f"{k:>8s}" for k in keys)]
    for r in rows:
        if r["status"] != "ok":
            lines.append(f"{r['setting']:22s} {r['status'][:90]}")
            continue
        lines.append(f"{r['setting']:22s} {r['events_per_second']:9.1f} {r['events']:7d} {r['recurrences']:7d} "
                     f"{r['fraction_large']:7.3f} " + " ".join(f"{r.get(k, float('nan')):8.4f}" for k in keys))
    lines.append(f"{'noise floor (mean)':22s} {'':9s} {'':7s} {'':7s} {'':7s} "
                 + " ".join(f"{floor[k]['mean']:8.4f}" for k in keys))
    lines.append(f"{'noise floor (max)':22s} {'':9s} {'':7s} {'':7s} {'':7s} "
                 + " ".join(f"{floor[k]['max']:8.4f}" for k in keys))
    lines.append("first row: the reference (distances not applicable); noise floor: halves of its seeds, "
                 "scaled to full-size samples")
    return lines


def plot(rows, floor, path, title, xlabel="events per second (one core)", floor_label="noise floor (reference halves)"):
    plt = pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(9, 7))
    ref = rows[0]
    for ax, key in zip(axes.flat, [f"{n}_{s}" for s in SAMPLES for n in DISTANCES]):
        band = floor[key]
        ax.axhspan(band["min"], band["max"], color="0.85", label=floor_label)
        ax.axhline(band["mean"], color="0.6", lw=1)
        for k, r in enumerate(rows[1:]):
            if r["status"] == "ok" and np.isfinite(r[key]) and np.isfinite(r["events_per_second"]):
                ax.plot(r["events_per_second"], r[key], "o", color=f"C{k}", label=r["setting"])
        if ref["status"] == "ok" and np.isfinite(ref["events_per_second"]):
            ax.axvline(ref["events_per_second"], color="k", ls=":", lw=1, label=f"reference {ref['setting']}")
        ax.set_xscale("log")
        ax.xaxis.set_minor_formatter(plt.NullFormatter())
        ax.set_ylim(bottom=0)
        ax.set_xlabel(xlabel, fontsize=8)
        name, sample = key.split("_")
        ax.set_ylabel(f"{'KS' if name == 'ks' else 'Wasserstein-1'} distance of "
                      f"{'mu' if sample == 'mu' else 'T nu'}", fontsize=8)
        ax.tick_params(labelsize=7)
    save_figure(fig, axes, f"statistical error against speed, {title}", path)


def with_rerun(floor, ref_seeds, rerun_seeds):
    """The noise floor widened by a rerun of the reference (its integrator, another root seed): its
    own halves, scaled like the reference's, and its full-size distance from the reference."""
    theirs = noise_floor(rerun_seeds)
    direct = distances(pooled(rerun_seeds)["mu"], pooled(ref_seeds)["mu"])
    direct_t = distances(pooled(rerun_seeds)["tnu"], pooled(ref_seeds)["tnu"])
    out = {}
    for key, entry in floor.items():
        name, sample = key.split("_", 1)
        values = entry["splits"] + theirs[key]["splits"] + [(direct if sample == "mu" else direct_t)[name]]
        out[key] = {"splits": values, "min": float(np.min(values)), "mean": float(np.mean(values)),
                    "max": float(np.max(values))}
    return out


def rerun_rows(rows, pools, rerun_seeds):
    """Every setting against the rerun (the reference's integrator from another root seed, the candidates'):
    the reference's own distance from it is the size of the sampling noise in one pair of samples."""
    rerun = pooled(rerun_seeds)
    if rerun["status"] != "ok":
        return []
    large = float(np.mean(rerun["mu"] >= 4))
    return [{**summarize(r["setting"], pool, rerun), "fraction_large_rerun": large}
            for r, pool in zip(rows, pools) if pool["status"] == "ok"]


def rerun_lines(rows):
    keys = [f"{n}_{s}" for s in SAMPLES for n in DISTANCES]
    lines = ["against the rerun (first row: the reference; then each candidate):",
             f"  {'setting':26s} {'frac>=4':>8s} {'rerun':>7s} " + " ".join(f"{k:>8s}" for k in keys)]
    for r in rows:
        lines.append(f"  {r['setting']:26s} {r['fraction_large']:8.4f} {r['fraction_large_rerun']:7.4f} "
                     + " ".join(f"{r[k]:8.4f}" for k in keys))
    return lines


def within_noise(rows, floor):
    """Labels of the candidates every distance of which is at most the noise floor's max."""
    keys = [f"{n}_{s}" for s in SAMPLES for n in DISTANCES]
    return [r["setting"] for r in rows[1:] if r["status"] == "ok"
            and all(r.get(k, np.inf) <= floor[k]["max"] for k in keys)]
