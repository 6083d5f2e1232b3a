"""TOML config -> validated frozen dataclasses (the one source of parameter truth).

Every key has a default, a one-line meaning and a valid range below. Unknown
keys and out-of-range values raise ConfigError naming the key; every float must
be finite (TOML has inf and nan, and 1e400 reads as inf), and parameter points
whose numbers the kernels' arithmetic cannot hold are refused (_OVERFLOW_RULES).
"""
import dataclasses
import itertools
import math
import tomllib
from contextlib import contextmanager
from dataclasses import dataclass, field, fields

from . import filekind
from .model import laws
from .sections import SECTION_NAMES


class ConfigError(ValueError):
    """A config file or override that cannot be used; the message names the key."""


def _positive(x):
    return x > 0


def _nonneg(x):
    return x >= 0


@dataclass(frozen=True)
class _Chain:
    """Dimensionless Burridge-Knopoff chain; the friction law's own keys follow (model/laws/)."""
    N: int = 800         # number of blocks (free ends)
    l: float = 3.0       # stiffness of the springs between blocks (l^2 relative to the driver spring)
    nu: float = 1e-8     # loading velocity of the driver plate
    law: str = laws.DEFAULT   # friction law: one of model/laws/ (aging: the paper's)

    def __post_init__(self):
        """Resolve the law's keys: a key left out takes the law's default; a key of another law
        (not None) is an error naming it."""
        if self.law not in laws.LAWS:
            raise ConfigError(f"model.law must be one of {', '.join(sorted(laws.LAWS))}, got {self.law!r}")
        own = laws.get(self.law).keys
        for name in LAW_KEYS:
            value = getattr(self, name)
            if name in own and value is None:
                object.__setattr__(self, name, own[name].default)
            elif name not in own and value is not None:
                raise ConfigError(f"model.{name} does not belong to model.law = {self.law!r} "
                                  f"(its keys: {', '.join(own)})")

    def law_keys(self):
        """The [model] keys of this model's law, in order."""
        return tuple(laws.get(self.law).keys)


# every law's keys, in the order of the registry (a name two laws share has one meaning)
LAW_KEYS = tuple(dict.fromkeys(k for law in laws.LAWS.values() for k in law.keys))
Model = dataclasses.make_dataclass(
    "Model", [(name, float, field(default=None)) for name in LAW_KEYS], bases=(_Chain,), frozen=True)
Model.__doc__ = _Chain.__doc__
Model.__module__ = __name__


# run.transient's default, in events per block of the longest chain of the sweep: from the random
# start the statistics drift for at most 1.25 events per block (b = 50, N = 800; b = 20: none seen at
# N = 800, 0.3-0.6 per block at N = 1600; benchmarks/transient.py, docs/benchmarks.md); 10 is eight
# times the longest.
TRANSIENT_PER_BLOCK = 10
# run.decorrelation's default, in events per block of the longest chain of the sweep: two branches of
# one spun-up state are as different as two independent chains after at most 0.30 events per block
# (220 events at N = 800, b = 50; median 0.1-0.15; benchmarks/decorrelation.py, docs/benchmarks.md);
# 1 is 3.3 times the longest.
DECORRELATION_PER_BLOCK = 1


@dataclass(frozen=True)
class Run:
    seeds: int = 1             # realisations per parameter point
    events: int = 200000       # events recorded per task
    transient: int = None      # events discarded at the start of each task, or of each spin-up (default TRANSIENT_PER_BLOCK N)
    seed: int = 0              # root seed: task k uses SeedSequence(seed, spawn_key=(k,))
    init_stress: float = 1.0   # initial forces are uniformly spread this far below threshold
    poll_seconds: float = 0.25  # kernel calls last about this long between MPI polls
    branch: bool = False       # spin each point up once (run.transient events), start its seeds from that state
    perturbation: float = 1e-6  # branch: each block's force is lowered by a uniform [0, this) (model force)
    decorrelation: int = None  # branch: events each seed discards after the branch point (default 1 N)

    @property
    def discarded(self):
        """Events each task runs before it records: the transient, or after branching the decorrelation stretch."""
        return self.decorrelation if self.branch else self.transient


