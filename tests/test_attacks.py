"""The attacks at the edges (tests/attack.py), each a test: full disks and file-size limits under MPI,
damaged tables and config, one rank failing in each collective step, inputs nobody meant."""
import pytest

from . import attack


@pytest.fixture(scope="module")
def workshop(tmp_path_factory):
    return attack.Workshop(tmp_path_factory.mktemp("attack"))


# attacks that compile an older version's kernels in a tree of their own (a minute or more each): slow by
# nature, in the slower tier (`make slow`, which CI runs)
COMPILING = ("an older catalog format reads, and is not continued",
             "a bk-catalog-5 catalog with creep states reads, and is not continued")


@pytest.mark.parametrize("name", [pytest.param(name, marks=pytest.mark.slow) if name in COMPILING else name
                                  for name in attack.ATTACKS])
def test_attack_holds(workshop, name):
    try:
        attack.ATTACKS[name](workshop)
    except attack.Skip as why:
        pytest.skip(str(why))


def test_a_flipped_parameter_table_and_record_are_refused(workshop):
    """The quick tier's attack: a flipped byte in a parameter table and in a task's record, read in-process."""
    for name in ("b", "status"):
        attack.ATTACKS[f"flip /tasks/{name}"](workshop)


@pytest.mark.parametrize("sets", [["run.events=20000"], ["model.N=5000", "run.seeds=50", "run.events=10"],
                                  ["model.N=10", "run.seeds=2000", "run.events=1"],
                                  ["run.branch=true", "run.seeds=3", "sweep.b=[20, 30, 40]", "run.events=100"],
                                  # creep states in the slots (b below the block stiffness), spin-ups too
                                  ["run.branch=true", "run.seeds=3", "sweep.b=[10, 15]", "run.events=10"]])
def test_the_size_checked_before_creation_bounds_the_catalog(tmp_path, sets):
    """space.check_fits asks for estimate_bytes: it must not be below the file HDF5 makes (then a
    disk that passed the check could still fill inside HDF5's collective create), nor far above it."""
    import os

    import h5py

    from ensemble.store.create import create_layout, estimate_bytes
    from ensemble.config import load
    from ensemble.sweep import task_list
    cfg = load(attack.ROOT / "examples" / "small.toml", sets)
    tasks = task_list(cfg)
    path = tmp_path / "c.h5"
    with h5py.File(path, "w") as h5:
        create_layout(h5, cfg, tasks, "method = 'ark4'", "software")
    actual, estimate = os.path.getsize(path), estimate_bytes(cfg, tasks)
    assert actual <= estimate <= 1.5 * actual + 2 ** 20, (actual, estimate)
