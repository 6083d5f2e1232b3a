"""The kernel gives the events of a reference commit bit for bit: a refactor of the kernel must cost nothing.

A reference is the code of an earlier commit, taken from git into a scratch directory and run in this same
environment (this Python, numba and numpy, this machine), so the comparison holds on any machine: only the
kernel's arithmetic can make the two catalogs differ. A change of arithmetic that is meant (a new formula, a
reordered sum) breaks this test; then name it in the commit, show that the difference is within the method's
tolerance, and move the reference on.

Two references. REFERENCE, the code before the kernel interface was reworked (issue 18): N = 100 (events up to
the whole chain, mu ~ 5), b = 20 (the paper's) and b = 50 (four times faster slip), with a = 0 (the paper's) and
a = 10 (the velocity-strengthening term), with ark4 and rk4; it predates the creep phase, exp4 and the slip law.
CREEP_REFERENCE, the code before geometry became a plug-in (issue 46), for what the first cannot reach: the creep
phase (b = 15, below the block stiffness 19 at l = 3: creep episodes, hand-overs to inertia and back) with exp4
(the aging law's default) and with the slip law, every column of the catalog (kind, ending, stress drop,
nucleation). The current code also runs with kernel calls paused in the middle of events (chain.simulate's work
budget), which must not change an event either.
"""
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from .conftest import write_config
from .processes import ROOT, child_env, run_bounded
from .same_catalogs import assert_same_events

# main before the kernel interface was reworked (issue 18, part 1)
REFERENCE = "f16fee6ccdc9585db7673b032669b1aa3652641f"
# main before geometry became a plug-in (issue 46): the creep phase, exp4, the slip law, catalog bk-catalog-7
CREEP_REFERENCE = "5fbff8304189581fb315bf5cfa9a95666deb400c"
TIMEOUT = 300           # seconds for one run, the reference's compilation included
# rk4 at a step stable for b = 50 (slip at v ~ 4500: dt v < 2.785); ark4 at rtol 1e-5 (its default
# at the reference commit)
INTEGRATORS = {"rk4": {"method": "rk4", "dt": 5e-4}, "ark4": {"method": "ark4", "rtol": 1e-5}}
FIRST_BUDGET = 1_000    # block-steps: the paused run pauses from its first large event on
POLL_SECONDS = 1e-5     # ... and every call after that stays at worker.MIN_BUDGET


def extracted(commit):
    """(tree, numba cache) of a reference commit, extracted from this repository once per checkout.

    Both live beside the checkout's own kernel cache (`.numba_cache/reference-COMMIT/`, ignored by git) at a
    path that does not change, and `git archive` gives every file the commit's time: numba's cache (keyed on
    a source file's path and time) then compiles the reference's kernels once per checkout and method, not in
    every test session (about 45 s each)."""
    found = subprocess.run(["git", "-C", ROOT, "cat-file", "-e", f"{commit}^{{commit}}"],
                           capture_output=True, text=True)
    if found.returncode != 0:
        pytest.fail(f"the reference commit {commit} is not in the repository at {ROOT} (a shallow clone? "
                    f"`git fetch --unshallow` gets it; CI clones the full history): {found.stderr.strip()}")
    base = Path(ROOT) / ".numba_cache" / f"reference-{commit[:12]}"
    tree = base / "tree"
    if not (tree / "ensemble" / "__init__.py").is_file():
        base.mkdir(parents=True, exist_ok=True)
        scratch = Path(tempfile.mkdtemp(dir=base))      # extracted whole, then renamed into place
        archive = subprocess.run(f"git -C '{ROOT}' archive {commit} | tar -x -C '{scratch}'", shell=True,
                                 capture_output=True, text=True)
        assert archive.returncode == 0, archive.stderr
        shutil.rmtree(tree, ignore_errors=True)
        scratch.rename(tree)
    return tree, base / "numba_cache"


@pytest.fixture(scope="module")
def reference():
    return extracted(REFERENCE)


def run(tree, cfg, out, cache=None, setup=None):
    """`python -m ensemble run cfg -o out` with the code of `tree` (its own numba cache if given), after
    `setup` (code using tests.inject, the current tree only); returns the run's output."""
    env = child_env(PYTHONPATH=str(tree), **({} if cache is None else {"NUMBA_CACHE_DIR": str(cache)}))
    argv = ["run", str(cfg), "-o", str(out)]
    if setup is None:
        cmd = [sys.executable, "-m", "ensemble", *argv]
    else:
        cmd = [sys.executable, "-c", f"from tests import inject; {setup}; inject.main({argv!r})"]
    # the tree's own code runs (not the checkout an editable install of the package points at)
    where = run_bounded([sys.executable, "-c", "import ensemble; print(ensemble.__file__)"], TIMEOUT, cwd=tree, env=env)
    assert where.stdout.strip() == str(tree / "ensemble" / "__init__.py"), where.stdout + where.stderr
    res = run_bounded(cmd, TIMEOUT, cwd=tree, env=env)
    assert res.returncode == 0, res.stdout + res.stderr
    return res.stdout


