"""The [integrator] keys are declared once (ensemble.integrators.KEYS), and everything else reads them.

The config's Integrator section, its checks, the kernels' parameter record and the exported tables
take each key's default, range, unit and meaning from there; adding a key there is enough for a config
to accept, check, write and export it (shown in a fresh process that adds one).
"""
import sys
from dataclasses import fields

from analysis.export_tables import INTEGRATOR_MEANINGS
from ensemble.config import Integrator, Model
from ensemble.config_rules import RULES
from ensemble.integrators import INTEGRATORS, KEYS, kernel_params
from ensemble.model.params import KernelParams

from .processes import ROOT, child_env, run_bounded


def test_the_config_section_is_the_declaration():
    assert [(f.name, f.type, f.default) for f in fields(Integrator)] == \
        [(name, type(key.default), key.default) for name, key in KEYS.items()]
    assert {k: v for (section, k), v in RULES.items() if section == "integrator"} == \
        {name: (key.check, key.rule) for name, key in KEYS.items() if key.check}
    assert INTEGRATOR_MEANINGS == {name: (key.unit, key.described) for name, key in KEYS.items()}


def test_each_key_reaches_the_kernels_by_name():
    """Distinct values in every numeric key come out in the record's field of the same name."""
    numeric = [name for name, key in KEYS.items() if isinstance(key.default, float)]
    given = {name: 0.5 ** (k + 2) for k, name in enumerate(numeric)}
    p = kernel_params(Model(N=10), Integrator(**given))
    assert set(numeric) <= set(KernelParams._fields)
    assert {name: getattr(p, name) for name in numeric} == given


def test_the_methods_that_read_a_key():
    adaptive = tuple(name for name, m in INTEGRATORS.items() if m.adaptive)
    assert "rk4" not in adaptive and "ark4" in adaptive and "exp4" in adaptive
    assert KEYS["rtol"].methods() == adaptive and KEYS["rtol"].described.startswith("adaptive methods: ")
    assert KEYS["dt"].methods() == tuple(INTEGRATORS)


ADDED = '''
import ensemble.integrators as integrators
integrators.KEYS["jitter"] = integrators.Key(0.0, "model time", "a key added in one place", lambda x: x >= 0, ">= 0")
from ensemble.config import ConfigError, Integrator, loads
from analysis.export_tables import INTEGRATOR_MEANINGS
assert Integrator().jitter == 0.0
assert loads("[integrator]\\njitter = 0.25\\n").integrator.jitter == 0.25
assert "jitter = 0.0" in loads("").to_toml()
try:
    loads("[integrator]\\njitter = -1\\n")
except ConfigError as err:
    assert str(err) == "integrator.jitter must be >= 0, got -1.0", err
else:
    raise AssertionError("not refused")
assert INTEGRATOR_MEANINGS["jitter"] == ("model time", "a key added in one place")
print("ok")
'''


def test_a_key_added_to_the_declaration_is_accepted_checked_and_described():
    res = run_bounded([sys.executable, "-c", ADDED], 120, cwd=ROOT, env=child_env(PYTHONPATH=str(ROOT)))
    assert res.returncode == 0 and res.stdout.strip() == "ok", res.stdout + res.stderr


def test_the_readme_states_every_key_with_its_declared_default():
    """The README's config table names every [integrator] key, with the default KEYS declares (the method's
    default is the law's, said in words)."""
    import re
    readme = (ROOT / "README.md").read_text()
    stated = {}
    for row in readme.splitlines():
        cells = [c.strip() for c in row.strip().strip("|").split("|")]
        keys = re.findall(r"`integrator\.(\w+)`", cells[0])
        if not keys or len(cells) < 3:
            continue
        for key, default in zip(keys, cells[1].split(",")):
            stated[key] = default.strip()
    assert set(stated) == set(KEYS), set(stated) ^ set(KEYS)
    for key, text in stated.items():
        if key != "method":
            assert float(text) == KEYS[key].default, (key, text, KEYS[key].default)
