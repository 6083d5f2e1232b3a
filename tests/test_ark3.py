"""The adaptive IMEX integrator ARK3(2): error follows the tolerance, same events as RK4."""
import numpy as np
import pytest

from ensemble.config import Integrator, Model
from ensemble.events import advance_to_onset, check, run_event

from .conftest import developed_state, run_cli, write_config


@pytest.fixture(scope="module")
def events():
    """Pre-event states of the next few events of a developed chain, and RK4 references."""
    model = Model(N=100, b=20.0, a=2.0)
    force, psi = developed_state(model, 200)
    out = []
    for _ in range(4):
        epicenter, _, f, p = advance_to_onset(force, psi, model)
        f[epicenter] = model.b * p[epicenter]
        ref = check(run_event(f, p, epicenter, model, Integrator(method="rk4", dt=1.25e-4)))
        out.append((f, p, epicenter, ref))
        force, psi = ref.force, ref.psi
    return model, out


def test_slip_error_follows_the_tolerance(events):
    model, evs = events
    for f, p, epicenter, ref in evs:
        errors = []
        for rtol in (1e-5, 1e-7):
            ev = check(run_event(f, p, epicenter, model, Integrator(method="ark3", rtol=rtol)))
            errors.append(abs(ev.slip - ref.slip) / ref.slip)
            assert np.linalg.norm(ev.profile - ref.profile) <= 100 * rtol * np.linalg.norm(ref.profile)
            assert ev.relative_energy_residual < 100 * rtol
        print(f"slip {ref.slip:.3g}: relative errors at rtol 1e-5, 1e-7: {errors[0]:.1e}, {errors[1]:.1e}")
        assert errors[0] < 1e-3 and errors[1] < 1e-5
        assert errors[1] < errors[0] / 10 or errors[1] < 1e-9


def test_takes_far_fewer_steps_than_rk4_in_slow_nucleation(events):
    """A strongly damped chain (a = 30) nucleates slowly: steps are set by accuracy, not by dt."""
    model = Model(N=40, b=20.0, a=30.0)
    force, psi = developed_state(model, 5)
    epicenter, _, f, p = advance_to_onset(force, psi, model)
    f[epicenter] = model.b * p[epicenter]
    rk4 = check(run_event(f, p, epicenter, model, Integrator(method="rk4", dt=1e-3)))
    ark = check(run_event(f, p, epicenter, model, Integrator(method="ark3", rtol=1e-7)))
    print(f"a = 30 event of duration {rk4.duration:.0f}: RK4 {rk4.steps} steps, ARK3 {ark.steps}")
    assert ark.slip == pytest.approx(rk4.slip, rel=1e-5)
    assert ark.steps < rk4.steps / 5


def test_run_with_ark3(tmp_path):
    cfg = write_config(tmp_path / "c.toml", integrator={"method": "ark3", "rtol": 1e-6},
                       run={"seeds": 1, "events": 30, "transient": 10})
    res = run_cli("run", cfg, "-o", tmp_path / "a.h5")
    assert res.returncode == 0, res.stderr