def config(path, method, transient, events, **run_keys):
    return write_config(path, model={"N": 100}, sweep={"b": [20.0, 50.0], "a": [0.0, 10.0]},
                        run={"seeds": 1, "transient": transient, "events": events, **run_keys},
                        integrator=INTEGRATORS[method])


# (method, transient events, recorded events per task). ark4 takes ~2 s a run at the full size, in `make test`;
# rk4's small step ~10 s, with the reference's rk4 kernels to compile first (about 45 s, once: `reference`), so
# rk4 is in the slower tier, which CI runs.
CASES = [pytest.param("ark4", 25, 75, id="ark4"),
         pytest.param("rk4", 25, 75, id="rk4", marks=pytest.mark.slow)]


@pytest.mark.parametrize("method, transient, events", CASES)
def test_events_as_the_reference_commit(method, transient, events, reference, tmp_path):
    tree, cache = reference
    cfg = config(tmp_path / "identity.toml", method, transient, events)
    run(tree, cfg, tmp_path / "reference.h5", cache)
    run(ROOT, cfg, tmp_path / "current.h5")
    assert_same_events(tmp_path / "reference.h5", tmp_path / "current.h5")
    # and with kernel calls paused in the middle of events, many times per large event
    count = tmp_path / "pauses.txt"
    paused = config(tmp_path / "paused.toml", method, transient, events, poll_seconds=POLL_SECONDS)
    run(ROOT, paused, tmp_path / "paused.h5", setup=f"inject.count_pauses({str(count)!r}, first_budget={FIRST_BUDGET})")
    pauses = int(count.read_text())
    assert pauses > 100, f"only {pauses} kernel calls paused inside an event: the budget path is hardly used"
    assert_same_events(tmp_path / "reference.h5", tmp_path / "paused.h5")


# (law, integrator, sweep) of the creep cases: b = 15 creeps (a block's stiffness 1 + 2 l^2 = 19 at l = 3), b = 20
# does not; a = 3 strengthens the creep's velocity. 40 rows after 20 per task: creep episodes and the events that
# take them over, hand-backs included (CREEP_ROWS checks that the rows are there)
CREEP_CASES = [pytest.param("aging", {"method": "exp4"}, id="exp4"),
               pytest.param("slip", {"method": "ark4"}, id="slip-ark4")]
CREEP_ROWS = 20         # creep episodes at least, over the run's tasks


def creep_config(path, law, integrator, **run_keys):
    return write_config(path, model={"N": 60, "law": law}, sweep={"b": [15.0, 20.0], "a": [0.0, 3.0]},
                        run={"seeds": 1, "transient": 20, "events": 40, **run_keys}, integrator=integrator)


@pytest.mark.slow       # the reference's kernels compile once per checkout and law (about 90 s each)
@pytest.mark.parametrize("law, integrator", CREEP_CASES)
def test_creep_as_the_reference_commit(law, integrator, tmp_path):
    from ensemble.store import reader
    tree, cache = extracted(CREEP_REFERENCE)
    cfg = creep_config(tmp_path / "creep.toml", law, integrator)
    run(tree, cfg, tmp_path / "reference.h5", cache)
    run(ROOT, cfg, tmp_path / "current.h5")
    assert_same_events(tmp_path / "reference.h5", tmp_path / "current.h5")
    ev, _, _ = reader.read(tmp_path / "current.h5")
    assert (ev["kind"] == 1).sum() >= CREEP_ROWS, f"{(ev['kind'] == 1).sum()} creep episodes: the creep is hardly used"
    count = tmp_path / "pauses.txt"
    paused = creep_config(tmp_path / "paused.toml", law, integrator, poll_seconds=POLL_SECONDS)
    run(ROOT, paused, tmp_path / "paused.h5", setup=f"inject.count_pauses({str(count)!r}, first_budget={FIRST_BUDGET})")
    assert int(count.read_text()) > 100, "the budget path is hardly used"
    assert_same_events(tmp_path / "reference.h5", tmp_path / "paused.h5")