# integrator.rtol's default: the fastest ark4 tolerance whose magnitudes and recurrence times are
# indistinguishable from rtol 1e-7's at 1e5 events per point (b = 20 and 50, N = 800); 1e-3's
# recurrence times at b = 50 are not (benchmarks/statistics.py --catalogs, docs/benchmarks.md).
@dataclass(frozen=True)
class Integrator:
    method: str = "ark4"           # event integrator (ensemble.integrators.INTEGRATORS); a config file without it
                                   # takes its law's (Law.method: exp4 for the aging law, ark4 for the others)
    dt: float = 1e-3               # time step of "rk4"; first step of the adaptive methods
    rtol: float = 1e-4             # adaptive methods (ark3, ark4, ark5): relative tolerance of the local error per step
    atol: float = 1e-12            # adaptive methods: absolute tolerance (slip, velocity)
    max_step: float = 0.5          # adaptive methods: largest step
    max_duration: float = 1e5      # an event lasting longer than this is an error
    creep_tol: float = 1e-6        # creep phase (b below a block's stiffness): local error of the state psi per creep step


@dataclass(frozen=True)
class Output:
    path: str = "catalog.h5"     # HDF5 event catalog
    batch: int = 10000           # events buffered per task before they are written (with a checkpoint)
    flush_seconds: float = 60.0  # ... or after this long, whichever comes first
    progress_seconds: float = 30.0  # rank 0 prints a progress line this often
    writer: str = "auto"         # "parallel" (mpio), "rank0" (messages to rank 0), "auto"


# sizes beyond what any run can do: refused at once instead of allocating, or promising an ETA of
# 1e14 minutes (1e12 events are decades of core time at the ~1000 events/s of N = 800)
MAX_BLOCKS = 10 ** 6
MAX_COUNT = 10 ** 12
MAX_BATCH = 10 ** 7
MAX_NU = 10.0

_RULES = {
    # a rank holds about 500 bytes per block: 1e6 blocks are 0.5 GB (the paper: 800 and 1600)
    ("model", "N"): (lambda x: 1 <= x <= MAX_BLOCKS, f"an integer in [1, {MAX_BLOCKS}] (a rank holds about 500 "
                                                      f"bytes per block)"),
    ("model", "l"): (_positive, "> 0"),
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
    ("integrator", "dt"): (lambda x: 0 < x <= 1, "in (0, 1]"),
    ("integrator", "max_duration"): (_positive, "> 0"),
    ("integrator", "rtol"): (lambda x: 0 < x < 1, "in (0, 1)"),
    ("integrator", "atol"): (_positive, "> 0"),
    ("integrator", "max_step"): (_positive, "> 0"),
    ("integrator", "creep_tol"): (lambda x: 0 < x < 1, "in (0, 1)"),
    # a task buffers a batch in memory, 80 bytes per event
    ("output", "batch"): (lambda x: 1 <= x <= MAX_BATCH, f"an integer in [1, {MAX_BATCH:.0e}] (80 bytes per event "
                                                          f"in memory)"),
    ("output", "flush_seconds"): (_positive, "> 0"),
    ("output", "progress_seconds"): (_positive, "> 0"),
    ("output", "writer"): (lambda x: x in ("auto", "parallel", "rank0"), "one of auto, parallel, rank0"),
    ("run", "poll_seconds"): (_positive, "> 0"),
    ("output", "path"): (lambda x: len(x) > 0, "a non-empty string"),
}

# (the names in sections.py, where filekind.py reads them too)
SECTIONS = dict(zip(SECTION_NAMES, (Model, Run, Integrator, Output), strict=True))


@dataclass(frozen=True)
class Config:
    model: Model = field(default_factory=Model)
    sweep: tuple = ()   # ((model key, (values...)), ...) in the order given
    run: Run = field(default_factory=Run)
    integrator: Integrator = field(default_factory=Integrator)
    output: Output = field(default_factory=Output)

    def __post_init__(self):
        """Resolve run.transient and run.decorrelation left out: TRANSIENT_PER_BLOCK and
        DECORRELATION_PER_BLOCK events per block of the largest N."""
        largest = max(int(n) for n in _values(self, "model.N")[1])
        if self.run.transient is None:
            object.__setattr__(self, "run", dataclasses.replace(self.run, transient=TRANSIENT_PER_BLOCK * largest))
        if self.run.decorrelation is None:
            object.__setattr__(self, "run", dataclasses.replace(
                self.run, decorrelation=DECORRELATION_PER_BLOCK * largest))

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
            out += section_lines(section)
            out.append("")
        return "\n".join(out)


def section_lines(section):
    """`key = value` TOML lines of one section's dataclass, in field order (a key of another
    friction law, None, is left out)."""
    return [f"{f.name} = {_toml_value(getattr(section, f.name))}" for f in fields(section)
            if getattr(section, f.name) is not None]


def _toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ("inf" if v > 0 else "-inf")
    return str(v)


