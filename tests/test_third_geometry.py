"""Adding a geometry touches one file (docs/design/geometry.md): a ring, the chain with its ends joined.

A copy of the package gets one new module, ensemble/model/geometry/ring.py, which declares the ring's neighbours,
springs and positions; geometry/graph.py supplies the rest (forces, energy, clusters and their creep). Nothing else is
edited; the copy then validates, runs and records `model.geometry = "ring"`. Two exact answers: a ring has no ends,
so every block is as stiff as the chain's interior ones, and turning its initial state by k blocks turns its whole
sequence by k blocks (the same onsets, slips and extents, epicenters moved by k), which a chain's ends break. The
analysis refuses the ring's catalog in one line: it reads the geometries on a grid (Geometry.grid), and a ring's
distances are its own.

Slow by nature (the slower tier, `make slow`, which CI runs): the copy's kernels compile for the new geometry,
about a minute.
"""
import sys

import numpy as np
import pytest

from ensemble.store import reader

from .processes import package_copy, run_bounded

RING = '''"""The ring: N blocks in a circle, each on the loader's spring and joined to its two neighbours (a
test's third geometry)."""
from collections import namedtuple

import numba as nb

from . import graph


class RingParams(namedtuple("RingParams", "l2")):
    __slots__ = ()


@nb.njit(cache=True)
def neighbours(g, i, n):
    return (i - 1) % n, (i + 1) % n


@nb.njit(cache=True)
def around(g, i, n):
    return (i - 1) % n, i, (i + 1) % n


@nb.njit(cache=True)
def stiffness(g, i, n):
    return 1.0 + 2.0 * g.l2 if n > 1 else 1.0


@nb.njit(cache=True)
def coupling(g, i, j):
    return g.l2


@nb.njit(cache=True)
def along(g, i):
    return i


@nb.njit(cache=True)
def across(g, i):
    return 0


@nb.njit(cache=True)
def max_stiffness(g, n):
    return stiffness(g, 0, n)


def _record(model):
    return RingParams(float(model.l) ** 2)


GEOMETRY = graph.geometry("ring", RingParams, _record, neighbours=neighbours, around=around, stiffness=stiffness,
                          coupling=coupling, along=along, across=across, max_stiffness=max_stiffness)
'''

# turning the ring's state: its sequence of events in the copy, from a state and from the state turned by SHIFT
TURNED = '''
import json, sys
import numpy as np
from ensemble.config import Integrator, Model
from ensemble.integrators import kernel_params
from ensemble.model.chain import simulate
from ensemble.model.workspace import D_FIRST, D_NSLIP, D_SLIP, NDIAG, UNLIMITED, Workspace

n, shift, events = 40, 13, 60
force = -np.random.default_rng(7).random(n)
out = {}
for geometry in ("ring", "chain"):
    p = kernel_params(Model(N=n, b=float(sys.argv[1]), geometry=geometry), Integrator(method="exp4"))
    for name, f in (("plain", force), ("turned", np.roll(force, shift))):
        ws = Workspace(n)
        ws.load(f, np.zeros(n))
        t, epi, diag = np.empty(events), np.empty(events, dtype=np.int64), np.empty((events, NDIAG))
        status, k = simulate(ws.arrays, np.zeros(2), p, events, UNLIMITED, t, epi, diag)
        out[geometry + " " + name] = {"status": int(status), "t": t[:k].tolist(), "epicenter": epi[:k].tolist(),
                                      "slip": diag[:k, D_SLIP].tolist(), "n_slipped": diag[:k, D_NSLIP].tolist()}
print(json.dumps(out))
'''


@pytest.fixture(scope="module")
def copy_with_a_ring(tmp_path_factory):
    root = tmp_path_factory.mktemp("third_geometry")
    env = package_copy(root, "ensemble", "analysis", own_cache=True)
    (root / "ensemble/model/geometry/ring.py").write_text(RING)
    (root / "cfg.toml").write_text('[model]\nN = 40\ngeometry = "ring"\n\n[sweep]\nb = [15.0, 20.0]\n\n'
                                   '[run]\nseeds = 1\nevents = 100\ntransient = 20\n\n[integrator]\nmethod = "exp4"\n')
    (root / "turned.py").write_text(TURNED)
    return root, env


def ensemble(root, env, *args):
    return run_bounded([sys.executable, "-m", "ensemble", *map(str, args)], 900, cwd=root, env=env)


@pytest.mark.slow
def test_a_geometry_in_one_new_module_validates_runs_and_is_recorded(copy_with_a_ring):
    root, env = copy_with_a_ring
    res = run_bounded([sys.executable, "-c", "import ensemble; print(ensemble.__file__)"], 60, cwd="/", env=env)
    assert res.stdout.strip() == str(root / "ensemble/__init__.py")       # the copy, not this tree
    res = ensemble(root, env, "validate", "cfg.toml")
    assert res.returncode == 0 and 'geometry = "ring"' in res.stdout, res.stdout + res.stderr
    res = ensemble(root, env, "run", "cfg.toml", "--set", "model.M=2")
    assert res.returncode == 2 and "model.M belongs to model.geometry = 'lattice' (not 'ring')" in res.stderr
    res = ensemble(root, env, "run", "cfg.toml", "-o", "ring.h5")
    assert res.returncode == 0, res.stderr
    events, tasks, _ = reader.read(root / "ring.h5")
    assert list(tasks["geometry"]) == ["ring", "ring"] and len(events["t"]) == 200
    # b = 15 below the ring's stiffness 1 + 2 l^2 = 19 everywhere: its blocks creep (the graph's clusters)
    creep = events["kind"] == 1
    assert creep[events["task"] == 0].sum() > 10 and not creep[events["task"] == 1].any()
    # the analysis reads the geometries on a grid (Geometry.grid); a ring's distances are its own: refused
    res = run_bounded([sys.executable, "-m", "analysis", "reduce", "ring.h5", "-o", "ring.summary.h5"], 300,
                      cwd=root, env=env)
    assert res.returncode == 2 and "ring.h5: a catalog of model.geometry = 'ring'; the analysis reads chain, " \
        "lattice" in res.stderr, res.stderr
    assert not (root / "ring.summary.h5").exists()


@pytest.mark.slow
@pytest.mark.parametrize("b", [20.0, 15.0])
def test_a_turned_ring_turns_its_events_and_a_chain_does_not(copy_with_a_ring, b):
    """The ring's 60 events from a state and from that state turned by 13 blocks: the same onsets, slips and
    sizes, the epicenters turned by 13 (b = 15 through creep episodes); the chain's ends make the two differ."""
    import json
    root, env = copy_with_a_ring
    res = run_bounded([sys.executable, "turned.py", str(b)], 900, cwd=root, env=env)
    assert res.returncode == 0, res.stderr
    out = json.loads(res.stdout)
    plain, turned = out["ring plain"], out["ring turned"]
    assert plain["status"] == turned["status"] == 0 and len(plain["t"]) == len(turned["t"]) == 60
    np.testing.assert_array_equal((np.array(plain["epicenter"]) + 13) % 40, turned["epicenter"])
    np.testing.assert_array_equal(plain["t"], turned["t"])
    np.testing.assert_array_equal(plain["n_slipped"], turned["n_slipped"])
    np.testing.assert_allclose(plain["slip"], turned["slip"], rtol=1e-12)
    chain, chain_turned = out["chain plain"], out["chain turned"]
    assert chain["t"][:10] != chain_turned["t"][:10]
