"""TOML config -> validated frozen dataclasses (the one source of parameter truth).

Every key has a default, a one-line meaning and a valid range below. Unknown
keys and out-of-range values raise ConfigError naming the key.
"""
import dataclasses
import math
import tomllib
from dataclasses import dataclass, field, fields


class ConfigError(ValueError):
    """A config file or override that cannot be used; the message names the key."""


def _positive(x):
    return x > 0


def _nonneg(x):
    return x >= 0


def _finite(x):
    return math.isfinite(x)


@dataclass(frozen=True)
class Model:
    """Dimensionless Burridge-Knopoff chain with rate- and state-dependent friction."""
    N: int = 800         # number of blocks (free ends)
    l: float = 3.0       # stiffness of the springs between blocks (l^2 relative to the driver spring)
    nu: float = 1e-8     # loading velocity of the driver plate
    a: float = 0.0       # velocity-strengthening coefficient of a ln(1 + v)
    b: float = 20.0      # state coefficient of b ln(theta) (slip weakening of slope b)
    c: float = 1000.0    # constant friction (removed exactly by a uniform shift of u)


@dataclass(frozen=True)
class Run:
    seeds: int = 1             # realisations per parameter point
    events: int = 200000       # events recorded per task
    transient: int = 10000     # events discarded at the start of each task
    seed: int = 0              # root seed: task k uses SeedSequence(seed, spawn_key=(k,))
    init_stress: float = 1.0   # initial forces are uniformly spread this far below threshold
    poll_seconds: float = 0.25  # kernel calls last about this long between MPI polls


@dataclass(frozen=True)
class Integrator:
    method: str = "ark4"           # event integrator (see ensemble.integrators.INTEGRATORS)
    dt: float = 1e-3               # time step of "rk4"; first step of the adaptive methods
    rtol: float = 1e-5             # adaptive methods (ark3, ark4, ark5): relative tolerance of the local error per step
    atol: float = 1e-12            # adaptive methods: absolute tolerance (slip, velocity)
    max_step: float = 0.5          # adaptive methods: largest step
    max_duration: float = 1e5      # an event lasting longer than this is an error


@dataclass(frozen=True)
class Output:
    path: str = "catalog.h5"     # HDF5 event catalog
    batch: int = 10000           # events buffered per task before they are written (with a checkpoint)
    flush_seconds: float = 60.0  # ... or after this long, whichever comes first
    progress_seconds: float = 30.0  # rank 0 prints a progress line this often
    writer: str = "auto"         # "parallel" (mpio), "rank0" (messages to rank 0), "auto"


_RULES = {
    ("model", "N"): (lambda x: x >= 2, "an integer >= 2"),
    ("model", "l"): (_positive, "> 0"),
    ("model", "nu"): (_positive, "> 0"),
    ("model", "a"): (_nonneg, ">= 0"),
    ("model", "b"): (_positive, "> 0"),
    ("model", "c"): (_finite, "finite"),
    ("run", "seeds"): (lambda x: x >= 1, "an integer >= 1"),
    ("run", "events"): (lambda x: x >= 1, "an integer >= 1"),
    ("run", "transient"): (_nonneg, "an integer >= 0"),
    ("run", "seed"): (_nonneg, "an integer >= 0"),
    ("run", "init_stress"): (_positive, "> 0"),
    ("integrator", "dt"): (lambda x: 0 < x <= 1, "in (0, 1]"),
    ("integrator", "max_duration"): (_positive, "> 0"),
    ("integrator", "rtol"): (lambda x: 0 < x < 1, "in (0, 1)"),
    ("integrator", "atol"): (_positive, "> 0"),
    ("integrator", "max_step"): (_positive, "> 0"),
    ("output", "batch"): (lambda x: x >= 1, "an integer >= 1"),
    ("output", "flush_seconds"): (_positive, "> 0"),
    ("output", "progress_seconds"): (_positive, "> 0"),
    ("output", "writer"): (lambda x: x in ("auto", "parallel", "rank0"), "one of auto, parallel, rank0"),
    ("run", "poll_seconds"): (_positive, "> 0"),
    ("output", "path"): (lambda x: len(x) > 0, "a non-empty string"),
}

SECTIONS = {"model": Model, "run": Run, "integrator": Integrator, "output": Output}


