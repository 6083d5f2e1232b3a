"""Populations of faults ([population], ensemble/population.py) and their regions (reduce --region,
analysis/region.py): the draws, the config's checks, the runner's promises, and a region's statistics
against a hand computation.

The commands run in this process (analysis.cli.main and ensemble.cli.main, which `python -m analysis` and
`python -m ensemble` call): a process of its own costs about 2.5 s of imports, more than the command's work
here. Only the runs under mpiexec, and the one killed, are processes of their own."""
import hashlib
import math
import sys

import numpy as np
import pytest

from analysis import summary
from ensemble.config import ConfigError, Model, loads
from ensemble.population import Draw, draw_values
from ensemble.sweep import task_list

from .catalog_writer import write_events
from .conftest import write_config
from .processes import analysis_here, ensemble_here

POPULATION = """
[model]
N = 40
[run]
events = 400
transient = 5
[population]
faults = {faults}
seed = 11
b = {{distribution = "uniform", min = 20, max = 50}}
{extra}
"""


def population(faults=6, extra="", sweep=""):
    return loads(POPULATION.format(faults=faults, extra=extra) + (f"[sweep]\n{sweep}\n" if sweep else ""))



# -- the draws ---------------------------------------------------------------------------------

def test_a_faults_draws_are_its_own():
    """Fault f's value of a key depends on the root seed, f and the key only: not on how many faults are drawn,
    nor on which other keys are; two regions of one sweep draw the same numbers (common random numbers)."""
    few, many = task_list(population(4)), task_list(population(9))
    assert [t.model.b for t in few] == [t.model.b for t in many[:4]]
    with_a = task_list(population(4, 'a = {distribution = "loguniform", min = 1, max = 30}'))
    assert [t.model.b for t in with_a] == [t.model.b for t in few] and len({t.model.a for t in with_a}) == 4
    swept = task_list(population(3, sweep="population.N = [[20, 30], [200, 300]]"))
    assert [t.region for t in swept] == [0, 0, 0, 1, 1, 1] and [t.point for t in swept] == list(range(6))
    low = [t.model.N for t in swept[:3]]
    assert set(low) <= {20, 30} and [{20: 200, 30: 300}[n] for n in low] == [t.model.N for t in swept[3:]]
    assert [t.model.b for t in swept[:3]] == [t.model.b for t in swept[3:]]
    other_seed = loads(POPULATION.format(faults=4, extra="").replace("seed = 11", "seed = 12"))
    assert [t.model.b for t in task_list(other_seed)] != [t.model.b for t in few]


# The draws below come from one generator each: sample() maps one number of its generator to a value, whatever
# stream it comes from (a fault's own stream is test_a_faults_draws_are_its_own's); a generator per draw, as a
# population makes, costs ~5 times the draw itself.

def test_integer_power_law_draws_have_the_stated_probabilities():
    """P(N = n) proportional to n^-exponent on [min, max], exactly: 40000 draws against the probabilities
    (each frequency within 5 binomial standard deviations), exponents 0, 1 and 2.5."""
    n = np.arange(2, 13)
    for alpha in (0.0, 1.0, 2.5):
        spec = Draw("power", 2, 12, alpha)
        rng = np.random.default_rng([7, int(10 * alpha)])
        values = np.array([spec.sample(rng, True) for _ in range(40000)])
        p = n ** -alpha / np.sum(n ** -alpha)
        freq = np.array([np.mean(values == k) for k in n])
        assert values.min() >= 2 and values.max() <= 12
        assert np.all(np.abs(freq - p) <= 5 * np.sqrt(p * (1 - p) / len(values))), (alpha, freq, p)


@pytest.mark.parametrize("kind,alpha,cdf", [
    ("uniform", None, lambda x: (x - 2) / 6),
    ("loguniform", None, lambda x: np.log(x / 2) / np.log(4)),
    ("power", 2.0, lambda x: (1 / 2 - 1 / x) / (1 / 2 - 1 / 8)),
    ("power", 1.0, lambda x: np.log(x / 2) / np.log(4)),
])
def test_float_draws_follow_their_distribution(kind, alpha, cdf):
    """On [2, 8]: the KS distance of 20000 draws from the stated CDF is below the 0.1% critical value."""
    spec = Draw(kind, 2.0, 8.0, alpha)
    rng = np.random.default_rng(3)
    x = np.sort([spec.sample(rng, False) for _ in range(20000)])
    ecdf = np.arange(1, len(x) + 1) / len(x)
    assert 2 <= x[0] and x[-1] <= 8
    assert np.max(np.abs(ecdf - cdf(x))) < 1.95 / math.sqrt(len(x))


