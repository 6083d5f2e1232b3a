"""The lattice (ensemble/model/geometry/lattice.py) in the kernels: a lattice of one row is the chain bit for bit,
and a plane's sequence of events agrees with a plain integration of the whole lattice (tests/reference.py: RK4 on
every block in physical variables, every stick and onset located by bisecting the step; it shares no code with
ensemble/).

The plane here is 6 x 5 blocks with different springs along (l = 2) and across strike (l_y = 1.5), so a spring
missing or swapped across strike changes every event; at b = 20 no block is stiffer than its weakening (the
stiffest, 1 + 2 l^2 + 2 l_y^2 = 13.5), so nothing creeps and the reference's inertial equations are the model's.
nu = 1e-2 makes the loading periods short enough to integrate.
"""
import sys

import numpy as np
import pytest

from analysis import summary
from ensemble.config import Integrator, Model
from ensemble.integrators import kernel_params
from ensemble.model.chain import simulate
from ensemble.model.geometry.lattice import LatticeParams
from ensemble.store import reader
from ensemble.model.workspace import (D_DURATION, D_FIRST, D_KIND, D_LAST, D_NSLIP, D_SLIP, KIND_CREEP, NDIAG, OK,
                                     UNLIMITED, Workspace)

from .conftest import run_cli, write_config
from .processes import ROOT, child_env, run_bounded
from .reference import displacements_for, reference_sequence
from .same_catalogs import assert_same_events
from .test_mpi import mpirun, start_and_interrupt

NX, NY = 6, 5
PLANE = {"l": 2.0, "nu": 1e-2, "a": 1.0, "b": 20.0, "c": 1000.0}
L_Y = 1.5
EVENTS = 11        # events of the sequence integrated by both
SEED = 5

# method: ([integrator], events compared, relative tolerance of the first event's onset time and slip, absolute
# tolerance of the durations); event k's tolerance is the first one's times 10^(k/2), the chaotic growth of a
# difference (tests/test_sequences.py measured it on the chain). Measured (onset time, slip; duration) over the
# 11 events: rk4 at most 2.0e-10, 2.9e-9 (event 10; 4.6e-10 before it); 4.9e-6; ark4 at rtol 1e-5 3.8e-6, 5.4e-5
# (event 10; 6.5e-6 before); 0.11. The 12th event's epicenter differs with ark4 (chaos).
METHODS = {"rk4": ({"method": "rk4", "dt": 1e-3}, 11, 1e-10, 1e-5),
           "ark4": ({"method": "ark4", "rtol": 1e-5}, 11, 1e-6, 0.5)}
REF_DT, ALPHA = 1e-3, 0.01


def lattice_params(model, integrator, nx, ny, l_y):
    """The kernels' record with the lattice nx x ny as its geometry."""
    p = kernel_params(model, Integrator(**integrator))
    return p._replace(geom=LatticeParams(nx, ny, float(model.l) ** 2, float(l_y) ** 2))


def run_kernels(params, force, events):
    """(status, onsets, epicenters, diagnostics) of `events` events from the c-free forces `force`, theta = 1, t = 0."""
    n = len(force)
    ws = Workspace(n)
    ws.load(force, np.zeros(n))
    clock = np.zeros(2)
    t, epi, diag = np.empty(events), np.empty(events, dtype=np.int64), np.empty((events, NDIAG))
    status, k = simulate(ws.arrays, clock, params, events, UNLIMITED, t, epi, diag)
    return status, t[:k], epi[:k], diag[:k]


def initial_forces(n, seed=SEED):
    return -np.random.default_rng(seed).random(n)


@pytest.mark.parametrize("b", [20.0, 15.0])
def test_one_row_is_the_chain_bit_for_bit(b):
    """The lattice of N x 1 gives the chain's catalog: every onset, epicenter and diagnostic, bit for bit; at
    b = 15 through the creep phase (creep episodes and the events that take them over)."""
    model = Model(N=60, b=b)
    integrator = {"method": "exp4"}
    chain = run_kernels(kernel_params(model, Integrator(**integrator)), initial_forces(60), 150)
    row = run_kernels(lattice_params(model, integrator, 60, 1, 2.5), initial_forces(60), 150)
    assert chain[0] == row[0] == OK
    for name, ours, theirs in zip(("onsets", "epicenters", "diagnostics"), row[1:], chain[1:]):
        np.testing.assert_array_equal(ours, theirs, err_msg=name)
    creep = (chain[3][:, D_KIND] == KIND_CREEP).sum()
    assert creep > 20 if b == 15.0 else creep == 0, f"{creep} creep episodes"


