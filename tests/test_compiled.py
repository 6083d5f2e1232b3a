"""Compiling ahead (ensemble/compiled.py): `python -m ensemble compile` leaves no first run anything to compile.

The kernels are compiled once per friction law, every method inside (model/methods.py). The slow test
compiles every law into an empty cache, as `make setup` does on a fresh clone, and then runs every law,
method and regime (benchmarks/first_run.py): none may compile. The fast ones check the command's
refusals and the line a compiling run says.
"""
import json
import shutil
import sys
from pathlib import Path

import numba
import pytest

from ensemble import compiled
from ensemble.model import geometry, laws

from .processes import ROOT, child_env, run_bounded


@pytest.mark.slow
@pytest.mark.timeout(1500)
def test_a_run_after_compile_compiles_nothing(tmp_path):
    env = child_env(NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    res = run_bounded([sys.executable, "-m", "ensemble", "compile"], 1200, cwd=ROOT, env=env)
    assert res.returncode == 0, res.stdout + res.stderr
    # every law on every geometry, into the empty cache
    assert res.stdout.count("kernels compiled (") == len(laws.LAWS) * len(geometry.GEOMETRIES), res.stdout
    res = run_bounded([sys.executable, "-m", "benchmarks.first_run", "--in-process", "--N", "8", "--events", "3",
                       "--out", str(tmp_path)], 600, cwd=ROOT, env=env)
    assert res.returncode == 0, res.stdout + res.stderr
    rows = json.loads((tmp_path / "first_run.json").read_text())["rows"]
    assert {(r["law"], r["regime"]) for r in rows} >= {("aging", "creep"), ("slip", "creep"),
                                                        ("carlson-langer", "events")}
    assert len({r["method"] for r in rows}) == 5
    compiling = [r for r in rows if r["compilations"] or r["exit"]]
    assert not compiling, compiling


def test_a_compilation_is_said_in_one_line_with_its_time_and_its_end():
    said = []

    @numba.njit
    def fresh(x):       # a function never compiled before: numba compiles it at the call
        return x + 1

    with compiled.announced(said.append, "aging"):
        assert fresh(1) == 2
    assert len(said) == 2, said
    assert said[0].startswith(f"compiling kernels for model.law = 'aging' (about {compiled.SECONDS_PER_LAW} s"), said
    assert "python -m ensemble compile" in said[0]
    assert said[1].startswith("kernels ready in "), said
    said.clear()
    with compiled.announced(said.append, "aging"):     # compiled now: nothing to say
        fresh(2)
    assert said == []


@pytest.mark.parametrize("args, message", [(["--law", "nope"], "--law 'nope': not a friction law (one of aging"),
                                           (["--jobs", "0"], "--jobs 0: must be at least 1")])
def test_compile_refuses_a_bad_argument_in_one_line(args, message):
    res = run_bounded([sys.executable, "-m", "ensemble", "compile", *args], 60, cwd=ROOT, env=child_env())
    assert res.returncode == 2, res.stdout + res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {message}"), lines


def test_compile_of_a_cached_law_says_so():
    res = run_bounded([sys.executable, "-m", "ensemble", "compile", "--law", "carlson-langer"], 600, cwd=ROOT,
                      env=child_env())
    assert res.returncode == 0, res.stdout + res.stderr
    lines = res.stdout.strip().splitlines()
    assert lines[0].startswith("compiling the kernels of carlson-langer on chain, lattice (1 law(s) x 2 "), lines
    assert sorted(line.split(":")[0] for line in lines[1:]) == [
        "model.law = 'carlson-langer'", "model.law = 'carlson-langer', model.geometry = 'lattice'"], lines


def test_a_cache_built_in_one_checkout_serves_a_copy_elsewhere(tmp_path):
    """The kernels compiled in this checkout (make setup) load, uncompiled, in a copy of the package at
    another path: numba files them by their path in the package (kernel_cache.relocatable), so clones of
    one commit (CI's install paths, a checkout copied to a cluster) share one cache."""
    from ensemble import kernel_cache
    here = Path(compiled.cache_directory())
    res = run_bounded([sys.executable, "-m", "ensemble", "compile", "--law", "carlson-langer"], 600, cwd=ROOT,
                      env=child_env())      # compiled here (by make setup: loaded in seconds)
    assert res.returncode == 0, res.stdout + res.stderr
    copy = tmp_path / "elsewhere"
    shutil.copytree(ROOT / "ensemble", copy / "ensemble", ignore=shutil.ignore_patterns("__pycache__"))
    cache = tmp_path / "cache"
    shutil.copytree(here, cache / here.name)
    same = kernel_cache.directory(copy / "ensemble" / "model", {"NUMBA_CACHE_DIR": str(cache)})
    assert same == str(cache / here.name)      # the copy's sources are this checkout's
    res = run_bounded([sys.executable, "-m", "ensemble", "compile", "--law", "carlson-langer"], 600, cwd=copy,
                      env=child_env(NUMBA_CACHE_DIR=str(cache), PYTHONPATH=str(copy)))
    assert res.returncode == 0, res.stdout + res.stderr
    assert "carlson-langer': kernels already compiled (loaded from the cache)" in res.stdout, res.stdout
    assert (cache / here.name / "ensemble_model").is_dir()