def _coerce(section, key, value, typ, where=None):
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
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"{where} must be an integer, got {value!r}")
        if not -2**63 <= value < 2**63:   # tomllib reads integers of any size; catalogs store int64
            raise ConfigError(f"{where} must fit in 64 bits, got {value!r}")
    elif typ is str:
        if not isinstance(value, str):
            raise ConfigError(f"{where} must be a string, got {value!r}")
    rule = _RULES.get((section, key))
    if rule is not None and not rule[0](value):
        raise ConfigError(f"{where} must be {rule[1]}, got {value!r}")
    return value


@contextmanager
def _from_set(overridden, section, key):
    """An error about a value that came from --set says so."""
    try:
        yield
    except ConfigError as err:
        if (section, key) not in overridden:
            raise
        raise ConfigError(f"{err} (from --set {overridden[section, key]})") from None


def _section(name, raw, overridden):
    cls = SECTIONS[name]
    if not isinstance(raw, dict):
        raise ConfigError(f"[{name}] must be a table")
    known = {f.name: f for f in fields(cls)}
    values = {}
    for key, value in raw.items():
        with _from_set(overridden, name, key):
            if key not in known:
                raise ConfigError(f"unknown key {name}.{key} (known: {', '.join(known)})")
            values[key] = _coerce(name, key, value, known[key].type)
    return cls(**values)


def _sweep(raw, overridden):
    if not isinstance(raw, dict):
        raise ConfigError("[sweep] must be a table")
    types = {f.name: f.type for f in fields(Model)}
    out = []
    for key, values in raw.items():
        with _from_set(overridden, "sweep", key):
            if key not in types or key == "law":
                raise ConfigError(f"unknown key sweep.{key} (only [model] keys can be swept: "
                                  f"{', '.join(k for k in types if k != 'law')})")
            if not isinstance(values, list) or not values:
                raise ConfigError(f"sweep.{key} must be a non-empty list of values, e.g. {key} = [20, 40] "
                                  f"(on the command line: --set 'sweep.{key}=[20, 40]'), got {values!r}")
            coerced = tuple(_coerce("model", key, v, types[key], where=f"sweep.{key}") for v in values)
            repeated = [v for i, v in enumerate(coerced) if v in coerced[:i]]
            if repeated:   # the points would be one point run twice, then pooled by the reduction
                raise ConfigError(f"sweep.{key} lists {repeated[0]!r} more than once")
            out.append((key, coerced))
    return tuple(out)


def _values(cfg, name):
    """Every value a key ("model.b", "run.init_stress") takes over the parameter points, and the
    name to give it ("sweep.b" if swept)."""
    section, key = name.split(".")
    for swept, values in cfg.sweep:
        if section == "model" and swept == key:
            return f"sweep.{key}", values
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
_OVERFLOW_RULES = (
    (("model.l",), lambda l: l * l,   # noqa: E741 - the model's name
     "l^2 (the stiffness between blocks, integrators.kernel_params)"),
    (("model.b", "model.nu", "run.init_stress"), _first_onset_bound,
     "the time of the first onset, up to 2 b/nu (ln(b/nu) + init_stress/b + nu/b) (model/onset.py)"),
)


def _check_overflow(cfg):
    for keys, number, meaning in _OVERFLOW_RULES:
        named = [_values(cfg, key) for key in keys]
        if any(v is None for _, values in named for v in values):
            continue    # a key of another friction law
        for corner in itertools.product(*[(min(v), max(v)) for _, v in named]):
            if not math.isfinite(number(*corner)):
                given = ", ".join(f"{name} = {x!r}" for (name, _), x in zip(named, corner))
                raise ConfigError(f"{given}: {meaning} overflows a float")


