"""benchmarks/time_to_statistics.py: the schedule model on known answers, and a tiny end-to-end run."""
import json

import pytest

from benchmarks import time_to_statistics as tts

from .conftest import write_config


def test_schedule_replays_the_counter():
    # one rank: the sum; two ranks: the next item goes to the rank free first
    assert tts.schedule([3, 1, 1, 1], 1) == 6
    assert tts.schedule([3, 1, 1, 1], 2) == 3          # 3 | 1 1 1
    assert tts.schedule([1, 1, 1, 3], 2) == 4          # 1 1 | 1 3
    # a barrier after the first two items: nobody starts item 2 before both are done
    assert tts.schedule([3, 1, 1, 1], 2, barrier=2) == 4     # 3 | 1 . . ; then 1 | 1
    assert tts.schedule([1, 1], 4) == 1                 # idle ranks cost nothing


def test_work_items_of_a_run_with_and_without_branching():
    costs = [{"spinup": 10.0, "event": 0.01}, {"spinup": 20.0, "event": 0.02}]
    items, barrier = tts.work_items(costs, seeds=2, events=1000, branch=False, decorrelation=100)
    assert barrier == 0 and items == pytest.approx([15, 15, 30, 30])      # transient + 500 events each
    items, barrier = tts.work_items(costs, seeds=2, events=1000, branch=True, decorrelation=100)
    assert barrier == 2 and items == pytest.approx([10, 20, 6, 6, 12, 12])   # spin-ups, then 600 events
    wall, core = tts.predict(costs, 1.0, 2, 2, 1000, True, 100)
    assert wall == pytest.approx(1 + 20 + 18) and core == pytest.approx(66)


def test_best_seeds_trades_transients_against_parallelism():
    costs = [{"spinup": 100.0, "event": 0.01}] * 4      # a transient costs 1e4 events
    # one rank: one seed per point (each more seed adds a transient)
    assert tts.best_seeds(costs, 0.0, 1, 200000, False, 100)[0] == 1
    # 64 ranks: 16 seeds per point keep every rank busy; branching pays one spin-up per point
    seeds, wall, _ = tts.best_seeds(costs, 0.0, 64, 200000, False, 100)
    assert seeds == 16 and wall == pytest.approx(100 + 12500 * 0.01)
    seeds, wall, core = tts.best_seeds(costs, 0.0, 64, 200000, True, 100)
    assert seeds == 16 and wall == pytest.approx(100 + 12600 * 0.01) and core == pytest.approx(400 + 64 * 126)


@pytest.mark.slow    # (a benchmark script's own run, 10 s: it tests the benchmark, not the product; CI runs it)
def test_a_tiny_run_measures_calibrates_and_writes(tmp_path):
    """Calibration in this process, then three runs of `python -m ensemble` (the fixed cost, without and with
    branching), each of a few seconds: mostly the start-up of a process."""
    cfg = write_config(tmp_path / "tiny.toml", model={"N": 30}, sweep={"b": [20.0, 50.0]},
                       run={"events": 40, "transient": 20, "decorrelation": 10, "seeds": 2})
    out = tmp_path / "out"
    assert tts.main(["--config", str(cfg), "--ranks", "1", "--seeds", "2", "--events", "80",
                     "--project", "1", "4", "--full-events", "2000", "--calibrate", "20", "--out", str(out)]) == 0
    data = json.loads((out / "time_to_statistics.json").read_text())
    assert [c["point"] for c in data["costs"]] == [0, 1] and all(c["event"] > 0 for c in data["costs"])
    assert [(m["ranks"], m["branch"]) for m in data["measured"]] == [(1, False), (1, True)]
    assert all(m["measured"] > 0 and m["model"] > 0 for m in data["measured"])
    assert len(data["projected"]) == 4 and (out / "time_to_statistics.png").exists()
    text = (out / "time_to_statistics.txt").read_text()
    assert "| 1 | yes |" in text and "model / measured" in text
