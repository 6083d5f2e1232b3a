"""[population]: a run of many faults, each task a fault whose parameters are drawn from stated distributions.

    [population]
    faults = 300                                    # faults drawn: each is one task (run.seeds = 1)
    seed = 7                                        # root seed of the draws (not of the dynamics: run.seed)
    N = {distribution = "power", exponent = 2, min = 100, max = 1600}
    b = {distribution = "uniform", min = 20, max = 50}
    a = {distribution = "loguniform", min = 1, max = 30}
    l = [3, 6]                                      # a list: each value equally likely

A drawn key is a [model] key of the run's law, or N or l; [model] gives every key not drawn. The
distributions, for a key whose values are floats, on [min, max]:

- "uniform": density constant;
- "loguniform": density proportional to 1/x (min > 0);
- "power": density proportional to x^-exponent (exponent >= 0; 0 is uniform, 1 log-uniform; min > 0);
- a list: each value with probability 1/len.

N takes integers: "power" gives P(N = n) proportional to n^-exponent for every integer n in [min, max],
exactly ("uniform" is exponent 0 and "loguniform" exponent 1); N of a population is at least 2.

Fault f draws key x from its own stream, SeedSequence(population.seed, spawn_key=(f, POPULATION_STREAM,
crc32(x))): a fault's value of one key does not change when faults or other keys are added, and two
populations of one run (a [sweep] of population specs, e.g. `population.N = [{...}, {...}]`) draw their
faults from the same numbers (common random numbers: their differences are the specs', not the luck's).
The dynamics of task k draws from SeedSequence(run.seed, spawn_key=(k,)) as in every run.
"""
import math
import zlib
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .config_rules import ConfigError, coerce

# second spawn-key entry of the draws of a fault's parameters (run/tasks.py: BRANCH_STREAM = 1 for a branch's
# perturbation; a task's dynamics has the one-entry key (k,))
POPULATION_STREAM = 2
DISTRIBUTIONS = ("power", "uniform", "loguniform")
MAX_FAULTS = 10 ** 6
NOT_DRAWN = ("law", "nu")   # one law per run; the faults of a region share the plate's velocity


@dataclass(frozen=True)
class Draw:
    """The distribution of one key: `kind` one of DISTRIBUTIONS or "list"."""
    kind: str
    lo: float = None
    hi: float = None
    exponent: float = None
    values: tuple = ()

    def bounds(self):
        """Every value the draws can reach the extremes of (for the config's range and overflow checks)."""
        return self.values if self.kind == "list" else (self.lo, self.hi)

    def to_toml(self):
        """The spec as TOML (an inline table, or a list)."""
        if self.kind == "list":
            return "[" + ", ".join(_number(v) for v in self.values) + "]"
        exponent = f", exponent = {_number(self.exponent)}" if self.kind == "power" else ""
        return f'{{distribution = "{self.kind}"{exponent}, min = {_number(self.lo)}, max = {_number(self.hi)}}}'

    def short(self):
        """A few words for labels: "power 2 on [100, 1600]", "uniform on [20, 50]", "one of 3, 6"."""
        if self.kind == "list":
            return "one of " + ", ".join(f"{v:g}" for v in self.values)
        exponent = f" {self.exponent:g}" if self.kind == "power" else ""
        return f"{self.kind}{exponent} on [{self.lo:g}, {self.hi:g}]"

    def sample(self, rng, integer):
        """One value drawn with rng (a numpy Generator)."""
        if self.kind == "list":
            return self.values[int(rng.integers(len(self.values)))]
        u = rng.random()
        if integer:
            return int(self.lo + np.searchsorted(_integer_cdf(self.lo, self.hi, self._exponent()), u, side="right"))
        alpha = self._exponent()
        if alpha == 0:
            return self.lo + (self.hi - self.lo) * u
        if alpha == 1:
            return self.lo * (self.hi / self.lo) ** u
        e = 1.0 - alpha
        return (self.lo ** e + u * (self.hi ** e - self.lo ** e)) ** (1.0 / e)

    def _exponent(self):
        return {"uniform": 0.0, "loguniform": 1.0}.get(self.kind, self.exponent)


def _number(v):
    """A finite int or float as TOML (repr keeps a float's every bit)."""
    return repr(v) if isinstance(v, float) else str(v)


@lru_cache(maxsize=64)
def _integer_cdf(lo, hi, alpha):
    """Cumulative probabilities of n = lo..hi with P(n) proportional to n^-alpha (the last is 1)."""
    n = np.arange(lo, hi + 1, dtype=float)
    w = np.exp(-alpha * np.log(n))
    cdf = np.cumsum(w)
    cdf /= cdf[-1]
    cdf[-1] = 1.0
    return cdf


@dataclass(frozen=True)
class Population:
    faults: int
    seed: int = 0
    draws: tuple = ()     # ((key, Draw), ...) in the order given

    def to_toml(self):
        return [f"faults = {self.faults}", f"seed = {self.seed}", *(f"{k} = {d.to_toml()}" for k, d in self.draws)]


def draw_values(population, fault, draws, types):
    """{key: value} of fault `fault` for the draws ((key, Draw), ...); types: {key: int or float}."""
    out = {}
    for key, spec in draws:
        rng = np.random.default_rng(np.random.SeedSequence(
            population.seed, spawn_key=(fault, POPULATION_STREAM, zlib.crc32(key.encode()))))
        out[key] = spec.sample(rng, types[key] is int)
    return out


