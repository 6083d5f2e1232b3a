"""The benchmark scripts at tiny sizes: their helpers against known answers, their outputs sane."""
import json

import numpy as np
import pytest

from benchmarks import cost_scaling, hard_cases, statistics, step_budget, step_trace, work_precision
from benchmarks.baselines import BASELINES
from benchmarks.common import cost_at_error, ks_distance, parse_setting, wasserstein1
from ensemble.config import Model
from ensemble.events import advance_to_onset

from .conftest import developed_state


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


def test_work_precision_tiny(tmp_path):
    # no wall-time cap on the baselines ("inf"): every row must be "ok", which a cap would make
    # depend on the machine's load; the per-test timeout stands guard against a hang
    work_precision.main(["--N", "40", "--b", "20", "--transient", "60", "--max-seconds", "inf", "--out",
                         str(tmp_path), "--runs", "rk4:dt=1e-3", "rk4:dt=5e-4", "ark3:rtol=1e-4", "ark3:rtol=1e-7",
                         "scipy:method=LSODA,rtol=1e-5", "scipy:method=LSODA,rtol=1e-8"])
    data = json.loads((tmp_path / "work_precision_N40_b20.json").read_text())
    assert (tmp_path / "work_precision_N40_b20.png").stat().st_size > 0
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


def test_statistics_tiny(tmp_path):
    data = statistics.main(["--N", "40", "--seeds", "2", "--events", "120", "--transient", "40",
                            "--reference", "rk4:dt=1e-3", "--runs", "ark3:rtol=1e-3", "--out", str(tmp_path)])
    assert json.loads((tmp_path / "statistics_N40_b20.json").read_text())["rows"][1]["setting"] == "ark3:rtol=1e-3"
    ref, cand = data["rows"]
    assert ref["events"] == cand["events"] == 240 and cand["recurrences"] > 0
    assert cand["events_per_second"] > 0
    for key in ("ks_mu", "ks_tnu"):
        assert 0 < cand[key] <= 1
    for key in ("w1_mu", "w1_tnu"):
        assert 0 < cand[key] < np.inf
    for band in data["noise_floor"].values():
        assert np.isfinite(band["mean"]) and 0 <= band["min"] <= band["mean"] <= band["max"]


def test_cost_scaling_tiny(tmp_path):
    data = cost_scaling.main(["--runs", "rk4:dt=1e-3", "--Ns", "40", "80", "--bs", "20", "30", "--N-at", "40",
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


def test_transient_tiny(tmp_path):
    from benchmarks import transient
    from .conftest import run_cli, write_config
    cfg = write_config(tmp_path / "t.toml", model={"N": 30, "b": 50.0},
                       run={"events": 2000, "transient": 0, "seeds": 2}, integrator={"method": "ark4"})
    assert run_cli("run", cfg, "-o", tmp_path / "t.h5").returncode == 0
    transient.main([str(tmp_path / "t.h5"), "--window", "200", "--out", str(tmp_path)])
    rows = json.loads((tmp_path / "transient.json").read_text())
    assert len(rows) == 1 and len(rows[0]["ks"]) == 10 and rows[0]["end_events"] % 200 == 0
    assert (tmp_path / "transient.png").stat().st_size > 10_000
    cfg = write_config(tmp_path / "u.toml", model={"N": 30}, run={"events": 50, "transient": 10, "seeds": 2})
    assert run_cli("run", cfg, "-o", tmp_path / "u.h5").returncode == 0
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
