"""The attacks at the edges (tests/attack.py), each a test: full disks and file-size limits under MPI,
damaged tables and config, one rank failing in each collective step, inputs nobody meant."""
import pytest

from . import attack


@pytest.fixture(scope="module")
def workshop(tmp_path_factory):
    return attack.Workshop(tmp_path_factory.mktemp("attack"))


@pytest.mark.parametrize("name", list(attack.ATTACKS))
def test_attack_holds(workshop, name):
    try:
        attack.ATTACKS[name](workshop)
    except attack.Skip as why:
        pytest.skip(str(why))


def test_a_flipped_parameter_table_and_record_are_refused(workshop):
    """The quick tier's attack: a flipped byte in a parameter table and in a task's record, read in-process."""
    for name in ("b", "status"):
        attack.ATTACKS[f"flip /tasks/{name}"](workshop)
