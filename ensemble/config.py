"""TOML config -> validated frozen dataclasses (the one source of parameter truth).

Every key has a default and a one-line meaning below, or where it is declared (a friction law's
keys in model/laws/, the [integrator] keys in integrators.KEYS), and a valid range
(config_rules.py). Unknown keys and out-of-range values raise ConfigError naming the key; every
float must be finite (TOML has inf and nan, and 1e400 reads as inf), and parameter points whose
numbers the kernels' arithmetic cannot hold are refused (config_rules.OVERFLOW_RULES).
"""
import dataclasses
import math
import tomllib
from contextlib import contextmanager
from dataclasses import dataclass, field, fields

from . import filekind, population as populations
from .config_rules import MAX_BLOCKS, ConfigError, check_overflow, coerce, point_values
from .integrators import INTEGRATORS
from .integrators import KEYS as INTEGRATOR_KEYS
from .model import geometry, laws
from .model.geometry import SOFTEST_STIFFNESS
from .sections import POPULATION, SECTION_NAMES, SWEEP

__all__ = ["Config", "ConfigError", "DECORRELATION_PER_BLOCK", "Integrator", "LAW_KEYS", "MEASURED_TRANSIENT_PER_BLOCK",
           "Model", "Output", "Run", "SECTIONS", "TRANSIENT_PER_BLOCK", "from_dict", "load", "loads", "parse_override",
           "parse_section", "replace", "section_lines"]


@dataclass(frozen=True)
class _Chain:
    """Dimensionless Burridge-Knopoff chain; the friction law's own keys follow (model/laws/)."""
    N: int = 800         # number of blocks (free ends); on a lattice, blocks along strike
    l: float = 3.0       # stiffness of the springs between blocks (l^2 relative to the driver spring)
    nu: float = 1e-8     # loading velocity of the driver plate
    law: str = laws.DEFAULT   # friction law: one of model/laws/ (aging: the paper's)
    geometry: str = geometry.DEFAULT   # how the blocks are joined: chain (a line), lattice (N x M, a fault plane)
    M: int = 1           # lattice: blocks across strike (M rows of N; free edges)
    l_across: float = None    # lattice: stiffness of the springs across strike (default: l)

    def __post_init__(self):
        """Resolve the law's keys: a key left out takes the law's default; a key of another law
        (not None) is an error naming it. The same for the geometry's keys (M, l_across: the lattice's)."""
        if self.geometry not in geometry.GEOMETRIES:
            raise ConfigError(f"model.geometry must be one of {', '.join(sorted(geometry.GEOMETRIES))}, "
                              f"got {self.geometry!r}")
        own = geometry.get(self.geometry).keys
        for key, unset in geometry.KEYS.items():
            if key not in own and getattr(self, key) != unset:
                takers = ", ".join(repr(g.name) for g in geometry.GEOMETRIES.values() if key in g.keys)
                raise ConfigError(f"model.{key} belongs to model.geometry = {takers} (not {self.geometry!r})")
        if "l_across" in own and self.l_across is None:
            object.__setattr__(self, "l_across", self.l)
        if self.N * self.M > MAX_BLOCKS:
            raise ConfigError(f"model.N * model.M must be at most {MAX_BLOCKS} blocks, got {self.N} x {self.M}")
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

    @property
    def blocks(self):
        """The number of blocks: N on a chain, N x M on a lattice."""
        return self.N * self.M

    def law_keys(self):
        """The [model] keys of this model's law, in order."""
        return tuple(laws.get(self.law).keys)


# every law's keys, in the order of the registry (a name two laws share has one meaning)
LAW_KEYS = tuple(dict.fromkeys(k for law in laws.LAWS.values() for k in law.keys))
Model = dataclasses.make_dataclass(
    "Model", [(name, float, field(default=None)) for name in LAW_KEYS], bases=(_Chain,), frozen=True)
Model.__doc__ = _Chain.__doc__
Model.__module__ = __name__
MODEL_TYPES = {f.name: f.type for f in fields(Model)}   # [model] key -> int, float or str


# run.transient's default, in events per block of the longest chain of the sweep: from the random
# start the statistics drift for at most 1.25 events per block (b = 50, N = 800; b = 20: none seen at
# N = 800, 0.3-0.6 per block at N = 1600; benchmarks/transient.py, docs/benchmarks.md); 10 is eight
# times the longest.
TRANSIENT_PER_BLOCK = 10
# the longest transient measured from the random start, events per block (b = 50, N = 800: 1000 events;
# benchmarks/results/transient.txt, docs/benchmarks.md); TRANSIENT_PER_BLOCK is 8x this
MEASURED_TRANSIENT_PER_BLOCK = 1.25
# run.decorrelation's default, in events per block of the longest chain of the sweep: two branches of
# one spun-up state are as different as two independent chains after at most 0.30 events per block
# (220 events at N = 800, b = 50; median 0.1-0.15; benchmarks/decorrelation.py, docs/benchmarks.md);
# 1 is 3.3 times the longest.
DECORRELATION_PER_BLOCK = 1


