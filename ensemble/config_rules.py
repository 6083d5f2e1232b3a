"""The checks of a config's values (config.py): types, valid ranges, and the parameter points whose
numbers the kernels' arithmetic cannot hold.

Every float must be finite (TOML has inf and nan, and 1e400 reads as inf); a value out of its range
raises ConfigError naming the key. The ranges of the friction laws' keys and of the [integrator]
keys are declared with those keys (model/laws/, integrators.KEYS); the others are here (RULES).
"""
import itertools
import math

from .integrators import KEYS as INTEGRATOR_KEYS
from .model import laws


class ConfigError(ValueError):
    """A config file or override that cannot be used; the message names the key."""


def _positive(x):
    return x > 0


def _nonneg(x):
    return x >= 0


# sizes beyond what any run can do: refused at once instead of allocating, or promising an ETA of
# 1e14 minutes (1e12 events are decades of core time at the ~1000 events/s of N = 800)
MAX_BLOCKS = 10 ** 6
MAX_COUNT = 10 ** 12
MAX_BATCH = 10 ** 7
# event histories: each takes up to history_snapshots x 16 N bytes of the catalog (ensemble/model/history.py)
MAX_HISTORIES = 1000
MAX_SNAPSHOTS = 100_000
MAX_NU = 10.0

RULES = {   # (section, key) -> (value -> bool, what it requires)
    # a rank holds about 500 bytes per block: 1e6 blocks are 0.5 GB (the paper: 800 and 1600)
    ("model", "N"): (lambda x: 1 <= x <= MAX_BLOCKS, f"an integer in [1, {MAX_BLOCKS}] (a rank holds about 500 "
                                                      f"bytes per block)"),
    ("model", "l"): (_positive, "> 0"),
    ("model", "M"): (lambda x: 1 <= x <= MAX_BLOCKS, f"an integer in [1, {MAX_BLOCKS}]"),
    ("model", "l_across"): (_positive, "> 0"),
    # the plate must be slow against slip, whose velocities are of order 1 in these units (the paper:
    # 1e-8); faster loading is not this model, and from about 1e8 on the kernels' floats fail
    ("model", "nu"): (lambda x: 0 < x <= MAX_NU, f"in (0, {MAX_NU:g}] (loading slow against slip; the paper: 1e-8)"),
    **{("model", name): (key.check, key.rule) for law in laws.LAWS.values() for name, key in law.keys.items()},
    ("run", "seeds"): (lambda x: 1 <= x <= MAX_COUNT, f"an integer in [1, {MAX_COUNT:.0e}]"),
    ("run", "events"): (lambda x: 1 <= x <= MAX_COUNT, f"an integer in [1, {MAX_COUNT:.0e}]"),
    ("run", "transient"): (lambda x: 0 <= x <= MAX_COUNT, f"an integer in [0, {MAX_COUNT:.0e}]"),
    ("run", "seed"): (_nonneg, "an integer >= 0"),
    ("run", "init_stress"): (_positive, "> 0"),
    ("run", "perturbation"): (_nonneg, ">= 0"),
    ("run", "decorrelation"): (lambda x: 0 <= x <= MAX_COUNT, f"an integer in [0, {MAX_COUNT:.0e}]"),
    **{("integrator", name): (key.check, key.rule) for name, key in INTEGRATOR_KEYS.items() if key.check},
    # a task buffers a batch in memory, 80 bytes per event
    ("output", "batch"): (lambda x: 1 <= x <= MAX_BATCH, f"an integer in [1, {MAX_BATCH:.0e}] (80 bytes per event "
                                                          f"in memory)"),
    ("output", "flush_seconds"): (_positive, "> 0"),
    ("output", "progress_seconds"): (_positive, "> 0"),
    ("output", "writer"): (lambda x: x in ("auto", "parallel", "rank0"), "one of auto, parallel, rank0"),
    ("run", "poll_seconds"): (_positive, "> 0"),
    ("output", "path"): (lambda x: len(x) > 0, "a non-empty string"),
    ("output", "history"): (lambda x: 0 <= x <= MAX_HISTORIES, f"an integer in [0, {MAX_HISTORIES}] (events per "
                                                               "task whose history is kept; 0: none)"),
    ("output", "history_snapshots"): (lambda x: 2 <= x <= MAX_SNAPSHOTS, f"an integer in [2, {MAX_SNAPSHOTS}]"),
    ("output", "history_dt"): (_positive, "> 0"),
    ("output", "history_dlogv"): (_positive, "> 0"),
}


