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