@dataclass(frozen=True)
class Run:
    seeds: int = 1             # realisations per parameter point
    events: int = 200000       # events recorded per task
    transient: int = None      # events discarded at the start of each task, or of each spin-up
    #                            (default TRANSIENT_PER_BLOCK N)
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


# [integrator]: the keys declared in integrators.KEYS (default, unit, range, meaning, the methods that
# read each); a config file without integrator.method takes its law's (Law.method, from_dict)
Integrator = dataclasses.make_dataclass(
    "Integrator", [(name, type(key.default), field(default=key.default)) for name, key in INTEGRATOR_KEYS.items()],
    frozen=True)
Integrator.__doc__ = "The event integrator and its settings (integrators.KEYS)."
Integrator.__module__ = __name__


@dataclass(frozen=True)
class Output:
    path: str = "catalog.h5"     # HDF5 event catalog
    batch: int = 10000           # events buffered per task before they are written (with a checkpoint)
    flush_seconds: float = 60.0  # ... or after this long, whichever comes first
    progress_seconds: float = 30.0  # rank 0 prints a progress line this often
    writer: str = "auto"         # "parallel" (mpio), "rank0" (messages to rank 0), "auto"
    history: int = 0             # events per task whose history (velocity and slip profiles in time) is kept
    history_mu: float = 4.0      # ... the first recorded events of magnitude at least this
    history_snapshots: int = 1000  # ... at most this many snapshots each (the last is the event's end)
    history_dt: float = 1.0      # ... a snapshot at least this often in the event's time (model time)
    history_dlogv: float = 0.1   # ... and whenever its largest velocity has changed by this in log10


# (the names in sections.py, where filekind.py reads them too)
SECTIONS = dict(zip(SECTION_NAMES, (Model, Run, Integrator, Output), strict=True))


@dataclass(frozen=True)
class Config:
    model: Model = field(default_factory=Model)
    sweep: tuple = ()   # ((model key, (values...)), ...) in the order given
    run: Run = field(default_factory=Run)
    integrator: Integrator = field(default_factory=Integrator)
    output: Output = field(default_factory=Output)
    population: object = None   # population.Population: each task a fault drawn from it (None: no population)

    def __post_init__(self):
        """Resolve run.transient and run.decorrelation left out: TRANSIENT_PER_BLOCK and
        DECORRELATION_PER_BLOCK events per block of the largest N (of N x M blocks on a lattice)."""
        largest = (max(int(n) for n in point_values(self, "model.N")[1])
                   * max(int(m) for m in point_values(self, "model.M")[1]))
        if self.run.transient is None:
            object.__setattr__(self, "run", dataclasses.replace(self.run, transient=TRANSIENT_PER_BLOCK * largest))
        if self.run.decorrelation is None:
            object.__setattr__(self, "run", dataclasses.replace(
                self.run, decorrelation=DECORRELATION_PER_BLOCK * largest))

    def to_toml(self):
        """The resolved config as TOML text (stored in every catalog)."""
        out = []
        for name, cls in SECTIONS.items():
            if name == "run" and self.population is not None:
                out += ["[population]", *self.population.to_toml(), ""]
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
    if isinstance(v, populations.Draw):
        return v.to_toml()
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ("inf" if v > 0 else "-inf")
    return str(v)


@contextmanager
def from_set(overridden, section, key):
    """An error about a value that came from --set says so."""
    try:
        yield
    except ConfigError as err:
        if (section, key) not in overridden:
            raise
        raise ConfigError(f"{err} (from --set {overridden[section, key]})") from None


def parse_section(name, raw):
    """One section's dataclass from its table alone (a task's stored [integrator]): its keys' checks."""
    return _section(name, raw, {})


def _section(name, raw, overridden):
    cls = SECTIONS[name]
    if not isinstance(raw, dict):
        raise ConfigError(f"[{name}] must be a table")
    known = {f.name: f for f in fields(cls)}
    given = {}
    for key, value in raw.items():
        with from_set(overridden, name, key):
            if key not in known:
                raise ConfigError(f"unknown key {name}.{key} (known: {', '.join(known)})")
            given[key] = coerce(name, key, value, known[key].type)
    return cls(**given)


