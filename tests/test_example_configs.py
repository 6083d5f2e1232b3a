"""Every config under examples/ loads (ensemble.config.load): a renamed or removed key, or a value out of range,
fails here, not in a user's run of a documented example."""
from pathlib import Path

import pytest

from ensemble.config import load

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = sorted((ROOT / "examples").rglob("*.toml"))


def test_the_examples_hold_configs():
    assert len(CONFIGS) >= 40 and ROOT / "examples/plane/p128.toml" in CONFIGS


@pytest.mark.parametrize("path", CONFIGS, ids=lambda p: str(p.relative_to(ROOT / "examples")))
def test_an_example_config_loads(path):
    load(path, [])
