"""The mutation check's entries (tests/mutations.py) still point at code: each mutant's text occurs exactly
once in its file, and the tests named to kill it exist. A moved or rewritten line otherwise surfaces only
when `make mutations` runs, as an entry that cannot be applied."""
from pathlib import Path

from . import mutations

ROOT = Path(__file__).resolve().parents[1]


def test_every_mutant_applies_once_and_names_existing_tests():
    stale = []
    for m in mutations.MUTATIONS:
        count = (ROOT / m.path).read_text().count(m.old)
        if count != 1:
            stale.append(f"{m.name}: its text occurs {count} times in {m.path}")
        for test in m.tests:
            path, _, name = test.partition("::")
            if not (ROOT / path).is_file() or (name and f"def {name.split('[')[0]}(" not in (ROOT / path).read_text()):
                stale.append(f"{m.name}: no test {test}")
    assert not stale, "\n".join(stale)
    assert len({m.name for m in mutations.MUTATIONS}) == len(mutations.MUTATIONS), "two mutants share a name"


def test_the_readme_counts_the_mutants():
    readme = (ROOT / "README.md").read_text()
    assert f"`make mutations`: {len(mutations.MUTATIONS)} plausible bugs" in readme, \
        "README's count of the mutation check's bugs is not len(MUTATIONS)"