def test_a_list_draws_each_value_alike():
    spec = Draw("list", values=(3.0, 6.0, 12.0))
    rng = np.random.default_rng(5)
    x = np.array([spec.sample(rng, False) for _ in range(30000)])
    assert all(abs(np.mean(x == v) - 1 / 3) < 5 * math.sqrt(2 / 9 / 30000) for v in (3.0, 6.0, 12.0))


# -- the config ---------------------------------------------------------------------------------

BAD = [  # (the [population] lines beyond faults and seed, the [run] lines, the [sweep] lines), what the error names
    ('b = {distribution = "uniform", min = 50, max = 20}', "", "", "population.b: the range is empty"),
    ('b = {distribution = "uniform", min = 20, max = 20}', "", "", "population.b: the range is empty"),
    ('N = {distribution = "power", exponent = -1, min = 100, max = 1600}', "", "",
     "population.N.exponent must be >= 0"),
    ('N = {distribution = "power", exponent = 2, min = 1, max = 1600}', "", "", "population.N.min must be at least 2"),
    ("N = [1, 40]", "", "", "population.N must be at least 2"),
    ('N = {distribution = "power", exponent = 2, min = 10.5, max = 1600}', "", "",
     "population.N.min must be an integer"),
    ('b = {distribution = "normal", min = 20, max = 50}', "", "", "population.b.distribution must be one of"),
    ('b = {min = 20, max = 50}', "", "", "population.b.distribution must be one of"),
    ('b = {distribution = "uniform", min = 20}', "", "", "population.b.max is missing"),
    ('a = {distribution = "loguniform", min = 0, max = 30}', "", "", "population.a.min must be > 0"),
    ('b = {distribution = "uniform", min = 20, max = 50, exponent = 2}', "", "", "unknown key population.b.exponent"),
    ("b = []", "", "", "population.b must be a non-empty list"),
    ("b = 20", "", "", "population.b must be a list of values or a table"),
    ("nu = [1e-8, 1e-7]", "", "", "population.nu: model.nu is not drawn"),
    ("alpha = [1, 2]", "", "", "population.alpha does not belong to model.law"),
    ("colour = [1, 2]", "", "", "unknown key population.colour"),
    ('l = {distribution = "uniform", min = -1, max = 3}', "", "", "population.l.min must be > 0"),
    ("", "seeds = 2", "", "run.seeds = 2: with a [population] each fault is one trajectory"),
    ("", "branch = true", "", "run.branch = true: a population"),
    ("", "", "b = [20, 30]", "sweep.b and population.b both set model.b"),
    ("", "", "population.N = []", "sweep.population.N must be a non-empty list"),
    ("", "", 'population.N = [[10], {distribution = "power", exponent = 1, min = 1, max = 10}]',
     "sweep.population.N.min must be at least 2"),
]


@pytest.mark.parametrize("population_lines,run_lines,sweep_lines,message", BAD)
def test_bad_population_specs_are_errors_naming_the_key(population_lines, run_lines, sweep_lines, message):
    text = (f"[run]\nevents = 10\n{run_lines}\n[population]\nfaults = 3\n{population_lines or 'b = [20.0]'}\n"
            + (f"[sweep]\n{sweep_lines}\n" if sweep_lines else ""))
    with pytest.raises(ConfigError) as err:
        loads(text)
    assert message in str(err.value) and "\n" not in str(err.value)


@pytest.mark.parametrize("lines,message", [
    ("[population]\nfaults = 0\n", "population.faults must be an integer in [1,"),
    ("[population]\nseed = 3\n", "population.faults is missing"),
    ("[sweep]\npopulation.b = [[20]]\n", "sweep.population.b needs a [population] section"),
])
def test_a_population_needs_its_faults(lines, message):
    with pytest.raises(ConfigError, match=message.replace("[", r"\[")):
        loads(lines)