def parse_entry(key, value, types, law_keys):
    """One key of the [population] table: ("faults", n), ("seed", s) or (key, Draw)."""
    if key == "faults":
        return key, _integer(value, "population.faults", 1, MAX_FAULTS)
    if key == "seed":
        return key, _integer(value, "population.seed", 0, 2 ** 63 - 1)
    return key, parse_draw(key, value, types, law_keys, f"population.{key}")


def build(entries):
    """The Population of the table's parsed entries [(key, value)] in the order given."""
    given = dict(entries)
    if "faults" not in given:
        raise ConfigError("population.faults is missing: the number of faults drawn (each is one task)")
    return Population(given["faults"], given.get("seed", 0),
                      tuple((k, v) for k, v in entries if k not in ("faults", "seed")))


def drawable(key, types, law_keys, where):
    """Refuse a key that cannot be drawn, naming it as `where`."""
    if key in NOT_DRAWN:
        why = "one law per run" if key == "law" else "the faults of a region share the plate velocity"
        raise ConfigError(f"{where}: model.{key} is not drawn ({why})")
    if key not in types:
        raise ConfigError(f"unknown key {where} (known: faults, seed, and the drawn [model] keys: "
                          f"{', '.join(k for k in types if k not in NOT_DRAWN)})")
    if key not in ("N", "l") and key not in law_keys:
        raise ConfigError(f"{where} does not belong to model.law (its keys: {', '.join(law_keys)})")


def parse_draw(key, value, types, law_keys, where):
    """One key's distribution: a list of values, or a table {distribution, min, max[, exponent]}."""
    drawable(key, types, law_keys, where)
    integer = types[key] is int

    def check(v, name):
        v = coerce("model", key, v, types[key], where=name)
        if key == "N" and v < 2:
            raise ConfigError(f"{name} must be at least 2 (a fault of a population has two blocks or more), got {v!r}")
        return v

    if isinstance(value, list):
        if not value:
            raise ConfigError(f"{where} must be a non-empty list of values or a distribution table, got []")
        values = tuple(check(v, where) for v in value)
        return Draw("list", values=values)
    if not isinstance(value, dict):
        raise ConfigError(f"{where} must be a list of values or a table such as "
                          f'{{distribution = "uniform", min = 20, max = 50}}, got {value!r}')
    kind = value.get("distribution")
    if kind not in DISTRIBUTIONS:
        raise ConfigError(f"{where}.distribution must be one of {', '.join(DISTRIBUTIONS)} "
                          f"(or give a list of values), got {kind!r}")
    known = {"distribution", "min", "max"} | ({"exponent"} if kind == "power" else set())
    for name in value:
        if name not in known:
            raise ConfigError(f"unknown key {where}.{name} (a {kind} distribution has: {', '.join(sorted(known))})")
    for end in ("min", "max"):
        if end not in value:
            raise ConfigError(f"{where}.{end} is missing (a {kind} distribution has: {', '.join(sorted(known))})")
    lo, hi = check(value["min"], f"{where}.min"), check(value["max"], f"{where}.max")
    if not hi > lo:
        raise ConfigError(f"{where}: the range is empty (min = {lo!r}, max = {hi!r}; max must be above min)")
    exponent = None
    if kind == "power":
        if "exponent" not in value:
            raise ConfigError(f"{where}.exponent is missing (a power distribution has: {', '.join(sorted(known))})")
        exponent = coerce("population", "exponent", value["exponent"], float, where=f"{where}.exponent")
        if exponent < 0:
            raise ConfigError(f"{where}.exponent must be >= 0 (density x^-exponent), got {exponent!r}")
    if kind != "uniform" and lo <= 0:
        raise ConfigError(f"{where}.min must be > 0 for a {kind} distribution, got {lo!r}")
    if integer and hi - lo > 10 ** 7:
        raise ConfigError(f"{where}: at most 1e7 integers in the range, got {hi - lo + 1}")
    if not integer and kind != "uniform" and not math.isfinite(math.log(hi / lo)):
        raise ConfigError(f"{where}: the range's ratio max/min overflows a float")
    return Draw(kind, lo, hi, exponent)


def check_run(population, sweep, run):
    """Refuse what a population cannot be combined with: a swept population key without [population], a key both
    drawn and swept as a [model] key, several seeds (each fault is one trajectory), branching."""
    swept = {k for k, _ in sweep}
    drawn_in_sweep = {k.partition(".")[2] for k in swept if k.startswith("population.")}
    if population is None:
        if drawn_in_sweep:
            raise ConfigError(f"sweep.population.{sorted(drawn_in_sweep)[0]} needs a [population] section "
                              f"(population.faults: the faults drawn at each point of the sweep)")
        return
    for key in sorted(({k for k, _ in population.draws} | drawn_in_sweep) & swept):
        raise ConfigError(f"sweep.{key} and population.{key} both set model.{key}: draw it or sweep it, not both")
    if run.seeds != 1:
        raise ConfigError(f"run.seeds = {run.seeds}: with a [population] each fault is one trajectory "
                          f"(run.seeds = 1); draw more faults (population.faults)")
    if run.branch:
        raise ConfigError("run.branch = true: a population's faults are all different, there is no point to "
                          "spin up once and branch from")


def _integer(value, where, lo, hi):
    if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
        raise ConfigError(f"{where} must be an integer in [{lo}, {hi:.0e}], got {value!r}" if hi < 2 ** 62 else
                          f"{where} must be an integer >= {lo}, got {value!r}")
    return value
