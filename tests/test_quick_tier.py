"""The quick tier (`make quick`): the tests tests/conftest.py names in QUICK exist, and every test
file has tests in it or says in NOT_QUICK why not (so that the tier keeps touching every layer as
files are added); a name with "[case]", one case of a parametrized test, names a case pytest collects.
Which source modules it touches, and how long it takes: docs/tests.md."""
import importlib
import subprocess
import sys

from .conftest import NOT_QUICK, QUICK
from .processes import ROOT


def test_every_test_named_in_the_quick_tier_exists():
    for name, tests in QUICK.items():
        module = importlib.import_module(f"tests.{name.removesuffix('.py')}")
        missing = [t for t in tests if not callable(getattr(module, t.split("[")[0], None))]
        assert not missing, f"tests/{name} has no {', '.join(missing)}: rename it in QUICK (tests/conftest.py)"


def test_every_case_named_in_the_quick_tier_is_collected():
    cases = [f"tests/{name}::{t}" for name, tests in QUICK.items() for t in tests if "[" in t]
    assert cases, "no case named: this test has nothing to check"
    files = sorted({c.split("::")[0] for c in cases})
    res = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider", *files],
                         capture_output=True, text=True, cwd=ROOT, timeout=300)
    collected = {line.strip() for line in res.stdout.splitlines()}
    missing = [c for c in cases if c not in collected]
    assert not missing, f"QUICK (tests/conftest.py) names cases pytest does not collect: {', '.join(missing)}"


def test_every_test_file_is_in_the_quick_tier_or_says_why_not():
    files = {p.name for p in (ROOT / "tests").glob("test_*.py")}
    unlisted = sorted(files - set(QUICK) - set(NOT_QUICK))
    assert not unlisted, (f"{', '.join(unlisted)}: add its cheapest test to QUICK in tests/conftest.py "
                          f"(the quick tier touches every layer), or the file to NOT_QUICK with the reason")
    assert not set(QUICK) & set(NOT_QUICK)
    assert not (set(QUICK) | set(NOT_QUICK)) - files, "QUICK or NOT_QUICK names a file that is gone"