def test_validate_refuses_a_bad_spec_in_one_line_and_lists_each_faults_parameters(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('[population]\nfaults = 3\nN = {distribution = "power", exponent = -2, min = 100, max = 1600}\n')
    res = ensemble_here("validate", bad)
    assert res.returncode == 2 and res.stderr.strip().count("\n") == 0 and "population.N.exponent" in res.stderr
    good = tmp_path / "good.toml"
    good.write_text(POPULATION.format(faults=3, extra="N = [20, 30]"))
    res = ensemble_here("validate", good)
    assert res.returncode == 0, res.stderr
    tasks = task_list(loads(good.read_text()))
    for t in tasks:
        assert f"# task {t.index}: point {t.index} region 0 fault {t.index} N={t.model.N} " in res.stdout
        assert f"b={t.model.b!r}" in res.stdout


def test_the_stored_config_reads_back_as_itself():
    cfg = population(5, 'N = {distribution = "power", exponent = 2, min = 100, max = 1600}\nl = [3, 6]',
                     sweep='population.a = [[0], {distribution = "loguniform", min = 0.5, max = 30}]\nc = [1e3, 1e4]')
    again = loads(cfg.to_toml())
    assert again == cfg and [t.model for t in task_list(again)] == [t.model for t in task_list(cfg)]
    assert len(task_list(cfg)) == 4 * 5
    # run.transient's default: 10 events per block of the longest fault any distribution allows
    free = loads("[population]\nfaults = 2\nN = {distribution = \"power\", exponent = 2, min = 100, max = 1600}\n")
    assert free.run.transient == 16000


# -- a region's statistics against a hand computation ---------------------------------------------

def _events(task, t, mu, n_chain=40):
    n = len(t)
    epi = (np.arange(n) * 7) % n_chain
    return {"task": np.full(n, task, dtype=np.int64), "t": np.asarray(t, dtype=float),
            "epicenter": epi.astype(np.int64),
            "mu": np.full(n, mu), "slip": np.full(n, 10.0 ** mu), "first": epi.astype(np.int64),
            "last": epi.astype(np.int64), "n_slipped": np.ones(n, dtype=np.int64), "boundary": np.zeros(n, bool),
            "duration": np.full(n, 0.5), "kind": np.zeros(n, np.int8), "ending": np.zeros(n, np.int8)}


@pytest.fixture(scope="module")
def two_faults(tmp_path_factory):
    """Two faults of disjoint magnitudes and different rates: fault 0 an event every 1 (mu = 1.05) from t = 0,
    fault 1 every 7 (mu = 3.05) from t = 100; 400 events each."""
    d = tmp_path_factory.mktemp("region")
    text = POPULATION.format(faults=2, extra="")
    path = d / "two.h5"
    write_events(path, text, [_events(0, np.arange(400.0), 1.05), _events(1, 100 + 7 * np.arange(400.0), 3.05)])
    return d, path


def test_a_region_of_two_faults_is_their_rate_weighted_mixture(two_faults):
    """The window is the shorter span (fault 0: 399 / nu... of loading): fault 0 gives its events with
    0 <= t < 399 (399 events), fault 1 those with 100 <= t < 499 (57); a single-fault reduction counts 400 each."""
    d, path = two_faults
    out = d / "two.region.h5"
    res = analysis_here("reduce", path, "--region", "-o", out, "--bootstrap", 50)
    assert res.returncode == 0, res.stderr
    # each fault discarded 5 events, fewer than the 50 its 40 blocks may need: both named
    assert res.stderr.count("discarded 5 events before it recorded") == 2, res.stderr
    s = summary.read(out)
    numbers = {name: s[f"points/numbers/{name}"][0][0] for name in ("n_events", "n_large", "fraction_large", "gr_b")}
    assert len(s["points/N"]) == 1 and s["points/method"][0] == "blocks"       # 2 faults: fewer than MIN_UNITS
    assert numbers["n_events"] == 399 + 57
    assert numbers["fraction_large"] == 0.0                                      # mu_c = 4: none large
    edges = s["bins/mu"]
    width = np.diff(edges)
    expect = np.zeros(len(width))
    expect[np.searchsorted(edges, 1.05) - 1] = 399 / (456 * width[10])
    expect[np.searchsorted(edges, 3.05) - 1] = 57 / (456 * width[30])
    assert np.allclose(s["points/mu_density"][0], expect, rtol=1e-12, atol=0)
    # GR b above 3 from fault 1's 57 events alone (Aki: log10(e) / (mean - cut))
    assert numbers["gr_b"] == pytest.approx(math.log10(math.e) / 0.05, rel=1e-9)
    nu = loads(s["attrs"]["config"]).model.nu
    assert s["points/region_span"][0] == pytest.approx(399 * nu, rel=1e-12)
    assert list(s["tasks/window_start"]) == [0.0, 100.0]
    assert np.allclose(s["tasks/window_end"], [399.0, 499.0], rtol=1e-12)
    assert np.isnan(s["points/b"][0]) and s["points/N"][0] == 40                  # drawn / shared
    # the same catalog point by point: every event of each fault
    plain = d / "two.plain.h5"
    assert analysis_here("reduce", path, "-o", plain, "--bootstrap", 50).returncode == 0
    p = summary.read(plain)
    assert list(p["points/numbers/n_events"][:, 0]) == [400, 400]
    res = analysis_here("report", out)
    assert res.returncode == 0 and "region 0: b: uniform on [20, 50]; aging: N = 40" in res.stdout
    # the later part alone: windows from 100 (T nu / nu) after each first onset, for the 299 left of the shorter span
    later = d / "two.later.h5"
    res = analysis_here("reduce", path, "--region", "--region-skip", 100 * nu, "-o", later, "--bootstrap", 20)
    assert res.returncode == 0, res.stderr
    s = summary.read(later)
    assert np.allclose(s["tasks/window_start"], [100.0, 200.0], rtol=1e-12)
    assert s["points/numbers/n_events"][0][0] == 299 + 42      # t in [100, 399) and 100 + 7k in [200, 499)


def test_a_partial_region_leaves_out_the_faults_not_yet_recorded(tmp_path):
    """An unfinished run: a third fault with no events yet is left out with --partial (said), and the region is
    the two faults' mixture."""
    path = tmp_path / "three.h5"
    write_events(path, POPULATION.format(faults=3, extra=""), [
        _events(0, np.arange(400.0), 1.05), _events(1, 100 + 7 * np.arange(400.0), 3.05), _events(2, [], 2.0)])
    res = analysis_here("reduce", path, "--region", "-o", tmp_path / "r.h5")
    assert res.returncode == 1 and "unfinished run" in res.stderr
    res = analysis_here("reduce", path, "--region", "--partial", "-o", tmp_path / "r.h5", "--bootstrap", 20)
    assert res.returncode == 0, res.stderr
    assert "1 of 3 faults left out: fewer than two inertial events recorded yet" in res.stderr
    s = summary.read(tmp_path / "r.h5")
    assert s["points/numbers/n_events"][0][0] == 399 + 57 and list(s["tasks/catalog_task"]) == [0, 1]


def test_region_errors_are_one_line(two_faults, tmp_path):
    d, path = two_faults
    res = analysis_here("reduce", path, "--region", "--region-span", 1.0, "-o", tmp_path / "x.h5")
    assert res.returncode == 2 and "--region-span 1: " in res.stderr and "task 0 spans only 3.99e-06" in res.stderr
    assert res.stderr.strip().count("\n") == 0
    res = analysis_here("reduce", path, "--region-span", 1e-6, "-o", tmp_path / "x.h5")
    assert res.returncode == 2 and "give --region too" in res.stderr
    res = analysis_here("reduce", path, "--region", "--region-skip", 1.0, "-o", tmp_path / "x.h5")
    assert res.returncode == 2 and "fewer than two inertial events recorded after --region-skip 1" in res.stderr
    single = tmp_path / "single.h5"
    text = "[model]\nN = 40\n[run]\nevents = 400\ntransient = 5\nseeds = 1\n"
    write_events(single, text, [_events(0, np.arange(400.0), 1.05)])
    res = analysis_here("reduce", single, "--region", "-o", tmp_path / "y.h5")
    assert res.returncode == 2 and "has no [population]" in res.stderr and not (tmp_path / "y.h5").exists()


def test_a_region_of_many_faults_resamples_faults(tmp_path):
    """12 faults with rates 1..12 over a common span: the events' interval is the bootstrap over faults by
    hand, from the region's own generator (analysis/region.py)."""
    path = tmp_path / "many.h5"
    text = POPULATION.format(faults=12, extra="")
    parts = [_events(k, np.arange(400.0) / (k + 1), 1.05 + 0.1 * (k % 3)) for k in range(12)]
    write_events(path, text, parts)
    out = tmp_path / "many.region.h5"
    res = analysis_here("reduce", path, "--region", "-o", out, "--bootstrap", 300, "--seed", 4)
    assert res.returncode == 0, res.stderr
    s = summary.read(out)
    assert s["points/method"][0] == "faults" and s["points/units"][0] == 12
    span = 399 / 12                                   # the fastest fault's
    counts = np.array([np.count_nonzero(np.arange(400.0) / (k + 1) < span) for k in range(12)])
    assert s["points/numbers/n_events"][0][0] == counts.sum()
    # the region's generator as documented: SeedSequence(--seed, spawn_key = sha256(its text)'s first 4 words)
    digest = hashlib.sha256(s["points/region"][0].encode()).digest()
    rng = np.random.default_rng(np.random.SeedSequence(4, spawn_key=tuple(
        int.from_bytes(digest[i:i + 4], "little") for i in range(0, 16, 4))))
    draws = counts[rng.integers(0, 12, size=(300, 12))].sum(axis=1)
    lo, hi = np.percentile(draws, [2.5, 97.5], method="linear")
    assert s["points/numbers/n_events"][0][1:] == pytest.approx([lo, hi], rel=1e-12)
    # the figure says what its bands resample (a region's faults)
    from analysis import plot
    import matplotlib.pyplot as plt
    fig = plot.figure([s], "magnitude")
    words = [t.get_text() for t in fig.findobj(match=lambda a: hasattr(a, "get_text"))]
    assert any("bootstrap over 12 faults" in w for w in words), words
    plt.close(fig)


def test_a_regions_magnitude_figure_shows_its_faults(two_faults):
    d, path = two_faults
    out = d / "fig.region.h5"
    assert analysis_here("reduce", path, "--region", "-o", out, "--bootstrap", 20).returncode == 0
    from analysis import plot
    import matplotlib.pyplot as plt
    fig = plot.figure([summary.read(out)], "magnitude")
    ax = fig.axes[0]
    grey = [line for line in ax.get_lines() if line.get_color() == "0.6"]
    assert len(grey) == 2      # one per fault
    plt.close(fig)


# -- the runner -----------------------------------------------------------------------------------

def test_population_configs_of_an_array_job_are_one_per_region(tmp_path):
    cfg = tmp_path / "pop.toml"
    cfg.write_text(POPULATION.format(faults=3, extra="N = [20, 30]") + "[sweep]\npopulation.a = [[0], [5, 10]]\n")
    res = ensemble_here("slurm", cfg, "--ntasks", 2, "--time", "10", "--kind", "array", "-o", tmp_path / "job")
    assert res.returncode == 0, res.stderr
    elements = sorted((tmp_path / "job" / "points").glob("*.toml"))
    assert len(elements) == 2
    whole = task_list(loads(cfg.read_text()))
    for i, path in enumerate(elements):
        one = loads(path.read_text())
        assert one.sweep == () and one.population.faults == 3
        assert [t.model for t in task_list(one)] == [t.model for t in whole if t.region == i]
    assert "REGION=1" in (tmp_path / "job" / "reduce.sbatch").read_text()


@pytest.mark.mpi
def test_a_population_runs_alike_on_one_and_two_ranks_and_resumes(tmp_path):
    """A run on two ranks, killed (kill -9) after its first committed batch and resumed on two ranks, gives
    the serial run's catalog: each rank started faults of its own before the kill, and the resume the rest.
    (4 faults of 120 events: ~2 s on 2 ranks, ~3/4 of it left after the first batch, measured.)"""
    from ensemble.store import reader
    from ensemble.store.files import partial_path
    from .same_catalogs import assert_same_events
    from .test_mpi import mpirun, start_and_interrupt
    events = 120
    cfg = write_config(tmp_path / "pop.toml", model={"N": 40, "b": 20.0},
                       run={"seeds": 1, "events": events, "transient": 20},
                       population={"faults": 4, "seed": 2, "N": [24, 60]},
                       output={"batch": 20, "flush_seconds": 0.25, "progress_seconds": 0.5})
    res = ensemble_here("run", cfg, "-o", tmp_path / "serial.h5")
    assert res.returncode == 0, res.stderr
    code, log = start_and_interrupt(cfg, tmp_path / "cut.h5", "kill")
    assert code != 0 and not (tmp_path / "cut.h5").exists()
    _, table, _ = reader.read_tasks(partial_path(tmp_path / "cut.h5"))
    assert 0 < table["events_written"].sum() < 4 * events          # really cut in the middle
    res = mpirun(2, "run", cfg, "-o", tmp_path / "cut.h5", "--resume")
    assert res.returncode == 0, res.stderr + log
    assert_same_events(tmp_path / "serial.h5", tmp_path / "cut.h5")
    tasks = task_list(loads(cfg.read_text()))
    _, table, _ = reader.read_tasks(tmp_path / "cut.h5")
    assert list(table["N"]) == [t.model.N for t in tasks] and set(table["N"]) <= {24, 60}


def test_the_model_record_of_a_fault_is_its_draw():
    cfg = population(5, "N = [20, 30]\nl = [3, 6]")
    types = {f.name: f.type for f in Model.__dataclass_fields__.values()}
    for t in task_list(cfg):
        drawn = draw_values(cfg.population, t.fault, cfg.population.draws, types)
        assert {k: getattr(t.model, k) for k in drawn} == drawn
        assert isinstance(t.model.N, int) and t.model.c == 1000.0


def _answer():
    """examples/populations/answer.py, the table of docs/populations.md (a script, not a module of the package)."""
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).parents[1] / "examples" / "populations"))
    try:
        import answer
    finally:
        sys.path.pop(0)
    return answer