@dataclass(frozen=True)
class Config:
    model: Model = field(default_factory=Model)
    sweep: tuple = ()   # ((model key, (values...)), ...) in the order given
    run: Run = field(default_factory=Run)
    integrator: Integrator = field(default_factory=Integrator)
    output: Output = field(default_factory=Output)

    def to_toml(self):
        """The resolved config as TOML text (stored in every catalog)."""
        out = []
        for name, cls in SECTIONS.items():
            if name == "run" and self.sweep:
                out.append("[sweep]")
                out += [f"{k} = [{', '.join(_toml_value(v) for v in vals)}]" for k, vals in self.sweep]
                out.append("")
            out.append(f"[{name}]")
            section = getattr(self, name)
            out += [f"{f.name} = {_toml_value(getattr(section, f.name))}" for f in fields(cls)]
            out.append("")
        return "\n".join(out)


def _toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ("inf" if v > 0 else "-inf")
    return str(v)


def _coerce(section, key, value, typ):
    """Check the type of one value (ints are accepted where floats are expected)."""
    where = f"{section}.{key}"
    if typ is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f"{where} must be a number, got {value!r}")
        value = float(value)
    elif typ is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"{where} must be an integer, got {value!r}")
    elif typ is str:
        if not isinstance(value, str):
            raise ConfigError(f"{where} must be a string, got {value!r}")
    rule = _RULES.get((section, key))
    if rule is not None and not rule[0](value):
        raise ConfigError(f"{where} must be {rule[1]}, got {value!r}")
    return value


def _section(name, raw):
    cls = SECTIONS[name]
    if not isinstance(raw, dict):
        raise ConfigError(f"[{name}] must be a table")
    known = {f.name: f for f in fields(cls)}
    for key in raw:
        if key not in known:
            raise ConfigError(f"unknown key {name}.{key} (known: {', '.join(known)})")
    values = {k: _coerce(name, k, v, known[k].type) for k, v in raw.items()}
    return cls(**values)


def _sweep(raw):
    if not isinstance(raw, dict):
        raise ConfigError("[sweep] must be a table")
    types = {f.name: f.type for f in fields(Model)}
    out = []
    for key, values in raw.items():
        if key not in types:
            raise ConfigError(f"unknown key sweep.{key} (only [model] keys can be swept: {', '.join(types)})")
        if not isinstance(values, list) or not values:
            raise ConfigError(f"sweep.{key} must be a non-empty list of values")
        out.append((key, tuple(_coerce("model", key, v, types[key]) for v in values)))
    return tuple(out)


def from_dict(raw):
    """Validate a parsed TOML document into a Config."""
    allowed = set(SECTIONS) | {"sweep"}
    for name in raw:
        if name not in allowed:
            raise ConfigError(f"unknown section [{name}] (known: {', '.join(sorted(allowed))})")
    parts = {name: _section(name, raw.get(name, {})) for name in SECTIONS}
    cfg = Config(sweep=_sweep(raw.get("sweep", {})), **parts)
    if cfg.integrator.method not in _integrator_names():
        raise ConfigError(f"integrator.method must be one of {', '.join(_integrator_names())}, "
                          f"got {cfg.integrator.method!r}")
    return cfg


def _integrator_names():
    from .integrators import INTEGRATORS
    return sorted(INTEGRATORS)


def parse_override(text):
    """'section.key=value' -> (section, key, value); the value is TOML, or a bare string."""
    if "=" not in text or "." not in text.split("=", 1)[0]:
        raise ConfigError(f"--set expects section.key=value, got {text!r}")
    lhs, rhs = text.split("=", 1)
    section, key = lhs.strip().split(".", 1)
    try:
        value = tomllib.loads(f"v = {rhs.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = rhs.strip()
    return section, key, value


def load(path, overrides=()):
    """Read a TOML file, apply 'section.key=value' overrides and validate."""
    try:
        with open(path, "rb") as fh:
            raw = tomllib.load(fh)
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such config file") from None
    except tomllib.TOMLDecodeError as err:
        raise ConfigError(f"{path}: not valid TOML ({err})") from None
    for text in overrides:
        section, key, value = parse_override(text)
        raw.setdefault(section, {})
        if not isinstance(raw[section], dict):
            raise ConfigError(f"[{section}] must be a table")
        raw[section][key] = value
    return from_dict(raw)


def loads(text):
    """Validate TOML text (e.g. the config stored in a catalog)."""
    return from_dict(tomllib.loads(text))


def replace(cfg, section, **changes):
    """A copy of cfg with some keys of one section changed."""
    return dataclasses.replace(cfg, **{section: dataclasses.replace(getattr(cfg, section), **changes)})