@pytest.fixture(scope="module")
def reference():
    """The plain integration's first EVENTS events of the plane from the test's initial state."""
    model = Model(N=NX, **PLANE)
    force = initial_forces(NX * NY)
    u = displacements_for(force, 0.0, model, nx=NX, l_y=L_Y)
    return reference_sequence(u, np.ones(NX * NY), 0.0, EVENTS, **PLANE, dt=REF_DT, alpha=ALPHA, nx=NX, l_y=L_Y)


@pytest.mark.parametrize("method", METHODS)
def test_plane_sequence_agrees_with_the_plain_integration(reference, method):
    """Epicenter, the slipped blocks' extent along strike and their number, onset time, slip and duration of the
    plane's first events (each block on the loader, its four neighbours or fewer at an edge)."""
    integrator, n, tol0, dur_atol = METHODS[method]
    status, t, epi, diag = run_kernels(lattice_params(Model(N=NX, **PLANE), integrator, NX, NY, L_Y),
                                       initial_forces(NX * NY), n)
    assert status == OK and len(t) == n
    slipped = reference["profile"][:n] > 0.0
    x = np.arange(NX * NY) % NX
    np.testing.assert_array_equal(epi, reference["epicenter"][:n])
    np.testing.assert_array_equal(diag[:, D_NSLIP], slipped.sum(axis=1))
    np.testing.assert_array_equal(diag[:, D_FIRST], [x[s].min() for s in slipped])
    np.testing.assert_array_equal(diag[:, D_LAST], [x[s].max() for s in slipped])
    rtol = tol0 * 10 ** (np.arange(n) / 2)
    assert np.all(np.abs(t / reference["t"][:n] - 1) <= rtol), np.abs(t / reference["t"][:n] - 1)
    assert np.all(np.abs(diag[:, D_SLIP] / reference["slip"][:n] - 1) <= rtol)
    assert np.all(np.abs(diag[:, D_DURATION] - reference["duration"][:n]) <= dur_atol)
    # the sequence has events of every kind: one block, the whole plane, between
    assert slipped.sum(axis=1).min() == 1 and slipped.sum(axis=1).max() == NX * NY


# A creeping cluster on a plane of 5 x 4 (l = 2, l_y = 1.5, b = 5.5): an edge block and a T of four interior ones, so
# the cluster is no interval, its springs run along and across strike, and the Newton's banded elimination meets
# fill-in; its K_C - b I has lambda_min 1.6 (stable), its resting neighbours stay far below their thresholds.
CREEP_NX, CREEP_NY, CREEP_B, CREEP_NU = 5, 4, 5.5, 1e-3
CREEP_CLUSTER = [1, 6, 7, 8, 12]