def _gr_counts(b, lo, hi, n, edges):
    """The expected (not drawn) counts of n magnitudes of GR(b) truncated to [lo, hi), in the bins of edges."""
    k = b * math.log(10)
    cdf = np.clip((1 - np.exp(-k * (edges - lo))) / (1 - math.exp(-k * (hi - lo))), 0, 1)
    return n * np.diff(cdf)


def _answer_and_figure(monkeypatch):
    """answer.py and figure.py, their bootstraps cut to 10 resamples (only estimates are checked with them)."""
    answer = _answer()
    monkeypatch.setattr(answer, "RESAMPLES", 10)
    sys.path.insert(0, str(__import__("pathlib").Path(answer.__file__).parent))
    try:
        import figure
    finally:
        sys.path.pop(0)
    monkeypatch.setattr(figure, "RESAMPLES", 10)
    return answer, figure


def test_the_answers_two_decade_fit_recovers_a_gutenberg_richter_law():
    """answer.py's truncated-GR fit: exact GR counts give b back and KS 0; the best stretch of a GR law with a
    hump of large events is found below the hump; the top stretch, over the hump, is far from GR; a stack of
    histograms is fitted as each alone."""
    answer = _answer()
    edges = np.linspace(0, 7, 701)
    gr = _gr_counts(0.7, 1.0, 7.0, 1e5, edges)
    ks, b = answer.truncated_gr_ks(gr[100:300], edges[100:301])
    assert b == pytest.approx(0.7, abs=1e-6) and ks < 1e-7
    hump = gr + 2e4 * np.diff(0.5 * (1 + np.vectorize(math.erf)((edges - 5.2) / (0.2 * math.sqrt(2)))))
    ks, lo, b = answer.best_decades(hump, edges)
    assert ks < 1e-6 and lo + 2 <= 4.4 and b == pytest.approx(0.7, abs=1e-4)
    ks, lo, b = answer.top_decades(hump, edges)
    assert ks > 0.3 and 3 <= lo < 4.5
    rows = np.stack([gr[200:400], hump[200:400], np.zeros(200)])
    ks_all, b_all = answer.truncated_gr_ks(rows, edges[200:401])
    for i in range(2):
        assert (ks_all[i], b_all[i]) == pytest.approx(answer.truncated_gr_ks(rows[i], edges[200:401]), rel=1e-9)
    assert np.isnan(ks_all[2]) and np.isnan(b_all[2])


