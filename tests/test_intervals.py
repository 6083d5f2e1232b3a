"""The intervals statistic (analysis/statistics/intervals.py) against the events themselves: the CV of
the local recurrence times and the mean and CV of the whole chain's inter-event times, computed here by
brute force from the committed catalog of tests/test_summary_identity.py."""
import sys

import h5py
import numpy as np

from .processes import ROOT, child_env, run_bounded
from .test_summary_identity import CATALOG, gunzip


def recurrences(t, epicenter, mu, mu_c, window):
    """Local recurrence times of one task's events in time order (brute force)."""
    large = np.flatnonzero(mu >= mu_c)
    out = []
    for a, i in enumerate(large):
        for j in large[a + 1:]:
            if abs(int(epicenter[j]) - int(epicenter[i])) <= window:
                out.append(t[j] - t[i])
                break
    return out


def cv(x):
    x = np.asarray(x)
    return x.std(ddof=1) / x.mean()


def test_recurrence_cv_and_inter_event_times_are_those_of_the_events(tmp_path):
    cat, out = gunzip(CATALOG, tmp_path / "catalog.h5"), tmp_path / "summary.h5"
    res = run_bounded([sys.executable, "-m", "analysis", "reduce", str(cat), "-o", str(out)], 600, cwd=ROOT,
                      env=child_env())
    assert res.returncode == 0, res.stderr
    with h5py.File(cat, "r") as c, h5py.File(out, "r") as s:
        ev = {k: c["events"][k][:] for k in ("task", "kind", "t", "mu", "epicenter")}
        nu = c["tasks"]["nu"][:]
        point = s["tasks/point"][:]
        mu_c, window = float(s.attrs["mu_c"]), int(s.attrs["window"])
        checked = 0
        for i in range(len(s["points/N"])):
            T, gaps = [], []
            for task in np.flatnonzero(point == i):
                mine = (ev["task"] == task) & (ev["kind"] == 0)
                t = ev["t"][mine]
                gaps += list(np.diff(t) * nu[task])
                T += [x * nu[task] for x in recurrences(t, ev["epicenter"][mine], ev["mu"][mine], mu_c, window)]
            assert len(T) >= 10 and len(gaps) >= 100        # what the comparison stands on
            np.testing.assert_allclose(s["points/numbers/cv_tnu"][i, 0], cv(T), rtol=1e-9)
            np.testing.assert_allclose(s["points/numbers/mean_gap"][i, 0], np.mean(gaps), rtol=1e-12)
            np.testing.assert_allclose(s["points/numbers/cv_gap"][i, 0], cv(gaps), rtol=1e-9)
            for name in ("cv_tnu", "mean_gap", "cv_gap"):
                est, lo, hi = s[f"points/numbers/{name}"][i]
                assert lo < est < hi, (name, est, lo, hi)
            checked += 1
        assert checked == 2


def test_every_statistic_is_the_same_whatever_the_chunks(tmp_path):
    """A task streamed in chunks of 7 rows gives every statistic's tables as in one chunk: what a statistic
    carries from chunk to chunk (the previous event's time, the pending recurrences) is carried."""
    from analysis import options, reduce
    from ensemble.model import laws
    from ensemble.store import reader, schema
    cat = gunzip(CATALOG, tmp_path / "catalog.h5")
    opt = options.make(scales=laws.get("aging").scales)
    with reader.Reader(str(cat)) as r:
        for k in range(len(r.tasks["N"])):
            args = (r.count(k, schema.KIND_EVENT), float(r.tasks["nu"][k]), int(r.tasks["N"][k]), opt,
                    int(r.tasks["events_written"][k]))
            whole = reduce.reduce_task(r.task_events(k, 1 << 16), *args)
            pieces = reduce.reduce_task(r.task_events(k, 7), *args)
            assert sorted(whole) == sorted(pieces)
            for name in whole:
                np.testing.assert_array_equal(whole[name], pieces[name], err_msg=name)
            assert whole["intervals"][:, 1].sum() == args[0] - 1      # every gap between its events, once


def test_the_recurrence_figure_gives_each_panel_its_cv(tmp_path):
    """`analysis plot --figure recurrence`: each panel's title carries its point's CV of T nu with its interval,
    as the summary has them; a summary without the statistic (before format 4) keeps the plain title."""
    from analysis import plot, summary
    from .test_summary_identity import REFERENCE
    s = summary.read(gunzip(REFERENCE, tmp_path / "summary.h5"))
    fig = plot.figure(s, "recurrence")
    try:
        titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
        cvs = s["points/numbers/cv_tnu"]
        assert len(titles) == len(cvs) == 2
        for title, (est, lo, hi) in zip(titles, cvs):
            assert title.endswith(f"CV of $T\\nu$ {est:.2f} [{lo:.2f}, {hi:.2f}]"), title
    finally:
        plot.plt.close(fig)
    old = {k: v for k, v in s.items() if k != "points/numbers/cv_tnu"}
    fig = plot.figure(old, "recurrence")
    try:
        assert not any("CV" in ax.get_title() for ax in fig.axes)
    finally:
        plot.plt.close(fig)