def _sweep(raw, overridden, law_keys):
    if not isinstance(raw, dict):
        raise ConfigError("[sweep] must be a table")
    types = MODEL_TYPES
    out = []
    for key, values in _flat(raw):
        with from_set(overridden, "sweep", key):
            if key.startswith(POPULATION + "."):
                drawn = key.partition(".")[2]
                if not isinstance(values, list) or not values:
                    raise ConfigError(f"sweep.{key} must be a non-empty list of distributions, e.g. "
                                      f'{key} = [{{distribution = "uniform", min = 20, max = 30}}, [40]], '
                                      f'got {values!r}')
                out.append((key, _distinct(key, tuple(populations.parse_draw(drawn, v, types, law_keys, f"sweep.{key}")
                                                      for v in values))))
                continue
            if key not in types or key in ("law", "geometry"):
                raise ConfigError(f"unknown key sweep.{key} (only [model] keys can be swept: "
                                  f"{', '.join(k for k in types if k not in ('law', 'geometry'))})")
            if not isinstance(values, list) or not values:
                raise ConfigError(f"sweep.{key} must be a non-empty list of values, e.g. {key} = [20, 40] "
                                  f"(on the command line: --set 'sweep.{key}=[20, 40]'), got {values!r}")
            out.append((key, _distinct(key, tuple(coerce("model", key, v, types[key], where=f"sweep.{key}")
                                                  for v in values))))
    return tuple(out)


def _population(raw, overridden, types, law_keys):
    if not isinstance(raw, dict):
        raise ConfigError("[population] must be a table")
    entries = []
    for key, value in raw.items():
        with from_set(overridden, POPULATION, key):
            entries.append(populations.parse_entry(key, value, types, law_keys))
    return populations.build(entries)


def _flat(raw):
    """The [sweep] table's (key, values): `population.N = [...]` in the file is a table `population` in
    TOML, from --set a key "population.N"; both are the key "population.N"."""
    for key, values in raw.items():
        if key == POPULATION and isinstance(values, dict):
            yield from ((f"{POPULATION}.{k}", v) for k, v in values.items())
        else:
            yield key, values


def _distinct(key, values):
    repeated = [v for i, v in enumerate(values) if v in values[:i]]
    if repeated:   # the points would be one point run twice, then pooled by the reduction
        shown = repeated[0].to_toml() if isinstance(repeated[0], populations.Draw) else repr(repeated[0])
        raise ConfigError(f"sweep.{key} lists {shown} more than once")
    return values


def from_dict(raw, overridden=None):
    """Validate a parsed TOML document into a Config.

    overridden: {(section, key): "section.key=value"} of the values that came from --set.
    """
    overridden = overridden or {}
    allowed = set(SECTIONS) | {SWEEP, POPULATION}
    for name in raw:
        if name not in allowed:
            raise ConfigError(f"unknown section [{name}] (known: {', '.join(sorted(allowed))})")
    parts = {name: _section(name, raw.get(name, {}), overridden) for name in SECTIONS}
    law_keys = parts["model"].law_keys()
    types = MODEL_TYPES
    population = _population(raw[POPULATION], overridden, types, law_keys) if POPULATION in raw else None
    sweep = _sweep(raw.get(SWEEP, {}), overridden, law_keys)
    populations.check_run(population, sweep, parts["run"])
    cfg = Config(sweep=sweep, population=population, **parts)
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
    refusal = INTEGRATORS[cfg.integrator.method].refusal(laws.get(cfg.model.law))
    if refusal:
        raise ConfigError(refusal)
    law = laws.get(cfg.model.law)
    if not law.creeps and cfg.integrator.creep_tol != Integrator.creep_tol:
        # a tolerance for a phase this law never enters: a mistake about the model, not a no-op
        raise ConfigError(f"integrator.creep_tol = {cfg.integrator.creep_tol!r}: model.law = {law.name!r} has no creep "
                          f"phase (its blocks always start inertial events; docs/laws.md)")
    check_overflow(cfg)
    _check_some_event(cfg, law)
    return cfg


def _check_some_event(cfg, law):
    """Refuse a point whose chain can never have an event: its law's steady weakening (laws: steady_weakening)
    below the chain's softest stiffness. It would creep steadily at v = nu for ever (a run of it would never end).
    At equality the whole chain's creep is not positive definite (creep.py): it turns unstable, and events follow."""
    if not law.steady_weakening:
        return
    name, values = point_values(cfg, f"model.{law.steady_weakening}")
    low = min(values)
    if low < SOFTEST_STIFFNESS:
        raise ConfigError(f"{name} = {low:g}: below the chain's softest stiffness {SOFTEST_STIFFNESS:g} (the "
                          f"loader's spring, every block moving together), so the chain creeps steadily at v = nu for "
                          f"ever and never has an event; model.law = {law.name!r} needs {law.steady_weakening} >= "
                          f"{SOFTEST_STIFFNESS:g} (docs/numerics.md)")


def _integrator_names():
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
