"""Hard cases run without tuning and without non-finite values; energy balance holds (small sizes)."""
import numpy as np
import pytest

from ensemble.config import Config, Integrator, Model, Run
from ensemble.events import relative_energy_residual
from ensemble.model.workspace import D_RESIDUAL, D_SLIP, D_VMAX, D_WORK
from ensemble.runner import Trajectory
from ensemble.tasks import task_list


@pytest.mark.parametrize("name,model,dt,events", [
    ("very fast slip b = 100", Model(N=100, b=100.0), 2e-4, 40),
    ("strong strengthening a = 30", Model(N=60, a=30.0), 1e-3, 8),
    ("c = 1e2", Model(N=100, c=1e2), 1e-3, 40),
    ("c = 1e6", Model(N=100, c=1e6), 1e-3, 40),
    ("nu = 1e-6", Model(N=100, nu=1e-6), 1e-3, 40),
    ("nu = 1e-10", Model(N=100, nu=1e-10), 1e-3, 40),
    ("N = 6400", Model(N=6400), 1e-3, 6),
])
def test_hard_case(name, model, dt, events):
    cfg = Config(model=model, run=Run(events=events, transient=events), integrator=Integrator(dt=dt))
    traj = Trajectory(cfg, task_list(cfg)[0])
    traj.advance(events)
    t, _, diag = traj.advance(events)
    assert np.all(np.isfinite(diag)) and np.all(np.isfinite(t)) and np.all(np.diff(t) > 0)
    assert np.all(diag[:, D_SLIP] > 0)
    residual = relative_energy_residual(diag[:, D_RESIDUAL], diag[:, D_WORK])
    print(f"{name}: max relative energy residual {residual.max():.1e}, v_max {diag[:, D_VMAX].max():.0f}, "
          f"mu {np.log10(diag[:, D_SLIP]).min():.2f}..{np.log10(diag[:, D_SLIP]).max():.2f}")
    assert residual.max() < 1e-8