def from_dict(raw, overridden=None):
    """Validate a parsed TOML document into a Config.

    overridden: {(section, key): "section.key=value"} of the values that came from --set.
    """
    overridden = overridden or {}
    allowed = set(SECTIONS) | {"sweep"}
    for name in raw:
        if name not in allowed:
            raise ConfigError(f"unknown section [{name}] (known: {', '.join(sorted(allowed))})")
    parts = {name: _section(name, raw.get(name, {}), overridden) for name in SECTIONS}
    cfg = Config(sweep=_sweep(raw.get("sweep", {}), overridden), **parts)
    if "method" not in raw.get("integrator", {}):      # the law's own (the resolved config records it)
        cfg = dataclasses.replace(cfg, integrator=dataclasses.replace(cfg.integrator,
                                                                      method=laws.get(cfg.model.law).method))
    for key, _ in cfg.sweep:
        if key in LAW_KEYS and key not in cfg.model.law_keys():
            raise ConfigError(f"sweep.{key} does not belong to model.law = {cfg.model.law!r} "
                              f"(its keys: {', '.join(cfg.model.law_keys())})")
    if cfg.integrator.method not in _integrator_names():
        raise ConfigError(f"integrator.method must be one of {', '.join(_integrator_names())}, "
                          f"got {cfg.integrator.method!r}")
    from .integrators import INTEGRATORS
    refusal = INTEGRATORS[cfg.integrator.method].refusal(laws.get(cfg.model.law))
    if refusal:
        raise ConfigError(refusal)
    law = laws.get(cfg.model.law)
    if not law.creeps and cfg.integrator.creep_tol != Integrator.creep_tol:
        # a tolerance for a phase this law never enters: a mistake about the model, not a no-op
        raise ConfigError(f"integrator.creep_tol = {cfg.integrator.creep_tol!r}: model.law = {law.name!r} has no creep "
                          f"phase (its blocks always start inertial events; docs/laws.md)")
    _check_overflow(cfg)
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


def _apply_overrides(raw, overrides):
    """Set parsed overrides [(text, (section, key, value))] into a document; {(section, key): text}."""
    overridden = {}
    for text, (section, key, value) in overrides:
        raw.setdefault(section, {})
        if not isinstance(raw[section], dict):
            raise ConfigError(f"[{section}] must be a table (from --set {text})")
        raw[section][key] = value
        overridden[section, key] = text
    return overridden


def loads(text, overrides=(), source=None):
    """Validate TOML text (e.g. the config stored in a catalog) with 'section.key=value' overrides.

    text: str, or bytes (UTF-8). Overrides are applied as by `load` (`--set` on the command
    line). source: where the text came from (a file, "the config stored in X"); errors start
    with it, except those of an override's syntax, which is not in the text.
    """
    overrides = [(o, parse_override(o)) for o in overrides]
    try:
        if isinstance(text, bytes):
            text = _decode(text)
        try:
            raw = tomllib.loads(text)
        except tomllib.TOMLDecodeError as err:
            raise ConfigError(f"not valid TOML ({err})") from None
        return from_dict(raw, _apply_overrides(raw, overrides))
    except ConfigError as err:
        if source is None:
            raise
        raise ConfigError(f"{source}: {err}") from None


def _decode(data):
    if b"\0" in data:   # valid UTF-8 or not, NUL bytes mean binary data
        raise ConfigError("binary data (NUL bytes), not a TOML config")
    try:
        # a byte-order mark (some editors write one) is not part of the TOML text
        return data.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as err:
        raise ConfigError(f"not UTF-8 text (byte 0x{data[err.start]:02x} at offset {err.start}), "
                          "not a TOML config") from None


def load(path, overrides=()):
    """Read a TOML file, apply 'section.key=value' overrides and validate.

    A path that cannot be a config (missing, a directory, unreadable, an HDF5 catalog or
    summary, binary data, too large) is a ConfigError whose one line names the file.
    """
    try:
        with open(path, "rb") as fh:
            data = fh.read(filekind.TOML_SIZE_LIMIT + 1)
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such config file") from None
    except IsADirectoryError:
        raise ConfigError(f"{path} is a directory, not a TOML config") from None
    except OSError as err:
        raise ConfigError(f"{path} cannot be read ({err.strerror or filekind.one_line(err)})") from None
    if data.startswith(filekind.HDF5_SIGNATURE):
        # say which: a catalog or summary given for its config is the likely slip
        filekind.require(path, "config", ConfigError)
    if len(data) > filekind.TOML_SIZE_LIMIT:
        raise ConfigError(f"{path} is larger than {filekind.TOML_SIZE_LIMIT >> 20} MiB, not a TOML config")
    if _empty(data):
        # (an empty file, or /dev/null, would otherwise start the paper's full run: 200000 events of 800 blocks)
        raise ConfigError(f"{path}: empty config (no keys): give at least one section; every key has a default, "
                          f"and examples/small.toml is a small run")
    return loads(data, overrides, source=path)


def _empty(data):
    """True if a config file's bytes hold no key (nothing, whitespace or comments only)."""
    try:
        return not tomllib.loads(_decode(data))
    except (ConfigError, tomllib.TOMLDecodeError):
        return False      # loads says what is wrong


def replace(cfg, section, **changes):
    """A copy of cfg with some keys of one section changed."""
    return dataclasses.replace(cfg, **{section: dataclasses.replace(getattr(cfg, section), **changes)})