def coerce(section, key, value, typ, where=None):
    """Check the type and range of one value (ints are accepted where floats are expected).

    where: the name the message gives the value (default section.key; sweep.KEY for a swept one).
    """
    where = where or f"{section}.{key}"
    if typ is bool:
        if not isinstance(value, bool):
            raise ConfigError(f"{where} must be true or false, got {value!r}")
    elif typ is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f"{where} must be a number, got {value!r}")
        try:
            value = float(value)
        except OverflowError:   # a TOML integer beyond float range
            value = math.inf
        if not math.isfinite(value):
            # "> 0" and ">= 0" alone let inf through (and TOML reads 1e400 as inf)
            raise ConfigError(f"{where} must be a finite number, got {value!r}")
    elif typ is int:
        # a count written as the docs write counts (2e5) is a float that is an exact integer: taken as that integer
        if isinstance(value, float) and math.isfinite(value) and value.is_integer() and abs(value) < 2 ** 53:
            value = int(value)
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"{where} must be an integer, got {value!r}")
        if not -2**63 <= value < 2**63:   # tomllib reads integers of any size; catalogs store int64
            raise ConfigError(f"{where} must fit in 64 bits, got {value!r}")
    elif typ is str:
        if not isinstance(value, str):
            raise ConfigError(f"{where} must be a string, got {value!r}")
    rule = RULES.get((section, key))
    if rule is not None and not rule[0](value):
        raise ConfigError(f"{where} must be {rule[1]}, got {value!r}")
    return value


def point_values(cfg, name):
    """Every value a key ("model.b", "run.init_stress") takes over the parameter points of a config
    (config.Config), and the name to give it ("sweep.b" if swept); of a key a population draws, the
    extremes of its distributions ("population.b")."""
    section, key = name.split(".")
    if section == "model" and cfg.population is not None:
        # a swept spec replaces the [population] one at its points
        specs = ([d for swept, vals in cfg.sweep if swept == f"population.{key}" for d in vals]
                 or [d for k, d in cfg.population.draws if k == key])
        if specs:
            return f"population.{key}", tuple(v for d in specs for v in d.bounds())
    for swept, vals in cfg.sweep:
        if section == "model" and swept == key:
            return f"sweep.{key}", vals
    return name, (getattr(getattr(cfg, section), key),)


def _first_onset_bound(b, nu, init_stress):
    """Latest time of the first onset from the initial state, as ensemble/model/onset.py finds it.

    Every block starts at theta = 1 with its force up to init_stress below threshold;
    onset_delay forms L = ln(b / nu) + init_stress / b + nu / b (at most), takes a root
    y <= max(2 L, 1) and returns (y - nu / b) * b / nu.
    """
    ratio = b / nu
    L = (math.log(ratio) if ratio > 0 else -math.inf) + init_stress / b + nu / b
    return max(2 * L, 1.0) * ratio


# Parameter points whose numbers the kernels' float arithmetic cannot hold. Each entry: the
# keys it reads, the number (must come out finite) and what that number is. The kernel is the
# wrong place to find out: with b / nu = 1e310 (b = 1e300, nu = 1e-10) a run looped forever
# inside the kernel, deaf to SIGTERM, and with nu / b = 1e310 it corrupted memory ("double
# free"). Each term that can overflow is largest at a corner of the sweep (smallest or largest
# b, nu, l), so only the corners are checked.
OVERFLOW_RULES = (
    (("model.l",), lambda l: l * l,
     "l^2 (the stiffness between blocks, integrators.kernel_params)"),
    (("model.b", "model.nu", "run.init_stress"), _first_onset_bound,
     "the time of the first onset, up to 2 b/nu (ln(b/nu) + init_stress/b + nu/b) (model/onset.py)"),
)


def check_overflow(cfg):
    """Refuse a config (config.Config) with a parameter point of OVERFLOW_RULES."""
    for keys, number, meaning in OVERFLOW_RULES:
        named = [point_values(cfg, key) for key in keys]
        if any(v is None for _, vals in named for v in vals):
            continue    # a key of another friction law
        for corner in itertools.product(*[(min(v), max(v)) for _, v in named]):
            if not math.isfinite(number(*corner)):
                given = ", ".join(f"{name} = {x!r}" for (name, _), x in zip(named, corner))
                raise ConfigError(f"{given}: {meaning} overflows a float")
