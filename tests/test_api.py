"""The Python front door (docs/api.md): its worked example and the README's three lines run as written, and the
front door is the commands' own code: the example's summary is the one `python -m analysis reduce` writes of its
catalog with the same options, dataset for dataset; its catalog is the one `python -m ensemble run` writes of the
same config. Bad input raises what the commands refuse with."""
import re
import sys

import h5py
import numpy as np
import pytest

from ensemble import checks
from ensemble.store import reader

from .processes import ROOT, child_env, run_bounded
from .test_summary_identity import contents, same

TIMEOUT = 600


def block(path, language="python"):
    """The first ```python block of a Markdown file, as written there."""
    text = (ROOT / path).read_text()
    found = re.search(rf"^```{language}\n(.*?)^```$", text, re.S | re.M)
    assert found, f"{path} has no ```{language} block"
    return found.group(1)


def run_python(code, cwd):
    res = run_bounded([sys.executable, "-c", code], TIMEOUT, cwd=cwd, env=child_env(PYTHONPATH=str(ROOT)))
    assert res.returncode == 0, res.stderr
    return res


@pytest.fixture(scope="module")
def example(tmp_path_factory):
    d = tmp_path_factory.mktemp("api")
    return d, run_python(block("docs/api.md"), d)


def test_the_worked_example_runs_as_written(example):
    d, res = example
    rows, mu = re.search(r"^(\d+) rows; largest magnitude (\S+)$", res.stdout, re.M).groups()
    events, _, _ = reader.read(d / "small.h5")
    assert int(rows) == len(events["t"]) == 1200 and float(mu) == events["mu"].max()
    assert re.search(r"^GR b \d\.\d{3} \[\d\.\d{3}, \d\.\d{3}\] from 1200 events$", res.stdout, re.M), res.stdout
    assert "summary of small.h5: mu_c = 4.0" in res.stdout
    for figure in ("r_mu.png", "recurrence.png"):
        assert (d / figure).stat().st_size > 10000


def test_the_front_door_is_the_commands_code(example):
    """The same config through `python -m ensemble run` gives the same catalog's events; the example's catalog
    through `python -m analysis reduce --bootstrap 200` gives the example's summary, every dataset."""
    d, _ = example
    config = d / "config.toml"
    config.write_text('[model]\nN = 60\nb = 20.0\n[run]\nseeds = 2\nevents = 600\ntransient = 50\n')
    for args in (("ensemble", "run", config, "-o", d / "cli.h5"),
                 ("analysis", "reduce", d / "small.h5", "-o", d / "cli.summary.h5", "--bootstrap", "200")):
        res = run_bounded([sys.executable, "-m", *map(str, args)], TIMEOUT, cwd=d, env=child_env(PYTHONPATH=str(ROOT)))
        assert res.returncode == 0, res.stderr
    api_events, _, _ = reader.read(d / "small.h5")
    cli_events, _, _ = reader.read(d / "cli.h5")
    for name in api_events:
        np.testing.assert_array_equal(api_events[name], cli_events[name], err_msg=name)
    (api, api_options), (cli, cli_options) = contents(d / "small.summary.h5"), contents(d / "cli.summary.h5")
    assert sorted(api) == sorted(cli) and api_options == cli_options
    differ = [name for name in api if not same(api[name], cli[name])]
    assert differ == [], differ


def test_the_readme_lines_run_as_written(tmp_path):
    res = run_python(block("README.md"), tmp_path)
    assert res.stdout.startswith("summary of mine.h5: ") and "point 0: aging: N = 60" in res.stdout, res.stdout
    with h5py.File(tmp_path / "mine.summary.h5", "r") as s:
        assert s["points/numbers/n_events"][0, 0] == 1000


def test_bad_input_raises_what_the_commands_refuse_with(example, tmp_path):
    import analysis
    import ensemble
    from analysis.summary import SummaryError
    from ensemble.config import ConfigError
    d, _ = example
    with pytest.raises(ensemble.RunError, match="exists"):
        ensemble.simulate({"model": {"N": 60}}, d / "small.h5")              # no force: the catalog stays
    with pytest.raises(ConfigError, match="model.b"):
        ensemble.load_config({"model": {"b": -1.0}})
    with pytest.raises(TypeError, match="no option bins"):
        analysis.summarize(d / "small.h5", bins=3)
    with pytest.raises(checks.UsageError, match="--mu-c"):
        analysis.summarize(d / "small.h5", output=tmp_path / "s.h5", mu_c=float("nan"))
    with pytest.raises(SummaryError, match="not a reduction summary"):
        analysis.Summary(d / "small.h5")
    assert not (tmp_path / "s.h5").exists()


def test_a_config_is_a_path_a_toml_text_or_a_dict(tmp_path, monkeypatch):
    """load_config takes the same config four ways; a one-line string is a file's name when such a file exists or
    it ends in .toml (then a missing file is said as one), else TOML text."""
    import ensemble
    from ensemble.config import ConfigError
    text = "[model]\nN = 7\n"
    (tmp_path / "cfg.conf").write_text(text)
    monkeypatch.chdir(tmp_path)
    for source in ({"model": {"N": 7}}, text, tmp_path / "cfg.conf", "cfg.conf", "model.N = 7"):
        cfg = ensemble.load_config(source)
        assert cfg.model.N == 7
    assert ensemble.load_config("cfg.conf", ["model.N=9"]).model.N == 9
    with pytest.raises(ConfigError, match="missing.toml: no such config file"):
        ensemble.load_config("missing.toml")
    with pytest.raises(ConfigError, match="a config is a path"):
        ensemble.load_config(7)