def test_a_creeping_cluster_on_a_plane_follows_the_full_equations():
    """The kernel's creep of a cluster across strike against scipy's solution of the cluster's full inertial
    equations (tests/creep_reference.py with the plane's stiffness matrix from tests/reference.py: no package
    code) over 1 / nu, the time its state takes to relax (psi by 0.16 to 0.48, velocities by 14-18 %): slips,
    velocities and psi to the chain's bounds (tests/test_creep.py; measured 1.7e-4, 2.4e-4, 1.1e-4). A wrong
    Jacobian in the Newton's elimination only slows its convergence; a wrong residual fails here
    (tests/mutations.py lattice-creep-across-spring)."""
    from .creep_reference import inertial, on_the_manifold
    from .reference import stiffness_matrix
    from .test_creep import creep_path
    n, C = CREEP_NX * CREEP_NY, CREEP_CLUSTER
    K = stiffness_matrix(n, PLANE["l"], CREEP_NX, L_Y)
    R = np.setdiff1d(np.arange(n), C)
    psi_c = np.log(CREEP_B / CREEP_NU) + np.array([0.8, 1.0, 1.5, 1.2, 1.1])
    u, v, psi = on_the_manifold(K, C, CREEP_B, CREEP_NU, psi_c, np.zeros(len(R)))
    model = Model(N=CREEP_NX, l=PLANE["l"], a=0.0, b=CREEP_B, nu=CREEP_NU)
    params = lattice_params(model, {"creep_tol": 1e-6}, CREEP_NX, CREEP_NY, L_Y)
    times, slips, psis, vs = creep_path(n, CREEP_B, CREEP_NU, (-(K @ u), psi), 1.0 / CREEP_NU, 1e-6, creeping=C,
                                        K=K, params=params)
    t_ref, ur, vr, pr, rest = inertial(K, C, 0.0, CREEP_B, CREEP_NU, u, v, psi, times[-1], times)
    assert np.all(rest < CREEP_B * psi[R]), "a neighbour would have started"
    slip_err = np.max(np.abs(slips - (ur - u[C]))) / np.max(np.abs(ur - u[C]))
    late = slice(len(times) // 10, None)        # the kernel starts from rest, the reference on the manifold
    v_err = np.max(np.abs(vs[late] / vr[late] - 1))
    psi_err = np.max(np.abs(psis - pr))
    assert abs(pr[-1, 2] - pr[0, 2]) > 0.4 and abs(vr[-1, 2] / vr[0, 2] - 1) > 0.15, "the comparison is not trivial"
    assert slip_err < 5e-4 and v_err < 1e-3 and psi_err < 1.5e-4, (slip_err, v_err, psi_err)


def test_a_plane_run_of_creep_and_events_keeps_the_energy_balance():
    """Over 300 rows of an 8 x 6 plane at b = 30 (its interior, stiffness 37, creeps; its edges, 28, do not), the
    driver's work equals the change of the elastic energy F K^-1 F / 2 (ensemble/energy.py: conjugate gradients on
    the plane's K from its springs, here also against a dense solve with tests/reference.py's K) plus the friction
    work of every row, events and creep episodes (measured 1.4e-7 of the driver's work); events.physical_state
    gives the forces of displacements from tests/reference.py back."""
    from ensemble import energy
    from .reference import stiffness_matrix
    model = Model(N=8, M=6, geometry="lattice", l=3.0, l_across=2.5, b=30.0, nu=1e-3)
    n, count = 48, 300
    p = kernel_params(model, Integrator(method="exp4"))
    ws = Workspace(n)
    ws.load(np.random.default_rng(1).uniform(0, 1, n) * model.b * 20, np.full(n, 20.0))
    clock = np.zeros(2)
    force0 = ws.state(clock, p)[0]
    K = stiffness_matrix(n, model.l, 8, model.l_across)
    assert energy.elastic_energy(force0, model) == pytest.approx(0.5 * force0 @ np.linalg.solve(K, force0),
                                                                 rel=1e-12)
    # the physical state of the same forces (events.physical_state) gives them back
    from ensemble.events import physical_state
    from .reference import displacements_for
    u = displacements_for(force0, 2.5e3, model, nx=8, l_y=model.l_across)
    np.testing.assert_allclose(physical_state(u, np.ones(n), 2.5e3, model)[0], force0, rtol=1e-9, atol=1e-9)
    start = (force0, 0.0, ws.episodes_in_flight())
    t, e, d = np.empty(count), np.empty(count, dtype=np.int64), np.empty((count, NDIAG))
    assert simulate(ws.arrays, clock, p, count, UNLIMITED, t, e, d) == (OK, count)
    balance = energy.balance(start, (ws.state(clock, p)[0], clock.sum(), ws.episodes_in_flight()), t, d, model)
    kinds = d[:, D_KIND]
    assert np.sum(kinds == KIND_CREEP) > 50 and np.sum(kinds != KIND_CREEP) > 50, np.bincount(kinds.astype(int))
    print(f"relative residual {abs(balance.residual) / abs(balance.load_work):.1e}")
    assert abs(balance.residual) < 2e-6 * abs(balance.load_work), balance


# -- the run: model.geometry = "lattice" through config, ranks, catalog and resume -------------------------------

@pytest.fixture(scope="module")
def plane_run(tmp_path_factory):
    """A plane of 10 x 8 blocks at b = 30 (its interior blocks, 1 + 4 l^2 = 37, creep; its edges, 28, do not) and
    b = 45 (nothing creeps), two seeds each; the serial run's catalog."""
    d = tmp_path_factory.mktemp("plane")
    cfg = write_config(d / "plane.toml", model={"geometry": "lattice", "N": 10, "M": 8}, sweep={"b": [30.0, 45.0]},
                       run={"seeds": 2, "events": 150, "transient": 30},
                       output={"batch": 20, "flush_seconds": 0.25, "progress_seconds": 0.5})
    res = run_cli("run", cfg, "-o", d / "serial.h5", timeout=900)
    assert res.returncode == 0, res.stderr
    return d, cfg


def test_a_plane_runs_on_two_ranks_and_resumes_after_a_kill_to_the_same_catalog(plane_run):
    """mpiexec -n 2 writes the serial run's catalog (real parallel HDF5 on the parallel stack), and so does a run
    killed (-9) after its first committed batch and resumed; the catalog holds the plane: its tasks' geometry,
    extents across strike, creep episodes where blocks are stiffer than their weakening."""
    d, cfg = plane_run
    res = mpirun(2, "run", cfg, "-o", d / "two.h5")
    assert res.returncode == 0, res.stderr
    assert_same_events(d / "serial.h5", d / "two.h5")
    out = d / "killed.h5"
    code, log = start_and_interrupt(cfg, out, "kill")
    assert code != 0 and not out.exists(), log
    res = mpirun(2, "run", cfg, "-o", out, "--resume")
    assert res.returncode == 0, res.stderr
    assert_same_events(d / "serial.h5", out)
    events, tasks, attrs = reader.read(out)
    assert attrs["format"] == "bk-catalog-8"
    assert list(tasks["geometry"]) == ["lattice"] * 4 and list(tasks["M"]) == [8] * 4
    assert list(tasks["l_across"]) == list(tasks["l"]) == [3.0] * 4
    creep = events["kind"] == 1
    soft = np.isin(events["task"], np.flatnonzero(tasks["b"] == 30.0))
    assert creep[soft].sum() > 20 and not creep[~soft].any()
    inertial = ~creep
    assert np.all((0 <= events["across_first"]) & (events["across_first"] <= events["across_last"])
                  & (events["across_last"] < 8) & (events["first"] <= events["last"]) & (events["last"] < 10))
    width = events["across_last"] - events["across_first"] + 1
    assert width[inertial].min() == 1 and width[inertial].max() == 8
    # an event reaching no edge is interior; one reaching an edge across strike is not
    edge = ((events["first"] == 0) | (events["last"] == 9) | (events["across_first"] == 0)
            | (events["across_last"] == 7))
    np.testing.assert_array_equal(events["boundary"], edge)


@pytest.mark.slow
@pytest.mark.parametrize("law, keys", [("slip", {"a": 1.0, "b": 30.0}),
                                       ("carlson-langer", {"alpha": 2.5, "sigma": 0.01, "nu": 0.01, "b": None})])
def test_every_law_runs_on_a_plane_on_two_ranks_to_the_serial_catalog(law, keys, tmp_path):
    """The slip law (its interior blocks creep before they rupture) and Carlson-Langer's on a 10 x 8 plane:
    mpiexec -n 2 writes the serial run's catalog (the aging law's: the test above)."""
    cfg = write_config(tmp_path / "p.toml", model={"geometry": "lattice", "N": 10, "M": 8, "law": law, **keys},
                       run={"seeds": 2, "events": 100, "transient": 20}, output={"batch": 20})
    res = run_cli("run", cfg, "-o", tmp_path / "serial.h5", timeout=900)
    assert res.returncode == 0, res.stderr
    res = mpirun(2, "run", cfg, "-o", tmp_path / "two.h5")
    assert res.returncode == 0, res.stderr
    assert_same_events(tmp_path / "serial.h5", tmp_path / "two.h5")
    events, tasks, _ = reader.read(tmp_path / "two.h5")
    assert list(tasks["law"]) == [law] * 2 and len(events["t"]) == 200
    creep = (events["kind"] == 1).sum()
    assert creep > 20 if law == "slip" else creep == 0, creep


def test_the_analysis_reads_a_plane(plane_run, tmp_path):
    """The analysis takes its distances from the geometry (analysis/geometry.py): a lattice's catalog reduces into
    points that say their shape, and the statistics of chains only say so in one line each."""
    d, _ = plane_run
    res = run_bounded([sys.executable, "-m", "analysis", "reduce", str(d / "serial.h5"), "-o",
                       str(tmp_path / "s.h5")], 120, cwd=ROOT, env=child_env())
    assert res.returncode == 0, res.stderr
    s = summary.read(tmp_path / "s.h5")
    assert list(s["points/geometry"]) == ["lattice"] * 2 and list(s["points/M"]) == [8] * 2
    assert list(s["points/b"]) == [30.0, 45.0] and s["points/numbers/n_creep"][:, 0].tolist()[1] == 0
    res = run_bounded([sys.executable, "-m", "analysis", "report", str(tmp_path / "s.h5")], 120, cwd=ROOT,
                      env=child_env())
    assert res.returncode == 0, res.stderr
    lines = res.stdout.splitlines()
    assert [line.split(":")[0].strip() for line in lines if "not on a lattice" in line] == \
        ["rupture_classes", "slow_slip"] * 2, lines


@pytest.mark.parametrize("model, message", [
    ({"M": 4}, "model.M belongs to model.geometry = 'lattice' (not 'chain')"),
    ({"l_across": 2.0}, "model.l_across belongs to model.geometry = 'lattice' (not 'chain')"),
    ({"geometry": "plane"}, "model.geometry must be one of chain, lattice, got 'plane'"),
    ({"geometry": "lattice", "N": 1000, "M": 2000}, "model.N * model.M must be at most 1000000 blocks"),
    ({"geometry": "lattice", "M": 0}, "model.M must be an integer in [1, 1000000], got 0")])
def test_a_bad_geometry_is_one_line_naming_the_key(model, message, tmp_path):
    cfg = write_config(tmp_path / "bad.toml", model=model)
    res = run_cli("validate", cfg, timeout=60)
    assert res.returncode == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], lines