def test_the_answer_finds_a_region_of_gr_faults_critical_and_a_characteristic_one_not(tmp_path, monkeypatch):
    """examples/populations/answer.py and figure.py end to end, on regions whose answer is known: twelve faults
    whose magnitudes follow GR (b = 0.7 on [1, 6]) make a region whose best two decades are GR (KS < 0.05, b back);
    twelve faults with 70% of their events in a hump at mu = 5 do not, over their top two decades (their best two
    decades are the flat part below the hump: KS small, but with b near 0, which is why the b is reported too).
    The bootstraps over faults run 10 resamples: only their estimates are checked here (the intervals of the
    docs' tables are test_the_docs_tables_are_the_committed_summaries'). One figure draws both regions."""
    answer, figure = _answer_and_figure(monkeypatch)
    rng = np.random.default_rng(3)
    k = 0.7 * math.log(10)

    def gr(n):
        return 1 - np.log1p(-rng.random(n) * -math.expm1(-5 * k)) / k      # truncated GR on [1, 6)

    def hump(n):
        return np.where(rng.random(n) < 0.7, rng.normal(5, 0.1, n), rng.uniform(1, 4, n))
    for name, draw in (("gr", gr), ("hump", hump)):
        path = tmp_path / f"{name}.h5"
        write_events(path, POPULATION.format(faults=12, extra="").replace("events = 400", "events = 1500"),
                     [_events(f, np.arange(1500.0) / (1 + f % 3), draw(1500)) for f in range(12)])
        out = tmp_path / f"{name}.region.h5"
        res = analysis_here("reduce", path, "--region", "--mu-bins", "0:7:700", "-o", out, "--bootstrap", 50)
        assert res.returncode == 0, res.stderr
        assert answer.main([str(out), "-o", str(tmp_path / name)]) == 0
        row = __import__("json").loads((tmp_path / f"{name}.json").read_text())[0]
        best, top = row["best_two_decades"], row["top_two_decades"]
        if name == "gr":
            assert best["ks"][0] < answer.CRITICAL_KS and best["gr_b"] == pytest.approx(0.7, abs=0.05)
            assert top["ks"][0] < answer.CRITICAL_KS
        else:
            assert top["ks"][0] > 0.2 and best["gr_b"] < 0.1
        assert row["region"] in (tmp_path / f"{name}.md").read_text()
    pairs = [str(tmp_path / f"{name}{suffix}") for name in ("gr", "hump") for suffix in (".region.h5", ".json")]
    assert figure.main([*pairs, "-o", str(tmp_path / "both.png")]) == 0
    assert (tmp_path / "both.png").stat().st_size > 10000


