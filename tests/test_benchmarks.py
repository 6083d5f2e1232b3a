"""The benchmark scripts at tiny sizes: their helpers against known answers, their outputs sane.

The scripts' tiny runs (SCRIPT_RUN) are in the slower tier: they test the benchmarks, not the product, and take
80 s together; their helpers' known answers stay in `make test`."""
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

from benchmarks import (cost_scaling, hard_cases, paired, revisions, statistics, step_budget, step_trace,
                        work_precision)
from benchmarks.baselines import BASELINES
from benchmarks.common import cost_at_error, ks_distance, parse_setting, wasserstein1
from ensemble.config import Model
from ensemble.events import advance_to_onset

from .conftest import developed_state

SCRIPT_RUN = pytest.mark.slow    # a benchmark script run end to end at a tiny size (docs/tests.md: the slower tier)


def test_distances_agree_with_scipy():
    stats = pytest.importorskip("scipy.stats")
    rng = np.random.default_rng(3)
    for n, m in ((50, 70), (400, 31), (1, 5)):
        x = rng.normal(size=n)
        y = np.round(rng.normal(0.3, 1.5, size=m), 1)    # ties within y and with x
        x[: n // 3] = np.round(x[: n // 3], 1)
        assert ks_distance(x, y) == pytest.approx(stats.ks_2samp(x, y).statistic, abs=1e-12)
        assert wasserstein1(x, y) == pytest.approx(stats.wasserstein_distance(x, y), rel=1e-12)
    assert ks_distance(x, x) == 0.0 and wasserstein1(x, x) == 0.0
    assert wasserstein1(x, x + 2.5) == pytest.approx(2.5)


def test_cost_at_error_known_answers():
    errors, seconds = [1e-4, 1e-6, 1e-8], [1.0, 10.0, 100.0]     # error ~ seconds^-2
    assert cost_at_error(errors, seconds, 1e-7) == (pytest.approx(10 ** 1.5), "interpolated")
    assert cost_at_error(errors, seconds, 1e-6) == (pytest.approx(10.0), "interpolated")
    assert cost_at_error(errors, seconds, 1e-2) == (1.0, "bound")
    assert cost_at_error(errors, seconds, 1e-9) == (None, "not reached")
    assert cost_at_error([None, 1e-5], [1.0, 2.0], 1e-6) == (None, "not reached")


def test_settings_are_validated():
    s = parse_setting("ark3:rtol=1e-5,atol=1e-12")
    assert s.integrator().rtol == 1e-5 and s.integrator().atol == 1e-12
    assert parse_setting("scipy:method=LSODA,rtol=1e-6", BASELINES).kwargs == {"method": "LSODA", "rtol": 1e-6}
    for bad in ("rk5:dt=1e-3", "rk4:step=1e-3", "rk4:dt", "numpy-rk4:dt=1e-3"):
        with pytest.raises(ValueError):
            parse_setting(bad)


def test_baseline_timeout_is_recorded():
    model = Model(N=30)
    epicenter, _, f, p = advance_to_onset(*developed_state(model, 50), model)
    f[epicenter] = model.b * p[epicenter]
    for text in ("scipy:method=LSODA", "numpy-rk4:dt=1e-3"):
        assert work_precision.measure(parse_setting(text, BASELINES), f, p, epicenter, model, 0.0)[-1] == "timeout"


@SCRIPT_RUN
def test_work_precision_tiny(tmp_path):
    # no wall-time cap on the baselines ("inf"): every row must be "ok", which a cap would make
    # depend on the machine's load; the per-test timeout stands guard against a hang
    # N = 20: the full-chain baselines' cost grows with N; the orders and agreements checked hold as at N = 40
    work_precision.main(["--N", "20", "--b", "20", "--transient", "60", "--max-seconds", "inf", "--out",
                         str(tmp_path), "--runs", "rk4:dt=1e-3", "rk4:dt=5e-4", "ark3:rtol=1e-4", "ark3:rtol=1e-7",
                         "scipy:method=LSODA,rtol=1e-5", "scipy:method=LSODA,rtol=1e-8"])
    data = json.loads((tmp_path / "work_precision_N20_b20.json").read_text())
    assert (tmp_path / "work_precision_N20_b20.png").stat().st_size > 0
    rows = data["rows"]
    assert {r["event"] for r in rows} == {"small", "large"} and all(r["status"] == "ok" for r in rows)
    for event in ("small", "large"):
        by = {r["setting"]: r for r in rows if r["event"] == event}
        # fourth order: halving dt cuts the slip error at least 8-fold (unless at round-off already)
        coarse, fine = by["rk4:dt=1e-3"]["slip_error"], by["rk4:dt=5e-4"]["slip_error"]
        assert fine * 8 < coarse or coarse < 1e-12
        # the full-chain scipy baseline integrates the same event as the kernel
        assert by["scipy:method=LSODA,rtol=1e-8"]["profile_error"] < 1e-5
        assert by["ark3:rtol=1e-7"]["slip_error"] < by["ark3:rtol=1e-4"]["slip_error"] < 1e-3
        assert all(r["seconds"] > 0 and r["block_rhs"] > 0 for r in by.values())
    assert data["speedups"] and all(q["ratio"] > 0 and q["ratio_is"] in ("=", ">=", "<=", "?")
                                    for q in data["speedups"])


@SCRIPT_RUN
def test_statistics_tiny(tmp_path):
    data = statistics.main(["--N", "40", "--seeds", "2", "--events", "60", "--transient", "20",
                            "--reference", "rk4:dt=1e-3", "--runs", "ark3:rtol=1e-3", "--out", str(tmp_path)])
    assert json.loads((tmp_path / "statistics_N40_b20.json").read_text())["rows"][1]["setting"] == "ark3:rtol=1e-3"
    ref, cand = data["rows"]
    assert ref["events"] == cand["events"] == 120 and cand["recurrences"] > 0
    assert cand["events_per_second"] > 0
    for key in ("ks_mu", "ks_tnu"):
        assert 0 < cand[key] <= 1
    for key in ("w1_mu", "w1_tnu"):
        assert 0 < cand[key] < np.inf
    for band in data["noise_floor"].values():
        assert np.isfinite(band["mean"]) and 0 <= band["min"] <= band["mean"] <= band["max"]


def brute_recurrences(t, epicenter, mu, mu_c=4.0, window=10):
    """Local recurrence times by their definition, O(n^2): for each large event the time to the
    next large one with its epicenter within `window` blocks (none if there is no such event)."""
    large = np.flatnonzero(mu >= mu_c)
    T = []
    for i in large:
        later = [j for j in large if j > i and abs(epicenter[j] - epicenter[i]) <= window]
        if later:
            T.append(t[later[0]] - t[i])
    return np.array(T)


@SCRIPT_RUN
def test_statistics_from_catalogs(tmp_path, capsys):
    from ensemble.store import reader
    from .catalog_writer import write_events
    from .conftest import run_cli, write_config
    cfg = write_config(tmp_path / "c.toml", model={"N": 30}, sweep={"b": [20.0, 50.0]},
                       run={"events": 150, "transient": 20, "seeds": 2}, integrator={"method": "ark4"})
    ref, cand, other = tmp_path / "ref.h5", tmp_path / "cand.h5", tmp_path / "other.h5"
    for out, sets in ((ref, ["integrator.rtol=1e-5", "run.seed=1"]), (cand, ["integrator.rtol=1e-3"])):
        assert run_cli("run", cfg, "-o", out, *[a for s in sets for a in ("--set", s)]).returncode == 0
    # a catalog of another chain (N = 20), through the project's writer: the candidate's events that lie on
    # its first 20 blocks
    events, _, _ = reader.read(cand)
    small = write_config(tmp_path / "o.toml", model={"N": 20}, sweep={"b": [20.0, 50.0]},
                         run={"events": 5, "transient": 20, "seeds": 2}, integrator={"method": "ark4"})
    write_events(other, small.read_text(), [{c: v[(events["task"] == k) & (events["last"] < 20)][:5]
                                             for c, v in events.items()} for k in range(4)])
    # the reference is also a candidate: its distance to itself is 0
    data = statistics.main(["--catalogs", str(ref), str(cand), str(ref), "--name", "tol", "--out", str(tmp_path)])
    assert sorted(data) == ["tol_N30_b20", "tol_N30_b50"]
    events, tasks, _ = reader.read(ref)
    for b in (20, 50):
        stem = f"tol_N30_b{b}"
        d = data[stem]
        assert json.loads((tmp_path / f"{stem}.json").read_text())["rows"] == json.loads(json.dumps(d["rows"]))
        assert (tmp_path / f"{stem}.png").stat().st_size > 10_000
        r, c, self_ = d["rows"]
        assert [x["setting"] for x in d["rows"]] == ["ark4:rtol=1e-5", "ark4:rtol=1e-3", "ark4:rtol=1e-5"]
        assert r["events"] == c["events"] == self_["events"] == 300
        # the reference's samples are its catalog's: mu and the recurrence times by their definition
        rows = np.flatnonzero(tasks["b"] == b)
        mine = np.isin(events["task"], rows)
        assert r["fraction_large"] == pytest.approx(np.mean(events["mu"][mine] >= 4.0))
        T = np.concatenate([brute_recurrences(*(events[k][events["task"] == g] for k in ("t", "epicenter", "mu")))
                            for g in rows]) * tasks["nu"][rows[0]]
        assert r["recurrences"] == len(T) > 0 and r["mean_tnu"] == pytest.approx(T.mean())
        assert r["events_per_second"] == pytest.approx(np.mean(tasks["events_per_second"][rows]))
        for key in ("ks_mu", "ks_tnu", "w1_mu", "w1_tnu"):
            assert self_[key] == 0.0
            assert 0 <= c[key] and (c[key] <= 1 if key.startswith("ks") else np.isfinite(c[key]))
        assert c["ks_mu"] > 0 and c["w1_tnu"] > 0
        text = (tmp_path / f"{stem}.txt").read_text()
        assert f"b = {b}," in text and "ark4:rtol=1e-3" in text and "300 / 300" in text
        assert "the reference's root seed" not in text.split("ark4:rtol=1e-3")[-1].splitlines()[0]
    labelled = statistics.main(["--catalogs", str(ref), str(cand), "--label", "tight", "loose",
                                "--out", str(tmp_path)])
    assert [x["setting"] for x in labelled["catalogs_N30_b20"]["rows"]] == ["tight", "loose"]
    capsys.readouterr()
    with pytest.raises(SystemExit) as refused:
        statistics.main(["--catalogs", str(ref), str(cand), str(other), "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert refused.value.code == 2 and str(other) in err and "N = 20" in err and len(err.splitlines()) == 1


def test_catalog_labels():
    assert statistics.integrator_label(['method = "rk4"\ndt = 0.001\nrtol = 1e-05\natol = 1e-12']) == "rk4:dt=1e-3"
    assert statistics.integrator_label(['method = "ark4"\ndt = 0.001\nrtol = 2.5e-07\natol = 1e-10'] * 2
                                       ) == "ark4:rtol=2.5e-7,atol=1e-10"
    assert statistics.short(0.5) == "0.5" and statistics.short(800.0) == "800" and statistics.short(1e-8) == "1e-8"


@SCRIPT_RUN
def test_cost_scaling_tiny(tmp_path):
    # the aging law's own method (exp4), a fraction of rk4's time: the cost classes are the same
    data = cost_scaling.main(["--runs", "exp4:rtol=1e-4", "--Ns", "40", "80", "--bs", "20", "30", "--N-at", "40",
                              "--events", "60", "--min-transient", "40", "--out", str(tmp_path)])
    assert (tmp_path / "cost_scaling.png").stat().st_size > 0
    points = data["points"]
    assert [(p["N"], p["b"]) for p in points] == [(40, 20.0), (80, 20.0), (40, 30.0)]
    for p in points:
        assert p["status"] == "ok" and p["events_per_second"] > 0
        assert sum(p[c]["count"] for c in cost_scaling.CLASSES) == 60
        for c in cost_scaling.CLASSES:
            if p[c]["count"]:
                assert p[c]["us_per_event"] > 0 and p[c]["block_steps_per_slid_block"] >= 1


class CallClock:
    """benchmarks.common.Clock counting deadline checks (one per kernel call) instead of seconds."""

    def __init__(self, limit=float("inf")):
        self.limit = limit
        self.checks = 0

    @property
    def expired(self):
        self.checks += 1
        return self.checks > self.limit

    @property
    def elapsed(self):
        return float(self.checks)


@SCRIPT_RUN
def test_hard_cases_tiny(tmp_path, monkeypatch):
    # The benchmark's choices hang on its wall-time caps: which nu the long run takes (the probe's
    # estimate against --long-max-seconds) and whether each phase ends "ok" or at its cap. Counted
    # in kernel calls they depend on the events alone, not on the machine's load: the probe
    # estimates ~400-800 calls to pass 1e14 at nu = 1e-8 (over 100: the long run takes 1e-10),
    # which then passes it within 2 calls.
    monkeypatch.setattr(hard_cases, "Clock", CallClock)
    data = hard_cases.main(["--runs", "rk4", "ark3", "--cases", "b100", "long", "--N", "30", "--transient", "10",
                            "--events", "15", "--long-t", "1e14", "--late-events", "5", "--probe-events", "10",
                            "--long-max-seconds", "100", "--out", str(tmp_path)])
    assert json.loads((tmp_path / "hard_cases.json").read_text())["long_nu"] == data["long_nu"] == 1e-10
    assert "long run rk4 (nu = 1e-10)" in (tmp_path / "hard_cases.txt").read_text()
    points = {(p["case"], p["setting"]): p for p in data["points"]}
    assert points["b100", "rk4"]["dt"] == 2e-4 and points["b100", "ark3"]["dt"] == 1e-3   # untuned ark3
    for p in points.values():
        assert p["status"] == "ok" and p["nonfinite"] == p["zero_slip"] == p["non_increasing_onsets"] == 0
        assert p["events_per_second"] > 0 and 0 < p["residual_median"] <= p["residual_max"] < 1e-3
    for method in ("rk4", "ark3"):
        long = points["long", method]
        assert long["final_time"] > 1e14 and long["long"]["after"]["events"] >= 5
        assert long["events"] == long["long"]["before"]["events"] + long["long"]["after"]["events"]
    assert [r["setting"] for r in data["probe"]] == ["rk4", "ark3"]
    assert all(r["status"] == "ok" and r["events_to_target"] > 0 for r in data["probe"])


@SCRIPT_RUN
def test_step_budget_tiny(tmp_path):
    data = step_budget.main(["--N", "40", "--transient", "60", "--sizes", "small:-inf:2", "large:2:inf",
                             "--runs", "rk4:dt=1e-3", "ark4:rtol=1e-4", "ark4:rtol=1e-7",
                             "--out", str(tmp_path)])
    assert json.loads((tmp_path / "step_budget_N40_b20.json").read_text())["rows"] == data["rows"]
    rows = {(r["event"], r["setting"]): r for r in data["rows"]}
    assert {e for e, _ in rows} == {"small", "large"}
    for (event, setting), r in rows.items():
        assert r["n_slid"] >= 1 and r["block_steps_per_slid"] * r["n_slid"] == pytest.approx(r["block_steps"])
        assert 0 <= r["rejected"] < r["steps"] and r["cuts"] >= 2 * (r["n_slid"] - 1)  # each block starts, stops
        if setting.startswith("rk4"):
            assert r["rejected"] == 0 and r["slip_error"] < 1e-6
    for event in ("small", "large"):
        loose, tight = rows[event, "ark4:rtol=1e-4"], rows[event, "ark4:rtol=1e-7"]
        assert tight["slip_error"] < max(loose["slip_error"], 1e-9) and tight["steps"] > loose["steps"]
        # the error control, not a fixed step, sets ark4's steps: far fewer than RK4's
        assert loose["block_steps"] * 5 < rows[event, "rk4:dt=1e-3"]["block_steps"]
    assert set(data["step_alone_ns"]) == {"rk4:dt=1e-3", "ark4:rtol=1e-4", "ark4:rtol=1e-7"}
    assert all(ns > 0 for ns in data["step_alone_ns"].values())
    text = (tmp_path / "step_budget_N40_b20.txt").read_text()
    assert "speed-up over rk4:dt=1e-3" in text and "one step alone" in text


@SCRIPT_RUN
def test_step_trace_tiny(tmp_path):
    data = step_trace.main(["--N", "40", "--transient", "60", "--sizes", "small:-inf:2", "large:2:inf",
                            "--runs", "ark4:rtol=1e-5", "ark5:rtol=1e-5", "--out", str(tmp_path)])
    assert json.loads((tmp_path / "step_trace_N40_b20.json").read_text())["rows"] == data["rows"]
    assert {(r["event"], r["setting"]) for r in data["rows"]} == {
        (e, s) for e in ("small", "large") for s in ("ark4:rtol=1e-5", "ark5:rtol=1e-5")}
    for r in data["rows"]:
        assert sum(r["part_share"].values()) == pytest.approx(1.0)
        assert sum(r["phase_share"].values()) == pytest.approx(1.0)
        assert sum(r["rejected_share"].values()) == pytest.approx(r["rejected"] / r["steps"])
        assert 1.0 <= r["multirate_bound"] <= r["sliding_per_step"] + 1e-12
    # one sliding block (the small events here): nobody to take another step
    single = [r for r in data["rows"] if r["sliding_per_step"] == 1.0]
    assert single and all(r["multirate_bound"] == pytest.approx(1.0) for r in single)
    with pytest.raises(SystemExit, match="rk4:dt=1e-3 has no error control"):
        step_trace.main(["--runs", "rk4:dt=1e-3", "--out", str(tmp_path)])


@SCRIPT_RUN
def test_paired_tiny(tmp_path):
    data = paired.main(["--N", "40", "--rounds", "2", "--transient", "20", "--events", "60", "--cpu", "-1",
                        "--runs", "rk4:dt=1e-3", "ark4:rtol=1e-4", "--out", str(tmp_path)])
    assert data["baseline"] == "rk4:dt=1e-3"
    rk4, ark4 = data["settings"]["rk4:dt=1e-3"], data["settings"]["ark4:rtol=1e-4"]
    assert rk4["ratios"] == [1.0, 1.0]
    assert all(r > 0 for r in rk4["rates"] + ark4["rates"])
    assert ark4["ratios"] == [x / y for x, y in zip(ark4["rates"], rk4["rates"])]
    assert (tmp_path / "paired_N40_b20.txt").read_text().count("\n") >= 3
    with pytest.raises(SystemExit, match="atol"):
        paired.main(["--runs", "ark4:rtol=1e-4,atol=1e-9", "--out", str(tmp_path)])


@SCRIPT_RUN
def test_revisions_tiny(tmp_path):
    # a command that writes which package it ran: the same check as a reduction (as in docs/benchmarks.md), which
    # took 13 s here (four of them, and the revision's fresh checkout compiles its analysis kernels first)
    which = "import sys, ensemble; open(sys.argv[1], 'w').write(ensemble.__file__)"
    data = revisions.main(["--before", "HEAD", "--rounds", "1", "--cpu", "-1", "--name", "t", "--out", str(tmp_path),
                           "--", "python", "-c", which, str(tmp_path / "{side}.txt")])
    (now, _), (before, _) = data["cost"]["now"][0], data["cost"]["before"][0]
    assert now > 0 and before > 0 and data["cpu_ratios"] == [now / before]
    # each side ran its own checkout's code: this one's, and that of the revision's worktree
    ran = {side: Path((tmp_path / f"{side}.txt").read_text()) for side in ("before", "now")}
    assert ran["now"] == revisions.ROOT / "ensemble" / "__init__.py"
    assert ran["before"].parts[-2:] == ("ensemble", "__init__.py") and revisions.ROOT not in ran["before"].parents
    assert "cpu ratio now / before" in (tmp_path / "revisions_t.txt").read_text()
    assert str(tmp_path) not in subprocess.run(["git", "worktree", "list"], capture_output=True, text=True,
                                               cwd=revisions.ROOT).stdout   # its checkout of HEAD removed
    with pytest.raises(SystemExit, match="not a revision"):
        revisions.main(["--before", "no-such-revision", "--out", str(tmp_path), "--", "true"])


def test_phase_of_a_block():
    v = np.array([300.0, 300.0, 300.0, 0.0, -1.0])
    psi = np.array([-np.log(300.0) + 1.0, -np.log(300.0) + 0.05, -np.log(300.0) - 1.0, 3.0, 3.0])
    assert step_trace.phase(v, psi).tolist() == [0, 1, 2, 2, 2]


def test_transient_finds_a_known_drift():
    """Seeds whose first 600 events come from another distribution: the transient ends after the
    second window of 500 (the one holding events 500..599); without the drift, after none. The
    events are correlated (an AR(1) with 50 events' memory), as the floor from stretches allows."""
    from benchmarks.transient import point_curves
    rng = np.random.default_rng(7)

    def seed(drift):
        x = np.empty(20000)
        x[0] = 0.0
        noise = rng.normal(size=len(x)) * np.sqrt(1 - 0.98 ** 2)
        for i in range(1, len(x)):
            x[i] = 0.98 * x[i - 1] + noise[i]
        if drift:
            x[:600] -= 3.0
        return x
    drifting = point_curves([seed(True) for _ in range(4)], 500, 1.0, np.random.default_rng(1))
    assert drifting["end_events"] == 1000 and drifting["ks"][0] > 0.8
    steady = point_curves([seed(False) for _ in range(4)], 500, 1.0, np.random.default_rng(1))
    assert steady["end_events"] == 0
    # the floor from stretches sees the correlation: events drawn one by one would put it far lower
    late = np.sort(np.concatenate([seed(False)[10000:] for _ in range(4)]))
    from benchmarks.transient import ks
    iid = np.percentile([ks(rng.choice(late, 2000, replace=False), late) for _ in range(200)], 99)
    assert steady["floor"] > 2 * iid


@SCRIPT_RUN
def test_transient_tiny(tmp_path):
    from benchmarks import transient
    from ensemble.store import reader
    from .catalog_writer import write_events
    from .conftest import run_cli, write_config
    cfg = write_config(tmp_path / "t.toml", model={"N": 30, "b": 50.0},
                       run={"events": 500, "transient": 0, "seeds": 2})
    assert run_cli("run", cfg, "-o", tmp_path / "t.h5").returncode == 0
    transient.main([str(tmp_path / "t.h5"), "--window", "50", "--out", str(tmp_path)])
    rows = json.loads((tmp_path / "transient.json").read_text())
    assert len(rows) == 1 and len(rows[0]["ks"]) == 10 and rows[0]["end_events"] % 50 == 0
    assert (tmp_path / "transient.png").stat().st_size > 10_000
    # a catalog of a run with a transient (its first events, through the project's writer): refused
    events, _, _ = reader.read(tmp_path / "t.h5")
    cfg = write_config(tmp_path / "u.toml", model={"N": 30, "b": 50.0}, run={"events": 5, "transient": 10, "seeds": 2})
    write_events(tmp_path / "u.h5", cfg.read_text(),
                 [{c: v[events["task"] == k][:5] for c, v in events.items()} for k in (0, 1)])
    with pytest.raises(SystemExit, match="run.transient is 10"):
        transient.main([str(tmp_path / "u.h5"), "--out", str(tmp_path)])


def test_default_transient_is_ten_events_per_block_of_the_longest_chain():
    from ensemble.config import TRANSIENT_PER_BLOCK, Config, Run, loads
    assert TRANSIENT_PER_BLOCK == 10
    assert loads("").run.transient == 8000
    assert loads("[model]\nN = 1600\n").run.transient == 16000
    assert loads("[sweep]\nN = [100, 3000, 400]\n").run.transient == 30000
    assert loads("[run]\ntransient = 0\n").run.transient == 0
    assert Config(model=Model(N=60), run=Run()).run.transient == 600
    assert "transient = 8000" in loads("").to_toml()     # resolved, as the catalog stores it


def test_decorrelation_rule_finds_a_known_crossing():
    """Window means of D (windows of 5 events) 1e-6, 0.9 (a spike that falls back), 1e-3, 0.5, 1, ...
    against the edge 0.4 (half the independent minimum 0.8): decorrelated for good from the fourth
    window on, i.e. after 20 events; a late window near identity again means not decorrelated."""
    from benchmarks.decorrelation import decorrelation_length, edges, settled
    assert settled([0.1, 2.0, 0.1, 2.0, 3.0], 1.0) == 3
    assert settled([2.0, 3.0], 1.0) == 0 and settled([2.0, 0.5], 1.0) is None and settled([], 1.0) is None
    assert settled([0.9, 0.1, 0.8, 0.2], 0.5, rising=False) == 3
    edge = edges(np.array([[0.8, 1.1], [0.9, 1.0]]), np.array([[0.0, 0.2]]))
    assert edge == {"distance": 0.4, "agree": pytest.approx(0.6)}
    d = np.repeat([1e-6, 0.9, 1e-3, 0.5, 1.0, 1.0, 1.0, 0.6], 5)
    d[15:20] = [0.1, 0.9, 0.9, 0.2, 0.4]                  # mean 0.5, and single events below the edge
    assert decorrelation_length(d, edge["distance"], 5) == 20
    assert decorrelation_length(d[:-1], edge["distance"], 5) == 20    # a partial last window is dropped
    d[-5:] = 0.01                                         # the last window close to identity again
    assert decorrelation_length(d, edge["distance"], 5) is None
    agree = np.r_[np.ones(12), np.zeros(28)]              # identical for 12 events, then nothing matches
    assert decorrelation_length(agree, edge["agree"], 5, rising=False) == 15
    agree[33] = 1.0                                       # one chance match in a late window: 0.2 <= 0.6
    assert decorrelation_length(agree, edge["agree"], 5, rising=False) == 15


def test_decorrelation_sequences_are_compared_in_time():
    from benchmarks.decorrelation import first_difference, matched
    t = np.arange(10) * 100.0
    epicenter = np.arange(10) % 4
    slipped = np.ones(10, dtype=int)
    ref = (t, epicenter, slipped)
    # the same events, 20 later or earlier by turns, and one extra event between the 3rd and the 4th
    shifted = t + 20.0 * (-1.0) ** np.arange(10)
    other = (np.insert(shifted, 3, 250.0), np.insert(epicenter, 3, 7), np.insert(slipped, 3, 1))
    assert first_difference(ref, ref) is None
    assert first_difference(ref, other) == 4                       # at equal index: the extra event
    assert matched(ref, other, 30.0).all()                        # in time: every event is there
    assert not matched(ref, other, 10.0).any()                    # ... but not within 10
    moved = (other[0], other[1] + 1, other[2])
    assert not matched(ref, moved, 30.0).any()                    # another epicenter is no match


def test_decorrelation_forces_are_read_at_one_time():
    """Follower.force_at: the forces of every block at the time asked (brought there from each
    block's own time), as Trajectory.state gives them at the trajectory's clock."""
    from benchmarks.decorrelation import Follower
    from ensemble.config import Config, Run
    from ensemble.run.trajectory import Trajectory
    from ensemble.sweep import task_list
    cfg = Config(model=Model(N=40, b=20.0), run=Run(seeds=1))
    task = task_list(cfg)[0]
    traj = Trajectory(cfg, task)
    traj.advance(60)
    force, _ = traj.state()
    clock = traj.checkpoint().clock
    assert np.ptp(traj.checkpoint().since[:, 0]) > 0       # the stored forces hold at different times
    follower = Follower(traj)                              # integrates the next event
    now = float(clock[0] + clock[1])
    assert follower.rest[0] == now and follower.onsets[0] > now
    assert np.allclose(follower.force_at(now), force, rtol=0, atol=1e-9)
    later = now + 0.5 * (follower.onsets[0] - now)
    assert np.allclose(follower.force_at(later), force + cfg.model.nu * (later - now), rtol=0, atol=1e-9)
    assert len(follower.onsets) == 1                       # no event before `later`
    follower.force_at(follower.onsets[0] + 1.0)
    assert len(follower.onsets) == 2 and follower.rest[1] > follower.onsets[0]


def test_decorrelation_unperturbed_branch_continues_the_trajectory():
    """A branch without perturbation records what the trajectory it was taken from records next,
    exactly; one with a perturbation starts its first event later (forces only lowered)."""
    from benchmarks.decorrelation import branched
    from ensemble.config import Config, Run
    from ensemble.run.trajectory import Trajectory
    from ensemble.run.tasks import branch_rng
    from ensemble.sweep import task_list
    cfg = Config(model=Model(N=40, b=20.0), run=Run(seeds=2))
    tasks = task_list(cfg)
    traj = Trajectory(cfg, tasks[0])
    traj.advance(60)
    start = traj.checkpoint()
    force = start.force.copy()
    same = branched(cfg, tasks[0], start, 0.0, None)
    moved = branched(cfg, tasks[0], start, 1e-3, branch_rng(cfg, tasks[1]))
    expected = traj.advance(30)
    for got, want in zip(same.advance(30), expected):
        assert np.array_equal(got, want, equal_nan=True)     # (NaN: an initial phase that never ended)
    t, _, _ = moved.advance(30)
    assert t[0] > expected[0][0] and not np.array_equal(t, expected[0])
    assert np.array_equal(start.force, force)      # the branch point is left as it was


@SCRIPT_RUN
def test_decorrelation_tiny(tmp_path):
    from benchmarks import decorrelation
    data = decorrelation.main(["--N", "40", "--b", "20", "--spinup", "200", "--events", "200", "--branches", "2",
                               "--repeats", "2", "--perturbation", "0", "1e-3", "--window", "5",
                               "--out", str(tmp_path)])
    assert json.loads((tmp_path / "decorrelation.json").read_text())["config"]["events"] == 200
    assert (tmp_path / "decorrelation.png").stat().st_size > 10_000
    assert "suggested decorrelation stretch" in (tmp_path / "decorrelation.txt").read_text()
    (point,) = data["points"]
    zero, positive = point["perturbations"]
    # no perturbation: the branches are the reference, event for event and force for force, to the end
    assert zero["first_difference"] == [None] * 4
    assert np.max(zero["distance"]["max"]) == 0.0 and np.min(zero["agree"]["min"]) == 1.0
    assert zero["stress_events"] == zero["sequence_events"] == [None] * 4
    # a perturbation: forces differ at once, events later, and then as much as independent chains';
    # while the events are the same, so are the forces at one time (not at each one's own time)
    assert np.min(positive["distance"]["min"]) > 0
    assert np.max(positive["distance"]["max"][:min(positive["first_difference"]) - 2]) < 1e-2
    assert all(1 < f < 200 for f in positive["first_difference"])
    assert all(k is not None and 0 < k < 200 for k in positive["stress_events"] + positive["sequence_events"])
    assert 0.7 < positive["late_distance_ratio"] < 1.3
    lo, median, hi = point["band"]["distance"]
    assert 0 < point["edges"]["distance"] < lo <= median <= hi


def test_statistics_rerun_widens_the_floor_and_names_the_settings_within_it():
    """--rerun: the floor takes the rerun's halves and its full-size distance from the reference;
    a candidate is within the noise when every distance is at most the floor's max."""
    rng = np.random.default_rng(3)

    def seeds(shift):
        return {k: {"status": "ok", "mu": rng.normal(shift, 1, 2000), "tnu": rng.exponential(1 + shift, 500),
                    "seconds": 1.0} for k in range(4)}
    ref, rerun = seeds(0.0), seeds(0.3)          # a rerun far off: its direct distance sets the max
    floor = statistics.noise_floor(ref)
    wide = statistics.with_rerun(floor, ref, rerun)
    direct = statistics.distances(statistics.pooled(rerun)["mu"], statistics.pooled(ref)["mu"])["ks"]
    for key in floor:
        assert len(wide[key]["splits"]) == 2 * len(floor[key]["splits"]) + 1
    assert wide["ks_mu"]["max"] == pytest.approx(direct) and direct > 3 * floor["ks_mu"]["max"]
    keys = [f"{n}_{s}" for s in statistics.SAMPLES for n in statistics.DISTANCES]
    rows = [{"setting": "ref", "status": "ok"},
            {"setting": "close", "status": "ok", **{k: 0.5 * wide[k]["max"] for k in keys}},
            {"setting": "one off", "status": "ok", **{k: 0.5 * wide[k]["max"] for k in keys}, "w1_tnu": 1e9}]
    assert statistics.within_noise(rows, wide) == ["close"]
    # every setting against the rerun: the reference's row is the direct distance, a candidate's its own
    pools = [statistics.pooled(ref), statistics.pooled(seeds(0.3))]
    against = statistics.rerun_rows([{"setting": "ref"}, {"setting": "near the rerun"}], pools, rerun)
    assert [r["setting"] for r in against] == ["ref", "near the rerun"]
    assert against[0]["ks_mu"] == pytest.approx(direct) and against[1]["ks_mu"] < direct / 3
    assert against[1]["fraction_large_rerun"] == pytest.approx(np.mean(statistics.pooled(rerun)["mu"] >= 4))
    with pytest.raises(SystemExit):
        statistics.main(["--rerun", "x.h5"])      # a catalog-mode option without --catalogs
