"""The kinds of run job (KINDS) and what each writes besides its scripts: config snapshots and catalogs.

"single" and "requeue" run one config into one catalog; "array" runs one standalone config per
parameter point of the sweep (point_configs), each with a seed of its own drawn from the root seed
(element_seed), into a catalog of its own.
"""
import dataclasses
from pathlib import Path

from .. import checks
from ..config import replace
from .options import check_path


def element_seed(root_seed, point):
    """run.seed of the array element of parameter point `point`: drawn from
    SeedSequence(root_seed, spawn_key=(point,)), so that elements are independent of each
    other and reproducible from the root seed (63 bits: run.seed is a TOML integer)."""
    import numpy as np
    state = np.random.SeedSequence(root_seed, spawn_key=(point,)).generate_state(1, np.uint64)[0]
    return int(state >> np.uint64(1))


def point_configs(cfg):
    """One standalone config per parameter point of the sweep: the point's model values (with a
    [population], its distributions: all its faults), no sweep, all seeds, run.seed from element_seed()."""
    from ..sweep import sweep_points
    out = []
    for point, (model, draws) in enumerate(sweep_points(cfg)):
        population = (None if cfg.population is None else dataclasses.replace(cfg.population, draws=draws))
        out.append(dataclasses.replace(cfg, model=model, sweep=(), population=population,
                                       run=dataclasses.replace(cfg.run, seed=element_seed(cfg.run.seed, point))))
    return out


def _single_configs(cfg, directory):
    """single, requeue: one config snapshot and one catalog."""
    path = Path(cfg.output.path)
    catalog = path if path.is_absolute() else directory / path
    snapshot = directory / "config.toml"
    checks.write_text(snapshot, replace(cfg, "output", path=str(catalog)).to_toml(), "config snapshot")
    return {"CONFIG": check_path(snapshot), "CATALOG": check_path(catalog)}, [snapshot], [catalog]


def _array_configs(cfg, directory):
    """array: points/point-<i>.toml and points/point-<i>.h5 for each parameter point i."""
    points_dir = directory / "points"
    points_dir.mkdir(exist_ok=True)
    files, catalogs = [], []
    for i, sub in enumerate(point_configs(cfg)):
        catalog = points_dir / f"point-{i:04d}.h5"
        path = points_dir / f"point-{i:04d}.toml"
        values = ", ".join(f"{key}={getattr(sub.model, key)!r}" if not key.startswith("population.") else
                           f"{key}={dict(sub.population.draws)[key.partition('.')[2]].to_toml()}"
                           for key, _ in cfg.sweep)
        checks.write_text(path, f"# array element {i}: point {i} of the sweep ({values or 'no sweep'}); "
                                f"run.seed from SeedSequence({cfg.run.seed}, spawn_key=({i},))\n"
                                + replace(sub, "output", path=str(catalog)).to_toml(), "config snapshot")
        files.append(path)
        catalogs.append(catalog)
    return {"POINTS_DIR": check_path(points_dir), "ARRAY": f"0-{len(catalogs) - 1}"}, files, catalogs


KINDS = {   # kind: (template, what it writes besides the scripts)
    "single": ("single.sbatch", _single_configs),
    "requeue": ("requeue.sbatch", _single_configs),
    "array": ("array.sbatch", _array_configs),
}