def test_the_answer_and_its_figure_on_a_small_population_say_what_they_cannot_compute(tmp_path, monkeypatch):
    """A small population (four faults of 300 events, the default bins of 0.1): answer.py prints no numpy warning
    and no nan (it printed "All-NaN slice" and "nan (nan-nan)": no fault, nor the region, has the 1000 events two
    decades need), and says so in words; figure.py's title gives the bins it drew (it said 0.1 while drawing bins
    of 1.0), its legend lies inside the figure (it was clipped on both sides) and the fitted law ends where the
    region's events do (it ran past them)."""
    import json
    import warnings
    answer, figure = _answer_and_figure(monkeypatch)
    drawn = []
    monkeypatch.setattr(figure, "save", lambda fig, path, dpi: drawn.append(fig))
    rng = np.random.default_rng(5)
    path = tmp_path / "small.h5"
    write_events(path, POPULATION.format(faults=4, extra="").replace("events = 400", "events = 300"),
                 [_events(f, np.arange(300.0) * (1 + f), rng.uniform(1.0, 2.6, 300)) for f in range(4)])
    regions, faults = tmp_path / "small.region.h5", tmp_path / "small.faults.h5"
    for out, extra in ((regions, ["--region"]), (faults, [])):
        res = analysis_here("reduce", path, *extra, "-o", out, "--bootstrap", 20)
        assert res.returncode == 0, res.stderr
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert answer.main([str(regions), "--faults", str(faults), "-o", str(tmp_path / "small")]) == 0
        table = (tmp_path / "small.md").read_text()
        assert "nan" not in table.lower() and "- (no fault has enough events)" in table, table
        assert "- (no two decades with 1000 events)" in table, table
        assert figure.main([str(regions), str(tmp_path / "small.json"), "-o", str(tmp_path / "small.png")]) == 0
    fig = drawn[0]
    assert "R(mu) in bins of 0.1," in fig._suptitle.get_text(), fig._suptitle.get_text()
    fig.canvas.draw()
    box, legend = fig.bbox, fig.legends[0].get_window_extent()
    assert box.x0 <= legend.x0 and legend.x1 <= box.x1 and box.y0 <= legend.y0, (legend, box)
    row = json.loads((tmp_path / "small.json").read_text())[0]
    assert not np.isfinite(row["best_two_decades"]["ks"][0])
    assert "no GR fit" in " ".join(t.get_text() for t in fig.axes[0].texts)
    figure.plt.close(fig)
    # a fit whose two decades reach past the last event: the law is drawn up to it
    edges = np.linspace(0.0, 7.0, 71)
    r = np.where(edges[1:] <= 2.6, 1.0, 0.0)
    mu, _ = figure.gr_line(edges, r, {"lo": 1.5, "gr_b": 0.7})
    assert mu[0] == 1.5 and mu[-1] == pytest.approx(2.6)


@pytest.mark.parametrize("name", ["regions", "short"])
def test_the_docs_tables_are_the_committed_summaries(name):
    """docs/populations.md's tables are answer.py's, from the committed regional summaries: the region's numbers,
    its hump and its best and top two decades recomputed here (a number edited by hand anywhere fails)."""
    import json
    from pathlib import Path
    from analysis.paper import shape_statistics
    answer = _answer()
    docs = Path(__file__).parents[1] / "docs" / "populations"
    s = summary.read(docs / f"{name}.region.summary.h5")
    rows = json.loads((docs / f"{name}-answer.json").read_text())
    assert [r["region"] for r in rows] == list(s["points/region_label"])
    for i, row in enumerate(rows):
        for key in ("n_events", "gr_b", "ks_gr", "fraction_large", "cv_tnu"):
            assert row[key] == pytest.approx(list(s[f"points/numbers/{key}"][i]), rel=1e-12), key
        hump = shape_statistics(s, i, merge=answer.hump_merge(s))["peak_over_dip"][:3]
        assert row["hump"] == pytest.approx(list(hump))
        counts = s["per_task/mu"][s["tasks/point"] == i].sum(axis=(0, 1))
        for key, fn in (("best_two_decades", answer.best_decades), ("top_two_decades", answer.top_decades)):
            ks, lo, b = fn(counts, s["bins/mu"])
            # the golden-section search compares log-likelihoods on their flat top, where rounding decides: the
            # maximum is found to about sqrt(eps) (3e-8 apart between two CPUs' numpy reductions), not to 1e-9
            assert (row[key]["ks"][0], row[key]["lo"], row[key]["gr_b"]) == pytest.approx((ks, lo, b), rel=1e-6), key
    table = answer.table(rows)
    assert table == (docs / f"{name}-answer.md").read_text().strip()
    assert table in (docs.parent / "populations.md").read_text()


def test_the_discreteness_table_is_the_committed_summaries(capsys):
    """docs/populations.md's discreteness table is examples/populations/discreteness.py's, from the committed
    summaries of l = 3, 6, 12; the large-event threshold of each is scaled with its blocks per unit length."""
    from pathlib import Path
    root = Path(__file__).parents[1]
    sys.path.insert(0, str(root / "examples" / "populations"))
    try:
        import discreteness
    finally:
        sys.path.pop(0)
    paths = [root / "docs" / "populations" / f"discrete_l{l}.summary.h5" for l in (3, 6, 12)]
    assert discreteness.main([str(p) for p in paths]) == 0
    table = capsys.readouterr().out.strip()
    assert table == (root / "docs" / "populations" / "discreteness.md").read_text().strip()
    assert table in (root / "docs" / "populations.md").read_text()
    for l, p in zip((3, 6, 12), paths):
        assert float(summary.read(p)["attrs"]["mu_c"]) == pytest.approx(4 + math.log10(l / 3))
